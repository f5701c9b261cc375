"""Figures of the steady friction curve (the paper's Fig 1 and Fig 4), and of a protocol.

Figures are built on :class:`matplotlib.figure.Figure` directly, never through
pyplot, so nothing here touches global state or opens a window: safe in
scripts, tests and headless servers.  Axes show velocities in um/s and
stresses in Pa; the objects passed in hold SI values.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

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
    from ..quasistatic.steady import SteadyState


def plot_steady(result: SteadyState, ax: Axes | None = None, **kwargs: Any) -> Axes:
    """sigma against log V for one :class:`~stickslip.quasistatic.steady.SteadyState`; returns the Axes.

    ``kwargs`` go to ``Axes.plot`` (``label`` defaults to "with aging" or
    "without aging").  Velocities are shown in um/s on a log axis.
    """
    ax = new_axes(ax)
    velocity = np.ravel(result.velocity) * UM_PER_S
    stress = np.ravel(result.stress)
    order = np.argsort(velocity)
    kwargs.setdefault("label", "with aging" if result.aging else "without aging")
    kwargs.setdefault("color", AGING_COLOR if result.aging else NO_AGING_COLOR)
    if velocity.size == 1:
        kwargs.setdefault("marker", "o")
    ax.plot(velocity[order], stress[order], **kwargs)
    _interesting_range(ax, stress[order])
    ax.set_xscale("log")
    ax.set_xlabel(VELOCITY_LABEL)
    ax.set_ylabel(STRESS_LABEL)
    apply_style(ax)
    return ax


def _interesting_range(ax: Axes, stress: np.ndarray) -> None:
    """With a minimum inside the grid, keep it in view: the aging curve climbs to tens of kPa far below Vc
    (19 kPa at 10 µm/s for the paper's set) and would squash the minimum flat; the top is set by the branch
    above the minimum (x 1.25, at least twice the minimum)."""
    finite = stress[np.isfinite(stress)]
    if finite.size < 3:
        return
    low = int(np.argmin(finite))
    if not 0 < low < finite.size - 1:
        return
    top = 1.25 * max(float(np.max(finite[low:])), 2.0 * float(finite[low]))
    if float(np.max(finite)) > top:
        ax.set_ylim(min(0.0, float(finite[low])), top)


def _data_arrays(data: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """(velocity, stress, stress error or None), SI, from a table, mapping, object or pair."""
    expected = "(velocity, stress[, stress_err]) arrays, a mapping or table with 'velocity' and 'stress'"
    v, s, err = data_columns(data, ("velocity", "stress"), "stress_err", expected)
    v, s = np.asarray(v, dtype=float).ravel(), np.asarray(s, dtype=float).ravel()
    if v.shape != s.shape:
        raise ValueError(f"data: velocity has {v.size} values but stress has {s.size}")
    if err is not None:
        err = np.asarray(err, dtype=float).ravel()
        if err.shape != v.shape or not np.any(np.isfinite(err)):
            err = None
    return v, s, err


def figure_steady_curve(
    params: Parameters,
    vmin: float = 10e-6,
    vmax: float = 10e-3,
    data: Any = None,
    points: int = 300,
    title: str | None = None,
) -> Figure:
    """The paper's Fig 1 / Fig 4: sigma against log V with and without aging.

    The critical point (Vc, sigma_c) of Eq 9 is marked when it lies in
    [``vmin``, ``vmax``] (m/s), and the two branches are labelled: velocity
    weakening to its left, velocity strengthening to its right.  ``data``
    (optional, SI) adds measured points: a pair/triple of arrays
    ``(velocity, stress[, stress_err])``, or anything indexable or with
    attributes ``velocity``, ``stress`` (and optionally ``stress_err``).
    """
    from matplotlib.figure import Figure

    from ..quasistatic.critical import critical_point
    from ..quasistatic.steady import steady_state

    if not (0 < vmin < vmax) or not np.isfinite(vmax):
        raise ValueError(f"figure_steady_curve: expected 0 < vmin < vmax, got vmin={vmin!r}, vmax={vmax!r}")
    grid = np.geomspace(vmin, vmax, max(int(points), 2))
    aging = steady_state(params, grid, aging=True)
    plain = steady_state(params, grid, aging=False)
    critical = critical_point(params)

    fig = Figure(figsize=(6.8, 4.6), layout="constrained")
    ax = fig.add_subplot()
    plot_steady(plain, ax=ax, linestyle=":", linewidth=1.8, label="without aging")
    plot_steady(aging, ax=ax, linewidth=2.0, label="with aging")

    tops = [float(np.max(plain.stress))]
    if data is not None:
        v, s, err = _data_arrays(data)
        ax.errorbar(
            v * UM_PER_S,
            s,
            yerr=err,
            fmt="o",
            markersize=4,
            color=DATA_COLOR,
            ecolor=DATA_COLOR,
            label="data",
            zorder=5,
        )
        if np.any(np.isfinite(s)):
            tops.append(float(np.nanmax(s)))
    if critical.exists and vmin <= critical.velocity <= vmax:
        _mark_critical(ax, critical.velocity, critical.stress, grid, aging.stress)
        _mark_maxima(ax, [e for e in critical.extrema if e.kind == "maximum" and vmin <= e.velocity <= vmax], grid)
        tops.append(critical.stress)
    # the aging curve climbs steeply below Vc (Fig 4); keep the interesting range in view
    top = 1.25 * max(tops)
    bottom = min(0.0, float(np.min(plain.stress)))
    if float(np.min(aging.stress)) < top:
        ax.set_ylim(bottom, top)
    ax.set_xlim(vmin * UM_PER_S, vmax * UM_PER_S)
    ax.legend(loc="lower right", frameon=False)
    ax.set_title(title if title is not None else f"Steady friction curve ({params.name})", fontsize=11)
    return fig


def _mark_critical(ax: Axes, vc: float, sc: float, grid: np.ndarray, stress: np.ndarray) -> None:
    """Vc and sigma_c with a guide line, and the two branch labels on either side of Vc."""
    from matplotlib.transforms import blended_transform_factory

    x = vc * UM_PER_S
    box = {"boxstyle": "round,pad=0.25", "facecolor": "white", "edgecolor": "none", "alpha": 0.85}
    ax.axvline(x, color=CRITICAL_COLOR, linestyle="--", linewidth=0.8, alpha=0.7)
    ax.plot(
        [x], [sc], marker="o", markersize=7, color=CRITICAL_COLOR, zorder=6, linestyle="none", label="critical point"
    )
    ax.annotate(
        f"$V_c$ = {x:.4g} µm/s\n$\\sigma_c$ = {sc:.4g} Pa",
        xy=(x, sc),
        xytext=(-12, -12),
        textcoords="offset points",
        ha="right",
        va="top",
        fontsize=9,
        bbox=box,
        zorder=7,
    )
    # x in data units, y in axes units: the labels sit on either side of Vc, high in the frame
    where = blended_transform_factory(ax.transData, ax.transAxes)
    style = {"transform": where, "fontsize": 9, "va": "top", "bbox": box, "zorder": 7}
    if np.count_nonzero(grid < vc) >= 2:
        ax.text(x / 2.0, 0.82, "velocity weakening\n(dσ/dV < 0)  ←", ha="right", **style)
    if np.count_nonzero(grid > vc) >= 2:
        ax.text(x * 1.5, 0.82, "→  velocity strengthening\n    (dσ/dV > 0)", ha="left", **style)


def plot_critical(point: Any, ax: Axes | None = None) -> Axes:
    """A :class:`~stickslip.quasistatic.critical.CriticalPoint` drawn: every extremum of the aging curve as a point
    (the minimum (Vc, sigma_c) labelled, a maximum open), on log V; without a minimum its message in the frame.

    On axes of its own or on empty ones given (``plot(ax=ax)``) it sets the log V axis, the style and both axis
    labels with their units; on axes that hold a drawing already (a steady curve) it keeps their scale, and labels
    an axis only where it has no label yet."""
    drawn_before = ax is not None and ax.has_data()
    ax = new_axes(ax)
    for extremum in point.extrema:
        minimum = extremum.kind == "minimum"
        x = extremum.velocity * UM_PER_S
        ax.plot([x], [extremum.stress], marker="o", markersize=7, linestyle="none", zorder=6,
                color=CRITICAL_COLOR, markerfacecolor=CRITICAL_COLOR if minimum else "white",
                label="critical point (Eq 9)" if minimum else f"maximum at {x:.4g} µm/s")  # fmt: skip
    if point.exists:
        box = {"boxstyle": "round,pad=0.25", "facecolor": "white", "edgecolor": "none", "alpha": 0.85}
        ax.annotate(f"$V_c$ = {point.velocity * UM_PER_S:.4g} µm/s\n$\\sigma_c$ = {point.stress:.4g} Pa",
                    xy=(point.velocity * UM_PER_S, point.stress), xytext=(-12, -12), textcoords="offset points",
                    ha="right", va="top", fontsize=9, bbox=box, zorder=7)  # fmt: skip
    else:
        ax.text(0.5, 0.5, point.message, transform=ax.transAxes, ha="center", va="center", fontsize=9, wrap=True)
    if not drawn_before:
        ax.set_xscale("log")
        apply_style(ax)
    if not ax.get_xlabel():
        ax.set_xlabel(VELOCITY_LABEL)
    if not ax.get_ylabel():
        ax.set_ylabel(STRESS_LABEL)
    return ax


def _mark_maxima(ax: Axes, maxima: list[Any], grid: np.ndarray) -> None:
    """A maximum of the aging curve (the paper's set: 5.04 mm/s) ends the strengthening branch: above it the
    curve weakens again, and the label says so rather than leave "strengthening" over the whole right side."""
    from matplotlib.transforms import blended_transform_factory

    where = blended_transform_factory(ax.transData, ax.transAxes)
    box = {"boxstyle": "round,pad=0.25", "facecolor": "white", "edgecolor": "none", "alpha": 0.85}
    for peak in maxima:
        x = peak.velocity * UM_PER_S
        ax.axvline(x, color=CRITICAL_COLOR, linestyle=":", linewidth=0.8, alpha=0.7)
        if np.count_nonzero(grid > peak.velocity) >= 2:
            ax.text(float(grid[-1]) * UM_PER_S, 0.55, f"weakening again\nabove {x / 1e3:.3g} mm/s  ",
                    transform=where, fontsize=9, va="top", ha="right", bbox=box, zorder=7)  # fmt: skip


def protocol_plot(protocol: Any, ax: Axes | None = None) -> Axes:
    """The load-point velocity of a :class:`~stickslip.protocols.Protocol` against time (a staircase)."""
    ax = new_axes(ax)
    b = protocol.boundaries
    v = np.append(protocol.velocities, protocol.velocities[-1]) * UM_PER_S
    ax.step(b, v, where="post", color=AGING_COLOR)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("load-point velocity (µm/s)")
    ax.set_title(protocol.describe(), fontsize="small")
    return apply_style(ax)
