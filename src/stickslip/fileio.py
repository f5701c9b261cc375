"""Writing output files without ever destroying what an output name points at.

What happens depends on what the name is:

* a new path or a regular file: written under a temporary name in the same
  folder, then renamed over it, so a reader (or a user who kills the program
  mid-write) sees either the old file or the whole new one;
* a symbolic link: followed; its final target is replaced as above (in the
  target's folder), and the link stays a link;
* a character device (``/dev/null``), a FIFO, a socket, or a name that leads
  through ``/proc/*/fd`` or ``/dev/fd`` (``/dev/stdout``): written as it is,
  appending, never replaced;
* ``-``: standard output.  Then (and for a link to this process's own
  standard output) everything else the command prints goes to standard
  error (:func:`claim_stdout`), so ``--plot - > fig.png`` is a whole image.

Temporary files are named ``.NAME.XXXXXXXX[.SUFFIX].tmp`` and locked
(``flock``) while written; a killed write leaves one behind, and the next
write to the same target removes those of its name that no one holds and that
are older than this process.  A file of any other name is never touched.

Inside a command-line invocation every input file is remembered (see
:func:`protect_inputs`), and a write that would replace one of them is refused
with :class:`~stickslip.errors.DataError`: same device and inode, so a symbolic
or hard link to an input is recognised too.
"""

from __future__ import annotations

import contextlib
import os
import re
import stat
import sys
import tempfile
import time
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import IO, Any

from .errors import DataError

__all__ = [
    "STDOUT",
    "atomic_open",
    "atomic_path",
    "atomic_write_bytes",
    "atomic_write_text",
    "claim_stdout",
    "is_stdout",
    "output_kind",
    "protect_inputs",
    "read_input_text",
    "refuse_input_as_output",
    "remove_orphaned_temporaries",
    "same_file",
]

#: The output name that means standard output.
STDOUT = "-"

#: When this process started, near enough: temporary files older than this are not being written by it.
_STARTED = time.time()

#: Temporary names this module makes: ``.NAME.`` + mkstemp's 8 characters + optional suffix + ``.tmp``.
_TEMP_TAIL = r"\.[a-z0-9_]{8}(?:\.[A-Za-z0-9_-]{1,16})?\.tmp"

#: Key of the protected inputs in the click context of a command-line invocation.
_META_KEY = "stickslip.fileio.inputs"

#: Key of the real standard output once an output file has claimed it (see :func:`claim_stdout`).
_STDOUT_KEY = "stickslip.fileio.stdout"


# --------------------------------------------------------------------------- what an output name is
def output_kind(path: str | Path) -> str:
    """``"stdout"`` for ``-``; ``"stream"`` for a device, FIFO, socket or /proc fd link; else ``"file"``."""
    if str(path) == STDOUT:
        return "stdout"
    if _through_fd_link(Path(path)):
        return "stream"
    try:
        mode = os.stat(path).st_mode  # follows symbolic links: the kind of the target
    except OSError:
        return "file"  # new (or a dangling link): created as a regular file
    if stat.S_ISREG(mode) or stat.S_ISDIR(mode):
        return "file"  # a folder fails at the rename with a clear OSError
    return "stream"


def _through_fd_link(path: Path) -> bool:
    """True if following ``path``'s links passes through ``/proc/*/fd/N`` or ``/dev/fd/N`` (e.g. /dev/stdout).

    Their target is an open file of some process (a pipe, a terminal, a file
    a shell opened with ``>``): it must be written through, never replaced.
    """
    return _fd_link(path) is not None


def _fd_link(path: str | Path) -> tuple[int, int] | None:
    """(process id, descriptor) of the first ``/proc/PID/fd/N`` on ``path``'s chain of links, or None."""
    current = Path(os.path.abspath(path))
    for _ in range(40):  # the kernel's own limit on link chains
        folder = os.path.realpath(current.parent)
        match = re.fullmatch(r"/proc/(\d+)(?:/task/\d+)?/fd|/dev/fd", folder)
        if match:
            pid = int(match.group(1)) if match.group(1) else os.getpid()
            return (pid, int(current.name)) if current.name.isdigit() else (pid, -1)
        if not current.is_symlink():
            return None
        link = os.readlink(current)
        current = Path(os.path.normpath(Path(folder) / link))
    return None


def _real_target(path: Path) -> Path:
    """The file a rename must replace: the final target of a chain of links (also a dangling one)."""
    return Path(os.path.realpath(path))


# --------------------------------------------------------------------------- inputs that no output may replace
def _invocation_meta() -> dict[str, Any] | None:
    """The click context's ``meta`` of the running command, if any (one per invocation, so nothing leaks)."""
    click = sys.modules.get("click")
    if click is None:
        return None
    ctx = click.get_current_context(silent=True)
    return None if ctx is None else ctx.meta


def require_input_file(path: str | Path, subject: str, error: type[Exception] = DataError) -> os.stat_result:
    """The stat of an input file that is a regular file (a FIFO would block, /dev/zero never end, /dev/null is
    empty); every other case is one ``error`` line that starts with ``subject``."""
    try:
        info = Path(path).stat()
    except FileNotFoundError:
        raise error(f"{subject}: file not found") from None
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the name
        raise error(f"{subject}: cannot be read ({getattr(exc, 'strerror', None) or exc})") from None
    if stat.S_ISDIR(info.st_mode):
        raise error(f"{subject}: is a folder, not a file")
    if not stat.S_ISREG(info.st_mode):
        raise error(f"{subject}: not a regular file (save a pipe or device to a file first)")
    return info


def read_input_text(path: str | Path, subject: str, max_bytes: int, error: type[Exception] = DataError) -> str:
    """The text of an input file, checked before it is read (:func:`require_input_file`), of at most
    ``max_bytes``, UTF-8 (a byte-order mark is fine).  Every problem is one ``error`` line that starts with
    ``subject`` (``"--params run.json"``, ``"protocol file p.csv"``)."""
    path = Path(path)
    info = require_input_file(path, subject, error)
    if info.st_size > max_bytes:
        raise error(f"{subject}: {info.st_size} bytes; at most {max_bytes} bytes are read")
    try:
        return path.read_bytes().decode("utf-8-sig")
    except OSError as exc:
        raise error(f"{subject}: cannot be read ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise error(f"{subject}: not a text (UTF-8) file ({exc.reason} at byte {exc.start})") from None


def protect_inputs(paths: Iterable[str | Path | None]) -> None:
    """Remember these input files for the running command: no later write may replace them.

    Outside a command-line invocation (the Python API) this does nothing.
    Names that are not existing regular files (a built-in parameter set's
    name, ``None``) are skipped.
    """
    meta = _invocation_meta()
    if meta is None:
        return
    known: dict[tuple[int, int], str] = meta.setdefault(_META_KEY, {})
    for path in paths:
        if path is None or str(path) == STDOUT:
            continue
        with contextlib.suppress(OSError, ValueError):
            info = os.stat(path)
            if stat.S_ISREG(info.st_mode):
                known.setdefault((info.st_dev, info.st_ino), str(path))


def _refuse_protected(target: Path, shown: str | Path) -> None:
    meta = _invocation_meta()
    if not meta or not meta.get(_META_KEY):
        return
    try:
        info = os.stat(target)
    except (OSError, ValueError):
        return
    source = meta[_META_KEY].get((info.st_dev, info.st_ino))
    if source is not None:
        raise DataError(f"{shown}: that is the input file {source}; refusing to overwrite it (choose another name)")


def _is_regular(path: str | Path) -> bool:
    """A regular file (a device or FIFO read as input is not destroyed by writing into it)."""
    try:
        return stat.S_ISREG(os.stat(path).st_mode)
    except (OSError, ValueError):
        return False


def same_file(a: str | Path, b: str | Path) -> bool:
    """True if both names exist and are one file (same device and inode: links and hard links included)."""
    try:
        first, second = os.stat(a), os.stat(b)
    except (OSError, ValueError):
        return False
    return (first.st_dev, first.st_ino) == (second.st_dev, second.st_ino)


def refuse_shared_outputs(outputs: list[tuple[str, str | Path | None]]) -> None:
    """Raise :class:`DataError` if two outputs name one file (``-o X --plot X``): the later would silently replace
    the earlier.  Standard output (``-``) taken twice is refused too; two names of one file (a link) are one file."""
    seen: list[tuple[str, str | Path]] = []
    for option, out in outputs:
        if out is None or not str(out).strip():
            continue
        for earlier, path in seen:
            if _one_output(path, out):
                where = "standard output" if is_stdout(out) else f"the file {out}"
                raise DataError(f"{earlier} {path} and {option} {out}: both write {where}; give each its own name")
        seen.append((option, out))


def _one_output(a: str | Path, b: str | Path) -> bool:
    if is_stdout(a) or is_stdout(b):  # ``-`` and /dev/stdout are one output
        return is_stdout(a) and is_stdout(b)
    if os.path.exists(a) and not _is_regular(a):  # /dev/null takes any number of outputs, and keeps none
        return False
    if same_file(a, b):
        return True
    return os.path.normcase(os.path.realpath(a)) == os.path.normcase(os.path.realpath(b))


def refuse_input_as_output(inputs: list[str | Path | None], outputs: list[tuple[str, str | Path | None]]) -> None:
    """Raise :class:`DataError` if any output names the same file as an input; remember the inputs.

    ``outputs`` are ``(option name, path)`` pairs, so the message can say which
    option would have overwritten which input.  The inputs are also kept for
    the rest of the invocation (:func:`protect_inputs`), so a file written
    later that was not listed here (a side file) cannot replace them either.
    """
    protect_inputs(inputs)
    refuse_shared_outputs(outputs)
    claim_stdout([out for _, out in outputs])
    existing = [p for p in inputs if p is not None and str(p) != STDOUT and _is_regular(p)]
    for option, out in outputs:
        if out is None or str(out) == STDOUT:
            continue
        for source in existing:
            if same_file(source, out):
                raise DataError(
                    f"{option} {out}: that is the input file; refusing to overwrite it (choose another name)"
                )


# --------------------------------------------------------------------------- standard output taken by a file
def claim_stdout(outputs: Iterable[str | Path | None]) -> bool:
    """If one of the running command's outputs is standard output (``-``, or ``/dev/stdout``: a link to this
    process's descriptor 1), send everything else it prints to standard error until the command ends.

    ``stickslip curve --plot - > fig.png`` must give a whole PNG, not the table and then the image; a CSV on
    ``-o -`` must not end in a summary.  Only inside a command-line invocation (the Python API prints nothing);
    True if standard output was claimed.
    """
    meta = _invocation_meta()
    if meta is None or _STDOUT_KEY in meta:
        return meta is not None and _STDOUT_KEY in meta
    if not any(out is not None and is_stdout(out) for out in outputs):
        return False
    click = sys.modules["click"]  # (loaded: the invocation's meta is its context's)
    real = sys.stdout
    with contextlib.suppress(Exception):
        real.flush()
    meta[_STDOUT_KEY] = real
    sys.stdout = sys.stderr

    def restore() -> None:
        if sys.stdout is sys.stderr:
            sys.stdout = real
        meta.pop(_STDOUT_KEY, None)

    click.get_current_context().call_on_close(restore)
    return True


def is_stdout(path: str | Path) -> bool:
    """True if writing ``path`` writes this process's standard output: ``-``, or a link to descriptor 1
    (``/dev/stdout``)."""
    if str(path) == STDOUT:
        return True
    try:
        return _fd_link(path) == (os.getpid(), 1)
    except (OSError, ValueError):
        return False


def _stdout() -> Any:
    """The real standard output: the one an output file claimed, else ``sys.stdout``."""
    meta = _invocation_meta()
    return meta[_STDOUT_KEY] if meta and _STDOUT_KEY in meta else sys.stdout


# --------------------------------------------------------------------------- writing
@contextlib.contextmanager
def atomic_path(path: str | Path, suffix: str | None = None, clean: bool = True) -> Iterator[Path]:
    """Yield a temporary path to write; on success its content goes to ``path`` as the module note says.

    For writers that want a file name (``savefig``, ``to_parquet``).  On any
    exception the temporary file is removed and ``path`` is untouched.
    ``clean=False`` skips the scan of the folder for stale temporaries (a
    writer of many files in one folder cleans it once, not at every file).
    """
    kind = output_kind(path)
    tail = (suffix if suffix is not None else Path(str(path)).suffix) + ".tmp"
    if kind != "file":
        with _scratch_file(tail) as temp:
            yield temp
            _copy_to_stream(temp, path, kind)
        return
    target = _real_target(Path(path))
    _refuse_protected(target, path)
    folder = target.parent
    if clean:
        remove_stale_temporaries(target)
    handle, temp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=tail, dir=folder)
    temp = Path(temp_name)
    try:
        _lock(handle)  # tells a later cleaner that this temporary is alive
        _set_mode(temp, target)
        yield temp
        _fsync_file(temp)
        os.replace(temp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            temp.unlink()
        raise
    finally:
        os.close(handle)


def atomic_write_text(path: str | Path, text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` (atomically when it is a file); returns the path."""
    return atomic_write_bytes(path, text.encode(encoding))


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` (atomically when it is a file); returns the path."""
    kind = output_kind(path)
    if kind == "stdout":
        _write_stdout(data)
    elif kind == "stream":
        _write_stream(path, data)
    else:
        with atomic_path(path) as temp, open(temp, "wb") as handle:
            handle.write(data)
    return Path(path)


@contextlib.contextmanager
def atomic_open(path: str | Path, mode: str = "w", **kwargs: Any) -> Iterator[IO[Any]]:
    """``open`` for writing, atomically: the file appears under ``path`` only when closed without error."""
    with atomic_path(path) as temp, open(temp, mode, **kwargs) as handle:
        yield handle


def _write_stdout(data: bytes) -> None:
    out = _stdout()
    out.flush()
    stream = getattr(out, "buffer", None)
    if stream is None:  # a text-only stand-in for stdout
        out.write(data.decode("utf-8", errors="replace"))
    else:
        stream.write(data)
        stream.flush()


def _write_stream(path: str | Path, data: bytes) -> None:
    """Write to a device, FIFO or open-file link as it is: no rename, no truncation of what it points at.

    A link to one of this process's own descriptors (``/dev/stdout``) is
    written through that descriptor, so the bytes land where the process's
    other output to it goes, in order (a fresh ``open`` would have an offset
    of its own in a file the shell opened with ``>``).
    """
    link = _fd_link(path)
    if link is not None and link[0] == os.getpid() and link[1] >= 0:
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        view = memoryview(data)
        while view:
            view = view[os.write(link[1], view) :]
        return
    descriptor = os.open(path, os.O_WRONLY | os.O_APPEND)
    with os.fdopen(descriptor, "wb") as handle:
        handle.write(data)


def _copy_to_stream(temp: Path, path: str | Path, kind: str) -> None:
    data = temp.read_bytes()
    if kind == "stdout":
        _write_stdout(data)
    else:
        _write_stream(path, data)


@contextlib.contextmanager
def _scratch_file(tail: str) -> Iterator[Path]:
    handle, name = tempfile.mkstemp(prefix=".stickslip.", suffix=tail)
    os.close(handle)
    try:
        yield Path(name)
    finally:
        with contextlib.suppress(OSError):
            os.unlink(name)


# --------------------------------------------------------------------------- temporaries of killed writes
def remove_stale_temporaries(target: str | Path) -> list[Path]:
    """Remove this module's temporaries for ``target`` left by killed writes; returns those removed.

    Only names of the exact pattern this module makes for ``target``'s name,
    only if older than this process and not locked by a live writer.
    """
    target = Path(target)
    pattern = re.compile(re.escape(f".{target.name}") + _TEMP_TAIL)
    removed = []
    try:
        entries = list(os.scandir(target.parent))
    except OSError:
        return removed
    for entry in entries:
        if pattern.fullmatch(entry.name) and _remove_if_stale(Path(entry.path)):
            removed.append(Path(entry.path))
    return removed


def remove_orphaned_temporaries(folder: str | Path) -> list[Path]:
    """Remove this module's temporaries in ``folder`` that no live writer holds, however new; returns those removed.

    For a caller that has just killed its own writers (a report's forked figure workers): their temporaries are
    newer than this process, so :func:`remove_stale_temporaries` would keep them.  A temporary another live
    process is writing stays: it is locked.
    """
    pattern = re.compile(r"\..+" + _TEMP_TAIL)
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        if pattern.fullmatch(entry.name) and _remove_if_stale(Path(entry.path), any_age=True):
            removed.append(Path(entry.path))
    return removed


def _remove_if_stale(path: Path, any_age: bool = False) -> bool:
    """Remove ``path`` if it is a regular file, older than this process (unless ``any_age``) and unlocked; True if
    removed."""
    try:
        info = path.lstat()
        if not stat.S_ISREG(info.st_mode) or (info.st_mtime >= _STARTED and not any_age):
            return False
        descriptor = os.open(path, os.O_RDONLY)
    except OSError:
        return False
    try:
        try:
            _lock(descriptor, wait=False)
        except OSError:  # a live writer holds it
            return False
        path.unlink()
        return True
    except OSError:
        return False
    finally:
        os.close(descriptor)


def _lock(descriptor: int, wait: bool = True) -> None:
    try:
        import fcntl
    except ImportError:  # pragma: no cover - no flock on this platform: no liveness marks, nothing removed
        if not wait:
            raise OSError("no file locks on this platform") from None
        return
    fcntl.flock(descriptor, fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))


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
