"""Round 29 (tester T, lab-style DAQ records): curved sticks (D2), the steady mean's standard error and window
(D3), the steady curve for `fit steady` (D4), a quantised load-point column (D6).

Every record is built here from the package's quasi-static solution (stickslip.quasistatic.cycle.simulate), whose
corners, stick times and steady stresses are the truth, with AR(1) noise (coefficient 0.8) and, where said, the
2 mN steps of a force logger over 5 cm^2 (4 Pa).
"""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pandas as pd
import pytest
from scipy.signal import lfilter

from cli_helpers import run_main
from stickslip import load_parameters
from stickslip.analysis import analyze_trace
from stickslip.quasistatic.cycle import simulate

PHI = 0.8  # AR(1) coefficient of the noise, per millisecond
NOISE = 3.0  # Pa, the noise's standard deviation
STEP = 4.0  # Pa: 2 mN over 5 cm^2


@pytest.fixture(scope="module")
def gelatin():
    return load_parameters("gelatin-glass")


def red_noise(size: int, seed: int, phi: float = PHI, sigma: float = NOISE) -> np.ndarray:
    """Stationary AR(1) noise of standard deviation ``sigma``."""
    rng = np.random.default_rng(seed)
    shocks = rng.standard_normal(size) * sigma * math.sqrt(1.0 - phi**2)
    shocks[0] = rng.standard_normal() * sigma
    return lfilter([1.0], [1.0, -phi], shocks)


# --------------------------------------------------------------------------- D2: curved sticks
BEND = 0.5  # the stick slope rises from (1 - BEND) to (1 + BEND) times its mean within each stick


def bent_record(gelatin, bend: float, seed: int):
    """The model's 50 um/s cycles at 500 Hz with each stick bent: sigma = sigma_c + drop (u + bend (u^2 - u)),
    u = (t - start) / t_s (the same corners and stick times), AR(1) noise, quantised; and the simulation."""
    sim = simulate(gelatin, 50e-6, 100.0)
    t = np.arange(4.0, 96.0, 2e-3)  # starts and ends mid-stick
    x = np.interp(t, sim.time, sim.stress)
    for c in sim.cycles:
        if c.stick_time is None:
            continue
        u = (t - c.start_time) / c.stick_time
        inside = (u >= 0) & (u <= 1)
        rise = c.peak_stress - c.start_stress
        x[inside] = c.start_stress + rise * (u[inside] + bend * (u[inside] ** 2 - u[inside]))
    x = x + red_noise(t.size, seed, phi=PHI**2)  # 0.8 per ms is 0.64 per 2 ms
    return t, np.round(x / STEP) * STEP, sim


def test_curved_sticks_are_said_and_their_corners_found(gelatin):
    """Before: the curvature was read as noise (8.0 Pa for 3.3), the corners moved into the sticks (t_s 9.65 s for
    12.59 s in the tester's record), nothing said but a "velocity step" blamed on a cut stick."""
    t, x, sim = bent_record(gelatin, BEND, seed=5)
    _, straight_x, _ = bent_record(gelatin, 0.0, seed=5)
    bent, straight = analyze_trace(t, x, 50e-6, gelatin), analyze_trace(t, straight_x, 50e-6, gelatin)
    assert bent.regime == straight.regime == "stick-slip"
    assert bent.noise == pytest.approx(straight.noise, rel=0.15)  # the bend is not noise
    complete = [c for c in bent.cycles if c.complete]
    assert len(complete) >= 3
    starts = np.array([c.start_time for c in sim.cycles])
    for cycle in complete:
        model = sim.cycles[int(np.argmin(np.abs(starts - cycle.start_time)))]
        drop = model.peak_stress - model.start_stress
        assert cycle.stick_time == pytest.approx(model.stick_time, rel=0.01)
        assert abs(cycle.critical_stress - model.start_stress) < 0.01 * drop
        assert abs(cycle.peak_stress - model.peak_stress) < 0.01 * drop
        assert cycle.slip_time == pytest.approx(model.slip_time, rel=0.05)
        assert cycle.stick_curved
        # d2sigma/dt2 = 2 bend drop / t_s^2; the mean slope is the model's K V0 = drop / t_s
        assert cycle.stick_curvature == pytest.approx(2 * BEND * drop / model.stick_time**2, rel=0.1)
        assert cycle.stick_slope == pytest.approx(drop / model.stick_time, rel=0.02)
    said = [w for w in bent.warnings if "not straight lines" in w]
    assert len(said) == 1 and "times the noise" in said[0]
    assert not any("velocity step" in w for w in bent.warnings)  # the cut sticks' slopes are parts of a bend
    # the straight record: nothing curved, nothing said
    assert not any(c.stick_curved for c in straight.cycles)
    assert not any("not straight" in w or "velocity step" in w for w in straight.warnings)


def test_straight_sticks_with_quantised_red_noise_and_drift_are_not_curved(gelatin):
    """No false alarm: straight sticks with AR(1) noise, 4 Pa steps and a slow drift (0.02 Pa/s)."""
    for seed in (11, 12, 13):
        t, x, _ = bent_record(gelatin, 0.0, seed=seed)
        x = np.round((x + 0.02 * (t - t[0])) / STEP) * STEP
        result = analyze_trace(t, x, 50e-6, gelatin)
        assert result.regime == "stick-slip"
        assert not any(c.stick_curved for c in result.cycles)
        measured = [c for c in result.cycles if c.stick_curvature_stderr]
        # the curvature's standard error is honest under the correlated noise: no stick is 5 of them off zero
        assert all(abs(c.stick_curvature) < 5 * c.stick_curvature_stderr for c in measured)
        assert not any("not straight" in w for w in result.warnings)


# --------------------------------------------------------------------------- D3: steady mean and its error
SEEDS = 30


@pytest.fixture(scope="module")
def steady_runs(gelatin):
    """30 seeds of a 60 s record of the model's start-up at 150 um/s (stick, slip, relaxation to steady sliding)
    at 1 kHz with AR(1) noise, each analysed at 1 kHz and at 500 Hz (every other sample)."""
    sim = simulate(gelatin, 150e-6, 60.0)
    t = np.arange(0.0, 60.0, 1e-3)
    clean = np.interp(t, sim.time, sim.stress)
    runs = []
    for seed in range(SEEDS):
        x = clean + red_noise(t.size, 700 + seed)
        runs.append(tuple(analyze_trace(t[::k], x[::k], 150e-6, gelatin).summary for k in (1, 2)))
    return sim, runs


def ar1_sem(samples: int, phi: float) -> float:
    """Standard error of the mean of ``samples`` of stationary AR(1) noise (closed form)."""
    n = samples
    factor = (1 + phi) / (1 - phi) - 2 * phi * (1 - phi**n) / (n * (1 - phi) ** 2)
    return NOISE * math.sqrt(factor / n)


def test_steady_sem_is_honest_under_correlated_noise_at_any_rate(steady_runs):
    """Before: stress_sem sd/sqrt(n), 3 times too small for phi = 0.8 and sqrt(2) larger at 500 Hz."""
    _, runs = steady_runs
    for k, phi in ((0, PHI), (1, PHI**2)):
        summaries = [run[k] for run in runs]
        assert all(s["regime"] == "steady" for s in summaries)
        ratios = [s["stress_sem"] / ar1_sem(s["steady_samples"], phi) for s in summaries]
        assert 0.85 < float(np.median(ratios)) < 1.15
        means = np.array([s["mean_stress"] for s in summaries])
        scatter = float(np.std(means, ddof=1))
        assert 0.7 < scatter / float(np.median([s["stress_sem"] for s in summaries])) < 1.4
    # one run read at 1 kHz and at 500 Hz: one error, one mean
    sems = np.array([[run[k]["stress_sem"] for k in (0, 1)] for run in runs])
    assert float(np.median(sems[:, 1] / sems[:, 0])) == pytest.approx(1.0, abs=0.1)
    for fast, slow in runs:
        assert abs(fast["mean_stress"] - slow["mean_stress"]) < 0.5 * fast["stress_sem"]


def test_steady_window_starts_where_the_relaxation_is_below_the_error(steady_runs):
    """Before: the window began where the relaxation was still 4.7-6.7 Pa above the final stress (the tester's
    hydrogel) and the mean was biased by 14 standard errors on white noise."""
    sim, runs = steady_runs
    final = float(sim.stress[-1])
    for fast, slow in runs:
        for summary in (fast, slow):
            left = float(np.interp(summary["steady_from"], sim.time, sim.stress)) - final
            assert abs(left) < 2.0 * summary["stress_sem"]
    bias = np.array([run[0]["mean_stress"] for run in runs]) - final
    assert abs(float(np.mean(bias))) < 3.0 * float(np.std(bias, ddof=1)) / math.sqrt(SEEDS)


# --------------------------------------------------------------------------- D4: the steady curve for fit steady
STEADY_VELOCITIES = (150, 200, 300, 500, 800, 2000)  # um/s, all above Vc = 124.1 um/s: steady sliding


def test_steady_table_of_several_records_is_what_fit_steady_reads(gelatin, tmp_path, capsys):
    """Before: no way from steady records to `fit steady` (analyze -o wrote the start-up cycle, mean_stress was
    only in the JSON, and analyze took one trace)."""
    names, truth = [], {}
    for k, v in enumerate(STEADY_VELOCITIES):
        sim = simulate(gelatin, v * 1e-6, 60.0)
        t = np.arange(0.0, 60.0, 2e-3)
        x = np.interp(t, sim.time, sim.stress) + red_noise(t.size, 40 + k, phi=PHI**2)
        path = tmp_path / f"r{v}.csv"
        pd.DataFrame({"time [s]": t, "stress [Pa]": x}).to_csv(path, index=False)
        names.append(str(path))
        truth[v] = float(sim.stress[-1])
    table = tmp_path / "steady.csv"
    v0s = [arg for v in STEADY_VELOCITIES for arg in ("--v0", f"{v} um/s")]
    code, _, err = run_main(capsys, "analyze", *names, *v0s, "--steady-table", str(table))
    assert code == 0, err
    read = pd.read_csv(table)
    assert list(read.columns) == ["velocity [m/s]", "stress [Pa]", "stress_err [Pa]"]
    assert read["velocity [m/s]"].tolist() == pytest.approx([v * 1e-6 for v in STEADY_VELOCITIES], rel=1e-12)
    for (_, stress, error), v in zip(read.itertuples(index=False), STEADY_VELOCITIES, strict=True):
        assert 0.02 < error < 0.2  # AR(1) at 500 Hz over ~40 s: ~0.06 Pa
        assert abs(stress - truth[v]) < 4 * error
    code, out, err = run_main(capsys, "fit", "steady", str(table), "--json")
    assert code == 0, err
    assert json.loads(out)["status"] == "ok"
    # a record that is no steady sliding has no point on the curve: refused, naming it
    sim = simulate(gelatin, 50e-6, 60.0)
    t = np.arange(0.0, 60.0, 2e-2)
    pd.DataFrame({"time [s]": t, "stress [Pa]": np.interp(t, sim.time, sim.stress)}).to_csv(
        tmp_path / "r50.csv", index=False
    )
    code, _, err = run_main(
        capsys, "analyze", names[0], str(tmp_path / "r50.csv"), "--v0", "150 um/s", "--v0", "50 um/s",
        "--steady-table", str(tmp_path / "mixed.csv"),
    )  # fmt: skip
    assert code == 2 and "r50.csv is stick-slip" in err and not (tmp_path / "mixed.csv").exists()
    code, _, err = run_main(capsys, "analyze", *names[:2], "--v0", "150 um/s", "--steady-table", str(table))
    assert code == 2 and "one per trace" in err


# --------------------------------------------------------------------------- D6: a quantised load point
def lab_record(path, quantum_mm: float, velocities=(50e-6, 50e-6)) -> None:
    """A force record at 1 kHz with a load-point column in mm rounded to ``quantum_mm``, moving at velocities[0]
    for the first half and velocities[1] for the second."""
    t = np.arange(0.0, 60.0, 1e-3)
    half = t[t.size // 2]
    position = np.where(t < half, velocities[0] * t, velocities[0] * half + velocities[1] * (t - half))
    rng = np.random.default_rng(3)
    force = 0.15 + 1e-2 * np.sin(t) + 1.5e-3 * rng.standard_normal(t.size)
    frame = pd.DataFrame(
        {
            "Time (s)": np.round(33651.567 + t, 4),
            "Force (N)": np.round(force / 2e-3) * 2e-3,
            "load_point_position (mm)": np.round(position * 1e3 / quantum_mm) * quantum_mm,
        }
    )
    frame.to_csv(path, index=False)


@pytest.mark.parametrize("quantum_mm", [1e-3, 1e-4])
def test_a_quantised_load_point_gives_the_pulling_velocity(tmp_path, capsys, quantum_mm):
    """Before: refused, "does not move at one velocity throughout" (exit 2; with --v0 only warned)."""
    path = tmp_path / "lab.csv"
    lab_record(path, quantum_mm)
    code, out, err = run_main(capsys, "analyze", str(path), "--contact-area", "5 cm^2", "--json")
    assert code == 0, err
    said = re.search(r"load point moves at ([0-9.]+) µm/s throughout", err)
    assert said and float(said.group(1)) == pytest.approx(50.0, rel=1e-4)
    assert json.loads(out)["pulling_velocity"] == pytest.approx(50e-6, rel=1e-4)
    code, _, err = run_main(capsys, "analyze", str(path), "--contact-area", "5 cm^2", "--v0", "50 um/s")
    assert code == 0 and "does not move at one velocity" not in err


@pytest.mark.parametrize("second", [55e-6, 51e-6])
def test_a_quantised_load_point_that_steps_velocity_is_still_refused(tmp_path, capsys, second):
    path = tmp_path / "step.csv"
    lab_record(path, 1e-3, velocities=(50e-6, second))
    code, _, err = run_main(capsys, "analyze", str(path), "--contact-area", "5 cm^2")
    assert code == 2 and "does not move at one velocity throughout" in err
