"""The steady stress for many parameter sets at once (finite-difference Jacobians, MCMC walkers).

:func:`stickslip.quasistatic.steady.steady_stress_many` evaluates all sets in one
quadrature march.  A set for which the model has no finite answer makes the
batch fail; then each set is evaluated alone so that only its row is NaN.

Trial parameters of an optimiser or a sampler can be absurd (a factor 1e4
from the start in every key).  Where the model's arithmetic overflows there,
the trial set is counted as a failure of the model (a ModelError, or a NaN
row) instead of letting numpy's warning reach the user; valid parameters
never warn, so nothing is hidden.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager

import numpy as np

from ..errors import ModelError, ParameterError
from ..parameters import Parameters
from ..quasistatic.steady import steady_stress_many


@contextmanager
def overflow_is_failure() -> Iterator[None]:
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        try:
            yield
        except (RuntimeWarning, FloatingPointError, OverflowError) as exc:
            raise ModelError(f"the steady model has no finite answer for these parameters ({exc})") from None


def model_stress(params: Parameters, velocity: np.ndarray, aging: bool = True) -> np.ndarray:
    """sigma(V) of Eqs 6-8; ModelError where the model's arithmetic overflows or the answer is not finite.

    A fit or a search calls this hundreds of times, and its Jacobians have loaded numba already: it runs the
    compiled march at any width (docs/steady-state.md, "Wide batches run compiled").
    """
    shape = np.shape(velocity)
    with overflow_is_failure():
        stress = steady_stress_many([params], velocity, aging=aging, compiled_from=1)[0].reshape(shape)
    if not np.all(np.isfinite(stress)):
        raise ModelError("the steady model has no finite answer for these parameters")
    return stress


def stress_many(params_list: Sequence[Parameters], velocity: np.ndarray, aging: bool = True) -> np.ndarray:
    """sigma(V) of Eqs 6-8, shape (len(params_list), len(velocity)); NaN rows where the model fails."""
    velocity = np.asarray(velocity, dtype=float).ravel()
    try:
        with overflow_is_failure():
            out = steady_stress_many(list(params_list), velocity, aging=aging)
        if np.all(np.isfinite(out)):
            return out
    except (ModelError, ParameterError):
        pass
    out = np.full((len(params_list), velocity.size), np.nan)
    for k, p in enumerate(params_list):  # each alone: only the sets that fail are NaN
        try:
            out[k] = model_stress(p, velocity, aging=aging)
        except (ModelError, ParameterError):
            pass
    return out
