"""`analyze` on records with gaps, outlier bursts (dropouts) and a pulling velocity that the record contradicts.

Every record here is an analytic sawtooth whose corners are known: sticks rising at SLOPE from LOW to HIGH, slips
falling exponentially over SLIP s to the next LOW, sampled at 20 Hz with white noise of NOISE Pa.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip.analysis import analyze_trace, detect
from stickslip.cli.analyze_cmd import cycles_csv
from stickslip.fitting.data import read_stick_data

SLOPE, LOW, HIGH, SLIP, NOISE, DT = 18.4, 257.4, 549.7, 4.0, 2.9, 0.05
STICK = (HIGH - LOW) / SLOPE  # 15.9 s
PERIOD = STICK + SLIP
T0, T1 = -5.0, 115.0  # starts mid-stick, ends mid-slip: cycles 2-6 of the truth are whole (k = 0 starts at 0)


def truth(t: np.ndarray, slope: float = SLOPE, step_at: float | None = None, factor: float = 1.0) -> np.ndarray:
    """The sawtooth (cycle k: stick from k PERIOD, peak at k PERIOD + STICK); with ``step_at`` the sticks that
    begin after it rise ``factor`` times faster (a velocity step at a stick's start)."""
    out = np.empty_like(t)
    start = math.floor(T0 / PERIOD) * PERIOD
    while start <= t[-1]:
        rate = slope * (factor if step_at is not None and start >= step_at else 1.0)
        stick = (HIGH - LOW) / rate
        peak, end = start + stick, start + stick + SLIP
        rise = (t >= start) & (t <= peak)
        out[rise] = LOW + rate * (t[rise] - start)
        fall = (t > peak) & (t < end)
        u = (t[fall] - peak) / SLIP
        out[fall] = LOW + (HIGH - LOW) * (np.exp(-3.0 * u) - math.exp(-3.0)) / (1.0 - math.exp(-3.0))
        start = end
    return out


def record(seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(T0, T1, DT)
    return t, truth(t) + NOISE * np.random.default_rng(seed).standard_normal(t.size)


def starts() -> np.ndarray:
    return np.arange(0.0, T1, PERIOD)


def touches(cycle_from: float, cycle_to: float, gap: tuple[float, float]) -> bool:
    return cycle_from < gap[1] and cycle_to > gap[0]


# ------------------------------------------------------------------------------------------------------- gaps
@pytest.mark.parametrize(
    "gap",
    [
        (40.0, 70.0),  # 30 s: over a peak, a whole slip and most of a stick
        (30.0, 35.5),  # 5.5 s: over the peak at 31.8 s and its slip (no other sign of it)
        (25.0, 45.0),  # 20 s: over a stick's end, a slip and a stick's start
    ],
)
@pytest.mark.parametrize("missing", ["nan", "rows"])
def test_no_cycle_is_made_up_across_a_gap(params, gap, missing):
    t, x = record()
    inside = (t > gap[0]) & (t < gap[1])
    first, last = t[~inside & (t <= gap[0])][-1], t[~inside & (t >= gap[1])][0]  # the samples about the gap
    if missing == "nan":
        x = np.where(inside, np.nan, x)
    else:
        t, x = t[~inside], x[~inside]
    result = analyze_trace(t, x, 50e-6, params)
    largest = float(np.nanmax(x))
    true_starts = starts()
    whole = [s for s in true_starts if s > T0 and s + PERIOD < T1]
    # whole cycles clear of the gap (by a second: a corner needs some stick beside it) stay complete
    clear = [s for s in whole if not touches(s - 1.0, s + PERIOD + 1.0, gap)]
    untouched = [s for s in whole if not touches(s, s + PERIOD, gap)]
    complete = [c for c in result.cycles if c.complete]
    assert len(clear) <= len(complete) <= len(untouched)
    for cycle in result.cycles:
        # never a peak stress extrapolated above everything measured
        assert cycle.peak_stress is None or cycle.peak_stress < largest + 3 * NOISE
        span = (cycle.start_time if cycle.start_time is not None else -math.inf,
                cycle.end_time if cycle.end_time is not None else math.inf)  # fmt: skip
        if cycle.complete:
            assert not touches(*span, gap)
            j = int(np.argmin(np.abs(true_starts - cycle.start_time)))
            assert cycle.start_time == pytest.approx(true_starts[j], abs=0.2)
            assert cycle.critical_stress == pytest.approx(LOW, abs=3 * NOISE)
            assert cycle.peak_stress == pytest.approx(HIGH, abs=3 * NOISE)
            assert cycle.stick_time == pytest.approx(STICK, rel=0.02)
            assert cycle.period == pytest.approx(PERIOD, rel=0.02)
    # the cycles that the gap cuts say so, with its times
    cut = [c for c in result.cycles if "gap in the record" in c.message]
    assert cut and all(not c.complete for c in cut)
    assert all(f"t = {first:.6g} s to {last:.6g} s" in c.message for c in cut)
    hidden_peak = [c for c in cut if c.peak_time is None]
    assert all(c.peak_stress is None and c.stick_time is None for c in hidden_peak)
    assert any(f"{first:.6g}–{last:.6g} s" in w for w in result.warnings), result.warnings


def test_cycles_table_leaves_the_cut_cycles_out_of_fit_stick(params, tmp_path):
    t, x = record()
    x = np.where((t > 40.0) & (t < 70.0), np.nan, x)
    path = tmp_path / "cycles.csv"
    path.write_text(cycles_csv(analyze_trace(t, x, 50e-6, params)), encoding="utf-8")
    data = read_stick_data(path)
    assert data.stick_time.size >= 2
    assert np.allclose(data.stick_time, STICK, rtol=0.02)  # no stick time made up across the gap


def test_short_nan_runs_are_bridged(params):
    """A few NaN samples (up to GAP_STEPS sampling intervals) within a stick leave its cycle whole."""
    t, x = record()
    x[(t > 20.0) & (t < 20.3)] = np.nan  # 5 samples in the stick of cycle 2 (from 19.9 s)
    result = analyze_trace(t, x, 50e-6, params)
    assert not result.warnings
    assert sum(c.complete for c in result.cycles) == 5


# --------------------------------------------------------------------------------------------------- dropouts
def test_dropouts_are_left_out_not_counted_as_slips(params):
    t, x = record()
    rng = np.random.default_rng(3)
    bursts = [100, 350, 600, 850, 1100, 1350, 1600, 1850]  # in sticks and in slips
    for k in bursts:
        x[k : k + 3] -= 120.0 + rng.uniform(0, 10)
    x[2000:2002] += 150.0  # and an upward burst of two samples
    result = analyze_trace(t, x, 50e-6, params)
    whole = [s for s in starts() if s > T0 and s + PERIOD < T1]
    assert sum(c.complete for c in result.cycles) == len(whole) == 5
    assert len(result.cycles) <= len(whole) + 2  # and the two cut by the record's ends at most
    assert any("left out 26 sample(s) in 9 dropout(s)" in w for w in result.warnings), result.warnings
    for cycle in result.cycles:
        assert cycle.stick_time is None or cycle.stick_time == pytest.approx(STICK, rel=0.02)
        assert cycle.critical_stress is None or cycle.critical_stress == pytest.approx(LOW, abs=3 * NOISE)
    assert np.isnan(result.stress[bursts[0] : bursts[0] + 3]).all()  # the analysed record has them as gaps


def test_no_dropout_in_a_clean_or_coarse_sawtooth():
    _, x = record()
    assert detect.dropouts(x, 10 * NOISE).size == 0
    for per_cycle in (3, 4, 5, 8):  # a sawtooth sampled a few times a cycle is no run of bursts
        coarse = np.arange(0.0, 20 * PERIOD, PERIOD / per_cycle + 1e-3)
        assert detect.dropouts(truth(coarse), 1.0).size == 0, per_cycle


# ------------------------------------------------------------------------------------------- V0 and its record
def write(path, t, x, load_point=None):
    lines = ["time [s],stress [Pa]" + (",load_point_position [m]" if load_point is not None else "")]
    for k in range(t.size):
        lines.append(
            f"{float(t[k])!r},{float(x[k])!r}" + (f",{float(load_point[k])!r}" if load_point is not None else "")
        )
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_v0_contradicting_the_recorded_load_point_is_refused(capsys, tmp_path):
    t, x = record()
    path = write(tmp_path / "run.csv", t - T0, x, load_point=100e-6 * (t - T0))
    code, out, err = run_main(capsys, "analyze", str(path), "--v0", "40 um/s")
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and "100 µm/s" in err and "40 µm/s" in err
    code, out, err = run_main(capsys, "analyze", str(path), "--v0", "100 um/s", "--json")
    assert code == 0, err


def test_a_change_of_the_stick_slope_is_warned_of(params, capsys, tmp_path):
    t = np.arange(T0, 160.0, DT)
    x = truth(t, step_at=80.0, factor=2.0) + NOISE * np.random.default_rng(5).standard_normal(t.size)
    result = analyze_trace(t, x, 50e-6, params)
    warning = next(w for w in result.warnings if "stick slope changes" in w)
    before, after = (float(v) for v in re.findall(r"([0-9.]+) Pa/s", warning))
    assert before == pytest.approx(SLOPE, rel=0.02) and after == pytest.approx(2 * SLOPE, rel=0.02)
    assert "one V0" in warning
    assert not analyze_trace(*record(), 50e-6, params).warnings  # one slope: no warning
    # with a load point that steps from 50 to 100 um/s at 80 s the command names both and the times
    load_point = np.where(t < 80.0, 50e-6 * (t - T0), 50e-6 * (80.0 - T0) + 100e-6 * (t - 80.0))
    path = write(tmp_path / "step.csv", t - T0, x, load_point=load_point)
    code, _, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s")
    assert code == 0, err
    line = next(w for w in err.splitlines() if "changes velocity" in w)
    assert "50 µm/s from t = 0 s" in line and "100 µm/s from t = 85 s" in line
