"""Round 30: ``stickslip analyze`` on what plug-in models write with ``run -o``.

D1: the docs' velocity-weakening plug-in (docs/models.md) writes each stick as its two ends, 0.46 s apart among
slips sampled every 1e-6 s; analyze read each stick as a gap ("4 gap(s) in the record", 6 cycles, 0 complete,
σc = σs = 600 Pa, stick slopes 186/202 Pa/s).  A long interval across which the record runs straight is no gap;
one that lost samples (NaN rows) or hides a drop still is.
D2: a Run CSV with a plug-in's state column (``theta [s]``, which Run.read reads) was refused ("unknown column
'theta'"); its extra columns are ignored with a note naming them, as the built-in models' are.  A plain record
with an unknown column is still refused.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from cli_helpers import run_main
from stickslip.analysis import detect, read_trace
from stickslip.models.run import Run

# ------------------------------------------------------------------------ D1: the docs' velocity-weakening plug-in
#: the class of docs/models.md, verbatim (as a user copies it into a module of their own)
PLUGIN = """\
import numpy as np
from scipy.integrate import solve_ivp

import stickslip
from stickslip.errors import ParameterError
from stickslip.models import Capabilities, FrictionModel, Run
from stickslip.units import to_si


class VelocityWeakening(FrictionModel):
    name = "velocity-weakening"
    description = "spring-slider, mu = mu0 - c ln(V/Vr) with a static peak"
    capabilities = Capabilities(controls=("spring",), protocols="constant", damping=True, mass=True)
    start_dimension = "velocity"  # --start "0.33 m/s": the slider's velocity at t = 0
    defaults = dict(mu0=0.5, c=0.01, v_ref=1e-3, mu_s=0.6, normal_stress=1e3, stiffness=1e4, damping=100.0, mass=1.0)

    def sweep_start(self, protocol):  # a sweep starts each point 10 % off steady sliding
        return 1.1 * protocol.segments[0].velocity

    def dimensions(self):
        return {"mu0": "dimensionless", "c": "dimensionless", "v_ref": "velocity", "mu_s": "dimensionless",
                "normal_stress": "stress", "stiffness": "stress_per_length", "damping": "stress_per_velocity",
                "mass": "mass_per_area"}

    def parameters(self, spec=None, overrides=None):
        values = dict(self.defaults if spec is None else spec)
        for key, raw in (overrides or {}).items():
            if key not in self.dimensions():
                raise ParameterError(f"{key}: unknown key; expected one of {', '.join(self.defaults)}")
            values[key] = to_si(raw, self.dimensions()[key], key)
        for key in ("v_ref", "normal_stress", "stiffness", "mass"):  # the equations divide by them
            if not values[key] > 0:
                raise ParameterError(f"{key}: expected a positive value, got {values[key]:g}")
        return values

    def values(self, params):
        return dict(params)

    def run(self, params, protocol, rig=None, *, start=None, **settings):
        rig = self.check(protocol, rig, settings)  # refuses what capabilities do not cover
        p = dict(params)
        for key, value in (("stiffness", rig.stiffness), ("damping", rig.damping), ("mass", rig.mass)):
            p[key] = p[key] if value is None else value
        sigma, k, eta, m, vp = p["normal_stress"], p["stiffness"], p["damping"], p["mass"], protocol.segments[0].velocity

        def mu(v):
            return np.minimum(p["mu_s"], p["mu0"] - p["c"] * np.log(np.maximum(v, 1e-300) / p["v_ref"]))

        def rhs(t, y):  # y = (spring stretch, slider velocity)
            return [vp - y[1], (k * y[0] - sigma * mu(y[1]) - eta * y[1]) / m]

        def stops(t, y):
            return y[1]

        stops.terminal, stops.direction = True, -1
        y, t, ts, ys = np.array([(sigma * mu(vp) + eta * vp) / k, start or vp]), 0.0, [], []
        said = {}
        while t < protocol.duration:
            sol = solve_ivp(rhs, (t, protocol.duration), y, rtol=1e-10, atol=1e-14, events=stops, method="LSODA")
            ts.append(sol.t), ys.append(sol.y)
            t, y = float(sol.t[-1]), sol.y[:, -1]
            if sol.status == -1:  # the integrator gave up: the run up to there, failed, and why
                said = dict(status="failed", message=f"{self.name}: {sol.message} at t = {t:.6g} s")
                break
            if sol.status == 1:  # stuck until the spring reaches the static peak
                t_go = min(protocol.duration, t + max(sigma * p["mu_s"] / k - y[0], 0.0) / vp)
                y = np.array([y[0] + vp * (t_go - t), 0.0])
                ts.append([t_go]), ys.append(y[:, None])
                t = t_go
        time, (s, v) = np.concatenate(ts), np.hstack(ys)
        # protocol: the regime and mean are read over its last segment; floor: this solver's accuracy, in Pa
        return Run.from_trace(self.name, time, stress=k * s, friction=k * s / sigma, slider_velocity=v,
                              slider_position=vp * time - s + s[0], load_point_position=vp * time,
                              protocol=protocol, floor=1e-7 * sigma, **said)


"""  # noqa: E501 (verbatim)

MU_S, SIGMA_N, K, V0 = 0.6, 1e3, 1e4, 0.03  # its defaults (Pa, Pa/m) and the run's pulling velocity (m/s)


@pytest.fixture(scope="module")
def plugin_run(tmp_path_factory):
    """The run of tester U's report: ``run --model vwdoc:VelocityWeakening --v0 "30 mm/s" --duration "2 s"
    --start "33 mm/s" -o d3.csv``; (path, analyze --json's output, its stderr)."""
    import sys

    folder = tmp_path_factory.mktemp("vwplugin")
    (folder / "vwdoc_r30.py").write_text(PLUGIN, encoding="utf-8")
    sys.path.insert(0, str(folder))
    try:
        capsys = _Capture()
        path = folder / "d3.csv"
        code, _, err = capsys.main("run", "--model", "vwdoc_r30:VelocityWeakening", "--v0", "30 mm/s", "--duration",
                                   "2 s", "--start", "33 mm/s", "-o", str(path))  # fmt: skip
        assert code == 0, err
        code, out, err = capsys.main("analyze", str(path), "--json")
        assert code == 0, err
    finally:
        sys.path.remove(str(folder))
    return path, json.loads(out), err


class _Capture:
    """main() in-process for a module-scoped fixture (pytest's capsys is function-scoped)."""

    def main(self, *args: str) -> tuple[int, str, str]:
        import contextlib
        import io

        from stickslip.cli.main import main

        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), pytest.raises(SystemExit) as info:
            main(list(args))
        return int(info.value.code), out.getvalue(), err.getvalue()


def _model_sticks(path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The sticks as the model wrote them: each is one interval longer than 0.1 s (the model's stop event, then
    the row where the spring reaches σn·μs).  Returns (start times, start stresses, end times)."""
    frame = pd.read_csv(path, skiprows=1)
    t, s = frame["time [s]"].to_numpy(), frame["stress [Pa]"].to_numpy()
    k = np.flatnonzero(np.diff(t) > 0.1)
    return t[k], s[k], t[k + 1]


def test_the_plugin_s_sticks_are_no_gaps_and_its_cycles_are_the_run_s(plugin_run):
    path, data, err = plugin_run
    assert "gap" not in err, err
    assert "not straight lines" not in err, err
    starts, low, ends = _model_sticks(path)
    assert starts.size == 4  # the model's four sticks (the last cut by the record's end)
    cycles = data["cycles"]
    assert len(cycles) == 4
    assert [c["complete"] for c in cycles] == [True, True, True, False]
    for j, cycle in enumerate(cycles):
        # closed forms: the stick is the spring loaded at K·V0 = 300 Pa/s, up to the static peak σn·μs = 600 Pa
        assert cycle["stick_slope"] == pytest.approx(K * V0, rel=2e-3)
        # the model's own stick start (where the slider stops: 462.45 Pa after the start at 0.033 m/s, then 414.03)
        assert cycle["critical_stress"] == pytest.approx(low[j], rel=1e-3)
        if cycle["complete"]:
            assert cycle["peak_stress"] == pytest.approx(MU_S * SIGMA_N, abs=0.2)
            assert cycle["stick_time"] == pytest.approx(ends[j] - starts[j], rel=2e-3)
            # (cycle 1's start, after the start-up slip, is read 0.6 ms early: its hinge meets a slower corner)
            assert cycle["period"] == pytest.approx(starts[j + 1] - starts[j], rel=1e-4 if j else 2e-3)
    # the repeating cycles' period is the run's own (its regime, from the peaks)
    meta = json.loads(path.read_text().splitlines()[0].partition(" run ")[2])
    assert cycles[2]["period"] == pytest.approx(meta["regime"]["period"], rel=1e-4)


# ----------------------------------------------------------------------------- D1: detect.gaps on its own
def _two_sample_stick(hidden_drop: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """A line rising at 300 Pa/s sampled every 1 ms for 0.1 s, then nothing for 0.5 s, then 0.1 s more; with
    ``hidden_drop`` the record after the interval lies that far below the line (a slip hidden in it)."""
    left = np.arange(0.0, 0.1, 1e-3)
    right = 0.6 + np.arange(0.0, 0.1, 1e-3)
    t = np.concatenate([left, right])
    x = 400.0 + 300.0 * t
    x[left.size :] -= hidden_drop
    return t, x


def test_a_straight_interval_is_no_gap_but_a_hidden_drop_or_nan_rows_are():
    t, x = _two_sample_stick()
    step = detect.sampling_step(t)
    k = 99  # the interval after the left stretch's last sample
    assert list(detect.gaps(t, step)) == [k]  # by the sampling alone: a gap
    assert detect.gaps(t, step, x, 1e-3).size == 0  # the record runs straight across it
    holes = np.zeros(t.size - 1, dtype=bool)
    holes[k] = True  # NaN rows inside it: the record says it lost samples there
    assert list(detect.gaps(t, step, x, 1e-3, holes=holes)) == [k]
    for drop in (150.0, 20.0):  # a slip hidden in it (the chord's slope 300 - drop/0.5 s)
        t, x = _two_sample_stick(drop)
        assert list(detect.gaps(t, step, x, 1e-3)) == [k], drop


def test_a_noisy_interval_too_short_to_tell_stays_a_gap():
    """With noise, the sides must show the chord's slope to 10 %: a rise of 150 Pa across the interval against
    3 Pa of noise (50 noise levels, under the 80 it needs) cannot be told from a hidden slip."""
    t, x = _two_sample_stick()
    x = x + 3.0 * np.random.default_rng(2).standard_normal(t.size)
    assert list(detect.gaps(t, detect.sampling_step(t), x, 3.0)) == [99]


# --------------------------------------------------------------------------------- D2: a plug-in's state column
LOW, HIGH, SLOPE, V_PULL = 257.4, 549.7, 18.4, 50e-6  # Pa, Pa, Pa/s, m/s


def _sawtooth_run(path) -> None:
    """A Run CSV of a sawtooth (sticks from LOW to HIGH at SLOPE, slips of 0.5 s) at 20 Hz, with a state column
    ``theta [s]`` as a plug-in's run -o writes it."""
    t = np.arange(0.0, 100.0, 0.05)
    stick = (HIGH - LOW) / SLOPE
    period = stick + 0.5
    phase = np.mod(t, period)
    x = np.where(phase <= stick, LOW + SLOPE * phase, HIGH - (HIGH - LOW) * (phase - stick) / 0.5)
    run = Run.from_trace(
        "log-strengthening", t, stress=x, slider_velocity=np.zeros_like(t), slider_position=np.zeros_like(t),
        load_point_position=V_PULL * t, states={"theta": 0.1 + phase}, state_units={"theta": "s"},
    )  # fmt: skip
    run.to_csv(path)


def test_a_run_csv_with_a_state_column_is_analysed_and_the_column_named(capsys, tmp_path):
    path = tmp_path / "state.csv"
    _sawtooth_run(path)
    assert "theta [s]" in path.read_text().splitlines()[1]
    assert "theta" in Run.read(path).states  # what Run.read reads ...
    code, out, err = run_main(capsys, "analyze", str(path), "--json")  # ... analyze reads (V0 from the load point)
    assert code == 0, err
    ignored = [line for line in err.splitlines() if "ignored column(s)" in line]
    assert len(ignored) == 1 and "theta" in ignored[0], err
    data = json.loads(out)
    complete = [c for c in data["cycles"] if c["complete"]]
    assert len(complete) >= 4
    for cycle in complete:
        assert cycle["stick_slope"] == pytest.approx(SLOPE, rel=1e-3)
        assert cycle["critical_stress"] == pytest.approx(LOW, abs=0.5)
        assert cycle["peak_stress"] == pytest.approx(HIGH, abs=0.5)
    assert read_trace(path).time.size == 2000


def test_a_plain_record_with_an_unknown_column_is_still_refused(capsys, tmp_path):
    path = tmp_path / "lab.csv"
    t = np.arange(0.0, 10.0, 0.05)
    rows = [f"{a:.2f},{300 + 10 * math.sin(a):.4f},0.1" for a in t]
    path.write_text("time [s],stress [Pa],theta [s]\n" + "\n".join(rows) + "\n", encoding="utf-8")
    code, _, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s")
    assert code == 2
    assert "unknown column 'theta'" in err, err
    assert "Traceback" not in err
