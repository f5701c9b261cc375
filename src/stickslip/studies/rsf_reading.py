"""A rate-and-state reading of the bond model's velocity steps (docs/extensions.md section 3).

The time-dependent bond model's stress over sigma_c through velocity steps, sampled uniformly in slip, is fitted
by :func:`read_step` with :func:`stickslip.rsf.fit.fit_record` (one or two states, aging or slip law, the rig
stiffness free) at a stated precision, :data:`STEP_PRECISION` of the record's friction range; the measures that
say which law describes the steps are in the docs section.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import DataError, ModelError, ParameterError
from ..protocols import Protocol, Segment, velocity_steps

__all__ = [
    "LEAD",
    "SLIP_SPACING",
    "STEP_PRECISION",
    "TRACE_RTOL",
    "WINDOW",
    "Reading",
    "StepRecord",
    "bond_step",
    "f_test",
    "interval_table",
    "read_step",
    "resample_in_slip",
    "step_guess",
    "step_record",
]

#: the bond model's tolerance for the reading: its own error (5e-7 Pa at 100 -> 1000 -> 100 um/s) is far below
#: the fits' misfit (~10 Pa)
TRACE_RTOL = 1e-7
#: record spacing in slip (m)
SLIP_SPACING = 2e-9
#: slip kept after each velocity change (m): the bond model's response is over within about Delta l_m = 1.07 um
WINDOW = 5e-6
#: slip kept before each change (m): the steady level the step leaves
LEAD = 1e-6
#: The precision (fraction of the step's friction range) at which RSF is asked to describe the bond model's step.
STEP_PRECISION = 0.01


@dataclass(frozen=True)
class StepRecord:
    """A velocity-step record of a model: friction (stress / sigma_c) sampled uniformly in slip.

    ``protocol`` is the slider's history from the record's first row (time 0); ``interpolation_error`` the largest
    change of the resampled friction when every other solver step is dropped (a bound on the spline's error).
    """

    name: str
    record: Any  # stickslip.rsf.data.LabRecord
    protocol: Protocol
    sigma_c: float
    interpolation_error: float
    cpu: float = 0.0


@dataclass(frozen=True)
class Reading:
    """One RSF fit to a :class:`StepRecord`: the law, how well it describes the record, the values found."""

    law: str
    states: int
    fit: Any  # stickslip.rsf.fit.RSFFit
    precision: float
    friction_range: float

    @property
    def status(self) -> str:
        return str(self.fit.status)

    @property
    def residuals(self) -> np.ndarray:
        return np.asarray(self.fit.residuals, float)

    @property
    def chi_square(self) -> float:
        return float(np.sum((self.residuals / self.precision) ** 2))

    @property
    def free(self) -> int:
        return sum(1 for p in self.fit.parameters.values() if not p.fixed)

    @property
    def rms(self) -> float:
        return float(self.fit.rms)

    @property
    def relative_rms(self) -> float:
        """rms misfit over the record's friction range."""
        return self.rms / self.friction_range

    @property
    def worst(self) -> float:
        """Largest misfit over the record's friction range."""
        return float(np.max(np.abs(self.residuals))) / self.friction_range

    @property
    def lag_one(self) -> float:
        """Lag-one autocorrelation of the residuals: about 0 for noise, near 1 for a misfit with structure."""
        r = self.residuals - float(np.mean(self.residuals))
        total = float(np.sum(r * r))
        return float(np.sum(r[1:] * r[:-1]) / total) if total > 0 else 0.0

    def summary(self) -> dict[str, Any]:
        return {
            "law": self.law, "states": self.states, "status": self.status, "reason": self.fit.reason,
            "reduced_chi_square": float(self.fit.reduced_chi_square), "precision": self.precision,
            "rms": self.rms, "relative_rms": self.relative_rms, "worst_relative": self.worst,
            "lag_one": self.lag_one, "parameters": interval_table(self.fit),
        }  # fmt: skip


def resample_in_slip(
    time: np.ndarray,
    stress: np.ndarray,
    protocol: Protocol,
    spacing: float = SLIP_SPACING,
    window: float = WINDOW,
    lead: float = LEAD,
) -> tuple[np.ndarray, np.ndarray]:
    """A trace's stress on a grid uniform in slip: ``lead`` before each velocity change, ``window`` after it.

    Within each segment the solver's rows are joined by a cubic spline (never across a change, where the slope
    breaks).  Every segment must slide: a hold has no slip to sample by.
    """
    from scipy.interpolate import CubicSpline

    time, stress = np.asarray(time, float), np.asarray(stress, float)
    pieces = list(protocol.pieces())
    grids, values = [], []
    for i, (t0, t1, v) in enumerate(pieces):
        if not v > 0:
            raise DataError(f"segment {i + 1}: the slider must slide (velocity {v:g} m/s) to be sampled in slip")
        inside = (time >= t0 - 1e-12 * max(t1, 1.0)) & (time <= t1 + 1e-12 * max(t1, 1.0))
        t, s = np.unique(time[inside], return_index=True)
        if t.size < 4:
            raise DataError(f"segment {i + 1}: {t.size} rows of the trace; expected at least 4 to interpolate")
        spline = CubicSpline(t, stress[inside][s])
        slip = (t1 - t0) * v
        spans = [(max(0.0, slip - lead), slip)] if i == 0 else [(0.0, min(slip, window))]
        if 0 < i < len(pieces) - 1 and slip > window:
            spans.append((max(window, slip - lead), slip))
        for lo, hi in spans:
            n = max(math.ceil((hi - lo) / spacing), 1)
            grid = t0 + np.linspace(lo, hi, n + 1) / v
            grids.append(grid)
            values.append(spline(grid))
    grid = np.concatenate(grids)
    kept, first = np.unique(grid, return_index=True)
    return kept, np.concatenate(values)[first]


def _from(protocol: Protocol, start: float) -> Protocol:
    """``protocol`` seen from time ``start`` on (the part before it dropped)."""
    kept = [Segment(v, t1 - max(start, t0)) for t0, t1, v in protocol.pieces() if t1 > start]
    return Protocol(tuple(kept), name=protocol.name)


def step_record(
    time: np.ndarray,
    stress: np.ndarray,
    protocol: Protocol,
    sigma_c: float,
    name: str = "bond model",
    cpu: float = 0.0,
    window: float = WINDOW,
) -> StepRecord:
    """A :class:`StepRecord` from a trace (time in s, stress in Pa) of the slider history ``protocol``, ``window``
    of slip (m) after each change."""
    from ..rsf.data import LabRecord

    t, s = resample_in_slip(time, stress, protocol, window=window)
    # the spline's own error: drop every other solver row and see how much the resampled stress moves
    keep = np.ones(np.asarray(time).size, bool)
    keep[1:-1:2] = False
    edges = np.isin(np.asarray(time, float), protocol.boundaries)
    keep |= edges
    try:
        _, coarse = resample_in_slip(np.asarray(time)[keep], np.asarray(stress)[keep], protocol, window=window)
        interpolation = float(np.max(np.abs(coarse - s))) / sigma_c
    except DataError:
        interpolation = math.nan
    shifted = _from(protocol, float(t[0]))
    record = LabRecord.from_arrays(t, protocol.displacement_at(t), s / sigma_c, source=name)
    return StepRecord(name, record, shifted, sigma_c, interpolation, cpu)


def bond_step(
    params: Any, velocities: list[float], rtol: float = TRACE_RTOL, name: str | None = None, window: float = WINDOW
) -> StepRecord:  # fmt: skip
    """The time-dependent bond model's response to the slider velocities ``velocities`` (m/s), from steady
    sliding at the first: ``lead`` of slip at the first velocity, then ``window`` at each of the others."""
    from ..transient import run_transient

    _check_steps(velocities, window)
    sigma_c = _critical(params)[1]
    durations = [LEAD / velocities[0]] + [window / v for v in velocities[1:]]
    protocol = velocity_steps(velocities, durations)
    start = _time.process_time()
    run = run_transient(params, protocol, control="velocity", start="steady", rtol=rtol)
    cpu = _time.process_time() - start
    label = name or " -> ".join(f"{v * 1e6:.4g}" for v in velocities) + " µm/s"
    return step_record(run.time, run.stress, protocol, sigma_c, label, cpu, window)


def _critical(params: Any) -> tuple[float, float]:
    """Vc (m/s) and sigma_c (Pa) of the bond model, which its friction is normalised by."""
    from ..quasistatic.critical import critical_point

    cp = critical_point(params)
    if not cp.exists or cp.velocity is None or cp.stress is None:
        raise ModelError(f"the bond model has no critical point here ({cp.message}); nothing to normalise by")
    return float(cp.velocity), float(cp.stress)


def _check_steps(velocities: Any, window: float) -> None:
    """Velocity steps to read: at least two positive velocities, each different from the one before."""
    try:
        speeds = [float(v) for v in velocities]
    except (TypeError, ValueError):
        raise ParameterError(f"velocities: expected a list of velocities in m/s, got {velocities!r}") from None
    if len(speeds) < 2:
        raise ParameterError(f"velocities: expected at least two (a step), got {len(speeds)}")
    for i, v in enumerate(speeds):
        if not (math.isfinite(v) and v > 0):
            raise ParameterError(f"velocities[{i}]: expected a positive velocity in m/s (the slider slides), got {v!r}")
        if i and v == speeds[i - 1]:
            raise ParameterError(f"velocities[{i}]: {v:g} m/s repeats the one before; expected a step")
    if not (isinstance(window, (int, float)) and math.isfinite(window) and window > 0):
        raise ParameterError(f"window: expected a positive slip in m, got {window!r}")


def read_step(
    step: StepRecord, law: str = "aging", states: int = 1, guess: dict[str, float] | None = None
) -> Reading:  # fmt: skip
    """Fit RSF (``law``, one or two ``states``, rig stiffness free) to ``step`` at the stated precision.

    Without ``guess`` the search starts from the values read off each velocity change in turn
    (:func:`step_guess`) and the lowest chi-square is kept: on a staircase the first
    change alone can start the search where it loses its way.
    """
    from ..rsf.fit import fit_record

    friction = step.record.friction
    span = float(np.ptp(friction))
    if not span > 0:
        raise DataError(f"{step.name}: the friction does not change; there is no step to read")
    if len(step.protocol.segments) < 2:
        raise DataError(f"{step.name}: one velocity only; there is no step to read")
    precision = STEP_PRECISION * span
    best = None
    for start in [guess] if guess else _guesses(step):
        fit = fit_record(step.record, law=law, states=states, protocol=step.protocol, guess=start, noise=precision)
        if best is None or fit.reduced_chi_square < best.reduced_chi_square * (1 - 1e-9):
            best = fit
    return Reading(law, states, best, precision, span)


def step_guess(time: np.ndarray, friction: np.ndarray, protocol: Protocol) -> dict[str, float]:
    """RSF starting values read off a velocity-step trace: the levels give a - b, the peak (the direct effect) a,
    the slip over which the peak decays by e Dc, and the slip of the rise the rig stiffness."""
    v0, v1 = protocol.segments[0].velocity, protocol.segments[1].velocity
    change = protocol.boundaries[1]
    before, after = time < change, time >= change
    mu0 = float(np.median(friction[before][-max(before.sum() // 10, 1) :]))
    tail = friction[after]
    mu1 = float(np.median(tail[-max(tail.size // 10, 1) :]))
    log_ratio = math.log(v1 / v0)
    up = v1 > v0
    k = int(np.argmax(tail) if up else np.argmin(tail))
    peak, t_after = float(tail[k]), time[after]
    overshoot = (peak - mu1) if up else (mu1 - peak)
    a = (peak - mu0) / log_ratio if overshoot > 0 else 1.5 * (mu1 - mu0) / log_ratio
    b = a - (mu1 - mu0) / log_ratio
    excess = np.abs(tail[k:] - mu1)
    decayed = np.nonzero(excess < excess[0] / math.e)[0]
    dc = v1 * float(t_after[k + decayed[0]] - t_after[k]) if decayed.size and overshoot > 0 else 1e-6
    rise = v1 * max(float(t_after[k] - change), 1e-12)
    return {"mu0": mu0, "a": abs(a), "b": b, "dc": max(dc, 1e-9), "stiffness": max(abs(peak - mu0) / rise, 1.0)}


def _guesses(step: StepRecord) -> list[dict[str, float]]:
    """Starting values read off each velocity change of ``step`` (mu0 is always the record's first level)."""
    time, friction = step.record.time, step.record.friction
    edges, segments = step.protocol.boundaries, step.protocol.segments
    out = []
    for i in range(1, len(segments)):
        inside = (time >= edges[i - 1]) & (time <= edges[i + 1])
        pair = Protocol((segments[i - 1], Segment(segments[i].velocity, edges[i + 1] - edges[i])))
        guess = step_guess(time[inside] - edges[i - 1], friction[inside], pair)
        out.append({**guess, "mu0": float(friction[0])})
    return out


def f_test(one: Reading, two: Reading) -> tuple[float, float]:
    """F statistic and p value of ``two`` (more parameters) against ``one`` on the same record.

    It assumes independent residuals; with the strongly correlated residuals of a systematic misfit a tiny p
    says only that the extra parameters reduce chi-square, not that the richer law describes the record.
    """
    from scipy import stats

    n = one.residuals.size
    extra, dof = two.free - one.free, n - two.free
    if extra <= 0 or dof <= 0 or two.chi_square <= 0:
        return math.nan, math.nan
    value = max(one.chi_square - two.chi_square, 0.0) / extra / (two.chi_square / dof)
    return float(value), float(stats.f.sf(value, extra, dof))


def interval_table(fit: Any) -> dict[str, dict[str, Any]]:
    """{name: {value, interval}} in SI for a, b, dc (b2, dc2), stiffness, mu0.

    The interval is the one the residuals support: widened by sqrt(chi-square_r) when the misfit exceeds the
    stated precision (``scaled_interval``), else the fit's own; None where the value is not constrained.
    """
    out: dict[str, dict[str, Any]] = {}
    for name in ("mu0", "a", "b", "dc", "b2", "dc2", "stiffness"):
        p = getattr(fit, "parameters", {}).get(name)
        if p is None:
            continue
        pair = p.scaled_interval or p.interval
        out[name] = {"value": float(p.value), "interval": None if pair is None else [float(pair[0]), float(pair[1])],
                     "constrained": bool(p.constrained)}  # fmt: skip
    return out


#: the velocity histories read (um/s): steps up and down of three sizes, the two together, and a staircase
CASES: dict[str, tuple[float, ...]] = {
    "up 100 -> 1000": (100, 1000),
    "down 1000 -> 100": (1000, 100),
    "up and down 100 -> 1000 -> 100": (100, 1000, 100),
    "up 100 -> 300": (100, 300),
    "down 300 -> 100": (300, 100),
    "up 300 -> 3000": (300, 3000),
    "down 3000 -> 300": (3000, 300),
    "staircase 150 -> 300 -> 600 -> 1200 -> 2400": (150, 300, 600, 1200, 2400),
}
#: the laws read
LAWS: tuple[tuple[str, int], ...] = (("aging", 1), ("slip", 1), ("aging", 2), ("slip", 2))


@dataclass
class Study:
    """Every case read with every law (:func:`run_study`)."""

    steps: dict[str, StepRecord] = field(default_factory=dict)
    readings: dict[str, dict[str, Reading]] = field(default_factory=dict)

    def summary(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for name, step in self.steps.items():
            fits = self.readings[name]
            tests = {}
            for law in ("aging", "slip"):
                if f"{law} 1" in fits and f"{law} 2" in fits:
                    value, p = f_test(fits[f"{law} 1"], fits[f"{law} 2"])
                    tests[law] = {"F": value, "p": p}
            out[name] = {
                "rows": len(step.record), "interpolation_error": step.interpolation_error, "cpu": step.cpu,
                "fits": {k: r.summary() for k, r in fits.items()}, "f_test_two_states": tests,
            }  # fmt: skip
        return out


def run_study(params: Any = None, cases: dict[str, tuple[float, ...]] | None = None) -> Study:
    """Read every case of :data:`CASES` (or ``cases``) with every law of :data:`LAWS`."""
    from ..parameters import load_parameters

    params = load_parameters("gelatin-glass") if params is None else params
    study = Study()
    for name, speeds in (cases or CASES).items():
        step = bond_step(params, [v * 1e-6 for v in speeds], name=name)
        study.steps[name] = step
        study.readings[name] = {f"{law} {n}": read_step(step, law, n) for law, n in LAWS}
    return study


def trace_error(params: Any, velocities: list[float], rtol: float = TRACE_RTOL) -> float:
    """Largest change of the resampled friction between ``rtol`` and ``rtol / 10`` (the trace's own error)."""
    coarse = bond_step(params, velocities, rtol)
    fine = bond_step(params, velocities, rtol / 10)
    return float(np.max(np.abs(coarse.record.friction - fine.record.friction)))


def main() -> None:  # pragma: no cover - prints the tables of docs/extensions.md section 3
    import json

    study = run_study()
    print(json.dumps(study.summary(), indent=1, default=float))


if __name__ == "__main__":  # pragma: no cover
    main()
