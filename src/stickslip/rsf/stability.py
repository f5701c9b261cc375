"""Linear stability of steady sliding: critical stiffness and the period at the Hopf point.

One aging, slip or PRZ state has the closed form k_c = ((b - a')/Dc) (1 + m V^2/(sigma a' Dc)) (a' = a + eta V);
several states or Nagata's law: the stiffness at which the largest real part of the Jacobian's eigenvalues
crosses zero (bisection in log k).  The derivation: docs/rsf.md, "Stability".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError, ParameterError
from ..units import to_si
from .laws import EXP_CAP
from .params import RSFParams
from .system import System

__all__ = ["Stability", "critical_stiffness", "growth_rate", "neutral_period", "stability"]

_CLASSICAL = {"aging", "slip", "prz"}


@dataclass(frozen=True)
class Stability:
    """Stability of steady sliding at ``velocity`` (SI; stiffness in friction per metre, 1/m)."""

    velocity: float
    stiffness: float
    critical_stiffness: float
    critical_stiffness_pa: float | None
    neutral_period: float
    growth_rate: float
    stable: bool
    method: str
    message: str

    def as_dict(self) -> dict[str, object]:
        return dict(self.__dict__)


def _closed_form_applies(p: RSFParams) -> bool:
    return len(p.states) == 1 and p.states[0].law in _CLASSICAL and not p.regularized and p.cutoff is None


def critical_stiffness(params: RSFParams, velocity: float | str) -> float:
    """k_c (1/m) at steady sliding velocity ``velocity``; 0 if steady sliding is stable at any stiffness."""
    velocity = _positive_velocity(velocity)
    if _closed_form_applies(params):
        s = params.states[0]
        a_eff = params.a + params.eta * velocity
        if s.b <= a_eff:
            return 0.0
        inertia = params.mass * velocity**2 / ((params.normal_stress or 1.0) * a_eff * s.dc) if params.mass else 0.0
        kc = (s.b - a_eff) / s.dc * (1.0 + inertia)
        if not math.isfinite(kc):
            raise ModelError(
                f"the critical stiffness at {velocity:.3g} m/s is beyond the floating-point range ((b - a')/Dc ="
                f" {(s.b - a_eff) / s.dc:.3g} 1/m, inertia factor m V^2/(sigma a' Dc) = {inertia:.3g}): check the"
                " mass, normal stress and Dc"
            )
        return kc
    return _numerical_critical(params, velocity)


def neutral_period(params: RSFParams, velocity: float | str) -> float:
    """Period (s) of the neutral oscillation at k = k_c; NaN if there is no Hopf point."""
    velocity = _positive_velocity(velocity)
    kc = critical_stiffness(params, velocity)
    if kc <= 0:
        return math.nan
    if _closed_form_applies(params):
        s = params.states[0]
        a_eff = params.a + params.eta * velocity
        return 2 * math.pi * (s.dc / velocity) * math.sqrt(a_eff / (s.b - a_eff))
    eig = _eigenvalues(params.replace(stiffness=kc), velocity)
    omega = float(np.max(np.abs(eig.imag)))
    return 2 * math.pi / omega if omega > 0 else math.nan


def stability(params: RSFParams, velocity: float | str) -> Stability:
    """Everything about the stability of steady sliding at ``velocity`` with the params' stiffness."""
    velocity = _positive_velocity(velocity)
    kc = critical_stiffness(params, velocity)
    growth = growth_rate(params, velocity)
    stable = params.stiffness > kc
    sigma = params.normal_stress
    method = "closed form" if _closed_form_applies(params) else "eigenvalues of the linearised equations"
    if kc == 0:
        rule = "b V2/(V2+V) <= a V1/(V1+V) + eta V" if params.cutoff else "b <= a + eta V"  # the slopes at V
        message = f"steady sliding is stable at every stiffness (velocity strengthening: {rule})"
    elif stable:
        message = f"stable: k = {params.stiffness:.4g} 1/m is above k_c = {kc:.4g} 1/m; perturbations decay"
    else:
        message = (
            f"unstable: k = {params.stiffness:.4g} 1/m is below k_c = {kc:.4g} 1/m; oscillations grow "
            "(stick-slip, or a blow-up without radiation damping)"
        )
    return Stability(
        velocity=velocity,
        stiffness=params.stiffness,
        critical_stiffness=kc,
        critical_stiffness_pa=None if sigma is None else kc * sigma,
        neutral_period=neutral_period(params, velocity),
        growth_rate=growth,
        stable=bool(stable),
        method=method,
        message=message,
    )


def growth_rate(params: RSFParams, velocity: float | str) -> float:
    """Largest real part (1/s) of the linearised equations' eigenvalues at steady sliding: > 0 means unstable."""
    return float(np.max(_eigenvalues(params, _positive_velocity(velocity)).real))


def _positive_velocity(velocity: float | str) -> float:
    """The velocity in m/s: a number (SI) or a string with its unit ("1 um/s"); positive and finite."""
    if isinstance(velocity, np.ndarray) and velocity.size == 1:
        velocity = velocity.item()
    if isinstance(velocity, (np.floating, np.integer)):
        velocity = float(velocity)
    v = to_si(velocity, "velocity", "velocity")
    if not (math.isfinite(v) and v > 0):
        raise ParameterError(f"velocity: expected a positive sliding velocity, got {velocity!r}")
    return v


def jacobian_at(system: System, y: np.ndarray, load_velocity: float) -> np.ndarray:
    """The Jacobian of the equations at ``y``: analytic where the system has one, else central differences."""
    if system.has_jacobian:
        return np.asarray(system.jacobian(0.0, y, load_velocity), dtype=float)
    jac = np.empty((y.size, y.size))
    for j in range(y.size):
        h = 1e-6 * max(1.0, abs(y[j]))
        up, down = y.copy(), y.copy()
        up[j] += h
        down[j] -= h
        rise = np.array(system.rhs(0.0, up, load_velocity)) - np.array(system.rhs(0.0, down, load_velocity))
        jac[:, j] = rise / (2 * h)
    return jac


def _eigenvalues(params: RSFParams, velocity: float) -> np.ndarray:
    ratio = math.log(velocity) - math.log(params.v_ref)
    if abs(ratio) > EXP_CAP - 10.0:  # the equations' exponentials are capped there: their linearisation is not
        raise ModelError(
            f"velocity: {velocity:.3g} m/s is e^{ratio:.0f} times v_ref = {params.v_ref:.3g} m/s; the equations"
            f" are represented for V/v_ref within about e^±{EXP_CAP - 10:.0f} (give velocities and v_ref of"
            " comparable size)"
        )
    system = System(params)
    try:
        jac = jacobian_at(system, system.steady_y(velocity), velocity)
    except (ZeroDivisionError, OverflowError):  # e.g. m V / sigma underflowing to 0
        jac = np.full((1, 1), np.nan)
    if not np.all(np.isfinite(jac)):
        raise ModelError(
            f"the linearised equations at {velocity:.3g} m/s overflow the floating-point range: these parameters"
            " (a, b, Dc, c, eta, mass, v_ref) are outside what can be computed; check their magnitudes"
        )
    return np.linalg.eigvals(jac)


def _numerical_critical(params: RSFParams, velocity: float) -> float:
    def growth(k: float) -> float:
        return float(np.max(_eigenvalues(params.replace(stiffness=k), velocity).real))

    scale = max(abs(params.b - params.a), params.a) / min(s.dc for s in params.states)
    lo, hi = scale * 1e-9, scale * 1e9
    if not (math.isfinite(hi) and lo > 0):
        raise ModelError(
            f"the stiffness scale |b - a|/Dc = {scale:.3g} 1/m is outside the floating-point range: check Dc"
            f" ({min(s.dc for s in params.states):.3g} m) and a, b"
        )
    if growth(lo) <= 0:
        # a state with a far longer Dc has its k_c below this bracket: look down to its own scale
        floor = max(abs(params.b - params.a), params.a) / max(s.dc for s in params.states) * 1e-9
        if not (0 < floor < lo) or growth(floor) <= 0:
            return 0.0
        lo, hi = floor, lo
    while growth(hi) > 0:  # inertia raises k_c by 1 + m V^2/(sigma a' Dc), without bound: widen the bracket up
        if hi > 1e300:
            raise ModelError(
                f"steady sliding at {velocity:.3g} m/s is unstable at every stiffness up to {hi:.3g} 1/m: no"
                " critical stiffness can be represented (check mass, normal stress, a, b and Dc)"
            )
        lo, hi = hi, hi * 1e9
    for _ in range(200):
        mid = math.sqrt(lo) * math.sqrt(hi)
        if growth(mid) > 0:
            lo = mid
        else:
            hi = mid
        if hi / lo - 1 < 1e-12:
            break
    return math.sqrt(lo) * math.sqrt(hi)
