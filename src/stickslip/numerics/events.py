"""Event-driven integration in chunks, with a check between chunks.

:func:`integrate_in_chunks` wraps :func:`scipy.integrate.solve_ivp` for
problems whose end is either an *event* (a terminal zero crossing, such as
the collapse of the attached chains) or a *decision* taken from the state at
checkpoints (such as a proof that the event never comes).  The pieces of
dense output are chained into one :class:`ChainedSolution`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from ..errors import ModelError


@dataclass
class ChainedSolution:
    """Dense output of consecutive solve_ivp runs over increasing ranges of the independent variable."""

    breaks: list[float] = field(default_factory=list)  # start of each piece, then the end of the last
    pieces: list[Callable[[np.ndarray], np.ndarray]] = field(default_factory=list)

    @property
    def start(self) -> float:
        return self.breaks[0]

    @property
    def end(self) -> float:
        return self.breaks[-1]

    def append(self, start: float, end: float, dense: Callable[[np.ndarray], np.ndarray]) -> None:
        if not self.breaks:
            self.breaks.append(start)
        self.breaks.append(end)
        self.pieces.append(dense)

    def __call__(self, s: np.ndarray | float) -> np.ndarray:
        """State at ``s`` (scalar -> shape (n,), array of m values -> shape (n, m))."""
        s_arr = np.atleast_1d(np.asarray(s, dtype=float))
        s_arr = np.clip(s_arr, self.start, self.end)
        which = np.clip(np.searchsorted(self.breaks, s_arr, side="right") - 1, 0, len(self.pieces) - 1)
        out = None
        for k in np.unique(which):
            mask = which == k
            values = np.asarray(self.pieces[k](s_arr[mask]))
            if out is None:
                out = np.empty((values.shape[0], s_arr.size))
            out[:, mask] = values
        assert out is not None
        return out[:, 0] if np.ndim(s) == 0 else out


@dataclass(frozen=True)
class ChunkedResult:
    """Outcome of :func:`integrate_in_chunks`."""

    solution: ChainedSolution
    s_end: float
    y_end: np.ndarray
    reason: str  # "event", "decided" or "horizon"


def integrate_in_chunks(
    fun: Callable[[float, np.ndarray], Sequence[float]],
    y0: Sequence[float],
    event: Callable[[float, np.ndarray], float],
    checkpoints: Sequence[float],
    decide: Callable[[float, np.ndarray], bool],
    rtol: float,
    atol: float,
    method: str = "DOP853",
    start: float = 0.0,
    chained: ChainedSolution | None = None,
) -> ChunkedResult:
    """Integrate ``fun`` from ``s = start`` until the terminal ``event``, a positive ``decide`` or the last checkpoint.

    ``checkpoints`` are increasing values of the independent variable; the
    integration stops at each, calls ``decide(s, y)`` and stops for good when
    it returns True.  Stopping is exact at the event (solve_ivp locates it on
    the dense output).  Pass ``chained`` to extend an earlier solution.
    """
    event.terminal = True  # type: ignore[attr-defined]
    event.direction = -1  # type: ignore[attr-defined]
    chained = ChainedSolution() if chained is None else chained
    s0, y = float(start), np.asarray(y0, dtype=float)
    for s1 in checkpoints:
        if s1 <= s0:
            continue
        sol = solve_ivp(fun, (s0, s1), y, method=method, rtol=rtol, atol=atol, events=event, dense_output=True)
        if sol.status < 0:
            raise ModelError(f"integration failed at s = {s0:.6g}: {sol.message}")
        chained.append(s0, float(sol.t[-1]), sol.sol)
        if sol.status == 1:
            return ChunkedResult(chained, float(sol.t_events[0][0]), sol.y_events[0][0], "event")
        s0, y = float(sol.t[-1]), sol.y[:, -1]
        if decide(s0, y):
            return ChunkedResult(chained, s0, y, "decided")
    return ChunkedResult(chained, s0, y, "horizon")
