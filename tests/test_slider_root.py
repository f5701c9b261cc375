"""The massless block's slider velocity: the stable root of g(V) nearest the last velocity (transient/kernel.py
``_slider_velocity_clocked``), against g written out in numpy here.

g(V) = (k_int + K) V - K Vp - sum w f r(V), r = (omega/tau) exp(beta |f| - (t_a/tau_a) e^(-V/V_a)) (Eq 1 with the
block's balance; docs/transient.md section 2; a cohort under compression carries no breakage term, as in the
kernel).  The kernel's Newton iteration stops where its next correction,
|g''/2g'| step^2, is within its tolerance, so its g'' must be right: checked against a difference quotient of g'.
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
PACE = 1e-4


def _population(velocity: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    pop = steady_cohorts(GEL, velocity, True)
    order = np.argsort(-pop.age)
    return -pop.extension[order], -pop.age[order], np.log(pop.weight[order])


def _g(v: np.ndarray, x: float, xb: np.ndarray, tb: np.ndarray, lw: np.ndarray, p: np.ndarray) -> np.ndarray:
    """g(V) for an array of V (t = 0), in numpy."""
    e = x - xb
    y = e / p[K.P_DLM]
    force = p[K.P_M] * e / (1.0 - y * y)
    stiffness = p[K.P_M] * (1.0 + y * y) / (1.0 - y * y) ** 2
    w = np.exp(lw)
    age = -tb
    decay = np.exp(-np.abs(np.asarray(v, dtype=float))[:, None] / p[K.P_VA])
    log_rate = p[K.P_LOG_U0_TAU] + p[K.P_FORCE_SENS] * np.abs(force) - age * p[K.P_INV_TAU_A] * decay
    # a cohort under compression (f <= 0) carries no breakage term, as in the kernel (_velocity_prepare)
    loss = np.where(force > 0.0, w * force * np.exp(log_rate), 0.0).sum(axis=1)
    return (w @ stiffness + p[K.P_K]) * np.asarray(v) - p[K.P_K] * PACE - loss


@pytest.mark.parametrize("x", [0.0, 2e-9, -2e-9])
@pytest.mark.parametrize("start", [0.3, 0.97, 1.0001, 1.5, 4.0])
def test_the_root_is_the_crossing_nearest_the_last_velocity(x: float, start: float) -> None:
    functions = K.compiled()
    p = pack_parameters(GEL, True, GEL.block.effective_stiffness)
    xb, tb, lw = _population(128e-6)
    n = xb.size
    first = functions["_slider_velocity"](128e-6, PACE, n, xb, tb, lw, x, 0.0, p, np.empty(n), np.empty(n),
                                          np.full((3, n), -1.0))  # fmt: skip
    v_prev = start * first
    v = functions["_slider_velocity"](v_prev, PACE, n, xb, tb, lw, x, 0.0, p, np.empty(n), np.empty(n),
                                      np.full((3, n), -1.0))  # fmt: skip
    scale = p[K.P_K] * PACE + abs(_g(np.array([0.0]), x, xb, tb, lw, p)[0])
    g_root, g_left, g_right = _g(np.array([v, v * (1 - 1e-7), v * (1 + 1e-7)]), x, xb, tb, lw, p)
    assert abs(g_root) <= 1e-10 * scale
    assert g_left < 0.0 < g_right  # a stable root: g rises through it
    between = np.linspace(min(v_prev, v), max(v_prev, v), 4001)[1:-1]
    inside = between[np.abs(between - v) > 1e-7 * v]
    signs = np.sign(_g(inside, x, xb, tb, lw, p))
    # no other crossing between the last velocity and the root
    assert np.all(signs == signs[0]) if inside.size else True
    assert v == pytest.approx(first, rel=1e-12)


def test_the_residuals_curvature_is_the_derivative_of_its_slope() -> None:
    functions = K.compiled()
    p = pack_parameters(GEL, True, GEL.block.effective_stiffness)
    xb, tb, lw = _population(128e-6)
    n = xb.size
    lc, aa, known = np.empty(n), np.empty(n), np.full((3, n), -1.0)
    k_int = functions["_velocity_prepare"](n, xb, tb, lw, 1e-9, 0.0, p, lc, aa, known, np.empty((2, 0)))
    for v in (3e-5, 1.28e-4, 5e-4):
        g, _slope, curvature = functions["_velocity_residual"](v, PACE, n, lc, aa, known, k_int, p)
        dv = 1e-4 * v
        assert g == pytest.approx(_g(np.array([v]), 1e-9, xb, tb, lw, p)[0], rel=1e-9, abs=1e-9 * p[K.P_K] * PACE)
        slopes = [functions["_velocity_residual"](v + s * dv, PACE, n, lc, aa, known, k_int, p)[1] for s in (-1, 1)]
        difference = (slopes[1] - slopes[0]) / (2 * dv)  # central: error ~ dv^2 g''''/6
        assert curvature == pytest.approx(difference, rel=1e-5)
        assert math.isfinite(curvature) and curvature != 0.0
