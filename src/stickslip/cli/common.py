"""Shared pieces of the command line: --params/--set, unit-aware options, output."""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import click

from ..errors import ParameterError
from ..parameters import Parameters, load_parameters
from ..units import to_si


def params_options(func: Callable[..., Any]) -> Callable[..., Any]:
    """Add ``--params NAME|FILE`` and repeatable ``--set section.key=VALUE``."""
    func = click.option(
        "--set",
        "overrides",
        multiple=True,
        metavar="SECTION.KEY=VALUE",
        help="Override one parameter (a value with a unit, or a bare number in SI); repeatable.",
    )(func)
    func = click.option(
        "--params",
        "params_name",
        default="gelatin-glass",
        show_default=True,
        metavar="NAME|FILE",
        help="Built-in parameter set or TOML parameter file.",
    )(func)
    return func


def resolve_params(params_name: str, overrides: Sequence[str]) -> Parameters:
    """Parameters from ``--params`` and ``--set`` values."""
    mapping: dict[str, str] = {}
    for item in overrides:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ParameterError(f"--set {item!r}: expected SECTION.KEY=VALUE, e.g. bonds.bond_time='224 us'")
        mapping[key.strip()] = value.strip()
    return load_parameters(params_name, overrides=mapping)


def quantity(text: str | float, dimension: str, name: str) -> float:
    """An option value with an optional unit, as an SI float; must be finite."""
    value = to_si(text, dimension, name)
    if not math.isfinite(value):
        raise ParameterError(f"{name}: expected a finite value, got {text!r}")
    return value


def positive(text: str | float, dimension: str, name: str, allow_zero: bool = False) -> float:
    """Like :func:`quantity`, and > 0 (or >= 0 with ``allow_zero``)."""
    value = quantity(text, dimension, name)
    if value < 0 or (value == 0 and not allow_zero):
        expected = "a value >= 0" if allow_zero else "a positive value"
        raise ParameterError(f"{name}: expected {expected}, got {text!r}")
    return value


def json_safe(obj: Any) -> Any:
    """Replace non-finite floats by None and numpy types by Python ones, recursively."""
    import numpy as np

    if isinstance(obj, dict):
        return {str(k): json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [json_safe(v) for v in obj.tolist()]
    if isinstance(obj, (np.floating, float)):
        value = float(obj)
        return value if math.isfinite(value) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def emit_json(obj: Any, output: Path | None = None) -> None:
    """Write JSON (SI units) to stdout or a file."""
    text = json.dumps(json_safe(obj), indent=2)
    if output is None:
        click.echo(text)
    else:
        write_text(output, text + "\n")


def write_text(path: Path, text: str) -> None:
    try:
        Path(path).write_text(text, encoding="utf-8")
    except OSError as exc:
        raise click.FileError(str(path), hint=str(exc.strerror or exc)) from None


def save_figure(fig: Any, path: Path) -> None:
    """Save a matplotlib figure, turning I/O problems into a one-line error."""
    try:
        fig.savefig(path, dpi=120, bbox_inches="tight")
    except (OSError, ValueError) as exc:
        raise click.FileError(str(path), hint=str(exc)) from None


def echo_err(message: str) -> None:
    click.echo(message, err=True)


def stdout_is_terminal() -> bool:
    return sys.stdout.isatty()
