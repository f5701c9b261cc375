"""A file option whose name ends with a slash names a folder: refused in one line (exit 2), nothing written
(``curve -o outdir/`` wrote a CSV named ``outdir``, ``--plot figdir/`` a PNG named ``figdir``: round-25 tester)."""

from __future__ import annotations

import pytest
from tests.cli_helpers import run_main

COMMANDS = [
    ("curve", "--points", "3", "--format", "csv", "-o", "{}"),
    ("curve", "--points", "3", "--plot", "{}"),
    ("params", "export", "gelatin-glass", "-o", "{}"),
    ("run", "--model", "rsf", "--v0", "1 um/s", "--duration", "1 s", "-o", "{}"),
    ("transient", "--v0", "350 um/s", "--duration", "1 ms", "--start", "steady", "--plot", "{}"),
]


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: " ".join(c[:2]))
def test_a_trailing_slash_is_a_folder_not_a_file(capsys, tmp_path, command):
    target = tmp_path / "out"
    status, _, err = run_main(capsys, *[word.format(f"{target}/") for word in command])
    assert status == 2 and err.count("\n") == 1 and "names a folder" in err, err
    assert not target.exists()


def test_the_same_name_without_the_slash_is_written(capsys, tmp_path):
    status, _, err = run_main(capsys, "curve", "--points", "3", "--format", "csv", "-o", str(tmp_path / "out"))
    assert status == 0 and (tmp_path / "out").is_file(), err
