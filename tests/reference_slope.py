"""An independent reference for the steady slope dsigma/dV, for the tests.

It shares no code with ``stickslip.quasistatic.steady``: the same vectorised
Dormand-Prince 5(4) integration in an arc-length variable as
``reference_steady.reference_many`` (its DP tables and stepping rules), with
the ln V derivatives carried as extra states of the ODE,

    dH_V/dx = (beta x - 1) e^L,   di_V/dx = -S H_V,   dj_V/dx = -S H_V x/(1-x^2),

(H_V = dH/d ln V; d ln T/d ln V = -1, d alpha/d ln V = -beta = -alpha (1 + V/V_a)), and the
absolute values |S H_V| accumulated beside them as error scales, so that the step control keeps the
derivatives to MANY_RTOL of their own size even where they cross zero.  The slope is then

    dsigma/dV = scale (j_V - (j/D)(birth + i_V)) / (D V),   D = birth + i.

The tests trust it because it agrees with a Richardson-extrapolated central difference in ln V of
``reference_many`` (which knows nothing of derivatives) where the curve is smooth enough for one.
"""

from __future__ import annotations

import math

import numpy as np

from reference_steady import DP_A, DP_B, DP_E, FAST, MAX_STEPS, SLOPE_FLOOR, case_groups

SLOPE_RTOL = 1e-11
#: e-folds of the survival integrated after the hazard has become fast (H_V grows at most like (1+beta) H)
H_STOP_SLOPE = 60.0
#: the relative rounding error of one evaluation of the log-hazard's terms
L_NOISE = 1e-15


def _rates(z, log_t, a, alpha, beta):
    """d/ds of the rows z = (x, y, H, i, j, H_V, i_V, j_V, |i_V|-scale, |j_V|-scale).

    The arc length is reference_many's (one unit of s changes ln y, L and H by about one at most) with
    one more term, so that H_V changes by at most about 1 + |H_V| per unit."""
    x, y, hazard = z[0], np.maximum(z[1], 1e-100), z[2]
    fene = x / (y * (1.0 + x))
    log_h = log_t + a * fene - alpha * x
    slope = a * (1.0 + x * x) / (y * (1.0 + x)) ** 2 - alpha
    log_slope_term = np.log(np.hypot(1.0, slope)) - np.logaddexp(0.0, -(log_h + SLOPE_FLOOR))
    # ... and H_V: with beta ~ 1e11 it grows by O(1) where the hazard is still ~1e-11 (ahead of the FENE cliff)
    log_hv = log_h + np.log(np.abs(beta * x - 1.0) + 1e-300) - np.log1p(np.abs(z[5]))
    log_g = np.logaddexp(np.logaddexp(0.0, -np.log(y)), np.logaddexp(np.logaddexp(log_h, log_hv), log_slope_term))
    speed = np.exp(-log_g)
    rate = np.exp(log_h - log_g)
    survival = np.exp(-hazard - log_g)
    weighted = survival * z[5]
    return np.stack(
        [
            speed,
            -speed,
            rate,
            survival,
            survival * fene,
            (beta * x - 1.0) * rate,
            -weighted,
            -weighted * fene,
            np.abs(weighted),
            np.abs(weighted) * fene,
        ]
    )


def _groups(cases):
    log_t, a, alpha, birth, scale = case_groups(cases)
    velocity = np.array([v for _, v, _ in cases], dtype=float)
    ratio = np.array([v / params.aging.aging_velocity for params, v, _ in cases])
    beta = alpha * (1.0 + ratio)
    return log_t, a, alpha, beta, birth, scale, velocity


def reference_slope_many(cases) -> tuple[np.ndarray, np.ndarray]:
    """(stress, dsigma/dV) arrays for ``cases``, a sequence of (params, velocity, aging)."""
    log_t, a, alpha, beta, birth, scale, velocity = _groups(cases)
    z = _integrate(log_t, a, alpha, beta)
    i, j, i_v, j_v = z[3], z[4], z[6], z[7]
    denom = birth + i
    stress = scale * j / denom
    slope = scale * (j_v - (j / denom) * (birth + i_v)) / denom / velocity
    return stress, slope


def _integrate(log_t, a, alpha, beta) -> np.ndarray:
    n = log_t.size
    out = np.full((10, n), np.nan)
    lane = np.arange(n)
    z = np.zeros((10, n))
    z[1] = 1.0
    h = np.full(n, 1e-3)
    fast_at = np.full(n, np.inf)
    k1 = _rates(z, log_t, a, alpha, beta)
    for _ in range(MAX_STEPS):
        stages = [k1]
        past_end = np.zeros(z.shape[1], dtype=bool)
        for row in DP_A[1:]:
            trial = z + h * sum(coef * k for coef, k in zip(row, stages, strict=False) if coef != 0.0)
            past_end |= trial[1] <= 0.0
            stages.append(_rates(trial, log_t, a, alpha, beta))
        z_new = z + h * sum(coef * k for coef, k in zip(DP_B, stages, strict=True) if coef != 0.0)
        err = h * sum(coef * k for coef, k in zip(DP_E, stages, strict=True) if coef != 0.0)
        size = np.maximum(np.abs(z), np.abs(z_new))
        size[2] = 1.0 + size[2]  # H: absolute (S = e^-H carries the relative error)
        size[5] = size[5] + size[2]  # H_V = beta G - H: at least the scale of H where the two cancel
        size[6] = size[6] + size[8]  # i_V, j_V: the scale of what was summed into them
        size[7] = size[7] + size[9]
        # ahead of the FENE cliff L is a difference of terms ~1e11, so e^L carries a rounding noise ~1e-5 that
        # no step can beat: the errors of H_V and what it feeds are measured beyond that noise times their increments
        y = np.maximum(z[1], 1e-100)
        noise = L_NOISE * (np.abs(log_t) + a * z[0] / (y * (1.0 + z[0])) + alpha * z[0])
        tolerance = SLOPE_RTOL * size + 1e-300
        tolerance[5:] += noise * np.abs(z_new[5:] - z[5:])
        ratio = np.max(np.abs(err) / tolerance, axis=0)
        ratio[past_end | (z_new[1] <= 0.0)] = 1e10
        accept = ratio <= 1.0
        z = np.where(accept, z_new, z)
        k1 = np.where(accept, stages[-1], k1)
        h = h * np.clip(0.9 * np.maximum(ratio, 1e-10) ** -0.2, 0.2, 5.0)
        x, y = z[0], z[1]
        log_h = log_t + a * x / (y * (1.0 + x)) - alpha * x
        slope = a * (1.0 + x * x) / (y * (1.0 + x)) ** 2 - alpha
        fast = (slope > 0.0) & (log_h + np.log(y) >= math.log(FAST))
        fast_at = np.where(fast & np.isinf(fast_at), z[2], fast_at)
        done = z[2] >= fast_at + H_STOP_SLOPE
        if done.any():
            out[:, lane[done]] = z[:, done]
            keep = ~done
            if not keep.any():
                return out
            lane, z, h, k1, fast_at = lane[keep], z[:, keep], h[keep], k1[:, keep], fast_at[keep]
            log_t, a, alpha, beta = log_t[keep], a[keep], alpha[keep], beta[keep]
    raise RuntimeError(f"reference_slope_many: {lane.size} points did not finish in {MAX_STEPS} steps")


def slope_error(got, ref, stress, velocity) -> np.ndarray:
    """|got - ref| / max(|ref|, 1e-3 sigma/V): relative, with a floor where the slope crosses zero."""
    floor = 1e-3 * np.asarray(stress) / np.asarray(velocity)
    return np.abs(np.asarray(got) - ref) / np.maximum(np.abs(ref), floor)
