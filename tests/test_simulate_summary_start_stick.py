"""The quasi-static run's summary when it ends during or just after the start-up stick.

A tester's finding: ``simulate --v0 "50 um/s" --duration "60 s" --start-stress "0 Pa"`` said "1 whole cycle(s) in
60 s", periods_seen 1 and peak 352.411 Pa, a stress that is no extremum of the trace (whose maximum, the start-up
stick's σs, is 769.389 Pa).  The cause: the last whole cycle's extremes were read over the settled period
(23.09 s) from its start, so for the start-up cycle (period 54.75 s) they were the ramp's stress 23.09 s in,
K V0 x 23.09 s above the start (452.359 Pa from 100 Pa).  A start-up cycle from another stress than σc does not
repeat: it is no period of the stick-slip cycle.  Checked against the trace's own extremes and the phases solved
here on their own (stick_phase, jump_velocity, slip_phase), not against earlier output.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip.models.run import Run
from stickslip.parameters import load_parameters
from stickslip.quasistatic.critical import critical_point
from stickslip.quasistatic.cycle import simulate
from stickslip.quasistatic.jump import jump_velocity
from stickslip.quasistatic.slip import slip_phase
from stickslip.quasistatic.stick import stick_phase

GEL = load_parameters("gelatin-glass")
V0 = 50e-6


def _cycle(start: float) -> tuple[float, float]:
    """(σs, period) of the stick from ``start`` and its slip, solved here phase by phase."""
    stick = stick_phase(GEL, V0, start)
    assert stick.peak_stress is not None and stick.stick_time is not None
    jump = jump_velocity(GEL, stick.peak_stress, "aging")
    assert jump.velocity is not None
    return stick.peak_stress, stick.stick_time + slip_phase(GEL, V0, jump.velocity).duration


@pytest.fixture(scope="module")
def phases():
    sigma_c = float(critical_point(GEL).stress)
    return {"σc": sigma_c, "settled": _cycle(sigma_c), 0.0: _cycle(0.0), 100.0: _cycle(100.0)}


def _settled_periods(phases, start: float, duration: float) -> int:
    """Whole settled cycles in ``duration``: those that end within it after the start-up cycle from ``start``."""
    _, first = phases[start]
    _, period = phases["settled"]
    return max(0, math.floor((duration - first) / period)) if first <= duration else 0


@pytest.mark.parametrize("start", [0.0, 100.0])
@pytest.mark.parametrize("duration", [30.0, 52.0, 60.0, 61.0, 120.0])
def test_the_regime_s_extremes_and_periods_are_the_solution_s(phases, start, duration):
    """From 0 Pa the start-up stick ends at 50.21 s, its slip at 54.75 s; from 100 Pa at 41.94 s.  30 s: still
    stuck; 52 s: the start-up slip under way (from 0 Pa); 60, 61 s: the start-up cycle only; 120 s: settled."""
    sim = simulate(GEL, V0, duration, start_stress=start)
    sigma_c = phases["σc"]
    sigma_s, period = phases["settled"]
    first_peak, first_period = phases[start]
    assert first_peak > sigma_s * 1.1  # the start-up stick overshoots the settled cycle's σs
    whole = _settled_periods(phases, start, duration)
    assert sim.regime.period == pytest.approx(period, rel=1e-9)
    if whole:  # the last whole cycle is the settled one: its σs and σc
        assert sim.regime.peak == pytest.approx(sigma_s, rel=1e-9)
        assert sim.regime.trough == pytest.approx(sigma_c, rel=1e-9)
    else:  # no period of the cycle seen: the run's own extremes, the start-up stick's among them
        assert sim.regime.peak == float(np.max(sim.stress))
        assert sim.regime.trough == float(np.min(sim.stress)) == start
        if duration >= _stick_end(start):  # the start-up stick ended in its slip: its σs
            assert sim.regime.peak == pytest.approx(first_peak, rel=1e-9)
        else:  # still stuck: the load's ramp at the end, σ0 + K V0 t (Eq 12)
            ramp_end = start + GEL.block.effective_stiffness * V0 * duration
            assert sim.regime.peak == pytest.approx(ramp_end, rel=1e-9)
    # never the ramp's stress one settled period into the start-up stick (the old 352.411 / 452.359 Pa)
    ramp = start + GEL.block.effective_stiffness * V0 * period
    assert not math.isclose(sim.regime.peak, ramp, rel_tol=1e-6)
    # periods of the cycle the run settles into: the start-up cycle is none
    assert sim.regime.periods == whole, sim.message
    assert f"; {whole} whole cycle(s) in {duration:.6g} s" in sim.message
    if duration < first_period and duration >= _stick_end(start):
        assert f"the start-up cycle from {start:.6g} Pa (σs = {first_peak:.6g} Pa" in sim.message
        assert f"still slipping at {duration:.6g} s" in sim.message
    if duration >= first_period:  # the start-up cycle completed: named as what it is
        assert f"after the start-up cycle from {start:.6g} Pa (a transient that does not repeat" in sim.message
        assert f"σs = {first_peak:.6g} Pa, period {first_period:.6g} s" in sim.message
    assert sim.regime.amplitude_ratio == 1.0 if whole >= 2 else math.isnan(sim.regime.amplitude_ratio)


def _stick_end(start: float) -> float:
    stick = stick_phase(GEL, V0, start)
    assert stick.stick_time is not None
    return stick.stick_time


def test_a_start_at_sigma_c_is_the_settled_cycle_from_the_first(phases):
    sigma_c = phases["σc"]
    sigma_s, period = phases["settled"]
    sim = simulate(GEL, V0, 60.0)
    assert sim.regime.periods == math.floor(60.0 / period) == 2
    assert sim.regime.peak == pytest.approx(sigma_s, rel=1e-9) and sim.regime.trough == pytest.approx(sigma_c)
    assert "start-up" not in sim.message
    # σc as typed to its printed digits is σc, not a start-up cycle
    typed = simulate(GEL, V0, 60.0, start_stress=float(f"{sigma_c:.6g}"))
    assert typed.regime.periods == 2 and "start-up" not in typed.message


def test_the_cli_s_json_text_csv_and_run_read_agree_with_the_trace(capsys, tmp_path, phases):
    """The tester's command: every place the run's extremes are written gives the trace's own."""
    sigma_s, period = phases["settled"]
    first_peak, first_period = phases[0.0]
    trace = tmp_path / "s0.csv"
    args = ("simulate", "--v0", "50 um/s", "--duration", "60 s", "--start-stress", "0 Pa", "-o", str(trace))
    code, out, _ = run_main(capsys, *args, "--json")
    assert code == 0
    summary = json.loads(out)
    read = Run.read(trace)
    stress = read.stress
    assert stress is not None
    top = float(np.max(stress))
    assert top == pytest.approx(first_peak, rel=1e-9)
    assert summary["peak_stress"] == pytest.approx(top, rel=1e-12)
    assert summary["trough_stress"] == 0.0 == float(np.min(stress))
    assert read.peak == pytest.approx(top, rel=1e-12) and read.trough == 0.0
    assert summary["periods_seen"] == 0 == read.regime.periods
    # the settled cycle's numbers stay its own, labelled so (the summary of the repeating cycle)
    assert summary["summary"]["peak_stress"] == pytest.approx(sigma_s, rel=1e-9)
    assert summary["summary"]["period"] == pytest.approx(period, rel=1e-9)
    assert summary["summary"]["cycles"] == 0
    # the cycle table keeps the start-up cycle, the one whole cycle of the run
    (cycle,) = summary["cycles"]
    assert cycle["start_stress"] == 0.0 and cycle["period"] == pytest.approx(first_period, rel=1e-9)
    code, out, _ = run_main(capsys, *args[:-2])
    assert code == 0
    assert "(no whole cycle within the run)" in out and f"highest {top:.6g} Pa" in out, out
    assert "0 whole cycle(s) in 60 s after the start-up cycle from 0 Pa" in out
