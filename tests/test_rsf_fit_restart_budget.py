"""A restart of the rate-and-state search in Dc has a budget: the CPU of RETRY_RUNS model runs at the first search's
pace (stickslip.rsf.fit; docs/fitting.md, "Restarts in Dc").

On 2026-12-02 the tester's record opening 1.5 s after an unseen step (tests/test_rsf_fit_verdicts_r29.py) took 120 s
to fail where it had taken 8 s: its first search took 1.0 s for 89 runs, and the restart from Dc = 22 nm ran into a
near-critical corner (Dc 5.6 nm, k 3e5 1/m, a slowly ringing slider) at 0.17 s a run, 107 s for 633 runs, to a
chi-square 2.5x the first search's.  It is now given up at the budget (~18 s there), and the fit says so.
"""

from __future__ import annotations

import math
import types

import numpy as np
import pytest

from stickslip.rsf import fit as rsf_fit
from test_rsf_fit_verdicts_r29 import _opening_record


@pytest.fixture(scope="module")
def cut_short():  # type: ignore[no-untyped-def]
    """The opening record's fit with restarts allowed one run's CPU each: every restart is given up."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(rsf_fit, "RETRY_RUNS", 1)
        return rsf_fit.fit_record(_opening_record(), trend="slip", drift_check=False)


def test_a_restart_over_its_budget_is_given_up_and_said(cut_short) -> None:  # type: ignore[no-untyped-def]
    said = [w for w in cut_short.warnings if "was given up" in w]
    assert len(said) == len(rsf_fit.RETRY_DC_FACTORS), cut_short.warnings  # the first search is troubled: all three
    assert all(w.startswith("the restart of the search from Dc = ") for w in said), said
    assert all("a minimum that way is not ruled out" in w for w in said), said
    # the fit itself stands on the first search: still failed, for the same reason as with every restart run
    assert cut_short.status == "failed" and cut_short.reason.startswith("the record seems to start out of steady")


def test_the_residual_of_a_finished_restart_runs_past_its_deadline(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """The deadline is the restart's alone: the fit goes on with a restart's residual (the polish, the curvature
    check), which must not be given up once the restart's budget has passed."""
    setup, start = _setup_and_start()
    clock = types.SimpleNamespace(now=0.0)
    monkeypatch.setattr(rsf_fit, "time", types.SimpleNamespace(process_time=lambda: clock.now))
    with pytest.raises(rsf_fit._OverBudget):
        rsf_fit._budgeted_search(setup, start, budget=-1.0)  # (past the deadline before the first run)
    assert rsf_fit._DEADLINE.get() == math.inf
    result, residual = rsf_fit._budgeted_search(setup, start, budget=10.0)  # the clock stands: within it
    assert rsf_fit._DEADLINE.get() == math.inf
    clock.now = 1e9  # long past that restart's deadline
    assert math.isfinite(float(np.sum(residual(result.params) ** 2)))


def _setup_and_start():  # type: ignore[no-untyped-def]
    """A quick search's setup and start: the opening record with Dc, the stiffness and the drift held."""
    captured = {}
    original = rsf_fit._best_search

    def capture(setup, start, mismatch, stiffness_given):  # type: ignore[no-untyped-def]
        captured["args"] = setup, start
        raise _Captured

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(rsf_fit, "_best_search", capture)
        with pytest.raises(_Captured):
            rsf_fit.fit_record(_opening_record(), fixed={"dc": 5e-6, "stiffness": 2000.0})
    assert original is rsf_fit._best_search
    return captured["args"]


class _Captured(Exception):
    pass
