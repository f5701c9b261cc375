"""Issue 27, items 5 (API), 6 and 9: fixed and guessed parameters, a fitting window in the record's own time,
weights near the steps with intervals that account for them, the drift term's influence on the conclusion, and
the JSON in SI.  Synthetic records from a known truth (a = 0.008, b = 0.012, Dc = 20 um, k = 3000 1/m)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stickslip import protocols
from stickslip.errors import ParameterError
from stickslip.rsf import rsf_params, simulate
from stickslip.rsf.data import LabRecord
from stickslip.rsf.fit import fit_record

UM = 1e-6
TRUTH = {"a": 0.008, "b": 0.012, "dc": 20 * UM, "stiffness": 3e3}
PARAMS = rsf_params(TRUTH["a"], TRUTH["b"], TRUTH["dc"], v_ref=UM, stiffness=TRUTH["stiffness"], mu0=0.6)
STEP = protocols.velocity_steps([1 * UM, 10 * UM], [60.0, 40.0])


def synthetic(seed: int, rows: int = 600, offset: float = 0.0, params=PARAMS, drift: float = 0.0) -> LabRecord:
    """The step 1 -> 10 um/s, white friction noise 2e-4, a slip drift per metre, the file's clock from offset."""
    t = np.linspace(0, STEP.duration, rows)
    run = simulate(params, STEP, times=t)
    f = run.friction + drift * run.load_point_displacement + 2e-4 * np.random.default_rng(seed).standard_normal(rows)
    return LabRecord.from_arrays(t + offset, run.load_point_displacement, f, length_unit="um")


def inside(fit, keys=("a", "b", "dc")) -> bool:
    return all(fit.parameters[k].interval[0] <= TRUTH[k] <= fit.parameters[k].interval[1] for k in keys)


def test_bad_fixed_guess_window_weight_and_law_name_the_key():
    rec = synthetic(0, rows=100)
    cases = [
        ({"fixed": {"dcc": 1e-5}}, "fixed: unknown parameter 'dcc'"),
        ({"fixed": {"dc": -1e-5}}, "fixed: dc = -1e-05; expected a positive"),
        ({"fixed": {"a": 0.0}}, "fixed: a = 0.0; expected a positive"),
        ({"guess": {"stiffness": float("nan")}}, "guess: stiffness = nan; expected a finite"),
        ({"guess": {"b2": 0.01}}, "guess: b2 needs two state variables"),
        ({"fixed": {"a": 0.01}, "guess": {"a": 0.01}}, "a: both fixed and guessed"),
        ({"stiffness": 3e3, "fixed": {"stiffness": 2e3}}, "stiffness: given twice"),
        ({"fixed": [("a", 0.01)]}, "fixed: expected a mapping"),
        ({"window": (50.0, 10.0)}, "window: expected finite start < end"),
        ({"window": (1e6, 2e6)}, "window: 1e\\+06 ... 2e\\+06 s holds 0 rows"),
        ({"window": "0:10"}, "window: expected \\(start, end\\)"),
        ({"step_weight": 0.0}, "step_weight: expected a positive weight"),
        ({"law": ("aging",), "states": 2}, "law: expected a law name or 2 of them"),
        ({"law": ("aging", "slow")}, "law: expected a law name or 1 of them"),
    ]
    for kwargs, message in cases:
        with pytest.raises(ParameterError, match=message):
            fit_record(rec, **kwargs)


def test_fixed_values_are_held_and_the_rest_recovered():
    fit = fit_record(synthetic(1), fixed={"a": 0.008, "stiffness": 3e3, "mu0": 0.6}, drift_check=False)
    assert fit.status == "ok", fit.reason
    for key, value in (("a", 0.008), ("stiffness", 3e3), ("mu0", 0.6)):
        assert fit.parameters[key].fixed and fit.parameters[key].value == value
        assert fit.parameters[key].interval is None
    assert inside(fit, ("b", "dc"))
    diff = fit.derived["a-b"]  # a held: a - b carries b's error alone
    assert diff.stderr == pytest.approx(fit.parameters["b"].stderr, rel=1e-12)
    # a fixed a carries no error of its own: b's interval is narrower than with a free (a and b correlate)
    free = fit_record(synthetic(1), fixed={"stiffness": 3e3}, drift_check=False)
    held, loose = (f.parameters["b"].interval[1] - f.parameters["b"].interval[0] for f in (fit, free))
    assert held < 0.5 * loose


def test_guess_starts_a_free_stiffness_and_the_old_words_still_work():
    rec = synthetic(2)
    guessed = fit_record(rec, guess={"stiffness": 1.5e3}, drift_check=False)
    assert not guessed.parameters["stiffness"].fixed and inside(guessed, ("a", "b", "dc", "stiffness"))
    old_free = fit_record(rec, stiffness=1.5e3, fit_stiffness=True, drift_check=False)
    assert old_free.parameters["stiffness"].value == pytest.approx(guessed.parameters["stiffness"].value, rel=1e-6)
    old_fixed = fit_record(rec, stiffness=3e3, drift_check=False)
    assert old_fixed.parameters["stiffness"].fixed and old_fixed.parameters["stiffness"].value == 3e3


def test_a_window_in_the_files_own_time_with_found_or_given_history():
    """Rows 1000 ... 1100 s in the file; the window 1020 ... 1100 s starts in steady sliding at 1 um/s."""
    rec = synthetic(3, offset=1000.0)
    for history in (None, STEP):  # a given history is in the record's time from its first row: it is cut too
        fit = fit_record(rec, window=(1020.0, 1100.0), protocol=history, fixed={"stiffness": 3e3}, drift_check=False)
        assert fit.status == "ok", fit.reason
        assert fit.record.t0 == pytest.approx(1020.0, abs=0.2) and fit.record.time[-1] < 80.0
        assert fit.protocol.boundaries[1] == pytest.approx(60.0 - (fit.record.t0 - 1000.0), abs=0.2)
        assert inside(fit)
        assert fit.summary()["window"] == [1020.0, 1100.0]


def test_step_weights_give_intervals_that_hold_for_the_weighted_fit():
    """Weight 20 on the rows within 3 Dc / V of the step: over 6 noise realisations the scatter of the estimates
    matches the reported standard errors (the unweighted formula, sigma^2 (J^T W J)^-1, would be ~3x narrow)."""
    values, errors = [], []
    for seed in range(6):
        fit = fit_record(synthetic(10 + seed, rows=300), step_weight=20.0, fixed={"stiffness": 3e3},
                         protocol=STEP, drift_check=False)  # fmt: skip
        assert fit.status == "ok", fit.reason
        values.append([fit.parameters[k].value for k in ("a", "dc")])
        errors.append([fit.parameters[k].stderr for k in ("a", "dc")])
    ratio = np.std(values, axis=0, ddof=1) / np.mean(errors, axis=0)
    assert np.all((ratio > 0.4) & (ratio < 2.0)), ratio
    assert fit.summary()["step_weight"] == 20.0


def test_the_drift_term_flips_the_sign_of_a_minus_b_and_the_fit_says_so():
    """a - b = -0.0005 under a drift of +10 per metre of slip: fitted without a drift term, a - b comes out
    positive; the comparison fit with the drift finds it negative, and the result says the sign depends on it."""
    weak = rsf_params(0.010, 0.0105, 20 * UM, v_ref=UM, stiffness=3e3, mu0=0.6)
    fit = fit_record(synthetic(4, params=weak, drift=10.0), fixed={"stiffness": 3e3})
    sens = fit.drift_sensitivity
    assert fit.derived["a-b"].value > 0 and sens["alternative"]["a-b"]["value"] < 0
    assert sens["depends"] and "the sign of a-b" in sens["differences"]
    lo, hi = sens["alternative"]["a-b"]["interval"]
    assert lo <= -0.0005 <= hi  # the fit with the drift holds the truth
    assert any(w.startswith("the conclusion depends on the drift term") for w in fit.warnings)
    assert sens["compared"] == "a drift in slip" and json.dumps(fit.summary(), allow_nan=False)
    with_trend = fit_record(synthetic(4, params=weak, drift=10.0), fixed={"stiffness": 3e3}, trend="slip")
    assert with_trend.drift_sensitivity["compared"] == "no drift term" and with_trend.drift_sensitivity["depends"]


def test_without_a_drift_the_conclusion_does_not_depend_on_the_drift_term():
    fit = fit_record(synthetic(5), fixed={"stiffness": 3e3})
    assert fit.status == "ok" and not fit.drift_sensitivity["depends"]
    assert not any("drift term" in w for w in fit.warnings)
    lo, hi = fit.drift_sensitivity["alternative"]["a-b"]["interval"]
    assert lo <= -0.004 <= hi


def test_summary_is_si_and_the_text_keeps_the_records_unit():
    fit = fit_record(synthetic(6), fixed={"stiffness": 3e3}, drift_check=False)
    report = json.loads(json.dumps(fit.summary(), allow_nan=False))
    dc = report["parameters"]["dc"]
    assert dc["unit"] == "m" and dc["value"] == pytest.approx(20e-6, rel=0.05)
    assert dc["interval"][0] < 20e-6 < dc["interval"][1] < 1e-4
    assert report["parameters"]["stiffness"]["unit"] == "1/m" and report["parameters"]["stiffness"]["value"] == 3e3
    assert [row["velocity"] for row in report["protocol"]] == pytest.approx([1e-6, 1e-5], rel=1e-3)
    assert report["protocol"][0]["unit"] == "m/s"
    assert report["units"]["length"] == "m" and report["units"]["record_length_unit"] == "um"
    assert "µm" in fit.parameters["dc"].text() and fit.protocol_rows()[0]["unit"] == "um/s"
    assert "steady sliding" in report["noise_method"] and report["effective_rows"] > 0


def test_a_guessed_stiffness_below_the_starts_critical_one_still_fits():
    """A free stiffness started at 1000 1/m with the default Dc start (1 % of the slip, 4.2 um here) and the
    measured b - a = 0.005 starts past k_c = 1190 1/m: the search met a blow-up at once and failed.  The start's
    Dc is raised until the spring is stable there, and the fit finds the record's own k = 1600 1/m."""
    from stickslip import protocols
    from stickslip.rsf import rsf_params, simulate
    from stickslip.rsf.data import LabRecord
    from stickslip.rsf.fit import fit_record

    truth = rsf_params(a=0.005, b=0.01, dc=20e-6, stiffness=1600.0, v_ref=1e-6)
    history = protocols.velocity_steps([1e-6, 10e-6], [20.0, 40.0])
    times = np.linspace(0.0, 60.0, 1201)
    rng = np.random.default_rng(1)
    friction = simulate(truth, history, times=times).friction + rng.normal(0.0, 1e-5, times.size)
    record = LabRecord.from_arrays(times, history.displacement_at(times), friction)
    fit = fit_record(record, guess={"stiffness": 1000.0}, noise=1e-5)
    assert fit.status == "ok", fit.reason
    k = fit.parameters["stiffness"]
    assert abs(k.value - 1600.0) < 3 * k.stderr
