"""How much do the predictions rest on the aging parameters tau_a and V_a? (docs/extensions.md section 2)

The joint steady fit's 95 % region of (tau_a, V_a), with the predictions recomputed on its boundary.  The profile
is linearised (:func:`region_points` with ``refit=False``: the other free parameters follow their conditional
mean given (tau_a, V_a) under the fit's covariance) or exact (``refit=True``: the steady fit rerun with tau_a and
V_a fixed); :func:`chi_square` checks where each point really lies.  ``scripts/sensitivity_table.py`` regenerates
the slow numbers.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from ..parameters import Parameters

AGING_KEYS = ("aging.aging_time", "aging.aging_velocity")
LEVEL = 0.95
STICK_VELOCITY = 100e-6  # m/s: Table 1's first cycle
#: a prediction is robust when it moves by at most this fraction of its best-fit value over the region
TOLERANCE = 0.1


#: The 95 % region of the shipped steady curve (scripts/sensitivity_table.py prints it; a test checks that each
#: point lies at Delta chi^2 = 5.99 and that N0, tau are the profile's): label, tau_a (s), V_a (m/s), N0 (1/m^2),
#: tau (s), Delta chi^2 above the minimum 19.698925 (24 points, stated 2 % errors).
REGION_95 = (
    ("best fit", 0.0009318758459178728, 0.0004383906238903578, 122303995259147.42, 0.0002193239075671391, 0.0),
    ("0°", 0.0010822607431585356, 0.0004383906238903578, 116697339109207.55, 0.00024267811755658995, 5.9914),
    ("45°", 0.0009918988951603802, 0.000696726097030769, 121742013119143.77, 0.0002098837324011673, 5.9914),
    ("90°", 0.0009318758459178728, 0.00087905474063078, 124813910502334.56, 0.00019342425254676088, 5.9915),
    ("135°", 0.0008564297194734126, 0.0008203369082773787, 130016715740618.23, 0.00018037401909477534, 5.9917),
    ("180°", 0.0008267292679966621, 0.0004383906238903578, 128338629701633.06, 0.00019934993861416082, 5.9912),
    ("225°", 0.0008676807209302629, 0.00025810640297309453, 117866968623693.36, 0.0002484800084764548, 5.9915),
    ("270°", 0.0009318758459178728, 0.00023865252038424425, 114235688950335.73, 0.00026747327094343913, 5.9913),
    ("315°", 0.0010027255649499, 0.0002544889355745414, 113214904568136.02, 0.0002717762506224238, 5.9913),
)


def stored_region(base: Parameters | None = None) -> list[RegionPoint]:
    """:data:`REGION_95` as parameter sets (the rest of ``base``, default gelatin-glass, as the fit held it)."""
    from ..parameters import load_parameters

    base = load_parameters("gelatin-glass") if base is None else base
    points = []
    for label, aging_time, aging_velocity, sites, bond_time, delta in REGION_95:
        params = base.with_overrides({
            "aging.aging_time": aging_time, "aging.aging_velocity": aging_velocity,
            "bonds.site_density": sites, "bonds.bond_time": bond_time,
        })  # fmt: skip
        points.append(RegionPoint(label, params, delta))
    return points


@dataclass(frozen=True)
class RegionPoint:
    """One parameter set of the study: ``label``, the full parameters, and its chi-square above the best fit."""

    label: str
    params: Parameters
    delta_chi_square: float

    @property
    def aging_time(self) -> float:
        return self.params.aging.aging_time

    @property
    def aging_velocity(self) -> float:
        return self.params.aging.aging_velocity


def steady_fit():  # type: ignore[no-untyped-def]
    """The joint least-squares fit of Eqs 6-8 to the shipped steady curve (free: N0, tau, tau_a, V_a)."""
    from ..fitting.datasets import synthetic_steady_path
    from ..fitting.steady_fit import fit_steady

    return fit_steady(synthetic_steady_path(), method="joint", intervals="delta")


def chi_square(data, params: Parameters, noise_scale: float = 1.0) -> float:  # type: ignore[no-untyped-def]
    """Chi-square of ``params`` on steady ``data`` (SteadyData), errors x ``noise_scale`` (stated errors: 1)."""
    from ..quasistatic.steady import steady_state

    model = np.array([float(steady_state(params, float(v)).stress) for v in data.velocity])
    err = (data.stress_err if data.stress_err is not None else data.stress) * noise_scale
    return float(np.sum(((data.stress - model) / err) ** 2))


@dataclass(frozen=True)
class Region:
    """The best fit of the profile and the boundary points of the region of (tau_a, V_a) the data allow."""

    points: tuple[RegionPoint, ...]  # the first is the profile's minimum
    level: float
    minimum_chi_square: float
    open_directions: tuple[str, ...]  # rays along which Delta chi^2 stayed below the target up to the cap


def profile(fit, aging_time: float, aging_velocity: float, start: Parameters | None = None):  # type: ignore[no-untyped-def]
    """(chi^2, parameters): the steady fit rerun with tau_a and V_a fixed, the fit's other free keys refitted.

    Every key the original fit held fixed (lambda, dl_m, M, T, u0) stays fixed at its value, so the
    profile is conditional on them exactly as the fit is.
    """
    from ..fitting import identify
    from ..fitting.steady_fit import fit_steady

    refitted = [k for k in fit.free_keys if k not in AGING_KEYS]
    base = fit.parameters if start is None else start
    fixed = {k: _value(base, k) for k in identify.STEADY_KEYS if k not in refitted}
    fixed.update({AGING_KEYS[0]: aging_time, AGING_KEYS[1]: aging_velocity})
    refit = fit_steady(fit.data, base.with_overrides(fixed), method="joint", intervals="delta", fix=fixed)
    if not refit.success:
        raise ModelError(f"profile fit at tau_a = {aging_time:.4g} s, V_a = {aging_velocity:.4g} m/s: {refit.reason}")
    return chi_square(fit.data, refit.parameters, fit.noise_scale), refit.parameters


def region_points(fit, n: int = 8, level: float = LEVEL, cap: float = 8.0) -> Region:  # type: ignore[no-untyped-def]
    """The profile's minimum and ``n`` points on the boundary of the ``level`` region of (tau_a, V_a).

    The minimum of the profile chi-square (:func:`profile`) over (ln tau_a, ln V_a) by Nelder-Mead from the
    fit; then along ``n`` rays from it, scaled by the fit's standard errors of ln tau_a and ln V_a, the
    radius where the profile exceeds the minimum by chi2.ppf(level, 2) (5.99 at 95 %), by Brent's method.
    A ray that stays inside up to ``cap`` standard errors ends there and is listed as open.
    """
    from scipy.optimize import brentq, minimize
    from scipy.stats import chi2

    keys = list(fit.free_keys)
    scale = np.sqrt(np.diag(np.asarray(fit.covariance, dtype=float))[[keys.index(k) for k in AGING_KEYS]])
    target = float(chi2.ppf(level, 2))
    centre = np.array([math.log(_value(fit.parameters, k)) for k in AGING_KEYS])

    def at(ln: np.ndarray) -> tuple[float, Parameters]:
        return profile(fit, math.exp(ln[0]), math.exp(ln[1]))

    found = minimize(lambda u: at(centre + scale * u)[0], np.zeros(2), method="Nelder-Mead",
                     options={"xatol": 1e-3, "fatol": 1e-3})  # fmt: skip
    centre = centre + scale * found.x
    lowest, best = at(centre)
    points = [RegionPoint("best fit", best, 0.0)]
    open_rays = []
    for angle in np.linspace(0.0, 2.0 * math.pi, n, endpoint=False):
        direction = np.array([math.cos(angle), math.sin(angle)]) * scale
        label = f"{math.degrees(angle):.0f}°"

        def excess(radius: float, direction: np.ndarray = direction) -> float:
            return at(centre + radius * direction)[0] - lowest - target

        low, high = 0.0, math.sqrt(target)
        while excess(high) < 0 and high < cap:
            low, high = high, min(2.0 * high, cap)
        if excess(high) < 0:
            open_rays.append(label)
            radius = high
        else:
            radius = brentq(excess, low, high, xtol=1e-4)
        chi, params = at(centre + radius * direction)
        points.append(RegionPoint(label, params, chi - lowest))
    return Region(tuple(points), level, lowest, tuple(open_rays))


def _value(params: Parameters, key: str) -> float:
    section, _, name = key.partition(".")
    return float(getattr(getattr(params, section), name))


def quasi_static_predictions(params: Parameters) -> dict[str, float]:
    """Vc (m/s), sigma_c (Pa), and the first stick at 100 um/s from rest and from sigma_c (s, Pa)."""
    from ..quasistatic.critical import critical_minimum
    from ..quasistatic.stick import stick_phase

    # Vc and sigma_c alone (the turnover and the curve's maximum are not shown), on the compiled march: the study
    # searches one curve per point of the region (~20 ms each on numpy, ~1.3 ms compiled; the same to ~1e-13)
    point = critical_minimum(params, compiled=True)
    velocity, stress = (None, None) if point is None else (point.velocity, point.stress)
    rest = stick_phase(params, STICK_VELOCITY, start_stress=0.0)
    cycle = stick_phase(params, STICK_VELOCITY, start_stress=stress)  # None (no minimum) raises, as it should
    return {
        "critical_velocity": _number(velocity),
        "critical_stress": _number(stress),
        "stick_time_from_rest": _number(rest.stick_time),
        "peak_stress_from_rest": _number(rest.peak_stress),
        "stick_time_from_sigma_c": _number(cycle.stick_time),
        "peak_stress_from_sigma_c": _number(cycle.peak_stress),
    }


def stability_predictions(params: Parameters, velocities: Sequence[float] = (100e-6, 120e-6)) -> dict[str, float]:
    """Kc (Pa/m) of Eq 1 at each V0, and V* (m/s) where Kc(V0) equals the block's K (bisection in V0)."""
    from scipy.optimize import brentq

    from ..quasistatic.critical import critical_point
    from ..transient.stability import critical_stiffness

    out = {f"kc_{v * 1e6:g}_um_s": critical_stiffness(params, v) for v in velocities}
    vc = critical_point(params).velocity
    k = params.block.effective_stiffness
    if vc is None:
        out["boundary_velocity"] = math.nan
        return out

    def excess(v: float) -> float:
        return math.log(max(critical_stiffness(params, v), 1e-300) / k)

    low = 0.9 * vc
    out["boundary_velocity"] = (
        float(brentq(excess, low, vc * (1 - 1e-7), xtol=1e-6 * vc)) if excess(low) > 0 else math.nan
    )
    return out


def hold_peaks(params: Parameters, holds: Sequence[float] = (1.0, 10.0), rtol: float = 1e-3) -> dict[str, float]:
    """Peak stress (Pa) on re-pulling at 350 um/s after each hold, through the block with the stick chains."""
    from ..protocols import segments
    from ..transient import run_transient

    out = {}
    for hold in holds:
        protocol = segments([(350e-6, 1.0), (0.0, hold), (350e-6, 8.0)])
        run = run_transient(params, protocol, start="steady", rtol=rtol, stick_population=True)
        out[f"hold_peak_{hold:g}_s"] = float(run.stress[run.time > 1.0 + hold].max())
    return out


@dataclass(frozen=True)
class Spread:
    """min, max and (max - min)/|best| of one prediction over the region; ``robust`` if within ``tolerance``."""

    key: str
    best: float
    low: float
    high: float
    tolerance: float = field(default=TOLERANCE)

    @property
    def relative(self) -> float:
        return (self.high - self.low) / abs(self.best) if self.best else math.inf

    @property
    def robust(self) -> bool:
        return math.isfinite(self.relative) and self.relative <= self.tolerance


def spreads(rows: Sequence[dict[str, float]], tolerance: float = TOLERANCE) -> list[Spread]:
    """One :class:`Spread` per key of ``rows`` (the first row is the best fit); NaN values count as not robust."""
    out = []
    for key in rows[0]:
        values = np.array([r[key] for r in rows], dtype=float)
        low, high = (math.nan, math.nan) if np.isnan(values).any() else (float(values.min()), float(values.max()))
        out.append(Spread(key, float(values[0]), low, high, tolerance))
    return out


def predictions(points: Sequence[RegionPoint], *compute: Callable[[Parameters], dict[str, float]]) -> list[dict]:
    """The merged outputs of each ``compute`` at each point."""
    return [{k: v for f in compute for k, v in f(p.params).items()} for p in points]


def _number(x: float | None) -> float:
    return math.nan if x is None else float(x)
