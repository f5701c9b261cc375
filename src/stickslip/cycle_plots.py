"""Old home of the stick-slip cycle figures, deprecated: it warns on import.

The drawing now lives in :mod:`stickslip.plots.cycles`.
"""

import warnings

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

warnings.warn(
    "stickslip.cycle_plots is deprecated; import from stickslip.plots.cycles",
    DeprecationWarning,
    stacklevel=2,
)
