"""Issue 33 item 3: the saturating set's block from rest, fast, with its first slip kept.

The method for saturating aging (docs/transient.md section 8, *Issue 33 item 3, landed*): the births' error is the
Gauss pair's own with converged sweeps, light saturated cohorts share wider bins, and the quasi-steady reduction
takes the creep from rest from 0.32 s (where the block is insensitive to its neglected term).  The references are
numbers of the method before the change (commit 3863829, or 241cbe5, the same kernel) at tighter tolerances: an
independent method in the sense that matters here, the plain births' bound and the cohorts until 2.5 s.
"""

from __future__ import annotations

import numpy as np
import pytest

import stickslip
from stickslip.protocols import constant
from stickslip.transient import reduction, run_transient

SAT = stickslip.load_parameters("gelatin-glass-saturating")

#: 350 um/s from rest, 6 s: the first slip (end of the stick, its peak stress) of the kernel at commit 241cbe5 at rtol
#: 1e-5 (323 567 steps, 297 s of CPU; docs/transient.md section 8), the cycle's stick end and peak
REF_350 = (5.3417232, 567.02713)
#: 50 um/s from rest: the first slip of the kernel at commit 3863829 at rtol 3e-5 (40 s, 1 384 433 steps, 705 s of
#: CPU; at rtol 1e-4 38.93123993 s, 554.3530651 Pa, 2.8e-8 and 1.6e-8 from it), the highest stress before the slider
#: first passes the puller's pace
REF_50 = (38.93124102, 554.3530561)


def first_slip(run, pace: float) -> tuple[float, float]:  # type: ignore[no-untyped-def]
    """(time, stress) of the highest stress between the slider first falling below half the puller's pace and first
    passing it again (from an empty surface the slider starts at the puller's pace)."""
    v = run.slider_velocity
    start = int(np.flatnonzero(v < 0.5 * pace)[0])
    passed = np.flatnonzero(v[start:] > pace)
    end = start + int(passed[0]) if passed.size else v.size
    i = start + int(np.argmax(run.stress[start:end]))
    return float(run.time[i]), float(run.stress[i])


def test_the_first_slip_from_rest_at_350_um_s() -> None:
    """rtol 1e-3: within 1e-4 of the rtol 1e-5 reference (measured 5.2e-5 and 4.8e-5; the reference is the cycle's
    stick end and peak, which differ from the highest stress row by ~3e-6 and 6e-7) in 6501 steps (21 252 before,
    4.4e-6 and 2.3e-6 off: the old bound held this run ~100 times tighter than its rtol).  At the default rtol 1e-4
    (69 616 steps, 131 056 before; not run here, 17 s): the cycle's 2.8e-8 and 6.9e-8 off."""
    run = run_transient(SAT, constant(350e-6, 6.0), rtol=1e-3)
    when, peak = first_slip(run, 350e-6)
    assert when == pytest.approx(REF_350[0], rel=1e-4)
    assert peak == pytest.approx(REF_350[1], rel=1e-4)
    assert run.steps < 10_000


def test_the_first_slip_of_45_s_from_rest_at_50_um_s() -> None:
    """The issue's run (40 s of it: the first slip at 38.93 s), rtol 1e-3: within 1e-4 of the reference (measured
    3.1e-5 and 2.4e-5) in 6507 steps (37 677 before for 45 s).  The creep from rest is reduced from 0.32 s (2.5 s
    before).  At the default rtol 1e-4 (benchmarks/bench_transient_from_rest.py): 1.2e-6 and 1.0e-6 off."""
    run = run_transient(SAT, constant(50e-6, 40.0), rtol=1e-3)
    when, peak = first_slip(run, 50e-6)
    assert when == pytest.approx(REF_50[0], rel=1e-4)
    assert peak == pytest.approx(REF_50[1], rel=1e-4)
    assert run.steps < 10_000
    # the first reduced stretch (rows at the ODE's steps, 0.05 s and more apart: its first step is 0.088 s) starts
    # before 0.5 s (2.5 s before: the table was built only once sigma was within 1 % of the steady curve, the lag
    # being 0.025 s/t of it); the cohorts' rows here are ~0.2 ms apart
    reduced = np.flatnonzero(np.diff(run.time) > 0.05)
    assert reduced.size and run.time[reduced[0]] < 0.5


def test_the_allowed_neglect_grows_only_where_the_block_creeps_far_below_the_puller() -> None:
    """tol |sigma| near the fold (S'|Vp - V| < sigma), tol S'|Vp - V| on the creep from rest, at most ten times more."""
    m = reduction.build_manifold(SAT, True, 1e-8, 2e-5, 1e-4)
    assert m is not None
    tol, vp = 3e-5, 50e-6
    for v in (2e-8, 2e-7, 2e-6, 1.2e-5):
        sigma, slope = m.values(v)[0], m.values(v)[1]
        ratio = reduction.allowed_neglect(m, v, vp, sigma, tol) / (tol * sigma)
        assert ratio == pytest.approx(min(max(1.0, slope * (vp - v) / sigma), reduction.NEGLECT_CAP), rel=1e-12)
    near_fold = reduction.allowed_neglect(m, 1.2e-5, vp, m.values(1.2e-5)[0], tol)
    assert near_fold == pytest.approx(tol * m.values(1.2e-5)[0], rel=1e-12)  # S'(Vp - V) = 0.25 sigma there
    creeping = reduction.allowed_neglect(m, 2e-8, vp, m.values(2e-8)[0], tol)
    assert creeping == pytest.approx(reduction.NEGLECT_CAP * tol * m.values(2e-8)[0], rel=1e-12)
