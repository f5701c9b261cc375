"""Figures of rate-and-state runs and fits (matplotlib Figure API, never pyplot)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from .style import apply_style, new_axes

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..rsf.fit import RSFFit
    from ..rsf.results import RSFRun


def plot_run(run: RSFRun, ax: Axes | None = None, x: str = "time", **kwargs: Any) -> Axes:
    """Friction against time (or ``x="displacement"``: load-point displacement in um)."""
    ax = new_axes(ax)
    xs = run.time if x == "time" else run.load_point_displacement * 1e6
    kwargs.setdefault("color", "#1f4e9c")
    kwargs.setdefault("lw", 1.2)
    ax.plot(xs, run.friction, **kwargs)
    ax.set_xlabel("time (s)" if x == "time" else "load-point displacement (µm)")
    ax.set_ylabel("friction μ")
    if run.status != "ok":
        ax.set_title(run.status, color="#c0392b", fontsize=9)
    return apply_style(ax)


def phase_plot(run: RSFRun, ax: Axes | None = None, **kwargs: Any) -> Axes:
    """ln(V/V0) against friction with the steady-state line (slope a - b) and constant-state lines (slope a)."""
    ax = new_axes(ax)
    p = run.params
    lnv = np.log(run.slider_velocity / p.v_ref)
    kwargs.setdefault("color", "k")
    kwargs.setdefault("lw", 1.5)
    ax.plot(lnv, run.friction, **kwargs)
    xlim = np.array(ax.get_xlim())
    ylim = ax.get_ylim()
    ax.plot(xlim, p.mu0 + (p.a - p.b) * xlim, color="#c0392b", ls="--", lw=1, label="steady state (slope a − b)")
    # constant-state lines: mu = mu_state + a ln(V/V0), through the start and through the end state
    levels = sorted({float(run.friction[0] - p.a * lnv[0]), float(run.friction[-1] - p.a * lnv[-1])})
    for i, level in enumerate(levels):
        label = "constant state (slope a)" if i == 0 else None
        ax.plot(xlim, level + p.a * xlim, color="#7f8c8d", ls=":", lw=1, label=label)
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_xlabel("ln(V/V₀)")
    ax.set_ylabel("friction μ")
    ax.legend(fontsize=8, frameon=False)
    return apply_style(ax)


def plot_record(record: Any, ax: Axes | None = None) -> Axes:
    """A measured friction record (:class:`~stickslip.rsf.data.LabRecord`) against load-point displacement."""
    ax = new_axes(ax)
    ax.plot(record.displacement * 1e6, record.friction, ".", ms=1.5, color="#777777")
    ax.set_xlabel("load-point displacement (µm)")
    ax.set_ylabel("friction μ")
    return apply_style(ax)


def plot_fit(fit: RSFFit, ax: Axes | None = None) -> Axes:
    """Data, fitted curve and residuals against load-point displacement."""
    ax = new_axes(ax)
    record, model = fit.record, fit.model_friction
    disp = record.displacement * 1e6
    ax.plot(disp, record.friction, ".", ms=1.5, color="#999999", label="data")
    ax.plot(disp, model, color="#c0392b", lw=1.4, label="fit")
    ax.set_xlabel("load-point displacement (µm)")
    ax.set_ylabel("friction μ")
    ax.legend(fontsize=8, frameon=False)
    return apply_style(ax)


def stability_figure(params: Any, v_low: float, v_high: float) -> Figure:
    """Critical stiffness against sliding velocity, with the spring's stiffness as a line."""
    from matplotlib.figure import Figure

    from ..rsf.stability import critical_stiffness

    fig = Figure(figsize=(6.4, 4.4), layout="constrained")
    ax = fig.add_subplot()
    speeds = np.geomspace(v_low, v_high, 80)
    kc = np.array([critical_stiffness(params, v) for v in speeds])
    ax.loglog(speeds * 1e6, np.where(kc > 0, kc, np.nan), color="#1f4e9c", label="k_c (unstable below)")
    ax.axhline(params.stiffness, color="#c0392b", ls="--", lw=1, label="spring k")
    ax.set_xlabel("sliding velocity V (µm/s)")
    ax.set_ylabel("stiffness (friction per m)")
    ax.legend(fontsize=8, frameon=False)
    apply_style(ax)
    return fig


def fit_figure(fit: RSFFit) -> Figure:
    """Data with the fit (top), residuals, and the load-point history fitted (found or given), against
    load-point displacement; a failed fit says so in red in the title."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 7.5), layout="constrained")
    ax1, ax2, ax3 = fig.subplots(3, 1, sharex=True, height_ratios=[3, 1, 1])
    plot_fit(fit, ax=ax1)
    disp = fit.record.displacement * 1e6
    ax2.plot(disp, fit.residuals, ".", ms=1.2, color="#777777")
    ax2.axhline(0, color="#c0392b", lw=1)
    ax2.set_ylabel("residual")
    apply_style(ax2)
    speed = fit.protocol.velocity_at(fit.record.time) * 1e6
    ax3.plot(disp, speed, color="#1f4e9c", lw=1.2, drawstyle="steps-post")
    changes = np.interp(fit.protocol.boundaries[1:-1], fit.record.time, disp)
    for x in changes:
        for ax in (ax1, ax3):
            ax.axvline(x, color="#bbbbbb", lw=0.8, ls=":")
    if np.all(speed > 0):
        ax3.set_yscale("log")
    ax3.set_xlabel("load-point displacement (µm)")
    ax3.set_ylabel(f"load point (µm/s),\n{fit.protocol_source.split(' from')[0]}", fontsize=8)
    apply_style(ax3)
    p = fit.parameters
    title = (f"a = {p['a'].value:.4g}, b = {p['b'].value:.4g}, Dc = {p['dc'].value * 1e6:.4g} µm, "
             f"χ²ᵣ = {fit.reduced_chi_square:.3g}")  # fmt: skip
    if fit.status != "ok":
        import textwrap

        lines = textwrap.wrap(f"FIT FAILED: {fit.reason}", 130, max_lines=4, placeholder=" …")
        ax1.set_title("\n".join([*lines, title]), fontsize=7, color="#c0392b")
    else:
        ax1.set_title(title, fontsize=9)
    return fig
