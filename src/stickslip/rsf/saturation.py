"""A saturated (clipped) friction sensor: rows that sit at the record's maximum or minimum (docs/rsf.md, "A saturated
sensor").

A sensor driven past its range reads its limit: a run of rows exactly at the record's maximum (or minimum).  Its
steady noise repeats a value now and then (the quantisation), so the test is whether the run is far longer than the
record's own repeats allow: with ``p`` the share of consecutive rows elsewhere that repeat their predecessor, a run
of ``L`` rows arises by chance about ``n p**(L - 1)`` times in ``n`` rows, and it must also be several times the
longest run of any other value (a noise-free, quantised record repeats its steady values for as long as it is
steady, at its extremes as anywhere; one that repeats its predecessor in more than MAX_REPEAT of its rows has
noise within about a quantum, and no run is read as a saturation).  The rows at the limit are censored (their
friction is the limit or beyond): the fit leaves them out, and with them the rows beside them whose model friction
comes within CENSOR_BAND of their rms of the limit (their noise may have carried them to it), chosen by the model so
that no row is kept or left out by its own noise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .data import LabRecord

__all__ = ["Saturation", "find_saturation"]

#: a run at the record's maximum or minimum shorter than this is never a saturation
MIN_RUN = 5
#: ... nor one whose count expected by chance (rows times the repeat share to its length) exceeds this
CHANCE = 1e-6
#: ... nor one shorter than this many times the longest run of any other value
OTHER_RUNS = 4.0
#: ... nor any where more than this share of the other consecutive rows repeat a value: the noise is then within
#: about a quantum, and steady sliding reads one value for as long as it lasts, at a limit or not
MAX_REPEAT = 0.5
#: rows whose model friction is within this many residual rms of the limit are censored too
CENSOR_BAND = 3.0
#: ... nor any in a record whose rows off its extremes scatter (second differences, robust) by less than this share
#: of its range: a noise-free record (a model's output) has no sensor, and a flat stretch at its extreme is steady
#: sliding (the bond model's step in `stickslip compare` opens with 502 rows at its minimum, its scatter 1e-10)
NOISE_FREE = 1e-6


@dataclass(frozen=True)
class Saturation:
    """The limit a saturated sensor reads: ``side`` ("maximum" or "minimum") and ``level``; ``at`` marks the rows at it
    and ``run`` is its longest run; ``repeat`` is the share of rows elsewhere that repeat their predecessor."""

    side: str
    level: float
    at: np.ndarray
    run: int
    repeat: float

    def near(self, model: np.ndarray, rms: float) -> np.ndarray:
        """Rows whose model friction is within CENSOR_BAND ``rms`` of the limit, or beyond it."""
        if self.side == "maximum":
            return model >= self.level - CENSOR_BAND * rms
        return model <= self.level + CENSOR_BAND * rms

    def censored(self, record: LabRecord, out: np.ndarray) -> LabRecord:
        """``record`` without the rows ``out`` (the t0 and clock kept), with a note saying what was left out."""
        clock = record.t0 + record.time[self.at]
        beside = int(np.count_nonzero(out & ~self.at))
        note = (
            f"a saturated friction sensor: {int(self.at.sum())} rows ({100 * self.at.mean():.2g} % of those fitted, "
            f"{clock[0]:g} ... {clock[-1]:g} s on the file's clock) read exactly the record's {self.side}, "
            f"{self.level:.6g}, in a run of up to {self.run} rows, where the record elsewhere repeats a value in "
            f"{100 * self.repeat:.2g} % of consecutive rows: a clipped reading (the friction was there or beyond). "
            f"They are left out of the fit as censored"
            + (f", with the {beside} rows beside them whose model friction comes within {CENSOR_BAND:g} residual rms "
               "of that level (their reading may be clipped too)" if beside else "")
            + f"; {int(out.sum())} rows left out in all"
        )  # fmt: skip
        keep = ~out
        return replace(record, time=record.time[keep], displacement=record.displacement[keep],
                       friction=record.friction[keep], notes=(*record.notes, note))  # fmt: skip


def _runs(flags: np.ndarray) -> np.ndarray:
    """The lengths of the runs of True in ``flags``."""
    edges = np.diff(np.r_[0, flags.astype(np.int8), 0])
    return np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)


def _longest_other_run(friction: np.ndarray, skip: np.ndarray) -> int:
    """The longest run of one value among the rows not in ``skip``."""
    same = (friction[1:] == friction[:-1]) & ~skip[1:] & ~skip[:-1]
    runs = _runs(same)
    return int(runs.max()) + 1 if runs.size else 1


def find_saturation(friction: np.ndarray) -> Saturation | None:
    """The record's maximum or minimum where a saturated sensor reads it (the module notes), else None."""
    f = np.asarray(friction, dtype=float)
    n = f.size
    if n < 4 * MIN_RUN:
        return None
    extreme = (f == f.max()) | (f == f.min())
    inner = f[~extreme]
    if inner.size >= 3:
        second = np.diff(inner, 2)
        if 1.4826 * float(np.median(np.abs(second - np.median(second)))) <= NOISE_FREE * float(np.ptp(f)):
            return None
    found = []
    for side, level in (("maximum", float(f.max())), ("minimum", float(f.min()))):
        at = f == level
        runs = _runs(at)
        run = int(runs.max()) if runs.size else 0
        if run < MIN_RUN:
            continue
        extreme = (f == f.max()) | (f == f.min())
        pairs = ~(extreme[1:] | extreme[:-1])
        if not pairs.any():
            continue
        repeats = int(np.count_nonzero((f[1:] == f[:-1]) & pairs))
        repeat = (repeats + 1) / (int(pairs.sum()) + 2)  # (never 0: one more repeat than seen)
        if repeat > MAX_REPEAT:
            continue
        chance = math.log10(n) + (run - 1) * math.log10(repeat)
        if chance < math.log10(CHANCE) and run >= OTHER_RUNS * _longest_other_run(f, extreme):
            found.append(Saturation(side, level, at, run, repeat))
    if not found:
        return None
    return max(found, key=lambda s: s.run)  # (both at once: the longer; the other is read as it is)
