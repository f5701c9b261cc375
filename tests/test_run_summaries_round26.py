"""Round 26: a run's summary describes the solution: a rigidly driven slider has no stick-slip cycles, a steady
run's mean is the value it settled at (every model's), the run's own extremes are reported beside the last
segment's, an extrapolation that is not one exponential says so, and a long run's cycle table is cut to its ends."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip import load_parameters, steady_state
from stickslip.models import get_model
from stickslip.models.base import Rig
from stickslip.protocols import Protocol, Segment, constant, segments

#: 350 -> 1000 -> 350 µm/s, 20 ms each (the tester's step.csv)
STEP = [(350e-6, 0.02), (1e-3, 0.02), (350e-6, 0.02)]


@pytest.fixture(scope="module")
def gel():
    return load_parameters("gelatin-glass")


@pytest.fixture(scope="module")
def step_runs(gel):
    """The velocity step under velocity control from the steady population at 350 µm/s, every accepted step kept
    and sampled every 1 ms and 5 ms."""
    model = get_model("transient")
    rig = Rig(control="velocity")
    return {every: model.run(gel, segments(STEP), rig, start="steady", every=every) for every in (None, 1e-3, 5e-3)}


def test_a_rigidly_driven_slider_has_no_stick_slip_cycles(step_runs):
    """The rows at the step's boundaries carry the velocity of the segment they end (350 µm/s at t = 20 ms, where
    the puller's pace read there is 1000); read against the next segment's pace they made a "stick" and a "jump",
    and the steady run reported one cycle (stick 0.0397 s, σs = 653.43 Pa) whose stick time moved with --every."""
    for every, run in step_runs.items():
        assert run.regime.kind == "steady", every
        assert run.native.cycles == (), every
        assert run.summary["cycles"] == 0, every
        assert math.isnan(run.summary["stick_time"]) and math.isnan(run.summary["peak_stress"]), every
        row = run.row({"cycles": "int", "mean_stress": "float"})  # what a sweep or compare reads
        assert row["cycles"] == 0 and row["mean_stress"] == run.mean


def test_a_steady_mean_is_the_settled_value_whatever_the_sampling(gel, step_runs):
    """σ(350 µm/s) of the steady solver, not the mean of a spurious cycle (522.47 / 520.07 / 507.37 Pa for no
    --every, 1 ms, 5 ms) or of the run (478.9 Pa); the run's mean is reported as run_mean_stress."""
    target = float(steady_state(gel, 350e-6).stress)
    for every, run in step_runs.items():
        assert run.mean == pytest.approx(target, rel=1e-5), every
        assert run.summary["mean_stress"] == run.mean
        # the run's mean is the trace's, an independent trapezoid over the rows (every state without --every)
        if every is None:
            trapezoid = float(np.trapezoid(run.stress, run.time)) / float(run.time[-1])
            assert run.summary["run_mean_stress"] == pytest.approx(trapezoid, rel=1e-3)
        assert run.summary["run_mean_stress"] > target + 50.0  # the 1000 µm/s segment is in it


def test_the_run_s_extremes_hold_the_step_up_s_overshoot(gel, step_runs):
    """The regime's extremes are the last segment's (from t = 40 ms: 653.4 down to 360.3 Pa); the step up's
    overshoot above σ(1 mm/s) lies before it and was in no number.  run_peak_stress is the solution's highest, the
    same at every sampling, at least every row's; run_trough_stress its lowest."""
    above = float(steady_state(gel, 1e-3).stress)
    reference = step_runs[None]
    for every, run in step_runs.items():
        native = run.native
        assert run.summary["run_peak_stress"] >= float(np.max(native.stress))
        assert run.summary["run_peak_stress"] > above + 30.0  # the overshoot, 713.6 Pa over 653.4 Pa
        assert run.summary["run_peak_stress"] > run.peak  # beyond the last segment's highest
        assert run.summary["run_trough_stress"] <= float(np.min(native.stress))
        assert run.summary["run_peak_stress"] == pytest.approx(reference.summary["run_peak_stress"], rel=1e-4), every


def test_the_text_and_json_of_a_step_say_the_run_s_range(capsys, tmp_path):
    protocol = tmp_path / "step.csv"
    protocol.write_text("velocity [um/s],duration [s]\n" + "".join(f"{v * 1e6:g},{t:g}\n" for v, t in STEP))
    args = ["run", "--model", "transient", "--control", "velocity", "--start", "steady", "--protocol", str(protocol)]
    code, out, err = run_main(capsys, *args, "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["cycles"] == [] and summary["summary"]["cycles"] == 0
    assert summary["units"]["run_peak_stress"] == summary["units"]["run_trough_stress"] == "Pa"
    assert summary["run_peak_stress"] > summary["peak_stress"]
    code, text, err = run_main(capsys, *args)
    assert code == 0, err
    assert "cycle 1" not in text
    assert (
        f"range over the whole run: {summary['run_trough_stress']:.6g} ... {summary['run_peak_stress']:.6g} Pa" in text
    )


def test_a_rigid_run_from_empty_means_its_steady_stress(gel):
    """1 mm/s for 50 ms from an empty surface: steady; its mean was the run's, 651.332 Pa, against σ(1 mm/s)."""
    run = get_model("transient").run(gel, constant(1e-3, 0.05), Rig(control="velocity"))
    assert run.regime.kind == "steady"
    assert run.mean == pytest.approx(float(steady_state(gel, 1e-3).stress), rel=1e-5)
    assert run.summary["run_mean_stress"] < run.mean  # the start from no bonds, 0 Pa, is in the run's


def test_a_slide_hold_slide_s_steady_friction_is_mu_ss():
    """Rate-and-state 100 µm/s for 20 s, held 10 s, 100 µm/s for 20 s (a = 0.005, b = 0.01, dc = 10 µm): steady
    sliding at μss = μ0 + (a - b) ln(V/v_ref); the mean over the run's second half held the hold's end (0.576136)."""
    model = get_model("rsf")
    params = model.parameters(None, {"a": "0.005", "b": "0.01", "dc": "10 um"})
    run = model.run(params, segments([(100e-6, 20.0), (0.0, 10.0), (100e-6, 20.0)]))
    assert run.regime.kind == "steady"
    mu_ss = params.mu0 + (params.a - params.states[0].b) * math.log(100e-6 / params.v_ref)
    assert run.mean == pytest.approx(mu_ss, abs=1e-7)
    assert run.summary["mean_friction"] == run.mean
    assert run.summary["run_mean_friction"] < mu_ss - 1e-4  # the hold's lower friction is in the run's mean


def test_a_trace_s_settled_mean_is_over_its_last_segment():
    """Run.from_trace classified over t >= start (the last segment): its mean over the settled half of that
    segment, not over the run's second half, which here holds the first segment's 5 Pa."""
    from stickslip.models.run import Run, settled_mean

    t = np.linspace(0.0, 10.0, 20001)
    stress = np.where(t < 6.0, 5.0, 2.0 + 3.0 * np.exp(-np.clip(t - 6.0, 0.0, None) / 0.1))
    zeros = np.zeros_like(t)
    run = Run.from_trace("trace", t, stress=stress, slider_velocity=zeros, slider_position=zeros,
                         load_point_position=zeros, start=6.0)  # fmt: skip
    assert run.regime.kind == "steady"
    assert run.mean == pytest.approx(2.0, abs=1e-6)
    assert settled_mean(t, stress, math.nan) > 2.5  # the run's second half: the old window
    assert settled_mean(t, stress, math.nan, 6.0) == pytest.approx(2.0, abs=1e-6)


def _verdict(stress_of, duration: float = 0.01, rows: int = 4001):
    """The transient summary's verdict (transient.cycles.judge) on a stress known in closed form, rigidly driven
    at 100 µm/s."""
    from stickslip.transient.cycles import judge

    t = np.linspace(0.0, duration, rows)
    velocity = np.full_like(t, 100e-6)
    return judge(t, stress_of(t), velocity, constant(100e-6, duration), (), [], "velocity", None, resolution=1e-4)


def _still_to_come(message: str) -> float | None:
    if "Pa still to come" not in message:
        return None
    return float(message.split("about ")[1].split(" Pa still to come")[0])


def test_one_exponential_approach_keeps_its_estimate():
    """300 - 60 exp(-t/20 ms): what is left after 10 ms is 60 exp(-0.5) = 36.39 Pa, and the estimate says so."""
    regime, message, _ = _verdict(lambda t: 300.0 - 60.0 * np.exp(-t / 0.02))
    assert regime == "undetermined"
    assert _still_to_come(message) == pytest.approx(60.0 * math.exp(-0.5), rel=0.02)


def test_an_approach_that_is_not_one_exponential_gives_no_false_estimate():
    """300 - 200 exp(-t/1 ms) - 60 exp(-t/20 ms): 36.39 Pa still to come after 10 ms; the one-exponential rule over
    the window's second half reads the fast refill and says ~0.7 Pa (a 1 s hold's re-slide read "about 4.15 Pa
    still to come" 50.4 Pa short of σ(100 µm/s)).  The estimate is given only where it is one exponential's."""
    truth = 60.0 * math.exp(-0.5) + 200.0 * math.exp(-10.0)
    regime, message, _ = _verdict(lambda t: 300.0 - 200.0 * np.exp(-t / 1e-3) - 60.0 * np.exp(-t / 0.02))
    assert regime == "undetermined" and "still changing" in message
    said = _still_to_come(message)
    assert said is None or said == pytest.approx(truth, rel=0.5), message
    assert "not as one exponential approach" in message and "not known" in message


def test_a_reslide_cut_short_is_undetermined_without_a_false_estimate(gel):
    """The 1 s hold's re-slide cut 15 ms in: still recovering from its peak's rupture towards σ(100 µm/s)
    (undetermined is the truth), and no "about ... Pa still to come" short of that value."""
    protocol = Protocol((Segment(100e-6, 0.002), Segment(0.0, 1.0), Segment(100e-6, 0.015)))
    run = get_model("transient").run(gel, protocol, Rig(control="velocity"), start="steady", rtol=1e-3)
    left = float(steady_state(gel, 100e-6).stress) - float(run.stress[-1])
    assert left > 40.0 and run.regime.kind == "undetermined"
    said = _still_to_come(run.message)
    assert said is None or said == pytest.approx(left, rel=0.5), run.message


def test_a_long_quasi_static_run_lists_its_first_and_last_cycles():
    """50 µm/s for 1e4 s: 433 cycles.  The text listed every one (1e6 s: 43,316 lines, 35 s, 550 MB); it lists the
    first 5 and the last 3, with the count left out, as the transient run's text does (one piece of code)."""
    from stickslip.cli.run_report import CYCLE_HEAD, CYCLE_TAIL, record_text

    run = get_model("quasi-static").run(load_parameters("gelatin-glass"), constant(50e-6, 1e4))
    count = len(run.native.cycles)
    assert count > 100
    lines = record_text(run).splitlines()
    numbered = [line.split("│")[1].strip() for line in lines if line.startswith("│") and line.split("│")[1].strip()]
    expected = (
        [str(k) for k in range(1, CYCLE_HEAD + 1)] + ["…"] + [str(count - k) for k in range(CYCLE_TAIL - 1, -1, -1)]
    )
    assert numbered == expected
    assert any(f"{count - CYCLE_HEAD - CYCLE_TAIL:,} cycles more" in line and "--json" in line for line in lines)


def test_an_estimate_the_rows_cannot_check_says_so():
    """The same two exponentials on 7 rows: the spans the check reads are not resolved, and the estimate, if
    given, is called one exponential's, unchecked."""
    regime, message, _ = _verdict(lambda t: 300.0 - 200.0 * np.exp(-t / 1e-3) - 60.0 * np.exp(-t / 0.02), rows=7)
    assert regime == "undetermined"
    if _still_to_come(message) is not None:
        assert "if the approach is one exponential, which 7 rows cannot check" in message


def test_an_undetermined_run_with_periods_is_not_said_to_have_no_oscillation():
    """The text said "94 period(s) ...", "period 0.000444168 s (no whole cycle within the run)" and "(no
    oscillation)" of one run: "no oscillation" is said only where no period was seen."""
    from stickslip.cli.run_cmd import summary_text

    base = {
        "model": "transient",
        "protocol": [{"velocity": 1e-6, "duration": 0.02}],
        "rig": {"control": "velocity", "stiffness": None},
        "regime": "undetermined",
        "status": "ok",
        "message": "undetermined: 94 period(s), ...",
        "evidence": "",
        "oscillates": False,
        "periods_seen": 94,
        "period": 0.000444168,
        "peak_stress": 40661.5,
        "trough_stress": 37500.7,
        "run_mean_stress": 39024.0,
    }
    text = summary_text(base)
    assert "period 0.000444168 s (no whole cycle within the run)" in text
    assert "no oscillation" not in text
    quiet = summary_text({**base, "periods_seen": 0, "period": None})
    assert "over the run (no oscillation)" in quiet
