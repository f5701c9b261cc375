"""Coarse segmentation of a stress record into stick rises and slip drops.

This step only finds *where* the phases are, to a few samples (the numbers per cycle come from :mod:`.cycles`):
a robust noise level, a median-filtered uniform resampling, drops as peaks of prominence above
:data:`PROMINENCE_SIGMAS` noise levels, and what the record does after its last peak (docs/analysis.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import median_filter, uniform_filter1d
from scipy.signal import find_peaks

#: A drop counts as a slip when it exceeds this many noise standard deviations.
PROMINENCE_SIGMAS = 10.0
#: Width (samples) of the median filter used for the coarse search.
MEDIAN_WIDTH = 5
#: Largest uniform grid used for the coarse search (long records are decimated).
MAX_GRID = 200_000
#: A steady tail stays within this fraction of the drop threshold of its final level ...
STEADY_BAND = 0.25
#: ... judged on a running mean over this many grid points.
STEADY_AVERAGE = 25
#: A record without slips has settled if its final flat stretch is at least this fraction of it.
SETTLED_FRACTION = 0.25
#: MAD -> standard deviation for Gaussian noise.
MAD_SCALE = 1.482602218505602


@dataclass(frozen=True)
class Coarse:
    """Approximate turning points of a record (times in s, stresses of the smoothed curve).

    ``peaks`` are the drop events; ``troughs[k]`` is the candidate start of the
    stick phase that ends at ``peaks[k]`` (``troughs[0]`` may be spurious when
    the record starts mid-stick: the fits decide); ``final_trough`` is the
    start of a stick phase cut by the end of the record, or None.  When the
    record ends in steady sliding, ``steady_from`` is where the flat stretch
    begins (for a record without slips: None when it never settles).
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


def noise_level(time: np.ndarray, stress: np.ndarray) -> float:
    """Robust standard deviation of white noise on a piecewise-smooth record (finite samples only)."""
    t, x = time, stress
    if t.size < 3:
        return 0.0
    # in place where possible: a 10^7-sample record makes each temporary 80 MB
    left, w_prev = t[1:-1] - t[:-2], t[2:] - t[1:-1]
    x_prev, x_mid, x_next = x[:-2], x[1:-1], x[2:]
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
    return float(MAD_SCALE * np.median(np.abs(residual, out=residual), overwrite_input=True))


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


def coarse_segments(time: np.ndarray, stress: np.ndarray) -> Coarse:
    """Find drop events, troughs and a steady tail in a record of finite samples."""
    noise = noise_level(time, stress)
    step = sampling_step(time)
    grid, raw = uniform_grid(time, stress, step)
    smooth = median_filter(raw, size=min(MEDIAN_WIDTH, raw.size), mode="nearest")
    scale = float(np.max(np.abs(smooth))) if smooth.size else 0.0
    threshold = max(PROMINENCE_SIGMAS * noise, 1e-9 * scale, 1e-300)
    peaks = _separated(smooth, find_peaks(smooth, prominence=threshold)[0], threshold)
    troughs = np.empty(peaks.size, dtype=int)
    for k, p in enumerate(peaks):
        lo = peaks[k - 1] if k else 0
        troughs[k] = lo + rise_start(smooth[lo : p + 1], threshold)
    final_trough = None
    steady_from = None
    last = peaks[-1] if peaks.size else 0
    tail = smooth[last:]
    if peaks.size:
        q = last + rise_start(tail, threshold)
        if smooth[-1] - np.min(tail) > threshold and q < smooth.size - 1:
            final_trough = q
        else:
            steady_from = _steady_tail(grid, smooth, last, threshold, _longest_stick(grid, peaks, troughs))
    else:  # no slip: where the record has settled, if it did for a quarter of its length
        steady_from = _steady_tail(grid, smooth, 0, threshold, SETTLED_FRACTION * float(grid[-1] - grid[0]))
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
    )


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


def _steady_tail(grid: np.ndarray, smooth: np.ndarray, start: int, threshold: float, stick: float) -> float | None:
    """Start of the flat stretch that ends the record, if it outlasts the longest stick phase.

    Flat means within :data:`STEADY_BAND` drop thresholds of the final level,
    judged on a running mean (so that the noise itself never leaves the band).
    """
    width = min(STEADY_AVERAGE, max(1, (smooth.size - start) // 4))
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
