"""``stickslip run --model NAME``: every model through the one interface, on the shared protocol vocabulary.

Checked against routes that do not pass through it: the quasi-static model's own ``simulate`` command, the
steady curve (``steady_state``) a velocity step must settle on, ``stickslip analyze`` reading the Run CSV back as
a measured record, and a user's model imported as ``module:attr``.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

from cli_helpers import run, run_main
from stickslip.models import Run
from stickslip.parameters import load_parameters

QS = ["run", "--model", "quasi-static", "--v0", "50 um/s", "--duration", "80 s"]


def as_json(*args: str) -> dict:
    return json.loads(run(CliRunner(), *args, "--json"))


def test_quasi_static_run_is_the_simulate_command():
    through_interface = as_json(*QS)
    direct = as_json("simulate", "--v0", "50 um/s", "--duration", "80 s")
    cycle = direct["cycles"][1]  # a whole cycle after the first
    assert through_interface["regime"] == direct["regime"] == "stick-slip"
    assert through_interface["period"] == pytest.approx(cycle["period"], rel=1e-9)
    assert through_interface["peak_stress"] == pytest.approx(cycle["peak_stress"], rel=1e-9)
    assert through_interface["trough_stress"] == pytest.approx(cycle["start_stress"], rel=1e-9)
    assert cycle["start_stress"] < through_interface["mean_stress"] < cycle["peak_stress"]


def test_the_run_csv_reads_back_and_analyze_finds_its_cycles(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    summary = json.loads(run(CliRunner(), *QS, "-o", "run.csv", "--json"))
    header = (tmp_path / "run.csv").read_text(encoding="utf-8").splitlines()[1]
    assert header.startswith("time [s],stress [Pa],slider_velocity [m/s]")
    back = Run.read(tmp_path / "run.csv")
    assert back.regime.kind == "stick-slip" and back.period == pytest.approx(summary["period"], rel=1e-12)
    code, out, err = run_main(capsys, "analyze", "run.csv", "--v0", "50 um/s", "--json")
    assert code == 0, err
    analysis = json.loads(out)
    whole = [c for c in analysis["cycles"] if c.get("period") is not None]
    assert analysis["regime"] == "stick-slip" and whole
    assert whole[0]["period"] == pytest.approx(summary["period"], rel=1e-3)
    assert whole[0]["peak_stress"] == pytest.approx(summary["peak_stress"], rel=1e-3)


def test_a_transient_velocity_step_settles_on_the_steady_curve():
    from stickslip import steady_state

    out = as_json("run", "--model", "transient", "--control", "velocity", "--start", "steady", "--v0", "350 um/s",
                  "--duration", "5 ms", "--segment", "1 mm/s:10 ms", "--setting", "rtol=1e-4")  # fmt: skip
    final = float(steady_state(load_parameters("gelatin-glass"), np.array([1e-3])).stress[0])
    assert out["regime"] == "steady" and out["rig"] == {"control": "velocity", "stiffness": None}
    assert out["final_stress"] == pytest.approx(final, rel=1e-4)


def test_rsf_takes_its_stiffness_in_friction_per_slip_or_as_its_key():
    base = ["run", "--model", "rsf", "--v0", "1 um/s", "--duration", "10 s", "--segment", "10 um/s:30 s",
            "--set", "a=0.005", "--set", "b=0.01", "--set", "dc=10 um", "--every", "1 s"]  # fmt: skip
    by_option = as_json(*base, "--stiffness", "1e-3 1/um")
    by_key = as_json(*base, "--set", "k=1000 1/m")
    # the same run; only the spring's source differs: the option (the rig) or the parameter set's key
    assert by_option.pop("rig") == {**by_key.pop("rig"), "stiffness_from": "rig"}
    assert by_option == by_key
    assert by_option["regime"] == "decaying oscillation"  # k = 1000/m above kc = (b - a)/dc = 500/m
    assert "mean_friction" in by_option and "mean_stress" not in by_option


@pytest.fixture
def viscous():
    import viscous_model

    yield "viscous_model:MODEL"
    viscous_model.forget()


def test_a_model_from_outside_the_package_runs_by_its_import_path(viscous, capsys):
    argv = ["run", "--model", viscous, "--control", "velocity", "--v0", "2 mm/s", "--duration", "1 s"]
    out = as_json(*argv, "--set", "c=5 MPa s/m")
    assert out["model"] == "test-viscous" and out["regime"] == "steady"
    assert out["mean_stress"] == pytest.approx(5e6 * 2e-3, rel=1e-12)
    code, _, err = run_main(capsys, *argv, "--setting", "fail=true")
    assert code == 3 and "the run failed: told to fail" in err


REFUSALS = [
    ([*QS, "--control", "velocity"], "velocity"),
    ([*QS, "--segment", "1 mm/s:1 s"], "one constant pulling velocity"),
    ([*QS, "--every", "1 s"], "the quasi-static model takes no --every"),
    ([*QS, "--set", "bonds.bond_time=224"], "needs a unit"),
    (["run", "--model", "no-such-model", "--v0", "1 um/s", "--duration", "1 s"], "model 'no-such-model': expected"),
    (["run", "--model", "rsf", "--v0", "1 um/s", "--duration", "1 s", "--control", "velocity"], "velocity"),
    (
        [
            "run",
            "--model",
            "transient",
            "--control",
            "velocity",
            "--v0",
            "1 um/s",
            "--duration",
            "1 s",
            "--stiffness",
            "1 MPa/m",
        ],
        "--stiffness",
    ),
    (["run", "--model", "quasi-static"], "give the protocol"),
    ([*QS, "-o", "/no-such-folder-of-stickslip/run.csv"], "does not exist"),  # refused before the run, not after
    ([*QS, "--plot", "run.xyz"], "unknown figure format .xyz"),
]


@pytest.mark.parametrize(("argv", "named"), REFUSALS, ids=[" ".join(a[1:4]) + f" {n}" for a, n in REFUSALS])
def test_what_a_model_cannot_run_is_one_line(argv, named, capsys):
    code, out, err = run_main(capsys, *argv)
    assert code == 2 and out == ""
    assert err.startswith("stickslip: error:") and err.count("\n") == 1 and named in err


def test_a_run_that_stops_or_fails_on_its_way_exits_3(capsys, monkeypatch):
    """A run stopped at its step budget, or whose state went non-finite, ran: exit 3 (a failed run), not the
    exit 2 of bad input, with the place it stopped in one line."""
    from cli_helpers import run_main

    words = ["run", "--model", "transient", "--v0", "100 um/s", "--duration", "40 s", "--setting",
             "stick_population=true"]  # fmt: skip
    code, _, err = run_main(capsys, *words, "--setting", "max_steps=1000")
    assert code == 3 and err.count("\n") == 1 and "stopped at the budget of 1000 steps at t = " in err, err
    from stickslip.models.transient import Transient
    from stickslip.transient.solver import SolverFailed

    def non_finite(*args, **kwargs):
        raise SolverFailed("transient: the state went non-finite at t = 3.07 ms")

    monkeypatch.setattr(Transient, "run", non_finite)
    code, _, err = run_main(capsys, *words)
    assert code == 3 and "the run failed: transient: the state went non-finite" in err, err


def test_a_run_that_does_not_oscillate_reports_its_range_not_a_peak_and_trough(capsys):
    """Issue 28 item 6: a stuck run's highest and lowest stress are a ramp's ends, not a cycle's peak and
    trough; the text says so and the JSON says whether the numbers belong to an oscillation."""
    import json

    from cli_helpers import run_main

    code, out, err = run_main(capsys, "run", "--model", "transient", "--v0", "50 um/s", "--duration", "1 s")
    assert code == 0, err
    assert "highest" in out and "lowest" in out and "(no oscillation)" in out and "peak" not in out.split("\n")[-2]
    code, out, err = run_main(capsys, "run", "--model", "transient", "--v0", "50 um/s", "--duration", "1 s", "--json")
    assert json.loads(out)["oscillates"] is False
    code, out, err = run_main(capsys, "run", "--model", "quasi-static", "--v0", "50 um/s", "--duration", "50 s",
                              "--json")  # fmt: skip
    assert json.loads(out)["oscillates"] is True
