"""Parameters of rate-and-state friction and of the spring-slider: frozen, validated, SI inside.

``stiffness`` is friction per slip (1/m): a machine stiffness K in Pa/m with a
normal stress sigma is ``K / sigma``.  ``eta`` is radiation damping in friction
per velocity (s/m: the shear impedance over sigma).  ``mass`` is the slider's
mass per unit area (kg/m^2) and needs ``normal_stress``.  ``cutoff = (V1, V2)``
(m/s) selects the cut-off velocity form ``mu = mu0 - a ln(V1/V + 1) + sum b_i
ln(V2 theta_i/Dc_i + 1)`` (QDYN's; see :mod:`stickslip.rsf.laws`), where mu0 is
the friction with both logarithms' arguments at 1 and v_ref only scales the
solver's variables.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import ParameterError, UnitError
from ..units import DIMENSIONS, bare_number, quantity_noun, shorten, to_si
from .laws import StateLaw, get_law

__all__ = ["RSFParams", "StateVariable", "rsf_params"]


def _finite(name: str, value: Any, minimum: float | None = None, strict: bool = True) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise ParameterError(f"{name}: expected a number, got {value!r}") from None
    value = float(value)
    if not math.isfinite(value):
        raise ParameterError(f"{name}: expected a finite number, got {value!r}")
    if minimum is not None and (value < minimum or (strict and value == minimum)):
        relation = ">" if strict else ">="
        raise ParameterError(f"{name}: expected a value {relation} {minimum:g}, got {value:g}")
    return value


@dataclass(frozen=True)
class StateVariable:
    """One state variable: its evolution ``law``, direct weight ``b``, length ``dc`` (m); ``c`` for Nagata."""

    law: str = "aging"
    b: float = 0.01
    dc: float = 10e-6
    c: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.law, (str, StateLaw)):
            raise ParameterError(f"law: expected a law name such as 'aging', got {shorten(self.law)}")
        law = get_law(self.law)
        object.__setattr__(self, "law", self.law.strip().lower() if isinstance(self.law, str) else law.name)
        object.__setattr__(self, "b", _finite("b", self.b))
        object.__setattr__(self, "dc", _finite("dc", self.dc, 0.0))
        object.__setattr__(self, "c", _finite("c", self.c, 0.0, strict=False))
        if law.coupling(1.0, 1.0) != 0.0 and self.b == 0:
            raise ParameterError(f"b: the {self.law} law divides by b; expected b != 0")


@dataclass(frozen=True)
class RSFParams:
    """Rate-and-state friction on a spring-slider (SI units; friction is dimensionless)."""

    a: float = 0.01
    states: tuple[StateVariable, ...] = field(default_factory=lambda: (StateVariable(),))
    mu0: float = 0.6
    v_ref: float = 1e-6
    stiffness: float = 1e3
    eta: float = 0.0
    mass: float = 0.0
    normal_stress: float | None = None
    regularized: bool = False
    cutoff: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "a", _finite("a", self.a, 0.0))
        if isinstance(self.states, StateVariable):
            raise ParameterError("states: expected a tuple of StateVariable, got one StateVariable; write (state,)")
        try:
            states = tuple(self.states)
        except TypeError:
            raise ParameterError(f"states: expected a tuple of StateVariable, got {shorten(self.states)}") from None
        if not states:
            raise ParameterError("states: expected at least one state variable")
        for item in states:
            if not isinstance(item, StateVariable):
                raise ParameterError(f"states: expected StateVariable items, got {type(item).__name__}")
        object.__setattr__(self, "states", states)
        mu0 = _finite("mu0", self.mu0)
        if mu0 <= 0:  # the friction coefficient at V0 of a slider pressed on its track: below zero it would push
            raise ParameterError(f"mu0: expected a positive friction coefficient (friction at V0), got {mu0:g}")
        object.__setattr__(self, "mu0", mu0)
        object.__setattr__(self, "v_ref", _finite("v_ref", self.v_ref, 0.0))
        object.__setattr__(self, "stiffness", _finite("stiffness", self.stiffness, 0.0))
        object.__setattr__(self, "eta", _finite("eta", self.eta, 0.0, strict=False))
        object.__setattr__(self, "mass", _finite("mass", self.mass, 0.0, strict=False))
        if self.normal_stress is not None:
            object.__setattr__(self, "normal_stress", _finite("normal_stress", self.normal_stress, 0.0))
        if self.mass > 0 and self.normal_stress is None:
            raise ParameterError("mass: a slider mass needs normal_stress (the inertia term is mass/normal stress)")
        if not isinstance(self.regularized, (bool, np.bool_)):  # bool("false") is True: take no strings or numbers
            raise ParameterError(f"regularized: expected true or false, got {shorten(self.regularized)}")
        object.__setattr__(self, "regularized", bool(self.regularized))
        if self.cutoff is not None:
            object.__setattr__(self, "cutoff", _cutoff_pair(self.cutoff))
            self._check_cutoff_combinations()

    def _check_cutoff_combinations(self) -> None:
        if self.regularized:
            raise ParameterError("cutoff: the cut-off velocity form and the regularised form exclude each other")
        for s in self.states:
            if get_law(s.law).coupling(1.0, 1.0) != 0.0:
                raise ParameterError(
                    f"cutoff: the {s.law} law couples the state to dmu/dt of the classical form; expected a law"
                    " without that coupling (aging, slip, prz) with the cut-off velocity form"
                )

    @property
    def b(self) -> float:
        """Sum of the state weights (the steady rate dependence is a - b)."""
        return sum(s.b for s in self.states)

    @property
    def dc(self) -> float:
        return self.states[0].dc

    def steady_friction(self, velocity: Any) -> Any:
        """mu_ss(V) = mu0 + (a - b) ln(V/V0) (the regularised form differs only where V/V0 << e^(-mu/a)).

        With ``cutoff = (V1, V2)``: mu0 - a ln(V1/V + 1) + b ln(V2/V + 1).
        """
        v = np.asarray(velocity, dtype=float)
        if self.cutoff is not None:  # theta_i = s Dc_i/V in steady state for every law: both terms are ln(Vc/V + 1)
            v1, v2 = self.cutoff
            lv = np.log(v)
            return (
                self.mu0 - self.a * np.logaddexp(0.0, math.log(v1) - lv) + self.b * np.logaddexp(0.0, math.log(v2) - lv)
            )
        if not self.regularized:
            return self.mu0 + (self.a - self.b) * np.log(v / self.v_ref)
        return self.a * np.arcsinh(0.5 * v / self.v_ref * np.exp((self.mu0 - self.b * np.log(v / self.v_ref)) / self.a))

    def replace(self, **changes: Any) -> RSFParams:
        return replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain SI values (the TOML/JSON written beside every trace and fit)."""
        out = {k: v for k, v in asdict(self).items() if k != "states"}
        out["states"] = [asdict(s) for s in self.states]
        if out["normal_stress"] is None:
            del out["normal_stress"]
        if self.cutoff is None:
            del out["cutoff"]
        else:
            out["cutoff"] = {"v1": self.cutoff[0], "v2": self.cutoff[1]}
        return out

    def to_toml(self) -> str:
        lines = ["# rate-and-state parameters (SI: m, s, m/s; stiffness in 1/m; eta in s/m; mass in kg/m^2)"]
        lines += [f"{key} = {_toml_value(value)}" for key, value in self.to_dict().items() if key != "states"]
        for state in self.states:
            lines += ["", "[[states]]", *(f"{key} = {_toml_value(value)}" for key, value in asdict(state).items())]
        return "\n".join(lines) + "\n"

    @classmethod
    def from_dict(cls, mapping: Mapping[str, Any], source: str = "parameters") -> RSFParams:
        """From plain values or strings with units (as written by :meth:`to_dict`); unknown keys are errors."""
        known = {"a", "states", "mu0", "v_ref", "stiffness", "eta", "mass", "normal_stress", "regularized", "cutoff"}
        if not isinstance(mapping, Mapping):
            raise ParameterError(f"{source}: expected a mapping of parameters, got {shorten(mapping)}")
        unknown = sorted(set(mapping) - known)
        if unknown:
            raise ParameterError(f"{source}: unknown key {unknown[0]!r}; expected one of {', '.join(sorted(known))}")
        values: dict[str, Any] = {"states": _states_from(mapping.get("states", _DEFAULT_STATES), source)}
        dims = {"a": "dimensionless", "mu0": "dimensionless", "v_ref": "velocity", "stiffness": "per_length",
                "eta": "slowness", "mass": "mass_per_area", "normal_stress": "stress"}  # fmt: skip
        for key in ("a", "mu0", "v_ref", "normal_stress", "mass", "regularized"):
            if key in mapping and not (key == "normal_stress" and mapping[key] is None):
                value = mapping[key]
                values[key] = _read(value, dims[key], f"{source}: {key}") if key in dims else value
        if mapping.get("cutoff") is not None:
            values["cutoff"] = _cutoff_from(mapping["cutoff"], f"{source}: cutoff")
        sigma = values.get("normal_stress")
        for key, stress_dim in (("stiffness", "stress_per_length"), ("eta", "stress_per_velocity")):
            if key in mapping:
                values[key] = _friction_units(mapping[key], dims[key], stress_dim, sigma, f"{source}: {key}")
        return cls(**values)


_DEFAULT_STATES = ({},)


def _states_from(items: Any, source: str) -> tuple[StateVariable, ...]:
    """State variables from a list of tables (law, b, dc, c); an empty or missing list is an error, not a default."""
    if isinstance(items, (str, bytes, Mapping)) or not isinstance(items, (list, tuple)) or not items:
        raise ParameterError(
            f"{source}: states: expected a non-empty list of tables with law, b, dc; got {shorten(items)}"
        )
    states = []
    for i, item in enumerate(items):
        if isinstance(item, StateVariable):
            states.append(item)
            continue
        if not isinstance(item, Mapping):
            raise ParameterError(f"{source}: states[{i}]: expected a table with law, b, dc; got {shorten(item)}")
        extra = sorted(set(item) - {"law", "b", "dc", "c"})
        if extra:
            raise ParameterError(f"{source}: states[{i}]: unknown key {extra[0]!r}; expected law, b, dc, c")
        states.append(
            StateVariable(
                law=item.get("law", "aging"),
                b=to_si(item.get("b", 0.01), "dimensionless", f"{source}: states[{i}].b"),
                dc=_read(item.get("dc", 10e-6), "length", f"{source}: states[{i}].dc"),
                c=to_si(item.get("c", 0.0), "dimensionless", f"{source}: states[{i}].c"),
            )
        )
    return tuple(states)


def _refuse_text_number(value: Any, dimension: str, name: str) -> None:
    """``dc = "10"`` (a file's quoted value, or text in a Python mapping): a non-zero number written as text without
    a unit is refused for a dimensional key, as the bond model's files and every argument of the Python API refuse
    it (before round 30 ``stickslip.run("rsf", {"dc": "10"}, ...)`` ran with dc = 10 m); a number is SI."""
    number = bare_number(value) if isinstance(value, str) else None
    if dimension == "dimensionless" or number is None or number == 0 or not math.isfinite(number):
        return
    typed, si, key = value.strip(), DIMENSIONS[dimension][1], name.rpartition(".")[2].rpartition(" ")[2]
    raise UnitError(
        f"{name}: {shorten(typed)} is a number written as text without a unit; {quantity_noun(dimension)} needs one,"
        f' e.g. {key} = "{typed} {si}" (or {key} = {typed}, a number, not text, for SI units, {si})'
    )


def _read(value: Any, dimension: str, name: str) -> float:
    """A value of a rate-and-state mapping in SI (:func:`to_si`), a number written as text without a unit refused."""
    _refuse_text_number(value, dimension, name)
    return to_si(value, dimension, name)


def _friction_units(value: Any, dimension: str, stress_dimension: str, sigma: float | None, name: str) -> float:
    """A value in friction units, or in stress units (Pa/m, Pa s/m) divided by the normal stress."""
    _refuse_text_number(value, dimension, name)
    try:
        return to_si(value, dimension, name)
    except UnitError:
        converted = to_si(value, stress_dimension, name)  # raises the one-line UnitError if neither fits
        if sigma is None:
            raise ParameterError(f"{name}: {value!r} is in stress units; give normal_stress to convert it") from None
        return converted / sigma


def _cutoff_pair(value: Any) -> tuple[float, float]:
    """(V1, V2) in m/s, each positive and finite."""
    if isinstance(value, (str, bytes, Mapping)) or not isinstance(value, (tuple, list, np.ndarray)) or len(value) != 2:
        raise ParameterError(f"cutoff: expected two velocities (V1, V2) in m/s, got {shorten(value)}")
    v1, v2 = (_finite(f"cutoff {name}", v, 0.0) for name, v in zip(("V1", "V2"), value, strict=True))
    return v1, v2


def _cutoff_from(value: Any, name: str) -> tuple[float, float]:
    """(V1, V2) from a table {v1, v2} or a pair, each a number (m/s) or a string with its unit."""
    if isinstance(value, Mapping):
        keys = {str(k).lower(): v for k, v in value.items()}
        if set(keys) != {"v1", "v2"}:
            raise ParameterError(f"{name}: expected a table with v1 and v2 (velocities), got {shorten(value)}")
        value = (keys["v1"], keys["v2"])
    if isinstance(value, (str, bytes)) or not isinstance(value, (list, tuple)) or len(value) != 2:
        raise ParameterError(f"{name}: expected v1 and v2 (velocities), got {shorten(value)}")
    return _read(value[0], "velocity", f"{name}.v1"), _read(value[1], "velocity", f"{name}.v2")


def _toml_value(value: Any) -> str:
    if isinstance(value, Mapping):
        return "{ " + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items()) + " }"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return repr(float(value))


def rsf_params(
    a: float,
    b: float,
    dc: float,
    *,
    law: str = "aging",
    b2: float | None = None,
    dc2: float | None = None,
    law2: str | None = None,
    c: float = 0.0,
    mu0: float = 0.6,
    v_ref: float = 1e-6,
    stiffness: float = 1e3,
    eta: float = 0.0,
    mass: float = 0.0,
    normal_stress: float | None = None,
    regularized: bool = False,
    cutoff: tuple[float, float] | None = None,
) -> RSFParams:
    """Convenience constructor for one or two state variables: numbers in SI, or values with their units
    (``dc="10 um"``, ``v_ref="1 um/s"``, ``stiffness="1e-3 1/um"``, ``eta="10 s/m"``, ``normal_stress="10 MPa"``)."""
    from ..units import refused_as_written_by_name, si_argument

    written = {"dc": dc, "dc2": dc2, "v_ref": v_ref, "stiffness": stiffness, "eta": eta, "normal_stress": normal_stress}
    dc, dc2, v_ref, stiffness, eta, normal_stress = (
        None if value is None else si_argument(value, dimension, name)
        for value, dimension, name in (
            (dc, "length", "dc"), (dc2, "length", "dc2"), (v_ref, "velocity", "v_ref"),
            (stiffness, "per_length", "stiffness"), (eta, "slowness", "eta"),
            (normal_stress, "stress", "normal_stress"),
        )
    )  # fmt: skip
    with refused_as_written_by_name(written):  # "got '-10 um'", not "got -1e-05"
        states = [StateVariable(law, b, dc, c)]
        if (b2 is None) != (dc2 is None):
            raise ParameterError("b2/dc2: a second state variable needs both b2 and dc2")
        if b2 is not None and dc2 is not None:
            states.append(StateVariable(law2 or law, b2, dc2, c))
        return RSFParams(a, tuple(states), mu0, v_ref, stiffness, eta, mass, normal_stress, regularized, cutoff)
