"""Stick times of many stick phases at once (the stick fit's inner loop).

Eq 15 of every row and every perturbed parameter set of a Jacobian, in the arc-length-like variable of
:mod:`stickslip.quasistatic.stick`, advances together in a vectorised Dormand-Prince 5(4) pair (rtol 1e-9), each
phase with its own step; past n = 0 the field is (0, -1), so t_s needs no event location.  A phase that has not
slipped by its ``horizon`` gets NaN (the fit reads "far too long"); nothing is claimed about it (docs/fitting.md).
"""

from __future__ import annotations

import numpy as np
from scipy.special import expit

#: Tolerances of the steps (t' and n are both O(1) per unit theta).
RTOL = 1e-9
ATOL = 1e-12
#: Below this n the chains are gone (as in stickslip.quasistatic.stick).
N_GONE = 1e-200
#: -ln of the shortest time scale used (1e-300 s), as in stickslip.quasistatic.stick.
SHORTEST_LOG_TIME = 690.0
#: Give up (NaN) after this many steps of the slowest phase.
MAX_STEPS = 20000

# Dormand-Prince 5(4): stage coefficients (row j: stage j from stages < j), 5th-order weights (= the last
# row: first same as last), and the weights of the error estimate (5th - 4th order)
_A = np.zeros((7, 7))
_A[1, :1] = [1 / 5]
_A[2, :2] = [3 / 40, 9 / 40]
_A[3, :3] = [44 / 45, -56 / 15, 32 / 9]
_A[4, :4] = [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729]
_A[5, :5] = [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656]
_A[6, :6] = [35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84]
_E = np.array([71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40])


class _Phases:
    """Constants of the phases being integrated (one entry per phase)."""

    def __init__(self, r: np.ndarray, s0: np.ndarray, k: np.ndarray, inv_aging: np.ndarray) -> None:
        fresh = np.log(r) + s0
        other = k + inv_aging
        total = np.where(other > 0, np.logaddexp(fresh, np.log(np.where(other > 0, other, 1.0))), fresh)
        log_scale = -np.minimum(total, SHORTEST_LOG_TIME)
        self.scale = np.exp(log_scale)  # T
        self.log_rt = np.log(r) + log_scale
        self.s0, self.k_t, self.aging_t = s0, k * self.scale, inv_aging * self.scale

    def subset(self, idx: np.ndarray) -> tuple[np.ndarray, ...]:
        """The constants of the phases ``idx``, for :func:`_field`."""
        return self.log_rt[idx], self.s0[idx], self.k_t[idx], self.aging_t[idx]


def _field(constants: tuple[np.ndarray, ...], y: np.ndarray, out: np.ndarray) -> None:
    """(dt'/dtheta, dn/dtheta) at y = (t', n) (shape (2, phases)) into ``out``.

    Below N_GONE, n is taken as N_GONE: there w is astronomically large, so the field is (0, -1), the
    collapse continued through n = 0 as in stickslip.quasistatic.stick.
    """
    log_rt, s0, k_t, aging_t = constants
    tau = y[0]
    n = np.maximum(y[1], N_GONE)
    log_w = k_t * tau
    log_w += s0
    log_w /= n
    log_w -= aging_t * tau
    log_w += np.log(n, out=n)
    log_w += log_rt
    expit(np.negative(log_w, out=log_w), out=out[0])  # 1/(1 + w) without overflow
    np.subtract(out[0], 1.0, out=out[1])


def stick_times(r: np.ndarray, s0: np.ndarray, k: np.ndarray, inv_aging: np.ndarray, horizon: np.ndarray) -> np.ndarray:
    """t_s (s) of each phase (broadcast arrays); NaN where the chains have not collapsed by ``horizon`` s.

    ``r`` = uc/tau (1/s), ``s0`` = (lambda/kT) sigma_0/Nc0, ``k`` = (lambda/kT) (d sigma/dt)/Nc0 (1/s),
    ``inv_aging`` = 1/tau_a (0 without aging).
    """
    r, s0, k, inv_aging, horizon = (np.asarray(a, dtype=float).ravel() for a in np.broadcast_arrays(
        r, s0, k, inv_aging, horizon))  # fmt: skip
    out = np.full(r.size, np.nan)
    phases = _Phases(r, s0, k, inv_aging)
    # the working arrays hold only the phases still marching (without load nothing ever slips): a step costs
    # what those cost, and finished phases are written out and dropped
    index = np.nonzero((s0 > 0) | (k > 0))[0]
    constants = phases.subset(index)
    limit = horizon[index] / phases.scale[index]  # in t'
    y0 = np.zeros((2, index.size))
    y0[1] = 1.0
    step = np.full(index.size, 1e-2)
    slopes = np.empty((7, 2, index.size))
    _field(constants, y0, slopes[0])  # the field at the current point (first same as last)
    for _ in range(MAX_STEPS):
        if index.size == 0:
            break
        m = index.size
        flat = slopes.reshape(7, 2 * m)
        for j in range(1, 7):
            y = (_A[j, :j] @ flat[:j]).reshape(2, m)
            y *= step
            y += y0
            _field(constants, y, slopes[j])
        # y: the last stage is taken at the 5th-order solution
        err = (_E @ flat).reshape(2, m)
        err *= step
        err /= ATOL + RTOL * np.maximum(np.abs(y0), np.abs(y))
        norm = np.sqrt(0.5 * (err[0] ** 2 + err[1] ** 2))
        ok = norm <= 1.0
        factor = np.clip(0.9 * np.where(norm > 0, norm, 1e-10) ** -0.2, 0.2, 5.0)
        step *= np.where(ok, factor, np.minimum(factor, 1.0))
        y0[:, ok] = y[:, ok]
        slopes[0][:, ok] = slopes[6][:, ok]
        collapsed = ok & (y[1] < 0.0)
        done = collapsed | (ok & (y[0] > limit))
        if done.any():
            out[index[collapsed]] = y[0, collapsed] * phases.scale[index[collapsed]]
            keep = ~done
            index, limit, step, y0 = index[keep], limit[keep], step[keep], y0[:, keep]
            slopes = np.ascontiguousarray(slopes[:, :, keep])
            constants = tuple(c[keep] for c in constants)
    return out
