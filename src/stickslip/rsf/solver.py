"""The spring-slider driven by a loading protocol, integrated in log V and log theta.

Each protocol segment is integrated on its own, with the segment's load-point
velocity held fixed in the right-hand side, so the solver never steps across a
velocity change: it stops exactly there and restarts from the state it reached.
With ``every`` the trace is sampled on a uniform grid by the solver's own
interpolant (ODEPACK LSODA through ``scipy.integrate.odeint``, analytic
Jacobian); without it the trace holds the solver's own adaptive steps
(``solve_ivp`` LSODA).  Both switch between non-stiff and stiff methods.

A quasi-static slider (no radiation damping, no mass) can reach infinite slip
rate in finite time.  Such a run stops where the slip rate passes
:data:`BLOW_UP_FACTOR` times the fastest driving velocity and says so in
``status``/``message``; it never returns the solver's garbage.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from ..errors import ModelError, ParameterError
from ..numerics.budget import require_rsf_budget
from ..protocols import Protocol
from .params import RSFParams
from .results import RSFRun, assemble_run
from .system import EXP_CAP, System

__all__ = ["BLOW_UP_FACTOR", "evolve_state", "simulate"]

#: A run "blows up" when V exceeds this multiple of max(driving velocities, start velocity).
BLOW_UP_FACTOR = 1e10
RTOL = 1e-10
#: Right-hand-side evaluations allowed per protocol segment before a run is declared stalled.
MAX_CALLS = 1_000_000


class _Stalled(Exception):
    def __init__(self, time: float) -> None:
        super().__init__(time)
        self.time = float(time)


ATOL = 1e-12


def simulate(
    params: RSFParams,
    protocol: Protocol,
    *,
    start_velocity: float | None = None,
    every: float | None = None,
    times: Any = None,
    rtol: float = RTOL,
    atol: float = ATOL,
    detect: bool = True,
) -> RSFRun:
    """Run ``protocol`` on the spring-slider, starting in steady sliding at ``start_velocity``.

    ``start_velocity`` defaults to the first segment's velocity; ``every``
    samples the trace every ``every`` seconds from t = 0; ``times`` (sorted,
    within the protocol) samples it at given times instead.  ``detect=False``
    skips the regime detection (for fits, which call this hundreds of times).
    """
    require_rsf_budget(params, protocol, start_velocity)
    if not isinstance(params, RSFParams):
        raise ParameterError(f"params: expected RSFParams, got {type(params).__name__}")
    if not isinstance(protocol, Protocol):
        raise ParameterError(f"protocol: expected a Protocol, got {type(protocol).__name__}")
    v_start = protocol.initial_velocity if start_velocity is None else float(start_velocity)
    if not (math.isfinite(v_start) and v_start > 0):
        raise ParameterError(
            f"start velocity: expected a positive velocity for the initial steady state, got {v_start:g} m/s"
            + (" (the first segment holds; give --start-velocity)" if start_velocity is None else "")
        )
    system = System(params)
    grid = _grid(protocol, every, times)
    v_cap = BLOW_UP_FACTOR * max(float(np.max(protocol.velocities)), v_start)
    x_cap = min(math.log(v_cap / params.v_ref), EXP_CAP - 10.0)
    y = system.steady_y(v_start)
    # Where a quasi-static slider may run away, odeint could step over the run-away between samples:
    # sample from the adaptive solver's interpolant instead, which watches every step.
    watch = grid is not None and params.eta == 0 and params.mass == 0 and _unstable_somewhere(params, protocol)
    t_parts, y_parts = [np.array([0.0])], [y[:, None]]
    status, message = "ok", ""
    for t0, t1, vlp in protocol.pieces():
        if grid is None:
            t_out, y_out, y_end, blown = _adaptive_piece(system, y, t0, t1, vlp, x_cap, rtol, atol)
        else:
            inside = grid[(grid > t0) & (grid <= t1)]
            t_out, y_out, y_end, blown = _sampled_piece(system, y, t0, t1, vlp, inside, x_cap, rtol, atol, watch)
        t_parts.append(t_out)
        y_parts.append(y_out)
        if blown is not None:
            status = "blow-up"
            message = (
                f"blow-up: the slip rate passed {v_cap:.3g} m/s ({BLOW_UP_FACTOR:.0e} x the driving velocity) at "
                f"t = {blown:.6g} s; without radiation damping or mass the quasi-static spring-slider has no "
                "meaningful solution from here on (give eta or a mass); the trace stops there"
            )
            break
        y = y_end
    t_all = np.concatenate(t_parts)
    y_all = np.concatenate(y_parts, axis=1)
    return assemble_run(system, protocol, t_all, y_all, status, message, v_start, detect)


def _grid(protocol: Protocol, every: float | None, times: Any) -> np.ndarray | None:
    if every is not None and times is not None:
        raise ParameterError("every/times: give one of them, not both")
    end = protocol.duration
    if every is not None:
        every = float(every)
        if not (math.isfinite(every) and every > 0):
            raise ParameterError(f"every: expected a positive time step, got {every!r}")
        count = math.floor(end / every * (1 + 1e-12)) + 1
        if count > 50_000_000:
            raise ParameterError(f"every: {every:g} s gives {count} samples over {end:g} s; expected at most 5e7")
        return np.arange(count) * every
    if times is None:
        return None
    grid = np.asarray(times, dtype=float).ravel()
    if grid.size == 0 or not np.all(np.isfinite(grid)) or np.any(np.diff(grid) <= 0):
        raise ParameterError("times: expected finite, strictly increasing sample times")
    if grid[0] < 0 or grid[-1] > end * (1 + 1e-12):
        raise ParameterError(f"times: expected times within the protocol, 0 ... {end:g} s")
    return grid


def _sampled_piece(
    system: System, y0: np.ndarray, t0: float, t1: float, vlp: float, inside: np.ndarray, x_cap: float,
    rtol: float, atol: float, watch: bool = False,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float | None]:  # fmt: skip
    from scipy.integrate import odeint

    if watch:
        return _dense_piece(system, y0, t0, t1, vlp, inside, x_cap, rtol, atol)
    t_eval = np.concatenate([[t0], inside, [] if inside.size and inside[-1] == t1 else [t1]])
    jac = system.jacobian if system.has_jacobian else None
    with warnings.catch_warnings():
        # A failed odeint call (e.g. a blow-up) is detected below from its report and
        # redone by the adaptive path, which locates the failure; its warning adds nothing.
        warnings.simplefilter("ignore")
        out, info = odeint(
            system.rhs, y0, t_eval, args=(vlp,), Dfun=jac, rtol=rtol, atol=atol, tfirst=True, mxstep=200_000,
            full_output=True,
        )  # fmt: skip
    x = out[:, system.offset]
    if info.get("message") != "Integration successful." or not np.all(np.isfinite(out)) or np.max(x) > x_cap:
        return _dense_piece(system, y0, t0, t1, vlp, inside, x_cap, rtol, atol)
    keep = slice(1, 1 + inside.size)
    return t_eval[keep], out[keep].T, out[-1], None


def _dense_piece(
    system: System, y0: np.ndarray, t0: float, t1: float, vlp: float, inside: np.ndarray, x_cap: float,
    rtol: float, atol: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float | None]:  # fmt: skip
    t_end, dense, y_end, blown = _adaptive_piece(system, y0, t0, t1, vlp, x_cap, rtol, atol, dense=True)
    keep = inside[inside <= t_end]
    return keep, (dense(keep) if keep.size else np.empty((system.size, 0))), y_end, blown


def _unstable_somewhere(params: RSFParams, protocol: Protocol) -> bool:
    from .stability import growth_rate

    speeds = {float(v) for v in protocol.velocities if v > 0}
    return any(growth_rate(params, v) > 0 for v in speeds)


def _adaptive_piece(
    system: System, y0: np.ndarray, t0: float, t1: float, vlp: float, x_cap: float, rtol: float, atol: float,
    dense: bool = False,
) -> tuple[Any, Any, np.ndarray, float | None]:  # fmt: skip
    from scipy.integrate import solve_ivp

    o = system.offset

    def blow_up(t: float, y: np.ndarray, vlp: float) -> float:
        return float(y[o]) - x_cap

    blow_up.terminal = True  # type: ignore[attr-defined]
    blow_up.direction = 1  # type: ignore[attr-defined]
    jac = system.jacobian if system.has_jacobian else None
    calls = [0]

    def rhs(t: float, y: np.ndarray, vlp: float) -> list[float]:
        calls[0] += 1
        if calls[0] > MAX_CALLS:
            raise _Stalled(t)
        return system.rhs(t, y, vlp)

    try:
        with warnings.catch_warnings():
            # LSODA's own warning on a failure is replaced by the ModelError or blow-up report below
            warnings.simplefilter("ignore", UserWarning)
            try:
                sol = solve_ivp(
                    rhs, (t0, t1), y0, method="LSODA", args=(vlp,), jac=jac, rtol=rtol, atol=atol, events=blow_up,
                    dense_output=dense,
                )  # fmt: skip
            except ValueError:
                # LSODA's interpolant can disagree in sign with its own step ends when the slip rate runs away,
                # so scipy's event root-finder has no bracket; Radau's collocation polynomial passes through
                # the step ends exactly, so the same event is bracketed there.
                calls[0] = 0
                sol = solve_ivp(
                    rhs, (t0, t1), y0, method="Radau", args=(vlp,), jac=jac, rtol=rtol, atol=atol, events=blow_up,
                    dense_output=dense,
                )  # fmt: skip
    except _Stalled as stalled:
        raise ModelError(
            f"rate-and-state solver stalled at t = {stalled.time:.6g} s ({MAX_CALLS} evaluations in the segment "
            f"{t0:g} ... {t1:g} s): the equations are too stiff here (e.g. the regularised form far below V0 "
            "under a very stiff spring); loosen the spring or use the classical form"
        ) from None
    blown = float(sol.t_events[0][0]) if sol.t_events[0].size else None
    if blown is None and sol.status != 0:
        t_fail = float(sol.t[-1])
        x_fail = float(sol.y[o, -1])
        if x_fail > 0.5 * x_cap:  # the solver gave up while the slip rate ran away: a blow-up
            blown = t_fail
        elif system.inertial:
            v = system.v0 * math.exp(min(x_fail, EXP_CAP))
            tau = system.inertia * v / system.a
            raise ModelError(
                f"rate-and-state solver failed at t = {t_fail:.6g} s: the slider's inertial time m V/(sigma a) = "
                f"{tau:.3g} s is too short beside the run ({t1 - t0:.3g} s); inertia this small does not matter, "
                "drop the mass (the quasi-static slider is its limit; use eta for fast slip)"
            )
        else:
            raise ModelError(f"rate-and-state solver failed at t = {t_fail:.6g} s ({sol.message})")
    if dense:
        return float(sol.t[-1]), sol.sol, sol.y[:, -1], blown
    return sol.t[1:], sol.y[:, 1:], sol.y[:, -1], blown


def evolve_state(
    params: RSFParams, velocity: float, times: Any, theta0: Any = None, rtol: float = RTOL, atol: float = ATOL
) -> tuple[np.ndarray, np.ndarray]:
    """State and friction when the slider itself is driven at constant ``velocity`` (an infinitely stiff rig).

    ``theta0`` (one value per state variable, s; > 0) defaults to steady state at
    ``params.v_ref``.  Returns ``(theta, friction)`` at ``times`` (from t = 0),
    ``theta`` with one row per state variable.
    """
    from scipy.integrate import odeint

    system = System(params)
    v = float(velocity)
    if not (math.isfinite(v) and v > 0):
        raise ParameterError(f"velocity: expected a positive slider velocity, got {velocity!r}")
    t = np.asarray(times, dtype=float)
    x = math.log(v / params.v_ref)
    if theta0 is None:
        psi0 = np.zeros(system.n)
    else:
        th = np.broadcast_to(np.asarray(theta0, dtype=float), (system.n,))
        if not np.all(np.isfinite(th) & (th > 0)):
            raise ParameterError(f"theta0: expected positive state values (s), got {theta0!r}")
        psi0 = np.log(th / system.theta(np.zeros(system.n)))

    def rhs(tt: float, psi: np.ndarray) -> list[float]:
        g = [law.rate(x, float(p), system.v0, dc)[0] for law, p, dc in zip(system.laws, psi, system.dc, strict=True)]
        mudot = sum(b * gi for b, gi in zip(system.b, g, strict=True)) / system.one_minus_h
        return [gi + hi * mudot for gi, hi in zip(g, system.h, strict=True)]

    grid = np.concatenate([[0.0], t]) if t.size == 0 or t[0] != 0 else t
    psi = odeint(rhs, psi0, grid, rtol=rtol, atol=atol, tfirst=True, mxstep=200_000)
    psi = psi[-t.size :].T if t.size else np.empty((system.n, 0))
    return system.theta(psi), system.friction_many(np.full(t.size, x), psi)
