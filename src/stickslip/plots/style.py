"""The package's common look: Axes and Figure makers, display units, colours, axis labels.

Axes show velocities in um/s and stresses in Pa; the objects drawn hold SI values.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    from collections.abc import Sequence

    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Display scale of velocities: SI (m/s) times this gives um/s.
UM_PER_S = 1e6
VELOCITY_LABEL = "sliding velocity V (µm/s)"
STRESS_LABEL = "friction stress σ (Pa)"
AGING_COLOR = "#1f4e9c"
NO_AGING_COLOR = "#c0392b"
CRITICAL_COLOR = "#222222"
DATA_COLOR = "#333333"


def new_axes(ax: Axes | None = None, figsize: tuple[float, float] = (6.4, 4.4)) -> Axes:
    """``ax`` itself, or the single Axes of a new pyplot-free Figure."""
    if ax is not None:
        return ax
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    return fig.add_subplot()


def apply_style(ax: Axes) -> Axes:
    """The package's common look: light grid, no top/right spines, outward ticks."""
    ax.grid(True, which="major", alpha=0.35, linewidth=0.6)
    ax.grid(True, which="minor", alpha=0.12, linewidth=0.4)
    for side in ("top", "right"):
        ax.spines[side].set_visible(False)
    ax.tick_params(direction="out", which="both")
    return ax


def data_columns(data: Any, names: tuple[str, str], optional: str | None, expected: str) -> tuple[Any, Any, Any]:
    """Measured data's two columns ``names`` and its ``optional`` one (None when absent): a tuple of them in that
    order, a mapping or table with those items, or an object with those attributes (``expected`` names the first
    two ways in the one-line refusal of anything else)."""
    if isinstance(data, tuple) and len(data) in (2, 3 if optional else 2):
        return data[0], data[1], data[2] if len(data) == 3 else None
    try:
        first, second = data[names[0]], data[names[1]]
        return first, second, data[optional] if optional and _has_key(data, optional) else None
    except (TypeError, KeyError, IndexError):
        first, second = getattr(data, names[0], None), getattr(data, names[1], None)
        if first is None or second is None:
            raise TypeError(
                f"data: expected {expected}, or an object with those attributes; got {type(data).__name__}"
            ) from None
        return first, second, getattr(data, optional, None) if optional else None


def _has_key(data: Any, key: str) -> bool:
    try:
        return key in data
    except TypeError:
        return False


def legend_of_all_panels(fig: Figure, axes: Sequence[Axes] | None = None, **kwargs: Any) -> None:
    """One legend, on the first panel, naming every line of every panel once (a phase that only a later panel
    shows, such as the steady part of Fig 5c, included).  ``axes``: the panels (default: all of ``fig``'s)."""
    panels = list(fig.axes if axes is None else axes)
    handles: dict[str, Any] = {}
    for ax in panels:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            handles.setdefault(label, handle)
    if handles:
        options = {"loc": "upper right", "frameon": False, "fontsize": 8, "ncols": 4, **kwargs}
        panels[0].legend(list(handles.values()), list(handles), **options)


#: The smallest span an axis shows, relative to the size of its values: round-off (1e-13 of a steady run's
#: friction) must not be autoscaled into a spike; nothing in friction is resolved below a millionth.
RESOLUTION = 1e-6


def resolved_limits(ax: Axes, *series: Any, axis: str = "y", resolution: float = RESOLUTION) -> None:
    """Keep a linear axis at least ``resolution`` x |values| wide (centred on the data) and without the
    offset notation that writes round-off as ``1e-13+5.80439885e-1``."""
    import numpy as np

    values = np.concatenate([np.asarray(s, dtype=float).ravel() for s in series]) if series else np.array([])
    values = values[np.isfinite(values)]
    if values.size == 0:
        return
    lo, hi = float(values.min()), float(values.max())
    size = max(abs(lo), abs(hi))
    least = resolution * size if size > 0 else 1.0
    if hi - lo < least:
        middle = 0.5 * (lo + hi)
        (ax.set_ylim if axis == "y" else ax.set_xlim)(middle - least, middle + least)
    if (ax.get_yscale() if axis == "y" else ax.get_xscale()) == "linear":
        ax.ticklabel_format(axis=axis, useOffset=False)
