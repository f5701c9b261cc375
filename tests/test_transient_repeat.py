"""A limit cycle of the stick chains repeated, not integrated again (solver._Repeater, issue 31).

The reference is the same run with every cycle integrated (``REPEAT_CYCLES = False``): the copies must agree with
it to within the run's own tolerance, cycle by cycle and in the state and running totals at the end.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import stickslip.transient.solver as solver
from stickslip.parameters import load_parameters
from stickslip.protocols import constant, segments
from stickslip.transient import run_transient
from stickslip.transient.solver import estimate_cost

GEL = load_parameters()
#: a block three times stiffer than the gel's: cycles of 5.8 s at 100 um/s, six slips in 40 s
STIFF = GEL.with_overrides({"block.height": GEL.block.shear_modulus / 1.2e6})
#: the runs' tolerance (1e-3: half the CPU of the default; the bounds below are fractions of it)
RTOL = 1e-3


def _both(params, protocol, **settings):
    runs = {}
    for repeat in (True, False):
        old = solver.REPEAT_CYCLES
        solver.REPEAT_CYCLES = repeat
        try:
            runs[repeat] = run_transient(params, protocol, stick_population=True, rtol=RTOL, **settings)
        finally:
            solver.REPEAT_CYCLES = old
    return runs[True], runs[False]


@pytest.fixture(scope="module")
def stiff_runs():
    """40 s at 100 um/s, then 2 s at 80 um/s: a new piece is judged afresh (nothing copied across its start)."""
    return _both(STIFF, segments([(100e-6, 40.0), (80e-6, 2.0)]))


def test_repeated_cycles_agree_with_integrated_ones(stiff_runs):
    repeated, integrated = stiff_runs
    assert "period(s) of the limit cycle repeated" in repeated.message
    assert "repeated" not in integrated.message
    assert repeated.steps < 0.8 * integrated.steps  # measured 4 092 against 6 090
    assert len(repeated.cycles) == len(integrated.cycles) >= 5
    for mine, theirs in zip(repeated.cycles, integrated.cycles, strict=True):
        for field in dataclasses.fields(mine):
            a, b = getattr(mine, field.name), getattr(theirs, field.name)
            if isinstance(a, float) and math.isfinite(b):
                assert a == pytest.approx(b, rel=1e-6, abs=1e-9), field.name  # measured within 5e-11
    assert repeated.regime == integrated.regime  # the last piece, 2 s at 80 um/s, is too short: undetermined


def test_the_run_ends_on_the_state_the_integration_reaches(stiff_runs):
    repeated, integrated = stiff_runs
    assert repeated.time[-1] == integrated.time[-1] == 42.0
    for name in ("stress", "slider_position", "puller_position", "bonded_fraction"):
        a, b = getattr(repeated, name)[-1], getattr(integrated, name)[-1]
        assert a == pytest.approx(b, rel=1e-6, abs=1e-12), name  # measured within 3e-10
    book_a, book_b = repeated.bookkeeping, integrated.bookkeeping
    for name in ("born", "broken", "work", "stress_integral"):
        a, b = getattr(book_a, name)[-1], getattr(book_b, name)[-1]
        assert a == pytest.approx(b, rel=1e-6), name  # measured within 4e-11


def test_the_copies_are_the_trace_row_by_row(stiff_runs):
    """A copied row stands where the integration put its own (the same instant within 1e-6 s) with the same stress
    and positions (within a tenth of the rtol): the copies are as dense as the integrated rows, and exact."""
    repeated, integrated = stiff_runs
    assert abs(len(repeated.time) - len(integrated.time)) <= 0.01 * len(integrated.time)
    nearest = np.clip(np.searchsorted(repeated.time, integrated.time), 1, len(repeated.time) - 1)
    nearest -= np.abs(repeated.time[nearest - 1] - integrated.time) < np.abs(repeated.time[nearest] - integrated.time)
    matched = np.abs(repeated.time[nearest] - integrated.time) < 1e-6
    assert matched.mean() > 0.95
    # measured: stress 1.2e-7 of the largest, position 4e-10, velocity 4.6e-6; the bound is a tenth of the rtol
    for name in ("stress", "slider_position", "slider_velocity"):
        a, b = getattr(repeated, name)[nearest[matched]], getattr(integrated, name)[matched]
        assert np.max(np.abs(a - b)) <= 0.1 * RTOL * np.max(np.abs(b)), name


def test_no_repeat_without_the_reduction_and_every_grid_instant_a_row_with_every():
    """reduction="off" is the reference; with ``every`` the cycle is repeated too, its rows sampled onto the grid
    (tests/test_transient_every_repeat.py)."""
    protocol = constant(100e-6, 40.0)
    estimate = estimate_cost(STIFF, protocol, stick_population=True, reduction="off")
    assert "repeated" not in estimate.basis
    assert "repeated" in estimate_cost(STIFF, protocol, stick_population=True, every=0.5).basis
    run = run_transient(STIFF, protocol, stick_population=True, every=0.5, rtol=RTOL)
    assert "repeated" in run.message
    grid = np.arange(81) * 0.5
    assert np.all(np.min(np.abs(run.time[:, None] - grid[None, :]), axis=0) < 1e-12)  # every grid instant a row


def test_a_long_run_costs_a_few_cycles_but_its_rows_count(monkeypatch):
    """1000 s of the paper's cycle (65 slips): the estimate counts 5 slips' CPU, and every row against max_steps."""
    long = constant(100e-6, 1000.0)
    estimate = estimate_cost(GEL, long, stick_population=True)
    monkeypatch.setattr(solver, "REPEAT_CYCLES", False)
    plain = estimate_cost(GEL, long, stick_population=True)
    assert "repeated, not integrated" in estimate.basis and "repeated" not in plain.basis
    assert estimate.steps == pytest.approx(plain.steps)
    assert estimate.seconds < 0.2 * plain.seconds
    # 65 000 cycles are still refused: their rows are the budget's
    with pytest.raises(Exception, match="budget"):
        run_transient(GEL, constant(100e-6, 1e6), start="steady", stick_population=True)
