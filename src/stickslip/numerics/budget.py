"""Cost bounds: estimate the work of a run before starting it, and refuse what would not finish.

Every time-stepping solver of the package resolves some time scale of the
physics; a run needs about ``duration / scale`` steps.  The estimate is made
from the parameters and the protocol alone (no step is taken), compared with
a stated budget, and a request above it is refused in one line that says what
the estimate rests on and how to raise the budget (``max_steps``,
``--max-steps`` on the command line).  An estimate is a guess within a stated
factor, so only a request far above the budget (:data:`REFUSE_FACTOR`) is
refused up front; any other run starts, and stops when it really uses up its
budget of steps or of CPU time (``max_time``, ``--max-time``), with a message
that says how far it got (:class:`BudgetExhausted`, which carries what was
computed up to there when the solver can give it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ParameterError

#: default budget in solver steps: about a minute of CPU for the time-dependent model at a few hundred cohorts
DEFAULT_MAX_STEPS = 3_000_000
#: default budget in CPU seconds (time.process_time of the process) of a run that has a time budget
DEFAULT_MAX_SECONDS = 600.0
#: a run is refused up front only when its estimate is more than this many times its step budget: below, it runs
#: (the estimate of steps is good to about 0.2-5x), and when its estimated CPU is more than TIME_REFUSE_FACTOR x
#: the time budget (what a person waits for: a run that would be stopped at a third of the way is not started)
REFUSE_FACTOR = 10.0
TIME_REFUSE_FACTOR = 3.0
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


def parse_step_count(text: str, name: str = "--max-steps") -> int:
    """A step budget as typed: a positive whole number in any float spelling (3e6, 3000000, 3_000_000)."""
    try:
        number = float(str(text).strip())
    except ValueError:
        number = math.nan
    if not (math.isfinite(number) and number >= 1 and number == int(number)):
        raise ParameterError(
            f"{name}: expected a positive whole number of steps (such as 3e6, 3000000 or 3_000_000), got {text!r}"
        )
    return int(number)


def check_max_time(max_time: object) -> float:
    """``max_time`` (CPU seconds) as a positive float (``None``: :data:`DEFAULT_MAX_SECONDS`); ParameterError."""
    if max_time is None:
        return DEFAULT_MAX_SECONDS
    if isinstance(max_time, bool) or not isinstance(max_time, (int, float)) or not (max_time > 0):
        raise ParameterError(f"max_time: expected a positive number of CPU seconds, got {max_time!r}")
    return float(max_time)  # inf: no time budget


def require_within(
    estimate: CostEstimate,
    max_steps: int,
    what: str,
    hint: str = "raise the budget (max_steps, --max-steps)",
    max_time: float | None = None,
    factor: float = 1.0,
    time_factor: float = 1.0,
) -> None:
    """Refuse (ParameterError, one line) a run whose estimate exceeds ``factor`` x its budget of ``max_steps``
    steps, or (if given) ``time_factor`` x its ``max_time`` CPU seconds."""
    steps = estimate.steps
    if not (math.isfinite(steps) and steps <= factor * max_steps):
        shown = "an unbounded number of" if not math.isfinite(steps) else f"about {steps:.2g}"
        far = "above" if factor == 1.0 else f"more than {factor:g} x"
        raise ParameterError(
            f"{what}: would take {shown} steps ({estimate.basis}), {far} the budget of {max_steps:g} steps;"
            f" shorten the run or {hint}"
        )
    if max_time is not None and not estimate.seconds <= time_factor * max_time:
        far = "above" if time_factor == 1.0 else f"more than {time_factor:g} x"
        raise ParameterError(
            f"{what}: would take about {_duration(estimate.seconds)} of CPU ({steps:.2g} steps, {estimate.basis}),"
            f" {far} the time budget of {_duration(max_time)}; shorten the run or raise the budget"
            " (max_time, --max-time)"
        )


class BudgetExhausted(ParameterError):
    """A run stopped at its budget of steps or CPU time before its end.

    ``partial`` is what the solver computed up to there (a result whose message says where it stopped), or
    None where the solver cannot give it; ``reached`` is the time of the run reached (s)."""

    def __init__(self, message: str, reached: float | None = None, partial: object = None) -> None:
        super().__init__(message)
        self.reached = reached  # None: not known (an error rebuilt from its message alone)
        self.partial = partial

    def __reduce__(self) -> tuple[object, ...]:  # pickled (a sweep's worker) with where it stopped
        return (type(self), (str(self), self.reached, self.partial))


def over_budget(
    what: str,
    steps: int,
    max_steps: int,
    reached: float,
    duration: float,
    cpu: float | None = None,
    max_time: float | None = None,
) -> BudgetExhausted:
    """The error for a run that used up its budget (steps, or CPU seconds when ``cpu`` is given) before its end."""
    done = f"t = {reached:.6g} s of {duration:.6g} s ({100 * reached / duration:.3g} %, {steps} steps)"
    if cpu is not None and max_time is not None:
        message = (
            f"{what}: stopped at the time budget of {_duration(max_time)} of CPU at {done};"
            " shorten the run or raise the budget (max_time, --max-time)"
        )
    else:
        message = (
            f"{what}: stopped at the budget of {max_steps:g} steps at {done};"
            " shorten the run or raise the budget (max_steps, --max-steps)"
        )
    return BudgetExhausted(message, reached)


def _duration(seconds: float) -> str:
    """CPU seconds in words: 45 s, 12 min, 3.2 h."""
    if seconds < 120:
        return f"{seconds:.3g} s"
    if seconds < 7200:
        return f"{seconds / 60:.3g} min"
    return f"{seconds / 3600:.3g} h"
