"""Lab records for rate-and-state fits: delimited text as rigs write it, and the load-point history.

A record has time, load-point displacement (or the load point's velocity, integrated) and friction (or a shear
stress over a normal stress), its columns found by name or mapped with ``columns={...}``, each in the unit its
header names, else ``displacement_unit`` / ``time_unit``, else SI; its separator and decimal mark are
:func:`stickslip.tables.text_format`'s, as every reader's.  The history comes from the displacement:
:func:`find_segments` (velocity levels) or :func:`measured_history` (the smoothed displacement).  How each works:
docs/rsf.md, "Reading a record".
"""

from __future__ import annotations

import itertools
import math
import re
import warnings
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from ..columns import with_units
from ..errors import DataError, ParameterError
from ..fileio import protect_inputs, require_input_file
from ..numerics.quantisation import quantum
from ..protocols import Protocol, Segment
from ..tables import open_input

__all__ = [
    "LabRecord", "change_time_uncertainty", "find_segments", "forward", "level_velocity_uncertainty",
    "measured_history", "parse_columns", "read_record",
]  # fmt: skip

ROLES = ("time", "displacement", "friction", "velocity", "shear_stress", "normal_stress")
#: the load point's words, before "displacement", "disp", "velocity", ... ("LP disp", "load_point_velocity")
_LOAD_POINT = ("", "lp ", "load point ", "loadpoint ", "lvdt ")
#: The names each role is found by without --columns, as :func:`_phrase` writes a header (lower case, its unit
#: left off, words split at blanks, "_", "-" and "."), in the order they are preferred.  "shear_stress" is the
#: friction's stress (divided by the normal stress) where no friction column is found.
_DEFAULT_NAMES = {
    "time": ("time", "t", "elapsed time"),
    "displacement": (
        *(f"{p}{w}" for w in ("displacement", "displ", "disp") for p in _LOAD_POINT),
        "load point position", "lp position",
    ),
    "friction": (
        "friction", "mu", "μ", "µ", "friction coefficient", "coefficient of friction", "friction coeff", "cof",
    ),
    "velocity": tuple(f"{p}{w}" for w in ("velocity", "vel") for p in _LOAD_POINT),
    "shear_stress": ("shear stress", "shear", "tau", "τ", "shear force", "shear load"),
    "normal_stress": ("normal stress", "normal", "sigma n", "sn", "σn", "normal force", "normal load"),
}  # fmt: skip


#: the fewest rows a record may have
MIN_RECORD_ROWS = 10


@dataclass(frozen=True)
class LabRecord:
    """Time (s, from the record's start), load-point displacement (m), friction; ``t0`` is the original start.

    ``length_unit`` is the unit the record's displacement was written in: reports give lengths in it.
    ``displacement_from``: "displacement", or "velocity" where it was integrated from a velocity column.
    """

    time: np.ndarray
    displacement: np.ndarray
    friction: np.ndarray
    t0: float = 0.0
    source: str = "record"
    length_unit: str = "m"
    displacement_from: str = "displacement"
    #: what reading the record did that a report should say (rows with an empty cell left out)
    notes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        """Each array 1-D, finite and of one length (at least MIN_RECORD_ROWS), the time increasing: a DataError
        naming the field, never a TypeError in the fit."""
        arrays = {}
        for name in ("time", "displacement", "friction"):
            value = getattr(self, name)
            if value is None:
                raise DataError(f"{self.source}: LabRecord {name} is None; expected an array of numbers")
            try:
                array = np.asarray(value, dtype=float)
            except (TypeError, ValueError):
                raise DataError(
                    f"{self.source}: LabRecord {name}: expected an array of numbers, got {type(value).__name__}"
                ) from None
            if array.ndim != 1:
                raise DataError(f"{self.source}: LabRecord {name}: expected a 1-D array, got shape {array.shape}")
            arrays[name] = array
            object.__setattr__(self, name, array)
        sizes = {name: array.size for name, array in arrays.items()}
        if len(set(sizes.values())) != 1:
            raise DataError(
                f"{self.source}: LabRecord time, displacement and friction have {sizes['time']},"
                f" {sizes['displacement']} and {sizes['friction']} values; expected one length"
            )
        if sizes["time"] < MIN_RECORD_ROWS:
            raise DataError(
                f"{self.source}: LabRecord has {sizes['time']} row(s); expected at least {MIN_RECORD_ROWS} to fit a"
                " record"
            )
        for name, array in arrays.items():
            bad = ~np.isfinite(array)
            if bad.any():
                k = int(np.argmax(bad))
                raise DataError(
                    f"{self.source}: LabRecord {name}[{k}] is {array[k]}; expected finite numbers"
                    f"{f' ({int(bad.sum())} in all)' if bad.sum() > 1 else ''}"
                )
        step = np.diff(arrays["time"])
        if np.any(step <= 0):
            k = int(np.argmax(step <= 0)) + 1
            raise DataError(
                f"{self.source}: LabRecord time[{k}] = {arrays['time'][k]:g} s does not increase (time[{k - 1}] ="
                f" {arrays['time'][k - 1]:g} s)"
            )

    def __len__(self) -> int:
        return int(self.time.size)

    @classmethod
    def from_arrays(
        cls,
        time: Any,
        displacement: Any,
        friction: Any,
        source: str = "arrays",
        length_unit: str = "m",
        rows: Any = None,
    ) -> LabRecord:
        """``rows``: each sample's line in its file, for messages; else the samples are counted from 1."""
        t = np.asarray(time, dtype=float).ravel()
        d = np.asarray(displacement, dtype=float).ravel()
        f = np.asarray(friction, dtype=float).ravel()
        if not (t.size == d.size == f.size):
            raise DataError(
                f"{source}: time, displacement and friction have {t.size}, {d.size} and {f.size} values; expected"
                " one length"
            )
        if t.size < MIN_RECORD_ROWS:
            raise DataError(f"{source}: {t.size} data row(s); expected at least {MIN_RECORD_ROWS} to fit a record")
        row = _row_names(rows, t.size)
        refuse_nonfinite(source, row, {"time": t, "displacement": d, "friction": f})
        for name, values, unit in (("time", t, "s"), ("displacement", d, "m"), ("friction", f, "")):
            # the fits square sums of these (analyze's limit): no measured record comes near it
            bad = np.flatnonzero(np.abs(values) > MAX_MAGNITUDE)
            if bad.size:
                k = int(bad[0])
                raise DataError(
                    f"{source}: row {row[k]}: {name} {values[k]:g}{f' {unit}' if unit else ''} is beyond"
                    f" {MAX_MAGNITUDE:g}{f' {unit}' if unit else ''} in magnitude; not a measured record"
                )
        _refuse_time_order(source, row, t)
        return cls(t - t[0], d - d[0], f, float(t[0]), source, length_unit)

    def to_frame(self) -> Any:
        import pandas as pd

        frame = pd.DataFrame(
            {"time": self.time, "load_point_displacement": self.displacement, "friction": self.friction}
        )
        return with_units(frame)

    def plot(self, ax: Any = None) -> Any:
        from ..plots.rsf import plot_record

        return plot_record(self, ax=ax)


#: no value of a record may exceed this in magnitude (SI), as analyze's records (a time of 1e300 s is a typing error)
MAX_MAGNITUDE = 1e100


def _refuse_time_order(source: str, row: Any, t: np.ndarray) -> None:
    """DataError at the first row whose time does not increase, naming the row that is out of place: where the
    row before it stands alone above both its neighbours (a 1e5 among 0.3 and 0.5 s), that one, with both
    neighbours; else the row that does not increase, with the time before it."""
    step = np.diff(t)
    if not np.any(step <= 0):
        return
    i = int(np.argmax(step <= 0)) + 1
    odd = i - 1  # the row before, out of place where the rows either side of it increase
    above = t[odd] > t[i]  # (not a repeated time: that row does not increase)
    if above and ((odd >= 1 and t[odd - 1] < t[i]) or (odd == 0 and t.size > 2 and t[1] < t[2] < t[0])):
        before = f"row {row[odd - 1]}: {t[odd - 1]:g} s, " if odd >= 1 else ""
        raise DataError(
            f"{source}: row {row[odd]}: time {t[odd]:g} s is out of order ({before}row {row[i]}: {t[i]:g} s);"
            " expected times that increase row by row"
        )
    raise DataError(
        f"{source}: row {row[i]}: time {t[i]:g} s does not increase (row {row[i - 1]}: {t[i - 1]:g} s); expected"
        " times that increase row by row"
    )


def parse_columns(text: str | None) -> dict[str, str]:
    """``time="Time(s)",displacement="Displ(microns)",friction=Friction`` to a mapping role -> header (roles:
    :data:`ROLES`; ``shear_stress`` and ``normal_stress`` give the friction as their ratio)."""
    if not text:
        return {}
    mapping: dict[str, str] = {}
    for item in re.findall(r'(\w+)\s*=\s*("[^"]*"|\'[^\']*\'|[^,]*)', text):
        role, name = item[0].strip().lower(), item[1].strip().strip("\"'")
        if role not in ROLES:
            raise ParameterError(f"--columns: unknown role {role!r}; expected {', '.join(ROLES)}")
        mapping[role] = name
    if not mapping:
        raise ParameterError(f'--columns {text!r}: expected ROLE=HEADER pairs, e.g. time="Time(s)",friction=Friction')
    return mapping


def read_record(
    path: str | Path,
    columns: dict[str, str] | None = None,
    displacement_unit: str | None = None,
    time_unit: str | None = None,
    normal_stress: float | str | None = None,
    contact_area: float | str | None = None,
) -> LabRecord:
    """A :class:`LabRecord` from delimited text (see the module notes).

    Each column's unit comes from its header (``Displ(microns)``, ``LP Displacement (um)``, ``disp [µm]``,
    ``time_ms``), else from ``displacement_unit`` / ``time_unit``, else metres and seconds.  A header and an
    option that name different units are refused (DataError), as is a load point moving faster than
    :data:`FASTEST_LOAD_POINT` (a unit forgotten: the message names the likely one).

    A shear-stress column instead of the friction (a stress unit in its header, or found or mapped as
    ``shear_stress``) is divided by the normal stress: a ``normal_stress`` column (found by name or mapped), else
    ``normal_stress`` (Pa, or a string with its unit, "10 MPa"); μ = τ/σn, each in the unit its header names.
    A shear force over a normal force (``Shear force (kN)``, ``Normal force (N)``: a force unit in the header) is
    their ratio, μ = Fs/Fn; a force beside a stress needs ``contact_area`` (m^2, or a string with its unit,
    "100 cm^2"), which makes the force a stress (refused without it).  A unit of another kind in either header is
    refused, as is a friction whose median is negative (a sign convention: flip the column) or outside
    :data:`FRICTION_RANGE` (percent, or a stress read as the coefficient).
    The file's separator, decimal mark and layout (title lines before the header, a units row under it, no header
    row: its columns then mapped by number, ``columns={"time": "1", ...}``): :func:`stickslip.tables.text_format`,
    as every reader's; a gzip file is read decompressed.
    """
    import pandas as pd

    from ..tables import text_encoding, text_format
    from ..units import to_si

    path = Path(path)
    require_input_file(path, str(path))  # not found, a folder, a device or pipe: each in its own words
    protect_inputs([path])  # in a command, no output may replace the record
    option = {
        "time": _option_scale(time_unit, "time", "--time-unit"),
        "length": _option_scale(displacement_unit, "length", "--displacement-unit"),
    }
    option["velocity"] = _velocity_option(option["length"], option["time"])
    sigma = None if normal_stress is None else to_si(normal_stress, "stress", "--normal-stress")
    if sigma is not None and not (math.isfinite(sigma) and sigma > 0):
        raise ParameterError(f"--normal-stress: expected a positive stress, got {sigma:g} Pa")
    area = None if contact_area is None else to_si(contact_area, "area", "--contact-area")
    if area is not None and not (math.isfinite(area) and area > 0):
        raise ParameterError(f"--contact-area: expected a positive area, got {area:g} m^2")
    form = text_format(path)
    form, header_note = _numbered_header(path, form, columns)
    frame = _with_row_units(_read_frame(path, pd, form), form.layout, path)
    with open_input(path, "rt", encoding="utf-8-sig", errors="replace") as handle:  # a byte-order mark: no content
        rows = _data_lines(handle, form.layout.data_after, len(frame))
    headers = {str(c).strip(): c for c in frame.columns}
    chosen, by_stress = _choose_columns(path, columns, headers, form.layout)
    data = {role: _numbers(frame[col], path, rows, pd, form) for role, col in chosen.items() if role != "normal_stress"}
    if "normal_stress" in chosen:  # its cells read only where the friction is a stress to divide by it
        data["normal_stress"] = lambda: _numbers(frame[chosen["normal_stress"]], path, rows, pd, form)
    dimension = {"time": "time", "displacement": "length", "velocity": "velocity"}
    units = {role: _header_unit(str(chosen[role]), dimension[role], path) for role in chosen if role in dimension}
    friction, read_notes = _friction(path, chosen, data, by_stress, sigma, _row_names(rows, len(frame)), area)
    if not by_stress and not read_notes:  # the friction column as it stands: a coefficient, positive
        _refuse_implausible_friction(path, str(chosen["friction"]), friction)
    read_notes[:0] = [n for n in (text_encoding(path).note, form.layout.note(str(path)), header_note, form.note) if n]

    def in_si(role: str) -> np.ndarray:
        """A column in SI: by the unit its header names, else by the option, else SI."""
        header, given = units.get(role), option[dimension[role]]
        if header is not None and given is not None and not math.isclose(header[0], given[0], rel_tol=1e-9):
            flag = "--time-unit" if role == "time" else "--displacement-unit"
            raise DataError(
                f"{path}: column {chosen[role]!r} is in {header[1]} but {flag} says {given[1]}; give one of them"
            )
        factor = header[0] if header is not None else given[0] if given is not None else 1.0
        return data[role] * factor

    time = in_si("time")
    _refuse_numbers_row(path, form, rows, time)
    if "displacement" in data:
        displacement = in_si("displacement")
        written = units.get("displacement") or option["length"]
        column = chosen["displacement"]
        cells = {"time": time, "displacement": displacement, "friction": friction}
        gaps = ("displacement", "friction")
    else:
        velocity = in_si("velocity")  # every column's first bad row before the velocity is integrated
        cells = {"time": time, "velocity": velocity, "friction": friction}
        if not (np.all(np.isfinite(time)) and np.all(np.isfinite(velocity))):  # each row's velocity holds to the
            refuse_nonfinite(str(path), _row_names(rows, time.size), cells)  # next: none may be missing
        displacement = _integrated(time, velocity, path, rows)
        speed_unit = units.get("velocity")
        written = _length_of(speed_unit) if speed_unit is not None else option["length"]
        column = chosen["velocity"]
        gaps = ("friction",)
    keep, note = _dropped_samples(str(path), _row_names(rows, time.size), cells, gaps)
    if note:
        warnings.warn(note, UserWarning, stacklevel=2)
        rows = [r for r, k in zip(_row_names(rows, time.size), keep, strict=True) if k]
        time, displacement, friction = time[keep], displacement[keep], friction[keep]
        read_notes.append(note)
    shown_unit = _plain_length(written[1]) if written is not None else "m"
    record = LabRecord.from_arrays(time, displacement, friction, str(path), shown_unit, rows)
    _refuse_implausible_speed(record, str(column), written)
    record = replace(record, notes=tuple(read_notes)) if read_notes else record
    return record if "displacement" in data else replace(record, displacement_from="velocity")


#: a friction coefficient read as shear stress over normal stress lies between these (its median): beyond them a
#: unit is wrong (a kPa column read as Pa gives 1e-3 of it)
FRICTION_RANGE = (1e-3, 10.0)
#: a normal-stress column and --normal-stress agree within this fraction (the column's median)
NORMAL_STRESS_AGREEMENT = 0.05


def _unit_among(header: str, kinds: tuple[str, ...], path: Path) -> tuple[Any, str]:
    """(what :func:`_header_unit` found, its kind) for the first of ``kinds`` the header's unit is of: the first
    kind also takes a bare header (None found), a later one only a unit it names.  Else the first kind's DataError
    (naming the column)."""
    refused: DataError | None = None
    for k, kind in enumerate(kinds):
        try:
            found = _header_unit(header, kind, path)
        except DataError as exc:
            refused = refused or exc
            continue
        if found is not None or k == 0:
            return found, kind
    assert refused is not None  # the first kind either returned or refused
    raise refused


def _load_unit(header: str, path: Path) -> tuple[float, str, str]:
    """(SI factor, unit, "stress" or "force") of a shear- or normal-load column's header: a stress unit, a force
    unit, or none (a bare header: Pa).  A unit of another kind is refused (DataError naming the column)."""
    found, kind = _unit_among(header, ("stress", "force"), path)
    return (found[0], found[1], kind) if found is not None else (1.0, "Pa", "stress")


def _friction(
    path: Path,
    chosen: dict[str, Any],
    data: dict[str, Any],
    by_stress: bool,
    sigma: float | None,
    row: Any,
    area: float | None = None,
) -> tuple[np.ndarray, list[str]]:
    """The friction coefficient, and what reading it did that a report should say: the friction column as it
    stands, or a shear load divided by the normal load: a shear stress by a normal stress (a column, else
    ``sigma`` in Pa), a shear force by a normal force (their ratio: the contact area cancels), and a force by a
    stress only with the contact ``area`` (m^2), which makes the force a stress."""
    header = str(chosen["friction"])
    if by_stress:
        shear = _load_unit(header, path)
    else:
        # a stress unit ("Shear stress [kPa]" mapped as friction) is a shear stress
        found, kind = _unit_among(header, ("dimensionless", "stress"), path)
        if kind == "dimensionless":
            return data["friction"], []
        shear = (found[0], found[1], "stress")
    tau = data["friction"] * shear[0]
    bare = [header] if not _header_names_unit(header) else []
    if "normal_stress" in chosen:
        column = str(chosen["normal_stress"])
        factor, unit_name, kind = _load_unit(column, path)
        bare += [column] if not _header_names_unit(column) else []
        written = data["normal_stress"]()
        sn = written * factor
        bad = np.flatnonzero(np.isfinite(sn) & (sn <= 0))
        if bad.size:
            k = int(bad[0])
            raise DataError(
                f"{path}: row {row[k]}, column {column!r}: {written[k]:.10g} {unit_name}; expected a positive"
                f" normal {'force' if kind == 'force' else 'stress'}"
            )
        converted = kind == "force" and shear[2] == "stress"
        if converted:  # the normal force over the contact area
            sn = sn / _area_for(path, column, unit_name, header, area)
            kind = "stress"
        typical = float(np.nanmedian(sn)) if np.any(np.isfinite(sn)) else math.nan
        if sigma is not None and kind == "force":
            raise DataError(
                f"{path}: column {column!r} gives the normal load as a force ({unit_name}) and --normal-stress gives"
                " a stress; give one of them"
            )
        if sigma is not None and not abs(typical - sigma) <= NORMAL_STRESS_AGREEMENT * typical:
            shown, said_unit = (1.0, "Pa") if converted else (factor, unit_name)
            raise DataError(
                f"{path}: column {column!r} gives the normal stress {typical / shown:.6g} {said_unit} (median) but"
                f" --normal-stress says {sigma / shown:.6g} {said_unit}; give one of them"
            )
        divisor, said = sn, f"column {column!r}"
        if kind == "stress" and shear[2] == "force":
            tau = tau / _area_for(path, header, shear[1], column, area)
    elif sigma is not None:
        if shear[2] == "force":
            tau = tau / _area_for(path, header, shear[1], "--normal-stress", area)
        divisor, said = np.full(tau.size, sigma), f"--normal-stress {_stress_text(sigma)}"
    else:
        what = "a force" if shear[2] == "force" else "a stress"
        raise DataError(
            f"{path}: column {header!r} is in {shear[1]}, {what}; expected the friction coefficient, or the"
            f" normal {'load' if shear[2] == 'force' else 'stress'} to divide it by: a normal-stress or normal-force"
            ' column (--columns normal_stress="HEADER"), or --normal-stress (e.g. "10 MPa"; Python: normal_stress=)'
        )
    # a normal stress <= 0 was refused above with its row; an empty cell (NaN) gives a NaN friction, which the reader
    # treats as any empty friction cell (dropped with a note, or refused beyond 1 %)
    with np.errstate(invalid="ignore", divide="ignore"):
        friction = tau / divisor
    typical = float(np.nanmedian(np.abs(friction))) if np.any(np.isfinite(friction)) else math.nan
    if not FRICTION_RANGE[0] <= typical <= FRICTION_RANGE[1]:
        hint = f" ({' and '.join(repr(b) for b in bare)} name no unit: read as Pa)" if bare else ""
        raise DataError(
            f"{path}: friction = column {header!r} / {said} is {typical:.3g} (median), outside"
            f" {FRICTION_RANGE[0]:g} to {FRICTION_RANGE[1]:g}; check the units of the two{hint}"
        )
    over = f", over the contact area {area:.6g} m^2" if area is not None and shear[2] == "force" else ""
    ratio = "μ = Fs/Fn" if shear[2] == "force" and "force" in _kinds(chosen, path) else "μ = τ/σn"
    return friction, [f"{path}: friction read as column {header!r} ({shear[1]}{over}) divided by {said}: {ratio}"]


def _kinds(chosen: dict[str, Any], path: Path) -> set[str]:
    """The kinds of load ("stress", "force") of the normal-load column, where there is one."""
    return {_load_unit(str(chosen["normal_stress"]), path)[2]} if "normal_stress" in chosen else set()


def _header_names_unit(header: str) -> bool:
    """Whether a header names a unit, in brackets at its end (a bare "Shear stress" is read as Pa)."""
    return re.search(r"[\(\[]\s*([^\(\)\[\]]+?)\s*[\)\]]\s*$", header.strip()) is not None


def _area_for(path: Path, force: str, unit: str, other: str, area: float | None) -> float:
    """The contact area (m^2) that makes the force column ``force`` a stress beside the stress ``other``; refused
    (DataError) where none was given."""
    if area is None:
        raise DataError(
            f"{path}: column {force!r} is a force ({unit}) but {other!r} is a stress; give --contact-area (the"
            ' sliding area, e.g. "100 cm^2"; Python: contact_area=) to make the force a stress, or give both as'
            " forces or both as stresses"
        )
    return area


def _refuse_implausible_friction(path: Path, column: str, friction: np.ndarray) -> None:
    """DataError where a friction column's median is no friction coefficient: negative (the rig's sign
    convention: flip the column), or outside :data:`FRICTION_RANGE` in magnitude (percent, or a stress)."""
    finite = friction[np.isfinite(friction)]
    if not finite.size:
        return  # every cell empty: the reader names the rows
    typical = float(np.median(finite))
    if typical < 0 and FRICTION_RANGE[0] <= -typical <= FRICTION_RANGE[1]:
        raise DataError(
            f"{path}: column {column!r}: the friction is negative (median {typical:.6g}); expected a positive"
            " friction coefficient: the rig's sign convention? flip the column's sign"
        )
    if not FRICTION_RANGE[0] <= abs(typical) <= FRICTION_RANGE[1]:
        if 0.01 <= abs(typical) / 100 <= 2.0:
            likely = "in percent? divide the column by 100"
        elif abs(typical) > FRICTION_RANGE[1]:
            likely = "a shear stress or force? map it as shear_stress, with the normal load as normal_stress"
        else:
            likely = "the wrong column, or a stress in a large unit?"
        raise DataError(
            f"{path}: column {column!r}: friction {typical:.6g} (median), outside {FRICTION_RANGE[0]:g} to"
            f" {FRICTION_RANGE[1]:g}; expected the friction coefficient ({likely})"
        )


def _stress_text(value: float) -> str:
    """A stress (Pa) in the unit people write it in: "10 MPa", "250 kPa"."""
    for unit, scale in (("GPa", 1e9), ("MPa", 1e6), ("kPa", 1e3)):
        if value >= scale:
            return f"{value / scale:.6g} {unit}"
    return f"{value:.6g} Pa"


#: rows with an empty (or NaN) friction or displacement cell a record may lose (dropped samples: each is left out,
#: with a note); more is refused
MISSING_SHARE = 0.01


def _dropped_samples(
    source: str, row: Any, cells: dict[str, np.ndarray], gaps: tuple[str, ...]
) -> tuple[np.ndarray, str]:  # fmt: skip
    """Which rows to keep, leaving out those whose ``gaps`` columns hold an empty (or NaN) cell where the time is
    there (a DAQ's dropped sample), and the one-line note saying so ("" when none is).  More than MISSING_SHARE of
    the rows is refused, as :func:`refuse_nonfinite` names them; infinities are left to it."""
    time = cells["time"]
    gap = {name: np.isnan(cells[name]) & np.isfinite(time) for name in gaps}
    missing = np.logical_or.reduce(list(gap.values()))
    count = int(np.count_nonzero(missing))
    if count == 0:
        return np.ones(time.size, dtype=bool), ""
    if count > max(MISSING_SHARE * time.size, 1.0):
        try:
            refuse_nonfinite(source, row, cells)
        except DataError as exc:
            raise DataError(
                f"{exc}; {count} of {time.size} rows have an empty or NaN cell, more than {100 * MISSING_SHARE:g} %: "
                "expected a number in every row, or an occasional dropped sample (fill the gaps, or remove those rows)"
            ) from None
    firsts = sorted((int(np.argmax(mask)), name, int(np.count_nonzero(mask))) for name, mask in gap.items()
                    if mask.any())  # fmt: skip
    where = ", ".join(f"{name} at row {row[i]}" if n == 1 else f"{name} in {n} rows from row {row[i]}"
                      for i, name, n in firsts)  # fmt: skip
    names = " or ".join(name for _, name, _ in firsts)
    rows = "1 row" if count == 1 else f"{count} rows"
    return ~missing, f"{source}: {rows} with an empty or NaN {names} cell left out ({where}): dropped samples"


#: a rock or gel friction rig's load point moves at nm/s to mm/s: faster than this (m/s) is a unit read wrong
FASTEST_LOAD_POINT = 0.1
_UNIT_WORDS = {"micron": "um", "microns": "um", "µm": "um", "μm": "um", "micrometre": "um", "micrometer": "um"}
#: last words of a header taken as its unit (without brackets only these, so "friction_coefficient" names none)
_TAIL_UNITS = {"m", "mm", "um", "µm", "μm", "nm", "micron", "microns", "s", "ms", "us", "µs", "min"}
_TAIL_UNITS |= {"m/s", "mm/s", "um/s", "µm/s", "μm/s", "nm/s"}


def _numbers(column: Any, path: Path, rows: Any, pd: Any, form: Any = None) -> np.ndarray:
    """A column as floats; DataError naming the first cell that is text (not a blank or NaN: a dropped sample,
    :func:`_dropped_samples`' or :meth:`LabRecord.from_arrays`' to judge), with the hint a comma needs
    (:meth:`stickslip.tables.TextFormat.hint`).  ``form``: the file's :class:`~stickslip.tables.TextFormat`."""
    from ..tables import TextFormat

    form = form if form is not None else TextFormat()
    numbers = column
    if form.decimal == "," and column.dtype == object:  # a column the parser left as text: its commas are marks
        numbers = column.astype(str).str.replace(",", ".", regex=False).where(column.notna())
    values = pd.to_numeric(numbers, errors="coerce").to_numpy(dtype=float)
    cells = column.to_numpy()
    text = np.isnan(values) & pd.notna(column).to_numpy()
    text &= np.array([str(c).strip().lower() not in ("", "nan") for c in cells], dtype=bool)  # bool: no rows too
    if text.any():
        i = int(np.argmax(text))
        cell = str(cells[i])
        raise DataError(f"{path}: row {_row_names(rows, values.size)[i]}, column {str(column.name)!r}: {cell!r} is "
                        f"not a number{form.hint(cell.strip())}")  # fmt: skip
    return values


def refuse_nonfinite(source: str, row: Any, columns: dict[str, np.ndarray]) -> None:
    """DataError at the first row (in the file's order) where any column is not a finite number, naming every
    column bad there and, where more rows are bad, how many and where each column's first bad value is."""
    bad = {name: ~np.isfinite(col) for name, col in columns.items()}
    anywhere = np.logical_or.reduce(list(bad.values()))
    if not anywhere.any():
        return
    first = int(np.argmax(anywhere))
    names = [name for name, mask in bad.items() if mask[first]]
    verb = "is not a finite number" if len(names) == 1 else "are not finite numbers"
    text = f"{source}: row {row[first]}: {' and '.join(names)} {verb}"
    count = int(np.count_nonzero(anywhere))
    if count > 1:
        firsts = sorted((int(np.argmax(mask)), name, int(np.count_nonzero(mask))) for name, mask in bad.items()
                        if mask.any())  # fmt: skip
        where = [f"{name} at row {row[i]}" if n == 1 else f"{name} in {n} from row {row[i]}" for i, name, n in firsts]
        text += f" ({count} rows in all: {', '.join(where)})"
    raise DataError(text)


def _line_cells(path: Path, row: int, delimiter: str) -> list[str]:
    """File row ``row``'s (1-based) cells as written, split at ``delimiter`` (" ": blanks)."""
    from ..tables import _cells

    with open_input(path, "rt", encoding="utf-8-sig", errors="replace") as handle:
        text = next(itertools.islice(handle, row - 1, None), "")
    return [c.strip() for c in _cells(text.rstrip("\r\n"), delimiter)]


def _numbered_header(path: Path, form: Any, columns: dict[str, str] | None) -> tuple[Any, str]:
    """The file's form with its first row read as the header where that row holds numbers and ``columns`` names
    its cells as written (``time=1`` where row 1 reads ``1,2,3``: the docs' own example), and the note that says
    so ("" and ``form`` as it is otherwise).  A map whose numbers would pick other columns by position than by
    name is refused (DataError)."""
    layout = form.layout
    if layout.header_row is not None or layout.commented or not columns or not layout.first_data_row:
        return form, ""
    row = layout.first_data_row
    cells = _line_cells(path, row, form.delimiter)
    wanted = {role: str(name).strip() for role, name in columns.items()}
    if len(set(cells)) != len(cells) or not all(name in cells for name in wanted.values()):
        return form, ""
    for role, name in wanted.items():
        if name.isdigit() and 1 <= int(name) <= len(cells) and cells.index(name) != int(name) - 1:
            raise DataError(
                f"{path}: --columns {role}={name}: row {row} ({', '.join(cells)}) may be the header (where {name!r}"
                f" is column {cells.index(name) + 1}) or data (column {name}); map the columns by their header"
                " names, or remove the header row"
            )
    header = replace(layout, header_row=row, first_data_row=0)
    note = f"{path}: row {row} ({', '.join(cells)}) read as the header: --columns names its cells"
    return replace(form, layout=header), note


#: a first data row whose time step to the next exceeds this many times the next rows' (median) is out of line
OUT_OF_LINE_STEP = 10.0


def _refuse_numbers_row(path: Path, form: Any, rows: Any, time: np.ndarray) -> None:
    """DataError naming the first data row where it is whole numbers only (``1,2,3``, ``2024,05,01``, ``1,1,1``)
    and out of line with the data: its time not before the next row's, or its step to the next more than
    :data:`OUT_OF_LINE_STEP` times the next rows' median step: a header, title or units row of numbers, never
    read silently as a sample."""
    if rows is None or len(rows) != time.size or time.size < 3 or not np.all(np.isfinite(time[:3])):
        return
    cells = _line_cells(path, rows[0], form.delimiter)
    if not cells or not all(re.fullmatch(r"[+-]?\d+", c) for c in cells):
        return
    steps = np.diff(time[1:52])
    steps = steps[np.isfinite(steps) & (steps > 0)]
    typical = float(np.median(steps)) if steps.size else math.nan
    first = time[1] - time[0]
    if first > 0 and not (math.isfinite(typical) and first > OUT_OF_LINE_STEP * typical):
        return
    after = f", the rows after stepping by {typical:g} s" if math.isfinite(typical) else ""
    layout = form.layout
    if layout.header_row is None:
        what = (
            "a header or title row of numbers? remove it, or where it is the header map the columns by its cells"
            f" as written (--columns time={cells[0]},...)"
        )
    else:
        what = (
            f"a units row? expected the data right under the header (row {layout.header_row}), units as words"
            " (s, um, -); remove the row"
        )
    raise DataError(
        f"{path}: row {rows[0]} ({', '.join(cells)}) is out of line with the data (time {time[0]:g} s, then"
        f" {time[1]:g} s at row {rows[1]}{after}): {what}"
    )


def _row_names(rows: Any, size: int) -> Any:
    """Each sample's row for messages: ``rows`` when it names every sample, else 1, 2, ..."""
    return rows if rows is not None and len(rows) == size else range(1, size + 1)


def _read_frame(path: Path, pd: Any, form: Any) -> Any:
    """The file's table as pandas reads it, with the separator, decimal mark and layout of ``form``
    (:func:`stickslip.tables.text_format`, every reader's one decision): title lines and a units row skipped, a
    header in a ``#`` comment read from it, a file with no header row its columns numbered from 1 ("1", "2", ...).
    A gzip file is read decompressed."""
    from ..tables import pandas_input

    layout = form.layout
    source, compression = pandas_input(path)  # a file that is not UTF-8: its UTF-8 transcript
    try:
        if form.delimiter == " ":
            return _read_whitespace_frame(path, pd, layout, form.decimal, compression, source)
        if layout.header_row is None or layout.commented:  # the names are not a row of the table
            frame = pd.read_csv(source, sep=form.delimiter, comment="#", engine="c", decimal=form.decimal,
                                header=None, skiprows=layout.data_after, compression=compression)  # fmt: skip
            return _named(frame, layout, path)
        skipped = {row - 1 for row in (*layout.title_rows, layout.units_row) if row is not None}  # 0-based lines
        return pd.read_csv(source, sep=form.delimiter, comment="#", engine="c", decimal=form.decimal,
                           skiprows=(lambda i: i in skipped) if skipped else None, compression=compression)  # fmt: skip
    except pd.errors.EmptyDataError:  # pandas' "No columns to parse from file"
        raise DataError(
            f"{path}: the file is empty (no line that is neither blank nor a '#' comment); expected a header row"
            " and the data (time, load-point displacement and friction)"
        ) from None
    except (OSError, EOFError, ValueError, pd.errors.ParserError) as exc:
        raise DataError(f"{path}: cannot read as delimited text ({str(exc).splitlines()[0]})") from None


def _named(frame: Any, layout: Any, path: Path) -> Any:
    """A frame read without a header row, its columns named by the header in a ``#`` comment, else numbered from 1
    as ``--columns time=1`` maps them."""
    if not layout.commented:
        frame.columns = [str(k) for k in range(1, frame.shape[1] + 1)]
        return frame
    if frame.shape[1] != len(layout.commented):
        raise DataError(
            f"{path}: the header in the comment on row {layout.header_row} names {len(layout.commented)} column(s)"
            f" ({', '.join(layout.commented)}) but the rows have {frame.shape[1]}"
        )
    frame.columns = list(layout.commented)
    return frame


def _with_row_units(frame: Any, layout: Any, path: Path) -> Any:
    """The frame's columns named with the unit a units row under the header gives them (``Time`` over ``ms``:
    "Time [ms]"), where their header names none; one that names another unit is refused."""
    from ..tables import SCALED_UNIT

    if layout.units_row is None:
        return frame
    names = []
    for position, column in enumerate(frame.columns):
        header, unit = str(column).strip(), layout.unit(position)
        if unit is not None and SCALED_UNIT.fullmatch(unit):
            raise DataError(
                f"{path}: row {layout.units_row} (the units row), column {header!r}: {unit!r} is no unit; expected a"
                " unit word (s, ms, um, mm, -); a scale such as 10 um belongs in the numbers"
            )
        written = re.search(r"[\(\[]\s*([^\(\)\[\]]+?)\s*[\)\]]\s*$", header)
        if unit is not None and written is not None and written.group(1) != unit:
            raise DataError(
                f"{path}: column {header!r} names its unit {written.group(1)!r} but the units row (row"
                f" {layout.units_row}) says {unit!r}; give one of them"
            )
        names.append(f"{header} [{unit}]" if unit is not None and written is None else column)
    frame.columns = names
    return frame


def _data_lines(lines: Any, after: int, count: int) -> list[int] | None:
    """The 1-based file line of each of the ``count`` data rows after file row ``after`` (the header, or the units
    row under it), blank lines and ``#`` comments skipped as the reader skips them; None where the numbers do not
    match what the reader kept (a quoted line end)."""
    numbers = [n for n, line in enumerate(lines, 1) if n > after and line.split("#", 1)[0].strip()]
    return numbers if len(numbers) == count else None


def whitespace_headers(line: str) -> list[str]:
    """A whitespace-separated header's names, a bracketed unit kept with its name: ``time [s]`` is one column."""
    return re.findall(r"[^\s\[\(]+(?:\s*[\[\(][^\]\)]*[\]\)])?|[\[\(][^\]\)]*[\]\)]", line)


def _read_whitespace_frame(
    path: Path, pd: Any, layout: Any, decimal: str = ".", compression: str | None = None, source: Any = None
) -> Any:
    """Columns split at blanks; the header's names by :func:`whitespace_headers` ("time [s]" is not two columns).
    ``source``: what pandas reads where it is not ``path`` (a transcript of a file that is not UTF-8)."""
    frame = pd.read_csv(path if source is None else source, sep=r"\s+", comment="#", engine="python", header=None,
                        skiprows=layout.data_after, decimal=decimal, compression=compression)  # fmt: skip
    if layout.header_row is None or layout.commented:
        return _named(frame, layout, path)
    with open_input(path, "rt", encoding="utf-8-sig", errors="replace") as handle:
        header = next(itertools.islice(handle, layout.header_row - 1, None), "") if layout.header_row else ""
    names = whitespace_headers(header)
    if frame.shape[1] != len(names):
        raise DataError(
            f"{path}: the header names {len(names)} column(s) ({', '.join(names) or 'none'}) but the rows have"
            f" {frame.shape[1]}; separate the columns with commas or tabs"
        )
    frame.columns = names
    return frame


def _phrase(header: str) -> str:
    """A header as the columns are found by name: lower case, its unit left off (in brackets or parentheses at its
    end, or a last word that is a unit: "time_ms"), its words split at blanks, "_", "-" and "."."""
    text = re.sub(r"\s*[\(\[][^\(\)\[\]]*[\)\]]\s*$", "", header.strip())
    words = [w for w in re.split(r"[\s_.\-]+", text.lower()) if w]
    if len(words) > 1 and words[-1] in _TAIL_UNITS:
        words.pop()
    return " ".join(words)


#: how the messages say the columns are mapped
_MAP_HINT = (
    "map them with --columns time=HEADER,displacement=HEADER,friction=HEADER; a header as written, or a column's"
    " number, 1-based"
)


def _choose_columns(
    path: Path, columns: dict[str, str] | None, headers: dict, layout: Any = None
) -> tuple[dict[str, Any], bool]:
    """The column of each role (mapped with ``columns``, else found by :data:`_DEFAULT_NAMES`, the first in the
    file where two have one name), and whether the "friction" is a shear stress to divide by the normal stress
    (mapped or found as ``shear_stress``).

    A mapped column is its header as written, else its name without the unit (``time=Time`` for "Time [ms]",
    the unit a units row gave it), else its number in the file, 1-based (``time=1``: a file with no header row
    has only these).  ``layout``: :class:`stickslip.tables.Layout`, for the messages."""
    columns = dict(columns or {})
    if "friction" in columns and "shear_stress" in columns:
        raise DataError(f"{path}: --columns maps both friction and shear_stress; map one of them")
    found = f"found {', '.join(headers) or 'none'}"
    if layout is not None and layout.header_row is None and not columns:
        raise DataError(
            f"{path}: no header row (row {layout.first_data_row} holds numbers); map its {len(headers)} columns by"
            " number, 1-based: --columns time=1,displacement=2,friction=3 (their units: --time-unit,"
            " --displacement-unit; Python: columns={'time': '1', ...})"
        )
    if layout is not None and layout.header_row is None:
        found = f"the file has no header row: its {len(headers)} columns are numbered from 1"
    phrases: dict[str, Any] = {}
    for header, column in headers.items():
        phrases.setdefault(_phrase(header), column)
    bare: dict[str, list[Any]] = {}
    for header, column in headers.items():
        bare.setdefault(re.sub(r"\s*[\(\[][^\(\)\[\]]*[\)\]]\s*$", "", header), []).append(column)
    positions = list(headers.values())

    def mapped(role: str) -> Any:
        wanted = str(columns[role]).strip()
        if wanted in headers:
            return headers[wanted]
        if len(bare.get(wanted, ())) == 1:  # "Time" for "Time [ms]"
            return bare[wanted][0]
        if wanted.isdigit() and 1 <= int(wanted) <= len(positions):
            return positions[int(wanted) - 1]
        if wanted.isdigit():
            raise DataError(
                f"{path}: --columns {role}={wanted}: no column {wanted}; the file has {len(positions)} (numbered"
                " from 1)"
            )
        raise DataError(f"{path}: no column {wanted!r} (for {role}); {found} (or give a column's number, 1-based)")

    def by_name(role: str) -> Any:
        return next((phrases[n] for n in _DEFAULT_NAMES[role] if n in phrases), None)

    if "displacement" in columns and "velocity" in columns:
        raise DataError(
            f"{path}: --columns maps both displacement and velocity; map one of them (the load point's history"
            " comes from one: the displacement, or the velocity integrated)"
        )
    chosen: dict[str, Any] = {}
    for role in ("time", "displacement", "velocity"):
        if role == "velocity" and "displacement" in chosen:
            continue
        if role == "displacement" and "velocity" in columns:
            continue  # the velocity the user mapped gives it, whatever displacement column the file also has
        match = mapped(role) if role in columns else by_name(role)
        by_velocity = "velocity" in columns or by_name("velocity") is not None
        if match is None and role == "displacement" and by_velocity:
            continue  # the velocity column gives it
        if match is None:
            raise DataError(f"{path}: no {role} column; {found} ({_MAP_HINT})")
        chosen[role] = match
    by_stress = "shear_stress" in columns
    if "friction" in columns or by_stress:
        chosen["friction"] = mapped("shear_stress" if by_stress else "friction")
    elif (match := by_name("friction")) is not None:
        chosen["friction"] = match
    elif (match := by_name("shear_stress")) is not None:
        chosen["friction"], by_stress = match, True
    else:
        raise DataError(
            f"{path}: no friction column; {found} ({_MAP_HINT}, or a shear stress and the normal stress:"
            " shear_stress=...,normal_stress=...)"
        )
    if "normal_stress" in columns:
        chosen["normal_stress"] = mapped("normal_stress")
    elif (match := by_name("normal_stress")) is not None:
        chosen["normal_stress"] = match
    return chosen, by_stress


def _option_scale(unit: str | None, dimension: str, flag: str) -> tuple[float, str] | None:
    from ..units import to_si

    if unit is None or not str(unit).strip():
        return None
    return to_si(f"1 {unit}", dimension, flag), str(unit).strip()


def _velocity_option(length: tuple[float, str] | None, time: tuple[float, str] | None) -> tuple[float, str] | None:
    """What the options say a velocity column is in (a length option alone: per second)."""
    if length is None:
        return None
    per = time if time is not None else (1.0, "s")
    return length[0] / per[0], f"{length[1]}/{per[1]}"


def _header_unit(header: str, dimension: str, path: Path) -> tuple[float, str] | None:
    """The SI factor and name of the unit a header names: in brackets at its end (``Displ(microns)``,
    ``disp [µm]``, ``Vel (um/s)``) or as its last word (``time_ms``, ``LP displacement um``); None when it
    names none.  A bracketed unit of another dimension is refused."""
    from ..units import to_si

    text = header.strip()
    match = re.search(r"[\(\[]\s*([^\(\)\[\]]+?)\s*[\)\]]\s*$", text)
    tail = re.search(r"[\s_]([A-Za-zµμ/]+)$", text)
    word = match.group(1) if match else tail.group(1) if tail and tail.group(1).lower() in _TAIL_UNITS else None
    if word is None:
        return None
    unit = _UNIT_WORDS.get(word.lower(), word)
    if dimension == "dimensionless" and unit in ("1", "-"):  # a pure number, as this package writes one
        return 1.0, unit
    try:
        return to_si(f"1 {unit}", dimension, header), unit
    except ParameterError:
        pass
    expected = "the friction coefficient (dimensionless)" if dimension == "dimensionless" else f"a {dimension}"
    for other in ("length", "time", "velocity", "stress", "force"):
        try:
            to_si(f"1 {unit}", other, header)
        except ParameterError:
            continue
        raise DataError(f"{path}: column {header!r} is in {word}, a {other}; expected {expected}") from None
    if match is not None and match.group(0).lstrip().startswith("["):  # this package's own way to write a unit
        if _known_unit(unit):  # of any other kind ("time [kg]"): never read as a bare number
            raise DataError(f"{path}: column {header!r} is in {word}, not {expected}; give the column in such a unit")
        raise DataError(f"{path}: column {header!r}: unknown unit {word!r}; expected {expected}")
    return None  # a word in round brackets that names no length, time, speed or stress: a label ("Displ (LVDT 2)",
    # "Displ (A)" for channel A, "Friction (mu)")


def _known_unit(unit: str) -> bool:
    """Whether pint reads ``unit`` as a unit (of any dimension)."""
    from ..units import registry

    try:
        registry().parse_units(unit)
    except Exception:  # pint raises many things on garbage; all mean "no unit"
        return False
    return True


def _length_of(velocity_unit: tuple[float, str]) -> tuple[float, str]:
    """The length unit of a velocity unit (``um/s`` -> um); its factor is not needed, only its name."""
    return 0.0, velocity_unit[1].split("/")[0].strip() or "m"


def _plain_length(unit: str) -> str:
    return _UNIT_WORDS.get(unit.lower(), unit)


def _refuse_implausible_speed(record: LabRecord, column: str, written: tuple[float, str] | None) -> None:
    """DataError when the load point moves faster than any friction rig's (a unit read wrong): the median speed
    over ten stretches of the record, so a short fast stretch is allowed."""
    t, d = record.time, record.displacement
    edges = np.unique(np.linspace(0, t.size - 1, 11).astype(int))
    speed = float(np.median(np.abs(np.diff(d[edges])) / np.diff(t[edges])))
    if speed <= FASTEST_LOAD_POINT:
        return
    unit = written[1] if written is not None else "m"
    factor = written[0] if written is not None and written[0] > 0 else 1.0
    scales = {"mm": 1e-3, "um": 1e-6, "nm": 1e-9}
    likely = min(scales, key=lambda u: abs(math.log10(speed / factor * scales[u]) + 5.0))  # nearest to 10 um/s
    raise DataError(
        f"{record.source}: the load point moves at {speed:.3g} m/s reading column {column!r} in {unit}, faster "
        f"than any friction rig's; if it is in {likely} give --displacement-unit {likely} (or name the unit in "
        f"its header, e.g. 'Displ ({likely})')"
    )


def _integrated(time: np.ndarray, velocity: np.ndarray, path: Path, rows: Any = None) -> np.ndarray:
    """Displacement from the load point's velocity column (in SI): row i's velocity holds on [t_i, t_(i+1))."""
    refuse_nonfinite(str(path), _row_names(rows, velocity.size), {"velocity": velocity})
    if velocity.size < 2:
        return np.zeros_like(velocity)
    return np.concatenate([[0.0], np.cumsum(velocity[:-1] * np.diff(time))])


def find_segments(
    time: np.ndarray,
    displacement: np.ndarray,
    max_segments: int = 60,
    min_change: float = 0.2,
    min_points: int = 10,
    min_duration: float | None = None,
    t0: float = 0.0,
) -> Protocol:
    """The load point's piecewise-constant velocity history from its displacement record.

    Equal time bins, a measured noise model (:func:`_noise_model`, :func:`_slope_inflation`), PELT proposing
    changes and each change tested (``min_change``, ``min_points``, ``min_duration``), then placed and dated on the
    full record: docs/rsf.md, "Velocity levels".

    Raises DataError when more than ``max_segments`` pieces remain or the pieces miss the record by more than
    :data:`CURVED` times its noise (the displacement is not piecewise linear; a jump, a re-zeroed transducer, is
    named with its time: ``t0`` plus the record's time, as in the record's file).
    """
    t = np.asarray(time, dtype=float)
    d = np.asarray(displacement, dtype=float)
    n = t.size
    if n < 2 * min_points:
        return Protocol((Segment(max(_line(t, d)[0], 0.0), float(t[-1] - t[0])),), name="from displacement")
    bins = _bins(t, d)
    proposed = _pelt(bins)
    bins = replace(bins, inflation=_slope_inflation(bins.t, bins.d, bins.var, proposed))
    shortest = 5.0 * bins.width if min_duration is None else float(min_duration)  # PELT leaves 3-bin slivers
    spacing = float(np.median(np.diff(t)))  # the record's usual row spacing (a sparse piece's rows count by time)
    hinges = _significant_hinges(bins, proposed, min_change, min_points, shortest, spacing)
    if len(hinges) + 1 > max_segments:
        raise DataError(
            f"load-point displacement: {len(hinges) + 1} straight pieces found, more than {max_segments}; "
            f"expected piecewise-constant velocity ({HISTORY_HINT})"
        )
    short = _short_pieces(t, d, bins, hinges, proposed, min_change, min_points, shortest)
    hinges, skip = _with_short_pieces(bins, hinges, short)
    if len(hinges) + 1 > max_segments:
        raise DataError(
            f"load-point displacement: {len(hinges) + 1} straight pieces found, more than {max_segments}; "
            f"expected piecewise-constant velocity ({HISTORY_HINT})"
        )
    _refuse_curved(bins, hinges, t, d, t0, skip)
    fixed = {int(bins.first[h]): row for piece in short for h, row in zip(piece.hinges, piece.rows, strict=True)}
    breaks = _refine(t, d, [0, *[fixed.get(int(bins.first[b]), int(bins.first[b])) for b in hinges], n],
                     bins.first, [None if int(bins.first[b]) in fixed else b for b in hinges], min_points)  # fmt: skip
    exact = set(fixed.values())  # a short piece's changes are placed on rows already, its lines short
    lines = [_line(t[i0:i1], d[i0:i1]) for i0, i1 in itertools.pairwise(breaks)]
    times = [float(t[0])]
    for j, i in enumerate(breaks[1:-1]):
        (s1, c1), (s2, c2) = lines[j], lines[j + 1]
        meet = (c2 - c1) / (s1 - s2) if s1 != s2 else math.nan
        # the lines of two whole pieces date a change better than the best row, which quantisation moves by a
        # few rows at 1 kHz; so their meeting is kept within a bin (the search's resolution) of that row, and
        # only a meeting farther off (nearly parallel lines) falls back to the rows' midpoint
        reach = 0.0 if i in exact else bins.width
        lo = min(t[max(i - 2, 0)], t[i - 1] - reach)
        hi = max(t[min(i + 1, n - 1)], t[i] + reach)
        times.append(meet if lo <= meet <= hi else 0.5 * (t[i - 1] + t[i]))
    times.append(float(t[-1]))
    items = [Segment(max(line[0], 0.0), b - a) for line, a, b in zip(lines, times[:-1], times[1:], strict=True)]
    return Protocol(tuple(items), name="from displacement")


def forward(record: LabRecord) -> tuple[LabRecord, bool]:
    """The record with its load point moving forward, and whether its displacement was negated to make it so.

    Rate and state sees the speed only: a transducer that counts the other way, or a velocity column written
    negative, is the same experiment, so a displacement that ends below its start is taken by its magnitude.
    (Whether it reverses mid-way is :func:`refuse_reversal`'s question.)
    """
    d = record.displacement
    if d[-1] - d[0] >= 0:
        return record, False
    return replace(record, displacement=-d), True


#: a piece moves when its speed is at least this share of the fastest piece's (below: a hold with drift)
MOVING_SHARE = 0.02


def refuse_reversal(record: LabRecord, protocol: Protocol) -> None:
    """DataError when the load point moves both ways: a piece of ``protocol`` (found from ``record``) whose own
    line runs backwards at a speed that is motion, not a hold's drift or noise, while another runs forwards.

    :func:`find_segments` gives a backward piece velocity 0, which would fit the record as a hold.
    """
    t, d = record.time, record.displacement
    pieces = []
    for a, b, _ in protocol.pieces():
        i0, i1 = np.searchsorted(t, [a, b], side="left")
        i0, i1 = i0 + 2, i1 - 2  # rows beside a change may lie on the other piece's line
        if i1 - i0 < 5:
            continue
        slope, intercept = _line(t[i0:i1], d[i0:i1])
        scatter = float(np.std(d[i0:i1] - slope * t[i0:i1] - intercept))
        travel = abs(slope) * float(t[i1 - 1] - t[i0])
        pieces.append((float(t[i0]), slope, travel > 10.0 * scatter))
    fastest = max((abs(v) for _, v, _ in pieces), default=0.0)
    moving = [(start, v) for start, v, clear in pieces if clear and abs(v) >= MOVING_SHARE * fastest > 0]
    backwards = [(start, v) for start, v in moving if v < 0]
    if backwards and len(backwards) < len(moving):
        start, v = backwards[0]
        ahead = next(u for _, u in moving if u > 0)
        raise DataError(
            f"{record.source}: the load point reverses: it moves at {ahead:.3g} m/s and, from t = "
            f"{record.t0 + start:.6g} s, at {v:.3g} m/s; expected it to move one way (fit each direction's rows "
            "with --window)"
        )


#: rows either side of a change whose scatter about the history gives the displacement's noise there
CHANGE_ROWS = 50


def change_time_uncertainty(
    time: np.ndarray, displacement: np.ndarray, protocol: Protocol, sampled_velocity: bool = False
) -> np.ndarray:
    """Each interior change time's standard uncertainty (s), as the displacement dates it.

    sqrt(2) s / |jump|, s the rows' scatter about the history within :data:`CHANGE_ROWS` rows either side, with the
    row spacing over sqrt(12) added where the change sits between two rows, and at every change where the
    displacement was integrated from a velocity column (``sampled_velocity``: :attr:`LabRecord.displacement_from`
    "velocity"), whose rows say only that the velocity changed since the row before; a change with no jump gets 0
    (docs/rsf.md, "the change times are fitted").
    """
    t = np.asarray(time, dtype=float)
    d = np.asarray(displacement, dtype=float)
    edges, speeds = protocol.boundaries, protocol.velocities
    off = d - protocol.displacement_at(t)
    out = np.zeros(max(speeds.size - 1, 0))
    for i in range(1, speeds.size):
        jump = abs(float(speeds[i] - speeds[i - 1]))
        k = int(np.clip(np.searchsorted(t, edges[i]), 1, t.size - 1))
        sides = [slice(max(k - CHANGE_ROWS, 0), k), slice(k, min(k + CHANGE_ROWS, t.size))]
        scatter = [_line_residuals(t[s], off[s]) for s in sides]
        pooled = np.concatenate(scatter)
        spread = float(np.sqrt(np.mean(pooled**2))) if pooled.size else 0.0
        halfway = abs(edges[i] - 0.5 * (t[k] + t[k - 1])) <= 1e-9 * max(abs(float(edges[i])), 1.0)
        spacing = float(t[k] - t[k - 1]) if halfway or sampled_velocity else 0.0
        out[i - 1] = math.hypot(math.sqrt(2.0) * spread / jump, spacing / math.sqrt(12.0)) if jump > 0 else 0.0
    return out


def level_velocity_uncertainty(time: np.ndarray, displacement: np.ndarray, protocol: Protocol) -> np.ndarray:
    """Each level's velocity standard uncertainty (m/s, or the displacement's unit per s), as the displacement
    measures it: the error of the slope of the straight line through the level's rows (the velocity
    :func:`find_segments` gives it) under :func:`find_segments`' own noise model.

    The line's slope is sum_i c_i d_i over the level's rows, c_i = (t_i - mean t) / sum (t - mean t)^2; with the
    rows' noise summed bin by bin (C_b = sum of c_i in bin b, each bin mean's variance var_b as measured, without
    the search's floors: an exact record's levels are exact) its variance is
    sum_b C_b^2 var_b, times the slope inflation at the level's length (the correlated noise and wander that make
    neighbouring stretches' velocities differ more than independent bins allow) and the pieces' excess misfit
    (at least 1; the bins beside a change left out).  0 for a level with fewer than 3 rows, and for every level
    of a record too short for the bins (docs/rsf.md, "What the history's own uncertainty does to a fit").
    """
    t = np.asarray(time, dtype=float)
    d = np.asarray(displacement, dtype=float)
    edges_t = protocol.boundaries
    out = np.zeros(len(protocol.segments))
    if t.size < 20:
        return out
    bins = _bins(t, d)
    rows = np.searchsorted(t, edges_t[1:-1], side="left")  # each later level's first row
    cuts = np.unique(np.clip(np.searchsorted(bins.first, rows, side="right") - 1, 1, bins.t.size - 1))
    bins = replace(bins, inflation=_slope_inflation(bins.t, bins.d, bins.var, list(cuts)))
    edges = np.array([0, *cuts, bins.t.size])
    guard = (np.diff(edges) >= 4).astype(int)
    lo, hi = edges[:-1] + guard, edges[1:] - guard
    sums = _running(1.0 / bins.var, bins.t, bins.d)
    used = int(np.sum(hi - lo))
    excess = max(float(np.sum(_misfit(sums, lo, hi))) / max(used - 2 * (edges.size - 1), 1), 1.0)
    bin_of = np.searchsorted(bins.first, np.arange(t.size), side="right") - 1
    tc = (t - t[0]) / bins.time_scale
    bounds = np.concatenate([[0], rows, [t.size]])
    for j, (i0, i1) in enumerate(itertools.pairwise(bounds)):
        if i1 - i0 < 3:
            continue
        u = tc[i0:i1] - float(np.mean(tc[i0:i1]))
        stt = float(np.sum(u * u))
        if not stt > 0:
            continue
        weights = np.bincount(bin_of[i0:i1] - bin_of[i0], weights=u / stt)
        measured = bins.measured if bins.measured is not None else bins.var
        inside = measured[bin_of[i0] : bin_of[i0] + weights.size]
        length = float(np.count_nonzero(weights))  # the level's bins
        variance = float(np.sum(weights**2 * inside)) * float(_inflation_at(bins, np.array([length]))[0]) * excess
        out[j] = math.sqrt(variance) * bins.scale / bins.time_scale
    return out


def _line_residuals(t: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Residuals of a straight line through (t, d), with its two degrees of freedom counted (none for < 3 rows)."""
    if t.size < 3:
        return np.zeros(0)
    tt = t - t.mean()
    stt = float(np.sum(tt * tt))
    slope = float(np.sum(tt * (d - d.mean()))) / stt if stt > 0 else 0.0
    r = d - d.mean() - slope * tt
    return r * math.sqrt(t.size / (t.size - 2))


#: the change-point search runs on at most this many equal time bins (each change is then placed on the full record)
SEARCH_BINS = 2000
#: rows of bins in one local straight-line fit of the noise model
_NOISE_WINDOW = 8


@dataclass(frozen=True)
class _Bins:
    """The record averaged in equal time bins, in scaled units (time and displacement O(1), a line removed)."""

    t: np.ndarray  # mean time of each bin (scaled)
    d: np.ndarray  # mean displacement (scaled)
    count: np.ndarray  # rows in each bin
    first: np.ndarray  # first row of each bin
    var: np.ndarray  # noise variance of each bin's mean (scaled)
    inflation: tuple[np.ndarray, np.ndarray]  # stretch lengths (bins) and their slope-variance inflation
    width: float  # the bins' width in seconds
    time_scale: float  # seconds per scaled time unit
    trend: float  # the slope of the line removed, in scaled units (added back to compare velocities)
    scale: float = 1.0  # the record's displacement per scaled unit
    measured: np.ndarray | None = None  # var as measured, without the floor the running sums' digits need


def _bins(t: np.ndarray, d: np.ndarray) -> _Bins:
    n = t.size
    span = float(t[-1] - t[0])
    tc = (t - t[0]) / span
    line = np.polyfit(tc, d, 1)
    dc = d - np.polyval(line, tc)
    scale = max(float(np.max(np.abs(dc))), 1e-300)
    dc = dc / scale
    steps = np.diff(t)
    if n <= SEARCH_BINS and np.max(steps) <= 1.5 * np.min(steps):
        first = np.arange(n)  # evenly sampled: a row is a bin
        width = span / max(n - 1, 1)
    else:  # equal time bins: a changed sampling rate changes only how many rows a bin holds
        bins = min(SEARCH_BINS, n)
        ids = np.minimum((tc * bins).astype(np.int64), bins - 1)
        first = np.flatnonzero(np.concatenate([[True], np.diff(ids) > 0]))
        width = span / bins
    count = np.diff(np.concatenate([first, [n]]))
    bt = np.add.reduceat(tc, first) / count
    bd = np.add.reduceat(dc, first) / count
    var, inflation, measured = _noise_model(bt, bd, count, quantum(d) / scale)
    return _Bins(bt, bd, count, first, var, inflation, width, span, float(line[0]) / scale, scale, measured)


def _window_residuals(bt: np.ndarray, bd: np.ndarray, width: int) -> tuple[np.ndarray, np.ndarray]:
    """Residuals of straight lines fitted to consecutive groups of ``width`` bins (one row per group), and the
    groups' first bins."""
    m = bt.size // width
    tt = bt[: m * width].reshape(m, width)
    dd = bd[: m * width].reshape(m, width)
    tt = tt - tt.mean(axis=1, keepdims=True)
    dd = dd - dd.mean(axis=1, keepdims=True)
    stt = np.sum(tt * tt, axis=1, keepdims=True)
    slope = np.divide(np.sum(tt * dd, axis=1, keepdims=True), stt, out=np.zeros_like(stt), where=stt > 0)
    return dd - slope * tt, np.arange(m) * width


def _noise_model(
    bt: np.ndarray, bd: np.ndarray, count: np.ndarray, q: float
) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray], np.ndarray]:
    """Each bin mean's noise variance, how much more the velocities of neighbouring stretches differ than that
    variance says (:func:`_slope_inflation`), and the variance as measured: without the floor of relative 3e-7
    the running sums' digits need, nor the q^2/12 of a step q (a noise-free record's is its printed precision's,
    and one that moves a whole number of steps per row, as `rsf simulate --every "0.1 s"` writes 1 um/s, shows no
    rounding at all; a quantised rig's rounding shows in the residuals).

    The variance of a bin mean is modelled as ``white / rows + floor`` from straight lines over a fixed span of
    bins, at least ``q^2 / 12`` per row for a quantisation step ``q`` (docs/rsf.md, "Velocity levels", step 2).
    """
    width = _NOISE_WINDOW if bt.size >= 4 * _NOISE_WINDOW else max(3, bt.size // 4)
    residual, starts = _window_residuals(bt, bd, width)
    per_window = np.sum(residual**2, axis=1) / (width - 2)
    inverse = np.array([np.mean(1.0 / count[s : s + width]) for s in starts])
    median_factor = _chi2_median_ratio(width - 2)
    classes = np.round(np.log2(1.0 / inverse)).astype(int)
    xs, vs = [], []
    for c in np.unique(classes):
        chosen = classes == c
        if np.count_nonzero(chosen) >= 3 or np.unique(classes).size == 1:
            xs.append(float(np.median(inverse[chosen])))
            vs.append(float(np.median(per_window[chosen])) / median_factor)
    white, floor = _two_part_variance(np.array(xs), np.array(vs))
    # the floor sits above the cancellation error of the running sums (relative 1e-16 * n)
    measured = white / count + floor
    var = np.maximum(measured, (q * q / 12.0) / count + (3e-7) ** 2)
    return var, _slope_inflation(bt, bd, var), measured


def _two_part_variance(x: np.ndarray, v: np.ndarray) -> tuple[float, float]:
    """``v = white * x + floor`` with both parts >= 0 (x the mean inverse row count of a class of bins)."""
    if x.size == 0:
        return 0.0, 0.0
    if x.size == 1 or np.ptp(x) < 0.2 * np.max(x):
        return 0.0, float(np.median(v))  # one sampling rate: the two parts cannot be told apart
    a, b = np.polyfit(x, v, 1)
    if a < 0:
        return 0.0, float(np.mean(v))
    if b < 0:
        return float(np.sum(v * x) / np.sum(x * x)), 0.0
    return float(a), float(b)


def _chi2_median_ratio(dof: int) -> float:
    """Median of chi^2_dof / dof (Wilson-Hilferty)."""
    return (1.0 - 2.0 / (9.0 * dof)) ** 3


def _slope_inflation(
    bt: np.ndarray, bd: np.ndarray, var: np.ndarray, breaks: list[int] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """How much more the slopes of neighbouring stretches of the record differ than the bins' variances say.

    Stretches of 8, 16, 32, ... bins against chi^2_1's median (docs/rsf.md, "Velocity levels", step 3); a stretch
    holding one of the proposed ``breaks`` is left out.  Returns the stretch lengths (bins) and the ratios, made
    non-decreasing and >= 1.
    """
    widths, ratios = [], []
    width = _NOISE_WINDOW
    marks = np.zeros(bt.size + 1)
    marks[np.asarray(breaks or [], dtype=int)] = 1.0
    crossed = np.concatenate([[0.0], np.cumsum(marks)])
    while bt.size // width >= 13:
        m = bt.size // width
        tt, dd, ww = (v[: m * width].reshape(m, width) for v in (bt, bd, 1.0 / var))
        sw = np.sum(ww, axis=1, keepdims=True)
        tm = np.sum(ww * tt, axis=1, keepdims=True) / sw
        dm = np.sum(ww * dd, axis=1, keepdims=True) / sw
        stt = np.sum(ww * (tt - tm) ** 2, axis=1)
        slope = np.sum(ww * (tt - tm) * (dd - dm), axis=1) / stt
        starts = np.arange(m) * width
        clean = crossed[starts + width] - crossed[starts + 1] == 0  # no break inside the stretch
        usable = clean[2:] & clean[1:-1] & clean[:-2]
        ratio = np.diff(slope, 2) ** 2 / (1.0 / stt[2:] + 4.0 / stt[1:-1] + 1.0 / stt[:-2])
        if np.count_nonzero(usable) < 5:
            break
        widths.append(width)
        ratios.append(float(np.median(ratio[usable])) / 0.455)
        width *= 2
    if not widths:
        return np.array([float(_NOISE_WINDOW)]), np.array([1.0])
    return np.array(widths, dtype=float), np.maximum.accumulate(np.maximum(ratios, 1.0))


def _inflation_at(bins: _Bins, length: np.ndarray) -> np.ndarray:
    """The slope-variance inflation for stretches of ``length`` bins (log-interpolated, held beyond the ends)."""
    widths, ratios = bins.inflation
    return np.interp(np.log(np.maximum(length, 1.0)), np.log(widths), ratios)


def _line(t: np.ndarray, d: np.ndarray) -> tuple[float, float]:
    slope, intercept = np.polyfit(t, d, 1)
    return float(slope), float(intercept)


def _misfit(sums: list[np.ndarray], lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Least-squares misfit of a straight line through rows [lo, hi)."""
    c, st, sd, stt, std, sdd = (s[hi] - s[lo] for s in sums)
    c = np.where(c > 0, c, 1.0)
    vt = stt - st * st / c
    cov = std - st * sd / c
    vd = sdd - sd * sd / c
    slope = np.divide(cov, vt, out=np.zeros_like(cov), where=vt > 0)
    return np.maximum(vd - slope * cov, 0.0)


def _pelt(bins: _Bins, min_bins: int = 3) -> list[int]:
    """Interior break bins minimising the bins' weighted misfit + ``4 ln n`` x inflation per piece (PELT)."""
    n = bins.t.size
    sums = _running(1.0 / bins.var, bins.t, bins.d)
    penalty = 4.0 * math.log(max(n, 3)) * float(bins.inflation[1][0])  # proposals: the shortest scale's
    best = np.full(n + 1, np.inf)
    best[0] = -penalty
    previous = np.zeros(n + 1, dtype=int)
    candidates = np.array([0], dtype=int)
    for end in range(min_bins, n + 1):
        newest = end - min_bins
        if newest > 0 and np.isfinite(best[newest]):
            candidates = np.append(candidates, newest)
        cost = best[candidates] + _misfit(sums, candidates, np.full_like(candidates, end)) + penalty
        k = int(np.argmin(cost))
        best[end], previous[end] = cost[k], candidates[k]
        candidates = candidates[cost - penalty <= best[end]]
    breaks = [n]
    while breaks[-1] > 0:
        breaks.append(int(previous[breaks[-1]]))
    return breaks[::-1][1:-1]


def _running(w: np.ndarray, t: np.ndarray, d: np.ndarray) -> list[np.ndarray]:
    """Running weighted sums of 1, t, d, t^2, t d, d^2 (what :func:`_misfit` reads)."""
    return [np.concatenate([[0.0], np.cumsum(v)]) for v in (w, w * t, w * d, w * t * t, w * t * d, w * d * d)]


def _piece_test(bins: _Bins, sums: list[np.ndarray], hinges: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Each piece's velocity (scaled units) and each change's t-value: the two pieces' slopes differ by how many
    standard errors (from the noise model, its inflation at the shorter piece's length and any excess misfit).

    The bin beside a change is left out of both pieces' lines (it may straddle the change), so a change's exact
    time within its bins does not matter here.
    """
    edges = np.array([0, *hinges, bins.t.size])
    lengths = np.diff(edges)
    guard = (lengths >= 4).astype(int)
    lo, hi = edges[:-1] + guard, edges[1:] - guard
    c, st, sd, stt, std, _ = (s[hi] - s[lo] for s in sums)
    vt = stt - st * st / c
    slopes = (std - st * sd / c) / vt + bins.trend
    excess = max(float(np.sum(_misfit(sums, edges[:-1], edges[1:]))) / max(bins.t.size - 2 * lengths.size, 1), 1.0)
    shorter = np.minimum(lengths[1:], lengths[:-1])
    var = (1.0 / vt[1:] + 1.0 / vt[:-1]) * excess * _inflation_at(bins, shorter)
    return slopes, np.diff(slopes) / np.sqrt(var)


#: a piece with fewer than ``min_points`` rows still counts as long enough where it has at least this many rows and
#: lasts as long as ``min_points`` rows at the record's usual spacing: a sparsely sampled stretch (an ODE solver's
#: own steps through steady sliding, as `rsf simulate -o` writes: 6 rows over the first 10 s)
SPARSE_ROWS = 4


def _significant_hinges(
    bins: _Bins, hinges: list[int], min_change: float, min_points: int, min_duration: float, spacing: float = 0.0
) -> list[int]:
    """Drop changes, weakest first, until each is significant, a real change of velocity and between pieces long
    enough (see :func:`find_segments`): at least ``min_points`` rows, or SPARSE_ROWS rows lasting ``min_points``
    times the record's usual row ``spacing`` (s; 0: rows alone), and ``min_duration`` seconds."""
    hinges = list(hinges)
    n = bins.t.size
    z_crit = math.sqrt(2.0 * math.log(max(n, 3))) + 2.0
    rows = np.concatenate([bins.first, [int(bins.first[-1] + bins.count[-1])]])
    sums = _running(1.0 / bins.var, bins.t, bins.d)
    while hinges:
        slopes, tvalue = _piece_test(bins, sums, hinges)
        strength = np.abs(tvalue)
        change = np.abs(np.diff(slopes)) / np.maximum(np.maximum(np.abs(slopes[1:]), np.abs(slopes[:-1])), 1e-300)
        weak = (strength < z_crit) | (change < min_change)
        edges = [0, *hinges, n]
        for j, (a, b) in enumerate(itertools.pairwise(edges)):
            duration = (bins.t[b - 1] - bins.t[a]) * bins.time_scale + bins.width
            count = rows[b] - rows[a]
            sparse = spacing > 0 and count >= SPARSE_ROWS and duration >= min_points * spacing
            if (count < min_points and not sparse) or duration < min_duration:
                neighbours = [k for k in (j - 1, j) if 0 <= k < len(hinges)]
                weak[min(neighbours, key=lambda k: strength[k])] = True
        if not weak.any():
            break
        candidates = np.flatnonzero(weak)
        del hinges[int(candidates[np.argmin(strength[candidates])])]
    return hinges


#: what a record that is not piecewise linear can do instead (the options as `rsf fit` spells them)
HISTORY_HINT = (
    "give the history with --segment or --protocol, or drive the model with the measured displacement: "
    "--history measured"
)
#: the pieces may miss the record by at most this many times its noise at the longest scale (a smooth curve
#: misses it by 1e5-1e7 times; the real sepiolite records by 0.5-0.9, synthetic quantised ones by about 1)
CURVED = 100.0


def _refuse_curved(
    bins: _Bins, hinges: list[int], t: np.ndarray, d: np.ndarray, t0: float, skip: np.ndarray | None = None
) -> None:  # fmt: skip
    """DataError when the straight pieces miss the binned record by far more than its noise: the load point's
    velocity changes smoothly, not in steps, or its displacement jumps (:func:`_jump`, then named).  Bins in
    ``skip`` (a short piece's, checked on its rows by :func:`_short_pieces`) are left out."""
    kept = np.ones(bins.t.size) if skip is None else (~skip).astype(float)
    sums = _running(kept / bins.var, bins.t, bins.d)
    counts = np.concatenate([[0.0], np.cumsum(kept)])
    edges = np.array([0, *hinges, bins.t.size])
    # the bin beside a change may straddle it: its mean lies off both lines by up to |dv| width / 8, which is
    # no curvature but, against bin means precise to a nanometre (exact or finely sampled quantised records),
    # hundreds of times the noise; so it is left out, as in _piece_test
    guard = (np.diff(edges) >= 4).astype(int)
    lo, hi = edges[:-1] + guard, edges[1:] - guard
    rows = counts[hi] - counts[lo]
    dof = max(int(np.sum(rows)) - 2 * int(np.count_nonzero(rows > 0)), 1)
    excess = float(np.sum(_misfit(sums, lo, hi))) / dof / float(bins.inflation[1][-1])
    if excess > CURVED:
        i = _jump(t, d)
        if i is not None:
            size = 1e6 * abs(d[i] - d[i - 1])  # its sign is that of a record the fit may have turned forward
            raise DataError(
                f"load-point displacement: it jumps by {size:.4g} µm between t = {t0 + t[i - 1]:.6g} and "
                f"{t0 + t[i]:.6g} s (a transducer re-zeroed?); expected a continuous load point (undo the offset, "
                "or fit the rows on one side of it with --window)"
            )
        raise DataError(
            f"load-point displacement: its {edges.size - 1} straight pieces miss it by {excess:.3g} times its noise; "
            f"expected piecewise-constant velocity ({HISTORY_HINT})"
        )


#: a short piece (shorter than find_segments' shortest, which drops it) is looked for where a proposed change has a
#: bin mean this many times its noise off the pieces, and kept where its excess travel (its rows' rms offset from
#: the best continuous two-piece line) is as many times the rows' noise: a servo overshoot of 0.3 s at 15 um/s
#: between 1 and 10 um/s, 100 Hz rows in 10 nm bits, is 100 times; the sepiolite records' suspects 1.6-5.2
SHORT_EXCESS = 10.0
#: a middle piece whose speed lies between its neighbours' (as a servo ramp's does) needs this much more
SHORT_RAMP_EXCESS = 3.0 * SHORT_EXCESS
#: and each of the three pieces must be straight: its rows' variance about its line at most this many times their
#: variance about lines as long as the search window elsewhere in the pieces either side.  A smooth ramp fails it:
#: 1 -> 10 um/s at 1 kHz in 10 nm bits over 0.05 s gives 3.4 (excess 10.5), over 0.08 s 8.5 (excess 17), over
#: 0.2 s 45 (excess 37); a smooth overshoot (1 -> 13 -> 10 um/s) over 0.03 s 9.2 (excess 10.4)
SHORT_MISFIT = 4.0
#: bins beyond the shortest piece's each side of a suspect bin searched for a short piece, and suspects tried
SHORT_MARGIN_BINS = 3
SHORT_TRIES = 12
#: above this many rows in the search window the two breaks are searched on a coarse grid first
SHORT_GRID = 600


@dataclass(frozen=True)
class _ShortPiece:
    """A short piece found on the rows: its first and one-past-last rows, the bins holding them (as hinges) and
    the search's hinges it replaces (those about it: the three pieces found on the rows stand for them)."""

    rows: tuple[int, int]
    hinges: tuple[int, int]
    replaces: tuple[int, ...]


def _short_pieces(
    t: np.ndarray, d: np.ndarray, bins: _Bins, hinges: list[int], proposed: list[int], min_change: float,
    min_points: int, shortest: float,
) -> list[_ShortPiece]:  # fmt: skip
    """Pieces too short for the binned search (under ``shortest`` seconds) that the record nonetheless holds: a
    servo's overshoot of a fraction of a second at a step.

    Where a change was proposed (PELT's, kept or not) and a bin mean within two bins of it lies SHORT_EXCESS times
    its noise off the pieces, the rows about it are searched for three straight pieces (two breaks at rows, the
    middle piece at least ``min_points`` rows) against the best continuous broken line (one kink).  The middle
    piece is kept when its rows lie SHORT_EXCESS times the rows' noise (rms) off the broken line (its excess
    travel), its speed differs from both neighbours' by ``min_change``, and each of the three pieces is straight to
    within SHORT_MISFIT times the rows' variance about lines as long elsewhere in the pieces either side (a smooth
    servo ramp is not); a middle speed between the neighbours' (as a ramp's is) needs SHORT_RAMP_EXCESS.  The
    three pieces replace the search's changes about it.  docs/rsf.md, "Velocity levels", step 6.
    """
    n_bins = bins.t.size
    edges = np.array([0, *hinges, n_bins])
    width = math.ceil(shortest / bins.width) + SHORT_MARGIN_BINS  # bins searched either side of a suspect
    z = np.abs(_bin_offsets(bins, edges))
    suspects = sorted(
        ((float(np.max(z[max(p - 2, 0) : p + 2])), p) for p in sorted(set(proposed) | set(hinges))), reverse=True
    )
    found: list[_ShortPiece] = []
    taken = np.zeros(n_bins, dtype=bool)
    for score, centre in suspects[:SHORT_TRIES]:
        if score <= SHORT_EXCESS:
            break
        if taken[centre]:
            continue
        piece = _short_piece_at(t, d, bins, edges, int(centre), width, min_change, min_points)
        taken[max(centre - width, 0) : centre + width + 1] = True
        if piece is None:
            continue
        if any(max(piece.rows[0], p.rows[0]) < min(piece.rows[1], p.rows[1]) + min_points for p in found):
            continue
        found.append(piece)
    return sorted(found, key=lambda p: p.rows[0])


def _bin_offsets(bins: _Bins, edges: np.ndarray) -> np.ndarray:
    """Each bin mean's offset from its piece's line (fitted without the bins beside the changes) over its noise."""
    z = np.zeros(bins.t.size)
    w = 1.0 / bins.var
    noise = np.sqrt(bins.var * float(bins.inflation[1][0]))
    for a, b in itertools.pairwise(edges):
        guard = 1 if b - a >= 4 else 0
        sel = slice(a + guard, b - guard)
        if b - a < 3:
            continue
        coef = np.polyfit(bins.t[sel], bins.d[sel], 1, w=np.sqrt(w[sel])) if b - a - 2 * guard >= 2 else None
        if coef is None:
            continue
        z[a:b] = (bins.d[a:b] - np.polyval(coef, bins.t[a:b])) / noise[a:b]
    return z


def _short_piece_at(
    t: np.ndarray, d: np.ndarray, bins: _Bins, edges: np.ndarray, centre: int, width: int, min_change: float,
    min_points: int,
) -> _ShortPiece | None:  # fmt: skip
    """The short piece about bin ``centre`` (see :func:`_short_pieces`), or None."""
    n_bins = bins.t.size
    inner = edges[1:-1]
    near = np.abs(inner - centre) <= width
    replaces = tuple(int(e) for e in inner[near])
    others = inner[~near]
    lo_bin = max([centre - width, *[e + 1 for e in others if e <= centre]], default=0)
    hi_bin = min([centre + width + 1, *[e - 1 for e in others if e > centre]], default=n_bins)
    lo_bin, hi_bin = max(lo_bin, 0), min(hi_bin, n_bins)
    first = np.concatenate([bins.first, [t.size]])
    i0, i1 = int(first[lo_bin]), int(first[hi_bin])
    side = 3  # rows an outer line needs at least
    if i1 - i0 < min_points + 2 * side + 2:
        return None
    tt, dd = t[i0:i1], d[i0:i1]
    span = max(float(tt[-1] - tt[0]), 1e-300)
    tc = (tt - tt[0]) / span
    scale = max(float(np.ptp(dd)), 1e-300)
    dc = (dd - np.polyval(np.polyfit(tc, dd, 1), tc)) / scale
    sums = _running(np.ones_like(tc), tc, dc)
    m = tc.size
    # two pieces: the continuous broken line (the load point does not jump), its kink anywhere among the rows
    s2 = _broken_line_misfit(tc, dc, side)
    # three pieces: breaks j1 < j2, the middle piece at least min_points rows
    j1, j2, s3 = _two_breaks(sums, m, side, min_points)
    if j1 is None:
        return None
    noise2 = _line_variance(t, d, i0, i1, edges, bins, m) / scale**2
    noise2 = max(noise2, (quantum(d) / scale) ** 2 / 12.0 + (3e-7) ** 2)  # as the bins' floor (_noise_model)
    rows_mid = j2 - j1
    excess = math.sqrt(max(s2 - s3, 0.0) / rows_mid)  # the middle rows' typical offset from two pieces
    cuts = np.array([0, j1, j2, m])
    each = _misfit(sums, cuts[:-1], cuts[1:]) / np.maximum(np.diff(cuts) - 2, 1)
    if float(np.max(each)) > SHORT_MISFIT * noise2:  # each piece straight: a ramp's middle piece is a chord
        return None
    speeds = [_line(tt[a:b], dd[a:b])[0] for a, b in ((0, j1), (j1, j2), (j2, m))]
    for v in (speeds[0], speeds[2]):
        if abs(speeds[1] - v) <= min_change * max(abs(speeds[1]), abs(v)):
            return None
    between = min(speeds[0], speeds[2]) <= speeds[1] <= max(speeds[0], speeds[2])
    if excess <= (SHORT_RAMP_EXCESS if between else SHORT_EXCESS) * math.sqrt(noise2):
        return None
    a_row, b_row = i0 + j1, i0 + j2
    bin_of = np.searchsorted(bins.first, [a_row, b_row], side="right") - 1
    a_bin, b_bin = int(bin_of[0]), int(bin_of[1])
    if b_row > int(bins.first[b_bin]):  # the break sits inside a bin: the piece after it starts at the next bin
        b_bin += 1
    if a_row > int(bins.first[a_bin]):
        a_bin += 1
    if not 0 < a_bin < b_bin < n_bins:
        return None
    return _ShortPiece((a_row, b_row), (a_bin, b_bin), replaces)


def _broken_line_misfit(t: np.ndarray, d: np.ndarray, side: int) -> float:
    """The least misfit of a continuous broken line (two straight pieces meeting at a kink) through (t, d), the
    kink at a row's time or halfway between two rows, at least ``side`` rows either side."""
    w, st, sd, stt, std, sdd = _running(np.ones_like(t), t, d)
    if t.size <= 2 * side:
        return math.inf
    kinks = np.concatenate([t[side:-side], 0.5 * (t[side - 1 : -side] + t[side : -side + 1])])
    k = np.searchsorted(t, kinks, side="left")  # rows [0, k) before the kink, [k, n) after
    n = t.size

    def moments(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, ...]:
        """Sums of 1, u, u^2, d, u d over rows [lo, hi), u = t - kink."""
        c, a1, a2, b0, b1 = (x[hi] - x[lo] for x in (w, st, stt, sd, std))
        return c, a1 - kinks * c, a2 - 2.0 * kinks * a1 + kinks**2 * c, b0, b1 - kinks * b0

    zero, end = np.zeros_like(k), np.full_like(k, n)
    cl, ul, uul, dl, udl = moments(zero, k)
    cr, ur, uur, dr, udr = moments(k, end)
    # d = c0 + v1 min(u, 0) + v2 max(u, 0): normal equations per kink
    rows = [np.stack([cl + cr, ul, ur], -1), np.stack([ul, uul, 0 * ul], -1), np.stack([ur, 0 * ur, uur], -1)]
    a = np.stack(rows, -2)
    b = np.stack([dl + dr, udl, udr], -1)
    ok = np.abs(np.linalg.det(a)) > 1e-300
    if not ok.any():
        return math.inf
    coef = np.linalg.solve(a[ok], b[ok][..., None])[..., 0]
    sse = float(sdd[-1]) - np.sum(coef * b[ok], axis=-1)
    return float(max(np.min(sse), 0.0))


def _two_breaks(sums: list[np.ndarray], m: int, side: int, min_points: int) -> tuple[int | None, int | None, float]:
    """The two break rows that leave three straight pieces with the least misfit (the middle one at least
    ``min_points`` rows, the outer ones ``side``); a coarse grid first where the rows are many."""
    step = max(math.ceil(m / SHORT_GRID), 1)

    def best(first_rows: np.ndarray, second_rows: np.ndarray) -> tuple[int | None, int | None, float]:
        a, b = np.meshgrid(first_rows, second_rows, indexing="ij")
        ok = (b - a >= min_points) & (a >= side) & (b <= m - side)
        if not ok.any():
            return None, None, math.inf
        a, b = a[ok], b[ok]
        cost = _misfit(sums, np.zeros_like(a), a) + _misfit(sums, a, b) + _misfit(sums, b, np.full_like(b, m))
        k = int(np.argmin(cost))
        return int(a[k]), int(b[k]), float(cost[k])

    grid = np.arange(side, m - side + 1, step)
    j1, j2, cost = best(grid, grid)
    if step > 1 and j1 is not None:
        j1, j2, cost = best(np.arange(max(j1 - step, side), min(j1 + step, m - side) + 1),
                            np.arange(max(j2 - step, side), min(j2 + step, m - side) + 1))  # fmt: skip
    return j1, j2, cost


def _line_variance(t: np.ndarray, d: np.ndarray, i0: int, i1: int, edges: np.ndarray, bins: _Bins, rows: int) -> float:
    """The rows' variance about straight lines through ``rows`` consecutive rows, in the pieces either side of
    rows [i0, i1) (those rows left out): the median over such stretches (a stretch holding a change is an outlier
    it ignores), over chi-square's median; fewer rows a stretch where the pieces hold under five of them."""
    first = np.concatenate([bins.first, [t.size]])
    k = int(np.searchsorted(edges, np.searchsorted(bins.first, i0, side="right") - 1, side="right"))
    start = int(first[edges[max(k - 1, 0)]])
    stop = int(first[edges[min(k + 1, edges.size - 1)]])
    chunks = [(start, i0), (i1, stop)]
    length = rows
    while length >= 8:
        values = []
        for a, b in chunks:
            count = (b - a) // length
            if count <= 0:
                continue
            tt = t[a : a + count * length].reshape(count, length)
            dd = d[a : a + count * length].reshape(count, length)
            tt = tt - tt.mean(axis=1, keepdims=True)
            dd = dd - dd.mean(axis=1, keepdims=True)
            stt = np.sum(tt * tt, axis=1, keepdims=True)
            slope = np.divide(np.sum(tt * dd, axis=1, keepdims=True), stt, out=np.zeros_like(stt), where=stt > 0)
            values.append(np.sum((dd - slope * tt) ** 2, axis=1) / (length - 2))
        pooled = np.concatenate(values) if values else np.zeros(0)
        if pooled.size >= 5:
            return float(np.median(pooled)) / _chi2_median_ratio(length - 2)
        length //= 2
    return math.inf


def _with_short_pieces(bins: _Bins, hinges: list[int], short: list[_ShortPiece]) -> tuple[list[int], np.ndarray]:
    """The hinges with each short piece's two in place of the one it replaces, and the bins the curvature test
    leaves out (each short piece's, and one either side: checked on its rows)."""
    skip = np.zeros(bins.t.size, dtype=bool)
    kept = set(hinges)
    for piece in short:
        kept.difference_update(piece.replaces)
        kept.update(piece.hinges)
        skip[max(piece.hinges[0] - 1, 0) : piece.hinges[1] + 1] = True
    return sorted(kept), skip


#: a row-to-row step this many times larger than the record's other large steps is a jump, not motion
JUMP_FACTOR = 20.0


def _jump(t: np.ndarray, d: np.ndarray) -> int | None:
    """The row at which the displacement jumps (the largest row-to-row step, when it is JUMP_FACTOR times the
    99.9th percentile of the others' |speed| times its own time step), or None.

    By speed, not by step, so a pause in sampling is no jump; the percentile lets the fastest 0.1 % of rows
    (a short fast segment) move without being one.
    """
    if t.size < 20:
        return None
    dt = np.diff(t)
    speed = np.abs(np.diff(d)) / dt
    i = int(np.argmax(speed))
    others = np.delete(speed, i)
    usual = float(np.percentile(others, 99.9))
    if speed[i] > JUMP_FACTOR * usual and speed[i] > 0:
        return i + 1
    return None


def _refine(
    t: np.ndarray, d: np.ndarray, breaks: list[int], first: np.ndarray, hinges: list[int | None], min_points: int
) -> list[int]:
    """Each interior break moved to its best row within two bins, between its neighbours (one whose hinge is None
    stays where it is), each piece keeping ``min_points`` rows (SPARSE_ROWS, a sparse piece with fewer)."""
    breaks = list(breaks)
    n = t.size
    for k in range(1, len(breaks) - 1):
        h = hinges[k - 1]
        if h is None:  # placed on its row already (a short piece's change)
            continue
        before, after = (min_points if b - a >= min_points else SPARSE_ROWS
                         for a, b in ((breaks[k - 1], breaks[k]), (breaks[k], breaks[k + 1])))  # fmt: skip
        lo = max(breaks[k - 1] + before, int(first[max(h - 2, 0)]))
        hi = min(breaks[k + 1] - after, int(first[h + 2]) if h + 2 < first.size else n)
        if hi <= lo:
            continue
        a, b = breaks[k - 1], breaks[k + 1]
        j = np.arange(lo, hi + 1)
        none = np.zeros_like(j)
        left = _residual_sums(t[a:hi], d[a:hi], lo - a)
        right = _residual_sums(t[lo:b][::-1], d[lo:b][::-1], b - hi)  # reversed: rows [j, b) come first
        cost = _misfit(left, none, j - a) + _misfit(right, none, b - j)
        breaks[k] = int(j[np.argmin(cost)])
    return breaks


def _residual_sums(t: np.ndarray, d: np.ndarray, clean: int) -> list[np.ndarray]:
    """Running sums (:func:`_running`) of the rows' offsets from the line through their first ``clean`` rows.

    One row more or less on a piece of 1e5 rows changes its misfit by 1e-9 of the misfit of the raw displacement
    about one line: sums over the whole record lose that to cancellation (a 1 kHz change was placed 2 rows late),
    sums of offsets from the piece's own line keep it.
    """
    fit = slice(0, clean if clean >= 3 else t.size)
    t0 = float(t[min(clean, t.size - 1)])
    span = max(float(np.ptp(t)), 1e-300)
    tc = (t - t0) / span
    e = d - np.polyval(np.polyfit(tc[fit], d[fit], 1), tc)
    return _running(np.ones_like(tc), tc, e)


#: the smoothing window makes a local line's velocity this precise (relative to the record's slower speeds)
SMOOTH_PRECISION = 0.05


def measured_history(record: LabRecord, smoothing: float | None = None) -> Protocol:
    """The load point's history as measured: its smoothed displacement, followed by piecewise-constant velocities.

    The levels' changes stay as kinks; between them the displacement is smoothed by local straight lines over
    ``smoothing`` seconds (default from the record's noise), never across a change, and cut into straight pieces
    where it bends; the velocities are >= 0 (docs/rsf.md, "The measured load point").
    """
    if smoothing is not None and not (
        isinstance(smoothing, (int, float)) and math.isfinite(smoothing) and smoothing > 0
    ):
        raise ParameterError(f"smoothing: expected a positive time window in seconds, got {smoothing!r}")
    record, _ = forward(record)
    t, d = record.time, record.displacement
    bins = _bins(t, d)
    scale = float(np.max(np.abs(d - np.polyval(np.polyfit(t, d, 1), t)))) or 1.0
    noise = math.sqrt(float(np.median(bins.var)) * float(bins.inflation[1][0])) * scale  # one bin's mean (m)
    window = float(smoothing) if smoothing is not None else _smoothing_window(t, d, noise, bins.width)
    kinks = None
    try:
        changes = find_segments(t, d, max_segments=10_000).boundaries
    except DataError:  # not straight pieces: steps, if any, are located as kinks between smoothly varying speeds
        changes, kinks = _kinks(t, d, window)
    grid_t, grid_d = _smoothed(t, d, changes, window)
    if kinks is not None:  # at a kink, its own fit's value (over several windows) for the two sides' short lines
        grid_d[np.searchsorted(grid_t, changes[1:-1])] = kinks
    keep = _bends(grid_t, grid_d, noise, np.searchsorted(grid_t, changes))
    knots_t, knots_d = grid_t[keep], np.maximum.accumulate(grid_d[keep])
    speeds = np.diff(knots_d) / np.diff(knots_t)
    items = tuple(Segment(float(v), float(dt)) for v, dt in zip(speeds, np.diff(knots_t), strict=True))
    return Protocol(items, name="measured load point")


def _smoothing_window(t: np.ndarray, d: np.ndarray, noise: float, width: float) -> float:
    """The window over which a line's slope through bins of ``noise`` is SMOOTH_PRECISION of the slower speeds:
    slope variance 12 noise^2 width / T^3 (T / width bins of a line over T)."""
    edges = np.unique(np.linspace(0, t.size - 1, 21).astype(int))
    speeds = np.abs(np.diff(d[edges])) / np.diff(t[edges])
    slow = float(np.percentile(speeds[speeds > 0], 10)) if np.any(speeds > 0) else 0.0
    span = float(t[-1] - t[0])
    if slow <= 0 or noise <= 0:
        return 3.0 * width
    window = (12.0 * noise**2 * width / (SMOOTH_PRECISION * slow) ** 2) ** (1.0 / 3.0)
    return float(min(max(window, 3.0 * width), span / 20.0))


def _smoothed(t: np.ndarray, d: np.ndarray, changes: np.ndarray, window: float) -> tuple[np.ndarray, np.ndarray]:
    """Local straight lines over ``window`` (truncated at each change, >= 5 rows) on a grid of window / 4 that
    holds every change; at a change the two sides' values are averaged (the load point is continuous)."""
    grid_t, grid_d = [], []
    for a, b in itertools.pairwise(changes):
        i0, i1 = np.searchsorted(t, [a, b + 1e-12 * max(abs(b), 1.0)])
        i1 = max(i1, i0 + 2)
        rows_t, rows_d = t[i0:i1], d[i0:i1]
        steps = max(math.ceil((b - a) / (0.25 * window)), 1)
        g = np.linspace(a, b, steps + 1)
        grid_t.append(g)
        grid_d.append(_local_lines(rows_t, rows_d, g, window))
    times = np.concatenate(grid_t)
    values = np.concatenate(grid_d)
    # the end of one piece and the start of the next are the same time: average them
    same = np.flatnonzero(np.diff(times) <= 0)
    values[same + 1] = 0.5 * (values[same] + values[same + 1])
    keep = np.ones(times.size, dtype=bool)
    keep[same] = False
    return times[keep], values[keep]


def _local_lines(t: np.ndarray, d: np.ndarray, g: np.ndarray, window: float) -> np.ndarray:
    """A straight line through the rows within window / 2 of each grid time (at least 5 rows), at that time."""
    if t.size < 3:
        return np.interp(g, t, d)
    t0 = float(t[0])
    tc, dc = t - t0, d - d[0]
    sums = [np.concatenate([[0.0], np.cumsum(v)]) for v in (np.ones_like(tc), tc, dc, tc * tc, tc * dc)]
    lo = np.searchsorted(t, g - 0.5 * window)
    hi = np.searchsorted(t, g + 0.5 * window, side="right")
    short = hi - lo < 5
    lo = np.where(short, np.clip(np.searchsorted(t, g) - 2, 0, max(t.size - 5, 0)), lo)
    hi = np.where(short, np.minimum(lo + 5, t.size), hi)
    c, st, sd, stt, std = (s[hi] - s[lo] for s in sums)
    vt = stt - st * st / c
    slope = np.divide(std - st * sd / c, vt, out=np.zeros_like(vt), where=vt > 0)
    return d[0] + sd / c + slope * (g - t0 - st / c)


def _bends(t: np.ndarray, d: np.ndarray, tolerance: float, fixed: np.ndarray) -> np.ndarray:
    """Indices of the points a broken line needs to stay within ``tolerance`` of (t, d) (Douglas-Peucker), the
    ``fixed`` ones always among them."""
    keep = np.zeros(t.size, dtype=bool)
    keep[np.clip(fixed, 0, t.size - 1)] = True
    keep[[0, -1]] = True
    stack = list(itertools.pairwise(np.flatnonzero(keep)))
    while stack:
        a, b = stack.pop()
        if b - a < 2:
            continue
        inner = slice(a + 1, b)
        line = d[a] + (d[b] - d[a]) * (t[inner] - t[a]) / (t[b] - t[a])
        miss = np.abs(d[inner] - line)
        k = int(np.argmax(miss))
        if miss[k] > tolerance:
            m = a + 1 + k
            keep[m] = True
            stack += [(a, m), (m, b)]
    return np.flatnonzero(keep)


#: a kink's local fit reaches this many smoothing windows either side of it, never past halfway to the next
#: proposed change; it is confirmed at KINK_CLOSE windows (at least KINK_ROWS rows either side)
KINK_WINDOWS = 8.0
KINK_CLOSE = 2.0
KINK_ROWS = 12
#: and its rows scatter about it by at most this many times the rows' variance about the smoothing's lines (a
#: step between drifting levels: 0.5-2.1, with correlated noise too; a servo ramp of 0.5-3 s: 5-440 over the
#: wider reach, 2-90 close to it)
KINK_MISFIT = 8.0


def _kinks(t: np.ndarray, d: np.ndarray, window: float) -> tuple[np.ndarray, np.ndarray]:
    """The change times (with the record's ends) of a load point that is not piecewise linear, and its
    displacement at each: velocity steps between stretches whose speed varies smoothly (a servo accelerating
    within each level), each a step at one instant located from the rows around it; none when the speed varies
    smoothly throughout.

    :func:`find_segments`' search proposes the changes (curvature refuses its pieces, not its changes); each is
    then fitted by a continuous broken line with a quadratic either side over a few smoothing windows
    (:func:`_local_kink`), which a steady acceleration does not bias as it biases where two whole pieces' lines
    meet.  It stays where the velocity jumps at that instant by more than ``min_change`` (20 %) of the faster side
    and by more than the search's critical number of its standard errors, both over those windows and again
    close to it (KINK_CLOSE windows): a step's jump is the same at every reach, while a smooth ramp, whose
    changes of acceleration within the wider reach a quadratic cannot follow, shows a jump that vanishes close to
    it.  And at both reaches the broken line must describe the rows to their noise (KINK_MISFIT): a short servo
    ramp looks like a jump close to it, but no broken line fits it.
    """
    ends = np.array([t[0], t[-1]])
    if t.size < 20:
        return ends, np.zeros(0)
    bins = _bins(t, d)
    proposed = _pelt(bins)
    bins = replace(bins, inflation=_slope_inflation(bins.t, bins.d, bins.var, proposed))
    hinges = _significant_hinges(bins, proposed, 0.2, 10, 5.0 * bins.width)
    guesses = [float(t[bins.first[h]]) for h in hinges]
    z_crit = math.sqrt(2.0 * math.log(max(bins.t.size, 3))) + 2.0
    edges = [float(t[0]), *guesses, float(t[-1])]
    row = float(np.median(np.diff(t)))
    scatter = float(np.median((d - _local_lines(t, d, t, window)) ** 2)) / 0.455  # the rows' variance (chi2_1)
    kept, values = [], []
    for j, guess in enumerate(guesses):
        fits = []
        for reach in (KINK_WINDOWS * window, max(KINK_CLOSE * window, KINK_ROWS * row)):
            lo = max(guess - reach, 0.5 * (edges[j] + guess))
            hi = min(guess + reach, 0.5 * (guess + edges[j + 2]))
            fits.append(_local_kink(t, d, lo, hi, guess, 3.0 * bins.width))
        if any(f is None or not _a_step(*f[2:5], z_crit) or f[5] > KINK_MISFIT * scatter for f in fits):
            continue
        if kept and fits[0][0] <= kept[-1]:  # each is fitted within halfway to its neighbours: kept in order
            continue
        kept.append(fits[0][0])
        values.append(fits[0][1])
    return np.array([t[0], *kept, t[-1]]), np.array(values)


def _a_step(before: float, after: float, se: float, z_crit: float) -> bool:
    """Whether a velocity jump from ``before`` to ``after`` (standard error ``se``) is a change of level: by more
    than 20 % of the faster side (find_segments' ``min_change``) and ``z_crit`` standard errors."""
    jump = abs(after - before)
    return jump > 0.2 * max(abs(before), abs(after)) and jump > z_crit * se


def _local_kink(
    t: np.ndarray, d: np.ndarray, lo: float, hi: float, guess: float, search: float
) -> tuple[float, float, float, float, float, float] | None:
    """The continuous broken line with a quadratic either side that fits the rows in [lo, hi] best, its kink
    within ``search`` of ``guess``: (kink time, displacement there, velocity before, velocity after, the velocity
    jump's standard error, the rows' variance about it); None with too few rows either side."""
    i0, i1 = np.searchsorted(t, [lo, hi])
    i1 = min(i1 + 1, t.size)
    tt, dd = t[i0:i1], d[i0:i1]
    if np.sum(tt < guess) < KINK_ROWS // 2 or np.sum(tt > guess) < KINK_ROWS // 2:
        return None
    span = max(hi - lo, 1e-300)
    level = float(np.interp(guess, tt, dd))
    size = max(float(np.ptp(dd)), 1e-300)
    y = (dd - level) / size

    def fit(tau: float) -> tuple[float, np.ndarray, np.ndarray]:
        u = (tt - tau) / span
        before, after = np.minimum(u, 0.0), np.maximum(u, 0.0)
        x = np.column_stack([np.ones_like(u), before, before**2, after, after**2])
        coef, *_ = np.linalg.lstsq(x, y, rcond=None)
        r = y - x @ coef
        return float(r @ r), coef, x

    a = max(guess - search, tt[KINK_ROWS // 2 - 1])
    b = min(guess + search, tt[-(KINK_ROWS // 2)])
    if not a < b:
        return None
    grid = np.unique(np.concatenate([tt[(tt >= a) & (tt <= b)], np.linspace(a, b, 41)]))
    costs = [fit(x)[0] for x in grid]
    k = int(np.argmin(costs))
    left, right = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    from scipy.optimize import minimize_scalar

    best = minimize_scalar(lambda x: fit(x)[0], bounds=(left, right), method="bounded",
                           options={"xatol": 1e-9 * span})  # fmt: skip
    tau = float(best.x) if best.fun <= costs[k] else float(grid[k])
    sse, coef, x = fit(tau)
    dof = max(y.size - x.shape[1], 1)
    cov = np.linalg.pinv(x.T @ x) * sse / dof
    contrast = np.array([0.0, -1.0, 0.0, 1.0, 0.0])
    se = math.sqrt(max(float(contrast @ cov @ contrast), 0.0)) * size / span
    before, after = float(coef[1]) * size / span, float(coef[3]) * size / span
    return tau, level + float(coef[0]) * size, before, after, se, sse / dof * size**2
