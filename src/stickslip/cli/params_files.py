"""``--params FILE`` of the rate-and-state commands and of ``run --model rsf``: a ``.params.json`` written beside
a trace or a fit, or a ``.toml`` file; every problem with the file is one line."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from ..errors import DataError
from ..fileio import protect_inputs, read_input_text

#: Largest --params file read (one written by a run or fit is a few kB).
MAX_PARAMS_BYTES = 1_000_000


def load_params_mapping(path: Path) -> dict[str, Any]:
    """The parameter mapping of a ``.params.json`` (trace or fit) or a ``.toml`` file."""
    data = load_params_file(path)
    mapping = data.get("parameters", data)
    if not isinstance(mapping, dict):
        raise DataError(f"--params {path}: 'parameters' must be a table of values, got {type(mapping).__name__}")
    if not mapping:  # an empty file read as the defaults hid a file that was never written (the bond model refuses)
        raise DataError(
            f"--params {path}: holds no parameters (empty); give at least one, e.g. a = 0.005, or leave --params out"
            " for the defaults"
        )
    return dict(mapping)


def load_params_file(path: Path) -> dict[str, Any]:
    """The whole top-level table of a ``--params`` file; every problem with the file is one DataError line."""
    path = Path(path)
    text = _params_text(path)
    protect_inputs([path])  # `rsf simulate --params run.params.json -o run.csv` must not rewrite it
    try:
        if path.suffix.lower() == ".toml":
            try:
                import tomllib
            except ModuleNotFoundError:  # pragma: no cover - Python 3.10
                import tomli as tomllib  # type: ignore[no-redef]
            data = tomllib.loads(text)
        else:
            data = json.loads(text)
    except ValueError as exc:  # JSONDecodeError and TOMLDecodeError are ValueErrors
        kind = "TOML" if path.suffix.lower() == ".toml" else "JSON"
        raise DataError(f"--params {path}: malformed {kind} ({(str(exc).splitlines() or [''])[0]})") from None
    except RecursionError:  # "[[[[..." a hundred thousand deep: the parsers recurse
        raise DataError(f"--params {path}: nested too deeply to be a parameter file") from None
    if not isinstance(data, dict):
        raise DataError(f"--params {path}: expected a table of parameters (a JSON object), got {type(data).__name__}")
    return data


def _params_text(path: Path) -> str:
    return read_input_text(path, f"--params {path}", MAX_PARAMS_BYTES)


__all__ = ["MAX_PARAMS_BYTES", "load_params_file", "load_params_mapping"]
