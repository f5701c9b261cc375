"""A closed connection at a cluster's end is how the cluster ends, not an error: kept off the user's terminal.

A local cluster's worker that closes while its heartbeat to the scheduler is in flight logged, at ERROR and with
the traceback, "Failed to communicate with scheduler during heartbeat." ... ``distributed.comm.core.CommClosedError:
in <TCP (closed) ConnectionPool.heartbeat_worker ...>: Stream is closed``: ``distributed.worker.Worker.close``
closes its connection pool (``rpc.close``) under the heartbeat that awaits it (distributed 2026.8.0).  The sweep was
right and whole; the traceback came from the worker process, whose logs go to the terminal the command runs in,
before the summary, on perhaps one run in ten (a heartbeat every 0.5 s, a round trip of a millisecond, longer on a
loaded machine).

:class:`ClosedConnectionNoise` drops the records of a closed connection (a ``CommClosedError`` or tornado's
``StreamClosedError``, raised or named) and nothing else: in the local cluster's worker processes always (a worker's
lost connection is the client's to report, and it does: the task's failure, "points ... failed on the cluster ...
run the same command again to resume"), and in this process while a sweep's cluster runs and closes
(:func:`quiet_closing`).  Every other record, a real error with its traceback, is written as before.
"""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Iterator
from typing import Any

#: the loggers that write a closed connection's record: every module of distributed's (their records reach the
#: handler distributed puts on "distributed"), asyncio's "exception was never retrieved", tornado's callbacks
LOGGERS = (
    "distributed",
    "distributed.batched",
    "distributed.client",
    "distributed.comm",
    "distributed.comm.tcp",
    "distributed.core",
    "distributed.nanny",
    "distributed.scheduler",
    "distributed.utils",
    "distributed.worker",
    "asyncio",
    "tornado",
    "tornado.application",
)
#: the names of the exceptions of a closed connection, as a record's text may give them without the exception
NAMES = ("CommClosedError", "StreamClosedError")


def closed_connection(error: BaseException | None) -> bool:
    """Whether ``error``, or an exception it was raised from, is a closed connection."""
    seen: set[int] = set()
    while error is not None and id(error) not in seen:
        if type(error).__name__ in NAMES:
            return True
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return False


class ClosedConnectionNoise(logging.Filter):
    """Drops a record of a closed connection (its exception, or its text naming one); passes every other."""

    def filter(self, record: logging.LogRecord) -> bool:
        if record.exc_info and closed_connection(record.exc_info[1]):
            return False
        try:
            text = record.getMessage()
        except Exception:  # a record whose arguments do not format: not ours to judge
            return True
        return not any(name in text for name in NAMES)


def _targets() -> list[Any]:
    """The loggers of :data:`LOGGERS` and every handler on them (distributed's one stream handler among them)."""
    loggers = [logging.getLogger(name) for name in LOGGERS]
    handlers = {id(h): h for logger in loggers for h in logger.handlers}
    return [*loggers, *handlers.values()]


def install() -> ClosedConnectionNoise:
    """Add the filter to :func:`_targets` for the rest of the process (a worker's); returns it."""
    noise = ClosedConnectionNoise()
    for target in _targets():
        target.addFilter(noise)
    return noise


@contextlib.contextmanager
def quiet_closing() -> Iterator[None]:
    """The filter in this process while the block runs (a sweep's cluster: its start, its work and its close)."""
    noise = ClosedConnectionNoise()
    targets = _targets()
    for target in targets:
        target.addFilter(noise)
    try:
        yield
    finally:
        for target in targets:
            target.removeFilter(noise)


def dask_setup(worker: Any) -> None:
    """A local cluster's worker process loads this module (``preload``): the filter for the process's life."""
    install()
