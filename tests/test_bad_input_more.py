"""Issue 29: the cases in the time-dependent and rate-and-state commands (one line, exit 2; no side files)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from cli_helpers import run_main
from stickslip.cli.rsf_cmd import sidecar


@pytest.mark.parametrize("rtol", ["0", "-1e-4", "nan", "0.5"])
def test_transient_refuses_a_tolerance_outside_its_range_in_one_line(capsys, rtol):
    code, _, err = run_main(capsys, "transient", "--v0", "50 um/s", "--duration", "1 s", "--rtol", rtol)
    assert code == 2 and err.count("\n") == 1 and "rtol: expected a number between 1e-12 and 0.1" in err, err


def test_no_parameters_file_beside_standard_output_or_a_special_file(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    assert sidecar(Path("-")) is None and sidecar(fifo) is None and sidecar(Path("/dev/null")) is None
    assert sidecar(tmp_path / "t.csv") == tmp_path / "t.params.json"  # a new or regular file has its own


def test_rsf_simulate_into_a_fifo_writes_nothing_beside_it(tmp_path, capsys):
    import threading

    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()))
    reader.start()
    code, _, err = run_main(capsys, "rsf", "simulate", "--segment", "1 um/s:10 s", "-o", str(fifo))
    reader.join(timeout=60)
    assert code == 0, err
    assert got and got[0].startswith(b"time")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe"]


def test_rsf_fit_mcmc_without_emcee_is_refused_before_any_work(tmp_path, capsys, monkeypatch):
    import importlib.util

    trace = tmp_path / "t.csv"
    code, _, err = run_main(capsys, "rsf", "simulate", "--segment", "1 um/s:10 s", "--segment", "10 um/s:10 s",
                            "--every", "0.1 s", "-o", str(trace))  # fmt: skip
    assert code == 0, err
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "emcee" else real(name, *a))
    code, _, err = run_main(capsys, "rsf", "fit", str(trace), "--mcmc", "20")
    assert code == 2 and err.count("\n") == 1 and "pip install stickslip[bayes]" in err, err
