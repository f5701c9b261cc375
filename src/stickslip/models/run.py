"""One result type for every model: :class:`Run` (the trace with units, and what it settled into).

Columns (SI): ``time`` (s), ``stress`` (Pa; the friction stress, where the model has one), ``friction``
(mu = stress / normal stress, where a normal stress exists), ``slider_velocity`` (m/s), ``slider_position`` (m),
``load_point_position`` (m), then the model's own state columns with their units.  ``regime`` is a
:class:`stickslip.regimes.Regime` from the one classifier, given by the model from its dense solution (its
interpolant, or exact events); a Run built from a trace alone is classified on that trace.
"""

from __future__ import annotations

import io
import json
import math
import os
import weakref
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import regimes
from ..errors import DataError, ParameterError
from ..reprs import compact_repr

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    from matplotlib.axes import Axes

__all__ = ["BASE_COLUMNS", "Run", "finished", "settled_mean", "time_mean"]

#: The columns every run has (``stress`` or ``friction`` may be absent), in order, with their SI units.
BASE_COLUMNS: dict[str, str | None] = {
    "time": "s",
    "stress": "Pa",
    "friction": "1",
    "slider_velocity": "m/s",
    "slider_position": "m",
    "load_point_position": "m",
}
#: The first line of a Run CSV: a comment the trace readers skip, holding what the columns cannot.
CSV_MARK = "# stickslip run "
#: a run's status: finished, failed (the model could not go on), stopped (at its budget: the run up to there)
STATUSES = ("ok", "failed", "stopped")


def recorded_status(path: str | Path) -> tuple[str, str]:
    """(status, message) a run trace written by :meth:`Run.to_csv` records in its first line; ("ok", "") for any
    other file, and for one that is not a regular file (a FIFO is read once, by the reader of its rows)."""
    path = Path(path)
    if not path.is_file():
        return "ok", ""
    from ..tables import open_input  # a gzipped trace too, as its rows are read (a failed run read as "ok")

    try:
        with open_input(path, "r", encoding="utf-8", errors="replace") as handle:
            first = handle.readline(1 << 20)
    except (OSError, EOFError, DataError):  # a damaged gzip file: its reader refuses it in one line
        return "ok", ""
    if not first.startswith(CSV_MARK):
        return "ok", ""
    try:
        meta = json.loads(first[len(CSV_MARK) :])
    except ValueError:
        return "ok", ""
    status = meta.get("status", "ok") if isinstance(meta, dict) else "ok"
    return (str(status), str(meta.get("message", ""))) if status != "ok" else ("ok", "")


NAN = float("nan")


def time_mean(time: np.ndarray, values: np.ndarray) -> float:
    """Time average by the trapezoidal rule (the last value for a single instant; NaN for none)."""
    span = float(time[-1] - time[0]) if time.size else 0.0
    if span <= 0:
        return float(values[-1]) if values.size else NAN
    # each interval's share of the span first: dt x value overflowed for a 1e300 s run (a stuck block's
    # 3e299 Pa after 1e300 s is the model's answer, and so is its mean)
    share = np.diff(time) / span
    return float(np.sum(share * (0.5 * values[1:] + 0.5 * values[:-1])))


def settled_mean(time: np.ndarray, values: np.ndarray, period: float, begin: float | None = None) -> float:
    """Mean over what the run settled into: the last whole periods within the second half of the window from
    ``begin`` (the protocol's last segment, whose regime is reported; the run's start by default) to the end, or
    over that half if it does not oscillate.  Steady, that is the settled value (a slide-hold-slide's mean over
    the run's second half held the hold's end: 0.576136 for the steady 0.576974)."""
    first = float(time[0])
    begin = first if begin is None or not math.isfinite(begin) else min(max(float(begin), first), float(time[-1]))
    return window_mean(time, values, regimes.settled_window_start(begin, float(time[-1]), period))


def window_mean(time: np.ndarray, values: np.ndarray, start: float) -> float:
    """Time average from ``start`` to the last row, the trace interpolated linearly to ``start`` (the window
    starts where it says, not at the next row: the mean must not depend on how the output is sampled)."""
    if not time.size or start <= float(time[0]):
        return time_mean(time, values)
    inside = time > start
    return time_mean(np.r_[start, time[inside]], np.r_[_value_from(time, values, start), values[inside]])


def _value_from(time: np.ndarray, values: np.ndarray, start: float) -> float:
    """The trace's value at ``start`` as the window from there sees it: at a time written more than once (a segment
    boundary: the old segment's value, then the new one's) the last sample, else linear interpolation."""
    j = int(np.searchsorted(time, start, side="right"))
    if j > 0 and time[j - 1] == start:
        return float(values[j - 1])
    return float(np.interp(start, time, values))


def segment_window(
    time: np.ndarray, signal: np.ndarray, start: float | None
) -> tuple[np.ndarray, np.ndarray, float | None]:
    """(time, signal, start) of the window ``t >= start`` that a segment starting at ``start`` reads, right-continuous
    at its start: where the trace holds several samples at the boundary (within :data:`END_TOLERANCE` of the run's
    length, at least 1 ns; a model solved segment by segment writes the boundary twice, the old segment's last value
    then the new one's first), only the last of them is kept, and the window starts at it.

    A velocity step under velocity control with a direct effect jumps the stress at the boundary: the window took in
    the hold's last value, and a re-slide that never fell below 1092.2 Pa reported "lowest 1000.3 Pa" (round-30
    tester).  A single sample at the boundary is kept as it is (a continuous signal's value there)."""
    if start is None or time.size < 2:
        return time, signal, start
    tolerance = END_TOLERANCE * max(abs(float(time[-1])), abs(float(start)), 1.0)
    near = np.flatnonzero(np.abs(time - start) <= tolerance)
    if near.size < 2:
        return time, signal, start
    keep = np.ones(time.size, dtype=bool)
    keep[near[:-1]] = False
    return time[keep], signal[keep], min(float(start), float(time[near[-1]]))


def _column(values: Any, name: str, size: int | None) -> np.ndarray:
    text = np.asarray(values).dtype.kind in "OUS"
    array = np.asarray(values, dtype=object) if text else np.asarray(values, dtype=float)
    if array.ndim != 1:
        raise ParameterError(f"run column {name}: expected one value per time, got an array of shape {array.shape}")
    if size is not None and array.size != size:
        raise ParameterError(f"run column {name}: {array.size} values for {size} times")
    return _read_only(array)


def _read_only(array: np.ndarray) -> np.ndarray:
    """``array`` frozen as a Run holds it: a read-only view (the caller's own array, that np.asarray may have passed
    through, stays writable; ``np.array(run.time)`` or ``run.time.copy()`` is a writable copy)."""
    if array.flags.writeable:
        array = array.view()
        array.setflags(write=False)
    return array


def _trace_arrays(time: Any, stress: Any, friction: Any) -> tuple[np.ndarray, np.ndarray]:
    """``time`` and the classified signal as float arrays, checked before anything is computed from them:
    one row per time, at least one row, times finite and never going back (a raw numpy error otherwise)."""
    if stress is None and friction is None:
        raise ParameterError("Run.from_trace: expected stress= or friction=, got neither")
    try:
        t = np.asarray(time, dtype=float)
        signal = np.asarray(stress if stress is not None else friction, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError("Run.from_trace: expected time and stress (or friction) as arrays of numbers") from None
    name = "stress" if stress is not None else "friction"
    if t.ndim != 1 or signal.ndim != 1:
        raise ParameterError(f"Run.from_trace: expected one-dimensional time and {name}, got shapes {t.shape}, "
                             f"{signal.shape}")  # fmt: skip
    if t.size == 0:
        raise ParameterError("Run.from_trace: time is empty; a run has at least one row")
    if signal.size != t.size:
        raise ParameterError(f"Run.from_trace: {signal.size} {name} values for {t.size} times; expected one per time")
    if not np.all(np.isfinite(t)):
        raise ParameterError(f"Run.from_trace: time holds a non-finite value at row {int(np.argmin(np.isfinite(t)))}")
    if np.any(np.diff(t) < 0):
        raise ParameterError(f"Run.from_trace: time goes back at row {int(np.argmax(np.diff(t) < 0)) + 1}")
    return t, signal


def _first_non_finite(columns: Mapping[str, Any], size: int) -> tuple[int, str] | None:
    """(row, column) of the first non-finite value among ``columns`` (the earliest row; None where all are finite).
    A column of another length is left to :class:`Run`'s own check, which names it."""
    first: tuple[int, str] | None = None
    for name, values in columns.items():
        if values is None:
            continue
        try:
            array = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            continue
        if array.shape != (size,):
            continue
        finite = np.isfinite(array)
        if not finite.all():
            row = int(np.argmin(finite))
            if first is None or row < first[0]:
                first = (row, name)
    return first


def _no_verdict(signal: np.ndarray, evidence: str) -> regimes.Regime:
    """The regime of a run that did not reach its protocol's end: undetermined, no periods, the trace's extremes."""
    return regimes.Regime(regimes.UNDETERMINED, 0, NAN, NAN, float(np.max(signal)), float(np.min(signal)), evidence)


def _failed_at(
    model: str,
    time: np.ndarray,
    columns: Mapping[str, Any],
    bad: tuple[int, str],
    states: Mapping[str, Any] | None,
    state_units: Mapping[str, str | None] | None,
    extra: Mapping[str, Any],
) -> Run:
    """A model's trace with a non-finite value (a plug-in's NaN or inf) as a failed run of the rows before it: a NaN
    written as an empty cell and a "steady" regime of the rows around it hid it (round-25 tester)."""
    from ..errors import RunFailed

    row, name = bad
    where = f"{model}: its {name} is not finite at row {row} (t = {time[row]:.6g} s)"
    if row == 0:
        raise RunFailed(f"{where}, its first: the model computed nothing to keep")
    kept = {key: None if values is None else np.asarray(values, dtype=float)[:row] for key, values in columns.items()}
    signal = kept["stress"] if kept["stress"] is not None else kept["friction"]
    message = f"{where}; the run is kept up to t = {time[row - 1]:.6g} s"
    regime = _no_verdict(signal, f"of the run up to its failure: {message}")
    base = {key: kept[key] for key in BASE_COLUMNS if key != "time"}
    others = {key: value for key, value in extra.items() if key not in ("status", "message", "mean")}
    others["mean"] = time_mean(time[:row], signal) if row > 1 else float(signal[0])
    return Run(model=model, time=time[:row], **base, regime=regime,
               states={key: kept[key] for key in (states or {})}, state_units=state_units or {},
               status="failed", message=message, **others)  # fmt: skip


#: a trace that ends this fraction of the protocol's length (at least 1 ns) short of its end ended early
END_TOLERANCE = 1e-9


def finished(run: Run, protocol: Any) -> Run:
    """``run`` as the model interface reports it: a run whose trace ends before ``protocol`` does, while the model
    called it "ok", is a failed run of what it computed (a plug-in's solver that stopped at t = 0 of 1 s read
    "undetermined: too short to tell" with exit 0).  A finished run that :meth:`Run.from_trace` classified over
    its whole trace is classified over ``protocol``'s last segment (:func:`in_last_segment`).  The command line,
    sweeps, compare and :func:`stickslip.models.run` pass every run through here."""
    if run.status != "ok" or protocol is None:
        return run
    end, reached = float(protocol.duration), float(run.time[-1])
    if reached >= end - END_TOLERANCE * max(end, 1.0):
        return in_last_segment(run, protocol)
    from dataclasses import replace

    message = (f"{run.model}: the model stopped at t = {reached:.6g} s of the protocol's {end:.6g} s without saying"
               " why (its trace ends there)")  # fmt: skip
    return replace(run, status="failed", message=message)


#: the relative tolerance of a trace whose model states none (``Run.from_trace`` without ``floor``): changes below
#: this fraction of the window's largest |signal| are no change.  scipy's ``solve_ivp`` at its defaults (RK45, rtol
#: 1e-3) ends a relaxation that has long settled with steps that still move it by up to 1e-3 of the scale (0.998e-3
#: the worst of 96 settled lags), which 1e-9 read as still changing, or as periods (docs/regimes.md, "A plug-in's
#: tolerance and window")
TRACE_TOLERANCE = 1e-3

#: the Runs :meth:`Run.from_trace` classified over the whole trace, knowing no protocol: (floor as given, dense,
#: whether the model gave its mean), for :func:`in_last_segment` (weak keys: a Run copied or pickled has none)
_WHOLE_TRACE: weakref.WeakKeyDictionary[Run, tuple[float | None, Any, bool]] = weakref.WeakKeyDictionary()


def last_segment_start(protocol: Any) -> float:
    """Where ``protocol``'s last segment starts (s): the window whose regime a run reports (0 for one segment)."""
    from ..protocols import Protocol

    if not isinstance(protocol, Protocol):
        raise ParameterError(f"protocol: expected a stickslip.protocols.Protocol, got {type(protocol).__name__}")
    return float(protocol.boundaries[-2])


def in_last_segment(run: Run, protocol: Any) -> Run:
    """``run`` classified, and its mean taken, over ``protocol``'s last segment, as every built-in model reports:
    for a Run that :meth:`Run.from_trace` classified over its whole trace (a plug-in that gave neither ``start`` nor
    ``protocol``); any other Run as it is.  A lag model stepped 100 -> 1000 -> 100 µm/s (20 ms each, relaxation time
    2 ms) reported the mean of the whole run, 346.0 Pa, for the 300.154 Pa of its last segment's settled half."""
    whole = _WHOLE_TRACE.get(run)
    if whole is None or protocol is None:
        return run
    begin = last_segment_start(protocol)
    if not begin > float(run.time[0]):
        return run
    from dataclasses import replace

    floor, dense, mean_given = whole
    regime = _classified(run.time, run.signal, floor, begin, dense, run.signal_unit)
    mean = run.mean if mean_given else settled_mean(run.time, run.signal, regime.period, begin)
    return replace(run, regime=regime, mean=mean)


def trace_floor(time: np.ndarray, signal: np.ndarray, start: float | None) -> float:
    """The default ``floor`` of :meth:`Run.from_trace`: :data:`TRACE_TOLERANCE` of the largest |signal| at
    ``t >= start`` (the classified window)."""
    inside = np.isfinite(signal) & (time >= (time[0] if start is None else start))
    scale = float(np.max(np.abs(signal[inside]), initial=0.0))
    return TRACE_TOLERANCE * scale if scale > 0 else 1e-300


def _classified(
    time: np.ndarray,
    signal: np.ndarray,
    floor: float | None,
    start: float | None,
    dense: regimes.Dense | None,
    unit: str,
) -> regimes.Regime:
    """The classifier's verdict on a trace over ``t >= start``, its words in ``unit`` (Pa; none for friction); at a
    boundary written twice, over the samples of the window's own segment (:func:`segment_window`)."""
    time, signal, start = segment_window(time, signal, start)
    floor = trace_floor(time, signal, start) if floor is None else floor
    return regimes.classify(time, signal, floor=floor, start=start, dense=dense, unit="" if unit == "1" else unit)


@dataclass(frozen=True, eq=False)  # arrays: equality is not a truth value; compare columns instead
class Run:
    """A model run: the trace (SI, one row per solver output), its regime, and its summary numbers.

    ``period``, ``peak``, ``trough`` come from ``regime`` (the settled cycle's, or the window's extremes when
    it does not oscillate); ``mean`` is the model's mean over the settled cycle.  ``summary`` holds the model's
    own scalar results (e.g. ``stick_time``), ``native`` the model's own result object (not compared, not
    written).  ``status`` is "ok", "failed" (the model could not go on) or "stopped" (at its step or CPU budget:
    the run up to there); ``message`` says why.
    """

    __repr__ = compact_repr  # counts, not hundreds of array elements

    model: str
    time: np.ndarray
    stress: np.ndarray | None
    friction: np.ndarray | None
    slider_velocity: np.ndarray
    slider_position: np.ndarray
    load_point_position: np.ndarray
    regime: regimes.Regime
    mean: float = NAN
    states: Mapping[str, np.ndarray] = field(default_factory=dict)
    state_units: Mapping[str, str | None] = field(default_factory=dict)
    summary: Mapping[str, Any] = field(default_factory=dict)
    message: str = ""
    status: str = "ok"
    native: Any = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        time = _column(self.time, "time", None)
        object.__setattr__(self, "time", time)
        for name in ("stress", "friction"):
            value = getattr(self, name)
            object.__setattr__(self, name, None if value is None else _column(value, name, time.size))
        if self.stress is None and self.friction is None:
            raise ParameterError("run: expected a stress or a friction column, got neither")
        for name in ("slider_velocity", "slider_position", "load_point_position"):
            object.__setattr__(self, name, _column(getattr(self, name), name, time.size))
        states = {str(k): _column(v, str(k), time.size) for k, v in self.states.items()}
        clash = sorted(set(states) & set(BASE_COLUMNS))
        if clash:
            raise ParameterError(f"run state column {clash[0]!r}: the name of a base column; name it otherwise")
        object.__setattr__(self, "states", states)
        object.__setattr__(self, "state_units", {k: self.state_units.get(k) for k in states})
        if not isinstance(self.regime, regimes.Regime):
            raise ParameterError(f"run regime: expected a stickslip.regimes.Regime, got {type(self.regime).__name__}")
        if self.status not in STATUSES:
            raise ParameterError(f"run status: expected one of {', '.join(map(repr, STATUSES))}, got {self.status!r}")

    def __setstate__(self, state: dict[str, Any]) -> None:
        """Unpickled with its columns read-only again (numpy's pickle gives back writable arrays)."""
        for name in ("time", "stress", "friction", "slider_velocity", "slider_position", "load_point_position"):
            if state.get(name) is not None:
                state[name] = _read_only(state[name])
        state["states"] = {k: _read_only(v) for k, v in state.get("states", {}).items()}
        self.__dict__.update(state)

    # ---------------------------------------------------------------- building
    @classmethod
    def from_trace(
        cls,
        model: str,
        time: Any,
        *,
        stress: Any = None,
        friction: Any = None,
        slider_velocity: Any,
        slider_position: Any,
        load_point_position: Any,
        states: Mapping[str, Any] | None = None,
        state_units: Mapping[str, str | None] | None = None,
        regime: regimes.Regime | None = None,
        floor: float | None = None,
        dense: regimes.Dense | None = None,
        start: float | None = None,
        protocol: Any = None,
        **extra: Any,
    ) -> Run:
        """A Run from the model's solution; without ``regime`` it is classified on the stress (or friction)
        by :func:`stickslip.regimes.classify`, with ``dense`` the solver's interpolant of that signal if there is
        one, over ``t >= start``, changes below ``floor`` counting as none; ``mean`` is taken over the settled part
        of that window.

        ``start`` (s): default the start of ``protocol``'s last segment, the window every built-in model reports;
        with neither, the whole trace, which the interface that ran the model (:func:`stickslip.run`, the command
        line, sweeps, compare: :func:`finished`) classifies again over the protocol's last segment.
        ``floor``: the model's accuracy in the signal's unit (Pa, or 1 for friction): changes and swings at or below
        it are no change; default :data:`TRACE_TOLERANCE` (1e-3) of the window's largest |signal|, the accuracy of
        scipy's ``solve_ivp`` at its defaults.  A model whose solver is more accurate says so here."""
        if start is None and protocol is not None:
            start = last_segment_start(protocol)
        t, signal = _trace_arrays(time, stress, friction)
        columns = {"stress": stress, "friction": friction, "slider_velocity": slider_velocity,
                   "slider_position": slider_position, "load_point_position": load_point_position,
                   **(states or {})}  # fmt: skip
        # the base columns only: a model's state may be undefined at times (the stick chains' fraction while they
        # do not hold is empty), and a run the model already calls failed or stopped is kept as it wrote it
        checked = {key: columns[key] for key in BASE_COLUMNS if key in columns}
        bad = _first_non_finite(checked, t.size) if extra.get("status", "ok") == "ok" else None
        if bad is not None:  # what the model computed up to there is kept, and the run is a failed one (exit 3)
            return _failed_at(model, t, columns, bad, states, state_units, extra)
        if regime is None and extra.get("status", "ok") != "ok":  # a run that did not finish has no verdict
            regime = _no_verdict(signal, f"of the run up to its {extra['status']} end: {extra.get('message', '')}")
        whole = regime is None and start is None  # classified here knowing no protocol: see in_last_segment
        if regime is None:
            regime = _classified(t, signal, floor, start, dense, "Pa" if stress is not None else "1")
        run = cls(
            model=model, time=t, stress=stress, friction=friction, slider_velocity=slider_velocity,
            slider_position=slider_position, load_point_position=load_point_position, regime=regime,
            states=states or {}, state_units=state_units or {}, **extra,
        )  # fmt: skip
        if "mean" not in extra and t.size:  # over the settled part of the classified window (t >= start)
            object.__setattr__(run, "mean", settled_mean(t, run.signal, regime.period, start))
        if whole:
            _WHOLE_TRACE[run] = (floor, dense, "mean" in extra)
        return run

    # ---------------------------------------------------------------- what it settled into
    @property
    def signal(self) -> np.ndarray:
        """The classified signal: the stress where there is one, else the friction coefficient."""
        return self.stress if self.stress is not None else self.friction  # type: ignore[return-value]

    @property
    def signal_name(self) -> str:
        return "stress" if self.stress is not None else "friction"

    @property
    def signal_unit(self) -> str:
        return "Pa" if self.stress is not None else "1"

    @property
    def period(self) -> float:
        return float(self.regime.period)

    @property
    def peak(self) -> float:
        return float(self.regime.peak)

    @property
    def trough(self) -> float:
        return float(self.regime.trough)

    @property
    def regime_name(self) -> str:
        """The regime as the model names it (rate-and-state keeps "steady sliding")."""
        return str(self.summary.get("regime", self.regime.kind))

    def row(self, columns: Mapping[str, str]) -> dict[str, Any]:
        """One sweep row: each of ``columns`` (name -> kind) from the model's summary, else from the Run."""
        # a run that settled (or never moved) had no stick-slip cycles, whatever oscillation decayed on the way
        cycles = 0 if self.regime.kind in (regimes.STEADY, regimes.STUCK) else self.regime.periods
        # a row's peak and trough are a cycle's (docs/sweep.md: "NaN if the block never slips"): a steady run's
        # window extremes (its start-up, or its steady value) read as a stick's peak stress beside the cycles' ones
        peak, trough = (self.peak, self.trough) if cycles > 0 else (NAN, NAN)
        generic = {
            "regime": self.regime_name,
            "period": self.period,
            "peak_stress": peak if self.stress is not None else NAN,
            "trough_stress": trough if self.stress is not None else NAN,
            "mean_stress": self.mean if self.stress is not None else NAN,
            "peak_friction": peak if self.stress is None else NAN,
            "trough_friction": trough if self.stress is None else NAN,
            "mean_friction": self.mean if self.stress is None else NAN,
            "growth": self.regime.amplitude_ratio,
            "cycles": cycles,
        }
        row: dict[str, Any] = {}
        for name, kind in columns.items():
            if name in self.summary:
                row[name] = self.summary[name]
            elif name in generic:
                row[name] = generic[name]
            else:
                row[name] = None if kind == "str" else 0 if kind == "int" else NAN
        row["message"] = self.message or self.regime.evidence
        row["status"] = self.status  # a run the model could not finish is "failed", its numbers what it computed
        return row

    # ---------------------------------------------------------------- tables and files
    @property
    def units(self) -> dict[str, str | None]:
        return {**BASE_COLUMNS, **self.state_units}

    def to_frame(self) -> pd.DataFrame:
        """The trace as a DataFrame, ``attrs["units"]`` naming every column's unit."""
        import pandas as pd

        from ..columns import with_units

        columns = {name: getattr(self, name) for name in BASE_COLUMNS if getattr(self, name) is not None}
        columns.update(self.states)
        return with_units(pd.DataFrame(columns), extra=self.units)

    def metadata(self) -> dict[str, Any]:
        """What the columns cannot hold: the model, the regime and its evidence, the summary."""
        from ..columns import json_safe

        r = self.regime
        return json_safe({
            "model": self.model, "status": self.status, "message": self.message, "mean": self.mean,
            "units": f"SI; regime period s, peak, trough and mean in {self.signal_unit} (the {self.signal_name})",
            "regime": {"kind": r.kind, "periods": r.periods, "amplitude_ratio": r.amplitude_ratio,
                       "period": r.period, "peak": r.peak, "trough": r.trough, "evidence": r.evidence},
            "summary": dict(self.summary),
        })  # fmt: skip

    def to_csv(self, path: str | Path) -> Path:
        """Write the trace as CSV (units in the header, numbers at 15 significant digits:
        :func:`stickslip.columns.csv_number`), the regime in a first comment line (every digit).

        Written atomically (a symlink's target, a FIFO or a device as it is); ``stickslip analyze`` reads it
        as a measured trace, :meth:`read` as a Run.
        """
        from ..columns import csv_text
        from ..fileio import atomic_write_text

        head = CSV_MARK + json.dumps(self.metadata(), separators=(",", ":"), allow_nan=False) + "\n"
        return atomic_write_text(path, head + csv_text(self.to_frame()))

    @classmethod
    def read(cls, path: str | Path) -> Run:
        """A Run from a CSV written by :meth:`to_csv` (any other trace with the base columns is classified anew)."""
        import pandas as pd

        from ..columns import split_header
        from ..fileio import read_input_text

        if not isinstance(path, (str, os.PathLike)):
            raise DataError(f"run file: expected a path, got {type(path).__name__}")
        text = read_input_text(path, f"run file {path}", 1 << 31)
        first, _, body = text.partition("\n")
        meta: dict[str, Any] = {}
        if first.startswith(CSV_MARK):
            try:
                meta = json.loads(first[len(CSV_MARK) :], parse_constant=lambda _: NAN)
            except ValueError:
                raise DataError(f"{path}: row 1: the run's metadata line is not valid JSON") from None
        else:
            body = text

        try:
            frame = pd.read_csv(io.StringIO(body), comment=None)
        except (ValueError, pd.errors.ParserError) as exc:
            raise DataError(f"{path}: not a CSV run trace ({str(exc).splitlines()[0]})") from None
        names = {}
        units = {}
        for cell in frame.columns:
            name, unit = split_header(str(cell))
            names[cell] = name
            units[name] = unit
        frame = frame.rename(columns=names)
        for need in ("time", "slider_velocity", "slider_position", "load_point_position"):
            if need not in frame:
                raise DataError(f"{path}: missing column {need!r}; a run trace has {', '.join(BASE_COLUMNS)}")
        for name, unit in units.items():
            if name in BASE_COLUMNS and unit != BASE_COLUMNS[name]:
                raise DataError(f"{path}: column {name!r} in [{unit}]; a run trace holds it in [{BASE_COLUMNS[name]}]")
        states = {n: frame[n].to_numpy() for n in frame.columns if n not in BASE_COLUMNS}
        regime = None
        if "regime" in meta:
            r = meta["regime"]
            regime = regimes.Regime(
                r["kind"], int(r["periods"]), _number(r["amplitude_ratio"]), _number(r["period"]), _number(r["peak"]),
                _number(r["trough"]), r["evidence"],
            )  # fmt: skip
        summary = {k: NAN if v is None else v for k, v in meta.get("summary", {}).items()}
        extra: dict[str, Any] = {"summary": summary, "message": meta.get("message", "")}
        extra["status"] = meta.get("status", "ok")
        if "mean" in meta:
            extra["mean"] = _number(meta["mean"])
        number = {n: _floats(frame, n, path) for n in BASE_COLUMNS if n in frame}
        return cls.from_trace(
            meta.get("model", "trace"), number["time"], stress=number.get("stress"), friction=number.get("friction"),
            slider_velocity=number["slider_velocity"], slider_position=number["slider_position"],
            load_point_position=number["load_point_position"],
            states=states, state_units={n: units[n] for n in states}, regime=regime, **extra,
        )  # fmt: skip

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        """Stress (or friction) against time, the slider velocity on a twin axis; returns the Axes."""
        from ..plots.run import plot_run

        return plot_run(self, ax=ax, **kwargs)


def _floats(frame: pd.DataFrame, name: str, path: str | Path) -> np.ndarray:
    import pandas as pd

    values = pd.to_numeric(frame[name], errors="coerce").to_numpy(dtype=float)
    bad = np.flatnonzero(np.isnan(values) & frame[name].notna().to_numpy())
    if bad.size:
        raise DataError(f"{path}: column {name!r}: not a number in data row {bad[0] + 1}: {frame[name].iloc[bad[0]]!r}")
    return values


def _number(value: Any) -> float:
    return NAN if value is None else float(value)
