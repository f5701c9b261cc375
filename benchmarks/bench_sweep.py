"""Sweep throughput: 10,000 quasi-static points on a local dask cluster, beside a plain loop of ``simulate`` calls.

The grid is the report's phase diagram: V0 = 5 µm/s … 5 mm/s (log) by the
block stiffness G/h × 0.1 … × 10 of gelatin-glass (log), 100 s per run.

* the plain reference: ``simulate`` called point after point in this process, on
  an evenly spread subset of the same grid (per-point cost, best and median of 3);
* the sweep: all points on a LocalCluster of 2 worker processes, chunks written
  to Parquet; wall time, this process's CPU time and the workers' CPU time;
* the speed-up from 1 to 2 workers on a smaller sweep (cluster start-up timed apart).

Run: ``PYTHONPATH=src python benchmarks/bench_sweep.py [--points 10000] [--small 2000]``.
"""

from __future__ import annotations

import argparse
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
    parser.add_argument("--points", type=int, default=10_000)
    parser.add_argument("--small", type=int, default=2_000, help="points of the 1-vs-2-worker comparison")
    parser.add_argument("--speedup-only", action="store_true", help="only the 1-vs-2-worker comparison")
    args = parser.parse_args()
    spec = build_spec(grid(args.points))
    small = build_spec(grid(args.small))
    if not args.speedup_only:
        big_sweep(spec)
    speedup(small)


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
