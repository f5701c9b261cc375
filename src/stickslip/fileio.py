"""Files written atomically: a temporary name in the same folder, then a rename.

A reader (or a user who kills the program mid-write) sees either the old file
or the whole new one, never a half-written or empty file.  Every output of the
package goes through here; nothing else opens a file for writing.
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

from .errors import DataError

__all__ = ["atomic_path", "atomic_write_bytes", "atomic_write_text", "refuse_input_as_output"]


@contextlib.contextmanager
def atomic_path(path: str | Path, suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success rename it onto ``path``.

    For writers that want a file name (``savefig``, ``to_parquet``).  On any
    exception the temporary file is removed and ``path`` is untouched.
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    handle, temp_name = tempfile.mkstemp(
        prefix=f".{target.name}.", suffix=(suffix if suffix is not None else target.suffix) + ".tmp", dir=folder
    )
    os.close(handle)
    temp = Path(temp_name)
    _set_mode(temp, target)
    try:
        yield temp
        _fsync_file(temp)
        os.replace(temp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            temp.unlink()
        raise


def atomic_write_text(path: str | Path, text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically; returns the path."""
    return atomic_write_bytes(path, text.encode(encoding))


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically; returns the path."""
    with atomic_path(path) as temp:
        with open(temp, "wb") as handle:
            handle.write(data)
    return Path(path)


@contextlib.contextmanager
def atomic_open(path: str | Path, mode: str = "w", **kwargs: Any) -> Iterator[IO[Any]]:
    """``open`` for writing, atomically: the file appears under ``path`` only when closed without error."""
    with atomic_path(path) as temp, open(temp, mode, **kwargs) as handle:
        yield handle


def refuse_input_as_output(inputs: list[str | Path | None], outputs: list[tuple[str, str | Path | None]]) -> None:
    """Raise :class:`DataError` if any output names the same file as an input.

    ``outputs`` are ``(option name, path)`` pairs, so the message can say which
    option would have overwritten which input.
    """
    existing = [Path(p) for p in inputs if p is not None and Path(p).exists()]
    for option, out in outputs:
        if out is None:
            continue
        target = Path(out)
        for source in existing:
            if target.exists() and _same_file(source, target):
                raise DataError(
                    f"{option} {out}: that is the input file; refusing to overwrite it (choose another name)"
                )


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return a.resolve() == b.resolve()


def _set_mode(temp: Path, target: Path) -> None:
    """Give the new file the mode a plain ``open`` would (mkstemp makes it private, 0600), or the old file's."""
    try:
        mode = stat.S_IMODE(target.stat().st_mode)
    except OSError:
        umask = os.umask(0o022)
        os.umask(umask)
        mode = 0o666 & ~umask
    with contextlib.suppress(OSError):
        os.chmod(temp, mode)


def _fsync_file(path: Path) -> None:
    with contextlib.suppress(OSError), open(path, "rb") as handle:
        os.fsync(handle.fileno())
