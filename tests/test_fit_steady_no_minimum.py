"""Steady fit of a curve with no minimum in its data, few-point wording, and repeated velocities (2026-12, tester A).

1. Six points rising 3.6-fold from 200 µm/s to 8 mm/s (no minimum in the data) gave, depending only on the start
   values (``--set``), Vc = 173.8 µm/s [154, 190.9], 186.7 [177.6, 195.1], 36.7 [21.4, 49.2] (all "ok") or "no
   significant velocity dependence" (exit 3).  The verdict on the velocity dependence now comes from the data alone
   (a polynomial trend in ln V besides the neighbours' scatter), and Vc, σc of such a curve are "not determined".
2. A 12-point noisy model curve spanning 40x was said to show "no velocity dependence" before "the model's fit
   does".
3. Repeated velocities were refused; each row is now a point, and the replicates measure the noise.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from cli_helpers import run_main
from stickslip.fitting import SteadyData, fit_steady
from stickslip.fitting.data import read_steady_data
from stickslip.fitting.scatter import (
    local_scatter,
    misfit_p_value,
    replicate_dependence,
    replicate_scatter,
    residual_scatter,
    trend_dependence,
    velocity_dependence,
)
from stickslip.parameters import load_parameters
from stickslip.quasistatic.critical import critical_point
from stickslip.quasistatic.steady import steady_state

TRUE = load_parameters("gelatin-glass")
VC = critical_point(TRUE).velocity  # 124.097 µm/s
#: the tester's curve (nomin.csv): mm/s and kPa, rising throughout
NOMIN_V = np.array([0.2, 0.5, 1.0, 2.0, 4.0, 8.0]) * 1e-3
NOMIN_S = np.array([0.26, 0.39, 0.55, 0.75, 0.93, 0.95]) * 1e3


def _write(path, velocity, stress, header="velocity [m/s],stress [Pa]"):  # type: ignore[no-untyped-def]
    path.write_text(header + "\n" + "\n".join(f"{v:.9g},{s:.9g}" for v, s in zip(velocity, stress, strict=True)))
    return path


# --------------------------------------------------------------------------- 1a: the data-only verdict


def test_the_trend_test_is_the_f_test_of_a_regression_line() -> None:
    """Closed form: with one degree the trend test is the t test of a straight line in ln V (scipy's linregress)."""
    rng = np.random.default_rng(3)
    velocity = np.geomspace(1e-5, 1e-2, 9)
    stress = 300.0 * np.exp(0.02 * np.log(velocity / 1e-4) + 0.03 * rng.standard_normal(9))
    import stickslip.fitting.scatter as scatter

    original = scatter.TREND_DEGREE
    try:
        scatter.TREND_DEGREE = 1
        got = trend_dependence(velocity, stress, None)
    finally:
        scatter.TREND_DEGREE = original
    assert got.degree == 1 and got.degrees == 1
    assert got.p_value == pytest.approx(stats.linregress(np.log(velocity), np.log(stress)).pvalue, rel=1e-6)


def test_the_trend_test_keeps_its_size_on_a_constant() -> None:
    """A constant with Gaussian noise in ln σ: the Bonferroni-corrected p is at most uniform (≤ 5 % of the draws
    at 0.05, and not far below: the three nested tests are strongly correlated)."""
    rng = np.random.default_rng(7)
    velocity = np.geomspace(30e-6, 3e-3, 8)
    ps = np.array([trend_dependence(velocity, 500.0 * np.exp(0.02 * rng.standard_normal(8)), None).p_value
                   for _ in range(2000)])  # fmt: skip
    assert 0.02 < np.mean(ps <= 0.05) <= 0.05 + 3 * math.sqrt(0.05 * 0.95 / 2000)


def test_a_curve_rising_throughout_is_a_velocity_dependence_from_the_data_alone() -> None:
    """The neighbours' scatter counts its bend as noise (p ≈ 0.004, not significant); the trend sees it."""
    scatter = local_scatter(NOMIN_V, NOMIN_S, None)
    alone = velocity_dependence(NOMIN_S, None, scatter)
    assert not alone.significant
    dependence = velocity_dependence(NOMIN_S, None, scatter, NOMIN_V)
    assert dependence.significant and dependence.p_value < 1e-3
    assert "polynomial in ln V" in dependence.text


@pytest.mark.parametrize(
    ("start", "stated"),
    [
        ({"aging.aging_velocity": 1e-3, "bonds.activation_length": 50e-12}, False),
        ({"aging.aging_velocity": 100e-6, "bonds.activation_length": 50e-12}, False),  # was "no velocity dependence"
        ({}, True),  # 2 % stated errors: only λ held, 1 degree of freedom left with it fitted too
    ],
)
def test_the_verdict_does_not_depend_on_the_start(start: dict[str, float], stated: bool) -> None:
    data = SteadyData.from_arrays(NOMIN_V, NOMIN_S, 0.02 * NOMIN_S if stated else None)
    fit = fit_steady(data, params=TRUE.with_overrides(start))
    assert fit.status == "ok", fit.reason
    # 1b: the data hold no minimum, and what puts the fitted one where it is was held at its start value
    for estimate in (fit.critical_velocity, fit.critical_stress):
        assert estimate.value is None and estimate.interval is None and estimate.status == "undetermined"
        assert estimate.note.startswith("not determined by the data")
    assert any("Vc and σc are not determined by the data" in m for m in fit.messages)


def test_cli_says_vc_is_not_determined_and_exits_0(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """Before: `Vc 173.811 ± 5.8 [154, 190.9] µm/s`, status ok, no warning.  The curve itself fits (exit 0, -o
    written); Vc and σc have no value, the report and stderr say why."""
    path = _write(tmp_path / "nomin.csv", NOMIN_V * 1e3, NOMIN_S / 1e3, "velocity (mm/s),stress (kPa)")
    code, out, err = run_main(capsys, "fit", "steady", str(path), "-o", str(tmp_path / "fitted.toml"))
    assert code == 0, err
    assert "stickslip: warning: Vc and σc: not determined by the data" in err
    cells = [cell.strip() for cell in next(line for line in out.splitlines() if line.startswith("| Vc |")).split("|")]
    assert cells[2:5] == ["—", "—", "—"]  # value, standard error, interval
    assert cells[6].startswith("not determined by the data")
    assert "Vc, σc (Eq 9): not determined by the data" in (tmp_path / "fitted.toml").read_text()


def test_an_extrapolated_minimum_with_an_open_profile_keeps_only_its_bound() -> None:
    """A profile interval open below for a Vc below the data: the value is withdrawn, the one-sided bound kept."""
    from types import SimpleNamespace

    from stickslip.fitting.results import Estimate
    from stickslip.fitting.steady_fit import _pinned_by_the_data

    check = SimpleNamespace(data=SteadyData.from_arrays(NOMIN_V, NOMIN_S))
    progress = SimpleNamespace(params=TRUE, undetermined=[], messages=[])
    vc = Estimate("critical_velocity", "Vc", "velocity", 150e-6, 10e-6, (None, 190e-6), "derived", "profile likelihood")
    sc = Estimate("critical_stress", "σc", "stress", 250.0, 5.0, (240.0, 260.0), "derived", "profile likelihood")
    got_v, got_s = _pinned_by_the_data(check, progress, ["bonds.site_density"], (vc, sc), False)  # type: ignore[arg-type]
    assert got_v.value is None and got_v.interval == (None, 190e-6) and got_v.status == "undetermined"
    assert got_s.value is None and got_s.interval is None
    assert "Vc below 190 µm/s" in progress.messages[0]
    inside = Estimate("critical_velocity", "Vc", "velocity", 1e-3, 1e-4, (None, 2e-3), "derived", "profile likelihood")
    assert _pinned_by_the_data(check, progress, [], (inside, sc), False)[0] is inside  # a minimum among the data


def test_an_extrapolated_minimum_the_data_pin_keeps_its_value_and_interval() -> None:
    """The shipped synthetic curve (gelatin-glass, 140 µm/s to 2 mm/s, true Vc 124.1 µm/s below the data, λ held):
    the profile with λ fitted too is bounded, so Vc stays, and its interval holds the truth."""
    from stickslip.fitting.datasets import synthetic_steady_path

    fit = fit_steady(read_steady_data(synthetic_steady_path()))
    assert fit.status == "ok", fit.reason
    low, high = fit.critical_velocity.interval
    assert low < VC < high and high / low < 1.5


# --------------------------------------------------------------------------- 2: the wording on a good curve


def test_a_noisy_model_curve_is_not_said_to_show_no_velocity_dependence() -> None:
    velocity = np.geomspace(20e-6, 10e-3, 12)
    stress = steady_state(TRUE, velocity).stress * (1 + 0.02 * np.random.default_rng(1).standard_normal(12))
    assert stress.max() / stress.min() > 30
    fit = fit_steady(SteadyData.from_arrays(velocity, stress))
    assert fit.status == "ok", fit.reason
    assert not any("finds no velocity dependence" in m for m in fit.messages)
    low, high = fit.critical_velocity.interval
    assert low < VC < high


def test_where_only_the_model_sees_the_curve_the_note_does_not_call_the_data_flat() -> None:
    """Ten exact points of the model, 60 µm/s to 3 mm/s: the data's own tests are inconclusive (a cubic in ln V does
    not follow the minimum: p ≈ 0.008), the model's fit decides; its note said "finds no velocity dependence"."""
    velocity = np.geomspace(60e-6, 3000e-6, 10)
    fit = fit_steady(SteadyData.from_arrays(velocity, steady_state(TRUE, velocity).stress), method="joint")
    assert fit.status == "ok", fit.reason
    note = next(m for m in fit.messages if "counts the curve's own bend" in m)
    assert "no velocity dependence" not in note and "the model's fit shows the dependence" in note
    assert fit.critical_velocity.value == pytest.approx(VC, rel=1e-4)


# --------------------------------------------------------------------------- 3: repeated velocities


def test_repeated_velocities_are_read_as_points(tmp_path) -> None:  # type: ignore[no-untyped-def]
    path = _write(tmp_path / "rep.csv", [1e-4, 1e-4, 2e-4, 3e-4, 3e-4, 4e-4, 1e-4], [300, 310, 320, 330, 330, 340, 300])
    data = read_steady_data(path)
    assert len(data) == 7 and data.velocities == 4
    notes = " ".join(data.notes())
    assert "7 rows at 4 velocities" in notes
    assert "identical rows (2 and 8; 5 and 6)" in notes  # warned, not refused: they may be real replicates


def test_too_few_distinct_velocities_are_still_bad_input(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    path = _write(tmp_path / "three.csv", [1e-4, 2e-4, 2e-4, 4e-4, 4e-4], [250, 300, 310, 400, 410])
    code, _, err = run_main(capsys, "fit", "steady", str(path))
    assert code == 2
    assert "5 data rows at 3 distinct velocities, expected at least 4 velocities" in err


def test_the_scatter_of_replicates_is_the_noise() -> None:
    """Known truth: relative Gaussian noise of 2 % on a curve, three rows at each of 8 velocities.  The pure error
    (replicates alone) and the pooled scatter with the neighbours' lines (zero bend: a straight line in ln V, so
    both are unbiased) have mean variance 0.02² and relative variance 2/ν (Satterthwaite)."""
    rng = np.random.default_rng(12)
    velocity = np.repeat(np.geomspace(10e-6, 10e-3, 8), 3)
    error = rng.uniform(2.0, 6.0, velocity.size)  # stated, unequal: the weighted contrasts
    pure, pooled, stated = [], [], []
    for _ in range(2000):
        noise = rng.standard_normal(velocity.size)
        stress = 400.0 * np.exp(0.1 * np.log(velocity / 1e-4) + 0.02 * noise)
        pure.append(replicate_scatter(velocity, stress, None).variance)
        pooled.append(local_scatter(velocity, stress, None).variance)
        line = 400.0 + 30.0 * np.log(velocity / 1e-4) + error * noise
        stated.append(local_scatter(velocity, line, error).variance)
    for values, scale, got in (
        (pure, 0.02**2, replicate_scatter(velocity, stress, None)),
        (pooled, 0.02**2, local_scatter(velocity, stress, None)),
        (stated, 1.0, local_scatter(velocity, line, error)),
    ):
        assert np.mean(values) == pytest.approx(scale, rel=0.05)
        assert np.var(values) / np.mean(values) ** 2 == pytest.approx(2.0 / got.dof, rel=0.25)
    assert replicate_scatter(velocity, stress, None).dof == 16 and local_scatter(velocity, stress, None).dof > 16


def test_replicates_leave_the_misfit_p_value_uniform_under_noise() -> None:
    """Pure noise taken as residuals (rows repeated twice at 10 velocities): p ≤ 0.05 in 5 % of the sets."""
    rng = np.random.default_rng(5)
    velocity = np.repeat(np.geomspace(20e-6, 3e-3, 10), 2)
    ps = []
    for _ in range(400):
        z = rng.standard_normal(velocity.size)
        scatter = residual_scatter(velocity, 100.0 + z, np.ones(velocity.size), np.full(velocity.size, 100.0))
        ps.append(misfit_p_value(velocity, np.ones(velocity.size), float(z @ z) / z.size / scatter.variance, scatter))
    assert abs(np.mean(np.asarray(ps) <= 0.05) - 0.05) < 3 * math.sqrt(0.05 * 0.95 / 400)


def test_the_replicates_test_is_the_one_way_analysis_of_variance() -> None:
    """Closed form: equal weights (relative noise) give scipy's f_oneway on ln σ."""
    rng = np.random.default_rng(9)
    velocity = np.repeat([1e-4, 2e-4, 4e-4, 8e-4], [2, 3, 2, 4])
    stress = 300.0 * np.exp(0.03 * rng.standard_normal(velocity.size))
    groups = [np.log(stress[velocity == v]) for v in np.unique(velocity)]
    assert replicate_dependence(velocity, stress, None) == pytest.approx(stats.f_oneway(*groups).pvalue, rel=1e-9)
    assert replicate_dependence(np.geomspace(1e-4, 1e-3, 6), stress[:6], None) is None  # no replicates


def test_a_model_curve_measured_twice_at_each_velocity_fits() -> None:
    velocity = np.repeat(np.geomspace(20e-6, 10e-3, 12), 2)
    stress = steady_state(TRUE, velocity).stress * (1 + 0.02 * np.random.default_rng(3).standard_normal(24))
    fit = fit_steady(SteadyData.from_arrays(velocity, stress))
    assert fit.status == "ok", fit.reason
    low, high = fit.critical_velocity.interval
    assert low < VC < high and high / low < 1.1
    assert "12 repeated measurement(s) alone" in fit.noise
    assert 0.01 < fit.noise_scale < 0.04  # the truth: 2 %
