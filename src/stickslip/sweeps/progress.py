"""Progress of a sweep: a rich bar with rate and ETA on a terminal, plain lines otherwise, or nothing."""

from __future__ import annotations

import sys
import time
from typing import Any, TextIO

#: Plain progress lines: at most one per this many seconds (and one at the end).
PLAIN_EVERY = 5.0


class Silent:
    """No output (``--quiet`` and the Python API's default)."""

    def start(self, total: int, done: int) -> None:
        self.total, self.done = total, done

    def advance(self, points: int) -> None:
        self.done += points

    def close(self) -> None:
        return None


class PlainLines(Silent):
    """``sweep: 1200/10000 points (12%), 85.3 points/s, ETA 1m43s`` every few seconds, for logs and pipes."""

    def __init__(self, stream: TextIO | None = None, every: float = PLAIN_EVERY) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.every = every

    def start(self, total: int, done: int) -> None:
        super().start(total, done)
        self.first, self.began, self.last = done, time.perf_counter(), -float("inf")
        self._line(f"sweep: {total} points, {done} already done" if done else f"sweep: {total} points")

    def advance(self, points: int) -> None:
        super().advance(points)
        now = time.perf_counter()
        if now - self.last >= self.every or self.done >= self.total:
            self.last = now
            self._line(self._status(now))

    def _status(self, now: float) -> str:
        rate = (self.done - self.first) / max(now - self.began, 1e-9)
        left = (self.total - self.done) / rate if rate > 0 else float("inf")
        eta = "" if self.done >= self.total else f", ETA {_duration(left)}"
        percent = 100.0 * self.done / self.total if self.total else 100.0
        return f"sweep: {self.done}/{self.total} points ({percent:.0f}%), {rate:.1f} points/s{eta}"

    def _line(self, text: str) -> None:
        print(text, file=self.stream, flush=True)


class RichBar(Silent):
    """A rich progress bar (points done, rate, elapsed and remaining time) on standard error."""

    def start(self, total: int, done: int) -> None:
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TaskProgressColumn,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        super().start(total, done)
        self.bar: Any = Progress(
            TextColumn("sweep"),
            BarColumn(),
            MofNCompleteColumn(),
            TaskProgressColumn(),
            TextColumn("{task.fields[rate]}"),
            TimeElapsedColumn(),
            TextColumn("ETA"),
            TimeRemainingColumn(),
            console=Console(stderr=True),
        )
        self.bar.start()
        self.task = self.bar.add_task("sweep", total=total, completed=done, rate="")
        self.first, self.began = done, time.perf_counter()

    def advance(self, points: int) -> None:
        super().advance(points)
        rate = (self.done - self.first) / max(time.perf_counter() - self.began, 1e-9)
        self.bar.update(self.task, completed=self.done, rate=f"{rate:.1f} points/s")

    def close(self) -> None:
        self.bar.stop()


def reporter(quiet: bool, terminal: bool | None = None) -> Silent:
    """The progress display for this output: nothing, a bar on a terminal, or plain lines."""
    if quiet:
        return Silent()
    if terminal is None:
        terminal = sys.stderr.isatty()
    return RichBar() if terminal else PlainLines()


def _duration(seconds: float) -> str:
    if seconds == float("inf"):
        return "unknown"
    seconds = round(seconds)
    hours, rest = divmod(seconds, 3600)
    minutes, secs = divmod(rest, 60)
    return f"{hours}h{minutes:02d}m" if hours else f"{minutes}m{secs:02d}s" if minutes else f"{secs}s"
