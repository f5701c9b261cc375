"""The reduction's glide ODE integrated by the compiled DOP853 (``transient/glide.py``, issue 31).

Three checks, each independent of the code's own output:

* a closed form: a manifold whose steady stress is linear in ln V with no lag, S = S0 + A ln V, makes the glide
  logistic, dV/dt = (K/A) V (Vp - V); its velocity, births, puller work and dissipation have closed forms (the last
  two by quad at 1e-13 of the logistic's own ln V), and the glide must end where V reaches the table's edge, at a
  time known in closed form;
* scipy: ``solve_ivp(method="DOP853")`` on the same right-hand side and events, with the same first step, must take
  as many steps and end at the same state to 1e-11 (the paper's cycle's glides);
* the first step judged on the velocity alone saves the steps that scipy's own heuristic spent growing a first step
  of 10 ulp of t (the quadratures' atol of 1e-30 counted), and the cycle's numbers stay within the rtol 1e-5 cohorts'.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.polynomial import chebyshev as cheb
from scipy.integrate import quad

import stickslip
from stickslip.protocols import Protocol, Segment
from stickslip.transient import glide as glide_ode
from stickslip.transient import reduction, run_transient


def _linear_manifold(s0: float, a: float, n_frac: float, v_lo: float, v_hi: float) -> reduction.Manifold:
    domain = [math.log(v_lo), math.log(v_hi)]

    def series(coef_in_x: list[float]) -> cheb.Chebyshev:
        # a polynomial in x = ln V expressed on the table's domain
        return cheb.Chebyshev.fit(np.array(domain), np.polyval(coef_in_x[::-1], np.array(domain)), 1, domain=domain)

    stress = series([s0, a])
    zero = series([0.0, 0.0])
    return reduction.Manifold(
        v_lo, v_hi, stress, stress.deriv(), stress.deriv(2), series([n_frac, 0.0]), zero, zero, zero, zero
    )


def test_the_glide_follows_the_logistic_closed_form_and_ends_at_the_tables_edge() -> None:
    s0, a, k, vp, v0 = 300.0, 40.0, 3e5, 200e-6, 100e-6
    n0, tau, n_frac = 1.2e14, 2.24e-4, 0.5
    v_lo, v_hi = 50e-6, 180e-6  # the slider accelerates towards Vp and leaves the table at 180 um/s
    m = _linear_manifold(s0, a, n_frac, v_lo, v_hi)
    stack, off, scl = m.stacked()
    rate = k * vp / a

    def velocity(t: float) -> float:
        return vp / (1.0 + (vp / v0 - 1.0) * math.exp(-rate * t))

    edge = v_hi * (1.0 - 1e-6)
    t_edge = math.log((vp / v0 - 1.0) / (vp / edge - 1.0)) / rate
    sol = glide_ode.solve(
        stack, off, scl, lo=v_lo, hi=v_hi, vp=vp, k_block=k, block=True, n0=n0, tau=tau, tol=3e-5,
        cap=reduction.NEGLECT_CAP, cap_off=reduction.OFF_MANIFOLD, t0=0.0, t_end=5.0,
        y0=np.array([v0, 0.0, 0.0, 0.0]), rtol=1e-10, atol=np.array([1e-9 * v0, 1e-12 * n0, 1e-30, 1e-30]),
    )  # fmt: skip
    assert sol.status == glide_ode.EVENT
    # the time is as good as the velocity (rtol 1e-10) divided by its rate of change there
    slope = rate * edge * (vp - edge) / vp
    assert abs(sol.t[-1] - t_edge) <= 10 * 1e-10 * edge / slope
    assert sol.y[0, -1] == pytest.approx(edge, rel=1e-10)
    times = np.linspace(0.0, sol.t[-1], 37)
    dense = sol.sol(times)
    exact_v = np.array([velocity(t) for t in times])
    assert np.max(np.abs(dense[0] / exact_v - 1.0)) < 1e-9
    # births at the constant steady N; work and dissipation: S(V) Vp and S(V) V integrated along the logistic
    assert np.allclose(dense[1], n0 * (1.0 - n_frac) / tau * times, rtol=1e-10, atol=0.0)
    end = sol.t[-1]
    work = quad(lambda t: (s0 + a * math.log(velocity(t))) * vp, 0.0, end, epsabs=0.0, epsrel=1e-13)[0]
    heat = quad(lambda t: (s0 + a * math.log(velocity(t))) * velocity(t), 0.0, end, epsabs=0.0, epsrel=1e-13)[0]
    assert sol.y[2, -1] == pytest.approx(work, rel=1e-9)
    assert sol.y[3, -1] == pytest.approx(heat, rel=1e-9)


def test_without_an_event_the_glide_reaches_its_end() -> None:
    m = _linear_manifold(300.0, 40.0, 0.5, 50e-6, 400e-6)
    stack, off, scl = m.stacked()
    sol = glide_ode.solve(
        stack, off, scl, lo=50e-6, hi=400e-6, vp=200e-6, k_block=3e5, block=True, n0=1.2e14, tau=2.24e-4,
        tol=3e-5, cap=reduction.NEGLECT_CAP, cap_off=reduction.OFF_MANIFOLD, t0=2.0, t_end=2.5,
        y0=np.array([100e-6, 0.0, 0.0, 0.0]), rtol=1e-10, atol=np.array([1e-13, 1e2, 1e-30, 1e-30]),
    )  # fmt: skip
    assert sol.status == glide_ode.DONE
    assert sol.t[-1] == 2.5
    rate = 3e5 * 200e-6 / 40.0
    assert sol.y[0, -1] == pytest.approx(200e-6 / (1.0 + math.exp(-rate * 0.5)), rel=1e-9)


CYCLE = Protocol((Segment(350e-6, 5.0), Segment(100e-6, 20.0)))


def _cycle_glides(solver: str) -> list[reduction.Glide]:
    """The glides of the paper's cycle (350 -> 100 um/s through the block, stick chains) with one ODE solver."""
    glides: list[reduction.Glide] = []
    original = reduction.glide

    def kept(*args, **kwargs):  # type: ignore[no-untyped-def]
        out = original(*args, **kwargs)
        glides.append(out)
        return out

    reduction.GLIDE_SOLVER = solver
    reduction.glide = kept  # type: ignore[assignment]
    try:
        run_transient(stickslip.load_parameters("gelatin-glass"), CYCLE, start="steady", stick_population=True)
    finally:
        reduction.glide = original  # type: ignore[assignment]
        reduction.GLIDE_SOLVER = "compiled"
    return glides


def test_the_compiled_glide_ends_where_scipys_does() -> None:
    compiled, scipy_ = _cycle_glides("compiled"), _cycle_glides("solve_ivp")
    assert len(compiled) == len(scipy_) >= 2
    for ours, theirs in zip(compiled, scipy_, strict=True):
        assert ours is not None and theirs is not None
        assert ours.rows.shape == theirs.rows.shape  # the same ODE steps (the rows are the steps and 64 more)
        assert ours.done == theirs.done
        assert ours.t == pytest.approx(theirs.t, rel=1e-11, abs=1e-11)
        assert ours.v == pytest.approx(theirs.v, rel=1e-11)
        # (the steps themselves agree to ~1e-7 only: each step's length comes from an error estimate that is a
        # difference of stages, where np.dot's and a loop's rounding differ; the ends agree to 1e-11)
        assert ours.bonded == pytest.approx(theirs.bonded, rel=1e-11)
        # S_eff near the fold, S' -> 0, magnifies the velocity's rounding ~1e5 times
        assert ours.sigma == pytest.approx(theirs.sigma, rel=1e-6)


def test_the_first_step_on_the_velocitys_scale_saves_the_growth_steps(monkeypatch: pytest.MonkeyPatch) -> None:
    ours = _cycle_glides("compiled")
    monkeypatch.setattr(glide_ode, "initial_step", lambda *args, **kwargs: 0.0)  # 0: scipy's own heuristic
    heuristic = _cycle_glides("compiled")
    for a, b in zip(ours, heuristic, strict=True):
        assert a is not None and b is not None
        # the heuristic's first step is 10 ulp of t: it grows tenfold per step for ~14 steps
        assert b.rows.shape[0] - a.rows.shape[0] >= 10
        # the same glide to the reduction's tolerance: where it ends in V, and when (sensitive at the fold)
        assert a.v == pytest.approx(b.v, rel=1e-9)
        assert a.t == pytest.approx(b.t, abs=1e-4)
