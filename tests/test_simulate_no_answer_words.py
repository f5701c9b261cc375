"""The quasi-static model's words where its picture has no answer or the run has not seen what it reports.

A tester's findings: valid parameters (τ = 1 s, inside the README's box) ended as bad input (exit 2); a stuck
block above Vc was explained by stick-slip seen below it; a run shorter than one stick printed its cycle's
period as if seen.  Checks against the steady solver and the model's own phases, not against earlier output.
"""

from __future__ import annotations

import pytest

from cli_helpers import run_main
from stickslip.errors import ModelError, RunFailed
from stickslip.parameters import load_parameters
from stickslip.quasistatic.steady import steady_state

GEL = load_parameters("gelatin-glass")


def test_a_curve_falling_everywhere_is_a_failed_run_not_bad_input(capsys):
    """τ = 1 s: σ(V) falls monotonically, velocity-weakening at every V0, no Vc and no branch to jump onto."""
    code, _, err = run_main(capsys, "simulate", "--v0", "50 um/s", "--duration", "60 s", "--set",
                            "bonds.bond_time=1 s")  # fmt: skip
    assert code == 3 and "no answer from the quasi-static model" in err and "falls monotonically" in err
    assert "stickslip transient" in err
    from stickslip.quasistatic.cycle import simulate

    params = GEL.with_overrides({"bonds.bond_time": 1.0})
    assert float(steady_state(params, 60e-6).stress) < float(steady_state(params, 50e-6).stress)  # weakening
    sim = simulate(params, 50e-6, 60.0)  # a failed run returned with its words (round 30; it raised RunFailed)
    assert sim.status == "failed" and "no answer from the quasi-static model" in sim.message
    assert issubclass(RunFailed, ModelError)


def test_a_block_stuck_above_vc_is_told_that_sliding_there_is_stable(capsys):
    """140 µm/s > Vc through a soft spring: the stick from σc never ends (Eq 15's limitation); the words now say
    that steady sliding is stable there, and the time-dependent model from a steady start slides at σ(V0)."""
    args = ("--v0", "140 um/s", "--stiffness", "30.65 kPa/m")
    code, out, _ = run_main(capsys, "simulate", *args, "--duration", "40 s")
    assert code == 0 and "regime: stuck" in out and "V0 is above Vc = 124.097 µm/s" in out
    code, out, _ = run_main(capsys, "transient", *args, "--duration", "5 s", "--start", "steady", "--json")
    import json

    run = json.loads(out)
    assert code == 0 and run["regime"] == "steady"
    assert run["final_stress"] == pytest.approx(float(steady_state(GEL, 140e-6).stress), rel=1e-4)


def test_a_run_shorter_than_a_stick_says_its_cycle_is_not_yet_seen(capsys):
    code, out, _ = run_main(capsys, "simulate", "--v0", "50 um/s", "--duration", "15 s")
    assert code == 0 and "0 whole cycle(s) in 15 s (the period and σs are its cycle's once settled" in out
    code, out, _ = run_main(capsys, "simulate", "--v0", "50 um/s", "--duration", "60 s")
    assert code == 0 and "whole cycle(s) in 60 s" in out and "once settled" not in out
