"""An independent, slow, high-accuracy evaluation of Eqs 6-8 for the tests.

It shares no code with ``stickslip.model.steady`` beyond the parameter object.
Instead of Gauss panels it integrates the ODE system

    dH/dx = e^L,   di/dx = e^-H,   dj/dx = e^-H x/(1-x^2)

with scipy's 8th-order Dormand-Prince method (DOP853, rtol 1e-13): in x on
[0, 1/2], then in y = 1 - x from 1/2 down towards 0, so that the FENE end keeps
full relative precision (near the cliff the FENE and aging terms of L can be
~1e9 each and nearly cancel).  Once L rises through 5 (it is convex, so it
then rises for good) the cumulative hazard H itself becomes the independent
variable, with dx/dH = e^-L, di/dH = e^-H e^-L, dj/dH = e^-H x/(1-x^2) e^-L:
smooth where the hazard explodes, which a step in x or y cannot follow
cheaply.  It stops at H = 60 (S < 1e-26).
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

    def done(_, state):
        return state[0] - H_END

    def rising_x(x, state):
        return log_hazard(x, 1.0 - x) - L_SWITCH

    def rising_y(y, state):
        return log_hazard(1.0 - y, y) - L_SWITCH

    for event in (done, rising_x, rising_y):
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

        return solve_ivp(rhs_h, (hazard, H_END), [position, i, j], method="DOP853", rtol=RTOL, atol=1e-300)

    # L rising already at x = 0 (when the FENE term beats aging) is caught by the event at once
    first = min(1e-3, 1e-3 / math.exp(log_t))  # inside the initial decay on x ~ 1/T
    sol = solve_ivp(
        rhs_x,
        (0.0, 0.5),
        [0.0, 0.0, 0.0],
        method="DOP853",
        rtol=RTOL,
        atol=1e-300,
        events=(done, rising_x),
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
            events=(done, rising_y),
            first_step=1e-6,
        )
        position_is_x = False
    if sol.status != 1:
        raise RuntimeError(f"reference integration did not reach H = {H_END}: {sol.message}")
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
