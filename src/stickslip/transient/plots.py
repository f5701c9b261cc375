"""Figures of time-dependent runs (built on matplotlib Figure objects; never pyplot)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..plotting import apply_style, new_axes

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

    from .result import TransientResult


def plot_transient(result: TransientResult, ax: Axes | None = None, velocity: bool = True, **kwargs: Any) -> Axes:
    """σ(t) on ``ax``, and the slider velocity on a twin axis; returns the stress Axes.

    The velocity axis is symmetric-log: logarithmic over the moving samples, linear near zero, so that a stick
    (the slider at rest, V = 0) is drawn at zero instead of being dropped and bridged by a line.
    """
    ax = new_axes(ax)
    ax.plot(result.time, result.stress, color=kwargs.pop("color", "C0"), label="σ (Pa)", **kwargs)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("stress σ (Pa)")
    if velocity:
        twin = ax.twinx()
        v = np.asarray(result.slider_velocity, float) * 1e6
        twin.plot(result.time, v, color="C3", lw=0.8, alpha=0.7, label="slider velocity (µm/s)")
        threshold = _linear_threshold(v)
        twin.set_yscale("symlog", linthresh=threshold)
        # a little room below zero so that the rest line is not hidden by the bottom spine
        twin.set_ylim(bottom=min(-0.3 * threshold, float(np.nanmin(v, initial=0.0))))
        twin.set_ylabel("slider velocity (µm/s; 0 = at rest)", color="C3")
    ax.set_title(f"{result.control} control: {result.regime}", fontsize="small")
    return apply_style(ax)


def _linear_threshold(v: np.ndarray) -> float:
    """The symlog axis' linear range: below the slowest moving sample (so all motion is on the log part)."""
    moving = np.abs(v[np.isfinite(v) & (v != 0)])
    if moving.size == 0:
        return 1.0
    return float(max(moving.min(), 1e-6 * moving.max()))
