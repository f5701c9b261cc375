"""Cycles and regime of a time-dependent trace, in the vocabulary of ``model.cycle.simulate``."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from .. import regimes
from ..display import velocity as show_velocity
from ..protocols import Protocol
from ..quasistatic.cycle import Cycle

if TYPE_CHECKING:  # pragma: no cover
    from ..parameters import Parameters

#: the slider counts as stuck below this fraction of the puller velocity
STUCK_FRACTION = 0.01
#: steady under block control: the slider's velocity within this fraction of the puller's
STEADY_TOLERANCE = 1e-3
#: steady: the stress has stopped changing within this fraction of it (a tenth of the solver's default rtol)
SETTLED = 1e-5
#: an oscillation's growth or decay is judged only above this many times the solver's tolerance, peak to trough
RESOLVED = 10.0
#: Eq 1 through the block: a slip is the slider outrunning the puller to this many times its pace, after a stick
#: where it fell below 1/SLIP_FACTOR of it (the saturating set's stick creeps at 5-22 % of V0, its slip jumps to 14x)
SLIP_FACTOR = 2.0
#: the verdicts whose peak and trough are an oscillation's (the last period's); the others' are the window's
OSCILLATING = regimes.OSCILLATING
#: a limit cycle in which the slider never sticks (a block with mass ringing on): no stick-slip
OSCILLATION = regimes.OSCILLATION
#: under velocity control at a constant velocity, a swing up to this share of the stress read as a limit cycle or a
#: growing oscillation is the discretisation's ripple on a steady state (:func:`_ripple`, docs/transient.md section 18)
RIPPLE_STEADY = 1e-2


@dataclasses.dataclass(frozen=True)
class Between:
    """Each row's extremes of the solver's states since the row before (the trace's columns 14-18): the lowest and
    highest stress, their times (the row's own unless a state between the rows went beyond it) and the fastest
    slider.  Rows sampled by ``every`` skip the solver's states; these keep what the summary needs of them."""

    lowest: np.ndarray
    highest: np.ndarray
    lowest_time: np.ndarray
    highest_time: np.ndarray
    fastest: np.ndarray

    def within(self, time: np.ndarray, k: int, highest: bool) -> tuple[float, float] | None:
        """(time, stress) of row k's extreme where a state strictly between rows k - 1 and k went beyond row k;
        None where none did (every state a row: the run without ``every``)."""
        when = float((self.highest_time if highest else self.lowest_time)[k])
        value = float((self.highest if highest else self.lowest)[k])
        return (when, value) if k > 0 and time[k - 1] < when < time[k] and math.isfinite(value) else None


def with_extremes(time: np.ndarray, stress: np.ndarray, between: Between | None) -> tuple[np.ndarray, np.ndarray]:
    """The trace with each row's extremes between it and the row before added at their times: what the classifier
    reads, so that the peaks, troughs and tolerance it finds are the solution's whatever the rows kept (the trace
    itself where every state is a row)."""
    if between is None or time.size < 2:
        return time, stress
    before, after = time[:-1], time[1:]
    extra_t, extra_y = [], []
    for when, value in ((between.lowest_time, between.lowest), (between.highest_time, between.highest)):
        w, v = np.asarray(when[1:], dtype=float), np.asarray(value[1:], dtype=float)
        ok = np.isfinite(v) & (w > before) & (w < after)
        extra_t.append(w[ok])
        extra_y.append(v[ok])
    added = np.concatenate(extra_t)
    if not added.size:
        return time, stress
    t, y = np.r_[time, added], np.r_[stress, np.concatenate(extra_y)]
    order = np.argsort(t, kind="stable")
    return t[order], y[order]


def window_extremes(
    time: np.ndarray, stress: np.ndarray, between: Between | None, start: float, end: float = math.inf
) -> tuple[float, float]:
    """(highest, lowest) stress of the solution from ``start`` on: the rows there and every state of the solver at
    or after ``start`` that a row's extremes carry (``between``), wherever that row lies (a row written at a
    slip closes the steps since the last state it saw, which can be before the grid row before it: 10 s rows
    of a re-slide from t = 11 s carried its lowest, 255.7 Pa at t = 11 s, on the slip's row at 14.8 s, past the
    row at 12 s).  Neither depends on the rows kept; NaN where the window holds nothing.  ``end``: the window's
    end (the states up to it), the run's by default."""
    time, stress = np.asarray(time, dtype=float), np.asarray(stress, dtype=float)
    values = [stress[(time >= start) & (time <= end) & np.isfinite(stress)]]
    if between is not None:
        for when, value in ((between.lowest_time, between.lowest), (between.highest_time, between.highest)):
            w, v = np.asarray(when, dtype=float), np.asarray(value, dtype=float)
            values.append(v[np.isfinite(v) & np.isfinite(w) & (w >= start) & (w <= end)])
    found = np.concatenate(values)
    if not found.size:
        return math.nan, math.nan
    return float(np.max(found)), float(np.min(found))


def stuck_mask(time: np.ndarray, velocity: np.ndarray, protocol: Protocol) -> np.ndarray:
    """Rows where the slider is below STUCK_FRACTION of the puller's pace; at rest under a protocol that never
    moves (pace 0) too, where it read "steady sliding at 0 µm/s"."""
    pace = _pace(time, protocol)
    return (velocity < STUCK_FRACTION * pace) | ((pace == 0.0) & (velocity == 0.0))


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each run of True."""
    edges = np.diff(np.r_[0, mask.astype(int), 0])
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1) - 1
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


def detect_cycles(
    time: np.ndarray,
    stress: np.ndarray,
    velocity: np.ndarray,
    protocol: Protocol,
    events: list,
    lowest: np.ndarray | None = None,
    stiffness: float | None = None,
    between: Between | None = None,
    jumps: Sequence[float] = (),
) -> tuple[Cycle, ...]:
    """A cycle is a stick that ended in a slip; its slip lasts until the next stick (None if the run ends first).

    With the stick chains the solver records each stick and slip as an event at its exact time and stress:
    the cycles are read from those, whatever the sampling; otherwise from the trace (:func:`_trace_cycles`).
    ``jumps``: the instants of the massless block's jumps through rupture cascades (transient/jump.py); a slip
    that holds one has no finite jump velocity (``inf``: the cascade takes no time, see :func:`describe_jump`).
    """
    from_events = _cycles_from_events(events)
    if from_events:
        return from_events
    return _trace_cycles(time, stress, velocity, protocol, lowest, stiffness, between, jumps)


def describe_jump(velocity: float) -> str:
    """The jump of a cycle in words: "jump to 711 µm/s", or, for the massless block's jump through a rupture
    cascade (an infinite jump velocity), "a jump in no time" (the slider's travel is in the run's message)."""
    return f"jump to {velocity * 1e6:.4g} µm/s" if math.isfinite(velocity) else "a jump in no time"


def _pace(time: np.ndarray, protocol: Protocol) -> np.ndarray:
    """The puller's velocity at each row (in a hold, vp = 0, the protocol's fastest: the sliding scale)."""
    vp = protocol.velocity_at(np.minimum(time, np.nextafter(protocol.duration, 0.0)))
    return np.where(vp > 0, vp, np.max(protocol.velocities))


def _pace_bounds(time: np.ndarray, protocol: Protocol, pace: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(slower, faster) of the puller's paces at each row: :func:`_pace`'s, but at a row written at a protocol
    boundary both segments' (the row is the state that ends the segment before it, whose velocity it carries,
    while the pace read at that instant is the next segment's).  A slider is behind the puller there only when
    below both, ahead only when above both: under velocity control the boundary row of 350 -> 1000 µm/s carried
    350 µm/s against a pace of 1000 ("a stick"), and that of 1000 -> 350 µm/s 1000 against 350 ("a jump"), and the
    rigidly driven slider read as one stick-slip cycle (stick 0.0397 s, σs = 653.43 Pa, jump to 1000 µm/s)."""
    edges = np.asarray(protocol.boundaries[1:-1], dtype=float)
    if not edges.size or not time.size:
        return pace, pace
    k = np.searchsorted(edges, time)
    nearest = [edges[np.clip(j, 0, edges.size - 1)] for j in (k - 1, k)]
    at = np.isclose(time, nearest[0], rtol=1e-12, atol=0.0) | np.isclose(time, nearest[1], rtol=1e-12, atol=0.0)
    if not at.any():
        return pace, pace
    before = protocol.velocity_at(np.nextafter(time[at], -np.inf))
    before = np.where(before > 0, before, np.max(protocol.velocities))
    low, high = pace.copy(), pace.copy()
    low[at], high[at] = np.minimum(pace[at], before), np.maximum(pace[at], before)
    return low, high


def _trace_cycles(
    time: np.ndarray,
    stress: np.ndarray,
    velocity: np.ndarray,
    protocol: Protocol,
    lowest: np.ndarray | None,
    stiffness: float | None,
    between: Between | None = None,
    jumps: Sequence[float] = (),
) -> tuple[Cycle, ...]:
    """The cycles of Eq 1 through the block, read from the solution: a slip is a stretch where the slider outruns
    the puller (the stress falls: dsigma/dt = K (Vp - V)) and reaches :data:`SLIP_FACTOR` x its pace, after a
    stick where it fell to 1/SLIP_FACTOR of it.  The stick runs from the previous slip's end (V back below Vp:
    the stress's trough) to the slip's onset (V up through Vp: its peak), whatever the slider creeps at in
    between; a run that starts faster than the puller (a steady start above it) has no stick before that.

    The trough is the lowest stress of the solver's steps (``lowest``), the peak the maximum of the cubic
    through the two rows around the onset with their slopes K (Vp - V) (``stiffness``; without it, the rows'),
    or, where rows sampled by ``every`` skip the solver's states, the highest of those (``between``, with the
    lowest's and highest's times): neither depends on the rows kept.  The jump velocity is the fastest state's,
    or ``inf`` where the slip holds one of ``jumps`` (the massless block's cascade: the runaway that set it off
    is not a velocity the slider reaches).
    """
    n = time.size
    if n < 3:
        return ()
    pace = _pace(time, protocol)
    slower, faster = _pace_bounds(time, protocol, pace)  # a row at a protocol boundary: both segments' paces
    ahead = velocity > faster
    runs = [(a, z) for a, z in _runs(ahead) if a > 0]  # a run from the first row is the start, not a slip
    cycles: list[Cycle] = []
    behind = np.flatnonzero(~ahead)  # the first stick starts at the first row, or after a start faster than the puller
    stick_from = int(behind[0]) if behind.size else ahead.size
    for a, z in runs:
        if a <= stick_from:
            continue
        slow = float(np.min(velocity[stick_from:a] / slower[stick_from:a]))
        jump = float(np.max(velocity[a : z + 1]))
        if between is not None:  # the states between the rows, to the one back below the puller
            jump = max(jump, float(np.max(between.fastest[a : z + 2])))
        end = z + 1 if z + 1 < n else None  # the row where the slider is back below the puller
        if any(time[a - 1] <= instant <= time[n - 1 if end is None else end] for instant in jumps):
            jump = math.inf
        if not (slow <= 1.0 / SLIP_FACTOR and jump >= SLIP_FACTOR * float(np.max(faster[a : z + 1]))):
            if slow > 1.0 / SLIP_FACTOR and end is not None:
                stick_from = end  # a swing while sliding: a stick, if any, starts after it
            continue  # else a creep that briefly outran the puller without a jump: the stick goes on
        t_peak, sigma_s = _turn(time, stress, velocity, pace, a, stiffness, True, between)
        start_time, start_stress = float(time[stick_from]), float(stress[stick_from])
        if stick_from > 0:  # the previous slip's end: the trough of the solution, not of the rows kept
            start_time, start_stress = _turn(time, stress, velocity, pace, stick_from, stiffness, False, between)
            if lowest is not None:  # the solver's own lowest: exact, where a cubic over long rows may undershoot
                start_stress = min(float(stress[stick_from - 1]), float(stress[stick_from]))
                if math.isfinite(lowest[stick_from]):  # the lowest of the solver's steps since the row before
                    start_stress = min(start_stress, float(lowest[stick_from]))
        slip_time = None
        if end is not None:
            slip_time = _turn(time, stress, velocity, pace, end, stiffness, False, between)[0] - t_peak
        cycles.append(_cycle(len(cycles), start_time, start_stress, sigma_s, t_peak - start_time, jump, slip_time))
        if end is None:
            break
        stick_from = end
    return tuple(cycles)


def _turn(
    time: np.ndarray,
    stress: np.ndarray,
    velocity: np.ndarray,
    pace: np.ndarray,
    a: int,
    stiffness: float | None,
    highest: bool,
    between: Between | None,
) -> tuple[float, float]:
    """(time, stress) of the turn between rows a - 1 and a: the solver's own extreme where a state between the rows
    went beyond both (rows sampled by ``every``: a cubic over such rows guesses), else :func:`_extremum`."""
    found = between.within(time, a, highest) if between is not None else None
    if found is None:
        return _extremum(time, stress, velocity, pace, a, stiffness, highest)
    sign = 1.0 if highest else -1.0
    rows = [(float(time[k]), float(stress[k])) for k in (a - 1, a)]
    return max([found, *rows], key=lambda point: sign * point[1])


def _extremum(
    time: np.ndarray,
    stress: np.ndarray,
    velocity: np.ndarray,
    pace: np.ndarray,
    a: int,
    stiffness: float | None,
    highest: bool,
) -> tuple[float, float]:
    """(time, stress) of the turn where the slider's velocity crosses the puller's, between rows a - 1 and a:
    the extremum of the cubic through both rows with their slopes dsigma/dt = K (Vp - V) (the rows' own
    without the stiffness)."""
    sign = 1.0 if highest else -1.0
    t0, t1 = float(time[a - 1]), float(time[a])
    s0, s1 = float(stress[a - 1]), float(stress[a])
    best = (t0, s0) if sign * s0 >= sign * s1 else (t1, s1)
    if stiffness is None or not t1 > t0:
        return best
    h = t1 - t0
    d0 = stiffness * (float(pace[a - 1]) - float(velocity[a - 1])) * h  # the slopes over the unit interval
    d1 = stiffness * (float(pace[a]) - float(velocity[a])) * h
    # the Hermite cubic p(u) has p'(u) = A u^2 + B u + d0
    big_a = 6 * s0 + 3 * d0 - 6 * s1 + 3 * d1
    big_b = -6 * s0 - 4 * d0 + 6 * s1 - 2 * d1
    roots = np.roots([big_a, big_b, d0]) if abs(big_a) + abs(big_b) > 0 else np.array([])
    for root in roots:
        if abs(root.imag) > 1e-12 or not 0.0 < root.real < 1.0:
            continue
        u = float(root.real)
        value = (
            (2 * u**3 - 3 * u**2 + 1) * s0 + (u**3 - 2 * u**2 + u) * d0 + (-2 * u**3 + 3 * u**2) * s1
            + (u**3 - u**2) * d1
        )  # fmt: skip
        if sign * value > sign * best[1]:
            best = (t0 + u * h, value)
    return best


def _cycles_from_events(events: list) -> tuple[Cycle, ...]:
    marks = [(kind, float(t), float(sigma), float(v)) for kind, t, sigma, v in events if kind in ("stick", "slip")]
    cycles: list[Cycle] = []
    for k, (kind, t_slip, sigma_s, v_jump) in enumerate(marks):
        if kind != "slip" or k == 0 or marks[k - 1][0] != "stick":
            continue
        _, t_stick, sigma_stick, _ = marks[k - 1]
        nxt = next((t for kind2, t, _, _ in marks[k + 1 :] if kind2 == "stick"), None)
        slip_time = None if nxt is None else nxt - t_slip
        cycles.append(_cycle(len(cycles), t_stick, sigma_stick, sigma_s, t_slip - t_stick, v_jump, slip_time))
    return tuple(cycles)


def _cycle(index: int, start: float, sigma: float, peak: float, stick: float, jump: float, slip: float | None) -> Cycle:
    """A Cycle; its period stick + slip once the slip has ended."""
    period = None if slip is None else stick + slip
    return Cycle(index, start, sigma, peak, stick, jump, slip, period)


def classify(
    time: np.ndarray,
    stress: np.ndarray,
    velocity: np.ndarray,
    protocol: Protocol,
    cycles: tuple[Cycle, ...],
    events: list,
    control: str,
    stop: str | None,
    resolution: float | None = None,
) -> tuple[str, str]:
    """(regime, message): :func:`judge` without its evidence."""
    regime, message, _ = judge(time, stress, velocity, protocol, cycles, events, control, stop, resolution)
    return regime, message


def judge(
    time: np.ndarray,
    stress: np.ndarray,
    velocity: np.ndarray,
    protocol: Protocol,
    cycles: tuple[Cycle, ...],
    events: list,
    control: str,
    stop: str | None,
    resolution: float | None = None,
    lowest: np.ndarray | None = None,
    between: Between | None = None,
    steady: SteadyReference | None = None,
    since_slip: np.ndarray | None = None,
) -> tuple[str, str, regimes.Regime | None]:
    """(regime, message, evidence) of the last protocol segment, by :func:`stickslip.regimes.classify` on the
    stress.

    "stick-slip" (a limit cycle: the amplitude constant over the last periods), "steady" (stress and, under
    block control, the slider's velocity settled), "decaying oscillation", "growing oscillation", "stuck"
    (no slip, the slider below 1 % of the puller's pace at the end) or "undetermined" with the evidence.
    "Settled" means within :data:`SETTLED` of the stress (a tenth of the solver's default rtol).
    ``resolution``: the solver's local error tolerance (relative).  Whether an oscillation grows, decays or
    repeats (a limit cycle) is judged only when its peak-to-trough stress is :data:`RESOLVED` times that
    tolerance of the stress or more: a smaller one is within what the steps may get wrong (a block with mass
    ringing against resting bonds at rtol 1e-4 swung by 2 x the tolerance, ~4 steps a period, and read as
    growing, or as a limit cycle, while it decays).  The third item: the classifier's evidence (periods seen,
    amplitude ratio, period, extremes), None when the run stopped.  ``between``: each row's extremes of the
    solver's states since the row before, which the classifier reads with the rows (:func:`with_extremes`).
    ``steady``: the steady state at the last segment's pace, against which a run whose stick chains' last event is
    a slip is found settled after it (:func:`settled_after_slip`), on ``since_slip`` where given: the solver's
    rows (:data:`Between`'s columns 14-18) from the last slip on, which a sampler keeps whatever ``every`` wrote.
    """
    if stop is not None:
        return regimes.UNDETERMINED, stop, None
    start = float(protocol.boundaries[-2])
    t_all, s_all = with_extremes(time, stress, between)
    inside = t_all >= start
    # the tolerance scales with the solution's peak, not the rows' (a re-slide's peak between rows 1 ms apart was
    # lost: 93.3 kPa for 3.56 MPa, and the verdict flipped)
    scale = float(np.max(np.abs(s_all[inside]))) if np.any(inside) else 0.0
    floor = SETTLED * max(scale, 1e-300)
    # settled is judged on the stress the run ends at (not below a thousandth of the peak): within SETTLED of a
    # 3.56 MPa re-slide peak (35.6 Pa), a re-slide 50 Pa short of steady read as steady
    settle = SETTLED * max(abs(float(stress[-1])), 1e-3 * scale, 1e-300)
    found = _from_events(events, start, time, stress, lowest, between, resolution)
    if found is not None and found.kind in (regimes.UNDETERMINED, regimes.DECAYING) and steady is not None:
        settled = settled_after_slip(
            events, start, time, stress, velocity, between, resolution, steady, since_slip=since_slip
        )
        if isinstance(settled, regimes.Regime):  # no stick since its last slip, and at the steady state long enough
            return settled.kind, settled.evidence, settled
        if settled is not None:  # sliding since its last slip, not (yet) settled: say how far from it
            found = dataclasses.replace(found, evidence=f"{found.evidence}; {settled}")
    if found is None:
        classified = regimes.classify(time, stress, floor=floor, start=start, unit="Pa", settle_floor=settle)
        found = solution_extremes(classified, time, stress, between, start)
    chains = any(kind == "stick" for kind, *_ in events)
    ripple = _ripple(found, time, stress, velocity, protocol, control, resolution, scale, between)
    if ripple is not None:
        return ripple
    regime, message = _words(found, time, stress, velocity, protocol, cycles, control, resolution, scale, chains)
    if regime not in OSCILLATING:  # no oscillation to take a period's extremes of: the window's, as reported
        peak, trough = window_extremes(time, stress, between, start)
        if math.isfinite(peak):
            found = dataclasses.replace(found, peak=peak, trough=trough)
    return regime, message, found


#: steady after the stick chains' last slip: the solution within the run's tolerance of the steady state at the
#: puller's pace over at least this many of its relaxation times (:class:`SteadyReference`) before the end
SETTLED_RELAXATIONS = 10.0
#: real rates s (in units of 1/tau, the bond time) at which a slide's instability is looked for first (a real root
#: of m s^2 + eta s + K + Z(s), :func:`steady_instability`): two a decade over Kc's scan, ~0.04 s at 100 um/s
INSTABILITY_RATES = np.geomspace(1e-6, 1e6, 25)


@dataclasses.dataclass(frozen=True)
class SteadyReference:
    """The steady state at the last segment's pace, from the steady solver (Eqs 6-8): what a run that slides on
    after its last slip settles to, and how fast.

    ``relaxation`` (s): the longer of the block's decay along the steady curve, |dσ/dV| / K (the quasi-static
    slip phase, σ'(V) dV/dt = K (Vp - V), relaxes V - Vp as exp(-t K / σ')), and the bonds' memory, dl_m / Vp
    (every bond of the steady population is born within it: the population renews itself within that time).
    ``every`` (s): the spacing of the rows where ``every`` sampled them (None: every solver state a row), named in
    the words where the rows' spacing is what keeps the verdict back.  ``instability``: called only where the run
    has not settled, words saying that steady sliding at the pace is unstable for the run's block (None where it
    is not, or not known): :func:`steady_instability`."""

    velocity: float  # m/s, the puller's pace over the last segment
    stress: float  # Pa, sigma of the steady curve at it
    slope: float  # Pa s/m, dsigma/dV there
    stiffness: float  # Pa/m, the block's
    memory: float  # s, dl_m / Vp
    every: float | None = None
    instability: Callable[[], str | None] | None = dataclasses.field(default=None, compare=False, repr=False)

    @property
    def block_decay(self) -> float:
        return abs(self.slope) / self.stiffness if self.stiffness > 0 else math.inf

    @property
    def relaxation(self) -> float:
        return max(self.block_decay, self.memory)


def steady_instability(
    params: Parameters,
    velocity: float,
    stiffness: float,
    mass: float = 0.0,
    damping: float = 0.0,
    aging: bool = True,
    critical_velocity: float = math.nan,
) -> str | None:
    """Words saying that steady sliding at ``velocity`` is linearly unstable through the run's block (K below
    Kc(V), transient.stability), for a slide that has not settled; None where it is stable or not known.

    First, cheaply, a real runaway: D(s) = m s^2 + eta s + K + Z(s) is K > 0 at s = 0, so D < 0 at a real rate
    s > 0 (:data:`INSTABILITY_RATES`) proves a real root in between, and K below Kc, which is at least the largest
    -(m s^2 + eta s + Z(s)) seen (the paper's set at 100 µm/s: 2.84e8 Pa/m in ~0.04 s, Kc 1.26e9 Pa/m).  Where
    that finds none (near Vc: at 123 µm/s the bound is 3.4e5 Pa/m, Kc 3.3e7), Kc itself (~1.5 s)."""
    from ..errors import ModelError, ParameterError
    from .stability import critical_stiffness_details, interface_response

    speed = f"{velocity * 1e6:.6g} µm/s"
    below = (
        f"V0 below Vc = {critical_velocity * 1e6:.4g} µm/s, and "
        if math.isfinite(critical_velocity) and velocity < critical_velocity
        else ""
    )
    block = f"K = {stiffness / 1e3:.6g} kPa/m"
    try:
        rates = INSTABILITY_RATES / float(params.bonds.bond_time)
        # at the fastest trial rates the response's exponentials may overflow: those margins are not finite and
        # are left out below (only a finite negative margin proves a root); the full Kc search decides otherwise
        with np.errstate(over="ignore", invalid="ignore"):
            z = interface_response(params, velocity, rates, aging).z.real
            margin = mass * rates**2 + damping * rates + stiffness + z
        finite = np.isfinite(margin)
        if np.any(finite & (margin < 0.0)):
            bound = float(np.max(stiffness - margin[finite]))
            return f"{below}{block} below Kc({speed}), which is at least {bound:.3g} Pa/m (a real unstable root)"
        found = critical_stiffness_details(params, velocity, aging, mass, damping)
    except (ModelError, ParameterError, FloatingPointError, ValueError):
        return None
    if not stiffness < found.value:
        return None
    mode = {"real": "a real unstable root", "oscillatory": "an oscillation that grows"}.get(found.mode, found.mode)
    return f"{below}{block} below Kc({speed}) = {found.value:.4g} Pa/m ({mode})"


def _known_states(
    time: np.ndarray, stress: np.ndarray, between: Between | None, start: float
) -> tuple[np.ndarray, np.ndarray]:
    """(times, stresses) of every state the trace knows at or after ``start``: the rows, and the extremes each row
    carries of the solver's states between (wherever that row lies, as :func:`window_extremes`), in time order."""
    times, values = [np.asarray(time, dtype=float)], [np.asarray(stress, dtype=float)]
    if between is not None:
        for when, value in ((between.lowest_time, between.lowest), (between.highest_time, between.highest)):
            times.append(np.asarray(when, dtype=float))
            values.append(np.asarray(value, dtype=float))
    t, y = np.concatenate(times), np.concatenate(values)
    ok = np.isfinite(t) & np.isfinite(y) & (t >= start)
    order = np.argsort(t[ok], kind="stable")
    return t[ok][order], y[ok][order]


def settled_after_slip(
    events: list,
    start: float,
    time: np.ndarray,
    stress: np.ndarray,
    velocity: np.ndarray,
    between: Between | None,
    resolution: float | None,
    steady: SteadyReference,
    since_slip: np.ndarray | None = None,
) -> regimes.Regime | str | None:
    """Steady sliding after the stick chains' last slip (a start-up stick-slip from rest, above Vc), judged from
    the solution; where it is not (yet), why not in words; None where the last event is no slip.

    The chains' events say what happened (a stick ended by a slip, and no stick since), but not what the slide
    did after: the verdict on the events alone, "1 slip, no stick after it: needs another slip", could never
    change however long the run.  The slide has settled when the solution is the steady state at the puller's
    pace Vp and has stayed it: every state of the solver over the last SETTLED_RELAXATIONS relaxation times (the
    rows and the extremes each row carries of the states between: where the stretch starts between two rows, the
    states there are known only by the later row's extremes, so the sampling can only delay the verdict, by about
    a row's interval, never advance it) within the run's tolerance,
    max(rtol, SETTLED) x σ(Vp), of the steady curve's σ(Vp), that stretch after the last slip, and the slider at
    Vp within STEADY_TOLERANCE at the end.  Why so long: under the block dσ/dt = K (Vp - V), so a stress held
    within ±B over a stretch L pins the slider's mean pace to Vp within 2 B / (K L); with L = 10 |σ'| / K that is
    a fifth of B / |σ'|, the velocity that moves the steady stress by B, and a departure from the steady state
    decays as exp(-L / relaxation) = 4.5e-5 over it (the quasi-static model calls its slip phase steady where V
    is within 1e-9 of Vp, docs/slip-phase.md; a steady start, where the trace's tail has stopped changing).

    Judged as: the last state known off that band (the slip's at the latest); the run is steady once the stretch
    starts after it where it is a row (the next row's extremes bound every state between), or at or after the
    first row after it where it is an extreme between two rows (the states between it and that row are not
    known).  Where the rows skip the solver's states (``every``), a row knows those between it and the row
    before only by their extremes, so the last state off the band is known only to lie between such an extreme
    and the next row; the words say so, with the end from which these rows read steady (that row + the stretch)
    and the earliest from which rows finer could (the extreme + the stretch).  Where steady sliding at Vp is
    unstable for the block (``steady.instability``), the words say the slide will not settle onto it.

    ``since_slip``: where the rows were sampled, the solver's own rows from the last slip on (trace columns, the
    sampler's :meth:`~stickslip.transient.sampling.Sampler.since_last_slip`): judged on them, the verdict and its
    words are the unsampled run's, whatever ``every`` (the stress's peak and trough over the segment stay the
    sampled trace's, which carries every extreme)."""
    window = (time, stress, between)
    if since_slip is not None and since_slip.shape[0] >= 2:
        time, stress, velocity = since_slip[:, 0], since_slip[:, 1], since_slip[:, 3]
        between = Between(*(since_slip[:, k] for k in range(14, 19)))
        steady = dataclasses.replace(steady, every=None)
    marks = [(kind, float(t), float(s)) for kind, t, s, _ in events if kind in ("stick", "slip") and t >= start]
    slips = [k for k, mark in enumerate(marks) if mark[0] == "slip"]
    vp = steady.velocity
    if not slips or marks[-1][0] != "slip" or not (vp > 0 and math.isfinite(steady.stress)) or time.size < 2:
        return None
    t_slip, sigma_s = marks[-1][1], marks[-1][2]
    end = float(time[-1])
    span = SETTLED_RELAXATIONS * steady.relaxation
    v_end = float(velocity[-1])
    rtol = max(resolution if resolution is not None else 0.0, SETTLED)
    band = rtol * abs(steady.stress)
    since = end - span
    # the row at or before the stretch's start: where its words say the stretch is judged from
    first = float(time[max(int(np.searchsorted(time, since, side="right")) - 1, 0)])
    # the last state known off the band since the slip (the slip's own at the latest), and the first row after it:
    # from there on every state is known within the band
    known_t, known_y = _known_states(time, stress, between, t_slip)
    off = np.abs(known_y - steady.stress) > band
    last_off = max(t_slip, float(known_t[off][-1])) if np.any(off) else t_slip
    after = time[time > last_off]
    entered = float(after[0]) if after.size else math.nan
    # a row off the band: the next row's extremes bound every state after it, so the band holds from just after it;
    # an extreme between two rows: the states between it and the next row are not known, so from that row
    on_row = bool(np.any(time == last_off))
    clear = math.isfinite(entered) and (since > last_off if on_row else since >= entered)
    pace = abs(v_end - vp) <= STEADY_TOLERANCE * vp
    if not (math.isfinite(span) and clear and pace):
        instability = steady.instability() if steady.instability is not None else None
        if instability is not None:
            return (
                f"steady sliding at {vp * 1e6:.6g} µm/s is unstable for this block ({instability};"
                f" transient.stability): the slide since the slip at t = {t_slip:.6g} s (σ = {float(stress[-1]):.6g}"
                f" Pa, V = {show_velocity(v_end, 4)} at the end) will not settle onto it; what comes next is a stick,"
                " and the slip after that stick says whether the cycles repeat"
            )
        return _not_settled(
            stress, steady, known_t, known_y, t_slip, first, since, (last_off, on_row, entered), span, band, v_end
        )
    settled = known_y[known_t > last_off]  # every state known after the last off the band: the stretch's, and within
    high, low = float(np.max(settled)), float(np.min(settled))
    before = marks[slips[-1] - 1] if slips[-1] > 0 and marks[slips[-1] - 1][0] == "stick" else None
    stick = f"stick from {before[2]:.6g} Pa at t = {before[1]:.6g} s to " if before is not None else ""
    n = len(slips)
    what = "a start-up stick-slip" if n == 1 else f"{n} stick-slip cycles (the last:"
    close = ")" if n == 1 else "))"
    words = (
        f"steady sliding at {v_end * 1e6:.6g} µm/s after {what}"
        f"{' (' if n == 1 else ' '}{stick}σs = {sigma_s:.6g} Pa at t = {t_slip:.6g} s, no stick since{close}:"
        f" σ = {float(stress[-1]):.6g} Pa at t = {end:.6g} s, and every state over the last {span:.3g} s within"
        f" {band:.3g} Pa (rtol {rtol:g}) of the steady curve's σ({vp * 1e6:.6g} µm/s) = {steady.stress:.6g} Pa"
        f" ({high - low:.3g} Pa peak to trough; {SETTLED_RELAXATIONS:g} relaxation times of {steady.relaxation:.3g} s:"
        f" the block's decay along the steady curve |dσ/dV|/K = {steady.block_decay:.3g} s, the bonds' memory"
        f" dl_m/V = {steady.memory:.3g} s)"
    )
    peak, trough = window_extremes(*window, start)
    return regimes.Regime(regimes.STEADY, 0, math.nan, math.nan, peak, trough, words)


def _not_settled(
    stress: np.ndarray,
    steady: SteadyReference,
    known_t: np.ndarray,
    known_y: np.ndarray,
    t_slip: float,
    first: float,
    since: float,
    band_from: tuple[float, bool, float],
    span: float,
    band: float,
    v_end: float,
) -> str:
    """Why a slide after the chains' last slip is not (yet) steady, in words (:func:`settled_after_slip`): how far
    the run ends from the steady state, the largest departure over the stretch judged, since when the run has been
    within the band (or that it never was after the slip), and, where the rows' spacing keeps the verdict back,
    that it does and by how much.  ``band_from``: the last state known off the band, whether it is a row's, and the
    first row after it.  Each stress to a hundredth of the band, each departure on its own."""
    vp, level = steady.velocity, steady.stress
    last_off, on_row, entered = band_from
    digits = max(0, math.ceil(-math.log10(band / 100.0))) if band > 0 else 6
    sigma_end = float(stress[-1])
    text = (
        f"the slide since has not settled to steady sliding (σ = {sigma_end:.{digits}f} Pa and V ="
        f" {show_velocity(v_end, 7)} at the end, {sigma_end - level:+.3g} Pa and {(v_end - vp) / vp:+.2g} × V0 from"
        f" the steady curve's σ({vp * 1e6:.6g} µm/s) = {level:.{digits}f} Pa at V0 = {vp * 1e6:.6g} µm/s"
    )
    if not math.isfinite(span):
        return text + (
            f"; with no relaxation time to judge it by, it counts as settled once every state lies within {band:.3g} Pa"
            " of it)"
        )
    judged = max(first, t_slip)
    inside = known_t >= judged
    gaps = known_y[inside] - level
    worst = int(np.argmax(np.abs(gaps))) if gaps.size else -1
    where = f"{gaps[worst]:+.4g} Pa at t = {known_t[inside][worst]:.6g} s" if worst >= 0 else "none known"
    if since < t_slip:
        text += (
            f"; the last {span:.3g} s reach back before the slip at t = {t_slip:.6g} s, and the largest departure"
            f" since the slip is {where}"
        )
    else:
        text += (
            f"; the largest departure over the stretch judged, from the row at t = {judged:.6g} s (the last at or"
            f" before the start of the last {span:.3g} s), is {where}"
        )
    if not math.isfinite(entered):
        text += f"; not within {band:.3g} Pa of it at any row since the slip"
    elif on_row:
        text += (
            f"; within {band:.3g} Pa of it after t = {last_off:.6g} s, the last state off it: staying so, the run"
            f" reads steady from about t = {last_off + span:.4g} s on"
        )
    else:
        every, end = steady.every, since + span
        row = entered
        if every is not None and entered >= end:  # the run's last row: a longer run's next row is the grid's
            row = every * math.floor(last_off / every + 1.0)
        text += (
            f"; within {band:.3g} Pa of it from the row at t = {entered:.6g} s on, which carries a state"
            f" {_gap_at(known_t, known_y, level, last_off):+.3g} Pa off at t = {last_off:.6g} s (a row knows the"
            f" solver's states since the row before only by their extremes, so the last state off the band lies"
            f" between t = {last_off:.6g} s and that row): staying so, the run reads steady from about t ="
            f" {row + span:.4g} s on"
        )
        if every is not None:
            text += (
                f" with rows every {every:.6g} s, and unsampled, or with rows finer, from as early as about t ="
                f" {last_off + span:.4g} s"
            )
            if last_off < since < entered:
                text += (
                    f"; it is these rows that keep it undetermined now: the stretch starts at t = {since:.6g} s,"
                    f" between the rows at {first:.6g} and {entered:.6g} s, and counts from the row at {first:.6g} s"
                )
    if abs(v_end - vp) > STEADY_TOLERANCE * vp:
        text += f"; the slider not within {STEADY_TOLERANCE:g} × V0 of V0 at the end"
    return (
        text + f"; it counts as settled once every state over the last {span:.3g} s"
        f" ({SETTLED_RELAXATIONS:g} relaxation times of {steady.relaxation:.3g} s), after the slip, lies within"
        f" {band:.3g} Pa of it)"
    )


def _gap_at(known_t: np.ndarray, known_y: np.ndarray, level: float, when: float) -> float:
    """The departure from ``level`` of the known state at ``when`` farthest from it (signed)."""
    gaps = known_y[known_t == when] - level
    return float(gaps[np.argmax(np.abs(gaps))]) if gaps.size else math.nan


def _ripple(  # type: ignore[no-untyped-def]
    found: regimes.Regime, time, stress, velocity, protocol: Protocol, control: str, resolution, scale: float, between
) -> tuple[str, str, regimes.Regime] | None:
    """Under velocity control at a constant velocity (the last segment's, > 0) Eq 1 is linear in the population and
    asymptotically stable (docs/transient.md section 18): it has no limit cycle and no growing oscillation, and its
    own transients decay.  A trace read as either, or as periods without a trend within RESOLVED x rtol, carries the
    discretisation's ripple.  (regime, message, evidence) saying so: "steady" where the mean over the last quarter
    of the segment is that of the quarter before within SETTLED and the swing there is at most RIPPLE_STEADY of the
    stress; "undetermined" (still changing, or a large swing) for a limit cycle or a growing oscillation otherwise;
    None for every other verdict (the classifier's stands) and under block control."""
    vp = protocol.segments[-1].velocity
    if control != "velocity" or not vp > 0 or time.size < 3:
        return None
    start, end = float(protocol.boundaries[-2]), float(time[-1])
    quarter = regimes.TAIL * (end - start)
    peak, trough = window_extremes(time, stress, between, end - quarter)  # the ripple: the last quarter's swing
    if not (math.isfinite(peak) and quarter > 0):
        return None
    swing = peak - trough
    tolerance = RESOLVED * (resolution if resolution is not None else 10.0 * SETTLED) * scale
    impossible = found.kind in (regimes.STICK_SLIP, regimes.GROWING)
    unresolved = found.kind in (regimes.UNDETERMINED, regimes.DECAYING) and found.periods > 0 and swing < tolerance
    if not (impossible or unresolved):
        return None
    last = _mean_over(time, stress, end - quarter, end)
    drift = last - _mean_over(time, stress, end - 2.0 * quarter, end - quarter)
    settled = abs(drift) <= SETTLED * abs(last) and swing <= RIPPLE_STEADY * abs(last)
    if not (settled or impossible):
        return None
    read = f"{found.periods} swing(s)" + (f" of {found.period:.3g} s" if math.isfinite(found.period) else "")
    ripple = f"{swing:.3g} Pa peak to trough ({swing / abs(last):.2g} of σ; {read}) over the last {quarter:.3g} s"
    why = (
        "under velocity control at a constant velocity Eq 1 is linear in the bonds and asymptotically stable"
        " (docs/transient.md section 18): it has no oscillation of its own"
    )
    window = window_extremes(time, stress, between, start)
    if settled:
        message = (
            f"steady sliding at {vp * 1e6:.6g} µm/s: σ = {stress[-1]:.6g} Pa at t = {end:.6g} s; the trace ripples by"
            f" {ripple}, which is numerical: {why}"
        )
        steady = dataclasses.replace(
            found, kind=regimes.STEADY, periods=0, amplitude_ratio=math.nan, period=math.nan, peak=window[0],
            trough=window[1], evidence=message,
        )  # fmt: skip
        return regimes.STEADY, message, steady
    message = (
        f"undetermined: σ still changes ({drift:+.3g} Pa in its mean over the last {quarter:.3g} s, to {last:.6g} Pa at"
        f" t = {end:.6g} s) and swings by {ripple}; {why}: its transients decay, and a ripple is numerical (a smaller"
        " rtol shrinks it); run longer to see it settle"
    )
    unsettled = dataclasses.replace(
        found, kind=regimes.UNDETERMINED, peak=window[0], trough=window[1], evidence=message
    )  # fmt: skip
    return regimes.UNDETERMINED, message, unsettled


def _mean_over(time: np.ndarray, stress: np.ndarray, a: float, b: float) -> float:
    """The time mean of the rows' stress over [a, b] (trapezoid, linear between the rows)."""
    inside = (time > a) & (time < b)
    t = np.concatenate([[a], time[inside], [b]])
    s = np.concatenate([[np.interp(a, time, stress)], stress[inside], [np.interp(b, time, stress)]])
    return float(np.sum(0.5 * (s[1:] + s[:-1]) * np.diff(t)) / (b - a))


def solution_extremes(
    found: regimes.Regime, time: np.ndarray, stress: np.ndarray, between: Between | None, start: float
) -> regimes.Regime:
    """The classifier's verdict on the rows, with the extremes of the solution: over the window (t >= start) when
    not oscillating, else each refined by the states between its row and the rows either side.

    The verdict is read from the rows, not from the rows with the states between them (:func:`with_extremes`):
    those states come at the steps, and a cohort of aged bonds dying at the FENE wall within a step that lands on
    a row drops the stress by ~1e-5 of a re-slide's peak, which read as a period and flipped a steady verdict."""
    if found.kind not in OSCILLATING:  # the window's extremes, not the last "period" of a verdict without one
        peak, trough = window_extremes(time, stress, between, start)
        if not math.isfinite(peak):
            return found
        return dataclasses.replace(found, peak=peak, trough=trough)
    if between is None:
        return found
    t_all, _ = with_extremes(time, stress, between)
    if t_all.size == time.size:  # every state a row: the rows' extremes are the solution's
        return found
    peak, trough = found.peak, found.trough
    for value, highest in ((found.peak, True), (found.trough, False)):
        for k in np.flatnonzero((stress == value) & (time >= start)).tolist():
            for row in (k, k + 1):
                beyond = between.within(time, row, highest) if row < time.size else None
                if beyond is not None and beyond[0] >= start:
                    peak, trough = (max(peak, beyond[1]), trough) if highest else (peak, min(trough, beyond[1]))
    return dataclasses.replace(found, peak=peak, trough=trough)


def _words(
    found: regimes.Regime,
    time: np.ndarray,
    stress: np.ndarray,
    velocity: np.ndarray,
    protocol: Protocol,
    cycles: tuple[Cycle, ...],
    control: str,
    resolution: float | None,
    scale: float,
    chains: bool = False,
) -> tuple[str, str]:
    """(regime, message) of the run from the classifier's ``found`` and the slider's motion at the end
    (``chains``: the stick chains took the load in this run)."""
    stuck = stuck_mask(time, velocity, protocol)
    vp = protocol.segments[-1].velocity
    whole = [c for c in cycles if c.period is not None]
    swing = found.peak - found.trough
    oscillating = found.kind in (regimes.STICK_SLIP, regimes.DECAYING, regimes.GROWING)
    if oscillating and resolution is not None and swing < RESOLVED * resolution * scale:
        return regimes.UNDETERMINED, (
            f"undetermined: an oscillation of {swing:.3g} Pa peak to trough ({found.evidence}), within"
            f" {RESOLVED:g} × the solver's tolerance (rtol {resolution:g} of {scale:.6g} Pa): whether it grows,"
            f" decays or repeats is not resolved; a smaller rtol resolves it (t = {time[-1]:.6g} s,"
            f" V = {show_velocity(velocity[-1], 3)})"
        )
    if found.kind == regimes.STICK_SLIP and not chains:
        never = _never_sticks(found, time, velocity, protocol)
        if never is not None:
            seen = found.evidence.removeprefix("stick-slip (limit cycle): ")
            return OSCILLATION, (
                f"oscillation (a limit cycle without a stick): {seen}, σ {found.trough:.6g} ... {found.peak:.6g} Pa;"
                f" the slider never sticks (V {show_velocity(never[0], 4)} ... {show_velocity(never[1], 4)} over the"
                f" last {never[2]} period(s), never below {STUCK_FRACTION:.0%} of the puller's"
                f" {show_velocity(vp, 4)}): no stick-slip"
            )
    if found.kind == regimes.STICK_SLIP:
        seen = found.evidence.removeprefix("stick-slip (limit cycle): ")
        text = f"stick-slip (limit cycle): {seen}, σ {found.trough:.6g} ... {found.peak:.6g} Pa"
        if whole:
            c = whole[-1]
            text += (
                f"; {len(cycles)} slip(s) in the run, the last whole cycle: stick {c.stick_time:.4g} s up to"
                f" σs = {c.peak_stress:.5g} Pa, {describe_jump(c.jump_velocity)}, slip {c.slip_time:.4g} s"
            )
        return regimes.STICK_SLIP, text
    if found.kind in (regimes.DECAYING, regimes.GROWING):
        return found.kind, found.evidence
    if stuck[-1] and time.size > 1 and (found.periods == 0 or _rang_and_stuck(time, stress, stuck, protocol, scale)):
        slipped = f" after {len(cycles)} slip(s)" if cycles else ""
        if velocity[-1] != 0.0:
            slow = abs(velocity[-1]) < 1e-6  # nm/s for a creep, µm/s (as the end's V is written) from 1 µm/s up
            creep = f"{velocity[-1] * 1e9:.3g} nm/s" if slow else show_velocity(velocity[-1], 3)
            motion = f"creeps at {creep}"
        elif control == "velocity":
            motion = "is held at rest by the protocol (V = 0 under velocity control)"
        elif not np.any(protocol.velocities > 0):
            motion = "is at rest (the puller never moves: 0 µm/s throughout the protocol)"
        else:
            motion = f"is at rest (the {'stick chains' if chains else 'bonds of Eq 1'} hold it)"
        return (
            regimes.STUCK,
            f"stuck{slipped}: at t = {time[-1]:.6g} s the slider {motion} under σ = {stress[-1]:.6g} Pa",
        )
    if found.kind == regimes.STEADY:
        v_end = float(velocity[-1])
        if control == "block" and vp > 0 and abs(v_end - vp) > STEADY_TOLERANCE * vp:
            return regimes.UNDETERMINED, (
                f"undetermined: the stress is flat but the slider moves at {v_end * 1e6:.6g} µm/s, not the"
                f" puller's {vp * 1e6:.6g} µm/s (t = {time[-1]:.6g} s)"
            )
        return regimes.STEADY, (
            f"steady sliding at {v_end * 1e6:.6g} µm/s: σ = {stress[-1]:.6g} Pa at t = {time[-1]:.6g} s"
            f" ({found.evidence.removeprefix('steady: ')})"
        )
    evidence = found.evidence
    change = _last_change(protocol)
    if change is not None and found.periods == 0 and evidence.startswith("undetermined: "):
        evidence = f"undetermined: {change} has not settled: {evidence.removeprefix('undetermined: ')}"
    return regimes.UNDETERMINED, (
        f"{evidence} at the end of the run (t = {time[-1]:.6g} s, σ = {stress[-1]:.6g} Pa,"
        f" V = {show_velocity(velocity[-1], 3)}): run longer to see where it goes"
    )


def _last_change(protocol: Protocol) -> str | None:
    """The re-slide that starts the last segment after a hold, in words ("the re-slide after the 10 s hold");
    None where the last segment follows no hold."""
    if len(protocol.segments) < 2 or not protocol.segments[-1].velocity > 0:
        return None
    before = protocol.segments[-2]
    return f"the re-slide after the {before.duration:.6g} s hold" if before.velocity == 0.0 else None


def _never_sticks(
    found: regimes.Regime, time: np.ndarray, velocity: np.ndarray, protocol: Protocol
) -> tuple[float, float, int] | None:
    """(slowest, fastest, periods) of the slider over the limit cycle's last periods (the RATIOS_NEEDED + 1 that
    back the verdict, at most those counted) when it never falls below STUCK_FRACTION of the puller's pace there:
    no stick in the cycle; None where it sticks (or the rows there are too few to tell).  A block of 0.1 kg/m^2
    at 300 µm/s rang 683 periods of 29 µs between 184 and 208 µm/s, and read "stick-slip"."""
    if not (math.isfinite(found.period) and found.period > 0):
        return None
    periods = max(1, min(found.periods, regimes.RATIOS_NEEDED + 1))
    tail = time >= max(float(time[-1]) - periods * found.period, float(protocol.boundaries[-2]))
    if np.count_nonzero(tail) < 3:
        return None
    if np.any(stuck_mask(time[tail], velocity[tail], protocol)):
        return None
    return float(np.min(velocity[tail])), float(np.max(velocity[tail])), periods


def _rang_and_stuck(time: np.ndarray, stress: np.ndarray, stuck: np.ndarray, protocol: Protocol, scale: float) -> bool:
    """The slider stuck over (nearly) the whole last segment, the stress without a swing over the second half of
    that stick: the periods the classifier counted were a block with mass ringing as it stopped, not a cycle.

    50 µm/s for 5 s: the massless block is stuck (creeping at 1.26 nm/s under 76.62 Pa); with 10.5 kg/m^2 it
    rang for its first 3.7 ms (26 swings of ~0.1 Pa), then crept the same, and read "undetermined: still changing
    ... no exponential approach" (at 60 s, "about 3.52e+07 Pa still to come") while the stress only rose with the
    puller's travel."""
    start = float(protocol.boundaries[-2])
    moving = np.flatnonzero(~stuck)
    first = int(moving[-1]) + 1 if moving.size else 0
    if first >= time.size or time[first] - start > 0.1 * (time[-1] - start):
        return False
    tail = time >= 0.5 * (time[first] + time[-1])
    if np.count_nonzero(tail) < 3:
        return False
    maxima, minima = regimes.turning_points(stress[tail], SETTLED * max(scale, 1e-300))
    return maxima.size + minima.size == 0


@dataclasses.dataclass(frozen=True)
class _ChainCycle:
    """One stick of the chains (from t_stick under sigma_stick) ended by a slip at t_slip under sigma_s; the
    stick after it (time, stress), if the run reached one."""

    t_stick: float
    sigma_stick: float
    t_slip: float
    sigma_s: float
    after: tuple[float, float] | None

    @property
    def rise(self) -> float:
        return self.sigma_s - self.sigma_stick


def _chain_cycles(events: list, start: float) -> list[_ChainCycle]:
    """The stick -> slip pairs of the chains with both events at or after ``start`` (the last protocol segment)."""
    marks = [(kind, float(t), float(s)) for kind, t, s, _ in events if kind in ("stick", "slip") and t >= start]
    found = []
    for k, (kind, t, sigma) in enumerate(marks):
        if kind != "slip" or k == 0 or marks[k - 1][0] != "stick":
            continue
        after = marks[k + 1][1:] if k + 1 < len(marks) and marks[k + 1][0] == "stick" else None
        found.append(_ChainCycle(marks[k - 1][1], marks[k - 1][2], t, sigma, after))
    return found


def _repeats(first: tuple[float, ...], second: tuple[float, ...], rise: float, resolution: float | None = None) -> bool:
    """The cycle's state repeated: each stress within :func:`_repeat_tolerance` of the one it repeats."""
    return all(abs(b - a) <= _repeat_tolerance(a, b, rise, resolution) for a, b in zip(first, second, strict=True))


def _repeat_tolerance(a: float, b: float, rise: float, resolution: float | None) -> float:
    """:func:`stickslip.regimes.repeat_tolerance`: 2 % of the rise, and no more than the run's rtol x the stress.

    2 % of the rise alone called a soft gel's cycles repeating whose sticks started 0.108 Pa apart and whose σs were
    0.241 Pa apart, 4x the run's tolerance (rtol 1e-4 of 624 Pa = 0.062 Pa), while the cycle after them repeats to
    1e-10 Pa (the solver's error there: 1.2e-3 Pa, against rtol 1e-6): the first was a start-up cycle."""
    return regimes.repeat_tolerance(a, b, rise, resolution)


def _from_events(
    events: list,
    start: float,
    time: np.ndarray,
    stress: np.ndarray,
    lowest: np.ndarray | None = None,
    between: Between | None = None,
    resolution: float | None = None,
) -> regimes.Regime | None:
    """The regime from the stick chains' exact sticks and slips (time, stress), independent of ``every``.

    With the chains a cycle has one number of state: a stick starts with fresh chains, so the stress it starts
    under (and the puller's pace) fixes its slip's σs; a slip lands on the steady population of its jump, so σs
    fixes the stick that follows.  A cycle whose state repeats the one before (the stick's start and σs within
    RATIO_TOLERANCE of its rise), or a stick that starts where the one before started, therefore repeats for
    ever: a limit cycle, shown by two slips (or by one slip and the stick after it).  Otherwise three or more
    whole cycles are judged by their amplitudes (regimes.classify_cycles); fewer are undetermined, in words.
    None when the last segment has no such cycle, or its last event is more than two periods before the end
    (the run left stick-slip: the trace decides).  A limit cycle's period and extremes are its last whole
    cycle's, stick to stick (the cycle the run's summary reports: one period per run), from the events and the
    solution between them (``between``: the solver's states between the rows); any other verdict's extremes
    are the events' or the trace's over the last period, whichever reaches further (the slip's lowest stress can
    come just before the stick); ``lowest``: each row's lowest stress of the solver's steps since the row before
    (``every`` must not move the trough); ``resolution``: the run's rtol, which bounds how far apart the stresses of
    two cycles that repeat may be (:func:`_repeat_tolerance`).
    """
    cycles = _chain_cycles(events, start)
    if not cycles:
        return None
    whole = [c for c in cycles if c.after is not None]
    lengths = [c.after[0] - c.t_stick for c in whole if c.after is not None]
    period = float(np.mean(lengths[-3:])) if lengths else math.nan
    last_event = max(float(t) for _, t, _, _ in events)
    if math.isfinite(period) and float(time[-1]) - last_event > 2 * period:
        return None
    found = _chain_verdict(cycles, whole, resolution)
    if found.kind == regimes.STICK_SLIP and whole:
        cycle = whole[-1]
        assert cycle.after is not None
        high, low = window_extremes(time, stress, between, cycle.t_stick, cycle.after[0])
        events_low = min(cycle.sigma_stick, cycle.after[1])
        peak = max(cycle.sigma_s, high) if math.isfinite(high) else cycle.sigma_s
        trough = min(events_low, low) if math.isfinite(low) else events_low
        return dataclasses.replace(found, peak=peak, trough=trough)
    recent = time >= (cycles[-2].t_slip if len(cycles) >= 2 else cycles[-1].t_stick)
    inside = np.flatnonzero(recent)
    if inside.size:
        troughs = [found.trough, float(np.min(stress[inside]))]
        if lowest is not None and inside.size > 1:  # the first row's steps began before the window: not counted
            troughs.append(float(np.min(lowest[inside[1:]])))
        found = dataclasses.replace(found, peak=max(found.peak, float(np.max(stress[inside]))), trough=min(troughs))
    return found


def _chain_verdict(
    cycles: list[_ChainCycle], whole: list[_ChainCycle], resolution: float | None = None
) -> regimes.Regime:
    """The verdict of the chains' cycles: a limit cycle as soon as one cycle repeats the one before, within the
    run's tolerance (:func:`_repeat_tolerance`).  Its period is the last whole cycle's, stick to stick (the run's
    summary's); a first cycle that does not repeat (the start-up stick, from rest at 0 Pa) gives no period
    (:func:`settled_chain_cycles`).  Cycles that do not repeat are said to drift, by how much per cycle."""
    last = cycles[-1]
    peak = last.sigma_s
    trough = min(c.sigma_stick for c in cycles[-2:])
    repeating = 0  # the trailing cycles that repeat the one before each: the periods that back the verdict
    for prev, this in zip(reversed(cycles[:-1]), reversed(cycles[1:]), strict=True):
        if not _repeats((prev.sigma_stick, prev.sigma_s), (this.sigma_stick, this.sigma_s), prev.rise, resolution):
            break
        repeating += 1
    if repeating:
        prev = cycles[-2]
        ratio = last.rise / prev.rise
        cycle = whole[-1]  # the last whole cycle (the one before the last slip's, at least)
        assert cycle.after is not None
        length = cycle.after[0] - cycle.t_stick
        members = cycles[-(repeating + 1) :]  # the slips whose cycles repeat one another: the limit cycle's
        periods = sum(1 for c in members if c.after is not None)  # its whole cycles, stick to stick: the periods
        before = len(cycles) - len(members)  # the window's cycles before it: start-up cycles, which do not repeat
        evidence = (
            f"stick-slip (limit cycle): {periods} period(s) of {length:.6g} s (its whole cycles, stick to stick; the"
            f" period is the last one's), {len(members)} slips whose cycles repeat"
            + (f", after {before} start-up cycle{' that does' if before == 1 else 's that do'} not" if before else "")
            + f" (the last two: stick from {prev.sigma_stick:.6g} then {last.sigma_stick:.6g} Pa, σs ="
            f" {prev.sigma_s:.6g} then {last.sigma_s:.6g} Pa, amplitude ratio {ratio:.4g};"
            f" {_apart(prev, last, resolution)}): with fresh chains at each stick the cycle repeats from there"
        )
        return regimes.Regime(regimes.STICK_SLIP, periods, ratio, length, peak, trough, evidence)
    if last.after is not None and _repeats((last.sigma_stick,), (last.after[1],), last.rise, resolution):
        length = last.after[0] - last.t_stick
        gap = abs(last.after[1] - last.sigma_stick)
        tolerance = _repeat_tolerance(last.sigma_stick, last.after[1], last.rise, resolution)
        evidence = (
            f"stick-slip (limit cycle): 1 period of {length:.6g} s: the stick after the slip (σs = {last.sigma_s:.6g}"
            f" Pa) starts under {last.after[1]:.6g} Pa, where the one before started ({last.sigma_stick:.6g} Pa;"
            f" {gap:.2g} Pa apart, within {tolerance:.3g} Pa), and with fresh chains the cycle repeats from there"
        )
        if len(cycles) >= 2:  # the cycle before did not repeat this one: a start-up cycle, not the limit cycle
            before = cycles[-2]
            evidence += (
                f"; the cycle before it, from {before.sigma_stick:.6g} Pa to σs = {before.sigma_s:.6g} Pa, was a"
                f" start-up cycle ({_apart(before, last, resolution)})"
            )
        return regimes.Regime(regimes.STICK_SLIP, 1, math.nan, length, peak, trough, evidence)
    if len(whole) >= 3:
        times = [c.t_slip for c in whole]
        troughs = [c.after[1] for c in whole if c.after is not None]
        found = regimes.classify_cycles(times, [c.sigma_s for c in whole], troughs)
        if found.kind != regimes.STICK_SLIP:  # growing or decaying beyond RATIO_TOLERANCE a period: the amplitudes
            return found
        # amplitudes within RATIO_TOLERANCE, but the cycles do not repeat within the run's tolerance: drifting
        return dataclasses.replace(found, kind=regimes.UNDETERMINED, evidence=_drifting(cycles, resolution))
    history = "; ".join(f"stick from {c.sigma_stick:.6g} Pa to σs = {c.sigma_s:.6g} Pa" for c in cycles[-3:])
    if last.after is not None:
        history += f"; the next stick from {last.after[1]:.6g} Pa"
    why = "no cycle repeats the one before yet" if len(cycles) >= 2 or last.after is not None else "no stick after it"
    if len(cycles) >= 2:
        why += f" ({_apart(cycles[-2], last, resolution)})"
    settled = settled_chain_cycles(whole, resolution)
    evidence = (
        f"undetermined: {len(cycles)} slip(s) ({history}), {why}: whether the run settles into a limit cycle needs"
        " another slip"
    )
    if whole and whole[0] not in settled:
        first = whole[0]
        assert first.after is not None
        evidence += (
            f"; the first is the start-up cycle from {first.sigma_stick:.6g} Pa (a transient that does not repeat:"
            f" σs = {first.sigma_s:.6g} Pa, period {first.after[0] - first.t_stick:.6g} s)"
        )
    lengths = [c.after[0] - c.t_stick for c in settled if c.after is not None]
    period = float(np.mean(lengths[-3:])) if lengths else math.nan
    ratio = last.rise / cycles[-2].rise if len(cycles) >= 2 and cycles[-2].rise > 0 else math.nan
    # the periods seen are the whole cycles (the start-up's too); the period only the settled ones'
    return regimes.Regime(regimes.UNDETERMINED, len(whole), ratio, period, peak, trough, evidence)


def _apart(prev: _ChainCycle, this: _ChainCycle, resolution: float | None) -> str:
    """How far two cycles' sticks and σs are apart, against the tolerances they repeat within, in words."""
    gaps = (abs(this.sigma_stick - prev.sigma_stick), abs(this.sigma_s - prev.sigma_s))
    tolerances = (
        _repeat_tolerance(prev.sigma_stick, this.sigma_stick, prev.rise, resolution),
        _repeat_tolerance(prev.sigma_s, this.sigma_s, prev.rise, resolution),
    )
    within = all(g <= t for g, t in zip(gaps, tolerances, strict=True))
    rule = "2 % of the rise" if resolution is None else f"rtol {resolution:g} of each stress"
    return (
        f"sticks {gaps[0]:.3g} Pa apart and σs {gaps[1]:.3g} Pa, {'within' if within else 'beyond'} the run's"
        f" tolerance of {tolerances[0]:.3g} and {tolerances[1]:.3g} Pa, {rule}"
    )


def _drifting(cycles: list[_ChainCycle], resolution: float | None) -> str:
    """Cycles whose amplitudes agree but whose state does not repeat within the run's tolerance, in words: how far
    each stick still moves, and, where successive moves shrink geometrically, how far they still go."""
    sticks = [c.sigma_stick for c in cycles]
    if cycles[-1].after is not None:
        sticks.append(cycles[-1].after[1])
    moves = np.diff(sticks[-3:])
    text = (
        f"undetermined: {len(cycles)} slips whose cycles still drift: the sticks start under"
        f" {', '.join(f'{v:.6g}' for v in sticks[-3:])} Pa, by {moves[-1]:+.3g} Pa in the last cycle"
        f" ({_apart(cycles[-2], cycles[-1], resolution)})"
    )
    if moves.size == 2 and moves[0] != 0 and 0 < moves[1] / moves[0] < 1:
        q = float(moves[1] / moves[0])
        text += f", shrinking by {q:.3g} a cycle: about {abs(moves[1]) * q / (1 - q):.3g} Pa still to come"
    return text + ": run longer to see whether they settle"


def settled_chain_cycles(whole: list[_ChainCycle], resolution: float | None = None) -> list[_ChainCycle]:
    """The whole cycles of the repeating one, as quasistatic.cycle.settled_cycles: every whole cycle after the
    first, and the first when the stick after it starts where it started (within :func:`_repeat_tolerance`).
    A first stick from another stress (from rest: 0 Pa; after a hold) is a start-up cycle that does not repeat."""
    if not whole:
        return []
    first = whole[0]
    assert first.after is not None
    keep_first = _repeats((first.sigma_stick,), (first.after[1],), first.rise, resolution)
    return whole if keep_first else whole[1:]
