"""Benchmark: stick-slip cycles at 50 um/s (issue 3, item 9), beside a plain reference in the same run.

Targets: one whole cycle <= 20 ms, 100 cycles <= 1 s.

* package: ``stickslip.quasistatic.cycle.simulate`` over one period and over 100 periods.  "cold" is the
  first call for a parameter set (it includes the critical-point search and the steady-branch series,
  both cached per parameter set afterwards); "warm" is every later call.
* reference: the plain approach — ``solve_ivp`` (LSODA) on Eq 15 in time until Nc/Nc0 = 0.2 (a
  time-stepper cannot go much further), then ``solve_ivp`` (RK45) on Eq 10 in time with a scalar
  ``steady_state`` call for dsigma/dV at every right-hand side, until V = 1.001 Vc (dV/dt -> -inf at
  Vc); the jump by ``brentq`` on scalar ``steady_state`` calls.  Each cycle is recomputed, as a plain
  loop would; 100 cycles are extrapolated from one (said so in the output).

Run: ``/work/venv/bin/python benchmarks/bench_cycle.py``
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from stickslip.parameters import load_parameters
from stickslip.quasistatic import jump as jump_module
from stickslip.quasistatic.critical import critical_point
from stickslip.quasistatic.cycle import simulate
from stickslip.quasistatic.steady import steady_state
from timing import best_of

V0 = 50e-6


def reference_cycle(params, sigma_c: float, v_c: float) -> tuple[float, float, float]:
    """(stick time, jump velocity, slip time) the plain way."""
    b, nc0 = params.bonds.force_sensitivity, params.stick.attached_chains
    r, tau_a, k_eff = params.stick.break_rate, params.stick.aging_time, params.block.effective_stiffness

    def eq15(t, y):  # y = ln n
        return [-r * math.exp(b * (sigma_c + k_eff * V0 * t) / (nc0 * math.exp(y[0])) - t / tau_a)]

    def chains_gone(t, y):
        return y[0] - math.log(0.2)

    chains_gone.terminal = True
    stick = solve_ivp(eq15, (0.0, 1e4), [0.0], method="LSODA", rtol=1e-10, atol=1e-12, events=chains_gone)
    ts = float(stick.t_events[0][0])
    sigma_s = sigma_c + k_eff * V0 * ts
    vs = brentq(lambda v: float(steady_state(params, v).stress) - sigma_s, v_c * 1.0001, 5e-3, xtol=1e-12)

    def eq10(t, y):
        return [-k_eff * (y[0] - V0) / float(steady_state(params, y[0]).stress_slope)]

    def near_vc(t, y):
        return y[0] - 1.001 * v_c

    near_vc.terminal = True
    slip = solve_ivp(eq10, (0.0, 100.0), [vs], method="RK45", rtol=1e-8, atol=1e-12, events=near_vc)
    return ts, vs, float(slip.t_events[0][0])


def main() -> None:
    params = load_parameters()
    jump_module.cached_critical_point.cache_clear()
    jump_module.branch_interpolant.cache_clear()
    start = time.perf_counter()
    first = simulate(params, V0, 30.0)
    cold = time.perf_counter() - start
    period = first.cycles[0].period
    one_warm, one = best_of(lambda: simulate(params, V0, period), 7)
    hundred, many = best_of(lambda: simulate(params, V0, 100 * period), 3)

    cp = critical_point(params)
    ref_time, (ts_ref, vs_ref, slip_ref) = best_of(lambda: reference_cycle(params, cp.stress, cp.velocity), 1)
    ours = one.cycles[0]

    print(f"stick-slip at V0 = {V0 * 1e6:g} um/s, gelatin-glass: period {period:.6f} s")
    print(f"{'task':<34}{'package':>14}{'reference':>16}{'speed-up':>10}")
    print(f"{'one whole cycle (warm)':<34}{one_warm * 1e3:>11.1f} ms{ref_time * 1e3:>13.1f} ms"
          f"{ref_time / one_warm:>9.0f}x   target <= 20 ms")  # fmt: skip
    print(f"{'one whole cycle (cold: + Vc, series)':<34}{cold * 1e3:>11.1f} ms{'':>16}{'':>10}")
    print(f"{'100 cycles (warm)':<34}{hundred * 1e3:>11.1f} ms{100 * ref_time:>14.2f} s*"
          f"{100 * ref_time / hundred:>9.0f}x   target <= 1 s")  # fmt: skip
    print("  * extrapolated: 100 x the measured reference cycle")
    print(f"  cycles in the 100-period run: {len(many.cycles)}, trace rows: {many.time.size}")
    print()
    print(f"{'quantity':<34}{'package':>16}{'reference':>16}")
    print(f"{'stick time ts (s)':<34}{ours.stick_time:>16.10f}{ts_ref:>16.10f}   (reference stops at Nc/Nc0 = 0.2)")
    print(f"{'jump velocity Vs (um/s)':<34}{ours.jump_velocity * 1e6:>16.8f}{vs_ref * 1e6:>16.8f}")
    print(f"{'slip time (s)':<34}{ours.slip_time:>16.10f}{slip_ref:>16.10f}   (reference stops at 1.001 Vc)")
    # the part of the slip the reference cannot do: from 1.001 Vc to Vc
    traj = one.slip_phases[0].trajectory
    rest = ours.slip_time - float(traj.time(np.log(1.001 * cp.velocity)))
    print(f"{'  of which from 1.001 Vc to Vc':<34}{rest:>16.10f}")


if __name__ == "__main__":
    main()
