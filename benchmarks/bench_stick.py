"""Benchmark: the stick phase (Eq 15, ``stickslip.quasistatic.stick.stick_phase``) per call (issue 31).

The calls are those of three workloads, recorded by running them once:

* transient: ``run_transient`` of the paper's cycle with the stick chains (350 µm/s for 5 s, then 100 µm/s for 20 s,
  from steady sliding, ``stick_population=True``);
* diagram: the report's phase diagram, 135 quasi-static runs of 20 s (``stickslip.report.sweep_section``);
* table1: the report's stick phases (``report.computations._sticks``: Table 1's columns, the runs' first sticks
  and the two bisections for V*).

Each recorded call (with ``chain_fraction_at(horizon)`` after it where the block has not slipped by then, as the
transient model and the quasi-static trace do) is replayed with ``stick.SOLVER = "steps"`` (scipy's DOP853 steps
on Python floats, :mod:`stickslip.numerics.dop853`) and with ``"solve_ivp"`` (the same method through
``solve_ivp``, the code before issue 31), alternating, best of ``--repeats`` runs, in process CPU time.  The
answers of the two are compared: status and message the same, stick time and peak stress within 1e-10 relative.

Run: ``PYTHONPATH=src python benchmarks/bench_stick.py [--repeats 5]``.
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from typing import Any

from stickslip import load_parameters
from stickslip.quasistatic import cycle as cycle_module
from stickslip.quasistatic import stick
from stickslip.report import computations

Call = tuple[Any, ...]


def record(workload: Any) -> tuple[list[Call], float]:
    """The stick_phase calls of ``workload()`` and its CPU time."""
    calls: list[Call] = []
    original = stick.stick_phase

    def recorder(params, pulling_velocity, start_stress=None, aging=True, horizon=None, aging_cap=None):
        calls.append((params, pulling_velocity, start_stress, aging, horizon, aging_cap))
        return original(params, pulling_velocity, start_stress, aging, horizon, aging_cap)

    modules = (stick, cycle_module, computations)
    for module in modules:
        module.stick_phase = recorder
    try:
        start = time.process_time()
        workload()
        cpu = time.process_time() - start
    finally:
        for module in modules:
            module.stick_phase = original
    return calls, cpu


def transient() -> None:
    from stickslip.protocols import Protocol, Segment
    from stickslip.transient.solver import run_transient

    protocol = Protocol((Segment(350e-6, 5.0), Segment(100e-6, 20.0)))
    run_transient(load_parameters("gelatin-glass"), protocol, start="steady", stick_population=True)


def diagram() -> None:
    from stickslip.report.sweep_section import DURATION, MODEL, STIFFNESS_FACTORS, VELOCITIES
    from stickslip.sweeps import build_spec, run_sweep

    params = load_parameters("gelatin-glass")
    low, high, count = STIFFNESS_FACTORS
    k = params.block.stiffness
    spec = build_spec(
        [f"pulling_velocity={VELOCITIES}", f"block.stiffness={low * k!r}..{high * k!r}:{count}:log"],
        model=MODEL,
        params=params,
        duration=DURATION,
    )
    with tempfile.TemporaryDirectory() as folder:
        run_sweep(spec, f"{folder}/sweep", workers=0, batch_size=spec.size)


def table1() -> None:
    run = computations.ModelRun(load_parameters("gelatin-glass"))
    computations._steady(run)
    computations._sticks(run)


def replay(calls: list[Call]) -> list[stick.StickPhase]:
    out = []
    for params, velocity, start, aging, horizon, cap in calls:
        phase = stick.stick_phase(params, velocity, start, aging, horizon, cap)
        if horizon is not None and (phase.stick_time is None or phase.stick_time > horizon):
            phase.chain_fraction_at(horizon)
        out.append(phase)
    return out


def timed_replay(calls: list[Call], solver: str) -> tuple[float, list[stick.StickPhase]]:
    stick.SOLVER = solver
    try:
        start = time.process_time()
        out = replay(calls)
        return time.process_time() - start, out
    finally:
        stick.SOLVER = "steps"


def compare(new: list[stick.StickPhase], old: list[stick.StickPhase]) -> tuple[int, float]:
    """(calls whose status or message differ, largest relative difference of t_s and sigma_s)."""
    differ, worst = 0, 0.0
    for a, b in zip(new, old, strict=True):
        if a.status != b.status or a.message != b.message:
            differ += 1
        for x, y in ((a.stick_time, b.stick_time), (a.peak_stress, b.peak_stress)):
            if x is not None and y is not None and y != 0:
                worst = max(worst, abs(x - y) / abs(y))
            elif (x is None) != (y is None):
                differ += 1
    return differ, worst


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    workloads = {"transient": transient, "diagram": diagram, "table1": table1}
    print(f"{'workload':<11}{'calls':>6}{'workload CPU':>14}{'solve_ivp':>12}{'steps':>10}{'speed-up':>10}"
          f"{'per call':>18}{'differ':>8}{'max rel':>10}")  # fmt: skip
    for name, workload in workloads.items():
        workload()  # warm the caches (critical point, numba, imports) before recording
        calls, cpu = record(workload)
        best = {"solve_ivp": math.inf, "steps": math.inf}
        results: dict[str, list[stick.StickPhase]] = {}
        for _ in range(args.repeats):
            for solver in best:
                spent, results[solver] = timed_replay(calls, solver)
                best[solver] = min(best[solver], spent)
        differ, worst = compare(results["steps"], results["solve_ivp"])
        old, new = best["solve_ivp"], best["steps"]
        per_call = f"{old / len(calls) * 1e3:.2f} -> {new / len(calls) * 1e3:.2f} ms"
        print(f"{name:<11}{len(calls):>6}{cpu:>12.3f} s{old:>10.3f} s{new:>8.3f} s{old / new:>9.1f}x{per_call:>18}"
              f"{differ:>8}{worst:>10.1e}")  # fmt: skip
    print("workload CPU: the whole workload once with the new solver; solve_ivp/steps: its stick calls replayed")


if __name__ == "__main__":
    main()
