r"""The quasi-steady reduction of Eq 1: where the slider changes pace slowly, the bonds are the steady population.

The bonds relax over a few bond lifetimes (tau = 224 us for the gel) while a slip
changes the slider velocity over seconds.  Along such a stretch the population is
the steady one of the current velocity up to a known order in the acceleration:
linearising the cohorts about steady sliding (``stability.interface_response``)
gives sigma = Z(s)/s V for a velocity perturbation, and Z(s)/s = S'(V) + C(V) s + ...,
so

    sigma = S(V) + C(V) dV/dt + O((dV/dt)^2, d^2V/dt^2),

S the steady stress of Eqs 6-8 (the steady solver) and C the first-order lag of the
population (Pa s^2/m).  Through the block, sigma = K (P - X) and d sigma/dt = K (Vp - V);
with the closure dV/dt ~ a0 = K (Vp - V)/S'(V) the slider obeys

    sigma = S_eff(V) = S(V) + C(V) K (Vp - V)/S'(V),        dV/dt = K (Vp - V)/S_eff'(V),

a scalar ODE in place of ~2000 cohorts.  What the reduction neglects is estimated by
the next order, C (a1 - a0) + (C^2/S') da/dt (the second term is exact for a
population with one exponential memory, Z/s = S'/(1 + sT)), and kept below
``THETA * rtol * sigma``; where it grows (towards the fold of the steady curve at Vc,
where S' -> 0) the solver switches back to cohorts rebuilt from the steady
population.  Under velocity control the slider's velocity is piecewise constant,
so a reduced stretch is exact steady sliding.  The manifold is assumed attracting: a
fast oscillatory instability of steady sliding (Kc(V) > K, ``stability``) is not
looked for while reduced (for the gel Kc = 0 from Vc to at least 1 mm/s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.polynomial import chebyshev as cheb
from numpy.polynomial import polyutils as pu

from ..parameters import Parameters
from . import glide as glide_ode
from . import kernel
from .cells import _steady_cells
from .model import CELL_HAZARD

#: share of the local tolerance the reduction may change the stress by (entry and stay)
THETA = 0.3
#: through the block, where the slider creeps far below the puller, the neglected stress may exceed THETA rtol sigma by
#: the block's insensitivity to it, S'|Vp - V|/sigma, up to this factor (:func:`allowed_neglect`)
NEGLECT_CAP = 10.0
#: the neglected stress reported where the first-order manifold itself folds (Pa; ends a stretch)
OFF_MANIFOLD = 1e300
#: fewest trace rows a reduced stretch writes (besides the ODE's steps; a plot of the trace)
ROWS = 64
#: Chebyshev degrees: the steady stress and bonded fraction (raised until the check passes), the lag C
DEGREE = 24
MAX_DEGREE = 96
LAG_DEGREE = 16
#: the lag's interpolant must hold at the probes to this share of |C| (or of S' tau)
LAG_SHARE = 0.02
#: the steady stress interpolant must agree with the steady solver to this share of rtol between its nodes
TABLE_SHARE = 1e-3
#: the glide's ODE: scipy's DOP853 compiled (``glide``), or "solve_ivp" (the same method through scipy; a reference)
GLIDE_SOLVER = "compiled"


@dataclass
class Manifold:
    """Chebyshev interpolants in ln V over [v_lo, v_hi] of the steady state and its first-order lag."""

    v_lo: float
    v_hi: float
    stress: cheb.Chebyshev  # S(ln V), Pa
    dstress: cheb.Chebyshev  # dS/dlnV
    d2stress: cheb.Chebyshev
    bonded: cheb.Chebyshev  # N/N0
    lag: cheb.Chebyshev  # C(ln V), Pa s^2/m
    dlag: cheb.Chebyshev  # dC/dlnV
    energy: cheb.Chebyshev  # bond energy of the steady population (J/m^2)
    bonded_lag: cheb.Chebyshev  # C_N/N0 (s^2/m): N/N0 = bonded + bonded_lag V' to first order
    _stacked: tuple[np.ndarray, np.floating, np.floating] | None = field(default=None, repr=False, compare=False)
    _last: tuple[float, np.ndarray | None] = field(default=(math.nan, None), repr=False, compare=False)
    _extrema: np.ndarray | None = field(default=None, repr=False, compare=False)  # real roots of S' in ln V

    def covers(self, lo: float, hi: float) -> bool:
        return self.v_lo <= lo and hi <= self.v_hi

    def rising(self, v: float) -> tuple[float, float] | None:
        """The stretch of the table around v where S' > 0 (between the curve's extrema), narrowed by 1e-3."""
        x = math.log(v)
        if not (self.dstress(x) > 0 and self.v_lo < v < self.v_hi):
            return None
        if self._extrema is None:  # the table's own numbers: found once (an eigenvalue problem, ~0.1 ms a call)
            roots = self.dstress.roots()
            self._extrema = roots[np.abs(roots.imag) < 1e-12].real
        roots = self._extrema
        below = roots[roots < x]
        above = roots[roots > x]
        lo = max(self.v_lo, math.exp(below.max()) * (1 + 1e-3)) if below.size else self.v_lo
        hi = min(self.v_hi, math.exp(above.min()) * (1 - 1e-3)) if above.size else self.v_hi
        return (lo, hi) if lo < v < hi else None

    def at(self, x: float) -> np.ndarray:
        """(S, dS/dlnV, d2S/dlnV2, C, dC/dlnV, N/N0) at ln V = x, in one Clenshaw recurrence over the six series'
        coefficients stacked (zero-padded to one degree).  Each column sees the operations its own series' call
        would do, so the values are the same to the bit; the reduced ODE asks for these at every stage and event
        test, where one numpy call per series cost more than the recurrences (the last x is remembered: the right-
        hand side and the event tests ask twice at one point)."""
        last_x, last = self._last
        if x == last_x and last is not None:
            return last
        stack, off, scl = self.stacked()
        out = _clenshaw()(stack, float(off + scl * x))
        self._last = (x, out)
        return out

    def stacked(self) -> tuple[np.ndarray, np.floating, np.floating]:
        """The six series' coefficients stacked as columns (zero-padded), and the map of ln V onto [-1, 1]."""
        if self._stacked is None:
            series = (self.stress, self.dstress, self.d2stress, self.lag, self.dlag, self.bonded)
            stack = np.zeros((max(s.coef.size for s in series), len(series)))
            for k, s in enumerate(series):
                stack[: s.coef.size, k] = s.coef
            off, scl = pu.mapparms(self.stress.domain, self.stress.window)
            self._stacked = (stack, off, scl)
        return self._stacked

    def many(self, x: np.ndarray) -> np.ndarray:
        """The six series of :meth:`at` at many ln V (shape (6, len(x))): one recurrence over the stacked columns
        (numpy's Clenshaw with two-dimensional coefficients), each value the same to the bit as its own series'
        call (the zero padding above a series' degree leaves its recurrence unchanged)."""
        stack, off, scl = self.stacked()
        return cheb.chebval(off + np.asarray(x) * scl, stack)

    def values(self, v: float) -> tuple[float, float, float, float, float]:
        """(S, S', S'', C, C') at velocity v (SI)."""
        s, sx, sxx, c, cx, _n = (float(value) for value in self.at(math.log(v)))
        slope = sx / v
        curv = (sxx - sx) / (v * v)
        return s, slope, curv, c, cx / v


def _lag(params: Parameters, velocity: float, aging: bool) -> tuple[float, float, float]:
    """(C, bond energy, C_N/N0) at ``velocity``: C = d/ds[Z(s)/s] at s = 0 by a Richardson central difference,
    C_N the same of the bonded count's response (N = N_ss(V) + C_N V' to first order, as sigma = S(V) + C V')."""
    from .model import pack_parameters
    from .stability import _response_kernel

    b = params.bonds
    p = pack_parameters(params, aging, 1.0)
    a, w, width, f, fp, r, gv, energy = _steady_cells()(velocity, p, CELL_HAZARD)
    birth_tau = b.site_density - w.sum()
    eps = 1e-2 * velocity / b.max_extension  # far below the population's slowest rate V/dl_m
    s = np.array([-eps, eps, -2 * eps, 2 * eps], dtype=complex)
    z = _response_kernel()(s, a, w, width, f, fp, r, gv, b.force_sensitivity, birth_tau).real
    q = z / s.real
    c1 = (q[:, 1] - q[:, 0]) / (2 * eps)
    c2 = (q[:, 3] - q[:, 2]) / (4 * eps)
    lags = (4 * c1 - c2) / 3
    return float(lags[0]), energy, float(lags[1]) / b.site_density


#: the stacked Clenshaw recurrence, compiled (glide.py, beside the glide's ODE that evaluates it at every stage)
_stacked_chebval, _clenshaw = glide_ode.stacked_chebval, glide_ode.clenshaw


def build_manifold(params: Parameters, aging: bool, v_lo: float, v_hi: float, rtol: float) -> Manifold | None:
    """The interpolants over [v_lo, v_hi]; None when the steady stress cannot be tabulated to its share of rtol."""
    from ..quasistatic.steady import steady_state

    domain = [math.log(v_lo), math.log(v_hi)]

    def steady(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        ss = steady_state(params, np.exp(x), aging)
        return np.asarray(ss.stress, float), np.asarray(ss.bonded_fraction, float), np.asarray(ss.stress_slope, float)

    degree = DEGREE
    while True:
        nodes = cheb.chebpts1(degree + 1)
        x = 0.5 * (domain[0] + domain[1]) + 0.5 * (domain[1] - domain[0]) * nodes
        probe = 0.5 * (domain[0] + domain[1]) + 0.5 * (domain[1] - domain[0]) * np.linspace(-0.97, 0.97, 9)
        s_all, n_all, _ = steady(np.r_[x, probe])
        stress = cheb.Chebyshev.fit(x, s_all[: x.size], degree, domain=domain)
        bonded = cheb.Chebyshev.fit(x, n_all[: x.size], degree, domain=domain)
        miss = np.max(np.abs(stress(probe) - s_all[x.size :]) / np.abs(s_all[x.size :]))
        if miss <= TABLE_SHARE * rtol:
            break
        if degree >= MAX_DEGREE:
            return None
        degree *= 2
    # the lag C varies over orders of magnitude towards the fold: its degree is raised until the fit holds at
    # the probes to LAG_SHARE of |C|, or of S' tau (a lag shorter than a bond's life changes nothing)
    lag_degree = LAG_DEGREE
    probe_c, _u, probe_n = _lags(params, aging, probe)
    tau = params.bonds.bond_time
    floor = np.abs(stress.deriv()(probe) / np.exp(probe)) * tau  # lags below a bond's life
    floor_n = np.abs(bonded.deriv()(probe) / np.exp(probe)) * tau
    while True:
        x_c = 0.5 * (domain[0] + domain[1]) + 0.5 * (domain[1] - domain[0]) * cheb.chebpts1(lag_degree + 1)
        c_nodes, u_nodes, n_nodes = _lags(params, aging, x_c)
        lag = cheb.Chebyshev.fit(x_c, c_nodes, lag_degree, domain=domain)
        bonded_lag = cheb.Chebyshev.fit(x_c, n_nodes, lag_degree, domain=domain)
        if np.all(np.abs(lag(probe) - probe_c) <= LAG_SHARE * (np.abs(probe_c) + floor)) and np.all(
            np.abs(bonded_lag(probe) - probe_n) <= LAG_SHARE * (np.abs(probe_n) + floor_n)
        ):
            break
        if lag_degree >= MAX_DEGREE:
            return None
        lag_degree *= 2
    energy = cheb.Chebyshev.fit(x_c, u_nodes, lag_degree, domain=domain)
    return Manifold(v_lo, v_hi, stress, stress.deriv(), stress.deriv(2), bonded, lag, lag.deriv(), energy, bonded_lag)


def _lags(params: Parameters, aging: bool, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """C, the steady bond energy and C_N/N0 at velocities e^x."""
    c, u, n = zip(*(_lag(params, float(math.exp(xk)), aging) for xk in x), strict=True)
    return np.array(c), np.array(u), np.array(n)


def effective(m: Manifold, v: float, vp: float, k_block: float) -> tuple[float, float, float]:
    """(S_eff(V), dV/dt, neglected stress) on the first-order slow manifold through the block."""
    # one source with the glide's compiled field (glide._effective): past the first-order manifold's own fold
    # (S_eff' <= 0) nothing quasi-steady is left, and the neglected stress reads OFF_MANIFOLD
    s_eff, a1, neglected, _slope = glide_ode.effective(*m.stacked(), v, vp, k_block, OFF_MANIFOLD)
    return s_eff, a1, neglected


def allowed_neglect(m: Manifold, v: float, vp: float, sigma: float, tol: float) -> float:
    """The neglected stress a stretch through the block may carry at V: ``tol`` |sigma|, or tol S'|Vp - V| where that
    is larger (a slider creeping far below the puller), at most NEGLECT_CAP times larger.

    The neglected stress d is the error of sigma = S_eff(V) at a given V, i.e. an error d/S' of the slider's
    velocity; through the block the true stress e leaves the reduced one as de/dt = -(K/S')(e - d) (sigma' =
    K (Vp - V)), so with d <= tol S'|Vp - V| it drifts at most tol |sigma'|: by tol times its own change over the
    stretch.  Near a fold (S' -> 0, S'|Vp - V| < |sigma|) the bound is tol |sigma| as before: there the slider's
    velocity at the stretch's end, d/S' off, decides what the cohorts do next (the stick chains' onset at V <
    V0/100: with the velocity's error alone bounded, at NEGLECT_CAP tol |sigma|, the paper's cycle at rtol 1e-3 began
    its stick 4e-3 late).  The cap bounds the velocity's error on the creep branch, d/(S' V) ~ d/|sigma| there.
    """
    return glide_ode.allowance(m.values(v)[1], v, vp, sigma, tol, NEGLECT_CAP)


def _effective_stress(m: Manifold, v: np.ndarray, vp: float, k_block: float) -> np.ndarray:
    """S_eff at many velocities (the first element of :func:`effective`)."""
    stress, dstress, _d2, lag, _dlag, _n = m.many(np.log(v))
    slope = dstress / v
    return stress + lag * k_block * (vp - v) / slope


def effective_bonded(m: Manifold, v: Any, vp: float, k_block: float, block: bool = True) -> Any:
    """N/N0 on the first-order slow manifold (with its lag, as :func:`effective`'s stress) at one or many V; under
    velocity control the steady N."""
    x = np.log(v)
    if not block:
        return m.bonded(x)
    _s, dstress, _d2, _lag, _dlag, bonded = m.many(x)
    return bonded + m.bonded_lag(x) * k_block * (vp - v) / (dstress / v)


def entry_velocity(m: Manifold, sigma: float, v: float, vp: float, k_block: float, rtol: float) -> float | None:
    """The velocity on the slow manifold carrying ``sigma`` near ``v``, if the state lies on it within tolerance."""
    branch = m.rising(v)
    if branch is None:
        return None
    lo, hi = branch
    s_eff, a1, neglected = effective(m, v, vp, k_block)
    tol = THETA * rtol * abs(sigma)
    if not (math.isfinite(a1) and abs(s_eff - sigma) <= tol):
        return None
    if not neglected <= 0.5 * allowed_neglect(m, v, vp, sigma, THETA * rtol):
        return None
    for _ in range(30):  # Newton on S_eff(V) = sigma (S_eff' ~ S' > 0 on the stable branch)
        s_eff, _a, _n = effective(m, v, vp, k_block)
        slope = m.values(v)[1]
        step = (s_eff - sigma) / slope
        v -= step
        if not (lo < v < hi):
            return None
        if abs(step) <= 1e-14 * v:
            return v
    return None


@dataclass
class Glide:
    """A reduced stretch: its rows (kernel layout) and where it ended."""

    t: float
    v: float
    sigma: float
    rows: np.ndarray
    done: bool  # reached t_end (else the reduction's error estimate or its table ended it)
    sample_index: int
    bonded: float  # N and bond energy at its end (the bookkeeping continues from them)
    energy: float


def glide(
    m: Manifold,
    params: Parameters,
    *,
    t: float,
    t_end: float,
    v: float,
    x: float,
    puller: float,
    vp: float,
    k_block: float,
    block: bool,
    rtol: float,
    acc: np.ndarray,
    bonded: float,
    energy: float,
    sample_times: np.ndarray,
    sample_index: int,
) -> Glide | None:
    """Advance the reduced description from t towards t_end (block: the ODE above; velocity: steady sliding).

    ``acc`` (born, broken, work, dissipation, steps, rejected, integral of sigma dt) is updated in place; ``bonded`` and
    ``energy`` are the cohorts' N and bond energy at entry, so that the bookkeeping stays continuous.
    """
    b = params.bonds
    n0, tau = b.site_density, b.bond_time
    tol = THETA * rtol
    lo, hi = m.rising(v) or (m.v_lo, m.v_hi)
    y0 = np.array([v, 0.0, 0.0, 0.0])
    atol = np.array([1e-9 * v, 1e-12 * n0, 1e-30, 1e-30])
    stack, off, scl = m.stacked()
    reduced = dict(lo=lo, hi=hi, vp=vp, k_block=k_block, block=block, n0=n0, tau=tau, cap_off=OFF_MANIFOLD)
    h_first = glide_ode.initial_step(stack, off, scl, **reduced, t0=t, t_end=t_end, v=v, rtol=1e-3 * rtol,
                                     atol_v=atol[0])  # fmt: skip
    sol: Any
    if GLIDE_SOLVER == "solve_ivp":
        from scipy.integrate import solve_ivp

        rhs, events = glide_ode.reference_field(stack, off, scl, **reduced, tol=tol, cap=NEGLECT_CAP)
        sol = solve_ivp(
            rhs, (t, t_end), y0, method="DOP853", rtol=1e-3 * rtol, atol=atol, events=events, dense_output=True,
            first_step=h_first,
        )  # fmt: skip
    else:
        sol = glide_ode.solve(
            stack, off, scl, **reduced, tol=tol, cap=NEGLECT_CAP, t0=t, t_end=t_end, y0=y0, rtol=1e-3 * rtol,
            atol=atol, h_first=h_first,
        )  # fmt: skip
    if not (np.all(np.isfinite(sol.y[:, -1])) and sol.y[0, -1] > 0.0 and sol.t.size > 1):
        return None  # the stretch could not be followed (the caller leaves it to the cohorts)
    t_stop = float(sol.t[-1])
    done = sol.status == 0 and t_stop >= t_end
    # rows at the ODE's own steps, and at least ROWS over the stretch (a plot of the trace); the summaries come
    # from the solution (the integral of sigma dt, the extremes of the steps), not from the rows
    times = np.unique(np.r_[sol.t, np.linspace(t, t_stop, ROWS)])
    if sample_times.size:
        inside = (sample_times > t) & (sample_times <= t_stop + 1e-12 * max(t_stop, 1.0))
        times = np.r_[sample_times[inside]]
        sample_index = int(np.searchsorted(sample_times, t_stop + 1e-12 * max(t_stop, 1.0), side="right"))
    else:
        times = times[times > t]
    y = sol.sol(times) if times.size else np.empty((4, 0))
    vel = y[0]
    logv = np.log(vel)
    if block:
        sigma = _effective_stress(m, vel, vp, k_block)
        pull = puller + vp * (times - t)
        pos = pull - sigma / k_block
    else:
        sigma = m.stress(logv)
        pos = x + vp * (times - t)
        pull = pos
    nn = n0 * effective_bonded(m, vel, vp, k_block, block)
    uu = m.energy(logv)
    born = acc[0] + y[1]
    broken = acc[1] + y[1] - (nn - bonded)
    work = acc[2] + y[2]
    dissipation = acc[3] + y[3] - (uu - energy)
    impulse, impulse_end = _stress_integral(sol, m, vp, k_block, block, (lo, hi), t, t_stop, times)
    stepped = (sol.t > t) & (sol.t <= t_stop)
    inner = sol.t[stepped]
    v_inner = np.clip(sol.y[0][stepped], lo, hi)
    sigma_inner = _effective_stress(m, v_inner, vp, k_block) if block else m.stress(np.log(v_inner))
    extremes = _extremes_per_row(sigma, vel, times, inner, sigma_inner, sol.y[0][stepped], acc)
    rows = np.c_[times, sigma, nn, vel, pos, pull, born, broken, work, dissipation, uu, acc[6] + impulse, extremes]
    end = sol.sol(t_stop)
    v_end = float(end[0])
    sigma_end = effective(m, v_end, vp, k_block)[0] if block else float(m.stress(math.log(v_end)))
    acc[0] += end[1]
    acc[2] += end[2]
    nn_end = n0 * float(effective_bonded(m, v_end, vp, k_block, block))
    acc[1] += end[1] - (nn_end - bonded)
    u_end = float(m.energy(math.log(v_end)))
    acc[3] += end[3] - (u_end - energy)
    acc[4] += max(1, sol.t.size - 1)
    acc[6] += impulse_end
    return Glide(t_stop, v_end, sigma_end, rows, done, sample_index, nn_end, u_end)


def _extremes_per_row(sigma, vel, times, inner, sigma_inner, v_inner, acc):  # type: ignore[no-untyped-def]
    """The extremes of the ODE's accepted steps closed by each row (the solver's own states, not the rows), as
    kernel._write_row writes them: columns lowest, highest stress, their times (the row's own unless a step went
    beyond it), fastest V; the steps after the last row are left in acc[7:12] for the next row."""
    closing = np.searchsorted(times, inner, side="left")
    ahead = closing < times.size
    lowest = np.array(sigma, dtype=float)
    np.minimum.at(lowest, closing[ahead], sigma_inner[ahead])
    highest = np.array(sigma, dtype=float)
    np.maximum.at(highest, closing[ahead], sigma_inner[ahead])
    fastest = np.array(vel, dtype=float)
    np.maximum.at(fastest, closing[ahead], v_inner[ahead])
    t_low, t_high = np.array(times, dtype=float), np.array(times, dtype=float)
    # each extreme's step (the earliest on a tie), where it is beyond the row's own stress
    if times.size:
        row = np.minimum(closing, times.size - 1)
        for value, when, sign in ((lowest, t_low, -1.0), (highest, t_high, 1.0)):
            beyond = ahead & (sigma_inner == value[row]) & (sign * sigma_inner > sign * np.asarray(sigma)[row])
            found, first = np.unique(closing[beyond], return_index=True)
            when[found] = inner[beyond][first]
        carried = [acc[7] < lowest[0], acc[8] > highest[0]]
        lowest[0], highest[0], fastest[0] = min(lowest[0], acc[7]), max(highest[0], acc[8]), max(fastest[0], acc[11])
        t_low[0] = acc[9] if carried[0] else t_low[0]
        t_high[0] = acc[10] if carried[1] else t_high[0]
        acc[7:12] = (np.inf, -np.inf, np.nan, np.nan, -np.inf)
    for k in np.flatnonzero(~ahead):  # the steps after the last row: the next row's
        if sigma_inner[k] < acc[7]:
            acc[7], acc[9] = sigma_inner[k], inner[k]
        if sigma_inner[k] > acc[8]:
            acc[8], acc[10] = sigma_inner[k], inner[k]
        acc[11] = max(acc[11], v_inner[k])
    return np.c_[lowest, highest, t_low, t_high, fastest]


def _stress_integral(sol, m, vp, k_block, block, bounds, t, t_stop, times):  # type: ignore[no-untyped-def]
    """The integral of sigma dt from t at ``times`` and at t_stop: Gauss (4 points) over the ODE's own steps
    on its dense output, so that a mean stress does not depend on which rows are written."""
    cut = np.r_[t, sol.t[(sol.t > t) & (sol.t < t_stop)], times[(times > t) & (times < t_stop)], t_stop]
    edges = np.unique(cut)
    half = 0.5 * np.diff(edges)
    nodes = (0.5 * (edges[1:] + edges[:-1]))[:, None] + half[:, None] * kernel.GL4_X[None, :]
    vel = np.clip(sol.sol(nodes.ravel())[0], *bounds)
    sigma = _effective_stress(m, vel, vp, k_block) if block else m.stress(np.log(vel))
    total = np.r_[0.0, np.cumsum((sigma.reshape(nodes.shape) @ kernel.GL4_W) * half)]
    return np.interp(times, edges, total), float(total[-1])


#: every table built in this process, one per exact request (steady curve, aging, range, rtol): a pure memo, so a
#: table is the same whoever asked first and a run's answer never depends on what the process ran before (a run
#: reuses only the tables it used itself: ``own`` in :func:`manifold_for`)
_BUILT: dict[tuple, Manifold | None] = {}
#: requests remembered at most (a sweep over many parameter sets forgets the oldest)
BUILT_KEPT = 64


def manifold_for(
    params: Parameters,
    aging: bool,
    lo: float,
    hi: float,
    build_hi: float,
    rtol: float,
    own: list[Manifold],
    build: bool = True,
) -> Manifold | None:
    """A manifold covering [lo, hi] at ``rtol``: one of the run's ``own`` tables, or one built up to ``build_hi``
    (and added to ``own``) so that the run's later stretches reuse it.

    ``build=False``: only one of the run's own (None if none covers).  A table built for the same request by an
    earlier run in the process is taken from the memo; it is the table this run would build.
    """
    from ..quasistatic.jump import steady_curve_key

    for m in own:
        if m.covers(lo, hi):
            return m
    if not build:
        return None
    key = (steady_curve_key(params), aging, lo, max(hi, build_hi), rtol)  # the block's stiffness plays no part
    if key not in _BUILT:
        _BUILT[key] = build_manifold(params, aging, lo, max(hi, build_hi), rtol)
        for old in list(_BUILT)[:-BUILT_KEPT]:
            del _BUILT[old]
    m = _BUILT[key]
    if m is not None:
        own.append(m)
        del own[:-8]
    return m


def steady_glide(
    params: Parameters,
    *,
    t: float,
    t_end: float,
    x: float,
    puller: float,
    vp: float,
    sigma: float,
    steady: tuple[float, float, float],
    bonded: float,
    energy: float,
    k_block: float,
    block: bool,
    acc: np.ndarray,
    sample_times: np.ndarray,
    sample_index: int,
) -> Glide:
    """Steady sliding at vp from t to t_end, the population the steady one (S, N of the steady solver).

    ``steady`` = (S, N, S') at vp.  Under velocity control sigma = S(vp) (the cohorts' limit; they are within
    THETA rtol of it at entry).  Through the block the rest of the cohorts' stress, d = sigma - S, relaxes
    quasi-statically, d' = -(K/S') d (the slider at vp + d/S'), exact to first order in d.
    """
    b = params.bonds
    s_ss, n_ss, slope = steady
    times = np.linspace(t, t_end, ROWS + 1)[1:]
    if sample_times.size:
        inside = (sample_times > t) & (sample_times <= t_end + 1e-12 * max(t_end, 1.0))
        times = sample_times[inside]
        sample_index = int(np.searchsorted(sample_times, t_end + 1e-12 * max(t_end, 1.0), side="right"))
    birth = (b.site_density - n_ss) / b.bond_time
    rate = k_block / slope if block else 0.0
    d0 = sigma - s_ss if block else 0.0

    def state(dt: np.ndarray) -> tuple[np.ndarray, ...]:
        decay = np.exp(-rate * dt)
        stress = s_ss + d0 * decay
        velocity = vp + d0 * decay / slope if block else vp + 0.0 * dt
        pull = puller + vp * dt
        pos = pull - stress / k_block if block else x + vp * dt
        # the integral of d over the stretch, with its limit d0 dt where the relaxation is slow
        shed = d0 * dt if rate * np.max(np.atleast_1d(dt), initial=0.0) < 1e-8 else d0 * -np.expm1(-rate * dt) / rate
        work = vp * (s_ss * dt + shed)
        dissipation = s_ss * vp * dt + (vp + s_ss / slope) * shed if block else work
        return stress, velocity, np.where(block, pull, pos), pos, work, dissipation, s_ss * dt + shed

    dt = times - t
    stress, velocity, pull, pos, work, dissipation, impulse = state(dt)
    one = np.ones_like(times)
    end = state(np.array([t_end - t]))
    rows = np.c_[
        times, stress, n_ss * one, velocity, pos, pull, acc[0] + birth * dt, acc[1] + birth * dt - (n_ss - bonded),
        acc[2] + work, acc[3] + dissipation, energy * one, acc[6] + impulse,
        _extremes_per_row(
            stress, velocity, times, np.r_[times, t_end], np.r_[stress, end[0]], np.r_[velocity, end[1]], acc
        ),
    ]  # fmt: skip
    acc[0] += birth * (t_end - t)
    acc[1] += birth * (t_end - t) - (n_ss - bonded)
    acc[2] += float(end[4][0])
    acc[3] += float(end[5][0])
    acc[4] += 1
    acc[6] += float(end[6][0])
    return Glide(t_end, float(end[1][0]), float(end[0][0]), rows, True, sample_index, n_ss, energy)
