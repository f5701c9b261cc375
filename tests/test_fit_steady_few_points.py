"""Steady fit of a few points on a curve: not "no velocity dependence" (2026-11-30, a user's hand-made curve).

The scatter between neighbouring points counts the bend of a curve between widely spaced points as noise, so ten
exact points of the model were refused as flat (p = 0.02).  Where that test finds nothing, the method's own fit
is tested against a constant (``scatter.model_dependence``); flat data and noise still fail.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from cli_helpers import run_main
from stickslip.fitting import SteadyData, fit_steady
from stickslip.fitting.scatter import local_scatter, model_dependence, velocity_dependence
from stickslip.parameters import load_parameters
from stickslip.quasistatic.critical import critical_point
from stickslip.quasistatic.steady import steady_state

TRUE = load_parameters("gelatin-glass")
#: the tester's ten points, 60 um/s to 3 mm/s, the minimum (124.1 um/s) among them
TEN = np.geomspace(60e-6, 3000e-6, 10)
#: a hand-made table: round velocities, the model's stress typed to two significant figures
HAND = np.array([20, 50, 100, 200, 400, 800, 1500, 3000]) * 1e-6


def _two_figures(values: np.ndarray) -> np.ndarray:
    return np.array([float(f"{v:.2g}") for v in values])


def test_the_neighbours_scatter_alone_calls_these_curves_flat() -> None:
    """The case this file is about: without the model's test these curves would fail (the old behaviour)."""
    for velocity, stress in (
        (TEN, steady_state(TRUE, TEN).stress),
        (HAND, _two_figures(steady_state(TRUE, HAND).stress)),
    ):
        assert not velocity_dependence(stress, None, local_scatter(velocity, stress, None)).significant


def test_ten_exact_points_fit_with_the_critical_point() -> None:
    truth = critical_point(TRUE)
    fit = fit_steady(SteadyData.from_arrays(TEN, steady_state(TRUE, TEN).stress, None))
    assert fit.status == "ok", fit.reason
    # two-step on exact data: its split approximation's bias (docs/fitting.md), a few per cent
    assert fit.critical_velocity.value == pytest.approx(truth.velocity, rel=0.03)
    assert fit.critical_stress.value == pytest.approx(truth.stress, rel=0.03)
    assert any("counts the curve's own bend" in m for m in fit.messages)
    joint = fit_steady(SteadyData.from_arrays(TEN, steady_state(TRUE, TEN).stress, None), method="joint")
    assert joint.status == "ok", joint.reason
    assert joint.critical_velocity.value == pytest.approx(truth.velocity, rel=1e-4)


@pytest.mark.parametrize("stated", [False, True])
def test_a_hand_typed_curve_fits_and_its_interval_holds_the_truth(stated: bool) -> None:
    truth = critical_point(TRUE)
    stress = _two_figures(steady_state(TRUE, HAND).stress)
    error = 0.02 * stress if stated else None
    fit = fit_steady(SteadyData.from_arrays(HAND, stress, error), method="joint")
    assert fit.status == "ok", fit.reason
    low, high = fit.critical_velocity.interval
    assert low <= truth.velocity <= high and high / low < 1.2
    assert fit.critical_velocity.value == pytest.approx(truth.velocity, rel=0.01)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_few_points_of_noise_still_fail_as_flat(seed: int) -> None:
    stress = np.random.default_rng(seed).uniform(100.0, 1000.0, TEN.size)
    fit = fit_steady(SteadyData.from_arrays(TEN, stress, None), method="joint")
    assert fit.status == "failed" and "no significant velocity dependence" in fit.reason


def test_the_model_test_is_the_f_test_of_a_nested_linear_model() -> None:
    """Known truth: a constant with Gaussian noise (stated errors 1) against a weighted least-squares quadratic
    (3 parameters, the level among them): p is uniform, so p <= 0.05 in 5 % of 4000 draws (sd 0.34 %)."""
    rng = np.random.default_rng(11)
    x = np.linspace(-1.0, 1.0, 9)
    basis = np.vander(x, 3)
    error = np.ones_like(x)
    ps = []
    for _ in range(4000):
        stress = 400.0 + rng.standard_normal(x.size)
        model = basis @ np.linalg.lstsq(basis, stress, rcond=None)[0]
        ps.append(model_dependence(stress, error, model, free=3))
    assert np.mean(np.asarray(ps) <= 0.05) == pytest.approx(0.05, abs=0.012)
    assert stats.kstest(ps, "uniform").pvalue > 1e-3


def test_the_model_test_has_nothing_to_say_without_residual_freedom() -> None:
    stress = np.array([300.0, 280.0, 350.0])
    assert model_dependence(stress, None, stress, free=3) == 1.0  # the fit interpolates: no noise left to measure
    assert model_dependence(stress, None, np.full(3, 310.0), free=1) == 1.0  # a constant against itself


def test_cli_fits_the_curve_command_s_own_ten_points(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """The chain `curve --format csv -o c.csv && fit steady c.csv` at ten points (exit 3 before)."""
    path = tmp_path / "c10.csv"
    code, _, err = run_main(
        capsys, "curve", "--vmin", "60 um/s", "--vmax", "3 mm/s", "--points", "10", "--format", "csv", "-o", str(path)
    )
    assert code == 0, err
    code, out, err = run_main(capsys, "fit", "steady", str(path))
    assert code == 0, err
    assert "no significant velocity dependence" not in out + err


def test_a_failed_profile_falls_back_to_the_delta_method_itself(monkeypatch: pytest.MonkeyPatch) -> None:
    """The tester's curve12: the fallback said "delta-method interval" but gave the search's floor, σc's standard
    error exactly 1e-3 σc, against 3.1e-11 Pa from the delta method on these exact data."""
    from stickslip.fitting import critical_uncertainty

    velocity = np.geomspace(10e-6, 10e-3, 12)
    data = SteadyData.from_arrays(velocity, steady_state(TRUE, velocity).stress, None)
    delta = fit_steady(data, method="joint", intervals="delta")
    monkeypatch.setattr(
        critical_uncertainty.Profile, "end", lambda *a, **k: critical_uncertainty.ProfileEnd(None, 1, False)
    )
    fallen = fit_steady(data, method="joint", intervals="profile")
    for got, want in (
        (fallen.critical_velocity, delta.critical_velocity),
        (fallen.critical_stress, delta.critical_stress),
    ):
        assert "the profile search failed, so the delta-method interval is given instead" in got.note
        assert got.stderr < 1e-6 * got.value  # not the search's floor, 1e-3 of the value
        assert got.stderr == pytest.approx(want.stderr, rel=0.6)  # the same method, its covariance refitted
