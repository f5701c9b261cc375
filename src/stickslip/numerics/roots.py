"""Brent's method for a bracketed root, in plain Python.

Why not ``scipy.optimize.brentq``: importing ``scipy.optimize`` takes about
0.3 s (it pulls in scipy.linalg, scipy.sparse and more), which is most of the
start-up time of ``stickslip critical``.  The algorithm is the same one
(Brent 1973, in the variant scipy uses: secant or inverse quadratic
interpolation, accepted only when the step is short enough, bisection
otherwise), so that the iterates, and the roots the model reports, are the
same floating-point numbers; tests/test_roots.py compares the two bit for bit.
"""

from __future__ import annotations

import math
from collections.abc import Callable

#: Smallest relative tolerance that makes sense in double precision (scipy's limit too).
MIN_RTOL = 4 * 2.220446049250313e-16


def brentq(
    f: Callable[[float], float],
    a: float,
    b: float,
    xtol: float = 2e-12,
    rtol: float = MIN_RTOL,
    maxiter: int = 100,
) -> float:
    """A root of ``f`` between ``a`` and ``b`` (``f(a)`` and ``f(b)`` of opposite signs).

    Converged when the bracket is narrower than ``xtol + rtol*|x|``.  Raises
    ValueError for a bracket without a sign change or a NaN value of ``f``,
    and RuntimeError after ``maxiter`` steps (as scipy's brentq does).
    """
    if xtol <= 0:
        raise ValueError(f"xtol too small ({xtol:g} <= 0)")
    if rtol < MIN_RTOL:
        raise ValueError(f"rtol too small ({rtol:g} < {MIN_RTOL:g})")
    x_old, x = float(a), float(b)
    f_old, fx = _value(f, x_old), _value(f, x)
    if f_old * fx > 0:
        raise ValueError("f(a) and f(b) must have different signs")
    if f_old == 0:
        return x_old
    if fx == 0:
        return x
    x_far = f_far = 0.0  # the other end of the bracket
    step_old = step = 0.0
    for _ in range(maxiter):
        if f_old * fx < 0:  # the sign changed on the last step: the old point is the far end now
            x_far, f_far = x_old, f_old
            step_old = step = x - x_old
        if abs(f_far) < abs(fx):  # keep the better of the two ends as the current estimate
            x_old, x, x_far = x, x_far, x
            f_old, fx, f_far = fx, f_far, fx
        tolerance = (xtol + rtol * abs(x)) / 2
        half = (x_far - x) / 2
        if fx == 0 or abs(half) < tolerance:
            return x
        step_old, step = _next_step(x_old, f_old, x, fx, x_far, f_far, step_old, step, half, tolerance)
        x_old, f_old = x, fx
        x += step if abs(step) > tolerance else (tolerance if half > 0 else -tolerance)
        fx = _value(f, x)
    raise RuntimeError(f"Brent's method did not converge in {maxiter} iterations")


def _next_step(
    x_old: float,
    f_old: float,
    x: float,
    fx: float,
    x_far: float,
    f_far: float,
    step_old: float,
    step: float,
    half: float,
    tolerance: float,
) -> tuple[float, float]:
    """(previous step, next step): an interpolated step where it is safely short, else bisection."""
    if abs(step_old) > tolerance and abs(fx) < abs(f_old):
        if x_old == x_far:  # two distinct points: secant
            trial = -fx * (x - x_old) / (fx - f_old)
        else:  # three points: inverse quadratic interpolation
            slope_old = (f_old - fx) / (x_old - x)
            slope_far = (f_far - fx) / (x_far - x)
            trial = -fx * (f_far * slope_far - f_old * slope_old) / (slope_far * slope_old * (f_far - f_old))
        limit = abs(step_old) if abs(step_old) < 3 * abs(half) - tolerance else 3 * abs(half) - tolerance
        if 2 * abs(trial) < limit:
            return step, trial
    return half, half


def _value(f: Callable[[float], float], x: float) -> float:
    value = float(f(x))
    if math.isnan(value):
        raise ValueError(f"The function value at x={x} is NaN; solver cannot continue.")
    return value
