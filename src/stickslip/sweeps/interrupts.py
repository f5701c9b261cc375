"""Ctrl-C (and the command line's SIGTERM) during a sweep: always heard, raised where the sweep can stop.

Python runs a signal's handler in the main thread between two bytecodes, wherever those are.  Inside a garbage
collector's callback or a ``__del__`` the KeyboardInterrupt that the default handler raises is printed as
"Exception ignored in: ... KeyboardInterrupt" and lost.  A local cluster's scheduler runs in this process and installs
distributed's ``GCDiagnosis._gc_callback``, so that a Ctrl-C to ``stickslip sweep --workers 2`` was lost in 2 of
7 tries (round 28): the sweep ran on to its end and exited 0.

:func:`heard_at_safe_points` replaces, for the sweep's duration, the handlers that raise (Python's own SIGINT handler,
and the command line's SIGTERM handler, marked ``stickslip_unwinds``) by one that notes the signal, and

* while the main thread waits on the cluster (:func:`deferred`), only notes it: the waiting loop looks every 0.1 s
  (:func:`stop_if_asked`) and raises it there;
* elsewhere raises it at once, as before, unless the main thread stands in a gc callback or a ``__del__`` (where it
  would be lost): then it is raised at the next :func:`stop_if_asked` (after the batch in this process).

Outside the main thread, or where someone else's handler is installed, nothing changes.
"""

from __future__ import annotations

import contextlib
import gc
import signal
import threading
from collections.abc import Callable, Iterator
from types import FrameType
from typing import Any

#: seconds between two looks at a noted signal while the main thread waits on the cluster
POLL_SECONDS = 0.1


class _State:
    def __init__(self) -> None:
        self.previous: dict[int, Callable[[int, FrameType | None], Any]] = {}
        self.heard: int | None = None
        self.deferring = 0


_STATE = _State()


def _raises(signum: int, handler: Any) -> bool:
    """A handler that ends the program's work by raising: Python's SIGINT handler, the command line's SIGTERM one."""
    if signum == signal.SIGINT:
        return handler is signal.default_int_handler
    return callable(handler) and bool(getattr(handler, "stickslip_unwinds", False))


def _in_ignored_frame(frame: FrameType | None) -> bool:
    """Whether ``frame`` runs inside a gc callback or a ``__del__``, where Python ignores a raised exception."""
    codes = set()
    for callback in gc.callbacks:
        function = getattr(callback, "__func__", callback)
        code = getattr(function, "__code__", None)
        if code is not None:
            codes.add(code)
    while frame is not None:
        if frame.f_code in codes or frame.f_code.co_name == "__del__":
            return True
        frame = frame.f_back
    return False


def _note(signum: int, frame: FrameType | None) -> None:
    _STATE.heard = signum  # kept until looked at: if the raise below is lost after all, the next look raises it
    if _STATE.deferring or _in_ignored_frame(frame):
        return  # raised at the next stop_if_asked
    _STATE.previous[signum](signum, frame)


def stop_if_asked() -> None:
    """Raise the signal noted since the last look (KeyboardInterrupt, or the command line's Terminated), if any."""
    signum, _STATE.heard = _STATE.heard, None
    if signum is not None and signum in _STATE.previous:
        _STATE.previous[signum](signum, None)


@contextlib.contextmanager
def heard_at_safe_points() -> Iterator[None]:
    """Within the block, SIGINT (and the command line's SIGTERM) are noted and raised where they cannot be lost."""
    if threading.current_thread() is not threading.main_thread() or _STATE.previous:
        yield  # another thread (no handler can be set there), or a sweep inside a sweep: as it stands
        return
    signals = [signal.SIGINT] + ([signal.SIGTERM] if hasattr(signal, "SIGTERM") else [])
    for signum in signals:
        handler = signal.getsignal(signum)
        if _raises(signum, handler):
            _STATE.previous[signum] = handler
            signal.signal(signum, _note)
    try:
        yield
        stop_if_asked()  # one noted and not yet raised (lost in a callback) still stops the sweep here
    finally:
        for signum, handler in _STATE.previous.items():
            if signal.getsignal(signum) is _note:  # a handler someone installed meanwhile is left alone
                signal.signal(signum, handler)
        _STATE.previous.clear()
        _STATE.heard = None


@contextlib.contextmanager
def deferred() -> Iterator[None]:
    """Within the block a signal is only noted; the block calls :func:`stop_if_asked` where it can stop."""
    _STATE.deferring += 1
    try:
        yield
    finally:
        _STATE.deferring -= 1
