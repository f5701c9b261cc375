"""A sweep's rows as one file that names its units: CSV (``name [unit]`` headers, no index), JSON, Parquet.

``pandas.read_parquet(OUT).to_csv(FILE)`` wrote headers without units and a nameless index column; this writes the
same rows (sorted by point, SI) under the package's conventions (:mod:`stickslip.columns`).
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path
from typing import Any

from ..errors import ParameterError

__all__ = ["TABLE_SUFFIXES", "write_table"]

#: The files :func:`write_table` writes, by suffix: CSV (tab-separated for .tsv), a JSON document, one Parquet file.
TABLE_SUFFIXES = {".csv": ",", ".txt": ",", ".tsv": "\t", ".json": None, ".parquet": None}


def write_table(folder: str | Path, path: str | Path) -> Path:
    """Write the rows of the sweep in ``folder`` to ``path`` as one file; returns the path.

    ``.csv``/``.txt`` (``.tsv``: tab-separated): a header of ``name [unit]`` cells (text columns bare: point, regime,
    status, message), one line per point in point order, no index column, SI numbers at 15 significant digits, an
    empty cell for NaN, text quoted where it holds the separator.  ``.json``: ``{"rows": [{column: value}, ...],
    "units": {column: unit}}`` (NaN as null).  ``.parquet``: one file whose fields and schema name the units.
    """
    from ..fileio import atomic_path, atomic_write_text
    from .engine import read_results

    target = Path(path)
    suffix = target.suffix.lower()
    if suffix not in TABLE_SUFFIXES:
        raise ParameterError(
            f"{path}: expected a file named .csv, .tsv, .txt, .json or .parquet, got {suffix or 'no suffix'}"
        )
    _refuse_inside(Path(folder), target)
    frame = read_results(folder)
    units: dict[str, str | None] = dict(frame.attrs.get("units") or {})
    if suffix == ".parquet":
        import pyarrow.parquet as pq

        from ..columns import parquet_table

        with atomic_path(target) as temp:
            pq.write_table(parquet_table(frame), temp)
        return target
    if suffix == ".json":
        rows = [{name: _json_value(value) for name, value in row.items()} for row in frame.to_dict("records")]
        document = {"rows": rows, "units": {name: unit for name, unit in units.items() if unit is not None}}
        return atomic_write_text(target, json.dumps(document, indent=2, ensure_ascii=False) + "\n")
    return atomic_write_text(target, csv_rows(frame, units, TABLE_SUFFIXES[suffix] or ","))


def _refuse_inside(folder: Path, target: Path) -> None:
    """A table written into the sweep's own folder became part of the sweep (a .parquet file is read as a chunk:
    every point twice; a _manifest.json replaced the sweep's), so it is refused, naming the folder."""
    from ..errors import DataError

    try:
        home = folder.resolve(strict=True)
        where = target.parent.resolve()
    except OSError:  # no such folder: read_results says so
        return
    if where == home or home in where.parents:
        raise DataError(
            f"{target}: inside the sweep's folder {folder}, whose files are the sweep (a table there is read as part"
            " of it, or replaces its manifest); write it elsewhere"
        )


def csv_rows(frame: Any, units: dict[str, str | None], separator: str = ",") -> str:
    """The frame as CSV text: ``name [unit]`` headers (:func:`stickslip.columns.header_cell`), no index."""
    from ..columns import header_cell

    out = io.StringIO()
    writer = csv.writer(out, delimiter=separator, lineterminator="\n")
    names = [str(c) for c in frame.columns]
    writer.writerow(header_cell(name, units.get(name)) for name in names)
    for row in zip(*(frame[c].tolist() for c in frame.columns), strict=True):
        writer.writerow(_cell(value) for value in row)
    return out.getvalue()


def _cell(value: Any) -> str:
    from ..columns import csv_number

    if value is None or isinstance(value, str):
        return value or ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    number = float(value)
    return "" if math.isnan(number) else csv_number(number)


def _json_value(value: Any) -> Any:
    if value is None or isinstance(value, (str, bool, int)):
        return value
    number = float(value)
    return number if math.isfinite(number) else None
