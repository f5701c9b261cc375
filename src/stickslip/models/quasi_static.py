"""The quasi-static bond model (stick -> jump -> slip cycles, :func:`stickslip.simulate`) behind the interface."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import regimes
from ..parameters import Parameters
from ..protocols import Protocol
from .base import Boundary, Capabilities, Rig
from .bond import BondModel
from .run import Run, time_mean

NAN = math.nan


class QuasiStatic(BondModel):
    """Juvekar & Singh's cycle: one constant pulling velocity through the block's spring (Eq 17), no inertia.

    ``start``: the stress (Pa) of the first stick (default sigma_c); setting ``jump_curve`` ("aging" or
    "no-aging").  The regime follows from the phases (every cycle after the first is the same cycle), so
    its amplitude ratio is exactly 1 once a cycle repeats.
    """

    name = "quasi-static"
    aliases = ("quasistatic", "cycle", "simulate")
    description = "bond model, quasi-static stick-jump-slip cycles (Eqs 6-17)"
    capabilities = Capabilities(controls=("spring",), protocols="constant", settings=("jump_curve",))
    start_dimension = "stress"
    start_words = ()

    def run(
        self, params: Parameters, protocol: Protocol, rig: Rig | None = None, *, start: Any = None, **settings: Any
    ) -> Run:
        from ..quasistatic.cycle import simulate

        rig = self.check(protocol, rig, settings)
        params = self.with_rig(_checked(params), rig)
        velocity, duration = protocol.segments[0].velocity, protocol.segments[0].duration
        sim = simulate(params, velocity, duration, start_stress=start, jump_curve=settings.get("jump_curve", "aging"))
        return simulation_run(sim)

    def describe_start(self, start: Any, protocol: Protocol, settings: Any = None) -> str:
        if start is None:
            return "first stick from σc (the cycle's own start)"
        return f"first stick from {float(start):.6g} Pa"

    def stability_boundary(self, fixed: Any, x: str, y: str, frame: Any = None) -> list[Boundary]:
        """V0 = Vc: the critical velocity against the other axis (from the rows' own Vc)."""
        if frame is None or "pulling_velocity" not in (x, y) or "critical_velocity" not in frame:
            return []
        other = y if x == "pulling_velocity" else x
        if other in frame:
            vc = frame.groupby(other)["critical_velocity"].median().dropna()
            along, critical = vc.index.to_numpy(dtype=float), vc.to_numpy(dtype=float)
        else:
            critical = np.full(2, float(frame["critical_velocity"].median()))
            along = np.array([np.nan, np.nan])
        curve = (critical, along) if x == "pulling_velocity" else (along, critical)
        return [Boundary(curve[0], curve[1], "V0 = Vc (Eq 9)")]


def _checked(params: Any) -> Parameters:
    from ..quasistatic.steady import require_parameters

    require_parameters(params)
    return params


def simulation_run(sim: Any) -> Run:
    """The :class:`Run` of a :class:`stickslip.Simulation` (its phases give the regime and the cycle's numbers)."""
    summary = cycle_numbers(sim)
    return Run(
        model=QuasiStatic.name,
        time=sim.time,
        stress=sim.stress,
        friction=None,
        slider_velocity=sim.velocity,
        slider_position=sim.slider_displacement,
        load_point_position=sim.puller_displacement,
        regime=sim.regime,  # the engine's, with its evidence (the phases: every cycle after the first repeats)
        mean=summary["mean_stress"],
        states={"block_shear": sim.block_shear, "chain_fraction": sim.chain_fraction, "phase": sim.phase},
        state_units={"block_shear": "m", "chain_fraction": "1", "phase": None},
        summary=summary,
        message=sim.message,
        # a run the model stopped short of its duration without an answer failed (exit 3), as other models' do
        status=getattr(sim, "status", "ok"),
        native=sim,
    )


def cycle_numbers(sim: Any) -> dict[str, Any]:
    """The repeating cycle's numbers (SI): period, stick time, sigma_s, Vs, the mean stress over the cycle, and how
    many whole ones the run holds (the run's own extremes are its regime's)."""
    row: dict[str, Any] = {
        "regime": sim.regime.kind,
        "period": NAN,
        "stick_time": NAN,
        "peak_stress": NAN,
        "jump_velocity": NAN,
        "mean_stress": time_mean(sim.time, sim.stress),
        # the regime's periods: in stick-slip the whole cycles of the repeating one (a start-up cycle from another
        # stress than σc does not repeat); otherwise every whole cycle, as counted before
        "cycles": sim.regime.periods,
        "critical_velocity": sim.critical_velocity,
    }
    k = _repeating_index(sim)
    if len(sim.slip_phases) > k and len(sim.jumps) > k and sim.jumps[k].velocity is not None:
        stick, slip = sim.stick_phases[k], sim.slip_phases[k]
        row.update(stick_time=stick.stick_time, peak_stress=stick.peak_stress, jump_velocity=sim.jumps[k].velocity)
        if sim.regime == regimes.STICK_SLIP:
            row["period"] = stick.stick_time + slip.duration
            row["mean_stress"] = _cycle_mean(stick, slip, sim.stiffness, sim.pulling_velocity)
        elif sim.regime == regimes.STEADY:
            row["mean_stress"] = slip.end_stress
    return row


def _repeating_index(sim: Any) -> int:
    """The phases of the repeating cycle: every stick after a slip starts at sigma_c, so the first one does too
    unless the run started elsewhere (``start_stress``); then the second."""
    sticks = sim.stick_phases
    if len(sticks) > 1 and len(sim.slip_phases) > 1 and sticks[0].start_stress != sticks[1].start_stress:
        return 1
    return 0


def _cycle_mean(stick: Any, slip: Any, stiffness: float, velocity: float) -> float:
    """Mean stress over the repeating cycle: the stick's is linear in time (Eq 12), the slip's by trapezoids."""
    ts = stick.stick_time
    stick_integral = stick.start_stress * ts + 0.5 * stiffness * velocity * ts * ts
    t, s = slip.time, slip.stress
    slip_integral = float(np.sum(np.diff(t) * (s[1:] + s[:-1])) / 2.0) if t.size > 1 else 0.0
    return (stick_integral + slip_integral) / (ts + slip.duration)
