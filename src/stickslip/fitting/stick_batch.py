r"""Stick times of many stick phases at once (the stick fit's inner loop).

Eq 15 for one stick phase, in the variables of :mod:`stickslip.model.stick`:
n = Nc/Nc0, dn/dt = -r n exp((s0 + k t)/n - t/tau_a).  As there, the
equation is integrated in the arc-length-like variable theta,

    dt'/dtheta = 1/(1 + w),   dn/dtheta = -w/(1 + w),   w = r T n exp((s0 + k t)/n - t/tau_a),

(t' = t/T), which is regular both while the chains hold and through their
collapse; past n = 0 the field is (0, -1), its limit, so no event location is
needed: t_s is t' T once n < 0.

:func:`stickslip.model.stick.stick_phase` solves one phase with scipy's
adaptive Runge-Kutta at rtol 1e-11, with the stuck-for-ever proof and the
full trajectory.  A fit needs only t_s, for every row and every perturbed
parameter set of a Jacobian: here all of them advance together, each with
its own step size, in a vectorised Dormand-Prince 5(4) pair (rtol 1e-9).
Phases that have not slipped by their ``horizon`` get NaN (the fit treats
them as "far too long"); nothing is claimed about them.  Tested against
``stick_phase`` and the constant-load closed form t_s = E1(s0)/r.
"""

from __future__ import annotations

import numpy as np

#: Tolerances of the steps (t' and n are both O(1) per unit theta).
RTOL = 1e-9
ATOL = 1e-12
#: Below this n the chains are gone (as in stickslip.model.stick).
N_GONE = 1e-200
#: -ln of the shortest time scale used (1e-300 s), as in stickslip.model.stick.
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
    collapse continued through n = 0 as in stickslip.model.stick.
    """
    log_rt, s0, k_t, aging_t = constants
    tau = y[0]
    n = np.maximum(y[1], N_GONE)
    log_w = log_rt + np.log(n) + (s0 + k_t * tau) / n - aging_t * tau
    out[0] = np.exp(-np.logaddexp(0.0, log_w))  # 1/(1 + w) without overflow
    out[1] = out[0] - 1.0


def stick_times(r: np.ndarray, s0: np.ndarray, k: np.ndarray, inv_aging: np.ndarray, horizon: np.ndarray) -> np.ndarray:
    """t_s (s) of each phase (broadcast arrays); NaN where the chains have not collapsed by ``horizon`` s.

    ``r`` = uc/tau (1/s), ``s0`` = (lambda/kT) sigma_0/Nc0, ``k`` = (lambda/kT) (d sigma/dt)/Nc0 (1/s),
    ``inv_aging`` = 1/tau_a (0 without aging).
    """
    r, s0, k, inv_aging, horizon = (np.asarray(a, dtype=float).ravel() for a in np.broadcast_arrays(
        r, s0, k, inv_aging, horizon))  # fmt: skip
    size = r.size
    out = np.full(size, np.nan)
    loaded = (s0 > 0) | (k > 0)  # without load nothing ever slips
    phases = _Phases(r, s0, k, inv_aging)
    limit = horizon / phases.scale  # in t'
    tau, n = np.zeros(size), np.ones(size)
    step = np.full(size, 1e-2)
    first = np.zeros((2, size))  # the field at the current point (first same as last)
    active = np.nonzero(loaded)[0]
    constants = phases.subset(active)
    start = np.empty((2, active.size))
    _field(constants, np.stack([tau[active], n[active]]), start)
    first[:, active] = start
    for _ in range(MAX_STEPS):
        if active.size == 0:
            break
        m = active.size
        y0 = np.stack([tau[active], n[active]])  # (2, m)
        h = step[active]
        slopes = np.empty((7, 2, m))
        flat = slopes.reshape(7, 2 * m)
        slopes[0] = first[:, active]
        for j in range(1, 7):
            y = y0 + h * (_A[j, :j] @ flat[:j]).reshape(2, m)
            _field(constants, y, slopes[j])
        y_new = y  # the last stage is taken at the 5th-order solution
        err = h * (_E @ flat).reshape(2, m)
        scale = ATOL + RTOL * np.maximum(np.abs(y0), np.abs(y_new))
        norm = np.sqrt(0.5 * ((err[0] / scale[0]) ** 2 + (err[1] / scale[1]) ** 2))
        ok = norm <= 1.0
        factor = np.clip(0.9 * np.where(norm > 0, norm, 1e-10) ** -0.2, 0.2, 5.0)
        step[active] = h * np.where(ok, factor, np.minimum(factor, 1.0))
        accepted = active[ok]
        tau[accepted], n[accepted] = y_new[0, ok], y_new[1, ok]
        first[:, accepted] = slopes[6][:, ok]
        collapsed = ok & (y_new[1] < 0.0)
        out[active[collapsed]] = y_new[0, collapsed] * phases.scale[active[collapsed]]
        late = ok & ~collapsed & (y_new[0] > limit[active])
        done = collapsed | late
        if done.any():
            active = active[~done]
            constants = phases.subset(active)
    return out
