"""Fixtures shared by the whole suite."""

from __future__ import annotations

import os

import pytest
from click.testing import CliRunner

from stickslip import critical_point, load_parameters

#: The heaviest test files, heaviest first: seconds of a whole-suite run on the 2-core machine (2026-11-29, one
#: process, ``--durations=0`` summed per file, numba's cache warm; the files issue 31 shortened as measured after
#: it): 21.9, 21.7, 20.3, 20, 20, 19.0 (the report's build), 18.8, 14.6, 14.0, 11.8, 9.7, 9.5, 7.5, 7.1, 6.8, 6.1,
#: 6 (and numba's compilation when it runs first), 5.9, 5.4, 5.3, 5.1, 5.1, then 5 and less.  Of 426 s.
HEAVY_FIRST = (
    "test_rsf_fit_protocols.py",
    "test_fit_steady.py",
    "test_transient_inertia.py",
    "test_docs.py",
    "test_bayes.py",
    "test_report.py",
    "test_transient.py",
    "test_transient_box.py",
    "test_transient_budget.py",
    "test_rsf_two_state.py",
    "test_regimes.py",
    "test_inertia.py",
    "test_rsf_fit.py",
    "test_cli_fit.py",
    "test_transient_speed.py",
    "test_robust_box.py",
    "test_aging_saturation.py",
    "test_fit_steady_global.py",
    "test_rsf_fit_cli.py",
    "test_steady_slope.py",
    "test_sweep_cluster.py",
    "test_transient_summary.py",
    "test_critical_aliasing.py",
)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Under xdist, the heaviest files first (largest job first: the last files to start are short ones).

    scripts/run-tests.sh hands whole files to the workers (``--dist loadfile``) in this order
    (``--no-loadscope-reorder``; xdist's own order, most tests first, put test_bayes.py, 62 s in 7 tests, near the
    end, where one worker ran it while the other had nothing left).  The sort is stable: the other files keep
    their order, and so do the tests in a file.  A run without workers keeps the plain order.
    """
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return
    rank = {name: place for place, name in enumerate(HEAVY_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))


@pytest.fixture(scope="session")
def params():
    """The paper's parameter set (frozen, so sharing it is safe)."""
    return load_parameters("gelatin-glass")


@pytest.fixture(scope="session")
def critical(params):
    """Vc and sigma_c of gelatin-glass (Eq 9)."""
    return critical_point(params)


@pytest.fixture(scope="session")
def sigma_c(critical):
    return critical.stress


@pytest.fixture(scope="session")
def runner() -> CliRunner:
    return CliRunner()
