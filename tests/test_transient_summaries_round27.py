"""Round 27, tester G: how runs of the time-dependent bond model are summarised (docs/regimes.md).

1. A run that rang for one period and then settled exactly read "undetermined: 1 period(s), period not known"
   (its one fall through mid-level gave no period, and without a period the classifier never found the tail
   quiet); a re-slide's ramp, its aged bonds reaching the FENE wall a cohort at a time, counted a dip of 849 Pa on
   the way to a 39.2 MPa peak as a period.  Now steady where it is steady, and a re-slide that has not settled
   says so.
2. A tail ringing below the tolerance read "still changing (0.000461 Pa ...; tolerance 0.00257 Pa)": the check was
   on the change still to come, read at three instants that sample the ringing's phases.  It is now read as means
   over whole periods, and where a change is not slowing down the words give both changes compared.
3. A stick that began under another pace and held to the run's end was "stuck"; the same stick within one pace
   "undetermined: ... they collapse at t = ...".  Both now say when Eq 15 has the chains let go.
4. The stick chains' cycles "repeat" within 2 % of the rise: two cycles whose sticks were 0.108 Pa apart (4x the
   run's tolerance) were called a limit cycle.  They now repeat within the run's rtol x the stress; cycles that do
   not are said to drift, by how much.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

import stickslip
from cli_helpers import run_main
from stickslip import protocols, regimes
from stickslip.protocols import Protocol, Segment
from stickslip.quasistatic.steady import steady_state
from stickslip.transient import run_transient
from stickslip.transient.cycles import judge

TESTER = Path("/tmp/testerG-work")
#: the soft gel of tester G (G = 1 kPa, h = 5 mm, B = 40 mm): written here if the tester's file is not there
SOFT_BLOCK = """
[block]
shear_modulus = "1 kPa"
height = "5 mm"
top_length = "40 mm"
base_length = "30 mm"
"""


def _floor(y: np.ndarray) -> float:
    """The transient model's tolerance: 1e-5 of the largest stress (transient.cycles.SETTLED)."""
    return 1e-5 * float(np.max(np.abs(y)))


# --------------------------------------------------------------------------- 1. settled exactly, and a re-slide
def test_a_run_that_rang_one_period_and_settled_exactly_is_steady():
    """Two peaks and one fall through mid-level, then the signal is exactly its level for 28 s: steady (it read
    'undetermined: 1 period(s), period not known' and oscillating, for want of a period to be quiet for)."""
    level, period, amplitude, decay = 257.36, 0.58, 0.2, 0.4
    t = np.linspace(0.0, 30.0, 300_001)
    cut = 2.25 * period  # a zero of the cosine: the ring ends on the level, continuously
    y = np.where(t < cut, level + amplitude * np.exp(-t / decay) * np.cos(2 * np.pi * t / period), level)
    found = regimes.classify(t, y, floor=_floor(y), unit="Pa")
    assert found.kind == regimes.STEADY, found.evidence
    assert "not known" not in found.evidence


def test_a_reslide_ramp_with_a_dip_is_no_period_and_says_it_is_still_changing():
    """A ramp to a 39.2 MPa peak with a 849 Pa dip at 31.9 kPa (a cohort at the FENE wall), a rupture to 6 Pa and a
    refill towards 293 Pa that is 35 Pa short at the end: no period, still changing, and the change still to come
    is the refill's (read from the peak, across the rupture, it was 67.8 Pa)."""
    t = np.linspace(0.0, 15e-3, 30_001)
    dip_at, peak_at, low, level, refill = 8.59e-3, 10.7e-3, 6.0, 293.0, 2e-3
    # 300 Pa to 31.9 kPa at 8.59 ms, then on to 39.2 MPa at 10.7 ms (the tester's re-slide), exponentially
    slow, fast = np.log(31.9e3 / 300.0) / dip_at, np.log(39.2e6 / 31.9e3) / (peak_at - dip_at)
    ramp = np.where(t < dip_at, 300.0 * np.exp(slow * t), 31.9e3 * np.exp(fast * (t - dip_at)))
    dip = np.where((t > dip_at) & (t < 8.75e-3), -849.0 * np.clip((t - dip_at) / 2e-6, 0, 1), 0.0)
    rupture = 39.2e6 + (low - 39.2e6) * (t - peak_at) / 0.1e-3
    after = level - (level - low) * np.exp(-(t - peak_at - 0.1e-3) / refill)
    y = np.where(t < peak_at, ramp + dip, np.where(t < peak_at + 0.1e-3, rupture, after))
    found = regimes.classify(t, y, floor=_floor(y), unit="Pa", settle_floor=1e-5 * abs(y[-1]))
    assert found.periods == 0 and found.kind == regimes.UNDETERMINED, found.evidence
    assert "still changing" in found.evidence and "period" not in found.evidence, found.evidence
    # read from the rupture's trough, not across the rupture: the change still to come is the refill's
    said = float(re.search(r"about ([0-9.e+-]+) Pa still to come", found.evidence).group(1))
    assert said == pytest.approx(level - y[-1], rel=0.05)


def test_the_testers_settled_run_with_the_stick_chains_is_steady_at_the_steady_stress(capsys):
    """127 -> 124.2 µm/s from the steady start with the stick chains: steady, as without them, at sigma(124.2 µm/s)
    of the steady solver (not 'undetermined ... period not known' beside '(no oscillation)')."""
    args = ["transient", "--start", "steady", "--start-velocity", "127 um/s", "--v0", "124.2 um/s"]
    code, out, err = run_main(capsys, *args, "--duration", "30 s", "--stick-population", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["regime"] == "steady", summary["message"]
    assert "not known" not in summary["message"]
    sigma = float(steady_state(stickslip.load_parameters("gelatin-glass"), 124.2e-6).stress)
    assert summary["final_stress"] == pytest.approx(sigma, rel=1e-6)


def test_a_reslide_after_a_hold_says_it_has_not_settled(capsys):
    """Velocity control, 10 s hold, a 15 ms re-slide: 'the re-slide after the 10 s hold has not settled', no period
    (it read '1 period(s), period not known'), and it is indeed short of sigma(100 µm/s) of the steady solver."""
    code, out, err = run_main(
        capsys, "transient", "--control", "velocity", "--start", "steady", "--v0", "100 um/s", "--duration", "2 ms",
        "--segment", "0 um/s:10 s", "--segment", "100 um/s:15 ms", "--json",
    )  # fmt: skip
    assert code == 0, err
    summary = json.loads(out)
    assert summary["regime"] == "undetermined" and summary["periods_seen"] == 0, summary["message"]
    assert "the re-slide after the 10 s hold has not settled" in summary["message"]
    assert "period not known" not in summary["message"]
    sigma = float(steady_state(stickslip.load_parameters("gelatin-glass"), 100e-6).stress)
    assert summary["final_stress"] < sigma - 10.0


# --------------------------------------------------------------------------- 2. a tail ringing below the tolerance
RING_PERIOD, RING_LEVEL, RING_START = 0.187, 257.36, 0.0103
RING_DECAY = -np.log(0.96) / RING_PERIOD  # 4 % a period, as the tester's run at 2.8 MPa/m


def _ringing(end: float, mean=None) -> tuple[np.ndarray, np.ndarray]:
    t = np.linspace(0.0, end, 100_001)
    ring = RING_START * np.exp(-RING_DECAY * t) * np.cos(2 * np.pi * t / RING_PERIOD)
    return t, (RING_LEVEL if mean is None else mean(t)) + ring


@pytest.mark.parametrize("end", [9.82, 9.9, 10.12, 10.2])
def test_a_tail_ringing_below_the_tolerance_about_a_fixed_level_is_steady(end):
    """The ring's swing is below the tolerance over the last periods and its level does not move: steady whatever
    phase the run ends on (these ends read 'still changing', with changes below the tolerance quoted)."""
    t, y = _ringing(end)
    floor = _floor(y)
    assert 2 * RING_START * np.exp(-RING_DECAY * (end - RING_PERIOD)) < floor  # the truth: below it at the end
    found = regimes.classify(t, y, floor=floor, unit="Pa")
    assert found.kind == regimes.STEADY, found.evidence
    swing = float(re.search(r"rings by ([0-9.e+-]+) Pa", found.evidence).group(1))
    assert swing <= floor


@pytest.mark.parametrize("end", [9.86, 10.16])
def test_a_ringing_tail_whose_level_still_moves_is_not_steady_and_says_how_far(end):
    """The same ring on a level still 0.05 Pa (20x the tolerance) from its end, approached exponentially: not
    steady, and the change still to come is the truth's."""
    to_come = 0.05
    t, y = _ringing(end, lambda t: RING_LEVEL - to_come * np.exp(-(t - end) / 2.0))
    found = regimes.classify(t, y, floor=_floor(y), unit="Pa")
    assert found.kind == regimes.UNDETERMINED, found.evidence
    said = float(re.search(r"about ([0-9.e+-]+) Pa still to come", found.evidence).group(1))
    assert said == pytest.approx(to_come, rel=0.1)


def test_a_change_that_does_not_slow_down_is_said_with_both_changes_compared():
    """A creep that speeds up, below the tolerance over the last tau: not steady (no exponential approach bounds
    it), and the words give the change over the last tau and over the tau before, the numbers compared (the truth:
    a (2 T tau - tau^2) and a (2 T tau - 3 tau^2) for y = a t^2)."""
    a, end, tau = 2e-4, 2.0, 0.5
    t = np.linspace(0.0, end, 2001)
    y = 257.36 + a * t**2
    found = regimes.classify(t, y, floor=_floor(y), unit="Pa", relaxation=tau)
    assert found.kind == regimes.UNDETERMINED
    changes = re.search(
        r"still changing \(([0-9.e+-]+) Pa over the last ([0-9.e+-]+) s after ([0-9.e+-]+) Pa", found.evidence
    )
    assert changes, found.evidence
    last, said_tau, before = (float(g) for g in changes.groups())
    assert said_tau == pytest.approx(tau, rel=1e-2)
    assert last == pytest.approx(a * (2 * end * tau - tau**2), rel=1e-2)
    assert before == pytest.approx(a * (2 * end * tau - 3 * tau**2), rel=1e-2)
    assert "not slowing down" in found.evidence


# --------------------------------------------------------------------------- 3. a stick across a change of pace
RAMP = "velocity (um/s);duration (ms)\n100;500\n150;500\n200;500\n250;500\n300;500\n"


@pytest.mark.parametrize("every", [None, "0.2 s"])
def test_a_stick_held_to_the_end_across_paces_says_when_the_chains_let_go(tmp_path, capsys, every):
    """Tester G's ramp 100 -> 300 µm/s ends mid-stick, the stick begun under 100 µm/s: it read 'stuck ... the stick
    chains hold it'.  Now 'undetermined', with the instant and stress at which the same protocol, run on for
    2.5 s more at 300 µm/s, slips (the truth), whatever the sampling."""
    ramp = tmp_path / "ramp.csv"
    ramp.write_text(RAMP)
    sampling = [] if every is None else ["--every", every]
    code, out, err = run_main(
        capsys, "transient", "--protocol", str(ramp), "--start", "steady", "--stick-population", *sampling, "--json"
    )
    assert code == 0, err
    summary = json.loads(out)
    assert summary["regime"] == "undetermined", summary["message"]
    found = re.search(r"they collapse at t = ([0-9.]+) s \(σs = ([0-9.]+) Pa", summary["message"])
    assert found, summary["message"]
    longer = Protocol((*(Segment(v * 1e-6, 0.5) for v in (100, 150, 200, 250)), Segment(300e-6, 3.0)))
    run = run_transient(stickslip.load_parameters("gelatin-glass"), longer, start="steady", stick_population=True)
    slip = run.cycles[0]
    assert float(found.group(1)) == pytest.approx(slip.start_time + slip.stick_time, abs=1e-4)
    assert float(found.group(2)) == pytest.approx(slip.peak_stress, abs=2e-3)


# --------------------------------------------------------------------------- 4. cycles that repeat, or drift
def _chain_events(sticks: list[float], slips: list[float], period: float = 20.0) -> list:
    events = []
    for k, (s0, ss) in enumerate(zip(sticks, slips, strict=False)):
        events += [("stick", k * period, s0, 0.0), ("slip", k * period + 0.8 * period, ss, 1e-3)]
    if len(sticks) > len(slips):
        events.append(("stick", len(slips) * period, sticks[-1], 0.0))
    return events


def _judge(sticks: list[float], slips: list[float], rtol: float | None) -> regimes.Regime:
    events = _chain_events(sticks, slips)
    end = events[-1][1] + 5.0
    time = np.linspace(0.0, end, 2001)
    stress = np.interp(time, [e[1] for e in events], [e[2] for e in events])
    velocity = np.full(time.size, 1e-4)
    _, _, found = judge(time, stress, velocity, protocols.constant(50e-6, end), (), events, "block", None, rtol)
    return found


def test_two_cycles_apart_by_more_than_the_runs_tolerance_do_not_repeat():
    """The tester's soft gel before its third stick: sticks 0.108 Pa and σs 0.241 Pa apart, against rtol 1e-4 of
    each stress (0.026 and 0.062 Pa): not a limit cycle yet (2 % of the rise, 7.3 Pa, called it one).  At rtol 1e-3
    (0.26 and 0.62 Pa) the same cycles repeat within what the run resolves."""
    sticks, slips = [256.760, 256.652], [624.122, 624.363]
    found = _judge(sticks, slips, 1e-4)
    assert found.kind == regimes.UNDETERMINED and "beyond the run's tolerance" in found.evidence, found.evidence
    assert _judge(sticks, slips, 1e-3).kind == regimes.STICK_SLIP


def test_a_third_stick_where_the_second_began_is_the_limit_cycle_after_a_start_up_cycle():
    """The stick after the second slip starts where the second started: one period of the limit cycle, and the first
    cycle named a start-up cycle, not 'cycles repeat'."""
    found = _judge([256.760, 256.652, 256.652], [624.122, 624.363], 1e-4)
    assert found.kind == regimes.STICK_SLIP and found.periods == 1, found.evidence
    assert found.period == pytest.approx(20.0, rel=1e-12)
    assert "start-up cycle" in found.evidence and "cycles repeat" not in found.evidence


def test_cycles_that_keep_drifting_are_said_to_drift_with_what_is_still_to_come():
    """Sticks 250, 251, 251.5, 251.75, 251.875 Pa (moves halving: the limit is 252 Pa), the rise the same each cycle
    (amplitude ratio 1): not a limit cycle within rtol 1e-4, drifting, 0.125 Pa still to come (the truth)."""
    sticks = [250.0, 251.0, 251.5, 251.75, 251.875]
    slips = [s + 300.0 for s in sticks[:4]]
    found = _judge(sticks, slips, 1e-4)
    assert found.kind == regimes.UNDETERMINED, found.evidence
    assert "still drift" in found.evidence
    said = float(re.search(r"about ([0-9.e+-]+) Pa still to come", found.evidence).group(1))
    assert said == pytest.approx(252.0 - 251.875, rel=1e-9)


def _soft_gel(tmp_path: Path) -> Path:
    mine = tmp_path / "soft.toml"
    if (TESTER / "soft.toml").exists():
        shutil.copy(TESTER / "soft.toml", mine)
    else:  # the gelatin-glass set with the tester's block
        text = (Path(stickslip.__file__).parent / "parameter_sets" / "gelatin-glass.toml").read_text()
        mine.write_text(text.split("[block]")[0] + SOFT_BLOCK)
    return mine


def test_the_testers_soft_gel_is_one_period_of_its_limit_cycle_after_a_start_up_cycle(tmp_path, capsys):
    """100 s at 50 µm/s: three sticks (256.760, 256.652, 256.652 Pa); the verdict and the summary both rest on the
    last whole cycle, the one that repeats, and the words say the first was a start-up cycle."""
    args = ["transient", "--params", str(_soft_gel(tmp_path)), "--v0", "50 um/s", "--duration", "100 s"]
    code, out, err = run_main(capsys, *args, "--stick-population", "--start", "steady", "--json")
    assert code == 0, err
    summary = json.loads(out)
    message = summary["message"]
    assert summary["regime"] == "stick-slip" and summary["periods_seen"] == 1, message
    assert "start-up cycle" in message and "cycles repeat" not in message
    last = summary["summary"]
    assert summary["period"] == pytest.approx(last["period"], rel=1e-12)


def test_two_slips_from_a_steady_start_are_not_yet_a_limit_cycle_in_the_verdict_and_the_summary(capsys):
    """50 µm/s for 45 s from the steady start (gelatin-glass, rtol 1e-4): the sticks 0.16 Pa apart, 6x the run's
    tolerance; the verdict is undetermined and the summary does not report the start-up cycle as the run's."""
    code, out, err = run_main(
        capsys, "transient", "--v0", "50 um/s", "--duration", "45 s", "--start", "steady", "--stick-population",
        "--json",
    )  # fmt: skip
    assert code == 0, err
    summary = json.loads(out)
    assert summary["regime"] == "undetermined" and "start-up cycle" in summary["message"], summary["message"]
    assert summary["summary"]["cycles"] == 0 and summary["summary"]["period"] is None
