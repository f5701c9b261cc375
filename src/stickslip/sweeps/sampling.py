"""Points of a sweep computed one batch at a time from the specification alone.

Grid points by mixed-radix decomposition of the index, Latin-hypercube points by a keyed Feistel permutation of
the strata (with cycle walking) and a counter-based hash inside each stratum, all in uint64 integer arithmetic:
nothing of size N is built, and the samples are the same on every machine and numpy version (docs/sweep.md).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

_MASK64 = np.uint64(0xFFFFFFFFFFFFFFFF)
_FEISTEL_ROUNDS = 6


def grid_values(index: np.ndarray, axes: Sequence[np.ndarray], keys: Sequence[str]) -> dict[str, np.ndarray]:
    """Values of grid points ``index`` (last axis fastest, as in ``itertools.product``)."""
    out: dict[str, np.ndarray] = {}
    rest = index.copy()
    for key, values in zip(reversed(keys), reversed(axes), strict=True):
        out[key] = np.asarray(values, dtype=float)[rest % values.size]
        rest //= values.size
    return {key: out[key] for key in keys}


def splitmix64(x: np.ndarray) -> np.ndarray:
    """The splitmix64 finaliser, elementwise on uint64 (a bijection with good avalanche)."""
    z = (x + np.uint64(0x9E3779B97F4A7C15)) & _MASK64
    z = ((z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)) & _MASK64
    z = ((z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)) & _MASK64
    return z ^ (z >> np.uint64(31))


def _key(seed: int, dimension: int, salt: int) -> np.uint64:
    mixed = splitmix64(np.array([seed & 0xFFFFFFFFFFFFFFFF], dtype=np.uint64))
    mixed = splitmix64(mixed ^ np.uint64(dimension * 0x100 + salt))
    return np.uint64(mixed[0])


def permute(index: np.ndarray, size: int, seed: int, dimension: int) -> np.ndarray:
    """A pseudo-random permutation of ``0 .. size-1`` evaluated at ``index`` (a bijection for each seed)."""
    half = max(1, (int(size - 1).bit_length() + 1) // 2)
    mask = np.uint64((1 << half) - 1)
    shift = np.uint64(half)
    keys = [_key(seed, dimension, r) for r in range(_FEISTEL_ROUNDS)]

    def once(x: np.ndarray) -> np.ndarray:
        left, right = x >> shift, x & mask
        for k in keys:
            left, right = right, left ^ (splitmix64(right ^ k) & mask)
        return (left << shift) | right

    x = np.asarray(index, dtype=np.uint64)
    x = once(x)
    outside = x >= np.uint64(size)
    while np.any(outside):  # cycle walking: the domain is < 4 * size, so this ends after a few passes
        x[outside] = once(x[outside])
        outside = x >= np.uint64(size)
    return x.astype(np.int64)


def uniform(index: np.ndarray, seed: int, dimension: int) -> np.ndarray:
    """A uniform number in [0, 1) for each index (counter-based: point i always gets the same one)."""
    bits = splitmix64(np.asarray(index, dtype=np.uint64) ^ _key(seed, dimension, 0xFF))
    return (bits >> np.uint64(11)).astype(np.float64) * 2.0**-53


def latin_hypercube(
    index: np.ndarray, size: int, seed: int, dimension: int, low: float, high: float, log: bool
) -> np.ndarray:
    """Coordinate ``dimension`` of Latin-hypercube points ``index`` out of ``size``, in [low, high].

    Each of the ``size`` equal strata of [low, high] (of log values with
    ``log``) holds exactly one point, at a uniform position inside it.
    """
    unit = (permute(index, size, seed, dimension) + uniform(index, seed, dimension)) / size
    if log:
        lo, hi = np.log(low), np.log(high)
        return np.clip(np.exp(lo + unit * (hi - lo)), min(low, high), max(low, high))
    return low + unit * (high - low)
