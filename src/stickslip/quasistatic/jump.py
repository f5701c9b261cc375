"""The jump from stick to slip: the velocity Vs at which the steady curve carries sigma_s (Eqs 8, 16).

The stress is continuous through the jump, so Vs is the root of sigma(Vs) = sigma_s on the right branch between
Vc and the curve's maximum, of the aging curve by default (``curve="no-aging"``: the paper's Section 3); an
unreachable jump is said in the result.  The branch is a Chebyshev series in ln V, computed once per parameter set
(:func:`branch_interpolant`); Brent's method finds the root (docs/slip-phase.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..errors import ModelError, ParameterError
from ..numerics.chebyshev import chebval  # numpy's, bit for bit, on floats for one point
from ..numerics.roots import brentq  # scipy's Brent bit for bit (tests/test_roots.py), without scipy.optimize
from ..numerics.transforms import dct1  # scipy.fft's, bit for bit, without its ~0.3 s import
from ..parameters import Parameters
from ..reprs import field_values
from .critical import CriticalPoint, cached_critical_point, steady_curve_key
from .steady import ACCURATE_QUADRATURE, marches_compiled, require_parameters, steady_state

CURVES = ("aging", "no-aging")

#: Chebyshev series: relative size of the trailing coefficients accepted as converged.
CHEBYSHEV_TOLERANCE = 1e-12
#: The same for V dsigma/dV: the quadrature's slope carries ~1e-10 relative noise (issue 12: asking 1e-12
#: of it made ordinary sets fail with "did not converge").
SLOPE_TOLERANCE = 1e-9
CHEBYSHEV_START = 32
#: Branches with a sharp maximum (strong aging) need ~700 points; 4097 leaves room.
CHEBYSHEV_MAX = 4096


# --------------------------------------------------------------------------- Chebyshev tools
def chebyshev_points(n: int) -> np.ndarray:
    """The n+1 Chebyshev points of the second kind, cos(pi j/n), from +1 down to -1."""
    return np.cos(np.pi * np.arange(n + 1) / n)


def chebyshev_coefficients(values: np.ndarray) -> np.ndarray:
    """Chebyshev coefficients of the interpolant through values at :func:`chebyshev_points` (last axis)."""
    n = values.shape[-1] - 1
    c = dct1(values) / n
    c[..., 0] /= 2.0
    c[..., -1] /= 2.0
    return c


def _converged(coefficients: np.ndarray, tol: np.ndarray | float, floor: np.ndarray | float) -> bool:
    tail = max(2, coefficients.shape[-1] // 8)
    scale = np.max(np.abs(coefficients), axis=-1)
    return bool(np.all(np.max(np.abs(coefficients[..., -tail:]), axis=-1) <= tol * scale + floor + 1e-300))


def adaptive_chebyshev(
    sample: Callable[[np.ndarray], np.ndarray],
    lo: float,
    hi: float,
    tol: np.ndarray | float = CHEBYSHEV_TOLERANCE,
    start: int = CHEBYSHEV_START,
    largest: int = CHEBYSHEV_MAX,
    floor: np.ndarray | float = 0.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Chebyshev interpolation on [lo, hi] of the rows of ``sample(x) -> (m, len(x))``, doubling until converged.

    Converged when the trailing coefficients of every row are below ``tol``
    (per row, or one for all) times its largest one plus ``floor`` (per row: the absolute noise of the
    samples, below which coefficients mean nothing).  Returns (x nodes,
    values (m, n+1), coefficients (m, n+1)).  The grids are nested, so
    doubling samples only the new points.
    """
    n = start
    x = 0.5 * (lo + hi) + 0.5 * (hi - lo) * chebyshev_points(n)
    values = np.atleast_2d(sample(x))
    while True:
        coefficients = chebyshev_coefficients(values)
        if _converged(coefficients, tol, floor):
            return x, values, coefficients
        if 2 * n > largest:
            raise ModelError(
                f"the steady curve varies too sharply between ln V = {lo:.6g} and {hi:.6g} to be followed with"
                f" {largest + 1} Chebyshev points"
            )
        n *= 2
        x = 0.5 * (lo + hi) + 0.5 * (hi - lo) * chebyshev_points(n)
        new = np.empty((values.shape[0], n + 1))
        new[:, ::2] = values
        new[:, 1::2] = np.atleast_2d(sample(x[1::2]))
        values = new


def to_unit(x: np.ndarray | float, lo: float, hi: float) -> np.ndarray:
    """Map [lo, hi] onto the Chebyshev interval [-1, 1]."""
    return (2.0 * np.asarray(x, dtype=float) - lo - hi) / (hi - lo)


# --------------------------------------------------------------------------- the steady curve, cached
def require_critical_point(params: Parameters, compiled: bool | None = None) -> CriticalPoint:
    """The critical point, or a ModelError saying why stick-slip is undefined without it (``compiled``: as
    :func:`~stickslip.quasistatic.critical.cached_critical_point`'s; None: :func:`marches_compiled`)."""
    require_parameters(params)  # before the cache: a dict is unhashable
    compiled = marches_compiled() if compiled is None else compiled
    cp = cached_critical_point(steady_curve_key(params), compiled)
    if not cp.exists:
        raise ModelError(f"no stick-slip cycle: {cp.message}")
    return cp


def branch_maximum(params: Parameters, curve: str, compiled: bool | None = None) -> tuple[float, float]:
    """(velocity, stress) where the right branch of ``curve`` ends: the curve's maximum above Vc (``compiled``: as
    :func:`require_critical_point`'s)."""
    cp = require_critical_point(params, compiled)
    assert cp.velocity is not None
    if curve == "aging":
        maxima = [e for e in cp.extrema if e.kind == "maximum" and e.velocity > cp.velocity]
        if maxima:
            return maxima[0].velocity, maxima[0].stress
    if cp.turnover_velocity is not None and cp.turnover_stress is not None:
        return cp.turnover_velocity, cp.turnover_stress
    v_top = 1e2  # the end of the critical-point search: the branch rises all the way
    return v_top, float(steady_state(params, v_top, aging=curve == "aging", quadrature=ACCURATE_QUADRATURE).stress)


#: The aging branch's series reaches this far below Vc, so that the slip phase can subtract a pole at
#: any V0 in [BELOW_VC * Vc, Vc) (see :mod:`stickslip.quasistatic.slip`).
BELOW_VC = 0.5


@dataclass(frozen=True)
class BranchInterpolant:
    """sigma(V) and g = V dsigma/dV on the right branch of a steady curve, as Chebyshev series in ln V.

    The series span [ln(BELOW_VC Vc), ln V_max] (or from nearer Vc, see
    :func:`branch_interpolant`) for the aging curve and
    [ln Vc, ln V_max] for the no-aging curve; ``log_vc`` marks Vc.
    """

    curve_name: str
    log_lo: float
    log_hi: float
    log_vc: float
    stress_series: np.ndarray
    g_series: np.ndarray

    def _u(self, velocity: np.ndarray | float) -> np.ndarray:
        return to_unit(np.log(velocity), self.log_lo, self.log_hi)

    def stress(self, velocity: np.ndarray | float) -> np.ndarray:
        return chebval(self._u(velocity), self.stress_series)

    def slope(self, velocity: np.ndarray | float) -> np.ndarray:
        """dsigma/dV."""
        return chebval(self._u(velocity), self.g_series) / np.asarray(velocity, dtype=float)

    def __call__(self, velocity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(sigma, dsigma/dV): the curve in the form the slip phase takes."""
        return self.stress(velocity), self.slope(velocity)

    @property
    def noise(self) -> tuple[float, float]:
        """Absolute accuracy of the series of sigma and of g (the convergence level they were built to)."""
        return (
            CHEBYSHEV_TOLERANCE * float(np.max(np.abs(self.stress_series))),
            SLOPE_TOLERANCE * float(np.max(np.abs(self.g_series))),
        )


def curve_branch(params: Parameters, curve: str) -> BranchInterpolant:
    """:func:`branch_interpolant` of ``params``'s steady curve (its cache key, :func:`steady_curve_key`) on the march
    in use (:func:`marches_compiled`)."""
    return branch_interpolant(steady_curve_key(params), curve, marches_compiled())


@lru_cache(maxsize=32)
def branch_interpolant(params: Parameters, curve: str, compiled: bool = False) -> BranchInterpolant:
    """The branch series of ``curve``, computed once per parameter set (cached; ``compiled``: its steady states on
    the compiled march, :func:`marches_compiled` at the callers)."""
    cp = require_critical_point(params, compiled)
    assert cp.velocity is not None
    v_max, _ = branch_maximum(params, curve, compiled)
    aging = curve == "aging"
    hi = math.log(v_max)

    def sample(x: np.ndarray) -> np.ndarray:
        v = np.exp(x)
        state = steady_state(
            params, v, aging=aging, quadrature=ACCURATE_QUADRATURE, compiled_from=1 if compiled else None
        )
        return np.array([state.stress, state.stress_slope * v])

    # Below Vc the aging curve can fall off a near-vertical cliff (issue 12: sigma dropping 1e6-fold within
    # 0.5 % of V): reach less far below Vc then (the slip phase checks how far the series reaches).
    reaches = (BELOW_VC, 0.9, 0.99, 1.0) if aging else (1.0,)
    for k, below in enumerate(reaches):
        lo = math.log(cp.velocity * below)
        try:
            _, _, c = adaptive_chebyshev(sample, lo, hi, tol=np.array([CHEBYSHEV_TOLERANCE, SLOPE_TOLERANCE]), start=64)
            break
        except ModelError:
            if k == len(reaches) - 1:
                raise ModelError(
                    f"the {curve} curve's right branch, from Vc = {cp.velocity:.6g} to {v_max:.6g} m/s, varies too"
                    f" sharply to be followed with {CHEBYSHEV_MAX + 1} Chebyshev points, so the slip phase cannot be"
                    " solved for these parameters"
                ) from None
    return BranchInterpolant(curve, lo, hi, math.log(cp.velocity), c[0], c[1])


# --------------------------------------------------------------------------- the jump
@dataclass(frozen=True)
class Jump:
    """The jump velocity Vs where the steady ``curve`` carries ``stress`` (None when unreachable)."""

    stress: float
    velocity: float | None
    reachable: bool
    curve: str
    message: str
    lowest_stress: float  # the branch's stress at Vc
    highest_stress: float  # the branch's maximum

    def as_dict(self) -> dict[str, object]:
        return {"stress": self.stress, "jump_velocity": self.velocity, **field_values(self, "reachable curve message")}


def check_curve(curve: str) -> str:
    if curve not in CURVES:
        raise ParameterError(f"jump curve: expected one of {', '.join(CURVES)}, got {curve!r}")
    return curve


def jump_velocity(params: Parameters, stress: float, curve: str = "aging") -> Jump:
    """Vs with sigma(Vs) = ``stress`` (Pa) on the right branch of the steady ``curve`` (Eq 8).

    ``curve`` is ``"aging"`` (default: the curve the slip then follows, so the
    stress is continuous) or ``"no-aging"`` (Eq 8 as written in Section 3).
    """
    from ..units import refused_as_written, si_argument

    check_curve(curve)
    with refused_as_written(stress):
        stress = si_argument(stress, "stress", "stress")
        if isinstance(stress, bool) or not isinstance(stress, (int, float, np.floating)) or not math.isfinite(stress):
            raise ParameterError(f"stress: expected a finite number in Pa, got {stress!r}")
        if stress < 0:  # a friction stress on the steady curve is >= 0 (a negative one was "below the branch")
            raise ParameterError(f"stress: expected a stress >= 0 in Pa, got {float(stress)!r}")
    stress = float(stress)
    cp = require_critical_point(params)
    assert cp.velocity is not None
    v_max, s_max = branch_maximum(params, curve)
    s_low = (
        cp.stress
        if curve == "aging"
        else float(steady_state(params, cp.velocity, aging=False, quadrature=ACCURATE_QUADRATURE).stress)
    )
    assert s_low is not None
    if not s_low <= stress <= s_max:
        where = "below" if stress < s_low else "above"
        return Jump(
            stress,
            None,
            False,
            curve,
            f"σ = {stress:.6g} Pa is {where} the stresses {s_low:.6g}-{s_max:.6g} Pa of the {curve} curve's"
            f" right branch (Vc = {cp.velocity:.6g} m/s to its maximum at {v_max:.6g} m/s): no jump velocity",
            s_low,
            s_max,
        )
    branch = curve_branch(params, curve)

    def excess(x: float) -> float:
        return float(branch.stress(math.exp(x))) - stress

    if excess(branch.log_vc) >= -branch.noise[0]:  # at sigma_c itself (to the series' accuracy)
        log_v = branch.log_vc
    elif excess(branch.log_hi) <= 0.0:
        log_v = branch.log_hi
    else:
        log_v = brentq(excess, branch.log_vc, branch.log_hi, xtol=1e-14, rtol=4 * np.finfo(float).eps)
    velocity = math.exp(log_v)
    return Jump(
        stress,
        velocity,
        True,
        curve,
        f"the {curve} curve carries {stress:.6g} Pa at Vs = {velocity:.6g} m/s",
        s_low,
        s_max,
    )
