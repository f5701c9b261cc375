"""The steady friction curve (Eqs 6-9) against independent references.

References: the closed forms of docs/steady-state.md (section 5), an
independent ODE integration at rtol 1e-13 (tests/reference_steady.py),
central finite differences, grid convergence, and the paper's printed numbers.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from reference_steady import reference_point
from stickslip import ModelError, ParameterError, critical_point, load_parameters, steady_state
from stickslip.parameters import BOLTZMANN
from stickslip.quasistatic.steady import QuadratureSettings

GEL = load_parameters("gelatin-glass")
SPEC = 1e-6  # the issue's accuracy requirement (relative)


def rel(a, b):
    return np.max(np.abs(np.asarray(a) / np.asarray(b) - 1.0))


# --- the paper's numbers ---------------------------------------------------------------


def test_critical_point_matches_paper_and_issue():
    c = critical_point(GEL)
    assert c.exists
    # the paper prints Vc = 125 um/s, sigma_c = 259 Pa (rounded parameters: ~1 % uncertainty, errata E11)
    assert c.velocity == pytest.approx(125e-6, rel=0.01)
    assert c.stress == pytest.approx(259.0, rel=0.01)
    # the issue's own computation: 124.1 um/s and 257.4 Pa
    assert c.velocity == pytest.approx(124.1e-6, rel=5e-4)
    assert c.stress == pytest.approx(257.4, rel=5e-4)


def test_critical_point_is_a_minimum_of_the_curve():
    c = critical_point(GEL)
    around = steady_state(GEL, c.velocity * np.array([0.98, 1.0, 1.02])).stress
    assert around[1] < around[0] and around[1] < around[2]
    assert float(steady_state(GEL, c.velocity).stress) == pytest.approx(c.stress, rel=1e-8)


def test_stress_at_350_um_per_s():
    stress = float(steady_state(GEL, 350e-6).stress)
    assert stress == pytest.approx(400.0, rel=0.03)  # paper: "0.4 kPa"
    assert stress == pytest.approx(391.5, rel=2e-4)  # issue


def test_no_aging_curve_turns_over_at_a_few_mm_per_s():
    c = critical_point(GEL)
    assert 1e-3 < c.turnover_velocity < 1e-2
    v = c.turnover_velocity * np.array([0.9, 1.0, 1.1])
    s = steady_state(GEL, v, aging=False).stress
    assert s[1] > s[0] and s[1] > s[2]


def test_curve_without_minimum_says_so():
    # aging switched off in practice: V_a so small that exp(-V/V_a) vanishes from 1 nm/s on
    p = GEL.with_overrides({"aging.aging_velocity": "1e-12 m/s"})
    c = critical_point(p)
    assert not c.exists and c.velocity is None and c.stress is None
    assert "no minimum" in c.message


# --- independent high-accuracy reference over the parameter box ----------------------


def _random_case(rng):
    def log_uniform(lo, hi):
        return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))

    overrides = {
        "bonds.max_extension": log_uniform(1e-8, 1.0),
        "bonds.bond_time": log_uniform(1e-9, 1.0),
        "bonds.breakage_weight": log_uniform(0.01, 100.0),
        "bonds.activation_length": log_uniform(1e-14, 1e-7),
        "bonds.chain_stiffness": log_uniform(1e-6, 1e-1),
        "aging.aging_time": log_uniform(1e-9, 1e3),
        "aging.aging_velocity": log_uniform(1e-7, 1.0),
    }
    return GEL.with_overrides(overrides), log_uniform(5e-6, 1.0), bool(rng.integers(2))


@pytest.mark.parametrize("seed", range(8))
def test_random_parameter_box_against_reference(seed):
    rng = np.random.default_rng(1000 + seed)
    for _ in range(5):
        params, velocity, aging = _random_case(rng)
        ref_stress, ref_fraction = reference_point(params, velocity, aging)
        got = steady_state(params, velocity, aging=aging)
        assert float(got.stress) == pytest.approx(ref_stress, rel=SPEC / 10)
        assert float(got.bonded_fraction) == pytest.approx(ref_fraction, rel=SPEC / 10)


CORNERS = {
    "long chains (survival falls at x ~ 1e-6)": {"bonds.max_extension": "1 m"},
    "short chains": {"bonds.max_extension": "10 nm"},
    "fast bonds (T up to 1e5)": {"bonds.bond_time": "1 ns"},
    "slow bonds": {"bonds.bond_time": "1 s"},
    "weak new bonds": {"bonds.breakage_weight": 100.0},
    "strong new bonds": {"bonds.breakage_weight": 0.01},
    "tiny activation length (cliff at 1 - x ~ 1e-9)": {"bonds.activation_length": "1e-18 m"},
    "strong aging (two scales)": {"aging.aging_time": "1 ns", "aging.aging_velocity": "1 m/s"},
    "extreme: 1 m chains, 1 ns bonds, u0 = 100": {
        "bonds.max_extension": "1 m",
        "bonds.bond_time": "1 ns",
        "bonds.breakage_weight": 100.0,
    },
}


@pytest.mark.parametrize("name", list(CORNERS))
@pytest.mark.parametrize("aging", [True, False])
def test_corners_of_the_box_against_reference(name, aging):
    params = GEL.with_overrides(CORNERS[name])
    velocities = np.array([5e-6, 1e-4, 1e-2, 1.0])
    got = steady_state(params, velocities, aging=aging)
    for k, v in enumerate(velocities):
        ref_stress, ref_fraction = reference_point(params, float(v), aging)
        assert got.stress[k] == pytest.approx(ref_stress, rel=SPEC / 10), v
        assert got.bonded_fraction[k] == pytest.approx(ref_fraction, rel=SPEC / 10), v


@pytest.mark.parametrize("velocity", [1e-9, 1e-7, 1e-6])
def test_below_5_um_per_s_stays_correct(velocity):
    for aging in (True, False):
        ref_stress, ref_fraction = reference_point(GEL, velocity, aging)
        got = steady_state(GEL, velocity, aging=aging)
        assert float(got.stress) == pytest.approx(ref_stress, rel=SPEC / 10)
        assert float(got.bonded_fraction) == pytest.approx(ref_fraction, rel=SPEC / 10)


def test_no_nan_inf_or_warning_anywhere_in_the_box():
    """RuntimeWarnings are errors in this suite (pyproject), so overflow would fail here."""
    velocities = np.geomspace(5e-6, 1.0, 25)
    for dl in ("10 nm", "1 um", "1 m"):
        for tau in ("1 ns", "1 ms", "1 s"):
            for u0 in (0.01, 1.0, 100.0):
                for lam in ("1e-16 m", "1 angstrom", "1e-7 m"):
                    p = GEL.with_overrides(
                        {
                            "bonds.max_extension": dl,
                            "bonds.bond_time": tau,
                            "bonds.breakage_weight": u0,
                            "bonds.activation_length": lam,
                        }
                    )
                    for aging in (True, False):
                        r = steady_state(p, velocities, aging=aging)
                        for array in (r.stress, r.bonded_fraction, r.stress_slope):
                            assert np.all(np.isfinite(array))
                        assert np.all(r.stress > 0)
                        assert np.all((r.bonded_fraction > 0) & (r.bonded_fraction < 1))


# --- closed forms (docs/steady-state.md, section 5) ------------------------------------


def _alternating_series(c):
    """sum_{k>=1} (-c)^k / (k^2 k!) summed term by term, exact to the working precision.

    Its terms grow to ~e^c before they fall (1e157 at c ~ 360, V = 5 um/s), so they are summed with c/ln(10)
    more digits than the caller asks for.  mpmath.nsum gave the same sum (to 1e-39 at c ~ 360) but spent 4 s on
    its extrapolation tests; the series converges absolutely, and past k = c each term is smaller than the last,
    so stopping once one is below the sum's last digit is exact to that precision."""
    with mpmath.extradps(int(float(c) / 2.3) + 10):
        total, power, k = mpmath.mpf(0), mpmath.mpf(1), 0
        ulp = mpmath.mpf(10) ** -mpmath.mp.dps
        while True:
            k += 1
            power *= -c / k  # (-c)^k / k!
            term = power / (k * k)
            total += term
            if k > c and abs(term) <= ulp * abs(total):
                break
    return +total  # rounded to the caller's precision


def _schallamach(params, velocity, aging):
    """Section 5.2: Dl_m -> infinity, through exponential integrals (mpmath, 30 digits)."""
    mpmath.mp.dps = 30
    b_ = params.bonds
    rate = b_.breakage_weight / b_.bond_time
    growth = b_.activation_length * b_.chain_stiffness * velocity / (BOLTZMANN * b_.temperature)
    if aging:
        growth -= math.exp(-velocity / params.aging.aging_velocity) / params.aging.aging_time
    assert growth > 0
    c = mpmath.mpf(rate) / growth
    mpmath.mp.dps = 30 + int(float(c) / 2.3)  # the alternating series cancels ~c/ln(10) digits
    i_total = mpmath.exp(c) * mpmath.e1(c) / growth
    f = (mpmath.euler + mpmath.log(c)) ** 2 / 2 + mpmath.pi**2 / 12
    f += _alternating_series(c)
    j_total = mpmath.exp(c) * f / growth**2
    denominator = b_.bond_time + i_total
    stress = b_.chain_stiffness * velocity * b_.site_density * j_total / denominator
    return float(stress), float(i_total / denominator)


@pytest.mark.parametrize("velocity", [5e-6, 1e-4, 1e-2, 1.0])
def test_schallamach_limit_without_aging(velocity):
    params = GEL.with_overrides({"bonds.max_extension": "1 m"})
    stress, fraction = _schallamach(params, velocity, aging=False)
    got = steady_state(params, velocity, aging=False)
    assert float(got.stress) == pytest.approx(stress, rel=1e-8)
    assert float(got.bonded_fraction) == pytest.approx(fraction, rel=1e-8)


@pytest.mark.parametrize("velocity", [1e-3, 1e-2])
def test_schallamach_limit_with_aging(velocity):
    # b - exp(-V/V_a)/tau_a > 0 needs a slow aging rate; tau_a = 1 s here
    params = GEL.with_overrides({"bonds.max_extension": "1 m", "aging.aging_time": "1 s"})
    stress, fraction = _schallamach(params, velocity, aging=True)
    got = steady_state(params, velocity, aging=True)
    assert float(got.stress) == pytest.approx(stress, rel=1e-8)
    assert float(got.bonded_fraction) == pytest.approx(fraction, rel=1e-8)


def _fraction_without_eyring(params, velocity, aging):
    """Section 5.1: bonded fraction for lambda = 0 (mpmath, 30 digits)."""
    mpmath.mp.dps = 30
    b_ = params.bonds
    t_big = mpmath.mpf(b_.breakage_weight * b_.max_extension / (velocity * b_.bond_time))
    u0 = b_.breakage_weight
    if not aging:
        return float(-mpmath.expm1(-t_big) / (u0 - mpmath.expm1(-t_big)))
    alpha = mpmath.mpf(b_.max_extension / (velocity * params.aging.aging_time)) * mpmath.exp(
        -velocity / params.aging.aging_velocity
    )
    if alpha * t_big < 1e-25:  # aging absent to O(alpha): Ei(c) - Ei(c e^-alpha) would cancel entirely
        return float(-mpmath.expm1(-t_big) / (u0 - mpmath.expm1(-t_big)))
    c = t_big / alpha
    i = mpmath.exp(-c) / alpha * (mpmath.ei(c) - mpmath.ei(c * mpmath.exp(-alpha)))
    return float(i / (u0 / t_big + i))


@pytest.mark.parametrize("velocity", [5e-6, 1e-4, 3e-3, 1.0])
@pytest.mark.parametrize("aging", [True, False])
def test_bonded_fraction_as_activation_length_vanishes(velocity, aging):
    params = GEL.with_overrides({"bonds.activation_length": "1e-22 m"})  # a ~ 3e-12
    got = float(steady_state(params, velocity, aging=aging).bonded_fraction)
    assert got == pytest.approx(_fraction_without_eyring(params, velocity, aging), rel=1e-9)


def test_zero_activation_length_has_no_finite_stress():
    params = GEL.with_overrides({"bonds.activation_length": 0.0})
    with pytest.raises(ModelError, match="diverges"):
        steady_state(params, 1e-4)


# --- dsigma/dV and convergence -----------------------------------------------------------


@pytest.mark.parametrize("aging", [True, False])
def test_slope_against_central_differences(aging):
    v = np.array([2e-5, 1.241e-4, 4e-4, 3e-3])
    slope = steady_state(GEL, v, aging=aging).stress_slope
    errors = []
    for step in (2e-3, 1e-3):
        up = steady_state(GEL, v * math.exp(step), aging=aging).stress
        down = steady_state(GEL, v * math.exp(-step), aging=aging).stress
        central = (up - down) / (2 * step) / v  # dsigma/dlnV / V
        errors.append(np.abs(central - slope))
    scale = steady_state(GEL, v, aging=aging).stress / v
    assert np.all(errors[1] < 1e-5 * scale)
    # second-order convergence of the difference quotient towards the analytic slope
    order = np.log2(errors[0] / errors[1])
    assert np.all((order > 1.8) & (order < 2.2)), order


def test_grid_convergence_has_the_gauss_order():
    """Low-order panels narrowed 2x, 4x, 8x: the error falls as w^(2K) (observed ~5.5-6 for K = 3)."""
    v = np.array([2e-5, 1.24e-4, 3.5e-4, 2e-3])
    exact = steady_state(GEL, v).stress
    coarse = QuadratureSettings(order=3, log_hazard_step=4.0, hazard_step=4.0, end_ratio=0.5)
    errors = [rel(steady_state(GEL, v, quadrature=coarse.refined(f)).stress, exact) for f in (2, 4, 8)]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((orders > 5.0) & (orders < 7.0)), orders
    assert errors[-1] < 1e-6


def test_default_quadrature_is_converged():
    v = np.geomspace(5e-6, 1.0, 30)
    for aging in (True, False):
        default = steady_state(GEL, v, aging=aging)
        fine = steady_state(GEL, v, aging=aging, quadrature=QuadratureSettings(order=24).refined(3))
        assert rel(default.stress, fine.stress) < 1e-8  # 100x inside the issue's 1e-6
        assert rel(default.bonded_fraction, fine.bonded_fraction) < 1e-8


# --- the result object and bad input -------------------------------------------------------


def test_scalar_and_array_shapes():
    assert steady_state(GEL, 1e-4).stress.shape == ()
    r = steady_state(GEL, np.full((2, 3), 1e-4))
    assert r.stress.shape == (2, 3) and r.stress_slope.shape == (2, 3)
    frame = r.to_frame()
    assert list(frame.columns) == ["velocity", "stress", "bonded_fraction", "stress_slope"]
    assert len(frame) == 6


def test_age_distribution_obeys_eqs_6_and_7():
    v = 3.5e-4
    r = steady_state(GEL, v, distribution=True)
    ages, density = r.age_distribution(0)
    assert np.all(np.diff(ages) > 0) and np.all(np.diff(density) <= 0)  # survival only falls
    b = GEL.bonds
    newborn = b.site_density * (1 - float(r.bonded_fraction)) / b.bond_time  # Eq 7: n(0) = (N0 - N)/tau
    # Eq 6 at small age: force and aging terms vanish, so n ~ n(0) exp(-u0 t_a/tau) to O(t_a^2)
    small_age = newborn * np.exp(-b.breakage_weight * ages[0] / b.bond_time)
    assert density[0] == pytest.approx(small_age, rel=1e-3)
    spline = CubicSpline(np.concatenate([[0.0], ages]), np.concatenate([[newborn], density]))
    total = spline.integrate(0.0, ages[-1])
    assert total / b.site_density == pytest.approx(float(r.bonded_fraction), rel=1e-3)  # Eq 2
    with pytest.raises(ValueError):
        steady_state(GEL, v).age_distribution(0)


@pytest.mark.parametrize("bad", [0.0, -1e-4, float("nan"), float("inf"), "fast"])
def test_bad_velocity_is_a_parameter_error(bad):
    with pytest.raises(ParameterError, match="velocity"):
        steady_state(GEL, bad)


def test_cliff_sharper_than_double_precision_is_a_step():
    """Far outside the physical box (from a runaway naive fit): FENE and aging terms ~1e51 cancel at the cliff.

    The cliff sits at 1 - x ~ a/(2 alpha) ~ 1e-51 and is narrower than one ulp there, so the survival is a
    step; with T/alpha ~ 1e-45 its plateau is 1, and Eqs 6-7 give N/N0 = 1/(1 + u0/T) (to ~1e-40).
    """
    p = GEL.with_overrides(
        {
            "bonds.bond_time": 3.0088761528934844e41,
            "bonds.activation_length": 8.542011288442298e-56,
            "bonds.max_extension": 1.4257884827815274e39,
        }
    )
    v = np.array([1e-9, 1e-7, 1e-5])
    got = steady_state(p, v)
    t_big = p.bonds.breakage_weight * p.bonds.max_extension / (v * p.bonds.bond_time)
    assert np.allclose(got.bonded_fraction, 1 / (1 + p.bonds.breakage_weight / t_big), rtol=1e-12, atol=0)
    assert np.all(np.isfinite(got.stress)) and np.all(got.stress > 0)
