"""Friction models behind one interface (see docs/architecture.md and docs/models.md).

    >>> import stickslip
    >>> from stickslip import protocols
    >>> run = stickslip.run("quasi-static", None, protocols.constant(50e-6, 20.0))  # doctest: +SKIP
    >>> run.regime.kind, run.period  # doctest: +SKIP

A model is a :class:`FrictionModel` (parameters, equations, its own solver); a protocol
(:mod:`stickslip.protocols`) says what the load point does, a :class:`Rig` how it reaches the slider;
every model returns a :class:`Run`.  :func:`register_model` adds a model from outside the package.
:func:`as_run` turns an engine's own result (``stickslip.simulate``, ``run_transient``, ``rsf.simulate``) into
its :class:`Run`: the engines do not know the interface that wraps them (docs/architecture.md).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from .base import CONTROLS, Boundary, Capabilities, FrictionModel, Rig
from .registry import available_models, get_model, register_model, unregister_model
from .run import Run

__all__ = [
    "CONTROLS",
    "Boundary",
    "Capabilities",
    "FrictionModel",
    "Rig",
    "Run",
    "as_run",
    "available_models",
    "get_model",
    "register_model",
    "run",
    "unregister_model",
]


def run(
    model: str | FrictionModel,
    params: Any = None,
    protocol: Any = None,
    rig: Rig | None = None,
    *,
    start: Any = None,
    **settings: Any,
) -> Run:
    """Run ``protocol`` on ``model`` (a name, ``module:attr``, or a model) and return its :class:`Run`.

    ``params``: the model's parameter object; a set name or a file (what its ``parameters()`` takes); a mapping
    ``{key: value}`` of the model's own keys (``model.dimensions()``: ``{"a": 0.01, "b": 0.015, "dc": "10 um"}``
    for rsf, ``{"block.height": "5 mm"}`` for the bond models; numbers in SI or values with their units) over the
    model's defaults, read by the model's own reader, ``model.parameters(None, mapping)``, so an unknown key is
    refused naming that model's keys (a nested mapping, a whole set as a file holds it, is read as a file is); None
    for the model's defaults.  ``rig``: default a spring of the model's own stiffness.  ``start``: a word the model
    takes, or a number (SI) or value with its unit of the model's ``start_dimension`` (``"300 Pa"``).
    """
    from ..errors import ParameterError

    found = get_model(model)
    if protocol is None:
        raise ParameterError("protocol: expected a stickslip.protocols.Protocol, e.g. protocols.constant(50e-6, 20)")
    if isinstance(params, Mapping) and not _nested(params):
        _refuse_text_numbers(found, params)
        params = found.parameters(None, params)  # the model's keys over its defaults (its own reader and message)
    elif params is None or isinstance(params, (str, Path, Mapping)):
        params = found.parameters(params)
    start = _start(found, start)
    from .run import finished

    return finished(found.run(params, protocol, rig, start=start, **settings), protocol)


def _refuse_text_numbers(model: FrictionModel, mapping: Mapping[Any, Any]) -> None:
    """Refuse a non-zero number written as text without a unit (``{"dc": "10"}``) for a key the model gives a
    dimension, naming the key, before the model's own reader (a plug-in's may read it with ``to_si`` as SI): a number
    (not text) is SI, as everywhere in the Python API."""
    texts = {key: value for key, value in mapping.items() if isinstance(value, str)}
    if not texts:
        return
    from ..units import require_unit
    from .base import checked_dimensions

    dimensions = checked_dimensions(model)
    for key, value in texts.items():
        if key in dimensions:
            require_unit(value, dimensions[key], f"{key}=")


def _nested(mapping: Mapping[Any, Any]) -> bool:
    """Whether a mapping of parameters is a whole set as a file holds it (sections as tables, rate-and-state's list
    of states) rather than ``{key: value}`` of the model's keys."""
    return any(isinstance(value, (Mapping, list, tuple)) for value in mapping.values())


def _start(model: FrictionModel, start: Any) -> Any:
    """``start`` with a unit (``"300 Pa"``, a pint quantity) in SI of the model's ``start_dimension``; a word
    (``"steady"``), a number or None as given (the model judges them)."""
    from ..errors import ParameterError
    from ..units import example_value, is_quantity, quantity_noun, shorten, si_argument

    dimension = getattr(model, "start_dimension", None)
    words = getattr(model, "start_words", None)
    if isinstance(start, str) and start.strip().isalpha() and words is not None and start.strip() not in words:
        # a word the model does not take, named as the argument is (the engine's own name, start_stress or
        # start_velocity, is no argument of run(): round 30)
        takes = f"one of {', '.join(words)}" if words else "no word"
        value = f"{quantity_noun(dimension)}, e.g. {example_value(dimension)}, " if dimension else ""
        raise ParameterError(
            f"start: {shorten(start)} is no start of model {model.name}: it takes {takes}; expected {value}or None"
            " for its own start"
        )
    if dimension is None or not (is_quantity(start) or (isinstance(start, str) and not start.strip().isalpha())):
        return start
    return si_argument(start, dimension, "start")


def as_run(result: Any, protocol: Any = None) -> Run:
    """An engine's own result as the interface's :class:`Run`, as its model's ``run`` would return it.

    ``result``: a :class:`stickslip.Simulation` (``stickslip.simulate``), a
    :class:`stickslip.transient.TransientResult` (``run_transient``; ``protocol``, the one it ran, judges its
    last segment) or a :class:`stickslip.rsf.RSFRun` (``rsf.simulate``); a :class:`Run` is returned as it is.
    """
    from ..errors import ParameterError
    from ..quasistatic.cycle import Simulation
    from ..rsf.results import RSFRun
    from ..transient.result import TransientResult

    if isinstance(result, Run):
        return result
    if isinstance(result, Simulation):
        from .quasi_static import simulation_run

        return simulation_run(result)
    if isinstance(result, TransientResult):
        from .transient import transient_run

        return transient_run(result, protocol)
    if isinstance(result, RSFRun):
        from .rsf import rsf_run

        return rsf_run(result)
    raise ParameterError(
        f"result: expected a Simulation, TransientResult or RSFRun (an engine's result), got {type(result).__name__}"
    )
