"""Audit of output chaining on the command line (second round).

1. Two outputs on standard output: data that go there for want of -o (``curve --format csv``, rsf simulate's
   trace) beside an output ``-`` (``--plot -``) are refused in one line naming both, exit 2, as ``-o - --plot -``
   is; before, the data went silently to stderr.  ``-`` and ``/dev/stdout`` are one output.  A summary (text or
   --json) still goes to stderr beside an output on stdout (tests/test_audit_files.py).
2. ``analyze -o cycles.csv`` then ``fit stick cycles.csv``: the cycles' table carries its pulling velocity, and fit
   stick reads it (σc as the start stress, cut cycles left out with a note).
"""

from __future__ import annotations

import pytest

from cli_helpers import run_main

TABLE1 = "src/stickslip/data/table1.csv"


def run_bytes(capsysbinary: pytest.CaptureFixture[bytes], *args: str) -> tuple[int, bytes, str]:
    """``main()`` in-process with standard output as bytes (a PNG there must not break the capture)."""
    from stickslip.cli.main import main

    with pytest.raises(SystemExit) as exit_info:
        main(list(args))
    out, err = capsysbinary.readouterr()
    return int(exit_info.value.code), out, err.decode()


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (("curve", "--velocity", "100 um/s", "--format", "csv", "--plot", "-"), ("--format csv", "--plot -")),
        (("curve", "--velocity", "100 um/s", "--format", "json", "--plot", "-"), ("--format json", "--plot -")),
        (("curve", "--format", "csv", "--plot", "/dev/stdout"), ("--format csv", "--plot /dev/stdout")),
        (("rsf", "simulate", "--v0", "1 um/s", "--duration", "10 s", "--plot", "-"), ("the trace", "--plot -")),
    ],
    ids=["curve-csv", "curve-json", "curve-dev-stdout", "rsf-simulate"],
)
def test_data_on_stdout_for_want_of_o_beside_an_output_on_stdout_is_refused(capsysbinary, args, named):
    """`stickslip curve --format csv --plot -` sent the CSV to stderr and the PNG to stdout."""
    status, out, err = run_bytes(capsysbinary, *args)
    assert status == 2, err
    assert out == b""
    line = err.strip()
    assert "\n" not in line and "both write standard output" in line
    for option in named:
        assert option in line


def test_dev_stdout_and_dash_are_one_output(capsysbinary):
    status, out, err = run_bytes(
        capsysbinary, "curve", "--velocity", "100 um/s", "--format", "csv", "-o", "-", "--plot", "/dev/stdout"
    )
    assert status == 2 and out == b""
    assert "-o - and --plot /dev/stdout: both write standard output" in err


def test_data_in_a_file_beside_a_figure_on_stdout_is_kept(capsys, tmp_path):
    """With -o FILE the csv is not on standard output: --plot - is the only output there, as before."""
    target = tmp_path / "curve.csv"
    status, _, err = run_main(
        capsys, "curve", "--velocity", "100 um/s", "--format", "csv", "-o", str(target), "--plot", "/dev/null"
    )
    assert status == 0, err
    assert target.read_text().startswith("velocity [m/s],stress [Pa]")
