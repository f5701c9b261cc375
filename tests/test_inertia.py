"""Issue 22 Q4: the block's mass and a viscous damping in the linear stability of the time-dependent model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip.errors import ParameterError
from stickslip.rsf import critical_stiffness as rsf_critical_stiffness
from stickslip.rsf import rsf_params
from stickslip.transient.stability import (
    SCAN,
    critical_from_response,
    critical_stiffness,
    critical_stiffness_details,
    follow_root,
    interface_response,
    real_growth_rates,
    unstable_root_count,
)

SIGMA, A, B, DC, V = 1e6, 0.01, 0.016, 10e-6, 20e-6
RATES = np.geomspace(1e-4, 1e6, 401)


def rsf_response(s: np.ndarray) -> np.ndarray:
    """Z(s) of one-state rate-and-state friction (aging law, linearised about V), in Pa/m."""
    return SIGMA * s * (A / V - B / (V + DC * s))


def test_hopf_point_with_mass_and_damping_matches_the_rsf_closed_form():
    """The generic characteristic analysis, fed RSF's Z(s), against k_c (1 + m V^2/(sigma a' Dc)) of docs/rsf.md."""
    mass, eta = 1e7, 100.0  # kg/m^2 and friction per velocity (s/m): the inertia term is a 6 % correction
    closed = SIGMA * rsf_critical_stiffness(rsf_params(A, B, DC, v_ref=V, eta=eta, mass=mass, normal_stress=SIGMA), V)
    found = critical_from_response(rsf_response, RATES, mass=mass, damping=eta * SIGMA)
    assert found.mode == "oscillatory"
    assert found.value == pytest.approx(closed, rel=1e-7)
    a_eff = A + eta * V
    assert found.rate == pytest.approx((V / DC) * math.sqrt((B - a_eff) / a_eff), rel=1e-6)  # 2 pi / period
    massless = critical_from_response(rsf_response, RATES)
    assert massless.value == pytest.approx(SIGMA * (B - A) / DC, rel=1e-7)


def test_roots_of_a_spring_mass_dashpot_are_the_quadratic_formula():
    """A Kelvin-Voigt interface Z = k + c s: m s^2 + (eta + c) s + K + k = 0 has closed-form roots."""
    k, c, mass, eta = 2e5, -900.0, 10.0, 100.0  # negative interface damping beats the dashpot: unstable pair

    def response(s: np.ndarray) -> np.ndarray:
        return k + c * s

    for stiffness in (1e5, 3e6):
        exact = np.roots([mass, eta + c, stiffness + k])
        start = complex(exact[np.argmax(exact.imag)]) * (1 + 0.01j)
        root = follow_root(response, start, stiffness, stiffness, mass, eta, steps=1)
        assert root == pytest.approx(exact[np.argmax(exact.imag)], rel=1e-9)
        assert unstable_root_count(response, stiffness, RATES, mass, eta) == 2
    assert unstable_root_count(lambda s: k + 900.0 * s, 1e5, RATES, mass, eta) == 0


GEL_MASS = 10.5  # kg/m^2: gelatin 1050 kg/m^3 x the block's 10 mm


@pytest.fixture(scope="module")
def near_vc(params):
    return critical_stiffness_details(params, 120e-6)


@pytest.fixture(scope="module")
def gel_block(params):
    return critical_stiffness_details(params, 120e-6, mass=GEL_MASS)


def test_massless_limit_is_the_papers_block(params, near_vc):
    """m = eta = 0 is the existing analysis (docs/transient.md: 1.31e8 Pa/m at 33 Hz) and its Hopf growth."""
    assert near_vc.mode == "oscillatory"
    assert near_vc.value == pytest.approx(1.31e8, rel=0.01)
    assert near_vc.rate / (2 * math.pi) == pytest.approx(33.0, rel=0.02)


def test_gel_block_mass_shifts_kc_by_m_omega_squared_and_the_count_agrees(params, near_vc, gel_block):
    """With eta = 0 the crossing frequency is unchanged and Kc grows by m w^2; the argument principle confirms it."""
    mass, heavy = GEL_MASS, gel_block
    assert heavy.rate == pytest.approx(near_vc.rate, rel=1e-9)
    assert heavy.value - near_vc.value == pytest.approx(mass * near_vc.rate**2, rel=1e-6)

    def response(s):
        return interface_response(params, 120e-6, s).z

    rates = SCAN[::8] / params.bonds.bond_time
    assert unstable_root_count(response, 0.98 * heavy.value, rates, mass) == 2
    assert unstable_root_count(response, 1.02 * heavy.value, rates, mass) == 0
    growth = follow_root(response, 1j * heavy.rate, heavy.value, 0.7 * heavy.value, mass)
    assert 12.0 < growth.real < 13.5  # the massless +12.8 1/s, barely changed


def test_mass_bounds_the_fastest_runaway_where_the_massless_block_is_ill_posed(params):
    """At 50 um/s Z(inf) < 0: the fast real root is sqrt(-(K + Z(inf))/m), diverging as m -> 0."""
    stiffness = params.block.effective_stiffness
    z_inf = interface_response(params, 50e-6, np.array([1e10])).z[0].real
    assert z_inf < -1e10
    mass = 1e-6
    fastest = real_growth_rates(params, 50e-6, stiffness, mass=mass).max()
    assert fastest == pytest.approx(math.sqrt(-(stiffness + z_inf) / mass), rel=0.02)


def test_bad_mass_or_damping_is_one_clear_error(params):
    with pytest.raises(ParameterError, match="mass: expected a non-negative"):
        critical_stiffness(params, 120e-6, mass=-1.0)
    with pytest.raises(ParameterError, match="damping: expected a non-negative"):
        critical_stiffness(params, 120e-6, damping=math.nan)


def test_cli_stability_with_a_block_mass(runner, gel_block, capsys):
    """``stickslip stability`` prints the API's Kc with the mass in SI, and refuses a negative mass in one line."""
    import json

    from cli_helpers import run, run_main

    out = json.loads(run(runner, "stability", "--v0", "120 um/s", "--mass", "10.5 kg/m^2", "--json"))
    row = out["rows"][0]
    assert out["units"]["critical_stiffness"] == "Pa/m" and row["mass"] == 10.5
    assert row["critical_stiffness"] == pytest.approx(gel_block.value, rel=1e-12)
    code, _, err = run_main(capsys, "stability", "--v0", "120 um/s", "--mass", "-1 kg/m^2")  # refused before any work
    assert code == 2 and err.count("\n") == 1 and "--mass" in err


def test_gel_block_cases_are_rho_h_and_rices_radiation_damping(params):
    """m = rho h and eta = G/(2 c_s) = sqrt(G rho)/2 for the gel (G = 4 kPa, h = 10 mm, rho = 1050 kg/m^3)."""
    from stickslip.studies.inertia import gel_block_cases

    cases = {c.label: c for c in gel_block_cases(params, density=1050.0)}
    assert cases["gel block rho h"].mass == pytest.approx(10.5, rel=1e-12)
    assert cases["1000 x rho h"].mass == pytest.approx(10500.0, rel=1e-12)
    assert cases["radiation damping G/(2 c_s)"].damping == pytest.approx(math.sqrt(4000.0 * 1050.0) / 2, rel=1e-12)
    assert cases["massless (the paper's)"].mass == cases["massless (the paper's)"].damping == 0.0
