"""`rsf fit`'s reasons and what it writes, checked against records with a planted truth: a law that does not
describe the record is named as such (not as friction without velocity dependence), a fit's ``.params.json`` reruns
with ``rsf simulate --params`` alone, and a record with several bad rows is refused at the first of them."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from cli_helpers import run_main
from stickslip import protocols
from stickslip.cli.params_files import run_history
from stickslip.errors import DataError
from stickslip.rsf import rsf_params, simulate
from stickslip.rsf.data import LabRecord, read_record
from stickslip.rsf.fit import NO_RESPONSE_TEXT, fit_record

UM = 1e-6

# --- the law that does not fit ----------------------------------------------------------------------------------

#: the tester's slip-law record: a = 0.008, b = 0.012, Dc = 20 um, k = 3000 1/m, 1 -> 10 -> 1 -> 3 um/s
SLIP = {"a": 0.008, "b": 0.012, "dc": 20 * UM, "stiffness": 3000.0}
SLIP_NOISE = 3e-4


@pytest.fixture(scope="module")
def slip_record() -> LabRecord:
    """30 s per velocity at 10 Hz (1201 rows), friction noise 3e-4 (the peak after 1 -> 10 um/s is ~0.015)."""
    params = rsf_params(SLIP["a"], SLIP["b"], SLIP["dc"], v_ref=UM, stiffness=SLIP["stiffness"], mu0=0.6, law="slip")
    history = protocols.velocity_steps([1 * UM, 10 * UM, 1 * UM, 3 * UM], [30.0] * 4)
    t = np.arange(0.0, history.duration + 1e-9, 0.1)
    run = simulate(params, history, times=t)
    rng = np.random.default_rng(2)
    d = run.load_point_displacement + 0.02 * UM * rng.standard_normal(t.size)
    f = run.friction + SLIP_NOISE * rng.standard_normal(t.size)
    return LabRecord.from_arrays(t, d, f, source="slip record", length_unit="um")


def test_a_slip_law_record_fitted_with_the_aging_law_is_a_misfit_not_flat_friction(slip_record):
    """It said "the friction shows no significant response to the velocity changes (F test ...: p = 0.031)" and
    marked a, b, Dc, k "not constrained: the friction shows no velocity dependence", at chi-square_r 74."""
    peak = float(np.max(slip_record.friction) - np.median(slip_record.friction))
    assert peak > 30 * SLIP_NOISE  # the planted response is far above the noise
    fit = fit_record(slip_record)  # the default: aging
    assert fit.status == "failed" and fit.reduced_chi_square > 20
    assert NO_RESPONSE_TEXT not in fit.reason and "velocity dependence" not in fit.reason
    assert fit.reason.startswith("the aging law does not describe the record: its residuals are ")
    assert f"reduced chi-square {fit.reduced_chi_square:.3g}" in fit.reason
    assert "structured (lag-one autocorrelation 0.9" in fit.reason
    assert "--law slip" in fit.reason
    for key in ("a", "b", "dc", "stiffness"):
        assert fit.parameters[key].note == "the aging law does not describe the record"
        assert "velocity dependence" not in fit.summary()["parameters"][key].get("note", "")
    # the law the reason suggests is the planted one: it gives the truth back, inside the intervals
    slip = fit_record(slip_record, law="slip")
    assert slip.status == "ok", slip.reason
    assert slip.reduced_chi_square == pytest.approx(1.0, abs=0.2)
    for key, true in SLIP.items():
        lo, hi = slip.parameters[key].interval
        assert lo <= true <= hi, (key, slip.parameters[key].text())


def test_constant_friction_is_still_no_velocity_dependence_and_says_why():
    """Friction 0.6 plus white noise 2e-4 under 1 -> 10 -> 1 um/s: constant friction is adequate against the noise."""
    history = protocols.velocity_steps([1 * UM, 10 * UM, 1 * UM], [40.0, 20.0, 40.0])
    t = np.arange(0.0, history.duration + 1e-9, 0.1)
    rng = np.random.default_rng(9)
    flat = LabRecord.from_arrays(t, history.displacement_at(t), 0.6 + 2e-4 * rng.standard_normal(t.size))
    fit = fit_record(flat, fixed={"stiffness": 2000.0}, drift_check=False)  # held and unchecked: 10x faster
    assert fit.status == "failed"
    assert f"{NO_RESPONSE_TEXT}: constant friction describes the record to within its noise" in fit.reason
    assert "does not describe the record" not in fit.reason
    assert fit.parameters["a"].note == "the friction shows no velocity dependence"


# --- fit -> simulate --params -----------------------------------------------------------------------------------

CHAIN = {"a": 0.010, "b": 0.015, "dc": 10 * UM, "stiffness": 1600.0}
CHAIN_STEPS = ([1 * UM, 10 * UM, 1 * UM], [40.0, 40.0, 40.0])


@pytest.fixture(scope="module")
def chain_record(tmp_path_factory):
    """1 -> 10 -> 1 um/s at 4 Hz (481 rows), friction noise 1e-4, displacement in um; and the noise-free truth."""
    params = rsf_params(CHAIN["a"], CHAIN["b"], CHAIN["dc"], v_ref=UM, stiffness=CHAIN["stiffness"], mu0=0.6)
    history = protocols.velocity_steps(*CHAIN_STEPS)
    t = np.arange(0.0, history.duration + 1e-9, 0.25)
    run = simulate(params, history, times=t)
    rng = np.random.default_rng(7)
    frame = pd.DataFrame({
        "time [s]": 500.0 + t,
        "load_point_displacement [um]": run.load_point_displacement / UM + 0.005 * rng.standard_normal(t.size),
        "friction": run.friction + 1e-4 * rng.standard_normal(t.size),
    })  # fmt: skip
    path = tmp_path_factory.mktemp("rsf-fit-reasons") / "record.csv"
    frame.to_csv(path, index=False)
    return path, t, run.friction


@pytest.mark.parametrize("name, rerun_from", [("fit.toml", "fit.params.json"), ("fit.json", "fit.json")])
def test_a_fits_parameters_rerun_with_simulate_params_alone(chain_record, tmp_path, capsys, name, rerun_from):
    """`rsf fit -o B.toml` then `rsf simulate --params B.params.json` exited 2 ("give the protocol"): the history
    was only under `fit.protocol`.  Now the file carries `protocol` and `start_velocity`, and the rerun is the
    planted record's friction."""
    path, t, truth = chain_record
    code, _, err = run_main(capsys, "rsf", "fit", str(path), "-o", str(tmp_path / name))
    assert code == 0, err
    written = json.loads((tmp_path / rerun_from).read_text())
    assert [s["velocity"] for s in written["protocol"]] == pytest.approx(CHAIN_STEPS[0], rel=0.01)
    assert [s["duration"] for s in written["protocol"]] == pytest.approx(CHAIN_STEPS[1], abs=0.5)
    assert written["start_velocity"] == pytest.approx(1 * UM, rel=0.01)
    again = tmp_path / "again.csv"
    code, _, err = run_main(capsys, "rsf", "simulate", "--params", str(tmp_path / rerun_from), "--every", "0.25 s",
                            "-o", str(again))  # fmt: skip
    assert code == 0, err
    rerun = pd.read_csv(again, comment="#")
    assert len(rerun) == t.size
    assert rerun["time [s]"].to_numpy() == pytest.approx(t, abs=0.3)  # the fitted change times, not the planted
    assert np.max(np.abs(rerun["friction [1]"].to_numpy() - truth)) < 3e-4  # of a 0.012 peak, noise 1e-4


def test_a_fits_file_with_its_history_under_fit_only_still_reruns(tmp_path):
    """Files written before the history was put beside the parameters: `fit.protocol` is read (SI rows)."""
    path = tmp_path / "old.params.json"
    rows = [{"start": 0.0, "velocity": 1e-6, "duration": 10.0, "unit": "m/s"},
            {"start": 10.0, "velocity": 1e-5, "duration": 5.0, "unit": "m/s"}]  # fmt: skip
    path.write_text(json.dumps({"parameters": {"a": 0.01}, "fit": {"protocol": rows}}))
    protocol, start = run_history(path)
    assert [(r["velocity"], r["duration"]) for r in protocol] == [(1e-6, 10.0), (1e-5, 5.0)]
    assert start is None


# --- bad rows ---------------------------------------------------------------------------------------------------


def _bad_frame(velocity: bool = False) -> pd.DataFrame:
    t = np.arange(60) * 0.1
    frame = pd.DataFrame({"time [s]": t, "friction": 0.6 + 1e-3 * np.sin(t)})
    if velocity:
        frame.insert(1, "load_point_velocity [um/s]", np.ones(t.size))
    else:
        frame.insert(1, "load_point_displacement [um]", t * 1.0)
    return frame


@pytest.mark.parametrize("velocity", [False, True])
def test_the_first_bad_row_is_named_whichever_column_it_is_in(tmp_path, velocity):
    """NaN friction at data rows 10-14 and a NaN load-point column at row 40: it named only row 40 (the columns were
    checked one after the other, the load point's first).  Rows are the file's lines: the header is line 1."""
    frame = _bad_frame(velocity)
    frame.iloc[10:15, 2] = np.nan
    frame.iloc[40, 1] = np.nan
    path = tmp_path / "bad.csv"
    frame.to_csv(path, index=False)
    with pytest.raises(DataError) as info:
        read_record(path)
    column = "velocity" if velocity else "displacement"
    text = str(info.value)
    assert (
        f"row 12: friction is not a finite number (6 rows in all: friction in 5 from row 12, {column} at row 42)"
        in text
    )


def test_a_row_with_two_bad_values_names_both():
    t = np.arange(20) * 0.1
    d, f = t * 1e-6, np.full(t.size, 0.6)
    d[7] = f[7] = np.nan
    with pytest.raises(DataError, match=r"record: row 8: displacement and friction are not finite numbers$"):
        LabRecord.from_arrays(t, d, f, source="record")
