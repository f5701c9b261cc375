"""The output folder of a sweep: a manifest and one Parquet chunk per finished batch.

``OUT/_manifest.json`` holds the specification, the package version and the
batch size; ``OUT/part-000123.parquet`` holds batch 123.  Each chunk appears
under its name only when whole (written under a temporary ``.part-...``
name, then renamed), so a chunk that exists is done, and resuming is "run
the batches whose chunk is missing": after ``kill -9`` at any moment nothing
is lost, nothing is duplicated and nothing is half-written.  Parquet readers
skip names that start with ``_`` or ``.``, so ``pandas.read_parquet(OUT)``
reads exactly the finished rows.
"""

from __future__ import annotations

import contextlib
import json
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import DataError, ParameterError
from ..fileio import atomic_path, atomic_write_text
from .spec import SweepSpec

MANIFEST = "_manifest.json"
FORMAT = "stickslip-sweep/1"
_CHUNK = re.compile(r"^part-(\d{6,})\.parquet$")
_TEMPORARY = re.compile(r"^\.(part-\d{6,}\.parquet|_manifest\.json)\..*\.tmp$")


def chunk_name(batch: int) -> str:
    return f"part-{batch:06d}.parquet"


def arrow_schema(inputs: tuple[str, ...], columns: Mapping[str, str]) -> Any:
    """The one schema of every chunk: point index, inputs (SI floats), then the model's columns."""
    import pyarrow as pa

    kinds = {"float": pa.float64(), "int": pa.int64(), "str": pa.string()}
    fields = [pa.field("point", pa.int64())]
    fields += [pa.field(key, pa.float64()) for key in inputs]
    fields += [pa.field(name, kinds[kind]) for name, kind in columns.items()]
    return pa.schema(fields)


@dataclass
class SweepStore:
    """An output folder opened for one specification."""

    folder: Path
    spec: SweepSpec
    batch_size: int
    version: str

    @property
    def batches(self) -> int:
        return -(-self.spec.size // self.batch_size)

    def batch_range(self, batch: int) -> tuple[int, int]:
        start = batch * self.batch_size
        return start, min(start + self.batch_size, self.spec.size)

    def finished(self) -> set[int]:
        """Batches whose chunk exists (whole, by construction)."""
        done = set()
        for path in self.folder.iterdir():
            match = _CHUNK.match(path.name)
            if match and int(match.group(1)) < self.batches:
                done.add(int(match.group(1)))
        return done

    def rows_done(self, done: set[int]) -> int:
        return sum(stop - start for start, stop in map(self.batch_range, done))

    def write(self, batch: int, table: Any) -> Path:
        """Write one batch's rows (a pyarrow Table) as its chunk, atomically."""
        import pyarrow.parquet as pq

        target = self.folder / chunk_name(batch)
        with atomic_path(target) as temp:
            pq.write_table(table, temp)
        return target


def open_store(folder: str | Path, spec: SweepSpec, batch_size: int, overwrite: bool = False) -> SweepStore:
    """Create ``folder`` for ``spec``, or reopen it to resume; refuse a folder made for another specification."""
    from .. import __version__

    path = Path(folder)
    if path.exists() and not path.is_dir():
        raise DataError(f"-o {folder}: is a file; a sweep writes a folder of Parquet chunks")
    path.mkdir(parents=True, exist_ok=True)
    _remove_temporaries(path)
    foreign = sorted(p.name for p in path.iterdir() if p.name != MANIFEST and not _CHUNK.match(p.name))
    if foreign:
        raise DataError(
            f"-o {folder}: holds files that are not a sweep's ({', '.join(foreign[:3])}); choose a new or empty folder"
        )
    manifest = read_manifest(path) if (path / MANIFEST).exists() else None
    if manifest is not None and not overwrite:
        if manifest["specification"] != json.loads(spec.to_json()):
            why = f"another specification ({_difference(manifest['specification'], spec)})"
        elif manifest["version"] != __version__:
            why = f"the same specification but stickslip {manifest['version']} (this is {__version__})"
        else:
            return SweepStore(path, spec, int(manifest["batch_size"]), __version__)
        raise ParameterError(
            f"-o {folder}: holds a sweep of {why}; give another output folder, or --overwrite to replace it"
        )
    if manifest is None and any(_CHUNK.match(p.name) for p in path.iterdir()) and not overwrite:
        raise DataError(f"-o {folder}: holds Parquet chunks but no {MANIFEST}; give --overwrite to replace them")
    for old in path.iterdir():
        if _CHUNK.match(old.name) or old.name == MANIFEST:
            old.unlink()
    store = SweepStore(path, spec, batch_size, __version__)
    atomic_write_text(path / MANIFEST, json.dumps(_manifest(store), indent=2) + "\n")
    return store


def _manifest(store: SweepStore) -> dict[str, Any]:
    return {
        "format": FORMAT,
        "version": store.version,
        "points": store.spec.size,
        "batch_size": store.batch_size,
        "batches": store.batches,
        "columns": "point, the varied keys (SI), then the model's results; status is 'ok' or 'error'",
        "specification": json.loads(store.spec.to_json()),
    }


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
