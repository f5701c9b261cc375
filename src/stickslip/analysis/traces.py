"""Measured stress-time records: reading a CSV trace and checking it.

A ``time`` column and ``stress`` or ``force`` (over a contact area), units in header brackets (bare names are SI);
gaps, jumps at one instant, duplicated rows and the package's own trace columns (:data:`MODEL_COLUMNS`, and any
state column of a Run CSV: :func:`run_state_columns`; ignored with a note) are handled as docs/analysis.md says.
Every problem is a typed error naming the file and row.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from ..columns import with_units
from ..errors import DataError, ParameterError
from ..reprs import compact_repr
from ..tables import Table, read_table, read_text_cells
from ..trace_columns import MODEL_COLUMNS

#: Fewest usable (finite-stress) samples a trace must have.
MIN_SAMPLES = 20
#: Largest |time| (s) and |stress| (Pa) accepted.
MAX_MAGNITUDE = 1e100

TRACE_DIMENSIONS = {"time": "time", "stress": "stress", "force": "force"}


@dataclass(frozen=True)
class Trace:
    """A stress record: ``time`` (s) and ``stress`` (Pa, NaN in gaps), with the file rows."""

    __repr__ = compact_repr  # counts, not hundreds of array elements

    time: np.ndarray
    stress: np.ndarray
    rows: np.ndarray
    source: str
    notes: tuple[str, ...] = ()  # what the reader did that a user should know (ignored columns, merged rows)

    @property
    def valid(self) -> np.ndarray:
        """Boolean mask of the samples with a finite stress."""
        return np.isfinite(self.stress)

    @property
    def duration(self) -> float:
        return float(self.time[-1] - self.time[0])

    def to_frame(self) -> Any:
        import pandas as pd

        return with_units(pd.DataFrame({"time": self.time, "stress": self.stress}))


def read_trace(path: str | Path, contact_area: float | None = None) -> Trace:
    """Read a trace CSV: ``time`` and ``stress``, or ``time`` and ``force`` with ``contact_area`` (m^2).

    Raises :class:`DataError` for a missing column, a bad cell, a time that
    goes back, a duplicated row of a record of time and stress alone, or too few usable samples (two rows at one
    time with different stresses are a jump and are kept; a model trace's row that repeats the time and stress
    of the row before is read once, with a note); :class:`ParameterError` for a
    missing, superfluous or non-positive contact area.
    """
    if not isinstance(path, (str, Path)) and not hasattr(path, "__fspath__"):
        raise DataError(f"read_trace: expected a file name (str or Path), got {type(path).__name__}")
    states = run_state_columns(path)
    table = read_table(
        path,
        TRACE_DIMENSIONS,
        required=["time"],
        allow_missing=["stress", "force"],
        ignore=(*MODEL_COLUMNS, *states),
    )
    has_stress, has_force = "stress" in table, "force" in table
    if has_stress and has_force:
        raise DataError(f"{table.source}: give either a 'stress' or a 'force' column, not both")
    if not (has_stress or has_force):
        hint = (
            "; its 'friction' column is a friction coefficient, not a stress: multiply it by the normal stress"
            " and name the column 'stress [Pa]'"
            if "friction" in table.ignored
            else ""
        )
        raise DataError(f"{table.source}: missing column 'stress' (or 'force' with a contact area){hint}")
    if has_force:
        if contact_area is None:
            raise ParameterError(f"{table.source}: the trace has a 'force' column; give the contact area to convert it")
        area = _positive_area(contact_area)
        stress = table["force"] / area
    else:
        if contact_area is not None:
            raise ParameterError(
                f"{table.source}: a contact area was given but the trace has a 'stress' column; it needs none"
            )
        stress = table["stress"]
    notes = list(table.notes)  # how the file was read, where not as usual (decimal commas)
    if table.ignored:
        own = [n for n in table.ignored if n in states]
        said = f" ({', '.join(own)}: the model's state, as Run.read reads it)" if own else ""
        notes.append(f"ignored column(s) {', '.join(table.ignored)}{said}: analyze reads time and stress only")
    time, stress, rows, merged = _merge_model_repeats(path, table, stress)
    notes.extend(merged)
    trace = check_trace(time, stress, source=table.source, rows=rows)
    return replace(trace, notes=tuple(notes))


#: the columns by which a CSV is a Run CSV (``Run.read`` requires them; any further column is a model's state)
RUN_BASE = ("time", "slider_velocity", "slider_position", "load_point_position")


def run_state_columns(path: str | Path) -> tuple[str, ...]:
    """The columns of a Run CSV (one with :data:`RUN_BASE`, which ``Run.read`` reads) beyond the package's known
    ones: a plug-in model's state variables (``theta [s]``), read by ``Run.read`` as states and ignored by
    ``analyze`` as the built-in models' are.  () for any other file: there an unknown column stays an error."""
    from ..tables import header_names

    names = header_names(path)
    if not set(RUN_BASE) <= set(names):
        return ()
    known = {*TRACE_DIMENSIONS, *MODEL_COLUMNS}
    return tuple(dict.fromkeys(n for n in names if n and n not in known))


#: the load-point columns of the package's own traces (Run CSV; old transient and rate-and-state traces)
LOAD_POINT_COLUMNS = ("load_point_position", "puller_position", "load_point_displacement")


def recorded_pulling_velocity(path: str | Path) -> tuple[float | None, str]:
    """The pulling velocity (m/s) a package trace records, when its load point moves at one velocity throughout.

    Returns (velocity, "") or (None, why not): a trace without a load-point column, or whose load point changes
    velocity (a protocol of segments), has no one pulling velocity to analyse at.
    """
    found = _load_point(path)
    if found is None:
        return None, "the trace has no load-point column (" + ", ".join(LOAD_POINT_COLUMNS) + ")"
    return _one_velocity(*found)


#: the package's bond models, whose Run CSV records the critical velocity of the parameter set it was run with
BOND_MODELS = ("quasi-static", "transient")
#: a recorded Vc and the parameter set's agree within this fraction (both come from one solver, to ~1e-12)
VC_AGREEMENT = 1e-4


def recorded_run(path: str | Path) -> dict[str, Any] | None:
    """The metadata a Run CSV (``run -o`` and its spellings) holds in its first line, ``# stickslip run {...}``;
    None for any other file (or one whose first line is no such mapping)."""
    from ..models.run import CSV_MARK

    path = Path(path)
    if not path.is_file():
        return None
    try:
        with open(path, encoding="utf-8", errors="replace") as handle:
            first = handle.readline(1 << 20)
    except OSError:
        return None
    if not first.startswith(CSV_MARK):
        return None
    try:
        meta = json.loads(first[len(CSV_MARK) :])
    except ValueError:
        return None
    return meta if isinstance(meta, dict) else None


def parameter_mismatch(path: str | Path, params: Any) -> str:
    """Why the bond-model run a trace records was not made with ``params`` ("" when it was, or cannot be told).

    A Run CSV holds no parameter set, but a bond model's (quasi-static, transient) records its critical velocity
    Vc, which depends on the bond and aging parameters alone: a Vc other than ``params``' is a run made with
    another set (the block's geometry, which Gd/h uses, is not seen by it).
    """
    meta = recorded_run(path)
    if meta is None or meta.get("model") not in BOND_MODELS:
        return ""
    summary = meta.get("summary")
    recorded = summary.get("critical_velocity") if isinstance(summary, dict) else None
    if not isinstance(recorded, (int, float)) or not math.isfinite(recorded) or recorded <= 0:
        return ""  # no Vc recorded (the transient model's summary has none): nothing to check against
    from ..quasistatic.critical import critical_minimum

    try:
        point = critical_minimum(params)
    except (ParameterError, DataError):
        return ""
    ours = None if point is None else point.velocity
    if ours is not None and abs(ours - recorded) <= VC_AGREEMENT * recorded:
        return ""
    said = "none (no minimum of its aging curve)" if ours is None else f"{ours * 1e6:.6g} µm/s"
    return (
        f"the {meta['model']} run it records was made with another parameter set: its critical velocity Vc is"
        f" {recorded * 1e6:.6g} µm/s, {params.name}'s is {said}; Vs and Gd/h here are {params.name}'s (give"
        " --params with the set the run was made with)"
    )


#: A load point moves at one velocity when no position lies further from the straight line fitted to them all than
#: this fraction of its travel (a model's load point, written to 17 digits) ...
WANDER_FRACTION = 1e-6
#: ... or than the column's own rounding, QUANTUM_WANDER of its quantum q (an encoder writing whole steps q lies
#: within q/2 of the line), plus this many standard deviations of the noise it has beyond that rounding.
QUANTUM_WANDER = 0.6
WANDER_SIGMAS = 6.0


def _one_velocity(name: str, t: np.ndarray, x: np.ndarray) -> tuple[float | None, str]:
    """(velocity, "") of a load point that moves at one velocity throughout, else (None, why not).

    The positions lie on one straight line to within :func:`_wander_tolerance`: the travel's 1e-6, or the column's
    own quantum and noise (a measured load point written in whole encoder steps).  A velocity step moves them off
    any one line by a good part of the travel times the step's relative size."""
    if not _usable(t, x):
        return None, f"its {name} column does not give a velocity"
    slope, offset = np.polyfit(t - t[0], x, 1)
    wander = float(np.max(np.abs(x - (offset + slope * (t - t[0])))))
    if not slope > 0 or wander > _wander_tolerance(t, x):
        return None, f"its load point ({name}) does not move at one velocity throughout"
    return float(slope), ""


def _wander_tolerance(t: np.ndarray, x: np.ndarray) -> float:
    """How far (m) a load point moving at one velocity may lie from its fitted line: :data:`WANDER_FRACTION` of its
    travel, or :data:`QUANTUM_WANDER` of the column's quantum (numerics.quantisation) plus :data:`WANDER_SIGMAS`
    of its noise beyond the rounding's q/sqrt(12) (detect.noise_level, which sees correlated noise too), if more."""
    from ..numerics.quantisation import quantum
    from .detect import noise_level

    travel = WANDER_FRACTION * abs(float(x[-1] - x[0]))
    if t.size < 3:
        return travel
    q = quantum(x[:1_000_000])
    extra = math.sqrt(max(noise_level(t, x) ** 2 - q**2 / 12.0, 0.0))
    return max(travel, QUANTUM_WANDER * q + WANDER_SIGMAS * extra)


def _load_point(path: str | Path) -> tuple[str, np.ndarray, np.ndarray] | None:
    """(column, time, position) of a trace's first load-point column; None without one."""
    for name in LOAD_POINT_COLUMNS:
        others = [c for c in (*MODEL_COLUMNS, *run_state_columns(path), "stress", "force") if c != name]
        try:
            table = read_table(path, {"time": "time", name: "length"}, required=["time", name], ignore=others)
        except DataError:
            continue
        return name, table["time"], table[name]
    return None


def _usable(t: np.ndarray, x: np.ndarray) -> bool:
    """Whether a load-point column gives a velocity: two rows or more, all finite, over a time that moves on."""
    return bool(t.size >= 2 and np.all(np.isfinite(t)) and np.all(np.isfinite(x)) and t[-1] > t[0])


#: Successive load-point velocities within this fraction of the largest one are one velocity ...
STEP_TOLERANCE = 1e-4
#: ... and a stretch at one velocity counts when it lasts at least this fraction of the record (the interval that
#: straddles a step has a velocity between the two).
STEP_MIN_FRACTION = 0.01
#: More stretches than this are no velocity steps but a load point that wanders (a measured one): none reported.
STEP_MAX_SEGMENTS = 20


def load_point_velocities(path: str | Path) -> tuple[str | None, list[tuple[float, float, float]]]:
    """(column, [(from, to, velocity), ...]): the stretches of the record over which its load point moves at one
    velocity (s, s, m/s), in time order; (None, []) without a load-point column, (column, []) when the load point
    does not move in stretches of one velocity.  One stretch: the velocity of :func:`recorded_pulling_velocity`;
    several: velocity steps (a transient protocol, or records spliced together)."""
    found = _load_point(path)
    if found is None:
        return None, []
    name, t, x = found
    velocity, _ = _one_velocity(name, t, x)
    if not _usable(t, x):
        return name, []
    if velocity is not None:
        return name, [(float(t[0]), float(t[-1]), velocity)]
    dt = np.diff(t)
    moving = dt > 0
    v = np.diff(x)[moving] / dt[moving]
    start, end = t[:-1][moving], t[1:][moving]
    scale = float(np.max(np.abs(v))) if v.size else 0.0
    if not scale > 0:
        return name, []
    breaks = np.flatnonzero(np.abs(np.diff(v)) > STEP_TOLERANCE * scale) + 1
    segments = []
    for a, b in zip([0, *breaks], [*breaks, v.size], strict=True):
        if end[b - 1] - start[a] >= STEP_MIN_FRACTION * float(t[-1] - t[0]):
            segments.append((float(start[a]), float(end[b - 1]), float(np.median(v[a:b]))))
    merged: list[tuple[float, float, float]] = []
    for segment in segments:  # stretches either side of a kink at one velocity (an event of the run) are one
        if merged and abs(segment[2] - merged[-1][2]) <= STEP_TOLERANCE * scale:
            merged[-1] = (merged[-1][0], segment[1], merged[-1][2])
        else:
            merged.append(segment)
    segments = merged
    if not 2 <= len(segments) <= STEP_MAX_SEGMENTS:
        return name, []
    return name, segments


def _merge_model_repeats(
    path: str | Path, table: Table, stress: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[str, ...]]:
    """Rows of a model trace (one with ignored columns) that repeat the time and stress of the row before, read once.

    A model trace writes such rows where its state changes at one instant (the chain fraction running out at the
    end of a stick: they differ in an ignored column), and where its solver stops at an event and starts again from
    the state it stopped at (a stick of the docs' velocity-weakening plug-in: the row repeats in every column); for
    the analysis either is one sample.  A record of time and stress alone has no other column to tell a model's
    repeat by: there a repeated row stays refused (:func:`check_trace`).  Returns (time, stress, rows, notes).
    """
    time, rows = table["time"], table.rows
    repeats = _repeated_samples(time, stress)
    if repeats.size == 0 or not table.ignored:
        return time, stress, rows, ()
    same = np.ones(repeats.size, dtype=bool)
    for column in read_text_cells(path, table.ignored, count=time.size).values():
        same &= column[repeats] == column[repeats - 1]
    keep = np.ones(time.size, dtype=bool)
    keep[repeats] = False
    notes = []
    exact, merged = repeats[same], repeats[~same]
    if exact.size:
        notes.append(
            f"{exact.size} row(s) repeat the row before in every column (first: row {rows[exact[0]]}), as a"
            " model's solver writes where it stops at an event and starts again: read once"
        )
    if merged.size:
        notes.append(
            f"{merged.size} row(s) repeat the time and stress of the row before and differ only in the"
            f" ignored columns (first: row {rows[merged[0]]}): read once"
        )
    return time[keep], stress[keep], rows[keep], tuple(notes)


def _repeated_samples(time: np.ndarray, stress: np.ndarray) -> np.ndarray:
    """Indices of samples that repeat the time and the stress (or the gap) of the sample before."""
    same_time = time[1:] == time[:-1]
    if not np.any(same_time):
        return np.empty(0, dtype=int)
    same_stress = (stress[1:] == stress[:-1]) | (np.isnan(stress[1:]) & np.isnan(stress[:-1]))
    return np.flatnonzero(same_time & same_stress) + 1


def check_trace(
    time: Any,
    stress: Any,
    source: str = "trace",
    rows: Sequence[int] | np.ndarray | None = None,
) -> Trace:
    """Validate a record given as arrays and return it as a :class:`Trace`.

    ``rows`` (file row numbers) are used in messages; without them samples are
    named by their 0-based index.
    """
    t = _as_vector(time, "time", source)
    s = _as_vector(stress, "stress", source)
    if t.size != s.size:
        raise DataError(f"{source}: time has {t.size} values but stress has {s.size}")
    labels = np.arange(t.size) if rows is None else np.asarray(rows, dtype=int)
    where = "row" if rows is not None else "sample"
    bad = np.nonzero(~np.isfinite(t))[0]
    if bad.size:
        raise DataError(f"{source}: {where} {labels[bad[0]]}: time is missing or not finite")
    bad = np.nonzero(np.isinf(s))[0]
    if bad.size:
        raise DataError(f"{source}: {where} {labels[bad[0]]}: stress is infinite")
    for name, values, unit in (("time", t, "s"), ("stress", s, "Pa")):
        # the fits square sums of these: keep them far from overflow (no record comes near 1e100)
        bad = np.flatnonzero(np.abs(values) > MAX_MAGNITUDE)
        if bad.size:
            raise DataError(
                f"{source}: {where} {labels[bad[0]]}: {name} {values[bad[0]]:g} {unit} is beyond"
                f" {MAX_MAGNITUDE:g} {unit} in magnitude; not a measured record"
            )
    _require_friction_stress(s, labels, where, source)
    back = np.flatnonzero(t[1:] < t[:-1])
    if back.size:
        k = back[0] + 1
        raise DataError(
            f"{source}: {where} {labels[k]}: time {t[k]:g} s goes back from the previous time {t[k - 1]:g} s;"
            " times must never decrease (sort the record)"
        )
    repeats = _repeated_samples(t, s)
    if repeats.size:
        k = repeats[0]
        raise DataError(
            f"{source}: {where} {labels[k]}: time {t[k]:g} s repeats the previous time {t[k - 1]:g} s with the same"
            " stress: a duplicated row (remove it; a repeated time with a different stress is read as a jump)"
        )
    usable = int(np.count_nonzero(np.isfinite(s)))
    if usable < MIN_SAMPLES:
        raise DataError(
            f"{source}: record too short: {usable} samples with a stress value, need at least {MIN_SAMPLES}"
        )
    if t[-1] == t[0]:
        raise DataError(f"{source}: every sample is at time {t[0]:g} s; a record must span some time")
    return Trace(time=t, stress=s, rows=np.asarray(labels), source=source)


def _require_friction_stress(s: np.ndarray, labels: np.ndarray, where: str, source: str) -> None:
    """A stress beyond the range of a friction stress that ``fit steady`` checks, or a record whose every stress
    is below its floor, is a unit read wrong (MPa written as Pa, a force without its area): refused in one line."""
    from ..fitting.data import STRESS_RANGE

    low, high = STRESS_RANGE
    beyond = np.flatnonzero(np.abs(s) > high)
    if beyond.size:
        k = beyond[0]
        raise DataError(
            f"{source}: {where} {labels[k]}: stress {s[k]:g} Pa is beyond the range of a friction stress"
            f" ({high:g} Pa); check the units in the header"
        )
    largest = float(np.nanmax(np.abs(s))) if np.isfinite(s).any() else math.nan
    if 0.0 < largest < low:
        raise DataError(
            f"{source}: every stress is below {low:g} Pa in magnitude (largest {largest:g} Pa), under the range of"
            " a friction stress; check the units in the header"
        )


def _as_vector(values: Any, name: str, source: str) -> np.ndarray:
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise DataError(f"{source}: {name}: expected numbers") from None
    if array.ndim != 1:
        raise DataError(f"{source}: {name}: expected a one-dimensional array, got shape {array.shape}")
    return array


def _positive_area(value: Any) -> float:
    try:
        area = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"contact_area: expected an area in m^2, got {value!r}") from None
    if not math.isfinite(area) or area <= 0:
        raise ParameterError(f"contact_area: expected a positive area, got {value!r}")
    return area
