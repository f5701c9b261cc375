"""Round 28: ``stickslip analyze`` on what the package's own runs write, and on slips faster than the sampling.

A1: a Run CSV whose rows repeat in every column (a solver that stops at an event and starts again from the state
it stopped at, as the docs' velocity-weakening plug-in does at each stick) is read, the repeats once, with a note
counting them; a record of time and stress alone keeps refusing a duplicated row, naming it.
A2: analyze names the parameter set its model comparisons use, and warns where a bond-model run was made with
another one (its recorded critical velocity is not the set's).
A3: a slip between two samples (an exact sawtooth sampled every 0.1 s) is reported as bounded by the sampling,
with σs and σc at the middle of the interval and their resolution, the same in identical cycles.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip.analysis import analyze_trace, read_trace
from stickslip.models.run import Run
from stickslip.parameters import load_parameters
from stickslip.quasistatic.critical import critical_minimum


# ------------------------------------------------------------------------------------------------ A1: repeated rows
def _restarting_run(path, repeats: int) -> tuple[float, float, float]:
    """A Run CSV of a spring-slider sawtooth whose solver restarts at each stick's end: the row at the restart is
    written twice, equal in every column (time, stress and the model columns).  Returns (trough, peak, slope)."""
    v0, slope, trough, peak = 0.03, 300.0, 414.0, 600.0  # m/s, Pa/s, Pa, Pa
    stick = (peak - trough) / slope
    slip = 0.05
    times, stresses = [], []
    start = 0.0
    for _ in range(repeats):
        t_stick = start + np.linspace(0.0, stick, 60)
        times.append(t_stick)
        stresses.append(trough + slope * (t_stick - start))
        times.append(t_stick[-1:])  # the restart: the stick's last row again, every column equal
        stresses.append(np.array([peak]))
        t_slip = t_stick[-1] + np.linspace(0.0, slip, 41)[1:-1]  # the next stick starts where the slip ends
        times.append(t_slip)
        stresses.append(peak - (peak - trough) * (t_slip - t_stick[-1]) / slip)
        start = t_stick[-1] + slip
    t, s = np.concatenate(times), np.concatenate(stresses)
    run = Run.from_trace(
        "restarting", t, stress=s, slider_velocity=np.zeros_like(t), slider_position=np.zeros_like(t),
        load_point_position=v0 * t,
    )  # fmt: skip
    run.to_csv(path)
    return trough, peak, slope


def test_a_run_csv_whose_rows_repeat_in_every_column_is_read_with_a_note(capsys, tmp_path):
    path = tmp_path / "restarting.csv"
    trough, peak, slope = _restarting_run(path, repeats=4)
    lines = path.read_text().splitlines()
    body = lines[2:]  # the metadata line and the header
    repeated = [k for k in range(1, len(body)) if body[k] == body[k - 1]]
    assert len(repeated) == 4  # the file does hold the exact repeats the plug-in writes
    code, out, err = run_main(capsys, "analyze", str(path), "--v0", "0.03 m/s", "--json")
    assert code == 0, err
    first_row = repeated[0] + 3  # rows are the file's lines: the metadata comment is line 1, the header line 2
    assert f"4 row(s) repeat the row before in every column (first: row {first_row})" in err, err
    assert read_trace(path).time.size == len(body) - 4
    data = json.loads(out)
    complete = [c for c in data["cycles"] if c["complete"]]
    assert len(complete) >= 2
    for cycle in data["cycles"]:
        assert cycle["stick_slope"] == pytest.approx(slope, rel=1e-3)
        if cycle["peak_stress"] is not None:
            assert cycle["peak_stress"] == pytest.approx(peak, abs=0.5)
        if cycle["critical_stress"] is not None:
            assert cycle["critical_stress"] == pytest.approx(trough, abs=0.5)


def test_a_repeated_row_of_a_record_of_time_and_stress_alone_is_still_refused(capsys, tmp_path):
    path = tmp_path / "dup.csv"
    rows = [f"{0.1 * k:.1f},{257 + 15 * (0.1 * k % 20):.3f}" for k in range(400)]
    rows.insert(101, rows[100])  # file row 103: the header is row 1, data from row 2
    path.write_text("time [s],stress [Pa]\n" + "\n".join(rows) + "\n")
    code, out, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s")
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "row 103: time 10 s repeats the previous time 10 s with the same stress" in err


# ------------------------------------------------------------------------------------- A2: the parameter set named
from test_results_round28 import MY_GEL as OTHER_SET  # noqa: E402  (tester J's own gel, one copy)

OTHER_GD_H = 6000.0 / 0.008  # Pa/m: the set's G_d/h, shear modulus over height


@pytest.fixture(scope="module")
def other_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("other_set")
    toml = folder / "pva3.toml"
    toml.write_text(OTHER_SET)
    trace = folder / "sim20.csv"
    from stickslip.cli.main import main

    with pytest.raises(SystemExit) as done:
        main(["simulate", "--params", str(toml), "--v0", "20 um/s", "--duration", "45 s", "-o", str(trace)])
    assert done.value.code == 0
    return toml, trace


def test_a_run_made_with_another_set_is_warned_of_and_the_set_used_is_named(capsys, other_run):
    toml, trace = other_run
    capsys.readouterr()
    code, out, err = run_main(capsys, "analyze", str(trace))
    assert code == 0, err
    assert "model comparisons (Vs, Gd/h's block geometry, --compare) with gelatin-glass (the default" in out
    theirs = critical_minimum(load_parameters(str(toml))).velocity
    ours = critical_minimum(load_parameters("gelatin-glass")).velocity
    assert abs(theirs / ours - 1) > 0.5  # the sets do differ
    warning = [line for line in err.splitlines() if line.startswith("warning:")]
    assert len(warning) == 1 and "made with another parameter set" in warning[0], err
    assert f"Vc is {theirs * 1e6:.6g} µm/s, gelatin-glass's is {ours * 1e6:.6g} µm/s" in warning[0]
    # the notes that quote gelatin-glass's aging curve say whose it is
    assert "no jump velocity with the parameter set gelatin-glass" in out.replace("\n", " ")


def test_with_the_run_s_own_set_there_is_no_warning_and_gd_h_is_the_set_s(capsys, other_run):
    toml, trace = other_run
    capsys.readouterr()
    code, out, err = run_main(capsys, "analyze", str(trace), "--params", str(toml), "--json")
    assert code == 0, err
    assert "warning" not in err, err
    data = json.loads(out)
    assert data["parameter_set"] == "pva3" and data["parameter_set_default"] is False
    assert data["summary"]["stiffness"]["mean"] == pytest.approx(OTHER_GD_H, rel=1e-3)
    code, out, err = run_main(capsys, "analyze", str(trace), "--json")
    assert code == 0 and json.loads(out)["parameter_set_default"] is True


def test_a_run_made_with_the_default_set_is_not_warned_of(capsys, tmp_path):
    trace = tmp_path / "gel.csv"
    code, _, err = run_main(capsys, "simulate", "--v0", "50 um/s", "--duration", "45 s", "-o", str(trace))
    assert code == 0, err
    code, _, err = run_main(capsys, "analyze", str(trace))
    assert code == 0 and "warning" not in err, err


# ------------------------------------------------------------------------------------- A3: slips between samples
PERIOD, DT, LOW, RATE = 20.0, 0.1, 257.0, 15.0  # s, s, Pa, Pa/s: the tester's sawtooth (instantaneous drops)
HIGH = LOW + RATE * PERIOD  # 557 Pa: the stress just before each drop


def _sawtooth(phase: float = 0.0, noise: float = 0.0, cycles: int = 4) -> tuple[np.ndarray, np.ndarray]:
    t = phase + DT * np.arange(int(cycles * PERIOD / DT))
    x = LOW + RATE * np.mod(t, PERIOD)
    return t, x + noise * np.random.default_rng(11).standard_normal(t.size)


@pytest.mark.parametrize("phase", [0.0, 0.037, 0.081])
def test_a_drop_between_two_samples_is_bounded_and_read_alike_in_identical_cycles(phase):
    t, x = _sawtooth(phase)
    result = analyze_trace(t, x, 50e-6)
    complete = [c for c in result.cycles if c.complete]
    assert len(complete) >= 2
    resolution = RATE * DT / 2  # 0.75 Pa: the stick slope times half the sampling interval
    for c in result.cycles:
        if c.peak_stress is not None and c.end_time is not None:
            assert c.slip_time_bound == pytest.approx(DT, rel=1e-6)  # "< 0.1 s": the drop is within one interval
            assert 0.0 <= c.slip_time <= c.slip_time_bound
            assert c.peak_stress_uncertainty == pytest.approx(resolution, rel=1e-6)
            assert abs(c.peak_stress - HIGH) <= resolution + 1e-6  # the truth within the resolution
        if c.critical_stress is not None and c.start_time is not None:
            assert c.critical_stress_uncertainty == pytest.approx(resolution, rel=1e-6)
            assert abs(c.critical_stress - LOW) <= resolution + 1e-6
    for c in complete:
        assert abs(c.stick_time - PERIOD) <= c.stick_time_uncertainty + 1e-6
        assert c.period == pytest.approx(PERIOD, abs=1e-6)
    # identical cycles, identical numbers (they were 255.5 and 256.8 Pa, slips of 0.035 and 0.123 s)
    lows = [c.critical_stress for c in result.cycles if c.critical_stress is not None]
    highs = [c.peak_stress for c in result.cycles if c.peak_stress is not None]
    assert max(lows) - min(lows) < 1e-6 and max(highs) - min(highs) < 1e-6
    assert result.summary["unresolved_slips"]["slip_time_bound"] == pytest.approx(DT, rel=1e-6)
    assert result.summary["slip_time"]["n"] == 0  # no slip was timed: none enters the mean


def test_a_noisy_drop_between_samples_keeps_the_truth_within_its_resolution():
    noise = 0.3  # Pa
    t, x = _sawtooth(0.061, noise=noise, cycles=8)
    result = analyze_trace(t, x, 50e-6)
    complete = [c for c in result.cycles if c.complete]
    assert len(complete) >= 6
    # a drop counts as between samples where the samples either side lie within 2 noise levels of their lines:
    # most of them here (each of the four does with probability 0.95)
    bounded = [c for c in complete if c.slip_time_bound is not None]
    assert len(bounded) >= len(complete) // 2
    for c in bounded:
        assert c.slip_time_bound == pytest.approx(DT, rel=1e-6)
        # the line's own scatter at the corner is a fraction of the noise; 2 noise levels of margin
        assert abs(c.critical_stress - LOW) <= c.critical_stress_uncertainty + 2 * noise
        assert abs(c.peak_stress - HIGH) <= c.peak_stress_uncertainty + 2 * noise
    for c in complete:  # the others, hinge-fitted as before: within a sample's rise and the noise
        assert abs(c.critical_stress - LOW) <= RATE * DT + 3 * noise
        assert abs(c.peak_stress - HIGH) <= RATE * DT + 3 * noise


def test_a_slip_of_several_samples_is_timed_as_before():
    """A fall over 0.5 s (five samples) is resolved: no bound, the hinge times it."""
    slip = 0.5
    t = DT * np.arange(int(4 * PERIOD / DT))
    u = np.mod(t, PERIOD)
    top = LOW + RATE * (PERIOD - slip)
    x = np.where(u < PERIOD - slip, LOW + RATE * u, top - (top - LOW) * (u - (PERIOD - slip)) / slip)
    result = analyze_trace(t, x, 50e-6)
    complete = [c for c in result.cycles if c.complete]
    assert len(complete) >= 2 and "unresolved_slips" not in result.summary
    for c in complete:
        assert c.slip_time_bound is None
        assert c.slip_time == pytest.approx(slip, abs=0.02)
        assert c.peak_stress == pytest.approx(top, abs=0.5)


def test_the_table_shows_the_bound_and_the_resolution(capsys, tmp_path):
    t, x = _sawtooth()
    path = tmp_path / "saw.csv"
    rows = "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(t, x, strict=True))
    path.write_text("time [s],stress [Pa]\n" + rows)
    code, out, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s")
    assert code == 0, err
    slip_row = next(line for line in out.splitlines() if "slip time [s]" in line)
    cells = [c.strip() for c in slip_row.split("│")[2:-1]]
    assert cells[0] == "< 0.1" and cells[-1] == "< 0.1", slip_row
    low_row = next(line for line in out.splitlines() if "σc [Pa]" in line)
    value, resolution = (float(v) for v in low_row.split("│")[3].split("±"))  # cycle 2: "256.2 ± 0.75"
    assert math.isclose(resolution, RATE * DT / 2, rel_tol=0.01)
    assert abs(value - LOW) <= resolution + 0.06  # the truth within the resolution (the cell has 4 digits)
    assert "falls between two samples" in out.replace("\n", " ")
