"""Reading measurement tables: CSV with a header, units in brackets.

``velocity [um/s],stress [Pa],stress_err [Pa]`` -- a bare column name means SI.
Every problem is a :class:`~stickslip.errors.DataError` naming the file, the
row (1-based, counting the header as row 1) and the column.
"""

from __future__ import annotations

import csv
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import DataError, UnitError
from .units import to_si

_HEADER = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(?:\[(.*)\])?\s*$")


@dataclass(frozen=True)
class Table:
    """Columns as SI float arrays (NaN where a cell was empty and allowed to be)."""

    source: str
    columns: dict[str, np.ndarray]
    rows: np.ndarray  # file row number of each data row (header is row 1)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def __contains__(self, name: object) -> bool:
        return name in self.columns

    def __len__(self) -> int:
        return int(self.rows.size)


def read_table(
    path: str | Path,
    dimensions: Mapping[str, str],
    required: Sequence[str],
    allow_missing: Sequence[str] = (),
) -> Table:
    """Read a CSV file whose columns are named in ``dimensions`` (name -> dimension).

    Columns in ``required`` must be present; others in ``dimensions`` are
    optional; any other column is an error.  Empty or NaN cells are errors
    except in columns listed in ``allow_missing`` (kept as NaN).
    """
    path = Path(path)
    source = str(path)
    try:
        with path.open(newline="", encoding="utf-8-sig") as handle:
            lines = [row for row in csv.reader(handle)]
    except FileNotFoundError:
        raise DataError(f"{source}: file not found") from None
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise DataError(f"{source}: cannot be read as CSV ({exc})") from None
    # skip blank lines and '#' comments, remembering file row numbers
    numbered = [(k + 1, row) for k, row in enumerate(lines) if row and any(c.strip() for c in row)]
    numbered = [(k, row) for k, row in numbered if not row[0].lstrip().startswith("#")]
    if not numbered:
        raise DataError(f"{source}: empty file, expected a header row with columns {', '.join(required)}")
    header_row, header = numbered[0]
    names, factors = [], []
    for position, cell in enumerate(header, start=1):
        match = _HEADER.match(cell)
        if not match:
            raise DataError(
                f"{source}: row {header_row}, column {position}: cannot read header {cell!r};"
                " expected name or 'name [unit]'"
            )
        name, unit = match.group(1), match.group(2)
        if name not in dimensions:
            raise DataError(f"{source}: unknown column {name!r}; expected {', '.join(dimensions)}")
        if name in names:
            raise DataError(f"{source}: column {name!r} appears twice")
        dimension = dimensions[name]
        try:
            factor = to_si(f"1 {unit}", dimension, f"column {name!r}") if unit and unit.strip() else 1.0
        except UnitError as exc:
            raise DataError(f"{source}: {exc}") from None
        names.append(name)
        factors.append(factor)
    missing = [c for c in required if c not in names]
    if missing:
        raise DataError(f"{source}: missing column(s) {', '.join(missing)}; found {', '.join(names)}")
    values: dict[str, list[float]] = {n: [] for n in names}
    rows = []
    for row_number, row in numbered[1:]:
        if len(row) != len(names):
            raise DataError(f"{source}: row {row_number}: expected {len(names)} values, got {len(row)}")
        for name, factor, cell in zip(names, factors, row, strict=True):
            text = cell.strip()
            try:
                value = float(text) if text else math.nan
            except ValueError:
                raise DataError(f"{source}: row {row_number}, column {name!r}: {cell!r} is not a number") from None
            if math.isnan(value) and name not in allow_missing:
                raise DataError(f"{source}: row {row_number}, column {name!r}: missing or NaN value")
            if math.isinf(value):
                raise DataError(f"{source}: row {row_number}, column {name!r}: infinite value")
            values[name].append(value * factor)
        rows.append(row_number)
    return Table(source, {n: np.asarray(v, dtype=float) for n, v in values.items()}, np.asarray(rows, dtype=int))


def require_positive(table: Table, name: str) -> None:
    """DataError naming the first row where column ``name`` is <= 0."""
    column = table[name]
    bad = np.nonzero(column <= 0)[0]
    if bad.size:
        k = bad[0]
        raise DataError(
            f"{table.source}: row {table.rows[k]}, column {name!r}: expected a positive value, got {column[k]:g}"
        )
