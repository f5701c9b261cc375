"""Rate-and-state laws and spring-slider against closed forms (docs/rsf.md derives each one)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip import protocols
from stickslip.errors import ModelError, ParameterError
from stickslip.rsf import (
    RSFParams,
    StateLaw,
    StateVariable,
    critical_stiffness,
    laws,
    neutral_period,
    register_law,
    rsf_params,
    simulate,
    stability,
)
from stickslip.rsf.laws import LAWS, Aging
from stickslip.rsf.solver import evolve_state
from stickslip.rsf.system import System

V0, DC = 1e-6, 10e-6


def test_aging_law_from_zero_state_matches_closed_form():
    """theta(t) = Dc/V (1 - e^(-Vt/Dc)) from theta = 0; started at theta0 = 1e-12 s, whose share is below 1e-11."""
    p = rsf_params(0.01, 0.015, DC, v_ref=V0)
    v = 3e-6
    t = np.linspace(0, 30, 61)[1:]
    theta, _ = evolve_state(p, v, t, theta0=1e-12)
    exact = DC / v * (1 - np.exp(-v * t / DC))
    assert np.max(np.abs(theta[0] / exact - 1)) < 1e-8


def test_slip_law_closed_form_at_constant_velocity():
    """ln(V theta/Dc) decays as e^(-Vt/Dc) (Ruina's law is linear in ln theta at constant V)."""
    p = rsf_params(0.01, 0.015, DC, law="slip", v_ref=V0)
    v, theta0 = 5e-6, 40.0
    t = np.linspace(0, 20, 41)[1:]
    theta, _ = evolve_state(p, v, t, theta0=theta0)
    omega = np.log(v * theta0 / DC) * np.exp(-v * t / DC)
    assert np.max(np.abs(theta[0] / (DC / v * np.exp(omega)) - 1)) < 1e-8


def test_prz_law_closed_form_at_constant_velocity():
    """u = V theta/(2 Dc) obeys du/dt = (V/(2Dc))(1 - u^2): u = tanh(V t/(2 Dc) + atanh u0)."""
    p = rsf_params(0.01, 0.015, DC, law="prz", v_ref=V0)
    v, theta0 = 2e-6, 1.0
    t = np.linspace(0, 40, 41)[1:]
    theta, _ = evolve_state(p, v, t, theta0=theta0)
    u = np.tanh(v * t / (2 * DC) + np.arctanh(v * theta0 / (2 * DC)))
    assert np.max(np.abs(theta[0] / (2 * DC * u / v) - 1)) < 1e-8


@pytest.mark.parametrize("law", ["aging", "slip", "prz", "nagata"])
def test_steady_friction_after_a_step(law):
    """mu_ss = mu0 + (a - b) ln(V/V0), whatever the law and the path there."""
    p = RSFParams(a=0.012, states=(StateVariable(law, 0.009, DC, c=1.0),), mu0=0.6, v_ref=V0, stiffness=5e3)
    run = simulate(p, protocols.velocity_steps([1e-6, 7e-6], [5.0, 300.0]), every=1.0)
    assert abs(run.final_friction - (0.6 + (0.012 - 0.009) * math.log(7.0))) < 1e-9
    assert run.regime.name == "steady sliding"


def test_regularized_form_is_classical_far_from_zero_velocity():
    """a asinh(V/(2V0) e^(Psi/a)) -> a ln(V/V0) + Psi when V/V0 e^(Psi/a) >> 1 (here by e^(0.6/0.01))."""
    base = rsf_params(0.01, 0.008, DC, v_ref=V0, stiffness=2e3)
    reg = base.replace(regularized=True)
    step = protocols.velocity_steps([1e-6, 10e-6], [2.0, 60.0])
    a, b = simulate(base, step, every=0.5), simulate(reg, step, every=0.5)
    assert np.max(np.abs(a.friction - b.friction)) < 1e-12 + 1e-9
    assert abs(reg.steady_friction(1e-6) - 0.6) < 1e-15 + 1e-12


@pytest.mark.parametrize("mass", [0.0, 50.0])
def test_analytic_jacobian_matches_central_differences(mass):
    states = (StateVariable("slip", 0.01, DC), StateVariable("nagata", 0.004, 5 * DC, c=0.5),
              StateVariable("prz", 0.002, 2 * DC))  # fmt: skip
    p = RSFParams(a=0.011, states=states, v_ref=V0, stiffness=800.0, eta=3.0, mass=mass, normal_stress=1e6)
    s = System(p)
    y = np.array([0.62, 0.7, -0.2, 0.4, -1.1] if mass else [0.7, -0.2, 0.4, -1.1])
    jac = s.jacobian(0.0, y, 2e-6)
    for j in range(y.size):
        h = 1e-6
        up, dn = y.copy(), y.copy()
        up[j] += h
        dn[j] -= h
        fd = (np.array(s.rhs(0.0, up, 2e-6)) - np.array(s.rhs(0.0, dn, 2e-6))) / (2 * h)
        assert np.allclose(jac[:, j], fd, rtol=1e-6, atol=1e-9 * np.max(np.abs(fd)))


def _oscillation(k_factor: float, law: str = "aging") -> tuple[float, float, float]:
    p = rsf_params(0.01, 0.014, DC, law=law, v_ref=V0, stiffness=1.0)
    kc = critical_stiffness(p, V0)
    run = simulate(p.replace(stiffness=k_factor * kc), protocols.constant(V0, 400.0), start_velocity=1.01 * V0,
                   every=0.02)  # fmt: skip
    return run.regime.growth, run.regime.period, neutral_period(p, V0)


@pytest.mark.parametrize("law", ["aging", "slip"])
def test_hopf_point_and_period(law):
    """Just above k_c a perturbation decays, just below it grows; both oscillate at 2 pi (Dc/V) sqrt(a/(b - a))."""
    p = rsf_params(0.01, 0.014, DC, law=law, v_ref=V0)
    assert critical_stiffness(p, V0) == pytest.approx(0.004 / DC, rel=1e-14)
    assert neutral_period(p, V0) == pytest.approx(2 * math.pi * 10 * math.sqrt(0.01 / 0.004), rel=1e-14)
    up_growth, up_period, period = _oscillation(1.03, law)
    down_growth, down_period, _ = _oscillation(0.97, law)
    assert up_growth < 0.97 and down_growth > 1.03
    assert up_period == pytest.approx(period, rel=0.03) and down_period == pytest.approx(period, rel=0.03)


def test_critical_stiffness_with_damping_and_inertia_matches_eigenvalues():
    """The closed form (docs/rsf.md) against the numerical Hopf point of the linearised equations."""
    from stickslip.rsf.stability import _numerical_critical

    p = rsf_params(0.01, 0.016, DC, v_ref=V0, eta=100.0, mass=1e7, normal_stress=1e6)
    v = 20e-6
    closed = critical_stiffness(p, v)
    a_eff = 0.01 + 100.0 * v
    inertia = 1e7 * v**2 / (1e6 * a_eff * DC)
    assert inertia > 0.02  # the correction is visible at the tolerance below
    assert closed == pytest.approx((0.016 - a_eff) / DC * (1 + inertia), rel=1e-14)
    assert _numerical_critical(p, v) == pytest.approx(closed, rel=1e-5)
    two = RSFParams(a=0.01, states=(StateVariable("aging", 0.012, DC), StateVariable("aging", 0.0, DC)), v_ref=V0)
    assert critical_stiffness(two, V0) == pytest.approx(0.002 / DC, rel=1e-6)
    report = stability(p.replace(stiffness=0.5 * closed), v)
    assert not report.stable and report.growth_rate > 0 and "unstable" in report.message


def test_quasi_static_blow_up_is_reported_not_returned():
    p = rsf_params(0.01, 0.015, DC, law="slip", v_ref=V0, stiffness=250.0)
    run = simulate(p, protocols.constant(V0, 300.0), start_velocity=1.1 * V0, every=0.1)
    assert run.status == "blow-up" and run.regime.name == "blow-up"
    assert "blow-up" in run.message and "eta" in run.message
    assert np.all(np.isfinite(run.friction)) and run.time[-1] < 300.0
    damped = simulate(p.replace(stiffness=250.0, eta=50.0), protocols.constant(V0, 300.0), start_velocity=1.1 * V0)
    assert damped.status == "ok" and np.all(np.isfinite(damped.friction))


def test_damped_stick_slip_is_a_limit_cycle():
    p = rsf_params(0.01, 0.015, 1e-6, v_ref=V0, stiffness=2500.0, eta=1.0)
    run = simulate(p, protocols.constant(V0, 400.0), start_velocity=1.1 * V0, every=0.02)
    assert run.regime.name == "stick-slip" and abs(run.regime.growth - 1) < 0.01
    assert run.regime.peak_friction > 0.6 > run.regime.trough_friction


def test_user_defined_law_plugs_in():
    class Doubled(StateLaw):
        name = "test-doubled-aging"

        def rate(self, x, psi, v0, dc):  # the aging law with Dc -> 2 Dc
            return Aging().rate(x, psi, v0, 2 * dc)

    register_law(Doubled())
    try:
        step = protocols.velocity_steps([1e-6, 5e-6], [2.0, 50.0])
        mine = simulate(RSFParams(states=(StateVariable("test-doubled-aging", 0.012, DC),), v_ref=V0), step, every=1.0)
        ref = simulate(RSFParams(states=(StateVariable("aging", 0.012, 2 * DC),), v_ref=V0), step, every=1.0)
        assert np.max(np.abs(mine.friction - ref.friction)) < 1e-10
    finally:
        LAWS.pop("test-doubled-aging")


def test_trace_frame_metadata_and_plots():
    p = rsf_params(0.01, 0.012, DC, b2=0.003, dc2=5 * DC, v_ref=V0)
    run = simulate(p, protocols.slide_hold_slide(1e-6, 20.0, 30.0), every=0.5)
    frame = run.to_frame()
    assert list(frame.columns) == ["time", "friction", "slider_velocity", "state", "state2",
                                   "load_point_displacement", "slider_displacement"]  # fmt: skip
    assert np.all(np.diff(frame["slider_displacement"]) >= -1e-15)
    back = RSFParams.from_dict(run.metadata()["parameters"])
    assert back == p
    run.plot()
    run.phase_plot()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [(dict(a=-0.01), "a: expected a value > 0"), (dict(dc=0.0), "dc"), (dict(law="bogus"), "law 'bogus'"),
     (dict(mass=1.0), "normal_stress"), (dict(b2=0.01), "b2/dc2")],
)  # fmt: skip
def test_bad_parameters_name_the_key(kwargs, match):
    base = dict(a=0.01, b=0.012, dc=DC)
    base.update(kwargs)
    with pytest.raises(ParameterError, match=match):
        rsf_params(**base)


def test_unknown_key_in_parameter_file_is_an_error():
    with pytest.raises(ParameterError, match="unknown key 'bee'"):
        RSFParams.from_dict({"a": 0.01, "bee": 1})


def test_small_mass_approaches_the_quasi_static_slider():
    """m -> 0: the inertial equations (s, x, psi) converge to the quasi-static slider, at first order in m."""
    step = protocols.velocity_steps([1e-6, 10e-6], [5.0, 60.0])
    quasi = rsf_params(0.01, 0.012, DC, v_ref=V0, stiffness=2e3)
    ref = simulate(quasi, step, every=0.5)
    gaps = [np.max(np.abs(simulate(quasi.replace(mass=m, normal_stress=1e6), step, every=0.5).friction - ref.friction))
            for m in (1e5, 1e4, 1e3)]  # fmt: skip
    assert gaps[-1] < 1e-7
    assert np.log10(gaps[0] / gaps[1]) == pytest.approx(1.0, abs=0.05)  # observed order 1 in m
    assert np.log10(gaps[1] / gaps[2]) == pytest.approx(1.0, abs=0.05)


def test_too_short_an_inertial_time_is_said_in_words():
    heavy = rsf_params(0.01, 0.012, DC, v_ref=V0, stiffness=2e3, mass=1.0, normal_stress=1e6)
    with pytest.raises(ModelError, match="inertial time"):
        simulate(heavy, protocols.velocity_steps([1e-6, 10e-6], [5.0, 60.0]), every=0.5)


def test_parameter_mapping_reads_units_and_stress_stiffness():
    p = RSFParams.from_dict({"a": 0.01, "v_ref": "1 um/s", "normal_stress": "30 MPa", "stiffness": "30 MPa/mm",
                             "eta": "3 MPa*s/m", "states": [{"law": "slip", "b": 0.012, "dc": "20 um"}]})  # fmt: skip
    assert p.stiffness == pytest.approx(1e3, rel=1e-12) and p.eta == pytest.approx(0.1, rel=1e-12)
    assert p.states[0].dc == pytest.approx(20e-6, rel=1e-12) and p.v_ref == pytest.approx(1e-6, rel=1e-12)
    with pytest.raises(ParameterError, match="normal_stress"):
        RSFParams.from_dict({"stiffness": "30 MPa/mm"})


def test_blow_up_under_a_soft_spring_with_the_slip_law_is_a_status_not_a_scipy_error():
    """A case where LSODA's interpolant leaves scipy's event search without a bracket (found by a sweep)."""
    run = simulate(
        rsf_params(0.005, 0.02, 10e-6, law="slip", stiffness=1.0), protocols.constant(1.0, 50.0), start_velocity=1.1
    )
    assert run.status == "blow-up"
    assert np.all(np.isfinite(run.friction)) and run.time[-1] < 50.0


@pytest.mark.parametrize("law", ["aging", "slip", "prz"])
def test_the_one_state_equations_are_the_general_ones_bit_for_bit(law):
    """A single state takes its own right-hand side (its numbers bound as locals); it must give what the general
    classical form and the fully general one give, exactly, and a System must still pickle."""
    import pickle

    p = RSFParams(a=0.011, states=(StateVariable(law, 0.015, DC),), v_ref=V0, stiffness=800.0, eta=3.0)
    s = System(p)
    assert s.rhs.__name__ == "rhs" and s.classical
    rng = np.random.default_rng(5)
    # and about the exponentials' cap (EXP_CAP = 700: the laws' state_rate caps as cexp does)
    edges = np.array([[750.0, -750.0], [-750.0, 750.0], [699.9, -0.5], [0.5, -700.1], [-360.0, 1400.0]])
    for y in np.vstack([rng.uniform(-8.0, 8.0, (200, 2)), edges]):
        one = s.rhs(0.0, y, 3e-6)
        assert one == s._rhs_classical(0.0, y, 3e-6) == System.rhs(s, 0.0, y, 3e-6)
    again = pickle.loads(pickle.dumps(s))
    assert again.rhs(0.0, np.array([0.3, -0.4]), 3e-6) == s.rhs(0.0, np.array([0.3, -0.4]), 3e-6)
    # a law that writes only rate() (a user's) gets state_rate from it
    plain = type("Plain", (type(s.laws[0]),), {"state_rate": laws.StateLaw.state_rate})()
    g, fast = plain.state_rate(V0, DC), s.laws[0].state_rate(V0, DC)
    assert all(g(x, p) == fast(x, p) == s.laws[0].rate(x, p, V0, DC)[0] for x, p in rng.uniform(-8.0, 8.0, (50, 2)))


@pytest.mark.parametrize("names", [("aging", "slip"), ("prz", "aging"), ("slip", "prz", "aging")])
def test_several_states_take_the_general_equations_bit_for_bit(names):
    """Two states (unrolled) and three (a loop) take their own right-hand side, each law's g alone, with the numbers
    bound as locals; it must give what the general classical form and the fully general one give, exactly, also
    at the exponentials' cap, and a System must still pickle."""
    import pickle

    states = tuple(StateVariable(law, 0.006 + 0.002 * k, DC * (1 + 5 * k)) for k, law in enumerate(names))
    s = System(RSFParams(a=0.011, states=states, v_ref=V0, stiffness=800.0, eta=3.0))
    assert s.classical and s.rhs.__name__ == ("two" if len(names) == 2 else "rhs")
    assert not hasattr(s.rhs, "__self__")  # a closure, not the method _rhs_classical
    rng = np.random.default_rng(11)
    size = len(names) + 1
    edges = np.array([[750.0] + [-750.0] * (size - 1), [-750.0] + [750.0] * (size - 1), [699.9] + [-0.5] * (size - 1)])
    for y in np.vstack([rng.uniform(-8.0, 8.0, (200, size)), edges]):
        fast = s.rhs(0.0, y, 3e-6)
        assert fast == s._rhs_classical(0.0, y, 3e-6) == System.rhs(s, 0.0, y, 3e-6)
    again = pickle.loads(pickle.dumps(s))
    y = rng.uniform(-1.0, 1.0, size)
    assert again.rhs(0.0, y, 3e-6) == s.rhs(0.0, y, 3e-6)


@pytest.mark.parametrize("names", [("aging",), ("slip",), ("prz",), ("aging", "slip"), ("slip", "prz", "aging")])
def test_the_bound_jacobian_is_the_general_one_bit_for_bit(names):
    """The classical form's Jacobian with its numbers bound (a closure) gives the general method's matrix byte for
    byte, at random states and at the exponentials' cap, and the closure is rebuilt after pickling."""
    import pickle

    states = tuple(StateVariable(law, 0.006 + 0.002 * k, DC * (1 + 5 * k)) for k, law in enumerate(names))
    s = System(RSFParams(a=0.011, states=states, v_ref=V0, stiffness=800.0, eta=3.0))
    assert s.classical and s.jacobian.__name__ == "jacobian" and not hasattr(s.jacobian, "__self__")
    rng = np.random.default_rng(13)
    size = len(names) + 1
    edges = np.array([[750.0] + [-750.0] * (size - 1), [-750.0] + [750.0] * (size - 1), [699.9] + [-0.5] * (size - 1)])
    for y in np.vstack([rng.uniform(-8.0, 8.0, (200, size)), edges]):
        fast, general = s.jacobian(0.0, y, 3e-6), System.jacobian(s, 0.0, y, 3e-6)
        assert fast.shape == general.shape == (size, size) and fast.dtype == general.dtype
        assert fast.tobytes() == general.tobytes(), (y, fast, general)
    again = pickle.loads(pickle.dumps(s))
    y = rng.uniform(-1.0, 1.0, size)
    assert again.jacobian(0.0, y, 3e-6).tobytes() == s.jacobian(0.0, y, 3e-6).tobytes()


@pytest.mark.parametrize("names", [("aging",), ("slip", "prz")])
def test_the_carried_integral_of_friction_takes_the_same_equations(names):
    """The classical form with the integral of mu carried (the run's mean friction) has its own right-hand side;
    its rates are the system's bit for bit, and its dmu/dt the friction (to rounding: the sum is associated
    differently)."""
    from stickslip.rsf.solver import WithIntegral

    states = tuple(StateVariable(law, 0.006 + 0.002 * k, DC * (1 + 5 * k)) for k, law in enumerate(names))
    s = System(RSFParams(a=0.011, states=states, v_ref=V0, stiffness=800.0, eta=3.0))
    carried = WithIntegral(s)
    assert not hasattr(carried.rhs, "__self__")  # the closure, not the general method
    rng = np.random.default_rng(13)
    size = len(names) + 2
    for y in np.vstack([rng.uniform(-8.0, 8.0, (200, size)), [[750.0] + [-750.0] * (size - 1)]]):
        fast, general = carried.rhs(0.0, y, 3e-6), carried._rhs(0.0, y, 3e-6)
        assert fast[:-1] == general[:-1]
        assert fast[-1] == pytest.approx(general[-1], rel=1e-14, abs=1e-12)
