"""Old home of the steady-curve figures and the common style, kept for code that imports it from here.

The drawing now lives in :mod:`stickslip.plots` (:mod:`~stickslip.plots.steady`, :mod:`~stickslip.plots.style`).
"""

from .plots.steady import figure_steady_curve, plot_steady, protocol_plot
from .plots.style import (
    AGING_COLOR,
    CRITICAL_COLOR,
    DATA_COLOR,
    NO_AGING_COLOR,
    STRESS_LABEL,
    UM_PER_S,
    VELOCITY_LABEL,
    apply_style,
    new_axes,
)

__all__ = [
    "AGING_COLOR",
    "CRITICAL_COLOR",
    "DATA_COLOR",
    "NO_AGING_COLOR",
    "STRESS_LABEL",
    "UM_PER_S",
    "VELOCITY_LABEL",
    "apply_style",
    "figure_steady_curve",
    "new_axes",
    "plot_steady",
    "protocol_plot",
]
