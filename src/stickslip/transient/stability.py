r"""Linear stability of steady sliding through the block: the interface response Z(s) and Kc.

Perturb the slider of a block sliding steadily at V0 by xi(t) = xi e^{st}.
Linearising Eq 1 in the history form along the characteristics
(docs/transient.md section 6) gives the stress response sigma = Z(s) xi with

    Z(s) = [sum W Phi][sum W f e^{-sa}] / (B0 tau + sum W e^{-sa})  -  sum W Phi f  +  sum W f' (1 - e^{-sa}),

over the steady cohorts (weight W, age a, force f, stiffness f'), B0 = (N0 - N)/tau, and

    Phi(a; s) = int_0^a r(a') [ (lambda/kT) f'(a') (e^{-s(a-a')} - e^{-sa}) + s g(a') e^{-s(a-a')} ] da',
    g(a') = a' e^{-V0/Va} / (tau_a Va)   (the aging term's velocity sensitivity; 0 without aging).

The block (sigma = -K xi for a fixed puller) closes the loop: eigenvalues are
the roots of Z(s) + K = 0.  Z(0) = 0, Z(s) ~ s dsigma_ss/dV for small s (the
quasi-static limit, checked in the tests), Z(inf) = the instantaneous
stiffness of the bonds.  Steady sliding is unstable when Z(s) < -K for some
real s > 0 (a real root, creep that runs away) or when Z(i w) crosses the
negative real axis at -K (oscillation).  Kc is the largest such K.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..errors import ParameterError
from ..parameters import Parameters
from .model import aging_age, chain_force, log_hazard, steady_population

#: frequencies / growth rates scanned, in units of 1/tau: from 1e-6 to 1e4
SCAN = np.geomspace(1e-6, 1e6, 561)
#: fastest velocity analysed, in units of dl_m/tau (beyond it the steady cohorts are below float resolution)
FASTEST = 1e6
#: age cells of the steady population used for Z (finer than the solver's default)
CELL_HAZARD = 0.002


@dataclass(frozen=True)
class Response:
    """Z(s) (Pa/m) at complex s (1/s) for steady sliding at ``velocity``."""

    velocity: float
    s: np.ndarray
    z: np.ndarray


def _stiffness(extension: np.ndarray, params: Parameters) -> np.ndarray:
    b = params.bonds
    y = extension / b.max_extension
    d = 1.0 - y * y
    return b.chain_stiffness * (1.0 + y * y) / (d * d)


def interface_response(params: Parameters, velocity: float, s: np.ndarray, aging: bool = True) -> Response:
    """Z(s) of the module docstring at the complex rates ``s`` (1/s)."""
    if not (isinstance(velocity, (int, float)) and math.isfinite(velocity) and velocity > 0):
        raise ParameterError(f"velocity: expected a positive sliding velocity in m/s, got {velocity!r}")
    b = params.bonds
    fastest = FASTEST * b.max_extension / b.bond_time
    if velocity > fastest:
        raise ParameterError(
            f"velocity: {velocity:.3g} m/s is beyond {FASTEST:.0e} x the set's dl_m/tau ({fastest:.3g} m/s): chains"
            " would reach full extension in a negligible fraction of a bond's life; check the unit"
        )
    a, w, width, f, fp, r, gv = _cells(params, float(velocity), aging)
    birth = (b.site_density - w.sum()) / b.bond_time
    s = np.atleast_1d(np.asarray(s, dtype=complex))
    z = _response_kernel()(s, a, w, width, f, fp, r, gv, b.force_sensitivity, birth * b.bond_time)
    return Response(float(velocity), s, z)


@lru_cache(maxsize=32)
def _cells(params: Parameters, velocity: float, aging: bool) -> tuple[np.ndarray, ...]:
    """Steady cohorts at ``velocity`` with force, stiffness, hazard and aging sensitivity (cached)."""
    g = params.aging
    pop = steady_population(params, velocity, aging, cell_hazard=CELL_HAZARD, rule="midpoint")
    a, w, e = pop.age, pop.weight, pop.extension
    f = chain_force(e, params)
    fp = _stiffness(e, params)
    r = np.exp(np.minimum(log_hazard(e, a, velocity, params, aging), 700.0))
    aged = aging_age(a, params)  # t_a, or the saturating extension's t_s (1 - e^(-t_a/t_s))
    gv = aged * (math.exp(-velocity / g.aging_velocity) / (g.aging_time * g.aging_velocity)) if aging else 0.0 * a
    # cell widths: the midpoints a_k are centred in cells that tile [0, a_end]
    width = np.empty_like(a)
    left = 0.0
    for k, mid in enumerate(a):
        width[k] = 2.0 * (mid - left)
        left += width[k]
    return a, w, width, f, fp, r, gv


def _phi1(x):  # type: ignore[no-untyped-def]
    """(1 - e^{-x})/x for complex x, exact near 0."""
    if abs(x) < 1e-4:
        return 1.0 - x / 2.0 + x * x / 6.0
    return (1.0 - np.exp(-x)) / x


def _response_sum(s, a, w, width, f, fp, r, gv, c_f, birth_tau):  # type: ignore[no-untyped-def]
    out = np.empty(s.size, dtype=np.complex128)
    for j in range(s.size):
        sj = s[j]
        e_acc = 0.0 + 0.0j  # int_0^a q1 e^{-s(a-a')}, by recursion over the cells
        r_acc = 0.0 + 0.0j  # int_0^a q2
        sum_wphi = 0.0 + 0.0j
        sum_wfe = 0.0 + 0.0j
        sum_we = 0.0 + 0.0j
        sum_wphif = 0.0 + 0.0j
        sum_inst = 0.0 + 0.0j
        for k in range(a.size):
            # the integrand is taken constant on each cell and e^{-s(a-a')} integrated exactly:
            # int over a width d of e^{-s u} du = d (1 - e^{-sd})/(sd)
            d = width[k]
            q1 = r[k] * (c_f * fp[k] + sj * gv[k])
            q2 = r[k] * c_f * fp[k]
            half = _phi1(sj * 0.5 * d) * 0.5 * d
            full = _phi1(sj * d) * d
            e_mid = e_acc * np.exp(-sj * 0.5 * d) + q1 * half
            r_mid = r_acc + q2 * 0.5 * d
            e_acc = e_acc * np.exp(-sj * d) + q1 * full
            r_acc = r_acc + q2 * d
            ea = np.exp(-sj * a[k])
            phi = e_mid - ea * r_mid
            sum_wphi += w[k] * phi
            sum_wfe += w[k] * f[k] * ea
            sum_we += w[k] * ea
            sum_wphif += w[k] * phi * f[k]
            sum_inst += w[k] * fp[k] * (1.0 - ea)
        out[j] = sum_wphi * sum_wfe / (birth_tau + sum_we) - sum_wphif + sum_inst
    return out


_KERNEL: list = []


def _response_kernel():  # type: ignore[no-untyped-def]
    if not _KERNEL:
        from numba import njit

        global _phi1
        _phi1 = njit(cache=True)(_phi1)
        _KERNEL.append(njit(cache=True)(_response_sum))
    return _KERNEL[0]


@dataclass(frozen=True)
class CriticalStiffness:
    """Kc (Pa/m) and how it arises; see :func:`critical_stiffness`."""

    value: float
    mode: str  # "real" (runaway creep), "oscillatory", or "none" (stable for every K > 0)
    rate: float  # growth rate or angular frequency (1/s) at the threshold
    message: str


def critical_stiffness(params: Parameters, velocity: float, aging: bool = True) -> float:
    """Kc (Pa/m): steady sliding at ``velocity`` through a block of stiffness K is linearly stable iff K > Kc.

    Returns 0.0 when steady sliding is stable for every stiffness (never NaN).
    :func:`critical_stiffness_details` gives the mode and a message.
    """
    return critical_stiffness_details(params, velocity, aging).value


def critical_stiffness_details(params: Parameters, velocity: float, aging: bool = True) -> CriticalStiffness:
    """Kc with the unstable mode (real runaway or oscillation) and its rate."""
    tau = params.bonds.bond_time
    rates = SCAN / tau
    real = interface_response(params, velocity, rates, aging).z.real
    k_real = float(max(0.0, -real.min()))
    s_real = float(rates[int(np.argmin(real))])
    z_im = interface_response(params, velocity, 1j * rates, aging).z
    k_osc, w_osc = 0.0, 0.0
    crossing = np.flatnonzero(np.sign(z_im.imag[1:]) != np.sign(z_im.imag[:-1]))
    for k in crossing:
        if z_im[k].real >= 0 and z_im[k + 1].real >= 0:
            continue  # crosses the positive real axis: no stiffness K > 0 puts a root there
        lo, hi = rates[k], rates[k + 1]
        zl, zh = z_im[k], z_im[k + 1]
        for _ in range(30):  # bisection on Im Z(i w) in log w
            mid = math.sqrt(lo * hi)
            zm = interface_response(params, velocity, np.array([1j * mid]), aging).z[0]
            if np.sign(zm.imag) == np.sign(zl.imag):
                lo, zl = mid, zm
            else:
                hi, zh = mid, zm
        z_cross = 0.5 * (zl + zh)
        if -z_cross.real > k_osc:
            k_osc, w_osc = float(-z_cross.real), float(math.sqrt(lo * hi))
    if k_real == 0.0 and k_osc == 0.0:
        return CriticalStiffness(0.0, "none", 0.0, "steady sliding is linearly stable for every stiffness")
    if k_real >= k_osc:
        return CriticalStiffness(
            k_real, "real", s_real, f"below Kc = {k_real:.6g} Pa/m a perturbation grows without oscillating"
        )
    return CriticalStiffness(
        k_osc, "oscillatory", w_osc, f"below Kc = {k_osc:.6g} Pa/m oscillations at {w_osc / (2 * math.pi):.4g} Hz grow"
    )
