r"""Fitting rate-and-state friction to a lab record (lmfit least squares, optional emcee posterior).

The model of a record: the spring-slider of :mod:`stickslip.rsf.solver`, driven by
the load-point history found in the record (or given), in steady state at the
first segment's velocity at the record's start, with ``V0`` = that velocity, so
``mu0`` is the initial steady friction.  Free: ``mu0``, ``a``, ``b`` and ``Dc``
(and ``b2``, ``Dc2`` with two states), optionally the stiffness and a linear
trend ``mu += trend * (load-point displacement)`` (slow drifts common in rock
and gouge records: wear, gouge growth), a trend in time ``mu += time_trend * t``
(a load cell's thermal drift), or both (``trend="both"``).  ``Dc`` and ``k`` are fitted in log space (they span
decades); their intervals are exp(log value +- 1.96 se), so asymmetric.

The noise is estimated from the record itself (the robust scatter of second
differences of friction), so the reduced chi-square says whether the model
describes the data to within its noise (about 1) or leaves structure behind
(much above 1).  Standard errors and intervals assume that noise level (the
covariance is not rescaled); when chi-square_r > 2 the residuals contradict it,
a warning says so and ``scaled_interval`` (widened by sqrt(chi-square_r)) is
offered beside each interval.  ``a - b`` comes with its own standard error from
the covariance (a and b are strongly correlated: their separate errors cannot
give it).

A fit is ``failed`` (never ``ok``) with a ``reason`` when the search did not
converge; the covariance could not be estimated; chi-square_r is absurd
(> :data:`ABSURD_CHI2`: the model or the load-point history does not describe
the record); a, b and Dc did not move from starting values that do not fit; the history
strays from the record's displacement by more than 10 % of its span; the
friction shows no velocity dependence (an F test against constant friction,
plus the trends when fitted); chi-square_r > 2 with a linear drift in slip and
time explaining > 20 % of the residuals (a drift the model misses); or a, b or
Dc is not constrained (at a bound of its range, no standard error, or known
only to within a factor e).  Unconstrained parameters show no interval, with a
note saying why.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..columns import with_units
from ..errors import DataError, ModelError, ParameterError
from ..protocols import Protocol, Segment
from .data import LabRecord, find_segments
from .params import RSFParams, StateVariable
from .solver import simulate

__all__ = ["FitParameter", "RSFFit", "fit_record"]

Z95 = 1.959963984540054
METHOD_MAX_NFEV = 1500
#: the solver's relative tolerance during fits
FIT_RTOL = 1e-8
#: chi-square_r above this: the residuals are >10x the noise, the model does not describe the record
ABSURD_CHI2 = 100.0
#: chi-square_r above this: warn that the intervals assume a noise level the residuals contradict
WARN_CHI2 = 2.0
#: an F test at this level decides whether the friction responds to velocity at all
NO_RESPONSE_LEVEL = 1e-3
NO_RESPONSE_TEXT = "the friction shows no significant response to the velocity changes"
_CORE = ("a", "b", "dc")
#: with chi-square_r > WARN_CHI2, a fit fails when a linear drift (in slip and time) explains this share of the
#: residuals: the intervals cannot hold while the model misses a drift
DRIFT_SHARE = 0.2
#: a history whose displacement strays from the record's by more than this share of its span is not the record's
MISMATCH_SHARE = 0.1
#: friction the solver reproduces at the fits' tolerances: the noise floor of a noise-free record
MODEL_PRECISION = 1e-9


@dataclass(frozen=True)
class FitParameter:
    """A fitted (or fixed) value with its standard error and 95 % interval (SI units inside).

    ``unit`` and ``scale`` (SI per unit) give the record's units for reports; ``constrained`` is False when the
    record does not determine the value (``note`` says why, and there is no interval); ``scaled_interval`` is
    the interval widened by sqrt(chi-square_r), offered when the residuals exceed the noise.
    """

    name: str
    value: float
    stderr: float | None
    interval: tuple[float, float] | None
    fixed: bool = False
    unit: str = ""
    scale: float = 1.0
    constrained: bool = True
    note: str = ""
    scaled_interval: tuple[float, float] | None = None

    def as_dict(self) -> dict[str, Any]:
        """In the record's units (``unit``; empty for dimensionless values)."""
        k = self.scale

        def shown(pair: tuple[float, float] | None) -> list[float] | None:
            return [pair[0] / k, pair[1] / k] if pair else None

        out: dict[str, Any] = {
            "value": self.value / k, "unit": self.unit or "dimensionless",
            "stderr": None if self.stderr is None else self.stderr / k, "interval": shown(self.interval),
            "fixed": self.fixed, "constrained": self.constrained,
        }  # fmt: skip
        if self.scaled_interval:
            out["scaled_interval"] = shown(self.scaled_interval)
        if self.note:
            out["note"] = self.note
        return out

    def text(self) -> str:
        """``0.0123 ± 0.0004 µm  95 % [..]`` in the record's units."""
        from ..display import unit as shown_unit

        k, unit = self.scale, f" {shown_unit(self.unit)}" if self.unit else ""
        if self.fixed:
            return f"{self.value / k:.6g}{unit} (fixed)"
        if not self.constrained:
            return f"{self.value / k:.6g}{unit} (not constrained: {self.note})"
        if self.interval is None or self.stderr is None:
            return f"{self.value / k:.6g}{unit} (no standard error)"
        line = (f"{self.value / k:.6g} ± {self.stderr / k:.2g}{unit}   95 % [{self.interval[0] / k:.6g}, "
                f"{self.interval[1] / k:.6g}]")  # fmt: skip
        if self.scaled_interval:
            line += f", scaled [{self.scaled_interval[0] / k:.6g}, {self.scaled_interval[1] / k:.6g}]"
        return line


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
    status: str = "ok"
    reason: str = ""
    derived: dict[str, FitParameter] = field(default_factory=dict)
    protocol_source: str = "given"

    @property
    def residuals(self) -> np.ndarray:
        return self.record.friction - self.model_friction

    def protocol_rows(self) -> list[dict[str, Any]]:
        """The load-point history fitted, in the record's units, with each segment's start time."""
        unit = self.record.length_unit
        scale = _length_scale(unit)
        starts = self.protocol.boundaries
        return [{"start": float(t), "velocity": s.velocity / scale, "duration": s.duration, "unit": f"{unit}/s"}
                for t, s in zip(starts, self.protocol.segments, strict=False)]  # fmt: skip

    def summary(self) -> dict[str, Any]:
        unit = self.record.length_unit
        return {
            "status": self.status,
            **({"reason": self.reason} if self.reason else {}),
            "parameters": {k: v.as_dict() for k, v in self.parameters.items()},
            "derived": {k: v.as_dict() for k, v in self.derived.items()},
            "reduced_chi_square": self.reduced_chi_square,
            "rms": self.rms,
            "noise": self.noise,
            "correlations": self.correlations,
            "warnings": list(self.warnings),
            "success": self.success,
            # the optimiser's own words ("Fit succeeded.") only beside a verdict that cannot contradict them
            "message": self.message if self.status == "ok" else f"fit failed: {self.reason}",
            "optimizer_message": self.message,
            "protocol": self.protocol_rows(),
            "protocol_source": self.protocol_source,
            "units": {
                "time": "s",
                "length": unit,
                "velocity": f"{unit}/s",
                "stiffness": f"1/{unit}",
                "trend": f"1/{unit}",
                "time_trend": "1/s",
                "friction": "dimensionless",
            },
            "record": {"source": self.record.source, "rows": len(self.record), "t0": self.record.t0},
            **({"posterior": self.posterior} if self.posterior else {}),
        }

    def to_toml(self) -> str:
        head = [
            f"# rate-and-state fit of {self.record.source} ({len(self.record)} rows): {self.status}"
            + (f" ({self.reason})" if self.reason else ""),
            f"# reduced chi-square {self.reduced_chi_square:.4g}, rms {self.rms:.4g}, trend {self.trend:.6g} per m",
            f"# protocol (load point, from t0 = {self.record.t0:.6g} s): {self.protocol.describe()}",
        ]
        for name, p in {**self.parameters, **self.derived}.items():
            head.append(f"# {name} = {p.text()}")
        head.append("# values below in SI units (m, 1/m)")
        return "\n".join(head) + "\n" + self.params.to_toml()

    def to_frame(self) -> Any:
        frame = self.record.to_frame()
        frame["model"] = self.model_friction
        frame["residual"] = self.residuals
        return with_units(frame)

    def plot(self, ax: Any = None) -> Any:
        from ..plots.rsf import plot_fit

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
    run = simulate(params, protocol, times=record.time, rtol=FIT_RTOL, atol=FIT_RTOL * 1e-2, detect=False)
    if run.status != "ok" or run.time.size != record.time.size:
        return np.full(record.time.size, np.nan)
    drift = values.get("trend", 0.0) * record.displacement + values.get("time_trend", 0.0) * record.time
    return run.friction + drift


def fit_record(
    record: LabRecord,
    *,
    law: str = "aging",
    states: int = 1,
    stiffness: float | None = None,
    fit_stiffness: bool | None = None,
    trend: bool | str = False,
    protocol: Protocol | None = None,
    guess: dict[str, float] | None = None,
    mcmc_steps: int = 0,
    seed: int | None = None,
    noise: float | None = None,
) -> RSFFit:
    """Fit rate-and-state friction to ``record`` (see the module notes).

    ``stiffness`` (1/m) is fixed unless ``fit_stiffness``; with neither it is
    fitted.  ``trend``: False, True or ``"slip"`` (linear in load-point
    displacement), ``"time"`` (linear in time) or ``"both"``.  ``mcmc_steps > 0``
    adds an emcee posterior (medians and 2.5/97.5 % percentiles) started from
    the least-squares fit.  ``noise``: the friction noise to judge the fit by, where it is known (a model's
    noise-free output fitted to a stated precision); by default it is estimated from the record.
    """
    if noise is not None and not (isinstance(noise, (int, float)) and math.isfinite(noise) and noise > 0):
        raise ParameterError(f"noise: expected a positive friction level, got {noise!r}")
    if states not in (1, 2):
        raise ParameterError(f"states: expected 1 or 2 state variables, got {states!r}")
    trend = _trend_kinds(trend)
    source = "given" if protocol is not None else "found from the load-point displacement"
    protocol = _covering(protocol, record) if protocol is not None else find_segments(record.time, record.displacement)
    if protocol.initial_velocity <= 0:
        raise DataError("record: the load point does not move in the first segment; expected steady sliding first")
    if fit_stiffness is None:
        fit_stiffness = stiffness is None
    start = _initial_guess(record, protocol, guess or {}, stiffness)
    if noise is not None:
        start["noise"] = float(noise)
    mismatch = _history_mismatch(record, protocol)
    result, residual = _search(record, protocol, law, states, start, fit_stiffness, trend)
    for factor in RETRY_DC_FACTORS:  # a troubled search may sit in a local minimum: start it elsewhere in Dc
        if mismatch or not _troubled(result):  # (no start helps a history that is not the record's)
            break
        other = {**start, "dc": min(max(start["dc"] * factor, 2e-9), 0.5 * start["max_dc"])}
        if stiffness is None and "stiffness" not in (guess or {}):
            other["stiffness"] = start["stiffness"] * start["dc"] / other["dc"]
        retry, retry_residual = _search(record, protocol, law, states, other, fit_stiffness, trend)
        same = abs(retry.chisqr - result.chisqr) <= 1e-4 * result.chisqr
        if retry.chisqr < result.chisqr * (1 - 1e-9) or (_troubled(result) and not _troubled(retry)):
            result, residual = retry, retry_residual
        if same and _troubled(retry):  # another start, the same answer: the record, not the start, is the cause
            break
    result, residual = _polish(record, protocol, law, states, start, fit_stiffness, trend, result, residual)
    base = _base(record, protocol, law, states, start)
    values = result.params.valuesdict()
    model = _model(record, protocol, base, values)
    if not np.all(np.isfinite(model)):
        raise ModelError("rate-and-state fit: the best parameters give a run that blows up; give a stiffness")
    noise = start["noise"]
    resid = record.friction - model
    dof = max(len(record) - result.nvarys, 1)
    redchi = float(np.sum((resid / noise) ** 2) / dof)
    units = _units(record.length_unit)
    table, corr, warns = _report(result, values, fit_stiffness, start["stiffness"], trend, redchi, units)
    derived = {"a-b": _difference(result, table, redchi)}
    problems = _problems(result, record, table, redchi, noise, trend)
    if any(p.startswith(NO_RESPONSE_TEXT) for p in problems):  # then no interval of the friction law means anything
        why = "the friction shows no velocity dependence"
        for key in ("a", "b", "dc", "b2", "dc2", "stiffness"):
            if key in table and not table[key].fixed:
                table[key] = replace(table[key], interval=None, scaled_interval=None, constrained=False, note=why)
    if mismatch:
        problems.insert(0, mismatch)
    drift = _residual_drift(record, resid)
    if redchi > WARN_CHI2 and drift > DRIFT_SHARE:
        problems.append(
            f"a linear drift in slip and time explains {100 * drift:.0f} % of the residuals (reduced chi-square "
            f"{redchi:.3g}): the model misses a drift, so its values and intervals are biased; fit the drift with "
            "--trend slip, time or both"
        )
    if redchi > WARN_CHI2:
        warns.append(
            f"reduced chi-square {redchi:.3g} > {WARN_CHI2:g}: the residuals are larger than the record's noise "
            f"({noise:.3g}), so the intervals, which assume that noise, are too narrow; the scaled intervals "
            f"(x sqrt({redchi:.3g}) = x{math.sqrt(redchi):.2g}) are offered beside them"
        )
    curvature = _quadratic_check(result, residual)
    if curvature is not None and not (QUADRATIC_RANGE[0] <= curvature <= QUADRATIC_RANGE[1]):
        warns.append(
            f"the chi-square surface is not quadratic over the intervals: two standard errors along the least "
            f"determined direction raise chi-square by {4 * curvature:.3g} instead of 4, so the intervals "
            f"(from the curvature at the best fit) are approximate{' and too narrow' if curvature < 1 else ''}; "
            "--mcmc N gives a posterior that does not assume it"
        )
    posterior = _posterior(residual, result, mcmc_steps, seed) if mcmc_steps > 0 else None
    return RSFFit(
        params=_final_params(base, values), parameters=table, correlations=corr, reduced_chi_square=redchi,
        rms=float(np.sqrt(np.mean(resid**2))), noise=noise, trend=float(values.get("trend", 0.0)), record=record,
        protocol=protocol, model_friction=model, warnings=tuple(warns), success=not problems,
        message=str(result.message), nfev=int(result.nfev), posterior=posterior,
        status="failed" if problems else "ok", reason="; ".join(problems), derived=derived, protocol_source=source,
    )  # fmt: skip


#: Dc starts tried (x the first start) when a search fails, fits badly or leaves a, b or Dc unconstrained
RETRY_DC_FACTORS = (0.1, 10.0, 0.01)


def _search(
    record: LabRecord, protocol: Protocol, law: str, states: int, start: dict[str, float], fit_stiffness: bool,
    trend: frozenset[str],
) -> Any:  # fmt: skip
    """The least-squares fit from ``start``, in stages where one stage alone can lose its way."""
    if "time" in trend:  # without the time drift first: with it free from the start the search can lose its way
        first, _ = _least_squares(record, protocol, law, 1, start, fit_stiffness, trend - {"time"})
        start = {**start, **_start_values(first.params.valuesdict())}
    if states == 2:  # a one-state fit first: the two-state search starts from its answer, with a slower second state
        first, _ = _least_squares(record, protocol, law, 1, start, fit_stiffness, trend)
        start = {**start, **_start_values(first.params.valuesdict())}
        start["dc2"] = 10 * start["dc"]
        start["b2"] = 0.2 * start["b"]
    return _least_squares(record, protocol, law, states, start, fit_stiffness, trend)


#: searches restarted from where the last one stopped, at most, while chi-square still falls near the answer
POLISH_ROUNDS = 3


def _polish(
    record: LabRecord, protocol: Protocol, law: str, states: int, start: dict[str, float], fit_stiffness: bool,
    trend: frozenset[str], result: Any, residual: Any,
) -> Any:  # fmt: skip
    """Search again from two standard errors along the covariance's widest direction when chi-square is lower
    there: MINPACK can stop short of the minimum in a long narrow valley, where its finite-difference Jacobian
    no longer sees the slope along the valley (a and b correlated at 0.99 on the bond model's step: a 1e-16
    change of the record left a 0.7 % off and chi-square 1.7 % above the minimum; a restart from the same
    point stops at once).  A new search is kept only when it lowers chi-square."""
    for _ in range(POLISH_ROUNDS):
        lower = _downhill(result, residual)
        if lower is None:
            break
        here = {**start, **_start_values(lower.valuesdict())}
        again, again_residual = _least_squares(record, protocol, law, states, here, fit_stiffness, trend)
        if not again.chisqr < result.chisqr * (1 - 1e-9):
            break
        result, residual = again, again_residual
    return result, residual


def _widest_step(result: Any) -> np.ndarray | None:
    """Two standard errors along the covariance's widest direction (None without a usable covariance)."""
    covar = result.covar
    if covar is None or not np.all(np.isfinite(covar)):
        return None
    values, vectors = np.linalg.eigh(covar)
    if values[-1] <= 0:
        return None
    return 2.0 * math.sqrt(values[-1]) * vectors[:, -1]


def _downhill(result: Any, residual: Any) -> Any:
    """The parameters two standard errors either way along the covariance's widest direction with the lower
    chi-square, when it is below the fit's (None otherwise)."""
    step = _widest_step(result)
    if step is None:
        return None
    best, best_chi = None, float(result.chisqr)
    for sign in (1.0, -1.0):
        trial = result.params.copy()
        for name, delta in zip(result.var_names, step, strict=True):
            par = trial[name]
            par.value = min(max(par.value + sign * delta, par.min), par.max)
        chi = float(np.sum(residual(trial) ** 2))
        if chi < best_chi * (1 - 1e-9):
            best, best_chi = trial, chi
    return best


#: chi-square rise two standard errors out, over the quadratic's 4, outside this range: the intervals are approximate
QUADRATIC_RANGE = (0.5, 2.0)


def _quadratic_check(result: Any, residual: Any) -> float | None:
    """Rise of chi-square two standard errors either way along the covariance's widest direction, over 4 (the
    quadratic's): the smaller side (None without a covariance)."""
    step = _widest_step(result)
    if step is None:
        return None
    rises = []
    for sign in (1.0, -1.0):
        trial = result.params.copy()
        for name, delta in zip(result.var_names, step, strict=True):
            par = trial[name]
            moved = par.value + sign * delta
            if (par.min is not None and moved < par.min) or (par.max is not None and moved > par.max):
                return None  # the bound, not the curvature, limits the parameter there
            par.value = moved
        r = residual(trial)
        rises.append((float(np.sum(r**2)) - float(result.chisqr)) / 4.0)
    return min(rises)


def _troubled(result: Any) -> bool:
    """The search did not converge, has no covariance, leaves residuals beyond the noise (chi-square_r > 2: often
    a local minimum) or leaves a, b or Dc unconstrained."""
    if not result.success or not result.errorbars or result.chisqr > WARN_CHI2 * max(result.nfree, 1):
        return True
    for key in ("a", "b", "log_dc"):
        par = result.params[key]
        se = par.stderr if par.stderr is not None and math.isfinite(par.stderr) else None
        if _unconstrained(key, par, se):
            return True
    return False


def _start_values(values: dict[str, float]) -> dict[str, float]:
    """A fit's values as starting values (log Dc, log k back to Dc, k)."""
    out = {k: v for k, v in values.items() if not k.startswith("log_")}
    out["dc"] = math.exp(values["log_dc"])
    if "log_k" in values:
        out["stiffness"] = math.exp(values["log_k"])
    return out


def _covering(protocol: Protocol, record: LabRecord) -> Protocol:
    """The given history over the record's span: cut at its end; one that ends early is refused."""
    end = float(record.time[-1])
    if protocol.duration < end * (1 - 1e-6) - 1e-9:
        raise DataError(
            f"protocol lasts {protocol.duration:g} s but the record {end:g} s; expected a history covering the record"
        )
    kept = []
    for t0, t1, v in protocol.pieces():
        if t0 >= end:
            break
        kept.append(Segment(v, min(t1, end) - t0))
    return Protocol(tuple(kept), name=protocol.name)


def _initial_guess(
    record: LabRecord, protocol: Protocol, guess: dict[str, float], stiffness: float | None
) -> dict[str, float]:
    """Starting values from the record: steady levels either side of the first step between two sliding
    velocities give a - b."""
    f = record.friction
    # the solver reproduces friction to ~1e-9 (rtol 1e-8 in fits): a noise-free record is known no better
    noise = max(_noise(f), MODEL_PRECISION * max(1.0, float(np.median(np.abs(f)))))
    edges, speeds = protocol.boundaries, protocol.velocities
    sliding_steps = [
        i for i in range(1, speeds.size) if min(speeds[i], speeds[i - 1]) > 0 and speeds[i] != speeds[i - 1]
    ]
    step = sliding_steps[0] if sliding_steps else None
    v1 = v2 = speeds[0]
    before = after = f[:0]
    if step is not None:
        v1, v2 = speeds[step - 1], speeds[step]
        before = f[(record.time >= edges[step - 1]) & (record.time < edges[step])]
        after = f[(record.time >= edges[step]) & (record.time < edges[step + 1])]
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
        "trend": guess.get("trend", 0.0), "time_trend": guess.get("time_trend", 0.0), "noise": noise, "max_dc": slip,
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
    trend: frozenset[str],
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
    if "slip" in trend:
        pars.add("trend", value=start["trend"])
    if "time" in trend:
        pars.add("time_trend", value=start["time_trend"])

    def residual(p: Any) -> np.ndarray:
        model = _model(record, protocol, base, p.valuesdict())
        out = (model - record.friction) / noise
        return np.where(np.isfinite(out), out, 1e6)

    try:
        # MINPACK's forward-difference step sqrt(epsfcn) = 1e-5 (relative) sits well above the solver's
        # tolerance, so the Jacobians are not solver noise
        # scale_covar=False: the intervals assume the record's own noise level; chi-square_r judges that
        result = lmfit.minimize(
            residual, pars, method="leastsq", epsfcn=1e-10, max_nfev=METHOD_MAX_NFEV, scale_covar=False
        )
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
           "trend": "trend", "time_trend": "time_trend"}  # fmt: skip


def _trend_kinds(trend: bool | str | None) -> frozenset[str]:
    """The drifts to fit: {"slip"}, {"time"}, both or none."""
    if trend is None or trend is False:
        return frozenset()
    if trend is True:
        return frozenset({"slip"})
    kinds = {"slip": {"slip"}, "time": {"time"}, "both": {"slip", "time"}, "none": set()}
    if not isinstance(trend, str) or trend.strip().lower() not in kinds:
        raise ParameterError(f"trend: expected slip, time, both or none, got {trend!r}")
    return frozenset(kinds[trend.strip().lower()])


def _length_scale(unit: str) -> float:
    """Metres per ``unit``."""
    from ..units import to_si

    return to_si(f"1 {unit}", "length", "length unit")


def _units(length_unit: str) -> dict[str, tuple[str, float]]:
    """Public name -> (unit label, SI per unit) for the values that carry a length."""
    scale = _length_scale(length_unit)
    per = (f"1/{length_unit}", 1.0 / scale)
    return {"dc": (length_unit, scale), "dc2": (length_unit, scale), "stiffness": per, "trend": per,
            "time_trend": ("1/s", 1.0)}  # fmt: skip


def _report(
    result: Any, values: dict[str, float], fit_stiffness: bool, k_fixed: float, trend: frozenset[str], redchi: float,
    units: dict[str, tuple[str, float]],
) -> tuple[dict[str, FitParameter], dict[str, float], list[str]]:  # fmt: skip
    table: dict[str, FitParameter] = {}
    warns: list[str] = []
    widen = math.sqrt(redchi) if redchi > WARN_CHI2 else None
    for key, public in _PUBLIC.items():
        if key not in result.params:
            continue
        par = result.params[key]
        se = par.stderr if par.stderr is not None and math.isfinite(par.stderr) else None
        value, stderr, interval, scaled = _interval(par.value, se, key.startswith("log_"), widen)
        note = _unconstrained(key, par, se)
        if note:
            interval = scaled = None
            warns.append(f"{public}: not constrained by the record ({note})")
        elif not key.startswith("log_") and key != "mu0" and abs(value) > 0 and se is not None and se > abs(value):
            warns.append(f"{public}: undetermined (standard error {se:.3g} exceeds the value {value:.3g})")
        unit, scale = units.get(public, ("", 1.0))
        table[public] = FitParameter(public, value, stderr, interval, unit=unit, scale=scale, constrained=not note,
                                     note=note, scaled_interval=scaled)  # fmt: skip
    if not fit_stiffness:
        unit, scale = units["stiffness"]
        table["stiffness"] = FitParameter("stiffness", k_fixed, None, None, fixed=True, unit=unit, scale=scale)
    if "slip" not in trend:
        unit, scale = units["trend"]
        table["trend"] = FitParameter("trend", 0.0, None, None, fixed=True, unit=unit, scale=scale)
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


def _interval(
    fitted: float, se: float | None, log: bool, widen: float | None
) -> tuple[float, float | None, tuple[float, float] | None, tuple[float, float] | None]:
    """Value, standard error, 95 % interval and the interval widened by ``widen`` (log-space ones asymmetric)."""
    if log:
        value = math.exp(fitted)
        if se is None:
            return value, None, None, None
        pair = (_exp(fitted - Z95 * se), _exp(fitted + Z95 * se))
        scaled = (_exp(fitted - Z95 * se * widen), _exp(fitted + Z95 * se * widen)) if widen else None
        return value, value * se, pair, scaled
    if se is None:
        return fitted, None, None, None
    scaled = (fitted - Z95 * se * widen, fitted + Z95 * se * widen) if widen else None
    return fitted, se, (fitted - Z95 * se, fitted + Z95 * se), scaled


def _unconstrained(key: str, par: Any, se: float | None) -> str:
    """Why the record does not determine this parameter ('' when it does)."""
    if not par.vary:
        return ""
    if par.min is not None and par.max is not None and math.isfinite(par.min) and math.isfinite(par.max):
        span = par.max - par.min
        if min(abs(par.value - par.min), abs(par.max - par.value)) < 1e-6 * span:
            edge = par.min if abs(par.value - par.min) < abs(par.max - par.value) else par.max
            shown = f"{math.exp(edge):.3g} m" if key.startswith("log_") and key != "log_k" else f"{edge:.3g}"
            return f"at the edge of its allowed range ({shown}): the data push it as far as allowed"
    if se is None:
        return "no standard error: the covariance is singular, the record cannot tell it apart from the others"
    if key.startswith("log_") and se > 1.0:
        return f"known only to within a factor e^{se:.2g}"
    return ""


def _difference(result: Any, table: dict[str, FitParameter], redchi: float) -> FitParameter:
    """a - b with its standard error from the covariance (their correlation included)."""
    value = table["a"].value - table["b"].value
    covar, names = result.covar, list(result.var_names)
    if covar is None or "a" not in names or "b" not in names:
        return FitParameter("a-b", value, None, None, constrained=False,
                            note="no covariance: the record cannot tell the parameters apart")  # fmt: skip
    i, j = names.index("a"), names.index("b")
    var = float(covar[i, i] + covar[j, j] - 2 * covar[i, j])
    if not (math.isfinite(var) and var >= 0):
        return FitParameter("a-b", value, None, None, constrained=False, note="covariance not positive")
    se = math.sqrt(var)
    widen = math.sqrt(redchi) if redchi > WARN_CHI2 else None
    _, _, interval, scaled = _interval(value, se, False, widen)
    return FitParameter("a-b", value, se, interval, scaled_interval=scaled)


def _problems(
    result: Any,
    record: LabRecord,
    table: dict[str, FitParameter],
    redchi: float,
    noise: float,
    trend: frozenset[str],
) -> list[str]:
    """Why the fit cannot be trusted (empty when it can)."""
    problems = []
    if not result.success:
        problems.append(f"the search did not converge ({result.message})")
    if not result.errorbars:
        problems.append("the covariance could not be estimated: the record cannot tell the parameters apart")
    if redchi > ABSURD_CHI2:
        problems.append(
            f"reduced chi-square {redchi:.3g} > {ABSURD_CHI2:g}: the model does not describe the record "
            "(check the load-point history: give it with --protocol or --segment)"
        )
    moved = [k for k in ("a", "b", "log_dc") if _moved(result.params[k])]
    if not moved and (redchi > WARN_CHI2 or not result.errorbars):  # (a start that already fits is no failure)
        problems.append("a, b and Dc did not move from their starting values")
    p_value = _response_p_value(result, record, noise, trend)
    if p_value > NO_RESPONSE_LEVEL:
        problems.append(
            f"{NO_RESPONSE_TEXT} (F test against constant friction"
            f"{' with the trends' if trend else ''}: p = {p_value:.2g}), so a, b and Dc are not determined"
        )
    loose = [f"{k} ({table[k].note})" for k in _CORE if not table[k].constrained]
    if loose:
        problems.append("not constrained by the record: " + ", ".join(loose))
    return problems


def _history_mismatch(record: LabRecord, protocol: Protocol) -> str:
    """'' when the history's displacement follows the record's; otherwise how far apart they drift."""
    expected = protocol.displacement_at(record.time)
    span = max(float(np.ptp(record.displacement)), float(np.ptp(expected)), 1e-300)
    off = float(np.max(np.abs(expected - record.displacement)))
    if off <= MISMATCH_SHARE * span:
        return ""
    scale = _length_scale(record.length_unit)
    return (
        f"the load-point history does not follow the record's displacement: they differ by up to "
        f"{off / scale:.4g} {record.length_unit} of {span / scale:.4g} {record.length_unit} (check --segment or "
        "--protocol)"
    )


def _residual_drift(record: LabRecord, resid: np.ndarray) -> float:
    """Share of the residuals' sum of squares a straight line in slip and time explains."""
    design = np.column_stack([np.ones(len(record)), record.displacement, record.time])
    coef, *_ = np.linalg.lstsq(design, resid, rcond=None)
    total = float(np.sum(resid**2))
    return 1.0 - float(np.sum((resid - design @ coef) ** 2)) / total if total > 0 else 0.0


def _moved(par: Any) -> bool:
    start = par.init_value if par.init_value is not None else par.value
    return abs(par.value - start) > 1e-9 * max(1.0, abs(start))


def _response_p_value(result: Any, record: LabRecord, noise: float, trend: frozenset[str]) -> float:
    """p of the rate-and-state fit's improvement over constant friction (plus the trend) arising by chance."""
    from scipy import stats

    columns = [np.ones(len(record))] + ([record.displacement] if "slip" in trend else [])
    columns += [record.time] if "time" in trend else []
    design = np.column_stack(columns)
    coef, *_ = np.linalg.lstsq(design, record.friction, rcond=None)
    null = float(np.sum(((record.friction - design @ coef) / noise) ** 2))
    extra = result.nvarys - design.shape[1]
    dof = max(len(record) - result.nvarys, 1)
    fitted = float(result.chisqr)
    if extra <= 0 or fitted <= 0:
        return 0.0 if null > fitted else 1.0
    f_value = max(null - fitted, 0.0) / extra / (fitted / dof)
    return float(stats.f.sf(f_value, extra, dof))


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
