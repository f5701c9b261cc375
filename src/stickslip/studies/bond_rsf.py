"""The bond model and rate-and-state friction on the same experiments (``stickslip compare``): a study.

It runs the bond model through the model interface, so it sits above the engines (docs/architecture.md).
:func:`bond_response` runs the time-dependent bond model when asked for, otherwise the quasi-static one
(``BondTrace.note`` says which); friction on both sides is stress over sigma_c (Eq 9); one RSF set
(:func:`rsf_of_bond`) stands for the bond model in every panel, and a set or panel with negative friction is
reported as failed (:func:`check_friction`).  How and why: docs/rsf.md, "Side by side with the bond model".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import DataError, ModelError, ParameterError
from ..protocols import Protocol, constant, velocity_steps
from ..rsf.params import RSFParams, StateVariable
from ..rsf.solver import simulate as rsf_simulate
from .rsf_reading import STEP_PRECISION, _critical, step_guess

__all__ = [
    "STEP_PRECISION",
    "BondRSF",
    "BondTrace",
    "bond_response",
    "check_friction",
    "fit_bond_step",
    "physical_problem",
    "rsf_of_bond",
    "step_guess",
    "stick_slip_pair",
]


@dataclass(frozen=True)
class BondTrace:
    """Stress (Pa) of the bond model against time (s) under a protocol; ``note`` says which model ran."""

    time: np.ndarray
    stress: np.ndarray
    source: str
    note: str


@dataclass(frozen=True)
class BondRSF:
    """Rate-and-state parameters that stand for the bond model near ``velocity``.

    ``status`` is "fitted" (to the bond model's step), "given" (on the command line) or "failed" (``note`` says
    why; ``params`` then holds what the fit wanted, for the record, and is not used).
    """

    params: RSFParams
    a_minus_b: float  # the bond model's steady slope (1/sigma_c) dsigma/dlnV at ``velocity``
    velocity: float
    sigma_c: float
    status: str
    note: str
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def usable(self) -> bool:
        return self.status != "failed"

    @property
    def determined(self) -> bool:
        return self.status == "fitted"

    def as_dict(self) -> dict[str, Any]:
        s = self.params.states[0]
        return {"a": self.params.a, "b": s.b, "dc": s.dc, "rsf_a_minus_b": self.params.a - s.b,
                "bond_steady_slope": self.a_minus_b, "velocity": self.velocity, "sigma_c": self.sigma_c,
                "status": self.status, "fitted": self.determined, "note": self.note, **self.extra}  # fmt: skip


def physical_problem(params: RSFParams) -> str | None:
    """Why an RSF parameter set cannot stand for the bond model, or None: a < 0 or Dc <= 0 (meaningless for any
    material), or b < 0 (a state that weakens in a hold, where the bonds heal; a legitimate reading of some gouges,
    docs/rsf.md "A negative b", but not of this model)."""
    problems = [f"a = {params.a:.3g} < 0" if params.a < 0 else ""]
    for k, state in enumerate(params.states):
        name = "" if len(params.states) == 1 else str(k + 1)
        problems.append(
            f"b{name} = {state.b:.3g} < 0 (weakening with hold time, where the bonds heal)" if state.b < 0 else ""
        )
        problems.append(f"Dc{name} = {state.dc:.3g} m is not positive" if not state.dc > 0 else "")
    found = [p for p in problems if p]
    return "; ".join(found) if found else None


def check_friction(time: np.ndarray, friction: np.ndarray) -> str | None:
    """None when the RSF friction stays positive; else where it goes below zero (meaningless), in words."""
    friction = np.asarray(friction, float)
    bad = ~np.isfinite(friction) | (friction < 0)
    if not bad.any():
        return None
    k = int(np.argmax(bad))
    low = float(np.nanmin(friction)) if np.isfinite(friction).any() else math.nan
    return (
        f"the RSF friction goes below zero from t = {float(time[k]):.4g} s (minimum {low:.3g}): negative friction"
        " has no physical meaning, so this parameter set does not describe the bond model here"
    )


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
    if model == "transient" and _transient() is not None:
        run = _bond_model("transient").run(params, protocol, _rig(control), start="steady")
        return BondTrace(np.asarray(run.time, float), np.asarray(run.stress, float), "time-dependent bond model",
                         "time-dependent bond model (stickslip.transient)")  # fmt: skip
    if control == "velocity":
        from ..quasistatic.steady import steady_state

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
    if len(set(protocol.velocities.tolist())) != 1:
        raise ModelError(
            "the quasi-static bond model runs only constant pulling under block control; a changing protocol "
            "needs the time-dependent bond model (stickslip.transient), not available here"
        )
    run = _bond_model("quasi-static").run(params, constant(protocol.initial_velocity, protocol.duration), _rig(control))
    return BondTrace(run.time, run.stress, "quasi-static bond model (jump cycles)",
                     f"quasi-static bond model, jump cycles: {run.message}")  # fmt: skip


def _bond_model(name: str) -> Any:
    """A bond model behind the model interface (:mod:`stickslip.models`)."""
    from ..models import get_model

    return get_model(name)


def _rig(control: str) -> Any:
    """The interface's rig for compare's control: the slider's velocity, or the block ("block") as the spring."""
    from ..models import Rig

    return Rig(control="velocity" if control == "velocity" else "spring")


def rsf_of_bond(
    params: Any, v0: float, v1: float, duration: float = 1.0, stiffness: float = 1e9, model: str = "quasi-static"
) -> BondRSF:
    """RSF a, b, Dc fitted to the bond model's velocity step ``v0`` -> ``v1`` (see the module notes).

    ``duration`` is the time spent at each velocity; ``stiffness`` (1/m) that of the RSF rig that copies the
    slider (stiff: the bond model is under velocity control).
    """
    from ..quasistatic.steady import steady_state

    if model not in ("quasi-static", "transient"):
        raise ParameterError(f"bond model: expected 'quasi-static' or 'transient', got {model!r}")
    sigma_c = _critical(params)[1]
    vm = math.sqrt(v0 * v1)
    steady = steady_state(params, np.array([v0, vm, v1]))
    stress = np.ravel(steady.stress)
    slope = float(np.ravel(steady.stress_slope)[1] * vm / sigma_c)
    if model == "transient" and _transient() is not None:
        protocol = velocity_steps([v0, v1], [duration, duration])
        return fit_bond_step(bond_response(params, protocol, "velocity", model="transient"), protocol, sigma_c, slope)
    mu0, mu1 = float(stress[0] / sigma_c), float(stress[2] / sigma_c)
    a = (mu1 - mu0) / math.log(v1 / v0)
    dl_m = float(params.bonds.max_extension)
    # a failed set is kept for the record only; RSFParams needs a > 0, so it holds |a| (the note gives a)
    rsf = RSFParams(a=max(abs(a), 1e-12), states=(StateVariable("aging", 0.0, dl_m),), mu0=mu0, v_ref=v0,
                    stiffness=stiffness)  # fmt: skip
    step = f"{v0 * 1e6:.4g} -> {v1 * 1e6:.4g} µm/s"
    if a <= 0:
        why = (f"fit failed: the quasi-static bond model's stress falls in the step {step} (μ {mu0:.4g} -> "
               f"{mu1:.4g}), so a rate-only law would need a = {a:.3g} <= 0: no positive direct effect")  # fmt: skip
        return BondRSF(rsf, slope, vm, sigma_c, "failed", why)
    note = (f"fitted to the quasi-static bond model's step {step}: it jumps at once from μ = {mu0:.4g} to "
            f"{mu1:.4g} (no transient, no state), which is exactly a = (μ1 − μ0)/ln(V1/V0) = {a:.4g}, b = 0; "
            f"Dc has no effect with b = 0 and is not determined (set to Δl_m = {dl_m * 1e6:.4g} µm)")  # fmt: skip
    return BondRSF(rsf, slope, vm, sigma_c, "fitted", note)


def fit_bond_step(trace: BondTrace, protocol: Protocol, sigma_c: float, slope: float) -> BondRSF:
    """RSF (aging law, one state) fitted to a bond-model trace of the velocity step ``protocol`` (given, not
    detected), with 95 % intervals (``extra["intervals"]``, SI).

    The trace is first resampled uniformly in slip around the step (:func:`stickslip.studies.rsf_reading.
    step_record`), so the fit does not depend on where the solver stepped.  The rig stiffness is fitted too: the
    bond model's stress rises over the slip that stretches its bonds (a fraction of a micrometre), which a rigid
    RSF rig would make instantaneous.  docs/extensions.md section 3 reads the bond model's steps in full.
    """
    from ..rsf.fit import fit_record
    from .rsf_reading import interval_table, step_record

    v0, v1 = protocol.segments[0].velocity, protocol.segments[1].velocity
    step = f"{v0 * 1e6:.4g} -> {v1 * 1e6:.4g} um/s"
    vm = math.sqrt(v0 * v1)
    try:
        sampled = step_record(trace.time, trace.stress, protocol, sigma_c, trace.source)
        t, friction = sampled.record.time, sampled.record.friction
        jump = float(np.ptp(friction))
        # a model's output has no noise: the fit is judged at a stated precision, 1 % of the step's range
        precision = STEP_PRECISION * jump if jump > 0 else None
        guess = step_guess(t, friction, sampled.protocol)
        fit = fit_record(sampled.record, protocol=sampled.protocol, guess=guess, noise=precision)
    except (ModelError, DataError) as exc:
        fallback = RSFParams(a=max(slope, 0.0), states=(StateVariable("aging", 0.0, 1e-6),), mu0=1.0, v_ref=v0)
        return BondRSF(fallback, slope, vm, sigma_c, "failed", f"fit to the {trace.source}'s step {step} failed: {exc}")
    p, s = fit.params, fit.params.states[0]
    intervals = interval_table(fit)

    def shown(name: str, value: float, scale: float = 1.0, unit: str = "") -> str:
        pair = intervals.get(name, {}).get("interval")
        where = f" [{pair[0] / scale:.3g}, {pair[1] / scale:.3g}]" if pair else ""
        return f"{name if name != 'dc' else 'Dc'} = {value / scale:.3g}{where}{unit}"

    values = ", ".join([shown("a", p.a), shown("b", s.b), shown("dc", s.dc, 1e-6, " um"),
                        f"rig stiffness {p.stiffness:.3g} 1/m"])  # fmt: skip
    extra = {"rms": fit.rms, "rig_stiffness": p.stiffness, "fit_success": fit.success, "warnings": list(fit.warnings),
             "law": "aging", "intervals": intervals, "precision": precision}  # fmt: skip
    problem = physical_problem(p)
    if problem is None and not fit.success:
        problem = f"the fit failed: {fit.reason}"
    if problem is None and jump > 0 and fit.rms > 0.05 * jump:
        problem = f"it does not describe the step: rms misfit {fit.rms:.3g} is over 5 % of the step's range {jump:.3g}"
    if problem is not None:
        note = f"fit failed: the best RSF fit to the {trace.source}'s velocity step {step} ({values}) is not usable: "
        return BondRSF(p, slope, vm, sigma_c, "failed", note + problem, extra)
    note = (f"fitted to the {trace.source}'s velocity step {step} (aging law, 95 % intervals: {values}), rms misfit "
            f"{fit.rms:.3g} ({100 * fit.rms / jump:.2g} % of the step's range)")  # fmt: skip
    return BondRSF(p, slope, vm, sigma_c, "fitted", note, extra)


def stick_slip_pair(params: Any, v0: float, duration: float, rsf: BondRSF, eta: float | None = None) -> dict[str, Any]:
    """The bond model's jump cycle and the RSF spring-slider at the same V0, stiffness and sigma_c.

    ``"bond"`` is the quasi-static model's :class:`stickslip.models.Run` (through the model interface).

    The RSF law is ``rsf``'s own (a, b, Dc, mu0 at its v_ref): only the rig (stiffness, radiation damping) is the
    bond model's block.  With a failed ``rsf`` the RSF side is not run (``"rsf": None``).
    """
    sim = _bond_model("quasi-static").run(params, constant(v0, duration), _rig("block"))  # a Run: the jump cycles
    k = float(params.block.effective_stiffness) / rsf.sigma_c  # Pa/m over sigma_c: friction per metre
    a = abs(rsf.params.a)
    eta = a / (100.0 * v0) if eta is None else eta  # damping matters only above ~100 V0
    if not rsf.usable:
        return {"bond": sim, "rsf": None, "stiffness": k, "eta": eta, "problem": "not run: the RSF fit failed"}
    p = rsf.params.replace(stiffness=k, eta=eta)
    run = rsf_simulate(p, constant(v0, duration), start_velocity=1.05 * v0)
    problem = check_friction(run.time, run.friction) or (None if run.status == "ok" else run.message)
    return {"bond": sim, "rsf": run, "stiffness": k, "eta": eta, "problem": problem}
