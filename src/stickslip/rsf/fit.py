"""Fitting rate-and-state friction to a lab record (lmfit least squares, optional emcee posterior).

The model of a record (the spring-slider of :mod:`stickslip.rsf.solver` driven by the record's load-point
history, steady at its first velocity, which is ``V0``), what is free, the two noise estimates, the intervals and
when a fit is ``failed`` with a ``reason``: docs/rsf.md, "Fitting lab records".
"""

from __future__ import annotations

import contextlib
import math
import os
import time
from collections.abc import Callable, Iterator
from contextvars import ContextVar
from dataclasses import dataclass, field, replace
from types import SimpleNamespace
from typing import Any

import numpy as np

from ..columns import with_units
from ..errors import DataError, ModelError, ParameterError
from ..numerics.quantisation import quantum
from ..protocols import Protocol, Segment
from ..reprs import compact_repr
from ..units import to_si
from .data import (
    LabRecord,
    change_time_uncertainty,
    find_segments,
    forward,
    level_velocity_uncertainty,
    refuse_reversal,
)
from .laws import get_law
from .params import RSFParams, StateVariable, _cutoff_pair
from .saturation import Saturation, find_saturation
from .solver import simulate

__all__ = [
    "FitNotEvaluated",
    "FitParameter",
    "RSFFit",
    "fit_record",
    "refuse_one_velocity",
    "response_check",
    "restart_notice",
]

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
#: the start of the reason when the friction varies beyond its noise and the law fitted does not describe it
MISFIT_TEXT = "{law} does not describe the record"
#: the start of the reason when the law fits to the noise but not significantly better than constant friction
WEAK_RESPONSE_TEXT = "the friction's response to the velocity changes is not significant"
#: the start of the reason when freeing the stiffness held describes the record (then "{k} does not describe ...")
HELD_STIFFNESS_TEXT = "the held stiffness"
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
    si_unit: str = ""

    def as_dict(self, si: bool = True) -> dict[str, Any]:
        """In SI (``si_unit``), or in the record's units (``unit``) with ``si=False``."""
        k = 1.0 if si else self.scale

        def shown(pair: tuple[float, float] | None) -> list[float] | None:
            return [pair[0] / k, pair[1] / k] if pair else None

        out: dict[str, Any] = {
            "value": self.value / k, "unit": (self.si_unit if si else self.unit) or "dimensionless",
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

    __repr__ = compact_repr  # counts, not the record's thousands of rows

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
    #: the optimiser's own words (lmfit/MINPACK: "Fit succeeded." means only that its search ended normally; the
    #: verdict is ``status``/``reason``, and :attr:`message` says it)
    optimizer_message: str
    nfev: int
    posterior: dict[str, Any] | None = field(default=None)
    status: str = "ok"
    reason: str = ""
    derived: dict[str, FitParameter] = field(default_factory=dict)
    protocol_source: str = "given"
    #: how the noise the fit is judged by, and its intervals, were had
    noise_method: str = ""
    #: the residuals' effective number of independent rows (their autocorrelation counted)
    effective_rows: float | None = None
    #: the same fit with the drift term toggled, and whether the conclusion depends on it
    drift_sensitivity: dict[str, Any] | None = None
    window: tuple[float, float] | None = None
    step_weight: float | None = None
    #: the found history's change times (s from the fitted rows' first row): fitted where they matter, else held
    change_times: tuple[FitParameter, ...] = ()
    #: the fits tried in place of this one when its residuals exceed the noise (a held stiffness freed, another law):
    #: what each reached (docs/rsf.md, "Is another model the answer?")
    alternatives: tuple[dict[str, Any], ...] = ()
    #: readings of the values that are no warning (a negative b)
    notes: tuple[str, ...] = ()

    @property
    def message(self) -> str:
        """The fit's verdict in words: the optimiser's message beside ``status == "ok"``, else "fit failed: REASON"
        (an optimiser's "Fit succeeded." beside a failed fit read as the opposite of the status; its words stay in
        :attr:`optimizer_message`)."""
        return self.optimizer_message if self.status == "ok" else f"fit failed: {self.reason}"

    @property
    def residuals(self) -> np.ndarray:
        return self.record.friction - self.model_friction

    def protocol_rows(self, si: bool = False) -> list[dict[str, Any]]:
        """The load-point history fitted, in the record's units (or SI), with each segment's start time."""
        unit = "m" if si else self.record.length_unit
        scale = _length_scale(unit)
        starts = self.protocol.boundaries
        return [{"start": float(t), "file_time": self.record.t0 + float(t), "velocity": s.velocity / scale,
                 "duration": s.duration, "unit": f"{unit}/s"}
                for t, s in zip(starts, self.protocol.segments, strict=False)]  # fmt: skip

    def rerun_mapping(self) -> dict[str, Any]:
        """What ``rsf simulate --params`` reads to rerun the fitted model (SI): ``parameters``, the fitted history
        as ``protocol`` ([{velocity, duration}]) and ``start_velocity`` (the fit starts in steady sliding at the
        first velocity).  The drift terms (``trend``, ``time_trend``) are no part of the spring-slider: a rerun is
        the model friction without them."""
        return {
            "model": "rate-and-state spring-slider",
            "parameters": self.params.to_dict(),
            "start_velocity": self.protocol.initial_velocity,
            "protocol": [{"velocity": s.velocity, "duration": s.duration} for s in self.protocol.segments],
        }

    def parameters_document(self, report: dict[str, Any] | None = None) -> dict[str, Any]:
        """The parameters file ``rsf fit -o`` writes (NAME.params.json, or NAME.json): :meth:`rerun_mapping`, the
        report as ``fit`` (``report``, else :meth:`summary`) and a top-level ``units`` map of every key in it that has
        a unit, rate-and-state's own first (PARAMETER_FILE_UNITS: the package's registry gives ``stiffness`` the
        bond model's Pa/m, which the file's 2002.1, friction per metre of slip, is not)."""
        from ..columns import json_safe, json_units

        document = {**self.rerun_mapping(), "fit": self.summary() if report is None else report}
        return {**document, "units": json_units(json_safe(document), PARAMETER_FILE_UNITS)}

    def summary(self) -> dict[str, Any]:
        """The report as JSON: SI throughout (m, 1/m, m/s; ``units`` says so); the text keeps the record's unit."""
        return {
            "status": self.status,
            **({"reason": self.reason} if self.reason else {}),
            "parameters": {k: v.as_dict() for k, v in self.parameters.items()},
            "derived": {k: v.as_dict() for k, v in self.derived.items()},
            "v_ref": self.params.v_ref,  # the velocity mu0 is the friction at (m/s)
            "reduced_chi_square": self.reduced_chi_square,
            "rms": self.rms,
            "noise": self.noise,
            "noise_method": self.noise_method or "given",
            "effective_rows": self.effective_rows,
            "correlations": self.correlations,
            "warnings": list(self.warnings),
            "notes": list(self.notes),
            "success": self.success,
            # the optimiser's own words ("Fit succeeded.") only beside a verdict that cannot contradict them
            "message": self.message,
            "optimizer_message": self.optimizer_message,
            "protocol": self.protocol_rows(si=True),
            "protocol_source": self.protocol_source,
            "units": {
                "time": "s", "length": "m", "velocity": "m/s", "v_ref": "m/s", "dc": "m", "stiffness": "1/m",
                "trend": "1/m", "time_trend": "1/s", "friction": "dimensionless",
                "record_length_unit": self.record.length_unit,
                "change_times": "s from the fitted rows' first row (file_time: on the file's own clock)",
                "protocol": "start: s from the fitted rows' first row (file_time: on the file's own clock)",
                "clock": f"the fitted rows' first row is at record.t0 = {self.record.t0:.10g} s on the file's own "
                         "clock; every file_time is on that clock, as the window is",
                "note": "all values SI; the text report gives lengths in the record's unit",
            },
            "record": {"source": self.record.source, "rows": len(self.record), "t0": self.record.t0},
            **({"change_times": self.change_rows()} if self.change_times else {}),
            **({"window": list(self.window)} if self.window else {}),
            **({"step_weight": self.step_weight} if self.step_weight is not None else {}),
            **({"drift_sensitivity": self.drift_sensitivity} if self.drift_sensitivity else {}),
            **({"alternatives": list(self.alternatives)} if self.alternatives else {}),
            **({"posterior": self.posterior} if self.posterior else {}),
        }  # fmt: skip

    def reference_velocity_text(self) -> str:
        """``v_ref = 1 µm/s``: the velocity mu0 is the friction at (the fit's V0, its first load-point velocity)."""
        from ..display import velocity

        return f"v_ref = {velocity(self.params.v_ref)}"

    def change_rows(self) -> list[dict[str, Any]]:
        """The change times as JSON: s from the fitted rows' first row, and ``file_time`` on the file's clock."""
        return [{"name": p.name, **p.as_dict(), "file_time": self.record.t0 + p.value} for p in self.change_times]

    def change_lines(self) -> list[str]:
        """One line per change time: fitted with its interval, or held and why (s on the record file's own clock,
        the clock of ``window`` and of the title, as the text report's history is)."""
        lines, t0 = [], self.record.t0
        for p in self.change_times:
            if p.fixed or p.stderr is None or p.interval is None:
                lines.append(f"{p.name:10s} {t0 + p.value:.6f} s ({'held: ' if p.fixed else ''}{p.note})")
                continue
            digits = _decimals(p.stderr)
            lo, hi = p.interval
            lines.append(f"{p.name:10s} {t0 + p.value:.{digits}f} ± {p.stderr:.2g} s   95 % [{t0 + lo:.{digits}f}, "
                         f"{t0 + hi:.{digits}f}] ({p.note})")  # fmt: skip
        return lines

    def to_toml(self) -> str:
        head = [
            f"# rate-and-state fit of {self.record.source} ({len(self.record)} rows): {self.status}"
            + (f" ({self.reason})" if self.reason else ""),
            f"# reduced chi-square {self.reduced_chi_square:.4g}, rms {self.rms:.4g}, trend {self.trend:.6g} per m",
            f"# protocol (load point, from t0 = {self.record.t0:.10g} s on the file's own clock, as the change times "
            f"below): {self.protocol.describe()}",
        ]
        for name, p in {**self.parameters, **self.derived}.items():
            head.append(f"# {name} = {p.text()}" + (f", at {self.reference_velocity_text()}" if name == "mu0" else ""))
        head += [f"# {line}" for line in self.change_lines()]
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


def _model_or_why(
    record: LabRecord, protocol: Protocol, base: RSFParams, values: dict[str, float]
) -> tuple[np.ndarray, str]:
    """The model friction at the record's rows, or NaN and what went wrong (never the caller's fault unsaid)."""
    params = _final_params(base, values)
    try:
        run = simulate(
            params, protocol, times=record.time, rtol=FIT_RTOL, atol=FIT_RTOL * 1e-2, detect=False, mean=False
        )
    except (ModelError, ParameterError) as exc:
        return np.full(record.time.size, np.nan), f"the solver refused the run: {exc}"
    if run.status == "blow-up":  # (the solver's own advice, eta or a mass, is no option of a fit)
        return np.full(record.time.size, np.nan), (
            f"the run stopped: blow-up at t = {record.t0 + float(run.time[-1]):.6g} s on the file's clock (the model "
            "slider's slip rate passed 1e10 "
            "times the driving velocity: the spring is too soft for these a, b and Dc)"
        )
    if run.status != "ok":
        return np.full(record.time.size, np.nan), f"the run stopped: {run.message}"
    if run.time.size != record.time.size:
        return np.full(record.time.size, np.nan), (
            f"the solver returned {run.time.size} samples for the record's {record.time.size} rows (a bookkeeping "
            "error in stickslip, not in the record: please report it)"
        )
    drift = values.get("trend", 0.0) * record.displacement + values.get("time_trend", 0.0) * record.time
    return run.friction + drift, ""


#: the callback of :func:`restart_notice` in force (None: nobody is told)
_RESTART_NOTICE: ContextVar[Callable[[str, int], None] | None] = ContextVar("rsf_fit_restart_notice", default=None)


@contextlib.contextmanager
def restart_notice(notify: Callable[[str, int], None] | None) -> Iterator[None]:
    """Within the block, :func:`fit_record` calls ``notify(text, searches)`` when its first search ends troubled and
    it restarts from other starts in Dc (``searches`` more at most): what makes a fit cost several times the typical
    estimate (docs/rsf.md, "Cost estimate and --max-time")."""
    token = _RESTART_NOTICE.set(notify)
    try:
        yield
    finally:
        _RESTART_NOTICE.reset(token)


def _lab_record(record: Any) -> LabRecord:
    """``record`` as a LabRecord: one already, or read from its path (fit_steady and fit_stick take paths too)."""
    if isinstance(record, LabRecord):
        return record
    if isinstance(record, (str, os.PathLike)):
        from .data import read_record

        return read_record(record)
    raise ParameterError(f"record: expected a LabRecord or the path of a record file, got {type(record).__name__}")


def fit_record(
    record: LabRecord,
    *,
    law: str | tuple[str, ...] = "aging",
    states: int = 1,
    stiffness: float | None = None,
    fit_stiffness: bool | None = None,
    trend: bool | str = False,
    protocol: Protocol | None = None,
    guess: dict[str, float] | None = None,
    fixed: dict[str, float] | None = None,
    window: tuple[float, float] | None = None,
    step_weight: float | None = None,
    mcmc_steps: int = 0,
    seed: int | None = None,
    noise: float | None = None,
    drift_check: bool | None = None,
    cutoff: tuple[float, float] | None = None,
    alternatives: bool | None = None,
) -> RSFFit:
    """Fit rate-and-state friction to ``record`` (see the module notes).

    ``law``: one law for every state, or one per state (``("aging", "slip")`` with ``states=2``).
    ``fixed`` holds any of mu0, a, b, dc, b2, dc2, stiffness, trend, time_trend (SI) at the value given; ``guess``
    starts the search there (``guess={"stiffness": k}`` starts a free stiffness, ``fixed={"stiffness": k}`` holds
    it).  The older words still work: ``stiffness`` is held fixed unless ``fit_stiffness``, then it is a start.
    ``trend``: False, True or ``"slip"`` (linear in load-point displacement), ``"time"`` or ``"both"``.
    ``window=(t0, t1)``: fit only the rows with t0 <= time <= t1 in the record file's own time (s, i.e.
    ``record.t0 + record.time``); the slider is assumed in steady sliding at the window's start.  ``step_weight=w``
    weights the rows within :data:`STEP_RENEWALS` Dc / V after each velocity change by ``w`` (their squared
    residuals count w times); the intervals account for the weights (they are not those of an unweighted fit).
    ``mcmc_steps > 0`` adds an emcee posterior.  ``noise``: the friction noise to judge the fit by, where it is
    known (a model's noise-free output fitted to a stated precision); by default it is estimated from the
    record (``noise_method`` says how).  ``drift_check`` (default: on unless ``noise`` is given) refits with the
    drift term toggled and reports when the conclusion depends on it (``drift_sensitivity``).
    ``cutoff=(V1, V2)`` (m/s, held fixed) fits the cut-off velocity form of the friction law (docs/rsf.md, Laws).
    ``alternatives`` (default: on unless ``noise`` is given): when chi-square_r > 2 and nothing else is wrong (or
    the law's misfit, its F test against constant friction failed, is the one thing wrong), the fit is tried again
    with a held stiffness freed and with the other built-in single-state laws, from its answer, and (one state,
    where none of those describes the record) with a second state variable of the same law;
    one that describes the record significantly better fails the fit (``alternatives`` in the result says what each
    reached; docs/rsf.md, "Is another model the answer?").
    Within ``with restart_notice(notify):``, ``notify(text, searches)`` is told when the first search ends troubled
    and the fit restarts it from other starts in Dc (``searches`` more at most): the moment a fit's cost leaves the
    typical estimate (``rsf fit`` says it on stderr).
    ``record`` may also be the path of a record file, read by :func:`stickslip.rsf.data.read_record` with its columns
    found by name (``read_record`` itself takes a column map and units).
    """
    arguments = {key: value for key, value in locals().items() if key != "record"}  # (a saturated sensor's 2 passes)
    record = _lab_record(record)
    if noise is not None and not (_real(noise) and math.isfinite(noise) and noise > 0):
        raise ParameterError(f"noise: expected a positive friction level, got {noise!r}")
    if states not in (1, 2):
        raise ParameterError(f"states: expected 1 or 2 state variables, got {states!r}")
    laws = _laws(law, states)
    cutoff = None if cutoff is None else _cutoff_pair(cutoff)  # as RSFParams checks it (positive, finite, m/s)
    kinds = _trend_kinds(trend)
    held = _named_values("fixed", fixed, states, strict=True)
    starts = _named_values("guess", guess, states, strict=False)
    held, starts = _stiffness_words(stiffness, fit_stiffness, held, starts)
    twice = sorted(set(held) & set(starts))
    if twice:
        raise ParameterError(f"{twice[0]}: both fixed and guessed; expected one of them")
    if step_weight is not None and not (_real(step_weight) and math.isfinite(step_weight) and step_weight > 0):
        raise ParameterError(f"step_weight: expected a positive weight, got {step_weight!r}")
    weight = None if step_weight is None else float(step_weight)
    source = "given" if protocol is not None else f"found from the load-point {record.displacement_from}"
    protocol_found = protocol is None
    given_record = record
    record, protocol, backwards = _fitted_rows(record, protocol, window)
    if protocol.initial_velocity <= 0:
        raise DataError("record: the load point does not move in the first segment; expected steady sliding first")
    saturation = find_saturation(record.friction)
    if saturation is not None:  # a clipped sensor: its rows (and those its model puts near the limit) censored
        censor = _CENSOR.get()
        if censor is None and not _CHECK_ONLY.get():
            return _censored_fit(given_record, record, protocol, saturation, arguments)
        record = saturation.censored(record, saturation.at if censor is None else censor)
    mismatch = _history_mismatch(record, protocol)
    if not mismatch:  # (a given history that is not the record's fails as such)
        _refuse_one_velocity(record, protocol)
    labels = _sampling_classes(record.time)
    given = noise is not None
    setup = _Setup(record, protocol, laws, states, "stiffness" not in held, kinds, held, None, frozenset(starts),
                   cutoff)  # fmt: skip
    start = _stable_start(_initial_guess(record, protocol, {**starts, **held}, held.get("stiffness")),
                          "dc" in starts or "dc" in held)  # fmt: skip
    start["noise"] = float(noise) if given else _pre_fit_noise(record, protocol, start["dc"], labels, start["noise"])
    check = None if mismatch else _response_check(setup, labels, start["noise"], given)
    if check is None and _CHECK_ONLY.get():
        return None  # type: ignore[return-value]  # (response_check: the search may go on)
    if check is not None:  # no response to fit: said in seconds, before the search and its restarts
        return _unsearched_fit(setup, start, check, source, window, weight)
    result, residual, given_up = _best_search(setup, start, mismatch, "stiffness" in starts or "stiffness" in held)
    seen: dict[int, dict[str, float]] = {}
    if protocol_found and not mismatch and len(protocol.segments) > 1:
        # the found change times are estimates: those that matter are fitted, so the intervals carry them
        first = result.params.valuesdict()
        changes, seen, prior_weight = _free_changes(setup, _base(setup, start), first, start["noise"], labels)
        setup = replace(setup, levels=tuple(level_velocity_uncertainty(record.time, record.displacement, protocol)))
        if changes:
            setup = replace(setup, changes=changes, change_noise=start["noise"], change_weight=prior_weight)
            result, residual = _least_squares(setup, {**start, **_start_values(first)})
            # the first fit's residuals hold the misplaced changes' misfit too: weigh the priors again by this fit's
            values = result.params.valuesdict()
            model, why = _model_or_why(record, _history(setup, values), _base(setup, start), values)
            again = prior_weight if why else _prior_weight(record.friction - model, start["noise"], labels)
            if not 0.5 <= again / prior_weight <= 2.0:
                setup = replace(setup, change_weight=again)
                result, residual = _least_squares(setup, {**start, **_start_values(values)})
    if weight is not None:
        first = _start_values(result.params.valuesdict())
        setup = replace(setup, weights=_step_weights(record, protocol, first["dc"], weight))
        result, residual = _least_squares(setup, {**start, **first})
    ladder: list[tuple[float, float, dict[str, float]]] = []
    if not mismatch and setup.fit_stiffness and _stiffness_loose(result):  # (with the change times, as the fit)
        result, residual, ladder = _stiffness_ladder(setup, start, result, residual)
    result, residual = _polish(setup, start, result, residual)
    curvature = _quadratic_check(result, residual)  # (with the search's own covariance, before it is replaced)
    base = _base(setup, start)
    values = result.params.valuesdict()
    try:
        model = _evaluated(setup, base, values)
    except ModelError as exc:  # no start tried could leave it: the report still says where the search ended
        failed = _unevaluated_fit(setup, start, result, str(exc), source, window, weight)
        raise FitNotEvaluated(str(exc), failed) from None
    level = _uncertainty(setup, base, result, model, labels, float(noise) if given else None)
    resid = record.friction - model
    units = _units(record.length_unit)
    widen = math.sqrt(level.redchi) if given and level.redchi > WARN_CHI2 else None
    table, corr, warns = _report(result, values, setup, start["stiffness"], widen, units)
    change_times, change_warns = _change_report(setup, result, seen) if protocol_found else ((), [])
    warns += change_warns + given_up
    if backwards:
        warns.insert(0, "the load-point displacement decreases (the load point moves in the negative direction): "
                        "it was taken by its magnitude, as friction depends on the speed only")  # fmt: skip
    derived = {"a-b": _difference(result, table, widen)}
    drift = _drift_reading(setup, start, result, resid, level, refit=not mismatch)
    opening = _opening_reading(record, setup.protocol, resid, level)
    opening_problem = ""
    if opening.warning and drift.text and not drift.describes:
        # the fit bends a, b, Dc and mu0 to an opening transient, and the residuals' line measures that bend, not a
        # drift to fit (the tester's record starting 1.5 s after an unseen step was told to fit the drift it had
        # fitted): the opening is the cause the reason gives, the drift's share beside it
        opening_problem = opening.problem + (
            f"; a line in slip and time explains {100 * drift.share:.0f} % of the residuals, which that bend leaves "
            "too: judge a drift once the opening is left out")  # fmt: skip
        drift = _Drift(drift.share)
    problems = _problems(result, record, resid, table, level, setup, drift.advice if drift.leads else "",
                         bool(opening.warning))  # fmt: skip
    if setup.states == 2 and not problems:
        problems += _second_state_problems(setup, start, result)
    if drift.text:  # one that explains most of the residuals comes first: no law can be judged before it is fitted
        problems.insert(0 if drift.leads else len(problems), drift.text)
    if opening.warning and not drift.describes and (problems or opening_problem):  # (alone: a warning, as before)
        problems.insert(0, opening_problem or opening.problem)
    tried: tuple[dict[str, Any], ...] = ()
    tried_said = ""  # what the alternatives tried reached, beside the chi-square warning
    # a law's misfit alone (its F test against constant friction not significant with its own smooth residuals as
    # the noise) is no reason to skip them: which model does describe the record is the advice it needs, and that F
    # test's effective rows grow with the sampling rate (the tester's two-state record: p = 0.001 at 100 Hz, 9e-35
    # at 1 kHz), so at 100 Hz it said "fit another law" where at 1 kHz it named --states 2
    misfit = _misfit_alone(problems, setup.laws)
    if ((not problems or misfit) and not mismatch and level.redchi > WARN_CHI2
            and (not given if alternatives is None else alternatives)):  # fmt: skip
        p_response = _response_p_value(result, record, resid, setup.trend, level.inflation) if misfit else 1.0
        tried, failure, tried_said = _alternatives(setup, start, result, model, level, labels, units,
                                                   float(noise) if given else None,
                                                   _misfit_words(record, resid, setup, level, p_response)
                                                   if misfit else "")  # fmt: skip
        if misfit and (failure or not any("skipped" in r for r in tried)):  # (else the floor's warning says why)
            problems = [failure or _no_response_problem(record, resid, setup, level, p_response, tried=tried_said)]
            tried_said = ""  # (in the reason)
        else:
            problems += [failure] if failure else []
    why = _law_not_determined(problems, setup.laws)
    if why:  # then no interval of the friction law means anything
        for key in ("a", "b", "dc", "b2", "dc2", "stiffness"):
            if key in table and not table[key].fixed:
                table[key] = replace(table[key], interval=None, scaled_interval=None, constrained=False, note=why)
        if not derived["a-b"].fixed:
            derived["a-b"] = replace(derived["a-b"], interval=None, scaled_interval=None, constrained=False, note=why)
    if ladder and not table["stiffness"].fixed and not table["stiffness"].constrained and not why:
        loose, said = _stiffness_dependence(setup, start, result, resid, labels, table, ladder, units)
        problems += [said] if loose else []
        warns += [] if loose else [said]
    if mismatch:
        problems.insert(0, mismatch)
    warns += _chi2_warnings(level, given) + ([tried_said] if tried_said else [])
    warns += [opening.warning] if opening.warning else []
    if curvature is not None and not (QUADRATIC_RANGE[0] <= curvature <= QUADRATIC_RANGE[1]):
        warns.append(
            f"the chi-square surface is not quadratic over the intervals: two standard errors along the least "
            f"determined direction raise chi-square by {4 * curvature:.3g} instead of 4, so the intervals "
            f"(from the curvature at the best fit) are approximate{' and too narrow' if curvature < 1 else ''}; "
            "--mcmc N gives a posterior that does not assume it"
        )
    sensitivity = None
    if (not given if drift_check is None else drift_check) and not mismatch and "trend" not in held:
        sensitivity = _drift_sensitivity(setup, start, result, table, derived, labels, given, noise)
        if sensitivity["depends"]:
            warns.append(sensitivity["text"])
    tempered = None if level.scale is None else start["noise"] / level.scale  # the search's residuals' scale undone
    posterior = _posterior(residual, result, mcmc_steps, seed, tempered) if mcmc_steps > 0 else None
    # the record's own notes (rows left out) belong to every report, a failed one too (the CLI prints warnings only
    # on success); the signs' notes only to a fit whose values are a reading
    notes = (*record.notes, *(() if problems else _sign_notes(table)))
    return RSFFit(
        params=_final_params(base, values), parameters=table, correlations=corr, reduced_chi_square=level.redchi,
        rms=float(np.sqrt(np.mean(resid**2))), noise=level.noise, trend=float(values.get("trend", 0.0)),
        record=record, protocol=_history(setup, values), model_friction=model, warnings=tuple(warns),
        success=not problems, change_times=change_times,
        optimizer_message=str(result.message), nfev=int(result.nfev), posterior=posterior,
        status="failed" if problems else "ok", reason="; ".join(problems), derived=derived, protocol_source=source,
        noise_method=level.method, effective_rows=level.n_eff, drift_sensitivity=sensitivity,
        window=None if window is None else (float(window[0]), float(window[1])), step_weight=weight,
        alternatives=tried, notes=notes,
    )  # fmt: skip


#: fit_record itself, for :func:`response_check` (a caller's stand-in for fit_record, a test's, is not it)
_fit_record = fit_record


#: the rows a saturated sensor's fit leaves out (None: found afresh; :func:`_censored_fit`)
_CENSOR: ContextVar[np.ndarray | None] = ContextVar("rsf_fit_censor", default=None)


def _censored_fit(
    given: LabRecord, rows: LabRecord, protocol: Protocol, saturation: Saturation, arguments: dict[str, Any]
) -> RSFFit:
    """The fit of a record whose sensor saturates: a first fit without the rows at the limit, whose model (over every
    row) puts more rows within the censoring band; the fit without those (docs/rsf.md, "A saturated sensor")."""
    out = saturation.at
    quick = {**arguments, "alternatives": False, "drift_check": False, "mcmc_steps": 0}
    token = _CENSOR.set(out)
    try:
        first = fit_record(given, **quick)
        model = simulate(first.params, first.protocol, times=rows.time, rtol=FIT_RTOL, atol=FIT_RTOL * 1e-2,
                         detect=False, mean=False).friction  # fmt: skip
        model = (
            model
            + first.trend * rows.displacement
            + first.parameters.get("time_trend", FitParameter("time_trend", 0.0, None, None)).value * rows.time
        )
        if model.size == rows.time.size and np.all(np.isfinite(model)) and math.isfinite(first.rms):
            out = out | saturation.near(model, first.rms)
    except (ModelError, ParameterError):  # (the fit without the rows at the limit alone says what went wrong)
        pass
    finally:
        _CENSOR.reset(token)
    token = _CENSOR.set(out)
    try:
        return fit_record(given, **arguments)
    finally:
        _CENSOR.reset(token)


#: set by :func:`response_check`: :func:`fit_record` returns after its check before the search (None: it may search)
_CHECK_ONLY: ContextVar[bool] = ContextVar("rsf_fit_check_only", default=False)


def response_check(record: LabRecord, **arguments: Any) -> RSFFit | None:
    """The failed fit of a record whose friction shows no response to its velocity changes, found as
    :func:`fit_record` (the same arguments) finds it before its search, in seconds; None where the search is needed
    (``rsf fit`` asks before estimating the fit's cost: docs/rsf.md, "No response, said before the search").
    Bad input is refused as :func:`fit_record` refuses it (rows at one velocity among them)."""
    token = _CHECK_ONLY.set(True)
    try:
        return _fit_record(record, **arguments)
    finally:
        _CHECK_ONLY.reset(token)


#: the check before the search: each change's decays, their time scales this factor apart, from
#: RESPONSE_FIRST_ROWS rows after the change to the rest of the record
RESPONSE_SCALE_STEP = 10.0
RESPONSE_FIRST_ROWS = 3
#: the search is skipped where the check's terms lower chi-square (in effective independent rows) by less than this
#: share of what the fit's own F test needs to call a response significant at NO_RESPONSE_LEVEL
RESPONSE_SHARE = 0.5
#: ... and the check is not made (the search decides) where its design would hold more cells than this (memory)
#: or more columns than this share of the rows
RESPONSE_MAX_CELLS = 30_000_000
RESPONSE_MAX_COLUMNS = 0.1


def _response_terms(record: LabRecord, protocol: Protocol) -> np.ndarray | None:
    """The check's step-response columns: per change, a level from it on (one level per segment) and decays
    exp(-(t - t_i) / tau) from it on, tau a factor RESPONSE_SCALE_STEP apart from RESPONSE_FIRST_ROWS rows' time to
    the rest of the record (a change's direct effect, its evolution over Dc / V and the spring's loading at any
    scale the rows resolve, and a hold's relaxation); None where they are too many (RESPONSE_MAX_CELLS)."""
    t = record.time
    edges = protocol.boundaries
    starts = []
    for edge in edges[1:-1]:
        k = int(np.searchsorted(t, edge))
        if k >= t.size - 1:
            continue
        spacing = float(np.median(np.diff(t[k : k + 50])))
        rest = float(t[-1] - edge)
        if not (spacing > 0 and rest > 0):
            continue
        low = math.log10(RESPONSE_FIRST_ROWS * spacing)
        count = max(math.ceil((math.log10(rest) - low) / math.log10(RESPONSE_SCALE_STEP)), 0) + 1
        starts.append((float(edge), RESPONSE_FIRST_ROWS * spacing * RESPONSE_SCALE_STEP ** np.arange(count)))
    columns = sum(1 + scales.size for _, scales in starts)
    if not starts or columns * t.size > RESPONSE_MAX_CELLS or columns > RESPONSE_MAX_COLUMNS * t.size:
        return None
    out = np.zeros((t.size, columns))
    j = 0
    for edge, scales in starts:
        after = t >= edge
        since = t[after] - edge
        out[after, j] = 1.0
        for tau in scales:
            out[after, j + 1] = np.exp(-since / tau)
            j += 1
        j += 1
    return out


def _response_check(setup: _Setup, labels: np.ndarray, noise: float, given: bool) -> dict[str, float] | None:
    """Whether the friction responds to the velocity changes at all, before the search: where a step response of
    any shape the rows resolve (:func:`_response_terms`, least squares, no model run) lowers chi-square against
    constant friction (plus the trends asked for) by less than RESPONSE_SHARE of what the rate-and-state fit's own F
    test (:func:`_response_p_value`, its free parameters beyond mu0 against constant friction) needs at
    NO_RESPONSE_LEVEL, no fit can find one: what it found (a dict), else None (the search goes on).  The drop is
    counted against the terms' residuals' variance, their rows counted 1/g each by their correlation (as that F
    test counts the fit's), or against ``noise`` (the steady sliding's, which the search is judged by) with every
    row counted, whichever makes it larger.  The terms can take up more of any response than the law's few
    parameters, and more terms only lower the chance of skipping a search, so skipping is conservative."""
    from scipy import stats

    record, held = setup.record, setup.fixed
    core = ("a", "b", "dc", "stiffness") + (("b2", "dc2") if setup.states == 2 else ())
    extra_law = sum(1 for key in core if key not in held)  # (the stiffness is free unless held)
    if "mu0" in held or extra_law == 0:
        return None
    terms = _response_terms(record, setup.protocol)
    if terms is None:
        return None
    null = _constant_design(record, setup.trend)
    design = np.column_stack([null, terms])
    design = design / np.maximum(np.max(np.abs(design), axis=0), 1e-300)  # (columns of one size for lstsq)
    f = record.friction
    n = f.size
    coef, *_ = np.linalg.lstsq(design[:, : null.shape[1]], f, rcond=None)
    constant = float(np.sum((f - design[:, : null.shape[1]] @ coef) ** 2))
    coef, _, rank, _ = np.linalg.lstsq(design, f, rcond=None)
    resid = f - design @ coef
    fitted = float(np.sum(resid**2))
    extra = int(rank) - int(np.linalg.matrix_rank(null))
    if extra <= 0 or n - rank < 10 or not fitted > 0:
        return None
    inflation = 1.0 if given else n / float(np.sum(1.0 / _correlation_factor(resid, labels)))
    # the rows' noise as the terms' residuals measure it, or as the search will judge it (``noise``, the steady
    # sliding's, counting each row once), whichever finds the larger drop: where the terms miss part of a response
    # far above the noise, their residuals are one smooth curve and would count the record as a few rows
    scale = min(fitted / (n - rank) * inflation, noise**2) if noise > 0 else fitted / (n - rank) * inflation
    inflation = scale / (fitted / (n - rank))
    lowered = (constant - fitted) / scale
    dof = max((n - rank) / inflation, 1.0)
    needed = extra_law * float(stats.f.isf(NO_RESPONSE_LEVEL, extra_law, dof))
    if not lowered < RESPONSE_SHARE * needed:
        return None
    return {"lowered": lowered, "needed": needed, "terms": float(extra), "p": float(stats.f.sf(lowered / extra, extra,
            dof)), "effective_rows": n / max(inflation, 1.0), "law_terms": float(extra_law)}  # fmt: skip


def _unsearched_fit(
    setup: _Setup, start: dict[str, float], check: dict[str, float], source: str, window: Any, weight: float | None
) -> RSFFit:
    """The failed report of a fit :func:`_response_check` ends before its search: the starting values, no
    intervals, the model not run (NaN), and the check's words (docs/rsf.md, "No response, said before the
    search")."""
    import lmfit

    record = setup.record
    trends = " with the trends" if setup.trend else ""
    noise = float(start["noise"])
    constant = _constant_chi2(record, setup.trend, np.full(len(record), noise))
    said = (f"constant friction{trends} describes the record to within its noise (reduced chi-square {constant:.3g}"
            f" against the noise {noise:.2g})" if constant <= WARN_CHI2 else
            f"the friction varies beyond its noise (constant friction{trends}: reduced chi-square {constant:.3g} "
            f"against the noise {noise:.2g}), but not with the velocity changes")  # fmt: skip
    reason = (
        f"{NO_RESPONSE_TEXT}: {said}; a step response of any shape the rows resolve ({check['terms']:.0f} terms: a "
        f"level after each change and decays at time scales a decade apart) lowers chi-square by "
        f"{check['lowered']:.3g} (in {check['effective_rows']:.4g} effective independent rows), under "
        f"{RESPONSE_SHARE:g} of the {check['needed']:.3g} the fit's {check['law_terms']:.0f} rate-and-state "
        f"parameters need to be significant at the {NO_RESPONSE_LEVEL:g} level (F test of the terms: p = "
        f"{check['p']:.2g}), so a, b and Dc are not determined; the search was not run (the values are its start)"
    )
    pars = lmfit.Parameters()
    pars.add("mu0", value=start["mu0"])
    pars.add("a", value=start["a"])
    pars.add("b", value=start["b"])
    pars.add("log_dc", value=math.log(start["dc"]))
    if setup.states == 2:
        pars.add("b2", value=start["b2"])
        pars.add("log_dc2", value=math.log(start["dc2"]))
    if setup.fit_stiffness:
        pars.add("log_k", value=math.log(start["stiffness"]))
    for key in ("trend", "time_trend"):
        if {"trend": "slip", "time_trend": "time"}[key] in setup.trend:
            pars.add(key, value=start[key])
    for key, value in setup.fixed.items():
        name = _INTERNAL[key]
        if key == "stiffness" or (key in ("b2", "dc2") and setup.states != 2):
            continue
        pars.add(name, value=math.log(value) if name.startswith("log_") else value, vary=False)
    values = pars.valuesdict()
    table, _, _ = _report(SimpleNamespace(params=pars), values, setup, start["stiffness"], None,
                          _units(record.length_unit))  # fmt: skip
    note = _law_not_determined([reason], setup.laws)
    for key, par in table.items():
        if not par.fixed:
            said = note if key in ("a", "b", "dc", "b2", "dc2", "stiffness") else "not fitted: the search was not run"
            table[key] = replace(par, stderr=None, interval=None, scaled_interval=None, constrained=False, note=said)
    a_b = FitParameter("a-b", table["a"].value - table["b"].value, None, None, constrained=False, note=note)
    return RSFFit(
        params=_final_params(_base(setup, start), values), parameters=table, correlations={},
        reduced_chi_square=math.nan, rms=math.nan, noise=noise, trend=float(values.get("trend", 0.0)),
        record=record, protocol=setup.protocol, model_friction=np.full(len(record), np.nan), warnings=(),
        success=False, optimizer_message="not run: no response to fit", nfev=0, status="failed", reason=reason,
        derived={"a-b": a_b}, protocol_source=source, window=None if window is None else
        (float(window[0]), float(window[1])), step_weight=weight, notes=record.notes,
    )  # fmt: skip


def fitted_rows(record: LabRecord, protocol: Protocol | None = None, window: Any = None) -> tuple[LabRecord, Protocol]:
    """The rows a fit uses (those of ``window``, on the record file's own clock) and their load-point history:
    ``protocol`` from the window's first row to its last, or the history found from the displacement.

    ``rsf fit`` times one model run over exactly these before it fits (its cost estimate).
    """
    rows, history, _ = _fitted_rows(record, protocol, window)
    return rows, history


def _fitted_rows(record: LabRecord, protocol: Protocol | None, window: Any) -> tuple[LabRecord, Protocol, bool]:
    """:func:`fitted_rows`, and whether the displacement decreases (then it is taken by its magnitude)."""
    rows, backwards = forward(_windowed(record, window))
    if protocol is None:
        found = find_segments(rows.time, rows.displacement, t0=rows.t0)
        refuse_reversal(rows, found)
        return rows, found, backwards
    return rows, _covering(_shifted(protocol, rows.t0 - record.t0), rows), backwards


def refuse_one_velocity(rows: LabRecord, protocol: Protocol) -> None:
    """DataError where the fitted rows ``rows`` hold one velocity of ``protocol`` (their own history, as
    :func:`fitted_rows` gives both), as :func:`fit_record` refuses them: no law can be fitted without a change (a
    history that does not follow the rows is left to the fit, which fails it as such)."""
    if not _history_mismatch(rows, protocol):
        _refuse_one_velocity(rows, protocol)


def _refuse_one_velocity(rows: LabRecord, protocol: Protocol) -> None:
    """No law can be fitted to rows at one velocity: a, b and Dc are read off the response to its changes."""
    speeds = protocol.velocities
    if np.all(np.abs(speeds - speeds[0]) <= 1e-9 * np.max(np.abs(speeds))):
        scale = _length_scale(rows.length_unit)
        clock = rows.t0 + rows.time
        raise DataError(
            f"record: the load point moves at one velocity ({speeds[0] / scale:.4g} {rows.length_unit}/s) over all "
            f"the rows fitted ({rows.source}, {clock[0]:g} ... {clock[-1]:g} s): there are no velocity changes, so "
            "no rate-and-state law can be fitted (a, b and Dc are read off the friction's response to a change); "
            "fit rows that hold one (a --window around a step)"
        )


@dataclass(frozen=True)
class _Setup:
    """What one least-squares search fits: the record, its history, the laws, what is free and the row weights."""

    record: LabRecord
    protocol: Protocol
    laws: tuple[str, ...]
    states: int
    fit_stiffness: bool
    trend: frozenset[str]
    fixed: dict[str, float]
    weights: np.ndarray | None
    #: the names the caller gave starting values for (the staged search keeps them)
    guessed: frozenset[str] = frozenset()
    #: the cut-off velocities (V1, V2) of the cut-off form, held fixed; None for the classical law
    cutoff: tuple[float, float] | None = None
    #: change times of a found history fitted as nuisance parameters: (boundary index, its uncertainty in s)
    changes: tuple[tuple[int, float], ...] = ()
    #: the friction noise the search scales its residuals by while the change times carry their prior
    change_noise: float = 1.0
    #: how much less each friction row tells than the search's chi-square says (the first fit's residual variance
    #: over the search's noise squared, times rows per independent row): the priors are weighted up by it
    change_weight: float = 1.0
    #: each level's velocity uncertainty (m/s) where the history was found from the displacement (carried into the
    #: intervals by :func:`_level_covariance`); empty for a history given (held exact)
    levels: tuple[float, ...] = ()
    #: model runs one least-squares search may take (an alternative's search is given fewer: its cost is bounded)
    max_nfev: int = 0


#: the names ``fixed`` and ``guess`` take (SI values)
FIXABLE = ("mu0", "a", "b", "dc", "b2", "dc2", "stiffness", "trend", "time_trend")
#: a step's weight covers the rows up to this many Dc / V after the velocity change
STEP_RENEWALS = 3.0


def _real(value: Any) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)


def _laws(law: Any, states: int) -> tuple[str, ...]:
    """One law name per state variable (a single name serves them all)."""
    names = (law,) * states if isinstance(law, str) else tuple(law) if isinstance(law, (tuple, list)) else None
    if names is None or len(names) != states or not all(isinstance(n, str) for n in names):
        raise ParameterError(f"law: expected a law name or {states} of them (one per state), got {law!r}")
    for name in names:
        get_law(name)  # ParameterError naming the law and the known ones
    return tuple(n.strip().lower() for n in names)


def _named_values(word: str, values: Any, states: int, strict: bool) -> dict[str, float]:
    """``fixed``/``guess`` checked: known names, finite numbers, positive where they must be."""
    if values is None:
        return {}
    if not isinstance(values, dict):
        raise ParameterError(f"{word}: expected a mapping of parameter names to values, got {values!r}")
    out = {}
    for key, value in values.items():
        if key not in FIXABLE:
            raise ParameterError(f"{word}: unknown parameter {key!r}; expected one of {', '.join(FIXABLE)}")
        if key in ("b2", "dc2") and states != 2:
            raise ParameterError(f"{word}: {key} needs two state variables (states=2)")
        if not (_real(value) and math.isfinite(value)):
            raise ParameterError(f"{word}: {key} = {value!r}; expected a finite number (SI)")
        if (key in ("dc", "dc2", "stiffness") or (strict and key == "a")) and not value > 0:
            raise ParameterError(f"{word}: {key} = {value!r}; expected a positive value (SI)")
        out[key] = float(value)
    return out


def _stiffness_words(
    stiffness: float | None, fit_stiffness: bool | None, held: dict[str, float], starts: dict[str, float]
) -> tuple[dict[str, float], dict[str, float]]:
    """The older keywords in the new words: ``stiffness`` fixed, or a start with ``fit_stiffness``."""
    if stiffness is None:
        if fit_stiffness is False and "stiffness" not in held:
            raise ParameterError("fit_stiffness: False needs a stiffness to hold (fixed={'stiffness': k})")
        return held, starts
    if not (_real(stiffness) and math.isfinite(stiffness) and stiffness > 0):
        raise ParameterError(f"stiffness: expected a positive stiffness (1/m), got {stiffness!r}")
    into = starts if fit_stiffness else held
    other = held if fit_stiffness else starts
    if ("stiffness" in into and into["stiffness"] != float(stiffness)) or "stiffness" in other:
        raise ParameterError("stiffness: given twice (as stiffness= and in fixed/guess); expected it once")
    return ({**held, "stiffness": float(stiffness)}, starts) if not fit_stiffness else (
        held, {**starts, "stiffness": float(stiffness)})  # fmt: skip


def _windowed(record: LabRecord, window: Any) -> LabRecord:
    """The rows inside ``window`` (the record file's own time), as a record of their own."""
    if window is None:
        return record
    if not (isinstance(window, (tuple, list)) and len(window) == 2 and all(_real(w) for w in window)):
        raise ParameterError(f"window: expected (start, end) in seconds of the record's own time, got {window!r}")
    lo, hi = float(window[0]), float(window[1])
    clock = record.t0 + record.time
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ParameterError(f"window: expected finite start < end, got {window!r}")
    inside = (clock >= lo) & (clock <= hi)
    if int(inside.sum()) < 10:
        raise ParameterError(
            f"window: {lo:g} ... {hi:g} s holds {int(inside.sum())} rows of the record ({clock[0]:g} ... "
            f"{clock[-1]:g} s); expected at least 10"
        )
    source = f"{record.source} [{lo:g} ... {hi:g} s]"
    kept = LabRecord.from_arrays(clock[inside], record.displacement[inside], record.friction[inside], source=source,
                                 length_unit=record.length_unit)  # fmt: skip
    return replace(kept, displacement_from=record.displacement_from)


def _shifted(protocol: Protocol, offset: float) -> Protocol:
    """The history from ``offset`` (s) on, restarted at t = 0 there."""
    if offset <= 0:
        return protocol
    kept = [Segment(v, t1 - max(t0, offset)) for t0, t1, v in protocol.pieces() if t1 > offset]
    if not kept:
        raise DataError(f"protocol: it ends at {protocol.duration:g} s, before the window starts ({offset:g} s in)")
    return Protocol(tuple(kept), name=protocol.name)


def _step_weights(record: LabRecord, protocol: Protocol, dc: float, weight: float) -> np.ndarray:
    """``weight`` on the rows within STEP_RENEWALS Dc / V after each velocity change, 1 elsewhere."""
    out = np.ones(len(record))
    edges, speeds = protocol.boundaries, protocol.velocities
    for i in range(1, speeds.size):
        if speeds[i] == speeds[i - 1]:
            continue
        speed = max(speeds[i], speeds[i - 1])
        zone = (record.time >= edges[i]) & (record.time < edges[i] + STEP_RENEWALS * dc / speed)
        out[zone] = weight
    return out


#: a restart in Dc may take at most the CPU of this many model runs at the first search's pace (METHOD_MAX_NFEV:
#: what a whole search may take).  The tester's record opening on an unseen step: the first search took 1.0 s for 89
#: runs, and the restart from Dc = 22 nm ran into a near-critical corner (Dc 5.6 nm, k 3e5 1/m, a slowly ringing
#: slider) at 0.17 s a run, 107 s for 633 runs, to a chi-square 2.5x the first search's (2026-12-02, AVX2 host;
#: 0.8 s and back to the first search's minimum on the host before)
RETRY_RUNS = METHOD_MAX_NFEV

#: the CPU time (time.process_time) past which a model run of the restart under way gives it up (inf: none)
_DEADLINE: ContextVar[float] = ContextVar("rsf_fit_deadline", default=math.inf)


class _OverBudget(Exception):
    """A restart's model runs passed its deadline (:data:`RETRY_RUNS`)."""


def _budgeted_search(setup: _Setup, start: dict[str, float], budget: float) -> Any:
    """:func:`_search` from ``start``, given up (:class:`_OverBudget`) once it has taken ``budget`` s of CPU; the
    residual it returns is free of the deadline (the fit goes on with it)."""
    token = _DEADLINE.set(time.process_time() + budget)
    try:
        return _search(setup, start)
    finally:
        _DEADLINE.reset(token)


def _best_search(
    setup: _Setup, start: dict[str, float], mismatch: str, stiffness_given: bool
) -> tuple[Any, Any, list[str]]:
    """The search, restarted from other starts when it never got going (the model cannot be run there, or a, b and
    Dc did not move), and elsewhere in Dc while it is troubled (a local minimum, no covariance); the
    :func:`restart_notice` callback is told before the first restart in Dc.  A restart in Dc that runs over
    :data:`RETRY_RUNS` model runs at the first search's pace is given up; the words saying so are returned."""
    notify = _RESTART_NOTICE.get()
    began = time.process_time()
    result, residual = _search(setup, start)
    pace = (time.process_time() - began) / max(int(getattr(result, "nfev", 0) or 0), 1)
    given_up: list[str] = []
    if not mismatch and _stuck(setup, start, result):
        for other in _rescue_starts(setup, start, stiffness_given):
            retry, retry_residual = _search(setup, other)
            if retry.chisqr < result.chisqr * (1 - 1e-9):
                result, residual = retry, retry_residual
            if not _stuck(setup, other, result):
                break
    sides: set[bool] = set()  # the sides of the first start in Dc that retries have started from
    for factor in RETRY_DC_FACTORS:  # a troubled search may sit in a local minimum: start it elsewhere in Dc
        if mismatch or not _troubled(result) or "dc" in setup.fixed:  # (no start helps a history not the record's)
            break
        if notify is not None and not sides:
            notify(f"the first search ended {_trouble_words(result)}: restarting it from other starts in Dc",
                   len(RETRY_DC_FACTORS))  # fmt: skip
        other = {**start, "dc": min(max(start["dc"] * factor, 2e-9), 0.5 * start["max_dc"])}
        if not stiffness_given:
            other["stiffness"] = start["stiffness"] * start["dc"] / other["dc"]
        sides.add(factor > 1.0)
        budget = RETRY_RUNS * pace
        try:
            retry, retry_residual = _budgeted_search(setup, other, budget)
        except _OverBudget:
            given_up.append(
                f"the restart of the search from Dc = {other['dc']:.3g} m was given up after {budget:.3g} s of CPU"
                f" (the cost of {RETRY_RUNS} model runs at the first search's pace, {pace:.3g} s a run): its runs"
                " had slowed, so a minimum that way is not ruled out"
            )
            continue
        same = abs(retry.chisqr - result.chisqr) <= 1e-4 * result.chisqr
        if retry.chisqr < result.chisqr * (1 - 1e-9) or (_troubled(result) and not _troubled(retry)):
            result, residual = retry, retry_residual
        # the same answer from starts on both sides: the record, not the start, is the cause (from one side only, the
        # start may sit in the basin of a minimum at the edge of Dc, which a start further that way only confirms:
        # RETRY_DC_FACTORS' docs)
        if same and _troubled(retry) and len(sides) == 2:
            break
    return result, residual, given_up


#: halvings (in log k) of the gap between the softest ladder rung within the 95 % region and the next softer one
STIFFNESS_BISECTIONS = 2


def _stiffness_dependence(
    setup: _Setup, start: dict[str, float], result: Any, resid: np.ndarray, labels: np.ndarray,
    table: dict[str, FitParameter], ladder: list[tuple[float, float, dict[str, float]]],
    units: dict[str, tuple[str, float]],
) -> tuple[bool, str]:  # fmt: skip
    """Whether a, b or Dc depend on a free stiffness the record leaves unconstrained, and the words: the softest
    stiffness held (ladder rungs, then bisection) whose chi-square lies within the 95 % region of the best fit's
    (a rise of 1.96^2 times what each unit of the search's chi-square is worth: :func:`_prior_weight`) gives a, b
    and Dc; any outside its interval fails the fit."""
    worth = _prior_weight(resid, start["noise"], labels)
    best = min([float(result.chisqr)] + [chi for _, chi, _ in ladder])
    reach = best + Z95**2 * worth
    rungs = sorted(ladder, key=lambda rung: rung[0])
    inside = [rung for rung in rungs if rung[1] <= reach]
    if not inside:
        inside = [(math.exp(result.params["log_k"].value), float(result.chisqr), _start_values(
            result.params.valuesdict()))]  # fmt: skip
    soft = inside[0]
    outside = [rung for rung in rungs if rung[0] < soft[0]]
    if outside:
        hard, low = soft, outside[-1]
        for _ in range(STIFFNESS_BISECTIONS):
            k = math.sqrt(hard[0] * low[0])
            held = replace(setup, fit_stiffness=False, fixed={**setup.fixed, "stiffness": k})
            fit, _ = _least_squares(held, {**start, **hard[2], "stiffness": k})
            here = (k, float(fit.chisqr), _start_values(fit.params.valuesdict()))
            hard, low = (here, low) if here[1] <= reach else (hard, here)
        soft = hard
    from ..display import unit as shown_unit

    k_unit, k_scale = units["stiffness"]
    shown_k = f"{soft[0] / k_scale:.3g} {shown_unit(k_unit)}"
    off = []
    for key in _CORE:
        entry = table[key]
        if entry.fixed or entry.interval is None:
            continue
        value = soft[2][key]
        if not entry.interval[0] <= value <= entry.interval[1]:
            unit, scale = units.get(key, ("", 1.0))
            unit = f" {shown_unit(unit)}" if unit else ""
            off.append(f"{key} = {value / scale:.4g}{unit} outside [{entry.interval[0] / scale:.4g}, "
                       f"{entry.interval[1] / scale:.4g}]{unit}")  # fmt: skip
    what = f"the stiffness is not determined by the record ({table['stiffness'].note})"
    if off:
        return True, (
            f"{what}, and the other values depend on it: held at {shown_k}, where chi-square is still within the 95 %"
            f" region of the best fit's, {', '.join(off)}; hold the rig's stiffness where it is known (--fix "
            "stiffness=..., fixed={'stiffness': k})"
        )
    return False, (
        f"{what}: any stiffness above about {shown_k} fits as well, and a, b and Dc stay within their intervals "
        "over that range"
    )


def _stuck(setup: _Setup, start: dict[str, float], result: Any) -> str:
    """Why a search never got going ('' when it did): the model cannot be run at its answer (a start past the
    spring's instability blows up at the first evaluation, and every residual is the same penalty), or a, b and Dc
    did not move while the fit is troubled (a start that already fits need not move)."""
    values = result.params.valuesdict()
    _, why = _model_or_why(setup.record, _history(setup, values), _base(setup, start), values)
    if why:
        return why
    free = [k for k in ("a", "b", "log_dc") if result.params[k].vary]
    if free and not any(_moved(result.params[k]) for k in free) and _troubled(result):
        return "a, b and Dc did not move from their starting values"
    return ""


#: a stuck search is started again with a spring this many times stiffer (further from the instability)
STIFFER_START = 10.0


def _rescue_starts(setup: _Setup, start: dict[str, float], stiffness_given: bool) -> list[dict[str, float]]:
    """Starts for a search that never got going (docs/rsf.md, "Local minima"): the aging law's answer when another
    law is fitted (its search is the most forgiving), a start neutral in velocity (a = b: stable on any spring) and
    a stiffer spring."""
    starts = []
    if any(law != "aging" for law in setup.laws):
        aging = replace(setup, laws=("aging",) * len(setup.laws))
        first, _ = _search(aging, start)
        if not _stuck(aging, start, first):
            starts.append({**start, **_start_values(first.params.valuesdict())})
    if start["b"] > start["a"] and "a" not in setup.fixed and "b" not in setup.fixed:
        starts.append({**start, "a": start["b"]})
    if not stiffness_given:
        starts.append({**start, "stiffness": STIFFER_START * start["stiffness"]})
    return starts


#: a free stiffness left unconstrained is searched again held at the start's stiffness times each of these; the best
#: is then freed (docs/rsf.md, "Local minima"), and the others say whether a, b and Dc depend on it
STIFFNESS_LADDER = (0.01, 0.1, 1.0, 10.0, 100.0, 1000.0)


def _stiffness_loose(result: Any) -> bool:
    """A free stiffness the search leaves unconstrained (at the edge of its range, or no usable error)."""
    par = result.params.get("log_k")
    if par is None or not par.vary:
        return False
    se = par.stderr if par.stderr is not None and math.isfinite(par.stderr) else None
    return bool(_unconstrained("log_k", par, se))


def _stiffness_ladder(
    setup: _Setup, start: dict[str, float], result: Any, residual: Any
) -> tuple[Any, Any, list[tuple[float, float, dict[str, float]]]]:
    """Searches with the stiffness held at each rung of STIFFNESS_LADDER, then a free search from the best rung
    when it is below the free search's chi-square (a free stiffness ran to a rigid rig at 1e12 1/m, chi-square_r
    9.568, where held at 1e4 1/m it gave 9.541: the free search had lost its way on a plateau)."""
    here = {**start, **_start_values(result.params.valuesdict())}
    rungs = []
    for factor in STIFFNESS_LADDER:
        k = factor * start["stiffness"]
        held = replace(setup, fit_stiffness=False, fixed={**setup.fixed, "stiffness": k})
        fit, _ = _search(held, {**here, "stiffness": k})
        rungs.append((k, float(fit.chisqr), _start_values(fit.params.valuesdict())))
    k, chi, values = min(rungs, key=lambda rung: rung[1])
    if chi < result.chisqr * (1 - 1e-9):
        again, again_residual = _search(setup, {**here, **values, "stiffness": k})
        if again.chisqr < result.chisqr * (1 - 1e-9):
            result, residual = again, again_residual
    return result, residual, rungs


def _evaluated(setup: _Setup, base: RSFParams, values: dict[str, float]) -> np.ndarray:
    """The model at the best parameters; a ModelError saying exactly what happened where it cannot be had."""
    model, why = _model_or_why(setup.record, _history(setup, values), base, values)
    if why:
        shown = ", ".join(f"{_PUBLIC[k]} = {math.exp(v) if k.startswith('log_') else v:.4g}" for k, v in values.items()
                          if k in _PUBLIC)  # fmt: skip
        raise ModelError(
            f"rate-and-state fit: the best parameters found ({shown}) cannot be evaluated: {why}; no start tried "
            "led the search where the model runs: give a start where it does (--guess or guess=: another law's fit, "
            "or a spring stiffer than (b - a)/Dc) or the rig's known stiffness (--fix stiffness=...)"
        )
    return model


class FitNotEvaluated(ModelError):
    """A fit whose best parameters cannot be evaluated (the model cannot be run there); ``fit`` is its failed report:
    the values where the search ended, no intervals, no model friction (NaN)."""

    def __init__(self, message: str, fit: RSFFit) -> None:
        super().__init__(message)
        self.fit = fit


def _unevaluated_fit(
    setup: _Setup, start: dict[str, float], result: Any, reason: str, source: str, window: Any, weight: float | None
) -> RSFFit:
    """The failed report of a fit whose best parameters cannot be evaluated (docs/rsf.md, "Failed means failed")."""
    record = setup.record
    values = result.params.valuesdict()
    table, _, _ = _report(result, values, setup, start["stiffness"], None, _units(record.length_unit))
    note = "not evaluated: the model cannot be run at these values"
    for key, par in table.items():
        if not par.fixed:
            table[key] = replace(par, stderr=None, interval=None, scaled_interval=None, constrained=False, note=note)
    a_b = FitParameter("a-b", table["a"].value - table["b"].value, None, None, constrained=False, note=note)
    nan = np.full(len(record), np.nan)
    return RSFFit(
        params=_final_params(_base(setup, start), values), parameters=table, correlations={},
        reduced_chi_square=math.nan, rms=math.nan, noise=float(start["noise"]), trend=float(values.get("trend", 0.0)),
        record=record, protocol=_history(setup, values), model_friction=nan, warnings=(), success=False,
        optimizer_message=str(result.message), nfev=int(result.nfev), status="failed", reason=reason.split(": ", 1)[-1],
        derived={"a-b": a_b}, protocol_source=source, window=None if window is None else
        (float(window[0]), float(window[1])), step_weight=weight,
    )  # fmt: skip


# --- the found history's change times as nuisance parameters ---------------------------------------------------

#: a found change time is fitted when moving it by this many of its own uncertainties ...
CHANGE_SHIFT = 3.0
#: ... changes chi-square (at the search's noise) by more than this: held, it could bias the other parameters by
#: up to sqrt(this) of their standard errors (the projection of the misfit onto them), here 0.3
CHANGE_CHI2 = 0.1
#: a fitted change time's parameter is offset + shift / its uncertainty: MINPACK's forward step (1e-5 relative)
#: is then 0.01 uncertainty, a friction change well above the solver's tolerance (at 0 it would be 1e-5 of it)
CHANGE_OFFSET = 1000.0
#: the covariance's central difference for a change time, in its uncertainties
CHANGE_STEP = 0.25
#: a fitted change this many of its uncertainties from where the displacement dates it earns a warning
CHANGE_FAR = 5.0


def _history(setup: _Setup, values: dict[str, float]) -> Protocol:
    """The load-point history at ``values``: the setup's, with each fitted change moved (kept in order)."""
    if not setup.changes:
        return setup.protocol
    edges = setup.protocol.boundaries.copy()
    for index, sigma in setup.changes:
        edges[index] += (values.get(f"tc{index}", CHANGE_OFFSET) - CHANGE_OFFSET) * sigma
    gap = 1e-9 * float(edges[-1])  # a search step that would swap two changes holds them apart
    for j in range(1, edges.size - 1):
        edges[j] = min(max(edges[j], edges[j - 1] + gap), edges[-1] - gap * (edges.size - 1 - j))
    speeds = setup.protocol.velocities
    return Protocol(tuple(Segment(v, float(e1 - e0)) for v, e0, e1 in zip(speeds, edges[:-1], edges[1:], strict=True)),
                    name=setup.protocol.name)  # fmt: skip


def _prior_weight(resid: np.ndarray, noise: float, labels: np.ndarray) -> float:
    """How much less a friction row tells than the search's chi-square says: the residuals' variance over
    ``noise`` squared, times rows per independent row (their correlation factor); 1 where it cannot be had."""
    g = _correlation_factor(resid, labels)
    weight = float(np.mean(resid**2)) / noise**2 * resid.size / float(np.sum(1.0 / g))
    return weight if math.isfinite(weight) and weight > 0 else 1.0


def _decimals(uncertainty: float) -> int:
    """Decimals that show a time to two significant digits of its uncertainty."""
    if not (uncertainty > 0 and math.isfinite(uncertainty)):
        return 6
    return min(max(1 - math.floor(math.log10(uncertainty)), 0), 12)


def _public(key: str) -> str:
    """The reported name of a search parameter (a change time ``tcN`` is ``change_N``)."""
    return _PUBLIC.get(key, f"change_{key[2:]}" if key.startswith("tc") else key)


def _free_changes(setup: _Setup, base: RSFParams, values: dict[str, float], noise: float, labels: np.ndarray) -> tuple[
        tuple[tuple[int, float], ...], dict[int, dict[str, float]], float]:  # fmt: skip
    """The found history's change times that matter at ``values`` (free where moving one by CHANGE_SHIFT of its
    uncertainty raises chi-square by more than CHANGE_CHI2), per change its uncertainty and that rise (for the
    report), and the priors' weight (:func:`_prior_weight`): docs/rsf.md, "Which are fitted" and "Fitted"."""
    record, protocol = setup.record, setup.protocol
    sigmas = change_time_uncertainty(record.time, record.displacement, protocol,
                                     sampled_velocity=record.displacement_from == "velocity")  # fmt: skip
    model, why = _model_or_why(record, protocol, base, values)
    weight = 1.0 if why else _prior_weight(record.friction - model, noise, labels)
    free, seen = [], {}
    for index, sigma in enumerate(sigmas, start=1):
        rise = 0.0
        if sigma > 0 and math.isfinite(sigma) and not why:
            for sign in (1.0, -1.0):
                moved = replace(setup, changes=((index, float(sigma)),))
                there = {**values, f"tc{index}": CHANGE_OFFSET + sign * CHANGE_SHIFT}
                shifted, _ = _model_or_why(record, _history(moved, there), base, there)
                rise = max(rise, float(np.sum(((shifted - model) / noise) ** 2)))
            rise = rise if math.isfinite(rise) else math.inf
        seen[index] = {"uncertainty": float(sigma), "chi_square_change": rise}
        if rise > CHANGE_CHI2:
            free.append((index, float(sigma)))
    return tuple(free), seen, weight


def _dated_by(record: LabRecord) -> str:
    """Who dates a found change, with its verb: the displacement (where its straight pieces meet), or a velocity
    column's rows (the change lies between the last row at the old velocity and the first at the new, to the row
    spacing: :func:`stickslip.rsf.data.change_time_uncertainty`)."""
    if record.displacement_from == "velocity":
        return "the velocity column's rows date"
    return "the displacement dates"


def _change_report(setup: _Setup, result: Any, seen: dict[int, dict[str, float]]) -> tuple[
        tuple[FitParameter, ...], list[str]]:  # fmt: skip
    """One FitParameter per change of the history (s, on the fitted rows' clock), and warnings for fitted changes
    far from where the displacement dates them."""
    protocol = setup.protocol
    dates = _dated_by(setup.record)
    free = dict(setup.changes)
    out, warns = [], []
    for index in range(1, len(protocol.segments)):
        found = float(protocol.boundaries[index])
        info = seen.get(index)
        name = f"change_{index}"
        if index not in free or info is None:
            why = ("given with the history" if info is None else
                   f"held where {dates} it (± {info['uncertainty']:.2g} s): moving it by "
                   f"{CHANGE_SHIFT:g} times that changes chi-square by {info['chi_square_change']:.2g} "
                   f"(<= {CHANGE_CHI2:g})")  # fmt: skip
            out.append(FitParameter(name, found, None, None, fixed=True, unit="s", note=why, si_unit="s"))
            continue
        sigma = free[index]
        par = result.params[f"tc{index}"]
        value = found + (par.value - CHANGE_OFFSET) * sigma
        se = par.stderr * sigma if par.stderr is not None and math.isfinite(par.stderr) else None
        interval = (value - Z95 * se, value + Z95 * se) if se is not None else None
        shown = f"{setup.record.t0 + found:.{_decimals(sigma)}f} ± {sigma:.2g} s on the file's clock"
        note = (f"fitted; {dates} it at {shown}, its prior" if se is not None else
                "fitted, no standard error: the record cannot tell it apart from the others")  # fmt: skip
        out.append(FitParameter(name, value, se, interval, unit="s", constrained=se is not None, note=note,
                                si_unit="s"))  # fmt: skip
        if abs(value - found) > CHANGE_FAR * sigma:
            warns.append(
                f"{name}: the friction places the velocity change at {setup.record.t0 + value:.6g} s, "
                f"{abs(value - found) / sigma:.3g} "
                f"times its uncertainty from where {dates} it ({shown}): check "
                "the history (--segment, --protocol or --history measured)"
            )
    return tuple(out), warns


# --- noise, its correlation and the intervals -------------------------------------------------------------------

#: a sampling class (rows whose spacing is within a factor ~1.4 of each other) needs this many rows of its own
MIN_CLASS_ROWS = 30
#: rows over which a row's spacing is its running median (irregular stamps of one rate are one class)
CLASS_SPAN = 31
#: rows after a velocity change, in Dc / V, before the sliding counts as steady for the noise estimate
QUIET_RENEWALS = 5.0
#: the friction's variogram has levelled off when doubling the lag adds less than this factor
PLATEAU = 1.15
#: rows ``lag`` apart count for the variogram at that lag when they are within this factor of lag rows' time apart
SPACING_SPREAD = 3.0
#: blocks per sampling class for the batch-means check of the residuals' correlation
CORRELATION_BLOCKS = 30
#: a lag correlation counts as correlation where it exceeds this many times white noise's sampling error
CORRELATION_Z = 3.0
#: harmonics of the quantisation error's sawtooth counted in its systematic covariance (99 % of its variance)
QUANTISATION_HARMONICS = 64
#: the opening stretch of the first segment checked for a start out of steady sliding, and its residuals' limit
#: (rms, in noise units: out of steady sliding beyond it, with the mean beyond one less and standing out of the rest
#: by one less)
OPENING_SHARE = 0.25
OPENING_MISFIT = 3.0


@dataclass(frozen=True)
class _Level:
    """The noise the fit is judged by and the covariance's correlation allowance."""

    noise: float
    redchi: float
    method: str
    n_eff: float
    inflation: float
    #: the noise of each row the fit is judged by (the steady sliding's per sampling rate, or the given level)
    rows: np.ndarray | None = None
    #: each row's likelihood scale for the posterior: the residuals' own sd per sampling rate times sqrt(g), each row
    #: counting 1/g of one as in the intervals (the given noise where one is given)
    scale: np.ndarray | None = None


def _sampling_classes(time: np.ndarray) -> np.ndarray:
    """A label per row: its sample spacing (the running median over CLASS_SPAN rows, so jittered stamps stay one
    rate) in log2 steps from the record's median spacing (rates that change mid-record get their own class);
    classes with fewer than MIN_CLASS_ROWS rows join the nearest larger one."""
    if time.size < 3:
        return np.zeros(time.size, dtype=int)
    from scipy.ndimage import median_filter

    dt = np.diff(time)
    spacing = np.r_[dt[0], np.minimum(dt[:-1], dt[1:]), dt[-1]]
    spacing = median_filter(np.log2(np.maximum(spacing, 1e-300)), size=min(CLASS_SPAN, time.size), mode="nearest")
    labels = np.rint(spacing - float(np.median(spacing))).astype(int)
    kinds, counts = np.unique(labels, return_counts=True)
    big = kinds[counts >= MIN_CLASS_ROWS]
    if big.size == 0:
        return np.zeros(time.size, dtype=int)
    for kind in kinds[counts < MIN_CLASS_ROWS]:
        labels[labels == kind] = big[np.argmin(np.abs(big - kind))]
    return labels


def _quiet_rows(
    record: LabRecord, protocol: Protocol, dc: float, settle: Callable[[float], float] | None = None
) -> np.ndarray:  # fmt: skip
    """Rows of steady sliding: not in a hold and more than QUIET_RENEWALS decay times after a velocity change.

    The decay time at velocity V is ``settle(V)`` (the fitted spring-slider's own, :func:`_settling`), else the
    renewal time Dc / V: the slowest transient of a stiff rig, but an underdamped one near k_c rings for longer."""
    t = record.time
    quiet = protocol.velocity_at(t) > 0
    edges, speeds = protocol.boundaries, protocol.velocities
    for i in range(1, speeds.size):
        if speeds[i] != speeds[i - 1] and speeds[i] > 0:
            decay = dc / speeds[i] if settle is None else settle(float(speeds[i]))
            quiet &= ~((t >= edges[i]) & (t < edges[i] + QUIET_RENEWALS * decay))
    return quiet


#: the fitted system's decay time counts for the noise's steady rows up to this many renewal times Dc / V (beyond,
#: as at and past k_c, where it never settles, the rows left would be too few; the residuals then judge the rest)
SETTLING_RENEWALS = 10.0


def _settling(params: RSFParams, dc: float) -> Callable[[float], float]:
    """The decay time (s) of the fitted spring-slider's slowest transient after a step to velocity V: 1 / |the
    largest real part| of its linearised equations' eigenvalues (:func:`stickslip.rsf.stability.growth_rate`), at
    least Dc / V and at most SETTLING_RENEWALS Dc / V.  A stiff rig's slowest mode is the state's renewal, Dc / V;
    an underdamped one decays at the rate V (k - k_c) / (2 a) (one aging state: 2.3 Dc / V at k = 3.3 k_c, whose
    ringing 5 Dc / V after a step raised the steady sliding's second differences by a quarter)."""
    from .stability import growth_rate

    def settle(velocity: float) -> float:
        renewal = dc / velocity
        try:
            growth = growth_rate(params, velocity)
        except (ModelError, ParameterError, ArithmeticError, ValueError, np.linalg.LinAlgError):
            return renewal
        if not (math.isfinite(growth) and growth < 0):
            return SETTLING_RENEWALS * renewal
        return min(max(-1.0 / growth, renewal), SETTLING_RENEWALS * renewal)

    return settle


def _quiet_noise(
    record: LabRecord, protocol: Protocol, dc: float, labels: np.ndarray, settle: Callable[[float], float] | None = None
) -> tuple[np.ndarray, str, np.ndarray]:  # fmt: skip
    """Per-row friction noise from steady sliding alone (model-independent), per sampling rate.

    The plateau of the variance of second differences (each row about the line through the rows a lag either side)
    over lags 1, 2, 4, ... rows: the first doubling of the lag that adds less than PLATEAU - 1; a variogram that
    never levels off gives its last value, and says so.  Lags with under a quarter of the first lag's triples are
    not used (as long as the steady stretches, they measure nothing), and the noise is never below the friction's
    quantisation noise: docs/rsf.md, "Noise, independent of the sampling rate".
    Returns (noise per row, how it was had, the level measured per row before that floor).
    """
    t, f = record.time, record.friction
    quiet = _quiet_rows(record, protocol, dc, settle)
    segment = np.clip(np.searchsorted(protocol.boundaries, t, side="right") - 1, 0, len(protocol.segments) - 1)
    sigma: dict[int, float] = {}
    lags: dict[int, tuple[float, bool]] = {}
    for c in np.unique(labels):
        usable = quiet & (labels == c)
        steps = np.diff(t)[usable[1:] & usable[:-1]]
        if steps.size == 0:
            continue
        step = float(np.median(steps))
        gammas: list[float] = []
        lag, first = 1, 0
        while 2 * lag < t.size:
            pairs = usable[:-lag] & usable[lag:] & (labels[:-lag] == c) & (labels[lag:] == c)
            # rows lag apart about lag rows' time apart (irregular stamps allowed; no pause in the sampling)
            span = (t[lag:] - t[:-lag]) / (lag * step)
            pairs &= (segment[:-lag] == segment[lag:]) & (span >= 1.0 / SPACING_SPREAD) & (span <= SPACING_SPREAD)
            triples = pairs[:-lag] & pairs[lag:]  # rows i, i + lag, i + 2 lag in one segment
            count = int(triples.sum())
            first = first or count
            if count < max(MIN_CLASS_ROWS, first / 4):  # lags as long as the steady stretches measure nothing
                break
            # each row about the line through its neighbours lag rows either side, at its own time: a drift, and a
            # transient slower than the lag (the record's unseen opening one), cancel, at any spacing
            gammas.append(_clipped_sd(_about_neighbours(t, f, lag)[triples]) ** 2)
            lag *= 2
        if not gammas:
            continue
        level = next((i + 1 for i in range(len(gammas) - 1) if gammas[i + 1] <= PLATEAU * gammas[i]), None)
        pick = level if level is not None else len(gammas) - 1
        sigma[int(c)] = math.sqrt(gammas[pick])
        lags[int(c)] = (2**pick * step, level is not None)
    bit = _quantisation_noise(f)
    floor = _noise_floor(f)
    if not sigma:
        white = _noise(f, t)
        how = "second differences of the friction (no steady sliding to measure)"
        return np.full(t.size, max(white, floor)), how, np.full(t.size, white)
    pooled = math.sqrt(float(np.mean(np.square(list(sigma.values())))))
    measured = np.array([sigma.get(int(c), pooled) for c in labels])
    rows = np.maximum(measured, floor)
    shown = ", ".join(f"{lag:.3g} s" + ("" if flat else " (not levelled off)") for lag, flat in lags.values())
    how = f"steady sliding's friction second differences where their variance levels off (lags {shown})"
    if bit == floor and any(sigma.get(int(c), pooled) < bit for c in np.unique(labels)):
        how += f", raised to the quantisation noise {bit:.3g} of friction written in steps of {bit * math.sqrt(12):.3g}"
    return rows, how, measured


def _noise_floor(friction: np.ndarray) -> float:
    """The least noise a friction record is judged by: the model's own precision (MODEL_PRECISION of the friction,
    at least 1e-9) or the quantisation noise of its written step, the larger."""
    return max(MODEL_PRECISION * max(1.0, float(np.median(np.abs(friction)))), _quantisation_noise(friction))


def _quantisation_noise(friction: np.ndarray) -> float:
    """q / sqrt(12) for friction written in whole steps q (its resolution, read from the values), else 0: the
    least noise such a record can have.  Where the noise is well below q the steady sliding sits on one step and
    its differences show no noise at all, yet no row is known to better than the step."""
    return quantum(friction) / math.sqrt(12.0)


def _systematic_quantisation(
    friction: np.ndarray, model: np.ndarray, measured: np.ndarray
) -> tuple[np.ndarray, float, np.ndarray] | None:  # fmt: skip
    """The systematic part of the quantisation error of friction written in steps q, as (model, q, c_k): None
    where there is no step or the noise dithers it away.

    Rounding x + n to steps q leaves, on average over the noise n (Gaussian, sd s), the error
    b(x) = sum_k (-1)^k (q / pi k) exp(-2 pi^2 k^2 s^2 / q^2) sin(2 pi k x / q): a function of the signal x, the same
    on every row where x is the same (a steady level sits on one step for good, however many rows it has).  With
    the grid's phase unknown, rows i and j share sum_k c_k cos(2 pi k (x_i - x_j) / q), c_k = q^2 / (2 pi^2 k^2)
    exp(-4 pi^2 k^2 s^2 / q^2) (q^2/12 in all at s = 0; nothing once s > q/2).  s is the steady sliding's measured
    level less q^2/12 (0 where the noise is below the step: the error is then taken as wholly systematic)."""
    step = quantum(friction)
    if not step > 0:
        return None
    dither2 = max(float(np.mean(measured**2)) - step**2 / 12.0, 0.0)
    k = np.arange(1, QUANTISATION_HARMONICS + 1, dtype=float)
    c = step**2 / (2.0 * math.pi**2 * k**2) * np.exp(-4.0 * math.pi**2 * k**2 * dither2 / step**2)
    if float(np.sum(c)) < 1e-3 * step**2 / 12.0:
        return None
    return model, step, c


def _quantisation_meat(wj: np.ndarray, model: np.ndarray, step: float, c: np.ndarray) -> np.ndarray:
    """sum_ij w_i w_j J_i J_j^T sum_k c_k cos(2 pi k (x_i - x_j) / q), x the model's friction (separable: each
    harmonic is the outer product of the cosine- and of the sine-weighted Jacobian sums)."""
    phase = 2.0 * math.pi * (model - float(np.min(model))) / step
    meat = np.zeros((wj.shape[1], wj.shape[1]))
    for k, weight in enumerate(c, start=1):
        for wave in (np.cos(k * phase), np.sin(k * phase)):
            total = wave @ wj
            meat += weight * np.outer(total, total)
    return meat


def _clipped_sd(x: np.ndarray) -> float:
    """Standard deviation with outliers beyond 4 sd cut (three rounds).  Not the MAD: with friction quantised to
    a bit size near the noise, the MAD of differences is a multiple of the bit (off by up to 2x)."""
    keep = x
    for _ in range(3):
        sd = float(np.std(keep))
        kept = x[np.abs(x - np.median(x)) <= 4.0 * sd] if sd > 0 else x
        if kept.size == keep.size or kept.size < MIN_CLASS_ROWS:
            break
        keep = kept
    return float(np.std(keep))


def _about_neighbours(t: np.ndarray, f: np.ndarray, lag: int = 1) -> np.ndarray:
    """Each row's offset from the straight line through the rows ``lag`` either side, evaluated at the row's own
    time, in units of white noise: divided by sqrt(1 + w^2 + (1 - w)^2), w the row's distance from its later
    neighbour over the two neighbours' distance (3/2 for even stamps: the classic second difference / sqrt(6)).
    A slope cancels at any spacing; irregular stamps only change the weights."""
    t0, t1, t2 = t[: -2 * lag], t[lag:-lag], t[2 * lag :]
    w = (t2 - t1) / (t2 - t0)
    offset = f[lag:-lag] - w * f[: -2 * lag] - (1.0 - w) * f[2 * lag :]
    return offset / np.sqrt(1.0 + w * w + (1.0 - w) ** 2)


def _pre_fit_noise(record: LabRecord, protocol: Protocol, dc: float, labels: np.ndarray, white: float) -> float:
    """The noise the search scales its residuals by.  Its answer does not depend on it in principle, but its path
    does (a search in a long valley ends elsewhere for a 1 % change), and the restarts for a troubled search
    judge chi-square by it: the white-noise level ``white`` (second differences) where the steady sliding
    agrees to within 2x, else the steady sliding's (correlated noise at 1 kHz: 5x above the white level)."""
    rows, _, _ = _quiet_noise(record, protocol, dc, labels)
    quiet = float(np.sqrt(np.mean(rows**2)))
    return quiet if quiet > 2.0 * white else white


def _correlation_factor(resid: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """Per row, g = 1 + 2 sum of the residuals' autocorrelations (rows of one sampling rate): each row counts as
    1/g independent rows.

    From the lag-one and lag-two correlations, each read only where it stands out of a white series' sampling
    error, checked by batch means over CORRELATION_BLOCKS blocks (docs/rsf.md, "Noise, independent of the
    sampling rate").
    """
    out = np.ones(resid.size)
    for c in np.unique(labels):
        rows = np.flatnonzero(labels == c)
        r = resid[rows] - float(np.mean(resid[rows]))
        var = float(np.mean(r**2))
        if rows.size < MIN_CLASS_ROWS or not var > 0:
            continue
        rho = [_lag_correlation(r, rows, k, var) for k in (1, 2)]
        parametric = _parametric_factor(*rho, pairs=int(np.count_nonzero(np.diff(rows) == 1)))
        out[rows] = max(_block_factor(r, rows, var, parametric), 1.0 / rows.size)
    return out


def _lag_correlation(r: np.ndarray, rows: np.ndarray, lag: int, var: float) -> float:
    pairs = rows[lag:] - rows[:-lag] == lag  # neighbours in the record, not across another rate's rows
    return float(np.mean(r[lag:][pairs] * r[:-lag][pairs]) / var) if np.any(pairs) else 0.0


def _parametric_factor(rho1: float, rho2: float, pairs: int | None = None) -> float:
    """1 + 2 sum rho_k for white noise plus an exponentially correlated part: 1 + 2 rho1 / (1 - rho2 / rho1).

    Each is read as correlation only where it stands out of white noise's sampling error, 1 / sqrt(pairs), by
    CORRELATION_Z of it (g = 1 where rho1 does not), and so is the ratio rho2 / rho1: for white residuals both
    are +-0.02 on 3000 rows, and their ratio anything up to 1 (g = 54 from rho1 = 0.027, rho2 = 0.038 on a white
    record)."""
    error = 1.0 / math.sqrt(pairs) if pairs else 0.0
    if abs(rho1) <= CORRELATION_Z * error:
        return 1.0
    if rho1 <= 0:
        return max(1.0 + 2.0 * rho1, 0.05)
    if rho2 <= CORRELATION_Z * error:
        return 1.0 + 2.0 * rho1
    phi = min(rho2 / rho1, 0.999)
    return 1.0 + 2.0 * rho1 / (1.0 - phi)


def _block_factor(r: np.ndarray, rows: np.ndarray, var: float, parametric: float) -> float:
    size = max(rows.size // CORRELATION_BLOCKS, 1)
    runs = np.split(np.arange(rows.size), np.flatnonzero(np.diff(rows) != 1) + 1)
    sums = [float(np.sum(r[run[i : i + size]])) for run in runs for i in range(0, run.size - size + 1, size)]
    if len(sums) < 5:
        return parametric
    block = float(np.mean(np.square(sums))) / (size * var)
    return block if block > parametric * (1 + 3 * math.sqrt(2.0 / len(sums))) else parametric


def _uncertainty(
    setup: _Setup, base: RSFParams, result: Any, model: np.ndarray, labels: np.ndarray, given: float | None
) -> _Level:
    """The fit's covariance (set on ``result``) and the noise it is judged by.

    Given noise: white at that level; otherwise the least-squares sandwich with the residuals' own variance and
    correlation factor per sampling rate, chi-square judged against the steady sliding's scatter (docs/rsf.md).
    """
    record = setup.record
    resid = record.friction - model
    n, p = len(record), result.nvarys
    dof = max(n - p, 1)
    if given is not None:
        redchi = float(np.sum((resid / given) ** 2) / dof)
        if setup.weights is not None or any(setup.levels):  # (else the search's own covariance at that noise)
            core = None if setup.weights is not None else result.covar
            _set_covariance(result, _sandwich(setup, base, result, np.full(n, given**2), core=core))
        return _Level(given, redchi, "given", float(n), 1.0, np.full(n, float(given)), np.full(n, float(given)))
    dc = math.exp(result.params["log_dc"].value)
    settle = _settling(_final_params(base, result.params.valuesdict()), dc)  # the fitted rig's own ringing left out
    rows, how, measured = _quiet_noise(record, setup.protocol, dc, labels, settle)
    rows, how, measured = _followed_signal(setup, dc, labels, resid, rows, how, measured, settle)
    redchi = float(np.sum((resid / rows) ** 2) / dof)
    g = _correlation_factor(resid, labels)
    variance = np.zeros(n)
    for c in np.unique(labels):
        inside = labels == c
        variance[inside] = float(np.mean(resid[inside] ** 2)) * n / dof
    scale = np.sqrt(np.maximum(variance * g, _noise_floor(record.friction) ** 2))
    systematic = _systematic_quantisation(record.friction, model, measured)
    if systematic is not None:  # that part of the residuals' variance is counted by its own covariance instead
        variance = np.maximum(variance - float(np.sum(systematic[2])), 0.0)
        how += "; the quantisation's systematic part counted in the intervals"
    _set_covariance(result, _sandwich(setup, base, result, variance * g, systematic))
    n_eff = float(np.sum(1.0 / g))
    levels = ("; the found levels' velocities' uncertainty (from the displacement) carried in them"
              if any(setup.levels) else "")  # fmt: skip
    method = (f"fit judged against the {how}; intervals from the residuals' own scatter and autocorrelation "
              f"(effective independent rows {n_eff:.4g} of {n}){levels}")  # fmt: skip
    return _Level(float(np.sqrt(np.mean(rows**2))), redchi, method, n_eff, n / n_eff, rows, scale)


#: the steady sliding's friction second differences are signal, not noise, where they exceed the residuals' own
#: (the same estimator, the model subtracted) this many times: the model follows them
SIGNAL_FACTOR = 2.0


def _followed_signal(
    setup: _Setup, dc: float, labels: np.ndarray, resid: np.ndarray, rows: np.ndarray, how: str, measured: np.ndarray,
    settle: Callable[[float], float] | None = None,
) -> tuple[np.ndarray, str, np.ndarray]:  # fmt: skip
    """The noise per row (and how it was had, and the level before its floor) where the friction's own second
    differences in steady sliding are signal the model follows, not noise: a noise-free record (a model's output,
    as `rsf simulate -o` writes it) whose "steady" rows still ring, or any record sampled too sparsely for a row's
    neighbours to lie on a line.  There the residuals' second differences (the same estimator, :func:`_quiet_noise`
    on friction minus model) are the noise, raised to the same floor (the model's precision, the friction's
    printed step); elsewhere, and on every record whose steady sliding is steady, nothing changes."""
    record = setup.record
    _, _, left = _quiet_noise(replace(record, friction=resid), setup.protocol, dc, labels, settle)
    signal = measured > SIGNAL_FACTOR * left
    if not np.any(signal):
        return rows, how, measured
    floor = _noise_floor(record.friction)
    kept = np.where(signal, np.maximum(left, floor), rows)
    was, now = float(np.sqrt(np.mean(measured[signal] ** 2))), float(np.sqrt(np.mean(left[signal] ** 2)))
    share = "" if signal.all() else f" on {int(np.count_nonzero(signal))} of {signal.size} rows"
    raised = f", raised to the noise floor {floor:.3g} (the model's precision or the friction's written step)" if (
        now < floor) else ""  # fmt: skip
    how += (f"; those follow the model{share} ({was:.3g} against the residuals' {now:.3g}: signal, not noise, as "
            f"on a noise-free record), so there the residuals' own{raised}")  # fmt: skip
    return kept, how, np.where(signal, left, measured)


def _sandwich(
    setup: _Setup, base: RSFParams, result: Any, variance: np.ndarray,
    systematic: tuple[np.ndarray, float, np.ndarray] | None = None, core: np.ndarray | None = None,
) -> np.ndarray | None:  # fmt: skip
    """B^-1 (sum_i w_i^2 v_i J_i J_i^T) B^-1, B = sum_i w_i J_i J_i^T (None when J or B is unusable); with
    ``systematic`` the quantisation's systematic error is added to the meat (:func:`_systematic_quantisation`).
    The found levels' velocities' share (:func:`_level_covariance`) is added; ``core`` (the search's own
    covariance, at a given noise) stands in for the sandwich where it is given."""
    jac = _jacobian(setup, base, result)
    if jac is None:
        return core
    w = np.ones(len(setup.record)) if setup.weights is None else setup.weights
    bread = jac.T @ (w[:, None] * jac)
    meat = jac.T @ ((w**2 * variance)[:, None] * jac)
    if systematic is not None:
        meat += _quantisation_meat(w[:, None] * jac, *systematic)
    # the change times' priors (rows sqrt(F) u_j, u_j of unit variance, beside friction rows scaled by the search's
    # noise n): n^2 F in the bread, n^4 F^2 in the meat, in friction units
    names = list(result.var_names)
    for index, _ in setup.changes:
        j = names.index(f"tc{index}")
        bread[j, j] += setup.change_noise**2 * setup.change_weight
        meat[j, j] += setup.change_noise**4 * setup.change_weight**2
    try:
        inverse = np.linalg.inv(bread)
    except np.linalg.LinAlgError:
        return None
    cov = inverse @ meat @ inverse if core is None else np.array(core, dtype=float)
    levels = _level_covariance(setup, base, result, inverse @ jac.T * w)
    if levels is None:  # the levels' share cannot be had: no interval claims a precision it may not have
        return None
    cov = cov + levels
    return cov if np.all(np.isfinite(cov)) else None


def _level_covariance(setup: _Setup, base: RSFParams, result: Any, lever: np.ndarray) -> np.ndarray | None:
    """What the found levels' velocity errors add to the parameters' covariance: G diag(sigma_v^2) G^T, with
    G = B^-1 J^T W J_v (``lever`` = B^-1 J^T W) the fitted parameters' shift per unit change of each level's
    velocity, J_v the model friction's derivative with respect to it (central differences of +-sigma_v, at most
    half the velocity) and sigma_v from the displacement (:func:`level_velocity_uncertainty`).  The levels are
    estimates whose errors are independent of the friction's noise, so their share adds.  Zero where the history
    was given (held exact) or no level has an uncertainty; None where a moved level's model cannot be run.
    docs/rsf.md, "What the history's own uncertainty does to a fit"."""
    size = lever.shape[0]
    if not any(setup.levels):
        return np.zeros((size, size))
    values = result.params.valuesdict()
    history = _history(setup, values)
    columns, sigmas = [], []
    for j, (segment, sigma) in enumerate(zip(history.segments, setup.levels, strict=False)):
        v = segment.velocity
        if not (sigma > 0 and v > 0 and math.isfinite(sigma)):
            continue
        h = min(float(sigma), 0.5 * v)
        runs = []
        for moved_v in (v + h, v - h):
            moved = Protocol(tuple(Segment(moved_v, s.duration) if i == j else s
                                   for i, s in enumerate(history.segments)), name=history.name)  # fmt: skip
            model, why = _model_or_why(setup.record, moved, base, values)
            if why or not np.all(np.isfinite(model)):
                return None
            runs.append(model)
        columns.append((runs[0] - runs[1]) / (2.0 * h))
        sigmas.append(float(sigma))
    if not columns:
        return np.zeros((size, size))
    shift = lever @ np.column_stack(columns)  # d parameters / d v_j
    return (shift * np.square(sigmas)) @ shift.T


def _jacobian(setup: _Setup, base: RSFParams, result: Any) -> np.ndarray | None:
    """d model / d parameter at the fit: exact for the linear ones, central differences for the rest."""
    record = setup.record
    values = result.params.valuesdict()
    linear = {"mu0": np.ones(len(record)), "trend": record.displacement, "time_trend": record.time}
    columns = []
    for name in result.var_names:
        if name in linear:
            columns.append(linear[name])
            continue
        value = values[name]
        h = 1e-3 if name.startswith("log_") else 1e-3 * max(abs(value), 1e-3)
        h = CHANGE_STEP if name.startswith("tc") else h
        moved_up, moved_down = {**values, name: value + h}, {**values, name: value - h}
        up, _ = _model_or_why(record, _history(setup, moved_up), base, moved_up)
        down, _ = _model_or_why(record, _history(setup, moved_down), base, moved_down)
        if not (np.all(np.isfinite(up)) and np.all(np.isfinite(down))):
            return None
        columns.append((up - down) / (2 * h))
    return np.column_stack(columns)


def _set_covariance(result: Any, cov: np.ndarray | None) -> None:
    """Standard errors and correlations on ``result`` from ``cov`` (none where it is unusable)."""
    names = list(result.var_names)
    diag = np.diag(cov) if cov is not None else np.array([])
    if cov is None or not np.all(diag > 0):
        result.covar, result.errorbars = None, False
        for name in names:
            result.params[name].stderr, result.params[name].correl = None, None
        return
    se = np.sqrt(diag)
    result.covar, result.errorbars = cov, True
    for i, name in enumerate(names):
        par = result.params[name]
        par.stderr = float(se[i])
        par.correl = {other: float(cov[i, j] / (se[i] * se[j])) for j, other in enumerate(names) if j != i}


def _chi2_warnings(level: _Level, given: bool) -> list[str]:
    if level.redchi <= WARN_CHI2:
        return []
    if given:
        return [
            f"reduced chi-square {level.redchi:.3g} > {WARN_CHI2:g}: the residuals are larger than the record's "
            f"noise ({level.noise:.3g}), so the intervals, which assume that noise, are too narrow; the scaled "
            f"intervals (x sqrt({level.redchi:.3g}) = x{math.sqrt(level.redchi):.2g}) are offered beside them"
        ]
    return [
        f"reduced chi-square {level.redchi:.3g} > {WARN_CHI2:g}: the residuals exceed the steady sliding's noise "
        f"({level.noise:.3g}), so they hold structure the model does not describe; the intervals, from the "
        "residuals' own scatter and correlation, treat that structure as noise and are optimistic where it is "
        "systematic"
    ]


@dataclass(frozen=True)
class _Opening:
    """A record that seems to open on a transient: the warning, and the reason's words where the fit fails ('' for
    neither)."""

    warning: str = ""
    problem: str = ""


#: how the start-out-of-steady warning and reason end: what the user can do (rsf fit has no history before the record)
OPENING_ADVICE = (
    'fit from where the friction has settled (--window "T0 s:", T0 on the file\'s clock past the opening decay); a '
    "history from before the record cannot be given (--segment and --protocol start at the record's first row)"
)


def _opening_reading(record: LabRecord, protocol: Protocol, resid: np.ndarray, level: _Level) -> _Opening:
    """A record that opens on a transient (of a velocity change made before it) while the model starts in steady
    sliding: over the first OPENING_SHARE of the first segment the residuals are over OPENING_MISFIT times the
    noise, mostly of one sign (mean over OPENING_MISFIT - 1 noise) and OPENING_MISFIT - 1 times the rest's."""
    t, f = record.time, record.friction
    end = float(protocol.boundaries[1]) if len(protocol.segments) > 1 else float(t[-1])
    opening = t <= t[0] + OPENING_SHARE * (end - t[0])
    if int(opening.sum()) < MIN_CLASS_ROWS or int((~opening).sum()) < MIN_CLASS_ROWS:
        return _Opening()
    noise = math.sqrt(float(np.mean(level.rows[opening] ** 2))) if level.rows is not None else level.noise
    misfit = math.sqrt(float(np.mean(resid[opening] ** 2)))
    shift = float(np.mean(resid[opening]))
    standout = misfit / math.sqrt(float(np.mean(resid[~opening] ** 2)))
    if not (misfit > OPENING_MISFIT * noise and abs(shift) > (OPENING_MISFIT - 1) * noise
            and standout > OPENING_MISFIT - 1):  # fmt: skip
        return _Opening()
    tenth = max(int(opening.sum()) // 10, 1)
    first, last = float(np.mean(f[opening][:tenth])), float(np.mean(f[opening][-tenth:]))
    side = "above" if shift > 0 else "below"
    warning = (
        f"the record seems to start out of steady sliding: over its first {t[opening][-1] - t[0]:.3g} s, before any "
        f"velocity change, the friction goes from {first:.4g} to {last:.4g} and the residuals are {misfit / noise:.3g} "
        f"times the noise {noise:.3g}, mostly {side} the model (mean {shift / noise:+.3g} noise) and "
        f"{standout:.3g} times those of the rest, as where a record opens on the transient of a change made before "
        "it.  The model starts in steady sliding at the first velocity, so the fit either misses that opening or "
        "bends Dc, a, b and mu0 to absorb it: their values and intervals are biased, Dc most (the opening decay has "
        f"the length scale of the unseen step).  {OPENING_ADVICE[0].upper()}{OPENING_ADVICE[1:]}"
    )
    problem = (
        f"the record seems to start out of steady sliding (over its first {t[opening][-1] - t[0]:.3g} s, before any "
        f"velocity change, the residuals are {misfit / noise:.3g} times the noise, mostly {side} the model, and "
        f"{standout:.3g} times those of the rest): the model starts in steady sliding, so a, b, Dc and mu0 bend to "
        f"absorb the opening; {OPENING_ADVICE}"
    )
    return _Opening(warning, problem)


# --- does the answer depend on the drift term? ------------------------------------------------------------------


def _drift_sensitivity(
    setup: _Setup, start: dict[str, float], result: Any, table: dict[str, FitParameter],
    derived: dict[str, FitParameter], labels: np.ndarray, given: bool, noise: float | None,
) -> dict[str, Any]:  # fmt: skip
    """One more fit with the slip drift toggled (added when none was asked, dropped when one was): does the sign
    of a - b (where either interval excludes 0), or a - b, a, b or Dc each outside the other's interval, depend
    on it?"""
    other = frozenset({"slip"}) if not setup.trend else frozenset()
    alt = replace(setup, trend=other)
    here = {**start, **_start_values(result.params.valuesdict())}
    here.setdefault("trend", 0.0)
    try:
        alt_result, _ = _least_squares(alt, here)
        base = _base(alt, start)
        model = _evaluated(alt, base, alt_result.params.valuesdict())
        level = _uncertainty(alt, base, alt_result, model, labels, noise if given else None)
        alt_table, _, _ = _report(alt_result, alt_result.params.valuesdict(), alt, start["stiffness"], None,
                                  _units(setup.record.length_unit))  # fmt: skip
        alt_diff = _difference(alt_result, alt_table, None)
    except (ModelError, ValueError, ArithmeticError) as exc:
        return {"compared": _trend_words(other), "depends": False, "note": f"the comparison fit failed: {exc}"}
    main = {**{k: table[k] for k in _CORE}, "a-b": derived["a-b"]}
    second = {**{k: alt_table[k] for k in _CORE}, "a-b": alt_diff}
    differences = []
    x, y = main["a-b"], second["a-b"]
    decided = [p for p in (x, y) if p.interval and (p.interval[0] > 0 or p.interval[1] < 0)]
    if x.value * y.value < 0 and decided:
        differences.append("the sign of a-b")
    for key in ("a-b", *_CORE):
        m, o = main[key], second[key]
        # each outside the other's interval: the drift term moves the value beyond both fits' uncertainty (the
        # fit with one parameter more is the wider; noise alone moves the other's value inside it)
        if (m.interval and not m.interval[0] <= o.value <= m.interval[1]) and (
            o.interval and not o.interval[0] <= m.value <= o.interval[1]
        ):
            differences.append(key)
    mine, theirs = _trend_words(setup.trend), _trend_words(other)
    text = ""
    if differences:
        shown = "; ".join(f"{k}: {_pair_text(main[k])} with {mine}, {_pair_text(second[k])} with {theirs}"
                          for k in ("a-b", *_CORE))  # fmt: skip
        text = (f"the conclusion depends on the drift term ({', '.join(differences)} differ between the fit with "
                f"{mine} and with {theirs}): {shown}; reduced chi-square {level.redchi:.3g} with {theirs}")  # fmt: skip
    return {
        "compared": theirs, "fitted": mine, "depends": bool(differences), "differences": differences,
        "fit": {k: _si_entry(p) for k, p in main.items()},
        "alternative": {k: _si_entry(p) for k, p in second.items()},
        "alternative_reduced_chi_square": level.redchi, "text": text,
    }  # fmt: skip


def _trend_words(kinds: frozenset[str]) -> str:
    return "no drift term" if not kinds else "a drift in " + " and ".join(sorted(kinds))


def _pair_text(p: FitParameter) -> str:
    k = p.scale
    unit = f" {p.unit}" if p.unit else ""
    if p.interval is None:
        return f"{p.value / k:.4g}{unit} (no interval)"
    return f"{p.value / k:.4g} [{p.interval[0] / k:.4g}, {p.interval[1] / k:.4g}]{unit}"


def _si_entry(p: FitParameter) -> dict[str, Any]:
    return {"value": p.value, "interval": list(p.interval) if p.interval else None, "unit": p.si_unit or
            "dimensionless"}  # fmt: skip


#: Dc starts tried (x the first start) when a search fails, fits badly or leaves a, b or Dc unconstrained; the retries
#: stop early only once starts on both sides of the first agree.  A velocity-strengthening record with a short Dc on a
#: soft spring (tests/test_rsf_fit_protocols.py, truth Dc 5.5 um) started at 7.2 um and k 11x the truth slid on an AVX2
#: machine to Dc ~1e-8 m (reduced chi-square 1.26, a and b unconstrained), and from 0.72 um to the same; from 72 um it
#: found the truth (1.03).  Where the first search reached it, as on the machines before, no retry is made.
RETRY_DC_FACTORS = (0.1, 10.0, 0.01)


def _search(setup: _Setup, start: dict[str, float]) -> Any:
    """The least-squares fit from ``start``, in stages where one stage alone can lose its way."""
    if "time" in setup.trend:  # without the time drift first: free from the start the search can lose its way
        first, _ = _least_squares(replace(setup, states=1, trend=setup.trend - {"time"}), start)
        start = {**start, **_start_values(first.params.valuesdict())}
    if setup.states == 2:  # one state first: the two-state search starts from its answer, with a slower second state
        first, _ = _least_squares(replace(setup, states=1), start)
        given = {k: start[k] for k in ("dc2", "b2") if k in setup.guessed}
        start = {**start, **_start_values(first.params.valuesdict())}
        start["dc2"] = given.get("dc2", 10 * start["dc"])
        start["b2"] = given.get("b2", 0.2 * start["b"])
        best = _least_squares(setup, start)
        stiffer = "log_k" in best[0].params and math.exp(best[0].params["log_k"].value) > STIFF_RIG * start["stiffness"]
        if stiffer and "stiffness" not in setup.guessed:
            # one state takes up the second's slow evolution with a stiffer spring; from there the two-state
            # search can run into a stiff-rig basin (k -> 1e7 1/m, chi-square above the truth's): it is started
            # again from a softer spring and the lower chi-square kept
            other = _least_squares(setup, {**start, "stiffness": SOFTER * start["stiffness"]})
            return other if other[0].chisqr < best[0].chisqr * (1 - 1e-9) else best
        return best
    return _least_squares(setup, start)


#: the two-state search's second start: the one-state fit's stiffness times this, when the first ended beyond
#: STIFF_RIG times it
SOFTER = 0.2
STIFF_RIG = 10.0

#: searches restarted from where the last one stopped, at most, while chi-square still falls near the answer
POLISH_ROUNDS = 3


def _polish(setup: _Setup, start: dict[str, float], result: Any, residual: Any) -> Any:
    """Search again from two standard errors along the covariance's widest direction when chi-square is lower
    there, keeping a new search only when it lowers chi-square (docs/rsf.md, "Stopping short")."""
    for _ in range(POLISH_ROUNDS):
        lower = _downhill(result, residual)
        if lower is None:
            break
        here = {**start, **_start_values(lower.valuesdict())}
        again, again_residual = _least_squares(setup, here)
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
    # (a held one is not unconstrained; the stiffness, fitted, can run off to a rigid rig's local minimum, where
    # the spring's effect is lost and with it the direction back: a two-state record's search stopped at k = 5.7e11
    # 1/m against the truth's 2e4, chi-square_r 0.964 against 0.859 there, tests/test_rsf_two_state.py)
    for key in ("a", "b", "log_dc", "log_k"):
        if key not in result.params:
            continue
        par = result.params[key]
        se = par.stderr if par.stderr is not None and math.isfinite(par.stderr) else None
        if _unconstrained(key, par, se):
            return True
    return False


def _trouble_words(result: Any) -> str:
    """Why :func:`_troubled` holds, in words ("at reduced chi-square 109 > 2")."""
    if not result.success:
        return "without converging"
    if not result.errorbars:
        return "without a covariance"
    if result.chisqr > WARN_CHI2 * max(result.nfree, 1):
        return f"at reduced chi-square {result.chisqr / max(result.nfree, 1):.3g} > {WARN_CHI2:g}"
    return "with a, b, Dc or the stiffness unconstrained"


def _start_values(values: dict[str, float]) -> dict[str, float]:
    """A fit's values as starting values (log Dc, log k back to Dc, k)."""
    out = {k: v for k, v in values.items() if not k.startswith("log_")}
    out["dc"] = math.exp(values["log_dc"])
    if "log_dc2" in values:
        out["dc2"] = math.exp(values["log_dc2"])
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
    kept = [Segment(v, min(t1, end) - t0) for t0, t1, v in protocol.pieces() if t0 < end]
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
    step = next((i for i in range(1, speeds.size) if min(speeds[i], speeds[i - 1]) > 0 and speeds[i] != speeds[i - 1]),
                None)  # fmt: skip
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


def _noise(values: np.ndarray, time: np.ndarray | None = None) -> float:
    """White-noise level from second differences (robust: 1.4826 MAD, so transients do not inflate it); with
    ``time``, each row about the line through its neighbours at its own time (:func:`_about_neighbours`), so
    irregular stamps do not turn the slope into noise."""
    if time is not None and values.size >= 3:
        second = _about_neighbours(np.asarray(time, dtype=float), values)
        return float(1.4826 * np.median(np.abs(second - np.median(second))))
    second = np.diff(values, 2)
    return float(1.4826 * np.median(np.abs(second - np.median(second))) / math.sqrt(6.0))


def _base(setup: _Setup, start: dict[str, float]) -> RSFParams:
    laws = setup.laws[: setup.states]
    states = tuple(StateVariable(law, start["b"], start["dc"]) for law in laws)
    return RSFParams(a=max(start["a"], 1e-12), states=states, mu0=start["mu0"], v_ref=setup.protocol.initial_velocity,
                     stiffness=setup.fixed.get("stiffness", start["stiffness"]), cutoff=setup.cutoff)  # fmt: skip


#: a start's spring must be this many times the critical stiffness (b - a)/Dc: a search that starts beyond the
#: instability meets a blow-up at its first evaluation and cannot find its way back
STABLE_MARGIN = 1.5


def _stable_start(start: dict[str, float], dc_given: bool) -> dict[str, float]:
    """The start with its Dc raised (when the caller gave none) until the spring is stable there: a held or
    guessed stiffness of 1000 1/m with the default Dc (1 % of the slip) and a measured b - a of 0.005 started
    past k_c = 1190 1/m, and the fit failed with a blow-up although the record's own parameters are stable."""
    weakening = start["b"] - start["a"]
    if dc_given or weakening <= 0 or start["stiffness"] >= STABLE_MARGIN * weakening / start["dc"]:
        return start
    stable_dc = STABLE_MARGIN * weakening / start["stiffness"]
    return {**start, "dc": min(stable_dc, 0.5 * start["max_dc"])}


#: lmfit's name of each public parameter (Dc and k in log space)
_INTERNAL = {"mu0": "mu0", "a": "a", "b": "b", "dc": "log_dc", "b2": "b2", "dc2": "log_dc2", "stiffness": "log_k",
             "trend": "trend", "time_trend": "time_trend"}  # fmt: skip


def _least_squares(setup: _Setup, start: dict[str, float]) -> Any:
    import lmfit

    record, states, trend = setup.record, setup.states, setup.trend
    base = _base(setup, start)
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
    if setup.fit_stiffness:
        pars.add("log_k", value=math.log(start["stiffness"]), min=math.log(1e-2), max=math.log(1e12))
    if "slip" in trend:
        pars.add("trend", value=start["trend"])
    if "time" in trend:
        pars.add("time_trend", value=start["time_trend"])
    for index, _ in setup.changes:  # unbounded: _history keeps the changes in order
        pars.add(f"tc{index}", value=start.get(f"tc{index}", CHANGE_OFFSET))
    for key, value in setup.fixed.items():  # held where the caller put it, whatever the bounds of a free one
        name = _INTERNAL[key]
        if key == "stiffness" or (key in ("b2", "dc2") and states != 2):
            continue  # (a fixed stiffness is the base's own)
        if name in pars:
            del pars[name]
        pars.add(name, value=math.log(value) if name.startswith("log_") else value, vary=False)
    weights = 1.0 if setup.weights is None else np.sqrt(setup.weights)

    def residual(p: Any) -> np.ndarray:
        if time.process_time() > _DEADLINE.get():
            raise _OverBudget
        values = p.valuesdict()
        model, _ = _model_or_why(record, _history(setup, values), base, values)
        out = (model - record.friction) * weights / noise
        if setup.changes:  # each fitted change time's prior from the displacement: found +- its uncertainty
            prior = [values[f"tc{i}"] - CHANGE_OFFSET for i, _ in setup.changes]
            out = np.concatenate([out, math.sqrt(setup.change_weight) * np.asarray(prior)])
        return np.where(np.isfinite(out), out, 1e6)

    # a search stopped at its budget (an alternative's) returns the last point lmfit tried, a Jacobian's probe or a
    # trial step: the second-state alternative on velstep2 stopped at reduced chi-square 2e6, its best point 17.3.
    # Where it is stopped, it is judged at the best point it evaluated
    best: dict[str, Any] = {"chi": math.inf, "values": None}

    def tracked(p: Any) -> np.ndarray:
        out = residual(p)
        chi = float(np.sum(out**2))
        if chi < best["chi"]:
            best["chi"], best["values"] = chi, {name: p[name].value for name in p if p[name].vary}
        return out

    try:
        # MINPACK's forward-difference step sqrt(epsfcn) = 1e-5 (relative) sits well above the solver's
        # tolerance, so the Jacobians are not solver noise
        # scale_covar=False: the search's covariance assumes its noise scale; the reported one is set afterwards
        # lmfit's leastsq turns numpy's warnings off and back on only when it returns: an exception through it
        # (a stopped fit, ModelError) left them off for the rest of the process; errstate restores them always
        with np.errstate():
            result = lmfit.minimize(
                tracked if setup.max_nfev else residual,
                pars,
                method="leastsq",
                epsfcn=1e-10,
                max_nfev=setup.max_nfev or METHOD_MAX_NFEV,
                scale_covar=False,
            )
    except (ValueError, ArithmeticError) as exc:
        raise ModelError(f"rate-and-state fit failed: {exc}") from None
    if setup.max_nfev and not result.success and best["values"] is not None and best["chi"] < float(result.chisqr):
        for name, value in best["values"].items():
            result.params[name].value = value
        result.chisqr = best["chi"]
    return result, residual


def _final_params(base: RSFParams, values: dict[str, float]) -> RSFParams:
    """The rate-and-state parameters at the search's ``values`` (Dc and k in log space) on ``base``."""
    first = base.states[0]
    states = [StateVariable(first.law, values["b"], math.exp(values["log_dc"]), first.c)]
    if "b2" in values:
        states.append(StateVariable(base.states[-1].law, values["b2"], math.exp(values["log_dc2"])))
    k = math.exp(values["log_k"]) if "log_k" in values else base.stiffness
    return base.replace(a=values["a"], mu0=values["mu0"], states=tuple(states), stiffness=k)


_PUBLIC = {name: key for key, name in _INTERNAL.items()}


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
    return to_si(f"1 {unit}", "length", "length unit")


def _units(length_unit: str) -> dict[str, tuple[str, float]]:
    """Public name -> (unit label, SI per unit) for the values that carry a length."""
    scale = _length_scale(length_unit)
    per = (f"1/{length_unit}", 1.0 / scale)
    return {"dc": (length_unit, scale), "dc2": (length_unit, scale), "stiffness": per, "trend": per,
            "time_trend": ("1/s", 1.0)}  # fmt: skip


def _report(
    result: Any, values: dict[str, float], setup: _Setup, k_start: float, widen: float | None,
    units: dict[str, tuple[str, float]],
) -> tuple[dict[str, FitParameter], dict[str, float], list[str]]:  # fmt: skip
    table: dict[str, FitParameter] = {}
    warns: list[str] = []
    for key, public in _PUBLIC.items():
        if key not in result.params:
            continue
        par = result.params[key]
        unit, scale = units.get(public, ("", 1.0))
        si = _SI_UNITS.get(public, "")
        if not par.vary:
            value = math.exp(par.value) if key.startswith("log_") else par.value
            table[public] = FitParameter(public, value, None, None, fixed=True, unit=unit, scale=scale, si_unit=si)
            continue
        se = par.stderr if par.stderr is not None and math.isfinite(par.stderr) else None
        value, stderr, interval, scaled = _interval(par.value, se, key.startswith("log_"), widen)
        note = _unconstrained(key, par, se)
        if note:
            interval = scaled = None
            warns.append(f"{public}: not constrained by the record ({note})")
        elif not key.startswith("log_") and key != "mu0" and abs(value) > 0 and se is not None and se > abs(value):
            warns.append(f"{public}: undetermined (standard error {se:.3g} exceeds the value {value:.3g})")
        table[public] = FitParameter(public, value, stderr, interval, unit=unit, scale=scale, constrained=not note,
                                     note=note, scaled_interval=scaled, si_unit=si)  # fmt: skip
    for key, held in (("stiffness", setup.fixed.get("stiffness", k_start)), ("trend", 0.0)):
        if key not in table:  # a stiffness not fitted is the base's own; no drift term is a drift of 0
            unit, scale = units[key]
            table[key] = FitParameter(key, held, None, None, fixed=True, unit=unit, scale=scale, si_unit="1/m")
    corr: dict[str, float] = {}
    for key, par in result.params.items():
        for other, value in (par.correl or {}).items():
            pair = tuple(sorted((_public(key), _public(other))))
            name = f"{pair[0]}-{pair[1]}"
            if name not in corr:
                corr[name] = float(value)
                if abs(value) > 0.95:
                    warns.append(f"{pair[0]} and {pair[1]} are strongly correlated ({value:+.3f}): the record "
                                 "constrains a combination of them better than either")  # fmt: skip
    return table, corr, warns


#: SI unit of each public value that has one (the JSON is SI)
_SI_UNITS = {"dc": "m", "dc2": "m", "stiffness": "1/m", "trend": "1/m", "time_trend": "1/s"}
#: the SI units of a fit's parameters file's keys where the package's registry (stickslip.columns) has none or
#: another model's (its ``stiffness`` is the bond model's Pa/m): as RSFParams.to_toml's header and ``fit.units`` say
PARAMETER_FILE_UNITS = {
    **_SI_UNITS, "eta": "s/m", "mass": "kg/m^2", "normal_stress": "Pa", "c": "1", "v1": "m/s", "v2": "m/s",
    "start_velocity": "m/s", "v_ref": "m/s", "velocity": "m/s", "duration": "s", "start": "s", "file_time": "s",
    "rms": "1", "noise": "1", "t0": "s", "seconds": "s", "estimated_seconds": "s", "model_run_seconds": "s",
}  # fmt: skip


def _interval(
    fitted: float, se: float | None, log: bool, widen: float | None
) -> tuple[float, float | None, tuple[float, float] | None, tuple[float, float] | None]:
    """Value, standard error, 95 % interval and the interval widened by ``widen`` (log-space ones asymmetric)."""
    value = math.exp(fitted) if log else fitted
    if se is None:
        return value, None, None, None
    end = _exp if log else (lambda x: x)
    pair = (end(fitted - Z95 * se), end(fitted + Z95 * se))
    scaled = (end(fitted - Z95 * se * widen), end(fitted + Z95 * se * widen)) if widen else None
    return value, value * se if log else se, pair, scaled


#: a log-space parameter this close (in its log) to a bound of its range is at the edge: within 1 %
LOG_EDGE = 0.01


def _unconstrained(key: str, par: Any, se: float | None) -> str:
    """Why the record does not determine this parameter ('' when it does)."""
    if not par.vary:
        return ""
    if par.min is not None and par.max is not None and math.isfinite(par.min) and math.isfinite(par.max):
        span = par.max - par.min
        # a log-space value within 1 % of its bound is at it: a stiffness of 9.99e11 1/m against the bound 1e12
        # was "known only to within a factor e^2.4e+06" and nothing more
        near = max(1e-6 * span, LOG_EDGE) if key.startswith("log_") else 1e-6 * span
        if min(abs(par.value - par.min), abs(par.max - par.value)) < near:
            edge = par.min if abs(par.value - par.min) < abs(par.max - par.value) else par.max
            unit = " 1/m" if key == "log_k" else " m"
            shown = f"{math.exp(edge):.3g}{unit}" if key.startswith("log_") else f"{edge:.3g}"
            return f"at the edge of its allowed range ({shown}): the data push it as far as allowed"
    if se is None:
        return "no standard error: the covariance is singular, the record cannot tell it apart from the others"
    if key.startswith("log_") and se > 1.0:
        return f"known only to within a factor e^{se:.2g}"
    return ""


def _difference(result: Any, table: dict[str, FitParameter], widen: float | None) -> FitParameter:
    """a - b with its standard error from the covariance (their correlation included)."""
    value = table["a"].value - table["b"].value
    covar, names = result.covar, list(result.var_names)
    free = [(names.index(k), sign) for k, sign in (("a", 1.0), ("b", -1.0)) if k in names]  # (a held: b's error)
    if not free:
        return FitParameter("a-b", value, None, None, fixed=True)
    if covar is None:
        return FitParameter("a-b", value, None, None, constrained=False,
                            note="no covariance: the record cannot tell the parameters apart")  # fmt: skip
    var = float(sum(si * sj * covar[i, j] for i, si in free for j, sj in free))
    if not (math.isfinite(var) and var >= 0):
        return FitParameter("a-b", value, None, None, constrained=False, note="covariance not positive")
    se = math.sqrt(var)
    _, _, interval, scaled = _interval(value, se, False, widen)
    return FitParameter("a-b", value, se, interval, scaled_interval=scaled)


def _problems(
    result: Any, record: LabRecord, resid: np.ndarray, table: dict[str, FitParameter], level: Any, setup: _Setup,
    drift: str = "", opening: bool = False,
) -> list[str]:  # fmt: skip
    """Why the fit cannot be trusted (empty when it can); ``drift``: the ``--trend`` word of a drift the fit misses
    that explains most of the residuals (then a misfit is the drift's, not the law's); ``opening``: the record seems
    to start out of steady sliding (then a misfit is the opening's)."""
    problems = []
    redchi = level.redchi
    if not result.success:
        problems.append(f"the search did not converge ({result.message})")
    if not result.errorbars:
        problems.append("the covariance could not be estimated: the record cannot tell the parameters apart")
    if redchi > ABSURD_CHI2:
        problems.append(
            f"reduced chi-square {redchi:.3g} > {ABSURD_CHI2:g}: the model does not describe the record "
            + (
                "(its opening transient, above; check the load-point history of the rest too: --protocol or --segment)"
                if opening
                else "(check the load-point history: give it with --protocol or --segment)"
            )
        )
    free = [k for k in ("a", "b", "log_dc") if result.params[k].vary]
    moved = [k for k in free if _moved(result.params[k])]
    if free and not moved and (redchi > WARN_CHI2 or not result.errorbars):  # (a start that already fits is fine)
        problems.append("a, b and Dc did not move from their starting values")
    p_value = _response_p_value(result, record, resid, setup.trend, level.inflation)
    if p_value > NO_RESPONSE_LEVEL:
        problems.append(_no_response_problem(record, resid, setup, level, p_value, drift, opening))
    loose = [f"{k} ({table[k].note})" for k in _CORE if not table[k].constrained]
    if loose:
        problems.append("not constrained by the record: " + ", ".join(loose))
    second = [f"{k} ({table[k].note})" for k in ("b2", "dc2") if k in table and not table[k].constrained]
    if second:  # the data that do not constrain a fitted parameter: a failure for the second state too
        problems.append(
            "the second state is not constrained by the record: "
            + ", ".join(second)
            + "; fit one state (--states 1), or hold it (--fix b2=..., --fix dc2=...)"
        )
    return problems


#: a second state variable is kept where the F test against the one-state fit gives p below this
SECOND_STATE_LEVEL = 1e-3


def _constant_design(record: LabRecord, trend: frozenset[str]) -> np.ndarray:
    """The columns of constant friction plus the trends ``trend`` names (slip, time): one row per record row."""
    columns = [np.ones(len(record))] + ([record.displacement] if "slip" in trend else [])
    columns += [record.time] if "time" in trend else []
    return np.column_stack(columns)


def _constant_chi2(record: LabRecord, trend: frozenset[str], rows: np.ndarray) -> float:
    """Reduced chi-square of constant friction (plus the fit's trends) against the noise of each row."""
    design = _constant_design(record, trend)
    coef, *_ = np.linalg.lstsq(design, record.friction, rcond=None)
    null = record.friction - design @ coef
    return float(np.sum((null / rows) ** 2) / max(len(record) - design.shape[1], 1))


def _lag_one(resid: np.ndarray) -> float:
    """The residuals' lag-one autocorrelation (near 0 for white noise, near 1 for a misfit's smooth structure)."""
    r = resid - float(np.mean(resid))
    total = float(np.sum(r**2))
    return float(np.sum(r[1:] * r[:-1]) / total) if total > 0 else 0.0


def _other_laws(laws: tuple[str, ...]) -> str:
    """The ``--law`` options of the built-in laws not fitted, for a misfit's reason."""
    others = [name for name in ("aging", "slip", "prz") if name not in laws]
    return " or ".join(f"--law {name}" for name in others)


def _law_words(laws: tuple[str, ...]) -> str:
    """``the aging law``, ``the aging and slip laws``."""
    names = list(dict.fromkeys(laws))
    return f"the {' and '.join(names)} law{'s' if len(names) > 1 else ''}"


def _law_not_determined(problems: list[str], laws: tuple[str, ...]) -> str:
    """The note for a, b, Dc and the stiffness when no interval of the friction law means anything (the fit is no
    better than constant friction, the law or the held stiffness is not the record's, or a drift the fit misses
    decides it), in the words of the reason; '' otherwise."""
    for problem in problems:
        if problem.startswith(NO_RESPONSE_TEXT):
            return "the friction shows no velocity dependence"
        if problem.startswith(MISFIT_TEXT.format(law=_law_words(laws))):
            return MISFIT_TEXT.format(law=_law_words(laws))
        if problem.startswith(WEAK_RESPONSE_TEXT):
            return WEAK_RESPONSE_TEXT
        if problem.startswith(HELD_STIFFNESS_TEXT):
            return "the held stiffness does not describe the record"
        if problem.startswith(ONE_STATE_TEXT):
            return ONE_STATE_TEXT
        if problem.startswith(DRIFT_MASKED_TEXT):
            return "not determined while the fit misses the drift"
        if problem.startswith(OPENING_MASKED_TEXT):
            return "not determined while the fit bends to the record's opening transient"
    return ""


def _no_response_problem(
    record: LabRecord, resid: np.ndarray, setup: _Setup, level: _Level, p_value: float, drift: str = "",
    opening: bool = False, tried: str = "",
) -> str:  # fmt: skip
    """Why a fit no better than constant friction fails: constant friction describes the record to within its noise
    (no velocity dependence), or the friction does vary but the law fitted does not describe how (a misfit) or, where
    a drift the fit misses explains most of the residuals (``drift``, the --trend word), the drift hides it.
    ``tried``: what the alternatives tried at a misfit reached (none describing the record), said in place of the
    advice to fit another law."""
    trends = " with the trends" if setup.trend else ""
    rows = level.rows if level.rows is not None else np.full(len(record), level.noise)
    constant = _constant_chi2(record, setup.trend, rows)
    if constant <= WARN_CHI2:
        return (
            f"{NO_RESPONSE_TEXT}: constant friction{trends} describes the record to within its noise (reduced "
            f"chi-square {constant:.3g} against the noise {level.noise:.2g}; F test of the fit against it: p = "
            f"{p_value:.2g}), so a, b and Dc are not determined"
        )
    if level.redchi > WARN_CHI2 and drift:  # the drift leads the reason; the law is judged once it is fitted
        return (
            f"{DRIFT_MASKED_TEXT}: with it missed, {_f_test_short(p_value, trends, constant)}, so a, b and Dc are not "
            f"determined until it is fitted (--trend {drift})"
        )
    if level.redchi > WARN_CHI2 and opening:  # the opening leads the reason: no law can start on its transient
        return (
            f"{OPENING_MASKED_TEXT}: bent to it, {_f_test_short(p_value, trends, constant)}, so a, b and Dc are not "
            "determined until the rows from where the friction has settled are fitted (--window)"
        )
    if level.redchi > WARN_CHI2:
        others = _other_laws(setup.laws)
        return (
            f"{MISFIT_TEXT.format(law=_law_words(setup.laws))}: {_misfit_words(record, resid, setup, level, p_value)}"
            "; so a, b and Dc are not determined; "
            + (f"{tried}; " if tried else f"fit another law ({others}), or " if others else "")
            + "check the load-point history (--segment, --protocol) and that the friction follows the velocity "
            "changes"
        )
    return (
        f"{WEAK_RESPONSE_TEXT} against its correlated noise (F test"
        f" against constant friction{trends}: p = {p_value:.2g}, with {level.n_eff:.3g} effective independent rows"
        f" of {len(record)}), though constant friction misses the record (reduced chi-square {constant:.3g}); so "
        "a, b and Dc are not determined"
    )


#: what follows the law's words in the reason of a misfit (:func:`_misfit_words`)
MISFIT_RESIDUALS = "its residuals are"


def _misfit_alone(problems: list[str], laws: tuple[str, ...]) -> bool:
    """Whether the one problem is the law's misfit (its F test against constant friction not significant while the
    friction varies beyond its noise): then the alternatives are tried for the advice."""
    head = f"{MISFIT_TEXT.format(law=_law_words(laws))}: {MISFIT_RESIDUALS}"
    return len(problems) == 1 and problems[0].startswith(head)


def _misfit_words(record: LabRecord, resid: np.ndarray, setup: _Setup, level: _Level, p_value: float) -> str:
    """What a misfit's residuals are, against the noise and against constant friction, and what the F test against
    constant friction found with them as the noise."""
    trends = " with the trends" if setup.trend else ""
    rows = level.rows if level.rows is not None else np.full(len(record), level.noise)
    constant = _constant_chi2(record, setup.trend, rows)
    return (
        f"{MISFIT_RESIDUALS} {math.sqrt(level.redchi):.3g} times the noise {level.noise:.2g} (reduced chi-square "
        f"{level.redchi:.3g}) and structured (lag-one autocorrelation {_lag_one(resid):.3f}), while the friction "
        f"varies well beyond its noise (constant friction{trends}: reduced chi-square {constant:.3g}); "
        + _f_test_words(record, level, p_value, trends)
    )


def _f_test_words(record: LabRecord, level: _Level, p_value: float, trends: str) -> str:
    """The F test of the fit against constant friction as :func:`_response_p_value` makes it: the fit's own
    residuals are its noise, each row counting 1/g of one, so a misfit's smooth residuals leave a handful of rows
    (and that handful grows with the sampling rate: g stops near 2000 rows)."""
    return (
        f"with the fit's own residuals taken as the noise (their correlation leaves {level.n_eff:.3g} effective "
        f"independent rows of {len(record)}), its improvement on constant friction{trends} is not significant at the "
        f"{NO_RESPONSE_LEVEL:g} level this check requires (F test: {_p_beside(p_value, NO_RESPONSE_LEVEL)})"
    )


def _f_test_short(p_value: float, trends: str, constant: float) -> str:
    """:func:`_f_test_words` where the reason's cause is another (a drift, an opening), with constant friction's
    chi-square_r."""
    return (
        f"the fit's improvement on constant friction{trends} is not significant at the {NO_RESPONSE_LEVEL:g} level "
        f"against its own residuals taken as the noise (F test: {_p_beside(p_value, NO_RESPONSE_LEVEL)}; constant "
        f"friction: reduced chi-square {constant:.3g})"
    )


def _p_beside(p_value: float, level: float) -> str:
    """``p = 0.00101``: with the digits that tell p from ``level`` (0.00101 beside 1e-3 printed 0.001 read as if it
    passed the level it failed)."""
    for digits in range(2, 7):
        text = f"{p_value:.{digits}g}"
        if (float(text) > level) == (p_value > level) and float(text) != level:
            return f"p = {text}"
    return f"p = {p_value:.6g}"


def _second_state_problems(setup: _Setup, start: dict[str, float], result: Any) -> list[str]:
    """Why a two-state fit cannot be trusted where the record shows one state: the F test of its fitted second
    state (b2, Dc2) against the best one-state fit (which the two-state search starts from).  Two states of one
    law can share one state's response in many ways (b + b2 and the Dc's in a ridge), intervals and all; without
    a second state in the record that ridge is all the fit has found."""
    from scipy import stats

    extra = sum(result.params[k].vary for k in ("b2", "log_dc2") if k in result.params)
    dof = result.ndata - result.nvarys
    if extra == 0 or dof <= 0 or not result.chisqr > 0:
        return []
    one, _ = _least_squares(replace(setup, states=1), start)
    value = max(one.chisqr - result.chisqr, 0.0) / extra / (result.chisqr / dof)
    p_value = float(stats.f.sf(value, extra, dof))
    if p_value <= SECOND_STATE_LEVEL:
        return []
    drop = 100.0 * max(one.chisqr - result.chisqr, 0.0) / one.chisqr
    return [
        f"the record shows no second state: two states lower chi-square by {drop:.3g} % of one state's (F test"
        f" against one state: p = {p_value:.2g}), so b, Dc, b2 and Dc2 are not determined apart; fit one state"
        " (--states 1)"
    ]


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


def _residual_drift(record: LabRecord, resid: np.ndarray, kinds: tuple[str, ...] = ("slip", "time")) -> float:
    """Share of the residuals' sum of squares a straight line in slip and time (or in ``kinds``) explains."""
    columns = {"slip": record.displacement, "time": record.time}
    design = np.column_stack([np.ones(len(record))] + [columns[k] for k in kinds])
    coef, *_ = np.linalg.lstsq(design, resid, rcond=None)
    total = float(np.sum(resid**2))
    return 1.0 - float(np.sum((resid - design @ coef) ** 2)) / total if total > 0 else 0.0


# --- a drift the fit misses ------------------------------------------------------------------------------------

#: a drift that explains more than this share of the residuals leads the reason: no law can be judged before it is
#: fitted (a law's misfit, and the F test against constant friction, then measure the drift, not the law)
DRIFT_LEAD = 0.5
#: a drift in slip and one in time whose refits' chi-square_r are within this share of each other: both are advised
DRIFT_ALIKE = 0.1
#: the start of a misfit's reason when a drift the fit misses explains most of the residuals
DRIFT_MASKED_TEXT = "the law cannot be judged while the fit misses the drift"
#: the start of a misfit's reason when the record seems to start out of steady sliding (the model cannot)
OPENING_MASKED_TEXT = "the law cannot be judged while the fit bends to the record's opening transient"


@dataclass(frozen=True)
class _Drift:
    """A drift in the residuals: the share a line in slip and time explains, the ``--trend`` word that would fit it,
    the reason's words ('' when it is no problem) and whether it leads the reason."""

    share: float
    advice: str = ""
    text: str = ""
    leads: bool = False
    #: a refit with the drift advised describes the record (chi-square_r <= WARN_CHI2)
    describes: bool = False


def _drift_advice(setup: _Setup) -> tuple[str, str]:
    """The ``--trend`` word and the words that advise fitting the drift terms not fitted or held yet (a fit with
    ``--trend`` was told to "fit the drift with --trend slip, time or both": the slip drift it had fitted)."""
    terms = {"slip": "trend", "time": "time_trend"}
    held = {kind for kind, term in terms.items() if term in setup.fixed}
    missing = sorted(set(terms) - setup.trend - held)
    missed = "the model misses a drift, so its values and intervals are biased"
    if len(missing) == 2:
        return "slip, time or both", f"{missed}; fit the drift with --trend slip, time or both"
    if not missing:
        return "", ("though the drifts in slip and time are in the fit already: what is left is no straight drift, "
                    "and the values and intervals are biased by it; check the load-point history and the "
                    "record")  # fmt: skip
    other = "slip" if missing[0] == "time" else "time"
    word = "both" if other in setup.trend else missing[0]
    how = "fitted" if other in setup.trend else "held"
    return word, f"{missed}; the drift in {other} is {how} already: add one in {missing[0]} with --trend {word}"


def _drift_reading(
    setup: _Setup, start: dict[str, float], result: Any, resid: np.ndarray, level: _Level, refit: bool = True
) -> _Drift:  # fmt: skip
    """With chi-square_r > WARN_CHI2 and a line in slip and time explaining over DRIFT_SHARE of the residuals, the
    problem.  Where it explains over DRIFT_LEAD it leads the reason, and the drift to fit is found by refitting, from
    the fit's answer, with a drift in slip and with one in time (each not already fitted): the lower chi-square's, or
    both where the two are within DRIFT_ALIKE of each other.  The residuals' own line is no guide to which: a slip
    drift of 30 per m on 1 -> 10 -> 1 um/s left residuals a line in time explained better, as a, b, Dc and k had bent
    to a part of it (refitted from the fit's answer: slip drift chi-square_r 1.11, time drift 8.53)."""
    record = setup.record
    both = _residual_drift(record, resid)
    if not (level.redchi > WARN_CHI2 and both > DRIFT_SHARE):
        return _Drift(both)
    if both <= DRIFT_LEAD:
        advice, said = _drift_advice(setup)
        return _Drift(
            both,
            advice,
            (
                f"a linear drift in slip and time explains {100 * both:.0f} % of the residuals (reduced chi-square "
                f"{level.redchi:.3g}): {said}"
            ),
        )
    rows = level.rows if level.rows is not None else np.full(len(record), level.noise)
    here = {**start, **_start_values(result.params.valuesdict())}
    reached = {}
    for kind in ("slip", "time") if refit else ():  # (no refit helps a history that is not the record's)
        term = "trend" if kind == "slip" else "time_trend"
        if kind in setup.trend or term in setup.fixed:  # (fitted already, or held where the caller put it)
            continue
        alt = replace(setup, trend=setup.trend | {kind})
        try:
            fit, _ = _least_squares(alt, {**here, term: 0.0})
        except ModelError:
            continue
        values = fit.params.valuesdict()
        model, why = _model_or_why(record, _history(alt, values), _base(alt, here), values)
        if not why:
            reached[kind] = float(np.sum(((record.friction - model) / rows) ** 2) / max(len(record) - fit.nvarys, 1))
    if reached:
        kind = min(reached, key=lambda k: reached[k])
        alike = len(reached) == 2 and max(reached.values()) <= (1 + DRIFT_ALIKE) * min(reached.values())
        kinds = ({"slip", "time"} if alike else {kind}) | set(setup.trend)
        shown = ", ".join(f"a drift in {k} {reached[k]:.3g}" for k in sorted(reached, key=lambda k: reached[k]))
        refits = f"; refitted from this answer, reduced chi-square with {shown}"
    else:
        kinds, refits = {"slip", "time"}, ""
    advice = "both" if len(kinds) == 2 else next(iter(kinds))
    if not reached and not _drift_advice(setup)[0]:  # (nothing left to add: no advice to fit what is in the fit)
        return _Drift(both, "", (
            f"a linear drift in slip and time explains {100 * both:.0f} % of the residuals (reduced chi-square "
            f"{level.redchi:.3g}) with drifts in slip and time in the fit already: the rest is no straight drift; "
            "check the load-point history and the record"))  # fmt: skip
    return _Drift(both, advice, (
        f"a linear drift in slip and time explains {100 * both:.0f} % of the residuals (reduced chi-square "
        f"{level.redchi:.3g}{refits}): the model misses a drift, so its values and intervals are biased, and no law "
        f"can be judged until the drift is fitted; fit the drift first with --trend {advice}"), True,
        bool(reached) and min(reached.values()) <= WARN_CHI2)  # fmt: skip


# --- is another model the answer? --------------------------------------------------------------------------------

#: an alternative that describes the record (chi-square_r <= WARN_CHI2) fails the fit where the chi-square it saves
#: is beyond what the noise allows at this one-sided level (docs/rsf.md, "Is another model the answer?")
ALTERNATIVE_LEVEL = 1e-3
#: the built-in single-state laws an alternative fit swaps between
ALTERNATIVE_LAWS = ("aging", "slip", "prz")


@dataclass(frozen=True)
class _Candidate:
    """One alternative to the fit: its words, the options that fit it, and its search's setup and start."""

    words: str
    option: str
    setup: _Setup
    start: dict[str, float]
    #: searched as a two-state fit is (:func:`_search`: a one-state stage, then the second state from its answer)
    staged: bool = False


def _candidates(setup: _Setup, here: dict[str, float], laws: tuple[str, ...], free: bool) -> list[_Candidate]:
    """The fit with ``laws`` (each in place of the one fitted) and, with ``free``, the held stiffness freed."""
    out = []
    freed = {k: v for k, v in setup.fixed.items() if k != "stiffness"}
    for law in laws:
        changed = law != setup.laws[0]
        parts = (f"the {law} law" if changed else "", "the stiffness free" if free else "")
        words = " with ".join(w for w in parts if w)
        option = " ".join(o for o in (f"--law {law}" if changed else "", "--free stiffness" if free else "") if o)
        alt = replace(setup, laws=(law,) * setup.states if changed else setup.laws,
                      fit_stiffness=setup.fit_stiffness or free, fixed=freed if free else setup.fixed)  # fmt: skip
        start = {**here, "stiffness": setup.fixed["stiffness"]} if free else here
        out.append(_Candidate(words, option, alt, start))
    return out


def _steady_bound(setup: _Setup, protocol: Protocol, rows: np.ndarray) -> float:
    """Chi-square (against the noise of each row) of the first 90 % of the first segment about its best constant
    (plus the fitted drifts' columns, less the held ones): every alternative starts in steady sliding at the first
    velocity, whatever its law or stiffness, and its friction there is mu0 plus the drifts, so none can go below
    this."""
    record, trend, held = setup.record, setup.trend, setup.fixed
    if len(protocol.segments) < 2:
        return 0.0
    first = record.time < 0.9 * float(protocol.boundaries[1])
    design = _constant_design(record, trend)[first] / rows[first, None]
    if int(first.sum()) <= design.shape[1]:
        return 0.0
    friction = record.friction - held.get("trend", 0.0) * record.displacement
    friction = friction - held.get("time_trend", 0.0) * record.time
    target = friction[first] / rows[first]
    coef, *_ = np.linalg.lstsq(design, target, rcond=None)
    return float(np.sum((target - design @ coef) ** 2))


def _alternatives(
    setup: _Setup, start: dict[str, float], result: Any, model: np.ndarray, level: _Level, labels: np.ndarray,
    units: dict[str, tuple[str, float]], noise: float | None, diagnosis: str = "",
) -> tuple[tuple[dict[str, Any], ...], str, str]:  # fmt: skip
    """The fit tried again, from its answer, with what the caller chose changed: a held stiffness freed, and a
    single-state built-in law swapped for each other one (then the best of those with the stiffness freed as well,
    where a held one was and neither alone describes the record).  Returns what each reached (JSON), the failure
    (an alternative describes the record, chi-square_r <= WARN_CHI2, and saves more chi-square than the noise
    allows: :func:`_paired_test`) and the warning's words ('' for none).  None is tried where the first segment
    alone, where every alternative gives the same steady friction, keeps chi-square_r above WARN_CHI2.
    ``diagnosis``: what the fit's misfit shows (:func:`_misfit_words`), said in the failure after its head."""
    record = setup.record
    values = result.params.valuesdict()
    here = {**start, **_start_values(values)}
    held = not setup.fit_stiffness and "stiffness" in setup.fixed
    laws = tuple(law for law in ALTERNATIVE_LAWS if law != setup.laws[0]) if (
        setup.states == 1 and setup.laws[0] in ALTERNATIVE_LAWS) else ()  # fmt: skip
    second = setup.states == 1  # a second state variable of the fit's own law (any law, a registered one too)
    if not held and not laws and not second:
        return (), "", ""
    rows = level.rows if level.rows is not None else np.full(len(record), level.noise)
    most = result.nvarys + int(held) + 2 * int(second)
    floor = _steady_bound(setup, _history(setup, values), rows) / max(len(record) - most, 1)
    tried_kinds = [f"the {law} law" for law in laws] + (["a free stiffness"] if held else [])
    tried_kinds += [SECOND_STATE_WORDS] if second else []
    if floor > WARN_CHI2:
        subject = f"neither {' nor '.join(tried_kinds)}" if len(tried_kinds) > 1 else tried_kinds[0]
        # what is tested is whether one could describe the record to within its noise (reduced chi-square <= 2, what
        # fails this fit), not whether one fits it somewhat better: the velstep3 record fits the slip law better
        return ({"skipped": tried_kinds, "reduced_chi_square_floor": floor},), "", (
            f"{subject} can describe the record to within its noise (reduced chi-square <= {WARN_CHI2:g}, what would "
            "fail this fit): over its first segment, where every law, stiffness and number of states give the same "
            f"steady friction, the residuals alone make reduced chi-square at least {floor:.3g} (> {WARN_CHI2:g}) "
            f"over the record, so {'none was' if len(tried_kinds) > 1 else 'it was not'} tried (one may still fit "
            "somewhat better: fit it to compare)"
        )  # fmt: skip
    candidates = _candidates(setup, here, (setup.laws[0],), True) if held else []
    candidates += _candidates(setup, here, laws, False)
    reached = [_tried(c, record, model, rows, labels) for c in candidates]
    swapped = [r for r in reached if r["law"] != setup.laws[0] and "values" in r]
    if held and swapped and not any(r["describes"] for r in reached):  # both changed: from the best other law
        best = min(swapped, key=lambda r: r["reduced_chi_square"])
        both = _candidates(setup, {**here, **best["values"]}, (best["law"],), True)[0]
        reached.append(_tried(both, record, model, rows, labels))
    if second and not any(r["describes"] for r in reached):  # (the simpler models first: a one-state one that
        # describes the record is the answer, and the two-state search, the costliest, is not made)
        reached.append(_tried(_second_state(setup, here), record, model, rows, labels))
    else:
        tried_kinds = [k for k in tried_kinds if k != SECOND_STATE_WORDS]
    kinds = " or ".join(tried_kinds)
    shown = ", ".join(_reached_text(r) for r in reached)
    good = sorted((r for r in reached if r["describes"] and r["better"]), key=lambda r: r["reduced_chi_square"])
    if not good:
        said = (f"alternatives tried from this fit's answer ({kinds}), reduced chi-square against the same noise: "
                f"{shown}; none describes the record (<= {WARN_CHI2:g}) significantly better")  # fmt: skip
        return tuple(_public_tried(r) for r in reached), "", said
    best = good[0]
    candidate = best.pop("candidate")
    alt_result = best.pop("result")
    base = _base(candidate.setup, candidate.start)
    alt_model = best["model"]
    _uncertainty(candidate.setup, base, alt_result, alt_model, labels, noise)  # (its covariance, for its intervals)
    table, _, _ = _report(alt_result, alt_result.params.valuesdict(), candidate.setup, candidate.start["stiffness"],
                          None, units)  # fmt: skip
    keys = ("stiffness", "a", "b", "dc") if "free" in candidate.words else ("a", "b", "dc", "b2", "dc2", "stiffness")
    best["parameters"] = {k: _si_entry(table[k]) for k in keys if k in table}
    values_text = _values_text(table, keys)
    from ..display import unit as shown_unit

    k_unit, k_scale = units["stiffness"]
    held_k = f"{setup.fixed['stiffness'] / k_scale:.4g} {shown_unit(k_unit)}" if held else ""
    evidence = (f"reduced chi-square {best['reduced_chi_square']:.3g} against this fit's {level.redchi:.3g}, "
                f"against the same noise; chi-square lower by {best['chi_square_drop']:.3g}, {best['z']:.3g} times "
                f"its spread under the noise alone: {_p_text(best['p_value'])}")  # fmt: skip
    others = [r for r in reached if r is not best]
    also = "; also tried: " + ", ".join(_reached_text(r) for r in others) if others else ""
    lead = f"{diagnosis}; " if diagnosis else ""
    if candidate.words == "the stiffness free":
        failure = (f"{HELD_STIFFNESS_TEXT} {held_k} does not describe the record: {lead}with the stiffness free the "
                   f"fit does, at {values_text} ({evidence}){also}; free the stiffness ({candidate.option}) or check "
                   "the rig's stiffness")  # fmt: skip
    elif candidate.staged:
        failure = (f"{ONE_STATE_TEXT}{f' with the stiffness held at {held_k}' if held else ''}: {lead}a second one "
                   f"does ({candidate.words}), at {values_text} ({evidence}){also}; fit it with "
                   f"{candidate.option}")  # fmt: skip
    else:
        law = MISFIT_TEXT.format(law=_law_words(setup.laws)) + (f" with the stiffness held at {held_k}" if held else "")
        failure = (f"{law}: {lead}{candidate.words} does, at {values_text} ({evidence}){also}; fit it with "
                   f"{candidate.option}")  # fmt: skip
    return tuple(_public_tried(r) for r in reached), failure, ""


#: Jacobians (each one model run per free parameter, and one) each search of the second-state alternative may take:
#: the tester's two-state record needed 11 (102 runs); on velstep2 with --trend --law slip the search ran to the
#: 1500-run cap (18 s of CPU, Dc2 at the edge of its range, reduced chi-square 17.34 against one state's 17.59)
SECOND_STATE_JACOBIANS = 30
#: the words of the second-state alternative in the lists of what was tried
SECOND_STATE_WORDS = "a second state variable"
#: the start of a one-state fit's reason where a second state variable describes the record significantly better
ONE_STATE_TEXT = "one state variable does not describe the record"


def _second_state(setup: _Setup, here: dict[str, float]) -> _Candidate:
    """The fit with a second state variable of its own law, everything else as the caller chose: searched as
    ``--states 2`` is (:func:`_search`), its one-state stage from this fit's answer."""
    law = setup.laws[0]
    free = 6 + sum(1 for value in (setup.fit_stiffness, "slip" in setup.trend, "time" in setup.trend) if value)
    free += len(setup.changes) - sum(1 for k in ("mu0", "a", "b", "dc") if k in setup.fixed)  # (and b2, Dc2)
    alt = replace(setup, states=2, laws=(law, law), max_nfev=SECOND_STATE_JACOBIANS * (free + 1))
    return _Candidate(f"two states of the {law} law", "--states 2", alt, here, staged=True)


def _tried(
    candidate: _Candidate, record: LabRecord, model: np.ndarray, rows: np.ndarray, labels: np.ndarray
) -> dict[str, Any]:  # fmt: skip
    """One alternative's search from the fit's answer and what it reached, judged by the fit's own noise."""
    out: dict[str, Any] = {"fit": candidate.words, "option": candidate.option, "law": candidate.setup.laws[0],
                           "reduced_chi_square": math.nan, "describes": False, "better": False, "note": "",
                           "candidate": candidate}  # fmt: skip
    try:
        result, _ = (_search if candidate.staged else _least_squares)(candidate.setup, candidate.start)
    except ModelError as exc:
        return {**out, "note": str(exc)}
    values = result.params.valuesdict()
    alt, why = _model_or_why(record, _history(candidate.setup, values), _base(candidate.setup, candidate.start), values)
    if why:
        return {**out, "note": why}
    dof = max(len(record) - result.nvarys, 1)
    redchi = float(np.sum(((record.friction - alt) / rows) ** 2) / dof)
    drop, z, p_value = _paired_test(record.friction, model, alt, rows, labels, redchi)
    if candidate.setup.max_nfev and not result.success:  # (judged where its bounded search stopped)
        out["note"] = f"its search stopped at its budget of {candidate.setup.max_nfev} model runs"
    return {**out, "reduced_chi_square": redchi, "chi_square_drop": drop, "z": z, "p_value": p_value,
            "describes": redchi <= WARN_CHI2, "better": p_value < ALTERNATIVE_LEVEL, "values": _start_values(values),
            "result": result, "model": alt}  # fmt: skip


def _paired_test(
    friction: np.ndarray, model: np.ndarray, alt: np.ndarray, rows: np.ndarray, labels: np.ndarray, redchi: float
) -> tuple[float, float, float]:
    """The chi-square the alternative saves, D = sum (r_fit^2 - r_alt^2) / sigma^2, against its spread under the
    noise alone, 2 sqrt(s sum g delta^2 / sigma^2) (delta the two models' difference, g the alternative's residuals'
    correlation factor per row, s its chi-square_r where above 1): (D, z, one-sided p).  For nested and non-nested
    alternatives alike (a law swapped has no extra parameter for an F test to count)."""
    from scipy import stats

    r_fit, r_alt = (friction - model) / rows, (friction - alt) / rows
    drop = float(np.sum(r_fit**2 - r_alt**2))
    g = _correlation_factor(friction - alt, labels)
    spread = 2.0 * math.sqrt(max(redchi, 1.0) * float(np.sum(g * ((alt - model) / rows) ** 2)))
    if not spread > 0:
        return drop, 0.0, 1.0
    z = drop / spread
    return drop, z, float(stats.norm.sf(z))


def _p_text(p_value: float) -> str:
    """``p = 1.2e-05``, or ``p < 1e-300`` where it underflows."""
    return f"p = {p_value:.2g}" if p_value >= 1e-300 else "p < 1e-300"


def _reached_text(entry: dict[str, Any]) -> str:
    """``the slip law 17.7`` (its chi-square_r), or why it could not be evaluated."""
    if math.isfinite(entry["reduced_chi_square"]):
        weak = f" (not significantly better: {_p_text(entry['p_value'])})" if entry["describes"] and not entry[
            "better"] else ""  # fmt: skip
        stopped = f" ({entry['note']})" if entry.get("note") else ""
        return f"{entry['fit']} {entry['reduced_chi_square']:.3g}{weak}{stopped}"
    return f"{entry['fit']} (not evaluated: {entry['note']})"


def _public_tried(entry: dict[str, Any]) -> dict[str, Any]:
    """An alternative as the JSON gives it (SI values)."""
    keep = (
        "fit",
        "option",
        "reduced_chi_square",
        "describes",
        "better",
        "chi_square_drop",
        "z",
        "p_value",
        "parameters",
        "note",
    )
    out = {k: entry[k] for k in keep if k in entry and entry[k] != ""}
    if "parameters" not in out and "values" in entry:
        out["values"] = {k: entry["values"][k] for k in ("a", "b", "dc", "b2", "dc2", "stiffness")
                         if k in entry["values"]}  # fmt: skip
    return out


def _values_text(table: dict[str, FitParameter], keys: tuple[str, ...]) -> str:
    """``a = 0.008 [0.00798, 0.00802], dc = 20 [19.9, 20.1] µm`` in the record's units (free values only)."""
    from ..display import unit as shown_unit

    parts = []
    for key in keys:
        p = table.get(key)
        if p is None or p.fixed:
            continue
        unit, k = (f" {shown_unit(p.unit)}" if p.unit else ""), p.scale
        if p.interval is None:
            parts.append(f"{key} = {p.value / k:.4g}{unit} (no interval)")
        else:
            parts.append(f"{key} = {p.value / k:.4g} [{p.interval[0] / k:.4g}, {p.interval[1] / k:.4g}]{unit}")
    return ", ".join(parts)


# --- the sign of b ----------------------------------------------------------------------------------------------


def _sign_notes(table: dict[str, FitParameter]) -> tuple[str, ...]:
    """A reading of each fitted negative b (b2): legitimate, and what it says (docs/rsf.md, "A negative b")."""
    notes = []
    for key in ("b", "b2"):
        p = table.get(key)
        if p is None or p.fixed or not p.value < 0 or p.interval is None:
            continue
        if p.interval[1] >= 0:
            notes.append(f"{key} = {p.value:.3g} is negative, but its interval [{p.interval[0]:.3g}, "
                         f"{p.interval[1]:.3g}] holds 0: the sign of the state's effect is not determined")  # fmt: skip
            continue
        notes.append(
            f"{key} = {p.value:.3g} [{p.interval[0]:.3g}, {p.interval[1]:.3g}] < 0: the state weakens the surface as "
            "it ages (and strengthens it as it is renewed by slip): after a step up the friction keeps rising beyond "
            "the direct effect instead of decaying, steady sliding is more velocity strengthening than a alone "
            "(a - b > a), and a hold would weaken rather than heal.  A legitimate reading, which clay-rich gouges "
            "often give; not a failed fit"
        )
    return tuple(notes)


def _moved(par: Any) -> bool:
    start = par.init_value if par.init_value is not None else par.value
    return abs(par.value - start) > 1e-9 * max(1.0, abs(start))


def _response_p_value(
    result: Any, record: LabRecord, resid: np.ndarray, trend: frozenset[str], inflation: float
) -> float:
    """p of the rate-and-state fit's improvement over constant friction (plus the trend) arising by chance; with
    correlated residuals each row counts 1/``inflation`` (the F statistic and its degrees of freedom shrink)."""
    from scipy import stats

    design = _constant_design(record, trend)
    coef, *_ = np.linalg.lstsq(design, record.friction, rcond=None)
    null = float(np.sum((record.friction - design @ coef) ** 2))
    extra = result.nvarys - design.shape[1]
    dof = max((len(record) - result.nvarys) / inflation, 1.0)
    fitted = float(np.sum(resid**2))
    if extra <= 0 or fitted <= 0:
        return 0.0 if null > fitted else 1.0
    f_value = max(null - fitted, 0.0) / extra / (fitted / (len(record) - result.nvarys)) / inflation
    return float(stats.f.sf(f_value, extra, dof))


#: a posterior's chain has mixed when it is this many integrated autocorrelation times long after its burn-in (the
#: check of ``fit steady --bayes``, :data:`stickslip.fitting.bayes.CONVERGED_TIMES`); short of it no interval is given
MIXED_TIMES = 50
#: the independence proposal's t (degrees of freedom) about the least-squares answer and covariance, and its share
#: of the moves (the rest differential evolution), as ``fit steady --bayes`` (stickslip.fitting.bayes)
PROPOSAL_DOF = 10.0
INDEPENDENCE_SHARE = 0.5


class _Independence:
    """Independence proposal q(x): a multivariate t about the least-squares answer with its covariance."""

    def __init__(self, centre: np.ndarray, root: np.ndarray) -> None:
        self.centre, self.root = centre, root
        self.inverse = np.linalg.pinv(root)

    def log_q(self, x: np.ndarray) -> np.ndarray:
        z = (x - self.centre) @ self.inverse.T
        return -0.5 * (PROPOSAL_DOF + self.centre.size) * np.log1p(np.sum(z * z, axis=1) / PROPOSAL_DOF)

    def __call__(self, x0: np.ndarray, random: np.random.RandomState) -> tuple[np.ndarray, np.ndarray]:
        count, dim = x0.shape
        w = np.sqrt(PROPOSAL_DOF / random.chisquare(PROPOSAL_DOF, size=count))
        x = self.centre + (random.standard_normal((count, dim)) @ self.root.T) * w[:, None]
        return x, self.log_q(x0) - self.log_q(x)  # log q(x0)/q(x): the Hastings factor


def _covariance_root(result: Any) -> np.ndarray | None:
    """A square root R (R R^T = covariance) of the fit's covariance over its varied parameters; None without one."""
    names = list(result.var_names)
    cov = getattr(result, "covar", None)
    if cov is None or np.shape(cov) != (len(names), len(names)) or not np.all(np.isfinite(cov)):
        return None
    values, vectors = np.linalg.eigh(0.5 * (cov + np.transpose(cov)))
    if not np.any(values > 0):
        return None
    return vectors * np.sqrt(np.clip(values, 0.0, None))


def _integrated_times(chain: np.ndarray) -> np.ndarray:
    """Each parameter's integrated autocorrelation time (steps) over the walkers of ``chain`` (steps, walkers,
    parameters); infinite where a walker never moved (emcee would divide by its zero variance)."""
    from emcee.autocorr import integrated_time

    out = np.full(chain.shape[2], np.inf)
    for k in range(chain.shape[2]):
        values = chain[:, :, k]
        if values.shape[0] > 1 and np.all(np.ptp(values, axis=0) > 0):
            out[k] = float(integrated_time(values[:, :, None], tol=0)[0])
    return out


def _posterior(
    residual: Any, result: Any, steps: int, seed: int | None, tempered: np.ndarray | None = None
) -> dict[str, Any]:  # fmt: skip
    """The emcee posterior of the fitted parameters (medians and 2.5/97.5 % percentiles, SI).

    The likelihood: Gaussian, each row's residual (the search's, times ``tempered`` per row) at the residuals' own
    scatter, each row counting 1/g of one for their correlation, as the least-squares intervals count them (the
    search's white noise at the steady sliding's level made a posterior 3x narrower than those intervals on a
    record with 731 effective rows of 30000); the change times' priors as in the search.  Sampled as ``fit steady
    --bayes`` samples: the walkers start drawn from the least-squares covariance about its answer, and half the
    moves are independence proposals from it, half differential evolution (lmfit's emcee started every walker
    within 1e-4 of each value, 10x narrower than a's interval and 300x wider than a change time's, with emcee's
    stretch move alone: 30 steps gave a 4x narrower interval for a, and one for Dc excluding the truth).  A chain
    shorter than MIXED_TIMES autocorrelation times after its burn-in (a third of the steps) has not mixed:
    ``converged`` is false, every ``interval`` is None (the percentiles stay as ``unconverged_percentiles``) and
    ``warning`` says so and about how many steps would do."""
    import emcee

    names = list(result.var_names)
    walkers = max(4 * len(names), 16)
    burn = int(steps) // 3
    rng = np.random.default_rng(seed)
    centre = np.array([float(result.params[n].value) for n in names])
    lower = np.array([float(result.params[n].min) for n in names])
    upper = np.array([float(result.params[n].max) for n in names])
    root = _covariance_root(result)
    trial = result.params.copy()

    def log_prob(x: np.ndarray) -> float:
        if not np.all((x > lower) & (x < upper)):
            return -np.inf
        for name, value in zip(names, x, strict=True):
            trial[name].value = float(value)
        r = np.asarray(residual(trial), dtype=float)
        if tempered is not None:
            r[: tempered.size] *= tempered
        total = float(np.dot(r, r))
        return -0.5 * total if math.isfinite(total) else -np.inf

    if root is None:  # no covariance: a small ball and differential evolution alone
        scale = 1e-4 * np.maximum(np.abs(centre), 1e-12)
        pos = centre + scale * rng.standard_normal((walkers, len(names)))
        moves: Any = [(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)]
        began = "a ball of 1e-4 of each value (the fit has no covariance), differential-evolution moves"
    else:
        pos = centre + rng.standard_normal((walkers, len(names))) @ root.T
        moves = [(emcee.moves.MHMove(_Independence(centre, root)), INDEPENDENCE_SHARE),
                 (emcee.moves.DEMove(), 1.0 - INDEPENDENCE_SHARE)]  # fmt: skip
        began = ("drawn from the least-squares covariance about the fit's answer; moves: independence proposals "
                 "from it (t, 10 degrees of freedom) and differential evolution")  # fmt: skip
    inside = (lower + 1e-9 * np.maximum(np.abs(centre), 1.0), upper - 1e-9 * np.maximum(np.abs(centre), 1.0))
    pos = np.clip(pos, *inside)  # (strictly inside: the prior is 0 on a bound)
    sampler = emcee.EnsembleSampler(walkers, len(names), log_prob, moves=moves)
    sampler.random_state = np.random.RandomState(int(rng.integers(2**31))).get_state()
    with np.errstate(over="ignore", invalid="ignore"):  # (a walker's model overflowing is a -inf, not a warning)
        sampler.run_mcmc(pos, int(steps))
    kept = int(steps) - burn
    chain = sampler.get_chain(discard=burn)
    tau = _integrated_times(chain)
    public = [j for j, key in enumerate(names) if key in _PUBLIC]  # (the change times' chains are nuisance)
    worst = float(np.max(tau[public])) if public else math.inf
    converged = math.isfinite(worst) and kept >= MIXED_TIMES * worst
    likelihood = ("Gaussian at the residuals' own scatter per sampling rate, each row counting 1/g of one (their "
                  "correlation), as the least-squares intervals count them" if tempered is not None else
                  "Gaussian at the search's noise")  # fmt: skip
    out: dict[str, Any] = {"steps": int(steps), "walkers": walkers, "burn": burn, "start": began,
                           "likelihood": likelihood,
                           "acceptance": float(np.mean(sampler.acceptance_fraction)),
                           "autocorrelation_time": {_PUBLIC[names[j]]: _finite_or_none(tau[j]) for j in public},
                           "converged": converged}  # fmt: skip
    if not converged:
        if math.isfinite(worst):
            need = math.ceil(1.5 * MIXED_TIMES * worst / 10.0) * 10
            short = (f"its {kept} steps after the burn-in ({burn}) are {kept / worst:.2g} autocorrelation times "
                     f"(up to {worst:.3g} steps), short of the {MIXED_TIMES} a mixed chain needs")  # fmt: skip
            more = f"; run --mcmc {need} or more ({MIXED_TIMES} autocorrelation times after a third's burn-in)"
        else:
            short, more = f"some walker did not move in the {kept} steps after the burn-in ({burn})", "; run more steps"
        out["warning"] = (
            f"NOT CONVERGED: {short}: the chain has not mixed, so its percentiles are no interval (too "
            f"narrow, or off centre) and none is given; the least-squares intervals stand{more}"
        )
    flat = chain.reshape(-1, len(names))
    for j in public:
        key = names[j]
        values = np.exp(flat[:, j]) if key.startswith("log_") else flat[:, j]
        lo, med, hi = np.percentile(values, [2.5, 50, 97.5])
        entry: dict[str, Any] = {"median": float(med), "interval": [float(lo), float(hi)] if converged else None}
        if not converged:
            entry["unconverged_percentiles"] = [float(lo), float(hi)]
        out[_PUBLIC[key]] = entry
    return out


def _finite_or_none(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def _exp(x: float) -> float:
    """exp that reports an interval end beyond the float range as inf (shown as unbounded), not OverflowError."""
    return math.exp(x) if x < 709.0 else math.inf
