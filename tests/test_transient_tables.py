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


def test_the_stacked_recurrence_gives_each_series_own_values_to_the_bit():
    """Manifold.at evaluates the six series in one Clenshaw recurrence over their zero-padded coefficients (the
    reduced ODE's right-hand side and event tests call it at every stage); against each numpy series' own call:
    equal bit for bit (the padding adds exact zeros, the mapping is the series' own), so the runs' numbers did not
    move.  The series have different degrees (the steady curve's and the lag's tables are refined separately),
    and a repeated point returns the remembered values."""
    gel = stickslip.load_parameters("gelatin-glass")
    m = reduction.build_manifold(gel, True, 110e-6, 1.2e-3, 1e-4)
    assert m is not None and m.stress.coef.size != m.lag.coef.size, "equal degrees: the padding is not exercised"
    series = (m.stress, m.dstress, m.d2stress, m.lag, m.dlag, m.bonded)
    for x in np.log(np.r_[110e-6, 1.2e-3, np.geomspace(111e-6, 1.19e-3, 37)]):
        got = m.at(float(x))
        want = np.array([float(s(float(x))) for s in series])
        assert np.array_equal(got, want), x
        assert m.at(float(x)) is got
    s, slope, curv, c, dc = m.values(300e-6)
    x = np.log(300e-6)
    assert (s, c) == (float(m.stress(x)), float(m.lag(x)))
    assert slope == float(m.dstress(x)) / 300e-6 and dc == float(m.dlag(x)) / 300e-6
    assert curv == (float(m.d2stress(x)) - float(m.dstress(x))) / (300e-6 * 300e-6)
