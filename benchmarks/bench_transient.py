"""Time-dependent model: the cohort solver against a plain method-of-lines solve_ivp in the same run.

Run as ``PYTHONPATH=src python benchmarks/bench_transient.py``.  Prints wall and process time (best and
median) and the accuracy reached against the steady solver.
"""

from __future__ import annotations

import numpy as np

import stickslip
from stickslip.protocols import constant
from stickslip.transient import run_transient
from timing import timed


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


def main() -> None:
    p = stickslip.load_parameters("gelatin-glass")
    run_transient(p, constant(350e-6, 1e-3), control="velocity")  # compile / load the numba cache
    v = 350e-6
    ref = stickslip.steady_state(p, v)
    best, med, cpu, run = timed(lambda: run_transient(p, constant(v, 0.012), control="velocity", rtol=1e-4), 3)
    err = abs(run.final_stress / float(ref.stress) - 1)
    print(
        f"constant V = 350 um/s from empty, 12 ms (54 tau), rtol 1e-4: best {best:.3f} s, median {med:.3f} s, "
        f"cpu {cpu:.3f} s, {run.steps} steps, sigma error {err:.2e}"
    )
    best, med, cpu, out = timed(lambda: method_of_lines(p, v, 0.012), 1)
    print(
        f"  method of lines (400 age cells, BDF): {best:.3f} s, cpu {cpu:.3f} s, sigma error "
        f"{abs(out[0] / float(ref.stress) - 1):.2e}"
    )
    best, med, cpu, run = timed(lambda: run_transient(p, constant(v, 0.012), control="velocity", rtol=1e-5), 3)
    err = abs(run.final_stress / float(ref.stress) - 1)
    print(f"  same at rtol 1e-5: best {best:.3f} s, median {med:.3f} s, {run.steps} steps, sigma error {err:.2e}")
    for rtol in (1e-3, 1e-4):
        best, med, cpu, run = timed(
            lambda rtol=rtol: run_transient(
                p, constant(50e-6, 25.0), start="steady", start_velocity=350e-6, rtol=rtol, stick_population=True
            ),
            1,
        )
        c = run.cycles[0]
        print(
            f"block, 350 -> 50 um/s with the stick chains, 25 s (slide, stick, jump, slip), rtol {rtol:g}: "
            f"{best:.2f} s wall, cpu {cpu:.2f} s, {run.steps} steps; stick {c.stick_time:.4f} s, "
            f"sigma_s {c.peak_stress:.3f} Pa, jump {c.jump_velocity * 1e6:.2f} um/s, slip {c.slip_time} s"
        )
    for rtol in (1e-3, 1e-4):
        best, med, cpu, run = timed(
            lambda rtol=rtol: run_transient(p, constant(350e-6, 1.0), start="steady", rtol=rtol, every=1e-3), 1
        )
        print(
            f"block, steady sliding at 350 um/s, 1 s, rtol {rtol:g}: {best:.2f} s wall, cpu {cpu:.2f} s, "
            f"{run.steps} steps, final sigma {run.final_stress:.4f} Pa (steady solver {float(ref.stress):.4f})"
        )
    best, med, cpu, run = timed(lambda: run_transient(p, constant(50e-6, 25.0), rtol=1e-3), 1)
    print(
        f"block, 50 um/s from rest, 25 s, rtol 1e-3: {best:.2f} s wall, cpu {cpu:.2f} s, {run.steps} steps, "
        f"regime {run.regime}, final sigma {run.final_stress:.4g} Pa (K V0 t = "
        f"{p.block.effective_stiffness * 50e-6 * 25:.4g} Pa)"
    )


if __name__ == "__main__":
    main()
