"""Trace analysis on records whose noise is correlated or written in ADC steps (stickslip.analysis.detect).

The truth is built into each record: a sawtooth of straight sticks (sigma_c = 250 Pa to sigma_s = 550 Pa at
15 Pa/s, t_s = 20 s) and quarter-sine slips of 4 s, period 24 s, starting 5 s into a stick and ending 15 s into
the third one; the noise is AR(1) of a known marginal standard deviation, the record rounded to a known step.
So the record holds three cycles, the second whole: its stick from 19 s to 39 s, its slip to 43 s.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.signal import lfilter

from stickslip.analysis import analyze_trace
from stickslip.analysis.detect import noise_level

LOW, HIGH, SLOPE, SLIP = 250.0, 550.0, 15.0, 4.0
STICK = (HIGH - LOW) / SLOPE
PERIOD = STICK + SLIP
OFFSET = 5.0  # the record starts this far into a stick
SPAN = 2 * PERIOD + 10.0
V0 = 50e-6


def ar1(n: int, phi: float, sd: float, seed: int) -> np.ndarray:
    """Stationary AR(1) noise of marginal standard deviation ``sd``."""
    rng = np.random.default_rng(seed)
    shocks = rng.normal(0.0, sd * math.sqrt(1.0 - phi**2), n)
    shocks[0] = rng.normal(0.0, sd)  # start in the stationary distribution
    return lfilter([1.0], [1.0, -phi], shocks)


def sawtooth(rate: float, phi: float = 0.0, sd: float = 0.0, step: float = 0.0, drift: float = 0.0, seed: int = 3):
    t = np.arange(0.0, SPAN, 1.0 / rate)
    phase = np.mod(t + OFFSET, PERIOD)
    clean = np.where(
        phase < STICK, LOW + SLOPE * phase, LOW + (HIGH - LOW) * (1.0 - np.sin(0.5 * np.pi * (phase - STICK) / SLIP))
    )
    x = clean + drift * t + (ar1(t.size, phi, sd, seed) if sd > 0 else 0.0)
    return t, (np.round(x / step) * step if step > 0 else x)


def check_cycles(result, drift: float = 0.0, stress_tol: float = 1.0, time_tol: float = 0.05) -> None:
    """Three cycles, the second complete, its numbers the truth's (drift included: it is part of the stress)."""
    assert result.regime == "stick-slip", result.message
    assert [c.complete for c in result.cycles] == [False, True, False], result.message
    whole = result.cycles[1]
    start, peak = STICK + SLIP - OFFSET, 2 * PERIOD - SLIP - OFFSET  # 19 s and 39 s
    assert whole.critical_stress == pytest.approx(LOW + drift * start, abs=stress_tol)
    assert whole.peak_stress == pytest.approx(HIGH + drift * peak, abs=stress_tol)
    assert whole.stick_time == pytest.approx(STICK, abs=time_tol)
    assert whole.slip_time == pytest.approx(SLIP, abs=time_tol)
    assert whole.stick_slope == pytest.approx(SLOPE + drift, rel=2e-3)
    first = result.cycles[0]  # cut by the start of the record, its peak at 15 s is whole
    assert first.peak_time == pytest.approx(STICK - OFFSET, abs=time_tol)
    assert first.peak_stress == pytest.approx(HIGH + drift * (STICK - OFFSET), abs=stress_tol)


@pytest.mark.parametrize("phi", [0.5, 0.7, 0.9, 0.95])
def test_noise_level_is_the_whole_correlated_noise(phi):
    # from neighbouring samples alone AR(1) noise looks 1 - 4 phi/3 + phi^2/3 times as large in variance
    # (7 % at phi = 0.9): the slip threshold then fell inside the noise's own wander
    t, x = sawtooth(1000.0, phi, 0.5, seed=11)
    assert noise_level(t, x) == pytest.approx(0.5, rel=0.1)


@pytest.mark.parametrize("phi", [0.7, 0.9])
def test_correlated_noise_sawtooth_is_read_exactly(params, phi):
    t, x = sawtooth(1000.0, phi, 0.5, seed=12)
    check_cycles(analyze_trace(t, x, V0, params))


def test_constant_with_correlated_noise_is_steady_sliding(params):
    rng_t = np.arange(0.0, 60.0, 1e-3)
    x = 400.0 + ar1(rng_t.size, 0.95, 0.5, seed=13)
    result = analyze_trace(rng_t, x, V0, params)
    assert result.regime == "steady", result.message
    assert not result.cycles
    assert result.summary["mean_stress"] == pytest.approx(400.0, abs=0.2)


@pytest.mark.parametrize("rate", [10.0, 100.0, 1000.0])
def test_quantised_noiseless_sawtooth_is_read_at_every_sampling_rate(params, rate):
    step = 0.25
    t, x = sawtooth(rate, step=step)
    result = analyze_trace(t, x, V0, params)
    # a staircase has at least its own rounding error, whatever the rate (0 Pa at 1 kHz before)
    assert result.noise >= step / math.sqrt(12.0) * (1 - 1e-9)
    check_cycles(result, stress_tol=0.3, time_tol=0.03)


def test_quantised_correlated_noise_with_drift(params):
    drift = 0.2
    t, x = sawtooth(1000.0, 0.9, 0.5, step=0.25, drift=drift, seed=14)
    result = analyze_trace(t, x, V0, params)
    assert result.noise == pytest.approx(0.5, rel=0.1)
    check_cycles(result, drift=drift)


def test_white_noise_estimate_is_unchanged():
    # white noise stops the widening at its first step: the estimate is the neighbours' MAD, as it always was
    t, x = sawtooth(1000.0, sd=0.5, seed=15)
    steps = x[1:-1] - 0.5 * (x[:-2] + x[2:])
    mad = 1.482602218505602 * np.median(np.abs(steps - np.median(steps))) / math.sqrt(1.5)
    assert noise_level(t, x) == pytest.approx(mad, rel=1e-9)  # the times are not exactly even
    assert mad == pytest.approx(0.5, rel=0.05)


def test_the_step_of_a_quantised_column() -> None:
    """numerics.quantisation.quantum, the rule both analyze and rsf fit use: known steps in, that step out."""
    from stickslip.numerics.quantisation import quantum

    rng = np.random.default_rng(5)
    smooth = np.cumsum(rng.normal(0.0, 1.0, 2000))
    assert quantum(0.25 * np.round(smooth / 0.25)) == pytest.approx(0.25, rel=1e-12)
    assert quantum(smooth) == 0.0  # not written in steps
    assert quantum(0.25 * np.round(smooth[:8] / 0.25)) == 0.0  # too few changes to tell
