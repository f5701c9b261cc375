"""A notice before numba compiles a model's kernels for this machine, the first time after an install.

numba compiles the kernels on their first call and caches them on disk; later processes load them in well under a
second.  The first compile is long: the time-dependent model's kernels take ~40-50 s of CPU on the 2-core AMD EPYC
machine (2026-11-30, an empty ``NUMBA_CACHE_DIR``: ``stickslip transient ... --stick-population`` 47 s, 1.5 s after),
which without a word looks like a hung command.  The package itself never prints (the core imports no face): a
command registers a listener with :func:`on_first_compile`, and :func:`announce_if_uncached` calls it, once per
kernel family and process, where numba's own cache index for a family's entry point holds nothing for this source.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

_LISTENERS: list[Callable[[str], None]] = []
_ANNOUNCED: set[str] = set()


def on_first_compile(listener: Callable[[str], None]) -> None:
    """Call ``listener(what)`` before a kernel family ``what`` (words: "the time-dependent model's kernels") is
    compiled rather than loaded from numba's cache."""
    if listener not in _LISTENERS:
        _LISTENERS.append(listener)


def announce_if_uncached(dispatcher: Any, what: str) -> None:
    """Tell the listeners that ``what`` is about to be compiled, where ``dispatcher`` (a numba function with
    ``cache=True``, not yet called) has no cached machine code for its current source; nothing otherwise, nothing
    without listeners, and nothing where numba's cache cannot be read (its layout is numba's own)."""
    if not _LISTENERS or what in _ANNOUNCED:
        return
    try:
        cached = bool(dispatcher._cache._cache_file._load_index())  # {} where absent or stale (source changed)
    except Exception:  # a numba without this layout, an unreadable cache: say nothing rather than guess
        return
    if not cached:
        _ANNOUNCED.add(what)
        for listener in _LISTENERS:
            listener(what)


__all__ = ["announce_if_uncached", "on_first_compile"]
