"""Issue 29: a generated corpus of bad command lines over the commands of the bond model and the shared options.

Every option that takes a value is given NaN, inf, 1e308, a denormal (5e-324), zero, a negative, a bare number
and a value of the wrong dimension, with and without a unit; protocol and trace files get duplicated columns;
commands with two outputs get one name for both.  Whatever the value, the command must end in one of three ways:

* exit 0 with no "nan" or "inf" anywhere in its output (a right answer, said in words where a number is unknown);
* exit 2 with exactly one line on stderr (a refusal naming what was wrong);
* exit 3 (an honest failure);

never exit 1 (an internal error) and never a traceback.  The whole matrix (``CORPUS``, several hundred lines)
is the issue's count; ``python tests/test_bad_input_cli.py`` runs all of it and prints the failures.  The test
suite runs the issue's own cases and a hypothesis sample of the matrix, a few seconds in all.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import sys
import warnings
from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from stickslip.cli.main import main

#: A number the output must never show: nan or inf as a word (not "info", "infinite" or "inflection").
NON_FINITE = re.compile(r"(?<![A-Za-z])[-+]?(nan|inf|infinity)(?![A-Za-z])", re.IGNORECASE)

#: Bad numbers, each bare and with the option's unit.
NUMBERS = ("nan", "inf", "-inf", "1e308", "-1e308", "5e-324", "0", "-1", "1e-300")


def _values(unit: str, wrong: str) -> list[str]:
    """Every bad spelling of a value whose unit is ``unit`` (``wrong``: a unit of another dimension)."""
    values = [*NUMBERS, "50", "x", "", f"1 {wrong}", unit]
    values += [f"{n} {unit}" for n in NUMBERS]
    return values


#: (command words before the option, option, unit, a wrong unit, the words after): the options under test.
#: Durations are short and the commands the fast ones, so that a value that is accepted runs in milliseconds.
SIM = ["simulate", "--duration", "2 s"]
RUN = ["run", "--duration", "2 s"]
RSF = ["run", "--model", "rsf", "--duration", "1 s", "--v0", "10 um/s"]
SWEEP = ["sweep", "-o", "SWEEP", "--workers", "0", "--quiet"]
OPTIONS: list[tuple[list[str], str, str, str, list[str]]] = [
    (["curve", "--points", "5"], "--vmin", "um/s", "Pa", []),
    (["curve", "--points", "5"], "--vmax", "mm/s", "s", []),
    (["curve"], "--velocity", "um/s", "kPa", []),
    (["curve", "--format", "json"], "--velocity", "um/s", "m", []),
    (["critical", "--json"], "--set", "us", "Pa", []),  # value prefixed with bonds.bond_time=
    (["stick", "--json"], "--v0", "um/s", "Pa", []),
    (["stick", "--v0", "50 um/s"], "--start-stress", "Pa", "m/s", []),
    (["stick", "--v0", "0"], "--until", "s", "m", []),
    (SIM, "--v0", "um/s", "Pa", []),
    (["simulate", "--v0", "50 um/s"], "--duration", "s", "Pa", []),
    ([*SIM, "--v0", "50 um/s"], "--stiffness", "kPa/m", "Pa", []),
    ([*SIM, "--v0", "50 um/s"], "--start-stress", "Pa", "um/s", []),
    (["simulate"], "--segment", "um/s:2 s", "Pa:2 s", []),
    ([*RUN, "--json"], "--v0", "um/s", "Pa", []),
    ([*RUN, "--v0", "50 um/s"], "--start", "Pa", "um/s", []),
    ([*RUN, "--v0", "50 um/s"], "--stiffness", "kPa/m", "Pa", []),
    ([*RUN, "--v0", "50 um/s"], "--every", "s", "m", []),
    (RSF, "--start", "um/s", "Pa", []),
    (RSF, "--every", "s", "Pa", []),
    (RSF, "--mass", "kg/m^2", "Pa", ["--set", "normal_stress=1 MPa"]),
    (["stability", "--v0", "120 um/s"], "--mass", "kg/m^2", "Pa", []),
    (["stability", "--v0", "120 um/s", "--mass", "1 kg/m^2"], "--damping", "Pa s/m", "Pa", []),
    (["stability"], "--v0", "um/s", "Pa", []),
    (["analyze", "TRACE"], "--v0", "um/s", "Pa", []),
    (["params", "show"], "--set", "us", "Pa", []),  # value prefixed with bonds.bond_time=
    ([*SWEEP, "--vary", "bonds.bond_time=100 us,200 us", "--v0", "50 um/s"], "--duration", "s", "Pa", []),
    ([*SWEEP, "--duration", "2 s"], "--vary", "um/s", "Pa", []),
]

#: Options whose value is a key=value: the value under test is given to this key.
KEYED = {("critical", "--set"): "bonds.bond_time=", ("params", "--set"): "bonds.bond_time="}

#: Whole command lines of the issue and of the matrix's other axes: files, duplicated columns, same-name outputs.
ISSUE_CASES: list[list[str]] = [
    ["run", "--model", "stickslip.models.base:FrictionModel", "--v0", "50 um/s", "--duration", "2 s"],
    ["simulate", "--segment", "50:60"],
    ["simulate", "--segment", "50 um/s:60"],
    ["simulate", "--segment", "50:60 s"],
    ["run", "--segment", "50:2"],
    ["sweep", "--vary", "bonds.bond_time=100 us,200 us", "--v0", "50 um/s", "--duration", "20", "-o", "SWEEP"],
    ["sweep", "--vary", "pulling_velocity=20 um/s...200 um/s:3", "--duration", "2 s", "-o", "SWEEP"],
    [*RSF, "--start", "3 Pa"],
    ["run", "--model", "quasi-static", "--v0", "50 um/s", "--duration", "2 s", "--start", "1 um/s"],
    ["run", "--model", "transient", "--v0", "50 um/s", "--duration", "2 s", "--start", "1 um/s"],
    ["simulate", "--protocol", "DUP_PROTOCOL"],
    ["run", "--protocol", "DUP_PROTOCOL"],
    ["analyze", "DUP_TRACE", "--v0", "50 um/s"],
    ["curve", "--vmax", "1e308 mm/s"],
    ["curve", "--vmin", "5e-324 m/s"],
    ["curve", "--set", "bonds.bond_time=5e-324 s"],
    ["critical", "--set", "bonds.bond_time=5e-324 s", "--json"],
    ["stability", "--v0", "120 um/s", "--mass", "1e308"],
    ["stability", "--v0", "120 um/s", "--mass", "1e308 kg/m^2"],
    ["stability", "--v0", "120 um/s", "--mass", "1 kg/m^2", "--growth-at", "1e308"],
    [*RSF, "--set", "a=1e308"],
    [*RSF, "--set", "mu0=-1"],
    [*SIM, "--v0", "50 um/s", "-o", "same.csv", "--plot", "same.csv"],
    [*RUN, "--v0", "50 um/s", "-o", "same.csv", "--plot", "same.csv"],
    [*RSF, "-o", "same.csv", "--plot", "same.csv"],
    ["curve", "--points", "5", "-o", "same.png", "--plot", "same.png"],
    ["stick", "--v0", "50 um/s", "-o", "same.png", "--plot", "same.png"],
    ["analyze", "TRACE", "--v0", "50 um/s", "-o", "same.csv", "--plot", "same.csv"],
    ["curve", "--points", "5", "-o", "-", "--plot", "-"],
    ["params", "export", "-o", ""],
    ["params", "export", "-o", "p.toml", "--set", "bonds.bond_time=5e-324 s"],
    ["sweep", "plot", "BROKEN_SWEEP"],
]


#: Issue cases that may also end in a right answer (exit 0 without nan or inf); every other one must be refused.
ANSWERABLE = (
    ["curve", "--vmax", "1e308 mm/s"],
    ["stability", "--v0", "120 um/s", "--mass", "1e308 kg/m^2"],
    ["stability", "--v0", "120 um/s", "--mass", "1 kg/m^2", "--growth-at", "1e308"],
)


def must_refuse(value: str, unit: str) -> bool:
    """A value no command may accept: a bare non-zero number, a unit of the wrong dimension, no number at all,
    NaN or an infinity (with or without its unit)."""
    number = value.split()[0] if value.split() else ""
    if value in ("", "x") or value == unit or (value.startswith("1 ") and value != f"1 {unit}"):
        return True
    if number.lower().lstrip("+-") in ("nan", "inf"):
        return True
    return " " not in value and value != "0"


def corpus() -> list[tuple[list[str], bool]]:
    """Every command line of the matrix (file names as placeholders, filled in by :func:`_resolved`), each with
    whether it must be refused (exit 2)."""
    lines = [(list(case), case not in ANSWERABLE) for case in ISSUE_CASES]
    for before, option, unit, wrong, after in OPTIONS:
        prefix = KEYED.get((before[0], option), "")
        for value in _values(unit, wrong):
            lines.append(([*before, option, prefix + value, *after], must_refuse(value, unit)))
    return lines


CORPUS = corpus()


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder with the files the corpus names: a trace, duplicated-column files, a damaged sweep."""
    folder = tmp_path_factory.mktemp("bad-input")
    _write_files(folder)
    return folder


def _write_files(folder: Path) -> None:
    rows = "".join(f"{0.01 * k!r},{300 + 50 * ((0.01 * k) % 2) / 2!r}\n" for k in range(2001))
    (folder / "trace.csv").write_text("time [s],stress [Pa]\n" + rows)
    (folder / "dup-trace.csv").write_text("time [s],stress [Pa],stress [Pa]\n0,1,1\n1,2,2\n2,3,3\n")
    (folder / "dup-protocol.csv").write_text("velocity,velocity,duration\n1e-5,1e-5,10\n")
    broken = folder / "broken-sweep"
    broken.mkdir()
    (broken / "_manifest.json").write_text("{}")
    (broken / "part-000000.parquet").write_bytes(b"PAR1 not a parquet file at all")


def _resolved(line: list[str], folder: Path, index: int) -> list[str]:
    names = {
        "TRACE": folder / "trace.csv",
        "DUP_TRACE": folder / "dup-trace.csv",
        "DUP_PROTOCOL": folder / "dup-protocol.csv",
        "BROKEN_SWEEP": folder / "broken-sweep",
        "SWEEP": folder / f"sweep-{index}",
    }
    return [str(names[word]) if word in names else word for word in line]


def invoke(args: list[str]) -> tuple[int, str, str]:
    """``main(args)`` in-process, as the console script runs it: (exit status, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with warnings.catch_warnings(), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        warnings.simplefilter("default")  # as the console script runs: pytest's "error" filter is not the user's
        try:
            main(args)
            status = 0
        except SystemExit as exit_info:
            status = exit_info.code if isinstance(exit_info.code, int) else 1
    return status, out.getvalue(), err.getvalue()


def problem(args: list[str], refuse: bool = False) -> str | None:
    """What is wrong with how the command ended, or None if it ended in one of the three allowed ways
    (``refuse``: only a refusal, exit 2, is right)."""
    status, out, err = invoke(args)
    if refuse and status != 2:
        return f"bad input accepted: expected a refusal (exit 2), got exit {status}: {(err or out)[-200:]}"
    if "Traceback" in out + err:
        return f"a traceback (exit {status}): {err[-300:]}"
    if status == 0:
        found = NON_FINITE.search(out + err)
        return None if found is None else f"exit 0 but the output shows {found.group(0)!r}: {(out + err)[-300:]}"
    if status == 2:
        lines = err.splitlines()
        return None if len(lines) == 1 and lines[0].startswith("stickslip: error: ") else f"exit 2 with: {err!r}"
    if status == 3:
        return None
    return f"exit {status}: {err[-300:]}"


@contextlib.contextmanager
def inside(folder: Path) -> Iterator[None]:
    here = os.getcwd()
    os.chdir(folder)
    try:
        yield
    finally:
        os.chdir(here)


#: Heavy commands (the Hopf search of stability takes seconds a point): only their refusals run in the suite.
SLOW = ("stability",)


def _heavy(line: list[str]) -> bool:
    """A line that runs the Hopf search (seconds): the full corpus runs it, the suite checks its guard directly."""
    return line[0] in SLOW and any(word.endswith("kg/m^2") for word in line)


QUICK_CASES = [i for i, c in enumerate(ISSUE_CASES) if not _heavy(c)]


@pytest.mark.parametrize("case", QUICK_CASES, ids=[" ".join(ISSUE_CASES[i])[:80] for i in QUICK_CASES])
def test_the_issue_cases_end_cleanly(case: int, files: Path) -> None:
    with inside(files):
        line = ISSUE_CASES[case]
        assert problem(_resolved(line, files, case), refuse=line not in ANSWERABLE) is None


def test_same_name_outputs_write_nothing(files: Path) -> None:
    """A refused command writes nothing: neither output appears."""
    target = files / "never.csv"
    status, _, err = invoke([*SIM, "--v0", "50 um/s", "-o", str(target), "--plot", str(target)])
    assert status == 2 and "both write" in err and not target.exists()


def test_a_refused_sweep_leaves_no_lock_file(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("mine")
    status, _, err = invoke(["sweep", "--vary", "bonds.bond_time=100 us,200 us", "--v0", "50 um/s",
                             "--duration", "2 s", "-o", str(tmp_path), "--workers", "0"])  # fmt: skip
    assert status == 2 and "not a sweep's" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]


def test_a_chunk_named_folder_is_refused_in_one_line(tmp_path: Path) -> None:
    args = ["sweep", "--vary", "bonds.bond_time=100 us,200 us", "--v0", "50 um/s", "--duration", "2 s",
            "-o", str(tmp_path / "out"), "--workers", "0", "--quiet"]  # fmt: skip
    assert invoke(args)[0] == 0
    chunk = tmp_path / "out" / "part-000000.parquet"
    chunk.unlink()
    chunk.mkdir()
    status, _, err = invoke(args)
    assert status == 2 and "part-000000.parquet is not a regular file" in err


def test_a_full_disk_on_standard_output_is_one_line() -> None:
    if not Path("/dev/full").exists():
        pytest.skip("no /dev/full here")
    import subprocess

    with open("/dev/full", "w") as full:
        done = subprocess.run(
            [sys.executable, "-m", "stickslip", "critical", "--json"],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            timeout=120,
        )
    assert done.returncode == 2 and done.stderr.count("\n") == 1 and "No space left" in done.stderr


def test_a_kc_beyond_the_float_range_is_refused_not_printed() -> None:
    """stability --mass 1e308: Kc = inf (or F x Kc beyond 1e308) is a refusal naming the inputs, never 'Kc = inf'."""
    from types import SimpleNamespace

    from stickslip.cli.stability_cmd import _refuse_unbounded
    from stickslip.errors import ParameterError

    with pytest.raises(ParameterError, match=r"--mass 1e308 kg/m\^2: Kc leaves the floating-point range"):
        _refuse_unbounded(SimpleNamespace(mode="oscillatory", value=float("inf"), rate=1.8), "120 um/s",
                          "1e308 kg/m^2", None, None)  # fmt: skip
    with pytest.raises(ParameterError, match="--growth-at 1e"):
        _refuse_unbounded(SimpleNamespace(mode="oscillatory", value=1.3e8, rate=1.8), "120 um/s", "1 kg/m^2", None,
                          1e308)  # fmt: skip
    _refuse_unbounded(SimpleNamespace(mode="oscillatory", value=1.3e8, rate=1.8), "120 um/s", None, None, 2.0)
    _refuse_unbounded(SimpleNamespace(mode="stable", value=None, rate=None), "120 um/s", None, None, None)


#: Commands whose accepted values take long (a sweep starts its machinery, stability a Hopf search): the full
#: corpus runs them; the suite samples the others.
SAMPLED_OUT = (*SLOW, "sweep")


# the same sample every run (derandomize): its cost was 1-11 s by which lines a run drew, and a failure must repeat
@settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.sampled_from([i for i, (line, _) in enumerate(CORPUS) if line[0] not in SAMPLED_OUT]))
def test_a_sample_of_the_corpus_ends_cleanly(files: Path, index: int) -> None:
    line, refuse = CORPUS[index]
    with inside(files):
        assert problem(_resolved(line, files, index), refuse) is None, line


def _run_all(folder: Path) -> int:  # pragma: no cover - the issue's count, run by hand
    failures = 0
    with inside(folder):
        for index, (line, refuse) in enumerate(CORPUS):
            why = problem(_resolved(line, folder, index), refuse)
            if why is not None:
                failures += 1
                print(f"FAIL {shlex.join(line)}\n     {why[:400]}")
    print(f"{failures} of {len(CORPUS)} command lines ended badly")
    return failures


if __name__ == "__main__":  # pragma: no cover
    import tempfile

    with tempfile.TemporaryDirectory() as scratch:
        _write_files(Path(scratch))
        sys.exit(1 if _run_all(Path(scratch)) else 0)
