"""What steady friction data can and cannot determine (docs/fitting.md).

sigma(V) depends on the nine bond and aging parameters only through six *combinations* (:data:`COMBINATIONS`,
integer exponents of the parameters).  A set of free parameters can be fitted only if the matrix of exponents
restricted to them has full column rank; beyond these exact degeneracies :func:`undetermined` finds the
directions the fit's covariance leaves weakly constrained.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..parameters import COMBINATIONS

#: Every parameter the steady curve depends on, in a fixed order.
STEADY_KEYS = (
    "bonds.site_density",
    "bonds.bond_time",
    "bonds.breakage_weight",
    "bonds.chain_stiffness",
    "bonds.activation_length",
    "bonds.temperature",
    "bonds.max_extension",
    "aging.aging_time",
    "aging.aging_velocity",
)
AGING_KEYS = ("aging.aging_time", "aging.aging_velocity")
NO_AGING_KEYS = tuple(k for k in STEADY_KEYS if k not in AGING_KEYS)

#: Fitted unless fixed: one carrier for each identifiable combination (u0 = 1 a priori, as in the paper).
DEFAULT_FREE = (
    "bonds.site_density",
    "bonds.bond_time",
    "bonds.activation_length",
    "aging.aging_time",
    "aging.aging_velocity",
)

#: When a direction is undetermined, the key to fix is chosen among equally good
#: candidates in this order (the FENE strength first, the stress scale last).
FIX_PREFERENCE = (
    "bonds.activation_length",
    "bonds.max_extension",
    "bonds.chain_stiffness",
    "bonds.temperature",
    "bonds.breakage_weight",
    "aging.aging_velocity",
    "aging.aging_time",
    "bonds.bond_time",
    "bonds.site_density",
)

#: A direction of the fitted ln-parameters whose standard deviation exceeds this
#: (a factor e at one sigma, ~50 across a 95 % interval) counts as not determined.
UNDETERMINED_SD = 1.0

SYMBOLS = {
    "bonds.site_density": "N0",
    "bonds.bond_time": "τ",
    "bonds.breakage_weight": "u0",
    "bonds.chain_stiffness": "M",
    "bonds.activation_length": "λ",
    "bonds.temperature": "T",
    "bonds.max_extension": "Δl_m",
    "aging.aging_time": "τa",
    "aging.aging_velocity": "Va",
    "stick.attached_chains": "Nc0",
    "stick.break_rate": "uc/τ",
    "stick.aging_time": "τa(stick)",
}


def exponent_matrix(keys: Sequence[str], aging: bool = True) -> np.ndarray:
    """d ln(combination) / d ln(parameter): rows are combinations, columns ``keys``."""
    combos = [c for c in COMBINATIONS if aging or not c.aging]
    return np.array([[c.exponents.get(k, 0) for k in keys] for c in combos], dtype=float)


def combination_names(aging: bool = True) -> list[str]:
    return [c.symbol for c in COMBINATIONS if aging or not c.aging]


@dataclass(frozen=True)
class Selection:
    """Free keys that the exact structure of sigma(V) allows, and what was dropped and why."""

    free: tuple[str, ...]
    dropped: tuple[str, ...]
    messages: tuple[str, ...]


def select_identifiable(candidates: Sequence[str], aging: bool = True) -> Selection:
    """Keep candidates in order while each adds a new direction in combination space.

    A candidate that adds none moves along an exact degeneracy of sigma(V)
    together with the keys already kept; it is dropped (left at its input
    value) with a message saying which combinations sigma depends on.
    """
    kept: list[str] = []
    dropped: list[str] = []
    messages: list[str] = []
    for key in candidates:
        trial = [*kept, key]
        if np.linalg.matrix_rank(exponent_matrix(trial, aging)) == len(trial):
            kept.append(key)
            continue
        dropped.append(key)
        partners = [k for k in kept if exponent_matrix([k], aging).any()]
        messages.append(
            f"{key} ({SYMBOLS[key]}) is not separately identifiable from {', '.join(partners)}: σ(V) depends on"
            f" these only through {', '.join(combination_names(aging))}; kept fixed at its input value"
        )
    return Selection(tuple(kept), tuple(dropped), tuple(messages))


@dataclass(frozen=True)
class Direction:
    """A direction of the fitted ln-parameters that the data leave undetermined."""

    sd: float
    weights: dict[str, float]

    def describe(self) -> str:
        parts = [f"{w:+.2f} ln {SYMBOLS.get(k, k)}" for k, w in self.weights.items() if abs(w) >= 0.05]
        sd = "unbounded" if not np.isfinite(self.sd) else f"{self.sd:.3g}"
        return f"({' '.join(parts)}) with standard deviation {sd}"


def undetermined(keys: Sequence[str], jacobian: np.ndarray, noise_scale: float) -> list[Direction]:
    """Directions of ln-parameter space with standard deviation above :data:`UNDETERMINED_SD`.

    ``jacobian`` is d(residual)/d(ln parameter) with residuals divided by
    their errors; ``noise_scale`` multiplies those errors (1 when they are
    stated, the estimated relative noise otherwise).
    """
    _, singular, vt = np.linalg.svd(jacobian, full_matrices=False)
    out = []
    for s, row in zip(singular, vt, strict=True):
        sd = noise_scale / s if s > 0 else float("inf")
        if not sd <= UNDETERMINED_SD:
            sign = 1.0 if row[np.argmax(np.abs(row))] > 0 else -1.0
            out.append(Direction(float(sd), {k: float(sign * w) for k, w in zip(keys, row, strict=True)}))
    return out


def choose_key_to_fix(
    keys: Sequence[str], direction: Direction, protected: Sequence[str], preference: Sequence[str] = FIX_PREFERENCE
) -> str:
    """The key to fix to remove an undetermined ``direction``.

    Candidates are the keys with at least half the largest weight in the
    direction (fixing any of them pins it); among them keys the user asked to
    fit (``protected``) come last, then ``preference`` (default :data:`FIX_PREFERENCE`) decides.
    """
    largest = max(abs(w) for w in direction.weights.values())
    candidates = [k for k in keys if abs(direction.weights[k]) >= 0.5 * largest]

    def rank(key: str) -> tuple[bool, int]:
        return (key in protected, preference.index(key) if key in preference else len(preference))

    return min(candidates, key=rank)
