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
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..errors import ModelError, ParameterError
from ..numerics.roots import brentq  # scipy.optimize would add 0.3 s to start-up
from ..parameters import Parameters
from ..units import checked_value, refuse_beyond_float
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


def _check_velocity(params: Parameters, velocity: float) -> None:
    """A positive, finite sliding velocity below FASTEST x the set's dl_m/tau, else a ParameterError."""
    refuse_beyond_float(velocity, "velocity")  # 10**400: a ParameterError, not an OverflowError of isfinite
    if not (isinstance(velocity, (int, float)) and math.isfinite(velocity) and velocity > 0):
        raise ParameterError(f"velocity: expected a positive sliding velocity in m/s, got {velocity!r}")
    b = params.bonds
    fastest = FASTEST * b.max_extension / b.bond_time
    if velocity > fastest:
        raise ParameterError(
            f"velocity: {velocity:.3g} m/s is beyond {FASTEST:.0e} × the set's Δl_m/τ ({fastest:.3g} m/s): chains"
            " would reach full extension in a negligible fraction of a bond's life; check the unit"
        )


def interface_response(
    params: Parameters, velocity: float, s: np.ndarray, aging: bool = True, cell_hazard: float = CELL_HAZARD
) -> Response:
    """Z(s) of the module docstring at the complex rates ``s`` (1/s); ``cell_hazard`` sets the age grid."""
    _check_velocity(params, velocity)
    b = params.bonds
    a, w, width, f, fp, r, gv = _cells(params, float(velocity), aging, cell_hazard)
    birth = (b.site_density - w.sum()) / b.bond_time
    s = np.atleast_1d(np.asarray(s, dtype=complex))
    z = _response_kernel()(s, a, w, width, f, fp, r, gv, b.force_sensitivity, birth * b.bond_time)[0]
    return Response(float(velocity), s, z)


@lru_cache(maxsize=32)
def _cells(
    params: Parameters, velocity: float, aging: bool, cell_hazard: float = CELL_HAZARD
) -> tuple[np.ndarray, ...]:
    """Steady cohorts at ``velocity`` with force, stiffness, hazard and aging sensitivity (cached).

    The compiled march of the same cells (``cells._cells``, the reduction's too: ~1 s less per velocity than the
    Python march of :func:`_cells_plain`, which agrees to rounding, tests/test_stability_response_sum.py); the
    Python march where the velocity or the cell count is out of range, for its error in words."""
    from .cells import _steady_cells
    from .model import MAX_CELLS, pack_parameters

    if velocity > 0 and math.isfinite(velocity):
        packed = pack_parameters(params, aging, 1.0)
        a, w, width, f, fp, r, gv, _ = _steady_cells()(float(velocity), packed, float(cell_hazard))
        if a.size < MAX_CELLS:
            return a, w, width, f, fp, r, gv
    return _cells_plain(params, velocity, aging, cell_hazard)


def _cells_plain(
    params: Parameters, velocity: float, aging: bool, cell_hazard: float = CELL_HAZARD
) -> tuple[np.ndarray, ...]:
    """:func:`_cells` by the Python march of model.steady_population (the midpoint rule)."""
    g = params.aging
    pop = steady_population(params, velocity, aging, cell_hazard=cell_hazard, rule="midpoint")
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


def _phi1(x, decay):  # type: ignore[no-untyped-def]
    """(1 - e^{-x})/x for complex x, exact near 0; ``decay`` is e^{-x}, which the caller has."""
    if abs(x) < 1e-4:
        return 1.0 - x / 2.0 + x * x / 6.0
    return (1.0 - decay) / x


def _response_sum(s, a, w, width, f, fp, r, gv, c_f, birth_tau):  # type: ignore[no-untyped-def]
    """Row 0: Z(s) of the module docstring; row 1: the bonded count's response dN/xi = -[sum W Phi] B0 tau /
    (B0 tau + sum W e^{-sa}) (the births' share of the same closure; the quasi-steady reduction's lag of N)."""
    out = np.empty((2, s.size), dtype=np.complex128)
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
            # int over a width d of e^{-s u} du = d (1 - e^{-sd})/(sd).  Two complex exps per cell, e^{-sd/2} (e^{-sd}
            # is its square) and e^{-sa}; five before
            d = width[k]
            q1 = r[k] * (c_f * fp[k] + sj * gv[k])
            q2 = r[k] * c_f * fp[k]
            x = sj * 0.5 * d
            h = np.exp(-x)
            hh = h * h
            half = _phi1(x, h) * 0.5 * d
            full = _phi1(2.0 * x, hh) * d
            e_mid = e_acc * h + q1 * half
            r_mid = r_acc + q2 * 0.5 * d
            e_acc = e_acc * hh + q1 * full
            r_acc = r_acc + q2 * d
            # taken directly: at |s a| ~ 1e-7 the sum cancels to O(s a), and a product carried over the cells, even
            # taken afresh every 64, left Z 8.5e-7 off (tests/test_stability_response_sum.py)
            ea = np.exp(-sj * a[k])
            phi = e_mid - ea * r_mid
            sum_wphi += w[k] * phi
            sum_wfe += w[k] * f[k] * ea
            sum_we += w[k] * ea
            sum_wphif += w[k] * phi * f[k]
            sum_inst += w[k] * fp[k] * (1.0 - ea)
        out[0, j] = sum_wphi * sum_wfe / (birth_tau + sum_we) - sum_wphif + sum_inst
        out[1, j] = -sum_wphi * birth_tau / (birth_tau + sum_we)
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


def _block_terms(mass: float, damping: float) -> tuple[float, float]:
    """The block's mass per unit area (kg/m^2) and viscous damping (Pa s/m), checked as the rig checks them (a value
    with its unit too)."""
    return checked_value("mass", mass, "mass_per_area"), checked_value("damping", damping, "stress_per_velocity")


def _block_polynomial(s: np.ndarray | complex, stiffness: float, mass: float, damping: float) -> np.ndarray | complex:
    """m s^2 + eta s + K (Pa/m): the block's part of the characteristic function D(s) = block + Z(s)."""
    return mass * s * s + damping * s + stiffness


def characteristic(
    params: Parameters,
    velocity: float,
    s: np.ndarray,
    stiffness: float,
    mass: float = 0.0,
    damping: float = 0.0,
    aging: bool = True,
) -> np.ndarray:
    """D(s) = m s^2 + eta s + K + Z(s) (Pa/m): its roots are the eigenvalues of the block on the interface.

    ``mass`` is the block's mass per unit area (kg/m^2), ``damping`` a viscous damping of the slider's
    velocity (Pa s/m, e.g. radiation damping G/(2 c_s)), ``stiffness`` K (Pa/m); docs/extensions.md section 4.
    """
    mass, damping = _block_terms(mass, damping)
    z = interface_response(params, velocity, s, aging)
    return _block_polynomial(z.s, stiffness, mass, damping) + z.z


def resolved_frequency(
    params: Parameters, velocity: float, aging: bool = True, cell_hazard: float = CELL_HAZARD
) -> float:
    """Highest angular frequency (1/s) the age cells of Z resolve: one radian across the widest cell.

    Above it the cohort sums alias (Im Z(i w) changes sign at random): a crossing there is the grid's (its
    K, -Re Z(i w), or m w^2 - Re Z(i w) with a mass, is noise), and Kc ignores it.
    """
    _, _, width, *_ = _cells(params, float(velocity), aging, cell_hazard)
    return float(1.0 / width.max())


def critical_stiffness(
    params: Parameters, velocity: float, aging: bool = True, mass: float = 0.0, damping: float = 0.0
) -> float:
    """Kc (Pa/m): steady sliding at ``velocity`` through a block of stiffness K is linearly stable iff K > Kc.

    ``mass`` (kg/m^2) and ``damping`` (Pa s/m) add the block's inertia and a viscous damping (default 0:
    the paper's massless block).  Returns 0.0 when steady sliding is stable for every stiffness (never
    NaN).  :func:`critical_stiffness_details` gives the mode and a message.

    A damping without a mass is the massless block with a dashpot, D(s) = eta s + K + Z(s): its Hopf point
    solves eta w + Im Z(iw) = 0, Kc = -Re Z(iw), the limit m -> 0 of the block with a mass (Kc then grows by
    m w^2).  The nonlinear solver (:func:`stickslip.transient.run_transient`) takes a damping only with a mass:
    without one its force balance is a differential-algebraic system it does not solve, not a physics limit.
    """
    return critical_stiffness_details(params, velocity, aging, mass, damping).value


def critical_stiffness_details(
    params: Parameters, velocity: float, aging: bool = True, mass: float = 0.0, damping: float = 0.0
) -> CriticalStiffness:
    """Kc with the unstable mode (real runaway or oscillation) and its rate."""
    from ..quasistatic.steady import require_parameters

    require_parameters(params)
    mass, damping = _block_terms(mass, damping)
    # crossings above the resolved frequency are the age grid's, not Z's, with or without a mass: a massless
    # block's scan of a short-lived bond (box draw tau = 64 ns) found 129 of them, each bisected (18 s), and
    # took the largest, Kc = 1.3e15 Pa/m at 6e11 Hz, which moved to 9e7 Hz on a grid twice as fine
    _check_velocity(params, velocity)  # before the resolved frequency's cells: a typed error, not an overflow
    top = resolved_frequency(params, velocity, aging)
    try:
        # raised, not warned: a mass of 1e300 kg/m^2 overflowed m w^2 over the scan and printed a Kc of 4e304 Pa/m
        # beside a warning, a damping of 1e300 Pa s/m "stable for every stiffness" from infinite Im D
        with np.errstate(over="raise", invalid="raise"):
            return critical_from_response(
                _finite_response(params, velocity, aging), SCAN / params.bonds.bond_time, mass, damping, top
            )
    except FloatingPointError:
        raise ModelError(
            f"Kc at {velocity:.6g} m/s through a block of mass {mass:.6g} kg/m^2 and damping {damping:.6g} Pa s/m"
            " leaves the floating-point range: expected a smaller block mass or damping"
        ) from None


def _finite_response(params: Parameters, velocity: float, aging: bool) -> Callable[[np.ndarray], np.ndarray]:
    """:func:`_response`, refused in words where Z(s) leaves the floating-point range (the compiled sums overflow
    silently): its infinities and nans made every step of the scan a sign change of Im D, each bisected (a site
    density of 1e300 1/m^2 took 26 s, then printed a Kc from the real part alone)."""
    z = _response(params, velocity, aging)

    def finite(s: np.ndarray) -> np.ndarray:
        values = z(s)
        if not np.all(np.isfinite(values)):
            b = params.bonds
            raise ModelError(
                f"Kc at {velocity:.6g} m/s: the interface response Z(s) leaves the floating-point range (N0 M ="
                f" {b.site_density * b.chain_stiffness:.3g} Pa/m): expected a smaller bonds.site_density or"
                " bonds.chain_stiffness"
            )
        return values

    return finite


def critical_from_response(
    response: Callable[[np.ndarray], np.ndarray],
    rates: np.ndarray,
    mass: float = 0.0,
    damping: float = 0.0,
    top: float = math.inf,
) -> CriticalStiffness:
    """Kc for any interface response Z(s) (Pa/m) loaded by a block m s^2 + eta s + K.

    A real root s > 0 exists for K < -(m s^2 + eta s + Z(s)); a root crosses the imaginary axis at i w
    where eta w + Im Z(i w) = 0, at K = m w^2 - Re Z(i w).  ``rates`` (1/s) is the scan of s and w;
    crossings above ``top`` (1/s, the resolved frequency) are ignored.
    """
    real = response(rates).real + _block_polynomial(rates, 0.0, mass, damping)
    k_real = float(max(0.0, -real.min()))
    s_real = float(rates[int(np.argmin(real))])

    def crossing_terms(w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d = _block_polynomial(1j * w, 0.0, mass, damping) + response(1j * w)  # D(i w) at K = 0
        return d.imag, -d.real  # (Im D(i w), K that puts a root at i w)

    # a crossing above the resolved frequency is ignored, so Z is not evaluated there (369 of the 561 rates are
    # below it at 120 um/s, 249 at 1 um/s)
    resolved = rates[rates <= top]
    im_d, k_at = crossing_terms(resolved)
    k_osc, w_osc = 0.0, 0.0
    crossing = np.flatnonzero(np.sign(im_d[1:]) != np.sign(im_d[:-1]))
    for k in crossing:
        if k_at[k] <= 0 and k_at[k + 1] <= 0:
            continue  # no stiffness K > 0 puts a root there
        lo, hi = resolved[k], resolved[k + 1]
        il, kl, kh = im_d[k], k_at[k], k_at[k + 1]
        for _ in range(30):  # bisection on Im D(i w) in log w
            mid = math.sqrt(lo * hi)
            im, km = (float(x[0]) for x in crossing_terms(np.array([mid])))
            if np.sign(im) == np.sign(il):
                lo, il, kl = mid, im, km
            else:
                hi, kh = mid, km
        k_cross = 0.5 * (kl + kh)
        if k_cross > k_osc:
            k_osc, w_osc = float(k_cross), float(math.sqrt(lo * hi))
    if k_real == 0.0 and k_osc == 0.0:
        return CriticalStiffness(0.0, "none", 0.0, "steady sliding is linearly stable for every stiffness")
    if k_real >= k_osc:
        return CriticalStiffness(
            k_real, "real", s_real, f"below Kc = {k_real:.6g} Pa/m a perturbation grows without oscillating"
        )
    return CriticalStiffness(
        k_osc, "oscillatory", w_osc, f"below Kc = {k_osc:.6g} Pa/m oscillations at {w_osc / (2 * math.pi):.4g} Hz grow"
    )


def follow_root(
    response: Callable[[np.ndarray], np.ndarray],
    start: complex,
    stiffness_from: float,
    stiffness_to: float,
    mass: float = 0.0,
    damping: float = 0.0,
    steps: int = 20,
) -> complex:
    """The root of m s^2 + eta s + K + Z(s) = 0 that is ``start`` at K = ``stiffness_from``, at ``stiffness_to``.

    Continuation in K (``steps`` equal steps) with Newton's method at each; Z'(s) by a central
    difference (Z is analytic).  Raises ModelError if Newton does not converge.
    """
    s = complex(start)
    for stiffness in np.linspace(stiffness_from, stiffness_to, steps + 1)[1:]:
        for _ in range(50):
            h = 1e-5 * max(abs(s), 1e-12)
            z = response(np.array([s, s + h, s - h]))
            d = _block_polynomial(s, stiffness, mass, damping) + z[0]
            dd = 2.0 * mass * s + damping + (z[1] - z[2]) / (2.0 * h)
            step = d / dd
            s -= step
            if abs(step) <= 1e-10 * max(abs(s), 1e-12):
                break
        else:
            raise ModelError(
                f"root of the characteristic equation lost near s = {s:.6g} 1/s at K = {stiffness:.6g} Pa/m"
            )
    return s


def hopf_root(
    params: Parameters,
    velocity: float,
    factor: float,
    mass: float = 0.0,
    damping: float = 0.0,
    aging: bool = True,
) -> complex:
    """The eigenvalue s (1/s) born at the Hopf point, followed to K = ``factor`` x Kc: Re s is its growth rate."""
    mass, damping = _block_terms(mass, damping)
    kc = critical_stiffness_details(params, velocity, aging, mass, damping)
    if kc.mode != "oscillatory":
        raise ModelError(f"no Hopf point at {velocity:.6g} m/s (mode {kc.mode!r}): {kc.message}")
    z = _response(params, velocity, aging)
    try:
        with np.errstate(over="raise", invalid="raise"):  # raised, as in critical_stiffness_details
            root = follow_root(z, 1j * kc.rate, kc.value, factor * kc.value, mass, damping)
    except FloatingPointError:
        root = complex(math.nan, math.nan)
    if not (math.isfinite(root.real) and math.isfinite(root.imag)):
        raise ModelError(
            f"the Hopf root followed to K = {factor:g} x Kc = {factor * kc.value:.6g} Pa/m leaves the floating-point"
            " range: expected a factor nearer 1"
        )
    return root


def _response(params: Parameters, velocity: float, aging: bool) -> Callable[[np.ndarray], np.ndarray]:
    """Z(s) (Pa/m) of steady sliding at ``velocity``, as a function of s; each s evaluated once per process.

    Kc's scan is the same ~800 rates for any block mass or damping (~1 s at 120 um/s): a second Kc at that
    velocity (another mass, the Hopf root's own Kc) pays only its bisection.  Each Z(s) is computed apart from the
    others (the kernel's outer loop), so a value from the memo is the one a fresh call gives, to the bit.
    """
    memo = _memo(params, float(velocity), bool(aging))

    def z(s: np.ndarray) -> np.ndarray:
        wanted = np.atleast_1d(np.asarray(s, dtype=complex)).tolist()
        missing = [x for x in dict.fromkeys(wanted) if x not in memo]
        if missing:
            values = interface_response(params, velocity, np.array(missing), aging).z.tolist()
            memo.update(zip(missing, values, strict=True))
        return np.array([memo[x] for x in wanted], dtype=complex)

    return z


@lru_cache(maxsize=32)
def _memo(params: Parameters, velocity: float, aging: bool) -> dict[complex, complex]:
    return {}


def real_growth_rates(
    params: Parameters,
    velocity: float,
    stiffness: float,
    mass: float = 0.0,
    damping: float = 0.0,
    aging: bool = True,
) -> np.ndarray:
    """The real positive roots (1/s) of m s^2 + eta s + K + Z(s) = 0 on the scan, ascending: runaway rates.

    Found by a sign change of D on the scan and bracketed to 1e-12; an empty array when none.
    """
    mass, damping = _block_terms(mass, damping)
    rates = SCAN / params.bonds.bond_time

    def d(s: float | np.ndarray) -> np.ndarray:
        return characteristic(params, velocity, np.atleast_1d(s), stiffness, mass, damping, aging).real

    values = d(rates)
    change = np.flatnonzero(np.sign(values[1:]) != np.sign(values[:-1]))
    roots = [
        brentq(lambda x: float(d(x)[0]), rates[k], rates[k + 1], xtol=1e-14 * rates[k], rtol=1e-12) for k in change
    ]
    return np.array(roots, dtype=float)


def unstable_root_count(
    response: Callable[[np.ndarray], np.ndarray],
    stiffness: float,
    rates: np.ndarray,
    mass: float = 0.0,
    damping: float = 0.0,
) -> int:
    """Roots of m s^2 + eta s + K + Z(s) in the right half-plane, by the argument principle.

    The winding of D(i w)/(i w + c)^n for w from 0 to the end of ``rates`` (1/s), n the order of the
    block's polynomial, doubled by the symmetry D(-i w) = conj D(i w); assumes Z has no pole there
    (the interface under velocity control is stable) and that the scan ends where D(i w) has settled.
    The scan is refined until the phase moves by less than 0.5 rad between points.
    """
    order = 2 if mass > 0 else (1 if damping > 0 else 0)
    c = float(rates[len(rates) // 2])

    def f(w: np.ndarray) -> np.ndarray:
        s = 1j * w
        return (_block_polynomial(s, stiffness, mass, damping) + response(s)) / (s + c) ** order

    w = np.concatenate([[0.0], np.asarray(rates, dtype=float)])
    values = f(w)
    for _ in range(12):
        jump = np.abs(np.angle(values[1:] / values[:-1]))
        coarse = np.flatnonzero(jump > 0.5)
        if coarse.size == 0:
            break
        mid = 0.5 * (w[coarse] + w[coarse + 1])
        w = np.insert(w, coarse + 1, mid)
        values = np.insert(values, coarse + 1, f(mid))
    turn = float(np.sum(np.angle(values[1:] / values[:-1])))
    return round(-turn / math.pi)
