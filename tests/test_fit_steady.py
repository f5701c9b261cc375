"""Steady fit: identifiability, recovery of known parameters, coverage of the intervals, Bayesian option."""

from __future__ import annotations

import json
import math
import sys

import numpy as np
import pytest
from scipy import stats

from stickslip.cli.common import json_safe
from stickslip.errors import DataError, ParameterError
from stickslip.fitting import SteadyData, datasets, fit_steady, identify, read_steady_data
from stickslip.fitting.batch import stress_many
from stickslip.fitting.critical_uncertainty import Profile, critical_gradient, critical_many
from stickslip.fitting.problem import Block, Space
from stickslip.parameters import load_parameters, replace
from stickslip.quasistatic.critical import critical_point
from stickslip.quasistatic.steady import steady_state

TRUE = load_parameters("gelatin-glass")
VC_TRUE, SC_TRUE = 124.097e-6, 257.359  # contracts.md: Vc = 124.097 um/s, sigma_c = 257.359 Pa
PAPER_RANGE = np.geomspace(140e-6, 2000e-6, 24)


@pytest.fixture(scope="module")
def synthetic() -> SteadyData:
    return read_steady_data(datasets.synthetic_steady_path())


@pytest.fixture(scope="module")
def two_step(synthetic):
    return fit_steady(synthetic, method="two-step")  # auto reports the joint fit (round 27)


def noisy(seed: int, relative: float = 0.02, velocity: np.ndarray = PAPER_RANGE, stated: bool = True) -> SteadyData:
    true = steady_state(TRUE, velocity).stress
    rng = np.random.default_rng(seed)
    stress = true * (1 + relative * rng.standard_normal(velocity.size))
    return SteadyData.from_arrays(velocity, stress, relative * true if stated else None)


# --------------------------------------------------------------------------- what sigma(V) depends on


def test_exact_scale_degeneracy():
    """docs/fitting.md: dl_m, tau, tau_a -> s x and lambda M/kT, M N0 -> x/s leave sigma(V) unchanged."""
    s = 3.7
    b = TRUE.bonds
    scaled = replace(
        TRUE,
        bonds={
            "max_extension": b.max_extension * s,
            "bond_time": b.bond_time * s,
            "activation_length": b.activation_length / s,
            "site_density": b.site_density / s,
        },
        aging={"aging_time": TRUE.aging.aging_time * s},
    )
    v = np.geomspace(20e-6, 5e-3, 9)
    assert np.allclose(steady_state(scaled, v).stress, steady_state(TRUE, v).stress, rtol=1e-9, atol=0)


def test_null_space_of_the_exponent_matrix_leaves_sigma_unchanged():
    """Every direction the combinations cannot see is invisible to the model too, and each combination is seen."""
    keys = list(identify.STEADY_KEYS)
    matrix = identify.exponent_matrix(keys)
    assert np.linalg.matrix_rank(matrix) == 6
    _, _, vt = np.linalg.svd(matrix)
    v = np.geomspace(50e-6, 3e-3, 7)
    base = steady_state(TRUE, v).stress
    space = Space(TRUE, tuple(keys))
    theta = space.vector()
    for direction in vt[6:]:  # the 3-dimensional null space
        moved = steady_state(space.params(theta + 0.4 * direction), v).stress
        assert np.allclose(moved, base, rtol=1e-9, atol=0)
    for direction in vt[:6]:
        moved = steady_state(space.params(theta + 0.4 * direction), v).stress
        assert np.max(np.abs(moved / base - 1)) > 1e-3


def test_combination_values_are_the_papers_groups():
    values = {c.name: c.value(TRUE) for c in identify.COMBINATIONS}
    b = TRUE.bonds
    assert values["stress_scale"] == pytest.approx(b.chain_stiffness * b.site_density * b.max_extension)
    assert values["fene_strength"] == pytest.approx(b.stretch_sensitivity * b.max_extension, rel=1e-12)
    assert values["velocity_scale"] == pytest.approx(1.074e-6 / 224e-6)


def test_structural_selection_drops_degenerate_keys_with_a_message():
    default = identify.select_identifiable(identify.DEFAULT_FREE)
    assert default.free == identify.DEFAULT_FREE and not default.messages
    chosen = identify.select_identifiable(["bonds.max_extension", *identify.DEFAULT_FREE])
    assert chosen.free[0] == "bonds.max_extension" and len(chosen.free) == 5
    assert len(chosen.dropped) == 1 and "not separately identifiable" in chosen.messages[0]
    no_aging = identify.select_identifiable(
        ["bonds.max_extension", "bonds.site_density", "bonds.bond_time", "bonds.activation_length"], aging=False
    )
    assert no_aging.dropped == ("bonds.activation_length",)


def test_near_eyring_limit_above_200_um_s():
    """docs/fitting.md: along a -> infinity with N0/lambda, tau*lambda, tau_a*lambda fixed, sigma changes by
    about 1 % above 200 um/s but strongly at 140 um/s: only the lowest velocities see the FENE strength."""
    v = np.array([140e-6, 300e-6, 1e-3, 2e-3])
    base = steady_state(TRUE, v).stress
    out = []
    for m in (10.0, 100.0):
        b = TRUE.bonds
        q = replace(
            TRUE,
            bonds={
                "activation_length": b.activation_length * m,
                "site_density": b.site_density * m,
                "bond_time": b.bond_time / m,
            },
            aging={"aging_time": TRUE.aging.aging_time / m},
        )
        out.append(steady_state(q, v).stress / base - 1)
    assert np.all(np.abs(out[0][1:]) < 0.015) and np.all(np.abs(out[1][1:]) < 0.015)
    assert np.all(np.abs(out[1][1:] - out[0][1:]) < 1e-3)  # converged: the limit
    assert out[0][0] > 0.3


# --------------------------------------------------------------------------- building blocks against independent routes


def test_stress_many_equals_steady_state():
    rng = np.random.default_rng(0)
    sets = [
        replace(
            TRUE,
            bonds={"bond_time": 224e-6 * math.exp(0.2 * rng.standard_normal())},
            aging={"aging_velocity": 360e-6 * math.exp(0.3 * rng.standard_normal())},
        )
        for _ in range(5)
    ]
    sets.append(replace(TRUE, bonds={"activation_length": 2e-10}))  # another FENE strength in the same batch
    got = stress_many(sets, PAPER_RANGE)
    expected = np.array([steady_state(p, PAPER_RANGE).stress for p in sets])
    assert np.allclose(got, expected, rtol=1e-12, atol=0)
    # a set without a finite stress (lambda = 0) gives a NaN row, the others are untouched
    with_bad = stress_many([sets[0], replace(TRUE, bonds={"activation_length": 0.0})], PAPER_RANGE)
    assert np.allclose(with_bad[0], expected[0], rtol=1e-12, atol=0) and np.all(np.isnan(with_bad[1]))


def test_critical_many_agrees_with_the_global_search():
    sets = [replace(TRUE, aging={"aging_velocity": va}) for va in (250e-6, 360e-6, 500e-6)]
    got = critical_many(sets, VC_TRUE)
    for p, (vc, sc) in zip(sets, got, strict=True):
        point = critical_point(p)
        assert vc == pytest.approx(point.velocity, rel=1e-8)
        assert sc == pytest.approx(point.stress, rel=1e-9)  # the quadrature is accurate to ~1e-10


def test_delta_gradient_matches_differences_of_critical_point(two_step):
    """The implicit-function gradient of (ln Vc, ln sigma_c) against brute-force differences of the global search."""
    space = Space(two_step.parameters, two_step.free_keys)
    theta = space.vector()
    grad_v, grad_s = critical_gradient(space, theta, two_step.critical_velocity.value)
    h = 1e-3
    for k in range(theta.size):
        step = np.zeros_like(theta)
        step[k] = h
        up, down = critical_point(space.params(theta + step)), critical_point(space.params(theta - step))
        assert (math.log(up.velocity / down.velocity) / (2 * h)) == pytest.approx(grad_v[k], rel=2e-3, abs=1e-5)
        assert (math.log(up.stress / down.stress) / (2 * h)) == pytest.approx(grad_s[k], rel=2e-3, abs=1e-5)


# --------------------------------------------------------------------------- the fit


def test_recovery_of_known_parameters_with_small_noise():
    """0.1 % noise: all five default keys are determined (the FENE strength too) and recovered from a
    perturbed start; Vc to better than 1 %."""
    data = noisy(11, relative=0.001)
    start = TRUE.with_overrides(
        {
            "bonds.site_density": 1.22e14 * 1.3,
            "bonds.bond_time": 224e-6 * 0.8,
            "bonds.activation_length": 1.2e-10,
            "aging.aging_time": 899e-6 * 1.2,
            "aging.aging_velocity": 360e-6 * 0.8,
        }
    )
    fit = fit_steady(data, params=start, method="joint", intervals="delta")
    assert fit.free_keys == identify.DEFAULT_FREE
    truth = TRUE.as_dict()
    for e in fit.estimates:
        if not e.fixed:
            assert abs(e.value - truth[e.key]) < 3 * e.stderr, e.key
            assert e.stderr < 0.2 * e.value
    assert abs(fit.critical_velocity.value / VC_TRUE - 1) < 0.01
    assert abs(fit.critical_velocity.value - VC_TRUE) < 3 * fit.critical_velocity.stderr
    assert abs(fit.critical_stress.value - SC_TRUE) < 3 * fit.critical_stress.stderr
    assert 0.3 < fit.reduced_chi_square < 2.0


def test_two_step_coverage_of_vc_and_sigma_c_over_seeds():
    """The default fit (two-step, delta method) on 40 synthetic data sets, 24 points, 2 % stated noise:
    the 95 % intervals must contain the truth at a rate compatible with 95 %, and the reported standard
    errors must match the actual scatter of the estimates across seeds."""
    n = 40
    hits = np.zeros(2, dtype=int)
    log_vc, se_vc, log_sc, se_sc = [], [], [], []
    for seed in range(n):
        fit = fit_steady(noisy(5000 + seed))
        vc, sc = fit.critical_velocity, fit.critical_stress
        hits += [vc.interval[0] < VC_TRUE < vc.interval[1], sc.interval[0] < SC_TRUE < sc.interval[1]]
        log_vc.append(math.log(vc.value))
        se_vc.append(vc.stderr / vc.value)
        log_sc.append(math.log(sc.value))
        se_sc.append(sc.stderr / sc.value)
    lowest = stats.binom.ppf(0.001, n, 0.95)  # P(hits < lowest | 95 % coverage) < 0.1 %
    assert hits[0] >= lowest and hits[1] >= lowest, hits
    for values, errors in ((log_vc, se_vc), (log_sc, se_sc)):
        ratio = float(np.mean(errors)) / float(np.std(values, ddof=1))
        assert 0.7 < ratio < 1.4, ratio


def test_estimated_noise_uses_t_quantiles_and_reports_the_noise():
    fit = fit_steady(noisy(3, stated=False), method="two-step")  # Wald intervals (auto: profile, round 27)
    assert "estimated from the scatter" in fit.noise
    assert 0.012 < fit.noise_scale < 0.03
    e = fit.estimate("aging.aging_velocity")
    half = math.log(e.interval[1] / e.value) / (e.stderr / e.value)
    assert half == pytest.approx(stats.t.ppf(0.975, fit.dof), rel=1e-9)


def test_undetermined_activation_length_is_fixed_with_a_message(two_step):
    lam = two_step.estimate("bonds.activation_length")
    assert lam.fixed and "not determined" in lam.note
    assert any("bonds.activation_length (λ) is not determined" in m for m in two_step.messages)
    assert "bonds.activation_length" not in two_step.free_keys
    assert any("Δl_m and τ are not separately identifiable" in m for m in two_step.messages)
    for key in ("bonds.max_extension", "bonds.breakage_weight", "bonds.chain_stiffness"):
        assert two_step.estimate(key).fixed


def test_freeing_a_degenerate_key_changes_nothing_but_which_key_is_fixed(synthetic, two_step):
    """Asking for dl_m: lambda becomes structurally redundant (exact degeneracy) and dl_m itself is then the
    undetermined FENE direction (in the Eyring limit N0 kT/lambda and kT/(lambda M tau) do not contain it);
    the model space, hence the best chi-square and Vc, is the default's."""
    fit = fit_steady(synthetic, free=["bonds.max_extension"], method="two-step")
    assert any("bonds.activation_length (λ) is not separately identifiable" in m for m in fit.messages)
    assert any("bonds.max_extension (Δl_m) is not determined" in m for m in fit.messages)
    assert fit.chi_square == pytest.approx(two_step.chi_square, rel=1e-5)
    assert fit.critical_velocity.value == pytest.approx(two_step.critical_velocity.value, rel=1e-4)


def test_a_determined_free_key_is_fitted(synthetic):
    """u0 on request: u0 and dl_m/tau enter sigma(V) separately (T = u0 c/V, birth = V/c), so it is fitted
    or declared undetermined, never silently dropped."""
    fit = fit_steady(synthetic, free=["bonds.breakage_weight"], method="joint", intervals="delta")
    u0 = fit.estimate("bonds.breakage_weight")
    assert (not u0.fixed) or "not determined" in u0.note


def test_fix_by_request(synthetic):
    fit = fit_steady(synthetic, fix={"bonds.bond_time": "200 us", "aging.aging_velocity": 4e-4})
    tau = fit.estimate("bonds.bond_time")
    assert tau.fixed and tau.value == pytest.approx(200e-6) and tau.note == "fixed by request"
    assert fit.parameters.aging.aging_velocity == 4e-4
    assert fit.as_dict()["parameters"]["bonds.bond_time"] == {
        "value": tau.value,
        "fixed": True,
        "reason": "fixed by request",
    }


def test_aging_neglect_warning_of_the_two_step_method(two_step):
    assert any("step 1 neglects aging above the split" in m for m in two_step.messages)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"free": ["stick.break_rate"]}, ParameterError, "does not depend on it"),
        ({"free": ["bonds.nonsense"]}, ParameterError, "unknown parameter key"),
        (
            {"fix": {"bonds.bond_time": 1e-4}, "free": ["bonds.bond_time"]},
            ParameterError,
            "both to --fix and to --free",
        ),
        ({"fix": {"bonds.bond_time": "3 m"}}, ParameterError, "bonds.bond_time"),
        ({"method": "three-step"}, ParameterError, "method"),
        ({"intervals": "guess"}, ParameterError, "intervals"),
        ({"level": 1.5}, ParameterError, "level"),
        ({"intervals": "profile", "method": "two-step"}, ParameterError, "needs --method joint"),
        ({"split": 1.5e-3}, DataError, "need more points than parameters"),
        ({"split": 1e-2}, DataError, "no data point at or above the split"),
    ],
)
def test_bad_requests(synthetic, kwargs, error, match):
    with pytest.raises(error, match=match):
        fit_steady(synthetic, **kwargs)


def test_fitted_parameters_reproduce_the_fitted_curve(tmp_path, two_step, synthetic):
    # the fit evaluates its model on the compiled march, which agrees with steady_state's numpy march to the
    # quadrature's rounding (docs/steady-state.md: 2.3e-12 at most)
    curve = steady_state(two_step.parameters, synthetic.velocity).stress
    assert np.allclose(curve, two_step.model_stress, rtol=1e-10, atol=0.0)
    path = tmp_path / "fitted.toml"
    path.write_text(two_step.parameters.to_toml())
    again = load_parameters(str(path))
    assert np.array_equal(steady_state(again, synthetic.velocity).stress, curve)  # the file holds every digit
    z = (synthetic.stress - two_step.model_stress) / synthetic.stress_err
    assert np.allclose(z, two_step.residuals)
    assert stats.chi2.sf(float(z @ z), two_step.dof) > 0.01  # the curve goes through the data


def test_json_summary(two_step):
    out = json.loads(json.dumps(json_safe(two_step.as_dict())))
    for name in ("critical_velocity", "critical_stress"):
        assert set(out[name]) >= {"value", "stderr", "interval"}
        lo, hi = out[name]["interval"]
        assert lo < out[name]["value"] < hi
    assert out["parameters"]["bonds.site_density"].keys() >= {"value", "stderr", "interval"}
    assert out["parameters"]["bonds.max_extension"]["fixed"] is True
    assert out["reduced_chi_square"] == pytest.approx(two_step.chi_square / two_step.dof)
    assert len(out["correlation"]["matrix"]) == len(two_step.free_keys)
    assert np.allclose(np.diag(two_step.correlation), 1.0)


def test_report_plot_and_frame(two_step):
    text = two_step.report()
    for heading in ("## Critical point", "## Parameters", "## Identifiable combinations", "## Residuals", "µm/s"):
        assert heading in text
    ax = two_step.plot()
    assert ax.get_xscale() == "log" and len(ax.lines) >= 2
    frame = two_step.to_frame()
    assert list(frame.columns[-2:]) == ["model_stress", "residual"] and len(frame) == 24


# --------------------------------------------------------------------------- other interval methods


def test_profile_intervals_are_where_the_constrained_chi_square_crosses_the_threshold(synthetic):
    fit = fit_steady(synthetic, method="joint")  # joint: profile likelihood by default
    vc = fit.critical_velocity
    assert fit.interval_method == "profile" and vc.interval[0] < vc.value < vc.interval[1]
    block = Block(synthetic.velocity, synthetic.stress, synthetic.stress_err, aging=True)
    space = Space(fit.parameters, fit.free_keys)
    profile = Profile(space, block, Space(fit.start, fit.free_keys).vector())
    best = profile.data_chi_square(space.vector())
    for end in vc.interval:
        chi, x = profile.chi_square_at_velocity(math.log(end), space.vector())
        # the constrained curve really has its minimum there (independent global search; the weighted
        # constraint holds to ~3e-4) ...
        assert critical_point(space.params(x)).velocity == pytest.approx(end, rel=1e-3)
        # ... and is worse than the best by the 95 % chi-square quantile (1 dof, stated errors)
        assert chi - best == pytest.approx(stats.chi2.ppf(0.95, 1), rel=0.06)


def test_bootstrap_intervals(synthetic):
    fit = fit_steady(synthetic, intervals="bootstrap", bootstrap_samples=20, seed=4)
    vc = fit.critical_velocity
    assert vc.interval[0] < vc.value < vc.interval[1]
    assert fit.samples["critical_velocity"].size >= 18
    delta = fit_steady(synthetic).critical_velocity
    assert 0.4 < vc.stderr / delta.stderr < 2.5


# --------------------------------------------------------------------------- Bayesian option


def test_posterior_agrees_with_the_least_squares_fit(two_step):
    from stickslip.fitting.bayes import sample_posterior

    post = sample_posterior(two_step, walkers=16, seed=2, critical_draws=200)
    # the default length passes the package's own convergence check (issue 9)
    assert not any("autocorrelation times" in m for m in post.messages)
    assert post.steps - post.burn >= 50 * np.max(post.autocorrelation)
    assert post.chain.shape[1] == len(two_step.free_keys)
    assert any("uniform in ln" in p for p in post.priors)
    vc = post.critical_velocity
    delta = two_step.critical_velocity
    assert abs(vc.value - delta.value) < 1.5 * delta.stderr
    assert 0.5 < vc.stderr / delta.stderr < 2.0
    v, lo, hi = post.stress_band(draws=40)
    assert np.all(lo <= hi)
    inside = (two_step.curve(v) >= lo) & (two_step.curve(v) <= hi)
    assert inside.mean() > 0.9
    fig = __import__("stickslip.plots.fits", fromlist=["corner_figure"]).corner_figure(post)
    assert len(fig.axes) == (len(two_step.free_keys) + 2) ** 2
    labels = {ax.get_xlabel() for ax in fig.axes} - {""}
    assert {"τ (µs)", "Vc (µm/s)", "σc (Pa)"} <= labels  # human units, not log10 of SI values


def test_missing_emcee_gives_a_one_line_instruction(monkeypatch, two_step):
    from stickslip.fitting import bayes

    monkeypatch.setitem(sys.modules, "emcee", None)
    with pytest.raises(bayes.BayesUnavailable, match=r"pip install stickslip\[bayes\]"):
        bayes.sample_posterior(two_step, walkers=8, steps=10)


# --------------------------------------------------------------------------- long records (issue 12)


def test_compressed_block_gives_the_exact_chi_square_and_jacobian():
    """A long record is fitted through Chebyshev interpolation at nodes and a Cholesky compression; the
    chi-square and J^T J of the compressed problem equal those of the plain one over all points."""
    from stickslip.fitting.problem import jacobian, make_block, residuals

    data = noisy(11, velocity=np.geomspace(140e-6, 2000e-6, 1500))
    plain = Block(data.velocity, data.stress, data.stress_err, True)
    long = make_block(data.velocity, data.stress, data.stress_err, True, TRUE)
    assert long.nodes is not None and long.residual_count < 100
    keys = ("bonds.site_density", "bonds.bond_time", "aging.aging_time")
    space = Space(TRUE.with_overrides({"bonds.bond_time": 2.5e-4, "aging.aging_time": 8e-4}), keys)
    theta = space.vector()
    r_plain, r_long = residuals(space, theta, plain), residuals(space, theta, long)
    assert long.chi_square(r_long) == pytest.approx(plain.chi_square(r_plain), rel=1e-8)
    j_plain, j_long = jacobian(space, theta, plain), jacobian(space, theta, long)
    assert np.allclose(j_long.T @ j_long, j_plain.T @ j_plain, rtol=1e-7)
    assert np.allclose(j_long.T @ r_long, j_plain.T @ r_plain, rtol=1e-6)


def test_two_step_interval_is_widened_by_its_own_bias_on_a_long_record():
    """Exact data at 2000 velocities: the two-step estimate is off by its split approximation (the joint fit
    recovers the truth), far beyond the delta interval; the printed interval is widened to cover it, and
    says so.  (Issue 12: 10^5 points gave [120.85, 121.00] around a truth of 124.10.)"""
    velocity = np.geomspace(140e-6, 2000e-6, 2000)
    true = steady_state(TRUE, velocity).stress
    fit = fit_steady(SteadyData.from_arrays(velocity, true, 0.02 * true), method="two-step")
    vc = fit.critical_velocity
    assert abs(vc.value - VC_TRUE) > 3 * vc.stderr  # the method's bias (5.6 standard errors), not noise
    assert vc.interval[0] <= VC_TRUE <= vc.interval[1]
    assert vc.bias == pytest.approx(vc.value - VC_TRUE, rel=0.02)
    assert any("split approximation shifts Vc" in m for m in fit.messages)
    assert "widened" in vc.note and fit.as_dict()["critical_velocity"]["method_bias"] == vc.bias


def test_estimated_noise_does_not_print_a_reduced_chi_square():
    fit = fit_steady(noisy(5, stated=False), method="two-step")
    assert fit.reduced_chi_square is None and 0.01 < fit.as_dict()["relative_noise"] < 0.04
    assert "χ²ᵣ = 1 by construction" in fit.report()


def test_log_interval_of_an_undetermined_quantity_is_unbounded_not_an_overflow():
    from stickslip.fitting.steady_fit import _log_interval

    lo, hi = _log_interval(1e-4, 500.0, 1.96)
    assert lo >= 0.0 and hi is None
