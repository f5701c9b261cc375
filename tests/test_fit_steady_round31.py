"""Round 31: a fit from the input values that is no closer to the data than a constant is searched again.

Tester Z's seven points of a U (500 -> 300 -> 800 Pa between 10 and 640 µm/s, no stated errors) were "the model's
fit finds none either (it is no closer to the data than the constant)": the method's fit from the input values had
stopped in a minimum of its own.  The model's curve has a minimum; least squares on the package's reference model
(``steady_state``, scipy from the paper's set, independently of the fit's code) comes within ~20 % rms of the
points where the best constant misses them by ~28 %.  The whole search box is now scanned there, as where a fit misses,
and the words give the better fit's test.
"""

from __future__ import annotations

import numpy as np
from scipy import optimize

import stickslip
from stickslip.fitting import SteadyData, fit_steady
from stickslip.quasistatic.steady import steady_state

VELOCITY = np.array([10.0, 20.0, 40.0, 80.0, 160.0, 320.0, 640.0]) * 1e-6  # m/s
STRESS = np.array([500.0, 400.0, 300.0, 350.0, 450.0, 600.0, 800.0])  # Pa
KEYS = ("bonds.site_density", "aging.aging_time", "aging.aging_velocity", "bonds.bond_time")


def _relative_rms(model: np.ndarray) -> float:
    return float(np.sqrt(np.mean(((model - STRESS) / STRESS) ** 2)))


def test_the_model_is_closer_to_the_u_than_a_constant_and_the_fit_says_so() -> None:
    gel = stickslip.load_parameters("gelatin-glass")
    start = np.log([gel.as_dict()[k] for k in KEYS])

    def residuals(x: np.ndarray) -> np.ndarray:
        model = steady_state(gel.with_overrides(dict(zip(KEYS, np.exp(x), strict=True))), VELOCITY).stress
        return (model - STRESS) / STRESS

    found = optimize.least_squares(residuals, start, diff_step=1e-6)
    constant = min(_relative_rms(np.full(STRESS.size, c)) for c in np.linspace(300.0, 800.0, 501))
    assert _relative_rms(STRESS * (1.0 + found.fun)) < 0.85 * constant  # measured 0.203 against 0.278

    fit = fit_steady(SteadyData(VELOCITY, STRESS, None, np.arange(2, 9)))
    assert fit.status == "failed"  # 7 points without errors cannot show the dependence at p <= 0.001
    assert "no closer to the data than the constant" not in fit.reason, fit.reason
    assert "the model's fit finds none either (p =" in fit.reason, fit.reason
