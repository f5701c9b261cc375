"""Benchmark of the fits (issue 4, items 4 and 6), each beside a plain reference in the same run.

Targets: a two-step fit of 20 points <= 0.5 s; emcee, 32 walkers x 2000 steps on 20 points <= 60 s.

* two-step fit: ``fit_steady`` (default: identifiability checks, covariance, Vc and sigma_c with delta
  intervals) on 20 points, 140-2000 um/s, 2 % noise.  Reference: the plain way --
  ``scipy.optimize.least_squares`` on the paper's six parameters (N0, tau, lambda, dl_m, tau_a, V_a, as
  ln-values, all free, two steps as in the paper, finite-difference Jacobians by scipy, one
  ``steady_state`` call per evaluation), printing the condition number that makes its error bars
  meaningless.
* Bayesian: ``sample_posterior`` (walkers evaluated in one batch, see stickslip.fitting.batch).
  Reference: the same emcee run with one ``steady_state`` call per walker (``vectorize=False``),
  run for 200 steps and extrapolated to 2000 (said so in the output).
* long record (issue 12): ``fit_steady`` two-step and joint on 10^5 points (140-2000 um/s, 2 % stated
  noise), fitted through the compressed block (Chebyshev nodes in ln V, docs/fitting.md).  Reference: the
  same fits evaluating the model at every point (compression switched off), run on 10^4 points and
  scaled by 10 (their cost is linear in the points; at 10^5 the two-step took 44 s and the joint did not
  finish in 580 s).  Wall and process times; the Vc interval against the truth.
* stick fit (issue 9): ``fit_stick`` on the paper's Table 1 (default options).  Reference: the same fit
  with each stick time from ``stick_phase`` (scipy's adaptive Runge-Kutta per row and per Jacobian set).
* ``--coverage N``: the coverage study behind docs/fitting.md -- N synthetic data sets (24 points, 2 %
  stated noise) fitted by (two-step, delta), (joint, delta) and (joint, profile); the fraction of 95 %
  intervals of Vc and sigma_c that contain the truth.  Slow (minutes), not a timing.

Run: ``python benchmarks/bench_fit.py [--only two-step|bayes|long|stick] [--coverage 100]`` (with the package installed)
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.optimize import least_squares

from stickslip.fitting import SteadyData, fit_steady
from stickslip.fitting.bayes import sample_posterior
from stickslip.parameters import load_parameters, replace
from stickslip.quasistatic.critical import critical_point
from stickslip.quasistatic.steady import steady_state
from timing import best_of

TRUE = load_parameters("gelatin-glass")
NAIVE_KEYS = (
    ("bonds", "site_density"),
    ("bonds", "bond_time"),
    ("bonds", "activation_length"),
    ("bonds", "max_extension"),
    ("aging", "aging_time"),
    ("aging", "aging_velocity"),
)


def synthetic(points: int, seed: int, relative: float = 0.02) -> SteadyData:
    v = np.geomspace(140e-6, 2000e-6, points)
    true = steady_state(TRUE, v).stress
    rng = np.random.default_rng(seed)
    return SteadyData.from_arrays(v, true * (1 + relative * rng.standard_normal(points)), relative * true)


def _sections(theta: np.ndarray) -> dict[str, dict[str, float]]:
    sections: dict[str, dict[str, float]] = {}
    for (s, k), t in zip(NAIVE_KEYS, theta, strict=True):
        sections.setdefault(s, {})[k] = math.exp(t)
    return sections


def naive_two_step(data: SteadyData) -> tuple[np.ndarray, float]:
    """The paper's procedure the plain way; returns the ln-parameters and the condition number of step 1."""
    theta = np.array([math.log(getattr(getattr(TRUE, s), k)) for s, k in NAIVE_KEYS])

    def params(th: np.ndarray):
        return replace(TRUE, **_sections(th))

    high = data.velocity >= 800e-6

    def step1(x: np.ndarray) -> np.ndarray:
        th = np.concatenate([x, theta[4:]])
        model = steady_state(params(th), data.velocity[high], aging=False).stress
        return (model - data.stress[high]) / data.stress_err[high]

    first = least_squares(step1, theta[:4])
    theta[:4] = first.x

    def step2(x: np.ndarray) -> np.ndarray:
        th = np.concatenate([theta[:4], x])
        model = steady_state(params(th), data.velocity[~high]).stress
        return (model - data.stress[~high]) / data.stress_err[~high]

    theta[4:] = least_squares(step2, theta[4:]).x
    singular = np.linalg.svd(first.jac, compute_uv=False)
    return theta, float(singular[0] / singular[-1])


def bench_two_step() -> None:
    data = synthetic(20, seed=1)
    fit_steady(data)  # warm-up (imports, caches)
    ours, fit = best_of(lambda: fit_steady(data), 5)
    plain, (theta, condition) = best_of(lambda: naive_two_step(data), 3)
    naive = critical_point(replace(TRUE, **_sections(theta)))
    print("two-step fit, 20 points (best of 5 / 3 runs)")
    print(f"  stickslip fit_steady:          {ours * 1e3:8.1f} ms   (target 500 ms)")
    print(f"  plain least_squares, 6 params: {plain * 1e3:8.1f} ms   condition number of step 1: {condition:.2g}")
    found = f"Vc = {naive.velocity * 1e6:.2f} um/s" if naive.exists else "its curve has no minimum (no Vc)"
    print(f"  (plain: {found}; no meaningful error bars, its J^T J is singular)")
    vc = fit.critical_velocity
    print(f"  Vc = {vc.value * 1e6:.2f} um/s [{vc.interval[0] * 1e6:.2f}, {vc.interval[1] * 1e6:.2f}] (true 124.10)")


def bench_bayes(walkers: int = 32, steps: int | None = None, reference_steps: int = 200) -> None:
    import emcee

    data = synthetic(20, seed=2)
    fit = fit_steady(data)
    start = time.perf_counter()
    post = sample_posterior(fit, walkers=walkers, steps=steps, seed=1)
    ours = time.perf_counter() - start
    numpy_batches = _with_numpy_batches(
        lambda: _timed(lambda: sample_posterior(fit, walkers=walkers, steps=steps, seed=1))
    )
    steps = post.steps
    keys = post.keys
    centre = np.array([math.log(fit.parameters.as_dict()[k]) for k in keys])

    def log_prob(th: np.ndarray) -> float:
        sections: dict[str, dict[str, float]] = {}
        for key, t in zip(keys, th, strict=True):
            s, k = key.split(".")
            sections.setdefault(s, {})[k] = math.exp(t)
        model = steady_state(replace(fit.parameters, **sections), data.velocity).stress
        r = (model - data.stress) / data.stress_err
        return -0.5 * float(r @ r)

    rng = np.random.default_rng(1)
    p0 = centre + 1e-3 * rng.standard_normal((walkers, len(keys)))
    sampler = emcee.EnsembleSampler(walkers, len(keys), log_prob)
    start = time.perf_counter()
    sampler.run_mcmc(p0, reference_steps)
    plain = (time.perf_counter() - start) * steps / reference_steps
    vc = post.critical_velocity
    converged = "passes" if post.converged else "FAILS"
    print(f"emcee, {walkers} walkers x {steps} steps (default: until converged), 20 points")
    print(
        f"  stickslip sample_posterior (independence proposal, batched walkers, Vc of 400 samples): {ours:6.1f} s;"
        f" tau up to {max(post.autocorrelation):.1f} steps, {converged} the 50-tau check"
    )
    print(
        f"  the same with the walkers' batches marched by numpy (the rule before BATCH_COMPILED_LANES):"
        f" {numpy_batches[0]:6.1f} s"
    )
    print(f"  plain loop, stretch move, one steady_state per walker ({reference_steps} steps, scaled):  {plain:6.1f} s")
    lo, hi = vc.interval
    print(f"  Vc posterior median {vc.value * 1e6:.2f} um/s, 95 % [{lo * 1e6:.2f}, {hi * 1e6:.2f}]")


def coverage(seeds: int) -> None:
    point = critical_point(TRUE)
    vc_true, sc_true = point.velocity, point.stress
    print(f"coverage of 95 % intervals over {seeds} data sets (24 points, 2 % stated noise)")
    for method, intervals in (("two-step", "delta"), ("joint", "delta"), ("joint", "profile")):
        hits = np.zeros(2)
        start = time.perf_counter()
        for seed in range(seeds):
            fit = fit_steady(synthetic(24, seed=10_000 + seed), method=method, intervals=intervals)
            lo, hi = fit.critical_velocity.interval
            slo, shi = fit.critical_stress.interval
            hits[0] += (lo is None or lo < vc_true) and (hi is None or vc_true < hi)
            hits[1] += (slo is None or slo < sc_true) and (shi is None or sc_true < shi)
        per_fit = (time.perf_counter() - start) / seeds
        rate = hits / seeds
        se = math.sqrt(0.95 * 0.05 / seeds)
        print(
            f"  {method:8s} {intervals:8s} Vc {100 * rate[0]:5.1f} %  sigma_c {100 * rate[1]:5.1f} %"
            f"   (binomial sd at 95 %: {100 * se:.1f} %; {per_fit:.2f} s per fit)"
        )


def _with_numpy_batches(func):
    """func() with steady_stress_many on the numpy march at every batch size (as before issue 31's round 4)."""
    from stickslip.quasistatic import steady

    saved = steady.BATCH_COMPILED_LANES
    steady.BATCH_COMPILED_LANES = 10**12
    try:
        return func()
    finally:
        steady.BATCH_COMPILED_LANES = saved


def _timed(func):  # (wall s, process s, result)
    wall, cpu = time.perf_counter(), time.process_time()
    out = func()
    return time.perf_counter() - wall, time.process_time() - cpu, out


def bench_long_record(points: int = 100_000, reference_points: int = 10_000) -> None:
    from stickslip.fitting import problem

    data = synthetic(points, seed=7)
    small = synthetic(reference_points, seed=7)
    print(f"steady fit of {points} points (wall / process time; the machine is shared, so wall is contended)")
    for method in ("two-step", "joint"):
        times = [_timed(lambda m=method: fit_steady(data, method=m)) for _ in range(2)]
        wall = sorted(t[0] for t in times)
        cpu = min(t[1] for t in times)
        vc = times[-1][2].critical_velocity
        lo, hi = vc.interval
        print(
            f"  {method:8s} stickslip: best {wall[0]:6.2f} s, median {wall[len(wall) // 2]:6.2f} s wall,"
            f" {cpu:6.2f} s process;  Vc = {vc.value * 1e6:.2f} um/s, 95 % [{lo * 1e6:.2f}, {hi * 1e6:.2f}]"
            " (true 124.10)"
        )
        saved = problem.INTERPOLATE_ABOVE
        problem.INTERPOLATE_ABOVE = 10**12  # the plain way: the model at every point
        try:
            wall_ref, cpu_ref, _ = _timed(lambda m=method: fit_steady(small, method=m))
        finally:
            problem.INTERPOLATE_ABOVE = saved
        scale = points / reference_points
        print(
            f"  {method:8s} plain (model at every point), {reference_points} points: {wall_ref:6.1f} s wall,"
            f" {cpu_ref:6.1f} s process; x{scale:g} for {points}: ~{wall_ref * scale:6.0f} s"
        )


def bench_stick() -> None:
    from stickslip.fitting import datasets, fit_stick, stick_fit
    from stickslip.quasistatic.stick import stick_phase

    table = datasets.table1_path()
    fit_stick(table)  # warm-up
    runs = [_timed(lambda: fit_stick(table)) for _ in range(5)]
    wall = sorted(r[0] for r in runs)
    fit = runs[-1][2]

    def one_by_one(sets, rows, horizon_factor=None):
        out = np.full((len(sets), rows.stick_time.size), np.nan)
        for i, params in enumerate(sets):
            for j, (v, s0, rate) in enumerate(zip(rows.velocity, rows.start, rows.rate, strict=True)):
                phase = stick_phase(stick_fit._params_for_rate(params, float(v), float(rate)), float(v), float(s0))
                out[i, j] = np.nan if phase.stick_time is None else phase.stick_time
        return out

    batched = stick_fit._stick_times
    stick_fit._stick_times = one_by_one
    try:
        wall_ref, cpu_ref, reference = _timed(lambda: fit_stick(table))
    finally:
        stick_fit._stick_times = batched
    nc0, ref_nc0 = fit.parameters.stick.attached_chains, reference.parameters.stick.attached_chains
    print("stick fit of Table 1 (default options)")
    print(
        f"  stickslip (vectorised stick times): best {wall[0] * 1e3:6.0f} ms, median {wall[2] * 1e3:6.0f} ms wall,"
        f" {min(r[1] for r in runs) * 1e3:6.0f} ms process   (target 1 s for the command)"
    )
    print(f"  plain (stick_phase per row and set): {wall_ref * 1e3:6.0f} ms wall, {cpu_ref * 1e3:6.0f} ms process")
    print(f"  Nc0 = {nc0:.6g} vs {ref_nc0:.6g} m^-2 (relative difference {abs(nc0 / ref_nc0 - 1):.1e})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--coverage", type=int, default=0, metavar="N", help="also run the coverage study")
    parser.add_argument("--only", choices=["two-step", "bayes", "long", "stick"], help="run one benchmark")
    args = parser.parse_args()
    benches = {"two-step": bench_two_step, "bayes": bench_bayes, "long": bench_long_record, "stick": bench_stick}
    for name, bench in benches.items():
        if args.only in (None, name):
            bench()
    if args.coverage:
        coverage(args.coverage)


if __name__ == "__main__":
    main()
