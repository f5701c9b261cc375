"""Units of everything that leaves the package: one registry, one convention for each kind of file.

Every column or JSON key the package writes has an SI unit here (``"1"`` for a
pure number, ``None`` for text).  The conventions, each written and read by
this module only:

- a DataFrame from any ``to_frame()`` carries ``frame.attrs["units"]`` (column -> unit);
- a CSV header cell is ``name [unit]`` (``[1]`` for a pure number; text columns are bare);
  :func:`stickslip.tables.read_table` reads those brackets back;
- a Parquet file holds each unit in its field's metadata (key ``unit``) and the whole
  map in the schema metadata (key ``stickslip:units``), so ``pyarrow`` users see them
  and :func:`read_parquet` restores ``attrs["units"]``;
- a JSON document gets a top-level ``units`` map for the keys it contains.
"""

from __future__ import annotations

import io
import json
import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .tables import split_header as split_header  # the readers' header rule, one definition

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    import pyarrow as pa

__all__ = [
    "CSV_DIGITS",
    "DIMENSIONLESS",
    "INHERITED",
    "JSON_DIGITS",
    "UNITS",
    "attribute_frame",
    "csv_number",
    "csv_text",
    "data_lines",
    "header_cell",
    "json_safe",
    "json_text",
    "json_units",
    "parquet_table",
    "read_parquet",
    "split_header",
    "unit_of",
    "units_of_frame",
    "with_units",
]

#: The unit written for a pure number (ISO 80000: the unit one).
DIMENSIONLESS = "1"
#: Key of the units map in Parquet schema metadata and in JSON documents.
PARQUET_KEY = b"stickslip:units"
JSON_KEY = "units"

_TIME, _STRESS, _VELOCITY, _LENGTH = "s", "Pa", "m/s", "m"

#: Column and JSON key -> SI unit (``"1"``: a pure number; ``None``: text or a flag).
UNITS: dict[str, str | None] = {
    # traces
    "time": _TIME,
    "stress": _STRESS,
    "velocity": _VELOCITY,
    "stress_slope": "Pa s/m",
    "bonded_fraction": DIMENSIONLESS,
    "chain_fraction": DIMENSIONLESS,
    "slider_displacement": _LENGTH,
    "puller_displacement": _LENGTH,
    "block_shear": _LENGTH,
    "slider_velocity": _VELOCITY,
    "slider_position": _LENGTH,
    "puller_position": _LENGTH,
    "load_point_displacement": _LENGTH,
    "friction": DIMENSIONLESS,
    "state": _TIME,
    "state2": _TIME,
    "phase": None,
    "held_by": None,  # what holds the block: "bonds" or the stick "chains"
    # bond population snapshots
    "age": _TIME,
    "extension": _LENGTH,
    "weight": "1/m^2",
    # protocols
    "start": _TIME,
    "end": _TIME,
    "duration": _TIME,
    # data and fits
    "row": None,
    "stress_err": _STRESS,
    "model_stress": _STRESS,
    "model": DIMENSIONLESS,
    "residual": DIMENSIONLESS,
    "pulling_velocity": _VELOCITY,
    "stick_time": _TIME,
    "peak_stress": _STRESS,
    "start_stress": _STRESS,
    "start_stress_used": _STRESS,
    "used": None,
    "loading_rate": "Pa/s",
    "model_stick_time": _TIME,
    "model_peak_stress": _STRESS,
    "log_prob": DIMENSIONLESS,
    # measured cycles (analyze)
    "index": None,
    "complete": None,
    "start_time": _TIME,
    "peak_time": _TIME,
    "end_time": _TIME,
    "critical_stress": _STRESS,
    "stick_slope": "Pa/s",
    "stick_slope_stderr": "Pa/s",
    "stiffness": "Pa/m",
    "stiffness_stderr": "Pa/m",
    "jump_velocity": _VELOCITY,
    "slip_time": _TIME,
    "period": _TIME,
    "stress_drop": _STRESS,
    "critical_stress_uncertainty": _STRESS,  # analyze's systematic uncertainty of a cycle's corners
    "peak_stress_uncertainty": _STRESS,
    "stick_time_uncertainty": _TIME,
    "start_stress_uncertainty": _STRESS,  # the same, in a stick table (fit stick)
    "stick_points": None,
    "stick_rms": _STRESS,
    "message": None,
    # summaries
    "critical_velocity": _VELOCITY,
    "mean_stress": _STRESS,
    "final_stress": _STRESS,
    "trough_stress": _STRESS,
    "final_friction": DIMENSIONLESS,
    "peak_friction": DIMENSIONLESS,
    "trough_friction": DIMENSIONLESS,
    "mean_friction": DIMENSIONLESS,
    "final_bonded_fraction": DIMENSIONLESS,
    "final_velocity": _VELOCITY,
    "split_velocity": _VELOCITY,
    "regime": None,
    "status": None,
    "reason": None,
    "cycles": None,  # a count (JSON: a list of cycles)
    "growth": DIMENSIONLESS,  # ratio of successive oscillation amplitudes
    # the massless block's jumps (transient.jump.Jump)
    "jumps": None,
    "stress_before": _STRESS,
    "stress_after": _STRESS,
    "travel": _LENGTH,
    "broken_share": DIMENSIONLESS,
    "survivors": None,  # a count of cohorts
    "point": None,
    # sweep axes beyond the parameter keys
    "block.stiffness": "Pa/m",
    "block.effective_stiffness": "Pa/m",
    # rate-and-state (friction is a pure number; stiffness per unit normal stress)
    "a": DIMENSIONLESS,
    "b": DIMENSIONLESS,
    "b2": DIMENSIONLESS,
    "dc": _LENGTH,
    "dc2": _LENGTH,
    "k": "1/m",
    "eta": "s/m",
    "mu0": DIMENSIONLESS,
    "v_ref": _VELOCITY,
    "normal_stress": _STRESS,
    "critical_stiffness": "1/m",
    "neutral_period": _TIME,
    "growth_rate": "1/s",
    # critical point and fits
    "turnover_velocity": _VELOCITY,
    "turnover_stress": _STRESS,
    "effective_stiffness": "Pa/m",
    "chi_square": DIMENSIONLESS,
    "reduced_chi_square": DIMENSIONLESS,
    "confidence_level": DIMENSIONLESS,
    "relative_noise": DIMENSIONLESS,
    "relative_floor": DIMENSIONLESS,  # fit stick's floor of a velocity's mean error (ln), and that mean's scatter
    "relative_scatter": DIMENSIONLESS,
    "residuals": DIMENSIONLESS,  # (data - fit) / error
    "dof": None,  # counts
    "steps": None,
    "wall_time": _TIME,  # a sweep point's computing time
    "periods": None,  # how many periods the regime classifier saw
    "periods_seen": None,  # the same, in a run's summary (run --json and its spellings)
    "amplitude_ratio": DIMENSIONLESS,
}
#: Keys whose numbers are in the unit of the key that holds them (``{"bonds.bond_time": {"value": ...}}``).
INHERITED = frozenset({"value", "stderr", "interval", "method_bias", "lower", "upper", "median", "scaled_interval"})


def _parameter_unit(name: str) -> str | type[KeyError] | None:
    """The SI unit of a parameter key (``bonds.bond_time``) or of an RSF key, else KeyError (the class)."""
    from .errors import ParameterError
    from .parameters import COMBINATIONS, key_dimension
    from .units import DIMENSIONS

    try:
        dimension = key_dimension(name)
    except ParameterError:
        dimension = next((c.dimension for c in COMBINATIONS if c.name == name), "")
        if not dimension:
            return KeyError
    si = DIMENSIONS[dimension][1]
    return si or DIMENSIONLESS


def unit_of(name: str, extra: Mapping[str, str | None] | None = None) -> str | None:
    """The SI unit of a column or key; raises KeyError for a name the package does not know.

    ``extra`` names the units of columns particular to one output (they win over the registry).
    """
    if extra is not None and name in extra:
        return extra[name]
    if name in UNITS:
        return UNITS[name]
    unit = _parameter_unit(name)
    if unit is KeyError:
        raise KeyError(f"no unit registered for column {name!r} (add it to stickslip.columns.UNITS)")
    return unit  # type: ignore[return-value]


def with_units(frame: pd.DataFrame, extra: Mapping[str, str | None] | None = None) -> pd.DataFrame:
    """``frame`` with ``attrs["units"]`` set for every column; returns the same frame."""
    frame.attrs["units"] = {str(c): unit_of(str(c), extra) for c in frame.columns}
    return frame


def attribute_frame(obj: Any, names: str) -> pd.DataFrame:
    """A frame of the space-separated ``names`` of ``obj``'s arrays (each flattened), with its units."""
    import numpy as np
    import pandas as pd

    return with_units(pd.DataFrame({name: np.ravel(getattr(obj, name)) for name in names.split()}))


def units_of_frame(frame: pd.DataFrame) -> dict[str, str | None]:
    """The units of a frame's columns: its ``attrs["units"]``, else the registry."""
    known = frame.attrs.get("units") or {}
    return {str(c): known[str(c)] if str(c) in known else unit_of(str(c)) for c in frame.columns}


def data_lines(lines: Iterable[str], count: int) -> list[int] | None:
    """The 1-based file line of each of the ``count`` data rows after the header, blank lines and ``#`` comments
    skipped as the readers skip them (an error names the line an editor shows); None where the numbers do not
    match what the reader kept (a quoted line end)."""
    numbers = [n for n, line in enumerate(lines, 1) if line.split("#", 1)[0].strip()][1:]
    return numbers if len(numbers) == count else None


def header_cell(name: str, unit: str | None) -> str:
    """``name [unit]``; a text column stays bare."""
    return name if unit is None else f"{name} [{unit}]"


def _cell(value: Any) -> str:
    if isinstance(value, str):
        return value
    if value is None:
        return ""
    if isinstance(value, (bool,)) or type(value).__name__ == "bool_":
        return "true" if value else "false"
    number = float(value)
    return "" if math.isnan(number) else csv_number(number)


#: Significant digits of the numbers the package writes to CSV: those of its JSON (:data:`JSON_DIGITS`).
CSV_DIGITS = 15


def csv_number(number: float) -> str:
    """``number`` as a CSV cell: at :data:`CSV_DIGITS` significant digits, written as the JSON writes it (the
    shortest text of that rounded float: ``1e-05`` for 10 µm/s read as 9.999999999999999e-06).  The rounding moves
    a value by at most 5e-15 of itself (half a unit of the 15th digit, 1.000000000000004 -> 1.0), far below the
    accuracy of anything the package computes (its tightest solver tolerances are 1e-11 relative, the stick
    phase's); a CSV read back agrees with the JSON of the same result."""
    return repr(float(f"{number:.{CSV_DIGITS}g}"))


def csv_text(frame: pd.DataFrame) -> str:
    """The frame as CSV: units in the header brackets, SI numbers at 15 significant digits (:func:`csv_number`)."""
    units = units_of_frame(frame)
    out = io.StringIO()
    names = [str(c) for c in frame.columns]
    out.write(",".join(header_cell(n, units[n]) for n in names) + "\n")
    columns = [frame[c].tolist() for c in frame.columns]
    for row in zip(*columns, strict=True):
        out.write(",".join(_cell(v) for v in row) + "\n")
    return out.getvalue()


def parquet_table(frame: pd.DataFrame) -> pa.Table:
    """A pyarrow Table of ``frame`` whose fields and schema carry the units."""
    import pyarrow as pa

    units = units_of_frame(frame)
    table = pa.Table.from_pandas(frame, preserve_index=False)
    fields = []
    for f in table.schema:
        unit = units.get(f.name)
        fields.append(f.with_metadata({b"unit": unit.encode()}) if unit is not None else f)
    metadata = dict(table.schema.metadata or {})
    metadata[PARQUET_KEY] = json.dumps(units).encode()
    return table.cast(pa.schema(fields, metadata=metadata))


def read_parquet(path: str | Path) -> pd.DataFrame:
    """A Parquet file (or folder of them) written by the package, with ``attrs["units"]`` restored."""
    import pandas as pd
    import pyarrow.parquet as pq

    frame = pd.read_parquet(path)
    frame.attrs["units"] = _parquet_units(path, list(frame.columns), pq)
    return frame


def _parquet_units(path: str | Path, columns: list[str], pq: Any) -> dict[str, str | None]:
    schema = pq.read_schema(path) if Path(path).is_file() else pq.ParquetDataset(path).schema
    stored = json.loads((schema.metadata or {}).get(PARQUET_KEY, b"{}"))
    units: dict[str, str | None] = {}
    for name in columns:
        if name in stored:
            units[name] = stored[name]
            continue
        try:
            unit = schema.field(name).metadata
        except KeyError:
            unit = None
        units[name] = unit[b"unit"].decode() if unit and b"unit" in unit else None
    return units


def _keys(obj: Any) -> Iterable[str]:
    if isinstance(obj, Mapping):
        for key, value in obj.items():
            yield str(key)
            yield from _keys(value)
    elif isinstance(obj, (list, tuple)):
        for item in obj:
            yield from _keys(item)


def _word_keys(obj: Any) -> set[str]:
    """The keys of ``obj`` (nested) whose every value is a string: a word has no unit ("model": "transient")."""
    seen: dict[str, bool] = {}

    def visit(item: Any) -> None:
        if isinstance(item, Mapping):
            for key, value in item.items():
                seen[str(key)] = seen.get(str(key), True) and isinstance(value, str)
                visit(value)
        elif isinstance(item, (list, tuple)):
            for each in item:
                visit(each)

    visit(obj)
    return {key for key, word in seen.items() if word}


def json_units(document: Mapping[str, Any], extra: Mapping[str, str | None] | None = None) -> dict[str, str]:
    """The ``units`` map of a JSON document: every key it contains that has a unit (SI)."""
    units: dict[str, str] = {}
    words = _word_keys(document)
    for key in _keys(document):
        if key in units or key == JSON_KEY or key in words:
            continue
        try:
            unit = unit_of(key, extra)
        except KeyError:
            continue
        if unit is not None:
            units[key] = unit
    return dict(sorted(units.items()))


def json_safe(obj: Any, digits: int | None = None) -> Any:
    """Replace non-finite floats by None and numpy types by Python ones, recursively.

    ``digits``: write floats at that many significant digits (15 drops float noise such as
    0.0007999999999999999 for 8e-4 and moves no value by more than 5e-16 of itself); None keeps every bit.
    """
    import numpy as np

    from .regimes import Regime

    if isinstance(obj, dict):
        return {str(k): json_safe(v, digits) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v, digits) for v in obj]
    if isinstance(obj, np.ndarray):
        return [json_safe(v, digits) for v in obj.tolist()]
    if isinstance(obj, (np.floating, float)):
        value = float(obj)
        if not math.isfinite(value):
            return None
        return value if digits is None else float(f"{value:.{digits}g}")
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, Regime):  # a regime is written by its kind's name, as when it was a str
        return obj.kind
    return obj


#: Significant digits of the numbers in the JSON people read (see :func:`json_safe`).
JSON_DIGITS = 15


def json_text(obj: Any) -> str:
    """The JSON text of a result: SI numbers without float noise, and a top-level ``units`` map naming them."""
    document = json_safe(obj, JSON_DIGITS)
    if isinstance(document, dict) and JSON_KEY not in document:
        document[JSON_KEY] = json_units(document)
    return json.dumps(document, indent=2)
