"""The cut-off velocity form of rate-and-state friction (QDYN's 'cut-off velocity', Okubo 1989, Dieterich 1981).

mu = mu0 - a ln(V1/V + 1) + b ln(V2 theta/Dc + 1).  Each check is against something the package does not
compute: the closed-form steady state, a direct solve_ivp of the equations in V and theta written out here,
the classical law it tends to when V1, V2 >> V, and the closed-form critical stiffness of its linearisation.
"""

from __future__ import annotations

import json
import math
import sys

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from cli_helpers import run_main
from stickslip import protocols
from stickslip.errors import ParameterError
from stickslip.rsf import RSFParams, critical_stiffness, rsf_params, simulate, stability
from stickslip.rsf.solver import evolve_state

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

V0, DC, A, B, MU0 = 1e-6, 10e-6, 0.01, 0.012, 0.6


def _mu_ss(v: float, v1: float, v2: float, a: float = A, b: float = B) -> float:
    return MU0 - a * math.log(v1 / v + 1.0) + b * math.log(v2 / v + 1.0)


def _reference_step(law: str, v1: float, v2: float, k: float, times: np.ndarray) -> np.ndarray:
    """Friction after a load-point step 1 -> 10 um/s at t = 1 s, by Radau in (V, theta) at rtol 1e-11.

    k (V_lp - V) = dmu/dt = mu_V dV/dt + mu_theta dtheta/dt, with mu_V = a V1/(V (V1 + V)) and
    mu_theta = b V2/(V2 theta + Dc) (QDYN's dmu_dv_dtheta).
    """

    def rhs(vlp: float):
        def f(t: float, y: np.ndarray) -> list[float]:
            v, theta = y
            omega = v * theta / DC
            dtheta = 1.0 - omega if law == "aging" else -omega * math.log(omega)
            mu_v = A * v1 / (v * (v1 + v))
            mu_theta = B * v2 / (v2 * theta + DC)
            return [(k * (vlp - v) - mu_theta * dtheta) / mu_v, dtheta]

        return f

    v_start = 1e-6
    y0 = [v_start, DC / v_start]
    before = times[times <= 1.0]
    first = solve_ivp(rhs(1e-6), (0.0, 1.0), y0, method="Radau", rtol=1e-11, atol=[1e-20, 1e-14], t_eval=before)
    second = solve_ivp(rhs(1e-5), (1.0, times[-1]), first.y[:, -1] if before.size else y0, method="Radau",
                       rtol=1e-11, atol=[1e-20, 1e-14], t_eval=times[times > 1.0], dense_output=False)  # fmt: skip
    v = np.concatenate([first.y[0], second.y[0]])
    theta = np.concatenate([first.y[1], second.y[1]])
    return MU0 - A * np.log(v1 / v + 1.0) + B * np.log(v2 * theta / DC + 1.0)


@pytest.mark.parametrize("law", ["aging", "slip"])
def test_velocity_step_matches_direct_solve_in_v_and_theta(law):
    v1, v2, k = 20e-6, 3e-6, 2e3
    p = rsf_params(A, B, DC, law=law, mu0=MU0, v_ref=V0, stiffness=k, cutoff=(v1, v2))
    times = np.linspace(0.0, 40.0, 401)
    run = simulate(p, protocols.velocity_steps([1e-6, 1e-5], [1.0, 39.0]), times=times, rtol=1e-11, atol=1e-13)
    reference = _reference_step(law, v1, v2, k, times)
    assert run.friction.size == times.size
    assert np.max(np.abs(run.friction - reference)) < 1e-10  # measured 3e-13
    assert np.ptp(reference) > 5e-3  # the step moved friction well beyond the tolerance


def test_steady_friction_is_the_closed_form_after_long_runs():
    """mu_ss(V) = mu0 - a ln(V1/V + 1) + b ln(V2/V + 1), reached from 1 um/s at each V (~300 Dc/V each)."""
    v1, v2, b = 100e-6, 1e-6, 0.008
    p = rsf_params(A, b, DC, mu0=MU0, v_ref=V0, stiffness=1e4, cutoff=(v1, v2))
    for v in (1e-7, 3e-6, 1e-5, 1e-3):
        run = simulate(p, protocols.velocity_steps([1e-6, v], [1.0, 300 * DC / v]), rtol=1e-11, atol=1e-13)
        expected = _mu_ss(v, v1, v2, b=b)
        assert abs(run.final_friction - expected) < 1e-9, v
        assert abs(float(p.steady_friction(v)) - expected) < 1e-14
    classical = MU0 + (A - b) * math.log(1e-3 / V0)
    assert abs(_mu_ss(1e-3, v1, v2, b=b) - classical) > 1e-2  # the form differs from the classical one here


def test_large_cutoffs_give_the_classical_law_with_mu0_shifted():
    """V1, V2 >> V: -a ln(V1/V + 1) + b ln(V2 theta/Dc + 1) -> a ln(V/V0) + b ln(V0 theta/Dc) - a ln(V1/V0)
    + b ln(V2/V0), so the step response is the classical law's with mu0 + b ln(V2/V0) - a ln(V1/V0), up to
    -a V/V1 + b Dc/(V2 theta): a gap of order (a + b)/ratio that falls tenfold for each tenfold ratio."""
    step = protocols.velocity_steps([1e-6, 1e-5], [1.0, 30.0])
    times = np.linspace(0.0, 31.0, 311)
    gaps = []
    for ratio in (1e4, 1e5):
        v1 = v2 = ratio * 1e-5
        cut = simulate(rsf_params(A, B, DC, mu0=MU0, v_ref=V0, stiffness=2e3, cutoff=(v1, v2)), step, times=times)
        shifted = MU0 + B * math.log(v2 / V0) - A * math.log(v1 / V0)
        classical = simulate(rsf_params(A, B, DC, mu0=shifted, v_ref=V0, stiffness=2e3), step, times=times)
        gaps.append(float(np.max(np.abs(cut.friction - classical.friction))))
        assert 0.3 < gaps[-1] * ratio / (A + B) < 3.0  # measured 0.853 at both ratios
    assert gaps[0] / gaps[1] == pytest.approx(10.0, rel=0.01)  # first order in 1/ratio: the limit is the law


def test_critical_stiffness_is_the_classical_one_with_effective_a_and_b():
    """Linearised at steady V: mu = A dx + B dpsi with A = a V1/(V1+V), B = b V2/(V2+V), so k_c = (B - A)/Dc."""
    v1, v2, b = 1e-6, 1e-4, 0.02
    p = rsf_params(A, b, DC, mu0=MU0, v_ref=V0, cutoff=(v1, v2))
    for v in (3e-7, 2e-6, 1e-5):
        a_eff, b_eff = A * v1 / (v1 + v), b * v2 / (v2 + v)
        assert b_eff > a_eff
        assert critical_stiffness(p, v) == pytest.approx((b_eff - a_eff) / DC, rel=1e-9)
    # b > a, yet steady sliding at 10 um/s with V2 = 1 um/s is stable at every stiffness, and is said to be why
    strong = stability(rsf_params(A, b, DC, cutoff=(1e-4, 1e-6)), 1e-5)
    assert strong.critical_stiffness == 0.0
    assert "b V2/(V2+V) <= a V1/(V1+V)" in strong.message


def test_state_at_fixed_velocity_and_its_friction():
    """theta(t) = Dc/V + (theta0 - Dc/V) e^(-Vt/Dc) (aging law at fixed V); friction is the cut-off form of it."""
    v1, v2, v = 5e-6, 2e-6, 4e-6
    p = rsf_params(A, B, DC, mu0=MU0, v_ref=V0, cutoff=(v1, v2))
    t = np.linspace(0.0, 20.0, 21)[1:]
    theta, friction = evolve_state(p, v, t, theta0=10.0)
    exact = DC / v + (10.0 - DC / v) * np.exp(-v * t / DC)
    assert np.max(np.abs(theta[0] / exact - 1)) < 1e-8
    expected = MU0 - A * math.log(v1 / v + 1) + B * np.log(v2 * exact / DC + 1)
    assert np.max(np.abs(friction - expected)) < 1e-9


def test_parameters_carry_and_round_trip_the_cutoff():
    p = rsf_params(A, B, DC, cutoff=(1e-3, 1e-6))
    assert p.cutoff == (1e-3, 1e-6)
    assert p.replace(a=0.02).cutoff == (1e-3, 1e-6)  # fits build their trial parameters with replace
    assert RSFParams.from_dict(p.to_dict()) == p
    assert RSFParams.from_dict(tomllib.loads(p.to_toml())) == p
    units = RSFParams.from_dict({"cutoff": {"v1": "1 mm/s", "v2": "1 um/s"}})
    assert units.cutoff == pytest.approx((1e-3, 1e-6), rel=1e-15)
    assert "cutoff" not in rsf_params(A, B, DC).to_dict()  # the classical form writes nothing new


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"cutoff": (0.0, 1e-6)}, "cutoff V1: expected a value > 0"),
        ({"cutoff": (1e-3, -1.0)}, "cutoff V2: expected a value > 0"),
        ({"cutoff": (math.inf, 1e-6)}, "cutoff V1: expected a finite number"),
        ({"cutoff": (math.nan, 1e-6)}, "cutoff V1: expected a finite number"),
        ({"cutoff": (1e-3,)}, "cutoff: expected two velocities"),
        ({"cutoff": "1 mm/s"}, "cutoff: expected two velocities"),
        ({"cutoff": (1e-3, 1e-6), "regularized": True}, "exclude each other"),
        ({"cutoff": (1e-3, 1e-6), "law": "nagata", "c": 1.0}, "nagata law couples"),
    ],
)
def test_bad_cutoffs_are_parameter_errors(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        rsf_params(A, B, DC, **kwargs)


def test_bad_cutoff_in_a_parameter_file():
    with pytest.raises(ParameterError, match="cutoff: expected a table with v1 and v2"):
        RSFParams.from_dict({"cutoff": {"v1": 1e-3}})


def test_command_line_cutoff(capsys, tmp_path):
    out = tmp_path / "run.csv"
    model = ["--a", "0.01", "--b", "0.008", "--dc", "10 um", "--cutoff-v1", "100 um/s", "--cutoff-v2", "1 um/s"]
    args = ["rsf", "simulate", *model, "--segment", "1 um/s:10 s", "--segment", "10 um/s:100 s", "-o", str(out)]
    status, _, _ = run_main(capsys, *args)
    assert status == 0
    saved = json.loads((tmp_path / "run.params.json").read_text())["parameters"]
    assert saved["cutoff"] == {"v1": pytest.approx(1e-4, rel=1e-15), "v2": pytest.approx(1e-6, rel=1e-15)}
    status, out_text, _ = run_main(capsys, *args[:-2], "--json")
    assert status == 0
    assert json.loads(out_text)["final_friction"] == pytest.approx(_mu_ss(1e-5, 1e-4, 1e-6, b=0.008), abs=1e-9)
    status, _, err = run_main(capsys, "rsf", "simulate", "--cutoff-v1", "1 mm/s", "--segment", "1 um/s:1 s")
    assert status == 2
    assert err.strip().splitlines()[-1].endswith("the cut-off velocity form needs both V1 and V2")


def test_model_interface_overrides_keep_the_cutoff():
    from stickslip.models import get_model

    base = rsf_params(A, B, DC, cutoff=(1e-3, 1e-6))
    assert get_model("rsf").parameters(base, {"a": 0.02}).cutoff == (1e-3, 1e-6)


def test_a_cutoff_record_is_fitted_with_the_cutoff_form_and_refused_by_the_classical_one():
    """A record made with the cut-off form (V1 = 20 um/s, V2 = 3 um/s, near the steps' 1 -> 10 um/s) and white
    noise of 1e-5: fitted with the same cut-offs held, a, b and Dc come back within 3 standard errors of the truth
    (over 12 seeds their z-scores had rms 1.0-1.4) at chi-square_r near 1; the classical law cannot describe it
    (chi-square_r far above, so the fit fails)."""
    from stickslip.rsf.data import LabRecord
    from stickslip.rsf.fit import fit_record

    truth = rsf_params(a=0.008, b=0.012, dc=20e-6, stiffness=2000.0, v_ref=1e-6, cutoff=(20e-6, 3e-6))
    history = protocols.velocity_steps([1e-6, 10e-6, 1e-6], [20.0, 20.0, 40.0])
    times = np.linspace(0.0, 80.0, 801)
    run = simulate(truth, history, times=times)
    rng = np.random.default_rng(0)
    record = LabRecord.from_arrays(times, history.displacement_at(times), run.friction + rng.normal(0, 1e-5, 801))
    fit = fit_record(record, protocol=history, fixed={"stiffness": 2000.0}, cutoff=(20e-6, 3e-6), noise=1e-5)
    assert fit.status == "ok", fit.reason
    assert fit.params.cutoff == (20e-6, 3e-6)
    assert 0.8 < fit.reduced_chi_square < 1.2
    for key, value in (("a", 0.008), ("b", 0.012), ("dc", 20e-6)):
        assert abs(fit.parameters[key].value - value) < 3 * fit.parameters[key].stderr, (key, fit.parameters[key])
    classical = fit_record(record, protocol=history, fixed={"stiffness": 2000.0}, noise=1e-5)
    assert classical.status == "failed" and classical.reduced_chi_square > 10 * fit.reduced_chi_square


def test_rsf_fit_takes_the_cutoff_on_the_command_line(capsys, tmp_path):
    """What `rsf simulate` writes with the cut-off form, `rsf fit` reads back with the same cut-offs held: the
    parameters it writes carry them, and a, b come back to the solver's precision (a noise-free record)."""
    trace = tmp_path / "run.csv"
    cut = ["--cutoff-v1", "20 um/s", "--cutoff-v2", "3 um/s"]
    model = ["--a", "0.008", "--b", "0.012", "--dc", "20 um", "--stiffness", "2000 1/m", *cut]
    status, _, err = run_main(capsys, "rsf", "simulate", *model, "--segment", "1 um/s:20 s", "--segment",
                              "10 um/s:20 s", "--every", "0.1 s", "-o", str(trace))  # fmt: skip
    assert status == 0, err
    fitted = tmp_path / "fit.toml"
    status, out, err = run_main(capsys, "rsf", "fit", str(trace), *cut, "--stiffness", "2000 1/m", "--json",
                                "-o", str(fitted))  # fmt: skip
    assert status == 0, err
    assert "cutoff = { v1 = " in fitted.read_text()
    report = json.loads(out)
    assert report["parameters"]["a"]["value"] == pytest.approx(0.008, rel=1e-3)
    assert report["parameters"]["b"]["value"] == pytest.approx(0.012, rel=1e-3)
    status, _, err = run_main(capsys, "rsf", "fit", str(trace), "--cutoff-v1", "20 um/s")
    assert status == 2 and "needs both V1 and V2" in err and err.count("\n") == 1, err
