"""Sweep schedules and throughput: the cost-ordered schedule beside the plain order, on 1 and 2 workers.

Default (issue 31): for each sweep, on a fresh LocalCluster of 1 and of 2 worker processes, the plain order
(``schedule="given"``: one task per chunk, in point order, as before issue 31) and the cost order (the dearest
points first by the model's estimate, in tasks that shrink toward the end), interleaved and repeated, so that
whatever else loads the machine loads both alike.  Each run gives the wall time of the sweep (cluster start
apart), the CPU of the workers and of this process, and the parallel efficiency (sum of the rows' point
times / (workers x wall)).  The sweeps:

* transient: the README's (V0, K) phase diagram with the stick chains, V0 20 µm/s–1 mm/s by K 40 kPa/m–4 MPa/m
  (log), smaller by default (``--transient 10x5``, 10 s runs): the same shape of cost, a few stick–slip points at
  the stiffest blocks, last in point order, among cheap steady ones (``--transient 20x10 --duration 30`` is the
  README's own);
* quasi-static: a V0 × stiffness grid of 100 s runs (``--quasi-static 1600`` points), cost uniform: the plan
  keeps the chunks and shrinks only the last tasks.

``--throughput``: the former benchmark, 10,000 quasi-static points on 2 workers beside a plain loop of
``simulate`` calls, and the speed-up from 1 to 2 workers (``--points``, ``--small``, ``--speedup-only``).

Run: ``PYTHONPATH=src python benchmarks/bench_sweep.py [--repeats 2] [--transient 10x5] [--quasi-static 1600]``.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import tempfile
import time
from pathlib import Path

from stickslip import load_parameters, simulate
from stickslip.quasistatic.jump import branch_interpolant, cached_critical_point
from stickslip.sweeps import build_spec
from stickslip.sweeps.engine import compute, dask_client, default_batch_size
from stickslip.sweeps.store import open_store

G_OVER_H = load_parameters().block.stiffness


def grid(points: int) -> list[str]:
    side = round(math.sqrt(points))
    return [
        f"pulling_velocity=5 um/s..5 mm/s:{side}:log",
        f"block.stiffness={0.1 * G_OVER_H!r} Pa/m..{10 * G_OVER_H!r} Pa/m:{max(1, points // side)}:log",
    ]


def plain_loop(spec, rows: int) -> tuple[list[float], float]:
    """Per-point wall times of ``simulate`` over ``rows`` whole rows of the grid (3 passes), and CPU per point.

    A row is one stiffness at every velocity, as a sweep's batch sees it; the per-set caches are emptied
    before each pass, so the critical point is paid once per row, as on a worker.
    """
    params = load_parameters()
    width = len(spec.axes[0].values)
    values = spec.points(0, spec.size)
    starts = [round(k * (spec.size // width) / rows) * width for k in range(rows)]
    picks = [s + j for s in starts for j in range(width)]
    walls, cpu = [], math.inf
    for _ in range(3):
        cached_critical_point.cache_clear()
        branch_interpolant.cache_clear()
        start, cpu_start = time.perf_counter(), time.process_time()
        for k in picks:
            p = params.with_overrides({"block.height": params.block.shear_modulus / values["block.stiffness"][k]})
            simulate(p, float(values["pulling_velocity"][k]), 100.0)
        walls.append((time.perf_counter() - start) / len(picks))
        cpu = min(cpu, (time.process_time() - cpu_start) / len(picks))
    return walls, cpu


def run(spec, workers: int) -> dict[str, float]:
    """Start a cluster, run the sweep into a fresh folder, stop; times in s."""
    with tempfile.TemporaryDirectory() as folder:
        store = open_store(Path(folder) / "out", spec, default_batch_size(spec.size))
        began = time.perf_counter()
        with dask_client(workers) as client:
            started = time.perf_counter()
            worker_cpu = client.run(time.process_time)
            cpu = time.process_time()
            compute(store, client, lambda _: None)
            wall = time.perf_counter() - started
            client_cpu = time.process_time() - cpu
            after = client.run(time.process_time)
        size = sum(p.stat().st_size for p in (Path(folder) / "out").iterdir())
        return {
            "bytes_per_row": size / spec.size,
            "start": started - began,
            "wall": wall,
            "client_cpu": client_cpu,
            "worker_cpu": sum(after[w] - worker_cpu[w] for w in after),
        }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2, help="rounds of the schedule comparison")
    parser.add_argument("--transient", default="10x5", help="V0 x K points of the transient sweep ('0': none)")
    parser.add_argument("--duration", type=float, default=10.0, help="s per transient run")
    parser.add_argument("--quasi-static", type=int, default=1600, help="points of the quasi-static sweep (0: none)")
    parser.add_argument("--workers", default="1,2", help="worker counts, comma-separated")
    parser.add_argument("--throughput", action="store_true", help="the former 10,000-point throughput benchmark")
    parser.add_argument("--predict", metavar="OUT", help="a finished sweep folder: makespans on --predict-workers")
    parser.add_argument("--predict-workers", default="1,2,4,8,16")
    parser.add_argument(
        "--worker-start", type=float, default=0.0, help="s each worker's first point pays for its start (--predict)"
    )
    parser.add_argument("--points", type=int, default=10_000)
    parser.add_argument("--small", type=int, default=2_000, help="points of the 1-vs-2-worker comparison")
    parser.add_argument("--speedup-only", action="store_true", help="only the 1-vs-2-worker comparison")
    args = parser.parse_args()
    if args.predict:
        predict(Path(args.predict), [int(w) for w in args.predict_workers.split(",")], args.worker_start)
        return
    if args.throughput or args.speedup_only:
        if not args.speedup_only:
            big_sweep(build_spec(grid(args.points)))
        speedup(build_spec(grid(args.small)))
        return
    sweeps = []
    if args.transient != "0":
        sweeps.append(("transient", transient_spec(args.transient, args.duration)))
    if args.quasi_static:
        sweeps.append(("quasi-static", build_spec(grid(args.quasi_static))))
    counts = [int(w) for w in args.workers.split(",")]
    for name, spec in sweeps:
        compare_schedules(name, spec, counts, args.repeats)


def predict(folder: Path, counts: list[int], worker_start: float = 0.0) -> None:
    """Makespans of a finished sweep on more workers than this machine has, from its rows' measured point times.

    List scheduling (each task to the worker free first) of the plain order's tasks (the chunks in point order)
    and of the cost plan (ordered by the model's estimate, timed by the measured times), beside the bound
    max(sum / workers, longest point): the longest point is the critical path no schedule shortens.

    ``worker_start`` (s, measured apart: a point's time as a fresh process's first less its time warm) is what
    each worker's first point pays for the worker's own start (numba's, for the time-dependent model).  The
    measured run's workers paid it on their first points (the first task of each, by the run's own schedule in
    ``_run.json``): it is taken off those, and every predicted worker pays it once before its first task.  Two
    efficiencies follow: the summary's (a worker starting counts as busy) and the work's (the points' own time
    over the cores' time).
    """
    from stickslip.sweeps import load_sweep
    from stickslip.sweeps.engine import point_costs
    from stickslip.sweeps.models import get_model
    from stickslip.sweeps.schedule import plan_tasks, predicted_makespan, usable_costs
    from stickslip.sweeps.store import read_manifest

    frame, spec = load_sweep(folder)
    times = frame.sort_values("point")["wall_time"].tolist()
    size = read_manifest(folder)["batch_size"]
    began = time.process_time()
    estimates = usable_costs(point_costs(spec, get_model(spec.model), range(spec.size)))
    spent = time.process_time() - began
    print(f"{folder}: {spec.size} points, chunks of {size}; point times: sum {sum(times):.1f} s, longest"
          f" {max(times):.1f} s; the estimates took {spent:.2f} s CPU")  # fmt: skip
    if worker_start > 0:
        measured = json.loads((folder / "_run.json").read_text())
        if measured["schedule"] == "cost":
            firsts = [task[0] for task in plan_tasks(estimates, measured["workers"], size)[: measured["workers"]]]
        else:
            firsts = list(range(0, spec.size, size))[: measured["workers"]]
        for k in firsts:
            times[k] = max(times[k] - worker_start, 0.0)
        print(f"  each worker's start {worker_start:.2f} s: taken off the first points of the measured run's"
              f" {measured['workers']} workers (points {firsts}); the work alone: sum {sum(times):.1f} s,"
              f" longest {max(times):.2f} s")  # fmt: skip
    work = sum(times)
    chunks = [sum(times[i : i + size]) for i in range(0, spec.size, size)]
    for workers in counts:
        starts = workers * worker_start
        given = worker_start + predicted_makespan(chunks, workers)
        plan = plan_tasks(estimates, workers, size)
        cost = worker_start + predicted_makespan([sum(times[k] for k in task) for task in plan], workers)
        bound = worker_start + max(work / workers, max(times))
        line = (
            f"  {workers:3d} workers: plain order {given:.1f} s (efficiency {(work + starts) / (workers * given):.0%}),"
            f" cost order {cost:.1f} s ({(work + starts) / (workers * cost):.0%}); bound {bound:.1f} s"
            f" ({(work + starts) / (workers * bound):.0%})"
        )
        if worker_start > 0:
            line += f"; the work's own share of the cores, cost order: {work / (workers * cost):.0%}"
        print(line)


def transient_spec(shape: str, duration: float):
    """The README's transient (V0, K) plane at ``shape`` = 'NxM' points (V0 fastest: the stiff blocks come last)."""
    across, up = (int(n) for n in shape.lower().split("x"))
    return build_spec(
        [f"pulling_velocity=20 um/s..1 mm/s:{across}:log", f"block.stiffness=40 kPa/m..4 MPa/m:{up}:log"],
        model="transient",
        stick_population=True,
        duration=duration,
    )


def scheduled_run(spec, workers: int, schedule: str) -> dict[str, float]:
    """One sweep on a fresh LocalCluster of ``workers`` processes in ``schedule`` order; times in s."""
    import logging

    from distributed import Client, LocalCluster

    from stickslip.sweeps import run_sweep

    with tempfile.TemporaryDirectory() as folder:
        began = time.perf_counter()
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                          scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}, silence_logs=logging.ERROR
                          ) as cluster, Client(cluster) as client:  # fmt: skip
            started = time.perf_counter() - began
            before, cpu = client.run(time.process_time), time.process_time()
            store = run_sweep(spec, Path(folder) / "out", scheduler=cluster.scheduler_address, schedule=schedule)
            client_cpu = time.process_time() - cpu
            after = client.run(time.process_time)
        report = store.report
        return {
            "start": started,
            "wall": report.wall,
            "worker_cpu": sum(after[w] - before[w] for w in after),
            "client_cpu": client_cpu,
            "point_seconds": report.point_seconds,
            "efficiency": report.efficiency or 0.0,
        }


def warm_up(spec) -> None:
    """One point of each chunk's kind in this process first: the compiled kernels are then on disk (numba's cache),
    and every cluster run loads them alike instead of the first one compiling them."""
    from stickslip.sweeps.engine import run_points

    began = time.process_time()
    run_points(spec.to_json(), [0, spec.size - 1])
    print(f"  warm-up (2 points in this process, compiled kernels cached on disk): {time.process_time() - began:.1f} s")


def compare_schedules(name: str, spec, counts: list[int], repeats: int) -> None:
    """Both orders on each worker count, interleaved (the order of the two alternates between rounds)."""
    print(f"{name} sweep: {spec.size} points, batches of {default_batch_size(spec.size)}; {repeats} rounds")
    warm_up(spec)
    results: dict[tuple[int, str], list[dict[str, float]]] = {}
    for round_ in range(repeats):
        for workers in counts:
            orders = ("given", "cost") if round_ % 2 == 0 else ("cost", "given")
            for schedule in orders:
                got = scheduled_run(spec, workers, schedule)
                results.setdefault((workers, schedule), []).append(got)
                print(
                    f"  round {round_ + 1}, {workers} worker(s), {schedule:5s} order: wall {got['wall']:.1f} s"
                    f" (+ {got['start']:.1f} s cluster start), CPU workers {got['worker_cpu']:.1f} s + client"
                    f" {got['client_cpu']:.1f} s, point time {got['point_seconds']:.1f} s,"
                    f" parallel efficiency {100 * got['efficiency']:.0f} %",
                    flush=True,
                )
    for (workers, schedule), runs in sorted(results.items()):
        walls = [r["wall"] for r in runs]
        efficiency = [100 * r["efficiency"] for r in runs]
        cpu = [r["worker_cpu"] + r["client_cpu"] for r in runs]
        print(
            f"{name}, {workers} worker(s), {schedule:5s} order: wall {min(walls):.1f}-{max(walls):.1f} s"
            f" (median {statistics.median(walls):.1f}), CPU {min(cpu):.1f}-{max(cpu):.1f} s, parallel efficiency"
            f" {min(efficiency):.0f}-{max(efficiency):.0f} %"
        )


def big_sweep(spec) -> None:
    print(f"sweep of {spec.size} quasi-static points (100 s runs), batches of {default_batch_size(spec.size)}")
    walls, cpu = plain_loop(spec, 5)
    print(
        f"plain loop of simulate (5 rows of the grid, 3 passes): best {min(walls) * 1e3:.1f} ms,"
        f" median {statistics.median(walls) * 1e3:.1f} ms per point wall; {cpu * 1e3:.1f} ms CPU"
        f" -> {spec.size} points in one process: {min(walls) * spec.size:.0f} s wall"
    )
    big = run(spec, 2)
    print(
        f"sweep, 2 workers: {big['wall']:.1f} s wall ({big['wall'] / spec.size * 1e3:.2f} ms per point)"
        f" + {big['start']:.1f} s cluster start; workers' CPU {big['worker_cpu']:.1f} s"
        f" ({big['worker_cpu'] / spec.size * 1e3:.1f} ms per point), this process's CPU {big['client_cpu']:.1f} s;"
        f" on 2 idle cores: about {big['worker_cpu'] / 2 + big['client_cpu'] / 2:.0f} s;"
        f" output {big['bytes_per_row']:.0f} bytes per row"
    )


def speedup(small) -> None:
    one, two = run(small, 1), run(small, 2)
    print(
        f"{small.size} points: 1 worker {one['wall']:.1f} s, 2 workers {two['wall']:.1f} s wall:"
        f" speed-up {one['wall'] / two['wall']:.2f} (workers' CPU {one['worker_cpu']:.1f} s and"
        f" {two['worker_cpu']:.1f} s; cluster start {one['start']:.1f} s and {two['start']:.1f} s)"
    )


if __name__ == "__main__":
    main()
