"""Slip phase (Eq 10) and the jump (Eq 8 at sigma_s).

Independent references:
* a curve with a closed-form slip time, sigma = sigma_c + A ln^2(V/Vc) at V0 = 0;
* mpmath quadrature (30 digits) of t = int sigma'/(K (v - V0)) dv and of int v sigma'/(K (v - V0)) dv
  for the same curve at every kind of V0 (far, near, on the path, above the start);
* Eq 10 itself: dt/dV from the trajectory against sigma'(V)/(K (V0 - V)) from steady_state;
* the direct steady curve instead of the cached branch series (a second path through the code);
* the local laws near the end: V - Vc ~ sqrt(t_end - t) at Vc, V - V0 ~ exp(-K t/sigma'(V0)) at V0 > Vc;
* the paper's Table 1 (Vs = 702 um/s at sigma_s ~ 553 Pa) and Fig 5d (V ends at Vc, or at V0 = 350 um/s).
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from stickslip.errors import ModelError, ParameterError
from stickslip.quasistatic.jump import branch_interpolant, jump_velocity
from stickslip.quasistatic.slip import SETTLE_TOLERANCE, slip_duration, slip_phase, slip_trajectory, steady_curve
from stickslip.quasistatic.steady import steady_state

VC, SC, A, K = 124e-6, 257.0, 180.0, 3.0e5  # the analytic test curve and stiffness
MP_DIGITS = 30


def log_square_curve(v):
    v = np.asarray(v, dtype=float)
    u = np.log(v / VC)
    return SC + A * u * u, 2.0 * A * u / v


def mp_reference(v0, v_start, v_stop=None, gap=None):
    """(time, slider displacement) of the slip on the analytic curve, by mpmath quadrature.

    The slip ends at ``v_stop`` or, with ``gap``, at V0 (1 + gap) in 30-digit arithmetic.
    """
    with mpmath.workdps(MP_DIGITS):
        v0m = mpmath.mpf(v0)
        if gap is not None:
            v_stop = v0m * (1 + mpmath.mpf(gap))

        def slope(v):
            return 2 * A * mpmath.log(v / VC) / v

        def dt(v):
            return slope(v) / (K * (v - v0m))

        lo, hi = sorted((mpmath.mpf(v_start), mpmath.mpf(v_stop)))  # v_stop may carry more digits
        # split geometrically towards V0 when the pole is next to the path
        points = [lo, hi]
        if v0 > 0 and min(abs(lo - v0m), abs(hi - v0m)) < (hi - lo) / 10:
            near = lo if abs(lo - v0m) < abs(hi - v0m) else hi
            offsets = [(hi - lo) * mpmath.mpf(10) ** -k for k in range(1, 12)]
            inner = [near + o if near == lo else near - o for o in offsets if o > abs(near - v0m)]
            points = sorted(set([lo, hi, *inner]))
        sign = 1 if mpmath.mpf(v_start) > v_stop else -1
        t = sign * mpmath.quad(dt, points)
        x = sign * mpmath.quad(lambda v: v * dt(v), points)
        return float(t), float(x)


# --- the quadrature on curves with known integrals ------------------------------------------------------


def test_closed_form_slip_time_at_zero_pulling_velocity():
    vs = 5.6 * VC
    traj = slip_trajectory(log_square_curve, K, 0.0, vs, VC)
    u = math.log(vs / VC)
    expected = 2.0 * A / (K * VC) * (1.0 - (1.0 + u) * math.exp(-u))
    assert traj.duration == pytest.approx(expected, rel=1e-12)
    assert traj.end_slider_displacement == pytest.approx(A * u * u / K, rel=1e-12)


@pytest.mark.parametrize(
    ("v0", "v_start", "v_stop"),
    [
        (0.2 * VC, 6 * VC, VC),  # far pole: direct integration
        (0.7 * VC, 6 * VC, VC),  # pole below Vc but close: subtracted
        (0.999 * VC, 6 * VC, VC),  # pole next to the end
        (2.0 * VC, 6 * VC, SETTLE_TOLERANCE),  # relaxation to V0 from above (a gap, not a velocity)
        (5.0 * VC, 1.3 * VC, -SETTLE_TOLERANCE),  # acceleration to V0 from below
    ],
)
def test_slip_trajectory_against_mpmath(v0, v_start, v_stop):
    if v_stop < 1e-3:  # a relative gap to V0
        traj = slip_trajectory(log_square_curve, K, v0, v_start, end_gap=v_stop)
        t_ref, x_ref = mp_reference(v0, v_start, gap=v_stop)
    else:
        traj = slip_trajectory(log_square_curve, K, v0, v_start, v_stop)
        t_ref, x_ref = mp_reference(v0, v_start, v_stop)
    assert traj.duration == pytest.approx(t_ref, rel=1e-11)
    assert traj.end_slider_displacement == pytest.approx(x_ref, rel=1e-10)
    # and half way (in ln V)
    mid = 0.5 * (traj.log_start + traj.log_end)
    t_mid, _ = mp_reference(v0, v_start, math.exp(mid))
    assert float(traj.time(mid)) == pytest.approx(t_mid, rel=1e-10)


# --- the model's slip phase ----------------------------------------------------------------------------------


def test_eq_10_holds_along_the_slip(params):
    slip = slip_phase(params, 50e-6, 700e-6)
    traj = slip.trajectory
    x = np.linspace(traj.log_start, traj.log_end, 9)[1:-1]
    h = 1e-5
    dt_dx = (traj.time(x + h) - traj.time(x - h)) / (2 * h)
    v = np.exp(x)
    eq10 = steady_state(params, v).stress_slope * v / (params.block.effective_stiffness * (50e-6 - v))
    assert np.allclose(dt_dx, eq10, rtol=1e-7)


@pytest.mark.parametrize("v0", [0.0, 50e-6, 100e-6, 120e-6, 350e-6])
def test_cached_branch_agrees_with_the_direct_steady_curve(params, critical, v0):
    vs = 700e-6
    slip = slip_phase(params, v0, vs)
    k_eff = params.block.effective_stiffness
    if v0 < critical.velocity:
        direct = slip_trajectory(steady_curve(params), k_eff, v0, vs, critical.velocity)
    else:
        direct = slip_trajectory(steady_curve(params), k_eff, v0, vs, end_gap=SETTLE_TOLERANCE)
    assert slip.duration == pytest.approx(direct.duration, rel=1e-9)
    assert slip.slider_displacement[-1] == pytest.approx(direct.end_slider_displacement, rel=1e-9)


def test_slip_ends_at_vc_in_finite_time_with_a_square_root(params, critical):
    slip = slip_phase(params, 50e-6, 702e-6)
    assert slip.ends == "stick"
    assert slip.end_velocity == critical.velocity
    assert slip.end_stress == pytest.approx(critical.stress, abs=1e-9)
    assert 1.0 < slip.duration < 10.0  # "slip durations of a few seconds"
    # dV/dt -> -infinity: V - Vc ~ sqrt(t_end - t)
    traj = slip.trajectory
    dx = np.array([1e-4, 1e-5])
    v = np.exp(traj.log_end + dx)
    left = slip.duration - traj.time(traj.log_end + dx)
    slope = math.log((v[0] - critical.velocity) / (v[1] - critical.velocity)) / math.log(left[0] / left[1])
    assert slope == pytest.approx(0.5, abs=2e-3)


def test_slip_settles_at_v0_above_vc_exponentially(params):
    slip = slip_phase(params, 350e-6, 800e-6)
    assert slip.ends == "steady"
    sigma_350 = float(steady_state(params, 350e-6).stress)
    assert slip.end_stress == pytest.approx(sigma_350, rel=1e-8)
    assert sigma_350 == pytest.approx(391.5, abs=0.05)
    # late in the relaxation V - V0 decays with the time constant sigma'(V0)/K
    k_eff = params.block.effective_stiffness
    tau = float(steady_state(params, 350e-6).stress_slope) / k_eff
    traj = slip.trajectory
    gaps = np.array([1e-6, 1e-7])
    t = traj.time(np.log(350e-6 * (1 + gaps)))
    assert (t[1] - t[0]) / math.log(10.0) == pytest.approx(tau, rel=1e-5)


def test_slip_from_below_v0_accelerates(params):
    slip = slip_phase(params, 350e-6, 200e-6)
    assert slip.ends == "steady"
    assert np.all(np.diff(slip.velocity) > 0)
    assert slip.end_velocity == pytest.approx(350e-6, rel=2 * SETTLE_TOLERANCE)


def test_bookkeeping_of_the_slip(params):
    v0 = 50e-6
    slip = slip_phase(params, v0, 702e-6)
    k_eff = params.block.effective_stiffness
    sigma = steady_state(params, slip.velocity).stress
    # the stress on the trace is the steady curve's, and int V dt = V0 t - (sigma - sigma_s)/K
    assert np.max(np.abs(slip.stress - sigma)) < 1e-8
    expected = v0 * slip.time - (sigma - sigma[0]) / k_eff
    assert np.max(np.abs(slip.slider_displacement - expected)) < 1e-9 * slip.slider_displacement[-1]
    # and against a plain trapezoid rule over the trace (second order, so a loose tolerance)
    trapezoid = np.concatenate([[0.0], np.cumsum(0.5 * (slip.velocity[1:] + slip.velocity[:-1]) * np.diff(slip.time))])
    assert trapezoid[-1] == pytest.approx(slip.slider_displacement[-1], rel=1e-4)


def test_slip_at_any_time_is_on_the_trajectory(params):
    slip = slip_phase(params, 100e-6, 705e-6)
    v, s, x = slip.at(0.5 * slip.duration)
    assert float(slip.trajectory.time(math.log(v))) == pytest.approx(0.5 * slip.duration, rel=1e-12)
    assert s == pytest.approx(float(steady_state(params, v).stress), abs=1e-8)
    assert 0 < x < slip.slider_displacement[-1]


def test_result_frame_and_plot(params):
    slip = slip_phase(params, 50e-6, 702e-6)
    assert list(slip.to_frame().columns) == ["time", "velocity", "stress", "slider_displacement"]
    assert np.all(np.diff(slip.time) > 0) and np.all(np.diff(slip.velocity) < 0)
    assert slip.plot().get_lines()


def test_bad_slip_input(params, critical):
    with pytest.raises(ParameterError, match="start_velocity"):
        slip_phase(params, 50e-6, 0.5 * critical.velocity)
    with pytest.raises(ParameterError, match="pulling_velocity"):
        slip_phase(params, -1e-6, 700e-6)
    with pytest.raises(ModelError, match="maximum of the steady curve"):
        slip_phase(params, 6e-3, 700e-6)


# --- the jump -------------------------------------------------------------------------------------------------


def test_jump_lands_on_the_aging_curve_at_table_1_velocity(params):
    jump = jump_velocity(params, 552.95)
    assert jump.reachable and jump.curve == "aging"
    assert float(steady_state(params, jump.velocity).stress) == pytest.approx(552.95, abs=1e-8)
    assert jump.velocity == pytest.approx(702e-6, abs=1e-6)  # Table 1: 702 um/s


def test_jump_on_the_no_aging_curve(params):
    jump = jump_velocity(params, 552.95, curve="no-aging")
    assert float(steady_state(params, jump.velocity, aging=False).stress) == pytest.approx(552.95, abs=1e-8)
    assert jump.velocity == pytest.approx(751e-6, abs=1e-6)  # the issue: ~751 um/s


def test_table_1_800_pa_is_not_760_um_per_s(params):
    """Table 1 pairs sigma_s = 800 Pa with Vs = 760 um/s; both curves put 800 Pa at ~1.64-1.65 mm/s."""
    for curve, expected in (("aging", 1.643e-3), ("no-aging", 1.651e-3)):
        jump = jump_velocity(params, 800.0, curve=curve)
        assert jump.velocity == pytest.approx(expected, rel=1e-3)
        assert abs(jump.velocity - 760e-6) > 800e-6


def test_unreachable_jumps_say_so(params, critical):
    high = jump_velocity(params, 1200.0)
    low = jump_velocity(params, 0.9 * critical.stress)
    for jump in (high, low):
        assert not jump.reachable and jump.velocity is None and "no jump velocity" in jump.message
    assert "above" in high.message and "below" in low.message
    with pytest.raises(ParameterError, match="jump curve"):
        jump_velocity(params, 500.0, curve="linear")
    with pytest.raises(ParameterError, match="stress"):
        jump_velocity(params, float("nan"))


def test_a_slip_of_a_few_parts_per_million_next_to_vc(params, critical):
    # sigma' ~ 0 all along: the Chebyshev series must stop at the curve's own accuracy, not chase zeros
    vs = critical.velocity * (1 + 3e-5)
    slip = slip_phase(params, 1e-7, vs)
    noise = branch_interpolant(params, "aging").noise  # the direct curve is no worse than the series
    k_eff = params.block.effective_stiffness
    direct = slip_trajectory(steady_curve(params), k_eff, 1e-7, vs, critical.velocity, noise=noise)
    assert slip.ends == "stick" and slip.duration > 0
    assert slip.duration == pytest.approx(direct.duration, rel=1e-6)


@pytest.mark.parametrize(("pull", "start"), [(1e-4, 711e-6), (300e-6, 700e-6), (50e-6, 800e-6)])
def test_slip_duration_is_the_slip_phases_own(params, pull, start):
    """The cost estimate's shortcut (docs/transient.md section 14): how the slip ends and when, as slip_phase."""
    full = slip_phase(params, pull, start)
    assert slip_duration(params, pull, start) == (full.ends, full.duration)
