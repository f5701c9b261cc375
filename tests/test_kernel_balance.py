"""The massless block's balance (kernel ``_balance_from``) stops where Newton's own correction is within its
tolerance: the root in at most two passes over the cohorts, within a few ulp of an extended-precision bisection.

Started within an ulp or two of the root (where each step of the cycle starts it: the predicted end, corrected
once), Newton's correction rounded to nothing, the new point fell on the bracket's edge, and the bracket's
fallback bisected some 16 more passes down to the tolerance (docs/transient.md section 14).
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
SLIDER = 1.75e-3  # m: where the paper's cycle has its slider after 5 s at 350 um/s


def _population(velocity: float):
    """Weights and birth positions of the steady population at ``velocity`` with the slider at SLIDER."""
    pop = steady_cohorts(GEL, velocity, True)
    return np.asarray(pop.weight, float), SLIDER - np.asarray(pop.extension, float)


def _residual_long(x, puller, w, xb, p):  # type: ignore[no-untyped-def]
    """g(x) = sum w f(x - x_b) - K (puller - x) in extended precision (x87 long double where numpy has it)."""
    ld = np.longdouble
    e = ld(x) - xb.astype(ld)
    y = e / ld(p[K.P_DLM])
    force = ld(p[K.P_M]) * e / (ld(1) - y * y)
    return float(np.sum(w.astype(ld) * force) - ld(p[K.P_K]) * (ld(puller) - ld(x)))


def _root_long(puller, w, xb, p):  # type: ignore[no-untyped-def]
    lo, hi = SLIDER - 1e-12, SLIDER + 1e-12
    assert _residual_long(lo, puller, w, xb, p) < 0 < _residual_long(hi, puller, w, xb, p)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if _residual_long(mid, puller, w, xb, p) > 0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("velocity", [120e-6, 350e-6])
def test_the_balance_takes_at_most_two_passes_and_lands_within_a_few_ulp(velocity, monkeypatch):
    functions = K.compiled()
    p = pack_parameters(GEL, True, GEL.block.effective_stiffness)
    w, xb = _population(velocity)
    n = w.size
    sigma = float(np.sum(w * np.asarray([K._chain_force(SLIDER - b, p[K.P_M], p[K.P_DLM]) for b in xb])))
    puller = SLIDER + sigma / p[K.P_K]
    root = _root_long(puller, w, xb, p)
    ulp = math.ulp(SLIDER)
    no_forces = np.empty((2, 0))
    start = root + 2 * ulp
    # called before the helper is replaced below: on a cold numba cache this call compiles, which must see the
    # jitted helper (run alone on a fresh cache the test failed with numba's "untyped global name")
    compiled_end = functions["_balance_from"](start, puller, n, xb, w, p, no_forces)
    passes = [0]
    stiffness = K._chain_stiffness

    def counted(e, m, dlm):  # type: ignore[no-untyped-def]
        passes[0] += 1
        return stiffness(e, m, dlm)

    monkeypatch.setattr(K, "_chain_stiffness", counted)  # the plain-Python balance looks its helpers up here
    balance = functions["_balance_from"].py_func
    for offset in (-40.0, -5.0, -2.0, -1.0, 1.0, 2.0, 5.0, 40.0, 1e4):
        passes[0] = 0
        x = balance(root + offset * ulp, puller, n, xb, w, p, no_forces)
        assert passes[0] <= 2 * n, (velocity, offset, passes[0] / n)
        assert abs(x - root) <= 4 * ulp, (velocity, offset, (x - root) / ulp)
    # the compiled function is the same arithmetic
    assert compiled_end == balance(start, puller, n, xb, w, p, no_forces)


def _inertial_residual_long(d, x0, v0, force0, h, puller1, mass, w, xb, p):  # type: ignore[no-untyped-def]
    """G(d) = m (v1 - v0) - h/2 (F0 + F1) of ``_inertial_step`` (no damping) in extended precision."""
    ld = np.longdouble
    e = (ld(x0) - xb.astype(ld)) + ld(d)
    y = e / ld(p[K.P_DLM])
    s = np.sum(w.astype(ld) * ld(p[K.P_M]) * e / (ld(1) - y * y))
    v1 = ld(2) * ld(d) / ld(h) - ld(v0)
    force1 = ld(p[K.P_K]) * (ld(puller1) - ld(x0) - ld(d)) - s
    return float(ld(mass) * (v1 - ld(v0)) - ld(0.5) * ld(h) * (ld(force0) + force1))


def test_the_inertial_step_stops_on_newtons_own_correction(monkeypatch):
    """The block with a mass: the same stop for its travel over a step (``_inertial_step``)."""
    functions = K.compiled()
    mass, h, v0 = 10.5, 2e-6, 120e-6
    p = pack_parameters(GEL, True, 1e7)
    p[K.P_MASS] = mass
    w, xb = _population(v0)
    n = w.size
    sigma = float(np.sum(w * np.asarray([K._chain_force(SLIDER - b, p[K.P_M], p[K.P_DLM]) for b in xb])))
    puller1 = SLIDER + sigma / p[K.P_K] + v0 * h
    force0 = p[K.P_K] * (puller1 - v0 * h - SLIDER) - sigma
    args = (SLIDER, v0, force0, h, puller1, mass, w, xb, p)
    lo, hi = 0.0, 2.0 * v0 * h
    assert _inertial_residual_long(lo, *args) < 0 < _inertial_residual_long(hi, *args)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        lo, hi = (lo, mid) if _inertial_residual_long(mid, *args) > 0 else (mid, hi)
    root = 0.5 * (lo + hi)
    passes = [0]
    stiffness = K._chain_stiffness

    def counted(e, m, dlm):  # type: ignore[no-untyped-def]
        passes[0] += 1
        return stiffness(e, m, dlm)

    monkeypatch.setattr(K, "_chain_stiffness", counted)
    step = functions["_inertial_step"].py_func
    ulp = math.ulp(root)
    for offset in (-1e3, -30.0, -3.0, -1.0, 1.0, 3.0, 30.0, 1e3):
        start = root + offset * ulp
        e = (SLIDER - xb) + start
        at_start = np.array(
            [[K._chain_force(q, p[K.P_M], p[K.P_DLM]) for q in e], [stiffness(q, p[K.P_M], p[K.P_DLM]) for q in e]]
        )
        passes[0] = 0
        d, _s, _k = step(start, SLIDER, v0, force0, h, puller1, n, xb, w, p, at_start)
        assert passes[0] <= 3 * n, (offset, passes[0] / n)
        assert abs(d - root) <= 1e-15 * (abs(root) + h * v0), (offset, (d - root) / ulp)
