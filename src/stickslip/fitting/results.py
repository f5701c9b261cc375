"""Small result records shared by the fits: an estimate with its uncertainty."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..units import format_si

#: Display units by dimension: (name, size in SI), smallest first; the largest not exceeding the value is used.
_DISPLAY = {
    "velocity": (("nm/s", 1e-9), ("µm/s", 1e-6), ("mm/s", 1e-3), ("m/s", 1.0)),
    "time": (("ns", 1e-9), ("µs", 1e-6), ("ms", 1e-3), ("s", 1.0)),
    "length": (("pm", 1e-12), ("nm", 1e-9), ("µm", 1e-6), ("mm", 1e-3), ("m", 1.0)),
    "stress": (("Pa", 1.0), ("kPa", 1e3), ("MPa", 1e6)),
}

#: The unit of a quantity with no value (undetermined): the one its values usually have.
_UNDETERMINED = {"velocity": ("µm/s", 1e-6)}


def display_unit(value: float | None, dimension: str) -> tuple[str, float]:
    """(unit name, size in SI) for showing ``value`` to people."""
    choices = _DISPLAY.get(dimension)
    if choices is None:
        text = format_si(1.0, dimension)
        return (text.split(" ", 1)[1] if " " in text else "", 1.0)
    if value is None:  # an undetermined Vc is shown in the unit of the determined ones, not in nm/s
        return _UNDETERMINED.get(dimension, choices[0])
    if value == 0 or not np.isfinite(value):
        return choices[0]
    chosen = choices[0]
    for name, size in choices:
        if abs(value) >= size:
            chosen = (name, size)
    return chosen


def human(value: float, dimension: str, digits: int = 6) -> str:
    """``value`` (SI) in a unit for people, e.g. ``human(1.24097e-4, "velocity") == "124.097 µm/s"``."""
    unit, size = display_unit(value, dimension)
    return f"{value / size:.{digits}g} {unit}".strip()


@dataclass(frozen=True)
class Estimate:
    """A fitted, fixed or derived quantity (SI units).

    ``stderr`` and ``interval`` are None for fixed values, and for derived
    values the data do not determine; ``note`` says why in words.
    """

    key: str
    symbol: str
    dimension: str
    value: float | None
    stderr: float | None = None
    interval: tuple[float | None, float | None] | None = None
    status: str = "fitted"  # "fitted", "fixed", "derived", "undetermined"
    note: str = ""
    bias: float | None = None  # the method's own bias, where it was estimated (two-step Vc, sigma_c)

    @property
    def fixed(self) -> bool:
        return self.status == "fixed"

    def as_dict(self) -> dict[str, Any]:
        """``{value, stderr, interval}``, or ``{value, fixed: true, reason}`` for a fixed value."""
        if self.fixed:
            return {"value": self.value, "fixed": True, "reason": self.note}
        out: dict[str, Any] = {
            "value": self.value,
            "stderr": self.stderr,
            "interval": None if self.interval is None else list(self.interval),
        }
        if self.status != "fitted":
            out["status"] = self.status
        if self.note:
            out["note"] = self.note
        if self.bias is not None:
            out["method_bias"] = self.bias
        return out


def unusable(estimate: Estimate, why: str) -> Estimate:
    """``estimate`` of a failed fit: undetermined, without error or interval (``why``); fixed ones stay."""
    if estimate.fixed or estimate.interval is None:
        return estimate
    return dataclasses.replace(estimate, stderr=None, interval=None, status="undetermined", note=why)


#: (key, symbol, dimension) of the critical point's estimates, Vc and sigma_c (Eq 9).
CRITICAL = (("critical_velocity", "Vc", "velocity"), ("critical_stress", "σc", "stress"))


def undetermined_critical(note: str) -> tuple[Estimate, Estimate]:
    """Vc and sigma_c, not determined; ``note`` says why."""
    vc, sc = (Estimate(*names, None, status="undetermined", note=note) for names in CRITICAL)
    return vc, sc


#: ln-widths beyond this give an unbounded upper end (e^700 ~ 1e304: no number, only "unbounded").
LARGEST_LOG_WIDTH = 700.0


def log_interval(value: float, sd_log: float, q: float) -> tuple[float, float | None]:
    """value e^(-q sd), value e^(q sd); the upper end is unbounded where that overflows (sd of hundreds)."""
    width = q * sd_log
    return value * math.exp(-width), (value * math.exp(width) if width < LARGEST_LOG_WIDTH else None)
