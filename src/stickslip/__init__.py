"""stickslip: the bond-population-balance model of soft-solid friction and stick-slip.

Implements Juvekar & Singh, "Analysis of Stick-Slip Motion as a Jump Phenomenon":
the steady friction curve sigma(V) (Eqs 6-9), the stick phase (Eqs 11-16), the
jump, the slip phase (Eq 10) and whole cycles (Eq 17).
"""

from .errors import DataError, ModelError, ParameterError, StickslipError, UnitError
from .model.critical import CriticalPoint, critical_point
from .model.steady import SteadyState, steady_state
from .parameters import Parameters, available_parameter_sets, load_parameters

__all__ = [
    "CriticalPoint",
    "DataError",
    "ModelError",
    "ParameterError",
    "Parameters",
    "SteadyState",
    "StickslipError",
    "UnitError",
    "available_parameter_sets",
    "critical_point",
    "load_parameters",
    "steady_state",
]
__version__ = "0.1.0"
