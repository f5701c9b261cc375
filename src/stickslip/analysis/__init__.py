"""Analysis of measured stick-slip records: per-cycle sigma_c, slope, stiffness, sigma_s, t_s, V_s (Table 1).

``read_trace(path, contact_area=None)`` reads a CSV record,
``analyze_trace(time, stress, pulling_velocity, params=None)`` finds the
regime and the cycles, ``compare_with_model(analysis)`` lays the simulated
model over the record.
"""

from __future__ import annotations

from .compare import Comparison, compare_with_model
from .cycles import CYCLE_QUANTITIES, CycleResult, TraceAnalysis, analyze_trace
from .traces import Trace, check_trace, read_trace

__all__ = [
    "CYCLE_QUANTITIES",
    "Comparison",
    "CycleResult",
    "Trace",
    "TraceAnalysis",
    "analyze_trace",
    "check_trace",
    "compare_with_model",
    "read_trace",
]
