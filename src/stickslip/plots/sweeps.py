"""Phase diagrams of a sweep: two varied keys on the axes, a result in colour, the analytic boundary drawn on.

Regimes are discrete colours; numbers a colour scale (logarithmic where they
span decades).  A full grid is drawn as cells, anything else (a Latin
hypercube) as points.  Failed points are grey crosses.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ParameterError
from ..sweeps.models import get_model
from ..units import DIMENSIONS
from .style import apply_style, new_axes

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

REGIME_COLORS = {
    "stick-slip": "#c0392b",
    "steady": "#1f4e9c",
    "stuck": "#7f8c8d",
    "undetermined": "#f1c40f",
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
}
#: Values whose largest/smallest ratio is at least this get a log axis or a log colour scale.
DECADES = 30.0


def plot_phase_diagram(frame: Any, spec: Any, x: str, y: str, color: str = "regime", ax: Axes | None = None) -> Axes:
    """The phase diagram of a sweep's rows ``frame`` (see :func:`stickslip.sweeps.load_sweep`); returns the Axes."""
    for option, key in (("--x", x), ("--y", y)):
        if key not in spec.keys:
            raise ParameterError(
                f"{option} {key}: not a varied key of this sweep; expected one of {', '.join(spec.keys)}"
            )
    if color not in frame.columns or color in ("point", "status", "message"):
        choices = [c for c in frame.columns if c not in ("point", "status", "message")]
        raise ParameterError(f"--color {color}: not a column of this sweep; expected one of {', '.join(choices)}")
    model = get_model(spec.model)
    dimensions = model.dimensions()
    ax = apply_style(new_axes(ax, figsize=(6.8, 4.8)))
    ok = frame[frame["status"] == "ok"]
    xs, ys = (_scaled(ok[k].to_numpy(dtype=float), dimensions[k]) for k in (x, y))
    cells = _is_full_grid(xs, ys)
    logs = (_log_axis(spec, x, xs), _log_axis(spec, y, ys))
    if color == "regime" or ok[color].dtype == object or str(ok[color].dtype) in ("str", "string"):
        _draw_categories(ax, xs, ys, ok[color].astype(str).to_numpy(), cells, logs)
    else:
        _draw_numbers(ax, xs, ys, ok[color].to_numpy(dtype=float), color, cells, logs)
    failed = frame[frame["status"] != "ok"]
    if len(failed):
        ax.scatter(
            _scaled(failed[x].to_numpy(dtype=float), dimensions[x]),
            _scaled(failed[y].to_numpy(dtype=float), dimensions[y]),
            marker="x", color="#555555", s=18, label=f"failed ({len(failed)})",
        )  # fmt: skip
    for boundary in model.boundaries(spec, ok, x, y):
        bx, by = _scaled(boundary.x, dimensions[x]), _scaled(boundary.y, dimensions[y])
        if np.all(np.isnan(by)):  # independent of the other axis: a line across the plot
            ax.axvline(bx[0], color="black", linewidth=1.6, linestyle="--", label=boundary.label)
        elif np.all(np.isnan(bx)):
            ax.axhline(by[0], color="black", linewidth=1.6, linestyle="--", label=boundary.label)
        else:
            ax.plot(
                bx,
                by,
                color="black",
                linewidth=1.6,
                linestyle="--",
                marker="" if len(bx) > 12 else ".",
                label=boundary.label,
            )
    for setter, key, values in ((ax.set_xscale, x, xs), (ax.set_yscale, y, ys)):
        if _log_axis(spec, key, values):
            setter("log")
    ax.set_xlabel(_label(x, dimensions[x]))
    ax.set_ylabel(_label(y, dimensions[y]))
    ax.set_title(f"{spec.label or spec.model}: {color} ({spec.model} model, {len(frame)} points)", fontsize=10)
    ax.legend(loc="best", fontsize=8, framealpha=0.85)
    return ax


def _scaled(values: np.ndarray, dimension: str) -> np.ndarray:
    return np.asarray(values, dtype=float) * DISPLAY.get(dimension, (1.0, ""))[0]


def _label(key: str, dimension: str) -> str:
    """The quantity's name and its display unit: ``block stiffness Gd/h (kPa/m)``, not the raw key."""
    unit = DISPLAY.get(dimension, (1.0, DIMENSIONS[dimension][1]))[1]
    name = KEY_NAMES.get(key) or _parameter_name(key) or key.replace("_", " ")
    return f"{name} ({unit})" if unit else name


def _parameter_name(key: str) -> str | None:
    """``bonds.bond_time`` -> ``thermal make-break time constant τ`` (the parameter's own description)."""
    from dataclasses import fields

    from ..parameters import SECTIONS

    section, _, name = key.partition(".")
    found = next((f for f in fields(SECTIONS[section]) if f.name == name), None) if section in SECTIONS else None
    if found is None:
        return None
    return f"{found.metadata['doc']} {SYMBOLS.get(found.metadata['symbol'], found.metadata['symbol'])}"


#: Parameter symbols as printed (the metadata spells them in ASCII).
SYMBOLS = {"tau": "τ", "tau_a": "τa", "lambda": "λ", "dl_m": "Δlm", "V_a": "Va", "G_d": "Gd"}


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
    return np.exp(edges) if log else edges


def _cells(
    xs: np.ndarray, ys: np.ndarray, values: np.ndarray, logs: tuple[bool, bool]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    ux, uy = np.unique(xs), np.unique(ys)
    grid = np.full((uy.size, ux.size), np.nan)
    grid[np.searchsorted(uy, ys), np.searchsorted(ux, xs)] = values
    return _edges(xs, logs[0]), _edges(ys, logs[1]), grid


def _draw_categories(
    ax: Axes, xs: np.ndarray, ys: np.ndarray, labels: np.ndarray, cells: bool, logs: tuple[bool, bool]
) -> None:
    from matplotlib.colors import ListedColormap

    names = [n for n in REGIME_COLORS if n in set(labels)] + sorted(set(labels) - set(REGIME_COLORS))
    spare = iter(["#8e44ad", "#16a085", "#d35400", "#2c3e50", "#27ae60"] * 4)
    colors = [REGIME_COLORS.get(n) or next(spare) for n in names]
    codes = np.array([names.index(label) for label in labels], dtype=float)
    if cells:
        ex, ey, grid = _cells(xs, ys, codes, logs)
        ax.pcolormesh(ex, ey, np.ma.masked_invalid(grid), cmap=ListedColormap(colors), vmin=-0.5, vmax=len(names) - 0.5)
        for n, c in zip(names, colors, strict=True):  # legend entries for the cells
            ax.scatter([], [], marker="s", color=c, label=n)
        return
    for name, c in zip(names, colors, strict=True):
        mask = labels == name
        ax.scatter(xs[mask], ys[mask], s=14, color=c, label=name, edgecolors="none")


def _draw_numbers(
    ax: Axes, xs: np.ndarray, ys: np.ndarray, values: np.ndarray, name: str, cells: bool, logs: tuple[bool, bool]
) -> None:
    from matplotlib.colors import LogNorm, Normalize

    finite = values[np.isfinite(values)]
    norm: Any = LogNorm() if _spans_decades(finite) else Normalize()
    if cells:
        ex, ey, grid = _cells(xs, ys, values, logs)
        mappable = ax.pcolormesh(ex, ey, np.ma.masked_invalid(grid), cmap="viridis", norm=norm)
    else:
        mappable = ax.scatter(xs, ys, c=values, s=14, cmap="viridis", norm=norm, plotnonfinite=False)
    unit = RESULT_UNITS.get(name, "")
    ax.figure.colorbar(mappable, ax=ax, label=f"{name} ({unit}); blank: none" if unit else f"{name}; blank: none")
