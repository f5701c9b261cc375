"""Gauss-Legendre panel rules with a spectral indefinite-integration matrix.

On a panel mapped to [-1, 1] with K Gauss-Legendre nodes t_k, a smooth f is
represented by its interpolating polynomial; then

* ``weights @ f``          is the panel integral (exact for degree <= 2K-1), and
* ``cumulative @ f``       is the integral from -1 to each node t_k (exact for degree <= K-1),
* ``cumulative_total``     is ``weights`` (the integral to +1), kept as the last row.

The steady-state model uses these to get the cumulative hazard H(x) at the
same nodes where the survival exp(-H) is integrated, to spectral accuracy.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.polynomial import legendre


@dataclass(frozen=True)
class PanelRule:
    """K-point Gauss-Legendre rule on [-1, 1] with its integration matrix."""

    nodes: np.ndarray  # (K,)
    weights: np.ndarray  # (K,)
    cumulative: np.ndarray  # (K+1, K): rows 0..K-1 integrate to the nodes, row K to +1


@lru_cache(maxsize=8)
def panel_rule(order: int) -> PanelRule:
    """The Gauss-Legendre rule of ``order`` nodes and its spectral integration matrix."""
    if order < 2:
        raise ValueError("panel rule needs at least 2 nodes")
    nodes, weights = legendre.leggauss(order)
    vander = legendre.legvander(nodes, order - 1)  # (K, K): Legendre polynomials at nodes
    lagrange_coefficients = np.linalg.inv(vander)  # column j: Legendre coefficients of l_j
    antiderivatives = legendre.legint(lagrange_coefficients, lbnd=-1.0, axis=0)
    at = np.append(nodes, 1.0)
    cumulative = legendre.legval(at, antiderivatives).T  # (K+1, K)
    return PanelRule(nodes=nodes, weights=weights, cumulative=np.ascontiguousarray(cumulative))
