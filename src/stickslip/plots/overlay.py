"""Several models' runs of one protocol on one figure (``stickslip compare --models A,B``)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..models.run import Run


def overlay_figure(runs: Mapping[str, Run], title: str = "") -> Figure:
    """Stress (Pa, left axis) or friction coefficient (right axis) of every run against time, and the slider
    velocities (lower panel, log scale where all are positive, in the unit of :func:`velocity_unit`); each line
    labelled with its model and regime."""
    import numpy as np
    from matplotlib.figure import Figure

    from .style import apply_style, resolved_limits

    scale, unit = velocity_unit(*(r.slider_velocity for r in runs.values()))
    fig = Figure(figsize=(9, 6), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(2, 1))
    right = None
    for k, (name, run) in enumerate(runs.items()):
        color = f"C{k}"
        label = f"{name}: {run.regime_name}"
        if run.stress is not None:
            top.plot(run.time, run.stress, color=color, lw=1.2, label=label)
        else:
            right = top.twinx() if right is None else right
            right.plot(run.time, run.friction, color=color, lw=1.2, ls="--", label=label)
        bottom.plot(run.time, np.asarray(run.slider_velocity) * scale, color=color, lw=0.9)
    top.set_ylabel("friction stress σ (Pa)")
    if right is not None:
        right.set_ylabel("friction coefficient μ (dashed)")
    handles = [h for ax in (top, right) if ax is not None for h in ax.get_legend_handles_labels()[0]]
    labels = [lab for ax in (top, right) if ax is not None for lab in ax.get_legend_handles_labels()[1]]
    top.legend(handles, labels, fontsize=8, frameon=False, loc="best")
    speeds = np.concatenate([np.asarray(r.slider_velocity, float) for r in runs.values()])
    if speeds.size and np.all(speeds[np.isfinite(speeds)] > 0):
        bottom.set_yscale("log")
    else:
        resolved_limits(bottom, *(np.asarray(r.slider_velocity, float) * scale for r in runs.values()))
    stresses = [r.stress for r in runs.values() if r.stress is not None]
    if stresses:
        resolved_limits(top, *stresses)
    if right is not None:
        resolved_limits(right, *(r.friction for r in runs.values() if r.stress is None))
    bottom.set_ylabel(f"slider velocity ({unit})")
    bottom.set_xlabel("time (s)")
    for ax in (top, bottom):
        apply_style(ax)
    if title:
        top.set_title(title, fontsize=9)
    return fig


#: The units the velocity panel is drawn in, largest first: (SI factor, name).
VELOCITY_UNITS = ((1.0, "m/s"), (1e3, "mm/s"), (1e6, "µm/s"), (1e9, "nm/s"))


def velocity_unit(*series: object) -> tuple[float, str]:
    """(factor from m/s, unit name): the largest unit in which the fastest |V| of ``series`` is at least 1, so the
    axis reads 1.7 m/s, not 1.7 with a "1e6" multiplier over "µm/s" (round 28: a 1.7 m/s slip in µm/s); µm/s for
    none or all zero."""
    import numpy as np

    values = [np.abs(np.asarray(s, dtype=float)).ravel() for s in series]
    finite = np.concatenate(values) if values else np.array([])
    finite = finite[np.isfinite(finite)]
    fastest = float(finite.max()) if finite.size else 0.0
    if fastest == 0.0:
        return 1e6, "µm/s"
    return next(((f, u) for f, u in VELOCITY_UNITS if fastest * f >= 1.0), VELOCITY_UNITS[-1])
