"""Timing helper shared by the benchmark scripts (run them as ``python benchmarks/<name>.py``)."""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable
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
