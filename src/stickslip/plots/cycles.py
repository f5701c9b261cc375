"""Figures of the stick-slip cycle: sigma(t) (Fig 5a-c), V(t) in slip (Fig 5d), Nc/Nc0(t) (Figs 3, 6), Fig 2.

Built on :class:`matplotlib.figure.Figure`, never pyplot: nothing opens a
window or touches global state.  The objects passed in hold SI values; axes
show seconds, Pa and um/s.

* :func:`plot_simulation`, :func:`plot_stick`, :func:`plot_slip` draw one
  result on an Axes (they back the results' ``plot()`` methods);
* :func:`figure_cycles`, :func:`figure_slip_velocity`,
  :func:`figure_chain_fraction` and :func:`figure_cycle_path` build the
  paper's figures from one or several results.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..display import velocity as _velocity_text
from .legends import legend_per_panel
from .style import (
    AGING_COLOR,
    CRITICAL_COLOR,
    DATA_COLOR,
    NO_AGING_COLOR,
    STRESS_LABEL,
    UM_PER_S,
    VELOCITY_LABEL,
    apply_style,
    data_columns,
    new_axes,
)

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..parameters import Parameters
    from ..quasistatic.cycle import Simulation
    from ..quasistatic.slip import SlipPhase
    from ..quasistatic.stick import StickPhase

STICK_COLOR = "#c0392b"
SLIP_COLOR = AGING_COLOR
STEADY_COLOR = "#27ae60"
PHASE_COLORS = {"stick": STICK_COLOR, "slip": SLIP_COLOR, "steady": STEADY_COLOR}
TIME_LABEL = "time t (s)"


def _um(v: float) -> str:
    return _velocity_text(v, digits=4)


# --------------------------------------------------------------------------- single results on an Axes
def plot_simulation(sim: Simulation, ax: Axes | None = None, phases: bool = True, **kwargs: Any) -> Axes:
    """sigma(t) of a simulated trace; with ``phases`` the stick, slip and steady parts are coloured."""
    ax = new_axes(ax)
    kwargs.setdefault("linewidth", 1.6)
    if phases:
        for name, color in PHASE_COLORS.items():
            mask = sim.phase == name
            if not np.any(mask):
                continue
            # NaN breaks the line between separate phases of the same kind
            stress = np.where(mask, sim.stress, np.nan)
            ax.plot(sim.time, stress, color=color, label=name, **kwargs)
    else:
        kwargs.setdefault("label", f"V0 = {_um(sim.pulling_velocity)}")
        ax.plot(sim.time, sim.stress, **kwargs)
    if math.isfinite(sim.critical_stress):  # a curve without Vc (steady sliding only) has no σc to mark
        ax.axhline(sim.critical_stress, color=CRITICAL_COLOR, linestyle="--", linewidth=0.8, alpha=0.6,
                   label=f"σc = {sim.critical_stress:.4g} Pa")  # fmt: skip
    ax.set_xlabel(TIME_LABEL)
    ax.set_ylabel(STRESS_LABEL)
    ax.set_xlim(0.0, sim.duration)
    apply_style(ax)
    return ax


def plot_stick(stick: StickPhase, ax: Axes | None = None, **kwargs: Any) -> Axes:
    """Nc/Nc0 against time in one stick phase (Figs 3, 6)."""
    ax = new_axes(ax)
    kwargs.setdefault("label", f"V0 = {_um(stick.pulling_velocity)}" + ("" if stick.aging else ", no aging"))
    kwargs.setdefault("linewidth", 1.8)
    line = ax.plot(stick.time, stick.chain_fraction, **kwargs)[0]
    if stick.stick_time is not None:  # gid: the name of its CSV in a report (it has no legend entry)
        ax.plot([stick.stick_time], [0.0], "o", color=line.get_color(), markersize=5,
                gid=f"stick time ts, {line.get_label()}")  # fmt: skip
    ax.set_xlabel("time since sticking t (s)")
    ax.set_ylabel("attached chains $N_c/N_{c0}$")
    ax.set_ylim(-0.03, 1.05)
    apply_style(ax)
    return ax


def plot_slip(slip: SlipPhase, ax: Axes | None = None, **kwargs: Any) -> Axes:
    """V(t) during one slip phase (Fig 5d), in um/s."""
    ax = new_axes(ax)
    kwargs.setdefault("label", f"V0 = {_um(slip.pulling_velocity)}, Vs = {_um(slip.start_velocity)}")
    kwargs.setdefault("linewidth", 1.8)
    ax.plot(slip.time, slip.velocity * UM_PER_S, **kwargs)
    ax.set_xlabel("time since the jump t (s)")
    ax.set_ylabel(VELOCITY_LABEL)
    apply_style(ax)
    return ax


# --------------------------------------------------------------------------- the paper's figures
def _figure(rows: int = 1, height: float = 4.4) -> Figure:
    from matplotlib.figure import Figure

    return Figure(figsize=(6.8, height * rows if rows > 1 else height), layout="constrained")


def figure_cycles(
    simulations: Sequence[Simulation],
    data: Sequence[Any | None] | None = None,
    title: str | None = None,
) -> Figure:
    """Fig 5a-c: sigma(t) over several cycles, one panel per simulation.

    ``data`` (optional, one entry per simulation, None to skip) sets a
    measured trace beside the model: a pair ``(time, stress)`` of SI arrays,
    or anything with ``time`` and ``stress`` items or attributes.
    """
    if not simulations:
        raise ValueError("figure_cycles: expected at least one simulation")
    if data is not None and len(data) != len(simulations):
        raise ValueError(f"figure_cycles: {len(simulations)} simulations but {len(data)} data entries")
    fig = _figure(len(simulations), height=2.6)
    axes = fig.subplots(len(simulations), 1, squeeze=False)[:, 0]
    for k, (ax, sim) in enumerate(zip(axes, simulations, strict=True)):
        if data is not None and data[k] is not None:
            t, s = _trace_arrays(data[k])
            ax.plot(t, s, "o", markersize=2.5, color=DATA_COLOR, alpha=0.6, label="data", zorder=1)
        plot_simulation(sim, ax=ax)
        ax.set_title(f"({chr(ord('a') + k)}) V0 = {_um(sim.pulling_velocity)}: {sim.regime}", fontsize=10, loc="left")
        if k < len(simulations) - 1:
            ax.set_xlabel("")
    legend_per_panel(fig)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def _trace_arrays(item: Any) -> tuple[np.ndarray, np.ndarray]:
    expected = "a (time, stress) pair, a mapping/table with 'time' and 'stress'"
    t, s, _ = data_columns(item, ("time", "stress"), None, expected)
    return np.asarray(t, dtype=float).ravel(), np.asarray(s, dtype=float).ravel()


def _first_slip(item: SlipPhase | Simulation) -> SlipPhase | None:
    phases = getattr(item, "slip_phases", None)
    if phases is None:
        return item  # type: ignore[return-value]
    return phases[0] if phases else None


def _first_stick(item: StickPhase | Simulation) -> StickPhase:
    phases = getattr(item, "stick_phases", None)
    if phases is None:
        return item  # type: ignore[return-value]
    return phases[0]


def figure_slip_velocity(
    slips: Sequence[SlipPhase | Simulation],
    labels: Sequence[str] | None = None,
    critical_velocity: float | None = None,
    title: str | None = "Sliding velocity in the slip phase (Fig 5d)",
) -> Figure:
    """Fig 5d: V(t) in slip for each slip phase (a Simulation contributes its first slip).

    ``critical_velocity`` (m/s; taken from a Simulation when not given)
    draws the asymptote Vc that the slips with V0 < Vc end on.
    """
    fig = _figure()
    ax = fig.add_subplot()
    for k, item in enumerate(slips):
        slip = _first_slip(item)
        if slip is None:
            continue
        kwargs = {"label": labels[k]} if labels is not None else {}
        plot_slip(slip, ax=ax, **kwargs)
        if critical_velocity is None:
            critical_velocity = getattr(item, "critical_velocity", None)
    if critical_velocity is not None:
        ax.axhline(critical_velocity * UM_PER_S, color=CRITICAL_COLOR, linestyle="--", linewidth=0.8)
        ax.annotate(f"$V_c$ = {_um(critical_velocity)}", xy=(1.0, critical_velocity * UM_PER_S),
                    xycoords=("axes fraction", "data"), ha="right", va="bottom", fontsize=9)  # fmt: skip
    ax.set_ylim(bottom=0.0)
    ax.legend(loc="upper right", frameon=False, fontsize=8)
    if title:
        ax.set_title(title, fontsize=11)
    return fig


def figure_chain_fraction(
    stick_phases: Sequence[StickPhase | Simulation],
    labels: Sequence[str] | None = None,
    title: str | None = "Attached chains in the stick phase (Figs 3, 6)",
) -> Figure:
    """Figs 3 and 6: Nc/Nc0 against time, one curve per stick phase (a Simulation gives its first)."""
    fig = _figure()
    ax = fig.add_subplot()
    for k, item in enumerate(stick_phases):
        stick = _first_stick(item)
        kwargs = {"label": labels[k]} if labels is not None else {}
        plot_stick(stick, ax=ax, **kwargs)
    ax.legend(loc="lower left", frameon=False, fontsize=8)
    if title:
        ax.set_title(title, fontsize=11)
    return fig


def figure_cycle_path(params: Parameters, simulation: Simulation, title: str | None = None) -> Figure:
    """Fig 2: one cycle's path over the sigma-V diagram (linear V axis, so that the stick at V = 0 shows).

    Path 3 is the stick (V = 0, sigma_c -> sigma_s), then the jump to Vs at
    constant stress, path 1 the slip down the aging curve, and the jump back
    to rest at sigma_c (path 2 schematically in the paper).
    """
    from ..quasistatic.steady import steady_state

    fig = _figure()
    ax = fig.add_subplot()
    stick = simulation.stick_phases[0] if simulation.stick_phases else None
    slip = simulation.slip_phases[0] if simulation.slip_phases else None
    v_top = 1.3 * max(simulation.critical_velocity, slip.start_velocity if slip is not None else 0.0, 1e-12)
    grid = np.linspace(0.2 * simulation.critical_velocity, v_top, 300)
    aging = steady_state(params, grid, aging=True)
    plain = steady_state(params, grid, aging=False)
    ax.plot(grid * UM_PER_S, plain.stress, ":", color=NO_AGING_COLOR, linewidth=1.6, label="steady, without aging")
    ax.plot(grid * UM_PER_S, aging.stress, color=AGING_COLOR, linewidth=1.6, alpha=0.6, label="steady, with aging")
    path_style = {"color": "#111111", "linewidth": 2.2}
    if stick is not None:
        top = stick.peak_stress if stick.peak_stress is not None else float(stick.stress[-1])
        ax.plot([0.0, 0.0], [stick.start_stress, top], **path_style, gid="stick path")
        ax.annotate("stick", xy=(0.0, 0.5 * (stick.start_stress + top)), xytext=(6, 0), textcoords="offset points",
                    fontsize=9, va="center")  # fmt: skip
        if slip is not None:
            ax.annotate("", xy=(slip.start_velocity * UM_PER_S, slip.start_stress), xytext=(0.0, top),
                        arrowprops={"arrowstyle": "->", "color": "#111111", "linestyle": "--"})  # fmt: skip
            ax.text(0.5 * slip.start_velocity * UM_PER_S, top, "jump", fontsize=9, ha="center", va="bottom")
    if slip is not None:
        ax.plot(slip.velocity * UM_PER_S, slip.stress, **path_style, label="cycle path")
        ax.text(slip.velocity[len(slip.velocity) // 3] * UM_PER_S, slip.stress[len(slip.stress) // 3], "  slip",
                fontsize=9, va="top")  # fmt: skip
        if slip.ends == "stick":
            ax.annotate("", xy=(0.0, slip.end_stress), xytext=(slip.end_velocity * UM_PER_S, slip.end_stress),
                        arrowprops={"arrowstyle": "->", "color": "#111111", "linestyle": "--"})  # fmt: skip
    ax.plot([simulation.critical_velocity * UM_PER_S], [simulation.critical_stress], "o", color=CRITICAL_COLOR,
            label="critical point")  # fmt: skip
    stresses = [simulation.critical_stress, float(np.max(plain.stress))]
    if stick is not None and stick.peak_stress is not None:
        stresses.append(stick.peak_stress)
    ax.set_ylim(0.0, 1.2 * max(stresses))
    ax.set_xlim(-0.03 * v_top * UM_PER_S, v_top * UM_PER_S)
    ax.set_xlabel(VELOCITY_LABEL)
    ax.set_ylabel(STRESS_LABEL)
    ax.legend(loc="lower right", frameon=False, fontsize=8)
    ax.set_title(title or f"Stick-slip cycle on the σ-V diagram (Fig 2), V0 = {_um(simulation.pulling_velocity)}",
                 fontsize=11)  # fmt: skip
    apply_style(ax)
    return fig
