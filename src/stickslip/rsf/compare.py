"""The bond model and rate-and-state friction on the same experiments (``stickslip compare``).

The bond-model side is one small pluggable function, :func:`bond_response`: it
uses the time-dependent bond model (``stickslip.transient.run_transient``) when
that module is importable, and otherwise falls back on the quasi-static model:
``steady_state`` under velocity control (its response to a velocity change is
instantaneous: the steady curve has no state, so there is no transient to
compare, and a hold has no steady value) and ``simulate`` (the jump cycle)
under block control.  ``BondTrace.note`` says which was used, in words.

Friction on both sides is stress over the critical stress sigma_c of the bond
model (Eq 9), so the two share one axis.  The RSF parameters of the bond model
(:func:`rsf_of_bond`): ``a - b`` is the bond model's steady slope
(1/sigma_c) dsigma/dlnV at the step's mean velocity; with the time-dependent
model, a, b and Dc are fitted to its velocity-step response; without it a and
Dc are not determined by the model, and the assumption made for the figure
(Dc = the bond's maximum extension dl_m, a = |a - b|) is stated in the output.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ModelError, ParameterError
from ..protocols import Protocol
from .params import RSFParams, StateVariable
from .solver import simulate as rsf_simulate

__all__ = ["BondRSF", "BondTrace", "bond_response", "rsf_of_bond", "stick_slip_pair"]


@dataclass(frozen=True)
class BondTrace:
    """Stress (Pa) of the bond model against time (s) under a protocol; ``note`` says which model ran."""

    time: np.ndarray
    stress: np.ndarray
    source: str
    note: str


@dataclass(frozen=True)
class BondRSF:
    """Rate-and-state parameters that stand for the bond model near ``velocity``."""

    params: RSFParams
    a_minus_b: float
    velocity: float
    sigma_c: float
    determined: bool
    note: str
    extra: dict[str, Any] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        s = self.params.states[0]
        return {"a": self.params.a, "b": s.b, "dc": s.dc, "a_minus_b": self.a_minus_b, "velocity": self.velocity,
                "sigma_c": self.sigma_c, "fitted": self.determined, "note": self.note, **self.extra}  # fmt: skip


def _transient() -> Any:
    try:
        from .. import transient  # type: ignore[attr-defined]
    except ImportError:
        return None
    return getattr(transient, "run_transient", None)


def bond_response(
    params: Any, protocol: Protocol, control: str = "velocity", times: Any = None, model: str = "quasi-static"
) -> BondTrace:
    """The bond model's stress under ``protocol`` (``control``: "velocity" of the slider, or "block" pulled).

    ``model="transient"`` runs the time-dependent model (Eqs 1-5).  It is opt-in because it resolves the
    bond time tau (224 us for gelatin): one to a few seconds of CPU per second of sliding; the quasi-static
    model (instant, no memory) is the default.
    """
    if control not in ("velocity", "block"):
        raise ParameterError(f"control: expected 'velocity' or 'block', got {control!r}")
    if model not in ("quasi-static", "transient"):
        raise ParameterError(f"bond model: expected 'quasi-static' or 'transient', got {model!r}")
    run_transient = _transient() if model == "transient" else None
    if run_transient is not None:
        result = run_transient(params, protocol, control=control, start="steady")
        return BondTrace(np.asarray(result.time, float), np.asarray(result.stress, float), "time-dependent bond model",
                         "time-dependent bond model (stickslip.transient)")  # fmt: skip
    if control == "velocity":
        from ..model.steady import steady_state

        t = np.linspace(0, protocol.duration, 801) if times is None else np.asarray(times, float)
        v = protocol.velocity_at(t)
        stress = np.full(t.size, np.nan)
        moving = v > 0
        if moving.any():
            speeds, inverse = np.unique(v[moving], return_inverse=True)
            stress[moving] = np.ravel(steady_state(params, speeds).stress)[inverse]
        note = ("quasi-static bond model: its stress follows the steady curve instantly (the steady state has no "
                "memory), so it shows no transient" + ("; during holds it has no steady value (blank)"
                                                         if not moving.all() else ""))  # fmt: skip
        return BondTrace(t, stress, "quasi-static bond model", note)
    from ..model.cycle import simulate

    if len(set(protocol.velocities.tolist())) != 1:
        raise ModelError(
            "the quasi-static bond model runs only constant pulling under block control; a changing protocol "
            "needs the time-dependent bond model (stickslip.transient), not available here"
        )
    sim = simulate(params, protocol.initial_velocity, protocol.duration)
    return BondTrace(sim.time, sim.stress, "quasi-static bond model (jump cycles)",
                     f"quasi-static bond model, jump cycles: {sim.message}")  # fmt: skip


def _critical(params: Any) -> tuple[float, float]:
    from ..model.critical import critical_point

    cp = critical_point(params)
    if not cp.exists or cp.velocity is None or cp.stress is None:
        raise ModelError(f"the bond model has no critical point here ({cp.message}); nothing to normalise by")
    return float(cp.velocity), float(cp.stress)


def rsf_of_bond(
    params: Any, v0: float, v1: float, duration: float = 1.0, stiffness: float = 1e9, model: str = "quasi-static"
) -> BondRSF:
    """RSF a, b, Dc standing for the bond model between velocities ``v0`` and ``v1`` (see the module notes).

    With ``model="transient"`` a, b and Dc are fitted to the time-dependent model's velocity step.
    """
    from ..model.steady import steady_state

    sigma_c = _critical(params)[1]
    vm = math.sqrt(v0 * v1)
    steady = steady_state(params, np.array([v0, vm, v1]))
    stress = np.ravel(steady.stress)
    a_minus_b = float(np.ravel(steady.stress_slope)[1] * vm / sigma_c)
    mu0 = float(stress[0] / sigma_c)
    if model == "transient" and _transient() is not None:
        return _fitted_rsf(params, v0, v1, duration, stiffness, a_minus_b, mu0, sigma_c)
    dl_m = float(params.bonds.max_extension)
    a = abs(a_minus_b)
    rsf = RSFParams(a=a, states=(StateVariable("aging", a - a_minus_b, dl_m),), mu0=mu0, v_ref=v0,
                    stiffness=stiffness)  # fmt: skip
    note = (f"a - b = {a_minus_b:.4g} is the bond model's steady slope (1/sigma_c) dsigma/dlnV at {vm * 1e6:.4g} um/s; "
            "the quasi-static bond model has no state, so a and Dc are not determined by it: assumed a = |a - b| "
            f"and Dc = dl_m = {dl_m * 1e6:.4g} um (the bond's maximum extension)")  # fmt: skip
    return BondRSF(rsf, a_minus_b, vm, sigma_c, False, note)


def _fitted_rsf(
    params: Any, v0: float, v1: float, duration: float, stiffness: float, a_minus_b: float, mu0: float, sigma_c: float
) -> BondRSF:
    from ..protocols import velocity_steps
    from .data import LabRecord
    from .fit import fit_record

    protocol = velocity_steps([v0, v1], [duration, duration])
    trace = bond_response(params, protocol, "velocity", model="transient")
    t = trace.time
    record = LabRecord.from_arrays(t, protocol.displacement_at(t), trace.stress / sigma_c, source="bond model")
    fit = fit_record(record, stiffness=stiffness, protocol=protocol)
    note = f"a, b, Dc fitted to the {trace.source}'s velocity step {v0 * 1e6:.4g} -> {v1 * 1e6:.4g} um/s"
    return BondRSF(fit.params, a_minus_b, math.sqrt(v0 * v1), sigma_c, True, note,
                   {"rms": fit.rms, "warnings": list(fit.warnings)})  # fmt: skip


def stick_slip_pair(params: Any, v0: float, duration: float, rsf: BondRSF, eta: float | None = None) -> dict[str, Any]:
    """The bond model's jump cycle and the RSF spring-slider at the same V0, stiffness and sigma_c."""
    from ..model.cycle import simulate as bond_simulate
    from ..protocols import constant

    sim = bond_simulate(params, v0, duration)
    k = float(sim.stiffness) / rsf.sigma_c  # Pa/m over sigma_c: friction per metre
    a = rsf.params.a
    eta = a / (100.0 * v0) if eta is None else eta  # damping matters only above ~100 V0
    from ..model.steady import steady_state

    mu_v0 = float(np.ravel(steady_state(params, np.array([v0])).stress)[0]) / rsf.sigma_c
    p = rsf.params.replace(stiffness=k, eta=eta, v_ref=v0, mu0=mu_v0)
    run = rsf_simulate(p, constant(v0, duration), start_velocity=1.05 * v0)
    return {"bond": sim, "rsf": run, "stiffness": k, "eta": eta}
