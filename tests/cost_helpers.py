"""The host's pace beside the cost estimate's constants, for tests that hold an estimate's CPU seconds to a run's.

The estimate's constants are CPU seconds of the project's 2-core box (``stickslip.transient.solver``: STEP_SECONDS,
SLIDING_COHORT_SECONDS, COHORT_STEP_SECONDS ...), and that box has run the same build at paces 2.3x apart between
sessions: plain cohorts at 350 um/s for 0.5 s took ~0.17 s of CPU when they were calibrated, 0.40 s on 2026-12-02,
when the project's CI read a slow steady start at 0.297 of its CPU against a bound of 0.3.  A test of one kind of
run's estimate therefore holds it to the CPU taken beside the pace of another kind measured on the same host, now.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable
from typing import Any

from stickslip.parameters import load_parameters
from stickslip.protocols import constant
from stickslip.transient import run_transient
from stickslip.transient.solver import estimate_cost


def least_cpu(run: Callable[[], Any], repeats: int = 2) -> tuple[Any, float]:
    """(the run's result, the least CPU seconds of ``repeats`` runs): the host's load only ever adds to a run's
    CPU, so the least is the run's own cost (timeit's convention)."""
    spent = []
    for _ in range(repeats):
        start = time.process_time()
        result = run()
        spent.append(time.process_time() - start)
    return result, min(spent)


@functools.cache
def plain_cohorts_pace() -> float:
    """CPU seconds per second estimated of plain cohorts sliding steadily through the gel's block (1 mm/s for
    0.2 s, the reduction off: ~10 000 steps, ~0.1-0.2 s), whose cost is :data:`SLIDING_COHORT_SECONDS` a cohort
    and step; 1.5-1.8 on the project's box on 2026-12-02.  The kernel is loaded first."""
    gel = load_parameters("gelatin-glass")
    settings = {"start": "steady", "reduction": "off"}
    run_transient(gel, constant(1e-3, 1e-3), **settings)
    protocol = constant(1e-3, 0.2)
    _, cpu = least_cpu(lambda: run_transient(gel, protocol, max_time=1e6, max_steps=10**9, **settings), repeats=3)
    return cpu / estimate_cost(gel, protocol, **settings).seconds
