"""Laying the model over a measured record: alignment, RMS misfit, per-cycle differences.

The quasi-static model (Eqs 10-17, through the model interface :mod:`stickslip.models`) is run at the
record's pulling velocity.  Its first cycle starts stuck at sigma_c, so it
is aligned with the record's first *whole* cycle: the model's time zero is
put at the record's first start corner that begins a complete cycle (or,
failing that, at the first start corner found; with none, at the record's
first sample), then refined by least squares over that cycle (within
:data:`ALIGN_WINDOW` of its length), so that the overlay does not inherit
the noise of a single corner.  The RMS misfit is taken over the record's samples from that
instant on; the per-cycle differences pair the record's cycles from the
aligned one on with the model's cycles in order.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.optimize import minimize_scalar

from ..columns import with_units
from ..parameters import Parameters
from .cycles import CycleResult, TraceAnalysis

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    from matplotlib.axes import Axes

    from ..quasistatic.cycle import Simulation

#: The shift is refined by least squares within this fraction of the aligned cycle.
ALIGN_WINDOW = 0.05
#: Quantities compared cycle by cycle (record field -> model source).
COMPARED = (
    "critical_stress",
    "stick_slope",
    "stiffness",
    "peak_stress",
    "stick_time",
    "jump_velocity",
    "slip_time",
    "period",
)


@dataclass(frozen=True)
class Comparison:
    """The model at the record's V0, shifted by ``shift`` seconds, and its misfit to the record (SI units)."""

    shift: float
    model_time: np.ndarray
    model_stress: np.ndarray
    model_regime: str
    model_message: str
    rms_misfit: float | None
    points: int
    aligned_cycle: int | None
    cycles: tuple[dict[str, Any], ...]
    message: str
    simulation: Simulation | None = field(default=None, repr=False, compare=False)
    analysis: TraceAnalysis | None = field(default=None, repr=False, compare=False)

    def as_dict(self) -> dict[str, Any]:
        return {
            "shift": self.shift,
            "model_regime": self.model_regime,
            "model_message": self.model_message,
            "rms_misfit": self.rms_misfit,
            "points": self.points,
            "aligned_cycle": self.aligned_cycle,
            "cycles": list(self.cycles),
            "message": self.message,
        }

    def to_frame(self) -> pd.DataFrame:
        """The model's trace on the record's time axis (time, stress; SI units)."""
        import pandas as pd

        return with_units(pd.DataFrame({"time": self.model_time, "stress": self.model_stress}))

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        """The record with its detected phases and the model on top; returns the Axes."""
        from ..plots.traces import plot_analysis

        assert self.analysis is not None
        return plot_analysis(self.analysis, ax=ax, comparison=self, **kwargs)


def compare_with_model(
    analysis: TraceAnalysis, params: Parameters | None = None, jump_curve: str = "aging"
) -> Comparison:
    """Simulate the model at the record's V0, align it with the first whole cycle, and measure the misfit."""
    from ..models import Rig, get_model
    from ..protocols import constant

    params = analysis.parameters if params is None else params
    t, x = analysis.time, analysis.stress
    anchor, aligned = _anchor(analysis)
    shift = float(t[0]) if anchor is None else anchor
    duration = float(t[-1]) - shift
    if duration <= 0:  # the anchor is the last instant of the record: nothing to overlay
        duration = max(float(t[-1] - t[0]), 1e-9)
    protocol = constant(analysis.pulling_velocity, duration + ALIGN_WINDOW * duration)
    # the Run's native result is the Simulation: its phases give the per-cycle comparison
    sim = get_model("quasi-static").run(params, protocol, Rig(), jump_curve=jump_curve).native
    if anchor is not None:
        shift = _refine_shift(analysis, sim, shift, aligned)
    model_time = sim.time + shift
    shown = model_time <= t[-1]  # the model was run a little longer, for the shift's refinement
    shown[: max(int(np.count_nonzero(shown)), 2)] = True
    model_time, model_stress = model_time[shown], sim.stress[shown]
    inside = np.isfinite(x) & (t >= shift) & (t <= model_time[-1])
    rms = None
    if np.any(inside):
        residual = x[inside] - np.interp(t[inside], model_time, model_stress)
        rms = float(np.sqrt(np.mean(residual**2)))
    rows = _per_cycle(analysis, sim, aligned, params)
    notes = []
    if anchor is None:
        notes.append("no stick start in the record: the model starts at the record's first sample")
    else:
        notes.append(
            f"model time 0 put at t = {shift:.6g} s, the start of record cycle {aligned}"
            f" (corner at {anchor:.6g} s, refined by least squares)"
        )
    if sim.regime != analysis.regime:
        notes.append(f"the record is {analysis.regime} but the model is {sim.regime} at this V0")
    return Comparison(
        shift=shift,
        model_time=model_time,
        model_stress=model_stress,
        model_regime=sim.regime.kind,
        model_message=sim.message,
        rms_misfit=rms,
        points=int(np.count_nonzero(inside)),
        aligned_cycle=aligned,
        cycles=tuple(rows),
        message="; ".join(notes),
        simulation=sim,
        analysis=analysis,
    )


def _refine_shift(analysis: TraceAnalysis, sim: Simulation, shift: float, aligned: int | None) -> float:
    """Least-squares time shift of the model over the aligned cycle, within ALIGN_WINDOW of its period."""
    cycle = next(c for c in analysis.cycles if c.index == aligned)
    end = cycle.end_time if cycle.end_time is not None else cycle.peak_time
    if end is None or not sim.cycles:
        return shift
    span = end - shift
    t, x = analysis.time, analysis.stress
    inside = np.isfinite(x) & (t >= shift) & (t <= end)
    if np.count_nonzero(inside) < 3:
        return shift
    times, values = t[inside], x[inside]

    def misfit(candidate: float) -> float:
        return float(np.mean((values - np.interp(times - candidate, sim.time, sim.stress)) ** 2))

    reach = ALIGN_WINDOW * span
    best = minimize_scalar(misfit, bounds=(shift - reach, shift + reach), method="bounded")
    return float(best.x) if best.fun < misfit(shift) else shift


def _anchor(analysis: TraceAnalysis) -> tuple[float | None, int | None]:
    started = [c for c in analysis.cycles if c.start_time is not None]
    chosen = next((c for c in started if c.complete), started[0] if started else None)
    return (None, None) if chosen is None else (chosen.start_time, chosen.index)


def _model_values(sim: Simulation, k: int, params: Parameters) -> dict[str, float | None]:
    model = sim.cycles[k]
    slope = params.block.effective_stiffness * sim.pulling_velocity
    return {
        "critical_stress": model.start_stress,
        "stick_slope": slope,
        "stiffness": params.block.stiffness,
        "peak_stress": model.peak_stress,
        "stick_time": model.stick_time,
        "jump_velocity": model.jump_velocity,
        "slip_time": model.slip_time,
        "period": model.period,
    }


def _per_cycle(
    analysis: TraceAnalysis, sim: Simulation, aligned: int | None, params: Parameters
) -> list[dict[str, Any]]:
    if aligned is None:
        return []
    record: list[CycleResult] = [c for c in analysis.cycles if c.index >= aligned]
    rows = []
    for k, cycle in enumerate(record[: len(sim.cycles)]):
        model = _model_values(sim, k, params)
        measured = {name: getattr(cycle, name) for name in COMPARED}
        difference = {
            name: (measured[name] - model[name]) if measured[name] is not None and model[name] is not None else None
            for name in COMPARED
        }
        rows.append(
            {
                "record_cycle": cycle.index,
                "model_cycle": k + 1,
                "complete": cycle.complete,
                "record": measured,
                "model": model,
                "difference": difference,
            }
        )
    return rows
