"""The ``stickslip`` command: a click group whose subcommands live one module per topic.

Errors a user can cause end as one line on stderr and exit status 2; no
traceback and no raw numpy/scipy warning ever reaches the user (warnings are
collected and summarised in one line).  ``stickslip`` alone prints the help.

Start-up time matters (``stickslip critical`` should answer in well under
half a second): the command modules import only click, numpy and the light
parts of the package at module level; pint, pandas, matplotlib, scipy,
lmfit and rich are imported inside the functions that use them.
"""

from __future__ import annotations

import math
import os
import re
import signal
import sys
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from importlib import import_module
from typing import TYPE_CHECKING, Any

import click

from .. import __version__
from ..errors import StickslipError
from ..numerics.numba_start import skip_blas_probe

if TYPE_CHECKING:  # loaded by name (COMMAND_MODULES); named here for the type checker and the import graph
    from . import (  # noqa: F401
        analyze_cmd,
        compare_cmd,
        cycle_cmd,
        fit_cmd,
        params_cmd,
        reproduce_cmd,
        rsf_cmd,
        run_cmd,
        stability_cmd,
        steady_cmd,
        sweep_cmd,
        transient_cmd,
    )

#: Longest error line printed (a message quoting a huge value is cut).
MAX_MESSAGE_LENGTH = 600


#: Each command's module (it registers the commands it defines): a command's module is imported only when that
#: command runs, or when the help lists them all, so that ``stickslip transient`` does not load ``analyze``'s
#: tables, ``rsf``'s options and the rest (issue 31: ~60 ms of its start-up).
COMMAND_MODULES = {
    "params": "params_cmd",
    "curve": "steady_cmd",
    "critical": "steady_cmd",
    "simulate": "cycle_cmd",
    "stick": "cycle_cmd",
    "transient": "transient_cmd",
    "fit": "fit_cmd",
    "analyze": "analyze_cmd",
    "reproduce": "reproduce_cmd",
    "run": "run_cmd",
    "rsf": "rsf_cmd",
    "compare": "compare_cmd",
    "sweep": "sweep_cmd",
    "stability": "stability_cmd",
}


class _CommandTable(dict[str, click.Command]):
    """The group's ``commands``, filled on demand: looking up a name imports the module of that command; looking at
    them all (iterating, ``items()``, ``len()``: the help, click's "did you mean") imports every one."""

    def __init__(self, group: click.Group) -> None:
        super().__init__()
        self._group = group

    def _load(self, names: Any) -> None:
        missing = [n for n in names if isinstance(n, str) and n in COMMAND_MODULES and not dict.__contains__(self, n)]
        for module in dict.fromkeys(COMMAND_MODULES[name] for name in missing):
            import_module(f"{__package__}.{module}").register(self._group)

    def get(self, name: str, default: Any = None) -> Any:
        self._load([name])
        return super().get(name, default)

    def __getitem__(self, name: str) -> click.Command:
        self._load([name])
        return super().__getitem__(name)

    def __contains__(self, name: object) -> bool:
        self._load([name])
        return super().__contains__(name)

    def __iter__(self) -> Iterator[str]:
        self._load(COMMAND_MODULES)
        return super().__iter__()

    def __len__(self) -> int:
        self._load(COMMAND_MODULES)
        return super().__len__()

    def __repr__(self) -> str:
        self._load(COMMAND_MODULES)
        return super().__repr__()

    def keys(self) -> Any:
        self._load(COMMAND_MODULES)
        return super().keys()

    def values(self) -> Any:
        self._load(COMMAND_MODULES)
        return super().values()

    def items(self) -> Any:
        self._load(COMMAND_MODULES)
        return super().items()

    def copy(self) -> dict[str, click.Command]:
        return dict(self.items())


class _Commands(click.Group):
    """A group whose commands are imported on first use (:data:`COMMAND_MODULES`, :class:`_CommandTable`)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        table = _CommandTable(self)
        table.update(self.commands)
        self.commands = table


@click.group(cls=_Commands, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(version=__version__, prog_name="stickslip")
def cli() -> None:
    """Friction and stick-slip of soft solids: the bond-population model of Juvekar & Singh.

    Values carry units: --v0 "50 um/s", --set bonds.bond_time="224 us".
    """


def _one_line(text: str) -> str:
    text = " ".join(text.split())
    if len(text) > MAX_MESSAGE_LENGTH:
        text = text[: MAX_MESSAGE_LENGTH - 30] + f"… ({len(text)} characters)"
    return text


def _fail(message: str, status: int = 2) -> int:
    click.echo(_one_line(f"stickslip: error: {message}"), err=True)
    return status


def _run(argv: list[str] | None) -> int:
    """Run the command; the exit status, every error already reported in one line."""
    try:
        cli.main(args=argv, prog_name="stickslip", standalone_mode=False)
    except click.exceptions.NoArgsIsHelpError as exc:  # `stickslip` or `stickslip fit` alone: the help
        click.echo(exc.ctx.get_help())
        return 0
    except click.exceptions.Abort as exc:  # click's word for an interrupt (it turns KeyboardInterrupt into Abort)
        if isinstance(exc.__context__, Terminated):
            click.echo("stickslip: terminated", err=True)
            return 128 + signal.SIGTERM
        click.echo("stickslip: aborted", err=True)
        return 130
    except click.exceptions.Exit as exc:
        return int(exc.exit_code)
    except click.ClickException as exc:  # usage errors, bad option values, unwritable files
        return _fail(exc.format_message())
    except StickslipError as exc:
        return _fail(str(exc))
    except Terminated:
        click.echo("stickslip: terminated", err=True)
        return 128 + signal.SIGTERM
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:  # `stickslip curve --format csv | head`: the reader left
        _silence_stdout()
        return 1
    except (OverflowError, FloatingPointError):
        return _fail(
            "a number left the floating-point range (about 1e-308 to 1e308) during the computation;"
            f" check that the input values are physical{_most_extreme_input(argv)}"
        )
    except OSError as exc:  # `stickslip critical --json > /dev/full`: the output could not be written
        _silence_stdout()
        return _fail(_os_error_text(exc))
    except MemoryError:
        return _fail("out of memory: the input or the requested size is too large for this machine")
    except Exception as exc:  # a bug: still one line, but say it is ours
        return _fail(f"internal error ({type(exc).__name__}): {exc}", status=1)
    return 0


#: a number as typed: the mantissa and an optional exponent
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _most_extreme_input(argv: list[str] | None) -> str:
    """``"; the most extreme value given was --damping '1e308 Pa s/m'"``: the typed value whose number is
    farthest from 1 in orders of magnitude (10 or more), so an overflow names its likely cause; else ``""``."""
    words = list(sys.argv[1:] if argv is None else argv)
    best, where = 10.0, ""
    option = ""
    for word in words:
        if word.startswith("--") and "=" not in word[2:]:
            option = word
            continue
        name, _, value = word.partition("=") if word.startswith("--") else (option, "", word)
        for text in _NUMBER.findall(value or word):
            try:
                number = abs(float(text))
            except ValueError:  # pragma: no cover - the pattern only matches numbers
                continue
            if number == 0 or not math.isfinite(number):
                continue
            size = abs(math.log10(number))
            if size >= best:
                best, where = size, f"{name} {value or word!r}".strip()
        option = ""
    return f"; the most extreme value given was {where}" if where else ""


def _os_error_text(exc: OSError) -> str:
    """An I/O failure in words: what could not be read or written, and why (no errno numbers, no traceback)."""
    reason = exc.strerror or str(exc) or type(exc).__name__
    where = exc.filename if exc.filename is not None else "the output (standard output or a file)"
    return f"cannot read or write {where}: {reason}"


def _flush_stdout() -> int:
    """Flush standard output now, so a full disk is reported in one line instead of at interpreter exit."""
    try:
        sys.stdout.flush()
    except OSError as exc:
        _silence_stdout()
        return _fail(_os_error_text(exc))
    except ValueError:  # closed stdout (tests)
        pass
    return 0


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush does not fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # stdout without a file descriptor (tests)
        pass


def _notice_first_compiles() -> None:
    """On a terminal, one line before a model's kernels are compiled for this machine (the first run after an
    install waits ~45 s for the time-dependent model's; numerics/first_compile.py).  Not in a pipe or a capture:
    there, as for the progress bars, standard error carries only what the command itself reports."""
    from ..numerics.first_compile import on_first_compile
    from ..progress import on_terminal

    if on_terminal():
        on_first_compile(
            lambda what: click.echo(
                f"stickslip: compiling {what} for this machine, once after an install (up to a minute; later runs"
                " load them from numba's cache)",
                err=True,
            )
        )


def main(argv: list[str] | None = None) -> None:
    """Console entry point."""
    skip_blas_probe()  # numba's, ~0.25 s of a transient run: see numba_start
    _notice_first_compiles()
    caught: list[tuple[type[Warning], str]] = []

    def collect(message: Any, category: type[Warning], *args: Any, **kwargs: Any) -> None:
        caught.append((category, str(message)))

    shown = warnings.showwarning
    warnings.showwarning = collect  # numpy's "overflow encountered in exp" is not for the user's eyes
    try:
        with sigterm_unwinds():
            status = _run(argv)
        status = _flush_stdout() or status
    finally:
        warnings.showwarning = shown
    if status == 0 and caught:
        click.echo(_one_line(f"stickslip: warning: {_warning_summary(caught)}"), err=True)
    if status == 128 + signal.SIGTERM:
        # terminated, its temporaries removed and its one line said: end here, past the interpreter's exit
        # handlers, which wake a process pool the command has already stopped through pipes already closed and
        # printed "Exception ignored ... OSError: [Errno 9] Bad file descriptor" after that line (seen under load)
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    sys.exit(status)


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived: raised where the program stands, so that every ``finally`` runs on the way out."""


@contextmanager
def sigterm_unwinds() -> Iterator[None]:
    """Within the block SIGTERM raises :class:`Terminated` instead of ending the process where it stands.

    Killed outright, a command left its half-written temporary output behind (``.out.csv.x1y2.tmp``; the next
    writer into that folder cleans it, but a user sees it first); unwound, the atomic writers remove it and the
    command ends with status 143 and one line.  Only the main thread can set a handler, and a handler someone
    else installed (an application embedding the CLI) is left alone.
    """
    import threading

    if threading.current_thread() is not threading.main_thread() or (
        signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL
    ):
        yield
        return

    def unwind(signum: int, frame: Any) -> None:
        raise Terminated

    unwind.stickslip_unwinds = True  # type: ignore[attr-defined]  # a sweep raises it where it cannot be lost
    signal.signal(signal.SIGTERM, unwind)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _warning_summary(caught: list[tuple[type[Warning], str]]) -> str:
    numeric = [text for category, text in caught if issubclass(category, RuntimeWarning)]
    if numeric:
        return (
            f"the computation met floating-point trouble ({numeric[0]}"
            + (f", and {len(numeric) - 1} more" if len(numeric) > 1 else "")
            + "); check the numbers above"
        )
    return "; ".join(dict.fromkeys(text for _, text in caught))


if __name__ == "__main__":  # pragma: no cover
    main()
