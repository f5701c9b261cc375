"""Round 28: lab exports the readers refused, gzip, and messages that named the wrong row or SI values.

* R1: a title line before the header, a units row under it (``ms  mm  -``), and a file with no header row
  (``--columns time=1,...``; a header in the ``#`` comment just before the data is read) -- one layout decision
  (:class:`stickslip.tables.Layout`) for the record reader and the measurement-table reader;
* R2: a gzip file is read decompressed by every reader (records, tables, protocols), by its bytes, not its name;
* R3: a record's time of 1e300 s (or one row out of order) is named at its own row, not at the row after it;
* R4: a protocol file's bad row is quoted as written, with its units, an empty cell said as such.

Every check is against the truth the synthetic files are written from.
"""

from __future__ import annotations

import gzip
import json

import numpy as np
import pytest

from stickslip import protocols
from stickslip.errors import DataError
from stickslip.rsf import rsf_params, simulate
from stickslip.rsf.data import read_record
from stickslip.tables import read_table
from test_readers_round27 import run_cli

UM = 1e-6
TRUTH = {"a": 0.008, "b": 0.012, "dc": 20 * UM, "stiffness": 3e3}
STEP = protocols.velocity_steps([1 * UM, 10 * UM], [60.0, 40.0])


@pytest.fixture(scope="module")
def truth() -> dict[str, np.ndarray]:
    """400 rows of a step 1 -> 10 um/s from the known parameters, white friction noise 2e-4."""
    params = rsf_params(TRUTH["a"], TRUTH["b"], TRUTH["dc"], v_ref=UM, stiffness=TRUTH["stiffness"], mu0=0.6)
    t = np.linspace(0.0, STEP.duration, 400)
    run = simulate(params, STEP, times=t)
    mu = run.friction + 2e-4 * np.random.default_rng(28).standard_normal(t.size)
    return {"t": t, "d": run.load_point_displacement, "mu": mu}


def lab_rows(truth: dict[str, np.ndarray], sep: str = "\t") -> list[str]:
    """Time in ms, displacement in mm, friction: as a LabVIEW export writes them."""
    return [f"{t * 1e3:.3f}{sep}{d * 1e3:.9f}{sep}{m:.6f}" for t, d, m in zip(truth["t"], truth["d"], truth["mu"],
                                                                              strict=True)]  # fmt: skip


def assert_truth(record, truth: dict[str, np.ndarray]) -> None:
    """The record holds the truth in SI (the file's rounding: 1e-3 ms, 1e-9 mm, 1e-6)."""
    np.testing.assert_allclose(record.time, truth["t"] - truth["t"][0], atol=1e-6)
    np.testing.assert_allclose(record.displacement, truth["d"] - truth["d"][0], atol=1e-11)
    np.testing.assert_allclose(record.friction, truth["mu"], atol=1e-6)


# ---------------------------------------------------------------- R1: title lines, units rows, no header row


def test_a_title_line_and_a_units_row_are_read_as_lab_software_writes_them(tmp_path, truth):
    """'Experiment p1234 2024-05-01' before the header was taken for the header ("no column 'Time'; found
    Experiment, p1234, ..."), and 'ms  mm  -' under it was refused ("'ms' is not a number")."""
    path = tmp_path / "units.txt"
    path.write_text("Experiment p1234  2024-05-01\nTime\tLP_Disp\tMu\nms\tmm\t-\n" + "\n".join(lab_rows(truth)) + "\n")
    record = read_record(path)
    assert_truth(record, truth)
    note = " ".join(record.notes)
    assert "row 1 before the header skipped" in note and "row 3 read as the columns' units (ms, mm, -)" in note
    assert record.length_unit == "mm"
    # the columns are still mapped by their names as the header writes them
    mapped = read_record(path, columns={"time": "Time", "displacement": "LP_Disp", "friction": "Mu"})
    assert_truth(mapped, truth)


def test_several_title_lines_and_comments_before_a_plain_header(tmp_path, truth):
    rows = [f"{t:.6f},{d * 1e6:.6f},{m:.6f}" for t, d, m in zip(truth["t"], truth["d"], truth["mu"], strict=True)]
    path = tmp_path / "titled.csv"
    path.write_text("# exported by RigSoft\nBiax run 17\nsample: gouge 12, 10 MPa\n\ntime [s],disp [um],mu\n"
                    + "\n".join(rows) + "\n")  # fmt: skip
    record = read_record(path)
    assert_truth(record, truth)
    assert any("rows 2-3 before the header skipped" in n for n in record.notes)


def test_a_units_row_that_contradicts_the_header_is_refused(tmp_path, truth):
    path = tmp_path / "both.txt"
    path.write_text("Time (s)\tLP_Disp\tMu\nms\tmm\t-\n" + "\n".join(lab_rows(truth)) + "\n")
    with pytest.raises(
        DataError, match=r"column 'Time \(s\)' names its unit 's' but the units row \(row 2\) says 'ms'"
    ):
        read_record(path)


def test_the_measurement_table_reader_shares_the_layout(tmp_path):
    """analyze's and fit steady's reader (read_table) reads the same exports: a title, a units row (kPa, ms)."""
    t = np.arange(20) * 0.25  # s
    stress = 1000.0 + 37.0 * np.arange(20)  # Pa
    lines = ["Shear test 3 (free text)", "time\tstress", "ms\tkPa"]
    lines += [f"{a * 1e3:g}\t{b / 1e3:g}" for a, b in zip(t, stress, strict=True)]
    path = tmp_path / "trace.txt"
    path.write_text("\n".join(lines) + "\n")
    table = read_table(path, {"time": "time", "stress": "stress"}, required=["time", "stress"])
    np.testing.assert_allclose(table["time"], t, rtol=1e-12)
    np.testing.assert_allclose(table["stress"], stress, rtol=1e-12)
    assert list(table.rows) == list(range(4, 24))  # each value's row in the file, for messages
    assert table.as_written("stress", 1500.0) == "1.5 kPa"
    assert any("row 3 read as the columns' units (ms, kPa)" in n for n in table.notes)


def test_a_bad_first_data_row_is_still_named_as_before(tmp_path, truth):
    """A text cell in the first data row is no units row and makes no title of the header: it is named (a guard:
    passes on the old code too)."""
    rows = lab_rows(truth)
    rows[0] = rows[0].split("\t")[0] + "\tn.a.\t0.6"
    path = tmp_path / "bad.txt"
    path.write_text("Time (ms)\tLP_Disp (mm)\tMu\n" + "\n".join(rows) + "\n")
    with pytest.raises(DataError, match=r"row 2, column 'LP_Disp \(mm\)': 'n.a.' is not a number"):
        read_record(path)


def test_a_file_with_no_header_row_is_mapped_by_column_number(tmp_path, truth, capsys):
    """The message said "map them with --columns time=...", but time=1 was refused ("no column '1'"): the columns
    of a file with no header row are numbered from 1, as the message now says."""
    path = tmp_path / "nohead.txt"
    path.write_text("\n".join(" ".join(r.split("\t")) for r in lab_rows(truth)) + "\n")
    with pytest.raises(DataError, match=r"no header row \(row 1 holds numbers\); map its 3 columns by number.*"
                                        r"--columns time=1,displacement=2,friction=3"):  # fmt: skip
        read_record(path)
    record = read_record(path, columns={"time": "1", "displacement": "2", "friction": "3"}, time_unit="ms",
                         displacement_unit="mm")  # fmt: skip
    assert_truth(record, truth)
    code, _, err = run_cli(capsys, "rsf", "fit", str(path))
    assert code == 2 and err.count("\n") == 1 and "--columns time=1,displacement=2,friction=3" in err
    with pytest.raises(DataError, match=r"--columns friction=4: no column 4; the file has 3"):
        read_record(path, columns={"time": "1", "displacement": "2", "friction": "4"})


def test_a_column_number_maps_a_file_with_a_header_too(tmp_path, truth):
    path = tmp_path / "odd.txt"
    path.write_text("Zeit (ms)\tWeg (mm)\tReibung\n" + "\n".join(lab_rows(truth)) + "\n")
    record = read_record(path, columns={"time": "1", "displacement": "Weg (mm)", "friction": "3"})
    assert_truth(record, truth)


def test_a_header_in_the_comment_before_the_data_is_read(tmp_path, truth):
    """xlook-style: '# time(ms) displacement(mm) friction' and blank-separated numbers, no header row."""
    path = tmp_path / "commented.txt"
    path.write_text("# time(ms) displacement(mm) friction\n" + "\n".join("  ".join(r.split("\t"))
                                                                          for r in lab_rows(truth)) + "\n")  # fmt: skip
    record = read_record(path)
    assert_truth(record, truth)
    assert any("the header read from the comment on row 1" in n for n in record.notes)


# ---------------------------------------------------------------- R2: gzip


def test_gzip_records_tables_and_protocols_read_as_their_plain_text(tmp_path, truth, capsys):
    """'d2_record.csv.gz' was decompressed by pandas but not by the separator's reader: "no time column; found
    time [s],friction [1],..." (one column).  Every reader now opens its file in one place."""
    params = rsf_params(TRUTH["a"], TRUTH["b"], TRUTH["dc"], v_ref=UM, stiffness=TRUTH["stiffness"], mu0=0.6)
    plain = tmp_path / "run.csv"
    frame = simulate(params, STEP, every=0.25).to_frame()
    units = frame.attrs["units"]
    frame.to_csv(plain, index=False, header=[f"{c} [{units[c]}]" if units.get(c) else c for c in frame])
    packed = tmp_path / "run.csv.gz"
    packed.write_bytes(gzip.compress(plain.read_bytes()))
    a, b = read_record(plain), read_record(packed)
    for name in ("time", "displacement", "friction"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    # a gzip file's name need not say so; the measurement tables' reader too
    hidden = tmp_path / "run_gz.csv"
    hidden.write_bytes(packed.read_bytes())
    dims = {"time": "time", "friction": "dimensionless"}
    ignore = [c for c in frame.columns if c not in dims]
    ta = read_table(plain, dims, required=["time", "friction"], ignore=ignore)
    tb = read_table(hidden, dims, required=["time", "friction"], ignore=ignore)
    np.testing.assert_array_equal(ta["friction"], tb["friction"])
    np.testing.assert_array_equal(ta.rows, tb.rows)
    # protocols
    protocol = tmp_path / "p.csv.gz"
    protocol.write_bytes(gzip.compress(b"time [ms],velocity [um/s]\n0,1\n2000,10\n5000,0\n"))
    read = protocols.read_protocol(protocol)
    np.testing.assert_allclose(read.velocities, [1e-6, 1e-5], rtol=1e-12)
    np.testing.assert_allclose(read.boundaries, [0.0, 2.0, 5.0], rtol=1e-12)
    # the command line fits it (exit 0), and the fit is that of the plain file
    code, out, err = run_cli(capsys, "rsf", "fit", str(packed), "--json")
    assert code == 0, err
    code2, out2, _ = run_cli(capsys, "rsf", "fit", str(plain), "--json")
    assert code2 == 0
    fitted, again = json.loads(out)["parameters"], json.loads(out2)["parameters"]
    for name in ("a", "b", "dc"):
        assert fitted[name]["value"] == pytest.approx(again[name]["value"], rel=1e-9)
        assert fitted[name]["value"] == pytest.approx(TRUTH[name], rel=0.05)


def test_a_broken_gzip_file_is_one_line(tmp_path, capsys):
    path = tmp_path / "cut.csv.gz"
    path.write_bytes(gzip.compress(b"time,displacement,friction\n" + b"0,0,0.6\n" * 200)[:-30])
    with pytest.raises(DataError, match=r"cut.csv.gz: a gzip file that does not decompress"):
        read_record(path)
    code, _, err = run_cli(capsys, "rsf", "fit", str(path))
    assert code == 2 and err.count("\n") == 1 and "gzip" in err


# ---------------------------------------------------------------- R3: the row that is out of place


def test_a_huge_time_is_named_at_its_own_row(tmp_path):
    """'time 1e300' on line 7 was blamed on line 8 ("row 8: time 0.5 s does not increase")."""
    rows = [f"{0.1 * k:.1f},{1e-7 * k:g},0.6" for k in range(30)]
    rows[4] = "1e300,4e-07,0.6"  # line 6 of the file (a comment, the header)
    path = tmp_path / "huge.csv"
    path.write_text("# a run\ntime,displacement,friction\n" + "\n".join(rows) + "\n")
    with pytest.raises(DataError, match=r"huge.csv: row 7: time 1e\+300 s is beyond 1e\+100 s"):
        read_record(path)


def test_one_time_out_of_order_is_named_with_its_neighbours(tmp_path):
    rows = [f"{0.1 * k:.1f},{1e-7 * k:g},0.6" for k in range(30)]
    rows[10] = "55,1e-06,0.6"  # line 12: 55 s between 0.9 s and 1.1 s
    path = tmp_path / "odd.csv"
    path.write_text("time,displacement,friction\n" + "\n".join(rows) + "\n")
    with pytest.raises(DataError, match=r"row 12: time 55 s is out of order \(row 11: 0.9 s, row 13: 1.1 s\)"):
        read_record(path)
    rows[10] = "0.9,1e-06,0.6"  # a repeated time: that row does not increase
    path.write_text("time,displacement,friction\n" + "\n".join(rows) + "\n")
    with pytest.raises(DataError, match=r"row 12: time 0.9 s does not increase \(row 11: 0.9 s\)"):
        read_record(path)


# ---------------------------------------------------------------- R4: protocol rows as written


@pytest.mark.parametrize(
    ("body", "said"),
    [
        ("100,1\n,1\n", r"row 3: expected two finite numbers \(velocity \[um/s\], duration \[s\]\); velocity \[um/s\]:"
                        r" empty cell \(the row reads ',1'\)"),
        ("100,inf\n", r"row 2: .*duration \[s\]: 'inf' is not a finite number \(the row reads '100,inf'\)"),
        ("100,1\n-5,1\n", r"row 3: segment velocity: expected a value >= 0, got -5 um/s"),
    ],
)  # fmt: skip
def test_a_bad_protocol_row_is_quoted_as_written(tmp_path, body, said):
    """'expected two finite numbers in SI units, got [100.0, inf]' for a row written '100,inf' in um/s and s; an
    empty cell was shown as nan."""
    path = tmp_path / "p.csv"
    path.write_text("velocity [um/s],duration [s]\n" + body)
    with pytest.raises(DataError, match=said):
        protocols.read_protocol(path)


def test_a_protocol_time_that_does_not_increase_is_said_in_its_unit(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("time [ms],velocity [um/s]\n0,100\n500,200\n400,50\n900,0\n")
    with pytest.raises(DataError, match=r"row 4: time 400 ms does not increase \(previous 500 ms\)"):
        protocols.read_protocol(path)
