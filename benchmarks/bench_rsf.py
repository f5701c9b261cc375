"""Benchmark of rate-and-state friction (issue 10), each case beside a plain ``solve_ivp`` implementation.

Targets: the rsfmodel velocity step 1 -> 10 over 40 s <= 20 ms; a 500 s damped stick-slip run <= 0.2 s;
a two-state fit of a 16,000-row record <= 5 s.

* step: rsfmodel's aging case (a = 0.005, b = 0.01, Dc = 10, k = 1e-3, V0 = 1; step at t = 10), sampled
  every 0.01 s (rsfmodel's grid).  Ours: ``stickslip.rsf.simulate(..., every=0.01)`` (LSODA in log V, log theta,
  analytic Jacobian, restart at the step).  Plain: ``solve_ivp`` (LSODA) on (mu, theta) as rsfmodel writes the
  equations, with ``t_eval``, restarted at the step.  Both at rtol 1e-10; accuracy against rsfmodel's published
  friction at t = 0, 1, ..., 40 s (tests/test_rsf_rsfmodel.py).
* stick-slip: aging law, a = 0.01, b = 0.015, Dc = 1 um (a limit cycle of period 34 s), k = kc/2,
  eta = 1 s/m, V = 1 um/s, 500 s sampled every 0.05 s; plain: the same equations in (mu, theta) with
  ``solve_ivp`` (LSODA).
* fit: a synthetic two-state record of 16,000 rows (step 0.2 -> 2 um/s, white noise 3e-4) fitted with
  ``fit_record(states=2)``; plain: the time of one ``solve_ivp`` model evaluation times our number of
  evaluations (a plain lmfit run would take minutes; said so in the output).

Figures are best and median of several repeats, wall time and CPU time (``time.process_time``).
Run: ``PYTHONPATH=src python benchmarks/bench_rsf.py``
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from stickslip import protocols
from stickslip.rsf import rsf_params, simulate
from stickslip.rsf.data import LabRecord
from stickslip.rsf.fit import fit_record
from timing import best_of, timed

PUBLISHED = np.array([0.6] * 11 + [0.60720485, 0.60186637, 0.5840091, 0.58563096, 0.58899543, 0.58998186,
                                   0.58879751, 0.58803412, 0.58825653, 0.58858313, 0.58860319, 0.58848625,
                                   0.58844431, 0.58847472, 0.58849913, 0.58849522, 0.58848506, 0.58848348,
                                   0.58848674, 0.5884883, 0.58848756, 0.58848677, 0.5884868, 0.58848711,
                                   0.58848718, 0.5884871, 0.58848704, 0.58848706, 0.58848708, 0.58848708])  # fmt: skip


def plain_rsf(a, b, dc, v0, k, mu0, eta, pieces, t_eval, y0=None):
    """mu and theta integrated as rsfmodel writes them (aging law), one solve_ivp per protocol piece."""

    def rhs(t, y, vlp):
        mu, theta = y
        v = v0 * np.exp((mu - mu0 - b * np.log(v0 * theta / dc)) / a)
        dtheta = 1 - v * theta / dc
        # with damping: dmu/dt = k (vlp - v) - eta dV/dt, dV/dt = V/a (dmu/dt - b dtheta/theta)
        dmu = (k * (vlp - v) + eta * v / a * b * dtheta / theta) / (1 + eta * v / a)
        return [dmu, dtheta]

    y = np.array([mu0, dc / v0] if y0 is None else y0)
    out = [np.array([y[0]])]
    for t0, t1, vlp in pieces:
        inside = t_eval[(t_eval > t0) & (t_eval < t1)]
        times = np.concatenate([inside, [t1]])
        sol = solve_ivp(rhs, (t0, t1), y, method="LSODA", args=(vlp,), t_eval=times, rtol=1e-10, atol=1e-12)
        y = sol.y[:, -1]
        out.append(sol.y[0] if t1 in t_eval else sol.y[0][:-1])
    return np.concatenate(out)


def bench_step() -> None:
    p = rsf_params(0.005, 0.01, 10.0, v_ref=1.0, stiffness=1e-3)
    step = protocols.velocity_steps([1.0, 10.0], [10.0, 30.0])
    grid = np.round(np.arange(0, 4001) * 0.01, 10)
    best, med, cpu, run = timed(lambda: simulate(p, step, every=0.01), 7)
    err = np.max(np.abs(run.friction[::100] - PUBLISHED))
    pieces = [(0.0, 10.0, 1.0), (10.0, 40.0, 10.0)]
    pb, pm, pc, mu = timed(lambda: plain_rsf(0.005, 0.01, 10.0, 1.0, 1e-3, 0.6, 0.0, pieces, grid), 3)
    perr = np.max(np.abs(mu[::100] - PUBLISHED))
    print(f"step 1 -> 10, 40 s, 4001 samples   ours: best {best * 1e3:.1f} ms, median {med * 1e3:.1f} ms "
          f"(CPU {cpu * 1e3:.1f} ms); max |mu - rsfmodel| {err:.1e}")  # fmt: skip
    print(f"                                   solve_ivp: best {pb * 1e3:.1f} ms, median {pm * 1e3:.1f} ms "
          f"(CPU {pc * 1e3:.1f} ms); max |mu - rsfmodel| {perr:.1e}   [target <= 20 ms]")  # fmt: skip


def bench_stick_slip() -> None:
    dc = 1e-6
    p = rsf_params(0.01, 0.015, dc, v_ref=1e-6, stiffness=0.5 * 0.005 / dc, eta=1.0)
    run_protocol = protocols.constant(1e-6, 500.0)
    best, med, cpu, run = timed(lambda: simulate(p, run_protocol, start_velocity=1.1e-6, every=0.05), 5)
    grid = np.arange(0, 10001) * 0.05
    y0 = [0.6 + 0.01 * np.log(1.1) - 0.015 * np.log(1.1), dc / 1.1e-6]
    pb, pm, pc, _ = timed(
        lambda: plain_rsf(0.01, 0.015, dc, 1e-6, p.stiffness, 0.6, 1.0, [(0.0, 500.0, 1e-6)], grid, y0), 2
    )
    print(f"damped stick-slip, 500 s           ours: best {best:.3f} s, median {med:.3f} s (CPU {cpu:.3f} s); "
          f"{run.regime.name}, period {run.regime.period:.4g} s")  # fmt: skip
    print(f"                                   solve_ivp: best {pb:.3f} s, median {pm:.3f} s (CPU {pc:.3f} s)"
          "   [target <= 0.2 s]")  # fmt: skip


def bench_fit() -> None:
    truth = rsf_params(0.012, 0.008, 20e-6, b2=0.006, dc2=200e-6, v_ref=0.2e-6, stiffness=2000.0, mu0=0.45)
    step = protocols.velocity_steps([0.2e-6, 2e-6], [1200.0, 1000.0])
    t = np.linspace(0, step.duration, 16000)
    clean = simulate(truth, step, times=t)
    rng = np.random.default_rng(3)
    record = LabRecord.from_arrays(
        t, clean.load_point_displacement, clean.friction + 3e-4 * rng.standard_normal(t.size)
    )
    best, med, cpu, fit = timed(lambda: fit_record(record, states=2, stiffness=2000.0), 3)
    pieces = [(0.0, 1200.0, 0.2e-6), (1200.0, 2200.0, 2e-6)]
    one = best_of(lambda: plain_rsf(0.012, 0.014, 20e-6, 0.2e-6, 2000.0, 0.45, 0.0, pieces, t), 1)[0]
    print(f"two-state fit, 16,000 rows         ours: best {best:.2f} s, median {med:.2f} s (CPU {cpu:.2f} s), "
          f"{fit.nfev} evaluations; a = {fit.parameters['a'].value:.4g} (0.012), "
          f"dc = {fit.parameters['dc'].value * 1e6:.3g} um (20)")  # fmt: skip
    print(f"                                   plain solve_ivp model: {one:.3f} s per evaluation x {fit.nfev} = "
          f"{one * fit.nfev:.1f} s (extrapolated)   [target <= 5 s]")  # fmt: skip


if __name__ == "__main__":
    print("measured on a shared 2-core machine (contended): wall times vary; CPU times are steadier")
    bench_step()
    bench_stick_slip()
    bench_fit()
