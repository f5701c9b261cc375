"""Everything the report computes, once: the model's counterpart of each number the paper states.

:class:`ModelRun` holds the results; :func:`run_steps` lists the named steps
that fill it (so the caller can show progress); :func:`computed_values` maps
each :mod:`~stickslip.report.paper` key to the value computed here and a
short note on how.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..analysis import TraceAnalysis, analyze_trace
from ..errors import ModelError
from ..parameters import Parameters
from ..quasistatic.critical import CriticalPoint, critical_point
from ..quasistatic.cycle import Simulation, simulate
from ..quasistatic.jump import Jump, jump_velocity
from ..quasistatic.slip import SlipPhase, slip_phase
from ..quasistatic.steady import steady_state
from ..quasistatic.stick import StickPhase, StuckThreshold, stick_phase, stuck_threshold
from .comparisons import Computed
from .paper import (
    CRITICAL_STRESS_BAND,
    PULLING_VELOCITIES,
    SLIP_STRESSES,
    TABLE1_COLUMNS,
    TABLE1_FROM_REST,
    TABLE1_ROWS,
    TABLE1_SET_APART,
    table1_value,
)

#: Simulated time at each pulling velocity (µm/s -> s): the cycles of Table 1 (3 at 50, 4 at 100 µm/s) and,
#: at 350 µm/s, the start-up stick from rest and the slip that settles into steady sliding (Fig 5c).
DURATIONS = {50: 75.0, 100: 65.0, 350: 45.0}
#: Pulling velocities (µm/s) whose run starts from rest, as the experiment did (Table 1 gives no sigma_c there).
FROM_REST = {350}

#: The paper's sigma_s for which it reads V_s off the steady curve (Table 1 and the text rows).
_TABLE1_SLIP_STRESSES = {
    column: float(value)
    for column, value in zip(TABLE1_COLUMNS, next(r[4] for r in TABLE1_ROWS if r[0] == "slip_stress"), strict=True)
    if value is not None
}
_TEXT_SLIP_STRESSES = {f"jump_velocity_{v0}": stress for v0, stress, _ in SLIP_STRESSES}

Column = tuple[int, int]  # (V0 in um/s, cycle)


@dataclass(frozen=True)
class ColumnStick:
    """The stick of one Table 1 column, at the stiffness its slope implies and at the nominal one."""

    velocity: float  # m/s
    start_stress: float  # Pa: the model's sigma_c, or 0 for a stick from rest
    stiffness: float  # Pa/m, effective (with the Eq 17 factor): the column's slope / V0
    measured: StickPhase  # with ``stiffness``
    nominal: StickPhase  # with the parameter set's K = 0.766 Gd/h


@dataclass
class ModelRun:
    """Results shared by the comparison table and the figures (SI units)."""

    params: Parameters
    critical: CriticalPoint | None = None
    steady_350: float | None = None
    sticks: dict[int, StickPhase] = field(default_factory=dict)  # by V0 in um/s: the first stick of each run
    columns: dict[Column, ColumnStick] = field(default_factory=dict)  # Table 1 column by column
    mean_sticks: dict[int, StickPhase] = field(default_factory=dict)  # at the mean measured stiffness of a V0
    thresholds: dict[str, StuckThreshold] = field(default_factory=dict)  # V* of Eq 15 from sigma_c and from rest
    jump_floor: float | None = None  # lowest V0 whose sigma_s (from sigma_c) the steady curve still carries
    jumps: dict[float, Jump] = field(default_factory=dict)  # by stress: V_s on the aging curve (Eq 8)
    simulations: dict[int, Simulation] = field(default_factory=dict)  # by pulling velocity in um/s
    table1_first_slip_100: SlipPhase | None = None  # slip from Table 1's sigma_s = 658 Pa at 100 um/s (Fig 5d)
    # inputs the paper does not state that give its numbers where its stated inputs do not (paper key -> words)
    reproduced_by: dict[str, str] = field(default_factory=dict)
    trace_analyses: dict[int, TraceAnalysis] = field(default_factory=dict)  # Table 1 measured on the model's traces

    def summary(self) -> dict[str, Any]:
        """The computed results (SI units) for results.json."""
        c = self.critical
        return {
            "critical_point": c.as_dict() if c is not None else None,
            "steady_stress_350": self.steady_350,
            "stick_phases": {f"{v} um/s": s.as_dict() for v, s in self.sticks.items()},
            "table1_sticks": {
                f"{v} um/s cycle {k}": {
                    "start_stress": col.start_stress,
                    "measured_stiffness": col.stiffness,
                    "measured": col.measured.as_dict(),
                    "nominal_stiffness": self.params.block.effective_stiffness,
                    "nominal": col.nominal.as_dict(),
                }
                for (v, k), col in self.columns.items()
            },
            "stuck_threshold": {name: t.as_dict() for name, t in self.thresholds.items()},
            "lowest_velocity_with_a_jump": self.jump_floor,
            "jump_velocities": [j.as_dict() for j in self.jumps.values()],
            "simulations": {f"{v} um/s": s.summary() for v, s in self.simulations.items()},
            "table1_of_model_traces": {f"{v} um/s": a.summary for v, a in self.trace_analyses.items()},
        }


def measured_stiffness(velocity: float, cycles: list[int] | None = None) -> float:
    """Effective stiffness K (Pa/m, Eq 17 factor included) from Table 1's stick slopes: slope / V0, averaged
    over ``cycles`` (default: the cycles at ``velocity`` the paper does not set apart)."""
    if cycles is None:
        cycles = [c for v, c in TABLE1_COLUMNS if v == velocity and (v, c) not in TABLE1_SET_APART]
    slopes = [table1_value("stick_slope", velocity, c) for c in cycles]
    return sum(s for s in slopes if s is not None) / len(slopes) / velocity


def with_stiffness(params: Parameters, stiffness: float) -> Parameters:
    """``params`` with the effective stiffness K (Pa/m) set through Gd (h and the trapezoid kept)."""
    block = params.block
    return params.with_overrides({"block.shear_modulus": stiffness / block.geometric_factor * block.height})


def _steady(run: ModelRun) -> None:
    run.critical = critical_point(run.params)
    run.steady_350 = float(steady_state(run.params, 350e-6).stress)


def _sticks(run: ModelRun) -> None:
    solved: dict[tuple[Parameters, float, float | None], StickPhase] = {}

    def phase(params: Parameters, velocity: float, start: float | None = None) -> StickPhase:
        # the columns of one velocity share the nominal-stiffness phase: solve each distinct one once
        key = (params, velocity, start)
        if key not in solved:
            solved[key] = stick_phase(params, velocity, start)
        return solved[key]

    for velocity in PULLING_VELOCITIES:
        start = 0.0 if _um(velocity) in FROM_REST else None
        run.sticks[_um(velocity)] = phase(run.params, velocity, start)
    assert run.critical is not None and run.critical.stress is not None
    for velocity, cycle in TABLE1_COLUMNS:
        start = 0.0 if (velocity, cycle) in TABLE1_FROM_REST else float(run.critical.stress)
        stiffness = measured_stiffness(velocity, [cycle])
        run.columns[(_um(velocity), cycle)] = ColumnStick(
            velocity,
            start,
            stiffness,
            phase(with_stiffness(run.params, stiffness), velocity, start),
            phase(run.params, velocity, start),
        )
    for velocity in (50e-6, 100e-6):
        run.mean_sticks[_um(velocity)] = phase(with_stiffness(run.params, measured_stiffness(velocity)), velocity)
    run.thresholds["from sigma_c"] = stuck_threshold(run.params)
    run.thresholds["from rest"] = stuck_threshold(run.params, start_stress=0.0)
    run.jump_floor = _jump_floor(run)
    run.reproduced_by.update(_reproducing_inputs(run))


def _solve(f: Callable[[float], float], low: float, high: float) -> float | None:
    """The root of ``f`` in [low, high], or None when the interval does not bracket one (then nothing is said)."""
    from scipy.optimize import brentq

    try:
        fl, fh = f(low), f(high)
    except (ModelError, TypeError):
        return None
    if not (math.isfinite(fl) and math.isfinite(fh)) or fl * fh > 0.0:
        return None
    return float(brentq(f, low, high, xtol=1e-12 * high))


def _reproducing_inputs(run: ModelRun) -> dict[str, str]:
    """For the paper's numbers that its stated inputs do not give (stickslip.report.paper.PAPER_UNSTATED), an input
    it does not state that does, found by solving the model for it: the stiffness, or the chain stiffness M at the
    paper's lambda M/kT (which sets the lambda/kT of Eq 15 and sigma_c), of the simulated stick times 18.3 s and
    9.3 s (E18), and the chain breakage rate of the first cycle at 100 um/s, whose contact aged before shearing
    began (E22)."""
    p, out = run.params, {}
    height = p.block.height

    def stick(gd_h: float, velocity: float) -> StickPhase:
        return stick_phase(p.with_overrides({"block.shear_modulus": gd_h * height}), velocity)

    def time_of(gd_h: float, velocity: float) -> float:
        ts = stick(gd_h, velocity).stick_time
        return math.nan if ts is None else ts

    found = {}
    for v0, printed in ((50, 18.3), (100, 9.3)):
        found[v0] = _solve(lambda g, v=v0 * 1e-6, ts=printed: time_of(g, v) - ts, 300e3, 600e3)
    # the chain stiffness M at the paper's lambda M/kT: lambda/kT = (lambda M/kT)/M in Eq 15, and every steady
    # stress, sigma_c among them, is proportional to M (E1)
    boltzmann_t = 1.380649e-23 * p.bonds.temperature
    lambda_m = p.bonds.stretch_sensitivity * boltzmann_t
    m0, sigma_c = p.bonds.chain_stiffness, run.critical.stress if run.critical is not None else None

    def time_at_m(m: float, velocity: float) -> float:
        if sigma_c is None:
            return math.nan
        q = p.with_overrides({"bonds.chain_stiffness": m, "bonds.activation_length": lambda_m / m})
        ts = stick_phase(q, velocity, sigma_c * m / m0).stick_time
        return math.nan if ts is None else ts

    m50 = _solve(lambda m: time_at_m(m, 50e-6) - 18.3, 0.8 * m0, 1.0 * m0)
    if found[50] is not None and found[100] is not None and m50 is not None:
        other, other_m = time_of(found[50], 100e-6), time_at_m(m50, 100e-6)
        sigma_m = sigma_c * m50 / m0
        low, high = CRITICAL_STRESS_BAND
        band = "" if low <= sigma_m <= high else ", outside the paper's σc = 259 ± 5 Pa"
        m_words = (
            f"at the nominal stiffness, M = {m50 * 1e6:.2f} µN/m at the paper's λM/kT (λ/kT ="
            f" {lambda_m / m50 / boltzmann_t:.4g} 1/N, σc = {sigma_m:.1f} Pa{band}; the paper states no M, and the"
            f" package's {m0 * 1e6:.0f} µN/m is its own choice, E1) gives 18.30 s and {other_m:.2f} s as well"
        )
        out["stick_time_50"] = (
            f"Gd/h = {found[50] / 1e3:.1f} kPa/m, which the paper does not state, gives 18.30 s (and {other:.2f} s at"
            f" 100 µm/s: one stiffness gives both printed values); {m_words}"
        )
        out["stick_time_100"] = (
            f"Gd/h = {found[100] / 1e3:.1f} kPa/m, which the paper does not state, gives 9.30 s; the"
            f" {found[50] / 1e3:.1f} kPa/m that gives 18.3 s at 50 µm/s gives {other:.2f} s; {m_words}"
        )
    # 100 um/s cycle 1: from sigma_s - slope t_s (Eq 12) at the column's own stiffness, the breakage rate of chains
    # that aged before shearing gives sigma_s and t_s together
    slope = table1_value("stick_slope", 100e-6, 1)
    sigma_s, t_s = table1_value("slip_stress", 100e-6, 1), table1_value("stick_time", 100e-6, 1)
    assert slope is not None and sigma_s is not None and t_s is not None
    start = sigma_s - slope * t_s
    column = with_stiffness(p, slope / 100e-6)

    def peak(rate: float) -> float:
        s = stick_phase(column.with_overrides({"stick.break_rate": rate}), 100e-6, start)
        return math.nan if s.peak_stress is None else s.peak_stress

    rate = _solve(lambda r: peak(r) - sigma_s, 1e-3 * p.stick.break_rate, p.stick.break_rate)
    if rate is not None:
        s = stick_phase(column.with_overrides({"stick.break_rate": rate}), 100e-6, start)
        words = (
            f"uc/τ = {rate:.3g} 1/s (stated: {p.stick.break_rate:.3g} 1/s; chains aged longer break more slowly),"
            f" which the paper does not state, gives σs = {s.peak_stress:.1f} Pa from σ0 = σs − slope × ts ="
            f" {start:.0f} Pa at the column's stiffness. One input fitted to one number, not a test: σ0 is taken from"
            f" this σs and ts, and the stick rises linearly (Eq 12), so σs = {sigma_s:.0f} Pa gives ts ="
            f" (σs − σ0)/slope = {s.stick_time:.2f} s by construction"
        )
        out["table1_slip_stress_100_1"] = out["table1_stick_time_100_1"] = words
    return out


def _jump_floor(run: ModelRun) -> float | None:
    """The V0 at which sigma_s (from sigma_c) equals the steady curve's maximum: below it no jump velocity exists."""
    from scipy.optimize import brentq

    c, threshold = run.critical, run.thresholds["from sigma_c"]
    if c is None or c.turnover_stress is None or threshold.velocity is None:
        return None
    top = float(c.turnover_stress)

    def excess(velocity: float) -> float:
        peak = stick_phase(run.params, velocity).peak_stress
        return float("inf") if peak is None else peak - top

    low, high = threshold.upper, PULLING_VELOCITIES[0]
    if not (excess(low) > 0.0 > excess(high)):
        return None
    return float(brentq(excess, low, high, xtol=1e-11))


def _jumps(run: ModelRun) -> None:
    stresses = set(_TABLE1_SLIP_STRESSES.values()) | set(_TEXT_SLIP_STRESSES.values())
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
        start = 0.0 if velocity in FROM_REST else None
        run.simulations[velocity] = simulate(run.params, si, DURATIONS[velocity], start_stress=start)

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
        ("Stick phases of every Table 1 column and the stuck threshold (Eqs 11-16)", _sticks),
        ("Jump velocities and slip phases (Eqs 8, 10)", _jumps),
        *((f"Stick-slip cycles at {v} µm/s (Eqs 10-17)", _simulation(v)) for v in DURATIONS),
        ("Table 1 measured on the model's traces (trace analysis)", _analyses),
    ]


def _um(velocity: float) -> int:
    return round(velocity * 1e6)


def _jump(run: ModelRun, stress: float | None) -> float | None:
    return run.jumps[stress].velocity if stress is not None else None


NOMINAL = "nominal K"  # = 0.766 × 400 kPa/m


def _echo(value: float, how: str = "parameter set") -> Computed:
    return Computed(value, how, echo=True)


def computed_values(run: ModelRun) -> dict[str, Computed]:
    """Paper key -> the value computed here (SI) and how."""
    p = run.params
    c = run.critical
    assert c is not None and run.steady_350 is not None
    vc = c.velocity if c.exists else None
    sc = c.stress if c.exists else None
    out: dict[str, Computed] = {
        "critical_velocity": Computed(vc, "minimum of the steady curve with aging, dσ/dV = 0 (Eq 9)"),
        "critical_stress": Computed(sc, "σ at Vc on the steady curve with aging (Eqs 8-9)"),
        "critical_stress_cycles": Computed(
            sc,
            "the model's σc: every slip below Vc ends at the minimum of the curve (Eq 10) and the stick after it"
            " begins there; the start-up sticks begin from rest",
        ),
        "steady_stress_350": Computed(run.steady_350, "steady curve with aging at V = 350 µm/s (Eqs 6-8)"),
        "site_density": _echo(p.bonds.site_density),
        "bond_time": _echo(p.bonds.bond_time),
        "stretch_sensitivity": _echo(p.bonds.stretch_sensitivity, "λM/kT from λ, M and T of the parameter set"),
        "max_extension": _echo(p.bonds.max_extension),
        "breakage_weight": _echo(p.bonds.breakage_weight),
        "aging_time": _echo(p.aging.aging_time),
        "aging_velocity": _echo(p.aging.aging_velocity),
        "shear_modulus": _echo(p.block.shear_modulus),
        "height": _echo(p.block.height),
        "stiffness_printed": _echo(p.block.stiffness, "Gd / h"),
        "stiffness": _echo(p.block.stiffness, "Gd / h"),
        "stiffness_against_table1": Computed(
            _mean_table1_stiffness(p), "mean over Table 1's eight columns of slope / (0.766 V0) (Eq 17 with V = 0)"
        ),
        "top_length": _echo(p.block.top_length),
        "base_length": _echo(p.block.base_length),
        "geometric_factor": _echo(p.block.geometric_factor, "ln(B/l)/(B/l − 1) with B and l of the parameter set"),
        "attached_chains": _echo(p.stick.attached_chains),
        "break_rate": _echo(p.stick.break_rate),
        "stick_aging_time": _echo(p.stick.aging_time),
    }
    for v0 in (50, 100):
        nominal, measured = run.sticks[v0], run.mean_sticks[v0]
        k = measured.stiffness / 1e3
        simulated = "Eq 15 from σc until Nc = 0 with the paper's parameters, K = 0.766 × 400 kPa/m (Eqs 12, 17)"
        out[f"stick_time_{v0}"] = Computed(
            nominal.stick_time, simulated, reproduced_by=run.reproduced_by.get(f"stick_time_{v0}", "")
        )
        with_k = f"with K = {k:.1f} kPa/m, the mean of Table 1's slopes at {v0} µm/s"
        how = f"Eq 15 from σc {with_k}"
        for prefix in ("stick_time_measured", "stick_time_table"):
            out[f"{prefix}_{v0}"] = Computed(measured.stick_time, how, alternative=nominal.stick_time,
                                             alternative_label=NOMINAL)  # fmt: skip
        out[f"slip_stress_{v0}"] = Computed(
            measured.peak_stress, f"σs = σc + K V0 ts (Eq 16) {with_k}", alternative=nominal.peak_stress,
            alternative_label=NOMINAL,
        )  # fmt: skip
    for key, stress in _TEXT_SLIP_STRESSES.items():
        out[key] = Computed(_jump(run, stress), f"steady curve with aging carries {stress:g} Pa (Eq 8, right branch)")
    for v0 in (50, 100, 350):
        slip = run.simulations[v0].slip_phases[0]
        if slip.ends == "stick":
            how = "end of the first slip phase (Eq 10): dσ/dV = 0 at Vc, where the block sticks"
            out[f"slip_asymptote_{v0}"] = Computed(slip.end_velocity, how)
        else:
            # steady sliding above Vc: Eq 5 with dσ/dt = 0 is V = V0, the pulling velocity handed back; what the
            # row checks is that the slip ends in steady sliding, not a number
            how = "end of the first slip phase (Eq 10): V settles at V0, the pulling velocity (steady sliding, Eq 5)"
            out[f"slip_asymptote_{v0}"] = Computed(slip.end_velocity, how, echo=True)
    for key, _label, _unit, _display, values, _scale in TABLE1_ROWS:
        for (velocity, cycle), value in zip(TABLE1_COLUMNS, values, strict=True):
            if value is None:
                continue
            row_key = f"table1_{key}_{_um(velocity)}_{cycle}"
            out[row_key] = _table1_value(run, key, velocity, cycle, sc)
    return out


def _mean_table1_stiffness(params: Parameters) -> float:
    ks = [measured_stiffness(v, [c]) / params.block.geometric_factor for v, c in TABLE1_COLUMNS]
    return sum(ks) / len(ks)


def _table1_value(run: ModelRun, key: str, velocity: float, cycle: int, sc: float | None) -> Computed:
    p = run.params
    column = run.columns[(_um(velocity), cycle)]
    k = column.stiffness / 1e3
    own = f"K = slope/V0 = {k:.1f} kPa/m (Gd/h {k / p.block.geometric_factor:.1f})"
    start = "from rest" if column.start_stress == 0.0 else "from σc"
    if key == "critical_stress":
        slip = run.table1_first_slip_100
        if column.start_stress == 0.0 and slip is not None and _um(velocity) == 100:
            # a stick from rest (sigma_s - slope t_s = 21 Pa) cannot have begun at 261 Pa: the cell is where the
            # cycle's slip ended (Eq 10 stops at Vc, where the stress is sigma_c), as in every other cycle
            return Computed(
                slip.end_stress, "the model's σc (Eq 9), where this cycle's slip from its σs = 658 Pa ends (Eq 10);"
                " its stick began from rest (σs − slope × ts = 21 Pa), not at σc",
            )  # fmt: skip
        return Computed(sc, "the model's σc (Eq 9), where the previous slip ended and this stick began")
    if key == "stick_slope":
        return Computed(
            column.stiffness * velocity, f"the column's own slope: {own} is taken from it",
            echo=True, alternative=p.block.effective_stiffness * velocity, alternative_label=NOMINAL,
        )  # fmt: skip
    if key == "stiffness":
        return Computed(
            column.stiffness / p.block.geometric_factor, "slope / (0.766 V0): the paper's arithmetic redone (Eq 17)",
            echo=True, alternative=p.block.stiffness, alternative_label="nominal Gd/h",
        )  # fmt: skip
    reproduced_by = run.reproduced_by.get(f"table1_{key}_{_um(velocity)}_{cycle}", "")
    if key == "slip_stress":
        return Computed(
            column.measured.peak_stress, f"σs = σ0 + K V0 ts (Eqs 15-16), {start}, {own}",
            alternative=column.nominal.peak_stress, alternative_label=NOMINAL, reproduced_by=reproduced_by,
        )  # fmt: skip
    if key == "stick_time":
        return Computed(
            column.measured.stick_time, f"Eq 15 {start} until Nc = 0, {own}",
            alternative=column.nominal.stick_time, alternative_label=NOMINAL, reproduced_by=reproduced_by,
        )  # fmt: skip
    if key == "jump_velocity":
        stress = _TABLE1_SLIP_STRESSES[(velocity, cycle)]
        return Computed(_jump(run, stress), f"steady curve with aging carries this cycle's σs = {stress:g} Pa (Eq 8)")
    raise KeyError(key)
