"""Records at real scale (issue 12 section 5): linear cost, flat memory, unchanged answers.

Truth here is independent of the code under test: the hinge profile against
its sample-by-sample definition, a sawtooth whose corners are known in closed
form, the row-by-row CSV reader against the columnar one, and the steady
curve evaluated in one call against the chunked command.
"""

from __future__ import annotations

import json
import time

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip.analysis import analyze_trace, read_trace
from stickslip.analysis.fits import QUADRATIC, STRAIGHT, Line, _HingeProfile, _sse_profile
from stickslip.cli import steady_cmd
from stickslip.errors import DataError
from stickslip.parameters import load_parameters
from stickslip.quasistatic.steady import steady_state
from stickslip.tables import _read_columnar, _read_header, _read_rows

SLOPE, LOW, HIGH, SLIP, NOISE = 15.3, 257.4, 552.9, 3.8, 0.5  # Pa/s, Pa, Pa, s, Pa
STICK = (HIGH - LOW) / SLOPE


def sawtooth(samples: int, rate: float = 1000.0, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Sticks rising at SLOPE from LOW to HIGH, exponential falls of SLIP s back to LOW, white noise."""
    t = np.arange(samples) / rate
    phase = np.mod(t + 5.0, STICK + SLIP)
    fall = (np.exp(-3.0 * (phase - STICK) / SLIP) - np.exp(-3.0)) / (1.0 - np.exp(-3.0))
    x = np.where(phase < STICK, LOW + SLOPE * phase, LOW + (HIGH - LOW) * fall)
    return t, x + np.random.default_rng(seed).normal(0.0, NOISE, samples)


# --------------------------------------------------------------------------- the hinge profile
@pytest.mark.parametrize("sign", [1.0, -1.0])
@pytest.mark.parametrize("powers", [STRAIGHT, QUADRATIC])
@pytest.mark.parametrize("branch_samples", [3, 40, 1500])
def test_running_sum_profile_equals_the_sample_by_sample_sum(sign, powers, branch_samples):
    rng = np.random.default_rng(branch_samples)
    t = np.sort(rng.uniform(0.0, 10.0, 3000))
    t[1000] = t[999]  # a repeated time
    edge = 7.0 if sign > 0 else 3.0
    search = (edge - 2.0, edge) if sign > 0 else (edge, edge + 2.0)
    beyond = np.flatnonzero(sign * (t - edge) > 0)
    keep = np.ones(t.size, bool)  # a branch of only a few samples beyond the edge: the narrow case
    keep[beyond[branch_samples:] if sign > 0 else beyond[: beyond.size - branch_samples]] = False
    t = t[keep]
    line = Line(5.0, 300.0, 15.0, 0.0, 0.0, 3, 0.0, 10.0)
    x = line(t) + rng.normal(0.0, 0.5, t.size)
    slip = sign * (t - edge) > 0
    x[slip] -= 40.0 * sign * (t[slip] - edge) + 3.0 * (t[slip] - edge) ** 2
    on_line = x - line(t)
    tcs = np.linspace(*search, 301)
    scale = float(t[-1] - t[0])
    direct = _sse_profile(t, x, on_line, line, tcs, sign, powers, scale)
    fast = _HingeProfile(t, on_line, line.slope, sign, search, powers, scale)(tcs)
    # differences between candidates matter at the noise variance (0.25): agree far below it
    np.testing.assert_allclose(fast, direct, rtol=1e-9, atol=1e-6)


# --------------------------------------------------------------------------- analysis at scale
def test_analysis_cost_is_linear_and_its_answers_exact():
    costs = {}
    for samples in (100_000, 1_000_000):
        t, x = sawtooth(samples)
        start = time.process_time()
        result = analyze_trace(t, x, 50e-6)
        costs[samples] = time.process_time() - start
    # 10x the samples and 10x the cycles: linear is 10x, the old samples x cycles was 100x
    assert costs[1_000_000] < 30 * max(costs[100_000], 0.02), costs
    summary = result.summary
    assert summary["n_complete"] >= 40
    assert summary["stick_slope"]["mean"] == pytest.approx(SLOPE, rel=1e-4)
    assert summary["peak_stress"]["mean"] == pytest.approx(HIGH, abs=0.1)
    assert summary["period"]["mean"] == pytest.approx(STICK + SLIP, rel=1e-3)
    assert result.noise == pytest.approx(NOISE, rel=0.05)


def test_columnar_reader_equals_the_row_reader(tmp_path):
    texts = {
        "plain": "time [ms],stress [kPa]\n" + "".join(f"{k},{0.25 + k / 1e3}\n" for k in range(50)),
        "gaps and blank lines": "time,stress\n1,\n\n2,3\r\n3,nan\n"
        + "".join(f"{k},{k}\n" for k in range(4, 40))
        + "\n\n",
        "comments above": "# rig 3\n\n# 1 kHz\ntime,stress\n" + "".join(f"{k},{k}\n" for k in range(30)),
        "byte order mark": "\ufefftime,stress\n" + "".join(f"{k},{k}\n" for k in range(30)),
        "no final newline": "time,stress\n" + "\n".join(f"{k},{k}" for k in range(30)),
    }
    dimensions = {"time": "time", "stress": "stress"}
    for name, text in texts.items():
        path = tmp_path / "t.csv"
        path.write_text(text, encoding="utf-8")
        header = _read_header(path, name, dimensions, ["time"], ())
        fast = _read_columnar(path, header, ["stress"])
        slow = _read_rows(path, name, header, ["stress"])
        assert fast is not None, name
        np.testing.assert_array_equal(fast[1], slow[1], err_msg=name)
        for column in slow[0]:
            np.testing.assert_array_equal(fast[0][column], slow[0][column], err_msg=name)


def test_a_bad_cell_deep_in_a_large_file_is_named(tmp_path):
    t, x = sawtooth(60_000)
    cells = [f"{a:.6f},{b:.6f}" for a, b in zip(t, x, strict=True)]
    cells[50_000] = f"{t[50_000]:.6f},12..5"
    path = tmp_path / "big.csv"
    path.write_text("time,stress\n" + "\n".join(cells) + "\n")
    with pytest.raises(DataError, match=r"row 50002, column 'stress': '12\.\.5' is not a number"):
        read_trace(path)
    cells[50_000] = f"{t[50_000]:.6f},{x[50_000]:.6f}"
    path.write_text("time,stress\n" + "\n".join(cells) + "\n\n")
    trace = read_trace(path)
    assert trace.rows[-1] == 60_001 and trace.time.size == 60_000


# --------------------------------------------------------------------------- the curve command
def test_curve_csv_in_chunks_equals_one_evaluation(capsys, monkeypatch, tmp_path):
    monkeypatch.setattr(steady_cmd, "CHUNK", 7)
    path = tmp_path / "curve.csv"
    code, out, err = run_main(capsys, "curve", "--points", "50", "--format", "csv", "-o", str(path))
    assert code == 0 and out == "" and err == ""
    lines = path.read_text().splitlines()
    assert lines[0] == "velocity [m/s],stress [Pa],bonded_fraction [1],stress_slope [Pa s/m]" and len(lines) == 51
    values = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    whole = steady_state(load_parameters(), np.geomspace(10e-6, 10e-3, 50))
    for k, name in enumerate(("velocity", "stress", "bonded_fraction", "stress_slope")):
        np.testing.assert_allclose(values[:, k], getattr(whole, name), rtol=1e-12)


def test_curve_table_and_json_are_bounded(capsys):
    code, out, err = run_main(capsys, "curve", "--points", "1000")
    assert code == 0, err
    rows = [line for line in out.splitlines() if "weakening" in line or "strengthening" in line]
    assert len(rows) == steady_cmd.TABLE_ROWS
    assert "100 of 1000 velocities shown, evenly spread; --format csv -o FILE writes every one" in out
    code, out, err = run_main(capsys, "curve", "--points", str(steady_cmd.JSON_POINTS + 1), "--format", "json")
    assert code == 2 and out == "" and err.count("\n") == 1 and "--format json holds at most" in err
    code, out, err = run_main(capsys, "curve", "--points", str(steady_cmd.MAX_POINTS + 1))
    assert code == 2 and out == "" and "--points" in err and "10000000" in err
    code, out, _ = run_main(capsys, "curve", "--points", "5", "--format", "json")
    assert code == 0 and len(json.loads(out)["velocity"]) == 5


def test_values_near_overflow_are_refused_in_one_line(capsys, tmp_path):
    path = tmp_path / "huge.csv"
    path.write_text("time,stress\n" + "".join(f"{k},{1e300 * (1 + k % 10 / 100)}\n" for k in range(100)))
    code, out, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s")
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "row 2: stress 1e+300 Pa is beyond 1e+100 Pa in magnitude" in err
