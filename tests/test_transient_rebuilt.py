"""The steady population rebuilt within a run (a glide's end, the paper's jump) on coarser cells (issue 31;
``solver._rebuilt_cells``, docs/transient.md section 13).

The coarsening is checked against the steady start's resolution, an independent discretisation of the same
population: the paper's cycle keeps its numbers, and the rebuilt population is the smaller one.  The error it may
bring is pinned where it is largest, on a re-slide after a hold (tests/test_transient_speed.py's slide-hold-slide
peak against the plain cohorts, 1e-4)."""

from __future__ import annotations

import numpy as np
import pytest

import stickslip
from stickslip.protocols import Protocol, Segment
from stickslip.transient import run_transient, solver
from stickslip.transient.reduction import THETA

GEL = stickslip.load_parameters("gelatin-glass")
CYCLE = Protocol((Segment(350e-6, 5.0), Segment(100e-6, 20.0)))


def test_the_coarsening_follows_the_tolerance() -> None:
    coarse = [solver._rebuilt_cells(rtol) for rtol in (1e-7, 1e-5, 1e-4, 1e-3, 1e-2)]
    hazards = [h for h, _ in coarse]
    assert hazards == sorted(hazards)
    assert coarse[0] == (0.05, 1000.0)  # tight: the steady start's own cells
    assert coarse[-1] == (0.5, 100.0)  # at most REBUILT_COARSEST
    h, least = solver._rebuilt_cells(1e-4)
    c = h / 0.05
    assert least == pytest.approx(1000.0 / c)
    assert solver.REBUILT_PEAK_ERROR * c * c == pytest.approx(THETA * 1e-4)


def _cycle(monkeypatch: pytest.MonkeyPatch, fine: bool) -> tuple[np.ndarray, list[int]]:
    """The cycle at rtol 1e-3; the cohorts held after each population rebuilt within the run."""
    if fine:
        monkeypatch.setattr(solver, "_rebuilt_cells", lambda rtol: (0.05, 1000.0))
    solver._STEADY_COHORTS.clear()
    sizes: list[int] = []
    original = solver._steady_cohorts

    def counted(*args, **kwargs):  # type: ignore[no-untyped-def]
        population = original(*args, **kwargs)
        sizes.append(np.asarray(population.age).size)
        return population

    monkeypatch.setattr(solver, "_steady_cohorts", counted)
    run = run_transient(GEL, CYCLE, start="steady", stick_population=True, rtol=1e-3)
    monkeypatch.setattr(solver, "_steady_cohorts", original)
    solver._STEADY_COHORTS.clear()
    c = run.cycles[0]
    return np.array([c.stick_time, c.peak_stress, c.jump_velocity, c.slip_time]), sizes


def test_the_cycle_keeps_its_numbers_on_the_coarser_rebuilt_population(monkeypatch: pytest.MonkeyPatch) -> None:
    coarse, coarse_sizes = _cycle(monkeypatch, fine=False)
    fine, fine_sizes = _cycle(monkeypatch, fine=True)
    # the steady start (first) is the same; each population rebuilt within the run is ~5x smaller
    assert coarse_sizes[0] == fine_sizes[0]
    assert len(coarse_sizes) == len(fine_sizes) >= 3
    assert all(5 * a < b for a, b in zip(coarse_sizes[1:], fine_sizes[1:], strict=True))
    # ts, sigma_s, V_s, the slip time: within 2e-7 of each other (measured 8.1e-8, the slip time), ~1e-2 of their
    # distance from the rtol 1e-5 cohorts (8e-7 .. 3.6e-6)
    assert np.max(np.abs(coarse / fine - 1.0)) < 2e-7
