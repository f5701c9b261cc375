"""Result of a rate-and-state run: the trace, how it ended, and what regime it settled in."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import regimes
from ..columns import with_units
from ..errors import StickslipError
from ..protocols import Protocol
from ..reprs import compact_repr
from .params import RSFParams

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

    from .system import System

__all__ = ["RSFRun", "Regime", "Solution", "assemble_run", "detect_regime"]

#: the evidence of a run whose regime was not looked for (``simulate(..., detect=False)``, as fits run it)
NOT_ANALYSED = "not analysed"


class Regime(regimes.Regime):
    """What the last protocol segment settled into: the one classifier's :class:`stickslip.regimes.Regime`
    (the same fields, friction dimensionless), read off the solver's dense solution.

    ``kind`` is one of :data:`stickslip.regimes.KINDS`; a run with ``detect=False`` (fits) is ``undetermined``
    with the evidence "not analysed".  Rate-and-state's own names stay as read-only aliases: ``name`` (the
    kind, ``steady sliding`` for ``steady``: :data:`stickslip.regimes.RSF_NAMES`), ``growth``
    (``amplitude_ratio``), ``peak_friction`` and ``trough_friction`` (``peak`` and ``trough``).  ``period``
    (s) is NaN unless the last segment oscillates; the extremes are over the last period (over the segment
    when it does not oscillate), whatever the output sampling.
    """

    @property
    def name(self) -> str:
        return regimes.RSF_NAMES.get(self.kind, self.kind)

    @property
    def growth(self) -> float:
        return self.amplitude_ratio

    @property
    def peak_friction(self) -> float:
        return self.peak

    @property
    def trough_friction(self) -> float:
        return self.trough


@dataclass(frozen=True)
class Solution:
    """The solver's own solution over one protocol piece: accepted steps and the interpolant between them."""

    __repr__ = compact_repr  # counts, not hundreds of array elements

    start: float
    t: np.ndarray
    y: np.ndarray
    dense: Any  # callable t -> y (scipy OdeSolution), or None


@dataclass(frozen=True)
class RSFRun:
    """A spring-slider trace (SI units; friction dimensionless; ``state`` has one row per state variable)."""

    __repr__ = compact_repr  # counts, not hundreds of array elements

    time: np.ndarray
    friction: np.ndarray
    slider_velocity: np.ndarray
    state: np.ndarray
    load_point_displacement: np.ndarray
    slider_displacement: np.ndarray
    load_point_velocity: np.ndarray
    params: RSFParams
    protocol: Protocol
    start_velocity: float
    status: str
    message: str
    regime: Regime
    #: the mean of mu over the run (to its end, or to a blow-up): the solver's integral of mu dt over its time,
    #: whatever the output sampling (NaN where the run was not integrated so)
    run_mean_friction: float = math.nan
    #: the mean of mu over the settled window (:func:`stickslip.models.run.settled_mean`'s: the last whole periods
    #: within the run's second half, else that half) from the same integral, whatever the sampling (NaN where not
    #: integrated so)
    settled_mean_friction: float = math.nan

    def __post_init__(self) -> None:
        # a run the solver had nothing to say about carries the words its summary gives (its regime's evidence), as
        # every other result's message does (round 30: RSFRun.message was always '' then)
        if not self.message:
            object.__setattr__(self, "message", _default_message(self.regime))

    @property
    def final_friction(self) -> float:
        return float(self.friction[-1])

    def to_frame(self) -> Any:
        import pandas as pd

        columns = {"time": self.time, "friction": self.friction, "slider_velocity": self.slider_velocity}
        for i, row in enumerate(self.state):
            columns["state" if i == 0 else f"state{i + 1}"] = row
        columns["load_point_displacement"] = self.load_point_displacement
        columns["slider_displacement"] = self.slider_displacement
        return with_units(pd.DataFrame(columns))

    def summary(self) -> dict[str, Any]:
        """The JSON summary: regime, final friction, period, peak and trough friction, message."""
        r = self.regime
        return {
            "regime": r.name,
            "final_friction": self.final_friction,
            "period": None if math.isnan(r.period) else r.period,
            "peak_friction": r.peak_friction,
            "trough_friction": r.trough_friction,
            "growth": None if math.isnan(r.growth) else r.growth,
            "periods": r.periods,
            "status": self.status,
            "message": self.message or _default_message(r),
        }

    def metadata(self) -> dict[str, Any]:
        """Everything needed to rerun this trace (written beside it)."""
        return {
            "model": "rate-and-state spring-slider",
            "parameters": self.params.to_dict(),
            "start_velocity": self.start_velocity,
            "protocol": [{"velocity": s.velocity, "duration": s.duration} for s in self.protocol.segments],
            "summary": self.summary(),
            "units": "SI (m, s, m/s); friction dimensionless; stiffness 1/m; eta s/m",
        }

    def metadata_json(self) -> str:
        from ..columns import json_safe

        return json.dumps(json_safe(self.metadata()), indent=2) + "\n"

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        from ..plots.rsf import plot_run

        return plot_run(self, ax=ax, **kwargs)

    def phase_plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        from ..plots.rsf import phase_plot

        return phase_plot(self, ax=ax, **kwargs)


def _default_message(regime: Regime) -> str:
    if regime.evidence:
        return regime.evidence
    return {
        "steady sliding": "the slider settled into steady sliding at the load-point velocity",
        "stick-slip": "stick-slip: the oscillation settled into a limit cycle of constant amplitude",
    }.get(regime.name, "")


def _blow_up(
    t: np.ndarray, friction: np.ndarray, system: System | None = None, solution: Solution | None = None
) -> Regime:
    """The regime of a run that blew up, with the oscillation that grew before it where there was one (a blow-up
    after 29 growing peaks read "no oscillation", periods 0: round-25 tester).

    With ``solution`` (the solver's steps over the whole run and its interpolant, and ``system``) the extremes are
    the solution's, placed between its steps, and the oscillation is read off the steps: nothing depends on how
    the trace was sampled (the rows' peak differed by 1.7e-7 between samplings: round-27 tester)."""
    dense = None
    if solution is not None and system is not None and solution.t.size >= 2:
        t, friction = _physical(system, solution.t, solution.y)[:2]
        if solution.dense is not None:
            interpolant = solution.dense

            def dense(times: np.ndarray) -> np.ndarray:
                return _physical(system, times, interpolant(times))[1]

    finite = np.isfinite(friction)
    t, friction = t[finite], friction[finite]
    peak = regimes.extremes(t, friction, int(np.argmax(friction)), dense)[1] if t.size else math.nan
    trough = regimes.extremes(t, friction, int(np.argmin(friction)), dense)[1] if t.size else math.nan
    if t.size >= 3:
        scale = float(np.max(np.abs(friction)))
        before = regimes.classify(t, friction, floor=1e-9 * scale if scale > 0 else 1e-300, dense=dense)
        if before.periods >= 1:
            grew = before.amplitude_ratio > 1 if math.isfinite(before.amplitude_ratio) else None
            kind = "growing " if grew else "decaying " if grew is False else ""
            measured = [f"period {before.period:.4g} s" if math.isfinite(before.period) else "",
                        f"last amplitude ratio {before.amplitude_ratio:.3g}" if math.isfinite(before.amplitude_ratio)
                        else ""]  # fmt: skip
            said = ", ".join(m for m in measured if m)  # (one period has neither: "period nan s" said nothing)
            evidence = f"blow-up after {before.periods} period(s) of {kind}oscillation" + (f" ({said})" if said else "")
            return Regime(regimes.BLOW_UP, before.periods, before.amplitude_ratio, before.period, peak, trough,
                          evidence)  # fmt: skip
    return Regime(regimes.BLOW_UP, 0, math.nan, math.nan, peak, trough, "")


def assemble_run(
    system: System,
    protocol: Protocol,
    t: np.ndarray,
    y: np.ndarray,
    status: str,
    message: str,
    v_start: float,
    detect: bool = True,
    solution: Solution | None = None,
    rtol: float = 1e-10,
) -> RSFRun:
    """Turn the solver's (t, y) into the physical trace."""
    _, friction, velocity = _physical(system, t, y)
    lp_disp = protocol.displacement_at(t)
    spring = y[0] if system.inertial else friction + system.eta * velocity
    slider = lp_disp - (spring - spring[0]) / system.k
    regime = (
        _blow_up(t, friction, system, solution)
        if status != "ok"
        else detect_regime(t, friction, velocity, protocol, system=system, solution=solution, rtol=rtol)
        if detect
        else Regime(regimes.UNDETERMINED, 0, math.nan, math.nan, math.nan, math.nan, NOT_ANALYSED)
    )
    return RSFRun(
        time=t,
        friction=friction,
        slider_velocity=velocity,
        state=system.theta(y[system.offset + 1 :]),
        load_point_displacement=lp_disp,
        slider_displacement=slider,
        load_point_velocity=protocol.velocity_at(t),
        params=system.params,
        protocol=protocol,
        start_velocity=v_start,
        status=status,
        message=message,
        regime=regime,
    )


def detect_regime(
    t: np.ndarray,
    friction: np.ndarray,
    velocity: np.ndarray,
    protocol: Protocol,
    *,
    system: System | None = None,
    solution: Solution | None = None,
    rtol: float = 1e-10,
) -> Regime:
    """Classify the last protocol segment with :func:`stickslip.regimes.classify` (see :class:`Regime`).

    With ``solution`` (the solver's accepted steps and interpolant over that segment, and ``system`` to turn
    them into friction) the regime, period and extremes are those of the solution; otherwise of the trace.
    """
    start = float(protocol.boundaries[-2])
    vlp = float(protocol.segments[-1].velocity)
    dense = None
    if solution is not None and system is not None and solution.t.size >= 2:
        t, friction, velocity = _physical(system, solution.t, solution.y)
        if solution.dense is not None:
            interpolant = solution.dense

            def dense(times: np.ndarray) -> np.ndarray:
                return _physical(system, times, interpolant(times))[1]

    scale = float(np.max(np.abs(friction))) if friction.size else 1.0
    floor = max(10.0 * rtol * scale, 1e-14)
    relaxation = (max(system.dc) / vlp) if (system is not None and vlp > 0) else None
    found = regimes.classify(t, friction, floor=floor, start=start, relaxation=relaxation, dense=dense)
    kind, evidence = found.kind, found.evidence
    if found.kind == regimes.STEADY and vlp > 0:
        mask = t >= start
        v_end = float(velocity[mask][-1]) if np.any(mask) else float(velocity[-1])
        if abs(v_end / vlp - 1) > 1e-3:  # friction flat but the slider not at the load point's pace
            kind = regimes.UNDETERMINED
            evidence = (
                f"undetermined: friction is flat but the slider moves at {v_end:.4g} m/s, not the load point's"
                f" {vlp:.4g} m/s"
            )
    if system is not None and vlp > 0:
        evidence += _stability_note(system, vlp, found.kind)
    return Regime(kind, found.periods, found.amplitude_ratio, found.period, found.peak, found.trough, evidence)


def _physical(system: System, t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    o = system.offset
    x, psi = y[o], y[o + 1 :]
    return t, system.friction_many(x, psi), system.v0 * np.exp(np.minimum(x, 700.0))


def _stability_note(system: System, velocity: float, kind: str) -> str:
    """What linear stability says at this stiffness: stated beside the regime, never as its cause unless they agree."""
    from .stability import critical_stiffness

    try:
        kc = critical_stiffness(system.params, velocity)
    except (StickslipError, ArithmeticError, np.linalg.LinAlgError):  # a note only: the regime stands without it
        return ""
    k = system.params.stiffness
    if kc <= 0:
        rule = "b V2/(V2+V) <= a V1/(V1+V) + eta V" if system.params.cutoff else "b <= a + eta V"  # slopes at V
        where = f"steady sliding is linearly stable at every stiffness here ({rule})"
        stable = True
    elif abs(k - kc) <= 1e-9 * kc:  # "k = 500 1/m is below kc = 500 1/m" read as a contradiction
        where = (f"k = {k:.6g} 1/m is kc (to {abs(k - kc) / kc:.1g} of it): steady sliding is neutrally stable,"
                 " a disturbance neither grows nor decays at first order")  # fmt: skip
        stable = None
    else:
        digits = next(d for d in range(4, 18) if f"{k:.{d}g}" != f"{kc:.{d}g}")  # enough digits to tell them apart
        relation, stable = ("above", True) if k > kc else ("below", False)
        where = (f"k = {k:.{digits}g} 1/m is {relation} kc = {kc:.{digits}g} 1/m: steady sliding is linearly"
                 f" {'stable' if stable else 'unstable'}")  # fmt: skip
    agrees = {regimes.DECAYING: stable, regimes.STEADY: stable, regimes.GROWING: not stable}
    if stable is not None and kind in agrees and not agrees[kind]:
        if kind == regimes.GROWING:
            return f"; {where}, so the growth is a finite-amplitude effect or a transient, not that instability"
        return f"; {where}, yet the run settles (the run may be too short or the start too close to steady)"
    return f"; {where}"
