"""Plots of a sweep: the phase diagram of two varied keys, or the results against one, with the model's boundary.

Regimes in discrete colours, numbers on a colour scale, failed points as grey crosses; a full grid as cells,
a Latin hypercube as points; one key (:func:`figure_sweep_1d`): a panel per result column (docs/sweep.md).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..display import symbol
from ..errors import ParameterError
from ..sweeps.models import get_model
from ..units import DIMENSIONS
from .style import apply_style, legend_of_all_panels, new_axes

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

REGIME_COLORS = {
    "stick-slip": "#c0392b",
    "steady": "#1f4e9c",
    "stuck": "#7f8c8d",
    "undetermined": "#f1c40f",
    "steady sliding": "#1f4e9c",  # rate-and-state's names
    "decaying oscillation": "#5dade2",
    "growing oscillation": "#e67e22",
}
#: Display units: velocities in µm/s, everything else in SI.
DISPLAY = {"velocity": (1e6, "µm/s")}
#: Axis names of the keys that are not parameters (those take their description from stickslip.parameters).
KEY_NAMES = {
    "pulling_velocity": "pulling velocity V0",
    "block.stiffness": "block stiffness Gd/h",
    "block.effective_stiffness": "effective block stiffness K",
    "a": "rate-and-state a",
    "b": "rate-and-state b",
    "dc": "critical slip distance Dc",
    "k": "spring stiffness k",
    "eta": "radiation damping η",
    "mu0": "reference friction μ0",
    "v_ref": "reference velocity",
    "normal_stress": "normal stress σn",
}
#: Units of the result columns in colour (SI, as stored).
RESULT_UNITS = {
    "period": "s",
    "stick_time": "s",
    "peak_stress": "Pa",
    "mean_stress": "Pa",
    "jump_velocity": "m/s",
    "critical_velocity": "m/s",
    "wall_time": "s",
    "peak_friction": "",
    "trough_friction": "",
    "mean_friction": "",
    "critical_stiffness": "1/m",  # rsf: friction per slip
    "growth": "",
    "cycles": "",
}
#: Axis names of the result columns (a column not named here is shown by its key).
RESULT_NAMES = {
    "period": "period",
    "stick_time": "stick time ts",
    "peak_stress": "peak stress σs",
    "mean_stress": "mean stress",
    "jump_velocity": "jump velocity Vs",
    "critical_velocity": "critical velocity Vc",
    "peak_friction": "peak friction μ",
    "trough_friction": "trough friction μ",
    "mean_friction": "mean friction μ",
    "critical_stiffness": "critical stiffness kc",
    "growth": "amplitude growth per period",
    "cycles": "whole cycles",
    "wall_time": "wall time",
}
#: The columns a 1-D plot shows by default, those of the model's results that exist, in this order.
ONE_KEY_COLUMNS = ("period", "peak_stress", "mean_stress", "peak_friction", "mean_friction")
#: Columns that are not results.
NOT_RESULTS = ("point", "status", "message")
#: Values whose largest/smallest ratio is at least this get a log axis or a log colour scale.
DECADES = 30.0


def plot_phase_diagram(
    frame: Any,
    spec: Any,
    x: str,
    y: str | None = None,
    color: str = "regime",
    ax: Axes | None = None,
    at: Mapping[str, Any] | None = None,
) -> Axes:
    """The phase diagram of a sweep's rows ``frame`` (see :func:`stickslip.sweeps.load_sweep`); returns the Axes.

    ``at`` (key -> value, a number in SI or a string with a unit) keeps the rows at those values of varied keys.
    A sweep that varies other keys than ``x`` and ``y`` draws one panel per combination of their values (up to
    :data:`MAX_PANELS`; returns the first panel, its ``.figure`` the whole figure): drawn in one panel, points
    at the same (x, y) would cover each other.  More combinations are refused unless ``at`` picks values, or
    unless no two points share an (x, y) (a Latin hypercube: one panel, its title naming the keys not shown).

    With ``y`` None (a sweep of one key) it draws :func:`figure_sweep_1d` instead, ``color`` naming the result
    column(s) to show (comma-separated; ``regime``: the default columns), and returns the first panel (its
    ``.figure`` is the whole figure).
    """
    if y is None:
        if ax is not None:
            raise ParameterError("plot_phase_diagram: a 1-D plot (y=None) draws its own figure; give no ax")
        columns = None if color == "regime" else [c.strip() for c in color.split(",") if c.strip()]
        return figure_sweep_1d(select_rows(frame, spec, at), spec, x, columns, pinned=tuple(at or ())).axes[0]
    for option, key in (("--x", x), ("--y", y)):
        if key not in spec.keys:
            raise ParameterError(
                f"{option} {key}: not a varied key of this sweep; expected one of {', '.join(spec.keys)}"
            )
    if y == x:
        other = "leave --y out for a sweep of one key" if len(spec.keys) == 1 else "give another varied key"
        raise ParameterError(f"--y {y}: the same key as --x; a phase diagram needs two keys ({other})")
    if color not in frame.columns or color in NOT_RESULTS:
        choices = [c for c in frame.columns if c not in NOT_RESULTS]
        what = "not a result column to colour by" if color in frame.columns else "not a column of this sweep"
        raise ParameterError(f"--color {color}: {what}; expected one of {', '.join(choices)}")
    frame = select_rows(frame, spec, at)
    model = get_model(spec.model)
    dimensions = model.dimensions()
    others = other_keys(frame, spec, x, y)
    groups = _panel_groups(frame, others, x, y, ax)
    ok = frame[frame["status"] == "ok"]
    numbers = not (color == "regime" or ok[color].dtype == object or str(ok[color].dtype) in ("str", "string"))
    all_xs, all_ys = (_scaled(frame[k].to_numpy(dtype=float), dimensions[k]) for k in (x, y))
    logs = (_log_axis(spec, x, all_xs), _log_axis(spec, y, all_ys))
    if len(groups) == 1:
        axes = [apply_style(new_axes(ax, figsize=(6.8, 4.8)))]
    else:
        from matplotlib.figure import Figure

        ncols = min(len(groups), PANEL_COLUMNS)
        nrows = -(-len(groups) // ncols)
        fig = Figure(figsize=(1.4 + 4.0 * ncols, 0.8 + 3.4 * nrows), layout="constrained")
        grid = fig.subplots(nrows, ncols, sharex=True, sharey=True, squeeze=False)
        axes = [apply_style(a) for a in grid.ravel()[: len(groups)]]
        for spare in grid.ravel()[len(groups) :]:
            spare.set_visible(False)
    # one colour per regime and one colour scale for every panel: the same colour means the same in each
    labels = ok[color].astype(str).to_numpy() if not numbers else None
    palette = _regime_colors(labels) if labels is not None else None
    norm = _norm(ok[color].to_numpy(dtype=float)) if numbers else None
    mappable = None
    failures = f"failed ({int((frame['status'] != 'ok').sum())})"  # one legend entry for every panel's crosses
    for panel, (values, rows) in zip(axes, groups, strict=True):
        drawn = _draw_panel(panel, rows, spec, model, dimensions, (x, y), color, logs, palette, norm, failures)
        mappable = drawn if mappable is None else mappable
        if values:
            panel.set_title(_values_text(values, dimensions), fontsize=9)
    if mappable is not None:
        unit = RESULT_UNITS.get(color, "")
        label = f"{color} ({unit}); blank: none" if unit else f"{color}; blank: none"
        axes[0].figure.colorbar(mappable, ax=axes, label=label)
    for panel in axes:
        for setter, on in ((panel.set_xscale, logs[0]), (panel.set_yscale, logs[1])):
            if on:
                setter("log")
    ncols = _ncols(axes) if len(axes) > 1 else 1
    for i, panel in enumerate(axes):
        if i + ncols >= len(axes):  # nothing below it (a spare cell of the last row is hidden): it names x
            panel.set_xlabel(_label(x, dimensions[x]))
            panel.xaxis.set_tick_params(labelbottom=True)
        if i % ncols == 0:
            panel.set_ylabel(_label(y, dimensions[y]))
    title = f"{spec.label or spec.model}: {color} ({spec.model} model, {len(frame)} points)"
    picked = {k: float(frame[k].iloc[0]) for k in (at or {}) if len(frame)}
    if picked:
        title += f" at {_values_text(picked, dimensions)}"
    note = keys_not_plotted(frame, spec, x, y)
    if note:  # a projection, or panels: the title says over which keys
        title += f";\n{note}"
    if len(groups) == 1:
        axes[0].set_title(title, fontsize=10)
    else:
        axes[0].figure.suptitle(title, fontsize=10)
    legend_of_all_panels(axes[0].figure, axes, loc="best", fontsize=8, framealpha=0.85, ncols=1, frameon=True)
    return axes[0]


#: The most panels a phase diagram draws for the values of the keys it does not plot (else: pick with ``at``).
MAX_PANELS = 6
#: Panels per row of the figure.
PANEL_COLUMNS = 3


def _ncols(axes: Sequence[Axes]) -> int:
    """The number of columns of the panels' grid."""
    return axes[0].get_subplotspec().get_gridspec().ncols


def other_keys(frame: Any, spec: Any, x: str, y: str) -> dict[str, list[float]]:
    """The varied keys other than ``x`` and ``y`` that take more than one value in ``frame``: key -> values (SI)."""
    others: dict[str, list[float]] = {}
    for key in spec.keys:
        if key not in (x, y) and key in frame.columns:
            values = sorted(set(frame[key].dropna().astype(float).tolist()))
            if len(values) > 1:
                others[key] = values
    return others


def keys_not_plotted(frame: Any, spec: Any, x: str, y: str) -> str:
    """What the phase diagram of ``frame`` does with the varied keys not on its axes, in words ("" if none):
    ``a panel per value of mu0 (0.4, 0.55)``, or ``not shown on the axes: mu0 (40 values, 0.4 to 0.55)`` where
    no two points share an (x, y)."""
    others = other_keys(frame, spec, x, y)
    if not others:
        return ""
    dimensions = get_model(spec.model).dimensions()
    parts = []
    for key, values in others.items():
        unit = DISPLAY.get(dimensions[key], (1.0, DIMENSIONS[dimensions[key]][1]))[1]
        shown = _scaled(np.asarray(values), dimensions[key])
        text = ", ".join(f"{v:.4g}" for v in shown)
        if len(values) > MAX_PANELS:
            text = f"{len(values)} values, {shown[0]:.4g} to {shown[-1]:.4g}"
        parts.append(f"{key} ({text}{' ' + unit if unit else ''})")
    listed = "; ".join(parts)
    if frame.duplicated(subset=[x, y]).any():
        return f"a panel per value of {listed}"
    return f"not shown on the axes: {listed}"


def select_rows(frame: Any, spec: Any, at: Mapping[str, Any] | None) -> Any:
    """The rows at ``at``'s values of varied keys (``--at KEY=VALUE``; a value in SI or with a unit)."""
    if not at:
        return frame
    from ..units import to_si

    dimensions = get_model(spec.model).dimensions()
    for key, raw in at.items():
        if key not in spec.keys:
            raise ParameterError(f"--at {key}: not a varied key of this sweep; expected one of {', '.join(spec.keys)}")
        value = to_si(raw, dimensions[key], f"--at {key}")
        column = frame[key].to_numpy(dtype=float)
        match = np.isclose(column, value, rtol=1e-9, atol=0.0)
        if not match.any():
            held = ", ".join(f"{v:g}" for v in sorted(set(column.tolist())))
            raise ParameterError(f"--at {key}={raw}: no point of the sweep has that value; it has {held} (SI)")
        frame = frame[match]
    return frame


def _panel_groups(
    frame: Any, others: Mapping[str, list[float]], x: str, y: str, ax: Axes | None
) -> list[tuple[dict[str, float], Any]]:
    """(values of the keys not plotted, their rows) for each panel; one panel, values {}, when they need none."""
    if not others:
        return [({}, frame)]
    keys = list(others)
    groups = [(dict(zip(keys, values, strict=True)), rows) for values, rows in frame.groupby(keys, sort=True)]
    groups = [({k: float(v) for k, v in values.items()}, rows) for values, rows in groups]
    if len(groups) == 1:
        return [({}, frame)]
    shared = frame.duplicated(subset=[x, y]).any()
    if not shared:  # every point has its own (x, y): nothing is covered, one panel shows all
        return [({}, frame)]
    pick = f"pick values with --at KEY=VALUE (e.g. --at {keys[0]}={others[keys[0]][0]:g})"
    if ax is not None:
        raise ParameterError(
            f"plot_phase_diagram: the sweep also varies {', '.join(keys)}, whose points share (x, y); a panel per"
            f" value needs a figure of its own: give no ax, or {pick}"
        )
    if len(groups) > MAX_PANELS:
        raise ParameterError(
            f"the sweep also varies {', '.join(keys)} ({len(groups)} combinations of values, more than"
            f" {MAX_PANELS} panels), whose points would cover each other at the same ({x}, {y}); {pick}"
        )
    return groups


def _values_text(values: Mapping[str, float], dimensions: Mapping[str, str]) -> str:
    """``mu0 = 0.4, pulling_velocity = 300 µm/s``: values in their display units."""
    parts = []
    for key, value in values.items():
        dimension = dimensions[key]
        unit = DISPLAY.get(dimension, (1.0, DIMENSIONS[dimension][1]))[1]
        shown = _scaled(np.array([value]), dimension)[0]
        parts.append(f"{key} = {shown:.4g}{' ' + unit if unit else ''}")
    return ", ".join(parts)


def _norm(values: np.ndarray) -> Any:
    from matplotlib.colors import LogNorm, Normalize

    finite = values[np.isfinite(values)]
    if not finite.size:
        return Normalize()
    low, high = float(finite.min()), float(finite.max())
    return LogNorm(low, high) if _spans_decades(finite) else Normalize(low, high)


def _draw_panel(
    ax: Axes,
    frame: Any,
    spec: Any,
    model: Any,
    dimensions: Mapping[str, str],
    keys: tuple[str, str],
    color: str,
    logs: tuple[bool, bool],
    palette: list[tuple[str, str]] | None,
    norm: Any,
    failures: str,
) -> Any:
    """One panel: the rows' points or cells, failed points, the model's boundary; returns the colour scale's
    mappable (None for categories)."""
    x, y = keys
    ok = frame[frame["status"] == "ok"]
    xs, ys = (_scaled(ok[k].to_numpy(dtype=float), dimensions[k]) for k in (x, y))
    cells = _is_full_grid(xs, ys)
    # the scales first: the limits kept below are read in them (read on linear axes, a Latin hypercube's log axes
    # were frozen at a negative lower limit, and its points fell outside the plot)
    for setter, on in ((ax.set_xscale, logs[0]), (ax.set_yscale, logs[1])):
        if on:
            setter("log")
    mappable = None
    if palette is not None:
        _draw_categories(ax, xs, ys, ok[color].astype(str).to_numpy(), cells, logs, palette)
    else:
        mappable = _draw_numbers(ax, xs, ys, ok[color].to_numpy(dtype=float), cells, logs, norm)
    failed = frame[frame["status"] != "ok"]
    if len(failed):
        ax.scatter(
            _scaled(failed[x].to_numpy(dtype=float), dimensions[x]),
            _scaled(failed[y].to_numpy(dtype=float), dimensions[y]),
            marker="x", color="#555555", s=18, label=failures,
        )  # fmt: skip
    # the axes keep the rows' range: a boundary is drawn where it falls inside it (the transient model's Kc(V0)
    # reached 1e11 Pa/m over rows of at most 4 MPa/m, and stretched the axis five decades above the points)
    xlim, ylim = ax.get_xlim(), ax.get_ylim()
    for boundary in model.boundaries(spec, ok, x, y):
        bx, by = _scaled(boundary.x, dimensions[x]), _scaled(boundary.y, dimensions[y])
        line = {"color": "black", "linewidth": 1.6, "linestyle": "--", "label": boundary.label}
        if np.all(np.isnan(by)):  # independent of the other axis: a line across the plot
            ax.axvline(bx[0], **line)
        elif np.all(np.isnan(bx)):
            ax.axhline(by[0], **line)
        else:
            if not _crosses(bx, by, xlim, ylim):
                line["label"] = f"{boundary.label} (outside the plotted range)"
            ax.plot(bx, by, marker="" if len(bx) > 12 else ".", **line)
    ax.set_xlim(xlim)
    ax.set_ylim(ylim)
    return mappable


def _crosses(bx: np.ndarray, by: np.ndarray, xlim: tuple[float, float], ylim: tuple[float, float]) -> bool:
    """Whether a curve through (bx, by) enters the box xlim x ylim: a point inside, or a segment across it (its
    bounding box meets the box: enough for a curve sampled finely beside the box's size)."""
    ok = np.isfinite(bx) & np.isfinite(by)
    bx, by = bx[ok], by[ok]
    (x0, x1), (y0, y1) = sorted(xlim), sorted(ylim)
    if not bx.size:
        return False
    if np.any((bx >= x0) & (bx <= x1) & (by >= y0) & (by <= y1)):
        return True
    low_x, high_x = np.minimum(bx[:-1], bx[1:]), np.maximum(bx[:-1], bx[1:])
    low_y, high_y = np.minimum(by[:-1], by[1:]), np.maximum(by[:-1], by[1:])
    return bool(np.any((low_x <= x1) & (high_x >= x0) & (low_y <= y1) & (high_y >= y0)))


def _scaled(values: np.ndarray, dimension: str) -> np.ndarray:
    return np.asarray(values, dtype=float) * DISPLAY.get(dimension, (1.0, ""))[0]


def _label(key: str, dimension: str) -> str:
    """The quantity's name and its display unit: ``block stiffness Gd/h (kPa/m)``, not the raw key."""
    unit = DISPLAY.get(dimension, (1.0, DIMENSIONS[dimension][1]))[1]
    name = _name(key)
    return f"{name} ({unit})" if unit else name


def _name(key: str) -> str:
    """The quantity a key stands for: ``pulling velocity V0``, ``block stiffness Gd/h``, a parameter's description."""
    return KEY_NAMES.get(key) or _parameter_name(key) or key.replace("_", " ")


def _parameter_name(key: str) -> str | None:
    """``bonds.bond_time`` -> ``thermal make-break time constant τ`` (the parameter's own description)."""
    from dataclasses import fields

    from ..parameters import SECTIONS

    section, _, name = key.partition(".")
    found = next((f for f in fields(SECTIONS[section]) if f.name == name), None) if section in SECTIONS else None
    if found is None:
        return None
    return f"{found.metadata['doc']} {symbol(found.metadata['symbol'])}"


def _log_axis(spec: Any, key: str, values: np.ndarray) -> bool:
    """A log axis for a key the sweep spaced geometrically, or whose values span decades."""
    axis = next((a for a in getattr(spec, "axes", ()) if a.key == key), None)
    positive = values[np.isfinite(values)]
    if axis is not None and axis.log and positive.size and positive.min() > 0:
        return True
    return _spans_decades(values)


def _spans_decades(values: np.ndarray) -> bool:
    finite = values[np.isfinite(values)]
    return bool(finite.size and finite.min() > 0 and finite.max() / finite.min() >= DECADES)


def _is_full_grid(xs: np.ndarray, ys: np.ndarray) -> bool:
    ux, uy = np.unique(xs), np.unique(ys)
    pairs = {(a, b) for a, b in zip(xs.tolist(), ys.tolist(), strict=True)}
    return len(pairs) == xs.size == ux.size * uy.size and ux.size > 1 and uy.size > 1


def _edges(values: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges halfway between grid values (geometrically on a log axis), extended at the ends."""
    u = np.unique(values)
    w = np.log(u) if log else u
    mid = 0.5 * (w[1:] + w[:-1])
    edges = np.r_[w[0] - (mid[0] - w[0]), mid, w[-1] + (w[-1] - mid[-1])]
    if not log and u[0] >= 0.0:  # a positive quantity's first cell stops at 0 (it reached -1.4 MPa/m of stiffness)
        edges[0] = max(edges[0], 0.0)
    return np.exp(edges) if log else edges


def _cells(
    xs: np.ndarray, ys: np.ndarray, values: np.ndarray, logs: tuple[bool, bool]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    ux, uy = np.unique(xs), np.unique(ys)
    grid = np.full((uy.size, ux.size), np.nan)
    grid[np.searchsorted(uy, ys), np.searchsorted(ux, xs)] = values
    return _edges(xs, logs[0]), _edges(ys, logs[1]), grid


def _draw_categories(
    ax: Axes,
    xs: np.ndarray,
    ys: np.ndarray,
    labels: np.ndarray,
    cells: bool,
    logs: tuple[bool, bool],
    palette: list[tuple[str, str]],
) -> None:
    from matplotlib.colors import ListedColormap

    names, colors = (list(column) for column in zip(*palette, strict=True))
    present = set(labels.tolist())
    codes = np.array([names.index(label) for label in labels], dtype=float)
    if cells:
        ex, ey, grid = _cells(xs, ys, codes, logs)
        ax.pcolormesh(ex, ey, np.ma.masked_invalid(grid), cmap=ListedColormap(colors), vmin=-0.5, vmax=len(names) - 0.5)
        for n, c in zip(names, colors, strict=True):  # legend entries for the cells
            if n in present:
                ax.scatter([], [], marker="s", color=c, label=n)
        return
    for name, c in zip(names, colors, strict=True):
        mask = labels == name
        if mask.any():
            ax.scatter(xs[mask], ys[mask], s=14, color=c, label=name, edgecolors="none")


def _draw_numbers(
    ax: Axes, xs: np.ndarray, ys: np.ndarray, values: np.ndarray, cells: bool, logs: tuple[bool, bool], norm: Any
) -> Any:
    """Numbers on the colour scale ``norm`` (shared by every panel); returns the mappable for the colour bar."""
    if cells:
        ex, ey, grid = _cells(xs, ys, values, logs)
        return ax.pcolormesh(ex, ey, np.ma.masked_invalid(grid), cmap="viridis", norm=norm)
    return ax.scatter(xs, ys, c=values, s=14, cmap="viridis", norm=norm, plotnonfinite=False)


# --------------------------------------------------------------------------- one key
def figure_sweep_1d(
    frame: Any, spec: Any, x: str, columns: Sequence[str] | None = None, pinned: Sequence[str] = ()
) -> Figure:
    """The results of a sweep against one varied key ``x``: one panel per column, sharing the x axis.

    ``columns`` default to those of :data:`ONE_KEY_COLUMNS` the sweep holds (period, peak and mean stress, or
    friction for rate-and-state).  Each point's marker has the colour of its regime (a point whose value is
    blank, such as the period of steady sliding, is absent from that panel only); failed points are grey crosses
    on the x axis.  The model's boundary on ``x`` (V0 = Vc, k = kc), where it gives one, is a dashed vertical
    line.  The x axis is logarithmic for a log-spaced key, a y axis where its values span decades.  ``pinned``:
    the varied keys ``frame`` was cut to one value of (``--at``): a sweep of several keys, all but x pinned, is a
    sweep of one key.
    """
    from matplotlib.figure import Figure

    free = [k for k in spec.keys if k not in pinned]
    if len(free) != 1 and x not in spec.keys:  # named first: a mistyped --x, not the --y left out
        raise ParameterError(f"--x {x}: not a varied key of this sweep; expected one of {', '.join(spec.keys)}")
    if len(free) != 1:
        others = ", ".join(k for k in free if k != x)
        raise ParameterError(
            f"--y: this sweep varies {', '.join(spec.keys)}; give --y KEY, or pin {others} with --at KEY=VALUE"
            " (a plot without --y needs one key left)"
        )
    if x not in free:
        raise ParameterError(f"--x {x}: not the varied key of this sweep; expected {free[0]}")
    chosen = _one_key_columns(frame, columns)
    model = get_model(spec.model)
    dimensions = model.dimensions()
    ok = frame[frame["status"] == "ok"]
    xs = _scaled(ok[x].to_numpy(dtype=float), dimensions[x])
    regimes = ok["regime"].astype(str).to_numpy() if "regime" in ok else np.full(xs.size, "ok")
    fig = Figure(figsize=(6.8, 1.2 + 2.4 * len(chosen)), layout="constrained")
    axes = fig.subplots(len(chosen), 1, sharex=True, squeeze=False)[:, 0]
    for ax, column in zip(axes, chosen, strict=True):
        _draw_column(ax, xs, ok[column].to_numpy(dtype=float), regimes, column)
        apply_style(ax)
    failed = frame[frame["status"] != "ok"]
    if len(failed):
        from matplotlib.transforms import blended_transform_factory

        where = blended_transform_factory(axes[-1].transData, axes[-1].transAxes)
        fx = _scaled(failed[x].to_numpy(dtype=float), dimensions[x])
        axes[-1].plot(fx, np.zeros(fx.size), "x", color="#555555", transform=where, clip_on=False,
                      label=f"failed ({len(failed)})")  # fmt: skip
    for boundary in model.boundaries(spec, ok, x, None):
        if boundary.x.size and np.all(np.isnan(boundary.y)) and np.isfinite(boundary.x[0]):
            for k, ax in enumerate(axes):
                ax.axvline(_scaled(boundary.x, dimensions[x])[0], color="black", linewidth=1.4, linestyle="--",
                           label=boundary.label if k == 0 else None)  # fmt: skip
    if _log_axis(spec, x, xs):
        axes[-1].set_xscale("log")
    axes[-1].set_xlabel(_label(x, dimensions[x]))
    legend_of_all_panels(fig, axes, loc="best", frameon=True, ncols=1, framealpha=0.85)
    axes[0].set_title(f"{spec.label or spec.model}: results against {_name(x)} ({len(frame)} points)", fontsize=10)
    return fig


def _one_key_columns(frame: Any, columns: Sequence[str] | None) -> list[str]:
    """The numeric result columns to draw: the ones asked for (checked), or the default ones the sweep holds."""
    numeric = [
        c for c in frame.columns if c not in NOT_RESULTS and c != "regime" and np.issubdtype(frame[c].dtype, np.number)
    ]
    if columns is None:
        chosen = [c for c in ONE_KEY_COLUMNS if c in numeric]
        return chosen or numeric[:1]
    if not columns:
        raise ParameterError(f"--color: name a result column; expected one of {', '.join(numeric)}")
    for column in columns:
        if column not in numeric:
            raise ParameterError(
                f"--color {column}: not a numeric result of this sweep; expected one of {', '.join(numeric)}"
            )
    return list(columns)


def _draw_column(ax: Axes, xs: np.ndarray, values: np.ndarray, regimes: np.ndarray, column: str) -> None:
    """The column against x: a thin line through the points in x order, each marker in its regime's colour."""
    dimension = RESULT_DIMENSIONS.get(column)
    shown = _scaled(values, dimension) if dimension else values
    order = np.argsort(xs, kind="stable")
    finite = order[np.isfinite(shown[order])]
    ax.plot(xs[finite], shown[finite], color="#999999", linewidth=0.8, zorder=1, label="_trend")
    for name, color in _regime_colors(regimes):
        mask = (regimes == name) & np.isfinite(shown)
        ax.scatter(xs[mask], shown[mask], s=22, color=color, label=name, zorder=3, edgecolors="none")
    if _spans_decades(shown):
        ax.set_yscale("log")
    ax.set_ylabel(_result_label(column))


#: Result columns shown in a display unit (velocities in µm/s).
RESULT_DIMENSIONS = {"jump_velocity": "velocity", "critical_velocity": "velocity"}


def _result_label(column: str) -> str:
    """``peak stress σs (Pa)``: the quantity's name and its display unit."""
    dimension = RESULT_DIMENSIONS.get(column)
    unit = DISPLAY[dimension][1] if dimension in DISPLAY else RESULT_UNITS.get(column, "")
    name = RESULT_NAMES.get(column, column.replace("_", " "))
    return f"{name} ({unit})" if unit else name


def _regime_colors(regimes: np.ndarray) -> list[tuple[str, str]]:
    """(regime, colour) in the order of REGIME_COLORS, then any other regime with a spare colour."""
    present = set(regimes.tolist())
    names = [n for n in REGIME_COLORS if n in present] + sorted(present - set(REGIME_COLORS))
    spare = iter(["#8e44ad", "#16a085", "#d35400", "#2c3e50", "#27ae60"] * 4)
    return [(n, REGIME_COLORS.get(n) or next(spare)) for n in names]
