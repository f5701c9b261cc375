"""The time-dependent bond model (Eqs 1-5, :func:`stickslip.transient.run_transient`) behind the interface."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import regimes
from ..parameters import Parameters
from ..protocols import Protocol
from .base import Boundary, Capabilities, Rig
from .bond import STIFFNESS_KEYS, BondModel
from .run import Run, time_mean

NAN = math.nan
#: relative stress change that counts as none (stickslip.transient.cycles.SETTLED, the solver's own verdict's)
SETTLED = 1e-5


class Transient(BondModel):
    """The population balance of bonds under any piecewise-constant protocol, rigid or through the block.

    ``start``: "empty" (no bonds, no stress; the default) or "steady" (the steady population at the first
    segment's velocity, or at the setting ``start_velocity``).  A spring rig's ``mass`` and ``damping`` give the
    block inertia (run_transient's ``mass``, ``damping``).  Settings: those of ``run_transient``
    (``stick_population``, ``aging``, ``start_velocity``, ``every``, ``rtol``, ``max_step``, ``max_steps``,
    ``max_time``, ``reduction``, ``snapshot_times``, ``progress``).
    """

    name = "transient"
    aliases = ("time-dependent", "population-balance")
    description = "bond model, time-dependent population balance (Eqs 1-5)"
    capabilities = Capabilities(
        controls=("spring", "velocity"),
        protocols="any",
        damping=True,
        mass=True,
        settings=(
            "stick_population", "aging", "start_velocity", "every", "rtol", "max_step", "max_steps", "max_time",
            "reduction", "snapshot_times", "progress",
        ),
    )  # fmt: skip
    sweep_start = "steady"
    requires = ("stickslip.transient",)

    def run(
        self, params: Parameters, protocol: Protocol, rig: Rig | None = None, *, start: Any = None, **settings: Any
    ) -> Run:
        from ..transient import run_transient

        rig = self.check(protocol, rig, settings)
        control = "velocity" if rig.control == "velocity" else "block"
        if control == "velocity" and settings.get("stick_population") is True:
            # in the interface's words (a rig's control 'spring', --control spring), not run_transient's 'block'
            from ..errors import ParameterError

            raise ParameterError(
                "stick_population: the attached chains hold a slider that a spring drives: they need spring control"
                " (--control spring; in Python a Rig(control='spring'), the default rig), got velocity control"
            )
        if rig.stiffness is not None:
            settings["stiffness"] = rig.stiffness
        if rig.has_mass or rig.has_damping:  # the block's inertia and damping (docs/extensions.md section 4)
            settings.update(mass=rig.mass, damping=rig.damping)
        result = run_transient(params, protocol, control=control, start="empty" if start is None else start, **settings)
        return transient_run(result, protocol, resolution=settings.get("rtol", _default_rtol()))

    def estimate_seconds(
        self, params: Parameters, protocol: Protocol, rig: Rig | None = None, *, start: Any = None, **settings: Any
    ) -> float:
        """The CPU seconds a run should take (``estimate_cost``, no step taken); a sweep runs its dearest first."""
        from ..transient.solver import estimate_cost

        rig = self.check(protocol, rig, settings)
        taken = ("stick_population", "aging", "start_velocity", "every", "rtol", "max_step", "reduction")
        options = {k: v for k, v in settings.items() if k in taken}
        if rig.stiffness is not None:
            options["stiffness"] = rig.stiffness
        if rig.has_mass:
            options["mass"] = rig.mass
        control = "velocity" if rig.control == "velocity" else "block"
        start = "empty" if start is None else start
        return estimate_cost(params, protocol, control=control, start=start, **options).seconds

    def describe_start(self, start: Any, protocol: Protocol, settings: Any = None, run: Run | None = None) -> str:
        """Where the run begins; given the ``run``, the start it really made: a steady start below Vc through the
        block begins sliding just above Vc under σc (run_transient moves it to the stable side), not at V0."""
        from ..display import velocity

        if start is None or start == "empty":
            return "empty: no bonds, no stress"
        if start == "steady":
            at = float((settings or {}).get("start_velocity") or protocol.segments[0].velocity)
            began = float(run.slider_velocity[0]) if run is not None and run.slider_velocity.size else at
            vc = float(run.summary.get("critical_velocity", NAN)) if run is not None else NAN
            if math.isfinite(began) and abs(began - at) > 1e-9 * max(abs(at), abs(began)):
                held = run is not None and run.stress is not None
                sigma = f", σ = {float(run.stress[0]):.4g} Pa" if held else ""
                critical = f" = {velocity(vc, 4)}" if math.isfinite(vc) else ""
                return (
                    f"steady population at {velocity(began, 4)}, just above Vc{critical}{sigma}: {velocity(at, 4)} is"
                    " below Vc"
                )
            return f"steady population at {velocity(at, 4)}"
        return f"start {start!r}"

    def stability_boundary(self, fixed: Any, x: str, y: str, frame: Any = None) -> list[Boundary]:
        """Kc(V0) of the linear stability of steady sliding, in the plane (V0, a stiffness key).

        Kc at BOUNDARY_VELOCITIES log-spaced velocities over the rows' V0 and, where the steady curve's minimum Vc
        (Eq 9) lies among them, at Vc (1 - 10^-j), j = 1..6: Kc falls to 0 at Vc (dsigma/dV = 0, the Hopf
        frequency to 0), about linearly in Vc - V0, so these carry the curve down through the decades of
        stiffness a sweep spans (the log grid alone jumps from ~1e9 Pa/m to 0 between two velocities).  Taken
        from the fastest down, and no slower once Kc is BEYOND_ROWS times the rows' stiffest (Kc grows as V0
        falls below Vc: the slower ones, the dearest, would be drawn outside the plot).  Each Kc by
        :func:`_critical_stiffness_for_plot`; a velocity where Kc is not defined is skipped.  The curve drawn
        between them is :func:`_boundary_curve`'s."""
        stiffness_axes = ("block.height", *STIFFNESS_KEYS)
        if frame is None or "pulling_velocity" not in (x, y) or not ({x, y} & set(stiffness_axes)):
            return []
        from ..errors import ModelError, ParameterError
        from ..quasistatic.critical import critical_point

        other = y if x == "pulling_velocity" else x
        params = self.parameters(None, {k: v for k, v in fixed.items() if k != "pulling_velocity"})
        lo, hi = float(frame["pulling_velocity"].min()), float(frame["pulling_velocity"].max())
        lo, hi = max(lo, 1e-12), max(hi, 2e-12)
        velocity = np.geomspace(lo, hi, BOUNDARY_VELOCITIES)
        vc = critical_point(params).velocity
        vc = vc if vc is not None and lo < vc <= hi else None
        if vc is not None:
            velocity = np.union1d(velocity, vc * (1.0 - np.logspace(-1, -6, 6)))
        stiffest = _stiffest_rows(other, params, frame)
        kc = np.full(velocity.size, NAN)
        for k in range(velocity.size - 1, -1, -1):
            try:
                kc[k] = _critical_stiffness_for_plot(params, float(velocity[k]))
            except (ModelError, ParameterError):  # beyond the steady population's range: no boundary there
                continue
            if kc[k] > BEYOND_ROWS * stiffest:
                break
        good = np.isfinite(kc) & (kc > 0)
        v, k_eff = _boundary_curve(velocity[good], kc[good], vc)
        along = self.stiffness_of(other, params, k_eff)
        curve = (v, along) if x == "pulling_velocity" else (along, v)
        return [Boundary(curve[0], curve[1], "K = Kc(V0), linear stability")]


#: velocities of a sweep plot's boundary Kc(V0), log-spaced over the rows' (each Kc ~0.3-1 s; 80 took 4 min)
BOUNDARY_VELOCITIES = 10
#: no slower velocity once Kc exceeds the rows' stiffest by this factor (its point is drawn, beyond the axis)
BEYOND_ROWS = 10.0
#: Kc for a plot scans every PLOT_SCAN_STRIDE-th rate of critical_stiffness's scan
PLOT_SCAN_STRIDE = 8
#: points drawn between two computed ones
BOUNDARY_FILL = 24


def _stiffest_rows(key: str, params: Parameters, frame: Any) -> float:
    """The rows' largest effective stiffness K (Pa/m) on axis ``key`` (block.height: the lowest block's)."""
    values = np.asarray(frame[key], dtype=float) if key in frame else np.array([], dtype=float)
    values = values[np.isfinite(values) & (values > 0)]
    if not values.size:
        return math.inf
    block = params.block
    if key == "block.height":
        return float(block.shear_modulus * block.geometric_factor / values.min())
    return float(values.max() * (block.geometric_factor if key == "block.stiffness" else 1.0))


def _boundary_curve(velocity: np.ndarray, kc: np.ndarray, vc: float | None) -> tuple[np.ndarray, np.ndarray]:
    """The curve Kc(V0) through the computed points, BOUNDARY_FILL points between each two: log Kc linear in
    log(Vc - V0) below Vc (Kc ~ Vc - V0 there), in log V0 elsewhere.  Against a direct critical_stiffness at
    the midpoints (gelatin-glass, 20 um/s - 1 mm/s): within 4.5 % where the points are furthest apart
    (112-123 um/s), 0.07-0.4 % nearer Vc; a line in log V0 was 40 % off there."""
    if velocity.size < 2:
        return velocity, kc
    below = vc is not None and bool(np.all(velocity < vc))
    u = np.log(vc - velocity) if below else np.log(velocity)
    fill = np.linspace(0.0, 1.0, BOUNDARY_FILL + 1)[:-1]
    drawn = np.r_[(u[:-1, None] + (u[1:] - u[:-1])[:, None] * fill).ravel(), u[-1]]
    along = np.exp(np.interp(drawn, u, np.log(kc)) if u[0] < u[-1] else np.interp(-drawn, -u, np.log(kc)))
    return (vc - np.exp(drawn) if below else np.exp(drawn)), along


def _critical_stiffness_for_plot(params: Parameters, velocity: float) -> float:
    """Kc (Pa/m) of :func:`stickslip.transient.critical_stiffness` on a scan of every PLOT_SCAN_STRIDE-th rate of
    its own, its crossings bisected as there: ~5x cheaper, for a curve drawn over a sweep's plot.

    The oscillatory Kc is the bisection's, whatever the bracket: the same to ~1e-9; the real mode's minimum of
    -Z(s) is read on the coarser scan, ~3e-6 below (gelatin-glass, 20-130 um/s).  Z at these rates is memoised by
    the stability module, so a direct critical_stiffness at the same velocity pays only for the other rates."""
    from ..transient import critical_stiffness

    if getattr(critical_stiffness, "__module__", None) != "stickslip.transient.stability":  # a stand-in package's
        return float(critical_stiffness(params, velocity))
    from ..transient import stability

    stability._check_velocity(params, velocity)  # before the cells: a typed error, as critical_stiffness's
    top = stability.resolved_frequency(params, velocity)
    rates = stability.SCAN[::PLOT_SCAN_STRIDE] / params.bonds.bond_time
    with np.errstate(over="raise", invalid="raise"):
        try:
            found = stability.critical_from_response(stability._finite_response(params, velocity, True), rates, top=top)
        except FloatingPointError:
            return NAN
    return found.value


def transient_run(result: Any, protocol: Protocol | None = None, resolution: float | None = None) -> Run:
    """The :class:`Run` of a :class:`stickslip.transient.TransientResult` (regime from its slip events, in the
    protocol's last segment; over the whole run without the protocol)."""
    summary = last_cycle_numbers(result, protocol, resolution)
    summary["critical_velocity"] = float(getattr(result, "critical_velocity", NAN))  # the run's parameters' Vc
    regime = _regime(result, protocol)
    if regime.kind not in regimes.OSCILLATING:
        # a period is an oscillation's: the last whole cycle of a run that does not repeat it (a slide-hold-slide,
        # steady at its end, carried its last stick-to-stick span, 30.15 or 35 s, holds included) is no period
        summary["period"] = NAN
    elif regime.kind == regimes.STICK_SLIP and getattr(result, "chain_fraction", None) is not None:
        # the stick chains' limit cycle: its whole cycles, as the verdict counts them (periods), not the run's with
        # its start-up cycles (19 whole cycles beside "18 period(s)", the first from rest, that did not repeat)
        summary["cycles"] = regime.periods
    settled = getattr(result, "status", "ok") == "ok" and (
        regime.kind == regimes.STEADY
        or (regime.kind == regimes.OSCILLATION and math.isfinite(regime.period) and not summary["cycles"])
    )
    if settled:
        # what the run settled into, over its settled window (regimes.settled_window_start) within the last
        # segment, from the solver's integral (not the rows: ``every`` must not move it): steady, sigma(V0) once
        # steady, where the mean of a whole cycle of an earlier segment or of the run (478.903 Pa for a 350 ->
        # 1000 -> 350 µm/s step, ending steady at 391.535 Pa) was reported; a limit cycle without a stick, its last
        # whole periods (the run's mean, 298.078 Pa, lay above its period's peak, 297.573 Pa, for a ringing block)
        time = np.asarray(result.time, dtype=float)
        begin = float(protocol.boundaries[-2]) if protocol is not None else float(time[0])
        period = regime.period if regime.kind == regimes.OSCILLATION else NAN
        start = regimes.settled_window_start(max(begin, float(time[0])), float(time[-1]), period)
        summary["mean_stress"] = _mean_stress(result, start, float(time[-1]), protocol=protocol)
    elif regime.kind == regimes.UNDETERMINED:
        # settled into nothing (a run stopped or failed is undetermined too): the run's mean, as docs/models.md
        # says, not the last whole cycle's of an earlier segment (a slide-hold-slide on a spring, held by the
        # chains at its end, reported cycle 4's 364.267 Pa, which ended 133 s before the run, for the run's
        # 422.449 Pa).  A run stuck for good after its slips keeps its last whole cycle's, with that cycle's
        # stick time, sigma_s and jump (tests/test_transient_summary_consistency.py)
        summary["mean_stress"] = summary["run_mean_stress"]
    states: dict[str, Any] = {}
    units: dict[str, str | None] = {}
    if getattr(result, "bonded_fraction", None) is not None:
        states["bonded_fraction"], units["bonded_fraction"] = result.bonded_fraction, "1"
    if getattr(result, "chain_fraction", None) is not None:
        states["chain_fraction"], units["chain_fraction"] = result.chain_fraction, "1"
        if hasattr(result, "held_by"):
            states["held_by"], units["held_by"] = result.held_by, None
    return Run(
        model=Transient.name,
        time=result.time,
        stress=result.stress,
        friction=None,
        # the names of a TransientResult, or of the quasi-static Simulation a stand-in solver may return
        slider_velocity=_first(result, "slider_velocity", "velocity"),
        slider_position=_first(result, "slider_position", "slider_displacement"),
        load_point_position=_first(result, "puller_position", "puller_displacement"),
        regime=regime,
        mean=summary["mean_stress"],
        states=states,
        state_units=units,
        summary=summary,
        message=result.message,
        status=getattr(result, "status", "ok"),  # (a stand-in solver's result may have none)
        native=result,
    )


def _default_rtol() -> float | None:
    """run_transient's default rtol (None for a stand-in package without one)."""
    from .. import transient

    solver = getattr(transient, "solver", None)
    return getattr(solver, "RTOL", None)


def _first(result: Any, *names: str) -> Any:
    return next(getattr(result, n) for n in names if hasattr(result, n))


def _regime(result: Any, protocol: Protocol | None) -> regimes.Regime:
    """The solver's verdict, with the evidence of the one classifier: the slips' exact peaks and the sticks'
    troughs (cycles) in the last segment when it oscillates, the classifier on the solver's steps otherwise."""
    if getattr(result, "status", "ok") != "ok":  # stopped at a budget, or failed: what it computed
        return _unfinished(result)
    found = getattr(result, "evidence", None)
    if isinstance(found, regimes.Regime):  # the solver's own verdict: the same periods and extremes, in the same words
        return regimes.Regime(
            result.regime, found.periods, found.amplitude_ratio, found.period, found.peak, found.trough, result.message
        )
    start = float(protocol.boundaries[-2]) if protocol is not None else float(result.time[0])
    whole = [c for c in result.cycles if c.period is not None and c.start_time >= start]
    time, stress = np.asarray(result.time, dtype=float), np.asarray(result.stress, dtype=float)
    if len(whole) >= 2 and result.regime in (regimes.STICK_SLIP, regimes.DECAYING, regimes.GROWING):
        peaks = [c.peak_stress for c in whole]
        troughs = [c.start_stress for c in whole[1:]] + [_last_trough(result, whole[-1].start_time)]
        found = regimes.classify_cycles([c.start_time + c.stick_time for c in whole], peaks, troughs)
    else:
        between = _between_rows(result)
        if between is not None:
            # the solver's own result: the states between its rows (sampled by ``every``) give the tolerance and
            # the extremes (a stand-in solver's result has no such columns, and its package no cycles module)
            from ..transient.cycles import solution_extremes, with_extremes

            t_all, s_all = with_extremes(time, stress, between)
            inside = t_all >= start
            scale = float(np.max(np.abs(s_all[inside]))) if np.any(inside) else 0.0
            found = regimes.classify(time, stress, floor=SETTLED * max(scale, 1e-300), start=start, unit="Pa")
            found = solution_extremes(found, time, stress, between, start)
        else:
            inside = time >= start
            scale = float(np.max(np.abs(stress[inside]))) if np.any(inside) else 0.0
            found = regimes.classify(time, stress, floor=SETTLED * max(scale, 1e-300), start=start, unit="Pa")
    return regimes.Regime(
        str(result.regime), found.periods, found.amplitude_ratio, found.period, found.peak, found.trough, result.message
    )


def _between_rows(result: Any) -> Any:
    """The solver's states between its rows (``transient.cycles.Between``); None for a stand-in solver's result,
    which has no such columns."""
    names = ("lowest_stress", "highest_stress", "lowest_time", "highest_time", "fastest_velocity")
    columns = [getattr(result, name, None) for name in names]
    if any(c is None for c in columns):
        return None
    from ..transient.cycles import Between

    return Between(*columns)


def _unfinished(result: Any) -> regimes.Regime:
    """The evidence of a run that ended before the protocol's end (a budget, a failure): no verdict, so no periods
    and no period, and the extremes of the whole trace computed (with the solver's states between the rows).

    The classifier on such a run's last segment counted the solver's step-to-step chatter as periods: 1 µm/s under
    velocity control stopped at t = 1.09 s read 1016 "periods" of 25 µs and a peak of 338.7 kPa, while its trace
    rose to 699.1 kPa (docs/transient.md section 9)."""
    time, stress = np.asarray(result.time, dtype=float), np.asarray(result.stress, dtype=float)
    between = _between_rows(result)
    if between is not None and time.size > 1:
        from ..transient.cycles import with_extremes

        time, stress = with_extremes(time, stress, between)
    stress = stress[np.isfinite(stress)]
    peak, trough = (float(np.max(stress)), float(np.min(stress))) if stress.size else (NAN, NAN)
    return regimes.Regime(str(result.regime), 0, NAN, NAN, peak, trough, result.message)


def last_cycle_numbers(
    result: Any, protocol: Protocol | None = None, resolution: float | None = None
) -> dict[str, Any]:
    """The last whole cycle's numbers (the run has settled onto its cycle by then, if ever) and the mean stress
    over it (over the run when there is none, and then the stick time, σs and Vs of the run's last slip, if any;
    the whole cycles from an empty surface began with the start-up stick, σs 631.6 Pa against the paper's cycle's
    556.4 Pa, which the mean is not of); ``run_mean_stress`` over the run.  ``protocol``: the run's, for the
    puller's exact travel into a stick that no cycle of the result starts (the run ended in it)."""
    whole = [c for c in result.cycles if getattr(c, "period", None) is not None]
    whole = _settled(result, whole, protocol, resolution)
    time = np.asarray(result.time, dtype=float)
    row: dict[str, Any] = {
        "regime": str(result.regime),  # a kind name (a Regime compares and prints as its kind)
        "period": NAN,
        "stick_time": NAN,
        "peak_stress": NAN,
        "jump_velocity": NAN,
        "mean_stress": _mean_stress(result, time[0], time[-1]),
        "cycles": len(whole),
        "critical_velocity": NAN,
    }
    row["run_mean_stress"] = row["mean_stress"]  # the mean over the run, whatever the cycles (run --json)
    # the run's highest and lowest stress, from the solver's states (a 350 -> 1000 µm/s step's overshoot to 713.6 Pa
    # lies before the last segment, whose extremes the regime reports): every state, whatever rows ``every`` kept
    row["run_peak_stress"], row["run_trough_stress"] = _run_extremes(result)
    if whole:
        last = whole[-1]
        row.update(
            period=last.period, stick_time=last.stick_time, peak_stress=last.peak_stress,
            jump_velocity=last.jump_velocity,
        )  # fmt: skip
        end = last.start_time + last.period
        following = [c.start_stress for c in result.cycles if c.index == last.index + 1]
        row["mean_stress"] = _mean_stress(
            result, last.start_time, end, last.start_stress, *following[:1], protocol=protocol
        )
    elif result.cycles:
        # no cycle that repeats (a start-up cycle, a slip before the run settled or stuck for good): the last slip
        # the run saw, its stick and jump, were NaN beside a message quoting them; no period (nothing repeats)
        last = result.cycles[-1]
        row.update(stick_time=last.stick_time, peak_stress=last.peak_stress, jump_velocity=last.jump_velocity)
    return row


def _run_extremes(result: Any) -> tuple[float, float]:
    """(highest, lowest) stress of the run: every state of the solver (the rows and the extremes each row carries
    of the states since the row before); the rows' own for a stand-in solver's result."""
    time, stress = np.asarray(result.time, dtype=float), np.asarray(result.stress, dtype=float)
    between = _between_rows(result)
    if between is not None and time.size:
        from ..transient.cycles import window_extremes

        return window_extremes(time, stress, between, float(time[0]))
    finite = stress[np.isfinite(stress)]
    return (float(np.max(finite)), float(np.min(finite))) if finite.size else (NAN, NAN)


def _settled(result: Any, whole: list[Any], protocol: Protocol | None, resolution: float | None = None) -> list[Any]:
    """The whole cycles without a start-up cycle that does not repeat (as quasistatic.cycle.settled_cycles): the
    first whole cycle of the last segment (of the run without the protocol) counts only where the stick after it
    starts where it started, within RATIO_TOLERANCE of its rise and the run's tolerance (``resolution``, its rtol,
    x the stress: regimes.repeat_tolerance, the verdict's) (from rest the first stick starts at 0 Pa: its period,
    54.8 s at 50 µm/s, is no period of the run's cycle, 23.3 s; from a steady start at 50 µm/s the first stick
    starts 0.16 Pa from the next, 6x rtol 1e-4 of it, and the summary reported that start-up cycle as the run's
    while the verdict called it a start-up cycle)."""
    if not whole:
        return whole
    start = float(protocol.boundaries[-2]) if protocol is not None else float(np.asarray(result.time)[0])
    inside = [c for c in whole if c.start_time >= start]
    if not inside or inside[0] is not whole[-1]:  # the last whole cycle follows another one of its segment
        return whole
    first = inside[0]
    following = [c.start_stress for c in result.cycles if c.index == first.index + 1]
    after = following[0] if following else _last_trough(result, first.start_time + first.period)
    rise = first.peak_stress - first.start_stress
    if abs(after - first.start_stress) <= regimes.repeat_tolerance(first.start_stress, after, rise, resolution):
        return whole
    return []


def _mean_stress(result: Any, start: float, end: float, *exact: float, protocol: Protocol | None = None) -> float:
    """Mean stress over [start, end] from the integral of sigma dt the solver keeps (not from the rows written:
    ``every`` must not change it); ``exact``: sigma at start (and end) where known (a stick event)."""
    time, stress = np.asarray(result.time, dtype=float), np.asarray(result.stress, dtype=float)
    book = getattr(result, "bookkeeping", None)
    integral = getattr(book, "stress_integral", None)
    if integral is None or not end > start or not np.all(np.isfinite(integral)):  # a stand-in's trace
        inside = (time >= start) & (time <= end)
        return time_mean(time[inside], stress[inside]) if np.count_nonzero(inside) > 1 else time_mean(time, stress)
    held = _HeldBlock(result, protocol) if getattr(result, "chain_fraction", None) is not None else None
    at = [_integral_at(time, stress, integral, t, *exact[k : k + 1], held=held) for k, t in enumerate((start, end))]
    return (at[1] - at[0]) / (end - start)


class _HeldBlock:
    """The stress of a block the stick chains hold, sigma = K (P - X) with the slider fixed: from a row of the stick
    back to its start, K times the puller's travel between (the protocol's, exact; the rows' puller positions,
    linear between them, without it), and its integral."""

    def __init__(self, result: Any, protocol: Protocol | None) -> None:
        self.stuck = np.isfinite(np.asarray(result.chain_fraction, dtype=float))  # the rows the chains hold
        self.stiffness = float(result.stiffness)
        self.protocol = protocol
        self.time = np.asarray(result.time, dtype=float)
        self.puller = np.asarray(_first(result, "puller_position", "puller_displacement"), dtype=float)

    def integral_before(self, k: int, stress: float, t: float) -> float:
        """The integral of sigma from t to row k of the same stick (t <= time[k]), given sigma at row k: exact, the
        puller's path piecewise linear between the protocol's boundaries (a stick that runs into a hold: the line
        from the stick's start to the row, read across the puller's stop at 22 s, moved the mean of a cycle ending
        at 21.58 s by 0.85 Pa with rows every 3 s)."""
        end = float(self.time[k])
        if self.protocol is not None:
            edges = np.asarray(self.protocol.boundaries, dtype=float)
            points = np.r_[t, edges[(edges > t) & (edges < end)], end]
            travel = float(self.protocol.displacement_at(end)) - np.asarray(
                self.protocol.displacement_at(points), dtype=float
            )
        else:
            points = np.array([t, end])
            travel = np.array([float(self.puller[k] - np.interp(t, self.time, self.puller)), 0.0])
        sigma = stress - self.stiffness * travel
        return float(np.sum(0.5 * (sigma[1:] + sigma[:-1]) * np.diff(points)))


def _integral_at(
    time: np.ndarray,
    stress: np.ndarray,
    integral: np.ndarray,
    t: float,
    *sigma: float,
    held: _HeldBlock | None = None,
) -> float:
    """The integral at t between rows: back from the next row, exactly through the held block (``held``) where the
    chains hold it at the next row, else by the trapezoid with sigma(t) given, or interpolated.

    With the stick chains every cycle's ends are stick events, and the first row at or after one lies in its stick
    (a row is written at each slip, at its exact time): sigma = K (P - X) follows the puller from t to that row,
    and the held block integrates it from the row's stress and the puller's travel since t, across any change of
    the puller's pace between (the line through the next two rows, used before, read the sliding row before the
    stick when ``every`` left the stick one row: 3 s and 7 s rows moved the paper's mean from empty by 5.9e-4 and
    2.5e-3; the line from the stick's start to the row read across a hold's start).
    """
    k = int(np.searchsorted(time, t, side="left"))
    if k >= time.size:
        return float(integral[-1])
    if time[k] == t or k == 0:
        return float(integral[k])
    if held is not None and held.stuck[k]:
        return float(integral[k] - held.integral_before(k, float(stress[k]), t))
    if sigma:
        here = sigma[0]
    else:
        here = float(np.interp(t, time, stress))
    return float(integral[k] - 0.5 * (here + stress[k]) * (time[k] - t))


def _last_trough(result: Any, start: float) -> float:
    """The lowest stress from ``start`` on, from the solver's accepted states (each row carries the lowest of the
    steps it closes: ``every`` must not move the trough) and the stick events' exact stresses."""
    time, stress = np.asarray(result.time, dtype=float), np.asarray(result.stress, dtype=float)
    lowest = getattr(result, "lowest_stress", None)
    when = getattr(result, "lowest_time", None)
    inside = np.flatnonzero(time >= start)
    values = stress[inside].tolist()
    if lowest is not None and when is not None:  # the states at or after start, whichever row carries them
        low, at = np.asarray(lowest, dtype=float), np.asarray(when, dtype=float)
        values += low[np.isfinite(low) & np.isfinite(at) & (at >= start)].tolist()
    elif lowest is not None and inside.size > 1:  # the first row's steps began before start: its own stress only
        values += np.asarray(lowest, dtype=float)[inside[1:]].tolist()
    sticks = [c.start_stress for c in result.cycles if c.start_time >= start]
    return float(min([*values, *sticks]))
