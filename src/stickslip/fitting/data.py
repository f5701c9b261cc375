"""Measurement files for fitting: steady friction curves and stick-phase tables.

CSV with a header row, units in brackets after the column name (a bare name is SI), ``#`` comments; the columns
of each kind, and those recognised and ignored: docs/fitting.md.  Every problem is a
:class:`~stickslip.errors.DataError` naming the file, the row (the header is row 1) and the column.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..columns import unit_of, with_units
from ..errors import DataError, ParameterError
from ..tables import Table, header_names, read_table

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    from matplotlib.axes import Axes

#: Fewest points a steady curve may have: the paper's two-step fit needs at
#: least one more point than free parameters in each velocity range.
MIN_STEADY_POINTS = 4
#: Fewest rows of a stick table.
MIN_STICK_ROWS = 2
#: Velocities closer than this (relative) count as one velocity: repeated measurements there (replicates).
DUPLICATE_TOLERANCE = 1e-9

STEADY_COLUMNS = {"velocity": "velocity", "stress": "stress", "stress_err": "stress"}
#: Columns of ``stickslip curve --format csv`` that the fit does not use: read (so that their units are
#: checked) and dropped with a note.  Any other column is an error.
STEADY_IGNORED_COLUMNS = {"bonded_fraction": "dimensionless", "stress_slope": "stress_per_velocity"}
#: The range a measured friction stress (and its error) may have, Pa: 1 TPa is above the ideal strength
#: of any solid; beyond these the numbers are unit mistakes, and their squares would overflow the sums.
STRESS_RANGE = (1e-9, 1e12)
#: The range of sliding velocities, m/s (the upper end is the speed of light).
VELOCITY_RANGE = (1e-15, 3e8)
#: The ranges of a stick phase's other columns: its duration (s; 1e12 s is ~30 000 years), its loading rate (Pa/s;
#: 1e15 Pa/s passes STRESS_RANGE's top within a millisecond) and the block's stiffness (Pa/m).  Beyond them the
#: numbers are unit mistakes; a stick_slope of 1e300 Pa/s held the stick fit's integration for minutes.
STICK_TIME_RANGE = (1e-12, 1e12)
STRESS_RATE_RANGE = (1e-15, 1e15)
STIFFNESS_RANGE = (1e-9, 1e18)
STICK_COLUMNS = {
    "pulling_velocity": "velocity",
    "stick_time": "time",
    "peak_stress": "stress",
    "start_stress": "stress",
    "cycle": "dimensionless",
    "stick_slope": "stress_rate",
    "stiffness": "stress_per_length",
    "jump_velocity": "velocity",
    # a measurement's own systematic uncertainty (analyze -o writes them): floors of the fit's errors
    "stick_time_uncertainty": "time",
    "start_stress_uncertainty": "stress",
    "peak_stress_uncertainty": "stress",
}
#: The uncertainty columns of a stick table (fit stick floors the error of each velocity's mean with them).
STICK_UNCERTAINTIES = ("stick_time_uncertainty", "start_stress_uncertainty", "peak_stress_uncertainty")
#: Stick-table columns that may have empty cells (``--`` in the paper's Table 1 becomes an empty cell).
STICK_OPTIONAL_CELLS = (
    "peak_stress", "start_stress", "cycle", "stick_slope", "stiffness", "jump_velocity", *STICK_UNCERTAINTIES,
)  # fmt: skip


#: Columns of ``stickslip analyze -o`` (its cycles table) that a stick fit reads, and what it reads them as.
CYCLES_COLUMNS = {"critical_stress": "start_stress", "critical_stress_uncertainty": "start_stress_uncertainty"}
#: Columns of that table the stick fit does not use (times within the record, errors, the slip, the model's Vs).
CYCLES_IGNORED = (
    "complete", "peak_time", "end_time", "stick_slope_stderr", "stiffness_stderr",
    "model_jump_velocity", "slip_time", "period", "stress_drop", "stick_curvature", "stick_curvature_stderr",
)  # fmt: skip
#: Columns only analyze's cycles table has: a table with any of them (and without the columns Table 1's reader
#: knows alone) is read as a cycles table, with or without its critical_stress (round 29: a table whose
#: critical_stress columns were deleted to fit without the measured start stresses was "unknown column 'complete'").
CYCLES_ONLY = ("critical_stress", "critical_stress_uncertainty", "start_time", *CYCLES_IGNORED)
#: analyze's flag of a stick curved beyond its noise (round 30; its curvature and that error are in
#: CYCLES_IGNORED): not a fit input; the stick fit's sticks are straight, so the rows it flags are named
CYCLE_CURVED = "stick_curved"
#: The time of each cycle's start within its record (s): read from a cycles table to date its start stress
#: (the drift check of fit stick, docs/fitting.md); not a fit input.
CYCLE_START_TIME = "start_time"


@dataclass(frozen=True)
class SteadyData:
    """A measured steady friction curve, SI units, in file order."""

    velocity: np.ndarray
    stress: np.ndarray
    stress_err: np.ndarray | None
    rows: np.ndarray
    source: str = "data"
    ignored_columns: tuple[str, ...] = ()
    read_notes: tuple[str, ...] = ()  # how the file was read where it is not the usual way (decimal commas)
    #: the file rows left out by request (``--exclude-row``, ``exclude_rows=``): not in ``rows``
    excluded: tuple[int, ...] = ()

    def __len__(self) -> int:
        return int(self.velocity.size)

    def without_rows(self, exclude: Sequence[int]) -> SteadyData:
        """These data less the file rows ``exclude`` (``--exclude-row``), a note naming them; a row that is not a
        data row, or too few points (or velocities) left to fit, is a :class:`DataError`."""
        gone = requested_rows(exclude, self.rows, self.source)
        if not gone:
            return self
        keep = ~np.isin(self.rows, sorted(gone))
        n, distinct = int(np.count_nonzero(keep)), _distinct_velocities(self.velocity[keep])
        named = ", ".join(map(str, sorted(gone)))
        if n < MIN_STEADY_POINTS or distinct < MIN_STEADY_POINTS:
            raise DataError(
                f"{self.source}: --exclude-row {named}: {n} data row(s) at {distinct} velocities left, expected at"
                f" least {MIN_STEADY_POINTS} velocities to fit a friction curve"
            )
        note = (
            f"{self.source}: {'rows' if len(gone) > 1 else 'row'} {named} left out by request (--exclude-row):"
            f" {n} of {len(self)} points fitted"
        )
        return dataclasses.replace(
            self,
            velocity=self.velocity[keep],
            stress=self.stress[keep],
            stress_err=None if self.stress_err is None else self.stress_err[keep],
            rows=self.rows[keep],
            read_notes=(*self.read_notes, note),
            excluded=tuple(sorted({*self.excluded, *gone})),
        )

    @property
    def velocities(self) -> int:
        """How many distinct velocities the points are at (fewer than the points where some are repeated)."""
        return _distinct_velocities(self.velocity)

    def notes(self) -> list[str]:
        """What the reader left out, and the repeated measurements it kept (a line each, or none)."""
        out = list(self.read_notes)
        if self.ignored_columns:
            names = ", ".join(self.ignored_columns)
            out.append(f"{self.source}: column(s) {names} not used by the steady fit (ignored)")
        out.extend(_replicate_notes(self))
        return out

    @classmethod
    def from_arrays(cls, velocity: Any, stress: Any, stress_err: Any = None, source: str = "data") -> SteadyData:
        """Validated data from arrays in SI units (rows are numbered from 1)."""
        columns = {"velocity": _as_column(velocity, "velocity", source), "stress": _as_column(stress, "stress", source)}
        if stress_err is not None:
            columns["stress_err"] = _as_column(stress_err, "stress_err", source)
        sizes = {name: col.size for name, col in columns.items()}
        if len(set(sizes.values())) != 1:
            raise DataError(f"{source}: columns have different lengths {sizes}")
        rows = np.arange(1, columns["velocity"].size + 1)
        return _validated_steady(Table(source, columns, rows))

    def to_frame(self) -> pd.DataFrame:
        import pandas as pd

        frame = {"row": self.rows, "velocity": self.velocity, "stress": self.stress}
        if self.stress_err is not None:
            frame["stress_err"] = self.stress_err
        return with_units(pd.DataFrame(frame))

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        """Stress against log velocity (um/s), with error bars where given."""
        from ..plots.fits import plot_steady_data

        return plot_steady_data(self, ax=ax, **kwargs)


@dataclass(frozen=True)
class StickData:
    """Measured stick phases: one row per cycle (NaN where a cell was empty)."""

    pulling_velocity: np.ndarray
    stick_time: np.ndarray
    peak_stress: np.ndarray | None
    start_stress: np.ndarray | None
    rows: np.ndarray
    extra: dict[str, np.ndarray]
    source: str = "table"
    read_notes: tuple[str, ...] = ()
    #: the file rows the reader left out, with why (a cycles table's cycles without a stick time): not in ``rows``
    left_out: tuple[tuple[int, str], ...] = ()

    def __len__(self) -> int:
        return int(self.pulling_velocity.size)

    def notes(self) -> list[str]:
        """What the reader read otherwise than as written, or left out (a cycles table's rows), and the rows
        identical in every column, one line each."""
        return [*self.read_notes, *_identical_stick_rows(self)]

    @classmethod
    def from_arrays(
        cls,
        pulling_velocity: Any,
        stick_time: Any,
        peak_stress: Any = None,
        start_stress: Any = None,
        source: str = "table",
    ) -> StickData:
        """Validated stick data from arrays in SI units (NaN allowed in peak_stress/start_stress)."""
        columns = {
            "pulling_velocity": _as_column(pulling_velocity, "pulling_velocity", source),
            "stick_time": _as_column(stick_time, "stick_time", source),
        }
        for name, values in (("peak_stress", peak_stress), ("start_stress", start_stress)):
            if values is not None:
                columns[name] = _as_column(values, name, source, allow_nan=True)
        sizes = {name: col.size for name, col in columns.items()}
        if len(set(sizes.values())) != 1:
            raise DataError(f"{source}: columns have different lengths {sizes}")
        return _validated_stick(Table(source, columns, np.arange(1, columns["stick_time"].size + 1)))

    def to_frame(self) -> pd.DataFrame:
        import pandas as pd

        frame: dict[str, np.ndarray] = {"row": self.rows, "pulling_velocity": self.pulling_velocity}
        frame["stick_time"] = self.stick_time
        if self.peak_stress is not None:
            frame["peak_stress"] = self.peak_stress
        if self.start_stress is not None:
            frame["start_stress"] = self.start_stress
        frame.update(self.extra)
        # the extra columns are read in SI: the registry's unit where it knows the name (a cycle number has none)
        return with_units(pd.DataFrame(frame), {name: None for name in self.extra if not _registered(name)})


def _registered(name: str) -> bool:
    try:
        unit_of(name)
    except KeyError:
        return False
    return True


def read_steady_data(path: str | Path) -> SteadyData:
    """Read and validate a steady friction curve (columns velocity, stress, optional stress_err).

    The extra columns of ``stickslip curve --format csv`` are ignored (:meth:`SteadyData.notes` says so).
    """
    table = read_table(
        path,
        STEADY_COLUMNS | STEADY_IGNORED_COLUMNS,
        required=["velocity", "stress"],
        allow_missing=tuple(STEADY_IGNORED_COLUMNS),
    )
    ignored = tuple(name for name in STEADY_IGNORED_COLUMNS if name in table)
    kept = dataclasses.replace(table, columns={k: v for k, v in table.columns.items() if k in STEADY_COLUMNS})
    return dataclasses.replace(_validated_steady(kept), ignored_columns=ignored, read_notes=table.notes)


def read_stick_data(path: str | Path) -> StickData:
    """Read and validate a stick table: Table 1's columns (pulling_velocity, stick_time, optional peak_stress,
    start_stress), or the cycles table of ``stickslip analyze -o`` (its ``critical_stress`` is the start stress;
    cycles cut by the record's ends or a gap in it, without a stick time, are left out; :meth:`StickData.notes`
    says so).  The one reader of ``fit stick`` and of the Python API."""
    # Table 1's reader first: it reads the file once (a pipe too); a cycles table fails it at its header
    try:
        table = read_table(
            path, STICK_COLUMNS, required=["pulling_velocity", "stick_time"], allow_missing=STICK_OPTIONAL_CELLS
        )
    except DataError:
        names = header_names(path)
        if not set(CYCLES_ONLY) & set(names):
            raise
        return _read_cycles_table(path, names)
    return dataclasses.replace(_validated_stick(table), read_notes=table.notes)


def _read_cycles_table(path: str | Path, names: Sequence[str]) -> StickData:
    """The cycles table of ``stickslip analyze -o`` as stick data, with notes on what was read so."""
    source = str(path)
    if "pulling_velocity" not in names:
        raise DataError(
            f"{source}: a cycles table of stickslip analyze without a pulling_velocity column (written before it"
            " had one): analyze the trace again, or add a column 'pulling_velocity [m/s]' holding its --v0"
        )
    dimensions = {n: d for n, d in STICK_COLUMNS.items() if n in names and n not in ("start_stress", "jump_velocity")}
    dimensions.pop("start_stress_uncertainty", None)
    for name in ("critical_stress", "critical_stress_uncertainty"):  # both optional: deleted, the sticks start
        if name in names:  # from the bond parameters' σc (docs/fitting.md)
            dimensions[name] = "stress"
    if CYCLE_START_TIME in names:
        dimensions[CYCLE_START_TIME] = "time"
    if CYCLE_CURVED in names:
        dimensions[CYCLE_CURVED] = "dimensionless"
    allowed = tuple(n for n in dimensions if n != "pulling_velocity")
    table = read_table(path, dimensions, required=["pulling_velocity", "stick_time"], allow_missing=allowed,
                       ignore=CYCLES_IGNORED)  # fmt: skip
    whole = np.isfinite(table["stick_time"])
    columns = {CYCLES_COLUMNS.get(n, n): v[whole] for n, v in table.columns.items()}
    curved = columns.pop(CYCLE_CURVED, np.zeros(int(whole.sum()))) > 0
    if "critical_stress" in names:
        said = "its critical_stress (σc) is each row's start_stress"
    else:
        said = "without its critical_stress column: no row has a measured start stress"
    notes = [*table.notes, f"{source}: the cycles table of stickslip analyze; {said}"]
    if not whole.all():
        cut = ", ".join(str(r) for r in table.rows[~whole])
        notes.append(f"{source}: row(s) {cut} left out: cycles cut by the record's ends or a gap in it (no stick time)")
    if curved.any():
        bent = ", ".join(str(r) for r in table.rows[whole][curved])
        notes.append(
            f"{source}: row(s) {bent}: analyze found the stick curved beyond its noise (stick_curved); the stick fit's"
            " sticks are straight (the block loaded at K V0), so their stick times carry the bend (docs/analysis.md)"
        )
    written = {CYCLES_COLUMNS.get(n, n): w for n, w in table.written.items() if n != CYCLE_CURVED}
    data = _validated_stick(Table(source, columns, table.rows[whole], written=written))
    why = "cycles cut by the record's ends or a gap in it: no stick time"
    cut_rows = tuple((int(r), why) for r in table.rows[~whole])
    return dataclasses.replace(data, read_notes=tuple(notes), left_out=cut_rows)


def _as_column(values: Any, name: str, source: str, allow_nan: bool = False) -> np.ndarray:
    try:
        column = np.asarray(values, dtype=float).ravel()
    except (TypeError, ValueError):
        raise DataError(f"{source}: column {name!r}: expected numbers, got {values!r}") from None
    bad = np.isinf(column) | (np.isnan(column) if not allow_nan else np.zeros(column.shape, bool))
    if np.any(bad):
        k = int(np.nonzero(bad)[0][0])
        raise DataError(f"{source}: row {k + 1}, column {name!r}: missing, NaN or infinite value")
    return column


def _require_positive(table: Table, names: Sequence[str]) -> None:
    """DataError at the first row (in file order) where a named column is <= 0 (NaN cells are skipped)."""
    present = [name for name in names if name in table]
    if not present:
        return
    bad = np.column_stack([table[name] <= 0 for name in present])  # NaN <= 0 is False
    rows = np.nonzero(bad.any(axis=1))[0]
    if rows.size:
        k = int(rows[0])
        name = present[int(np.argmax(bad[k]))]
        raise DataError(
            f"{table.source}: row {table.rows[k]}, column {name!r}: expected a positive value, got"
            f" {table.as_written(name, table[name][k])}"
        )


def _require_not_negative(table: Table, names: Sequence[str]) -> None:
    """DataError at the first row where a named column (an uncertainty) is negative or infinite (empty is none)."""
    for name in names:
        if name not in table:
            continue
        bad = np.nonzero((table[name] < 0) | np.isinf(table[name]))[0]
        if bad.size:
            k = int(bad[0])
            raise DataError(
                f"{table.source}: row {table.rows[k]}, column {name!r}: expected a finite uncertainty >= 0 (or an"
                f" empty cell), got {table.as_written(name, table[name][k])}"
            )


def _require_range(table: Table, name: str, bounds: tuple[float, float], unit: str, what: str) -> None:
    """DataError at the first row where column ``name`` is outside ``bounds`` (after the positivity check)."""
    if name not in table:
        return
    column = table[name]
    bad = np.nonzero((column < bounds[0]) | (column > bounds[1]))[0]
    if bad.size:
        k = int(bad[0])
        written = ""
        if table.written.get(name, ("", 1.0))[1] != 1.0:  # in SI, and as the file wrote it
            written = f" (written {table.as_written(name, column[k])})"
        raise DataError(
            f"{table.source}: row {table.rows[k]}, column {name!r}: {column[k]:g} {unit} is outside the range of"
            f" {what} ({bounds[0]:g} to {bounds[1]:g} {unit}); check the units in the header{written}"
        )


def _validated_steady(table: Table) -> SteadyData:
    # every row's values first, the count after: a file with a wrong value (a unit forgotten, a sign) says so
    # however few rows it has
    _require_positive(table, ["velocity", "stress", "stress_err"])
    _require_range(table, "velocity", VELOCITY_RANGE, "m/s", "a sliding velocity")
    for name in ("stress", "stress_err"):
        _require_range(table, name, STRESS_RANGE, "Pa", "a friction stress")
    n = len(table)
    if n < MIN_STEADY_POINTS:
        raise DataError(
            f"{table.source}: {n} data row(s), expected at least {MIN_STEADY_POINTS} to fit a friction curve"
        )
    v = table["velocity"]
    # repeated velocities are replicates, each row a point of the fit (their scatter measures the noise without the
    # model); the curve still needs MIN_STEADY_POINTS velocities
    distinct = _distinct_velocities(v)
    if distinct < MIN_STEADY_POINTS:
        raise DataError(
            f"{table.source}: {n} data rows at {distinct} distinct velocit{'y' if distinct == 1 else 'ies'}, expected"
            f" at least {MIN_STEADY_POINTS} velocities to fit a friction curve (rows repeated at one velocity are"
            " replicates: they measure the noise, not the curve's shape)"
        )
    err = table["stress_err"] if "stress_err" in table else None
    return SteadyData(v, table["stress"], err, table.rows, table.source)


def _distinct_velocities(velocity: np.ndarray) -> int:
    """The number of velocities, those closer than DUPLICATE_TOLERANCE (relative) counted once."""
    v = np.sort(np.asarray(velocity, dtype=float))
    return int(1 + np.count_nonzero(np.diff(v) > DUPLICATE_TOLERANCE * v[1:])) if v.size else 0


def _replicate_notes(data: SteadyData) -> list[str]:
    """A note on the repeated velocities (how many rows, at how many velocities), and one naming identical rows."""
    n, distinct = len(data), data.velocities
    if distinct == n:
        return []
    order = np.argsort(data.velocity, kind="stable")
    v = data.velocity[order]
    group = np.r_[0, np.cumsum(np.diff(v) > DUPLICATE_TOLERANCE * v[1:])]
    repeated = int(np.count_nonzero(np.bincount(group) > 1))
    out = [
        f"{data.source}: {n} rows at {distinct} velocities ({repeated} of them measured more than once): each row is"
        " a point of the fit, and the scatter of the repeated ones measures the noise without the model"
    ]
    err = np.zeros(n) if data.stress_err is None else data.stress_err[order]
    same = identical_rows(data.rows[order], [group, data.stress[order], err])
    if same:
        out.append(
            f"warning: {data.source}: identical rows ({same}): replicates that agree to every digit,"
            " or a row entered twice? each counts as a measurement (a copy adds weight and no scatter)"
        )
    return out


def requested_rows(exclude: Sequence[int], rows: np.ndarray, source: str) -> set[int]:
    """The file rows ``exclude`` (``--exclude-row N``, as the warnings number them: the header is row 1), checked
    against the data rows ``rows``: both fits' one parser.  A number that is not an integer is a ParameterError, one
    that is not a data row a DataError, each in one line."""
    if isinstance(exclude, (str, bytes)) or not isinstance(exclude, Sequence | set | frozenset | np.ndarray):
        exclude = [exclude]  # type: ignore[list-item]  # one row given alone: refused below unless an integer
    known = {int(r) for r in rows}
    out: set[int] = set()
    for row in exclude:
        if isinstance(row, bool) or not isinstance(row, (int, np.integer)):
            raise ParameterError(f"exclude_rows: expected file row numbers (integers), got {row!r}")
        if int(row) not in known:
            raise DataError(f"{source}: --exclude-row {row}: no such data row (rows are {_row_span(sorted(known))})")
        out.add(int(row))
    return out


def _row_span(rows: list[int]) -> str:
    """The data rows in a message: all of them where few, else the first and last and how many."""
    if len(rows) <= 12:
        return str(rows)
    return f"{rows[0]} to {rows[-1]}, {len(rows)} rows"


def identical_rows(rows: np.ndarray, columns: Sequence[np.ndarray], shown: int = 5) -> str:
    """The pairs of rows equal in every one of ``columns`` (NaN equal to NaN), "11 and 12; 13 and 14, and 3 more",
    or '' where there are none.  The check of both fits' data (steady, and stick since round 28: a table pasted
    three times gave intervals √3 too narrow without a word)."""
    if not len(rows):
        return ""
    key = np.column_stack([np.asarray(c, dtype=float) for c in columns])
    key = np.where(np.isnan(key), np.inf, key)  # NaN cells (an empty peak stress) compare equal
    order = np.lexsort(key.T[::-1])  # identical rows side by side
    key, ordered = key[order], np.asarray(rows)[order]
    same = np.flatnonzero(np.all(key[1:] == key[:-1], axis=1))
    if not same.size:
        return ""
    found = sorted((min(ordered[k], ordered[k + 1]), max(ordered[k], ordered[k + 1])) for k in same)
    pairs = [f"{a} and {b}" for a, b in found[:shown]]
    more = f", and {same.size - shown} more" if same.size > shown else ""
    return "; ".join(pairs) + more


def _identical_stick_rows(data: StickData) -> list[str]:
    """A warning naming the stick rows identical in every column read (the cycle number too, where there is one)."""
    columns = [data.pulling_velocity, data.stick_time]
    columns += [c for c in (data.peak_stress, data.start_stress) if c is not None]
    columns += [data.extra[name] for name in sorted(data.extra)]
    same = identical_rows(data.rows, columns)
    if not same:
        return []
    what = (
        "the same cycle (its cycle number too) entered twice?"
        if "cycle" in data.extra
        else "replicates that agree to every digit, or a row entered twice?"
    )
    return [
        f"warning: {data.source}: identical rows ({same}), equal in every column: {what} each counts as a stick"
        " phase (a copy adds weight and no scatter, and narrows the intervals; --exclude-row to leave it out)"
    ]


def _validated_stick(table: Table) -> StickData:
    n = len(table)
    _require_positive(
        table,
        ["pulling_velocity", "stick_time", "peak_stress", "start_stress", "stick_slope", "stiffness", "jump_velocity"],
    )
    _require_not_negative(table, STICK_UNCERTAINTIES)
    for name, bounds, unit, what in (
        ("pulling_velocity", VELOCITY_RANGE, "m/s", "a pulling velocity"),
        ("jump_velocity", VELOCITY_RANGE, "m/s", "a sliding velocity"),
        ("stick_time", STICK_TIME_RANGE, "s", "a stick time"),
        ("peak_stress", STRESS_RANGE, "Pa", "a friction stress"),
        ("start_stress", STRESS_RANGE, "Pa", "a friction stress"),
        ("stick_slope", STRESS_RATE_RANGE, "Pa/s", "a stick phase's loading rate"),
        ("stiffness", STIFFNESS_RANGE, "Pa/m", "a block's stiffness"),
    ):
        _require_range(table, name, bounds, unit, what)
    if n < MIN_STICK_ROWS:  # after the values: a wrong one says so however few rows there are
        raise DataError(f"{table.source}: {n} data row(s), expected at least {MIN_STICK_ROWS} stick phases")
    peak = table["peak_stress"] if "peak_stress" in table else None
    start = table["start_stress"] if "start_stress" in table else None
    if peak is not None and start is not None:
        both = np.isfinite(peak) & np.isfinite(start)
        bad = np.nonzero(both & (peak <= start))[0]
        if bad.size:
            k = int(bad[0])
            raise DataError(
                f"{table.source}: row {table.rows[k]}, column 'peak_stress': {peak[k]:g} Pa is not above the"
                f" start_stress {start[k]:g} Pa of the same row"
            )
    kept = ("cycle", "stick_slope", "stiffness", "jump_velocity", *STICK_UNCERTAINTIES, CYCLE_START_TIME)
    extra = {name: table[name] for name in kept if name in table}
    return StickData(table["pulling_velocity"], table["stick_time"], peak, start, table.rows, extra, table.source)
