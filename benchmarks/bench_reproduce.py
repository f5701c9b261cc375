"""Benchmark: what ``stickslip reproduce`` costs, wall and CPU (user + system, its forked workers included), issue 31.

Each build runs as a fresh subprocess into a new temporary folder, ``--repeat`` times after one warm-up run
(which also fills the numba cache); the script prints the best and the median wall time and CPU time.  Beside
``stickslip reproduce`` (figures drawn in two forked processes) it times the plain reference, the same report
built in one process (``build_report(workers=1)``): the same files, no fork, so the difference between the two
CPU columns is what the parallel drawing costs.  The target is <= 7 s CPU for ``stickslip reproduce``.

    python benchmarks/bench_reproduce.py [--repeat N] [--compare OTHER_SRC] [--only reproduce|one-process]

The package is taken from this checkout's ``src/``, with its bytecode (``PYTHONDONTWRITEBYTECODE`` is dropped, as
in bench_startup.py).  ``--compare`` times a second copy of the package (e.g. an
older commit unpacked with ``git archive COMMIT src | tar -x -C /tmp/old``, then ``--compare /tmp/old/src``) in
the same run, build by build in turn, so that both see the same machine load.  Issue 31's baseline is commit
1e04c4c (15.0 s CPU quiet when the issue was filed; README's speed table has this round's figures beside it).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import tempfile
from pathlib import Path

from timing import child_run, package_environments

ROOT = Path(__file__).resolve().parent.parent
REPRODUCE = [sys.executable, "-m", "stickslip.cli.main", "reproduce", "--quiet", "-o"]
ONE_PROCESS = [sys.executable, "-c", "import sys; from stickslip.report import build_report; "
               "build_report(sys.argv[1], workers=1)"]  # fmt: skip
CASES = {
    "reproduce": ("stickslip reproduce (target <= 7 s CPU)", REPRODUCE),
    "one-process": ("build_report(workers=1) (reference)", ONE_PROCESS),
}


def run_once(command: list[str], env: dict[str, str]) -> tuple[float, float]:
    """(wall time, CPU time of the child and its children) of one build into a new folder; it must succeed."""
    with tempfile.TemporaryDirectory(prefix="bench-reproduce-") as folder:
        return child_run([*command, str(Path(folder) / "report")], env)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="timed builds per case")
    parser.add_argument("--compare", type=Path, default=None, help="another src/ folder to time beside this one")
    parser.add_argument("--only", choices=sorted(CASES), default=None, help="time this case alone")
    args = parser.parse_args()
    sources = {"": ROOT / "src"} if args.compare is None else {"this: ": ROOT / "src", "other: ": args.compare}
    envs = package_environments(sources)
    machine = f"Python {platform.python_version()} on {platform.machine()}, {os.cpu_count()} cores"
    print(f"{machine}; {args.repeat} builds each after a warm-up, wall and CPU (user + system, children included)")
    print(f"{'build':50s} {'best':>8s} {'median':>8s} {'cpu best':>9s} {'cpu med':>8s}")
    for label, command in [CASES[args.only]] if args.only else CASES.values():
        for env in envs.values():
            run_once(command, env)  # warm the numba cache, the file cache and the bytecode
        times: dict[str, list[tuple[float, float]]] = {source: [] for source in envs}
        for _ in range(args.repeat):  # in turn, so that every copy sees the same load
            for source, env in envs.items():
                times[source].append(run_once(command, env))
        for source, measured in times.items():
            walls, cpus = zip(*measured, strict=True)
            print(
                f"{source + label:50s} {min(walls):7.2f}s {statistics.median(walls):7.2f}s"
                f" {min(cpus):8.2f}s {statistics.median(cpus):7.2f}s"
            )


if __name__ == "__main__":
    main()
