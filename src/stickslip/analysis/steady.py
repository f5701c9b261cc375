"""The steady-sliding stretch of a record: where its start-up relaxation has decayed, and its mean with an honest
standard error under correlated noise (docs/analysis.md, section 6, "steady").

* :func:`mean_and_error`: the mean over the stretch and its standard error from the effective number of samples,
  n / tau, with tau the integrated autocorrelation time of the residuals about the stretch's straight-line trend
  (Sokal's automatic window).  White noise gives tau = 1, the plain sd / sqrt(n); AR(1) noise of coefficient phi
  (1 + phi) / (1 - phi).  A record sampled twice as fast has twice the samples and, for the same noise, twice the
  tau: the error does not change with the sampling rate.
* :func:`settled_start`: the start of the averaging window, where a relaxation fitted to the stretch (an
  exponential in time on time blocks, plus a straight line for a drift) has decayed below that standard error.
  It is judged on blocks of a fixed share of the stretch's duration, not on samples, so it does not move with the
  sampling rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

#: Sokal's window: the autocorrelation is summed up to the first lag M with M >= WINDOW_FACTOR * tau(M).
WINDOW_FACTOR = 6.0
#: Lags summed directly at one resolution; beyond them the residuals are averaged in pairs and the sum continues on
#: the coarser series (the error of the mean is that of the pair means), so the cost stays ~ 2 * LAGS * n.
LAGS = 64
#: The stretch is cut into this many blocks of equal duration to fit its relaxation ...
BLOCKS = 50
#: ... each of at least this many samples (fewer blocks in a short stretch; none below MIN_BLOCKS).
BLOCK_SAMPLES = 10
MIN_BLOCKS = 12
#: The relaxation's time constant is sought between half a block and this fraction of the stretch (a longer one is
#: the stretch's trend, which the straight line takes) ...
LONGEST_RELAXATION = 0.25
RELAXATION_GRID = 60
#: ... and counts when it lowers the blocks' sum of squares by this many times their noise variance.
RELAXATION_CHI2 = 25.0
#: The relaxation's tail: the blocks after the last one whose mean lies further than the drop threshold, and than
#: this many times the blocks' scatter, from the line through the last half's.
BAND = 10.0
#: MAD -> standard deviation for Gaussian noise.
MAD_SCALE = 1.482602218505602
#: The window keeps at least this share of the stretch: a relaxation that outlasts it has not decayed (said).
MIN_WINDOW = 0.5


@dataclass(frozen=True)
class SteadyMean:
    """The mean stress over a window (Pa), its standard error under correlated noise (Pa), the samples, the
    effective samples n / tau, and tau in samples and in seconds."""

    mean: float
    sem: float
    samples: int
    effective_samples: float
    correlation: float  # tau, the integrated autocorrelation time in samples (1 for white noise)
    correlation_time: float  # tau times the mean sampling interval (s)


def mean_and_error(time: np.ndarray, stress: np.ndarray) -> SteadyMean | None:
    """The mean of ``stress`` and its standard error from the effective sample size; None for fewer than 4."""
    n = stress.size
    if n < 4:
        return None
    mean = float(np.mean(stress))
    residual = _detrended(time, stress)
    variance = float(np.einsum("i,i", residual, residual)) / (n - 2)
    tau = integrated_time(residual)
    sem = math.sqrt(variance * tau / n)
    interval = float(time[-1] - time[0]) / (n - 1) if n > 1 else 0.0
    return SteadyMean(mean, sem, int(n), n / tau, tau, tau * interval)


def _detrended(time: np.ndarray, stress: np.ndarray) -> np.ndarray:
    """Residuals about the least-squares straight line (a drift is no noise)."""
    u = time - float(np.mean(time))
    y = stress - float(np.mean(stress))
    spread = float(np.einsum("i,i", u, u))
    if spread > 0:
        y = y - float(np.einsum("i,i", u, y)) / spread * u
    return y


def integrated_time(residual: np.ndarray) -> float:
    """tau = 1 + 2 sum_k rho_k of a zero-mean series, summed up to Sokal's window (the first M >= 6 tau(M)); at
    least 1 (anticorrelated residuals do not make a mean better known than independent ones would).

    The sum runs over :data:`LAGS` lags of the series; where the window is not reached there, the series is averaged
    in pairs (tau of the pair means, times the pair's 2 samples over the ratio of the variances) and the search
    goes on at the coarser resolution."""
    series = np.asarray(residual, dtype=float)
    scale = 1.0  # samples of the original series per element of the current one
    base = float(np.einsum("i,i", series, series)) / series.size
    if not base > 0:
        return 1.0
    while series.size >= 4 * LAGS // 2:
        gamma0 = float(np.einsum("i,i", series, series)) / series.size
        if not gamma0 > 0:
            return 1.0
        tau = 1.0
        for lag in range(1, min(LAGS, series.size // 2)):
            rho = float(np.einsum("i,i", series[:-lag], series[lag:])) / (series.size * gamma0)
            tau += 2.0 * rho
            if lag >= WINDOW_FACTOR * tau:
                # Var(mean) = gamma0 * tau / m for the m current elements = base * T / n for the n original samples
                return max(1.0, tau * gamma0 * scale / base)
        even = series.size - series.size % 2
        series = 0.5 * (series[0:even:2] + series[1:even:2])
        scale *= 2.0
    # the correlation outlasts what the series can show: the coarsest estimate (pairs of pairs ... as one sample)
    gamma0 = float(np.einsum("i,i", series, series)) / max(series.size, 1)
    return max(1.0, scale * gamma0 / base)


def settled_start(
    time: np.ndarray, stress: np.ndarray, steady_from: float, band: float
) -> tuple[float, float | None, float | None, float | None]:
    """(start, relaxation there in Pa, its time constant in s, where the relaxation was fitted from) of the
    averaging window of a steady stretch that the coarse search found from ``steady_from``; ``time`` and ``stress``
    run from the earliest sample the relaxation may be sought at (after the last slip) to the record's end.

    The stretch is cut into :data:`BLOCKS` blocks of equal duration.  Back from the end, the blocks whose means lie
    within ``band`` (the drop threshold) of the line through the last half's are the relaxation's tail,
    fitted by a line plus A exp(-(t - t0)/tau); where the exponential stands out of the blocks' scatter, the window
    starts where it has decayed below the standard error of the mean over the window from there on (a fixed point:
    the error grows as the window shortens), but no later than leaves :data:`MIN_WINDOW` of the stretch.  Where none
    stands out, the window starts at ``steady_from``.  (None, None, None) for the last three where no relaxation was
    found."""
    t0, t1 = float(time[0]), float(time[-1])
    span = t1 - t0
    count = min(BLOCKS, stress.size // BLOCK_SAMPLES)
    if count < MIN_BLOCKS or not span > 0:
        return steady_from, None, None, None
    edges = t0 + span * np.arange(count + 1) / count
    index = np.clip(np.searchsorted(edges, time, "right") - 1, 0, count - 1)
    sizes = np.bincount(index, minlength=count)
    filled = sizes > 0
    centre = np.bincount(index, weights=time, minlength=count)[filled] / sizes[filled]
    means = np.bincount(index, weights=stress, minlength=count)[filled] / sizes[filled]
    lower = edges[:-1][filled]
    if centre.size < MIN_BLOCKS:
        return steady_from, None, None, None
    # the final level and the blocks' scatter, from the last half (a drift: the line through it)
    half = centre >= t0 + 0.5 * span
    if np.count_nonzero(half) < 4:
        return steady_from, None, None, None
    slope, level = np.polyfit(centre[half] - t1, means[half], 1)
    scatter = MAD_SCALE * float(np.median(np.abs(np.diff(means[half])))) / math.sqrt(2.0)
    if not scatter > 0:
        return steady_from, None, None, None
    off = np.abs(means - (level + slope * (centre - t1))) > max(band, BAND * scatter)
    first = int(np.flatnonzero(off)[-1]) + 1 if np.any(off) else 0
    if centre.size - first < MIN_BLOCKS:
        return steady_from, None, None, None
    origin = float(lower[first])
    fit = _relaxation(centre[first:] - origin, means[first:], span / count, LONGEST_RELAXATION * (t1 - origin))
    if fit is None:
        return steady_from, None, None, None
    amplitude, tau, gain, left = fit
    # the blocks' noise, from their scatter about the fitted relaxation and line (4 coefficients)
    block_variance = max(left / (centre.size - first - 4), scatter**2)
    if not gain > RELAXATION_CHI2 * block_variance:
        return steady_from, None, None, None
    start = origin
    latest = origin + (1.0 - MIN_WINDOW) * (t1 - origin)
    for _ in range(5):  # the window's own error sets where the relaxation is small enough: a fixed point
        lo = int(np.searchsorted(time, start, "left"))
        error = mean_and_error(time[lo:], stress[lo:])
        if error is None:
            break
        wanted = origin + tau * math.log(abs(amplitude) / error.sem) if abs(amplitude) > error.sem else origin
        wanted = min(max(wanted, origin), latest)
        done = abs(wanted - start) <= 1e-3 * span
        start = wanted
        if done:
            break
    return start, amplitude * math.exp(-(start - origin) / tau), tau, origin


def _relaxation(u: np.ndarray, y: np.ndarray, block: float, longest: float) -> tuple[float, float, float, float] | None:
    """(A, tau, the drop in the sum of squares from a straight line alone, the sum left) of the least-squares
    y = L + D u + A exp(-u/tau), tau on a logarithmic grid from half a block to ``longest``; None where the grid is
    empty."""
    shortest = 0.5 * block
    if not longest > shortest:
        return None
    base = np.column_stack([np.ones_like(u), u - float(np.mean(u))])
    line_sse = _sse(base, y)

    def fitted(log_tau: float) -> tuple[float, float]:
        design = np.column_stack([base, np.exp(-u / math.exp(log_tau))])
        coef, *_ = np.linalg.lstsq(design, y, rcond=None)
        return float(np.sum((y - design @ coef) ** 2)), float(coef[2])

    grid = np.linspace(math.log(shortest), math.log(longest), RELAXATION_GRID)
    sse = np.array([fitted(g)[0] for g in grid])
    k = int(np.argmin(sse))
    best = float(grid[k])
    if 0 < k < grid.size - 1:  # refined between the grid's neighbours
        refined = minimize_scalar(
            lambda g: fitted(g)[0], bounds=(grid[k - 1], grid[k + 1]), method="bounded", options={"xatol": 1e-4}
        )
        if refined.fun < sse[k]:
            best = float(refined.x)
    left, amplitude = fitted(best)
    return amplitude, math.exp(best), line_sse - left, left


def _sse(design: np.ndarray, y: np.ndarray) -> float:
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    return float(np.sum((y - design @ coef) ** 2))
