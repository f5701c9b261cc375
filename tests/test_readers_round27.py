"""Round 27: how users' files are read (rate-and-state records, stress records, steady curves, stick tables).

* ';'- (or tab-) separated files with decimal commas, the European spreadsheet's and DAQ's export, are read, with
  one note; ambiguous commas (a comma-separated file, thousands separators) stay refused in one line;
* a record of shear stress and normal stress is fitted as μ = τ/σn (a column, or --normal-stress);
* column names are matched as docs/rsf.md says ("LP disp (um)" is a displacement);
* a steady curve's bad value is named as the file wrote it, before any count;
* a LabRecord is validated when it is made.

Every check is against the truth the synthetic files are written from.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from stickslip import protocols
from stickslip.analysis.traces import read_trace
from stickslip.cli.main import main
from stickslip.errors import DataError
from stickslip.fitting.data import read_steady_data, read_stick_data
from stickslip.rsf import rsf_params, simulate
from stickslip.rsf.data import LabRecord, read_record
from stickslip.rsf.fit import fit_record

UM = 1e-6
TRUTH = {"a": 0.008, "b": 0.012, "dc": 20 * UM, "stiffness": 3e3}
PARAMS = rsf_params(TRUTH["a"], TRUTH["b"], TRUTH["dc"], v_ref=UM, stiffness=TRUTH["stiffness"], mu0=0.6)
STEP = protocols.velocity_steps([1 * UM, 10 * UM], [60.0, 40.0])
SIGMA_N = 10e6  # Pa


def run_cli(capsys, *args: str) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as info:
        main(list(args))
    out = capsys.readouterr()
    return int(info.value.code or 0), out.out, out.err


@pytest.fixture(scope="module")
def truth() -> dict[str, np.ndarray]:
    """600 rows of the step 1 -> 10 um/s from the known parameters, white friction noise 2e-4, and a normal stress
    that wanders by 2 % (a divisor that is a constant would leave a 0.012 ripple in μ, 60 times the noise)."""
    t = np.linspace(0.0, STEP.duration, 600)
    run = simulate(PARAMS, STEP, times=t)
    mu = run.friction + 2e-4 * np.random.default_rng(27).standard_normal(t.size)
    sn = SIGMA_N * (1.0 + 0.02 * np.sin(2 * np.pi * t / 37.0))
    return {"t": t, "d": run.load_point_displacement, "mu": mu, "sn": sn}


def european(path: Path, header: str, rows: list[str], comma: bool = True) -> Path:
    """A spreadsheet's export: byte-order mark, CRLF, '#' comments, ';' between cells, two empty columns at the
    end, and decimal commas (``comma``) or points."""
    lines = ["# Rig: biax-2  sample S17", "# exported 2025-01-01", header + ";;"]
    lines += [(r.replace(".", ",") if comma else r) + ";;" for r in rows]
    path.write_bytes(("\r\n".join(lines) + "\r\n").encode("utf-8-sig"))
    return path


def stress_record(path: Path, truth: dict[str, np.ndarray], comma: bool = True) -> Path:
    """Time in ms, load point in mm, shear stress in kPa and normal stress in MPa, as tester F's rig writes."""
    tau = truth["mu"] * truth["sn"]
    rows = [
        f"{t * 1e3:.3f};{d * 1e3:.9f};{s / 1e3:.5f};{n / 1e6:.7f}"
        for t, d, s, n in zip(truth["t"], truth["d"], tau, truth["sn"], strict=True)
    ]
    return european(path, "Time [ms];LP Displacement [mm];Shear stress [kPa];Normal stress [MPa]", rows, comma)


# --------------------------------------------------------------------------- decimal commas


def test_a_semicolon_record_with_decimal_commas_reads_as_the_truth(tmp_path, truth):
    """Tester F's recA_semicolon_comma.csv: "row 1, column 'Time [ms]': '0,0' is not a number" (exit 2).  Now its
    numbers are the truth to the digits written, and one note says how the commas were read."""
    record = read_record(stress_record(tmp_path / "recA.csv", truth))
    assert np.allclose(record.time, truth["t"], rtol=0, atol=1e-6)  # ms to 3 decimals
    assert np.allclose(record.displacement, truth["d"], rtol=0, atol=1e-12)
    assert np.allclose(record.friction, truth["mu"], rtol=0, atol=1e-6)  # τ/σn, each to 7 digits
    assert record.length_unit == "mm"
    assert any("decimal commas" in note and "0,5 read as 0.5" in note for note in record.notes)
    assert any("μ = τ/σn" in note and "Normal stress [MPa]" in note for note in record.notes)


def test_the_comma_record_fits_the_truth(tmp_path, truth):
    """τ/σn with its wandering σn column, decimal commas, ms and mm: the fit's 95 % intervals hold a, b, Dc, k."""
    record = read_record(stress_record(tmp_path / "recA.csv", truth))
    fit = fit_record(record, drift_check=False)
    assert fit.status == "ok", fit.reason
    for key, value in TRUTH.items():
        low, high = fit.parameters[key].interval
        assert low <= value <= high, (key, low, high)


def test_a_comma_record_on_the_command_line(tmp_path, capsys, truth):
    """The command of the defect report, without --columns: exit 0, the notes in the report; a, b in SI."""
    path = stress_record(tmp_path / "recA.csv", truth)
    code, out, err = run_cli(capsys, "rsf", "fit", str(path), "--json")
    assert code == 0, err
    report = json.loads(out)
    assert any("decimal commas" in note for note in report["notes"])
    a, b = (report["parameters"][k] for k in ("a", "b"))
    assert a["interval"][0] <= TRUTH["a"] <= a["interval"][1] and b["interval"][0] <= TRUTH["b"] <= b["interval"][1]


def test_stress_records_steady_curves_and_stick_tables_read_decimal_commas(tmp_path):
    """The same shared reading routine for analyze's records, fit steady's curves and fit stick's tables."""
    t = np.arange(0.0, 30.0, 0.5)
    stress = 500.0 + 40.0 * np.sin(t)
    trace = tmp_path / "trace.csv"
    trace.write_text("time [ms];stress [kPa]\n" + "".join(f"{a * 1e3:.1f};{s / 1e3:.6f}\n".replace(".", ",")
                                                            for a, s in zip(t, stress, strict=True)))  # fmt: skip
    read = read_trace(trace)
    assert np.allclose(read.time, t, atol=1e-9) and np.allclose(read.stress, stress, rtol=0, atol=1e-3)
    assert any("decimal commas" in note for note in read.notes)

    v = np.array([1.0, 3.0, 10.0, 30.0, 100.0])  # um/s
    s = np.array([812.5, 640.25, 590.0, 615.75, 701.0])  # Pa
    steady = tmp_path / "steady.txt"
    steady.write_text("velocity [um/s]\tstress [Pa]\n" + "".join(f"{a:g}\t{b:g}\n".replace(".", ",")
                                                                  for a, b in zip(v, s, strict=True)))  # fmt: skip
    data = read_steady_data(steady)
    assert np.allclose(data.velocity, v * UM, rtol=1e-12) and np.allclose(data.stress, s, rtol=1e-12)
    assert any("tab-separated with decimal commas" in note for note in data.notes())

    stick = tmp_path / "stick.csv"
    stick.write_text("pulling_velocity [um/s];stick_time [s];;\n12,5;3,25;;\n25,0;1,75;;\n50,0;0,5;;\n")  # empty ends
    table = read_stick_data(stick)
    assert np.allclose(table.pulling_velocity, [12.5e-6, 25e-6, 50e-6]) and np.allclose(table.stick_time,
                                                                                       [3.25, 1.75, 0.5])  # fmt: skip
    assert any("decimal commas" in note for note in table.notes())


def test_analyze_says_so_in_one_note_line(tmp_path, capsys):
    t = np.arange(0.0, 60.0, 0.05)
    stress = 500.0 + 0.5 * t  # a stick that never slips: enough for the reader's note
    trace = tmp_path / "ssE_semi.csv"
    trace.write_text("time [ms];stress [kPa]\n" + "".join(f"{a * 1e3:.1f};{s / 1e3:.5f}\n".replace(".", ",")
                                                            for a, s in zip(t, stress, strict=True)))  # fmt: skip
    code, _, err = run_cli(capsys, "analyze", str(trace), "--v0", "50 um/s")
    assert code == 0, err
    notes = [line for line in err.splitlines() if "decimal commas" in line]
    assert len(notes) == 1 and notes[0].startswith("note: ")


@pytest.mark.parametrize(
    ("text", "said"),
    [
        # a comma between the cells: a comma in a cell (quoted) cannot be a decimal mark
        ('time [s],stress [Pa]\n"0,0","1,5"\n"1,0","2,5"\n', "in a comma-separated file a comma cannot be a decimal"),
        # a thousands separator with a decimal comma, and decimal points elsewhere
        ("time [s];stress [Pa]\n0.0;1.234,5\n1.0;1.200,0\n", "thousands separators?"),
        # every comma before three digits: 1,000 is one thousand or one
        ("time [s];stress [Pa]\n1,000;2,000\n2,000;3,500\n", "a decimal comma or a thousands separator?"),
        # decimal points and one decimal comma
        ("time [s];stress [Pa]\n0.0;1.5\n1.0;2,5\n", "a decimal comma? the file's other numbers have decimal points"),
    ],
    ids=["comma-separated", "thousands", "grouping-or-decimal", "mixed"],
)
def test_ambiguous_commas_stay_refused_in_one_line(tmp_path, text, said):
    path = tmp_path / "t.csv"
    path.write_text(text)
    with pytest.raises(DataError, match=r"row \d") as info:
        read_trace(path)
    assert said in str(info.value) and "\n" not in str(info.value)


def test_an_ambiguous_record_names_its_row(tmp_path):
    rows = [f"{i},000;{i},000;0,600" for i in range(1, 30)]  # "0,600" could be 600 with a thousands separator
    path = tmp_path / "r.csv"
    path.write_text("time [s];disp [mm];mu\n" + "\n".join(rows).replace("0,600", "1,600") + "\n")
    with pytest.raises(DataError, match=r"r\.csv: row 2: '1,000': a decimal comma or a thousands separator\?"):
        read_record(path)


def test_text_format_decides_once_for_every_reader(tmp_path):
    from stickslip.tables import text_format  # (new in round 27)

    comma = tmp_path / "c.csv"
    comma.write_text("a;b\n0,5;1\n")
    point = tmp_path / "p.csv"
    point.write_text("a;b\n0.5;1\n")
    plain = tmp_path / "x.csv"
    plain.write_text("a,b\n0.5,1\n")
    assert (text_format(comma).delimiter, text_format(comma).decimal) == (";", ",")
    assert (text_format(point).decimal, text_format(point).note) == (".", "")
    assert (text_format(plain).delimiter, text_format(plain).decimal) == (",", ".")


# --------------------------------------------------------------------------- shear stress and normal stress


def test_a_shear_stress_mapped_as_friction_needs_the_normal_stress(tmp_path, capsys, truth):
    """Tester F: "column 'Shear stress [kPa]' is in kPa, a stress; expected the friction coefficient" with no way
    on.  Without any normal stress the refusal says what to give; with --normal-stress, μ = τ/σn."""
    tau = truth["mu"] * SIGMA_N
    rows = [f"{t:.4f};{d / UM:.6f};{s / 1e3:.5f}" for t, d, s in zip(truth["t"], truth["d"], tau, strict=True)]
    path = european(tmp_path / "tau.csv", "Time (s);LP disp (um);Shear stress [kPa]", rows, comma=False)
    columns = 'friction="Shear stress [kPa]"'
    code, _, err = run_cli(capsys, "rsf", "fit", str(path), "--columns", columns)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "is in kPa, a stress; expected the friction coefficient, or the normal stress" in err
    assert "--normal-stress" in err and "normal_stress=" in err
    record = read_record(path, {"friction": "Shear stress [kPa]"}, normal_stress="10 MPa")
    assert np.allclose(record.friction, truth["mu"], rtol=0, atol=1e-6)
    assert np.allclose(read_record(path, normal_stress=SIGMA_N).friction, record.friction)  # found by name


def test_normal_stress_column_and_option_problems_are_named(tmp_path, truth):
    tau = truth["mu"] * truth["sn"]
    rows = [f"{t:.4f};{d / UM:.6f};{s / 1e3:.5f};{n / 1e6:.7f}"
            for t, d, s, n in zip(truth["t"], truth["d"], tau, truth["sn"], strict=True)]  # fmt: skip
    path = european(tmp_path / "both.csv", "t;disp (um);tau (kPa);sn (MPa)", rows, comma=False)
    with pytest.raises(DataError, match=r"gives the normal stress 10\.0\d* MPa \(median\) but --normal-stress says 5 "):
        read_record(path, normal_stress="5 MPa")
    assert np.allclose(read_record(path, normal_stress="10 MPa").friction, truth["mu"], atol=1e-6)
    rows[4] = rows[4].rsplit(";", 1)[0] + ";0"
    zero = european(tmp_path / "zero.csv", "t;disp (um);tau (kPa);sn (MPa)", rows, comma=False)
    with pytest.raises(DataError, match=r"row 8, column 'sn \(MPa\)': 0 MPa; expected a positive normal stress"):
        read_record(zero)
    bare = european(tmp_path / "bare.csv", "t;disp (um);tau;sn (MPa)", rows[:4] + rows[5:], comma=False)
    with pytest.raises(DataError, match=r"is 0\.0006\d* \(median\), outside 0\.001 to 10; check the units"):
        read_record(bare)  # tau written in kPa under a bare header (Pa): μ 1000 times too small


# --------------------------------------------------------------------------- column names


@pytest.mark.parametrize(
    ("time", "displacement", "friction"),
    [
        ("Time (s)", "LP disp (um)", "Friction"),
        ("time_s", "disp_um", "mu"),
        ("t", "Load-point displacement [um]", "friction coefficient"),
        ("Time [s]", "LVDT displacement um", "μ"),
        ("Time(s)", "Displ (um)", "Coefficient of friction"),
    ],
)
def test_columns_are_found_by_name_as_the_docs_say(tmp_path, truth, time, displacement, friction):
    """Tester F: "LP disp (um)" gave "no displacement column" though the docs say `disp` is found."""
    rows = [f"{t:.4f}\t{d / UM:.6f}\t{m:.7f}" for t, d, m in zip(truth["t"], truth["d"], truth["mu"], strict=True)]
    path = tmp_path / "r.txt"
    path.write_text(f"{time}\t{displacement}\t{friction}\n" + "\n".join(rows) + "\n")
    record = read_record(path)
    assert np.allclose(record.displacement, truth["d"], rtol=0, atol=1e-12)
    assert np.allclose(record.friction, truth["mu"], rtol=0, atol=1e-7)


def test_a_normal_displacement_is_no_load_point(tmp_path):
    path = tmp_path / "r.txt"
    path.write_text("Time (s)\tNormal disp (um)\tmu\n" + "".join(f"{i}\t{i}\t0.6\n" for i in range(20)))
    with pytest.raises(DataError, match="no displacement column; found Time \\(s\\), Normal disp \\(um\\), mu"):
        read_record(path)


# --------------------------------------------------------------------------- steady curves


def test_a_negative_velocity_is_named_as_written(tmp_path):
    """Tester F's bad3.csv: "expected a positive value, got -2e-05"; the row and the value as written, its unit."""
    path = tmp_path / "bad3.csv"
    path.write_text("velocity [um/s],stress [Pa]\n10,500\n-20,400\n40,300\n80,350\n160,400\n")
    with pytest.raises(
        DataError, match=r"bad3\.csv: row 3, column 'velocity': expected a positive value, got -20 um/s$"
    ):
        read_steady_data(path)


@pytest.mark.parametrize(
    ("text", "said"),
    [
        (
            "velocity [mm/min],stress [kPa]\n0.6,18\n-1.2,11\n2.4,5\n",
            "row 3, column 'velocity': expected a positive value, got -1.2 mm/min",
        ),
        (
            "velocity [km/s],stress [kPa]\n1e6,18\n2e6,11\n4e6,5\n",
            "row 2, column 'velocity': 1e+09 m/s is outside the range of a sliding velocity",
        ),
    ],
    ids=["negative", "out-of-range"],
)
def test_a_steady_curve_s_values_are_checked_before_its_count(tmp_path, text, said):
    """Three rows with a wrong value: the value is named (it was "3 data row(s), expected at least 4")."""
    path = tmp_path / "s.csv"
    path.write_text(text)
    with pytest.raises(DataError) as info:
        read_steady_data(path)
    assert said in str(info.value)


def test_a_stick_table_s_values_are_checked_before_its_count(tmp_path):
    path = tmp_path / "stick.csv"
    path.write_text("pulling_velocity [um/s],stick_time [ms]\n50,-300\n")
    with pytest.raises(DataError, match=r"row 2, column 'stick_time': expected a positive value, got -300 ms"):
        read_stick_data(path)


def test_a_five_point_curve_in_an_unusual_unit_reaches_the_fit(tmp_path, capsys):
    """Tester F: 5 points in mm/min gave only "5 data point(s) for 5 free parameter(s)".  That count is right for 5
    points (the joint fit frees 5); what matters is that every check of the file came first: a bad unit or value
    in the same 5 rows is named instead of the count."""
    rows = "0.6,18.4\n1.2,11.5\n2.4,5.3\n4.8,1.1\n9.6,0.27\n"
    good = tmp_path / "good.csv"
    good.write_text("velocity [mm/min],stress [kPa]\n" + rows)
    code, _, err = run_cli(capsys, "fit", "steady", str(good), "--method", "joint")
    assert code == 2 and "5 data point(s) for 5 free parameter(s)" in err
    for header, said in (("velocity [mm/mn]", "unknown unit"), ("velocity [mm],stress [kPa]", "expected a velocity")):
        bad = tmp_path / "bad.csv"
        bad.write_text(header.split(",")[0] + ",stress [kPa]\n" + rows)
        code, _, err = run_cli(capsys, "fit", "steady", str(bad))
        assert code == 2 and said in err and "free parameter" not in err


# --------------------------------------------------------------------------- LabRecord


@pytest.mark.parametrize(
    ("change", "said"),
    [
        ({"displacement": None}, "LabRecord displacement is None"),
        ({"friction": np.zeros(11)}, "have 12, 12 and 11 values"),
        (
            {"time": np.arange(5.0), "displacement": np.zeros(5), "friction": np.zeros(5)},
            "has 5 row(s); expected at least 10",
        ),
        ({"friction": np.r_[np.zeros(3), np.nan, np.zeros(8)]}, "LabRecord friction[3] is nan; expected finite"),
        ({"time": np.r_[np.arange(6.0), 4.0, np.arange(7.0, 12.0)]}, "LabRecord time[6] = 4 s does not increase"),
        ({"displacement": np.zeros((12, 2))}, "LabRecord displacement: expected a 1-D array"),
        ({"time": "soon"}, "LabRecord time: expected an array of numbers"),
    ],
)
def test_a_lab_record_is_validated_when_made(change, said):
    """Tester E: LabRecord(time=t, displacement=None, friction=mu) was accepted and fit_record failed with
    "TypeError: 'NoneType' object is not subscriptable"."""
    fields = {"time": np.arange(12.0), "displacement": np.linspace(0, 1e-5, 12), "friction": np.full(12, 0.6)}
    fields.update(change)
    with pytest.raises(DataError) as info:
        LabRecord(**fields)
    assert said in str(info.value)


def test_a_valid_lab_record_holds_float_arrays():
    record = LabRecord(time=[0, 1, 2, 3, 4, 5, 6, 7, 8, 9], displacement=range(10), friction=[0.6] * 10)
    assert record.time.dtype == float and record.displacement[-1] == 9.0 and len(record) == 10
    assert not math.isnan(float(record.friction.sum()))
