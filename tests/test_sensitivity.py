"""Issue 22 Q2: the (tau_a, V_a) region the steady curve allows, and the spread of the predictions over it."""

from __future__ import annotations

import math

import pytest

from stickslip.fitting.data import read_steady_data
from stickslip.fitting.datasets import synthetic_steady_path
from stickslip.studies.sensitivity import (
    REGION_95,
    Spread,
    chi_square,
    predictions,
    profile,
    quasi_static_predictions,
    spreads,
    steady_fit,
    stored_region,
)


@pytest.fixture(scope="module")
def data():
    return read_steady_data(synthetic_steady_path())


@pytest.fixture(scope="module")
def region(params):
    return stored_region(params)


def test_stored_region_lies_on_the_95_percent_contour(data, region):
    """Each boundary point is Delta chi^2 = chi2.ppf(0.95, 2) = 5.991 above the best fit, recomputed from the data."""
    best = chi_square(data, region[0].params)
    assert best == pytest.approx(19.6989, abs=1e-3)  # 24 points, 4 fitted: chi^2/dof ~ 1 for the 2 % noise
    for point in region[1:]:
        assert chi_square(data, point.params) - best == pytest.approx(5.9915, abs=0.01), point.label


def test_stored_region_is_the_profile_and_its_centre_the_fit(region):
    """The best fit is fit_steady's; refitting N0 and tau at a boundary point's (tau_a, V_a) does not lower chi^2."""
    fit = steady_fit()
    for key, value in zip(("aging.aging_time", "aging.aging_velocity"), REGION_95[0][1:3], strict=True):
        section, _, name = key.partition(".")
        assert getattr(getattr(fit.parameters, section), name) == pytest.approx(value, rel=1e-6)
    point = region[3]  # 90°: the largest V_a
    chi, _ = profile(fit, point.aging_time, point.aging_velocity, start=point.params)
    assert chi >= chi_square(fit.data, point.params) - 0.01


def test_spread_says_robust_only_within_its_tolerance():
    rows = [{"x": 100.0, "y": 10.0}, {"x": 104.0, "y": 30.0}, {"x": 97.0, "y": math.nan}]
    x, y = spreads(rows, tolerance=0.1)
    assert (x.low, x.high, x.relative, x.robust) == (97.0, 104.0, pytest.approx(0.07), True)
    assert math.isnan(y.relative) and not y.robust  # a prediction that fails somewhere is not robust
    assert not Spread("z", 1.0, 0.5, 1.7).robust


def test_vc_moves_over_the_region_but_the_stick_from_rest_does_not(region, critical):
    """Vc (Eq 9) depends on the aging parameters; Eq 15's stick from rest (stick chains, block) does not."""
    rows = predictions([region[0], region[1], region[4]], quasi_static_predictions)
    assert rows[0]["critical_velocity"] == pytest.approx(critical.velocity, rel=0.01)  # the fit recovers the truth
    assert rows[1]["critical_velocity"] < 0.9 * rows[0]["critical_velocity"] < rows[2]["critical_velocity"]
    assert rows[1]["stick_time_from_rest"] == rows[0]["stick_time_from_rest"] == rows[2]["stick_time_from_rest"]
