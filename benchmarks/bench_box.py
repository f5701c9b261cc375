"""Benchmark: the steady curve over the whole parameter box against an independent integration (issue 12).

Draws N random (parameter set, velocity, aging) points from tests/reference_steady.BOX with a fixed
seed, half of them in issue 12's deep-dip/cliff corner, evaluates them with the production quadrature
(stickslip.quasistatic.steady.steady_stress_many, paired, default settings) and with the independent
vectorised reference (tests/reference_steady.reference_many: Dormand-Prince 5(4) in an arc-length
variable, no code shared), and prints the worst relative difference in sigma and where it is.

    python benchmarks/bench_box.py [N] [SEED]
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from reference_steady import box_cases, reference_many  # noqa: E402
from stickslip import load_parameters  # noqa: E402
from stickslip.quasistatic.steady import steady_stress_many  # noqa: E402


def production(cases) -> np.ndarray:
    out = np.empty(len(cases))
    for aging in (True, False):
        index = [k for k, case in enumerate(cases) if case[2] is aging]
        if index:
            params = [cases[k][0] for k in index]
            out[index] = steady_stress_many(params, [cases[k][1] for k in index], aging=aging, paired=True)
    return out


def main() -> None:
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 20000
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 2026
    cases = box_cases(seed, count, load_parameters("gelatin-glass"), corner_share=0.5)
    start, cpu = time.perf_counter(), time.process_time()
    got = production(cases)
    prod_wall, prod_cpu = time.perf_counter() - start, time.process_time() - cpu
    start, cpu = time.perf_counter(), time.process_time()
    ref, _ = reference_many(cases)
    ref_wall, ref_cpu = time.perf_counter() - start, time.process_time() - cpu
    error = np.abs(got / ref - 1.0)
    corner = np.arange(count) < count // 2
    worst = int(np.argmax(error))
    print(f"{count} random sets (seed {seed}), half in the deep-dip/cliff corner; default quadrature")
    print(f"  production (steady_stress_many, paired)  wall {prod_wall:6.2f} s  cpu {prod_cpu:6.2f} s")
    print(f"  independent reference (reference_many)   wall {ref_wall:6.2f} s  cpu {ref_cpu:6.2f} s")
    print(f"  non-finite results: {int(np.sum(~np.isfinite(got)))}")
    worst_corner, worst_rest = error[corner].max(), error[~corner].max()
    print(f"  worst relative error in sigma: {error.max():.2e} (corner {worst_corner:.2e}, rest {worst_rest:.2e})")
    above = f"above 1e-6: {int(np.sum(error > 1e-6))}, above 1e-8: {int(np.sum(error > 1e-8))}"
    print(f"  {above}, median {np.median(error):.1e}")
    params, velocity, aging = cases[worst]
    print(f"  worst at V = {velocity:.6g} m/s, aging {aging}: {params.as_dict()}")


if __name__ == "__main__":
    main()
