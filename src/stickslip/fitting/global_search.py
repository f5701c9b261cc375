"""A global search for the steady fit: where a local least-squares fit ends far from the data.

Before the fit calls the model unable to describe the data it scans the whole search box of the free
ln-parameters (N0 profiled out in closed form; the others by a scrambled Sobol sequence with the box's corners,
edge and face centres, through the batched quadrature), then polishes the 8 best distinct points by a batched
Levenberg-Marquardt; the best end starts the ordinary fit, which the caller runs (docs/fitting.md).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..parameters import Parameters
from .batch import stress_many
from .problem import FAILED_RESIDUAL, JACOBIAN_STEP, SEARCH_BOX, Block, Space

#: The key whose effect on sigma is a factor (sigma is proportional to N0): profiled out, not scanned.
LINEAR_KEY = "bonds.site_density"
#: Sobol points per scanned dimension in the first pass.
POINTS_PER_DIMENSION = 512
#: Distinct best points of the scan polished together, at least this fraction of the box's half-width apart.
CANDIDATES = 8
SEPARATION = 0.5
#: Iterations of the batched Levenberg-Marquardt polish.
POLISH_ITERATIONS = 25
#: Up to this many scanned dimensions the 3^d grid of the box's corners, edge and face centres is added.
CORNER_DIMENSIONS = 5
#: Evaluate this many parameter sets per batch (bounded memory).
CHUNK = 512


@dataclass(frozen=True)
class Found:
    """The best point of the scan: the parameters (free keys set) and the chi-square there."""

    params: Parameters
    chi_square: float
    evaluations: int


def _profiled_chi_square(stress: np.ndarray, block: Block, scale: bool) -> tuple[np.ndarray, np.ndarray]:
    """chi^2 of each row of model stress at the block's points, with the best factor when ``scale``."""
    weighted = block.weighted(stress)  # linear in the stress: the factor passes through
    data = block.data_term()
    if scale:
        factor = (weighted @ data) / np.einsum("ij,ij->i", weighted, weighted)
        factor = np.where(np.isfinite(factor) & (factor > 0), factor, np.nan)
    else:
        factor = np.ones(stress.shape[0])
    r = factor[:, None] * weighted - data[None, :]
    chi = np.einsum("ij,ij->i", r, r) + block.offset
    return np.where(np.isfinite(chi), chi, np.inf), factor


def _evaluate(space: Space, thetas: np.ndarray, block: Block, scale: bool) -> tuple[np.ndarray, np.ndarray]:
    chi = np.empty(len(thetas))
    factor = np.empty(len(thetas))
    for start in range(0, len(thetas), CHUNK):
        part = thetas[start : start + CHUNK]
        stress = stress_many([space.params(t) for t in part], block.eval_points, aging=block.aging)
        chi[start : start + CHUNK], factor[start : start + CHUNK] = _profiled_chi_square(stress, block, scale)
    return chi, factor


def _corner_grid(dimension: int) -> np.ndarray:
    """The 3^d points with every coordinate at the box's lower end, middle or upper end (unit box)."""
    axes = np.meshgrid(*([np.array([0.0, 0.5, 1.0])] * dimension), indexing="ij")
    return np.stack([a.ravel() for a in axes], axis=1)


def _distinct_best(thetas: np.ndarray, chi: np.ndarray, count: int, separation: float) -> list[int]:
    """Indices of the ``count`` lowest chi^2 that lie at least ``separation`` apart (max-norm)."""
    chosen: list[int] = []
    for k in np.argsort(chi):
        if not np.isfinite(chi[k]):
            break
        if all(np.max(np.abs(thetas[k] - thetas[j])) >= separation for j in chosen):
            chosen.append(int(k))
        if len(chosen) == count:
            break
    return chosen


def _residual_rows(space: Space, thetas: np.ndarray, block: Block) -> np.ndarray:
    """Weighted residuals at the block's points for each row of ``thetas``; rows of FAILED where the model fails."""
    stress = stress_many([space.params(t) for t in thetas], block.eval_points, aging=block.aging)
    r = block.weighted(stress) - block.data_term()[None, :]
    return np.where(np.isfinite(r).all(axis=1, keepdims=True), r, FAILED_RESIDUAL)


def polish_many(space: Space, thetas: np.ndarray, block: Block, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Levenberg-Marquardt from every row of ``thetas`` at once, kept inside [lower, upper]; returns the
    chi^2 of each end (the rows of ``thetas`` are updated in place).

    One batch per iteration holds every start's point and its 2p central-difference neighbours, so K starts
    cost about what one does in the single-set fit.
    """
    k_count, p = thetas.shape
    damping = np.full(k_count, 1e-2)
    eye = np.eye(p)
    r = _residual_rows(space, thetas, block)
    chi = np.einsum("ij,ij->i", r, r)
    for _ in range(POLISH_ITERATIONS):
        shifted = np.repeat(thetas, 2 * p, axis=0).reshape(k_count, 2 * p, p)
        for j in range(p):
            shifted[:, 2 * j, j] += JACOBIAN_STEP
            shifted[:, 2 * j + 1, j] -= JACOBIAN_STEP
        rows = _residual_rows(space, shifted.reshape(-1, p), block).reshape(k_count, 2 * p, -1)
        jac = (rows[:, 0::2] - rows[:, 1::2]).transpose(0, 2, 1) / (2 * JACOBIAN_STEP)  # K x m x p
        normal = np.einsum("kmi,kmj->kij", jac, jac)
        gradient = np.einsum("kmi,km->ki", jac, r)
        scaled = normal + damping[:, None, None] * (np.einsum("kii->ki", normal)[:, :, None] * eye + 1e-12 * eye)
        try:
            step = -np.linalg.solve(scaled, gradient[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:
            break
        trial = np.clip(thetas + step, lower, upper)
        trial_r = _residual_rows(space, trial, block)
        trial_chi = np.einsum("ij,ij->i", trial_r, trial_r)
        better = trial_chi < chi
        improvement = np.where(better, (chi - trial_chi) / np.maximum(chi, 1e-300), 0.0)
        thetas[better], r[better], chi[better] = trial[better], trial_r[better], trial_chi[better]
        damping = np.where(better, damping / 3.0, damping * 4.0)
        if np.all((improvement < 1e-9) & (better | (damping > 1e8))):
            break
    return chi + block.offset


def global_start(base: Parameters, centre: Parameters, keys: Sequence[str], block: Block, seed: int = 0) -> Found:
    """The best point of the scan over ``keys`` in the search box around ``centre`` (module docstring)."""
    scale = LINEAR_KEY in keys
    scanned = tuple(k for k in keys if k != LINEAR_KEY)
    space = Space(base, scanned)
    middle = Space(centre, scanned).vector()
    lower, upper = middle - SEARCH_BOX, middle + SEARCH_BOX
    if scanned:
        from scipy.stats import qmc

        unit = qmc.Sobol(len(scanned), scramble=True, seed=seed).random(POINTS_PER_DIMENSION * len(scanned))
        if len(scanned) <= CORNER_DIMENSIONS:  # the best fit of a curve the model cannot follow is often on the edge
            unit = np.concatenate([unit, _corner_grid(len(scanned))])
        thetas = lower + (upper - lower) * unit
    else:
        thetas = np.zeros((1, 0))
    chi, factor = _evaluate(space, thetas, block, scale)
    best = _distinct_best(thetas, chi, CANDIDATES, SEPARATION * SEARCH_BOX) or [int(np.argmin(chi))]
    starts = [space.params(thetas[k]) for k in best]
    if scale:
        starts = [
            p.with_overrides({LINEAR_KEY: _clipped(p.bonds.site_density * float(factor[k]), centre)})
            for p, k in zip(starts, best, strict=True)
        ]
    full = Space(base, tuple(keys))
    box_centre = Space(centre, tuple(keys)).vector()
    points = np.array([full.vector(p) for p in starts])
    ends = polish_many(full, points, block, box_centre - SEARCH_BOX, box_centre + SEARCH_BOX)
    k = int(np.argmin(ends))
    return Found(full.params(points[k]), float(ends[k]), len(thetas) + len(best))


def _clipped(n0: float, centre: Parameters) -> float:
    middle = centre.bonds.site_density
    return min(max(n0, middle * math.exp(-SEARCH_BOX)), middle * math.exp(SEARCH_BOX))
