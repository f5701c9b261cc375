"""A sweep point through the model interface: ``model.parameters(...)`` + ``model.run(...)`` -> Run -> one row.

Any registered model sweeps (:mod:`stickslip.models.registry`: the built-ins, installed plug-ins, models
registered in the process, ``module:attr``), with nothing here that knows one model from another: the keys are
the protocol's pulling velocity and the model's :meth:`~stickslip.models.FrictionModel.dimensions`; a point
runs ``constant(V0, duration)`` through the model's own spring from its ``sweep_start``; the row's columns are
the model's ``sweep_columns`` read off the Run (:meth:`stickslip.models.Run.row`); the phase diagram's
boundaries are the model's ``stability_boundary``.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from typing import Any

from ..errors import ParameterError, StickslipError
from ..models import FrictionModel, Rig, available_models
from ..models import get_model as find_model
from ..models.base import Boundary
from ..models.rsf import ALIASES as RSF_ALIASES

__all__ = [
    "ALIASES",
    "MODELS",
    "PROTOCOL_KEYS",
    "Boundary",
    "SweepModel",
    "get_model",
    "key_units",
    "result_columns",
    "run_point",
]

#: The keys a sweep adds to the model's own: the protocol's constant pulling velocity.
PROTOCOL_KEYS = {"pulling_velocity": "velocity"}
#: Other spellings accepted for keys (the issue's symbols): rate-and-state's own, and V0 for the protocol's.
ALIASES = {**RSF_ALIASES, "V0": "pulling_velocity"}
NAN = float("nan")


class SweepModel:
    """A registered model seen by a sweep: its keys, its fixed values, one point's row.  Holds no physics."""

    def __init__(self, model: FrictionModel) -> None:
        self.model = model
        self.name = model.name
        self.results: Mapping[str, str] = dict(model.sweep_columns)

    def dimensions(self) -> dict[str, str]:
        return {**PROTOCOL_KEYS, **self.model.dimensions()}

    def key_units(self) -> dict[str, str | None]:
        """The SI unit of each of the model's keys, from its own ``dimensions()`` (a plug-in's keys are unknown to
        the package's column registry, so their units must come from the model)."""
        from ..columns import DIMENSIONLESS
        from ..models.base import checked_dimensions
        from ..units import DIMENSIONS

        dimensions = {**PROTOCOL_KEYS, **checked_dimensions(self.model)}
        return {key: DIMENSIONS[dimension][1] or DIMENSIONLESS for key, dimension in dimensions.items()}

    def check_available(self) -> None:
        self.model.check_available()

    def takes(self, setting: str) -> bool:
        return setting in self.model.capabilities.settings

    def fixed_values(self, params: Any, overrides: Mapping[str, Any]) -> tuple[dict[str, float], str]:
        """(SI values of every key not varied, the parameter set's label) from ``--params`` and ``--set``.

        Keys the model's parameter values do not hold (e.g. the bond model's ``block.stiffness``, which sets
        the height) are kept as given, in SI, and applied again at each point, after the varied keys.
        """
        from ..units import override_to_si

        dimensions = self.dimensions()
        given = {ALIASES.get(k, k) if ALIASES.get(k, k) in dimensions else k: v for k, v in overrides.items()}
        base = self.model.parameters(params)
        held = set(self.model.values(base))
        apart = {k: v for k, v in given.items() if k in dimensions and k not in held}
        inside = {k: v for k, v in given.items() if k not in apart}
        built = self.model.parameters(base, inside) if inside else base
        fixed = self.model.values(built)
        for key, raw in apart.items():
            fixed[key] = override_to_si(raw, dimensions[key], key)  # "400" refused: a unit, or a number (SI)
        return fixed, self.model.label(built)

    def check_keys(self, varied: tuple[str, ...], fixed: Mapping[str, float]) -> None:
        check = getattr(self.model, "check_keys", None)
        if check is not None:
            check(varied, fixed)

    def parameters(self, values: Mapping[str, float]) -> tuple[Any, float]:
        """(the model's parameters, the pulling velocity) of one point (validated)."""
        params, velocity, _start = self.point(values, 1.0)
        return params, velocity

    def point(self, values: Mapping[str, float], duration: float) -> tuple[Any, float, Any]:
        """(the model's parameters, the pulling velocity, the start) of one point of ``duration`` (validated)."""
        if "pulling_velocity" not in values:
            raise ParameterError("pulling_velocity: give --v0 V or --vary 'pulling_velocity=...'")
        velocity = values["pulling_velocity"]
        if not velocity >= 0:
            raise ParameterError(f"pulling_velocity: expected a value >= 0 m/s, got {velocity:g}")
        start = self.start(velocity, duration)  # a velocity the model cannot start from is refused with the others
        return self.model.parameters(None, {k: v for k, v in values.items() if k not in PROTOCOL_KEYS}), velocity, start

    def start(self, velocity: float, duration: float) -> Any:
        """The model's ``sweep_start`` for a run at ``velocity``."""
        from ..protocols import constant

        start = self.model.sweep_start
        return start(constant(velocity, duration)) if callable(start) else start

    def run(self, values: Mapping[str, float], settings: Mapping[str, Any]) -> dict[str, Any]:
        from ..errors import RunFailed
        from ..models import as_run
        from ..models.run import finished
        from ..protocols import constant

        params, velocity, start = self.point(values, settings["duration"])
        protocol = constant(velocity, settings["duration"])
        taken = {k: v for k, v in settings.items() if self.takes(k)}
        try:
            run = finished(self.model.run(params, protocol, self.rig(), start=start, **taken), protocol)
        except RunFailed as exc:  # it ran and could not go on: a "failed" row of what it computed, where it says
            if getattr(exc, "partial", None) is None:
                raise
            run = as_run(exc.partial, protocol)
        return run.row(self.results)

    @property
    def estimates_cost(self) -> bool:
        """Whether the model estimates a run's CPU seconds before running it (an ``estimate_seconds`` method)."""
        return callable(getattr(self.model, "estimate_seconds", None))

    def cost(self, values: Mapping[str, float], settings: Mapping[str, Any]) -> float | None:
        """The model's estimate of one point's CPU seconds, for the schedule; None when it gives none or the point
        cannot be estimated (its run will say why it fails)."""
        from ..protocols import constant

        if not self.estimates_cost:
            return None
        try:
            params, velocity, start = self.point(values, settings["duration"])
            taken = {k: v for k, v in settings.items() if self.takes(k)}
            protocol = constant(velocity, settings["duration"])
            seconds = float(self.model.estimate_seconds(params, protocol, self.rig(), start=start, **taken))
        except Exception:  # an estimate only orders the points: a point refused here fails, with its reason, in run
            return None
        return seconds if math.isfinite(seconds) and seconds >= 0 else None

    def rig(self) -> Rig:
        """The model's own spring; a model that runs only under velocity control is driven directly."""
        return Rig() if "spring" in self.model.capabilities.controls else Rig(control="velocity")

    def boundaries(self, spec: Any, frame: Any, x: str, y: str) -> list[Boundary]:
        """The model's analytic stability boundaries in the (x, y) plane; none if it has none."""
        return list(self.model.stability_boundary(dict(spec.fixed), x, y, frame))


class _Models(Mapping[str, SweepModel]):
    """Every registered model by name, as a sweep sees it (a live view of the registry)."""

    def __getitem__(self, name: str) -> SweepModel:
        return SweepModel(available_models()[name])

    def __iter__(self) -> Iterator[str]:
        return iter(available_models())

    def __len__(self) -> int:
        return len(available_models())


MODELS: Mapping[str, SweepModel] = _Models()


def get_model(name: str) -> SweepModel:
    """The model of ``--model NAME`` (or ``module:attr``), as a sweep sees it."""
    return SweepModel(find_model(name))


def key_units(model: SweepModel) -> dict[str, str | None]:
    """The units of a sweep's input columns as the model states them (see :meth:`SweepModel.key_units`)."""
    return model.key_units()


def result_columns(model: SweepModel) -> dict[str, str]:
    """Columns after the inputs: the model's results, then status, message and wall time."""
    return {**model.results, "status": "str", "message": "str", "wall_time": "float"}


def run_point(model: SweepModel, values: Mapping[str, float], settings: Mapping[str, Any]) -> dict[str, Any]:
    """One point as a row; a failure is a row with status "error" and the one-line reason, never an exception.

    A run the model could not finish (status "failed") keeps what it computed, and its message says where it
    stopped."""
    import time

    start = time.perf_counter()
    try:
        row = model.run(values, settings)
        row["status"] = row.get("status") or "ok"
    except Exception as exc:  # any failure of one point is that point's result; the sweep goes on
        row = {name: (None if kind == "str" else 0 if kind == "int" else NAN) for name, kind in model.results.items()}
        kind = "" if isinstance(exc, StickslipError) else f"{type(exc).__name__}: "
        row.update(status="error", message=(kind + str(exc)).replace("\n", " "))
    row["wall_time"] = time.perf_counter() - start
    return row
