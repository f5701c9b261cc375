"""The unit boundary: strings such as ``"224 us"`` become SI floats here, and only here.

Inside the package every number is a float in SI base units.  A value string
is a number followed by a unit expression (``"224 us"``, ``"1.22e14 1/m^2"``,
``"20 degC"``); a bare number (``0.000224``) is already SI, in TOML files and
in the Python API alike.  A non-zero number written as text without a unit
(``"0.000224"``) is refused for a dimensional value, on the command line, in a
file's quoted value and by the Python API (:func:`require_unit`,
:func:`si_argument`, :func:`override_to_si`); :func:`to_si` itself still reads
it as SI for the callers that check it first.

What is parsed is bounded before anything is evaluated: at most
:data:`MAX_VALUE_LENGTH` characters, one leading number, and a unit
expression whose only digits are small exponents (``m^2``, ``s**-1``), so no
value string can make the program compute for long.  Common units
(``um/s``, ``kPa``, ``1/m^2``, ...) are converted by a small table, which
keeps pint (slow to import and to build) off the path of everyday commands;
tests check every entry of the table against pint.  Anything else (``degC``,
``ft``, ``angstrom**2``) goes to pint.
"""

from __future__ import annotations

import contextlib
import decimal
import math
import re
from collections.abc import Iterator
from contextlib import contextmanager
from functools import lru_cache
from typing import Any

from .errors import ParameterError, UnitError, as_written

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
    "stress_acceleration": ("[mass] / [length] / [time] ** 4", "Pa/s^2"),  # a stick's bend (analyze -o)
    "stress_per_length": ("[mass] / [length] ** 2 / [time] ** 2", "Pa/m"),
    "force": ("[mass] * [length] / [time] ** 2", "N"),
    "area": ("[length] ** 2", "m^2"),
    "stress_per_velocity": ("[mass] / [length] ** 2 / [time]", "Pa s/m"),
    "per_length": ("1 / [length]", "1/m"),
    "slowness": ("[time] / [length]", "s/m"),
    "mass_per_area": ("[mass] / [length] ** 2", "kg/m^2"),
}

#: The base dimensions, in the order of the exponent vectors below.
_BASE_DIMENSIONS = ("[mass]", "[length]", "[time]", "[temperature]")


def _vector(dimensionality: str) -> tuple[int, int, int, int]:
    """(mass, length, time, temperature) exponents of a pint dimensionality string of :data:`DIMENSIONS`."""
    exponents = [0, 0, 0, 0]
    for k, part in enumerate(dimensionality.split(" / ")):
        for factor in part.split(" * "):
            name, _, power = factor.partition(" ** ")
            if name in _BASE_DIMENSIONS:
                exponents[_BASE_DIMENSIONS.index(name)] += (1 if k == 0 else -1) * int(power or 1)
    return exponents[0], exponents[1], exponents[2], exponents[3]


#: Exponents of (mass, length, time, temperature) of each dimension.
_DIMENSION_VECTORS = {name: _vector(pint_text) for name, (pint_text, _) in DIMENSIONS.items()}

#: Longest value string accepted (the longest sensible one is ~30 characters).
MAX_VALUE_LENGTH = 200
#: Longest piece of a user's value echoed in an error message.
ECHO_LENGTH = 60

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
#: "nan s" and "inf s" are numbers with a unit (the caller's range check names them), not a unit alone.
_NON_FINITE = r"[-+]?(?i:nan|inf(?:inity)?)(?![^\W\d])"
_NUMBER_THEN_UNIT = re.compile(rf"^({_NUMBER}|{_NON_FINITE})\s*(.*)$", re.DOTALL)
#: An exponent pint may see: one or two digits, optionally a short fraction, not itself raised to a power.
_EXPONENT = re.compile(r"(?:\^|\*\*)\s*[-+]?\d{1,2}(?:\.\d{1,3})?(?!\d)(?!\s*(?:\^|\*\*))")
#: A leading "1" of "1/m^2" (also inside parentheses).
_LEADING_ONE = re.compile(r"(?<![\w.])1(?=\s*/)")
_UNIT_CHARACTERS = re.compile(r"^(?:[^\W\d]|[\s*/()°%])*$")

#: Units converted without pint: symbol -> (factor to SI, (mass, length, time, temperature) exponents).
_UNITS: dict[str, tuple[float, tuple[int, int, int, int]]] = {
    "m": (1.0, (0, 1, 0, 0)),
    "s": (1.0, (0, 0, 1, 0)),
    "g": (1e-3, (1, 0, 0, 0)),
    "N": (1.0, (1, 1, -2, 0)),
    "Pa": (1.0, (1, -1, -2, 0)),
    "J": (1.0, (1, 2, -2, 0)),
    "Hz": (1.0, (0, 0, -1, 0)),
    "K": (1.0, (0, 0, 0, 1)),
}
#: Units that take no prefix here.
_PLAIN_UNITS: dict[str, tuple[float, tuple[int, int, int, int]]] = {
    "angstrom": (1e-10, (0, 1, 0, 0)),
    "min": (60.0, (0, 0, 1, 0)),
    "h": (3600.0, (0, 0, 1, 0)),
}
_PREFIXES = {"G": 1e9, "M": 1e6, "k": 1e3, "c": 1e-2, "m": 1e-3, "u": 1e-6, "µ": 1e-6, "μ": 1e-6, "n": 1e-9, "p": 1e-12}
_FAST_TOKEN = re.compile(r"\s*(?:(\*\*|\^)\s*([-+]?\d)|([*/])|([^\W\d]+)|(1)(?=\s*/)|(\S))")


@lru_cache(maxsize=1)
def registry() -> Any:
    """The package's single pint registry (built lazily: importing pint is slow)."""
    import pint

    return pint.UnitRegistry(autoconvert_offset_to_baseunit=True)


def shorten(value: Any, limit: int = ECHO_LENGTH) -> str:
    """``repr(value)``, its middle cut out beyond ``limit`` characters, so that an error line stays short."""
    text = repr(value)
    if len(text) <= limit:
        return text
    head = (2 * limit) // 3
    return f"{text[:head]}…{text[head - limit :]} ({len(text)} characters)"


#: How a message names a quantity of each dimension (with its article).
_NOUNS = {
    "dimensionless": "a dimensionless number",
    "per_area": "a number per area",
    "area": "an area",
    "per_length": "an inverse length",
    "stress_per_length": "a stress per length",
    "stress_per_velocity": "a stress per velocity",
    "stress_rate": "a stress rate",
    "stress_acceleration": "a stress rate's rate of change",
    "mass_per_area": "a mass per area",
}


def quantity_noun(dimension: str) -> str:
    """``"a velocity"``, ``"an area"``: the quantity of ``dimension`` as a message names it."""
    return _NOUNS.get(dimension, f"a {dimension.replace('_', ' ')}")


#: A value of each dimension as a message shows one (``e.g. '20 s'``); others: 1 of the SI unit.
_EXAMPLES = {
    "dimensionless": "0.5",
    "time": "20 s",
    "length": "10 um",
    "velocity": "350 um/s",
    "rate": "0.1 1/s",
    "stress": "5 kPa",
    "temperature": "300 K",
}


def example_value(dimension: str) -> str:
    """``"'20 s'"``: a value of ``dimension`` written as a number and a unit, quoted, for a message's e.g."""
    return repr(_EXAMPLES.get(dimension) or f"1 {DIMENSIONS[dimension][1]}")


def _describe(dimension: str) -> str:
    unit = DIMENSIONS[dimension][1]
    return quantity_noun(dimension) + (f" (e.g. in {unit})" if unit else "")


def checked_number(name: str, value: Any, unit: str, *, strict: bool = False) -> float:
    """A number given by code in SI ``unit`` (no text), as a float: finite and >= 0 (> 0 with ``strict``).

    Otherwise a ParameterError naming ``name``; a bool is no number.  The rig's and the stability analysis'
    stiffness, damping and mass are checked by it alike.
    """
    if isinstance(value, bool) or not (isinstance(value, (int, float)) or hasattr(value, "__float__")):
        raise ParameterError(f"{name}: expected a number in {unit}, got {shorten(value)}")
    refuse_beyond_float(value, name)
    number = float(value)
    if not math.isfinite(number) or number < 0 or (strict and number == 0):
        expected = f"a finite value > 0 {unit}" if strict else f"a non-negative finite value in {unit}"
        raise ParameterError(f"{name}: expected {expected}, got {shorten(value)}")
    return number


def checked_value(name: str, value: Any, dimension: str, *, strict: bool = False) -> float:
    """A number in SI or a value with its unit of ``dimension`` (:func:`si_argument`), checked by
    :func:`checked_number` in the dimension's display unit; a refusal quotes the value as written.  The rig's and
    the stability analysis' stiffness, damping and mass are read by it alike."""
    number = si_argument(value, dimension, name)
    with refused_as_written(value):
        return checked_number(name, number, DIMENSIONS[dimension][1], strict=strict)


def bare_number(text: str) -> float | None:
    """The number if ``text`` is a number without a unit (``"50"``, ``" 1e-4 "``), else None."""
    if len(text) > MAX_VALUE_LENGTH:
        return None
    try:
        return float(text)
    except ValueError:
        return None


def to_si(value: Any, dimension: str, name: str = "value") -> float:
    """Convert ``value`` to a float in SI base units of the given ``dimension``.

    ``value`` may be a number (taken as SI already), a string with a unit
    (``"224 us"``, ``"20 degC"``, ``"350 um/s"``), a bare number as a string
    (SI, like a number) or a pint quantity.  ``name`` is the key or option
    named in the error message.
    """
    if dimension not in DIMENSIONS:
        raise KeyError(f"unknown dimension {dimension!r}")
    if getattr(value, "shape", None) == () and hasattr(value, "item") and not hasattr(value, "dimensionality"):
        value = value.item()  # a numpy scalar (float32, int64, 0-d array) is its Python number
    if isinstance(value, bool):
        raise UnitError(f"{name}: expected {_describe(dimension)}, got {value!r}")
    if isinstance(value, (int, float)):
        try:
            return float(value)
        except OverflowError:  # a Python int beyond the float range
            raise UnitError(f"{name}: {shorten(value)} is beyond the range of a float") from None
    if isinstance(value, str):
        return _string_to_si(value, dimension, name)
    if is_quantity(value):
        return _quantity_to_si(value, dimension, name, value)
    raise UnitError(f"{name}: expected {_describe(dimension)}, got {shorten(value)}")


def override_to_si(value: Any, dimension: str, name: str, typical: float | None = None) -> float:
    """A parameter override's or a model key's value (``{"bonds.bond_time": "224 us"}``) in SI of ``dimension``, as
    :func:`to_si` reads it, except that a non-zero number written as text without a unit (``"224"``) is refused, a
    :class:`UnitError` naming ``name`` (:func:`require_unit`), as every other argument of the Python API and a quoted
    value in a file refuse it; a number (not text) is SI.  Before round 30 ``with_overrides({"bonds.bond_time":
    "224"})`` was 224 s without a word.  ``typical`` (SI; the value the key holds) sizes the unit suggested."""
    if isinstance(value, str):
        require_unit(value, dimension, f"{name}=", typical)
    return to_si(value, dimension, name)


def is_quantity(value: Any) -> bool:
    """Whether ``value`` is a pint quantity (of any registry): what :func:`to_si` reads with its unit."""
    return hasattr(value, "dimensionality") and hasattr(value, "to")


def si_argument(value: Any, dimension: str, name: str) -> Any:
    """A dimensional argument of a public function, the one reader of them all: a string with a unit
    (``"0.2 mm/s"``, ``"100 ms"``, ``"300 kPa/m"``) or a pint quantity becomes a float in SI of ``dimension``
    (:func:`to_si`; a unit of another dimension is a :class:`UnitError` naming ``name``, the value and the
    dimension expected; a bare number as text is SI); anything else (a number, already SI) is returned as it is,
    for the caller's own checks of type and range.

    Arrays are not read here: an array of velocities or times is numbers in SI.  A number beyond the float range
    (``10**400``, a Fraction) is refused here, a :class:`ParameterError` naming ``name``, not a raw OverflowError of
    the caller's ``float()``.
    """
    if isinstance(value, str):  # text is read for its unit, as a quoted value in a file and on the command line
        require_unit(value, dimension, f"{name}=")
    if isinstance(value, str) or is_quantity(value):
        return to_si(value, dimension, name)
    refuse_beyond_float(value, name)
    return value


def refuse_beyond_float(value: Any, name: str) -> None:
    """Refuse a number that ``float()`` cannot hold (an OverflowError: Python's big ints, Fractions), naming
    ``name``; anything else (a float, numpy's, a non-number) is the caller's to check."""
    if isinstance(value, (bool, float)) or not hasattr(value, "__float__"):
        return
    try:
        float(value)
    except OverflowError:
        raise ParameterError(f"{name}: {shorten(value)} is beyond the range of a float (about ±1.8e308)") from None
    except (TypeError, ValueError):  # the caller's type check names it
        return


@contextmanager
def refused_as_written(value: Any) -> Iterator[None]:
    """A caller's range check of a value :func:`si_argument` read from text, refused naming the value as the user
    wrote it (``"got '-50 um/s'"``, not ``"got -5e-05"``); a :class:`UnitError` (already so named) passes as is."""
    try:
        yield
    except UnitError:
        raise
    except ParameterError as exc:
        if not isinstance(value, str):
            raise
        raise type(exc)(as_written(str(exc), value)) from None


@contextmanager
def refused_as_written_by_name(written: dict[str, Any]) -> Iterator[None]:
    """:func:`refused_as_written` for several arguments checked together: a refusal that starts with one's name
    (``"every: expected ..."``) quotes that one as written where it was text."""
    try:
        yield
    except UnitError:
        raise
    except ParameterError as exc:
        value = written.get(str(exc).partition(":")[0])
        if not isinstance(value, str):
            raise
        raise type(exc)(as_written(str(exc), value)) from None


def _string_to_si(text: str, dimension: str, name: str) -> float:
    stripped = text.strip()
    if not stripped:
        raise UnitError(f"{name}: empty value, expected {_describe(dimension)}")
    if len(stripped) > MAX_VALUE_LENGTH:
        raise UnitError(
            f"{name}: value of {len(stripped)} characters is too long (at most {MAX_VALUE_LENGTH}): {shorten(stripped)}"
        )
    number = bare_number(stripped)
    if number is not None:  # a bare number (also "nan", "inf") is SI; range checks are the caller's
        return number
    match = _NUMBER_THEN_UNIT.match(stripped)
    magnitude, unit = (float(match.group(1)), match.group(2).strip()) if match else (1.0, stripped)
    if match is not None and unit.startswith("/"):  # "1.6e-3/um", as lab notes write a stiffness: per micrometre
        unit = "1" + unit
    if not _readable_unit(unit):
        raise UnitError(
            f"{name}: cannot read {shorten(stripped)} as {_describe(dimension)}:"
            f" expected a number and a unit, e.g. {example_value(dimension)}"
            " (digits in a unit only as small exponents, m^2)"
        )
    if match is None:  # "um/s" alone is a unit, not a value: reading it as 1 um/s would hide a forgotten number
        raise UnitError(
            f"{name}: {shorten(stripped)} has no number; expected {_describe(dimension)} written as a number"
            f" and a unit, e.g. {example_value(dimension)}"
        )
    fast = _fast_unit(unit)
    if fast is not None:
        if fast[1] != _DIMENSION_VECTORS[dimension]:
            raise UnitError(
                f"{name}: {shorten(stripped)} has dimension {_dimension_text(fast[1])}, expected {_describe(dimension)}"
            )
        return _scaled(match.group(1), magnitude, fast[0])
    return _quantity_to_si(_pint_quantity(magnitude, unit, stripped, name, dimension), dimension, name, stripped)


def _scaled(written: str, magnitude: float, factor: float) -> float:
    """``magnitude`` (``written`` as text) times a unit's ``factor`` to SI.  A decimal prefix's factor (a power of
    ten, to the rounding of the table's products) shifts the written decimal number's exponent, correctly rounded:
    "10 um" is 1e-05, as the literal 10e-6 is (the product 10 * 1e-6 is 9.999999999999999e-06, one step off, so
    ``stick_phase(p, "50 um/s")`` and ``stick_phase(p, 50e-6)`` differed in their 15th digit)."""
    power = _decimal_power(factor)
    if power is not None and math.isfinite(magnitude):
        with contextlib.suppress(ArithmeticError, ValueError):
            return float(decimal.Decimal(written).scaleb(power))
    return magnitude * factor


def _decimal_power(factor: float) -> int | None:
    """k where a unit's ``factor`` is 10^k (to the rounding of the unit table's products), else None."""
    if not (factor > 0 and math.isfinite(factor)):
        return None
    power = round(math.log10(factor))
    return power if abs(factor / 10.0**power - 1.0) < 1e-14 else None


def _readable_unit(unit: str) -> bool:
    """Whether ``unit`` is a bounded unit expression: names, * / ( ), small exponents and a leading 1."""
    rest = _LEADING_ONE.sub(" ", _EXPONENT.sub(" ", unit))
    return bool(_UNIT_CHARACTERS.match(rest)) and "**" not in rest


def _fast_unit(unit: str) -> tuple[float, tuple[int, ...]] | None:
    """(factor, dimension exponents) of a product/quotient of table units, or None to ask pint.

    Handles ``um/s``, ``1/m^2``, ``Pa*s/m``, ``N/m``, ``kPa`` and the like:
    names joined by ``*`` and ``/`` (left to right), each with an optional
    one-digit exponent.  Juxtaposition (``Pa s``) and parentheses go to pint.
    """
    factor, dims = 1.0, [0, 0, 0, 0]
    sign, expect_term, position = 1, True, 0
    while position < len(unit):
        token = _FAST_TOKEN.match(unit, position)
        if token is None:
            return None
        position = token.end()
        operator, name, one, other = token.group(3, 4, 5, 6)
        if other is not None:
            return None
        if operator is not None:
            if expect_term:
                return None
            sign, expect_term = (-1 if operator == "/" else 1), True
        elif name is not None or one is not None:
            if not expect_term:
                return None  # juxtaposition: pint's precedence rules, not ours
            entry = (1.0, (0, 0, 0, 0)) if one is not None else _table_unit(name)
            if entry is None:
                return None
            exponent = 1
            after = _FAST_TOKEN.match(unit, position)
            if after is not None and after.group(2) is not None:
                exponent, position = int(after.group(2)), after.end()
            factor = factor * entry[0] ** exponent if sign > 0 else factor / entry[0] ** exponent
            dims = [d + sign * exponent * e for d, e in zip(dims, entry[1], strict=True)]
            expect_term = False
        else:  # an exponent with nothing to raise
            return None
    if expect_term:
        return None
    return factor, tuple(dims)


def _dimension_text(vector: tuple[int, ...]) -> str:
    """pint's way of writing a dimension: ``[length] / [time] ** 2``."""
    up = [n + (f" ** {e}" if e != 1 else "") for n, e in zip(_BASE_DIMENSIONS, vector, strict=True) if e > 0]
    down = [n + (f" ** {-e}" if e != -1 else "") for n, e in zip(_BASE_DIMENSIONS, vector, strict=True) if e < 0]
    if not up and not down:
        return "dimensionless"
    return " / ".join([" * ".join(up) or "1", *down])


def _table_unit(name: str) -> tuple[float, tuple[int, int, int, int]] | None:
    if name in _UNITS or name in _PLAIN_UNITS:
        return _UNITS.get(name) or _PLAIN_UNITS[name]
    prefix, base = name[:1], name[1:]
    if prefix in _PREFIXES and base in _UNITS:
        return _PREFIXES[prefix] * _UNITS[base][0], _UNITS[base][1]
    return None


def _pint_quantity(magnitude: float, unit: str, text: str, name: str, dimension: str) -> Any:
    import pint

    ureg = registry()
    try:
        units = ureg.parse_units(unit) if unit else ureg.dimensionless
        return ureg.Quantity(magnitude, units)
    except pint.UndefinedUnitError as exc:
        raise UnitError(f"{name}: unknown unit in {shorten(text)} ({shorten(str(exc))})") from None
    except Exception:  # pint raises many things on garbage; all mean "not a quantity"
        raise UnitError(f"{name}: cannot read {shorten(text)} as {_describe(dimension)}") from None


def _quantity_to_si(quantity: Any, dimension: str, name: str, shown: Any) -> float:
    import pint

    ureg = registry()
    if not isinstance(quantity, ureg.Quantity):
        quantity = _own_quantity(quantity, name, shown)
    try:
        if dimension == "dimensionless":
            return float(quantity.to("dimensionless").magnitude)
        return float(quantity.to_base_units().to(ureg.parse_units(DIMENSIONS[dimension][1])).magnitude)
    except pint.DimensionalityError:
        raise UnitError(
            f"{name}: {shorten(shown)} has dimension {quantity.dimensionality}, expected {_describe(dimension)}"
        ) from None
    except (OverflowError, ZeroDivisionError, ValueError, TypeError):
        raise UnitError(f"{name}: cannot read {shorten(shown)} as {_describe(dimension)}") from None


def _own_quantity(quantity: Any, name: str, shown: Any) -> Any:
    """A quantity of another pint registry (the user's own ``pint.UnitRegistry()``) as one of :func:`registry`: its
    magnitude and its units' name, or, for a unit only its registry defines, its value in that registry's base
    units.  (Before round 30 such a quantity was refused, "a quantity from another pint registry".)"""
    ureg = registry()
    try:
        return ureg.Quantity(quantity.magnitude, ureg.parse_units(str(quantity.units)))
    except Exception:  # a unit the user's registry defines and ours does not: go through its base units
        pass
    try:
        base = quantity.to_base_units()
        return ureg.Quantity(base.magnitude, ureg.parse_units(str(base.units)))
    except Exception:
        raise UnitError(f"{name}: cannot read the pint quantity {shorten(shown)}: its unit is unknown here") from None


def format_si(value: float, dimension: str) -> str:
    """``value`` (SI) with its display unit, e.g. ``'0.000224 s'``."""
    unit = DIMENSIONS[dimension][1]
    if math.isinf(value):
        return "inf" + (f" {unit}" if unit else "")
    return f"{value:.6g}" + (f" {unit}" if unit else "")


#: Units a person writes, per dimension: (factor to SI, unit), largest first; the first not above |value| is used.
_WRITTEN_UNITS: dict[str, tuple[tuple[float, str], ...]] = {
    "time": ((1.0, "s"), (1e-3, "ms"), (1e-6, "us"), (1e-9, "ns"), (1e-12, "ps")),
    "length": ((1.0, "m"), (1e-3, "mm"), (1e-6, "um"), (1e-9, "nm"), (1e-10, "angstrom"), (1e-12, "pm")),
    "velocity": ((1.0, "m/s"), (1e-3, "mm/s"), (1e-6, "um/s"), (1e-9, "nm/s")),
    "stress": ((1e9, "GPa"), (1e6, "MPa"), (1e3, "kPa"), (1.0, "Pa"), (1e-3, "mPa")),
    "force": ((1.0, "N"), (1e-3, "mN"), (1e-6, "uN"), (1e-9, "nN"), (1e-12, "pN")),
}


def format_quantity(value: float, dimension: str) -> str:
    """``value`` (SI) as a person would write it: ``"360 um/s"``, ``"1.22e14 1/m^2"``, ``"1.0"``.

    The unit is chosen for readability (SI prefixes for times, lengths,
    velocities, stresses and forces) and the number has the fewest digits
    that :func:`to_si` reads back as exactly ``value``.
    """
    if dimension == "dimensionless":
        text = _shortest(value, "") or repr(value)
        return text if any(c in text for c in ".en") else text + ".0"  # a TOML float, not an integer
    si_unit = DIMENSIONS[dimension][1]
    choices = _WRITTEN_UNITS.get(dimension, ((1.0, si_unit),))
    unit = choices[0][1]
    if value != 0 and math.isfinite(value):
        unit = next((u for f, u in choices if abs(value) >= f * (1 - 1e-9)), choices[-1][1])
    text = _shortest(value, unit)
    return f"{text} {unit}" if text is not None else f"{value!r} {si_unit}"


def _shortest(value: float, unit: str) -> str | None:
    """The shortest number x such that ``"x unit"`` reads back as exactly ``value`` (None if there is none)."""
    if not math.isfinite(value):
        return None
    fast = _fast_unit(unit) if unit else None
    factor = fast[0] if fast is not None else 1.0  # units outside the table are SI units here
    scaled = value / factor
    candidates = [_plain(scaled, digits) for digits in range(1, 18)]
    candidates += [repr(math.nextafter(scaled, math.copysign(math.inf, step))) for step in (1, -1)]
    power = _decimal_power(factor)
    if power is not None:  # a decimal prefix: the value's own shortest digits, shifted, read back exactly
        candidates.append(format(decimal.Decimal(repr(value)).scaleb(-power).normalize(), "g"))
    return next((text for text in candidates if _scaled(text, float(text), factor) == value), None)


def _plain(number: float, digits: int) -> str:
    """``number`` to ``digits`` significant digits: ``360``, ``1.074``, ``1e-4``, ``1.22e14``."""
    mantissa, exponent = f"{number:.{digits - 1}e}".split("e")
    power = int(exponent)
    if -3 <= power < 6:  # read as a plain decimal
        text = f"{float(f'{mantissa}e{power}'):.{max(digits - 1 - power, 0)}f}"
        return text.rstrip("0").rstrip(".") if "." in text else text
    mantissa = mantissa.rstrip("0").rstrip(".") if "." in mantissa else mantissa
    return f"{mantissa}e{power}"


#: Per dimension: a typical size (SI) of an option's value, and the units a bare number may have been meant in,
#: as (unit, factor to SI).  A bare number is taken to be in the unit that puts it nearest the typical size
#: (pulling velocities of um/s to mm/s, stresses of kPa, times of seconds...).
_MEANT_UNITS: dict[str, tuple[float, tuple[tuple[str, float], ...]]] = {
    "time": (10.0, (("s", 1.0), ("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9), ("min", 60.0), ("h", 3600.0))),
    "length": (1e-5, (("m", 1.0), ("mm", 1e-3), ("um", 1e-6), ("nm", 1e-9), ("angstrom", 1e-10))),
    "velocity": (1e-4, (("m/s", 1.0), ("mm/s", 1e-3), ("um/s", 1e-6), ("nm/s", 1e-9))),
    "rate": (1.0, (("1/s", 1.0),)),
    "per_area": (1e14, (("1/m^2", 1.0), ("1/um^2", 1e12))),
    "stiffness": (1e-4, (("N/m", 1.0), ("mN/m", 1e-3))),
    "temperature": (300.0, (("K", 1.0),)),
    "stress": (1e3, (("Pa", 1.0), ("kPa", 1e3), ("MPa", 1e6), ("GPa", 1e9))),
    "stress_rate": (1e2, (("Pa/s", 1.0), ("kPa/s", 1e3))),
    "stress_acceleration": (1.0, (("Pa/s^2", 1.0),)),
    "stress_per_length": (1e5, (("Pa/m", 1.0), ("kPa/m", 1e3), ("MPa/m", 1e6))),
    "force": (1.0, (("N", 1.0), ("mN", 1e-3), ("uN", 1e-6))),
    "area": (1e-3, (("m^2", 1.0), ("cm^2", 1e-4), ("mm^2", 1e-6))),
    "stress_per_velocity": (1e6, (("Pa s/m", 1.0), ("MPa s/m", 1e6))),
    "per_length": (1e3, (("1/m", 1.0), ("1/mm", 1e3), ("1/um", 1e6))),
    "slowness": (1.0, (("s/m", 1.0), ("s/mm", 1e3), ("s/um", 1e6))),
    "mass_per_area": (100.0, (("kg/m^2", 1.0), ("g/m^2", 1e-3))),
}


def _meant_unit(number: float, dimension: str, typical: float | None) -> str:
    """The unit that puts ``number`` nearest (in decades) to a typical value of its quantity."""
    typical_si, candidates = _MEANT_UNITS.get(dimension, (1.0, ((DIMENSIONS[dimension][1], 1.0),)))
    target = math.log10(typical if typical and typical > 0 else typical_si)
    size = math.log10(abs(number))
    return min(candidates, key=lambda unit: abs(size + math.log10(unit[1]) - target))[0]


def require_unit(text: str, dimension: str, prefix: str, typical: float | None = None) -> None:
    """Refuse a bare non-zero number written as text for a dimensional value: typed on the command line, or given
    as text to the Python API (``stick_phase(p, "50")`` was 50 m/s without a word; a number, not text, is SI).

    ``prefix`` is how the value was introduced (``"--v0 "``, ``"--set bonds.bond_time="``):
    the message quotes it and shows the same value with the unit it was presumably meant in,
    the one that puts it nearest ``typical`` (SI; a typical size of that dimension by default),
    and the SI unit beside it when that differs.
    """
    number = bare_number(text)
    if dimension == "dimensionless" or number is None or number == 0 or not math.isfinite(number):
        return
    typed = text.strip()
    if len(typed) > 40:
        typed = shorten(typed, 40)
    unit = _meant_unit(number, dimension, typical)
    si = DIMENSIONS[dimension][1]
    hint = f'e.g. {prefix}"{typed} {unit}"' + (f' (or "{typed} {si}" if you mean SI)' if si != unit else "")
    raise UnitError(f"{prefix}{typed}: {quantity_noun(dimension)} needs a unit, {hint}")
