"""The output folder of a sweep: a manifest, one Parquet chunk per finished batch, a ledger of the chunks.

A chunk appears under its name only when whole and is recorded with its SHA-256, so resuming runs the batches
whose chunk is missing or fails its check; one process writes a folder at a time (``flock`` on
``OUT/.stickslip.lock``).  The layout and what survives ``kill -9``: docs/sweep.md.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import shutil
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import DataError, ParameterError
from ..fileio import atomic_path, atomic_write_text
from .spec import SweepSpec

MANIFEST = "_manifest.json"
LEDGER = "_chunks.jsonl"
LOCK = ".stickslip.lock"
RUN = "_run.json"  # the latest run: workers, schedule, wall, point time, parallel efficiency
FORMAT = "stickslip-sweep/1"
_CHUNK = re.compile(r"^part-(\d{6,})\.parquet$")
_TEMPORARY = re.compile(r"^\.(part-\d{6,}\.parquet|_manifest\.json|_chunks\.jsonl|_run\.json)\..*\.tmp$")
_OWN = (MANIFEST, LEDGER, LOCK, RUN)
#: Bytes a row takes at least in its chunk: 8 per number that differs from row to row (floats do not compress).
_BYTES_PER_NUMBER = 8
#: Disk space a sweep leaves free, beyond its estimated size.
_DISK_MARGIN = 100_000_000


def is_chunk(name: str) -> bool:
    """True for a chunk's file name, ``part-NNNNNN.parquet``."""
    return _CHUNK.match(name) is not None


def chunk_name(batch: int) -> str:
    return f"part-{batch:06d}.parquet"


def arrow_schema(
    inputs: tuple[str, ...], columns: Mapping[str, str], key_units: Mapping[str, str | None] | None = None
) -> Any:
    """The one schema of every chunk: point index, inputs (SI floats), then the model's columns.

    ``key_units`` gives the units of the model's own keys (a plug-in's keys are not in the package's registry).
    """
    import pyarrow as pa

    from ..columns import PARQUET_KEY, unit_of

    kinds = {"float": pa.float64(), "int": pa.int64(), "str": pa.string()}
    types = {"point": pa.int64(), **dict.fromkeys(inputs, pa.float64())}
    types.update({name: kinds[kind] for name, kind in columns.items()})
    units = {name: unit_of(name, key_units) for name in types}  # every column names its unit (pyarrow field metadata)
    fields = [pa.field(name, kind, metadata=_unit_metadata(units[name])) for name, kind in types.items()]
    # PANDAS_ATTRS: the key pandas (>= 2.1) restores DataFrame.attrs from, so that a plain pandas.read_parquet(OUT)
    # holds attrs["units"] as stickslip.columns.read_parquet does (before: empty attrs; the units in PARQUET_KEY only)
    return pa.schema(fields, metadata={PARQUET_KEY: json.dumps(units).encode(), **pandas_attrs(units)})


#: The Parquet schema metadata key from which pandas (2.1 and later) restores ``DataFrame.attrs`` (JSON).
PANDAS_ATTRS = b"PANDAS_ATTRS"


def pandas_attrs(units: Mapping[str, str | None]) -> dict[bytes, bytes]:
    """``{PANDAS_ATTRS: '{"units": {column: unit}}'}``: the frame's ``attrs`` as pandas reads them back."""
    return {PANDAS_ATTRS: json.dumps({"units": dict(units)}).encode()}


def _unit_metadata(unit: str | None) -> dict[bytes, bytes] | None:
    return None if unit is None else {b"unit": unit.encode()}


@dataclass
class SweepStore:
    """An output folder opened (and locked) for one specification; :meth:`close` releases it."""

    folder: Path
    spec: SweepSpec
    batch_size: int
    version: str
    done: set[int] = field(default_factory=set)  # batches whose chunk is whole and checked
    damaged: list[str] = field(default_factory=list)  # "part-000003.parquet (why)": removed, to recompute
    lock: int | None = None  # descriptor holding the folder's flock
    points_written: int = 0  # rows written by this process, and the sum of their wall_time (the parallel efficiency)
    point_seconds: float = 0.0
    report: Any = None  # the run's stickslip.sweeps.schedule.RunReport, once run_sweep has run it

    @property
    def batches(self) -> int:
        return -(-self.spec.size // self.batch_size)

    def batch_range(self, batch: int) -> tuple[int, int]:
        start = batch * self.batch_size
        return start, min(start + self.batch_size, self.spec.size)

    def finished(self) -> set[int]:
        """Batches whose chunk is whole and belongs to this specification (checked when the folder was opened)."""
        return set(self.done)

    def rows_done(self, done: set[int]) -> int:
        return sum(stop - start for start, stop in map(self.batch_range, done))

    def write(self, batch: int, table: Any) -> Path:
        """Write one batch's rows (a pyarrow Table) as its chunk, atomically, and record it in the ledger."""
        import pyarrow.parquet as pq

        start, stop = self.batch_range(batch)
        if table.num_rows != stop - start:
            raise DataError(f"batch {batch}: {table.num_rows} rows for points {start}..{stop - 1}; nothing written")
        target = self.folder / chunk_name(batch)
        with atomic_path(target, clean=False) as temp:  # the folder was cleaned when opened, under its lock
            pq.write_table(table, temp)
            _record(self.folder, batch, start, stop, temp)  # before the rename: see the module's note
        self.done.add(batch)
        self.points_written += table.num_rows
        self.point_seconds += sum(t for t in table.column("wall_time").to_pylist() if t is not None)
        return target

    def write_report(self, report: Any) -> None:
        """Keep the run's report (``RunReport.as_dict``) as ``_run.json``, atomically."""
        self.report = report
        atomic_write_text(self.folder / RUN, json.dumps(report.as_dict(), indent=2) + "\n")

    def close(self) -> None:
        """Release the folder's lock and remove its file (a killed process's lock is released by the kernel; its
        file, left with the dead process's id, is taken over by the next run)."""
        if self.lock is not None:
            with contextlib.suppress(OSError):  # removed while still held: a writer waiting on it tries again
                (self.folder / LOCK).unlink()
            os.close(self.lock)
            self.lock = None

    def __enter__(self) -> SweepStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def open_store(folder: str | Path, spec: SweepSpec, batch_size: int, overwrite: bool = False) -> SweepStore:
    """Create ``folder`` for ``spec``, or reopen it to resume; refuse a folder made for another specification.

    The folder is locked for this process until :meth:`SweepStore.close`.  On
    resume every chunk is checked against the ledger (or, unrecorded, read);
    a damaged one is removed and listed in ``SweepStore.damaged``.
    """
    if isinstance(batch_size, bool) or not isinstance(batch_size, int) or batch_size < 1:
        raise ParameterError(f"batch_size: expected a positive whole number of points, got {batch_size!r}")
    created = not os.path.lexists(folder) if str(folder).strip() else False
    had_lock = os.path.lexists(Path(folder) / LOCK) if str(folder).strip() else True
    path = _folder(folder)
    lock = _lock_folder(path, folder)
    try:
        store = _open_locked(path, folder, spec, batch_size, overwrite)
    except BaseException:
        if created:  # refused before anything was written: leave no empty folder behind
            with contextlib.suppress(OSError):
                (path / LOCK).unlink()
                (path / MANIFEST).unlink(missing_ok=True)
                path.rmdir()
        elif not had_lock:  # a refused command writes nothing: not even the lock file, in a folder of other files
            with contextlib.suppress(OSError):
                (path / LOCK).unlink()
        os.close(lock)
        raise
    store.lock = lock
    return store


def _open_locked(path: Path, folder: str | Path, spec: SweepSpec, batch_size: int, overwrite: bool) -> SweepStore:
    from .. import __version__

    _remove_temporaries(path)
    foreign = sorted(p.name for p in path.iterdir() if p.name not in _OWN and not _CHUNK.match(p.name))
    if foreign:
        raise DataError(
            f"-o {folder}: holds files that are not a sweep's ({', '.join(foreign[:3])}); choose a new or empty folder"
        )
    manifest = checked_manifest(path) if (path / MANIFEST).exists() and not overwrite else None
    if manifest is not None:
        if manifest["specification"] != json.loads(spec.to_json()):
            why = f"another specification ({_difference(manifest['specification'], spec)})"
        elif manifest["version"] != __version__:
            why = f"the same specification but stickslip {manifest['version']} (this is {__version__})"
        else:
            store = SweepStore(path, spec, manifest["batch_size"], __version__)
            _check_chunks(store)
            if "units" not in manifest:  # a folder made before the manifest named its units (round 29)
                named = {**manifest, "units": manifest_units(spec)}
                atomic_write_text(path / MANIFEST, json.dumps(named, indent=2) + "\n")
            return store
        raise ParameterError(
            f"-o {folder}: holds a sweep of {why}; give another output folder, or --overwrite to replace it"
        )
    if not (path / MANIFEST).exists() and any(_CHUNK.match(p.name) for p in path.iterdir()) and not overwrite:
        raise DataError(f"-o {folder}: holds Parquet chunks but no {MANIFEST}; give --overwrite to replace them")
    store = SweepStore(path, spec, batch_size, __version__)
    _refuse_too_large(store, folder)
    for old in path.iterdir():
        if _CHUNK.match(old.name) or old.name in (MANIFEST, LEDGER, RUN):
            old.unlink()
    atomic_write_text(path / MANIFEST, json.dumps(_manifest(store), indent=2) + "\n")
    return store


def _folder(folder: str | Path) -> Path:
    """The output folder, created; every way it can be wrong is one line."""
    if str(folder).strip() == "":
        raise ParameterError("-o: the output folder name is empty; give a folder, e.g. -o sweep-out")
    path = Path(folder)
    if path.exists() and not path.is_dir():
        raise DataError(f"-o {folder}: is a file; a sweep writes a folder of Parquet chunks")
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / LOCK
        os.close(os.open(probe, os.O_RDWR | os.O_CREAT, 0o644))
    except OSError as exc:
        raise DataError(f"-o {folder}: cannot create or write the folder ({exc.strerror or exc})") from None
    return path


def _lock_folder(path: Path, folder: str | Path) -> int:
    """An exclusive, non-blocking flock on the folder's lock file; a second writer is refused."""
    import fcntl

    while True:
        try:
            descriptor = os.open(path / LOCK, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise DataError(f"-o {folder}: cannot create its lock file ({exc.strerror or exc})") from None
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            holder = os.pread(descriptor, 32, 0).decode("ascii", errors="replace").strip()
            os.close(descriptor)
            who = f" (process {holder})" if holder.isdigit() else ""
            raise DataError(
                f"-o {folder}: another sweep is writing into this folder{who}; wait for it to end or choose another"
                " folder"
            ) from None
        if _same_file(descriptor, path / LOCK):
            break
        os.close(descriptor)  # the run that held it ended and removed the file meanwhile: lock the one there now
    os.ftruncate(descriptor, 0)
    os.pwrite(descriptor, f"{os.getpid()}\n".encode(), 0)
    return descriptor


def _same_file(descriptor: int, path: Path) -> bool:
    """Whether ``descriptor`` is still the file at ``path`` (not one removed since it was opened)."""
    try:
        there = os.stat(path)
    except FileNotFoundError:
        return False
    here = os.fstat(descriptor)
    return (here.st_dev, here.st_ino) == (there.st_dev, there.st_ino)


def _refuse_too_large(store: SweepStore, folder: str | Path) -> None:
    """Refuse, before any work, a sweep whose rows cannot fit on the folder's disk."""
    from .models import get_model, result_columns

    numbers = 1 + len(store.spec.keys) + sum(k == "float" for k in result_columns(get_model(store.spec.model)).values())
    need = store.spec.size * numbers * _BYTES_PER_NUMBER + store.batches * 200  # the ledger's lines
    free = shutil.disk_usage(store.folder).free
    if need + _DISK_MARGIN > free:
        raise ParameterError(
            f"-o {folder}: {store.spec.size:.4g} points need at least {_size(need)} of Parquet and the disk has"
            f" {_size(free)} free; sweep fewer points (or into a folder on a larger disk)"
        )


def _size(count: float) -> str:
    for unit in ("bytes", "kB", "MB", "GB", "TB"):
        if count < 1000:
            return f"{count:.3g} {unit}"
        count /= 1000
    return f"{count:.3g} PB"


def _fingerprint(path: Path) -> dict[str, Any]:
    digest = hashlib.sha256()
    size = 0
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
            size += len(block)
    return {"bytes": size, "sha256": digest.hexdigest()}


def _record(folder: Path, batch: int, start: int, stop: int, chunk: Path) -> None:
    """Append the chunk's ledger entry (its points and fingerprint), flushed to the disk."""
    entry = {"batch": batch, "start": start, "stop": stop, **_fingerprint(chunk)}
    with open(folder / LEDGER, "a", encoding="utf-8") as handle:
        handle.write(json.dumps(entry, sort_keys=True) + "\n")
        handle.flush()
        os.fsync(handle.fileno())


def _ledger(folder: Path) -> dict[int, dict[str, Any]]:
    """The last entry of each batch (a torn last line of a killed run is skipped)."""
    entries: dict[int, dict[str, Any]] = {}
    with contextlib.suppress(FileNotFoundError), open(folder / LEDGER, encoding="utf-8", errors="replace") as lines:
        for line in lines:
            with contextlib.suppress(ValueError, TypeError, KeyError):
                entry = json.loads(line)
                entries[int(entry["batch"])] = entry
    return entries


def saved_points(folder: str | Path) -> tuple[int, int] | None:
    """(points whose chunk is in ``folder``, the sweep's points), read off its manifest and ledger without the
    lock (what an interrupted command says it leaves); None where the folder holds no sweep's manifest."""
    path = Path(folder)
    try:
        manifest = json.loads((path / MANIFEST).read_text(encoding="utf-8"))
        total = int(manifest["points"])
    except (OSError, ValueError, KeyError, TypeError):
        return None
    saved = 0
    for batch, entry in _ledger(path).items():
        if not (path / chunk_name(batch)).is_file():  # recorded, then renamed: one killed in between is not saved
            continue
        with contextlib.suppress(KeyError, TypeError, ValueError):
            saved += max(int(entry["stop"]) - int(entry["start"]), 0)
    return min(saved, total), total


def _check_chunks(store: SweepStore) -> None:
    """Keep the chunks that are whole and of this sweep's batches; remove (and list) the others."""
    ledger = _ledger(store.folder)
    for path in sorted(store.folder.iterdir()):
        match = _CHUNK.match(path.name)
        if not match:
            continue
        if not path.is_file() or path.is_symlink():  # a folder or a link by a chunk's name is not ours to remove
            raise DataError(
                f"-o {store.folder}: {path.name} is not a regular file (a folder, link or device by a chunk's name);"
                " remove or rename it, then run the same command again"
            )
        batch = int(match.group(1))
        why = _chunk_problem(store, batch, path, ledger.get(batch))
        if why is None:
            store.done.add(batch)
            continue
        store.damaged.append(f"{path.name} ({why})")
        path.unlink()


def _chunk_problem(store: SweepStore, batch: int, path: Path, entry: dict[str, Any] | None) -> str | None:
    """Why the chunk of ``batch`` cannot be kept, or None if it is whole and belongs here."""
    if batch >= store.batches:
        return f"batch {batch} is beyond the sweep's {store.batches} batches"
    start, stop = store.batch_range(batch)
    if entry is not None and (entry.get("start"), entry.get("stop")) == (start, stop):
        if _fingerprint(path) == {"bytes": entry.get("bytes"), "sha256": entry.get("sha256")}:
            return None
        return "its bytes differ from those written"
    why = _read_problem(store, path, start, stop)  # unrecorded (older folder, lost ledger) or recorded otherwise
    if why is None:
        _record(store.folder, batch, start, stop, path)
    return why


def _read_problem(store: SweepStore, path: Path, start: int, stop: int) -> str | None:
    """Read a chunk the ledger does not vouch for: the right schema and exactly points start..stop-1."""
    import pyarrow.parquet as pq

    from .models import get_model, key_units, result_columns

    try:
        table = pq.read_table(path)
    except Exception as exc:  # pyarrow raises ArrowInvalid, OSError, ... on a damaged file
        return f"unreadable: {type(exc).__name__}"
    model = get_model(store.spec.model)
    expected = arrow_schema(store.spec.keys, result_columns(model), key_units(model))
    if not table.schema.equals(expected, check_metadata=False):
        return "not the columns of this sweep"
    if table.column("point").to_pylist() != list(range(start, stop)):
        return f"not the points {start}..{stop - 1} of its batch"
    return None


def _manifest(store: SweepStore) -> dict[str, Any]:
    return {
        "format": FORMAT,
        "version": store.version,
        "points": store.spec.size,
        "batch_size": store.batch_size,
        "batches": store.batches,
        "columns": "point, the varied keys (SI), then the model's results; status is 'ok', 'failed' (the model"
        " stopped short; what it computed) or 'error' (no result)",
        "specification": json.loads(store.spec.to_json()),
        "units": manifest_units(store.spec),
    }


def manifest_units(spec: SweepSpec) -> dict[str, str]:
    """The SI unit of every value the manifest holds and of every column of the rows, by name (the package's JSON
    convention: the keys that have a unit, "1" for a pure number; text, flags and the point index have none):
    the fixed and varied keys, the settings' ``duration``, and the chunks' columns."""
    from ..columns import unit_of
    from .models import get_model, key_units, result_columns

    model = get_model(spec.model)
    known = key_units(model)
    names = [*spec.fixed, *spec.keys, *spec.settings, *result_columns(model)]
    units: dict[str, str] = {}
    for name in dict.fromkeys(names):
        try:
            unit = unit_of(name, known)
        except KeyError:  # a setting or a fixed index without a unit (rate-and-state's law)
            continue
        if unit is not None:
            units[name] = unit
    return units


def read_manifest(folder: str | Path) -> dict[str, Any]:
    """The manifest of a sweep output folder."""
    path = Path(folder) / MANIFEST
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DataError(f"{folder}: not a sweep output folder (no {MANIFEST})") from None
    except (OSError, ValueError) as exc:
        raise DataError(f"{path}: cannot be read as a sweep manifest ({exc})") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise DataError(f"{path}: not a stickslip sweep manifest (expected format {FORMAT})")
    return data


def checked_manifest(folder: Path) -> dict[str, Any]:
    """The manifest, with every field a resume relies on present and sane (else one line)."""
    data = read_manifest(folder)
    where = f"{folder / MANIFEST}"
    batch_size = data.get("batch_size")
    if isinstance(batch_size, bool) or not isinstance(batch_size, int) or batch_size < 1:
        raise DataError(f"{where}: batch_size is {batch_size!r}, not a positive whole number; --overwrite starts again")
    if not isinstance(data.get("version"), str):
        raise DataError(f"{where}: no version; --overwrite starts again")
    try:
        SweepSpec.from_dict(data["specification"])
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise DataError(
            f"{where}: the specification is missing or damaged ({type(exc).__name__}: {exc}); --overwrite starts again"
        ) from None
    return data


def _difference(old: Mapping[str, Any], spec: SweepSpec) -> str:
    """Name the first field in which two specifications differ, for the refusal message."""
    new = json.loads(spec.to_json())
    for key in ("model", "design", "axes", "samples", "seed", "settings", "fixed", "label"):
        if old.get(key) != new.get(key):
            if key == "fixed":
                changed = [k for k in sorted(set(old[key]) | set(new[key])) if old[key].get(k) != new[key].get(k)]
                return f"fixed value of {', '.join(changed[:3])} differs"
            if key == "axes":
                return f"varied {[a['key'] for a in old[key]]} with other values than now"
            return f"{key} {old.get(key)!r}, now {new.get(key)!r}"
    return "it differs"


def _remove_temporaries(folder: Path) -> None:
    """Half-written chunks of a killed run (never read: their names start with a dot)."""
    for path in folder.iterdir():
        if _TEMPORARY.match(path.name):
            with contextlib.suppress(OSError):
                path.unlink()
