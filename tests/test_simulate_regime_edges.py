"""The quasi-static model (``simulate``) at the edges of its regimes: a steady curve without Vc, a run that ends
before it settles (its verdict is where its phases settle), and a run the model cannot continue."""

from __future__ import annotations

import json

import pytest

from cli_helpers import run_main
from stickslip import load_parameters, simulate
from stickslip.models.quasi_static import simulation_run  # the Run a sweep row is read from
from stickslip.models.run import time_mean
from stickslip.quasistatic.steady import steady_state
from stickslip.sweeps.models import get_model, run_point

RISING = {"bonds.bond_time": "1 ns"}  # the aging curve rises at every velocity: no Vc
UNSETTLED = {"bonds.bond_time": "129.8 us"}  # V0 = 124.97 um/s > Vc = 77.2 um/s: settles at 61.97 s


def test_a_curve_without_vc_is_steady_sliding_not_an_input_error(capsys):
    code, out, err = run_main(
        capsys, "simulate", "--set", "bonds.bond_time=1 ns", "--v0", "50 um/s", "--duration", "60 s", "--json"
    )
    assert code == 0, err
    summary = json.loads(out)
    sigma = float(steady_state(load_parameters("gelatin-glass", overrides=RISING), 50e-6).stress)
    assert summary["status"] == "ok" and summary["regime"] == "steady"
    assert summary["mean_stress"] == pytest.approx(sigma, rel=1e-9)
    assert summary["final_stress"] == pytest.approx(sigma, rel=1e-9) and summary["end_time"] == 60.0
    assert "no Vc" in summary["message"] and "rises monotonically" in summary["message"]
    assert summary["critical_velocity"] is None  # not a number in words or JSON
    code, out, _ = run_main(capsys, "simulate", "--set", "bonds.bond_time=1 ns", "--v0", "50 um/s", "--duration", "6 s")
    assert code == 0 and "regime: steady" in out and "nan" not in out


def test_a_start_stress_without_vc_is_refused_in_one_line(capsys):
    code, _, err = run_main(
        capsys, "simulate", "--set", "bonds.bond_time=1 ns", "--v0", "50 um/s", "--duration", "6 s",
        "--start-stress", "300 Pa",
    )  # fmt: skip
    assert code == 2 and err.count("\n") == 1
    assert "start stress" in err and "leave the start stress out" in err


def test_a_sweep_point_without_vc_is_steady():
    model = get_model("quasi-static")
    row = run_point(model, {"pulling_velocity": 50e-6, "bonds.bond_time": 1e-9}, {"duration": 60.0})
    assert row["status"] == "ok" and row["regime"] == "steady"
    assert row["mean_stress"] == pytest.approx(3.05001e-4, rel=1e-5)


def test_a_run_that_ends_before_it_settles_says_so_and_keeps_the_run_s_own_mean():
    """The quasi-static verdict is where its phases settle (computed, 61.97 s here), not a sampled tail: `steady`,
    saying the run ends before it gets there; the settled mean is sigma(V0), the run's own mean beside it."""
    params = load_parameters("gelatin-glass", overrides=UNSETTLED)
    sim = simulate(params, 124.97e-6, 20.0)
    assert sim.regime == "steady" and sim.status == "ok"
    assert "the run ends at 20 s, still slipping, before it settles at t = 61.9736 s" in sim.message
    summary = simulation_run(sim).summary
    assert time_mean(sim.time, sim.stress) == pytest.approx(305.913, abs=1e-3)  # the run's own (run --json)
    assert summary["mean_stress"] == pytest.approx(float(steady_state(params, 124.97e-6).stress), rel=1e-6)
    settled = simulate(params, 124.97e-6, 100.0)  # long enough: settled within the run
    assert settled.regime == "steady" and "before it settles" not in settled.message


def test_a_run_the_model_cannot_continue_fails_with_what_it_computed(capsys):
    code, out, err = run_main(capsys, "simulate", "--v0", "1 m/s", "--duration", "1 h", "--json")
    assert code == 3
    summary = json.loads(out)
    assert summary["status"] == "failed" and summary["regime"] == "undetermined"
    assert summary["end_time"] == pytest.approx(0.00308926, rel=1e-5)
    assert "no jump velocity" in summary["message"] and "what follows is not known" in summary["message"]
    assert "the run failed" in err
    sim = simulate(load_parameters("gelatin-glass"), 1.0, 3600.0)
    assert sim.status == "failed" and sim.summary()["status"] == "failed"
    # a run that reaches its duration is not failed, stuck included
    assert simulate(load_parameters("gelatin-glass"), 50e-6, 60.0).status == "ok"


def test_a_sweep_point_the_model_cannot_continue_is_failed_not_ok(tmp_path, capsys):
    """A failure is never reported as success: the sweep row of that run is "failed" (its message says where the
    model stopped), counted among the failures of the summary line and drawn as one in the phase diagram."""
    row = run_point(get_model("quasi-static"), {"pulling_velocity": 1.0}, {"duration": 60.0})
    assert row["status"] == "failed" and row["regime"] == "undetermined"
    assert "no jump velocity" in row["message"]
    ok = run_point(get_model("quasi-static"), {"pulling_velocity": 50e-6}, {"duration": 60.0})
    assert ok["status"] == "ok"
    out = tmp_path / "sweep"
    args = ["--vary", "pulling_velocity=50 um/s,1 m/s", "--duration", "60 s", "--workers", "0", "-o", str(out)]
    code, text, err = run_main(capsys, "sweep", *args)
    assert code == 0, err
    assert "(1 failed)" in text + err
