"""One-line refusals that name what the user wrote: --every, edited parameter files, outputs that cannot be
written, and the units of analyze's cycle table and of the run's JSON."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from cli_helpers import run_main
from stickslip.parameters import load_parameters

RUN = ["run", "--v0", "50 um/s", "--duration", "60 s"]


@pytest.mark.parametrize("argv", [["run", "--model", "quasi-static"]])
def test_quasi_static_takes_no_every(capsys, argv):
    code, _, err = run_main(capsys, *argv, "--v0", "50 um/s", "--duration", "60 s", "--every", "1 s")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "--every '1 s': the quasi-static model takes no --every (its trace is its phases, thinned)" in err
    assert "unknown setting" not in err


@pytest.mark.parametrize("command", [["run", "--model", "transient"], ["transient"]])
def test_every_longer_than_the_run_is_said_with_its_unit(capsys, command):
    code, _, err = run_main(capsys, *command, "--v0", "50 um/s", "--duration", "60 s", "--every", "2 min")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "--every: got 2 min (120 s), longer than the run (60 s)" in err


def _edited(tmp_path: Path, name: str, old: str, new: str) -> Path:
    text = load_parameters("gelatin-glass").to_toml()
    assert old in text
    path = tmp_path / name
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize("command", [["stick", "--v0", "50 um/s"], RUN])
def test_unknown_key_in_a_parameter_file_names_the_file(capsys, tmp_path, command):
    path = _edited(tmp_path, "unknown_key.toml", "bond_time =", "bond_tme =")
    code, _, err = run_main(capsys, *command, "--params", str(path))
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert f"{path}: unknown parameter key 'bonds.bond_tme'" in err


@pytest.mark.parametrize("command", [["stick", "--v0", "50 um/s"], RUN])
def test_negative_temperature_in_a_file_is_given_as_written_and_in_si(capsys, tmp_path, command):
    path = _edited(tmp_path, "neg.toml", 'temperature = "293.15 K"', 'temperature = "-300 degC"')
    code, _, err = run_main(capsys, *command, "--params", str(path))
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert f"{path}: bonds.temperature: expected a positive value, got -300 degC = -26.85 K" in err


def test_negative_bare_number_in_a_file_carries_its_si_unit(capsys, tmp_path):
    path = _edited(tmp_path, "neg.toml", 'bond_time = "224 us"', "bond_time = -0.000224")
    code, _, err = run_main(capsys, "stick", "--v0", "50 um/s", "--params", str(path))
    assert code == 2 and f"{path}: bonds.bond_time: expected a positive value, got -0.000224 s" in err


def test_dangling_link_into_a_missing_folder(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    os.symlink(tmp_path / "nofolder" / "x.csv", "dang.csv")
    code, _, err = run_main(capsys, *RUN, "-o", "dang.csv")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "a link into the folder" in err and "nofolder" in err and "does not exist" in err
    assert "Could not open" not in err


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
@pytest.mark.parametrize("option", ["-o", "--plot"])
def test_full_device_says_the_write_failed(capsys, option):
    code, _, err = run_main(capsys, *RUN, option, "/dev/full")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "'/dev/full': no space left on the device while writing it" in err
    assert "Could not open" not in err


def test_analyze_cycle_table_marks_pure_numbers(capsys, tmp_path):
    trace, table = tmp_path / "trace.csv", tmp_path / "cycles.csv"
    assert run_main(capsys, *RUN, "-o", str(trace))[0] == 0
    code, _, err = run_main(capsys, "analyze", str(trace), "-o", str(table))
    assert code == 0, err
    header = table.read_text().splitlines()[0].split(",")
    assert header[1:3] == ["cycle [1]", "complete [1]"]


def test_run_json_gives_no_unit_for_a_word(capsys):
    code, out, _ = run_main(capsys, *RUN, "--json")
    assert code == 0
    document = json.loads(out)
    assert document["model"] == "quasi-static" and "model" not in document["units"]
    assert document["units"]["mean_stress"] == "Pa"


def test_a_hold_under_velocity_control_is_held_by_the_protocol_not_the_chains(capsys):  # type: ignore[no-untyped-def]
    """A slide-hold without the stick chains said "the stick chains hold it" and advised adding them."""
    code, out, err = run_main(
        capsys, "transient", "--control", "velocity", "--start", "steady", "--v0", "100 um/s", "--duration", "5 ms",
        "--segment", "0:0.1 s",
    )  # fmt: skip
    assert code == 0, err
    assert "held at rest by the protocol" in out
    assert "stick chains" not in out
