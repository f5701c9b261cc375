r"""The cohort integrator of Eq 1 (numba): bonds grouped by birth time, advanced along their characteristics.

A cohort born at time ``s`` when the slider was at ``x_b`` has, at time t,
age ``t - s`` and chain extension ``X(t) - x_b`` (the slider's travel since
the bond formed, docs/transient.md section 1).  Its weight w (bonds per m^2)
obeys d ln w/dt = -r with the hazard of Eq 1,

    r = (u0/tau) exp( (lambda/kT) f(e) - (t_a/tau_a) exp(-V/V_a) ),   f(e) = M e / (1 - (e/dl_m)^2)  (Eq 3).

Births, (N0 - N)/tau per unit time, make one new cohort per step, placed at
the middle of the step.  The vacancy N0 - N is advanced with the exact
exponential of its linear birth term, so steps may be much longer than tau
when nothing else moves (a stuck block).

Block control: sigma = K (P - X) at every instant.  Differentiating it with
sigma = sum w f(e) gives the slider velocity as the root of

    g(V) = (k_int + K) V - K V_p - sum r_i(V) w_i f_i = 0,     k_int = sum w_i f'(e_i),

which is explicit without aging and a scalar root otherwise; the root is
followed by continuity (the nearest crossing with g' > 0, the stable one for
any small mass), and when it disappears the slider jumps to the next one.

Time stepping: Heun's method (trapezoidal hazard, trapezoidal slider
velocity) with the explicit-Euler predictor as embedded error estimate,
measured in stress (sum f |dw| + k_int |dX|) and in bonds (sum |dw|).
Everything is SI.
"""

from __future__ import annotations

import math

import numpy as np

#: log of the largest hazard used (exp(700) ~ 1e304 per second); beyond it a cohort is gone in any step
LOG_RATE_CAP = 700.0
#: cohorts lighter than this fraction of N0 are dropped (counted as broken)
LIGHTEST = 1e-30

# float parameter vector layout (see pack_parameters in model.py)
P_LOG_U0_TAU, P_TAU, P_FORCE_SENS, P_M, P_DLM, P_INV_TAU_A, P_VA, P_N0, P_K, P_AGING = range(10)
# integer status returned by advance()
DONE, FULL, STEPS, STICK, FAILED = 0, 1, 2, 3, 4


def _jit(func):  # type: ignore[no-untyped-def]
    from numba import njit

    return njit(cache=True, fastmath=False, nogil=True)(func)


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


def _log_rate(e, age, slope, p):  # type: ignore[no-untyped-def]
    """ln r of Eq 1 for extension e and age, with slope = _aging_factor(V); +inf past the FENE limit."""
    if e >= p[P_DLM] or -e >= p[P_DLM]:
        return np.inf
    f = _chain_force(e, p[P_M], p[P_DLM])
    return p[P_LOG_U0_TAU] + p[P_FORCE_SENS] * abs(f) - age * slope


def _velocity_prepare(n, xb, tb, lw, x, t, p, lc, aa):  # type: ignore[no-untyped-def]
    """k_int; fills lc = ln(w f r) without the aging term and aa = t_a/tau_a for the cohorts."""
    k_int = 0.0
    for i in range(n):
        e = x - xb[i]
        if lw[i] == -np.inf or e >= p[P_DLM] or -e >= p[P_DLM]:
            lc[i] = -np.inf
            aa[i] = 0.0
            continue
        w = math.exp(lw[i])
        k_int += w * _chain_stiffness(e, p[P_M], p[P_DLM])
        f = _chain_force(e, p[P_M], p[P_DLM])
        lc[i] = lw[i] + math.log(f) + p[P_LOG_U0_TAU] + p[P_FORCE_SENS] * f if f > 0.0 else -np.inf
        aa[i] = (t - tb[i]) * p[P_INV_TAU_A] if p[P_AGING] > 0.0 else 0.0
    return k_int


def _velocity_residual(v, vp, n, lc, aa, k_int, p):  # type: ignore[no-untyped-def]
    """(g(V), g'(V)) of the module docstring, from the prepared lc, aa."""
    decay = math.exp(-abs(v) / p[P_VA]) if p[P_AGING] > 0.0 else 0.0
    loss = 0.0
    dloss = 0.0
    for i in range(n):
        if lc[i] == -np.inf:
            continue
        term = math.exp(min(lc[i] - aa[i] * decay, LOG_RATE_CAP))
        loss += term
        dloss += term * aa[i] * decay / p[P_VA]
    return (k_int + p[P_K]) * v - p[P_K] * vp - loss, (k_int + p[P_K]) - dloss


def _slider_velocity(v_prev, vp, n, xb, tb, lw, x, t, p, lc, aa):  # type: ignore[no-untyped-def]
    """The stable root of g nearest v_prev (block control): safeguarded Newton inside a bracket."""
    k_int = _velocity_prepare(n, xb, tb, lw, x, t, p, lc, aa)
    g0, d0 = _velocity_residual(v_prev, vp, n, lc, aa, k_int, p)
    if p[P_AGING] == 0.0:  # g is linear in V
        return v_prev - g0 / d0
    if g0 == 0.0:
        return v_prev
    # bracket the nearest crossing in the direction of the root (g(0) <= 0 always)
    scale = max(abs(v_prev), 1e-12)
    if g0 < 0.0:
        lo, hi = v_prev, np.inf
        if d0 > 0.0:
            trial = v_prev - g0 / d0
        else:
            trial = v_prev + scale
        for _ in range(400):
            gt, _d = _velocity_residual(trial, vp, n, lc, aa, k_int, p)
            if gt >= 0.0:
                hi = trial
                break
            lo = trial
            trial = lo + 2.0 * (lo - v_prev) + scale
    else:
        lo, hi = 0.0, v_prev
        trial = v_prev - g0 / d0 if d0 > 0.0 else 0.5 * v_prev
        if trial < 0.0:
            trial = 0.0
        for _ in range(400):
            gt, _d = _velocity_residual(trial, vp, n, lc, aa, k_int, p)
            if gt <= 0.0:
                lo = trial
                break
            hi = trial
            trial = 0.5 * trial if trial > 1e-300 else 0.0
    if not hi < np.inf:
        return lo
    v = lo if g0 < 0.0 else hi
    for _ in range(100):
        g, d = _velocity_residual(v, vp, n, lc, aa, k_int, p)
        if g == 0.0:
            return v
        if g < 0.0:
            lo = v
        else:
            hi = v
        v_new = v - g / d if d > 0.0 else 0.5 * (lo + hi)
        if not (lo < v_new < hi):
            v_new = 0.5 * (lo + hi)
        if abs(v_new - v) <= 1e-13 * max(abs(v_new), 1e-300) or hi - lo <= 1e-14 * hi:
            return v_new
        v = v_new
    return v


def _balance_position(x, puller, n, xb, lw, p):  # type: ignore[no-untyped-def]
    """X with sum w f(X - x_b) = K (puller - X): Newton on a strictly increasing function."""
    lo = -np.inf
    hi = np.inf
    for i in range(n):  # the FENE wall of the oldest live chain
        if lw[i] > -np.inf:
            hi = min(hi, xb[i] + p[P_DLM] * (1.0 - 1e-15))
    if x >= hi:
        x = hi - 1e-3 * p[P_DLM]
    for _ in range(100):
        s = 0.0
        k = p[P_K]
        for i in range(n):
            w = math.exp(lw[i])
            if w == 0.0:
                continue
            e = x - xb[i]
            s += w * _chain_force(e, p[P_M], p[P_DLM])
            k += w * _chain_stiffness(e, p[P_M], p[P_DLM])
        g = s - p[P_K] * (puller - x)
        if g > 0.0:
            hi = min(hi, x)
        else:
            lo = max(lo, x)
        x_new = x - g / k
        if not (lo < x_new < hi):  # FENE walls: stay inside the bracket
            x_new = 0.5 * (lo + hi) if (lo > -np.inf and hi < np.inf) else x - 0.5 * g / k
        if abs(x_new - x) <= 1e-15 * max(abs(x), p[P_DLM]):
            return x_new
        x = x_new
    return x


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


def advance(
    t,
    t_end,
    x,
    v,
    h,
    puller0,
    vp,
    t0,
    block,
    n,
    xb,
    tb,
    lw,
    lw_new,
    rate0,
    lc,
    aa,
    acc,
    p,
    rtol,
    h_max,
    sample_times,
    sample_index,
    out,
    out_max,
    stick_velocity,
    max_steps,
):  # type: ignore[no-untyped-def]
    """Integrate from t to t_end (one protocol piece).  Returns (status, t, x, v, h, n, sample_index, rows).

    ``acc`` accumulates [born, broken, puller work, dissipation, steps, rejected].  Rows written to
    ``out`` (time, sigma, N, V, X, P, born, broken, work, dissipation, bond energy): every accepted step
    when ``sample_times`` is empty, else only at those times (the steps land on them exactly).
    ``block``: 1 for block control (vp is the puller's velocity), 0 for velocity control (v = vp).
    """
    big = p[P_N0]
    rows = 0
    steps = 0
    n_samples = sample_times.shape[0]
    while t < t_end:
        if steps >= max_steps:
            return STEPS, t, x, v, h, n, sample_index, rows
        if n + 1 >= xb.shape[0]:
            return FULL, t, x, v, h, n, sample_index, rows
        hh = min(h, h_max, t_end - t)
        landing = False
        if sample_index < n_samples and t + hh >= sample_times[sample_index]:
            hh = sample_times[sample_index] - t
            landing = True
        if t_end - t - hh <= 1e-12 * max(t_end, 1.0):
            hh = t_end - t
        if hh <= 0.0:
            hh = t_end - t
        # ---- stage 1 at t, and the Euler predictor
        if block == 0:
            v0 = vp
        else:
            v0 = v
        nn0 = 0.0
        s0 = 0.0
        slope0 = _aging_factor(v0, p)
        for i in range(n):
            e = x - xb[i]
            lr = _log_rate(e, t - tb[i], slope0, p)
            r0 = math.exp(min(lr, LOG_RATE_CAP))
            rate0[i] = r0
            lw_new[i] = lw[i] - hh * r0
            w = math.exp(lw[i])
            nn0 += w
            if lr < np.inf:
                s0 += w * _chain_force(e, p[P_M], p[P_DLM])
        t1 = t + hh
        x_pred = x + hh * v0
        if block == 1:
            vp_end = vp
            v1 = _slider_velocity(v0, vp_end, n, xb, tb, lw_new, x_pred, t1, p, lc, aa)
        else:
            v1 = vp
        x1 = x + 0.5 * hh * (v0 + v1)
        # ---- corrector (trapezoid) with one re-evaluation of V at the corrected state
        err_s = 0.0
        err_n = 0.0
        broken = 0.0
        dissip = 0.0
        nn1 = 0.0
        s1 = 0.0
        k1 = 0.0
        x_half = 0.5 * (x + x1)
        slope1 = _aging_factor(v1, p)
        for i in range(n):
            e1 = x1 - xb[i]
            lr = _log_rate(e1, t1 - tb[i], slope1, p)
            r1 = math.exp(min(lr, LOG_RATE_CAP))
            new = lw[i] - 0.5 * hh * (rate0[i] + r1)
            w_old = math.exp(lw[i])
            w_eul = math.exp(lw_new[i])
            if lr == np.inf:
                f1 = 0.0
                w_new = 0.0
                new = -np.inf
                u_mid = _chain_energy(x - xb[i], p[P_M], p[P_DLM]) if abs(x - xb[i]) < p[P_DLM] else 0.0
            else:
                w_new = math.exp(new)
                f1 = _chain_force(e1, p[P_M], p[P_DLM])
                u_mid = _chain_energy(x_half - xb[i], p[P_M], p[P_DLM]) if w_old > w_new else 0.0
                nn1 += w_new
                s1 += w_new * f1
                k1 += w_new * _chain_stiffness(e1, p[P_M], p[P_DLM])
            dw = abs(w_new - w_eul)
            err_s += abs(f1) * dw
            err_n += dw
            broken += w_old - w_new
            dissip += (w_old - w_new) * u_mid
            lw_new[i] = new
            rate0[i] = r1  # kept for the merging of quiet cohorts after the step
        if block == 1:  # put the slider where the bonds balance the block exactly (sigma = K (P - X))
            x1 = _balance_position(x1, puller0 + vp * (t1 - t0), n, xb, lw_new, p)
            v1 = _slider_velocity(v1, vp, n, xb, tb, lw_new, x1, t1, p, lc, aa)
        # births: the vacancy Q = N0 - N relaxes at 1/tau and is refilled by the breakage of this step
        q0 = big - nn0
        decay = math.exp(-hh / p[P_TAU])
        loss_rate = broken / hh
        q1 = q0 * decay + loss_rate * p[P_TAU] * (1.0 - decay)
        born = q0 - q1 + broken
        if born < 0.0:
            born = 0.0
        # the newborn cohort, born mid-step; its hazard over the half step it has lived
        x_mid = 0.5 * (x + x1)
        lr_new = _log_rate(x1 - x_mid, 0.5 * hh, _aging_factor(v1, p), p)
        survive = math.exp(-0.5 * hh * math.exp(min(lr_new, LOG_RATE_CAP)))
        born_alive = born * survive
        if block == 1:
            nn1, s1, k1, _u1 = _sums(n, xb, lw_new, x1, p)
        s_ref = max(abs(s1), abs(s0), 1e-9 * p[P_M] * p[P_N0] * p[P_DLM])
        err_s += k1 * abs(x1 - x_pred)
        # a lumped newborn cohort is wrong by about its mass times the fraction of tau the step spans
        err_n += born * min(1.0, hh * math.exp(p[P_LOG_U0_TAU]))
        err = max(err_s / (rtol * s_ref), err_n / (rtol * big))
        if not (err <= 1.0) and hh > 1e-15 * max(t, p[P_TAU]):
            acc[5] += 1.0
            factor = 0.9 / math.sqrt(err) if err == err else 0.1
            h = hh * max(0.1, min(0.5, factor))
            continue
        # ---- accept
        for i in range(n):
            lw[i] = lw_new[i]
        xb[n] = x_mid
        tb[n] = t + 0.5 * hh
        lw[n] = math.log(born_alive) if born_alive > 0.0 else -np.inf
        n += 1
        broken += born - born_alive
        dissip += 0.0  # a newborn chain breaking in its first half step carries no energy to first order
        acc[0] += born
        acc[1] += broken
        if block == 1:
            s_new_block = p[P_K] * (puller0 + vp * (t1 - t0) - x1)
            acc[2] += 0.5 * (p[P_K] * (puller0 + vp * (t - t0) - x) + s_new_block) * vp * hh
        else:
            acc[2] += 0.5 * (s0 + s1) * vp * hh
        acc[3] += dissip
        acc[4] += 1.0
        t = t1
        x = x1
        v = v1
        steps += 1
        # drop dead cohorts (their weight counts as broken already, up to LIGHTEST * N0), and merge
        # neighbours that are quiet (negligible breakage for the rest of the piece) and born at nearly the
        # same slider position: the merged cohort keeps the weight and the mean extension, so the stress
        # changes only through the FENE curvature, by far less than rtol
        quiet = 1e-3 * rtol / max(t_end - t, 1.0)
        gap = 1e-4 * math.sqrt(rtol) * p[P_DLM]
        keep = 0
        for i in range(n):
            if lw[i] > math.log(LIGHTEST * big):
                if (
                    keep > 0
                    and rate0[i] < quiet
                    and rate0[keep - 1] < quiet
                    and abs(xb[i] - xb[keep - 1]) < gap
                    and i < n - 1
                ):
                    wa = math.exp(lw[keep - 1])
                    wb = math.exp(lw[i])
                    wt = wa + wb
                    xb[keep - 1] = (wa * xb[keep - 1] + wb * xb[i]) / wt
                    tb[keep - 1] = (wa * tb[keep - 1] + wb * tb[i]) / wt
                    lw[keep - 1] = math.log(wt)
                    rate0[keep - 1] = max(rate0[keep - 1], rate0[i])
                    continue
                xb[keep] = xb[i]
                tb[keep] = tb[i]
                lw[keep] = lw[i]
                rate0[keep] = rate0[i]
                keep += 1
            else:
                w = math.exp(lw[i])
                acc[1] += w
                acc[3] += w * _chain_energy(x - xb[i], p[P_M], p[P_DLM]) if abs(x - xb[i]) < p[P_DLM] else 0.0
        n = keep
        factor = 0.9 / math.sqrt(max(err, 1e-10))
        h = min(hh * min(4.0, max(0.2, factor)), h_max) if not landing else max(h, hh)
        record = n_samples == 0
        if landing:
            sample_index += 1
            record = True
        if record and rows < out_max:
            nn, ss, _kk, uu = _sums(n, xb, lw, x, p)
            out[rows, 0] = t
            out[rows, 1] = ss
            out[rows, 2] = nn
            out[rows, 3] = v
            out[rows, 4] = x
            out[rows, 5] = puller0 + vp * (t - t0) if block == 1 else x
            out[rows, 6] = acc[0]
            out[rows, 7] = acc[1]
            out[rows, 8] = acc[2]
            out[rows, 9] = acc[3]
            out[rows, 10] = uu
            rows += 1
            if rows >= out_max:
                return STEPS, t, x, v, h, n, sample_index, rows
        if stick_velocity > 0.0 and block == 1 and v < stick_velocity:
            return STICK, t, x, v, h, n, sample_index, rows
    return DONE, t, x, v, h, n, sample_index, rows


_COMPILED: dict[str, object] = {}


def compiled() -> dict[str, object]:
    """The numba-compiled kernel functions (compiled on first use, cached on disk)."""
    if not _COMPILED:
        g = globals()
        # compile helpers first so that the jitted callers bind to jitted callees
        for name in ("_chain_force", "_chain_stiffness", "_chain_energy", "_aging_factor", "_log_rate"):
            g[name] = _jit(g[name])
        for name in (
            "_velocity_prepare",
            "_velocity_residual",
            "_slider_velocity",
            "_balance_position",
            "_sums",
            "advance",
        ):
            g[name] = _jit(g[name])
            _COMPILED[name] = g[name]
    return _COMPILED
