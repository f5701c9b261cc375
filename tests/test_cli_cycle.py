"""Command line: ``stickslip simulate`` and ``stickslip stick``.

The numbers are the issue's acceptance numbers (item 6 and "Done when"): at 50 um/s stick-slip with
ts ~ 19.3 s, sigma_s ~ 553 Pa, Vs ~ 702 um/s (Table 1); at 350 um/s steady sliding at ~391.5 Pa;
at 10 um/s the block stays stuck.  Bad input goes through ``main()`` for exit status 2 and one line.
"""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from cli_helpers import run, run_main


def test_simulate_json_at_50_um_per_s(runner):
    summary = json.loads(run(runner, "simulate", "--v0", "50 um/s", "--duration", "120 s", "--json"))
    assert summary["regime"] == "stick-slip"
    assert len(summary["cycles"]) == 5
    first = summary["cycles"][0]
    assert first["stick_time"] == pytest.approx(19.3, abs=0.05)
    assert first["peak_stress"] == pytest.approx(553.0, abs=1.0)
    assert first["jump_velocity"] == pytest.approx(702e-6, abs=1e-6)  # SI: m/s
    assert 1.0 < first["slip_time"] < 10.0
    assert first["period"] == pytest.approx(first["stick_time"] + first["slip_time"])
    assert summary["final_velocity"] == 0.0  # 120 s falls in the sixth stick
    assert summary["critical_stress"] == pytest.approx(257.4, abs=0.05)


def test_simulate_json_at_100_um_per_s_in_si_units(runner):
    summary = json.loads(run(runner, "simulate", "--v0", "1e-4 m/s", "--duration", "30 s", "--json"))
    assert summary["cycles"][0]["stick_time"] == pytest.approx(9.75, abs=0.01)
    assert summary["cycles"][0]["peak_stress"] == pytest.approx(556.0, abs=1.0)


def test_simulate_350_ends_in_steady_sliding(runner):
    summary = json.loads(run(runner, "simulate", "--v0", "350 um/s", "--duration", "120 s", "--json"))
    assert summary["regime"] == "steady"
    assert summary["final_stress"] == pytest.approx(391.5, abs=0.05)
    assert summary["final_velocity"] == pytest.approx(350e-6, rel=1e-12)
    assert summary["cycles"][0]["slip_time"] is None and summary["cycles"][0]["period"] is None


def test_simulate_human_output_trace_and_plot(runner, tmp_path):
    trace, figure = tmp_path / "trace.csv", tmp_path / "trace.png"
    out = run(runner, "simulate", "--v0", "50 um/s", "--duration", "50 s", "-o", str(trace), "--plot", str(figure))
    assert "regime: stick-slip" in out and "Vs (µm/s)" in out and "701.98" in out
    assert figure.stat().st_size > 1000
    with trace.open() as handle:
        rows = list(csv.reader(handle))[1:]  # the Run CSV: its metadata line first
    header = rows[0]
    assert header[:3] == ["time [s]", "stress [Pa]", "slider_velocity [m/s]"]
    assert [h.split(" [")[0] for h in header] == [
        "time", "stress", "slider_velocity", "slider_position", "load_point_position",
        "block_shear", "chain_fraction", "phase",
    ]  # fmt: skip
    body = np.array([[float(x) for x in row[:-1]] for row in rows[1:]])
    assert body[-1, 0] == pytest.approx(50.0)
    assert {row[-1] for row in rows[1:]} == {"stick", "slip"}


def test_simulate_no_aging_jump_curve(runner):
    summary = json.loads(
        run(runner, "simulate", "--v0", "50 um/s", "--duration", "25 s", "--jump-curve", "no-aging", "--json")
    )
    assert summary["jump_curve"] == "no-aging"
    assert summary["cycles"][0]["jump_velocity"] == pytest.approx(751e-6, abs=1e-6)


def test_stick_says_the_block_stays_stuck(runner):
    out = run(runner, "stick", "--v0", "10 um/s")
    assert "STAYS STUCK" in out and "never slips" in out
    result = json.loads(run(runner, "stick", "--v0", "10 um/s", "--json"))
    assert result["stuck"] is True and result["stick_time"] is None and result["peak_stress"] is None
    assert result["status"] == "stuck"
    assert result["curve"]["time"][-1] >= 100.0  # followed for 10 aging times by default


def test_stick_slips_at_50_um_per_s(runner, tmp_path):
    result = json.loads(run(runner, "stick", "--v0", "50 um/s", "--json"))
    assert result["stuck"] is False and result["stick_time"] == pytest.approx(19.3, abs=0.05)
    assert result["curve"]["chain_fraction"][0] == 1.0 and result["curve"]["chain_fraction"][-1] == 0.0
    curve, figure = tmp_path / "nc.csv", tmp_path / "nc.png"
    out = run(runner, "stick", "--v0", "50 um/s", "-o", str(curve), "--plot", str(figure))
    assert "slips after ts = 19.28" in out
    assert curve.read_text().splitlines()[0] == "time [s],stress [Pa],chain_fraction [1]"
    assert figure.stat().st_size > 1000


def test_stick_constant_load_without_aging(runner):
    from scipy.special import exp1

    from stickslip.parameters import load_parameters

    p = load_parameters()
    result = json.loads(run(runner, "stick", "--v0", "0", "--no-aging", "--json"))
    s0 = p.bonds.force_sensitivity * result["start_stress"] / p.stick.attached_chains
    assert result["stuck"] is False
    assert result["stick_time"] == pytest.approx(exp1(s0) / p.stick.break_rate, rel=1e-9)  # closed form


@pytest.mark.parametrize(
    ("args", "word"),
    [
        (["simulate", "--v0", "-50 um/s", "--duration", "10 s"], "--v0"),
        (["simulate", "--v0", "50 um/s", "--duration", "0 s"], "--duration"),
        (["simulate", "--v0", "50 um", "--duration", "10 s"], "--v0"),
        (["simulate", "--v0", "50 um/s", "--duration", "10 s", "--start-stress", "-5 Pa"], "--start-stress"),
        (["simulate", "--v0", "50 um/s", "--duration", "10 s", "--set", "block.shear_modulus=0"], "shear_modulus"),
        (["stick", "--v0", "fast"], "--v0"),
        (["stick", "--v0", "50 um/s", "--until", "-1 s"], "--until"),
    ],
)
def test_bad_input_exits_2_with_one_line(capsys, args, word):
    status, _, err = run_main(capsys, *args)
    assert status == 2
    assert err.startswith("stickslip: error:") and word in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
