"""``every`` on a repeated limit cycle of the stick chains, and the trace of a long run (solver._Repeater, sampling).

With ``every`` such a run is integrated as without it (the settled cycle repeated, not integrated again) and its
rows are sampled onto the grid: the steps, the cycles, the regime and the end are the run's without ``every``
(the reference: the same run unsampled), and the grid rows agree with the cycle integrated directly onto the grid
(the reference: ``REPEAT_CYCLES = False``, where the solver lands on every grid instant).  Without ``every`` the
copies of a repeated cycle add a bounded number of rows to the trace, and the text lists a few cycles, not all.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import stickslip.transient.solver as solver
from stickslip.parameters import load_parameters
from stickslip.protocols import constant
from stickslip.transient import run_transient
from stickslip.transient.solver import estimate_cost

GEL = load_parameters()
#: a block three times stiffer than the gel's: cycles of 5.8 s at 100 um/s (as tests/test_transient_repeat.py)
STIFF = GEL.with_overrides({"block.height": GEL.block.shear_modulus / 1.2e6})
RTOL = 1e-3
PROTOCOL = constant(100e-6, 40.0)
EVERY = 0.25


@pytest.fixture(scope="module")
def runs():
    """The run unsampled, sampled every 0.25 s, and sampled with every cycle integrated (the solver on the grid)."""
    plain = run_transient(STIFF, PROTOCOL, stick_population=True, rtol=RTOL)
    sampled = run_transient(STIFF, PROTOCOL, stick_population=True, rtol=RTOL, every=EVERY)
    old = solver.REPEAT_CYCLES
    solver.REPEAT_CYCLES = False
    try:
        direct = run_transient(STIFF, PROTOCOL, stick_population=True, rtol=RTOL, every=EVERY)
    finally:
        solver.REPEAT_CYCLES = old
    return plain, sampled, direct


def test_every_changes_neither_the_steps_nor_the_cycles(runs):
    plain, sampled, _ = runs
    assert "period(s) of the limit cycle repeated" in plain.message
    assert "period(s) of the limit cycle repeated" in sampled.message
    assert sampled.steps == plain.steps and sampled.rejected == plain.rejected
    assert sampled.regime == plain.regime == "stick-slip"
    assert sampled.message == plain.message and sampled.status == plain.status == "ok"
    assert len(sampled.cycles) == len(plain.cycles) >= 6
    for mine, theirs in zip(sampled.cycles, plain.cycles, strict=True):
        assert dataclasses.asdict(mine) == dataclasses.asdict(theirs)
    assert sampled.time[-1] == plain.time[-1] == 40.0
    for name in ("stress", "slider_position", "puller_position", "bonded_fraction", "slider_velocity"):
        assert getattr(sampled, name)[-1] == getattr(plain, name)[-1], name
    for name in ("born", "broken", "stress_integral"):  # (the work reads nan while the chains hold)
        assert getattr(sampled.bookkeeping, name)[-1] == getattr(plain.bookkeeping, name)[-1], name
    # the run's extremes are the unsampled run's states (which keeps the stuck block's row at a slip's instant, the
    # sampled run also the jump's: the stress and velocity of the jumped population, within 5e-10 and 3.1e-7)
    assert np.max(sampled.highest_stress) == pytest.approx(np.max(plain.stress), rel=1e-9)
    assert np.min(sampled.lowest_stress) == np.min(plain.lowest_stress)
    assert np.max(sampled.fastest_velocity) == pytest.approx(np.max(plain.slider_velocity), rel=1e-6)


def test_the_rows_are_the_grid_and_the_slips(runs):
    _, sampled, _ = runs
    grid = EVERY * np.arange(int(40.0 / EVERY) + 1)
    slips = [c.start_time + c.stick_time for c in sampled.cycles if c.slip_time is not None]
    expected = np.union1d(grid, slips)
    assert sampled.time.size == expected.size
    assert np.max(np.abs(sampled.time - expected)) < 1e-9


def test_grid_rows_agree_with_the_cycle_integrated_on_the_grid(runs):
    """Every grid row, the repeated cycles' included, against the run whose solver lands on each grid instant."""
    _, sampled, direct = runs
    assert "repeated" not in direct.message
    grid = EVERY * np.arange(int(40.0 / EVERY) + 1)
    # the grid's rows (at a slip's instant the direct run keeps the jump's state, the unsampled run the stick's)
    common, mine, theirs = np.intersect1d(sampled.time, direct.time, return_indices=True)
    on_grid = np.isin(common, grid)
    common, mine, theirs = common[on_grid], mine[on_grid], theirs[on_grid]
    assert common.size == grid.size
    repeated = common > sampled.cycles[-3].start_time  # the copies (two periods) and the last cycle integrated
    assert repeated.sum() > 20
    # measured: stress 7.6e-8 of the largest, position 1.5e-8, velocity 1.3e-5, N/N0 5.3e-5
    bounds = {"stress": 0.1 * RTOL, "slider_position": 0.1 * RTOL, "slider_velocity": 0.1 * RTOL}
    bounds["puller_position"] = 1e-12
    for name, bound in bounds.items():
        a, b = getattr(sampled, name)[mine], getattr(direct, name)[theirs]
        assert np.max(np.abs(a - b)) <= bound * np.max(np.abs(b)), name
    assert np.max(np.abs(sampled.bonded_fraction[mine] - direct.bonded_fraction[theirs])) <= RTOL
    for name in ("born", "broken", "stress_integral"):
        a, b = getattr(sampled.bookkeeping, name)[mine], getattr(direct.bookkeeping, name)[theirs]
        assert np.max(np.abs(a - b)) <= 0.1 * RTOL * np.max(np.abs(b)), name


def test_each_rows_extremes_are_those_of_the_steps_it_closes(runs):
    """A sampled row's highest and lowest stress: the unsampled rows' since the row before, and its own (at a
    slip's instant the jump's row, which the unsampled trace drops: within 1e-9 in stress, 1e-6 in velocity)."""
    plain, sampled, _ = runs
    t = sampled.time
    for k in range(1, t.size):
        inside = (plain.time > t[k - 1]) & (plain.time <= t[k])
        high = max(np.max(plain.highest_stress[inside], initial=-np.inf), sampled.stress[k])
        low = min(np.min(plain.lowest_stress[inside], initial=np.inf), sampled.stress[k])
        assert sampled.highest_stress[k] == pytest.approx(high, rel=1e-9), t[k]
        assert sampled.lowest_stress[k] == pytest.approx(low, rel=1e-9), t[k]
        fastest = max(np.max(plain.fastest_velocity[inside], initial=-np.inf), sampled.slider_velocity[k])
        assert sampled.fastest_velocity[k] == pytest.approx(fastest, rel=1e-6), t[k]


def test_the_reported_case_keeps_its_cost_with_every():
    """The paper's cycle, 300 s: with every 10 s the same steps and verdict as without (was ~5x the steps), and the
    estimate the same."""
    long = constant(100e-6, 300.0)
    plain = run_transient(GEL, long, stick_population=True)
    sampled = run_transient(GEL, long, stick_population=True, every=10.0)
    assert sampled.steps == plain.steps and sampled.regime == plain.regime == "stick-slip"
    assert sampled.message == plain.message and "repeated" in sampled.message
    assert sampled.time.size <= 31 + len(sampled.cycles)
    with_every = estimate_cost(GEL, long, stick_population=True, every=10.0)
    without = estimate_cost(GEL, long, stick_population=True)
    assert with_every.steps == without.steps and "repeated" in with_every.basis


def test_copies_past_the_row_limit_are_thinned(monkeypatch):
    """Without ``every``, the copies beyond TRACE_COPY_ROWS are sampled (a note says how); the run is the same."""
    long = constant(100e-6, 120.0)
    whole = run_transient(STIFF, long, stick_population=True, rtol=RTOL)
    monkeypatch.setattr(solver, "TRACE_COPY_ROWS", 3000)
    monkeypatch.setattr(solver, "THIN_ROWS", 400)
    thinned = run_transient(STIFF, long, stick_population=True, rtol=RTOL)
    assert "rows, one every" in thinned.message and "rows, one every" not in whole.message
    assert thinned.time.size < 0.5 * whole.time.size
    assert thinned.steps == whole.steps and thinned.regime == whole.regime
    assert [dataclasses.asdict(c) for c in thinned.cycles] == [dataclasses.asdict(c) for c in whole.cycles]
    for name in ("stress", "slider_position", "bonded_fraction"):
        assert getattr(thinned, name)[-1] == getattr(whole, name)[-1], name
    assert np.max(thinned.highest_stress) == np.max(whole.highest_stress)
    # the thinned rows lie on the unthinned trace: in the sticks sigma is linear in time between its rows
    stuck = thinned.slider_velocity == 0.0
    assert stuck.sum() > 100
    between = np.interp(thinned.time[stuck], whole.time, whole.stress)
    assert np.max(np.abs(between - thinned.stress[stuck])) <= 1e-9 * np.max(whole.stress)


def test_the_text_lists_the_first_and_last_cycles():
    from stickslip.cli.run_report import _transient_record

    run = run_transient(STIFF, constant(100e-6, 120.0), stick_population=True, rtol=RTOL)
    assert len(run.cycles) > 15
    lines = _transient_record(run)
    cycles = [line for line in lines if line.startswith("  cycle ")]
    assert len(cycles) < 12 and f"cycle {len(run.cycles)}:" in lines[-1] and "cycle 1:" in lines[1]
    assert any(f"{len(run.cycles) - len(cycles)} cycles more" in line for line in lines)
    assert math.isfinite(run.final_stress)
