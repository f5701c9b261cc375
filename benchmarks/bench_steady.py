"""Benchmark: the steady friction curve sigma(V) (Eqs 6-8), issue 2.

Times stickslip.steady_state on 1000 log-spaced velocities from 10 um/s to
10 mm/s (gelatin-glass, with aging) on one core, beside a plain implementation
that calls scipy.integrate.quad per velocity (the survival S(t_a) needs the
cumulative hazard, itself a quad: a nested quad).  The plain one is timed on
a subset of velocities spread over the same range and scaled to 1000.

1000 velocities run the compiled march (stickslip.quasistatic.steady_kernel); the
numpy march (what narrower calls use) is timed beside it in the same run, and
the first call's cost (loading numba and its cached machine code, or
compiling it when the cache is cold) is printed apart.

    python benchmarks/bench_steady.py
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"  # one core, as the issue asks

import math  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402
from scipy.integrate import quad  # noqa: E402

from stickslip import load_parameters, steady_state  # noqa: E402
from stickslip.quasistatic import steady  # noqa: E402

VELOCITIES = np.geomspace(10e-6, 10e-3, 1000)
PLAIN_SUBSET = 12


def plain_quad_stress(params, velocity: float) -> float:
    """Eqs 6-8 the straightforward way: nested adaptive quadrature, one velocity at a time."""
    b, g = params.bonds, params.aging
    t_max = b.max_extension / velocity
    aging = math.exp(-velocity / g.aging_velocity) / g.aging_time

    def hazard(t):
        x = t / t_max
        exponent = b.force_sensitivity * b.chain_stiffness * t * velocity / (1 - x * x) - t * aging
        return b.breakage_weight / b.bond_time * math.exp(min(exponent, 700.0))

    def survival(t):
        return math.exp(-quad(hazard, 0.0, t, limit=200)[0])

    end = t_max * (1 - 1e-12)
    bonded = quad(survival, 0.0, end, limit=200)[0]
    moment = quad(lambda t: t * survival(t) / (1 - (t / t_max) ** 2), 0.0, end, limit=200)[0]
    return b.chain_stiffness * velocity * b.site_density * moment / (b.bond_time + bonded)


def _runs(params, repeat: int = 30) -> tuple[list[float], list[float], object]:
    """(wall times, CPU times, last result) of ``repeat`` steady_state calls on VELOCITIES."""
    runs, cpu, fast = [], [], None
    for _ in range(repeat):
        start, start_cpu = time.perf_counter(), time.process_time()
        fast = steady_state(params, VELOCITIES)
        runs.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    return runs, cpu, fast


def main() -> None:
    params = load_parameters("gelatin-glass")
    start_cpu = time.process_time()
    steady_state(params, VELOCITIES)  # first call: numba and the compiled march (from its disk cache) load
    first_cpu = time.process_time() - start_cpu
    runs, cpu, fast = _runs(params)
    best, median = min(runs), statistics.median(runs)
    lanes = steady.COMPILED_LANES
    steady.COMPILED_LANES = 10**12  # the numpy march, in the same run
    try:
        _, numpy_cpu, numpy_curve = _runs(params)
    finally:
        steady.COMPILED_LANES = lanes
    march_difference = float(np.max(np.abs(fast.stress / numpy_curve.stress - 1)))

    subset = VELOCITIES[np.linspace(0, VELOCITIES.size - 1, PLAIN_SUBSET).astype(int)]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        start = time.perf_counter()
        plain = np.array([plain_quad_stress(params, float(v)) for v in subset])
        plain_per_velocity = (time.perf_counter() - start) / subset.size
    plain_total = plain_per_velocity * VELOCITIES.size
    agreement = np.max(np.abs(steady_state(params, subset).stress / plain - 1))

    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, one thread")
    print("sigma(V), gelatin-glass with aging, 1000 log-spaced velocities, 10 um/s - 10 mm/s")
    print(f"  stickslip.steady_state   best {best * 1e3:8.2f} ms   median {median * 1e3:8.2f} ms   (30 runs, wall)")
    cpu_best, cpu_median = min(cpu) * 1e3, statistics.median(cpu) * 1e3
    print(f"                           best {cpu_best:8.2f} ms   median {cpu_median:8.2f} ms   (cpu)")
    print(
        f"  plain nested scipy quad  {plain_total:8.2f} s    ({plain_per_velocity * 1e3:.0f} ms per velocity,"
        f" timed on {subset.size} velocities)"
    )
    numpy_best, numpy_median = min(numpy_cpu) * 1e3, statistics.median(numpy_cpu) * 1e3
    print(f"  numpy march (narrow calls) best {numpy_best:8.2f} ms   median {numpy_median:8.2f} ms   (cpu)")
    print(
        f"  compiled / numpy (median cpu): {statistics.median(cpu) / statistics.median(numpy_cpu):.2f};"
        f" max relative difference of their stresses {march_difference:.1e}"
    )
    print(f"  first call (loads numba and the cached compiled march): {first_cpu:.2f} s cpu")
    print(f"  speed-up (plain / best)  {plain_total / best:8.0f}x")
    print(
        f"  max relative difference of the two on the subset: {agreement:.1e}"
        f" (the plain quad raised {len(caught)} IntegrationWarnings near the FENE end)"
    )
    print(f"  Vc on this grid ~ {VELOCITIES[np.argmin(fast.stress)] * 1e6:.1f} um/s (the curve's minimum)")


if __name__ == "__main__":
    main()
