"""The registry of friction models: built-ins, ``stickslip.models`` entry points, and ``module:attr`` paths.

A package outside stickslip makes its model available by declaring, in its ``pyproject.toml``::

    [project.entry-points."stickslip.models"]
    my-model = "my_package.friction:MODEL"

or a script calls :func:`register_model` (then ``--model my-model`` works in that process), or the command
line names it as an import path, ``--model my_package.friction:MODEL``.
"""

from __future__ import annotations

import importlib
from importlib import metadata
from typing import Any

from ..errors import ParameterError
from ..parameters import require_flag
from .base import FrictionModel

__all__ = ["ENTRY_POINT_GROUP", "available_models", "get_model", "is_plugin", "plugin_error", "register_model"]

ENTRY_POINT_GROUP = "stickslip.models"
_MODELS: dict[str, FrictionModel] = {}
_ALIASES: dict[str, str] = {}
_LOADED = {"builtins": False, "entry points": False}
_REQUIRED = ("name", "dimensions", "parameters", "run")


def register_model(model: Any, *, replace: bool = False) -> FrictionModel:
    """Make ``model`` (a :class:`FrictionModel` instance, or a class to instantiate) available by its name and
    aliases; returns it.  A name already taken by another model is refused unless ``replace=True``."""
    replace = require_flag(replace, "register_model: replace")
    model = _instance(model, "register_model")
    missing = [attr for attr in _REQUIRED if not hasattr(model, attr)]
    if missing:
        raise ParameterError(
            f"register_model: {type(model).__name__} is not a friction model (no {', '.join(missing)});"
            " subclass stickslip.models.FrictionModel"
        )
    name = model.name
    if not isinstance(name, str) or not name.strip() or ":" in name or "," in name:
        raise ParameterError(f"register_model: a model's name must be a word without ':' or ',', got {name!r}")
    _builtins()
    names = (name, *getattr(model, "aliases", ()))
    for alias in names:
        owner = _ALIASES.get(alias, alias if alias in _MODELS else None)
        if owner is not None and _MODELS[owner] is not model and not replace:
            raise ParameterError(f"register_model: the name {alias!r} is taken by model {owner!r}; pass replace=True")
    _MODELS[name] = model
    for alias in names[1:]:
        _ALIASES[alias] = name
    return model


def unregister_model(name: str) -> None:
    """Forget the model registered as ``name`` (and its aliases); a built-in model comes back on the next lookup."""
    _MODELS.pop(name, None)
    for alias in [a for a, owner in _ALIASES.items() if owner == name]:
        del _ALIASES[alias]


def get_model(name: Any) -> FrictionModel:
    """The model called ``name`` (or one of its aliases), or ``module:attr`` imported; a model is returned as is."""
    if not isinstance(name, str):
        if all(hasattr(name, attr) for attr in _REQUIRED):
            return name
        raise ParameterError(f"model: expected a name, one of {', '.join(available_models())}; got {name!r}")
    key = name.strip()
    if ":" in key:
        return _imported(key)
    _builtins()
    found = _lookup(key)
    if found is None:
        _entry_points()
        found = _lookup(key)
    if found is None:
        raise ParameterError(f"model {name!r}: expected one of {', '.join(available_models())} (or module:attr)")
    return found


def available_models() -> dict[str, FrictionModel]:
    """Every registered model by name (built-ins first, then those of installed packages and of this process)."""
    _builtins()
    _entry_points()
    return dict(_MODELS)


def _lookup(key: str) -> FrictionModel | None:
    return _MODELS.get(_ALIASES.get(key, key))


def _builtins() -> None:
    if _LOADED["builtins"]:
        return
    _LOADED["builtins"] = True
    from .quasi_static import QuasiStatic
    from .rsf import RSFModel
    from .transient import Transient

    for model in (QuasiStatic(), Transient(), RSFModel()):
        register_model(model)


def _entry_points() -> None:
    if _LOADED["entry points"]:
        return
    _LOADED["entry points"] = True
    for entry in metadata.entry_points(group=ENTRY_POINT_GROUP):
        if _lookup(entry.name) is not None:
            continue  # a built-in or a model registered in this process wins
        try:
            model = entry.load()
        except Exception as exc:  # a broken plug-in is that plug-in's problem: say so, keep the others
            import warnings

            warnings.warn(f"stickslip: model entry point {entry.name!r} ({entry.value}) failed to load: {exc}",
                          UserWarning, stacklevel=3)  # fmt: skip
            continue
        register_model(model)


def is_plugin(model: Any) -> bool:
    """Whether ``model`` is a plug-in: its class defined outside the stickslip package."""
    module = getattr(type(model), "__module__", "") or ""
    return module != "stickslip" and not module.startswith("stickslip.")


def plugin_error(model: Any, exc: BaseException, doing: str, start: Any = None, start_option: str = "--start ") -> str:
    """A plug-in's own exception (not a stickslip error) in one line that names the model, where it came from and,
    for a word ``start`` the model declares no words for (``start_words`` None: every word goes to its ``run`` as
    given), that option: ``--start steady: model velocity-weakening (the plug-in vwdoc.VelocityWeakening) raised
    ValueError in its run: ...``.  ``doing``: "its run", "its parameters()"."""
    from ..units import DIMENSIONS, quantity_noun, shorten

    cls = type(model)
    said = " ".join(str(exc).split()) or "(no message)"
    if len(said) > 300:
        said = said[:280] + f"… ({len(said)} characters)"
    line = (
        f"model {getattr(model, 'name', '?')} (the plug-in {cls.__module__}.{cls.__qualname__}) raised"
        f" {type(exc).__name__} in {doing}: {said}"
    )
    if isinstance(start, str) and getattr(model, "start_words", None) is None:
        line = (
            f"{start_option}{shorten(start)}: {line}; the model declares no start words (start_words), so the word"
            " went to its run as given"
        )
        dimension = getattr(model, "start_dimension", None)
        if dimension in DIMENSIONS:
            line += f"; it starts from {quantity_noun(dimension)}: give one with its unit"
    return line


def _instance(target: Any, where: str) -> Any:
    """A class instantiated (no arguments), anything else as is; an abstract class or one needing arguments refused."""
    if not isinstance(target, type):
        return target
    import inspect

    if inspect.isabstract(target):
        missing = ", ".join(sorted(getattr(target, "__abstractmethods__", ())))
        raise ParameterError(
            f"{where}: {target.__name__} is an abstract class (it lacks {missing});"
            " expected a concrete friction model, e.g. a subclass of stickslip.FrictionModel that defines them"
        )
    try:
        return target()
    except TypeError as exc:
        raise ParameterError(f"{where}: {target.__name__} cannot be made without arguments ({exc})") from None


def _imported(path: str) -> FrictionModel:
    """``module:attr`` (attr may be dotted): the model there, registered under its name."""
    module_name, _, attr = path.partition(":")
    if not module_name or not attr:
        raise ParameterError(f"model {path!r}: expected an import path MODULE:ATTRIBUTE, e.g. my_models:MODEL")
    try:
        target: Any = importlib.import_module(module_name)
    except ImportError as exc:
        raise ParameterError(f"model {path!r}: cannot import {module_name!r} ({exc})") from None
    for part in attr.split("."):
        if not hasattr(target, part):
            raise ParameterError(f"model {path!r}: module {module_name!r} has no attribute {attr!r}")
        target = getattr(target, part)
    model = _instance(target, f"model {path!r}")
    if not all(hasattr(model, a) for a in _REQUIRED):
        raise ParameterError(f"model {path!r}: {attr} is not a friction model (subclass stickslip.FrictionModel)")
    _builtins()
    known = _lookup(model.name)
    if known is None or type(known) is type(model):
        return known or register_model(model)
    return model
