"""Running a sweep on dask.distributed: batches of points as tasks, chunks written as they finish.

The client keeps a bounded window of batches in flight (a few per worker
thread) and submits the next one whenever one finishes, so neither the
client, the scheduler nor any worker ever holds more than a window of
results: a 10^7-point sweep needs no more memory than a 10^3-point one.
Each finished batch goes straight to its Parquet chunk.
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Callable, Iterator
from functools import lru_cache
from pathlib import Path
from typing import Any

from ..errors import DataError, ParameterError, StickslipError
from .models import get_model, key_units, result_columns, run_point
from .spec import SweepSpec
from .store import SweepStore, arrow_schema

#: A batch holds at most this many points (a few seconds of work for the quasi-static cycle) ...
MAX_BATCH = 256
#: ... and a sweep is cut into at least this many batches, so that every worker has work and progress moves.
MIN_BATCHES = 64
#: Batches in flight per worker thread: enough to hide the round trip, few enough to bound memory.
WINDOW_PER_THREAD = 3


def default_batch_size(points: int) -> int:
    """Points per task: independent of the cluster, so a resumed sweep cuts its batches the same way."""
    return max(1, min(MAX_BATCH, math.ceil(points / MIN_BATCHES)))


@lru_cache(maxsize=8)
def _spec(text: str) -> SweepSpec:
    return SweepSpec.from_json(text)


def run_batch(spec_json: str, start: int, stop: int) -> dict[str, list[Any]]:
    """The rows of points ``start .. stop-1``, as columns (runs on a worker)."""
    spec = _spec(spec_json)
    model = get_model(spec.model)
    varied = spec.points(start, stop)
    columns: dict[str, list[Any]] = {"point": list(range(start, stop))}
    columns.update({key: values.tolist() for key, values in varied.items()})
    names = list(result_columns(model))
    for name in names:
        columns[name] = []
    for k in range(stop - start):
        values = {**spec.fixed, **{key: float(v[k]) for key, v in varied.items()}}
        row = run_point(model, values, spec.settings)
        for name in names:
            columns[name].append(row.get(name))
    return columns


def to_table(spec: SweepSpec, columns: dict[str, list[Any]]) -> Any:
    """A batch's columns as a pyarrow Table of the sweep's one schema."""
    import pyarrow as pa

    model = get_model(spec.model)
    return pa.Table.from_pydict(columns, schema=arrow_schema(spec.keys, result_columns(model), key_units(model)))


def check_scheduler_address(scheduler: str) -> None:
    """Refuse an address that is not one (before any folder is touched or cluster contacted)."""
    from distributed.comm.addressing import get_address_host_port, parse_address

    try:
        scheme, _ = parse_address(scheduler)
        if scheme in ("tcp", "tls", "ws", "wss"):
            get_address_host_port(scheduler)
    except (ValueError, TypeError) as exc:
        raise ParameterError(
            f"--scheduler {scheduler}: not a scheduler address ({exc}); expected e.g. tcp://HOST:8786"
        ) from None


@contextlib.contextmanager
def dask_client(workers: int | None = None, scheduler: str | None = None) -> Iterator[Any]:
    """A client of the cluster at ``scheduler``, or of a local cluster of ``workers`` processes started here."""
    import logging

    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="20s")
        except (OSError, TimeoutError, ValueError, TypeError) as exc:  # ValueError: not an address at all
            raise StickslipError(f"--scheduler {scheduler}: cannot connect ({exc})") from None
        with client:
            yield client
        return
    count = workers if workers is not None else (os.cpu_count() or 1)
    if count < 1:
        raise StickslipError(f"--workers: expected at least 1 worker process, got {count}")
    try:
        cluster = LocalCluster(
            n_workers=count,
            threads_per_worker=1,  # the model is Python and numpy on small arrays: processes, not threads
            processes=True,
            dashboard_address=None,
            scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},  # its status server on a free port, not 8787
            silence_logs=logging.ERROR,
        )
    except RuntimeError as exc:  # typically a script without the __main__ guard that spawned processes need
        raise StickslipError(
            f"could not start {count} local dask worker processes ({exc}); a script that runs a sweep must call it"
            " under `if __name__ == '__main__':`, or use workers=0 to run in this process"
        ) from None
    with cluster, Client(cluster) as client:
        yield client


#: Seconds a local cluster takes to start and ship the first batches (measured on the 2-core machine: a 60-point
#: quasi-static sweep took 11 s on 2 workers and 2.3 s in this process); a sweep whose remaining work in this
#: process is projected below it never starts one.
CLUSTER_START_SECONDS = 5.0


def compute_while_cheap(store: SweepStore, progress: Callable[[int], None]) -> bool:
    """Run batches in this process while the rest is projected to take less than starting a cluster would;
    True when every batch is done (no cluster needed), False when the rest is worth a cluster."""
    import time

    spec_json = store.spec.to_json()
    todo = [batch for batch in range(store.batches) if batch not in store.finished()]
    per_point = None  # from the latest batch: the first pays one-off costs (imports, compiled kernels, caches)
    for k, batch in enumerate(todo):
        if k >= 2 and per_point is not None:  # judged from the second batch on
            rest = sum(stop - start for start, stop in map(store.batch_range, todo[k:]))
            if per_point * rest > CLUSTER_START_SECONDS:
                return False
        start, stop = store.batch_range(batch)
        began = time.perf_counter()
        store.write(batch, to_table(store.spec, run_batch(spec_json, start, stop)))
        per_point = (time.perf_counter() - began) / (stop - start)
        progress(stop - start)
    return True


def compute(
    store: SweepStore,
    client: Any | None,
    progress: Callable[[int], None],
) -> int:
    """Run every batch whose chunk is missing; ``progress(points)`` after each one.  Returns the batches run."""
    spec_json = store.spec.to_json()
    done = store.finished()
    todo = (batch for batch in range(store.batches) if batch not in done)  # lazily: memory flat in the batches
    ran = 0
    if client is None:  # in this process: for tiny sweeps and tests of the writer
        for batch in todo:
            start, stop = store.batch_range(batch)
            store.write(batch, to_table(store.spec, run_batch(spec_json, start, stop)))
            progress(stop - start)
            ran += 1
        return ran
    from distributed import as_completed

    threads = sum(client.nthreads().values()) or 1
    pending = todo

    def submit(batch: int) -> Any:
        start, stop = store.batch_range(batch)
        future = client.submit(run_batch, spec_json, start, stop, pure=False)
        future.batch = batch  # type: ignore[attr-defined]
        return future

    window = [submit(b) for _, b in zip(range(WINDOW_PER_THREAD * threads), pending, strict=False)]
    finished = as_completed(window)
    for future in finished:
        batch = future.batch
        try:
            columns = future.result()
        except Exception as exc:  # a worker died or the cluster went away: what is written stays written
            raise StickslipError(
                f"batch {batch} failed on the cluster ({type(exc).__name__}: {exc}); run the same command again"
                " to resume"
            ) from None
        store.write(batch, to_table(store.spec, columns))
        future.release()
        progress(len(columns["point"]))
        ran += 1
        following = next(pending, None)
        if following is not None:
            finished.add(submit(following))
    return ran


def read_results(folder: str | Path) -> Any:
    """The rows written so far, sorted by point, as a pandas DataFrame."""

    from .store import is_chunk

    if not any(is_chunk(p.name) for p in Path(folder).iterdir()):
        raise DataError(f"{folder}: no finished batch yet (no part-*.parquet); run or resume the sweep first")
    from ..columns import read_parquet

    try:
        frame = read_parquet(folder)
    except StickslipError:
        raise
    except (OSError, ValueError) as exc:  # pyarrow.ArrowInvalid (a ValueError) on a truncated or foreign chunk
        raise DataError(
            f"{folder}: a Parquet chunk cannot be read ({type(exc).__name__}: {exc}); run the same sweep command"
            " again to check the chunks and recompute the damaged ones"
        ) from None
    units = frame.attrs["units"]
    frame = frame.sort_values("point", kind="stable").reset_index(drop=True)
    frame.attrs["units"] = units  # the units each chunk's schema names (stickslip.columns)
    return frame
