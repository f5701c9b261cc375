"""A run's status is the same wherever it is read (a tester's findings, 2026-11-30): a run stopped at its budget
says "stopped" in the file it writes, not only in its summary; a run the model cannot continue is "failed" (exit 3)
in every model, with what it computed; and files of the wrong kind are named as such in one line."""

from __future__ import annotations

import json

import pytest

from cli_helpers import run_main
from stickslip import load_parameters, simulate, steady_state
from stickslip.display import velocity
from stickslip.models.run import Run, recorded_status


def test_a_run_stopped_at_its_budget_says_so_in_its_file_and_analyze_notes_it(tmp_path, capsys):
    """The CSV's first line said status "ok" while the summary said "stopped" (exit 3); `analyze` then read it
    as a whole record without a word."""
    trace = tmp_path / "budget.csv"
    args = ["--v0", "100 um/s", "--duration", "10 s", "--no-reduce", "--max-steps", "300", "-o", str(trace)]
    code, _, err = run_main(capsys, "transient", *args)
    assert code == 3 and "budget of 300 steps" in err
    assert recorded_status(trace)[0] == "stopped"
    assert Run.read(trace).status == "stopped"
    code, _, err = run_main(capsys, "analyze", str(trace))
    assert code == 0, err
    assert f"note: {trace} is a run that stopped before its end: transient: stopped at the budget" in err
    # gzipped, as analyze reads its rows (round 28): its first line was read raw and the run taken as "ok"
    import gzip

    packed = tmp_path / "budget.csv.gz"
    packed.write_bytes(gzip.compress(trace.read_bytes()))
    assert recorded_status(packed)[0] == "stopped"
    broken = tmp_path / "broken.csv.gz"
    broken.write_bytes(gzip.compress(trace.read_bytes())[:40])
    assert recorded_status(broken) == ("ok", "")  # left to the reader, which refuses it in one line


def test_the_stick_chains_without_a_landing_point_fail_the_transient_run(capsys):
    """At 0.1 m/s the chains collapse at 1024.5 Pa, above the aging curve's right branch (up to 982.4 Pa): the
    transient run ended at 0.033 s of 0.1 s with status ok and exit 0; the quasi-static model failed there."""
    code, out, err = run_main(capsys, "transient", "--v0", "0.1 m/s", "--duration", "0.1 s", "--stick-population",
                              "--json")  # fmt: skip
    assert code == 3
    summary = json.loads(out)
    assert summary["status"] == "failed" and summary["regime"] == "undetermined"
    assert summary["end_time"] == pytest.approx(0.0334275, rel=1e-5)
    assert "the model stops at t = 0.0334275 s of the 0.1 s asked for" in summary["message"]
    assert "the run failed" in err
    quasi = simulate(load_parameters("gelatin-glass"), 0.1, 0.1)
    assert quasi.status == "failed"  # the same verdict as the quasi-static model's


@pytest.mark.parametrize("v0", [6e-3, 13.8e-3])
def test_above_the_curve_s_maximum_the_quasi_static_run_fails_as_beyond_it(v0):
    """Above the aging curve's maximum (5.0385 mm/s) the slip after the jump has nothing to relax to.  At 6 and
    13.8 mm/s the jump lands (σs 810 Pa is on the branch) and Eq 10 raised a ModelError (exit 2, an error row in a
    sweep), while at 0.1 m/s, whose σs is off the branch, the run failed with what it computed (exit 3): now both
    fail after the stick, and say why."""
    sim = simulate(load_parameters("gelatin-glass"), v0, 10.0)
    assert sim.status == "failed" and sim.regime == "undetermined"
    assert "at or above the maximum of the steady curve (5038.5 µm/s)" in sim.message
    assert "the model stops at t =" in sim.message
    assert sim.time[-1] < 1.0 and sim.stress[-1] > 257.36  # the stick it computed, up to σs


def test_fast_velocities_are_written_out_not_in_exponent_form():
    assert velocity(0.1, 4) == "100 mm/s" and velocity(1.0, 4) == "1 m/s"
    assert velocity(7.02e-4) == "702 µm/s" and velocity(123.4567e-6, 4) == "123.5 µm/s"


def test_json_given_to_a_table_reader_is_named_as_json(tmp_path, capsys):
    """`curve --format json` fed to `fit steady` said "cannot read header '{'"; `analyze` asked for --v0 first."""
    curve = tmp_path / "c.json"
    code, _, err = run_main(capsys, "curve", "--points", "10", "--format", "json", "-o", str(curve))
    assert code == 0, err
    for command in (["fit", "steady"], ["analyze"]):
        code, _, err = run_main(capsys, *command, str(curve))
        assert code == 2
        assert "row 1 starts with '{': a JSON file, not a CSV table" in err, command


def test_a_header_only_record_is_bad_input_for_rsf_fit(tmp_path, capsys):
    """An internal error (TypeError from numpy, exit 1) before."""
    path = tmp_path / "header.csv"
    path.write_text("time [s],friction [1],load_point_position [m]\n")
    code, _, err = run_main(capsys, "rsf", "fit", str(path))
    assert code == 2 and err.strip() == f"stickslip: error: {path}: 0 data row(s); expected at least 10 to fit a record"


def test_an_option_s_bad_value_names_the_option(capsys):
    code, _, err = run_main(capsys, "rsf", "simulate", "--a", "0", "--v0", "1 um/s", "--duration", "1 s")
    assert code == 2 and err.strip() == "stickslip: error: --a: expected a value > 0, got 0"


def test_sweep_plot_names_a_mistyped_x_before_asking_for_y(tmp_path, capsys):
    """Without --y on a sweep of two keys, a mistyped --x was answered "--y: this sweep varies ...; give --y KEY"."""
    out = tmp_path / "sweep"
    code, _, err = run_main(capsys, "sweep", "--vary", "pulling_velocity=50 um/s,80 um/s", "--vary",
                            "block.stiffness=300 kPa/m,600 kPa/m", "--duration", "5 s", "--workers", "0",
                            "--quiet", "-o", str(out))  # fmt: skip
    assert code == 0, err
    code, _, err = run_main(capsys, "sweep", "plot", str(out), "--x", "foo", "-o", str(tmp_path / "p.png"))
    assert code == 2
    assert "--x foo: not a varied key of this sweep; expected one of pulling_velocity, block.stiffness" in err


def test_a_two_state_fit_of_a_one_state_record_fails_by_the_f_test(tmp_path):
    """The tester's up-down record of one aging state (a 0.010, b 0.015, Dc 20 µm), fitted with two states: "ok"
    with b ± 0.03 and b2 ± 0.03 in a ridge of b + b2.  Two states lower chi-square by 0.18 % (p = 0.31)."""
    import numpy as np

    from stickslip import protocols
    from stickslip.rsf.data import LabRecord
    from stickslip.rsf.fit import fit_record
    from stickslip.rsf.params import rsf_params
    from stickslip.rsf.solver import simulate as rsf_simulate

    t = np.arange(0.0, 130.0, 0.25)
    history = protocols.segments([(1e-6, 40.0), (10e-6, 30.0), (1e-6, 60.0)])
    run = rsf_simulate(rsf_params(0.010, 0.015, 20e-6, stiffness=2000.0), history, times=t)
    rng = np.random.default_rng(1)
    record = LabRecord.from_arrays(t, run.load_point_displacement, run.friction + 2e-4 * rng.standard_normal(t.size))
    fit = fit_record(record, states=2, protocol=history)
    assert fit.status == "failed" and "second state" in fit.reason and "--states 1" in fit.reason
    assert len(repr(fit)) < 1200 and f"model_friction=<{t.size} values>" in repr(fit)  # was 5 900 characters


def test_a_multi_segment_run_s_range_names_its_window(capsys):
    """The range shown is the last segment's (the regime's window), the mean the run's: "lowest 30.6 Pa, highest
    61.3 Pa, mean 25.5 Pa over the run" had the mean outside the range (the run starts at 0 Pa)."""
    code, out, err = run_main(capsys, "transient", "--v0", "100 um/s", "--duration", "1 s", "--segment",
                              "200 um/s:0.5 s")  # fmt: skip
    assert code == 0, err
    line = next(x for x in out.splitlines() if "lowest" in x)
    assert "over the last segment (from t = 1 s), mean" in line and line.endswith("over the run (no oscillation)")
    lowest, highest, mean = (float(line.split(word)[1].split()[0]) for word in ("lowest", "highest", "mean"))
    assert mean < lowest < highest  # the mean is over the whole run, from 0 Pa


def test_a_puller_that_never_moves_leaves_the_block_at_rest_not_sliding(tmp_path, capsys):
    """It read "steady sliding at 0 µm/s ... (tolerance 1e-305 Pa)", with advice to add the stick chains."""
    hold = tmp_path / "hold.csv"
    hold.write_text("time,velocity\n0,0\n5,0\n")
    code, out, err = run_main(capsys, "run", "--model", "transient", "--protocol", str(hold))
    assert code == 0, err
    assert "regime: stuck" in out and "the puller never moves" in out
    assert "sliding" not in out and "--stick-population" not in out


def test_a_transient_run_the_solver_cannot_follow_keeps_what_it_computed(tmp_path, capsys):
    """A run the solver cannot follow (exit 3) used to write nothing, and a sweep's row was an "error" without
    results; now both keep the run up to there, status "failed".  The case (round 30): 300 s held under velocity
    control, then re-slid at 100 µm/s: the bonds aged at rest die at the FENE wall within ~2e-13 s, below what the
    clock resolves at t = 300 s (docs/transient.md section 2, step 6; section 17's 4 MPa/m creeping block, the case
    before, no longer fails: section 22).  The sweep's point (a spring and a constant pace) is the stick chains'
    collapse at 0.1 m/s, which has no landing point: the model stops there."""
    trace = tmp_path / "fail.csv"
    args = ["--control", "velocity", "--v0", "100 um/s", "--duration", "2 ms", "--segment", "0 um/s:300 s",
            "--segment", "100 um/s:15 ms", "--start", "steady"]  # fmt: skip
    code, out, err = run_main(capsys, "run", "--model", "transient", *args, "-o", str(trace), "--json")
    assert code == 3 and "the run failed: transient solver failed at t = 300.0" in err and "FENE wall" in err
    summary = json.loads(out)
    assert summary["status"] == "failed" and 300.002 < summary["end_time"] < 300.017
    run = Run.read(trace)
    assert run.status == "failed" and run.time[-1] == pytest.approx(summary["end_time"], rel=1e-12)
    assert run.stress[-1] == pytest.approx(summary["final_stress"], rel=1e-9)
    # what was kept is the run itself: the steady start, and the slider where the imposed velocity put it
    steady = float(steady_state(load_parameters("gelatin-glass"), 100e-6).stress)
    assert run.stress[0] == pytest.approx(steady, rel=1e-6)
    travel = 100e-6 * (2e-3 + run.time[-1] - 300.002)
    assert run.slider_position[-1] == pytest.approx(travel, rel=1e-6)
    assert run.time.size > 100 and 300.002 < run.time[-1]
    from stickslip.sweeps.models import get_model, run_point

    args = ["--v0", "0.1 m/s", "--duration", "0.1 s", "--start", "steady", "--setting", "stick_population=true"]
    code, out, err = run_main(capsys, "run", "--model", "transient", *args, "--json")
    assert code == 3 and "the run failed" in err and "no landing point" in err
    summary = json.loads(out)
    assert summary["status"] == "failed" and 0.0 < summary["end_time"] < 0.1
    row = run_point(get_model("transient"), {"pulling_velocity": 0.1}, {"duration": 0.1, "stick_population": True})
    assert row["status"] == "failed" and row["mean_stress"] == pytest.approx(summary["run_mean_stress"], rel=1e-9)
    assert "no landing point" in row["message"] and "t = " in row["message"]


def test_a_key_set_twice_is_refused_not_the_last_taken(capsys):
    code, _, err = run_main(capsys, "simulate", "--set", "block.height=5 mm", "--set", "block.height=20 mm", "--v0",
                            "50 um/s", "--duration", "10 s")  # fmt: skip
    assert code == 2 and err.strip() == (
        "stickslip: error: --set block.height: given twice ('5 mm', then '20 mm'); give it once"
    )
