"""Timing helper shared by the benchmark scripts (run them as ``python benchmarks/<name>.py``)."""

from __future__ import annotations

import math
import os
import statistics
import subprocess
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any


def best_of(func: Callable[[], Any], repeat: int) -> tuple[float, Any]:
    """(fastest wall time in s over ``repeat`` calls, the last result)."""
    best, out = math.inf, None
    for _ in range(repeat):
        start = time.perf_counter()
        out = func()
        best = min(best, time.perf_counter() - start)
    return best, out


def timed(func: Callable[[], Any], repeat: int) -> tuple[float, float, float, Any]:
    """(best wall, median wall, median CPU time in s over ``repeat`` calls, the last result)."""
    walls, cpus, out = [], [], None
    for _ in range(repeat):
        wall, cpu = time.perf_counter(), time.process_time()
        out = func()
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    return min(walls), statistics.median(walls), statistics.median(cpus), out


def child_run(command: list[str], env: dict[str, str]) -> tuple[float, float]:
    """(wall time, CPU time of the child and its children) of one run of ``command``; it must succeed."""
    before = os.times()
    start = time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True, check=False)
    wall = time.perf_counter() - start
    after = os.times()
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(command)} failed: {done.stderr.decode(errors='replace')[-2000:]}")
    return wall, (after.children_user - before.children_user) + (after.children_system - before.children_system)


def package_environments(sources: dict[str, Path]) -> dict[str, dict[str, str]]:
    """For each labelled ``src/`` folder, this process's environment with ``PYTHONPATH`` on it and the bytecode
    allowed (``PYTHONDONTWRITEBYTECODE`` dropped): the warm-up run writes it, as an installed package has it."""
    base = {name: value for name, value in os.environ.items() if name != "PYTHONDONTWRITEBYTECODE"}
    return {label: {**base, "PYTHONPATH": str(src)} for label, src in sources.items()}
