"""Figures of a trace analysis: the record, the fitted stick lines, peaks, troughs, and the model."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..analysis.compare import Comparison
    from ..analysis.cycles import TraceAnalysis


def plot_analysis(
    analysis: TraceAnalysis, ax: Axes | None = None, comparison: Comparison | None = None, **kwargs: Any
) -> Axes:
    """Stress against time with the detected phases; the model on top when ``comparison`` is given."""
    if ax is None:
        from matplotlib.figure import Figure

        ax = Figure(figsize=(9, 4.5)).add_subplot()
    valid = np.isfinite(analysis.stress)
    ax.plot(
        analysis.time[valid],
        analysis.stress[valid],
        color="0.55",
        lw=0.8,
        label="record",
        **kwargs,
    )
    if comparison is not None:
        ax.plot(comparison.model_time, comparison.model_stress, color="tab:purple", lw=1.0, ls="--", label="model")
    first = True
    for cycle in analysis.cycles:
        if cycle.line is None:
            continue
        span = np.array([cycle.stick_from, cycle.stick_to])
        ax.plot(span, cycle.line(span), color="tab:blue", lw=1.6, label="stick fits" if first else None)
        first = False
    starts = [(c.start_time, c.critical_stress) for c in analysis.cycles if c.start_time is not None]
    peaks = [(c.peak_time, c.peak_stress) for c in analysis.cycles if c.peak_time is not None]
    if starts:
        ax.plot(*zip(*starts, strict=True), "v", color="tab:green", ms=7, label=r"stick starts ($\sigma_c$)")
    if peaks:
        ax.plot(*zip(*peaks, strict=True), "^", color="tab:red", ms=7, label=r"slips ($\sigma_s$)")
    if analysis.steady_from is not None and "mean_stress" in analysis.summary:
        mean = analysis.summary["mean_stress"]
        ax.axvspan(analysis.steady_from, analysis.time[-1], color="tab:orange", alpha=0.12, label="steady sliding")
        ax.axhline(mean, color="tab:orange", lw=1.2, ls="--", label=f"mean {mean:.4g} Pa")
    v0 = analysis.pulling_velocity
    ax.set_title(f"{analysis.source}: {analysis.regime}, V0 = {v0 * 1e6:.4g} µm/s")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("stress [Pa]")
    ax.legend(loc="best", fontsize="small")
    return ax


def figure_analysis(analysis: TraceAnalysis, comparison: Comparison | None = None) -> Figure:
    """The figure of ``stickslip analyze --plot``: :func:`plot_analysis` of the record on a Figure of its own, with
    the model of ``comparison`` (:func:`stickslip.analysis.compare_with_model` of this analysis) on top when given."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 4.5))
    plot_analysis(analysis, ax=fig.add_subplot(), comparison=comparison)
    return fig
