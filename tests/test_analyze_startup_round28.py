"""Round 28: the summary of ``stickslip analyze`` (its "mean ± sd" column, ``--json``'s ``summary``) leaves out the
cycles the record cuts (starred in the table): a transient run from rest starts with a stick from 0 Pa that ages
longer than the limit cycle's (σs 631.6 against 556.4 Pa at 100 µm/s), and it was averaged in.

Truth: the quasi-static limit cycle of the same parameter set at the same V0 (``quasistatic.cycle.simulate``),
and the record cut after the start-up cycle, whose mean must not move; the stick slope K·V0 of a synthetic record.
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from cli_helpers import run_main
from stickslip.fitting.data import read_stick_data
from stickslip.parameters import load_parameters
from stickslip.quasistatic.cycle import simulate

V0 = 100e-6  # m/s


@pytest.fixture(scope="module")
def transient_record(tmp_path_factory: pytest.TempPathFactory):
    """The tester's record: a transient run from rest at 100 µm/s for 60 s (a start-up cycle, two limit cycles, a
    stick the record ends in), and its analysis as JSON."""
    from stickslip.cli.main import main

    path = tmp_path_factory.mktemp("startup") / "tr100.csv"
    with pytest.raises(SystemExit) as exit_info:
        main(["transient", "--v0", "100 um/s", "--duration", "60 s", "--stick-population", "-o", str(path)])
    assert exit_info.value.code == 0
    return path


def _analysis(capsys, path, *extra: str) -> dict:
    code, out, err = run_main(capsys, "analyze", str(path), "--v0", "100 um/s", "--json", *extra)
    assert code == 0, err
    return json.loads(out)


def _limit_cycle():
    return simulate(load_parameters("gelatin-glass"), V0, 80.0).cycles[-1]


def test_the_summary_is_the_limit_cycles_not_the_start_ups(capsys, transient_record):
    data = _analysis(capsys, transient_record)
    truth = _limit_cycle()
    cycles, summary = data["cycles"], data["summary"]
    first = cycles[0]
    # the record holds a start-up cycle, cut by its start, far from the limit cycle (else this test proves nothing)
    assert not first["complete"] and first["peak_stress"] > 1.05 * truth.peak_stress
    complete = [c["index"] for c in cycles if c["complete"]]
    assert len(complete) >= 2 and 1 not in complete
    # the means against the quasi-static limit cycle (the transient model's differs from it by < 0.1 % in σs)
    assert summary["peak_stress"]["mean"] == pytest.approx(truth.peak_stress, rel=2e-3)  # was 4.5 % high
    assert summary["jump_velocity"]["mean"] == pytest.approx(truth.jump_velocity, rel=5e-3)  # was 10 % high
    assert summary["critical_stress"]["mean"] == pytest.approx(truth.start_stress, rel=5e-3)
    assert summary["stick_time"]["mean"] == pytest.approx(truth.stick_time, rel=5e-3)
    assert summary["peak_stress"]["n"] == len(complete)
    assert summary["averaged_cycles"] == complete
    assert {e["cycle"] for e in summary["left_out_cycles"]} == {c["index"] for c in cycles if not c["complete"]}
    assert "before the record" in summary["left_out_cycles"][0]["why"]
    # the stick line is the same in every stick, the start-up one too: K·V0 over all of them
    assert summary["stick_slope"]["n"] == len(cycles)


def test_the_mean_does_not_move_when_the_start_up_cycle_is_cut_off(capsys, transient_record, tmp_path):
    full = _analysis(capsys, transient_record)
    first = full["cycles"][0]
    cut_at = first["peak_time"] + 0.5 * first["slip_time"]  # within the start-up cycle's slip
    frame = pd.read_csv(transient_record, comment="#")
    later = tmp_path / "later.csv"
    kept = frame.loc[frame["time [s]"] >= cut_at, ["time [s]", "stress [Pa]"]]
    kept.drop_duplicates().to_csv(later, index=False)  # the run repeats a row where the solver restarts
    rest = _analysis(capsys, later)
    assert rest["cycles"][0]["peak_stress"] < 1.01 * _limit_cycle().peak_stress  # no start-up cycle left in it
    for name in ("peak_stress", "jump_velocity", "critical_stress", "stick_time", "slip_time", "period"):
        assert rest["summary"][name]["mean"] == pytest.approx(full["summary"][name]["mean"], rel=1e-4), name


def test_the_table_says_which_cycles_its_mean_is_over(capsys, transient_record):
    code, out, _ = run_main(capsys, "analyze", str(transient_record), "--v0", "100 um/s")
    assert code == 0
    row = next(line for line in out.splitlines() if line.startswith("│ σs [Pa]"))
    cells = [c.strip() for c in row.strip("│").split("│")]
    mean = float(cells[-1].split("±")[0])
    assert mean == pytest.approx(_limit_cycle().peak_stress, rel=2e-3)  # 581.5 before
    text = " ".join(out.split())
    assert "complete cycle(s) 2-3" in text and "cycle 1 (stick began before the record)" in text


def test_no_complete_cycle_gives_no_mean_of_the_cut_ones(capsys, tmp_path):
    """One slip between a stick cut by the record's start and one cut by its end: nothing to average but the
    stick lines (slope 30 Pa/s by construction)."""
    t = np.arange(0.0, 20.0, 0.01)
    x = np.where(t < 8, 300 + 30 * t, np.where(t < 9, 540 - 280 * (t - 8), 260 + 30 * (t - 9)))
    path = tmp_path / "cut.csv"
    pd.DataFrame({"time [s]": t, "stress [Pa]": x}).to_csv(path, index=False)
    data = _analysis(capsys, path)
    assert [c["complete"] for c in data["cycles"]] == [False, False]
    assert data["cycles"][0]["peak_stress"] == pytest.approx(540.0, abs=1.0)  # measured, in its own column
    summary = data["summary"]
    assert summary["peak_stress"] == {"mean": None, "std": None, "n": 0}  # was 540 from the cut cycle
    assert summary["averaged_cycles"] == []
    assert summary["stick_slope"]["mean"] == pytest.approx(30.0, rel=1e-6) and summary["stick_slope"]["n"] == 2
    code, out, _ = run_main(capsys, "analyze", str(path), "--v0", "100 um/s")
    assert code == 0 and "no complete cycle" in " ".join(out.split())


def test_fit_stick_still_reads_every_cycle_with_a_stick_time(capsys, transient_record, tmp_path):
    """The per-cycle rows of -o are not the summary: every cycle is written, and fit stick's reader keeps the
    rows with a stick time (the complete ones here), as before."""
    table = tmp_path / "cycles.csv"
    data = _analysis(capsys, transient_record, "-o", str(table))
    rows = pd.read_csv(table)
    assert list(rows["cycle [1]"]) == [c["index"] for c in data["cycles"]]
    stick = read_stick_data(table)
    timed = [c for c in data["cycles"] if c["stick_time"] is not None]
    assert len(stick.stick_time) == len(timed)
    assert np.allclose(stick.stick_time, [c["stick_time"] for c in timed], rtol=1e-9)
