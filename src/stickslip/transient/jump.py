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

from ..display import velocity as show_velocity
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


#: a creeping massless block whose step collapsed (docs/transient.md section 22): at most this many cohorts at the
#: FENE wall are broken at once, one at a time, to give the slider its creeping balance back
WALL_LUMPS = 8
#: the cohorts that may be broken so: stretched beyond this share of the FENE length (aged bonds die at the wall,
#: 1 - y ~ 2e-5 after a minute of rest at the paper's set, ~2e-4 after 5 s)
WALL_REACH = 0.99
#: the block counts as creeping (stopped) below this share of the protocol's pace: the solver's stick threshold
CREEP = 1e-2
#: a creeping root of g is one within this share of the largest of its terms (K Vp, (k_int + K) V)
ROOT_TOLERANCE = 1e-8


@dataclass(frozen=True)
class WallLumps:
    """Cohorts broken at once at the FENE wall under a creeping massless block: the instant (s), how many, their
    bonds' share of N0, the load they carried (Pa), the slider's advance (m) and the stress before and after (Pa),
    the creep velocity before and after (m/s)."""

    time: float
    cohorts: int
    broken_share: float
    load: float
    travel: float
    stress_before: float
    stress_after: float
    velocity_before: float
    velocity_after: float


def _creeping_root(
    x: float, t: float, v: float, vp: float, n: int, xb: np.ndarray, tb: np.ndarray, lw: np.ndarray, p: np.ndarray,
    functions: dict[str, Any], scratch: tuple[np.ndarray, np.ndarray, np.ndarray], creep: float,
) -> float | None:  # fmt: skip
    """The stable root of g nearest the creep velocity v at slider position x, if it is one (g there within
    :data:`ROOT_TOLERANCE` of its terms, g' > 0, below ``creep``); None where g has no creeping root."""
    lc, aa, known = scratch
    known.fill(-1.0)
    root = float(functions["_slider_velocity"](v, vp, n, xb, tb, lw, x, t, p, lc, aa, known))
    if not (math.isfinite(root) and 0.0 <= root <= creep):
        return None
    known.fill(-1.0)
    k_int = functions["_velocity_prepare"](n, xb, tb, lw, x, t, p, lc, aa, known, np.empty((2, 0)))
    g, slope, _ = functions["_velocity_residual"](root, vp, n, lc, aa, known, k_int, p)
    scale = max(p[K.P_K] * abs(vp), (k_int + p[K.P_K]) * root)
    return root if abs(g) <= ROOT_TOLERANCE * scale and slope > 0.0 else None


def wall_lumps(
    t: float, x: float, v: float, puller: float, vp: float, pace: float, n: int, xb: np.ndarray, tb: np.ndarray,
    lw: np.ndarray, p: np.ndarray, functions: dict[str, Any],
) -> tuple[float, float, int, WallLumps, float] | None:  # fmt: skip
    """A creeping massless block whose step collapsed because a cohort at the FENE wall holds the slider alone.

    A cohort stands for the bonds born over its cell (0.3-2 nm of slider travel on a slip's way to rest); held at
    rest those bonds age until they die only at the FENE wall, within ~1e-16 m of it, and a continuous density of
    them dies there as the slider creeps on: the interface stays stiff (dS/dX ~ 1e10 Pa/m, far above K) and the
    creep goes on.  The cohort instead arrives as one lump carrying up to a fifth of sigma, whose death the slider
    cannot follow by creep (g has no creeping root: the step collapses).  Such a cohort is broken at once (the
    largest loss w r f at the wall first), the slider put where the survivors balance the spring, until g has a
    creeping root again, at most :data:`WALL_LUMPS` cohorts.  None (nothing changed) where the block is not
    creeping, where the cohort that carries the largest loss is not at the wall, or where no creeping balance
    comes back (the block may then let go: the caller says so).  Otherwise the survivors are compacted in place,
    as :func:`cascade` does, and (x, v, n, the record, the energy dissipated, J/m^2) is returned."""
    creep = CREEP * pace
    if not (0.0 <= v <= creep and n > 0):
        return None
    balance, sums = functions["_balance_weights"], functions["_sums"]
    n_before, sigma_before, _, bond_energy_before = sums(n, xb, lw, x, p)
    x_before = x
    alive = np.isfinite(lw[:n])
    weights = np.where(alive, np.exp(np.where(alive, lw[:n], 0.0)), 0.0)
    live_lw = lw[:n].copy()
    scratch = (np.empty(n), np.empty(n), np.empty((3, n)))
    broken = 0
    load = 0.0
    while True:
        x = balance(x, puller, n, xb, weights, p)
        root = _creeping_root(x, t, v, vp, n, xb, tb, live_lw, p, functions, scratch, creep) if broken else None
        if root is not None:
            break
        if broken == WALL_LUMPS:
            return None
        live = np.flatnonzero(alive)
        e = x - xb[live]
        y = e / p[K.P_DLM]
        force = p[K.P_M] * e / (1.0 - y * y)
        # log 0 = -inf for a cohort that carries no load (force <= 0) or no weight: it cannot be the largest loss,
        # which argmax picks from the others, so -inf is the right answer there, not a hidden error
        with np.errstate(divide="ignore"):
            loss = np.log(weights[live] * np.maximum(force, 0.0)) + _log_hazard(e, t - tb[live], v, p)
        first = int(np.argmax(loss))
        if not y[first] >= WALL_REACH:  # the collapse is not a lump at the wall
            return None
        j = live[first]
        load += float(weights[j] * force[first])
        alive[j], weights[j], live_lw[j] = False, 0.0, -np.inf
        broken += 1
    keep = np.flatnonzero(alive)
    m = keep.size
    xb[:m], tb[:m], lw[:m] = xb[keep], tb[keep], lw[keep]
    n_after, sigma_after, _, bond_energy_after = sums(m, xb, lw, x, p)
    released = 0.5 * p[K.P_K] * ((puller - x_before) ** 2 - (puller - x) ** 2)
    record = WallLumps(
        time=t, cohorts=broken, broken_share=float((n_before - n_after) / p[K.P_N0]), load=load, travel=x - x_before,
        stress_before=float(sigma_before), stress_after=float(sigma_after), velocity_before=v, velocity_after=root,
    )  # fmt: skip
    return x, root, m, record, released - (bond_energy_after - bond_energy_before)


def lumps_note(lumps: list[WallLumps]) -> str:
    """The cohorts broken at the FENE wall under a creeping block, in words for the run's message ('' if none)."""
    if not lumps:
        return ""
    count = sum(lump.cohorts for lump in lumps)
    share = sum(lump.broken_share for lump in lumps)
    travel = max(lump.travel for lump in lumps)
    change = max(abs(lump.stress_after - lump.stress_before) for lump in lumps)
    return (
        f"; the block stayed stopped while its oldest bonds reached the FENE wall, and {count} cohort(s) of them that"
        f" held the creeping slider alone were broken at once, from t = {lumps[0].time:.6g} s ({share:.3g} N0 in all;"
        f" each time the slider moved at most {travel * 1e9:.3g} nm and σ by at most {change:.2g} Pa): the cohort"
        " method lumps bonds that die one by one as the slider creeps, and the creep velocity it gives is the lumps'"
        " too, far below the bonds' own (docs/transient.md section 22)"
    )


def creep_collapse(t: float, sigma: float, v: float, lumps: int) -> str:
    """The failure in words where no creeping balance came back after :data:`WALL_LUMPS` cohorts at the wall."""
    return (
        f"transient solver failed at t = {t:.6g} s: the block had stopped and was creeping ({v * 1e6:.3g} µm/s under"
        f" σ = {sigma:.6g} Pa) when its oldest bonds reached the FENE wall and gave way, and breaking the {lumps}"
        " cohorts there did not leave the slider a creeping balance: the block may let go here, from rest, and a"
        " block without mass cannot follow that (no finite slip velocity); give the block a mass (--mass, with"
        " --damping; docs/extensions.md section 4) to follow it; what follows is not known"
    )


#: under velocity control, a cohort whose hazard would leave it e^-INSTANT of its weight within the kernel's floor
#: step (1e-15 of the time reached) dies at once: the clock cannot resolve its death (docs/transient.md section 24)
INSTANT = 30.0


@dataclass(frozen=True)
class InstantDeaths:
    """Cohorts that died at once under velocity control: the instant (s), the imposed velocity (m/s), how many, their
    bonds' share of N0, the stress before and after (Pa), and the age of the oldest (s)."""

    time: float
    velocity: float
    cohorts: int
    broken_share: float
    stress_before: float
    stress_after: float
    oldest: float


def instant_deaths(
    t: float, x: float, v: float, n: int, xb: np.ndarray, tb: np.ndarray, lw: np.ndarray, p: np.ndarray,
    functions: dict[str, Any],
) -> tuple[int, InstantDeaths, float, float] | None:  # fmt: skip
    """Under velocity control (the slider at x moving at the imposed v), the cohorts that die within the kernel's
    floor step, broken at once.

    Eq 1 as printed erases the aging term at the velocity's pace: a velocity step from V to 3 V takes
    t_a/tau_a (e^(-V/V_a) - e^(-3V/V_a)) off ln r at once, over 100 for the oldest bonds of a steady population whose
    aging held them against the FENE force (tester Y's set 31: ln r from 16 to 139, 23 % of sigma on cohorts that
    die within 1e-17 s).  Their stress falls in no time; a step of the kernel loses more than a fifth of sigma
    however short (kernel.MAX_DROP) and collapsed to the floor.  Each cohort with ln r + ln(floor) >= ln INSTANT is
    broken (its bonds keep e^-30 of their weight within the floor step, within the e^-30 that bounds the rest), the
    survivors compacted in place (oldest first, as :func:`cascade` keeps them).  None where no cohort dies so (the
    collapse is another: the caller says so in words); else (n, the record, the energy dissipated in J/m^2, the
    largest surviving ln r)."""
    if n <= 0:
        return None
    floor = 1e-15 * max(t, p[K.P_TAU])
    alive = np.isfinite(lw[:n])
    live = np.flatnonzero(alive)
    if not live.size:
        return None
    hazard = _log_hazard(x - xb[live], t - tb[live], v, p)
    dying = hazard + math.log(floor) >= math.log(INSTANT)
    if not dying.any():
        return None
    sums = functions["_sums"]
    n_before, sigma_before, _, bond_energy_before = sums(n, xb, lw, x, p)
    dead = live[dying]
    oldest = float(t - np.min(tb[dead]))
    alive[dead] = False
    keep = np.flatnonzero(alive)
    m = keep.size
    xb[:m], tb[:m], lw[:m] = xb[keep], tb[keep], lw[keep]
    n_after, sigma_after, _, bond_energy_after = sums(m, xb, lw, x, p)
    record = InstantDeaths(
        time=t, velocity=v, cohorts=int(dead.size), broken_share=float((n_before - n_after) / p[K.P_N0]),
        stress_before=float(sigma_before), stress_after=float(sigma_after), oldest=oldest,
    )  # fmt: skip
    rest = float(np.max(hazard[~dying])) if (~dying).any() else -math.inf
    return m, record, float(bond_energy_before - bond_energy_after), rest


def instant_note(deaths: list[InstantDeaths]) -> str:
    """The cohorts that died at once under velocity control, in words for the run's message ('' if none)."""
    if not deaths:
        return ""
    first = deaths[0]
    share = sum(d.broken_share for d in deaths)
    more = f" (and {len(deaths) - 1} more time(s) after it, {share:.3g} N0 in all)" if len(deaths) > 1 else ""
    return (
        f"; at t = {first.time:.6g} s, sliding at {show_velocity(first.velocity, 4)}, {first.cohorts} cohort(s) of"
        f" bonds up to {first.oldest:.3g} s old ({first.broken_share:.3g} N0) died at once,"
        f" σ {first.stress_before:.6g} → {first.stress_after:.6g} Pa{more}: Eq 1 erases the aging term at the"
        " velocity's pace, and the aged bonds it held against their stretch died faster than the clock resolves"
        " (docs/transient.md section 24)"
    )
