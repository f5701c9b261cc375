"""Round 30 (tester W): what `rsf fit` says before its search.

A change read from a load-point velocity column is dated by its rows (to their spacing), not "where the
displacement dates it (± 2e-14 s)"; rows at one velocity are refused before the cost estimate; and a record whose
friction shows no response to its velocity changes is failed in seconds by a check before the search (tester W's
1e6 noise rows ran 47 s of CPU, announcing "up to 8.7 min"), while real records and weak but significant responses
are still fitted (docs/rsf.md, "No response, said before the search")."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cli_helpers import run_main
from stickslip import protocols
from stickslip.cli import rsf_cmd
from stickslip.errors import DataError
from stickslip.fitting.datasets import data_path
from stickslip.rsf import fit as rsf_fit
from stickslip.rsf import rsf_params, simulate
from stickslip.rsf.data import LabRecord, read_record
from stickslip.rsf.fit import NO_RESPONSE_TEXT, fit_record, response_check

UM = 1e-6
RECORDS = Path(__file__).parent / "records"
#: tests/records/velocity_column.txt: 10 Hz rows, the velocity's new value first at t = 50.0 and 80.0 s
VELOCITY_STEPS = (50.0, 80.0)
SHARED = Path("/work/shared/data/giacomel-steadystate")


# --- a change read from a velocity column ---------------------------------------------------------------------------


def test_a_change_read_from_a_velocity_column_is_dated_by_its_rows_not_the_displacement():
    """It said "held where the displacement dates it (± 2.2e-14 s)": the integrated displacement's two lines meet
    exactly, but the rows say only that the velocity changed since the row before (0.1 s here: ± 0.1/sqrt(12))."""
    fit = fit_record(read_record(RECORDS / "velocity_column.txt"), drift_check=False)
    assert fit.status == "ok", fit.reason
    assert len(fit.change_times) == len(VELOCITY_STEPS)
    for change, truth in zip(fit.change_times, VELOCITY_STEPS, strict=True):
        assert "displacement dates" not in change.note, change.note
        assert "the velocity column's rows date it" in change.note, change.note
        assert f"± {0.1 / math.sqrt(12.0):.2g} s" in change.note, change.note  # the row spacing's, 0.029 s
        if change.interval is not None:  # fitted: its interval holds the step's first new row
            assert change.interval[0] <= truth <= change.interval[1], change.text()
        else:
            assert change.value == pytest.approx(truth, abs=0.1)


def test_rsf_fit_says_a_velocity_columns_change_is_known_to_its_row_spacing(capsys):
    code, out, err = run_main(capsys, "rsf", "fit", str(RECORDS / "velocity_column.txt"))
    assert code == 0, err
    assert "displacement dates" not in out
    assert "the velocity column's rows date it at 50.000 ± 0.029 s" in out


# --- rows at one velocity: refused before the estimate -------------------------------------------------------------


def _one_velocity_file(tmp_path: Path) -> Path:
    t = np.arange(0.0, 100.0, 0.1)
    rng = np.random.default_rng(4)
    frame = pd.DataFrame({"Time (s)": t, "Displ (um)": 1.0 * t, "Friction": 0.6 + 1e-3 * rng.standard_normal(t.size)})
    path = tmp_path / "one_velocity.csv"
    frame.to_csv(path, index=False)
    return path


def test_rows_at_one_velocity_are_refused_before_the_cost_estimate(tmp_path, capsys, monkeypatch):
    """It printed "about 38 s ... up to 6.3 min" before refusing the file as having no velocity change."""
    monkeypatch.setattr(rsf_cmd, "PROGRESS_AFTER_SECONDS", 0.0)  # any estimate made would be printed
    code, _, err = run_main(capsys, "rsf", "fit", str(_one_velocity_file(tmp_path)))
    assert code == 2, err
    assert "about" not in err and "model runs" not in err, err
    assert "moves at one velocity" in err and len(err.strip().splitlines()) == 1, err


def test_the_cost_estimate_itself_refuses_rows_at_one_velocity(tmp_path):
    record = read_record(_one_velocity_file(tmp_path))
    settings = {"law": "aging", "states": 1, "trend": False, "protocol": None, "mcmc_steps": 0, "seed": None}
    with pytest.raises(DataError, match="moves at one velocity"):
        rsf_cmd.estimate_fit_cost(record, settings)


# --- no response: said before the search ----------------------------------------------------------------------------

#: 1 -> 10 um/s at 50 s, 100 Hz rows, friction 0.6 plus white noise 1e-3 with no part along any step response
STEP_AT, RATE, NOISE = 50.0, 100.0, 1e-3


def _no_response_record() -> LabRecord:
    """The noise has its projection removed onto a level after the step and decays from it on at time scales a
    quarter decade apart (10 ms to 100 s, finer than the check's own), so no step response of any scale is in it:
    a fit's F test could find none, whatever the noise's draw."""
    history = protocols.velocity_steps([1 * UM, 10 * UM], [STEP_AT, STEP_AT])
    t = np.arange(0.0, history.duration, 1.0 / RATE)
    after = t >= STEP_AT
    columns = [np.ones(t.size), after.astype(float)]
    columns += [
        np.where(after, np.exp(-np.maximum(t - STEP_AT, 0.0) / tau), 0.0) for tau in 10.0 ** np.arange(-2.0, 2.01, 0.25)
    ]
    basis, _ = np.linalg.qr(np.column_stack(columns))
    noise = np.random.default_rng(11).standard_normal(t.size)
    noise -= basis @ (basis.T @ noise)
    friction = 0.6 + NOISE * noise / np.std(noise)
    return LabRecord.from_arrays(t, history.displacement_at(t), friction, source="no response", length_unit="um")


def test_a_record_with_no_response_fails_before_the_search(monkeypatch):
    """The search (and its restarts from other starts in Dc) is not run: the failed fit says why, with the
    starting values and no intervals."""

    def no_search(*args, **kwargs):
        raise AssertionError("the search ran")

    monkeypatch.setattr(rsf_fit, "_least_squares", no_search)
    fit = fit_record(_no_response_record())
    assert fit.status == "failed" and not fit.success and fit.nfev == 0
    assert fit.reason.startswith(f"{NO_RESPONSE_TEXT}: constant friction describes the record to within its noise")
    assert "the search was not run" in fit.reason
    for key in ("a", "b", "dc", "stiffness"):
        assert fit.parameters[key].interval is None and not fit.parameters[key].constrained
        assert fit.parameters[key].note == "the friction shows no velocity dependence"


def test_rsf_fit_fails_a_record_with_no_response_without_estimating_a_search(tmp_path, capsys, monkeypatch):
    record = _no_response_record()
    path = tmp_path / "noise.csv"
    pd.DataFrame({"Time (s)": record.time, "LP disp (um)": record.displacement / UM,
                  "Friction": record.friction}).to_csv(path, index=False)  # fmt: skip

    def no_estimate(*args, **kwargs):
        raise AssertionError("estimated a search")

    monkeypatch.setattr(rsf_cmd, "estimate_fit_cost", no_estimate)
    code, out, err = run_main(capsys, "rsf", "fit", str(path), "-o", str(tmp_path / "never.toml"))
    assert code == 3, err
    assert err.splitlines()[-1].startswith(f"stickslip: fit failed: {NO_RESPONSE_TEXT}")
    assert "the search was not run" in err and "no search: nothing to estimate" in out
    assert not (tmp_path / "never.toml").exists()


# --- what the check must not stop ------------------------------------------------------------------------------------

#: a weak response: a - b = 2e-4, the step's direct effect a ln 10 = 0.0046 under noise 0.006 (one row), where the
#: full fit still finds the response significant (F test p ~ 3e-4 against its 1e-3 level)
WEAK = {"a": 0.002, "b": 0.0018, "dc": 10 * UM, "stiffness": 2000.0}


def test_a_weak_but_significant_response_is_still_fitted():
    params = rsf_params(WEAK["a"], WEAK["b"], WEAK["dc"], v_ref=UM, stiffness=WEAK["stiffness"], mu0=0.6)
    history = protocols.velocity_steps([1 * UM, 10 * UM, 1 * UM], [40.0, 40.0, 40.0])
    t = np.arange(0.0, history.duration + 1e-9, 0.1)
    run = simulate(params, history, times=t)
    friction = run.friction + 0.006 * np.random.default_rng(1).standard_normal(t.size)
    record = LabRecord.from_arrays(t, history.displacement_at(t), friction, source="weak", length_unit="um")
    held = {"stiffness": WEAK["stiffness"]}
    assert response_check(record, fixed=held) is None
    fit = fit_record(record, fixed=held, drift_check=False, alternatives=False)
    assert fit.status == "ok", fit.reason
    assert fit.nfev > 0


REAL = [data_path("giacomel-sepiolite/velstep3_TR2_exp013_sepiolite.txt"), RECORDS / "sepiolite_velstep1_slice.txt",
        SHARED / "velstep1_TR2_exp013_sepiolite.txt", SHARED / "velstep2_TR2_exp013_sepiolite.txt"]  # fmt: skip


@pytest.mark.parametrize("path", REAL, ids=lambda p: p.name)
@pytest.mark.parametrize("trend", [False, "time"])
def test_real_records_pass_the_check(path, trend):
    if not path.exists():
        pytest.skip("the shared sepiolite records are not on this machine")
    assert response_check(read_record(path), trend=trend) is None


# --- a noise-free record is no clipped sensor ------------------------------------------------------------------------


def test_a_noise_free_records_steady_opening_at_its_minimum_is_not_a_saturated_sensor():
    """`stickslip compare --bond-model transient` fits the model's noise-free step, whose 502 opening rows sit
    exactly at its minimum: read as a clipped sensor (round 30's saturation check), they were censored and the fitted
    a - b missed the model's steady slope by 14 %."""
    from stickslip.rsf.saturation import find_saturation

    params = rsf_params(0.012, 0.008, 10 * UM, v_ref=UM, stiffness=5000.0, mu0=0.6)
    history = protocols.velocity_steps([1 * UM, 10 * UM], [20.0, 20.0])
    t = np.arange(0.0, history.duration + 1e-9, 0.05)
    friction = simulate(params, history, times=t).friction
    opening = friction[t < 20.0]
    assert np.all(opening == friction.min()) and opening.size > 100  # the steady opening is the minimum, exactly
    assert find_saturation(friction) is None
    clipped = np.minimum(friction + 1e-4 * np.random.default_rng(5).standard_normal(t.size), 0.615)
    assert find_saturation(clipped) is not None  # a noisy record's flat top still is
