"""``stickslip compare --models A,B``: one protocol, one rig, each model through the interface, side by side.

Each row is checked against something that does not pass through compare: the model's own ``stickslip run``
on the same protocol and rig, the steady curve a velocity step settles on, and c V for a user's viscous model.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip import steady_state
from stickslip.parameters import load_parameters

STEP = ["--control", "velocity", "--v0", "350 um/s", "--duration", "5 ms", "--segment", "1 mm/s:10 ms"]


@pytest.fixture
def viscous():
    import viscous_model

    yield "viscous_model:MODEL"
    viscous_model.forget()


def ok_json(capsys, *argv: str) -> dict:
    code, out, err = run_main(capsys, *argv, "--json")
    assert code == 0, err
    return json.loads(out)


def test_each_model_runs_the_same_protocol_and_rig(viscous, capsys, tmp_path):
    figure = tmp_path / "overlay.png"
    both = ok_json(
        capsys, "compare", "--models", f"transient,{viscous}", *STEP, "--set", "c=1 MPa s/m", "-o", str(figure)
    )
    assert list(both["models"]) == ["transient", "test-viscous"]
    assert both["rig"] == {"control": "velocity", "stiffness": None} and len(both["protocol"]) == 2
    steady = float(steady_state(load_parameters("gelatin-glass"), np.array([1e-3])).stress[0])
    assert both["models"]["transient"]["final_stress"] == pytest.approx(steady, rel=1e-3)
    assert both["models"]["test-viscous"]["final_stress"] == pytest.approx(1e6 * 1e-3, rel=1e-12)
    alone = ok_json(capsys, "run", "--model", "transient", *STEP)
    for key in ("regime", "peak_stress", "trough_stress", "mean_stress", "final_stress"):
        assert both["models"]["transient"][key] == alone[key]
    assert figure.read_bytes()[:4] == b"\x89PNG"


def test_the_table_names_regime_period_peak_trough_mean(capsys):
    argv = [
        "compare",
        "--models",
        "quasi-static,rsf",
        "--v0",
        "50 um/s",
        "--duration",
        "60 s",
        "--set",
        "a=0.005",
        "--set",
        "b=0.01",
        "--set",
        "dc=10 um",
    ]
    code, out, err = run_main(capsys, *argv)
    assert code == 0, err
    for word in ("model", "regime", "period (s)", "peak", "trough", "mean", "quasi-static", "stick-slip", "rsf"):
        assert word in out
    both = ok_json(capsys, *argv)
    qs = ok_json(capsys, "run", "--model", "quasi-static", "--v0", "50 um/s", "--duration", "60 s")
    assert both["models"]["quasi-static"]["period"] == qs["period"]
    assert "mean_friction" in both["models"]["rsf"]  # no normal stress: friction, not stress


def test_a_failed_run_is_not_success(viscous, capsys):
    code, _, err = run_main(capsys, "compare", "--models", f"transient,{viscous}", *STEP, "--set", "fail=1")
    assert code == 3 and "the run of test-viscous failed: told to fail" in err


REFUSALS = [
    (
        [
            "compare",
            "--models",
            "quasi-static,transient",
            "--v0",
            "50 um/s",
            "--duration",
            "1 s",
            "--segment",
            "1 mm/s:1 s",
        ],
        "model quasi-static: one constant pulling velocity",
    ),
    (
        ["compare", "--models", "quasi-static,rsf", "--v0", "50 um/s", "--duration", "1 s", "--control", "velocity"],
        "no velocity control",
    ),
    (
        ["compare", "--models", "quasi-static,rsf", "--v0", "50 um/s", "--duration", "1 s", "--set", "zz=1"],
        "--set zz: none of the models",
    ),
    (["compare", "--models", "quasi-static", "--v0", "50 um/s", "--duration", "1 s"], "two or more models"),
    (["compare", "--models", "quasi-static,simulate", "--v0", "50 um/s", "--duration", "1 s"], "the same model"),
    (
        ["compare", "--models", "quasi-static,rsf", "--v0", "50 um/s", "--duration", "1 s", "--hold", "2 s"],
        "--hold: not with --models",
    ),
    (["compare", "--segment", "1 mm/s:1 s"], "--segment: only with --models"),
]


@pytest.mark.parametrize(("argv", "named"), REFUSALS, ids=[n for _, n in REFUSALS])
def test_what_cannot_be_compared_is_one_line(argv, named, capsys):
    code, out, err = run_main(capsys, *argv)
    assert code == 2 and out == ""
    assert err.startswith("stickslip: error:") and err.count("\n") == 1 and named in err


def test_models_take_run_settings_and_starts_and_say_where_each_began(capsys):
    """Issue 28 item 4: the two bond models on the paper's cycle need the stick chains (--setting) and a steady
    start for the transient model (--start MODEL=S); each row states its start.  The transient model's row is
    checked against `stickslip run` with the same words (an independent path through the CLI)."""
    words = ["--v0", "100 um/s", "--duration", "12 s"]
    both = ok_json(capsys, "compare", "--models", "quasi-static,transient", *words,
                   "--setting", "stick_population=true", "--start", "transient=steady")  # fmt: skip
    transient, quasi = both["models"]["transient"], both["models"]["quasi-static"]
    assert transient["settings"] == {"stick_population": True} and quasi["settings"] == {}
    # the start the run made (round 29): below Vc the steady start slides just above Vc, not at 100 µm/s
    assert transient["start"].startswith("steady population at 124.2 µm/s, just above Vc")
    assert quasi["start"].startswith("first stick from σc")
    alone = ok_json(capsys, "run", "--model", "transient", *words, "--setting", "stick_population=true",
                    "--start", "steady")  # fmt: skip
    assert transient["peak_stress"] == pytest.approx(alone["peak_stress"], rel=1e-12)
    assert transient["mean_stress"] == pytest.approx(alone["mean_stress"], rel=1e-12)
    # without the stick chains the same transient run never lets the block go: the setting did reach it
    plain = ok_json(capsys, "compare", "--models", "quasi-static,transient", *words, "--start", "transient=steady")
    assert plain["models"]["transient"]["peak_stress"] != pytest.approx(transient["peak_stress"], rel=1e-3)


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (["--setting", "nonsense=1"], "--setting nonsense"),
        (["--start", "rsf=steady"], "rsf"),
        (["--every", "-1 s"], "--every"),
    ],
)
def test_settings_and_starts_no_model_takes_are_refused_in_one_line(capsys, argv, named):
    code, _, err = run_main(capsys, "compare", "--models", "quasi-static,transient", "--v0", "100 um/s",
                            "--duration", "1 s", *argv)  # fmt: skip
    assert code == 2 and err.count("\n") == 1 and named in err, err


def test_the_classic_compare_refuses_the_run_words(capsys):
    code, _, err = run_main(capsys, "compare", "--setting", "stick_population=true")
    assert code == 2 and "--setting" in err and err.count("\n") == 1, err


def test_each_model_names_the_spring_it_pulls_through_in_its_own_unit(capsys):
    """compare --models --json gave rig.stiffness null for every model whose spring came from its parameters, and
    one units map for all models, where the bond model's K is Pa/m and rate-and-state's k is 1/m.  Each model's rig
    and units are checked against the parameters themselves and against its own `stickslip run --json`."""
    from stickslip.models import get_model

    words = ["--v0", "50 um/s", "--duration", "5 s"]
    both = ok_json(capsys, "compare", "--models", "quasi-static,rsf", *words)
    quasi, rsf = both["models"]["quasi-static"], both["models"]["rsf"]
    own_k = load_parameters("gelatin-glass").block.effective_stiffness
    assert quasi["rig"]["stiffness"] == pytest.approx(own_k, rel=1e-12) and quasi["units"]["stiffness"] == "Pa/m"
    assert rsf["rig"]["stiffness"] == pytest.approx(get_model("rsf").parameters(None, {}).stiffness, rel=1e-12)
    assert rsf["units"]["stiffness"] == "1/m" and rsf["rig"]["stiffness_from"] == "parameters"
    for name, row in both["models"].items():
        alone = ok_json(capsys, "run", "--model", name, *words)
        assert row["rig"] == alone["rig"] and row["units"]["stiffness"] == alone["units"]["stiffness"]
    # springs in two units: none at the top, which says where they are
    assert both["rig"] == {"control": "spring", "stiffness": None, "stiffness_from": "each model"}
    # one spring given to both bond models: it is the top-level one too
    given = ok_json(capsys, "compare", "--models", "quasi-static,transient", *words, "--stiffness", "400 kPa/m")
    assert given["rig"] == {"control": "spring", "stiffness": 4e5, "stiffness_from": "rig"}
    assert given["units"]["stiffness"] == "Pa/m"
    assert all(row["rig"]["stiffness"] == 4e5 for row in given["models"].values())
