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

from cli_helpers import run_main, run_main_bytes

TABLE1 = "src/stickslip/data/table1.csv"


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
    status, out, err = run_main_bytes(capsysbinary, *args)
    assert status == 2, err
    assert out == b""
    line = err.strip()
    assert "\n" not in line and "both write standard output" in line
    for option in named:
        assert option in line


def test_dev_stdout_and_dash_are_one_output(capsysbinary):
    status, out, err = run_main_bytes(
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


@pytest.fixture(scope="module")
def cycles_tables(tmp_path_factory):
    """`run -o trace.csv` at 50 and 100 um/s, each `analyze -o`: the cycles tables of two traces."""
    from stickslip.cli.main import main

    folder = tmp_path_factory.mktemp("chain")
    tables = []
    for v0, duration in (("50 um/s", "120 s"), ("100 um/s", "60 s")):
        trace, cycles = folder / f"trace{v0[:3].strip()}.csv", folder / f"cycles{v0[:3].strip()}.csv"
        for args in (
            ["run", "--model", "quasi-static", "--v0", v0, "--duration", duration, "-o", str(trace)],
            ["analyze", str(trace), "-o", str(cycles)],
        ):
            with pytest.raises(SystemExit) as exit_info:
                main(args)
            assert exit_info.value.code == 0
        tables.append(cycles)
    return tables


def test_analyze_cycles_table_names_its_pulling_velocity(cycles_tables):
    import pandas as pd

    frame = pd.read_csv(cycles_tables[1])
    assert list(frame["pulling_velocity [m/s]"].unique()) == [pytest.approx(100e-6, rel=1e-9)]


def test_fit_stick_reads_the_cycles_of_analyze(capsys, cycles_tables, tmp_path):
    """`analyze TRACE -o cycles.csv` then `fit stick cycles.csv`: unknown column 'complete' (exit 2) before."""
    lines = cycles_tables[0].read_text().splitlines() + cycles_tables[1].read_text().splitlines()[1:]
    both = tmp_path / "both.csv"
    both.write_text("\n".join(lines) + "\n")
    status, out, err = run_main(capsys, "fit", "stick", str(both), "--json")
    assert status == 0, err
    import json

    result = json.loads(out)
    assert result["status"] == "ok"
    fitted = {key: e["value"] for key, e in result["parameters"].items()}
    assert fitted["stick.attached_chains"] == pytest.approx(2.07e12, rel=1e-3)  # the run's own parameters
    assert fitted["stick.aging_time"] == pytest.approx(10.0, rel=1e-3)
    assert any("left out: cycles cut by the record's ends" in m for m in result["messages"])


def test_fit_stick_of_one_trace_fails_for_its_one_velocity(capsys, cycles_tables):
    status, _, err = run_main(capsys, "fit", "stick", str(cycles_tables[0]))
    assert status == 3
    assert "every fitted row is at one pulling velocity" in err


def test_an_old_cycles_table_without_its_velocity_is_refused_in_one_line(capsys, cycles_tables, tmp_path):
    import pandas as pd

    old = tmp_path / "old.csv"
    pd.read_csv(cycles_tables[0]).drop(columns="pulling_velocity [m/s]").to_csv(old, index=False)
    status, out, err = run_main(capsys, "fit", "stick", str(old))
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and "without a pulling_velocity column" in err


def test_exact_stick_times_flag_no_outlier_off_by_a_factor_1(cycles_tables):
    """The cycles of a simulated trace agree to 1e-8: a row off by 1e-7 was called an outlier "off by a factor 1"."""
    from stickslip.fitting.stick_fit import fit_stick

    fit = fit_stick(cycles_tables[0])
    assert not [m for m in fit.messages if "outlier" in m], fit.messages


def test_the_python_reader_takes_the_cycles_table_as_fit_stick_does(cycles_tables, tmp_path):
    """stickslip.read_stick_data refused the cycles table of analyze -o (unknown column 'complete') that `fit
    stick` read: one reader serves both.  The chain run -> analyze -o -> read_stick_data -> fit_stick recovers the
    run's own stick parameters (gelatin-glass: Nc0 = 2.07e12 /m^2, stick aging time 10 s)."""
    import numpy as np

    import stickslip
    from stickslip.fitting.stick_fit import fit_stick

    lines = cycles_tables[0].read_text().splitlines() + cycles_tables[1].read_text().splitlines()[1:]
    both = tmp_path / "both.csv"
    both.write_text("\n".join(lines) + "\n")
    data = stickslip.read_stick_data(both)
    assert sorted(set(data.pulling_velocity)) == [pytest.approx(50e-6, rel=1e-12), pytest.approx(100e-6, rel=1e-12)]
    assert np.all(np.isfinite(data.stick_time)) and np.all(np.isfinite(data.start_stress))
    assert any("left out: cycles cut by the record's ends" in note for note in data.notes())
    fit = fit_stick(data)
    assert fit.status == "ok"
    fitted = {e.key: e.value for e in fit.estimates}
    assert fitted["stick.attached_chains"] == pytest.approx(2.07e12, rel=1e-3)
    assert fitted["stick.aging_time"] == pytest.approx(10.0, rel=1e-3)
    assert any("critical_stress" in m for m in fit.messages)  # the reader's notes reach the fit's
