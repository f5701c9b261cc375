"""Per-cycle characteristics of a measured stick-slip record (the rows of Table 1).

Each stick phase found by :mod:`.detect` is fitted by a straight line (Eq 12) whose ends are located by hinge fits
(:mod:`.fits`); the cycle's stresses, times, slope, stiffness and jump velocity are read off them
(docs/analysis.md).  A cycle is one stick and the slip that follows; what the record does not contain is None and
the cycle is ``complete=False``.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import regimes
from ..columns import with_units
from ..errors import DataError, ParameterError
from ..parameters import Parameters, load_parameters
from ..reprs import compact_repr
from .detect import (
    GAP_STEPS,
    MEDIAN_WIDTH,
    MIN_ASYMMETRY,
    Coarse,
    coarse_segments,
    coarse_spacing,
    dropouts,
    gaps,
    rise_start,
    sampling_step,
    unresolved_swings,
)
from .fits import QUADRATIC, Corner, Line, fit_corner, fit_line, with_time_uncertainty
from .steady import integrated_time, mean_and_error, settled_start
from .traces import Trace, check_trace

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    from matplotlib.axes import Axes

#: Slip-side window at the end corner: at most this fraction of the stress drop ...
BRANCH_FRACTION = 0.25
#: ... and at most this fraction of the slip's duration.
BRANCH_TIME_FRACTION = 0.25
#: A sample this many noise levels off the stick line belongs to a slip.
DEVIATION_SIGMAS = 5.0
#: Slip-side window at the start corner (fractions of the drop and of the slip time) and its shape.
START_FRACTION = 0.35
START_TIME_FRACTION = 0.35
START_POWERS: tuple[float, ...] | None = QUADRATIC
#: Fraction of the stick phase used on the stick side of a hinge fit.
STICK_WINDOW = 0.3
#: Margin excluded at each real corner from the stick-line regression (fraction of the phase).
LINE_MARGIN = 0.05
#: R^2 above which a record without slips is one linear stick rise ("stuck").
STUCK_R2 = 0.9
#: A record whose stress swings up and down with drops (nearly) all as slow as its rises is a smooth oscillation,
#: not stick-slip (no slip phase): ``regimes.DECAYING`` or ``regimes.GROWING`` when its peak-to-trough amplitude
#: changes from period to period by more than ``regimes.RATIO_TOLERANCE`` (and by more than three standard errors
#: of its trend), this when it does not.
OSCILLATION = regimes.OSCILLATION
#: An oscillation's amplitude trend is judged on at least this many swings (regimes.RATIOS_NEEDED ratios).
TREND_SWINGS = regimes.RATIOS_NEEDED + 1
#: ... and counts when the fitted ratio per period is this many standard errors from 1.
TREND_SIGMAS = 3.0

#: The per-cycle quantities summarised by mean and standard deviation, with their SI units.
CYCLE_QUANTITIES = {
    "critical_stress": "Pa",
    "stick_slope": "Pa/s",
    "stiffness": "Pa/m",
    "peak_stress": "Pa",
    "stick_time": "s",
    "jump_velocity": "m/s",
    "slip_time": "s",
    "period": "s",
    "stress_drop": "Pa",
}
#: Of those, the stick line's: its slope (and Gd/h from it) is measured on a stick cut by the record or a gap too,
#: the same in a start-up stick as in the limit cycle (the elastic loading K*V0), so their summary is over every
#: stick line.  The others are read at corners that a cut cycle lacks or does not have as a repeat of the cycle (a
#: start-up stick from rest ages longer, to a higher sigma_s and a faster, longer slip): their summary is over the
#: complete cycles alone (SUMMARY_LEFT_OUT says which and why).
LINE_QUANTITIES = ("stick_slope", "stiffness")


#: Per-cycle quantities that come from the model, not from the record: field -> how (they change with the
#: parameter set, e.g. ``--set bonds.bond_time=...``; every other quantity is read off the record alone).
MODEL_DERIVED = {
    "jump_velocity": "model-derived, not measured: where the bond model's aging steady curve (Eq 8) carries the "
    "measured peak stress σs; it changes with the parameter set",
}

#: Units of the CycleResult fields particular to the analysis (the package's registry, stickslip.columns, has the
#: others): the JSON's "units" and :meth:`TraceAnalysis.to_frame` name them.
CYCLE_UNITS: dict[str, str | None] = {
    "slip_time_bound": "s",
    "stick_curvature": "Pa/s^2",
    "stick_curvature_stderr": "Pa/s^2",
    "stick_sagitta": "Pa",
    "stick_curved": None,  # a flag
}

#: CycleResult fields kept for plotting, not reported.
_PRIVATE_FIELDS = ("line", "stick_from", "stick_to")


@dataclass(frozen=True)
class CycleResult:
    """One stick phase and the slip after it (SI units; None where the record does not show it)."""

    index: int
    complete: bool
    start_time: float | None
    peak_time: float | None
    end_time: float | None
    critical_stress: float | None
    stick_slope: float | None
    stick_slope_stderr: float | None
    stiffness: float | None
    stiffness_stderr: float | None
    peak_stress: float | None
    stick_time: float | None
    jump_velocity: float | None
    slip_time: float | None
    period: float | None
    stress_drop: float | None
    stick_points: int
    stick_rms: float | None
    #: the systematic uncertainty of sigma_c, sigma_s (Pa) and t_s (s) from how the corners are located, apart from
    #: the scatter the noise gives them: the same in every repeat of one cycle (fits.Corner.time_uncertainty)
    critical_stress_uncertainty: float | None
    peak_stress_uncertainty: float | None
    stick_time_uncertainty: float | None
    message: str = ""
    #: where the drop falls between two samples (none lies off both stick lines, :func:`_unresolved_slips`): the
    #: slip lasts less than this (s), the sampling interval that holds it.  Both corners are then at the middle of
    #: that interval, so ``slip_time`` is 0, no measurement, and σs and the next σc are known to their resolution
    #: (``peak_stress_uncertainty``, ``critical_stress_uncertainty``: the stick slope times half the interval)
    slip_time_bound: float | None = None
    #: the stick's curvature (Pa/s^2, d2sigma/dt2 of a parabola fitted to the stick between its corners; 0 for the
    #: model's straight stick), its standard error under the record's correlated noise, the parabola's largest
    #: departure from the straight line over the stick (Pa, the sagitta: curvature * stick time^2 / 8), and whether
    #: the stick is curved beyond its noise (:data:`CURVE_SIGMAS` standard errors and :data:`CURVE_NOISE` noise
    #: levels): then σc and σs are read on the parabola's tangent at each corner (docs/analysis.md, "Curved sticks")
    stick_curvature: float | None = None
    stick_curvature_stderr: float | None = None
    stick_sagitta: float | None = None
    stick_curved: bool = False
    line: Line | None = field(default=None, repr=False, compare=False)
    stick_from: float = field(default=math.nan, repr=False, compare=False)
    stick_to: float = field(default=math.nan, repr=False, compare=False)

    def as_dict(self) -> dict[str, Any]:
        data = asdict(self)
        for key in _PRIVATE_FIELDS:
            data.pop(key)
        return data


@dataclass(frozen=True)
class TraceAnalysis:
    """Result of :func:`analyze_trace`: the regime, the cycles and their summary."""

    __repr__ = compact_repr  # counts, not hundreds of array elements

    time: np.ndarray
    stress: np.ndarray
    pulling_velocity: float
    #: "stick-slip" | "steady" | "stuck" | "oscillation" | "decaying oscillation" | "growing oscillation" |
    #: "undetermined" (slips, but no whole stick phase: too short a record to tell stick-slip from a transient)
    regime: str
    message: str
    cycles: tuple[CycleResult, ...]
    summary: dict[str, Any]
    noise: float
    threshold: float
    steady_from: float | None
    parameters: Parameters = field(repr=False)
    source: str = "trace"
    #: what the analysis did to the record, or found in it, that a reader of the cycles must know: dropouts
    #: removed, gaps the record was cut at, stick slopes that change within the record (one V0 assumed)
    warnings: tuple[str, ...] = ()

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (SI units)."""
        return {
            "source": self.source,
            "regime": self.regime,
            "message": self.message,
            "warnings": list(self.warnings),
            "pulling_velocity": self.pulling_velocity,
            "noise": self.noise,
            "drop_threshold": self.threshold,
            "cycles": [c.as_dict() for c in self.cycles],
            "summary": self.summary,
            "model_derived": dict(MODEL_DERIVED),
            "parameter_set": self.parameters.name,  # the set Vs and Gd/h's block geometry come from
        }

    def to_frame(self) -> pd.DataFrame:
        """One row per cycle."""
        import pandas as pd

        columns = [name for name in CycleResult.__dataclass_fields__ if name not in _PRIVATE_FIELDS]
        frame = pd.DataFrame([c.as_dict() for c in self.cycles], columns=columns)
        return with_units(frame, CYCLE_UNITS)

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        from ..plots.traces import plot_analysis

        return plot_analysis(self, ax=ax, **kwargs)


@dataclass
class _Stick:
    """Working record of one stick phase while it is being fitted."""

    start_guess: float | None
    end_guess: float | None
    prev_peak: tuple[float, float] | None  # coarse (time, level) of the peak before
    start_level: float | None
    end_level: float | None
    next_level: float | None  # coarse level the slip after the peak falls to
    next_time: float | None = None  # coarse time where it gets there
    line: Line | None = None
    start: Corner | None = None
    end: Corner | None = None
    slip_first: int | None = None  # the first sample of the slip after the stick (clearly below its line)
    slip_last: int | None = None  # the last sample of the slip before the stick (clearly above its line)
    slip_bound: float | None = None  # the drop after the stick falls between two samples: the interval (s)
    curve: _Curve | None = None  # the parabola through the stick, where measured
    curve_passes: int = 0


def analyze_trace(
    time: Any,
    stress: Any,
    pulling_velocity: float,
    params: Parameters | None = None,
    source: str = "trace",
) -> TraceAnalysis:
    """Detect stick phases, slips and cycles in a stress record and measure Table 1's quantities.

    ``time`` (s) and ``stress`` (Pa, NaN for gaps) are arrays; times strictly
    increasing.  ``time`` may instead be a :class:`~.traces.Trace` from
    :func:`~.traces.read_trace`, with ``stress=None``.  ``pulling_velocity`` V0 (m/s) turns the stick slope into a
    stiffness with the geometric factor of ``params.block`` (Eq 17);
    ``params`` (default gelatin-glass) also gives the steady curve on which
    the jump velocity is read.
    """
    if isinstance(time, Trace):
        if stress is not None:
            raise DataError("analyze_trace: give either a Trace (and stress=None) or time and stress arrays")
        trace = time
    else:
        trace = check_trace(time, stress, source=source)
    v0 = _check_velocity(pulling_velocity)
    params = load_parameters("gelatin-glass") if params is None else params
    valid = trace.valid
    t, x = (trace.time, trace.stress) if np.all(valid) else (trace.time[valid], trace.stress[valid])
    rows = np.flatnonzero(valid)  # each usable sample's index in the record: NaN rows between two are a hole
    step = sampling_step(t)
    coarse = coarse_segments(t, x, step)
    if np.median(x) < -coarse.threshold:
        raise DataError(
            f"{trace.source}: the stress is negative over most of the record (median {np.median(x):.4g} Pa);"
            " friction stress is taken positive: flip the sign of the column"
        )
    warnings: list[str] = []
    stress = trace.stress
    dropped = dropouts(x, coarse.threshold)
    if dropped.size:  # outlier bursts, not slips: left out, and the record's drops sought again without them
        warnings.append(_dropout_note(t, dropped))
        stress = stress.copy()
        stress[np.flatnonzero(valid)[dropped]] = np.nan
        keep = np.ones(t.size, dtype=bool)
        keep[dropped] = False
        t, x, rows = t[keep], x[keep], rows[keep]
        coarse = coarse_segments(t, x, step)
    # a long interval is a gap unless the record runs straight across it (a model's two-sample stick)
    cuts = gaps(t, step, x, coarse.noise, holes=np.diff(rows) > 1)
    if cuts.size:
        warnings.append(_gap_note(t, cuts, step))
        coarse, swings, regime, steady_from, cycles = _across_gaps(t, x, coarse, cuts, step, v0, params)
    else:
        sticks, swings, regime, steady_from = _piece(t, x, coarse, step)
        cycles = _cycles(sticks, v0, params, steady_from is not None)
    bent = _curvature_note(cycles, coarse.noise)
    if bent:
        warnings.append(bent)
    slopes = _slope_change(cycles, v0)
    if slopes:
        warnings.append(slopes)
    if regime == regimes.STICK_SLIP and not _whole_stick(cycles):
        # a slip, but no stick seen from its start to its end: a start-up transient looks the same
        regime = regimes.UNDETERMINED
    unresolved = None
    if regime == regimes.STEADY and steady_from is not None:  # or a sawtooth of too few samples a cycle?
        tail = _between(t, steady_from, math.inf)
        unresolved = unresolved_swings(t[tail], x[tail], coarse.noise, step)
        if unresolved is not None:
            regime, steady_from = regimes.UNDETERMINED, None
    long_cycles = _long_cycles(cycles, step)
    if long_cycles:
        warnings.append(long_cycles)
    if regime == regimes.STEADY and steady_from is not None:
        scattered = _wide_steady_scatter(x[_between(t, steady_from, math.inf)])
        if scattered:
            warnings.append(scattered)
        # the relaxation is sought after the last slip (and the last gap) on
        ends = [float(t[0]), *(c.peak_time for c in cycles if c.peak_time is not None)]
        ends.extend(float(t[k + 1]) for k in cuts)
        steady_from, unsettled = _settled(t, x, steady_from, max(ends), coarse.threshold)
        if unsettled:
            warnings.append(unsettled)
    summary = _summary(t, x, cycles, regime, steady_from, v0)
    if unresolved is not None:
        summary["unresolved_swings"] = unresolved.as_dict()
    if swings is not None:
        summary["oscillation"] = swings
    message = _message(regime, cycles, coarse, summary)
    return TraceAnalysis(
        time=trace.time,
        stress=stress,
        pulling_velocity=v0,
        regime=regime,
        message=message,
        cycles=tuple(cycles),
        summary=summary,
        noise=coarse.noise,
        threshold=coarse.threshold,
        steady_from=steady_from,
        parameters=params,
        source=trace.source,
        warnings=tuple(warnings),
    )


def _piece(
    t: np.ndarray, x: np.ndarray, coarse: Coarse, step: float
) -> tuple[list[_Stick], dict[str, Any] | None, str, float | None]:
    """The fitted stick phases of one unbroken stretch of record, its oscillation, regime and steady start."""
    sticks = _stick_phases(t, x, coarse)
    for stick in sticks:
        _fit_stick(t, x, coarse, stick, step)
    sticks = [s for s in sticks if s.line is not None]
    _unresolved_slips(t, x, coarse.noise, sticks)
    swings = _oscillation(t, x, coarse)
    regime, steady_from = _regime(t, x, coarse, sticks, swings)
    return sticks, swings, regime, steady_from


#: A drop between two samples: the sample before it and the one after it (and their neighbours on the same side)
#: lie within this many noise levels of their stick lines, and no sample lies off both lines.  The slip then left
#: no sample to place a hinge's branch by, and the hinge placed the corners of identical cycles anywhere within the
#: sampling interval (an exact sawtooth sampled every 0.1 s: slip times 0.035 s and 0.123 s, σc 255.5 Pa and
#: 256.8 Pa for 257 Pa).  The band is tighter than the 5 noise levels that mark a slip's samples: a slip that
#: ends gently (the model's, whose slope changes by only K·Vc at the trough) leaves samples a few noise levels
#: above the next stick line, which the hinge reads better than the middle of an interval would
ON_LINE_SIGMAS = 2.0
#: ... the samples either side of the drop that must be on their lines (the two bracketing it among them)
ON_LINE_SAMPLES = 2


def _unresolved_slips(t: np.ndarray, x: np.ndarray, noise: float, sticks: list[_Stick]) -> None:
    """Corners at a drop that falls between two samples, placed by the sampling rather than by a hinge fit.

    With i the first sample below the stick line before the slip and j the last above the one after it, a drop
    between samples i - 1 and i has j = i - 1 (no sample off both lines), and the samples either side of it on
    their lines (ON_LINE_SIGMAS, ON_LINE_SAMPLES).  Then the stick ended, and the next began, within
    (t[i-1], t[i]), no closer: both corners go to its middle, on their stick lines, with half the interval as
    their time uncertainty, and the slip is said to last less than the interval (its time is not measured: the
    slip time between the corners is 0).  A drop at one instant written as two rows (a jump) is left to the hinge:
    its time is known."""
    band = ON_LINE_SIGMAS * max(noise, 1e-12 * float(np.max(np.abs(x))))
    for before, after in itertools.pairwise(sticks):
        i, j = before.slip_first, after.slip_last
        if before.end is None or after.start is None or i is None or j != i - 1 or after.line is None:
            continue
        below, above = np.arange(i - ON_LINE_SAMPLES, i), np.arange(i, i + ON_LINE_SAMPLES)
        if below[0] < 0 or above[-1] >= t.size or not t[i] > t[i - 1]:
            continue
        off = np.concatenate([x[below] - before.line(t[below]), x[above] - after.line(t[above])])
        if np.any(np.abs(off) > band):
            continue
        middle, half = 0.5 * float(t[i - 1] + t[i]), 0.5 * float(t[i] - t[i - 1])
        before.end = dataclasses.replace(
            before.end, time=middle, stress=float(before.line(middle)), time_uncertainty=half, basis=None
        )
        after.start = dataclasses.replace(
            after.start, time=middle, stress=float(after.line(middle)), time_uncertainty=half, basis=None
        )
        before.slip_bound = 2.0 * half


#: A stretch between gaps with fewer usable samples than this is not analysed on its own.
MIN_PIECE = 20


def _gap_text(t: np.ndarray, k: int) -> str:
    return f"the gap in the record from t = {t[k]:.6g} s to {t[k + 1]:.6g} s"


def _gap_note(t: np.ndarray, cuts: np.ndarray, step: float) -> str:
    shown = ", ".join(f"{t[k]:.6g}–{t[k + 1]:.6g} s" for k in cuts[:5])
    more = f" and {cuts.size - 5} more" if cuts.size > 5 else ""
    return (
        f"{cuts.size} gap(s) in the record (no usable sample for more than {GAP_STEPS:g} sampling intervals of"
        f" {step:.3g} s): t = {shown}{more}; the record is analysed on either side of each gap, and a cycle whose"
        " stick or slip runs into one is incomplete (what the gap hides is left empty)"
    )


def _dropout_note(t: np.ndarray, dropped: np.ndarray) -> str:
    starts = dropped[np.concatenate([[True], np.diff(dropped) > 1])]
    shown = ", ".join(f"{t[k]:.6g}" for k in starts[:5])
    more = f" and {starts.size - 5} more" if starts.size > 5 else ""
    return (
        f"left out {dropped.size} sample(s) in {starts.size} dropout(s) at t = {shown}{more} s: bursts of a few"
        " samples that leave the record by more than the drop threshold and return to where it left in one"
        " sample (outliers, not slips)"
    )


def _across_gaps(
    t: np.ndarray,
    x: np.ndarray,
    coarse: Coarse,
    cuts: np.ndarray,
    step: float,
    v0: float,
    params: Parameters,
) -> tuple[Coarse, dict[str, Any] | None, str, float | None, list[CycleResult]]:
    """A record with gaps, analysed stretch by stretch (each as a record of its own, whose ends at a gap cut its
    cycles as the record's own ends do); (coarse of the longest stretch, swings, regime, steady start, cycles).

    A record none of whose stretches has a slip is analysed whole, as before (no cycle to invent)."""
    edges = [0, *(int(k) + 1 for k in cuts), t.size]
    pieces = []
    for j in range(len(edges) - 1):
        a, b = edges[j], edges[j + 1]
        if b - a < MIN_PIECE:
            pieces.append(None)
            continue
        piece_coarse = coarse_segments(t[a:b], x[a:b], step)
        pieces.append((a, b, piece_coarse, *_piece(t[a:b], x[a:b], piece_coarse, step)))
    if not any(p is not None and p[2].peaks.size for p in pieces):
        sticks, swings, regime, steady_from = _piece(t, x, coarse, step)
        return coarse, swings, regime, steady_from, _cycles(sticks, v0, params, steady_from is not None)
    cycles: list[CycleResult] = []
    last = len(pieces) - 1
    for j, piece in enumerate(pieces):
        if piece is None:
            continue
        a, b, _, sticks, _, _, steady_from = piece
        head = _gap_text(t, a - 1) if j > 0 else None
        tail = _gap_text(t, b - 1) if j < last else None
        ends_steady = j == last and steady_from is not None
        cycles.extend(_cycles(sticks, v0, params, ends_steady, head=head, tail=tail, first=len(cycles) + 1))
    longest = max((p for p in pieces if p is not None), key=lambda p: p[1] - p[0])
    final = pieces[-1]
    if final is not None and final[5] == regimes.STEADY and final[6] is not None:
        return longest[2], None, regimes.STEADY, final[6], cycles
    return longest[2], None, regimes.STICK_SLIP, None, cycles


#: Successive cycles' stick slopes that differ by more than this factor (and by more than SLOPE_SIGMAS of their
#: standard errors) are a change of the loading rate within the record: a velocity step, or spliced records.
SLOPE_FACTOR = 1.3
SLOPE_SIGMAS = 5.0
#: Only stick lines of at least this many samples are compared.
SLOPE_POINTS = 10


def _slope_change(cycles: list[CycleResult], v0: float) -> str:
    """A warning where the stick slope (K·V0) changes by a large factor within the record, naming the times and
    saying that Gd/h per cycle then assumes one V0; "" when it does not.  Where the sticks are curved
    (:func:`_curvature_note`) a cut stick's slope is that of the part of it the record holds, which differs from a
    whole one's with no change of V0: only complete sticks are compared."""
    curved = any(c.stick_curved for c in cycles)
    sticks = [c for c in cycles if c.stick_points >= SLOPE_POINTS and c.stick_slope is not None and c.stick_slope > 0]
    if curved:
        sticks = [c for c in sticks if c.complete]
    changes = []
    for before, after in itertools.pairwise(sticks):
        ratio = after.stick_slope / before.stick_slope
        error = math.hypot(before.stick_slope_stderr or 0.0, after.stick_slope_stderr or 0.0)
        if (
            max(ratio, 1.0 / ratio) > SLOPE_FACTOR
            and abs(after.stick_slope - before.stick_slope) > SLOPE_SIGMAS * error
        ):
            changes.append(
                f"from {before.stick_slope:.4g} Pa/s (cycle {before.index}, stick to t = {before.stick_to:.6g} s)"
                f" to {after.stick_slope:.4g} Pa/s (cycle {after.index}, from t = {after.stick_from:.6g} s)"
            )
    if not changes:
        return ""
    return (
        "the stick slope changes within the record " + "; ".join(changes) + ": a change of the pulling velocity"
        " (a velocity step) or spliced records?  Gd/h per cycle is the slope over one V0"
        f" ({v0 * 1e6:.6g} µm/s for every cycle), and a stick spanning the change is not one line"
    )


def _curvature_note(cycles: list[CycleResult], noise: float) -> str:
    """A warning naming the sticks that are curved beyond their noise (:data:`CURVE_SIGMAS`, :data:`CURVE_NOISE`)
    with how much, and what the analysis did about it; "" when none is."""
    curved = [c for c in cycles if c.stick_curved and c.stick_curvature is not None]
    if not curved:
        return ""
    measured = [c for c in cycles if c.stick_curvature is not None]
    which = "every one" if len(curved) == len(measured) else "cycles " + ", ".join(_runs([c.index for c in curved]))
    if noise > 0 and 2 * len(curved) < len(measured):  # a few sticks bent, the others straight
        bends = ", ".join(f"{c.stick_sagitta:.3g} Pa" for c in curved[:5] if c.stick_sagitta is not None)
        return (
            f"{len(curved)} of {len(measured)} sticks ({which}) are curved beyond their noise (by {bends}, against a"
            f" noise of {noise:.3g} Pa), the others are straight: noise correlated over seconds, or an event within"
            " those sticks?  Their σc, σs and ts are read where the slips meet the tangents of the parabola fitted to"
            ' each (docs/analysis.md, "Curved sticks")'
        )
    curvature = float(np.median([c.stick_curvature for c in curved]))
    sigmas = float(np.median([abs(c.stick_curvature) / c.stick_curvature_stderr for c in curved
                              if c.stick_curvature_stderr]))  # fmt: skip
    sagitta = float(np.median([c.stick_sagitta for c in curved if c.stick_sagitta is not None]))
    whole = [c for c in curved if c.stick_time is not None and c.stick_slope is not None]
    slopes = ""
    if whole:
        mean = float(np.median([c.stick_slope for c in whole]))
        first = float(np.median([c.stick_slope - 0.5 * c.stick_curvature * c.stick_time for c in whole]))
        last = float(np.median([c.stick_slope + 0.5 * c.stick_curvature * c.stick_time for c in whole]))
        slopes = (
            f"; within a stick its slope goes from {first:.4g} Pa/s at σc to {last:.4g} Pa/s at σs"
            f" ({first / mean:.2g} to {last / mean:.2g} times its mean slope {mean:.4g} Pa/s)"
        )
    cut = [c.index for c in cycles if not c.complete and c.stick_slope is not None]
    cut_text = (
        f"; the stick slopes of the cut cycle(s) {', '.join(str(k) for k in cut)} are those of the part of a curved"
        " stick the record holds, not a change of the pulling velocity"
        if cut
        else ""
    )
    return (
        (
            f"the stick phases are not straight lines: {len(curved)} of {len(measured)} sticks ({which}) are curved,"
            f" d²σ/dt² = {curvature:.3g} Pa/s² ({sigmas:.3g} standard errors under the record's correlated noise),"
            " which"
            f" bends a stick {sagitta:.3g} Pa off a straight line, {sagitta / noise:.3g} times the noise"
            f" ({noise:.3g} Pa)"
            f"{slopes}.  The spring-block model's stick is the straight line σ = σc + K·V0·t: here σc, σs and ts are"
            " read where the slips meet the parabola's tangents, dσ/dt and Gd/h are the mean slope over each stick"
            " (not K·V0 at any one point), and a fit of the model to these cycles fits a stick it does not"
            f" have{cut_text}"
        )
        if noise > 0
        else ""
    )


def _check_velocity(value: Any) -> float:
    try:
        v0 = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"pulling_velocity: expected a velocity in m/s, got {value!r}") from None
    if not math.isfinite(v0) or v0 <= 0:
        raise ParameterError(f"pulling_velocity: expected a positive finite velocity in m/s, got {value!r}")
    return v0


def _stick_phases(t: np.ndarray, x: np.ndarray, coarse: Coarse) -> list[_Stick]:
    sticks = []
    for k, peak in enumerate(coarse.peaks):
        prev = (float(coarse.peaks[k - 1]), float(coarse.peak_levels[k - 1])) if k else None
        next_time = None
        if k + 1 < coarse.peaks.size:
            next_level, next_time = float(coarse.trough_levels[k + 1]), float(coarse.troughs[k + 1])
        elif coarse.final_trough is not None:
            next_level, next_time = coarse.final_level, coarse.final_trough
        else:
            after = coarse.grid_time >= peak
            next_level = float(np.min(coarse.grid_stress[after]))
        sticks.append(
            _Stick(
                float(coarse.troughs[k]),
                float(peak),
                prev,
                float(coarse.trough_levels[k]),
                float(coarse.peak_levels[k]),
                next_level,
                next_time,
            )
        )
    if coarse.final_trough is not None:
        prev = (float(coarse.peaks[-1]), float(coarse.peak_levels[-1]))
        sticks.append(_Stick(coarse.final_trough, None, prev, coarse.final_level, None, None))
    if not coarse.peaks.size:
        q = rise_start(coarse.grid_stress, coarse.threshold)
        sticks.append(_Stick(float(coarse.grid_time[q]), None, None, float(coarse.grid_stress[q]), None, None))
    return sticks


def _fit_stick(t: np.ndarray, x: np.ndarray, coarse: Coarse, stick: _Stick, step: float) -> None:
    """Stick line and corners: line on the coarse interior -> corners -> line between the corners -> corners.

    Every step works on the samples near this stick phase only (``t`` is sorted: windows are
    found by bisection), so that a record costs time in proportion to its length, not to
    its length times its number of cycles.
    """
    lo = stick.start_guess if stick.start_guess is not None else float(t[0])
    hi = stick.end_guess if stick.end_guess is not None else float(t[-1])
    margin = min(max(3 * MEDIAN_WIDTH * step, 0.1 * (hi - lo)), 0.25 * (hi - lo))
    inner_lo = lo + margin if lo > t[0] else lo
    inner_hi = hi - margin if stick.end_guess is not None else hi
    line = _line_between(t, x, inner_lo, inner_hi) or _line_between(t, x, lo, hi)
    if line is None:
        return
    stick.line = line
    stick.start = _start_corner(t, x, coarse, stick, step)
    stick.end = _end_corner(t, x, coarse, stick, step)
    began = stick.start is not None and stick.start.significant
    a = stick.start.time if began else (float(t[0]) if stick.prev_peak is None else inner_lo)
    b = stick.end.time if stick.end is not None else inner_hi
    span = b - a
    # two samples clear of each corner; one in a coarse record, whose sticks hold a handful (ten samples a cycle
    # left three of them to the line, and a line of three carried on to the next corner found it early)
    clear = (1 if coarse_spacing(coarse.peaks, step) else 2) * step
    lo_cut = a + max(clear, LINE_MARGIN * span) if began else a
    hi_cut = b - max(clear, LINE_MARGIN * span) if stick.end is not None else b
    refit = _line_between(t, x, lo_cut, hi_cut) if hi_cut > lo_cut else None
    if refit is not None:
        stick.line = refit
        stick.start = _start_corner(t, x, coarse, stick, step)
        stick.end = _end_corner(t, x, coarse, stick, step)
        _curved_corners(t, x, coarse, stick, step, clear)
    # the final corners only: their systematic uncertainty costs one more hinge fit each
    stick.start, stick.end = with_time_uncertainty(stick.start), with_time_uncertainty(stick.end)


#: A stick is curved when the parabola fitted to it (between its corners, LINE_MARGIN clear of them) has a curvature
#: this many standard errors from zero (under the record's correlated noise: the residuals' integrated
#: autocorrelation time, analysis.steady) ...
CURVE_SIGMAS = 5.0
#: ... that departs from the straight line over the stick by more than this many noise levels (its sagitta).
CURVE_NOISE = 1.0
#: Fewest samples a stick needs for its curvature to be measured.
CURVE_SAMPLES = 20
#: The corners of a curved stick are sought again on the parabola's tangents this many times (the window the
#: parabola is fitted on moves with them).
CURVE_PASSES = 2


@dataclass(frozen=True)
class _Curve:
    """sigma = a + b (t - t_ref) + c (t - t_ref)^2 fitted to a stick; c's standard error; whether it is curved."""

    t_ref: float
    a: float
    b: float
    c: float
    c_stderr: float
    sagitta: float
    curved: bool

    def __call__(self, t: np.ndarray | float) -> np.ndarray | float:
        u = np.asarray(t) - self.t_ref
        return self.a + self.b * u + self.c * u * u

    def tangent(self, at: float, like: Line) -> Line:
        """The parabola's tangent at ``at``, as a stick line (the other fields of ``like``)."""
        u = at - self.t_ref
        return dataclasses.replace(like, t_ref=at, intercept=self.a + self.b * u + self.c * u * u,
                                   slope=self.b + 2.0 * self.c * u)  # fmt: skip


def _fit_curve(t: np.ndarray, x: np.ndarray, lo: float, hi: float, span: float, noise: float) -> _Curve | None:
    """The parabola through the samples in [lo, hi] and whether it is curved beyond the noise over a stick of
    duration ``span`` (s): None with fewer than :data:`CURVE_SAMPLES` samples."""
    inside = _between(t, lo, hi)
    tt, xx = t[inside], x[inside]
    if tt.size < CURVE_SAMPLES or not tt[-1] > tt[0]:
        return None
    t_ref = float(np.mean(tt))
    u = tt - t_ref
    design = np.column_stack([np.ones_like(u), u, u * u])
    coef, *_ = np.linalg.lstsq(design, xx, rcond=None)
    residual = xx - design @ coef
    variance = float(np.einsum("i,i", residual, residual)) / (tt.size - 3)
    w = u * u - np.mean(u * u)  # the curvature's own direction, clear of the line's
    w -= float(np.einsum("i,i", u, w)) / float(np.einsum("i,i", u, u)) * u
    ww = float(np.einsum("i,i", w, w))
    if not ww > 0:
        return None
    c = float(coef[2])
    stderr = math.sqrt(variance * integrated_time(residual) / ww)
    sagitta = abs(c) * span * span / 4.0  # the parabola c u^2 over a stick of duration span, off its chord
    # a noise-free record's stick is straight to its rounding, ~1e-16 of the stress, whatever its standard errors
    floor = max(noise, 1e-9 * float(np.max(np.abs(xx))))
    curved = abs(c) > CURVE_SIGMAS * stderr and sagitta > CURVE_NOISE * floor
    return _Curve(t_ref, float(coef[0]), float(coef[1]), c, stderr, sagitta, bool(curved))


def _curved_corners(t: np.ndarray, x: np.ndarray, coarse: Coarse, stick: _Stick, step: float, clear: float) -> None:
    """Measure the stick's curvature; where it is curved beyond its noise, seek its corners again on the tangents of
    the parabola at each of them (a straight line through a stick whose slope grows lies above it in its middle and
    below it at its ends, and the hinges found the corners well inside the stick: t_s 9.6 s for 12.6 s)."""
    straight = stick.line
    if straight is None:
        return
    for _ in range(CURVE_PASSES + 1):
        began = stick.start is not None and stick.start.significant
        a = stick.start.time if began else max(float(t[0]), straight.t_min)
        b = stick.end.time if stick.end is not None else straight.t_max
        span = b - a
        lo = a + max(clear, LINE_MARGIN * span) if began else a
        hi = b - max(clear, LINE_MARGIN * span) if stick.end is not None else b
        curve = _fit_curve(t, x, lo, hi, span, coarse.noise) if hi > lo else None
        stick.curve = curve
        if curve is None or not curve.curved or stick.curve_passes >= CURVE_PASSES:
            break
        stick.curve_passes += 1
        # the slip's samples are those off the parabola (a stick cut by the record's start lies above the tangent at
        # its first sample, and read as a slip onto it); the hinge joins the slip to the tangent at the corner
        stick.line = curve.tangent(a, straight)
        stick.start = _start_corner(t, x, coarse, stick, step)
        stick.line = curve.tangent(b, straight)
        stick.end = _end_corner(t, x, coarse, stick, step)
        stick.line = straight
    if stick.curve is not None and stick.curve.curved:  # the mean slope over the stick between its final corners
        began = stick.start is not None and stick.start.significant
        a = stick.start.time if began else max(float(t[0]), straight.t_min)
        b = stick.end.time if stick.end is not None else straight.t_max
        lo = a + max(clear, LINE_MARGIN * (b - a)) if began else a
        hi = b - max(clear, LINE_MARGIN * (b - a)) if stick.end is not None else b
        stick.line = (_line_between(t, x, lo, hi) if hi > lo else None) or straight


def _line_between(t: np.ndarray, x: np.ndarray, lo: float, hi: float) -> Line | None:
    inside = _between(t, lo, hi)
    return fit_line(t[inside], x[inside])


def _between(t: np.ndarray, lo: float, hi: float) -> slice:
    """The samples with lo <= t <= hi, as a slice of the sorted times."""
    return slice(int(np.searchsorted(t, lo, "left")), int(np.searchsorted(t, hi, "right")))


def _indices(t: np.ndarray, lo: float, hi: float) -> np.ndarray:
    window = _between(t, lo, hi)
    return np.arange(window.start, max(window.start, window.stop))


def _stick_span(t: np.ndarray, stick: _Stick) -> float:
    lo = stick.start.time if stick.start is not None else stick.start_guess
    hi = stick.end.time if stick.end is not None else stick.end_guess
    lo = float(t[0]) if lo is None else lo
    hi = float(t[-1]) if hi is None else hi
    return max(hi - lo, 0.0)


def _start_corner(t: np.ndarray, x: np.ndarray, coarse: Coarse, stick: _Stick, step: float) -> Corner | None:
    """Where the stick began: hinge between the end of the previous slip and the stick line."""
    guess, line = stick.start_guess, stick.line
    if guess is None or line is None:
        return None
    span = _stick_span(t, stick)
    reach = max(5 * step, 0.1 * span)
    top, level = stick.prev_peak if stick.prev_peak is not None else (float(t[0]), None)
    hi = guess + reach if stick.end_guess is None else min(guess + reach, 0.5 * (guess + stick.end_guess))
    near = _indices(t, top, hi)
    # the last sample clearly above the stick line (a curved stick's parabola) is the last one of the slip
    off = near[x[near] - _stick_curve(stick)(t[near]) > _deviation(coarse)]
    stick.slip_last = None
    if off.size == 0:
        return None
    last = int(_slip_run(off, coarse, step, first=True)[-1])
    stick.slip_last = last
    branch_lo = t[last] - START_TIME_FRACTION * (t[last] - top)
    if level is not None:
        branch_lo = max(
            branch_lo,
            _crossing_before(coarse, t[last], stick.start_level + START_FRACTION * (level - stick.start_level)),
        )
    branch_lo = min(max(branch_lo, top), float(t[max(last - 1, 0)]))
    search = (float(t[last]), float(t[last]) + reach)
    inside = _between(t, branch_lo, search[1] + max(STICK_WINDOW * span, reach))
    return fit_corner(t[inside], x[inside], line, False, search, coarse.noise, START_POWERS)


def _end_corner(t: np.ndarray, x: np.ndarray, coarse: Coarse, stick: _Stick, step: float) -> Corner | None:
    """Where the stick ended: hinge between the stick line and the start of the slip."""
    guess, line = stick.end_guess, stick.line
    if guess is None or line is None:
        return None
    span = _stick_span(t, stick)
    reach = max(5 * step, 0.1 * span)
    bottom = stick.next_time if stick.next_time is not None else float(t[-1])
    lo = guess - reach if stick.start_guess is None else max(guess - reach, 0.5 * (guess + stick.start_guess))
    near = _indices(t, lo, bottom)
    # the first sample clearly below the stick line (a curved stick's parabola) is the first one of the slip
    off = near[_stick_curve(stick)(t[near]) - x[near] > _deviation(coarse)]
    stick.slip_first = None
    if off.size == 0:
        return None
    first = int(_slip_run(off, coarse, step, first=False)[0])
    stick.slip_first = first
    branch_hi = t[first] + BRANCH_TIME_FRACTION * (bottom - t[first])
    branch_hi = min(
        branch_hi,
        _crossing_after(coarse, t[first], stick.end_level - BRANCH_FRACTION * (stick.end_level - stick.next_level)),
    )
    branch_hi = max(min(branch_hi, bottom), float(t[min(first + 1, t.size - 1)]))
    search = (float(t[first]) - reach, float(t[first]))
    inside = _between(t, search[0] - max(STICK_WINDOW * span, reach), branch_hi)
    return fit_corner(t[inside], x[inside], line, True, search, coarse.noise)


def _stick_curve(stick: _Stick) -> Callable[[np.ndarray], Any]:
    """What a stick's samples lie on: its parabola where it is curved, else its line."""
    curve = stick.curve
    return curve if curve is not None and curve.curved else stick.line  # type: ignore[return-value]


def _slip_run(off: np.ndarray, coarse: Coarse, step: float, first: bool) -> np.ndarray:
    """The samples off the stick line (indices, ascending) that belong to the slip: all of them in a finely sampled
    record; in one whose slips come fewer than ``detect.COARSE_CYCLE`` samples apart, the run of consecutive
    ones that the slip makes, the first run after the previous peak (``first``) or the last before the next
    trough.  There a stick line rests on a handful of samples and, carried a few samples on, can be off by several
    noise levels: a lone sample beyond the band inside the stick is that, not the slip (a stick of 10 samples at
    15 a cycle ended two samples early, at a sample 9 Pa below a line fitted to 5 samples at 2 Pa of noise, the
    next one back within the band)."""
    if off.size < 2 or not coarse_spacing(coarse.peaks, step):
        return off
    breaks = np.flatnonzero(np.diff(off) > 1)  # where a run of consecutive samples ends
    if not breaks.size:
        return off
    return off[: breaks[0] + 1] if first else off[breaks[-1] + 1 :]


def _deviation(coarse: Coarse) -> float:
    """A departure from the stick line larger than noise: DEVIATION_SIGMAS noise levels."""
    return max(DEVIATION_SIGMAS * coarse.noise, 1e-9 * float(np.max(np.abs(coarse.grid_stress))))


def _crossing_after(coarse: Coarse, start: float, level: float) -> float:
    """First grid time after ``start`` where the smoothed record falls below ``level``."""
    g, y = coarse.grid_time, coarse.grid_stress
    first = int(np.searchsorted(g, start, "right"))
    after = _first_index(y[first:], lambda chunk: chunk < level)
    return float(g[first + after]) if after is not None else float(g[-1])


def _crossing_before(coarse: Coarse, end: float, level: float) -> float:
    """Last grid time before ``end`` where the smoothed record is above ``level``."""
    g, y = coarse.grid_time, coarse.grid_stress
    stop = int(np.searchsorted(g, end, "left"))
    before = _first_index(y[:stop][::-1], lambda chunk: chunk > level)
    return float(g[stop - 1 - before]) if before is not None else float(g[0])


def _first_index(values: np.ndarray, test: Callable[[np.ndarray], np.ndarray]) -> int | None:
    """Index of the first value passing ``test``, or None; scans in doubling chunks, so a crossing
    near the start costs in proportion to its distance, not to the length of ``values``."""
    start, size = 0, 256
    while start < values.size:
        passed = test(values[start : start + size])
        k = int(np.argmax(passed))
        if passed[k]:
            return start + k
        start, size = start + size, 2 * size
    return None


def _oscillation(t: np.ndarray, x: np.ndarray, coarse: Coarse) -> dict[str, Any] | None:
    """A smooth oscillation's evidence, read off the record (None when ``coarse`` found none): whole periods
    (maxima − 1, as :func:`stickslip.regimes.classify` counts them), the mean period and its scatter, the mean
    peak-to-trough swing, the amplitude ratio per period (a straight-line fit to the log of the swings; None
    with fewer than :data:`TREND_SWINGS`), its kind in :mod:`stickslip.regimes`' words, and the mean stress."""
    swings = coarse.oscillation
    if swings is None:
        return None
    peaks = swings.peaks
    amplitudes = swings.peak_levels[:-1] - swings.trough_levels
    # the period from the rises' mid-level crossings (a peak's time wanders along its flat top with the noise)
    crossings = _rising_crossings(coarse, swings)
    marks = crossings if crossings.size >= 2 else peaks
    intervals = np.diff(marks)
    period = float(marks[-1] - marks[0]) / (marks.size - 1)
    ratio = ratio_error = None
    kind = OSCILLATION
    positive = amplitudes[amplitudes > 0]
    if positive.size >= TREND_SWINGS and positive.size == amplitudes.size:
        k = np.arange(amplitudes.size, dtype=float)
        (slope, _), cov = np.polyfit(k, np.log(amplitudes), 1, cov="unscaled")
        residual = np.log(amplitudes) - np.polyval([slope, _], k)
        dof = max(amplitudes.size - 2, 1)
        error = math.sqrt(max(float(cov[0, 0]) * float(residual @ residual) / dof, 0.0))
        ratio, ratio_error = math.exp(slope), math.exp(slope) * error
        if abs(slope) > TREND_SIGMAS * error and abs(ratio - 1.0) > regimes.RATIO_TOLERANCE:
            kind = regimes.DECAYING if ratio < 1.0 else regimes.GROWING
    inside = _between(t, float(peaks[0]), float(peaks[-1]))
    return {
        "kind": kind,
        "periods": int(peaks.size - 1),
        "period": period,
        "period_std": float(np.std(intervals, ddof=1)) if intervals.size > 1 else None,
        "peak_to_trough": float(np.mean(amplitudes)),
        "amplitude_ratio": ratio,
        "amplitude_ratio_stderr": ratio_error,
        "asymmetry": swings.asymmetry,
        "mean_stress": float(np.mean(x[inside])),
        "first_peak": float(peaks[0]),
        "last_peak": float(peaks[-1]),
    }


def _rising_crossings(coarse: Coarse, swings: Any) -> np.ndarray:
    """Times where each rise from a trough to the next peak crosses its own mid-level (linear interpolation)."""
    grid, y = coarse.grid_time, coarse.grid_stress
    times = []
    for a, b, low, high in zip(swings.troughs, swings.peaks[1:], swings.trough_levels, swings.peak_levels[1:],
                               strict=True):  # fmt: skip
        i, j = int(np.searchsorted(grid, a)), int(np.searchsorted(grid, b))
        level = 0.5 * (low + high)
        above = np.nonzero(y[i : j + 1] >= level)[0]
        if above.size == 0 or above[0] == 0:
            continue
        k = i + int(above[0])
        y0, y1 = y[k - 1], y[k]
        times.append(grid[k - 1] + (grid[k] - grid[k - 1]) * ((level - y0) / (y1 - y0) if y1 > y0 else 1.0))
    return np.asarray(times, dtype=float)


def _regime(
    t: np.ndarray, x: np.ndarray, coarse: Coarse, sticks: list[_Stick], swings: dict[str, Any] | None = None
) -> tuple[str, float | None]:
    """(regime in :mod:`stickslip.regimes`' names, where steady sliding starts): a measured record is noisy, so
    its slips are the drops beyond ten noise levels (``coarse``), not the turning points of a solution; a record
    whose drops are as slow as its rises oscillates (``swings``, :func:`_oscillation`): no slip, no cycles."""
    if swings is not None:
        sticks.clear()
        if coarse.steady_from is not None and coarse.steady_from >= swings["last_peak"]:
            return regimes.STEADY, coarse.steady_from
        return swings["kind"], None
    if coarse.peaks.size:
        if coarse.steady_from is not None:
            return regimes.STEADY, coarse.steady_from
        return regimes.STICK_SLIP, None
    whole = fit_line(t, x)
    spread = float(np.sum((x - np.mean(x)) ** 2))
    if whole is not None and spread > 0:
        r2 = 1.0 - whole.rms**2 * whole.count / spread
        rise = whole.slope * float(t[-1] - t[0])
        if rise > coarse.threshold and r2 > STUCK_R2:
            return regimes.STUCK, None
    sticks.clear()
    return regimes.STEADY, float(t[0]) if coarse.steady_from is None else coarse.steady_from


def _cycles(
    sticks: list[_Stick],
    v0: float,
    params: Parameters,
    ends_steady: bool,
    head: str | None = None,
    tail: str | None = None,
    first: int = 1,
) -> list[CycleResult]:
    """The cycles of the stick phases of one stretch of record, numbered from ``first``; ``head`` and ``tail``
    name the gaps that begin and end the stretch (None: the record's own ends)."""
    factor = params.block.geometric_factor
    cycles = []
    for k, stick in enumerate(sticks):
        line = stick.line
        start = stick.start if stick.start is not None and stick.start.significant else None
        end = stick.end
        following = sticks[k + 1] if k + 1 < len(sticks) else None
        nxt = following.start if following is not None and following.start is not None else None
        if nxt is not None and not nxt.significant:
            nxt = None
        if end is None:
            nxt = None
        peak = end.stress if end is not None else None
        jump, jump_message = _jump(params, peak)
        notes = [jump_message] if jump_message else []
        if start is None:
            notes.append(f"stick began in {head}" if head and k == 0 else "stick began before the record")
        if end is None:
            notes.append(f"{tail} hides the end of the stick" if tail and following is None else
                         "record ends before the slip")  # fmt: skip
        elif nxt is None and following is not None:  # a stick follows, but where it began is not clear
            notes.append("no clear corner where the next stick begins")
        elif nxt is None:
            notes.append(
                f"the slip runs into {tail}"
                if tail
                else ("slip ends in steady sliding" if ends_steady else "record ends during the slip")
            )
        cycles.append(
            CycleResult(
                index=first + k,
                complete=start is not None and end is not None and nxt is not None,
                start_time=start.time if start else None,
                peak_time=end.time if end else None,
                end_time=nxt.time if nxt else None,
                critical_stress=start.stress if start else None,
                stick_slope=line.slope,
                stick_slope_stderr=line.slope_stderr,
                stiffness=line.slope / (v0 * factor),
                stiffness_stderr=line.slope_stderr / (v0 * factor),
                peak_stress=peak,
                stick_time=end.time - start.time if start and end else None,
                jump_velocity=jump,
                slip_time=nxt.time - end.time if nxt and end else None,
                period=nxt.time - start.time if nxt and start else None,
                stress_drop=end.stress - nxt.stress if nxt and end else None,
                stick_points=line.count,
                stick_rms=line.rms,
                critical_stress_uncertainty=_times(abs(line.slope), start),
                peak_stress_uncertainty=_times(abs(line.slope), end),
                stick_time_uncertainty=math.hypot(start.time_uncertainty or 0.0, end.time_uncertainty or 0.0)
                if start and end
                else None,
                message="; ".join(notes),
                slip_time_bound=stick.slip_bound if nxt and end else None,
                stick_curvature=None if stick.curve is None else 2.0 * stick.curve.c,
                stick_curvature_stderr=None if stick.curve is None else 2.0 * stick.curve.c_stderr,
                stick_sagitta=None if stick.curve is None else stick.curve.sagitta,
                stick_curved=stick.curve is not None and stick.curve.curved,
                line=line,
                stick_from=start.time if start else line.t_min,
                stick_to=end.time if end else line.t_max,
            )
        )
    return cycles


#: A complete cycle longer than this many times the median period of the complete cycles is warned of: a slip
#: inside it may have been missed (judged with at least LONG_CYCLE_AMONG complete cycles).
LONG_CYCLE = 1.6
LONG_CYCLE_AMONG = 3


#: A steady stretch scattering by more than this fraction of its mean (sd) is warned: friction is measured to a few
#: per cent, and stick-slip sampled about twice a cycle or less looks like such scatter (aliased, no regular swing)
WIDE_STEADY_SCATTER = 0.05


def _settled(t: np.ndarray, x: np.ndarray, steady_from: float, earliest: float, band: float) -> tuple[float, str]:
    """(start of the averaging window, a warning or "") of a steady stretch found from ``steady_from``: where its
    relaxation, sought from ``earliest`` (after the last slip, or a gap) on, has decayed below the mean's standard
    error (:func:`.steady.settled_start`); the warning when it has not by the latest start that keeps half the
    stretch."""
    inside = _between(t, min(earliest, steady_from), math.inf)
    start, left, tau, _ = settled_start(t[inside], x[inside], steady_from, band)
    if left is None or tau is None:
        return start, ""
    error = mean_and_error(t[_between(t, start, math.inf)], x[_between(t, start, math.inf)])
    if error is None or abs(left) <= 1.01 * error.sem:
        return start, ""
    return start, (
        f"the steady stretch is still relaxing: a relaxation of time constant {tau:.3g} s is {abs(left):.3g} Pa at"
        f" t = {start:.6g} s, the latest start that keeps half the stretch, above the standard error of the mean"
        f" ({error.sem:.2g} Pa): the mean stress is not yet the steady one; record for longer"
    )


def _wide_steady_scatter(stress: np.ndarray) -> str:
    """A warning when a steady stretch's scatter is WIDE_STEADY_SCATTER of its mean or more, "" otherwise."""
    stress = stress[np.isfinite(stress)]
    if stress.size < 3:
        return ""
    mean, spread = float(np.mean(stress)), float(np.std(stress, ddof=1))
    if not (mean > 0 and spread >= WIDE_STEADY_SCATTER * mean):
        return ""
    return (
        f"the steady stretch scatters by {100 * spread / mean:.2g} % of its mean (sd {spread:.4g} Pa over"
        f" {stress.size} samples), more than a friction measurement's noise usually is: stick-slip sampled about"
        " twice a cycle or less looks the same; sample faster to tell them apart"
    )


def _long_cycles(cycles: list[CycleResult], step: float) -> str:
    """A warning naming the complete cycles that last LONG_CYCLE times the median period or more, "" when none."""
    periods = [c.period for c in cycles if c.complete and c.period is not None]
    if len(periods) < LONG_CYCLE_AMONG:
        return ""
    median = float(np.median(periods))
    long = [c for c in cycles if c.complete and c.period is not None and c.period >= LONG_CYCLE * median]
    if not long or not median > 0:
        return ""
    shown = "; ".join(
        f"cycle {c.index} lasts {c.period:.4g} s ({c.period / median:.2g} times; stick {c.stick_time:.4g} s, slip"
        f" {_slip_text(c)})"
        for c in long[:5]
    )
    more = f" and {len(long) - 5} more" if len(long) > 5 else ""
    samples = f", {median / step:.3g} samples per cycle" if step > 0 else ""
    return (
        f"{shown}{more}, against a median period of {median:.4g} s over the {len(periods)} complete cycles"
        f"{samples}: a slip inside may have been missed (two cycles read as one), and such a cycle's slip time,"
        " period and stress drop are not one cycle's"
    )


def _slip_text(cycle: CycleResult) -> str:
    """A cycle's slip time in words: its value, or its bound where the slip falls between samples."""
    if cycle.slip_time_bound is not None:
        return f"< {cycle.slip_time_bound:.4g} s, between samples"
    return "--" if cycle.slip_time is None else f"{cycle.slip_time:.4g} s"


def _jump(params: Parameters, peak: float | None) -> tuple[float | None, str]:
    if peak is None:
        return None, ""
    try:
        from ..quasistatic.jump import jump_velocity
    except ImportError:
        return None, "jump velocity not computed: the jump solver (stickslip.quasistatic.jump) is not available"
    if peak <= 0:
        return None, f"no jump velocity: peak stress {peak:.4g} Pa is not positive"
    result = jump_velocity(params, peak)
    # the note names the set: the aging curve it quotes (Vc, its stresses) is the parameter set's, not the record's
    why = f"no jump velocity with the parameter set {params.name}: {result.message}"
    return (result.velocity, "" if result.velocity is not None else why)


def _times(slope: float, corner: Corner | None) -> float | None:
    """A stress's uncertainty at a corner of the stick line: the slope times the corner time's."""
    return None if corner is None or corner.time_uncertainty is None else slope * corner.time_uncertainty


def _whole_stick(cycles: list[CycleResult]) -> bool:
    """Does any cycle show a stick phase from its start corner to its end corner?"""
    return any(c.start_time is not None and c.peak_time is not None for c in cycles)


def _stats(values: list[float]) -> dict[str, Any]:
    n = len(values)
    if n == 0:
        return {"mean": None, "std": None, "n": 0}
    array = np.asarray(values, dtype=float)
    return {"mean": float(np.mean(array)), "std": float(np.std(array, ddof=1)) if n > 1 else None, "n": n}


def _summary(
    t: np.ndarray, x: np.ndarray, cycles: list[CycleResult], regime: str, steady_from: float | None, v0: float
) -> dict[str, Any]:
    summary: dict[str, Any] = {
        "regime": regime,
        "pulling_velocity": v0,
        "n_cycles": len(cycles),
        "n_complete": sum(c.complete for c in cycles),
    }
    for name in CYCLE_QUANTITIES:
        # a cycle the record or a gap cuts (a start-up stick, one the record ends in) is no repeat of the cycle:
        # left out of the corners' quantities, whose mean would move with it (LINE_QUANTITIES)
        counted = cycles if name in LINE_QUANTITIES else [c for c in cycles if c.complete]
        # a slip between samples has no measured time (its 0 is the corners' difference): only its bound, below
        timed = [c for c in counted if name != "slip_time" or c.slip_time_bound is None]
        summary[name] = _stats([getattr(c, name) for c in timed if getattr(c, name) is not None])
    summary["averaged_cycles"] = [c.index for c in cycles if c.complete]
    summary["left_out_cycles"] = [{"cycle": c.index, "why": _cut_reason(c)} for c in cycles if not c.complete]
    bounds = [c.slip_time_bound for c in cycles if c.slip_time_bound is not None]
    if bounds:
        summary["unresolved_slips"] = {"n": len(bounds), "slip_time_bound": max(bounds)}
    if steady_from is not None:
        inside = _between(t, steady_from, math.inf)
        tail = x[inside]
        trend = fit_line(t[inside], tail)
        # the standard error from the effective sample size (correlated noise: analysis.steady)
        error = mean_and_error(t[inside], tail)
        summary.update(
            mean_stress=float(np.mean(tail)),
            stress_std=float(np.std(tail, ddof=1)) if tail.size > 1 else None,
            stress_sem=None if error is None else error.sem,
            stress_correlation_time=None if error is None else error.correlation_time,
            steady_effective_samples=None if error is None else error.effective_samples,
            stress_slope=None if trend is None else trend.slope,
            steady_from=float(steady_from),
            steady_to=float(t[-1]),
            steady_samples=int(tail.size),
        )
    return summary


def _cut_reason(cycle: CycleResult) -> str:
    """Why a cycle is incomplete, in the words of its message (without its note on the jump velocity)."""
    parts = [p for p in cycle.message.split("; ") if p and "jump velocity" not in p]
    return "; ".join(parts) or "cut by the record's ends or a gap in it"


def summary_note(summary: dict[str, Any]) -> str:
    """Which cycles the summary's means are over, in words ("" when every cycle is complete)."""
    left_out = summary.get("left_out_cycles") or []
    if not left_out:
        return ""
    averaged = summary.get("averaged_cycles") or []
    reasons = "; ".join(f"cycle {e['cycle']} ({e['why']})" for e in left_out[:6])
    more = f" and {len(left_out) - 6} more" if len(left_out) > 6 else ""
    lines = ", ".join(_runs(averaged))
    if averaged:
        over = f"mean ± sd of the complete cycle(s) {lines}"
    else:
        over = "no complete cycle: σc, σs, ts, Vs, the slip time and the period are not averaged (no mean)"
    return (
        f"{over}; left out, cut by the record's ends or a gap in it: {reasons}{more};"
        f" dσ/dt and Gd/h are over every stick line ({summary['stick_slope']['n']})"
    )


def _runs(indices: list[int]) -> list[str]:
    """Consecutive cycle numbers as ranges: [2, 3, 4, 7] -> ["2-4", "7"]."""
    out: list[str] = []
    for _, group in itertools.groupby(enumerate(indices), key=lambda pair: pair[1] - pair[0]):
        run = [k for _, k in group]
        out.append(str(run[0]) if len(run) == 1 else f"{run[0]}-{run[-1]}")
    return out


def _message(regime: str, cycles: list[CycleResult], coarse: Coarse, summary: dict[str, Any]) -> str:
    complete = sum(c.complete for c in cycles)
    if regime == regimes.STICK_SLIP:
        return f"stick-slip: {len(cycles)} cycle(s), {complete} complete"
    swings = summary.get("unresolved_swings")
    if swings is not None:
        after = f" after {len(cycles)} stick-slip cycle(s)" if cycles else ""
        return (
            f"{regimes.UNDETERMINED}: {swings['samples_per_swing']:.3g} samples per cycle{after}: the stress swings"
            f" regularly by {swings['peak_to_trough']:.4g} Pa peak to trough every {swings['period']:.4g} s"
            f" ({swings['swings']} swings; sd {swings['spread']:.3g} Pa about its trend, against a sample-to-sample"
            f" noise of {swings['noise']:.3g} Pa), so it is not steady sliding, but too few samples a swing to"
            f" resolve a stick and a slip (no drop above {coarse.threshold:.3g} Pa found): sample faster"
        )
    if regime == regimes.UNDETERMINED:
        return (
            f"{regimes.UNDETERMINED}: {len(cycles)} cycle(s), none complete; no whole stick phase: too short a"
            " record to tell stick-slip from a transient"
        )
    if regime == "stuck":
        return "stuck: the stress rises along one stick line and never drops; no slip in the record"
    swings = summary.get("oscillation")
    if swings is not None and regime != regimes.STEADY:
        return f"{regime}: {_swing_evidence(swings)}"
    mean = summary["mean_stress"]
    if cycles:
        return (
            f"steady sliding at {mean:.6g} Pa after {len(cycles)} stick-slip transient(s); no stick after the last slip"
        )
    drop = f"no stress drop larger than {coarse.threshold:.3g} Pa (10 noise levels)" if coarse.noise > 0 else "no drop"
    text = f"steady sliding at {mean:.6g} Pa: {drop}"
    if swings is not None:
        kind = "smooth oscillation" if swings["kind"] == OSCILLATION else swings["kind"]
        text = f"steady sliding at {mean:.6g} Pa after a {kind} ({_swing_evidence(swings)})"
    if summary["steady_from"] > float(coarse.grid_time[0]):
        text += f"; settled from t = {summary['steady_from']:.6g} s"
    elif coarse.steady_from is None:
        text += f"; the stress has not settled (it changes by {summary['stress_slope']:.3g} Pa/s)"
    return text


def _swing_evidence(swings: dict[str, Any]) -> str:
    """An oscillation's evidence in words, as :mod:`stickslip.regimes` gives it, and why it is not stick-slip."""
    ratio = swings["amplitude_ratio"]
    trend = (
        f"amplitude ratio {ratio:.4g} ± {swings['amplitude_ratio_stderr']:.2g} per period"
        if ratio is not None
        else f"amplitude ratio not known (fewer than {TREND_SWINGS} swings)"
    )
    spread = "" if swings["period_std"] is None else f" ± {swings['period_std']:.2g} s"
    return (
        f"{swings['periods']} period(s) of {swings['period']:.6g} s{spread},"
        f" {swings['peak_to_trough']:.4g} Pa peak to trough about {swings['mean_stress']:.6g} Pa, {trend};"
        f" the stress falls as slowly as it rises (fall/rise asymmetry {swings['asymmetry']:.2f}; a slip falls at"
        f" least {MIN_ASYMMETRY:g} times faster), so there is no slip phase: a smooth oscillation, not stick-slip"
    )
