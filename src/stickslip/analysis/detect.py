"""Coarse segmentation of a stress record into stick rises and slip drops.

This step only finds *where* the phases are, to a few samples (the numbers per cycle come from :mod:`.cycles`):
a robust noise level, a median-filtered uniform resampling, drops as peaks of prominence above
:data:`PROMINENCE_SIGMAS` noise levels that fall faster than they rose, and what the record does after its last
peak (docs/analysis.md).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.ndimage import median_filter, uniform_filter1d
from scipy.signal import find_peaks

from ..numerics.quantisation import quantum

#: A drop counts as a slip when it exceeds this many noise standard deviations.
PROMINENCE_SIGMAS = 10.0
#: A candidate drop counts only if the record stays near its peak this many times longer before the peak than
#: after it (the top ASYMMETRY_BAND of the drop): a slip falls faster than the stick rose, noise does not ...
MIN_ASYMMETRY = 1.5
ASYMMETRY_BAND = 0.3
#: ... unless it is this many drop thresholds deep (a start-up slip above Vc falls about as fast as it rose) ...
CLEAR_DROP = 3.0
#: ... and the record is not a smooth oscillation: at least this many such deep drops that fall no faster than
#: they rose (an isolated one is a start-up slip; several are the swings of an oscillation) ...
OSCILLATION_SWINGS = 2
#: ... with at most this fraction of all its candidate drops falling faster than they rose.
OSCILLATION_FAST_SHARE = 0.2
#: Shallower swings (above the threshold, below CLEAR_DROP of it) are an oscillation when there are at least this
#: many, their median asymmetry is below MIN_ASYMMETRY, their median depth is at least REGULAR_DEPTH thresholds,
#: and they repeat: their depths and the intervals between them scatter by at most REGULAR_SCATTER of their mean
#: (the wanders of red noise, as often slow to fall as to rise, that pass the threshold barely do so, and are
#: not evenly spaced).
REGULAR_SWINGS = 5
REGULAR_DEPTH = 1.5
REGULAR_SCATTER = 0.2
#: When the candidate stick phases scatter about their lines by more than this factor times the noise estimate,
#: that scatter is the noise (correlated over longer than the estimate saw), and the drops are sought again ...
STICK_CONSISTENCY = 1.2
#: ... at most this many times.
MAX_REFINEMENTS = 8
#: Width (samples) of the median filter used for the coarse search.
MEDIAN_WIDTH = 5
#: Largest uniform grid used for the coarse search (long records are decimated).
MAX_GRID = 200_000
#: A steady tail stays within this fraction of the drop threshold of its final level ...
STEADY_BAND = 0.25
#: ... judged on a running mean over this many grid points.
STEADY_AVERAGE = 25
#: ... times the noise's correlation time in samples (a correlated-noise record), at most this many.
MAX_CORRELATION = 100.0
#: A record without slips has settled if its final flat stretch is at least this fraction of it.
SETTLED_FRACTION = 0.25
#: MAD -> standard deviation for Gaussian noise.
MAD_SCALE = 1.482602218505602
#: The trimmed RMS keeps this fraction of the smallest absolute deviations ...
TRIM_FRACTION = 0.5
#: ... whose RMS is this many standard deviations for Gaussian noise: sqrt(1 - 2 z phi(z) / 0.5), z = 0.6745.
TRIM_SCALE = 0.377594
#: A candidate drop whose top (its top ASYMMETRY_BAND, on the median-filtered curve) spans fewer than this many
#: filter widths of grid points has its asymmetry read on the samples themselves, from the times its rise and its
#: fall take between these two fractions of its depth below the peak (the filter flattens such a top into a
#: symmetric plateau, and a band of one or two samples a side counts where they fall, not how fast).
NARROW_TOP = 3
MID_BAND = (0.25, 0.75)
#: A fall between two samples takes at least this many sampling intervals between the MID_BAND levels.
MIN_CROSSING = 0.01
#: A record whose slips (or swings) come fewer than this many samples apart is coarse: its slips are sought again
#: near the sample-to-sample noise (which its corners inflate: 11.6 Pa for 5 Pa at eight samples a cycle), its
#: stick lines fitted one sample clear of the corners, and regular swings found no slip in are no steady sliding.
COARSE_CYCLE = 40
#: A coarsely sampled sawtooth is sought at this quantile of the absolute deviations of the residuals at lag 1 ...
LOW_QUANTILE = 0.25
#: ... which is this many standard deviations for Gaussian noise (the normal quantile at 0.625).
LOW_SCALE = 0.318639


@dataclass(frozen=True)
class Coarse:
    """Approximate turning points of a record (times in s, stresses of the smoothed curve).

    ``peaks`` are the drop events; ``troughs[k]`` is the candidate start of the
    stick phase that ends at ``peaks[k]`` (``troughs[0]`` may be spurious when
    the record starts mid-stick: the fits decide); ``final_trough`` is the
    start of a stick phase cut by the end of the record, or None.  When the
    record ends in steady sliding, ``steady_from`` is where the flat stretch
    begins (for a record without slips: None when it never settles).
    ``oscillation`` is set, and ``peaks`` empty, when the record's drops are
    (nearly) all as slow as its rises: a smooth oscillation, not stick-slip.
    """

    noise: float
    threshold: float
    grid_time: np.ndarray
    grid_stress: np.ndarray
    peaks: np.ndarray
    peak_levels: np.ndarray
    troughs: np.ndarray
    trough_levels: np.ndarray
    final_trough: float | None
    final_level: float | None
    steady_from: float | None
    step: float = 0.0  # median interval between distinct sample times
    oscillation: Swings | None = None


@dataclass(frozen=True)
class Swings:
    """The swings of a smooth oscillation (times in s, stresses of the smoothed curve): its maxima, the minimum
    between each two successive maxima, and the median over the maxima of the fall/rise asymmetry."""

    peaks: np.ndarray
    peak_levels: np.ndarray
    troughs: np.ndarray
    trough_levels: np.ndarray
    asymmetry: float


def noise_level(time: np.ndarray, stress: np.ndarray) -> float:
    """Robust standard deviation of the noise on a piecewise-smooth record (finite samples only).

    White noise is read off each sample against the line through its two neighbours; correlated noise by
    widening that triple (:func:`_correlated_level`) until the estimate stops growing; and a record written in
    whole ADC steps q never gets less than the steps' own q/sqrt(12) (docs/analysis.md, "Noise level").
    """
    return _noise_levels(time, stress)[1]


def _noise_levels(time: np.ndarray, stress: np.ndarray) -> tuple[float, float]:
    """(white, whole): the noise seen sample by sample (the MAD at lag 1) and the whole noise of
    :func:`noise_level`, each at least the quantisation's q/sqrt(12)."""
    if time.size < 3:
        return 0.0, 0.0
    white = _lag_level(time, stress, 1)
    floor = _quantisation_level(stress)
    return max(white, floor), max(_correlated_level(time, stress, white), floor)


#: The noise estimate widens its triples (lag 1, 2, 4, ... samples) while the estimate's variance still grows by
#: more than this factor (plus sampling scatter, :data:`GROWTH_SCATTER` / sqrt(independent triples)) ...
NOISE_GROWTH = 1.3
GROWTH_SCATTER = 6.0
#: ... up to lags of this fraction of the record (in samples and in time): the stick lines, not the slips'
#: curvature, must hold the median of the residuals.  (It was 1 %: noise correlated over 10 samples then needed
#: 13,000 of them to be seen whole, and shorter records of it were read as stick-slip at a third of its level.)
MAX_LAG_FRACTION = 0.125
#: Triples per lag beyond which the estimate takes every n-th one (the median needs no more).
LAG_TRIPLES = 1_000_000
#: The quantisation step is read off at most this many samples from the start of the record.
QUANTUM_SAMPLES = 1_000_000


def _correlated_level(time: np.ndarray, stress: np.ndarray, white: float) -> float:
    """The noise's whole standard deviation where successive samples are correlated.

    For stationary noise of autocovariance g(k), the residual about the line through samples k apart has
    variance 1.5 g(0) - 2 g(k) + 0.5 g(2k): g(0) (1 - 4 phi/3 + phi^2/3) at k = 1 for AR(1) noise, 7 % of it at
    phi = 0.9, all of it once k outlasts the correlation.  Straight stick lines add nothing at any k, so the
    noise is the level at the first lag k = 1, 2, 4, ... beyond which the next two doublings add no more than
    their scatter: ``white`` (the MAD at k = 1) when that is k = 1, as for white noise.  Growth that never
    levels off within :data:`MAX_LAG_FRACTION` of the record is the signal's curvature, not noise: ``white``.
    The ladder compares trimmed RMS values, not MADs: on a quantised record the residuals take a few discrete
    values, and a median can stay on one of them while the spread grows.
    """
    n = time.size
    longest = max(MAX_LAG_FRACTION * n, 5.0)
    horizon = time[0] + MAX_LAG_FRACTION * float(time[-1] - time[0])
    lags: list[int] = []
    lag = 1
    while 2 * lag + 1 <= min(longest, n) and (lag == 1 or time[2 * lag] <= horizon):
        lags.append(lag)
        lag *= 2
    levels: list[float] = []  # computed as the ladder climbs: white noise needs three rungs, not all of them
    for i in range(len(lags) - 1):
        while len(levels) < min(i + 3, len(lags)):
            levels.append(_lag_level(time, stress, lags[len(levels)], trimmed=True))
        ahead = levels[i + 1 : i + 3]
        growth = NOISE_GROWTH + GROWTH_SCATTER / math.sqrt(max(n / 2.0 ** (i + len(ahead)), 1.0))
        if all(level**2 <= growth * levels[i] ** 2 for level in ahead):
            return white if i == 0 else max(levels[i : i + 3])
    return white


def _quantisation_level(stress: np.ndarray) -> float:
    """q / sqrt(12) for a record written in whole steps q (an ADC's bit), else 0: the least noise it can have.

    Below that the record is a staircase whose treads are exact straight lines, so neighbouring samples show no
    noise at all when the stress rises by less than q between samples (1 kHz) and some at 100 Hz."""
    return quantum(stress[:QUANTUM_SAMPLES]) / math.sqrt(12.0)


def _lag_level(time: np.ndarray, stress: np.ndarray, lag: int, trimmed: bool = False, low: bool = False) -> float:
    """Robust standard deviation of the residual of each sample about the line through the samples ``lag``
    before and after it, scaled to the noise of one sample as if it were white: the MAD, with ``trimmed``
    the RMS of the :data:`TRIM_FRACTION` smallest deviations from the median, with ``low`` their
    :data:`LOW_QUANTILE` quantile (robust to a larger share of corners)."""
    stride = max(1, (time.size - 2 * lag) // LAG_TRIPLES)
    middle = slice(lag, time.size - lag, stride)
    t_mid, x_mid = time[middle], stress[middle]
    if lag == 1 and stride == 1:
        t_prev, x_prev, t_next, x_next = time[:-2], stress[:-2], time[2:], stress[2:]
    else:
        before = slice(0, time.size - 2 * lag, stride)
        after = slice(2 * lag, time.size, stride)
        t_prev, x_prev, t_next, x_next = time[before], stress[before], time[after], stress[after]
    # in place where possible: a 10^7-sample record makes each temporary 80 MB
    left, w_prev = t_mid - t_prev, t_next - t_mid
    span = left + w_prev
    spaced = span > 0  # three samples at one instant (a jump written as a run of rows) define no line
    if not np.all(spaced):
        left, w_prev, span, x_prev, x_mid, x_next = (a[spaced] for a in (left, w_prev, span, x_prev, x_mid, x_next))
    if span.size == 0:
        return 0.0
    w_prev /= span
    w_next = np.subtract(1.0, w_prev, out=left)
    residual = np.multiply(w_prev, x_prev)
    residual += np.multiply(w_next, x_next, out=span)
    np.subtract(x_mid, residual, out=residual)
    # Var(residual) = sigma^2 (1 + w_prev^2 + w_next^2) for independent noise
    norm = np.square(w_prev, out=w_prev)
    norm += np.square(w_next, out=w_next)
    norm += 1.0
    residual /= np.sqrt(norm, out=norm)
    centre = np.median(residual)
    residual -= centre
    deviation = np.abs(residual, out=residual)
    if low:
        return float(np.quantile(deviation, LOW_QUANTILE, overwrite_input=True)) / LOW_SCALE
    if not trimmed:
        return float(MAD_SCALE * np.median(deviation, overwrite_input=True))
    kept = max(1, int(TRIM_FRACTION * deviation.size))
    smallest = np.partition(deviation, kept - 1)[:kept]
    return float(math.sqrt(float(np.mean(np.square(smallest)))) / TRIM_SCALE)


def sampling_step(time: np.ndarray) -> float:
    """Median interval between successive distinct times (repeated times at jumps do not count)."""
    steps = np.diff(time)
    steps = steps[steps > 0]
    return float(np.median(steps, overwrite_input=True)) if steps.size else 0.0


def uniform_grid(time: np.ndarray, stress: np.ndarray, step: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The finite samples interpolated on a uniform grid at the median sampling interval.

    At a repeated time (a jump) the grid takes the value before it on its left and the one after it on its
    right (``np.interp`` never selects the zero-width interval).
    """
    step = sampling_step(time) if step is None else step
    span = float(time[-1] - time[0])
    count = int(min(MAX_GRID, max(2, round(span / step) + 1))) if step > 0 else 2
    grid = np.linspace(time[0], time[-1], count)
    return grid, np.interp(grid, time, stress)


def coarse_segments(time: np.ndarray, stress: np.ndarray, step: float | None = None) -> Coarse:
    """Find drop events, troughs and a steady tail in a record of finite samples.

    A drop is a slip when it is deeper than :data:`PROMINENCE_SIGMAS` noise levels and falls faster than the
    stick before it rose (:func:`_drops`); when the sticks so found scatter about their lines by more than the
    noise estimate allows, their scatter is the noise and the drops are sought again (docs/analysis.md, "Red
    noise").  When the correlated-noise estimate exceeds the sample-to-sample one, the drops are also sought at
    the latter, and kept when the sawtooth they make accounts for the excess (:func:`_coarse_sawtooth`,
    "Coarse sampling").  ``step`` is the sampling interval (:func:`sampling_step` when not given).
    """
    white, whole = _noise_levels(time, stress)
    step = sampling_step(time) if step is None else step
    grid, raw = uniform_grid(time, stress, step)
    smooth = median_filter(raw, size=min(MEDIAN_WIDTH, raw.size), mode="nearest")
    scale = float(np.max(np.abs(smooth))) if smooth.size else 0.0
    noise, threshold, peaks, troughs, swings = _segment(time, stress, grid, smooth, scale, whole, raw)
    if whole > STICK_CONSISTENCY * white:  # the ladder climbed: correlated noise, or the sawtooth itself?
        sawtooth = _coarse_sawtooth(time, stress, grid, (smooth, raw), scale, white)
        if sawtooth is not None:
            smooth, (noise, threshold, peaks, troughs, swings) = sawtooth
    elif _doubtful(grid, raw, peaks, noise, whole):  # more slips near the sample-to-sample noise than were found?
        sawtooth = _coarse_sawtooth(time, stress, grid, (smooth, raw), scale, white)
        # kept when it finds more slips, or as many in a coarse record (its noise is then the sticks' scatter, which
        # the corners do not inflate as they do the sample-to-sample noise)
        if sawtooth is not None and (
            sawtooth[1][2].size > peaks.size or (sawtooth[1][2].size == peaks.size and coarse_spacing(peaks))
        ):
            smooth, (noise, threshold, peaks, troughs, swings) = sawtooth
    final_trough = None
    steady_from = None
    last = peaks[-1] if peaks.size else 0
    # the steady tail's running mean spans as many independent samples whatever the noise's correlation: its
    # correlation time in samples is about (whole / white)^2 (6.8 for AR(1) noise of coefficient 0.8, whose
    # integrated autocorrelation time is 9), when the record's noise is the correlated one
    correlated = noise >= 0.9 * whole and white > 0
    average = STEADY_AVERAGE * (min((whole / white) ** 2, MAX_CORRELATION) if correlated else 1.0)
    tail = smooth[last:]
    if peaks.size:
        q = last + rise_start(tail, threshold)
        if smooth[-1] - np.min(tail) > threshold and q < smooth.size - 1:
            final_trough = q
        else:
            steady_from = _steady_tail(grid, smooth, last, threshold, _longest_stick(grid, peaks, troughs), average)
    else:  # no slip: where the record has settled, if it did for a quarter of its length
        steady_from = _steady_tail(grid, smooth, 0, threshold, SETTLED_FRACTION * float(grid[-1] - grid[0]), average)
    oscillation = _swings(grid, smooth, swings) if swings is not None else None
    return Coarse(
        noise=noise,
        threshold=threshold,
        grid_time=grid,
        grid_stress=smooth,
        peaks=grid[peaks],
        peak_levels=smooth[peaks],
        troughs=grid[troughs],
        trough_levels=smooth[troughs],
        final_trough=None if final_trough is None else float(grid[final_trough]),
        final_level=None if final_trough is None else float(smooth[final_trough]),
        steady_from=steady_from,
        step=step,
        oscillation=oscillation,
    )


def coarse_spacing(peaks: np.ndarray, step: float = 1.0) -> bool:
    """Whether slips at ``peaks`` (grid indices, or times with the sampling interval ``step``) come fewer than
    :data:`COARSE_CYCLE` samples apart (the median of their intervals)."""
    return peaks.size >= 2 and step > 0 and float(np.median(np.diff(peaks))) < COARSE_CYCLE * step


def _doubtful(grid: np.ndarray, raw: np.ndarray, peaks: np.ndarray, noise: float, whole: float) -> bool:
    """Whether a search at the record's noise ``whole`` that found the slips ``peaks`` (grid indices) at the noise
    ``noise`` may have missed slips a search near the sample-to-sample noise finds (:func:`_coarse_sawtooth`):
    at most one found (a sawtooth of a few samples a cycle, which the 5-point median flattens, looks steady), the
    sticks found scatter by more than ``whole`` allows (a stick that spans a missed slip reads the slip as noise),
    or the slips found, or the record's swings about its trend (on the uniform grid ``grid``, ``raw``), come fewer
    than :data:`COARSE_CYCLE` samples apart (where the corners inflate the sample-to-sample noise, and the drop
    threshold with it)."""
    if peaks.size < 2 or noise > STICK_CONSISTENCY * whole or coarse_spacing(peaks):
        return True
    swings = _swings_about_trend(grid, raw, _sample_level(raw, grid))
    return swings is not None and float(np.median(np.diff(swings[0]))) < COARSE_CYCLE


#: (noise, threshold, peaks, troughs, swings) of :func:`_segment`.
Segmentation = tuple[float, float, np.ndarray, np.ndarray, tuple[np.ndarray, float] | None]


def _segment(
    time: np.ndarray,
    stress: np.ndarray,
    grid: np.ndarray,
    smooth: np.ndarray,
    scale: float,
    noise: float,
    raw: np.ndarray | None = None,
) -> Segmentation:
    """Drops at ``noise``, sought again while the sticks found scatter about their lines by more than the noise
    allows (that scatter then being the noise): (noise, threshold, peaks, troughs, swings) as :func:`_drops`,
    which reads narrow peaks on ``raw``."""
    threshold = max(PROMINENCE_SIGMAS * noise, 1e-9 * scale, 1e-300)
    peaks, troughs, swings = _drops(smooth, threshold, raw)
    for _ in range(MAX_REFINEMENTS):  # the sticks found must be straight lines to within the noise
        scatter = _stick_scatter(time, stress, grid, peaks, troughs)
        if not scatter > STICK_CONSISTENCY * noise:
            break
        noise = scatter
        threshold = max(PROMINENCE_SIGMAS * noise, 1e-9 * scale, 1e-300)
        peaks, troughs, swings = _drops(smooth, threshold, raw)
    return noise, threshold, peaks, troughs, swings


#: The sawtooth found at the sample-to-sample noise explains a correlated-noise estimate above it when at least
#: this many of its sticks hold EXPLAIN_SAMPLES samples or more (their middle 80 %) ...
EXPLAIN_STICKS = 3
EXPLAIN_SAMPLES = 3
#: ... and the residuals about those sticks' lines have the sample-to-sample noise's RMS (within
#: :data:`STICK_CONSISTENCY`) with a pooled lag-one correlation of at most this (a line through a stretch of red
#: noise leaves residuals that move together; white noise about a line of n samples gives about -1/n).
EXPLAIN_CORRELATION = 0.3
#: ... and the sticks fill at least this share of the time from one slip to the next (median over the cycles; a
#: stick starts where the rise leaves the bottom, a sample or two late on a coarse record): the record is a
#: sawtooth from end to end, not a few straight stretches of a wander picked out between long detours.
EXPLAIN_STICK_SHARE = 1.0 / 3.0


def _coarse_sawtooth(
    time: np.ndarray,
    stress: np.ndarray,
    grid: np.ndarray,
    curves: tuple[np.ndarray, np.ndarray],
    scale: float,
    white: float,
) -> tuple[np.ndarray, Segmentation] | None:
    """The slips found near the sample-to-sample noise ``white`` when they account for the growth of the
    correlated-noise ladder (:func:`_correlated_level`), with the curve they were found on; None when they do
    not (docs/analysis.md, "Coarse sampling").

    A sawtooth sampled a few tens of times per cycle has its slips inside the ladder's wider triples, which read
    the sawtooth itself as noise.  The slips are sought at the lower quartile of the lag-1 residuals
    (:data:`LOW_QUANTILE`, which the corners disturb less than the MAD; at most ``white``), on the
    median-filtered curve and on the samples themselves (the filter cuts the tops of sticks a few samples long,
    and can make them as slow to fall as to rise).  They explain the ladder's growth when the record less its
    piecewise-linear sticks is white noise (:func:`_stick_residual`); of the two, the one with more slips is
    kept, the filtered one on a tie.  The noise is then the residual's RMS (not below the quantisation's
    q/sqrt(12)): the sample-to-sample estimate also sees the corners, up to twice the noise at ten samples a
    cycle.
    """
    floor = _quantisation_level(stress)
    start = min(white, max(_lag_level(time, stress, 1, low=True), floor))
    found = []
    raw = curves[1]
    for curve in curves:
        sawtooth = _segment(time, stress, grid, curve, scale, start, raw)
        residual = _stick_residual(time, stress, grid, sawtooth, white)
        if residual is None:
            continue
        level = max(residual, floor)
        if level < sawtooth[0]:  # the same slips at the noise left once they are taken out
            refined = _segment(time, stress, grid, curve, scale, level, raw)
            if _stick_residual(time, stress, grid, refined, level) is not None:
                sawtooth = refined
        found.append((curve, sawtooth))
    return max(found, key=lambda pair: pair[1][2].size) if found else None


def _stick_residual(
    time: np.ndarray, stress: np.ndarray, grid: np.ndarray, sawtooth: Segmentation, white: float
) -> float | None:
    """RMS of the record about the lines of the sticks of ``sawtooth`` (the middle 80 % of each, pooled) when it
    is white noise of about the level ``white`` and the sticks fill the record: at least :data:`EXPLAIN_STICKS`
    sticks of :data:`EXPLAIN_SAMPLES` samples, filling :data:`EXPLAIN_STICK_SHARE` of their cycles, an RMS
    within :data:`STICK_CONSISTENCY` of ``white`` and a lag-one correlation of at most
    :data:`EXPLAIN_CORRELATION`; else None."""
    noise, _, peaks, troughs, _ = sawtooth
    tiny = 1e-9 * float(np.max(np.abs(stress)))  # rounding alone, on a noise-free record
    if peaks.size < EXPLAIN_STICKS or noise > STICK_CONSISTENCY * white + tiny:
        return None
    share = (grid[peaks[1:]] - grid[troughs[1:]]) / (grid[peaks[1:]] - grid[peaks[:-1]])
    if not np.median(share) >= EXPLAIN_STICK_SHARE:  # stretches of a wander between long detours
        return None
    squares, dof, products, pairs, sticks = 0.0, 0, 0.0, 0.0, 0
    for a, b in zip(grid[troughs], grid[peaks], strict=True):
        margin = 0.1 * (b - a)
        lo, hi = int(np.searchsorted(time, a + margin, "left")), int(np.searchsorted(time, b - margin, "right"))
        if hi - lo < EXPLAIN_SAMPLES:
            continue
        u = time[lo:hi] - np.mean(time[lo:hi])
        spread = float(np.dot(u, u))
        if not spread > 0:  # a run of rows at one instant
            continue
        y = stress[lo:hi] - np.mean(stress[lo:hi])
        y -= float(np.dot(u, y)) / spread * u
        squares += float(np.dot(y, y))
        dof += y.size - 2
        products += float(np.dot(y[:-1], y[1:]))
        pairs += float(np.dot(y[:-1], y[:-1]) + np.dot(y[1:], y[1:])) / 2.0
        sticks += 1
    if sticks < EXPLAIN_STICKS or dof <= 0:
        return None
    rms = math.sqrt(squares / dof)
    if not rms <= STICK_CONSISTENCY * white + tiny:
        return None
    return rms if products <= EXPLAIN_CORRELATION * pairs or rms <= tiny else None


def _drops(
    smooth: np.ndarray, threshold: float, raw: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, float] | None]:
    """Grid indices of the slips' peaks and of the starts of the sticks before them, and the swings of a smooth
    oscillation (its peaks' indices and their median asymmetry; None when the record does not oscillate).

    A peak is a slip when its prominence exceeds ``threshold`` and it falls faster than it rose (by
    :data:`MIN_ASYMMETRY`, :func:`_asymmetry`), unless it is :data:`CLEAR_DROP` thresholds deep.  That exemption
    is for an isolated deep drop (a start-up slip above Vc): when :data:`OSCILLATION_SWINGS` or more deep drops
    fall no faster than they rose and at most :data:`OSCILLATION_FAST_SHARE` of all the candidates fall faster,
    the record is a smooth oscillation, which has no slip phase: no slips, and its candidates are its swings.
    A peak whose top spans fewer than :data:`NARROW_TOP` filter widths of ``smooth`` (a record of a few tens of
    samples a cycle or fewer) has its asymmetry read on ``raw``, the samples on the grid, by
    :func:`_crossing_asymmetry` (docs/analysis.md, "Six to fifteen samples a cycle").
    """
    peaks = _separated(smooth, find_peaks(smooth, prominence=threshold)[0], threshold)
    asymmetry, depth, width = _asymmetry(smooth, peaks, with_width=True)
    narrow = width < NARROW_TOP * MEDIAN_WIDTH
    if raw is not None and np.any(narrow):
        asymmetry = np.where(narrow, _crossing_asymmetry(raw, _raw_peaks(raw, peaks)), asymmetry)
    fast = asymmetry >= MIN_ASYMMETRY
    deep = depth >= CLEAR_DROP * threshold
    slow_deep = int(np.count_nonzero(deep & ~fast))
    clear = slow_deep >= OSCILLATION_SWINGS and np.count_nonzero(fast) <= OSCILLATION_FAST_SHARE * peaks.size
    if clear or _regular_swings(peaks, asymmetry, depth, threshold):
        empty = np.empty(0, dtype=int)
        return empty, empty, (peaks, float(np.median(asymmetry)))
    peaks = peaks[fast | deep]
    troughs = np.empty(peaks.size, dtype=int)
    for k, p in enumerate(peaks):
        lo = peaks[k - 1] if k else 0
        troughs[k] = lo + rise_start(smooth[lo : p + 1], threshold)
    return peaks, troughs, None


def _regular_swings(peaks: np.ndarray, asymmetry: np.ndarray, depth: np.ndarray, threshold: float) -> bool:
    """Whether candidate peaks too shallow to be clear are the repeating swings of a smooth oscillation
    (:data:`REGULAR_SWINGS`); the first and last depths are left out (the record's ends may cut those swings)."""
    if peaks.size < REGULAR_SWINGS or not np.median(asymmetry) < MIN_ASYMMETRY:
        return False
    if not np.median(depth) >= REGULAR_DEPTH * threshold:
        return False
    inner = depth[1:-1]
    intervals = np.diff(peaks).astype(float)
    return bool(
        np.std(inner) <= REGULAR_SCATTER * np.mean(inner) and np.std(intervals) <= REGULAR_SCATTER * np.mean(intervals)
    )


def _swings(grid: np.ndarray, smooth: np.ndarray, swings: tuple[np.ndarray, float]) -> Swings:
    """The oscillation's maxima and the minimum between each two successive ones."""
    peaks, asymmetry = swings
    troughs = np.array([a + int(np.argmin(smooth[a : b + 1])) for a, b in itertools.pairwise(peaks)], dtype=int)
    return Swings(
        peaks=grid[peaks],
        peak_levels=smooth[peaks],
        troughs=grid[troughs],
        trough_levels=smooth[troughs],
        asymmetry=asymmetry,
    )


def _asymmetry(y: np.ndarray, peaks: np.ndarray, with_width: bool = False) -> Any:
    """Per peak of ``y``: (time spent near it before it) / (time spent near it after it), and its depth.

    The depth is the peak's height above the higher of the lows on either side (up to the neighbouring peaks);
    "near" is within :data:`ASYMMETRY_BAND` of that depth below the peak, counted in grid points between the low
    before and the low after (each count plus half the peak's own point).  A stick rising at K V0 into a slip
    falling at K (V - V0) stays there (Vs - V0)/V0 times longer before the peak than after it; stationary noise
    of any spectrum is reversible in time, so for its wanders the ratio is as often below 1 as above.
    """
    ratio = np.empty(peaks.size)
    depth = np.empty(peaks.size)
    width = np.empty(peaks.size)
    bounds = np.concatenate([[0], peaks, [y.size - 1]]).astype(int)
    for k, p in enumerate(peaks):
        before, after = y[bounds[k] : p + 1], y[p : bounds[k + 2] + 1]
        low_before, low_after = int(np.argmin(before)), int(np.argmin(after))
        depth[k] = y[p] - max(before[low_before], after[low_after])
        level = y[p] - ASYMMETRY_BAND * depth[k]
        rise = np.count_nonzero(before[low_before:-1] >= level) + 0.5
        fall = np.count_nonzero(after[1 : low_after + 1] >= level) + 0.5
        ratio[k] = rise / fall
        width[k] = rise + fall  # the top's grid points, the peak's own included
    return (ratio, depth, width) if with_width else (ratio, depth)


def _raw_peaks(raw: np.ndarray, peaks: np.ndarray) -> np.ndarray:
    """The sample on the grid ``raw`` highest within half a median-filter width of each peak of the filtered curve
    (whose flat top of a coarse peak ends where the samples' own peak is); never past a neighbouring peak."""
    half = MEDIAN_WIDTH // 2
    found = np.empty(peaks.size, dtype=int)
    for k, p in enumerate(peaks):
        lo = max(int(p) - half, 0 if k == 0 else int(peaks[k - 1]) + 1)
        hi = min(int(p) + half + 1, raw.size if k + 1 == peaks.size else int(peaks[k + 1]))
        found[k] = lo + int(np.argmax(raw[lo:hi]))
    return found


def _crossing_asymmetry(y: np.ndarray, peaks: np.ndarray) -> np.ndarray:
    """Per peak of ``y``: how long its rise takes to climb from :data:`MID_BAND`'s deeper to its shallower level
    below the peak, over how long its fall takes back down between them (each time where the samples cross the
    level, linearly interpolated; the depth as in :func:`_asymmetry`).

    On a peak of a few samples the top band of :func:`_asymmetry` holds one or two of them on either side, and its
    ratio of counts is that of where the samples happen to fall: 0.6 to 1.7 on a sinusoid sampled ten times a
    period, 1 on a sawtooth whose slip spans two samples.  The middle of the swing is where both a stick and a
    sinusoid are straight, so its crossing times are read to a fraction of a sample: a sinusoid gives 1, a
    stick rising at K V0 into a slip falling at K (V - V0) the ratio of their rates; stationary noise, reversible
    in time, is as often above 1 as below.  A fall between two samples counts a hundredth of a sample.
    """
    ratio = np.empty(peaks.size)
    bounds = np.concatenate([[0], peaks, [y.size - 1]]).astype(int)
    for k, p in enumerate(peaks):
        first, last = int(bounds[k]), int(bounds[k + 2])
        low = max(float(np.min(y[first : p + 1])), float(np.min(y[p : last + 1])))
        depth = float(y[p]) - low
        if not depth > 0:
            ratio[k] = 1.0
            continue
        shallow, deep = (float(y[p]) - f * depth for f in MID_BAND)
        rise = _crossing(y, p, first, shallow, -1) - _crossing(y, p, first, deep, -1)
        fall = _crossing(y, p, last, deep, 1) - _crossing(y, p, last, shallow, 1)
        ratio[k] = rise / max(fall, MIN_CROSSING)
    return ratio


def _crossing(y: np.ndarray, start: int, stop: int, level: float, direction: int) -> float:
    """(Fractional) index where ``y``, followed from ``start`` towards ``stop`` in ``direction``, first falls below
    ``level``: linear interpolation between the last sample at or above it and the first below; ``stop`` when
    it never does."""
    i = start
    while i != stop and y[i + direction] >= level:
        i += direction
    if i == stop:
        return float(stop)
    above, below = float(y[i]), float(y[i + direction])
    return i + direction * (above - level) / (above - below)


def _stick_scatter(
    time: np.ndarray, stress: np.ndarray, grid: np.ndarray, peaks: np.ndarray, troughs: np.ndarray
) -> float:
    """Median over the candidate stick phases of the RMS about a straight line fitted to its samples (the middle
    80 % of the phase, so no corner), less a curvature common to them all; NaN when there is none of at least 8
    samples.

    The common curvature (one d2sigma/dt2, Pa/s^2, fitted to every stick at once; taken out of a stick where it
    brings the stick's RMS down) is the record's: sticks that bend
    alike (a stick slope that grows within each stick) are no noise, and read as noise they raised the drop
    threshold (8.0 Pa for 3.3 Pa with sticks rising from 0.5 to 1.5 times K V0) and moved the corners.  The wander
    of red noise bends each stick its own way and is left in the scatter (docs/analysis.md, "Curved sticks")."""
    pieces = []
    for a, b in zip(grid[troughs], grid[peaks], strict=True):
        margin = 0.1 * (b - a)
        lo, hi = int(np.searchsorted(time, a + margin, "left")), int(np.searchsorted(time, b - margin, "right"))
        if hi - lo < 8:
            continue
        u = time[lo:hi] - np.mean(time[lo:hi])
        uu = float(np.einsum("i,i", u, u))
        if not uu > 0:
            continue
        y = stress[lo:hi] - np.mean(stress[lo:hi])
        y -= float(np.einsum("i,i", u, y)) / uu * u
        w = u * u  # the curvature's shape, less its mean and its share along the line
        w -= np.mean(w)
        w -= float(np.einsum("i,i", u, w)) / uu * u
        pieces.append((y, w))
    if not pieces:
        return math.nan
    ww = sum(float(np.einsum("i,i", w, w)) for _, w in pieces)
    bend = sum(float(np.einsum("i,i", w, y)) for y, w in pieces) / ww if ww > 0 else 0.0
    # each stick's RMS about its line, less the common curvature where that brings it closer (a stick that bends
    # otherwise, or not at all, keeps its line's)
    rms = []
    for y, w in pieces:
        bent = y - bend * w
        rms.append(math.sqrt(min(float(np.einsum("i,i", y, y)), float(np.einsum("i,i", bent, bent))) / (y.size - 2)))
    return float(np.median(rms))


def _separated(y: np.ndarray, peaks: np.ndarray, threshold: float) -> np.ndarray:
    """Merge peaks not separated by a dip deeper than ``threshold`` (flat tops give twin peaks)."""
    kept: list[int] = []
    for p in peaks:
        if kept and np.min(y[kept[-1] : p + 1]) > min(y[kept[-1]], y[p]) - threshold:
            if y[p] >= y[kept[-1]]:
                kept[-1] = int(p)
            continue
        kept.append(int(p))
    return np.asarray(kept, dtype=int)


def rise_start(values: np.ndarray, threshold: float) -> int:
    """Index where the final rise of ``values`` leaves its minimum (the end of a flat bottom)."""
    low = np.nonzero(values <= np.min(values) + 0.5 * threshold)[0]
    return int(low[-1])


def _longest_stick(grid: np.ndarray, peaks: np.ndarray, troughs: np.ndarray) -> float:
    return float(np.max(grid[peaks] - grid[troughs])) if peaks.size else 0.0


def _steady_tail(
    grid: np.ndarray, smooth: np.ndarray, start: int, threshold: float, stick: float, average: float = STEADY_AVERAGE
) -> float | None:
    """Start of the flat stretch that ends the record, if it outlasts the longest stick phase.

    Flat means within :data:`STEADY_BAND` drop thresholds of the final level,
    judged on a running mean of ``average`` grid points (so that the noise itself never leaves the band: for
    correlated noise, :data:`STEADY_AVERAGE` times its correlation time in samples).
    """
    width = min(max(1, round(average)), max(1, (smooth.size - start) // 4))
    mean = uniform_filter1d(smooth[start:], size=width, mode="nearest")
    count = max(10, mean.size // 20)
    level = float(np.median(mean[-count:]))
    outside = np.nonzero(np.abs(mean - level) > STEADY_BAND * threshold)[0]
    first = start + (outside[-1] + 1 if outside.size else 0)
    if first >= smooth.size:
        return None
    length = grid[-1] - grid[first]
    step = grid[1] - grid[0]
    if length >= max(stick, min(20 * step, 0.5 * (grid[-1] - grid[start]))):
        return float(grid[first])
    return None


#: A time between successive usable samples longer than this many sampling intervals is a gap in the record
#: (NaN cells or missing rows): the record is analysed on either side of it, never through it.  (Shorter runs of
#: NaN, up to a few samples, are bridged as before: they cannot hide a slip that the samples about them miss.)
#: The interval is the record's median one and, where the sampling changes (a model's adaptive steps), the
#: larger of the median intervals just before and just after (GAP_NEIGHBOURS each side).
GAP_STEPS = 10.0
GAP_NEIGHBOURS = 5
#: A dropout is a burst of at most this many samples ...
DROPOUT_SAMPLES = 5
#: ... that all lie beyond the samples either side of it by more than the drop threshold (the depth), where the
#: samples either side agree to within this fraction of the depth (the record comes back to where it left:
#: a slip does not), and the record moves by no more than it in the one sample before the burst and in the one
#: after (the burst is abrupt: a finely sampled rounded trough is not) ...
DROPOUT_RETURN = 0.25
#: ... and the burst itself is flat: its samples agree to within this fraction of the depth (a sawtooth sampled
#: three or four times a cycle is not flat over its trough).
DROPOUT_FLAT = 0.25


#: A long interval is no gap where the record runs straight across it, as a model's solver (or an event-driven
#: logger) writes a straight stick as its two ends (the docs' velocity-weakening plug-in: 0.46 s between two rows,
#: among slips sampled every 1e-6 s).  Straight: no sample removed inside it (no NaN row, no dropout), and on one
#: side at least the samples over STRAIGHT_REACH times the time in which a slope STRAIGHT_SLOPE (relative) off the
#: chord's moves STRAIGHT_SIGMAS noise levels off it (and STRAIGHT_SAMPLES samples at least) all lie within
#: STRAIGHT_SIGMAS noise levels, plus that slope's reach, of the chord run on past its end; that span must be no
#: longer than the interval, and the side must have it (before another gap or the record's end).  A record that
#: rises across the interval as fast as its sticks rise hides no slip in it (the slip's drop would have to be made
#: up by a faster rise); a gap over a slip of a sawtooth has a chord whose slope is half the sticks' or less, whose
#: sides leave it by 10 such bands and more.  A side too short or too noisy to tell leaves it a gap: the record
#: must rise across it by 2·STRAIGHT_REACH·STRAIGHT_SIGMAS/STRAIGHT_SLOPE = 80 noise levels at least.
STRAIGHT_SLOPE = 0.1
STRAIGHT_SIGMAS = 4.0
STRAIGHT_REACH = 2.0
STRAIGHT_SAMPLES = 3


def gaps(
    time: np.ndarray,
    step: float,
    stress: np.ndarray | None = None,
    noise: float = 0.0,
    holes: np.ndarray | None = None,
) -> np.ndarray:
    """Indices k of the usable samples after which the record has a gap: time[k + 1] - time[k] longer than
    :data:`GAP_STEPS` times the sampling interval ``step`` and the local one (:data:`GAP_NEIGHBOURS`).

    With ``stress`` (and its ``noise`` level), an interval across which the record is one straight line
    (:func:`straight_across`) is no gap; ``holes[k]`` True marks an interval that lost samples (NaN rows, a
    dropout), which stays a gap whatever the line."""
    found = _long_intervals(time, step)
    if stress is None or found.size == 0:
        return found
    bridged = [
        k for k in found if not (holes is not None and holes[k]) and straight_across(time, stress, k, noise, found)
    ]
    return np.setdiff1d(found, np.asarray(bridged, dtype=int))


def straight_across(time: np.ndarray, stress: np.ndarray, k: int, noise: float, cuts: np.ndarray) -> bool:
    """Whether the record is one straight line across the interval after sample k (see :data:`STRAIGHT_SLOPE`):
    the samples on either side, up to the next of the long intervals ``cuts`` or the record's end, continue the
    chord from sample k to sample k + 1."""
    t0, t1 = float(time[k]), float(time[k + 1])
    x0, x1 = float(stress[k]), float(stress[k + 1])
    span = t1 - t0
    slope = (x1 - x0) / span
    band = STRAIGHT_SIGMAS * max(noise, 1e-12 * max(abs(x0), abs(x1)))
    if not abs(slope) > 0:
        return False
    reach = STRAIGHT_REACH * band / (STRAIGHT_SLOPE * abs(slope))  # the span each side must show
    if not reach <= span:
        return False
    others = cuts[cuts != k]
    first = int(others[others < k].max()) + 1 if np.any(others < k) else 0  # the stretches about the interval
    last = int(others[others > k].min()) if np.any(others > k) else time.size - 1
    sides = []  # a side shorter than the reach (another gap, the record's end) cannot tell: not asked
    lo = min(int(np.searchsorted(time, t0 - reach, side="left")), k - STRAIGHT_SAMPLES)
    if lo >= first and float(time[first]) <= t0 - reach:
        sides.append((slice(lo, k), k))
    hi = max(int(np.searchsorted(time, t1 + reach, side="right")), k + 2 + STRAIGHT_SAMPLES)
    if hi <= last + 1 and float(time[last]) >= t1 + reach:
        sides.append((slice(k + 2, hi), k + 1))
    for near, edge in sides:
        dt = time[near] - time[edge]
        off = np.abs(stress[near] - (float(stress[edge]) + slope * dt))
        if np.all(off <= band + STRAIGHT_SLOPE * abs(slope) * np.abs(dt)):
            return True
    return False


def _long_intervals(time: np.ndarray, step: float) -> np.ndarray:
    """The gaps by the sampling alone (:func:`gaps` without a stress)."""
    if step <= 0 or time.size < 2:
        return np.empty(0, dtype=int)
    dt = np.diff(time)
    cuts = np.flatnonzero(dt > GAP_STEPS * step)  # none in an evenly sampled record without gaps: one pass
    if cuts.size == 0:
        return cuts
    offsets = np.arange(1, GAP_NEIGHBOURS + 1)
    local = np.zeros(cuts.size)
    for side in (-offsets, offsets):
        index = cuts[:, None] + side[None, :]
        inside = (index >= 0) & (index < dt.size)
        near = np.where(inside, dt[np.clip(index, 0, dt.size - 1)], np.nan)
        near[near <= 0] = np.nan  # repeated times (jumps) are no interval
        # a gap without a usable neighbouring interval on this side counts 0 there (no all-NaN row for nanmedian)
        level = np.nanmedian(np.where(np.isnan(near).all(axis=1)[:, None], 0.0, near), axis=1)
        local = np.maximum(local, level)
    return cuts[dt[cuts] > GAP_STEPS * local]


def dropouts(stress: np.ndarray, threshold: float) -> np.ndarray:
    """Indices of the samples in dropouts: bursts of at most :data:`DROPOUT_SAMPLES` samples that leave the record
    by more than ``threshold`` in one sample and come back to it in one sample (docs/analysis.md, "Dropouts").

    A slip leaves the stick line in a sample or a few, but the stress stays down and climbs back at the stick's
    loading rate; an outlier burst (a lost connection, a glitch of the sensor) returns to the level it left.
    Candidates are the one-sample steps larger than ``threshold`` (few in any record), so the cost is one pass.
    """
    n = stress.size
    if n < 3 or not threshold > 0:
        return np.empty(0, dtype=int)
    steps = np.diff(stress)
    entries = np.flatnonzero(np.abs(steps) > threshold)  # the burst starts at entry + 1
    if entries.size == 0:
        return np.empty(0, dtype=int)
    down = steps[entries] < 0
    found = np.zeros(entries.size, dtype=int)  # burst length per candidate, 0: none
    for length in range(1, DROPOUT_SAMPLES + 1):
        open_ = (found == 0) & (entries >= 1) & (entries + length + 2 < n)
        if not np.any(open_):
            break
        k = entries[open_]
        before, after = stress[k], stress[k + length + 1]
        outside = np.maximum(np.abs(before - stress[k - 1]), np.abs(stress[k + length + 2] - after))
        burst = np.stack([stress[k + m] for m in range(1, length + 1)])
        high, low = np.max(burst, axis=0), np.min(burst, axis=0)
        is_down = down[open_]
        depth = np.where(is_down, np.minimum(before, after) - high, low - np.maximum(before, after))
        ok = (depth > threshold) & (np.abs(after - before) <= DROPOUT_RETURN * depth)
        ok &= (high - low <= DROPOUT_FLAT * depth) & (outside <= DROPOUT_RETURN * depth)
        found[np.flatnonzero(open_)[ok]] = length
    hit = found > 0
    if not np.any(hit):
        return np.empty(0, dtype=int)
    rows = np.concatenate([np.arange(e + 1, e + 1 + m) for e, m in zip(entries[hit], found[hit], strict=True)])
    return np.unique(rows)


#: A stretch the search calls steady is no steady sliding when it swings regularly about its trend, too few samples
#: a swing for the slips to be resolved: at least this many whole swings ...
UNRESOLVED_SWINGS = 5
#: ... each crossing from below to above this many noise levels (the sample-to-sample noise, read at the lower
#: quartile of the lag-1 residuals, which the swing itself inflates least) about the trend ...
SWING_SIGMAS = 2.0
#: ... or this fraction of the residuals' RMS about the trend if that is more ...
SWING_SPREAD = 0.5
#: ... whose durations and peak-to-trough heights scatter by at most this fraction of their means (red noise
#: wanders about its mean at no one period or height; a sawtooth sampled six times a cycle, its peak anywhere in
#: the last sampling interval, scatters by about 0.2/sqrt(12) = 0.06 in height) ...
UNRESOLVED_SCATTER = 0.1
#: ... and that spread about the trend by this many noise levels or more.
SWING_NOISE = 2.0


@dataclass(frozen=True)
class UnresolvedSwings:
    """Regular swings of a stretch of record about its trend, too coarsely sampled to be resolved into slips: how
    many whole swings, their mean duration (s), sampling intervals a swing, mean peak-to-trough height (Pa), the
    standard deviation about the trend (Pa) and the noise level the swings were judged against (Pa)."""

    swings: int
    period: float
    samples: float
    height: float
    spread: float
    noise: float

    def as_dict(self) -> dict[str, float | int]:
        return {
            "swings": self.swings,
            "period": self.period,
            "samples_per_swing": self.samples,
            "peak_to_trough": self.height,
            "spread": self.spread,
            "noise": self.noise,
        }


def _sample_level(stress: np.ndarray, time: np.ndarray) -> float:
    """The sample-to-sample noise at the lower quartile of the lag-1 residuals (which a sawtooth of a few samples a
    cycle inflates least), not below the quantisation's q/sqrt(12)."""
    return max(_lag_level(time, stress, 1, low=True), _quantisation_level(stress))


def _swings_about_trend(
    time: np.ndarray, stress: np.ndarray, level: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """The swings of a record about its straight-line trend: (sample index of each rise above a band after a fall
    below minus the band, the band :data:`SWING_SIGMAS` ``level`` or :data:`SWING_SPREAD` of the residuals' RMS if
    that is more (a sawtooth of six samples a cycle is all corners, and inflates any sample-to-sample noise
    estimate to a good part of its swing), the time of the zero crossing before it
    (interpolated), the peak-to-trough height of each whole swing between two such rises, the residuals about
    the trend); None with fewer than two rises."""
    n = time.size
    u = time - float(np.mean(time))
    spread = float(np.einsum("i,i", u, u))
    if n < 4 or not spread > 0:
        return None
    residual = stress - float(np.mean(stress))
    residual -= float(np.einsum("i,i", u, residual)) / spread * u
    band = max(SWING_SIGMAS * level, SWING_SPREAD * math.sqrt(float(np.einsum("i,i", residual, residual)) / n))
    if not band > 0:
        return None
    index = np.arange(n)
    sign = np.where(residual > band, 1, np.where(residual < -band, -1, 0))
    beyond = index[sign != 0]
    turns = beyond[1:][(sign[beyond[1:]] > 0) & (sign[beyond[:-1]] < 0)]  # first sample above +band after a low
    if turns.size < 2:
        return None
    last_low = np.maximum.accumulate(np.where(residual <= 0, index, -1))[turns - 1]  # the zero crossing before
    a, b = residual[last_low], residual[last_low + 1]
    ups = time[last_low] + (time[last_low + 1] - time[last_low]) * (-a / (b - a))
    # peak to trough of each whole swing: the highest point after one rise over the lowest before the next
    heights = (np.maximum.reduceat(residual, turns) - np.minimum.reduceat(residual, turns))[:-1]
    return turns, ups, heights, residual


def unresolved_swings(time: np.ndarray, stress: np.ndarray, noise: float, step: float) -> UnresolvedSwings | None:
    """The regular swings of a stretch that the search found no slip in (or no more after its last), when they come
    fewer than :data:`COARSE_CYCLE` samples apart; None when it has none.

    The swings are counted on the stretch less its straight-line trend, from each rise above
    :data:`SWING_SIGMAS` noise levels (or :data:`SWING_SPREAD` of the residuals' RMS) after a fall below minus as
    many (the zero crossing between them, interpolated, times the swing); ``noise`` is capped by the lower
    quartile of the lag-1 residuals, which a sawtooth of a few samples a cycle inflates least (the drop
    threshold's noise may be a stick line drawn across missed slips).  A sawtooth of six or eight samples a cycle
    swings by tens of noise levels at one period and one height; steady sliding, white or red noise, does neither
    (docs/analysis.md, "Six to fifteen samples a cycle").
    """
    if time.size < 2 * UNRESOLVED_SWINGS + 2 or not step > 0:
        return None
    level = min(noise, _sample_level(stress, time))
    found = _swings_about_trend(time, stress, level)
    if found is None:
        return None
    _, ups, heights, residual = found
    intervals = np.diff(ups)
    if intervals.size < UNRESOLVED_SWINGS:
        return None
    scatter = max(np.std(intervals) / np.mean(intervals), np.std(heights) / np.mean(heights))
    if not scatter <= UNRESOLVED_SCATTER:
        return None
    period = float(np.mean(intervals))
    spread = float(np.std(residual, ddof=2))
    if not period / step < COARSE_CYCLE or not spread >= SWING_NOISE * level:
        return None
    return UnresolvedSwings(
        swings=int(intervals.size),
        period=period,
        samples=period / step,
        height=float(np.mean(heights)),
        spread=spread,
        noise=level,
    )
