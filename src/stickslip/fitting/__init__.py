"""Fitting the model to measurements: steady friction curves and stick phases (paper, Section 3).

>>> from stickslip.fitting import datasets, fit_steady, fit_stick
>>> fit = fit_steady(datasets.synthetic_steady_path())          # doctest: +SKIP
>>> fit.critical_velocity.value, fit.critical_velocity.interval  # doctest: +SKIP

See docs/fitting.md for what the data can determine and how the intervals are made.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    from .bayes import SteadyPosterior, sample_posterior
    from .data import SteadyData, StickData, read_steady_data, read_stick_data
    from .results import Estimate
    from .steady_fit import SteadyFit, fit_steady
    from .stick_fit import StickFit, fit_stick

#: Where each public name lives: imported on first use, so that ``fit stick`` does not import lmfit/emcee.
_HOME = {
    "SteadyPosterior": "bayes",
    "sample_posterior": "bayes",
    "SteadyData": "data",
    "StickData": "data",
    "read_steady_data": "data",
    "read_stick_data": "data",
    "Estimate": "results",
    "SteadyFit": "steady_fit",
    "fit_steady": "steady_fit",
    "StickFit": "stick_fit",
    "fit_stick": "stick_fit",
}


def __getattr__(name: str) -> Any:
    if name in _HOME:
        return getattr(import_module(f".{_HOME[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


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
