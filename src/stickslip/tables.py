"""Reading measurement tables: CSV with a header, units in brackets.

``velocity [um/s],stress [Pa],stress_err [Pa]`` -- a bare column name means SI.
Every problem is a :class:`~stickslip.errors.DataError` naming the file, the
row (1-based, counting the header as row 1) and the column.
"""

from __future__ import annotations

import codecs
import csv
import functools
import gzip
import io
import math
import re
import stat
import zlib
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import numpy as np

from .errors import DataError, UnitError
from .fileio import protect_inputs
from .units import shorten, to_si


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
    """Column names of a CSV's header (:class:`Layout`'s header row: its first line that is no comment, or the
    line after its title lines); [] if it cannot be read or has none."""
    try:
        form = text_format(Path(path))
        delimiter = "," if form.delimiter == " " else form.delimiter
        if form.layout.commented:  # the header is the comment before the data
            return [split_header(cell, parentheses=True)[0] for cell in form.layout.commented]
        with open_input(path, "rt", encoding="utf-8-sig", errors="replace") as handle:
            for row, line in enumerate(handle, start=1):
                if form.layout.header_row is None:
                    return []
                if line.strip() and not line.lstrip().startswith("#") and row >= form.layout.header_row:
                    return [split_header(cell, parentheses=True)[0] for cell in line.strip().split(delimiter)]
    except (OSError, EOFError, zlib.error, DataError):  # (DataError: commas that may be decimal marks or
        pass  # thousands separators)
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
    data_after: int = 0  # the last file row that is no data (the header, or the units row under it)


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
    form = text_format(path)
    notes = tuple(n for n in (text_encoding(path).note, form.layout.note(source), form.note) if n)
    return Table(source, columns, rows, ignored, written, notes)


def read_text_cells(path: str | Path, names: Sequence[str], count: int | None = None) -> dict[str, np.ndarray]:
    """Raw text of the named columns, one entry per data row as :func:`read_table` numbers them.

    ``count``, the number of data rows :func:`read_table` found, guards the columnar path: a file it
    reads differently (a row of empty cells, which the row reader skips) is read row by row.
    """
    path = Path(path)
    first = _header_row(path, str(path))
    if first is None:
        return {n: np.empty(0, dtype=object) for n in names}
    header_row, header = first
    after = max(header_row, text_format(path).layout.data_after)
    positions = [_header_position(header, n) for n in names]
    columnar = _text_columns(path, after, len(header), positions)
    if columnar is not None and (count is None or all(c.size == count for c in columnar)):
        return dict(zip(names, columnar, strict=True))
    cells: list[list[str]] = [[] for _ in names]
    for row_number, row in _content_rows(path, str(path)):
        if row_number > after:
            for values, k in zip(cells, positions, strict=True):
                values.append(row[k].strip() if k < len(row) else "")
    return {n: np.asarray(v, dtype=object) for n, v in zip(names, cells, strict=True)}


def _text_columns(path: Path, data_after: int, width: int, positions: list[int]) -> list[np.ndarray] | None:
    try:
        import pyarrow as pa
        import pyarrow.csv as pacsv
    except ImportError:  # pragma: no cover - pyarrow is a dependency
        return None
    labels = [f"c{k}" for k in range(width)]
    try:
        with _arrow_input(path) as stream:
            table = pacsv.read_csv(
                stream,
                read_options=pacsv.ReadOptions(skip_rows=data_after, column_names=labels),
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
    #: where the table starts: title lines, the header, a units row (:class:`Layout`)
    layout: Layout = field(default_factory=lambda: Layout())

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
    """The separator, decimal mark and layout of a delimited text file: the one decision every reader shares.

    Where the table starts (title lines before the header, a units row under it, no header row): :class:`Layout`,
    in :attr:`TextFormat.layout`.  The separator is the header's (its first line that is no ``#`` comment, or the
    line :class:`Layout` finds after title lines; the data's where there is no header row): a tab where it has
    one, else ';' where it has more semicolons than commas, else ',' where it has a comma, else blanks where it
    holds several names; a header of one name takes the data's the same way.  With ';', a tab or blanks between
    the cells, data whose numbers hold commas and no decimal point anywhere (the European spreadsheet's and DAQ's
    export) have decimal commas, said in :attr:`TextFormat.note`.  Where every such comma could as well separate
    thousands (``1,000`` and never ``0,5`` or ``12,25``) the file is refused here (DataError naming the row).  A
    comma among decimal points, or in a comma-separated file, is refused by the reader at its cell, with
    :meth:`TextFormat.hint`.  Read once per file (cached while it is unchanged); a gzip file decompressed.
    """
    path = Path(path)
    try:
        info = path.stat()
    except OSError:
        return TextFormat()
    if not stat.S_ISREG(info.st_mode):  # a pipe is read once, by the reader (which refuses it): never opened here
        return TextFormat()
    return _text_format(str(path), info.st_mtime_ns, info.st_size)


@functools.lru_cache(maxsize=16)
def _text_format(path: str, mtime: int, size: int) -> TextFormat:
    try:
        with open_input(path, "rb") as handle:
            head = handle.read(1 << 20)
            found = _header_line(head, complete=len(head) < 1 << 20)
            if found is None:
                return TextFormat()
            layout, end, header, data_separator = found
            sample = head[end : end + 65536].decode("utf-8", "replace")
            delimiter = data_separator or _separator(header, sample)
            if delimiter == ",":  # a comma is the separator, never a decimal mark: the rest need not be read
                return TextFormat(delimiter, layout=layout)
            data = head[end:] + handle.read()
    except (OSError, EOFError, zlib.error):
        return TextFormat()
    if b"," not in data:
        return TextFormat(delimiter, layout=layout)
    if b"#" in data:  # comment lines among the data hold no cells (blanked, their line ends kept for the rows)
        data = _COMMENT_LINE.sub(b"", data)
    first = re.search(rb"\d,\d", data)
    if first is None or _DECIMAL_POINT.search(data):
        return TextFormat(delimiter, layout=layout)  # commas in text cells only, or decimal points: no decimal comma
    if not _NO_GROUPING.search(data):
        row = layout.data_after + 1 + data[: first.start()].count(b"\n")
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
        layout,
    )


#: the lines (neither blank nor ``#`` comments) :func:`text_format` reads to find where a table starts
_LAYOUT_LINES = 200
#: cells a reader takes as a missing value (pandas' words), neither a number nor a name
_MISSING_WORDS = frozenset({"nan", "-nan", "na", "n/a", "#n/a", "null", "none", "inf", "-inf", "+inf", "infinity"})
#: at most this many rows of numbers above a header are read as title text ("2024,05,01"), not as data
_NUMERIC_TITLES = 3
#: a units row's cell that names no unit: a pure number, or nothing
_NO_UNIT = frozenset({"", "-", "--", "1", "()", "[]", "(-)", "[-]", "(1)", "[1]"})
#: the dimensions a units row's words are read in (a friction record's or a measurement table's columns, and the
#: load, temperature and rate columns lab exports hold beside them)
_ROW_UNIT_DIMENSIONS = ("time", "length", "velocity", "stress", "force", "temperature", "rate")


@dataclass(frozen=True)
class Layout:
    """Where a delimited text file's table starts, decided once by :func:`text_format` for every reader.

    The usual file has its header on its first line that is neither blank nor a ``#`` comment and its data from
    the next.  Lab software also writes free text before the header (a title line: "Experiment p1234
    2024-05-01"), a row of units under it (``ms  mm  -``, as xlook and LabVIEW exports do), or no header at all
    (its names only in a ``#`` comment, or nowhere).  The first data row is the first line whose cells are
    numbers where the data's are (the data: the last line of the file's first 200); the header is the line
    before it, or the line before that where that one is a row of unit words; the lines before the header are
    titles.  A header must name as many columns as the data has cells, none of them a number; where no such
    line is found the first line is the header, as usual (the reader then names what is wrong with it).
    """

    #: file row (1-based) of the header; None: the file has no header row (its first row holds numbers); 0: the
    #: file has no table (no line that is neither blank nor a comment)
    header_row: int | None = 0
    #: file row of the units row under the header, and its cells (as written, brackets taken off; "" for none)
    units_row: int | None = None
    units: tuple[str, ...] = ()
    #: file rows of free text before the header
    title_rows: tuple[int, ...] = ()
    #: file row of the first data row (0 when not known)
    first_data_row: int = 0
    #: the header's cells where it is a ``#`` comment just before the data (``# time(ms) disp(mm) mu``): the
    #: file has no other header row; ``header_row`` is the comment's row
    commented: tuple[str, ...] = ()

    @property
    def data_after(self) -> int:
        """The last file row that is no data: the units row, else the header, else the last title (0 for none)."""
        return max(self.units_row or 0, self.header_row or 0, *self.title_rows, 0)

    def unit(self, position: int) -> str | None:
        """The unit the units row gives the column at ``position`` (0-based); None where it names none."""
        if position >= len(self.units):
            return None
        cell = self.units[position]
        return None if cell in _NO_UNIT else cell

    def note(self, source: str) -> str:
        """What a reader says it did where the layout is not the usual one ("" where it is)."""
        parts = []
        if self.title_rows:
            rows = _row_span(self.title_rows)
            parts.append(f"{rows} before the header skipped (free text)")
        if self.units_row is not None:
            parts.append(f"row {self.units_row} read as the columns' units ({', '.join(c or '-' for c in self.units)})")
        if self.commented:
            parts.append(f"the header read from the comment on row {self.header_row}: {', '.join(self.commented)}")
        if self.header_row is None:
            parts.append(f"no header row (row {self.first_data_row} holds numbers): the columns are numbered from 1")
        return f"{source}: {'; '.join(parts)}" if parts else ""


def _row_span(rows: Sequence[int]) -> str:
    return f"row {rows[0]}" if len(rows) == 1 else f"rows {rows[0]}-{rows[-1]}"


def _content_lines(head: bytes, complete: bool) -> list[tuple[int, int, int, str]]:
    """(file row, start offset, end offset, text) of the first :data:`_LAYOUT_LINES` lines of ``head`` that are
    neither blank nor a ``#`` comment (a byte-order mark skipped); a last line cut off by the end of ``head`` (not
    ``complete``: the file goes on) is left out."""
    position = 3 if head.startswith(b"\xef\xbb\xbf") else 0
    row = 0
    found = []
    while position < len(head) and len(found) < _LAYOUT_LINES:
        row += 1
        end = head.find(b"\n", position)
        if end < 0 and not complete and found:
            break
        end = len(head) if end < 0 else end + 1
        line = head[position:end]
        if line.strip() and not line.lstrip().startswith(b"#"):
            found.append((row, position, end, line.decode("utf-8", "replace").rstrip("\r\n")))
        position = end
    return found


def _cells(text: str, separator: str) -> list[str]:
    """A line's cells split at ``separator`` (quotes as a CSV reader reads them; " ": runs of blanks)."""
    if separator == " ":
        return text.split()
    try:
        return next(csv.reader([text], delimiter=separator))
    except (csv.Error, StopIteration):
        return text.split(separator)


def _kind(cell: str) -> str:
    """ "number" (a missing-value word too: NaN, n/a), "empty" or "text"."""
    text = cell.strip()
    if not text:
        return "empty"
    if text.lower() in _MISSING_WORDS:
        return "number"
    for candidate in (text, text.replace(",", ".", 1)):
        try:
            float(candidate)
            return "number"
        except ValueError:
            pass
    return "text"


def _data_separator(text: str) -> str:
    """The separator of a data line: the first of tab, ';', ',' and blanks that splits it into numbers only (a
    decimal comma read as a mark), else :func:`_separator`'s reading of it (a text column among the numbers)."""
    for separator in ("\t", ";", ",", " "):
        cells = _cells(text, separator)
        kinds = [_kind(c) for c in cells]
        if len(cells) > 1 and "text" not in kinds and "number" in kinds:
            return separator
    return _separator(text, "")


def _header_cells(text: str, separator: str) -> list[str]:
    """A header's cells: between blanks, a bracketed unit kept with its name ("time [s]" is one column)."""
    if separator == " ":
        return re.findall(r"[^\s\[\(]+(?:\s*[\[\(][^\]\)]*[\]\)])?|[\[\(][^\]\)]*[\]\)]", text)
    return _cells(text, separator)


def _unit_cell(cell: str) -> str | None:
    """A units row's cell, brackets taken off: "" for none ("-", "1", empty), the unit where it names a time,
    length, speed, stress, force, temperature or rate ("ms", "(um)", "[MPa]", "N"); None where it is no unit (a
    name, a number; a one-letter word other than s, m, N and K: pint's "a" is a year, "t" a tonne)."""
    text = cell.strip()
    if text in _NO_UNIT:
        return ""
    if len(text) > 2 and text[0] + text[-1] in ("()", "[]"):
        text = text[1:-1].strip()
    if text in _NO_UNIT:
        return ""
    if _kind(text) != "text" or (len(text) == 1 and text not in "smNK"):
        return None
    from .units import to_si

    for dimension in _ROW_UNIT_DIMENSIONS:
        try:
            to_si(f"1 {text}", dimension, "unit")
            return text
        except (UnitError, ValueError, TypeError):
            continue
    return None


#: a units row's cell that is a number glued to a unit ("10um", "1e-6 m"): no unit a reader reads (the scale
#: belongs in the numbers); kept so that the reader refuses it at its row instead of taking the row as the header
SCALED_UNIT = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?\s*[A-Za-zµμ][\w/^]*")


def _row_unit(cell: str) -> str | None:
    """:func:`_unit_cell`, or a number glued to a unit as written (:data:`SCALED_UNIT`)."""
    unit = _unit_cell(cell)
    return cell.strip() if unit is None and SCALED_UNIT.fullmatch(cell.strip()) else unit


def _layout(lines: list[tuple[int, int, int, str]]) -> tuple[Layout, int]:
    """The table's :class:`Layout`, and the index in ``lines`` of its header (where it has none: the number of
    cells of its data rows)."""
    if not lines:
        return Layout(), 0
    usual = Layout(header_row=lines[0][0], first_data_row=lines[1][0] if len(lines) > 1 else 0)
    if len(lines) < 2:
        return usual, 0
    reference = lines[-1][3]
    separator = _data_separator(reference)
    kinds = [_kind(c) for c in _cells(reference, separator)]
    numeric = [k for k, kind in enumerate(kinds) if kind == "number"]
    width = len(kinds)
    if not numeric:
        return usual, 0

    def data_like(text: str) -> bool:
        cells = [_kind(c) for c in _cells(text, separator)]
        return len(cells) == width and all(cells[k] != "text" for k in numeric) and "number" in cells

    first = next((k for k, line in enumerate(lines) if data_like(line[3])), None)
    if first is None or first == 1:
        return usual, 0
    fallback = usual, 0
    if first == 0:
        fallback = Layout(header_row=None, first_data_row=lines[0][0]), width
        # a title of numbers ("2024,05,01") above a header: a few numeric rows, then text, then the data
        gap = next((k for k, line in enumerate(lines) if not data_like(line[3])), None)
        if gap is None or gap > _NUMERIC_TITLES:
            return fallback
        first = next((k for k in range(gap + 1, len(lines)) if data_like(lines[k][3])), None)
        if first is None:
            return fallback

    def header_like(text: str) -> bool:
        cells = _header_cells(text, separator)
        return len(cells) == width and all(_kind(c) != "number" for c in cells) and any(c.strip() for c in cells)

    units: list[str | None] = []
    if first >= 2:
        units = [_row_unit(c) for c in _cells(lines[first - 1][3], separator)]
    if (
        len(units) == width
        and all(u is not None for u in units)
        and any(u and not SCALED_UNIT.fullmatch(u) for u in units)
        and header_like(lines[first - 2][3])
        and not all(_unit_cell(c) is not None for c in _header_cells(lines[first - 2][3], separator))
    ):
        at = first - 2
        layout = Layout(lines[at][0], lines[first - 1][0], tuple(u or "" for u in units),
                        tuple(line[0] for line in lines[:at]), lines[first][0])  # fmt: skip
        return layout, at
    if header_like(lines[first - 1][3]):
        at = first - 1
        return Layout(lines[at][0], None, (), tuple(line[0] for line in lines[:at]), lines[first][0]), at
    return fallback


def _header_line(head: bytes, complete: bool = True) -> tuple[Layout, int, str, str] | None:
    """(layout, end offset of its last row that is no data, header text, separator where there is no header row)
    of the table in ``head``; None without a line that is neither blank nor a ``#`` comment."""
    lines = _content_lines(head, complete)
    if not lines:
        return None
    layout, at = _layout(lines)
    if layout.header_row is not None:
        last = max((line for line in lines if line[0] <= layout.data_after), key=lambda line: line[0])
        return layout, last[2], lines[at][3], ""
    separator = _data_separator(lines[-1][3])
    found = _commented_header(head[: lines[0][1]], separator, width=at)
    if found is not None:  # the names in the comment just before the data
        row, cells = found
        layout = Layout(row, None, (), (), layout.first_data_row, tuple(c.strip() for c in cells))
    return layout, lines[0][1], "", separator


def _commented_header(head: bytes, separator: str, width: int) -> tuple[int, list[str]] | None:
    """(file row, cells) of the last ``#`` comment in ``head`` (the lines before the first data row) where it
    names ``width`` columns (``# time(ms) disp(mm) mu``: names, each with its unit or none, no number); None
    where it does not."""
    text = head[3:] if head.startswith(b"\xef\xbb\xbf") else head
    numbered = [(k, line) for k, line in enumerate(text.decode("utf-8", "replace").split("\n"), start=1)
                if line.lstrip().startswith("#")]  # fmt: skip
    if not numbered:
        return None
    row, line = numbered[-1]
    cells = _header_cells(line.lstrip()[1:].strip(), separator)
    names = [split_header(c, parentheses=True)[0] for c in cells]
    if len(cells) != width or not all(_WORDS.fullmatch(n) or _NAME.fullmatch(n) for n in names):
        return None
    return row, cells


#: a gzip file's first two bytes
GZIP_MAGIC = b"\x1f\x8b"


def is_gzip(path: str | Path) -> bool:
    """Whether ``path`` is a gzip-compressed file (by its first bytes, whatever its name), which every reader of the
    package reads decompressed (:func:`open_input`).  One that does not decompress to its end is refused here,
    once (DataError), so no reader meets a broken stream halfway."""
    try:
        info = Path(path).stat()
        if not stat.S_ISREG(info.st_mode):
            return False
        with open(path, "rb") as handle:
            if handle.read(2) != GZIP_MAGIC:
                return False
    except (OSError, ValueError):
        return False
    _check_gzip(str(path), info.st_mtime_ns, info.st_size)
    return True


@functools.lru_cache(maxsize=16)
def _check_gzip(path: str, mtime: int, size: int) -> None:
    try:
        with gzip.open(path, "rb") as handle:
            while handle.read(_CHUNK):
                pass
    except (OSError, EOFError, zlib.error) as exc:
        raise DataError(
            f"{path}: a gzip file that does not decompress ({exc}); expected a complete .gz file or plain text"
        ) from None


def open_input(path: str | Path, mode: str = "rb", **options: Any) -> IO[Any]:
    """``open(path, mode, **options)`` for reading, a gzip-compressed file (:func:`is_gzip`) decompressed: the
    one place the readers open their files.  A file that is not UTF-8 (:func:`text_encoding`: UTF-16 or UTF-32
    by its byte-order mark, 8-bit text) is read as its UTF-8 transcript (bytes), or as text whatever ``encoding``
    says; a binary file is refused (DataError)."""
    encoding = text_encoding(path)
    if encoding.transcoded:
        stream = io.BytesIO(_transcript(str(path), *_stamp(path)))
        if "b" in mode:
            return stream
        return io.TextIOWrapper(stream, encoding="utf-8", errors=options.get("errors"), newline=options.get("newline"))
    if is_gzip(path):
        return gzip.open(path, mode if "b" in mode else mode.replace("r", "rt"), **options)
    return open(path, mode, **options)


@contextmanager
def _arrow_input(path: Path) -> Iterator[Any]:
    """What pyarrow reads: the file's stream, decompressed where it is gzip (whatever its name), transcribed to
    UTF-8 where it is other text (:func:`text_encoding`)."""
    import pyarrow as pa

    if text_encoding(path).transcoded:
        yield pa.BufferReader(_transcript(str(path), *_stamp(path)))
        return
    with pa.input_stream(str(path), compression="gzip" if is_gzip(path) else None) as stream:
        yield stream


def pandas_compression(path: str | Path) -> str | None:
    """pandas' ``compression=`` for ``path``: "gzip" where it is (:func:`is_gzip`), else none (whatever its name)."""
    return "gzip" if is_gzip(path) else None


def pandas_input(path: str | Path) -> tuple[Any, str | None]:
    """What pandas' ``read_csv`` reads for ``path`` and its ``compression=``: the file (gzip or not), or its UTF-8
    transcript where it is other text (:func:`text_encoding`)."""
    if text_encoding(path).transcoded:
        return io.BytesIO(_transcript(str(path), *_stamp(path))), None
    return path, pandas_compression(path)


@dataclass(frozen=True)
class TextEncoding:
    """How a text file's bytes are characters: ``codec`` (Python's name), and the note a reader adds where that
    was a guess (8-bit text, UTF-16 without a byte-order mark)."""

    codec: str = "utf-8"
    note: str = ""

    @property
    def transcoded(self) -> bool:
        """Whether the readers read the file's UTF-8 transcript rather than its bytes."""
        return self.codec not in ("utf-8", "utf-8-sig")


#: byte-order marks and the codec each names (UTF-32's first: its little-endian mark starts with UTF-16's)
_BYTE_ORDER_MARKS = (
    (codecs.BOM_UTF32_LE, "utf-32"),
    (codecs.BOM_UTF32_BE, "utf-32"),
    (codecs.BOM_UTF16_LE, "utf-16"),
    (codecs.BOM_UTF16_BE, "utf-16"),
    (codecs.BOM_UTF8, "utf-8-sig"),
)
#: control characters no text table holds (a tab, line ends and a form feed are text)
_CONTROL = re.compile(rb"[\x00-\x08\x0e-\x1f\x7f]")
#: the five bytes Windows-1252 leaves undefined: a file holding one is read as Latin-1 (ISO 8859-1)
_NOT_CP1252 = re.compile(rb"[\x81\x8d\x8f\x90\x9d]")
#: the share of control characters beyond which 8-bit "text" is binary data
_BINARY_SHARE = 0.01


def _stamp(path: str | Path) -> tuple[int, int]:
    info = Path(path).stat()
    return info.st_mtime_ns, info.st_size


def text_encoding(path: str | Path) -> TextEncoding:
    """How the readers decode a delimited text file: UTF-8 (a byte-order mark is fine), UTF-16 or UTF-32 by its
    byte-order mark (or UTF-16 without one, where every other byte of its start is zero), else 8-bit text,
    Windows-1252 (Latin-1 where it holds a byte Windows-1252 leaves undefined), said in
    :attr:`TextEncoding.note`.  A file of binary data (a zero byte, or more than 1 % control characters) is
    refused (DataError): no reader meets it as a table with a garbled header.  Read once per file while it is
    unchanged; a gzip file decompressed."""
    try:
        info = Path(path).stat()
        if not stat.S_ISREG(info.st_mode):  # a pipe is read once, by the reader
            return TextEncoding()
    except (OSError, ValueError):
        return TextEncoding()
    return _text_encoding(str(path), info.st_mtime_ns, info.st_size)


@functools.lru_cache(maxsize=16)
def _text_encoding(path: str, mtime: int, size: int) -> TextEncoding:
    try:
        with gzip.open(path, "rb") if is_gzip(path) else open(path, "rb") as handle:
            head = handle.read(1 << 16)
            for mark, codec in _BYTE_ORDER_MARKS:
                if head.startswith(mark):
                    return TextEncoding(codec)
            wide = _wide_without_mark(head)
            if wide:
                return TextEncoding(wide, f"{path}: UTF-16 text without a byte-order mark: read as {wide.upper()}")
            decoder = codecs.getincrementaldecoder("utf-8")()
            chunk, offset, bad = head, 0, None
            while chunk:
                zero = chunk.find(b"\x00")
                if zero >= 0:
                    _refuse_binary(path, f"a zero byte at byte {offset + zero}")
                try:
                    if not (chunk.isascii() and not decoder.getstate()[0]):  # ASCII: UTF-8 as it stands (fast)
                        decoder.decode(chunk)
                except UnicodeDecodeError as exc:
                    bad = offset + exc.start
                    break
                offset += len(chunk)
                chunk = handle.read(_CHUNK)
            if bad is None:
                try:
                    decoder.decode(b"", final=True)
                    return TextEncoding()
                except UnicodeDecodeError:
                    bad = offset
            handle.seek(0)
            data = handle.read()
    except (OSError, EOFError, zlib.error):  # the reader says it cannot read the file
        return TextEncoding()
    zero = data.find(b"\x00")
    if zero >= 0:
        _refuse_binary(path, f"a zero byte at byte {zero}")
    sample = data[: 1 << 16]
    controls = len(_CONTROL.findall(sample))
    if controls > _BINARY_SHARE * len(sample):
        _refuse_binary(path, f"{controls} control characters in its first {len(sample)} bytes")
    said = f"{path}: not UTF-8 (byte {bad} is 0x{data[bad : bad + 1].hex()})"
    if _NOT_CP1252.search(data) is None:
        return TextEncoding("cp1252", f"{said}: read as Windows-1252 (Latin-1) text")
    return TextEncoding("latin-1", f"{said}: read as Latin-1 (ISO 8859-1) text")


def _wide_without_mark(head: bytes) -> str:
    """ "utf-16-le" or "utf-16-be" where ``head`` is UTF-16 text without a byte-order mark (every other byte zero,
    the others not), else ""."""
    sample = head[: 4096 - 4096 % 2] if len(head) >= 2 else b""
    if len(sample) < 8:
        return ""
    even, odd = sample[0::2], sample[1::2]
    if not odd.strip(b"\x00") and b"\x00" not in even:
        return "utf-16-le"
    if not even.strip(b"\x00") and b"\x00" not in odd:
        return "utf-16-be"
    return ""


def _refuse_binary(path: str, why: str) -> None:
    raise DataError(
        f"{path}: cannot be read as CSV: not a text table (binary data: {why}); expected delimited text (CSV, tab- or"
        " blank-separated;"
        " UTF-8, UTF-16 or 8-bit text)"
    )


@functools.lru_cache(maxsize=2)
def _transcript(path: str, mtime: int, size: int) -> bytes:
    """The UTF-8 bytes of a text file that is not UTF-8 (:func:`text_encoding`), decompressed where it is gzip."""
    codec = _text_encoding(path, mtime, size).codec
    with gzip.open(path, "rb") if is_gzip(path) else open(path, "rb") as handle:
        text = handle.read().decode(codec, errors="replace")
    return text.lstrip("\ufeff").encode("utf-8")


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
        with open_input(path, "rt", newline="", encoding="utf-8-sig") as handle:
            for k, row in enumerate(csv.reader(handle, delimiter=delimiter), start=1):
                if row and any(c.strip() for c in row) and not row[0].lstrip().startswith("#"):
                    yield k, row
    except FileNotFoundError:
        raise DataError(f"{source}: file not found") from None
    except (OSError, EOFError, zlib.error, UnicodeDecodeError, csv.Error) as exc:
        raise DataError(f"{source}: cannot be read as CSV ({exc})") from None


def _header_row(path: Path, source: str, expected: Sequence[str] = ()) -> tuple[int, list[str]] | None:
    """(file row, cells) of the table's header (:class:`Layout`'s: after any title lines); None for a file with no
    row; DataError naming the first data row where the file has no header row (``expected``: the columns it
    should name)."""
    layout = text_format(path).layout
    if layout.commented:
        return int(layout.header_row or 0), list(layout.commented)
    rows = _content_rows(path, source)
    try:
        for row_number, row in rows:
            if layout.header_row is None:
                raise DataError(
                    f"{source}: row {row_number}: no header row (the file's first row holds numbers:"
                    f" {shorten(_row_text(row))}); expected a header row naming the columns"
                    f"{' ' + ', '.join(expected) if expected else ''}"
                )
            if row_number >= layout.header_row:
                return row_number, row
        return None
    finally:
        rows.close()


def _row_text(row: list[str]) -> str:
    return ",".join(cell.strip() for cell in row)


def _read_header(
    path: Path, source: str, dimensions: Mapping[str, str], required: Sequence[str], ignore: Sequence[str]
) -> _Header:
    first = _header_row(path, source, required)
    if first is None:
        raise DataError(f"{source}: empty file, expected a header row with columns {', '.join(required)}")
    header_row, header = first
    layout = text_format(path).layout
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
        below = layout.unit(position - 1)  # a units row's word under a header that names none ("ms")
        if below is not None and SCALED_UNIT.fullmatch(below):
            raise DataError(
                f"{source}: row {layout.units_row} (the units row), column {position}: {below!r} is no unit; expected"
                " a unit word (s, ms, um, mm, -); a scale such as 10 um belongs in the numbers"
            )
        if below is not None and unit is not None and unit.strip() and unit.strip() != below:
            raise DataError(
                f"{source}: column {cell.strip()!r} names its unit {unit.strip()!r} but the units row (row"
                f" {layout.units_row}) says {below!r}; give one of them"
            )
        unit = below if below is not None and not (unit or "").strip() else unit
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
    return _Header(header_row, names, factors, units, max(header_row, layout.data_after))


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
        if row_number <= header.data_after:
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
        with _arrow_input(path) as stream:
            table = pacsv.read_csv(
                stream,
                read_options=pacsv.ReadOptions(skip_rows=header.data_after, column_names=header.names),
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
    rows = _data_rows(path, header.data_after, len(next(iter(columns.values()))) if columns else 0)
    return None if rows is None else (columns, rows)


#: Bytes read at a time when numbering the rows of a large file.
_CHUNK = 1 << 24


def _data_rows(path: Path, header_row: int, count: int) -> np.ndarray | None:
    """File row numbers of the ``count`` data rows after ``header_row`` (the header, or the units row under it;
    empty lines skipped), or None if they cannot be matched line for line (e.g. a quoted cell spanning lines)."""
    lines = 0
    ends_open = False
    with open_input(path, "rb") as handle:
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
    with open_input(path, "rb") as handle:
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
