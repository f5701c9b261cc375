"""`rsf fit`'s verdicts against records with a planted truth: a held stiffness or a law that is not the record's
fails the fit when the alternative describes the record (it was "ok" with intervals that missed the truth); a
drift the fit misses leads the reason with the drift to fit; a window's times are all on the file's own clock; a
negative b is read, not hidden."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip import protocols
from stickslip.rsf import rsf_params, simulate
from stickslip.rsf.data import LabRecord
from stickslip.rsf.fit import fit_record

UM = 1e-6
#: the tester's record: a = 0.008, b = 0.012, Dc = 20 um, k = 3000 1/m, 1 -> 10 -> 1 um/s (40, 20, 40 s) at 10 Hz
TRUTH = {"a": 0.008, "b": 0.012, "dc": 20 * UM, "stiffness": 3000.0}


def _record(noise: float = 2e-4, seed: int = 5, law: str = "aging", time_drift: float = 0.0, slip_drift: float = 0.0,
            wander: float = 0.0, wander_from: float = 0.0, t0: float = 0.0, **truth: float) -> LabRecord:  # fmt: skip
    """The record simulated from ``TRUTH`` (or ``truth``), with white friction noise, a linear drift in time (per s)
    or slip (per m), and a sine wander of period 7 s from ``wander_from`` s on; time from ``t0`` on the file's clock."""
    values = {**TRUTH, **truth}
    params = rsf_params(values["a"], values["b"], values["dc"], v_ref=UM, stiffness=values["stiffness"], mu0=0.6,
                        law=law)  # fmt: skip
    history = protocols.velocity_steps([1 * UM, 10 * UM, 1 * UM], [40.0, 20.0, 40.0])
    t = np.arange(0.0, history.duration + 1e-9, 0.1)
    run = simulate(params, history, times=t)
    rng = np.random.default_rng(seed)
    d = run.load_point_displacement
    f = run.friction + noise * rng.standard_normal(t.size) + time_drift * t + slip_drift * d
    f = f + wander * np.sin(2 * np.pi * t / 7.0) * (t >= wander_from)
    return LabRecord.from_arrays(t + t0, d, f, source="planted record", length_unit="um")


def _covers(entry: dict, true: float) -> bool:
    lo, hi = entry["interval"]
    return lo <= true <= hi


def _near(entry: dict, true: float) -> bool:
    """Within 3 standard errors (a correct fit misses by chance 0.3 % of the time, not 5 %)."""
    return abs(entry["value"] - true) <= 3.0 * entry["stderr"]


@pytest.fixture(scope="module")
def clean() -> LabRecord:
    return _record()


# --- a wrong model is no longer "ok" -----------------------------------------------------------------------------


def _written(record: LabRecord, path) -> str:
    """The record as a rig writes it (time on the file's clock, displacement in um)."""
    rows = np.column_stack([record.t0 + record.time, record.displacement / UM, record.friction])
    np.savetxt(path, rows, delimiter="\t", header="Time(s)\tDispl(microns)\tFriction", comments="", fmt="%.10g")
    return str(path)


def test_a_held_stiffness_that_is_not_the_records_fails_naming_the_free_fit(clean, capsys, tmp_path):
    """Held at 2000 1/m (truth 3000) the fit said ok (exit 0) at chi-square_r 10 with intervals that missed the
    truth.  Now exit 3, the reason names the free fit, and that fit holds the planted truth."""
    path = _written(clean, tmp_path / "clean.txt")
    code, out, err = run_main(capsys, "rsf", "fit", path, "--stiffness", "2e-3 1/um", "--json")
    report = json.loads(out)
    assert code == 3 and report["status"] == "failed" and report["reduced_chi_square"] > 2
    assert report["reason"].startswith(
        "the held stiffness 0.002 1/µm does not describe the record: with the stiffness free the fit does, at "
    )
    assert "stickslip: fit failed: the held stiffness" in err
    freed = [alt for alt in report["alternatives"] if alt.get("fit") == "the stiffness free"]
    assert len(freed) == 1 and freed[0]["describes"] and freed[0]["better"]
    assert freed[0]["reduced_chi_square"] < 1.5
    for key, true in TRUTH.items():  # the alternative the reason names holds the planted truth
        assert _covers(freed[0]["parameters"][key], true), (key, freed[0]["parameters"][key])
    assert report["parameters"]["a"]["interval"] is None  # no interval that misleads


def test_a_law_that_is_not_the_records_fails_naming_the_law_that_is():
    """The slip law on an aging-law record (noise 6e-4) said ok at chi-square_r 16.5."""
    fit = fit_record(_record(noise=6e-4), law="slip", drift_check=False)
    assert fit.status == "failed" and fit.reduced_chi_square > 2
    assert fit.reason.startswith("the slip law does not describe the record: the aging law does, at ")
    assert "fit it with --law aging" in fit.reason
    aging = next(alt for alt in fit.alternatives if alt["fit"] == "the aging law")
    assert aging["reduced_chi_square"] <= 2 and aging["p_value"] < 1e-3
    for key, true in TRUTH.items():
        assert _covers(aging["parameters"][key], true), (key, aging["parameters"][key])
    assert fit.parameters["b"].note == "the slip law does not describe the record"
    assert not any(alt["fit"].startswith("two states") for alt in fit.alternatives)  # (a one-state one describes it)


def test_where_no_alternative_describes_the_record_the_fit_stays_ok_and_says_what_was_tried():
    """A wander no law describes (after the first segment): ok, with each alternative's chi-square_r (a second state
    variable too, since round 29: tried where no one-state alternative describes the record)."""
    fit = fit_record(_record(wander=6e-4, wander_from=40.0))
    assert fit.status == "ok" and fit.reduced_chi_square > 2
    tried = [alt for alt in fit.alternatives if "fit" in alt]
    assert [alt["fit"] for alt in tried] == ["the slip law", "the prz law", "two states of the aging law"]
    assert all(alt["reduced_chi_square"] > 2 for alt in tried)
    said = next(w for w in fit.warnings if w.startswith("alternatives tried from this fit's answer"))
    assert "none describes the record" in said and "the slip law" in said


def test_where_the_first_segment_alone_rules_the_alternatives_out_none_is_tried():
    """Every law and stiffness give the same steady friction before the first change: a first segment whose
    residuals alone exceed chi-square_r 2 over the record leaves nothing to try (the real records' case)."""
    record = _record(wander=1e-3)
    first = record.time < 36.0
    floor = np.sum(((record.friction[first] - np.mean(record.friction[first])) / 2e-4) ** 2) / len(record)
    assert floor > 2  # (an independent count: the wander over the first segment against the planted noise)
    fit = fit_record(record)
    assert fit.status == "ok"
    skipped = ["the slip law", "the prz law", "a second state variable"]
    assert len(fit.alternatives) == 1 and fit.alternatives[0]["skipped"] == skipped
    assert any("none was tried" in w for w in fit.warnings)


def test_a_fit_to_the_noise_tries_nothing_and_a_given_noise_turns_the_alternatives_off(clean):
    fit = fit_record(clean)
    assert fit.status == "ok" and fit.reduced_chi_square < 2 and fit.alternatives == ()
    given = fit_record(_record(noise=6e-4), law="slip", noise=6e-4)  # (the studies that compare the laws themselves)
    assert given.alternatives == () and "the aging law does" not in given.reason


# --- a drift leads the reason ------------------------------------------------------------------------------------


@pytest.mark.parametrize(("drift", "kind"), [({"time_drift": 2e-5, "seed": 2}, "time"),
                                             ({"slip_drift": 30.0, "seed": 2}, "slip")])  # fmt: skip
def test_a_drift_that_explains_most_of_the_residuals_leads_the_reason_with_the_drift_to_fit(drift, kind):
    """The reason led with "the aging law does not describe the record ... fit another law" for a record whose
    residuals a time drift explained; the drift it names is the planted one, and fitting it gives the truth back."""
    record = _record(**drift)
    fit = fit_record(record, drift_check=False)
    assert fit.status == "failed"
    first = fit.reason.split("; fit the drift first with ")
    assert first[0].startswith("a linear drift in slip and time explains ")
    assert first[1].startswith(f"--trend {kind};") or first[1] == f"--trend {kind}"
    assert "fit another law" not in fit.reason
    refit = fit_record(record, trend=kind, drift_check=False)
    assert refit.status == "ok", refit.reason
    summary = refit.summary()["parameters"]
    key, true = ("time_trend", drift["time_drift"]) if kind == "time" else ("trend", drift["slip_drift"])
    assert _near(summary[key], true), summary[key]
    for name, value in TRUTH.items():
        assert _near(summary[name], value), (name, summary[name])


# --- one clock ---------------------------------------------------------------------------------------------------


def test_a_windows_times_are_all_on_the_files_own_clock(capsys, tmp_path):
    """A record whose clock starts at 5000 s fitted over 5010 ... 5100 s: the history and the change times were
    relative to the window's start (from 30 s: 10 um/s; change_1 30 s) under a title on the file's clock."""
    path = _written(_record(t0=5000.0), tmp_path / "late.txt")
    code, out, _ = run_main(capsys, "rsf", "fit", path, "--window", "5010 s:5100 s")
    assert code == 0, out
    assert "[5010 ... 5100 s]" in out and "times on the file's own clock" in out
    lines = [line.split() for line in out.splitlines()]
    starts = [float(line[1].rstrip("s:")) for line in lines if line and line[0] == "from"]
    assert starts == pytest.approx([5010.0, 5040.0, 5060.0], abs=0.01)  # the planted changes, on the file's clock
    changes = [float(line[1]) for line in lines if line and line[0].startswith("change_")]
    assert changes == pytest.approx([5040.0, 5060.0], abs=0.01)
    code, out, _ = run_main(capsys, "rsf", "fit", path, "--window", "5010 s:5100 s", "--json")
    report = json.loads(out)
    assert [row["file_time"] for row in report["protocol"]] == pytest.approx([5010.0, 5040.0, 5060.0], abs=0.01)
    assert [row["file_time"] for row in report["change_times"]] == pytest.approx([5040.0, 5060.0], abs=0.01)
    assert report["record"]["t0"] == pytest.approx(5010.0) and "5010" in report["units"]["clock"]


# --- a negative b ------------------------------------------------------------------------------------------------


def test_a_negative_b_is_read_in_a_note_not_failed_and_a_positive_one_gets_none(clean):
    """b < 0 is a state that weakens with age (clay gouges show it): the fit holds the planted b and says so."""
    fit = fit_record(_record(a=0.012, b=-0.004, seed=3))
    assert fit.status == "ok"
    assert _covers(fit.summary()["parameters"]["b"], -0.004)
    assert len(fit.notes) == 1 and fit.notes[0].startswith("b = -0.00") and "< 0: the state weakens" in fit.notes[0]
    assert fit.summary()["notes"] == list(fit.notes)
    assert fit_record(clean).notes == ()
