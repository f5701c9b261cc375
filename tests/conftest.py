"""Fixtures shared by the whole suite."""

from __future__ import annotations

import os

import pytest
from click.testing import CliRunner

from stickslip import critical_point, load_parameters

#: The heaviest test files, heaviest first: seconds of a whole-suite run on the 2-core machine (2026-11-29,
#: ``--durations=0`` summed per file, numba's cache warm): 39.5, 32.6, 29.4, 28.1, 23.8 (the report's build), 20.6,
#: 20.5, 18.6, 17.4, 15.1, 13.0, 12.5, 12.1, 11.2, 10.3, 9.6, 9.1, 8.4, 7.3, 7.1, 6.7, 6.3, 6.3, then 6 and less.
#: Of 525 s.
HEAVY_FIRST = (
    "test_docs.py",
    "test_rsf_fit_protocols.py",
    "test_bayes.py",
    "test_fit_steady.py",
    "test_report.py",
    "test_transient_inertia.py",
    "test_transient.py",
    "test_transient_box.py",
    "test_transient_budget.py",
    "test_inertia.py",
    "test_bad_input_cli.py",
    "test_rsf_two_state.py",
    "test_steady.py",
    "test_transient_speed.py",
    "test_fit_steady_global.py",
    "test_regimes.py",
    "test_rsf_fit.py",
    "test_steady_slope.py",
    "test_sweep_cluster.py",
    "test_robust_box.py",
    "test_cli_fit.py",
    "test_fixred_reduction.py",
    "test_fit_stick.py",
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
