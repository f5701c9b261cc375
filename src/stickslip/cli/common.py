"""Shared pieces of the command line: --params/--set, unit-aware options, input files, output.

On the command line a dimensional value needs its unit: ``--v0 "50 um/s"``,
``--set bonds.bond_time="224 us"``.  A bare non-zero number (``--v0 50``) is
refused with a line that shows how to write it, because nobody means 50 m/s;
zero needs no unit, and dimensionless keys (``bonds.breakage_weight``) take
bare numbers.  TOML files and the Python API keep reading bare numbers as SI.

Every file a command writes goes through :mod:`stickslip.fileio` (atomic),
and every input file is checked by :class:`InputFile` (a regular file of
bounded size: a FIFO or /dev/zero is refused instead of read for ever).
"""

from __future__ import annotations

import errno
import io
import math
import os
import stat
import sys
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import click

from ..columns import JSON_DIGITS as JSON_DIGITS  # re-exported: the JSON helpers live in stickslip.columns
from ..columns import json_safe as json_safe
from ..columns import json_text
from ..errors import ParameterError, StickslipError
from ..fileio import atomic_path, atomic_write_text, is_stdout, protect_inputs, refuse_input_as_output
from ..parameters import Parameters, load_parameters, override_dimension
from ..units import bare_number, require_unit, shorten, to_si

#: Largest data file (CSV) a command reads: a 10^7-sample record is about 0.4 GB.
MAX_INPUT_BYTES = 2_000_000_000


def stacked(options: Sequence[Callable[[Any], Any]], func: Callable[..., Any]) -> Callable[..., Any]:
    """``func`` with click ``options`` applied, the first listed shown first in ``--help``."""
    for option in reversed(options):
        func = option(func)
    return func


def params_options(func: Callable[..., Any]) -> Callable[..., Any]:
    """Add ``--params NAME|FILE`` and repeatable ``--set section.key=VALUE``."""
    options = [
        click.option("--params", "params_name", default="gelatin-glass", show_default=True, metavar="NAME|FILE",
                     help="Built-in parameter set or TOML parameter file."),
        click.option("--set", "overrides", multiple=True, metavar="SECTION.KEY=VALUE",
                     help="Override one parameter, with its unit, e.g. bonds.bond_time='224 us'; repeatable."),
    ]  # fmt: skip
    return stacked(options, func)


def resolve_params(params_name: str, overrides: Sequence[str]) -> Parameters:
    """Parameters from ``--params`` and ``--set`` values."""
    mapping = set_values(overrides, override_dimension, typical_of=typical_value, form="SECTION.KEY=VALUE")
    protect_inputs([params_name])  # a TOML file is an input: no output of this command may replace it
    return load_parameters(params_name, overrides=mapping)


#: How ``--set`` is written, in its messages.
SET_EXAMPLE = "--set 'bonds.bond_time=224 us'"


def key_value(item: str, flag: str = "--set", form: str = "KEY=VALUE", example: str = SET_EXAMPLE) -> tuple[str, str]:
    """One ``FLAG KEY=VALUE`` text as (key, value), both stripped; one line naming the item when it is no pair."""
    key, sep, value = item.partition("=")
    key, value = key.strip(), value.strip()
    if not sep or not key:
        raise ParameterError(f"{flag} {shorten(item)}: expected {form}, e.g. {example}")
    return key, value


def set_values(
    items: Sequence[str],
    dimension_of: Callable[[str], str | None] = lambda key: None,
    *,
    typical_of: Callable[[str], float | None] | None = None,
    form: str = "KEY=VALUE",
) -> dict[str, str]:
    """Repeated ``--set KEY=VALUE`` as {key: text}, the one parser of every command.

    ``dimension_of(key)`` names a key's dimension (None: not known here, the model reads the value); a dimensional
    value then needs its unit, as everywhere on the command line, and ``typical_of(key)`` sizes the unit suggested.
    """
    mapping: dict[str, str] = {}
    for item in items:
        key, value = key_value(item, "--set", form)
        if key in mapping:  # which one was meant is not ours to guess (a protocol file's repeated column neither)
            raise ParameterError(f"--set {key}: given twice ({mapping[key]!r}, then {value!r}); give it once")
        check_unit(key, value, dimension_of(key), typical_of)
        mapping[key] = value
    return mapping


def check_unit(
    key: str, value: str, dimension: str | None, typical_of: Callable[[str], float | None] | None = None
) -> None:
    """Refuse ``--set KEY=VALUE`` with a bare number for a dimensional key (None or dimensionless: any value)."""
    if dimension is None or dimension == "dimensionless" or bare_number(value) is None:
        return
    require_unit(value, dimension, f"--set {key}=", None if typical_of is None else typical_of(key))


#: output options that name a figure (their suffix must be a format matplotlib writes)
FIGURE_OPTIONS = frozenset({"--plot", "--corner"})


def refuse_overwriting_inputs(
    inputs: Sequence[Path | str | None],
    outputs: Sequence[tuple[str, Path | None]],
    params_name: str | None = None,
    printed: str | None = None,
) -> None:
    """Refuse (DataError, one line) any output that names an input: a data file, or the --params TOML file.

    Call it before computing anything, so the user does not wait for a refusal.
    The inputs stay protected for the rest of the command (:func:`stickslip.fileio.protect_inputs`):
    a side file written later cannot replace them either.  An output ``-`` is standard output.
    ``printed`` names the data the command prints on standard output when ``-o`` is not given (``"--format csv
    (no -o)"``), if any: an output ``-`` beside it is refused too (:func:`refuse_printed_beside`).
    """
    files: list[str | Path | None] = list(inputs)
    if params_name is not None:
        files.append(params_name)  # a built-in set name is no file, and is skipped
    refuse_printed_beside(printed, outputs)
    refuse_input_as_output(files, list(outputs))
    for option, path in outputs:  # an unknown figure format or a missing folder is said before anything is written
        if path is not None and str(path) != "-":
            check_output(option, Path(path), plot=option in FIGURE_OPTIONS)


def refuse_printed_beside(printed: str | None, outputs: Sequence[tuple[str, Path | str | None]]) -> None:
    """Refuse (ParameterError, one line naming both) an output on standard output (``-``, /dev/stdout) when the
    command's data go there too for want of ``-o``: ``curve --format csv --plot -`` would put the CSV and the PNG in
    one stream (the CSV was sent to stderr).  ``printed`` names those data; None when there are none: ``-o`` was
    given, or the command prints only for people (a table, a summary, its ``--json`` summary), which then goes
    to stderr (:func:`stickslip.fileio.claim_stdout`).  ``-o - --plot -`` is refused by the same rule."""
    if printed is None:
        return
    for option, path in outputs:
        if path is not None and str(path).strip() and is_stdout(path):
            raise ParameterError(
                f"{printed} and {option} {path}: both write standard output; give {option} a file name"
            )


def typical_value(key: str) -> float | None:
    """The value (SI) of a parameter key in the built-in set, the yardstick for a bare number's unit."""
    from ..parameters import load_parameters

    try:
        block = load_parameters("gelatin-glass").block
        stiffness = {"block.stiffness": block.stiffness, "block.effective_stiffness": block.effective_stiffness}
        return stiffness.get(key, load_parameters("gelatin-glass").as_dict().get(key))
    except ParameterError:  # pragma: no cover - the built-in set always loads
        return None


def quantity(text: str | float, dimension: str, name: str) -> float:
    """An option value with its unit, as an SI float; must be finite.

    A string that is a bare non-zero number is refused (see the module note);
    a float passed by code (a default) is SI.
    """
    if isinstance(text, str):
        require_unit(text, dimension, f"{name} ")
    value = to_si(text, dimension, name)
    if not math.isfinite(value):
        raise ParameterError(f"{name}: expected a finite value, got {shorten(text)}")
    if 0 < abs(value) < sys.float_info.min:  # a denormal: no physical value, and any product with it loses its digits
        raise ParameterError(
            f"{name} {shorten(text)}: {value:g} (SI) is below the smallest normal float, 2.2e-308;"
            " expected a physical value"
        )
    return value


def positive(text: str | float, dimension: str, name: str, allow_zero: bool = False) -> float:
    """Like :func:`quantity`, and > 0 (or >= 0 with ``allow_zero``)."""
    value = quantity(text, dimension, name)
    if value < 0 or (value == 0 and not allow_zero):
        expected = "a value >= 0" if allow_zero else "a positive value"
        raise ParameterError(f"{name}: expected {expected}, got {shorten(text)}")
    return value


def emit_json(obj: Any, output: Path | None = None) -> None:
    """Write JSON (SI units, named in a top-level ``units`` map) to stdout or a file."""
    text = json_text(obj)
    if output is None:
        click.echo(text)
    else:
        write_text(output, text + "\n")


def write_text(path: Path, text: str) -> None:
    """Write ``text`` atomically (the old file stays whole until the new one is complete)."""
    try:
        atomic_write_text(path, text)
    except OSError as exc:
        raise write_failed(path, exc) from None


def write_failed(path: Path | str, exc: OSError) -> click.ClickException:
    """One line for an output that could not be written: the file, and what failed (a full device while writing,
    a missing folder, a refusal of the system), never click's "Could not open file" for a failed write."""
    shown = shorten(str(path))
    if exc.errno == errno.ENOSPC:
        return click.ClickException(f"{shown}: no space left on the device while writing it")
    if exc.errno == errno.ENOENT:
        folder = Path(os.path.realpath(path)).parent
        return click.ClickException(f"{shown}: cannot be written: the folder {shorten(str(folder))} does not exist")
    return click.ClickException(f"{shown}: cannot be written ({exc.strerror or exc})")


def save_figure(fig: Any, path: Path) -> None:
    """Save a matplotlib figure atomically, in the format its suffix names; I/O problems are one line."""
    from ..plots.export import file_tick_labels

    path = Path(path)
    fmt = path.suffix[1:].lower() or "png"
    try:
        with atomic_path(path, suffix=f".{fmt}") as temp, file_tick_labels(fig):  # log labels that never crowd
            fig.savefig(temp, format=fmt, dpi=120, bbox_inches="tight")
    except StickslipError:
        raise
    except (OSError, ValueError) as exc:
        if isinstance(exc, OSError):
            raise write_failed(path, exc) from None
        raise click.ClickException(f"{shorten(str(path))}: cannot be written ({exc})") from None


class InputFile(click.ParamType):
    """A file argument that must be a regular, readable file of at most :data:`MAX_INPUT_BYTES`.

    Checked before reading, so a FIFO (which would block) or a device such as
    /dev/zero (which never ends) is refused in one line.
    """

    name = "file"

    def __init__(self, max_bytes: int = MAX_INPUT_BYTES) -> None:
        self.max_bytes = max_bytes

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Path:
        path = Path(value)
        shown = shorten(str(value), 240)
        try:
            info = path.stat()
        except FileNotFoundError:
            self.fail(f"{shown}: file not found", param, ctx)
        except (OSError, ValueError) as exc:
            self.fail(f"{shown}: cannot be read ({getattr(exc, 'strerror', None) or exc})", param, ctx)
        if stat.S_ISDIR(info.st_mode):
            self.fail(f"{shown} is a folder, not a file", param, ctx)
        if not stat.S_ISREG(info.st_mode):
            self.fail(f"{shown} is not a regular file (save a pipe or device to a file first)", param, ctx)
        if info.st_size > self.max_bytes:
            self.fail(f"{shown} is {info.st_size} bytes; at most {self.max_bytes} bytes are read", param, ctx)
        protect_inputs([path])
        return path


class FilePath(click.Path):
    """A file's name on the command line, as a Path; one that ends with a slash names a folder, and is refused
    (``-o out/`` wrote a file named ``out``: Path drops the slash).  ``FILE_PATH`` is every command's."""

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        text = value if isinstance(value, str) else None
        if text is not None and len(text) > 1 and text.endswith(("/", os.sep)):
            self.fail(f"{text!r} ends with '/', so it names a folder; expected a file name", param, ctx)
        return super().convert(value, param, ctx)


#: the type of every file option and argument: a Path, never a folder
FILE_PATH = FilePath(dir_okay=False, path_type=Path)


def check_output(option: str, path: Path | None, plot: bool = False) -> None:
    """Refuse, before computing, an output that cannot be written: no name, no such folder, an unknown format."""
    if path is None:
        return
    text = str(path)
    if not text.strip() or text == ".":
        raise ParameterError(f"{option}: expected a file name, got an empty one")
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise ParameterError(f"{option} {shorten(text)}: the folder {shorten(str(folder))} does not exist")
    if path.is_symlink() and not path.exists():  # a dangling link: the file is made where it points
        target = Path(os.path.realpath(path))
        if not target.parent.is_dir():
            raise ParameterError(
                f"{option} {shorten(text)}: a link into the folder {shorten(str(target.parent))}, which does not exist"
            )
    try:
        info = path.stat()
    except OSError:
        info = None
    if info is not None and stat.S_ISDIR(info.st_mode):
        raise ParameterError(f"{option} {shorten(text)}: that is a folder, not a file")
    if info is None or stat.S_ISREG(info.st_mode):  # written beside, then renamed: the folder must take a file
        try:
            with tempfile.TemporaryFile(dir=folder):
                pass
        except OSError as exc:
            reason = exc.strerror or str(exc)
            raise ParameterError(
                f"{option} {shorten(text)}: cannot write in {shorten(str(folder))} ({reason})"
            ) from None
    if plot:
        from matplotlib.figure import Figure

        formats = Figure().canvas.get_supported_filetypes()
        suffix = path.suffix[1:].lower() or "png"
        if suffix not in formats:
            raise ParameterError(
                f"{option} {shorten(text)}: unknown figure format .{suffix};"
                f" expected one of {', '.join(sorted(formats))}"
            )


def plain_text(renderables: Sequence[Any], width: int) -> str:
    """Rich renderables as plain text ``width`` wide (a table in box characters, no colour), every line stripped."""
    from rich.console import Console

    buffer = io.StringIO()
    console = Console(file=buffer, width=width, color_system=None, highlight=False, force_terminal=False)
    for item in renderables:
        console.print(item)
    return "\n".join(line.rstrip() for line in buffer.getvalue().splitlines())


def echo_err(message: str) -> None:
    click.echo(message, err=True)


def stdout_is_terminal() -> bool:
    return sys.stdout.isatty()
