"""dsigma/dV over the parameter box: steady_state's stress_slope against independent references.

The slope comes from differentiating the quadrature under the integral; where the FENE cliff is
sharper than floating point can resolve (aging rates alpha ~ 1e13-1e15, the survival steps to 0 within
ulps) the step's own ln V derivative has to be added, and a 'negligible' hazard ahead of the cliff is
only negligible for dH/d ln V when (1 + beta) times it is.  Without those the slope was off by up to
100 % (box_cases(seed=12, count=9000): cases 7049, 6140, 4905, ...), silently.

References: tests/reference_slope.py (the ln V derivatives carried as states of the vectorised
Dormand-Prince reference) on the hard corner, and a Richardson-extrapolated central difference in
ln V of reference_many on the sets whose cliff is sharper than the reference's steps can follow.
"""

from __future__ import annotations

import numpy as np

from reference_slope import reference_slope_many, slope_error
from reference_steady import box_cases, reference_many
from stickslip import load_parameters, steady_state

GEL = load_parameters("gelatin-glass")
SPEC = 1e-6  # relative to max(|dsigma/dV|, 1e-3 sigma/V)
#: box_cases(seed=12, count=9000) indices where the slope was wrong (1.0, 0.48, 0.10, 0.074, ...)
STEEP_CLIFF_CASES = (7049, 6140, 4905, 8929, 6330, 7236, 6921, 7249, 6970, 8705)


def _slopes(cases):
    return np.array([float(steady_state(p, v, aging=aging).stress_slope) for p, v, aging in cases])


def test_slope_in_the_hard_corner_against_the_derivative_reference():
    cases = box_cases(seed=41, count=120, base=GEL, corner_share=1.0)
    stress, ref = reference_slope_many(cases)
    velocity = np.array([c[1] for c in cases])
    err = slope_error(_slopes(cases), ref, stress, velocity)
    assert err.max() <= SPEC, (float(err.max()), int(err.argmax()))


def test_slope_where_the_cliff_is_a_step_against_a_finite_difference():
    cases = box_cases(seed=12, count=9000, base=GEL, corner_share=0.5, only=STEEP_CLIFF_CASES)
    velocity = np.array([c[1] for c in cases])
    h = 1e-2
    shifted = {m: reference_many([(p, v * np.exp(m * h), aging) for p, v, aging in cases])[0] for m in (-2, -1, 1, 2)}
    d1 = (shifted[1] - shifted[-1]) / (2 * h)
    d2 = (shifted[2] - shifted[-2]) / (4 * h)
    ref = (4 * d1 - d2) / 3 / velocity  # O(h^4); these curves are smooth in ln V (h = 1e-3 agrees to 1e-6)
    stress = reference_many(cases)[0]
    err = slope_error(_slopes(cases), ref, stress, velocity)
    assert err.max() <= SPEC, (float(err.max()), int(err.argmax()))
