"""A time-dependent run's answer does not depend on what the process ran before it.

The quasi-steady reduction tabulates the steady curve (transient/reduction.py).  Tables used to be shared across
runs: any table that covered a stretch's velocities at a tolerance as tight or tighter served it, so a run gave
other numbers (within its rtol) after a run at a tighter rtol over wider velocities: a sweep's point depended on
the points its worker had run before, and a report's number on the sections before it.  Now a run reuses only its
own tables, and the process keeps a memo of exact requests, which returns the table the run would build itself.
"""

from __future__ import annotations

import numpy as np

import stickslip
from stickslip.protocols import Protocol, Segment
from stickslip.transient import reduction, run_transient, solver


def _run(rtol: float, pieces: list[tuple[float, float]]):
    protocol = Protocol(tuple(Segment(v, d) for v, d in pieces))
    return run_transient(stickslip.load_parameters("gelatin-glass"), protocol, start="steady", every=5e-3, rtol=rtol)


def _trace(run) -> list[np.ndarray]:
    return [np.asarray(run.time), np.asarray(run.stress), np.asarray(run.slider_velocity), np.array([run.steps])]


def _clear() -> None:
    reduction._BUILT.clear()
    solver._STEADY_COHORTS.clear()


def test_a_run_gives_the_same_numbers_after_a_tighter_run_over_wider_velocities():
    """Before: the tighter run's table (rtol 1e-5, 297-909 um/s) served the run's stretches, and its stress moved by
    1.5e-13 (within its rtol, but the numbers depended on the process's history)."""
    _clear()
    fresh = _trace(_run(1e-4, [(350e-6, 0.2), (700e-6, 0.2)]))
    assert reduction._BUILT, "the run used no table: the test would not see a shared one"
    _clear()
    _run(1e-5, [(300e-6, 0.2), (2e-3, 0.05)])  # its tables cover every stretch of the run above
    after = _trace(_run(1e-4, [(350e-6, 0.2), (700e-6, 0.2)]))
    for a, b in zip(fresh, after, strict=True):
        assert np.array_equal(a, b)


def test_the_memo_returns_the_table_a_run_would_build():
    reduction._BUILT.clear()
    gel = stickslip.load_parameters("gelatin-glass")
    own: list = []
    first = reduction.manifold_for(gel, True, 300e-6, 800e-6, 2.4e-3, 1e-4, own)
    assert first is not None and own == [first]
    # another run, the same request: the memo's table; a request it does not hold is built anew
    theirs: list = []
    assert reduction.manifold_for(gel, True, 300e-6, 800e-6, 2.4e-3, 1e-4, theirs) is first
    assert reduction.manifold_for(gel, True, 310e-6, 800e-6, 2.4e-3, 1e-4, [], build=False) is None
    fresh = reduction.build_manifold(gel, True, 300e-6, 2.4e-3, 1e-4)
    x = np.log(np.geomspace(300e-6, 2.4e-3, 7))
    assert np.array_equal(first.stress(x), fresh.stress(x)) and np.array_equal(first.lag(x), fresh.lag(x))
