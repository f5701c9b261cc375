"""`stickslip sweep plot` over a sweep of three keys: the third key's points never cover each other unsaid, a
number in colour gets a colour bar and no leaked legend warning, and a settled run of a plug-in counts no cycles.

The model is the plug-in of docs/models.md (velocity-weakening friction on a spring-slider): at V0 = 0.03 m/s it
sticks and slips for mu0 = 0.55 and is undetermined for mu0 = 0.4, at 0.3 m/s it settles (after decayed periods).
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path
from typing import ClassVar

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

import stickslip
from cli_helpers import run_main
from stickslip.errors import ParameterError
from stickslip.models import Capabilities, FrictionModel, Run
from stickslip.plots.sweeps import plot_phase_diagram
from stickslip.sweeps import load_sweep
from stickslip.units import to_si


class VelocityWeakening(FrictionModel):
    """docs/models.md's plug-in, as a user writes it."""

    name = "velocity-weakening"
    description = "spring-slider, mu = mu0 - c ln(V/Vr) with a static peak"
    capabilities = Capabilities(controls=("spring",), protocols="constant", damping=True, mass=True)
    start_dimension = "velocity"
    defaults: ClassVar[dict[str, float]] = dict(
        mu0=0.5, c=0.01, v_ref=1e-3, mu_s=0.6, normal_stress=1e3, stiffness=1e4, damping=100.0, mass=1.0
    )

    def sweep_start(self, protocol):
        return 1.1 * protocol.segments[0].velocity

    def dimensions(self):
        return {"mu0": "dimensionless", "c": "dimensionless", "v_ref": "velocity", "mu_s": "dimensionless",
                "normal_stress": "stress", "stiffness": "stress_per_length", "damping": "stress_per_velocity",
                "mass": "mass_per_area"}  # fmt: skip

    def parameters(self, spec=None, overrides=None):
        values = dict(self.defaults if spec is None else spec)
        for key, raw in (overrides or {}).items():
            if key not in self.dimensions():
                raise ParameterError(f"{key}: unknown key; expected one of {', '.join(self.defaults)}")
            values[key] = to_si(raw, self.dimensions()[key], key)
        return values

    def values(self, params):
        return dict(params)

    def run(self, params, protocol, rig=None, *, start=None, **settings):
        rig = self.check(protocol, rig, settings)
        p = dict(params)
        for key, value in (("stiffness", rig.stiffness), ("damping", rig.damping), ("mass", rig.mass)):
            p[key] = p[key] if value is None else value
        sigma, k, eta, m, vp = (
            p["normal_stress"],
            p["stiffness"],
            p["damping"],
            p["mass"],
            protocol.segments[0].velocity,
        )

        def mu(v):
            return np.minimum(p["mu_s"], p["mu0"] - p["c"] * np.log(np.maximum(v, 1e-300) / p["v_ref"]))

        def rhs(t, y):
            return [vp - y[1], (k * y[0] - sigma * mu(y[1]) - eta * y[1]) / m]

        def stops(t, y):
            return y[1]

        stops.terminal, stops.direction = True, -1
        y, t, ts, ys = np.array([(sigma * mu(vp) + eta * vp) / k, start or vp]), 0.0, [], []
        while t < protocol.duration:
            sol = solve_ivp(rhs, (t, protocol.duration), y, rtol=1e-10, atol=1e-14, events=stops, method="LSODA")
            ts.append(sol.t), ys.append(sol.y)
            t, y = float(sol.t[-1]), sol.y[:, -1]
            if sol.status == 1:
                t_go = min(protocol.duration, t + max(sigma * p["mu_s"] / k - y[0], 0.0) / vp)
                y = np.array([y[0] + vp * (t_go - t), 0.0])
                ts.append([t_go]), ys.append(y[:, None])
                t = t_go
        time, (s, v) = np.concatenate(ts), np.hstack(ys)
        return Run.from_trace(
            self.name, time, stress=k * s, friction=k * s / sigma, slider_velocity=v,
            slider_position=vp * time - s + s[0], load_point_position=vp * time, floor=1e-7 * sigma,
        )  # fmt: skip


MODEL = VelocityWeakening()


@pytest.fixture(scope="module")
def three_keys(tmp_path_factory) -> Path:
    """The tester's sweep: 2 x 2 x 2 points over pulling_velocity, damping and mu0."""
    folder = tmp_path_factory.mktemp("overlap") / "swp"
    here = str(Path(__file__).parent)
    sys.path.insert(0, here)
    try:
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(sys, "argv", ["stickslip"])
            args = ["sweep", "--model", f"{__name__}:MODEL", "--vary", "pulling_velocity=0.03 m/s,0.3 m/s",
                    "--vary", "damping=50 Pa*s/m,200 Pa*s/m", "--vary", "mu0=0.4,0.55", "--duration", "2 s",
                    "-o", str(folder), "--workers", "0", "--quiet"]  # fmt: skip
            with pytest.raises(SystemExit) as exit_info:
                stickslip.cli.main.main(args)
            assert exit_info.value.code == 0
    finally:
        sys.path.remove(here)
    return folder


def _regimes(frame: pd.DataFrame) -> dict[tuple[float, float, float], str]:
    return {(r.pulling_velocity, r.damping, r.mu0): r.regime for r in frame.itertuples()}


def test_the_third_key_gets_a_panel_per_value_and_the_command_says_so(three_keys, tmp_path, capsys):
    frame, spec = load_sweep(three_keys)
    regimes = _regimes(frame)
    # the case the tester saw: the same (V0, eta) is stick-slip at one mu0 and not at the other
    assert regimes[(0.03, 50.0, 0.55)] == "stick-slip" and regimes[(0.03, 50.0, 0.4)] != "stick-slip"
    ax = plot_phase_diagram(frame, spec, x="pulling_velocity", y="damping", color="regime")
    panels = [a for a in ax.figure.axes if a.get_visible() and a.get_title()]
    assert [a.get_title() for a in panels] == ["mu0 = 0.4", "mu0 = 0.55"]
    suptitle = ax.figure.get_suptitle()
    assert "a panel per value of mu0 (0.4, 0.55)" in suptitle and "8 points" in suptitle
    # each panel holds its own four cells: no point lies under another
    assert [int(np.isfinite(a.collections[0].get_array()).sum()) for a in panels] == [4, 4]
    assert "stick-slip" in [t.get_text() for t in ax.get_legend().get_texts()]
    image = tmp_path / "swp.png"
    status, out, err = run_main(capsys, "sweep", "plot", str(three_keys), "--x", "pulling_velocity", "--y",
                                "damping", "-o", str(image))  # fmt: skip
    assert status == 0 and err == "" and image.stat().st_size > 0
    assert out.strip() == f"phase diagram: {image} (a panel per value of mu0 (0.4, 0.55))"


def test_at_picks_one_value_of_the_third_key(three_keys, tmp_path, capsys):
    image = tmp_path / "one.png"
    status, out, err = run_main(capsys, "sweep", "plot", str(three_keys), "--x", "pulling_velocity", "--y",
                                "damping", "--at", "mu0=0.55", "-o", str(image))  # fmt: skip
    assert status == 0 and err == "" and out.strip() == f"phase diagram: {image}"
    frame, spec = load_sweep(three_keys)
    ax = plot_phase_diagram(frame, spec, x="pulling_velocity", y="damping", at={"mu0": 0.55})
    assert "at mu0 = 0.55" in ax.get_title() and len(ax.figure.axes) == 1
    status, _, err = run_main(capsys, "sweep", "plot", str(three_keys), "--y", "damping", "--at", "mu0=0.5")
    assert status == 2 and "no point of the sweep has that value" in err and "0.4, 0.55" in err
    assert err.count("\n") == 1


def test_too_many_values_of_the_other_keys_are_refused_naming_at(three_keys):
    frame, spec = load_sweep(three_keys)
    many = pd.concat([frame.assign(mu0=frame["mu0"] + 0.01 * i) for i in range(4)], ignore_index=True)  # 8 values
    with pytest.raises(ParameterError, match=r"also varies mu0 \(8 combinations.*--at mu0="):
        plot_phase_diagram(many, spec, x="pulling_velocity", y="damping")
    with pytest.raises(ParameterError, match="give no ax, or pick values with --at"):  # no room for panels
        plot_phase_diagram(frame, spec, x="pulling_velocity", y="damping", ax=plot_phase_diagram(
            frame, spec, x="pulling_velocity", y="damping", at={"mu0": "0.4"}))  # fmt: skip


def test_points_at_distinct_places_stay_in_one_panel_whose_title_names_the_projected_key(three_keys):
    frame, spec = load_sweep(three_keys)
    scattered = frame.assign(pulling_velocity=frame["pulling_velocity"] * (1 + 0.01 * np.arange(len(frame))))
    ax = plot_phase_diagram(scattered, spec, x="pulling_velocity", y="damping")
    assert len(ax.figure.axes) == 1 and "not shown on the axes: mu0 (0.4, 0.55)" in ax.get_title()


def test_a_number_in_colour_gets_a_colour_bar_and_no_legend_warning(three_keys, tmp_path, capsys):
    frame, spec = load_sweep(three_keys)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # matplotlib's "No artists with labels found to put in legend" leaked
        ax = plot_phase_diagram(frame[frame["mu0"] == 0.55], spec, x="pulling_velocity", y="damping",
                                color="mean_stress")  # fmt: skip
    assert ax.get_legend() is None and any(a.get_ylabel().startswith("mean_stress (Pa)") for a in ax.figure.axes)
    image = tmp_path / "stress.png"
    status, _, err = run_main(capsys, "sweep", "plot", str(three_keys), "--x", "pulling_velocity", "--y", "damping",
                              "--color", "mean_stress", "-o", str(image))  # fmt: skip
    assert status == 0 and err == ""
    # one colour scale over both panels: the same colour is the same stress in each
    panels = [a for a in plot_phase_diagram(frame, spec, "pulling_velocity", "damping", "mean_stress").figure.axes
              if a.get_title()]  # fmt: skip
    assert len({(a.collections[0].norm.vmin, a.collections[0].norm.vmax) for a in panels}) == 1


def test_a_settled_plugin_run_counts_no_cycles(three_keys):
    """Decayed periods are not stick-slip cycles: 0, as the bond models report for steady rows."""
    frame, _ = load_sweep(three_keys)
    assert (frame.loc[frame["regime"] == "steady", "cycles"] == 0).all()
    assert (frame.loc[frame["regime"] == "stick-slip", "cycles"] > 0).all()
