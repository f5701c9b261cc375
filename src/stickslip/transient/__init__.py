"""The time-dependent population balance of bonds (Eqs 1-5), any loading history: docs/transient.md.

``run_transient`` solves Eq 1 by the method of characteristics (cohorts of
bonds by birth time, chain extension = slider travel since birth) under
velocity control or through the elastic block; ``critical_stiffness`` gives
the stiffness below which steady sliding is linearly unstable.
"""

from __future__ import annotations

from .result import TRACE_COLUMNS, Snapshot, TransientResult
from .solver import run_transient
from .stability import critical_stiffness, interface_response

__all__ = ["TRACE_COLUMNS", "Snapshot", "TransientResult", "critical_stiffness", "interface_response", "run_transient"]
