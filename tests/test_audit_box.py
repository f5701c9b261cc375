"""Robustness over the physical box: corners of parameter space found by fuzzing (audit a3)."""

from __future__ import annotations

import math

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


def test_steady_state_refuses_a_pint_quantity_instead_of_dropping_its_unit() -> None:
    # np.asarray(1 um/s) is 1.0: the unit was dropped and the stress at 1 m/s (41 Pa) returned for 1 um/s.
    pint = pytest.importorskip("pint")
    from stickslip.errors import ParameterError
    from stickslip.parameters import load_parameters
    from stickslip.quasistatic.steady import steady_state

    params = load_parameters("gelatin-glass")
    with pytest.raises(ParameterError, match=r"velocity: .*units"):
        steady_state(params, pint.UnitRegistry().Quantity(1.0, "um/s"))
