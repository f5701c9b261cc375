"""Model parameters: frozen, validated dataclasses, TOML files and built-in sets.

Every value is stored in SI base units.  Files and overrides carry units as
strings (``bond_time = "224 us"``); :mod:`stickslip.units` converts them.
A bare number (``bond_time = 0.000224`` in a TOML file, ``{"bonds.bond_time":
2.24e-4}`` or ``"2.24e-4"`` in Python) is taken as SI; only the command line
insists on a unit for a dimensional value.  Unknown keys are errors, never ignored.

The canonical keys, ``section.key``, and the symbols of Juvekar & Singh:

========================  =======  ===============================================
key                       symbol   meaning
========================  =======  ===============================================
bonds.site_density        N0       occupiable bonding sites per unit area (Eq 1, 7)
bonds.bond_time           tau      thermal make-break time constant (Eq 1)
bonds.breakage_weight     u0       exp(-W0/kT), breakage weight of a new bond
bonds.chain_stiffness     M        chain stiffness (FENE, Eq 3)
bonds.activation_length   lambda   activation length of the Eyring factor
bonds.temperature         T        absolute temperature
bonds.max_extension       dl_m     maximum chain extension (FENE, Eq 3)
aging.aging_time          tau_a    aging time constant of Eq 1 / Eq 6
aging.aging_velocity      V_a      characteristic aging velocity (Eq 1 / Eq 6)
aging.saturation_age      t_s      optional: age past which a bond stops strengthening (the
                                   saturating-aging extension, docs/extensions.md; absent = the paper)
stick.attached_chains     Nc0      attached chains per area at the stick (Eq 15)
stick.break_rate          uc/tau   chain breakage rate at the stick (Eq 15)
stick.aging_time          tau_a    aging time constant of Eq 15
block.shear_modulus       G_d      shear modulus of the block (Eq 5)
block.height              h        height of the block (Eq 5)
block.top_length          B        trapezoid length on the puller side (Eq 17)
block.base_length         l        trapezoid length on the contact side (Eq 17)
========================  =======  ===============================================

Overrides take two keys more, the block's stiffness (Pa/m): ``block.stiffness`` (G_d/h, Eq 5) and
``block.effective_stiffness`` (K of Eq 17); each sets the height that gives it (:data:`STIFFNESS_KEYS`).
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import os
import sys
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field, fields
from importlib import resources
from pathlib import Path
from typing import Any

from .errors import ParameterError, as_written
from .fileio import protect_inputs, read_input_text
from .units import format_quantity, format_si, override_to_si, shorten, to_si

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

BOLTZMANN = 1.380649e-23  # J/K, exact in the 2019 SI


def _spec(dimension: str, symbol: str, doc: str, zero_allowed: bool = False, optional: bool = False) -> Any:
    metadata = {"dimension": dimension, "symbol": symbol, "doc": doc, "zero_allowed": zero_allowed}
    metadata["optional"] = optional
    if optional:  # an extension's key: absent (None) means the paper's model
        return field(default=None, metadata=metadata)
    return field(metadata=metadata)


def _optional(f: Any) -> bool:
    return bool(f.metadata.get("optional", False))


@functools.cache
def _fields_of(cls: type) -> tuple[Any, ...]:
    return fields(cls)


class _Validated:
    """Mixin: every field must be a finite float, positive (or >= 0 where allowed)."""

    _section = ""

    def __post_init__(self) -> None:
        for f in _fields_of(type(self)):
            raw = getattr(self, f.name)
            # the common case, a float already finite, normal and of the allowed sign, needs no conversion (a
            # sampler's walkers make ~10^5 sets; the checks below, key text included, cost most of a set's making)
            if type(raw) is float and sys.float_info.min <= raw < math.inf:
                continue
            key = f"{self._section}.{f.name}"
            if raw is None and _optional(f):
                continue
            if isinstance(raw, bool) or not isinstance(raw, (int, float)):
                raise ParameterError(f"{key}: expected a number in SI units, got {shorten(raw)}")
            value = float(raw)
            if math.isnan(value) or math.isinf(value):
                raise ParameterError(f"{key}: expected a finite number, got {value}")
            if 0 < abs(value) < sys.float_info.min:  # a denormal: every product with it loses its digits
                raise ParameterError(
                    f"{key}: {value:g} (SI) is below the smallest normal float, 2.2e-308; expected a physical value"
                )
            if f.metadata["zero_allowed"]:
                if value < 0:
                    raise ParameterError(f"{key}: expected a value >= 0, got {value:g}")
            elif value <= 0:
                raise ParameterError(f"{key}: expected a positive value, got {value:g}")
            object.__setattr__(self, f.name, value)


@dataclass(frozen=True)
class BondParameters(_Validated):
    """Bond population of the slip phase (Eqs 1-8)."""

    _section = "bonds"
    site_density: float = _spec("per_area", "N0", "occupiable bonding sites per unit area")
    bond_time: float = _spec("time", "tau", "thermal make-break time constant")
    breakage_weight: float = _spec("dimensionless", "u0", "breakage weight exp(-W0/kT) of a new bond")
    chain_stiffness: float = _spec("stiffness", "M", "chain stiffness (FENE)")
    activation_length: float = _spec("length", "lambda", "activation length (Eyring factor)", zero_allowed=True)
    temperature: float = _spec("temperature", "T", "absolute temperature")
    max_extension: float = _spec("length", "dl_m", "maximum chain extension (FENE)")

    @property
    def force_sensitivity(self) -> float:
        """lambda/kT in 1/N: the Eyring exponent per unit chain force."""
        return self.activation_length / (BOLTZMANN * self.temperature)

    @property
    def stretch_sensitivity(self) -> float:
        """lambda*M/kT in 1/m (the paper's 'lambda M/kT')."""
        return self.force_sensitivity * self.chain_stiffness


@dataclass(frozen=True)
class AgingParameters(_Validated):
    """Velocity-dependent aging of bonds (the aging term of Eqs 1 and 6)."""

    _section = "aging"
    aging_time: float = _spec("time", "tau_a", "aging time constant")
    aging_velocity: float = _spec("velocity", "V_a", "characteristic aging velocity")
    #: the saturating-aging extension (docs/extensions.md): the aging term's age t_a becomes
    #: t_s (1 - exp(-t_a/t_s)); None is the paper's linear aging
    saturation_age: float | None = _spec(
        "time", "t_s", "age past which a bond stops strengthening (extension; none = the paper)", optional=True
    )


@dataclass(frozen=True)
class StickParameters(_Validated):
    """Attached-chain population of the stick phase (Eqs 13-15)."""

    _section = "stick"
    attached_chains: float = _spec("per_area", "Nc0", "attached chains per unit area when the block sticks")
    break_rate: float = _spec("rate", "uc/tau", "chain breakage rate at the stick")
    aging_time: float = _spec("time", "tau_a", "aging time constant of the stick phase")


@dataclass(frozen=True)
class BlockParameters(_Validated):
    """The elastic block and its trapezoid geometry (Eqs 5, 11, 17)."""

    _section = "block"
    shear_modulus: float = _spec("stress", "G_d", "shear modulus of the block")
    height: float = _spec("length", "h", "height of the block")
    top_length: float = _spec("length", "B", "length on the puller side")
    base_length: float = _spec("length", "l", "length on the contact side")

    @property
    def stiffness(self) -> float:
        """G_d/h in Pa/m (Eq 5)."""
        return self.shear_modulus / self.height

    @property
    def geometric_factor(self) -> float:
        """ln(B/l)/(B/l - 1) of Eq 17; exactly 1 for a rectangular block."""
        d = self.top_length / self.base_length - 1.0
        if abs(d) < 1e-6:  # series of log1p(d)/d, error O(d^3)
            return 1.0 - d / 2.0 + d * d / 3.0
        return math.log1p(d) / d

    @property
    def effective_stiffness(self) -> float:
        """K = (G_d/h) * geometric factor, Pa/m: d(sigma)/dt = K (V0 - V) (Eq 17)."""
        return self.stiffness * self.geometric_factor


SECTIONS: dict[str, type] = {
    "bonds": BondParameters,
    "aging": AgingParameters,
    "stick": StickParameters,
    "block": BlockParameters,
}
_META_KEYS = ("name", "description", "reference")


def require_flag(value: Any, name: str) -> bool:
    """``value`` as a bool; anything but True/False (numpy's included) is one ParameterError naming ``name``.

    ``bool("false")`` is True: a truthy text, number or None is refused instead of silently read.
    """
    if isinstance(value, bool) or (
        getattr(value, "dtype", None) is not None and value.dtype.kind == "b" and getattr(value, "ndim", 1) == 0
    ):  # fmt: skip - numpy's bool, not imported here
        return bool(value)
    raise ParameterError(f"{name}: expected True or False, got {shorten(value)}")


def parameter_keys() -> list[str]:
    """All canonical keys, ``section.key``."""
    return [f"{s}.{f.name}" for s, cls in SECTIONS.items() for f in fields(cls)]


def optional_keys() -> list[str]:
    """The keys an extension adds: absent means the paper's model."""
    return [f"{s}.{f.name}" for s, cls in SECTIONS.items() for f in fields(cls) if _optional(f)]


#: Keys that set the block's stiffness, through its height (shear modulus and trapezoid kept): G_d/h (Eq 5) and
#: K = (G_d/h) ln(B/l)/(B/l - 1) (Eq 17).  Overrides take them (:meth:`Parameters.with_overrides`), as sweeps
#: and ``--set`` do; a set holds the height.
STIFFNESS_KEYS = {"block.stiffness": "stress_per_length", "block.effective_stiffness": "stress_per_length"}


def override_dimension(key: str) -> str:
    """The dimension of a key an override may set: a canonical key (:func:`key_dimension`) or a stiffness key of
    :data:`STIFFNESS_KEYS`; an unknown key is one ParameterError listing them all."""
    if key in STIFFNESS_KEYS:
        return STIFFNESS_KEYS[key]
    try:
        return key_dimension(key)
    except ParameterError:
        known = ", ".join([*parameter_keys(), *STIFFNESS_KEYS])
        raise ParameterError(f"unknown parameter key {shorten(key)}; expected one of: {known}") from None


def key_dimension(key: str) -> str:
    """The dimension (see :data:`stickslip.units.DIMENSIONS`) of a canonical key."""
    section, _, name = key.partition(".")
    cls = SECTIONS.get(section)
    if cls is None or name not in {f.name for f in fields(cls)}:
        raise ParameterError(f"unknown parameter key {shorten(key)}; expected one of: {', '.join(parameter_keys())}")
    return next(f.metadata["dimension"] for f in fields(cls) if f.name == name)


@dataclass(frozen=True)
class Parameters:
    """A complete, validated parameter set (SI units throughout)."""

    bonds: BondParameters
    aging: AgingParameters
    stick: StickParameters
    block: BlockParameters
    name: str = "custom"
    description: str = ""
    reference: str = ""

    def __post_init__(self) -> None:
        for section, cls in SECTIONS.items():  # Parameters(bonds=None) would fail later, far from its cause
            given = getattr(self, section)
            if not isinstance(given, cls):
                raise ParameterError(f"Parameters({section}=...): expected a {cls.__name__}, got {shorten(given)}")
        for meta in ("name", "description", "reference"):
            if not isinstance(getattr(self, meta), str):
                raise ParameterError(f"Parameters({meta}=...): expected a text, got {shorten(getattr(self, meta))}")

    def _held(self) -> Iterator[tuple[str, Any, float]]:
        """(``section.key``, its field, SI value) of each key, in order; an optional key left out is absent."""
        for s, cls in SECTIONS.items():
            for f in fields(cls):
                value = getattr(getattr(self, s), f.name)
                if value is not None:
                    yield f"{s}.{f.name}", f, value

    def as_dict(self) -> dict[str, float]:
        """Flat mapping ``section.key -> SI float`` (an optional key left out is absent)."""
        return {key: value for key, _, value in self._held()}

    def with_overrides(self, overrides: Mapping[str, Any] | None) -> Parameters:
        """A new set with ``section.key`` values replaced (numbers in SI, or values with their units: strings such
        as ``"224 us"`` or pint quantities).  A number written as text without a unit (``"224"``) is refused, a
        :class:`~stickslip.errors.UnitError` naming the key, as everywhere in the Python API (zero and dimensionless
        keys need no unit).

        ``block.stiffness`` (G_d/h) or ``block.effective_stiffness`` (K of Eq 17) sets the block's height to give
        that stiffness with the set's shear modulus and trapezoid (after the other overrides, so a
        ``block.shear_modulus`` given beside it is the one used); with ``block.height``, or both, it is refused.
        """
        if not overrides:
            return self
        if not isinstance(overrides, Mapping):
            raise ParameterError(f"overrides: expected a mapping of 'section.key' to values, got {shorten(overrides)}")
        values: dict[str, Any] = self.as_dict()
        held = {**values, **{key: getattr(self.block, key.partition(".")[2]) for key in STIFFNESS_KEYS}}
        stiffness: dict[str, float] = {}
        for key, raw in overrides.items():
            if not isinstance(key, str):
                raise ParameterError(f"overrides: expected 'section.key' names, got {shorten(key)}")
            dimension = override_dimension(key)
            (stiffness if key in STIFFNESS_KEYS else values)[key] = override_to_si(raw, dimension, key, held.get(key))
        setting = [k for k in ("block.height", *STIFFNESS_KEYS) if k in overrides]
        if stiffness and len(setting) > 1:
            raise ParameterError(f"{' and '.join(setting)} both set the block's height; give only one of them")
        try:
            if stiffness:
                values["block.height"] = _height_for(values, *next(iter(stiffness.items())))
            return _build(values, name=self.name, description=self.description, reference=self.reference)
        except ParameterError as exc:
            raise _as_written(exc, overrides) from None

    def rows(self) -> list[tuple[str, str, str, str]]:
        """(key, symbol, value with unit, meaning) for display."""
        return [
            (key, f.metadata["symbol"], format_si(value, f.metadata["dimension"]), f.metadata["doc"])
            for key, f, value in self._held()
        ]

    def to_toml(self) -> str:
        """An editable TOML file; values as a person writes them (``"360 um/s"``), and a reload gives the same set."""
        lines = [f"name = {_toml_str(self.name)}"]
        if self.description:
            lines.append(f"description = {_toml_str(self.description)}")
        if self.reference:
            lines.append(f"reference = {_toml_str(self.reference)}")
        for key, f, value in self._held():
            header = f"[{key.partition('.')[0]}]"
            if header not in lines:  # a section's first key (every section holds required keys)
                lines += ["", header]
            dimension = f.metadata["dimension"]
            text = format_quantity(value, dimension)
            shown = text if dimension == "dimensionless" else _toml_str(text)
            lines.append(f"{f.name} = {shown}  # {f.metadata['symbol']}: {f.metadata['doc']}")
        return "\n".join(lines) + "\n"

    def to_json(self) -> str:
        """The set as a JSON object, the same entries as :meth:`to_toml` (name, description, reference, then one
        object per section, values as a person writes them, ``"360 um/s"``; a dimensionless value a number) without
        its comments; ``--params FILE.json`` and :func:`load_parameters` read it back to the same set."""
        document: dict[str, Any] = {meta: getattr(self, meta) for meta in _META_KEYS if getattr(self, meta)}
        for key, f, value in self._held():
            section, _, name = key.partition(".")
            dimension = f.metadata["dimension"]
            text = format_quantity(value, dimension)
            document.setdefault(section, {})[name] = float(text) if dimension == "dimensionless" else text
        return json.dumps(document, indent=2, ensure_ascii=False) + "\n"


def _height_for(values: Mapping[str, float], key: str, stiffness: float) -> float:
    """The block height (m) at which stiffness ``key`` of :data:`STIFFNESS_KEYS` is ``stiffness`` (Pa/m), with the
    shear modulus and trapezoid of ``values``: h = G_d/stiffness, times the Eq 17 factor for K."""
    if not (math.isfinite(stiffness) and stiffness > 0):
        raise ParameterError(f"{key}: expected a positive finite value in Pa/m, got {stiffness:g}")
    block = BlockParameters(**{f.name: values[f"block.{f.name}"] for f in fields(BlockParameters)})
    factor = block.geometric_factor if key == "block.effective_stiffness" else 1.0
    return block.shear_modulus * factor / stiffness


def _toml_str(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _build(values: Mapping[str, float], **meta: str) -> Parameters:
    sections = {}
    for s, cls in SECTIONS.items():
        sections[s] = cls(**{f.name: values[f"{s}.{f.name}"] for f in fields(cls) if f"{s}.{f.name}" in values})
    return Parameters(**sections, **meta)


def parameters_from_mapping(data: Mapping[str, Any], source: str = "parameters") -> Parameters:
    """Build a set from a nested mapping as read from TOML (values with units)."""
    meta: dict[str, str] = {}
    values: dict[str, float] = {}
    written: dict[str, Any] = {}  # each key's value as the file writes it
    for top, content in data.items():
        if top in _META_KEYS:
            if not isinstance(content, str):
                raise ParameterError(f"{source}: {top} must be a string, got {shorten(content)}")
            meta[top] = content
            continue
        if top not in SECTIONS:
            raise ParameterError(
                f"{source}: unknown section or key {shorten(top)}; expected sections {', '.join(SECTIONS)}"
                f" (and optional {', '.join(_META_KEYS)})"
            )
        if not isinstance(content, Mapping):
            raise ParameterError(f"{source}: [{top}] must be a table of key = value")
        for name, raw in content.items():
            key = f"{top}.{name}"
            try:
                dimension = key_dimension(key)
            except ParameterError as exc:  # an unknown key: named with the file it is in
                raise ParameterError(f"{source}: {exc}") from None
            _refuse_quoted_number(raw, dimension, f"{source}: {key}", name)
            values[key] = to_si(raw, dimension, f"{source}: {key}")
            written[key] = raw
    missing = [k for k in parameter_keys() if k not in values and k not in optional_keys()]
    if missing:
        raise ParameterError(f"{source}: missing parameter(s) {', '.join(missing)}")
    try:
        return _build(values, **meta)
    except ParameterError as exc:  # a value out of range: named with its file, as written and in SI
        raise ParameterError(f"{source}: {_written_and_si(str(exc), written, values)}") from None


def _refuse_quoted_number(raw: Any, dimension: str, where: str, name: str) -> None:
    """``bond_time = "224"``: a quoted value is text with its unit, as on the command line; a quoted bare non-zero
    number of a dimensional key is refused (unquoted, ``bond_time = 224``, a number is SI)."""
    from .units import DIMENSIONS, bare_number, quantity_noun

    number = bare_number(raw) if isinstance(raw, str) else None
    if dimension == "dimensionless" or number is None or number == 0 or not math.isfinite(number):
        return
    si = DIMENSIONS[dimension][1]
    typed = raw.strip()
    raise ParameterError(
        f"{where}: {shorten(typed)} is a quoted number without a unit; {quantity_noun(dimension)} needs one,"
        f' e.g. {name} = "{typed} {si}" (or {name} = {typed}, unquoted, for a number in SI units, {si})'
    )


def _written_and_si(message: str, written: Mapping[str, Any], values: Mapping[str, float]) -> str:
    """A refusal ``"key: expected ..., got <SI number>"`` ending instead with the value as written and its SI value
    with unit ("got -300 degC = -26.85 K"); other messages unchanged."""
    key = message.partition(":")[0]
    raw = written.get(key)
    if ", got " not in message or key not in values or raw is None:
        return message
    si = format_si(values[key], key_dimension(key))
    text = raw.strip() if isinstance(raw, str) else None  # a bare number is SI: shown with its unit
    shown = si if text is None or text == si else f"{text} = {si}"
    return f"{message.rsplit(', got ', 1)[0]}, got {shown}"


def available_parameter_sets() -> list[str]:
    """Names of the built-in parameter sets."""
    folder = resources.files("stickslip") / "parameter_sets"
    return sorted(p.name[: -len(".toml")] for p in folder.iterdir() if p.name.endswith(".toml"))


#: Largest parameter file read (a complete one is about 2 kB).
MAX_PARAMETER_FILE_BYTES = 1_000_000


def read_parameter_file(path: str | Path) -> Parameters:
    """Read a parameter file, TOML or JSON (:func:`parameter_file_format`; a regular file of at most
    :data:`MAX_PARAMETER_FILE_BYTES`)."""
    if not isinstance(path, (str, os.PathLike)):
        raise ParameterError(f"parameter file: expected a path, got {type(path).__name__}")
    path = Path(path)
    text = read_input_text(path, f"parameter file {shorten(str(path), 240)}", MAX_PARAMETER_FILE_BYTES, ParameterError)
    protect_inputs([path])  # in a command, no output may replace its parameter file
    data = parse_parameter_text(text, path, str(path))
    return _named_by_file(parameters_from_mapping(data, str(path)), path, "name" in data)


#: How the text of each format is parsed (JSONDecodeError and TOMLDecodeError are ValueErrors).
_PARSERS: dict[str, Any] = {"JSON": json.loads, "TOML": tomllib.loads}


def parameter_file_format(path: str | Path, text: str) -> tuple[str, str]:
    """("JSON" or "TOML", why) of a parameter file: its suffix (.json, .toml) says; a file named otherwise is JSON
    when its text starts with ``{`` (a TOML file never does), else TOML."""
    suffix = Path(path).suffix.lower()
    if suffix in (".json", ".toml"):
        return suffix[1:].upper(), f"its name ends in {suffix}"
    if text.lstrip("\ufeff \t\r\n").startswith("{"):
        return "JSON", "its name ends in neither .json nor .toml and its text starts with '{'"
    return "TOML", "its name ends in neither .json nor .toml and its text does not start with '{'"


def parse_parameter_text(
    text: str, path: str | Path, source: str, error: type[Exception] = ParameterError
) -> dict[str, Any]:
    """The top-level table of a parameter file's ``text``: the one reader of every ``--params FILE`` (the bond
    model's sets, rate-and-state's ``.params.json`` and TOML), JSON or TOML as :func:`parameter_file_format` says.

    A file whose text is the other format (a ``.json`` holding TOML, as ``params export -o x.json`` wrote before
    it wrote JSON) is read as that format: the two never parse the same text.  A file that is neither is refused
    in one line (``error``, prefixed with ``source``) naming the format it was read as, why, and the parser's
    complaint."""
    kind, why = parameter_file_format(path, text)
    other = "TOML" if kind == "JSON" else "JSON"
    text = text.removeprefix("\ufeff")
    try:
        data = _PARSERS[kind](text)
    except RecursionError:  # "[[[[..." a hundred thousand deep: the parsers recurse
        raise error(f"{source}: malformed {kind}: nested too deeply to be a parameter file") from None
    except ValueError as exc:
        detail = (str(exc).splitlines() or [""])[0]
        try:
            data = _PARSERS[other](text)
        except (ValueError, RecursionError):
            raise error(f"{source}: malformed {kind} (read as {kind}: {why}): {detail}") from None
        if not isinstance(data, dict):  # "3" is a JSON number: no sign the file was meant as JSON
            raise error(f"{source}: malformed {kind} (read as {kind}: {why}): {detail}") from None
    if not isinstance(data, dict):
        raise error(f"{source}: expected a table of parameters (a JSON object), got {type(data).__name__}")
    return data


def _parse_toml(text: str, source: str) -> Parameters:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{source}: malformed TOML: {exc}") from None
    except RecursionError:  # "a = [[[[..." a hundred thousand deep: tomllib recurses
        raise ParameterError(f"{source}: malformed TOML: nested too deeply to be a parameter file") from None
    return parameters_from_mapping(data, source)


def _as_written(exc: ParameterError, overrides: Mapping[str, Any]) -> ParameterError:
    """An override refused after its conversion to SI, named as the user wrote it ("got '-5 mm'", not "got
    -0.005")."""
    message = str(exc)
    for key, raw in overrides.items():
        if isinstance(raw, str) and message.startswith(f"{key}:") and ", got " in message:
            return ParameterError(as_written(message, raw))
    return exc


def load_parameters(
    name_or_path: str | Path | Parameters = "gelatin-glass", overrides: Mapping[str, Any] | None = None
) -> Parameters:
    """A built-in set by name (``"gelatin-glass"``) or a TOML or JSON file by path, with optional overrides.

    A set whose values the overrides change is no longer the set it was read as: its name says so,
    ``"gelatin-glass, modified: bonds.bond_time"`` (:func:`modified_name`), wherever it is shown or exported.

    >>> p = load_parameters("gelatin-glass", overrides={"bonds.max_extension": "1 m"})
    >>> p.bonds.max_extension
    1.0
    >>> p.name
    'gelatin-glass, modified: bonds.max_extension'
    """
    if isinstance(name_or_path, Parameters):
        return _overridden(name_or_path, overrides)
    text = str(name_or_path)
    if not text.strip():
        raise ParameterError(
            "empty parameter set name: expected a built-in name"
            f" ({', '.join(available_parameter_sets())}) or a TOML or JSON file"
        )
    if text in available_parameter_sets():
        resource = resources.files("stickslip") / "parameter_sets" / f"{text}.toml"
        params = _parse_toml(resource.read_text(encoding="utf-8"), text)
    elif text.endswith((".toml", ".json")) or "/" in text or _exists(text):
        params = read_parameter_file(text)
    else:
        raise ParameterError(
            f"unknown parameter set {shorten(text)}: expected a built-in name"
            f" ({', '.join(available_parameter_sets())}) or a TOML or JSON file"
        )
    return _overridden(params, overrides)


#: What a set's name says after the keys that overrides changed (``"gelatin-glass, modified: bonds.bond_time"``).
MODIFIED = ", modified: "


def modified_name(name: str, keys: Iterable[str]) -> str:
    """``name`` with ``keys`` listed as modified (after any it lists already, each once); unchanged without keys."""
    base, said, earlier = name.partition(MODIFIED)
    listed = [k for k in earlier.split(", ") if k] if said else []
    listed += [k for k in keys if k not in listed]
    return f"{base}{MODIFIED}{', '.join(listed)}" if listed else name


def _overridden(params: Parameters, overrides: Mapping[str, Any] | None) -> Parameters:
    """``params.with_overrides(overrides)``, named for the keys whose values it changed (a value set to what the
    set holds leaves the name as it is; a height set by a stiffness key is named by that key)."""
    changed = params.with_overrides(overrides)
    if changed is params:
        return params
    keys = _differing(params, changed)
    given = next((k for k in STIFFNESS_KEYS if k in (overrides or {})), None)
    if given is not None:
        keys = [given if k == "block.height" else k for k in keys]
    name = modified_name(params.name, keys)
    return changed if name == changed.name else dataclasses.replace(changed, name=name)


def _differing(before: Parameters, after: Parameters) -> list[str]:
    """The keys whose values differ between two sets (in ``after``'s order; a key one of them lacks included)."""
    old, new = before.as_dict(), after.as_dict()
    return [k for k in new if old.get(k) != new[k]] + [k for k in old if k not in new]


def _named_by_file(params: Parameters, path: Path, named: bool) -> Parameters:
    """A set read from ``path`` named by its file: a file without a ``name`` by the file's name; one that carries a
    built-in set's name (``gelatin-glass``, or ``gelatin-glass, modified: ...``) with other values than the name
    says is named so, ``"gelatin-glass from my.toml, modified: bonds.bond_time"`` (every key whose value differs
    from the built-in set's and the name does not list); otherwise by the name it carries."""
    if not named:
        return dataclasses.replace(params, name=path.name)
    base, said, listed = params.name.partition(MODIFIED)
    if base not in available_parameter_sets():
        return params
    shipped = load_parameters(base)
    already = listed.split(", ") if said else []
    if any(k in already for k in STIFFNESS_KEYS):  # a stiffness key set the height
        already.append("block.height")
    unsaid = [k for k in _differing(shipped, params) if k not in already]
    if not unsaid:
        return params
    name = modified_name(f"{base} from {path.name}" + (f"{MODIFIED}{listed}" if said else ""), unsaid)
    return dataclasses.replace(params, name=name)


def _exists(text: str) -> bool:
    """Whether ``text`` names something on disk (a FIFO or a folder too: reading it then says what is wrong)."""
    try:
        return Path(text).exists()
    except (OSError, ValueError):  # a name too long for the system, or with a NUL byte
        return False


def replace(params: Parameters, **sections: Any) -> Parameters:
    """``dataclasses.replace`` for nested sections, e.g. ``replace(p, bonds={"bond_time": 1e-3})``."""
    changes = {}
    for s, values in sections.items():
        if s not in SECTIONS:
            raise ParameterError(f"unknown section {shorten(s)}")
        changes[s] = dataclasses.replace(getattr(params, s), **values)
    return dataclasses.replace(params, **changes)


@dataclass(frozen=True)
class Combination:
    """A product of powers of parameters on which sigma(V) depends (the dimensionless form of Eqs 6-8).

    Defined here, beside the keys, so that :mod:`stickslip.columns` knows the unit of a fit's combination key
    (``stress_scale``, ...) without importing the fits above it; :mod:`stickslip.fitting.identify` uses them.
    """

    name: str
    symbol: str
    dimension: str
    exponents: dict[str, int]
    aging: bool = False

    def value(self, params: Parameters) -> float:
        values = params.as_dict()
        out = 1.0
        for key, power in self.exponents.items():
            out *= values[key] ** power
        if self.name == "fene_strength":
            out /= BOLTZMANN
        return out


COMBINATIONS = (
    Combination(
        "stress_scale",
        "M·N0·Δl_m",
        "stress",
        {"bonds.chain_stiffness": 1, "bonds.site_density": 1, "bonds.max_extension": 1},
    ),
    Combination("velocity_scale", "Δl_m/τ", "velocity", {"bonds.max_extension": 1, "bonds.bond_time": -1}),
    Combination(
        "fene_strength",
        "a = λMΔl_m/kT",
        "dimensionless",
        {
            "bonds.activation_length": 1,
            "bonds.chain_stiffness": 1,
            "bonds.max_extension": 1,
            "bonds.temperature": -1,
        },
    ),
    Combination("breakage_weight", "u0", "dimensionless", {"bonds.breakage_weight": 1}),
    Combination(
        "aging_velocity_scale", "Δl_m/τa", "velocity", {"bonds.max_extension": 1, "aging.aging_time": -1}, aging=True
    ),
    Combination("aging_velocity", "Va", "velocity", {"aging.aging_velocity": 1}, aging=True),
)
