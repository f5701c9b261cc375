"""An independent, slow, high-accuracy evaluation of Eqs 6-8 for the tests.

It shares no code with ``stickslip.quasistatic.steady`` beyond the parameter object.
Instead of Gauss panels it integrates the ODE system

    dH/dx = e^L,   di/dx = e^-H,   dj/dx = e^-H x/(1-x^2)

with scipy's 8th-order Dormand-Prince method (DOP853, rtol 1e-13): in x on
[0, 1/2], then in y = 1 - x from 1/2 down towards 0, so that the FENE end keeps
full relative precision (near the cliff the FENE and aging terms of L can be
~1e9 each and nearly cancel).  Once L rises through 5 (it is convex, so it
then rises for good) the cumulative hazard H itself becomes the independent
variable, with dx/dH = e^-L, di/dH = e^-H e^-L, dj/dH = e^-H x/(1-x^2) e^-L:
smooth where the hazard explodes, which a step in x or y cannot follow
cheaply.  It stops once the survival has fallen by e^-60 on the rising branch
of L (after the minimum of L: then the hazard only grows).  Not before: with
aging H can level off on a plateau S ~ 1e-19 that still carries most of j when
the survival fell early (x ~ 1/T, where x/(1-x^2) is tiny), so stopping at a
fixed H while L still falls would drop it.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

KB = 1.380649e-23
H_END = 60.0
L_SWITCH = 5.0
RTOL = 1e-13


def reference_point(params, velocity: float, aging: bool = True) -> tuple[float, float]:
    """(stress, bonded_fraction) at one velocity."""
    b, g = params.bonds, params.aging
    t_max = b.max_extension / velocity
    log_t = math.log(b.breakage_weight * t_max / b.bond_time)
    a = b.activation_length * b.chain_stiffness * b.max_extension / (KB * b.temperature)
    alpha = (t_max / g.aging_time) * math.exp(-velocity / g.aging_velocity) if aging else 0.0

    def log_hazard(x, y):
        if y <= 0.0:  # events evaluated at the FENE end itself
            return math.inf
        return log_t + a * x / (y * (1.0 + x)) - alpha * x

    def rates(x, y, hazard):
        if y <= 0.0:  # past the FENE end (trial stages only): no survivors, no hazard to add
            return 0.0, 0.0, 0.0
        survival = math.exp(min(-hazard, 300.0))  # trial stages of rejected steps may overshoot
        return math.exp(min(log_hazard(x, y), 300.0)), survival, survival * x / (y * (1.0 + x))

    def rhs_x(x, state):
        return list(rates(x, 1.0 - x, state[0]))

    def rhs_y(y, state):
        return [-r for r in rates(1.0 - y, y, state[0])]

    def rising(x, y):
        return y <= 0.0 or a * (1.0 + x * x) / (y * (1.0 + x)) ** 2 >= alpha

    def done_x(x, state):  # H = 60 counts only on the rising branch (see the module docstring)
        return state[0] - H_END if rising(x, 1.0 - x) else -1.0

    def done_y(y, state):
        return state[0] - H_END if rising(1.0 - y, y) else -1.0

    def rising_x(x, state):
        return log_hazard(x, 1.0 - x) - L_SWITCH

    def rising_y(y, state):
        return log_hazard(1.0 - y, y) - L_SWITCH

    for event in (done_x, done_y, rising_x, rising_y):
        event.terminal = True
    rising_x.direction = rising_y.direction = 1

    def finish_in_h(hazard, position, i, j, position_is_x):
        sign = 1.0 if position_is_x else -1.0

        def rhs_h(h, state):
            p = state[0]
            x, y = (p, 1.0 - p) if position_is_x else (1.0 - p, p)
            if y <= 0.0:  # a trial stage stepped past the FENE end, where e^-L and its products vanish
                return [0.0, 0.0, 0.0]
            dpos = math.exp(min(-log_hazard(x, y), 300.0))
            survival = math.exp(-h)
            return [sign * dpos, survival * dpos, survival * x / (y * (1.0 + x)) * dpos]

        return solve_ivp(rhs_h, (hazard, hazard + H_END), [position, i, j], method="DOP853", rtol=RTOL, atol=1e-300)

    # L rising already at x = 0 (when the FENE term beats aging) is caught by the event at once
    first = min(1e-3, 1e-3 / math.exp(log_t))  # inside the initial decay on x ~ 1/T
    sol = solve_ivp(
        rhs_x,
        (0.0, 0.5),
        [0.0, 0.0, 0.0],
        method="DOP853",
        rtol=RTOL,
        atol=1e-300,
        events=(done_x, rising_x),
        first_step=first,
    )
    position_is_x = True
    if sol.status == 0:
        sol = solve_ivp(
            rhs_y,
            (0.5, 0.0),
            sol.y[:, -1],
            method="DOP853",
            rtol=RTOL,
            atol=1e-300,
            events=(done_y, rising_y),
            first_step=1e-6,
        )
        position_is_x = False
    if sol.status != 1:
        raise RuntimeError(f"reference integration did not reach its end: {sol.message}")
    hazard, i, j = sol.y[:, -1]
    if sol.t_events[1].size:  # switched: finish with H as the variable
        fin = finish_in_h(hazard, float(sol.t[-1]), i, j, position_is_x)
        if fin.status != 0:
            raise RuntimeError(f"reference integration failed in H: {fin.message}")
        _, i, j = fin.y[:, -1]
    birth = b.bond_time * velocity / b.max_extension
    stress = b.chain_stiffness * b.site_density * b.max_extension * j / (birth + i)
    return float(stress), float(i / (birth + i))


def reference_curve(params, velocities, aging: bool = True) -> tuple[np.ndarray, np.ndarray]:
    out = np.array([reference_point(params, float(v), aging) for v in np.ravel(velocities)])
    return out[:, 0], out[:, 1]


# --------------------------------------------------------------------------- many points at once
#
# reference_many: the same integrals for thousands of (parameter set, velocity) points together, fast
# enough for a random-set test of the whole box.  It shares no code with stickslip.quasistatic.steady (no
# panels, no Gauss rule, no width search, no tail bound) nor with reference_point above: one adaptive
# Dormand-Prince 5(4) integration per point, all points stepping together in numpy arrays, each with
# its own step, in an arc-length variable s with
#
#     dx/ds = 1/g,   g = 1 + 1/y + e^L + sqrt(1 + L'^2) w(L),   w(L) = 1/(1 + e^-(L + SLOPE_FLOOR)),
#
# so that across one unit of s, ln y, the log-hazard L (wherever the hazard is not negligible: w cuts
# |L'| out of the deep aging dip, where e^L < e^-50 cannot add to H) and the cumulative hazard H each
# change by at most about one.  x and y = 1 - x are both carried as states, so the FENE end keeps full
# relative precision.  It stops H_STOP e-folds after the hazard has become fast (L rising and
# e^L y >= FAST): from there on S decays at a rate >= FAST/y to the end, so what is left is negligible.
# A fixed stop at some H would be wrong: with aging H can level off on a plateau S ~ 1e-19 that
# carries most of j up to the FENE cliff when the survival fell early (x ~ 1/T).

DP_A = [
    [],
    [1 / 5],
    [3 / 40, 9 / 40],
    [44 / 45, -56 / 15, 32 / 9],
    [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729],
    [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656],
    [35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84],
]
DP_B = [35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0.0]
DP_E = [71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40]
SLOPE_FLOOR = 50.0
H_STOP = 40.0
FAST = 100.0
MANY_RTOL = 1e-10
MAX_STEPS = 200_000


def _log_hazard_slope(x, y, log_t, a, alpha):
    fene = x / (y * (1.0 + x))
    return fene, log_t + a * fene - alpha * x, a * (1.0 + x * x) / (y * (1.0 + x)) ** 2 - alpha


def _many_rates(z, log_t, a, alpha):
    """d(x, y, H, i, j)/ds for rows z = (x, y, H, i, j); a trial stage past the FENE end (y <= 0) is
    evaluated at y = 1e-100 (the step is then rejected, see _integrate_many)."""
    x, y, hazard = z[0], np.maximum(z[1], 1e-100), z[2]
    fene, log_h, slope = _log_hazard_slope(x, y, log_t, a, alpha)
    log_slope_term = np.log(np.hypot(1.0, slope)) - np.logaddexp(0.0, -(log_h + SLOPE_FLOOR))
    log_g = np.logaddexp(np.logaddexp(0.0, -np.log(y)), np.logaddexp(log_h, log_slope_term))
    speed = np.exp(-log_g)
    survival = np.exp(-hazard - log_g)
    return np.stack([speed, -speed, np.exp(log_h - log_g), survival, survival * fene])


def case_groups(cases) -> tuple[np.ndarray, ...]:
    """The dimensionless groups (ln T, a, alpha, birth, stress scale) of each (params, velocity, aging) case."""
    log_t, a, alpha, birth, scale = (np.empty(len(cases)) for _ in range(5))
    for k, (params, velocity, aging) in enumerate(cases):
        b, g = params.bonds, params.aging
        t_max = b.max_extension / velocity
        log_t[k] = math.log(b.breakage_weight) + math.log(t_max) - math.log(b.bond_time)
        a[k] = b.activation_length * b.chain_stiffness * b.max_extension / (KB * b.temperature)
        alpha[k] = (t_max / g.aging_time) * math.exp(-velocity / g.aging_velocity) if aging else 0.0
        birth[k] = b.bond_time * velocity / b.max_extension
        scale[k] = b.chain_stiffness * b.site_density * b.max_extension
    return log_t, a, alpha, birth, scale


def reference_many(cases) -> tuple[np.ndarray, np.ndarray]:
    """(stress, bonded_fraction) arrays for ``cases``, a sequence of (params, velocity, aging)."""
    log_t, a, alpha, birth, scale = case_groups(cases)
    i, j = _integrate_many(log_t, a, alpha)
    return scale * j / (birth + i), i / (birth + i)


def _integrate_many(log_t, a, alpha) -> tuple[np.ndarray, np.ndarray]:
    n = log_t.size
    i_out, j_out = np.full(n, np.nan), np.full(n, np.nan)
    lane = np.arange(n)
    z = np.zeros((5, n))
    z[1] = 1.0
    h = np.full(n, 1e-3)
    fast_at = np.full(n, np.inf)  # H where the hazard became fast (see above)
    k1 = _many_rates(z, log_t, a, alpha)
    for _ in range(MAX_STEPS):
        stages = [k1]
        past_end = np.zeros(z.shape[1], dtype=bool)
        for row in DP_A[1:]:
            trial = z + h * sum(coef * k for coef, k in zip(row, stages, strict=False) if coef != 0.0)
            past_end |= trial[1] <= 0.0
            stages.append(_many_rates(trial, log_t, a, alpha))
        z_new = z + h * sum(coef * k for coef, k in zip(DP_B, stages, strict=True) if coef != 0.0)
        err = h * sum(coef * k for coef, k in zip(DP_E, stages, strict=True) if coef != 0.0)
        size = np.maximum(np.abs(z), np.abs(z_new))
        size[2] = 1.0 + size[2]  # H: absolute (S = e^-H carries the relative error)
        ratio = np.max(np.abs(err) / (MANY_RTOL * size + 1e-300), axis=0)
        ratio[past_end | (z_new[1] <= 0.0)] = 1e10  # stepped past y = 0: reject, shrink the step fivefold
        accept = ratio <= 1.0
        z = np.where(accept, z_new, z)
        k1 = np.where(accept, stages[-1], k1)  # first same as last
        h = h * np.clip(0.9 * np.maximum(ratio, 1e-10) ** -0.2, 0.2, 5.0)
        _, log_h, slope = _log_hazard_slope(z[0], z[1], log_t, a, alpha)
        fast = (slope > 0.0) & (log_h + np.log(z[1]) >= math.log(FAST))
        fast_at = np.where(fast & np.isinf(fast_at), z[2], fast_at)
        done = z[2] >= fast_at + H_STOP
        if done.any():
            i_out[lane[done]], j_out[lane[done]] = z[3, done], z[4, done]
            keep = ~done
            if not keep.any():
                return i_out, j_out
            lane, z, h, k1, fast_at = lane[keep], z[:, keep], h[keep], k1[:, keep], fast_at[keep]
            log_t, a, alpha = log_t[keep], a[keep], alpha[keep]
    raise RuntimeError(f"reference_many: {lane.size} points did not finish in {MAX_STEPS} steps")


# --------------------------------------------------------------------------- the parameter box
#: The physical box of the random-set tests (SI), sampled log-uniformly; ``velocity`` is V.
BOX = {
    "bonds.site_density": (1e12, 1e16),
    "bonds.bond_time": (1e-9, 1.0),
    "bonds.breakage_weight": (0.01, 100.0),
    "bonds.chain_stiffness": (1e-6, 0.1),
    "bonds.activation_length": (1e-12, 1e-7),
    "bonds.max_extension": (1e-8, 1.0),
    "aging.aging_time": (1e-9, 1e3),
    "aging.aging_velocity": (1e-7, 1.0),
    "velocity": (1e-7, 1.0),
}
#: The hard corner of issue 12: FENE strength a = lambda M dl_m/kT of 30-3e4 and the aging rate
#: alpha = dl_m/(V tau_a) e^(-V/V_a) a little above it, so the log-hazard dips deep and climbs a cliff at x ~ 1.
CORNER_A = (30.0, 3e4)
CORNER_RATIO = (1.0, 4.0)


def _log_uniform(rng, lo, hi):
    return float(np.exp(rng.uniform(math.log(lo), math.log(hi))))


def _box_values(rng, base, corner: bool):
    """The draws of one box case: (overrides, velocity, aging); ``base`` only for its temperature."""
    while True:
        values = {key: _log_uniform(rng, lo, hi) for key, (lo, hi) in BOX.items()}
        velocity = values.pop("velocity")
        aging = True if corner else bool(rng.integers(2))
        if corner:
            kt = KB * base.bonds.temperature
            a = _log_uniform(rng, *CORNER_A)
            stretch = values["bonds.chain_stiffness"] * values["bonds.max_extension"]
            values["bonds.activation_length"] = a * kt / stretch
            alpha = a * rng.uniform(*CORNER_RATIO)
            decay = math.exp(-velocity / values["aging.aging_velocity"])
            values["aging.aging_time"] = values["bonds.max_extension"] / (velocity * alpha) * decay
            if not all(BOX[k][0] <= values[k] <= BOX[k][1] for k in ("bonds.activation_length", "aging.aging_time")):
                continue
        return values, velocity, aging


def box_case(rng, base, corner: bool):
    """One random (params, velocity, aging) in BOX; ``corner`` forces issue 12's deep-dip/cliff shape."""
    values, velocity, aging = _box_values(rng, base, corner)
    return base.with_overrides(values), velocity, aging


def box_cases(seed: int, count: int, base, corner_share: float = 0.5, only=None):
    """``count`` cases from a fixed seed, ``corner_share`` of them in the deep-dip/cliff corner.

    ``only``: the indices wanted, in that order; every case is still drawn (the same random stream), but only
    these become parameter sets (making one is most of the cost: 1.9 s for 9000 cases)."""
    rng = np.random.default_rng(seed)
    drawn = [_box_values(rng, base, k < corner_share * count) for k in range(count)]
    picked = range(count) if only is None else only
    return [(base.with_overrides(drawn[k][0]), *drawn[k][1:]) for k in picked]
