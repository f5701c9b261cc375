r"""Eq 1 in the cohort (history) form: parameters for the kernel, the steady population, the stick chains.

``docs/transient.md`` derives everything here.  The one modelling choice that
differs from the printed equations: the chain extension of a bond is the
slider's travel since the bond formed, X(t) - X(t - t_a), not t_a V(t)
(Eq 3), which equals it only at constant velocity.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..parameters import Parameters
from . import kernel as K

#: half-distance of the Gauss-Legendre points from a cell's middle, as a fraction of the cell
GAUSS = 0.5 / math.sqrt(3.0)


def pack_parameters(
    params: Parameters,
    aging: bool,
    stiffness: float,
    mass: float = 0.0,
    damping: float = 0.0,
    relaxed_births: bool = False,
    wall_landing: bool = False,
) -> np.ndarray:
    """The float vector the kernel reads (layout: kernel.P_*); ``mass`` (kg/m^2) and ``damping`` (Pa s/m): the
    block's inertia and viscous damping (0: the paper's massless block); ``relaxed_births``: no bond born sliding
    is held and slid again (kernel._relaxed_births); ``wall_landing``: steps end short of a loaded cohort's arrival at
    the FENE wall (kernel.WALL_LANDING)."""
    b, g = params.bonds, params.aging
    p = np.zeros(16)
    p[K.P_LOG_U0_TAU] = math.log(b.breakage_weight / b.bond_time)
    p[K.P_TAU] = b.bond_time
    p[K.P_FORCE_SENS] = b.force_sensitivity
    p[K.P_M] = b.chain_stiffness
    p[K.P_DLM] = b.max_extension
    p[K.P_INV_TAU_A] = 1.0 / g.aging_time
    p[K.P_VA] = g.aging_velocity
    p[K.P_N0] = b.site_density
    p[K.P_K] = stiffness
    p[K.P_AGING] = 1.0 if aging else 0.0
    p[K.P_SATURATION] = 0.0 if g.saturation_age is None else g.saturation_age  # 0: the paper's linear aging
    p[K.P_MASS] = mass
    p[K.P_DAMPING] = damping
    p[K.P_MERGE_SATURATED] = _MERGE_SATURATED[0]
    p[K.P_RELAXED_BIRTHS] = 1.0 if relaxed_births else 0.0
    p[K.P_WALL_LANDING] = K.WALL_LANDING if wall_landing else 0.0
    return p


#: the kernel's housekeeping of saturating aging (kernel._saturated_bins) on, or off (see :func:`plain_cohorts`)
_MERGE_SATURATED = [K.SATURATED_SPREAD]


@contextmanager
def plain_cohorts() -> Iterator[None]:
    """Within the block, saturating aging keeps every cohort until it weighs 1e-30 N0 and merges only quiet ones.

    The reference for the kernel's merging of saturated cohorts and its relative drop (docs/transient.md
    section 2, *Housekeeping*; ``benchmarks/bench_transient.py``, ``tests/test_transient_stuck.py``).
    """
    _MERGE_SATURATED[0] = 0.0
    try:
        yield
    finally:
        _MERGE_SATURATED[0] = K.SATURATED_SPREAD


def aging_age(age: np.ndarray, params: Parameters) -> np.ndarray:
    """The age the aging term of Eq 1 sees: t_a (the paper), or t_s (1 - e^(-t_a/t_s)) with saturation.

    The saturating-aging extension (docs/extensions.md): a bond's barrier grows at kT/tau_a per unit age
    while young and levels off at kT t_s/tau_a, first-order kinetics of the contact's maturation.
    """
    ts = params.aging.saturation_age
    if ts is None:
        return age
    return -ts * np.expm1(-np.asarray(age) / ts)


def chain_force(extension: np.ndarray, params: Parameters) -> np.ndarray:
    """Eq 3 with the history extension: M e / (1 - (e/dl_m)^2)."""
    b = params.bonds
    y = extension / b.max_extension
    return b.chain_stiffness * extension / (1.0 - y * y)


def log_hazard(extension: np.ndarray, age: np.ndarray, velocity: float, params: Parameters, aging: bool) -> np.ndarray:
    """ln of the breakage rate of Eq 1 (1/s), finite inside the FENE limit."""
    b, g = params.bonds, params.aging
    out = math.log(b.breakage_weight / b.bond_time) + b.force_sensitivity * chain_force(extension, params)
    if aging:
        out = out - aging_age(age, params) / g.aging_time * math.exp(-velocity / g.aging_velocity)
    return out


@dataclass(frozen=True)
class Population:
    """Cohorts: extension (m), age (s) and weight (bonds per m^2), oldest last."""

    extension: np.ndarray
    age: np.ndarray
    weight: np.ndarray

    @property
    def bonded(self) -> float:
        return float(self.weight.sum())


#: steady populations: largest hazard increment per age cell, and where the survival counts as zero
CELL_HAZARD = 0.05
HAZARD_END = 45.0
#: a cell spans at most this share of its distance in age from the FENE wall (the chain force, 1/(1 - y^2), resolved)
WALL_CELL = 0.05
#: most age cells a steady population may take (the gel's set takes ~2000-20000)
MAX_CELLS = 1_000_000
#: a steady start's cells whose cohorts reach the FENE cliff within the run are cut until the ripple their lumped
#: deaths there leave in the stress is at most this share of the run's rtol (cells.steady_cohorts, the lumping
#: ripple's estimate cells._lumping; docs/transient.md section 18)
RIPPLE_SHARE = 0.1
#: and the cells so cut add at most this many, those nearest the cliff first (they arrive first): the gel at 1 um/s
#: adds ~5 600 for a run of 20 ms (its CPU 4.7 s against 0.44 s uncut), and would add ~4e5 for one of 1 s
REFINED_MOST = 40_000


def steady_population(
    params: Parameters, velocity: float, aging: bool, cell_hazard: float = CELL_HAZARD, rule: str = "gauss"
) -> Population:
    """The steady age distribution of Eqs 6-7 at ``velocity`` as cohorts.

    The cells follow the hazard: each spans at most ``cell_hazard`` of cumulative
    hazard and at most 1/1000 of the time to full extension, so the survival
    is resolved wherever it falls (near t_a = 0, on an aging plateau or at the
    FENE cliff); the last bound also keeps the cohorts closer than the width of
    the FENE cliff they will reach, so that a steady start stays steady.
    ``rule="gauss"``: two cohorts per cell at its Gauss-Legendre points
    (fourth order, the solver's start); ``"midpoint"``: one per cell at its
    middle, cells tiling the ages (the linear-stability quadrature's layout).
    """
    b = params.bonds
    if not velocity > 0:
        raise ModelError(f"steady start: expected a positive sliding velocity, got {velocity!r} m/s")
    t_max = b.max_extension / velocity
    ages = [0.0]
    hazard = [0.0]
    a, big_h = 0.0, 0.0
    widest = t_max / 1000.0
    for _ in range(MAX_CELLS):
        if not (big_h < HAZARD_END and a < t_max):
            break
        lr = float(log_hazard(np.array(velocity * a), np.array(a), velocity, params, aging))
        step = widest if lr < -700 else min(widest, cell_hazard / math.exp(min(lr, 700.0)))
        # never step past the FENE wall; approach it geometrically
        step = min(step, WALL_CELL * (t_max - a))  # resolves the FENE force as well as the survival
        if step <= 1e-15 * a:  # no progress left in floating point (the FENE wall approached geometrically)
            break
        # Simpson on the cell for the cumulative hazard; a cell over which the hazard climbs (a force cliff the
        # hazard at its start does not foresee) is shrunk until it holds a few times cell_hazard: sized from its
        # start alone, one cell swallowed the whole population in corners of the box (two cohorts, sigma 100 % off)
        while True:
            mid = a + 0.5 * step
            end = a + step
            nodes = np.array([a, mid, end])
            rates = np.exp(np.minimum(log_hazard(velocity * nodes, nodes, velocity, params, aging), 700.0))
            increment = step * (rates[0] + 4 * rates[1] + rates[2]) / 6.0
            steady = increment <= 2.0 * cell_hazard and rates[2] <= 2.0 * rates[0] + 1e-300
            if steady or increment <= 0.1 * cell_hazard or step <= 1e-12 * max(a, t_max):
                break
            step *= 0.25
        big_h += increment
        a = end
        ages.append(a)
        hazard.append(big_h)
    else:
        raise ModelError(
            f"steady population at {velocity:.3g} m/s: more than {MAX_CELLS} age cells (the hazard changes on scales"
            " below float resolution of the bond's life); the velocity is far outside the parameter set's range"
        )
    edges = np.array(ages)
    cum = np.array(hazard)
    if rule == "midpoint":
        return _midpoint_cells(params, velocity, edges, cum)
    # two cohorts per cell at its Gauss-Legendre points (fourth order in the cell width): their survival from the
    # cumulative hazard at the cell's start plus Simpson's rule over the part of the cell before the point
    a0, width = edges[:-1], np.diff(edges)
    ages_g, weights_g = [], []
    for offset in (0.5 - GAUSS, 0.5 + GAUSS):
        ag = a0 + offset * width
        mid = 0.5 * (a0 + ag)
        rates = [np.exp(np.minimum(log_hazard(velocity * a, a, velocity, params, aging), 700.0)) for a in (a0, mid, ag)]
        part = (ag - a0) * (rates[0] + 4.0 * rates[1] + rates[2]) / 6.0
        ages_g.append(ag)
        weights_g.append(0.5 * width * np.exp(-(cum[:-1] + part)))
    age = np.stack(ages_g, axis=1).ravel()
    survival = np.stack(weights_g, axis=1).ravel()
    birth = b.site_density / (b.bond_time + survival.sum())  # Eq 7: n(0) = N0/(tau + I)
    return Population(extension=velocity * age, age=age, weight=birth * survival)


def _midpoint_cells(params: Parameters, velocity: float, edges: np.ndarray, cum: np.ndarray) -> Population:
    """One cohort per cell at its middle, weighted by its survival integrated exactly for a hazard linear in it."""
    b = params.bonds
    mid_age = 0.5 * (edges[1:] + edges[:-1])
    width = np.diff(edges)
    dh = np.diff(cum)
    s0 = np.exp(-cum[:-1])
    safe = np.where(dh > 1e-12, dh, 1.0)
    cell = np.where(dh > 1e-12, s0 * -np.expm1(-dh) / safe, s0 * (1.0 - 0.5 * dh)) * width
    birth = b.site_density / (b.bond_time + cell.sum())  # Eq 7: n(0) = N0/(tau + I)
    return Population(extension=velocity * mid_age, age=mid_age, weight=birth * cell)


# --------------------------------------------------------------------------- the paper's stick chains (Eqs 13-15)
#: the collapse counts as complete when the per-chain breakage rate passes e^COLLAPSE_LOG_RATE per second
COLLAPSE_LOG_RATE = 60.0


@dataclass(frozen=True)
class StickChains:
    """Outcome of a stick with the attached chains of Eq 15 over a stretch of constant puller velocity."""

    duration: float  # time spent in this stretch (s)
    fraction: float  # Nc/Nc0 at its end
    collapsed: bool
    times: np.ndarray
    fractions: np.ndarray
    #: fresh chains not collapsed within the stretch: when they would under the same loading (s from the stretch's
    #: start; None: not known), or whether Eq 15 proves they never do
    due: float | None = None
    never: bool = False


def stick_chains(
    params: Parameters,
    aging: bool,
    stress0: float,
    loading_rate: float,
    elapsed: float,
    fraction: float,
    span: float,
) -> StickChains:
    """Integrate Eq 15 from ``elapsed`` s after the stick, at stress ``stress0 + loading_rate * t``, for ``span`` s.

    ln(Nc/Nc0) is integrated (LSODA, rtol 1e-10) until the per-chain rate exceeds
    e^60 per second: the remaining chains then go in less than e^-60 s.
    """
    st = params.stick
    c = params.bonds.force_sensitivity / st.attached_chains
    inv_age = 1.0 / st.aging_time if aging else 0.0
    log_r = math.log(st.break_rate)

    def log_rate(t: float, y: float) -> float:
        stress = stress0 + loading_rate * t
        return log_r + c * stress * math.exp(-y) - (elapsed + t) * inv_age

    def rhs(t: float, y: np.ndarray) -> list[float]:
        return [-math.exp(min(log_rate(t, y[0]), COLLAPSE_LOG_RATE + 5.0))]

    def collapse(t: float, y: np.ndarray) -> float:
        return log_rate(t, y[0]) - COLLAPSE_LOG_RATE

    collapse.terminal = True  # type: ignore[attr-defined]
    collapse.direction = 1  # type: ignore[attr-defined]
    y0 = math.log(max(fraction, 1e-300))
    if collapse(0.0, np.array([y0])) >= 0:
        return StickChains(0.0, fraction, True, np.array([0.0]), np.array([fraction]))
    if elapsed == 0.0 and fraction == 1.0 and loading_rate > 0.0:
        return _fresh_chains(params, aging, stress0, loading_rate, span)
    from scipy.integrate import solve_ivp  # here: fresh chains (the cycle's sticks) need no scipy.integrate (~0.4 s)

    try:
        sol = solve_ivp(rhs, (0.0, span), [y0], method="LSODA", rtol=1e-10, atol=1e-12, events=collapse)
    except ValueError:  # event bracketing lost in the explosive collapse: step without events
        sol = solve_ivp(rhs, (0.0, span), [y0], method="Radau", rtol=1e-10, atol=1e-12)
    if sol.status < 0 and not log_rate(float(sol.t[-1]), float(sol.y[0, -1])) > 0.0:
        raise ModelError(f"stick chains (Eq 15): integration failed: {sol.message}")
    if sol.status < 0:  # the step size collapsed inside the explosive end: the chains are going at > 1/s
        return StickChains(float(sol.t[-1]), 0.0, True, sol.t, np.exp(sol.y[0]))
    done = sol.status == 1 or log_rate(float(sol.t[-1]), float(sol.y[0, -1])) >= COLLAPSE_LOG_RATE
    t_end = float(sol.t_events[0][0]) if sol.status == 1 else float(sol.t[-1])
    return StickChains(t_end, float(np.exp(sol.y[0, -1])), bool(done), sol.t, np.exp(sol.y[0]))


def _fresh_chains(params: Parameters, aging: bool, stress0: float, loading_rate: float, span: float) -> StickChains:
    """A stick from fresh chains at constant loading: the package's stick solver (quasistatic.stick, Eq 15)."""
    from ..quasistatic.stick import stick_phase

    velocity = loading_rate / params.block.effective_stiffness
    stick = stick_phase(params, velocity, start_stress=stress0, aging=aging, horizon=span)
    if stick.status == "slipped" and stick.stick_time is not None and stick.stick_time <= span:
        return StickChains(stick.stick_time, 0.0, True, stick.time, stick.chain_fraction)
    inside = stick.time < span
    times = np.r_[stick.time[inside], span]
    fractions = np.r_[stick.chain_fraction[inside], stick.chain_fraction_at(span)]
    due = stick.stick_time if stick.status == "slipped" else None
    return StickChains(span, float(fractions[-1]), False, times, fractions, due, stick.status == "stuck")
