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
* ``--coverage N``: the coverage study behind docs/fitting.md -- N synthetic data sets (24 points, 2 %
  stated noise) fitted by (two-step, delta), (joint, delta) and (joint, profile); the fraction of 95 %
  intervals of Vc and sigma_c that contain the truth.  Slow (minutes), not a timing.

Run: ``/work/venv/bin/python benchmarks/bench_fit.py [--coverage 100]``
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.optimize import least_squares

from stickslip.fitting import SteadyData, fit_steady
from stickslip.fitting.bayes import sample_posterior
from stickslip.model.critical import critical_point
from stickslip.model.steady import steady_state
from stickslip.parameters import load_parameters, replace
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


def bench_bayes(walkers: int = 32, steps: int = 2000, reference_steps: int = 200) -> None:
    import emcee

    data = synthetic(20, seed=2)
    fit = fit_steady(data)
    start = time.perf_counter()
    post = sample_posterior(fit, walkers=walkers, steps=steps, seed=1)
    ours = time.perf_counter() - start
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
    print(f"emcee, {walkers} walkers x {steps} steps, 20 points")
    print(f"  stickslip sample_posterior (batched walkers, incl. Vc of 200 samples): {ours:6.1f} s   (target 60 s)")
    print(f"  plain loop, one steady_state per walker (200 steps, x10):             {plain:6.1f} s")
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--coverage", type=int, default=0, metavar="N", help="also run the coverage study")
    args = parser.parse_args()
    bench_two_step()
    bench_bayes()
    if args.coverage:
        coverage(args.coverage)


if __name__ == "__main__":
    main()
