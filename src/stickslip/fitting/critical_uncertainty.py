"""Uncertainty of the critical point (Vc, sigma_c of Eq 9) of a fitted curve.

Three methods: ``delta`` (first-order propagation through the implicit function and envelope theorems),
``profile`` (the profile likelihood with the constraint dsigma/dV(v) = 0) and ``bootstrap`` (refits of data
simulated from the fitted curve, :mod:`stickslip.fitting.steady_fit`); how each works and how it was checked:
docs/fitting.md.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import brentq, least_squares

from ..errors import ModelError, ParameterError
from ..parameters import Parameters
from ..quasistatic.critical import critical_point
from ..quasistatic.steady import steady_state
from .batch import overflow_is_failure, stress_many
from .problem import FAILED_RESIDUAL, JACOBIAN_STEP, SEARCH_BOX, Block, Space

#: Weight of the constraint residuals of the profile (dimensionless elasticity dln sigma/dln V): the
#: constrained minimum then sits within ~3e-4 (relative) of the trial velocity, far inside the 2 %
#: tolerance of the interval ends, while Levenberg-Marquardt converges in tens of steps (a weight of
#: 1e3 needs several times more).
CONSTRAINT_WEIGHT = 1e2
#: Half-width, in ln V, of the bracket searched around a previous Vc by the local solver.
LOCAL_BRACKET = 1.5
#: Newton steps and their finite-difference half-width (in ln V) of :func:`critical_many`.
NEWTON_STEPS = 3
NEWTON_DELTA = 1e-4
#: Constrained refits allowed for one end of a profile interval, the relative tolerance on the
#: signed root there, and how far (in ln) from the estimate an end is looked for.
PROFILE_STEPS = 12
PROFILE_TOLERANCE = 0.02
PROFILE_REACH = math.log(100.0)
#: Stiffness of the profile's sigma_c constraint against the data: its weight is this many times the data
#: chi-square's own curvature along ln sigma_c (the delta method's), so a constrained refit lands within
#: 1/(1 + STRESS_STIFFNESS^2) ~ 1 % of the way back to the best fit.  CONSTRAINT_WEIGHT alone let it land
#: ~60 % of the way back when the data pin sigma_c to better than 1 % (issue: sigma_c profile 2.3x too wide).
STRESS_STIFFNESS = 10.0


def _steady(params: Parameters, velocity: Any, aging: bool = True) -> Any:
    """steady_state on the compiled march at any width: locating Vc repeats narrow calls (the fit's Jacobians
    have loaded numba already)."""
    return steady_state(params, velocity, aging=aging, compiled_from=1)


def local_critical(params: Parameters, guess: float) -> tuple[float, float] | None:
    """(Vc, sigma_c) near ``guess``: a slope sign change on a log grid refined by Brent's method.

    Falls back to the global search of :func:`critical_point` when the bracket
    holds no minimum; None when the curve has none at all.
    """
    grid = guess * np.exp(np.linspace(-LOCAL_BRACKET, LOCAL_BRACKET, 13))
    try:
        slope = _steady(params, grid).stress_slope
    except (ModelError, ParameterError):
        return None
    ups = np.nonzero((slope[:-1] < 0) & (slope[1:] >= 0))[0]
    if ups.size == 0:
        point = critical_point(params)
        return (point.velocity, point.stress) if point.exists else None
    k = ups[np.argmin(np.abs(np.log(grid[ups] / guess)))]

    def g(log_v: float) -> float:
        return float(_steady(params, math.exp(log_v)).stress_slope)

    log_v = brentq(g, math.log(grid[k]), math.log(grid[k + 1]), xtol=1e-10)
    v = math.exp(log_v)
    return v, float(_steady(params, v).stress)


def critical_many(params_list: list[Parameters], guess: float) -> np.ndarray:
    """(Vc, sigma_c) of many parameter sets near ``guess``, shape (n, 2); NaN rows where none is found.

    The stress of all sets on one log grid (spacing 0.1 in ln V, one batched
    evaluation) brackets each minimum; the vertex of the parabola through the
    three lowest points starts Newton's method on dsigma/d ln V = 0 with the
    model's analytic slope (two steps: quadratic convergence from ~1e-3).
    Sets whose minimum is not inside the grid go to :func:`local_critical`.
    """
    grid_ln = math.log(guess) + np.linspace(-LOCAL_BRACKET, LOCAL_BRACKET, 31)
    stress = stress_many(params_list, np.exp(grid_ln))
    out = np.full((len(params_list), 2), np.nan)
    h = grid_ln[1] - grid_ln[0]
    for n, params in enumerate(params_list):
        row = stress[n]
        if not np.all(np.isfinite(row)):
            continue
        k = int(np.argmin(row))
        if k == 0 or k == row.size - 1:
            found = local_critical(params, guess)
            if found is not None:
                out[n] = found
            continue
        curvature = row[k - 1] - 2 * row[k] + row[k + 1]
        log_v = grid_ln[k] + 0.5 * h * (row[k - 1] - row[k + 1]) / curvature
        try:
            for _ in range(NEWTON_STEPS):
                trio = _steady(params, np.exp(log_v + np.array([-NEWTON_DELTA, 0.0, NEWTON_DELTA])))
                g = trio.stress_slope * trio.velocity  # dsigma/d ln V
                step = g[1] * 2 * NEWTON_DELTA / (g[2] - g[0])
                log_v -= float(np.clip(step, -h, h))
            v = math.exp(log_v)
            out[n] = (v, float(_steady(params, v).stress))
        except (ModelError, ParameterError):
            continue
    return out


def critical_gradient(space: Space, theta: np.ndarray, vc: float) -> tuple[np.ndarray, np.ndarray]:
    """(d ln Vc/d theta, d ln sigma_c/d theta) by the implicit function theorem (module docstring)."""
    h = JACOBIAN_STEP
    params = space.params(theta)
    around = _steady(params, np.array([vc * math.exp(-h), vc * math.exp(h)]))
    curvature = (around.stress_slope[1] - around.stress_slope[0]) / (2 * h)  # d slope/d ln V
    grad_v = np.empty(theta.size)
    grad_s = np.empty(theta.size)
    for k in range(theta.size):
        step = np.zeros_like(theta)
        step[k] = h
        up = _steady(space.params(theta + step), vc)
        down = _steady(space.params(theta - step), vc)
        grad_v[k] = -(float(up.stress_slope) - float(down.stress_slope)) / (2 * h) / curvature
        grad_s[k] = (math.log(float(up.stress)) - math.log(float(down.stress))) / (2 * h)
    return grad_v, grad_s


@dataclass(frozen=True)
class ProfileEnd:
    value: float | None  # ln of the end; None: not bounded by the data within PROFILE_REACH
    evaluations: int
    converged: bool


class Profile:
    """Constrained refits of the joint chi-square for profile-likelihood intervals.

    Residuals are the data's plus heavily weighted constraints: the
    elasticity dln sigma/dln V at the trial velocity v must vanish (v is the
    minimum), and for sigma_c also ln sigma(v) = ln s with ln v free.
    Jacobians are central differences with all perturbed sets evaluated in
    one batch (:func:`stress_many`); the elasticity there is a central
    difference in ln V (step NEWTON_DELTA), the residual itself uses the
    model's analytic slope.
    """

    def __init__(
        self, space: Space, block: Block, centre: np.ndarray, stress_weight: float = CONSTRAINT_WEIGHT
    ) -> None:
        self.space = space
        self.block = block
        # weight of the constraint ln sigma(v) = ln s: see STRESS_STIFFNESS (never below CONSTRAINT_WEIGHT)
        weight = float(stress_weight)
        self.stress_weight = max(weight, CONSTRAINT_WEIGHT) if math.isfinite(weight) else CONSTRAINT_WEIGHT
        self.lower = centre - SEARCH_BOX
        self.upper = centre + SEARCH_BOX
        self.evaluations: list[tuple[int, int]] = []

    # -- residuals -----------------------------------------------------------------
    def _state(self, theta: np.ndarray, v: float) -> tuple[np.ndarray, float, float] | None:
        try:
            with overflow_is_failure():
                state = _steady(self.space.params(theta), np.append(self.block.eval_points, v), aging=True)
        except (ModelError, ParameterError):
            return None
        stress = float(state.stress[-1])
        return state.stress[:-1], stress, float(state.stress_slope[-1]) * v / stress

    def data_chi_square(self, theta: np.ndarray) -> float:
        got = self._state(theta, float(self.block.velocity[0]))
        if got is None:
            return math.inf
        return self.block.chi_square(self.block.residuals_of(got[0]))

    def _residual(self, theta: np.ndarray, log_v: float, log_s: float | None) -> np.ndarray:
        extra = 1 if log_s is None else 2
        got = self._state(theta, math.exp(log_v))
        if got is None:
            return np.full(self.block.residual_count + extra, FAILED_RESIDUAL)
        model, stress, elasticity = got
        r = self.block.residuals_of(model)
        constraints = [CONSTRAINT_WEIGHT * elasticity]
        if log_s is not None:
            constraints.append(self.stress_weight * (math.log(stress) - log_s))
        return np.append(r, constraints)

    def _jacobian(self, theta: np.ndarray, log_v: float, log_s: float | None, with_v: bool) -> np.ndarray:
        h, d = JACOBIAN_STEP, NEWTON_DELTA
        v = math.exp(log_v)
        m = self.block.eval_points.size
        velocity = np.append(self.block.eval_points, v * np.exp([-d, 0.0, d]))
        sets = []
        for k in range(theta.size):
            for sign in (1.0, -1.0):
                shifted = np.array(theta, dtype=float)
                shifted[k] += sign * h
                sets.append(self.space.params(shifted))
        evaluated = stress_many(sets, velocity)
        n = self.block.residual_count
        # residual space for the data part (compressed for long records), then the three stresses around v
        stress = np.concatenate([self.block.weighted(evaluated[:, :m]), evaluated[:, m:]], axis=1)
        rows = n + (1 if log_s is None else 2)
        out = np.zeros((rows, theta.size + (1 if with_v else 0)))
        if not np.all(np.isfinite(stress)):
            return out  # a failed set: a zero column makes the optimiser stay put along it
        elasticity = (stress[:, n + 2] - stress[:, n]) / (2 * d * stress[:, n + 1])
        for k in range(theta.size):
            up, down = 2 * k, 2 * k + 1
            out[:n, k] = (stress[up, :n] - stress[down, :n]) / (2 * h)
            out[n, k] = CONSTRAINT_WEIGHT * (elasticity[up] - elasticity[down]) / (2 * h)
            if log_s is not None:
                out[n + 1, k] = self.stress_weight * (math.log(stress[up, n + 1] / stress[down, n + 1])) / (2 * h)
        if with_v:
            trio = _steady(self.space.params(theta), v * np.exp([-h, h]))
            slopes = trio.stress_slope * trio.velocity / trio.stress
            out[n, -1] = CONSTRAINT_WEIGHT * (slopes[1] - slopes[0]) / (2 * h)
            if log_s is not None:
                out[n + 1, -1] = self.stress_weight * float(np.mean(slopes))  # d ln sigma/d ln v = elasticity
        return out

    # -- constrained minima ----------------------------------------------------------
    def _solve(self, fun: Any, jac: Any, start: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
        # Levenberg-Marquardt copes with the stiff constraint far better than the bounded trust region;
        # the start lies in the box and failed evaluations repel the steps
        x0 = np.clip(start, lower + 1e-9, upper - 1e-9)
        result = least_squares(fun, x0, jac=jac, method="lm")
        self.evaluations.append((result.nfev, result.njev))
        return result.x

    def chi_square_at_velocity(self, log_v: float, start: np.ndarray) -> tuple[float, np.ndarray]:
        """Smallest data chi-square of curves whose minimum is at V = e^log_v, and where it is."""
        x = self._solve(
            lambda th: self._residual(th, log_v, None),
            lambda th: self._jacobian(th, log_v, None, with_v=False),
            start,
            self.lower,
            self.upper,
        )
        return self.data_chi_square(x), x

    def chi_square_at_stress(self, log_s: float, start: np.ndarray) -> tuple[float, np.ndarray]:
        """Smallest data chi-square of curves whose minimum stress is e^log_s (x = theta, ln v)."""
        lower = np.append(self.lower, math.log(1e-12))
        upper = np.append(self.upper, math.log(1e3))
        x = self._solve(
            lambda x: self._residual(x[:-1], x[-1], log_s),
            lambda x: self._jacobian(x[:-1], x[-1], log_s, with_v=True),
            start,
            lower,
            upper,
        )
        return self.data_chi_square(x[:-1]), x

    def attained_stress(self, x: np.ndarray) -> float:
        """ln of the minimum stress of the curve a constrained refit ``x`` = (theta, ln v) ended on.

        The constraint is a weighted residual, not exact: the refit sits a little back towards the best fit,
        and its chi-square belongs to the sigma_c it reached (the profile point), not to the one asked for.
        """
        got = self._state(x[:-1], math.exp(x[-1]))
        return math.nan if got is None else math.log(got[1])

    # -- the ends of an interval -------------------------------------------------------
    def end(
        self,
        chi_at: Callable[[float, np.ndarray], tuple[float, np.ndarray]],
        centre: float,
        start: np.ndarray,
        best_chi: float,
        threshold: float,
        scale: float,
        guess_sd: float,
        side: int,
        attained: Callable[[np.ndarray], float] | None = None,
    ) -> ProfileEnd:
        """Where the signed root sqrt((chi - best)/scale) reaches sqrt(threshold) on ``side`` (+1 or -1).

        Secant steps outwards until the threshold is passed, then regula falsi
        inside the bracket.  Each constrained fit starts from the last point
        found inside; a point that lands outside is refitted from the best fit
        too (the lower chi-square wins), so one bad local minimum cannot end
        the interval early.  ``attained`` maps a refit to the value (in ln) its curve really reached: each
        chi-square is placed there, on the profile, rather than at the value asked for.
        """
        target = math.sqrt(threshold)
        inside: list[tuple[float, float, np.ndarray]] = [(centre, 0.0, start)]
        outside: tuple[float, float] | None = None
        x = centre + side * target * max(guess_sd, 1e-3)
        lag = 0.0  # how far short of the value asked a refit stops (attained): the next request asks that much more
        for n in range(1, PROFILE_STEPS + 1):
            ask = x + lag
            chi, solution = chi_at(ask, inside[-1][2])
            root = math.sqrt(max(chi - best_chi, 0.0) / scale)
            if root > target and len(inside) > 1:
                chi2, solution2 = chi_at(ask, start)
                if chi2 < chi:
                    chi, solution = chi2, solution2
                    root = math.sqrt(max(chi - best_chi, 0.0) / scale)
            if attained is not None:
                reached = attained(solution)
                # a refit that did not move towards x (or crossed back over the centre) keeps x
                if math.isfinite(reached) and side * (reached - centre) > 0:
                    # asked x again, a refit stopping short by the same amount would stall the search there (the
                    # shipped curve's sigma_c: asked 269.41 Pa again and again, each refit stopped at 268.87, until
                    # the steps ran out): the shortfall is carried over, never more than half the way from the centre
                    lag = float(np.clip(ask - reached, -0.5 * abs(reached - centre), 0.5 * abs(reached - centre)))
                    x = reached
            if abs(root - target) <= PROFILE_TOLERANCE * target:
                return ProfileEnd(x, n, True)
            if root < target:
                inside.append((x, root, solution))
            else:
                outside = (x, root)
            x = self._next(inside, outside, target, centre, side)
            if abs(x - centre) > PROFILE_REACH:
                return ProfileEnd(None, n, True)
        if outside is None:
            return ProfileEnd(None, PROFILE_STEPS, False)
        (xi, ri, _), (xo, ro) = inside[-1], outside
        return ProfileEnd(xi + (target - ri) * (xo - xi) / (ro - ri), PROFILE_STEPS, False)

    @staticmethod
    def _next(
        inside: list[tuple[float, float, np.ndarray]],
        outside: tuple[float, float] | None,
        target: float,
        centre: float,
        side: int,
    ) -> float:
        xi, ri, _ = inside[-1]
        if outside is not None:
            xo, ro = outside
            return xi + (target - ri) * (xo - xi) / (ro - ri)
        x0, r0, _ = inside[-2] if len(inside) > 1 else (centre, 0.0, None)
        distance = abs(xi - centre)
        if ri > r0 and xi != x0:
            step = (target - ri) * (xi - x0) / (ri - r0)
            return xi + side * min(abs(step), 3.0 * max(distance, 1e-3))
        return xi + side * 2.0 * max(distance, 1e-3)  # flat so far: look twice as far
