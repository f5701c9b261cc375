r"""The cohort integrator of Eq 1 (numba): bonds grouped by birth time, advanced along their characteristics.

A cohort born at time ``s`` when the slider was at ``x_b`` has, at time t,
age ``t - s`` and chain extension ``X(t) - x_b`` (the slider's travel since
the bond formed, docs/transient.md section 1).  Its weight w (bonds per m^2)
obeys d ln w/dt = -r with the hazard of Eq 1,

    r = (u0/tau) exp( (lambda/kT) f(e) - (t_a/tau_a) exp(-V/V_a) ),   f(e) = M e / (1 - (e/dl_m)^2)  (Eq 3).

Births, (N0 - N)/tau per unit time, make two new cohorts per step, at the
Gauss-Legendre points of the step; the vacancy N0 - N between them solves its
linear equation exactly for a Hermite-cubic breakage rate, so steps may be
much longer than tau when nothing else moves (a stuck block).

Block control with a mass m (and a viscous damping eta) per unit area, m X'' = K (P - X) - eta X' - sigma:
the slider's position and velocity are states, advanced by the trapezoid rule (implicit in the end position,
a monotone scalar equation; second order), with the population over the step along the predicted path as
below.  Without a mass (the paper's block), sigma = K (P - X) at every instant.  Differentiating it with
sigma = sum w f(e) gives the slider velocity as the root of

    g(V) = (k_int + K) V - K V_p - sum r_i(V) w_i f_i = 0,     k_int = sum w_i f'(e_i),

which is explicit without aging and a scalar root otherwise; the root is
followed by continuity (the nearest crossing with g' > 0, the stable one for
any small mass), and when it disappears the slider jumps to the next one.

Time stepping (fourth order; see ``advance`` and docs/transient.md section 2):
each cohort's log weight by the trapezoid rule of its hazard with the
Euler-Maclaurin end correction, births at the Gauss points, and under block
control the slider put where the bonds balance the block.
Everything is SI.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np

from ..numerics.first_compile import announce_if_uncached

#: log of the largest hazard used (exp(700) ~ 1e304 per second); beyond it a cohort is gone in any step
LOG_RATE_CAP = 700.0
MAX_RATE = math.exp(LOG_RATE_CAP)  # the same cap on a cohort's w f r in the slider's residual
#: cohorts lighter than this fraction of N0 are dropped (counted as broken)
LIGHTEST = 1e-30
#: with saturating aging (docs/transient.md section 2, *Housekeeping*): a cohort is dropped once it carries less than
#: this share of rtol times the bonds alive and of the stress; saturated cohorts are merged while the spread of their
#: log hazards (aging exponent, and the force's through the slider position) stays within this share of sqrt(rtol)
LIGHT_SHARE = 1e-3
SATURATED_SPREAD = 0.1
#: cohorts lighter than the mean are binned up to 2^LIGHT_LEVELS wider (:func:`_light_spread`), those within 4x of it
#: not (compared in logs)
LIGHT_LEVELS = 5
LOG_FOUR = math.log(4.0)
#: the force term's bin, in units of the aging term's: at the fold of a creeping block (11 um/s) neighbouring births
#: differ by 1.3e-3 in log hazard through the force; 1 merged none of them (first slip from rest at 50 um/s in 60 s
#: of CPU), 3 halves the cost with the slip equal to 1e-7, 10 broke a held population's closed form (5e-5)
FORCE_SPREAD = 3.0

#: saturating aging (:func:`_relaxed_births`): the births' fixed-point sweeps run until the newborns alive at the step's
#: end move by less than this fraction of N0 (at most MAX_SWEEPS), and the Gauss pair's bias (h (r + 1/tau_a))^4/4320
#: of the births counts BIRTH_BIAS times over (held to a tenth of the share)
SWEEP_SETTLED = 1e-12
MAX_SWEEPS = 20
BIRTH_BIAS = 10.0
SATURATED_BARRIER = 30.0
#: saturating aging's clock (:func:`_aging_clock`): below this decay e^(-t_a/t_s), 1 - decay is exact to an ulp
CLOCK_PLAIN_DECAY = 0.5
#: saturating aging: saturated cohorts are merged, and the negligible dropped, every MERGE_EVERY accepted steps (the
#: bin tests were ~15 % of a step's CPU at the fold; in between at most 2 (MERGE_EVERY - 1) more cohorts are kept)
MERGE_EVERY = 4
#: at rest under velocity control, a cohort whose hazard times the step is below this keeps its weight to the last
#: bit (1 - e^(-c) < 2^-60 of it): only its age and hazard move (:func:`_cohort_pass`, docs/transient.md section 27)
FROZEN_HAZARD = 2.0**-60
#: a cohort's error by the series of 1 - e^(-c) below this end correction c (:func:`_cohort_weight`)
CORRECTION_SERIES = 1e-3

# float parameter vector layout (see pack_parameters in model.py)
(
    P_LOG_U0_TAU,
    P_TAU,
    P_FORCE_SENS,
    P_M,
    P_DLM,
    P_INV_TAU_A,
    P_VA,
    P_N0,
    P_K,
    P_AGING,
    P_SATURATION,
    P_MASS,
    P_DAMPING,
    P_MERGE_SATURATED,
    P_RELAXED_BIRTHS,
    P_WALL_LANDING,
) = range(16)
# integer status returned by advance()
DONE, FULL, STEPS, STICK, FAILED = 0, 1, 2, 3, 4
#: advance's running totals at the start of a run (its docstring names them): the extremes since the last row
#: start empty; the last entry, ACC_SPLIT, is a switch: 1 splits cohorts ahead of a hazard cliff (:func:`_split`), 0
#: not (the reference: :func:`cohorts_unsplit`)
ACC_START = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, math.inf, -math.inf, math.nan, math.nan, -math.inf, 1.0)
ACC_SPLIT = 12
#: the columns of advance's rows (:func:`_write_row`)
ROW_COLUMNS = 17
#: half-distance of the two Gauss-Legendre points from the middle of a step, as a fraction of the step
GAUSS = 0.5 / math.sqrt(3.0)
#: the weight of the first harmonic of a train of Gauss pairs, |cos 2 pi GAUSS| (docs/transient.md section 18)
GAUSS_HARMONIC = abs(math.cos(2.0 * math.pi * GAUSS))
#: a stick is taken within this share of rtol x sigma past the slider's crossing of the stick velocity
STICK_LANDING = 0.01
#: largest fraction by which the stress may fall within one step (the trace resolves ruptures)
MAX_DROP = 0.2
#: the step after an accepted one ends at this share of the time the nearest loaded cohort needs to reach the FENE
#: wall at the slider's velocity (p[P_WALL_LANDING]; 0: no such bound, ``solver.WALL_LANDING = False``); loaded:
#: carrying WALL_SHARE x rtol x |sigma| or more
WALL_LANDING = 0.9
WALL_SHARE = 0.1
#: the balanced end's bond energies follow from the predicted end's while the two lie within this share of dl_m
#: (:func:`_energy_at_end`: the rule's error, ~(shift/dl_m)^5 of the energy, is then below rounding)
ENERGY_SHIFT = 1e-4
#: cohorts cut ahead of a hazard cliff under velocity control (:func:`_split_plan`, docs/transient.md section 21): a
#: cohort stands for the bonds born over its cell (halfway to its neighbours); reaching a cliff (ln r climbing at g)
#: whose width 1/g is shorter than the time tau its cell takes to cross it, it dies as one lump, and a train of such
#: lumps leaves a sawtooth of (2/pi) s |Gamma(1 - 2 pi i/(tau g))| in the stress (s: its stress at the cliff).  Where
#: that exceeds SPLIT_TRIGGER x SPLIT_SHARE x rtol x |sigma|, the cohort is cut into the fewest equal pieces over its
#: cell (SPLIT_FEWEST to SPLIT_MOST) that bring it below SPLIT_SHARE x rtol x |sigma|, as soon as its cell's leading
#: edge is within SPLIT_FAR (in ln r) of the cliff, and while it is at least SPLIT_LATE short of it; cells that cross
#: the cliff in less than SPLIT_SPACING/g, or in more than SPLIT_STEEPEST/g (re-sliding after a 1 s hold: ~100-300/g,
#: where the pieces cost 10x the CPU), are left whole.  The cliff by Newton (SPLIT_NEWTON steps, SPLIT_TARGETS rounds
#: of ln g there); pieces are recognised as three equally spaced cohorts (relative SPLIT_EVEN); at most SPLIT_SLOTS
#: cohorts are cut per step (the others the step after)
SPLIT_SHARE = 0.1
SPLIT_TRIGGER = 2.0
SPLIT_FEWEST = 4
SPLIT_MOST = 128
SPLIT_LATE = 3.0
SPLIT_ALIVE = math.exp(SPLIT_LATE)
SPLIT_FAR = 60.0
SPLIT_SPACING = 0.4
SPLIT_EVEN = 1e-9
SPLIT_SLOTS = 64
SPLIT_NEWTON = 80
SPLIT_TARGETS = 8
SPLIT_STEEPEST = 64.0
SPLIT_ESTIMATE = 4.0
#: four-point Gauss-Legendre rule on [-1, 1]
GL4_X = np.array([-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526])
GL4_W = np.array([0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538])


def _jit(func, inline: bool = False):  # type: ignore[no-untyped-def]
    from numba import njit

    # error_model="numpy": IEEE division (no zero-divisor test on every division; a zero divisor gives inf or nan,
    # which the solver reports as a non-finite state instead of a raw ZeroDivisionError)
    return njit(cache=True, fastmath=False, nogil=True, error_model="numpy", inline="always" if inline else "never")(
        func
    )


def _chain_force(e, m, dlm):  # type: ignore[no-untyped-def]
    y = e / dlm
    return m * e / (1.0 - y * y)


def _chain_stiffness(e, m, dlm):  # type: ignore[no-untyped-def]
    y = e / dlm
    d = 1.0 - y * y
    return m * (1.0 + y * y) / (d * d)


def _chain_energy(e, m, dlm):  # type: ignore[no-untyped-def]
    y = e / dlm
    return -0.5 * m * dlm * dlm * math.log1p(-y * y)


def _aging_factor(v, p):  # type: ignore[no-untyped-def]
    """exp(-|V|/V_a)/tau_a: the aging slope of the log-hazard per unit age (0 without aging)."""
    return p[P_INV_TAU_A] * math.exp(-abs(v) / p[P_VA]) if p[P_AGING] > 0.0 else 0.0


def _aging_clock(age, p):  # type: ignore[no-untyped-def]
    """(A, dA/dt_a): the age the aging term sees and its rate.  A = t_a (the paper's Eq 1), or, with the
    saturating-aging extension (p[P_SATURATION] = t_s > 0), A = t_s (1 - e^(-t_a/t_s)), dA/dt_a = e^(-t_a/t_s).

    Past CLOCK_PLAIN_DECAY (t_a > t_s ln 2) 1 - e^(-t_a/t_s) is taken from the decay already computed: no
    cancellation there (the difference is within an ulp of expm1's), and expm1, a library call, was 15 % of the
    45 s from rest's CPU (four per cohort and step; docs/transient.md section 8).  Younger (and a saturation age
    beyond every age of a run, the paper's model) keep expm1, where 1 - e^(-x) would lose digits."""
    ts = p[P_SATURATION]
    if ts > 0.0:
        decay = math.exp(-age / ts)
        if decay < CLOCK_PLAIN_DECAY:
            return ts * (1.0 - decay), decay
        return -ts * math.expm1(-age / ts), decay
    return age, 1.0


def _log_rate(e, age, slope, p):  # type: ignore[no-untyped-def]
    """ln r of Eq 1 for extension e and age, with slope = _aging_factor(V); +inf past the FENE limit."""
    if e >= p[P_DLM] or -e >= p[P_DLM]:
        return np.inf
    f = _chain_force(e, p[P_M], p[P_DLM])
    return p[P_LOG_U0_TAU] + p[P_FORCE_SENS] * abs(f) - _aging_clock(age, p)[0] * slope


def _velocity_prepare(n, xb, tb, lw, x, t, p, lc, aa, known, clock):  # type: ignore[no-untyped-def]
    """k_int; fills lc = ln(w r) without the aging term (w f r = f e^lc, f in known[1]) and aa = A(t_a)/tau_a for the
    cohorts.

    ``known[0, i]``: exp(lw[i]) where the caller has it (bit for bit), negative where not; on return it holds
    exp(lw[i]), and known[1, i], known[2, i] the chain force and stiffness at x (nan for a dead cohort)."""
    k_int = 0.0
    for i in range(n):
        e = x - xb[i]
        if lw[i] == -np.inf or e >= p[P_DLM] or -e >= p[P_DLM]:
            lc[i] = -np.inf
            aa[i] = 0.0
            known[1, i] = np.nan
            continue
        w = known[0, i] if known[0, i] >= 0.0 else math.exp(lw[i])
        stiffness = _chain_stiffness(e, p[P_M], p[P_DLM])
        k_int += w * stiffness
        f = _chain_force(e, p[P_M], p[P_DLM])
        known[0, i] = w
        known[1, i] = f
        known[2, i] = stiffness
        lc[i] = lw[i] + p[P_LOG_U0_TAU] + p[P_FORCE_SENS] * f if f > 0.0 else -np.inf  # ln(w r) unaged
        if p[P_AGING] == 0.0:
            aa[i] = 0.0
        elif p[P_SATURATION] > 0.0:
            # ``clock``: A at t where the step's pass left it (the same number; nan or absent: computed)
            age = clock[0, i] if i < clock.shape[1] and clock[0, i] == clock[0, i] else _aging_clock(t - tb[i], p)[0]
            aa[i] = age * p[P_INV_TAU_A]
        else:  # the paper's linear aging, kept branch-free of the extension
            aa[i] = (t - tb[i]) * p[P_INV_TAU_A]
    return k_int


def _velocity_residual(v, vp, n, lc, aa, known, k_int, p):  # type: ignore[no-untyped-def]
    """(g(V), g'(V), g''(V)) of the module docstring, from the prepared lc, aa and the forces in known[1]."""
    decay = math.exp(-abs(v) / p[P_VA]) if p[P_AGING] > 0.0 else 0.0
    loss = 0.0
    dloss = 0.0
    ddloss = 0.0
    for i in range(n):
        if lc[i] == -np.inf:
            continue
        # w f r, the force a factor (no log per cohort), capped as the hazards are (a cohort at the FENE wall)
        term = min(known[1, i] * math.exp(min(lc[i] - aa[i] * decay, LOG_RATE_CAP)), MAX_RATE)
        rate = aa[i] * decay / p[P_VA]  # d(ln term)/dV
        loss += term
        dloss += term * rate
        ddloss += term * rate * (rate - 1.0 / p[P_VA])
    return (k_int + p[P_K]) * v - p[P_K] * vp - loss, (k_int + p[P_K]) - dloss, -ddloss


def _slider_velocity(v_prev, vp, n, xb, tb, lw, x, t, p, lc, aa, known):  # type: ignore[no-untyped-def]
    """The stable root of g nearest v_prev (block control): :func:`_slider_velocity_clocked` with no clock known."""
    return _slider_velocity_clocked(v_prev, vp, n, xb, tb, lw, x, t, p, lc, aa, known, np.empty((2, 0)))


def _slider_velocity_clocked(v_prev, vp, n, xb, tb, lw, x, t, p, lc, aa, known, clock):  # type: ignore[no-untyped-def]
    """The stable root of g nearest v_prev (block control): safeguarded Newton inside a bracket."""
    k_int = _velocity_prepare(n, xb, tb, lw, x, t, p, lc, aa, known, clock)
    g0, d0, c0 = _velocity_residual(v_prev, vp, n, lc, aa, known, k_int, p)
    if p[P_AGING] == 0.0:  # g is linear in V
        return v_prev - g0 / d0
    if g0 == 0.0:
        return v_prev
    # Newton from v_prev inside a bracket [lo, hi] with g(lo) < 0 <= g(hi) (g(0) <= 0 always): each step from
    # the last point evaluated, a bisection where Newton leaves the bracket, a growing leap while no g >= 0 is known
    scale = max(abs(v_prev), 1e-12)
    lo, hi = (v_prev, np.inf) if g0 < 0.0 else (0.0, v_prev)
    v, g, d, c = v_prev, g0, d0, c0
    for _ in range(500):
        v_new = v - g / d if d > 0.0 else np.nan
        newton = lo < v_new < hi
        if not newton:
            v_new = 0.5 * (lo + hi) if hi < np.inf else lo + 2.0 * (lo - v_prev) + scale
        step = abs(v_new - v)
        if step <= 1e-13 * max(abs(v_new), 1e-300) or (hi < np.inf and hi - lo <= 1e-14 * hi):
            return v_new
        # Newton's next correction would be ~|g''/(2 g')| step^2: within the tolerance, v_new is the root to it (one
        # residual, an exp per cohort, saved on most steps)
        if newton and abs(c) * step * step <= 2e-13 * d * max(abs(v_new), 1e-300):
            return v_new
        v = v_new
        g, d, c = _velocity_residual(v, vp, n, lc, aa, known, k_int, p)
        if g == 0.0:
            return v
        if g < 0.0:
            lo = v
        else:
            hi = v
    return v


def _sums(n, xb, lw, x, p):  # type: ignore[no-untyped-def]
    """(N, sigma, k_int, bond energy) of the population at slider position x."""
    nn = 0.0
    s = 0.0
    k = 0.0
    u = 0.0
    for i in range(n):
        w = math.exp(lw[i])
        if w == 0.0:
            continue
        e = x - xb[i]
        nn += w
        s += w * _chain_force(e, p[P_M], p[P_DLM])
        k += w * _chain_stiffness(e, p[P_M], p[P_DLM])
        u += w * _chain_energy(e, p[P_M], p[P_DLM])
    return nn, s, k, u


def _sums_keeping(n, xb, tb, lw, x, t, slope, p, cache, known, prepared, clock_end, frozen_known, rate0):  # type: ignore[no-untyped-def]
    """(N, sigma, bond energy) as _sums, keeping each cohort's weight, force, stiffness, energy and hazard at
    (x, t, slope) in ``cache``: exactly what the next step computes at its start (so it reuses them, bit for bit);
    ``known`` as _velocity_prepare leaves it (its force and stiffness used where ``prepared``, and then its row 3, the
    bond energy :func:`_energy_at_end` derived, where not nan); ``clock_end``: the
    saturating clock at t where the step's pass left it (nan where not: the newborns, merged cohorts).
    ``frozen_known`` (velocity control): the force, stiffness and energy in known[1:4] where known[3] is not nan,
    which :func:`_cohort_pass` leaves only for a cohort frozen at rest (the same numbers at the same extension), and
    its hazard in ``rate0`` (the pass's exp of the same log hazard at the same time).
    Returns ok = False (nothing kept) if a cohort is dead or beyond the FENE wall."""
    nn = 0.0
    s = 0.0
    u = 0.0
    ok = True
    saturating = p[P_SATURATION] > 0.0
    for i in range(n):
        w = known[0, i] if known[0, i] >= 0.0 else math.exp(lw[i])
        e = x - xb[i]
        if w == 0.0 or e >= p[P_DLM] or -e >= p[P_DLM]:
            ok = False
            if w == 0.0:
                continue
        frozen = frozen_known and known[3, i] == known[3, i]
        have = (prepared and known[1, i] == known[1, i]) or frozen
        f = known[1, i] if have else _chain_force(e, p[P_M], p[P_DLM])
        energy = (
            known[3, i] if (prepared or frozen) and known[3, i] == known[3, i] else _chain_energy(e, p[P_M], p[P_DLM])
        )
        nn += w
        s += w * f
        u += w * energy
        if ok:
            age = t - tb[i]
            if saturating:  # kept for the next step's start (rows 6, 7: the same numbers it would compute)
                if clock_end[0, i] == clock_end[0, i]:
                    age, decay = clock_end[0, i], clock_end[1, i]
                else:
                    age, decay = _aging_clock(age, p)
                cache[6, i] = age
                cache[7, i] = decay
            lr = min(p[P_LOG_U0_TAU] + p[P_FORCE_SENS] * abs(f) - age * slope, LOG_RATE_CAP)
            cache[0, i] = w
            cache[1, i] = f
            cache[2, i] = known[2, i] if have else _chain_stiffness(e, p[P_M], p[P_DLM])
            cache[3, i] = energy
            cache[4, i] = lr
            cache[5, i] = rate0[i] if frozen else math.exp(lr)
    return nn, s, u, ok


def _balance_weights(x, puller, n, xb, w, p):  # type: ignore[no-untyped-def]
    """X with sum w f(X - x_b) = K (puller - X), weights given (not logs): Newton inside the FENE bracket."""
    return _balance_from(x, puller, n, xb, w, p, np.empty((2, 0)))


def _balance_from(x, puller, n, xb, w, p, at_x):  # type: ignore[no-untyped-def]
    """_balance_weights, with the chains' force and stiffness at the starting x in ``at_x`` where it has columns."""
    # from the array, not a literal True/False at the call: numba compiles a function once per literal argument
    given = at_x.shape[1] > 0
    lo = -np.inf
    hi = np.inf
    for i in range(n):  # the FENE wall of the oldest live chain
        if w[i] > 0.0:
            hi = min(hi, xb[i] + p[P_DLM] * (1.0 - 1e-15))
    if x >= hi:
        x = hi - 1e-3 * p[P_DLM]
        given = False
    for _ in range(100):
        s = 0.0
        k = p[P_K]
        if given:  # the same numbers, already computed
            for i in range(n):
                if w[i] == 0.0:
                    continue
                s += w[i] * at_x[0, i]
                k += w[i] * at_x[1, i]
            given = False
        else:
            for i in range(n):
                if w[i] == 0.0:
                    continue
                e = x - xb[i]
                s += w[i] * _chain_force(e, p[P_M], p[P_DLM])
                k += w[i] * _chain_stiffness(e, p[P_M], p[P_DLM])
        g = s - p[P_K] * (puller - x)
        if g > 0.0:
            hi = min(hi, x)
        else:
            lo = max(lo, x)
        x_new = x - g / k
        settled = 1e-15 * max(abs(x), p[P_DLM])
        if abs(x_new - x) <= settled and lo <= x_new <= hi:
            # Newton's own correction is within the tolerance: converged.  Tested after the bracket's fallback
            # instead, a correction below an ulp of x (x_new == x, the bracket's edge) was taken for a step out of
            # the bracket and bisected some 16 more passes over the cohorts down to the tolerance, to a root no
            # closer (the paper's cycle: 1 400 of its 3 000 balances; docs/transient.md section 14)
            return x_new
        if not (lo < x_new < hi):  # FENE walls: stay inside the bracket
            x_new = 0.5 * (lo + hi) if (lo > -np.inf and hi < np.inf) else x - 0.5 * g / k
        if abs(x_new - x) <= settled:
            return x_new
        x = x_new
    return x


def _inertial_step(d, x0, v0, force0, h, puller1, n, xb, w, p, at_x):  # type: ignore[no-untyped-def]
    """(d, sigma, k_int) at the end of a step of the block with mass: the slider's travel d over the step by the
    trapezoid rule, m (v1 - v0) = h/2 (F0 + F1), x1 = x0 + d, v1 = 2 d/h - v0, F = K (P - X) - eta V - sigma,
    with the weights w at the step's end; sigma and k_int there.  G(d) = m (v1 - v0) - h/2 (F0 + F1) rises with d
    (dG/dd = 2 m/h + h (K + k_int)/2 + eta, the chains' stiffness positive) from -inf at one FENE wall to +inf at
    the other: Newton inside that bracket.  ``at_x``: force and stiffness at the starting d (the predicted end).
    The travel, not the end position, is the unknown: v1 keeps its digits however far the slider has gone."""
    k_spring = p[P_K]
    mass = p[P_MASS]
    eta = p[P_DAMPING]
    dlm = p[P_DLM]
    lo = -np.inf
    hi = np.inf
    for i in range(n):  # the FENE walls of the live chains, as travels from x0
        if w[i] > 0.0:
            hi = min(hi, xb[i] - x0 + dlm * (1.0 - 1e-15))
            lo = max(lo, xb[i] - x0 - dlm * (1.0 - 1e-15))
    given = True
    if not (lo < d < hi):
        d = 0.5 * (lo + hi) if (lo > -np.inf and hi < np.inf) else 0.0
        given = False
    s = 0.0
    k = 0.0
    for iteration in range(201):
        s = 0.0
        k = 0.0
        for i in range(n):
            if w[i] == 0.0:
                continue
            if given:  # the same numbers, already computed
                s += w[i] * at_x[0, i]
                k += w[i] * at_x[1, i]
            else:
                e = (x0 - xb[i]) + d
                s += w[i] * _chain_force(e, p[P_M], dlm)
                k += w[i] * _chain_stiffness(e, p[P_M], dlm)
        given = False
        if iteration == 200:  # not converged (never seen): the sums at the d returned
            break
        v1 = 2.0 * d / h - v0
        force1 = k_spring * (puller1 - x0 - d) - eta * v1 - s
        g = mass * (v1 - v0) - 0.5 * h * (force0 + force1)
        slope = 2.0 * mass / h + 0.5 * h * (k_spring + k) + eta
        if g > 0.0:
            hi = min(hi, d)
        else:
            lo = max(lo, d)
        d_new = d - g / slope
        # v1 = 2 d/h - v0 to ~1e-15 of the slider's pace (a step landing on a sample can be ~1e-20 s long); Newton's
        # own correction is judged before the bracket's fallback, which bisected a correction below an ulp of d
        # (as in _balance_from)
        settled = 1e-15 * (abs(d) + h * abs(v0))
        if abs(d_new - d) <= settled:
            break
        if not (lo < d_new < hi):
            d_new = 0.5 * (lo + hi) if (lo > -np.inf and hi < np.inf) else d - 0.5 * g / slope
        if abs(d_new - d) <= settled or d_new == d:
            break
        d = d_new
    return d, s, k


def _relaxed_births(p):  # type: ignore[no-untyped-def]
    """The births' error is the Gauss pair's own (docs/transient.md section 8) where no bond born sliding is held
    and slid again (p[P_RELAXED_BIRTHS], set by the solver for the stick chains under a moving puller: every stop
    is a stick, where the bonds of Eq 1 are set aside), and with saturating aging with its housekeeping on; otherwise
    (the paper's aging, :func:`model.plain_cohorts`) one lumped cohort's, as before: their spacing is the quadrature
    of a held population that a re-slide drives to the FENE wall (docs/transient.md section 11).  Saturating aging
    only where the saturated barrier t_s/tau_a is at most SATURATED_BARRIER: beyond it a resting bond is as permanent
    as under the paper's linear aging (a saturation age beyond every age of a run is the paper's model, bit for
    bit)."""
    return p[P_RELAXED_BIRTHS] > 0.0 or (
        p[P_SATURATION] > 0.0
        and p[P_SATURATION] * p[P_INV_TAU_A] <= SATURATED_BARRIER
        and p[P_AGING] > 0.0
        and p[P_MERGE_SATURATED] > 0.0
    )


def _hermite(theta, h, l0, d0, l1, d1):  # type: ignore[no-untyped-def]
    """The cubic with values l0, l1 and slopes d0, d1 at the ends of a step of length h, at theta = u/h."""
    t2 = theta * theta
    t3 = t2 * theta
    return (
        (2.0 * t3 - 3.0 * t2 + 1.0) * l0
        + (t3 - 2.0 * t2 + theta) * h * d0
        + (-2.0 * t3 + 3.0 * t2) * l1
        + (t3 - t2) * h * d1
    )


def _vacancy(u, q0, tau, h, l0, d0, l1, d1):  # type: ignore[no-untyped-def]
    """Q(u) for dQ/du = -Q/tau + L(u), L the Hermite cubic of the breakage rate over the step.

    Exact for the cubic: Gauss-Legendre (4 points, degree 7) when u < tau, where the exponential kernel is
    smooth on [0, u]; the closed form by parts (no cancellation once u >= tau) otherwise.
    """
    dec, c0, c1, c2, c3 = _vacancy_kernel(u, tau)
    return _vacancy_from(u, q0, tau, h, l0, d0, l1, d1, dec, c0, c1, c2, c3)


def _vacancy_kernel(u, tau):  # type: ignore[no-untyped-def]
    """The exponentials of :func:`_vacancy` at u, which do not depend on the breakage rate: e^(-u/tau) and, for
    u < tau, the kernel e^(-(u - s)/tau) at the four Gauss points s (the births' sweeps take them once a step)."""
    if u <= 0.0:
        return 1.0, 0.0, 0.0, 0.0, 0.0
    dec = math.exp(-u / tau)
    if u < tau:
        c0 = math.exp(-(u - 0.5 * u * (1.0 + GL4_X[0])) / tau)
        c1 = math.exp(-(u - 0.5 * u * (1.0 + GL4_X[1])) / tau)
        c2 = math.exp(-(u - 0.5 * u * (1.0 + GL4_X[2])) / tau)
        c3 = math.exp(-(u - 0.5 * u * (1.0 + GL4_X[3])) / tau)
        return dec, c0, c1, c2, c3
    return dec, 0.0, 0.0, 0.0, 0.0


def _vacancy_from(u, q0, tau, h, l0, d0, l1, d1, dec, c0, c1, c2, c3):  # type: ignore[no-untyped-def]
    """:func:`_vacancy` with its exponentials from :func:`_vacancy_kernel` (the same numbers)."""
    if u <= 0.0:
        return q0
    if u < tau:
        total = GL4_W[0] * _hermite(0.5 * u * (1.0 + GL4_X[0]) / h, h, l0, d0, l1, d1) * c0
        total += GL4_W[1] * _hermite(0.5 * u * (1.0 + GL4_X[1]) / h, h, l0, d0, l1, d1) * c1
        total += GL4_W[2] * _hermite(0.5 * u * (1.0 + GL4_X[2]) / h, h, l0, d0, l1, d1) * c2
        total += GL4_W[3] * _hermite(0.5 * u * (1.0 + GL4_X[3]) / h, h, l0, d0, l1, d1) * c3
        return q0 * dec + 0.5 * u * total
    # L = a + b s + c s^2 + e s^3, and the integral of L(s) e^{-(u-s)/tau} over [0, u] is F(u) - e^{-u/tau} F(0)
    # with F = tau (L - tau dL + tau^2 d2L - tau^3 d3L)
    a = l0
    b = d0
    c = (3.0 * (l1 - l0) / h - 2.0 * d0 - d1) / h
    e = (2.0 * (l0 - l1) / h + d0 + d1) / (h * h)
    lu = a + u * (b + u * (c + u * e))
    dlu = b + u * (2.0 * c + 3.0 * u * e)
    ddlu = 2.0 * c + 6.0 * u * e
    f_u = tau * (lu - tau * dlu + tau * tau * ddlu - tau * tau * tau * 6.0 * e)
    f_0 = tau * (a - tau * b + tau * tau * 2.0 * c - tau * tau * tau * 6.0 * e)
    return q0 * dec + f_u - dec * f_0


def _saturated_bins(n, nn, ss, s_floor, rtol, p):  # type: ignore[no-untyped-def]
    """The housekeeping of saturating aging: (log weight floor, stress floor, bin width in log hazard).

    A cohort past the saturation age that is lighter than LIGHT_SHARE rtol of the bonds alive and carries less
    than that share of the stress, both shared among the n cohorts, is dropped (the absolute floor LIGHTEST N0 kept
    cohorts dying at the resting hazard for ~1.7 s: 5e4 of them on a stuck block).  Shared among the cohorts, so
    that all those dropped at once stay within the share, and so do, at a steady pace of drops, those that would
    still be alive (the bonds missing are the drops' flux times their remaining life 1/r: LIGHT_SHARE rtol N over
    the log of a cohort's weight ratio from birth to the floor).  Cohorts are merged within bins
    (:func:`_same_bin`) of the returned width in log hazard.
    """
    share = LIGHT_SHARE * rtol / max(n, 1)
    return math.log(max(share * nn, 1e-300)), share * max(abs(ss), s_floor), p[P_MERGE_SATURATED] * math.sqrt(rtol)


def _negligible(lw, e, w_known, f_known, light_n, light_s, p):  # type: ignore[no-untyped-def]
    """Lighter than the share of the bonds alive, and carrying less than the share of the stress."""
    return lw < light_n and _cohort_load(lw, e, w_known, f_known, p) < light_s


def _cohort_load(lw, e, w_known, f_known, p):  # type: ignore[no-untyped-def]
    """w |f(e)|, the stress a cohort carries: its weight and force where the step left them (``known``: the same
    numbers; negative or nan where not), else computed."""
    w = w_known if w_known >= 0.0 else math.exp(lw)
    f = f_known if f_known == f_known else _chain_force(e, p[P_M], p[P_DLM])
    return w * abs(f)


def _same_bin(x, decay_i, decay_g, xb_i, xb_g, spread, p):  # type: ignore[no-untyped-def]
    """Cohort i and the (merged) cohort g before it lie in one bin of width ``spread`` in both log-hazard terms.

    The aging term: its distance from saturation, (t_s/tau_a) e^(-t_a/t_s), which only shrinks as both age.  The
    force term: beta f'(e) x_b, f' at the larger extension of the two or at half the FENE length, whichever is
    larger (the bonds break further out when the block slips; no merge within 1e-3 of the wall), in bins
    FORCE_SPREAD times wider (the FENE curvature bounds it: the merged cohort's force is its parts' to second
    order in their spread of positions).  A merged cohort
    (weight, mean position and mean age kept) then breaks as its parts to second order in the spread, ~spread^2/8
    of its hazard, in any later history.  Bins, not neighbours' distances: a chain of merges cannot drift.
    ``decay_i``, ``decay_g``: e^(-t_a/t_s) of both (:func:`_saturation_decay`).
    """
    ts = p[P_SATURATION]
    scale = ts * p[P_INV_TAU_A]
    if np.floor(scale * decay_i / spread) != np.floor(scale * decay_g / spread):
        return False
    dlm = p[P_DLM]
    e = max(abs(x - xb_i), abs(x - xb_g), 0.5 * dlm)
    if e >= 0.999 * dlm:
        return False
    width = FORCE_SPREAD * spread / (p[P_FORCE_SENS] * _chain_stiffness(e, p[P_M], dlm))
    return np.floor(xb_i / width) == np.floor(xb_g / width)


def _saturation_decay(t, tb, p):  # type: ignore[no-untyped-def]
    """e^(-t_a/t_s) of a cohort born at tb, at t (:func:`_same_bin`)."""
    return math.exp(-(t - tb) / p[P_SATURATION])


def _light_spread(spread, log_ratio, load, s_mean):  # type: ignore[no-untyped-def]
    """The bin width for two cohorts: ``spread`` times 2^k, k the whole number of halvings in sqrt(w_mean/w) of the
    heavier of the two (``log_ratio``: ln(w_mean/w), at least LOG_FOUR: lighter ones share no wider bin), or in
    sqrt of the mean stress a cohort carries over theirs (``load``, the larger) if that is smaller (at most
    LIGHT_LEVELS).

    A merge moves the population by ~w spread^2/8 of its hazard, and its stress by as much through the FENE
    curvature, so a cohort lighter than the mean by w_mean/w in both may be binned sqrt(w_mean/w) wider for the same
    error as one of mean weight; the old, light cohorts of a creeping block (ages up to ~0.4 s at the resting hazard,
    their birth positions spread by the creep) then share bins.  Both shares: in a hold the newborns at zero
    extension make up N while the old cohorts carry the stress.  Widths are powers of two of ``spread``, so the bins
    of each level nest in the next and a chain of merges cannot drift past the coarsest bin it was merged in."""
    ratio = min(math.exp(log_ratio), s_mean / max(load, 1e-300))
    k = math.floor(0.5 * math.log(max(ratio, 1.0)) / math.log(2.0))
    return spread * 2.0 ** min(k, LIGHT_LEVELS)


def _edge(xi, a, b, c, three):  # type: ignore[no-untyped-def]
    """The edge between a cohort born at xi and its neighbour born at a (b and c the next two beyond a, where
    ``three``): half their spacing beyond a where a, b, c are equally spaced (the pieces of a cut cohort, whose cell
    ends there), else halfway to a."""
    if three:
        d = a - b
        if d != 0.0 and abs(d - (b - c)) <= SPLIT_EVEN * abs(d):
            edge = a + 0.5 * d
            if (edge - a) * (xi - edge) > 0.0:
                return edge
    return 0.5 * (a + xi)


def _piece(i, n, xb):  # type: ignore[no-untyped-def]
    """Whether cohort i of n is a piece of a cut cohort (:func:`_split`), equally spaced with two of its neighbours:
    the first of those three (so its spacing is xb[j + 1] - xb[j]), else -1."""
    for j in range(max(i - 2, 0), min(i, n - 3) + 1):
        d = xb[j + 1] - xb[j]
        if d != 0.0 and abs(xb[j + 2] - xb[j + 1] - d) <= SPLIT_EVEN * abs(d):
            return j
    return -1


def _cell(i, n, xb, tb):  # type: ignore[no-untyped-def]
    """(x_lo, x_hi, t_lo, t_hi): the birth positions cohort i of n stands for, towards its older and its younger
    neighbour (:func:`_edge`; a missing neighbour mirrors the other side), and the birth times there (linear
    between the cohort and that neighbour).  A cell whose two edges lie on one side of the cohort (the slider turned
    between the births) comes back empty (both edges at the cohort)."""
    xi = xb[i]
    ti = tb[i]
    j = _piece(i, n, xb)
    if j >= 0:  # a piece of a cut cohort: its own spacing, on both sides
        d = xb[j + 1] - xb[j]
        dt = 0.5 * (tb[j + 1] - tb[j])
        return xi - 0.5 * d, xi + 0.5 * d, ti - dt, ti + dt
    lo = hi = math.nan
    t_lo = t_hi = ti
    if i > 0:
        a = xb[i - 1]
        lo = _edge(xi, a, xb[i - 2] if i > 1 else a, xb[i - 3] if i > 2 else a, i > 2)
        if a != xi:
            t_lo = ti + (lo - xi) * (ti - tb[i - 1]) / (xi - a)
    if i + 1 < n:
        a = xb[i + 1]
        hi = _edge(xi, a, xb[i + 2] if i + 2 < n else a, xb[i + 3] if i + 3 < n else a, i + 3 < n)
        if a != xi:
            t_hi = ti + (hi - xi) * (tb[i + 1] - ti) / (a - xi)
    if lo != lo and hi != hi:
        return xi, xi, ti, ti
    if lo != lo:
        lo = 2.0 * xi - hi
        t_lo = 2.0 * ti - t_hi
    elif hi != hi:
        hi = 2.0 * xi - lo
        t_hi = 2.0 * ti - t_lo
    if not ((xi - lo) * (hi - xi) > 0.0):
        return xi, xi, ti, ti
    return lo, hi, t_lo, t_hi


def _cliff(u, lr, g, speed, aging, p):  # type: ignore[no-untyped-def]
    """(force, g) where a cohort at extension u > 0 moving outwards at ``speed``, its log hazard lr climbing at g > 0,
    dies: ln r = ln g there (its cumulative hazard ~1), along ln r(u') = lr + beta (f(u') - f(u)) - aging (u' - u)/
    speed (the velocity and the aging term's rate held).  Newton inside the bracket [u, dl_m) (ln r is convex in u'),
    again with ln g at the cliff found until that moves by less than 0.01."""
    m = p[P_M]
    dlm = p[P_DLM]
    beta = p[P_FORCE_SENS]
    f_u = _chain_force(u, m, dlm)
    target = math.log(g)
    x = u
    g_c = g
    for _ in range(SPLIT_TARGETS):
        lo, hi = u, dlm
        x = u
        fx = lr - target
        for _ in range(SPLIT_NEWTON):
            if fx > 0.0:
                hi = x
            else:
                lo = x
            if abs(fx) < 1e-3:
                break
            d = beta * _chain_stiffness(x, m, dlm) - aging / speed
            xn = x - fx / d if d > 0.0 else math.nan
            if not (lo < xn < hi):
                xn = 0.5 * (lo + hi)
            x = xn
            fx = lr + beta * (_chain_force(x, m, dlm) - f_u) - aging * (x - u) / speed - target
        g_c = beta * _chain_stiffness(x, m, dlm) * speed - aging
        if not (g_c > 0.0):
            return _chain_force(x, m, dlm), g
        if abs(math.log(g_c) - target) < 1e-2:
            break
        target = math.log(g_c)
    return _chain_force(x, m, dlm), g_c


def _ripple(stress, pieces, crossing):  # type: ignore[no-untyped-def]
    """The stress's sawtooth from a train of lumps each carrying stress/pieces, crossing = tau g/pieces apart in
    units of the cliff's width: (2/pi)(stress/pieces)|Gamma(1 - 2 pi i/crossing)|, |Gamma(1 - iy)|^2 =
    pi y/sinh(pi y) (a cliff's death profile is Gumbel's; its Fourier transform is Gamma)."""
    py = 2.0 * math.pi * math.pi / crossing
    if py > 30.0:
        mod = math.exp(0.5 * (math.log(2.0 * py) - py))
    elif py > 1e-8:
        mod = math.sqrt(py / math.sinh(py))
    else:
        mod = 1.0
    return 2.0 / math.pi * stress / pieces * mod


def _split_plan(w, e, lr, g, v, aging, lo, hi, xi, paired, floor, p):  # type: ignore[no-untyped-def]
    """The pieces to cut a cohort into (1: none): weight w, extension e, log hazard lr climbing at g > 0, cell [lo, hi]
    (born at xi; ``paired``: one of a Gauss pair, not a piece of a cut cohort), the slider at v, the sawtooth allowed
    ``floor``.  None where it is dying already (z = ln g - ln r < SPLIT_LATE, or its cell's leading edge past the
    cliff: those bonds are gone in truth), where that edge is more than SPLIT_FAR below the cliff (not yet), where the
    cliff (:func:`_cliff`) is more than SPLIT_STEEPEST times steeper than the cell's crossing, or where its lump leaves
    a sawtooth of at most SPLIT_TRIGGER x floor (:func:`_ripple`); else the fewest (at least SPLIT_FEWEST) that leave
    at most floor."""
    speed = abs(v)
    if speed == 0.0 or e * v <= 0.0:
        return 1
    crossing = abs(hi - lo) / speed * g
    if crossing < SPLIT_SPACING:
        return 1
    z = math.log(g) - lr
    if z < SPLIT_LATE:
        return 1
    lead = (xi - min(lo, hi)) if v > 0.0 else (max(lo, hi) - xi)
    # far from its cliff yet, with g there as the FENE stiffening makes it (g ~ f^2 near the wall, beta f climbing by
    # z; more than g itself everywhere), or that g far steeper than SPLIT_STEEPEST (SPLIT_ESTIMATE times, for the
    # estimate): not planned (the cliff's own Newton, ~1e-5 of dl_m from the wall after a 10 s hold, not spent)
    force = p[P_FORCE_SENS] * abs(_chain_force(e, p[P_M], p[P_DLM]))
    ahead = g * (1.0 + z / force) ** 2 if force > 0.0 else g
    if z - ahead * lead / speed > SPLIT_FAR or crossing / g * ahead > SPLIT_ESTIMATE * SPLIT_STEEPEST:
        return 1
    f_c, g_c = _cliff(abs(e), lr, g, speed, aging, p)
    crossing = abs(hi - lo) / speed * g_c
    if crossing > SPLIT_STEEPEST or z - g_c * lead / speed < SPLIT_LATE:
        return 1
    stress = w * abs(f_c)
    # births come in Gauss pairs (a step's, a cell's): their train repeats every two cells, its first harmonic
    # weighted |cos 2 pi GAUSS| = 0.24 (docs/transient.md section 18), and it is the wider of the two that a cliff
    # about as wide as a cell lets through (not so the pieces of a cut cohort, evenly spaced)
    ripple = _ripple(stress, 1.0, crossing)
    if paired:
        ripple = max(ripple, _ripple(2.0 * GAUSS_HARMONIC * stress, 1.0, 2.0 * crossing))
    if ripple <= SPLIT_TRIGGER * floor:
        return 1
    k = SPLIT_FEWEST
    while k < SPLIT_MOST and _ripple(stress, k, crossing / k) > floor:
        k += 1
    return k


def _split_look(i, n, xb, tb, w, e, lr, g, v, aging, floor, p):  # type: ignore[no-untyped-def]
    """The pieces :func:`_split_plan` cuts cohort i of the pass into (weight w, extension e, log hazard lr climbing at
    g > 0 at the step's end, the slider at v; its cell from its neighbours), 1: none.  Out of the pass's loop (not
    inlined): most cohorts never come here, and the loop stays as fast as before."""
    lo, hi, _t_lo, _t_hi = _cell(i, n, xb, tb)
    return _split_plan(w, e, lr, g, v, aging, lo, hi, xb[i], _piece(i, n, xb) < 0, floor, p)


def _in_pairs(n, count, split_at, split_pieces, xb):  # type: ignore[no-untyped-def]
    """split_at[:count] (ascending) kept two neighbours at a time, each pair cut into the larger number of pieces; one
    whose younger neighbour is to be cut too but not yet waits for it (unless that neighbour is a piece already, or a
    newborn).  Returns the new count."""
    kept = 0
    c = 0
    while c < count:
        i = split_at[c]
        if c + 1 < count and split_at[c + 1] == i + 1:
            k = max(split_pieces[c], split_pieces[c + 1])
            split_at[kept] = i
            split_pieces[kept] = k
            split_at[kept + 1] = i + 1
            split_pieces[kept + 1] = k
            kept += 2
            c += 2
            continue
        if i + 1 >= n - 2 or _piece(i + 1, n, xb) >= 0:
            split_at[kept] = i
            split_pieces[kept] = split_pieces[c]
            kept += 1
        c += 1
    return kept


def _split(n, count, split_at, split_pieces, cells, xb, tb, lw, rate0, known, clock_end):  # type: ignore[no-untyped-def]
    """Cut the cohorts split_at[:count] (ascending), two neighbours at a time (:func:`_in_pairs`), into split_pieces
    equal pieces spread evenly over their cells (:func:`_cell`, from the neighbours before any cut), each with its
    share of the weight, its birth position and time; the others moved up.  Returns (n, False), or (n, True)
    unchanged where the arrays lack the room.

    Two neighbours at once: a Gauss cohort sits 0.039 of a step off its cell's middle, the next one as far the other
    way, so that spreading one alone over its cell moved sigma by its weight x f' x that offset (0.9 Pa, 3e-5 of
    sigma, for the report's gel, each cut undone at the next: a floor of 2e-5 on the error at rtol 1e-5)."""
    count = _in_pairs(n, count, split_at, split_pieces, xb)
    extra = 0
    for c in range(count):
        extra += split_pieces[c] - 1
    if n + extra + 3 >= xb.shape[0]:
        return n, True
    for c in range(count):
        lo, hi, t_lo, t_hi = _cell(split_at[c], n, xb, tb)
        cells[0, c] = lo
        cells[1, c] = hi
        cells[2, c] = t_lo
        cells[3, c] = t_hi
    src_end = n
    dest_end = n + extra
    for c in range(count - 1, -1, -1):
        i = split_at[c]
        k = split_pieces[c]
        for j in range(src_end - 1, i, -1):  # the cohorts after it move up
            d = dest_end - (src_end - j)
            xb[d] = xb[j]
            tb[d] = tb[j]
            lw[d] = lw[j]
            rate0[d] = rate0[j]
            for r in range(4):
                known[r, d] = known[r, j]
            clock_end[0, d] = clock_end[0, j]
            clock_end[1, d] = clock_end[1, j]
        dest_end -= src_end - i - 1
        xi, ti, lw_i, rate_i = xb[i], tb[i], lw[i], rate0[i]
        lo, hi, t_lo, t_hi = cells[0, c], cells[1, c], cells[2, c], cells[3, c]
        lw_piece = lw_i - math.log(k)
        base = dest_end - k
        for j in range(k):
            x_j = lo + (j + 0.5) / k * (hi - lo)
            if (x_j - xi) * (lo - xi) > 0.0:  # on the older neighbour's side
                t_j = ti + (x_j - xi) / (lo - xi) * (t_lo - ti)
            else:
                t_j = ti + (x_j - xi) / (hi - xi) * (t_hi - ti)
            xb[base + j] = x_j
            tb[base + j] = t_j
            lw[base + j] = lw_piece
            rate0[base + j] = rate_i
            known[0, base + j] = -1.0
            known[1, base + j] = np.nan
            known[2, base + j] = np.nan
            known[3, base + j] = np.nan
            clock_end[0, base + j] = np.nan
            clock_end[1, base + j] = np.nan
        dest_end = base
        src_end = i
    return n + extra, False


def _step_length(t, t_end, h, h_max, sample_times, sample_index):  # type: ignore[no-untyped-def]
    """(hh, landing): the step tried from t, the proposed h cut to h_max and to the piece's end, or landing exactly
    on the next sample time; a sliver left before the end is taken with this step."""
    hh = min(h, h_max, t_end - t)
    landing = False
    if sample_index < sample_times.shape[0] and t + hh >= sample_times[sample_index]:
        hh = sample_times[sample_index] - t
        landing = True
    if t_end - t - hh <= 1e-12 * max(t_end, 1.0):
        hh = t_end - t
    if hh <= 0.0:
        hh = t_end - t
    return hh, landing


def _predicted_path(x, v, v_prev, h_prev, hh, vp, block, inertial, accel_now, accel_prev):  # type: ignore[no-untyped-def]
    """(v0, v1p, x1p, x_mid, jerk): the slider's velocity at the step's start, and its velocity and position at the
    end and its position at mid-step: exact under velocity control, predicted through the block (the velocity
    extrapolated from the last step), Taylor's cubic for a block with mass (its acceleration known, its jerk from
    the last step)."""
    jerk = 0.0
    if block == 0:
        v0 = vp
        v1p = vp
    elif inertial:
        v0 = v
        # the jerk from the last step, unless that step was much shorter (one landing on a sample time), where
        # the difference quotient amplifies the acceleration's rounding
        jerk = (accel_now - accel_prev) / h_prev if h_prev > 0.25 * hh else 0.0
        v1p = v + hh * accel_now + 0.5 * hh * hh * jerk
    else:
        v0 = v
        v1p = v + (v - v_prev) * (hh / h_prev) if h_prev > 0.0 else v
        if v1p < 0.0:
            v1p = 0.0
    if inertial:
        x1p = x + hh * (v0 + hh * (0.5 * accel_now + hh * jerk / 6.0))
        x_mid = x + 0.5 * hh * (v0 + 0.5 * hh * (0.5 * accel_now + 0.5 * hh * jerk / 6.0))
    else:
        x1p = x + 0.5 * hh * (v0 + v1p)
        x_mid = x + 0.5 * hh * v0 + 0.125 * hh * (v1p - v0)
    return v0, v1p, x1p, x_mid, jerk


def _hazard_slopes(f0, f1, k0, k1, v0, v1p, age0, age1, clock0, clock1, slope0, slope1, accel, beta, va, aging):  # type: ignore[no-untyped-def]
    """(g0, g1): d ln r/dt along a cohort's characteristic at both ends of the step, through the force (its
    stiffness k), the age the aging term sees (its clock rate), and the velocity's effect on aging."""
    g0 = beta * (1.0 if f0 >= 0.0 else -1.0) * k0 * v0 - slope0 * clock0
    g1 = beta * (1.0 if f1 >= 0.0 else -1.0) * k1 * v1p - slope1 * clock1
    if aging and accel != 0.0:
        g0 += age0 * slope0 * accel / va * (1.0 if v0 >= 0.0 else -1.0)
        g1 += age1 * slope1 * accel / va * (1.0 if v1p >= 0.0 else -1.0)
    return g0, g1


def _cohort_weight(lw_i, w0, f0, hh, lr0, r0, lr1, r1, g0, g1):  # type: ignore[no-untyped-def]
    """A cohort's log weight at the step's end from its hazard at both ends: (new, its weight, its error, the
    stress dying at a cliff, the trapezoid of the hazard, whether exp(new) was taken exactly).

    The error, the weight's distance from the plain trapezoid's, w |1 - e^(-c)| for the end correction c, is taken
    by its Taylor series where |c| < CORRECTION_SERIES (to ~1e-12 of itself) instead of a second exp per cohort and
    step (docs/transient.md section 15)."""
    trap = 0.5 * hh * (r0 + r1)
    dying = 0.0
    if abs(lr1 - lr0) > 1.0 and max(lr0, lr1) < LOG_RATE_CAP:
        # the hazard changes by more than a factor e within the step (a young bond aging on a stuck
        # block, or a rupture): the rule exact for ln r linear in time, where the trapezoid would kill
        # the 2 % of young bonds that age into permanence; its error from the curvature of ln r
        integral = hh * (r1 - r0) / (lr1 - lr0)
        wn = w0 * math.exp(-integral)
        new = lw_i - integral
        delta = abs(g1 - g0) * hh / 8.0 * integral
        dw = min(wn * math.expm1(min(delta, 50.0)), w0) + abs(wn - w0 * math.exp(-min(trap, 745.0))) * 1e-3
        if g1 > 0.0:
            # a cliff of the hazard (the force, or the FENE stiffening) steeper than the steps: bonds born
            # over a step like this die as a block there, and the stress falls in steps; the Gauss births
            # resolve it only for h g < 1, erring by ~(h g)^4/4320 of the stress that dies
            # (the current step stands for the birth spacing of bonds born under the current drive only)
            hg = hh * g1
            dying = (w0 - wn) * abs(f0) * min(hg * hg * hg * hg / 4320.0, 1.0)
        return new, wn, dw, dying, trap, False
    corr = hh * hh / 12.0 * (r1 * g1 - r0 * g0)  # Euler-Maclaurin end correction: fourth order
    limit = 0.5 * trap
    corr = min(max(corr, -limit), limit)
    new = lw_i - trap + corr
    wn = math.exp(new)
    if abs(corr) < CORRECTION_SERIES:
        dw = wn * abs(corr * (1.0 - corr * (0.5 - corr * (1.0 / 6.0 - corr / 24.0))))
    else:
        dw = abs(wn - w0 * math.exp(-min(trap, 745.0)))  # against the plain trapezoid
    return new, wn, dw, dying, trap, True


def _cohort_dissipation(trap, hh, w0, wn, r0, r1, g0, g1, f0, f1, v0, v1p, e0, u1, e_mid, u0, m, dlm):  # type: ignore[no-untyped-def]
    """The energy a cohort's breakage dissipates over the step: r w u by the end-corrected trapezoid (fourth
    order; u0 the energy at the start where known, else nan; u1 the energy at the step's predicted end), or, a
    cohort breaking within the step, its lost mass at the mid-step energy."""
    if trap < 0.5:
        if u0 != u0:
            u0 = _chain_energy(e0, m, dlm)
        phi0 = r0 * w0 * u0
        phi1 = r1 * wn * u1
        dphi0 = phi0 * (g0 - r0) + r0 * w0 * f0 * v0
        dphi1 = phi1 * (g1 - r1) + r1 * wn * f1 * v1p
        return 0.5 * hh * (phi0 + phi1) - hh * hh / 12.0 * (dphi1 - dphi0)
    return (w0 - wn) * _chain_energy(e_mid, m, dlm)


def _cohort_pass(  # type: ignore[no-untyped-def]
    n, t, t1, t0, hh, x, x1p, x_mid, v0, v1p, slope0, slope1, accel, xb, tb, lw, lw_new, rate0, w1, known,
    predicted, cache, cached, clock_end, wall_load, old_walls_free, old_wall_count, split_floor, split_at, split_pieces,
    p,
):  # fmt: skip
    """One pass over the cohorts: each one's log weight at the step's end (``lw_new``, ``w1``; its hazard there in
    ``rate0``, its force and stiffness at the predicted end in ``predicted``), and the sums over them:
    (N and sigma at both ends, the breakage rate and its time derivative at both ends, bonds broken, energy
    dissipated, sum r w f and the interface stiffness at both ends, the errors in stress and bonds, the step's
    stress loss's sensitivity to the slider's position and to the aging slope, bonds freed by the FENE wall, the
    stress dying at a hazard cliff of bonds born within and before this piece, the least extension left to the FENE
    wall of a cohort carrying wall_load, how many cohorts to cut ahead of their cliff (:func:`_split_plan`; their
    indices and pieces in split_at and split_pieces; split_floor: the sawtooth allowed, inf: none cut), and the sites
    freed at the wall within the step still vacant at its two Gauss points (:func:`_births` refills them)).

    ``old_walls_free`` (velocity control): a cohort born before this piece that reaches the wall within the step is
    dead at its end whichever way it died and nothing else depends on how, so its stress counts as a cliff of old
    bonds (where the stress falls: the peak the trace must resolve), the sites it freed refill from its arrival,
    and what that timing may miss, its bonds times min(1, h/tau), counts in N; such a cohort is landed on only where
    it holds ``old_wall_count`` bonds or more (docs/transient.md section 25)."""
    m = p[P_M]
    dlm = p[P_DLM]
    beta = p[P_FORCE_SENS]
    log_u0_tau = p[P_LOG_U0_TAU]
    va = p[P_VA]
    saturating = p[P_SATURATION] > 0.0
    aging_on = p[P_AGING] > 0.0
    ts = p[P_SATURATION]
    step_decay = math.exp(-hh / ts) if saturating else 1.0
    nn0 = s0 = nn1 = s1 = 0.0
    loss0 = loss1 = 0.0  # breakage rate (bonds per m^2 per s) at both ends of the step
    dloss0 = dloss1 = 0.0  # and its time derivative
    broken = dissip = 0.0
    rate_s0 = rate_s1 = 0.0  # sum r w f: the stress lost to breakage per unit time, at both ends
    kint0 = kint1 = 0.0  # sum w f': the interface stiffness, at both ends
    err_s = err_n = 0.0
    sens_x = 0.0  # sum w f r beta f': how the step's stress loss depends on the slider position
    sens_a = 0.0  # sum w f r t_a: how it depends on the aging slope
    walled = 0.0  # bonds freed by the FENE wall within the step (not part of the smooth breakage rate)
    cliff = 0.0  # stress dying at a hazard cliff steeper than the step (see _cohort_weight)
    cliff_old = 0.0  # the same for bonds born before this piece of the protocol
    wall_gap = np.inf  # the least extension left to the FENE wall of a cohort carrying wall_load or more towards it
    refill_a = refill_b = 0.0  # sites freed at the wall by bonds born before this piece, vacant at the Gauss points
    gauss_a = hh * (0.5 - GAUSS)
    gauss_b = hh * (0.5 + GAUSS)
    n_split = 0
    # a slider at rest under velocity control (its path the protocol's: x1p = x), the paper's linear aging: each
    # cohort's extension, force, stiffness and energy stay, its log hazard falls by h/tau_a; where the hazard breaks
    # less than FROZEN_HAZARD of the cohort over the step, nothing but those sums is computed (one exp, where the
    # full pass takes ~8 transcendental functions: a hold's aged bonds, most of its cohorts; section 27)
    frozen = old_walls_free and cached and v0 == 0.0 and v1p == 0.0 and x1p == x and slope0 == slope1
    frozen = frozen and not saturating
    for i in range(n):
        w0 = cache[0, i] if cached else math.exp(lw[i])
        e0 = x - xb[i]
        e1 = x1p - xb[i]
        nn0 += w0
        if frozen and cache[5, i] * hh < FROZEN_HAZARD:
            f0 = cache[1, i]
            k0 = cache[2, i]
            u0 = cache[3, i]
            r0 = cache[5, i]
            age1 = t1 - tb[i]
            lr1 = min(log_u0_tau + beta * abs(f0) - age1 * slope1, LOG_RATE_CAP)
            r1 = math.exp(lr1)
            g = -slope1  # d ln r/dt at rest: the aging alone
            s0 += w0 * f0
            loss0 += w0 * r0
            loss1 += w0 * r1
            dloss0 += w0 * r0 * (g - r0)
            dloss1 += w0 * r1 * (g - r1)
            dissip += _cohort_dissipation(0.0, hh, w0, w0, r0, r1, g, g, f0, f0, 0.0, 0.0, e0, u0, e0, u0, m, dlm)
            err_s += abs(f0) * w0 * r0 * hh  # the breakage the weight cannot show
            err_n += w0 * r0 * hh
            sens_x += w0 * abs(f0) * r1 * beta * k0
            sens_a += w0 * abs(f0) * r1 * age1
            rate_s0 += w0 * r0 * f0
            rate_s1 += w0 * r1 * f0
            kint0 += w0 * k0
            kint1 += w0 * k0
            nn1 += w0
            s1 += w0 * f0
            predicted[0, i] = f0
            predicted[1, i] = k0
            predicted[2, i] = u0
            lw_new[i] = lw[i]
            w1[i] = w0
            known[0, i] = w0
            known[1, i] = f0  # its values at the end, where it is (:func:`_sums_keeping` takes them)
            known[2, i] = k0
            known[3, i] = u0
            rate0[i] = r1
            continue
        if old_walls_free:  # (velocity control: known[3] marks the frozen cohorts' values at the end alone)
            known[3, i] = np.nan
        if e0 >= dlm or -e0 >= dlm:  # beyond the FENE wall already (cannot happen for a live cohort)
            lw_new[i] = -np.inf
            rate0[i] = np.inf
            w1[i] = 0.0
            known[0, i] = -1.0
            predicted[2, i] = np.nan
            broken += w0
            continue
        f0 = cache[1, i] if cached else _chain_force(e0, m, dlm)
        s0 += w0 * f0
        if e1 >= dlm or -e1 >= dlm:  # the chain reaches full extension within the step
            lw_new[i] = -np.inf
            rate0[i] = np.inf
            w1[i] = 0.0
            known[0, i] = -1.0
            predicted[2, i] = np.nan
            broken += w0
            dissip += w0 * _chain_energy(e0, m, dlm)
            if old_walls_free and tb[i] < t0:  # (see the docstring)
                arrival = hh * min(max((dlm - abs(e0)) / max(abs(e1 - e0), 1e-300), 0.0), 1.0)
                walled += w0 * math.exp(-(hh - arrival) / p[P_TAU])
                if arrival < gauss_a:
                    refill_a += w0 * math.exp(-(gauss_a - arrival) / p[P_TAU])
                if arrival < gauss_b:
                    refill_b += w0 * math.exp(-(gauss_b - arrival) / p[P_TAU])
                cliff_old += w0 * abs(f0)
                err_n += w0 * min(1.0, hh / p[P_TAU])
            else:
                walled += w0
                err_s += w0 * abs(f0)
                err_n += w0
            continue
        if saturating:  # the age the aging term sees, and its rate (at the start as the last row kept it)
            if cached:
                age0, clock0 = cache[6, i], cache[7, i]
            else:
                age0, clock0 = _aging_clock(t - tb[i], p)
            if cached and clock0 < CLOCK_PLAIN_DECAY:
                # e^(-t_a/t_s) carried over the step by one factor for all (an exp per cohort saved; ~2 ulp per
                # step, ~1e-11 of the decay after 1e5 steps, itself < 1/2 here: no digit of the age that matters)
                clock1 = clock0 * step_decay
                age1 = ts * (1.0 - clock1)
            else:
                age1, clock1 = _aging_clock(t1 - tb[i], p)
            clock_end[0, i] = age1  # the same numbers the row at t1 needs (:func:`_sums_keeping`)
            clock_end[1, i] = clock1
        else:
            age0, clock0 = t - tb[i], 1.0
            age1, clock1 = t1 - tb[i], 1.0
        f1 = _chain_force(e1, m, dlm)
        if cached:  # the last row's values at the step's start (the same numbers)
            lr0 = cache[4, i]
            r0 = cache[5, i]
            k0 = cache[2, i]
        else:
            lr0 = min(log_u0_tau + beta * abs(f0) - age0 * slope0, LOG_RATE_CAP)
            r0 = math.exp(lr0)
            k0 = _chain_stiffness(e0, m, dlm)
        lr1 = min(log_u0_tau + beta * abs(f1) - age1 * slope1, LOG_RATE_CAP)
        r1 = math.exp(lr1)
        k1 = _chain_stiffness(e1, m, dlm)
        predicted[0, i] = f1
        predicted[1, i] = k1
        g0, g1 = _hazard_slopes(f0, f1, k0, k1, v0, v1p, age0, age1, clock0, clock1, slope0, slope1, accel, beta,
                                va, aging_on)  # fmt: skip
        new, wn, dw, dying, trap, exact = _cohort_weight(lw[i], w0, f0, hh, lr0, r0, lr1, r1, g0, g1)
        known[0, i] = wn if exact else -1.0
        if tb[i] >= t0:
            cliff += dying
        elif dying > 0.0 and not (split_floor < np.inf and _piece(i, n, xb) >= 0):
            # (a piece of a cut cohort dies in lumps the cut already holds below its share of rtol: not counted)
            cliff_old += dying
        err_s += abs(f1) * dw
        err_n += dw
        sens_x += wn * abs(f1) * r1 * beta * k1
        sens_a += wn * abs(f1) * r1 * age1
        loss0 += w0 * r0
        loss1 += wn * r1
        dloss0 += w0 * r0 * (g0 - r0)
        dloss1 += wn * r1 * (g1 - r1)
        broken += w0 - wn
        u0 = cache[3, i] if cached else np.nan
        u1 = _chain_energy(e1, m, dlm) if trap < 0.5 else np.nan
        predicted[2, i] = u1  # the energy at x1p: the balanced end's follows from it (:func:`_energy_at_end`)
        dissip += _cohort_dissipation(trap, hh, w0, wn, r0, r1, g0, g1, f0, f1, v0, v1p, e0, u1, x_mid - xb[i], u0, m,
                                      dlm)  # fmt: skip
        rate_s0 += w0 * r0 * f0
        rate_s1 += wn * r1 * f1
        kint0 += w0 * k0
        kint1 += wn * k1
        nn1 += wn
        s1 += wn * f1
        lw_new[i] = new
        w1[i] = wn
        rate0[i] = r1  # kept for the merging of quiet cohorts after the step
        if e1 * v1p > 0.0 and (wn >= old_wall_count if old_walls_free and tb[i] < t0 else wn * abs(f1) >= wall_load):
            wall_gap = min(wall_gap, dlm - abs(e1))
        # a cohort whose hazard climbs fast against the time its cell takes to pass (a first look at one neighbour)
        if split_floor < np.inf and g1 > r1 * SPLIT_ALIVE:  # climbing, and short of its cliff (z > SPLIT_LATE)
            j = i + 1 if i + 1 < n else i - 1
            if j >= 0 and abs(xb[j] - xb[i]) * g1 >= 0.5 * SPLIT_SPACING * abs(v1p):
                k = _split_look(i, n, xb, tb, wn, e1, lr1, g1, v1p, slope1 * clock1, split_floor, p)
                if k > 1 and n_split < split_at.shape[0]:
                    split_at[n_split] = i
                    split_pieces[n_split] = k
                    n_split += 1
    return (
        nn0, s0, nn1, s1, loss0, loss1, dloss0, dloss1, broken, dissip, rate_s0, rate_s1, kint0, kint1, err_s, err_n,
        sens_x, sens_a, walled, cliff, cliff_old, wall_gap, n_split, refill_a, refill_b,
    )  # fmt: skip


def _birth_point(  # type: ignore[no-untyped-def]
    k, n, t, hh, x, x1p, v0, v1p, accel, accel_now, jerk, slope1, r_birth, inertial, xb, tb, known, rate0, predicted, p
):  # fmt: skip
    """The births of half the step (k = 0, 1), lumped at its Gauss-Legendre point as cohort n + k: what does not
    depend on how many are born (their place, force, hazard, survival to the step's end), computed once a step.
    Returns (the Gauss point u within the step, the share of them alive at the step's end, the energy each one
    that breaks dissipates, the lumping error per bond born, their hazard at the end and its log's rate there,
    their extension there, the vacancy's exponentials at u).

    The births' mass comes from the vacancy, which the newborns' own breakage refills: :func:`_births` sweeps
    that (:func:`_birth_mass`) without computing these again (two exponentials, a log and the chains' force,
    stiffness and energy per point and sweep; ~9 sweeps a step in the stick chains' cycle)."""
    m = p[P_M]
    dlm = p[P_DLM]
    u = hh * (0.5 - GAUSS if k == 0 else 0.5 + GAUSS)
    d = hh - u  # its age at t1
    if inertial:  # on the predicted cubic path
        x_k = x + u * (v0 + u * (0.5 * accel_now + u * jerk / 6.0))
    else:
        x_k = x + u * v0 + 0.5 * (v1p - v0) * u * u / hh
    e_k = x1p - x_k
    predicted[0, n + k] = _chain_force(e_k, m, dlm)
    predicted[1, n + k] = _chain_stiffness(e_k, m, dlm)
    predicted[2, n + k] = np.nan  # their energy at x1p is not computed (:func:`_energy_at_end`)
    lr_end = min(_log_rate(e_k, d, slope1, p), LOG_RATE_CAP)
    r_end = math.exp(lr_end)
    g_end = p[P_FORCE_SENS] * _chain_stiffness(e_k, m, dlm) * v1p - slope1 * _aging_clock(d, p)[1]
    g_start = p[P_FORCE_SENS] * m * (v0 + accel * u) - _aging_factor(v0 + accel * u, p)
    trap = 0.5 * d * (r_birth + r_end)
    lr_birth = p[P_LOG_U0_TAU]
    if abs(lr_end - lr_birth) > 1.0 and lr_end < LOG_RATE_CAP:  # as for the cohorts (_cohort_weight)
        survival = math.exp(-d * (r_end - r_birth) / (lr_end - lr_birth))
    else:
        corr = d * d / 12.0 * (r_end * g_end - r_birth * g_start)
        corr = min(max(corr, -0.5 * trap), 0.5 * trap)
        survival = math.exp(-trap + corr)
    # births reaching the FENE wall within the step are gone by its end; their energy is taken at
    # half the wall's extension (the step control keeps such losses small, below)
    energy = _chain_energy(0.5 * min(e_k, dlm), m, dlm)
    # the error of lumping this half-step's births into one cohort: (h r)^2/24 of its mass for a
    # gentle hazard; when the births die within the step, what a resolved step would keep alive at
    # its end (the birth rate times the newborns' life 1/r, at most all of it; :func:`_birth_mass`): bonds
    # living shorter than a step would otherwise vanish from the population without a word
    z = max(r_birth * hh, trap)
    # births under a slider at rest (velocity control, a hold) share one birth position: lumping them misplaces
    # no stretch, only ages, which the Gauss pair's own bias bounds (docs/transient.md section 23)
    if _relaxed_births(p) or (v0 == 0.0 and v1p == 0.0 and not inertial):  # the Gauss pair's own bias
        z = max(hh * (r_birth + p[P_INV_TAU_A]), trap)
        lumping = min(1.0, BIRTH_BIAS * z**4 / 4320.0)
    else:
        lumping = min(1.0, z * z / 24.0)
    xb[n + k] = x_k
    tb[n + k] = t + u
    known[0, n + k] = -1.0
    known[3, n + k] = np.nan
    rate0[n + k] = r_end
    dec, c0, c1, c2, c3 = _vacancy_kernel(u, p[P_TAU])
    return u, survival, energy, lumping, r_end, g_end, e_k, dec, c0, c1, c2, c3


def _birth_mass(  # type: ignore[no-untyped-def]
    u, q0, hh, loss0, dloss0, l1, d1, r_birth, survival, energy, lumping, r_end, g_end, dec, c0, c1, c2, c3, refill,
    p,
):  # fmt: skip
    """The births of half the step at its Gauss point (:func:`_birth_point`), from the vacancy's relaxation from
    q0 with the breakage rate's Hermite cubic (l1, d1 at the end): (born, alive at the step's end, the energy of
    those that broke, the error of lumping them, their breakage rate at the end and its derivative)."""
    tau = p[P_TAU]
    q = _vacancy_from(u, q0, tau, hh, loss0, dloss0, l1, d1, dec, c0, c1, c2, c3) + refill
    mass = 0.5 * hh * max(q, 0.0) / tau
    alive = mass * survival
    dissip = (mass - alive) * energy
    lump = min(mass * lumping, 2.0 * mass / (hh * r_birth))
    return mass, alive, dissip, lump, alive * r_end, alive * r_end * (g_end - r_end)


def _births(  # type: ignore[no-untyped-def]
    n, t, hh, x, x1p, v0, v1p, accel, accel_now, jerk, slope1, nn0, nn1, loss0, dloss0, loss1, dloss1, inertial,
    xb, tb, lw_new, w1, known, rate0, predicted, refill_a, refill_b, p,
):  # fmt: skip
    """Births over the step, as two cohorts at the Gauss-Legendre points (fourth order in h): the vacancy
    Q = N0 - N relaxes at 1/tau and is refilled by breakage, a Hermite cubic over the step; the newborns' own
    breakage joins it (fixed-point passes, for their mass and rate at t1).  Returns (born, alive at t1, their
    breakage rate at t1, the energy of those that broke, the lumping error, the second's extension, the vacancy
    at the start, the breakage rate's derivative at both ends with the newborns')."""
    big = p[P_N0]
    tau = p[P_TAU]
    q0 = big - nn0
    r_birth = math.exp(p[P_LOG_U0_TAU])  # hazard at age 0, extension 0
    dloss0 += r_birth * q0 / tau
    u_a, surv_a, energy_a, lumping_a, r_a, g_a, _e_a, dec_a, a0, a1, a2, a3 = _birth_point(
        0, n, t, hh, x, x1p, v0, v1p, accel, accel_now, jerk, slope1, r_birth, inertial, xb, tb, known, rate0,
        predicted, p,
    )  # fmt: skip
    u_b, surv_b, energy_b, lumping_b, r_b, g_b, e_nb, dec_b, b0, b1, b2, b3 = _birth_point(
        1, n, t, hh, x, x1p, v0, v1p, accel, accel_now, jerk, slope1, r_birth, inertial, xb, tb, known, rate0,
        predicted, p,
    )  # fmt: skip
    born = born_alive = newborn_loss = newborn_dloss = newborn_dissip = lump = 0.0
    alive_a = alive_b = 0.0
    q_end = q0
    d1 = 0.0
    relaxed = _relaxed_births(p)
    last = -1.0
    residual = 0.0
    for _sweep in range(MAX_SWEEPS if relaxed else 3):
        l1 = loss1 + newborn_loss
        d1 = dloss1 + newborn_dloss + r_birth * q_end / tau
        mass, alive_a, dissip, lumped, loss_k, dloss_k = _birth_mass(
            u_a, q0, hh, loss0, dloss0, l1, d1, r_birth, surv_a, energy_a, lumping_a, r_a, g_a, dec_a, a0, a1, a2,
            a3, refill_a, p,
        )  # fmt: skip
        born = mass
        born_alive = alive_a
        newborn_dissip = dissip
        lump = lumped
        newborn_loss = loss_k
        newborn_dloss = dloss_k
        mass, alive_b, dissip, lumped, loss_k, dloss_k = _birth_mass(
            u_b, q0, hh, loss0, dloss0, l1, d1, r_birth, surv_b, energy_b, lumping_b, r_b, g_b, dec_b, b0, b1, b2,
            b3, refill_b, p,
        )  # fmt: skip
        born += mass
        born_alive += alive_b
        newborn_dissip += dissip
        lump += lumped
        newborn_loss += loss_k
        newborn_dloss += dloss_k
        q_end = max(big - nn1 - born_alive, 0.0)
        if relaxed:  # swept until the newborns' own breakage settles; what the last sweep moved counts as an error
            residual = abs(born_alive - last) if last >= 0.0 else born_alive
            if residual <= SWEEP_SETTLED * big:
                break
            last = born_alive
    lw_new[n] = math.log(alive_a) if alive_a > 0.0 else -np.inf
    w1[n] = alive_a
    lw_new[n + 1] = math.log(alive_b) if alive_b > 0.0 else -np.inf
    w1[n + 1] = alive_b
    return born, born_alive, newborn_loss, newborn_dissip, lump + residual, e_nb, q0, dloss0, d1


def _births_within_vacancy(  # type: ignore[no-untyped-def]
    n, hh, q0, loss0, dloss0, loss1, newborn_loss, d1, walled, nn1, born, born_alive, newborn_dissip, err_n, w1,
    lw_new, p,
):  # fmt: skip
    """The births must not overfill the vacancy the bonds left: (born, alive, their dissipation, err_n) rescaled.

    Over a step much longer than tau the Gauss masses rest on the Hermite cubic of the breakage rate across the
    whole step, which is poor where the hazard of young bonds falls at 1/tau_a (a stuck block: N/N0 came out
    1.00005); there the vacancy at t1 is set by its own equation instead, N(t1) = N0 - Q(t1), Q relaxing over the
    last few tau of the step, where the breakage rate is the exact one at t1 (sites freed by the FENE wall refill
    from the next step on).  Over shorter steps the Gauss masses stand (where N << N0 they are far more accurate
    than N0 - Q), but never above the vacancy."""
    big = p[P_N0]
    tau = p[P_TAU]
    target = born_alive
    if hh > 2.0 * tau:
        q_h = max(_vacancy(hh, q0, tau, hh, loss0, dloss0, loss1 + newborn_loss, d1), 0.0) + walled
        target = max(big - nn1 - q_h, 0.0)
    elif _relaxed_births(p):  # the Gauss masses stand; their distance from the vacancy's own N counts as an error
        q_h = max(_vacancy(hh, q0, tau, hh, loss0, dloss0, loss1 + newborn_loss, d1), 0.0) + walled
        err_n += abs(max(big - nn1 - q_h, 0.0) - born_alive)
    target = min(target, max(big - nn1, 0.0))
    if born_alive > 0.0 and target != born_alive:
        scale = target / born_alive
        err_n += abs(target - born_alive)
        for k in range(2):
            w1[n + k] *= scale
            lw_new[n + k] = math.log(w1[n + k]) if w1[n + k] > 0.0 else -np.inf
        born *= scale
        born_alive = target
        newborn_dissip *= scale
    return born, born_alive, newborn_dissip, err_n


def _birth_errors(err_s, err_n, lump, born, hh, x1p, x_mid, v1p, slope1, p):  # type: ignore[no-untyped-def]
    """(err_s, err_n) with the births' errors: one lumped cohort's (a conservative estimate: the Gauss pair's is far
    smaller), and the Gauss rule's at a hazard cliff.

    Births lumped at two instants per step meet the hazard's cliff later (ln r climbing at g = beta M V minus the
    aging slope): the Gauss rule over birth times then errs by ~(h g)^4/4320 of the stress the bonds carry there,
    the whole stream born at this pace over their life a_cliff (bonds living ~40 us, dying within ~3 us, steps of
    ~10 us left the stress 5e-3 off the steady curve with nothing in the estimate).  A quadrature error of the
    population, not one that accumulates: it is compared, as a whole, with rtol times the stress."""
    m = p[P_M]
    dlm = p[P_DLM]
    r_birth = math.exp(p[P_LOG_U0_TAU])
    err_n += lump
    err_s += lump * abs(_chain_force(min(x1p - x_mid, 0.5 * dlm), m, dlm))
    g_cliff = p[P_FORCE_SENS] * m * abs(v1p) - slope1
    if g_cliff > r_birth:
        z4 = (hh * g_cliff) ** 4 / 4320.0
        a_cliff = math.log1p(g_cliff / r_birth) / g_cliff  # age at which the cumulative hazard reaches 1
        e_cliff = min(abs(v1p) * a_cliff, 0.5 * dlm)
        carried = born * max(1.0, a_cliff / hh) * 0.5 * _chain_force(e_cliff, m, dlm)
        err_s += min(z4, 1.0) * carried
    return err_s, err_n


def _energy_at_end(n, shift, predicted, known, dlm):  # type: ignore[no-untyped-def]
    """known[3]: each cohort's bond energy at the balanced end x1 = x1p + shift, from the pass's at x1p
    (predicted[2]) and the force and stiffness at both ends (predicted[:2], known[1:3]): u(x1p) + shift (f(x1p) +
    f(x1))/2 - shift^2 (k(x1) - k(x1p))/12, the integral of f by the end-corrected trapezoid, whose error (shift^5
    times the fourth derivative of f over 720) is below rounding for |shift| <= ENERGY_SHIFT dl_m: a log1p per
    cohort and step saved; nan where not known, or the shift is longer."""
    near = abs(shift) <= ENERGY_SHIFT * dlm
    for i in range(n):
        u = predicted[2, i]
        if near and u == u and known[1, i] == known[1, i]:
            half_sum = 0.5 * (predicted[0, i] + known[1, i])
            known[3, i] = u + shift * (half_sum - shift * (known[2, i] - predicted[1, i]) / 12.0)
        else:
            known[3, i] = np.nan


def _slider_at_end(  # type: ignore[no-untyped-def]
    n, t, t1, t0, hh, x, v0, x1p, v1p, slope1, s0, s1, e_nb, sens_x, sens_a, err_s, puller0, vp, block, inertial,
    xb, tb, lw_new, w1, lc, aa, known, predicted, clock_end, p,
):  # fmt: skip
    """The slider at the step's end and the stress there: (x1, v1, s1, err_s, the block's force at the start).

    Velocity control: the slider where it was told, sigma with the newborns' force.  Through the massless block:
    where the bonds balance the block exactly, then its velocity (the stable root of g).  With a mass: its travel
    by the trapezoid rule against the end population.  err_s gains the error of the hazards having used the
    predicted path."""
    dlm = p[P_DLM]
    x1 = x1p
    v1 = v1p
    spring0 = p[P_K] * (puller0 + vp * (t - t0) - x)  # the block's force (massless: sigma) at the step's start
    if inertial:
        # the hazards used the predicted path, and the rule's own error (Milne's: a sixth of the corrector's
        # distance from the predictor, whose error is five times the trapezoid's) counts in the stress of the
        # block's mode
        force0 = spring0 - p[P_DAMPING] * v0 - s0
        travel, s1, k_end = _inertial_step(
            x1p - x, x, v0, force0, hh, puller0 + vp * (t1 - t0), n + 2, xb, w1, p, predicted
        )
        x1 = x + travel
        v1 = 2.0 * travel / hh - v0
        err_s += 0.5 * hh * (abs(x1 - x1p) * sens_x + abs(_aging_factor(v1, p) - slope1) * sens_a)
        k_mode = p[P_K] + k_end
        err_s += (math.sqrt(p[P_MASS] * k_mode) * abs(v1 - v1p) + k_mode * abs(x1 - x1p)) / 6.0
        if not (hh * abs(v1 - v1p) <= dlm):
            err_s = np.inf
    elif block == 1:
        x1 = _balance_from(x1p, puller0 + vp * (t1 - t0), n + 2, xb, w1, p, predicted)
        v1 = _slider_velocity_clocked(v1p, vp, n + 2, xb, tb, lw_new, x1, t1, p, lc, aa, known, clock_end)
        _energy_at_end(n + 2, x1 - x1p, predicted, known, dlm)
        err_s += 0.5 * hh * (abs(x1 - x1p) * sens_x + abs(_aging_factor(v1, p) - slope1) * sens_a)
        s1 = p[P_K] * (puller0 + vp * (t1 - t0) - x1)
        # that estimate is linear in the correction, and the hazard near the FENE wall is not: a cohort the
        # predicted position left just short of the wall can sit on its cliff (ln r at the cap) at the
        # balanced one, where g keeps no slow root and the slider's velocity comes out ~1e178 m/s (a creeping
        # steady start, 40 s at 100 um/s, went non-finite so).  A step whose end velocity would carry the
        # slider over a whole chain extension within the step does not follow the path it assumed: shorter.
        if not (hh * abs(v1 - v1p) <= dlm):
            err_s = np.inf
    else:
        s1 += w1[n] * _chain_force(x1p - xb[n], p[P_M], dlm) + w1[n + 1] * _chain_force(e_nb, p[P_M], dlm)
    return x1, v1, s1, err_s, spring0


def _step_error(err_s, err_n, cliff, cliff_old, s0, s1, s_floor, rtol, p):  # type: ignore[no-untyped-def]
    """The step's error as a fraction of the tolerance (accepted at most 1).

    Bonds born before this piece (a hold's, the steady start's) were lumped at steps unrelated to this one, which
    cannot mend that: their cliff counts only where it makes the stress fall across the step, a maximum the trace
    must resolve (the peak on re-sliding after a hold, old bonds dying at the FENE wall).  Counted always, the
    steady start's oldest bonds reaching the wall one cohort after another while sigma is ~1e-3 of that peak held
    the steps at ~0.1 us: 1 s hold then 5x the steps, 25x the CPU.  A rupture cascade is resolved in the trace:
    the stress falls by at most MAX_DROP within one step (both ends can be exact while the peak between them is
    lost)."""
    s_ref = max(abs(s1), abs(s0), s_floor)
    if abs(s1) < abs(s0):
        cliff += cliff_old
    err_s += cliff
    err = max(err_s / (rtol * s_ref), err_n / (rtol * p[P_N0]))
    return max(err, (max(abs(s0) - abs(s1), 0.0) / (MAX_DROP * s_ref)) ** 3)


def _stick_landing(hh, v0, v1, stick_velocity, s1, vp, rtol, p):  # type: ignore[no-untyped-def]
    """A step of length hh that took the slider below the stick velocity: the length that lands within
    STICK_LANDING x rtol of the stress past the crossing (found by linear interpolation of the velocity), or hh
    where it already does.  The chains take over at the step's end with the stress there, which moves at
    K (Vp - V) after the crossing: a stick taken wherever the step happened to end put sigma_s ~K Vp h/2 off
    (2e-6 of it for the gel, whatever rtol; docs/transient.md section 11)."""
    rate = p[P_K] * max(abs(vp - v0), abs(vp - v1))  # |dsigma/dt| over the step (the massless block)
    allowed = STICK_LANDING * rtol * max(abs(s1), 1e-300) / max(rate, 1e-300)
    crossing = hh * (v0 - stick_velocity) / (v0 - v1)
    if hh - crossing <= allowed:
        return hh
    return crossing + 0.5 * allowed


def _shorter_step(hh, err):  # type: ignore[no-untyped-def]
    """The step to try after a rejected one of length hh (its error err, nan: a tenth)."""
    factor = 0.9 * err ** (-1.0 / 3.0) if err == err else 0.1
    return hh * max(0.1, min(0.7, factor))


def _next_step(hh, err, h, h_max, landing):  # type: ignore[no-untyped-def]
    """The step to try after an accepted one of length hh: grown or shrunk by its error (a step that landed on a
    sample time keeps the step proposed before it)."""
    factor = 0.9 * max(err, 1e-12) ** (-1.0 / 3.0)
    return min(hh * min(4.0, max(0.2, factor)), h_max) if not landing else max(h, hh)


def _book_step(  # type: ignore[no-untyped-def]
    acc, n, t, t1, t0, hh, x1, v0, v1, s0, s1, spring0, kint0, kint1, rate_s0, rate_s1, born, born_alive, broken,
    dissip, newborn_dissip, puller0, vp, block, inertial, xb, w1, rate0, p,
):  # fmt: skip
    """The accepted step's totals into ``acc`` (``n``: the cohorts with the two newborns, last): born, broken, the
    puller's work and the integral of sigma (the end-corrected trapezoid, dsigma/dt = K (Vp - V) through the
    massless block, else k_int V - sum r w f), dissipation, steps, the lowest and highest stress (and when), the
    fastest slider."""
    m = p[P_M]
    dlm = p[P_DLM]
    broken += born - born_alive
    acc[0] += born
    acc[1] += broken
    if block == 1 and not inertial:
        mean = 0.5 * (spring0 + s1) - hh / 12.0 * p[P_K] * (v0 - v1)  # over the step
        acc[2] += mean * vp * hh
        acc[6] += mean * hh
    else:
        for k in range(2):
            e_k = x1 - xb[n - 2 + k]
            kint1 += w1[n - 2 + k] * _chain_stiffness(e_k, m, dlm)
            rate_s1 += w1[n - 2 + k] * rate0[n - 2 + k] * _chain_force(e_k, m, dlm)
        ds0 = kint0 * v0 - rate_s0
        ds1 = kint1 * v1 - rate_s1
        corr = hh / 12.0 * (ds1 - ds0)
        mean = 0.5 * (s0 + s1) - corr
        if abs(corr) > 0.5 * max(abs(s0), abs(s1)):
            # no correction: the rates change by orders within the step (a velocity step erasing the aging of old
            # bonds: dsigma/dt ~ -1e19 Pa/s at its start, tester Y's set 49, where the end correction booked
            # -2.7e12 Pa s and -3.6e8 J/m^2 of work in one 0.46 us step); sigma within the step's ends instead
            mean = min(max(mean, min(s0, s1)), max(s0, s1))
        acc[6] += mean * hh
        if inertial:  # the puller works against the block's spring, not the interface
            spring1 = p[P_K] * (puller0 + vp * (t1 - t0) - x1)
            mean = 0.5 * (spring0 + spring1) - hh / 12.0 * p[P_K] * (v0 - v1)
        acc[2] += mean * vp * hh
    acc[3] += dissip + newborn_dissip
    if inertial:  # the damping's share, eta V^2 over the step
        acc[3] += 0.5 * hh * p[P_DAMPING] * (v0 * v0 + v1 * v1)
    acc[4] += 1.0
    # the extremes of the accepted steps since the last row, with their times: a summary read from sampled rows
    # (--every) takes them from here, not from the rows kept
    if s1 < acc[7]:
        acc[9] = t1
    acc[7] = min(acc[7], s1)
    if s1 > acc[8]:
        acc[8] = s1
        acc[10] = t1
    acc[11] = max(acc[11], v1)


def _quiet_neighbours(rate_i, rate_g, xb_i, xb_g, tb_i, tb_g, quiet, gap, age_gap, p):  # type: ignore[no-untyped-def]
    """Two cohorts both quiet (negligible breakage for the rest of the piece) and born at nearly the same slider
    position and time (in units of the aging time, none without aging)."""
    return (
        rate_i < quiet
        and rate_g < quiet
        and abs(xb_i - xb_g) < gap
        and abs(tb_i - tb_g) * p[P_INV_TAU_A] * p[P_AGING] < age_gap
    )


def _housekeeping(
    n, t, t_end, x, nn1, s1, s_floor, rtol, xb, tb, lw, rate0, known, prepared, merging, acc, clock_end, p
):  # type: ignore[no-untyped-def]
    """Drop dead cohorts (their weight counts as broken, up to LIGHTEST * N0; with saturated aging, the negligible
    ones of :func:`_saturated_bins`) and merge neighbours that are quiet and born close (:func:`_quiet_neighbours`)
    or, past the saturation age, in one bin (:func:`_same_bin`); never the newest.  ``known`` as the step left it:
    each weight where exact, and each force at x where ``prepared`` (the massless block's balance): the same
    numbers, not computed again.  Returns the cohorts kept."""
    dlm = p[P_DLM]
    quiet = 1e-3 * rtol / max(t_end - t, 1.0)
    gap = 1e-4 * math.sqrt(rtol) * dlm
    age_gap = 1e-2 * math.sqrt(rtol)  # in units of the aging time: merged cohorts age alike in any future
    keep = 0
    floor = math.log(LIGHTEST * p[P_N0])
    # the housekeeping of saturating aging; off: the paper's, as for linear aging
    saturated = merging and p[P_SATURATION] > 0.0 and p[P_AGING] > 0.0 and p[P_MERGE_SATURATED] > 0.0
    light_n, light_s, spread = 0.0, 0.0, 1.0
    lw_mean = s_mean = 0.0
    if saturated:
        light_n, light_s, spread = _saturated_bins(n, nn1, s1, s_floor, rtol, p)
        lw_mean = math.log(max(nn1, 1e-300) / max(n, 1))
        s_mean = max(abs(s1), s_floor) / max(n, 1)
    # e^(-t_a/t_s) of the last kept cohort g, while its birth time stands (an exp per cohort saved: the next
    # cohort compares with it; the same numbers); negative: not known
    decay_g = -1.0
    for i in range(n):
        # only cohorts past the saturation age: those linger at the resting hazard (the young are as before)
        aged = saturated and t - tb[i] >= p[P_SATURATION]
        decay_i = -1.0
        f_i = known[1, i] if prepared else np.nan
        if lw[i] > floor and not (aged and _negligible(lw[i], x - xb[i], known[0, i], f_i, light_n, light_s, p)):
            g = keep - 1
            width = spread
            if aged and keep > 0:
                log_ratio = lw_mean - max(lw[i], lw[g])
                if log_ratio >= LOG_FOUR:  # lighter than a quarter of the mean: the loads decide a wider bin
                    load = max(
                        _cohort_load(lw[i], x - xb[i], known[0, i], f_i, p),
                        _cohort_load(lw[g], x - xb[g], known[0, g], known[1, g] if prepared else np.nan, p),
                    )
                    width = _light_spread(spread, log_ratio, load, s_mean)
                # the pass's clock at t where it left it (the same number), else computed
                decay_i = clock_end[1, i] if clock_end[0, i] == clock_end[0, i] else _saturation_decay(t, tb[i], p)
                if decay_g < 0.0:
                    decay_g = _saturation_decay(t, tb[g], p)
            if (
                keep > 0
                and i < n - 1
                and (
                    _quiet_neighbours(rate0[i], rate0[g], xb[i], xb[g], tb[i], tb[g], quiet, gap, age_gap, p)
                    or (aged and _same_bin(x, decay_i, decay_g, xb[i], xb[g], width, p))
                )
            ):
                # merged: the weight, the mean extension and age kept, so it breaks as its parts would in any
                # later history (a hold followed by re-sliding, for one)
                wa = math.exp(lw[g])
                wb = math.exp(lw[i])
                wt = wa + wb
                xb[g] = (wa * xb[g] + wb * xb[i]) / wt
                tb[g] = (wa * tb[g] + wb * tb[i]) / wt
                lw[g] = math.log(wt)
                known[0, g] = -1.0
                known[1, g] = np.nan
                known[3, g] = np.nan
                rate0[g] = max(rate0[g], rate0[i])
                decay_g = -1.0  # its birth time moved
                clock_end[0, g] = np.nan
                continue
            decay_g = decay_i
            xb[keep] = xb[i]
            tb[keep] = tb[i]
            lw[keep] = lw[i]
            known[0, keep] = known[0, i]
            known[1, keep] = known[1, i]
            known[2, keep] = known[2, i]
            known[3, keep] = known[3, i]
            rate0[keep] = rate0[i]
            clock_end[0, keep] = clock_end[0, i]
            clock_end[1, keep] = clock_end[1, i]
            keep += 1
        elif lw[i] > -np.inf:
            w = math.exp(lw[i])
            acc[1] += w
            acc[3] += w * _chain_energy(x - xb[i], p[P_M], dlm) if abs(x - xb[i]) < dlm else 0.0
    return keep


def _write_row(out, row, t, x, v, nn, ss, uu, puller0, vp, t0, block, acc):  # type: ignore[no-untyped-def]
    """One row of the trace: (time, sigma, N, V, X, P, born, broken, work, dissipation, bond energy, integral of
    sigma dt, lowest and highest stress since the last row, their times, the fastest slider since the last row;
    those extremes then reset).  An extreme's time is the row's own unless a step before it went beyond the row."""
    out[row, 0] = t
    out[row, 1] = ss
    out[row, 2] = nn
    out[row, 3] = v
    out[row, 4] = x
    out[row, 5] = puller0 + vp * (t - t0) if block == 1 else x
    out[row, 6] = acc[0]
    out[row, 7] = acc[1]
    out[row, 8] = acc[2]
    out[row, 9] = acc[3]
    out[row, 10] = uu
    out[row, 11] = acc[6]
    out[row, 12] = min(acc[7], ss)
    out[row, 13] = max(acc[8], ss)
    out[row, 14] = acc[9] if acc[7] < ss else t
    out[row, 15] = acc[10] if acc[8] > ss else t
    out[row, 16] = max(acc[11], v)
    acc[7] = np.inf
    acc[8] = -np.inf
    acc[9] = np.nan
    acc[10] = np.nan
    acc[11] = -np.inf


def advance(  # type: ignore[no-untyped-def]
    t, t_end, x, v, h, puller0, vp, t0, block, n, xb, tb, lw, lw_new, rate0, lc, aa, w1, acc, p, rtol, h_max,
    sample_times, sample_index, out, out_max, stick_velocity, max_steps,
):  # fmt: skip
    """Integrate from t to t_end (one protocol piece).  Returns (status, t, x, v, h, n, sample_index, rows).

    One step (docs/transient.md section 2): its length (:func:`_step_length`), the slider's path over it
    (:func:`_predicted_path`), every cohort's log weight along its characteristic (:func:`_cohort_pass`), the
    births at the Gauss points (:func:`_births`, :func:`_births_within_vacancy`, :func:`_birth_errors`), the slider
    at the end (:func:`_slider_at_end`), the error (:func:`_step_error`); then rejected (:func:`_shorter_step`) or
    accepted: its totals (:func:`_book_step`), the cohorts dropped and merged (:func:`_housekeeping`), the next
    step (:func:`_next_step`) and a row (:func:`_write_row`).

    ``acc`` accumulates [born, broken, puller work, dissipation, steps, rejected, integral of sigma dt, lowest
    and highest sigma since the last row, the times of those two, the fastest V since the last row, then the switch
    ACC_SPLIT: cohorts cut ahead of a hazard cliff under velocity control (:func:`_split`), 1, or not, 0]
    (:data:`ACC_START`).  Rows (:data:`ROW_COLUMNS`) are written to ``out`` every accepted step when
    ``sample_times`` is empty, else only at those times (the steps land on them exactly).  ``t0``: the start of
    the protocol's piece (puller0 is the puller there; bonds born before it were born at other steps).  ``block``:
    1 for block control (vp is the puller's velocity), 0 for velocity control (v = vp).
    """
    rows = 0
    steps = 0
    n_samples = sample_times.shape[0]
    v_prev = v
    h_prev = 0.0
    s_floor = 1e-9 * p[P_M] * p[P_N0] * p[P_DLM]
    wall_load = np.inf  # no landing before the first step's stress is known
    old_wall_count = np.inf
    old_walls_free = block == 0  # (velocity control: :func:`_cohort_pass`)
    # cohorts cut ahead of a hazard cliff (:func:`_split`), under velocity control: none before the first step's
    # stress is known.  Not through the block: there the cohorts at the wall of a creeping block are too coarse for
    # the slider's balance itself (docs/transient.md section 17), which the cut moves (4 MPa/m: failed at 4.66 s
    # instead of 5.08 s) without mending it
    splitting = block == 0 and acc.shape[0] > ACC_SPLIT and acc[ACC_SPLIT] > 0.0
    split_floor = np.inf
    split_at = np.zeros(SPLIT_SLOTS, np.int64)
    split_pieces = np.zeros(SPLIT_SLOTS, np.int64)
    split_cells = np.empty((4, SPLIT_SLOTS))
    need_room = False
    while sample_index < n_samples and sample_times[sample_index] <= t:  # grid points already passed
        sample_index += 1
    cache = np.empty((8, xb.shape[0]))  # the cohorts' values at the start of the step, when ``cached``
    # saturating aging: each cohort's clock (A, dA/dt_a) at the step's end, from its pass; nan: not known
    clock_end = np.full((2, xb.shape[0]), np.nan)
    # exp(lw_new) (then exp(lw)) where computed exactly so, else -1; force and stiffness at the step's end (block)
    known = np.full((4, xb.shape[0]), -1.0)
    known[3] = np.nan  # and the bond energy at the step's end where derived from the pass's (:func:`_energy_at_end`)
    predicted = np.empty((3, xb.shape[0]))  # force, stiffness and bond energy at the step's predicted end x1p
    # False, typed bool: a literal False here made numba compile _cohort_pass a second time (~2.5 s on a fresh cache)
    cached = xb.shape[0] < 0
    # the block with a mass: the slider's acceleration now and at the previous step's start (for the predictor)
    inertial = block == 1 and p[P_MASS] > 0.0
    accel_now = 0.0
    if inertial:
        accel_now = (p[P_K] * (puller0 + vp * (t - t0) - x) - p[P_DAMPING] * v - _sums(n, xb, lw, x, p)[1]) / p[P_MASS]
    accel_prev = accel_now
    while t < t_end:
        if steps >= max_steps:
            return STEPS, t, x, v, h, n, sample_index, rows
        if n + 3 >= xb.shape[0] or need_room:
            return FULL, t, x, v, h, n, sample_index, rows
        hh, landing = _step_length(t, t_end, h, h_max, sample_times, sample_index)
        t1 = t + hh
        v0, v1p, x1p, x_mid, jerk = _predicted_path(
            x, v, v_prev, h_prev, hh, vp, block, inertial, accel_now, accel_prev
        )
        slope0 = _aging_factor(v0, p)
        slope1 = _aging_factor(v1p, p)
        accel = (v1p - v0) / hh
        (
            nn0, s0, nn1, s1, loss0, loss1, dloss0, dloss1, broken, dissip, rate_s0, rate_s1, kint0, kint1, err_s,
            err_n, sens_x, sens_a, walled, cliff, cliff_old, wall_gap, n_split, refill_a, refill_b,
        ) = _cohort_pass(
            n, t, t1, t0, hh, x, x1p, x_mid, v0, v1p, slope0, slope1, accel, xb, tb, lw, lw_new, rate0, w1, known,
            predicted, cache, cached, clock_end, wall_load, old_walls_free, old_wall_count, split_floor, split_at,
            split_pieces, p,
        )  # fmt: skip
        clock_end[0, n] = np.nan  # the newborns' clock is not computed by the pass
        clock_end[0, n + 1] = np.nan
        born, born_alive, newborn_loss, newborn_dissip, lump, e_nb, q0, dloss0, d1 = _births(
            n, t, hh, x, x1p, v0, v1p, accel, accel_now, jerk, slope1, nn0, nn1, loss0, dloss0, loss1, dloss1,
            inertial, xb, tb, lw_new, w1, known, rate0, predicted, refill_a, refill_b, p,
        )  # fmt: skip
        born, born_alive, newborn_dissip, err_n = _births_within_vacancy(
            n, hh, q0, loss0, dloss0, loss1, newborn_loss, d1, walled, nn1, born, born_alive, newborn_dissip, err_n,
            w1, lw_new, p,
        )  # fmt: skip
        err_s, err_n = _birth_errors(err_s, err_n, lump, born, hh, x1p, x_mid, v1p, slope1, p)
        x1, v1, s1, err_s, spring0 = _slider_at_end(
            n, t, t1, t0, hh, x, v0, x1p, v1p, slope1, s0, s1, e_nb, sens_x, sens_a, err_s, puller0, vp, block,
            inertial, xb, tb, lw_new, w1, lc, aa, known, predicted, clock_end, p,
        )  # fmt: skip
        nn1 += born_alive
        err = _step_error(err_s, err_n, cliff, cliff_old, s0, s1, s_floor, rtol, p)
        if not (err <= 1.0):
            if hh > 1e-15 * max(t, p[P_TAU]):
                acc[5] += 1.0
                h = _shorter_step(hh, err)
                continue
            # the step has collapsed to its floor and still fails (a massless block whose bonds give way faster
            # than it can follow): accepted, it left the outcome to where the steps happened to land, a runaway
            # unsampled and a landing on a stuck block sampled every 0.1 ms (issue 33.1)
            return FAILED, t, x, v, hh, n, sample_index, rows
        if stick_velocity > 0.0 and block == 1 and v1 < stick_velocity <= v:
            landing_time = _stick_landing(hh, v, v1, stick_velocity, s1, vp, rtol, p)
            if landing_time < hh:  # the step passed the stick by more than its stress may move: landed on it
                acc[5] += 1.0
                h = landing_time
                continue
        # ---- accepted
        cached = False
        for i in range(n + 2):
            lw[i] = lw_new[i]
        n += 2
        _book_step(
            acc, n, t, t1, t0, hh, x1, v0, v1, s0, s1, spring0, kint0, kint1, rate_s0, rate_s1, born, born_alive,
            broken, dissip, newborn_dissip, puller0, vp, block, inertial, xb, w1, rate0, p,
        )  # fmt: skip
        v_prev, h_prev, t, x, v = v, hh, t1, x1, v1
        if inertial:
            accel_prev = accel_now
            accel_now = (p[P_K] * (puller0 + vp * (t - t0) - x) - p[P_DAMPING] * v - s1) / p[P_MASS]
        steps += 1
        if n_split > 0:  # cohorts coming to a cliff in lumps: cut (the newborns, last, stay where _book_step read them)
            n, need_room = _split(n, n_split, split_at, split_pieces, split_cells, xb, tb, lw, rate0, known, clock_end)
        n = _housekeeping(
            n, t, t_end, x, nn1, s1, s_floor, rtol, xb, tb, lw, rate0, known, block == 1 and not inertial,
            steps % MERGE_EVERY == 0, acc, clock_end, p,
        )  # fmt: skip
        h = _next_step(hh, err, h, h_max, landing)
        if p[P_WALL_LANDING] > 0.0 and abs(v1) > 0.0:
            # the next step ends short of the next loaded cohort's arrival at the FENE wall (a chain reaching full
            # extension within a step counts its whole stress as the step's error: such a step was rejected,
            # three times on average, re-sliding after a hold, where aged bonds die at the wall one after another)
            h = min(h, p[P_WALL_LANDING] * wall_gap / abs(v1))
        wall_load = WALL_SHARE * rtol * max(abs(s1), s_floor)
        old_wall_count = WALL_SHARE * rtol * p[P_N0]
        if splitting:
            split_floor = SPLIT_SHARE * rtol * max(abs(s1), s_floor)
        record = n_samples == 0
        if landing:
            sample_index += 1
            record = True
        if record and rows < out_max:
            # the next step starts from this state: its opening values are kept (rejected steps keep them too)
            slope = _aging_factor(v if block == 1 else vp, p)
            nn, ss, uu, cached = _sums_keeping(
                n, xb, tb, lw, x, t, slope, p, cache, known, block == 1 and not inertial, clock_end, block == 0, rate0
            )
            _write_row(out, rows, t, x, v, nn, ss, uu, puller0, vp, t0, block, acc)
            rows += 1
            if rows >= out_max:
                return STEPS, t, x, v, h, n, sample_index, rows
        if stick_velocity > 0.0 and block == 1 and v < stick_velocity:
            return STICK, t, x, v, h, n, sample_index, rows
    return DONE, t, x, v, h, n, sample_index, rows


@contextmanager
def cohorts_unsplit() -> Iterator[None]:
    """Runs started within keep every cohort whole up to its cliff (the kernel before docs/transient.md section 21):
    the reference of tests/test_transient_low_velocity.py and of the section's measurements."""
    global ACC_START
    saved = ACC_START
    ACC_START = (*saved[:ACC_SPLIT], 0.0)
    try:
        yield
    finally:
        ACC_START = saved


_COMPILED: dict[str, object] = {}
#: inlined into their callers by numba: the per-cohort steps (they take numbers, never arrays: helpers taking arrays
#: once per cohort left the kernel 1.4x slower) and the steps ``advance`` takes once per step.  The two loops over
#: the cohorts (_cohort_pass, _housekeeping) stay functions of their own: inlined, the kernel was 5-9 % slower.
#: Measured against the kernel before the split in one process (docs/transient.md section 8).
INLINED = (
    "_piece",
    "_edge",
    "_cell",
    "_split_plan",
    "_hazard_slopes",
    "_cohort_weight",
    "_cohort_dissipation",
    "_quiet_neighbours",
    "_birth_point",
    "_birth_mass",
    "_step_length",
    "_predicted_path",
    "_births",
    "_births_within_vacancy",
    "_birth_errors",
    "_slider_at_end",
    "_step_error",
    "_stick_landing",
    "_shorter_step",
    "_next_step",
    "_book_step",
    "_write_row",
)


#: the words of the first-compile notice (numerics/first_compile.py) for the time-dependent model's kernels
TRANSIENT_KERNELS = "the time-dependent model's kernels"


def compiled() -> dict[str, object]:
    """The numba-compiled kernel functions (compiled on first use, cached on disk)."""
    if not _COMPILED:
        g = globals()
        # compile helpers first so that the jitted callers bind to jitted callees
        for name in (
            "_relaxed_births",
            "_chain_force",
            "_chain_stiffness",
            "_chain_energy",
            "_aging_factor",
            "_aging_clock",
            "_log_rate",
            "_hermite",
            "_vacancy_kernel",
            "_vacancy_from",
            "_vacancy",
            "_cohort_load",
            "_negligible",
            "_light_spread",
            "_same_bin",
            "_saturation_decay",
            "_energy_at_end",
            "_cliff",
            "_ripple",
        ):
            g[name] = _jit(g[name])
        for name in INLINED:
            g[name] = _jit(g[name], inline=True)
        for name in (
            "_velocity_prepare",
            "_velocity_residual",
            "_slider_velocity_clocked",
            "_slider_velocity",
            "_balance_from",
            "_balance_weights",
            "_inertial_step",
            "_saturated_bins",
            "_sums",
            "_sums_keeping",
            "_split_look",
            "_cohort_pass",
            "_housekeeping",
            "_in_pairs",
            "_split",
            "advance",
        ):
            g[name] = _jit(g[name])
            _COMPILED[name] = g[name]
        announce_if_uncached(_COMPILED["advance"], TRANSIENT_KERNELS)
    return _COMPILED
