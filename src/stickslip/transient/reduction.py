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
    return Manifold(
        v_lo, v_hi, stress, stress.deriv(), stress.deriv(2), bonded, lag_slope, lag_slope.deriv(), energy
    )
