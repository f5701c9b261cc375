"""Rate-and-state friction (RSF) beside the bond model: laws, spring-slider, stability, fits.

    >>> from stickslip import protocols
    >>> from stickslip.rsf import rsf_params, simulate
    >>> p = rsf_params(a=0.005, b=0.01, dc=10e-6, v_ref=1e-6, stiffness=1e3)
    >>> run = simulate(p, protocols.velocity_steps([1e-6, 10e-6], [10, 30]), every=0.1)

See docs/rsf.md for the equations, the tests and the fits.
"""

from __future__ import annotations

from .laws import LAWS, StateLaw, get_law, register_law
from .params import RSFParams, StateVariable, rsf_params
from .results import Regime, RSFRun
from .solver import simulate
from .stability import Stability, critical_stiffness, neutral_period, stability

__all__ = [
    "LAWS",
    "RSFParams",
    "RSFRun",
    "Regime",
    "Stability",
    "StateLaw",
    "StateVariable",
    "critical_stiffness",
    "get_law",
    "neutral_period",
    "register_law",
    "rsf_params",
    "simulate",
    "stability",
]
