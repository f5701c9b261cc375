"""What a local cluster's worker process does before its first point (a dask preload module).

Each worker is a fresh process that pays numba's start on its first point: the CPU target built, the cached
kernels loaded.  Part of that target's build is numba's BLAS probe, which imports the whole of scipy.linalg
(~0.18 s of CPU of a ~0.8 s first point on the 2-core machine) for an answer no kernel of the package uses; the
command's own process refuses it (:mod:`stickslip.numerics.numba_start`), and so does each worker of the cluster a
sweep starts, the sweep's own process.  A cluster the user runs (``--scheduler``) keeps its workers as they are,
unless they start with ``dask worker ADDRESS --preload stickslip.sweeps.worker_start``.
"""

from __future__ import annotations

from typing import Any

from ..numerics.numba_start import skip_blas_probe


def dask_setup(worker: Any) -> None:
    """distributed's hook for a preload module, run as the worker starts (importing this module does nothing: the
    sweep's own process imports it for its name)."""
    skip_blas_probe()
