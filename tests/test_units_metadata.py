"""Every output names its units: frames, CSV headers, Parquet metadata and JSON, each read back."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pint
import pytest

import stickslip
from cli_helpers import run_main
from stickslip import columns, protocols
from stickslip.columns import csv_text, json_units, parquet_table, read_parquet, unit_of, with_units
from stickslip.tables import read_table

_UREG = pint.UnitRegistry()
#: rsf simulate with one aging state (the command lines below share it)
RSF_MODEL = ("rsf", "simulate", "--a", "0.01", "--b", "0.015", "--dc", "10 um", "--stiffness", "1e-3 1/um")
TABLE1 = Path(stickslip.__file__).parent / "data" / "table1.csv"


def test_every_registered_unit_is_a_unit_pint_reads():
    """A unit string nobody can parse names nothing; '1' is the unit one."""
    for name, unit in columns.UNITS.items():
        if unit is None or unit == columns.DIMENSIONLESS:
            continue
        quantity = _UREG.Quantity(1.0, unit.replace("^", "**"))
        assert quantity.to_base_units().magnitude == pytest.approx(1.0), name  # SI base, factor one


def test_parameter_keys_have_their_si_unit():
    assert unit_of("bonds.bond_time") == "s"
    assert unit_of("block.stiffness") == "Pa/m"
    assert unit_of("bonds.breakage_weight") == "1"
    with pytest.raises(KeyError, match="no unit registered"):
        unit_of("no_such_column")


def _results(params):
    """One small result of each kind the package returns (seconds in all)."""
    from stickslip.rsf import RSFParams, StateVariable
    from stickslip.rsf import simulate as rsf_simulate
    from stickslip.transient import run_transient

    rsf = RSFParams(a=0.01, states=(StateVariable("aging", 0.015, 10e-6),), stiffness=1e3)
    yield "steady", stickslip.steady_state(params, np.geomspace(1e-5, 1e-3, 5))
    yield "stick", stickslip.stick_phase(params, 100e-6)
    yield "simulate", stickslip.simulate(params, pulling_velocity=100e-6, duration=20.0)
    yield "transient", run_transient(params, protocols.constant(350e-6, 1e-3), control="velocity")
    yield "rsf", rsf_simulate(rsf, protocols.segments([(1e-6, 5.0), (10e-6, 5.0)]), every=0.5)
    yield "protocol", protocols.segments([(1e-6, 5.0), (10e-6, 5.0)])


def test_every_frame_names_the_unit_of_every_column(params):
    for kind, result in _results(params):
        frame = result.to_frame()
        units = frame.attrs.get("units")
        assert units is not None, kind
        assert set(units) == {str(c) for c in frame.columns}, kind
        assert units["time" if "time" in units else next(iter(units))] is not None or kind == "protocol"


def test_csv_header_carries_units_and_read_table_converts_them(tmp_path):
    frame = with_units(pd.DataFrame({"time": [0.0, 1.0], "stress": [1.0, 2.0], "bonded_fraction": [0.5, 0.25]}))
    path = tmp_path / "t.csv"
    path.write_text(csv_text(frame))
    assert path.read_text().splitlines()[0] == "time [s],stress [Pa],bonded_fraction [1]"
    table = read_table(path, {"time": "time", "stress": "stress", "bonded_fraction": "dimensionless"}, ["time"])
    np.testing.assert_array_equal(table["bonded_fraction"], [0.5, 0.25])
    # a header in other units is converted by the reader: the brackets are read, not decoration
    path.write_text("time [ms],stress [kPa],bonded_fraction [1]\n1000,1,0.5\n2000,2,0.25\n")
    table = read_table(path, {"time": "time", "stress": "stress", "bonded_fraction": "dimensionless"}, ["time"])
    np.testing.assert_allclose(table["time"], [1.0, 2.0])
    np.testing.assert_allclose(table["stress"], [1000.0, 2000.0])


def test_csv_numbers_at_15_digits_read_back_within_5e_15():
    """Round 28: CSV numbers at 15 significant digits, as the JSON (before: every digit, a 1e-05 of a unit's
    rounding written 0.000009999999999999999)."""
    values = np.array([1 / 3, 8e-4, np.pi * 1e-300, 1e300, 10 * 1e-6])
    frame = with_units(pd.DataFrame({"time": values}))
    text = csv_text(frame)
    assert text.splitlines()[1:] == ["0.333333333333333", "0.0008", "3.14159265358979e-300", "1e+300", "1e-05"]
    back = [float(x) for x in text.splitlines()[1:]]
    np.testing.assert_allclose(back, values, rtol=1e-14, atol=0)


def test_parquet_keeps_units_for_pandas_and_pyarrow(tmp_path):
    import pyarrow.parquet as pq

    frame = with_units(pd.DataFrame({"pulling_velocity": [5e-5], "block.stiffness": [4e5], "regime": ["steady"]}))
    path = tmp_path / "x.parquet"
    pq.write_table(parquet_table(frame), path)
    schema = pq.read_schema(path)
    assert schema.field("block.stiffness").metadata[b"unit"] == b"Pa/m"
    assert schema.field("regime").metadata is None
    back = read_parquet(path)
    assert back.attrs["units"] == {"pulling_velocity": "m/s", "block.stiffness": "Pa/m", "regime": None}
    # a plain pandas user recovers them from the schema metadata
    stored = json.loads(pq.read_schema(path).metadata[columns.PARQUET_KEY])
    assert stored["pulling_velocity"] == "m/s"


def test_json_units_map_names_the_keys_present():
    document = {"critical_velocity": 1.2e-4, "cycles": [{"stick_time": 9.7, "peak_stress": 556.4}], "regime": "x"}
    assert json_units(document) == {
        "critical_velocity": "m/s",
        "peak_stress": "Pa",
        "stick_time": "s",
    }


@pytest.mark.parametrize(
    "argv",
    [
        ("critical", "--json"),
        ("simulate", "--v0", "100 um/s", "--duration", "30 s", "--json"),
        ("transient", "--v0", "350 um/s", "--duration", "2 ms", "--control", "velocity", "--json"),
        ("stick", "--v0", "100 um/s", "--json"),
        ("curve", "--points", "3", "--format", "json"),
        (
            *RSF_MODEL,
            "--segment",
            "1 um/s:5 s",
            "--segment",
            "10 um/s:5 s",
            "--json",
        ),
        ("rsf", "stability", "--a", "0.01", "--b", "0.015", "--dc", "10 um", "--velocity", "1 um/s", "--json"),
        ("fit", "stick", str(TABLE1), "--json"),
        ("fit", "steady", str(TABLE1.with_name("synthetic_steady.csv")), "--json"),
    ],
)
def test_cli_json_has_a_units_map_for_its_numbers(capsys, argv):
    """Every key holding a number (or numbers) is in the document's units map, or is registered as a count."""
    code, out, err = run_main(capsys, *argv)
    assert code == 0, err
    document = json.loads(out)
    units = document.pop("units")
    for key, parent in _numeric_keys(document):
        if key in columns.INHERITED:
            assert parent in units or unit_of(parent) is None, f"{parent}/{key}"
        else:
            assert key in units or unit_of(key) is None, key


def _numeric_keys(obj, parent=""):
    """(key, enclosing key) of every key that holds a number or a list of numbers."""
    if isinstance(obj, dict):
        for key, value in obj.items():
            leaves = value if isinstance(value, list) else [value]
            if any(isinstance(v, (int, float)) and not isinstance(v, bool) for v in leaves):
                yield key, parent
            yield from _numeric_keys(value, key)
    elif isinstance(obj, list):
        for item in obj:
            yield from _numeric_keys(item, parent)


def test_json_drops_float_noise(capsys):
    """8e-4 typed by a person is written as 0.0008, not 0.0007999999999999999."""
    from stickslip.cli.common import json_text

    noisy = math.nextafter(0.0008, 0.0)  # 0.0007999999999999999, as a unit conversion can give it
    assert noisy != 0.0008
    assert json.loads(json_text({"split_velocity": noisy, "x": float("nan")})) == {
        "split_velocity": 0.0008,
        "x": None,
        "units": {"split_velocity": "m/s"},
    }


@pytest.mark.parametrize(
    ("argv", "header"),
    [
        (("simulate", "--v0", "100 um/s", "--duration", "30 s"), "time [s],stress [Pa],slider_velocity [m/s]"),
        (("transient", "--v0", "350 um/s", "--duration", "2 ms", "--control", "velocity"), "time [s],stress [Pa]"),
        (
            (
                *RSF_MODEL,
                "--segment",
                "1 um/s:5 s",
                "--every",
                "1 s",
            ),
            "time [s],friction [1]",
        ),
    ],
)
def test_trace_csv_headers_name_units(capsys, tmp_path, argv, header):
    out = tmp_path / "trace.csv"
    code, _, err = run_main(capsys, *argv, "-o", str(out))
    assert code == 0, err
    assert out.read_text().splitlines()[1].startswith(header)  # below the Run CSV's metadata line


def test_sweep_parquet_names_its_units_for_pandas_and_pyarrow(tmp_path):
    import pyarrow.parquet as pq

    from stickslip.sweeps import read_results

    out = tmp_path / "sweep"
    code = _sweep(out)
    assert code == 0
    back = read_results(out)
    assert back.attrs["units"]["pulling_velocity"] == "m/s"
    assert back.attrs["units"]["mean_stress"] == "Pa"
    assert back.attrs["units"]["regime"] is None
    chunk = next(out.glob("part-*.parquet"))
    assert pq.read_schema(chunk).field("pulling_velocity").metadata[b"unit"] == b"m/s"


def _sweep(out):
    from click.testing import CliRunner

    from stickslip.cli.main import cli

    args = ["sweep", "--vary", "pulling_velocity=50 um/s..500 um/s:3:log", "-o", str(out), "--workers", "1", "--quiet"]
    return CliRunner().invoke(cli, args, catch_exceptions=False).exit_code


def test_every_sweep_model_column_and_axis_has_a_unit():
    from stickslip.sweeps.models import MODELS, result_columns
    from stickslip.units import DIMENSIONS

    for name in ("quasi-static", "transient", "rsf"):  # a user's model (a docs example) names its own units
        model = MODELS[name]
        for column in result_columns(model):
            unit_of(column)  # KeyError names what is missing
        for key, dimension in model.dimensions().items():  # the model's own dimensions agree with the registry
            assert unit_of(key) == (DIMENSIONS[dimension][1] or "1"), (model.name, key)


def test_rsf_trace_with_units_in_its_header_is_read_by_rsf_fit_in_si(tmp_path):
    """What `rsf simulate -o` writes (``time [s]``, ``load_point_displacement [m]``) `rsf fit` reads, units and all;
    a header in other units is converted by the brackets, not by the --displacement-unit default."""
    from stickslip.rsf.data import read_record

    t = np.linspace(0.0, 10.0, 21)
    path = tmp_path / "trace.csv"
    path.write_text("time [ms],friction [1],load_point_displacement [um]\n"
                    + "".join(f"{1e3 * x:.17g},0.6,{2.0 * x:.17g}\n" for x in t))  # fmt: skip
    record = read_record(path)
    np.testing.assert_allclose(record.time, t)
    np.testing.assert_allclose(record.displacement, 2e-6 * t)


def test_transient_trace_with_the_stick_chains_shows_what_holds_the_block(params, tmp_path, capsys):
    """While the slider is stuck the chains carry the load (bonded_fraction reads 0 then): the frame and the CSV
    say so (chain_fraction, held_by), and analyze still reads the file."""
    from stickslip.transient import run_transient

    run = run_transient(params, protocols.constant(100e-6, 12.0), start="steady", stick_population=True, rtol=1e-3)
    frame = run.to_frame()
    stuck = frame["slider_velocity"] == 0.0
    assert stuck.any() and (~stuck).any()
    assert set(frame.loc[stuck, "held_by"]) == {"chains"} and set(frame.loc[~stuck, "held_by"]) == {"bonds"}
    assert frame.loc[stuck, "chain_fraction"].between(0.0, 1.0).all()
    assert frame.loc[~stuck, "chain_fraction"].isna().all()
    assert frame.attrs["units"]["chain_fraction"] == "1" and frame.attrs["units"]["held_by"] is None
    trace = tmp_path / "trace.csv"
    code, _, err = run_main(capsys, "transient", "--v0", "100 um/s", "--duration", "12 s", "--start", "steady",
                            "--stick-population", "-o", str(trace))  # fmt: skip
    assert code == 0, err
    assert trace.read_text().splitlines()[1].endswith(",chain_fraction [1],held_by")  # the Run CSV's header
    code, out, err = run_main(capsys, "analyze", str(trace), "--v0", "100 um/s", "--json")
    assert code == 0, err
    assert json.loads(out)["cycles"][0]["stick_time"] == pytest.approx(run.cycles[0].stick_time, abs=1e-2)
