"""The sweep's schedule (issue 31): points dearest first in shrinking tasks, the same rows in the same order.

The plan is checked against an independent list-scheduling simulation and the
exact optimum found by enumeration (LPT's 4/3 bound), and a real sweep on a
LocalCluster of two workers is run in both orders and compared bit for bit.
"""

from __future__ import annotations

import heapq
import itertools
import json
import math
import random
import struct

import pyarrow.parquet as pq
import pytest

from stickslip.errors import ParameterError
from stickslip.sweeps import build_spec, run_sweep
from stickslip.sweeps import engine as engine_module
from stickslip.sweeps.models import SweepModel, get_model
from stickslip.sweeps.schedule import GUIDED_FACTOR, RunReport, plan_tasks, usable_costs


def list_schedule_makespan(task_costs: list[float], workers: int) -> float:
    """The test's own simulation: each task in turn to the worker that is free first."""
    free = [0.0] * workers
    for cost in task_costs:
        heapq.heapreplace(free, free[0] + cost)
    return max(free)


def optimum(costs: list[float], workers: int) -> float:
    """The least makespan over every assignment of the points to the workers (enumeration)."""
    best = math.inf
    for assignment in itertools.product(range(workers), repeat=len(costs) - 1):
        loads = [0.0] * workers
        loads[0] = costs[0]  # the first point on worker 0: the workers are interchangeable
        for cost, worker in zip(costs[1:], assignment, strict=True):
            loads[worker] += cost
        best = min(best, max(loads))
    return best


def _task_costs(plan: list[list[int]], costs: list[float]) -> list[float]:
    return [sum(costs[k] for k in task) for task in plan]


@pytest.mark.parametrize("workers, points", [(2, 9), (3, 7)])
def test_the_plan_ends_within_lpt_bound_of_the_optimum_on_random_costs(workers, points):
    rng = random.Random(31)
    bound = 4 / 3 - 1 / (3 * workers)
    worst = 0.0
    for _ in range(40):
        costs = [rng.lognormvariate(0.0, 1.5) for _ in range(points)]
        for max_points in (1, 3, points):
            plan = plan_tasks(costs, workers, max_points)
            assert sorted(k for task in plan for k in task) == list(range(points))  # every point once
            ratio = list_schedule_makespan(_task_costs(plan, costs), workers) / optimum(costs, workers)
            assert ratio <= bound + 1e-12, (costs, plan)
            worst = max(worst, ratio)
    assert worst > 1.0  # the instances are not all trivially optimal


def test_the_bound_discriminates_the_given_order_breaks_it():
    costs = [1.0, 1.0, 1.0, 1.0, 4.0]  # the dear point last: point order ends on it alone
    given = list_schedule_makespan(costs, 2)
    assert given / optimum(costs, 2) > 4 / 3
    planned = list_schedule_makespan(_task_costs(plan_tasks(costs, 2, 5), costs), 2)
    assert planned == optimum(costs, 2) == 4.0


def test_the_plan_takes_the_dearest_first_and_its_tasks_shrink():
    rng = random.Random(7)
    costs = [rng.uniform(0.01, 0.05) for _ in range(300)]
    for k in rng.sample(range(300), 12):
        costs[k] = rng.uniform(5.0, 20.0)  # a few stick-slip points among cheap steady ones
    workers = 4
    plan = plan_tasks(costs, workers, max_points=40)
    dear = sorted(range(300), key=lambda k: -costs[k])[:12]
    assert [task for task in plan[:12]] == [[k] for k in dear]  # alone, in descending cost
    remaining = sum(costs)
    for task in plan:
        cost = sum(costs[k] for k in task)
        if len(task) > 1:  # a task of several points is at most 1/(2 workers) of the work left, itself included
            assert cost <= remaining / (GUIDED_FACTOR * workers) * (1 + 1e-12)
        assert len(task) <= 40 and task == sorted(task)
        remaining -= cost
    sizes = [len(task) for task in plan]
    assert sizes[12] > 10 and sizes[-1] == 1 and sizes[12:] == sorted(sizes[12:], reverse=True)  # then they shrink


def test_equal_costs_keep_the_points_in_order_in_whole_chunks_then_shrink():
    plan = plan_tasks([1.0] * 1000, workers=2, max_points=50)
    assert [k for task in plan for k in task] == list(range(1000))
    assert all(len(task) == 50 for task in plan[:10])
    assert len(plan[-1]) == 1
    # with later work beyond this group the tasks stay whole: they shrink only toward the end of the sweep
    assert all(len(task) == 50 for task in plan_tasks([1.0] * 1000, 2, 50, after=1e6))


def test_costs_without_an_estimate_and_bad_plans():
    assert usable_costs([None, None]) == [1.0, 1.0]
    assert usable_costs([2.0, None, 4.0, 8.0]) == [2.0, 4.0, 4.0, 8.0]  # the median of the known
    assert usable_costs([0.0, 1.0])[0] == pytest.approx(1e-6)
    with pytest.raises(ParameterError, match="workers"):
        plan_tasks([1.0], 0, 1)
    with pytest.raises(ParameterError, match="schedule"):
        run_sweep(build_spec(["pulling_velocity=30 um/s,40 um/s"]), "unused", workers=0, schedule="fastest")


def test_the_transient_model_estimates_a_stick_slip_point_dearer_than_a_steady_one():
    model = get_model("transient")
    assert model.estimates_cost and not get_model("quasi-static").estimates_cost
    spec = build_spec(["pulling_velocity=80 um/s,1 mm/s"], model="transient", stick_population=True,
                      overrides={"block.stiffness": "4 MPa/m"}, duration="30 s")  # fmt: skip
    below, above = (model.cost({**spec.fixed, "pulling_velocity": v}, spec.settings) for v in (80e-6, 1e-3))
    # the README sweep's rows: 80-104 um/s at 4 MPa/m are stick-slip cycles, 1 mm/s slides after its first stick;
    # estimated 0.83 s and 0.057 s, taken 0.79 s and 0.14 s of CPU (the stick chains' births spaced by their own
    # error, docs/transient.md section 11; before, a stiff block's slips were counted in proportion to K: 20x)
    assert below > 5 * above > 0


def test_report_words_and_json_say_what_is_not_known():
    assert "in process" in RunReport("cost", in_process_points=3, in_process_seconds=0.1).words()
    assert RunReport("cost").as_dict()["parallel_efficiency"] is None
    report = RunReport("cost", workers=2, points=10, point_seconds=3.0, wall=2.0)
    assert report.efficiency == pytest.approx(0.75) and "75 %" in report.words()
    assert "nan" not in json.dumps(RunReport("given", workers=2).as_dict()).lower()


@pytest.fixture(scope="module")
def cluster():
    import logging

    from distributed import LocalCluster

    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=logging.ERROR
    ) as local:
        yield local


def _bits(value):
    """A value as its bytes (floats bit for bit, NaN included), else itself."""
    return struct.pack("<d", value).hex() if isinstance(value, float) else value


def _chunks(folder) -> dict[str, list]:
    """Each chunk's rows as written (the columns in file order), wall_time left out (it is a timing)."""
    out = {}
    for path in sorted(folder.glob("part-*.parquet")):
        table = pq.read_table(path)
        columns = [[_bits(v) for v in table.column(n).to_pylist()] for n in table.schema.names if n != "wall_time"]
        out[path.name] = [table.schema.names, *columns]
    return out


def test_cost_and_given_schedules_write_the_same_chunks_bit_for_bit(cluster, tmp_path, monkeypatch):
    spec = build_spec(["pulling_velocity=30 um/s..3 mm/s:5:log", "block.height=1 cm,1.5 cm"], duration="40 s")
    # costs that scatter the points across chunks: the plan's tasks are not the chunks, nor in point order
    fake = {k: (k * 7) % 10 + 1.0 for k in range(spec.size)}
    velocities = spec.points(0, spec.size)["pulling_velocity"]
    heights = spec.points(0, spec.size)["block.height"]
    index = {(float(v), float(h)): k for k, (v, h) in enumerate(zip(velocities, heights, strict=True))}
    monkeypatch.setattr(SweepModel, "estimates_cost", property(lambda self: True))
    monkeypatch.setattr(SweepModel, "cost", lambda self, values, settings: fake[
        index[(values["pulling_velocity"], values["block.height"])]])  # fmt: skip
    planned: list[list[int]] = []
    real = engine_module.plan_tasks

    def spy(*args, **kwargs):
        plan = real(*args, **kwargs)
        planned.extend(plan)
        return plan

    monkeypatch.setattr(engine_module, "plan_tasks", spy)
    given = run_sweep(spec, tmp_path / "given", scheduler=cluster.scheduler_address, batch_size=3, schedule="given")
    cost = run_sweep(spec, tmp_path / "cost", scheduler=cluster.scheduler_address, batch_size=3)
    assert planned[0] == [7] and len(planned) > 4  # the dearest (point 7, cost 10) first, alone; not the chunks
    firsts = [task[0] for task in planned]
    assert firsts != sorted(firsts) and not {tuple(t) for t in planned} & {(0, 1, 2), (3, 4, 5), (6, 7, 8)}
    assert _chunks(tmp_path / "given") == _chunks(tmp_path / "cost")
    assert len(_chunks(tmp_path / "cost")) == 4
    for store in (given, cost):
        saved = json.loads((store.folder / "_run.json").read_text())
        rows = pq.read_table(store.folder).column("wall_time").to_pylist()
        assert saved["workers"] == 2 and saved["points_on_workers"] == spec.size
        assert saved["point_seconds"] == pytest.approx(sum(rows), rel=1e-6, abs=1e-6)  # JSON keeps 6 decimals
        assert saved["parallel_efficiency"] == pytest.approx(sum(rows) / (2 * saved["wall_seconds"]), rel=1e-4)
        assert 0 < saved["parallel_efficiency"] <= 1.05


def test_a_sweep_is_planned_group_by_group_each_point_once(tmp_path, monkeypatch):
    from stickslip.sweeps.store import open_store

    monkeypatch.setattr(engine_module, "FIRST_PLAN_POINTS", 4)
    monkeypatch.setattr(engine_module, "PLAN_POINTS", 8)
    spec = build_spec(["pulling_velocity=30 um/s..3 mm/s:30:log"])
    with open_store(tmp_path / "out", spec, batch_size=3) as store:
        tasks = list(engine_module.cost_ordered_tasks(store, [0, 2, 3, 4, 5, 6, 7, 8, 9], workers=2, points=27))
    points = [p for task in tasks for p in task]
    assert sorted(points) == [p for p in range(30) if p not in (3, 4, 5)]  # chunk 1 was done: not run again
    # groups of whole chunks (6, then 9, 9, 3 points), each in turn: a later group's points never come first
    groups = [set(range(0, 3)) | set(range(6, 9)), set(range(9, 18)), set(range(18, 27)), set(range(27, 30))]
    assert [next(k for k, g in enumerate(groups) if p in g) for p in points] == sorted(
        next(k for k, g in enumerate(groups) if p in g) for p in points
    )
    # equal costs: a task is a chunk (3) until 1/(2 x 2 workers) of what is left in the whole sweep is less
    left, in_group = 27, {0: 6, 1: 9, 2: 9, 3: 3}
    for task in tasks:
        group = next(k for k, g in enumerate(groups) if task[0] in g)
        assert len(task) == min(3, max(1, left // 4), in_group[group])
        left -= len(task)
        in_group[group] -= len(task)
    assert len(tasks[0]) == 3 and len(tasks[-1]) == 1
