"""The stick solver's DOP853 steps on Python floats (stickslip.numerics.dop853, issue 31).

Checked three ways: the integrator alone against a closed form; the stick phase against solve_ivp's DOP853 (the
code before issue 31, kept as ``stick.SOLVER = "solve_ivp"``) over a box of parameters; the dense output
against the closed form of the constant load with aging (docs/stick-phase.md §2.2).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import exp1

import stickslip.quasistatic.stick as stick_module
from stickslip.numerics.dop853 import integrate
from stickslip.parameters import load_parameters, replace
from stickslip.quasistatic.stick import stick_phase


@pytest.fixture(scope="module")
def params():
    return load_parameters("gelatin-glass")


def test_integrator_on_a_field_with_a_closed_form():
    # g = n/2: n' = n/2 - 1, n(0) = 1 -> n = 2 - e^{theta/2}, zero at theta = 2 ln 2;
    # t' = g = 1 - e^{theta/2}/2 -> t' = theta + 1 - e^{theta/2}
    out = integrate(lambda tp, n: 0.5 * n, (0.0, 1.0), [10.0], lambda *_: False, rtol=1e-11, atol=1e-13)
    assert out.reason == "event"
    assert out.s_end == pytest.approx(2 * math.log(2), rel=1e-12)
    assert out.y_end[0] == pytest.approx(2 * math.log(2) - 1, rel=1e-11)
    assert abs(out.y_end[1]) < 1e-13
    theta = np.linspace(0.0, out.s_end, 97)
    tp, n = out.steps(theta)
    np.testing.assert_allclose(n, 2 - np.exp(theta / 2), rtol=0, atol=1e-11)
    np.testing.assert_allclose(tp, theta + 1 - np.exp(theta / 2), rtol=0, atol=1e-11)
    assert out.steps(0.7) == pytest.approx((0.7 + 1 - math.exp(0.35), 2 - math.exp(0.35)), abs=1e-11)


def test_integrator_stops_at_the_first_positive_decision():
    seen = []

    def decide(theta, tp, n):
        seen.append(theta)
        return theta >= 2.0

    # g = 1: n stays 1 (no event), so only the checkpoints end it
    out = integrate(lambda tp, n: 1.0, (0.0, 1.0), [1.0, 2.0, 3.0], decide, rtol=1e-11, atol=1e-13)
    assert (out.reason, seen) == ("decided", [1.0, 2.0])
    assert out.y_end == pytest.approx((2.0, 1.0), rel=1e-14)
    more = integrate(lambda tp, n: 1.0, out.y_end, [5.0], lambda *_: False, 1e-11, 1e-13, out.s_end, out.steps)
    assert more.reason == "horizon" and more.steps is out.steps and out.steps.end == 5.0


def _box():
    """Stick keys, stiffness, V0 and start stress over decades (seeded), with and without aging."""
    rng = np.random.default_rng(31)
    cases = []
    for _ in range(24):
        stick = {
            "attached_chains": 10 ** rng.uniform(11.5, 13.0),
            "break_rate": 10 ** rng.uniform(-6, -2),
            "aging_time": 10 ** rng.uniform(0, 2),
        }
        block = {"shear_modulus": 10 ** rng.uniform(3, 4.5)}
        velocity = 0.0 if rng.random() < 0.15 else 10 ** rng.uniform(-6, -3)
        start = None if rng.random() < 0.3 else 10 ** rng.uniform(1, 3)
        cases.append((stick, block, velocity, start, bool(rng.random() < 0.8)))
    return cases


@pytest.mark.parametrize(("stick", "block", "velocity", "start", "aging"), _box())
def test_same_answers_as_solve_ivp_over_a_box(params, monkeypatch, stick, block, velocity, start, aging):
    p = replace(params, stick=stick, block=block)
    new = stick_phase(p, velocity, start, aging=aging, horizon=30.0)
    monkeypatch.setattr(stick_module, "SOLVER", "solve_ivp")
    old = stick_phase(p, velocity, start, aging=aging, horizon=30.0)
    assert (new.status, new.message) == (old.status, old.message)
    assert (new.chain_floor is None) == (old.chain_floor is None)
    if old.chain_floor is not None:
        assert new.chain_floor == pytest.approx(old.chain_floor, rel=1e-10)
    if old.stick_time is not None:
        assert new.stick_time == pytest.approx(old.stick_time, rel=1e-10)
        assert new.peak_stress == pytest.approx(old.peak_stress, rel=1e-10)
    span = old.time[-1]
    np.testing.assert_allclose(new.time, old.time, rtol=0, atol=1e-9 * span)
    np.testing.assert_allclose(new.chain_fraction, old.chain_fraction, rtol=0, atol=1e-9)
    probe = 0.37 * span
    assert new.chain_fraction_at(probe) == pytest.approx(old.chain_fraction_at(probe), abs=1e-9)


def test_dense_output_follows_the_closed_form_with_aging(params):
    # held at a constant load with aging, t(n) = -tau_a ln(1 - (E1(s0) - E1(s0/n))/(r tau_a)) (§2.2); r chosen
    # so that the chains collapse at tau_a ln 2
    sigma = 600.0
    b, nc0, tau_a = params.bonds.force_sensitivity, params.stick.attached_chains, params.stick.aging_time
    s0 = b * sigma / nc0
    r = exp1(s0) / (tau_a * 0.5)
    phase = stick_phase(replace(params, stick={"break_rate": r}), 0.0, sigma)
    assert phase.status == "slipped"
    assert phase.stick_time == pytest.approx(tau_a * math.log(2), rel=1e-11)
    n = phase.chain_fraction[1:-1]
    expected = -tau_a * np.log1p(-(exp1(s0) - exp1(s0 / n)) / (r * tau_a))
    np.testing.assert_allclose(phase.time[1:-1], expected, rtol=0, atol=1e-8 * phase.stick_time)
    for t in (0.1, 2.0, 5.0, 6.9):
        n_t = phase.chain_fraction_at(t)
        t_back = -tau_a * math.log1p(-(exp1(s0) - exp1(s0 / n_t)) / (r * tau_a))
        assert t_back == pytest.approx(t, rel=1e-8)
