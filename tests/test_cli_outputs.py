"""The command line never writes over one of its inputs, and writes every kind of output target as it should.

Special targets are private copies in tmp_path (mknod, mkfifo, a link to
/proc/self/fd/1), never the system's /dev/null or /dev/stdout.
"""

from __future__ import annotations

import os
import stat
import threading
import time
from pathlib import Path

import pytest

from cli_helpers import run_main

CURVE_CSV = ["curve", "--format", "csv", "--points", "3"]


def _one_error_line(status: int, err: str) -> str:
    assert status == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stickslip: error: "), err
    return lines[0]


@pytest.fixture()
def inputs(tmp_path, capsys):
    """A parameter TOML and an rsf run (run.csv with its run.params.json), made by the commands themselves."""
    status, _, err = run_main(capsys, "params", "export", "gelatin-glass", "-o", str(tmp_path / "p.toml"))
    assert status == 0, err
    status, _, err = run_main(capsys, "rsf", "simulate", "--segment", "1 um/s:10 s", "-o", str(tmp_path / "run.csv"))
    assert status == 0, err
    os.link(tmp_path / "p.toml", tmp_path / "hard.toml")
    (tmp_path / "soft.toml").symlink_to(tmp_path / "p.toml")
    return tmp_path


REFUSED = [
    # the --params file of the bond model, by its name, a hard link and a symbolic link
    (["transient", "--params", "{d}/p.toml", "--v0", "50 um/s", "--duration", "1 s", "-o", "{d}/p.toml"], "p.toml"),
    (["transient", "--params", "{d}/p.toml", "--v0", "50 um/s", "--duration", "1 s", "-o", "{d}/hard.toml"], "p.toml"),
    ([*CURVE_CSV, "--params", "{d}/p.toml", "-o", "{d}/soft.toml"], "p.toml"),
    (
        ["simulate", "--params", "{d}/p.toml", "--v0", "50 um/s", "--duration", "1 s", "--plot", "{d}/hard.toml"],
        "p.toml",
    ),
    # the rerun workflow of docs/rsf.md: its NAME.params.json side file would replace the --params input
    (["rsf", "simulate", "--params", "{d}/run.params.json", "--a", "0.02", "-o", "{d}/run.csv"], "run.params.json"),
    (["rsf", "simulate", "--params", "{d}/run.params.json", "-o", "{d}/run.params.json"], "run.params.json"),
    (
        [
            "rsf",
            "stability",
            "--params",
            "{d}/run.params.json",
            "--velocity",
            "1 um/s",
            "--plot",
            "{d}/run.params.json",
        ],
        "run.params.json",
    ),
]


@pytest.mark.parametrize(
    ("args", "protected"), REFUSED, ids=[" ".join(a[:2]) + f" #{i}" for i, (a, _) in enumerate(REFUSED)]
)
def test_no_command_overwrites_its_inputs(inputs, capsys, args, protected):
    before = {p.name: p.read_bytes() for p in inputs.iterdir() if not p.is_symlink()}
    began = time.perf_counter()
    status, _, err = run_main(capsys, *[a.format(d=inputs) for a in args])
    line = _one_error_line(status, err)
    assert "input file" in line and "refusing to overwrite" in line
    assert time.perf_counter() - began < 5
    assert {p.name: p.read_bytes() for p in inputs.iterdir() if not p.is_symlink()} == before
    assert (inputs / "soft.toml").is_symlink()


def _expected_csv(tmp_path: Path, capsys) -> bytes:
    status, _, err = run_main(capsys, *CURVE_CSV, "-o", str(tmp_path / "reference.csv"))
    assert status == 0, err
    return (tmp_path / "reference.csv").read_bytes()


def test_dash_writes_standard_output(tmp_path, capsys, monkeypatch):
    expected = _expected_csv(tmp_path, capsys)
    monkeypatch.chdir(tmp_path)
    status, out, err = run_main(capsys, *CURVE_CSV, "-o", "-")
    assert status == 0, err
    assert out.encode() == expected and not (tmp_path / "-").exists()


def test_a_symlinked_output_replaces_its_target_and_keeps_the_link(tmp_path, capsys):
    expected = _expected_csv(tmp_path, capsys)
    (tmp_path / "data").mkdir()
    real = tmp_path / "data" / "curve.csv"
    real.write_text("old\n")
    link = tmp_path / "link.csv"
    link.symlink_to(real)
    status, _, err = run_main(capsys, *CURVE_CSV, "-o", str(link))
    assert status == 0, err
    assert link.is_symlink() and real.read_bytes() == expected


def test_a_fifo_output_reaches_its_reader_and_stays_a_fifo(tmp_path, capsys):
    expected = _expected_csv(tmp_path, capsys)
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    received: list[bytes] = []

    def reader() -> None:
        with open(fifo, "rb") as handle:
            received.append(handle.read())

    thread = threading.Thread(target=reader, daemon=True)
    thread.start()
    status, _, err = run_main(capsys, *CURVE_CSV, "-o", str(fifo))
    thread.join(10)
    assert status == 0, err
    assert received == [expected] and stat.S_ISFIFO(fifo.lstat().st_mode)


def test_a_character_device_output_stays_a_device(tmp_path, capsys):
    node = tmp_path / "null"
    os.mknod(node, stat.S_IFCHR | 0o666, os.makedev(1, 3))  # a private /dev/null
    status, _, err = run_main(capsys, *CURVE_CSV, "-o", str(node), "--plot", str(node))
    assert status == 0, err
    assert stat.S_ISCHR(node.lstat().st_mode) and sorted(p.name for p in tmp_path.iterdir()) == ["null"]


def test_a_link_to_the_process_stdout_is_written_through(tmp_path, capfd):
    expected = _expected_csv(tmp_path, capfd)
    link = tmp_path / "stdout"
    link.symlink_to("/proc/self/fd/1")  # a private /dev/stdout
    status, out, err = run_main(capfd, *CURVE_CSV, "-o", str(link))
    assert status == 0, err
    assert out.encode() == expected and link.is_symlink() and os.readlink(link) == "/proc/self/fd/1"


def test_stale_temporaries_of_a_killed_write_are_removed_at_the_next_one(tmp_path, capsys):
    stale = tmp_path / ".curve.csv.k1ll3d00.csv.tmp"
    stale.write_bytes(b"half a curve")
    from stickslip import fileio

    before = fileio._STARTED - 60  # older than this process, however long the suite ran before this test
    os.utime(stale, (before, before))
    mine = tmp_path / ".curve.csv.notes.tmp"
    mine.write_bytes(b"a user's file")
    status, _, err = run_main(capsys, *CURVE_CSV, "-o", str(tmp_path / "curve.csv"))
    assert status == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == [".curve.csv.notes.tmp", "curve.csv"]
