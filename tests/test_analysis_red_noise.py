"""Red (strongly correlated) noise is not stick-slip, whatever the record's length or sampling rate.

A constant stress plus AR(1) noise wanders up and down on the noise's correlation time.  Seen sample by sample
it looks a third of its size (1 - 4 phi/3 + phi^2/3 of its variance), and its wanders were read as slips: 21
cycles in 60 s of phi = 0.9 noise at 50 Hz (sd 3 Pa, noise given as 0.81 Pa), 208 in a minute of phi = 0.999 at
1 kHz, while 6000 samples of the same noise were called steady.  A stick-slip record is told from it by what a
wander lacks: drops far above the whole noise, falling faster than the stick rose (docs/analysis.md, "Red noise").
Every record is built here with a fixed seed; the sawtooths' stresses and times are the planted ones.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.signal import lfilter

from stickslip.analysis import analyze_trace
from stickslip.analysis.detect import _asymmetry

V0 = 50e-6
SD = 3.0  # the red noise's marginal standard deviation (Pa)


def ar1(n: int, phi: float, sd: float, seed: int) -> np.ndarray:
    """Stationary AR(1) noise of marginal standard deviation ``sd``."""
    rng = np.random.default_rng(seed)
    shocks = rng.normal(0.0, sd * math.sqrt(1.0 - phi**2), n)
    shocks[0] = rng.normal(0.0, sd)
    return lfilter([1.0], [1.0, -phi], shocks)


@pytest.mark.parametrize(
    ("phi", "rate", "samples", "seed"),
    [
        (0.9, 50.0, 3000, 1),  # correlation time 0.2 s: was 21 cycles, noise 0.81 Pa
        (0.9, 50.0, 1500, 2),  # the same noise, half as long
        (0.9, 1000.0, 3000, 1),  # the same samples at 1 kHz (a correlation time of 10 ms)
        (0.82, 50.0, 3000, 3),
        (0.98, 100.0, 3000, 4),
    ],
)
def test_red_noise_about_a_constant_is_steady(params, phi, rate, samples, seed):
    t = np.arange(samples) / rate
    x = 300.0 + ar1(samples, phi, SD, seed)
    result = analyze_trace(t, x, V0, params)
    assert result.regime == "steady", result.message
    assert not result.cycles
    assert result.noise == pytest.approx(SD, rel=0.25)  # the whole noise, not its sample-to-sample part


def test_slow_red_noise_at_1khz_and_50hz_is_steady(params):
    # phi = 0.999 at 1 kHz (a correlation time of 1 s), written in 0.5 Pa steps: the noise came out as the
    # rounding's own 0.14 Pa and the record as 208 stick-slip cycles; every 20th sample gave 24
    n = 60_000
    t = np.arange(n) * 1e-3
    x = np.round((300.0 + ar1(n, 0.999, SD, 21)) / 0.5) * 0.5
    for every in (1, 20):
        result = analyze_trace(t[::every], x[::every], V0, params)
        assert result.regime == "steady", (every, result.message)
        assert result.noise == pytest.approx(SD, rel=0.25), every


# --------------------------------------------------------------------------- real stick-slip in the same noise
LOW, HIGH, SLOPE, SLIP, K_SHAPE = 250.0, 550.0, 15.0, 3.0, 2.2
STICK = (HIGH - LOW) / SLOPE  # 20 s
PERIOD = STICK + SLIP
OFFSET = 8.0  # the record starts this far into a stick ...
SPAN = 3 * PERIOD  # ... and ends as far into the fourth
DRIFT = 0.1  # Pa/s, part of the stress


def sawtooth(rate: float, noise: np.ndarray | None = None, step: float = 0.5):
    """Straight sticks LOW -> HIGH at SLOPE, exponential falls over SLIP (the model's shape at 50 um/s)."""
    t = np.arange(0.0, SPAN, 1.0 / rate)
    phase = np.mod(t + OFFSET, PERIOD)
    u = np.clip((phase - STICK) / SLIP, 0.0, 1.0)
    fall = (np.exp(-K_SHAPE * u) - math.exp(-K_SHAPE)) / (1.0 - math.exp(-K_SHAPE))
    x = np.where(phase < STICK, LOW + SLOPE * phase, LOW + (HIGH - LOW) * fall) + DRIFT * t
    if noise is not None:
        x = x + noise
    return t, np.round(x / step) * step


def test_noisy_sawtooth_at_1khz_in_red_noise_keeps_its_cycles(params):
    # white noise 2 Pa plus the red noise of the first test at 1 kHz (phi = 0.995: 0.2 s), written in 0.5 Pa steps
    rate = 1000.0
    n = int(SPAN * rate)
    noise = ar1(n, 0.995, SD, 31) + np.random.default_rng(32).normal(0.0, 2.0, n)
    t, x = sawtooth(rate, noise)
    result = analyze_trace(t, x, V0, params)
    assert result.regime == "stick-slip", result.message
    assert result.noise == pytest.approx(math.hypot(SD, 2.0), rel=0.3)
    peaks = [k * PERIOD + STICK - OFFSET for k in range(3)]  # 12, 35, 58 s; the fourth stick is cut
    assert [c.complete for c in result.cycles] == [False, True, True, False], result.message
    # a 20 s stick holds only ~50 independent values of noise correlated over 0.2 s: 1.7 % of the drop, 1 % of t_s
    tolerance = 5.0
    for cycle, peak in zip(result.cycles[:3], peaks, strict=True):
        assert cycle.peak_time == pytest.approx(peak, abs=0.1)
        assert cycle.peak_stress == pytest.approx(HIGH + DRIFT * peak, abs=tolerance)
    for cycle in result.cycles[1:3]:
        start = cycle.peak_time - STICK
        assert cycle.critical_stress == pytest.approx(LOW + DRIFT * start, abs=tolerance)
        assert cycle.stick_time == pytest.approx(STICK, abs=0.2)
        assert cycle.slip_time == pytest.approx(SLIP, rel=0.1)
    for cycle in result.cycles:
        assert cycle.stick_slope == pytest.approx(SLOPE + DRIFT, rel=0.02)


@pytest.mark.parametrize("rate", [50.0, 1000.0])
def test_white_noise_sawtooth_is_read_as_before(params, rate):
    n = int(SPAN * rate)
    t, x = sawtooth(rate, np.random.default_rng(41).normal(0.0, 3.0, n))
    result = analyze_trace(t, x, V0, params)
    assert result.noise == pytest.approx(3.0, rel=0.1)
    assert [c.complete for c in result.cycles] == [False, True, True, False], result.message
    for cycle in result.cycles[1:3]:
        assert cycle.peak_stress == pytest.approx(HIGH + DRIFT * cycle.peak_time, abs=1.5)
        assert cycle.stick_time == pytest.approx(STICK, abs=0.1)


def test_a_slip_falls_faster_than_the_stick_rose_and_noise_does_not():
    # the asymmetry that tells a slip from a wander: time near the peak before it over time after it
    _, x = sawtooth(50.0, step=1e-9)
    peaks = np.array([round((k * PERIOD + STICK - OFFSET) * 50.0) for k in range(3)])
    forward, depth = _asymmetry(x, peaks)
    assert np.all(forward > 5.0)  # the top 30 % of the drop: 6 s of stick against about 0.7 s of slip
    assert depth[0] == pytest.approx(SLOPE * (STICK - OFFSET), rel=0.02)  # the record starts 8 s into a stick
    assert depth[1:] == pytest.approx(HIGH - LOW, rel=0.02)
    backward, _ = _asymmetry(x[::-1], x.size - 1 - peaks[::-1])
    assert np.all(backward < 0.2)
