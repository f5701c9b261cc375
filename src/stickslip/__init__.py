"""stickslip: the bond-population-balance model of soft-solid friction and stick-slip.

Implements Juvekar & Singh, "Analysis of Stick-Slip Motion as a Jump Phenomenon":
the steady friction curve sigma(V) (Eqs 6-8), the critical point (Eq 9), the
stick phase (Eqs 11-16), the jump, the slip phase (Eq 10) and whole cycles
(Eq 17); fitting to measurements and the analysis of measured traces.

Every public name is loaded on first use (PEP 562), so that ``import
stickslip`` (and the command line, which imports it first) stays fast: the
model pulls in scipy, fitting lmfit, trace analysis pandas.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

from .errors import DataError, ModelError, ParameterError, StickslipError, UnitError

if TYPE_CHECKING:
    from .models import FrictionModel, Rig, Run, available_models, get_model, register_model, run
    from .parameters import Parameters, available_parameter_sets, load_parameters
    from .quasistatic.critical import CriticalPoint, critical_point
    from .quasistatic.cycle import Simulation, simulate
    from .quasistatic.jump import jump_velocity
    from .quasistatic.slip import SlipPhase, slip_phase
    from .quasistatic.steady import SteadyState, steady_state, steady_stress_many
    from .quasistatic.stick import StickPhase, stick_phase

_LAZY = {
    "CriticalPoint": "stickslip.quasistatic.critical",
    "critical_point": "stickslip.quasistatic.critical",
    "Simulation": "stickslip.quasistatic.cycle",
    "simulate": "stickslip.quasistatic.cycle",
    "jump_velocity": "stickslip.quasistatic.jump",
    "SlipPhase": "stickslip.quasistatic.slip",
    "slip_phase": "stickslip.quasistatic.slip",
    "SteadyState": "stickslip.quasistatic.steady",
    "steady_state": "stickslip.quasistatic.steady",
    "steady_stress_many": "stickslip.quasistatic.steady",
    "StickPhase": "stickslip.quasistatic.stick",
    "stick_phase": "stickslip.quasistatic.stick",
    "Parameters": "stickslip.parameters",
    "available_parameter_sets": "stickslip.parameters",
    "load_parameters": "stickslip.parameters",
    "fit_steady": "stickslip.fitting",
    "fit_stick": "stickslip.fitting",
    "read_steady_data": "stickslip.fitting",
    "read_stick_data": "stickslip.fitting",
    "sample_posterior": "stickslip.fitting",
    "analyze_trace": "stickslip.analysis",
    "read_trace": "stickslip.analysis",
    "compare_with_model": "stickslip.analysis",
    "sweep": "stickslip.sweeps",
    "run": "stickslip.models",
    "Run": "stickslip.models",
    "Rig": "stickslip.models",
    "FrictionModel": "stickslip.models",
    "register_model": "stickslip.models",
    "get_model": "stickslip.models",
    "available_models": "stickslip.models",
}

__all__ = [  # every public name once: the errors (loaded now) and the lazy names above
    "CriticalPoint",
    "DataError",
    "FrictionModel",
    "ModelError",
    "ParameterError",
    "Parameters",
    "Rig",
    "Run",
    "Simulation",
    "SlipPhase",
    "SteadyState",
    "StickPhase",
    "StickslipError",
    "UnitError",
    "analyze_trace",
    "available_models",
    "available_parameter_sets",
    "compare_with_model",
    "critical_point",
    "fit_steady",
    "fit_stick",
    "get_model",
    "jump_velocity",
    "load_parameters",
    "read_steady_data",
    "read_stick_data",
    "read_trace",
    "register_model",
    "run",
    "sample_posterior",
    "simulate",
    "slip_phase",
    "steady_state",
    "steady_stress_many",
    "stick_phase",
    "sweep",
]
__version__ = "0.1.0"


#: subpackages and modules reachable as ``stickslip.rsf`` etc. after a plain ``import stickslip``
_SUBMODULES = frozenset(
    {"analysis", "errors", "fileio", "fitting", "models", "numerics", "parameters", "protocols", "quasistatic",
     "report", "rsf", "sweeps", "transient", "units"}
)  # fmt: skip


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    if name in _SUBMODULES:
        return import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'stickslip' has no attribute {name!r}")


def __dir__() -> list[str]:
    # The public names (loaded or not yet), the subpackages and the module's dunders; not the helpers it imports.
    shown = {name for name in globals() if name.startswith("__") or not name.startswith("_")}
    return sorted((shown | set(__all__) | _SUBMODULES) - _PRIVATE)


_PRIVATE = {"Any", "TYPE_CHECKING", "annotations", "import_module"}
