"""``stickslip compare`` and its pluggable bond-model side."""

from __future__ import annotations

import json
import types

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip import protocols
from stickslip.parameters import load_parameters
from stickslip.quasistatic.steady import steady_state
from stickslip.rsf import RSFParams, StateVariable, simulate
from stickslip.studies import bond_rsf as cmp

PARAMS = load_parameters("gelatin-glass")


def test_quasi_static_fallback_follows_the_steady_curve_and_says_so(monkeypatch):
    monkeypatch.setattr(cmp, "_transient", lambda: None)
    step = protocols.velocity_steps([200e-6, 2000e-6], [1.0, 1.0])
    trace = cmp.bond_response(PARAMS, step, "velocity", times=[0.5, 1.5])
    expected = np.ravel(steady_state(PARAMS, np.array([200e-6, 2000e-6])).stress)
    assert trace.stress == pytest.approx(expected, rel=1e-12)
    assert "no transient" in trace.note and trace.source == "quasi-static bond model"
    hold = cmp.bond_response(PARAMS, protocols.slide_hold_slide(200e-6, 1.0, 1.0), "velocity", times=[1.5])
    assert np.isnan(hold.stress[0]) and "holds" in hold.note


def test_time_dependent_model_is_used_when_asked_for(monkeypatch):
    """bond_response runs the bond models through the model interface: the transient one only when asked for."""
    asked = []

    class FakeTransient:
        def run(self, params, protocol, rig=None, *, start=None):
            asked.append((rig.control, start))
            return types.SimpleNamespace(time=np.linspace(0, protocol.duration, 5), stress=np.full(5, 42.0))

    real = cmp._bond_model
    monkeypatch.setattr(cmp, "_bond_model", lambda name: FakeTransient() if name == "transient" else real(name))
    trace = cmp.bond_response(PARAMS, protocols.constant(1e-4, 1.0), model="transient")
    assert trace.source == "time-dependent bond model" and np.all(trace.stress == 42.0)
    assert asked == [("velocity", "steady")]
    default = cmp.bond_response(PARAMS, protocols.constant(1e-4, 1.0), times=[0.5])
    assert default.source == "quasi-static bond model"  # the slow model only when asked for


def test_quasi_static_step_is_exactly_a_rate_only_law(monkeypatch):
    """The quasi-static model jumps at once to the new steady stress: a = dmu/dlnV over the step, b = 0."""
    monkeypatch.setattr(cmp, "_transient", lambda: None)
    rsf = cmp.rsf_of_bond(PARAMS, 200e-6, 2000e-6)
    sigma_c = rsf.sigma_c
    mu = np.ravel(steady_state(PARAMS, np.array([200e-6, 2000e-6])).stress) / sigma_c
    assert rsf.status == "fitted" and rsf.params.b == 0.0
    assert rsf.params.a == pytest.approx((mu[1] - mu[0]) / np.log(10.0), rel=1e-12)
    assert "not determined" in rsf.note  # Dc has no effect with b = 0
    # the RSF run of the step lands on the bond model's level at once (rigid rig: no transient with b = 0)
    step = protocols.velocity_steps([200e-6, 2000e-6], [1.0, 1.0])
    run = simulate(rsf.params, step, times=np.linspace(0.0, 2.0, 2001))
    assert np.interp([0.5, 1.0 + 1e-3, 1.5], run.time, run.friction) == pytest.approx([mu[0], mu[1], mu[1]], rel=1e-5)
    h = 1e-4  # the bond model's steady slope at the step's mean velocity, by central difference
    s = np.ravel(steady_state(PARAMS, np.sqrt(200e-6 * 2000e-6) * np.exp([-h, h])).stress)
    assert rsf.a_minus_b == pytest.approx((s[1] - s[0]) / (2 * h) / sigma_c, rel=1e-5)


def test_a_falling_quasi_static_step_is_a_failed_fit(monkeypatch):
    monkeypatch.setattr(cmp, "_transient", lambda: None)
    rsf = cmp.rsf_of_bond(PARAMS, 30e-6, 100e-6)  # below Vc the steady stress falls with V
    mu = np.ravel(steady_state(PARAMS, np.array([30e-6, 100e-6])).stress) / rsf.sigma_c
    a = (mu[1] - mu[0]) / np.log(100 / 30)
    assert a < 0 and rsf.status == "failed" and f"a = {a:.3g} <= 0" in rsf.note and not rsf.usable


def _synthetic_step(a: float, b: float, dc: float, k: float) -> tuple[cmp.BondTrace, protocols.Protocol]:
    step = protocols.velocity_steps([200e-6, 2000e-6], [0.05, 0.05])
    times = np.unique(np.concatenate([np.linspace(0, 0.1, 401), 0.05 + np.geomspace(1e-7, 0.01, 400)]))
    truth = RSFParams(a=a, states=(StateVariable("aging", b, dc),), mu0=1.2, v_ref=200e-6, stiffness=k)
    run = simulate(truth, step, times=times)
    return cmp.BondTrace(run.time, run.friction * 250.0, "synthetic RSF", ""), step


def test_step_fit_recovers_a_known_rate_and_state_step():
    """A trace made by RSF itself (a = 1.5, b = 0.8, Dc = 0.1 um, k = 2e7 /m): the fit gives them back."""
    trace, step = _synthetic_step(1.5, 0.8, 0.1e-6, 2e7)
    rsf = cmp.fit_bond_step(trace, step, 250.0, slope=0.0)
    assert rsf.status == "fitted", rsf.note
    p = rsf.params
    assert (p.a, p.b, p.dc, p.stiffness) == pytest.approx((1.5, 0.8, 0.1e-6, 2e7), rel=1e-3)


def test_an_unphysical_best_fit_is_reported_failed_with_its_values(monkeypatch):
    """The best fit the issue saw (a = 4.9e-5, b = -0.93, Dc = 0.031 um) must not be used or called fitted."""
    import stickslip.rsf.fit as fit_module

    wanted = RSFParams(a=4.9e-5, states=(StateVariable("aging", -0.93, 0.031e-6),), mu0=1.16, v_ref=200e-6)
    fake = types.SimpleNamespace(params=wanted, rms=0.016, success=True, message="", warnings=())
    monkeypatch.setattr(fit_module, "fit_record", lambda *args, **kwargs: fake)
    trace, step = _synthetic_step(1.5, 0.8, 0.1e-6, 2e7)
    rsf = cmp.fit_bond_step(trace, step, 250.0, slope=0.0)
    assert rsf.status == "failed" and not rsf.usable and not rsf.determined
    assert "b = -0.93 < 0" in rsf.note
    pair = cmp.stick_slip_pair(PARAMS, 50e-6, 5.0, rsf)
    assert pair["rsf"] is None and "fit failed" in pair["problem"]


def test_negative_friction_is_named_with_where_it_starts():
    assert cmp.check_friction(np.array([0.0, 1.0]), np.array([1.0, 0.5])) is None
    text = cmp.check_friction(np.array([0.0, 1.0, 2.0]), np.array([1.0, -0.5, -11.0]))
    assert "t = 1 s" in text and "-11" in text and "no physical meaning" in text
    assert cmp.physical_problem(RSFParams(a=0.01, states=(StateVariable("aging", -0.1, 1e-6),))) is not None


def test_one_parameter_set_for_every_panel():
    rsf = cmp.BondRSF(RSFParams(a=0.3, states=(StateVariable("aging", 0.6, 100e-6),), mu0=1.2, v_ref=200e-6),
                      -0.3, 100e-6, 257.0, "given", "given")  # fmt: skip
    pair = cmp.stick_slip_pair(PARAMS, 50e-6, 5.0, rsf)
    used = pair["rsf"].params
    assert (used.a, used.b, used.dc, used.mu0, used.v_ref) == (0.3, 0.6, 100e-6, 1.2, 200e-6)  # only the rig differs


def test_compare_command_reports_negative_friction_as_what_rsf_cannot_describe(tmp_path, capsys):
    """Defaults: the rate-only law fitted to the quasi-static step has no healing, so in the hold its friction
    falls below zero. The fit itself succeeded, so the command does too (exit 0); the panel is named, in words,
    as one the fitted law cannot describe, and the figure still shows what was found."""
    figure = tmp_path / "compare.png"
    code, out, err = run_main(capsys, "compare", "--duration", "60 s", "--json", "-o", str(figure))
    assert code == 0, err
    summary = json.loads(out)
    assert summary["status"] == "ok" and summary["failures"] == []
    assert "below zero" in " ".join(summary["rsf_cannot_describe"])
    r = summary["rsf_of_bond_model"]
    assert {"a", "b", "dc", "status", "note"} <= set(r) and r["status"] == "fitted" and r["b"] == 0.0
    assert "rsf_parameters" not in summary["stick_slip"]  # one set, not a second one for stick-slip
    assert "slide-hold-slide" in summary["panels"] and summary["panels"]["velocity step"]["problem"] is None
    assert summary["stick_slip"]["bond"]["regime"] == "stick-slip"
    assert figure.stat().st_size > 0 and (tmp_path / "compare.params.json").is_file()


def test_compare_with_rsf_overrides_shows_an_rsf_oscillation(capsys):
    code, out, err = run_main(capsys, "compare", "--duration", "120 s", "--a", "0.3", "--b", "0.6", "--dc", "100 um",
                              "--json")  # fmt: skip
    summary = json.loads(out)
    rsf = summary["rsf_of_bond_model"]
    assert (rsf["a"], rsf["b"], rsf["dc"]) == pytest.approx((0.3, 0.6, 100e-6)) and rsf["status"] == "given"
    assert "given on the command line" in rsf["note"] and not rsf["fitted"]
    assert summary["stick_slip"]["rsf"]["period"] is not None
    assert code == 0 and summary["failures"] == [], err


def test_compare_figure_labels_the_set_by_how_it_was_obtained(monkeypatch):
    from stickslip.cli.compare_cmd import _how

    assert _how("fitted") == "fitted to the bond model's step" and _how("given") == "given on the command line"
    assert _how("failed") == "FIT FAILED"


def test_time_dependent_step_is_fitted_with_its_peak(capsys, tmp_path):
    """The time-dependent bond model overshoots after the step (its peak, ~4.3 sigma_c at 200 -> 2000 um/s):
    the fitted RSF has a direct effect and reproduces the peak (short durations keep this test to seconds)."""
    code, out, _ = run_main(capsys, "compare", "--bond-model", "transient", "--step-time", "0.1 s", "--hold",
                              "0.1 s", "--duration", "5 s", "--json")  # fmt: skip
    summary = json.loads(out)
    r = summary["rsf_of_bond_model"]
    assert r["status"] == "fitted", r["note"]
    assert r["a"] > 0 and r["b"] > 0 and r["dc"] > 0
    assert r["rsf_a_minus_b"] == pytest.approx(r["bond_steady_slope"], rel=0.1)  # both carry the steady slope
    panel = summary["panels"]["velocity step"]
    assert panel["bond_max"] > 1.2 * panel["bond_final"]  # the overshoot is there ...
    assert panel["rsf_max"] == pytest.approx(panel["bond_max"], rel=0.05)  # ... and the fitted RSF has it too
    assert code == (3 if summary["failures"] else 0)
