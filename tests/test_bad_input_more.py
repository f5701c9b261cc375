"""Issue 29: the cases in the time-dependent and rate-and-state commands (one line, exit 2; no side files)."""

from __future__ import annotations

import os
import re
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
    assert got and got[0].startswith(b"# stickslip run") and b"\ntime [s]," in got[0]  # the Run CSV, whole
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


def test_an_overflow_names_the_most_extreme_value_typed(capsys, monkeypatch):
    """An overflow no check foresaw, in one line naming the value typed farthest from 1 (a damping of 1e308 Pa s/m
    did this until the range check of 2026-11-30 refused it up front; the run's overflow is simulated here)."""
    import stickslip.transient

    def overflowing(*args, **kwargs):
        raise FloatingPointError("overflow encountered in multiply")

    monkeypatch.setattr(stickslip.transient, "run_transient", overflowing)
    code, _, err = run_main(
        capsys, "transient", "--v0", "50 um/s", "--duration", "1 s", "--mass", "1 kg/m^2", "--damping", "1e12 Pa s/m"
    )
    assert code == 2 and err.count("\n") == 1, err
    assert "floating-point range" in err and "--damping '1e12 Pa s/m'" in err, err


def test_most_extreme_input_ignores_ordinary_values():
    from stickslip.cli.main import _most_extreme_input

    assert _most_extreme_input(["transient", "--v0", "50 um/s", "--duration", "1 s"]) == ""
    assert "--set 'bonds.bond_time=1e-320 s'" in _most_extreme_input(["run", "--set", "bonds.bond_time=1e-320 s"])
    assert "--rtol '1e-40'" in _most_extreme_input(["transient", "--rtol=1e-40"])


def test_rsf_simulate_with_an_unknown_figure_format_writes_nothing(tmp_path, capsys):
    trace, figure = tmp_path / "t.csv", tmp_path / "x.json"
    code, _, err = run_main(capsys, "rsf", "simulate", "--v0", "1 um/s", "--duration", "10 s", "-o", str(trace),
                            "--plot", str(figure))  # fmt: skip
    assert code == 2 and err.count("\n") == 1 and "--plot" in err and "unknown figure format .json" in err, err
    assert sorted(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "command",
    [["rsf", "simulate", "--v0", "1 um/s", "--duration", "10 s"], ["rsf", "stability", "--velocity", "1 um/s"]],
)
def test_rsf_refuses_a_negative_reference_friction(capsys, command):
    code, _, err = run_main(capsys, *command, "--mu0", "-1")
    assert code == 2 and err.count("\n") == 1 and "mu0: expected a positive friction coefficient" in err, err


def test_rsf_fit_refuses_bare_numbers_in_its_segments(capsys):
    from stickslip.fitting.datasets import data_path

    record = data_path("giacomel-sepiolite/velstep3_TR2_exp013_sepiolite.txt")
    code, _, err = run_main(capsys, "rsf", "fit", str(record), "--segment", "10:10")
    assert code == 2 and err.count("\n") == 1 and "--segment '10:10'" in err and "needs a unit" in err, err


def test_api_refusals_are_typed_and_name_the_argument():
    import stickslip
    from stickslip.errors import DataError, ParameterError, UnitError
    from stickslip.fitting import datasets, fit_steady
    from stickslip.transient import critical_stiffness

    with pytest.raises(ParameterError, match="params: expected a stickslip Parameters set"):
        critical_stiffness(None, 50e-6)
    with pytest.raises(DataError, match=r"data: expected SteadyData .* or the path"):
        fit_steady(None)
    with pytest.raises(UnitError, match=r"split: .* expected a velocity"):
        fit_steady(datasets.synthetic_steady_path(), split="800 Pa")
    with pytest.raises(stickslip.StickslipError):
        fit_steady(datasets.synthetic_steady_path(), split="-1 um/s")


def test_fit_steady_takes_its_split_with_a_unit():
    from stickslip.fitting import datasets, fit_steady

    path = datasets.synthetic_steady_path()
    with_unit, in_si = fit_steady(path, split="800 um/s"), fit_steady(path, split=800e-6)
    assert with_unit.split == pytest.approx(800e-6, rel=1e-12) and in_si.split == pytest.approx(800e-6, rel=1e-12)
    assert with_unit.critical_velocity.value == pytest.approx(in_si.critical_velocity.value, rel=1e-6)


def test_an_inertial_rsf_slider_that_stops_says_so_in_words():
    """A slider with mass whose velocity underflows (it stops) has no state of rest in ln V: a ModelError that
    says the slider stopped, not an internal ZeroDivisionError nor 'the inertia is too small to matter'."""
    import stickslip
    from stickslip import protocols
    from stickslip.errors import ModelError
    from stickslip.models import Rig

    spec = {"mu0": 0.5, "v_ref": 1e-3, "a": 0.001, "b": 0.015, "dc": "10 um", "normal_stress": 1e3}
    params = stickslip.get_model("rsf").parameters(None, spec)
    rig = Rig(stiffness=1e4, damping=100.0, mass=1.0)
    with pytest.raises(ModelError, match="the slider stopped") as info:
        stickslip.run("rsf", params, protocols.constant(0.03, 2.0), rig, start=0.033)
    assert "too small to matter" not in str(info.value)


@pytest.mark.parametrize(
    ("words", "named"),
    [
        ({"progress": "notcallable"}, "progress: expected a function"),
        ({"control": "velocity", "stiffness": 1e5}, "stiffness: 100000.0 given with control='velocity'"),
        ({"snapshot_times": [-1.0]}, "snapshot_times: expected times within the run, 0 to 0.01 s, got -1.0"),
        ({"snapshot_times": [float("nan")]}, "snapshot_times: expected times within the run"),
        ({"snapshot_times": [0.5]}, "got 0.5"),
        ({"snapshot_times": "soon"}, "snapshot_times: expected times in s"),
    ],
)
def test_run_transient_refuses_its_words_before_a_step(words, named):
    import stickslip
    from stickslip import protocols
    from stickslip.errors import ParameterError
    from stickslip.transient import run_transient

    with pytest.raises(ParameterError, match=re.escape(named)):
        run_transient(stickslip.load_parameters(), protocols.constant(50e-6, 0.01), **words)


def test_run_transient_keeps_a_snapshot_at_a_time_within_the_run():
    import stickslip
    from stickslip import protocols
    from stickslip.transient import run_transient

    result = run_transient(stickslip.load_parameters(), protocols.constant(50e-6, 0.01), snapshot_times=[0.005])
    assert any(abs(s.time - 0.005) < 1e-12 for s in result.snapshots)


def test_the_softest_block_accepted_against_the_bonds_still_gives_k_v0_t():
    """The limit of the pinned slider: at K just above 1e-16 N0 M (N0 = 1e25 m^-2 with the paper's chains) the stuck
    block's sigma is still K V0 t to 1e-5 (it was 2.6e-2 off at 3e-21 N0 M); 10 x those bonds are refused."""
    import numpy as np

    from stickslip.errors import ParameterError
    from stickslip.parameters import load_parameters
    from stickslip.protocols import constant
    from stickslip.transient import run_transient
    from stickslip.transient.solver import PINNED

    base = load_parameters("gelatin-glass")
    k = base.block.effective_stiffness
    bonds = k / (3.0 * PINNED)  # N0 M, 3 x inside the limit
    params = base.with_overrides({"bonds.site_density": bonds / base.bonds.chain_stiffness})
    run = run_transient(params, constant(50e-6, 0.1), control="block")
    stuck = k * 50e-6 * run.time
    assert np.max(np.abs(run.stress - stuck)) <= 1e-5 * stuck[-1]
    softer = base.with_overrides({"bonds.site_density": 10.0 * bonds / base.bonds.chain_stiffness})
    with pytest.raises(ParameterError, match="less than 1e-16 x the bonds' own"):
        run_transient(softer, constant(50e-6, 0.1), control="block")
