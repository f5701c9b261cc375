"""Loading protocols as data: what the load point (puller) does, and when.

A :class:`Protocol` is a sequence of :class:`Segment` s, each a constant
load-point velocity held for a duration.  Every experiment friction researchers
run on a rig is one of these: constant pulling, velocity steps, slide-hold-slide,
arbitrary piecewise-constant histories, or a CSV of (time, velocity) change points.

The protocol knows nothing of any model.  The quasi-static bond model, the
time-dependent bond model and rate-and-state friction all read the same object:
``protocol.pieces()`` for the intervals to integrate (a solver stops exactly at
each change, never steps across one), ``velocity_at(t)`` and ``displacement_at(t)``
for the load point's history.  Everything is SI (m/s, s).
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .columns import data_lines, split_header, with_units
from .display import velocity as velocity_text
from .errors import DataError, ParameterError, UnitError, as_written
from .fileio import protect_inputs, read_input_text
from .units import is_quantity, refuse_beyond_float, refused_as_written, si_argument

__all__ = [
    "Protocol",
    "Segment",
    "constant",
    "parse_segment",
    "read_protocol",
    "segments",
    "slide_hold_slide",
    "velocity_steps",
]


@dataclass(frozen=True)
class Segment:
    """The load point moves at ``velocity`` (m/s, >= 0) for ``duration`` (s, > 0).

    Each is a number in SI or a value with its unit (``Segment("0.2 mm/s", "3 s")``, a pint quantity too), read by
    :func:`stickslip.units.si_argument`; the segment holds SI floats."""

    velocity: float
    duration: float

    def __post_init__(self) -> None:
        for name, dimension in (("velocity", "velocity"), ("duration", "time")):
            value = given = getattr(self, name)
            if isinstance(given, str) or (not isinstance(given, float) and is_quantity(given)):  # a number as is
                value = si_argument(given, dimension, f"segment {name}")
                with refused_as_written(given):
                    _check_segment_value(name, value)
            else:
                _check_segment_value(name, value)
            object.__setattr__(self, name, float(value))


def _check_segment_value(name: str, value: Any) -> None:
    """A segment's velocity (m/s, >= 0) or duration (s, > 0), in SI: one ParameterError naming it otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise ParameterError(
            f"segment {name}: expected a number in SI units or a value with its unit"
            f" ({'0.2 mm/s' if name == 'velocity' else '3 s'!r}), got {value!r}"
        )
    refuse_beyond_float(value, f"segment {name}")  # 10**400: a ParameterError, not float()'s OverflowError
    if not math.isfinite(float(value)):
        raise ParameterError(f"segment {name}: expected a finite number, got {value!r}")
    if name == "velocity" and value < 0:
        raise ParameterError(f"segment velocity: expected a value >= 0 m/s, got {value:g}")
    if name == "duration" and value <= 0:
        raise ParameterError(f"segment duration: expected a positive time, got {value:g} s")


@dataclass(frozen=True)
class Protocol:
    """A piecewise-constant load-point velocity history starting at t = 0."""

    segments: tuple[Segment, ...]
    name: str = "segments"

    def __post_init__(self) -> None:
        items = tuple(_sequence(self.segments, "protocol", "Segment"))
        if not items:
            raise ParameterError("protocol: expected at least one segment (velocity and duration)")
        for item in items:
            if not isinstance(item, Segment):
                raise ParameterError(f"protocol: expected Segment items, got {type(item).__name__}")
        object.__setattr__(self, "segments", items)

    @property
    def duration(self) -> float:
        """Total length of the protocol (s)."""
        return float(self.boundaries[-1])

    @property
    def boundaries(self) -> np.ndarray:
        """Segment start times and the end time: ``[0, t1, ..., T]`` (length n + 1)."""
        return np.concatenate([[0.0], np.cumsum([s.duration for s in self.segments])])

    @property
    def velocities(self) -> np.ndarray:
        return np.array([s.velocity for s in self.segments])

    @property
    def change_times(self) -> np.ndarray:
        """Interior times where the velocity changes (solvers must stop exactly there)."""
        b = self.boundaries[1:-1]
        v = self.velocities
        return b[v[1:] != v[:-1]]

    @property
    def initial_velocity(self) -> float:
        return self.segments[0].velocity

    def pieces(self) -> Iterator[tuple[float, float, float]]:
        """``(t_start, t_end, velocity)`` for each segment, in order."""
        b = self.boundaries
        for i, s in enumerate(self.segments):
            yield float(b[i]), float(b[i + 1]), s.velocity

    def velocity_at(self, t: Any) -> np.ndarray:
        """Load-point velocity at times ``t`` (right-continuous; the last segment's beyond the end)."""
        t = _times(t, "velocity_at")
        index = np.clip(np.searchsorted(self.boundaries, t, side="right") - 1, 0, len(self.segments) - 1)
        return self.velocities[index]

    def displacement_at(self, t: Any) -> np.ndarray:
        """Load-point displacement since t = 0 (m): the exact integral of the velocity."""
        t = _times(t, "displacement_at")
        b = self.boundaries
        v = self.velocities
        start_disp = np.concatenate([[0.0], np.cumsum(v * np.diff(b))])
        index = np.clip(np.searchsorted(b, t, side="right") - 1, 0, len(v) - 1)
        return start_disp[index] + v[index] * (t - b[index])

    def to_frame(self) -> Any:
        import pandas as pd

        b = self.boundaries
        return with_units(pd.DataFrame({"start": b[:-1], "end": b[1:], "velocity": self.velocities}))

    def describe(self) -> str:
        """One line a person can read: ``100 µm/s for 10 s, then 1000 µm/s for 20 s``."""
        parts = [f"{velocity_text(s.velocity)} for {s.duration:g} s" for s in self.segments]
        return ", then ".join(parts)

    def plot(self, ax: Any = None) -> Any:
        from .plots.steady import protocol_plot

        return protocol_plot(self, ax=ax)


def constant(velocity: float | str, duration: float | str) -> Protocol:
    """Pulling at one velocity for ``duration``: numbers in SI (m/s, s) or values with their units
    (``constant("0.2 mm/s", "3 s")``), as every builder here takes them."""
    return Protocol((Segment(velocity, duration),), name="constant")


def segments(items: Sequence[tuple[float, float] | Segment]) -> Protocol:
    """Piecewise-constant velocities from ``[(velocity, duration), ...]``."""
    return Protocol(
        tuple(_as_segment(item) for item in _sequence(items, "segments", "(velocity, duration) pairs")), name="segments"
    )


def _sequence(items: Any, name: str, what: str = "numbers in SI units") -> list[Any]:
    """``items`` as a list; a string, None or a number is a ParameterError naming ``name``."""
    if isinstance(items, (str, bytes)) or not hasattr(items, "__iter__"):
        raise ParameterError(f"{name}: expected a sequence of {what}, got {items!r}")
    return list(items)


def velocity_steps(velocities: Sequence[float], durations: Sequence[float] | float) -> Protocol:
    """Velocity steps: ``velocities[i]`` held for ``durations[i]`` (or one duration for all); each a number in SI
    or a value with its unit (``velocity_steps(["1 um/s", "10 um/s"], "20 s")``)."""
    velocities = _sequence(velocities, "velocities")
    if isinstance(durations, (str, int, float, np.floating, np.integer)) and not isinstance(durations, bool):
        durations = [durations] * len(velocities)  # one duration for all ("10 s" too: each segment reads it)
    elif is_quantity(durations) and np.ndim(durations.magnitude) == 0:
        durations = [durations] * len(velocities)
    durations = _sequence(durations, "durations")
    if len(durations) != len(velocities):
        raise ParameterError(
            f"velocity_steps: {len(velocities)} velocities but {len(durations)} durations; expected one duration each"
        )
    return Protocol(tuple(Segment(v, d) for v, d in zip(velocities, durations, strict=True)), name="velocity steps")


def slide_hold_slide(
    slide_velocity: float,
    slide_time: float,
    hold_time: float,
    reslide_time: float | None = None,
    hold_velocity: float = 0.0,
) -> Protocol:
    """Slide at ``slide_velocity``, hold (load point still, or at ``hold_velocity``), slide again (numbers in SI
    or values with their units, ``slide_hold_slide("10 um/s", "20 s", "100 s")``)."""
    reslide = slide_time if reslide_time is None else reslide_time
    return Protocol(
        (Segment(slide_velocity, slide_time), Segment(hold_velocity, hold_time), Segment(slide_velocity, reslide)),
        name="slide-hold-slide",
    )


def _times(t: Any, method: str) -> np.ndarray:
    """Times (s) as floats, or one ParameterError naming the method: 'x' or NaN is no time."""
    try:
        times = np.asarray(t, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(
            f"Protocol.{method}(t): expected a time in seconds or an array of them, got {t!r}"[:300]
        ) from None
    if np.isnan(times).any():
        raise ParameterError(f"Protocol.{method}(t): expected times in seconds, got NaN")
    return times


def split_segment(text: str, name: str, example: str) -> tuple[str, str, str]:
    """``"V:T"`` as (V, ":", T) (``str.rpartition``), refusing a third field ("50 um/s:30 s:3" is not a duration
    without its unit); ``example`` ends the message (``'100 um/s:10 s'``)."""
    velocity_text, sep, duration_text = str(text).rpartition(":")
    if ":" in velocity_text:
        raise ParameterError(
            f"{name} {text!r}: expected VELOCITY:DURATION (two fields, one colon), got {str(text).count(':') + 1}"
            f" fields; e.g. {example}"
        )
    return velocity_text, sep, duration_text


def parse_segment(text: str, name: str = "--segment") -> Segment:
    """``"100 um/s:10 s"`` (velocity, colon, duration; units optional, bare numbers SI) to a Segment."""
    from .units import to_si

    velocity_text, sep, duration_text = split_segment(text, name, "'100 um/s:10 s'")
    if not sep or not velocity_text.strip() or not duration_text.strip():
        raise ParameterError(f"{name} {text!r}: expected VELOCITY:DURATION, e.g. '100 um/s:10 s'")
    velocity = to_si(velocity_text.strip(), "velocity", f"{name} velocity")
    duration = to_si(duration_text.strip(), "time", f"{name} duration")
    try:
        return Segment(velocity, duration)
    except ParameterError as exc:  # named as written ("got '-5 um/s'"), not in SI
        message = str(exc)
        written = velocity_text if message.startswith("segment velocity") else duration_text
        raise ParameterError(f"{name} {text!r}: {as_written(message, written)}") from None


def _refuse_duplicated_columns(text: str, path: Path) -> None:
    """A header naming a column twice (``velocity,velocity,duration``) is ambiguous: which one is meant?

    pandas would rename the second ``velocity.1`` and read the first silently; the data readers refuse it, so here too.
    """
    import csv

    for line in text.splitlines():
        if line.strip() and not line.lstrip().startswith("#"):
            try:
                dialect = csv.Sniffer().sniff(line, delimiters=",\t;")
                names = next(csv.reader([line], dialect))
            except csv.Error:
                names = line.split(",")
            seen: set[str] = set()
            for name in (split_header(n, parentheses=True)[0].lower() for n in names):
                if name and name in seen:
                    raise DataError(f"{path}: the column {name!r} appears twice in the header; keep one")
                seen.add(name)
            return


def _refuse_extra_fields(text: str, sep: str, path: Path) -> None:
    """A data row with more fields than the header (``0,350e-6,5`` under ``time,velocity``) is refused naming
    that row: pandas would take its first field for an index and blame a later row."""
    import csv

    from .units import shorten

    header: list[str] | None = None
    for number, line in enumerate(text.split("\n"), 1):
        kept = line.split("#", 1)[0]
        if not kept.strip():
            continue
        try:
            fields = next(csv.reader([kept.rstrip("\r")], delimiter=sep))
        except (csv.Error, StopIteration):
            return  # a quoted line end: left to the CSV reader
        if header is None:
            header = fields
        elif len(fields) > len(header):
            names = ",".join(f.strip() for f in header)
            raise DataError(
                f"{path}: row {number}: expected {len(header)} fields ({names}), got {len(fields)}:"
                f" {shorten(kept.strip())}"
            )


def read_protocol(path: str | Path, *, negative_time: str = "") -> Protocol:
    """A protocol from a CSV file.

    ``negative_time``: where a reader's time starts at 0 (``rsf fit``: the record's first row), why a negative
    change time is refused (a DataError naming the row); by default the first row's time is the start, whatever it is.

    Two layouts, told apart by the header (SI units, or the unit a header cell names as the package writes
    them, ``time [ms]``; comma, tab or semicolon separated):

    * ``velocity,duration``: one segment per row;
    * ``time,velocity``: change points.  ``velocity`` holds from that row's
      ``time`` until the next row's; the last row marks the end of the protocol
      (its velocity is not used).  Times must increase strictly; the first
      row's time is taken as the start.

    Lines starting with ``#`` are comments.  The format, with an example file shipped in the package
    (``data/slide-hold-slide.csv``), is described in docs/protocols.md.
    """
    import csv
    import io

    import pandas as pd

    if not isinstance(path, (str, os.PathLike)):
        raise DataError(f"protocol file: expected a path, got {type(path).__name__}")
    path = Path(path)
    text = _protocol_text(path)
    protect_inputs([path])  # in a command, no output may replace the protocol
    if not text.strip():
        raise DataError(f"{path}: empty file, expected a CSV with columns time,velocity or velocity,duration")
    # the separator from the header (pandas' sniffer took the "t" of a lone "time" column for one)
    header = next((line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#")), "")
    sep = "\t" if "\t" in header else ";" if header.count(";") > header.count(",") else ","
    _refuse_extra_fields(text, sep, path)
    try:
        frame = pd.read_csv(io.StringIO(text), sep=sep, comment="#", nrows=1_000_000)
    except (ValueError, csv.Error, pd.errors.ParserError) as exc:  # csv.Error: no delimiter could be found
        raise DataError(f"{path}: cannot read as CSV ({(str(exc).splitlines() or [''])[0]})") from None
    # a header cell may carry its unit, as the package writes CSV headers: "time [s]", "velocity [um/s]"
    columns = {split_header(str(c), parentheses=True)[0].lower(): c for c in frame.columns}
    _refuse_duplicated_columns(text, path)
    if {"time", "duration"} <= set(columns):  # which layout is meant? (read as segments, the times were ignored)
        raise DataError(
            f"{path}: the header has both time and duration; give time,velocity (change points) or velocity,duration"
            " (segments)"
        )
    text_lines = text.split("\n")
    found_lines = data_lines(text_lines, len(frame))
    lines = found_lines or list(range(2, len(frame) + 2))
    raw = _RawRows(text_lines if found_lines else None, sep, list(frame.columns))
    if {"velocity", "duration"} <= set(columns):
        cols = [columns["velocity"], columns["duration"]]
        pairs = _numeric_rows(frame, path, cols, lines, raw)
        velocity, duration = (_Written(c, d, path) for c, d in zip(cols, ("velocity", "time"), strict=True))
        try:
            return Protocol(
                tuple(
                    _checked_segment(v, d, path, lines[i], velocity.text(v), duration.text(d))
                    for i, (v, d) in enumerate(pairs)
                ),
                name=path.name,
            )
        except ParameterError as exc:
            raise DataError(str(exc)) from None
    if {"time", "velocity"} <= set(columns):
        cols = [columns["time"], columns["velocity"]]
        rows = _numeric_rows(frame, path, cols, lines, raw)
        if len(rows) < 2:
            raise DataError(f"{path}: expected at least two rows (a start and an end time), got {len(rows)}")
        time, velocity = (_Written(c, d, path) for c, d in zip(cols, ("time", "velocity"), strict=True))
        items = []
        early = next((i for i, (t, _) in enumerate(rows) if t < 0), None) if negative_time else None
        if early is not None:
            shown = time.text(rows[early][0])
            raise DataError(f"{path}: row {lines[early]}: time {shown} is negative; {negative_time}")
        for i in range(len(rows) - 1):
            (t0, v), (t1, _) = rows[i], rows[i + 1]
            if not t1 > t0:
                raise DataError(
                    f"{path}: row {lines[i + 1]}: time {time.text(t1)} does not increase (previous {time.text(t0)})"
                )
            items.append(_checked_segment(v, t1 - t0, path, lines[i], velocity.text(v), time.text(t1 - t0)))
        return Protocol(tuple(items), name=path.name)
    found = ", ".join(str(c) for c in frame.columns) or "none"
    raise DataError(f"{path}: expected columns time,velocity or velocity,duration (SI units); found {found}")


#: Largest protocol file read (a million change points is about 30 MB).
MAX_PROTOCOL_BYTES = 100_000_000


def _protocol_text(path: Path) -> str:
    """The protocol file's text; a gzip file (:func:`stickslip.tables.is_gzip`, as every reader) decompressed."""
    from .tables import is_gzip, open_input

    subject = f"protocol file {path}"
    if not is_gzip(path):
        return read_input_text(path, subject, MAX_PROTOCOL_BYTES)
    with open_input(path, "rb") as handle:
        data = handle.read(MAX_PROTOCOL_BYTES + 1)
    if len(data) > MAX_PROTOCOL_BYTES:
        raise DataError(f"{subject}: more than {MAX_PROTOCOL_BYTES} bytes decompressed; at most that many are read")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise DataError(f"{subject}: not a text (UTF-8) file ({exc.reason} at byte {exc.start})") from None


@dataclass(frozen=True)
class _RawRows:
    """The file's lines (None where its rows cannot be matched to them), its separator and the frame's columns:
    a bad row quoted as written."""

    lines: list[str] | None
    sep: str
    columns: list[Any]

    def cells(self, line: int, frame_row: Any, cols: list[Any]) -> tuple[list[str], str]:
        """The cells of ``cols`` in file line ``line`` as written, and the whole line ("" where not known)."""
        import csv

        if self.lines is not None and 0 < line <= len(self.lines):
            text = self.lines[line - 1].split("#", 1)[0].strip()
            try:
                fields = next(csv.reader([text], delimiter=self.sep))
            except (csv.Error, StopIteration):
                fields = text.split(self.sep)
            positions = [self.columns.index(c) for c in cols]
            return [fields[k].strip() if k < len(fields) else "" for k in positions], text
        values = frame_row.tolist()
        return ["" if isinstance(v, float) and math.isnan(v) else str(v).strip() for v in values], ""


class _Written:
    """A protocol column's values as the file writes them: its unit from its header (SI where it names none)."""

    def __init__(self, column: Any, dimension: str, path: Path) -> None:
        from .units import DIMENSIONS

        self.name = str(column).strip()
        self.factor = _header_factor(column, dimension, path)
        self.unit = split_header(self.name, parentheses=True)[1] or DIMENSIONS[dimension][1]

    def text(self, value: float) -> str:
        """``value`` (SI) as written: "400 ms", "-5 um/s"."""
        return f"{value / self.factor:.10g} {self.unit}"


def _numeric_rows(
    frame: Any, path: Path, cols: list[Any], lines: list[int], raw: _RawRows | None = None
) -> list[tuple[float, float]]:
    """The two columns' numbers in SI, row by row; a DataError naming the first row with a cell that is empty,
    no number or not finite, quoting that cell and the row as written."""
    import pandas as pd

    from .units import shorten

    data = frame[cols].apply(pd.to_numeric, errors="coerce").to_numpy(dtype=float)
    data = data * [
        _header_factor(c, "velocity" if split_header(str(c), True)[0].lower() == "velocity" else "time", path)
        for c in cols
    ]
    bad = ~np.isfinite(data).all(axis=1)
    if bad.any():
        row = int(np.argmax(bad))
        raw = raw if raw is not None else _RawRows(None, ",", list(frame.columns))
        cells, text = raw.cells(lines[row], frame.iloc[row][cols], cols)
        problems = []
        for column, cell, value in zip(cols, cells, data[row], strict=True):
            if math.isfinite(value):
                continue
            name = str(column).strip()
            if not cell:
                problems.append(f"{name}: empty cell")
            elif math.isnan(value) and cell.lower() not in ("nan", "-nan", "+nan"):
                problems.append(f"{name}: {shorten(cell)} is not a number")
            else:
                problems.append(f"{name}: {shorten(cell)} is not a finite number")
        names = ", ".join(str(c).strip() for c in cols)
        quoted = f" (the row reads {shorten(text)})" if text else ""
        said = "; ".join(problems)
        raise DataError(f"{path}: row {lines[row]}: expected two finite numbers ({names}); {said}{quoted}")
    return [(float(a), float(b)) for a, b in data]


def _header_factor(column: Any, dimension: str, path: Path) -> float:
    """The SI factor of a header cell's unit (``"time [ms]"``: 1e-3); a bare name is SI already."""
    from .units import to_si

    unit = split_header(str(column), parentheses=True)[1]
    if not unit:
        return 1.0
    try:
        return to_si(f"1 {unit}", dimension, f"column {str(column).strip()!r}")
    except UnitError as exc:
        raise DataError(f"{path}: {exc}") from None


def _checked_segment(
    velocity: float, duration: float, path: Path, line: int, velocity_text: str = "", duration_text: str = ""
) -> Segment:
    """A segment of a protocol file's row; refused naming the row and the value as the file writes it, with its
    unit (``velocity_text``, ``duration_text``: "-5 um/s", "400 ms")."""
    try:
        return Segment(velocity, duration)
    except ParameterError as exc:
        message = str(exc)
        written = velocity_text if message.startswith("segment velocity") else duration_text
        if written:
            message = f"{message.split(':', 1)[0]}: {_expected(message)}, got {written}"
        raise DataError(f"{path}: row {line}: {message}") from None


def _expected(message: str) -> str:
    """The "expected ..." part of a segment's refusal, without its value: "expected a value >= 0"."""
    body = message.split(":", 1)[1].strip() if ":" in message else message
    body = body.rsplit(", got ", 1)[0]
    return body.replace(" >= 0 m/s", " >= 0").replace("a positive time", "a positive duration")


def _as_segment(item: tuple[float, float] | Segment) -> Segment:
    if isinstance(item, Segment):
        return item
    try:
        velocity, duration = item
    except (TypeError, ValueError):
        raise ParameterError(f"protocol: expected (velocity, duration) pairs, got {item!r}") from None
    return Segment(velocity, duration)
