"""scipy's DCT-I and ``exprel`` without scipy: the jump's and the slip's Chebyshev series (issue 31).

``scipy.fft`` and ``scipy.special`` take ~0.3 s to import (scipy's array-API layer, numpy.f2py and more), which a
stick-slip run of ``stickslip transient`` paid at its first jump (the branch's Chebyshev coefficients) and slip.
Both are computed here the way scipy computes them, so the numbers are scipy's (tests/test_transforms.py compares
them bit for bit):

* :func:`dct1`: scipy.fft's type-1 DCT is pocketfft's: a real FFT of the even extension of length 2n, the real
  parts of its bins.  numpy 2's ``numpy.fft.rfft`` is the same pocketfft (C++) plan, so the same floats; numpy 1's
  older pocketfft (C) agrees to rounding only.
* :func:`exprel`: scipy's ``exprel(x)`` is ``expm1(x)/x`` of the C library, 1 for ``|x| < eps`` and inf above 717;
  :func:`math.expm1` is that C function (numpy's vectorised ``expm1`` is not: it differs in the last bit).
"""

from __future__ import annotations

import math

import numpy as np

_EPS = float(np.finfo(float).eps)
#: above this exprel is inf (scipy's cut, near ln of the largest double)
_EXPREL_INF = 717.0


def dct1(values: np.ndarray) -> np.ndarray:
    """The type-1 DCT along the last axis, unnormalised: ``scipy.fft.dct(values, type=1, axis=-1)``."""
    values = np.asarray(values, dtype=float)
    if values.shape[-1] < 2:
        raise ValueError(f"dct1: needs at least 2 points along the last axis, got {values.shape[-1]}")
    extended = np.concatenate([values, values[..., -2:0:-1]], axis=-1)
    return np.fft.rfft(extended, axis=-1).real


def _exprel(x: float) -> float:
    if abs(x) < _EPS:
        return 1.0
    if x > _EXPREL_INF:
        return math.inf
    try:
        return math.expm1(x) / x
    except OverflowError:  # between ln(max double) and the cut: C's expm1 gives inf, Python's math raises
        return math.inf


def exprel(x: np.ndarray | float) -> np.ndarray:
    """(e^x - 1)/x, 1 at x = 0, elementwise: ``scipy.special.exprel(x)``."""
    x = np.asarray(x, dtype=float)
    return np.array([_exprel(value) for value in x.ravel().tolist()], dtype=float).reshape(x.shape)
