"""Legends that name what a reader sees: one entry per visible line, in the panel that shows it.

* :func:`legend_per_panel`: each panel's legend names what that panel draws and no earlier legend named (so
  Fig 5c's "steady" is named in panel c, not in panel a where nothing is steady);
* :func:`coinciding_groups`: which curves lie on top of one another at the axis' resolution, so that a figure
  draws them as one line with one legend entry instead of naming lines nobody can see.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Curves closer than this fraction of the axis' height at every point are one line to the eye (2 px of 200).
COINCIDE = 0.01


def legend_per_panel(fig: Figure, axes: Sequence[Axes] | None = None, **kwargs: Any) -> None:
    """A legend on each panel naming the lines it draws that no earlier panel's legend named; none where all are.

    ``axes``: the panels, top to bottom (default: all of ``fig``'s); ``kwargs`` go to each legend.
    """
    named: set[str] = set()
    for ax in list(fig.axes if axes is None else axes):
        handles, labels = [], []
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            if label not in named and label not in labels:
                handles.append(handle)
                labels.append(label)
        if handles:
            options = {"loc": "upper right", "frameon": False, "fontsize": 8, "ncols": 4, **kwargs}
            ax.legend(handles, labels, **options)
            named.update(labels)
        elif ax.get_legend() is not None:  # drawn again after a relabelling: an old legend would name too much
            ax.get_legend().remove()


def coinciding_groups(ax: Axes, curves: Sequence[Any], tolerance: float = COINCIDE) -> list[list[int]]:
    """The indices of ``curves`` (y arrays on a common x) grouped where they coincide as ``ax`` shows them.

    Distances are measured in the axis' own scale (log, symlog), against the span all the curves cover: two
    curves are one group when they differ by less than ``tolerance`` of it at every point.  Set the y scale
    before calling.  Groups keep the order of their first curve.
    """
    transform = ax.yaxis.get_transform()
    shown = [np.asarray(transform.transform(np.asarray(y, dtype=float)), dtype=float) for y in curves]
    finite = np.concatenate([y[np.isfinite(y)] for y in shown]) if shown else np.array([])
    span = float(finite.max() - finite.min()) if finite.size else 0.0
    groups: list[list[int]] = []
    for k, y in enumerate(shown):
        home = next((g for g in groups if _close(shown[g[0]], y, tolerance * span)), None)
        if home is None:
            groups.append([k])
        else:
            home.append(k)
    return groups


def _close(a: np.ndarray, b: np.ndarray, distance: float) -> bool:
    if a.shape != b.shape:
        return False
    both = np.isfinite(a) & np.isfinite(b)
    return bool(np.array_equal(np.isfinite(a), np.isfinite(b)) and np.all(np.abs(a[both] - b[both]) <= distance))
