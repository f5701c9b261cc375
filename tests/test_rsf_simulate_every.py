"""``rsf simulate --every``: the run's end is always a row, and a run that blows up fails the same way (exit 3,
the slip rate's run-away, the trace up to it) whether or not the trace is sampled."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from cli_helpers import run_main
from stickslip import protocols
from stickslip.numerics.grid import sample_grid
from stickslip.rsf import rsf_params, simulate
from stickslip.transient import solver as transient_solver

UM = 1e-6
STABLE = ["--a", "0.01", "--b", "0.005", "--dc", "10 um", "--stiffness", "1e-3 1/um", "--v0", "1 um/s"]
#: b > a under a spring far below k_c: the quasi-static slider runs away after the step (at t = 6.93 s)
RUNAWAY = ["--a", "0.005", "--b", "0.01", "--dc", "10 um", "--stiffness", "1e-4 1/um", "--v0", "1 um/s",
           "--duration", "1 s", "--segment", "10 um/s:200 s"]  # fmt: skip


def _trace(path):
    frame = pd.read_csv(path, skiprows=1)  # the Run CSV: its metadata line first
    frame.columns = [c.split(" [")[0] for c in frame.columns]
    return frame


@pytest.mark.parametrize(("duration", "every"), [(10.0, 3.0), (1001.0, 20.0), (0.3, 0.1), (0.7, 0.1), (2.0, 5.0)])
def test_a_sampled_run_ends_at_the_protocols_end(duration, every):
    params = rsf_params(0.01, 0.005, 10 * UM)
    run = simulate(params, protocols.constant(UM, duration), every=every)
    assert run.time[-1] == duration  # was 9 s for 10 s every 3 s, 1000 s for 1001 s every 20 s
    assert np.all(np.diff(run.time) > 0)
    assert run.time[:-1] == pytest.approx(every * np.arange(run.time.size - 1))


def test_the_cli_writes_and_reports_the_end(tmp_path, capsys):
    trace = tmp_path / "rsf_end.csv"
    code, out, err = run_main(capsys, "rsf", "simulate", *STABLE, "--duration", "10 s", "--every", "3 s",
                              "-o", str(trace), "--json")  # fmt: skip
    assert code == 0, err
    assert json.loads(out)["end_time"] == 10.0
    assert list(_trace(trace)["time"]) == [0.0, 3.0, 6.0, 9.0, 10.0]
    code, out, err = run_main(capsys, "rsf", "simulate", *STABLE, "--duration", "10 s", "--every", "3 s")
    assert code == 0, err
    assert "at t = 10 s:" in out + err


def test_the_transient_model_samples_on_the_same_grid():
    assert transient_solver._sample_grid is sample_grid
    assert list(sample_grid(3.0, 10.0)) == [0.0, 3.0, 6.0, 9.0, 10.0]
    assert sample_grid(None, 10.0).size == 0


@pytest.mark.parametrize("every", [None, 0.5])
def test_a_run_away_is_a_blow_up_whatever_the_sampling(every):
    params = rsf_params(0.005, 0.01, 10 * UM, stiffness=100.0)
    run = simulate(params, protocols.segments([(UM, 1.0), (10 * UM, 200.0)]), every=every)
    assert run.status == "blow-up"  # without --every: a ModelError "stalled ... use the classical form" (exit 2)
    assert "give eta or a mass" in run.message
    assert run.time[-1] == pytest.approx(6.930688, rel=1e-6)  # the trace ends at the blow-up, sampled or not
    assert run.slider_velocity[-1] == pytest.approx(1e5, rel=1e-3)


def test_the_cli_fails_a_run_away_with_exit_3_and_its_trace_either_way(tmp_path, capsys):
    outcomes = []
    for name, extra in (("plain", []), ("sampled", ["--every", "0.5 s"])):
        trace = tmp_path / f"{name}.csv"
        code, out, err = run_main(capsys, "rsf", "simulate", *RUNAWAY, *extra, "-o", str(trace), "--json")
        assert code == 3, err
        assert "blow-up: the slip rate passed" in err and "give eta or a mass" in err
        assert "classical form" not in err and "stalled" not in err
        summary = json.loads(out)
        frame = _trace(trace)
        assert frame["time"].iloc[-1] == pytest.approx(summary["end_time"], rel=1e-12)
        outcomes.append((summary["status"], summary["end_time"], summary["final_friction"], summary["message"]))
    assert outcomes[0] == outcomes[1]


def test_a_stall_of_the_classical_form_does_not_advise_the_classical_form(capsys):
    code, _, err = run_main(capsys, "rsf", "simulate", "--segment", "1 um/s:10 s", "--segment", "10 um/s:10 s",
                            "--a", "1e-300")  # fmt: skip
    assert code == 2, err
    assert "rate-and-state solver stalled" in err
    assert "use the classical form" not in err  # it is the form in use
