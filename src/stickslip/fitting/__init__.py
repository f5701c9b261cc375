"""Fitting the model to measurements: steady friction curves and stick phases (paper, Section 3).

>>> from stickslip.fitting import fit_steady, read_steady_data, datasets
>>> fit = fit_steady(datasets.synthetic_steady_path())          # doctest: +SKIP
>>> fit.critical_velocity.value, fit.critical_velocity.interval  # doctest: +SKIP
"""

from __future__ import annotations

from .data import SteadyData, StickData, read_steady_data, read_stick_data
from .results import Estimate
from .steady_fit import SteadyFit, fit_steady

__all__ = [
    "Estimate",
    "SteadyData",
    "SteadyFit",
    "StickData",
    "fit_steady",
    "read_steady_data",
    "read_stick_data",
]
