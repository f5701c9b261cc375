"""Numbers for people: SI floats shown in the unit a reader of the paper expects."""

from __future__ import annotations

import math

#: display unit -> (SI value of one display unit, how it is written)
DISPLAY_UNITS: dict[str, tuple[float, str]] = {
    "": (1.0, ""),
    "um/s": (1e-6, "µm/s"),
    "Pa": (1.0, "Pa"),
    "kPa": (1e3, "kPa"),
    "Pa/s": (1.0, "Pa/s"),
    "Pa/m": (1.0, "Pa/m"),
    "kPa/m": (1e3, "kPa/m"),
    "s": (1.0, "s"),
    "us": (1e-6, "µs"),
    "um": (1e-6, "µm"),
    "mm": (1e-3, "mm"),
    "1/s": (1.0, "s⁻¹"),
    "1/m": (1.0, "m⁻¹"),
    "1/m^2": (1.0, "m⁻²"),
}

_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def format_number(value: float | None, digits: int = 4) -> str:
    """``digits`` significant figures; powers of ten as × 10ⁿ outside 1e-3..1e5."""
    if value is None or not math.isfinite(value):
        return "—"
    if value == 0:
        return "0"
    exponent = math.floor(math.log10(abs(value)))
    if -3 <= exponent < 5:
        decimals = max(digits - 1 - exponent, 0)
        return f"{value:.{decimals}f}"
    mantissa = value / 10.0**exponent
    if round(abs(mantissa), digits - 1) >= 10.0:  # 9.9996e5 rounds to 10.00 × 10⁵
        mantissa /= 10.0
        exponent += 1
    return f"{mantissa:.{digits - 1}f} × 10{str(exponent).translate(_SUPERSCRIPT)}"


def format_quantity(value: float | None, display: str, digits: int = 4) -> str:
    """An SI value in the display unit, e.g. ``format_quantity(1.24e-4, "um/s") == "124.1 µm/s"``."""
    scale, written = DISPLAY_UNITS[display]
    if value is None:
        return "—"
    text = format_number(value / scale, digits)
    return f"{text} {written}" if written else text


def format_percent(fraction: float | None) -> str:
    """A signed relative difference in per cent, e.g. ``-0.73 %``."""
    if fraction is None or not math.isfinite(fraction):
        return "—"
    percent = 100.0 * fraction
    if round(percent, 2) == 0.0:  # no "-0.00 %" for a difference of one rounding error
        return "0.00 %"
    if abs(percent) >= 1000:
        return f"{percent:+.3g} %".replace("e+0", "e").replace("e+", "e")
    if abs(percent) >= 10:
        return f"{percent:+.1f} %"
    return f"{percent:+.2f} %"


#: Parameter dimension -> the unit a person writes, with SI prefixes chosen per value (see format_parameter).
_PREFIXED_UNITS = {
    "time": "s",
    "length": "m",
    "velocity": "m/s",
    "stress": "Pa",
    "stiffness": "N/m",
    "stress_per_length": "Pa/m",
}
_PREFIXES = ((1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"))
#: Units written with a power of ten rather than a prefix.
_PLAIN_UNITS = {"rate": "s⁻¹", "per_area": "m⁻²", "temperature": "K", "dimensionless": "", "force": "N"}


def format_parameter(value: float, dimension: str, digits: int = 6) -> str:
    """A parameter (SI) as a person writes it: ``format_parameter(0.000224, "time") == "224 µs"``.

    Prefixed units pick the prefix that puts the number in [1, 1000); trailing zeros are dropped.
    """
    if not math.isfinite(value):
        return format_number(value)
    if dimension in _PREFIXED_UNITS and value != 0:
        unit = _PREFIXED_UNITS[dimension]
        scale, prefix = next(((s, p) for s, p in _PREFIXES if abs(value) >= s * (1 - 1e-12)), _PREFIXES[-1])
        return f"{_trim(format_number(value / scale, digits))} {prefix}{unit}"
    written = _PLAIN_UNITS.get(dimension, "")
    text = _trim(format_number(value, digits))
    return f"{text} {written}" if written else text


def _trim(text: str) -> str:
    """``"224.0"`` -> ``"224"``, ``"1.220 × 10¹⁴"`` -> ``"1.22 × 10¹⁴"``."""
    mantissa, sep, rest = text.partition(" × ")
    if "." in mantissa:
        mantissa = mantissa.rstrip("0").rstrip(".")
    return mantissa + sep + rest
