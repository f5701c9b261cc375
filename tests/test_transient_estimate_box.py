"""The cost estimate inside the README's box (V 0.1 um/s - 1 m/s, tau 1 ns - 1 s), a tester's two misses.

1. Too low: velocity control at 1 um/s for 10 s was estimated at 1.5e5 steps and 15 s of CPU, then ran for 10 min
   and more: the bonds that age into permanence (1.8 % of the gel's) live to the FENE wall, reach it dl_m/V = 1.07 s
   on and die there within ~1 us of their arrival, so the cohorts then step at ~2.5e5 per second, over ~5e5 living
   cohorts each, and the disturbance of the empty start echoes through the wall every dl_m/V, decaying by 0.99 per
   echo: never quasi-steady.  Now refused up front (~1e5 h of CPU).
2. Too high: tau = 1 ns at 50 um/s was estimated at 8e7 steps for 10 ms (refused) since the settling counted the
   bonds' memory as dl_m/V = 21 ms; they leave the population within 13 ns, and the run takes 97 steps.
"""

from __future__ import annotations

import pytest

from cli_helpers import run_main
from stickslip.parameters import load_parameters
from stickslip.protocols import constant
from stickslip.transient import run_transient
from stickslip.transient.solver import estimate_cost

GEL = load_parameters("gelatin-glass")
FAST_BONDS = GEL.with_overrides({"bonds.bond_time": 1e-9})


def _ratio(params, protocol, **settings) -> float:  # type: ignore[no-untyped-def]
    """Steps estimated / steps taken, both in this test."""
    taken = run_transient(params, protocol, max_time=20.0, **settings).steps
    return estimate_cost(params, protocol, **settings).steps / taken


@pytest.mark.parametrize("duration", [1e-3, 1e-2, 1.0])
def test_bonds_that_turn_over_in_a_nanosecond_are_estimated_as_steady_sliding(duration: float) -> None:
    """Measured: 97 steps for 1 ms, 10 ms or 1 s (estimated 329; before: 8e7 for 10 ms, refused)."""
    assert 1.0 <= _ratio(FAST_BONDS, constant(50e-6, duration), control="velocity") <= 5.0


def test_the_nanosecond_run_of_the_report_is_accepted(capsys) -> None:  # type: ignore[no-untyped-def]
    code, out, err = run_main(
        capsys, "transient", "--control", "velocity", "--v0", "50 um/s", "--duration", "10 ms",
        "--set", "bonds.bond_time=1 ns", "--max-time", "5 s",
    )  # fmt: skip
    assert code == 0, err
    assert "steady" in out


@pytest.mark.parametrize(("velocity", "duration"), [(10e-6, 0.15), (30e-6, 0.1)])
def test_slow_sliding_past_the_fene_wall_is_estimated_within_its_factor(velocity: float, duration: float) -> None:
    """Past dl_m/V the cohorts step at the wall (measured: 3 845 and 4 886 steps; estimated 6 710 and 4 430)."""
    assert 0.3 <= _ratio(GEL, constant(velocity, duration), control="velocity") <= 5.0


def test_ten_seconds_at_one_micron_per_second_is_refused_up_front(capsys) -> None:  # type: ignore[no-untyped-def]
    """It ran silently in a pipe until its CPU budget (12 256 steps reached 1.108 s of 10 s in 20 s of CPU)."""
    estimate = estimate_cost(GEL, constant(1e-6, 10.0), control="velocity")
    assert estimate.steps > 1e6 and estimate.seconds > 3600
    code, _, err = run_main(capsys, "transient", "--control", "velocity", "--v0", "1 um/s", "--duration", "10 s")
    assert code == 2 and "of CPU" in err and err.count("\n") == 1, err


def test_a_slow_run_over_its_budget_stops_with_what_it_computed(capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    out_file = tmp_path / "t.csv"
    code, _, err = run_main(
        capsys, "transient", "--control", "velocity", "--v0", "1 um/s", "--duration", "0.5 s",
        "--max-steps", "2000", "--max-time", "20 s", "-o", str(out_file),
    )  # fmt: skip
    assert code == 3 and "stopped at the budget of 2000 steps" in err, err
    assert out_file.exists()
