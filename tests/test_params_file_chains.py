"""What ``rsf simulate -o`` and ``rsf fit -o`` write beside their output (``NAME.params.json``: the parameters, the
load-point history and the start) is read by the other commands that take ``--params``: ``run --model rsf`` reruns
the history as ``rsf simulate --params`` does, and ``params show`` / ``params export`` read the file (a tester's
round-25 findings: ``run --model rsf`` asked for a protocol, ``params show`` called the JSON "malformed TOML")."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
from tests.cli_helpers import run_main

#: a velocity step up and down on a spring, the slider's own law: its trace is what the reruns must give again
FIRST = ("rsf", "simulate", "--a", "0.011", "--b", "0.015", "--dc", "20 um", "--mu0", "0.61", "--v-ref", "1 um/s",
         "--stiffness", "4e-3 1/um", "--segment", "1 um/s:30 s", "--segment", "10 um/s:20 s",
         "--segment", "1 um/s:30 s", "--every", "0.5 s")  # fmt: skip


def _trace(path) -> pd.DataFrame:
    return pd.read_csv(path, comment="#")


def test_run_model_rsf_reruns_the_history_a_params_json_carries(capsys, tmp_path):
    first = tmp_path / "step.csv"
    assert run_main(capsys, *FIRST, "-o", str(first))[0] == 0
    sidecar = tmp_path / "step.params.json"
    assert sidecar.is_file()
    again = tmp_path / "again.csv"
    status, _, err = run_main(capsys, "run", "--model", "rsf", "--params", str(sidecar), "--every", "0.5 s", "-o",
                              str(again))  # fmt: skip
    assert status == 0, err
    original, rerun = _trace(first), _trace(again)
    friction = next(c for c in original.columns if c.startswith("friction"))
    assert len(original) == len(rerun) == 161  # 80 s every 0.5 s, both ends
    assert np.array_equal(original.iloc[:, 0], rerun.iloc[:, 0])
    # the same parameters, history and start: the same trace as the run that wrote the file
    assert np.max(np.abs(original[friction] - rerun[friction])) < 1e-9
    step = original[friction].to_numpy()
    assert step.max() - step.min() > 0.01  # the step shows: a rerun of a constant would not test the history


def test_an_explicit_protocol_still_wins_over_the_files_history(capsys, tmp_path):
    first = tmp_path / "step.csv"
    assert run_main(capsys, *FIRST, "-o", str(first))[0] == 0
    status, out, err = run_main(capsys, "run", "--model", "rsf", "--params", str(tmp_path / "step.params.json"),
                                "--v0", "3 um/s", "--duration", "5 s", "--json")  # fmt: skip
    assert status == 0, err
    assert json.loads(out)["protocol"] == [{"velocity": 3e-6, "duration": 5.0}]


def test_params_show_and_export_read_a_rate_and_state_file(capsys, tmp_path):
    first = tmp_path / "step.csv"
    assert run_main(capsys, *FIRST, "-o", str(first))[0] == 0
    sidecar = tmp_path / "step.params.json"
    status, out, err = run_main(capsys, "params", "show", str(sidecar))
    assert status == 0, err
    rows = {line.split("│")[1].strip(): line for line in out.splitlines() if line.count("│") >= 4}
    assert "0.011 " in rows["a"] and "0.61 " in rows["mu0"] and "1e-06" in rows["v_ref"] and "m/s" in rows["v_ref"]
    assert "4000 " in rows["stiffness"] and "0.015 " in rows["states[1].b"] and "2e-05" in rows["states[1].dc"]
    exported = tmp_path / "step.toml"
    assert run_main(capsys, "params", "export", str(sidecar), "-o", str(exported))[0] == 0
    # the exported TOML runs the same slider: the first segment again, from the TOML's parameters
    by_toml, by_json = tmp_path / "toml.csv", tmp_path / "json.csv"
    for params, out_path in ((exported, by_toml), (sidecar, by_json)):
        protocol = ("--v0", "1 um/s", "--duration", "30 s", "--segment", "10 um/s:20 s", "--every", "1 s")
        status, _, err = run_main(capsys, "rsf", "simulate", "--params", str(params), *protocol, "-o", str(out_path))
        assert status == 0, err
    assert np.array_equal(_trace(by_toml).to_numpy(), _trace(by_json).to_numpy())


def test_params_show_refuses_set_on_a_rate_and_state_file_in_one_line(capsys, tmp_path):
    assert run_main(capsys, *FIRST, "-o", str(tmp_path / "step.csv"))[0] == 0
    status, _, err = run_main(capsys, "params", "show", str(tmp_path / "step.params.json"), "--set", "a=0.02")
    assert status == 2 and err.count("\n") == 1 and "rate-and-state" in err and "--set" in err, err
