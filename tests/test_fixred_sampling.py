"""Summaries that must not depend on how the output is sampled (fixred)."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.models.run import settled_mean


def test_settled_mean_starts_its_window_at_the_cut_not_at_the_next_row():
    """A ramp s = t over [0, 10] s, no period: the mean over the second half [5, 10] s is 7.5 whatever the rows;
    the window began at the first row after the cut (here the last row: 10)."""
    for time in (np.array([0.0, 1.0, 2.0, 3.0, 10.0]), np.linspace(0.0, 10.0, 7), np.linspace(0.0, 10.0, 1001)):
        assert settled_mean(time, time.copy(), np.nan) == pytest.approx(7.5, rel=1e-14)


def test_settled_mean_over_whole_periods_of_a_sampled_oscillation():
    """s = 1 + sin(2 pi t / T) over 10.3 periods: the mean over the last whole periods of the second half is 1
    (exactly, for the trace's linear interpolant on rows that divide each period evenly from the cut)."""
    period = 0.7
    end = 10.3 * period
    for rows in (50, 233, 4001):
        time = np.linspace(0.0, end, rows)
        values = 1.0 + np.sin(2 * np.pi * time / period)
        fine = np.linspace(0.0, end, 200_001)
        want = settled_mean(fine, 1.0 + np.sin(2 * np.pi * fine / period), period)
        assert want == pytest.approx(1.0, abs=1e-9)
        step = end / (rows - 1)
        # the linear interpolant of a sine errs by ~(step/T)^2; the window's start no longer adds ~step/T
        assert settled_mean(time, values, period) == pytest.approx(1.0, abs=2.0 * (2 * np.pi * step / period) ** 2)


@pytest.fixture(scope="module")
def sampled_runs():
    """The paper's stick-slip (Eq 1 with the stick chains) over 60 s, traced at every step, every 0.1 s, 1 s."""
    import stickslip
    from stickslip.protocols import constant

    gel = stickslip.load_parameters("gelatin-glass")
    model = stickslip.get_model("transient")
    kw = {"start": "steady", "start_velocity": 350e-6, "rtol": 1e-4, "stick_population": True}
    return {every: model.run(gel, constant(100e-6, 60.0), every=every, **kw) for every in (None, 0.1, 1.0)}


def test_transient_mean_stress_does_not_depend_on_the_sampling(sampled_runs):
    """The mean over the whole cycles comes from the integral of sigma dt the solver keeps: the trapezoid over
    1 s rows was 1.6e-4 off (382.91 against 382.97 Pa); now every sampling agrees to the local tolerance."""
    ref = sampled_runs[None]
    assert ref.regime.kind == "stick-slip" and ref.summary["cycles"] >= 2
    for every in (0.1, 1.0):
        run = sampled_runs[every]
        assert run.regime.kind == ref.regime.kind
        assert run.summary["cycles"] == ref.summary["cycles"]
        assert run.summary["mean_stress"] == pytest.approx(ref.summary["mean_stress"], rel=1e-5)
        assert run.summary["period"] == pytest.approx(ref.summary["period"], rel=1e-5)


def test_transient_stress_integral_is_the_trace_integrated():
    """Independent of the rows: the integral column against a fine trapezoid of the every-step trace (a stick and
    a slip through the block, with the quasi-steady reduction on)."""
    import stickslip
    from stickslip.protocols import segments

    gel = stickslip.load_parameters("gelatin-glass")
    run = stickslip.transient.run_transient(gel, segments([(200e-6, 0.02), (350e-6, 0.5)]), start="steady")
    time, stress = run.time, run.stress
    integral = run.bookkeeping.stress_integral
    trapezoid = np.r_[0.0, np.cumsum(np.diff(time) * 0.5 * (stress[1:] + stress[:-1]))]
    assert integral[0] == 0.0
    assert np.max(np.abs(integral - trapezoid)) <= 1e-6 * integral[-1]


def test_transient_trough_does_not_depend_on_the_sampling(sampled_runs):
    """The last trough (it feeds the amplitude ratio) is the lowest of the solver's accepted states: the slip ends
    below the stick's start (sigma turns where V = Vp, before the stick), which 0.1 s and 1 s rows missed
    (257.0995 against 256.8855 Pa)."""
    ref = sampled_runs[None]
    assert ref.regime.trough < min(c.start_stress for c in ref.native.cycles)  # the turn, not the stick event
    for every in (0.1, 1.0):
        run = sampled_runs[every]
        # to a tenth of the local tolerance: 0.1 s rows make the solver land on them (other steps), and the
        # reduction's tables are shared within a process (built at other ranges by earlier runs)
        assert run.regime.trough == pytest.approx(ref.regime.trough, rel=1e-5)
        assert run.regime.peak == pytest.approx(ref.regime.peak, rel=1e-5)
        assert run.regime.amplitude_ratio == pytest.approx(ref.regime.amplitude_ratio, rel=1e-5)


@pytest.mark.parametrize("every", [None, 0.05])
def test_stuck_rows_are_the_held_block_in_closed_form(every):
    """The rows of a stick held by the chains (written as one array per stretch): sigma = K (P - X) with the slider
    fixed, the block's energy sigma^2/2K, and the integral of sigma dt growing by the exact integral of a linear
    sigma; on the sampling grid where one is asked for."""
    import stickslip
    from stickslip.protocols import Protocol, Segment

    gel = stickslip.load_parameters("gelatin-glass")
    cycle = Protocol((Segment(350e-6, 5.0), Segment(100e-6, 20.0)))
    run = stickslip.transient.run_transient(gel, cycle, start="steady", stick_population=True, every=every)
    held = run.to_frame()["held_by"].to_numpy() == "chains"
    assert held.sum() >= 50
    k = run.stiffness
    t, sigma = run.time[held], run.stress[held]
    x, puller = run.slider_position[held], run.puller_position[held]
    same = np.diff(t) < 1.0  # consecutive rows of one stretch (the two sticks are ~15 s apart)
    assert np.all(run.slider_velocity[held] == 0.0) and np.all(np.diff(x)[same] == 0.0)
    assert np.max(np.abs(sigma - k * (puller - x))) <= 1e-12 * np.max(sigma)
    assert np.allclose(run.bookkeeping.block_energy[held], sigma**2 / (2 * k), rtol=1e-14, atol=0.0)
    assert np.all(np.diff(run.chain_fraction[held])[same] <= 0.0)
    if every is not None:
        assert np.allclose(t / every, np.round(t / every), rtol=0.0, atol=1e-9)
    # consecutive rows of one stretch: the stress rises at K Vp, its integral by the trapezoid (exact for a line)
    integral = run.bookkeeping.stress_integral[held]
    rise = np.diff(sigma)[same] - k * 100e-6 * np.diff(t)[same]
    assert np.max(np.abs(rise)) <= 1e-12 * np.max(sigma)
    step = (np.diff(t) * 0.5 * (sigma[1:] + sigma[:-1]))[same]
    assert np.max(np.abs(np.diff(integral)[same] - step)) <= 1e-12 * np.max(integral)
