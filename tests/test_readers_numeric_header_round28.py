"""Round 28, tester M: a header, title or units row made of numbers is never read as a data row.

The synthetic record's truth: times 10.0, 10.1, ... s (or 0.0, 0.1, ...), displacement 0.1 um per row, friction
0.6 + 0.001 sin(row); every case checks the rows read against it.
"""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.errors import DataError
from stickslip.rsf.data import read_record

N = 400
BY_NUMBER = {"time": "1", "displacement": "2", "friction": "3"}


def _truth(t0: float = 10.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    k = np.arange(N)
    return t0 + 0.1 * k, 0.1 * k, 0.6 + 0.001 * np.sin(k)


def _rows(t0: float = 10.0, sep: str = ",") -> list[str]:
    t, x, mu = _truth(t0)
    return [sep.join(f"{v:.10g}" for v in row) for row in zip(t, x, mu, strict=True)]


def _write(tmp_path, name: str, lines: list[str]):
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


def _assert_exact(record, t0: float = 10.0) -> None:
    t, x, mu = _truth(t0)
    assert len(record.time) == N
    np.testing.assert_allclose(record.time - record.time[0], t - t[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(record.displacement, x * 1e-6, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(record.friction, mu, rtol=1e-9)


def test_numeric_header_named_by_columns_is_the_header(tmp_path):
    path = _write(tmp_path, "m1.csv", ["1,2,3", *_rows()])
    record = read_record(path, columns=BY_NUMBER, displacement_unit="um")
    _assert_exact(record)  # old code: 401 rows, the first t = 1 s, x = 2 um, mu = 3
    assert any("row 1 (1, 2, 3) read as the header" in note for note in record.notes)


def test_numeric_header_over_data_from_zero_is_the_header(tmp_path):
    path = _write(tmp_path, "v07.csv", ["1,2,3", *_rows(0.0)])
    _assert_exact(read_record(path, columns=BY_NUMBER, displacement_unit="um"), 0.0)


def test_headerless_file_still_maps_by_number(tmp_path):
    path = _write(tmp_path, "v03.csv", _rows())
    record = read_record(path, columns=BY_NUMBER, displacement_unit="um")
    _assert_exact(record)
    assert not any("read as the header" in note for note in record.notes)


def test_header_whose_names_are_other_positions_is_ambiguous(tmp_path):
    path = _write(tmp_path, "swap.csv", ["2,1,3", *_rows()])
    with pytest.raises(DataError, match=r"row 1 \(2, 1, 3\) may be the header"):
        read_record(path, columns=BY_NUMBER, displacement_unit="um")


def test_numeric_title_without_header_is_refused_at_row_1(tmp_path):
    path = _write(tmp_path, "m3.csv", ["2,3,4", *_rows()])
    with pytest.raises(DataError, match=r"row 1 \(2, 3, 4\) is out of line with the data \(time 2 s, then 10 s"):
        read_record(path, columns=BY_NUMBER, displacement_unit="um")


def test_all_ones_row_under_header_is_refused_at_its_row(tmp_path):
    path = _write(tmp_path, "m4.txt", ["Time,Disp (um),Mu", "1,1,1", *_rows()])
    with pytest.raises(DataError, match=r"row 2 \(1, 1, 1\) is out of line with the data.*units row"):
        read_record(path)


def test_integer_first_row_in_line_with_the_data_is_data(tmp_path):
    rows = _rows(0.0)
    rows[0] = "0,0,1"  # whole numbers, in step with the rows after it: a sample
    record = read_record(_write(tmp_path, "ok.csv", ["time (s),disp (um),friction", *rows]))
    assert len(record.time) == N and record.friction[0] == 1.0


@pytest.mark.parametrize("titles", [["2024,05,01"], ["12,34,56"], ["1,2,3"], ["2024,05,01", "7,8,9"]])
def test_numeric_title_over_a_text_header_is_title_text(tmp_path, titles):
    path = _write(tmp_path, "v09.csv", [*titles, "time (s),disp (um),friction", *_rows()])
    record = read_record(path)
    _assert_exact(record)
    rows = "row 1" if len(titles) == 1 else "rows 1-2"
    assert any(f"{rows} before the header skipped" in note for note in record.notes)


def test_numeric_title_over_units_row(tmp_path):
    path = _write(tmp_path, "v09u.txt", ["2024\t05\t01", "Time\tLP_Disp\tMu", "s\tum\t-", *_rows(sep="\t")])
    _assert_exact(read_record(path))


@pytest.mark.parametrize("cell", ["10um", "1e-6 m"])
def test_scaled_unit_in_units_row_refused_at_its_row(tmp_path, cell):
    path = _write(tmp_path, "v08c.txt", ["Time\tLP_Disp\tMu", f"s\t{cell}\t-", *_rows(sep="\t")])
    with pytest.raises(DataError, match=rf"row 2 \(the units row\), column 'LP_Disp': '{cell}' is no unit"):
        read_record(path)


def test_cli_refuses_numeric_title_row_with_exit_2(tmp_path, capsys):
    """``rsf fit`` names row 1, not "the load point does not move" (the old, untrue cause)."""
    from stickslip.cli.main import main

    path = _write(tmp_path, "m3.csv", ["2,3,4", *_rows()])
    argv = ["rsf", "fit", str(path), "--columns", "time=1,displacement=2,friction=3", "--displacement-unit", "um"]
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert "row 1 (2, 3, 4) is out of line" in capsys.readouterr().err
