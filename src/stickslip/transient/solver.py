"""run_transient: drive the cohort kernel through a loading protocol (docs/transient.md)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ModelError, ParameterError
from ..model.cycle import Cycle
from ..parameters import Parameters
from ..protocols import Protocol
from . import kernel as K
from .model import Population, pack_parameters, steady_population, stick_chains
from .result import Bookkeeping, Snapshot, TransientResult

CONTROLS = ("block", "velocity")
STARTS = ("empty", "steady")
#: the slider counts as stuck below this fraction of the puller velocity (cycle detection, stick chains)
STICK_FRACTION = 0.01
#: kernel calls return after this many steps (progress reports, buffer flushes)
CHUNK = 20000
#: default relative tolerance of the local error (stress and bonded fraction)
RTOL = 1e-4


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
    acc: np.ndarray = field(default_factory=lambda: np.zeros(6))

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
    begins stuck.  ``every`` (s) samples the trace on a uniform grid hit by
    the solver itself; otherwise every accepted step is a row.  ``rtol`` is
    the local error tolerance (relative, in stress and bonded fraction).
    ``progress`` is called with the fraction done.  ``snapshot_times`` (s):
    extra instants to keep the age/extension distribution at (the start, the
    end of every protocol segment and the end are always kept).
    """
    _check_choice(control, CONTROLS, "control")
    _check_choice(start, STARTS, "start")
    if not isinstance(protocol, Protocol):
        raise ParameterError(f"protocol: expected a stickslip.protocols.Protocol, got {type(protocol).__name__}")
    if not (isinstance(rtol, (int, float)) and 1e-12 <= rtol <= 1e-1):
        raise ParameterError(f"rtol: expected a number between 1e-12 and 0.1, got {rtol!r}")
    if stick_population and control != "block":
        raise ParameterError("stick_population: the attached chains need block control (control='block')")
    k_block = params.block.effective_stiffness if stiffness is None else float(stiffness)
    if not (math.isfinite(k_block) and k_block > 0):
        raise ParameterError(f"stiffness: expected a positive finite value in Pa/m, got {stiffness!r}")
    duration = protocol.duration
    if every is not None and not (math.isfinite(every) and 0 < every <= duration):
        raise ParameterError(f"every: expected a positive time no longer than the run ({duration:g} s), got {every!r}")
    functions = K.compiled()
    advance = functions["advance"]
    slider_velocity = functions["_slider_velocity"]
    p = pack_parameters(params, aging, k_block)
    b = params.bonds

    state = _State(0.0, 0.0, 0.0, b.bond_time * 1e-3, 0.0, 0, np.empty(4096), np.empty(4096), np.empty(4096))
    v_first = protocol.initial_velocity
    if start == "steady":
        v_start = v_first if start_velocity is None else float(start_velocity)
        if not v_start > 0:
            raise ParameterError(f"start velocity: a steady start needs a positive sliding velocity, got {v_start!r}")
        pop = steady_population(params, v_start, aging)
        state.load(pop)
        state.v = v_start
    elif start_velocity is not None:
        raise ParameterError("start velocity: only used with start='steady'")
    else:
        state.v = v_first  # no bonds: the slider moves with the puller
    sigma0 = float(np.exp(state.lw[: state.n]) @ _force(state.x - state.xb[: state.n], params)) if state.n else 0.0
    state.puller = state.x + sigma0 / k_block if control == "block" else state.x

    times = _sample_grid(every, duration)
    wanted = sorted(set([0.0, duration, *protocol.boundaries.tolist(), *np.atleast_1d(snapshot_times or []).tolist()]))
    snapshots: list[Snapshot] = []
    rows: list[np.ndarray] = [_row(state, params, control, k_block)]
    chain_rows: list[np.ndarray] = []
    chains_on = stick_population and start == "empty"
    events: list[tuple[str, float, float, float]] = []  # (kind, time, stress, velocity)
    chain_state = {"elapsed": 0.0, "fraction": 1.0}
    sample_index = 1 if times.size else 0  # t = 0 is already a row
    out = np.empty((CHUNK, 11))
    h_max = math.inf if max_step is None else float(max_step)
    snap_index = 0
    if chains_on:
        events.append(("stick", 0.0, sigma0, 0.0))
    for t0, t1, vp in protocol.pieces():
        while snap_index < len(wanted) and wanted[snap_index] <= t0 + 1e-15:
            snapshots.append(_snapshot(state))
            snap_index += 1
        if control == "velocity":
            state.v = vp
        while state.t < t1 - 1e-12 * max(t1, 1.0):
            if chains_on:
                # the stuck block: slider fixed, chains of Eq 15 carry sigma = K (P - X)
                stress0 = k_block * (state.puller - state.x)
                res = stick_chains(
                    params, aging, stress0, k_block * vp, chain_state["elapsed"], chain_state["fraction"], t1 - state.t
                )
                t_new = state.t + res.duration
                chain_rows.append(np.c_[state.t + res.times, res.fractions])
                if times.size:  # the trace on the sampling grid: stress and positions are exact while stuck
                    inside = (times > state.t) & (times <= t_new)
                    for tt in times[inside]:
                        ff = float(np.interp(tt - state.t, res.times, res.fractions))
                        rows.append(_stuck_row(state, params, float(tt), vp, k_block, ff))
                    sample_index = max(sample_index, int(np.searchsorted(times, t_new, side="right")))
                else:
                    for tt, ff in zip(res.times[1:], res.fractions[1:], strict=True):
                        rows.append(_stuck_row(state, params, state.t + tt, vp, k_block, ff))
                state.puller += vp * res.duration
                state.t = t_new
                chain_state["elapsed"] += res.duration
                chain_state["fraction"] = res.fraction
                if not res.collapsed:
                    continue
                sigma_s = k_block * (state.puller - state.x)
                vs = _jump(params, sigma_s, aging)
                if vs is None:
                    events.append(("unreachable", state.t, sigma_s, 0.0))
                    return _finish(
                        rows,
                        chain_rows,
                        events,
                        snapshots,
                        state,
                        params,
                        protocol,
                        control,
                        k_block,
                        int(state.acc[4]),
                        stop=f"the chains collapse at sigma_s = {sigma_s:.6g} Pa, beyond the"
                        " steady curve's reach: the paper's jump has no landing point",
                    )
                events.append(("slip", state.t, sigma_s, vs))
                pop = steady_population(params, vs, aging)
                state.load(pop)
                state.v = vs
                state.h = b.bond_time * 1e-3
                chains_on = False
                # put the slider where the new bonds carry sigma_s
                weights = np.exp(state.lw[: state.n])
                state.x = functions["_balance_weights"](state.x, state.puller, state.n, state.xb, weights, p)
                state.v = slider_velocity(
                    vs, vp, state.n, state.xb, state.tb, state.lw, state.x, state.t, p, *_scratch(state)
                )
                rows.append(_row(state, params, control, k_block))
                continue
            if control == "block":
                state.v = slider_velocity(
                    state.v, vp, state.n, state.xb, state.tb, state.lw, state.x, state.t, p, *_scratch(state)
                )
            # in a hold (vp = 0) the slider counts as stopped below 1 % of the protocol's sliding velocity
            pace = vp if vp > 0 else float(np.max(protocol.velocities))
            stick_v = STICK_FRACTION * pace if (stick_population and pace > 0) else 0.0
            puller0 = state.puller - vp * state.t  # puller position extrapolated to t = 0 of this piece's line
            lw_new, rate0, lc, aa, w1 = (np.empty(state.xb.size) for _ in range(5))
            status, t, x, v, h, n, sample_index, count = advance(
                state.t, t1, state.x, state.v, state.h, puller0, vp, 0.0, 1 if control == "block" else 0,
                state.n, state.xb, state.tb, state.lw, lw_new, rate0, lc, aa, w1, state.acc, p, float(rtol), h_max,
                times, sample_index, out, CHUNK, stick_v, CHUNK,
            )  # fmt: skip
            state.t, state.x, state.v, state.h, state.n = float(t), float(x), float(v), float(h), int(n)
            state.puller = puller0 + vp * state.t if control == "block" else state.x
            if count:
                rows.extend(_kernel_rows(out[:count], k_block, control))
            if status == K.FULL:
                state.grow()
            elif status == K.STICK:
                chains_on = True
                chain_state = {"elapsed": 0.0, "fraction": 1.0}
                events.append(("stick", state.t, k_block * (state.puller - state.x), state.v))
            if not all(math.isfinite(q) for q in (state.t, state.x, state.v, state.h)):
                raise ModelError(f"transient solver failed at t = {state.t:.6g} s (non-finite state)")
            if progress is not None:
                progress(min(1.0, state.t / duration))
            while snap_index < len(wanted) and wanted[snap_index] <= state.t + 1e-15 and wanted[snap_index] < t1:
                snapshots.append(_snapshot(state))
                snap_index += 1
    while snap_index < len(wanted):
        snapshots.append(_snapshot(state))
        snap_index += 1
    return _finish(rows, chain_rows, events, snapshots, state, params, protocol, control, k_block, int(state.acc[4]))


def _force(extension: np.ndarray, params: Parameters) -> np.ndarray:
    from .model import chain_force

    return chain_force(extension, params)


def _scratch(state: _State) -> tuple[np.ndarray, np.ndarray]:
    return np.empty(state.xb.size), np.empty(state.xb.size)


def _sample_grid(every: float | None, duration: float) -> np.ndarray:
    if every is None:
        return np.empty(0)
    count = math.floor(duration / every + 1e-9)
    grid = every * np.arange(count + 1)
    if duration - grid[-1] > 1e-9 * every:
        grid = np.append(grid, duration)
    return grid


def _row(state: _State, params: Parameters, control: str, k_block: float) -> np.ndarray:
    pop = state.population()
    f = _force(pop.extension, params)
    sigma = float(pop.weight @ f)
    block_energy = sigma * sigma / (2 * k_block) if control == "block" else 0.0
    b = params.bonds
    y = pop.extension / b.max_extension
    energy = float(pop.weight @ (-0.5 * b.chain_stiffness * b.max_extension**2 * np.log1p(-y * y)))
    acc = state.acc
    return np.array(
        [state.t, sigma, pop.bonded, state.v, state.x, state.puller, acc[0], acc[1], acc[2], acc[3], energy,
         block_energy, np.nan]
    )  # fmt: skip


def _stuck_row(state: _State, params: Parameters, t: float, vp: float, k_block: float, fraction: float) -> np.ndarray:
    puller = state.puller + vp * (t - state.t)
    sigma = k_block * (puller - state.x)
    acc = state.acc
    return np.array(
        [t, sigma, np.nan, 0.0, state.x, puller, acc[0], acc[1], np.nan, np.nan, np.nan, sigma**2 / (2 * k_block),
         fraction]
    )  # fmt: skip


def _kernel_rows(block: np.ndarray, k_block: float, control: str) -> list[np.ndarray]:
    sigma = block[:, 1]
    block_energy = sigma**2 / (2 * k_block) if control == "block" else np.zeros_like(sigma)
    full = np.c_[block, block_energy, np.full(sigma.size, np.nan)]
    return [full]


def _snapshot(state: _State) -> Snapshot:
    pop = state.population()
    return Snapshot(state.t, pop.age.copy(), pop.extension.copy(), pop.weight.copy())


def _jump(params: Parameters, sigma: float, aging: bool) -> float | None:
    from ..model.jump import jump_velocity

    jump = jump_velocity(params, sigma, "aging" if aging else "no-aging")
    return jump.velocity if jump.reachable else None


def _finish(
    rows: list[np.ndarray],
    chain_rows: list[np.ndarray],
    events: list[tuple[str, float, float, float]],
    snapshots: list[Snapshot],
    state: _State,
    params: Parameters,
    protocol: Protocol,
    control: str,
    k_block: float,
    steps: int,
    stop: str | None = None,
) -> TransientResult:
    from .cycles import classify, detect_cycles

    table = np.vstack([np.atleast_2d(r) for r in rows])
    order = np.argsort(table[:, 0], kind="stable")
    table = table[order]
    keep = np.r_[True, np.diff(table[:, 0]) > 0]
    table = table[keep]
    n0 = params.bonds.site_density
    time, sigma, bonded, v, x, puller = (table[:, k] for k in range(6))
    bonded = bonded / n0
    bonded = np.where(np.isnan(bonded), 0.0, bonded)  # the bonds of Eq 1 are set aside while the chains hold
    cycles = detect_cycles(time, sigma, v, protocol, events)
    regime, message = classify(time, sigma, v, protocol, cycles, events, control, stop)
    chain = table[:, 12] if chain_rows else None
    book = Bookkeeping(
        born=table[:, 6], broken=table[:, 7], work=table[:, 8], dissipation=table[:, 9], bond_energy=table[:, 10],
        block_energy=table[:, 11],
    )  # fmt: skip
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
        steps=steps,
        rejected=int(state.acc[5]),
    )


__all__ = ["Cycle", "run_transient"]
