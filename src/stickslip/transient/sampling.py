"""The solver's rows (one per accepted step) sampled onto a grid as they come (docs/transient.md sections 10, 19).

A run with ``every`` is integrated exactly as without it, whatever the control (the steps, the repeat of a settled
cycle, the events: the same) and its rows are streamed through :class:`Sampler`, which keeps only the grid's (and
the protocol's boundaries and the slips' instants): at an instant between two rows each column by the cubic Hermite
interpolant through the two rows and their rates; a row at the instant itself is kept as it is.  The rates are the
rows' own where the model gives them: dX/dt = V, d/dt int sigma dt = sigma, dW/dt = (the force the puller works
against) Vp, through the massless block dsigma/dt = K (Vp - V) (the slider's velocity then from the stress's
cubic), with a mass dV/dt = (K (P - X) - eta V - sigma)/m.  The others (the interface's stress under velocity
control and with a mass, the bonded count, the running totals, the bonds' energy) are read from the rows: those of
the polynomial through the interval's rows and up to two more on each side within one smooth stretch (not across a
protocol boundary, where the pace jumps), so the last two rows fed wait for the next; such a stress is then held to
the solver's own integral over the interval (:func:`_stress_with_integral`).  A held block is in closed form, and
under velocity control the velocity is the protocol's.  An interpolated stress, velocity or bonded count stays
within its two rows' (a cubic's overshoot at a turn is no state of the solver), so the rows carry no extreme the
solver did not reach; but a peak of the stress between two rows is located on that cubic into the row's highest
stress (:func:`locate_peaks`, as on the unsampled trace: docs/transient.md section 19).

The slips' instants are rows of their own (the jump's state, the last of the rows there).  Each row carries the
extremes of the rows it closes (lowest, highest stress and their times, the fastest slider), as the kernel's rows
carry those of its steps; of rows at one instant only the first counts, as the unsampled trace keeps only the first
(solver._finish), so a summary read from the samples is the run's own.  A repeated cycle's copies (its rows shifted
by whole periods) are sampled the same way, so their grid rows come from the cycle's own solution; only the grid's
rows are held, whatever the run's length.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

#: columns of a trace row (solver._row): time, sigma, N, V, X, puller, ..., work, ..., block energy, chain fraction,
#: the integral of sigma dt, then the extremes since the row before (lowest, highest, their times, fastest V)
TIME, SIGMA, V, X, P, WORK, BLOCK_ENERGY, CHAINS, IMPULSE = 0, 1, 3, 4, 5, 8, 11, 12, 13
LOW, HIGH, T_LOW, T_HIGH, FAST = 14, 15, 16, 17, 18
#: no rows closed yet: the extremes' neutral elements (kernel.ACC_START's)
NONE_SEEN = (np.inf, -np.inf, np.nan, np.nan, -np.inf)
BONDED, BORN, BROKEN, DISSIPATION, BOND_ENERGY = 2, 6, 7, 9, 10
#: grid points interpolated at a time
BATCH = 20_000
#: a rate read from the rows takes up to this many rows on each side of the interval (the polynomial through six
#: rows: its rates within O(h^5), the cubic Hermite with them then within about h^4 max|f^(4)|/384)
NEIGHBOURS = 2
#: the most rows a sampler keeps since the last slip (:meth:`Sampler.since_last_slip`, what the verdict on a slide
#: settling after it reads: cycles.settled_after_slip); beyond them the verdict reads the sampled rows
TAIL_ROWS = 500_000


class Sampler:
    """Rows streamed in time order (:meth:`feed`), kept on ``grid`` and the instants given with them; :meth:`rows`
    the kept ones (after :meth:`flush`, which samples what still waits).

    ``control``: "block" (a spring of stiffness ``k_block`` drives the slider; with ``mass`` and ``damping`` a
    block with inertia) or "velocity" (the protocol moves the slider).  ``breaks``: the instants where the pace
    jumps (the protocol's boundaries), where a rate read from the rows takes no neighbour across; ``instants``:
    times whose row is kept as it is (the protocol's boundaries, where a summary's window starts), a grid point
    within 1e-9 of the grid's spacing of one standing for it."""

    def __init__(
        self,
        grid: np.ndarray,
        k_block: float,
        *,
        control: str = "block",
        mass: float = 0.0,
        damping: float = 0.0,
        breaks: Sequence[float] | np.ndarray = (),
        instants: Sequence[float] | np.ndarray = (),
    ) -> None:
        self.grid = np.array(grid, dtype=float)
        kept = np.unique(np.asarray(instants, dtype=float))
        if self.grid.size > 1 and kept.size:  # a grid point on an instant (to rounding) is that instant
            spacing = float(self.grid[1] - self.grid[0])
            near = np.clip(np.searchsorted(self.grid, kept), 1, self.grid.size - 1)
            near = np.where(np.abs(self.grid[near - 1] - kept) < np.abs(self.grid[near] - kept), near - 1, near)
            on = np.abs(self.grid[near] - kept) <= 1e-9 * spacing
            self.grid[near[on]] = kept[on]
        self.k_block = float(k_block)
        self.rigid = control == "velocity"  # no spring: the protocol moves the slider
        self.mass, self.damping = float(mass), float(damping)
        #: the stress's rate is a row's own only through the massless block; otherwise read from the rows around
        self.known_rate = not self.rigid and self.mass == 0.0
        self.breaks = np.unique(np.asarray(breaks, dtype=float))
        self.jumps: list[float] = []  # instants of the massless block's jumps (no row holds the state after one)
        self.slips = np.empty(0)  # the slips' instants given with the rows (no peak is located across one)
        self.next = 0  # the next grid point to write
        self.anchor: np.ndarray | None = None  # the last row sampled through (the left end of the next interval)
        self.before = np.empty((0, 0))  # the rows before it (its left neighbours, for the rates read from rows)
        self.waiting: np.ndarray | None = None  # the last rows fed, until those after them give their rates
        self.instants = kept  # instants given, still ahead of the rows sampled through
        self.pending = np.array(NONE_SEEN)  # extremes of the rows fed after the last row written
        self.out: list[np.ndarray] = []
        self.last_written = -np.inf
        # every row since the last slip, as the unsampled trace has them (None: more than TAIL_ROWS)
        self.tail: list[np.ndarray] | None = []
        self.tail_rows = 0
        self.tail_from = -np.inf

    def feed(self, fine: np.ndarray, instants: np.ndarray | None = None) -> None:
        """Rows in time order after those fed before; ``instants``: times at which the row itself is kept (the
        last row at that time: a jump's state)."""
        fine = np.atleast_2d(np.asarray(fine, dtype=float))
        if not fine.size:
            return
        if self.waiting is not None:
            fine = np.vstack([self.waiting, fine])
            self.waiting = None
        fine = fine[np.argsort(fine[:, TIME], kind="stable")]
        if instants is not None and np.size(instants):
            self.instants = np.union1d(self.instants, np.asarray(instants, dtype=float))
            self.slips = np.union1d(self.slips, np.asarray(instants, dtype=float))
        # the last rows wait for the next: the rates read from the rows take up to NEIGHBOURS on each side
        self.waiting = fine[-NEIGHBOURS:].copy()
        self._sample(fine[:-NEIGHBOURS], self.waiting)

    def flush(self) -> None:
        """Sample what waits (the last rows' rates from the rows before them): the run has ended."""
        if self.waiting is not None:
            last, self.waiting = self.waiting, None
            self._sample(last, None)

    def rows(self) -> list[np.ndarray]:
        return self.out

    def _sample(self, fine: np.ndarray, ahead: np.ndarray | None) -> None:
        """The grid points and instants up to the last of ``fine`` (``ahead``: the rows after it, for the rates read
        from the rows; None at the run's end)."""
        if not fine.size:
            return
        context = [] if self.anchor is None else [self.before.reshape(-1, fine.shape[1]), self.anchor[None, :]]
        offset = sum(len(r) for r in context)  # rows of ``every`` before ``fine``
        every = np.vstack([*context, fine, *([] if ahead is None else [ahead])])
        # the stress's peaks between the rows fed, into their highest (each row closes the interval before it)
        locate_peaks(
            every, offset, offset + fine.shape[0], k_block=self.k_block, known_rate=self.known_rate,
            breaks=self.breaks, events=np.r_[self.slips, self.jumps],
        )  # fmt: skip
        fine = every[offset : offset + fine.shape[0]]
        times = every[:, TIME]
        first, last = times[offset - 1] if self.anchor is not None else times[0], float(fine[-1, TIME])
        start = self.next
        stop = int(np.searchsorted(self.grid, last, side="right"))
        grid = self.grid[start:stop]
        grid = grid[grid > first] if self.anchor is not None else grid[grid >= first]
        self.next = max(start, stop)
        wanted = grid
        inst = self.instants[(self.instants > max(first, self.last_written)) & (self.instants <= last)]
        self.instants = self.instants[self.instants > last]
        if inst.size:
            wanted = np.union1d(grid, inst)
        wanted = wanted[wanted > self.last_written]
        rows = self._values(every, wanted)
        # of rows at one instant the trace keeps the first (solver._finish): the others close no extreme
        previous = np.r_[-np.inf if self.anchor is None else self.anchor[TIME], fine[:-1, TIME]]
        first = fine[fine[:, TIME] > previous]
        self._close(first, wanted, rows)
        self._keep_since_slip(first)
        if wanted.size:
            self.out.append(rows)
            self.last_written = float(wanted[-1])
        chain = every[: offset + fine.shape[0]]
        self.before = chain[-1 - NEIGHBOURS : -1].copy()
        self.anchor = chain[-1].copy()

    def since_last_slip(self) -> np.ndarray | None:
        """Every row from the last slip on (the first at each instant, the stress's peaks between them located), as
        the unsampled trace holds them: a slide's settling after its last slip is judged on these, so that ``every``
        cannot move the verdict (cycles.settled_after_slip); None where no slip was given or they were too many."""
        if not self.tail:
            return None
        return np.vstack(self.tail)

    def _keep_since_slip(self, rows: np.ndarray) -> None:
        if self.tail is None or not self.slips.size:
            return
        last = float(self.slips[-1])
        if last > self.tail_from:  # a later slip: the rows before it are no longer needed
            kept = np.vstack(self.tail) if self.tail else np.empty((0, rows.shape[1]))
            self.tail = [kept[kept[:, TIME] >= last]]
            self.tail_rows, self.tail_from = len(self.tail[0]), last
        rows = rows[rows[:, TIME] >= last]
        if rows.size:
            self.tail.append(rows.copy())
            self.tail_rows += len(rows)
        if self.tail_rows > TAIL_ROWS:
            self.tail = None

    def _values(self, every: np.ndarray, wanted: np.ndarray) -> np.ndarray:
        """The state at each wanted instant: the last row at it, else the interpolant between its two rows."""
        times = every[:, TIME]
        right = np.searchsorted(times, wanted, side="right")  # first row after the instant
        exact = (right > 0) & (times[np.maximum(right - 1, 0)] == wanted)
        out = np.empty((wanted.size, every.shape[1]))
        out[exact] = every[right[exact] - 1]
        between = np.flatnonzero(~exact)
        for first in range(0, between.size, BATCH):  # (a bounded working set, however many grid points at once)
            part = between[first : first + BATCH]
            out[part] = self._between(every, right[part] - 1, wanted[part])
        return out

    def _between(self, every: np.ndarray, i: np.ndarray, when: np.ndarray) -> np.ndarray:
        """The state at ``when`` inside the intervals (i, i + 1) of ``every``."""
        a, b = every[i], every[i + 1]
        h = b[:, TIME] - a[:, TIME]
        s = (when - a[:, TIME]) / h
        rows = a + s[:, None] * (b - a)
        gap = np.isnan(a) | np.isnan(b)  # a column defined on one side only: the state the interval ends in
        rows[gap] = b[gap]
        vp = (b[:, P] - a[:, P]) / h
        k = self.k_block
        read = _rate_weights(every[:, TIME], i, self._broken(every[:, TIME]))
        if self.known_rate:  # the massless block: dsigma/dt = K (Vp - V)
            rate_a, rate_b = k * (vp - a[:, V]), k * (vp - b[:, V])
        else:
            rate_a, rate_b = _read_rates(every[:, SIGMA], read)
        if self.rigid:  # the protocol's velocity: the segment's the interval ends in (its first row may end the last)
            velocity_a = velocity_b = b[:, V]
            force_a, force_b = a[:, SIGMA], b[:, SIGMA]
        else:
            velocity_a, velocity_b = a[:, V], b[:, V]
            force_a, force_b = a[:, SIGMA], b[:, SIGMA]
            if self.mass > 0:  # the puller works against the spring, K (P - X)
                force_a, force_b = k * (a[:, P] - a[:, X]), k * (b[:, P] - b[:, X])
        columns = [
            (X, velocity_a, velocity_b),
            (IMPULSE, a[:, SIGMA], b[:, SIGMA]),
            (WORK, force_a * vp, force_b * vp),
        ]
        if self.known_rate:
            columns.append((SIGMA, rate_a, rate_b))
        if self.mass > 0:  # m dV/dt = K (P - X) - eta V - sigma
            accel_a = (force_a - self.damping * a[:, V] - a[:, SIGMA]) / self.mass
            accel_b = (force_b - self.damping * b[:, V] - b[:, SIGMA]) / self.mass
            columns.append((V, accel_a, accel_b))
        # the bonded count, the running totals of bonds born and broken and of the energy dissipated, and the bonds'
        # energy: rates read from the rows (no row carries them)
        for column in (BONDED, BORN, BROKEN, DISSIPATION, BOND_ENERGY):
            columns.append((column, *_read_rates(every[:, column], read)))
        for column, slope_a, slope_b in columns:
            value = _hermite(a[:, column], b[:, column], slope_a, slope_b, h, s)
            ok = np.isfinite(value)
            rows[ok, column] = value[ok]
        if not self.known_rate:  # with the solver's integral over the interval
            value = _stress_with_integral(a, b, rate_a, rate_b, h, s)
            ok = np.isfinite(value)
            rows[ok, SIGMA] = value[ok]
        if self.rigid:
            rows[:, V] = b[:, V]
        elif self.known_rate:
            # the slider's velocity from the stress's rate, V = Vp - (dsigma/dt)/K, on the same cubic (third order
            # between the rows, where a line through the two velocities was second: 6.5e-4 of the fastest slider
            # in the paper's slip, against 1e-4 rtol)
            rate = _hermite_rate(a[:, SIGMA], b[:, SIGMA], rate_a, rate_b, h, s)
            velocity = np.where((a[:, V] == 0.0) & (b[:, V] == 0.0), 0.0, vp - rate / k)  # a held slider: held
            ok = np.isfinite(velocity)
            rows[ok, V] = velocity[ok]
        # a turn between the rows: the cubic's overshoot is no state of the solver (the rows' own hold its extremes)
        for column in (SIGMA, V, BONDED):
            low, high = np.fmin(a[:, column], b[:, column]), np.fmax(a[:, column], b[:, column])
            ok = np.isfinite(low) & np.isfinite(high)
            rows[ok, column] = np.clip(rows[ok, column], low[ok], high[ok])
        rows[:, TIME] = when
        if self.known_rate:
            # an instant where the chains hold the block (the row after it stuck): the held slider in closed form,
            # sigma = K (P - X) rising linearly, its integral exact (the stuck rows' own, solver._stuck_rows)
            held = np.isfinite(b[:, CHAINS]) & (b[:, V] == 0.0)
            if held.any():
                rows[held, X], rows[held, V] = b[held, X], 0.0
                rows[held, SIGMA] = k * (rows[held, P] - b[held, X])
                ahead = b[held, TIME] - rows[held, TIME]
                rows[held, IMPULSE] = b[held, IMPULSE] - 0.5 * ahead * (rows[held, SIGMA] + b[held, SIGMA])
        if self.jumps:  # after a jump of the massless block (transient/jump.py): the state it jumped to
            jumped = np.isin(a[:, TIME], self.jumps)
            rows[jumped, 1:] = b[jumped, 1:]
        if self.rigid:
            rows[:, BLOCK_ENERGY] = 0.0
        elif self.mass > 0:  # the spring's own stretch, and the moving block's kinetic energy
            rows[:, BLOCK_ENERGY] = 0.5 * k * (rows[:, P] - rows[:, X]) ** 2 + 0.5 * self.mass * rows[:, V] ** 2
        else:
            rows[:, BLOCK_ENERGY] = rows[:, SIGMA] ** 2 / (2 * k)
        return rows

    def _broken(self, times: np.ndarray) -> np.ndarray:
        """Rows at a protocol boundary (the pace jumps there: a rate read from the rows takes no neighbour across)."""
        return broken_rows(times, self.breaks)

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


def broken_rows(times: np.ndarray, breaks: np.ndarray) -> np.ndarray:
    """Rows at a protocol boundary ``breaks`` (sorted; the pace jumps there: a rate read from the rows takes no
    neighbour across)."""
    n = breaks.size
    if not n:
        return np.zeros(times.size, dtype=bool)
    k = np.searchsorted(breaks, times)
    near = np.minimum(np.abs(times - breaks[np.clip(k - 1, 0, n - 1)]), np.abs(times - breaks[np.clip(k, 0, n - 1)]))
    return near <= 1e-12 * np.maximum(np.abs(times), 1.0)


#: a peak located between two rows counts only within this share of the largest change of the stress over its
#: interval and the intervals either side beyond the rows (a smooth peak lies within an eighth of it where the steps are
#: even, a third where one is twice the other) ...
PEAK_REACH = 0.5
#: ... and where the polynomial through the peak's row and two rows on each side puts it within this share of that
#: excess (a resolved peak: the two agree to 3e-3-0.08 of it at rtol 1e-7-1e-3 on a velocity step; a block with mass
#: ringing at three steps a period, whose rows do not resolve the ring, disagrees by more than the excess)
PEAK_AGREEMENT = 0.5
#: points on which that polynomial is searched between the peak's neighbours
PEAK_GRID = 129
#: and beyond the rows by more than this share of the stress (rounding: a flat stretch's rates are rounding), at a
#: peak whose rows change by more than PEAK_FLOOR of it (no peak below is worth locating)
ROUNDING = 1e-12
PEAK_FLOOR = 1e-10


def locate_peaks(
    every: np.ndarray,
    first: int,
    last: int,
    *,
    k_block: float,
    known_rate: bool,
    breaks: np.ndarray,
    events: np.ndarray,
) -> None:
    """The stress's peaks between rows, located on the interpolant the rows are sampled on, into the highest stress
    of the rows that close them (in place; rows ``first`` to ``last`` - 1 of ``every``, each closing the interval
    from the row before it).

    A row's highest stress was the highest of the solver's states at its steps, and a peak between two steps was
    read at the nearer step: a velocity step from 350 um/s to 3.5 mm/s peaks 105 us later at 1495.7563 Pa, read
    0.65 Pa low at rtol 1e-4 (steps of 5.9 us there; 0.004 Pa high, 0.093, 0.041 and 0.0038 Pa low at rtol 1e-3,
    1e-5, 1e-6, 1e-7), while the states at the steps were within 1.1e-3 Pa of a tight run's.  At each row where
    the rows peak (a rise before it, none after), the intervals either side are searched on their cubic: the rows'
    values and rates, the rates K (Vp - V) of a massless block or read from the rows and held to the solver's
    integral over the interval (:func:`_integral_rates`, the cubic :func:`_stress_with_integral` samples).  Left
    out: an interval with a held slider (the stick chains'), with no length, or whose rows within two of it reach
    one of ``events`` (the slips' and jumps' instants, and any with two rows: a kink no cubic follows), and a peak
    beyond :data:`PEAK_REACH` or away from the polynomial through five rows (:data:`PEAK_AGREEMENT`).  The troughs
    are the steps' (a trough located so moved tests/test_transient_split.py's ``velocity_step`` lowest stress by
    7.7e-4 Pa at one row, beyond the 1e-6 of its largest value that test holds)."""
    n = every.shape[0]
    if last <= max(first, 1) or n < 3:
        return
    times, sigma = every[:, TIME], every[:, SIGMA]
    # two rows at one instant are a jump's (the trace keeps the first: solver._finish, which gives their instants)
    events = np.union1d(np.asarray(events, dtype=float), times[1:][np.diff(times) == 0.0])
    with np.errstate(invalid="ignore"):  # a row without a stress (NaN) compares False: it is never a peak
        d = np.diff(sigma)
        peak = np.flatnonzero((d[:-1] > 0.0) & (d[1:] <= 0.0)) + 1  # rows with a rise before and none after
    peak = peak[(peak + 1 >= max(first, 1)) & (peak < last)]  # (either interval closed by a row of first..last - 1)
    # how far the stress changes over the two intervals and those either side
    reach = np.abs(d[peak - 1])
    for k in (peak - 2, peak, peak + 1):
        inside = (k >= 0) & (k < d.size)
        reach = np.fmax(reach, np.where(inside, np.abs(d[np.clip(k, 0, d.size - 1)]), 0.0))
    worth = reach > PEAK_FLOOR * np.abs(sigma[peak])  # (steady sliding's rows wander by ~2e-12: 60 000 such peaks)
    peak, reach = peak[worth], reach[worth]
    if not peak.size:
        return
    y1 = sigma[peak]
    vertex = _quartic_peaks(times, sigma, peak)  # the polynomial through the peak's row and two on each side
    for j in (peak, peak + 1):  # the intervals (j - 1, j) either side of the peak's row, each on its own
        mine = (j >= max(first, 1)) & (j < last)
        value, when = _cubic_peaks(every, j[mine], k_block=k_block, known_rate=known_rate, breaks=breaks, events=events)
        excess = value - y1[mine]
        # an interval with no turn inside gives NaN (value, vertex): NaN compares False, so its row keeps its own value
        with np.errstate(invalid="ignore"):
            ok = (excess > ROUNDING * np.abs(y1[mine])) & (excess <= PEAK_REACH * reach[mine])
            ok &= np.abs(value - vertex[mine]) <= PEAK_AGREEMENT * excess
        rows = j[mine][ok]
        raise_ = value[ok] > every[rows, HIGH]
        every[rows[raise_], HIGH], every[rows[raise_], T_HIGH] = value[ok][raise_], when[ok][raise_]


def _quartic_peaks(times: np.ndarray, sigma: np.ndarray, peak: np.ndarray) -> np.ndarray:
    """The highest value between rows peak - 1 and peak + 1 of the polynomial through rows peak - 2 ... peak + 2
    (fourth degree; on :data:`PEAK_GRID` points), nan where those rows do not exist or are not in time order."""
    n = times.size
    offsets = np.arange(-2, 3)
    rows = peak[:, None] + offsets[None, :]
    exists = np.all((rows >= 0) & (rows < n), axis=1)
    rows = np.clip(rows, 0, n - 1)
    scale = times[rows[:, 3]] - times[rows[:, 1]]
    # rows beyond the trace (clipped) or at one instant give NaN or inf here; ``exists`` and the agreement test
    # below reject such a peak, so it keeps its row's value
    with np.errstate(invalid="ignore", divide="ignore"):
        x = (times[rows] - times[peak][:, None]) / scale[:, None]  # (centred and scaled: well conditioned)
        coef = sigma[rows].astype(float)  # Newton's divided differences, in place
        for level in range(1, 5):
            coef[:, level:] = (coef[:, level:] - coef[:, level - 1 : -1]) / (x[:, level:] - x[:, : 5 - level])
        grid = x[:, 1:2] + (x[:, 3:4] - x[:, 1:2]) * np.linspace(0.0, 1.0, PEAK_GRID)[None, :]
        value = np.repeat(coef[:, 4:5], PEAK_GRID, axis=1)
        for level in range(3, -1, -1):
            value = value * (grid - x[:, level : level + 1]) + coef[:, level : level + 1]
        best = np.max(value, axis=1)
    ordered = np.all(np.diff(times[rows], axis=1) > 0, axis=1)
    return np.where(exists & ordered & np.isfinite(best), best, np.nan)


def _cubic_peaks(
    every: np.ndarray, j: np.ndarray, *, k_block: float, known_rate: bool, breaks: np.ndarray, events: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(the highest value, its time) of the cubic over each interval (j - 1, j) of ``every`` (:func:`locate_peaks`)
    where it peaks inside; -inf, nan where it does not or the interval is left out."""
    n = every.shape[0]
    value = np.full(j.size, -np.inf)
    when = np.full(j.size, np.nan)
    i = j - 1
    inside = (i >= 0) & (j < n)
    i, jj = np.clip(i, 0, n - 1), np.clip(j, 0, n - 1)
    times, sigma = every[:, TIME], every[:, SIGMA]
    a, b = every[i], every[jj]
    h = b[:, TIME] - a[:, TIME]
    ok = inside & (h > 0) & np.isfinite(a[:, SIGMA]) & np.isfinite(b[:, SIGMA])
    ok &= ~np.isfinite(a[:, CHAINS]) & ~np.isfinite(b[:, CHAINS])  # the stick chains hold the slider
    if np.size(events):
        marks = events  # (sorted)
        near_lo, near_hi = times[np.maximum(i - 2, 0)], times[np.minimum(jj + 2, n - 1)]
        ok &= np.searchsorted(marks, near_lo, side="left") == np.searchsorted(marks, near_hi, side="right")
    if not ok.any():
        return value, when
    pick = np.flatnonzero(ok)
    i, a, b, h = i[pick], a[pick], b[pick], h[pick]
    if known_rate:  # the massless block: dsigma/dt = K (Vp - V)
        vp = (b[:, P] - a[:, P]) / h
        rate_a, rate_b = k_block * (vp - a[:, V]), k_block * (vp - b[:, V])
    else:
        rate_a, rate_b = _read_rates(sigma, _rate_weights(times, i, broken_rows(times, breaks)))
        rate_a, rate_b, _, _ = _integral_rates(a, b, rate_a, rate_b, h)
    sa, sb = a[:, SIGMA], b[:, SIGMA]
    # the cubic's turns: the roots in (0, 1) of its derivative in s, quad s^2 + lin s + const
    quad = 6.0 * (sa - sb) + 3.0 * h * (rate_a + rate_b)
    lin = -6.0 * (sa - sb) - 4.0 * h * rate_a - 2.0 * h * rate_b
    const = h * rate_a
    # no real turn (negative discriminant) is NaN by construction and a flat cubic divides by ~0: both are left out
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.sqrt(np.where(lin * lin - 4.0 * quad * const >= 0.0, lin * lin - 4.0 * quad * const, np.nan))
        q = -0.5 * (lin + np.copysign(root, lin))
        flat = np.abs(quad) <= 1e-12 * (np.abs(lin) + np.abs(const))
        roots = (np.where(flat, -const / lin, q / quad), np.where(flat, np.nan, const / q))
    top = np.full(pick.size, -np.inf)
    top_t = np.full(pick.size, np.nan)
    for s in roots:
        found = np.isfinite(s) & (s > 0.0) & (s < 1.0)
        at = np.where(found, s, 0.5)
        cubic = np.where(found, _hermite(sa, sb, rate_a, rate_b, h, at), -np.inf)
        higher = cubic > top
        top, top_t = np.where(higher, cubic, top), np.where(higher, a[:, TIME] + at * h, top_t)
    value[pick], when[pick] = top, top_t
    return value, when


def _stress_with_integral(
    a: np.ndarray, b: np.ndarray, rate_a: np.ndarray, rate_b: np.ndarray, h: np.ndarray, s: np.ndarray
) -> np.ndarray:
    """The stress between rows a and b whose rates were read from the rows (:func:`_rate_weights`): the cubic with the
    rows' values and those rates shifted alike so that its integral over the interval is the solver's (the kernel's
    end-corrected trapezoid is the integral of its own cubic through the step's ends and exact rates, so the
    difference of the rates is then the kernel's; under velocity control the energy balance's integral); where that
    cubic leaves the two rows' range while their mean lies inside it (a step the error control let grow long: 0.1
    um/s, one 6 s step from 5.7 to 88.3 kPa), sigma_a + (sigma_b - sigma_a) s^p with that integral.  Where the
    interval's integral is rounding (or not known), the cubic with the rates read."""
    sa, sb = a[:, SIGMA], b[:, SIGMA]
    rate_a, rate_b, mean, known = _integral_rates(a, b, rate_a, rate_b, h)
    value = _hermite(sa, sb, rate_a, rate_b, h, s)
    low, high = np.fmin(sa, sb), np.fmax(sa, sb)
    inside = known & (mean > low) & (mean < high)
    if inside.any():
        probe = np.linspace(0.05, 0.95, 19)[None, :]
        cubic = _hermite(sa[:, None], sb[:, None], rate_a[:, None], rate_b[:, None], h[:, None], probe)
        leaves = np.any((cubic < low[:, None]) | (cubic > high[:, None]), axis=1)
        power = inside & leaves
        if power.any():
            rise = sb[power] - sa[power]
            value[power] = sa[power] + rise * s[power] ** (rise / (mean[power] - sa[power]) - 1.0)
    return value


def _integral_rates(
    a: np.ndarray, b: np.ndarray, rate_a: np.ndarray, rate_b: np.ndarray, h: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The stress's rates read from the rows at rows a and b, shifted alike so that the cubic through the two rows
    with them integrates over the interval to the solver's integral (:func:`_stress_with_integral`); with the
    interval's mean stress and where that integral is known (beyond rounding)."""
    sa, sb = a[:, SIGMA], b[:, SIGMA]
    # an integral not carried (NaN) gives a NaN mean, which ``known`` leaves out: the cubic with the rates read
    with np.errstate(invalid="ignore"):
        mean = (b[:, IMPULSE] - a[:, IMPULSE]) / h
        trapezoid = 0.5 * (sa + sb)
        rounding = 8.0 * np.finfo(float).eps * np.fmax(np.abs(a[:, IMPULSE]), np.abs(b[:, IMPULSE])) / h
        known = np.isfinite(mean) & (np.abs(mean - trapezoid) > rounding)
        # the cubic's integral is h (trapezoid + h (rate_a - rate_b) / 12): the rates' difference that gives the mean
        shift = np.where(known, 0.5 * ((rate_b - rate_a) - 12.0 * (trapezoid - mean) / h), 0.0)
    return rate_a + shift, rate_b - shift, mean, known


def _rate_weights(t: np.ndarray, i: np.ndarray, broken: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """How rates are read from the rows at rows i and i + 1 of the intervals (i, i + 1): the rows taken (``rows``,
    n x 6) and the weights (n x 6 each) that give the derivative, at those two rows, of the polynomial through the
    interval's rows and up to NEIGHBOURS rows on each side (six rows: fifth degree), as far as the rows go on in one
    smooth stretch: not beyond a row where the pace jumps (``broken``; such a row is the state there, the limit from
    before, and takes no part in the rates beyond it: a column with a jump there, the reduced bonded count's lag
    C_N V', would bend them), a second row at one instant (a jump), or the rows' end; the interval's secant where
    there is no row on either side (:func:`_read_rates`)."""
    last = t.size - 1
    width = 2 * NEIGHBOURS + 2
    offsets = np.arange(-NEIGHBOURS, NEIGHBOURS + 2)
    rows = np.clip(i[:, None] + offsets[None, :], 0, last)
    x = t[rows]
    valid = np.zeros(rows.shape, dtype=bool)
    valid[:, NEIGHBOURS : NEIGHBOURS + 2] = True
    for side, step in ((range(NEIGHBOURS - 1, -1, -1), 1), (range(NEIGHBOURS + 2, width), -1)):
        going = np.ones(i.size, dtype=bool)
        for k in side:
            inner = k + step  # the row next to it, towards the interval
            going &= (
                (i + offsets[k] >= 0) & (i + offsets[k] <= last) & ~broken[rows[:, k]] & ~broken[rows[:, inner]]
                & (step * (x[:, inner] - x[:, k]) > 0)
            )  # fmt: skip
            valid[:, k] = going
    # the barycentric weights of the valid rows, and the derivative of their polynomial at rows i and i + 1:
    # p'(x_j) = sum over m != j of (w_m / w_j) (y_m - y_j) / (x_j - x_m)
    gaps = x[:, :, None] - x[:, None, :]
    pair = valid[:, :, None] & valid[:, None, :] & ~np.eye(width, dtype=bool)[None, :, :]
    found = []
    # the row's own term (x_j - x_j = 0) and the rows left out are computed and then dropped by np.where: the
    # warnings silenced are theirs alone (valid rows have distinct times)
    with np.errstate(divide="ignore", invalid="ignore"):
        weights = 1.0 / np.prod(np.where(pair, gaps, 1.0), axis=2)
        for j in (NEIGHBOURS, NEIGHBOURS + 1):
            others = valid & (np.arange(width) != j)[None, :]
            d = np.where(others, (weights / weights[:, j : j + 1]) / (x[:, j : j + 1] - x), 0.0)
            d[:, j] = -np.sum(d, axis=1)
            found.append(d)
    return rows, found[0], found[1]


def _read_rates(y: np.ndarray, weights: tuple[np.ndarray, np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The rates of y, read from the rows with :func:`_rate_weights`' ``weights``, at the intervals' two rows."""
    rows, at_a, at_b = weights
    values = y[rows]
    return np.einsum("nm,nm->n", at_a, values), np.einsum("nm,nm->n", at_b, values)


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
