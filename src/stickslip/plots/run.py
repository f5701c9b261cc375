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
        ax.set_ylabel("friction stress σ (Pa)")
    else:
        ax.plot(run.time, run.friction, color="C0", lw=1.2, label="friction")
        ax.set_ylabel("friction coefficient")
    ax.set_xlabel("time (s)")
    if velocity:
        twin = ax.twinx()
        twin.plot(run.time, run.slider_velocity * UM_PER_S, color="C1", lw=0.8, alpha=0.7)
        twin.set_ylabel("slider velocity (µm/s)", color="C1")
    ax.set_title(f"{run.model}{_pulling(run)}: {run.regime_name}")
    return apply_style(ax)


def _pulling(run: Run) -> str:
    """`` at V0 = 50 µm/s`` when the load point moves at one speed (its travel a straight line in time to 1e-6 of
    the travel); '' when it does not."""
    import numpy as np

    from ..display import velocity

    x, t = np.asarray(run.load_point_position, float), np.asarray(run.time, float)
    if x.size < 2 or not t[-1] > t[0] or not np.all(np.isfinite(x)):
        return ""
    v0 = (x[-1] - x[0]) / (t[-1] - t[0])
    straight = np.max(np.abs(x - x[0] - v0 * (t - t[0]))) <= 1e-6 * max(abs(x[-1] - x[0]), 1e-300)
    return f" at V0 = {velocity(v0, 4)}" if straight else ""
