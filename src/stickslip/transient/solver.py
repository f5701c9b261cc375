"""run_transient: drive the cohort kernel through a loading protocol (docs/transient.md)."""

from __future__ import annotations

import bisect
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import lru_cache
from typing import Any

import numpy as np

from ..display import velocities_apart
from ..display import velocity as show_velocity
from ..errors import ModelError, ParameterError, RunFailed
from ..numerics.budget import (
    REFUSE_FACTOR,
    TIME_REFUSE_FACTOR,
    CostEstimate,
    check_max_steps,
    check_max_time,
    over_budget,
    require_within,
)
from ..numerics.grid import sample_grid as _sample_grid
from ..parameters import Parameters
from ..protocols import Protocol
from ..quasistatic.cycle import Cycle
from ..quasistatic.steady import compiled_marches
from ..units import checked_number
from . import jump
from . import kernel as K
from .arguments import check_progress, check_rig_words, check_snapshot_times
from .model import RIPPLE_SHARE, Population, chain_force, pack_parameters, stick_chains
from .result import Bookkeeping, Snapshot, TransientResult
from .sampling import Sampler, locate_peaks

CONTROLS = ("block", "velocity")
STARTS = ("empty", "steady")
REDUCTIONS = ("auto", "off")
#: the slider counts as stuck below this fraction of the puller velocity (cycle detection, stick chains)
STICK_FRACTION = 0.01
#: a protocol of more segments keeps snapshots only at its start, its end and the snapshot_times asked for
SNAPSHOT_SEGMENTS = 100
#: kernel calls return after this many steps (progress reports, buffer flushes)
CHUNK = 20000
#: and after about this many cohort-steps (from 5e5 cohorts on), so that a time budget is checked between calls
#: of a run with very many cohorts.  A count of the state, never a clock: where the kernel returns changes the
#: answer within the tolerance (556.404384 or 556.404426 Pa at 100 um/s), and a clock-paced call (the first one
#: compiling the kernel) made the printed answer depend on the machine's load.  Each call costs work over all its
#: cohorts, so calls are kept long: 5e7 made the report's 10 s hold 1.6x slower (4.14 s against 2.52 s of CPU)
COHORT_STEPS_PER_CALL = 10_000_000_000
#: default relative tolerance of the local error (stress and bonded fraction)
RTOL = 1e-4
#: a limit cycle of the stick chains is repeated, not integrated again, once its state has settled (``_Repeater``;
#: ``reduction="auto"`` only; with ``every`` its rows are sampled after the fact, ``_Driver.sampler``); False integrates
#: every cycle (the reference of the tests)
REPEAT_CYCLES = True
#: without ``every``, the copies of repeated cycles add at most this many rows to a run's trace (each row ~870 bytes
#: until the trace is written); beyond, a copy is sampled on a uniform grid of at least THIN_ROWS rows
#: (``_Repeater._copy``, transient/sampling.py); with ``every`` the copies are sampled onto its grid
TRACE_COPY_ROWS = 200_000
THIN_ROWS = 20_000
#: rows of copies shifted at a time (a bounded working set, whatever the number of periods)
COPY_BATCH = 200_000
#: with a sampler, the rows' entries held before the settled ones are sampled (a kernel call adds one)
SAMPLER_ENTRIES = 64
#: with ``every`` a run is integrated as without it and its rows are sampled onto the grid afterwards
#: (transient/sampling.py, docs/transient.md section 19), whatever the control; False (with REPEAT_CYCLES = False):
#: the solver lands a step on each grid instant (the reference of the tests)
SAMPLED_AFTER = True
#: with the stick chains under a moving puller the births' spacing is bounded by their own Gauss error, not one
#: lumped cohort's (kernel._relaxed_births, docs/transient.md section 11); False: the lumped bound throughout (the
#: reference of the benchmark and the tests)
RELAXED_BIRTHS = True
#: steps end short of a loaded cohort's arrival at the FENE wall (kernel.WALL_LANDING; False: the reference, where such
#: a step was rejected and retried, three times on average re-sliding after a hold; docs/transient.md section 12)
WALL_LANDING = True


@dataclass
class _State:
    t: float
    x: float
    v: float
    h: float
    puller: float  # puller position at time t
    n: int
    xb: np.ndarray
    tb: np.ndarray
    lw: np.ndarray
    # kernel.advance's running totals: ..., the integral of sigma dt, the extremes since the last row (K.ACC_START)
    acc: np.ndarray = field(default_factory=lambda: np.array(K.ACC_START))

    def grow(self) -> None:
        size = 2 * self.xb.size
        for name in ("xb", "tb", "lw"):
            old = getattr(self, name)
            new = np.empty(size)
            new[: old.size] = old
            setattr(self, name, new)

    def population(self) -> Population:
        w = np.exp(self.lw[: self.n])
        return Population(self.x - self.xb[: self.n], self.t - self.tb[: self.n], w)

    def load(self, pop: Population) -> None:
        while pop.age.size + 16 >= self.xb.size:
            self.grow()
        order = np.argsort(-pop.age)  # oldest first
        m = pop.age.size
        self.xb[:m] = self.x - pop.extension[order]
        self.tb[:m] = self.t - pop.age[order]
        with np.errstate(divide="ignore"):  # an empty cohort has log weight -inf, which the kernel skips
            self.lw[:m] = np.log(pop.weight[order])
        self.n = m


def _check_choice(value: str, allowed: tuple[str, ...], name: str) -> str:
    if value not in allowed:
        raise ParameterError(f"{name}: expected one of {', '.join(allowed)}, got {value!r}")
    return value


def run_transient(
    params: Parameters,
    protocol: Protocol,
    *,
    control: str = "block",
    start: str = "empty",
    start_velocity: float | None = None,
    aging: bool = True,
    stick_population: bool = False,
    every: float | None = None,
    rtol: float = RTOL,
    progress: Callable[[float], None] | None = None,
    stiffness: float | None = None,
    snapshot_times: Any = None,
    max_step: float | None = None,
    max_steps: int | None = None,
    reduction: str = "auto",
    mass: float | None = None,
    damping: float | None = None,
    max_time: float | None = None,
) -> TransientResult:
    """Solve Eqs 1-5 (history form of Eq 3) through ``protocol``.

    ``control="block"``: the protocol is the puller's velocity, and the block
    (stiffness K of Eq 17, or ``stiffness`` in Pa/m) couples it to the slider
    without inertia.  ``control="velocity"``: the protocol is the slider's
    velocity (a rigid rig).  ``start="empty"``: no bonds, no stress;
    ``start="steady"``: the steady population (Eqs 6-8) at ``start_velocity``
    (default: the first segment's), with the block in balance.
    ``stick_population=True`` adds the paper's attached chains (Eqs 13-15):
    when the slider stops (V < 1 % of the puller velocity) the chains take the
    load and the bonds of Eq 1 are set aside; when the chains collapse, the
    slider jumps onto the steady aging curve at the stress reached (the
    paper's jump) and Eq 1 takes over again.  A run from an empty start then
    begins stuck.  ``every`` (s) samples the trace on a uniform grid (and
    each slip's instant): the run is integrated as without it, whatever the
    control (the same steps, events and summary; a settled cycle of the stick
    chains still repeated), and its rows are sampled onto the grid
    afterwards (transient/sampling.py, docs/transient.md section 19);
    otherwise every accepted step is a row.  ``rtol`` is
    the local error tolerance (relative, in stress and bonded fraction).
    ``progress`` is called with the fraction done.  ``snapshot_times`` (s):
    extra instants to keep the age/extension distribution at (the start and
    the end are always kept, and the end of every protocol segment when there
    are at most :data:`SNAPSHOT_SEGMENTS`).

    A steady start below Vc through the block, at the first segment's
    velocity, would sit on the unstable branch of the steady curve: the run
    then starts at the critical point's stable side (steady sliding at Vc,
    sigma_c), from where the slider decelerates and sticks near sigma_c, the
    paper's path into stick-slip; the message says so.  An explicit
    ``start_velocity`` below Vc is honoured (a stiff block, K > Kc(V), can
    slide steadily there) and the message notes the branch.

    ``reduction="auto"`` replaces the cohorts by the steady population of the
    current velocity wherever the slider changes pace slowly over the bonds'
    memory, under an error estimate kept below a tenth of ``rtol``
    (:mod:`stickslip.transient.reduction`, docs/transient.md section 8);
    ``reduction="off"`` keeps the cohorts throughout (the reference), as does
    a ``max_step`` (fixed-step studies of the cohort method).

    ``mass`` (kg/m^2) gives the block inertia, ``damping`` (Pa s/m, with a
    mass) a viscous or radiation damping: m X'' = K (P - X) - eta X' - sigma,
    the slider's position and velocity advanced by the trapezoid rule
    (second order; docs/extensions.md section 4).  The stress of the trace is
    then the interface's, sigma = sum w f; the block's spring carries
    K (P - X).  Such a run keeps the cohorts throughout (no reduction).

    The work is estimated first (:func:`estimate_cost`, within its stated
    factor); a run estimated at more than ten times its budget of steps
    (``max_steps``, default :data:`stickslip.numerics.budget.DEFAULT_MAX_STEPS`)
    or three times its budget of CPU seconds (``max_time``, default
    :data:`stickslip.numerics.budget.DEFAULT_MAX_SECONDS`; ``math.inf``: none)
    is refused before it starts; any other runs, and stops when it uses up
    either budget by raising :class:`stickslip.numerics.budget.BudgetExhausted`
    (a ParameterError) whose ``partial`` is the result up to there (its message
    says where it stopped).
    """
    from ..units import refused_as_written_by_name, si_argument

    # "100 ms", "50 um/s", "300 kPa/m" too, as rsf.simulate and the rig read them (a number is SI)
    written = {"every": every, "max_step": max_step, "max_time": max_time, "start velocity": start_velocity,
               "stiffness": stiffness, "mass": mass, "damping": damping}  # fmt: skip
    every, max_step, max_time, start_velocity, stiffness, mass, damping = (
        None if value is None else si_argument(value, dimension, name)
        for value, dimension, name in (
            (every, "time", "every"), (max_step, "time", "max_step"), (max_time, "time", "max_time"),
            (start_velocity, "velocity", "start_velocity"), (stiffness, "stress_per_length", "stiffness"),
            (mass, "mass_per_area", "mass"), (damping, "stress_per_velocity", "damping"),
        )
    )  # fmt: skip
    with refused_as_written_by_name(written):  # "got '-10 ms'", not "got -0.01"
        progress, mass, damping, k_block, start_velocity, budget, seconds = _checked_arguments(
            params, protocol, control, start, reduction, aging, stick_population, rtol, progress, stiffness, mass,
            damping, every, max_step, start_velocity, max_steps, max_time,
        )  # fmt: skip
    cpu0 = time.process_time()
    _require_finite_chains(params, protocol, control, start, start_velocity, k_block)
    _require_steady_range(params, protocol, aging, start_velocity)
    with compiled_marches():  # numba runs the kernels in any case: every steady state the run asks for runs compiled
        require_within(
            estimate_cost(params, protocol, control=control, start_velocity=start_velocity, rtol=rtol,
                          every=every, max_step=max_step, aging=aging, reduction=reduction, start=start, mass=mass,
                          stiffness=k_block, stick_population=bool(stick_population)),
            budget,
            "transient",
            max_time=seconds,
            factor=REFUSE_FACTOR,
            time_factor=TIME_REFUSE_FACTOR,
        )  # fmt: skip
        note = ""
        if start == "steady" and control == "block" and aging:
            start_velocity, note = _steady_start_below_vc(params, protocol, start_velocity)
        driver = _Driver(
            params, protocol, control=control, k_block=k_block, aging=aging, stick_population=bool(stick_population),
            rtol=float(rtol), mass=mass, damping=damping, budget=budget, seconds=seconds, cpu0=cpu0, note=note,
            progress=progress,
        )  # fmt: skip
        driver.start(start, start_velocity, every, max_step, snapshot_times, reduction)
        return driver.run()


def _checked_arguments(  # type: ignore[no-untyped-def]
    params, protocol, control, start, reduction, aging, stick_population, rtol, progress, stiffness, mass, damping,
    every, max_step, start_velocity, max_steps, max_time,
):  # fmt: skip
    """run_transient's arguments checked (a ParameterError naming the first one wrong): (progress, mass, damping,
    the block's stiffness, the start velocity, the budgets of steps and of CPU seconds)."""
    if not isinstance(params, Parameters):
        raise ParameterError(f"params: expected stickslip Parameters, got {type(params).__name__}")
    _check_choice(control, CONTROLS, "control")
    _check_choice(start, STARTS, "start")
    _check_choice(reduction, REDUCTIONS, "reduction")
    for flag, name in ((aging, "aging"), (stick_population, "stick_population")):
        if not isinstance(flag, (bool, np.bool_)):
            raise ParameterError(f"{name}: expected True or False, got {flag!r}")
    if not isinstance(protocol, Protocol):
        raise ParameterError(f"protocol: expected a stickslip.protocols.Protocol, got {type(protocol).__name__}")
    check_rtol(rtol)
    progress = check_progress(progress)
    check_rig_words(control, stiffness)
    if stick_population and control != "block":
        raise ParameterError("stick_population: the attached chains need block control (control='block')")
    mass, damping = _block_inertia(mass, damping, control, stick_population)
    k_block = params.block.effective_stiffness if stiffness is None else _finite(stiffness, "stiffness")
    if not (math.isfinite(k_block) and k_block > 0):
        raise ParameterError(f"stiffness: expected a positive finite value in Pa/m, got {stiffness!r}")
    rigid = RIGID * params.bonds.site_density * params.bonds.chain_stiffness
    if control == "block" and k_block > rigid:
        raise ParameterError(
            f"block stiffness {k_block:.3g} Pa/m is more than {RIGID:.0e} x the bonds' own (N0 M = {rigid / RIGID:.3g}"
            " Pa/m): the block is rigid, the slider follows the puller (use control='velocity', --control velocity)"
        )
    if control == "block" and k_block < PINNED * rigid / RIGID:
        raise ParameterError(
            f"block stiffness {k_block:.3g} Pa/m is less than {PINNED:.0e} x the bonds' own (N0 M = {rigid / RIGID:.3g}"
            " Pa/m): the chains' stretch is below the float resolution of the slider's travel, and sigma loses its"
            " digits; expected a stiffer block or a smaller bonds.site_density or bonds.chain_stiffness"
        )
    scale = params.bonds.site_density * params.bonds.chain_stiffness * params.bonds.max_extension
    if not LEAST_STRESS <= scale <= MOST_STRESS:
        raise ParameterError(
            f"the bonds' stress scale N0 M dl_m = {scale:.3g} Pa leaves the floating-point range of the cohorts' sums;"
            f" expected {LEAST_STRESS:.0e} to {MOST_STRESS:.0e} Pa (set bonds.site_density, chain_stiffness or"
            " max_extension within it)"
        )
    duration = protocol.duration
    if every is not None and not (isinstance(every, (int, float)) and math.isfinite(every) and 0 < every <= duration):
        raise ParameterError(f"every: expected a positive time no longer than the run ({duration:g} s), got {every!r}")
    if every is not None and duration / every > MAX_SAMPLES:
        raise ParameterError(
            f"every: {every:g} s gives {duration / every:.3g} rows over {duration:g} s; expected at most"
            f" {MAX_SAMPLES:.0e} (each row holds ~{SAMPLE_BYTES} bytes until the trace is written: sample less often)"
        )
    if max_step is not None and not (isinstance(max_step, (int, float)) and math.isfinite(max_step) and max_step > 0):
        raise ParameterError(f"max_step: expected a positive time in s, got {max_step!r}")
    if start_velocity is not None:
        start_velocity = _finite(start_velocity, "start velocity")
    return progress, mass, damping, k_block, start_velocity, check_max_steps(max_steps), check_max_time(max_time)


class _Driver:
    """One run of :func:`run_transient` through its protocol, piece by piece: the stuck block under the attached
    chains (:meth:`_stuck`, then the jump, :meth:`_jump_to_steady`), a quasi-steady stretch (:meth:`_glide`), or the
    cohort kernel (:meth:`_cohorts`, its state checked by :meth:`_check`); snapshots kept on the way
    (:meth:`_snapshots_through`)."""

    def __init__(  # type: ignore[no-untyped-def]
        self, params, protocol, *, control, k_block, aging, stick_population, rtol, mass, damping, budget, seconds,
        cpu0, note, progress,
    ) -> None:  # fmt: skip
        self.params, self.protocol, self.control, self.k_block = params, protocol, control, k_block
        self.aging, self.stick_population, self.rtol = aging, stick_population, rtol
        self.mass, self.damping, self.inertial = mass, damping, mass > 0
        self.budget, self.seconds, self.cpu0, self.note, self.progress = budget, seconds, cpu0, note, progress
        self.duration = protocol.duration
        self.functions = K.compiled()
        relaxed = RELAXED_BIRTHS and _births_never_held(protocol, stick_population)
        self.p = pack_parameters(
            params, aging, k_block, mass, damping, relaxed_births=relaxed, wall_landing=WALL_LANDING
        )
        self.snapshots: list[Snapshot] = []
        self.chain_rows: list[np.ndarray] = []
        self.events: list[tuple[str, float, float, float]] = []  # (kind, time, stress, velocity)
        self.jumps: list[jump.Jump] = []  # the massless block's jumps through rupture cascades
        self.chain_state = {"elapsed": 0.0, "fraction": 1.0}
        self.chains_ahead: tuple[tuple[float, float] | None, bool] = (None, False)  # set by each stuck stretch
        self.snap_index = 0
        self.out = np.empty((CHUNK, K.ROW_COLUMNS))
        self.repeater: _Repeater | None = None
        #: with ``every``, a repeating run's rows sampled after the fact (transient/sampling.py); None: the rows kept
        self.sampler: Sampler | None = None
        self.dropped = 0  # entries of self.rows already fed to the sampler
        self.slips_fed = 0  # events looked at for the sampler's instants
        self.copy_rows_left = TRACE_COPY_ROWS  # rows the copies of repeated cycles may still add without ``every``
        #: velocity control with a sampler: the last row balanced (as the solver gave it) and the corrections of its
        #: integral of sigma dt and work (_balanced_integral), carried on to the rows fed next
        self.balanced_from: tuple[np.ndarray, tuple[float, float]] | None = None
        self.thinned: list[tuple[int, float, int, int]] = []  # (periods, spacing, rows kept, rows in place of)

    def start(
        self, start: str, start_velocity: float | None, every: float | None, max_step: float | None,
        snapshot_times: Any, reduction: str,
    ) -> None:  # fmt: skip
        """The state at t = 0 (empty, or the steady population with the block in balance), its row, the sampling
        grid, the snapshot instants and the reduction."""
        params, control, k_block = self.params, self.control, self.k_block
        state = _State(0.0, 0.0, 0.0, params.bonds.bond_time * 1e-3, 0.0, 0, *(np.empty(4096) for _ in range(3)))
        v_first = self.protocol.initial_velocity
        if start == "steady":
            v_start = v_first if start_velocity is None else float(start_velocity)
            if not v_start > 0:
                raise ParameterError(
                    f"start velocity: a steady start needs a positive sliding velocity, got {v_start!r}"
                )
            # the cells whose cohorts reach the FENE cliff within the run cut to the tolerance (section 18); a start
            # held while the velocity stays (below) carries them only from the first change on
            held = _held_start(self.protocol, control, start, reduction, max_step, self.mass, start_velocity)
            reach = _start_reach(params, self.protocol, v_start, self.aging, control, k_block, held)
            state.load(_steady_cohorts(params, v_start, self.aging, reach=reach, ripple=RIPPLE_SHARE * self.rtol))
            state.v = v_start
        elif start_velocity is not None:
            raise ParameterError("start velocity: only used with start='steady'")
        else:
            state.v = v_first  # no bonds: the slider moves with the puller
        pop = state.population()  # no cohort: sigma0 = 0
        sigma0 = float(pop.weight @ chain_force(pop.extension, params))
        # the block in balance with the bonds (and the damping, which a moving slider meets)
        state.puller = state.x + (sigma0 + self.damping * state.v) / k_block if control == "block" else state.x
        self.state = state
        self.times = _sample_grid(every, self.duration)
        # a snapshot copies every cohort: at each segment end only for a protocol of a few segments (issue 29: 1e5
        # segments of 1 ms held 8.4 GB of them)
        ends = self.protocol.boundaries.tolist() if len(self.protocol.segments) <= SNAPSHOT_SEGMENTS else []
        self.wanted = sorted(set([0.0, self.duration, *ends, *check_snapshot_times(snapshot_times, self.duration)]))
        self.rows: list[np.ndarray] = [_row(state, params, control, k_block, self.mass)]
        self.chains_on = self.stick_population and start == "empty"
        self.sample_index = 1 if self.times.size else 0  # t = 0 is already a row
        self.h_max = math.inf if max_step is None else float(max_step)
        if self.chains_on:
            self.events.append(("stick", 0.0, sigma0, 0.0))
        self.reducer = None
        if reduction == "auto" and max_step is None and not self.inertial:  # a bound on the step: cohorts throughout
            self.reducer = _Reducer(params, self.p, self.functions, control, k_block, self.rtol, self.aging)
            self.reducer.disturbed(state.t)  # from empty, or a steady start: the cohorts first replace every bond
            if REPEAT_CYCLES and self.stick_population and control == "block":
                self.repeater = _Repeater(self)
                if self.times.size:  # the run integrated as without ``every``, its rows sampled onto the grid
                    self.sampler = Sampler(self.times, k_block)
                    self.times = np.empty(0)
                    self.sample_index = 0
        # under velocity control a steady start at the first piece's velocity is the exact solution until the
        # velocity changes (docs/transient.md section 18): held, not integrated (:meth:`_held_steady`)
        self.held = _held_start(self.protocol, control, start, reduction, max_step, self.mass, start_velocity)
        self.start_population = state.population() if self.held else None
        self.start_population_velocity = state.v

    def run(self) -> TransientResult:
        """Every piece of the protocol, to its end (or to where the chains' jump has no landing point)."""
        self._sample_after()
        state = self.state
        for t0, t1, vp in self.protocol.pieces():
            while self.snap_index < len(self.wanted) and self.wanted[self.snap_index] <= t0 + 1e-15:
                self._snapshot()
            if self.control == "velocity":
                if self.reducer is not None and vp != state.v:
                    self.reducer.disturbed(state.t)
                state.v = vp
            if self.reducer is not None:
                self.reducer.next_try = state.acc[4]
            while state.t < t1 - 1e-12 * max(t1, 1.0):
                if self.chains_on:
                    stopped = self._stuck(t1, vp)
                    if stopped is not None:
                        return stopped
                    continue
                # the solver stops at the next snapshot instant (a reduced stretch rebuilds its cohorts there)
                following = bisect.bisect_right(self.wanted, state.t + 1e-15, lo=self.snap_index)  # 1e5 segments
                wanted = self.wanted
                t_stop = wanted[following] if following < len(wanted) and wanted[following] < t1 else t1
                if self._held_steady(t_stop, t1, vp) or self._glide(t0, t_stop, t1, vp):
                    continue
                self._cohorts(t0, t_stop, t1, vp)
        while self.snap_index < len(self.wanted):
            self._snapshot()
        return self._finish()

    def _sample_after(self) -> None:
        """With ``every``, the run integrated as without it and its rows sampled onto the grid as they come
        (transient/sampling.py): the steps never land on the grid, so ``every`` changes neither them nor the summary.
        The protocol's boundaries are rows too (a summary's window starts at one: the last segment), all of them for
        a protocol of at most SNAPSHOT_SEGMENTS segments, else the last segment's start.  (A repeating run's
        sampler, set up with its repeater in :meth:`start` before any row, is set up again here.)"""
        grid = self.sampler.grid if self.sampler is not None else self.times
        if not (grid.size and (SAMPLED_AFTER or self.sampler is not None)):
            return
        bounds = self.protocol.boundaries
        kept = bounds[1:] if len(self.protocol.segments) <= SNAPSHOT_SEGMENTS else bounds[-2:]  # (and the end)
        self.sampler = Sampler(
            grid, self.k_block, control=self.control, mass=self.mass, damping=self.damping, breaks=bounds[1:-1],
            instants=kept,
        )  # fmt: skip
        self.times = np.empty(0)
        self.sample_index = 0

    def _bound_rows(self) -> None:
        """With a sampler, the rows it may take are sampled once they pile up (a bounded working set)."""
        if self.sampler is not None and len(self.rows) > SAMPLER_ENTRIES:
            self._feed_settled()

    def _snapshot(self) -> None:
        self.snapshots.append(_snapshot(self.state))
        self.snap_index += 1

    def _snapshots_through(self, t1: float) -> None:
        """The snapshot instants the run has reached within this piece (before its end t1)."""
        while (
            self.snap_index < len(self.wanted)
            and self.wanted[self.snap_index] <= self.state.t + 1e-15
            and self.wanted[self.snap_index] < t1
        ):
            self._snapshot()

    def _report_progress(self) -> None:
        if self.progress is not None:
            self.progress(min(1.0, self.state.t / self.duration))

    def _feed(self, keep: int | None = None) -> None:
        """The rows before entry ``keep`` (counted from the run's first; None: all) to the sampler, and dropped (the
        repeater still needs those from its last mark on)."""
        if self.sampler is None:
            return
        count = len(self.rows) if keep is None else keep - self.dropped
        if count <= 0:
            return
        fine = np.vstack([np.atleast_2d(r) for r in self.rows[:count]])
        if self.control == "velocity":  # the integral between rows from the energy balance, as over the whole trace
            fine = self._balanced(fine)
        self.sampler.feed(fine, self._slips_until(float(fine[-1, 0])))
        del self.rows[:count]
        self.dropped += count

    def _balanced(self, fine: np.ndarray) -> np.ndarray:
        """Velocity control: the rows' integral of sigma dt and work from the energy balance
        (:func:`_balanced_integral`), carried on from the rows fed before: the numbers of the whole trace balanced at
        once (solver._finish), to the bit."""
        before = self.balanced_from
        table = fine.copy() if before is None else np.vstack([before[0][None, :], fine])
        carried = _balanced_integral(table, self.protocol, (0.0, 0.0) if before is None else before[1])
        self.balanced_from = (fine[-1].copy(), carried)
        return table if before is None else table[1:]

    def _slips_until(self, t: float) -> np.ndarray:
        """The slips' instants up to t not yet given to the sampler (each a row of its own)."""
        events, k, found = self.events, self.slips_fed, []
        while k < len(events) and events[k][1] <= t:
            if events[k][0] == "slip":
                found.append(events[k][1])
            k += 1
        self.slips_fed = k
        return np.array(found)

    def _feed_settled(self) -> None:
        """The rows the repeater no longer needs (before its last mark) to the sampler."""
        if self.sampler is not None:
            marks = self.repeater.marks if self.repeater is not None else []
            self._feed(marks[-1][2] if marks else None)

    def trace_rows(self) -> list[np.ndarray]:
        """The trace's rows: all of them, or with a sampler the grid's (and the run's last state)."""
        if self.sampler is None:
            return self.rows
        self._feed()
        self.sampler.flush()
        out = list(self.sampler.rows())
        anchor = self.sampler.anchor
        if anchor is not None and anchor[0] > self.sampler.last_written:  # a run stopped between grid points
            out.append(anchor[None, :])
        return out

    def _finish(self, stop: str | None = None) -> TransientResult:
        note = self.note + _jumps_note(self.jumps) + (self.repeater.note() if self.repeater else "")
        result = _finish(self, self.snapshots, stop, note)
        return replace(result, jumps=tuple(self.jumps)) if self.jumps else result

    def _stuck(self, t1: float, vp: float) -> TransientResult | None:
        """The stuck block to the piece's end or the chains' collapse: the slider fixed, the chains of Eq 15 carry
        sigma = K (P - X); at a collapse the jump (None), or the run's end where it has no landing point."""
        self._bound_rows()
        state, k_block, times, rows, params = self.state, self.k_block, self.times, self.rows, self.params
        stress0 = k_block * (state.puller - state.x)
        chain = self.chain_state
        res = stick_chains(params, self.aging, stress0, k_block * vp, chain["elapsed"], chain["fraction"], t1 - state.t)
        # what the chains would do under this loading past the stretch (the verdict of a run that ends stuck)
        due = None if res.due is None else (state.t + res.due, stress0 + k_block * vp * res.due)
        self.chains_ahead = (due, res.never)
        t_new = state.t + res.duration
        self.chain_rows.append(np.c_[state.t + res.times, res.fractions])
        if times.size:  # the trace on the sampling grid: stress and positions are exact while stuck
            inside = (times > state.t) & (times <= t_new)
            grid = times[inside]
            if grid.size:
                rows.append(_stuck_rows(state, vp, k_block, grid, np.interp(grid - state.t, res.times, res.fractions)))
            # sigma rises while stuck: the stretch's lowest is its start, in its first row, and its highest its end,
            # left for the next row where no grid point closes the stretch (the chains' collapse: the slip's σs)
            if not grid.size:
                _extremes_at(state.acc, state.t, k_block * (state.puller - state.x))
            else:
                _extremes_reset(state.acc)
            end_sigma = k_block * (state.puller + vp * res.duration - state.x)
            if not (grid.size and grid[-1] >= t_new) and end_sigma > state.acc[8]:
                state.acc[8], state.acc[10] = end_sigma, t_new
            self.sample_index = max(self.sample_index, int(np.searchsorted(times, t_new, side="right")))
        elif res.times.size > 1:
            rows.append(_stuck_rows(state, vp, k_block, state.t + res.times[1:], res.fractions[1:]))
            _extremes_reset(state.acc)
        state.acc[6] += _stuck_impulse(state, vp, k_block, res.duration)
        state.puller += vp * res.duration
        state.t = t_new
        chain["elapsed"] += res.duration
        chain["fraction"] = res.fraction
        if not res.collapsed:
            return None
        sigma_s = k_block * (state.puller - state.x)
        from ..quasistatic.jump import jump_velocity

        where = "beyond the steady curve's reach"
        try:
            landing = jump_velocity(params, sigma_s, "aging" if self.aging else "no-aging")
        except ModelError as exc:  # no critical point: nothing for the jump to land beyond (words, not a traceback)
            landing, where = None, f"and {str(exc).removeprefix('no stick-slip cycle: ')}"
        vs = landing.velocity if landing is not None and landing.reachable else None
        if vs is None:
            self.events.append(("unreachable", state.t, sigma_s, 0.0))
            return self._finish(stop=f"the chains collapse at σs = {sigma_s:.6g} Pa, {where}: the paper's jump has"
                                f" no landing point; the model stops at t = {state.t:.6g} s of the"
                                f" {self.duration:.6g} s asked for: what follows is not known")  # fmt: skip
        self._jump_to_steady(sigma_s, vs, vp)
        return None

    def _jump_to_steady(self, sigma_s: float, vs: float, vp: float) -> None:
        """The paper's jump: the steady population at vs, the slider where the new bonds carry sigma_s."""
        state, p = self.state, self.p
        self.events.append(("slip", state.t, sigma_s, vs))
        state.load(_steady_cohorts(self.params, vs, self.aging, *_rebuilt_cells(self.rtol)))
        state.v = vs
        state.h = self.params.bonds.bond_time * 1e-3
        self.chains_on = False
        weights = np.exp(state.lw[: state.n])
        state.x = self.functions["_balance_weights"](state.x, state.puller, state.n, state.xb, weights, p)
        state.v = self.functions["_slider_velocity"](
            vs, vp, state.n, state.xb, state.tb, state.lw, state.x, state.t, p, *_scratch(state)
        )
        # the new bonds carry sigma_s (balanced to ~1e-12 of it): the row says so, as the stuck block's at this instant
        self.rows.append(_row(state, self.params, self.control, self.k_block, sigma=sigma_s))
        if self.reducer is not None:
            self.reducer.loaded_steady(state)

    def _held_steady(self, t_stop: float, t1: float, vp: float) -> bool:
        """A steady start under velocity control while the velocity is still the start's: at constant V Eq 1 is
        linear and asymptotically stable and its steady state is the exact solution (docs/transient.md section 18),
        so the stretch to ``t_stop`` (in the piece ending at ``t1``) is written as steady sliding
        (reduction.steady_glide, the steady solver's sigma and N) and the start's cohorts are carried on unchanged in
        age and extension, not integrated: the discretised start's ripple never enters.  False once the velocity has
        changed (or without the reduction)."""
        state = self.state
        if not (self.held and vp == self.start_population_velocity):
            self.held, self.start_population = False, None
            return False
        from . import reduction as R

        assert self.reducer is not None  # held only with the reduction on
        steady = self.reducer._steady_at(vp)
        nn, _ss, _k, uu = self.functions["_sums"](state.n, state.xb, state.lw, state.x, self.p)
        glide = R.steady_glide(
            self.params, t=state.t, t_end=t_stop, x=state.x, puller=state.puller, vp=vp, sigma=steady[0],
            steady=steady, bonded=nn, energy=uu, k_block=self.k_block, block=False, acc=state.acc,
            sample_times=self.times, sample_index=self.sample_index,
        )  # fmt: skip
        self.rows.extend(_kernel_rows(glide.rows, self.k_block, "velocity"))
        self.sample_index = glide.sample_index
        state.x += vp * (glide.t - state.t)
        state.t, state.puller = glide.t, state.x
        state.load(self.start_population)  # the same ages and extensions, now
        state.acc[1] += glide.bonded - nn  # the cohorts' N carries on, as after a reduced stretch
        state.h = 1e-2 * self.params.bonds.bond_time  # and their first step, as there
        self._snapshots_through(t1)
        self._report_progress()
        return True

    def _glide(self, t0: float, t_stop: float, t1: float, vp: float) -> bool:
        """A quasi-steady stretch where the reduction takes one (when it is time to look for one)."""
        state, reducer = self.state, self.reducer
        if reducer is None or state.acc[4] < reducer.next_try:
            return False
        glided, self.sample_index = reducer.attempt(state, t0, t_stop, vp, self.times, self.sample_index, self.rows)
        if glided:
            self._snapshots_through(t1)
            self._report_progress()
            self._bound_rows()
        return glided

    def _cohorts(self, t0: float, t_stop: float, t1: float, vp: float) -> None:
        """One call of the cohort kernel towards t_stop (it returns early on a full buffer, a stick, its pace)."""
        state, p, control = self.state, self.p, self.control
        if control == "block" and not self.inertial:  # with a mass the velocity is a state of its own
            state.v = self.functions["_slider_velocity"](
                state.v, vp, state.n, state.xb, state.tb, state.lw, state.x, state.t, p, *_scratch(state)
            )
        # in a hold (vp = 0) the slider counts as stopped below 1 % of the protocol's sliding velocity
        pace = vp if vp > 0 else float(np.max(self.protocol.velocities))
        stick_v = STICK_FRACTION * pace if (self.stick_population and pace > 0) else 0.0
        puller0 = state.puller - vp * (state.t - t0)  # puller position at the start t0 of this piece
        lw_new, rate0, lc, aa, w1 = (np.empty(state.xb.size) for _ in range(5))
        status, t, x, v, h, n, self.sample_index, count = self.functions["advance"](
            state.t, t_stop, state.x, state.v, state.h, puller0, vp, t0, 1 if control == "block" else 0,
            state.n, state.xb, state.tb, state.lw, lw_new, rate0, lc, aa, w1, state.acc, p, self.rtol, self.h_max,
            self.times, self.sample_index, self.out, CHUNK, stick_v,
            _chunk(state, self.budget, self.reducer, _paced(state.n)),
        )  # fmt: skip
        state.t, state.x, state.v, state.h, state.n = float(t), float(x), float(v), float(h), int(n)
        state.puller = puller0 + vp * (state.t - t0) if control == "block" else state.x
        if count:
            self.rows.extend(_kernel_rows(self.out[:count], self.k_block, control, self.mass))
            self._bound_rows()
        if status == K.FULL:
            state.grow()
        elif status == K.STICK:
            self.chains_on = True
            self.chain_state = {"elapsed": 0.0, "fraction": 1.0}
            self.events.append(("stick", state.t, self.k_block * (state.puller - state.x), state.v))
            if self.repeater is not None:
                self.repeater.at_stick(t0, t1, vp)
                self._feed_settled()
        collapsed = status == K.FAILED and not self._jumped(vp)
        self._check(count, collapsed)
        self._report_progress()
        self._snapshots_through(t1)

    def _jumped(self, vp: float) -> bool:
        """A collapsed step of the massless block in a rupture cascade: the jump (transient/jump.py), in no time;
        on a creeping block, the cohorts at the FENE wall that hold it alone broken at once (jump.wall_lumps,
        docs/transient.md section 22; a creep that does not come back fails in its own words); False where the
        collapse is neither (the run then fails in words)."""
        state, pace = self.state, float(np.max(self.protocol.velocities))
        if self.control == "velocity":
            return self._instant_deaths()
        cascade = self.control == "block" and not self.inertial and math.isfinite(state.x)
        if not (cascade and math.isfinite(state.v)):
            return False
        if state.v <= jump.ENTRY * pace:  # a creeping block: lumps at the FENE wall, or a let-go from rest
            sigma = self.k_block * (state.puller - state.x)
            lumps = jump.wall_lumps(
                state.t, state.x, state.v, state.puller, vp, pace, state.n, state.xb, state.tb, state.lw, self.p,
                self.functions,
            )  # fmt: skip
            if lumps is None:
                if 0.0 <= state.v <= jump.CREEP * pace and np.any(
                    state.x - state.xb[: state.n][np.isfinite(state.lw[: state.n])]
                    >= jump.WALL_REACH * self.params.bonds.max_extension
                ):  # stopped, its oldest bonds at the wall, and no creep comes back: said so, the run kept
                    failed = SolverFailed(jump.creep_collapse(state.t, sigma, state.v, jump.WALL_LUMPS))
                    try:
                        failed.partial = _finish(self, list(self.snapshots), str(failed), self.note)
                    except (ArithmeticError, ValueError, IndexError):
                        failed.partial = None
                    raise failed
                return False
            state.x, state.v, state.n, found, dissipated = lumps
            acc = state.acc
            acc[1] += found.broken_share * self.params.bonds.site_density
            acc[3] += dissipated
            _extremes_at(acc, state.t, found.stress_after)
            acc[4] += 1.0
            state.h = self.params.bonds.bond_time * 1e-3
            if not hasattr(self, "wall_lumps"):  # the message's note, with the lumps said once at its end
                self.wall_lumps, self.note_before_lumps = [], self.note
            self.wall_lumps.append(found)
            self.note = self.note_before_lumps + jump.lumps_note(self.wall_lumps)
            if self.reducer is not None:
                self.reducer.disturbed(state.t)
            return True
        cohorts = state.n
        x, v, n, found, dissipated = jump.cascade(
            state.t, state.x, state.v, state.puller, vp, pace, state.n, state.xb, state.tb, state.lw, self.p,
            self.functions,
        )  # fmt: skip
        if n == cohorts:  # no bond broke: not a cascade the jump can take (the kernel would fail there again)
            return False
        state.x, state.v, state.n = x, v, n
        acc = state.acc
        acc[1] += found.broken_share * self.params.bonds.site_density
        acc[3] += dissipated
        _extremes_at(acc, state.t, found.stress_after)
        acc[4] += 1.0  # a step, so that the step budget bounds a run that jumps again and again
        state.h = self.params.bonds.bond_time * 1e-3
        self.jumps.append(found)
        if self.sampler is not None:  # no row holds the state it jumped to: the next row's, from this instant
            self.sampler.jumps.append(state.t)
        if self.reducer is not None:
            self.reducer.disturbed(state.t)
        return True

    def _instant_deaths(self) -> bool:
        """A collapsed step under velocity control: the cohorts that die within the kernel's floor step (a velocity
        step erasing the aging term that held aged bonds against their stretch) broken at once (jump.instant_deaths,
        docs/transient.md section 24); False where none does (the run then fails in words)."""
        state = self.state
        if not (math.isfinite(state.x) and math.isfinite(state.v)):
            return False
        found = jump.instant_deaths(
            state.t, state.x, state.v, state.n, state.xb, state.tb, state.lw, self.p, self.functions
        )
        if found is None:
            return False
        state.n, deaths, dissipated, rest = found
        acc = state.acc
        acc[1] += deaths.broken_share * self.params.bonds.site_density
        acc[3] += dissipated
        _extremes_at(acc, state.t, deaths.stress_after)
        acc[4] += 1.0  # a step, so that the step budget bounds a run that breaks cohorts so again and again
        # the next step from the survivors' fastest death (the kernel's own control shortens it where needed)
        floor = 1e-15 * max(state.t, self.params.bonds.bond_time)
        state.h = min(max(math.exp(-min(rest, K.LOG_RATE_CAP)), 10.0 * floor), self.params.bonds.bond_time * 1e-3)
        if not hasattr(self, "instant_deaths"):  # the message's note, with the deaths said once at its end
            self.instant_deaths, self.note_before_deaths = [], self.note
        self.instant_deaths.append(deaths)
        self.note = self.note_before_deaths + jump.instant_note(self.instant_deaths)
        if self.sampler is not None:  # no row holds the state after the deaths: the next row's, from this instant
            self.sampler.jumps.append(state.t)
        if self.reducer is not None:
            self.reducer.disturbed(state.t)
        return True

    def _check(self, count: int, collapsed: bool = False) -> None:
        """A state gone non-finite, or a step that collapsed to the kernel's floor and still failed, fails the run
        (SolverFailed, in words); a budget used up stops it (BudgetExhausted, with the run so far)."""
        state, duration = self.state, self.duration
        if collapsed or not all(math.isfinite(q) for q in (state.t, state.x, state.v, state.h)):
            pace = float(np.max(self.protocol.velocities))
            rigid = (
                _rigid_collapse(state, self.params, self.aging, self.protocol) if self.control == "velocity" else None
            )
            failed = SolverFailed(
                _non_finite(state.t, self.out[:count], self.rows, pace, self.inertial, state.h, rigid)
            )
            try:  # the run up to its last good row, as a budget's stop keeps it (status "failed")
                failed.partial = _finish(self, list(self.snapshots), str(failed), self.note)
            except (ArithmeticError, ValueError, IndexError):  # rows that make no result: the message alone
                failed.partial = None
            raise failed
        unfinished = state.t < duration - 1e-12 * max(duration, 1.0)  # a run that got to its end is whole
        if unfinished and (state.acc[4] > self.budget or time.process_time() - self.cpu0 > self.seconds):
            cpu = time.process_time() - self.cpu0
            stopped = over_budget("transient", int(state.acc[4]), self.budget, state.t, duration,
                                  cpu=cpu if cpu > self.seconds else None, max_time=self.seconds)  # fmt: skip
            # the budget's error carries the run up to where it stopped (its message says so; regime undetermined)
            partial = _finish(self, [*self.snapshots, _snapshot(state)], str(stopped), self.note)
            stopped.partial = replace(partial, status="stopped")  # at its budget: not a failure of the model
            raise stopped


class _Repeater:
    """A limit cycle of the stick chains repeated rather than integrated again (docs/transient.md section 10).

    With the chains a stick starts with fresh chains and the bonds of Eq 1 set aside, so the stress it starts under
    is the whole state of the cycle (in the puller's frame, under a constant pace): a cycle that starts where the
    one before started is the same cycle, shifted by its period in time and by Vp T in position.  Once the sticks'
    stresses and the periods have settled (:meth:`_periods`), the last cycle's rows, chain rows and events are
    copied forward, whole periods at a time, with the running totals (bonds born and broken, work, dissipation,
    the stress integral) advanced by the cycle's own increments; the last period or two before the piece's end
    are integrated again, so that the run ends on a state of its own (its snapshot, the next piece).
    """

    #: the trace's running totals (bonds born and broken, work, dissipation, the stress integral): row column and
    #: accumulator index
    TOTALS = ((6, 0), (7, 1), (8, 2), (9, 3), (13, 6))

    def __init__(self, driver: _Driver) -> None:
        self.driver = driver
        self.marks: list[tuple[float, float, int, int, int, int, np.ndarray, float]] = []
        self.repeated = 0

    def at_stick(self, t0: float, t1: float, vp: float) -> None:
        """A stick has just begun: mark it, and copy the cycle forward if it has settled."""
        d, state = self.driver, self.driver.state
        sigma = d.k_block * (state.puller - state.x)
        self.marks.append(
            (state.t, sigma, d.dropped + len(d.rows), len(d.chain_rows), len(d.events), len(d.jumps), state.acc.copy(),
             t0)
        )  # fmt: skip
        del self.marks[:-3]
        periods = self._periods(t1, vp)
        if periods:
            self._copy(periods, vp)

    def _periods(self, t1: float, vp: float) -> int:
        """Whole periods to copy: 0 where the sticks have not settled, or too little is left to gain.

        Settled, over the copies: the sticks' stress within rtol of where the integration would have taken it (the
        last difference carried over the copies, shrinking geometrically as the last two differences shrank, or
        not at all), and their clock within rtol of a period (the last two periods' difference, once per copy)."""
        if len(self.marks) < 3 or vp <= 0:
            return 0
        (ta, sa, *_, t0a), (tb, sb, *rest_b), (tc, sc, *rest_c) = self.marks
        if not t0a == rest_b[-1] == rest_c[-1] or rest_b[3] != rest_c[3]:  # one piece; no cascade jump in the cycle
            return 0
        d, period = self.driver, tc - tb
        following = bisect.bisect_right(d.wanted, tc + 1e-15)
        end = min(t1, d.wanted[following]) if following < len(d.wanted) else t1
        periods = max(0, math.floor((end - tc) / period) - 1) if period > 0 else 0
        before, last = abs(sb - sa), abs(sc - sb)
        ratio = last / before if before > 0 else (0.0 if last == 0 else math.inf)
        carried = last * (min(periods, 1.0 / (1.0 - ratio)) if ratio < 1 else periods)
        drift = periods * abs(period - (tb - ta))
        return periods if carried <= d.rtol * abs(sc) and drift <= d.rtol * period else 0

    def _copy(self, periods: int, vp: float) -> None:
        d, state = self.driver, self.driver.state
        (tb, _, rows_b, _c, events_b, _, acc_b, _), (tc, _, rows_c, _c2, events_c, _, acc_c, _) = self.marks[-2:]
        period, travel = tc - tb, vp * (tc - tb)
        rows = np.vstack([np.atleast_2d(r) for r in d.rows[rows_b - d.dropped : rows_c - d.dropped]])
        events = d.events[events_b:events_c]
        gained = {index: acc_c[index] - acc_b[index] for _, index in self.TOTALS}  # acc[7], the lowest, may be inf
        slips = np.array([t for kind, t, *_ in events if kind == "slip"])
        end = tc + periods * period  # where the copies end (state.t below, to the bit)

        def shifted(j: int) -> np.ndarray:
            copied = rows.copy()
            copied[:, [0, 16, 17]] += j * period  # the time, and those of the row's extremes
            copied[:, 4:6] += j * travel
            for column, index in self.TOTALS:
                copied[:, column] += j * gained[index]
            return copied

        # without ``every`` the copies are rows while the run's trace stays within TRACE_COPY_ROWS of them; beyond,
        # they are sampled on a uniform grid (a note says how); with ``every``, onto its grid
        sampler = d.sampler
        last = np.atleast_2d(d.rows[-1])[-1] if d.rows else None  # the stick at tc, the cycle's start
        if sampler is None and periods * len(rows) > d.copy_rows_left and last is not None and last[0] == tc:
            kept = max(d.copy_rows_left, THIN_ROWS)
            grid = tc + (end - tc) * np.arange(1, kept + 1) / kept
            grid[-1] = end
            sampler = Sampler(grid, d.k_block)
            sampler.anchor = last.copy()
            sampler.last_written = tc
            d.thinned.append((periods, (end - tc) / kept, kept, periods * len(rows)))
            d.copy_rows_left = 0
        elif sampler is None:
            d.copy_rows_left -= periods * len(rows)
        else:
            d._feed()  # everything up to the cycle's end first
        batch = max(1, COPY_BATCH // max(len(rows), 1))
        for first in range(1, periods + 1, batch):
            js = range(first, min(first + batch, periods + 1))
            block = [shifted(j) for j in js]
            if sampler is None:
                d.rows.extend(block)
            else:
                sampler.feed(np.vstack(block), np.concatenate([slips + j * period for j in js]))
            d.events.extend((kind, t + j * period, s, v) for j in js for kind, t, s, v in events)
        if sampler is not None and sampler is not d.sampler:
            d.rows.extend(sampler.rows())
        if d.sampler is not None:
            d.slips_fed = len(d.events)  # the copies' slips were given with them
        state.t += periods * period
        state.x += periods * travel
        state.puller += periods * travel
        for _, index in self.TOTALS:
            state.acc[index] += periods * gained[index]
        self.repeated += periods
        self.marks.clear()  # the next settled cycle is judged afresh
        d._report_progress()

    def note(self) -> str:
        if not self.repeated:
            return ""
        thinned = "".join(
            f"; the trace holds {periods} of them as {kept} rows, one every {spacing:.3g} s (and each slip's instant),"
            f" in place of {rows} rows (at most {TRACE_COPY_ROWS:,} copied rows are kept; --every / every sets"
            " the sampling)"
            for periods, spacing, kept, rows in self.driver.thinned
        )
        return (
            f"; {self.repeated} period(s) of the limit cycle repeated, not integrated again: the sticks' stress had"
            " settled within rtol (reduction='auto')" + thinned
        )


#: a slider faster than this many times the protocol's fastest velocity has run away (no inertia holds it)
RUNAWAY = 1e6


def _rested(protocol: Protocol, born: float, t: float) -> float:
    """The time (s) a bond born at ``born`` spent at rest (the protocol's holds, vp = 0) up to t."""
    return float(sum(max(0.0, min(t1, t) - max(t0, born)) for t0, t1, vp in protocol.pieces() if vp == 0))


def _rigid_collapse(state: _State, params: Parameters, aging: bool, protocol: Protocol | None = None) -> str:
    """Why the step collapses under velocity control (no block, nothing to run away), in words for
    :func:`_non_finite`: the loaded cohort nearest the FENE wall, its age, and how fast it dies there.  Its age is
    said as what it was: time at rest (a hold of ``protocol``) or sliding (tester Y: a plain velocity step's bonds
    were said "aged at rest (a hold)" where the protocol had no hold; such a step no longer collapses: section 24).

    A bond aged at rest for a time t_a is held by its aging term A = t_a/tau_a e^(-V/Va) until its force matches it,
    at 1 - (e/dl_m)^2 ~ c/A (c = lambda M dl_m/kT), and dies there within ~ c dl_m/(2 A^2 V): after a hold of 300 s
    at 100 um/s (the gel) ~2e-13 s, below what the clock resolves at t = 300 s (the kernel's floor, 1e-15 t)."""
    b, g = params.bonds, params.aging
    n = state.n
    ext = state.x - state.xb[:n]
    loaded = np.isfinite(state.lw[:n]) & (ext > 0.9 * b.max_extension)
    clock = f"the clock's resolution at t = {state.t:.6g} s (the solver's floor: 1e-15 of the time reached)"
    if not (aging and loaded.any()):
        return f"the bonds' deaths need steps below {clock}"
    i = int(np.flatnonzero(loaded)[np.argmax(ext[loaded])])
    age = float(state.t - state.tb[i])
    v = abs(state.v)
    from .model import aging_age

    strength = float(aging_age(np.asarray(age), params)) / g.aging_time * math.exp(-v / g.aging_velocity)
    c = b.force_sensitivity * b.chain_stiffness * b.max_extension
    rest = _rested(protocol, float(state.tb[i]), float(state.t)) if protocol is not None else 0.0
    aged = f"aged at rest (a hold: {rest:.3g} s of it)" if rest > 0 else "aged while sliding (no hold)"
    words = (
        f"bonds {age:.3g} s old, {aged}, are held by their aging term (t_a/τa e^(-V/Va) ="
        f" {strength:.3g} in ln r) until their force matches it, at 1 − (e/Δl_m)² ≈ {c / strength:.2g},"
        " by the FENE wall"
    )
    if strength > c and v > 0:
        words += f", and die there within about {c * b.max_extension / (2.0 * strength**2 * v):.2g} s of their arrival"
    if rest <= 0:
        return f"{words}: faster than the solver can follow, below {clock}"
    return (
        f"{words}: faster than the solver can follow, below {clock}; a shorter hold stays within it (the"
        " gel's set at 100 µm/s: holds up to ~100 s)"
    )


def _non_finite(
    t: float,
    block: np.ndarray,
    rows: list[np.ndarray],
    pace: float,
    inertial: bool = False,
    step: float = math.nan,
    rigid: str | None = None,
) -> str:
    """The failure in words: a runaway slip (the bonds gave way faster than an inertia-free block can follow).

    ``block``: the kernel's rows of its last call; ``rows``: the trace so far, single rows or blocks of them
    (time, sigma, N, V, X first in both); ``step``: the step size the kernel had come down to.  What decides is
    the kernel's state (its step collapsed, or a recorded velocity past :data:`RUNAWAY` x ``pace``), so that
    the sampling of the rows (``every``) does not change the verdict; the rows only add the last state known.
    Never nan or inf in the words: what is not known is said so.
    """
    recent = [np.atleast_2d(np.asarray(r, dtype=float))[:, :5] for r in (*rows[-2:], block) if np.size(r)]
    table = np.vstack(recent) if recent else np.empty((0, 5))
    finite = table[np.all(np.isfinite(table[:, [0, 1, 3, 4]]), axis=1)] if table.size else table
    when = f"t = {t:.6g} s" if math.isfinite(t) else "an unknown time"
    if finite.size:
        last = finite[np.argmax(finite[:, 0])]
        when += f" (last finite state at t = {last[0]:.6g} s: σ = {last[1]:.6g} Pa, V = {show_velocity(last[3], 3)})"
    collapsed = math.isfinite(step) and math.isfinite(t) and step < COLLAPSED * max(t, 1e-300)
    if inertial:
        what = f"the step collapsed to {step:.3g} s" if collapsed else "non-finite state"
        return f"transient solver failed at {when}: {what} of the block with mass"
    if rigid is not None and collapsed:  # velocity control: the slider's velocity is imposed, nothing runs away
        return (
            f"transient solver failed at {when}: the step down to {step:.3g} s under velocity control (the slider's"
            f" velocity is imposed: no block, nothing runs away): {rigid}; what follows is not known"
        )
    fast = finite[finite[:, 3] > RUNAWAY * max(pace, 1e-300)] if finite.size else finite
    if not (fast.size or collapsed):
        return f"transient solver failed at {when}: non-finite state"
    why = (
        " (a steady start on the unstable branch below Vc does this, and so can sliding faster than Δl_m/τ, where"
        " steady sliding through the block is oscillatory-unstable: transient.critical_stiffness)"
    )
    if fast.size:  # the first row past the bound: what followed is the runaway itself
        seen = f"{fast[0][3]:.3g} m/s under σ = {fast[0][1]:.6g} Pa at t = {fast[0][0]:.6g} s"
        return (
            f"transient solver failed at {when}: the slider ran away, {seen}: the bonds gave way faster than a block"
            f" without inertia can follow, and Eq 1 through the block has no finite slip velocity from there{why};"
            " this solver cannot carry the block through that jump, so what follows (a new stick or sliding) is"
            " not known"
        )
    # the step collapsed with no runaway seen: a runaway and a jump this method cannot resolve look alike here
    # (issue 33.1: an independent solver ends one such case stuck), so the words claim neither
    return (
        f"transient solver failed at {when}: the step down to {step:.3g} s, the bonds gave way faster than the"
        " solver could follow: either the slider runs away (a block without inertia has no finite slip velocity"
        f" past a fold of Eq 1{why}) or the jump is one this method cannot resolve; what follows is not known"
    )


#: a step shorter than this fraction of the time reached has collapsed (the kernel's floor is 1e-15 of it)
COLLAPSED = 1e-12


class SolverFailed(RunFailed):
    """The run started and could not go on (its state went non-finite): a failed run, not bad input."""


def _paced(cohorts: int) -> int:
    """Steps per kernel call: :data:`COHORT_STEPS_PER_CALL` shared by the cohorts (a step over thousands of them
    is slow), within 64..CHUNK; a function of the state alone, so the answer never depends on the machine."""
    return int(min(CHUNK, max(64, COHORT_STEPS_PER_CALL // max(cohorts, 1))))


def _chunk(state: _State, budget: int, reducer: _Reducer | None, pace: int = CHUNK) -> int:
    """Steps the kernel may take in this call: the budget, the pace, the next look for a quasi-steady stretch."""
    steps = min(CHUNK, pace, budget + 1 - int(state.acc[4]))
    if reducer is not None:
        steps = min(steps, int(reducer.next_try - state.acc[4]) if reducer.next_try > state.acc[4] else steps)
    return max(1, steps)


class _Reducer:
    """Switches between the cohorts and the quasi-steady reduction (transient/reduction.py)."""

    FIRST_LOOK = 32  # cohort steps between looks for a quasi-steady stretch, doubled after each miss
    LAST_LOOK = 4096

    def __init__(
        self, params: Parameters, p: np.ndarray, functions: dict, control: str, k_block: float, rtol: float, aging: bool
    ) -> None:
        self.params, self.p, self.functions = params, p, functions
        self.block = control == "block"
        self.k_block, self.rtol, self.aging = k_block, rtol, aging
        self.disturbed_at: float | None = None
        self.next_try = 0.0
        self.interval = self.FIRST_LOOK
        self.steady: dict[float, tuple[float, float, float]] = {}
        self.unbuildable = -math.inf  # the start of the protocol piece where a table could not be built
        self.tables: list[Any] = []  # the steady curve's tables this run has used (reduction.manifold_for)
        self.fold: float | None = None

    def _fold(self) -> float:
        """Vc, the fold of the steady curve (0: none; inf: not found), looked for once."""
        if self.fold is None:
            self.fold = _reduced_from(self.params, "block", self.aging) / FOLD_MARGIN
        return self.fold

    def _steady_at(self, v: float) -> tuple[float, float, float]:
        """(S, N, S') of the steady solver at v, remembered for the run."""
        if v not in self.steady:
            ref = _steady_state(self.params, v, self.aging)
            n0 = self.params.bonds.site_density
            self.steady[v] = (float(ref.stress), float(ref.bonded_fraction) * n0, float(ref.stress_slope))
        return self.steady[v]

    def disturbed(self, t: float) -> None:
        """The population is out of balance from t: no reduction while bonds born before t carry weight."""
        self.disturbed_at = t
        self.interval = self.FIRST_LOOK

    def loaded_steady(self, state: _State) -> None:
        """A steady population was put in (the jump): the cohorts replace it before a reduced stretch."""
        self.disturbed(state.t)
        self.next_try = state.acc[4]

    def _remembers_disturbance(self, state: _State) -> bool:
        """Bonds born before the disturbance still carry more than a hundredth of the reduction's share."""
        if self.disturbed_at is None:
            return False
        n = state.n
        old = state.tb[:n] < self.disturbed_at
        if not old.any():
            self.disturbed_at = None
            return False
        from .reduction import THETA

        w = np.exp(state.lw[:n])
        f = np.abs(chain_force(state.x - state.xb[:n], self.params))
        share = 1e-2 * (THETA * self.rtol)
        if w[old].sum() <= share * w.sum() and (w * f)[old].sum() <= share * (w * f).sum():
            self.disturbed_at = None
            return False
        return True

    def _may_enter(self, s: float, slope: float, sigma: float, v: float, vp: float) -> bool:
        """Whether the state can pass reduction.entry_velocity's first test, |S_eff(v) - sigma| <= THETA rtol |sigma|,
        with the lag C computed at v alone (one steady population, ~1 ms) instead of a table (~30-70 ms): with the
        table's own share of C (LAG_SHARE) and twice the tolerance to spare.  Near the fold a slider slowing past Vc
        asked for tables down to a third of its velocity that no stretch then entered: 3 of the 5 tables of a stiff
        block's first cycle, 0.2 s of its 0.7 s (docs/transient.md section 12)."""
        from . import reduction as R

        lag = R._lag(self.params, v, self.aging)[0]
        accel = self.k_block * (vp - v) / slope
        spare = 2.0 * R.THETA * self.rtol * abs(sigma)
        spare += R.LAG_SHARE * (abs(lag) + slope * self.params.bonds.bond_time) * abs(accel)
        return abs(s + lag * accel - sigma) <= spare

    def _miss(self, state: _State) -> None:
        self.next_try = state.acc[4] + self.interval
        self.interval = min(2 * self.interval, self.LAST_LOOK)

    def attempt(
        self, state: _State, t0: float, t1: float, vp: float, times: np.ndarray, sample_index: int, rows: list
    ) -> tuple[bool, int]:
        if self._remembers_disturbance(state):
            self.next_try = state.acc[4] + self.FIRST_LOOK
            return False, sample_index
        glide = self._glide(state, t0, t1, vp, times, sample_index)
        if glide is None:
            self._miss(state)
            return False, sample_index
        rows.extend(_kernel_rows(glide.rows, self.k_block, "block" if self.block else "velocity"))
        x_entry, t_entry = state.x, state.t
        state.t = glide.t
        state.v = glide.v
        if self.block:
            state.puller = state.puller + vp * (glide.t - t_entry)
            state.x = state.puller - glide.sigma / self.k_block
        else:
            state.x = x_entry + vp * (glide.t - t_entry)
            state.puller = state.x
        # the cohorts again, rebuilt from the steady population (balanced against the block)
        state.load(_steady_cohorts(self.params, glide.v, self.aging, *_rebuilt_cells(self.rtol)))
        if self.block:
            weights = np.exp(state.lw[: state.n])
            state.x = self.functions["_balance_weights"](state.x, state.puller, state.n, state.xb, weights, self.p)
        # the rebuilt cohorts' N and bond energy differ from the reduction's by its tabulation: the difference is
        # booked as broken bonds and dissipated energy, so that both balances stay exact across the switch
        nn, _ss, _k, uu = self.functions["_sums"](state.n, state.xb, state.lw, state.x, self.p)
        state.acc[1] += glide.bonded - nn
        state.acc[3] += glide.energy - uu
        state.h = 1e-2 * self.params.bonds.bond_time
        if glide.done:  # the end of a protocol piece: the next may glide on at once (if its entry check passes)
            self.disturbed_at = None
            self.next_try = state.acc[4]
        else:  # the reduction's error grew past its share: cohorts from here, until they replace the rebuilt bonds
            self.disturbed(state.t)
            self._miss(state)
        return True, glide.sample_index

    def _glide(self, state: _State, t0: float, t1: float, vp: float, times: np.ndarray, sample_index: int):  # type: ignore[no-untyped-def]
        from . import reduction as R

        b = self.params.bonds
        v = state.v if self.block else vp
        if state.n == 0 or not v > 0 or not vp >= 0 or (not self.block and not vp > 0):
            return None
        if self.block and max(v, vp) > BLOCK_FASTEST * b.max_extension / b.bond_time:
            return None  # where sliding through the block may be oscillatory-unstable: the cohorts follow it
        nn, ss, _k, uu = self.functions["_sums"](state.n, state.xb, state.lw, state.x, self.p)
        sigma = self.k_block * (state.puller - state.x) if self.block else ss
        tol = R.THETA * self.rtol
        common = dict(t=state.t, t_end=t1, k_block=self.k_block, block=self.block, acc=state.acc,
                      sample_times=times, sample_index=sample_index)  # fmt: skip
        if vp > 0:
            s_p, n_p, slope_p = self._steady_at(vp)
            # through the block only the rising branch is steady (below Vc a slider leaves it); a rigid rig holds V
            rising = slope_p > 0 or not self.block
            if rising and abs(sigma - s_p) <= tol * abs(sigma) and abs(nn - n_p) <= tol * b.site_density:
                return R.steady_glide(self.params, x=state.x, puller=state.puller, vp=vp, sigma=sigma,
                                      steady=(s_p, n_p, slope_p), bonded=nn, energy=uu, **common)  # fmt: skip
        if not self.block:
            return None
        # the table spans the velocities ahead (down to a third of v at most: a stretch ending at its edge is
        # taken up again by a new table) and three times the fastest, for the jumps of later cycles
        lo = max(min(v, vp), v / 3.0) * 0.99
        hi = max(v, vp) * 1.01
        m = R.manifold_for(self.params, self.aging, lo, hi, 3.0 * hi, self.rtol, self.tables, build=False)
        if m is None:  # worth building only where the state is near the steady curve's rising branch
            if self.unbuildable >= t0:
                return None
            # below Vc the falling branch: no table (and no costly steady_state for each short piece); with saturating
            # aging the curve is N-shaped and its creep branch, below the maximum, rises (a stuck block creeps up it)
            if v < self._fold() and self.params.aging.saturation_age is None:
                return None
            ref = _steady_state(self.params, v, self.aging)
            if not (float(ref.stress_slope) > 0 and abs(sigma - float(ref.stress)) <= 0.1 * abs(sigma)):
                return None
            if not self._may_enter(float(ref.stress), float(ref.stress_slope), sigma, v, vp):
                return None
            m = R.manifold_for(self.params, self.aging, lo, hi, 3.0 * hi, self.rtol, self.tables)
            if m is None:  # the steady curve cannot be tabulated here to its share of rtol: cohorts for this piece
                self.unbuildable = t0
                return None
        v_entry = R.entry_velocity(m, sigma, v, vp, self.k_block, self.rtol)
        if v_entry is None:
            return None
        # the bonded count on the manifold, with its own lag: a stiff block decelerates fast enough that N trails
        # the steady N(V) by 3e-5 to 1e-4 of N0 in its slips (docs/transient.md section 10)
        n_entry = float(R.effective_bonded(m, v_entry, vp, self.k_block)) * b.site_density
        if abs(nn - n_entry) > tol * b.site_density:
            return None
        return R.glide(m, self.params, v=v_entry, x=state.x, puller=state.puller, vp=vp, rtol=self.rtol, bonded=nn,
                       energy=uu, **common)  # fmt: skip


def _steady_state(params: Parameters, velocity: float, aging: bool) -> Any:
    """The steady solver at one velocity, its march compiled: the reduction's checks ask for S, N and S' at the
    puller's and the slider's velocity ~4 times a stick-slip cycle, 2.3-3.3 ms each through numpy's march against
    0.1-0.6 ms compiled (its load from numba's cache, ~25 ms, once per process; the two agree to ~1e-12,
    docs/transient.md section 14)."""
    from ..quasistatic.steady import steady_state

    return steady_state(params, velocity, aging, compiled_from=1)


_STEADY_COHORTS: dict[tuple[Parameters, float, bool], Population] = {}


#: a steady population rebuilt within a run (a glide's end, the paper's jump) takes cells up to this many times
#: coarser than the steady start's (model.CELL_HAZARD in hazard, dl_m/V / 1000 in age): see :func:`_rebuilt_cells`
REBUILT_COARSEST = 10.0
#: the relative error of a re-slide's peak after a hold of a rebuilt population, per squared coarsening (measured:
#: tests/test_transient_speed.py's slide-hold-slide, coarsening 4, 6, 10: 2.5e-5, 7.0e-5, 1.9e-4)
REBUILT_PEAK_ERROR = 1.9e-6


def _rebuilt_cells(rtol: float) -> tuple[float, float]:
    """(cell hazard, least cells over dl_m/V) of a steady population rebuilt within a run (docs/transient.md
    section 13).  The steady start's resolution (CELL_HAZARD = 0.05, cells of dl_m/V / 1000 where the hazard is
    low) is ~10x finer in age than the cohorts' own births at the steps of a fold passage: the ~2 800 cohorts rebuilt
    at a glide's end, most living for tens of steps, were a third of the passage's CPU.  Coarser cells by a factor c
    move what the rebuilt bonds do later at second order in the cells' width (each cohort carries its cell's bonds
    to the FENE wall as one: the peak re-sliding after a hold moved by REBUILT_PEAK_ERROR c^2), so c is held where
    that is the reduction's share of the tolerance, THETA rtol, and at most REBUILT_COARSEST."""
    from .model import CELL_HAZARD
    from .reduction import THETA

    coarsening = min(max(math.sqrt(THETA * rtol / REBUILT_PEAK_ERROR), 1.0), REBUILT_COARSEST)
    return CELL_HAZARD * coarsening, 1000.0 / coarsening


def _steady_cohorts(
    params: Parameters,
    velocity: float,
    aging: bool,
    cell_hazard: float = 0.05,
    cells_least: float = 1000.0,
    reach: float = 0.0,
    ripple: float = 0.0,
) -> Population:
    """steady_population, remembered (a steady run starts and ends on the same one); ``reach`` and ``ripple``: its
    cells cut ahead of the FENE cliff (cells.steady_cohorts, the steady start: docs/transient.md section 18)."""
    from ..quasistatic.jump import steady_curve_key

    key = (steady_curve_key(params), float(velocity), bool(aging), cell_hazard, cells_least, reach, ripple)
    if key not in _STEADY_COHORTS:
        if len(_STEADY_COHORTS) > 16:
            _STEADY_COHORTS.clear()
        from .cells import steady_cohorts

        _STEADY_COHORTS[key] = steady_cohorts(params, velocity, aging, cell_hazard, cells_least, reach, ripple)
    return _STEADY_COHORTS[key]


def _start_reach(
    params: Parameters, protocol: Protocol, velocity: float, aging: bool, control: str, k_block: float, held: bool
) -> float:
    """The ages (s, at the steady start's ``velocity``) through which the run may carry the start's cohorts: the
    slider's travel over the protocol (through the block the puller's plus the spring's release of the start's
    stress; ``held``: from the first piece at another velocity on), at most dl_m, over ``velocity``."""
    b = params.bonds
    pieces = list(protocol.pieces())
    if held:
        while pieces and pieces[0][2] == velocity:
            pieces.pop(0)
    travel = float(sum(abs(vp) * (t1 - t0) for t0, t1, vp in pieces))
    if control == "block":
        travel += abs(float(_steady_state(params, velocity, aging).stress)) / k_block
    return min(travel, b.max_extension) / velocity


def _critical_velocity(params: Parameters, aging: bool) -> float:
    """Vc (m/s) of Eq 9, the aging steady curve's minimum, as a steady start below Vc reads it (``critical_minimum``,
    remembered per curve); NaN without aging (that curve has no minimum) or where the curve has none."""
    from ..quasistatic.critical import critical_minimum

    if not aging:
        return math.nan
    try:
        found = critical_minimum(params)
    except (ModelError, ParameterError):
        return math.nan
    return math.nan if found is None else float(found.velocity)


def _steady_reference(d: Any) -> Any:
    """The steady state at the last segment's pace (cycles.SteadyReference), against which a run whose stick chains'
    last event is a slip is judged settled after it; None where there is none to judge (no chains, no slip in the
    last segment, the puller held, or the steady solver cannot give it)."""
    from .cycles import SteadyReference, steady_instability

    start = float(d.protocol.boundaries[-2])
    vp = float(d.protocol.segments[-1].velocity)
    slipped = any(kind == "slip" and t >= start for kind, t, *_ in d.events)
    if not (d.stick_population and d.control == "block" and vp > 0 and slipped):
        return None
    try:
        found = _steady_state(d.params, vp, d.aging)
    except (ModelError, ParameterError):  # beyond the steady population's range: no steady state to settle to
        return None
    stress, slope = float(np.ravel(found.stress)[0]), float(np.ravel(found.stress_slope)[0])
    if not (math.isfinite(stress) and math.isfinite(slope)):
        return None
    memory = float(d.params.bonds.max_extension) / vp
    grid = d.sampler.grid if d.sampler is not None else np.asarray(d.times)  # ``every``'s grid (none: no grid)
    every = float(grid[1] - grid[0]) if grid.size > 1 else None
    # where the slide has not settled, and only then: is steady sliding at vp unstable for this block (below Vc,
    # K < Kc)?  Only a velocity-weakening steady curve (dσ/dV < 0) can be: Kc = 0 above Vc
    params, k_block, mass, damping, aging = d.params, float(d.k_block), float(d.mass), float(d.damping), d.aging

    def instability() -> str | None:
        vc = _critical_velocity(params, aging)
        return steady_instability(params, vp, k_block, mass, damping, aging, vc)

    return SteadyReference(vp, stress, slope, k_block, memory, every, instability if slope < 0 else None)


def _chains_ahead(d: Any, regime: str, message: str, time: np.ndarray, sigma: np.ndarray) -> tuple[str, str]:
    """A run that ends with the stick chains holding is stuck only if they would hold on: where Eq 15 has them
    collapse later under the same loading it is undetermined, saying when; where it proves they never do, stuck
    says so."""
    if regime != "stuck" or not d.chains_on:
        return regime, message
    due, never = d.chains_ahead
    held_on = False
    if due is None and not never:  # aged chains (a stick begun under another pace): follow Eq 15 on from the end
        due, held_on = _aged_chains_ahead(d, float(time[-1]), float(sigma[-1]))
    if due is not None and due[0] > float(time[-1]):
        return "undetermined", (
            f"undetermined: stuck to the end of the run (t = {time[-1]:.6g} s, σ = {sigma[-1]:.6g} Pa), the stick"
            f" chains holding; under this loading they collapse at t = {due[0]:.6g} s (σs = {due[1]:.6g} Pa, Eq 15),"
            " after the run's end: run longer to see the slip"
        )
    if never:
        return regime, message + "; Eq 15 proves the chains never collapse under this loading"
    if held_on:
        horizon = CHAINS_HORIZON * float(d.params.stick.aging_time)
        return regime, message + (
            f"; under this loading Eq 15 has them hold for {CHAINS_HORIZON:g} of their aging times ({horizon:.3g} s)"
            " more at least"
        )
    return regime, message


#: Eq 15 is followed past the run's end for at most this many of the stick's aging times
CHAINS_HORIZON = 1e4


def _aged_chains_ahead(d: Any, end: float, sigma_end: float) -> tuple[tuple[float, float] | None, bool]:
    """When chains that aged under other paces collapse under the last pace's loading, from their exact state at
    the run's end (their age and fraction): ((t, σs), False), or (None, True) where they hold for CHAINS_HORIZON
    aging times (the solver's own stick stretches look ahead only for fresh chains, quasistatic.stick)."""
    pace = max(float(d.protocol.velocity_at(np.nextafter(end, -np.inf))), 0.0)  # (held: the stress stays)
    chain = d.chain_state
    horizon = CHAINS_HORIZON * float(d.params.stick.aging_time)
    ahead = stick_chains(d.params, d.aging, sigma_end, d.k_block * pace, chain["elapsed"], chain["fraction"], horizon)
    if not ahead.collapsed:
        return None, True
    return (end + ahead.duration, sigma_end + d.k_block * pace * ahead.duration), False


def _scratch(state: _State) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Work arrays of kernel._slider_velocity (no weight known beforehand: the third, all -1)."""
    return np.empty(state.xb.size), np.empty(state.xb.size), np.full((3, state.xb.size), -1.0)


def _row(
    state: _State, params: Parameters, control: str, k_block: float, mass: float = 0.0, sigma: float | None = None
) -> np.ndarray:
    """The trace's row of ``state`` (``sigma``: the stress where known otherwise than from the bonds' sum)."""
    pop = state.population()
    f = chain_force(pop.extension, params)
    if sigma is None:
        sigma = float(pop.weight @ f)
    block_energy = sigma * sigma / (2 * k_block) if control == "block" else 0.0
    if mass > 0:  # the spring's own stretch, and the moving block's kinetic energy
        block_energy = 0.5 * k_block * (state.puller - state.x) ** 2 + 0.5 * mass * state.v**2
    b = params.bonds
    y = pop.extension / b.max_extension
    energy = float(pop.weight @ (-0.5 * b.chain_stiffness * b.max_extension**2 * np.log1p(-y * y)))
    acc = state.acc
    extremes = _closing_extremes(acc, state.t, sigma, state.v)
    _extremes_reset(acc)  # this row closes the stretch of steps it summarises
    return np.array(
        [state.t, sigma, pop.bonded, state.v, state.x, state.puller, acc[0], acc[1], acc[2], acc[3], energy,
         block_energy, np.nan, acc[6], *extremes]
    )  # fmt: skip


def _closing_extremes(acc: np.ndarray, t: float, sigma: float, v: float) -> tuple[float, float, float, float, float]:
    """(lowest, highest stress, lowest's time, highest's time, fastest V) of a row at (t, sigma, v) closing the
    steps in ``acc`` (as kernel._write_row: the row's own time unless a step went beyond the row)."""
    return (
        min(acc[7], sigma),
        max(acc[8], sigma),
        acc[9] if acc[7] < sigma else t,
        acc[10] if acc[8] > sigma else t,
        max(acc[11], v),
    )


def _extremes_reset(acc: np.ndarray) -> None:
    """No step since the last row (kernel.ACC_START's extremes)."""
    acc[7:12] = K.ACC_START[7:12]


def _extremes_at(acc: np.ndarray, t: float, sigma: float) -> None:
    """A state at (t, sigma) between rows into the extremes since the last row (the earlier time on a tie)."""
    if sigma < acc[7]:
        acc[7], acc[9] = sigma, t
    if sigma > acc[8]:
        acc[8], acc[10] = sigma, t


def _stuck_rows(state: _State, vp: float, k_block: float, t: np.ndarray, fraction: np.ndarray) -> np.ndarray:
    """The trace's rows at times ``t`` of a stretch stuck from state.t (chain fractions ``fraction`` there): the
    slider held, sigma = K (P - X) exact.  One array for the stretch (a row at a time cost ~7 us each, ~3 ms of the
    paper's cycle)."""
    dt = t - state.t
    puller = state.puller + vp * dt
    sigma = k_block * (puller - state.x)
    acc = state.acc
    rows = np.full((t.size, 19), np.nan)
    rows[:, 0], rows[:, 1], rows[:, 3], rows[:, 4], rows[:, 5] = t, sigma, 0.0, state.x, puller
    rows[:, 6], rows[:, 7], rows[:, 11], rows[:, 12] = acc[0], acc[1], sigma * sigma / (2 * k_block), fraction
    rows[:, 13] = acc[6] + _stuck_impulse(state, vp, k_block, dt)
    start = k_block * (state.puller - state.x)
    rows[:, 14] = np.minimum(min(acc[7], start), sigma)
    # each row's highest is its own stress (sigma rises), the first's also the steps before the stretch
    rows[:, 15], rows[:, 17], rows[:, 18] = sigma, t, 0.0
    if acc[8] > sigma[0]:
        rows[0, 15], rows[0, 17] = acc[8], acc[10]
    rows[0, 18] = max(acc[11], 0.0)
    rows[:, 16] = np.where(rows[:, 14] < sigma, acc[9] if acc[7] < start else state.t, t)
    return rows


def _stuck_impulse(state: _State, vp: float, k_block: float, dt: Any) -> Any:
    """The integral of sigma = K (P - X) over dt from state.t with the slider held (exact: sigma is linear)."""
    return k_block * ((state.puller - state.x) * dt + 0.5 * vp * dt * dt)


def _kernel_rows(block: np.ndarray, k_block: float, control: str, mass: float = 0.0) -> list[np.ndarray]:
    sigma = block[:, 1]
    block_energy = sigma**2 / (2 * k_block) if control == "block" else np.zeros_like(sigma)
    if mass > 0:  # sigma is the interface's: the spring's stretch P - X, and the kinetic energy
        block_energy = 0.5 * k_block * (block[:, 5] - block[:, 4]) ** 2 + 0.5 * mass * block[:, 3] ** 2
    full = np.empty((sigma.size, 19))  # (np.c_ took ~80 us a call, ~2 ms of the paper's cycle)
    full[:, :11], full[:, 11], full[:, 12], full[:, 13:] = block[:, :11], block_energy, np.nan, block[:, 11:]
    return [full]


def _snapshot(state: _State) -> Snapshot:
    pop = state.population()
    return Snapshot(state.t, pop.age.copy(), pop.extension.copy(), pop.weight.copy())


def _finish(d: _Driver, snapshots: list[Snapshot], stop: str | None, note: str) -> TransientResult:
    """The result of run ``d`` so far: its rows sorted by time, cycles and regime (``stop``: why it ended early)."""
    from .cycles import Between, detect_cycles, judge

    params, protocol, control, k_block, mass, events = d.params, d.protocol, d.control, d.k_block, d.mass, d.events
    table = np.vstack([np.atleast_2d(r) for r in d.trace_rows()])
    order = np.argsort(table[:, 0], kind="stable")
    table = table[order]
    keep = np.r_[True, np.diff(table[:, 0]) > 0]
    doubled = table[~keep, 0]  # instants of two rows (a jump's), where no peak is located across
    table = table[keep]
    if control == "velocity" and d.sampler is None:  # (a sampler's rows were balanced as they came: _Driver._balanced)
        _balanced_integral(table, protocol)
    if d.sampler is None:  # the stress's peaks between rows, into their highest (a sampler's located as they came)
        locate_peaks(
            table, 1, table.shape[0], k_block=k_block, known_rate=control != "velocity" and mass == 0,
            breaks=np.unique(np.asarray(protocol.boundaries[1:-1], dtype=float)),
            events=np.r_[[e[1] for e in events if e[0] == "slip"], [j.time for j in d.jumps], doubled],
        )  # fmt: skip
    n0 = params.bonds.site_density
    time, sigma, bonded, v, x, puller = (table[:, k] for k in range(6))
    bonded = bonded / n0
    bonded = np.where(np.isnan(bonded), 0.0, bonded)  # the bonds of Eq 1 are set aside while the chains hold
    # the slopes K (Vp - V) of sigma place each peak between rows: a massless block's spring carries sigma
    slope = k_block if control == "block" and mass == 0 else None
    # each row's extremes of the solver's steps since the row before (lowest, highest, their times, fastest V):
    # the summary's, whatever rows ``every`` kept
    between = Between(*(table[:, k] for k in range(14, 19)))
    cycles = detect_cycles(
        time, sigma, v, protocol, events, lowest=table[:, 14], stiffness=slope, between=between,
        jumps=[j.time for j in d.jumps],
    )  # fmt: skip
    regime, message, evidence = judge(
        time, sigma, v, protocol, cycles, events, control, stop, resolution=d.rtol, lowest=table[:, 14],
        between=between, steady=_steady_reference(d) if stop is None else None,
        since_slip=d.sampler.since_last_slip() if d.sampler is not None else None,
    )  # fmt: skip
    regime, message = _chains_ahead(d, regime, message, time, sigma)
    message = message + note
    saturating = params.aging.saturation_age is not None  # the extension lets go: its stuck is its own answer
    # a rig holds the slider, or nothing ever pulls it: the chains would change nothing there
    held = control == "velocity" or not np.any(protocol.velocities > 0)
    if (
        regime == "stuck"
        and not cycles
        and not any(kind == "stick" for kind, *_ in events)
        and not (saturating or held)
    ):
        message += (
            "; one population of Eq 1 never lets go: its aging term makes a resting bond unbreakable within"
            " milliseconds (docs/transient.md section 7); to let the paper's stick chains (Eqs 13-16) end it, with"
            " its stick-slip cycle, run with --stick-population (with `run --model transient`: --setting"
            " stick_population=true; in Python: stick_population=True)"
        )
    chain = table[:, 12] if d.chain_rows else None
    book = Bookkeeping(
        born=table[:, 6], broken=table[:, 7], work=table[:, 8], dissipation=table[:, 9], bond_energy=table[:, 10],
        block_energy=table[:, 11], stress_integral=table[:, 13],
    )  # fmt: skip
    lowest = table[:, 14]
    return TransientResult(
        time=time,
        stress=sigma,
        bonded_fraction=bonded,
        slider_velocity=v,
        slider_position=x,
        puller_position=puller,
        regime=regime,
        cycles=cycles,
        message=message,
        control=control,
        stiffness=k_block,
        snapshots=tuple(snapshots),
        bookkeeping=book,
        chain_fraction=chain,
        steps=int(d.state.acc[4]),
        rejected=int(d.state.acc[5]),
        lowest_stress=lowest,
        highest_stress=table[:, 15],
        lowest_time=table[:, 16],
        highest_time=table[:, 17],
        fastest_velocity=table[:, 18],
        mass=mass,
        damping=d.damping,
        evidence=evidence,
        status="ok" if stop is None else "failed",  # the model could not go on to the protocol's end
        critical_velocity=_critical_velocity(d.params, d.aging),
    )


#: velocity control: the integral of sigma dt between rows from the energy balance where the energy the breaking
#: bonds lost is within this share of the energy stored (solver._balanced_integral)
BALANCE_SHARE = 1e-3


def _balanced_integral(
    table: np.ndarray, protocol: Protocol, carried: tuple[float, float] = (0.0, 0.0)
) -> tuple[float, float]:
    """Velocity control: the integral of sigma dt (and the rig's work) between rows from the energy balance,
    V (integral of sigma dt) = change of the bonds' FENE energy + the energy lost as they broke, wherever the rows
    lie in one segment at a constant pace V > 0 with Eq 1's bonds holding and hardly breaking (in place, columns
    8 and 13).

    The kernel's end-corrected trapezoid is the integral of the cubic through each step's ends and slopes; a step
    the state's error control lets grow long (0.1 um/s for 10 s: one 6 s step from 5.7 to 88.3 kPa near the FENE
    wall) made it overshoot to a negative mean (-5634 Pa, 13931 Pa with rows every 0.5 s); the balance's ends are
    the states themselves, exact at any step where the bonds hardly break (energy lost within BALANCE_SHARE of the
    energy stored): 13940.479 Pa at every sampling (docs/transient.md section 9).

    ``carried``: the corrections (balanced less the solver's) of columns 13 and 8 at the first row, from the rows
    before it; returns those at the last row.  The corrections add up row by row (one running sum), so rows balanced
    a block at a time (_Driver._balanced, with ``every``) get the numbers of the whole trace at once, to the bit; a
    trace without a balanced pair keeps the solver's columns as they are."""
    t = table[:, 0]
    if t.size < 2:
        return carried
    bounds = protocol.boundaries
    tol = 1e-12 * max(float(bounds[-1]), 1.0)
    k = np.clip(np.searchsorted(bounds, 0.5 * (t[1:] + t[:-1]), side="right") - 1, 0, len(protocol.segments) - 1)
    vp = np.asarray(protocol.velocities, dtype=float)[k]
    one_segment = (t[:-1] >= bounds[k] - tol) & (t[1:] <= bounds[k + 1] + tol)
    bonds = ~np.isfinite(table[:, 12])  # rows the stick chains do not hold
    stored, lost = np.diff(table[:, 10]), np.diff(table[:, 9])  # the bonds' energy, and what broke with them
    # the energy lost is a quadrature over the breakage (a velocity step at rtol 1e-4: 3e-5 of the integral off,
    # against the trapezoid's 4e-7): the balance only where little broke, exact there
    quiet = np.abs(lost) <= BALANCE_SHARE * np.abs(stored)
    use = one_segment & (vp > 0) & bonds[:-1] & bonds[1:] & quiet
    gain = stored + lost
    out = []
    for column, increment, start in ((13, gain / np.where(use, vp, 1.0), carried[0]), (8, gain, carried[1])):
        change = np.where(use, increment - np.diff(table[:, column]), 0.0)
        correction = np.cumsum(np.r_[start, change])  # (sequential: the same sums, whatever the blocks)
        table[:, column] += correction
        out.append(float(correction[-1]))
    return out[0], out[1]


def _jumps_note(jumps: list[jump.Jump]) -> str:
    """The jumps of the run in words (the first in full, and how many more)."""
    if not jumps:
        return ""
    more = f"; {len(jumps) - 1} more jump(s) followed" if len(jumps) > 1 else ""
    return f"; {jumps[0].describe()}{more}"


def _births_never_held(protocol: Protocol, stick_population: bool) -> bool:
    """No bond of Eq 1 born sliding is held and slid again: with the stick chains under a puller that never stops,
    every stop of the slider is a stick, where those bonds are set aside (the chains hold it, and the slip after
    lands on the steady population of its jump).  A puller at rest lets the slider creep to a stop on them."""
    return stick_population and bool(np.all(protocol.velocities > 0))


#: the softest block against the bonds' N0 M: at the paper's set the stuck block's sigma = K V0 t was off by 1.1e-6
#: at K = 3e-15 N0 M, 3.7e-6 at 3e-17, 2.6e-4 at 3e-19 and 2.6e-2 at 3e-21 (the chains' stretch lost in the slider's
#: travel): refused below 1e-16
PINNED = 1e-16
#: the largest stress scale N0 M dl_m (Pa) the kernel's sums hold: the paper's set ran under velocity control to
#: N0 = 1e300 (scale 1e290 Pa), and at 1e308 stopped with "non-finite state" (exit 3); a gel's is ~1e4 Pa
MOST_STRESS = 1e295
#: the smallest: at N0 = 1e-300 m^-2 (scale 1e-310 Pa) sigma went subnormal and the step collapsed; 1e-192 Pa ran
LEAST_STRESS = 1e-250
#: the weakest FENE strength a = lambda M dl_m / kT the cohorts follow to the FENE wall: the paper's set at 50 um/s
#: under velocity control crossed it at a = 1.05e-9 (slowly: 12 256 steps in 15 s of CPU for 0.023 s) and the step
#: collapsed there at 1.05e-11 (exit 3); the README's box starts at 2.5e-6
WEAKEST_FENE = 1e-6
#: the largest block mass (kg/m^2): a fuzz's 1e300 overflowed the trapezoid's Newton slope 2 m/h (exit 3, "the step
#: collapsed"); 1e12 already runs almost as an infinite mass (at 50 um/s its velocity 5e-5 below V0 after 1 s)
MAX_MASS = 1e30
#: the largest damping (Pa s/m): where eta V0 dwarfs sigma by ~1e12 the force balance K (P - X) - eta V - sigma has no
#: digits left for sigma; 1e20 at 50 um/s never finished 0.01 s, 1e16 ran it in 1.5 s
MAX_DAMPING = 1e12


def _block_inertia(mass: Any, damping: Any, control: str, stick_population: bool) -> tuple[float, float]:
    """(m, eta) of the block, checked: non-negative and finite; a damping only with a mass; neither under
    velocity control, nor with the paper's attached chains (whose jump the mass would resolve instead)."""
    m, eta = (
        0.0 if value is None else checked_number(name, _finite(value, name), unit)
        for value, name, unit in ((mass, "mass", "kg/m^2"), (damping, "damping", "Pa s/m"))
    )
    for value, name, unit, limit, why in (
        (m, "mass", "kg/m^2", MAX_MASS, "from 1e12 kg/m^2 on the block already keeps its velocity over a run"),
        (eta, "damping", "Pa s/m", MAX_DAMPING, "a rock's radiation damping G/(2 c_s) is ~5e6 Pa s/m"),
    ):
        if value > limit:
            raise ParameterError(f"{name}: {value:g} {unit} is out of range; expected at most {limit:g} {unit} ({why})")
    if (m > 0 or eta > 0) and control != "block":
        raise ParameterError("mass/damping: a rigid rig (control='velocity') has no block; use control='block'")
    if eta > 0 and m == 0:
        raise ParameterError(
            "damping: the time-dependent model takes a damping only with a block mass (mass > 0 kg/m^2);"
            " the gel block's own is about 10 kg/m^2 (docs/extensions.md section 4)"
        )
    if m > 0 and stick_population:
        raise ParameterError(
            "mass: the paper's attached chains (stick_population) impose the jump that a block with mass resolves;"
            " use one or the other"
        )
    return m, eta


def _finite(value: Any, name: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: expected a number (SI), got {value!r}") from None
    if not math.isfinite(number):
        raise ParameterError(f"{name}: expected a finite number (SI), got {value!r}")
    return number


def _travel(protocol: Protocol) -> float:
    return float(sum(abs(vp) * (t1 - t0) for t0, t1, vp in protocol.pieces()))


def _require_finite_chains(
    params: Parameters, protocol: Protocol, control: str, start: str, start_velocity: float | None, k_block: float
) -> None:
    """With lambda = 0 a sliding chain is only stopped by the FENE wall, where Eq 3's force is infinite; with a FENE
    strength a = lambda M dl_m / kT below :data:`WEAKEST_FENE` the cohorts cannot follow it there."""
    b = params.bonds
    strength = b.stretch_sensitivity * b.max_extension
    if strength >= WEAKEST_FENE:
        return
    reach = _travel(protocol)
    if not (start == "steady" or reach >= b.max_extension):
        return
    travel = "" if start == "steady" else f" (the slider may travel {reach:.3g} m, Δl_m is {b.max_extension:.3g} m)"
    if b.activation_length == 0.0:
        raise ModelError(
            "bonds.activation_length = 0: sliding bonds survive to full extension, where the FENE force (Eq 3) is"
            " infinite, so the stress diverges (as in the steady solver); use a positive activation length" + travel
        )
    raise ModelError(
        f"the bonds' FENE strength a = λ M Δl_m/kT = {strength:.3g} is below {WEAKEST_FENE:g}: the chain force hardly"
        " speeds a sliding bond's breaking, so bonds reach full extension, where the time-dependent model cannot"
        " follow them; expected a larger bonds.activation_length, chain_stiffness or max_extension" + travel
    )


def _require_steady_range(params: Parameters, protocol: Protocol, aging: bool, start_velocity: float | None) -> None:
    """The steady model's floating-point range (its FENE strength and aging rate below 1e200) at every velocity the
    run is driven at: the steady start, the reduction and the cost estimate use that model, and outside it a run
    was refused part-way, failed at its first step (a steady start: "non-finite state"), or, with a block mass,
    rang against bonds that never break until its time budget ran out (aging.aging_time = 1e-300 s)."""
    from ..quasistatic.steady import check_steady_range

    driven = [abs(float(v)) for v in protocol.velocities if v != 0.0]
    if start_velocity:
        driven.append(abs(start_velocity))
    if driven:
        check_steady_range(params, driven, aging)


def _steady_start_below_vc(
    params: Parameters, protocol: Protocol, start_velocity: float | None
) -> tuple[float | None, str]:
    """(start velocity, note): below Vc the default steady start moves to the stable side of the critical point."""
    from ..quasistatic.critical import critical_minimum

    v_start = protocol.initial_velocity if start_velocity is None else start_velocity
    if not v_start > 0:
        return start_velocity, ""
    try:
        # Vc and sigma_c alone, once per steady curve: half the search of the whole point (issue 31), which a
        # jump later completes without solving them again (quasistatic.critical remembers the search's parts)
        cp = critical_minimum(params)
    except (ModelError, ParameterError):
        return start_velocity, ""
    if cp is None or v_start >= cp.velocity:
        return start_velocity, ""
    start_shown, vc_shown = velocities_apart(v_start, cp.velocity)
    if start_velocity is not None:
        return start_velocity, (
            f" (steady start at {start_shown}, below Vc = {vc_shown}: on the"
            " unstable branch of the steady curve unless the block is stiffer than Kc(V), transient.critical_stiffness)"
        )
    v_stable = cp.velocity * (1.0 + STABLE_SIDE)
    return v_stable, (
        f" (steady start: {start_shown} is below Vc = {vc_shown}, where steady"
        " sliding is unstable,"
        f" so the run starts on the stable side of the critical point, sliding at Vc under σc ="
        f" {cp.stress:.6g} Pa; give start_velocity / --start-velocity to start elsewhere)"
    )


#: a block stiffer than this many times the interface stiffness N0 M is rigid (sigma = K (P - X) loses its digits)
RIGID = 1e6
#: a steady start below Vc starts this fraction above Vc (the stable side; sigma within ~1e-6 of sigma_c)
STABLE_SIDE = 1e-3
#: CPU of one step (s; 55-160 us measured on this 2-core machine), and what one protocol segment costs in steps
STEP_SECONDS = 100e-6
#: CPU of a row copied from a repeated limit cycle (s; the rows are the run's steps, counted against max_steps)
ROW_SECONDS = 1e-6
#: CPU of a sampled row (``every``), written out (s): 100 um/s for 60 s with the chains every 200 us, 3e5 rows,
#: cost 3.3 s more than unsampled (11 us a row), and ~870 bytes a row; every 20 us (3e6 rows) was estimated at 5 min
#: (a step's CPU a row) and took 39 s, 2.7 GB
SAMPLE_SECONDS = 1.1e-5
SAMPLE_BYTES = 870
#: the most rows ``every`` may ask for: ~4 GB held until the trace is written
MAX_SAMPLES = 5_000_000
SEGMENT_STEPS = 10.0
#: CPU of a segment's start through the block with the reduction (its look for a stretch; 19 ms measured for
#: 1000 segments of 1 ms at 350/400 um/s), a tenth of that otherwise
SEGMENT_SECONDS = 0.02
#: CPU per step and cohort (s): a block stuck for good keeps every cohort it bears, its run costs ~ this x steps^2
#: (1000 segments of 1 ms from rest: 3291 steps, 7 s; one segment: 2409 steps, 1.5-2 s; measured on the kernel of
#: issue 31's start: the kernel now takes 1.25 s, 3.16 s for 3000 segments and 0.39 s for one, ~1.2e-7 s per cohort
#: and step, but this count is the default runs' estimate too, and tests hold refusals on it: docs/transient.md 2a)
COHORT_SECONDS = 5e-7
#: with the paper's attached chains a stuck block is their closed form: a stick-slip cycle costs the steps of its
#: slip and re-stick, measured 3100-5550 from 30 to 120 um/s (gel, K = 3.06e5 Pa/m, rtol 1e-4); a stiffer block
#: no more since its slips glide on the reduction (the bonded count's own lag, issue 31: ~2100 per slip at
#: K = 3.06e6 Pa/m, where 16 500-21 000 at 4e6 had been counted in proportion to K)
SLIP_STEPS = 4000.0
#: a piece whose limit cycle is repeated (_Repeater) integrates about this many slips: two to settle after its
#: first, the one it is judged on, and the last period or two before its end
REPEAT_SLIPS = 5.0
#: with the stick chains under a moving puller the births' spacing is bounded by their own Gauss error
#: (kernel._relaxed_births): a slip and its re-stick take this share of the steps (measured 0.37-0.38: the paper's
#: cycle 3027 against 8224 steps, 100 um/s from rest for 40 s 1663 against 4375)
RELAXED_SHARE = 0.37
#: a slider sliding into a piece below the fold decelerates to its stick in about this many steps (1454-1491
#: from a steady start, with the chains)
STOP_STEPS = 1500.0
#: the block's own motion is counted at no fewer steps than the cohorts' over this many bond times (for the gel,
#: ~40: never binding; for a set whose births outpace any step, the cohorts' count)
FORMING = 10.0
#: through the block the slider slides only part of the time (a stuck block takes long steps): measured 0.04-0.4
#: of the velocity-control estimate (350 um/s sliding steadily: 0.42; 350 -> 50 um/s with the chains: 0.04)
BLOCK_SHARE = 0.4
#: with the quasi-steady reduction a piece is cohorts until the bonds born before its start are gone (at most the
#: travel dl_m, where the FENE wall breaks them), for SETTLE such memories (the looks for a stretch double their
#: interval after each miss), then a reduced stretch of about REDUCED_STEPS ODE steps
SETTLE = 4.0
REDUCED_STEPS = 100.0
#: a bond's memory for the settling above is the age beyond which the steady population keeps less than the
#: reduction's share THETA rtol of its bonds and of its stress, at most dl_m/V (bonds that die in a few tau leave
#: the population in a few tau: tau = 1 ns at 50 um/s, 13 ns, where dl_m/V = 21 ms was counted, 8e7 steps for 10 ms)
#: Bonds that age into permanence live to the FENE wall and die there within ~1/g of their arrival (g: the climb of
#: ln r there, 1e6/s at 1 um/s for the gel, 9.4e4/s at 10 um/s): once they arrive the cohorts take about WALL_SHARE g
#: steps per second more (measured 0.23-0.38 g from 1 to 30 um/s under velocity control, 2.5e5 steps/s at 1 um/s)
WALL_SHARE = 0.3
#: a steady population not disturbed (a steady start under velocity control, at its own velocity) meets the wall
#: smoothly: its cohorts take about WALL_STEADY g steps per second more (measured, total steps over the first
#: memory less the births' count: 0.08 g at 3.5 um/s, 0.1 g at 10 um/s, ~0.004 g at 1 um/s; the tester's 3.5 um/s
#: for 1 s, 18 913 steps and 33 s of CPU, had been estimated at 7.4e4 steps and 13.9 min)
WALL_STEADY = 0.08
#: but the wall's steps are the loaded cohorts' arrivals there, each landed on in a few steps (kernel.WALL_LANDING
#: ends a step at 0.9 of the gap to the next: ~log10(g h) steps), not g a second: over the first memory dl_m/V of a
#: piece the population it starts with arrives (the steady start's ~2 000 cohorts, two per cell of at most
#: dl_m/V/1000: about WALL_ARRIVALS steps over that memory), then the run's own births, at most WALL_ECHO steps per
#: step that bore them.  g grows as 1/V below ~3 um/s (the aging term a bond brings to the wall, dl_m/(V tau_a),
#: leaves only the FENE divergence to break it, ever closer to the wall): 0.08 g was 4.9e6 steps/s at 0.01 um/s,
#: whose run takes ~3 000-7 000 (the wall adds ~6 000 steps/s at 1 um/s, ~26 000 at 3.5 um/s; 0.3 g from empty at
#: 1 um/s, 2.5e5 steps/s measured, is ~7 steps per step of births)
WALL_ARRIVALS = 8000.0
WALL_ECHO = 8.0
#: the births' pace 4 (1 + u0)/tau was calibrated where at least this share of the sites is vacant (>= 1 um/s for
#: the gel); where fewer are (slower sliding: aged bonds hold their sites to the FENE wall) the births' flux into
#: them, whose error the step's third-order control bounds, falls with the vacancy, and the steps with its cube
#: root (velocity control from a steady start, steps/s: 0.1 um/s ~9 300-12 000, 0.01 um/s ~2 600-7 100 against
#: 35 700 counted; the vacancy there 1.2e-3 and 1.2e-4)
VACANT = 0.01
#: under velocity control each step of a steady start's first memory works through the start's cohorts that outlive
#: its first steps (of its 3 100-4 100 for the gel, those nearest the wall die at once: 1 810 of 4 084 within 0.05 s
#: at 0.01 um/s; about this many counted beyond STEP_SECONDS) and about one of the two born at each step so far
#: (measured 0.5-1.5 kept a step from 0.01 to 1 um/s): 0.01 um/s for 4 s took 17 365 steps and 22 s of CPU, its step
#: cost growing from ~0.35 to ~2 ms (estimated as all of the two born a step kept: 160 s; so: 88 s)
STEADY_COHORTS = 1000.0
#: where bonds leave the population before dl_m/V, the settling counts this many of their memories (the look for a
#: stretch comes after about twice the steps it waits for)
TAIL_SETTLE = 2.0
#: and the population's disturbance echoes through the wall every dl_m/V, decaying per echo by the root of
#: z + K (1 - e^-z) = 0 (K = the wall's share of the bonds' lives): at 10 um/s by 0.45 (measured ~0.47), at 1 um/s by
#: 0.99; the reduction waits until the echo is below THETA rtol, counted from the piece's start (docs/transient.md)
#: CPU per step and living cohort (s; velocity control from empty, 10 and 1 um/s: 1.0e-7 and 1.9e-7 measured): a
#: population that remembers dl_m/V = 1 s at 1 um/s keeps ~5e5 cohorts
COHORT_STEP_SECONDS = 1.5e-7
#: CPU of a step besides its cohorts (s) where those are counted (COHORT_STEP_SECONDS or SLIDING_COHORT_SECONDS for
#: the plain cohorts' pieces and holds): ~1 us measured (the rest of
#: STEP_SECONDS' 100 us, which stands for a step's cohorts where they are not counted, is theirs; plain cohorts
#: sliding at 350 um/s take 10-12 us a step over ~150 cohorts, where 100 us a step had been counted besides them:
#: 7.1 s of CPU estimated for 2 s through the block, 0.65-0.72 s taken)
PLAIN_STEP_SECONDS = 1.5e-6
#: CPU per step and living cohort (s) where the count holds, two cohorts a step alive over the memory (the plain
#: cohorts sliding through the block, and under velocity control after a change of velocity or from empty): measured
#: 7.5e-8-8.3e-8 s through the block from 200 um/s to 5 mm/s (the count 0.44-1.56 of the cohorts alive), 5.5e-8-9e-8
#: under velocity control from 10 um/s to 2 mm/s, the step's own cost included
SLIDING_COHORT_SECONDS = 7e-8
#: a steady start held as exact steady sliding until the velocity first changes (_Driver._held_steady): one
#: steady stretch a piece, whatever its length (10 um/s for 0.15 s: 1 step, 2 ms of CPU)
HELD_STEPS = 1.0
#: each cohort the start's cells cut ahead of the FENE cliff add (cells._refine, docs/transient.md section 18) costs
#: about this many steps where it reaches the cliff (velocity control, rtol 1e-4, the gel: 0.13-0.19 at 1 um/s,
#: 0.20-0.25 at 3 um/s, 0.71-0.74 at 10 um/s, 0.25 after 0.1 um/s held and slowed to 0.01 um/s, 0.52 after 10 um/s
#: held and sped to 20 um/s), and each step works through those not yet arrived (COHORT_STEP_SECONDS)
CUT_STEPS = 0.35
#: through the block a piece is reduced only this far above the fold of the steady curve at Vc: below it the slider
#: decelerates, creeps along the fold and sticks (cohorts), or slips in cycles whose approach to the stick is cohorts
FOLD_MARGIN = 1.02
#: through the block a piece is counted as reduced up to this many dl_m/tau (4.8 mm/s for the gel): faster, steady
#: sliding can be oscillatory-unstable (the gel: Kc = 0 up to 5 mm/s, 7.1e8 Pa/m at 10 mm/s), which the reduction
#: does not follow (docs/transient.md section 9, Limits); under velocity control up to 100 dl_m/tau (beyond: a likely
#: slip of units, where the refusal says "check the unit")
BLOCK_FASTEST = 1.0
#: a block from rest first sticks under Eq 1 alone, in slowly lengthening steps (1712 steps for 0.1 s, 2413 for 100 s)
STUCK_STEPS = 2500.0
#: a resting bond's hazard falls with its age at 1/tau_a (Eq 1 at V = 0), so a newborn ages into permanence with
#: probability exp(-u0 tau_a/tau) and a vacancy fills over tau exp(u0 tau_a/tau); for ln(1/rtol) such times the
#: births and deaths churn at steps of about CHURN_STEP tau (the gel, u0 tau_a/tau = 4.0: filled in 12 ms, ~1 000
#: of its 2 409 steps from rest; tau = 150 us, 6.0: 12 256 steps in the first 0.5 s; 10 us, 90: never filled, 94 176
#: steps in 0.14 s), and a block stuck for good takes CHURN_SHARE times the churn's steps (2 409 against ~1 020)
CHURN_STEP = 0.5
CHURN_SHARE = 2.4
#: a hold under velocity control relaxes in lengthening steps, at most about this many (2 375-2 377 measured for
#: holds of 1-100 s at 100 um/s, the gel; 271 for 10 ms, where the churn's count binds: _hold_steps)
HOLD_STEPS = 2500.0
#: re-sliding after a hold, the bonds aged at rest die at the FENE wall as stiff lumps once their aging term
#: A = t_hold/tau_a e^(-V/Va) passes RESLIDE_STRENGTH: the first travel dl_m costs (A/RESLIDE_STRENGTH)^RESLIDE_POWER
#: times its cohorts' count (_resliding_steps; the gel at 100 um/s: 576, 1 560, 10 529 steps after 1, 10, 100 s)
RESLIDE_STRENGTH = 1000.0
RESLIDE_POWER = 0.63
#: steps no budget allows even with the reduction (the fold's velocity is not looked for then)
HOPELESS = 1e9
#: a block with mass rings at f_b = sqrt((K + N0 M)/m)/(2 pi) after each change of the protocol (and lightly damped
#: against resting bonds): this many steps per ringing period over at most RING_WINDOW of each piece (measured:
#: 200 -> 0 -> 300 um/s, 10/50/20 ms, m = 10.5, 1, 0.1 kg/m^2 took 2347, 4542, 21338 steps, estimated 3000-31000)
RING_STEPS = 10.0
RING_WINDOW = 0.05
#: share of rtol dl_m that the rounding of a position may take, and of tau that the rounding of the clock may take
PRECISION = 1e-2
CLOCK = 0.1


def check_rtol(rtol: object) -> None:
    """Refuse a tolerance outside 1e-12..0.1 (ParameterError, one line): 0 divided the cost estimate by zero."""
    if isinstance(rtol, bool) or not (isinstance(rtol, (int, float)) and 1e-12 <= rtol <= 1e-1):
        raise ParameterError(f"rtol: expected a number between 1e-12 and 0.1, got {rtol!r}")


def estimate_cost(
    params: Parameters,
    protocol: Protocol,
    *,
    control: str = "block",
    start_velocity: float | None = None,
    rtol: float = RTOL,
    every: float | None = None,
    max_step: float | None = None,
    aging: bool = True,
    reduction: str = "auto",
    start: str = "empty",
    stick_population: bool = False,
    mass: float = 0.0,
    stiffness: float | None = None,
) -> CostEstimate:
    """The steps a run needs, and its CPU seconds, from the time scales and cycles it must resolve (no step taken).

    While sliding at V the cohorts' steps resolve the births (a few per
    tau/(1+u0)), the climb of the hazard (ln r grows at g = (lambda/kT) M V less
    the aging slope: a bond dies within ~1/g) and the FENE wall (V/dl_m);
    calibrated on the gel's set from 10 um/s to 1 m/s and the audit set of
    issue 17 (within 0.4-5x of the cohorts' steps while sliding; through the
    block the estimate is scaled by :data:`BLOCK_SHARE`).  Every protocol
    segment costs at least a step; a sampling instant none (the rows are sampled after the steps,
    :data:`SAMPLE_SECONDS` each).

    With ``reduction="auto"`` (and no ``max_step``) a piece the quasi-steady
    reduction can take (any sliding piece under velocity control; through the
    block, a puller faster than :data:`FOLD_MARGIN` x Vc, where steady sliding
    is stable) costs the cohorts' steps over :data:`SETTLE` bond memories
    dl_m/Vp and :data:`REDUCED_STEPS` for the stretch, whatever its length (the
    cohorts are counted through the block above :data:`BLOCK_FASTEST` dl_m/tau,
    under velocity control above 100 dl_m/tau, a likely slip of units).

    Through the block (with aging, no mass) the block's own motion is counted,
    not the cohorts' bound (issue 28: 70x too high for stick-slip):

    * with ``stick_population`` a stuck block is the chains' closed form (no
      step), and a piece below the fold costs :data:`SLIP_STEPS` per slip, the
      slips counted from the quasi-static model's first stick and period
      (:mod:`stickslip.quasistatic.cycle`, at the block's K; a slider that was
      sliding first decelerates, :data:`STOP_STEPS`); from rest the chains hold
      the block at any puller velocity until Eq 15 lets them go
      (:func:`_chains_let_go`), and where the paper's jump then has no landing
      point the run, and the count, stop there;
    * without it (and with aging that never saturates) one population of Eq 1
      never lets go: a block from rest is stuck for good, and a sliding block
      that meets a piece below the fold stops and is stuck for good; the run
      costs :data:`STUCK_STEPS` (and :data:`STOP_STEPS`), one step per later
      segment, whatever its length.

    A hold under velocity control costs what the solver does in it (the
    population relaxes in lengthening steps: :func:`_hold_steps`), and the
    re-slide after it the aged bonds' stiff deaths at the FENE wall
    (:func:`_resliding_steps`).  A steady start under velocity control with the reduction on, at the first piece's
    velocity, is held as exact steady sliding until the velocity first changes (:func:`_held_start`, the solver's
    ``_Driver._held_steady``): :data:`HELD_STEPS` a piece; what follows is counted as below.  Where the run carries
    the start's cohorts (the reduction off, or after that first change) the cells cut ahead of the FENE cliff
    (docs/transient.md section 18) add cohorts, each :data:`CUT_STEPS` steps where it arrives there, and each step
    works through those still to arrive (:func:`_cut_start`).  Pieces below the fold otherwise,
    ``reduction="off"`` and a ``max_step`` cost the cohorts' steps throughout.  Measured over the box
    (docs/transient.md section 2a, tests/test_transient_budget.py): steps
    taken / estimated 0.44-1.55 for the block's own motion (K from 3e5 to
    4e6 Pa/m, 1 um/s to 10 mm/s, 0.1 s to 1e6 s), 0.14-0.29 above the fold,
    0.07-2.4 under velocity control (0.3-1 at 0.01-1 um/s, where the FENE
    wall costs its cohorts' arrivals, :func:`_wall_steps`, and the births slow
    with the vacant sites, :func:`_births_steps`; a held start: 1 step taken, 1
    estimated; the reduction off, through the cut cells: 0.66-1.5 from 0.1 to
    10 um/s, 5-6 at 0.01 um/s); a run that takes more than
    its budget after all is stopped with the reason (and what it computed).

    A block with ``mass`` (kg/m^2; ``stiffness`` K in Pa/m, default the set's block) is never reduced, and its
    ringing at f_b = sqrt((K + N0 M)/m)/(2 pi) costs :data:`RING_STEPS` per period over up to
    :data:`RING_WINDOW` of every piece: a light block rings fast, and against resting bonds for long.

    ``seconds``: :data:`STEP_SECONDS` a step, :data:`SEGMENT_SECONDS` a segment (its set-up and look for a
    quasi-steady stretch), and for a block stuck for good :data:`COHORT_SECONDS` x steps^2 (it keeps every
    cohort it bears: 1e5 segments of 1 ms are ~1e5 steps but ~1.5 h of CPU).
    """
    check_rtol(rtol)
    _check_choice(reduction, REDUCTIONS, "reduction")
    if mass > 0:
        reduction = "off"
    _check_choice(start, STARTS, "start")
    b = params.bonds
    scale = (1e-4 / rtol) ** 0.25
    v_start = 0.0 if start_velocity is None else abs(start_velocity)
    reducing = reduction == "auto" and max_step is None
    k_block = params.block.effective_stiffness if stiffness is None else float(stiffness)
    # the block's own motion: stick-slip with the chains, or stuck for good under Eq 1 alone
    # with ``every`` too: such a run is integrated as without it, its rows sampled onto the grid (transient/sampling.py)
    repeating = REPEAT_CYCLES and reducing
    # SLIP_STEPS were measured with the reduction: without it a slip costs more than the births' share saves
    relaxed = RELAXED_BIRTHS and reducing and _births_never_held(protocol, bool(stick_population))
    churn = _churn(params, protocol.duration, rtol)
    motion = _BlockMotion(params, aging, k_block, bool(stick_population), start, repeating, relaxed, churn) if (
        control == "block" and aging and mass == 0 and max_step is None
    ) else None  # fmt: skip
    natural = b.max_extension / b.bond_time
    own = motion is not None and motion.counts()  # the block's own motion is counted (else the cohorts')
    # a steady start held while the velocity stays (velocity control, the reduction on), and the cohorts its cut
    # cells add where the run carries them (docs/transient.md section 18)
    holds = _held_start(protocol, control, start, reduction, max_step, mass, start_velocity)
    # (beyond 100 dl_m/tau, a likely slip of units, the cohorts are counted, as for the reduction: the refusal says
    # "check the unit")
    held = _held_pieces(protocol) if (holds and abs(protocol.initial_velocity) <= 100.0 * natural) else 0
    cut = _cut_start(params, protocol, control, start, start_velocity, aging, rtol, k_block, holds)
    steps, fastest, reduced, living, plain = _pieces_steps(
        params, protocol, control, aging, v_start, scale, motion, reducing, start=start, rtol=rtol, every=every,
        steady_held=held, cut=cut,
    )  # fmt: skip
    if control == "block" and start == "empty" and not stick_population and reduced and not own:
        steps += STUCK_STEPS  # a block from rest sticks first (the chains hold a stuck block)
    if control == "block" and mass > 0:
        ringing = math.sqrt((k_block + b.site_density * b.chain_stiffness) / mass) / (2.0 * math.pi)
        steps += RING_STEPS * ringing * sum(min(t1 - t0, RING_WINDOW) for t0, t1, _ in protocol.pieces())
    duration = protocol.duration
    ended = duration if (motion is None or motion.ended is None) else min(motion.ended, duration)
    samples = 0.0 if every is None else ended / every  # none after the run stops
    # a sampling instant costs no step: the rows are sampled after the fact (_Driver.sampler), whatever the control
    sampled_late = SAMPLED_AFTER or (repeating and bool(stick_population) and control == "block" and mass == 0)
    steps += 0.0 if sampled_late else samples
    if max_step is not None:
        steps = max(steps, duration / max_step)
    basis = f"{duration:.3g} s at up to {fastest:.3g} m/s, resolving τ = {b.bond_time:.3g} s"
    if len(protocol.segments) > 1:
        basis += f", {len(protocol.segments)} segments"
    if reduced:
        basis += f", {reduced} quasi-steady"
    if held:
        span = float(protocol.boundaries[held])
        basis += f", the steady start held for {span:.3g} s (exact steady sliding until the velocity changes)"
    if cut[0] > 0:
        basis += f", {cut[0]:.3g} cohorts of the start cut ahead of the FENE cliff"
    if motion is not None:
        basis += motion.describe()
    unit = ""
    if fastest > 100.0 * natural:
        unit = f"; {fastest:.3g} m/s is {fastest / natural:.2g} × the set's Δl_m/τ = {natural:.3g} m/s: check the unit"
    _require_resolvable(params, protocol, rtol, unit)
    basis += unit
    stuck = 0.0 if motion is None else motion.stuck_steps
    moving = len(protocol.segments) - (0 if motion is None else motion.stuck_segments)  # a stuck one looks for none
    per_segment = SEGMENT_SECONDS if (reducing and control == "block") else 0.1 * SEGMENT_SECONDS
    copied = 0.0 if motion is None else min(motion.copied * scale, steps)  # rows of a repeated limit cycle
    # the steps of the plain cohorts' pieces, whose cohorts ``living`` counts, cost PLAIN_STEP_SECONDS besides; the
    # others STEP_SECONDS, which stands for their cohorts too (a block stuck for good: both, as calibrated)
    counted = min(plain, steps - copied)
    seconds = (steps - copied - counted - (0.0 if sampled_late else samples)) * STEP_SECONDS + copied * ROW_SECONDS
    seconds += counted * PLAIN_STEP_SECONDS
    seconds += samples * SAMPLE_SECONDS
    seconds += moving * per_segment
    seconds += COHORT_SECONDS * stuck * stuck + living  # the cohorts each step works through
    return CostEstimate(steps, basis, seconds)


def _pieces_steps(  # type: ignore[no-untyped-def]
    params, protocol, control, aging, v_start, scale, motion, reducing, start="empty", rtol=RTOL, every=None,
    steady_held=0, cut=(0.0, 0.0),
) -> tuple[float, float, int, float, float]:  # fmt: skip
    """:func:`estimate_cost`'s steps piece by piece: (steps, the fastest velocity, the pieces reduced, the CPU
    seconds of the living cohorts each step works through, :data:`COHORT_STEP_SECONDS`, and the steps of the pieces
    whose living cohorts that counts: the plain cohorts' sliding pieces and holds, at :data:`PLAIN_STEP_SECONDS`).
    ``steady_held``: the pieces held as the exact steady start (:func:`_held_pieces`), :data:`HELD_STEPS` each;
    ``cut``: (cohorts, travel in m) that the start's cells cut ahead of the FENE cliff add and over which they arrive
    there (:func:`_cut_start`)."""
    b, g = params.bonds, params.aging
    fold: list[float] = []  # FOLD_MARGIN x Vc, looked for only when a piece needs it
    steps = 0.0
    fastest = 0.0
    reduced = 0
    living = 0.0
    plain = 0.0  # steps whose living cohorts are counted (the others' cost is STEP_SECONDS, their cohorts included)
    natural = b.max_extension / b.bond_time
    memories: dict[float, _Memory] = {}  # by velocity, for this estimate (1e5 segments ask again and again)
    # the velocity the population was last steady at (None: an empty start, whose first bonds reach the wall dl_m/V on)
    previous = None if start == "empty" else (v_start if v_start > 0 else abs(protocol.initial_velocity))
    held = 0.0  # the hold just before a piece (velocity control), and the cohorts it keeps
    kept = 0.0
    cut_total, cut_travel = cut
    cut_left = cut_total  # the cut cells' cohorts not yet at the FENE cliff, and the travel that brings them there
    for index, (t0, t1, vp) in enumerate(protocol.pieces()):
        if motion is not None and motion.ended is not None:
            break  # the chains collapsed beyond the steady curve's reach: the run stops there
        v = max(abs(vp), v_start) if control == "block" else abs(vp)
        fastest = max(fastest, v)
        if index < steady_held:  # the steady start held, exact: one steady stretch (_Driver._held_steady)
            steps += HELD_STEPS
            continue
        arriving, before = 0.0, cut_left  # the cut cells' cohorts that reach the cliff within this piece
        if cut_left > 0:
            travel = min(abs(vp) * (t1 - t0), cut_travel)
            arriving = min(cut_total * travel / cut[1], cut_left)
            cut_left, cut_travel = cut_left - arriving, cut_travel - travel
        slope = math.exp(-v / g.aging_velocity) / g.aging_time if aging else 0.0
        climb = max(b.force_sensitivity * b.chain_stiffness * v - slope, 0.0)
        births = 4.0 * (1.0 + b.breakage_weight) / b.bond_time
        share = scale * (BLOCK_SHARE if control == "block" else 1.0)
        filling, disturbed, previous = previous is None, previous is None or abs(vp) != previous, abs(vp)
        memory = _memory_of(memories, params, v, aging, rtol) if (v > 0 and control == "velocity") else None
        vacant = memory.vacant if memory is not None else 1.0  # (through the block: the births' full pace)
        others = 10.0 * climb + 100.0 * v / b.max_extension
        rate = (births * min((vacant / VACANT) ** (1.0 / 3.0), 1.0) + others) * share
        cohorts = (_births_steps(births, vacant, b.bond_time, t1 - t0, filling) + others * (t1 - t0)) * share
        if control == "velocity" and vp == 0 and aging and g.saturation_age is None:
            # a hold: the population relaxes smoothly in lengthening steps (not the births' pace throughout); resting
            # bonds that never age into permanence (no aging, or aging that saturates) churn on: the cohorts' count
            lump = min(cohorts, _hold_steps(params, t1 - t0, rtol) * scale)
            steps += lump + SEGMENT_STEPS
            held += t1 - t0
            # every step bears two cohorts, and resting ones age into permanence and stay: each step works through
            # those kept so far (a sampling instant was a step until the rows were sampled after the fact: 10 s held
            # every 0.1 ms, 1e5 steps past 2e5 cohorts, stopped at 10 min of CPU at 99 % of the hold)
            taken = lump + (0.0 if (every is None or SAMPLED_AFTER) else (t1 - t0) / every)
            living += COHORT_STEP_SECONDS * taken * (kept + taken + cut_left)  # (none of the cut cells' arrive)
            kept += 2.0 * taken
            plain += lump
            continue
        if motion is not None and motion.counts():
            piece = motion.piece(t1 - t0, vp, lambda v=vp: v < _fold(fold, params, control, aging))
            if motion.ended is not None:
                motion.ended += t0  # the run's end, where the chains' collapse has no landing point
            if piece is not None:  # births a block cannot resolve in STUCK_STEPS or a slip (a huge u0) are counted
                floor = rate * FORMING * b.bond_time if piece > 0 else 0.0  # a piece held by the chains: no step
                bound = math.inf if motion.stuck_for_good else cohorts  # the sticking is one lump, however short
                steps += min(max(piece, floor) * scale, bound) + motion.segment_steps()
                continue
            if motion.held > 0:  # held by the chains from rest until they let go: the rest of the piece slides,
                t0 += motion.held  # from the steady population the paper's jump lands on
                cohorts, filling, disturbed = rate * (t1 - t0), False, True
        if memory is None and v > 0:
            memory = _memory_of(memories, params, v, aging, rtol)
        # a steady population undisturbed (velocity control, the velocity it is steady at) meets the wall smoothly
        smooth = control == "velocity" and not disturbed
        wall = 0.0 if memory is None else (WALL_STEADY if smooth else WALL_SHARE) * memory.climb * share
        arrive = b.max_extension / v if (filling and v > 0) else 0.0  # the first of them arrive there
        walled = _wall_steps(wall, rate, share, b.max_extension / v, not filling, t1 - t0 - arrive) if v > 0 else 0.0
        cohorts += walled
        span = t1 - t0
        reduced_here = False
        if reducing and 0 < vp <= (BLOCK_FASTEST if control == "block" else 100.0) * natural:
            own = _memory_of(memories, params, abs(vp), aging, rtol)
            settling = min(SETTLE * b.max_extension / abs(vp), TAIL_SETTLE * own.age)
            if disturbed:  # the disturbance echoes through the wall until it falls below the reduction's share
                settling = max(settling, own.echo)
            settle = (_births_steps(births, vacant, b.bond_time, settling, filling) + others * settling) * share
            settle += REDUCED_STEPS
            settle += _wall_steps(wall, rate, share, b.max_extension / v, not filling, settling - arrive)
            if settle < min(cohorts, HOPELESS):  # beyond HOPELESS the fold is not worth finding
                if vp >= _fold(fold, params, control, aging):
                    cohorts = settle
                    span = min(span, settling)
                    reduced += 1
                    reduced_here = True
        covered = 0.0  # the share of this piece's steps whose living cohorts are counted (plain cohorts, not reduced)
        if wall > 0:  # each step once bonds die at the wall works through those born over the last memory.keep
            after = max(span - arrive, 0.0)
            wall = _wall_steps(wall, rate, share, b.max_extension / v, not filling, after) / after if after > 0 else 0.0
            if smooth:  # the steady start's cohorts over its memory (STEADY_COHORTS; gone after it: 2 358 cohorts
                # at 350 um/s, 150 from 3 ms on, and counted over the whole piece 0.5 s there was estimated at 9.6 s
                # of CPU, 0.15 s taken), and about one of the two born each step kept
                first = (rate + wall) * min(after, memory.keep)
                taken = (rate + wall) * after
                half = 0.5 * (rate + wall) * min(memory.keep, after)
                living += COHORT_STEP_SECONDS * (first * STEADY_COHORTS + taken * half)
            else:  # two cohorts born a step, alive over the memory (SLIDING_COHORT_SECONDS: a count that holds)
                living += SLIDING_COHORT_SECONDS * (rate + wall) ** 2 * after * 2.0 * min(memory.keep, after)
            # (before the first arrivals the cohorts are not counted: STEP_SECONDS stands for them)
            covered = after / span if (span > 0 and not reduced_here) else 0.0
        if held > 0 and v > 0:  # re-sliding after a hold: the aged bonds die at the FENE wall, stiffly
            aged = _resliding_steps(params, held, v, aging, rate * min(t1 - t0, b.max_extension / v))
            cohorts += aged
            living += COHORT_STEP_SECONDS * kept * (aged + rate * min(t1 - t0, b.max_extension / v))
            held, kept = 0.0, 0.0
        if before > 0:  # the cut cells' cohorts: their arrivals' steps, and each step works through those left
            cohorts += CUT_STEPS * arriving
            living += COHORT_STEP_SECONDS * cohorts * 0.5 * (before + cut_left)
        plain += covered * cohorts
        steps += cohorts + SEGMENT_STEPS
    return steps, fastest, reduced, living, plain


def _births_steps(births: float, vacant: float, tau: float, span: float, filling: bool) -> float:
    """The births' steps over ``span`` (s) at ``births`` steps/s, slowed where fewer than :data:`VACANT` of the sites
    are vacant as the cube root of the vacancy: the steady population's ``vacant``, or an empty start's filling one,
    tau/(tau + t) while above it (its bonds, aging into permanence, are at most t old)."""
    if not vacant < VACANT:
        return births * span
    if not filling:
        return births * (vacant / VACANT) ** (1.0 / 3.0) * span
    t_full = tau / VACANT - tau  # the filling population's vacancy tau/(tau + t) falls to VACANT, then to vacant
    t_low = max(tau / vacant - tau, t_full)
    steps = births * min(span, t_full)
    if span > t_full:
        end = min(span, t_low)  # the integral of (tau/(VACANT (tau + t)))^(1/3)
        grown = (tau + end) ** (2.0 / 3.0) - (tau + t_full) ** (2.0 / 3.0)
        steps += births * (tau / VACANT) ** (1.0 / 3.0) * 1.5 * grown
    if span > t_low:
        steps += births * (vacant / VACANT) ** (1.0 / 3.0) * (span - t_low)
    return steps


def _wall_steps(wall: float, rate: float, share: float, memory: float, present: bool, duration: float) -> float:
    """The steps bonds dying at the FENE wall add over ``duration`` (s) from the first arrivals: ``wall`` (steps/s,
    the climb's count), at most the arrivals' count: over the first ``memory`` (dl_m/V) the population the piece
    started with (``present``; else none: an empty start's births), :data:`WALL_ARRIVALS` steps, then
    :data:`WALL_ECHO` per step of births (``rate``, steps/s)."""
    if not duration > 0:
        return 0.0
    first = min(duration, memory) if present else 0.0
    arrivals = WALL_ARRIVALS * share * first / memory + WALL_ECHO * rate * (duration - first)
    return min(wall * duration, arrivals)


def _hold_steps(params: Parameters, duration: float, rtol: float) -> float:
    """Steps of a hold under velocity control (the slider at rest): the resting bonds churn at steps of ~tau/2
    until their vacancies fill (:func:`_churn`), after which the population relaxes in lengthening steps, at most
    :data:`HOLD_STEPS` whatever the hold's length (the gel at 100 um/s: 271 steps for 10 ms, 2 375 for 1 s,
    2 377 for 10 s and for 100 s); where the vacancies never fill the churn lasts the whole hold."""
    churn = _churn(params, duration, rtol)
    if not churn.holds:
        return churn.steps
    return max(HOLD_STEPS, CHURN_SHARE * churn.steps)


def _held_start(
    protocol: Protocol, control: str, start: str, reduction: str, max_step: float | None, mass: float,
    start_velocity: float | None,
) -> bool:  # fmt: skip
    """Whether the run holds its steady start as exact steady sliding until the velocity first changes (one
    predicate for ``_Driver.start``, which sets ``self.held`` for :meth:`_Driver._held_steady`, and for the cost
    estimate): the reduction on (``reduction="auto"``, no ``max_step``, no mass: the driver's reducer), velocity
    control, a steady start, at the first piece's velocity (no ``start_velocity``, or the same number)."""
    reducer = reduction == "auto" and max_step is None and not mass > 0
    v_first = protocol.initial_velocity
    v_start = v_first if start_velocity is None else float(start_velocity)
    return reducer and control == "velocity" and start == "steady" and v_start == v_first


def _held_pieces(protocol: Protocol) -> int:
    """The leading pieces of a held steady start: those at the first piece's velocity (_Driver._held_steady holds
    while ``vp`` is the start's, and never again once it has changed)."""
    v_first = protocol.initial_velocity
    count = 0
    for _t0, _t1, vp in protocol.pieces():
        if vp != v_first:
            break
        count += 1
    return count


def _cut_start(
    params: Parameters, protocol: Protocol, control: str, start: str, start_velocity: float | None, aging: bool,
    rtol: float, k_block: float, held: bool,
) -> tuple[float, float]:  # fmt: skip
    """(cohorts, travel in m): the cohorts that a steady start's cells cut ahead of the FENE cliff add to the uncut
    start (cells._refine, docs/transient.md section 18), and the slider's travel over which they arrive there (the
    reach, :func:`_start_reach`, at the start velocity); (0, 0) where none.  The start is the run's own: the same
    reach and ripple, so the population is built once (``_steady_cohorts`` remembers it) and the run loads it; the
    uncut one is only counted (:func:`_uncut_cohorts`).  Under velocity control only: through the block a steady start
    below Vc is moved to Vc by the run after the estimate (:func:`_steady_start_below_vc`), and nothing is cut from
    ~50 um/s up for the gel."""
    if control != "velocity" or start != "steady":
        return 0.0, 0.0
    v = protocol.initial_velocity if start_velocity is None else float(start_velocity)
    if not (v > 0 and math.isfinite(v)):
        return 0.0, 0.0
    reach = _start_reach(params, protocol, v, aging, control, k_block, held)
    if not reach > 0:
        return 0.0, 0.0
    try:
        cut = _steady_cohorts(params, v, aging, reach=reach, ripple=RIPPLE_SHARE * float(rtol)).age.size
        added = float(cut - _uncut_cohorts(params, v, aging))
    except (ModelError, ParameterError):  # the run says what is wrong with the steady start, in its words
        return 0.0, 0.0
    return (added, reach * v) if added > 0 else (0.0, 0.0)


@lru_cache(maxsize=64)
def _uncut_cohorts(params: Parameters, velocity: float, aging: bool) -> int:
    """The cohorts of the uncut steady start at ``velocity`` (cells.steady_cohorts' march, ~1 ms; remembered)."""
    from .cells import steady_cohorts

    return int(steady_cohorts(params, velocity, aging).age.size)


def _resliding_steps(params: Parameters, held: float, v: float, aging: bool, fresh: float) -> float:
    """The steps a re-slide at v after a hold of ``held`` s adds to ``fresh`` (its cohorts' count over the first
    dl_m/V): the bonds that aged at rest are held by their aging term A = held/tau_a e^(-V/Va) until their force
    matches it, at 1 - (e/dl_m)^2 ~ (lambda M dl_m/kT)/A, and die at the FENE wall within ~1/(2 A^2 V/(c dl_m)),
    each a stiff lump (the gel at 100 um/s: 576, 1 560 and 10 529 steps over that first travel after holds of 1,
    10 and 100 s, 0.19-3.4 steps per cohort that arrives there)."""
    if not aging:
        return 0.0
    from .model import aging_age

    g = params.aging
    strength = float(aging_age(np.asarray(held), params)) / g.aging_time * math.exp(-v / g.aging_velocity)
    return fresh * (max(strength / RESLIDE_STRENGTH, 1.0) ** RESLIDE_POWER - 1.0)


@dataclass(frozen=True)
class _Memory:
    """What the steady population at one velocity remembers, for :func:`estimate_cost` (:func:`_memory`)."""

    age: float  # beyond it the bonds carry less than THETA rtol of N and of sigma (at most dl_m/V)
    keep: float  # a cohort is dropped (survival 1e-30, kernel.LIGHTEST) or reaches the FENE wall
    climb: float  # d ln r/dt where the bonds that live to the wall die there (0: none do)
    echo: float  # the time a disturbance of the births takes to fall below THETA rtol (refilling, echoing)
    vacant: float = 1.0  # the steady population's share of vacant sites, tau/(tau + its mean life)


def _memory_of(memories: dict[float, _Memory], params: Parameters, v: float, aging: bool, rtol: float) -> _Memory:
    key = float(f"{v:.3g}")
    if key not in memories:
        memories[key] = _memory(params, key, aging, float(rtol))
    return memories[key]


@lru_cache(maxsize=256)
def _memory(params: Parameters, v: float, aging: bool, rtol: float) -> _Memory:
    """The steady population's memory at velocity v (:class:`_Memory`) from Eq 1's survival along one bond's life,
    on ages geometric from tau/1e6 to dl_m/V/2 and towards the FENE wall (~0.3 ms; remembered).

    A share Pw of the bonds lives to the wall (aging makes resting bonds permanent: the gel's 1.8 % at 1 um/s) and
    dies there in a lump; the rest within c - tau of their birth (c = tau + their mean life).  A disturbance of the
    birth rate then echoes through the wall every dl_m/V: linearised, c e(t) = -Pw (integral of e over the last
    dl_m/V), whose slowest root z + K (1 - e^-z) = 0 (K = Pw dl_m/V / c, z = s dl_m/V) decays per echo by
    e^-delta, delta = ln(1 + (2 pi/K)^2)/2 (large K: 2 pi^2/K^2; small K: ln(2 pi/K))."""
    from .model import log_hazard
    from .reduction import THETA

    b = params.bonds
    share = THETA * rtol
    tm = b.max_extension / v
    plain = _Memory(tm, tm, 0.0, 0.0)
    # the ages reach the FENE wall, where the hazard's integral overflows (survival 0) and the chain force diverges
    # (0 x inf): what comes of it is checked below, and a non-finite sum gives the plain memory (an estimate only)
    with np.errstate(all="ignore"):
        lo = min(b.bond_time, tm) * 1e-6
        wall = tm - np.geomspace(1e-13 * tm, 0.5 * tm, 600)
        a = np.unique(np.concatenate(([0.0], np.geomspace(lo, 0.5 * tm, 600), wall)))
        lr = np.minimum(log_hazard(v * a, a, v, params, aging), 700.0)
        r = np.exp(lr)
        da, dl = np.diff(a), np.diff(lr)
        curved = np.abs(dl) > 1e-9
        inc = np.where(curved, da * (r[1:] - r[:-1]) / np.where(curved, dl, 1.0), 0.5 * da * (r[1:] + r[:-1]))
        hazard = np.concatenate(([0.0], np.cumsum(inc)))
        survival = np.exp(-hazard)
        force = survival * chain_force(v * a, params)
        bonds = np.concatenate(([0.0], np.cumsum(0.5 * da * (survival[1:] + survival[:-1]))))
        stress = np.concatenate(([0.0], np.cumsum(0.5 * da * (force[1:] + force[:-1]))))
    if not (np.all(np.isfinite(bonds)) and np.all(np.isfinite(stress)) and bonds[-1] > 0 and stress[-1] > 0):
        return plain
    forgotten = (bonds >= (1.0 - share) * bonds[-1]) & (stress >= (1.0 - share) * stress[-1])
    age = float(a[np.argmax(forgotten)]) if forgotten.any() else tm
    dropped = hazard >= -math.log(K.LIGHTEST)
    keep = float(a[np.argmax(dropped)]) if dropped.any() else tm
    half = int(np.searchsorted(a, 0.5 * tm))
    pw = float(survival[half])
    died = int(np.searchsorted(hazard, hazard[half] + 1.0))
    # the births refill the population at 1/tau + 1/(its mean life) (one exponential life: exact)
    fill = math.log(1.0 / share) / (1.0 / b.bond_time + 1.0 / float(bonds[-1]))
    vacant = b.bond_time / (b.bond_time + float(bonds[-1]))
    if not (pw > 1e-12 and half < died < a.size):
        return _Memory(age, keep, 0.0, fill, vacant)
    climb = float((lr[died] - lr[died - 1]) / (a[died] - a[died - 1]))
    a_d = float(a[died])
    fast = np.where(a < a_d, np.maximum(survival - pw, 0.0), survival)
    c = b.bond_time + float(np.sum(0.5 * da * (fast[1:] + fast[:-1])))
    k = pw * a_d / c
    delta = 0.5 * math.log1p((2.0 * math.pi / k) ** 2) if k > 1e-3 else math.log(2.0 * math.pi / k)
    echo = math.log(1.0 / share) * a_d / delta
    if not (math.isfinite(climb) and climb > 0 and math.isfinite(echo)):
        return _Memory(age, keep, 0.0, fill, vacant)
    return _Memory(age, keep, climb, max(echo, fill), vacant)


def _fold(found: list[float], params: Parameters, control: str, aging: bool) -> float:
    """FOLD_MARGIN x Vc (:func:`_reduced_from`), found once per estimate."""
    if not found:
        found.append(_reduced_from(params, control, aging))
    return found[0]


@dataclass(frozen=True)
class _Churn:
    """The resting bonds' churn on a block that sticks under Eq 1 alone (:data:`CHURN_STEP`): its steps within the
    run, the probability that a newborn ages into permanence, and whether every cohort born is kept (its permanent
    weight above the kernel's LIGHTEST: then each step works through all of them)."""

    steps: float
    permanence: float
    lifetime: float  # u0 tau_a/tau, a resting newborn's integrated hazard
    kept: bool
    holds: bool  # the vacancy fills within the run: the block can stick for good


def _churn(params: Parameters, duration: float, rtol: float) -> _Churn:
    b, g = params.bonds, params.aging
    lifetime = b.breakage_weight * g.aging_time / b.bond_time
    filled = math.log(1.0 / rtol) * b.bond_time * math.exp(min(lifetime, 700.0))
    steps = min(duration, filled) / (CHURN_STEP * b.bond_time)
    kept = lifetime < -math.log(K.LIGHTEST)
    return _Churn(steps, math.exp(-min(lifetime, 745.0)), lifetime, kept, filled <= duration)


class _BlockMotion:
    """The block's own motion through the protocol, for :func:`estimate_cost`: stick-slip cycles of the quasi-static
    model with the paper's attached chains, or a block stuck for good under Eq 1 alone (aging that never saturates)."""

    def __init__(
        self,
        params: Parameters,
        aging: bool,
        k_block: float,
        chains: bool,
        start: str,
        repeating: bool = False,
        relaxed: bool = False,
        churn: _Churn | None = None,
    ) -> None:
        self.params, self.aging, self.k_block, self.chains = params, aging, k_block, chains
        self.churn = churn if churn is not None else _Churn(0.0, 1.0, 0.0, True, True)
        self.repeating = repeating and chains  # a limit cycle repeated after a few (_Repeater)
        self.share = RELAXED_SHARE if relaxed else 1.0  # the births' spacing by their Gauss error
        self.repeated = 0.0  # slips repeated, not integrated
        self.copied = 0.0  # their rows: counted as steps (the trace holds them), their CPU a copy's
        self.sliding = start == "steady"
        self.stuck_for_good = False
        self.stuck_steps = 0.0  # the steps of a block stuck for good: its cohorts, all kept
        self.lump = 0.0  # its sticking, counted with the next piece
        self.stuck_segments = 0
        self.from_rest = start == "empty"  # the first stick starts at sigma = 0
        self.from_steady = start == "steady"  # still sliding steadily since a steady start (no stop met yet)
        self.churned = False  # a piece was counted as the resting bonds' churn
        self.clock = 0.0  # time since the slider last stopped (the chains' stick and the cycles after it)
        self.slips = 0.0
        self.clocks: dict[tuple[float, bool], tuple[float, float]] = {}
        self.failed = False
        self.held = 0.0  # the part of the last piece the chains held from rest before they let go
        self.ended: float | None = None  # the run stops there (the chains' first collapse has no landing point)
        self.let_go: tuple[float, float] | None = None  # (time, stress) of the first collapse counted
        if not chains and params.aging.saturation_age is None and start == "empty" and self.churn.holds:
            self._stick_for_good(stop=False)

    def counts(self) -> bool:
        """Whether this motion is counted (else the cohorts' estimate): with the chains, or stuck for good (where
        resting bonds age into permanence within the run: else they churn, and the block creeps or slides)."""
        forever = self.params.aging.saturation_age is None
        return not self.failed and (self.chains or self.stuck_for_good or forever)

    def _stick_for_good(self, stop: bool) -> None:
        self.stuck_for_good = True
        self.lump = max(STUCK_STEPS, CHURN_SHARE * self.churn.steps) + (STOP_STEPS if stop else 0.0)
        # cohorts too light to keep die as they are born: then the steps cost what sliding ones do
        self.stuck_steps = self.lump if self.churn.kept else 0.0

    def _churning(self) -> bool:
        return self.stuck_for_good and CHURN_SHARE * self.churn.steps > STUCK_STEPS

    def segment_steps(self) -> float:
        """A stuck block takes one step per segment (and keeps its cohort); a moving one more."""
        if self.stuck_for_good:
            self.stuck_steps += 1.0
            self.stuck_segments += 1
            return 1.0
        return SEGMENT_STEPS

    def piece(self, dt: float, vp: float, below: Callable[[], bool]) -> float | None:
        """Steps of a piece of length dt at puller velocity vp (``below()``: below the fold, looked for only when
        needed), or None: the cohorts' count."""
        if self.stuck_for_good:
            lump, self.lump = self.lump, 0.0
            return lump
        if not self.chains and not self.churn.holds and self.params.aging.saturation_age is None:
            # resting bonds never fill the vacancies within the run: the births and deaths churn at steps of ~tau
            # throughout, whether the block creeps or slides (tau = 10 us: 657 719 steps for 1 s, 1 ns: ~1e10),
            # unless it slides steadily above the fold from a steady start (the reduction's count: tau = 1 ns at
            # 100 um/s from a steady start, 129 steps for 1 s, had been counted as 2e9 churning ones)
            if self.sliding and self.from_steady and vp > 0 and not below():
                self.clock = 0.0
                return None
            self.from_steady, self.churned = False, True
            return dt / (CHURN_STEP * self.params.bonds.bond_time)
        self.held = 0.0
        on_chains = self.chains and self.from_rest and not self.sliding  # held by the chains since the start
        if on_chains and vp > 0:
            stopped = self._first_collapse(dt, vp)
            if stopped is not None:
                return stopped
        if not below():
            if on_chains and vp > 0:
                if self.clock + dt < self._let_go(vp)[0]:
                    self.clock += dt  # held by the chains throughout: their closed form, no step
                    return 0.0
                self.held = max(self._let_go(vp)[0] - self.clock, 0.0)  # the rest of the piece slides
            self.sliding = self.sliding or not self.chains or vp > 0
            self.clock, self.from_rest = 0.0, False
            return None  # sliding: the cohorts' (or the reduction's) count
        if not self.chains:  # a sliding block decelerates and sticks for good
            self._stick_for_good(stop=self.sliding)
            lump, self.lump = self.lump, 0.0
            return lump
        steps = 0.0
        if self.sliding:  # it decelerates to a stick near sigma_c
            steps += STOP_STEPS * self.share
            self.sliding, self.clock = False, 0.0
        if vp > 0:
            try:
                first, period = self._cycle(vp)
            except (ModelError, ParameterError):
                self.failed = True
                return None
            before = _slips(self.clock, first, period)
            self.clock += dt
            slips = _slips(self.clock, first, period) - before
            self.slips += slips
            steps += SLIP_STEPS * slips * self.share
            if self.repeating and slips > REPEAT_SLIPS:
                self.repeated += slips - REPEAT_SLIPS
                self.copied += SLIP_STEPS * (slips - REPEAT_SLIPS) * self.share
        else:
            self.clock += dt
        return steps

    def _let_go(self, vp: float) -> tuple[float, float, bool]:
        """(time, stress, whether the paper's jump lands) of the chains' first collapse from rest at vp (Eq 15)."""
        return _chains_let_go(self.params, float(f"{vp:.3g}"), self.aging, self.k_block)

    def _first_collapse(self, dt: float, vp: float) -> float | None:
        """0 steps where the chains' first collapse from rest falls within this piece beyond the steady curve's
        reach: the run stops there (the solver's "no landing point"), the pieces after it cost nothing; else None."""
        t_go, sigma_s, lands = self._let_go(vp)
        if lands or not self.clock + dt >= t_go:
            return None
        self.held = max(t_go - self.clock, 0.0)
        self.ended, self.let_go = self.held, (t_go, sigma_s)
        return 0.0

    def _cycle(self, vp: float) -> tuple[float, float]:
        """(time to the first slip, period after it) of the quasi-static model at vp (inf: never), remembered by
        velocity to 1 %."""
        key = (float(f"{vp:.2g}"), self.from_rest)
        if key not in self.clocks:
            self.clocks[key] = _quasi_static_clock(self.params, key[0], self.aging, self.k_block, self.from_rest)
        return self.clocks[key]

    def describe(self) -> str:
        if self.let_go is not None:
            t_go, sigma_s = self.let_go
            return (
                f", the block held by the stick chains until t = {t_go:.6g} s, where they collapse (Eq 15) at σs ="
                f" {sigma_s:.6g} Pa, beyond the steady curve's reach: the run stops there"
            )
        if self._churning():
            c = self.churn
            return (
                f", the block stuck for good under Eq 1 (no stick chains) once resting bonds, which age into"
                f" permanence with probability e^(-u0 τa/τ) = {c.permanence:.3g}, fill its vacancies: until then their"
                f" births and deaths churn at steps of ~τ/2 ({c.steps:.3g} such steps)"
            )
        if self.stuck_for_good:
            return ", the block stuck for good under Eq 1 (no stick chains)"
        if self.churned:
            return (
                f", resting bonds that age into permanence with probability e^(-u0 τa/τ) = {self.churn.permanence:.3g}"
                " (never filling the vacancies within the run): their births and deaths churn at steps of ~τ/2"
            )
        if self.chains and self.slips > 0:
            repeated = f", {self.repeated:.3g} of them repeated, not integrated" if self.repeated else ""
            return f", about {self.slips:.3g} stick–slip cycles of the quasi-static model{repeated}"
        return ""


def _slips(t: float, first: float, period: float) -> float:
    """Slips within a time t stuck or cycling: the first at ``first``, then one per ``period``."""
    if not t >= first:
        return 0.0
    return 1.0 + ((t - first) / period if math.isfinite(period) else 0.0)


@lru_cache(maxsize=64)
def _chains_let_go(params: Parameters, vp: float, aging: bool, k_block: float) -> tuple[float, float, bool]:
    """(time, stress, whether the paper's jump lands on the steady curve) of the stick chains' first collapse
    under a block at rest from sigma = 0 pulled at vp (Eq 15 at K, quasistatic.stick; inf: they never collapse),
    ~1-5 ms, remembered.  The solver's stuck block follows the same closed form (transient.model.stick_chains)."""
    from ..quasistatic.jump import jump_velocity
    from ..quasistatic.stick import stick_time

    k_set = params.block.effective_stiffness
    scaled = params
    if not math.isclose(k_block, k_set, rel_tol=1e-9):
        scaled = params.with_overrides({"block.shear_modulus": params.block.shear_modulus * k_block / k_set})
    try:
        first = stick_time(scaled, vp, 0.0, aging=aging)
        if first is None or not first[0]:
            return math.inf, math.inf, True
    except (ModelError, ParameterError):
        return 0.0, 0.0, True  # not known: counted as sliding from the start, as before
    try:
        landing = jump_velocity(params, first[1], "aging" if aging else "no-aging")
    except (ModelError, ParameterError):  # no critical point to land beyond: the solver stops at the collapse
        return float(first[0]), float(first[1]), False
    return float(first[0]), float(first[1]), bool(landing.reachable and landing.velocity is not None)


@lru_cache(maxsize=64)
def _quasi_static_clock(
    params: Parameters, vp: float, aging: bool, k_block: float, from_rest: bool
) -> tuple[float, float]:
    """(first stick's time, stick + slip period from sigma_c) of the quasi-static cycle (quasistatic.cycle) at K.

    Remembered by its arguments (a frozen parameter set; ~5 ms, as much as the cohorts' steps of a tenth of the
    paper's cycle): runs of one set at one puller velocity ask again (a repeated run, a sweep over a protocol's
    keys)."""
    from ..quasistatic.jump import jump_velocity
    from ..quasistatic.slip import slip_duration
    from ..quasistatic.stick import stick_time

    k_set = params.block.effective_stiffness
    if not math.isclose(k_block, k_set, rel_tol=1e-9):
        params = params.with_overrides({"block.shear_modulus": params.block.shear_modulus * k_block / k_set})
    first = stick_time(params, vp, 0.0 if from_rest else None, aging=aging)
    again = first if not from_rest else stick_time(params, vp, None, aging=aging)
    t_first = first[0] if first is not None and first[0] else math.inf
    if again is None or not again[0]:
        return t_first, math.inf
    jump = jump_velocity(params, again[1], "aging" if aging else "no-aging")
    if not jump.reachable or jump.velocity is None:
        return t_first, math.inf  # the run stops at the collapse
    ends, duration = slip_duration(params, vp, jump.velocity)
    if ends == "steady":
        return t_first, math.inf
    return t_first, again[0] + duration


def _require_resolvable(params: Parameters, protocol: Protocol, rtol: float, unit: str) -> None:
    """Refuse a run whose positions or times outgrow double precision (a reduced stretch costs few steps whatever
    its length, so the step budget no longer bounds the duration): the bonds' extensions, differences of positions
    of the size of the travel, must keep rtol of dl_m, and the clock must resolve a tenth of tau."""
    b = params.bonds
    eps = float(np.finfo(float).eps)
    travel, duration = _travel(protocol), protocol.duration
    if travel * eps > PRECISION * rtol * b.max_extension or duration * eps > CLOCK * b.bond_time:
        raise ParameterError(
            f"transient: {duration:.3g} s ({travel:.3g} m of travel) is beyond what double precision resolves: the"
            f" bonds' extensions (Δl_m = {b.max_extension:.3g} m) to rtol {rtol:g} need a travel below"
            f" {PRECISION * rtol * b.max_extension / eps:.3g} m, the clock (τ = {b.bond_time:.3g} s) a run shorter"
            f" than {CLOCK * b.bond_time / eps:.3g} s; shorten the run{unit}"
        )


def _reduced_from(params: Parameters, control: str, aging: bool) -> float:
    """The slowest puller velocity whose pieces the quasi-steady reduction takes (0: all; inf: none)."""
    if control != "block" or not aging:  # a rigid rig holds V; without aging the steady curve has no fold
        return 0.0
    from ..quasistatic.critical import critical_minimum

    try:
        cp = critical_minimum(params)  # Vc alone (as _steady_start_below_vc)
    except (ModelError, ParameterError):
        return math.inf  # no critical point to be found: count the cohorts throughout
    if cp is None:
        return 0.0
    return FOLD_MARGIN * float(cp.velocity)


__all__ = ["Cycle", "estimate_cost", "run_transient"]
