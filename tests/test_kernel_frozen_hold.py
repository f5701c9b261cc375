"""A slider at rest under velocity control (a hold): the cohorts whose breakage over a step is below 2^-60 of them
take the pass's short path, which keeps their weight, force, stiffness and energy and moves only their hazard
(kernel._cohort_pass, docs/transient.md section 27; round 32).

Reference: the same pass on the same population without the short path (nothing cached: every cohort through the
full computation), and _sums_keeping computing every value afresh.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import stickslip
from stickslip.transient import kernel as K
from stickslip.transient.cells import steady_cohorts
from stickslip.transient.model import pack_parameters

GEL = stickslip.load_parameters("gelatin-glass")
HOLD = 0.05  # s since the slider stopped: the steady population's oldest are frozen, its youngest are not


def _held_population(every: int = 2):
    """The steady population at 100 um/s with every ``every``-th cohort aged by HOLD (1: all of them)."""
    pop = steady_cohorts(GEL, 100e-6, True)
    order = np.argsort(-pop.age)
    xb = -pop.extension[order]
    tb = -pop.age[order] - HOLD * (np.arange(order.size) % every == 0)
    lw = np.log(pop.weight[order])
    return xb, tb, lw


def _pass(functions, p, xb, tb, lw, cache, cached, hh):
    n = xb.size
    size = n + 3
    lw_new, rate0, w1 = np.zeros(size), np.zeros(size), np.zeros(size)
    known = np.full((4, size), -1.0)
    known[3] = np.nan
    predicted = np.zeros((3, size))
    clock_end = np.full((2, size), np.nan)
    x, t = 0.0, 0.0
    slope = p[K.P_INV_TAU_A]  # the aging slope at rest
    sums = functions["_cohort_pass"](
        n, t, t + hh, -1.0, hh, x, x, x, 0.0, 0.0, slope, slope, 0.0, xb, tb, lw, lw_new, rate0, w1, known,
        predicted, cache, cached, clock_end, np.inf, True, np.inf, np.inf, np.zeros(8, np.int64),
        np.zeros(8, np.int64), p,
    )  # fmt: skip
    return sums, lw_new[:n], w1[:n], rate0[:n], predicted[:, :n], known[:, :n]


@pytest.mark.parametrize("every", [2, 1], ids=["half-aged", "all-aged"])
@pytest.mark.parametrize("hh", [1e-5, 3e-4, 5e-3])
def test_the_short_path_gives_what_the_full_pass_gives(hh, every):
    functions = K.compiled()
    p = pack_parameters(GEL, False, GEL.block.effective_stiffness)
    xb, tb, lw = _held_population(every)
    n = xb.size
    cache = np.empty((8, n + 3))
    unknown = np.full((4, n + 3), -1.0)
    unknown[3] = np.nan
    functions["_sums_keeping"](n, xb, tb, lw, 0.0, 0.0, p[K.P_INV_TAU_A], p, cache, unknown, False,
                               np.full((2, n + 3), np.nan), True, np.zeros(n + 3))  # fmt: skip
    frozen = cache[5, :n] * hh < K.FROZEN_HAZARD
    # both paths taken; aged alike, the frozen carry the whole of the rate sums, which then test the short path
    assert 0.1 * n < frozen.sum() < 0.9 * n if every > 1 else frozen.sum() >= 0.75 * n
    short = _pass(functions, p, xb, tb, lw, cache, True, hh)
    full = _pass(functions, p, xb, tb, lw, cache, False, hh)
    names = "nn0 s0 nn1 s1 loss0 loss1 dloss0 dloss1 broken dissip rate_s0 rate_s1 kint0 kint1 err_s err_n".split()
    for name, a, b in zip(names, short[0][:16], full[0][:16], strict=True):
        if name in ("err_s", "err_n"):  # the short path's bound on the breakage it does not book, 2^-60 at most
            assert a <= b + K.FROZEN_HAZARD * short[0][0] * 4.0, name
            continue
        assert a == pytest.approx(b, rel=1e-13, abs=1e-300), name
    lw_a, w_a, r_a, pred_a, known_a = short[1:]
    lw_b, w_b, r_b, pred_b, _ = full[1:]
    assert np.array_equal(lw_a[frozen], lw_b[frozen])  # the weight to the last bit
    assert np.array_equal(w_a[frozen], w_b[frozen])
    assert np.array_equal(r_a, r_b)  # the same hazard at the end, bit for bit
    assert np.array_equal(pred_a, pred_b, equal_nan=True)
    assert np.array_equal(known_a[1:, frozen], pred_a[:, frozen])  # what _sums_keeping reads next
    assert np.all(np.isnan(known_a[3, ~frozen]))


def test_the_row_after_a_frozen_step_is_the_fresh_computation():
    functions = K.compiled()
    p = pack_parameters(GEL, False, GEL.block.effective_stiffness)
    xb, tb, lw = _held_population()
    n = xb.size
    slope = p[K.P_INV_TAU_A]
    cache = np.empty((8, n + 3))
    fresh_known = np.full((4, n + 3), -1.0)
    fresh_known[3] = np.nan
    no_clock = np.full((2, n + 3), np.nan)
    functions["_sums_keeping"](
        n, xb, tb, lw, 0.0, 0.0, slope, p, cache, fresh_known, False, no_clock, True, np.zeros(n)
    )
    hh = 3e-4
    _sums, lw_new, _w, rate, _pred, known = _pass(functions, p, xb, tb, lw, cache, True, hh)
    known = np.concatenate([known, np.full((4, 3), np.nan)], axis=1)
    kept, again = np.empty((8, n + 3)), np.empty((8, n + 3))
    got = functions["_sums_keeping"](n, xb, tb, lw_new, 0.0, hh, slope, p, kept, known, False, no_clock, True, rate)
    plain = np.full((4, n + 3), -1.0)
    plain[3] = np.nan
    direct = functions["_sums_keeping"](
        n, xb, tb, lw_new, 0.0, hh, slope, p, again, plain, False, no_clock, False, np.zeros(n)
    )
    assert got == direct
    assert np.array_equal(kept[:6, :n], again[:6, :n])
    assert math.isfinite(got[1])
