"""The least-squares problem behind the steady fit: ln-parameters -> weighted residuals.

Parameters are fitted as natural logarithms of their SI values (positivity,
and the identifiable combinations are then linear in them).  Residuals are
``(model - data) / error`` where the error is the stated ``stress_err`` or,
without it, the measured stress itself (a constant relative error whose size
is estimated from the scatter).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass

import lmfit
import numpy as np

from ..errors import ModelError, ParameterError
from ..model.steady import steady_state
from ..parameters import Parameters, replace
from .batch import stress_many

#: Each fitted ln-parameter stays within this distance of its start value (a factor 1e4).
SEARCH_BOX = math.log(1e4)
#: Residual given to a point where the model has no finite answer, so the optimiser steps back.
FAILED_RESIDUAL = 1e6
#: Step in ln-parameter for central-difference Jacobians (the model is accurate to ~1e-7).
JACOBIAN_STEP = 1e-3


@contextmanager
def lmfit_covariance_ignored() -> Iterator[None]:
    """Ignore lmfit's complaint about its own covariance estimate, which is not used.

    lmfit's least_squares always inverts J^T J and takes square roots of the
    diagonal; along a direction the data do not determine that matrix is
    singular and numpy warns.  Such directions are found and handled by
    :mod:`stickslip.fitting.identify`; the covariance reported is computed
    separately (:func:`jacobian`).  Only that one warning from lmfit's module
    is filtered.
    """
    with warnings.catch_warnings():
        warnings.filterwarnings(
            "ignore", message="invalid value encountered in sqrt", category=RuntimeWarning, module="lmfit"
        )
        warnings.filterwarnings("ignore", message="divide by zero encountered", category=RuntimeWarning, module="lmfit")
        yield


def lmfit_name(key: str) -> str:
    """A valid lmfit parameter name for a canonical key (ln of its SI value)."""
    return "ln_" + key.replace(".", "__")


@dataclass(frozen=True)
class Space:
    """ln-values of ``keys`` on top of ``base``."""

    base: Parameters
    keys: tuple[str, ...]

    def params(self, theta: Sequence[float]) -> Parameters:
        sections: dict[str, dict[str, float]] = {}
        for key, t in zip(self.keys, theta, strict=True):
            section, name = key.split(".")
            sections.setdefault(section, {})[name] = math.exp(float(t))
        return replace(self.base, **sections) if sections else self.base

    def vector(self, params: Parameters | None = None) -> np.ndarray:
        values = (params or self.base).as_dict()
        return np.array([math.log(values[k]) for k in self.keys])


@dataclass(frozen=True)
class Block:
    """Data points fitted with one model variant (with or without aging)."""

    velocity: np.ndarray
    stress: np.ndarray
    error: np.ndarray
    aging: bool

    def __len__(self) -> int:
        return int(self.velocity.size)


def residuals(space: Space, theta: Sequence[float], block: Block) -> np.ndarray:
    """Weighted residuals (model - data)/error; FAILED_RESIDUAL where the model fails."""
    try:
        model = steady_state(space.params(theta), block.velocity, aging=block.aging).stress
    except (ModelError, ParameterError):
        return np.full(len(block), FAILED_RESIDUAL)
    return (model - block.stress) / block.error


def jacobian(space: Space, theta: np.ndarray, block: Block) -> np.ndarray:
    """d(residual)/d(ln parameter) by central differences, shape (points, keys).

    All 2p perturbed sets are evaluated together (:func:`stress_many`); where
    a perturbed set has no finite answer the one-sided difference is used.
    """
    p = len(space.keys)
    if p == 0:
        return np.zeros((len(block), 0))
    sets = []
    for k in range(p):
        for sign in (1.0, -1.0):
            shifted = np.array(theta, dtype=float)
            shifted[k] += sign * JACOBIAN_STEP
            sets.append(space.params(shifted))
    stress = stress_many(sets, block.velocity, aging=block.aging)
    up, down = stress[0::2], stress[1::2]
    centre = None
    out = np.empty((len(block), p))
    for k in range(p):
        if np.all(np.isfinite(up[k])) and np.all(np.isfinite(down[k])):
            out[:, k] = (up[k] - down[k]) / (2 * JACOBIAN_STEP) / block.error
            continue
        if centre is None:
            centre = steady_state(space.params(theta), block.velocity, aging=block.aging).stress
        side = up[k] - centre if np.all(np.isfinite(up[k])) else centre - down[k]
        out[:, k] = np.nan_to_num(side / JACOBIAN_STEP / block.error)
    return out


@dataclass(frozen=True)
class Minimum:
    theta: np.ndarray
    chi_square: float
    nfev: int
    success: bool
    message: str
    at_edge: tuple[str, ...]


def minimize(space: Space, start: np.ndarray, block: Block, centre: np.ndarray | None = None) -> Minimum:
    """Least squares over ``space.keys`` (lmfit, trust-region reflective, bounded search box)."""
    centre = start if centre is None else centre
    if len(space.keys) == 0:
        r = residuals(space, start, block)
        return Minimum(start, float(r @ r), 1, True, "nothing to fit", ())
    pars = lmfit.Parameters()
    for key, t, c in zip(space.keys, start, centre, strict=True):
        lo, hi = c - SEARCH_BOX, c + SEARCH_BOX
        pars.add(lmfit_name(key), value=float(np.clip(t, lo, hi)), min=lo, max=hi)
    names = [lmfit_name(k) for k in space.keys]

    def objective(p: lmfit.Parameters) -> np.ndarray:
        return residuals(space, [p[n].value for n in names], block)

    def gradient(p: lmfit.Parameters) -> np.ndarray:
        return jacobian(space, np.array([p[n].value for n in names]), block)

    with lmfit_covariance_ignored():
        result = lmfit.minimize(objective, pars, method="least_squares", calc_covar=False, Dfun=gradient)
    theta = np.array([result.params[n].value for n in names])
    r = residuals(space, theta, block)
    edge = tuple(
        k for k, t, c in zip(space.keys, theta, centre, strict=True) if abs(abs(t - c) - SEARCH_BOX) < 1e-3 * SEARCH_BOX
    )
    return Minimum(theta, float(r @ r), int(result.nfev), bool(result.success), str(result.message), edge)
