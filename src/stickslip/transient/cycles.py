"""Cycles and regime of a time-dependent trace, in the vocabulary of ``model.cycle.simulate``."""

from __future__ import annotations

import numpy as np

from ..model.cycle import Cycle
from ..protocols import Protocol

#: the slider counts as stuck below this fraction of the puller velocity
STUCK_FRACTION = 0.01
#: steady: over the last fifth of the final segment sigma and V vary by less than this (relative)
STEADY_TOLERANCE = 1e-3


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
    """A cycle is a stick that ended in a slip; its slip lasts until the next stick (None if the run ends first)."""
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


def classify(
    time: np.ndarray,
    stress: np.ndarray,
    velocity: np.ndarray,
    protocol: Protocol,
    cycles: tuple[Cycle, ...],
    events: list,
    control: str,
    stop: str | None,
) -> tuple[str, str]:
    """(regime, message): "stick-slip", "steady", "stuck" or "undetermined"."""
    if stop is not None:
        return "undetermined", stop
    stuck = stuck_mask(time, velocity, protocol)
    whole = [c for c in cycles if c.period is not None]
    t_last = protocol.boundaries[-2]
    tail = time >= t_last + 0.8 * (time[-1] - t_last)
    vp = protocol.segments[-1].velocity
    if len(whole) >= 1:
        c = whole[-1]
        return "stick-slip", (
            f"stick-slip: {len(cycles)} slip(s), {len(whole)} whole cycle(s); last: stick {c.stick_time:.4g} s up to"
            f" sigma_s = {c.peak_stress:.5g} Pa, jump to {c.jump_velocity * 1e6:.4g} um/s, slip {c.slip_time:.4g} s"
        )
    if stuck[-1]:
        slipped = f" after {len(cycles)} slip(s)" if cycles else ""
        return "stuck", (
            f"stuck{slipped}: at t = {time[-1]:.6g} s the slider creeps at {velocity[-1]:.3g} m/s under"
            f" sigma = {stress[-1]:.6g} Pa"
        )
    s_tail, v_tail = stress[tail], velocity[tail]
    settled = np.ptp(s_tail) <= STEADY_TOLERANCE * max(abs(stress[-1]), 1e-300)
    if control == "block" and vp > 0:
        settled = settled and abs(v_tail[-1] - vp) <= STEADY_TOLERANCE * vp and np.ptp(v_tail) <= STEADY_TOLERANCE * vp
    if settled:
        return "steady", (
            f"steady sliding at {velocity[-1] * 1e6:.6g} um/s: sigma = {stress[-1]:.6g} Pa at t = {time[-1]:.6g} s"
        )
    return "undetermined", (
        f"still changing at the end of the run (t = {time[-1]:.6g} s, sigma = {stress[-1]:.6g} Pa,"
        f" V = {velocity[-1]:.3g} m/s): run longer to see where it goes"
    )
