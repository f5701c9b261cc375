"""Round 29 (tester O): the time-dependent model's verdicts with the stick chains.

D1: a run that slides steadily after its start-up stick and slip is steady (it read "undetermined: 1 slip(s) ... no
stick after it ... run longer", whatever its length); D3: a period only for an oscillation; D4: the counts of a
limit cycle agree and say what they count; D7: the refusal of the chains under velocity control in the
interface's words."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

import stickslip
from cli_helpers import run_main
from stickslip import protocols, regimes
from stickslip.errors import ParameterError
from stickslip.models import Rig
from stickslip.quasistatic.steady import steady_state
from stickslip.transient import run_transient
from stickslip.transient.cycles import SETTLED_RELAXATIONS, SteadyReference, judge
from tester_sets import TESTER_GEL


@pytest.fixture(scope="module")
def gel_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("gel") / "mygel.toml"
    path.write_text(TESTER_GEL)
    return path


# --------------------------------------------------------------------------- D1 on a trace whose end is known
V_PULL, SIGMA_END, TAU, T_SLIP, SIGMA_S = 300e-6, 587.45, 1.0, 3.0, 775.0
STIFFNESS = 7.8e5


def _start_up(end: float, every: float = 0.01, level: float = SIGMA_END) -> tuple:
    """A stick from 0 Pa to σs at T_SLIP, then a slide that relaxes to ``level`` as one exponential of TAU."""
    time = np.unique(np.r_[np.arange(0.0, end, every), T_SLIP, end])
    after = time > T_SLIP
    decay = np.exp(-(time - T_SLIP) / TAU)
    stress = np.where(after, level + (560.0 - level) * decay, SIGMA_S * time / T_SLIP)
    velocity = np.where(after, V_PULL + 250e-6 * decay, 0.0)
    events = [("stick", 0.0, 0.0, 0.0), ("slip", T_SLIP, SIGMA_S, 5.5e-4)]
    return time, stress, velocity, protocols.constant(V_PULL, end), events


#: the steady state the synthetic slide goes to, its block decay TAU (slope / K) the relaxation
REFERENCE = SteadyReference(V_PULL, SIGMA_END, TAU * STIFFNESS, STIFFNESS, 1e-6 / V_PULL)


def _judge(end: float, every: float = 0.01, reference: SteadyReference = REFERENCE, level: float = SIGMA_END):
    time, stress, velocity, protocol, events = _start_up(end, every, level)
    return judge(time, stress, velocity, protocol, (), events, "block", None, resolution=1e-4, steady=reference)


@pytest.mark.parametrize("every", [0.01, 1.0, 7.0])
@pytest.mark.parametrize("end", [100.0, 1000.0])
def test_a_slide_settled_after_its_start_up_slip_is_steady_whatever_the_sampling_and_the_end(end, every):
    """Settled to 200 e^-97 Pa of the steady state: steady, the start-up stick-slip named in the words."""
    kind, message, found = _judge(end, every)
    assert kind == regimes.STEADY and found.kind == regimes.STEADY, message
    assert "after a start-up stick-slip" in message and f"σs = {SIGMA_S:.6g} Pa" in message, message
    assert found.periods == 0 and math.isnan(found.period)


@pytest.mark.parametrize(
    "end",
    [
        T_SLIP + 5.0 * TAU,  # 1.3 Pa from the steady state: still relaxing
        T_SLIP + 0.9 * SETTLED_RELAXATIONS * TAU,  # 2.5e-2 Pa off, but for less than the stretch after the slip
    ],
)
def test_a_slide_still_relaxing_after_its_start_up_slip_stays_undetermined(end):
    kind, message, _ = _judge(end)
    assert kind == regimes.UNDETERMINED and "has not settled" in message, message


def test_a_slide_that_stops_changing_away_from_the_steady_state_is_not_called_steady():
    """The trace settles 1 Pa above the steady curve's stress (a state that is not the steady state at Vp)."""
    kind, message, _ = _judge(200.0, level=SIGMA_END + 1.0)
    assert kind == regimes.UNDETERMINED, message


# --------------------------------------------------------------------------- D1 on the model
@pytest.mark.parametrize("every", [None, 7.0])
def test_the_papers_set_from_rest_above_vc_is_steady_after_its_start_up_stick_slip(every):
    """350 um/s for 100 s from rest: one stick to σs, the jump, then steady sliding at σ(350 um/s) of the steady
    solver; it read undetermined ("needs another slip ... run longer")."""
    params = stickslip.load_parameters("gelatin-glass")
    run = run_transient(params, protocols.constant(350e-6, 100.0), stick_population=True, every=every)
    want = float(steady_state(params, 350e-6).stress)
    assert run.stress[-1] == pytest.approx(want, rel=1e-4)
    (cycle,) = run.cycles
    assert cycle.slip_time is None  # one slip, no stick after it
    assert run.regime == regimes.STEADY, run.message
    assert "after a start-up stick-slip" in run.message and f"σs = {cycle.peak_stress:.6g} Pa" in run.message


def test_the_papers_set_still_relaxing_after_its_slip_stays_undetermined():
    params = stickslip.load_parameters("gelatin-glass")
    run = run_transient(params, protocols.constant(350e-6, 15.0), stick_population=True)
    want = float(steady_state(params, 350e-6).stress)
    assert abs(run.stress[-1] - want) > 1e-4 * want  # the premise: not yet at the steady state
    assert run.regime == regimes.UNDETERMINED and "has not settled" in run.message, run.message


@pytest.mark.parametrize("duration", ["1000 s", "3000 s"])
def test_the_testers_gel_above_vc_is_steady_at_any_length(capsys, gel_file, duration):
    code, out, err = run_main(
        capsys, "transient", "--params", str(gel_file), "--v0", "300 um/s", "--duration", duration,
        "--stick-population", "--json",
    )  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    params = stickslip.load_parameters(str(gel_file))
    want = float(steady_state(params, 300e-6).stress)
    assert data["status"] == "ok" and data["regime"] == "steady", data["message"]
    assert data["final_stress"] == pytest.approx(want, rel=1e-4)
    assert data["mean_stress"] == pytest.approx(want, rel=1e-4)
    assert data["period"] is None and data["summary"]["period"] is None and data["summary"]["cycles"] == 0


def test_stick_slip_below_vc_keeps_its_period_and_counts_its_cycles_once():
    """100 um/s for 60 s from rest (the paper's set): stick-slip, its period the quasi-static model's within the
    slip phase's 1.5 % (docs/transient.md); the periods seen are the whole cycles after the start-up cycle."""
    params = stickslip.load_parameters("gelatin-glass")
    run = stickslip.run("transient", params, protocols.constant(100e-6, 60.0), stick_population=True)
    quasi = stickslip.simulate(params, 100e-6, 60.0)
    assert run.regime.kind == regimes.STICK_SLIP, run.message
    assert run.regime.period == pytest.approx(quasi.regime.period, rel=0.015)
    assert run.summary["period"] == pytest.approx(run.regime.period, rel=1e-12)
    cycles = run.native.cycles
    whole_after_start_up = [c for c in cycles[1:] if c.period is not None]
    assert cycles[0].start_stress == 0.0  # from rest: the start-up cycle
    assert run.regime.periods == run.summary["cycles"] == len(whole_after_start_up) >= 2


# --------------------------------------------------------------------------- D4: the counts, labelled
def test_a_limit_cycle_counts_its_whole_cycles_after_the_start_up_cycle():
    """A start-up cycle from 0 Pa, then four identical whole cycles (the run ends in the stick after the fifth
    slip): four periods, five slips in all."""
    sticks, slips, period = [0.0, 250.0, 250.0, 250.0, 250.0, 250.0], [630.0, 550.0, 550.0, 550.0, 550.0], 20.0
    events = []
    for k, (s0, ss) in enumerate(zip(sticks, slips, strict=False)):
        events += [("stick", k * period, s0, 0.0), ("slip", k * period + 0.8 * period, ss, 1e-3)]
    events.append(("stick", len(slips) * period, sticks[-1], 0.0))
    end = events[-1][1] + 5.0
    time = np.linspace(0.0, end, 4001)
    stress = np.interp(time, [e[1] for e in events], [e[2] for e in events])
    _, message, found = judge(time, stress, np.full(time.size, 1e-4), protocols.constant(50e-6, end), (), events,
                              "block", None)  # fmt: skip
    assert found.kind == regimes.STICK_SLIP and found.periods == 4, message
    assert found.period == pytest.approx(period, rel=1e-12)
    assert "4 period(s)" in message and "after 1 start-up cycle" in message, message


def test_the_testers_limit_cycle_counts_agree(capsys, gel_file):
    """30 um/s for 300 s: "17 period(s) ... 18 slips whose cycles repeat ... 19 slip(s)" and cycles 19; now the
    periods seen, the summary's cycles and the message's periods are the whole cycles after the start-up one,
    and the slips in the run are the cycles listed."""
    code, out, err = run_main(
        capsys, "transient", "--params", str(gel_file), "--v0", "30 um/s", "--duration", "300 s",
        "--stick-population", "--json",
    )  # fmt: skip
    assert code == 0, err
    data = json.loads(out)
    message = data["message"]
    listed = data["cycles"]
    assert listed[0]["start_stress"] == 0.0  # the start-up cycle, from rest
    whole = sum(1 for c in listed[1:] if c["period"] is not None)
    assert data["regime"] == "stick-slip", message
    assert data["periods_seen"] == data["summary"]["cycles"] == whole, message
    assert int(re.search(r"(\d+) period\(s\) of", message).group(1)) == whole
    assert int(re.search(r"(\d+) slip\(s\) in the run", message).group(1)) == len(listed)


# --------------------------------------------------------------------------- D3: a period only for an oscillation
def test_a_slide_hold_slide_that_ends_steady_has_no_period(gel_file):
    shs = protocols.slide_hold_slide("100 um/s", "30 s", "5 s", "30 s")
    run = stickslip.run("transient", str(gel_file), shs, stick_population=True)
    assert run.regime.kind not in regimes.OSCILLATING, run.message
    assert any(c.period is not None for c in run.native.cycles)  # a whole cycle was there: no period of the run
    assert math.isnan(run.summary["period"]) and math.isnan(run.regime.period)


# --------------------------------------------------------------------------- D7: the refusal in the user's words
@pytest.mark.parametrize(
    "args",
    [
        ("transient", "--stick-population"),
        ("run", "--model", "transient", "--setting", "stick_population=true"),
    ],
)
def test_the_chains_under_velocity_control_are_refused_in_the_command_lines_words(capsys, args):
    code, out, err = run_main(
        capsys, *args, "--v0", "100 um/s", "--duration", "1 s", "--control", "velocity"
    )  # fmt: skip
    assert code == 2 and not out
    assert "--control spring" in err and "control='block'" not in err, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_the_chains_under_velocity_control_are_refused_in_the_apis_words():
    with pytest.raises(ParameterError, match=r"Rig\(control='spring'\)"):
        stickslip.run("transient", None, protocols.constant(100e-6, 1.0), Rig("velocity"), stick_population=True)
