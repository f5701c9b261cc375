"""Fit the stick-phase parameters (Eq 15) to measured stick times, like the paper's Table 1.

Each row is one stick phase from ``start_stress`` (sigma_c of the bond parameters where the cell is empty, or in
every row with ``start_stress="model"``: for start stresses a sensor's drift or offset moved) at the measured
loading rate ``stick_slope``, else K V0 (Eq 17); the model's t_s and sigma_s come from
:func:`stickslip.quasistatic.stick.stick_phase`.  Nc0, uc/tau and tau_a are fitted as ln-values on the residuals
ln(model/measured); a direction the data do not determine is fixed with a message, as the steady fit does
(docs/fitting.md).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.special import stdtrit

from ..columns import with_units
from ..errors import DataError, ParameterError
from ..parameters import Parameters, available_parameter_sets, key_dimension, load_parameters, replace
from ..quasistatic.critical import critical_point
from ..reprs import compact_repr
from ..units import override_to_si
from . import identify
from .data import CYCLE_START_TIME, StickData, read_stick_data, requested_rows
from .input_uncertainty import FitCovariance, matching_covariance, read_fit_covariance
from .problem import JACOBIAN_STEP, SEARCH_BOX
from .results import Estimate, human, log_interval, unusable
from .scatter import STICK_OUTLIER_SPREADS, outlying
from .stick_batch import stick_times

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    from matplotlib.axes import Axes

STICK_KEYS = ("stick.attached_chains", "stick.break_rate", "stick.aging_time")
#: Fixed first when the data leave a direction undetermined.
STICK_FIX_PREFERENCE = ("stick.aging_time", "stick.break_rate", "stick.attached_chains")
#: ln-residual given to a row whose block never slips in the model (a factor e^5 off).
STUCK_RESIDUAL = 5.0
#: Evaluations per (free parameter + 1) allowed in the first pass of the fit.
FIRST_PASS_EVALUATIONS = 4
#: Factors of Nc0 tried for the start (:func:`_scanned_start`).
SCAN_FACTORS = (0.25, 0.4, 0.63, 0.8, 1.0, 1.25, 1.6, 2.5, 4.0)
#: Confidence levels the fit's intervals may have (``fit stick --level`` takes the same: one range, tested).
LEVEL_RANGE = (0.5, 0.999)
#: Where each stick starts (``fit stick --start-stress``): "measured", the table's start_stress (σc of the bond
#: parameters where a cell is empty); "model", σc of the bond parameters in every row (the table's are compared).
START_STRESS_MODES = ("measured", "model")


@dataclass(frozen=True)
class StartDrift:
    """A trend of the measured start stresses within one pulling velocity's rows (:func:`_start_drifts`)."""

    pulling_velocity: float  # m/s
    rows: tuple[int, ...]  # file rows, in the order of the trend's axis
    drift: float  # Pa, from the first row to the last along the fitted line
    rate: float | None  # Pa/s where the table dates its cycles (start_time), else None
    t_value: float  # the trend's slope over its standard error
    scatter: float  # Pa, the start stresses' scatter about the line
    sensitivity: float  # d ln t_s / d sigma_0 of the model (1/Pa), median over the rows
    time_scatter: float  # relative scatter of the rows' stick times (about their mean)
    loading_rate: float | None = None  # Pa/s, the rows' median measured stick_slope (None: not measured)

    def as_dict(self) -> dict[str, Any]:
        """The drift in the JSON's names (their units: :data:`JSON_UNITS`)."""
        return {
            "pulling_velocity": self.pulling_velocity,
            "rows": list(self.rows),
            "drift": self.drift,
            "drift_rate": self.rate,
            "t_value": self.t_value,
            "scatter": self.scatter,
            "sensitivity": self.sensitivity,
            "relative_time_scatter": self.time_scatter,
            "loading_rate": self.loading_rate,
        }


#: Units of the keys of :meth:`StickFit.as_dict` that the column registry does not name (``fit stick --json``'s
#: ``units`` map): the start stresses' drift (Pa over the rows, Pa/s, the t value of its slope, the scatter about
#: it, d ln t_s/d sigma_0, the stick times' relative scatter) and the combination Nc0·kT/lambda.
JSON_UNITS = {
    "drift": "Pa", "drift_rate": "Pa/s", "t_value": "1", "scatter": "Pa", "sensitivity": "1/Pa",
    "relative_time_scatter": "1", "stick_stress_scale": "Pa",
}  # fmt: skip


@dataclass(frozen=True)
class StickFit:
    """Result of :func:`fit_stick` (SI units)."""

    data: StickData
    parameters: Parameters
    start: Parameters
    estimates: tuple[Estimate, ...]
    free_keys: tuple[str, ...]
    covariance: np.ndarray
    correlation: np.ndarray
    used: np.ndarray  # bool per row
    excluded: dict[int, str]  # file row -> reason
    start_stress: np.ndarray
    loading_rate: np.ndarray
    model_stick_time: np.ndarray
    model_peak_stress: np.ndarray
    fitted_peak_stress: bool
    chi_square: float
    dof: int
    noise: str
    noise_scale: float
    level: float
    messages: tuple[str, ...]
    status: str = "ok"  # "failed" when the fit cannot be trusted; ``reason`` says why
    reason: str = ""
    #: velocities whose mean's error was floored by the table's own uncertainties:
    #: (pulling velocity m/s, floor, scatter of the mean; both relative, in ln t_s)
    floors: tuple[tuple[float, float, float], ...] = ()
    #: where the sticks start (START_STRESS_MODES)
    start_stress_mode: str = "measured"
    #: Nc0·kT/λ, the combination the stick times determine whatever λ is (derived; Eq 15 holds Nc0 only there)
    combinations: tuple[Estimate, ...] = ()
    #: what the intervals are conditional on, or whose uncertainty they include (one sentence)
    intervals_note: str = ""
    #: the bond-parameter keys whose covariance (written by fit steady -o) the intervals include (empty: conditional)
    input_keys: tuple[str, ...] = ()
    #: the covariance of the fitted ln-parameters with the bond parameters held fixed (= ``covariance`` when
    #: ``input_keys`` is empty)
    conditional_covariance: np.ndarray | None = None
    #: trends of the measured start stresses within a velocity's rows beyond their scatter (a sensor drift?)
    start_drifts: tuple[StartDrift, ...] = ()

    __repr__ = compact_repr  # counts, not hundreds of array elements

    @property
    def success(self) -> bool:
        return self.status == "ok"

    @property
    def reduced_chi_square(self) -> None:
        """Not a test of the fit: the noise is estimated from the residuals, so chi^2/dof is 1 by construction."""
        return None

    def left_out(self) -> dict[int, str]:
        """Every file row not fitted, with why: those the reader left out (a cycles table's cut cycles) and those the
        fit did (--exclude-row, V0 above Vc), in file order."""
        rows = dict(self.data.left_out)
        rows.update((int(r), self.excluded.get(int(r), "")) for r, u in zip(self.data.rows, self.used, strict=True)
                    if not u)  # fmt: skip
        return dict(sorted(rows.items()))

    def rows_line(self) -> str:
        """ "13 of 18 rows fitted; 5 left out: rows 2, 3, 9, 10, 19 (why)": the table's rows, the reader's left-outs
        counted in (the Notes and the Rows table say the same)."""
        left = self.left_out()
        total = len(self.data) + len(self.data.left_out)
        text = f"{int(self.used.sum())} of {total} rows fitted"
        if not left:
            return text
        reasons: dict[str, list[int]] = {}
        for row, why in left.items():
            reasons.setdefault(why, []).append(row)
        groups = "; ".join(
            f"{'rows' if len(rows) > 1 else 'row'} {', '.join(map(str, rows))}" + (f" ({why})" if why else "")
            for why, rows in reasons.items()
        )
        return f"{text}; {len(left)} left out: {groups}"

    def to_frame(self) -> pd.DataFrame:
        frame = self.data.to_frame()
        frame["used"] = self.used
        frame["start_stress_used"] = self.start_stress
        frame["loading_rate"] = self.loading_rate
        frame["model_stick_time"] = self.model_stick_time
        frame["model_peak_stress"] = self.model_peak_stress
        return with_units(frame, frame.attrs["units"])  # the table's own extra columns keep their units

    def as_dict(self) -> dict[str, Any]:
        return {
            "status": self.status,
            **({"reason": self.reason} if self.reason else {}),
            "parameters": {e.key: e.as_dict() for e in self.estimates},
            "combinations": {e.key: e.as_dict() | {"symbol": e.symbol} for e in self.combinations},
            "start_stress": self.start_stress_mode,
            "intervals": {
                "conditional_on_bond_parameters": not self.input_keys,
                "bond_parameter_uncertainty_of": list(self.input_keys),
                "note": self.intervals_note,
            },
            "start_stress_drifts": [d.as_dict() for d in self.start_drifts],
            "chi_square": self.chi_square,
            "dof": self.dof,
            "reduced_chi_square": self.reduced_chi_square,
            "noise": self.noise,
            "relative_noise": self.noise_scale,
            "confidence_level": self.level,
            "error_floors": [
                {"pulling_velocity": v, "relative_floor": floor, "relative_scatter": scatter}
                for v, floor, scatter in self.floors
            ],
            "correlation": {"keys": list(self.free_keys), "matrix": self.correlation.tolist()},
            "rows": [
                {
                    "row": int(r),
                    "used": bool(u),
                    "pulling_velocity": float(v),
                    "stick_time": float(t),
                    "model_stick_time": float(m) if u else None,
                    "model_peak_stress": float(s) if u else None,
                    "excluded": self.excluded.get(int(r)),
                }
                for r, u, v, t, m, s in zip(
                    self.data.rows,
                    self.used,
                    self.data.pulling_velocity,
                    self.data.stick_time,
                    self.model_stick_time,
                    self.model_peak_stress,
                    strict=True,
                )
            ],
            # the file rows the reader left out (a cycles table's cut cycles): not in "rows", counted in the report
            "left_out_rows": [{"row": r, "reason": why} for r, why in self.data.left_out],
            "messages": list(self.messages),
        }

    def stick_time_curve(self, velocity: Any) -> tuple[np.ndarray, float, float]:
        """The fitted t_s(V0) (s) at ``velocity`` (m/s), NaN where the block does not slip within 100 times
        the longest measured stick time; the start stress and the stiffness used are the medians over the
        fitted rows (start stress, loading rate / V0).  Returns (t_s, start stress Pa, stiffness Pa/m)."""
        velocity = np.atleast_1d(np.asarray(velocity, dtype=float))
        start = float(np.median(self.start_stress[self.used]))
        stiffness = float(np.median(self.loading_rate[self.used] / self.data.pulling_velocity[self.used]))
        longest = 100.0 * float(np.max(self.data.stick_time))
        rows = _Rows(
            velocity, np.full(velocity.size, start), stiffness * velocity, np.full(velocity.size, longest), None
        )
        return _stick_times([self.parameters], rows, horizon_factor=1.0)[0], start, stiffness

    def report(self) -> str:
        from .report import stick_report

        return stick_report(self)

    def plot(self, ax: Axes | None = None) -> Axes:
        from ..plots.fits import plot_stick_fit

        return plot_stick_fit(self, ax=ax)


@dataclass(frozen=True)
class _Rows:
    velocity: np.ndarray
    start: np.ndarray
    rate: np.ndarray  # d sigma/dt in the stick phase, Pa/s
    stick_time: np.ndarray
    peak: np.ndarray | None  # only when fitted
    #: the rows' own systematic uncertainties (the table's *_uncertainty columns; 0 where not given): start stress
    #: (Pa), stick time (s), peak stress (Pa)
    start_err: np.ndarray | None = None
    time_err: np.ndarray | None = None
    peak_err: np.ndarray | None = None


def _params_for_rate(params: Parameters, velocity: float, rate: float) -> Parameters:
    """Parameters whose Eq 17 loading rate K V0 equals the measured ``rate`` (by the shear modulus)."""
    block = params.block
    modulus = rate / (velocity * block.geometric_factor) * block.height
    return replace(params, block={"shear_modulus": modulus})


def _model(params: Parameters, rows: _Rows) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Stick times and peak stresses of the rows; where the chains do not collapse within the fit's horizon
    the full solver (:func:`stick_phase`) says what happens instead (NaN and its message)."""
    times = _stick_times([params], rows)[0]
    problems = []
    if np.all(np.isfinite(times)):
        return times, rows.start + rows.rate * times, problems
    from ..quasistatic.stick import stick_phase  # only here: it loads scipy.integrate (~30 ms of the command)

    for k in np.nonzero(~np.isfinite(times))[0]:
        v, s0, rate = float(rows.velocity[k]), float(rows.start[k]), float(rows.rate[k])
        phase = stick_phase(_params_for_rate(params, v, rate), v, start_stress=s0)
        if phase.stick_time is None:
            problems.append(phase.message)
        else:
            times[k] = phase.stick_time
    return times, rows.start + rows.rate * times, problems


def _stick_times(sets: Sequence[Parameters], rows: _Rows, horizon_factor: float | None = None) -> np.ndarray:
    """t_s of every row for every parameter set, shape (sets, rows); NaN beyond e^STUCK_RESIDUAL times the
    measured stick time (:func:`stick_batch.stick_times`, all sets and rows in one vectorised march)."""
    b = np.array([[p.bonds.force_sensitivity] for p in sets])
    nc0 = np.array([[p.stick.attached_chains] for p in sets])
    r = np.array([[p.stick.break_rate] for p in sets])
    inv_aging = np.array([[1.0 / p.stick.aging_time] for p in sets])
    factor = math.exp(STUCK_RESIDUAL) if horizon_factor is None else horizon_factor
    horizon = factor * rows.stick_time[None, :]
    shape = (len(sets), rows.stick_time.size)
    times = stick_times(r, b * rows.start / nc0, b * rows.rate / nc0, inv_aging, horizon)
    return times.reshape(shape)


def _residuals_many(sets: Sequence[Parameters], rows: _Rows) -> np.ndarray:
    """ln(model/measured) of t_s (and sigma_s where fitted) for each set; STUCK_RESIDUAL where the block has
    not slipped by e^STUCK_RESIDUAL times the measured time (so the residual is continuous there)."""
    times = _stick_times(sets, rows)
    r = np.log(times / rows.stick_time)
    if rows.peak is not None:
        r = np.concatenate([r, np.log((rows.start + rows.rate * times) / rows.peak)], axis=1)
    return np.where(np.isfinite(r), np.minimum(r, STUCK_RESIDUAL), STUCK_RESIDUAL)


def _residuals(params: Parameters, rows: _Rows) -> np.ndarray:
    return _residuals_many([params], rows)[0]


def _with(params: Parameters, keys: Sequence[str], theta: Sequence[float]) -> Parameters:
    values = {k.split(".")[1]: math.exp(float(t)) for k, t in zip(keys, theta, strict=True)}
    return replace(params, stick=values) if values else params


def _jacobian(params: Parameters, keys: Sequence[str], theta: np.ndarray, rows: _Rows) -> np.ndarray:
    """Central differences in the ln-parameters, all 2p perturbed sets in one batch."""
    return _Evaluator(params, keys, rows)(theta)[1]


class _Evaluator:
    """Residuals and their Jacobian at theta from one batch (the centre and the 2p perturbed sets).

    The optimiser asks for the residuals and then, at the same point, for the Jacobian: one vectorised
    march serves both, for about the price of one (the march advances all phases together).
    """

    def __init__(self, params: Parameters, keys: Sequence[str], rows: _Rows) -> None:
        self.params, self.keys, self.rows = params, keys, rows
        self.last: tuple[bytes, np.ndarray, np.ndarray] | None = None

    def __call__(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        key = np.asarray(theta, dtype=float).tobytes()
        if self.last is None or self.last[0] != key:
            sets = [_with(self.params, self.keys, theta)]
            for k in range(len(self.keys)):
                for sign in (1.0, -1.0):
                    shifted = np.array(theta, dtype=float)
                    shifted[k] += sign * JACOBIAN_STEP
                    sets.append(_with(self.params, self.keys, shifted))
            r = _residuals_many(sets, self.rows)
            jac = ((r[1::2] - r[2::2]) / (2 * JACOBIAN_STEP)).T
            self.last = (key, r[0], jac)
        return self.last[1], self.last[2]


def _minimize(
    params: Parameters, keys: Sequence[str], centre: np.ndarray, rows: _Rows, max_nfev: int | None = None
) -> tuple[Parameters, float, bool]:
    """Least squares in the ln-parameters (scipy's trust-region reflective, bounded to the search box)."""
    from scipy.optimize import least_squares

    theta0 = np.array([math.log(params.as_dict()[k]) for k in keys])
    lower, upper = centre - SEARCH_BOX, centre + SEARCH_BOX
    evaluate = _Evaluator(params, keys, rows)
    # stick times are known to a few per cent: tolerances of 1e-6 are ample and save integrations
    result = least_squares(
        lambda theta: evaluate(theta)[0],
        np.clip(theta0, lower, upper),
        jac=lambda theta: evaluate(theta)[1],
        bounds=(lower, upper),
        method="trf",
        ftol=1e-6,
        xtol=1e-6,
        gtol=1e-6,
        max_nfev=max_nfev,
    )
    fitted = _with(params, keys, result.x)
    r = _residuals(fitted, rows)
    return fitted, float(r @ r), bool(result.success)


def _select_rows(
    data: StickData, params: Parameters, exclude: Sequence[int], include_steady: bool
) -> tuple[np.ndarray, dict[int, str], float | None, list[str]]:
    messages: list[str] = []
    exclude = requested_rows(exclude, data.rows, data.source)  # the steady fit's parser too
    point = critical_point(params)
    vc = point.velocity if point.exists else None
    used = np.ones(len(data), dtype=bool)
    excluded: dict[int, str] = {}
    for k, row in enumerate(data.rows):
        row = int(row)
        if row in exclude:
            used[k], excluded[row] = False, "excluded by request"
        elif vc is not None and not include_steady and data.pulling_velocity[k] >= vc:
            used[k] = False
            excluded[row] = f"V0 above Vc = {human(vc, 'velocity')}: steady sliding, a start from rest"
    steady_rows = [r for r, why in excluded.items() if why.startswith("V0 above")]
    if steady_rows:
        messages.append(
            f"{'rows' if len(steady_rows) > 1 else 'row'} {', '.join(map(str, steady_rows))} left out: pulling"
            " velocity above the critical velocity"
            f" {human(vc, 'velocity')} of the bond parameters, where sliding is steady and the one stick is a"
            " start from rest, not a stick at σc (use --include-steady to keep them)"
        )
    return used, excluded, (point.stress if point.exists else None), messages


def _too_few_rows(data: StickData, usable: int, excluded: Mapping[int, str], params: Parameters) -> str:
    """The error for fewer than two usable rows, naming which rows were left out and why (a tester's Table 1 with
    its velocities headed [m/s] for µm/s: "0 usable row(s)" and nothing else; round 30), and, where rows were left
    out above Vc, the unit that would put them below it."""
    text = f"{data.source}: {usable} usable row(s); need at least 2 stick phases to fit"
    reasons: dict[str, list[int]] = {}
    for row, why in excluded.items():
        reasons.setdefault(why, []).append(row)
    parts = []
    for why, rows in reasons.items():
        shown = ", ".join(map(str, rows[:8])) + (f" and {len(rows) - 8} more" if len(rows) > 8 else "")
        parts.append(f"{'rows' if len(rows) > 1 else 'row'} {shown} left out ({why})")
    if parts:
        text += ": " + "; ".join(parts)
    above = [k for k, row in enumerate(data.rows) if excluded.get(int(row), "").startswith("V0 above")]
    if above:
        v = data.pulling_velocity[above]
        vc = critical_point(params).velocity
        low, high = human(float(np.min(v)), "velocity"), human(float(np.max(v)), "velocity")
        text += f"; their pulling velocities are {low} to {high}"
        for unit, factor in (("mm/s", 1e-3), ("um/s", 1e-6), ("nm/s", 1e-9)):
            if float(np.max(v)) * factor < vc:  # the unit that would put every one of them below Vc
                column = "pulling_velocity"
                text += (
                    f": if they are in {unit}, the column's unit is wrong (a header such as {column} [{unit}]); if"
                    " they are right, --include-steady keeps them"
                )
                break
        else:
            text += "; --include-steady keeps them"
    return text


def fit_stick(
    table: StickData | str | Path,
    params: Parameters | str | None = None,
    fix: Mapping[str, Any] | None = None,
    free: Sequence[str] | None = None,
    exclude_rows: Sequence[int] = (),
    include_steady: bool = False,
    level: float = 0.95,
    start_stress: str = "measured",
    bond_covariance: FitCovariance | bool | None = None,
) -> StickFit:
    """Fit Nc0, uc/tau and the stick aging time (Eq 15) to measured stick times (module docstring).

    ``params`` supplies the bond parameters (lambda/kT, and sigma_c where a
    row has no start stress), the block and the start values; ``fix`` holds
    stick keys at given values; ``free`` lists keys the user insists on
    fitting (they are fixed only if nothing else pins an undetermined direction); ``level``, the intervals'
    confidence level, is taken from LEVEL_RANGE (0.5-0.999), as ``--level``.

    ``start_stress``: "measured" (each row's start_stress; sigma_c of the bond parameters where empty) or "model"
    (sigma_c of the bond parameters in every row: for start stresses a sensor's drift or offset has moved; Eq 15
    turns 1 Pa of start stress into ~1 % of t_s).  ``bond_covariance``: the covariance of the bond parameters'
    ln-values that ``fit steady -o`` writes into its file (:mod:`stickslip.fitting.input_uncertainty`), carried
    into the intervals; None reads it from ``params`` where that is such a file, False holds the bond parameters
    exact (the intervals are then conditional on them, and the result says so).
    """
    if isinstance(free, str):  # one key: iterating the string would give its characters
        free = [free]
    if start_stress not in START_STRESS_MODES:
        raise ParameterError(
            f"start_stress: expected one of {', '.join(START_STRESS_MODES)} (as --start-stress), got {start_stress!r}"
        )
    data = table if isinstance(table, StickData) else read_stick_data(table)
    notes = data.notes()
    low, high = LEVEL_RANGE
    number = isinstance(level, (int, float, np.integer, np.floating)) and not isinstance(level, bool)
    if not (number and low <= level <= high):
        raise ParameterError(f"level: expected a confidence level from {low:g} to {high:g} (as --level), got {level!r}")
    if bond_covariance is None:  # a file's, not a built-in set's (they carry none)
        builtin = isinstance(params, str) and params in available_parameter_sets()
        bond_covariance = read_fit_covariance(params if isinstance(params, (str, Path)) and not builtin else None)
    elif bond_covariance is True or not (bond_covariance is False or isinstance(bond_covariance, FitCovariance)):
        raise ParameterError(
            f"bond_covariance: expected a FitCovariance, None (read from the params file) or False, got"
            f" {bond_covariance!r}"
        )
    base = params if isinstance(params, Parameters) else load_parameters(params or "gelatin-glass")
    fixed: dict[str, float] = {}
    for key, raw in (fix or {}).items():
        _check_stick_key(key, "--fix")
        fixed[key] = override_to_si(raw, key_dimension(key), key)
    base = base.with_overrides(fixed) if fixed else base
    for key in free or ():
        _check_stick_key(key, "--free")
        if key in fixed:
            raise ParameterError(f"{key} is given both to --fix and to --free")
    keys = [k for k in STICK_KEYS if k not in fixed]
    used, excluded, sigma_c, messages = _select_rows(data, base, exclude_rows, include_steady)
    messages[:0] = notes
    start, rate = _start_column(data, sigma_c, start_stress), _rate_column(data, base)
    from_model = _from_model(data, start_stress)  # rows whose stick starts at the bond parameters' σc
    rows, fitted_peak = _rows(data, used, start, rate, sigma_c, messages, start_stress)
    n_obs = rows.stick_time.size + (0 if rows.peak is None else rows.peak.size)
    if rows.stick_time.size < 2:
        raise DataError(_too_few_rows(data, rows.stick_time.size, excluded, base))
    undetermined: list[str] = []
    centre_all = {k: math.log(base.as_dict()[k]) for k in STICK_KEYS}
    current = base
    protected = list(free or ())
    while len(keys) >= n_obs:
        key = identify.choose_key_to_fix(
            keys, identify.Direction(math.inf, {k: 1.0 for k in keys}), protected, STICK_FIX_PREFERENCE
        )
        _fix(keys, undetermined, messages, key, base, "more parameters than observations")
    current = _scanned_start(current, keys, rows)
    for _ in range(len(keys) + 1):
        if not keys:
            break
        centre = np.array([centre_all[k] for k in keys])
        # a short first pass: the determined directions converge quickly, an undetermined one would
        # be followed for hundreds of ODE solves before the optimiser gives up on it
        current, _, converged = _minimize(
            current, keys, centre, rows, max_nfev=FIRST_PASS_EVALUATIONS * (len(keys) + 1)
        )
        bad = _undetermined(current, keys, rows, n_obs)
        if not bad:
            if not converged:
                current, _, _ = _minimize(current, keys, centre, rows)
                bad = _undetermined(current, keys, rows, n_obs)
            if not bad:
                break
        key = identify.choose_key_to_fix(keys, bad[0], protected, STICK_FIX_PREFERENCE)
        current = current.with_overrides({key: base.as_dict()[key]})
        _fix(keys, undetermined, messages, key, base, f"the direction {bad[0].describe()} is unconstrained")
    dof = n_obs - len(keys)
    r = _residuals(current, rows)
    chi = float(r @ r)
    scale2 = chi / dof if dof > 0 else float("nan")
    theta = np.array([math.log(current.as_dict()[k]) for k in keys])
    jac = _jacobian(current, keys, theta, rows) if keys else np.zeros((n_obs, 0))
    covariance, floors = np.zeros((0, 0)), []
    own = _floors(current, rows, from_model[used])  # the table's own uncertainties in ln (zeros where none)
    if keys:  # the scatter's covariance, floored at each velocity by the table's own uncertainties (if any)
        covariance, floors = _covariance(jac, scale2, own, _blocks(rows))
    messages.extend(_floor_messages(floors))
    conditional = covariance
    inputs, unused_note = matching_covariance(bond_covariance or None, base)
    if unused_note:
        messages.append(unused_note)
    propagated = _bond_propagation(current, keys, rows, from_model[used], inputs, jac)
    if propagated is not None:
        covariance = covariance + propagated.stick
    sd = np.sqrt(np.clip(np.diag(covariance), 0, np.inf))
    correlation = covariance / np.outer(sd, sd) if keys else np.zeros((0, 0))
    q = float(stdtrit(max(dof, 1), 0.5 + level / 2))  # Student-t quantile (scipy.stats costs 0.2 s to import)
    estimates = []
    for key in STICK_KEYS:
        value = current.as_dict()[key]
        dim = key_dimension(key)
        if key in keys:
            s = float(sd[keys.index(key)])
            estimates.append(Estimate(key, identify.SYMBOLS[key], dim, value, value * s, log_interval(value, s, q)))
        else:
            reason = "fixed by request" if key in fixed else "not determined by the data; fixed at its input value"
            estimates.append(Estimate(key, identify.SYMBOLS[key], dim, value, status="fixed", note=reason))
    combinations = _combinations(current, keys, conditional, propagated, q)
    source = str(params) if isinstance(params, (str, Path)) else f"the set {base.name!r}"
    source = inputs.source if propagated is not None and inputs is not None and inputs.source else source
    intervals_note = _intervals_note(current, keys, conditional, propagated, bool(np.any(from_model[used])),
                                     sigma_c, source, inputs is not None)  # fmt: skip
    times, peaks, problems = _model(current, rows)
    model_t = np.full(len(data), np.nan)
    model_s = np.full(len(data), np.nan)
    model_t[used], model_s[used] = times, peaks
    messages.extend(f"model: {p}" for p in problems)
    messages.extend(_outliers(data, used, model_t))
    if dof <= 0:
        messages.append("no degrees of freedom left: the noise cannot be estimated and the errors are undefined")
    noise = f"relative (ln), estimated from the scatter: {100 * math.sqrt(scale2):.3g} %" if dof > 0 else "undefined"
    problems = _stick_problems(rows, current, keys, fixed, dof, scale2, problems, own[: rows.stick_time.size])
    sensitivity = _start_sensitivity(current, rows)
    drifts = _start_drifts(data, used, from_model, sensitivity) if start_stress == "measured" else []
    messages.extend(_offset_note(data, used, sigma_c, sensitivity, start_stress))
    if drifts:
        advice = _drift_advice(drifts, sigma_c)
        if problems:  # the likely cause, said in the reason
            problems.append(advice)
        else:
            messages.append(f"warning: {advice}")
    if problems:
        estimates = [unusable(e, "the fit failed") for e in estimates]
        combinations = [unusable(e, "the fit failed") for e in combinations]
    return StickFit(
        data=data,
        parameters=current,
        start=base,
        estimates=tuple(estimates),
        free_keys=tuple(keys),
        covariance=covariance,
        correlation=correlation,
        used=used,
        excluded=excluded,
        start_stress=start,
        loading_rate=rate,
        model_stick_time=model_t,
        model_peak_stress=model_s,
        fitted_peak_stress=fitted_peak,
        chi_square=chi,
        dof=dof,
        noise=noise,
        noise_scale=math.sqrt(scale2) if dof > 0 else float("nan"),
        level=level,
        messages=tuple(messages),
        status="failed" if problems else "ok",
        reason="; ".join(problems),
        floors=tuple(floors),
        start_stress_mode=start_stress,
        combinations=tuple(combinations),
        intervals_note=intervals_note,
        input_keys=() if propagated is None else propagated.keys,
        conditional_covariance=conditional,
        start_drifts=tuple(drifts),
    )


def _floors(params: Parameters, rows: _Rows, from_model: np.ndarray | None = None) -> np.ndarray:
    """Each observation's own systematic standard uncertainty in ln (the stick times', then the peak stresses' when
    fitted; zeros where the table gives none), from the table's ``*_uncertainty`` columns (docs/fitting.md).

    ``from_model``: the rows whose stick starts at the bond parameters' σc, not at the measured start stress
    (--start-stress model): the start stress's own uncertainty does not enter their start, and a start corner's
    time uncertainty moves only their measured t_s (it no longer cancels against a measured σc).

    The start stress's is carried into ln t_s by the model's own derivative d ln t_s / d sigma_0 and added in
    quadrature to the stick time's.  Where the start and the peak stress both have one and the peaks are not
    fitted (analyze's cycles: the corners of a measured stick line) they are read as the corners' time
    uncertainties dt0 = u(sigma_c)/rate and dt1 = u(sigma_s)/rate, which move sigma_c and t_s together.  The
    columns are bounds (the error lies within +-u): the standard uncertainty is u/sqrt(3) (a uniform error).
    """
    n = rows.stick_time.size
    size = n if rows.peak is None else 2 * n
    start_err = _or_zeros(rows.start_err, n)
    time_err = _or_zeros(rows.time_err, n)
    peak_err = _or_zeros(rows.peak_err, n)
    if not (np.any(start_err > 0) or np.any(time_err > 0) or (rows.peak is not None and np.any(peak_err > 0))):
        return np.zeros(size)
    step = FLOOR_STEP * rows.start
    shifted = [dataclasses.replace(rows, start=rows.start + sign * step) for sign in (1.0, -1.0)]
    with np.errstate(invalid="ignore", divide="ignore"):
        times = _stick_times([params], rows)[0]
        up, down = (_stick_times([params], r)[0] for r in shifted)
        dlog_t = (np.log(up) - np.log(down)) / (2 * step)
        # a start at the model's σc does not carry the measured start stress's uncertainty
        own_start = start_err if from_model is None else np.where(from_model, 0.0, start_err)
        floors = np.hypot(dlog_t * own_start, time_err / rows.stick_time)
        if rows.peak is None and rows.start_err is not None and rows.peak_err is not None:
            # the corners of a measured stick line (analyze's cycles): sigma_c = L(t0), sigma_s = L(t1), t_s = t1 - t0,
            # so an uncertainty dt0 of the start moves sigma_c by rate dt0 and t_s by -dt0 together, and
            # ln(model/measured) by dt0 (rate d ln t_s/d sigma_0 + 1/t_s): the two partly cancel
            start_time, end_time = start_err / rows.rate, peak_err / rows.rate
            corners = np.hypot(start_time * (rows.rate * dlog_t + 1.0 / rows.stick_time), end_time / rows.stick_time)
            if from_model is not None:  # a start at the model's σc: the start corner's time moves t_s alone
                alone = np.hypot(start_time, end_time) / rows.stick_time
                corners = np.where(from_model, alone, corners)
            floors = np.where((start_err > 0) & (peak_err > 0), corners, floors)
        if rows.peak is not None:
            model_peak = rows.start + rows.rate * times
            dlog_peak = (1.0 + rows.rate * (up - down) / (2 * step)) / model_peak
            floors = np.concatenate([floors, np.hypot(dlog_peak * own_start, peak_err / rows.peak)])
    # the columns bound a systematic error (it lies within +-u); its standard uncertainty is u/sqrt(3) (uniform); a
    # row whose model stick time is not finite (no stick from its start: silenced above) keeps no floor, as before
    return np.where(np.isfinite(floors), floors, 0.0) / math.sqrt(3.0)


def _or_zeros(values: np.ndarray | None, n: int) -> np.ndarray:
    return np.zeros(n) if values is None else np.where(np.isfinite(values), values, 0.0)


def _blocks(rows: _Rows) -> list[tuple[np.ndarray, float]]:
    """The observations at each pulling velocity (stick times, then peak stresses when fitted), with it."""
    n = rows.stick_time.size
    blocks = [(g, float(rows.velocity[g[0]])) for g in _groups(rows.velocity)]
    if rows.peak is not None:
        blocks += [(g + n, v) for g, v in blocks]
    return blocks


def _covariance(
    jac: np.ndarray, scale2: float, floors: np.ndarray, blocks: Sequence[tuple[np.ndarray, float]]
) -> tuple[np.ndarray, list[tuple[float, float, float]]]:
    """Covariance of the fitted ln-parameters, and the velocities where a floor set the error of the mean.

    The scatter (``scale2``, relative variance per observation) averages out over the repeated cycles at one
    velocity; the observations' own systematic uncertainty (``floors``) is the same in every repeat and does not.
    So the error of the mean at each velocity is floored at the mean of its observations' floors: where that is
    larger than the scatter of the mean, the difference is added to the observations' covariance as an error they
    share, and the least-squares estimate's covariance is the sandwich (J'J)^-1 J' C J (J'J)^-1.
    """
    normal = np.linalg.pinv(jac.T @ jac)
    if not math.isfinite(scale2) or not np.any(floors > 0):
        return scale2 * normal, []
    shared = np.zeros((floors.size, floors.size))
    floored: list[tuple[float, float, float]] = []
    for index, velocity in blocks:
        floor = float(np.mean(floors[index]))
        scatter2 = scale2 / index.size
        if floor**2 > scatter2:
            shared[np.ix_(index, index)] += floor**2 - scatter2
            floored.append((velocity, floor, math.sqrt(scatter2)))
    if not floored:
        return scale2 * normal, []
    a = normal @ jac.T
    return a @ (scale2 * np.eye(floors.size) + shared) @ a.T, floored


def _floor_messages(floors: Sequence[tuple[float, float, float]]) -> list[str]:
    if not floors:
        return []
    parts = ", ".join(
        f"{human(v, 'velocity')} {100 * floor:.2g} % (scatter of the mean {100 * scatter:.2g} %)"
        for v, floor, scatter in sorted(set(floors))
    )
    return [
        "errors floored by the table's own uncertainties (its *_uncertainty columns, as analyze -o writes them: bounds"
        " ±u on where each cycle's corners are, standard uncertainty u/√3): they are the same in every repeat of a"
        " cycle and do not average out over the cycles at one velocity as their scatter does; where they exceed"
        f" the scatter of a velocity's mean they set its error (relative, in ln t_s): {parts}"
    ]


#: Largest rms of the ln-residuals a usable fit may leave: beyond it the model predicts the stick times only
#: to within a factor e^0.5 = 1.65 (Table 1 is fitted to 1.7 %, stick times are measured to a few per cent).
MAX_RELATIVE_NOISE = 0.5
#: p of the F test of the stick fit's misfit against the scatter of repeated cycles at one velocity (the noise
#: measured without the model).
STICK_SIGNIFICANCE = 1e-3
#: Relative step in the start stress of the derivative that carries its uncertainty into ln t_s (:func:`_floors`).
FLOOR_STEP = 1e-5
#: Pulling velocities closer than this (relative) are the same velocity (repeated cycles).
SAME_VELOCITY = 1e-6


def _groups(velocity: np.ndarray) -> list[np.ndarray]:
    """Indices of the rows at each distinct pulling velocity."""
    order = np.argsort(velocity)
    groups: list[list[int]] = []
    for k in order:
        if groups and abs(velocity[k] - velocity[groups[-1][0]]) <= SAME_VELOCITY * velocity[groups[-1][0]]:
            groups[-1].append(int(k))
        else:
            groups.append([int(k)])
    return [np.array(g) for g in groups]


def _stick_problems(
    rows: _Rows,
    fitted: Parameters,
    keys: Sequence[str],
    fixed: Mapping[str, float],
    dof: int,
    scale2: float,
    model_problems: Sequence[str],
    time_floors: np.ndarray | None = None,
) -> list[str]:
    """Why the stick fit cannot be trusted (empty when it can).

    ``time_floors``: each stick time's own systematic standard uncertainty in ln (:func:`_floors`).  It is shared by
    the repeats of a cycle, so the scatter between them does not show it, yet the model may miss each velocity's
    mean by that much: the misfit is judged against the repeats' scatter plus the mean square of these floors
    (analyze's corners, 0.02-0.5 ms late in every cycle, failed a noise-free chain's fit against a scatter of 1e-8).
    """
    from scipy import stats

    problems = [f"the fitted model does not reproduce every stick: {p}" for p in model_problems]
    requested = [k for k in STICK_KEYS if k not in fixed]
    if requested and not keys:
        problems.append(
            f"the stick times determine none of the free parameters ({', '.join(requested)}): each was fixed at its"
            " input value"
        )
    groups = _groups(rows.velocity)
    if len(groups) < 2:
        problems.append(
            f"every fitted row is at one pulling velocity ({human(float(rows.velocity[0]), 'velocity')}): the stick"
            " times cannot show the velocity dependence Eq 15 describes"
        )
    if dof <= 0:
        problems.append("no degrees of freedom are left: the noise and the errors cannot be estimated")
        return problems
    if math.sqrt(scale2) > MAX_RELATIVE_NOISE:
        problems.append(
            f"the model does not describe these stick times: the fit leaves an rms misfit of"
            f" {100 * math.sqrt(scale2):.3g} % in ln (a factor {math.exp(math.sqrt(scale2)):.3g}), more than"
            f" the {100 * MAX_RELATIVE_NOISE:g} % a usable fit may leave"
        )
    log_t = np.log(rows.stick_time)
    r_t = np.log(_stick_times([fitted], rows)[0] / rows.stick_time)
    n, p = log_t.size, len(keys)  # the stick times alone: with fitted peaks the test is conservative
    if np.all(np.isfinite(r_t)) and n - p > 0 and len(groups) >= 2:
        s_model = float(r_t @ r_t) / (n - p)
        replicate = _replicate_scatter(log_t, groups, printed_resolution(rows.stick_time))
        if replicate is not None:
            s_rep, dof_rep, rounded = replicate
            shared = float(np.mean(time_floors**2)) if time_floors is not None and time_floors.size else 0.0
            expected = s_rep + shared
            p_misfit = float(stats.f.sf(s_model / expected, n - p, dof_rep)) if expected > 0 else 0.0
            if p_misfit < STICK_SIGNIFICANCE:
                worst = int(np.argmax(np.abs(r_t)))
                floored, repeated = rounded
                rounding = (
                    f" ({floored} of {repeated} velocities' repeats floored at the rounding of their printed values)"
                    if floored
                    else ""
                )
                problems.append(
                    f"the model does not describe these stick times: rms misfit {100 * math.sqrt(s_model):.3g} %"
                    f" against a scatter of {100 * math.sqrt(s_rep):.3g} % between repeated cycles at one velocity"
                    + rounding
                    + (f" and the table's own uncertainties of {100 * math.sqrt(shared):.2g} %" if shared > 0 else "")
                    + f" (F test, {n - p} and {dof_rep} degrees of freedom: p = {p_misfit:.2g}); the largest is a"
                    f" factor {math.exp(-r_t[worst]):.3g} at"
                    f" {human(float(rows.velocity[worst]), 'velocity')}"
                )
    return problems


def _replicate_scatter(
    log_t: np.ndarray, groups: Sequence[np.ndarray], resolution: np.ndarray | None = None
) -> tuple[float, int, tuple[int, int]] | None:
    """Pooled variance of ln t_s within groups of repeated cycles, its degrees of freedom, and how many of the
    velocities with repeats were floored, of how many (None: no repeats).

    ``resolution``: each stick time's printed resolution d (s, :func:`printed_resolution`).  Values rounded to d
    are off by a uniform error of variance d^2/12 that repeats closer than d do not show (two cycles printed as the
    same "30" scatter by 0): each velocity's sum of squares is floored at its degrees of freedom times the mean
    (d/t_s)^2/12 of its rows.  The degrees of freedom stay those of the repeats: the F test still knows how little
    one pair says.
    """
    dof = sum(g.size - 1 for g in groups)
    if dof < 1:
        return None
    ss, floored, repeated = 0.0, 0, 0
    for g in groups:
        if g.size < 2:
            continue
        repeated += 1
        measured = float(np.sum((log_t[g] - np.mean(log_t[g])) ** 2))
        floor = 0.0
        if resolution is not None:
            floor = (g.size - 1) * float(np.mean((resolution[g] / np.exp(log_t[g])) ** 2)) / 12.0
        floored += floor > measured
        ss += max(measured, floor)
    return ss / dof, dof, (floored, repeated)


#: Relative agreement with which a value is taken to be its shortest decimal form (:func:`printed_resolution`):
#: a value read in ms or µm/s and converted to SI is off its decimal form by an ulp or two.
DECIMAL_MATCH = 1e-12


def printed_resolution(values: np.ndarray) -> np.ndarray:
    """The unit d of the last printed digit of each value of one column (in its unit, SI as read), from the values.

    A value alone gives the last significant digit of its shortest decimal form (within DECIMAL_MATCH), and for a
    whole number at least its units digit ("30" is 30 +- 0.5, not 30 +- 5: trailing zeros may be printed digits).
    A number does not keep the trailing zeros it was printed with ("14.0" reads as "14"), so the column completes
    it: printed alike, its values have at most its largest count of significant digits K (as "%.3g" prints) or at
    most its finest digit (as "%.1f" prints), whichever is the coarser for the value; d is the finer of that and
    the value's own reading.  What stays unknowable errs small (a column in minutes converted to seconds, "1.4e2"
    written as 140 among values read to the units).
    """
    flat = np.ravel(np.asarray(values, dtype=float))
    own = np.zeros(flat.size)
    exponents = np.zeros(flat.size, dtype=int)
    significant = 0
    for k, value in enumerate(flat):
        if not (math.isfinite(value) and value > 0):
            continue
        for digits in range(1, 18):
            text = f"{value:.{digits - 1}e}"
            if abs(float(text) - value) <= DECIMAL_MATCH * value:
                break
        exponents[k] = int(text.split("e")[1])
        own[k] = min(10.0 ** (exponents[k] - digits + 1), 1.0)
        significant = max(significant, digits)
    if not np.any(own > 0):
        return own
    finest = float(np.min(own[own > 0]))
    column = np.maximum(finest, 10.0 ** (exponents - significant + 1.0))
    return np.where(own > 0, np.minimum(own, column), 0.0)


#: Least ln-misfit a row needs to be flagged as an outlier: on exact stick times (a simulated trace's cycles) the
#: scatter is 1e-8 and a row off by 1e-7 is no outlier ("off by a factor 1"); stick times are measured to ~1 %.
OUTLIER_FLOOR = 1e-3


def _outliers(data: StickData, used: np.ndarray, model_t: np.ndarray) -> list[str]:
    """Rows whose stick time is off by more than 4 robust standard deviations of the others."""
    r = np.log(model_t[used] / data.stick_time[used])
    far, spread, _ = outlying(r, STICK_OUTLIER_SPREADS, OUTLIER_FLOOR)
    out = []
    for row, value in zip(data.rows[used][far], r[far], strict=True):
        out.append(
            f"row {row}: the model's stick time is off by a factor {math.exp(-value):.3g}, far outside the scatter"
            f" of the other rows ({100 * spread:.2g} %): an outlier? (--exclude-row {row} leaves it out)"
        )
    return out


def _scanned_start(params: Parameters, keys: Sequence[str], rows: _Rows) -> Parameters:
    """The start with the best Nc0 of a coarse scan (factors 1/4 to 4).

    The stick time depends most strongly on Nc0 (the load per chain), and a
    start where some block never slips gives the optimiser no gradient.
    """
    if "stick.attached_chains" not in keys:
        return params
    trials = [
        params.with_overrides({"stick.attached_chains": params.stick.attached_chains * factor})
        for factor in SCAN_FACTORS
    ]
    cost = np.sum(_residuals_many(trials, rows) ** 2, axis=1)
    return trials[int(np.argmin(cost))]


def _undetermined(params: Parameters, keys: Sequence[str], rows: _Rows, n_obs: int) -> list[identify.Direction]:
    if not keys:
        return []
    theta = np.array([math.log(params.as_dict()[k]) for k in keys])
    r = _residuals(params, rows)
    scale = math.sqrt(float(r @ r) / (n_obs - len(keys)))
    return identify.undetermined(keys, _jacobian(params, keys, theta, rows), max(scale, 1e-3))


def _fix(keys: list[str], undetermined: list[str], messages: list[str], key: str, base: Parameters, why: str) -> None:
    keys.remove(key)
    undetermined.append(key)
    value = base.as_dict()[key]
    messages.append(
        f"{key} ({identify.SYMBOLS[key]}) is not determined by these stick times ({why}): fixed at its input value"
        f" {human(value, key_dimension(key))}; the other estimates are conditional on it"
    )


def _check_stick_key(key: str, option: str) -> None:
    key_dimension(key)
    if key not in STICK_KEYS:
        raise ParameterError(
            f"{option} {key}: not a stick-phase fit parameter; expected one of {', '.join(STICK_KEYS)}"
        )


def _from_model(data: StickData, mode: str) -> np.ndarray:
    """The rows whose stick starts at the bond parameters' σc: all with --start-stress model, else the empty cells."""
    if mode == "model" or data.start_stress is None:
        return np.ones(len(data), dtype=bool)
    return ~np.isfinite(data.start_stress)


def _start_column(data: StickData, sigma_c: float | None, mode: str = "measured") -> np.ndarray:
    missing = _from_model(data, mode)
    start = np.full(len(data), np.nan) if data.start_stress is None else np.array(data.start_stress, dtype=float)
    if np.any(missing):
        if sigma_c is None:
            if mode == "model":
                raise ParameterError(
                    "--start-stress model: the bond parameters have no critical stress (no stick-slip: σ(V) has no"
                    " minimum) to start the sticks from; give the measured start stresses (--start-stress measured)"
                )
            raise DataError(
                f"{data.source}: row {data.rows[np.nonzero(missing)[0][0]]}, column 'start_stress' is empty and the"
                " bond parameters have no critical stress to start from; give the start stress"
            )
        start = np.where(missing, sigma_c, start)
    return start


def _rate_column(data: StickData, params: Parameters) -> np.ndarray:
    model_rate = params.block.effective_stiffness * data.pulling_velocity
    measured = data.extra.get("stick_slope")
    if measured is None:
        return model_rate
    return np.where(np.isfinite(measured), measured, model_rate)


def _rows(
    data: StickData,
    used: np.ndarray,
    start: np.ndarray,
    rate: np.ndarray,
    sigma_c: float | None,
    messages: list[str],
    mode: str = "measured",
) -> tuple[_Rows, bool]:
    if mode == "model":
        have = 0 if data.start_stress is None else int(np.count_nonzero(np.isfinite(data.start_stress[used])))
        unused = f": the table's start stresses ({have} rows) are not used" if have else ""
        messages.append(
            f"every stick starts at the critical stress σc = {human(sigma_c or 0.0, 'stress')} of the bond parameters"
            f" (--start-stress model){unused}"
        )
    elif data.start_stress is None or np.any(~np.isfinite(data.start_stress[used])):
        messages.append(
            f"rows without start_stress start at the critical stress σc = {human(sigma_c or 0.0, 'stress')} of the"
            " bond parameters"
        )
    measured = "stick_slope" in data.extra
    if measured:
        messages.append("loading rate of each stick phase from its measured stick_slope (instead of K·V0 of Eq 17)")
    peak = None
    fitted_peak = False
    if data.peak_stress is not None and mode == "model":
        messages.append(
            "peak stresses not fitted: with --start-stress model the table's stresses are not taken as absolute"
        )
    elif data.peak_stress is not None and not measured:
        have = np.isfinite(data.peak_stress)
        if np.any(have & used):
            if not np.all(have[used]):
                raise DataError(
                    f"{data.source}: column 'peak_stress' is empty in some fitted rows; give it in every row or in none"
                )
            peak = data.peak_stress[used]
            fitted_peak = True
            messages.append("peak stresses fitted together with stick times (one relative noise level)")
    elif data.peak_stress is not None:
        messages.append(
            "peak stresses compared, not fitted: with the measured loading rate σs = σc + rate·ts repeats"
            " the stick time"
        )

    def err(name: str) -> np.ndarray | None:
        values = data.extra.get(name)
        return None if values is None else values[used]

    rows = _Rows(
        data.pulling_velocity[used],
        start[used],
        rate[used],
        data.stick_time[used],
        peak,
        err("start_stress_uncertainty"),
        err("stick_time_uncertainty"),
        err("peak_stress_uncertainty"),
    )
    return rows, fitted_peak


# --- the start stresses: drift and offset (round 29) --------------------------------------------------------------

#: Fewest rows at one velocity whose start stresses are tested for a trend (two degrees of freedom).
DRIFT_MIN_ROWS = 4
#: Least effect on ln t_s (relative) a drift or offset of the start stresses must have to be said: below it the
#: start stresses move the model's stick times less than stick times are measured to.
START_EFFECT_FLOOR = 1e-2
#: How many times the stick times' own scatter a drift's effect must exceed to be said (else the stick times would
#: show it themselves).
DRIFT_EFFECT_FACTOR = 3.0
#: How many standard errors of their mean the table's start stresses must lie from the model's σc to be said.
OFFSET_SIGNIFICANCE = 4.0


def _start_sensitivity(params: Parameters, rows: _Rows) -> np.ndarray:
    """d ln t_s / d sigma_0 of each row (1/Pa) at ``params``: how Eq 15 turns a start stress into a stick time."""
    step = FLOOR_STEP * rows.start
    shifted = [dataclasses.replace(rows, start=rows.start + sign * step) for sign in (1.0, -1.0)]
    # a row whose stick never collapses at these parameters has an infinite (or no) stick time: its sensitivity is
    # not finite, and both readers (_start_drifts, _offset_note) keep only the finite ones
    with np.errstate(invalid="ignore", divide="ignore"):
        up, down = (_stick_times([params], r)[0] for r in shifted)
        return (np.log(up) - np.log(down)) / (2 * step)


def _start_drifts(
    data: StickData, used: np.ndarray, from_model: np.ndarray, sensitivity: np.ndarray
) -> list[StartDrift]:
    """The velocities whose measured start stresses trend along the record (start_time where the table has it,
    else the row order) beyond their scatter (t test of the slope, p < STICK_SIGNIFICANCE), where the trend moves
    the model's stick times by more than START_EFFECT_FLOOR and DRIFT_EFFECT_FACTOR times the rows' own scatter
    of ln t_s: a sensor's drift that the stick times, measured as differences of times, do not carry."""
    from scipy.special import stdtr

    if data.start_stress is None:
        return []
    index = np.nonzero(used)[0]
    per_row = np.full(len(data), np.nan)
    per_row[index] = sensitivity
    when = data.extra.get(CYCLE_START_TIME)
    out = []
    for group in _groups(data.pulling_velocity[index]):
        k = index[group]
        k = k[np.isfinite(data.start_stress[k]) & ~from_model[k]]
        if k.size < DRIFT_MIN_ROWS:
            continue
        dated = when is not None and bool(np.all(np.isfinite(when[k])))
        x = np.asarray(when[k] if dated else data.rows[k], dtype=float)
        order = np.argsort(x, kind="stable")
        k, x = k[order], x[order]
        y = data.start_stress[k]
        centred = x - x.mean()
        sxx = float(centred @ centred)
        if not sxx > 0:
            continue
        slope = float(centred @ (y - y.mean())) / sxx
        rest = y - y.mean() - slope * centred
        s2 = float(rest @ rest) / (k.size - 2)
        se = math.sqrt(s2 / sxx)
        t_value = abs(slope) / se if se > 0 else math.inf
        if not 2.0 * float(stdtr(k.size - 2, -t_value)) < STICK_SIGNIFICANCE:
            continue
        drift = slope * float(x[-1] - x[0])
        gain = per_row[k][np.isfinite(per_row[k])]
        if not gain.size:
            continue
        gain_median = float(np.median(gain))
        time_scatter = float(np.std(np.log(data.stick_time[k]), ddof=1))
        effect = abs(drift * gain_median)
        if not effect > max(START_EFFECT_FLOOR, DRIFT_EFFECT_FACTOR * time_scatter):
            continue
        rows = tuple(int(r) for r in data.rows[k])
        velocity = float(data.pulling_velocity[k[0]])
        measured = data.extra.get("stick_slope")
        loading = None if measured is None or not np.any(np.isfinite(measured[k])) else float(np.nanmedian(measured[k]))
        out.append(StartDrift(velocity, rows, drift, slope if dated else None, t_value, math.sqrt(s2), gain_median,
                              time_scatter, loading))  # fmt: skip
    return sorted(out, key=lambda d: -abs(d.drift * d.sensitivity))


def _drift_advice(drifts: Sequence[StartDrift], sigma_c: float | None) -> str:
    """One sentence: which velocities' start stresses drift, by how much, what Eq 15 makes of it, and what to do."""
    worst = drifts[0]
    span = f"rows {worst.rows[0]} to {worst.rows[-1]}"
    rate = f", {worst.rate:+.2g} Pa/s" if worst.rate is not None else ""
    others = [f"{d.drift:+.2g} Pa at {human(d.pulling_velocity, 'velocity', 3)}" for d in drifts[1:3]]
    if len(drifts) > 3:
        others.append(f"{len(drifts) - 3} more")
    also = f" ({', '.join(others)})" if others else ""
    where = f"at {len(drifts)} velocities" if len(drifts) > 1 else "within one velocity's rows"
    start = f" = {human(sigma_c, 'stress', 4)}" if sigma_c is not None else ""
    effect = abs(worst.drift * worst.sensitivity)
    return (
        f"the start stresses drift along the record {where}, far beyond their scatter: those of the"
        f" {human(worst.pulling_velocity, 'velocity', 3)} rows by {worst.drift:+.2g} Pa ({span}{rate}; scatter"
        f" about the trend {worst.scatter:.2g} Pa){also} (a sensor drift or offset?); Eq 15 turns 1 Pa of start"
        f" stress into {100 * abs(worst.sensitivity):.2g} % of ts there, {100 * effect:.2g} % over these rows,"
        f" whose measured stick times scatter by {100 * worst.time_scatter:.2g} %: fit without"
        f" them with --start-stress model (each stick from the bond parameters' σc{start})"
        + (
            f"; the measured stick_slope carries a sensor's drift too ({worst.rate:+.2g} of"
            f" {worst.loading_rate:.3g} Pa/s there): correct it where the drift is the sensor's"
            if worst.rate is not None and worst.loading_rate is not None
            else ""
        )
    )


def _offset_note(
    data: StickData, used: np.ndarray, sigma_c: float | None, sensitivity: np.ndarray, mode: str
) -> list[str]:
    """A note where the table's start stresses lie off the bond parameters' σc by more than OFFSET_SIGNIFICANCE
    standard errors of their mean and by more than START_EFFECT_FLOOR in ln t_s (a sensor's offset, not zeroed?)."""
    if data.start_stress is None or sigma_c is None:
        return []
    measured = data.start_stress[used]
    have = np.isfinite(measured)
    gain = sensitivity[have & np.isfinite(sensitivity)]
    if np.count_nonzero(have) < 2 or not gain.size:
        return []
    values = measured[have]
    offset = float(np.mean(values)) - sigma_c
    sem = float(np.std(values, ddof=1)) / math.sqrt(values.size)
    per_pascal = abs(float(np.median(gain)))
    if not (abs(offset) * per_pascal > START_EFFECT_FLOOR and abs(offset) > OFFSET_SIGNIFICANCE * sem):
        return []
    where = f"{abs(offset):.3g} Pa {'above' if offset > 0 else 'below'}"
    said = (
        f"the table's start stresses (mean {human(float(np.mean(values)), 'stress', 5)} over {values.size} rows,"
        f" standard error {sem:.2g} Pa) lie {where} the critical stress σc = {human(sigma_c, 'stress', 5)} of the bond"
        f" parameters; Eq 15 turns 1 Pa of start stress into {100 * per_pascal:.2g} % of ts"
    )
    if mode == "model":
        return [f"{said} (not used: --start-stress model): a force sensor's offset, or bond parameters of another"
                " sample?"]  # fmt: skip
    return [
        f"{said}, {100 * abs(offset) * per_pascal:.2g} % here.  The fit takes them as absolute: a force sensor's"
        " offset (not zeroed with the block unloaded) moves uc/τ and Nc0 without failing the fit; if the forces have"
        " one, or the bond parameters are another sample's, --start-stress model starts every stick from σc"
    ]


# --- the bond parameters' uncertainty (round 29) ------------------------------------------------------------------

#: Step in the ln of a bond parameter of the derivatives that carry its uncertainty into the stick fit.
BOND_STEP = 1e-3


@dataclass(frozen=True)
class _Propagation:
    keys: tuple[str, ...]  # the bond-parameter keys carried
    sensitivity: np.ndarray  # d theta / d ln p: free stick ln-parameters by keys
    log_force_sensitivity: np.ndarray  # d ln(lambda/kT) / d ln p
    critical_stress: np.ndarray  # d sigma_c / d ln p (Pa), zeros where no row starts at the model's σc
    inputs: np.ndarray  # the covariance of ln p
    stick: np.ndarray  # S inputs S': what it adds to the fitted ln-parameters' covariance


def _bond_propagation(
    params: Parameters,
    keys: Sequence[str],
    rows: _Rows,
    from_model: np.ndarray,
    inputs: FitCovariance | None,
    jac: np.ndarray,
) -> _Propagation | None:
    """The bond parameters' covariance (``inputs``, ln-values) carried into the fitted stick ln-parameters to first
    order: d theta/d ln p = -(J'J)^-1 J' dr/d ln p at the optimum, dr/d ln p by central differences (through
    lambda/kT, and sigma_c where a row starts at the model's)."""
    if inputs is None or not keys:
        return None
    carried = [k for k in inputs.keys if k not in STICK_KEYS]
    if not carried:
        return None
    at = [inputs.keys.index(k) for k in carried]
    normal = np.linalg.pinv(jac.T @ jac)
    sens = np.zeros((len(keys), len(carried)))
    log_b = np.zeros(len(carried))
    d_sigma = np.zeros(len(carried))
    value = params.as_dict()
    for j, key in enumerate(carried):
        residuals, logs, sigmas = [], [], []
        for sign in (1.0, -1.0):
            shifted = params.with_overrides({key: value[key] * math.exp(sign * BOND_STEP)})
            these = rows
            if np.any(from_model):
                point = critical_point(shifted)
                if not point.exists:
                    return None
                these = dataclasses.replace(rows, start=np.where(from_model, point.stress, rows.start))
                sigmas.append(point.stress)
            residuals.append(_residuals(shifted, these))
            logs.append(math.log(shifted.bonds.force_sensitivity))
        dr = (residuals[0] - residuals[1]) / (2 * BOND_STEP)
        sens[:, j] = -normal @ (jac.T @ dr)
        log_b[j] = (logs[0] - logs[1]) / (2 * BOND_STEP)
        d_sigma[j] = (sigmas[0] - sigmas[1]) / (2 * BOND_STEP) if sigmas else 0.0
    sigma = inputs.covariance[np.ix_(at, at)]
    return _Propagation(tuple(carried), sens, log_b, d_sigma, sigma, sens @ sigma @ sens.T)


#: The combination Eq 15 determines: Nc0 enters it only through (lambda/kT)/Nc0.
STRESS_SCALE = ("stick_stress_scale", "Nc0·kT/λ")


def _combinations(
    params: Parameters, keys: Sequence[str], conditional: np.ndarray, propagated: _Propagation | None, q: float
) -> list[Estimate]:
    """Nc0·kT/lambda (Pa): the stress at which each attached chain carries kT/lambda, what the stick times determine
    of Nc0 whatever lambda is; its error from the fit (and from the bond parameters where carried)."""
    if "stick.attached_chains" not in keys:
        return []
    i = keys.index("stick.attached_chains")
    value = params.stick.attached_chains / params.bonds.force_sensitivity
    var = float(conditional[i, i])
    if propagated is not None:
        g = propagated.sensitivity[i] - propagated.log_force_sensitivity
        var += float(g @ propagated.inputs @ g)
    s = math.sqrt(max(var, 0.0))
    key, symbol = STRESS_SCALE
    note = "derived: what the stick times determine of Nc0 (Eq 15 holds it only through (λ/kT)/Nc0)"
    return [Estimate(key, symbol, "stress", value, value * s, log_interval(value, s, q), status="derived", note=note)]


def _intervals_note(
    params: Parameters,
    keys: Sequence[str],
    conditional: np.ndarray,
    propagated: _Propagation | None,
    model_start: bool,
    sigma_c: float | None,
    source: str,
    had_inputs: bool = False,
) -> str:
    """What the intervals are conditional on, or whose uncertainty they include (the report's and --json's line)."""
    sc = f"σc = {human(sigma_c, 'stress', 4)}" if sigma_c is not None else "σc"
    scale = params.stick.attached_chains / params.bonds.force_sensitivity
    if propagated is None:
        why = (
            f"the covariance of them in {source} could not be carried into this fit"
            if had_inputs
            else f"{source} carries no covariance of them, as the file of fit steady -o does"
        )
        text = f"conditional on the bond parameters, held exact ({why})"
        if "stick.attached_chains" in keys:
            text += (
                f": the stick times determine Nc0 only as Nc0·kT/λ = {human(scale, 'stress', 4)} (its interval holds"
                " whatever λ is), so an error of x % in λ/kT is one of x % in Nc0"
            )
            text += (
                f"; the sticks start from the bond parameters' {sc}, whose error moves all three"
                if model_start
                else ", and uc/τ and τa(stick) do not depend on λ"
            )
        return text
    se = np.sqrt(np.clip(np.diag(conditional), 0, np.inf))
    total = np.sqrt(np.clip(np.diag(conditional + propagated.stick), 0, np.inf))
    changes = ", ".join(
        f"{identify.SYMBOLS[k]} {100 * a:.2g} % → {100 * b:.2g} %" for k, a, b in zip(keys, se, total, strict=True)
    )
    inputs = []
    if "bonds.activation_length" in propagated.keys:
        j = propagated.keys.index("bonds.activation_length")
        inputs.append(f"λ ±{100 * math.sqrt(propagated.inputs[j, j]):.2g} %")
    if model_start:
        g = propagated.critical_stress
        inputs.append(f"{sc} ±{math.sqrt(max(float(g @ propagated.inputs @ g), 0.0)):.2g} Pa")
    text = (
        f"including the uncertainty of the bond parameters that fit steady wrote into {source} (the covariance of"
        f" {len(propagated.keys)} keys{': ' + ', '.join(inputs) if inputs else ''}; to first order): standard errors"
        f" of the ln-values, the fit's alone → with it: {changes}"
    )
    held = [k for k in ("bonds.activation_length", "bonds.temperature") if k not in propagated.keys]
    if "stick.attached_chains" in keys and "bonds.activation_length" in held:
        text += (
            f"; λ is not among them (fit steady held it fixed), so Nc0 stays conditional on λ: the stick times"
            f" determine Nc0·kT/λ = {human(scale, 'stress', 4)}"
        )
    return text
