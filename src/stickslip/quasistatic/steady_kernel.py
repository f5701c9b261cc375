"""The steady-state march (:func:`stickslip.quasistatic.steady._march`) compiled by numba, one velocity at a time.

The same panels, nodes and sums as the numpy march, lane by lane, so the two agree to rounding (~1e-15;
tests/test_steady_speed.py); :mod:`stickslip.quasistatic.steady` uses it for batches of ``COMPILED_LANES``
velocities or more, where it pays for loading numba, and for callers that repeat narrow calls (``compiled_from``:
fits, studies, the time-dependent solver; docs/steady-state.md).  Linear aging (the paper's) and the
saturating-aging extension alike.
"""

from __future__ import annotations

import math

import numpy as np

from ..numerics.first_compile import announce_if_uncached

#: status of a lane after the march
MARCHED, TOO_MANY_PANELS = 0, 1


#: exp(x) = 2^n e^r, n = round(x / ln 2), |r| <= ln(2)/2, with ln 2 split in two (Cody-Waite) so that r is exact
_LOG2E = 1.4426950408889634
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10
#: below this e^x would be subnormal (< 2.2e-308): taken as 0, which no sum of the march can tell apart
_EXP_FLOOR = -708.0


def _exp_into(values: np.ndarray, out: np.ndarray, bits: np.ndarray) -> None:
    """out = exp(values) (values <= 709), within ~1 ulp of libm's, in loops the compiler vectorises.

    numba calls libm's scalar exp (~5 ns; no vector math library here); the march spends ~40 % of its time in
    32 exponentials per panel.  Taylor series of degree 13 on |r| <= 0.347 (remainder < 4e-18) by Horner,
    times 2^n built in the exponent bits.
    """
    for k in range(values.size):
        v = max(values[k], _EXP_FLOOR)
        n = math.floor(v * _LOG2E + 0.5)
        r = (v - n * _LN2_HI) - n * _LN2_LO
        p = 1.0 / 6227020800.0
        p = p * r + 1.0 / 479001600.0
        p = p * r + 1.0 / 39916800.0
        p = p * r + 1.0 / 3628800.0
        p = p * r + 1.0 / 362880.0
        p = p * r + 1.0 / 40320.0
        p = p * r + 1.0 / 5040.0
        p = p * r + 1.0 / 720.0
        p = p * r + 1.0 / 120.0
        p = p * r + 1.0 / 24.0
        p = p * r + 1.0 / 6.0
        p = p * r + 0.5
        p = p * r + 1.0
        out[k] = p * r + 1.0
        bits[k] = (np.int64(n) + 1023) << 52
    scale = bits.view(np.float64)
    for k in range(values.size):
        out[k] = out[k] * scale[k] if values[k] >= _EXP_FLOOR else 0.0


def _aged(x: float, sat: float) -> float:
    """The scaled age the aging term sees (steady._aged): x, or (1 - e^(-x sat))/sat with saturation (sat > 0)."""
    return -math.expm1(-x * sat) / sat if sat > 0.0 else x


def _aged_rate(x: float, sat: float) -> float:
    """d(aged)/dx (steady._aged_rate): 1, or e^(-x sat) with saturation."""
    return math.exp(-x * sat) if sat > 0.0 else 1.0


def _ln_v_moment(x: float, sat: float, ratio: float) -> float:
    """m(x) of steady._ln_v_moment: x, or (ratio aged + x aged')/(1 + ratio) with saturation."""
    if sat > 0.0:
        return (ratio * _aged(x, sat) + x * _aged_rate(x, sat)) / (1.0 + ratio)
    return x


def _log_hazard(x: float, y: float, log_t: float, a: float, alpha: float, sat: float) -> tuple[float, float]:
    """L and |L'| at x (y = 1 - x), as steady._log_hazard_and_slope."""
    d = y * (1.0 + x)
    if sat > 0.0:
        return log_t + a * x / d - alpha * _aged(x, sat), abs(a * (1.0 + x * x) / (d * d) - alpha * _aged_rate(x, sat))
    return log_t + a * x / d - alpha * x, abs(a * (1.0 + x * x) / (d * d) - alpha)


def _good(
    log_w: float,
    x: float,
    y: float,
    log_t: float,
    a: float,
    alpha: float,
    sat: float,
    cap_resolved: float,
    cap_negligible: float,
    log_negligible: float,
    log_hazard_step: float,
    log_resolved: float,
) -> bool:
    """Is the panel [x, x + e^log_w] resolved or negligible (steady._panel_width's test)?"""
    w = math.exp(log_w)
    l_right, slope_right = _log_hazard(x + w, y - w, log_t, a, alpha, sat)
    log_integral = l_right + log_w
    resolved = log_w <= cap_resolved and slope_right * w <= log_hazard_step and log_integral <= log_resolved
    return resolved or (log_w <= cap_negligible and log_integral <= log_negligible)


def _width(
    x: float,
    y: float,
    log_t: float,
    a: float,
    alpha: float,
    sat: float,
    log_negligible: float,
    settings: np.ndarray,
    search: np.ndarray,
) -> tuple[float, bool]:
    """(width of the next panel, whether the survival steps to 0 here): steady._panel_width for one lane.

    ``log_negligible`` = ln(negligible_hazard) - ln(1 + beta), a constant of the lane.
    """
    log_hazard_step, end_ratio, widest_panel = settings[0], settings[2], settings[3]
    step_ulps, log_width_ratio, start_offset, first_reach, tiny, max_bisections = (
        search[0],
        search[1],
        search[2],
        search[3],
        search[4],
        int(search[5]),
    )
    log_widest = math.log(min(widest_panel, end_ratio * y))
    l_left, slope_left = _log_hazard(x, y, log_t, a, alpha, sat)
    log_slope_left = math.log(max(slope_left, tiny))
    log_step, log_resolved = settings[10], settings[11]
    cap_resolved = min(log_resolved - l_left, log_step - log_slope_left)
    cap_negligible = log_negligible - l_left
    if not (log_widest > cap_resolved and log_widest > cap_negligible):
        if _good(
            log_widest, x, y, log_t, a, alpha, sat, cap_resolved, cap_negligible, log_negligible, log_hazard_step,
            log_resolved,
        ):  # fmt: skip
            return math.exp(log_widest), False
    top = log_widest
    low = math.log(step_ulps * np.spacing(x if x < 0.5 else y))
    guess = min(max(cap_resolved - start_offset, low), top)
    found, confirmed, sure, reach = low, False, False, first_reach
    closed = False
    for _ in range(max_bisections):
        better = _good(
            guess, x, y, log_t, a, alpha, sat, cap_resolved, cap_negligible, log_negligible, log_hazard_step,
            log_resolved,
        )  # fmt: skip
        if better:
            low = guess
        else:
            top = guess
        sure = sure or better
        reach *= 2.0
        gap = top - low
        if not gap > log_width_ratio:
            found, confirmed, closed = low, sure, True
            break
        move = min(reach, 0.5 * gap)
        guess = low + move if sure else top - move
    if not closed:
        found, confirmed = low, sure
    step = False
    if not confirmed:
        step = not _good(
            found, x, y, log_t, a, alpha, sat, cap_resolved, cap_negligible, log_negligible, log_hazard_step,
            log_resolved,
        )  # fmt: skip
    return math.exp(found), step


def march(
    log_t: np.ndarray,
    a: np.ndarray,
    alpha: np.ndarray,
    beta: np.ndarray,
    sat: np.ndarray,
    ratio: np.ndarray,
    settings: np.ndarray,
    search: np.ndarray,
    t_half: np.ndarray,
    integrate: np.ndarray,
    weights: np.ndarray,
    out: np.ndarray,
) -> int:  # pragma: no cover - run compiled (numba), see compiled()
    """i, j, di/dlnV, dj/dlnV of every lane into out (4, n); returns MARCHED or TOO_MANY_PANELS.

    ``sat`` and ``ratio``: the saturating-aging extension's dl_m/(V t_s) and V/V_a per lane (sat 0: the paper's
    linear aging, ratio unused), as steady._Scales.

    ``settings``: log_hazard_step, hazard_step, end_ratio, widest_panel, negligible_hazard, hazard_cutoff,
    tail_tolerance, smallest gap, log cap, MAX_PANELS, ln log_hazard_step, ln hazard_step; ``search``:
    STEP_ULPS, ln WIDTH_RATIO, START_OFFSET, FIRST_REACH, _TINY, MAX_BISECTIONS, _CLIFF_LOG_HAZARD (steady.py).
    """
    order = t_half.size
    cutoff, tail_tolerance, smallest_gap, log_cap = settings[5], settings[6], settings[7], settings[8]
    max_panels = int(settings[9])
    tiny, cliff = search[4], search[6]
    h = np.empty(order)
    g = np.empty(order)
    stretch = np.empty(order)
    at = np.empty(order)
    aged = np.empty(order)
    weight = np.empty(order)
    exponent = np.empty(order)
    survivals = np.empty(order)
    bits = np.empty(order, dtype=np.int64)
    big_h_at = np.empty(order + 1)
    big_g_at = np.empty(order + 1)
    integrate_t = np.ascontiguousarray(integrate.T)  # (K, K+1)
    for p in range(log_t.size):
        lt, ap, al, be, sa, ra = log_t[p], a[p], alpha[p], beta[p], sat[p], ratio[p]
        log_negligible = math.log(settings[4]) - math.log1p(be)
        x_left, y_left, hazard, moment = 0.0, 1.0, 0.0, 0.0
        s0, s1, s2, s3 = 0.0, 0.0, 0.0, 0.0
        finished = False
        for _ in range(max_panels):
            w, step = _width(x_left, y_left, lt, ap, al, sa, log_negligible, settings, search)
            if step:
                # the survival steps to 0 within a few ulps; where it lies moves with V (steady._march)
                d = y_left * (1.0 + x_left)
                rise = ap * (1.0 + x_left * x_left) / (d * d) - al * _aged_rate(x_left, sa)
                shift = math.exp(-hazard) * (be * _ln_v_moment(x_left, sa, ra) - 1.0) / rise
                s2 += shift
                s3 += shift * (x_left / d)
                finished = True
                break
            half = 0.5 * w
            for k in range(order):
                offset = t_half[k] * w
                x = offset + x_left
                y = y_left - offset
                stretch[k] = x / ((1.0 + x) * y)
                at[k] = x
            # the scaled age the aging term sees and the ln V moment's weight: x for the paper's linear aging; the
            # saturating extension's apart, so that the loops the compiler vectorises have no branch
            if sa > 0.0:
                for k in range(order):
                    aged[k] = _aged(at[k], sa)
                    weight[k] = _ln_v_moment(at[k], sa, ra)
            else:
                for k in range(order):
                    aged[k] = at[k]
                    weight[k] = at[k]
            for k in range(order):
                exponent[k] = min(stretch[k] * ap - aged[k] * al + lt, log_cap)
            _exp_into(exponent, h, bits)
            for k in range(order):
                h[k] *= half
                g[k] = weight[k] * h[k]
            # H and G at the nodes and over the panel: columns of the integration matrix accumulated one node at
            # a time (independent rows: the compiler vectorises this without reordering any sum)
            for m in range(order + 1):
                big_h_at[m] = 0.0
                big_g_at[m] = 0.0
            for k in range(order):
                hk, gk = h[k], g[k]
                for m in range(order + 1):
                    big_h_at[m] += integrate_t[k, m] * hk
                    big_g_at[m] += integrate_t[k, m] * gk
            for m in range(order):
                exponent[m] = -(big_h_at[m] + hazard)
            _exp_into(exponent, survivals, bits)
            for m in range(order):
                big_h = big_h_at[m] + hazard
                d_hazard = (big_g_at[m] + moment) * be - big_h
                survival = survivals[m] * weights[m] * half
                weighted = survival * stretch[m]
                s0 += survival
                s1 += weighted
                s2 += survival * d_hazard
                s3 += weighted * d_hazard
            total_h, total_g = big_h_at[order], big_g_at[order]
            hazard += total_h
            moment += total_g
            x_left += w
            y_left -= w
            if y_left <= smallest_gap:
                finished = True
                break
            if hazard >= cutoff:
                # steady._tail_negligible
                y_c = min(y_left, max(ap, tiny) / (3.0 * (al + abs(lt) + cliff)))
                room_i = math.log(max(tail_tolerance * s0, tiny)) - math.log(y_left)
                room_j = math.log(max(tail_tolerance * s1, tiny)) - math.log(0.5 * math.log(1.0 / y_c) + 1.0)
                if -hazard <= min(room_i, room_j):
                    finished = True
                    break
        if not finished:
            return TOO_MANY_PANELS
        out[0, p], out[1, p], out[2, p], out[3, p] = s0, s1, -s2, -s3
    return MARCHED


#: reassociation and fused multiply-adds only (no assumptions about inf or NaN, which the march meets)
_FAST = {"reassoc", "contract"}

_COMPILED: list = []


def compiled():  # type: ignore[no-untyped-def]
    """:func:`march` compiled by numba (on first use; cached on disk, so later processes only load it)."""
    if not _COMPILED:
        from numba import njit

        g = globals()
        for name in (
            "_exp_into",
            "_aged",
            "_aged_rate",
            "_ln_v_moment",
            "_log_hazard",
            "_good",
            "_width",
        ):  # callees first, so that the callers bind to them
            g[name] = njit(cache=True, nogil=True, fastmath=_FAST)(g[name])
        _COMPILED.append(njit(cache=True, nogil=True, fastmath=_FAST)(march))
        announce_if_uncached(_COMPILED[0], "the steady curve's kernel")
    return _COMPILED[0]
