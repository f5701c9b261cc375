"""Everything the report computes, once: the model's counterpart of each number the paper states.

:class:`ModelRun` holds the results; :func:`run_steps` lists the named steps
that fill it (so the caller can show progress); :func:`computed_values` maps
each :mod:`~stickslip.report.paper` key to the value computed here and a
short note on how.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..analysis import TraceAnalysis, analyze_trace
from ..errors import ModelError
from ..model.critical import CriticalPoint, critical_point
from ..model.cycle import Simulation, simulate
from ..model.jump import Jump, jump_velocity
from ..model.slip import SlipPhase, slip_phase
from ..model.steady import steady_state
from ..model.stick import StickPhase, stick_phase
from ..parameters import Parameters
from .comparisons import Computed
from .paper import PULLING_VELOCITIES, TABLE1_COLUMNS, TABLE1_ROWS, TEXT_NUMBERS

#: Simulated time at each pulling velocity (µm/s -> s): the cycles of Table 1 (3 at 50, 4 at 100 µm/s) and,
#: at 350 µm/s, the first stick and the slip that settles into steady sliding (Fig 5c).
DURATIONS = {50: 75.0, 100: 65.0, 350: 45.0}

#: The paper's sigma_s for which it reads V_s off the steady curve (Table 1 and the text rows).
_TABLE1_SLIP_STRESSES = {
    column: float(value)
    for column, value in zip(TABLE1_COLUMNS, next(r[4] for r in TABLE1_ROWS if r[0] == "slip_stress"), strict=True)
    if value is not None
}
_TEXT_SLIP_STRESSES = {
    "jump_velocity_50": next(n.paper for n in TEXT_NUMBERS if n.key == "slip_stress_50"),
    "jump_velocity_100": next(n.paper for n in TEXT_NUMBERS if n.key == "slip_stress_100"),
}


@dataclass
class ModelRun:
    """Results shared by the comparison table and the figures (SI units)."""

    params: Parameters
    critical: CriticalPoint | None = None
    steady_350: float | None = None
    sticks: dict[int, StickPhase] = field(default_factory=dict)  # by pulling velocity in um/s, from sigma_c
    jumps: dict[float, Jump] = field(default_factory=dict)  # by stress: V_s on the aging curve (Eq 8)
    simulations: dict[int, Simulation] = field(default_factory=dict)  # by pulling velocity in um/s
    table1_first_slip_100: SlipPhase | None = None  # slip from Table 1's sigma_s = 658 Pa at 100 um/s (Fig 5d)
    trace_analyses: dict[int, TraceAnalysis] = field(default_factory=dict)  # Table 1 measured on the model's traces

    def summary(self) -> dict[str, Any]:
        """The computed results (SI units) for results.json."""
        c = self.critical
        return {
            "critical_point": c.as_dict() if c is not None else None,
            "steady_stress_350": self.steady_350,
            "stick_phases": {f"{v} um/s": s.as_dict() for v, s in self.sticks.items()},
            "jump_velocities": [j.as_dict() for j in self.jumps.values()],
            "simulations": {f"{v} um/s": s.summary() for v, s in self.simulations.items()},
            "table1_of_model_traces": {f"{v} um/s": a.summary for v, a in self.trace_analyses.items()},
        }


def _steady(run: ModelRun) -> None:
    run.critical = critical_point(run.params)
    run.steady_350 = float(steady_state(run.params, 350e-6).stress)


def _sticks(run: ModelRun) -> None:
    for velocity in PULLING_VELOCITIES:
        run.sticks[_um(velocity)] = stick_phase(run.params, velocity)


def _jumps(run: ModelRun) -> None:
    stresses = {s for s in _TABLE1_SLIP_STRESSES.values() if s is not None}
    stresses |= set(_TEXT_SLIP_STRESSES.values())
    stresses |= {s.peak_stress for s in run.sticks.values() if s.peak_stress is not None}
    for stress in sorted(stresses):
        run.jumps[stress] = jump_velocity(run.params, stress)
    first = run.jumps[_TABLE1_SLIP_STRESSES[(100e-6, 1)]]
    if first.velocity is None:
        raise ModelError(f"Table 1's first cycle at 100 um/s (Fig 5d): {first.message}")
    run.table1_first_slip_100 = slip_phase(run.params, 100e-6, first.velocity)


def _simulation(velocity: int) -> Callable[[ModelRun], None]:
    si = next(v for v in PULLING_VELOCITIES if _um(v) == velocity)

    def action(run: ModelRun) -> None:
        run.simulations[velocity] = simulate(run.params, si, DURATIONS[velocity])

    return action


def _analyses(run: ModelRun) -> None:
    for velocity, sim in run.simulations.items():
        # the trace repeats the time at each phase boundary (stress continuous there): keep one sample
        keep = np.append(np.diff(sim.time) > 0, True)
        run.trace_analyses[velocity] = analyze_trace(
            sim.time[keep], sim.stress[keep], sim.pulling_velocity, run.params, source=f"model trace at {velocity} um/s"
        )


Step = tuple[str, Callable[[ModelRun], None]]


def run_steps() -> list[Step]:
    """The named steps that fill a :class:`ModelRun`, in order."""
    return [
        ("Steady friction curve and critical point (Eqs 6-9)", _steady),
        ("Stick phases at 50, 100 and 350 µm/s (Eqs 11-16)", _sticks),
        ("Jump velocities and slip phases (Eqs 8, 10)", _jumps),
        *((f"Stick-slip cycles at {v} µm/s (Eqs 10-17)", _simulation(v)) for v in DURATIONS),
        ("Table 1 measured on the model's traces (trace analysis)", _analyses),
    ]


def _um(velocity: float) -> int:
    return round(velocity * 1e6)


def _jump(run: ModelRun, stress: float | None) -> float | None:
    return run.jumps[stress].velocity if stress is not None else None


def computed_values(run: ModelRun) -> dict[str, Computed]:
    """Paper key -> the value computed here (SI) and how."""
    p = run.params
    c = run.critical
    assert c is not None and run.steady_350 is not None
    vc = c.velocity if c.exists else None
    sc = c.stress if c.exists else None
    stick = run.sticks
    out: dict[str, Computed] = {
        "critical_velocity": Computed(vc, "minimum of the steady curve with aging, dσ/dV = 0 (Eq 9)"),
        "critical_stress": Computed(sc, "σ at Vc on the steady curve with aging (Eqs 8-9)"),
        "critical_stress_cycles": Computed(sc, "the model's σc: every stick begins at the minimum of the curve"),
        "steady_stress_350": Computed(run.steady_350, "steady curve with aging at V = 350 µm/s (Eqs 6-8)"),
        "site_density": Computed(p.bonds.site_density, "parameter set"),
        "bond_time": Computed(p.bonds.bond_time, "parameter set"),
        "stretch_sensitivity": Computed(p.bonds.stretch_sensitivity, "λM/kT from λ, M and T of the parameter set"),
        "max_extension": Computed(p.bonds.max_extension, "parameter set"),
        "breakage_weight": Computed(p.bonds.breakage_weight, "parameter set"),
        "aging_time": Computed(p.aging.aging_time, "parameter set"),
        "aging_velocity": Computed(p.aging.aging_velocity, "parameter set"),
        "shear_modulus": Computed(p.block.shear_modulus, "parameter set"),
        "height": Computed(p.block.height, "parameter set"),
        "stiffness_printed": Computed(p.block.stiffness, "Gd / h"),
        "stiffness": Computed(p.block.stiffness, "Gd / h"),
        "top_length": Computed(p.block.top_length, "parameter set"),
        "base_length": Computed(p.block.base_length, "parameter set"),
        "geometric_factor": Computed(p.block.geometric_factor, "ln(B/l)/(B/l − 1) with B and l of the parameter set"),
        "attached_chains": Computed(p.stick.attached_chains, "parameter set"),
        "break_rate": Computed(p.stick.break_rate, "parameter set"),
        "stick_aging_time": Computed(p.stick.aging_time, "parameter set"),
    }
    how_ts = "Eq 15 from σc until Nc = 0, with K = (Gd/h) ln(B/l)/(B/l − 1) (Eqs 12, 17)"
    for v0 in (50, 100):
        ts = stick[v0].stick_time
        for prefix in ("stick_time", "stick_time_measured", "stick_time_table"):
            out[f"{prefix}_{v0}"] = Computed(ts, how_ts)
        out[f"slip_stress_{v0}"] = Computed(stick[v0].peak_stress, "σs = σc + K V0 ts (Eq 16)")
    for key, stress in _TEXT_SLIP_STRESSES.items():
        out[key] = Computed(_jump(run, stress), f"steady curve with aging carries {stress:g} Pa (Eq 8, right branch)")
    for v0 in (50, 100, 350):
        slip = run.simulations[v0].slip_phases[0]
        how = "end of the first slip phase (Eq 10): " + (
            "dσ/dV = 0 at Vc, where the block sticks" if slip.ends == "stick" else "V settles at V0 (steady sliding)"
        )
        out[f"slip_asymptote_{v0}"] = Computed(slip.end_velocity, how)
    for key, _label, _unit, _display, values, _scale in TABLE1_ROWS:
        for (velocity, cycle), value in zip(TABLE1_COLUMNS, values, strict=True):
            if value is None:
                continue
            row_key = f"table1_{key}_{_um(velocity)}_{cycle}"
            out[row_key] = _table1_value(run, key, velocity, cycle, sc)
    return out


def _table1_value(run: ModelRun, key: str, velocity: float, cycle: int, sc: float | None) -> Computed:
    p = run.params
    stick = run.sticks[_um(velocity)]
    if key == "critical_stress":
        return Computed(sc, "the model's σc (Eq 9)")
    if key == "stick_slope":
        return Computed(p.block.effective_stiffness * velocity, "K V0 = (Gd/h) ln(B/l)/(B/l − 1) V0 (Eqs 12, 17)")
    if key == "stiffness":
        return Computed(p.block.stiffness, "Gd / h of the parameter set")
    if key == "slip_stress":
        return Computed(stick.peak_stress, "σs = σc + K V0 ts (Eqs 15-16), stick from σc")
    if key == "stick_time":
        return Computed(stick.stick_time, "Eq 15 from σc until Nc = 0")
    if key == "jump_velocity":
        stress = _TABLE1_SLIP_STRESSES[(velocity, cycle)]
        return Computed(_jump(run, stress), f"steady curve with aging carries this cycle's σs = {stress:g} Pa (Eq 8)")
    raise KeyError(key)
