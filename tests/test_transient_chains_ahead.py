"""A run that ends with the stick chains holding is "stuck" only if they would hold on (issue 31's round, found by
using the package: 50 um/s for 30 s from rest said "stuck" while the chains were loading towards a slip at 50 s).

Where Eq 15 has the chains collapse after the run's end under the same loading the verdict is undetermined and says
when; a longer run slips there (its own slip event, the check); where Eq 15 proves they never collapse, stuck says so.
"""

from __future__ import annotations

import re

import pytest

import stickslip
from stickslip.protocols import constant
from stickslip.transient import run_transient

GEL = stickslip.load_parameters("gelatin-glass")


def test_a_run_shorter_than_its_first_stick_is_undetermined_and_says_when_the_chains_go() -> None:
    short = run_transient(GEL, constant(50e-6, 30.0), stick_population=True)
    assert short.regime == "undetermined"
    found = re.search(r"they collapse at t = ([0-9.]+) s \(σs = ([0-9.]+) Pa", short.message)
    assert found, short.message
    due, sigma_s = float(found.group(1)), float(found.group(2))
    assert due > 30.0
    longer = run_transient(GEL, constant(50e-6, due + 5.0), stick_population=True)
    assert longer.cycles, longer.message
    first = longer.cycles[0]
    assert first.peak_stress == pytest.approx(sigma_s, rel=1e-5)  # the printed 6 digits
    assert first.stick_time == pytest.approx(due, rel=1e-5)


def test_a_load_the_chains_hold_for_ever_stays_stuck_and_says_why() -> None:
    run = run_transient(GEL, constant(5e-6, 30.0), stick_population=True)
    assert run.regime == "stuck"
    assert "Eq 15 proves the chains never collapse under this loading" in run.message


def test_chains_aged_under_another_pace_are_followed_on_by_run_transient_itself() -> None:
    """350 -> 35 -> 350 µm/s (2, 10, 2 s) ends mid-stick, the stick begun under 350 µm/s: ``run_transient`` said
    "stuck ... the stick chains hold it" (only the model's Run looked ahead).  It now says when they collapse, and
    the same protocol run on for two seconds more slips there (the truth: its own slip event)."""
    from stickslip.protocols import Protocol, Segment

    paces = (Segment(350e-6, 2.0), Segment(35e-6, 10.0))
    short = run_transient(GEL, Protocol((*paces, Segment(350e-6, 2.0))), stick_population=True)
    assert short.regime == "undetermined", short.message
    found = re.search(r"they collapse at t = ([0-9.]+) s \(σs = ([0-9.]+) Pa", short.message)
    assert found, short.message
    longer = run_transient(GEL, Protocol((*paces, Segment(350e-6, 4.0))), stick_population=True)
    slip = longer.cycles[0]
    assert float(found.group(1)) == pytest.approx(slip.start_time + slip.stick_time, abs=1e-4)
    assert float(found.group(2)) == pytest.approx(slip.peak_stress, abs=2e-3)


def test_aged_chains_held_at_the_end_stay_stuck_and_say_for_how_long_at_least() -> None:
    """The puller stops mid-stick: σ stays, the chains age and strengthen; Eq 15 holds them for 1e4 aging times."""
    from stickslip.protocols import Protocol, Segment

    run = run_transient(
        GEL, Protocol((Segment(350e-6, 2.0), Segment(35e-6, 10.0), Segment(0.0, 5.0))), stick_population=True
    )
    assert run.regime == "stuck", run.message
    assert "hold for 10000 of their aging times" in run.message
