"""Lab records for rate-and-state fits: delimited text as rigs write it, and the load-point history.

A record has time, load-point displacement and friction.  Columns are found
by name: the package's own trace CSV (``time``, ``load_point_displacement``,
``friction``), or any header mapped with ``columns={"time": "Time(s)",
"displacement": "Displ(microns)", "friction": "Friction"}`` and a
``displacement_unit`` such as ``"um"``.  A record without a displacement column
but with the load point's velocity (``load_point_velocity``, ``velocity`` or a
mapped ``velocity=...``, in displacement units per time unit) has it integrated
(trapezoids) into the displacement.  Tab, comma, semicolon or whitespace
separated; ``#`` comments are skipped.

The load point's velocity history comes from the displacement record:
:func:`find_segments` splits it into straight pieces by the exact penalised
least-squares segmentation (PELT with O(1) misfits from running sums), then
merges neighbours whose velocities differ by less than ``min_change``.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..columns import split_header, with_units
from ..errors import DataError, ParameterError
from ..fileio import protect_inputs
from ..protocols import Protocol, Segment

__all__ = ["LabRecord", "find_segments", "parse_columns", "read_record"]

ROLES = ("time", "displacement", "friction", "velocity")
_DEFAULT_NAMES = {
    "time": ("time", "time(s)", "time_s", "t"),
    "displacement": ("load_point_displacement", "displacement", "displ", "lp_disp", "displ(m)"),
    "friction": ("friction", "mu", "friction_coefficient"),
    "velocity": ("load_point_velocity", "velocity", "lp_velocity", "lp_vel"),
}


@dataclass(frozen=True)
class LabRecord:
    """Time (s, from the record's start), load-point displacement (m), friction; ``t0`` is the original start.

    ``length_unit`` is the unit the record's displacement was written in: reports give lengths in it.
    """

    time: np.ndarray
    displacement: np.ndarray
    friction: np.ndarray
    t0: float = 0.0
    source: str = "record"
    length_unit: str = "m"

    def __len__(self) -> int:
        return int(self.time.size)

    @classmethod
    def from_arrays(
        cls, time: Any, displacement: Any, friction: Any, source: str = "arrays", length_unit: str = "m"
    ) -> LabRecord:
        t = np.asarray(time, dtype=float).ravel()
        d = np.asarray(displacement, dtype=float).ravel()
        f = np.asarray(friction, dtype=float).ravel()
        if not (t.size == d.size == f.size) or t.size < 10:
            raise DataError(f"{source}: expected time, displacement and friction of one length >= 10")
        for name, col in (("time", t), ("displacement", d), ("friction", f)):
            bad = ~np.isfinite(col)
            if bad.any():
                raise DataError(f"{source}: row {int(np.argmax(bad)) + 1}: {name} is not a finite number")
        step = np.diff(t)
        if np.any(step <= 0):
            row = int(np.argmax(step <= 0)) + 2
            raise DataError(f"{source}: row {row}: time {t[row - 1]:g} s does not increase")
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


def parse_columns(text: str | None) -> dict[str, str]:
    """``time="Time(s)",displacement="Displ(microns)",friction=Friction`` to a mapping role -> header."""
    if not text:
        return {}
    mapping: dict[str, str] = {}
    for item in re.findall(r'(\w+)\s*=\s*("[^"]*"|\'[^\']*\'|[^,]*)', text):
        role, name = item[0].strip().lower(), item[1].strip().strip("\"'")
        if role not in ROLES:
            raise ParameterError(f"--columns: unknown role {role!r}; expected time, displacement, friction or velocity")
        mapping[role] = name
    if not mapping:
        raise ParameterError(f'--columns {text!r}: expected ROLE=HEADER pairs, e.g. time="Time(s)",friction=Friction')
    return mapping


def read_record(
    path: str | Path, columns: dict[str, str] | None = None, displacement_unit: str = "m", time_unit: str = "s"
) -> LabRecord:
    """A :class:`LabRecord` from delimited text (see the module notes)."""
    import pandas as pd

    from ..units import to_si

    path = Path(path)
    if not path.is_file():
        raise DataError(f"{path}: record not found")
    protect_inputs([path])  # in a command, no output may replace the record
    d_scale = to_si(f"1 {displacement_unit}", "length", "--displacement-unit")
    t_scale = to_si(f"1 {time_unit}", "time", "--time-unit")
    try:
        with open(path, encoding="utf-8", errors="replace") as handle:
            head = "".join(line for _, line in zip(range(20), handle, strict=False) if not line.startswith("#"))
        sep = "\t" if "\t" in head else ";" if head.count(";") > head.count(",") else "," if "," in head else r"\s+"
        frame = pd.read_csv(path, sep=sep, comment="#", engine="c" if len(sep) == 1 else "python")
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise DataError(f"{path}: cannot read as delimited text ({str(exc).splitlines()[0]})") from None
    headers = {str(c).strip(): c for c in frame.columns}
    bracketed = {str(c): split_header(str(c)) for c in frame.columns}  # "time [s]" as this package writes it
    lower = {k.lower(): v for k, v in headers.items()}
    lower.update(
        {name.lower(): c for c, (name, unit) in bracketed.items() if unit is not None and name.lower() not in lower}
    )
    chosen = {}
    for role in ROLES:
        if role == "velocity" and "displacement" in chosen:
            continue
        if columns and role in columns:
            wanted = columns[role]
            if wanted not in headers:
                found = ", ".join(headers) or "none"
                raise DataError(f"{path}: no column {wanted!r} (for {role}); found {found}")
            chosen[role] = headers[wanted]
            continue
        match = next((lower[n] for n in _DEFAULT_NAMES[role] if n in lower), None)
        if match is None and role == "displacement" and not (columns and "velocity" in columns):
            if any(n in lower for n in _DEFAULT_NAMES["velocity"]):
                continue  # the velocity column gives it
        if match is None and role == "displacement" and columns and "velocity" in columns:
            continue
        if match is None:
            found = ", ".join(headers) or "none"
            raise DataError(
                f"{path}: no {role} column; found {found} (map them with --columns time=...,displacement=...,"
                "friction=...)"
            )
        chosen[role] = match
    data = {role: pd.to_numeric(frame[col], errors="coerce").to_numpy(dtype=float) for role, col in chosen.items()}
    unit_of_role = {role: bracketed[str(col)][1] for role, col in chosen.items()}

    def in_si(role: str, dimension: str, default: float) -> np.ndarray:
        """A column in SI: by the unit in its header's brackets (the file's word), else by the option."""
        unit = unit_of_role.get(role)
        factor = to_si(f"1 {unit}", dimension, f"column {chosen[role]!r}") if unit else default
        return data[role] * factor

    time = in_si("time", "time", t_scale)
    if "displacement" in data:
        displacement = in_si("displacement", "length", d_scale)
    else:
        displacement = _integrated(time, in_si("velocity", "velocity", d_scale / t_scale), path)
    shown_unit = unit_of_role.get("displacement") or displacement_unit.strip()
    return LabRecord.from_arrays(time, displacement, data["friction"], str(path), shown_unit)


def _integrated(time: np.ndarray, velocity: np.ndarray, path: Path) -> np.ndarray:
    """Displacement from the load point's velocity by trapezoids (in the record's units)."""
    bad = ~np.isfinite(velocity)
    if bad.any():
        raise DataError(f"{path}: row {int(np.argmax(bad)) + 1}: velocity is not a finite number")
    if velocity.size < 2:
        return np.zeros_like(velocity)
    steps = 0.5 * (velocity[1:] + velocity[:-1]) * np.diff(time)
    return np.concatenate([[0.0], np.cumsum(steps)])


def find_segments(
    time: np.ndarray, displacement: np.ndarray, max_segments: int = 60, min_change: float = 0.2, min_points: int = 10
) -> Protocol:
    """The load point's piecewise-constant velocity history from its displacement record.

    The optimal segmentation of the displacement into straight pieces under a
    penalty per piece (PELT, Killick et al. 2012, exact for an additive cost):
    each piece costs its least-squares misfit plus ``4 sigma^2 ln n``, sigma the
    displacement's white-noise level from second differences.  Neighbouring
    pieces whose velocities differ by less than ``min_change`` (relative) are
    merged; a change time is where the two fitted lines meet (the load point's
    displacement is continuous).  Raises DataError when more than
    ``max_segments`` pieces remain (the displacement is not piecewise linear).
    """
    t = np.asarray(time, dtype=float)
    d = np.asarray(displacement, dtype=float)
    n = t.size
    if n < 2 * min_points:
        return Protocol((Segment(max(_line(t, d)[0], 0.0), float(t[-1] - t[0])),), name="from displacement")
    breaks = _merge(t, d, _segment(t, d, min_points), min_change)
    if len(breaks) - 1 > max_segments:
        raise DataError(
            f"load-point displacement: {len(breaks) - 1} straight pieces found, more than {max_segments}; "
            "expected piecewise-constant velocity (give the history with --segment or --protocol)"
        )
    lines = [_line(t[i0:i1], d[i0:i1]) for i0, i1 in itertools.pairwise(breaks)]
    times = [0.0]
    for j, i in enumerate(breaks[1:-1]):
        (s1, c1), (s2, c2) = lines[j], lines[j + 1]
        meet = (c2 - c1) / (s1 - s2) if s1 != s2 else math.nan
        lo, hi = t[max(i - 2, 0)], t[min(i + 1, n - 1)]
        times.append(meet if lo <= meet <= hi else 0.5 * (t[i - 1] + t[i]))
    times.append(float(t[-1]))
    items = [Segment(max(line[0], 0.0), b - a) for line, a, b in zip(lines, times[:-1], times[1:], strict=True)]
    return Protocol(tuple(items), name="from displacement")


def _noise(d: np.ndarray) -> float:
    """White-noise level from second differences (1.4826 MAD: the kinks do not inflate it)."""
    if d.size < 4:
        return 0.0
    second = np.diff(d, 2)
    return float(1.4826 * np.median(np.abs(second - np.median(second))) / math.sqrt(6.0))


def _line(t: np.ndarray, d: np.ndarray) -> tuple[float, float]:
    slope, intercept = np.polyfit(t, d, 1)
    return float(slope), float(intercept)


def _cumulative_sums(t: np.ndarray, d: np.ndarray) -> list[np.ndarray]:
    """Running sums for O(1) straight-line misfits; t and d scaled to O(1) so the differences keep their digits."""
    tc = (t - t.mean()) / max(float(np.ptp(t)), 1e-300)
    dc = d - np.polyval(np.polyfit(tc, d, 1), tc)
    dc = dc / max(float(np.max(np.abs(dc))), 1e-300)
    return [np.concatenate([[0.0], np.cumsum(v)]) for v in (np.ones_like(tc), tc, dc, tc * tc, tc * dc, dc * dc)]


def _misfit(sums: list[np.ndarray], lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Least-squares misfit of a straight line through rows [lo, hi)."""
    c, st, sd, stt, std, sdd = (s[hi] - s[lo] for s in sums)
    vt = stt - st * st / c
    cov = std - st * sd / c
    vd = sdd - sd * sd / c
    slope = np.divide(cov, vt, out=np.zeros_like(cov), where=vt > 0)
    return np.maximum(vd - slope * cov, 0.0)


#: above this many rows the search runs on block means and each break is then placed on the full record
SEARCH_ROWS = 2000


def _segment(t: np.ndarray, d: np.ndarray, min_points: int) -> list[int]:
    """PELT's breaks; on a long record found on block means (the pruning keeps every candidate inside a straight
    piece, so the search grows as n^2 there), then each break moved to its best row between its neighbours."""
    n = t.size
    block = math.ceil(n / SEARCH_ROWS)
    if block <= 1:
        return _pelt(t, d, min_points)
    rows = (n // block) * block
    coarse_t = t[:rows].reshape(-1, block).mean(axis=1)
    coarse_d = d[:rows].reshape(-1, block).mean(axis=1)
    coarse = _pelt(coarse_t, coarse_d, max(3, math.ceil(min_points / block)))
    breaks = [0, *[b * block for b in coarse[1:-1]], n]
    sums = _cumulative_sums(t, d)
    penalty = _penalty(sums, n)
    breaks = _refine(sums, breaks, block, min_points)
    # a block straddling a change looks like a short piece of its own: drop every break the full record's
    # penalised misfit does not pay for (each drop re-placing the others)
    improved = True
    while improved and len(breaks) > 2:
        improved = False
        current = _objective(sums, breaks, penalty)
        for k in range(1, len(breaks) - 1):
            fewer = _refine(sums, breaks[:k] + breaks[k + 1 :], block, min_points)
            if _objective(sums, fewer, penalty) < current:
                breaks, improved = fewer, True
                break
    return breaks


def _penalty(sums: list[np.ndarray], n: int) -> float:
    """The cost of one more piece: 4 sigma^2 ln n in the running sums' scaled units."""
    scaled = sums[2][1:] - sums[2][:-1]
    # the floor sits above the cancellation error of the running sums (relative 1e-16 * n)
    sigma = max(_noise(scaled), 3e-7)
    return 4.0 * sigma**2 * math.log(n)


def _objective(sums: list[np.ndarray], breaks: list[int], penalty: float) -> float:
    lo, hi = np.array(breaks[:-1]), np.array(breaks[1:])
    return float(np.sum(_misfit(sums, lo, hi))) + penalty * (len(breaks) - 1)


def _refine(sums: list[np.ndarray], breaks: list[int], block: int, min_points: int) -> list[int]:
    """Each interior break moved to its best row within two blocks, between its neighbours."""
    breaks = list(breaks)
    for k in range(1, len(breaks) - 1):
        lo = max(breaks[k - 1] + min_points, breaks[k] - 2 * block)
        hi = min(breaks[k + 1] - min_points, breaks[k] + 2 * block)
        if hi <= lo:
            continue
        j = np.arange(lo, hi + 1)
        cost = _misfit(sums, np.full_like(j, breaks[k - 1]), j) + _misfit(sums, j, np.full_like(j, breaks[k + 1]))
        breaks[k] = int(j[np.argmin(cost)])
    return breaks


def _pelt(t: np.ndarray, d: np.ndarray, min_points: int) -> list[int]:
    """Break indices ``[0, ..., n]`` minimising total misfit + penalty per piece (pruned exact search)."""
    n = t.size
    sums = _cumulative_sums(t, d)
    penalty = _penalty(sums, n)
    best = np.full(n + 1, np.inf)
    best[0] = -penalty
    previous = np.zeros(n + 1, dtype=int)
    candidates = np.array([0], dtype=int)
    for end in range(min_points, n + 1):
        newest = end - min_points
        if newest > 0 and np.isfinite(best[newest]):
            candidates = np.append(candidates, newest)
        cost = best[candidates] + _misfit(sums, candidates, np.full_like(candidates, end)) + penalty
        k = int(np.argmin(cost))
        best[end], previous[end] = cost[k], candidates[k]
        candidates = candidates[cost - penalty <= best[end]]
    breaks = [n]
    while breaks[-1] > 0:
        breaks.append(int(previous[breaks[-1]]))
    return breaks[::-1]


def _merge(t: np.ndarray, d: np.ndarray, breaks: list[int], min_change: float) -> list[int]:
    """Drop the break between the two most similar neighbouring velocities while they differ by < min_change."""
    breaks = list(breaks)
    while len(breaks) > 2:
        slopes = [_line(t[a:b], d[a:b])[0] for a, b in itertools.pairwise(breaks)]
        change = [abs(s1 - s2) / max(abs(s1), abs(s2), 1e-300) for s1, s2 in itertools.pairwise(slopes)]
        j = int(np.argmin(change))
        if change[j] >= min_change:
            break
        del breaks[j + 1]
    return breaks
