"""Figures of time-dependent runs of the bond model (built on matplotlib Figure objects; never pyplot)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from .style import STRESS_LABEL, apply_style, new_axes

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..quasistatic.cycle import Simulation
    from ..transient.result import TransientResult


def plot_transient(result: TransientResult, ax: Axes | None = None, velocity: bool = True, **kwargs: Any) -> Axes:
    """σ(t) on ``ax``, and the slider velocity on a twin axis; returns the stress Axes.

    The velocity axis is symmetric-log: logarithmic over the moving samples, linear near zero, so that a stick
    (the slider at rest, V = 0) is drawn at zero instead of being dropped and bridged by a line.
    """
    ax = new_axes(ax)
    ax.plot(result.time, result.stress, color=kwargs.pop("color", "C0"), label="σ (Pa)", **kwargs)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(STRESS_LABEL)
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
    """The symlog axis' linear range: a power of ten at or below the slowest moving sample (so all motion is on
    the log part, and 0 and the first decade's tick are a whole decade apart rather than printed over each
    other)."""
    moving = np.abs(v[np.isfinite(v) & (v != 0)])
    if moving.size == 0:
        return 1.0
    return float(10.0 ** np.floor(np.log10(max(moving.min(), 1e-6 * moving.max()))))


def figure_transient_runs(
    alone: TransientResult,
    full: TransientResult,
    quasi: Simulation,
    step_down: tuple[float, float, float],
    steps: TransientResult,
    step_starts: tuple[float, float],
    step_title: str,
    holds: Sequence[float],
    peaks: Sequence[float],
) -> Figure:
    """Three panels of the time-dependent model (the report's Eq 1 figure).

    Top: a step down ``step_down = (from, to, duration)`` (m/s, m/s, s) through the block, with Eq 1 ``alone``,
    with the stick chains (``full``) and the quasi-static cycle ``quasi`` shifted to the full run's first stick.
    Bottom left: stress against slip after each velocity step of ``steps`` (which start at ``step_starts``, s).
    Bottom right: the peak stress on re-sliding against the hold time.
    """
    from matplotlib.figure import Figure

    high, low, duration = step_down
    # the width of the report's other figures (readable on a phone-sized page): the cycle on top, two panels below
    fig = Figure(figsize=(6.8, 7.0))
    grid = fig.add_gridspec(2, 2)
    ax_cycle, ax_step, ax_hold = fig.add_subplot(grid[0, :]), fig.add_subplot(grid[1, 0]), fig.add_subplot(grid[1, 1])
    ax_cycle.plot(*_thin(alone.time, alone.stress), color="C2", lw=2.4, label="Eq 1 alone")
    ax_cycle.plot(*_thin(full.time, full.stress), color="C0", lw=1.2, label="Eq 1 + stick chains")
    if full.cycles:
        shift = full.cycles[0].start_time
        ax_cycle.plot(quasi.time + shift, quasi.stress, color="k", lw=0.8, ls="--", label="quasi-static, shifted")
    ax_cycle.set_xlim(0, duration)
    ax_cycle.set_xlabel("time (s)")
    ax_cycle.set_ylabel(STRESS_LABEL)
    ax_cycle.set_title(f"{high * 1e6:.0f} → {low * 1e6:.0f} µm/s through the block", fontsize=10)
    ax_cycle.legend(fontsize="small", loc="upper left")

    for start, label, color in ((step_starts[0], "step up", "C0"), (step_starts[1], "step down", "C1")):
        after = steps.time >= start
        slip = (steps.slider_position[after] - steps.slider_position[after][0]) * 1e6
        near = slip <= 2.0
        ax_step.plot(slip[near], steps.stress[after][near], color=color, lw=1.2, label=label)
    ax_step.set_xlabel("slip since the step (µm)")
    ax_step.set_ylabel(STRESS_LABEL)
    ax_step.set_title(step_title, fontsize=9)
    ax_step.legend(fontsize="small")

    ax_hold.loglog(holds, peaks, "o-", color="C3", label="peak on re-sliding")
    ax_hold.set_xlabel("hold time (s)")
    ax_hold.set_ylabel("peak friction stress (Pa)")
    ax_hold.set_title("slide-hold-slide at 100 µm/s", fontsize=9)
    for ax in (ax_cycle, ax_step, ax_hold):
        apply_style(ax)
    fig.set_layout_engine("tight")  # laid out when drawn, with the text sizes the drawing measures anyway
    return fig


def _thin(time: np.ndarray, values: np.ndarray, points: int = 4000) -> tuple[np.ndarray, np.ndarray]:
    """About ``points`` samples of a long trace for drawing, keeping every local extremum's neighbourhood."""
    if time.size <= points:
        return time, values
    grid = np.searchsorted(time, np.linspace(time[0], time[-1], points))
    turning = np.flatnonzero(np.diff(np.sign(np.diff(values))) != 0) + 1
    keep = np.unique(np.r_[0, np.minimum(grid, time.size - 1), turning, time.size - 1])
    return time[keep], values[keep]
