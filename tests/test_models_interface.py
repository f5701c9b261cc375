"""The model interface (stickslip.models): the rig, what each model refuses, the registry, one Run per model."""

from __future__ import annotations

import math

import numpy as np
import pytest

import stickslip
from stickslip import protocols
from stickslip.errors import ModelError, ParameterError
from stickslip.models import FrictionModel, Rig, Run, as_run, available_models, get_model, register_model
from stickslip.models.bond import with_stiffness


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"control": "force"}, "rig control: expected one of velocity, spring"),
        ({"stiffness": -1.0}, "rig stiffness: expected a finite value > 0 Pa/m"),
        ({"stiffness": 0.0}, "rig stiffness"),
        ({"damping": float("nan")}, "rig damping"),
        ({"mass": "heavy"}, "rig mass: 'heavy' has no number; expected a mass per area"),
        ({"control": "velocity", "stiffness": 1e5}, "velocity control has no spring"),
    ],
)
def test_rig_refuses_bad_values_in_one_line(kwargs, words):
    with pytest.raises(ParameterError, match=words) as info:
        Rig(**kwargs)
    assert "\n" not in str(info.value)


def test_the_public_names_are_there():
    for name in ("run", "Run", "Rig", "register_model", "get_model", "available_models", "FrictionModel"):
        assert name in stickslip.__all__ and getattr(stickslip, name) is not None
    assert {"quasi-static", "transient", "rsf"} <= set(available_models())
    assert get_model("rate-and-state") is get_model("rsf")
    assert get_model("stickslip.models.quasi_static:QuasiStatic").name == "quasi-static"


@pytest.mark.parametrize("name", ["nope", "stickslip.models:nothing", "no_such_module_xyz:MODEL", ":"])
def test_unknown_models_are_one_line_errors(name):
    with pytest.raises(ParameterError) as info:
        get_model(name)
    assert "\n" not in str(info.value)


def test_the_quasi_static_model_refuses_what_it_cannot_do():
    qs = get_model("quasi-static")
    params = qs.parameters()
    steps = protocols.velocity_steps([50e-6, 100e-6], 10.0)
    with pytest.raises(ModelError, match="one constant pulling velocity only"):
        qs.run(params, steps)
    with pytest.raises(ModelError, match="no velocity control"):
        qs.run(params, protocols.constant(50e-6, 10.0), Rig("velocity"))
    with pytest.raises(ModelError, match="damping is not part"):
        qs.run(params, protocols.constant(50e-6, 10.0), Rig(damping=1.0))
    with pytest.raises(ParameterError, match="unknown setting 'every'"):
        qs.run(params, protocols.constant(50e-6, 10.0), every=1.0)
    with pytest.raises(ParameterError, match="no_such"):
        qs.parameters(None, {"bonds.no_such": 1.0})


def test_a_rig_spring_is_the_blocks_effective_stiffness():
    """The rig's K replaces Eq 17's; the stick is then loaded at K V0 (Eq 12), checked on the trace."""
    qs = get_model("quasi-static")
    k_rig, v0 = 2.0e5, 50e-6
    run = qs.run(qs.parameters(), protocols.constant(v0, 30.0), Rig(stiffness=k_rig))
    stick = run.states["phase"] == "stick"
    t, s = run.time[stick], run.stress[stick]
    first = t < t[0] + 1.0
    slope = np.polyfit(t[first], s[first], 1)[0]
    assert slope == pytest.approx(k_rig * v0, rel=1e-9)
    same = qs.run(with_stiffness(qs.parameters(), {"block.effective_stiffness": k_rig}), protocols.constant(v0, 30.0))
    assert np.array_equal(same.stress, run.stress)


def test_quasi_static_run_is_the_simulation_and_its_period():
    """Period = stick time + slip time of the Simulation's phases; the repeating cycle's extremes are
    sigma_s (Eq 16) and sigma_c (Eq 9)."""
    p = stickslip.load_parameters()
    sim = stickslip.simulate(p, 50e-6, 100.0)
    run = stickslip.run("quasi-static", p, protocols.constant(50e-6, 100.0))
    assert run.regime.kind == sim.regime == "stick-slip"
    assert run.period == pytest.approx(sim.stick_phases[0].stick_time + sim.slip_phases[0].duration, rel=1e-14)
    assert run.peak == pytest.approx(sim.stick_phases[0].peak_stress, rel=1e-12)
    assert run.trough == pytest.approx(sim.critical_stress, rel=1e-9)
    assert run.regime.amplitude_ratio == 1.0
    assert np.array_equal(run.stress, sim.stress)
    assert run.trough < run.mean < run.peak


def test_rsf_run_keeps_its_regime_and_reads_a_rig_through_the_normal_stress():
    rsf = get_model("rsf")
    params = rsf.parameters(None, {"normal_stress": "1 MPa", "k": 2e3})
    run = rsf.run(params, protocols.constant(1e-6, 100.0), start=1.1e-6)
    native = stickslip.rsf.simulate(params, protocols.constant(1e-6, 100.0), start_velocity=1.1e-6)
    assert np.array_equal(run.friction, native.friction)
    assert np.allclose(run.stress, native.friction * 1e6, rtol=1e-15)
    assert run.regime_name == native.regime.name and run.regime.evidence == native.regime.evidence
    # K = k sigma through the rig gives the same run as k in the parameters
    by_rig = rsf.run(rsf.parameters(None, {"normal_stress": "1 MPa"}), protocols.constant(1e-6, 100.0),
                     Rig(stiffness=2e3 * 1e6), start=1.1e-6)  # fmt: skip
    assert np.allclose(by_rig.friction, run.friction, rtol=1e-12, atol=0)
    with pytest.raises(ParameterError, match="set normal_stress"):
        rsf.run(rsf.parameters(), protocols.constant(1e-6, 10.0), Rig(stiffness=1e9))


def test_transient_under_velocity_control_settles_to_the_steady_curve():
    """A rigid rig at V0 above Vc ends on sigma(V0) of the steady curve (Eqs 6-8), an independent solver."""
    p = stickslip.load_parameters()
    v0 = 300e-6
    run = stickslip.run("transient", p, protocols.constant(v0, 0.3), Rig("velocity"), start="steady")
    assert run.regime.kind == "steady"
    assert run.stress[-1] == pytest.approx(stickslip.steady_state(p, v0).stress, rel=1e-4)
    assert np.allclose(run.slider_velocity, v0)


def test_register_model_refuses_a_taken_name_and_non_models():
    class Copy(FrictionModel):
        name = "rsf"

        def dimensions(self):
            return {}

        def parameters(self, spec=None, overrides=None):
            return None

        def run(self, params, protocol, rig=None, *, start=None, **settings):
            raise AssertionError

    with pytest.raises(ParameterError, match="taken by model 'rsf'"):
        register_model(Copy())
    with pytest.raises(ParameterError, match="not a friction model"):
        register_model(object())


def test_a_run_from_a_trace_is_classified_by_the_one_classifier():
    """A synthetic limit cycle (a sawtooth of constant amplitude) is stick-slip with its exact period."""
    t = np.linspace(0.0, 50.0, 20001)
    stress = 100.0 + 20.0 * ((t / 5.0) % 1.0)
    zeros = np.zeros_like(t)
    run = Run.from_trace("test", t, stress=stress, slider_velocity=zeros, slider_position=zeros,
                         load_point_position=zeros)  # fmt: skip
    assert run.regime.kind == "stick-slip"
    assert run.period == pytest.approx(5.0, rel=1e-3)
    assert run.mean == pytest.approx(110.0, rel=1e-3)
    assert math.isnan(run.friction[0]) if run.friction is not None else run.friction is None


def test_the_old_results_convert_to_the_same_run():
    p = stickslip.load_parameters()
    sim = stickslip.simulate(p, 50e-6, 60.0)
    direct = stickslip.run("quasi-static", p, protocols.constant(50e-6, 60.0))
    columns = get_model("quasi-static").sweep_columns
    assert as_run(sim).row(columns) == direct.row(columns)
    rsf = stickslip.rsf.simulate(stickslip.rsf.rsf_params(0.005, 0.01, 10e-6), protocols.constant(1e-6, 20.0))
    assert as_run(rsf).regime_name == rsf.regime.name


def test_an_installed_package_registers_by_its_entry_point(monkeypatch):
    """A ``stickslip.models`` entry point is found by name, without any import by the user."""
    from importlib import metadata

    from stickslip.models import registry

    class Plugin(FrictionModel):
        name = "plugin-model"

        def dimensions(self):
            return {}

        def parameters(self, spec=None, overrides=None):
            return {}

        def run(self, params, protocol, rig=None, *, start=None, **settings):
            raise AssertionError

    entry = metadata.EntryPoint("plugin-model", f"{__name__}:PLUGIN", "stickslip.models")
    monkeypatch.setitem(globals(), "PLUGIN", Plugin())
    monkeypatch.setattr(registry.metadata, "entry_points", lambda group: [entry] if group == "stickslip.models" else [])
    monkeypatch.setitem(registry._LOADED, "entry points", False)
    monkeypatch.setattr(registry, "_MODELS", dict(registry._MODELS))
    assert get_model("plugin-model") is PLUGIN  # noqa: F821 - set above
    assert "plugin-model" in available_models()


def test_rsf_keys_refuse_a_second_state_variable_rather_than_drop_it():
    rsf = get_model("rsf")
    two = stickslip.rsf.rsf_params(0.005, 0.01, 10e-6, b2=0.005, dc2=100e-6)
    assert rsf.parameters(two) is two  # as given, without keys
    with pytest.raises(ParameterError, match="one state variable") as info:
        rsf.parameters(two, {"a": 0.006})
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(("v0", "kind"), [(50e-6, "stick-slip"), (300e-6, "steady")])
def test_the_quasi_static_phases_agree_with_the_one_classifier_on_the_trace(v0, kind):
    """The phase-based verdict (both sides of Vc = 124 um/s, Eq 9) is what regimes.classify reads off the trace."""
    from stickslip import regimes

    run = stickslip.run("quasi-static", None, protocols.constant(v0, 150.0))
    found = regimes.classify(run.time, run.stress, floor=1e-6 * float(np.max(run.stress)))
    assert run.regime.kind == found.kind == kind, found.evidence
    if kind == "stick-slip":
        assert found.period == pytest.approx(run.period, rel=1e-3)
        assert found.peak == pytest.approx(run.peak, rel=1e-9)


def test_a_sample_repeated_at_an_extremum_does_not_flip_peaks_and_troughs():
    """A trace that writes a phase boundary twice (same time, same stress) is the same signal (regimes._kinds)."""
    from stickslip import regimes

    t = np.linspace(0.0, 40.0, 4001)
    y = 10.0 + np.where((t % 4.0) < 3.0, (t % 4.0), 3.0 - 3.0 * ((t % 4.0) - 3.0))  # slow rise, fast fall
    peaks = np.flatnonzero(np.isclose(t % 4.0, 3.0))
    tt, yy = np.insert(t, peaks + 1, t[peaks]), np.insert(y, peaks + 1, y[peaks])
    plain, doubled = regimes.classify(t, y, floor=1e-9), regimes.classify(tt, yy, floor=1e-9)
    assert plain.kind == doubled.kind == "stick-slip"
    assert doubled.period == pytest.approx(4.0, rel=1e-6) and doubled.peak == pytest.approx(13.0)


def test_an_rsf_sweep_refuses_a_pulling_velocity_it_cannot_start_from_up_front():
    from stickslip.sweeps import build_spec

    with pytest.raises(ParameterError, match=r"pulling_velocity: expected a value > 0 m/s"):
        build_spec(["pulling_velocity=0 um/s,1 um/s"], model="rsf")


def test_quasi_static_run_reports_the_repeating_cycle_when_started_off_sigma_c():
    """A stick from 300 Pa is shorter than the repeating one (which starts at σc): the Run's period is the latter."""
    params = stickslip.load_parameters("gelatin-glass")
    from_c = stickslip.simulate(params, 50e-6, 120.0)
    from_300 = stickslip.simulate(params, 50e-6, 120.0, start_stress=300.0)
    assert from_300.cycles[0].period < 0.9 * from_c.cycles[0].period  # the first cycle is not the repeating one
    assert as_run(from_300).period == pytest.approx(as_run(from_c).period, rel=1e-9)
    assert as_run(from_300).peak == pytest.approx(as_run(from_c).peak, rel=1e-9)


def test_a_sweep_point_of_plain_values_takes_the_cached_fast_path_with_or_without_an_extension_key():
    from stickslip.models.bond import _parameter_set

    model = get_model("quasi-static")
    for name in ("gelatin-glass", "gelatin-glass-saturating"):
        params = stickslip.load_parameters(name)
        values = model.values(params)
        _parameter_set.cache_clear()
        again = [model.parameters(None, values) for _ in range(3)]
        assert _parameter_set.cache_info().hits == 2, name  # not load_parameters at every point (0.8 ms each)
        assert all(p.as_dict() == params.as_dict() for p in again)
