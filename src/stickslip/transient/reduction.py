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
so a reduced stretch is exact steady sliding.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import chebyshev as cheb

from ..parameters import Parameters

#: share of the local tolerance the reduction may change the stress by (entry and stay)
THETA = 0.1
#: fewest trace rows a reduced stretch writes (the classifier reads the stress of the trace)
ROWS = 64
#: Chebyshev degrees: the steady stress and bonded fraction (raised until the check passes), the lag C
DEGREE = 24
MAX_DEGREE = 96
LAG_DEGREE = 6
#: the steady stress interpolant must agree with the steady solver to this share of rtol between its nodes
TABLE_SHARE = 1e-3


@dataclass
class Manifold:
    """Chebyshev interpolants in ln V over [v_lo, v_hi] of the steady state and its first-order lag."""

    v_lo: float
    v_hi: float
    stress: cheb.Chebyshev  # S(ln V), Pa
    dstress: cheb.Chebyshev  # dS/dlnV
    d2stress: cheb.Chebyshev
    bonded: cheb.Chebyshev  # N/N0
    lag_slope: cheb.Chebyshev  # C(V) S'(V), smooth through the range (C alone diverges at the fold)
    d_lag_slope: cheb.Chebyshev
    energy: cheb.Chebyshev  # bond energy of the steady population (J/m^2)

    def covers(self, lo: float, hi: float) -> bool:
        return self.v_lo <= lo and hi <= self.v_hi

    def values(self, v: float) -> tuple[float, float, float, float, float]:
        """(S, S', S'', C, C') at velocity v (SI)."""
        x = math.log(v)
        s = float(self.stress(x))
        sx = float(self.dstress(x))
        sxx = float(self.d2stress(x))
        slope = sx / v
        curv = (sxx - sx) / (v * v)
        q = float(self.lag_slope(x))
        qv = float(self.d_lag_slope(x)) / v
        lag = q / slope
        dlag = (qv - lag * curv) / slope
        return s, slope, curv, lag, dlag


def _lag(params: Parameters, velocity: float, aging: bool) -> tuple[float, float]:
    """(C, bond energy) at ``velocity``: C = d/ds[Z(s)/s] at s = 0 by a Richardson central difference."""
    from .model import chain_force, log_hazard, steady_population
    from .stability import _response_kernel, _stiffness

    b, g = params.bonds, params.aging
    pop = steady_population(params, velocity, aging, rule="midpoint")
    a, w, e = pop.age, pop.weight, pop.extension
    f = chain_force(e, params)
    fp = _stiffness(e, params)
    r = np.exp(np.minimum(log_hazard(e, a, velocity, params, aging), 700.0))
    gv = a * math.exp(-velocity / g.aging_velocity) / (g.aging_time * g.aging_velocity) if aging else np.zeros_like(a)
    width = _tiling(a)  # cells tiling [0, a_end] around the midpoints
    birth_tau = b.site_density - w.sum()
    eps = 1e-2 * velocity / b.max_extension  # far below the population's slowest rate V/dl_m
    s = np.array([-eps, eps, -2 * eps, 2 * eps], dtype=complex)
    z = _response_kernel()(s, a, w, width, f, fp, r, gv, b.force_sensitivity, birth_tau).real
    q = z / s.real
    c1 = (q[1] - q[0]) / (2 * eps)
    c2 = (q[3] - q[2]) / (4 * eps)
    y = e / b.max_extension
    energy = float(w @ (-0.5 * b.chain_stiffness * b.max_extension**2 * np.log1p(-y * y)))
    return (4 * c1 - c2) / 3, energy


def _tiling(mid: np.ndarray) -> np.ndarray:
    width = np.empty_like(mid)
    left = 0.0
    for k, m in enumerate(mid):
        width[k] = 2.0 * (m - left)
        left += width[k]
    return width


def build_manifold(params: Parameters, aging: bool, v_lo: float, v_hi: float, rtol: float) -> Manifold | None:
    """The interpolants over [v_lo, v_hi]; None when the steady stress cannot be tabulated to its share of rtol."""
    from ..model.steady import steady_state

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
    lag_nodes = 0.5 * (domain[0] + domain[1]) + 0.5 * (domain[1] - domain[0]) * cheb.chebpts1(LAG_DEGREE + 1)
    lags, energies = zip(*(_lag(params, float(math.exp(xk)), aging) for xk in lag_nodes), strict=True)
    slope_nodes = stress.deriv()(lag_nodes) / np.exp(lag_nodes)
    lag_slope = cheb.Chebyshev.fit(lag_nodes, np.array(lags) * slope_nodes, LAG_DEGREE, domain=domain)
    energy = cheb.Chebyshev.fit(lag_nodes, np.array(energies), LAG_DEGREE, domain=domain)
    return Manifold(v_lo, v_hi, stress, stress.deriv(), stress.deriv(2), bonded, lag_slope, lag_slope.deriv(), energy)


def effective(m: Manifold, v: float, vp: float, k_block: float) -> tuple[float, float, float]:
    """(S_eff(V), dV/dt, neglected stress) on the first-order slow manifold through the block."""
    s, s1, s2, c, c1 = m.values(v)
    a0 = k_block * (vp - v) / s1
    da0 = -k_block / s1 - k_block * (vp - v) * s2 / (s1 * s1)
    s_eff = s + c * a0
    ds_eff = s1 + c1 * a0 + c * da0
    a1 = k_block * (vp - v) / ds_eff if ds_eff > 0.0 else math.inf
    neglected = abs(c * (a1 - a0)) + abs(c * c / s1 * a1 * da0)
    return s_eff, a1, neglected


def entry_velocity(m: Manifold, sigma: float, v: float, vp: float, k_block: float, rtol: float) -> float | None:
    """The velocity on the slow manifold carrying ``sigma`` near ``v``, if the state lies on it within tolerance."""
    if not (m.v_lo < v < m.v_hi):
        return None
    s_eff, a1, neglected = effective(m, v, vp, k_block)
    tol = THETA * rtol * abs(sigma)
    if not (math.isfinite(a1) and abs(s_eff - sigma) <= tol and neglected <= 0.5 * tol):
        return None
    for _ in range(30):  # Newton on S_eff(V) = sigma (S_eff' ~ S' > 0 on the stable branch)
        s_eff, _a, _n = effective(m, v, vp, k_block)
        slope = m.values(v)[1]
        step = (s_eff - sigma) / slope
        v -= step
        if not (m.v_lo < v < m.v_hi):
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
) -> Glide:
    """Advance the reduced description from t towards t_end (block: the ODE above; velocity: steady sliding).

    ``acc`` (born, broken, work, dissipation, steps, rejected) is updated in place; ``bonded`` and
    ``energy`` are the cohorts' N and bond energy at entry, so that the bookkeeping stays continuous.
    """
    from scipy.integrate import solve_ivp

    b = params.bonds
    n0, tau = b.site_density, b.bond_time
    tol = THETA * rtol

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        vv = min(max(y[0], m.v_lo), m.v_hi)  # a trial stage may overshoot; the events end the stretch at the edges
        if block:
            s_eff, a1, _n = effective(m, vv, vp, k_block)
        else:
            s_eff, a1 = float(m.stress(math.log(vv))), 0.0
        born = (n0 - n0 * float(m.bonded(math.log(vv)))) / tau
        return np.array([a1, born, s_eff * vp, s_eff * vv])

    def off_manifold(_t: float, y: np.ndarray) -> float:
        s_eff, _a, neglected = effective(m, min(max(y[0], m.v_lo), m.v_hi), vp, k_block)
        return neglected - tol * abs(s_eff)

    def off_table(_t: float, y: np.ndarray) -> float:
        return min(y[0] / m.v_lo - 1.0 - 1e-6, 1.0 - 1e-6 - y[0] / m.v_hi)

    off_manifold.terminal = True  # type: ignore[attr-defined]
    off_table.terminal = True  # type: ignore[attr-defined]
    events = [off_manifold, off_table] if block else []
    y0 = np.array([v, 0.0, 0.0, 0.0])
    sol = solve_ivp(
        rhs, (t, t_end), y0, method="DOP853", rtol=1e-3 * rtol, atol=[1e-9 * v, 1e-12 * n0, 1e-30, 1e-30],
        events=events, dense_output=True,
    )  # fmt: skip
    t_stop = float(sol.t[-1])
    done = sol.status == 0 and t_stop >= t_end
    times = np.unique(np.r_[sol.t, np.linspace(t, t_stop, ROWS)])
    if sample_times.size:
        inside = (sample_times > t) & (sample_times <= t_stop + 1e-12 * max(t_stop, 1.0))
        times = np.r_[sample_times[inside]]
        sample_index = int(np.searchsorted(sample_times, t_stop + 1e-12 * max(t_stop, 1.0), side="right"))
        if not done or times.size == 0 or times[-1] < t_stop:
            times = np.r_[times, t_stop] if not (times.size and times[-1] >= t_stop) else times
    else:
        times = times[times > t]
    y = sol.sol(times) if times.size else np.empty((4, 0))
    vel = y[0]
    logv = np.log(vel)
    if block:
        sigma = np.array([effective(m, vv, vp, k_block)[0] for vv in vel])
        pull = puller + vp * (times - t)
        pos = pull - sigma / k_block
    else:
        sigma = m.stress(logv)
        pos = x + vp * (times - t)
        pull = pos
    nn = n0 * m.bonded(logv)
    uu = m.energy(logv)
    born = acc[0] + y[1]
    broken = acc[1] + y[1] - (nn - bonded)
    work = acc[2] + y[2]
    dissipation = acc[3] + y[3] - (uu - energy)
    rows = np.c_[times, sigma, nn, vel, pos, pull, born, broken, work, dissipation, uu]
    end = sol.sol(t_stop)
    v_end = float(end[0])
    sigma_end = effective(m, v_end, vp, k_block)[0] if block else float(m.stress(math.log(v_end)))
    acc[0] += end[1]
    acc[2] += end[2]
    nn_end = n0 * float(m.bonded(math.log(v_end)))
    acc[1] += end[1] - (nn_end - bonded)
    acc[3] += end[3] - (float(m.energy(math.log(v_end))) - energy)
    acc[4] += max(1, sol.t.size - 1)
    return Glide(t_stop, v_end, sigma_end, rows, done, sample_index)


#: manifolds built so far, per (parameter set, aging): a sweep or a comparison reuses them
_BUILT: dict[tuple[Parameters, bool], list[tuple[Manifold, float]]] = {}


def manifold_for(
    params: Parameters, aging: bool, lo: float, hi: float, build_hi: float, rtol: float
) -> Manifold | None:
    """A manifold covering [lo, hi] at ``rtol``, built up to ``build_hi`` so that later stretches reuse it."""
    built = _BUILT.setdefault((params, aging), [])
    for m, tol in built:
        if m.covers(lo, hi) and tol <= rtol:
            return m
    m = build_manifold(params, aging, lo, max(hi, build_hi), rtol)
    if m is not None:
        built.append((m, rtol))
        del built[:-8]
    return m


_EXTREMA: dict[tuple[Parameters, bool], tuple[float, ...]] = {}


def rising_branch(params: Parameters, aging: bool, v: float) -> tuple[float, float] | None:
    """(lo, hi): the stretch of the steady curve around v between its extrema (S' changes sign at each)."""
    from ..errors import ModelError, ParameterError
    from ..model.critical import find_extrema

    key = (params, aging)
    if key not in _EXTREMA:
        try:
            _EXTREMA[key] = tuple(float(e.velocity) for e in find_extrema(params, aging=aging))
        except (ModelError, ParameterError):
            _EXTREMA[key] = (math.nan,)
    ext = _EXTREMA[key]
    if any(not math.isfinite(e) for e in ext):
        return None
    lo = max([e for e in ext if e < v], default=0.0)
    hi = min([e for e in ext if e > v], default=math.inf)
    return lo, hi


def steady_glide(
    params: Parameters,
    *,
    t: float,
    t_end: float,
    x: float,
    vp: float,
    sigma: float,
    bonded: float,
    energy: float,
    k_block: float,
    block: bool,
    acc: np.ndarray,
    sample_times: np.ndarray,
    sample_index: int,
) -> Glide:
    """Steady sliding at vp from t to t_end: the population is the steady one, sigma and N constant."""
    b = params.bonds
    times = np.linspace(t, t_end, ROWS + 1)[1:]
    if sample_times.size:
        inside = (sample_times > t) & (sample_times <= t_end + 1e-12 * max(t_end, 1.0))
        times = sample_times[inside]
        sample_index = int(np.searchsorted(sample_times, t_end + 1e-12 * max(t_end, 1.0), side="right"))
    dt = times - t
    birth = (b.site_density - bonded) / b.bond_time
    pos = x + vp * dt
    pull = pos + sigma / k_block if block else pos
    one = np.ones_like(times)
    rows = np.c_[
        times, sigma * one, bonded * one, vp * one, pos, pull, acc[0] + birth * dt, acc[1] + birth * dt,
        acc[2] + sigma * vp * dt, acc[3] + sigma * vp * dt, energy * one,
    ]  # fmt: skip
    span = t_end - t
    acc[0] += birth * span
    acc[1] += birth * span
    acc[2] += sigma * vp * span
    acc[3] += sigma * vp * span
    acc[4] += 1
    return Glide(t_end, vp, sigma, rows, True, sample_index)
