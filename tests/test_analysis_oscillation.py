"""A smooth oscillation is not stick-slip (docs/analysis.md, "Smooth oscillations").

A slip falls faster than the stick before it rose; a sinusoid or a symmetric triangle falls as slowly as it
rises, so it has no slip phase, however deep its swings.  Every record here is synthetic, with its truth
(period, amplitude trend, stick and slip times) known from its construction.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip import regimes
from stickslip.analysis import analyze_trace
from stickslip.parameters import load_parameters

V0 = 50e-6


@pytest.fixture(scope="module")
def params():
    return load_parameters("gelatin-glass")


def sine(t: np.ndarray, amplitude: float, period: float, noise: float, seed: int, envelope=None) -> np.ndarray:
    rng = np.random.default_rng(seed)
    scale = amplitude if envelope is None else amplitude * envelope(t)
    return 300.0 + scale * np.sin(2 * np.pi * t / period) + rng.normal(0.0, noise, t.size)


def triangle(t: np.ndarray, period: float, slip_over_stick: float, low: float, high: float) -> np.ndarray:
    """Rise from ``low`` to ``high`` for ``stick`` s, fall back in ``slip_over_stick`` × ``stick`` s."""
    u = (t % period) / period
    rise = 1.0 / (1.0 + slip_over_stick)  # the stick's share of the period
    return low + (high - low) * np.where(u < rise, u / rise, (1.0 - u) / (1.0 - rise))


def assert_no_slips(result) -> None:
    assert result.cycles == ()
    for name in ("peak_stress", "critical_stress", "stick_time", "slip_time", "jump_velocity"):
        assert result.summary[name]["n"] == 0
    assert "not stick-slip" in result.message


@pytest.mark.parametrize(
    ("amplitude", "period", "noise", "dt"),
    [
        (50.0, 20.0, 2.0, 0.02),  # the tester's a_sine.csv, at half its sampling rate: 25 noise levels deep
        (150.0, 2.0, 2.0, 0.005),  # 75 noise levels, 400 samples a period
        (20.0, 20.0, 2.0, 0.02),  # 10 noise levels: shallower than the old exemption's 30
    ],
)
def test_a_sinusoid_is_a_smooth_oscillation_not_stick_slip(params, amplitude, period, noise, dt):
    t = np.arange(0.0, 10 * period, dt)
    result = analyze_trace(t, sine(t, amplitude, period, noise, seed=11), V0, params)
    assert result.regime == "oscillation"
    assert_no_slips(result)
    swings = result.summary["oscillation"]
    assert swings["periods"] == 9  # ten maxima in ten periods that start at a zero crossing
    assert swings["period"] == pytest.approx(period, rel=0.01)
    # extremes of the (median-filtered) record: the noise adds about two of its levels to each swing
    assert 2 * amplitude - noise < swings["peak_to_trough"] < 2 * amplitude + 4 * noise
    assert swings["amplitude_ratio"] == pytest.approx(1.0, abs=regimes.RATIO_TOLERANCE)
    assert swings["asymmetry"] < 1.5
    assert f"{swings['period']:.6g} s" in result.message


def test_a_symmetric_triangle_oscillates_and_an_asymmetric_one_sticks_and_slips(params):
    t = np.arange(0.0, 200.0, 0.02)
    noise = np.random.default_rng(3).normal(0.0, 2.0, t.size)
    symmetric = analyze_trace(t, triangle(t, 20.0, 1.0, 250.0, 500.0) + noise, V0, params)
    assert symmetric.regime == "oscillation"
    assert_no_slips(symmetric)
    assert symmetric.summary["oscillation"]["period"] == pytest.approx(20.0, rel=0.01)
    # slip time = half the stick time: falls twice as fast as it rose, a (slow) slip
    sawtooth = analyze_trace(t, triangle(t, 20.0, 0.5, 250.0, 500.0) + noise, V0, params)
    assert sawtooth.regime == "stick-slip"
    assert len(sawtooth.cycles) == 10
    complete = [c for c in sawtooth.cycles if c.complete]
    assert len(complete) >= 8
    for cycle in complete:
        assert cycle.stick_time == pytest.approx(40.0 / 3.0, rel=0.03)
        assert cycle.slip_time == pytest.approx(20.0 / 3.0, rel=0.06)
        assert cycle.peak_stress == pytest.approx(500.0, abs=3.0)


@pytest.mark.parametrize(("tau", "kind"), [(-60.0, regimes.DECAYING), (80.0, regimes.GROWING)])
def test_a_changing_amplitude_is_named_as_the_regime_classifier_names_it(params, tau, kind):
    t = np.arange(0.0, 100.0, 0.02)
    amplitude = 80.0 if tau < 0 else 30.0
    x = sine(t, amplitude, 10.0, 1.0, seed=5, envelope=lambda s: np.exp(s / tau))
    result = analyze_trace(t, x, V0, params)
    assert result.regime == kind
    assert_no_slips(result)
    swings = result.summary["oscillation"]
    assert swings["period"] == pytest.approx(10.0, rel=0.01)
    assert swings["amplitude_ratio"] == pytest.approx(math.exp(10.0 / tau), abs=0.03)
    assert result.message.startswith(f"{kind}: ")


def test_a_sawtooth_with_a_rounded_top_still_sticks_and_slips(params):
    """Each stick bends over into a flat top (a half parabola over its last 30 %) before a fast slip."""
    t = np.arange(0.0, 200.0, 0.02)
    u = (t % 20.0) / 20.0
    x = 250.0 + 250.0 * u / 0.9  # straight stick at 12.5 Pa/s
    top = (u >= 0.63) & (u < 0.9)
    w = (u[top] - 0.63) / 0.27
    x0, h = 250.0 + 250.0 * 0.63 / 0.9, 250.0 * 0.27 / 0.9
    x[top] = x0 + h * (w - 0.5 * w**2)  # tangent to the stick, flat at the peak x0 + h/2
    slip = u >= 0.9
    x[slip] = x0 + 0.5 * h - (x0 + 0.5 * h - 250.0) * (u[slip] - 0.9) / 0.1
    x += np.random.default_rng(8).normal(0.0, 2.0, t.size)
    result = analyze_trace(t, x, V0, params)
    assert result.regime == "stick-slip"
    assert len(result.cycles) == 10
    assert "oscillation" not in result.summary


def test_an_isolated_slow_start_up_drop_is_still_a_slip(params):
    """The start-up exemption (CLEAR_DROP) stays for what it was for: one deep drop as slow as its rise,
    then steady sliding, is a start-up stick and slip, not an oscillation."""
    t = np.arange(0.0, 120.0, 0.02)
    x = np.where(t < 20.0, 250.0 + 12.5 * t, np.maximum(500.0 - 12.5 * (t - 20.0), 400.0))
    x = x + np.random.default_rng(4).normal(0.0, 2.0, t.size)
    result = analyze_trace(t, x, V0, params)
    assert result.regime == "steady"
    assert len(result.cycles) == 1
    assert result.cycles[0].peak_stress == pytest.approx(500.0, abs=3.0)
    assert "oscillation" not in result.summary
    assert result.summary["mean_stress"] == pytest.approx(400.0, abs=1.0)


def test_cli_says_oscillation_in_words_with_no_cycle_table(capsys, tmp_path):
    t = np.arange(0.0, 200.0, 0.02)
    path = tmp_path / "sine.csv"
    np.savetxt(path, np.column_stack([t, sine(t, 50.0, 20.0, 2.0, seed=1)]), delimiter=",",
               header="time [s],stress [Pa]", comments="")  # fmt: skip
    code, out, _ = run_main(capsys, "analyze", str(path), "--v0", "50 um/s")
    assert code == 0
    assert "oscillation: 9 period(s) of " in out
    assert "not stick-slip" in out
    assert "stick-slip:" not in out and "Per cycle" not in out and "σs" not in out
    code, out, _ = run_main(capsys, "analyze", str(path), "--v0", "50 um/s", "--json")
    data = json.loads(out)
    assert data["regime"] == "oscillation" and data["cycles"] == []
    assert data["summary"]["oscillation"]["period"] == pytest.approx(20.0, rel=0.01)
