"""The critical point of the steady friction curve (Eq 9) and the no-aging turnover.

Eq 9: dsigma/dV0 = 0 at V0 = Vc, the minimum of the aging curve separating the
velocity-weakening left branch from the velocity-strengthening right branch.
The no-aging curve has no such minimum but turns over at a few mm/s (for
gelatin-glass); the jump velocity of the stick-slip cycle is sought below
that maximum.

Method: dsigma/dV (computed analytically under the integral, see
:mod:`stickslip.model.steady`) is sampled on a log grid of velocities; each
sign change is refined by Brent's method on log V.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..numerics.roots import brentq  # scipy.optimize would add 0.3 s to start-up
from ..parameters import Parameters
from .steady import ACCURATE_QUADRATURE, steady_state

#: Velocity range searched for extrema, m/s, and the grid density per decade.
SEARCH_RANGE = (1e-9, 1e2)
POINTS_PER_DECADE = 16


@dataclass(frozen=True)
class Extremum:
    velocity: float
    stress: float
    kind: str  # "minimum" or "maximum"


@dataclass(frozen=True)
class CriticalPoint:
    """Vc and sigma_c of Eq 9 (None with a message when the curve has no minimum)."""

    velocity: float | None
    stress: float | None
    exists: bool
    message: str
    turnover_velocity: float | None
    turnover_stress: float | None
    turnover_message: str
    extrema: tuple[Extremum, ...]

    def as_dict(self) -> dict[str, object]:
        return {
            "critical_velocity": self.velocity,
            "critical_stress": self.stress,
            "exists": self.exists,
            "message": self.message,
            "turnover_velocity": self.turnover_velocity,
            "turnover_stress": self.turnover_stress,
            "turnover_message": self.turnover_message,
        }


def find_extrema(
    params: Parameters, aging: bool, search_range: tuple[float, float] = SEARCH_RANGE
) -> tuple[Extremum, ...]:
    """Every local extremum of sigma(V) in ``search_range``, lowest velocity first."""
    lo, hi = search_range
    n = int(np.ceil(np.log10(hi / lo) * POINTS_PER_DECADE)) + 1
    grid = np.geomspace(lo, hi, n)
    slope = steady_state(params, grid, aging=aging, quadrature=ACCURATE_QUADRATURE).stress_slope
    sign = np.sign(slope)
    found = []
    for k in np.nonzero(sign[:-1] * sign[1:] < 0)[0]:

        def g(log_v: float) -> float:
            return float(steady_state(params, np.exp(log_v), aging=aging).stress_slope)

        log_v = brentq(g, np.log(grid[k]), np.log(grid[k + 1]), xtol=1e-13, rtol=1e-13)
        v = float(np.exp(log_v))
        stress = float(steady_state(params, v, aging=aging, quadrature=ACCURATE_QUADRATURE).stress)
        found.append(Extremum(v, stress, "minimum" if slope[k] < 0 else "maximum"))
    return tuple(found)


def _no_minimum_message(params: Parameters, extrema: tuple[Extremum, ...]) -> str:
    """Say in words why there is no Vc, from the slope of the curve at the ends of the range."""
    lo, hi = SEARCH_RANGE
    span = f"between {lo:g} and {hi:g} m/s"
    if not extrema:
        slope = float(steady_state(params, np.sqrt(lo * hi)).stress_slope)
        if slope > 0:
            return (
                f"the steady friction curve with aging rises monotonically {span}: no velocity-weakening branch,"
                " so no critical velocity (steady sliding is stable at every pulling velocity in that range)"
            )
        return (
            f"the steady friction curve with aging falls monotonically {span}: it is velocity-weakening throughout"
            " and has no minimum, so no critical velocity separates stick-slip from steady sliding in that range"
        )
    return (
        f"the steady friction curve with aging has no minimum {span} (only a maximum at"
        f" {extrema[0].velocity:.6g} m/s): the weakening branch lies above it, and there is no critical velocity"
        " in the sense of Eq 9"
    )


def critical_point(params: Parameters) -> CriticalPoint:
    """Vc and sigma_c (Eq 9): the lowest-velocity minimum of the aging curve.

    Also the turnover (maximum) of the no-aging curve.  When a curve has no
    such extremum between 1 nm/s and 100 m/s the field is None and the
    message says so in words.
    """
    extrema = find_extrema(params, aging=True)
    minima = [e for e in extrema if e.kind == "minimum"]
    if minima:
        v, s = minima[0].velocity, minima[0].stress
        message = f"minimum of the aging curve at Vc = {v:.6g} m/s, sigma_c = {s:.6g} Pa"
    else:
        v = s = None
        message = _no_minimum_message(params, extrema)
    maxima = [e for e in find_extrema(params, aging=False) if e.kind == "maximum"]
    if maxima:
        tv, ts = maxima[0].velocity, maxima[0].stress
        turnover_message = f"maximum of the no-aging curve at {tv:.6g} m/s, {ts:.6g} Pa"
    else:
        tv = ts = None
        turnover_message = (
            f"the no-aging curve rises over the whole range {SEARCH_RANGE[0]:g} to {SEARCH_RANGE[1]:g} m/s: no turnover"
        )
    return CriticalPoint(v, s, v is not None, message, tv, ts, turnover_message, extrema)
