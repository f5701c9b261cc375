"""The uniform sampling grid of a run's trace, shared by the models that sample "every DT"."""

from __future__ import annotations

import math

import numpy as np


def sample_grid(every: float | None, duration: float) -> np.ndarray:
    """Times 0, every, 2 every, ... up to ``duration``, and ``duration`` itself: a trace sampled this way always
    holds the run's end (its last state, the one a summary's final value reads), whatever ``every``.  A multiple
    of ``every`` within 1e-9 ``every`` of the end stands for it.  Empty without ``every``."""
    if every is None:
        return np.empty(0)
    count = math.floor(duration / every + 1e-9)
    grid = every * np.arange(count + 1)
    grid = grid[grid <= duration]  # every * count may round past the end, which no step reaches
    if duration - grid[-1] > 1e-9 * every:
        grid = np.append(grid, duration)
    return grid
