"""Old home of the bond-versus-RSF comparison, deprecated: it warns on import.

The comparison runs the bond model through the model interface, so it is a study above the engines:
:mod:`stickslip.studies.bond_rsf`.  This alias is the one engine module allowed to import upwards
(``tests/test_import_graph.py``: ``DEPRECATED_ALIASES``); nothing in the package imports it.
"""

import warnings

from ..studies.bond_rsf import (
    STEP_PRECISION,
    BondRSF,
    BondTrace,
    bond_response,
    check_friction,
    fit_bond_step,
    physical_problem,
    rsf_of_bond,
    step_guess,
    stick_slip_pair,
)

__all__ = [
    "STEP_PRECISION",
    "BondRSF",
    "BondTrace",
    "bond_response",
    "check_friction",
    "fit_bond_step",
    "physical_problem",
    "rsf_of_bond",
    "step_guess",
    "stick_slip_pair",
]

warnings.warn(
    "stickslip.rsf.compare is deprecated; import from stickslip.studies.bond_rsf", DeprecationWarning, stacklevel=2
)
