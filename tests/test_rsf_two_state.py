"""`rsf fit` with two state variables: known parameters recovered from a synthetic noisy step, inside their
intervals; the F test of two states against one says yes on a two-state record and no on a one-state record.

(The two-state spring-slider itself is checked against rsfmodel's published values in tests/test_rsf_rsfmodel.py.)
"""

from __future__ import annotations

import numpy as np
import pytest

from stickslip import protocols
from stickslip.rsf import RSFParams, simulate
from stickslip.rsf.data import LabRecord
from stickslip.rsf.fit import fit_record
from stickslip.rsf.params import StateVariable
from stickslip.studies.rsf_reading import Reading, f_test

UM = 1e-6
HISTORY = protocols.velocity_steps([10 * UM, 100 * UM, 10 * UM], [8.0, 4.0, 24.0])
NOISE = 2e-4


def record(law: str, states: tuple[tuple[float, float], ...], seed: int) -> LabRecord:
    """The step 10 -> 100 -> 10 um/s sampled at 10 Hz with white friction noise NOISE (a = 0.012, k = 2e4 1/m)."""
    truth = RSFParams(a=0.012, states=tuple(StateVariable(law, b, dc) for b, dc in states), mu0=0.6, v_ref=10 * UM,
                      stiffness=2e4)  # fmt: skip
    t = np.arange(0.0, HISTORY.duration + 1e-9, 0.1)
    run = simulate(truth, HISTORY, times=t)
    noisy = run.friction + NOISE * np.random.default_rng(seed).standard_normal(t.size)
    return LabRecord.from_arrays(t, run.load_point_displacement, noisy, source=f"synthetic {law}")


TWO = ((0.006, 5 * UM), (0.004, 60 * UM))


@pytest.mark.parametrize("law", ["aging"])
def test_two_state_fit_recovers_known_parameters_inside_its_intervals(law):
    fit = fit_record(record(law, TWO, seed=3), law=law, states=2, protocol=HISTORY, noise=NOISE)
    assert fit.status == "ok", fit.reason
    assert fit.reduced_chi_square == pytest.approx(1.0, abs=0.15)  # the model describes the record to its noise
    truth = {"a": 0.012, "b": TWO[0][0], "dc": TWO[0][1], "b2": TWO[1][0], "dc2": TWO[1][1], "stiffness": 2e4}
    for key, value in truth.items():
        lo, hi = fit.parameters[key].interval
        assert lo <= value <= hi, (key, fit.parameters[key].text())
        assert hi - lo < 0.5 * value, (key, fit.parameters[key].text())  # and the interval says something


def test_f_test_finds_the_second_state_only_where_there_is_one():
    def reading(rec: LabRecord, states: int) -> Reading:
        fit = fit_record(rec, law="aging", states=states, protocol=HISTORY, noise=NOISE)
        return Reading("aging", states, fit, NOISE, float(np.ptp(rec.friction)))

    two = record("aging", TWO, seed=4)
    one_fit, two_fit = reading(two, 1), reading(two, 2)
    assert one_fit.fit.reduced_chi_square > 3  # one state leaves structure behind ...
    assert one_fit.lag_one > 0.5 and abs(two_fit.lag_one) < 0.2  # ... correlated residuals; two states: noise
    value, p = f_test(one_fit, two_fit)
    assert p < 1e-10 and value > 50
    assert two_fit.fit.status == "ok", two_fit.fit.reason
    one = record("aging", ((0.01, 20 * UM),), seed=5)
    one_state, spare = reading(one, 1), reading(one, 2)
    _, p_one = f_test(one_state, spare)
    assert p_one > 1e-3  # no second state to find: the two extra parameters buy nothing beyond chance
    # and the two-state fit says so itself (it was "ok", b and b2 each undetermined in a ridge of b + b2)
    assert one_state.fit.status == "ok" and spare.fit.status == "failed"
    assert "second state" in spare.fit.reason and "--states 1" in spare.fit.reason  # (unconstrained, or no F)


def test_mixed_laws_aging_then_slip_are_recovered():
    """One law per state (rsfmodel's mixed two-state fits): aging for the fast state, slip for the slow one.

    (Two-state searches can end in a stiff-rig local minimum, where the stiffness is left unconstrained: on an
    AVX2-only machine this record's first search stopped at k = 5.7e11 1/m, chi-square_r 0.964 against 0.859 at the
    truth, and the fit reported it as ok.  A search that leaves the stiffness unconstrained is now restarted as one
    that leaves Dc so (rsf.fit._troubled); from Dc x 10 it finds k = 1.9e4 1/m, chi-square_r 0.842.)"""
    truth = RSFParams(a=0.012, states=(StateVariable("aging", 0.006, 5 * UM), StateVariable("slip", 0.004, 60 * UM)),
                      mu0=0.6, v_ref=10 * UM, stiffness=2e4)  # fmt: skip
    t = np.arange(0.0, HISTORY.duration + 1e-9, 0.1)
    run = simulate(truth, HISTORY, times=t)
    noisy = run.friction + NOISE * np.random.default_rng(7).standard_normal(t.size)
    rec = LabRecord.from_arrays(t, run.load_point_displacement, noisy, source="synthetic aging + slip")
    fit = fit_record(rec, law=("aging", "slip"), states=2, protocol=HISTORY, noise=NOISE)
    assert fit.status == "ok", fit.reason
    assert [s.law for s in fit.params.states] == ["aging", "slip"]
    at_truth = float(np.sum(((noisy - run.friction) / NOISE) ** 2)) / (t.size - 7)
    assert fit.reduced_chi_square <= at_truth * (1 + 1e-6)  # the search found the minimum, not a point above it
    values = {"a": 0.012, "b": 0.006, "dc": 5 * UM, "b2": 0.004, "dc2": 60 * UM, "stiffness": 2e4}
    for key, value in values.items():
        lo, hi = fit.parameters[key].interval
        assert lo <= value <= hi, (key, fit.parameters[key].text())
    # the second state's law is the slip law's: the fitted parameters run with the aging law there fit worse
    aging = fit.params.replace(states=(fit.params.states[0], StateVariable("aging", *_b_dc(fit.params.states[1]))))
    other = simulate(aging, HISTORY, times=t)
    assert float(np.sum(((noisy - other.friction) / NOISE) ** 2)) / (t.size - 7) > fit.reduced_chi_square + 1.0


def _b_dc(state: StateVariable) -> tuple[float, float]:
    return state.b, state.dc
