"""numpy's ``chebval`` for one point on Python floats: the quasi-static jump's and slip's series (issue 31).

``numpy.polynomial.chebyshev.chebval(x, c)`` runs Clenshaw's recurrence with a numpy operation per coefficient: for a
scalar (or 0-d) ``x`` and 48 coefficients, as the slip's and the jump's series have, ~24 us a call, and the
quasi-static cycle asks for thousands of single points (root searches on the branch and the slip's clock: ~3 100 in
the report's phase diagram, ~5 % of its CPU).  The same recurrence on Python floats takes 7-10 us.  It is numpy's
arithmetic, operation by operation and in the same order, on the same IEEE doubles (neither contracts a multiply
and an add), so the numbers are numpy's to the bit (tests/test_transforms.py); the result is a numpy float, as
numpy's, so that a division by zero downstream still gives inf with a warning, not a ZeroDivisionError.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.polynomial import chebyshev as _cheb


def chebval(x: Any, c: np.ndarray) -> Any:
    """``numpy.polynomial.chebyshev.chebval(x, c)``: on Python floats for one point and one series, else numpy's."""
    if np.ndim(x) != 0 or np.ndim(c) != 1 or len(c) < 3:
        return _cheb.chebval(x, c)
    coefficients = c.tolist()
    point = float(x)
    twice = 2 * point
    c0 = coefficients[-2]
    c1 = coefficients[-1]
    for ck in reversed(coefficients[:-2]):  # numpy's loop: tmp = c0; c0 = c[-i] - c1; c1 = tmp + c1 x2
        c0, c1 = ck - c1, c0 + c1 * twice
    return np.float64(c0 + c1 * point)
