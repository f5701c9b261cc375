"""``--params FILE`` of the rate-and-state commands and of ``run --model rsf``: a ``.params.json`` written beside
a trace or a fit, or a ``.toml`` file (read as the bond model's files are, JSON or TOML); every problem with the
file is one line."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import DataError
from ..fileio import protect_inputs, read_input_text
from ..units import shorten

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
    """The whole top-level table of a ``--params`` file, JSON or TOML (the one reader,
    :func:`stickslip.parameters.parse_parameter_text`); every problem with the file is one DataError line."""
    from ..parameters import parse_parameter_text

    path = Path(path)
    text = _params_text(path)
    protect_inputs([path])  # `rsf simulate --params run.params.json -o run.csv` must not rewrite it
    return parse_parameter_text(text, path, f"--params {path}", DataError)


def run_history(path: Path) -> tuple[list[dict[str, Any]] | None, float | None]:
    """The protocol and start velocity a ``.params.json`` of an earlier run or fit carries (None where absent): what
    ``rsf simulate --params`` and ``run --model rsf --params`` run when no protocol is given."""
    data = load_params_file(path)
    protocol, start = data.get("protocol"), data.get("start_velocity")
    fitted = data.get("fit")
    if protocol is None and isinstance(fitted, dict) and fitted.get("protocol") is not None:
        protocol = fitted["protocol"]  # a fit's file written before the history was put beside its parameters
    if protocol is not None:
        rows = protocol if isinstance(protocol, list) else None
        if rows is None or not all(isinstance(r, dict) and {"velocity", "duration"} <= set(r) for r in rows):
            raise DataError(
                f'--params {path}: \'protocol\' must be a list of {{"velocity": ..., "duration": ...}} segments'
                f" (SI), got {shorten(protocol)}"
            )
    if start is not None and (isinstance(start, bool) or not isinstance(start, (int, float))):
        raise DataError(f"--params {path}: 'start_velocity' must be a number in m/s, got {shorten(start)}")
    return protocol or None, start


def history_protocol(path: Path | None) -> tuple[Any, float | None]:
    """(Protocol, start velocity) of the history a ``.params.json`` carries (:func:`run_history`); (None, None) for
    no file, another kind of file, or one without a history.  The fallback protocol of ``rsf simulate --params`` and
    ``run --model rsf --params``."""
    if path is None or Path(path).suffix.lower() != ".json":
        return None, None
    rows, start = run_history(Path(path))
    if not rows:
        return None, start
    from ..protocols import segments

    return segments([(row["velocity"], row["duration"]) for row in rows]), start


def _params_text(path: Path) -> str:
    return read_input_text(path, f"--params {path}", MAX_PARAMS_BYTES)


__all__ = ["MAX_PARAMS_BYTES", "history_protocol", "load_params_file", "load_params_mapping", "run_history"]
