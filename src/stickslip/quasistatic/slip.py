"""The slip phase: quasi-static sliding down the steady curve (Eqs 5, 10, 17): dV/dt = -K (V - V0) / sigma'(V).

Below Vc the slip reaches Vc in finite time and the block sticks; above it V relaxes to V0 and the phase ends
within ``SETTLE_TOLERANCE``.  Time and displacement are integrals over V (x = ln V, the pole at V0 subtracted,
Chebyshev series of the aging branch from :func:`stickslip.quasistatic.jump.branch_interpolant`):
docs/slip-phase.md.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.polynomial import Chebyshev
from numpy.polynomial import chebyshev as cheb

from ..columns import attribute_frame
from ..errors import ModelError, ParameterError
from ..numerics.chebyshev import chebval  # numpy's, bit for bit, on floats for one point
from ..numerics.roots import brentq  # scipy's Brent bit for bit (tests/test_roots.py), without scipy.optimize
from ..numerics.transforms import exprel  # scipy.special's, bit for bit, without its import
from ..parameters import Parameters
from ..reprs import compact_repr
from .jump import (
    BELOW_VC,
    adaptive_chebyshev,
    branch_maximum,
    chebyshev_coefficients,
    curve_branch,
    require_critical_point,
    to_unit,
)
from .steady import ACCURATE_QUADRATURE, steady_state
from .stick import check_velocity

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    from matplotlib.axes import Axes

#: V0 >= Vc: the slip ends when |V - V0| <= SETTLE_TOLERANCE * V0 (V only tends to V0).
SETTLE_TOLERANCE = 1e-9
#: Below this fraction of the stopping velocity the pole at V0 is far enough to integrate directly
#: (the aging branch series reaches down to this fraction of Vc).
FAR_POLE = BELOW_VC
#: Chebyshev points to start with: 65 resolve the gelatin-glass branch, so one curve evaluation usually suffices.
START_POINTS = 64
#: Points of the output trajectory: uniform in ln V, and as many uniform in time.
SAMPLES = 160
_FINE = 2000

Curve = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class SlipTrajectory:
    """t, slider displacement and sigma as functions of x = ln V along one slip (Chebyshev series)."""

    __repr__ = compact_repr  # counts, not hundreds of array elements

    stiffness: float
    pulling_velocity: float
    log_start: float
    log_end: float
    lo: float
    hi: float
    time_series: np.ndarray  # K t(x) minus the analytic log part, as a series
    stress_series: np.ndarray  # sigma(x)
    integral_series: np.ndarray  # int_{xs}^{x} g = sigma(x) - sigma(xs), from the quadrature of sigma'
    pole_weight: float  # g0/V0 of the subtracted pole (0 when integrated directly)
    log_pole: float  # x0 = ln V0 (unused when pole_weight is 0)
    nodes: int
    end_offset: float | None = None  # exact ln(V_end/V0) when the end is V0 (1 +- gap)

    def _u(self, x: np.ndarray) -> np.ndarray:
        return to_unit(x, self.lo, self.hi)

    def time(self, x: np.ndarray | float) -> np.ndarray:
        """Time since the jump at which the velocity is e^x."""
        x = np.asarray(x, dtype=float)
        return self._time(x, x - self.log_pole)

    def _time(self, x: np.ndarray, offset: np.ndarray | float) -> np.ndarray:
        # offset = x - x0, passed separately so that the end V0 (1 +- gap) keeps its digits
        smooth = chebval(self._u(x), self.time_series)
        if self.pole_weight != 0.0:
            smooth = smooth + self.pole_weight * (
                (x - self.log_start)
                - np.log(np.abs(np.expm1(offset)))
                + math.log(abs(math.expm1(self.log_start - self.log_pole)))
            )
        return smooth / self.stiffness

    def stress(self, x: np.ndarray | float) -> np.ndarray:
        return chebval(self._u(np.asarray(x, dtype=float)), self.stress_series)

    def slider_displacement(self, x: np.ndarray | float) -> np.ndarray:
        """int V dt since the jump = V0 t - (sigma(x) - sigma(xs))/K, with the sigma difference from int sigma'."""
        return self._slider(np.asarray(x, dtype=float), self.time(x))

    def _slider(self, x: np.ndarray, t: np.ndarray | float) -> np.ndarray:
        integral = chebval(self._u(x), self.integral_series)
        return self.pulling_velocity * t - integral / self.stiffness

    @property
    def duration(self) -> float:
        offset = self.log_end - self.log_pole if self.end_offset is None else self.end_offset
        return float(self._time(np.asarray(self.log_end), offset))

    @property
    def end_slider_displacement(self) -> float:
        return float(self._slider(np.asarray(self.log_end), self.duration))

    def log_velocity_at(self, t: float) -> float:
        """x = ln V at time t since the jump (t(x) is monotone)."""
        if t <= 0.0:
            return self.log_start
        if t >= self.duration:
            return self.log_end
        return brentq(lambda x: float(self.time(x)) - t, self.log_end, self.log_start, xtol=1e-15, rtol=1e-15)


def slip_trajectory(
    curve: Curve,
    stiffness: float,
    pulling_velocity: float,
    start_velocity: float,
    end_velocity: float | None = None,
    end_gap: float | None = None,
    noise: tuple[float, float] = (0.0, 0.0),
    lowest: float = 0.0,
) -> SlipTrajectory:
    """Eq 10 in the V-parametrisation for any smooth steady curve ``curve(v) -> (sigma, dsigma/dV)``.

    The slip runs from ``start_velocity`` to ``end_velocity`` (Vc), or to
    V0 (1 + ``end_gap``) when it settles at V0 (the gap is kept exactly: the
    time grows like ln(1/gap) there).  ``curve`` must be smooth and sigma' of
    one sign between them.  ``noise`` is the absolute accuracy of the curve's
    (sigma, V dsigma/dV): Chebyshev coefficients below it are not asked to
    converge (this matters for a short slip next to Vc, where sigma' ~ 0).
    ``lowest`` is the lowest velocity ``curve`` may be evaluated at (the pole
    at V0 is subtracted only above it).  Exposed separately so that it can be
    checked on curves with known integrals.
    """
    v0, k = pulling_velocity, stiffness
    end_offset = None
    if end_gap is not None:
        end_offset = math.log1p(end_gap)
        end_velocity = v0 * (1.0 + end_gap)
    if end_velocity is None:
        raise ValueError("slip_trajectory: give end_velocity or end_gap")
    xs = math.log(start_velocity)
    xe = math.log(v0) + end_offset if end_offset is not None else math.log(end_velocity)
    subtract = v0 > 0.0 and v0 >= max(FAR_POLE * min(start_velocity, end_velocity), lowest)
    if subtract:
        x0 = math.log(v0)
        lo, hi = min(xs, xe, x0), max(xs, xe, x0)
    else:
        x0 = 0.0
        lo, hi = min(xs, xe), max(xs, xe)
    if hi - lo <= 0.0:
        raise ModelError("slip trajectory of zero length")

    def sample(x: np.ndarray) -> np.ndarray:
        v = np.exp(x)
        sigma, slope = curve(v)
        g = slope * v
        rows = [sigma, g]
        if not subtract:
            rows.append(g / (v0 - v))
        return np.array(rows)

    floor = list(noise)
    if not subtract:  # the row g/(V0 - v)
        floor.append(noise[1] / abs(v0 - math.exp(lo if v0 < math.exp(lo) else hi)))
    x, _, coefficients = adaptive_chebyshev(sample, lo, hi, start=START_POINTS, floor=np.array(floor))
    u_start = float(to_unit(xs, lo, hi))
    half = 0.5 * (hi - lo)
    stress_series = coefficients[0]
    integral_series = cheb.chebint(coefficients[1], lbnd=u_start) * half
    if subtract:
        g_series = Chebyshev(coefficients[1])
        u0 = float(to_unit(x0, lo, hi))
        g0 = float(g_series(u0))
        divided = ((g_series - g0) // Chebyshev([-u0, 1.0])).coef / half  # (g - g0)/(x - x0)
        h = -chebval(to_unit(x, lo, hi), divided) / (v0 * exprel(x - x0))
        time_series = cheb.chebint(chebyshev_coefficients(h), lbnd=u_start) * half
        pole_weight = g0 / v0
    else:
        time_series = cheb.chebint(coefficients[2], lbnd=u_start) * half
        pole_weight = 0.0
    return SlipTrajectory(
        stiffness=k,
        pulling_velocity=v0,
        log_start=xs,
        log_end=xe,
        lo=lo,
        hi=hi,
        time_series=time_series,
        stress_series=stress_series,
        integral_series=integral_series,
        pole_weight=pole_weight,
        log_pole=x0,
        nodes=x.size,
        end_offset=end_offset if subtract else None,
    )


@dataclass(frozen=True)
class SlipPhase:
    """One slip phase (Eq 10).  Arrays in SI units; time from the jump."""

    __repr__ = compact_repr  # counts, not hundreds of array elements

    time: np.ndarray
    velocity: np.ndarray
    stress: np.ndarray
    slider_displacement: np.ndarray
    ends: str  # "stick" (V reached Vc) or "steady" (V settled at V0)
    duration: float
    end_velocity: float
    end_stress: float
    start_velocity: float
    start_stress: float
    pulling_velocity: float
    stiffness: float
    message: str
    trajectory: SlipTrajectory | None = field(default=None, repr=False, compare=False)

    def at(self, t: float) -> tuple[float, float, float]:
        """(velocity, stress, slider displacement) at time ``t`` since the jump."""
        if self.trajectory is None:
            return self.end_velocity, self.end_stress, 0.0
        x = self.trajectory.log_velocity_at(min(max(t, 0.0), self.duration))
        return math.exp(x), float(self.trajectory.stress(x)), float(self.trajectory.slider_displacement(x))

    def to_frame(self) -> pd.DataFrame:
        """time [s], velocity [m/s], stress [Pa], slider_displacement [m]."""
        return attribute_frame(self, "time velocity stress slider_displacement")

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        """V(t) during the slip (Fig 5d); returns the Axes."""
        from ..plots.cycles import plot_slip

        return plot_slip(self, ax=ax, **kwargs)


def steady_curve(params: Parameters) -> Curve:
    """The aging steady curve as ``v -> (sigma, dsigma/dV)``, evaluated afresh at every call.

    :func:`slip_phase` uses the cached branch series instead; this direct form
    is the reference it is tested against.
    """

    def curve(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        state = steady_state(params, v, aging=True, quadrature=ACCURATE_QUADRATURE)
        return state.stress, state.stress_slope

    return curve


def slip_phase(params: Parameters, pulling_velocity: float, start_velocity: float) -> SlipPhase:
    """Solve Eq 10 on the aging curve from ``start_velocity`` (m/s, on the right branch).

    Ends at Vc when V0 < Vc (``ends="stick"``, reached in finite time) or when
    V has settled at V0 >= Vc (``ends="steady"``, within SETTLE_TOLERANCE).
    """
    from ..units import refused_as_written, si_argument

    with refused_as_written(pulling_velocity):
        v0 = check_velocity(si_argument(pulling_velocity, "velocity", "pulling_velocity"))
    with refused_as_written(start_velocity):
        vs = check_velocity(si_argument(start_velocity, "velocity", "start_velocity"), "start_velocity")
    cp = require_critical_point(params)
    assert cp.velocity is not None and cp.stress is not None
    vc = cp.velocity
    stiffness = params.block.effective_stiffness
    ends, v_end, trajectory = _trajectory(params, v0, vs, vc)
    if trajectory is None:
        sigma = float(curve_branch(params, "aging")(np.array([vs]))[0][0])
        return _empty_slip(v0, vs, sigma, stiffness, ends)
    xs, xe = trajectory.log_start, trajectory.log_end
    x = _output_points(trajectory)
    time = trajectory.time(x)
    time[0], x[0], x[-1] = 0.0, xs, xe
    time[-1] = trajectory.duration
    velocity = np.exp(x)
    velocity[-1] = v_end
    stress = trajectory.stress(x)
    if ends == "stick":  # the curve's minimum, known to more digits than the series
        stress[-1] = cp.stress
    slider = trajectory.slider_displacement(x)
    slider[0], slider[-1] = 0.0, trajectory.end_slider_displacement
    duration = float(time[-1])
    end_stress = float(stress[-1])
    message = (
        f"slides from {vs:.6g} m/s down to Vc = {vc:.6g} m/s in {duration:.6g} s, then sticks at {end_stress:.6g} Pa"
        if ends == "stick"
        else f"relaxes from {vs:.6g} m/s to the pulling velocity {v0:.6g} m/s (within {SETTLE_TOLERANCE:g}) in"
        f" {duration:.6g} s: steady sliding at {end_stress:.6g} Pa"
    )
    return SlipPhase(
        time=time,
        velocity=velocity,
        stress=stress,
        slider_displacement=slider,
        ends=ends,
        duration=duration,
        end_velocity=float(velocity[-1]),
        end_stress=end_stress,
        start_velocity=vs,
        start_stress=float(stress[0]),
        pulling_velocity=v0,
        stiffness=stiffness,
        message=message,
        trajectory=trajectory,
    )


def slip_duration(params: Parameters, pulling_velocity: float, start_velocity: float) -> tuple[str, float]:
    """(how the slip ends, its duration in s) of :func:`slip_phase`, the same numbers, without its output points (a
    time-dependent run's cost estimate asks for these two alone: half of slip_phase's CPU is its output)."""
    from ..units import refused_as_written, si_argument

    with refused_as_written(pulling_velocity):
        v0 = check_velocity(si_argument(pulling_velocity, "velocity", "pulling_velocity"))
    with refused_as_written(start_velocity):
        vs = check_velocity(si_argument(start_velocity, "velocity", "start_velocity"), "start_velocity")
    cp = require_critical_point(params)
    assert cp.velocity is not None
    ends, _v_end, trajectory = _trajectory(params, v0, vs, cp.velocity)
    return ends, 0.0 if trajectory is None else trajectory.duration


def _trajectory(params: Parameters, v0: float, vs: float, vc: float) -> tuple[str, float, SlipTrajectory | None]:
    """(how the slip ends, the velocity where it ends, its trajectory; None where the jump lands there) of Eq 10
    on the aging curve from vs, the puller at v0 (both checked against the curve's right branch)."""
    v_max, _ = branch_maximum(params, "aging")
    if v0 >= v_max:
        raise ModelError(
            f"pulling velocity {v0:.6g} m/s is at or above the maximum of the steady curve ({v_max:.6g} m/s):"
            " sliding there is velocity-weakening again and Eq 10 has no quasi-static solution"
        )
    if not vc * (1 - 1e-12) <= vs <= v_max * (1 + 1e-12):
        raise ParameterError(
            f"start_velocity: expected a velocity on the right branch, {vc:.6g} to {v_max:.6g} m/s, got {vs!r}"
        )
    gap = None
    if v0 < vc:
        ends, v_end = "stick", vc
    else:
        ends = "steady"
        gap = math.copysign(SETTLE_TOLERANCE, vs - v0)
        v_end = v0 * (1.0 + gap)
        if abs(vs - v0) <= SETTLE_TOLERANCE * v0:
            v_end, gap = vs, None
    # spectrally accurate, solved once per curve
    curve = curve_branch(params, "aging")
    if abs(math.log(vs / v_end)) < 1e-14:
        return ends, v_end, None
    trajectory = slip_trajectory(
        curve, params.block.effective_stiffness, v0, vs, v_end, end_gap=gap, noise=curve.noise,
        lowest=math.exp(curve.log_lo) * (1 + 1e-12),
    )  # fmt: skip
    return ends, v_end, trajectory


def _empty_slip(v0: float, v: float, sigma: float, stiffness: float, ends: str) -> SlipPhase:
    return SlipPhase(
        time=np.zeros(1),
        velocity=np.array([v]),
        stress=np.array([sigma]),
        slider_displacement=np.zeros(1),
        ends=ends,
        duration=0.0,
        end_velocity=v,
        end_stress=sigma,
        start_velocity=v,
        start_stress=sigma,
        pulling_velocity=v0,
        stiffness=stiffness,
        message="the jump lands where the slip ends: no slip phase",
    )


def _output_points(trajectory: SlipTrajectory) -> np.ndarray:
    """ln V of the output: uniform in ln V, merged with points uniform in time."""
    xs, xe = trajectory.log_start, trajectory.log_end
    fine = np.linspace(xs, xe, _FINE)
    t_fine = trajectory.time(fine)
    t_fine = np.maximum.accumulate(t_fine)  # monotone against rounding
    t_targets = np.linspace(0.0, t_fine[-1], SAMPLES)
    x_time = np.interp(t_targets, t_fine, fine)
    x = np.concatenate([np.linspace(xs, xe, SAMPLES), x_time])
    order = np.argsort(-(x - xe) / (xs - xe))  # from the start to the end
    x = x[order]
    keep = np.concatenate([[True], np.abs(np.diff(x)) > 1e-13 * abs(xs - xe)])
    return x[keep]
