"""The transient run's window extremes, period and kind come from the solution, not from how it is sampled.

A tester's reports: a velocity-controlled re-slide's "lowest" was 30169 Pa while its trace went down to 6.18 Pa
(a last "period" of a verdict without one); a re-slide through the block sampled every 3 s said 363 Pa for the
255.7 Pa the block started the segment under; a run from rest reported its start-up cycle's 54.8 s as the period;
a run carried two periods (the regime's and its summary's); a light block ringing on without a stick was called
stick-slip.  Each is checked against the trace's own numbers or a finely sampled run.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import stickslip
from stickslip import protocols, regimes
from stickslip.models.transient import transient_run
from stickslip.transient import run_transient


@pytest.fixture(scope="module")
def params():
    return stickslip.load_parameters("gelatin-glass")


def _window(result, start):
    inside = np.asarray(result.time) >= start
    return np.asarray(result.stress)[inside]


def test_a_reslide_window_lowest_is_the_trace_minimum_whatever_the_sampling(params):
    """Velocity control, 100 um/s for 2 ms, hold 10 s, 100 um/s for 15 ms: the re-slide's stress falls to ~6 Pa
    after its peak and ends at ~242 Pa; the "lowest over the last segment" was 30169 Pa (the trough of the
    classifier's one "period" before the fall), below neither the trace's minimum nor its final stress."""
    protocol = protocols.segments([(100e-6, 2e-3), (0.0, 10.0), (100e-6, 15e-3)])
    start = float(protocol.boundaries[-2])
    plain = run_transient(params, protocol, control="velocity", start="steady")
    # rows every 5 ms (every 1 ms the hold's 10 000 rows cost the suite 11 s)
    fine = run_transient(params, protocol, control="velocity", start="steady", every=5e-3)
    stress = _window(plain, start)
    assert plain.regime not in (regimes.STICK_SLIP, regimes.DECAYING, regimes.GROWING)
    for result in (plain, fine):
        run = transient_run(result, protocol)
        assert run.trough == pytest.approx(float(np.min(stress)), rel=1e-3), result.regime
        assert run.peak == pytest.approx(float(np.max(stress)), rel=1e-3)
        assert run.trough <= float(result.stress[-1])
        assert result.evidence.trough == pytest.approx(run.trough, rel=1e-12)
    # the unsampled run's rows are every state: its window extremes are exactly the trace's
    assert transient_run(plain, protocol).trough == float(np.min(stress))
    # a finely sampled run sees about as low (it cannot see lower than the solution: its rows are states of it)
    assert float(np.min(_window(fine, start))) >= transient_run(fine, protocol).trough - 1e-9


def test_a_reslide_through_the_block_sampled_every_3_s_keeps_the_window_start(params):
    """350 um/s for 1 s, hold 10 s, 350 um/s for 10 s with the stick chains: the chains hold the block under
    255.7 Pa into the re-slide (t = 11 s); rows every 3 s (none at 11 s) said "lowest 362.986 Pa", the row at
    12 s, for the unsampled run's 255.712 Pa."""
    protocol = protocols.segments([(350e-6, 1.0), (0.0, 10.0), (350e-6, 10.0)])
    start = float(protocol.boundaries[-2])
    runs = {
        every: run_transient(params, protocol, start="steady", stick_population=True, rtol=1e-3, every=every)
        for every in (None, 3.0)
    }
    stress = _window(runs[None], start)
    for every, result in runs.items():
        run = transient_run(result, protocol)
        assert run.trough == pytest.approx(float(np.min(stress)), rel=1e-9), every
        assert run.peak == pytest.approx(float(np.max(stress)), rel=1e-9), every


def test_a_start_up_cycle_that_does_not_repeat_gives_no_period(params):
    """50 um/s for 60 s from rest: one whole cycle, the start-up stick from 0 Pa (54.8 s; the settled cycle's is
    23.3 s), then a stick under way: no period, in the regime or the summary."""
    protocol = protocols.constant(50e-6, 60.0)
    result = run_transient(params, protocol, stick_population=True, rtol=1e-3)
    whole = [c for c in result.cycles if c.period is not None]
    assert len(whole) == 1 and whole[0].start_stress == pytest.approx(0.0, abs=1e-9)  # the start-up cycle
    run = transient_run(result, protocol)
    assert run.regime.kind == regimes.UNDETERMINED
    assert math.isnan(run.period), run.period
    assert math.isnan(run.summary["period"]), run.summary["period"]


def test_one_period_and_peak_per_run(params):
    """100 um/s for 32 s from the steady start with the chains: the regime said 15.3553 s and 556.404 Pa (slip to
    slip, the last slip's), its summary 15.3522 s and 556.386 Pa (the last whole cycle): now both the last whole
    cycle's, stick to stick, as its events give it.  (32 s, not 30: with two slips the sticks are 0.0785 Pa apart,
    the start-up cycle and the limit cycle, which round 27 no longer calls repeating; the third stick is 2e-10 Pa
    from the second.)"""
    protocol = protocols.constant(100e-6, 32.0)
    result = run_transient(params, protocol, start="steady", stick_population=True)
    run = transient_run(result, protocol)
    last = [c for c in result.cycles if c.period is not None][-1]
    assert run.regime.kind == regimes.STICK_SLIP
    assert run.period == pytest.approx(last.period, rel=1e-12)
    assert run.summary["period"] == pytest.approx(run.period, rel=1e-12)
    assert run.peak == pytest.approx(last.peak_stress, rel=1e-9)
    assert run.summary["peak_stress"] == pytest.approx(run.peak, rel=1e-12)
    # the trough: the lowest of the solution over that cycle, from the trace's rows
    time, stress = np.asarray(result.time), np.asarray(result.stress)
    inside = (time >= last.start_time) & (time <= last.start_time + last.period)
    assert run.trough == pytest.approx(float(np.min(stress[inside])), rel=1e-9)


def test_a_light_block_ringing_without_a_stick_is_no_stick_slip(params):
    """0.1 kg/m^2, 200 -> 0 -> 300 um/s: the block rings on at 29 us a period while the slider stays between
    184 and 208 um/s; it read "stick-slip (limit cycle)"."""
    protocol = protocols.segments([(200e-6, 10e-3), (0.0, 50e-3), (300e-6, 20e-3)])
    result = run_transient(params, protocol, start="steady", mass=0.1)
    start = float(protocol.boundaries[-2])
    tail = np.asarray(result.time) >= start + 0.5 * (result.time[-1] - start)
    assert float(np.min(np.asarray(result.slider_velocity)[tail])) > 0.5 * 300e-6  # the trace: no stick
    assert result.regime != regimes.STICK_SLIP, result.message
    assert result.regime == "oscillation", result.message
    assert "never sticks" in result.message
    run = transient_run(result, protocol)  # its mean is its cycle's: between its trough and its peak
    assert run.trough <= run.mean <= run.peak, (run.trough, run.mean, run.peak)
