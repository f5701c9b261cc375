"""Time-dependent model: each workload with the quasi-steady reduction beside the plain cohort solver, same run.

Run as ``PYTHONPATH=src python benchmarks/bench_transient.py`` (``--reference`` adds the rtol 1e-5 cohort run of
the cycle, 49 s of CPU, whose numbers tests/test_transient_speed.py compares with; ``--quick`` skips the plain
cohort runs that take more than a few seconds; ``--phases`` only counts where the cycle's steps go, issue 31;
``--repeat`` only times long stick-slip runs, a settled limit cycle repeated beside every cycle integrated;
``--births`` only times the cycle with the births spaced by their own error beside the lumped bound; ``--holds`` only
times re-slides after holds with the steps landed short of the FENE wall beside the solver before; ``--against
OTHER_SRC`` only times the cycle with this checkout and another copy of ``src/`` in alternate processes).
CPU time (``time.process_time``) is printed with the ratio
to the plain solver's in the same process, and the accuracy reached: against the steady solver, or the
cycle's stick time, peak, jump velocity and slip time against the tighter run.
"""

from __future__ import annotations

import sys
import time

import numpy as np

import stickslip
from stickslip.protocols import Protocol, Segment, constant
from stickslip.transient import cells, reduction, run_transient
from stickslip.transient.solver import estimate_cost
from timing import timed

CYCLE = Protocol((Segment(350e-6, 5.0), Segment(100e-6, 20.0)))
CYCLE_KEYS = ("stick_time", "peak_stress", "jump_velocity", "slip_time")


def method_of_lines(params, velocity, duration, cells=400):  # type: ignore[no-untyped-def]
    """Plain reference: Eq 1 at constant V on a uniform age grid (upwind), integrated by solve_ivp (BDF)."""
    from scipy.integrate import solve_ivp

    b, g = params.bonds, params.aging
    t_max = b.max_extension / velocity
    da = t_max / cells
    age = (np.arange(cells) + 0.5) * da
    e = velocity * age
    f = b.chain_stiffness * e / (1 - (e / b.max_extension) ** 2)
    rate = (
        b.breakage_weight
        / b.bond_time
        * np.exp(np.minimum(b.force_sensitivity * f - age / g.aging_time * np.exp(-velocity / g.aging_velocity), 700.0))
    )

    def rhs(t, n):  # type: ignore[no-untyped-def]
        inflow = np.empty_like(n)
        inflow[0] = (b.site_density - n.sum() * da) / b.bond_time / da
        inflow[1:] = n[:-1] / da
        return inflow - n / da - rate * n

    sol = solve_ivp(rhs, (0, duration), np.zeros(cells), method="BDF", rtol=1e-8, atol=1e-6)
    n = sol.y[:, -1]
    return float(n @ f * da), float(n.sum() * da / b.site_density)


def cpu(func):  # type: ignore[no-untyped-def]
    start = time.process_time()
    out = func()
    return time.process_time() - start, out


def pair(label, func, quick=False):  # type: ignore[no-untyped-def]
    """The workload reduced and plain: (cpu reduced, result), (cpu plain, result) or None when skipped."""
    reduced = cpu(lambda: func("auto"))
    plain = None if quick else cpu(lambda: func("off"))
    text = f"{label}: reduced {reduced[0]:.3f} s CPU ({reduced[1].steps} steps)"
    if plain is not None:
        text += f", plain cohorts {plain[0]:.3f} s ({plain[1].steps} steps): {plain[0] / reduced[0]:.0f}x"
    print(text, flush=True)
    return reduced, plain


def cycle_numbers(run):  # type: ignore[no-untyped-def]
    c = run.cycles[0]
    return np.array([getattr(c, key) for key in CYCLE_KEYS])


def cycle_phases() -> None:
    """Issue 31: where the cycle's steps go (a trace row per step): gliding on the reduction, the stick on the
    chains (Eqs 11-16), and the cohorts, these split by the slider's pace against the bonds' memory dl_m/V: slow
    (V/|V'| above ten memories, where the population is quasi-steady but the reduction's closure has left it, near
    the fold) or fast (the collapse to rest and the jump).  Measured: 8 224 steps; 8 048 of them in the two fold
    passages (4 024 each, steps of 3.46e-5 s), and 7 169 of the 8 197 cohort steps quasi-steady in that sense
    (docs/transient.md section 8)."""
    p = stickslip.load_parameters("gelatin-glass")
    run = run_transient(p, CYCLE, start="steady", stick_population=True)
    t, v = run.time, run.slider_velocity
    chains = run.to_frame()["held_by"].to_numpy() == "chains"
    gap = np.diff(t, prepend=0.0)
    cohorts = ~chains & (gap < 0.2 * p.bonds.bond_time)  # the cohorts' steps resolve tau; the glide's rows do not
    memory = p.bonds.max_extension / np.maximum(np.abs(v), 1e-12)
    with np.errstate(divide="ignore", invalid="ignore"):
        pace = np.abs(v / np.gradient(v, t))
    slow = cohorts & (pace > 10 * memory)
    print(f"cycle, rtol 1e-4: {run.steps} steps; trace rows: {np.count_nonzero(~chains & ~cohorts)} gliding or "
          f"longer, {np.count_nonzero(chains)} on the stick chains, {np.count_nonzero(cohorts)} cohort steps, of them "
          f"{np.count_nonzero(slow)} where V/|V'| > 10 dl_m/V (quasi-steady) and {np.count_nonzero(cohorts & ~slow)} "
          "faster")  # fmt: skip
    for start, end in ((8.5, 10.0), (23.5, 25.0)):
        inside = cohorts & (t > start) & (t <= end)
        if inside.any():
            first, last, step = t[inside][0], t[inside][-1], np.median(gap[inside])
            print(f"  the fold passage in {start:g}-{end:g} s: {np.count_nonzero(inside)} cohort steps from "
                  f"{first:.4f} s to {last:.4f} s, median step {step:.3g} s")  # fmt: skip


#: (label, parameter overrides, velocity m/s, duration s) of the --repeat runs
REPEAT_RUNS = (
    ("the paper's set, 100 um/s, 120 s", {}, 100e-6, 120.0),
    ("the paper's set, 100 um/s, 1000 s", {}, 100e-6, 1000.0),
    ("K = 4 MPa/m (the phase diagram's corner), 104 um/s, 30 s", {"block.height": 1e-3}, 104e-6, 30.0),
)


def repeated_cycles() -> None:
    """Long stick-slip runs with a settled limit cycle repeated (the default) beside every cycle integrated
    (``solver.REPEAT_CYCLES = False``, the plain reference), in turn in the same process; the cycles' largest
    relative difference and the end stress's."""
    from dataclasses import fields

    from stickslip.transient import solver

    p = stickslip.load_parameters("gelatin-glass")
    run_transient(p, constant(100e-6, 1.0), stick_population=True)  # the numba caches
    for label, overrides, velocity, duration in REPEAT_RUNS:
        params = p.with_overrides(overrides) if overrides else p
        runs = {}
        for repeat in (True, False):
            solver.REPEAT_CYCLES = repeat
            runs[repeat] = cpu(lambda params=params, v=velocity, d=duration: run_transient(
                params, constant(v, d), stick_population=True))  # fmt: skip
        solver.REPEAT_CYCLES = True
        (t_on, on), (t_off, off) = runs[True], runs[False]
        worst = max(
            abs(getattr(a, f.name) / getattr(b, f.name) - 1)
            for a, b in zip(on.cycles, off.cycles, strict=True)
            for f in fields(a)
            if isinstance(getattr(a, f.name), float) and np.isfinite(getattr(b, f.name)) and getattr(b, f.name) != 0
        )
        print(
            f"{label}: repeated {t_on:.2f} s CPU ({on.steps} steps), every cycle integrated {t_off:.2f} s "
            f"({off.steps} steps): {t_off / t_on:.1f}x; {len(on.cycles)} cycles, largest relative difference "
            f"{worst:.1e}; end stress {on.stress[-1]:.6f} against {off.stress[-1]:.6f} Pa",
            flush=True,
        )


#: the stick chains' cycle against the plain cohorts at rtol 1e-5 (tests/test_transient_speed.py's reference)
CYCLE_TIGHT = np.array([9.765432041866394, 556.4046077148165, 0.0007110383712498472, 5.590082951461191])


def births_spacing(repeats: int = 5) -> None:
    """Issue 31: the paper's cycle with the births spaced by their own Gauss error (the default with the stick
    chains under a moving puller) beside the lumped bound (``solver.RELAXED_BIRTHS = False``: the code before,
    with the stick landed), alternated in one process, best and median CPU of ``repeats`` each; and both against
    the plain cohorts at rtol 1e-5 (docs/transient.md section 11)."""
    from stickslip.transient import solver

    p = stickslip.load_parameters("gelatin-glass")
    run_transient(p, CYCLE, start="steady", stick_population=True)  # the numba caches and the tables
    times: dict[bool, list[float]] = {True: [], False: []}
    runs = {}
    for _ in range(repeats):
        for relaxed in (True, False):
            solver.RELAXED_BIRTHS = relaxed
            t_cpu, runs[relaxed] = cpu(lambda: run_transient(p, CYCLE, start="steady", stick_population=True))
            times[relaxed].append(t_cpu)
    solver.RELAXED_BIRTHS = True
    for relaxed, label in ((True, "births by their Gauss error"), (False, "the lumped bound")):
        run, t = runs[relaxed], sorted(times[relaxed])
        error = np.abs(cycle_numbers(run) / CYCLE_TIGHT - 1)
        print(
            f"one cycle (350 -> 100 um/s, 25 s, stick chains, rtol 1e-4), {label}: best {t[0]:.3f} s CPU, median "
            f"{t[len(t) // 2]:.3f} s, {run.steps} steps; against the rtol 1e-5 cohorts: "
            + ", ".join(f"{k} {e:.1e}" for k, e in zip(CYCLE_KEYS, error, strict=True)),
            flush=True,
        )
    print(f"speed-up: {sorted(times[False])[0] / sorted(times[True])[0]:.1f}x (best against best)")


#: re-slide peaks after 1 s and 10 s holds (2 ms at 100 um/s, the hold, 15 ms at 100 um/s, velocity control) from
#: the solver before the wall landing at rtol 1e-5 (8 750 and 11 147 steps): tests/test_transient_wall_landing.py;
#: the 0.1 s hold's from the births in the hold spaced a hundred times finer at rtol 3e-6 (docs/transient.md
#: section 23: the old spacing's 225 907.003 Pa lay on a floor 4.1e-5 low)
HOLD_PEAKS = {0.1: 225915.4, 1.0: 3559901.17, 10.0: 39200921.6}


def wall_landing(repeats: int = 3) -> None:
    """Issue 31: re-sliding after a hold (the report's slide-hold-slide runs) with the steps ending short of a loaded
    cohort's arrival at the FENE wall (the default) beside the solver before (``solver.WALL_LANDING = False``),
    alternated in one process, best CPU of ``repeats`` each; the peak against the rtol 1e-5 reference."""
    from stickslip.protocols import segments
    from stickslip.transient import solver

    p = stickslip.load_parameters("gelatin-glass")
    run_transient(p, constant(100e-6, 1e-3), control="velocity")  # the numba caches
    for rtol in (1e-3, 1e-4):
        for hold, reference in HOLD_PEAKS.items():
            protocol = segments([(100e-6, 0.002), (0.0, hold), (100e-6, 0.015)])
            times: dict[bool, list[float]] = {True: [], False: []}
            runs = {}
            for _ in range(repeats):
                for landing in (True, False):
                    solver.WALL_LANDING = landing
                    t_cpu, runs[landing] = cpu(lambda protocol=protocol, rtol=rtol: run_transient(
                        p, protocol, control="velocity", start="steady", rtol=rtol))  # fmt: skip
                    times[landing].append(t_cpu)
            solver.WALL_LANDING = True
            parts = []
            for landing, label in ((True, "landed"), (False, "before")):
                run = runs[landing]
                peak = float(run.stress[run.time > 0.002 + hold].max())
                parts.append(f"{label} {min(times[landing]):.2f} s CPU, {run.steps} steps + {run.rejected} rejected, "
                             f"peak {peak / reference - 1:+.1e}")  # fmt: skip
            print(f"re-slide after {hold:g} s, rtol {rtol:g}: " + "; ".join(parts), flush=True)


#: the child of ``--against``: the cycle in a warm process, best and median CPU of 7, its steps and numbers
_CYCLE_CHILD = """
import json, time, stickslip
from stickslip.protocols import Protocol, Segment
from stickslip.transient import run_transient
cycle = Protocol((Segment(350e-6, 5.0), Segment(100e-6, 20.0)))
p = stickslip.load_parameters("gelatin-glass")
run_transient(p, cycle, start="steady", stick_population=True)
times = []
for _ in range(7):
    start = time.process_time()
    run = run_transient(p, cycle, start="steady", stick_population=True)
    times.append(time.process_time() - start)
c = run.cycles[0]
times.sort()
print(json.dumps([times[0], times[3], run.steps, [c.stick_time, c.peak_stress, c.jump_velocity, c.slip_time]]))
"""


def cycle_against(other: str, rounds: int = 3) -> None:
    """Issue 31: the paper's cycle with this checkout's package and with another copy of ``src/`` (an older commit:
    ``git archive COMMIT src | tar -x -C /tmp/old``, then ``--against /tmp/old/src``), each in its own process,
    alternated ``rounds`` times so that both see the same machine; CPU best/median of 7 warm runs each."""
    import json
    import os
    import subprocess
    from pathlib import Path

    sources = {"this": str(Path(__file__).resolve().parent.parent / "src"), "other": other}
    for _ in range(rounds):
        for label, src in sources.items():
            env = {**os.environ, "PYTHONPATH": src}
            out = subprocess.run([sys.executable, "-c", _CYCLE_CHILD], env=env, capture_output=True, text=True,
                                 check=True).stdout  # fmt: skip
            best, median, steps, numbers = json.loads(out.strip().splitlines()[-1])
            error = np.abs(np.array(numbers) / CYCLE_TIGHT - 1)
            against = ", ".join(f"{k} {e:.1e}" for k, e in zip(CYCLE_KEYS, error, strict=True))
            print(f"{label} ({src}): one cycle best {best:.3f} s CPU, median {median:.3f} s, {steps} steps; against "
                  f"the rtol 1e-5 cohorts: {against}", flush=True)  # fmt: skip


def main() -> None:
    if "--against" in sys.argv:
        cycle_against(sys.argv[sys.argv.index("--against") + 1])
        return
    if "--holds" in sys.argv:
        wall_landing()
        return
    if "--births" in sys.argv:
        births_spacing()
        return
    if "--phases" in sys.argv:
        cycle_phases()
        return
    if "--repeat" in sys.argv:
        repeated_cycles()
        return
    quick = "--quick" in sys.argv
    p = stickslip.load_parameters("gelatin-glass")
    # compile / load the numba caches of the cohort kernel and of the reduction's tables, and find Vc once (a
    # steady start through the block asks for it, ~0.07 s per parameter set)
    run_transient(p, constant(350e-6, 1e-3), control="velocity")
    run_transient(p, constant(350e-6, 1e-3), start="steady")
    cells.steady_cohorts(p, 350e-6, True)
    reduction._lag(p, 350e-6, True)

    v = 350e-6
    ref = stickslip.steady_state(p, v)
    for mode in ("off", "auto"):
        best, med, t_cpu, run = timed(
            lambda mode=mode: run_transient(p, constant(v, 0.012), control="velocity", rtol=1e-4, reduction=mode), 3
        )
        print(
            f"constant V = 350 um/s from empty, 12 ms (54 tau), rtol 1e-4, reduction {mode}: best {best:.3f} s, "
            f"median {med:.3f} s, cpu {t_cpu:.3f} s, {run.steps} steps, "
            f"sigma error {abs(run.final_stress / float(ref.stress) - 1):.2e}"
        )
    if not quick:
        best, med, t_cpu, out = timed(lambda: method_of_lines(p, v, 0.012), 1)
        print(
            f"  method of lines (400 age cells, BDF): {best:.3f} s, cpu {t_cpu:.3f} s, sigma error "
            f"{abs(out[0] / float(ref.stress) - 1):.2e}"
        )

    plain_1s = float("nan")
    for rtol in (1e-4, 1e-3):
        (_cpu, r_run), plain = pair(
            f"block, steady sliding at 350 um/s, 1 s, rtol {rtol:g}",
            lambda mode, rtol=rtol: run_transient(p, constant(v, 1.0), start="steady", rtol=rtol, reduction=mode),
        )
        errors = f"sigma {abs(r_run.final_stress / float(ref.stress) - 1):.1e} off the steady solver (reduced)"
        if plain is not None and rtol == 1e-4:
            plain_1s = plain[0]
        if plain is not None:
            errors += f", {abs(plain[1].final_stress / float(ref.stress) - 1):.1e} (plain)"
        print("  " + errors)

    # a run the cohorts cannot afford (2.9e7 steps estimated, ~10 min): accepted since the estimate knows the reduction
    estimate = estimate_cost(p, constant(v, 1000.0), start="steady")
    plain_estimate = estimate_cost(p, constant(v, 1000.0), start="steady", reduction="off")
    t_cpu, long_run = cpu(lambda: run_transient(p, constant(v, 1000.0), start="steady"))
    print(
        f"block, steady sliding at 350 um/s, 1000 s, rtol 1e-4: reduced {t_cpu:.3f} s CPU ({long_run.steps} steps; "
        f"estimated {estimate.steps:.3g}), plain cohorts estimated {plain_estimate.steps:.3g} steps "
        f"(~{plain_estimate.seconds:.0f} s): {t_cpu / plain_1s:.2g} of the plain solver's 1 s run"
    )

    tight = None
    if "--reference" in sys.argv:
        t_cpu, tight_run = cpu(
            lambda: run_transient(p, CYCLE, start="steady", stick_population=True, rtol=1e-5, reduction="off")
        )
        tight = cycle_numbers(tight_run)
        print(f"cycle reference (plain cohorts, rtol 1e-5): {t_cpu:.1f} s CPU, {tight_run.steps} steps, " + ", ".join(
            f"{key} {value!r}" for key, value in zip(CYCLE_KEYS, tight, strict=True)))  # fmt: skip
    for rtol in (1e-4, 1e-3):
        (_cpu, r_run), plain = pair(
            f"one cycle, 350 um/s 5 s then 100 um/s 20 s with the stick chains, rtol {rtol:g}",
            lambda mode, rtol=rtol: run_transient(
                p, CYCLE, start="steady", stick_population=True, rtol=rtol, reduction=mode
            ),
            quick=quick,
        )
        got = cycle_numbers(r_run)
        print("  reduced: " + ", ".join(f"{k} {x:.6g}" for k, x in zip(CYCLE_KEYS, got, strict=True)))
        if plain is not None:
            diff = np.max(np.abs(got / cycle_numbers(plain[1]) - 1))
            print(f"  largest relative difference from the plain run: {diff:.1e}")
        if tight is not None:
            print(f"  largest relative difference from the rtol 1e-5 run: {np.max(np.abs(got / tight - 1)):.1e}")

    best, med, t_cpu, run = timed(lambda: run_transient(p, constant(50e-6, 25.0), rtol=1e-3), 1)
    print(
        f"block, 50 um/s from rest, 25 s, rtol 1e-3 (stuck: never quasi-steady): cpu {t_cpu:.2f} s, "
        f"{run.steps} steps, regime {run.regime}, final sigma {run.final_stress:.4g} Pa (K V0 t = "
        f"{p.block.effective_stiffness * 50e-6 * 25:.4g} Pa)"
    )

    stuck_from_rest(quick)


def first_slip(run, pace=50e-6):  # type: ignore[no-untyped-def]
    """(time, stress) of the highest stress before the first jump (the slider past the puller's pace, after the
    first second: from an empty surface the slider starts at the puller's pace)."""
    jumped = np.flatnonzero((run.time > 1.0) & (run.slider_velocity > pace))
    end = jumped[0] if jumped.size else run.time.size
    i = int(np.argmax(run.stress[:end]))
    return float(run.time[i]), float(run.stress[i])


def stuck_from_rest(quick: bool) -> None:
    """Issue 33: gelatin-glass-saturating at 50 um/s from rest, 45 s (a creep, the first slip at ~39 s, the slip,
    the re-stick), with the kernel's merging of saturated cohorts and its relative drop beside the plain cohorts
    (``plain_cohorts()``: every cohort kept until it weighs 1e-30 N0; ~5-10 min of CPU, skipped with --quick).
    Measured (docs/transient.md section 8, issue 33 item 3): merged 27.2-30.1 s of CPU, 104 334 steps, most of
    them at ~0.2 tau in 0-2.5 s (10.4 s) and 37-39 s (13 s); the plain cohorts 662 s."""
    from stickslip.transient.model import plain_cohorts

    sat = stickslip.load_parameters("gelatin-glass-saturating")
    protocol = constant(50e-6, 45.0)
    for label, plain in (("merged", False), ("plain cohorts", True)):
        if plain and quick:
            continue
        start = time.process_time()
        if plain:
            with plain_cohorts():
                run = run_transient(sat, protocol)
        else:
            run = run_transient(sat, protocol)
        t_cpu = time.process_time() - start
        when, peak = first_slip(run)
        print(
            f"gelatin-glass-saturating, 50 um/s from rest, 45 s, rtol 1e-4, {label}: cpu {t_cpu:.1f} s, "
            f"{run.steps} steps, first slip at {when!r} s from {peak!r} Pa, final sigma {run.final_stress!r} Pa",
            flush=True,
        )


if __name__ == "__main__":
    main()
