"""The model interface: a rig, and what every friction model provides (PyBaMM's model / experiment / solution split).

A :class:`FrictionModel` holds the equations and the solver; the *protocol*
(:mod:`stickslip.protocols`) says what the load point does; the :class:`Rig`
says how the load point is coupled to the slider (rigidly, or through a spring
of stiffness K with optional damping and mass); :meth:`FrictionModel.run`
returns one :class:`~stickslip.models.run.Run`.  A model declares what it can
do in its :class:`Capabilities` and refuses anything else in one line.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..errors import ModelError, ParameterError
from ..units import checked_value

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np

    from ..protocols import Protocol
    from .run import Run

__all__ = ["CONTROLS", "CYCLE_RESULTS", "Boundary", "Capabilities", "FrictionModel", "Rig", "checked_dimensions"]

#: The results of a sweep row every cycle model reports (SI), beside the inputs, status, message and wall time.
CYCLE_RESULTS: Mapping[str, str] = {
    "regime": "str",
    "period": "float",
    "stick_time": "float",
    "peak_stress": "float",
    "jump_velocity": "float",
    "mean_stress": "float",
    "cycles": "int",
}
#: "velocity": the protocol drives the slider itself (a rigid rig); "spring": it drives the load point of a spring.
CONTROLS = ("velocity", "spring")


def _optional_positive(name: str, value: Any, dimension: str, strict: bool) -> float | None:
    """The rig's ``name``: None, or a number in SI or a value with its unit of ``dimension``, checked >= 0 (> 0
    with ``strict``)."""
    return None if value is None else checked_value(f"rig {name}", value, dimension, strict=strict)


@dataclass(frozen=True)
class Rig:
    """How the protocol reaches the slider (SI; per unit contact area).

    ``control="velocity"``: the protocol is the slider's own velocity.  ``control="spring"``: the protocol moves
    the load point of a spring of ``stiffness`` K (Pa/m); ``stiffness=None`` takes the model's own (the bond
    model's Eq 17 block, rate-and-state's ``k``).  ``damping`` eta (Pa s/m) and ``mass`` (kg/m^2) are optional
    and only for models whose capabilities include them.  Each is a number in SI or a value with its unit
    (``Rig(stiffness="300 kPa/m", mass="10 kg/m^2")``); the rig holds SI floats.
    """

    control: str = "spring"
    stiffness: float | None = None
    damping: float | None = None
    mass: float | None = None

    def __post_init__(self) -> None:
        if self.control not in CONTROLS:
            raise ParameterError(f"rig control: expected one of {', '.join(CONTROLS)}, got {self.control!r}")
        stiffness = _optional_positive("stiffness", self.stiffness, "stress_per_length", strict=True)
        object.__setattr__(self, "stiffness", stiffness)
        object.__setattr__(self, "damping", _optional_positive("damping", self.damping, "stress_per_velocity", False))
        object.__setattr__(self, "mass", _optional_positive("mass", self.mass, "mass_per_area", strict=False))
        if self.control == "velocity" and any(v is not None for v in (self.stiffness, self.damping, self.mass)):
            raise ParameterError(
                "rig: velocity control has no spring; give stiffness, damping or mass with control='spring'"
            )

    @property
    def has_damping(self) -> bool:
        return bool(self.damping)

    @property
    def has_mass(self) -> bool:
        return bool(self.mass)


@dataclass(frozen=True)
class Capabilities:
    """What a model can run: ``controls`` (of :data:`CONTROLS`), ``protocols`` ("constant" for one constant
    pulling velocity only, "any" for every piecewise-constant history), whether the rig may carry damping or a
    mass, and the run settings it takes beyond the protocol (e.g. ``jump_curve``)."""

    controls: tuple[str, ...] = ("spring",)
    protocols: str = "any"
    damping: bool = False
    mass: bool = False
    settings: tuple[str, ...] = ()


@dataclass(frozen=True)
class Boundary:
    """An analytic stability boundary in the plane of two keys (SI), with its legend label."""

    x: np.ndarray
    y: np.ndarray
    label: str


def checked_dimensions(model: Any) -> dict[str, str]:
    """``model.dimensions()``, each a :data:`stickslip.units.DIMENSIONS` name; a plug-in's key of another
    dimension is refused in one line naming the model, the key, the dimension and the known ones."""
    from ..units import DIMENSIONS

    dimensions = dict(model.dimensions())
    for key, dimension in dimensions.items():
        if not isinstance(dimension, str) or dimension not in DIMENSIONS:
            known = ", ".join(sorted(DIMENSIONS))
            raise ParameterError(
                f"model {getattr(model, 'name', model)!r}: key {key!r} has dimension {dimension!r},"
                f" not a known dimension; expected one of {known}"
            )
    return dimensions


class FrictionModel(ABC):
    """A friction model behind one interface; subclass it, fill the class attributes, implement the methods.

    ``name`` is what ``--model`` and :func:`stickslip.run` take (``aliases`` too); ``sweep_start`` is the
    ``start`` a sweep runs each point from (a start from which an instability can show).
    """

    name: str = ""
    aliases: tuple[str, ...] = ()
    description: str = ""
    capabilities: Capabilities = Capabilities()
    sweep_start: Any = None
    #: the dimension of a numeric ``start`` (a :data:`stickslip.units.DIMENSIONS` name, e.g. "stress" or
    #: "velocity"), so the command line reads ``--start`` in it and refuses another; None: words only
    start_dimension: str | None = None
    #: the words ``start`` may be (transient: "empty", "steady"); None: any, the model's ``run`` judges them
    start_words: tuple[str, ...] | None = None
    #: modules the model needs (an install without them refuses the model in one line, see check_available)
    requires: tuple[str, ...] = ()
    #: the columns of a sweep row (name -> "str", "float" or "int"), read off the Run (:meth:`Run.row`)
    sweep_columns: Mapping[str, str] = CYCLE_RESULTS

    @abstractmethod
    def dimensions(self) -> dict[str, str]:
        """Every parameter key the model accepts -> its dimension (a :data:`stickslip.units.DIMENSIONS` name)."""

    @abstractmethod
    def parameters(self, spec: Any = None, overrides: Mapping[str, Any] | None = None) -> Any:
        """Frozen, validated parameters from ``spec`` (a set name, a file, a parameter object or None for the
        defaults) and ``overrides`` ({key: SI number or text with unit}); an unknown key is a ParameterError."""

    @abstractmethod
    def run(
        self, params: Any, protocol: Protocol, rig: Rig | None = None, *, start: Any = None, **settings: Any
    ) -> Run:
        """Run ``protocol`` through ``rig`` from ``start``; returns the one result type."""

    def values(self, params: Any) -> dict[str, float]:
        """The SI value of every key of :meth:`dimensions` in ``params`` (what a sweep keeps fixed)."""
        if hasattr(params, "as_dict"):
            return {k: float(v) for k, v in params.as_dict().items()}
        out = {}
        for key in self.dimensions():
            value = params.get(key) if isinstance(params, Mapping) else getattr(params, key, None)
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                out[key] = float(value)
        return out

    def spring(self, params: Any, rig: Rig) -> tuple[float, str, str] | None:
        """The spring a run of ``params`` through ``rig`` pulls through: (stiffness in SI, its unit, where it came
        from: "rig" or "parameters"); None under velocity control, or where the model does not say (a model whose
        own spring the rig leaves to it reports None unless it overrides this)."""
        if rig.control != "spring" or rig.stiffness is None:
            return None
        return rig.stiffness, "Pa/m", "rig"

    def label(self, params: Any) -> str:
        """A short name of the parameter set (shown in sweep tables and figures)."""
        return str(getattr(params, "name", "") or self.name)

    def stability_boundary(self, params: Any, x: str, y: str, frame: Any = None) -> list[Boundary]:
        """Analytic boundaries between steady sliding and stick-slip in the (x, y) plane; none by default."""
        return []

    def describe_start(self, start: Any, protocol: Protocol, settings: Mapping[str, Any] | None = None) -> str:
        """In words, where a run of ``protocol`` from ``start`` begins (tables that set models side by side
        say it, since models that start differently do not settle alike)."""
        if start is None:
            return "the model's own start"
        from ..units import DIMENSIONS

        unit = DIMENSIONS.get(self.start_dimension or "", ("", ""))[1]
        if unit and isinstance(start, (int, float)) and not isinstance(start, bool):
            return f"start {float(start):.6g} {unit}"  # a number is SI in the model's start_dimension
        return f"start {start!r}"

    # ------------------------------------------------------------------ checks every implementation shares
    def check_available(self) -> None:
        """Refuse, in one line, a model whose modules this installation does not have."""
        from importlib import import_module

        for module in self.requires:
            try:
                import_module(module)
            except ModuleNotFoundError as exc:
                if exc.name is not None and module.startswith(exc.name):
                    raise ParameterError(
                        f"model {self.name}: this version of stickslip has no {module} module; use another model"
                    ) from None
                raise

    def check(self, protocol: Protocol, rig: Rig | None, settings: Mapping[str, Any] | None = None) -> Rig:
        """The rig (default: a spring of the model's own stiffness), after refusing what the model cannot do."""
        from ..protocols import Protocol

        if not isinstance(protocol, Protocol):
            raise ParameterError(f"protocol: expected a stickslip.protocols.Protocol, got {type(protocol).__name__}")
        rig = Rig() if rig is None else rig
        if not isinstance(rig, Rig):
            raise ParameterError(f"rig: expected a stickslip.Rig, got {type(rig).__name__}")
        caps = self.capabilities
        if rig.control not in caps.controls:
            raise ModelError(f"model {self.name}: no {rig.control} control; it runs under {' or '.join(caps.controls)}")
        if caps.protocols == "constant" and len(protocol.segments) != 1:
            raise ModelError(
                f"model {self.name}: one constant pulling velocity only, got a protocol of {len(protocol.segments)}"
                " segments (use the transient or rsf model for velocity histories)"
            )
        if rig.has_damping and not caps.damping:
            raise ModelError(f"model {self.name}: the rig's damping is not part of this model; leave it out")
        if rig.has_mass and not caps.mass:
            raise ModelError(f"model {self.name}: the rig's mass (inertia) is not part of this model; leave it out")
        unknown = sorted(set(settings or {}) - set(caps.settings))
        if unknown:
            takes = ", ".join(caps.settings) or "none"
            raise ParameterError(f"model {self.name}: unknown setting {unknown[0]!r}; it takes: {takes}")
        return rig

    def __repr__(self) -> str:
        return f"<friction model {self.name!r}: {self.description}>"
