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
