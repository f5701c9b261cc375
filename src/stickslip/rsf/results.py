"""Result of a rate-and-state run: the trace, how it ended, and what regime it settled in."""

from __future__ import annotations

import itertools
import json
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..columns import with_units
from ..protocols import Protocol
from .params import RSFParams

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

    from .system import System

__all__ = ["RSFRun", "Regime", "assemble_run", "detect_regime"]


@dataclass(frozen=True)
class Regime:
    """What the last protocol segment settled into.

    ``name``: ``steady sliding``, ``decaying oscillation``, ``stick-slip``
    (a limit cycle), ``growing oscillation``, ``transient`` (still evolving
    without oscillating) or ``blow-up``.  ``period`` (s) is NaN unless the
    last segment oscillates; ``growth`` is the ratio of the last two
    oscillation amplitudes (NaN when there are fewer than three peaks).
    """

    name: str
    period: float
    peak_friction: float
    trough_friction: float
    growth: float


@dataclass(frozen=True)
class RSFRun:
    """A spring-slider trace (SI units; friction dimensionless; ``state`` has one row per state variable)."""

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

    @property
    def final_friction(self) -> float:
        return float(self.friction[-1])

    def to_frame(self) -> Any:
        import pandas as pd

        columns: dict[str, Any] = {"time": self.time, "friction": self.friction}
        columns["slider_velocity"] = self.slider_velocity
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
        from ..cli.common import json_safe  # plain-data helper, no CLI machinery

        return json.dumps(json_safe(self.metadata()), indent=2) + "\n"

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        from .plots import plot_run

        return plot_run(self, ax=ax, **kwargs)

    def phase_plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        from .plots import phase_plot

        return phase_plot(self, ax=ax, **kwargs)


def _default_message(regime: Regime) -> str:
    return {
        "steady sliding": "the slider settled into steady sliding at the load-point velocity",
        "decaying oscillation": "oscillations decay towards steady sliding (stable: k above critical)",
        "stick-slip": "stick-slip: the oscillation settled into a limit cycle of constant amplitude",
        "growing oscillation": "oscillations grow (unstable: k below critical) and had not settled by the end",
        "transient": "still evolving at the end of the protocol (run longer to see where it settles)",
    }.get(regime.name, "")


def assemble_run(
    system: System,
    protocol: Protocol,
    t: np.ndarray,
    y: np.ndarray,
    status: str,
    message: str,
    v_start: float,
    detect: bool = True,
) -> RSFRun:
    """Turn the solver's (t, y) into the physical trace."""
    o = system.offset
    x, psi = y[o], y[o + 1 :]
    friction = system.friction_many(x, psi)
    velocity = system.v0 * np.exp(np.minimum(x, 700.0))
    lp_disp = protocol.displacement_at(t)
    k = system.k
    if system.inertial:
        spring = y[0]
    else:
        spring = friction + system.eta * velocity
    slider = lp_disp - (spring - spring[0]) / k
    regime = (
        Regime("blow-up", math.nan, float(np.max(friction)), float(np.min(friction)), math.nan)
        if status != "ok"
        else detect_regime(t, friction, velocity, protocol)
        if detect
        else Regime("not analysed", math.nan, math.nan, math.nan, math.nan)
    )
    return RSFRun(
        time=t,
        friction=friction,
        slider_velocity=velocity,
        state=system.theta(psi),
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


def detect_regime(t: np.ndarray, friction: np.ndarray, velocity: np.ndarray, protocol: Protocol) -> Regime:
    """Classify the last protocol segment from its friction peaks (see :class:`Regime`).

    Peaks count when their prominence exceeds 5 % of the friction range over
    the segment's second half (and a floor far above rounding), so the small
    overshoots that follow each slip are not taken for cycles.
    """
    start, end = protocol.boundaries[-2], protocol.boundaries[-1]
    mask = t >= start
    tt, mu, v = t[mask], friction[mask], velocity[mask]
    if tt.size < 5:
        return Regime("transient", math.nan, float(np.max(friction)), float(np.min(friction)), math.nan)
    span = float(np.ptp(mu[tt >= start + 0.5 * (end - start)]))
    floor = 1e-10 * max(1.0, float(np.max(np.abs(mu))))
    peaks = turning_points(mu, max(floor, 0.05 * span))[0]
    vlp = protocol.segments[-1].velocity
    if peaks.size < 3:
        settled = vlp > 0 and abs(v[-1] / vlp - 1) < 1e-3
        name = "steady sliding" if settled else "transient"
        return Regime(name, math.nan, float(np.max(mu)), float(np.min(mu)), math.nan)
    amplitude = np.array([mu[p] - np.min(mu[p:q]) for p, q in itertools.pairwise(peaks)])
    growth = float(amplitude[-1] / amplitude[-2]) if amplitude[-2] > 0 else math.nan
    period = float(np.mean(np.diff(tt[peaks[-4:]])))
    last = slice(peaks[-2], None)
    peak, trough = float(np.max(mu[last])), float(np.min(mu[last]))
    if growth > 1.02:
        name = "growing oscillation"
    elif growth < 0.98:
        name = "decaying oscillation"
    else:
        name = "stick-slip"
    return Regime(name, period, peak, trough, growth)


def turning_points(values: np.ndarray, delta: float) -> tuple[np.ndarray, np.ndarray]:
    """(maxima, minima) indices, alternating, each extremum ``delta`` beyond its neighbours (hysteresis scan).

    Cheaper to import than scipy.signal and immune to wiggles smaller than ``delta``.
    """
    maxima: list[int] = []
    minima: list[int] = []
    data = np.asarray(values, dtype=float).tolist()
    hi = lo = data[0]
    hi_i = lo_i = 0
    looking_for_max = True
    for i, value in enumerate(data):
        if value > hi:
            hi, hi_i = value, i
        if value < lo:
            lo, lo_i = value, i
        if looking_for_max and value < hi - delta:
            maxima.append(hi_i)
            lo, lo_i = value, i
            looking_for_max = False
        elif not looking_for_max and value > lo + delta:
            minima.append(lo_i)
            hi, hi_i = value, i
            looking_for_max = True
    return np.array(maxima, dtype=int), np.array(minima, dtype=int)
