"""The steady stress for many parameter sets at once (finite-difference Jacobians, MCMC walkers).

:func:`stickslip.model.steady.steady_stress_many` evaluates all sets in one
quadrature march.  A set for which the model has no finite answer makes the
batch raise; then each set is evaluated alone so that only its row is NaN.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import ModelError, ParameterError
from ..model.steady import steady_state, steady_stress_many
from ..parameters import Parameters


def _loop(params_list: Sequence[Parameters], velocity: np.ndarray, aging: bool) -> np.ndarray:
    out = np.full((len(params_list), velocity.size), np.nan)
    for k, p in enumerate(params_list):
        try:
            out[k] = steady_state(p, velocity, aging=aging).stress
        except (ModelError, ParameterError):
            pass
    return out


def stress_many(params_list: Sequence[Parameters], velocity: np.ndarray, aging: bool = True) -> np.ndarray:
    """sigma(V) of Eqs 6-8, shape (len(params_list), len(velocity)); NaN rows where the model fails."""
    velocity = np.asarray(velocity, dtype=float).ravel()
    try:
        return steady_stress_many(list(params_list), velocity, aging=aging)
    except (ModelError, ParameterError):
        return _loop(params_list, velocity, aging)  # isolate the sets that fail
