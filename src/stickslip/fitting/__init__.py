"""Fitting the model to measurements: steady friction curves and stick phases (paper, Section 3).

>>> from stickslip.fitting import datasets, fit_steady, fit_stick
>>> fit = fit_steady(datasets.synthetic_steady_path())          # doctest: +SKIP
>>> fit.critical_velocity.value, fit.critical_velocity.interval  # doctest: +SKIP

See docs/fitting.md for what the data can determine and how the intervals are made.
"""

from __future__ import annotations

from .bayes import SteadyPosterior, sample_posterior
from .data import SteadyData, StickData, read_steady_data, read_stick_data
from .results import Estimate
from .steady_fit import SteadyFit, fit_steady
from .stick_fit import StickFit, fit_stick

__all__ = [
    "Estimate",
    "SteadyData",
    "SteadyFit",
    "SteadyPosterior",
    "StickData",
    "StickFit",
    "fit_steady",
    "fit_stick",
    "read_steady_data",
    "read_stick_data",
    "sample_posterior",
]
