"""Figures of time-dependent runs (built on matplotlib Figure objects; never pyplot)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..plotting import apply_style, new_axes

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

    from .result import TransientResult


def plot_transient(result: TransientResult, ax: Axes | None = None, velocity: bool = True, **kwargs: Any) -> Axes:
    """σ(t) on ``ax``, and the slider velocity on a twin axis (log scale); returns the stress Axes."""
    ax = new_axes(ax)
    ax.plot(result.time, result.stress, color=kwargs.pop("color", "C0"), label="σ (Pa)", **kwargs)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("stress σ (Pa)")
    if velocity:
        twin = ax.twinx()
        v = result.slider_velocity * 1e6
        positive = v > 0
        twin.plot(result.time[positive], v[positive], color="C3", lw=0.8, alpha=0.7)
        twin.set_yscale("log")
        twin.set_ylabel("slider velocity (µm/s)", color="C3")
    ax.set_title(f"{result.control} control: {result.regime}", fontsize="small")
    return apply_style(ax)
