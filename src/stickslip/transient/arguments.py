"""Checks of :func:`stickslip.transient.run_transient`'s words that are not numbers of the model (issue 29).

Each refusal is a :class:`~stickslip.errors.ParameterError` naming the argument, raised before any step, so that a
run is never thrown away at its end for an argument it could have refused at its start.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..units import shorten


def check_progress(progress: Any) -> Callable[[float], None] | None:
    """``progress`` is None or a function of the fraction done (called during the run)."""
    if progress is not None and not callable(progress):
        raise ParameterError(f"progress: expected a function of the fraction done (0 to 1), got {shorten(progress)}")
    return progress


def check_rig_words(control: str, stiffness: Any) -> None:
    """A rigid rig (``control='velocity'``: the protocol is the slider's velocity) has no spring to be given."""
    if control == "velocity" and stiffness is not None:
        raise ParameterError(
            f"stiffness: {shorten(stiffness)} given with control='velocity', where the protocol drives the slider"
            " itself and no spring is involved; drop it, or use control='block' for a spring"
        )


def check_snapshot_times(snapshot_times: Any, duration: float) -> list[float]:
    """The instants (s) at which to keep the population: finite times within the run, 0 to ``duration``."""
    if snapshot_times is None:
        return []
    try:
        values = np.atleast_1d(np.asarray(snapshot_times, dtype=float)).ravel()
    except (TypeError, ValueError):
        raise ParameterError(f"snapshot_times: expected times in s, got {shorten(snapshot_times)}") from None
    for value in values.tolist():
        if not (math.isfinite(value) and 0.0 <= value <= duration):
            raise ParameterError(f"snapshot_times: expected times within the run, 0 to {duration:g} s, got {value!r}")
    return values.tolist()
