"""The critical point of the steady friction curve (Eq 9) and the no-aging turnover.

dsigma/dV (analytic, :mod:`stickslip.quasistatic.steady`) is sampled on a log grid; each sign change clear of the
quadrature noise is refined by Brent's method on the same function and kept only when it is verified to be an
extremum of the converged curve (docs/steady-state.md section 7).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from dataclasses import dataclass
from functools import lru_cache
from itertools import pairwise
from typing import Any

import numpy as np

from ..errors import ModelError
from ..numerics.roots import brentq  # scipy.optimize would add 0.3 s to start-up
from ..parameters import BlockParameters, Parameters, StickParameters
from ..reprs import compact_repr, field_values
from .steady import ACCURATE_QUADRATURE, marches_compiled, require_parameters, steady_state

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

    __repr__ = compact_repr  # counts, not hundreds of array elements

    velocity: float | None
    stress: float | None
    exists: bool
    message: str
    turnover_velocity: float | None
    turnover_stress: float | None
    turnover_message: str
    extrema: tuple[Extremum, ...]

    def as_dict(self) -> dict[str, object]:
        turnover = field_values(self, "exists message turnover_velocity turnover_stress turnover_message")
        return {"critical_velocity": self.velocity, "critical_stress": self.stress, **turnover}

    def to_frame(self) -> Any:
        """One row: Vc [m/s], sigma_c [Pa], whether they exist, the turnover and the messages (units in
        ``attrs["units"]``, as every result's frame)."""
        import pandas as pd

        from ..columns import with_units

        frame = pd.DataFrame([self.as_dict()])
        return with_units(frame, {"exists": None, "turnover_message": None})

    def plot(self, ax: Any = None) -> Any:
        """The curve's extrema in the (log V, sigma) plane, Vc and sigma_c labelled: on their own, or over a
        steady curve (``point.plot(ax=curve.plot())``); where there is no minimum, the message in the frame.
        Returns the Axes (never shows the figure)."""
        from ..plots.steady import plot_critical

        return plot_critical(self, ax=ax)


#: Relative accuracy of sigma and of V dsigma/dV with ACCURATE_QUADRATURE, with margin: slopes below this
#: (times sigma) are noise, and a minimum must be deeper than this to count.
NOISE = 1e-9
#: At most this many sign changes are refined (more means the curve is noise, not extrema).
MAX_EXTREMA = 8


def _curve(
    params: Parameters, velocity: np.ndarray | float, aging: bool, compiled: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """(sigma, V dsigma/dV) with the accurate quadrature: the same function on the grid and in the root search
    (its march compiled at every width where ``compiled``)."""
    state = steady_state(
        params,
        np.atleast_1d(velocity),
        aging=aging,
        quadrature=ACCURATE_QUADRATURE,
        compiled_from=1 if compiled else None,
    )
    stress, log_slope = state.stress, state.stress_slope * state.velocity
    if not (np.all(np.isfinite(stress)) and np.all(np.isfinite(log_slope))):
        raise ModelError(
            "the steady friction curve is not finite between"
            f" {float(np.min(velocity)):.3g} and {float(np.max(velocity)):.3g} m/s for these parameters"
        )
    return stress, log_slope


def _significant_signs(stress: np.ndarray, log_slope: np.ndarray) -> np.ndarray:
    """+1/-1 where V dsigma/dV stands clear of the quadrature noise, 0 where the curve is flat to it."""
    sign = np.sign(log_slope)
    sign[np.abs(log_slope) <= NOISE * np.abs(stress)] = 0.0
    return sign


@lru_cache(maxsize=128)
def _refine(params: Parameters, aging: bool, lo: float, hi: float, compiled: bool = False) -> tuple[float, float]:
    """(ln V, sigma) at the zero of V dsigma/dV between ln V = lo and hi (Brent), or at the better end if the signs
    disagree.  Each point is evaluated once: Brent asks for the ends again, and the root it returns is one of its
    points (a third of the scalar steady states of a search saved, the same numbers).  Remembered, as
    :func:`_grid_signs`: the whole point after Vc alone (:func:`critical_minimum`, what a transient run asks first)
    refines the minimum once."""
    seen: dict[float, tuple[float, float]] = {}

    def at(log_v: float) -> tuple[float, float]:
        if log_v not in seen:
            stress, log_slope = _curve(params, math.exp(log_v), aging, compiled)
            seen[log_v] = (float(stress[0]), float(log_slope[0]))
        return seen[log_v]

    def g(log_v: float) -> float:
        return at(log_v)[1]

    g_lo, g_hi = g(lo), g(hi)
    if g_lo == 0.0:
        root = lo
    elif g_hi == 0.0:
        root = hi
    elif g_lo * g_hi > 0.0:  # cannot happen with the grid's own values; never let brentq raise
        root = lo if abs(g_lo) < abs(g_hi) else hi
    else:
        root = float(brentq(g, lo, hi, xtol=1e-12, rtol=1e-13, maxiter=200))
    return root, at(root)[0]


def find_extrema(
    params: Parameters, aging: bool, search_range: tuple[float, float] = SEARCH_RANGE, *, compiled: bool = False
) -> tuple[Extremum, ...]:
    """Every local extremum of sigma(V) in ``search_range`` that the converged curve resolves, lowest first.

    The slope is sampled on a log grid; each change of sign (ignoring slopes
    within NOISE of zero) is refined by Brent's method on the same
    function, and kept only if the stress there is below (minimum) or above
    (maximum) both ends of its bracket by more than NOISE: a verified
    extremum of the converged curve, not a flicker of quadrature noise.

    ``compiled`` runs every steady state of the search on the compiled march (numba), ~15x cheaper a search
    once numba is loaded; the extrema agree with the numpy march's to ~1e-13 (tests/test_critical_compiled.py).
    For a caller that searches many curves in one process (a fit, a study); a single search stays on numpy,
    which costs less than loading numba (docs/steady-state.md, "Wide batches run compiled").
    """
    return tuple(_extrema(params, aging, search_range, ("minimum", "maximum"), compiled or marches_compiled()))


def _extrema(
    params: Parameters,
    aging: bool,
    search_range: tuple[float, float],
    kinds: tuple[str, ...],
    compiled: bool = False,
) -> Iterator[Extremum]:
    """The verified extrema of :func:`find_extrema` of the ``kinds`` asked for, lowest velocity first, each
    refined only when asked for (a bracket refined costs ~10 scalar steady states, the grid one call)."""
    require_parameters(params)
    grid, stress, sign = _grid_signs(params, aging, *search_range, compiled)
    clear = np.nonzero(sign)[0]
    changes = [(a, b) for a, b in pairwise(clear) if sign[a] != sign[b]]
    for a, b in changes[:MAX_EXTREMA]:
        kind = "minimum" if sign[a] < 0 else "maximum"
        if kind not in kinds:
            continue
        log_v, s = _refine(params, aging, math.log(grid[a]), math.log(grid[b]), compiled)
        depth = (min(stress[a], stress[b]) - s) if kind == "minimum" else (s - max(stress[a], stress[b]))
        if depth > NOISE * abs(s):
            yield Extremum(math.exp(log_v), s, kind)


@lru_cache(maxsize=32)
def _grid_signs(
    params: Parameters, aging: bool, lo: float, hi: float, compiled: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(grid, sigma, significant sign of the slope) of :func:`_extrema`'s search grid, read-only (remembered)."""
    n = int(np.ceil(np.log10(hi / lo) * POINTS_PER_DECADE)) + 1
    grid = np.geomspace(lo, hi, n)
    stress, log_slope = _curve(params, grid, aging, compiled)
    found = grid, stress, _significant_signs(stress, log_slope)
    for array in found:
        array.setflags(write=False)
    return found


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
    message says so in words.  Computed once per steady curve: the point
    depends only on the bond and aging parameters, and a report, a fit or a
    plot asks for the same one several times (~30 ms each).
    """
    require_parameters(params)  # before the cache: a dict is unhashable
    return cached_critical_point(steady_curve_key(params), marches_compiled())


_ANY_STICK = StickParameters(1.0, 1.0, 1.0)
_ANY_BLOCK = BlockParameters(1.0, 1.0, 1.0, 1.0)


def steady_curve_key(params: Parameters) -> Parameters:
    """``params`` with all but the bonds and aging sections replaced by fixed values: the cache key of the curve.

    The steady curve (Eqs 6-8), its critical point and its branch depend on nothing else, so a sweep over the
    block's stiffness or the stick parameters (or a renamed set) reuses them instead of solving them again.
    """
    return dataclasses.replace(params, stick=_ANY_STICK, block=_ANY_BLOCK, name="", description="", reference="")


@lru_cache(maxsize=32)
def cached_critical_point(params: Parameters, compiled: bool = False) -> CriticalPoint:
    """The critical point of one steady curve; callers pass :func:`steady_curve_key` (the one cache of the point)
    and ``compiled``, :func:`~stickslip.quasistatic.steady.marches_compiled` (its steady states on the compiled
    march)."""
    extrema = find_extrema(params, aging=True, compiled=compiled)
    minima = [e for e in extrema if e.kind == "minimum"]
    if minima:
        v, s = minima[0].velocity, minima[0].stress
        message = f"minimum of the aging curve at Vc = {v:.6g} m/s, σc = {s:.6g} Pa"
    else:
        v = s = None
        message = _no_minimum_message(params, extrema)
    maxima = [e for e in find_extrema(params, aging=False, compiled=compiled) if e.kind == "maximum"]
    if maxima:
        tv, ts = maxima[0].velocity, maxima[0].stress
        turnover_message = f"maximum of the no-aging curve at {tv:.6g} m/s, {ts:.6g} Pa"
    else:
        tv = ts = None
        turnover_message = (
            f"the no-aging curve rises over the whole range {SEARCH_RANGE[0]:g} to {SEARCH_RANGE[1]:g} m/s: no turnover"
        )
    return CriticalPoint(v, s, v is not None, message, tv, ts, turnover_message, extrema)


def critical_minimum(params: Parameters, *, compiled: bool = False) -> Extremum | None:
    """Vc and sigma_c alone (Eq 9), as :func:`critical_point` finds them, or None where the aging curve has no
    minimum: the same numbers at about half the cost, for a study that needs nothing else of the point (the
    curve's maximum and the no-aging turnover are neither refined nor searched).  ``compiled``: as in
    :func:`find_extrema` (the same point to ~1e-13)."""
    require_parameters(params)
    return _cached_minimum(steady_curve_key(params), compiled or marches_compiled())


@lru_cache(maxsize=32)
def _cached_minimum(params: Parameters, compiled: bool = False) -> Extremum | None:
    return next(_extrema(params, True, SEARCH_RANGE, ("minimum",), compiled), None)
