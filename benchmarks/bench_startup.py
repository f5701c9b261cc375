"""Benchmark: how long a ``stickslip`` command takes to start and finish, issue 9 section 5.

Each command runs as a fresh subprocess (as a user runs it), several times;
the script prints the best and the median wall time and the child's CPU time
(user + system), beside ``python -c pass`` (the interpreter alone) and
``python -c "import numpy"`` as the plain references.  The target is
<= 0.4 s for ``stickslip --help``, ``stickslip critical`` and ``stickslip curve``
with a few velocities.

    python benchmarks/bench_startup.py [--repeat N]

Run from the repository root; the package is taken from ``src/`` (or from an
installed stickslip when ``src/`` is absent).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
STICKSLIP = [sys.executable, "-m", "stickslip.cli.main"]
CASES = (
    ("python -c pass (reference)", [sys.executable, "-c", "pass"]),
    ('python -c "import numpy" (reference)', [sys.executable, "-c", "import numpy"]),
    ("stickslip --help", [*STICKSLIP, "--help"]),
    ("stickslip critical", [*STICKSLIP, "critical"]),
    ("stickslip critical --json", [*STICKSLIP, "critical", "--json"]),
    (
        "stickslip curve --velocity (3 velocities)",
        [*STICKSLIP, "curve", "--velocity", "50 um/s", "--velocity", "350 um/s", "--velocity", "1 mm/s"],
    ),
    ("stickslip params show", [*STICKSLIP, "params", "show"]),
)


def run_once(command: list[str], env: dict[str, str]) -> tuple[float, float]:
    """(wall time, child CPU time) of one run; the command must succeed."""
    before = os.times()
    start = time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True, check=False)
    wall = time.perf_counter() - start
    after = os.times()
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(command)} failed: {done.stderr.decode(errors='replace')}")
    cpu = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    return wall, cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=9, help="runs per command")
    args = parser.parse_args()
    env = dict(os.environ)
    if (ROOT / "src" / "stickslip").is_dir():
        env["PYTHONPATH"] = str(ROOT / "src") + os.pathsep + env.get("PYTHONPATH", "")
    machine = f"Python {platform.python_version()} on {platform.machine()}, {os.cpu_count()} cores"
    print(f"{machine}; {args.repeat} runs each, wall time and the child's CPU time (user + system)")
    print(f"{'command':44s} {'best':>8s} {'median':>8s} {'cpu best':>9s} {'cpu med':>8s}")
    for label, command in CASES:
        run_once(command, env)  # warm the file cache and the bytecode
        walls, cpus = zip(*(run_once(command, env) for _ in range(args.repeat)), strict=True)
        print(
            f"{label:44s} {min(walls):7.3f}s {statistics.median(walls):7.3f}s"
            f" {min(cpus):8.3f}s {statistics.median(cpus):7.3f}s"
        )


if __name__ == "__main__":
    main()
