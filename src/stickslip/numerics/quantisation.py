"""The step in which a measured column is written (an ADC's bit, a transducer's resolution).

Lab records are often written in whole steps q of one quantity; below q a record is a staircase, and its noise
is never less than q/sqrt(12).  Both the lab records of rate-and-state fits (rsf/data.py, the load point's
displacement) and the trace analysis (analysis/detect.py, the stress) use this one rule.
"""

from __future__ import annotations

import numpy as np


def quantum(values: np.ndarray) -> float:
    """The step in which ``values`` are written, where they are written in whole steps of one (0 when not).

    The smallest nonzero change between successive values is the candidate; it is the step when at least 90 %
    of the changes are whole multiples of it (within 2 %) and the largest change is under 1e6 of them."""
    steps = np.abs(np.diff(values))
    steps = steps[steps > 0]
    if steps.size < 10:
        return 0.0
    q = float(np.min(steps))
    whole = np.abs(steps / q - np.round(steps / q)) < 0.02
    return q if np.mean(whole) > 0.9 and np.max(steps) / q < 1e6 else 0.0
