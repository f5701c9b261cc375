"""Old home of the steady-curve figures and the common style, deprecated: it warns on import.

The drawing now lives in :mod:`stickslip.plots` (:mod:`~stickslip.plots.steady`, :mod:`~stickslip.plots.style`).
"""

import warnings

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

warnings.warn(
    "stickslip.plotting is deprecated; import from stickslip.plots.steady and stickslip.plots.style",
    DeprecationWarning,
    stacklevel=2,
)
