"""One spelling per quantity in what people read (issue 19): µm/s, σs, σc, τa, Δl_m, never um/s, sigma_s, tau_a.

Every command that prints prose is run here, through the cases whose messages come from the models
(stick-slip, stuck, undetermined, steady).  The RSF fit's report in the record's unit (µm) is checked in
test_rsf_fit_protocols.  What a user types
stays ASCII ("350 um/s"): the arguments below are chosen so that none is echoed back.  JSON keys and CSV
headers are for machines and are not checked.
"""

from __future__ import annotations

import re

import pytest
from click.testing import CliRunner

from stickslip.cli.main import cli
from stickslip.fitting import datasets

#: ASCII spellings that must not reach a person's eyes (the paper's symbols are σs, σc, τ, τa, Δl_m).
ASCII_SPELLINGS = re.compile(r"um/s|\bum\b|sigma|tau_?a?\b|\bdl_m\b|\bmu\b")


COMMANDS = {
    "params show": ["params", "show"],
    "critical": ["critical"],
    "stick slips": ["stick", "--v0", "50 um/s"],
    "stick stuck": ["stick", "--v0", "15 um/s"],
    "stick undetermined": ["stick", "--v0", "20 um/s"],
    "simulate stick-slip": ["simulate", "--v0", "50 um/s", "--duration", "60 s"],
    "simulate undetermined": ["simulate", "--v0", "20 um/s", "--duration", "60 s"],
    "simulate stuck": ["simulate", "--v0", "10 um/s", "--duration", "60 s"],
    "transient stuck": ["transient", "--v0", "50 um/s", "--duration", "0.2 s", "--rtol", "1e-3"],
    "transient steady": [
        "transient",
        "--control",
        "velocity",
        "--start",
        "steady",
        "--v0",
        "350 um/s",
        "--duration",
        "5 ms",
        "--segment",
        "1 mm/s:5 ms",
        "--rtol",
        "1e-3",
    ],
    "rsf simulate": [
        "rsf",
        "simulate",
        "--a",
        "0.005",
        "--b",
        "0.01",
        "--dc",
        "10 um",
        "--stiffness",
        "1e-3 1/um",
        "--segment",
        "1 um/s:10 s",
        "--segment",
        "10 um/s:30 s",
        "--every",
        "0.1 s",
        "-o",
        "t.csv",
    ],
    "rsf stability": [
        "rsf",
        "stability",
        "--a",
        "0.01",
        "--b",
        "0.015",
        "--dc",
        "20 um",
        "--stiffness",
        "100 1/m",
        "--velocity",
        "1 um/s",
    ],
    "fit steady": ["fit", "steady", str(datasets.synthetic_steady_path())],
    "fit stick": ["fit", "stick", str(datasets.table1_path()), "--exclude-row", "11"],
    "compare": ["compare"],
    "run": ["run", "--model", "quasi-static", "--v0", "20 um/s", "--duration", "60 s"],
    "compare --models": ["compare", "--models", "quasi-static,rsf", "--v0", "50 um/s", "--duration", "60 s"],
    "help of analyze": ["analyze", "--help"],
    "help of curve": ["curve", "--help"],
    "help of critical": ["critical", "--help"],
    "help of stick": ["stick", "--help"],
}


#: A value as the user types it in a help text, quoted ("50 um/s", '224 us') or a default ([default: 10 um/s]):
#: ASCII on purpose.
TYPED_EXAMPLE = re.compile(r"\"[^\"]*\"|'[^']*'|\[[^\]]*\]")


def offending_lines(text: str, typed_examples: bool = False) -> list[str]:
    """Lines with an ASCII spelling; ``typed_examples``: quoted examples of what to type do not count."""
    clean = (lambda line: TYPED_EXAMPLE.sub("", line)) if typed_examples else (lambda line: line)
    return [line.strip() for line in text.splitlines() if ASCII_SPELLINGS.search(clean(line))]


@pytest.mark.parametrize("name", list(COMMANDS))
def test_text_output_spells_quantities_one_way(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(cli, COMMANDS[name], catch_exceptions=False)
    assert result.exit_code == 0, result.output
    assert offending_lines(result.output, typed_examples="--help" in COMMANDS[name]) == []


def test_analyze_of_a_simulated_trace_spells_quantities_one_way(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    runner = CliRunner()
    made = runner.invoke(cli, ["simulate", "--v0", "50 um/s", "--duration", "100 s", "-o", "trace.csv"])
    assert made.exit_code == 0, made.output
    result = runner.invoke(cli, ["analyze", "trace.csv", "--v0", "50 um/s", "--compare"], catch_exceptions=False)
    assert result.exit_code == 0, result.output
    assert offending_lines(result.output) == []


def test_the_check_sees_the_old_spellings():
    """The pattern catches what the models used to print (a check that cannot fail is a defect)."""
    for old in ("sigma_s = 552.9 Pa", "jump to 702 um/s", "-t/tau_a grows", "sigma = 30 Pa", "set to dl_m = 1 um"):
        assert offending_lines(old) == [old]
    assert offending_lines('--v0 V  Pulling velocity, e.g. "50 um/s".', typed_examples=True) == []
    assert offending_lines("--no-aging  Drop the aging term (tau_a -> infinity).", typed_examples=True) != []
    for new in ("σs = 552.9 Pa", "jump to 702 µm/s", "−t/τa grows", "σ = 30 Pa", "Δl_m = 1.074 µm", "1 mm/s"):
        assert offending_lines(new) == []
