"""``stickslip compare`` and its pluggable bond-model side."""

from __future__ import annotations

import json
import sys
import types

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip import protocols
from stickslip.model.steady import steady_state
from stickslip.parameters import load_parameters
from stickslip.rsf import compare as cmp

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
    fake = types.ModuleType("stickslip.transient")

    def run_transient(params, protocol, control="velocity", start="steady"):
        t = np.linspace(0, protocol.duration, 5)
        return types.SimpleNamespace(time=t, stress=np.full(5, 42.0))

    fake.run_transient = run_transient
    monkeypatch.setitem(sys.modules, "stickslip.transient", fake)
    monkeypatch.setattr("stickslip.transient", fake, raising=False)
    trace = cmp.bond_response(PARAMS, protocols.constant(1e-4, 1.0), model="transient")
    assert trace.source == "time-dependent bond model" and np.all(trace.stress == 42.0)
    default = cmp.bond_response(PARAMS, protocols.constant(1e-4, 1.0), times=[0.5])
    assert default.source == "quasi-static bond model"  # the slow model only when asked for


def test_rsf_of_bond_states_a_minus_b_as_the_steady_slope(monkeypatch):
    monkeypatch.setattr(cmp, "_transient", lambda: None)
    rsf = cmp.rsf_of_bond(PARAMS, 200e-6, 2000e-6)
    vm = np.sqrt(200e-6 * 2000e-6)
    h = 1e-4
    s = np.ravel(steady_state(PARAMS, vm * np.exp([-h, h])).stress)
    slope = (s[1] - s[0]) / (2 * h) / rsf.sigma_c  # dmu/dlnV by central difference
    assert rsf.a_minus_b == pytest.approx(slope, rel=1e-5)
    assert rsf.params.a - rsf.params.b == pytest.approx(rsf.a_minus_b, rel=1e-12)
    assert not rsf.determined and "not determined" in rsf.note


def test_compare_command(tmp_path, capsys):
    figure = tmp_path / "compare.png"
    code, out, err = run_main(capsys, "compare", "--duration", "60 s", "--json", "-o", str(figure))
    assert code == 0, err
    summary = json.loads(out)
    assert {"a", "b", "dc", "a_minus_b", "note"} <= set(summary["rsf_of_bond_model"])
    assert "bond model" in summary["bond_model"]
    assert summary["stick_slip"]["bond"]["regime"] == "stick-slip"
    assert figure.stat().st_size > 0 and (tmp_path / "compare.params.json").is_file()


def test_compare_with_rsf_overrides_shows_an_rsf_oscillation(capsys):
    code, out, err = run_main(capsys, "compare", "--duration", "120 s", "--a", "0.3", "--b", "0.6", "--dc", "100 um",
                              "--json")  # fmt: skip
    assert code == 0, err
    summary = json.loads(out)
    rsf = summary["stick_slip"]["rsf_parameters"]
    assert (rsf["a"], rsf["b"], rsf["dc"]) == pytest.approx((0.3, 0.6, 100e-6)) and "overridden" in rsf["note"]
    assert summary["stick_slip"]["rsf"]["period"] is not None
