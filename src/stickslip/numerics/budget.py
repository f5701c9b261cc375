"""Cost bounds: estimate the work of a run before starting it, and refuse what would not finish.

Every time-stepping solver of the package resolves some time scale of the
physics; a run needs about ``duration / scale`` steps.  The estimate is made
from the parameters and the protocol alone (no step is taken), compared with
a stated budget, and a request above it is refused in one line that says what
the estimate rests on and how to raise the budget (``max_steps``,
``--max-steps`` on the command line).  The solvers also stop, with the same
kind of message, if a run takes more steps than the budget after all.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ParameterError

#: default budget in solver steps: about a minute of CPU for the time-dependent model at a few hundred cohorts
DEFAULT_MAX_STEPS = 3_000_000
#: a run expected to take longer than this (s of CPU) shows a progress bar on a terminal
PROGRESS_AFTER_SECONDS = 2.0


@dataclass(frozen=True)
class CostEstimate:
    """The expected number of solver steps, what it rests on (words), and a rough CPU time (s)."""

    steps: float
    basis: str
    seconds: float


def check_max_steps(max_steps: object) -> int:
    """``max_steps`` as a positive int (``None``: the default budget); ParameterError otherwise."""
    if max_steps is None:
        return DEFAULT_MAX_STEPS
    if isinstance(max_steps, bool) or not isinstance(max_steps, (int, float)):
        raise ParameterError(f"max_steps: expected a positive whole number of steps, got {max_steps!r}")
    if not (math.isfinite(max_steps) and max_steps >= 1 and float(max_steps) == int(max_steps)):
        raise ParameterError(f"max_steps: expected a positive whole number of steps, got {max_steps!r}")
    return int(max_steps)


def require_within(
    estimate: CostEstimate, max_steps: int, what: str, hint: str = "raise the budget (max_steps, --max-steps)"
) -> None:
    """Refuse (ParameterError, one line) a run whose estimated steps exceed ``max_steps``."""
    steps = estimate.steps
    if math.isfinite(steps) and steps <= max_steps:
        return
    shown = "an unbounded number of" if not math.isfinite(steps) else f"about {steps:.2g}"
    raise ParameterError(
        f"{what}: would take {shown} steps ({estimate.basis}), above the budget of {max_steps:g} steps;"
        f" shorten the run or {hint}"
    )


def over_budget(what: str, steps: int, max_steps: int, reached: float, duration: float) -> ParameterError:
    """The error for a run that used up its budget before its end (the estimate was too low)."""
    return ParameterError(
        f"{what}: used the budget of {max_steps:g} steps at t = {reached:.6g} s of {duration:.6g} s"
        f" ({steps} steps); shorten the run or raise the budget (max_steps, --max-steps)"
    )


#: steps per state-evolution length Dc slid (rate-and-state: LSODA takes ~1-10 per Dc through stick-slip cycles,
#: far fewer in steady sliding; the estimate is for refusing the absurd, such as a start at 1e300 m/s)
RSF_STEPS_PER_DC = 1.0
#: rate-and-state budget: the solver has its own per-segment bound (MAX_CALLS), so this only refuses the absurd
RSF_MAX_STEPS = 1e12
#: a protocol segment shorter than this fraction of Dc/V cannot be stepped (the solver's first step underflows)
RSF_SHORTEST = 1e-15


def rsf_cost(params: object, protocol: object, start_velocity: float | None = None) -> CostEstimate | None:
    """Steps a rate-and-state run needs: about RSF_STEPS_PER_DC per Dc slid at the fastest of each segment.

    Returns None when the inputs are not what ``rsf.simulate`` takes (it says so itself).
    """
    from ..protocols import Protocol
    from ..rsf.params import RSFParams

    if not isinstance(params, RSFParams) or not isinstance(protocol, Protocol):
        return None
    try:
        v_start = abs(float(protocol.initial_velocity if start_velocity is None else start_velocity))
    except (TypeError, ValueError):
        return None
    if not math.isfinite(v_start):
        return None
    dc = min(state.dc for state in params.states)
    if not dc > 0:
        return None
    steps = 0.0
    for t0, t1, vp in protocol.pieces():
        v = max(abs(float(vp)), v_start)
        steps += RSF_STEPS_PER_DC * v * (t1 - t0) / dc + 1.0
        shortest = RSF_SHORTEST * dc / v if v > 0 else 0.0
        if t1 - t0 < shortest:
            raise ParameterError(
                f"protocol: a segment of {t1 - t0:.3g} s at t = {t0:.6g} s is below {RSF_SHORTEST:.0e} of the"
                f" state's time scale Dc/V = {dc / v:.3g} s: too short to step; lengthen or drop it"
            )
    fastest = max(v_start, float(max(protocol.velocities)))
    basis = f"{protocol.duration:.3g} s, sliding up to {fastest:.3g} m/s, Dc = {dc:.3g} m"
    return CostEstimate(steps, basis, steps * 1e-4)


def require_rsf_budget(params: object, protocol: object, start_velocity: float | None = None) -> None:
    """Refuse (one line) a rate-and-state run estimated above the default budget (``rsf.simulate`` calls it)."""
    estimate = rsf_cost(params, protocol, start_velocity)
    if estimate is not None:
        require_within(estimate, int(RSF_MAX_STEPS), "rate-and-state run", "check the velocities and their units")
