"""When a sweep's points run: the dearest first, in tasks that shrink toward the end (guided self-scheduling).

The points sorted by estimated cost, longest first, are cut into tasks of at most ``1 / (factor x workers)`` of
the work not yet planned, so the workers finish together (within LPT's bound for factor >= 2: docs/sweep.md).
Only *when* a point runs changes: every point is computed alone and the rows are written in point order.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from ..errors import ParameterError

#: How a sweep submits its tasks: "cost" (planned here) or "given" (the chunks in point order, as before issue 31).
SCHEDULES = ("cost", "given")
#: A task holds at most 1/(GUIDED_FACTOR x workers) of the work not yet planned (>= 2 keeps LPT's 4/3 bound).
GUIDED_FACTOR = 2.0


def check_schedule(schedule: Any) -> str:
    if schedule not in SCHEDULES:
        raise ParameterError(f"schedule: expected one of {', '.join(map(repr, SCHEDULES))}, got {schedule!r}")
    return str(schedule)


def plan_tasks(
    costs: Sequence[float], workers: int, max_points: int, factor: float = GUIDED_FACTOR, after: float = 0.0
) -> list[list[int]]:
    """Positions in ``costs`` grouped into tasks, in the order to submit them (each task's positions ascending).

    Longest first (ties keep the given order, so equal costs keep the points in order and the tasks aligned with
    the chunks); a task takes the next points while its cost stays within ``1/(factor x workers)`` of the cost
    not yet planned (``after``: the cost of the work that follows these points, planned later), and at most
    ``max_points`` of them; a point dearer than that is a task alone.
    """
    if workers < 1 or max_points < 1 or not factor >= 1 or not after >= 0:
        raise ParameterError(f"plan_tasks: expected workers, max_points >= 1, factor >= 1 and after >= 0, got "
                             f"{workers}, {max_points}, {factor}, {after}")  # fmt: skip
    order = sorted(range(len(costs)), key=lambda k: -costs[k])
    remaining = math.fsum(costs) + after
    tasks: list[list[int]] = []
    k = 0
    while k < len(order):
        target = remaining / (factor * workers)
        task, spent = [order[k]], costs[order[k]]
        k += 1
        while k < len(order) and len(task) < max_points and spent + costs[order[k]] <= target:
            task.append(order[k])
            spent += costs[order[k]]
            k += 1
        remaining = max(remaining - spent, 0.0)
        tasks.append(sorted(task))
    return tasks


def usable_costs(estimates: Sequence[float | None]) -> list[float]:
    """Costs to plan with: a point without an estimate costs the median of the others (all 1 when none has one);
    each at least a millionth of the dearest, so a zero estimate still counts as a point."""
    known = sorted(c for c in estimates if c is not None and math.isfinite(c) and c >= 0)
    if not known or known[-1] <= 0:
        return [1.0] * len(estimates)
    middle = known[len(known) // 2]
    floor = known[-1] * 1e-6
    return [max(middle if c is None or not math.isfinite(c) or c < 0 else c, floor) for c in estimates]


def predicted_makespan(task_costs: Sequence[float], workers: int) -> float:
    """The end of the last task when each task, in order, goes to the worker that is free first."""
    free = [0.0] * max(1, workers)
    for cost in task_costs:
        heapq.heappush(free, heapq.heappop(free) + cost)
    return max(free)


@dataclass
class RunReport:
    """What one run of a sweep computed, on how many workers, in how long (its parallel efficiency).

    ``workers`` is the cluster's worker threads (None: everything ran in this process); ``wall`` the seconds from
    the first task submitted to the last row written; ``point_seconds`` the sum of the rows' ``wall_time`` of the
    points the cluster ran; ``in_process_points``/``in_process_seconds`` those run here first (a small sweep's
    start, see ``compute_while_cheap``), not counted in the efficiency.
    """

    schedule: str
    workers: int | None = None
    points: int = 0
    point_seconds: float = 0.0
    wall: float = 0.0
    cluster_start: float = 0.0
    in_process_points: int = 0
    in_process_seconds: float = 0.0

    @property
    def efficiency(self) -> float | None:
        """(sum of point times) / (workers x wall) of the cluster's part; None where it means nothing."""
        if self.workers is None or self.workers < 1 or self.points == 0 or not self.wall > 0:
            return None
        return self.point_seconds / (self.workers * self.wall)

    def efficiency_words(self) -> str:
        """The efficiency, or in words why there is none."""
        if self.efficiency is not None:
            return f"{100.0 * self.efficiency:.0f} %"
        if self.workers is None:
            return "not meaningful (in process)" if self.in_process_points else "not meaningful (nothing to run)"
        return "not meaningful (no point ran on the cluster)"

    def words(self) -> str:
        """One clause for the sweep's summary line."""
        if self.workers is None:
            if not self.in_process_points:
                return "nothing to run (every chunk was already written)"
            return (f"in process ({self.in_process_points} points, {self.in_process_seconds:.3g} s of point time);"
                    " parallel efficiency not meaningful")  # fmt: skip
        plural = "s" if self.workers != 1 else ""
        text = f"{self.workers} worker{plural}, parallel efficiency {self.efficiency_words()}"
        if self.efficiency is not None:
            text += (f" ({self.point_seconds:.3g} s of point time over {self.workers} x {self.wall:.3g} s wall,"
                     f" {self.schedule} order; cluster start {self.cluster_start:.2g} s)")  # fmt: skip
        if self.in_process_points:
            text += f"; {self.in_process_points} points first in this process"
        return text

    def as_dict(self) -> dict[str, Any]:
        """SI, no NaN: the efficiency is a number or, in ``parallel_efficiency_note``, words."""
        efficiency = self.efficiency
        return {
            "schedule": self.schedule,
            "workers": self.workers if self.workers is not None else "in process",
            "points_on_workers": self.points,
            "point_seconds": round(self.point_seconds, 6),
            "wall_seconds": round(self.wall, 6),
            "cluster_start_seconds": round(self.cluster_start, 6),
            "points_in_process": self.in_process_points,
            "point_seconds_in_process": round(self.in_process_seconds, 6),
            "parallel_efficiency": None if efficiency is None else round(efficiency, 6),
            "parallel_efficiency_note": self.efficiency_words(),
        }
