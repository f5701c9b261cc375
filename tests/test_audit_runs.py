"""Audit of runs and sweeps: what a user met calling the run results and the protocol files as documented."""

from __future__ import annotations

import json

import numpy as np
import pytest

import stickslip
from cli_helpers import run_main
from stickslip import protocols
from stickslip.errors import DataError
from stickslip.transient import run_transient

P = stickslip.load_parameters("gelatin-glass")


def test_transient_result_prints_a_few_lines_not_its_arrays():
    result = run_transient(P, protocols.constant(350e-6, 0.02), control="velocity", start="steady")
    text = repr(result)
    assert text.startswith("TransientResult(") and len(text) < 1200, text
    assert f"<{result.time.size} values>" in text and "array(" not in text
    assert isinstance(result.time, np.ndarray) and result.time.size > 6


@pytest.mark.parametrize("brackets", ["[]", "()"])
def test_a_protocol_file_with_units_in_its_header_is_read_in_those_units(tmp_path, brackets):
    """Every CSV the package writes names its units as ``name [unit]``; the protocol reader refused such a header,
    and ``name (unit)`` (spreadsheets, lab software: "expected columns time,velocity")."""
    o, c = brackets
    steps = tmp_path / "steps.csv"
    steps.write_text(f"time {o}s{c},velocity {o}um/s{c}\n0,1\n10,0\n15,10\n20,0\n")
    protocol = protocols.read_protocol(steps)
    assert [s.velocity for s in protocol.segments] == pytest.approx([1e-6, 0.0, 1e-5], rel=1e-12)
    assert protocol.duration == pytest.approx(20.0)
    segments = tmp_path / "segments.csv"
    segments.write_text(f"velocity {o}mm/s{c};duration {o}min{c}\n1e-3;1\n1e-2;0.5\n")
    protocol = protocols.read_protocol(segments)
    assert [s.velocity for s in protocol.segments] == pytest.approx([1e-6, 1e-5], rel=1e-12)
    assert [s.duration for s in protocol.segments] == pytest.approx([60.0, 30.0])


def test_a_protocol_header_of_the_wrong_unit_or_twice_is_refused(tmp_path):
    wrong = tmp_path / "wrong.csv"
    wrong.write_text("time [s],velocity [Pa]\n0,1\n10,0\n")
    with pytest.raises(DataError, match=r"wrong.csv: column 'velocity \[Pa\]'"):
        protocols.read_protocol(wrong)
    twice = tmp_path / "twice.csv"
    twice.write_text("time,velocity [m/s],velocity\n0,1e-6,1e-6\n10,0,0\n")
    with pytest.raises(DataError, match="appears twice"):
        protocols.read_protocol(twice)


def test_a_protocol_header_of_both_layouts_or_one_column_is_refused_naming_its_columns(tmp_path):
    """A fuzz of the command line (2026-11-29): time,velocity,duration was read as segments, its times ignored;
    a lone 'time' column was split on its 't' by pandas' sniffer ('found Unnamed: 0, ime')."""
    both = tmp_path / "both.csv"
    both.write_text("time,velocity,duration\n0,1e-6,10\n10,2e-6,10\n")
    with pytest.raises(DataError, match="the header has both time and duration"):
        protocols.read_protocol(both)
    lone = tmp_path / "lone.csv"
    lone.write_text("time\n0\n10\n")
    with pytest.raises(DataError, match=r"found time$"):
        protocols.read_protocol(lone)
    for sep in (";", "\t"):  # the other separators still read
        other = tmp_path / "other.csv"
        other.write_text(f"time{sep}velocity\n0{sep}1e-6\n10{sep}2e-6\n")
        assert protocols.read_protocol(other).segments[0].velocity == pytest.approx(1e-6)


def test_a_bad_protocol_row_is_named_by_its_line_in_the_file(tmp_path):
    """Comment and blank lines were not counted: the NaN on line 5 was reported on 'row 3', the header's line."""
    commented = tmp_path / "commented.csv"
    commented.write_text("# slide-hold-slide\n# by hand\ntime,velocity\n0,1e-6\n10,nan\n20,0\n")
    with pytest.raises(
        DataError, match=r"commented.csv: row 5: expected two finite numbers \(time, velocity\); velocity: 'nan'"
    ):  # (round 28: the row quoted as written, each column with its unit)
        protocols.read_protocol(commented)
    blank = tmp_path / "blank.csv"
    blank.write_text("time,velocity\n0,1e-6\n\n10,1e-5\n5,0\n")
    with pytest.raises(DataError, match=r"blank.csv: row 5: time 5 s does not increase"):
        protocols.read_protocol(blank)
    negative = tmp_path / "negative.csv"
    negative.write_text("velocity,duration\n# the hold\n1e-6,10\n-1e-6,5\n")
    with pytest.raises(DataError, match=r"negative.csv: row 4: segment velocity"):
        protocols.read_protocol(negative)


def test_compare_protocol_set_json_names_the_unit_of_every_number(capsys):
    """The stick-slip pair's spring is rate-and-state's k in 1/m; the units map said Pa/m, and left out sigma_c
    and the panels' friction extremes."""
    code, out, _ = run_main(capsys, "compare", "--duration", "30 s", "--json")
    assert code == 0
    document = json.loads(out)
    units = document["units"]
    assert units["stiffness"] == "1/m" and units["sigma_c"] == "Pa"

    def numeric_keys(obj):
        if isinstance(obj, dict):
            for key, value in obj.items():
                if isinstance(value, float):
                    yield key
                yield from numeric_keys(value)

    assert sorted(set(numeric_keys(document)) - set(units)) == []


def test_sweep_plot_refuses_one_key_on_both_axes(tmp_path, capsys):
    """--x K --y K drew a 'phase diagram' of V0 against itself, with the Vc line across it."""
    out = tmp_path / "sweep"
    stickslip.sweep(["pulling_velocity=30 um/s,1 mm/s"], out, workers=0, duration=10.0)
    code, _, err = run_main(
        capsys,
        "sweep",
        "plot",
        str(out),
        "--x",
        "pulling_velocity",
        "--y",
        "pulling_velocity",
        "-o",
        str(tmp_path / "p.png"),
    )
    assert code == 2 and "--y pulling_velocity: the same key as --x" in err
    assert not (tmp_path / "p.png").exists()


def test_a_plug_in_models_numeric_start_is_described_with_its_unit():
    """compare --models printed a plug-in's --start "0.033 m/s" as 'start 0.033', no unit."""
    from stickslip.models import Capabilities, FrictionModel

    class Minimal(FrictionModel):
        name = "minimal"
        capabilities = Capabilities(controls=("spring",), protocols="constant")
        start_dimension = "velocity"

        def dimensions(self):
            return {}

        def parameters(self, spec=None, overrides=None):
            return {}

        def run(self, params, protocol, rig=None, *, start=None, **settings):
            raise NotImplementedError

    protocol = protocols.constant(0.03, 2.0)
    assert Minimal().describe_start(0.033, protocol) == "start 0.033 m/s"
    assert Minimal().describe_start(None, protocol) == "the model's own start"


@pytest.mark.parametrize(
    ("model", "noun", "example"), [("quasi-static", "a stress", "400 Pa"), ("rsf", "a velocity", "50 um/s")]
)
def test_a_word_start_for_a_model_that_starts_from_a_number_names_the_option(capsys, model, noun, example):
    """``--start steady`` for the quasi-static model said "start_stress: expected a number in Pa, got 'steady'",
    naming the Python argument, where a transient-only word should be refused as ``--start`` is elsewhere."""
    code, _, err = run_main(
        capsys, "run", "--model", model, "--v0", "50 um/s", "--duration", "5 s", "--start", "steady"
    )
    assert code == 2
    assert f"--start 'steady': --model {model} starts from {noun}, not a word" in err
    assert f"--start '{example}'" in err and "start_stress" not in err and "start_velocity" not in err
