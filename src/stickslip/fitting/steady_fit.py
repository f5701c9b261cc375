"""Fit the steady friction curve (Eqs 6-8) to measured stress against velocity (paper, Section 3).

Methods ``two-step`` (the paper's: no aging above the split velocity, then tau_a and V_a below it) and ``joint``
(every free parameter at once, from the two-step result).  What the data cannot determine is fixed with a message
(:mod:`stickslip.fitting.identify`); Vc and sigma_c (Eq 9) come with ``delta``, ``profile`` or ``bootstrap``
intervals (docs/fitting.md).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy import stats
from scipy.optimize import least_squares

from ..columns import with_units
from ..errors import DataError, ModelError, ParameterError
from ..parameters import Parameters, key_dimension, load_parameters
from ..quasistatic.critical import critical_point
from ..quasistatic.steady import compiled_marches, steady_state
from ..reprs import compact_repr
from ..units import override_to_si, shorten, to_si
from . import identify
from .critical_uncertainty import STRESS_STIFFNESS, Profile, critical_gradient, local_critical
from .data import SteadyData, read_steady_data
from .global_search import global_start
from .problem import (
    FAILED_RESIDUAL,
    INTERPOLATION_TOLERANCE,
    SEARCH_BOX,
    Block,
    Space,
    interpolation_error,
    jacobian,
    make_block,
    minimize,
    residuals,
)
from .results import CRITICAL, LARGEST_LOG_WIDTH, Estimate, display_unit, human, undetermined_critical, unusable
from .results import log_interval as _log_interval
from .scatter import (
    SIGNIFICANCE,
    STEADY_OUTLIER_SPREADS,
    Dependence,
    Misfit,
    Scatter,
    agrees_with_stated_errors,
    fitted_dependence,
    local_scatter,
    misfit,
    model_dependence,
    outlying,
    replicate_scatter,
    residual_scatter,
    velocity_dependence,
)

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    from matplotlib.axes import Axes

METHODS = ("auto", "two-step", "joint")
INTERVAL_METHODS = ("delta", "profile", "bootstrap")
DEFAULT_SPLIT = 800e-6


class TooFewPointsError(DataError):
    """A method's step has no more data points than free parameters (or none at all): bad input for that method,
    which ``auto`` answers with the joint fit where the two-step method is the one short of points.  ``short`` is
    the message without its advice."""

    def __init__(self, short: str, advice: str) -> None:
        super().__init__(f"{short}; {advice}" if advice else short)
        self.short = short


#: Above the split the two-step fit neglects aging; warn when that changes sigma by more than this many errors.
AGING_NEGLECT_WARNING = 0.5
#: Above this many points the joint fit's automatic intervals are the delta method's, not the profile's.
PROFILE_MAX_POINTS = 1000


@dataclass(frozen=True)
class Stage:
    """One least-squares step of a method."""

    name: str
    keys: tuple[str, ...]
    points: int
    chi_square: float
    nfev: int
    success: bool
    message: str


@dataclass(frozen=True)
class SteadyFit:
    """Result of :func:`fit_steady`; every number in SI units."""

    data: SteadyData
    parameters: Parameters
    start: Parameters
    method: str
    split: float | None
    estimates: tuple[Estimate, ...]
    combinations: tuple[Estimate, ...]
    free_keys: tuple[str, ...]
    covariance: np.ndarray  # of ln(parameter) for free_keys
    correlation: np.ndarray
    chi_square: float
    dof: int
    noise: str
    noise_scale: float
    model_stress: np.ndarray
    residuals: np.ndarray  # (data - model)/(error * noise_scale): in units of the noise, stated or estimated
    critical_velocity: Estimate
    critical_stress: Estimate
    interval_method: str
    level: float
    stages: tuple[Stage, ...]
    messages: tuple[str, ...]
    samples: dict[str, np.ndarray] | None = field(default=None, repr=False)
    status: str = "ok"  # "failed" when the fit cannot be trusted; ``reason`` says why
    reason: str = ""
    flat_level: float | None = None  # set when the data show no velocity dependence and nothing was fitted
    #: True when the stated errors were found too small for the data and scaled by ``noise_scale`` (= sqrt of
    #: chi^2/dof): every interval is then computed with the scaled errors (docs/fitting.md, "Stated errors")
    stated_errors_scaled: bool = False
    #: how the intervals of the parameters and the combinations were computed: "wald" (symmetric in ln, from the
    #: covariance) or "profile" (the profile likelihood of each fitted key, the joint fit's: docs/fitting.md)
    parameter_intervals: str = "wald"

    __repr__ = compact_repr  # counts, not hundreds of array elements

    @property
    def success(self) -> bool:
        return self.status == "ok"

    @property
    def noise_estimated(self) -> bool:
        """True when the data state no errors and the noise level is estimated from the residuals."""
        return self.data.stress_err is None

    @property
    def reduced_chi_square(self) -> float | None:
        """chi^2/dof with the stated errors; None when the noise is estimated from the residuals (it is 1 then)."""
        if self.noise_estimated or self.dof <= 0:
            return None
        return self.chi_square / self.dof

    def estimate(self, key: str) -> Estimate:
        for e in (*self.estimates, *self.combinations):
            if e.key == key:
                return e
        raise KeyError(key)

    def curve(self, velocity: Any, aging: bool = True) -> np.ndarray:
        """The fitted sigma(V) at ``velocity`` (m/s); the constant level where nothing was fitted."""
        if self.flat_level is not None:
            return np.full(np.shape(np.atleast_1d(velocity)), self.flat_level)
        return steady_state(self.parameters, velocity, aging=aging).stress

    def to_frame(self) -> pd.DataFrame:
        """One row per data point: data, fitted stress, normalised residual."""
        frame = self.data.to_frame()
        frame["model_stress"] = self.model_stress
        frame["residual"] = self.residuals
        return with_units(frame)

    def as_dict(self) -> dict[str, Any]:
        """The JSON summary (SI units)."""
        return {
            "status": self.status,
            **({"reason": self.reason} if self.reason else {}),
            "method": self.method,
            "split_velocity": self.split,
            "parameters": {e.key: e.as_dict() for e in self.estimates},
            "combinations": {e.key: e.as_dict() | {"symbol": e.symbol} for e in self.combinations},
            "critical_velocity": self.critical_velocity.as_dict(),
            "critical_stress": self.critical_stress.as_dict(),
            "interval_method": self.interval_method,
            "parameter_interval_method": self.parameter_intervals,
            "confidence_level": self.level,
            "chi_square": self.chi_square,
            "dof": self.dof,
            "reduced_chi_square": self.reduced_chi_square,
            "noise": self.noise,
            "relative_noise": self.noise_scale if self.noise_estimated else None,
            "stated_error_scale": self.noise_scale if self.stated_errors_scaled else None,
            "correlation": {
                "keys": list(self.free_keys),
                "matrix": self.correlation.tolist(),
            },
            "residuals": self.residuals.tolist(),
            "excluded_rows": list(self.data.excluded),
            "messages": list(self.messages),
        }

    def report(self) -> str:
        """A Markdown report of the fit."""
        from .report import steady_report

        return steady_report(self)

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        """Data, fitted curve (extended below the data to show the minimum) and Vc; returns the Axes."""
        from ..plots.fits import plot_steady_fit

        return plot_steady_fit(self, ax=ax, **kwargs)


# --------------------------------------------------------------------------- setup


def _resolve_fix(params: Parameters, fix: Mapping[str, Any] | None) -> tuple[Parameters, dict[str, float]]:
    values: dict[str, float] = {}
    for key, raw in (fix or {}).items():
        _check_steady_key(key, "--fix")
        values[key] = override_to_si(raw, key_dimension(key), key)
    if values:
        params = params.with_overrides(values)
    return params, values


def _check_steady_key(key: str, option: str) -> None:
    key_dimension(key)  # unknown keys raise ParameterError with the list of keys
    if key not in identify.STEADY_KEYS:
        raise ParameterError(
            f"{option} {key}: the steady friction curve does not depend on it; steady-fit keys are"
            f" {', '.join(identify.STEADY_KEYS)}"
        )


def _requested(free: Sequence[str] | None, fixed: Mapping[str, float]) -> tuple[list[str], list[str]]:
    explicit: list[str] = []
    for key in free or ():
        _check_steady_key(key, "--free")
        if key in fixed:
            raise ParameterError(f"{key} is given both to --fix and to --free")
        if key not in explicit:
            explicit.append(key)
    defaults = [k for k in identify.DEFAULT_FREE if k not in fixed and k not in explicit]
    return explicit, explicit + defaults


def _blocks(data: SteadyData, split: float, params: Parameters) -> tuple[np.ndarray, Block, Block, Block]:
    """The error column and the blocks: all points with aging, and the two-step's ranges (long ones interpolated)."""
    error = data.stress_err if data.stress_err is not None else data.stress
    everything = make_block(data.velocity, data.stress, error, True, params)
    high = data.velocity >= split
    hi_block = make_block(data.velocity[high], data.stress[high], error[high], False, params)
    lo_block = make_block(data.velocity[~high], data.stress[~high], error[~high], True, params)
    return error, everything, hi_block, lo_block


def _require_finite_start(block: Block, params: Parameters, fixed: Mapping[str, float]) -> None:
    """ParameterError unless the start values give a finite, non-zero steady stress at the data's velocities: a
    value far outside the physical box (N0 = 1e300 m^-2, tau = 1e-300 s) overflowed in the fit's search, or
    rescaled N0 to 0 or inf, and was then reported as an internal error or against a key the user never gave."""
    try:
        # an overflow here gives inf and an underflow 0, both refused just below: silenced because it is checked
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            model = np.asarray(block.model(params), dtype=float)
            level = float(np.sum(model * model)) if model.size else math.nan
    except (ModelError, ParameterError, ArithmeticError) as exc:
        model, level, why = np.array([math.nan]), math.nan, str(exc)
    else:
        why = ""
    if np.all(np.isfinite(model)) and math.isfinite(level) and level > 0.0:
        return
    given = ", ".join(f"{key} = {value:.6g} (SI)" for key, value in fixed.items())
    where = f" with {given} held fixed" if given else ""
    if why:
        shown = why
    elif np.any(np.isfinite(model)):
        largest = float(np.nanmax(np.abs(model)))
        shown = f"at most {largest:.3g} Pa, whose squares {'overflow' if largest > 1.0 else 'vanish'}"
    else:
        shown = "not a finite number"
    raise ParameterError(
        f"the start values{where} give a steady stress at the data's velocities of {shown}: the fit cannot start"
        " there; check the values given with --fix and --set, and the parameter set"
    )


def _scaled_start(params: Parameters, block: Block, free: Sequence[str]) -> Parameters:
    """Rescale N0 so that the start curve matches the data's level (sigma is proportional to N0)."""
    if "bonds.site_density" not in free:
        return params
    model = block.model(params)
    w = 1.0 / block.error**2
    factor = float(np.sum(w * model * block.stress) / np.sum(w * model * model))
    return params.with_overrides({"bonds.site_density": params.bonds.site_density * factor})


# --------------------------------------------------------------------------- fitting


@dataclass
class _Progress:
    params: Parameters
    start: Parameters
    explicit: tuple[str, ...]
    noise_known: bool
    messages: list[str]
    undetermined: list[str]
    stages: list[Stage]
    #: where a key the data do not determine is held (the start's value: the input's, or the global search's)
    held: str = "its input value"


#: What to do when the joint fit has too few points (no method can fit them as asked).
JOINT_ADVICE = "need more points than parameters (measure more velocities or --fix some parameters)"


def _fit_block(
    progress: _Progress,
    keys: Sequence[str],
    block: Block,
    name: str,
    precheck: bool = False,
    advice: str = JOINT_ADVICE,
) -> tuple[list[str], np.ndarray]:
    """Fit ``keys`` on ``block``; fix and refit while a direction is undetermined.

    With ``precheck`` (a start already close to the minimum) undetermined
    directions are first looked for at the start, which saves the optimiser
    a walk along them.
    """
    keys = list(keys)
    if len(keys) >= len(block):
        raise TooFewPointsError(
            f"{name}: {len(block)} data point(s) for {len(keys)} free parameter(s) ({', '.join(keys)})", advice
        )
    while precheck and keys:
        space = Space(progress.params, tuple(keys))
        r = residuals(space, space.vector(), block)
        scale = 1.0 if progress.noise_known else math.sqrt(block.chi_square(r) / (len(block) - len(keys)))
        bad = identify.undetermined(keys, jacobian(space, space.vector(), block), scale)
        if not bad:
            break
        _fix_undetermined(progress, keys, bad[0], name)
    while True:  # each round that does not return fixes one key
        space = Space(progress.params, tuple(keys))
        theta0 = space.vector()
        centre = Space(progress.start, tuple(keys)).vector()
        got = minimize(space, theta0, block, centre)
        progress.params = space.params(got.theta)
        dof = len(block) - len(keys)
        scale = 1.0 if progress.noise_known else math.sqrt(got.chi_square / dof)
        jac = jacobian(Space(progress.params, tuple(keys)), got.theta, block)
        bad = identify.undetermined(keys, jac, scale) if keys else []
        if not bad:
            for key in got.at_edge:
                progress.messages.append(
                    f"warning: {key} ended at the edge of the search box (a factor 1e4 from its start value);"
                    " the fit may be wrong: start from closer values (--params/--set) or fix it"
                )
            progress.stages.append(
                Stage(name, tuple(keys), len(block), got.chi_square, got.nfev, got.success, got.message)
            )
            return keys, got.theta
        _fix_undetermined(progress, keys, bad[0], name)


def _fix_undetermined(progress: _Progress, keys: list[str], direction: identify.Direction, name: str) -> None:
    """Fix the key that pins ``direction`` at its input value (removing it from ``keys``), with a message."""
    key = identify.choose_key_to_fix(keys, direction, progress.explicit)
    start_value = progress.start.as_dict()[key]
    progress.params = progress.params.with_overrides({key: start_value})
    keys.remove(key)
    progress.undetermined.append(key)
    progress.messages.append(
        f"{key} ({identify.SYMBOLS[key]}) is not determined by these data in {name}: the direction"
        f" {direction.describe()} of the fitted ln-parameters is unconstrained, so {key} is fixed at"
        f" {progress.held} {human(start_value, key_dimension(key))} and the results are conditional on it"
    )


def _steps(requested: Sequence[str]) -> tuple[identify.Selection, list[str]]:
    """The two-step method's keys: step 1's (no aging; those it can identify) and step 2's (aging)."""
    step1 = identify.select_identifiable([k for k in requested if k in identify.NO_AGING_KEYS], aging=False)
    return step1, [k for k in requested if k in identify.AGING_KEYS]


def _two_step(progress: _Progress, requested: Sequence[str], hi: Block, lo: Block, split: float) -> None:
    step1, step2 = _steps(requested)
    progress.messages.extend(step1.messages)
    v_split = human(split, "velocity")
    # advise the joint fit only where it has the points it needs (4 points for its 5 parameters: it fails too)
    joint = len(hi) + len(lo) > len(identify.select_identifiable(requested, aging=True).free)
    if len(hi) == 0 or len(lo) == 0:
        side = "at or above" if len(hi) == 0 else "below"
        raise TooFewPointsError(
            f"two-step fit: no data point {side} the split velocity {v_split}",
            "set --split inside the data range" + (" or use --method joint" if joint else ""),
        )
    advice = "need more points than parameters (lower --split, --fix some parameters" + (
        " or use --method joint)" if joint else ")"
    )
    progress.params = _scaled_start(progress.params, hi, step1.free)
    _fit_block(progress, step1.free, hi, f"step 1 (V >= {v_split}, no aging)", advice=advice)
    _fit_block(progress, step2, lo, f"step 2 (V < {v_split}, with aging)", advice=advice)


def _joint_start(
    progress: _Progress, requested: Sequence[str], hi: Block, lo: Block, everything: Block, split: float
) -> bool:
    """Start values for the joint fit: the two-step result when both velocity ranges can carry their step (True:
    a start fitted to the data), else the input values with N0 scaled to the data's level (False)."""
    step1, step2 = _steps(requested)
    if len(hi) > len(step1.free) and len(lo) > len(step2):
        _two_step(progress, requested, hi, lo, split)
        return True
    progress.params = _scaled_start(progress.params, everything, requested)
    return False


def _covariance_two_step(params: Parameters, keys: Sequence[str], hi: Block, lo: Block, scale2: float) -> np.ndarray:
    """Covariance of the two-step estimator: step-1 uncertainty propagated through step 2 (docs/fitting.md)."""
    keys1 = [k for k in keys if k in identify.NO_AGING_KEYS]
    keys2 = [k for k in keys if k in identify.AGING_KEYS]
    p1, p2 = len(keys1), len(keys2)
    space1 = Space(params, tuple(keys1))
    c1 = scale2 * _gauss_newton(space1, space1.vector(), hi)
    if p2 == 0:
        return c1
    space2 = Space(params, tuple(keys2))
    j22 = jacobian(space2, space2.vector(), lo)
    h22 = _inverse(j22.T @ j22)
    if p1 == 0:
        return scale2 * h22
    j21 = jacobian(space1, space1.vector(), lo)
    gain = h22 @ j22.T @ j21  # d theta2 / d theta1 = -gain
    c22 = gain @ c1 @ gain.T + scale2 * h22
    c12 = -c1 @ gain.T
    return np.block([[c1, c12], [c12.T, c22]])


def _inverse(matrix: np.ndarray) -> np.ndarray:
    """Inverse of a symmetric positive semi-definite matrix; infinite variance along null directions."""
    values, vectors = np.linalg.eigh(matrix)
    if values.size == 0:
        return matrix
    if values.min() <= values.max() * 1e-14:
        return np.full_like(matrix, np.inf)
    return (vectors / values) @ vectors.T


def _gauss_newton(space: Space, theta: np.ndarray, block: Block) -> np.ndarray:
    """(J^T J)^-1 of the weighted residuals at ``theta``: the covariance for unit noise."""
    jac = jacobian(space, theta, block)
    return _inverse(jac.T @ jac)


def _quantile(level: float, dof: int, noise_known: bool) -> float:
    tail = 0.5 + level / 2.0
    return float(stats.norm.ppf(tail) if noise_known else stats.t.ppf(tail, max(dof, 1)))


def fit_steady(
    data: SteadyData | str | Path,
    params: Parameters | str | None = None,
    method: str = "auto",
    split: float | str | None = None,
    fix: Mapping[str, Any] | None = None,
    free: Sequence[str] | None = None,
    intervals: str | None = None,
    level: float = 0.95,
    bootstrap_samples: int = 200,
    seed: int | None = None,
    exclude_rows: Sequence[int] = (),
) -> SteadyFit:
    """Fit Eqs 6-8 to a steady friction curve; see the module docstring for the methods.

    ``method``: ``two-step`` (the paper's), ``joint``, or ``auto`` (the default): the two-step fit, and the joint
    fit instead where the two-step's split approximation does not describe the data while the model does (a
    note says so).  ``params`` gives the start values and every value not fitted (default
    gelatin-glass); ``fix`` maps keys to values (SI numbers or strings with
    units) held fixed; ``free`` adds keys to fit (e.g. ``bonds.breakage_weight``).  ``split``: the two-step
    method's split velocity (default 800 µm/s); ``auto`` answers a two-step fit short of points at the default
    split with the joint fit (a note says why), while a split given here is kept and its shortage is an error.
    ``intervals`` chooses how the intervals of Vc and sigma_c are computed;
    None picks the method whose coverage was checked for each fit method
    (docs/fitting.md): ``delta`` for two-step, ``profile`` for joint.  ``exclude_rows``: file rows (as the
    warnings number them, the header row 1) left out of the fit, as ``--exclude-row``; a note and the JSON's
    ``excluded_rows`` name them.
    """
    if not isinstance(data, SteadyData | str | Path):
        # a frame or an array is named by its type: its repr runs over many lines
        got = shorten(data) if isinstance(data, str | int | float | None) else f"a {type(data).__name__}"
        raise DataError(
            f"data: expected SteadyData (SteadyData.from_arrays(velocity, stress[, stress_err]), SI) or the path of a"
            f" steady-sliding table, got {got}"
        )
    if isinstance(free, str):  # one key: iterating the string would give its characters ("unknown key 'b'")
        free = [free]
    if not isinstance(data, SteadyData):
        data = read_steady_data(data)
    data = data.without_rows(exclude_rows)  # the stick fit's parser of row numbers (one source)
    if method not in METHODS:
        raise ParameterError(f"method: expected one of {', '.join(METHODS)}, got {method!r}")
    split_given = split is not None
    if split is None:
        split = DEFAULT_SPLIT
    settings = dict(split=split, fix=fix, free=free, level=level, bootstrap_samples=bootstrap_samples, seed=seed)
    if method != "auto":
        return _fit_steady(data, params, method, intervals=intervals, **settings)
    if intervals == "profile":  # the profile likelihood is the joint fit's
        return _fit_steady(data, params, "joint", intervals=intervals, **settings)
    try:
        paper = _fit_steady(data, params, "two-step", intervals=intervals, **settings)
    except TooFewPointsError as short:
        if split_given:  # the split asked for is the problem: say so (and what would fit)
            raise
        # too few points for the two-step's steps is not bad data: the joint fit may have enough (else its own error)
        joint = _fit_steady(data, params, "joint", intervals=intervals, **settings)
        note = (
            f"the two-step method (the paper's) cannot fit these points at its default split"
            f" ({human(split, 'velocity')}): {short.short}; the joint fit (every point with aging) is reported"
            " instead (--split to move the split)"
        )
        return dataclasses.replace(joint, messages=(note, *joint.messages))
    if paper.status != "ok" and paper.reason.startswith(TWO_STEP_MISFIT):
        why = paper.reason.split("; use --method joint")[0]
    elif paper.status == "ok" and _shifted_by_the_split(paper):
        why = (
            "the two-step estimate (the paper's method) of the critical point differs from the joint fit of all"
            " points with aging by more than chance (the split's own bias)"
        )
    elif paper.status == "ok" and any(m.startswith(SPLIT_MISFIT_NOTE) for m in paper.messages):
        note = next(m for m in paper.messages if m.startswith(SPLIT_MISFIT_NOTE))
        measured = note.removeprefix(SPLIT_MISFIT_NOTE + ": ").split(", so the")[0]
        why = f"the two-step method's (the paper's) residuals are mostly its split approximation's: {measured}"
    elif paper.status == "ok" and intervals is None and not split_given:  # a split asked for asks for two-step
        # the paper's fit describes the data: the joint fit is reported for its intervals (docs/fitting.md)
        joint = _fit_steady(data, params, "joint", intervals=intervals, **settings)
        if joint.status != "ok":  # the paper's fit stands where the joint fit cannot be trusted
            note = f"method auto: the joint fit failed ({joint.reason}), so the two-step fit (the paper's) is reported"
            return dataclasses.replace(paper, messages=(note, *paper.messages))
        return dataclasses.replace(joint, messages=(AUTO_JOINT_NOTE, *joint.messages))
    else:
        return paper
    joint = _fit_steady(data, params, "joint", intervals=intervals, **settings)
    note = (
        f"{why}: the joint fit (every point with aging, started from the two-step result) is reported instead"
        " (--method two-step keeps the paper's method)"
    )
    return dataclasses.replace(joint, messages=(note, *joint.messages))


#: The note of ``auto`` reporting the joint fit of data the two-step method describes (docs/fitting.md, Methods).
AUTO_JOINT_NOTE = (
    "method auto: the joint fit (every point with aging, started from the paper's two-step result) is reported, its"
    " intervals by profile likelihood; the two-step method's intervals of the parameters are linearised and carry"
    " its split approximation's bias (at 95 %, τ's held the truth in 79 % of synthetic sets: docs/fitting.md);"
    " --method two-step gives the paper's method"
)


def _shifted_by_the_split(fit: SteadyFit) -> bool:
    """Whether the two-step fit's interval of Vc or σc was widened for the split approximation's bias."""
    return any(WIDENED_NOTE in e.note for e in (fit.critical_velocity, fit.critical_stress))


#: A two-step fit whose chi-square the joint refit of all points with aging lowers below this share of it: the
#: residuals (and the noise estimated from them) are mostly the split approximation's.
SPLIT_MISFIT_SHARE = 0.5
SPLIT_MISFIT_NOTE = "note: the two-step's misfit is mostly its own"
#: The note of an interval widened for the two-step method's own bias.
WIDENED_NOTE = "widened to take in the joint fit's interval"
#: The start of the reason a two-step fit fails for its split approximation while the model describes the data.
TWO_STEP_MISFIT = "the two-step method (no aging above the split) does not describe these data"


def _fit_steady(data: SteadyData, params: Parameters | str | None, method: str, **settings: Any) -> SteadyFit:
    """:func:`_fit_one_method` with every steady state on the compiled march, the fitted curve's critical point
    too: a fit has loaded numba for its Jacobians, and the numpy search of Vc and σc was ~17 % of a fit's CPU
    (0.54 -> 0.45 s a fit of 24 points, Vc within 1.2e-14 and its interval within 5e-13; docs/steady-state.md)."""
    with compiled_marches():
        return _fit_one_method(data, params, method, **settings)


def _fit_one_method(
    data: SteadyData,
    params: Parameters | str | None,
    method: str,
    split: float | str,
    fix: Mapping[str, Any] | None,
    free: Sequence[str] | None,
    intervals: str | None,
    level: float,
    bootstrap_samples: int,
    seed: int | None,
) -> SteadyFit:
    """:func:`fit_steady` by one method, ``two-step`` or ``joint``."""
    auto_note = ""
    if intervals is None:
        intervals = "delta" if method == "two-step" or len(data) > PROFILE_MAX_POINTS else "profile"
        if method == "joint" and intervals == "delta":
            auto_note = (
                f"intervals of Vc and σc by the delta method: with {len(data)} points the chi-square is quadratic"
                " over the interval, where the profile likelihood gives the same ends (--intervals profile to"
                " compute it anyway)"
            )
    if intervals not in INTERVAL_METHODS:
        raise ParameterError(f"intervals: expected one of {', '.join(INTERVAL_METHODS)}, got {intervals!r}")
    if intervals == "profile" and method != "joint":
        raise ParameterError(
            "intervals: the profile likelihood needs --method joint (the two-step estimate does not minimise"
            " one chi-square); use delta or bootstrap with two-step"
        )
    if not 0.0 < level < 1.0:
        raise ParameterError(f"level: expected a confidence level between 0 and 1, got {level!r}")
    split = to_si(split, "velocity", "split")  # a number (m/s) or a string with its unit, "800 um/s"
    if not (math.isfinite(split) and split > 0):
        raise ParameterError(f"split: expected a positive velocity in m/s, got {split!r}")
    if intervals == "bootstrap" and bootstrap_samples < 20:
        raise ParameterError(f"bootstrap samples: expected at least 20, got {bootstrap_samples}")
    base = params if isinstance(params, Parameters) else load_parameters(params or "gelatin-glass")
    base, fixed = _resolve_fix(base, fix)
    explicit, requested = _requested(free, fixed)
    noise_known = data.stress_err is not None
    # the noise measured without the model: a fit far from the data must not set the yardstick it is judged by
    scatter = local_scatter(data.velocity, data.stress, data.stress_err)
    dependence = velocity_dependence(data.stress, data.stress_err, scatter, data.velocity)
    check = _Check(
        method, data, base, requested, explicit, fixed, split, scatter, intervals, level, bootstrap_samples, seed
    )
    if dependence.spread == 0.0:  # one stress throughout: nothing to fit (31 s of joint fit before issue 29)
        return _no_response_fit(check, dependence)
    stated, everything, hi, lo = _blocks(data, split, base)  # the stated errors (or the stress: relative)
    if not dependence.significant:
        # the neighbours' scatter counts a curve's bend between few points as noise: the method's own fit decides
        fitted_anyway = _fit_of_a_flat_looking_curve(check, (everything, hi, lo), dependence)
        if isinstance(fitted_anyway, str):  # noise: say so (a joint fit of it ran 92 s before issue 29, now ~0.3 s)
            return _no_response_fit(check, dependence, fitted_anyway, _rejected_constant(data, dependence))
        progress, keys = fitted_anyway
        # why the fit went on: said once, whatever refits follow (the scaled errors' pass dropped it; round 28)
        trend_notes = [progress.messages.pop()]
        if trend_notes[0].startswith(LEFT_OUT_WARNING):  # and the outlier found by leaving each point out
            trend_notes.insert(0, progress.messages.pop())
    else:
        _require_finite_start(everything, base, fixed)
        progress, keys = _run_method(check, (everything, hi, lo))
        # a dependence the neighbours' scatter missed and the data's trend shows: said once, whatever refits follow
        missed = dependence.neighbours_p > SIGNIFICANCE >= dependence.p_value
        trend_notes = [_trend_note(check, dependence)] if missed else []
    progress, keys, adequacy, check = _adequate_or_searched(check, progress, keys, (everything, hi, lo))
    if not _interpolation_holds((everything, hi, lo), progress.params):
        # the curve changed shape on the way from the start: interpolate where the fit ended, and fit again
        restart = progress.params if adequacy.searched else None
        _, everything, hi, lo = _blocks(data, split, progress.params)
        progress, keys = _run_method(check, (everything, hi, lo), start=restart)
        adequacy = _judge(check, progress, keys, everything, adequacy.searched)
    too_small = _errors_too_small(check, adequacy, len(keys))
    factor = 1.0  # the stated errors' scale found too small (1: taken as stated)
    if too_small:
        # the model describes the data within their own scatter, the stated errors do not: fit again with them
        # scaled by sqrt(chi2_r) and their scale estimated from the residuals (t quantiles), so that what the data
        # determine, the covariance, the profile and the bootstrap all see the real noise.  Scaled, not only
        # reweighted: the profile's constraint residuals have a fixed weight, calibrated for chi^2 ~ dof.  From the
        # first pass's start (or the global search's best): started where it ended, a key it moved far and this
        # pass finds undetermined would be put back at its input value with the others fitted to the moved one
        factor = math.sqrt(adequacy.model.chi_square / (len(data) - len(keys)))
        scaled = dataclasses.replace(data, stress_err=data.stress_err * factor)  # type: ignore[operator]
        check = dataclasses.replace(
            check,
            data=scaled,
            scaled_errors=True,
            scatter=local_scatter(scaled.velocity, scaled.stress, scaled.stress_err),
        )
        restart = progress.params if adequacy.searched else None
        first, first_fit = progress.params, adequacy.method_fit.chi_square / factor**2  # in the scaled errors
        _, everything, hi, lo = _blocks(scaled, split, progress.params)
        progress, keys = _run_method(check, (everything, hi, lo), start=restart)
        adequacy = _judge(check, progress, keys, everything, adequacy.searched)
        if restart is None and adequacy.method_fit.chi_square > LOST_OPTIMUM * first_fit:
            # this pass left the first's optimum (a tester's 12 points: χ²ᵣ 3.3 in the first pass, rms 65 % here,
            # "the model does not describe these data"; round 28): from where the first pass ended, the better kept
            again, again_keys = _run_method(check, (everything, hi, lo), start=first)
            again_fit = _judge(check, again, again_keys, everything, adequacy.searched)
            if again_fit.method_fit.chi_square < adequacy.method_fit.chi_square:
                progress, keys, adequacy = again, again_keys, again_fit
        progress.messages.append(too_small)
    noise_known = data.stress_err is not None and not check.scaled_errors
    fitted = progress.params
    if auto_note:
        progress.messages.append(auto_note)
    full_r = residuals(Space(fitted, ()), np.zeros(0), everything)
    chi_square = everything.chi_square(full_r)
    dof = len(data) - len(keys)
    if method == "joint":
        scale2 = 1.0 if noise_known else chi_square / dof
        space = Space(fitted, tuple(keys))
        covariance = scale2 * _gauss_newton(space, space.vector(), everything) if keys else np.zeros((0, 0))
    else:
        scale2 = 1.0 if noise_known else sum(s.chi_square for s in progress.stages) / dof
        covariance = _covariance_two_step(fitted, keys, hi, lo, scale2)
        _warn_aging_neglected(progress, fitted, hi, math.sqrt(scale2))
    if dof <= 0:
        raise DataError(f"{data.source}: {len(data)} points for {len(keys)} free parameters; need more points")
    noise_scale = math.sqrt(scale2) * factor  # in units of the stated errors (or relative)
    q = _quantile(level, dof, noise_known)
    sd = np.sqrt(np.clip(np.diag(covariance), 0.0, np.inf)) if keys else np.zeros(0)
    correlation = covariance / np.outer(sd, sd) if keys else np.zeros((0, 0))
    estimates = _parameter_estimates(fitted, keys, sd, q, fixed, progress)
    combos = _combination_estimates(fitted, keys, covariance, q)
    model = everything.model(fitted)
    if noise_known:
        noise = "stated stress_err (chi-square not rescaled)"
    elif check.scaled_errors:
        noise = (
            f"stated stress_err, too small for these data: scaled by {noise_scale:.3g} (√χ²ᵣ of the fit), and every"
            " interval computed with the scaled errors"
        )
    else:
        noise = f"relative, estimated from the scatter: {100 * noise_scale:.3g} % of the stress"
    # the neighbours' scatter counts the curve's bend between them as noise (it errs large where the curve bends):
    # the same measure on the fit's residuals, the model's bend taken out, stands beside it
    own_scatter = residual_scatter(data.velocity, data.stress, data.stress_err, model)
    noise += (
        f"; between neighbouring points, of the fit's residuals: {own_scatter.describe()}; of the data without the"
        f" model (which counts the curve's bend between neighbours as noise): {scatter.describe()}"
    ) + _replicate_noise(data, noise_scale if not noise_known else None)
    misfits = adequacy.problems()
    own, best = adequacy.method_fit, adequacy.model
    if method == "two-step" and not misfits and best.chi_square < SPLIT_MISFIT_SHARE * own.chi_square:
        progress.messages.append(
            f"{SPLIT_MISFIT_NOTE}: the joint fit of all points with aging leaves an rms misfit of"
            f" {100 * best.rms_relative:.3g} % against the two-step's {100 * own.rms_relative:.3g} %, so the"
            " two-step's residuals are mostly its split approximation's, and so are the noise and intervals taken"
            " from them (--method joint)"
        )
    why = "the model does not describe the data (see the reason)"
    vc, sc = undetermined_critical(why)
    samples = None
    parameter_intervals = "wald"
    if not misfits:  # intervals (a profile or a bootstrap can take long) only for a curve the model describes
        vc, sc, samples = _critical_estimates(check, fitted, keys, covariance, q, everything, scale2, progress)
        if method == "joint" and check.intervals == "profile" and keys:
            estimates, combos = _profiled_parameters(
                (estimates, combos), fitted, keys, sd, q, everything, progress, level
            )
            parameter_intervals = "profile"
        if method == "two-step" and vc.value is not None:
            vc, sc, estimates, combos = _flag_split_bias(
                (vc, sc, estimates, combos), fitted, everything, keys, scale2, level, progress, adequacy.refit
            )
        said = len(progress.messages)
        vc, sc = _pinned_by_the_data(check, progress, keys, (vc, sc), noise_known)
        if len(progress.messages) == said:  # what it says includes the extrapolation
            _note_extrapolation(progress, vc, data)
    joint_model = None  # two-step: its residuals carry the split approximation's smooth misfit, which can hide a point
    if method == "two-step" and adequacy.refit is not None:
        try:
            joint_model = everything.model(adequacy.refit)
        except (ModelError, ParameterError):  # pragma: no cover - the refit was evaluated by the adequacy check
            joint_model = None
    progress.messages.extend(_outlier_warnings(data, model, stated, noise_scale, dof, joint_model))
    problems = _problems(progress, keys, fitted, base, covariance, chi_square, data) + misfits
    if misfits:
        estimates = tuple(unusable(e, why) for e in estimates)
        combos = tuple(unusable(e, why) for e in combos)
    return SteadyFit(
        data=data,
        parameters=fitted,
        start=base,
        method=method,
        split=split if method == "two-step" else None,
        estimates=estimates,
        combinations=combos,
        free_keys=tuple(keys),
        covariance=covariance,
        correlation=correlation,
        chi_square=chi_square * factor**2,  # against the stated errors
        dof=dof,
        noise=noise,
        noise_scale=noise_scale,
        model_stress=model,
        # with the noise estimated, error is the stress itself (relative weights): scale it to the noise found
        residuals=(data.stress - model) / (stated * noise_scale),
        critical_velocity=vc,
        critical_stress=sc,
        interval_method=intervals,
        level=level,
        stages=tuple(progress.stages),
        messages=tuple(data.notes() + trend_notes + progress.messages),
        samples=samples,
        status="failed" if problems else "ok",
        reason="; ".join(problems),
        stated_errors_scaled=check.scaled_errors,
        parameter_intervals=parameter_intervals,
    )


def _replicate_noise(data: SteadyData, estimated: float | None) -> str:
    """The noise line's clause on the repeated velocities: their scatter alone, which needs neither the model nor
    the curve's shape (pure error), beside the scale the fit estimated (``estimated``, relative or in units of the
    stated errors; None: not estimated)."""
    pure = replicate_scatter(data.velocity, data.stress, data.stress_err)
    if pure is None:
        return ""
    size = f"{100 * pure.scale:.3g} % of the stress" if pure.relative else f"{pure.scale:.3g} stated errors"
    text = (
        f"; of the {pure.replicates} repeated measurement(s) alone, each against the others at its velocity"
        f" (no model, no bend): {size}, {pure.dof:.0f} degrees of freedom, part of every test of the fit against"
        " the noise"
    )
    if estimated is not None and pure.variance > 0:
        text += f"; the fit's residuals, which include them, give {estimated / pure.scale:.3g} times it"
    return text


def _errors_too_small(check: _Check, adequacy: _Adequacy, free: int) -> str:
    """The warning when the stated errors are significantly too small for data the model describes ('' if not).

    The model describes the data when its misfit is within the scatter between neighbouring points (measured
    without the model); if chi^2 against the stated errors is nevertheless far above its degrees of freedom
    (chi^2 test, p <= 1e-3), it is the errors, not the model, that are wrong, and intervals computed from them
    would be too narrow by sqrt(chi^2/dof).  A model that does not describe the data fails instead (elsewhere)."""
    data = check.data
    dof = len(data) - free
    if data.stress_err is None or check.scaled_errors or dof < 1 or adequacy.problems():
        return ""
    best = adequacy.model
    p = float(stats.chi2.sf(best.chi_square, dof))
    if p > SIGNIFICANCE:
        return ""
    reduced = best.chi_square / dof
    scatter = best.scatter  # the best fit's residuals between neighbours: the noise without the model's bend
    text = (
        f"warning: the stated errors (stress_err) are too small for these data: the first fit's residuals (every"
        f" parameter free) are {math.sqrt(reduced):.3g} times them (χ²ᵣ = {reduced:.4g} with {dof} degrees of"
        f" freedom, χ² test: p ="
        f" {p:.2g}), and the scatter of its residuals between neighbouring points is"
        f" {scatter.scale:.3g} times them; the model describes the data within that scatter (p ="
        f" {best.p_value:.2g}), so the errors' scale is estimated from the residuals instead: every interval (Vc, σc,"
        " the parameters and the combinations) is computed with the errors scaled by √χ²ᵣ (Student-t quantiles)"
    )
    if scatter.dof > 0 and float(stats.chi2.sf(scatter.variance * scatter.dof, scatter.dof)) > SIGNIFICANCE:
        text += (
            "; the scatter between neighbours does not confirm errors that small: part of the excess may be a misfit"
            " of the model that these points cannot tell from noise"
        )
    return text


def _outlier_warnings(
    data: SteadyData, model: np.ndarray, error: np.ndarray, scale: float, dof: int, joint: np.ndarray | None = None
) -> list[str]:
    """Warnings naming the points far outside the robust scatter of the residuals (as the stick fit's rows).

    A chi-square (and the scaled errors above) only says the residuals are large on the whole; one or two
    mistyped points are found by their distance from the median in robust standard deviations, which they do not
    move, and confirmed against the rms of the other points (the noise's own 3.7 sigma point is no outlier).  The
    floor (0.1 % of the stress) keeps the approximations of a fit to exact data from being named.
    ``error`` is the stated error (or the stress itself, relative noise), ``scale`` the noise in its units.  The
    distance quoted is the one tested, from the median residual.  ``joint`` (two-step): the stress of the joint fit
    of all points with aging; the two-step's residuals carry the split approximation's smooth misfit, which widens
    their robust scatter and can hide a point that the model's own residuals show (it is named, saying so)."""
    stated = (data.stress - model) / error
    z = stated / scale
    floor = OUTLIER_FLOOR * data.stress / (error * scale)
    far, spread, centre = outlying(z, STEADY_OUTLIER_SPREADS, floor, True)
    ratio = {int(k): abs(z[k] - centre) / spread for k in far}
    hidden: set[int] = set()
    if joint is not None and np.all(np.isfinite(joint)):
        zj = (data.stress - joint) / (error * scale)
        far_j, spread_j, centre_j = outlying(zj, STEADY_OUTLIER_SPREADS, floor, True)
        for k in far_j:
            if int(k) not in ratio:
                ratio[int(k)] = abs(zj[k] - centre_j) / spread_j
                hidden.add(int(k))
    far = np.array(sorted(ratio), dtype=int)
    out = []
    for k in far:
        if data.stress_err is None:
            size = f"{100 * stated[k]:+.3g} % ({z[k]:+.3g} in units of the noise)"
        else:
            size = f"{stated[k]:+.3g} stated errors" + (f" ({z[k]:+.3g} scaled)" if scale != 1.0 else "")
        if k in hidden:
            where = (
                f"the residuals of the joint fit of all points with aging from their median (threshold"
                f" {STEADY_OUTLIER_SPREADS:g}; in this two-step fit's residuals, which carry its split approximation's"
                f" smooth misfit, {abs(z[k] - centre) / spread:.2g} times)"
            )
        else:
            where = f"the residuals from their median (threshold {STEADY_OUTLIER_SPREADS:g})"
        out.append(
            f"warning: row {data.rows[k]} ({human(float(data.velocity[k]), 'velocity', 4)}): σ = {data.stress[k]:.4g}"
            f" Pa against the fit's {model[k]:.4g} Pa, a residual of {size}; {ratio[k]:.2g} times the"
            f" robust scatter of {where}: an outlier? check it (--exclude-row {data.rows[k]} leaves it out)"
        )
    if out and data.stress_err is not None and dof > len(far):
        rest = np.delete(stated, far)
        out.append(
            f"warning: the residuals of the other points, without the {len(far)} named above, give χ²ᵣ ="
            f" {float(rest @ rest) / (dof - len(far)):.3g} against the stated errors (all points:"
            f" {float(stated @ stated) / dof:.4g}; this fit, not refitted without them)"
        )
    return out


#: Least relative misfit a point needs to be named as an outlier (the two-step split leaves 0.3-3 % on exact data,
#: but smoothly; a mistyped point is off by far more).
OUTLIER_FLOOR = 1e-3


NO_RESPONSE_TEXT = "the stress shows no significant velocity dependence"


def _problems(
    progress: _Progress, keys: Sequence[str], fitted: Parameters, base: Parameters, covariance: np.ndarray,
    chi_square: float, data: SteadyData,
) -> list[str]:  # fmt: skip
    """Why the fit cannot be trusted (empty when it can)."""
    problems = []
    stuck = [s.name for s in progress.stages if not s.success]
    if stuck:
        problems.append(f"the search did not converge in {', '.join(stuck)}")
    if keys and not np.all(np.isfinite(covariance)):
        problems.append("the covariance could not be estimated: the data cannot tell the free parameters apart")
    stated_misfit = data.stress_err is not None and chi_square > 2.0 * max(len(data) - len(keys), 1)
    now, start = fitted.as_dict(), base.as_dict()
    unmoved = all(abs(now[k] - start[k]) <= 1e-9 * max(abs(start[k]), 1e-300) for k in keys)
    if keys and unmoved and stated_misfit:  # a start that fits is no failure
        problems.append("the free parameters did not move from their start values, which do not fit the data")
    return problems


#: The whole search box is scanned, and the fit restarted from its best point, where the first fit's misfit against
#: the noise has p at most this (a suspect misfit; it fails at ``SIGNIFICANCE``): the better fit is kept.
SEARCH_P = 0.05

#: The second pass with the stated errors scaled (errors too small) has lost the first pass's optimum when its
#: chi-square exceeds the first's (in the same scaled errors) by more than this factor: it is run again from there.
LOST_OPTIMUM = 1.01

#: A method's fit whose misfit the noise does not explain fails, when the model itself (its best fit on all
#: points with aging) does describe the data, only if its rms misfit also exceeds this fraction of the stress
#: and 3 times the best fit's: the two-step split approximation leaves 0.3-3 % even on exact data
#: (docs/fitting.md), and holding an undetermined key at its input value costs a little.
METHOD_TOLERANCE = 0.05


@dataclass(frozen=True)
class _Check:
    """The fit's request: what the method, the adequacy checks, the global search and the intervals need."""

    method: str
    data: SteadyData
    base: Parameters
    requested: Sequence[str]
    explicit: Sequence[str]
    fixed: Mapping[str, float]
    split: float
    scatter: Scatter
    intervals: str
    level: float
    samples: int  # bootstrap refits
    seed: int | None
    #: the stated errors were found too small and their scale is estimated from the residuals (a second pass)
    scaled_errors: bool = False
    #: where the keys the data do not determine are held (``base`` is the global search's best where it moved)
    held: str = "its input value"


@dataclass(frozen=True)
class _Adequacy:
    """The misfit of the best fit of the model found (``model``) and of the method's own fit, against the
    model-independent noise; ``searched``: trial sets of the global search (0 when none was needed)."""

    model: Misfit
    method_fit: Misfit
    method: str
    searched: int
    #: the joint refit from the two-step result (two-step only): where the bias check starts its own
    refit: Parameters | None = None

    def problems(self) -> list[str]:
        m = self.model
        if m.significant:
            how = (
                f"a global search of {self.searched} trial parameter sets, then least squares on all points with aging"
                if self.searched
                else "least squares on all points with aging"
            )
            pure = m.lack_of_fit
            repeats = f"; {pure.describe()}" if pure is not None else ""
            against = (
                f"{math.sqrt(m.ratio):.3g} times the noise measured between neighbouring points"
                f" ({m.scatter.describe()}; p = {m.neighbours_p:.2g} that noise alone leaves this ratio)"
            )
            if m.data_p <= SIGNIFICANCE and m.data_scatter is not None:
                # the data's own scatter decided (the residuals' is inflated by a fit that wiggles between points)
                stated = " (and the χ² test against the stated errors)" if not m.data_scatter.relative else ""
                against = (
                    f"{math.sqrt(m.data_ratio):.3g} times the data's own scatter between neighbouring points, measured"
                    f" without the model ({m.data_scatter.describe()}; it also counts the curve's bend as noise, so it"
                    f" errs large): F test{stated} p = {m.data_p:.2g}; its residuals' scatter between neighbours is"
                    f" {m.scatter.describe()}"
                )
            return [
                f"the model does not describe these data: its best fit ({how}) leaves an rms misfit of"
                f" {100 * m.rms_relative:.3g} % ({m.rms_pa:.4g} Pa), {against}{repeats};"
                f" the largest residual is {m.worst_pa:+.4g} Pa at {human(m.worst_velocity, 'velocity')} (data"
                f" {m.worst_stress:.4g} Pa, fit {m.worst_stress - m.worst_pa:.4g} Pa)"
            ]
        own = self.method_fit
        if not (own.significant and own.rms_relative > max(3.0 * m.rms_relative, METHOD_TOLERANCE)):
            return []
        misses = (
            f"rms misfit {100 * own.rms_relative:.3g} %, largest residual {own.worst_pa:+.4g} Pa at"
            f" {human(own.worst_velocity, 'velocity')}, while the best fit of the model to all points with aging"
            f" leaves {100 * m.rms_relative:.3g} %"
        )
        if self.method == "two-step":
            return [f"{TWO_STEP_MISFIT}: {misses}; use --method joint"]
        return [
            f"the joint fit, with the parameters the data do not determine held at their input values, does not"
            f" describe these data: {misses}; start from values closer to the data (--params/--set) or --fix them"
        ]


def _misfit_of(check: _Check, params: Parameters, everything: Block, free: int) -> Misfit:
    d = check.data
    try:
        model = everything.model(params)
    except (ModelError, ParameterError):
        model = np.zeros_like(d.stress)
    return misfit(d.velocity, d.stress, d.stress_err, model, free)


def _joint_refit(check: _Check, params: Parameters, keys: Sequence[str], everything: Block) -> Parameters:
    """Least squares of ``keys`` on all points with aging from ``params`` (box centred on the input values)."""
    space = Space(params, tuple(keys))
    try:
        got = minimize(space, space.vector(), everything, Space(check.base, tuple(keys)).vector())
    except (ModelError, ParameterError):  # pragma: no cover - residuals already absorb model failures
        return params
    return space.params(got.theta)


def _judge(check: _Check, progress: _Progress, keys: Sequence[str], everything: Block, searched: int) -> _Adequacy:
    """The method's misfit and, for two-step, that of the joint refit from it (the model's own best nearby)."""
    own = _misfit_of(check, progress.params, everything, len(keys))
    if check.method == "joint":
        return _Adequacy(own, own, check.method, searched)
    # the model is judged by its own best fit near the two-step's (the split approximation is the method's), and
    # so are the stated errors: the two-step's misfit on exact data is no evidence that they are too small
    refit = _joint_refit(check, progress.params, keys, everything)
    joint = _misfit_of(check, refit, everything, len(keys))
    return _Adequacy(joint if joint.chi_square < own.chi_square else own, own, check.method, searched, refit)


def _adequate_or_searched(
    check: _Check, progress: _Progress, keys: list[str], blocks: tuple[Block, Block, Block]
) -> tuple[_Progress, list[str], _Adequacy, _Check]:
    """The method's fit if the model describes the data there; else search globally and refit from the best.

    The misfit is judged against the noise measured without the model (:mod:`stickslip.fitting.scatter`).
    """
    everything = blocks[0]
    first = _judge(check, progress, keys, everything, 0)
    # searched also where the misfit is only suspect (p <= SEARCH_P): 8 points falling steeply, fitted from the
    # input values with a minimum at 58 µm/s and 21.7 % noise (p ≈ 0.01 against the data's own scatter of 4.5 %)
    # where a fit of 4.7 % without a minimum in the data existed (round 30); the better of the two is kept
    if first.model.p_value > SEARCH_P:
        return progress, keys, first, check
    searched, again, again_keys, again_fit, polished_fit, evaluations = _searched_refit(check, blocks)
    best_model = polished_fit if polished_fit.chi_square < first.model.chi_square else first.model
    if again_fit.chi_square < first.method_fit.chi_square:
        check = searched
        progress, keys, own = again, again_keys, again_fit
    else:
        own = first.method_fit
    if own.chi_square < best_model.chi_square:
        best_model = own
    before, after = 100 * first.method_fit.rms_relative, 100 * own.rms_relative
    why = "more than the noise measured between neighbouring points explains"
    if not first.model.significant:
        why = f"more than that noise is likely to leave (p = {first.model.p_value:.2g} ≤ {SEARCH_P:g})"
    elif first.model.neighbours_p > SIGNIFICANCE:  # the repeats decided
        why = "more than the scatter of the repeated measurements explains"
    progress.messages.append(
        f"the least-squares fit from the input values left an rms misfit of {before:.3g} %, {why}, so the whole"
        f" search box was scanned ({evaluations} trial parameter sets) and the fit restarted from the best"
        f" point: rms misfit now {after:.3g} %"
    )
    return progress, keys, _Adequacy(best_model, own, check.method, evaluations), check


def _searched_refit(
    check: _Check, blocks: tuple[Block, Block, Block]
) -> tuple[_Check, _Progress, list[str], Misfit, Misfit, int]:
    """The method's fit restarted from the best point of a scan of the whole search box: (the check it was made
    with, its progress, its free keys, its misfit, the misfit at the polished search point, the trial sets)."""
    everything = blocks[0]
    joint_keys = identify.select_identifiable(check.requested, aging=True).free
    found = global_start(check.base, check.base, joint_keys, everything)
    # polished without the fix-and-refit loop: the model's best, even where the data leave a direction open
    polished = _joint_refit(check, found.params, joint_keys, everything)
    polished_fit = _misfit_of(check, polished, everything, len(joint_keys))
    again, again_keys = _run_method(check, blocks, start=polished)
    again_fit = _misfit_of(check, again.params, everything, len(again_keys))
    if again_fit.chi_square > LOST_OPTIMUM * polished_fit.chi_square:
        # the keys the data do not determine, put back at their input values, lost the search's minimum (8 points
        # falling steeply: 3.3 % at the search's best, 18.8 % with λ, τa and Va back at the input; round 30):
        # held at the search's values instead, where the method's fit can keep it
        moved = dataclasses.replace(check, base=polished, held="the global search's best value")
        held, held_keys = _run_method(moved, blocks, start=polished)
        held_fit = _misfit_of(moved, held.params, everything, len(held_keys))
        if held_fit.chi_square < again_fit.chi_square:
            check, again, again_keys, again_fit = moved, held, held_keys, held_fit
    return check, again, again_keys, again_fit, polished_fit, found.evaluations


def _trend_note(check: _Check, dependence: Dependence) -> str:
    """Why a curve the neighbours' scatter finds flat is fitted: its trend in ln V, from the data alone."""
    return (
        f"the scatter between neighbouring points ({check.scatter.describe()}) counts the curve's own bend between"
        f" these {len(check.data)} points as noise, and against it the stress's variation is not significant (p ="
        f" {dependence.neighbours_p:.2g}, above the threshold p ≤ {SIGNIFICANCE:g} of every test of a velocity"
        " dependence here; one F test, no correction); the other tests of the data alone show the velocity"
        f" dependence: {dependence.others}"
    )


def _fit_of_a_flat_looking_curve(
    check: _Check, blocks: tuple[Block, Block, Block], dependence: Dependence
) -> tuple[_Progress, list[str]] | str:
    """The method's fit of data in which the tests of the data alone (the scatter between neighbours, the trend in
    ln V, the replicates) find no velocity dependence, where the fit does find one
    (:func:`~stickslip.fitting.scatter.model_dependence` or :func:`~stickslip.fitting.scatter.fitted_dependence` at
    the same significance); else what the fit found ('' if it could not be made).

    Few points far apart on a curved σ(V) look like noise to that scatter (ten exact points of the model: p =
    0.02, "no velocity dependence"); flat data and noise stay failed: the model does not explain them better
    than a constant."""
    data = check.data
    try:
        _require_finite_start(blocks[0], check.base, check.fixed)
        progress, keys = _run_method(check, blocks)
        model = blocks[0].model(progress.params)
    except (ModelError, ParameterError):
        return ""
    nested = model_dependence(data.stress, data.stress_err, model, len(keys))
    # the nested F test has n - k degrees of freedom for its noise (one for six points and the joint fit's five
    # parameters: p = 0.014 for a curve varying by a factor 25 with 2 % noise); the scatter of the fit's residuals
    # between neighbours has ~(n - 2)/1.9 whatever k, and with stated errors it agrees with, the errors themselves
    against, noise = fitted_dependence(data.velocity, data.stress, data.stress_err, model)
    if min(nested, against) >= 1.0:
        # no closer to the data than a constant: a fit from the input values that stopped in a minimum of its own
        # (seven points of a U, 500 -> 300 -> 800 Pa: "no closer than the constant" where the model's curve has a
        # minimum; round 31); the whole search box is scanned and the better fit kept, as where a fit misses
        try:
            _, again, again_keys, again_fit, _, _ = _searched_refit(check, blocks)
        except (ModelError, ParameterError):
            again_fit = None
        if (
            again_fit is not None
            and again_fit.chi_square < _misfit_of(check, progress.params, blocks[0], len(keys)).chi_square
        ):
            progress, keys, model = again, again_keys, blocks[0].model(again.params)
            nested = model_dependence(data.stress, data.stress_err, model, len(keys))
            against, noise = fitted_dependence(data.velocity, data.stress, data.stress_err, model)
    p = min(nested, against)
    outliers = left_out = ""
    if p > SIGNIFICANCE:
        # one point far off the fit inflates both noise estimates (a tester's 12 points, one typed 3.9 for 1.74 kPa:
        # 23.6 and 19.5 stated errors, "described by a constant" that misses three points by 30-48 errors; round 28)
        far, keep = _outliers_of_the_fit(data, model, len(keys))
        if not far.size:  # a fit that one point pulled hides it from the robust scatter: each point left out in turn
            far, keep, model_out = _outlier_left_out(check, blocks, len(keys))
            if far.size:
                # judged against the fit of the others, which it did not pull (8 exact points, one halved: the fit
                # of all 8 missed it by 25 % and its neighbour by 40 %, "described by a constant"; round 28)
                k = int(far[0])
                left_out = (
                    f"{LEFT_OUT_WARNING} {data.rows[k]} ({human(float(data.velocity[k]), 'velocity', 4)}): σ ="
                    f" {data.stress[k]:.4g} Pa against {model_out[k]:.4g} Pa of the fit of the other {len(data) - 1}"
                    f" points, a residual of {100 * (data.stress[k] / model_out[k] - 1):+.3g} %, far outside their"
                    f" own residuals' scatter ({STEADY_OUTLIER_SPREADS:g} times it at least): an outlier? check it"
                    f" (--exclude-row {data.rows[k]} leaves it out); the fit below includes it, which pulls the curve"
                    " toward it"
                )
                model = model_out
        if far.size:
            e = None if data.stress_err is None else data.stress_err[keep]
            kept_nested = model_dependence(data.stress[keep], e, model[keep], len(keys))
            kept_against, kept_noise = fitted_dependence(data.velocity[keep], data.stress[keep], e, model[keep])
            if min(kept_nested, kept_against) <= SIGNIFICANCE:
                rows = ", ".join(
                    f"row {data.rows[k]} ({human(float(data.velocity[k]), 'velocity', 4)}, σ = {data.stress[k]:.4g}"
                    f" Pa against the fit's {model[k]:.4g} Pa)"
                    for k in far
                )
                outliers = (
                    f" without {rows}, which the robust scatter of the fit's residuals names as outlying (the"
                    f" outlier test below; with {'them' if far.size > 1 else 'it'}, p = {p:.2g}:"
                    f" {'they inflate' if far.size > 1 else 'it inflates'} the noise measured between neighbours)"
                )
                nested, against, noise = kept_nested, kept_against, kept_noise
                p = min(nested, against)
    if p > SIGNIFICANCE:
        few = (
            f"; with {len(data)} points the noise the fit leaves has ≈{noise.dof:.2g} degrees of freedom: stated"
            " errors (stress_err) or more velocities can show a dependence"
            if data.stress_err is None and noise.dof < 3
            else ""
        )
        if p >= 1.0:
            return "the model's fit finds none either (it is no closer to the data than the constant)"
        return (
            f"the model's fit finds none either (p = {p:.2g}, the smaller of its two tests, above the threshold p ≤"
            f" {SIGNIFICANCE:g}; its residuals scatter {noise.describe()}){few}"
        )
    rms = float(np.sqrt(np.mean(((data.stress - model) / data.stress) ** 2)))
    if data.stress_err is not None and agrees_with_stated_errors(noise):
        how = f"χ² of a constant against the stated errors, which the fit's residuals bear out ({noise.describe()})"
    else:
        how = f"F test of a constant against the noise the fit leaves, {noise.describe()}"
    polynomial = f"; {dependence.others}" if dependence.others else ""
    progress.messages.append(
        f"the tests of the data alone do not settle whether the stress of these {len(data)} points depends on"
        f" velocity (threshold p ≤ {SIGNIFICANCE:g}; p = {dependence.neighbours_p:.2g} against the scatter between"
        " neighbouring points,"
        f" {check.scatter.describe()}, which counts the curve's own bend between them as noise{polynomial}); the"
        f" model's fit shows the dependence{outliers} (rms misfit {100 * rms:.3g} %; {how}: p = {against:.2g}; F test"
        f" of a constant nested in the model: p = {nested:.2g}; the smaller p of the two decides, at the threshold p ≤"
        f" {SIGNIFICANCE:g} of every test of a velocity dependence here), and the noise is measured from its residuals"
    )
    if left_out:
        progress.messages.append(left_out)
    return progress, keys


#: How the warning on a point found by leaving each out in turn starts (the caller keeps it with the trend note).
LEFT_OUT_WARNING = "warning: the fit of the others misses row"


#: At most this share of the points may be left out as outliers when the model's fit decides a velocity dependence.
OUTLIER_SHARE = 0.2


def _outliers_of_the_fit(data: SteadyData, model: np.ndarray, free: int) -> tuple[np.ndarray, np.ndarray]:
    """The points the outlier test of the final fit would name (:func:`_outlier_warnings`, without the two-step's
    joint refit), and the mask of the others; none where they would be more than ``OUTLIER_SHARE`` of the points
    or would leave the fit no more than two degrees of freedom."""
    error = data.stress if data.stress_err is None else data.stress_err
    z = (data.stress - model) / error
    far, _, _ = outlying(z, STEADY_OUTLIER_SPREADS, OUTLIER_FLOOR * data.stress / error, True)
    keep = np.ones(len(data), dtype=bool)
    if far.size > OUTLIER_SHARE * len(data) or len(data) - far.size - free <= 2:
        return np.zeros(0, dtype=int), keep
    keep[far] = False
    return far, keep


#: At most this many points are each left out in turn to find one outlier that pulls the fit of all of them.
LEAVE_ONE_OUT_MAX = 20


def _outlier_left_out(
    check: _Check, blocks: tuple[Block, Block, Block], free: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One point that the fit of the others misses by more than ``STEADY_OUTLIER_SPREADS`` times the robust scatter
    of their residuals (and their rms, and the floor): its index, the mask of the others and, where it is left out,
    the stress of the others' fit (all points).  The one the others' fit misses most, and none with more than
    ``LEAVE_ONE_OUT_MAX`` points or too few left for the fit (:func:`_outliers_of_the_fit`'s limits)."""
    data = check.data
    n = len(data)
    none = np.zeros(0, dtype=int), np.ones(n, dtype=bool), np.full(n, np.nan)
    if n > LEAVE_ONE_OUT_MAX or 1 > OUTLIER_SHARE * n or n - 1 - free <= 2:
        return none
    error = data.stress if data.stress_err is None else data.stress_err
    best, best_ratio, best_model = -1, 0.0, None
    for k in range(n):
        keep = np.ones(n, dtype=bool)
        keep[k] = False
        rest = SteadyData(
            data.velocity[keep], data.stress[keep], None if data.stress_err is None else data.stress_err[keep],
            data.rows[keep], data.source,
        )  # fmt: skip
        try:
            _, everything, hi, lo = _blocks(rest, check.split, check.base)
            progress, _ = _run_method(dataclasses.replace(check, data=rest), (everything, hi, lo))
            model = blocks[0].model(progress.params)
        except (ModelError, ParameterError, TooFewPointsError):
            # the others too few for every requested key (6 points, 5 keys: "5 data point(s) for 5 free
            # parameter(s)", exit 2, for a file of 6 points; round 30): that point is not tested, the fit goes on
            continue
        if not np.all(np.isfinite(model)):
            continue
        z = (data.stress - model) / error
        others = z[keep]
        centre = float(np.median(others))
        spread = 1.4826 * float(np.median(np.abs(others - centre)))
        rms = float(np.sqrt(np.mean((others - centre) ** 2)))
        distance = abs(z[k] - centre)
        if distance <= max(OUTLIER_FLOOR * data.stress[k] / error[k], STEADY_OUTLIER_SPREADS * max(spread, rms)):
            continue
        ratio = distance / max(spread, rms, 1e-300)
        if ratio > best_ratio:
            best, best_ratio, best_model = k, ratio, model
    if best < 0 or best_model is None:
        return none
    keep = np.ones(n, dtype=bool)
    keep[best] = False
    return np.array([best]), keep, best_model


def _rejected_constant(data: SteadyData, dependence: Dependence) -> str:
    """Where the stated errors reject a constant (χ² test, p ≤ ``SIGNIFICANCE``) and the tests of the data alone
    lean toward a dependence (p ≤ ``CONSTANT_DESCRIBES_P``), though not significantly, the χ² in words ('' else).

    A U of 7 points, 500 -> 300 -> 800 Pa with 2 % errors, was "the stress shows no significant velocity
    dependence" beside a constant's χ² p = 6.9e-290 (round 30): the scatter between neighbours, which counts the
    U's own bend as noise (4.5 stated errors), hid it, and the model's best fit misses by 13 % rms; what fails
    there is the model.  Flat noise with errors stated too small leaves the data's own tests far from p ≤ 0.05."""
    if data.stress_err is None or dependence.p_value > CONSTANT_DESCRIBES_P:
        return ""
    w = 1.0 / data.stress_err**2
    level = float(np.sum(w * data.stress) / np.sum(w))
    chi_square = float(np.sum(w * (data.stress - level) ** 2))
    dof = len(data) - 1
    p = float(stats.chi2.sf(chi_square, dof)) if dof > 0 else 1.0
    if p > SIGNIFICANCE:
        return ""
    return f"χ² = {chi_square:.4g} with {dof} degrees of freedom, p = {p:.2g}"


#: The reason's start where the stated errors reject a constant and the model describes the data no better.
NO_MODEL_TEXT = "the model does not describe these data"


def _no_response_fit(check: _Check, dependence: Dependence, fitted: str = "", rejected: str = "") -> SteadyFit:
    """The failed result for data whose stress does not vary by more than its noise: nothing is fitted.
    ``rejected``: the stated errors' χ² of a constant where it rejects it (:func:`_rejected_constant`): the reason
    is then the model's."""
    data, base = check.data, check.base
    why = "not fitted: the data show no velocity dependence"
    found = f"; {fitted}" if fitted else ""
    reason = (
        f"{NO_RESPONSE_TEXT}: {dependence.text}{found}; a dependence is claimed where a test gives p ≤"
        f" {SIGNIFICANCE:g}, so Vc, σc and the parameters are not determined"
    )
    if rejected:
        why = "not fitted: the model does not describe the data"
        reason = (
            f"{NO_MODEL_TEXT}: the stated errors reject a constant stress ({rejected}) and the data alone lean"
            f" toward a velocity dependence (p = {dependence.p_value:.2g} ≤ {CONSTANT_DESCRIBES_P:g}){found}; the"
            " tests of the data alone"
            f" ({dependence.text}) do not reach the threshold p ≤ {SIGNIFICANCE:g} because the scatter between"
            " neighbouring points, which counts the curve's own bend as noise, is large: either the curve has a"
            " shape the model cannot take, or the errors are stated too small and the stress does not depend on"
            " velocity; Vc, σc and the parameters are not determined"
        )
    error = data.stress_err if data.stress_err is not None else data.stress
    weight = 1.0 / error**2
    flat = float(np.sum(weight * data.stress) / np.sum(weight))
    chi_square = float(np.sum(weight * (data.stress - flat) ** 2))
    dof = len(data) - 1
    noise_scale = 1.0 if data.stress_err is not None else math.sqrt(chi_square / max(dof, 1))
    values = base.as_dict()
    estimates = []
    for key in identify.STEADY_KEYS:
        symbol, dimension = identify.SYMBOLS[key], key_dimension(key)
        if key in check.requested:
            estimates.append(Estimate(key, symbol, dimension, values[key], status="undetermined", note=why))
        else:
            note = "fixed by request" if key in check.fixed else "held at its input value"
            estimates.append(Estimate(key, symbol, dimension, values[key], status="fixed", note=note))
    combos = tuple(
        Estimate(c.name, c.symbol, c.dimension, c.value(base), status="undetermined", note=why)
        for c in identify.COMBINATIONS
    )
    noise = (
        ("stated stress_err" if data.stress_err is not None else "relative")
        + f"; between neighbouring points: {check.scatter.describe()}"
        + _replicate_noise(data, None)
    )
    vc, sc = undetermined_critical(why)
    return SteadyFit(
        data=data,
        parameters=base,
        start=base,
        method=check.method,
        split=check.split if check.method == "two-step" else None,
        estimates=tuple(estimates),
        combinations=combos,
        free_keys=(),
        covariance=np.zeros((0, 0)),
        correlation=np.zeros((0, 0)),
        chi_square=chi_square,
        dof=dof,
        noise=noise,
        noise_scale=noise_scale,
        model_stress=np.full(len(data), flat),
        # all equal (a flat record at its logger's resolution): chi-square and the noise scale are 0, the residuals 0
        residuals=np.divide(data.stress - flat, error * noise_scale, out=np.zeros(len(data)), where=noise_scale > 0),
        critical_velocity=vc,
        critical_stress=sc,
        interval_method=check.intervals,
        level=check.level,
        stages=(),
        messages=(*data.notes(), _constant_note(data, flat, chi_square, dof, dependence)),
        status="failed",
        reason=reason,
        flat_level=flat,
    )


#: Without stated errors the constant's own χ² cannot reject it (the noise is measured from it): it is said to
#: describe the stress within its noise only where the tests of a dependence give p above this (the usual 5 %).
CONSTANT_DESCRIBES_P = 0.05


def _constant_note(data: SteadyData, flat: float, chi_square: float, dof: int, dependence: Dependence) -> str:
    """What the constant level of data found without a velocity dependence is: within the noise, or (stated errors
    whose χ² rejects it) not, with the points it misses most; without stated errors, "within its noise" only where
    the tests of a dependence are far from rejecting it, else that the dependence is not significant against the
    large noise estimated, with the numbers."""
    level = human(flat, "stress", 4)
    if data.stress_err is None:
        scatter = math.sqrt(chi_square / max(dof, 1))  # rms of the relative residuals about the constant
        low, high = human(float(data.stress.min()), "stress", 4), human(float(data.stress.max()), "stress", 4)
        measured = (
            f"the stress scatters {100 * scatter:.3g} % (rms, relative) about the constant {level}, from {low} to"
            f" {high}; the tests of a dependence give p = {dependence.p_value:.2g}"
        )
        if dependence.p_value > CONSTANT_DESCRIBES_P:
            return f"the stress is described by a constant {level} within its noise ({measured}); no model was fitted"
        # a round-28 tester: "described by a constant 632.1 Pa within its noise" of stresses from 411 Pa to 21.9 kPa
        return (
            f"the velocity dependence is not significant against the noise estimated from these data, which is large:"
            f" {measured}, above the threshold p ≤ {SIGNIFICANCE:g} but not above {CONSTANT_DESCRIBES_P:g}, so the"
            " data neither show a dependence nor a constant within a small noise (stated errors, more points or"
            " an outlier left out with --exclude-row may decide); no model was fitted"
        )
    p = float(stats.chi2.sf(chi_square, dof)) if dof > 0 else 1.0
    if p > SIGNIFICANCE:
        return f"the stress is described by a constant {level} within its noise; no model was fitted"
    z = (data.stress - flat) / data.stress_err  # type: ignore[operator]
    worst = np.argsort(-np.abs(z), kind="stable")[:3]
    misses = ", ".join(
        f"row {data.rows[k]} ({human(float(data.velocity[k]), 'velocity', 4)}) by {z[k]:+.3g}" for k in worst
    )
    # a round-28 tester: "described by a constant 1.877 kPa within its noise" of points it missed by 48 errors
    return (
        f"the constant {level} does not describe the stress within the stated errors either (χ² = {chi_square:.4g}"
        f" with {dof} degrees of freedom, p = {p:.2g}; it misses {misses} stated errors): the scatter between"
        " neighbouring points is as large as the variation, so the errors are stated too small for these data, or"
        " some points are outliers; no model was fitted"
    )


def _run_method(
    check: _Check, blocks: tuple[Block, Block, Block], start: Parameters | None = None
) -> tuple[_Progress, list[str]]:
    """The least-squares steps of the method from ``start`` (default the base set, which also centres the search
    box and gives the values of what is fixed): the progress record and the fitted keys."""
    everything, hi, lo = blocks
    base, requested = check.base, check.requested
    noise_known = check.data.stress_err is not None and not check.scaled_errors
    progress = _Progress(start or base, base, tuple(check.explicit), noise_known, [], [], [], check.held)
    progress.messages.append(_structure_note(requested, check.fixed))
    if check.method == "joint":
        # what the data do not determine is looked for at the start only where the start was fitted to them: at
        # the input values the noise taken from a start far from the data is huge, and every direction looks open
        # (a tester's gel, Vc 42 µm/s: 4 of 5 keys held at the gelatin-glass values, σc 148 Pa "ok" under data
        # >= 1180 Pa; round 28)
        fitted_start = start is not None or _joint_start(progress, requested, hi, lo, everything, check.split)
        # the two-step result is only the start: what the joint fit cannot determine is decided afresh
        progress.messages = progress.messages[:1]
        progress.stages = [dataclasses.replace(s, name=f"start, {s.name}") for s in progress.stages]
        progress.undetermined = []
        selection = identify.select_identifiable(requested, aging=True)
        progress.messages.extend(selection.messages)
        keys, _ = _fit_block(progress, selection.free, everything, "the joint fit", precheck=fitted_start)
        abandoned = [k for k in progress.undetermined if k in progress.explicit]
        if abandoned:
            keys = _without_abandoned(progress, requested, abandoned, everything)
        return progress, keys
    _two_step(progress, requested, hi, lo, check.split)
    kept = [k for k in requested if k not in progress.undetermined and any(k in s.keys for s in progress.stages)]
    return progress, [k for k in kept if k in identify.NO_AGING_KEYS] + [k for k in kept if k in identify.AGING_KEYS]


def _without_abandoned(
    progress: _Progress, requested: Sequence[str], abandoned: Sequence[str], everything: Block
) -> list[str]:
    """The joint fit again without the keys asked for by name (``--free``) that the data leave undetermined.

    Taken first, such a key shapes what else is fitted: ``--free bonds.max_extension`` makes τa structurally
    redundant beside N0, τ and λ (Δl_m enters Δl_m/τa), and an undetermined direction shared with it fixes Va
    (the key asked for is fixed last); once Δl_m itself is fixed, Va and Δl_m/τa were left held, a worse fit than
    the default's in the same model space (χ² 20.1 against 19.7 on the shipped curve, Vc withdrawn).  Held at its
    input value, the key is out of the request, and the selection and the fit are made afresh; its message
    stays."""
    starts = tuple(f"{k} ({identify.SYMBOLS[k]}) is not determined" for k in abandoned)
    said = [m for m in progress.messages if m.startswith(starts)]
    progress.messages = [*progress.messages[:1], *said]
    progress.undetermined = list(abandoned)
    progress.explicit = tuple(k for k in progress.explicit if k not in abandoned)
    values = progress.start.as_dict()
    progress.params = progress.params.with_overrides({k: values[k] for k in abandoned})
    selection = identify.select_identifiable([k for k in requested if k not in abandoned], aging=True)
    progress.messages.extend(selection.messages)
    keys, _ = _fit_block(progress, selection.free, everything, "the joint fit", precheck=True)
    return keys


def _interpolation_holds(blocks: Sequence[Block], params: Parameters) -> bool:
    """True when every interpolated block is still accurate at ``params`` (10x the tolerance it was made to)."""
    try:
        return all(interpolation_error(b, params) <= 10 * INTERPOLATION_TOLERANCE for b in blocks)
    except (ModelError, ParameterError):
        return False


def _flag_split_bias(
    estimated: tuple[Estimate, Estimate, tuple[Estimate, ...], tuple[Estimate, ...]],
    fitted: Parameters,
    everything: Block,
    keys: Sequence[str],
    scale2: float,
    level: float,
    progress: _Progress,
    start: Parameters | None = None,
) -> tuple[Estimate, Estimate, tuple[Estimate, ...], tuple[Estimate, ...]]:
    """Widen the two-step intervals of Vc, sigma_c, the parameters and the combinations by the method's own bias
    when it matters.

    The two-step fit neglects aging above the split, so even exact data give a shifted answer, and the
    shift does not shrink with more data while the interval does (docs/fitting.md).  The shift is measured
    against the joint fit of the same free keys on all points with aging, started from the two-step
    result (``start``: that refit, already made by the adequacy check): the joint fit has no such
    approximation.  With noise the two estimates also differ by chance, by up to about the larger of their
    standard errors (on 24 points they differ by 0-1.5 of them).  When the difference exceeds that times the
    interval's quantile -- the bias would carry the truth out of the interval -- the interval is extended by it
    towards the joint value, and said so.  The parameters and the combinations carry the same bias as Vc (on
    exact gelatin-glass data tau is off by 8 %, 6 standard errors), so they get the same treatment, from the
    same joint fit and its covariance.
    """
    vc, sc, estimates, combos = estimated
    space = Space(start if start is not None else fitted, tuple(keys))  # the adequacy check's refit, if made
    try:
        theta = minimize(space, space.vector(), everything).theta
        joint_space = Space(space.params(theta), tuple(keys))
        covariance = scale2 * _gauss_newton(joint_space, theta, everything)
        located = local_critical(joint_space.base, float(vc.value))  # type: ignore[arg-type]
        gradients = critical_gradient(joint_space, theta, located[0]) if located is not None else None
    except (ModelError, ParameterError):  # pragma: no cover - the two-step optimum is a valid start
        return estimated
    if located is not None and gradients is not None:
        out = []
        for estimate, other, grad in zip((vc, sc), located, gradients, strict=True):
            joint_se = other * math.sqrt(max(float(grad @ covariance @ grad), 0.0))
            out.append(_widened(estimate, float(estimate.value) - other, joint_se, level, progress))  # type: ignore[arg-type]
        vc, sc = out
    joint = joint_space.base
    joint_values = joint.as_dict()
    widened: list[str] = []

    def shifted(estimate: Estimate, other: float, sd_log: float) -> Estimate:
        got = _widened(estimate, float(estimate.value) - other, other * sd_log, level, progress, say=False)  # type: ignore[arg-type]
        if got.interval != estimate.interval and not any(w.startswith(f"{estimate.symbol} ") for w in widened):
            size = abs(float(got.bias)) / float(estimate.stderr)  # type: ignore[arg-type]
            widened.append(f"{estimate.symbol} by {human(float(got.bias), estimate.dimension, 3)} ({size:.2g} s.e.)")  # type: ignore[arg-type]
        return got

    variances = np.diag(covariance)
    estimates = tuple(
        shifted(e, joint_values[e.key], math.sqrt(max(float(variances[keys.index(e.key)]), 0.0)))
        if e.key in keys and e.interval is not None
        else e
        for e in estimates
    )
    matrix = identify.exponent_matrix(keys)
    combo_variances = np.diag(matrix @ covariance @ matrix.T)
    combos = tuple(
        shifted(e, combo.value(joint), math.sqrt(max(float(combo_variances[k]), 0.0))) if e.interval is not None else e
        for k, (e, combo) in enumerate(zip(combos, identify.COMBINATIONS, strict=True))
    )
    if widened:
        progress.messages.append(
            f"warning: the two-step split approximation also shifts {', '.join(widened)} against the joint fit of all"
            f" points with aging: their {100 * level:g} % intervals are widened to take in the joint fit's (the"
            " table's notes say which); --method joint has no such bias"
        )
    return vc, sc, estimates, combos


def _widened(
    estimate: Estimate, bias: float, joint_se: float, level: float, progress: _Progress, say: bool = True
) -> Estimate:
    """``estimate`` with its estimated method bias; the interval extended by it when it is not negligible (and,
    with ``say``, a warning of its own: the parameters' share one)."""
    stderr = estimate.stderr
    if estimate.interval is None or stderr is None or not stderr > 0 or not math.isfinite(joint_se):
        return dataclasses.replace(estimate, bias=bias)
    quantile = float(stats.norm.ppf(0.5 + level / 2.0))
    if abs(bias) <= quantile * max(stderr, joint_se):  # within what chance alone gives: no evidence of bias
        return dataclasses.replace(estimate, bias=bias)
    lo, hi = estimate.interval
    joint = float(estimate.value) - bias  # type: ignore[arg-type]
    joint_lo, joint_hi = _log_interval(joint, joint_se / joint, quantile)
    new_lo = None if lo is None else min(lo, joint_lo)
    new_hi = None if hi is None or joint_hi is None else max(hi, joint_hi)
    dim, symbol, size = estimate.dimension, estimate.symbol, abs(bias) / stderr
    note = (
        f"{estimate.note + '; ' if estimate.note else ''}{WIDENED_NOTE}: the two-step"
        f" method's own bias {human(bias, dim, 3)} ({size:.2g} standard errors) would otherwise leave the truth outside"
    )
    if say:
        progress.messages.append(
            f"warning: the two-step split approximation shifts {symbol} by {human(bias, dim, 3)} against the joint"
            f" fit of all points with aging ({size:.2g} standard errors): the {100 * level:g} % interval"
            f" {_bracket(lo, hi, dim)} alone would claim a precision the method does not have, so it is widened to"
            f" {_bracket(new_lo, new_hi, dim)}, taking in the joint fit's ({symbol} = {human(joint, dim, 5)} ±"
            f" {joint_se / display_unit(joint, dim)[1]:.2g}); --method joint has no such bias"
        )
    return dataclasses.replace(estimate, interval=(new_lo, new_hi), note=note, bias=bias)


def _bracket(lo: float | None, hi: float | None, dimension: str) -> str:
    def end(x: float | None) -> str:
        return "unbounded" if x is None else human(x, dimension, 5)

    return f"[{end(lo)}, {end(hi)}]"


def _structure_note(requested: Sequence[str], fixed: Mapping[str, float]) -> str:
    held = [k for k in identify.STEADY_KEYS if k not in requested]
    combos = ", ".join(identify.combination_names())
    note = f"σ(V) depends on the bond and aging parameters only through {combos} (docs/fitting.md)."
    if "bonds.max_extension" not in requested:
        note += (
            " Δl_m and τ are not separately identifiable from steady data (Δl_m, τ, τa -> s times with"
            " λM/kT, M·N0 -> 1/s times leaves σ(V) unchanged): Δl_m is fixed at its input value."
        )
    user = [k for k in held if k in fixed]
    if user:
        note += f" Fixed by request: {', '.join(user)}."
    rest = [k for k in held if k not in fixed]
    if rest:
        note += f" Held at input values: {', '.join(rest)}."
    return note


def _warn_aging_neglected(progress: _Progress, params: Parameters, hi: Block, noise_scale: float) -> None:
    with_aging = hi.with_aging(True).model(params)
    without = hi.with_aging(False).model(params)
    shift = np.abs(with_aging - without) / (hi.error * noise_scale)
    k = int(np.argmax(shift))
    if shift[k] > AGING_NEGLECT_WARNING:
        progress.messages.append(
            f"warning: step 1 neglects aging above the split, but with the fitted parameters aging changes σ by"
            f" {shift[k]:.2g} standard errors at {human(hi.velocity[k], 'velocity')}: the two-step estimates are"
            " biased by the approximation; --method joint fits all points with aging"
        )


def _parameter_estimates(
    fitted: Parameters, keys: Sequence[str], sd: np.ndarray, q: float, fixed: Mapping[str, float], progress: _Progress
) -> tuple[Estimate, ...]:
    values = fitted.as_dict()
    out = []
    for key in identify.STEADY_KEYS:
        symbol, dimension, value = identify.SYMBOLS[key], key_dimension(key), values[key]
        if key in keys:
            s = float(sd[keys.index(key)])
            out.append(Estimate(key, symbol, dimension, value, value * s, _log_interval(value, s, q)))
            continue
        if key in fixed:
            reason = "fixed by request"
        elif key in progress.undetermined:
            reason = f"not determined by the data; fixed at {progress.held}"
        elif key == "bonds.breakage_weight":
            reason = "u0 = 1 a priori (W0 = 0, paper Section 3)"
        elif key == "bonds.max_extension":
            reason = "exact scale degeneracy with τ, τa, λM/kT and M·N0; fixed at its input value"
        else:
            reason = "σ(V) depends on it only through products with fitted parameters; fixed at its input value"
        out.append(Estimate(key, symbol, dimension, value, status="fixed", note=reason))
    return tuple(out)


def _profiled_parameters(
    estimated: tuple[tuple[Estimate, ...], tuple[Estimate, ...]],
    fitted: Parameters,
    keys: Sequence[str],
    sd: np.ndarray,
    q: float,
    everything: Block,
    progress: _Progress,
    level: float,
) -> tuple[tuple[Estimate, ...], tuple[Estimate, ...]]:
    """The parameters' (and the combinations') intervals from the profile likelihood of the joint fit.

    For each fitted key the others are refitted with its ln-value held at trial values; the interval is where the
    chi-square exceeds the best by the chi^2_1 quantile (stated errors) or the F(1, dof) quantile times the noise
    variance (estimated), as for Vc (:func:`_profile_estimates`).  The linearised (Wald) interval, symmetric in ln,
    under-covered where the chi-square surface is curved along the near-degenerate directions (docs/fitting.md,
    "Uncertainty of the parameters"): 175 and 173 of 200 intervals of tau and tau_a held the truth.  A combination
    carried by one fitted key (the default keys) takes that key's interval; others keep the Wald interval.
    Where a profile search fails the Wald interval is kept, and said."""
    estimates, combos = estimated
    keys = list(keys)
    space = Space(fitted, tuple(keys))
    theta = space.vector()
    centre = Space(progress.start, tuple(keys)).vector()
    best_chi = everything.chi_square(residuals(space, theta, everything))
    dof = max(len(everything) - len(keys), 1)
    if progress.noise_known:
        threshold, scale = float(stats.chi2.ppf(level, 1)), 1.0
    else:
        threshold, scale = float(stats.f.ppf(level, 1, dof)), best_chi / dof
    profile = Profile(space, everything, centre)
    lower = [np.delete(centre - SEARCH_BOX, k) for k in range(len(keys))]
    upper = [np.delete(centre + SEARCH_BOX, k) for k in range(len(keys))]
    # ln-interval (lower, upper) of each key relative to its estimate; None where the search failed
    relative: dict[str, tuple[float | None, float | None] | None] = {}
    for k, key in enumerate(keys):
        others = [j for j in range(len(keys)) if j != k]
        sub_keys = tuple(keys[j] for j in others)

        def chi_at(
            x: float, start: np.ndarray, k: int = k, sub_keys: tuple[str, ...] = sub_keys
        ) -> tuple[float, np.ndarray]:
            pinned = theta.copy()
            pinned[k] = x
            sub = Space(space.params(pinned), sub_keys)
            if not sub_keys:
                return everything.chi_square(residuals(sub, np.zeros(0), everything)), np.zeros(0)
            low, high = lower[k], upper[k]

            def fun(t: np.ndarray) -> np.ndarray:  # Levenberg-Marquardt has no bounds: the box's outside repels
                if np.any(t < low) or np.any(t > high):
                    return np.full(everything.residual_count, FAILED_RESIDUAL)
                return residuals(sub, t, everything)

            try:
                found = least_squares(
                    fun,
                    np.clip(start, low + 1e-9, high - 1e-9),
                    jac=lambda t: jacobian(sub, t, everything),
                    method="lm",
                )
            except (ModelError, ParameterError, ArithmeticError, ValueError):  # a refit that breaks: no profile point
                return math.inf, start
            return everything.chi_square(found.fun), found.x

        start = np.delete(theta, k)
        guess = float(sd[k]) if math.isfinite(float(sd[k])) and sd[k] > 0 else 0.1  # the first step's size, in ln
        ends = [
            profile.end(chi_at, float(theta[k]), start, best_chi, threshold, scale, guess, side) for side in (-1, 1)
        ]
        lo, hi = (None if e.value is None else e.value - float(theta[k]) for e in ends)
        if not all(e.converged for e in ends) or (lo is not None and lo >= 0) or (hi is not None and hi <= 0):
            relative[key] = None
            progress.messages.append(
                f"warning: the profile-likelihood interval of {key} ({identify.SYMBOLS[key]}) failed; its interval is"
                " the linearised one (symmetric in ln)"
            )
            continue
        relative[key] = (lo, hi)
    note = "profile likelihood"
    if progress.undetermined:
        note += f", conditional on {', '.join(progress.undetermined)}"

    def profiled(estimate: Estimate, value: float, ln_ends: tuple[float | None, float | None]) -> Estimate:
        lo, hi = ln_ends
        interval = (
            None if lo is None else value * math.exp(lo),
            None if hi is None or hi >= LARGEST_LOG_WIDTH else value * math.exp(hi),
        )
        stderr = value * (hi - lo) / (2 * q) if lo is not None and hi is not None else estimate.stderr
        unbounded = [side for side, end in zip(("below", "above"), interval, strict=True) if end is None]
        extra = f"; the data do not bound it from {' or '.join(unbounded)} within a factor 100" if unbounded else ""
        return dataclasses.replace(estimate, stderr=stderr, interval=interval, note=note + extra)

    estimates = tuple(
        profiled(e, float(e.value), relative[e.key])  # type: ignore[arg-type]
        if e.key in relative and relative[e.key] is not None and e.value is not None
        else e
        for e in estimates
    )
    matrix = identify.exponent_matrix(keys)
    out = []
    for row, e in zip(matrix, combos, strict=True):
        carriers = np.flatnonzero(row)
        if e.fixed or e.value is None or carriers.size != 1 or relative.get(keys[carriers[0]]) is None:
            out.append(e)
            continue
        power = float(row[carriers[0]])
        lo, hi = relative[keys[carriers[0]]]  # type: ignore[misc]
        ln_ends = (None if lo is None else power * lo, None if hi is None else power * hi)
        if power < 0:
            ln_ends = ln_ends[::-1]
        out.append(profiled(e, float(e.value), ln_ends))
    return estimates, tuple(out)


def _combination_estimates(
    fitted: Parameters, keys: Sequence[str], covariance: np.ndarray, q: float
) -> tuple[Estimate, ...]:
    matrix = identify.exponent_matrix(keys) if keys else np.zeros((len(identify.COMBINATIONS), 0))
    cov = matrix @ covariance @ matrix.T if keys else np.zeros((len(identify.COMBINATIONS),) * 2)
    out = []
    for k, combo in enumerate(identify.COMBINATIONS):
        value = combo.value(fitted)
        if not matrix[k].any():
            out.append(Estimate(combo.name, combo.symbol, combo.dimension, value, status="fixed", note="not fitted"))
            continue
        s = math.sqrt(max(cov[k, k], 0.0))
        out.append(Estimate(combo.name, combo.symbol, combo.dimension, value, value * s, _log_interval(value, s, q)))
    return tuple(out)


def _note_extrapolation(progress: _Progress, vc: Estimate, data: SteadyData) -> None:
    if vc.value is None:
        return
    lo, hi = float(data.velocity.min()), float(data.velocity.max())
    if not lo <= vc.value <= hi:
        progress.messages.append(
            f"Vc = {human(vc.value, 'velocity')} lies outside the measured range"
            f" {human(lo, 'velocity')} to {human(hi, 'velocity')}: it is an extrapolation of the fitted curve"
        )


#: Fewest residual degrees of freedom the fit with the held keys fitted too must leave for an extrapolated Vc to
#: be a measurement (:func:`_pinned_by_the_data`).
RELEASED_DOF = 2
#: The start of the note of a Vc and σc the data do not determine.
NOT_PINNED = "not determined by the data"


def _pinned_by_the_data(
    check: _Check, progress: _Progress, keys: Sequence[str], critical: tuple[Estimate, Estimate], noise_known: bool
) -> tuple[Estimate, Estimate]:
    """Vc and σc as estimated, or undetermined where the data hold no minimum and do not pin it.

    The data hold a minimum when points lie on both sides of it; the fitted curve's minimum below the second
    velocity measured (or above the second-highest) is an extrapolation of the curve's shape.  That shape is data
    only where the data determine it.  Vc and σc are given as undetermined (no value, no interval; the notes say
    why, in words) when such an extrapolated minimum

    * rests on an aging key held because the data do not determine it (``aging.aging_time``, ``aging.aging_velocity``:
      the aging branch that turns the curve down below Vc is what the data do not reach): six points rising from
      200 µm/s to 8 mm/s gave, holding Va (and λ) at the start values, Vc = 173.8 µm/s [154, 190.9] from the
      default start and 36.7 [21.4, 49.2] from another, each "ok";
    * or leaves, with its held keys fitted too, fewer than ``RELEASED_DOF`` degrees of freedom (the model would all
      but pass through the points: with 2 % stated errors on the six points some starts held only λ);
    * or has a profile interval open on one side (kept as that one-sided bound).

    A minimum extrapolated with only λ held (the Eyring near-degeneracy, docs/fitting.md) stays: on the shipped
    synthetic curve (Vc 124.1 µm/s, data from 140 µm/s) the profile with λ fitted too is [108.4, 144.9] µm/s from
    every start tried, against [108.1, 140.8] with λ held."""
    vc, sc = critical
    data = check.data
    velocities = np.unique(data.velocity)
    low, high = float(velocities[0]), float(velocities[-1])
    # a minimum the data hold has points on both sides: one point beyond it shows no turn
    if vc.value is None or float(velocities[1]) <= vc.value <= float(velocities[-2]):
        return vc, sc
    below = vc.value < float(velocities[1])
    if low <= vc.value <= high:
        pair = (low, float(velocities[1])) if below else (float(velocities[-2]), high)
        where = f"between the {'two lowest' if below else 'two highest'} velocities measured"
        where += f" ({human(pair[0], 'velocity')} and {human(pair[1], 'velocity')}), with one point beyond it"
    else:
        where = f"{'below' if below else 'above'} the measured range ({human(low, 'velocity')} to"
        where += f" {human(high, 'velocity')})"
    found = f"the fitted curve's minimum, Vc = {human(vc.value, 'velocity', 4)} (σc = {human(sc.value, 'stress', 4)})"  # type: ignore[arg-type]
    found += f", lies {where}{_edge_shape(progress.params, low if below else high, below)}"
    ends = (None, None) if vc.interval is None else vc.interval
    if vc.interval is not None and None in ends:
        return _withdrawn(progress, f"{NOT_PINNED}: {found}, and the data do not bound it on one side", ends, below)
    interval = "" if None in ends else f" [{human(ends[0], 'velocity', 4)}, {human(ends[1], 'velocity', 4)}]"  # type: ignore[arg-type]
    aging = [k for k in progress.undetermined if k in identify.AGING_KEYS]
    released = len(data) - len(keys) - len(progress.undetermined)
    if aging:
        why = (
            f"{NOT_PINNED}: {found}; where the curve turns there is set by its aging branch, and the data do not"
            f" determine {', '.join(f'{k} ({identify.SYMBOLS[k]})' for k in aging)}, held at the value given: its"
            f" interval{interval} holds only for that value, and another value the data allow as well puts the"
            " minimum elsewhere"
        )
    elif progress.undetermined and released < RELEASED_DOF:
        why = (
            f"{NOT_PINNED}: {found}; its interval{interval} holds only with {', '.join(progress.undetermined)} at the"
            f" values given, which the data do not determine, and fitted too they leave {len(data)} points"
            f" {max(released, 0)} degree(s) of freedom: the model would all but pass through them"
        )
    else:
        return vc, sc
    return _withdrawn(progress, why, (None, None), below)


def _withdrawn(
    progress: _Progress, why: str, bound: tuple[float | None, float | None], below: bool
) -> tuple[Estimate, Estimate]:
    """Vc and σc undetermined (``why``, said in the notes too); Vc keeps a one-sided ``bound`` where it has one."""
    lo, hi = bound
    one_sided = (lo is None) != (hi is None)
    if one_sided:
        side = f"below {human(hi, 'velocity', 4)}" if hi is not None else f"above {human(lo, 'velocity', 4)}"
        why += f"; the data bound it on one side only: Vc {side}"
    progress.messages.append(
        f"Vc and σc are {why}; no value is given{'' if one_sided else ' and no interval'} (measure"
        f" {'lower' if below else 'higher'} velocities, where the minimum is, to determine them)"
    )
    short = why.split(";")[0]
    return (
        Estimate(*CRITICAL[0], None, None, bound if one_sided else None, "undetermined", short),
        Estimate(*CRITICAL[1], None, None, None, "undetermined", short),
    )


def _edge_shape(params: Parameters, edge: float, below: bool) -> str:
    """', where the fitted curve rises (falls) from the lowest (highest) velocity: the data hold no minimum'."""
    try:
        slope = float(np.atleast_1d(steady_state(params, edge).stress_slope)[0])
    except (ModelError, ParameterError):  # pragma: no cover - the fitted curve is evaluated at the data
        return ""
    if slope == 0 or (slope > 0) != below:
        return ""
    return (
        f", where the fitted curve {'rises from the lowest' if below else 'falls to the highest'} velocity measured:"
        " the data hold no minimum"
    )


def _critical_estimates(
    check: _Check,
    fitted: Parameters,
    keys: Sequence[str],
    covariance: np.ndarray,
    q: float,
    everything: Block,
    scale2: float,
    progress: _Progress,
) -> tuple[Estimate, Estimate, dict[str, np.ndarray] | None]:
    point = critical_point(fitted)
    if not point.exists:
        message = f"the fitted curve has no minimum: {point.message}"
        progress.messages.append(message)
        return (*undetermined_critical(message), None)
    vc, sc = float(point.velocity), float(point.stress)
    space = Space(fitted, tuple(keys))
    if check.intervals == "delta" or not keys:
        gradients = critical_gradient(space, space.vector(), vc) if keys else (np.zeros(0), np.zeros(0))
        note = "first-order propagation (delta method) of the parameter covariance, interval symmetric in ln"
        out = []
        for names, value, grad in zip(CRITICAL, (vc, sc), gradients, strict=True):
            sd = math.sqrt(max(float(grad @ covariance @ grad), 0.0))
            out.append(Estimate(*names, value, value * sd, _log_interval(value, sd, q), "derived", note))
        return out[0], out[1], None
    if check.intervals == "profile":
        return (*_profile_estimates(fitted, keys, vc, sc, check.level, everything, progress), None)
    return _bootstrap_estimates(check, fitted, vc, sc, scale2, progress)


def _profile_estimates(
    fitted: Parameters, keys: Sequence[str], vc: float, sc: float, level: float, everything: Block, progress: _Progress
) -> tuple[Estimate, Estimate]:
    """Profile-likelihood intervals of the joint fit over its free keys (fixed keys stay fixed)."""
    space = Space(fitted, tuple(keys))
    centre = Space(progress.start, tuple(keys)).vector()
    best = minimize(space, space.vector(), everything, centre)
    theta = best.theta
    # the profile runs about the refit's own minimum; the values reported stay those of the parameters reported
    # (the refit's Vc was 1.5e-6 to 3.5e-6 off theirs: a fit written out and fed to `critical` read another Vc)
    reported = vc, sc
    located = local_critical(space.params(theta), vc)
    if located is not None:
        vc, sc = located
    profile_dof = max(len(everything) - len(keys), 1)
    if progress.noise_known:
        threshold, scale = float(stats.chi2.ppf(level, 1)), 1.0
    else:
        threshold, scale = float(stats.f.ppf(level, 1, profile_dof)), best.chi_square / profile_dof
    grad_v, grad_s = critical_gradient(space, theta, vc)
    cov = _gauss_newton(space, theta, everything)
    cov = scale * cov if np.all(np.isfinite(cov)) else None
    # the delta method's sd (in ln) is the fallback's interval; the search's first step is never below 1e-3
    delta_v = math.sqrt(max(float(grad_v @ cov @ grad_v), 0.0)) if cov is not None else None
    delta_s = math.sqrt(max(float(grad_s @ cov @ grad_s), 0.0)) if cov is not None else None
    guess_v = max(delta_v, 1e-3) if delta_v is not None else 0.1
    guess_s = max(delta_s, 1e-3) if delta_s is not None else 0.05
    # the σc constraint must be stiff against the data's own curvature along ln σc (scale/guess_s² in the
    # chi-square's units), or each refit slides back towards the best fit and the interval comes out too wide
    profile = Profile(space, everything, centre, stress_weight=STRESS_STIFFNESS * math.sqrt(scale) / guess_s)
    both_ends = [
        [
            profile.end(chi_at, math.log(x), start, best.chi_square, threshold, scale, sd, side, attained)
            for side in (-1, 1)
        ]
        for chi_at, x, start, sd, attained in (
            (profile.chi_square_at_velocity, vc, theta, guess_v, None),
            (profile.chi_square_at_stress, sc, np.append(theta, math.log(vc)), guess_s, profile.attained_stress),
        )
    ]
    note = "profile likelihood"
    if progress.undetermined:
        note += f", conditional on {', '.join(progress.undetermined)}"
    out = []
    q = _quantile(level, profile_dof, progress.noise_known)
    for (name, symbol, dim), value, ends, sd in zip(CRITICAL, reported, both_ends, (delta_v, delta_s), strict=True):
        interval = tuple(None if e.value is None else math.exp(e.value) for e in ends)
        lo, hi = interval
        extra = ""
        if (lo is not None and lo >= value) or (hi is not None and hi <= value) or not all(e.converged for e in ends):
            if sd is None:
                interval = (None, None)
                extra = "; the profile search failed and the covariance is not finite: no interval"
                progress.messages.append(f"warning: profile-likelihood interval of {symbol} failed; no interval")
            else:
                interval = _log_interval(value, sd, q)
                extra = "; the profile search failed, so the delta-method interval is given instead"
                progress.messages.append(f"warning: profile-likelihood interval of {symbol} failed; delta method used")
        else:
            unbounded = [where for where, e in zip(("below", "above"), ends, strict=True) if e.value is None]
            if unbounded:
                extra = f"; the data do not bound {symbol} from {' or '.join(unbounded)} within a factor 100"
        known = [x for x in interval if x is not None]
        stderr = (max(known) - min(known)) / (2 * q) if len(known) == 2 else None
        out.append(Estimate(name, symbol, dim, value, stderr, interval, "derived", note + extra))  # type: ignore[arg-type]
    return out[0], out[1]


def _bootstrap_estimates(
    check: _Check, fitted: Parameters, vc: float, sc: float, scale2: float, progress: _Progress
) -> tuple[Estimate, Estimate, dict[str, np.ndarray]]:
    """Parametric bootstrap: refit curves simulated from the fit with its noise; percentile intervals."""
    data, split = check.data, check.split
    rng = np.random.default_rng(check.seed)
    model = steady_state(fitted, data.velocity).stress
    sigma = (data.stress_err if data.stress_err is not None else model) * math.sqrt(scale2)
    held = dict(check.fixed)
    for key in progress.undetermined:
        held[key] = check.base.as_dict()[key]
    found_v, found_s, failed = [], [], 0
    _, everything, hi, lo = _blocks(data, split, fitted)
    high = data.velocity >= split
    for _ in range(check.samples):
        fake = model + sigma * rng.standard_normal(model.size)
        if np.any(fake <= 0):
            failed += 1
            continue
        blocks = (everything.with_stress(fake), hi.with_stress(fake[high]), lo.with_stress(fake[~high]))
        try:
            refit = _point_fit(blocks, fitted, check.method, held, check.explicit)
        except (DataError, ParameterError):
            failed += 1
            continue
        located = local_critical(refit, vc)
        if located is None:
            failed += 1
            continue
        found_v.append(located[0])
        found_s.append(located[1])
    tail = (1 - check.level) / 2
    note = f"parametric bootstrap, {len(found_v)} refits, percentile interval"
    if failed:
        note += f" ({failed} simulated data sets gave no fit or no minimum and were left out)"
    out = []
    for names, value, sample in zip(CRITICAL, (vc, sc), (np.array(found_v), np.array(found_s)), strict=True):
        if sample.size < 10:
            out.append(Estimate(*names, value, None, None, "derived", note + ": too few to use"))
            continue
        lo, hi = np.quantile(sample, [tail, 1 - tail])
        out.append(Estimate(*names, value, float(np.std(sample, ddof=1)), (float(lo), float(hi)), "derived", note))
    return out[0], out[1], {"critical_velocity": np.array(found_v), "critical_stress": np.array(found_s)}


def _point_fit(
    blocks: tuple[Block, Block, Block],
    start: Parameters,
    method: str,
    held: Mapping[str, float],
    explicit: Sequence[str],
) -> Parameters:
    """Best-fit parameters only (no covariance, no identifiability loop): the bootstrap's refit."""
    params = start.with_overrides(held) if held else start
    _, requested = _requested([k for k in explicit if k not in held], held)
    everything, hi, lo = blocks
    step1, step2 = _steps(requested)
    for keys, block in ((step1.free, hi), (step2, lo)):
        space = Space(params, tuple(keys))
        params = space.params(minimize(space, space.vector(), block).theta)
    if method == "joint":
        keys = identify.select_identifiable([*step1.free, *step2], aging=True).free
        space = Space(params, tuple(keys))
        params = space.params(minimize(space, space.vector(), everything).theta)
    return params
