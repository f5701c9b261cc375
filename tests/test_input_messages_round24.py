"""Input messages (round 24): each refusal one line naming what is wrong, exit 2, never an internal error."""

from __future__ import annotations

import json
from typing import Any

import pytest

import stickslip
from cli_helpers import run_main
from stickslip.errors import DataError, ParameterError
from stickslip.models import FrictionModel
from stickslip.protocols import parse_segment, read_protocol


class _BadDimension(FrictionModel):
    """A plug-in whose key names a dimension the package does not know."""

    name = "bad-dimension"

    def dimensions(self) -> dict[str, str]:
        return {"mu0": "furlongs"}

    def parameters(self, spec: Any = None, overrides: Any = None) -> Any:
        return {"mu0": 0.5, **dict(overrides or {})}

    def run(self, params: Any, protocol: Any, rig: Any = None, *, start: Any = None, **settings: Any) -> Any:
        raise AssertionError("a model of an unknown dimension must be refused before it runs")


BADDIM = _BadDimension()
PLUGIN = f"{__name__}:BADDIM"
REFUSAL = "model 'bad-dimension': key 'mu0' has dimension 'furlongs', not a known dimension; expected one of area,"


@pytest.mark.parametrize(
    "args",
    [
        ("sweep", "--model", PLUGIN, "--vary", "mu0=0.4,0.55", "--v0", "100 um/s", "--duration", "2 s",
         "--workers", "0"),
        ("run", "--model", PLUGIN, "--v0", "100 um/s", "--duration", "2 s", "--set", "mu0=0.5"),
        ("run", "--model", PLUGIN, "--v0", "100 um/s", "--duration", "2 s"),
        ("compare", "--models", f"{PLUGIN},quasi-static", "--v0", "100 um/s", "--duration", "2 s"),
    ],
)  # fmt: skip
def test_a_plugin_key_of_an_unknown_dimension_is_refused_in_one_line(args, tmp_path, capsys):
    extra = ("-o", str(tmp_path / "sweep")) if args[0] == "sweep" else ()
    status, _, err = run_main(capsys, *args, *extra)
    assert status == 2 and err.count("\n") == 1, err
    assert REFUSAL in err and "velocity" in err and "internal error" not in err, err
    assert not (tmp_path / "sweep").exists()


def test_the_sweep_api_refuses_it_too():
    from stickslip.sweeps import build_spec

    with pytest.raises(ParameterError, match="key 'mu0' has dimension 'furlongs'"):
        build_spec(["mu0=0.4,0.55"], model=PLUGIN, pulling_velocity="100 um/s", duration="2 s")


def test_a_protocol_row_with_a_third_field_is_named(tmp_path, capsys):
    path = tmp_path / "extra.csv"
    path.write_text("time,velocity\n0,350e-6,5\n2,0\n")
    status, _, err = run_main(capsys, "transient", "--protocol", str(path))
    assert status == 2 and err.count("\n") == 1, err
    assert "extra.csv: row 2: expected 2 fields (time,velocity), got 3: '0,350e-6,5'" in err, err
    commented = tmp_path / "late.csv"  # comment and blank lines counted, as an editor shows them
    commented.write_text("# a protocol\nvelocity;duration\n\n1e-4;2\n1e-4;2;\n")
    with pytest.raises(DataError, match=r"late.csv: row 5: expected 2 fields \(velocity,duration\), got 3"):
        read_protocol(commented)


def test_compare_json_units_name_every_result(capsys):
    args = ["compare", "--models", "quasi-static,rsf", "--v0", "50 um/s", "--duration", "30 s", "--set", "a=0.005",
            "--set", "b=0.01", "--set", "dc=10 um", "--json"]  # fmt: skip
    status, out, err = run_main(capsys, *args)
    assert status == 0, err
    document = json.loads(out)
    units = document["units"]
    for key, unit in {"period": "s", "peak_stress": "Pa", "mean_stress": "Pa", "peak_friction": "1",
                      "mean_friction": "1", "end_time": "s", "velocity": "m/s", "duration": "s"}.items():  # fmt: skip
        assert units.get(key) == unit, (key, units)
    for name, row in document["models"].items():  # every unit of every model's map, where the models agree
        for key, unit in row["units"].items():
            if key != "stiffness":
                assert units[key] == unit, (name, key)
    assert units["stiffness"] == "Pa/m"  # the top-level rig's; each model's own map keeps its spring's (1/m)
    assert document["models"]["rsf"]["units"]["stiffness"] == "1/m"


def test_merged_units_leave_a_disputed_key_to_each_model():
    from stickslip.cli.compare_models import merged_units

    merged = merged_units({"duration": "s"}, [{"period": "s", "spring": "Pa/m"}, {"period": "s", "spring": "1/m"}])
    assert merged == {"duration": "s", "period": "s"}


def test_an_unreadable_time_is_shown_a_time(capsys):
    status, _, err = run_main(capsys, "transient", "--segment", "50 um/s:abc")
    assert status == 2 and err.count("\n") == 1, err
    assert "expected a time (e.g. in s) written as a number and a unit, e.g. '20 s'" in err, err
    assert "350 um/s" not in err


def test_a_segment_of_three_fields_says_the_form(capsys):
    status, _, err = run_main(capsys, "simulate", "--segment", "50 um/s:30 s:3")
    assert status == 2 and err.count("\n") == 1, err
    assert (
        "--segment '50 um/s:30 s:3': expected VELOCITY:DURATION (two fields, one colon), got 3 fields;"
        " e.g. --segment '1 mm/s:2 s'"
    ) in err, err
    assert "needs a unit" not in err
    with pytest.raises(ParameterError, match="expected VELOCITY:DURATION"):
        parse_segment("50 um/s:30 s:3")


def test_run_read_names_the_file(tmp_path):
    missing = tmp_path / "nonexist.csv"
    with pytest.raises(DataError, match=f"run file {missing}: file not found"):
        stickslip.Run.read(missing)
    garbage = tmp_path / "garbage.csv"
    garbage.write_bytes(b"\xff\xfe\x00\x89PNG")
    with pytest.raises(DataError, match=r"run file .*garbage.csv: not a text \(UTF-8\) file"):
        stickslip.Run.read(garbage)
    with pytest.raises(DataError, match="run file: expected a path, got int"):
        stickslip.Run.read(123)  # type: ignore[arg-type]


def test_a_quoted_number_without_a_unit_in_a_parameter_file_is_refused(tmp_path, capsys):
    text = stickslip.load_parameters("gelatin-glass").to_toml()
    lines = [('bond_time = "224"' if line.startswith("bond_time =") else line) for line in text.splitlines()]
    assert 'bond_time = "224"' in lines
    path = tmp_path / "quoted.toml"
    path.write_text("\n".join(lines) + "\n")
    expected = (
        "bonds.bond_time: '224' is a quoted number without a unit; a time needs one, e.g. bond_time = \"224 s\""
        " (or bond_time = 224, unquoted, for a number in SI units, s)"
    )
    with pytest.raises(ParameterError) as info:
        stickslip.load_parameters(str(path))
    assert expected in str(info.value)
    status, _, err = run_main(capsys, "critical", "--params", str(path))
    assert status == 2 and err.count("\n") == 1 and expected in err, err
    # a number unquoted is SI, a quoted one with its unit is read, and a quoted zero or dimensionless key needs none
    unquoted = path.with_name("unquoted.toml")
    unquoted.write_text(path.read_text().replace('bond_time = "224"', "bond_time = 0.000224"))
    assert stickslip.load_parameters(str(unquoted)).bonds.bond_time == pytest.approx(224e-6)
    weighted = path.with_name("weighted.toml")
    weighted.write_text(path.read_text().replace('bond_time = "224"', 'bond_time = "224 us"'))
    weighted.write_text(
        "\n".join(
            'breakage_weight = "1.0"' if line.startswith("breakage_weight =") else line
            for line in weighted.read_text().splitlines()
        )
    )
    assert stickslip.load_parameters(str(weighted)).bonds.breakage_weight == 1.0


def test_a_capitalised_header_is_read_as_its_column(tmp_path, capsys):
    """'Velocity [um/s]' was 'unknown column'; rsf fit already read 'Time (s)'."""
    from stickslip.fitting.data import read_steady_data

    table = tmp_path / "cap.csv"
    table.write_text("Velocity [um/s],Stress [kPa]\n10,0.9\n20,0.7\n50,0.4\n100,0.3\n")
    data = read_steady_data(table)
    assert list(data.velocity) == pytest.approx([10e-6, 20e-6, 50e-6, 100e-6])
    assert list(data.stress) == pytest.approx([900.0, 700.0, 400.0, 300.0])
