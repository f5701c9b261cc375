"""Issue 20 item 5: a model written outside the package (below, as in docs/models.md) is one class plus one
registration, and then runs from Python, in ``stickslip.sweep`` and through ``stickslip sweep --model``.

The physics is checked against closed forms derived for this model (docs/models.md): a spring-slider of mass m
(per area), dashpot eta to the ground, spring K, under normal stress sigma, with velocity-weakening friction
mu(V) = mu0 - c ln(V/Vr), capped at the static peak mu_s (the slider sticks at V = 0 until K s = sigma mu_s):

* steady sliding at V0: the spring stress is sigma mu(V0) + eta V0;
* linearised about it, m x'' + (eta - sigma c/V0) x' + K x = 0: steady sliding is stable iff V0 > V* = sigma c/eta,
  whatever K; above V* a disturbance rings down with the period 2 pi / sqrt(K/m - gamma^2), gamma = (eta -
  sigma c/V0)/(2m).
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import stickslip
from stickslip.models import Boundary, Capabilities, FrictionModel, Rig, Run
from stickslip.models.registry import unregister_model


# ----------------------------------------------------------------------------- the user's model (docs/models.md)
class VelocityWeakening(FrictionModel):
    """mu(V) = mu0 - c ln(V/Vr) capped at mu_s, on a spring-slider with mass and a dashpot (SI, per area)."""

    name = "velocity-weakening"
    description = "spring-slider, mu = mu0 - c ln(V/Vr) with a static peak"
    capabilities = Capabilities(controls=("spring",), protocols="constant", damping=True, mass=True)
    defaults: ClassVar[dict[str, float]] = dict(
        mu0=0.5, c=0.01, v_ref=1e-3, mu_s=0.6, normal_stress=1e3, stiffness=1e4, damping=100.0, mass=1.0
    )

    def sweep_start(self, protocol):
        return 1.1 * protocol.segments[0].velocity  # steady sliding, pushed: the disturbance whose fate we see

    def dimensions(self):
        return {"mu0": "dimensionless", "c": "dimensionless", "v_ref": "velocity", "mu_s": "dimensionless",
                "normal_stress": "stress", "stiffness": "stress_per_length", "damping": "stress_per_velocity",
                "mass": "mass_per_area"}  # fmt: skip

    def parameters(self, spec=None, overrides=None):
        from stickslip.errors import ParameterError
        from stickslip.units import to_si

        values = dict(self.defaults if spec is None else spec)
        for key, raw in (overrides or {}).items():
            if key not in self.dimensions():
                raise ParameterError(f"{key}: unknown key of {self.name}; expected one of {', '.join(self.defaults)}")
            values[key] = to_si(raw, self.dimensions()[key], key)
        return values

    def values(self, params):
        return dict(params)

    def run(self, params, protocol, rig=None, *, start=None, **settings):
        rig = self.check(protocol, rig, settings)
        rig_values = {"stiffness": rig.stiffness, "damping": rig.damping, "mass": rig.mass}
        p = {**params, **{key: value for key, value in rig_values.items() if value is not None}}
        sigma, k, eta, m = p["normal_stress"], p["stiffness"], p["damping"], p["mass"]
        vp = protocol.segments[0].velocity

        def mu(v):
            return np.minimum(p["mu_s"], p["mu0"] - p["c"] * np.log(np.maximum(v, 1e-300) / p["v_ref"]))

        def rhs(t, y):  # y = (spring stretch s, slider velocity V)
            return [vp - y[1], (k * y[0] - sigma * mu(y[1]) - eta * y[1]) / m]

        def stops(t, y):
            return y[1]

        stops.terminal, stops.direction = True, -1
        v = vp if start is None else float(start)
        y, t, end, ts, ys = np.array([(sigma * mu(vp) + eta * vp) / k, v]), 0.0, protocol.duration, [], []
        while t < end:
            sol = solve_ivp(rhs, (t, end), y, rtol=1e-10, atol=[1e-14, 1e-14], events=stops, method="LSODA")
            ts.append(sol.t), ys.append(sol.y)
            t, y = float(sol.t[-1]), sol.y[:, -1]
            if sol.status == 1:  # stuck: the spring loads at K vp until it reaches the static peak
                t_go = min(end, t + max(sigma * p["mu_s"] / k - y[0], 0.0) / vp)
                y = np.array([y[0] + vp * (t_go - t), 0.0])
                ts.append([t_go]), ys.append(y[:, None])
                t = t_go
        time, (s, vel) = np.concatenate(ts), np.hstack(ys)
        return Run.from_trace(
            self.name, time, stress=k * s, friction=k * s / sigma, slider_velocity=vel,
            slider_position=vp * time - s + s[0], load_point_position=vp * time, floor=1e-7 * sigma,
        )  # fmt: skip

    def stability_boundary(self, fixed, x, y, frame=None):
        """V* = sigma c / eta (linear stability), as a line across the other axis."""
        if "pulling_velocity" not in (x, y):
            return []
        v_star = fixed.get("normal_stress", 1e3) * fixed.get("c", 0.01) / fixed.get("damping", 100.0)
        line, across = np.full(2, v_star), np.array([np.nan, np.nan])
        return [Boundary(line, across, "V0 = sigma c / eta") if x == "pulling_velocity" else Boundary(across, line, "")]


MODEL = VelocityWeakening()
P = VelocityWeakening.defaults
V_STAR = P["normal_stress"] * P["c"] / P["damping"]  # 0.1 m/s


@pytest.fixture(scope="module", autouse=True)
def registered():
    stickslip.register_model(MODEL, replace=True)
    yield
    unregister_model(MODEL.name)  # later tests (docs/models.md) register their own copy under the same name


def steady_stress(v0: float) -> float:
    return P["normal_stress"] * (P["mu0"] - P["c"] * math.log(v0 / P["v_ref"])) + P["damping"] * v0


def test_runs_from_python_and_settles_on_the_closed_form_steady_stress():
    v0 = 3 * V_STAR
    run = stickslip.run("velocity-weakening", None, stickslip.protocols.constant(v0, 2.0), start=1.1 * v0)
    assert run.regime.kind == "steady", run.regime.evidence
    assert run.stress[-1] == pytest.approx(steady_stress(v0), rel=1e-9)
    assert run.mean == pytest.approx(steady_stress(v0), rel=1e-6)


def test_the_ring_down_above_v_star_has_the_linear_period():
    """Just above V* the damping is small: many periods, each of 2 pi / sqrt(K/m - gamma^2)."""
    v0 = 1.05 * V_STAR
    run = stickslip.run(MODEL, None, stickslip.protocols.constant(v0, 1.5), start=1.02 * v0)
    gamma = (P["damping"] - P["normal_stress"] * P["c"] / v0) / (2 * P["mass"])
    period = 2 * math.pi / math.sqrt(P["stiffness"] / P["mass"] - gamma**2)
    assert run.regime.kind == "decaying oscillation", run.regime.evidence
    assert run.period == pytest.approx(period, rel=1e-3)
    assert run.regime.amplitude_ratio == pytest.approx(math.exp(-gamma * period), rel=2e-2)


def test_a_sweep_finds_the_closed_form_boundary_v_star():
    frame = stickslip.sweep(["pulling_velocity=0.03,0.07,0.14,0.3"], model=MODEL, duration=2.0, workers=0)
    assert list(frame["status"]) == ["ok"] * 4, list(frame["message"])
    below, above = frame[frame.pulling_velocity < V_STAR], frame[frame.pulling_velocity > V_STAR]
    assert set(below["regime"]) == {"stick-slip"}, list(frame["message"])
    assert set(above["regime"]) <= {"steady", "decaying oscillation"}, list(frame["message"])
    steady = above[above.regime == "steady"]
    assert not steady.empty
    np.testing.assert_allclose(steady["mean_stress"], [steady_stress(v) for v in steady.pulling_velocity], rtol=1e-6)
    # stick-slip: each stick ends at the static peak; the slider, released at rest, lets the spring load on a little
    assert (below["peak_stress"] > P["normal_stress"] * P["mu_s"]).all()
    assert (below["peak_stress"] < P["normal_stress"] * P["mu_s"] * 1.01).all()


def test_the_cli_sweeps_it_by_import_path(tmp_path, capsys):
    from cli_helpers import run_main

    out = tmp_path / "sweep"
    args = ["sweep", "--model", f"{__name__}:MODEL", "--vary", "pulling_velocity=0.05 m/s,0.3 m/s", "--duration",
            "2 s", "--set", "damping=100 Pa*s/m", "-o", str(out), "--workers", "0", "--quiet"]  # fmt: skip
    status, _, err = run_main(capsys, *args)
    assert status == 0, err
    frame, spec = stickslip.sweeps.load_sweep(out)
    assert spec.model == f"{__name__}:MODEL"
    assert list(frame["regime"]) == ["stick-slip", "steady"], list(frame["message"])
    status, _, err = run_main(capsys, "sweep", "--model", "velocity-weakening", "--vary", "nope=1", "-o",
                              str(tmp_path / "x"))  # fmt: skip
    assert status == 2 and err.count("\n") == 1 and "nope" in err, err


def test_it_refuses_what_it_declares_it_cannot_do():
    from stickslip.errors import ModelError

    with pytest.raises(ModelError, match="one constant pulling velocity only"):
        MODEL.run(MODEL.parameters(), stickslip.protocols.velocity_steps([0.1, 0.2], 1.0))
    with pytest.raises(ModelError, match="no velocity control"):
        MODEL.run(MODEL.parameters(), stickslip.protocols.constant(0.1, 1.0), Rig("velocity"))


def test_the_cli_sweeps_it_over_its_own_keys_with_their_units(tmp_path, capsys):
    """Issue 28 item 5: a plug-in's own keys (unknown to the package's column registry) are varied, their units
    come from the model's ``dimensions()`` into the Parquet metadata, and the phase diagram labels them."""
    import pyarrow.parquet as pq

    from cli_helpers import run_main

    out = tmp_path / "own"
    args = ["sweep", "--model", f"{__name__}:MODEL", "--vary", "mu0=0.4,0.55", "--vary", "damping=50 Pa*s/m,2 kPa*s/m",
            "--v0", "0.3 m/s", "--duration", "1 s", "-o", str(out), "--workers", "0", "--quiet"]  # fmt: skip
    status, _, err = run_main(capsys, *args)
    assert status == 0, err
    frame, _ = stickslip.sweeps.load_sweep(out)
    assert sorted(frame["damping"].unique()) == [50.0, 2000.0]  # SI, as written
    assert frame.attrs["units"]["mu0"] == "1" and frame.attrs["units"]["damping"] == "Pa s/m"
    schema = pq.read_schema(next(out.glob("part-*.parquet")))
    assert schema.field("damping").metadata == {b"unit": b"Pa s/m"}
    assert (frame["status"] == "ok").all(), list(frame["message"])
    # steady sliding where eta V0 > sigma c (V* = 0.1 m/s at eta = 100): the stress is the closed form
    steady = frame[frame["damping"] == 2000.0]
    expected = 1e3 * (steady["mu0"] - 0.01 * math.log(0.3 / 1e-3)) + 2000.0 * 0.3
    assert np.allclose(steady["mean_stress"], expected, rtol=1e-3)
    png = tmp_path / "own.png"
    status, _, err = run_main(capsys, "sweep", "plot", str(out), "--x", "mu0", "--y", "damping", "-o", str(png))
    assert status == 0 and png.stat().st_size > 0, err


def test_a_velocity_controlled_plugin_sweeps_under_velocity_control(tmp_path, capsys, monkeypatch):
    """A plug-in that declares no spring is driven directly (it used to fail every point: 'no spring control')."""
    from cli_helpers import run_main

    monkeypatch.syspath_prepend(str(__import__("pathlib").Path(__file__).parent))
    out = tmp_path / "viscous"
    status, _, err = run_main(
        capsys,
        "sweep",
        "--model",
        "viscous_model:MODEL",
        "--vary",
        "c=1 MPa*s/m,2 MPa*s/m",
        "--v0",
        "3 um/s",
        "--duration",
        "1 s",
        "-o",
        str(out),
        "--workers",
        "0",
        "--quiet",
    )
    assert status == 0, err
    frame, _ = stickslip.sweeps.load_sweep(out)
    assert (frame["status"] == "ok").all(), list(frame["message"])
    assert np.allclose(frame["mean_stress"], frame["c"] * 3e-6, rtol=1e-12)  # stress = c V exactly
    assert frame.attrs["units"]["c"] == "Pa s/m"
    import viscous_model

    viscous_model.forget()
