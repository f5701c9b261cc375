"""Fit the saturating-aging extension (docs/extensions.md section 1) to the steady curve and Table 1.

With aging that saturates at age t_s, one bond population gives an N-shaped steady
curve: a maximum at low velocity (the static threshold, where creep gives way to
slip) before the minimum at Vc.  Quasi-statically the block sticks at the
minimum (sigma_c) and slips at the maximum (sigma_s), so Table 1's stick and slip
stresses are two more data for the curve.  Fitted: tau_a, V_a and t_s (ln-values),
on the steady data (weighted by their errors) plus the mean sigma_s and sigma_c of
Table 1's cycles that start from a slip (weighted by their standard errors of the
mean); N0, tau and the rest are held at the input set's values.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..parameters import Parameters
from ..quasistatic.critical import Extremum, find_extrema
from ..quasistatic.steady import steady_state

#: the fitted keys, as natural logarithms of their SI values
KEYS = ("aging.aging_time", "aging.aging_velocity", "aging.saturation_age")
#: where the maximum (creep/slip) and the minimum (Vc) of the N-shaped curve are looked for, m/s
PEAK_RANGE = (1e-8, 6e-5)
MINIMUM_RANGE = (2e-5, 4e-4)
#: residual of a trial set whose curve has no minimum near Vc
FAILED_RESIDUAL = 1e3


@dataclass(frozen=True)
class SaturationFit:
    """Fitted values (SI), 95 % intervals, the fitted set, and the curve's extrema."""

    parameters: Parameters
    values: dict[str, float]
    intervals: dict[str, tuple[float, float]]
    chi_square: float
    dof: int
    peak: Extremum  # the static threshold sigma_s (creep gives way to slip)
    minimum: Extremum  # Vc, sigma_c


def curve_extrema(params: Parameters) -> tuple[Extremum | None, Extremum]:
    """The low-velocity maximum (None if the curve has none) and the minimum of the steady curve with aging.

    The search runs on the compiled march: the fit searches a curve per residual (0.43 s of the report's CPU on
    numpy, ~0.03 s compiled; the extrema agree to ~1e-13)."""
    extrema = find_extrema(params, aging=True, search_range=(PEAK_RANGE[0], MINIMUM_RANGE[1]), compiled=True)
    peaks = [e for e in extrema if e.kind == "maximum" and PEAK_RANGE[0] < e.velocity < PEAK_RANGE[1]]
    minima = [e for e in extrema if e.kind == "minimum" and MINIMUM_RANGE[0] < e.velocity < MINIMUM_RANGE[1]]
    if not minima:
        raise ModelError("saturating aging: the steady curve has no minimum between 20 and 400 µm/s")
    peak = max(peaks, key=lambda e: e.stress) if peaks else None
    return peak, min(minima, key=lambda e: e.stress)


def table1_targets(table: object) -> tuple[float, float, float, float]:
    """(mean sigma_s, its standard error, mean sigma_c, its standard error) of the cycles that start from a slip.

    The first cycle at 100 um/s and the 350 um/s start-up begin from rest (extra aging, the paper says), and
    the 350 um/s row has no sigma_c: both are left out.
    """
    frame = table  # a pandas frame as read by stickslip.fitting.datasets.table1()
    slipped = frame[frame["start_stress"].notna()]  # type: ignore[index]
    first = np.isclose(slipped["pulling_velocity"], 100e-6) & (slipped["cycle"] == 1)
    peaks = slipped.loc[~first, "peak_stress"].to_numpy(float)
    starts = slipped["start_stress"].to_numpy(float)
    return (
        float(peaks.mean()),
        float(peaks.std(ddof=1) / math.sqrt(peaks.size)),
        float(starts.mean()),
        float(starts.std(ddof=1) / math.sqrt(starts.size)),
    )


def fit_saturation(params: Parameters, velocity: np.ndarray, stress: np.ndarray, error: np.ndarray, table: object):  # type: ignore[no-untyped-def]
    """Least squares in ln(tau_a, V_a, t_s); start from ``params`` (which must carry a saturation age)."""
    from scipy.optimize import least_squares
    from scipy.stats import t as student

    if params.aging.saturation_age is None:
        raise ModelError("fit_saturation: start from a set with aging.saturation_age")
    peak_goal, peak_err, min_goal, min_err = table1_targets(table)

    def at(theta: np.ndarray) -> Parameters:
        return params.with_overrides({k: math.exp(v) for k, v in zip(KEYS, theta, strict=True)})

    def residuals(theta: np.ndarray) -> np.ndarray:
        p = at(theta)
        try:
            peak, minimum = curve_extrema(p)
        except ModelError:  # no minimum near Vc: a curve Table 1 rules out; the optimiser steps back
            return np.full(velocity.size + 2, FAILED_RESIDUAL)
        peak_stress = peak.stress if peak is not None else 0.0  # no maximum: the model has no static threshold
        steady = (steady_state(p, velocity).stress - stress) / error
        return np.r_[steady, (peak_stress - peak_goal) / peak_err, (minimum.stress - min_goal) / min_err]

    start = np.log([params.aging.aging_time, params.aging.aging_velocity, params.aging.saturation_age])
    solution = least_squares(residuals, start, diff_step=1e-4, x_scale=1.0)
    chi_square = float(2.0 * solution.cost)
    dof = solution.fun.size - start.size
    try:
        covariance = np.linalg.inv(solution.jac.T @ solution.jac) * max(chi_square / dof, 1.0)
    except np.linalg.LinAlgError:
        raise ModelError(
            "saturating-aging fit failed: the data do not constrain tau_a, V_a and t_s together (singular Jacobian)"
        ) from None
    if dof <= 0 or not np.all(np.isfinite(covariance)):
        raise ModelError(f"saturating-aging fit failed: no covariance ({solution.fun.size} residuals for 3 parameters)")
    half = student.ppf(0.975, dof) * np.sqrt(np.diag(covariance))
    fitted = at(solution.x)
    values = {k: math.exp(v) for k, v in zip(KEYS, solution.x, strict=True)}
    intervals = {k: (math.exp(v - h), math.exp(v + h)) for k, v, h in zip(KEYS, solution.x, half, strict=True)}
    peak, minimum = curve_extrema(fitted)
    if peak is None:
        raise ModelError("saturating aging: the fitted steady curve has no static threshold (no low-velocity maximum)")
    return SaturationFit(fitted, values, intervals, chi_square, dof, peak, minimum)
