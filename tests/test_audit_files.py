"""Output files as a user chains them: an output on standard output is the whole file and nothing else."""

from __future__ import annotations

import sys

import pytest

from cli_helpers import run_main, run_main_bytes

PNG_END = b"IEND\xaeB`\x82"


@pytest.mark.parametrize(
    "args",
    [
        ["curve", "--points", "5", "--plot", "-"],  # the table went to stdout before the image
        ["critical", "--plot", "-"],  # the text went to stdout after the image
        ["critical", "--json", "--plot", "-"],
        ["rsf", "stability", "--a", "0.01", "--b", "0.015", "--dc", "10 um", "--velocity", "1 um/s", "--plot", "-"],
    ],
    ids=["curve", "critical", "critical-json", "rsf-stability"],
)
def test_a_figure_on_standard_output_is_the_whole_output(capsysbinary, args):
    """`stickslip curve --plot - > fig.png` gave the table and then the PNG: an image no viewer opens."""
    status, out, err = run_main_bytes(capsysbinary, *args)
    assert status == 0, err
    assert out.startswith(b"\x89PNG\r\n\x1a\n") and out.endswith(PNG_END), out[:80]
    assert err.strip(), "the text the command prints goes to stderr instead"


def test_a_csv_on_standard_output_has_no_json_or_table_mixed_in(capsys):
    """`run -o - --json` printed the JSON summary into the CSV; `analyze -o -` put its table before the CSV."""
    status, out, err = run_main(
        capsys, "run", "--model", "quasi-static", "--v0", "50 um/s", "--duration", "5 s", "-o", "-", "--json"
    )
    assert status == 0, err
    lines = out.splitlines()
    assert lines[0].startswith("# stickslip run ") and lines[1].startswith("time [s],stress [Pa]")
    assert all(line[:1].isdigit() for line in lines[2:]), [line for line in lines[2:] if not line[:1].isdigit()][:3]
    assert '"units"' in err  # the JSON summary, on stderr


def test_standard_output_is_given_back_after_the_command(capsys):
    """The command's claim on standard output ends with it: a later command prints to stdout again."""
    real = sys.stdout
    status, out, err = run_main(capsys, "curve", "--points", "3", "--format", "csv", "-o", "-", "--plot", "/dev/null")
    assert status == 0 and sys.stdout is real and out.startswith("velocity [m/s]"), err
    status, out, _ = run_main(capsys, "critical")
    assert status == 0 and "Critical point" in out


def test_the_python_api_is_not_affected():
    """Outside a command-line invocation nothing is redirected."""
    from stickslip.fileio import claim_stdout

    before = sys.stdout
    assert claim_stdout(["-"]) is False
    assert sys.stdout is before


def test_reproduce_refuses_dash_as_its_folder(tmp_path, capsys, monkeypatch):
    """`reproduce -o -` (the README: `-o -` is standard output) silently made a folder named '-' of 93 files."""
    monkeypatch.chdir(tmp_path)
    status, _, err = run_main(capsys, "reproduce", "-o", "-", "--quiet")
    assert status == 2 and err.strip().startswith("stickslip: error: output folder '-'"), err
    assert len(err.strip().splitlines()) == 1 and list(tmp_path.iterdir()) == []
