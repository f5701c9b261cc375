"""What the two forms of the bond model share: their parameter keys, the stiffness keys, the rig's spring."""

from __future__ import annotations

from collections.abc import Mapping
from functools import lru_cache
from typing import Any, ClassVar

import numpy as np

from ..errors import ParameterError
from ..parameters import (
    Parameters,
    key_dimension,
    load_parameters,
    optional_keys,
    parameter_keys,
    parameters_from_mapping,
)
from .base import CYCLE_RESULTS, FrictionModel, Rig

#: Keys that set the block's stiffness directly (through its height): G_d/h, and K = (G_d/h) ln(B/l)/(B/l - 1).
STIFFNESS_KEYS = {"block.stiffness": "stress_per_length", "block.effective_stiffness": "stress_per_length"}
DEFAULT_SET = "gelatin-glass"


class BondModel(FrictionModel):
    """Parameters of the bond model (:class:`stickslip.Parameters`, keys ``section.name``) and its block."""

    sweep_columns: ClassVar[Mapping[str, str]] = {**CYCLE_RESULTS, "critical_velocity": "float"}

    def dimensions(self) -> dict[str, str]:
        return {**{k: key_dimension(k) for k in parameter_keys()}, **STIFFNESS_KEYS}

    def parameters(self, spec: Any = None, overrides: Mapping[str, Any] | None = None) -> Parameters:
        """A parameter set (name, TOML file, :class:`Parameters`, or a mapping of ``section.key`` values, nested
        sections or a whole exported set as a dict, over the default gelatin-glass) with ``overrides``;
        ``block.stiffness`` or ``block.effective_stiffness`` set the block's height."""
        from ..units import override_to_si

        if overrides is not None and not isinstance(overrides, Mapping):
            kind = type(overrides).__name__
            raise ParameterError(f"overrides: expected a mapping {{'section.key': value}}, got {kind}")
        given = dict(overrides or {})
        if isinstance(spec, Mapping):  # {"bonds.bond_time": ...}, {"bonds": {...}} or a whole exported set as a dict
            given, spec = {**_flat_keys(spec), **given}, None
        stiffness = {k: given.pop(k) for k in STIFFNESS_KEYS if k in given}
        keys = parameter_keys()
        required = set(keys) - set(optional_keys())  # an extension's key (aging.saturation_age) may be absent
        present = [k for k in keys if k in given]
        if spec is None and required <= set(given) and all(_is_number(given[k]) for k in present):
            if len(given) > len(present):
                key_dimension(next(k for k in given if k not in keys))  # the one-line error naming the key
            params = _parameter_set(tuple(float(given[k]) if k in given else None for k in keys))
            return with_stiffness(params, {k: override_to_si(v, STIFFNESS_KEYS[k], k) for k, v in stiffness.items()})
        # load_parameters reads the stiffness keys itself and names the set after them ("modified: block.stiffness")
        return load_parameters(DEFAULT_SET if spec is None else spec, {**given, **stiffness})

    def values(self, params: Parameters) -> dict[str, float]:
        return params.as_dict()

    def check_keys(self, varied: tuple[str, ...], fixed: Mapping[str, float]) -> None:
        """Refuse two keys that set the same thing (the height and a stiffness)."""
        setting = [k for k in ("block.height", *STIFFNESS_KEYS) if k in varied or (k in STIFFNESS_KEYS and k in fixed)]
        if len(setting) > 1:
            raise ParameterError(f"{' and '.join(setting)} both set the block's height; vary or set only one of them")

    def stiffness_of(self, key: str, params: Parameters, k_effective: np.ndarray) -> np.ndarray:
        """The value of stiffness-like ``key`` at which the effective stiffness is ``k_effective``."""
        factor = params.block.geometric_factor
        if key == "block.effective_stiffness":
            return k_effective
        if key == "block.stiffness":
            return k_effective / factor
        return params.block.shear_modulus * factor / k_effective  # block.height

    def with_rig(self, params: Parameters, rig: Rig) -> Parameters:
        """The parameters whose block has the rig's stiffness (Eq 17's K; the block's own when the rig has none)."""
        if rig.stiffness is None:
            return params
        return with_stiffness(params, {"block.effective_stiffness": rig.stiffness})

    def spring(self, params: Parameters, rig: Rig) -> tuple[float, str, str] | None:
        """The rig's K (Pa/m) as given, else the block's own (Eq 17's K of the parameters); None without a spring."""
        if rig.control != "spring":
            return None
        if rig.stiffness is not None:
            return rig.stiffness, "Pa/m", "rig"
        return float(params.block.effective_stiffness), "Pa/m", "parameters"


def with_stiffness(params: Parameters, stiffness: Mapping[str, float]) -> Parameters:
    """``params`` with the block's height set by ``block.stiffness`` (G/h) or ``block.effective_stiffness`` (K)."""
    block = params.block
    if "block.stiffness" in stiffness:
        params = params.with_overrides({"block.height": block.shear_modulus / _positive(stiffness, "block.stiffness")})
    if "block.effective_stiffness" in stiffness:
        height = block.shear_modulus * block.geometric_factor / _positive(stiffness, "block.effective_stiffness")
        params = params.with_overrides({"block.height": height})
    return params


#: the top-level entries of an exported set that describe it rather than set a value
_DESCRIPTIVE = ("name", "description", "reference")


def _flat_keys(spec: Mapping[str, Any]) -> dict[str, Any]:
    """A mapping of parameters as ``section.key`` entries: nested sections (a TOML file read as a dict) flattened,
    the set's name, description and reference dropped; every key is checked where the set is built."""
    flat: dict[str, Any] = {}
    for key, value in spec.items():
        if isinstance(value, Mapping):
            flat.update((f"{key}.{inner}", item) for inner, item in value.items())
        elif str(key) not in _DESCRIPTIVE:
            flat[str(key)] = value
    return flat


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool)


@lru_cache(maxsize=64)
def _parameter_set(values: tuple[float | None, ...]) -> Parameters:
    """Parameters from the SI values of :func:`parameter_keys`, in that order (validated; None: an optional key
    left out)."""
    nested: dict[str, dict[str, float]] = {}
    for key, value in zip(parameter_keys(), values, strict=True):
        if value is None:
            continue
        section, _, name = key.partition(".")
        nested.setdefault(section, {})[name] = value
    return parameters_from_mapping({"name": "sweep point", **nested}, "sweep point")


def _positive(values: Mapping[str, float], key: str) -> float:
    value = values[key]
    if not value > 0:
        raise ParameterError(f"{key}: expected a positive value, got {value:g}")
    return value
