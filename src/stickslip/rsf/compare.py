"""Old home of the bond-versus-RSF comparison, deprecated: it warns on import.

The comparison runs the bond model through the model interface, so it is a study above the engines:
:mod:`stickslip.studies.bond_rsf`.  This alias is the one engine module allowed to import upwards
(``tests/test_import_graph.py``: ``DEPRECATED_ALIASES``); nothing in the package imports it.
"""

import warnings

from ..studies.bond_rsf import *  # noqa: F403  (every public name of the new home)
from ..studies.bond_rsf import __all__  # noqa: F401

warnings.warn(
    "stickslip.rsf.compare is deprecated; import from stickslip.studies.bond_rsf", DeprecationWarning, stacklevel=2
)
