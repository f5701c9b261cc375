"""The solver's rows (one per accepted step) sampled onto a grid as they come (docs/transient.md section 10).

A run of the stick chains' limit cycle through the massless block with ``every`` is integrated exactly as without
it (the steps, the repeat of a settled cycle, the events: the same), and its rows are streamed through
:class:`Sampler`, which keeps only the grid's: at a grid instant between two rows, the stress, the slider's
position, the stress integral and the puller's work by the cubic Hermite interpolant through the two rows and their
known rates (dsigma/dt = K (Vp - V), dX/dt = V, d/dt int sigma dt = sigma, dW/dt = sigma Vp), the slider's velocity
from the stress's cubic, the other columns linearly (a held block in closed form); a row at the instant itself is
kept as it is.  The slips' instants are rows of their own (the jump's state, the last of the two rows there).  Each
row carries the extremes of the rows it closes (lowest, highest stress and their times, the fastest slider), as
the kernel's rows carry those of its steps, so a summary read from the samples is the run's own.  A repeated
cycle's copies (its rows shifted by whole periods) are sampled the same way, so their grid rows come from the
cycle's own solution; only the grid's rows are held, whatever the run's length.
"""

from __future__ import annotations

import numpy as np

#: columns of a trace row (solver._row): time, sigma, N, V, X, puller, ..., work, ..., block energy, chain fraction,
#: the integral of sigma dt, then the extremes since the row before (lowest, highest, their times, fastest V)
TIME, SIGMA, V, X, P, WORK, BLOCK_ENERGY, CHAINS, IMPULSE = 0, 1, 3, 4, 5, 8, 11, 12, 13
LOW, HIGH, T_LOW, T_HIGH, FAST = 14, 15, 16, 17, 18
#: no rows closed yet: the extremes' neutral elements (kernel.ACC_START's)
NONE_SEEN = (np.inf, -np.inf, np.nan, np.nan, -np.inf)


class Sampler:
    """Rows of a massless block (stiffness ``k_block``) streamed in time order, kept on ``grid`` and the instants
    given with them (:meth:`feed`); :meth:`rows` the kept ones."""

    def __init__(self, grid: np.ndarray, k_block: float) -> None:
        self.grid = np.asarray(grid, dtype=float)
        self.k_block = float(k_block)
        self.next = 0  # the next grid point to write
        self.anchor: np.ndarray | None = None  # the last row fed (the left end of the next interpolation)
        self.pending = np.array(NONE_SEEN)  # extremes of the rows fed after the last row written
        self.out: list[np.ndarray] = []
        self.last_written = -np.inf

    def feed(self, fine: np.ndarray, instants: np.ndarray | None = None) -> None:
        """Rows in time order after those fed before; ``instants``: times at which the row itself is kept (the
        last row at that time: a jump's state)."""
        fine = np.atleast_2d(np.asarray(fine, dtype=float))
        if not fine.size:
            return
        fine = fine[np.argsort(fine[:, TIME], kind="stable")]
        every = fine if self.anchor is None else np.vstack([self.anchor[None, :], fine])
        times = every[:, TIME]
        first, last = times[0], times[-1]
        start = self.next
        stop = int(np.searchsorted(self.grid, last, side="right"))
        grid = self.grid[start:stop]
        grid = grid[grid > first] if self.anchor is not None else grid[grid >= first]
        self.next = max(start, stop)
        wanted = grid
        if instants is not None and np.size(instants):
            inst = np.asarray(instants, dtype=float)
            inst = inst[(inst > max(first, self.last_written)) & (inst <= last)]
            wanted = np.union1d(grid, inst)
        wanted = wanted[wanted > self.last_written]
        rows = self._values(every, wanted)
        self._close(fine, wanted, rows)
        if wanted.size:
            self.out.append(rows)
            self.last_written = float(wanted[-1])
        self.anchor = fine[-1].copy()

    def rows(self) -> list[np.ndarray]:
        return self.out

    def _values(self, every: np.ndarray, wanted: np.ndarray) -> np.ndarray:
        """The state at each wanted instant: the last row at it, else the interpolant between its two rows."""
        times = every[:, TIME]
        right = np.searchsorted(times, wanted, side="right")  # first row after the instant
        exact = (right > 0) & (times[np.maximum(right - 1, 0)] == wanted)
        out = np.empty((wanted.size, every.shape[1]))
        out[exact] = every[right[exact] - 1]
        between = ~exact
        if between.any():
            i = right[between] - 1
            a, b = every[i], every[i + 1]
            h = b[:, TIME] - a[:, TIME]
            s = (wanted[between] - a[:, TIME]) / h
            rows = a + s[:, None] * (b - a)
            gap = np.isnan(a) | np.isnan(b)  # a column defined on one side only: the state the interval ends in
            rows[gap] = b[gap]
            vp = (b[:, P] - a[:, P]) / h
            k = self.k_block
            for column, rate_a, rate_b in (
                (SIGMA, k * (vp - a[:, V]), k * (vp - b[:, V])),
                (X, a[:, V], b[:, V]),
                (IMPULSE, a[:, SIGMA], b[:, SIGMA]),
                (WORK, a[:, SIGMA] * vp, b[:, SIGMA] * vp),
            ):
                value = _hermite(a[:, column], b[:, column], rate_a, rate_b, h, s)
                ok = np.isfinite(value)
                rows[ok, column] = value[ok]
            # the slider's velocity from the stress's rate, V = Vp - (dsigma/dt)/K, on the same cubic (third order
            # between the rows, where a line through the two velocities was second: 6.5e-4 of the fastest slider
            # in the paper's slip, against 1e-4 rtol)
            rate = _hermite_rate(a[:, SIGMA], b[:, SIGMA], k * (vp - a[:, V]), k * (vp - b[:, V]), h, s)
            velocity = np.where((a[:, V] == 0.0) & (b[:, V] == 0.0), 0.0, vp - rate / k)  # a held slider: held
            ok = np.isfinite(velocity)
            rows[ok, V] = velocity[ok]
            rows[:, TIME] = wanted[between]
            # an instant where the chains hold the block (the row after it stuck): the held slider in closed form,
            # sigma = K (P - X) rising linearly, its integral exact (the stuck rows' own, solver._stuck_rows)
            held = np.isfinite(b[:, CHAINS]) & (b[:, V] == 0.0)
            if held.any():
                rows[held, X], rows[held, V] = b[held, X], 0.0
                rows[held, SIGMA] = k * (rows[held, P] - b[held, X])
                ahead = b[held, TIME] - rows[held, TIME]
                rows[held, IMPULSE] = b[held, IMPULSE] - 0.5 * ahead * (rows[held, SIGMA] + b[held, SIGMA])
            rows[:, BLOCK_ENERGY] = rows[:, SIGMA] ** 2 / (2 * k)
            out[between] = rows
        return out

    def _close(self, fine: np.ndarray, wanted: np.ndarray, rows: np.ndarray) -> None:
        """Each written row's extremes: those of the rows fed since the row written before it (and its own state),
        the earliest on a tie, as kernel._write_row closes its steps; what follows the last is left pending."""
        groups = np.searchsorted(wanted, fine[:, TIME], side="left")  # the first written row at or after each row
        m = wanted.size
        group = np.r_[0, groups]
        ext = np.vstack([self.pending[None, :], fine[:, LOW:]])
        low = np.full(m + 1, np.inf)
        high = np.full(m + 1, -np.inf)
        fast = np.full(m + 1, -np.inf)
        np.fmin.at(low, group, ext[:, 0])
        np.fmax.at(high, group, ext[:, 1])
        np.fmax.at(fast, group, ext[:, 4])
        t_low = np.full(m + 1, np.nan)
        t_high = np.full(m + 1, np.nan)
        for values, col, when in ((low, 0, t_low), (high, 1, t_high)):
            hit = ext[:, col] == values[group]
            found, index = np.unique(group[hit], return_index=True)
            when[found] = ext[hit, col + 2][index]
        self.pending = np.array([low[m], high[m], t_low[m], t_high[m], fast[m]])
        if not m:
            return
        own_sigma, own_v, own_t = rows[:, SIGMA], rows[:, V], rows[:, TIME]
        lower = low[:m] < own_sigma
        higher = high[:m] > own_sigma
        rows[:, LOW] = np.where(lower, low[:m], own_sigma)
        rows[:, T_LOW] = np.where(lower, t_low[:m], own_t)
        rows[:, HIGH] = np.where(higher, high[:m], own_sigma)
        rows[:, T_HIGH] = np.where(higher, t_high[:m], own_t)
        rows[:, FAST] = np.fmax(fast[:m], own_v)


def _hermite(
    y0: np.ndarray, y1: np.ndarray, m0: np.ndarray, m1: np.ndarray, h: np.ndarray, s: np.ndarray
) -> np.ndarray:
    """The cubic through (0, y0) and (h, y1) with slopes m0, m1, at s h."""
    s2, s3 = s * s, s * s * s
    return (2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * h * m0 + (3 * s2 - 2 * s3) * y1 + (s3 - s2) * h * m1


def _hermite_rate(
    y0: np.ndarray, y1: np.ndarray, m0: np.ndarray, m1: np.ndarray, h: np.ndarray, s: np.ndarray
) -> np.ndarray:
    """The time derivative of :func:`_hermite`'s cubic at s h."""
    s2 = s * s
    return ((6 * s2 - 6 * s) * (y0 - y1)) / h + (3 * s2 - 4 * s + 1) * m0 + (3 * s2 - 2 * s) * m1
