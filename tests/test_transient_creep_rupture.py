"""A stopped block whose aged bonds reach the FENE wall (round 29; transient/jump.py wall_lumps, docs/transient.md
section 22).

`stickslip transient --v0 "100 um/s" --duration "60 s" --start steady` (Eq 1 alone, the paper's block) failed at
t = 55.4419 s, sigma = 1954.11 Pa: "the bonds gave way faster than the solver could follow".  The block had stopped
and was creeping; one cohort at the FENE wall (1.17e-6 N0 carrying 356 Pa) held the slider alone and g, the
slider's velocity balance, had no creeping root.  An independent computation (the same bonds as a continuous
density, deaths at the wall, refills at the slider) creeps on smoothly with dS/dX >= 1.3e10 Pa/m, 4e4 x K, through
300 s: the block does not let go.  Such a cohort is now broken at once and the creep goes on.  Checked against what
does not come from that rule: a stopped block's stress rises at K V0 (the creep bounded), the bonds' books, a
closed-form balance and creep velocity after the break, and the same run at a tighter tolerance."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import stickslip
from cli_helpers import run_main
from stickslip import protocols
from stickslip.transient import jump, run_transient
from stickslip.transient import kernel as K
from stickslip.transient.model import pack_parameters
from stickslip.transient.solver import SolverFailed

PAPER = stickslip.load_parameters("gelatin-glass")
V0 = 100e-6
#: the slider's creep from t = 20 s on is at most this (an independent continuum computation: 81 nm to 60 s at the
#: paper's block, 0.11 um from 5 to 10 s at 4 MPa/m): sigma = K (P - X) rises at K V0 less K x the creep
CREEP_BOUND = 0.3e-6


def _run(rtol: float = 1e-4, stiffness: float | None = None, duration: float = 60.0):  # type: ignore[no-untyped-def]
    params = PAPER if stiffness is None else PAPER.with_overrides({"block.stiffness": stiffness})
    return run_transient(params, protocols.segments([(V0, duration)]), start="steady", rtol=rtol)


def _stuck_loading(run, t0: float, t1: float) -> None:  # type: ignore[no-untyped-def]
    """Between t0 and t1 the block is stopped: sigma rises at K V0 less K x the creep, 0 < creep < CREEP_BOUND."""
    sigma0, sigma1 = np.interp([t0, t1], run.time, run.stress)
    x0, x1 = np.interp([t0, t1], run.time, run.slider_position)
    rise = run.stiffness * V0 * (t1 - t0)
    assert 0.0 < x1 - x0 < CREEP_BOUND, (x0, x1)
    assert rise - run.stiffness * CREEP_BOUND < sigma1 - sigma0 < rise, (sigma1 - sigma0, rise)
    assert sigma1 - sigma0 == pytest.approx(rise - run.stiffness * (x1 - x0), rel=1e-9, abs=1e-6)  # sigma = K (P - X)


def test_the_testers_run_stays_stuck_past_55_s(capsys):
    """It failed (exit 3) at 55.4419 s; now stuck at 60 s with sigma = sigma(20 s) + K V0 40 s less K x the creep,
    and the message says what was done at the wall."""
    code, out, err = run_main(capsys, "transient", "--v0", "100 um/s", "--duration", "60 s", "--start", "steady")
    assert code == 0, err
    assert "regime: stuck" in out and "the run FAILED" not in out
    assert "oldest bonds reached the FENE wall" in out and "t = 55.44" in out and "section 22" in out
    run = _run()
    assert run.regime == "stuck" and run.time[-1] == 60.0
    assert run.slider_velocity[-1] < 0.01 * V0 and run.bonded_fraction[-1] > 0.9999
    _stuck_loading(run, 20.0, 60.0)


def test_the_bonds_broken_at_the_wall_are_booked():
    """N(0) + born - broken = N(t) to 1e-9 N0 over the run (the cohort broken at the wall is 1.17e-6 N0), and the
    puller's work is the stored energy plus the dissipated to within the tolerance."""
    run = _run()
    n0 = PAPER.bonds.site_density
    book = run.bookkeeping
    assert book.broken[-1] - book.broken[0] > 1e-6 * n0
    bonds = run.bonded_fraction[0] * n0 + book.born - book.broken
    assert np.allclose(bonds / n0, run.bonded_fraction, rtol=0, atol=1e-9)
    stored = book.bond_energy + book.block_energy
    work = book.work[-1] - book.work[0]
    assert abs(work - (stored[-1] - stored[0]) - (book.dissipation[-1] - book.dissipation[0])) < 1e-4 * work


def test_a_tighter_tolerance_gives_the_same_stuck_block():
    """rtol 1e-5: the cohort reaches the wall at 49.84 s instead (it failed there); the same stress at 60 s to
    K x 0.1 um (measured 2093.8139 / 2093.8123 Pa at rtol 1e-4 / 1e-5; the continuum computation 2093.806 Pa)."""
    coarse, fine = _run(), _run(rtol=1e-5)
    assert fine.regime == coarse.regime == "stuck"
    assert abs(fine.stress[-1] - coarse.stress[-1]) < fine.stiffness * 0.1e-6
    _stuck_loading(fine, 20.0, 60.0)


def test_a_stiff_block_creeps_on_past_the_old_failure():
    """4 MPa/m (K = 3.065e6 Pa/m) at 100 um/s, docs/transient.md section 17: it failed at 5.08327 s (1803.37 Pa);
    now stuck at 10 s, its stress rising at K V0 less K x the creep (the continuum computation: 3310.0095 Pa)."""
    run = _run(stiffness=4e6, duration=10.0)
    assert run.regime == "stuck" and run.time[-1] == 10.0, run.message
    _stuck_loading(run, 5.0, 10.0)


def test_a_creep_that_does_not_come_back_fails_in_its_own_words(monkeypatch):
    """Where breaking the cohorts at the wall leaves no creeping balance (here: none may be broken), the run fails
    saying the block had stopped and may let go, with the run kept up to there."""
    monkeypatch.setattr(jump, "WALL_LUMPS", 0)
    with pytest.raises(SolverFailed) as failed:
        _run()
    message = str(failed.value)
    assert message.startswith("transient solver failed at t = 55.44"), message
    assert "the block had stopped and was creeping" in message and "--mass" in message, message
    assert "gave way faster than the solver could follow" not in message
    partial = failed.value.partial
    assert partial is not None and partial.time[-1] == pytest.approx(55.4419, rel=1e-5)


# --- the rule itself on a population built by hand: one aged bulk cohort and lumps at the wall
STIFFNESS = 3.065e5
AGE = 50.0  # s at rest: the aging term 5.56e4 in ln r


def _population(lumps: int):  # type: ignore[no-untyped-def]
    """A bulk cohort (0.999 N0 at 5 % of the FENE length) and ``lumps`` cohorts of 1e-6 N0 at the wall, where the
    force matches the aging term (ln r ~ +10): the slider at x = 0 balancing the spring."""
    p = pack_parameters(PAPER, True, STIFFNESS)
    dlm, m, n0 = p[K.P_DLM], p[K.P_M], p[K.P_N0]
    b = PAPER.bonds
    force_at = (AGE / PAPER.aging.aging_time + 10.0 - math.log(b.breakage_weight / b.bond_time)) / b.force_sensitivity
    y_wall = (-m * dlm + math.sqrt((m * dlm) ** 2 + 4 * force_at**2)) / (2 * force_at)
    ext = np.r_[[dlm * (y_wall - 1e-9 * k) for k in range(lumps)], 0.05 * dlm]  # ln r 2.3 apart
    weight = np.r_[[1e-6 * n0] * lumps, 0.999 * n0]
    sigma = float(np.sum(weight * m * ext / (1 - (ext / dlm) ** 2)))
    xb, tb, lw = -ext, np.zeros(ext.size), np.log(weight)  # born at t = 0, aged AGE at t = AGE
    return p, xb, tb, lw, sigma / STIFFNESS


def test_one_lump_at_the_wall_is_broken_and_the_slider_creeps_on_in_closed_form():
    """The lump (1e-6 N0, ~270 Pa) breaks; the slider lands where the bulk alone balances the spring (brentq on
    K (P - X) = w f(X - x_b)), creeping at K Vp/(K + w f'(e)) (the bulk's hazard is e^-5.6e4: no loss)."""
    p, xb, tb, lw, puller = _population(1)
    dlm, m = p[K.P_DLM], p[K.P_M]
    w_bulk, xb_bulk = math.exp(lw[1]), xb[1]
    x, v, n, found, dissipated = jump.wall_lumps(AGE, 0.0, 1e-9, puller, V0, V0, 2, xb, tb, lw, p, K.compiled())
    assert n == 1 and xb[0] == xb_bulk and found.cohorts == 1
    assert found.broken_share == pytest.approx(1e-6, rel=1e-9)

    def force(e: float) -> float:
        return m * e / (1 - (e / dlm) ** 2)

    landing = brentq(lambda q: w_bulk * force(q - xb_bulk) - STIFFNESS * (puller - q), 0.0, 1e-6, xtol=1e-22)
    assert x == pytest.approx(landing, rel=1e-9, abs=1e-20) and found.travel == pytest.approx(landing, rel=1e-9)
    y = (x - xb_bulk) / dlm
    creep = STIFFNESS * V0 / (STIFFNESS + w_bulk * m * (1 + y * y) / (1 - y * y) ** 2)
    assert v == pytest.approx(creep, rel=1e-6)
    assert found.stress_after == pytest.approx(STIFFNESS * (puller - x), rel=1e-9)
    assert found.load == pytest.approx(found.stress_before - w_bulk * force(-xb_bulk), rel=1e-6)
    assert dissipated > 0.0


def test_no_creep_back_within_the_allowance_changes_nothing(monkeypatch):
    """Nine lumps at the wall, at most eight broken: None, and the population is left as it was (with nine
    allowed, all nine break and the creep comes back); nor is a block that is not creeping, or a collapse whose
    largest loss is not at the wall, touched."""
    p, xb, tb, lw, puller = _population(jump.WALL_LUMPS + 1)
    before = (xb.copy(), tb.copy(), lw.copy())
    n = xb.size
    functions = K.compiled()
    assert jump.wall_lumps(AGE, 0.0, 1e-9, puller, V0, V0, n, xb, tb, lw, p, functions) is None
    assert all(np.array_equal(a, b) for a, b in zip((xb, tb, lw), before, strict=True))
    monkeypatch.setattr(jump, "WALL_LUMPS", n - 1)
    _, v, left, found, _ = jump.wall_lumps(AGE, 0.0, 1e-9, puller, V0, V0, n, xb, tb, lw, p, functions)
    assert left == 1 and found.cohorts == n - 1 and 0.0 < v < 0.01 * V0
    p, xb, tb, lw, puller = _population(1)
    assert jump.wall_lumps(AGE, 0.0, 0.02 * V0, puller, V0, V0, 2, xb, tb, lw, p, functions) is None
    xb[0] = -0.9 * p[K.P_DLM]  # the "lump" well short of the wall: not one
    assert jump.wall_lumps(AGE, 0.0, 1e-9, puller, V0, V0, 2, xb, tb, lw, p, functions) is None
