"""Lab records for rate-and-state fits: delimited text as rigs write it, and the load-point history.

A record has time, load-point displacement and friction.  Columns are found
by name: the package's own trace CSV (``time``, ``load_point_displacement``,
``friction``), or any header mapped with ``columns={"time": "Time(s)",
"displacement": "Displ(microns)", "friction": "Friction"}`` and a
``displacement_unit`` such as ``"um"``.  Tab, comma, semicolon or whitespace
separated; ``#`` comments are skipped.

The load point's velocity history comes from the displacement record:
:func:`find_segments` splits it into straight pieces (binary segmentation of a
piecewise-linear least-squares fit, with cumulative sums, so it costs O(n) per
split) and a split is kept only where the two slopes differ by more than
``min_change`` (relative) and the split explains much more than the noise.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..columns import with_units
from ..errors import DataError, ParameterError
from ..fileio import protect_inputs
from ..protocols import Protocol, Segment

__all__ = ["LabRecord", "find_segments", "parse_columns", "read_record"]

ROLES = ("time", "displacement", "friction")
_DEFAULT_NAMES = {
    "time": ("time", "time(s)", "time_s", "t"),
    "displacement": ("load_point_displacement", "displacement", "displ", "lp_disp", "displ(m)"),
    "friction": ("friction", "mu", "friction_coefficient"),
}


@dataclass(frozen=True)
class LabRecord:
    """Time (s, from the record's start), load-point displacement (m), friction; ``t0`` is the original start."""

    time: np.ndarray
    displacement: np.ndarray
    friction: np.ndarray
    t0: float = 0.0
    source: str = "record"

    def __len__(self) -> int:
        return int(self.time.size)

    @classmethod
    def from_arrays(cls, time: Any, displacement: Any, friction: Any, source: str = "arrays") -> LabRecord:
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
        return cls(t - t[0], d - d[0], f, float(t[0]), source)

    def to_frame(self) -> Any:
        import pandas as pd

        frame = pd.DataFrame(
            {"time": self.time, "load_point_displacement": self.displacement, "friction": self.friction}
        )
        return with_units(frame)

    def plot(self, ax: Any = None) -> Any:
        from ..plotting import apply_style, new_axes

        ax = new_axes(ax)
        ax.plot(self.displacement * 1e6, self.friction, ".", ms=1.5, color="#777777")
        ax.set_xlabel("load-point displacement (µm)")
        ax.set_ylabel("friction μ")
        return apply_style(ax)


def parse_columns(text: str | None) -> dict[str, str]:
    """``time="Time(s)",displacement="Displ(microns)",friction=Friction`` to a mapping role -> header."""
    if not text:
        return {}
    mapping: dict[str, str] = {}
    for item in re.findall(r'(\w+)\s*=\s*("[^"]*"|\'[^\']*\'|[^,]*)', text):
        role, name = item[0].strip().lower(), item[1].strip().strip("\"'")
        if role not in ROLES:
            raise ParameterError(f"--columns: unknown role {role!r}; expected time, displacement, friction")
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
    lower = {k.lower(): v for k, v in headers.items()}
    chosen = {}
    for role in ROLES:
        if columns and role in columns:
            wanted = columns[role]
            if wanted not in headers:
                found = ", ".join(headers) or "none"
                raise DataError(f"{path}: no column {wanted!r} (for {role}); found {found}")
            chosen[role] = headers[wanted]
            continue
        match = next((lower[n] for n in _DEFAULT_NAMES[role] if n in lower), None)
        if match is None:
            found = ", ".join(headers) or "none"
            raise DataError(
                f"{path}: no {role} column; found {found} (map them with --columns time=...,displacement=...,"
                "friction=...)"
            )
        chosen[role] = match
    data = {role: pd.to_numeric(frame[col], errors="coerce").to_numpy(dtype=float) for role, col in chosen.items()}
    return LabRecord.from_arrays(data["time"] * t_scale, data["displacement"] * d_scale, data["friction"], str(path))


def find_segments(
    time: np.ndarray, displacement: np.ndarray, max_segments: int = 12, min_change: float = 0.2, min_points: int = 20
) -> Protocol:
    """The load point's piecewise-constant velocity history from its displacement record."""
    t = np.asarray(time, dtype=float)
    d = np.asarray(displacement, dtype=float)
    breaks = [0, t.size]
    noise = max(_noise(d), 1e-300)
    while len(breaks) - 1 < max_segments:
        best = None
        for i0, i1 in itertools.pairwise(breaks):
            split = _best_split(t[i0:i1], d[i0:i1], min_points)
            if split is None:
                continue
            j, gain, s_left, s_right = split
            relative = abs(s_left - s_right) / max(abs(s_left), abs(s_right), 1e-300)
            if relative < min_change or gain < 100 * noise**2:
                continue
            if best is None or gain > best[1]:
                best = (i0 + j, gain)
        if best is None:
            break
        breaks = sorted([*breaks, best[0]])
    lines = [_line(t[i0:i1], d[i0:i1]) for i0, i1 in itertools.pairwise(breaks)]
    times = [0.0]
    for j, i in enumerate(breaks[1:-1]):
        (s1, c1), (s2, c2) = lines[j], lines[j + 1]
        # the load point's displacement is continuous: the change is where the two lines meet
        meet = (c2 - c1) / (s1 - s2) if s1 != s2 else math.nan
        lo, hi = t[max(i - 2, 0)], t[min(i + 1, t.size - 1)]
        times.append(meet if lo <= meet <= hi else 0.5 * (t[i - 1] + t[i]))
    times.append(float(t[-1]))
    items = [Segment(max(line[0], 0.0), b - a) for line, a, b in zip(lines, times[:-1], times[1:], strict=True)]
    return Protocol(tuple(items), name="from displacement")


def _noise(d: np.ndarray) -> float:
    """Scatter of the displacement about a smooth line (from second differences)."""
    if d.size < 4:
        return 0.0
    return float(np.std(np.diff(d, 2)) / math.sqrt(6.0))


def _line(t: np.ndarray, d: np.ndarray) -> tuple[float, float]:
    slope, intercept = np.polyfit(t, d, 1)
    return float(slope), float(intercept)


def _best_split(t: np.ndarray, d: np.ndarray, min_points: int) -> tuple[int, float, float, float] | None:
    """Index splitting [0, n) into two straight-line fits with the least total squared error, and the gain."""
    n = t.size
    if n < 2 * min_points:
        return None
    tc = t - t.mean()
    dc = d - d.mean()
    sums = [np.concatenate([[0.0], np.cumsum(v)]) for v in (np.ones(n), tc, dc, tc * tc, tc * dc, dc * dc)]

    def sse(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        c, st, sd, stt, std, sdd = (s[hi] - s[lo] for s in sums)
        vt = stt - st * st / c
        cov = std - st * sd / c
        vd = sdd - sd * sd / c
        slope = np.divide(cov, vt, out=np.zeros_like(cov), where=vt > 0)
        return np.maximum(vd - slope * cov, 0.0), slope

    idx = np.arange(min_points, n - min_points + 1)
    left, s_left = sse(np.zeros_like(idx), idx)
    right, s_right = sse(idx, np.full_like(idx, n))
    total, _ = sse(np.array([0]), np.array([n]))
    k = int(np.argmin(left + right))
    return int(idx[k]), float(total[0] - left[k] - right[k]), float(s_left[k]), float(s_right[k])
