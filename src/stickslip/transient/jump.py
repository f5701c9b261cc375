"""The massless block's jump through a rupture cascade (issue 33 item 1; docs/transient.md section 2b).

Through a spring far softer than the bonds (K << k_int), bonds that start to give way leave their load to the
survivors, which then break faster: the slider accelerates without bound (4e8 m/s within 3e-17 s in issue 33's
case), and a time step can no longer be told from the time reached.  A block without inertia has no finite slip
velocity there: the cascade takes no time.  With the time held, the slider is put where the survivors balance the
spring, and while the slider velocity of Eq 1 at that balance is still beyond what the time steps can follow, the
cohort with the highest hazard breaks (it would break first, within a time that does not count); the slider moves
on to the next balance.  Either the cascade is arrested (the velocity at a balance falls below :data:`EXIT` x the
protocol's pace, and the time steps take over again), or every bond breaks and the spring relaxes: sigma = 0 at
the same instant, and the bonds grow again from empty.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import kernel as K

#: the kernel's step collapsed with the slider faster than this many times the protocol's fastest velocity: a
#: cascade, which the jump takes over
ENTRY = 1e3
#: beyond FAR x EXIT x the pace the cohorts break up to 1/BATCH of the live ones at a time (the highest hazards):
#: a cascade through 5e4 cohorts one at a time would cost 5e4 balances
FAR, BATCH = 1e6, 200
#: the aging term is erased (e^-V/V_a < 1e-21) beyond this many aging velocities
FAST = 50.0
#: the jump hands back to the time steps once the slider velocity at a balance is below this many times the pace
EXIT = 1e3


@dataclass(frozen=True)
class Jump:
    """One jump: its instant (s), the stress before and after (Pa), the slider's travel (m), the bonds broken
    (per m^2, the share of N0 in ``broken_share``) and the cohorts left."""

    time: float
    stress_before: float
    stress_after: float
    travel: float
    broken_share: float
    survivors: int

    def describe(self) -> str:
        after = (
            "every bond broke and the spring relaxed" if self.survivors == 0 else f"{self.survivors} cohorts held on"
        )
        return (
            f"the block jumped at t = {self.time:.6g} s: σ {self.stress_before:.6g} → {self.stress_after:.4g} Pa,"
            f" the slider slid {self.travel * 1e3:.4g} mm in no time ({self.broken_share:.3g} N0 of bonds broke;"
            f" {after})"
        )


def _log_hazard(e: np.ndarray, age: np.ndarray, v: float, p: np.ndarray) -> np.ndarray:
    """ln r of Eq 1 at slider velocity v (the kernel's _log_rate, for an array of live cohorts)."""
    y = e / p[K.P_DLM]
    force = p[K.P_M] * e / (1.0 - y * y)
    slope = p[K.P_INV_TAU_A] * math.exp(-abs(v) / p[K.P_VA]) if p[K.P_AGING] > 0.0 else 0.0
    ts = p[K.P_SATURATION]
    clock = -ts * np.expm1(-age / ts) if ts > 0.0 else age
    return p[K.P_LOG_U0_TAU] + p[K.P_FORCE_SENS] * np.abs(force) - clock * slope


def _fast_root(
    x: float, t: float, n: int, xb: np.ndarray, tb: np.ndarray, lw: np.ndarray, vp: float, p: np.ndarray, prepare: Any,
    scratch: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> float:  # fmt: skip
    """The root of g with the aging term erased, (K Vp + sum w r f)/(K + k_int): g's largest root wherever it is
    many V_a fast.  ``prepare``: the kernel's _velocity_prepare (k_int, each cohort's ln(w r) without the aging
    term, capped below as the kernel's residual caps it, and its force f in known[1]); ``scratch``: its work arrays
    (lc, aa, known)."""
    lc, aa, known = scratch
    known.fill(-1.0)
    k_int = prepare(n, xb, tb, lw, x, t, p, lc, aa, known, np.empty((2, 0)))
    live = lc[:n] > -np.inf
    with np.errstate(over="ignore"):  # a cohort at the FENE wall: its w f r capped as the kernel caps it
        terms = np.minimum(known[1, :n][live] * np.exp(np.minimum(lc[:n][live], K.LOG_RATE_CAP)), K.MAX_RATE)
    loss = float(np.sum(terms))
    return (p[K.P_K] * vp + loss) / (p[K.P_K] + k_int)


def cascade(
    t: float, x: float, v: float, puller: float, vp: float, pace: float, n: int, xb: np.ndarray, tb: np.ndarray,
    lw: np.ndarray, p: np.ndarray, functions: dict[str, Any],
) -> tuple[float, float, int, Jump, float]:  # fmt: skip
    """The cascade at time t from slider position x (velocity v): the survivors are compacted in place in xb, tb,
    lw (oldest first, as the kernel keeps them).  Returns (x, v, n, the jump, the energy dissipated in it, J/m^2)."""
    balance, velocity, sums = functions["_balance_weights"], functions["_slider_velocity"], functions["_sums"]
    n_before, sigma_before, _, bond_energy_before = sums(n, xb, lw, x, p)
    x_before = x
    alive = np.isfinite(lw[:n])
    weights = np.where(alive, np.exp(np.where(alive, lw[:n], 0.0)), 0.0)
    live_lw = lw[:n].copy()
    lc, aa, known = np.empty(n), np.empty(n), np.empty((3, n))
    while alive.any():
        x = balance(x, puller, n, xb, weights, p)
        v = _fast_root(x, t, n, xb, tb, live_lw, vp, p, functions["_velocity_prepare"], (lc, aa, known))
        if p[K.P_AGING] > 0.0 and v < FAST * p[K.P_VA]:  # where aging still counts, g's stable root below it
            known.fill(-1.0)
            v = velocity(v, vp, n, xb, tb, live_lw, x, t, p, lc, aa, known)
        if v <= EXIT * pace:
            break
        live = np.flatnonzero(alive)
        hazard = _log_hazard(x - xb[live], t - tb[live], v, p)
        # far from where it could be arrested, a cascade through many cohorts breaks them a share at a time
        count = max(1, live.size // BATCH) if v > FAR * EXIT * pace else 1
        first = live[np.argpartition(-hazard, count - 1)[:count]]
        alive[first] = False
        weights[first] = 0.0
        live_lw[first] = -np.inf
    keep = np.flatnonzero(alive)
    m = keep.size
    xb[:m], tb[:m], lw[:m] = xb[keep], tb[keep], lw[keep]
    if m == 0:  # nothing holds the slider: the spring relaxes (sigma = 0), the slider moves with the puller
        x, v = puller, vp
    n_after, sigma_after, _, bond_energy_after = sums(m, xb, lw, x, p)
    k_block = p[K.P_K]
    released = 0.5 * k_block * ((puller - x_before) ** 2 - (puller - x) ** 2)
    jump = Jump(
        time=t, stress_before=float(sigma_before), stress_after=float(sigma_after), travel=x - x_before,
        broken_share=float((n_before - n_after) / p[K.P_N0]), survivors=m,
    )  # fmt: skip
    return x, v, m, jump, released - (bond_energy_after - bond_energy_before)
