"""Fixtures shared by the whole suite."""

from __future__ import annotations

import gc
import os
from collections.abc import Generator

import pytest
from click.testing import CliRunner

from stickslip import critical_point, load_parameters

# property tests draw the same examples on every run and machine: a failure repeats, and their cost does not move
# with the draw (a corpus sample cost 1-11 s by the lines it drew); the examples' variety is each test's own.
# hypothesis is a test extra: the documentation build runs its few tests without it
try:
    from hypothesis import settings
except ImportError:  # pragma: no cover - scripts/build-docs.sh's environment
    pass
else:
    settings.register_profile("stickslip", derandomize=True)
    settings.load_profile("stickslip")

#: The heaviest test files, heaviest first, and the first ones arranged for a cold numba cache (a fresh clone, as CI
#: runs): test_docs.py starts alone on one worker and its README page compiles the transient kernels (~50 s of its
#: ~100 s cold), while the other worker runs the rate-and-state and steady fits, which need none of them (~105 s);
#: the next transient files then load the kernels from the cache instead of compiling them a second time on the
#: other core (two workers compiling side by side cost the suite ~45 s of wall time).  Seconds per file, summed
#: from ``--durations=0`` of a cold whole-suite run on the 2-core AMD EPYC machine (2026-11-29): 103.6 (docs; 36 warm),
#: 34.2, 30.1, 23.5, 19.9, 64.7 (transient_inertia; 28 warm), 28.0, 26.4 (the report's build), 20.8, 17.4, 15.1,
#: 13.3, 13.0, 12.4, 10.9, 10.6, then 10 and less.  Of 690 s.
HEAVY_FIRST = (
    "test_docs.py",
    "test_rsf_fit_protocols.py",
    "test_fit_steady.py",
    "test_rsf_two_state.py",
    "test_bayes.py",
    "test_transient_inertia.py",
    "test_transient.py",
    "test_report.py",
    "test_transient_box.py",
    "test_critical_aliasing.py",
    "test_rsf_fit.py",
    "test_transient_budget.py",
    "test_rsf_fit_cli.py",
    "test_inertia.py",
    "test_robust_box.py",
    "test_cli_boundary.py",
    "test_fixred_reduction.py",
    "test_regimes.py",
    "test_transient_speed.py",
    "test_plots.py",
    "test_fit_stick.py",
    "test_fit_steady_global.py",
    "test_cli_fit.py",
    "test_steady_slope.py",
    "test_aging_saturation.py",
    "test_sweep_cluster.py",
)


@pytest.hookimpl(wrapper=True)
def pytest_collection(session: pytest.Session) -> Generator[None, object, object]:
    """Collect with Python's cyclic garbage collector paused.

    Collecting imports every test module through pytest's assert rewriting, which builds and drops millions of
    syntax-tree nodes while the heap already holds numpy, scipy, pandas and matplotlib: each full collection the
    allocations trigger walks that whole heap.  Paused, collecting took 8.6-9.4 s of CPU in each worker instead of
    15.2-16.1 s (the rewriting itself 3.5 s instead of 8.3 s; 2026-11-30, the 2-core AMD EPYC machine).  Pausing it for
    the whole run saved nothing measurable (tests/test_rsf_fit_protocols.py with tests/test_transient.py), so the
    tests run with it as a user's program does."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        return (yield)
    finally:
        if enabled:
            gc.enable()


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
