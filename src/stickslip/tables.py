"""Reading measurement tables: CSV with a header, units in brackets.

``velocity [um/s],stress [Pa],stress_err [Pa]`` -- a bare column name means SI.
Every problem is a :class:`~stickslip.errors.DataError` naming the file, the
row (1-based, counting the header as row 1) and the column.
"""

from __future__ import annotations

import csv
import functools
import math
import re
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import DataError, UnitError
from .fileio import protect_inputs
from .units import to_si


def split_header(cell: str, parentheses: bool = False) -> tuple[str, str | None]:
    """``"name [unit]"`` -> (``"name"``, ``"unit"``); a header without brackets has no unit (None).  With
    ``parentheses`` ``"name (unit)"`` too (spreadsheets' and lab software's way; where a bracketed word may be no
    unit, "Displ (LVDT 2)", the caller leaves it off)."""
    text = cell.strip()
    for opening, closing in (("[", "]"), ("(", ")")) if parentheses else (("[", "]"),):
        if text.endswith(closing) and opening in text:
            name, _, unit = text[:-1].rpartition(opening)
            if name.strip():
                return name.strip(), unit.strip()
    return text, None


#: a column name (its unit, in brackets or in parentheses, is split off by :func:`split_header`)
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
#: a name of several words ("Shear stress", "Load-cell force"): readable, but no column name of the package
_WORDS = re.compile(r"[A-Za-z_][A-Za-z0-9_ .\-/]*[A-Za-z0-9_]")


def header_names(path: str | Path) -> list[str]:
    """Column names of a CSV's header (its first line that is no comment); [] if it cannot be read."""
    try:
        delimiter = delimiter_of(Path(path))
        with open(path, encoding="utf-8-sig", errors="replace") as handle:
            for line in handle:
                if line.strip() and not line.lstrip().startswith("#"):
                    return [split_header(cell, parentheses=True)[0] for cell in line.strip().split(delimiter)]
    except (OSError, DataError):  # (DataError: commas that may be decimal marks or thousands separators)
        pass
    return []


def _header_cell(cell: str) -> tuple[str, str | None] | None:
    """(name, unit or None) of a header cell, ``name [unit]`` as the package writes it or ``name (unit)`` as
    spreadsheets and lab software do; None when the name is no identifier."""
    name, unit = split_header(cell, parentheses=True)
    return (name, unit) if _NAME.fullmatch(name) else None


@dataclass(frozen=True)
class Table:
    """Columns as SI float arrays (NaN where a cell was empty and allowed to be)."""

    source: str
    columns: dict[str, np.ndarray]
    rows: np.ndarray  # file row number of each data row (header is row 1)
    ignored: tuple[str, ...] = ()  # known columns present in the file and not read
    #: each read column's unit as its header names it (or its SI unit) and that unit's SI factor: messages give a
    #: value as the file wrote it
    written: Mapping[str, tuple[str, float]] = field(default_factory=dict)
    notes: tuple[str, ...] = ()  # how the file was read where it is not the usual way (decimal commas)

    def as_written(self, name: str, value: float) -> str:
        """``value`` (SI) of column ``name`` as the file wrote it, with its unit: "-20 um/s"."""
        # read_table names every column it reads; a Table built by hand holds SI (tables sits below columns, whose
        # registry of units would make an import loop)
        unit, factor = self.written.get(name, ("", 1.0))
        number = value / factor if factor else value
        return f"{number:.10g} {unit}".rstrip()

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def __contains__(self, name: object) -> bool:
        return name in self.columns

    def __len__(self) -> int:
        return int(self.rows.size)


#: the name of an empty header cell at the end of the header (a spreadsheet's "a;b;;")
_EMPTY_COLUMN = "(empty column "


@dataclass(frozen=True)
class _Header:
    row: int  # file row of the header (1-based)
    names: list[str]  # every column, in file order
    factors: dict[str, float]  # SI factor of each column that is read
    units: dict[str, str]  # the unit each read column's header names ("" for a bare name: SI)


def read_table(
    path: str | Path,
    dimensions: Mapping[str, str],
    required: Sequence[str],
    allow_missing: Sequence[str] = (),
    ignore: Sequence[str] = (),
) -> Table:
    """Read a CSV file whose columns are named in ``dimensions`` (name -> dimension).

    Columns in ``required`` must be present; others in ``dimensions`` are
    optional; columns named in ``ignore`` are known but not read (listed in
    ``Table.ignored``); any other column is an error.  Empty or NaN cells are
    errors except in columns listed in ``allow_missing`` (kept as NaN).

    Large files are parsed column-wise by pyarrow when it is installed; a file
    it cannot take as it stands (comment lines among the data, a bad cell) is
    read row by row, which names the first offending row and column.
    """
    path = Path(path)
    protect_inputs([path])  # in a command, no output may replace what was read
    source = str(path)
    header = _read_header(path, source, dimensions, required, ignore)
    fast = _read_columnar(path, header, allow_missing)
    if fast is not None:
        columns, rows = fast
    else:
        columns, rows = _read_rows(path, source, header, allow_missing)
    ignored = tuple(n for n in header.names if n not in header.factors and not n.startswith(_EMPTY_COLUMN))
    written = {n: (header.units[n] or _si_unit(dimensions[n]), header.factors[n]) for n in header.factors}
    note = text_format(path).note
    return Table(source, columns, rows, ignored, written, (note,) if note else ())


def read_text_cells(path: str | Path, names: Sequence[str], count: int | None = None) -> dict[str, np.ndarray]:
    """Raw text of the named columns, one entry per data row as :func:`read_table` numbers them.

    ``count``, the number of data rows :func:`read_table` found, guards the columnar path: a file it
    reads differently (a row of empty cells, which the row reader skips) is read row by row.
    """
    path = Path(path)
    rows = _content_rows(path, str(path))
    first = next(rows, None)
    rows.close()
    if first is None:
        return {n: np.empty(0, dtype=object) for n in names}
    header_row, header = first
    positions = [_header_position(header, n) for n in names]
    columnar = _text_columns(path, header_row, len(header), positions)
    if columnar is not None and (count is None or all(c.size == count for c in columnar)):
        return dict(zip(names, columnar, strict=True))
    cells: list[list[str]] = [[] for _ in names]
    for row_number, row in _content_rows(path, str(path)):
        if row_number > header_row:
            for values, k in zip(cells, positions, strict=True):
                values.append(row[k].strip() if k < len(row) else "")
    return {n: np.asarray(v, dtype=object) for n, v in zip(names, cells, strict=True)}


def _text_columns(path: Path, header_row: int, width: int, positions: list[int]) -> list[np.ndarray] | None:
    try:
        import pyarrow as pa
        import pyarrow.csv as pacsv
    except ImportError:  # pragma: no cover - pyarrow is a dependency
        return None
    labels = [f"c{k}" for k in range(width)]
    try:
        table = pacsv.read_csv(
            path,
            read_options=pacsv.ReadOptions(skip_rows=header_row, column_names=labels),
            parse_options=pacsv.ParseOptions(delimiter=delimiter_of(path)),
            convert_options=pacsv.ConvertOptions(
                include_columns=[labels[k] for k in positions],
                column_types={labels[k]: pa.string() for k in positions},
                strings_can_be_null=False,
            ),
        )
    except (pa.ArrowException, OSError, ValueError):
        return None
    return [np.char.strip(table.column(labels[k]).to_numpy(zero_copy_only=False).astype(str)) for k in positions]


def _header_position(header: list[str], name: str) -> int:
    for k, cell in enumerate(header):
        found = _header_cell(cell)
        if found and found[0] == name:
            return k
    raise KeyError(name)


#: how the format's separator is named in its note
_SEPARATOR_NAMES = {";": "';'", "\t": "tab", " ": "blank"}
#: a comma that no thousands separator writes: one or two digits, or four and more, after it, or a leading "0,"
_NO_GROUPING = re.compile(rb"\d,\d{1,2}(?!\d)|\d,\d{4}|(?<![\d,.])0,\d")
#: a decimal point in a number (a dot followed by a digit: "0.5", ".5"; "n.a." is none)
_DECIMAL_POINT = re.compile(rb"\.\d")
_COMMENT_LINE = re.compile(rb"(?m)^[ \t]*#[^\n]*")


@dataclass(frozen=True)
class TextFormat:
    """How a delimited text file writes its table: the cell separator (``" "``: runs of blanks) and the decimal
    mark, decided once by :func:`text_format` for every reader of the package (measurement tables, stress records,
    lab records), and the one-line note a reader adds where the numbers are read otherwise than with a point."""

    delimiter: str = ","
    decimal: str = "."
    note: str = ""

    def number(self, text: str) -> float:
        """A cell's number (ValueError when it is none): ``0,5`` is 0.5 in a decimal-comma file."""
        return float(text.replace(",", ".") if self.decimal == "," and "." not in text else text)

    def hint(self, cell: str) -> str:
        """What a cell that is no number may be, as "; ..." after "is not a number" ("" when nothing is known)."""
        if "," not in cell:
            return ""
        if "." in cell:
            return "; thousands separators? expected plain numbers with one decimal mark (1234.5)"
        if self.decimal == ",":
            return "; expected one decimal comma per number (0,5)"
        if self.delimiter == ",":
            return (
                "; a decimal comma? in a comma-separated file a comma cannot be a decimal mark: expected numbers with"
                " a decimal point (0.5, not 0,5), or the columns separated by ';'"
            )
        return (
            "; a decimal comma? the file's other numbers have decimal points: expected one decimal mark throughout"
            " (0.5, not 0,5)"
        )


def text_format(path: str | Path) -> TextFormat:
    """The separator and decimal mark of a delimited text file: the one decision every reader shares.

    The separator is the header's (its first line that is no ``#`` comment): a tab where it has one, else ';'
    where it has more semicolons than commas, else ',' where it has a comma, else blanks where it holds several
    names; a header of one name takes the data's the same way.  With ';', a tab or blanks between the cells, data
    whose numbers hold commas and no decimal point anywhere (the European spreadsheet's and DAQ's export) have
    decimal commas, said in :attr:`TextFormat.note`.  Where every such comma could as well separate thousands
    (``1,000`` and never ``0,5`` or ``12,25``) the file is refused here (DataError naming the row).  A comma
    among decimal points, or in a comma-separated file, is refused by the reader at its cell, with
    :meth:`TextFormat.hint`.  Read once per file (cached while it is unchanged).
    """
    path = Path(path)
    try:
        info = path.stat()
    except OSError:
        return TextFormat()
    return _text_format(str(path), info.st_mtime_ns, info.st_size)


@functools.lru_cache(maxsize=16)
def _text_format(path: str, mtime: int, size: int) -> TextFormat:
    try:
        with open(path, "rb") as handle:
            head = handle.read(1 << 20)
            found = _header_line(head)
            if found is None:
                return TextFormat()
            header_row, end, header = found
            delimiter = _separator(header, head[end : end + 65536].decode("utf-8", "replace"))
            if delimiter == ",":  # a comma is the separator, never a decimal mark: the rest need not be read
                return TextFormat(delimiter)
            data = head[end:] + handle.read()
    except OSError:
        return TextFormat()
    if b"," not in data:
        return TextFormat(delimiter)
    if b"#" in data:  # comment lines among the data hold no cells (blanked, their line ends kept for the rows)
        data = _COMMENT_LINE.sub(b"", data)
    first = re.search(rb"\d,\d", data)
    if first is None or _DECIMAL_POINT.search(data):
        return TextFormat(delimiter)  # commas in text cells only, or decimal points: no comma is a decimal mark
    if not _NO_GROUPING.search(data):
        row = header_row + 1 + data[: first.start()].count(b"\n")
        line_start = data.rfind(b"\n", 0, first.start()) + 1
        cell = re.search(rb"[-+\d,]*\d,\d+", data[line_start : first.end() + 40])
        text = cell.group(0).decode() if cell else "1,000"
        raise DataError(
            f"{path}: row {row}: {text!r}: a decimal comma or a thousands separator? every comma in the file's"
            " numbers stands before three digits; expected numbers with one decimal mark and no thousands"
            " separators (1000, 1000.0 or 1000,0)"
        )
    name = _SEPARATOR_NAMES[delimiter]
    return TextFormat(
        delimiter,
        ",",
        f"{path}: {name}-separated with decimal commas (no decimal point in its numbers): 0,5 read as 0.5",
    )


def _header_line(head: bytes) -> tuple[int, int, str] | None:
    """(file row, end offset, text) of the header: the first line of ``head`` that is neither blank nor a ``#``
    comment (a byte-order mark before it skipped); None without one."""
    position = 3 if head.startswith(b"\xef\xbb\xbf") else 0
    row = 0
    while position < len(head):
        row += 1
        end = head.find(b"\n", position)
        end = len(head) if end < 0 else end + 1
        line = head[position:end]
        if line.strip() and not line.lstrip().startswith(b"#"):
            return row, end, line.decode("utf-8", "replace")
        position = end
    return None


def _separator(header: str, data: str) -> str:
    """The cell separator a header names (see :func:`text_format`); the data's where it names none."""
    for text in (header, data):
        if "\t" in text:
            return "\t"
        if text.count(";") > text.count(","):
            return ";"
        if "," in text:
            return ","
        if len(text.split()) > 1:  # names between blanks ("time disp mu"): the data's commas are decimal marks
            return " "
    return " "


def delimiter_of(path: Path) -> str:
    """The cell separator of a measurement table (:func:`text_format`'s; a table of blank-separated cells is read
    as comma-separated, its header one cell that the reader names)."""
    delimiter = text_format(path).delimiter
    return "," if delimiter == " " else delimiter


def _content_rows(path: Path, source: str) -> Iterator[tuple[int, list[str]]]:
    """(file row, cells) of every row that is not blank and not a '#' comment, streamed."""
    delimiter = delimiter_of(path)
    try:
        with path.open(newline="", encoding="utf-8-sig") as handle:
            for k, row in enumerate(csv.reader(handle, delimiter=delimiter), start=1):
                if row and any(c.strip() for c in row) and not row[0].lstrip().startswith("#"):
                    yield k, row
    except FileNotFoundError:
        raise DataError(f"{source}: file not found") from None
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise DataError(f"{source}: cannot be read as CSV ({exc})") from None


def _read_header(
    path: Path, source: str, dimensions: Mapping[str, str], required: Sequence[str], ignore: Sequence[str]
) -> _Header:
    rows = _content_rows(path, source)
    first = next(rows, None)
    rows.close()
    if first is None:
        raise DataError(f"{source}: empty file, expected a header row with columns {', '.join(required)}")
    header_row, header = first
    if header[0].lstrip().startswith(("{", "[")):  # `curve --format json`, `--json` output: not a table
        raise DataError(
            f"{source}: row {header_row} starts with {header[0].lstrip()[0]!r}: a JSON file, not a CSV table;"
            f" expected a header row with columns {', '.join(required)} (write the table as CSV, e.g. --format csv)"
        )
    names: list[str] = []
    factors: dict[str, float] = {}
    units: dict[str, str] = {}
    named = len(header)
    while named > 1 and not header[named - 1].strip():  # a spreadsheet's empty columns at the end ("a;b;;")
        named -= 1
    for position, cell in enumerate(header, start=1):
        if position > named:
            names.append(f"{_EMPTY_COLUMN}{position})")  # never read, never named as ignored
            continue
        found = _header_cell(cell)
        if found is None and _WORDS.fullmatch(split_header(cell, parentheses=True)[0]):
            # a readable header whose name is no column of ours ("Shear stress (kPa)"): say so, not "cannot read"
            raise DataError(
                f"{source}: row {header_row}, column {position}: unknown column"
                f" {split_header(cell, parentheses=True)[0]!r} (header {cell.strip()!r}); expected"
                f" {', '.join(dimensions)}"
            )
        if found is None:
            raise DataError(
                f"{source}: row {header_row}, column {position}: cannot read header {cell!r};"
                " expected name, 'name [unit]' or 'name (unit)'"
            )
        name, unit = found
        if name not in dimensions and name not in ignore and (name.lower() in dimensions or name.lower() in ignore):
            name = name.lower()  # "Velocity [um/s]", as spreadsheets capitalise headers
        if name not in dimensions and name not in ignore:
            raise DataError(f"{source}: unknown column {name!r}; expected {', '.join(dimensions)}")
        if name in names:
            raise DataError(f"{source}: column {name!r} appears twice")
        names.append(name)
        if name not in dimensions:
            continue
        try:
            factor = _unit_factor(unit, dimensions[name], name)
        except UnitError as exc:
            raise DataError(f"{source}: {exc}") from None
        factors[name] = factor
        units[name] = (unit or "").strip()
    missing = [c for c in required if c not in factors]
    if missing:
        raise DataError(f"{source}: missing column(s) {', '.join(missing)}; found {', '.join(names)}")
    return _Header(header_row, names, factors, units)


def _si_unit(dimension: str) -> str:
    """The SI unit a bare column name means ("" for a pure number)."""
    from .units import DIMENSIONS

    return DIMENSIONS[dimension][1] if dimension in DIMENSIONS else ""


def _unit_factor(unit: str | None, dimension: str, name: str) -> float:
    """SI factor of a header's unit; ``[1]`` (and an empty bracket) mark a pure number, as the package writes it."""
    text = (unit or "").strip()
    if not text or (text == "1" and dimension == "dimensionless"):
        return 1.0
    return to_si(f"1 {text}", dimension, f"column {name!r}")


def _read_rows(
    path: Path, source: str, header: _Header, allow_missing: Sequence[str]
) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Row by row: slow, but names the first bad row and column exactly."""
    used = [(k, n, header.factors[n]) for k, n in enumerate(header.names) if n in header.factors]
    form = text_format(path)
    values: dict[str, list[float]] = {n: [] for _, n, _ in used}
    rows = []
    for row_number, row in _content_rows(path, source):
        if row_number <= header.row:
            continue
        if len(row) != len(header.names):
            raise DataError(f"{source}: row {row_number}: expected {len(header.names)} values, got {len(row)}")
        for position, name, factor in used:
            cell = row[position]
            text = cell.strip()
            try:
                value = form.number(text) if text else math.nan
            except ValueError:
                raise DataError(
                    f"{source}: row {row_number}, column {name!r}: {cell!r} is not a number{form.hint(text)}"
                ) from None
            if math.isnan(value) and name not in allow_missing:
                raise DataError(f"{source}: row {row_number}, column {name!r}: missing or NaN value")
            if math.isinf(value):
                raise DataError(f"{source}: row {row_number}, column {name!r}: infinite value")
            values[name].append(value * factor)
        rows.append(row_number)
    return {n: np.asarray(v, dtype=float) for n, v in values.items()}, np.asarray(rows, dtype=int)


def _read_columnar(
    path: Path, header: _Header, allow_missing: Sequence[str]
) -> tuple[dict[str, np.ndarray], np.ndarray] | None:
    """The columns parsed by pyarrow, or None when the file needs the row-by-row reader (or for its message)."""
    try:
        import pyarrow as pa
        import pyarrow.csv as pacsv
    except ImportError:  # pragma: no cover - pyarrow is a dependency; the row reader still works without it
        return None
    used = list(header.factors)
    form = text_format(path)
    try:
        table = pacsv.read_csv(
            path,
            read_options=pacsv.ReadOptions(skip_rows=header.row, column_names=header.names),
            parse_options=pacsv.ParseOptions(ignore_empty_lines=True, delimiter=delimiter_of(path)),
            convert_options=pacsv.ConvertOptions(
                decimal_point=form.decimal,
                include_columns=used,
                column_types={n: pa.float64() for n in used},
                null_values=[""],
                strings_can_be_null=False,
            ),
        )
    except (pa.ArrowException, OSError, ValueError):
        return None
    columns = {}
    for name in used:
        column = table.column(name).to_numpy()
        if (name not in allow_missing and np.isnan(column).any()) or np.isinf(column).any():
            return None  # the row reader names the row
        factor = header.factors[name]
        columns[name] = column * factor if factor != 1.0 else np.array(column, dtype=float)
    del table
    rows = _data_rows(path, header.row, len(next(iter(columns.values()))) if columns else 0)
    return None if rows is None else (columns, rows)


#: Bytes read at a time when numbering the rows of a large file.
_CHUNK = 1 << 24


def _data_rows(path: Path, header_row: int, count: int) -> np.ndarray | None:
    """File row numbers of the ``count`` data rows after the header (empty lines skipped), or None if they
    cannot be matched line for line (e.g. a quoted cell spanning lines)."""
    lines = 0
    ends_open = False
    with path.open("rb") as handle:
        while chunk := handle.read(_CHUNK):
            lines += chunk.count(b"\n")
            ends_open = not chunk.endswith(b"\n")
    lines += int(ends_open)
    if lines - header_row == count:
        return np.arange(header_row + 1, header_row + 1 + count)
    numbers = _non_empty_lines(path)
    numbers = numbers[numbers > header_row]
    return numbers if numbers.size == count else None


def _non_empty_lines(path: Path) -> np.ndarray:
    """1-based numbers of the lines that hold more than a line ending."""
    found: list[np.ndarray] = []
    line = 0
    carry = b""
    with path.open("rb") as handle:
        while True:
            chunk = handle.read(_CHUNK)
            data = carry + chunk
            if not chunk:
                if data.strip(b"\r"):
                    found.append(np.array([line + 1]))
                break
            raw = np.frombuffer(data, dtype=np.uint8)
            ends = np.flatnonzero(raw == 10)
            starts = np.concatenate([[0], ends[:-1] + 1])
            length = ends - starts
            empty = (length == 0) | ((length == 1) & (raw[starts] == 13))
            found.append(line + 1 + np.flatnonzero(~empty))
            line += ends.size
            carry = data[ends[-1] + 1 :] if ends.size else data
    return np.concatenate(found) if found else np.empty(0, dtype=int)
