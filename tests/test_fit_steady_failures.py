"""Steady fit: residuals in units of the noise when it is estimated; flat data carry no velocity dependence."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.fitting import SteadyData, fit_steady
from stickslip.model.steady import steady_state
from stickslip.parameters import load_parameters

TRUE = load_parameters("gelatin-glass")
VELOCITY = np.geomspace(140e-6, 2000e-6, 24)


@pytest.mark.parametrize("method", ["two-step", "joint"])
def test_residuals_are_in_units_of_the_estimated_noise(method):
    """Issue 17 §5: a row 2.5 sigma off was printed as (data - fit)/error = -0.05 (it was ln(data/fit))."""
    true = steady_state(TRUE, VELOCITY).stress
    rng = np.random.default_rng(3)
    stress = true * (1 + 0.02 * rng.standard_normal(VELOCITY.size))
    stress[10] = true[10] * (1 - 2.5 * 0.02)
    fit = fit_steady(SteadyData.from_arrays(VELOCITY, stress, None), method=method)
    z = fit.residuals
    # normalised by the noise the fit itself estimated: rms ~ sqrt(dof/n), the outlier near -2.5
    assert np.sqrt(np.mean(z**2)) == pytest.approx(np.sqrt(fit.dof / VELOCITY.size), rel=0.25)
    assert -3.5 < z[10] < -1.5
    assert f"| {z[10]:+.2f} |" in fit.report()
