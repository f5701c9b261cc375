"""``stickslip rsf simulate`` and ``stickslip rsf stability`` end to end."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from cli_helpers import run_main

STEP = ["--segment", "1 um/s:10 s", "--segment", "10 um/s:30 s"]
MODEL = ["--a", "0.005", "--b", "0.01", "--dc", "10 um", "--v-ref", "1 um/s", "--stiffness", "1e-3 1/um"]


def test_simulate_writes_trace_parameters_and_summary(tmp_path, capsys):
    trace = tmp_path / "trace.csv"
    code, out, err = run_main(capsys, "rsf", "simulate", *MODEL, *STEP, "--every", "1 s", "-o", str(trace), "--json",
                              "--plot", str(tmp_path / "run.png"))  # fmt: skip
    assert code == 0, err
    summary = json.loads(out)
    assert set(summary) >= {"regime", "final_friction", "period", "peak_friction", "trough_friction", "message"}
    assert summary["final_friction"] == pytest.approx(0.6 - 0.005 * math.log(10), abs=2e-6)  # still ringing at 40 s
    frame = pd.read_csv(trace, skiprows=1)  # the Run CSV: its metadata line first
    assert list(frame.columns) == ["time [s]", "friction [1]", "slider_velocity [m/s]", "slider_position [m]",
                                   "load_point_position [m]", "state [s]"]  # fmt: skip
    frame.columns = [c.split(" [")[0] for c in frame.columns]
    # rsfmodel's published friction at t = 11 s (tests/test_rsf_rsfmodel.py has the full comparison)
    assert frame["friction"].iloc[11] == pytest.approx(0.60720485, abs=1e-7)
    assert (tmp_path / "run.png").stat().st_size > 0
    code, out2, _ = run_main(capsys, "rsf", "simulate", "--params", str(tmp_path / "trace.params.json"), "--every",
                             "1 s", "--json")  # fmt: skip
    assert code == 0 and json.loads(out2)["final_friction"] == pytest.approx(summary["final_friction"], abs=1e-12)


def test_simulate_stiffness_in_pa_per_m_with_normal_stress(capsys):
    code, out, _ = run_main(capsys, "rsf", "simulate", "--a", "0.005", "--b", "0.01", "--dc", "10 um",
                            "--stiffness", "30 MPa/mm", "--normal-stress", "30 MPa", *STEP, "--every", "1 s",
                            "--json")  # fmt: skip
    assert code == 0
    _, out2, _ = run_main(capsys, "rsf", "simulate", *MODEL, *STEP, "--every", "1 s", "--json")
    assert json.loads(out)["final_friction"] == pytest.approx(json.loads(out2)["final_friction"], abs=1e-12)


def test_simulate_blow_up_is_said_in_words(capsys):
    code, out, _ = run_main(capsys, "rsf", "simulate", "--law", "slip", "--a", "0.01", "--b", "0.015", "--dc", "10 um",
                            "--stiffness", "250 1/m", "--start-velocity", "1.1 um/s", "--segment", "1 um/s:300 s",
                            "--every", "0.5 s", "--json")  # fmt: skip
    assert code == 3  # as `run --model rsf`: a run that ran away is a failed run, its summary printed first
    summary = json.loads(out)
    assert summary["status"] == "failed" and summary["regime"] == "blow-up"
    assert "radiation damping" in summary["message"]


def test_stability_json_matches_closed_form(capsys):
    code, out, _ = run_main(capsys, "rsf", "stability", "--a", "0.01", "--b", "0.015", "--dc", "20 um",
                            "--stiffness", "100 1/m", "--velocity", "2 um/s", "--json")  # fmt: skip
    assert code == 0
    report = json.loads(out)
    assert report["critical_stiffness"] == pytest.approx(0.005 / 20e-6, rel=1e-12)
    assert report["neutral_period"] == pytest.approx(2 * np.pi * 10 * np.sqrt(2.0), rel=1e-12)
    assert report["stable"] is False


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--dc", "10 kg"], "--dc"),
        (["--stiffness", "30 MPa/mm"], "--normal-stress"),
        (["--law", "bogus"], "law 'bogus'"),
        (["--b2", "0.01"], "--b2/--dc2"),
        (["--every", "-1 s"], "--every"),
    ],
)
def test_simulate_bad_input_is_one_line_exit_2(capsys, args, message):
    code, _, err = run_main(capsys, "rsf", "simulate", "--segment", "1 um/s:10 s", *args)
    assert code == 2
    assert err.startswith("stickslip: error:") and message in err and err.count("\n") == 1


def test_simulate_reads_a_protocol_file(tmp_path, capsys):
    protocol = tmp_path / "protocol.csv"
    protocol.write_text("velocity,duration\n1e-6,10\n1e-5,30\n")
    code, out, _ = run_main(capsys, "rsf", "simulate", *MODEL, "--protocol", str(protocol), "--every", "1 s", "--json")
    code2, out2, _ = run_main(capsys, "rsf", "simulate", *MODEL, *STEP, "--every", "1 s", "--json")
    assert code == code2 == 0
    # "10 um/s" is 9.999999999999999e-06 m/s, the file's 1e-5 is not: the runs agree to the solver's rtol (1e-10)
    assert json.loads(out)["final_friction"] == pytest.approx(json.loads(out2)["final_friction"], abs=1e-11)
