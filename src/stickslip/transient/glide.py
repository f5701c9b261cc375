"""The reduced ODE of a glide (:func:`stickslip.transient.reduction.glide`), integrated by scipy's DOP853, compiled.

A glide follows the slider on the first-order slow manifold: y = (V, births, puller work, dissipation), dV/dt from
S_eff of the Chebyshev tables, the other three quadratures along (docs/transient.md section 9).  Through
:func:`scipy.integrate.solve_ivp` each of the ~50 DOP853 steps a cycle takes cost ~0.7 ms, two thirds of it the
solver's own array overhead around a right-hand side of four numbers (issue 31).  Here the same method runs in
numba: the Dormand-Prince 8(5,3) tableau of scipy (``numerics.dop853``'s copy), scipy's initial step (Hairer et al.
II.4), step-size control, terminal events (a sign change of the event at a step's end, its root by Brent's method
on the step's 7th-order dense output, xtol = rtol = 4 eps, as ``solve_ivp``), and the dense output (scipy's
``Dop853DenseOutput`` evaluated as :class:`Solution`).  The right-hand side and the events are the reduction's
(:func:`stickslip.transient.reduction.effective`, ``allowed_neglect``) on the tables' stacked coefficients, with
the same operations in the same order; the sums of the stages are plain loops where scipy calls ``np.dot``, so the
two agree to rounding, not to the bit (tests/test_transient_glide.py compares them on the paper's cycle).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..numerics import dop853 as _tableau
from ..numerics.first_compile import announce_if_uncached
from . import kernel

#: the tableau (scipy's ``dop853_coefficients``): 12 stages, 3 more for the dense output, 7 interpolant powers
_A = np.array(_tableau._A)
_B = np.array(_tableau._B)
_C = np.array(_tableau._C)
_E3 = np.array(_tableau._E3)
_E5 = np.array(_tableau._E5)
_D = np.array(_tableau._D)
N_STAGES = 12
N_STAGES_EXTENDED = 16
POWERS = 7
#: status codes, as solve_ivp's: 0 reached t_end, 1 a terminal event, -1 a step below its floor
DONE, EVENT, FAILED = 0, 1, -1


def _table(stack, off, scl, v):  # type: ignore[no-untyped-def]
    """(S, dS/dlnV, d2S/dlnV2, C, dC/dlnV, N/N0) at velocity v: Manifold.at's Clenshaw recurrence."""
    return _chebval(stack, off + scl * math.log(v))


def _effective(stack, off, scl, v, vp, k_block, cap_off):  # type: ignore[no-untyped-def]
    """reduction.effective: (S_eff, dV/dt, neglected stress, S') at v."""
    t = _table(stack, off, scl, v)
    s, sx, sxx, c, cx = t[0], t[1], t[2], t[3], t[4]
    s1 = sx / v
    s2 = (sxx - sx) / (v * v)
    c1 = cx / v
    a0 = k_block * (vp - v) / s1
    da0 = -k_block / s1 - k_block * (vp - v) * s2 / (s1 * s1)
    s_eff = s + c * a0
    ds_eff = s1 + c1 * a0 + c * da0
    if not ds_eff > 0.0:
        return s_eff, 0.0, cap_off, s1
    a1 = k_block * (vp - v) / ds_eff
    neglected = abs(c * (a1 - a0)) + abs(c * c / s1 * a1 * da0)
    return s_eff, a1, min(neglected, cap_off), s1


def _rhs(stack, off, scl, y0, lo, hi, vp, k_block, block, n0, tau, cap_off, out):  # type: ignore[no-untyped-def]
    """The glide's right-hand side into ``out`` (reduction.glide's ``rhs``)."""
    vv = min(max(y0, lo), hi)  # a trial stage may overshoot; the events end the stretch at the edges
    table = _table(stack, off, scl, vv)
    if block:
        s_eff, a1, _n, _s1 = _effective(stack, off, scl, vv, vp, k_block, cap_off)
    else:
        s_eff, a1 = table[0], 0.0
    out[0] = a1
    out[1] = (n0 - n0 * table[5]) / tau
    out[2] = s_eff * vp
    out[3] = s_eff * vv


def _event(which, stack, off, scl, y0, lo, hi, vp, k_block, tol, cap, cap_off):  # type: ignore[no-untyped-def]
    """reduction.glide's events: 0 off_manifold (the neglected stress past its allowance), 1 off_table."""
    if which == 1:
        return min(y0 / lo - 1.0 - 1e-6, 1.0 - 1e-6 - y0 / hi)
    vv = min(max(y0, lo), hi)
    s_eff, _a, neglected, slope = _effective(stack, off, scl, vv, vp, k_block, cap_off)
    return neglected - _allowance(slope, vv, vp, s_eff, tol, cap)


def _allowance(slope, v, vp, sigma, tol, cap):  # type: ignore[no-untyped-def]
    """The neglected stress a stretch may carry at v: tol |sigma|, or tol S'|Vp - V| up to cap times more
    (reduction.allowed_neglect, which says why)."""
    return tol * max(abs(sigma), min(abs(slope * (vp - v)), cap * abs(sigma)))


def _dense_at(f, y_old, x, component):  # type: ignore[no-untyped-def]
    """One component of a step's dense output at the fraction x (scipy's Dop853DenseOutput)."""
    y = 0.0
    for i in range(POWERS):
        y += f[POWERS - 1 - i, component]
        if i % 2 == 0:
            y *= x
        else:
            y *= 1.0 - x
    return y + y_old


def _event_root(which, f, y_old, t_old, h, ta, tb, stack, off, scl, lo, hi, vp, k_block, tol, cap, cap_off):  # type: ignore[no-untyped-def]
    """The event's root in [ta, tb] on the step's dense output: scipy's brentq (xtol = rtol = 4 eps)."""
    eps4 = 4.0 * 2.220446049250313e-16
    xpre, xcur = ta, tb
    fpre = _event(which, stack, off, scl, _dense_at(f, y_old, (xpre - t_old) / h, 0), lo, hi, vp, k_block, tol, cap,
                  cap_off)  # fmt: skip
    fcur = _event(which, stack, off, scl, _dense_at(f, y_old, (xcur - t_old) / h, 0), lo, hi, vp, k_block, tol, cap,
                  cap_off)  # fmt: skip
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    xblk = fblk = spre = scur = 0.0
    for _ in range(100):
        if fpre != 0.0 and fcur != 0.0 and (fpre < 0.0) != (fcur < 0.0):
            xblk = xpre
            fblk = fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre = xcur
            xcur = xblk
            xblk = xpre
            fpre = fcur
            fcur = fblk
            fblk = fpre
        delta = (eps4 + eps4 * abs(xcur)) / 2.0
        sbis = (xblk - xcur) / 2.0
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - delta):
                spre = scur
                scur = stry
            else:
                spre = sbis
                scur = sbis
        else:
            spre = sbis
            scur = sbis
        xpre = xcur
        fpre = fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0.0 else -delta
        fcur = _event(which, stack, off, scl, _dense_at(f, y_old, (xcur - t_old) / h, 0), lo, hi, vp, k_block, tol,
                      cap, cap_off)  # fmt: skip
    return xcur


def _stage(k, a, s, y, h, n, stage):  # type: ignore[no-untyped-def]
    """The state where stage s is evaluated, y + h sum_j a[s, j] k_j over the stages before it, into ``stage``
    (scipy's ``np.dot(K[:s].T, a[:s]) * h``)."""
    for i in range(n):
        acc = 0.0
        for j in range(s):
            acc += k[j, i] * a[s, j]
        stage[i] = y[i] + acc * h


def _squares(x, n):  # type: ignore[no-untyped-def]
    total = 0.0
    for i in range(n):
        total += x[i] * x[i]
    return total


def _scaled_norm(x, y, atol, rtol, m):  # type: ignore[no-untyped-def]
    """scipy's RMS norm of x / (atol + rtol |y|) over the first m components (one: the plain ratio)."""
    if m == 1:
        return abs(x[0]) / (atol[0] + abs(y[0]) * rtol)
    total = 0.0
    for i in range(m):
        ratio = x[i] / (atol[i] + abs(y[i]) * rtol)
        total += ratio * ratio
    return math.sqrt(total) / math.sqrt(m)


def _select_initial_step(  # type: ignore[no-untyped-def]
    stack, off, scl, lo, hi, vp, k_block, block, n0, tau, cap_off, t0, t_end, y, f, rtol, atol, m
):  # fmt: skip
    """scipy's select_initial_step (order 7, Hairer et al. II.4), its norms over the first m components."""
    interval = abs(t_end - t0)
    d0 = _scaled_norm(y, y, atol, rtol, m)
    d1 = _scaled_norm(f, y, atol, rtol, m)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, interval)
    f1 = np.empty(y.shape[0])
    _rhs(stack, off, scl, y[0] + h0 * f[0], lo, hi, vp, k_block, block, n0, tau, cap_off, f1)  # (V alone matters)
    d2 = _scaled_norm(f1 - f, y, atol, rtol, m) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1, interval)


def first_step(stack, off, scl, lo, hi, vp, k_block, block, n0, tau, cap_off, t0, t_end, v, rtol, atol_v):  # type: ignore[no-untyped-def]
    """scipy's initial step (select_initial_step, order 7) judged on the velocity alone.

    The other three components are quadratures that start at 0 with tiny atol (births, work, dissipation):
    counted, they made the heuristic's first step 10 ulp of t, and the solver then spent ~14 of a glide's ~22
    steps growing it tenfold per step to the velocity's own scale.  Where the velocity does not change (velocity
    control), the quadratures are linear in time and the whole stretch is one exact step."""
    y = np.zeros(4)
    y[0] = v
    f = np.empty(4)
    _rhs(stack, off, scl, v, lo, hi, vp, k_block, block, n0, tau, cap_off, f)
    if f[0] == 0.0:
        return abs(t_end - t0)
    # np.int64(1), not 1: numba compiles a function once per literal argument (here 1, and 4 from integrate)
    return _select_initial_step(stack, off, scl, lo, hi, vp, k_block, block, n0, tau, cap_off, t0, t_end, y, f, rtol,
                                np.full(4, atol_v), np.int64(1))  # fmt: skip


def integrate(  # type: ignore[no-untyped-def]
    stack, off, scl, lo, hi, vp, k_block, block, n0, tau, tol, cap, cap_off, t0, t_end, y0, rtol, atol, h_first,
    a, b, c, e3, e5, d,
):  # fmt: skip
    """solve_ivp(rhs, (t0, t_end), y0, method="DOP853", rtol, atol, first_step=h_first (0: scipy's own),
    events=[off_manifold, off_table] if block, dense_output=True) of reduction.glide.  Returns (status, ts, ys,
    t_old, h, y_old, F): the accepted steps' ends (the last one the event's root where one ended the glide), the
    states there, and each step's dense output."""
    n = 4
    cap_steps = 64
    ts = np.empty(cap_steps + 1)
    ys = np.empty((cap_steps + 1, n))
    seg_t = np.empty(cap_steps)
    seg_h = np.empty(cap_steps)
    seg_y = np.empty((cap_steps, n))
    seg_f = np.empty((cap_steps, POWERS, n))
    k = np.empty((N_STAGES_EXTENDED, n))
    y = y0.copy()
    f = np.empty(n)
    _rhs(stack, off, scl, y[0], lo, hi, vp, k_block, block, n0, tau, cap_off, f)
    ts[0] = t0
    for i in range(n):  # element by element: a row assigned from an array compiles numba's shape-error message, ~7 s
        ys[0, i] = y[i]
    if h_first > 0.0:
        h_abs = h_first
    else:
        h_abs = _select_initial_step(stack, off, scl, lo, hi, vp, k_block, block, n0, tau, cap_off, t0, t_end, y, f,
                                     rtol, atol, np.int64(n))  # fmt: skip
    n_events = 2 if block else 0
    g = np.empty(2)
    for which in range(n_events):
        g[which] = _event(which, stack, off, scl, y[0], lo, hi, vp, k_block, tol, cap, cap_off)
    t = t0
    steps = 0
    status = DONE
    y_new = np.empty(n)
    f_new = np.empty(n)
    stage = np.empty(n)
    err5 = np.empty(n)
    err3 = np.empty(n)
    while t < t_end:
        # ---- one step (scipy's RungeKutta._step_impl with DOP853's error norm)
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        if h_abs < min_step:
            h_abs = min_step
        accepted = False
        rejected = False
        h = 0.0
        t_new = t
        while not accepted:
            if h_abs < min_step:
                status = FAILED
                break
            t_new = t + h_abs
            if t_new - t_end > 0.0:
                t_new = t_end
            h = t_new - t
            h_abs = abs(h)
            for i in range(n):
                k[0, i] = f[i]
            for s in range(1, N_STAGES):
                _stage(k, a, s, y, h, n, stage)
                _rhs(stack, off, scl, stage[0], lo, hi, vp, k_block, block, n0, tau, cap_off, k[s])
            for i in range(n):
                acc = 0.0
                for j in range(N_STAGES):
                    acc += k[j, i] * b[j]
                y_new[i] = y[i] + h * acc
            _rhs(stack, off, scl, y_new[0], lo, hi, vp, k_block, block, n0, tau, cap_off, f_new)
            for i in range(n):
                k[N_STAGES, i] = f_new[i]
            for i in range(n):
                sc = atol[i] + max(abs(y[i]), abs(y_new[i])) * rtol
                a5 = 0.0
                a3 = 0.0
                for j in range(N_STAGES + 1):
                    a5 += k[j, i] * e5[j]
                    a3 += k[j, i] * e3[j]
                err5[i] = a5 / sc
                err3[i] = a3 / sc
            e5n = _squares(err5, n)
            e3n = _squares(err3, n)
            if e5n == 0.0 and e3n == 0.0:
                error_norm = 0.0
            else:
                error_norm = abs(h) * e5n / math.sqrt((e5n + 0.01 * e3n) * n)
            if error_norm < 1.0:
                factor = 10.0 if error_norm == 0.0 else min(10.0, 0.9 * error_norm ** (-1.0 / 8.0))
                if rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                accepted = True
            else:
                factor = 0.9 * error_norm ** (-1.0 / 8.0)
                h_abs *= factor if factor > 0.2 else 0.2
                rejected = True
        if status == FAILED:
            break
        # ---- the step's dense output (scipy's DOP853._dense_output_impl)
        if steps >= cap_steps:
            cap_steps *= 2
            ts = _grown(ts, cap_steps + 1)
            ys = _grown(ys, cap_steps + 1)
            seg_t = _grown(seg_t, cap_steps)
            seg_h = _grown(seg_h, cap_steps)
            seg_y = _grown(seg_y, cap_steps)
            seg_f = _grown(seg_f, cap_steps)
        for s in range(N_STAGES + 1, N_STAGES_EXTENDED):
            _stage(k, a, s, y, h, n, stage)
            _rhs(stack, off, scl, stage[0], lo, hi, vp, k_block, block, n0, tau, cap_off, k[s])
        for i in range(n):
            delta = y_new[i] - y[i]
            seg_f[steps, 0, i] = delta
            seg_f[steps, 1, i] = h * k[0, i] - delta
            seg_f[steps, 2, i] = 2.0 * delta - h * (f_new[i] + k[0, i])
            for r in range(4):
                acc = 0.0
                for j in range(N_STAGES_EXTENDED):
                    acc += d[r, j] * k[j, i]
                seg_f[steps, 3 + r, i] = h * acc
            seg_y[steps, i] = y[i]
        seg_t[steps] = t
        seg_h[steps] = h
        t_end_step = t_new
        # ---- events: a sign change at the step's end, the earliest root ends the glide
        root = np.inf
        for which in range(n_events):
            g_new = _event(which, stack, off, scl, y_new[0], lo, hi, vp, k_block, tol, cap, cap_off)
            if (g[which] <= 0.0 and g_new >= 0.0) or (g[which] >= 0.0 and g_new <= 0.0):
                r = _event_root(which, seg_f[steps], seg_y[steps, 0], t, h, t, t_end_step, stack, off, scl, lo, hi,
                                vp, k_block, tol, cap, cap_off)  # fmt: skip
                root = min(root, r)
            g[which] = g_new
        steps += 1
        if root < np.inf:
            x = (root - t) / h
            for i in range(n):
                ys[steps, i] = _dense_at(seg_f[steps - 1], seg_y[steps - 1, i], x, i)
            ts[steps] = root
            status = EVENT
            break
        t = t_new
        for i in range(n):
            y[i] = y_new[i]
            f[i] = f_new[i]
            ys[steps, i] = y[i]
        ts[steps] = t
    return status, ts[: steps + 1], ys[: steps + 1], seg_t[:steps], seg_h[:steps], seg_y[:steps], seg_f[:steps]


def _grown(x, size):  # type: ignore[no-untyped-def]
    out = np.empty((size,) + x.shape[1:])  # noqa: RUF005 (numba: tuple concatenation, not unpacking)
    # element by element (both C-contiguous): a slice assigned from an array compiles numba's shape-mismatch
    # message, string formatting included, ~7 s of a cold first run
    src, dst = x.reshape(x.size), out.reshape(out.size)
    for i in range(x.size):
        dst[i] = src[i]
    return out


class Solution:
    """The glide's steps and dense output, as scipy's OdeSolution: ``t`` (the steps' ends), ``y`` (4 x steps+1),
    ``status``, and ``sol(times)`` (each time on the step it falls in, the first or last outside)."""

    def __init__(self, status: int, ts: np.ndarray, ys: np.ndarray, seg_t, seg_h, seg_y, seg_f) -> None:  # type: ignore[no-untyped-def]
        self.status = int(status)
        self.t = ts
        self.y = ys.T
        self._seg = (seg_t, seg_h, seg_y, seg_f)

    def sol(self, times):  # type: ignore[no-untyped-def]
        seg_t, seg_h, seg_y, seg_f = self._seg
        scalar = np.ndim(times) == 0
        tt = np.atleast_1d(np.asarray(times, float))
        ind = np.searchsorted(self.t, tt, side="left")
        seg = np.minimum(np.maximum(ind - 1, 0), seg_t.size - 1)
        x = ((tt - seg_t[seg]) / seg_h[seg])[:, None]
        y = np.zeros((tt.size, 4))
        f = seg_f[seg]
        for i in range(POWERS):
            y += f[:, POWERS - 1 - i, :]
            if i % 2 == 0:
                y *= x
            else:
                y *= 1 - x
        y += seg_y[seg]
        return y[0] if scalar else y.T


def stacked_chebval(stack, x):  # type: ignore[no-untyped-def]
    """numpy's ``chebval(x, stack)`` for a scalar x and stacked columns: the same Clenshaw recurrence, the same
    operations in the same order (so the same bits), compiled: numpy's call costs ~40 us, and the paper's cycle
    makes ~900 of them (a sixth of its CPU)."""
    size = stack.shape[0]
    if size == 1:
        return stack[0].copy()
    c0 = stack[size - 2].copy()
    c1 = stack[size - 1].copy()
    if size == 2:
        return c0 + c1 * x
    x2 = 2 * x
    for i in range(3, size + 1):
        tmp = c0
        c0 = stack[size - i] - c1
        c1 = tmp + c1 * x2
    return c0 + c1 * x


#: the compiled :func:`stacked_chebval`
_CLENSHAW: list = []


def clenshaw():  # type: ignore[no-untyped-def]
    if not _CLENSHAW:
        _CLENSHAW.append(kernel._jit(stacked_chebval))
    return _CLENSHAW[0]


#: the compiled functions (compiled on first use, cached on disk)
_COMPILED: dict[str, object] = {}
_chebval = None


def _compiled():  # type: ignore[no-untyped-def]
    if not _COMPILED:
        g = globals()
        g["_chebval"] = clenshaw()
        for name in ("_table", "_effective", "_allowance", "_event", "_rhs", "_grown"):
            g[name] = kernel._jit(g[name])
        for name in ("_dense_at", "_stage", "_squares", "_scaled_norm"):
            g[name] = kernel._jit(g[name], inline=True)
        for name in ("_event_root", "_select_initial_step", "first_step", "integrate"):
            g[name] = kernel._jit(g[name])
            _COMPILED[name] = g[name]
        announce_if_uncached(_COMPILED["integrate"], kernel.TRANSIENT_KERNELS)
    return _COMPILED


def solve(
    stack: np.ndarray,
    off: float,
    scl: float,
    *,
    lo: float,
    hi: float,
    vp: float,
    k_block: float,
    block: bool,
    n0: float,
    tau: float,
    tol: float,
    cap: float,
    cap_off: float,
    t0: float,
    t_end: float,
    y0: np.ndarray,
    rtol: float,
    atol: np.ndarray,
    h_first: float = 0.0,
) -> Solution:
    """The glide's ODE from t0 towards t_end (see :func:`integrate`)."""
    result = _compiled()["integrate"](
        stack, float(off), float(scl), lo, hi, vp, k_block, bool(block), n0, tau, tol, cap, cap_off, t0, t_end,
        np.asarray(y0, float), rtol, np.asarray(atol, float), h_first, _A, _B, _C, _E3, _E5, _D,
    )  # fmt: skip
    return Solution(*result)


def effective(
    stack: np.ndarray, off: float, scl: float, v: float, vp: float, k_block: float, cap_off: float
) -> tuple[float, float, float, float]:
    """(S_eff, dV/dt, neglected stress, S') at v on the tables' stacked series (reduction.effective's numbers)."""
    _compiled()
    return _effective(stack, off, scl, v, vp, k_block, cap_off)


def allowance(slope: float, v: float, vp: float, sigma: float, tol: float, cap: float) -> float:
    """The neglected stress a stretch may carry at v (reduction.allowed_neglect)."""
    _compiled()
    return _allowance(slope, v, vp, sigma, tol, cap)


def reference_field(
    stack: np.ndarray, off: float, scl: float, *, lo: float, hi: float, vp: float, k_block: float, block: bool,
    n0: float, tau: float, cap_off: float, tol: float, cap: float,
) -> tuple[Callable[[float, np.ndarray], np.ndarray], list[Callable[[float, np.ndarray], float]]]:  # fmt: skip
    """The glide's right-hand side and its terminal events (off the manifold, off the table; block only) as
    ``solve_ivp`` takes them: the reference that steps the same field by scipy."""
    _compiled()

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        out = np.empty(4)
        _rhs(stack, off, scl, y[0], lo, hi, vp, k_block, block, n0, tau, cap_off, out)
        return out

    def event(which: int) -> Callable[[float, np.ndarray], float]:
        def crossing(_t: float, y: np.ndarray) -> float:
            return _event(which, stack, off, scl, y[0], lo, hi, vp, k_block, tol, cap, cap_off)

        crossing.terminal = True  # type: ignore[attr-defined]
        return crossing

    return rhs, ([event(0), event(1)] if block else [])


def initial_step(
    stack: np.ndarray, off: float, scl: float, *, lo: float, hi: float, vp: float, k_block: float, block: bool,
    n0: float, tau: float, cap_off: float, t0: float, t_end: float, v: float, rtol: float, atol_v: float,
) -> float:  # fmt: skip
    """The glide's first step (see :func:`first_step`)."""
    return float(
        _compiled()["first_step"](
            stack,
            float(off),
            float(scl),
            lo,
            hi,
            vp,
            k_block,
            bool(block),
            n0,
            tau,
            cap_off,
            t0,
            t_end,
            v,
            rtol,
            atol_v,
        )
    )
