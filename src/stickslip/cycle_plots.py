"""Old home of the stick-slip cycle figures, kept for code that imports them from here.

The drawing now lives in :mod:`stickslip.plots.cycles`.
"""

from .plots.cycles import (
    figure_chain_fraction,
    figure_cycle_path,
    figure_cycles,
    figure_slip_velocity,
    legend_of_all_panels,
    plot_simulation,
    plot_slip,
    plot_stick,
)

__all__ = [
    "figure_chain_fraction",
    "figure_cycle_path",
    "figure_cycles",
    "figure_slip_velocity",
    "legend_of_all_panels",
    "plot_simulation",
    "plot_slip",
    "plot_stick",
]
