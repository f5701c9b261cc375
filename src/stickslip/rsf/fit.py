r"""Fitting rate-and-state friction to a lab record (lmfit least squares, optional emcee posterior).

The model of a record: the spring-slider of :mod:`stickslip.rsf.solver`, driven by
the load-point history found in the record (or given), in steady state at the
first segment's velocity at the record's start, with ``V0`` = that velocity, so
``mu0`` is the initial steady friction.  Free: ``mu0``, ``a``, ``b`` and ``Dc``
(and ``b2``, ``Dc2`` with two states), optionally the stiffness and a linear
trend ``mu += trend * (load-point displacement)`` (slow drifts common in rock
and gouge records).  ``Dc`` and ``k`` are fitted in log space (they span
decades); their intervals are exp(log value +- 1.96 se), so asymmetric.

The noise is estimated from the record itself (the robust scatter of second
differences of friction), so the reduced chi-square says whether the model
describes the data to within its noise (about 1) or leaves structure behind
(much above 1); standard errors are the covariance scaled by it (lmfit's
default), as for the steady fit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..columns import with_units
from ..errors import DataError, ModelError, ParameterError
from ..protocols import Protocol
from .data import LabRecord, find_segments
from .params import RSFParams, StateVariable
from .solver import simulate

__all__ = ["FitParameter", "RSFFit", "fit_record"]

Z95 = 1.959963984540054
METHOD_MAX_NFEV = 1500


@dataclass(frozen=True)
class FitParameter:
    """A fitted (or fixed) value with its standard error and 95 % interval (SI units)."""

    name: str
    value: float
    stderr: float | None
    interval: tuple[float, float] | None
    fixed: bool = False

    def as_dict(self) -> dict[str, Any]:
        return {"value": self.value, "stderr": self.stderr, "interval": list(self.interval) if self.interval else None,
                "fixed": self.fixed}  # fmt: skip


@dataclass(frozen=True)
class RSFFit:
    """The result of :func:`fit_record`."""

    params: RSFParams
    parameters: dict[str, FitParameter]
    correlations: dict[str, float]
    reduced_chi_square: float
    rms: float
    noise: float
    trend: float
    record: LabRecord
    protocol: Protocol
    model_friction: np.ndarray
    warnings: tuple[str, ...]
    success: bool
    message: str
    nfev: int
    posterior: dict[str, Any] | None = field(default=None)

    @property
    def residuals(self) -> np.ndarray:
        return self.record.friction - self.model_friction

    def summary(self) -> dict[str, Any]:
        return {
            "parameters": {k: v.as_dict() for k, v in self.parameters.items()},
            "reduced_chi_square": self.reduced_chi_square,
            "rms": self.rms,
            "noise": self.noise,
            "correlations": self.correlations,
            "warnings": list(self.warnings),
            "success": self.success,
            "message": self.message,
            "protocol": [{"velocity": s.velocity, "duration": s.duration} for s in self.protocol.segments],
            "record": {"source": self.record.source, "rows": len(self.record), "t0": self.record.t0},
            **({"posterior": self.posterior} if self.posterior else {}),
        }

    def to_toml(self) -> str:
        head = [
            f"# rate-and-state fit of {self.record.source} ({len(self.record)} rows)",
            f"# reduced chi-square {self.reduced_chi_square:.4g}, rms {self.rms:.4g}, trend {self.trend:.6g} per m",
            f"# protocol (load point, from t0 = {self.record.t0:.6g} s): {self.protocol.describe()}",
        ]
        for name, p in self.parameters.items():
            if p.interval:
                head.append(f"# {name} = {p.value:.6g}  95 % [{p.interval[0]:.6g}, {p.interval[1]:.6g}]")
        return "\n".join(head) + "\n" + self.params.to_toml()

    def to_frame(self) -> Any:
        frame = self.record.to_frame()
        frame["model"] = self.model_friction
        frame["residual"] = self.residuals
        return with_units(frame)

    def plot(self, ax: Any = None) -> Any:
        from .plots import plot_fit

        return plot_fit(self, ax=ax)


def _model(record: LabRecord, protocol: Protocol, base: RSFParams, values: dict[str, float]) -> np.ndarray:
    states = [StateVariable(base.states[0].law, values["b"], math.exp(values["log_dc"]), base.states[0].c)]
    if "b2" in values:
        law2 = base.states[1].law if len(base.states) > 1 else base.states[0].law
        states.append(StateVariable(law2, values["b2"], math.exp(values["log_dc2"])))
    params = base.replace(
        a=values["a"], mu0=values["mu0"], states=tuple(states),
        stiffness=math.exp(values["log_k"]) if "log_k" in values else base.stiffness,
    )  # fmt: skip
    run = simulate(params, protocol, times=record.time, rtol=1e-8, atol=1e-10, detect=False)
    if run.status != "ok" or run.time.size != record.time.size:
        return np.full(record.time.size, np.nan)
    return run.friction + values.get("trend", 0.0) * record.displacement


def fit_record(
    record: LabRecord,
    *,
    law: str = "aging",
    states: int = 1,
    stiffness: float | None = None,
    fit_stiffness: bool | None = None,
    trend: bool = False,
    protocol: Protocol | None = None,
    guess: dict[str, float] | None = None,
    mcmc_steps: int = 0,
    seed: int | None = None,
) -> RSFFit:
    """Fit rate-and-state friction to ``record`` (see the module notes).

    ``stiffness`` (1/m) is fixed unless ``fit_stiffness``; with neither it is
    fitted.  ``mcmc_steps > 0`` adds an emcee posterior (medians and 2.5/97.5 %
    percentiles) started from the least-squares fit.
    """
    if states not in (1, 2):
        raise ParameterError(f"states: expected 1 or 2 state variables, got {states!r}")
    protocol = protocol if protocol is not None else find_segments(record.time, record.displacement)
    if abs(protocol.duration - record.time[-1]) > 1e-6 * max(1.0, record.time[-1]):
        raise DataError(
            f"protocol lasts {protocol.duration:g} s but the record {record.time[-1]:g} s; expected the same span"
        )
    if protocol.initial_velocity <= 0:
        raise DataError("record: the load point does not move in the first segment; expected steady sliding first")
    if fit_stiffness is None:
        fit_stiffness = stiffness is None
    start = _initial_guess(record, protocol, guess or {}, stiffness)
    if states == 2:  # a one-state fit first: the two-state search starts from its answer, with a slower second state
        first, _ = _least_squares(record, protocol, law, 1, start, fit_stiffness, trend)
        start = {**start, **first.params.valuesdict()}
        start["dc"], start["dc2"] = math.exp(start["log_dc"]), 10 * math.exp(start["log_dc"])
        start["b2"] = 0.2 * start["b"]
        start["stiffness"] = math.exp(start["log_k"]) if "log_k" in start else start["stiffness"]
    result, residual = _least_squares(record, protocol, law, states, start, fit_stiffness, trend)
    base = _base(record, protocol, law, states, start)
    values = result.params.valuesdict()
    model = _model(record, protocol, base, values)
    if not np.all(np.isfinite(model)):
        raise ModelError("rate-and-state fit: the best parameters give a run that blows up; give a stiffness")
    noise = start["noise"]
    resid = record.friction - model
    dof = max(len(record) - result.nvarys, 1)
    redchi = float(np.sum((resid / noise) ** 2) / dof)
    table, corr, warns = _report(result, values, fit_stiffness, start["stiffness"], trend)
    posterior = _posterior(residual, result, mcmc_steps, seed) if mcmc_steps > 0 else None
    return RSFFit(
        params=_final_params(base, values), parameters=table, correlations=corr, reduced_chi_square=redchi,
        rms=float(np.sqrt(np.mean(resid**2))), noise=noise, trend=float(values.get("trend", 0.0)), record=record,
        protocol=protocol, model_friction=model, warnings=tuple(warns), success=bool(result.success),
        message=str(result.message), nfev=int(result.nfev), posterior=posterior,
    )  # fmt: skip


def _initial_guess(
    record: LabRecord, protocol: Protocol, guess: dict[str, float], stiffness: float | None
) -> dict[str, float]:
    """Starting values from the record: steady levels before and after the first change give a - b."""
    f = record.friction
    noise = max(_noise(f), 1e-12)
    change = protocol.boundaries[1] if len(protocol.segments) > 1 else record.time[-1]
    before = f[record.time < change]
    after = f[(record.time >= change) & (record.time < protocol.boundaries[min(2, len(protocol.segments))])]
    v1, v2 = protocol.segments[0].velocity, protocol.segments[min(1, len(protocol.segments) - 1)].velocity
    slip = max(float(record.displacement[-1]), 1e-9)
    dc = guess.get("dc", min(max(slip / 100, 1e-7), 1e-3))
    a = guess.get("a", 0.01)
    b = guess.get("b", 0.01)
    if v2 > 0 and v2 != v1 and before.size > 10 and after.size > 10:
        tail = max(after.size // 10, 5)
        a_minus_b = (np.median(after[-tail:]) - np.median(before[-tail:])) / math.log(v2 / v1)
        b = guess.get("b", a - a_minus_b)
    k = stiffness if stiffness is not None else guess.get("stiffness", 0.02 / dc)
    return {
        "mu0": guess.get("mu0", float(np.median(f[: max(5, f.size // 50)]))), "a": a, "b": b, "dc": dc,
        "b2": guess.get("b2", 0.002), "dc2": guess.get("dc2", 10 * dc), "stiffness": k,
        "trend": guess.get("trend", 0.0), "noise": noise, "max_dc": slip,
    }  # fmt: skip


def _noise(values: np.ndarray) -> float:
    """White-noise level from second differences (robust: 1.4826 MAD, so transients do not inflate it)."""
    second = np.diff(values, 2)
    return float(1.4826 * np.median(np.abs(second - np.median(second))) / math.sqrt(6.0))


def _base(record: LabRecord, protocol: Protocol, law: str, states: int, start: dict[str, float]) -> RSFParams:
    state = StateVariable(law, start["b"], start["dc"])
    return RSFParams(a=start["a"], states=(state,) * states, mu0=start["mu0"], v_ref=protocol.initial_velocity,
                     stiffness=start["stiffness"])  # fmt: skip


def _least_squares(
    record: LabRecord, protocol: Protocol, law: str, states: int, start: dict[str, float], fit_stiffness: bool,
    trend: bool,
) -> Any:  # fmt: skip
    import lmfit

    base = _base(record, protocol, law, states, start)
    noise = start["noise"]
    log_dc = (math.log(1e-9), math.log(start["max_dc"]))
    pars = lmfit.Parameters()
    pars.add("mu0", value=start["mu0"])
    # rock friction has |a|, |b| < 0.2; a record normalised otherwise (the bond model's sigma/sigma_c) may not
    bound = max(0.2, 5.0 * float(np.ptp(record.friction[np.isfinite(record.friction)])))
    pars.add("a", value=min(max(start["a"], 2e-5), 0.95 * bound), min=1e-5, max=bound)
    pars.add("b", value=min(max(start["b"], -0.95 * bound), 0.95 * bound), min=-bound, max=bound)
    pars.add("log_dc", value=min(max(math.log(start["dc"]), log_dc[0] + 1), log_dc[1] - 0.1), min=log_dc[0],
             max=log_dc[1])  # fmt: skip
    if states == 2:
        pars.add("b2", value=start["b2"], min=-bound, max=bound)
        pars.add("log_dc2", value=min(max(math.log(start["dc2"]), log_dc[0] + 1), log_dc[1] - 0.1), min=log_dc[0],
                 max=log_dc[1])  # fmt: skip
    if fit_stiffness:
        pars.add("log_k", value=math.log(start["stiffness"]), min=math.log(1e-2), max=math.log(1e12))
    if trend:
        pars.add("trend", value=start["trend"])

    def residual(p: Any) -> np.ndarray:
        model = _model(record, protocol, base, p.valuesdict())
        out = (model - record.friction) / noise
        return np.where(np.isfinite(out), out, 1e6)

    try:
        # MINPACK's forward-difference step sqrt(epsfcn) = 1e-5 (relative) sits well above the solver's
        # tolerance, so the Jacobians are not solver noise
        result = lmfit.minimize(residual, pars, method="leastsq", epsfcn=1e-10, max_nfev=METHOD_MAX_NFEV)
    except (ValueError, ArithmeticError) as exc:
        raise ModelError(f"rate-and-state fit failed: {exc}") from None
    return result, residual


def _final_params(base: RSFParams, values: dict[str, float]) -> RSFParams:
    states = [StateVariable(base.states[0].law, values["b"], math.exp(values["log_dc"]), base.states[0].c)]
    if "b2" in values:
        states.append(StateVariable(base.states[-1].law, values["b2"], math.exp(values["log_dc2"])))
    k = math.exp(values["log_k"]) if "log_k" in values else base.stiffness
    return base.replace(a=values["a"], mu0=values["mu0"], states=tuple(states), stiffness=k)


_PUBLIC = {"mu0": "mu0", "a": "a", "b": "b", "log_dc": "dc", "b2": "b2", "log_dc2": "dc2", "log_k": "stiffness",
           "trend": "trend"}  # fmt: skip


def _report(
    result: Any, values: dict[str, float], fit_stiffness: bool, k_fixed: float, trend: bool
) -> tuple[dict[str, FitParameter], dict[str, float], list[str]]:
    table: dict[str, FitParameter] = {}
    warns: list[str] = []
    for key, public in _PUBLIC.items():
        if key not in result.params:
            continue
        par = result.params[key]
        se = par.stderr if par.stderr is not None and math.isfinite(par.stderr) else None
        if key.startswith("log_"):
            value = math.exp(par.value)
            interval = (_exp(par.value - Z95 * se), _exp(par.value + Z95 * se)) if se is not None else None
            stderr = value * se if se is not None else None
        else:
            value = par.value
            interval = (value - Z95 * se, value + Z95 * se) if se is not None else None
            stderr = se
        table[public] = FitParameter(public, value, stderr, interval)
        if se is None:
            warns.append(f"{public}: no standard error (the fit cannot tell it apart from the others)")
        elif key.startswith("log_") and se > 1.0:
            warns.append(f"{public}: undetermined (known only to within a factor e^{se:.2g}); consider fixing it")
        elif not key.startswith("log_") and key != "mu0" and abs(value) > 0 and se > abs(value):
            warns.append(f"{public}: undetermined (standard error {se:.3g} exceeds the value {value:.3g})")
        if par.min is not None and par.max is not None and se is not None:
            span = par.max - par.min
            if min(abs(par.value - par.min), abs(par.max - par.value)) < 1e-6 * span:
                warns.append(f"{public}: at the edge of its allowed range; the fit is not trustworthy there")
    if not fit_stiffness:
        table["stiffness"] = FitParameter("stiffness", k_fixed, None, None, fixed=True)
    if not trend:
        table["trend"] = FitParameter("trend", 0.0, None, None, fixed=True)
    corr: dict[str, float] = {}
    for key, par in result.params.items():
        for other, value in (par.correl or {}).items():
            pair = tuple(sorted((_PUBLIC[key], _PUBLIC[other])))
            name = f"{pair[0]}-{pair[1]}"
            if name not in corr:
                corr[name] = float(value)
                if abs(value) > 0.95:
                    warns.append(f"{pair[0]} and {pair[1]} are strongly correlated ({value:+.3f}): the record "
                                 "constrains a combination of them better than either")  # fmt: skip
    return table, corr, warns


def _posterior(residual: Any, result: Any, steps: int, seed: int | None) -> dict[str, Any]:
    import lmfit

    walkers = max(4 * result.nvarys, 16)
    mc = lmfit.minimize(
        residual, result.params, method="emcee", steps=int(steps), nwalkers=walkers, burn=int(steps) // 3,
        is_weighted=True, progress=False, seed=seed,
    )  # fmt: skip
    out: dict[str, Any] = {"steps": int(steps), "walkers": walkers}
    for key in result.var_names:
        chain = np.asarray(mc.flatchain[key])
        if key.startswith("log_"):
            chain = np.exp(chain)
        lo, med, hi = np.percentile(chain, [2.5, 50, 97.5])
        out[_PUBLIC[key]] = {"median": float(med), "interval": [float(lo), float(hi)]}
    return out


def _exp(x: float) -> float:
    """exp that reports an interval end beyond the float range as inf (shown as unbounded), not OverflowError."""
    return math.exp(x) if x < 709.0 else math.inf
