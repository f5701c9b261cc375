"""A stick-slip sawtooth sampled a few tens of times per cycle is stick-slip, not steady (stickslip.analysis.detect).

The correlated-noise ladder (docs/analysis.md, "Noise level") widens the triple about each sample to lags of up to
an eighth of the record.  On a sawtooth of 3 s periods sampled at 10 Hz those triples straddle a slip more often
than not, and the ladder read the sawtooth itself as noise: 257 Pa for 2 Pa of white noise, a drop threshold of
2.6 kPa, and the record (250 -> 500 Pa every 3 s) "steady".  The noise is what is left once the sawtooth is taken
out (docs/analysis.md, "Coarse sampling").  Every record is built here with a fixed seed: straight sticks from
LOW to HIGH over all but ``slip`` samples of each period, straight falls back over those ``slip`` samples, white
noise, an optional drift; the cycles' stresses and times are the planted ones.  Red noise sampled as coarsely
stays steady.
"""

from __future__ import annotations

import numpy as np
import pytest
from tests.test_analysis_red_noise import ar1

from stickslip.analysis import analyze_trace

V0 = 50e-6
LOW, HIGH = 250.0, 500.0
PERIOD = 3.0
SPAN = 60.0
OFFSET = 1.2  # the record starts this far into a stick


def sawtooth(per_cycle: int, slip: int, noise: float, drift: float = 0.0, seed: int = 0):
    """(t, x, peak times, stick duration, sampling interval) of a sawtooth sampled ``per_cycle`` times a period."""
    dt = PERIOD / per_cycle
    stick = PERIOD - slip * dt
    t = np.arange(0.0, SPAN - 0.5 * dt, dt)
    phase = np.mod(t + OFFSET, PERIOD)
    clean = np.where(
        phase < stick, LOW + (HIGH - LOW) * phase / stick, HIGH - (HIGH - LOW) * (phase - stick) / (PERIOD - stick)
    )
    x = clean + drift * t + np.random.default_rng(seed).normal(0.0, noise, t.size)
    peaks = np.arange(stick - OFFSET, SPAN, PERIOD)
    return t, x, peaks, stick, dt


def check_sawtooth(result, peaks, stick, dt, noise, drift):
    """Every planted slip found, and nothing else; the complete cycles' stresses within the bracket of a slip
    between samples (the stick's rise over a sampling interval and a half) plus three noise levels."""
    assert result.regime == "stick-slip", result.message
    found = [c for c in result.cycles if c.peak_time is not None]
    assert len(found) == peaks.size, result.message
    # the record starts inside a stick; every slip but the last is followed by a whole stick
    assert not found[0].complete
    assert all(c.complete for c in found[1:-1]), result.message
    rise = (HIGH - LOW) / stick * dt
    tolerance = 1.5 * rise + 3.0 * noise
    for cycle, peak in zip(found, peaks, strict=True):
        assert cycle.peak_time == pytest.approx(peak, abs=1.5 * dt)
        assert cycle.peak_stress == pytest.approx(HIGH + drift * peak, abs=tolerance)
    for cycle in found[1:-1]:
        start = cycle.peak_time - stick
        assert cycle.critical_stress == pytest.approx(LOW + drift * start, abs=tolerance)
        assert cycle.stick_time == pytest.approx(stick, abs=1.5 * dt)


def test_the_reported_record_is_stick_slip():
    # 3 s periods at 10 Hz (30 samples a cycle, slips of 3 samples), 2 Pa of white noise, 60 s: was "steady",
    # with a noise of 257 Pa
    t, x, peaks, stick, dt = sawtooth(30, 3, 2.0, seed=1)
    result = analyze_trace(t, x, V0)
    assert result.noise == pytest.approx(2.0, rel=0.3)  # the white noise, not the sawtooth
    assert result.threshold < 0.25 * (HIGH - LOW)
    check_sawtooth(result, peaks, stick, dt, 2.0, 0.0)


@pytest.mark.parametrize(
    ("per_cycle", "slip", "noise", "drift", "seed"),
    [
        (10, 1, 1.0, 0.0, 2),  # 10 samples a cycle, the slip inside one sampling interval
        (10, 2, 0.5, 1.0, 3),  # with a drift of 1 Pa/s
        (20, 3, 5.0, 0.0, 4),  # 5 Pa: 50 noise levels deep, 0.4 of the stick's rise per sample
        (20, 1, 2.0, 1.0, 5),
        (30, 2, 5.0, 1.0, 6),
        (60, 1, 2.0, 0.0, 7),
    ],
)
def test_coarse_sawtooths_are_found_whatever_their_sampling(per_cycle, slip, noise, drift, seed):
    t, x, peaks, stick, dt = sawtooth(per_cycle, slip, noise, drift, seed)
    result = analyze_trace(t, x, V0)
    assert 0.7 * noise < result.noise < 1.5 * noise, result.message
    check_sawtooth(result, peaks, stick, dt, noise, drift)


def test_a_noise_free_coarse_sawtooth_is_stick_slip():
    # no noise at all, 20 samples a cycle: the lag-1 residuals vanish on the sticks, the wider ones do not
    t, x, peaks, stick, dt = sawtooth(20, 3, 0.0)
    result = analyze_trace(t, x, V0)
    assert result.noise < 1e-6
    check_sawtooth(result, peaks, stick, dt, 0.0, 0.0)


# --------------------------------------------------------------------------- red noise sampled as coarsely
@pytest.mark.parametrize(
    ("phi", "step", "white", "seed"),
    [
        (0.9, 0.0, 0.0, 11),  # a few short, straight stretches of wander: not a sawtooth from end to end
        (0.9, 0.5, 0.5, 15),  # the same in 0.5 Pa steps with 0.5 Pa of white noise on top
        (0.9, 0.0, 0.0, 1),
        (0.98, 0.5, 0.0, 2),
        (0.98, 0.0, 0.5, 3),
        (0.999, 0.5, 0.0, 4),
    ],
)
def test_red_noise_sampled_at_10hz_stays_steady(phi, step, white, seed):
    # 600 samples at 10 Hz of AR(1) noise (sd 3 Pa) about 300 Pa: the sawtooths' sampling, no sawtooth
    n = 600
    t = np.arange(n) / 10.0
    x = 300.0 + ar1(n, phi, 3.0, 7000 + seed)
    if white:
        x = x + np.random.default_rng(9000 + seed).normal(0.0, white, n)
    if step:
        x = np.round(x / step) * step
    result = analyze_trace(t, x, V0)
    assert result.regime == "steady", result.message
    assert not result.cycles
