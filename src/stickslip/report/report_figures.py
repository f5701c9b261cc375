"""The report's figures, in the paper's order, each built from a :class:`ModelRun`.

The drawing itself is the package's (:mod:`stickslip.plots.steady`,
:mod:`stickslip.plots.cycles`); this module chooses what the paper shows and
adds the paper's own numbers where they can be set beside the model.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from .computations import ModelRun
from .figures import ReportFigure
from .formatting import format_quantity
from .paper import DATA_RANGE

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

UM = 1e6
PAPER_COLOR = "#e67e22"
#: Figure 6's simulated stick times: (V0 in µm/s, ts in s).
PAPER_STICK_TIMES = ((50, 18.3), (100, 9.3))


def steady_figure(run: ModelRun) -> ReportFigure:
    from ..plots.steady import figure_steady_curve

    fig = figure_steady_curve(run.params, vmin=10e-6, vmax=10e-3, title="Steady friction curve (Figs 1 and 4)")
    ax = fig.axes[0]
    lo, hi = DATA_RANGE
    ax.axvspan(lo * UM, hi * UM, color="#8aa6d6", alpha=0.15, zorder=0, label="range of the steady data (Fig 4)")
    # an open diamond, drawn under the computed critical point, so that both stay visible (they nearly coincide)
    ax.plot(
        [125.0], [259.0], "D", markerfacecolor="none", markeredgecolor=PAPER_COLOR, markeredgewidth=1.6,
        markersize=11, zorder=4, label="paper: Vc = 125 µm/s, σc = 259 Pa",
    )  # fmt: skip
    ax.plot([350.0], [400.0], "s", color=PAPER_COLOR, markersize=6, zorder=8, label="measured: 0.4 kPa at 350 µm/s")
    ax.legend(loc="lower right", frameon=False, fontsize=8)
    c = run.critical
    assert c is not None and c.velocity is not None and c.stress is not None
    caption = (
        "Friction stress against sliding velocity at steady sliding (Eqs 6-8), with the aging term of Eq 6 "
        "(solid) and without it (dotted). The aging curve has its minimum at the critical point "
        f"Vc = {c.velocity * UM:.1f} µm/s, σc = {c.stress:.1f} Pa (Eq 9; the paper's 125 µm/s, 259 Pa are the "
        "open orange diamond around the computed point); left of it the friction is velocity weakening and "
        "steady sliding is unstable, and "
        "the curve rises steeply as the paper notes. Without aging there is no minimum, only the turnover "
        f"at {c.turnover_velocity * UM / 1e3:.2f} mm/s. The shaded band is the velocity range of the "
        "steady-sliding data of Baumberger et al. (140-2000 µm/s) that the parameters were fitted to; below "
        "it the curve is the paper's extrapolation. The orange square is the steady stress read off the "
        "350 µm/s trace (Section 3)."
    )
    return ReportFigure("fig1-4_steady_curve", "Figs 1 and 4", "Steady friction curve", caption, fig)


def cycle_path_figure(run: ModelRun) -> ReportFigure:
    from ..plots.cycles import figure_cycle_path

    sim = run.simulations[50]
    fig = figure_cycle_path(run.params, sim, title="Stick-slip cycle on the σ-V diagram (Fig 2), V0 = 50 µm/s")
    cycle = sim.cycles[0]
    caption = (
        "One cycle at V0 = 50 µm/s drawn over the steady curves. Stick (path 3 of the paper): the block is at "
        f"rest and the stress rises from σc = {cycle.start_stress:.1f} Pa to σs = {cycle.peak_stress:.1f} Pa. "
        f"Jump (path 4): the chains let go and the block jumps to Vs = {cycle.jump_velocity * UM:.0f} µm/s, "
        "where the steady curve with aging carries σs. Slip (path 1): the block slides down the right branch "
        "of the aging curve (Eq 10) to the critical point, where dσ/dV = 0 and it jumps back to rest "
        "(path 2), sticking again at σc."
    )
    return ReportFigure("fig2_cycle_path", "Fig 2", "A stick-slip cycle on the stress-velocity diagram", caption, fig)


def chain_fraction_figure(run: ModelRun) -> ReportFigure:
    from ..plots.cycles import figure_chain_fraction

    sims = [run.simulations[50], run.simulations[100]]
    fig = figure_chain_fraction(sims, labels=["V0 = 50 µm/s", "V0 = 100 µm/s"], title="Attached chains (Figs 3 and 6)")
    ax = fig.axes[0]
    # each paper triangle in the colour of the model curve it belongs to (the model's own ts is the dot)
    curves = [line for line in ax.get_lines() if not line.get_label().startswith("_")]
    for line, (velocity, paper_ts) in zip(curves, PAPER_STICK_TIMES, strict=True):
        ax.plot(
            [paper_ts], [0.0], "v", color=line.get_color(), markeredgecolor="black", markeredgewidth=0.6,
            markersize=9, zorder=8, label=f"paper, V0 = {velocity} µm/s: ts = {paper_ts} s",
        )  # fmt: skip
    ax.legend(loc="lower left", frameon=False, fontsize=8)
    ts50, ts100 = (s.cycles[0].stick_time for s in sims)
    stick = run.params.stick
    caption = (
        "Fraction of the attached chains Nc/Nc0 during the stick phase (Eq 15, "
        f"Nc0 = {format_quantity(stick.attached_chains, '1/m^2', 3)}, "
        f"uc/τ = {format_quantity(stick.break_rate, '1/s', 2)}, "
        f"τa = {stick.aging_time:g} s), starting at σc. As in the paper, it falls slowly while the load is "
        "shared by many chains, then collapses: each chain that lets go loads the others more (Eq 14). "
        f"The collapse gives the stick time ts = {ts50:.2f} s at 50 µm/s and {ts100:.2f} s at 100 µm/s; the "
        "paper's simulation gives 18.3 s and 9.3 s (triangles in the colour of each curve; see the table and "
        "errata E18, E5)."
    )
    return ReportFigure("fig3-6_chain_fraction", "Figs 3 and 6", "Attached chains in the stick phase", caption, fig)


def cycles_figure(run: ModelRun) -> ReportFigure:
    from ..plots.cycles import figure_cycles

    sims = [run.simulations[v] for v in (50, 100, 350)]
    fig = figure_cycles(sims, title="Stick-slip cycles (Fig 5a-c)")
    _label_critical_stress_and_clear_peaks(fig, sims[0].critical_stress)
    s50, s100, s350 = sims
    first = s350.cycles[0]
    caption = (
        "Friction stress against time at V0 = 50, 100 and 350 µm/s (Eqs 10-17). At 50 and 100 µm/s the run starts "
        "with a stick at σc (dashed line); stick phases rise linearly (Eq 12) and end at σs (Eq 16); slip phases "
        f"follow the steady curve down to σc. At 50 µm/s the period is {s50.cycles[0].period:.1f} s "
        f"(stick {s50.cycles[0].stick_time:.1f} s); at 100 µm/s {s100.cycles[0].period:.1f} s "
        f"(stick {s100.cycles[0].stick_time:.2f} s). At 350 µm/s, above Vc, the run starts from rest as the "
        f"experiment did (Table 1 gives no σc there): one start-up stick of {first.stick_time:.2f} s to "
        f"σs = {first.peak_stress:.1f} Pa, a jump to {first.jump_velocity * UM:.0f} µm/s, and a slip "
        f"that settles at the steady stress {s350.final_stress:.1f} Pa (the paper's 0.4 kPa). The measured "
        "traces of Baumberger et al. that the paper plots as points are not distributed with the package; "
        "their characteristics (Table 1) are compared with the model in the table below."
    )
    return ReportFigure("fig5a-c_cycles", "Fig 5a-c", "Stress during stick-slip at 50, 100 and 350 µm/s", caption, fig)


def _label_critical_stress_and_clear_peaks(fig: Figure, critical_stress: float) -> None:
    """Name the dashed σc line in the legend, and leave room above the peaks so the legends cover no data."""
    from ..plots.legends import legend_per_panel

    for index, ax in enumerate(fig.axes):
        for line in ax.get_lines():
            if line.get_linestyle() == "--":
                line.set_label(f"σc = {critical_stress:.1f} Pa" if index == 0 else "_σc")
        low, high = ax.get_ylim()
        ax.set_ylim(low, high + 0.25 * (high - low))
    legend_per_panel(fig)


def slip_velocity_figure(run: ModelRun) -> ReportFigure:
    from ..plots.cycles import figure_slip_velocity

    s50, s100, s350 = (run.simulations[v] for v in (50, 100, 350))
    first_100 = run.table1_first_slip_100
    assert first_100 is not None
    slips = [s50, first_100, s100, s350]
    labels = [
        f"5a, 50 µm/s: Vs = {s50.cycles[0].jump_velocity * UM:.0f} µm/s",
        f"5b cycle 1, 100 µm/s: Vs = {first_100.start_velocity * UM:.0f} µm/s (Table 1 σs = 658 Pa)",
        f"5b, 100 µm/s: Vs = {s100.cycles[0].jump_velocity * UM:.0f} µm/s",
        f"5c, 350 µm/s: Vs = {s350.cycles[0].jump_velocity * UM:.0f} µm/s",
    ]
    fig = figure_slip_velocity(slips, labels=labels, title="Sliding velocity in the slip phase (Fig 5d)")
    caption = (
        "Sliding velocity after the jump (Eq 10), for the slip phases the paper shows: the first cycle of "
        "Fig 5a, the first and a later cycle of Fig 5b (the first starts from Table 1's higher σs = 658 Pa, "
        "which the paper puts down to extra aging before the first stick), and Fig 5c. With V0 below Vc the "
        f"velocity falls to Vc = {s50.critical_velocity * UM:.1f} µm/s in finite time and the block sticks "
        "(the paper: 125 µm/s); at 350 µm/s it settles at V0 (the paper: 350 µm/s)."
    )
    return ReportFigure("fig5d_slip_velocity", "Fig 5d", "Sliding velocity in the slip phase", caption, fig)


FIGURE_BUILDERS: list[tuple[str, Callable[[ModelRun], ReportFigure]]] = [
    ("Figs 1 and 4: steady friction curve", steady_figure),
    ("Fig 2: cycle path on the σ-V diagram", cycle_path_figure),
    ("Figs 3 and 6: attached chains", chain_fraction_figure),
    ("Fig 5a-c: stick-slip cycles", cycles_figure),
    ("Fig 5d: sliding velocity in slip", slip_velocity_figure),
]
