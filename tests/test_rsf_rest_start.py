"""A sampled piece that starts at its own stable steady sliding: written at rest, not left to LSODA's stall.

docs/rsf.md, "A piece that starts at rest": where f(y0) is rounding alone on a stiff slider, odeint kept its first
step (sqrt(rtol) x the first output time) for the whole piece, ten million evaluations.  Each check here is against
an independent Radau integration at rtol 1e-12, or counts odeint's own evaluations.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
import scipy.integrate
from scipy.integrate import solve_ivp

from stickslip.protocols import Protocol, Segment
from stickslip.rsf import simulate
from stickslip.rsf.params import RSFParams, StateVariable
from stickslip.rsf.solver import _at_rest
from stickslip.rsf.system import System

RTOL, ATOL = 1e-8, 1e-10  # a fit's tolerances (FIT_RTOL)

#: the sepiolite velstep2 window 11200-12500 s, fitted with a free stiffness: its found first level (1.99450 um/s)
#: moved down by its uncertainty, as the fit's level covariance moves it (the fit's own rows: every 0.136 s)
FOUND = RSFParams(a=0.0020586336328802923, states=(StateVariable(law="aging", b=-0.008966699606007184,
                  dc=2.586968201389546e-05),), mu0=0.4906861752370119, v_ref=1.9945029471392276e-06,
                  stiffness=5354037.186531586)  # fmt: skip
MOVED = Protocol(
    (Segment(1.9936145932838744e-06, 137.15492841896696), Segment(1.999504031601645e-07, 1162.733071581034))
)


def _radau(system: System, y0: np.ndarray, t0: float, t1: float, vlp: float, times: np.ndarray) -> Any:
    sol = solve_ivp(system.rhs, (t0, t1), y0, method="Radau", args=(vlp,), jac=system.jacobian, rtol=1e-12,
                    atol=1e-14, t_eval=times, dense_output=True)  # fmt: skip
    assert sol.status == 0
    return sol


@pytest.fixture
def evaluations(monkeypatch):
    """odeint's evaluations, summed over the calls a run makes (its own count, ``full_output``'s nfe)."""
    counted = [0]
    plain = scipy.integrate.odeint

    def counting(*args, **kwargs):
        out = plain(*args, **{**kwargs, "full_output": True})
        counted[0] += int(out[1]["nfe"][-1])
        return out if kwargs.get("full_output") else out[0]

    monkeypatch.setattr(scipy.integrate, "odeint", counting)
    return counted


@pytest.mark.parametrize("mean", [False, True], ids=["fit", "simulate"])
def test_the_found_level_moved_by_its_error_runs_in_hundreds_of_evaluations_and_matches_radau(evaluations, mean):
    times = np.arange(0.0, 1299.8, 0.136)
    run = simulate(FOUND, MOVED, times=times, rtol=RTOL, atol=ATOL, detect=False, mean=mean)
    assert run.status == "ok"
    assert evaluations[0] < 5000, evaluations[0]  # 10,085,866 before (14.8 s)
    system = System(FOUND)
    (v1, d1), (v2, _) = [(s.velocity, s.duration) for s in MOVED.segments]
    first = times[times <= d1]
    one = _radau(system, system.steady_y(MOVED.segments[0].velocity), 0.0, d1, v1, first)
    end = d1 + MOVED.segments[1].duration
    two = _radau(system, one.sol(d1), d1, end, v2, times[times > d1])
    y = np.c_[one.y, two.y]
    friction = np.array([system.friction(x, [p]) for x, p in y.T])
    assert np.max(np.abs(run.friction - friction)) < 1e-9
    assert np.allclose(run.slider_velocity, FOUND.v_ref * np.exp(y[0]), rtol=1e-7, atol=0)
    if mean:  # the carried integral of mu dt: mu(y0) over the rest piece, then the step's relaxation
        rest_mu = system.friction(*system.steady_y(v1)[:1], system.steady_y(v1)[1:])

        def with_integral(t, y, vlp):  # (quad on the dense output misses the step's 0.2 ms first transient)
            return [*system.rhs(t, y[:2], vlp), system.friction(y[0], y[1:2])]

        relaxation = solve_ivp(with_integral, (d1, end), np.r_[one.sol(d1), 0.0], method="Radau", args=(v2,),
                               rtol=1e-12, atol=1e-14).y[-1, -1]  # fmt: skip
        assert run.run_mean_friction == pytest.approx((rest_mu * d1 + relaxation) / end, rel=1e-9)


def test_random_stable_rest_starts_are_the_radau_solution_within_a_thousandth_of_the_tolerance(evaluations):
    """Stiff one-state sliders (k 1e3-1e8 1/m, both laws, a - b of either sign) started at their loading velocity's
    own steady state, the reference velocity 1 % away: before, 10 of 300 such draws took 10-20 million evaluations."""
    rng = np.random.default_rng(1)
    grid = np.arange(0.0, 137.2, 0.136)
    checked = 0
    for _ in range(40):
        a = 10 ** rng.uniform(-3.5, -1.5)
        b, dc, k = a * rng.uniform(-3, 3), 10 ** rng.uniform(-7, -4), 10 ** rng.uniform(3, 8)
        law = str(rng.choice(["aging", "slip"]))
        params = RSFParams(a=a, states=(StateVariable(law=law, b=b, dc=dc),), mu0=0.5, v_ref=2e-6, stiffness=k)
        vlp = 2e-6 * (1 + rng.uniform(-0.01, 0.01))
        system = System(params)
        y0 = system.steady_y(vlp)
        if not _at_rest(system, y0, vlp, RTOL, ATOL):
            continue
        evaluations[0] = 0
        run = simulate(params, Protocol((Segment(vlp, 137.2),)), times=grid, rtol=RTOL, atol=ATOL, detect=False)
        assert evaluations[0] == 0  # written at rest
        ref = _radau(system, y0, 0.0, 137.2, vlp, grid)
        scale = RTOL * np.abs(ref.y) + ATOL
        assert np.max(np.abs(np.log(run.slider_velocity / 2e-6) - ref.y[0]) / scale[0]) < 1e-3
        assert run.run_mean_friction == pytest.approx(system.friction(y0[0], y0[1:]), rel=1e-14)
        checked += 1
    assert checked >= 30, checked


def test_an_unstable_equilibrium_a_velocity_step_and_a_carried_integral_are_not_at_rest():
    """Below the critical stiffness rounding seeds the growth the solver must follow; a step's first slope is
    far from rounding; the solver's carried q (dq/dt = mu) is never at rest, only the system beneath it."""
    unstable = RSFParams(
        a=0.002, states=(StateVariable(law="aging", b=0.0043, dc=2.8e-7),), mu0=0.5, v_ref=2e-6, stiffness=1739.0
    )  # fmt: skip  kc = (b - a)/Dc = 8200 1/m
    system = System(unstable)
    assert not _at_rest(system, system.steady_y(2.01e-6), 2.01e-6, RTOL, ATOL)
    stable = System(FOUND)
    assert _at_rest(stable, stable.steady_y(1.99e-6), 1.99e-6, RTOL, ATOL)
    assert not _at_rest(stable, stable.steady_y(1.99e-6), 2.2e-6, RTOL, ATOL)
