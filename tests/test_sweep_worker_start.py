"""A local cluster's workers start numba without its BLAS probe (stickslip.sweeps.worker_start, issue 31).

The probe imports the whole of scipy.linalg (~0.18 s of each worker's first point) for an answer no kernel uses;
the command's own process refuses it (tests/test_cli_boundary.py), and so must each worker the sweep starts.
"""

from __future__ import annotations

from stickslip.sweeps.engine import dask_client


def test_a_sweeps_local_worker_builds_numbas_target_without_importing_scipy_linalg():
    def build_numbas_target():  # defined here: sent to the worker by value
        import sys

        from numba import njit

        before = "scipy.linalg" in sys.modules
        njit(lambda x: x + 1.0)(1.0)  # the first compile builds the CPU target, the BLAS probe included
        return before, "numba.np.arraymath" in sys.modules, "scipy.linalg" in sys.modules

    with dask_client(workers=1) as client:
        (answer,) = client.run(build_numbas_target).values()
    assert answer == (False, True, False)  # the target was built (the probe ran) and scipy.linalg stayed out
