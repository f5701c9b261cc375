"""What a sweep computes: the varied keys, the design (grid or Latin hypercube), the fixed values.

A :class:`SweepSpec` is plain data (JSON in the output's manifest), so the
same specification can be compared on resume and shipped to any worker.
Values are SI floats; units live only in the ``--vary`` text parsed here.

``--vary`` forms (values with units, e.g. ``'bonds.bond_time=100 us..1 ms:20:log'``):

* ``KEY=LO..HI:N`` — N values evenly spaced from LO to HI (``:log`` for geometric spacing);
* ``KEY=V1,V2,...`` — the listed values;
* ``KEY=LO..HI`` or ``KEY=LO..HI:log`` — a range to sample (Latin hypercube, ``--samples N``).
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..units import to_si
from .sampling import grid_values, latin_hypercube

#: Values of one grid axis at most: the manifest lists each of them.
MAX_AXIS_VALUES = 1_000_000
#: Points of a Latin hypercube at most (indices stay exact in float64 and int64); the disk refuses far fewer.
MAX_SAMPLES = 2**53
_RANGE = re.compile(r"^(?P<lo>.+?)\.\.(?P<hi>[^:]+)(?::(?P<n>[^:]*))?(?::(?P<scale>[^:]*))?$")


@dataclass(frozen=True)
class Axis:
    """One varied key: explicit ``values`` (grid), or a range ``low..high`` (Latin hypercube)."""

    key: str
    values: tuple[float, ...] = ()
    low: float | None = None
    high: float | None = None
    log: bool = False

    def __post_init__(self) -> None:
        where = f"Axis({self.key!r})"
        if not isinstance(self.key, str) or not self.key.strip():
            raise ParameterError(f"Axis: expected key as a non-empty text, got {self.key!r}")
        if not isinstance(self.log, (bool, np.bool_)):  # bool("false") is True: take no texts
            raise ParameterError(f"{where}: expected log=True or False, got {self.log!r}")
        if isinstance(self.values, (str, bytes)):
            raise ParameterError(f"{where}: expected values as a sequence of numbers, got a text")
        values = tuple(_finite(v, f"{where}: values") for v in self.values)
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "log", bool(self.log))
        if values:
            if self.low is not None or self.high is not None:
                raise ParameterError(f"{where}: give either values or low..high, not both")
            ends = values
        else:
            if self.low is None or self.high is None:
                raise ParameterError(f"{where}: expected values, or both low and high")
            low, high = _finite(self.low, f"{where}: low"), _finite(self.high, f"{where}: high")
            if low > high:
                raise ParameterError(f"{where}: expected low <= high, got {low:g} > {high:g}")
            object.__setattr__(self, "low", low)
            object.__setattr__(self, "high", high)
            ends = (low, high)
        if self.log and min(ends) <= 0:
            raise ParameterError(f"{where}: a log axis needs positive values, got {min(ends):g}")

    @property
    def is_range(self) -> bool:
        return not self.values

    def as_dict(self) -> dict[str, Any]:
        if self.is_range:
            return {"key": self.key, "low": self.low, "high": self.high, "log": self.log}
        return {"key": self.key, "values": list(self.values), "log": self.log}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Axis:
        return cls(
            key=data["key"],
            values=tuple(float(v) for v in data.get("values", ())),
            low=data.get("low"),
            high=data.get("high"),
            log=bool(data.get("log", False)),
        )


@dataclass(frozen=True)
class SweepSpec:
    """A whole sweep: model, fixed values (SI, every key of the model), varied axes and design."""

    model: str
    fixed: Mapping[str, float]
    axes: tuple[Axis, ...]
    design: str = "grid"
    samples: int = 0
    seed: int = 0
    settings: Mapping[str, Any] = field(default_factory=dict)  # model options: duration, jump curve, ...
    label: str = ""  # the parameter set's name, for titles

    def __post_init__(self) -> None:
        if not isinstance(self.model, str) or not self.model.strip():
            raise ParameterError(f"SweepSpec: expected model as a name, got {self.model!r}")
        if not isinstance(self.fixed, Mapping) or not all(isinstance(k, str) for k in self.fixed):
            raise ParameterError("SweepSpec: expected fixed as a mapping {key: SI value}")
        object.__setattr__(self, "fixed", {k: _finite(v, f"SweepSpec: fixed[{k!r}]") for k, v in self.fixed.items()})
        if isinstance(self.axes, Axis) or not all(isinstance(a, Axis) for a in self.axes):
            raise ParameterError("SweepSpec: expected axes as a tuple of Axis")
        axes = tuple(self.axes)
        object.__setattr__(self, "axes", axes)
        if self.design not in ("grid", "latin-hypercube"):
            raise ParameterError(f"SweepSpec: expected design 'grid' or 'latin-hypercube', got {self.design!r}")
        for name in ("samples", "seed"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
                raise ParameterError(f"SweepSpec: expected {name} as a whole number >= 0, got {value!r}")
        samples = int(self.samples) if self.design == "latin-hypercube" else None
        if check_design(axes, samples) != self.design:  # pragma: no cover - check_design refuses a mismatch first
            raise ParameterError(f"SweepSpec: the axes do not make a {self.design} design")
        if not isinstance(self.settings, Mapping):
            raise ParameterError(f"SweepSpec: expected settings as a mapping, got {type(self.settings).__name__}")
        if not isinstance(self.label, str):
            raise ParameterError(f"SweepSpec: expected label as a text, got {self.label!r}")

    @property
    def keys(self) -> tuple[str, ...]:
        return tuple(a.key for a in self.axes)

    @property
    def size(self) -> int:
        """Number of points."""
        if self.design == "latin-hypercube":
            return self.samples
        return math.prod(len(a.values) for a in self.axes)

    def points(self, start: int, stop: int) -> dict[str, np.ndarray]:
        """The varied values of points ``start .. stop-1`` (one array per key), computed from the spec alone."""
        return self.points_at(np.arange(start, min(stop, self.size), dtype=np.int64))

    def points_at(self, index: Any) -> dict[str, np.ndarray]:
        """The varied values of the points ``index`` (any indices, in any order), elementwise as :meth:`points`:
        a task of points that are not contiguous (the sweep's cost-ordered schedule) gets the same values."""
        index = np.asarray(index, dtype=np.int64)
        if index.size and (int(index.min()) < 0 or int(index.max()) >= self.size):
            raise ParameterError(f"SweepSpec.points_at: indices must lie in 0..{self.size - 1}")
        if self.design == "latin-hypercube":
            return {
                a.key: latin_hypercube(index, self.samples, self.seed, k, a.low, a.high, a.log)  # type: ignore[arg-type]
                for k, a in enumerate(self.axes)
            }
        # the pulling velocity varies fastest: consecutive points then share a parameter set, and the
        # per-set work (critical point, branch of the steady curve) is cached on the worker
        order = sorted(self.axes, key=lambda a: a.key == "pulling_velocity")
        values = grid_values(index, [np.asarray(a.values) for a in order], [a.key for a in order])
        return {key: values[key] for key in self.keys}

    def as_dict(self) -> dict[str, Any]:
        return {
            "model": self.model,
            "design": self.design,
            "axes": [a.as_dict() for a in self.axes],
            "samples": self.samples,
            "seed": self.seed,
            "fixed": dict(self.fixed),
            "settings": dict(self.settings),
            "label": self.label,
        }

    def to_json(self) -> str:
        """Canonical JSON (sorted keys, every digit): equal specs give equal text."""
        return json.dumps(self.as_dict(), sort_keys=True)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> SweepSpec:
        return cls(
            model=data["model"],
            fixed={k: float(v) for k, v in data["fixed"].items()},
            axes=tuple(Axis.from_dict(a) for a in data["axes"]),
            design=data.get("design", "grid"),
            samples=int(data.get("samples", 0)),
            seed=int(data.get("seed", 0)),
            settings=dict(data.get("settings", {})),
            label=data.get("label", ""),
        )

    @classmethod
    def from_json(cls, text: str) -> SweepSpec:
        return cls.from_dict(json.loads(text))


def parse_vary(
    text: str, dimensions: Mapping[str, str], unit_check: Callable[[str, str, str], None] | None = None
) -> Axis:
    """``KEY=LO..HI:N[:log]``, ``KEY=LO..HI[:log]`` or ``KEY=V1,V2,...`` as an :class:`Axis` (SI values).

    ``dimensions`` maps each key the model accepts to its dimension; an
    unknown key, a malformed range or a value of the wrong unit is a
    :class:`~stickslip.errors.ParameterError` naming the ``--vary`` text.
    ``unit_check(value, dimension, prefix)`` (the command line's) refuses bare numbers.
    """
    if not isinstance(text, str):
        raise ParameterError(f"--vary: expected a text 'KEY=LO..HI:N[:log]', got {text!r}")
    where = f"--vary {text!r}"
    key, sep, body = text.partition("=")
    key, body = key.strip(), body.strip()
    if not sep or not key or not body:
        raise ParameterError(
            f"{where}: expected KEY=LO..HI:N[:log] or KEY=V1,V2,..., e.g. 'pulling_velocity=5 um/s..5 mm/s:20:log'"
        )
    if key not in dimensions:
        raise ParameterError(f"{where}: unknown key {key!r}; expected one of: {', '.join(dimensions)}")
    dimension = dimensions[key]

    def value(text: str) -> float:
        if unit_check is not None:
            unit_check(text.strip(), dimension, f"--vary {key}=")
        return _value(text, dimension, where)

    match = _RANGE.match(body)
    if match is not None and ("..." in body or match["hi"].strip().startswith(".")):
        raise ParameterError(f"{where}: expected two dots between the ends (LO..HI), got three or more")
    if match is None:
        items = body.split(",")
        if len(items) > MAX_AXIS_VALUES:
            raise ParameterError(f"{where}: {len(items)} values; at most {MAX_AXIS_VALUES} per key")
        return Axis(key, values=tuple(value(v) for v in items))
    low, high = value(match["lo"]), value(match["hi"])
    count_text, scale = match["n"], match["scale"]
    if count_text is not None and count_text.strip() == "log" and scale is None:
        count_text, scale = None, "log"
    log = _scale(scale, where)
    if log and (low <= 0 or high <= 0):
        raise ParameterError(f"{where}: a log range needs positive ends, got {low:g} and {high:g} (SI)")
    if count_text is None:
        return Axis(key, low=low, high=high, log=log)
    count = _count(count_text, where)
    if count > 1 and low == high:
        raise ParameterError(f"{where}: {count} points between equal ends; give one value or two different ends")
    return Axis(key, values=tuple(float(v) for v in _spaced(low, high, count, log)), log=log)


def _finite(value: Any, where: str) -> float:
    """A finite float, or one ParameterError naming ``where`` (a text, None, NaN or inf is no value)."""
    if isinstance(value, (bool, str, bytes)) or value is None:
        raise ParameterError(f"{where}: expected a finite number (SI), got {value!r}"[:300])
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{where}: expected a finite number (SI), got {value!r}"[:300]) from None
    if not math.isfinite(number):
        raise ParameterError(f"{where}: expected a finite number (SI), got {number}")
    return number


def _value(text: str, dimension: str, where: str) -> float:
    text = text.strip()
    if not text:
        raise ParameterError(f"{where}: empty value")
    value = to_si(text, dimension, where)
    if not math.isfinite(value):
        raise ParameterError(f"{where}: expected finite values, got {text!r}")
    return value


def _scale(text: str | None, where: str) -> bool:
    if text is None or text.strip() in ("", "lin", "linear"):
        return False
    if text.strip() == "log":
        return True
    raise ParameterError(f"{where}: unknown spacing {text.strip()!r}; expected 'log' (or nothing for linear)")


def _count(text: str, where: str) -> int:
    try:
        count = int(text.strip())
    except ValueError:
        raise ParameterError(f"{where}: the number of points must be a whole number, got {text.strip()!r}") from None
    if count < 1:
        raise ParameterError(f"{where}: the number of points must be at least 1, got {count}")
    if count > MAX_AXIS_VALUES:
        raise ParameterError(
            f"{where}: {count} points on one key; at most {MAX_AXIS_VALUES} (the manifest lists every value);"
            " for more, sample the range with --samples N"
        )
    return count


def _spaced(low: float, high: float, count: int, log: bool) -> np.ndarray:
    if count == 1:
        return np.array([low])
    values = np.geomspace(low, high, count) if log else np.linspace(low, high, count)
    values[0], values[-1] = low, high  # the ends exactly as given
    return values


def check_design(axes: Sequence[Axis], samples: int | None) -> str:
    """The design the axes make ("grid" or "latin-hypercube"); refuses mixtures in one line."""
    if not axes:
        raise ParameterError(
            "--vary: give at least one varied key, e.g. --vary 'pulling_velocity=5 um/s..5 mm/s:20:log'"
        )
    seen: set[str] = set()
    for a in axes:
        if a.key in seen:
            raise ParameterError(f"--vary: {a.key!r} is varied twice; give each key once")
        seen.add(a.key)
    if samples is None:
        ranges = [a.key for a in axes if a.is_range]
        if ranges:
            raise ParameterError(
                f"--vary {ranges[0]}: a range without a number of points needs --samples N (Latin hypercube);"
                " for a grid write LO..HI:N"
            )
        return "grid"
    if samples < 1 or samples > MAX_SAMPLES:
        raise ParameterError(f"--samples: expected a number of points from 1 to {MAX_SAMPLES}, got {samples}")
    lists = [a.key for a in axes if not a.is_range]
    if lists:
        raise ParameterError(
            f"--vary {lists[0]}: with --samples every varied key must be a range LO..HI[:log], not a list or grid"
        )
    return "latin-hypercube"
