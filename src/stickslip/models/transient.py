"""The time-dependent bond model (Eqs 1-5, :func:`stickslip.transient.run_transient`) behind the interface."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import regimes
from ..parameters import Parameters
from ..protocols import Protocol
from .base import Boundary, Capabilities, Rig
from .bond import STIFFNESS_KEYS, BondModel
from .run import Run, time_mean

NAN = math.nan
#: relative stress change that counts as none (stickslip.transient.cycles.SETTLED, the solver's own verdict's)
SETTLED = 1e-5


class Transient(BondModel):
    """The population balance of bonds under any piecewise-constant protocol, rigid or through the block.

    ``start``: "empty" (no bonds, no stress; the default) or "steady" (the steady population at the first
    segment's velocity, or at the setting ``start_velocity``).  A spring rig's ``mass`` and ``damping`` give the
    block inertia (run_transient's ``mass``, ``damping``).  Settings: those of ``run_transient``
    (``stick_population``, ``aging``, ``start_velocity``, ``every``, ``rtol``, ``max_step``, ``max_steps``,
    ``max_time``, ``reduction``, ``snapshot_times``, ``progress``).
    """

    name = "transient"
    aliases = ("time-dependent", "population-balance")
    description = "bond model, time-dependent population balance (Eqs 1-5)"
    capabilities = Capabilities(
        controls=("spring", "velocity"),
        protocols="any",
        damping=True,
        mass=True,
        settings=(
            "stick_population", "aging", "start_velocity", "every", "rtol", "max_step", "max_steps", "max_time",
            "reduction", "snapshot_times", "progress",
        ),
    )  # fmt: skip
    sweep_start = "steady"
    requires = ("stickslip.transient",)

    def run(
        self, params: Parameters, protocol: Protocol, rig: Rig | None = None, *, start: Any = None, **settings: Any
    ) -> Run:
        from ..transient import run_transient

        rig = self.check(protocol, rig, settings)
        control = "velocity" if rig.control == "velocity" else "block"
        if rig.stiffness is not None:
            settings["stiffness"] = rig.stiffness
        if rig.has_mass or rig.has_damping:  # the block's inertia and damping (docs/extensions.md section 4)
            settings.update(mass=rig.mass, damping=rig.damping)
        result = run_transient(params, protocol, control=control, start="empty" if start is None else start, **settings)
        return transient_run(result, protocol)

    def estimate_seconds(
        self, params: Parameters, protocol: Protocol, rig: Rig | None = None, *, start: Any = None, **settings: Any
    ) -> float:
        """The CPU seconds a run should take (``estimate_cost``, no step taken); a sweep runs its dearest first."""
        from ..transient.solver import estimate_cost

        rig = self.check(protocol, rig, settings)
        taken = ("stick_population", "aging", "start_velocity", "every", "rtol", "max_step", "reduction")
        options = {k: v for k, v in settings.items() if k in taken}
        if rig.stiffness is not None:
            options["stiffness"] = rig.stiffness
        if rig.has_mass:
            options["mass"] = rig.mass
        control = "velocity" if rig.control == "velocity" else "block"
        start = "empty" if start is None else start
        return estimate_cost(params, protocol, control=control, start=start, **options).seconds

    def describe_start(self, start: Any, protocol: Protocol, settings: Any = None) -> str:
        from ..display import velocity

        if start is None or start == "empty":
            return "empty: no bonds, no stress"
        if start == "steady":
            at = (settings or {}).get("start_velocity") or protocol.segments[0].velocity
            return f"steady population at {velocity(float(at), 4)}"
        return f"start {start!r}"

    def stability_boundary(self, fixed: Any, x: str, y: str, frame: Any = None) -> list[Boundary]:
        """Kc(V0) of the linear stability of steady sliding, in the plane (V0, a stiffness key)."""
        from ..transient import critical_stiffness

        stiffness_axes = ("block.height", *STIFFNESS_KEYS)
        if frame is None or "pulling_velocity" not in (x, y) or not ({x, y} & set(stiffness_axes)):
            return []
        other = y if x == "pulling_velocity" else x
        params = self.parameters(None, {k: v for k, v in fixed.items() if k != "pulling_velocity"})
        lo, hi = float(frame["pulling_velocity"].min()), float(frame["pulling_velocity"].max())
        velocity = np.geomspace(max(lo, 1e-12), max(hi, 2e-12), 80)
        kc = np.array([critical_stiffness(params, v) for v in velocity], dtype=float)
        good = np.isfinite(kc) & (kc > 0)
        along = self.stiffness_of(other, params, kc[good])
        curve = (velocity[good], along) if x == "pulling_velocity" else (along, velocity[good])
        return [Boundary(curve[0], curve[1], "K = Kc(V0), linear stability")]


def transient_run(result: Any, protocol: Protocol | None = None) -> Run:
    """The :class:`Run` of a :class:`stickslip.transient.TransientResult` (regime from its slip events, in the
    protocol's last segment; over the whole run without the protocol)."""
    summary = last_cycle_numbers(result)
    states: dict[str, Any] = {}
    units: dict[str, str | None] = {}
    if getattr(result, "bonded_fraction", None) is not None:
        states["bonded_fraction"], units["bonded_fraction"] = result.bonded_fraction, "1"
    if getattr(result, "chain_fraction", None) is not None:
        states["chain_fraction"], units["chain_fraction"] = result.chain_fraction, "1"
        if hasattr(result, "held_by"):
            states["held_by"], units["held_by"] = result.held_by, None
    return Run(
        model=Transient.name,
        time=result.time,
        stress=result.stress,
        friction=None,
        # the names of a TransientResult, or of the quasi-static Simulation a stand-in solver may return
        slider_velocity=_first(result, "slider_velocity", "velocity"),
        slider_position=_first(result, "slider_position", "slider_displacement"),
        load_point_position=_first(result, "puller_position", "puller_displacement"),
        regime=_regime(result, protocol),
        mean=summary["mean_stress"],
        states=states,
        state_units=units,
        summary=summary,
        message=result.message,
        status=getattr(result, "status", "ok"),  # (a stand-in solver's result may have none)
        native=result,
    )


def _first(result: Any, *names: str) -> Any:
    return next(getattr(result, n) for n in names if hasattr(result, n))


def _regime(result: Any, protocol: Protocol | None) -> regimes.Regime:
    """The solver's verdict, with the evidence of the one classifier: the slips' exact peaks and the sticks'
    troughs (cycles) in the last segment when it oscillates, the classifier on the solver's steps otherwise."""
    found = getattr(result, "evidence", None)
    if isinstance(found, regimes.Regime):  # the solver's own verdict: the same periods and extremes, in the same words
        return regimes.Regime(
            result.regime, found.periods, found.amplitude_ratio, found.period, found.peak, found.trough, result.message
        )
    start = float(protocol.boundaries[-2]) if protocol is not None else float(result.time[0])
    whole = [c for c in result.cycles if c.period is not None and c.start_time >= start]
    time, stress = np.asarray(result.time, dtype=float), np.asarray(result.stress, dtype=float)
    if len(whole) >= 2 and result.regime in (regimes.STICK_SLIP, regimes.DECAYING, regimes.GROWING):
        peaks = [c.peak_stress for c in whole]
        troughs = [c.start_stress for c in whole[1:]] + [_last_trough(result, whole[-1].start_time)]
        found = regimes.classify_cycles([c.start_time + c.stick_time for c in whole], peaks, troughs)
    else:
        names = ("lowest_stress", "highest_stress", "lowest_time", "highest_time", "fastest_velocity")
        columns = [getattr(result, name, None) for name in names]
        if all(c is not None for c in columns):
            # the solver's own result: the states between its rows (sampled by ``every``) give the tolerance and
            # the extremes (a stand-in solver's result has no such columns, and its package no cycles module)
            from ..transient.cycles import Between, solution_extremes, with_extremes

            between = Between(*columns)
            t_all, s_all = with_extremes(time, stress, between)
            inside = t_all >= start
            scale = float(np.max(np.abs(s_all[inside]))) if np.any(inside) else 0.0
            found = regimes.classify(time, stress, floor=SETTLED * max(scale, 1e-300), start=start, unit="Pa")
            found = solution_extremes(found, time, stress, between, start)
        else:
            inside = time >= start
            scale = float(np.max(np.abs(stress[inside]))) if np.any(inside) else 0.0
            found = regimes.classify(time, stress, floor=SETTLED * max(scale, 1e-300), start=start, unit="Pa")
    return regimes.Regime(
        str(result.regime), found.periods, found.amplitude_ratio, found.period, found.peak, found.trough, result.message
    )


def last_cycle_numbers(result: Any) -> dict[str, Any]:
    """The last whole cycle's numbers (the run has settled onto its cycle by then, if ever) and the mean stress
    over the whole cycles (over the run when there are none); ``run_mean_stress`` over the run."""
    whole = [c for c in result.cycles if getattr(c, "period", None) is not None]
    time = np.asarray(result.time, dtype=float)
    row: dict[str, Any] = {
        "regime": str(result.regime),  # a kind name (a Regime compares and prints as its kind)
        "period": NAN,
        "stick_time": NAN,
        "peak_stress": NAN,
        "jump_velocity": NAN,
        "mean_stress": _mean_stress(result, time[0], time[-1]),
        "cycles": len(whole),
        "critical_velocity": NAN,
    }
    row["run_mean_stress"] = row["mean_stress"]  # the mean over the run, whatever the cycles (run --json)
    if whole:
        last = whole[-1]
        row.update(
            period=last.period, stick_time=last.stick_time, peak_stress=last.peak_stress,
            jump_velocity=last.jump_velocity,
        )  # fmt: skip
        end = last.start_time + last.period
        following = [c.start_stress for c in result.cycles if c.index == last.index + 1]
        row["mean_stress"] = _mean_stress(result, whole[0].start_time, end, whole[0].start_stress, *following[:1])
    return row


def _mean_stress(result: Any, start: float, end: float, *exact: float) -> float:
    """Mean stress over [start, end] from the integral of sigma dt the solver keeps (not from the rows written:
    ``every`` must not change it); ``exact``: sigma at start (and end) where known (a stick event)."""
    time, stress = np.asarray(result.time, dtype=float), np.asarray(result.stress, dtype=float)
    book = getattr(result, "bookkeeping", None)
    integral = getattr(book, "stress_integral", None)
    if integral is None or not end > start or not np.all(np.isfinite(integral)):  # a stand-in's trace
        inside = (time >= start) & (time <= end)
        return time_mean(time[inside], stress[inside]) if np.count_nonzero(inside) > 1 else time_mean(time, stress)
    chains = getattr(result, "chain_fraction", None)
    stuck = np.isfinite(chains) if chains is not None else np.zeros(time.size, dtype=bool)
    at = [_integral_at(time, stress, integral, stuck, t, *exact[k : k + 1]) for k, t in enumerate((start, end))]
    return (at[1] - at[0]) / (end - start)


def _integral_at(
    time: np.ndarray, stress: np.ndarray, integral: np.ndarray, stuck: np.ndarray, t: float, *sigma: float
) -> float:
    """The integral at t between rows: back from the next row by the trapezoid, with sigma(t) given, or on the
    line through the next two rows where the chains hold the block (sigma = K (P - X) is linear there: exact),
    else interpolated."""
    k = int(np.searchsorted(time, t, side="left"))
    if k >= time.size:
        return float(integral[-1])
    if time[k] == t or k == 0:
        return float(integral[k])
    if sigma:
        here = sigma[0]
    elif k + 1 < time.size and stuck[k] and stuck[k + 1]:
        here = float(stress[k] + (stress[k + 1] - stress[k]) * (t - time[k]) / (time[k + 1] - time[k]))
    else:
        here = float(np.interp(t, time, stress))
    return float(integral[k] - 0.5 * (here + stress[k]) * (time[k] - t))


def _last_trough(result: Any, start: float) -> float:
    """The lowest stress from ``start`` on, from the solver's accepted states (each row carries the lowest of the
    steps it closes: ``every`` must not move the trough) and the stick events' exact stresses."""
    time, stress = np.asarray(result.time, dtype=float), np.asarray(result.stress, dtype=float)
    lowest = getattr(result, "lowest_stress", None)
    inside = np.flatnonzero(time >= start)
    values = stress[inside].tolist()
    if lowest is not None and inside.size > 1:  # the first row's steps began before start: its own stress only
        values += np.asarray(lowest, dtype=float)[inside[1:]].tolist()
    sticks = [c.start_stress for c in result.cycles if c.start_time >= start]
    return float(min([*values, *sticks]))
