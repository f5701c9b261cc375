"""Steady fit: residuals in units of the noise when it is estimated; flat data carry no velocity dependence."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip.fitting import SteadyData, fit_steady
from stickslip.parameters import load_parameters
from stickslip.quasistatic.steady import steady_state

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


@pytest.mark.parametrize("noise", [0.0, 0.02])
def test_flat_data_have_no_critical_point_and_the_fit_fails(noise, tmp_path, capsys):
    """Issue 18: flat 400 Pa data gave Vc = 171.5 um/s [153.7, 191.4]; it must say the data carry no information."""
    stress = 400.0 * (1 + noise * np.random.default_rng(1).standard_normal(VELOCITY.size))
    fit = fit_steady(SteadyData.from_arrays(VELOCITY, stress, None))
    assert fit.status == "failed" and "no significant velocity dependence" in fit.reason
    assert fit.critical_velocity.value is None and fit.critical_velocity.interval is None
    assert all(e.interval is None for e in fit.estimates)
    assert "Fit failed" in fit.report()
    path = tmp_path / "flat.csv"
    path.write_text("velocity,stress\n" + "\n".join(f"{v},{s}" for v, s in zip(VELOCITY, stress, strict=True)))
    out_toml = tmp_path / "fitted.toml"
    code, out, err = run_main(capsys, "fit", "steady", str(path), "--json", "-o", str(out_toml))
    assert code == 3 and "fit failed" in err and not out_toml.exists()
    assert json.loads(out)["status"] == "failed"


def test_a_curve_with_a_minimum_still_fits(tmp_path):
    true = steady_state(TRUE, VELOCITY).stress
    fit = fit_steady(SteadyData.from_arrays(VELOCITY, true * (1 + 0.02 * np.random.default_rng(5).standard_normal(24)),
                                            None))  # fmt: skip
    assert fit.status == "ok" and fit.critical_velocity.interval is not None
