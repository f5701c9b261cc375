"""numba's start in the package's own processes, without its BLAS probe (issue 31).

numba builds its CPU target the first time a kernel is loaded from its cache; that imports
``numba.np.arraymath``, whose module-level ``_check_blas()`` probes for BLAS by importing
``scipy.linalg.cython_blas``, and with scipy installed that imports the whole of ``scipy.linalg``
(scipy._lib's array-API layer and more: ~0.25 s of CPU of the ~1.1 s of a short ``stickslip transient``,
as much as the rest of numba's target).  The probe's answer is used for one thing only: whether numba's
``np.convolve``/``np.correlate`` on floats call BLAS's dot or a plain loop.  None of the package's kernels
uses them, and ``np.dot``, ``@`` and the rest of ``numba.np.linalg`` import scipy.linalg themselves when one
is compiled (tests/test_cli_boundary.py compiles np.dot after the skipped probe).

So in the command's process and in a sweep's local worker processes (:mod:`stickslip.sweeps.worker_start`),
never on ``import stickslip`` (a user's own numba code in a notebook keeps its BLAS convolutions), the probe's
import of scipy.linalg is refused and numba takes "no BLAS" for those two.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from importlib.machinery import ModuleSpec
from types import ModuleType

#: the package the probe would import, and where the probe is (numba 0.68: module, function)
PROBED = "scipy.linalg"
PROBE = ("numba.np.arraymath", "_check_blas")


class _RefuseBlasProbe:
    """A meta-path finder that answers only numba's BLAS probe's import of scipy.linalg, with ImportError."""

    def find_spec(
        self, fullname: str, path: Sequence[str] | None = None, target: ModuleType | None = None
    ) -> ModuleSpec | None:
        if fullname != PROBED:
            return None
        frame = sys._getframe(1)
        while frame is not None:  # only the probe's import: any other import of scipy.linalg goes ahead
            if (frame.f_globals.get("__name__"), frame.f_code.co_name) == PROBE:
                raise ModuleNotFoundError(f"{PROBED} is not imported for numba's BLAS probe", name=fullname)
            frame = frame.f_back
        return None


def skip_blas_probe() -> None:
    """Refuse numba's BLAS probe its import of scipy.linalg in this process (once; nothing if numba's target is
    already built)."""
    if PROBE[0] in sys.modules or any(isinstance(finder, _RefuseBlasProbe) for finder in sys.meta_path):
        return
    sys.meta_path.insert(0, _RefuseBlasProbe())  # type: ignore[arg-type]
