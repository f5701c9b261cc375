"""Issue 27, items 2 and 3: no requested sample dropped at the protocol's end; noise that does not depend on the
sampling rate, with intervals that cover the truth on 1 kHz quantised records with correlated noise.

The synthetic records are made from a known truth by :func:`stickslip.rsf.simulate` (a = 0.008, b = 0.012,
Dc = 20 um, k = 3000 1/m; 1 -> 10 -> 1 um/s), sampled at 10 Hz with 1 kHz stretches around each step, with an
Ornstein-Uhlenbeck friction noise (sd 3e-4, correlation time 20 ms: strongly correlated row to row at 1 kHz,
white at 10 Hz) and the friction quantised to a bit of 2e-4.  ``STICKSLIP_COVERAGE=N`` runs the coverage test on
N records instead of the default few (docs/rsf.md quotes the 100-record run).
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
from scipy import stats

from stickslip import protocols
from stickslip.errors import ModelError, ParameterError
from stickslip.rsf import rsf_params, simulate
from stickslip.rsf.data import LabRecord
from stickslip.rsf.fit import fit_record

UM = 1e-6
TRUTH = {"a": 0.008, "b": 0.012, "dc": 20 * UM, "stiffness": 3e3}
PARAMS = rsf_params(TRUTH["a"], TRUTH["b"], TRUTH["dc"], v_ref=UM, stiffness=TRUTH["stiffness"], mu0=0.6)
HISTORY = protocols.velocity_steps([1 * UM, 10 * UM, 1 * UM], [30.0, 30.0, 40.0])
SIGMA, TAU, BIT = 3e-4, 0.02, 2e-4


def mixed_times(fast: tuple[tuple[float, float], ...] = ((29.5, 32.5), (59.5, 62.5))) -> np.ndarray:
    """10 Hz, and 1 kHz over the stretches in ``fast`` (as a rig switches its rate at a step)."""
    t = np.round(np.arange(0.0, HISTORY.duration + 1e-9, 0.1), 9)
    for lo, hi in fast:
        t = np.union1d(t, np.round(np.arange(lo, hi, 1e-3), 9))
    return t


def noisy(time: np.ndarray, friction: np.ndarray, displacement: np.ndarray, seed: int) -> LabRecord:
    """Friction + OU noise sampled exactly at ``time``, quantised to BIT; displacement quantised to 0.05 um."""
    rng = np.random.default_rng(seed)
    phi = np.exp(-np.diff(time) / TAU)
    kicks = SIGMA * np.sqrt(1 - phi**2) * rng.standard_normal(phi.size)
    ou = np.empty(time.size)
    ou[0] = SIGMA * rng.standard_normal()
    for i in range(1, time.size):
        ou[i] = phi[i - 1] * ou[i - 1] + kicks[i - 1]
    f = np.round((friction + ou) / BIT) * BIT
    d = np.round(displacement / (0.05 * UM)) * 0.05 * UM
    return LabRecord.from_arrays(time, d, f, source=f"synthetic {seed}", length_unit="um")


@pytest.fixture(scope="module")
def mixed_run():
    t = mixed_times()
    return t, simulate(PARAMS, HISTORY, times=t)


# --- item 2: the protocol's end ----------------------------------------------------------------------------------


def test_a_sample_within_rounding_of_the_end_is_kept():
    end = HISTORY.duration
    for last in (np.nextafter(np.nextafter(end, math.inf), math.inf), end * (1 + 1e-12), end * (1 + 5e-10)):
        t = np.linspace(0.0, end, 1373)
        t[-1] = last
        run = simulate(PARAMS, HISTORY, times=t)
        assert run.status == "ok" and run.time.size == 1373 and run.time[-1] == end
        # the sample at the end is the end's: the steady friction at 1 um/s reached again, and a run to exactly
        # the end agrees
        exact = simulate(PARAMS, HISTORY, times=np.r_[t[:-1], end])
        assert run.friction[-1] == exact.friction[-1]
    with pytest.raises(ParameterError, match="within the protocol"):
        simulate(PARAMS, HISTORY, times=[1.0, end * (1 + 1e-8)])


def test_times_not_starting_at_zero_give_only_the_times_asked_for():
    run = simulate(PARAMS, HISTORY, times=[0.5, 1.0, 40.0])
    assert list(run.time) == [0.5, 1.0, 40.0]
    full = simulate(PARAMS, HISTORY, times=[0.0, 0.5, 1.0, 40.0])
    assert np.allclose(run.friction, full.friction[1:], rtol=0, atol=1e-9)


def test_a_record_ending_a_rounding_after_the_history_fits():
    """It said 'the best parameters give a run that blows up; give a stiffness' with the stiffness given."""
    t = np.linspace(0.0, HISTORY.duration, 1001)
    run = simulate(PARAMS, HISTORY, times=t)
    t[-1] = HISTORY.duration * (1 + 3e-12)
    f = run.friction + 2e-4 * np.random.default_rng(0).standard_normal(t.size)
    fit = fit_record(LabRecord.from_arrays(t, run.load_point_displacement, f), protocol=HISTORY,
                     fixed={"stiffness": 3e3}, drift_check=False)  # fmt: skip
    assert fit.status == "ok", fit.reason
    assert len(fit.model_friction) == 1001


def test_a_model_that_cannot_run_says_what_happened_not_give_a_stiffness():
    """Everything held where the slider is unstable (k = 10 < k_c = 200 1/m): the run blows up, and it says so."""
    t = np.linspace(0.0, HISTORY.duration, 501)
    run = simulate(PARAMS, HISTORY, times=t)
    rec = LabRecord.from_arrays(t, run.load_point_displacement, run.friction)
    held = {"a": 0.008, "b": 0.012, "dc": 20 * UM, "stiffness": 10.0}
    with pytest.raises(ModelError, match="cannot be evaluated: the run stopped: blow-up") as caught:
        fit_record(rec, protocol=HISTORY, fixed=held, drift_check=False)
    assert "give a stiffness" not in str(caught.value)


# --- item 3: noise independent of the sampling rate ---------------------------------------------------------------


def coverage_records() -> int:
    return int(os.environ.get("STICKSLIP_COVERAGE", "4"))


def test_intervals_cover_the_truth_on_1khz_quantised_records_with_correlated_noise(mixed_run):
    """The old second-difference noise was ~5x too small at 1 kHz (chi2_r in the hundreds, 'failed'); now the fit
    is judged at chi2_r ~ 1 and the 95 % intervals of a, b, a-b, Dc and k hold the truth at the binomial rate.

    Accepted: hits >= the 0.1 % quantile of Binomial(trials, 0.95) (100 records, 500 intervals: >= 459; the
    default 4 records, 20 intervals: >= 15) and, on the large run, <= its 99.9 % quantile (too wide fails too)."""
    t, run = mixed_run
    trials = hits = 0
    chi2 = []
    for seed in range(coverage_records()):
        rec = noisy(t, run.friction, run.load_point_displacement, 300 + seed)
        fit = fit_record(rec, protocol=HISTORY, drift_check=False)
        assert fit.status == "ok", fit.reason
        assert "steady sliding" in fit.noise_method and "autocorrelation" in fit.noise_method
        chi2.append(fit.reduced_chi_square)
        for key in ("a", "b", "dc", "stiffness", "a-b"):
            p = fit.derived[key] if key == "a-b" else fit.parameters[key]
            true = TRUTH["a"] - TRUTH["b"] if key == "a-b" else TRUTH[key]
            hits += p.interval[0] <= true <= p.interval[1]
            trials += 1
    assert 0.7 < np.median(chi2) < 1.4  # judged against the record's own noise: about 1, not 380-630
    assert hits >= stats.binom.ppf(0.001, trials, 0.95)
    if trials >= 200:
        assert hits <= stats.binom.ppf(0.999, trials, 0.95)


def test_1khz_and_the_same_record_decimated_to_100hz_give_comparable_intervals():
    """A 1 kHz record and every tenth row of it: the correlated rows carry about as much as the decimated ones, so
    the intervals agree to well within 2x (the second-difference noise made the 1 kHz ones ~5x narrower)."""
    history = protocols.velocity_steps([1 * UM, 10 * UM, 1 * UM], [3.0, 3.0, 6.0])
    truth = rsf_params(0.008, 0.012, 2 * UM, v_ref=UM, stiffness=3e4, mu0=0.6)
    t = np.round(np.arange(0.0, history.duration + 1e-9, 1e-3), 9)
    run = simulate(truth, history, times=t)
    fast = noisy(t, run.friction, run.load_point_displacement, 7)
    rows = np.arange(0, t.size, 10)
    slow = LabRecord.from_arrays(t[rows], fast.displacement[rows], fast.friction[rows], length_unit="um")
    fits = [fit_record(rec, protocol=history, drift_check=False) for rec in (fast, slow)]
    for fit in fits:
        assert fit.status == "ok", fit.reason
        assert 0.6 < fit.reduced_chi_square < 1.6
    for key in ("a", "b", "dc"):
        widths = [f.parameters[key].interval[1] - f.parameters[key].interval[0] for f in fits]
        assert 0.5 < widths[0] / widths[1] < 1.6, (key, widths)
        for fit in fits:  # the truth within 4 standard errors: this noise puts both fits ~3 off (the same
            p = fit.parameters[key]  # realisation); the coverage test above judges the rate of misses
            assert abs(p.value - {"a": 0.008, "b": 0.012, "dc": 2 * UM}[key]) < 4 * p.stderr, (key, p.text())


def test_a_missed_step_still_fails_on_a_1khz_record(mixed_run):
    """Correlated noise must not excuse a wrong model: the same record read with the down step left out."""
    t, run = mixed_run
    rec = noisy(t, run.friction, run.load_point_displacement, 1)
    wrong = protocols.velocity_steps([1 * UM, 10 * UM], [30.0, 70.0])
    fit = fit_record(rec, protocol=wrong, drift_check=False)
    assert fit.status == "failed"
    assert fit.reduced_chi_square > 100 or "does not follow" in fit.reason
