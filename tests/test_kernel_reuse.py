"""The cohort kernel's reuse of values it already has (issue 21, one cycle <= 0.5 s): bit for bit the same numbers.

The kernel keeps, from the row it records after a step, each cohort's weight, force, stiffness, energy and hazard
for the start of the next step, reuses the weights it computed as exp(new log weight) and the slider balance's
force and stiffness, and starts the slider's Newton iteration from a residual already evaluated.  Each shortcut
must give exactly what the direct formula gives (the plain cohort solver's results do not move at all).
"""

from __future__ import annotations

import math

import numpy as np

import stickslip
from stickslip.transient import kernel as K
from stickslip.transient.cells import steady_cohorts
from stickslip.transient.model import pack_parameters

GEL = stickslip.load_parameters("gelatin-glass")


def _population(velocity: float = 128e-6):
    """A steady population at ``velocity`` as the kernel holds it (oldest first), slider at 0."""
    pop = steady_cohorts(GEL, velocity, True)
    order = np.argsort(-pop.age)
    xb = -pop.extension[order]
    tb = -pop.age[order]
    lw = np.log(pop.weight[order])
    return xb, tb, lw


def test_row_sums_keep_exactly_what_the_next_step_computes():
    functions = K.compiled()
    p = pack_parameters(GEL, True, GEL.block.effective_stiffness)
    xb, tb, lw = _population()
    n = xb.size
    x, t, v = 2e-9, 1e-6, 128e-6
    slope = math.exp(-v / p[K.P_VA]) * p[K.P_INV_TAU_A]
    cache = np.empty((6, n))
    unknown = np.full((3, n), -1.0)
    no_clock = np.full((2, n), np.nan)  # the saturating clock at t, not known (the paper's aging has none)
    nn, ss, uu, ok = functions["_sums_keeping"](
        n, xb, tb, lw, x, t, slope, p, cache, unknown, False, no_clock, False, np.zeros(n)
    )
    assert ok
    direct_n, direct_sigma, _k, direct_energy = functions["_sums"](n, xb, lw, x, p)
    assert (nn, ss, uu) == (direct_n, direct_sigma, direct_energy)
    e = x - xb
    y = e / p[K.P_DLM]
    force = p[K.P_M] * e / (1.0 - y * y)
    log_rate = np.minimum(p[K.P_LOG_U0_TAU] + p[K.P_FORCE_SENS] * np.abs(force) - (t - tb) * slope, K.LOG_RATE_CAP)
    assert np.array_equal(cache[0], [math.exp(q) for q in lw])  # libm's exp, as the kernel
    assert np.array_equal(cache[1], force)
    assert np.array_equal(cache[2], p[K.P_M] * (1.0 + y * y) / ((1.0 - y * y) * (1.0 - y * y)))
    half_m_dlm2 = 0.5 * p[K.P_M] * p[K.P_DLM] * p[K.P_DLM]
    assert np.array_equal(cache[3], [-half_m_dlm2 * math.log1p(-q * q) for q in y])
    assert np.array_equal(cache[4], log_rate)
    assert np.array_equal(cache[5], [math.exp(q) for q in log_rate])
    # the slider balance's force and stiffness, when given, are the same numbers
    lc, aa = np.empty(n), np.empty(n)
    known = np.full((4, n), -1.0)
    known[3] = np.nan  # no bond energy carried from a step's pass (kernel._energy_at_end): computed
    functions["_velocity_prepare"](n, xb, tb, lw, x, t, p, lc, aa, known, no_clock)
    again = np.empty((6, n))
    assert functions["_sums_keeping"](
        n, xb, tb, lw, x, t, slope, p, again, known, True, no_clock, False, np.zeros(n)
    ) == (
        nn,
        ss,
        uu,
        True,
    )
    assert np.array_equal(again, cache)


def test_a_dead_cohort_keeps_nothing():
    functions = K.compiled()
    p = pack_parameters(GEL, True, GEL.block.effective_stiffness)
    xb, tb, lw = _population()
    lw[3] = -np.inf
    n = xb.size
    *_sums, ok = functions["_sums_keeping"](
        n,
        xb,
        tb,
        lw,
        0.0,
        0.0,
        0.0,
        p,
        np.empty((6, n)),
        np.full((3, n), -1.0),
        False,
        np.full((2, n), np.nan),
        False,
        np.zeros(n),
    )
    assert not ok


def test_slider_velocity_does_not_depend_on_the_weights_given():
    functions = K.compiled()
    p = pack_parameters(GEL, True, GEL.block.effective_stiffness)
    xb, tb, lw = _population()
    n = xb.size
    args = (1.3e-4, 1e-4, n, xb, tb, lw, 1e-9, 0.0, p, np.empty(n), np.empty(n))
    blind = functions["_slider_velocity"](*args, np.full((3, n), -1.0))
    given = np.full((3, n), -1.0)
    given[0] = [math.exp(q) for q in lw]
    assert functions["_slider_velocity"](*args, given) == blind
    assert 0.0 < blind < 1e-2


def test_the_balanced_ends_energy_from_the_predicted_ends_is_the_direct_one_to_rounding():
    """kernel._energy_at_end: u(x1) from u(x1p) by the end-corrected trapezoid of the force, against the direct
    -m dl_m^2/2 ln(1 - y^2) (math.log1p), for shifts up to ENERGY_SHIFT dl_m over a steady population (its
    extensions from 2e-4 to 0.87 dl_m); a longer shift, a cohort without the pass's energy or force: nan."""
    K.compiled()
    p = pack_parameters(GEL, True, GEL.block.effective_stiffness)
    xb, _tb, _lw = _population()
    n = xb.size
    m, dlm = p[K.P_M], p[K.P_DLM]
    x1p = 0.0
    e1p = x1p - xb
    assert np.max(np.abs(e1p)) / dlm > 0.85

    def force(e):
        return m * e / (1.0 - (e / dlm) ** 2)

    def stiffness(e):
        y = e / dlm
        return m * (1.0 + y * y) / (1.0 - y * y) ** 2

    def energy(e):
        return np.array([-0.5 * m * dlm * dlm * math.log1p(-((q / dlm) ** 2)) for q in e])

    predicted = np.vstack([force(e1p), stiffness(e1p), energy(e1p)])
    predicted[2, 3] = np.nan  # a cohort the pass left without its energy
    for share in (-1.0, -1e-3, 1e-2, 0.3, 1.0):
        shift = share * K.ENERGY_SHIFT * dlm
        e1 = e1p + shift
        known = np.vstack([np.ones(n), force(e1), stiffness(e1), np.zeros(n)])
        known[1, 5] = np.nan  # a cohort without the balance's force
        K._energy_at_end(n, shift, predicted, known, dlm)  # compiled by K.compiled(), as the kernel calls it
        direct = energy(e1)
        ok = np.ones(n, dtype=bool)
        ok[[3, 5]] = False
        assert np.all(np.isnan(known[3, ~ok]))
        worst = np.max(np.abs(known[3, ok] - direct[ok]) / direct[ok])
        assert worst <= 1e-14
    beyond = np.vstack([np.ones(n), force(e1p), stiffness(e1p), np.zeros(n)])
    K._energy_at_end(n, 1.5 * K.ENERGY_SHIFT * dlm, predicted, beyond, dlm)
    assert np.all(np.isnan(beyond[3]))
