"""Figures of the fits (matplotlib, no pyplot: safe in any backend; never shows anything)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

import numpy as np

from .style import UM_PER_S, VELOCITY_LABEL

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..fitting.bayes import SteadyPosterior
    from ..fitting.data import SteadyData
    from ..fitting.steady_fit import SteadyFit
    from ..fitting.stick_fit import StickFit


def panels(rows: int = 1, height: float = 4.0) -> tuple[Figure, list[Axes]]:
    """A new Figure of ``rows`` panels stacked on one shared x axis (the first three times as tall)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, height * rows), constrained_layout=True)
    if rows == 1:
        return fig, [fig.add_subplot(1, 1, 1)]
    axes = fig.subplots(rows, 1, sharex=True, gridspec_kw={"height_ratios": [3] + [1] * (rows - 1)})
    return fig, list(axes)


def _axes(ax: Axes | None) -> Axes:
    return panels()[1][0] if ax is None else ax


def plot_steady_data(data: SteadyData, ax: Axes | None = None, **kwargs: Any) -> Axes:
    ax = _axes(ax)
    style = {"fmt": "o", "color": "k", "ms": 4, "capsize": 2, "label": "data"} | kwargs
    err = None if data.stress_err is None else data.stress_err
    ax.errorbar(data.velocity * UM_PER_S, data.stress, yerr=err, **style)
    ax.set_xscale("log")
    ax.set_xlabel(VELOCITY_LABEL)
    ax.set_ylabel("friction stress σ (Pa)")
    return ax


def _curve_range(fit: SteadyFit) -> np.ndarray:
    lo = float(fit.data.velocity.min()) / 2.0
    if fit.critical_velocity.value is not None:
        lo = min(lo, fit.critical_velocity.value / 2.0)
    return np.geomspace(lo, float(fit.data.velocity.max()) * 1.3, 120)


def plot_steady_fit(fit: SteadyFit, ax: Axes | None = None, band: tuple[np.ndarray, ...] | None = None) -> Axes:
    """Data, fitted curve (with aging; without aging dashed) and Vc with its interval."""
    ax = plot_steady_data(fit.data, _axes(ax))
    v = _curve_range(fit)
    ax.plot(v * UM_PER_S, fit.curve(v), color="C0", label=f"fit ({fit.method})")
    ax.plot(v * UM_PER_S, fit.curve(v, aging=False), color="C0", ls="--", lw=1, label="fit without aging")
    if band is not None:
        bv, lo, hi = band
        ax.fill_between(bv * UM_PER_S, lo, hi, color="C0", alpha=0.25, lw=0, label="95 % credible band")
    vc, sc = fit.critical_velocity, fit.critical_stress
    if vc.value is not None and sc.value is not None:
        xerr = None
        if vc.interval is not None and None not in vc.interval:
            xerr = [[(vc.value - vc.interval[0]) * UM_PER_S], [(vc.interval[1] - vc.value) * UM_PER_S]]  # type: ignore[operator]
        yerr = None
        if sc.interval is not None and None not in sc.interval:
            yerr = [[sc.value - sc.interval[0]], [sc.interval[1] - sc.value]]  # type: ignore[operator]
        ax.errorbar(
            [vc.value * UM_PER_S], [sc.value], xerr=xerr, yerr=yerr, fmt="s", color="C3", capsize=3, label="Vc, σc"
        )
    if fit.split is not None:
        ax.axvline(fit.split * UM_PER_S, color="0.6", ls=":", lw=1, label="split (two-step)")
    top = float(np.max(fit.data.stress)) * 1.4
    ax.set_ylim(0, top)
    ax.legend(fontsize="small")
    return ax


def plot_residuals(fit: SteadyFit, ax: Axes | None = None) -> Axes:
    ax = _axes(ax)
    ax.axhline(0.0, color="0.5", lw=1)
    ax.plot(fit.data.velocity * UM_PER_S, fit.residuals, "o", color="k", ms=4)
    ax.set_xscale("log")
    ax.set_xlabel(VELOCITY_LABEL)
    ax.set_ylabel("(data − fit)/error")
    return ax


def steady_fit_figure(fit: SteadyFit, band: tuple[np.ndarray, ...] | None = None) -> Figure:
    """Two panels: the fit and its normalised residuals."""
    fig, (top, bottom) = panels(rows=2, height=2.4)
    plot_steady_fit(fit, top, band=band)
    top.set_xlabel("")
    plot_residuals(fit, bottom)
    return fig


def plot_stick_fit(fit: StickFit, ax: Axes | None = None) -> Axes:
    """Stick time against pulling velocity (linear axes): data with error bars of the estimated scatter,
    the model's value for each fitted row, and the fitted t_s(V0) as a line."""
    ax = _axes(ax)
    data, used = fit.data, fit.used
    v = data.pulling_velocity * UM_PER_S
    offsets = _spread(data.pulling_velocity, used)
    sd = fit.noise_scale if np.isfinite(fit.noise_scale) else 0.0
    err = data.stick_time[used] * sd if sd > 0 else None
    ax.errorbar(
        v[used] + offsets[used], data.stick_time[used], yerr=err, fmt="o", color="k", ms=5, capsize=3,
        label=f"data (bars: ±1 sd, {100 * sd:.2g} % from the scatter)" if sd > 0 else "data",
    )  # fmt: skip
    ax.plot(v[used] + offsets[used], fit.model_stick_time[used], "s", mfc="none", color="C0", ms=7, label="model, row")
    if np.any(~used):
        ax.plot(v[~used], data.stick_time[~used], "x", color="0.5", ms=7, label="left out")
    lo, hi = float(np.min(data.pulling_velocity[used])), float(np.max(data.pulling_velocity[used]))
    grid = np.linspace(0.6 * lo, 1.25 * hi, 120)
    curve, start, stiffness = fit.stick_time_curve(grid)
    ax.plot(
        grid * UM_PER_S, curve, color="C0",
        label=f"model t_s(V0): start {start:.4g} Pa, loading rate/V0 {stiffness / 1e3:.4g} kPa/m (row medians)",
    )  # fmt: skip
    ax.set_xlim(0.0, max(1.3 * hi, 1.1 * float(np.max(data.pulling_velocity))) * UM_PER_S)  # left-out rows too
    top = np.nanmax(np.concatenate([data.stick_time, fit.model_stick_time[used], curve[np.isfinite(curve)]]))
    ax.set_ylim(0.0, 1.15 * top)
    ax.set_xlabel("pulling velocity V0 (µm/s)")
    ax.set_ylabel("stick time ts (s)")
    ax.set_title("Stick-phase fit (Eq 15)", fontsize="medium")
    ax.legend(fontsize="small")
    return ax


def _spread(velocity: np.ndarray, used: np.ndarray) -> np.ndarray:
    """Small horizontal offsets (um/s) so that repeated cycles at one velocity do not hide each other."""
    out = np.zeros(velocity.size)
    width = 0.006 * float(np.max(velocity[used])) * UM_PER_S
    for v in np.unique(velocity[used]):
        same = np.nonzero(used & (velocity == v))[0]
        out[same] = (np.arange(same.size) - (same.size - 1) / 2) * width
    return out


def corner_figure(posterior: SteadyPosterior) -> Figure:
    """Corner plot of the posterior (the ``corner`` package) in units people use, with Vc and sigma_c;
    titles give the median and the central 95 % credible interval."""
    import corner
    from matplotlib.figure import Figure

    samples, labels = posterior.corner_samples()
    size = 1.9 * len(labels) + 1
    fig = Figure(figsize=(size, size))
    with _corner_log_captured():
        corner.corner(
            samples, labels=labels, fig=fig, quantiles=[0.025, 0.5, 0.975], show_titles=True, title_fmt=".3g",
            title_quantiles=[0.025, 0.5, 0.975], title_kwargs={"fontsize": 9}, label_kwargs={"fontsize": 10},
            max_n_ticks=3, plot_contours=samples.shape[0] >= 200,
        )  # fmt: skip
    fig.suptitle(f"posterior: {samples.shape[0]} samples; titles: median and central 95 % interval", fontsize=10)
    return fig


@contextmanager
def _corner_log_captured() -> Iterator[None]:
    """Keep corner's messages (it logs to the root logger) off the user's terminal; they are about contour drawing
    only."""
    import logging

    def outside_corner(record: logging.LogRecord) -> bool:
        return "corner" not in record.pathname

    root = logging.getLogger()
    root.addFilter(outside_corner)
    try:
        yield
    finally:
        root.removeFilter(outside_corner)
