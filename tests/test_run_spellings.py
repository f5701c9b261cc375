"""One run command (issue 30 item 3, issue 28 item 7): ``simulate``, ``transient`` and ``rsf simulate`` are
spellings of ``run --model NAME``: the same Run CSV, the same figure, the same summary; ``simulate().regime`` is a
``Regime`` equal to its kind's name; plain ``compare`` is ``compare --models quasi-static,rsf --protocol-set
bond-vs-rsf``.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import stickslip
from cli_helpers import run_main
from stickslip import protocols, regimes
from stickslip.columns import json_safe, json_text

#: Each spelling and its ``run --model`` form, on one short protocol (a second or less of CPU each).
SPELLINGS = {
    "quasi-static": (
        ["simulate", "--v0", "50 um/s", "--duration", "30 s", "--jump-curve", "no-aging", "--start-stress", "300 Pa"],
        ["run", "--model", "quasi-static", "--v0", "50 um/s", "--duration", "30 s", "--setting",
         "jump_curve=no-aging", "--start", "300 Pa"],
    ),
    "transient": (
        ["transient", "--control", "velocity", "--start", "steady", "--v0", "350 um/s", "--duration", "2 ms",
         "--every", "0.5 ms"],
        ["run", "--model", "transient", "--control", "velocity", "--start", "steady", "--v0", "350 um/s",
         "--duration", "2 ms", "--every", "0.5 ms"],
    ),
    "rsf": (
        ["rsf", "simulate", "--a", "0.005", "--b", "0.01", "--dc", "10 um", "--stiffness", "1e-3 1/um",
         "--segment", "1 um/s:5 s", "--segment", "10 um/s:5 s", "--every", "1 s"],
        ["run", "--model", "rsf", "--set", "a=0.005", "--set", "b=0.01", "--set", "dc=10 um", "--stiffness",
         "1e-3 1/um", "--segment", "1 um/s:5 s", "--segment", "10 um/s:5 s", "--every", "1 s"],
    ),
}  # fmt: skip
#: The Run CSV's base columns, then each model's own (the columns every spelling writes).
COLUMNS = {
    "quasi-static": ["time", "stress", "slider_velocity", "slider_position", "load_point_position", "block_shear",
                     "chain_fraction", "phase"],
    "transient": ["time", "stress", "slider_velocity", "slider_position", "load_point_position", "bonded_fraction"],
    "rsf": ["time", "friction", "slider_velocity", "slider_position", "load_point_position", "state"],
}  # fmt: skip


def _ok(capsys, *argv: str) -> str:
    code, out, err = run_main(capsys, *argv)
    assert code == 0, err
    return out


@pytest.mark.parametrize("model", sorted(SPELLINGS))
def test_each_spelling_writes_the_run_csv_of_run_model(capsys, tmp_path, model):
    spelling, run = SPELLINGS[model]
    mine, theirs = tmp_path / "spelling.csv", tmp_path / "run.csv"
    _ok(capsys, *spelling, "-o", str(mine), "--plot", str(tmp_path / "spelling.png"))
    _ok(capsys, *run, "-o", str(theirs), "--plot", str(tmp_path / "run.png"))
    # one --plot path (Run.plot()) for every spelling: the same picture, pixel for pixel
    assert (tmp_path / "spelling.png").read_bytes() == (tmp_path / "run.png").read_bytes()
    header = mine.read_text().splitlines()[1]
    assert [cell.split(" [")[0] for cell in header.split(",")] == COLUMNS[model]
    assert mine.read_text() == theirs.read_text()  # metadata line, header and every digit
    back = stickslip.Run.read(mine)  # Run.read reads a spelling's trace, regime and all
    assert back.model == model and back.regime.kind in regimes.KINDS


@pytest.mark.parametrize("model", sorted(SPELLINGS))
def test_each_spelling_prints_the_summary_of_run_model(capsys, model):
    spelling, run = SPELLINGS[model]
    assert json.loads(_ok(capsys, *spelling, "--json")) == json.loads(_ok(capsys, *run, "--json"))
    if model == "rsf":  # without -o rsf simulate writes the trace to stdout, the summary to stderr (run -o -)
        _, out, err = run_main(capsys, *spelling)
        _, out_run, err_run = run_main(capsys, *run, "-o", "-")
        assert (out, err) == (out_run, err_run) and out.startswith("# stickslip run")
        return
    text = _ok(capsys, *spelling)
    assert text == _ok(capsys, *run)
    assert text.startswith(f"model {model}: ")


def test_simulate_text_holds_the_cycles_from_the_closed_form_stick(capsys):
    """The summary's numbers are the model's: the stick from 300 Pa rises at K V0 (Eq 12) to the printed peak."""
    text = _ok(capsys, *SPELLINGS["quasi-static"][0])
    data = json.loads(_ok(capsys, *SPELLINGS["quasi-static"][0], "--json"))
    first = data["cycles"][0]
    k, v0 = data["effective_stiffness"], data["pulling_velocity"]
    assert first["peak_stress"] == pytest.approx(300.0 + k * v0 * first["stick_time"], rel=1e-9)
    assert f"{first['peak_stress']:.5g}" in text and "Cycles" in text
    assert data["start_stress"] == 300.0 and data["jump_curve"] == "no-aging"


def test_analyze_reads_the_old_simulate_columns_and_the_run_csv_alike(capsys, tmp_path):
    """A user's file of the columns simulate wrote before (velocity, slider_displacement, ...) and the Run CSV of
    today give the same cycles, those of the simulation that made them."""
    from stickslip.columns import csv_text
    from stickslip.quasistatic.cycle import CYCLE_COLUMNS

    sim = stickslip.simulate(stickslip.load_parameters("gelatin-glass"), 50e-6, 60.0)
    old = tmp_path / "old.csv"
    old.write_text(csv_text(sim.to_frame()), encoding="utf-8")
    assert old.read_text().splitlines()[0].startswith("time [s],stress [Pa],velocity [m/s],slider_displacement [m]")
    assert list(sim.to_frame().columns) == list(CYCLE_COLUMNS)
    new = tmp_path / "new.csv"
    _ok(capsys, "simulate", "--v0", "50 um/s", "--duration", "60 s", "-o", str(new))
    found = [json.loads(_ok(capsys, "analyze", str(path), "--v0", "50 um/s", "--json")) for path in (old, new)]
    assert len(found[0]["cycles"]) == len(found[1]["cycles"]) == 3
    for then, now in zip(found[0]["cycles"], found[1]["cycles"], strict=True):  # the same rows of time and stress
        assert then["complete"] == now["complete"]
        for key in ("peak_stress", "critical_stress", "stick_time", "period", "jump_velocity", "slip_time"):
            # rel 1e-8: CSV numbers at 15 digits (round 28), and "50 um/s" read as 4.9999999999999996e-05
            assert then[key] == (None if now[key] is None else pytest.approx(now[key], rel=1e-8)), key
    complete = next(c for c in found[0]["cycles"] if c["complete"])
    assert complete["peak_stress"] == pytest.approx(sim.cycles[1].peak_stress, rel=1e-4)
    assert complete["critical_stress"] == pytest.approx(sim.critical_stress, rel=1e-4)


def test_simulation_regime_is_the_runs_type_and_equals_its_kind():
    params = stickslip.load_parameters("gelatin-glass")
    sim = stickslip.simulate(params, 50e-6, 60.0)
    run = stickslip.run("quasi-static", params, protocols.constant(50e-6, 60.0))
    assert type(sim.regime) is type(run.regime) is regimes.Regime
    assert sim.regime == run.regime  # the run takes the engine's regime, evidence and all
    assert sim.regime == "stick-slip" and "stick-slip" == sim.regime and sim.regime != "steady"
    assert str(sim.regime) == f"{sim.regime}" == "stick-slip"
    assert sim.regime in (regimes.STICK_SLIP, regimes.DECAYING) and sim.regime not in (regimes.STEADY,)
    assert {"stick-slip": 1}[sim.regime] == 1 and hash(sim.regime) == hash("stick-slip")
    assert sim.regime.periods == 2 and sim.regime.amplitude_ratio == 1.0
    # its period is the repeating cycle's stick and slip, the table's own numbers
    whole = sim.cycles[1]
    assert sim.regime.period == pytest.approx(whole.stick_time + whole.slip_time, rel=1e-12)
    assert json_safe({"regime": sim.regime}) == {"regime": "stick-slip"}
    assert json.loads(json_text(sim.summary()))["regime"] == "stick-slip"
    other = regimes.Regime("stick-slip", 3, 1.0, 1.0, 2.0, 0.0, "another run")
    assert other != sim.regime and other == "stick-slip"  # two regimes compare by their evidence too


def test_plain_compare_is_the_bond_vs_rsf_protocol_set(capsys):
    plain = _ok(capsys, "compare", "--json")
    spelled = _ok(capsys, "compare", "--models", "quasi-static,rsf", "--protocol-set", "bond-vs-rsf", "--json")
    assert plain == spelled
    data = json.loads(plain)
    assert data["status"] == "ok" and set(data["panels"]) == {"velocity step", "slide-hold-slide"}


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--models", "quasi-static,transient", "--protocol-set", "bond-vs-rsf"], "quasi-static,rsf or transient"),
        (["--models", "rsf", "--protocol-set", "bond-vs-rsf"], "a bond model beside rate-and-state"),
        (["--models", "quasi-static,rsf", "--protocol-set", "bond-vs-rsf", "--bond-model", "transient"],
         "--bond-model transient"),
        (["--models", "quasi-static,rsf", "--protocol-set", "bond-vs-rsf", "--segment", "1 um/s:1 s"], "--segment"),
        (["--models", "quasi-static,rsf", "--protocol-set", "nope"], "--protocol-set"),
    ],
)  # fmt: skip
def test_protocol_set_refusals_are_one_line(capsys, args, words):
    code, out, err = run_main(capsys, "compare", *args)
    assert code == 2 and out == "" and err.count("\n") == 1 and words in err, err


def test_a_transient_run_stopped_by_its_budget_keeps_its_trace(capsys, tmp_path):
    """transient and run --model transient alike: the Run CSV up to the stop, status "stopped", exit 3."""
    trace = tmp_path / "t.csv"
    code, out, err = run_main(capsys, "transient", "--v0", "100 um/s", "--duration", "5 s", "--max-steps", "1000",
                              "-o", str(trace), "--json")  # fmt: skip
    assert code == 3 and "the run up to there is in" in err, err
    data = json.loads(out)
    assert data["status"] == "stopped" and 0 < data["end_time"] < 5.0 and data["steps"] == 1001
    back = stickslip.Run.read(trace)
    assert np.isclose(back.time[-1], data["end_time"], rtol=1e-12)
