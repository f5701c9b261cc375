"""Robustness over the physical box: corners of parameter space found by fuzzing (audit a3)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip import rsf


def test_rsf_numerical_critical_stiffness_with_large_inertia_is_finite() -> None:
    # Two states (numerical route) with a mass whose correction 1 + m V^2/(sigma a Dc) ~ 1e9 put k_c above the
    # bisection's first bracket (1e9 (b - a)/Dc): it was returned as inf, and stability() then failed with
    # "stiffness: expected a finite number, got inf".  The closed form of the first state alone gives 6.9456e15.
    kw = dict(mass=88767.77, normal_stress=653131.99, stiffness=1.54e6)
    one = rsf.rsf_params(0.000101, 0.0805, 1.61e-8, **kw)
    two = rsf.rsf_params(0.000101, 0.0805, 1.61e-8, b2=1e-12, dc2=3.522e-6, **kw)
    closed = rsf.critical_stiffness(one, 0.129)
    numerical = rsf.critical_stiffness(two, 0.129)
    assert math.isfinite(numerical)
    assert numerical == pytest.approx(closed, rel=1e-5)
    report = rsf.stability(two, 0.129)
    assert not report.stable and math.isfinite(report.neutral_period)


def test_steady_state_reads_a_pint_quantity_in_its_unit() -> None:
    # np.asarray(1 um/s) is 1.0: the unit was dropped and the stress at 1 m/s (41 Pa) returned for 1 um/s.
    pint = pytest.importorskip("pint")
    from stickslip.errors import ParameterError
    from stickslip.parameters import load_parameters
    from stickslip.quasistatic.steady import steady_state

    params = load_parameters("gelatin-glass")
    ureg = pint.UnitRegistry()  # a user's own registry, not the package's
    one = steady_state(params, ureg.Quantity(1.0, "um/s")).stress  # (pint's factor may round differently)
    assert one == pytest.approx(steady_state(params, 1e-6).stress, rel=1e-9)
    both = steady_state(params, ureg.Quantity([1.0, 350.0], "um/s")).stress
    assert both == pytest.approx(steady_state(params, [1e-6, 350e-6]).stress, rel=1e-9)
    with pytest.raises(ParameterError, match=r"velocity: expected a velocity, got"):
        steady_state(params, ureg.Quantity(1.0, "Pa"))


def test_rsf_inertial_run_whose_regime_interpolant_probes_v_zero_finishes() -> None:
    # The regime's dense interpolant restarts LSODA (odeint) from an accepted step; a trial step with
    # V = v_ref e^x underflowing to 0 made dV/dt = (...)/(m V/sigma) a raw ZeroDivisionError out of simulate().
    from stickslip import protocols

    p = rsf.rsf_params(
        4.418535456009215e-05, 0.0006029620679651103, 3.576722905439472e-05, stiffness=0.7853394924736056,
        eta=1.3482482764787035e-06, mass=1.0177977091646792e-05, normal_stress=97802.63226493173,
        v_ref=0.4079399015321571,
    )  # fmt: skip
    v, v2, duration = 1.769748365139191e-05, 0.0008936521280123709, 0.1545280135033514
    run = rsf.simulate(p, protocols.velocity_steps([v, v2], [duration, duration]))
    assert run.status == "ok"
    assert np.all(np.isfinite(run.to_frame().select_dtypes("number").to_numpy()))


def test_rsf_critical_stiffness_of_a_long_second_state_is_found() -> None:
    # Dc2 / Dc = 1e10: the bisection's bracket started at 1e-9 (b - a)/min(Dc), above this k_c (~1.2e-3 1/m), and
    # the result was 0 with "stable at every stiffness (velocity strengthening)"; the growth rate says otherwise.
    from stickslip.rsf.stability import growth_rate

    p = rsf.rsf_params(0.01, 0.002, 1e-9, b2=0.02, dc2=10.0)
    kc = rsf.critical_stiffness(p, 1e-6)
    assert 1e-3 < kc < 2e-3
    assert growth_rate(p.replace(stiffness=0.9 * kc), 1e-6) > 0 > growth_rate(p.replace(stiffness=1.1 * kc), 1e-6)


@pytest.mark.parametrize(
    "mass, normal_stress", [(1e-300, 1e300), (1e300, 1.0)], ids=["inertia underflows", "k_c overflows"]
)
def test_rsf_stability_out_of_float_range_is_a_model_error(mass: float, normal_stress: float) -> None:
    # was a raw ZeroDivisionError (m/sigma = 0 in dV/dt) and an infinite k_c
    from stickslip.errors import ModelError

    p = rsf.rsf_params(0.01, 0.02, 1e-5, mass=mass, normal_stress=normal_stress)
    with pytest.raises(ModelError):
        rsf.stability(p, 1000.0)
