"""Cycles and regime of a time-dependent trace, in the vocabulary of ``model.cycle.simulate``."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import regimes
from ..display import velocity as show_velocity
from ..model.cycle import Cycle
from ..protocols import Protocol

#: the slider counts as stuck below this fraction of the puller velocity
STUCK_FRACTION = 0.01
#: steady under block control: the slider's velocity within this fraction of the puller's
STEADY_TOLERANCE = 1e-3
#: steady: the stress has stopped changing within this fraction of it (a tenth of the solver's default rtol)
SETTLED = 1e-5
#: an oscillation's growth or decay is judged only above this many times the solver's tolerance, peak to trough
RESOLVED = 10.0


def stuck_mask(time: np.ndarray, velocity: np.ndarray, protocol: Protocol) -> np.ndarray:
    vp = protocol.velocity_at(np.minimum(time, np.nextafter(protocol.duration, 0.0)))
    reference = np.maximum(vp, np.max(protocol.velocities))  # holds (vp = 0) keep the sliding scale
    return velocity < STUCK_FRACTION * np.where(vp > 0, vp, reference)


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each run of True."""
    edges = np.diff(np.r_[0, mask.astype(int), 0])
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1) - 1
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


def detect_cycles(
    time: np.ndarray, stress: np.ndarray, velocity: np.ndarray, protocol: Protocol, events: list
) -> tuple[Cycle, ...]:
    """A cycle is a stick that ended in a slip; its slip lasts until the next stick (None if the run ends first).

    With the stick chains the solver records each stick and slip as an event at its exact time and stress:
    the cycles are read from those, whatever the sampling; otherwise from the trace.
    """
    from_events = _cycles_from_events(events)
    if from_events:
        return from_events
    stuck = stuck_mask(time, velocity, protocol)
    runs = _runs(stuck)
    cycles: list[Cycle] = []
    for k, (a, z) in enumerate(runs):
        if z + 1 >= time.size:
            break  # still stuck at the end: no slip
        nxt = runs[k + 1][0] if k + 1 < len(runs) else None
        slip_end = nxt if nxt is not None else time.size - 1
        jump = float(np.max(velocity[z + 1 : slip_end + 1])) if slip_end > z else float(velocity[z + 1])
        vp = float(protocol.velocity_at(min(time[z + 1], np.nextafter(protocol.duration, 0.0))))
        if jump <= vp:
            continue  # the slider crept back up to the puller's pace without jumping: no slip
        stick_time = float(time[z + 1] - time[a])
        slip_time = float(time[nxt] - time[z + 1]) if nxt is not None else None
        cycles.append(
            Cycle(
                index=len(cycles),
                start_time=float(time[a]),
                start_stress=float(stress[a]),
                peak_stress=float(np.max(stress[a : z + 2])),
                stick_time=stick_time,
                jump_velocity=jump,
                slip_time=slip_time,
                period=None if slip_time is None else stick_time + slip_time,
            )
        )
    return tuple(cycles)


def _cycles_from_events(events: list) -> tuple[Cycle, ...]:
    marks = [(kind, float(t), float(sigma), float(v)) for kind, t, sigma, v in events if kind in ("stick", "slip")]
    cycles: list[Cycle] = []
    for k, (kind, t_slip, sigma_s, v_jump) in enumerate(marks):
        if kind != "slip" or k == 0 or marks[k - 1][0] != "stick":
            continue
        _, t_stick, sigma_stick, _ = marks[k - 1]
        nxt = next((t for kind2, t, _, _ in marks[k + 1 :] if kind2 == "stick"), None)
        stick_time = t_slip - t_stick
        slip_time = None if nxt is None else nxt - t_slip
        cycles.append(
            Cycle(
                index=len(cycles),
                start_time=t_stick,
                start_stress=sigma_stick,
                peak_stress=sigma_s,
                stick_time=stick_time,
                jump_velocity=v_jump,
                slip_time=slip_time,
                period=None if slip_time is None else stick_time + slip_time,
            )
        )
    return tuple(cycles)


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
    """(regime, message) of the last protocol segment, by :func:`stickslip.regimes.classify` on the stress.

    "stick-slip" (a limit cycle: the amplitude constant over the last periods), "steady" (stress and, under
    block control, the slider's velocity settled), "decaying oscillation", "growing oscillation", "stuck"
    (no slip, the slider below 1 % of the puller's pace at the end) or "undetermined" with the evidence.
    "Settled" means within :data:`SETTLED` of the stress (a tenth of the solver's default rtol).
    ``resolution``: the solver's local error tolerance (relative).  Whether an oscillation grows, decays or
    repeats (a limit cycle) is judged only when its peak-to-trough stress is :data:`RESOLVED` times that
    tolerance of the stress or more: a smaller one is within what the steps may get wrong (a block with mass
    ringing against resting bonds at rtol 1e-4 swung by 2 x the tolerance, ~4 steps a period, and read as
    growing, or as a limit cycle, while it decays).
    """
    if stop is not None:
        return regimes.UNDETERMINED, stop
    start = float(protocol.boundaries[-2])
    inside = time >= start
    scale = float(np.max(np.abs(stress[inside]))) if np.any(inside) else 0.0
    floor = SETTLED * max(scale, 1e-300)
    found = _from_events(events, start, time, stress) or regimes.classify(
        time, stress, floor=floor, start=start, unit="Pa"
    )
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
    if found.kind == regimes.STICK_SLIP:
        seen = found.evidence.removeprefix("stick-slip (limit cycle): ")
        text = f"stick-slip (limit cycle): {seen}, σ {found.trough:.6g} ... {found.peak:.6g} Pa"
        if whole:
            c = whole[-1]
            text += (
                f"; {len(cycles)} slip(s), last: stick {c.stick_time:.4g} s up to σs = {c.peak_stress:.5g} Pa,"
                f" jump to {c.jump_velocity * 1e6:.4g} µm/s, slip {c.slip_time:.4g} s"
            )
        return regimes.STICK_SLIP, text
    if found.kind in (regimes.DECAYING, regimes.GROWING):
        return found.kind, found.evidence
    if stuck[-1] and found.periods == 0 and time.size > 1:
        slipped = f" after {len(cycles)} slip(s)" if cycles else ""
        motion = (
            "is at rest (the stick chains hold it)"
            if velocity[-1] == 0.0
            else f"creeps at {velocity[-1] * 1e9:.3g} nm/s"
        )
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
    return regimes.UNDETERMINED, (
        f"{found.evidence} at the end of the run (t = {time[-1]:.6g} s, σ = {stress[-1]:.6g} Pa,"
        f" V = {show_velocity(velocity[-1], 3)}): run longer to see where it goes"
    )


def _from_events(events: list, start: float, time: np.ndarray, stress: np.ndarray) -> regimes.Regime | None:
    """The regime from the stick chains' exact slips and sticks (time, stress), independent of ``every``.

    Each slip (the chains collapse at sigma_s) and the stick that follows it (sigma where the slider stops) is
    one period's peak and trough.  None when the run has no such cycles in its last segment, or when the last
    of them ended more than two periods before the end (the run left stick-slip: the trace decides).  The
    reported extremes are the events' or the trace's over the last period, whichever reaches further (both
    are values of the solution; the slip's lowest stress can come just before the stick).
    """
    slips = [(t, s) for kind, t, s, _ in events if kind == "slip" and t >= start]
    sticks = [(t, s) for kind, t, s, _ in events if kind == "stick" and t >= start]
    times, peaks, troughs = [], [], []
    for t_slip, sigma_s in slips:
        after = [s for t, s in sticks if t > t_slip]
        if not after:
            break
        times.append(t_slip)
        peaks.append(sigma_s)
        troughs.append(after[0])
    if not times:
        return None
    found = regimes.classify_cycles(times, peaks, troughs)
    last_event = max(t for _, t, _, _ in events)
    if math.isfinite(found.period) and float(time[-1]) - last_event > 2 * found.period:
        return None
    last = time >= (times[-2] if len(times) >= 2 else times[-1])
    if np.any(last):
        found = dataclasses.replace(
            found,
            peak=max(found.peak, float(np.max(stress[last]))),
            trough=min(found.trough, float(np.min(stress[last]))),
        )
    return found
