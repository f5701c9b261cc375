"""The least-squares problem behind the steady fit: ln-parameters -> weighted residuals.

Parameters are fitted as natural logarithms of their SI values (positivity,
and the identifiable combinations are then linear in them).  Residuals are
``(model - data) / error`` where the error is the stated ``stress_err`` or,
without it, the measured stress itself (a constant relative error whose size
is estimated from the scatter).
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError, ParameterError
from ..parameters import Parameters, replace
from .batch import model_stress, stress_many

#: Each fitted ln-parameter stays within this distance of its start value (a factor 1e4).
SEARCH_BOX = math.log(1e4)
#: Residual given to a point where the model has no finite answer, so the optimiser steps back.
FAILED_RESIDUAL = 1e6
#: Evaluations per (free parameter + 1) a least-squares search may use.  Fits that converge take 7-60 in all;
#: a search walking along a direction the data do not determine took 3174 (20 s), which the fix-and-refit loop
#: then has to undo anyway (a joint fit of a power law with stated errors, issue 29).
MAX_EVALUATIONS = 40
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
    """Data points fitted with one model variant (with or without aging).

    Residuals are (model - data)/error.  A long record is compressed
    (:func:`make_block`): the model is evaluated only at ``nodes``
    (Chebyshev points in ln V spanning the data) and carried to the data by
    the interpolation matrix L (points x nodes).  With A = diag(1/error) L,
    b = data/error and R^T R = A^T A (Cholesky), the chi-square of any
    interpolated curve m is |A m - b|^2 = |R m - R^-T A^T b|^2 + offset
    exactly, so the optimiser works on as many residuals as there are nodes:
    a record of 10^5 points costs what one of 24 does (docs/fitting.md,
    "Long records").
    """

    velocity: np.ndarray
    stress: np.ndarray
    error: np.ndarray
    aging: bool
    nodes: np.ndarray | None = None
    basis: np.ndarray | None = None  # L, points x nodes
    r_factor: np.ndarray | None = None  # R, nodes x nodes, upper triangular
    target: np.ndarray | None = None  # R^-T A^T b
    offset: float = 0.0  # |b|^2 - |target|^2: the part of chi-square no curve can change

    def __len__(self) -> int:
        return int(self.velocity.size)

    @property
    def eval_points(self) -> np.ndarray:
        """The velocities where the model is evaluated."""
        return self.velocity if self.nodes is None else self.nodes

    @property
    def residual_count(self) -> int:
        return len(self) if self.nodes is None else int(self.nodes.size)

    def expand(self, stress: np.ndarray) -> np.ndarray:
        """Model stress at the data points from its values at :attr:`eval_points` (last axis)."""
        return stress if self.basis is None else stress @ self.basis.T

    def weighted(self, stress: np.ndarray) -> np.ndarray:
        """Model values at :attr:`eval_points` (last axis) -> their part of the residuals (linear)."""
        return stress / self.error if self.r_factor is None else stress @ self.r_factor.T

    def data_term(self) -> np.ndarray:
        return self.stress / self.error if self.target is None else self.target

    def residuals_of(self, stress: np.ndarray) -> np.ndarray:
        """Residuals of model values at :attr:`eval_points`."""
        return self.weighted(stress) - self.data_term()

    def chi_square(self, residuals: np.ndarray) -> float:
        """The data's chi-square from residuals of this block (adds the compressed-away part)."""
        return float(residuals @ residuals) + self.offset

    def model(self, params: Parameters) -> np.ndarray:
        """sigma(V) at the data points (raises ModelError/ParameterError where the model fails)."""
        return self.expand(model_stress(params, self.eval_points, self.aging))

    def with_aging(self, aging: bool) -> Block:
        return dataclasses.replace(self, aging=aging)

    def with_stress(self, stress: np.ndarray) -> Block:
        """The same points with other measured stresses (bootstrap, bias refits)."""
        if self.r_factor is None or self.basis is None:
            return dataclasses.replace(self, stress=stress)
        from scipy.linalg import solve_triangular

        scaled = stress / self.error
        target = solve_triangular(self.r_factor, (scaled / self.error) @ self.basis, trans="T")
        offset = max(float(scaled @ scaled) - float(target @ target), 0.0)
        return dataclasses.replace(self, stress=stress, target=target, offset=offset)


#: Blocks with more points than this are fitted through interpolation at Chebyshev nodes in ln V.
INTERPOLATE_ABOVE = 200
#: Node counts tried in turn until the interpolant meets INTERPOLATION_TOLERANCE.
NODE_COUNTS = (24, 48, 96, 192)
#: Largest error of the interpolated model, relative to the stress (the model itself is good to ~1e-9).
INTERPOLATION_TOLERANCE = 1e-9


def chebyshev_nodes(lo: float, hi: float, count: int) -> np.ndarray:
    """``count`` velocities at Chebyshev points of the second kind in [e^lo, e^hi] (ln V), ascending."""
    x = np.cos(np.pi * np.arange(count) / (count - 1))[::-1]
    return np.exp(0.5 * (lo + hi) + 0.5 * (hi - lo) * x)


def chebyshev_basis(velocity: np.ndarray, nodes: np.ndarray, chunk: int = 8192) -> np.ndarray:
    """Barycentric interpolation matrix (points x nodes) for the Chebyshev points ``nodes`` in ln V."""
    lo, hi = math.log(float(nodes[0])), math.log(float(nodes[-1]))
    count = nodes.size
    weights = np.where(np.arange(count) % 2 == 0, 1.0, -1.0)
    weights[0] *= 0.5
    weights[-1] *= 0.5
    x_nodes = _unit(np.log(nodes), lo, hi)
    out = np.empty((velocity.size, count))
    for start in range(0, velocity.size, chunk):
        x = _unit(np.log(velocity[start : start + chunk]), lo, hi)
        diff = x[:, None] - x_nodes[None, :]
        exact = diff == 0.0
        terms = weights / np.where(exact, 1.0, diff)
        part = terms / terms.sum(axis=1, keepdims=True)
        hit = exact.any(axis=1)
        part[hit] = exact[hit].astype(float)  # a data point on a node takes that node's value
        out[start : start + chunk] = part
    return out


def _unit(log_v: np.ndarray, lo: float, hi: float) -> np.ndarray:
    return (2.0 * log_v - (lo + hi)) / (hi - lo)


def interpolation_error(block: Block, params: Parameters) -> float:
    """Largest relative error of the interpolated model halfway (in angle) between the nodes."""
    if block.nodes is None:
        return 0.0
    lo, hi = math.log(float(block.nodes[0])), math.log(float(block.nodes[-1]))
    count = block.nodes.size
    x = np.cos(np.pi * (np.arange(count - 1) + 0.5) / (count - 1))
    check = np.exp(0.5 * (lo + hi) + 0.5 * (hi - lo) * x)
    direct = model_stress(params, check, block.aging)
    interpolated = chebyshev_basis(check, block.nodes) @ model_stress(params, block.nodes, block.aging)
    return float(np.max(np.abs(interpolated - direct) / direct))


def make_block(
    velocity: np.ndarray, stress: np.ndarray, error: np.ndarray, aging: bool, params: Parameters | None = None
) -> Block:
    """A block of data; above INTERPOLATE_ABOVE points interpolated, if that is accurate at ``params``."""
    plain = Block(velocity, stress, error, aging)
    if len(plain) <= INTERPOLATE_ABOVE or params is None:
        return plain
    lo, hi = math.log(float(velocity.min())), math.log(float(velocity.max()))
    for count in NODE_COUNTS:
        if 4 * count > len(plain):
            break
        nodes = chebyshev_nodes(lo, hi, count)
        trial = dataclasses.replace(plain, nodes=nodes)
        try:
            if interpolation_error(trial, params) <= INTERPOLATION_TOLERANCE:
                return _compressed(trial)
        except (ModelError, ParameterError):
            return plain
    return plain


def _compressed(block: Block) -> Block:
    """``block`` with the factors of its least-squares problem (Cholesky of the Gram matrix: fast and,
    for the well-conditioned Lagrange basis at Chebyshev points, accurate); uncompressed if that fails."""
    assert block.nodes is not None
    basis = chebyshev_basis(block.velocity, block.nodes)
    design = basis / block.error[:, None]
    try:
        r_factor = np.linalg.cholesky(design.T @ design).T
    except np.linalg.LinAlgError:
        return dataclasses.replace(block, nodes=None)
    out = dataclasses.replace(block, basis=basis, r_factor=r_factor)
    return out.with_stress(block.stress)


def residuals(space: Space, theta: Sequence[float], block: Block) -> np.ndarray:
    """Weighted residuals (model - data)/error; FAILED_RESIDUAL where the model fails."""
    try:
        model = model_stress(space.params(theta), block.eval_points, block.aging)
    except (ModelError, ParameterError):
        return np.full(block.residual_count, FAILED_RESIDUAL)
    return block.residuals_of(model)


def jacobian(space: Space, theta: np.ndarray, block: Block) -> np.ndarray:
    """d(residual)/d(ln parameter) by central differences, shape (residuals, keys).

    All 2p perturbed sets are evaluated together (:func:`stress_many`); where
    a perturbed set has no finite answer the one-sided difference is used.
    """
    p = len(space.keys)
    if p == 0:
        return np.zeros((block.residual_count, 0))
    sets = []
    for k in range(p):
        for sign in (1.0, -1.0):
            shifted = np.array(theta, dtype=float)
            shifted[k] += sign * JACOBIAN_STEP
            sets.append(space.params(shifted))
    stress = stress_many(sets, block.eval_points, aging=block.aging)
    up, down = stress[0::2], stress[1::2]
    centre = None
    out = np.empty((p, block.residual_count))
    for k in range(p):
        if np.all(np.isfinite(up[k])) and np.all(np.isfinite(down[k])):
            out[k] = block.weighted(up[k] - down[k]) / (2 * JACOBIAN_STEP)
            continue
        if centre is None:
            centre = model_stress(space.params(theta), block.eval_points, block.aging)
        side = up[k] - centre if np.all(np.isfinite(up[k])) else centre - down[k]
        out[k] = np.nan_to_num(block.weighted(side) / JACOBIAN_STEP)
    return out.T


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
    import lmfit  # here: the stick fit and `stickslip --help` need not pay for importing it

    centre = start if centre is None else centre
    if len(space.keys) == 0:
        r = residuals(space, start, block)
        return Minimum(start, block.chi_square(r), 1, True, "nothing to fit", ())
    pars = lmfit.Parameters()
    for key, t, c in zip(space.keys, start, centre, strict=True):
        lo, hi = c - SEARCH_BOX, c + SEARCH_BOX
        pars.add(lmfit_name(key), value=float(np.clip(t, lo, hi)), min=lo, max=hi)
    names = [lmfit_name(k) for k in space.keys]

    def objective(p: lmfit.Parameters) -> np.ndarray:
        return residuals(space, [p[n].value for n in names], block)

    def gradient(p: lmfit.Parameters) -> np.ndarray:
        return jacobian(space, np.array([p[n].value for n in names]), block)

    with lmfit_covariance_ignored(), np.errstate():  # numpy's error state as it was, whatever lmfit does to it
        result = lmfit.minimize(
            objective,
            pars,
            method="least_squares",
            calc_covar=False,
            Dfun=gradient,
            max_nfev=MAX_EVALUATIONS * (len(space.keys) + 1),
        )
    theta = np.array([result.params[n].value for n in names])
    r = residuals(space, theta, block)
    edge = tuple(
        k for k, t, c in zip(space.keys, theta, centre, strict=True) if abs(abs(t - c) - SEARCH_BOX) < 1e-3 * SEARCH_BOX
    )
    return Minimum(theta, block.chi_square(r), int(result.nfev), bool(result.success), str(result.message), edge)
