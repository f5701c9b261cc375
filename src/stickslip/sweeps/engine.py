"""Running a sweep on dask.distributed: batches of points as tasks, chunks written as they finish.

A bounded window of batches is in flight, so no process holds more than a window of results; tasks are planned
by cost (:mod:`stickslip.sweeps.schedule`, a group of at most :data:`PLAN_POINTS` at a time), and a chunk is
written once all its points are back, its rows in point order (docs/sweep.md).
"""

from __future__ import annotations

import contextlib
import math
import os
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from functools import lru_cache
from pathlib import Path
from typing import Any

from ..errors import DataError, ParameterError, StickslipError
from .interrupts import POLL_SECONDS, deferred, stop_if_asked
from .models import get_model, key_units, result_columns, run_point
from .schedule import check_schedule, plan_tasks, usable_costs
from .spec import SweepSpec
from .store import SweepStore, arrow_schema

#: A batch holds at most this many points (a few seconds of work for the quasi-static cycle) ...
MAX_BATCH = 256
#: ... and a sweep is cut into at least this many batches, so that every worker has work and progress moves.
MIN_BATCHES = 64
#: Batches in flight per worker thread: enough to hide the round trip, few enough to bound memory.
WINDOW_PER_THREAD = 3
#: Points planned at a time by cost: the client holds the rows of at most about this many points whose chunk is not
#: yet complete, and estimates their costs (the time-dependent model's estimate takes a few ms a point) in one go.
PLAN_POINTS = 4096
#: ... the first group fewer, since the workers wait while it is estimated (the later ones are planned meanwhile).
FIRST_PLAN_POINTS = 512


def default_batch_size(points: int) -> int:
    """Points per task: independent of the cluster, so a resumed sweep cuts its batches the same way."""
    return max(1, min(MAX_BATCH, math.ceil(points / MIN_BATCHES)))


@lru_cache(maxsize=8)
def _spec(text: str) -> SweepSpec:
    return SweepSpec.from_json(text)


def run_batch(spec_json: str, start: int, stop: int) -> dict[str, list[Any]]:
    """The rows of points ``start .. stop-1``, as columns (runs on a worker)."""
    return run_points(spec_json, range(start, stop))


def run_points(spec_json: str, points: Sequence[int]) -> dict[str, list[Any]]:
    """The rows of the points ``points`` (in that order), as columns (runs on a worker)."""
    spec = _spec(spec_json)
    model = get_model(spec.model)
    varied = spec.points_at(list(points))
    columns: dict[str, list[Any]] = {"point": [int(p) for p in points]}
    columns.update({key: values.tolist() for key, values in varied.items()})
    names = list(result_columns(model))
    for name in names:
        columns[name] = []
    for k in range(len(columns["point"])):
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
    from .quiet import quiet_closing

    # a closed connection's traceback at the cluster's close (a worker's heartbeat in flight) is not the user's:
    # kept off the terminal here and in the workers (quiet.py), every other record shown as before
    with quiet_closing():
        yield from _client(workers, scheduler)


def _client(workers: int | None, scheduler: str | None) -> Iterator[Any]:
    import logging

    from distributed import Client, LocalCluster

    from . import quiet, worker_start

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
    with workers_without_ctrl_c() as hear:  # the workers started meanwhile never hear a terminal's Ctrl-C
        try:
            cluster = LocalCluster(
                n_workers=count,
                threads_per_worker=1,  # the model is Python and numpy on small arrays: processes, not threads
                processes=True,
                dashboard_address=None,
                scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},  # its status server on a free port, not 8787
                silence_logs=logging.ERROR,
                # each worker: its closed connections' records dropped (quiet), numba without its BLAS probe
                preload=[quiet.__name__, worker_start.__name__],
            )
        except RuntimeError as exc:  # typically a script without the __main__ guard that spawned processes need
            raise StickslipError(
                f"could not start {count} local dask worker processes ({exc}); a script that runs a sweep must call"
                " it under `if __name__ == '__main__':`, or use workers=0 to run in this process"
            ) from None
        with cluster:
            hear()
            with Client(cluster) as client:
                yield client


@contextlib.contextmanager
def workers_without_ctrl_c() -> Iterator[Callable[[], None]]:
    """SIGINT blocked in this thread while the block starts processes, and so in the threads it starts (distributed's
    event loop, which spawns the workers, and so in the workers); ``hear()`` unblocks it here.  This process still
    hears Ctrl-C meanwhile (another of its threads takes it, and Python raises it in the main thread).

    A terminal sends Ctrl-C to every process of its foreground group: each worker process died of it with
    multiprocessing's traceback ("Process Dask Worker process (from Nanny): ... KeyboardInterrupt") and its nanny
    logged a CancelledError's, between the progress and "stickslip: aborted".  Spawned with SIGINT blocked, a
    worker inherits the mask and never hears it; this process does, and closes the cluster, which ends them.
    """
    import signal
    from multiprocessing import resource_tracker

    block = getattr(signal, "pthread_sigmask", None)
    if block is None:  # pragma: no cover - POSIX has it
        yield lambda: None
        return
    # multiprocessing starts its resource tracker with the first worker, blocking then unblocking SIGINT in the
    # thread that starts it (bpo-33613), which lifted this block before the workers were spawned: started here first
    resource_tracker.ensure_running()
    before = block(signal.SIG_BLOCK, {signal.SIGINT})
    restored = False

    def hear() -> None:
        nonlocal restored
        if not restored:
            restored = True
            block(signal.SIG_SETMASK, before)

    try:
        yield hear
    finally:
        hear()


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
    schedule: str = "cost",
) -> int:
    """Run every batch whose chunk is missing; ``progress(points)`` as rows come back.  Returns the chunks written.

    On a cluster, ``schedule="cost"`` submits the points dearest first in shrinking tasks, one task per worker
    thread in flight when the model estimates costs, so that a free worker always takes the next (list
    scheduling, see :mod:`stickslip.sweeps.schedule`); ``"given"`` submits one task per chunk in point order, a
    window of :data:`WINDOW_PER_THREAD` per thread (the order before issue 31).  Either writes the same chunks.
    """
    schedule = check_schedule(schedule)
    spec_json = store.spec.to_json()
    done = store.finished()
    todo = (batch for batch in range(store.batches) if batch not in done)  # lazily: memory flat in the batches
    if client is None:  # in this process: for tiny sweeps and tests of the writer
        ran = 0
        for batch in todo:
            start, stop = store.batch_range(batch)
            store.write(batch, to_table(store.spec, run_batch(spec_json, start, stop)))
            progress(stop - start)
            ran += 1
        return ran
    threads = sum(client.nthreads().values()) or 1
    if schedule == "given":
        tasks: Iterator[Sequence[int]] = (range(*store.batch_range(batch)) for batch in todo)
        return _run_window(store, client, tasks, WINDOW_PER_THREAD * threads, progress)
    tasks = cost_ordered_tasks(store, todo, threads, store.spec.size - store.rows_done(done))
    # costs that differ: one task per thread, so each goes to the first worker free (a dear task queued behind
    # another would wait while a worker idles); all alike, or one worker: a window, so a queued task hides the
    # round trip (measured: one worker without it lost 2-3 % of its time)
    ordered = get_model(store.spec.model).estimates_cost and threads > 1
    window = threads if ordered else WINDOW_PER_THREAD * threads
    return _run_window(store, client, tasks, window, progress)


def cost_ordered_tasks(store: SweepStore, batches: Iterable[int], workers: int, points: int) -> Iterator[list[int]]:
    """The ``points`` points of ``batches`` as tasks planned by cost, a group at a time (lazily).

    The first group is :data:`FIRST_PLAN_POINTS` (the workers wait while it is estimated), the others
    :data:`PLAN_POINTS`, each estimated and planned in a thread while the group before it runs.
    """
    from concurrent.futures import ThreadPoolExecutor

    model = get_model(store.spec.model)
    groups = _groups(store, iter(batches), points)
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="stickslip-plan") as planner:
        ahead = next(groups, None)
        planning = None if ahead is None else planner.submit(_plan, store, model, *ahead, workers)
        while planning is not None:
            tasks = _waited(planning)
            ahead = next(groups, None)
            planning = None if ahead is None else planner.submit(_plan, store, model, *ahead, workers)
            yield from tasks


def _waited(planning: Any) -> Any:
    """The planner's result, looking for a noted Ctrl-C meanwhile (a group's costs can take seconds to estimate)."""
    from concurrent.futures import TimeoutError as NotYet  # (the built-in TimeoutError from Python 3.11 on)

    while True:
        stop_if_asked()
        try:
            return planning.result(timeout=POLL_SECONDS)
        except NotYet:
            continue


def _groups(store: SweepStore, batches: Iterator[int], points: int) -> Iterator[tuple[list[int], int]]:
    """(the points of the next group of whole chunks, the points after it)."""
    later, size = points, FIRST_PLAN_POINTS
    group: list[int] = []
    for batch in batches:
        group.extend(range(*store.batch_range(batch)))
        if len(group) >= size:
            later = max(later - len(group), 0)
            yield group, later
            group, size = [], PLAN_POINTS
    if group:
        yield group, 0


def _plan(store: SweepStore, model: Any, group: list[int], later: int, workers: int) -> list[list[int]]:
    """One group's tasks; the points after it (``later``) count at the group's mean cost, so that the tasks shrink
    only toward the end of the sweep, not of each group."""
    costs = usable_costs(point_costs(store.spec, model, group))
    after = later * sum(costs) / len(costs)
    return [[group[k] for k in task] for task in plan_tasks(costs, workers, store.batch_size, after=after)]


def point_costs(spec: SweepSpec, model: Any, points: Sequence[int]) -> list[float | None]:
    """The model's estimate of each point's CPU seconds (None for each when the model gives none)."""
    if not model.estimates_cost:
        return [None] * len(points)
    varied = spec.points_at(list(points))
    return [
        model.cost({**spec.fixed, **{key: float(v[k]) for key, v in varied.items()}}, spec.settings)
        for k in range(len(points))
    ]


def _run_window(
    store: SweepStore, client: Any, tasks: Iterator[Sequence[int]], window: int, progress: Callable[[int], None]
) -> int:
    """Keep ``window`` tasks in flight; each result is filed under its chunk, written once whole."""
    from distributed import as_completed

    spec_json = store.spec.to_json()
    chunks = _Chunks(store)

    def submit(points: Sequence[int]) -> Any:
        future = client.submit(run_points, spec_json, points, pure=False)
        future.points = points  # type: ignore[attr-defined]
        return future

    with deferred():  # a Ctrl-C meanwhile is raised by the loop (interrupts.py), never lost in a gc callback
        finished = as_completed([submit(t) for _, t in zip(range(window), tasks, strict=False)])
        for future in _completed(finished):
            following = next(tasks, None)
            if following is not None:  # before fetching and writing the rows: the freed worker starts at once
                finished.add(submit(following))
            try:
                columns = future.result()
            except Exception as exc:  # a worker died or the cluster went away: what is written stays written
                raise StickslipError(
                    f"points {_shown_points(future.points)} failed on the cluster ({type(exc).__name__}: {exc});"
                    " run the same command again to resume"
                ) from None
            future.release()
            chunks.add(columns)
            progress(len(columns["point"]))
    if chunks.parts:  # pragma: no cover - every point of every chunk run was in some task
        raise StickslipError(f"sweep: chunks {sorted(chunks.parts)[:3]} were left incomplete; run it again")
    return chunks.written


def _completed(finished: Any) -> Iterator[Any]:
    """The futures of ``finished`` (distributed's as_completed) as they complete, looking for a noted Ctrl-C every
    :data:`~stickslip.sweeps.interrupts.POLL_SECONDS` meanwhile (``next(finished)`` alone waits until one does)."""
    condition = getattr(finished, "thread_condition", None)  # notified by as_completed as each future completes
    while True:
        stop_if_asked()
        if finished.has_ready():
            yield next(finished)
        elif finished.is_empty():
            return
        elif condition is None:  # pragma: no cover - distributed's as_completed has it
            time.sleep(POLL_SECONDS / 4)
        else:
            with condition:
                if not finished.has_ready():
                    condition.wait(timeout=POLL_SECONDS)


def _shown_points(points: Sequence[int]) -> str:
    if isinstance(points, range) or list(points) == list(range(points[0], points[-1] + 1)):
        return f"{points[0]}..{points[-1]}"
    return ", ".join(map(str, points[:4])) + (f" and {len(points) - 4} more" if len(points) > 4 else "")


class _Chunks:
    """Rows back from tasks, held per chunk until the chunk's every point is there; then written in point order."""

    def __init__(self, store: SweepStore) -> None:
        self.store = store
        self.parts: dict[int, list[dict[str, list[Any]]]] = {}
        self.rows: dict[int, int] = {}
        self.written = 0

    def add(self, columns: dict[str, list[Any]]) -> None:
        size = self.store.batch_size
        by_batch: dict[int, list[int]] = {}
        for row, point in enumerate(columns["point"]):
            by_batch.setdefault(point // size, []).append(row)
        for batch, rows in by_batch.items():
            part = {name: [values[r] for r in rows] for name, values in columns.items()}
            self.parts.setdefault(batch, []).append(part)
            self.rows[batch] = self.rows.get(batch, 0) + len(rows)
            start, stop = self.store.batch_range(batch)
            if self.rows[batch] == stop - start:
                self.store.write(batch, to_table(self.store.spec, self._whole(batch)))
                self.written += 1

    def _whole(self, batch: int) -> dict[str, list[Any]]:
        parts = self.parts.pop(batch)
        del self.rows[batch]
        merged = {name: [value for part in parts for value in part[name]] for name in parts[0]}
        order = sorted(range(len(merged["point"])), key=merged["point"].__getitem__)
        return {name: [values[k] for k in order] for name, values in merged.items()}


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
