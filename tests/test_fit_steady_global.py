"""Steady fit: the model's misfit is not blamed on the data (issue 27 item 8, issue 29).

The noise the fit is judged against is measured without the model (neighbouring points); a local fit that
misses is followed by a global search; a curve the model cannot follow fails with its misfit, never with
"no velocity dependence"; data without velocity dependence fail at once, without a fit.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip.fitting import SteadyData, fit_steady
from stickslip.fitting.scatter import local_scatter, velocity_dependence
from stickslip.parameters import load_parameters
from stickslip.quasistatic.critical import critical_point
from stickslip.quasistatic.steady import steady_state

TRUE = load_parameters("gelatin-glass")
WIDE = np.geomspace(10e-6, 2000e-6, 20)


def hand_made_u_curve() -> np.ndarray:
    """Issue 27: 905 Pa at 10 um/s, 301 Pa at the minimum at 150 um/s, 884 Pa at 2 mm/s, parabolic in ln V."""
    x = np.log(WIDE / 150e-6)
    low, high = np.log(10 / 150), np.log(2000 / 150)
    return np.where(x < 0, 301 + (905 - 301) * (x / low) ** 2, 301 + (884 - 301) * (x / high) ** 2)


def power_law() -> np.ndarray:
    """A monotone velocity-weakening power law, 905 Pa at 10 um/s falling as V^-0.3."""
    return 905.0 * (WIDE / 10e-6) ** -0.3


def _misfit_numbers(reason: str) -> tuple[float, float]:
    found = re.search(r"rms misfit of ([0-9.e+-]+) % \(([0-9.e+-]+) Pa\)", reason)
    assert found, reason
    return float(found.group(1)) / 100, float(found.group(2))


# --------------------------------------------------------------------------- the noise without the model


def test_scatter_between_neighbours_has_the_noise_and_the_satterthwaite_spread():
    """Known truth: 2 % relative noise on a smooth model curve, 400 realisations.  The estimate's mean is the
    noise variance (plus the curve's small curvature term) and its relative variance is 2/dof."""
    velocity = np.geomspace(140e-6, 2000e-6, 24)
    true = steady_state(TRUE, velocity).stress
    rng = np.random.default_rng(7)
    estimates = np.array(
        [local_scatter(velocity, true * np.exp(0.02 * rng.standard_normal(24)), None).variance for _ in range(400)]
    )
    dof = local_scatter(velocity, true, None).dof
    assert 10 < dof < 13  # (n - 2)/1.9 for even spacing in ln V
    assert np.mean(estimates) / 0.02**2 == pytest.approx(1.0, abs=0.06)  # 400 draws: sd of the mean 0.02
    assert np.var(estimates) / np.mean(estimates) ** 2 == pytest.approx(2 / dof, rel=0.25)


def test_a_factor_of_three_is_a_velocity_dependence_flat_noise_is_not():
    u = hand_made_u_curve()
    assert velocity_dependence(u, None, local_scatter(WIDE, u, None)).significant
    flat = 400.0 * np.exp(0.02 * np.random.default_rng(2).standard_normal(WIDE.size))
    assert not velocity_dependence(flat, None, local_scatter(WIDE, flat, None)).significant


# --------------------------------------------------------------------------- curves the model cannot follow


def test_the_u_curve_fails_with_the_misfit_of_the_best_basin():
    """Issue 27 item 8: "no significant velocity dependence (p = 1)"; the fit had ended at 107 Pa where the data
    say 488.  Now the misfit of the best fit found, against the noise between neighbours.  The local fit from
    gelatin-glass ends at an rms misfit of 33 %; an independent dense multi-start (lmfit from the 8 best of 2048
    Sobol points, during development) found 16 %: the search must reach that basin."""
    stress = hand_made_u_curve()
    fit = fit_steady(SteadyData.from_arrays(WIDE, stress, None), method="joint")
    assert fit.status == "failed"
    assert "no significant velocity dependence" not in fit.reason
    assert "the model does not describe these data" in fit.reason and "global search" in fit.reason
    rms, rms_pa = _misfit_numbers(fit.reason)
    assert rms < 0.2
    # the quoted misfit is that of a curve of the model: recomputed from the fitted parameters it is no smaller
    model = steady_state(fit.parameters, WIDE).stress
    assert np.sqrt(np.mean(((stress - model) / stress) ** 2)) >= rms * 0.999
    assert rms_pa > 10 * local_scatter(WIDE, stress, None).scale * np.mean(stress)
    assert fit.critical_velocity.value is None and all(e.interval is None for e in fit.estimates)


def test_cli_power_law_fails_with_exit_3_and_writes_no_parameters(tmp_path, capsys):
    """A monotone power law (issue 27 item 8) with the default two-step method: exit 3, the misfit, no -o."""
    path = tmp_path / "power.csv"
    rows = zip(WIDE * 1e6, power_law(), strict=True)
    path.write_text("velocity [um/s],stress [Pa]\n" + "\n".join(f"{v:.9g},{s:.9g}" for v, s in rows) + "\n")
    out_toml = tmp_path / "fitted.toml"
    code, out, err = run_main(capsys, "fit", "steady", str(path), "--json", "-o", str(out_toml))
    assert code == 3 and not out_toml.exists()
    assert "fit failed: the model does not describe these data" in err and "not written" in err
    assert "no significant velocity dependence" not in err
    document = json.loads(out)
    assert document["status"] == "failed" and "nan" not in out.lower() and "inf" not in out.lower()


def test_joint_fit_of_a_decreasing_curve_with_stated_errors_fails():
    """Issue 29: status ok with chi2_r 771.7 and residuals up to 66 sigma."""
    stress = power_law()
    fit = fit_steady(SteadyData.from_arrays(WIDE, stress, 0.01 * stress), method="joint")
    assert fit.status == "failed" and "does not describe these data" in fit.reason
    # round 30: the keys the data leave open held at the global search's values, no longer put back at the input's:
    # χ²ᵣ 28.7 (was > 100), still p ~ 1e-90 against the stated 1 % errors
    assert fit.chi_square / fit.dof > 10


# --------------------------------------------------------------------------- curves the model can follow


def test_a_model_curve_far_from_the_start_is_found_by_the_global_search():
    """Known truth: gelatin-glass with N0 x 2.5, tau / 5, lambda / 22, tau_a / 27, Va x 8 and 2 % noise, 20 um/s
    to 5 mm/s.  The fit from gelatin-glass ends far off; after the global search Vc is inside its interval."""
    factors = np.exp([0.9, -1.6, -3.1, -3.3, 2.1])
    keys = ("bonds.site_density", "bonds.bond_time", "bonds.activation_length", "aging.aging_time",
            "aging.aging_velocity")  # fmt: skip
    truth = TRUE.with_overrides({k: TRUE.as_dict()[k] * f for k, f in zip(keys, factors, strict=True)})
    point = critical_point(truth)
    velocity = np.geomspace(20e-6, 5000e-6, 24)
    stress = steady_state(truth, velocity).stress * (1 + 0.02 * np.random.default_rng(0).standard_normal(24))
    fit = fit_steady(SteadyData.from_arrays(velocity, stress, None), method="joint", intervals="delta")
    assert fit.status == "ok", fit.reason
    assert any("whole search box was scanned" in m for m in fit.messages)
    lo, hi = fit.critical_velocity.interval
    assert lo <= point.velocity <= hi
    assert 0.01 < fit.noise_scale < 0.03


# --------------------------------------------------------------------------- nothing to fit: fail at once


@pytest.mark.parametrize("kind", ["constant", "noise"])
def test_joint_fit_of_data_without_velocity_dependence_fails_before_fitting(kind):
    """Issue 29: 31 s on a constant stress and 92 s on pure noise before "fit failed"; now no fit is run."""
    rng = np.random.default_rng(4)
    velocity = np.geomspace(140e-6, 2000e-6, 24)
    stress = np.full(24, 400.0) if kind == "constant" else rng.uniform(100.0, 1000.0, 24)
    fit = fit_steady(SteadyData.from_arrays(velocity, stress, None), method="joint")
    assert fit.status == "failed" and "no significant velocity dependence" in fit.reason
    assert fit.stages == () and fit.free_keys == ()
    assert "between neighbouring points" in fit.reason
    assert "no model fitted" in fit.report()
    assert np.allclose(fit.curve(velocity[:3]), fit.model_stress[0])
