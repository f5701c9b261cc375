"""One regime classifier for every model: what a run settled into, read off its dense solution.

It sees a signal (stress or friction) at the solver's own steps, optionally with the solver's interpolant to
place each extremum, and answers one of :data:`KINDS` with the evidence (periods seen, amplitude ratios); it never
depends on the output sampling and says "undetermined" rather than guess.  The kinds and the rules:
docs/regimes.md.  Rate-and-state keeps its name ``steady sliding`` for ``steady`` (:data:`RSF_NAMES`).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = [
    "BLOW_UP",
    "DECAYING",
    "GROWING",
    "KINDS",
    "OSCILLATING",
    "OSCILLATION",
    "RATIO_TOLERANCE",
    "STEADY",
    "STICK_SLIP",
    "STUCK",
    "UNDETERMINED",
    "Regime",
    "classify",
    "classify_cycles",
    "extremes",
    "remaining_change",
    "repeat_tolerance",
    "turning_points",
]

STEADY = "steady"
DECAYING = "decaying oscillation"
STICK_SLIP = "stick-slip"
GROWING = "growing oscillation"
STUCK = "stuck"
BLOW_UP = "blow-up"
UNDETERMINED = "undetermined"
#: a limit cycle without a stick or a slip phase (a block with mass ringing on; a record whose stress falls as slowly
#: as it rises): not stick-slip.  Named by the transient model and by ``stickslip analyze``, not by ``classify``
OSCILLATION = "oscillation"
KINDS = (STEADY, DECAYING, STICK_SLIP, GROWING, OSCILLATION, STUCK, BLOW_UP, UNDETERMINED)
#: the kinds whose peak and trough are those of an oscillation (the last period's); the others' are the window's
OSCILLATING = (STICK_SLIP, DECAYING, GROWING, OSCILLATION)
#: rate-and-state's names where they differ (kept for its JSON and sweep tables)
RSF_NAMES = {STEADY: "steady sliding"}

#: amplitude ratio per period within 1 +- this counts as constant (a limit cycle)
RATIO_TOLERANCE = 0.02
#: a verdict on an oscillation needs this many consecutive period-to-period ratios that agree
RATIOS_NEEDED = 2
#: the most maxima one period of a limit cycle may have (a main peak and the ringing after a slip)
MAX_MAXIMA_PER_PERIOD = 3
#: a swing smaller than this fraction of the larger of its neighbours is a wiggle on a larger swing, not a period
WIGGLE = 0.05
#: more turning points than this and the scan keeps only swings of WIGGLE of the whole range (cost bound)
MAX_EXTREMA = 20_000
#: a last swing smaller than this fraction of the one before is the start of an unfinished period
TAIL = 0.25

Dense = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class Regime:
    """A classified run: the kind, and the evidence for it.

    ``periods``: whole oscillation periods seen in the analysed window;
    ``amplitude_ratio``: the last period's peak-to-trough amplitude over the
    one before (NaN with fewer than two); ``period`` (s): mean of the last
    periods (NaN unless oscillating); ``peak``/``trough``: extremes of the
    solution over the last period (over the window when not oscillating);
    ``evidence``: the same in words.  Two Regimes are equal where every field is, a NaN (a field that does not
    apply) equal to a NaN; a Regime also equals its kind's name.
    """

    kind: str
    periods: int
    amplitude_ratio: float
    period: float
    peak: float
    trough: float
    evidence: str

    def __str__(self) -> str:
        """The kind: ``f"regime: {run.regime}"`` reads "regime: stick-slip"."""
        return self.kind

    def __eq__(self, other: object) -> bool:
        # equal to its kind's name, so that ``sim.regime == "stick-slip"`` keeps working where a str was kept
        if isinstance(other, str):
            return self.kind == other
        if isinstance(other, Regime):
            # a field that does not apply is NaN, and a NaN is a NaN: a steady run's Regime equals its pickled copy
            # (tuple equality held only while both held the very same float object)
            return all(_same(a, b) for a, b in zip(self._fields(), other._fields(), strict=True))
        return NotImplemented

    def __hash__(self) -> int:
        # as its kind's, so that a Regime and the str it equals find the same dict entry
        return hash(self.kind)

    def _fields(self) -> tuple[object, ...]:
        return (self.kind, self.periods, self.amplitude_ratio, self.period, self.peak, self.trough, self.evidence)


def _same(a: object, b: object) -> bool:
    """Equal, or both NaN (a field that does not apply)."""
    if a == b:
        return True
    return isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b)


def turning_points(values: np.ndarray, delta: float) -> tuple[np.ndarray, np.ndarray]:
    """(maxima, minima) indices, alternating, each extremum ``delta`` beyond its neighbours (hysteresis scan)."""
    maxima: list[int] = []
    minima: list[int] = []
    data = np.asarray(values, dtype=float).tolist()
    if not data:
        return np.array([], dtype=int), np.array([], dtype=int)
    hi = lo = data[0]
    hi_i = lo_i = 0
    looking_for_max = True
    for i, value in enumerate(data):
        if value > hi:
            hi, hi_i = value, i
        if value < lo:
            lo, lo_i = value, i
        if looking_for_max and value < hi - delta:
            maxima.append(hi_i)
            lo, lo_i = value, i
            looking_for_max = False
        elif not looking_for_max and value > lo + delta:
            minima.append(lo_i)
            hi, hi_i = value, i
            looking_for_max = True
    return np.array(maxima, dtype=int), np.array(minima, dtype=int)


def _alternating(y: np.ndarray, floor: float) -> list[int]:
    """Indices of the alternating extrema beyond ``floor``, wiggles on larger swings removed."""
    maxima, minima = turning_points(y, floor)
    if maxima.size + minima.size > MAX_EXTREMA:  # thousands of periods: the small ones are not what decides
        maxima, minima = turning_points(y, max(floor, WIGGLE * float(np.ptp(y))))
    ext = sorted([*maxima.tolist(), *minima.tolist()])
    # A slip's small overshoot is a pair of tiny swings inside a big one: merge it into the big one.
    while len(ext) >= 4:
        swings = np.abs(np.diff(y[ext]))
        around = np.maximum(swings[:-2], swings[2:])
        relative = swings[1:-1] / np.where(around > 0, around, np.inf)
        j = int(np.argmin(relative)) + 1
        if not relative[j - 1] < WIGGLE:
            break
        up = y[ext[j - 1]] > y[ext[j]]  # ext[j - 1] and ext[j + 1] are maxima
        first = _outer(y, ext[j - 1], ext[j + 1], up)
        second = _outer(y, ext[j], ext[j + 2], not up)
        if not first < second:
            break
        ext[j - 1 : j + 3] = [first, second]
    # the swings after the last full one are a period the run did not finish: not counted
    while (n := _unfinished(y[ext])) > 0:
        del ext[-n:]
    return ext


def _unfinished(values: np.ndarray) -> int:
    """How many extrema at the end start a period the run did not finish (``values``: the alternating extrema's):
    one where the last swing is smaller than TAIL of the one before it (an overshoot); two where the last two swings
    are a slip's after-swing up and back that the merge in :func:`_alternating` would take into the next rise, were
    there one (the last swing under WIGGLE of the larger of the swing before it and the rise back to the last peak,
    where a limit cycle's next peak is), but which at the window's end has no rise to merge into; else none.

    Rate-and-state's slip law with radiation damping (k = 200 1/m, eta = 10 s/m: docs/regimes.md, round 28) falls
    0.0572 in mu in each slip, rises 0.0056 as the slip stops and falls back 0.0023 (0.042 of the 0.0539 rise to
    the next peak: merged inside the window); a run that ended in the 310 s before the next rise kept that
    after-swing, read it as a period of 0.404 s, and called the limit cycle of 316.33 s "undetermined"."""
    swings = np.abs(np.diff(values))
    if swings.size >= 2 and swings[-1] < TAIL * swings[-2]:
        return 1
    if swings.size >= 3 and swings[-1] < WIGGLE * max(swings[-2], abs(values[-4] - values[-1])):
        return 2
    return 0


def _outer(y: np.ndarray, i: int, k: int, highest: bool) -> int:
    return i if (y[i] >= y[k]) == highest else k


def _kinds(y: np.ndarray, ext: list[int]) -> list[bool]:
    """True where the alternating extremum is a maximum."""
    if not ext:
        return []
    e = ext[0]
    # the nearest sample of another value decides: a trace may repeat a sample (a phase boundary written twice)
    after = np.flatnonzero(y[e + 1 :] != y[e])
    before = np.flatnonzero(y[:e] != y[e])
    if after.size:
        first_max = bool(y[e] > y[e + 1 + after[0]])
    else:
        first_max = bool(before.size and y[e] > y[before[-1]])
    return [first_max == (k % 2 == 0) for k in range(len(ext))]


def extremes(t: np.ndarray, y: np.ndarray, index: int, dense: Dense | None = None) -> tuple[float, float]:
    """(time, value) of the extremum at sample ``index``, placed between its neighbouring samples.

    With the solver's interpolant ``dense`` the extremum is found on it (a fine grid, then a parabola
    through the best three points, kept only if it does not overshoot them); without, the sample itself.
    """
    n = t.size
    lo, hi = max(index - 1, 0), min(index + 1, n - 1)
    is_max = (y[index] >= y[lo]) and (y[index] >= y[hi])
    sign = 1.0 if is_max else -1.0
    if dense is not None and t[hi] > t[lo]:
        grid = np.linspace(t[lo], t[hi], 201)
        values = np.asarray(dense(grid), dtype=float)
        k = int(np.argmax(sign * values))
        k = min(max(k, 1), grid.size - 2)
        tt, vv = grid[k - 1 : k + 2], values[k - 1 : k + 2]
    else:  # without the interpolant the samples are the answer: a stick-slip peak is a kink, a parabola overshoots
        return float(t[index]), float(y[index])
    t_x, v_x = _parabola_vertex(tt, vv)
    best = float(np.max(sign * vv)) * sign
    if not (math.isfinite(v_x) and tt[0] <= t_x <= tt[-1]) or sign * v_x < sign * best:
        k = int(np.argmax(sign * vv))
        return float(tt[k]), float(vv[k])
    return t_x, v_x


def _parabola_vertex(t: np.ndarray, v: np.ndarray) -> tuple[float, float]:
    (t0, t1, t2), (v0, v1, v2) = t.tolist(), v.tolist()
    if not t0 < t1 < t2:
        return math.nan, math.nan
    d0, d1 = (v1 - v0) / (t1 - t0), (v2 - v1) / (t2 - t1)
    curvature = (d1 - d0) / (t2 - t0)
    if curvature == 0 or not math.isfinite(curvature):
        return math.nan, math.nan
    # p(t) = v0 + d0 (t - t0) + curvature (t - t0)(t - t1) has p'(t) = 0 at:
    t_x = 0.5 * (t0 + t1) - d0 / (2 * curvature)
    return t_x, v0 + d0 * (t_x - t0) + curvature * (t_x - t0) * (t_x - t1)


def remaining_change(t: np.ndarray, y: np.ndarray, tau: float, dense: Dense | None = None) -> tuple[float, float]:
    """(change over the last ``tau``, change still to come if the approach is exponential; inf if it is not).

    The tail is read at T - 2 tau, T - tau and T (the interpolant or linear interpolation between steps);
    with successive changes d1, d2 of one sign and q = d2/d1 < 1, what is left is d2 q/(1 - q).
    """
    return _aitken(*_tail_changes(t, y, tau, dense))


def _tail_changes(t: np.ndarray, y: np.ndarray, tau: float, dense: Dense | None) -> tuple[float, float]:
    """(d1, d2): the changes over [T - 2 tau, T - tau] and [T - tau, T]."""
    end = float(t[-1])
    points = np.array([end - 2 * tau, end - tau, end])
    values = np.asarray(dense(points), dtype=float) if dense is not None else np.interp(points, t, y)
    return float(values[1] - values[0]), float(values[2] - values[1])


def _aitken(d1: float, d2: float) -> tuple[float, float]:
    """(|d2|, what is still to come after two successive changes d1, d2 of an exponential approach)."""
    if d2 == 0.0:
        return 0.0, 0.0
    q = d2 / d1 if d1 != 0 else math.inf
    if q <= 0:  # the tail turned: an oscillation too small to count, bounded by the last change
        return abs(d2), abs(d2)
    if q >= 1:
        return abs(d2), math.inf
    return abs(d2), abs(d2) * q / (1 - q)


def classify(
    t: np.ndarray,
    y: np.ndarray,
    *,
    floor: float,
    start: float | None = None,
    relaxation: float | None = None,
    dense: Dense | None = None,
    unit: str = "",
    settle_floor: float | None = None,
) -> Regime:
    """Classify the signal ``y(t)`` over ``t >= start`` (default: all of it).

    ``floor``: changes and amplitudes at or below it are no change (the solver's tolerance in ``y``);
    ``settle_floor``: the change still to come below which the tail is settled (default ``floor``; a window
    whose peak dwarfs its tail, a re-slide's, judges the tail on the tail's own level);
    ``relaxation`` (s): the time scale over which the tail's approach is judged (at most half the time since
    the last turning point, and half the window; default those);
    ``dense``: the solver's interpolant of ``y`` (extremes are then those of the solution, not of its steps).
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    inside = (t >= (t[0] if start is None else start)) & np.isfinite(t) & np.isfinite(y)
    tw, yw = t[inside], y[inside]
    suffix = f" {unit}" if unit else ""
    if tw.size < 3 or not tw[-1] > tw[0]:
        span = float(tw[-1] - tw[0]) if tw.size else 0.0
        hi, lo = float(np.max(yw, initial=-math.inf)), float(np.min(yw, initial=math.inf))
        text = f"undetermined: too short to tell ({tw.size} points over {span:.3g} s)"
        return Regime(UNDETERMINED, 0, math.nan, math.nan, hi, lo, text)
    window = float(tw[-1] - tw[0])
    floor = max(float(floor), 0.0)
    # an extremum at the window's first point is where the window starts, not a turning point of the solution
    ext = _without_leading_wiggles(yw, [i for i in _alternating(yw, floor) if i > 0])
    placed = [extremes(tw, yw, i, dense) for i in ext]
    is_max = _kinds(yw, ext)
    peaks = [placed[k] for k in range(len(ext)) if is_max[k]]
    amplitudes = [
        placed[k][1] - placed[k + 1][1] for k in range(len(ext) - 1) if is_max[k] and placed[k][1] > placed[k + 1][1]
    ]
    periods = max(len(peaks) - 1, 0)
    ratios = [b / a for a, b in itertools.pairwise(amplitudes) if a > 0]
    ratio = ratios[-1] if ratios else math.nan
    period, latest = _period(tw, yw, ext, is_max, placed, dense)
    if not math.isfinite(period) and len(peaks) >= 2:
        # one fall through mid-level, two peaks: their spacing is the period seen (a settled run that rang for one
        # period read "1 period(s), period not known" and, without a period to be quiet for, oscillating for ever)
        period = latest = peaks[-1][0] - peaks[-2][0]
    last_extremum = placed[-1][0] if placed else float(tw[0])
    quiet = float(tw[-1]) - last_extremum
    oscillating = periods >= 1 and not (math.isfinite(period) and quiet > 2 * period)
    verdict = None
    if oscillating:
        last = [v for (tp, v) in placed if tp >= peaks[-2][0]] if len(peaks) >= 2 else [v for _, v in placed]
        peak, trough = max(last), min(last)
        verdict = _verdict(periods, ratios, period, peak, trough, latest)
        if verdict.kind == STICK_SLIP:
            return verdict
    # a period of several maxima: judged on its own period (the gaps between single maxima are not one)
    several = _repeating_with_several_maxima(placed, is_max) if periods >= 2 else None
    if several is not None and not quiet > 2 * several.period:
        return several
    if verdict is not None:
        return verdict
    # not (or no longer) oscillating: steady only when the tail has stopped changing
    tail_from = _last_turn(tw, yw, ext[-1], is_max[-1]) if placed else float(tw[0])
    tau = min(relaxation if relaxation else math.inf, (float(tw[-1]) - tail_from) / 2.0, window / 2.0)
    peak, trough = _window_extremes(tw, yw, dense)
    if not tau > 0:
        return Regime(UNDETERMINED, periods, ratio, period, peak, trough, "undetermined: no tail to judge")
    change, remaining = remaining_change(tw, yw, tau, dense)
    floor = floor if settle_floor is None else min(float(settle_floor), floor)
    ringing = None
    if not (remaining <= floor or change <= floor * 1e-3) and math.isfinite(period) and period > 0:
        ringing = _ringing_tail(tw, yw, period, floor, dense)
    if ringing is not None and ringing[0] <= floor and ringing[2] <= floor:
        swing, drift, left = ringing
        text = (
            f"steady: rings by {swing:.3g}{suffix} peak to trough over the last period ({_seconds(period)}), below the"
            f" tolerance; its mean over a period changed {drift:.3g}{suffix} from the period before,"
            f" {left:.3g}{suffix} still to come (tolerance {floor:.3g}{suffix})"
        )
        if periods:
            text += f" after {periods} decayed period(s)"
        return Regime(STEADY, periods, ratio, math.nan, peak, trough, text)
    if remaining <= floor or change <= floor * 1e-3:
        left = "nothing measurable" if math.isinf(remaining) else f"{remaining:.3g}{suffix}"
        text = (
            f"steady: changed {change:.3g}{suffix} over the last {tau:.3g} s, {left} still to come"
            f" (tolerance {floor:.3g}{suffix})"
        )
        if periods:
            text += f" after {periods} decayed period(s)"
        return Regime(STEADY, periods, ratio, math.nan, peak, trough, text)
    return Regime(
        UNDETERMINED, periods, ratio, math.nan, peak, trough,
        f"undetermined: {_still_changing(tw, yw, tau, change, remaining, floor, suffix, dense)}",
    )  # fmt: skip


#: the change still to come, read as one exponential approach over the last tau, tau/2 and tau/4, is given only
#: where the three agree within this factor (one exponential gives one answer on every scale)
APPROACH_AGREEMENT = 2.0
#: a span of the tail is read only with at least this many points over the two spans it compares
RESOLVING_POINTS = 8


#: a tail that rings below the floor is read as means over whole periods only where it holds this many periods
RINGING_PERIODS = 3


def _ringing_tail(
    t: np.ndarray, y: np.ndarray, period: float, floor: float, dense: Dense | None
) -> tuple[float, float, float] | None:
    """(swing over the last period, change of the mean over a period from the period before, change of that mean
    still to come) of a tail that still rings below ``floor`` at the ``period`` seen before it; None where the
    window holds fewer than RINGING_PERIODS periods.

    Read at three instants (:func:`remaining_change`) a ringing tail is read at its phases: a decaying oscillation
    of 0.187 s whose swing had fallen to the tolerance (0.0027 Pa of 257.36 Pa), read over 0.36 s, changed
    0.00046 Pa after 0.00035 Pa, "no exponential approach", and the run was "still changing" with a change below
    the tolerance it quoted.  Means over whole periods carry no phase: where they have stopped and the last
    period's swing is within ``floor``, the tail has settled."""
    end = float(t[-1])
    if not (period > 0 and end - RINGING_PERIODS * period >= float(t[0])):
        return None
    edges = end - period * np.arange(RINGING_PERIODS, -1, -1, dtype=float)
    means = [_mean_between(t, y, a, b, dense) for a, b in itertools.pairwise(edges.tolist())]
    last = (t >= edges[-2]) & (t <= end)
    span = np.r_[y[last], np.interp(edges[-2], t, y)]
    if dense is not None:
        span = np.r_[span, np.asarray(dense(np.linspace(edges[-2], end, 201)), dtype=float)]
    drift, left = _aitken(means[-2] - means[-3], means[-1] - means[-2])
    return float(np.ptp(span)), drift, left


def _mean_between(t: np.ndarray, y: np.ndarray, a: float, b: float, dense: Dense | None) -> float:
    """The time mean of y over [a, b]: the trapezoid on the samples (and the interpolant's grid where given)."""
    inside = (t > a) & (t < b)
    tt = np.r_[a, t[inside], b]
    if dense is not None:
        tt = np.union1d(tt, np.linspace(a, b, 201))
        yy = np.asarray(dense(tt), dtype=float)
    else:
        yy = np.interp(tt, t, y)
    return float(np.sum(0.5 * (yy[1:] + yy[:-1]) * np.diff(tt)) / (b - a))


def _last_turn(t: np.ndarray, y: np.ndarray, last: int, was_max: bool) -> float:
    """Where the tail's approach starts: the last counted extremum, or the turn after it that the hysteresis could
    not count, where the swing into it is a large one (TAIL of the window's range at least) and the swing out of it
    is too small to count (a re-slide's rupture from 39.2 MPa to 6.18 Pa, then its refill of 236 Pa, within the
    392 Pa tolerance of the peak: read from the peak, across the rupture, the refill's 35 Pa still to come read
    67.8 Pa).  The turn is the lowest (after a maximum) or highest point after the extremum, unless the signal ends
    there."""
    after = y[last:]
    k = int(np.argmin(after) if was_max else np.argmax(after))
    large = abs(after[k] - after[0]) >= TAIL * float(np.ptp(y))
    return float(t[last + k]) if 0 < k < after.size - 1 and large else float(t[last])


def _without_leading_wiggles(y: np.ndarray, ext: list[int]) -> list[int]:
    """The alternating extrema without a first swing smaller than WIGGLE of the swing after it: a wiggle on the
    window's first rise or fall, as :func:`_alternating` merges one inside.  A re-slide after a 10 s hold rises
    from 0.3 kPa to 39.2 MPa, its aged bonds reaching the FENE wall a cohort at a time (docs/transient.md section
    17): a dip of 849 Pa at 31.9 kPa counted as a period beside the 39.2 MPa peak, and the re-slide, a transient,
    read "undetermined: 1 period(s), period not known"."""
    ext = list(ext)
    while len(ext) >= 3 and abs(y[ext[1]] - y[ext[0]]) < WIGGLE * abs(y[ext[2]] - y[ext[1]]):
        del ext[:2]
    return ext


def _still_changing(
    t: np.ndarray,
    y: np.ndarray,
    tau: float,
    change: float,
    remaining: float,
    floor: float,
    suffix: str,
    dense: Dense | None,
) -> str:
    """The words of a tail still changing: the change still to come where the tail is one exponential approach.

    The estimate d2 q/(1 - q) (:func:`remaining_change`) is exact for one exponential, over any span; so it is
    read again over tau/2 and tau/4 and given only where the three agree.  A 1 s hold's re-slide cut 4.3 ms after
    its 3.56 MPa peak (the rupture to 6.12 Pa, then the bonds' refill) read "about 4.15 Pa still to come" from
    242.535 Pa, over a span starting at the trough: it goes on to sigma(100 µm/s) = 292.943 Pa, 50.4 Pa on; over
    half and a quarter of that span the same rule says 33.8 and 70.4 Pa."""
    head = f"still changing ({change:.3g}{suffix} over the last {tau:.3g} s"
    tolerance = f"tolerance {floor:.3g}{suffix}"
    if math.isinf(remaining):
        # what was compared with the tolerance is the change still to come, not the change seen: say both changes
        before = abs(_tail_changes(t, y, tau, dense)[0])
        return (
            f"{head} after {before:.3g}{suffix} over the {tau:.3g} s before: not slowing down, so no exponential"
            f" approach bounds the change still to come, which is what the {tolerance} is for)"
        )
    # a span is read only where points resolve it (a line between two rows sampled by ``every`` is no approach)
    divisors = [1.0]
    if dense is None:
        divisors += [d for d in (2.0, 4.0) if np.count_nonzero(t >= t[-1] - 2.0 * tau / d) >= RESOLVING_POINTS]
    else:
        divisors += [2.0, 4.0]
    if len(divisors) < 2:
        points = int(np.count_nonzero(t >= t[-1] - 2.0 * tau))
        return (
            f"{head}, about {remaining:.3g}{suffix} still to come if the approach is one exponential, which"
            f" {points} rows cannot check; {tolerance})"
        )
    estimates = [remaining] + [remaining_change(t, y, tau / d, dense)[1] for d in divisors[1:]]
    if all(math.isfinite(e) and e > 0 for e in estimates) and max(estimates) <= APPROACH_AGREEMENT * min(estimates):
        return f"{head}, about {remaining:.3g}{suffix} still to come; {tolerance})"
    spans = ", ".join(f"{2 * tau / d:.3g}" for d in divisors[:-1]) + f" and {2 * tau / divisors[-1]:.3g} s"
    readings = [_approach_reading(*_tail_changes(t, y, tau / d, dense), suffix) for d in divisors]
    read = ", ".join(readings[:-1]) + f" and {readings[-1]}"
    return (
        f"{head}; {tolerance}), and not as one exponential approach, which slows down by one factor on every"
        f" scale (its changes over the two halves of the last {spans}: {read}): how far it still goes is not known"
    )


def _approach_reading(d1: float, d2: float, suffix: str) -> str:
    """Two successive changes of a tail in words: what still comes where they slow down, else that they do not.

    A tail that turns back (changes of opposite signs) or speeds up (|d2| >= |d1|, or d1 = 0) is no exponential
    approach and bounds nothing: the change still to come of d2 q/(1 - q) was printed as "inf Pa" for a decaying
    oscillation that sped up over its last 0.17 s (-0.0135 then -0.021 Pa), and as the last change itself (the
    bound that :func:`remaining_change` keeps for a turn too small to count) where it turned (round-30 tester)."""
    changes = f"{d1:+.3g}{suffix} then {d2:+.3g}{suffix}"
    if d2 == 0.0:
        return f"{changes} (stopped)"
    if d1 * d2 < 0:
        return f"{changes} (turns back)"
    left = _aitken(d1, d2)[1]
    if not math.isfinite(left):
        return f"{changes} (not slowing down)"
    return f"{changes} (slows down: {left:.3g}{suffix} more as one exponential)"


def _verdict(
    periods: int, ratios: list[float], period: float, peak: float, trough: float, latest: float | None = None
) -> Regime:
    """The oscillation's kind from its period-to-period amplitude ratios (the last RATIOS_NEEDED must agree).

    A limit cycle's period is the mean of its last intervals; any other oscillation's is the ``latest`` interval
    (its period may still be changing, and a mean would mix in the start-up swings).
    """
    ratio = ratios[-1] if ratios else math.nan
    recent = ratios[-RATIOS_NEEDED:]
    if len(recent) == RATIOS_NEEDED and all(abs(r - 1) <= RATIO_TOLERANCE for r in recent):
        evidence = f"{periods} period(s) of {_seconds(period)}, {_ratio(ratio)}"
        return Regime(STICK_SLIP, periods, ratio, period, peak, trough, f"stick-slip (limit cycle): {evidence}")
    if latest is not None and math.isfinite(latest):
        period = latest
    latest_text = f"the latest {_seconds(period)}" if math.isfinite(period) else f"period {_seconds(period)}"
    evidence = f"{periods} period(s), {latest_text}, {_ratio(ratio)}"
    if len(recent) == RATIOS_NEEDED:
        if all(r < 1 - RATIO_TOLERANCE for r in recent):
            return Regime(DECAYING, periods, ratio, period, peak, trough, f"decaying oscillation: {evidence}")
        if all(r > 1 + RATIO_TOLERANCE for r in recent):
            return Regime(GROWING, periods, ratio, period, peak, trough, f"growing oscillation: {evidence}")
    return Regime(UNDETERMINED, periods, ratio, period, peak, trough, f"undetermined: {evidence}")


def _repeating_with_several_maxima(placed: list[tuple[float, float]], is_max: list[bool]) -> Regime | None:
    """A limit cycle with up to MAX_MAXIMA_PER_PERIOD maxima per period (a slip that rings, an inertial slider's
    overshoot): every swing repeats the one m swings earlier, in size and in timing, over the last RATIOS_NEEDED
    periods; then one period is m swings (the smallest such m).  None when no m fits."""
    peaks = [placed[k] for k in range(len(placed)) if is_max[k]]
    falls = [placed[k][1] - placed[k + 1][1] for k in range(len(placed) - 1) if is_max[k]]
    times = [tp for tp, _ in peaks]
    for m in range(2, MAX_MAXIMA_PER_PERIOD + 1):
        needed = m * RATIOS_NEEDED
        ratios = [falls[k + m] / falls[k] for k in range(len(falls) - m) if falls[k] > 0]
        spans = [times[k + m] - times[k] for k in range(len(times) - m)]
        if len(ratios) < needed or len(spans) < needed:
            continue
        recent, lasting = ratios[-needed:], spans[-needed:]
        period = float(np.mean(lasting[-m:]))
        if all(abs(r - 1) <= RATIO_TOLERANCE for r in recent) and np.ptp(lasting) <= RATIO_TOLERANCE * period:
            periods = (len(peaks) - 1) // m
            values = [v for (tp, v) in placed if tp >= peaks[-(m + 1)][0]]
            evidence = f"{periods} period(s) of {_seconds(period)}, {_ratio(recent[-1])}, {m} maxima per period"
            return Regime(STICK_SLIP, periods, recent[-1], period, max(values), min(values),
                          f"stick-slip (limit cycle): {evidence}")  # fmt: skip
    return None


def _seconds(period: float) -> str:
    """A period in words: its length, or that it is not known (NaN never reaches a user)."""
    return f"{period:.6g} s" if math.isfinite(period) else "not known (fewer than two peaks)"


def _ratio(ratio: float) -> str:
    return (
        f"amplitude ratio {ratio:.4g} per period"
        if math.isfinite(ratio)
        else "amplitude ratio not known (fewer than two swings)"
    )


def repeat_tolerance(a: float, b: float, rise: float, resolution: float | None = None) -> float:
    """How far a stress of one cycle may be from the same stress of the cycle before and the cycle still repeat:
    RATIO_TOLERANCE of the cycle's rise, and no more than the run's tolerance, ``resolution`` (its rtol) x the
    stress, where it is known (the time-dependent model's stick chains: their sticks and σs are exact events)."""
    tolerance = RATIO_TOLERANCE * abs(rise)
    if resolution is not None and resolution > 0:
        tolerance = min(tolerance, resolution * max(abs(a), abs(b)))
    return tolerance


def settled_window_start(begin: float, end: float, period: float) -> float:
    """Where a run over [begin, end] is averaged for what it settled into: the last whole periods within its second
    half, or that half if it does not oscillate (``models.run.settled_mean``; rate-and-state's from its integral)."""
    half = 0.5 * (end - begin)
    span = float(np.floor(half / period) * period) if np.isfinite(period) and period > 0 else 0.0
    return end - (span if span > 0 else half)


def classify_cycles(peak_times: list[float], peaks: list[float], troughs: list[float]) -> Regime:
    """Classify from exact cycles instead of a trace: the time and stress of each peak, and the trough after it.

    For models that know their slips as events (the time-dependent model's stick chains collapse at a
    known instant and stress), so the verdict needs no sampling at all.
    """
    amplitudes = [p - q for p, q in zip(peaks, troughs, strict=True)]
    ratios = [b / a for a, b in itertools.pairwise(amplitudes) if a > 0]
    periods = max(len(peak_times) - 1, 0)
    intervals = np.diff(peak_times[-4:])
    period = float(np.mean(intervals)) if intervals.size else math.nan
    latest = float(intervals[-1]) if intervals.size else math.nan
    peak = peaks[-1] if peaks else math.nan
    trough = troughs[-1] if troughs else math.nan
    return _verdict(periods, ratios, period, peak, trough, latest)


def _period(
    t: np.ndarray, y: np.ndarray, ext: list[int], is_max: list[bool], placed: list[tuple[float, float]],
    dense: Dense | None,
) -> tuple[float, float]:  # fmt: skip
    """(Mean of the last up to three intervals between the falls through mid-level, one per period; the last one).

    A fall through the middle of the swing is steep, so its time is well defined; a flat peak's is not.  Where the
    last swings repeat (each fall's size within RATIO_TOLERANCE of the one before, as :func:`_verdict` judges a limit
    cycle) the mean is over those settled swings only: a start-up swing, smaller, falls through its own mid-level at
    another phase, and its interval (143.764 s against the cycle's 144.591 s) made the period 144.315 s until a
    fourth settled swing pushed it out, so the period changed with the run's length.
    """
    falls, sizes = [], []
    for k in range(len(ext) - 1):
        if not is_max[k]:
            continue
        level = 0.5 * (placed[k][1] + placed[k + 1][1])
        falls.append(_crossing(t, y, ext[k], ext[k + 1], level, dense))
        sizes.append(placed[k][1] - placed[k + 1][1])
    if len(falls) < 2:
        return math.nan, math.nan
    settled = 1  # the trailing falls whose swings repeat, each the size of the one after it
    while settled < len(falls):
        before, after = sizes[-settled - 1], sizes[-settled]
        if not (before > 0 and abs(after / before - 1) <= RATIO_TOLERANCE):
            break
        settled += 1
    intervals = np.diff(falls[-min(settled, 4) :] if settled >= 3 else falls[-4:])
    return float(np.mean(intervals)), float(np.diff(falls[-2:])[0])


def _crossing(t: np.ndarray, y: np.ndarray, i: int, k: int, level: float, dense: Dense | None) -> float:
    """Time where y falls through ``level`` between samples i < k (a maximum and the minimum after it)."""
    below = np.flatnonzero(y[i : k + 1] < level)
    j = i + int(below[0]) if below.size else k
    a, b = float(t[j - 1]), float(t[j])
    ya, yb = float(y[j - 1]) - level, float(y[j]) - level
    if dense is None or not b > a:
        return a + (b - a) * ya / (ya - yb) if ya != yb else b
    for _ in range(2):  # twice on a fine grid of the interpolant: the bracket shrinks 32-fold each time
        grid = np.linspace(a, b, 33)
        values = np.asarray(dense(grid), dtype=float) - level
        below = np.flatnonzero(values <= 0)
        m = int(below[0]) if below.size else grid.size - 1
        if m == 0:
            return a
        a, b, ya, yb = float(grid[m - 1]), float(grid[m]), float(values[m - 1]), float(values[m])
    return a + (b - a) * ya / (ya - yb) if ya != yb else b


def _window_extremes(t: np.ndarray, y: np.ndarray, dense: Dense | None) -> tuple[float, float]:
    hi, lo = int(np.argmax(y)), int(np.argmin(y))
    return extremes(t, y, hi, dense)[1], extremes(t, y, lo, dense)[1]
