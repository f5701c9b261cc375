"""Whole stick-slip cycles: stick (Eqs 11-17) -> jump (Eqs 8, 16) -> slip (Eq 10) -> jump back -> ...

Every stick after the first starts at sigma_c with Nc = Nc0, so every cycle after the first is the same cycle:
each distinct phase is solved once and repeated with a time and displacement offset (the model's physics, not an
approximation).  The trace keeps puller = slider + shear at all times, across a no-aging jump too
(``jump_curve="no-aging"``).  The cycle and its bookkeeping: docs/slip-phase.md.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import regimes
from ..columns import attribute_frame
from ..errors import ModelError, ParameterError
from ..parameters import Parameters
from ..reprs import compact_repr, field_values
from ..trace_columns import QUASI_STATIC
from .critical import NOISE, CriticalPoint, critical_point
from .jump import Jump, branch_maximum, check_curve, jump_velocity
from .steady import ACCURATE_QUADRATURE, require_parameters, steady_state

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    from matplotlib.axes import Axes

    # the phases are imported where they are solved: Cycle alone (what a transient run's result needs) loads neither
    from .slip import SlipPhase
    from .stick import StickPhase

#: Trace columns, in order (SI units: s, Pa, m/s, m, m, m, Nc/Nc0, phase name).
CYCLE_COLUMNS = QUASI_STATIC
#: Long runs are thinned so that the trace stays below about this many rows (phase ends are always kept).
MAX_ROWS = 1_000_000
#: Runs of more cycles than this are refused (the trace would be mostly thinning).
MAX_CYCLES = 100_000
#: A stick whose σs is within this fraction of σc has not left the steady curve's minimum: the model resolves the
#: curve's stress to this (critical.NOISE, its stated accuracy with margin, below which a dip of the curve is no
#: minimum), so the jump lands at Vc and the cycle is degenerate (docs/slip-phase.md §6).
DEGENERATE_RTOL = NOISE
#: A cycle (stick + slip) shorter than this many times the sliding bonds' memory at Vc, Δl_m/Vc (the oldest age of
#: the steady population, Eqs 6-8: 8.65 ms for gelatin-glass, 39 bond times τ), is outside the quasi-static model,
#: whose slip takes the bonds to follow the steady curve (docs/slip-phase.md §6: the time-dependent model has no such
#: cycle at 0.3-5 Δl_m/Vc, and the shortest cycle of the report's grids lasts 15 Δl_m/Vc).
SHORTEST_CYCLE = 1.0


@dataclass(frozen=True)
class Cycle:
    """One stick phase that ended in a slip, and the slip that followed."""

    index: int
    start_time: float
    start_stress: float  # sigma where the stick began (sigma_c after the first; else a start-up cycle)
    peak_stress: float  # sigma_s (Eq 16)
    stick_time: float  # t_s
    jump_velocity: float  # Vs
    slip_time: float | None = None  # None until the next stick began
    period: float | None = None

    def as_dict(self) -> dict[str, Any]:
        return field_values(self, "start_time start_stress peak_stress stick_time jump_velocity slip_time period")


@dataclass(frozen=True)
class Simulation:
    """A simulated trace (SI units) and its cycles; see :func:`simulate`."""

    __repr__ = compact_repr  # counts, not hundreds of array elements

    time: np.ndarray
    stress: np.ndarray
    velocity: np.ndarray
    slider_displacement: np.ndarray
    puller_displacement: np.ndarray
    block_shear: np.ndarray
    chain_fraction: np.ndarray
    phase: np.ndarray
    regime: regimes.Regime  # compares equal to its kind's name ("stick-slip"), as the str it once was
    cycles: tuple[Cycle, ...]
    final_stress: float  # at the end of the trace: ``duration``, or where the model stops ("undetermined")
    final_velocity: float
    message: str
    pulling_velocity: float
    duration: float
    start_stress: float
    jump_curve: str
    critical_velocity: float
    critical_stress: float
    stiffness: float
    stick_phases: tuple[StickPhase, ...] = field(default=(), repr=False)
    slip_phases: tuple[SlipPhase, ...] = field(default=(), repr=False)
    jumps: tuple[Jump, ...] = field(default=(), repr=False)
    parameters: Parameters | None = field(default=None, repr=False, compare=False)
    #: "ok", or "failed" when the model stopped before ``duration`` without an answer (``message`` says where)
    status: str = "ok"

    def summary(self) -> dict[str, Any]:
        """The JSON summary, SI units."""
        return {
            "regime": self.regime.kind,
            "status": self.status,
            "message": self.message,
            "final_stress": self.final_stress,
            "final_velocity": self.final_velocity,
            "end_time": float(self.time[-1]),
            "pulling_velocity": self.pulling_velocity,
            "duration": self.duration,
            "start_stress": self.start_stress,
            "jump_curve": self.jump_curve,
            "critical_velocity": self.critical_velocity,
            "critical_stress": self.critical_stress,
            "effective_stiffness": self.stiffness,
            "cycles": [c.as_dict() for c in self.cycles],
        }

    def to_frame(self) -> pd.DataFrame:
        """The trace, one row per sample, columns :data:`CYCLE_COLUMNS` (SI units)."""
        return attribute_frame(self, " ".join(CYCLE_COLUMNS))

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        """sigma(t) over the cycles (Fig 5a-c); returns the Axes."""
        from ..plots.cycles import plot_simulation

        return plot_simulation(self, ax=ax, **kwargs)


@dataclass(frozen=True)
class SteadySliding(Simulation):
    """A run on a steady curve without a minimum: no Vc, so no stick and no cycle, only steady sliding at V0 where
    the curve rises there, else a failed run (status "failed", the start alone; ``critical_velocity`` and
    ``critical_stress`` are NaN).  Its own type, so that what describes a
    cycle's start and critical point (the command line's record) is not printed; the figure draws no σc."""


@dataclass
class _Trace:
    """Rows of the trace, appended phase by phase; each phase thinned by ``stride`` (its ends always kept)."""

    sigma0: float
    stiffness: float
    v0: float
    end: float
    stride: int = 1
    parts: list[tuple[np.ndarray, ...]] = field(default_factory=list)
    names: list[str] = field(default_factory=list)

    def add(
        self, t: np.ndarray, stress: np.ndarray, velocity: np.ndarray, slider: np.ndarray, n: np.ndarray, phase: str
    ) -> None:
        if self.stride > 1 and t.size > 2:
            keep = np.unique(np.r_[np.arange(0, t.size, self.stride), t.size - 1])
            t, stress, velocity, slider, n = t[keep], stress[keep], velocity[keep], slider[keep], n[keep]
        self.parts.append((t, stress, velocity, slider, n))
        self.names.append(phase)

    def build(self) -> dict[str, np.ndarray]:
        t, stress, velocity, slider, n = (np.concatenate(column) for column in zip(*self.parts, strict=True))
        phase = np.repeat(np.array(self.names), [part[0].size for part in self.parts])
        return {
            "time": t,
            "stress": stress,
            "velocity": velocity,
            "slider_displacement": slider,
            "puller_displacement": self.sigma0 / self.stiffness + self.v0 * t,
            "block_shear": stress / self.stiffness,
            "chain_fraction": n,
            "phase": phase,
        }


def _add_stick(trace: _Trace, stick: StickPhase, t0: float, slider: float) -> None:
    t = stick.time
    if t0 + t[-1] > trace.end:  # cut at the end of the run, with the exact state there
        cut = trace.end - t0
        inside = t < cut
        t = np.r_[t[inside], cut]
        n = np.r_[stick.chain_fraction[inside], stick.chain_fraction_at(cut)]
    else:
        n = stick.chain_fraction
    trace.add(t0 + t, stick.stress_at(t), np.zeros(t.size), np.full(t.size, slider), n, "stick")


def _add_slip(trace: _Trace, slip: SlipPhase, t0: float, slider: float) -> None:
    t, v, s, x = slip.time, slip.velocity, slip.stress, slip.slider_displacement
    if t0 + slip.duration > trace.end:
        cut = trace.end - t0
        inside = t < cut
        v_cut, s_cut, x_cut = slip.at(cut)
        t, v, s, x = np.r_[t[inside], cut], np.r_[v[inside], v_cut], np.r_[s[inside], s_cut], np.r_[x[inside], x_cut]
    trace.add(t0 + t, s, v, slider + x, np.zeros(t.size), "slip")


def _add_steady(trace: _Trace, t0: float, stress: float, slider: float) -> None:
    t = np.linspace(t0, trace.end, 50) if trace.end > t0 else np.array([t0])
    trace.add(
        t, np.full(t.size, stress), np.full(t.size, trace.v0), slider + trace.v0 * (t - t0), np.zeros(t.size), "steady"
    )


@dataclass(frozen=True)
class _Cycle:
    """A stick from a given stress and what follows it; ``problem`` says why the chain of phases stops."""

    stick: StickPhase
    jump: Jump | None
    slip: SlipPhase | None
    problem: str | None  # None, or the regime ("stuck"/"undetermined") with ``message``
    message: str = ""


@dataclass
class _Phases:
    """Each distinct phase solved once (keyed by the stress the stick starts at)."""

    params: Parameters
    v0: float
    curve: str
    horizon: float
    cycles: dict[float, _Cycle] = field(default_factory=dict)

    def cycle(self, sigma: float) -> _Cycle:
        if sigma not in self.cycles:
            self.cycles[sigma] = self._solve(sigma)
        return self.cycles[sigma]

    def _solve(self, sigma: float) -> _Cycle:
        from .slip import slip_phase
        from .stick import stick_phase

        stick = stick_phase(self.params, self.v0, sigma, horizon=self.horizon)
        if stick.status != "slipped":
            return _Cycle(stick, None, None, regimes.STUCK if stick.stuck else regimes.UNDETERMINED, stick.message)
        assert stick.peak_stress is not None and stick.stick_time is not None
        if stick.stick_time <= 0.0:  # issue 12: was reported as a cycle
            message = (
                f"the attached chains collapse the moment the block sticks at {sigma:.6g} Pa (stick time 0): there"
                " is no stick phase, so no stick-slip cycle; the quasi-static model has no answer here"
            )
            return _Cycle(stick, None, None, regimes.UNDETERMINED, message)
        degenerate = self._degenerate(stick)
        if degenerate is not None:
            return self._too_short(degenerate) or degenerate
        jump = jump_velocity(self.params, stick.peak_stress, self.curve)
        if not jump.reachable or jump.velocity is None:
            message = f"the chains collapse at σs = {stick.peak_stress:.6g} Pa, but {jump.message}"
            return _Cycle(stick, jump, None, regimes.UNDETERMINED, message)
        v_max, _ = branch_maximum(self.params, "aging")
        if self.v0 >= v_max:  # the slip after the jump has nothing to relax to (slip_phase refuses it)
            message = (
                f"the chains collapse at σs = {stick.peak_stress:.6g} Pa and the block jumps to"
                f" {jump.velocity * 1e6:.6g} µm/s, but the pulling velocity {self.v0 * 1e6:.6g} µm/s is at or above"
                f" the maximum of the steady curve ({v_max * 1e6:.6g} µm/s): sliding there is velocity-weakening"
                " again and the slip (Eq 10) has no quasi-static solution"
            )
            return _Cycle(stick, jump, None, regimes.UNDETERMINED, message)
        slip = slip_phase(self.params, self.v0, jump.velocity)
        short = self._too_short(_Cycle(stick, jump, slip, None))
        if short is not None:
            return short
        if slip.ends == "stick" and slip.duration == 0.0:  # the no-aging curve's jump landing at Vc
            message = (
                f"degenerate cycle: the chains collapse after {stick.stick_time:.6g} s at σs ="
                f" {stick.peak_stress:.6g} Pa, so the jump lands at Vc where the slip ends at"
                " once and the block sticks again without moving (creep by infinitesimal slips, outside the model)"
            )
            return _Cycle(stick, jump, slip, regimes.UNDETERMINED, message)
        return _Cycle(stick, jump, slip, None)

    def _too_short(self, cycle: _Cycle) -> _Cycle | None:
        """The cycle, stopped at its collapse, when its stick and the slip back to Vc together last less than
        :data:`SHORTEST_CYCLE` times the sliding bonds' memory at Vc, Δl_m/Vc (None otherwise, and for a slip
        that settles at V0, which has no period).

        The quasi-static slip (Eq 10) takes the bonds to be the steady population of the velocity at each
        instant; that population is renewed within Δl_m/V (Eqs 6-8 end there), so a whole cycle shorter than
        Δl_m/Vc leaves it no time to form.  The rule is on time, not stress: N0 = 1e15 m^-2 at 50 µm/s gives the
        same 3.17 ns stick at every stiffness, σs - σc = K V0 ts = 2e-12 of σc at 4 kPa/m and 2.3e-9 at
        40 MPa/m, where the stress rule (:data:`DEGENERATE_RTOL`) left a 5.3 ns "cycle" refused as 1.1e10 cycles
        in 60 s (round 29, tester S)."""
        stick, slip = cycle.stick, cycle.slip
        if slip is None or slip.ends != "stick" or stick.stick_time is None or stick.peak_stress is None:
            return None
        cp = critical_point(self.params)
        assert cp.velocity is not None
        v_c, extension, bond_time = float(cp.velocity), self.params.bonds.max_extension, self.params.bonds.bond_time
        memory = extension / v_c
        period = stick.stick_time + slip.duration
        if period >= SHORTEST_CYCLE * memory:
            return None
        message = (
            f"degenerate cycle: the chains collapse after {stick.stick_time:.6g} s at σs = {stick.peak_stress:.6g}"
            f" Pa, and the whole cycle, that stick and the slip back to Vc ({slip.duration:.3g} s), lasts"
            f" {period:.3g} s: {period / memory:.2g} of the {memory:.3g} s the sliding bonds take to renew at Vc"
            f" (Δl_m/Vc = {extension * 1e6:.4g} µm / {v_c * 1e6:.6g} µm/s, the oldest age of the steady population;"
            f" bond time τ = {bond_time:.3g} s); the quasi-static model takes the bonds to be steady during the slip,"
            " which needs a cycle longer than that, so this one is outside the model (stickslip transient"
            " --stick-population integrates Eq 1 without that picture)"
        )
        return _Cycle(stick, cycle.jump, None, regimes.UNDETERMINED, message)

    def _degenerate(self, stick: StickPhase) -> _Cycle | None:
        """The cycle of a stick whose σs is σc to the steady curve's resolution (:data:`DEGENERATE_RTOL`), below Vc
        and jumping onto the aging curve: the jump lands at Vc, where the slip ends at once (None otherwise).

        The stress rule puts the jump at Vc where the root finder would find noise (at N0 = 1e15 m^-2 and
        50 µm/s it put the jump exactly at Vc at 40 kPa/m and 4e-6 above it at 400 kPa/m); a stick that short is
        also a cycle shorter than the bonds' memory (:meth:`_too_short`), whose words the run then gives.  Alone
        it decides where the stick is long, e.g. a puller standing still under chains that do not age."""
        from .slip import slip_phase

        cp = critical_point(self.params)
        assert cp.velocity is not None and cp.stress is not None and stick.peak_stress is not None
        sigma_c, v_c = float(cp.stress), float(cp.velocity)
        rise = stick.peak_stress - sigma_c
        if self.curve != "aging" or self.v0 >= v_c or abs(rise) > DEGENERATE_RTOL * sigma_c:
            return None  # at V0 >= Vc the slip from Vc to V0 is steady sliding, whatever σs
        _, s_max = branch_maximum(self.params, "aging")
        jump = Jump(
            stick.peak_stress,
            v_c,
            True,
            "aging",
            f"σs = {stick.peak_stress:.6g} Pa is σc to the steady curve's resolution: the jump lands at Vc ="
            f" {v_c:.6g} m/s",
            sigma_c,
            s_max,
        )
        slip = slip_phase(self.params, self.v0, v_c)  # from Vc to Vc: no slip
        message = (
            f"degenerate cycle: the chains collapse after {stick.stick_time:.6g} s at σs ="
            f" {stick.peak_stress:.6g} Pa, σs − σc = {rise:.3g} Pa ({abs(rise) / sigma_c:.2g} of σc, within the"
            f" {DEGENERATE_RTOL:g} of σc to which the model resolves the steady curve's stress), so the jump lands"
            " at Vc where the slip ends at once and the block sticks again without moving (creep by infinitesimal"
            " slips, outside the model)"
        )
        return _Cycle(stick, jump, slip, regimes.UNDETERMINED, message)

    def all(self, kind: str) -> tuple[Any, ...]:
        return tuple(getattr(c, kind) for c in self.cycles.values() if getattr(c, kind) is not None)


def simulate(
    params: Parameters,
    pulling_velocity: float,
    duration: float,
    start_stress: float | None = None,
    jump_curve: str = "aging",
) -> Simulation:
    """Simulate the block pulled at ``pulling_velocity`` (m/s, >= 0) for ``duration`` seconds.

    Each of ``pulling_velocity``, ``duration`` and ``start_stress`` is a number in SI or a value with its unit
    (``simulate(p, "50 um/s", "2 min")``).  Starts stuck at ``start_stress`` (Pa; default sigma_c) with fresh chains
    and chains stick -> jump -> slip -> jump -> ...  ``jump_curve`` is the
    steady curve on which the jump lands (``"aging"``, default, keeps the
    stress continuous; ``"no-aging"`` is the paper's Section 3 reading).

    ``regime`` (a :class:`stickslip.regimes.Regime`, the type of ``stickslip.run(...).regime``, equal to its
    kind's name) describes where the run is heading, whatever ``duration``:
    ``"stick-slip"`` (cycles repeat), ``"steady"`` (the slip settles at V0 >=
    Vc), ``"stuck"`` (a stick never ends) or ``"undetermined"`` (the model has
    no answer: the jump stress is off the branch, a stick can neither be
    shown to end nor to last for ever, or the cycle degenerates); ``message``
    says which and why.  Runs longer than MAX_CYCLES periods are refused.
    """
    from ..units import refused_as_written, si_argument
    from .stick import _number, check_stress, check_velocity

    require_parameters(params)
    with refused_as_written(pulling_velocity):
        v0 = check_velocity(si_argument(pulling_velocity, "velocity", "pulling_velocity"))
    with refused_as_written(duration):
        end = _number(si_argument(duration, "time", "duration"), "duration", "s")
        if end <= 0:
            raise ParameterError(f"duration: expected a positive time in s, got {end!r}")
    if start_stress is not None:
        with refused_as_written(start_stress):
            start_stress = check_stress(si_argument(start_stress, "stress", "start_stress"))
    check_curve(jump_curve)
    cp = critical_point(params)
    if not cp.exists:
        return _without_critical_point(params, cp, v0, end, start_stress, jump_curve)
    assert cp.velocity is not None and cp.stress is not None
    sigma_c = float(cp.stress)
    sigma0 = sigma_c if start_stress is None else check_stress(start_stress)
    stiffness = params.block.effective_stiffness
    phases = _Phases(params, v0, jump_curve, end)
    regime, message, period = _outlook(phases, sigma0, sigma_c)
    if regime == regimes.STUCK and v0 >= float(cp.velocity):
        # the stick chains' limitation above Vc says nothing of the slip: a block already sliding stays there
        message += (
            f"; V0 is above Vc = {float(cp.velocity) * 1e6:.6g} µm/s, where steady sliding is stable: a block"
            " already sliding at V0 stays there (stickslip transient --start steady)"
        )
    trace = _Trace(sigma0, stiffness, v0, end)
    if period is not None:
        repeat = phases.cycle(sigma_c)
        assert repeat.slip is not None
        count = end / period
        if count > MAX_CYCLES:
            raise ParameterError(
                f"duration: {end:.6g} s holds {count:.3g} cycles of {period:.6g} s; at most {MAX_CYCLES:g} are"
                f" traced, so give a shorter duration (at most {MAX_CYCLES * period:.3g} s)"
            )
        rows = count * (repeat.stick.time.size + repeat.slip.time.size)
        trace.stride = max(1, math.ceil(rows / MAX_ROWS))
    cycles: list[Cycle] = []
    t, slider, sigma = 0.0, 0.0, sigma0
    problem: tuple[float, _Cycle] | None = None  # the cycle the model has no answer for, and when its stick began
    while True:  # one stick (and the slip after it) per pass; t advances by a period > 0
        cycle = phases.cycle(sigma)
        stick, jump, slip = cycle.stick, cycle.jump, cycle.slip
        if cycle.problem is not None and problem is None:
            problem = (t, cycle)
        _add_stick(trace, stick, t, slider)
        if slip is None or jump is None or jump.velocity is None:
            break  # stuck, or no answer; _outlook has the words
        assert stick.stick_time is not None and stick.peak_stress is not None
        if t + stick.stick_time > end:
            break
        cycles.append(Cycle(len(cycles), t, sigma, stick.peak_stress, stick.stick_time, jump.velocity))
        t += stick.stick_time
        slider += (stick.peak_stress - slip.start_stress) / stiffness  # 0 unless the jump left the aging curve
        _add_slip(trace, slip, t, slider)
        if slip.ends == "steady":
            if t + slip.duration < end:
                _add_steady(trace, t + slip.duration, slip.end_stress, slider + slip.slider_displacement[-1])
            break
        if cycle.problem is not None or t + slip.duration > end:
            break
        slider += slip.slider_displacement[-1]
        t += slip.duration
        cycles[-1] = dataclasses.replace(cycles[-1], slip_time=slip.duration, period=stick.stick_time + slip.duration)
        sigma = sigma_c
    # the regime's periods: in stick-slip the whole cycles of the repeating one (below), else every whole cycle
    settled = [c for c in cycles if c.period is not None]
    if regime == regimes.STICK_SLIP:
        sigma_s = phases.cycle(sigma_c).stick.peak_stress
        assert sigma_s is not None
        settled = settled_cycles(cycles, sigma_c, sigma_s)
        whole = len(settled)
        message += f"; {whole} whole cycle(s) in {end:.6g} s" + _start_up_words(cycles, sigma0, sigma_c, sigma_s, end)
        if not whole:  # the numbers above are the cycle the run heads for, not one it has seen
            message += " (the period and σs are its cycle's once settled, from σc: the run ends before one)"
    elif regime == regimes.STUCK and cycles:
        message += f" (after {len(cycles)} slip(s))"
    columns = trace.build()
    if regime == regimes.STEADY and _settle_time(phases, sigma0, sigma_c) > end:
        # the regime is where the run is heading, which the phases prove (the slip's own relaxation settles at a
        # computed time; a 20 s run of a soft block at 3 mm/s ends 0.13 % short of V0, and 31 of the report's 135
        # phase-diagram points would read "undetermined"): say that the run ends before it gets there
        where = "stuck" if columns["phase"][-1] == "stick" else "slipping"
        message += (
            f"; the run ends at {end:.6g} s, still {where}, before it settles at t ="
            f" {_settle_time(phases, sigma0, sigma_c):.6g} s"
        )
    status = "ok"
    if regime == regimes.UNDETERMINED and columns["time"][-1] < end:
        # the model has no next phase: what was asked for beyond here is not computed, so the run failed
        status = "failed"
        message += (
            f"; the model stops at t = {columns['time'][-1]:.6g} s of the {end:.6g} s asked for:"
            " what follows is not known"
        )
    elif regime == regimes.UNDETERMINED:
        # the run computed all it asked for, and the phase the model has no answer for lies beyond it: say so
        message += _beyond_the_run(problem, sigma_c, end, columns)
    return Simulation(
        **columns,
        regime=_regime(regime, message, period, settled, columns),
        cycles=tuple(cycles),
        final_stress=float(columns["stress"][-1]),
        final_velocity=float(columns["velocity"][-1]),
        message=message,
        pulling_velocity=v0,
        duration=end,
        start_stress=sigma0,
        jump_curve=jump_curve,
        critical_velocity=float(cp.velocity),
        critical_stress=sigma_c,
        stiffness=stiffness,
        stick_phases=phases.all("stick"),
        slip_phases=phases.all("slip"),
        jumps=phases.all("jump"),
        parameters=params,
        status=status,
    )


def _without_critical_point(
    params: Parameters, cp: CriticalPoint, v0: float, end: float, start_stress: float | None, jump_curve: str
) -> Simulation:
    """The run where the aging curve has no minimum: steady sliding at V0 where the curve rises there (the
    physics' answer: there is no Vc, so no stick at σc to start from and no stick-slip); elsewhere no answer."""
    if v0 > 0.0:
        state = steady_state(params, v0, aging=True, quadrature=ACCURATE_QUADRATURE)
        sigma, rising = float(state.stress), float(state.stress_slope) > 0.0
    else:  # the puller stands still: nothing loads the block
        sigma, rising = 0.0, True
    if not rising:  # velocity-weakening at V0 with no minimum: neither steady sliding nor a cycle to follow
        # valid parameters on which the quasi-static picture has no answer: a failed run (exit 3), not bad input,
        # returned with status "failed" and the words as the model's other stops are (it raised RunFailed before
        # round 30), its trace the start alone (t = 0), where the model stops
        message = (
            f"no answer from the quasi-static model: {cp.message}; steady sliding at V0 would be unstable, and a"
            " stick has no branch to jump onto, so neither steady sliding nor a stick-slip cycle exists here (the"
            " time-dependent model, stickslip transient or --model transient, integrates Eq 1 without that picture);"
            f" the model stops at t = 0 s of the {end:.6g} s asked for: what follows is not known"
        )
        start = sigma if start_stress is None else float(start_stress)
        trace = _Trace(start, params.block.effective_stiffness, v0, end)
        at_rest = start_stress is not None  # a stick from the given stress; else steady sliding at V0, unstable
        trace.add(*(np.array([x]) for x in (0.0, start, 0.0 if at_rest else v0, 0.0, 1.0 if at_rest else 0.0)),
                  "stick" if at_rest else "steady")  # fmt: skip
        columns = trace.build()
        return _run_without_critical_point(params, columns, regimes.UNDETERMINED, message, v0, end, start, jump_curve)
    if start_stress is not None:
        # a stick from a given stress ends in a jump onto the curve's right branch, which starts at Vc
        raise ModelError(
            f"start stress: the steady curve has no Vc ({cp.message}), so a stick from {float(start_stress):.6g} Pa"
            " has no branch to jump onto; leave the start stress out for steady sliding at V0"
        )
    stiffness = params.block.effective_stiffness
    trace = _Trace(sigma, stiffness, v0, end)
    _add_steady(trace, 0.0, sigma, 0.0)
    columns = trace.build()
    if v0 > 0.0:
        kind = regimes.STEADY
        message = (
            f"steady sliding at V0 = {v0 * 1e6:.6g} µm/s from the start, σ = σ(V0) = {sigma:.6g} Pa: the steady"
            f" curve has no Vc, so no stick at σc to start from and no stick-slip ({cp.message})"
        )
    else:
        kind = regimes.STUCK
        message = f"the puller stands still and the block stays at rest, unloaded (σ = 0 Pa): {cp.message}"
    return _run_without_critical_point(params, columns, kind, message, v0, end, sigma, jump_curve)


def _run_without_critical_point(
    params: Parameters,
    columns: dict[str, np.ndarray],
    kind: str,
    message: str,
    v0: float,
    end: float,
    start: float,
    jump_curve: str,
) -> Simulation:
    """A run of :func:`_without_critical_point` (no Vc): steady or stuck from the start, or, with ``kind``
    undetermined, the failed run where the model has no answer (status "failed")."""
    failed = kind == regimes.UNDETERMINED
    sigma = float(columns["stress"][-1])
    return SteadySliding(
        **columns,
        regime=regimes.Regime(kind, 0, math.nan, math.nan, sigma, sigma, message),
        cycles=(),
        final_stress=sigma,
        final_velocity=float(columns["velocity"][-1]),
        message=message,
        pulling_velocity=v0,
        duration=end,
        start_stress=start,
        jump_curve=jump_curve,
        critical_velocity=math.nan,
        critical_stress=math.nan,
        stiffness=params.block.effective_stiffness,
        parameters=params,
        status="failed" if failed else "ok",
    )


def settled_cycles(cycles: list[Cycle] | tuple[Cycle, ...], sigma_c: float, sigma_s: float) -> list[Cycle]:
    """The whole cycles of the repeating one (σc -> σs): every whole cycle after the first, and the first when it
    starts at σc.  A first stick from another stress is a start-up cycle that does not repeat; one from within
    :data:`stickslip.regimes.RATIO_TOLERANCE` of the rise σs - σc of σc, to as near a σs, is the repeating cycle
    (the transient model's rule, docs/regimes.md: a typed σc is σc to its printed digits)."""
    return [c for c in cycles if c.period is not None and (c.index > 0 or _repeats(c, sigma_c, sigma_s))]


def _repeats(first: Cycle | None, sigma_c: float, sigma_s: float, start: float | None = None) -> bool:
    """Whether the first cycle (or, without one, a stick from ``start``) is the repeating cycle's."""
    near = regimes.RATIO_TOLERANCE * abs(sigma_s - sigma_c)
    if first is None:
        return start is not None and abs(start - sigma_c) <= near
    return abs(first.start_stress - sigma_c) <= near and abs(first.peak_stress - sigma_s) <= near


def _start_up_words(cycles: list[Cycle], sigma0: float, sigma_c: float, sigma_s: float, end: float) -> str:
    """What the first stick from a start stress other than σc did: it is no cycle of the repeating one."""
    first = cycles[0] if cycles else None
    if _repeats(first, sigma_c, sigma_s, sigma0):
        return ""
    if first is None:
        return f", the start-up stick from {sigma0:.6g} Pa still under way at {end:.6g} s"
    if first.period is None:
        return (
            f", the start-up cycle from {sigma0:.6g} Pa (σs = {first.peak_stress:.6g} Pa after"
            f" {first.stick_time:.6g} s) still slipping at {end:.6g} s"
        )
    return (
        f" after the start-up cycle from {sigma0:.6g} Pa (a transient that does not repeat: σs ="
        f" {first.peak_stress:.6g} Pa, period {first.period:.6g} s)"
    )


def _regime(
    kind: str, message: str, period: float | None, whole: list[Cycle], columns: dict[str, np.ndarray]
) -> regimes.Regime:
    """The run's regime with its evidence: every cycle from σc is the same cycle (amplitude ratio 1); ``whole``,
    the whole ones the run holds (:func:`settled_cycles`), are its periods, the peak and trough those of the last
    of them; without one (a start-up cycle from another stress is none), the run's extremes."""
    time, stress = columns["time"], columns["stress"]
    if period is not None and whole:
        last = whole[-1]
        assert last.period is not None
        inside = (time >= last.start_time) & (time <= last.start_time + last.period)
        peak, trough = float(np.max(stress[inside])), float(np.min(stress[inside]))
    else:
        peak, trough = float(np.max(stress)), float(np.min(stress))
    ratio = 1.0 if kind == regimes.STICK_SLIP and len(whole) >= 2 else math.nan
    return regimes.Regime(kind, len(whole), ratio, math.nan if period is None else period, peak, trough, message)


def _beyond_the_run(
    problem: tuple[float, _Cycle] | None, sigma_c: float, end: float, columns: dict[str, np.ndarray]
) -> str:
    """Words for an undetermined run that reached its end: the phase the model has no answer for comes after it,
    which is no failure of the run, so the run is ``ok`` and says when that phase comes (round 29: 8.02 µm/s at
    958 kPa/m for 300 s read "the chains collapse at σs = 2335.68 Pa ... no jump velocity", the collapse being at
    353.1 s, while neighbours that reach their collapse within the run are ``failed``)."""
    where = "stuck" if columns["phase"][-1] == "stick" else "slipping"
    final = f"the run ends {where}, at σ = {float(columns['stress'][-1]):.6g} Pa"
    if problem is None:  # the start-up cycle is still under way at the end: the stick from σc has not begun
        return (
            f"; the stick from σc = {sigma_c:.6g} Pa that this describes begins after the run's end at {end:.6g} s:"
            f" {final}"
        )
    began, cycle = problem
    ts = cycle.stick.stick_time
    if ts is None:  # a stick neither proven to end nor to last (its own message gives the times)
        return ""
    return (
        f"; that collapse comes at t = {began + ts:.6g} s, after the run's end at {end:.6g} s: {final}, and what"
        " follows the collapse is not known"
    )


def _settle_time(phases: _Phases, sigma0: float, sigma_c: float) -> float:
    """When a run heading for steady sliding reaches it (the slip's end, within its tolerance of V0): the first
    stick and slip, and the repeating cycle's stick and slip when the first slip ended in a stick."""
    first = phases.cycle(sigma0)
    assert first.slip is not None and first.stick.stick_time is not None
    t = first.stick.stick_time + first.slip.duration
    if first.slip.ends == "steady":
        return t
    repeat = phases.cycle(sigma_c)
    assert repeat.slip is not None and repeat.stick.stick_time is not None
    return t + repeat.stick.stick_time + repeat.slip.duration


def _outlook(phases: _Phases, sigma0: float, sigma_c: float) -> tuple[str, str, float | None]:
    """(regime, message, period of the repeating cycle or None): where the run is heading, whatever its length."""
    first = phases.cycle(sigma0)
    if first.problem is not None:
        return first.problem, first.message, None
    assert first.slip is not None
    if first.slip.ends == "steady":
        return regimes.STEADY, first.slip.message, None
    repeat = phases.cycle(sigma_c)
    if repeat.problem is not None:
        return repeat.problem, repeat.message, None
    assert repeat.slip is not None and repeat.jump is not None and repeat.jump.velocity is not None
    stick = repeat.stick
    assert stick.stick_time is not None and stick.peak_stress is not None
    if repeat.slip.ends == "steady":
        return regimes.STEADY, repeat.slip.message, None
    period = stick.stick_time + repeat.slip.duration
    return (
        regimes.STICK_SLIP,
        f"stick-slip with period {period:.6g} s (stick {stick.stick_time:.6g} s, slip {repeat.slip.duration:.6g} s):"
        f" σc = {sigma_c:.6g} Pa -> σs = {stick.peak_stress:.6g} Pa,"
        f" jump to Vs = {repeat.jump.velocity * 1e6:.6g} µm/s",
        period,
    )
