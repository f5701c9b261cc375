"""The transient model's limit-cycle mean stress does not depend on ``every`` (a summary never depends on how the
output is sampled), with a run that ends inside a stick."""

from __future__ import annotations

import numpy as np
import pytest

#: the puller's pace (m/s) and the run's length (s): from empty, three whole cycles, the run ending 2.7 s into a stick
PACE, DURATION = 100e-6, 60.0
EVERY = (None, 3.0, 7.0, 11.0)


@pytest.fixture(scope="module")
def runs():
    """The paper's stick-slip with the stick chains from empty, traced at every step and sampled every 3, 7, 11 s
    (rows that leave the last stick, cut off by the run's end, one row or none before the end)."""
    import stickslip
    from stickslip.protocols import constant

    gel = stickslip.load_parameters("gelatin-glass")
    model = stickslip.get_model("transient")
    kw = {"start": "empty", "stick_population": True}
    return {every: model.run(gel, constant(PACE, DURATION), every=every, **kw) for every in EVERY}


def _end_corrected_trapezoid(time: np.ndarray, stress: np.ndarray, slope: np.ndarray) -> float:
    """The integral of a trace with its slopes, h/2 (s0 + s1) + h^2/12 (s0' - s1') per interval: fourth order,
    and nothing of the solver's own integral."""
    h = np.diff(time)
    return float(np.sum(0.5 * h * (stress[1:] + stress[:-1]) + h * h / 12.0 * (slope[:-1] - slope[1:])))


def test_the_cycles_mean_stress_is_the_same_at_every_sampling(runs):
    """The mean over the whole cycles ends at a stick the run ended in: no cycle gives its stress, and the rows
    once put it on the line through the sliding row before the stick (mean 355.785 at 3 s, 355.099 at 7 s,
    against 355.994 Pa traced at every step).  Now sigma = K (P - X) of the held block gives it: every sampling
    agrees to a tenth of the solver's rtol (1e-4), as the integral it reads is the same solution's."""
    ref = runs[None]
    assert ref.regime.kind == "stick-slip" and ref.summary["cycles"] >= 2
    last = ref.native.cycles[-1]
    assert (
        last.start_time + last.period < DURATION < last.start_time + last.period + last.stick_time
    )  # stuck at the end
    for every in EVERY[1:]:
        run = runs[every]
        assert run.summary["cycles"] == ref.summary["cycles"]
        assert run.summary["period"] == pytest.approx(ref.summary["period"], rel=1e-9)
        assert run.summary["mean_stress"] == pytest.approx(ref.summary["mean_stress"], rel=1e-5)
        assert run.summary["run_mean_stress"] == pytest.approx(ref.summary["run_mean_stress"], rel=1e-5)


def test_the_puller_positions_give_the_same_mean_without_the_protocol(runs):
    """Without the protocol (last_cycle_numbers of the result alone) the puller's travel into the last stick comes
    from the rows' puller positions, linear at a constant pace: the same mean."""
    from stickslip.models.transient import last_cycle_numbers

    for every in EVERY:
        run = runs[every]
        assert last_cycle_numbers(run.native)["mean_stress"] == pytest.approx(run.summary["mean_stress"], rel=1e-12)


def test_the_unsampled_mean_is_the_trace_integrated_over_the_cycles(runs):
    """Independent of the solver's integral: the every-step trace between the cycles' exact stick events (rows of
    their own without ``every``), by the end-corrected trapezoid with the massless block's slopes
    d sigma/dt = K (Vp - V).  The rule's error across the slip's kink (V jumps from 0 at the slip's row) is ~4e-7
    here; the solver's local tolerance is 1e-4."""
    run = runs[None]
    native = run.native
    whole = [c for c in native.cycles if c.period is not None]
    start, end = whole[-1].start_time, whole[-1].start_time + whole[-1].period  # the settled (last whole) cycle
    i, j = (int(np.argmin(np.abs(native.time - t))) for t in (start, end))
    assert native.time[i] == pytest.approx(start, abs=1e-9) and native.time[j] == pytest.approx(end, abs=1e-9)
    time, stress = native.time[i : j + 1], native.stress[i : j + 1]
    slope = native.stiffness * (PACE - native.slider_velocity[i : j + 1])
    mean = _end_corrected_trapezoid(time, stress, slope) / (time[-1] - time[0])
    assert run.summary["mean_stress"] == pytest.approx(mean, rel=1e-5)
    # the cycles' mean is not the run's (the run ends 2.7 s into a stick): the comparison can tell them apart
    assert abs(run.summary["run_mean_stress"] / mean - 1.0) > 1e-3


def test_a_velocity_step_run_keeps_its_mean():
    """No stick chains (a velocity step under velocity control): the mean over the run is the solver's integral
    over the run, as before, and agrees with the trace integrated by the end-corrected trapezoid to the rtol."""
    import stickslip
    from stickslip.models.base import Rig
    from stickslip.protocols import segments

    gel = stickslip.load_parameters("gelatin-glass")
    run = stickslip.get_model("transient").run(
        gel, segments([(200e-6, 0.02), (350e-6, 0.05)]), Rig(control="velocity"), start="steady"
    )
    native = run.native
    integral = native.bookkeeping.stress_integral
    # (round 26: the run's mean is run_mean_stress; mean_stress, steady, the settled value: test_run_summaries_round26)
    assert run.summary["run_mean_stress"] == pytest.approx(integral[-1] / native.time[-1], rel=1e-14)
    h = np.diff(native.time)
    trapezoid = float(np.sum(0.5 * h * (native.stress[1:] + native.stress[:-1])))
    assert run.summary["run_mean_stress"] == pytest.approx(trapezoid / native.time[-1], rel=1e-4)


def test_the_mean_is_the_settled_cycle_s_not_the_start_up_s(runs):
    """From an empty surface the first whole cycle is the start-up stick (σs 631.6 Pa against the paper's cycle's
    556.4 Pa): the mean is the last whole cycle's, which the quasi-static model's cycle (stick 9.7549 s, slip
    5.509 s; the full model's slip lasts 1.5 % longer) matches to its own ~1 %; the mean over every whole cycle,
    the start-up's included, is further off than that."""
    import stickslip
    from stickslip.protocols import constant

    run = runs[None]
    quasi = stickslip.run("quasi-static", stickslip.load_parameters("gelatin-glass"), constant(PACE, DURATION))
    assert run.summary["mean_stress"] == pytest.approx(quasi.summary["mean_stress"], rel=0.01)
    native = run.native
    whole = [c for c in native.cycles if c.period is not None]
    assert len(whole) == 3 and whole[0].peak_stress == pytest.approx(631.58, abs=0.01)
    ends = (whole[0].start_time, whole[-1].start_time + whole[-1].period)
    i, j = (int(np.argmin(np.abs(native.time - t))) for t in ends)
    slope = native.stiffness * (PACE - native.slider_velocity[i : j + 1])
    every_cycle = _end_corrected_trapezoid(native.time[i : j + 1], native.stress[i : j + 1], slope)
    every_cycle /= native.time[j] - native.time[i]
    assert abs(every_cycle / quasi.summary["mean_stress"] - 1.0) > 0.05  # 356.0 against 383.7 Pa: what it read
