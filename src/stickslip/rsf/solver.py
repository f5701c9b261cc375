"""The spring-slider driven by a loading protocol, integrated in log V and log theta.

Each protocol segment is integrated on its own (the solver stops exactly at a velocity change and restarts from
the state it reached), by LSODA with the analytic Jacobian: ``odeint`` on a uniform grid with ``every``, else
``solve_ivp`` at its own steps.  The regime is read off the last segment's accepted steps whatever the sampling.
A run whose slip rate passes :data:`BLOW_UP_FACTOR` times the fastest driving velocity stops and says so in
``status``/``message`` (docs/rsf.md, "Spring–slider").
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from .. import regimes
from ..errors import ModelError, ParameterError, StickslipError
from ..numerics.grid import sample_grid
from ..protocols import Protocol
from ..units import override_to_si, shorten, si_argument
from .params import RSFParams
from .results import RSFRun, Solution, assemble_run
from .stability import jacobian_at
from .system import EXP_CAP, System

__all__ = ["BLOW_UP_FACTOR", "evolve_state", "simulate"]

#: A run "blows up" when V exceeds this multiple of max(driving velocities, start velocity).
BLOW_UP_FACTOR = 1e10
RTOL = 1e-10
#: Most samples a trace with ``every`` may hold (1e7 samples: about 2 GB and 10 s).
MAX_SAMPLES = 10_000_000
#: Right-hand-side evaluations per protocol segment after which its pace is judged: the segment is refused where
#: that pace projects more than MAX_PROJECTED_CALLS for it (a clock that stops is refused at once, whatever the count).
MAX_CALLS = 1_000_000
#: Evaluations a segment may be projected to need, and take at most (~1 minute of CPU on solve_ivp's LSODA).
MAX_PROJECTED_CALLS = 10_000_000
#: Evaluations after which a solver whose clock has not moved (relative 1e-12) is declared stalled.
PROGRESS_CALLS = 20_000


#: The absolute tolerance of the carried integral of mu dt: out of reach, so that it never limits a step.
FREE_ATOL = 1e100
#: Evaluations a piece may be projected to need (from its pace so far) before LSODA gives way to Radau.
STIFF_PROJECTION = 1e8


class _Stalled(Exception):
    def __init__(
        self,
        time: float,
        projected: bool = False,
        state: np.ndarray | None = None,
        cost: tuple[int, float] | None = None,
    ) -> None:
        super().__init__(time)
        self.time = float(time)
        self.state = None if state is None else np.array(state, dtype=float)  # (a trial state near the stall)
        self.projected = projected  # not stuck: on its pace the piece would need over STIFF_PROJECTION evaluations
        self.cost = cost  # not stuck: (evaluations taken, projected for the piece) past MAX_PROJECTED_CALLS


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
    mean: bool = True,
) -> RSFRun:
    """Run ``protocol`` on the spring-slider, starting in steady sliding at ``start_velocity``.

    ``start_velocity`` defaults to the first segment's velocity; ``every``
    samples the trace every ``every`` seconds from t = 0, and at the run's end
    (the protocol's, or a blow-up's; a step longer than the run gives those two
    rows, t = 0 and the end, where ``run_transient`` refuses it; a number or a
    value with its unit, ``"0.5 s"``: text without a unit is refused); ``times`` (sorted,
    within the protocol) samples it at given times instead; neither changes
    the regime or the summary, which come from the solver's accepted steps.
    ``detect=False`` skips the regime detection (for fits, which call this
    hundreds of times); ``mean=False`` does not carry the integral of mu dt
    (``run_mean_friction`` is then nan), the same trace: a fit reads neither.
    """
    if not isinstance(params, RSFParams):
        raise ParameterError(f"params: expected RSFParams, got {type(params).__name__}")
    if not isinstance(protocol, Protocol):
        raise ParameterError(f"protocol: expected a Protocol, got {type(protocol).__name__}")
    _check_tolerances(rtol, atol)
    given = start_velocity
    v_start = protocol.initial_velocity if given is None else override_to_si(given, "velocity", "start_velocity")
    if not (math.isfinite(v_start) and v_start > 0):
        raise ParameterError(
            f"start velocity: expected a positive velocity for the initial steady state, got {v_start:g} m/s"
            + (" (the first segment holds; give --start-velocity)" if start_velocity is None else "")
        )
    system = System(params)
    # the solver also carries q = integral of mu dt (a last unknown that feeds nothing back): the run's mean
    # friction is q(T)/T from the solver's own steps, whatever the output sampling
    carried: Any = WithIntegral(system) if mean else system
    inner = slice(None, -1) if mean else slice(None)  # the system's own unknowns (less q where it is carried)
    # q's own error never limits a step (its tolerance is out of reach): the steps, and so the trace, are those of
    # the equations without it (a fit's search, which follows differences of 1e-12, takes the same path), and q is
    # integrated on them by the same formulas
    carried_atol = np.r_[np.full(system.size, atol), FREE_ATOL] if mean else atol
    grid = _grid(protocol, every, times)
    v_cap = BLOW_UP_FACTOR * max(float(np.max(protocol.velocities)), v_start)
    x_cap = _blow_up_level(params, max(float(np.max(protocol.velocities)), v_start))
    y = np.r_[system.steady_y(v_start), 0.0] if mean else np.asarray(system.steady_y(v_start), float)
    # Where a quasi-static slider may run away, odeint could step over the run-away between samples:
    # sample from the adaptive solver's interpolant instead, which watches every step.
    watch = grid is not None and params.eta == 0 and params.mass == 0 and _unstable_somewhere(params, protocol)
    t_parts, y_parts = [np.array([0.0])], [y[:, None]]
    piece_starts: list[tuple[float, np.ndarray, float]] = []  # (t0, the state there, vlp) of each piece integrated
    # without a grid the rows are the solver's steps: each piece's (t0, vlp, start state, steps, states, one Euler
    # step?), kept (as references) for a blow-up's summary, which is read off the solution of the whole run
    steps_of: list[tuple[float, float, np.ndarray, np.ndarray, np.ndarray, bool]] = []
    integral, reached = 0.0, 0.0
    status, message = "ok", ""
    last: Solution | None = None
    last_piece = len(protocol.segments) - 1
    for t0, t1, vlp in protocol.pieces():  # every piece's clock before any is integrated (a long hold would
        _check_clock(params, max(vlp, v_start if t0 == 0 else 0.0), t1)  # stall before the slide after it)
    for index, (t0, t1, vlp) in enumerate(protocol.pieces()):
        piece_starts.append((t0, y, vlp))
        short = None
        try:
            short = _short_piece(carried, y, t0, t1, vlp, grid)
            if short is not None:
                t_out, y_out, y_end, blown = short
            elif grid is None:
                t_out, y_out, y_end, blown, _ = _adaptive_piece(carried, y, t0, t1, vlp, x_cap, rtol, carried_atol)
                t_steps, y_steps = t_out, y_out
                if detect and index == last_piece and blown is None and mean and system.implicit:
                    # Radau's error norm is a mean over all the unknowns, q's included: its steps with q are not
                    # those of the equations alone, which a sampled run reads the regime off (below)
                    t_steps, y_steps = _regime_steps(system, y[inner], t0, t1, vlp, x_cap, rtol, atol, mean)
            else:
                inside = grid[(grid > t0) & (grid <= t1)]
                t_out, y_out, y_end, blown = _sampled_piece(carried, y, t0, t1, vlp, inside, x_cap, rtol, carried_atol,
                                                            watch)  # fmt: skip
                if detect and index == last_piece and blown is None:
                    # the regime is read off every accepted step of the last segment, whatever the sampling
                    t_steps, y_steps = _regime_steps(system, y[inner], t0, t1, vlp, x_cap, rtol, atol, mean)
        except (ZeroDivisionError, OverflowError) as exc:  # e.g. m V / sigma underflowing to 0 in dV/dt
            raise ModelError(_out_of_range(system, t0, t1, exc, vlp)) from None
        if grid is None:
            steps_of.append((t0, vlp, y, t_out, y_out, short is not None))
        if detect and index == last_piece and blown is None and short is None:  # a one-step piece has no steps
            steps_t, steps_y = np.r_[t0, t_steps], np.c_[y, y_steps][inner]
            last = Solution(t0, steps_t, steps_y, _interpolant(system, vlp, steps_t, steps_y, rtol, atol))
        if blown is not None and every is not None and not (t_out.size and t_out[-1] >= blown):
            # a sampled trace ends where the run stopped, as the solver's own steps do: its last row, the final
            # value and end time a summary reads, must not depend on --every
            t_out, y_out = np.r_[t_out, blown], np.c_[y_out, y_end]
        t_parts.append(t_out)
        y_parts.append(y_out)
        integral, reached = (float(y_end[-1]) if mean else math.nan), (t1 if blown is None else blown)
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
    if status != "ok" and detect and grid is None:  # a blow-up's extremes: of the run's solution, not of its steps
        last = Solution(0.0, t_all, y_all[inner], _run_interpolant(system, steps_of, inner, rtol, atol))
    run = assemble_run(system, protocol, t_all, y_all[inner], status, message, v_start, detect, last, rtol)
    if status != "ok" and detect and grid is not None:
        run = replace(run, regime=_unsampled_regime(run, params, protocol, v_start, rtol, atol, mean))
    if mean:
        run = replace(
            run, run_mean_friction=integral / reached if reached > 0 else float(run.friction[-1]),
            settled_mean_friction=_settled_mean(carried, t_all, y_all, piece_starts, integral, reached,
                                                run.regime.period, rtol, carried_atol),
        )  # fmt: skip
    return _requested(run, grid) if times is not None else run


def _unsampled_regime(
    run: RSFRun, params: RSFParams, protocol: Protocol, v_start: float, rtol: float, atol: float, mean: bool
) -> Any:
    """A sampled run's blow-up regime: that of the same run integrated at the solver's own steps (the summary of a
    run without ``every``, to the bit), never the samples' (their peak read 0.6056108691, 0.6056109684 and
    0.6056109762 at three samplings: round-27 tester); the rows' where that run does not blow up too."""
    try:
        unsampled = simulate(params, protocol, start_velocity=v_start, rtol=rtol, atol=atol, mean=mean)
    except StickslipError:  # (the sampled run went through: its trace's regime stands)
        return run.regime
    return unsampled.regime if unsampled.status == run.status else run.regime


def _run_interpolant(
    system: System, pieces: list[tuple[float, float, np.ndarray, np.ndarray, np.ndarray, bool]], inner: slice,
    rtol: float, atol: float,
) -> Callable[[np.ndarray], np.ndarray]:  # fmt: skip
    """The state at any sorted times of a run integrated at the solver's steps (``pieces`` as :func:`simulate`
    keeps them): each piece's own interpolant (:func:`_interpolant`; a one-Euler-step piece's straight line)."""
    starts = np.array([piece[0] for piece in pieces])
    parts = []
    for t0, vlp, y0, t_out, y_out, short in pieces:
        steps_t, steps_y = np.r_[t0, t_out], np.c_[y0, y_out][inner]
        if short:
            parts.append(lambda times, st=steps_t, sy=steps_y: np.array([np.interp(times, st, row) for row in sy]))
        else:
            parts.append(_interpolant(system, vlp, steps_t, steps_y, rtol, atol))

    def evaluate(times: np.ndarray) -> np.ndarray:
        times = np.asarray(times, dtype=float)
        which = np.clip(np.searchsorted(starts, times, side="right") - 1, 0, len(parts) - 1)
        out = np.empty((system.size, times.size))
        for i in np.unique(which).tolist():
            chosen = which == i
            out[:, chosen] = parts[i](times[chosen])
        return out

    return evaluate


def _settled_mean(
    carried: WithIntegral, t_rows: np.ndarray, y_rows: np.ndarray, starts: list[tuple[float, np.ndarray, float]],
    integral: float, end: float, period: float, rtol: float, atol: Any,
) -> float:  # fmt: skip
    """The mean of mu over :func:`stickslip.models.run.settled_mean`'s window of the last piece integrated (the
    protocol's last segment, whose regime is reported) from the carried integral q: q(end) less q at the window's
    start, which the solver reaches from the last row or piece start before it (each holds the solver's own q;
    none is interpolated), so that the mean does not depend on the sampling.  NaN where that short integration
    fails (the caller then takes the rows').  (The window was of [0, end]: a slide-hold-slide's second half held
    the hold's end, and its "steady sliding" mean read 0.576136 for the settled 0.576974.)"""
    if not end > 0:
        return math.nan
    start = regimes.settled_window_start(min(starts[-1][0], end) if starts else 0.0, end, period)
    k = max(int(np.searchsorted(t_rows, start, side="right")) - 1, 0)
    j = max(int(np.searchsorted([s[0] for s in starts], start, side="right")) - 1, 0)
    t_anchor, y_anchor = float(t_rows[k]), y_rows[:, k]
    if starts[j][0] > t_anchor:  # a piece began after the last row: its start is nearer, and on the same velocity
        t_anchor, y_anchor = starts[j][0], starts[j][1]
    if t_anchor == start:
        q = float(y_anchor[-1])
    else:
        out, ok = _odeint(carried, np.asarray(y_anchor, float), np.array([t_anchor, start]), starts[j][2], rtol, atol)
        if not ok:
            return math.nan
        q = float(out[-1, -1])
    return (integral - q) / (end - start)


class WithIntegral:
    """The equations of ``system`` with one more unknown last, q = integral of mu dt (dq/dt = mu), which no
    other equation reads; every other attribute is the system's."""

    def __init__(self, system: System) -> None:
        self.system = system
        self.size = system.size + 1
        o = system.offset
        self._x, self._psi = o, slice(o + 1, o + 1 + system.n)
        # the common case (System._rhs_classical's equations, mu inline): the wrapper's cost is per evaluation
        self.rhs = _classical_with_integral(system) if system.classical else self._rhs

    def __getattr__(self, name: str) -> Any:
        return getattr(self.system, name)

    def _rhs(self, t: float, y: np.ndarray, vlp: float) -> list[float]:
        inner = y[:-1]
        return [*self.system.rhs(t, inner, vlp), self.system.friction(float(inner[self._x]), inner[self._psi])]

    def jacobian(self, t: float, y: np.ndarray, vlp: float) -> np.ndarray:
        """The system's Jacobian bordered by dmu/dy (analytic: the classical and cut-off forms have one)."""
        s = self.system
        inner = y[:-1]
        jac = np.zeros((self.size, self.size))
        jac[:-1, :-1] = s.jacobian(t, inner, vlp)
        x = float(inner[self._x])
        psi = inner[self._psi].tolist()
        if s.cutoff is not None:
            jac[-1, self._x] = s.cutoff.direct(s.a, x)[0]
            jac[-1, self._psi] = [s.cutoff.evolution(b, p)[0] for b, p in zip(s.b, psi, strict=True)]
        else:
            jac[-1, self._x] = s.a
            jac[-1, self._psi] = s.b
        return jac


def _classical_with_integral(system: System) -> Callable[[float, np.ndarray, float], list[float]]:
    """:class:`WithIntegral`'s right-hand side for the classical form: System._rhs_classical's equations with mu
    inline, each law's state rate alone and the numbers bound as locals (the same arithmetic in the same order)."""
    v0, k, a, eta, mu0, exp, cap = system.v0, system.k, system.a, system.eta, system.mu0, math.exp, EXP_CAP
    terms = [(law.state_rate(v0, dc), b) for law, b, dc in zip(system.laws, system.b, system.dc, strict=True)]

    def rhs(t: float, y: np.ndarray, vlp: float) -> list[float]:
        x, *psi = y.tolist()
        psi.pop()  # q
        out = [0.0]
        G = 0.0
        mu = mu0 + a * x
        for (rate, b), p in zip(terms, psi):  # noqa: B905  (lengths match by construction)
            g = rate(x, p)
            out.append(g)
            G += b * g
            mu += b * p
        v = v0 * exp(x if x < cap else cap)
        out[0] = (k * (vlp - v) - G) / (a + eta * v)
        out.append(mu)
        return out

    return rhs


def _requested(run: RSFRun, grid: np.ndarray) -> RSFRun:
    """The run at the requested times only: the start (t = 0, always computed) is dropped when not asked for."""
    if grid[0] == 0.0 or run.time.size == 0 or run.time[0] != 0.0:
        return run
    keep = slice(1, None)
    return replace(
        run, time=run.time[keep], friction=run.friction[keep], slider_velocity=run.slider_velocity[keep],
        state=run.state[:, keep], load_point_displacement=run.load_point_displacement[keep],
        slider_displacement=run.slider_displacement[keep], load_point_velocity=run.load_point_velocity[keep],
    )  # fmt: skip


#: A slider whose inertial time m V/(sigma a) at its loading velocity is below this fraction of the segment cannot
#: stop by its inertia: a V that underflows there is a solver's trial step, not the slider's
NEGLIGIBLE_INERTIA = 1e-9


def _out_of_range(system: System, t0: float, t1: float, exc: Exception, vlp: float = 0.0) -> str:
    where = f"the rate-and-state equations left the floating-point range in the segment {t0:g} ... {t1:g} s ({exc})"
    tau = system.inertia * vlp / system.a if system.inertial and system.a > 0 else math.inf
    if isinstance(exc, ZeroDivisionError) and tau < NEGLIGIBLE_INERTIA * (t1 - t0):
        # (a stiff slider with m V/(sigma a) = 3e-16 s was "stopped" here while its steps without a grid ran on to
        # a steady slide at the closed-form friction: tests/test_rsf_box_draws.py)
        return f"rate-and-state solver failed in the segment {t0:g} ... {t1:g} s: {_negligible_inertia(tau, t0, t1)}"
    if system.inertial and isinstance(exc, ZeroDivisionError) and system.inertia > 1e-200:  # V underflowed
        return (
            f"the slider stopped in the segment {t0:g} ... {t1:g} s: its velocity fell below the floating-point"
            " range, and a slider with mass, whose equations are written in ln V, has no state of rest (the model"
            " has no answer after that): raise eta or a, or drop the mass (without it the slider creeps instead of"
            " stopping)"
        )
    if system.inertial:
        return (
            f"{where}: the slider's inertia m/σ = {system.inertia:.3g} s^2/m is too small to matter; drop the"
            " mass (the quasi-static slider is its limit; use eta for fast slip)"
        )
    return f"{where}: check the magnitudes of a, b, Dc, the stiffness, eta and v_ref"


def _blow_up_level(params: RSFParams, fastest: float) -> float:
    """ln(v_cap / v_ref), the slip rate at which a run is declared blown up; it must fit below EXP_CAP."""
    level = math.log(fastest) - math.log(params.v_ref) + math.log(BLOW_UP_FACTOR)
    if level > EXP_CAP - 10.0:  # the blow-up watch could not be represented: the run would stall, not report
        ratio = level - math.log(BLOW_UP_FACTOR)
        limit = EXP_CAP - 10.0 - math.log(BLOW_UP_FACTOR)
        raise ParameterError(
            f"velocity: {fastest:.3g} m/s is e^{ratio:.0f} times v_ref = {params.v_ref:.3g} m/s; the solver"
            f" represents V/v_ref up to about e^{limit:.0f} (give velocities and v_ref of comparable size)"
        )
    return level


#: Most state renewals (slip / Dc) up to a time t that the solver's clock (resolution ~1e-16 t) can follow.
MAX_RENEWALS = 1e12


def _check_clock(params: RSFParams, velocity: float, t_end: float) -> None:
    """ModelError when the state's time scale Dc/V is below the resolution of the clock at t_end.

    Beyond about 1e12 renewals the integrator, which steps in t, rounds its steps away and reports a
    blow-up or stalls (measured on steady sliding with a = b: 1e12 renewals follow it, 1e13 report a false blow-up).
    """
    dc = min(s.dc for s in params.states)
    renewals = velocity * t_end / dc
    if renewals > MAX_RENEWALS:
        raise ModelError(
            f"the run spans {renewals:.3g} state renewals (slip V t / Dc at {velocity:.3g} m/s up to"
            f" t = {t_end:.3g} s);"
            f" the solver's clock (double precision) follows at most {MAX_RENEWALS:.0e}: use a shorter protocol,"
            " a smaller velocity or a larger Dc"
        )


def _check_tolerances(rtol: Any, atol: Any) -> None:
    """ODEPACK takes a NaN or negative tolerance without complaint and then integrates nonsense."""
    for name, value in (("rtol", rtol), ("atol", atol)):
        if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
            raise ParameterError(f"{name}: expected a positive number, got {value!r}")
        if not (math.isfinite(value) and 0 < value < 1):
            raise ParameterError(f"{name}: expected a tolerance between 0 and 1, got {value!r}")


#: sample times this close (relative) beyond the protocol's ends are read at the end
END_SLACK = 1e-9


def _grid(protocol: Protocol, every: float | None, times: Any) -> np.ndarray | None:
    if every is not None and times is not None:
        raise ParameterError("every/times: give one of them, not both")
    end = protocol.duration
    if every is not None:
        written = every
        every = si_argument(every, "time", "every")  # text needs its unit ("5" is refused, as everywhere)
        if isinstance(every, bool) or not isinstance(every, (int, float, np.floating, np.integer)):
            raise ParameterError(f"every: expected a positive time step in s, got {shorten(written)}")
        every = float(every)
        if not (math.isfinite(every) and every > 0):
            shown = repr(written.strip()) if isinstance(written, str) else repr(every)
            raise ParameterError(f"every: expected a positive time step, got {shown}")
        count = end / every * (1 + 1e-12) + 1  # a float: end / 5e-324 s is beyond any integer we would build
        if not count <= MAX_SAMPLES:  # each sample holds about 180 bytes in memory until the trace is written
            raise ParameterError(
                f"every: {every:g} s gives {count:.3g} samples over {end:g} s; expected at most {MAX_SAMPLES:.0e}"
            )
        grid = sample_grid(every, end)
        # (a multiple within rounding of the end, or a step beyond it: then the run's two ends, t = 0 and its end,
        # as the docstring says; tests/test_rsf_simulate_every.py and test_edges.py's --every 1e300 s hold it)
        if grid[-1] < end:
            grid = np.append(grid[:-1] if grid.size > 1 else grid, end)
        return grid
    if times is None:
        return None
    try:
        grid = np.asarray(times, dtype=float).ravel()
    except (TypeError, ValueError):
        raise ParameterError(f"times: expected a sequence of sample times in s, got {shorten(times)}") from None
    if grid.size == 0 or not np.all(np.isfinite(grid)) or np.any(np.diff(grid) <= 0):
        raise ParameterError("times: expected finite, strictly increasing sample times")
    # a time within rounding of the end (a record's last row against a history summed from its pieces) is the
    # end: it is sampled there, never dropped
    slack = END_SLACK * max(end, float(np.max(np.abs(grid))))
    if grid[0] < -slack or grid[-1] > end + slack:
        raise ParameterError(f"times: expected times within the protocol, 0 ... {end:g} s")
    grid = np.clip(grid, 0.0, end)
    if np.any(np.diff(grid) <= 0):
        raise ParameterError(f"times: two sample times within rounding ({END_SLACK:g} relative) of the protocol's end")
    return grid


def _sampled_piece(
    system: System, y0: np.ndarray, t0: float, t1: float, vlp: float, inside: np.ndarray, x_cap: float,
    rtol: float, atol: float, watch: bool = False,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float | None]:  # fmt: skip
    if watch:
        return _dense_piece(system, y0, t0, t1, vlp, inside, x_cap, rtol, atol)
    t_eval = np.concatenate([[t0], inside, [] if inside.size and inside[-1] == t1 else [t1]])
    # a failed odeint call (e.g. a blow-up) is redone by the adaptive path, which locates the failure
    out, ok = _odeint(system, y0, t_eval, vlp, rtol, atol)
    if not ok or np.max(out[:, system.offset]) > x_cap:
        return _dense_piece(system, y0, t0, t1, vlp, inside, x_cap, rtol, atol)
    keep = slice(1, 1 + inside.size)
    return t_eval[keep], out[keep].T, out[-1], None


#: A segment is "short" when its duration times the fastest rate of the linearised equations is below this.
SHORT_PIECE = 1e-8


def _short_piece(
    system: System, y0: np.ndarray, t0: float, t1: float, vlp: float, grid: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, None] | None:
    """One Euler step over a segment far shorter than every time scale of the equations, or None.

    ODEPACK cannot start on an interval of 1e-300 s (it stalls); over a step h with h ||J|| <= 1e-8 the
    Euler step's error, about h ||J|| / 2 of the step's own change, is far below any tolerance.
    """
    h = t1 - t0
    with np.errstate(all="ignore"):  # a Jacobian beyond the floats only means "not short": the solver decides
        jac = jacobian_at(system, y0, vlp)
    rate = float(np.max(np.sum(np.abs(jac), axis=1)))  # the infinity norm bounds every eigenvalue
    if not (math.isfinite(rate) and h * rate < SHORT_PIECE):
        return None
    slope = np.asarray(system.rhs(t0, y0, vlp), dtype=float)
    if not np.all(np.isfinite(slope)):
        return None

    def state_at(t: np.ndarray) -> np.ndarray:
        return y0[:, None] + slope[:, None] * (t - t0)[None, :]

    inside = np.array([t1]) if grid is None else grid[(grid > t0) & (grid <= t1)]
    return inside, state_at(inside), state_at(np.array([t1]))[:, 0], None


def _dense_piece(
    system: System, y0: np.ndarray, t0: float, t1: float, vlp: float, inside: np.ndarray, x_cap: float,
    rtol: float, atol: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float | None]:  # fmt: skip
    t_steps, _, y_end, blown, dense = _adaptive_piece(
        system, y0, t0, t1, vlp, x_cap, rtol, atol, dense=True, watch=True
    )
    keep = inside[inside <= (float(t_steps[-1]) if t_steps.size else t0)]
    return keep, (dense(keep) if keep.size else np.empty((system.size, 0))), y_end, blown


def _unstable_somewhere(params: RSFParams, protocol: Protocol) -> bool:
    from .stability import growth_rate

    speeds = {float(v) for v in protocol.velocities if v > 0}
    return any(growth_rate(params, v) > 0 for v in speeds)


def _regime_steps(
    system: System, y0: np.ndarray, t0: float, t1: float, vlp: float, x_cap: float, rtol: float, atol: float,
    mean: bool,
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """The accepted steps of the equations alone (without q) over a piece, and the states there (with a zero row for
    q where the run carries it: it is not read there)."""
    t_steps, y_steps, _, _, _ = _adaptive_piece(system, y0, t0, t1, vlp, x_cap, rtol, atol)
    if mean:
        y_steps = np.r_[y_steps, np.zeros((1, y_steps.shape[1]))]
    return t_steps, y_steps


def _interpolant(system: System, vlp: float, t_steps: np.ndarray, y_steps: np.ndarray, rtol: float, atol: float) -> Any:
    """y at any sorted times within the steps, by the solver itself restarted from the accepted step before them.

    Cheaper than keeping scipy's interpolant for every step when only a few extremes and crossings are wanted.
    """

    def evaluate(times: np.ndarray) -> np.ndarray:
        # within the steps only: a tail reading before the segment's start (a segment shorter than the
        # relaxation time) is read at the start
        times = np.clip(np.asarray(times, dtype=float), t_steps[0], t_steps[-1])
        j = max(int(np.searchsorted(t_steps, times[0], side="right")) - 1, 0)
        out, ok = _odeint(system, y_steps[:, j], np.r_[t_steps[j], times], vlp, rtol, atol)
        if not ok:  # the accepted steps themselves, linearly between them: coarser, never invented
            return np.array([np.interp(times, t_steps, row) for row in y_steps])
        return out[1:].T

    return evaluate


def _odeint(
    system: System, y0: np.ndarray, grid: np.ndarray, vlp: float, rtol: float, atol: float
) -> tuple[np.ndarray, bool]:
    """odeint (LSODA) at ``grid`` and whether it succeeded with finite values (its failure warning is silenced:
    the caller reports or redoes a failed run)."""
    from scipy.integrate import odeint

    rest = _rest_solution(system, y0, grid, vlp, rtol, atol)
    if rest is not None:
        return rest, True
    jac = system.jacobian if system.has_jacobian else None
    failed = np.full((len(grid), len(y0)), np.nan), False
    if not system.implicit:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                # a slider with mass is watched for LSODA keeping to explicit steps on its inertial time (its pace
                # projected); a massless one is not (the wrapper cost a fit's 1.4 million evaluations ~1 s in 37)
                rhs = _counted(system, grid[0], grid[-1], limit=False) if system.inertial else system.rhs
                out, info = odeint(
                    rhs, y0, grid, args=(vlp,), Dfun=jac, rtol=rtol, atol=atol, tfirst=True, mxstep=200_000,
                    full_output=True,
                )  # fmt: skip
        except (ZeroDivisionError, OverflowError):  # a trial step far out (m V / sigma underflowing to 0 in dV/dt)
            return failed
        except _Stalled as stalled:
            if not stalled.projected:
                return failed
            _take_implicit_steps(system)
        else:
            return out, info.get("message") == "Integration successful." and bool(np.all(np.isfinite(out)))
    try:  # (odeint is LSODA only: the implicit steps at the same times)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sol = _solve(system, y0, grid[0], grid[-1], vlp, rtol, atol, False, t_eval=grid)
    except (_Stalled, ValueError, ArithmeticError):
        return failed
    if sol.status != 0 or len(sol.t) != len(grid):  # (no time of the grid reached: solve_ivp's y is then a list)
        return failed
    out = sol.y.T
    return out, bool(np.all(np.isfinite(out)))


#: A piece starts at rest when the state's distance to the equilibrium, -J^-1 f, is below this fraction of the
#: tolerance in every unknown.
REST_FRACTION = 1e-3


def _rest_solution(
    system: Any, y0: np.ndarray, grid: np.ndarray, vlp: float, rtol: float, atol: Any
) -> np.ndarray | None:
    """The piece's states at ``grid`` where it starts at rest (:func:`_at_rest`): y0 throughout, and a carried
    q = integral of mu dt growing at that mu; else None."""
    carried = isinstance(system, WithIntegral)
    inner = y0[:-1] if carried else y0
    own_atol = atol[:-1] if carried and np.ndim(atol) else atol
    if not _at_rest(system.system if carried else system, inner, vlp, rtol, own_atol):
        return None
    states = np.tile(y0, (len(grid), 1))
    if carried:
        mu = float(system.rhs(grid[0], y0, vlp)[-1])
        states[:, -1] = y0[-1] + mu * (grid - grid[0])
    return states


def _at_rest(system: System, y0: np.ndarray, vlp: float, rtol: float, atol: Any) -> bool:
    """Whether ``y0`` is the stable steady sliding at ``vlp`` to within rounding: the piece then stays there.

    Its solution is the equilibrium y* = y0 - J^-1 f(y0) approached from y0, so y0 at every time is the solution
    to within |J^-1 f| (below :data:`REST_FRACTION` of the tolerance).  odeint cannot be trusted with it: where
    f(y0) is rounding alone (1e-12 where k V / a is 1e4 1/s), LSODA kept its first step, sqrt(rtol) x the first
    output time, for the whole piece, 10 million evaluations and ~10 s where 60 do (docs/rsf.md, "A piece that
    starts at rest").  An unstable equilibrium is left to the solver: rounding is the seed of its growth."""
    with np.errstate(all="ignore"):  # (a value beyond the floats only means "not at rest": the solver decides)
        slope = np.asarray(system.rhs(0.0, y0, vlp), dtype=float)
        jac = jacobian_at(system, y0, vlp)
        if not (np.all(np.isfinite(slope)) and np.all(np.isfinite(jac))):
            return False
        scale = rtol * np.abs(y0) + atol
        norm = float(np.max(np.sum(np.abs(jac), axis=1)))
        # |J^-1 f| >= |f| / ||J||: most pieces (a velocity step's) are told apart here, without an eigenvalue
        if not norm > 0 or float(np.max(np.abs(slope) / scale)) > REST_FRACTION * norm:
            return False
        if float(np.max(np.linalg.eigvals(jac).real)) >= 0.0:
            return False
        try:
            offset = np.linalg.solve(jac, slope)
        except np.linalg.LinAlgError:
            return False
    return bool(float(np.max(np.abs(offset) / scale)) <= REST_FRACTION)


def _take_implicit_steps(system: System) -> None:
    """From now on the run integrates ``system`` by Radau (implicit) instead of LSODA: LSODA was found keeping to
    its explicit steps on a stiff problem (see :func:`_counted`), which it may do again on any piece."""
    getattr(system, "system", system).implicit = True  # (the system itself, under a WithIntegral)


def _solve(
    system: System, y0: np.ndarray, t0: float, t1: float, vlp: float, rtol: float, atol: float, dense: bool,
    method: str = "LSODA", events: Any = None, t_eval: Any = None,
) -> Any:  # fmt: skip
    """solve_ivp from ``t0`` to ``t1``, its evaluations counted (:func:`_counted`)."""
    from scipy.integrate import solve_ivp

    if method == "LSODA" and system.implicit:
        method = "Radau"
    jac = system.jacobian if system.has_jacobian else None
    return solve_ivp(_counted(system, t0, t1), (t0, t1), y0, method=method, args=(vlp,), jac=jac, rtol=rtol,
                     atol=atol, events=events, dense_output=dense, t_eval=t_eval)  # fmt: skip


def _adaptive_piece(
    system: System, y0: np.ndarray, t0: float, t1: float, vlp: float, x_cap: float, rtol: float, atol: float,
    dense: bool = False, watch: bool = False,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float | None, Any]:  # fmt: skip
    """(accepted step times after t0, states there, final state, blow-up time or None, interpolant or None).

    Without ``watch`` the steps are taken without the blow-up event (scipy checks events at a cost of about
    twice the integration); a run that fails or passes the cap is redone with it.
    """
    if not watch:
        try:
            fast = _quiet_solve(system, y0, t0, t1, vlp, rtol, atol, dense)
        except _Stalled as stalled:
            # a quasi-static slider whose slip rate runs away stalls the unwatched solver once past the cap (its
            # clock stops as V grows without bound): that is the blow-up, which the watched path below locates
            # and reports, as a sampled run does, not a stiffness to loosen
            running_away = stalled.state is not None and float(stalled.state[system.offset]) > 0.5 * x_cap
            if not running_away and (not stalled.projected or system.implicit):
                raise _stall_error(stalled, t0, t1, system) from None
            fast = None
            if not running_away:
                _take_implicit_steps(system)  # the watched path below, by Radau
        x = fast.y[system.offset] if fast is not None else None
        if fast is not None and fast.status == 0 and np.all(np.isfinite(fast.y)) and np.max(x) <= x_cap:
            return fast.t[1:], fast.y[:, 1:], fast.y[:, -1], None, fast.sol

    o = system.offset

    def blow_up(t: float, y: np.ndarray, vlp: float) -> float:
        return float(y[o]) - x_cap

    blow_up.terminal = True  # type: ignore[attr-defined]
    blow_up.direction = 1  # type: ignore[attr-defined]
    try:
        with warnings.catch_warnings():
            # LSODA's own warning on a failure is replaced by the ModelError or blow-up report below
            warnings.simplefilter("ignore", UserWarning)
            try:
                sol = _solve(system, y0, t0, t1, vlp, rtol, atol, dense, events=blow_up)
            except ValueError:
                # LSODA's interpolant can disagree in sign with its own step ends when the slip rate runs away,
                # so scipy's event root-finder has no bracket; Radau's collocation polynomial passes through
                # the step ends exactly, so the same event is bracketed there.
                sol = _solve(system, y0, t0, t1, vlp, rtol, atol, dense, method="Radau", events=blow_up)
            except _Stalled as stalled:
                if not stalled.projected or system.implicit:
                    raise
                _take_implicit_steps(system)
                sol = _solve(system, y0, t0, t1, vlp, rtol, atol, dense, events=blow_up)
    except _Stalled as stalled:
        raise _stall_error(stalled, t0, t1, system) from None
    blown = float(sol.t_events[0][0]) if sol.t_events[0].size else None
    if blown is None and sol.status != 0:
        t_fail = float(sol.t[-1])
        x_fail = float(sol.y[o, -1])
        if x_fail > 0.5 * x_cap:  # the solver gave up while the slip rate ran away: a blow-up
            blown = t_fail
        elif system.inertial and not system.implicit:
            # LSODA gave up on a slider with mass far below V0 (stiff: its inertial time m V/(sigma a)), where
            # implicit steps go on; a massless run that LSODA cannot follow is refused as before (b = 1e300: Radau
            # "integrated" it through overflows)
            _take_implicit_steps(system)
            return _adaptive_piece(system, y0, t0, t1, vlp, x_cap, rtol, atol, dense, watch=True)
        elif system.inertial:
            raise _inertia_error(system, t_fail, x_fail, t0, t1, "failed")
        else:
            raise ModelError(
                f"rate-and-state solver failed at t = {t_fail:.6g} s ({sol.message}): the equations cannot be"
                " integrated with these parameters; check the magnitudes of a, b, Dc, the stiffness and v_ref"
            )
    return sol.t[1:], sol.y[:, 1:], sol.y[:, -1], blown, sol.sol


def _counted(system: System, t0: float, t1: float, limit: bool = True) -> Callable[[float, np.ndarray, float], Any]:
    """The right-hand side, raising _Stalled after MAX_CALLS evaluations or as soon as the clock stops moving, and
    (``projected``) where its pace projects more than STIFF_PROJECTION evaluations for the piece.  ``limit=False``
    (a sampled trace, which may need more than MAX_CALLS in all): the projection only."""
    calls = [0]
    checkpoint = [t0]

    def rhs(t: float, y: np.ndarray, vlp: float) -> Any:
        calls[0] += 1
        if calls[0] % PROGRESS_CALLS == 0:
            # a clock that has not moved in PROGRESS_CALLS evaluations is stuck for good: say so now
            if limit and t - checkpoint[0] <= 1e-12 * max(abs(t), t1 - t0):
                raise _Stalled(t, state=y)
            # LSODA can stay with its explicit (Adams) steps on a stiff problem, each held to the fastest time
            # scale (a slider with mass far below V0: m V/(sigma a) = 1e-12 s, 3e-10 s steps): on its pace
            # it would run for hours; the caller redoes the piece by implicit steps (_take_implicit_steps)
            if calls[0] * (t1 - t0) > STIFF_PROJECTION * (t - t0):
                raise _Stalled(t, projected=True, state=y)
            # past MAX_CALLS a piece that keeps its pace goes on (fast stick-slip: 2.5 million evaluations for 100 s
            # at 2.4 mm/s, ~40,000 a cycle), one whose pace projects past MAX_PROJECTED_CALLS is refused
            projected = calls[0] * (t1 - t0) / (t - t0)
            if limit and calls[0] > MAX_CALLS and projected > MAX_PROJECTED_CALLS:
                raise _Stalled(t, state=y, cost=(calls[0], projected))
            checkpoint[0] = t
        return system.rhs(t, y, vlp)

    return rhs


def _inertia_error(system: System, t_fail: float, x_fail: float, t0: float, t1: float, what: str) -> ModelError:
    tau = system.inertia * system.v0 * math.exp(min(x_fail, EXP_CAP)) / system.a
    return ModelError(f"rate-and-state solver {what} at t = {t_fail:.6g} s: {_negligible_inertia(tau, t0, t1)}")


def _negligible_inertia(tau: float, t0: float, t1: float) -> str:
    return (
        f"the slider's inertial time mV/(σa) = {tau:.3g} s is too short beside the run ({t1 - t0:.3g} s); inertia "
        "this small does not matter, drop the mass (the quasi-static slider is its limit; use eta for fast slip)"
    )


def _stall_error(stalled: _Stalled, t0: float, t1: float, system: System | None = None) -> ModelError:
    """The stall in words; with a slider with mass, its inertial time where it stalled (the stiffness that
    neither LSODA nor Radau's implicit steps could follow)."""
    if stalled.cost is not None:
        taken, projected = stalled.cost
        return ModelError(
            f"rate-and-state solver: the segment {t0:g} ... {t1:g} s took {taken:,} evaluations to reach "
            f"t = {stalled.time:.6g} s, on pace for about {projected:,.0f} (more than {MAX_PROJECTED_CALLS:,}, about a "
            "minute of CPU): each slip or swing needs many steps at these a, b, Dc and stiffness; run a shorter segment"
        )
    if system is not None and system.inertial and stalled.state is not None:
        return _inertia_error(system, stalled.time, float(stalled.state[system.offset]), t0, t1, "stalled")
    if system is not None and not system.regularized:  # the classical form is already in use: no advice to take it
        remedy = "(e.g. a very stiff spring or a tiny a); loosen the spring or check the magnitudes of a, b and Dc"
    else:
        remedy = (
            "(e.g. the regularised form far below V0 under a very stiff spring); loosen the spring or use the"
            " classical form"
        )
    return ModelError(
        f"rate-and-state solver stalled at t = {stalled.time:.6g} s (in the segment "
        f"{t0:g} ... {t1:g} s): the equations are too stiff here {remedy}"
    )


def _quiet_solve(
    system: System, y0: np.ndarray, t0: float, t1: float, vlp: float, rtol: float, atol: float, dense: bool
) -> Any:
    """solve_ivp (LSODA) without events; None where it raises (the watched path then reports)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return _solve(system, y0, t0, t1, vlp, rtol, atol, dense)
    except (ValueError, ArithmeticError):
        return None


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
