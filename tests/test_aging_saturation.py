"""Issue 22 Q1: the saturating-aging extension of Eq 1 (aging.saturation_age, docs/extensions.md section 1).

The aging term's age t_a becomes A(t_a) = t_s (1 - e^(-t_a/t_s)); absent, the model is the paper's.
Checked against things computed independently of the code under test: the closed-form survival of a
held bond (an exponential integral), Eq 6 integrated as an ODE in age, finite differences of sigma(V).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import expi

import stickslip
from stickslip.errors import ParameterError, StickslipError
from stickslip.protocols import constant
from stickslip.quasistatic.steady import steady_state
from stickslip.transient import kernel as K
from stickslip.transient import run_transient
from stickslip.transient.model import chain_force, pack_parameters, steady_population

GEL = stickslip.load_parameters("gelatin-glass")
TS = 3.04e-3  # the fitted set of docs/extensions.md section 1 (steady curve + Table 1), rounded
SAT = GEL.with_overrides(
    {"aging.saturation_age": TS, "aging.aging_time": "0.6456 ms", "aging.aging_velocity": "279 um/s"}
)


def test_absent_key_is_the_paper_model() -> None:
    assert GEL.aging.saturation_age is None
    assert "aging.saturation_age" not in GEL.as_dict()  # results.json's parameter echo is unchanged
    assert "saturation_age" not in GEL.to_toml()
    assert pack_parameters(GEL, True, 1.0)[K.P_SATURATION] == 0.0  # the kernel's linear aging
    assert pack_parameters(SAT, True, 1.0)[K.P_SATURATION] == TS
    # a saturation age far beyond every age in a run reduces to the paper's model
    far = GEL.with_overrides({"aging.saturation_age": "1e9 s"})
    v = np.array([20e-6, 124e-6, 350e-6])
    assert np.allclose(steady_state(far, v).stress, steady_state(GEL, v).stress, rtol=1e-9, atol=0)
    a = run_transient(GEL, constant(350e-6, 2e-3), control="velocity", rtol=1e-4)
    b = run_transient(far, constant(350e-6, 2e-3), control="velocity", rtol=1e-4)
    assert a.time.size == b.time.size
    assert np.allclose(a.stress, b.stress, rtol=1e-9, atol=0)


def test_the_key_reads_units_and_refuses_bad_values() -> None:
    assert GEL.with_overrides({"aging.saturation_age": "5 ms"}).aging.saturation_age == pytest.approx(5e-3)
    toml = SAT.to_toml()
    assert "saturation_age" in toml
    for bad in ("-1 ms", "0 s", "nan"):
        with pytest.raises(ParameterError, match=r"aging\.saturation_age"):
            GEL.with_overrides({"aging.saturation_age": bad})
    with pytest.raises(StickslipError, match="saturation_age"):
        GEL.with_overrides({"aging.saturation_age": "5 m"})
    with pytest.raises(ParameterError, match="unknown parameter key"):
        GEL.with_overrides({"aging.saturation": "5 ms"})


def _held_stress(t: float, velocity: float) -> float:
    """Stress of the steady population at ``velocity`` held still for t: each cohort keeps its force f and ages.

    At V = 0 the hazard of a cohort of age a is (u0/tau) e^(c f) exp(-g (1 - e^(-a/t_s))), g = t_s/tau_a, so
    its cumulative hazard over [a0, a0 + t] is (u0/tau) e^(c f) t_s e^-g [Ei(g y0) - Ei(g y1)], y = e^(-a/t_s).
    Bonds born during the hold sit at zero extension and carry nothing.
    """
    b, g = SAT.bonds, SAT.aging
    pop = steady_population(SAT, velocity, True)
    f = chain_force(pop.extension, SAT)
    gam = TS / g.aging_time
    y0, y1 = np.exp(-pop.age / TS), np.exp(-(pop.age + t) / TS)
    big_h = b.breakage_weight / b.bond_time * np.exp(b.force_sensitivity * f) * TS * math.exp(-gam)
    big_h = big_h * (expi(gam * y0) - expi(gam * y1))
    return float(np.sum(pop.weight * np.exp(-big_h) * f))


def test_held_bonds_follow_the_closed_form_survival() -> None:
    """The kernel integrates the saturated hazard along the characteristics: at rtol 1e-4 within 2e-6 (0.02 rtol) of
    the closed form while the held stress falls ~100-fold (measured 9.4e-8, 1.2e-7, 3.4e-7, 1.05e-6 at 1, 5, 20, 50
    ms, 692 steps: the births' own error bound, docs/transient.md section 8; one lumped cohort's bound, 1239 steps:
    6e-9, 5e-9, 2.1e-7, 6.8e-7)."""
    run = run_transient(
        SAT, constant(0.0, 0.05), control="velocity", start="steady", start_velocity=100e-6, rtol=1e-4, every=1e-3
    )
    for t in (1e-3, 5e-3, 2e-2, 5e-2):
        row = int(np.argmin(np.abs(run.time - t)))
        assert run.time[row] == pytest.approx(t, rel=1e-12)
        assert run.stress[row] == pytest.approx(_held_stress(t, 100e-6), rel=2e-6)
    # the held stress decays towards zero: saturated bonds let go (linear aging keeps ~100 Pa for seconds)
    assert _held_stress(0.2, 100e-6) < 1e-2 * _held_stress(0.0, 100e-6)


def _steady_by_ode(velocity: float) -> tuple[float, float]:
    """Eqs 6-8 with the saturating aging term, integrated as an ODE in age (DOP853, rtol 1e-12)."""
    b, g = SAT.bonds, SAT.aging
    dlm = b.max_extension

    def rhs(t: float, y: np.ndarray) -> list[float]:
        f = b.chain_stiffness * velocity * t / (1.0 - (velocity * t / dlm) ** 2)
        aged = -TS * math.expm1(-t / TS)
        log_rate = math.log(b.breakage_weight / b.bond_time) + b.force_sensitivity * f
        log_rate -= aged / g.aging_time * math.exp(-velocity / g.aging_velocity)
        s = math.exp(-y[0])
        return [math.exp(min(log_rate, 700.0)), s, s * f]

    def gone(t: float, y: np.ndarray) -> float:
        return y[0] - 40.0

    gone.terminal = True  # type: ignore[attr-defined]
    end = dlm / velocity * (1.0 - 1e-12)
    sol = solve_ivp(rhs, (0.0, end), [0.0, 0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-30, events=gone)
    i, j = sol.y[1, -1], sol.y[2, -1]
    birth = b.site_density / (b.bond_time + i)
    return birth * j, birth * i / b.site_density


@pytest.mark.parametrize("compiled_from", [None, 1], ids=["numpy", "compiled"])  # the compiled march too (round 32)
@pytest.mark.parametrize("velocity", [1e-6, 5e-6, 20e-6, 100e-6, 350e-6])
def test_steady_curve_with_saturation_against_an_ode(velocity: float, compiled_from: int | None) -> None:
    stress, fraction = _steady_by_ode(velocity)
    got = steady_state(SAT, velocity, compiled_from=compiled_from)
    assert float(got.stress) == pytest.approx(stress, rel=1e-8)
    assert float(got.bonded_fraction) == pytest.approx(fraction, rel=1e-8)
    # dsigma/dV under the integral against a central difference
    h = 1e-5
    up, down = (steady_state(SAT, velocity * (1 + e), compiled_from=compiled_from).stress for e in (h, -h))
    diff = (up - down) / (2 * h)
    assert float(got.stress_slope) * velocity == pytest.approx(float(diff), rel=1e-5, abs=1e-6 * stress)


def test_a_batch_mixing_sets_with_and_without_saturation_matches_each_set() -> None:
    """steady_stress_many (fits, sweeps) in one march: the paper's lanes exactly as alone, the extension's too."""
    from stickslip.quasistatic.steady import steady_stress_many

    v = np.array([20e-6, 124e-6, 350e-6])
    both = steady_stress_many([GEL, SAT, GEL], v)
    assert np.array_equal(both[0], steady_state(GEL, v).stress)
    assert np.array_equal(both[2], steady_state(GEL, v).stress)
    assert np.allclose(both[1], steady_state(SAT, v).stress, rtol=1e-12, atol=0)


def test_saturation_makes_the_steady_curve_n_shaped() -> None:
    """With saturation the curve has a low-velocity maximum (the static threshold) before the minimum at Vc."""
    v = np.geomspace(1e-7, 3e-4, 60)
    stress = steady_state(SAT, v).stress
    top = int(np.argmax(stress[v < 1e-4]))
    assert 0 < top and stress[top] > 2 * stress[0]
    assert np.min(stress[top:]) < stress[top]
    # the paper's curve rises without a maximum as V falls
    assert np.all(np.diff(steady_state(GEL, v[v < 1e-4]).stress) < 0)


def test_fit_recovers_a_known_saturation_age() -> None:
    """Steady data and Table-1-like stresses made from a known set: the fit, started elsewhere, finds it again."""
    import pandas as pd

    from stickslip.fitting.saturation_fit import curve_extrema, fit_saturation

    peak, minimum = curve_extrema(SAT)
    assert peak is not None
    velocity = np.geomspace(140e-6, 2e-3, 12)
    stress = steady_state(SAT, velocity).stress
    spread = np.array([-2.0, 0.0, 2.0])  # Pa: the cycles scatter about the curve's extrema
    table = pd.DataFrame(
        {
            "pulling_velocity": [50e-6] * 3 + [100e-6],
            "cycle": [1, 2, 3, 1],
            "peak_stress": [*(peak.stress + spread), 5000.0],  # the first cycle at 100 um/s starts from rest: left out
            "start_stress": [*(minimum.stress + spread), minimum.stress],
        }
    )
    start = GEL.with_overrides({"aging.saturation_age": "4 ms"})
    fit = fit_saturation(start, velocity, stress, 0.02 * stress, table)
    assert fit.values["aging.saturation_age"] == pytest.approx(TS, rel=1e-4)
    assert fit.values["aging.aging_time"] == pytest.approx(0.6456e-3, rel=1e-4)
    lo, hi = fit.intervals["aging.saturation_age"]
    assert lo < TS < hi
    assert fit.peak.stress == pytest.approx(peak.stress, rel=1e-5)


def test_quasi_static_stick_time_against_a_quadrature() -> None:
    """The report's cycle (trapezoid in sigma on the creep branch) against Gauss-Legendre in ln V with the
    analytic slope: t = int dsigma/dV dV / (K (V0 - V)) from the landing at sigma_c to the maximum."""
    from scipy.optimize import brentq

    from stickslip.fitting.saturation_fit import curve_extrema
    from stickslip.report.aging_section import quasi_static_cycle

    peak, minimum = curve_extrema(SAT)
    assert peak is not None
    v0 = 50e-6
    _t, _s, stick, slip, jump = quasi_static_cycle(SAT, v0, peak, minimum, 30.0)
    k = SAT.block.effective_stiffness
    landing = brentq(
        lambda lv: float(steady_state(SAT, math.exp(lv)).stress) - minimum.stress, -40.0, math.log(peak.velocity)
    )
    nodes, weights = np.polynomial.legendre.leggauss(120)
    lo, hi = landing, math.log(peak.velocity)
    ln_v = 0.5 * (hi - lo) * nodes + 0.5 * (hi + lo)
    v = np.exp(ln_v)
    slope = steady_state(SAT, v).stress_slope
    exact = 0.5 * (hi - lo) * float(np.sum(weights * slope * v / (k * (v0 - v))))
    assert stick == pytest.approx(exact, rel=1e-5)
    assert float(steady_state(SAT, jump).stress) == pytest.approx(peak.stress, rel=1e-9)
    assert 0.0 < slip < stick


def test_the_quasi_steady_reduction_carries_the_saturating_clock():
    """Reduced and plain cohort runs agree with saturation set: the reduction's steady cells and lag see A(t_a)."""
    from stickslip.protocols import segments
    from stickslip.transient import run_transient
    from stickslip.transient.cells import steady_cohorts
    from stickslip.transient.model import steady_population

    p = stickslip.load_parameters("gelatin-glass").with_overrides({"aging.saturation_age": 3e-3})
    for v in (20e-6, 350e-6, 2e-3):  # the compiled steady cells are model.steady_population's, saturation and all
        compiled, plain = steady_cohorts(p, v, True), steady_population(p, v, True)
        np.testing.assert_allclose(compiled.weight, plain.weight, rtol=1e-10, atol=0)
    cases = ((segments([(350e-6, 0.05), (1000e-6, 0.05)]), "velocity"), (constant(350e-6, 0.5), "block"))
    for protocol, control in cases:
        auto = run_transient(p, protocol, control=control, start="steady", reduction="auto")
        off = run_transient(p, protocol, control=control, start="steady", reduction="off")
        assert auto.stress[-1] == pytest.approx(off.stress[-1], rel=1e-5), control
        assert auto.slider_velocity[-1] == pytest.approx(off.slider_velocity[-1], rel=1e-5), control


def test_the_shipped_saturating_set_is_the_fit_of_the_shipped_data():
    """`--params gelatin-glass-saturating` holds what fit_saturation finds (to the file's five digits)."""
    from stickslip.fitting.data import read_steady_data
    from stickslip.fitting.datasets import synthetic_steady_path, table1
    from stickslip.fitting.saturation_fit import fit_saturation

    shipped = stickslip.load_parameters("gelatin-glass-saturating")
    paper = stickslip.load_parameters("gelatin-glass")
    data = read_steady_data(synthetic_steady_path())
    start = paper.with_overrides({"aging.saturation_age": 5e-3})  # the paper's tau_a and V_a, far from the optimum
    fit = fit_saturation(
        start, np.asarray(data.velocity), np.asarray(data.stress), np.asarray(data.stress_err), table1()
    )
    assert shipped.aging.saturation_age == pytest.approx(fit.values["aging.saturation_age"], rel=5e-5)
    assert shipped.aging.aging_time == pytest.approx(fit.values["aging.aging_time"], rel=5e-5)
    assert shipped.aging.aging_velocity == pytest.approx(fit.values["aging.aging_velocity"], rel=5e-5)
    assert shipped.bonds == paper.bonds and shipped.stick == paper.stick and shipped.block == paper.block


def test_a_wide_steady_curve_with_saturation_is_the_same_curve():
    """1000 velocities (the compiled march's width) give what 999 give: the saturating clock is never dropped."""
    p = stickslip.load_parameters("gelatin-glass-saturating")
    velocity = np.geomspace(1e-6, 2e-3, 1000)
    wide = steady_state(p, velocity).stress
    narrow = np.concatenate([steady_state(p, velocity[:999]).stress, steady_state(p, velocity[999:]).stress])
    np.testing.assert_allclose(wide, narrow, rtol=1e-12)
