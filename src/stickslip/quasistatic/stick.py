"""The stick phase: linear loading of the stuck block and the collapse of the attached chains (Eqs 11-17).

With n = Nc/Nc0, s(t) = (lambda/kT) sigma(t)/Nc0 and r = uc/tau, Eq 15 is dn/dt = -r n exp(s(t)/n - t/tau_a).
It is explosive, not stiff, so it is solved in an arc-length-like variable theta (``w`` handled through its
logarithm), and whether the block never slips is proved at checkpoints (:func:`never_slips`), else the answer is
"undetermined".  The derivation, the numerics and the threshold velocity (:func:`stuck_threshold`):
docs/stick-phase.md.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..columns import attribute_frame
from ..errors import ModelError, ParameterError
from ..numerics.roots import brentq  # scipy's Brent bit for bit (tests/test_roots.py), without scipy.optimize
from ..parameters import Parameters, require_flag
from ..reprs import compact_repr, field_values
from ..units import refuse_beyond_float, shorten
from .jump import require_critical_point
from .steady import require_parameters

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    from matplotlib.axes import Axes

#: Tolerances of the theta integration (time and n are both O(1) there).
RTOL = 1e-11
ATOL = 1e-13
#: With aging, give up (status "undetermined") after this many aging times without slip or proof.
HORIZON_AGING_TIMES = 1e4
#: Without aging the collapse always comes; this only guards against absurd parameters.
HORIZON_SCALED_TIME = 1e15
#: Below this n the chains are gone for the integrator (exp(-s/n) underflowed long before).
N_GONE = 1e-200
#: -ln of the shortest time scale used (1e-300 s), see _Rates.time_scale.
SHORTEST_LOG_TIME = 690.0
#: Samples of the output curve.
SAMPLES = 400
#: Said whenever Eq 15 keeps a pulled block stuck for ever (docs/stick-phase.md §5).
STUCK_LIMITATION = "this is a limitation of Eq 15, whose aging term −t/τa grows without bound, not a prediction"
#: Added for the paper's gel alone (:data:`PAPER_SETS`): a user's own gel was never measured by the paper.
PAPER_DATA_NOTE = "the paper has no stick-slip data below 50 µm/s"
#: The built-in parameter sets of the paper's gelatin gel (overrides keep the name).
PAPER_SETS = ("gelatin-glass", "gelatin-glass-saturating")
#: Largest bound of the aging exponent accepted by the bounded-aging extension (e^-100: aging has long won).
MAX_AGING_CAP = 100.0
#: Relative width to which :func:`stuck_threshold` brackets the threshold velocity.
THRESHOLD_RTOL = 1e-4
#: Candidate floors, as fractions of the way from K V0 tau_a b/Nc0 to n, tried by the stuck proof.
FLOOR_FRACTIONS = (0.5, 0.8, 0.9, 0.95, 0.99)
#: How the theta integration is done: "steps" (scipy's DOP853 steps on Python floats, stickslip.numerics.dop853)
#: or "solve_ivp" (the same method through scipy, ~6x dearer per call: the reference of benchmarks/bench_stick.py)
SOLVER = "steps"


@dataclass(frozen=True)
class StickPhase:
    """One stick phase (Eqs 11-16).  Arrays in SI units; time from the instant of sticking."""

    __repr__ = compact_repr  # counts, not hundreds of array elements

    time: np.ndarray
    stress: np.ndarray
    chain_fraction: np.ndarray
    stuck: bool
    stick_time: float | None
    peak_stress: float | None
    start_stress: float
    pulling_velocity: float
    status: str  # "slipped", "stuck" or "undetermined"
    message: str
    aging: bool
    stiffness: float  # the effective K of Eq 17, Pa/m
    chain_floor: float | None = None  # a proven lower bound of Nc/Nc0 for all time, when stuck
    parameters: Parameters | None = field(default=None, repr=False, compare=False)
    _dense: Any = field(default=None, repr=False, compare=False)

    @property
    def end_time(self) -> float:
        """The last time computed (t_s when the block slipped)."""
        return float(self.time[-1])

    def stress_at(self, t: np.ndarray | float) -> np.ndarray:
        """sigma(t) of Eq 12 (with the Eq 17 stiffness)."""
        return self.start_stress + self.stiffness * self.pulling_velocity * np.asarray(t, dtype=float)

    def chain_fraction_at(self, t: float) -> float:
        """Nc/Nc0 at time ``t`` (0 after the collapse; the dense solution in between)."""
        t = float(t)
        if self.stick_time is not None and t >= self.stick_time:
            return 0.0
        if t <= 0.0:
            return 1.0
        if self._dense is None or t >= self.end_time:
            return float(np.interp(t, self.time, self.chain_fraction))
        dense, scale = self._dense
        theta = brentq(lambda s: float(dense(s)[0]) * scale - t, dense.start, dense.end, xtol=1e-14, rtol=1e-14)
        return float(min(max(dense(theta)[1], 0.0), 1.0))

    def as_dict(self) -> dict[str, object]:
        names = "status stuck stick_time peak_stress start_stress pulling_velocity aging chain_floor message"
        return field_values(self, names)

    def to_frame(self) -> pd.DataFrame:
        """time [s], stress [Pa], chain_fraction (Nc/Nc0)."""
        return attribute_frame(self, "time stress chain_fraction")

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        """Nc/Nc0 against time (Figs 3, 6); returns the Axes."""
        from ..plots.cycles import plot_stick

        return plot_stick(self, ax=ax, **kwargs)


def check_velocity(value: Any, name: str = "pulling_velocity") -> float:
    """A pulling velocity in m/s: finite and >= 0."""
    return _number(value, name, "m/s", "a velocity")


def check_stress(value: Any, name: str = "start_stress") -> float:
    return _number(value, name, "Pa", "a stress")


def _start_stress(params: Parameters, start_stress: Any) -> float:
    """The stress a stick starts from: ``start_stress`` checked, or sigma_c of the critical point when None."""
    if start_stress is not None:
        return check_stress(start_stress)
    cp = require_critical_point(params)
    assert cp.stress is not None
    return float(cp.stress)


def _number(value: Any, name: str, unit: str, at_least_zero: str = "") -> float:
    """``value`` as a finite float; given ``at_least_zero`` (what it is, "a stress"), one >= 0."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ParameterError(f"{name}: expected a number in {unit}, got {shorten(value)}")
    refuse_beyond_float(value, name)
    v = float(value)
    if not math.isfinite(v):
        raise ParameterError(f"{name}: expected a finite number in {unit}, got {v!r}")
    if at_least_zero and v < 0:
        raise ParameterError(f"{name}: expected {at_least_zero} >= 0 in {unit}, got {v!r}")
    return v


@dataclass(frozen=True)
class _Rates:
    """Eq 15 in the variables of the module docstring: dn/dt = -r n exp((s0 + k t)/n - t/tau_a)."""

    r: float  # uc/tau, 1/s
    s0: float  # (lambda/kT) sigma_0/Nc0
    k: float  # (lambda/kT) K V0/Nc0, 1/s
    inv_aging: float  # 1/tau_a (0 without aging), 1/s
    aging_cap: float = math.inf  # bound of the aging exponent t/tau_a (the bounded-aging extension)

    def aging(self, t: float) -> float:
        """The aging exponent of Eq 15, t/tau_a, bounded by ``aging_cap``."""
        return min(t * self.inv_aging, self.aging_cap)

    def time_scale(self) -> float:
        """T: the time in which the fresh load would break the chains, or the loading and aging times.

        Kept above 1e-300 s: a load that breaks the chains faster collapses them at t ~ 0 anyway.
        """
        fresh = math.log(self.r) + self.s0
        other = self.k + self.inv_aging
        total = np.logaddexp(fresh, math.log(other)) if other > 0 else fresh
        return float(math.exp(-min(float(total), SHORTEST_LOG_TIME)))


def never_slips(rates: _Rates, t: float, n: float) -> float | None:
    """A proven floor of n for all times after ``t`` (so the block never slips), or None.

    For t' > t, while n >= n_low, the breakage rate per chain is at most
    r exp(c t' + d) with c = k/n_low - 1/tau_a and d = s0/n_low.  If c < 0 the
    remaining breakage is at most R = r exp(c t + d)/|c|, so n stays above
    n e^{-R}; if that is >= n_low, n can never reach n_low (the first time it
    did would contradict the bound).  docs/stick-phase.md has the details.
    """
    if rates.inv_aging == 0.0 or n <= 0.0 or math.isfinite(rates.aging_cap):
        return None  # without aging, or with bounded aging, the load always wins in the end
    balance = rates.k / rates.inv_aging  # n must stay above k tau_a for aging to win
    if n <= balance:
        return None
    for fraction in FLOOR_FRACTIONS:
        floor = balance + fraction * (n - balance)
        if floor <= 0.0:
            continue
        c = rates.k / floor - rates.inv_aging
        log_r = math.log(rates.r) + c * t + rates.s0 / floor - math.log(-c)
        if log_r < math.log(math.log(n / floor)):
            return floor
    return None


def stuck_limitation(params: Parameters) -> str:
    """What a "stuck for ever" verdict of Eq 15 means: :data:`STUCK_LIMITATION`, and for the paper's gel
    (:data:`PAPER_SETS`) that the paper has no data there; a user's own gel (tester J, round 28) gets the first
    alone."""
    return f"{STUCK_LIMITATION}: {PAPER_DATA_NOTE}" if params.name in PAPER_SETS else STUCK_LIMITATION


def _no_load_phase(
    params: Parameters, rates: _Rates, v0: float, stress: float, aging: bool, horizon: float
) -> StickPhase:
    # Nothing pulls: n decays as exp(-r tau_a (1 - e^{-t/tau_a})) (or e^{-r t}) and the block never slips.
    t = np.linspace(0.0, max(horizon, 1.0 / rates.r if rates.r > 0 else 1.0), SAMPLES)
    if aging:
        capped = np.minimum(t * rates.inv_aging, rates.aging_cap)  # the aging exponent, bounded or not
        aged = -np.expm1(-capped) / rates.inv_aging + (t - capped / rates.inv_aging) * np.exp(-capped)
        n = np.exp(-rates.r * aged)
    else:
        n = np.exp(-rates.r * t)
    return StickPhase(
        time=t,
        stress=np.zeros_like(t),
        chain_fraction=n,
        stuck=True,
        stick_time=None,
        peak_stress=None,
        start_stress=stress,
        pulling_velocity=v0,
        status="stuck",
        message="no load (zero start stress and zero pulling velocity): the block never slips",
        aging=aging,
        stiffness=params.block.effective_stiffness,
        parameters=params,
    )


def _hold(log_rt: float, s0: float, k: float, inv_aging: float, cap: float, scale: float, tp: float, n: float) -> float:
    """dt'/dtheta = 1/(1 + w) at (t', n), the aging exponent bounded by ``cap`` (the bounded-aging extension)."""
    if n <= N_GONE:  # the collapse, continued smoothly through n = 0
        return 0.0
    t = tp * scale
    log_w = log_rt + math.log(n) + (s0 + k * t) / n - min(t * inv_aging, cap)
    if log_w > 0.0:  # 1/(1 + w) without overflow
        e = math.exp(-log_w)
        return e / (1.0 + e)
    return 1.0 / (1.0 + math.exp(log_w))


def _hold_unbounded(log_rt: float, s0: float, k: float, inv_aging: float, scale: float, tp: float, n: float) -> float:
    """:func:`_hold` without the bound of aging (most calls)."""
    if n <= N_GONE:
        return 0.0
    t = tp * scale
    log_w = log_rt + math.log(n) + (s0 + k * t) / n - t * inv_aging
    if log_w > 0.0:
        e = math.exp(-log_w)
        return e / (1.0 + e)
    return 1.0 / (1.0 + math.exp(log_w))


def _hold_function(rates: _Rates, scale: float, log_rt: float) -> Callable[[float, float], float]:
    """dt'/dtheta = 1/(1 + w) at (t', n); dn/dtheta is that minus 1 (docs/stick-phase.md §3).

    A :func:`functools.partial` of a module-level function, not a closure: the dense output keeps it (to fill its
    interpolation coefficients lazily) and the StickPhase keeps the dense output, so a closure made every
    quasi-static result unpicklable (round 28).
    """
    s0, k, inv_aging, cap = rates.s0, rates.k, rates.inv_aging, rates.aging_cap
    if math.isfinite(cap):
        return functools.partial(_hold, log_rt, s0, k, inv_aging, cap, scale)
    return functools.partial(_hold_unbounded, log_rt, s0, k, inv_aging, scale)


def _solve_steps(
    rates: _Rates,
    scale: float,
    log_rt: float,
    checkpoints: list[float],
    decide: Callable[[float, float, float], bool],
    horizon: float | None,
) -> tuple[str, Any, tuple[float, float]]:
    """The theta integration on Python floats (:mod:`stickslip.numerics.dop853`: solve_ivp's DOP853, ~6x cheaper)."""
    from ..numerics.dop853 import integrate

    hold = _hold_function(rates, scale, log_rt)
    result = integrate(hold, (0.0, 1.0), checkpoints, decide, rtol=RTOL, atol=ATOL)
    if result.reason == "decided" and horizon is not None and horizon > result.y_end[0] * scale:
        # the block is stuck: follow the (slow, t-like) decay on to the requested horizon
        theta_h = result.s_end + (horizon / scale - result.y_end[0]) * 1.001 + 1.0
        integrate(hold, result.y_end, [theta_h], lambda *_: False, RTOL, ATOL, result.s_end, result.steps)
    return result.reason, result.steps, result.y_end


def _solve_ivp(
    rates: _Rates,
    scale: float,
    log_rt: float,
    checkpoints: list[float],
    decide: Callable[[float, float, float], bool],
    horizon: float | None,
) -> tuple[str, Any, tuple[float, float]]:
    """The theta integration through solve_ivp (the reference of benchmarks/bench_stick.py and the tests)."""
    from ..numerics.events import integrate_in_chunks

    hold = _hold_function(rates, scale, log_rt)

    def field_(_theta: float, y: np.ndarray) -> list[float]:
        g = hold(y[0], y[1])
        return [g, g - 1.0]

    def collapse(_theta: float, y: np.ndarray) -> float:
        return float(y[1])

    def decide_(theta: float, y: np.ndarray) -> bool:
        return decide(theta, float(y[0]), float(y[1]))

    result = integrate_in_chunks(field_, [0.0, 1.0], collapse, checkpoints, decide_, rtol=RTOL, atol=ATOL)
    dense = result.solution
    if result.reason == "decided" and horizon is not None and horizon > float(result.y_end[0]) * scale:
        theta_h = result.s_end + (horizon / scale - float(result.y_end[0])) * 1.001 + 1.0
        integrate_in_chunks(
            field_, result.y_end, collapse, [theta_h], lambda *_: False, rtol=RTOL, atol=ATOL,
            start=result.s_end, chained=dense,
        )  # fmt: skip
    return result.reason, dense, (float(result.y_end[0]), float(result.y_end[1]))


def stick_phase(
    params: Parameters,
    pulling_velocity: float,
    start_stress: float | None = None,
    aging: bool = True,
    horizon: float | None = None,
    aging_cap: float | None = None,
) -> StickPhase:
    """Solve the stick phase (Eqs 11-16) from the instant of sticking.

    ``aging_cap`` switches on the **bounded-aging extension** (not in the
    paper; off by default): the aging exponent t/tau_a of Eq 15 is replaced
    by min(t/tau_a, aging_cap), a contact that stops strengthening after
    aging_cap aging times.  Then the load always wins and every stick ends
    (docs/stick-phase.md §6).

    ``pulling_velocity`` (m/s) may be 0: a constant load ``start_stress`` is
    held (a creep-rupture lifetime).  ``start_stress=None`` means sigma_c of
    the critical point (Eq 9).  ``aging=False`` drops the aging term of
    Eq 15 (tau_a -> infinity).  When the block stays stuck the chain
    fraction is followed at least up to ``horizon`` seconds (if given).

    The result's ``status`` is ``"slipped"`` (with ``stick_time`` = t_s and
    ``peak_stress`` = sigma_s of Eq 16), ``"stuck"`` (proven: the block never
    slips) or ``"undetermined"`` (neither within 10^4 aging times).
    """
    solved = _solved(params, pulling_velocity, start_stress, aging, horizon, aging_cap)
    if isinstance(solved, StickPhase):
        return solved
    return _phase(params, solved)


def stick_time(
    params: Parameters, pulling_velocity: float, start_stress: float | None = None, aging: bool = True
) -> tuple[float, float] | None:
    """(t_s, sigma_s) of Eq 16 as :func:`stick_phase` finds them, without its trace; None where the block does not
    slip (stuck, or undetermined).  A cost estimate asks for these alone: the trace's dense output was half the
    time of a stick phase (~1 ms)."""
    solved = _solved(params, pulling_velocity, start_stress, aging, None, None)
    if isinstance(solved, StickPhase) or solved.reason != "event":
        return None
    ts = solved.y_end[0] * solved.scale
    return ts, solved.sigma0 + solved.stiffness * solved.v0 * ts


@dataclass(frozen=True)
class _Solved:
    """Eq 15 integrated in theta (:func:`_solved`): what :func:`_phase` makes the result of."""

    v0: float
    sigma0: float
    aging: bool
    stiffness: float
    scale: float
    reason: str
    dense: Any
    y_end: tuple[float, float]
    floor: list[float]


def _solved(
    params: Parameters,
    pulling_velocity: float,
    start_stress: float | None,
    aging: bool,
    horizon: float | None,
    aging_cap: float | None,
) -> _Solved | StickPhase:
    """The arguments checked and Eq 15 integrated (a StickPhase at once where nothing loads the block)."""
    from ..units import refused_as_written, si_argument

    require_parameters(params)
    with refused_as_written(pulling_velocity):
        v0 = check_velocity(si_argument(pulling_velocity, "velocity", "pulling_velocity"))
    with refused_as_written(start_stress):
        sigma0 = _start_stress(
            params, None if start_stress is None else si_argument(start_stress, "stress", "start_stress")
        )
    aging = require_flag(aging, "aging")
    if horizon is not None:
        horizon = _number(si_argument(horizon, "time", "horizon"), "horizon", "s")
        if horizon < 0:  # 0 is allowed: the time-dependent model asks with what is left of a segment
            raise ParameterError(f"horizon: expected a time >= 0 in s, got {horizon!r}")
    cap = math.inf
    if aging_cap is not None:
        cap = _number(aging_cap, "aging_cap", "aging times")
        if not 0 <= cap <= MAX_AGING_CAP:
            raise ParameterError(f"aging_cap: expected a bound of t/τa from 0 to {MAX_AGING_CAP:g}, got {cap!r}")
    stiffness = params.block.effective_stiffness
    b = params.bonds.force_sensitivity
    nc0 = params.stick.attached_chains
    rates = _Rates(
        r=params.stick.break_rate,
        s0=b * sigma0 / nc0,
        k=b * stiffness * v0 / nc0,
        inv_aging=1.0 / params.stick.aging_time if aging else 0.0,
        aging_cap=cap if aging else math.inf,
    )
    if not rates.k <= math.exp(SHORTEST_LOG_TIME):  # issue 12: such loads made the integration hang (or NaN)
        raise ModelError(
            f"the block is loaded at K V0 = {stiffness * v0:.3g} Pa/s: the chains would collapse within 1e-300 s"
            " of sticking, below what the stick model resolves; use a smaller pulling velocity or block stiffness"
        )
    if rates.s0 == 0.0 and rates.k == 0.0:
        return _no_load_phase(params, rates, v0, sigma0, aging, horizon or 0.0)
    scale = rates.time_scale()
    log_rt = math.log(rates.r) + math.log(scale)

    if aging and not math.isfinite(rates.aging_cap):
        t_end = HORIZON_AGING_TIMES * params.stick.aging_time
        # checkpoints in theta; theta = t' + (1 - n) exactly, so theta >= t'
        count = max(1, math.ceil(math.log2(max(t_end / params.stick.aging_time, 2.0))) + 1)
        checkpoints = [params.stick.aging_time * 2.0**j / scale + 1.0 for j in range(count)]
    else:
        checkpoints = [HORIZON_SCALED_TIME]
    floor: list[float] = []

    def decide(_theta: float, tp: float, n: float) -> bool:
        found = never_slips(rates, tp * scale, n)
        if found is not None:
            floor.append(found)
        return found is not None

    solve = _solve_steps if SOLVER == "steps" else _solve_ivp
    reason, dense, y_end = solve(rates, scale, log_rt, checkpoints, decide, horizon)
    return _Solved(v0, sigma0, aging, stiffness, scale, reason, dense, y_end, floor)


def _phase(params: Parameters, solved: _Solved) -> StickPhase:
    """The stick phase's trace and verdict from its integration."""
    v0, sigma0, aging, stiffness, scale = solved.v0, solved.sigma0, solved.aging, solved.stiffness, solved.scale
    reason, dense, y_end, floor = solved.reason, solved.dense, solved.y_end, solved.floor
    theta = np.linspace(dense.start, dense.end, SAMPLES)
    tp, n = dense(theta)
    time = np.maximum.accumulate(tp * scale)
    n = np.clip(n, 0.0, 1.0)
    if reason == "event":
        ts = y_end[0] * scale
        time = np.minimum(np.maximum.accumulate(time), ts)  # dense output may overshoot ts by rounding
        time[-1], n[-1] = ts, 0.0
        sigma_s = sigma0 + stiffness * v0 * ts
        status, stuck = "slipped", False
        message = f"the attached chains collapse at ts = {ts:.6g} s, σs = {sigma_s:.6g} Pa (Eqs 15-16): the block slips"
        stick_time, peak = ts, sigma_s
    elif reason == "decided":
        status, stuck, stick_time, peak = "stuck", True, None, None
        message = (
            f"the block stays stuck: aging wins and Nc/Nc0 provably stays above {floor[0]:.4g} for all time"
            f" (Eq 15; checked at t = {y_end[0] * scale:.4g} s)"
        )
        if v0 > 0.0:
            message += f"; {stuck_limitation(params)}"
    else:
        status, stuck, stick_time, peak = "undetermined", False, None, None
        message = (
            f"undetermined: no slip up to t = {time[-1]:.4g} s, and no proof that the block stays stuck"
            f" (Nc/Nc0 = {n[-1]:.4g} there)"
        )
    return StickPhase(
        time=time,
        stress=sigma0 + stiffness * v0 * time,
        chain_fraction=n,
        stuck=stuck,
        stick_time=stick_time,
        peak_stress=peak,
        start_stress=sigma0,
        pulling_velocity=v0,
        status=status,
        message=message,
        aging=aging,
        stiffness=stiffness,
        chain_floor=floor[0] if floor else None,
        parameters=params,
        _dense=(dense, scale),
    )


@dataclass(frozen=True)
class StuckThreshold:
    """The pulling velocity below which Eq 15 keeps the block stuck for ever (docs/stick-phase.md §5).

    ``velocity`` is the midpoint of the bracket ``(lower, upper)``: at
    ``lower`` the block provably never slips, at ``upper`` it slips.
    ``ceiling`` = Nc0 kT/(lambda K tau_a) is the closed-form bound above
    which no block stays stuck.  ``velocity`` is 0 when the block slips at
    every V0 (no aging, or a start stress that breaks the chains unpulled),
    and None when the bracket could not be decided (``message`` says why).
    """

    velocity: float | None
    lower: float
    upper: float
    ceiling: float
    start_stress: float
    aging: bool
    message: str

    def as_dict(self) -> dict[str, object]:
        return field_values(self, "velocity lower upper ceiling start_stress aging message")


def stuck_ceiling(params: Parameters) -> float:
    """Nc0 kT/(lambda K tau_a), m/s: at and above it k tau_a >= 1 >= n, so every stick ends in a slip."""
    return params.stick.attached_chains / (
        params.bonds.force_sensitivity * params.block.effective_stiffness * params.stick.aging_time
    )


def stuck_threshold(
    params: Parameters, start_stress: float | None = None, aging: bool = True, rtol: float = THRESHOLD_RTOL
) -> StuckThreshold:
    """The threshold V* of Eq 15: below it the block never slips, above it every stick ends (§5 of the note).

    The stick phase is monotone in V0 (a faster puller breaks more chains at
    every instant), and it ends in a slip exactly when Nc/Nc0 falls below
    k tau_a = (lambda/kT) K V0 tau_a/Nc0, so V* is unique and lies below
    :func:`stuck_ceiling`; it is bracketed by bisection on the proven outcome
    of :func:`stick_phase`.  ``start_stress=None`` means sigma_c.
    """
    sigma0 = _start_stress(params, start_stress)
    ceiling = stuck_ceiling(params)

    def result(velocity: float | None, lower: float, upper: float, message: str) -> StuckThreshold:
        return StuckThreshold(velocity, lower, upper, ceiling, sigma0, aging, message)

    if not aging:
        return result(0.0, 0.0, 0.0, "without the aging term of Eq 15 every stick ends in a slip")
    unpulled = stick_phase(params, 0.0, sigma0)
    if unpulled.status == "slipped":
        return result(0.0, 0.0, 0.0, f"held at {sigma0:.6g} Pa the chains collapse even unpulled: {unpulled.message}")
    if unpulled.status != "stuck":
        return result(None, 0.0, ceiling, f"undecided at V0 = 0: {unpulled.message}")
    lower, upper = 0.0, ceiling
    while upper - lower > rtol * upper:
        middle = 0.5 * (lower + upper)
        status = stick_phase(params, middle, sigma0).status
        if status == "undetermined":
            return result(None, lower, upper, f"undecided at V0 = {middle:.6g} m/s (neither slip nor proof)")
        if status == "stuck":
            lower = middle
        else:
            upper = middle
    velocity = 0.5 * (lower + upper)
    return result(
        velocity,
        lower,
        upper,
        f"from {sigma0:.6g} Pa the block never slips below V0 = {velocity * 1e6:.5g} µm/s (Eq 15 with"
        f" τa = {params.stick.aging_time:g} s; every V0 above {ceiling * 1e6:.5g} µm/s slips);"
        f" {stuck_limitation(params)}",
    )
