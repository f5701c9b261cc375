"""Progress of long work: a rich bar on a terminal, nothing anywhere else.

Anything that may take more than about 2 s reports through :func:`progress`::

    with progress("sampling", total=2000, unit="steps") as bar:
        for ...:
            bar.update(done, total=estimate, note="τ ≈ 41 steps")

The bar is drawn on standard error only when standard error is a terminal (so
pipes, files, ``--json`` runs and the test suite see nothing) and when the
caller has not switched it off (``enabled=False``).  ``enabled=True`` forces it
(rich then decides how to draw on a non-terminal).  Sweeps keep their own
display (``stickslip.sweeps.progress``), which also writes plain lines to logs.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any


class Silent:
    """Takes the same calls as the bar and shows nothing."""

    def update(self, completed: float, total: float | None = None, note: str = "") -> None:
        return None

    def advance(self, amount: float = 1.0, note: str = "") -> None:
        return None


class Bar(Silent):
    """A rich progress bar on standard error: description, bar, done/total with the unit, a note, times."""

    def __init__(self, description: str, total: float | None, unit: str) -> None:
        from rich.console import Console
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

        amount = "{task.completed:.0f}/{task.total:.0f}" + (f" {unit}" if unit else "")
        self._bar: Any = Progress(
            TextColumn("{task.description}"),
            BarColumn(),
            TextColumn(amount),
            TextColumn("{task.fields[note]}"),
            TimeElapsedColumn(),
            TimeRemainingColumn(),
            console=Console(stderr=True),
            transient=True,  # the bar goes when the work is done; the result says what happened
        )
        self._task = self._bar.add_task(description, total=total, note="")
        self._done = 0.0

    def start(self) -> None:
        self._bar.start()

    def stop(self) -> None:
        self._bar.stop()

    def update(self, completed: float, total: float | None = None, note: str = "") -> None:
        self._done = completed
        changes: dict[str, Any] = {"completed": completed, "note": note}
        if total is not None:
            changes["total"] = total
        self._bar.update(self._task, **changes)

    def advance(self, amount: float = 1.0, note: str = "") -> None:
        self.update(self._done + amount, note=note)


def on_terminal() -> bool:
    """Whether standard error is a terminal (a closed or replaced stream counts as not)."""
    try:
        return bool(sys.stderr.isatty())
    except (AttributeError, ValueError):
        return False


@contextmanager
def progress(
    description: str, total: float | None = None, unit: str = "", enabled: bool | None = None
) -> Iterator[Silent]:
    """A progress display for the work in the ``with`` block (module docstring); ``enabled=None``: on a terminal."""
    shown = on_terminal() if enabled is None else enabled
    if not shown:
        yield Silent()
        return
    bar = Bar(description, total, unit)
    bar.start()
    try:
        yield bar
    finally:
        bar.stop()
