"""The figure of a :class:`stickslip.models.Run`: stress (or friction) against time, slider velocity on a twin axis."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

    from ..models.run import Run


def plot_run(run: Run, ax: Axes | None = None, *, velocity: bool = True) -> Axes:
    """Draw ``run`` on ``ax`` (a new figure's Axes by default) and return it; the title names the regime."""
    from .style import UM_PER_S, apply_style, new_axes

    ax = new_axes(ax, figsize=(7, 4))
    if run.stress is not None:
        ax.plot(run.time, run.stress, color="C0", lw=1.2, label="stress")
        ax.set_ylabel("friction stress (Pa)")
    else:
        ax.plot(run.time, run.friction, color="C0", lw=1.2, label="friction")
        ax.set_ylabel("friction coefficient")
    ax.set_xlabel("time (s)")
    if velocity:
        twin = ax.twinx()
        twin.plot(run.time, run.slider_velocity * UM_PER_S, color="C1", lw=0.8, alpha=0.7)
        twin.set_ylabel("slider velocity (µm/s)", color="C1")
    ax.set_title(f"{run.model}: {run.regime_name}")
    return apply_style(ax)
