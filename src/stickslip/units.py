"""The unit boundary: strings such as ``"224 us"`` become SI floats here, and only here.

Inside the package every number is a float in SI base units.  pint does the
parsing and the dimension check; this module adds the error messages.
"""

from __future__ import annotations

import math
import re
from functools import lru_cache
from typing import Any

from .errors import UnitError

#: Dimensions used by the model, as pint dimensionality strings, with the
#: unit used to *display* a value of that dimension.
DIMENSIONS: dict[str, tuple[str, str]] = {
    "dimensionless": ("", ""),
    "time": ("[time]", "s"),
    "length": ("[length]", "m"),
    "velocity": ("[length] / [time]", "m/s"),
    "rate": ("1 / [time]", "1/s"),
    "per_area": ("1 / [length] ** 2", "1/m^2"),
    "stiffness": ("[mass] / [time] ** 2", "N/m"),
    "temperature": ("[temperature]", "K"),
    "stress": ("[mass] / [length] / [time] ** 2", "Pa"),
    "stress_rate": ("[mass] / [length] / [time] ** 3", "Pa/s"),
    "stress_per_length": ("[mass] / [length] ** 2 / [time] ** 2", "Pa/m"),
    "force": ("[mass] * [length] / [time] ** 2", "N"),
    "area": ("[length] ** 2", "m^2"),
    "stress_per_velocity": ("[mass] / [length] ** 2 / [time]", "Pa s/m"),
    "per_length": ("1 / [length]", "1/m"),
    "slowness": ("[time] / [length]", "s/m"),
    "mass_per_area": ("[mass] / [length] ** 2", "kg/m^2"),
}

_NUMBER_THEN_UNIT = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")


@lru_cache(maxsize=1)
def registry() -> Any:
    """The package's single pint registry (built lazily: importing pint is slow)."""
    import pint

    ureg = pint.UnitRegistry(autoconvert_offset_to_baseunit=True)
    return ureg


def _describe(dimension: str) -> str:
    unit = DIMENSIONS[dimension][1]
    return f"a {dimension.replace('_', ' ')}" + (f" (e.g. in {unit})" if unit else " number")


def to_si(value: Any, dimension: str, name: str = "value") -> float:
    """Convert ``value`` to a float in SI base units of the given ``dimension``.

    ``value`` may be a number (taken as SI already), a string with a unit
    (``"224 us"``, ``"20 degC"``, ``"350 um/s"``) or a pint quantity.
    ``name`` is the key or option named in the error message.
    """
    if dimension not in DIMENSIONS:
        raise KeyError(f"unknown dimension {dimension!r}")
    if isinstance(value, bool):
        raise UnitError(f"{name}: expected {_describe(dimension)}, got {value!r}")
    if isinstance(value, (int, float)):
        return float(value)
    ureg = registry()
    if isinstance(value, str):
        try:  # a bare number (also "nan", "inf") is SI; range checks are the caller's
            return float(value)
        except ValueError:
            pass
        quantity = _parse(value, name, dimension)
    elif isinstance(value, ureg.Quantity):
        quantity = value
    else:
        raise UnitError(f"{name}: expected {_describe(dimension)}, got {value!r}")
    wanted = DIMENSIONS[dimension][0]
    import pint

    try:
        if wanted:
            return float(quantity.to_base_units().to(ureg.parse_units(_base_unit(dimension))).magnitude)
        return float(quantity.to("dimensionless").magnitude)
    except pint.DimensionalityError:
        raise UnitError(
            f"{name}: {value!r} has dimension {quantity.dimensionality}, expected {_describe(dimension)}"
        ) from None


def _base_unit(dimension: str) -> str:
    return {
        "time": "s",
        "length": "m",
        "velocity": "m/s",
        "rate": "1/s",
        "per_area": "1/m**2",
        "stiffness": "N/m",
        "temperature": "K",
        "stress": "Pa",
        "stress_rate": "Pa/s",
        "stress_per_length": "Pa/m",
        "force": "N",
        "area": "m**2",
        "stress_per_velocity": "Pa*s/m",
        "per_length": "1/m",
        "slowness": "s/m",
        "mass_per_area": "kg/m**2",
    }[dimension]


def _parse(text: str, name: str, dimension: str) -> Any:
    import pint

    ureg = registry()
    text = text.strip()
    if not text:
        raise UnitError(f"{name}: empty value, expected {_describe(dimension)}")
    match = _NUMBER_THEN_UNIT.match(text)
    try:
        if match:
            number, unit = float(match.group(1)), match.group(2)
            if not unit:  # a bare number is SI, whatever the dimension
                return ureg.Quantity(number, _base_unit(dimension) if dimension != "dimensionless" else "")
            return ureg.Quantity(number, unit)
        return ureg.Quantity(ureg.parse_expression(text))
    except (pint.UndefinedUnitError, pint.errors.DefinitionSyntaxError) as exc:
        raise UnitError(f"{name}: unknown unit in {text!r} ({exc})") from None
    except Exception:  # pint raises many things on garbage; all mean "not a quantity"
        raise UnitError(f"{name}: cannot read {text!r} as {_describe(dimension)}") from None


def format_si(value: float, dimension: str) -> str:
    """``value`` (SI) with its display unit, e.g. ``'0.000224 s'``."""
    unit = DIMENSIONS[dimension][1]
    if math.isinf(value):
        return "inf" + (f" {unit}" if unit else "")
    return f"{value:.6g}" + (f" {unit}" if unit else "")
