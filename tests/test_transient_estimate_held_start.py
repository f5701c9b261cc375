"""The cost estimate against a steady start held as exact steady sliding, and against the start's cut cells
(docs/transient.md sections 2a and 18).

1. Under velocity control with the reduction on, a steady start at the first piece's velocity is held as exact
   steady sliding until the velocity first changes: one step a piece, whatever its length (10 um/s for 0.15 s: 1 step,
   ~2 ms of CPU).  The estimate still counted the cohorts (6 640 steps, 4.0 s there; 0.01 um/s for 100 s was
   refused at hours).
2. Where the run carries the start's cohorts (the reduction off, or after the first change) the start's cells are
   cut ahead of the FENE cliff and add cohorts (1 um/s for 20 ms: 15 148 against 3 886), each step working through
   them: 4.7 s of CPU taken against 0.28 s estimated.
"""

from __future__ import annotations

import re
import time

import pytest

from cost_helpers import least_cpu, plain_cohorts_pace
from stickslip.parameters import load_parameters
from stickslip.protocols import constant, segments
from stickslip.transient import run_transient
from stickslip.transient.cells import steady_cohorts
from stickslip.transient.solver import estimate_cost

GEL = load_parameters("gelatin-glass")
VELOCITY = {"control": "velocity", "start": "steady"}


def _taken(protocol, **settings):  # type: ignore[no-untyped-def]
    """(the run, its CPU seconds), with budgets that the estimate does not bind."""
    start = time.process_time()
    result = run_transient(GEL, protocol, max_time=1e6, max_steps=10**9, **settings)
    return result, time.process_time() - start


@pytest.mark.parametrize(
    ("settings", "held"),
    [
        ({}, True),
        ({"start_velocity": 100e-6}, True),  # the first piece's velocity, given
        ({"start_velocity": 101e-6}, False),  # another velocity: the cohorts from the start
        ({"reduction": "off"}, False),
        ({"max_step": 1e-4}, False),
        ({"control": "block"}, False),
        ({"start": "empty"}, False),
    ],
)
def test_the_estimate_holds_the_steady_start_exactly_where_the_run_does(settings, held) -> None:  # type: ignore[no-untyped-def]
    """100 um/s for 2 ms: a held start takes one step (~60 otherwise), and the estimate says so."""
    protocol = constant(100e-6, 2e-3)
    settings = {**VELOCITY, **settings}
    result, _ = _taken(protocol, **settings)
    estimate = estimate_cost(GEL, protocol, **settings)
    if held:
        assert result.steps == 1 and estimate.steps <= 2.0, (result.steps, estimate.steps)
        assert "held" in estimate.basis, estimate.basis
    else:
        assert result.steps > 10 and estimate.steps > 10, (result.steps, estimate.steps)
        assert "held" not in estimate.basis, estimate.basis


@pytest.mark.parametrize(("velocity", "duration"), [(10e-6, 0.15), (1e-6, 1.0), (1e-8, 100.0)])
def test_a_held_steady_start_is_estimated_at_one_step_whatever_its_length(velocity: float, duration: float) -> None:
    """One step and a few ms of CPU taken; estimated before at 6 640 steps and 4.0 s (10 um/s, 0.15 s), and refused
    at hours (0.01 um/s for 100 s)."""
    protocol = constant(velocity, duration)
    result, cpu = _taken(protocol, **VELOCITY)
    estimate = estimate_cost(GEL, protocol, **VELOCITY)
    assert result.steps == 1 and cpu < 1.0, (result.steps, cpu)
    assert estimate.steps <= 2.0 and estimate.seconds <= 0.05, (estimate.steps, estimate.seconds)


def test_a_held_stretch_costs_the_same_whatever_its_length() -> None:
    """100 um/s held for 2 ms or for 1 s, then 300 um/s for 5 ms: the run after the change starts from the same
    population (reloaded as it was) and takes the same steps; the estimate differs by nothing (the held stretch counted
    as the cohorts' 1 s at 100 um/s before: 856 steps more)."""
    after = (300e-6, 5e-3)
    short, long = segments([(100e-6, 2e-3), after]), segments([(100e-6, 1.0), after])
    taken = [_taken(protocol, **VELOCITY)[0].steps for protocol in (short, long)]
    assert abs(taken[0] - taken[1]) <= 0.05 * taken[0] + 2, taken
    estimated = [estimate_cost(GEL, protocol, **VELOCITY).steps for protocol in (short, long)]
    assert abs(estimated[1] - estimated[0]) <= 1.0, estimated


def test_held_pieces_are_one_step_each_and_the_change_is_counted_from_there() -> None:
    """Three pieces at the start's velocity (three stretches, three steps taken), then the velocity changes: the
    estimate is the three held pieces and what the one-piece-held protocol counts after the change."""
    after = (300e-6, 5e-3)
    three = segments([(100e-6, 1e-3), (100e-6, 1e-3), (100e-6, 1e-3), after])
    one = segments([(100e-6, 3e-3), after])
    result, _ = _taken(three, **VELOCITY)
    alone, _ = _taken(one, **VELOCITY)
    assert result.steps - alone.steps == 2, (result.steps, alone.steps)  # one steady stretch a piece
    gap = estimate_cost(GEL, three, **VELOCITY).steps - estimate_cost(GEL, one, **VELOCITY).steps
    assert 1.5 <= gap <= 2.5, gap


@pytest.mark.parametrize(("velocity", "duration", "repeats"), [(1e-6, 5e-3, 2), (3e-6, 0.02, 1)])  # (~1.2 and ~4.4 s)
def test_the_cut_cells_cohorts_are_counted_with_the_reduction_off(
    velocity: float, duration: float, repeats: int
) -> None:
    """The reduction off, the start's cohorts integrated from t = 0 through cells cut ahead of the FENE cliff:
    839 steps and ~0.6 s of CPU at 1 um/s for 5 ms (estimated before at 226 and 0.06 s), 2 488 and ~1.6 s at
    3 um/s for 20 ms (1 177 and 0.40 s).  The estimate counts the cohorts the cut adds: those of the population the
    run starts from (its first snapshot) beyond the uncut steady start's."""
    protocol = constant(velocity, duration)
    settings = {**VELOCITY, "reduction": "off"}
    run_transient(GEL, constant(velocity, 1e-4), **settings)  # the kernel and tables loaded, once
    result, cpu = least_cpu(lambda: _taken(protocol, **settings)[0], repeats)
    estimate = estimate_cost(GEL, protocol, **settings)
    assert 0.3 <= estimate.steps / result.steps <= 3.0, (estimate.steps, result.steps)
    pace = plain_cohorts_pace()  # the host's, beside the estimate's constants (tests/cost_helpers.py)
    assert 0.3 <= estimate.seconds * pace / cpu <= 3.0, (estimate.seconds, pace, cpu)
    added = result.snapshots[0].age.size - steady_cohorts(GEL, velocity, True).age.size
    assert added > 0
    counted = re.search(r"([0-9.e+]+) cohorts of the start cut", estimate.basis)
    assert counted is not None and abs(float(counted.group(1)) - added) <= 0.005 * added, (estimate.basis, added)
