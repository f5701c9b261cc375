"""One protocol vocabulary for every model's run command (issue 20 item 4).

``simulate`` (quasi-static), ``transient`` and ``rsf simulate`` all take ``--v0 V --duration T``,
``--segment "V:T"`` (repeatable), ``--protocol FILE``, ``--stiffness K`` and ``--control spring|velocity``;
a model that cannot run what was asked refuses it in one line (exit 2).  Each spelling of one protocol must
give the same run as the others; a stiffness must reach the model (checked against the same stiffness set
through the block's height, a route that does not pass through --stiffness).
"""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from cli_helpers import run, run_main
from stickslip.fitting.datasets import data_path
from stickslip.parameters import load_parameters
from stickslip.units import to_si

RSF = ["rsf", "simulate", "--a", "0.005", "--b", "0.01", "--dc", "10 um", "--every", "1 s", "--json"]


def summary(*args: str) -> dict:
    return json.loads(run(CliRunner(), *args))


def one_segment_file(tmp_path, velocity: float, duration: float):
    path = tmp_path / "one.csv"
    path.write_text(f"velocity,duration\n{velocity!r},{duration!r}\n", encoding="utf-8")
    return path


def two_segment_file(tmp_path):
    path = tmp_path / "two.csv"
    v0, v1 = to_si("350 um/s", "velocity"), to_si("1 mm/s", "velocity")
    path.write_text(f"time,velocity\n0,{v0!r}\n0.004,{v1!r}\n0.008,0\n", encoding="utf-8")
    return path


# ----------------------------------------------------------------------------- simulate (quasi-static)
def test_simulate_takes_each_word_of_the_vocabulary(tmp_path):
    base = summary("simulate", "--v0", "50 um/s", "--duration", "60 s", "--json")
    assert base["regime"] == "stick-slip"
    assert summary("simulate", "--segment", "50 um/s:60 s", "--json") == base
    v0 = to_si("50 um/s", "velocity")  # the float the option gives, to the last bit
    assert summary("simulate", "--protocol", str(one_segment_file(tmp_path, v0, 60.0)), "--json") == base
    assert summary("simulate", "--v0", "50 um/s", "--duration", "60 s", "--control", "spring", "--json") == base


def test_simulate_stiffness_is_the_block_of_that_stiffness():
    block = load_parameters("gelatin-glass").block
    k = 600e3  # Pa/m, about twice the gel block's 306.5 kPa/m
    height = block.shear_modulus * block.geometric_factor / k
    given = summary("simulate", "--v0", "50 um/s", "--duration", "60 s", "--stiffness", "600 kPa/m", "--json")
    through_block = summary("simulate", "--v0", "50 um/s", "--duration", "60 s", "--set",
                            f"block.height={height!r} m", "--json")  # fmt: skip
    assert given["effective_stiffness"] == pytest.approx(k, rel=1e-12)
    assert given["cycles"] == through_block["cycles"]
    default = summary("simulate", "--v0", "50 um/s", "--duration", "60 s", "--json")
    assert given["cycles"][0]["stick_time"] < 0.6 * default["cycles"][0]["stick_time"]  # a stiffer spring loads faster


# ----------------------------------------------------------------------------- transient
VELOCITY_STEP = ["--control", "velocity", "--start", "steady", "--rtol", "1e-3"]


def test_transient_takes_each_word_of_the_vocabulary(tmp_path):
    base = summary("transient", *VELOCITY_STEP, "--v0", "350 um/s", "--duration", "4 ms", "--segment", "1 mm/s:4 ms",
                   "--json")  # fmt: skip
    alone = summary("transient", *VELOCITY_STEP, "--segment", "350 um/s:4 ms", "--segment", "1 mm/s:4 ms", "--json")
    from_file = summary("transient", *VELOCITY_STEP, "--protocol", str(two_segment_file(tmp_path)), "--json")
    assert alone == base and from_file == base
    assert base["final_stress"] > 0


def test_transient_spring_is_the_old_block_and_its_stiffness_reaches_the_solver():
    spring = ["transient", "--v0", "50 um/s", "--duration", "0.05 s", "--rtol", "1e-3", "--json"]
    assert summary(*spring, "--control", "block") == summary(*spring, "--control", "spring") == summary(*spring)
    k_block = load_parameters("gelatin-glass").block.effective_stiffness
    given = summary(*spring, "--stiffness", f"{k_block!r} Pa/m")
    assert given.pop("rig") == {"control": "spring", "stiffness": pytest.approx(k_block, rel=1e-14),
                                "stiffness_from": "rig"}  # as given  # fmt: skip
    assert given == {key: value for key, value in summary(*spring).items() if key != "rig"}
    # from rest the load rises as K V0 t while the slider barely moves: the stress scales with K
    stiffer = summary(*spring, "--stiffness", f"{2 * k_block!r} Pa/m")
    assert stiffer["final_stress"] == pytest.approx(2 * summary(*spring)["final_stress"], rel=0.02)


# ----------------------------------------------------------------------------- rsf simulate
def test_rsf_simulate_takes_v0_and_duration_like_the_others(tmp_path):
    spring = ["--stiffness", "1e-3 1/um"]
    base = summary(*RSF, *spring, "--segment", "1 um/s:10 s", "--segment", "10 um/s:30 s")
    assert summary(*RSF, *spring, "--v0", "1 um/s", "--duration", "10 s", "--segment", "10 um/s:30 s") == base
    path = tmp_path / "rsf.csv"
    v0, v1 = to_si("1 um/s", "velocity"), to_si("10 um/s", "velocity")
    path.write_text(f"velocity,duration\n{v0!r},10\n{v1!r},30\n", encoding="utf-8")
    assert summary(*RSF, *spring, "--protocol", str(path)) == base
    assert summary(*RSF, *spring, "--control", "spring", "--v0", "1 um/s", "--duration", "10 s",
                   "--segment", "10 um/s:30 s") == base  # fmt: skip
    # a stiffer spring (2000 1/m, still above kc = 500 1/m: a softer one runs away, a failed run) rings otherwise
    stiffer = summary(*RSF, "--stiffness", "2e-3 1/um", "--segment", "1 um/s:10 s", "--segment", "10 um/s:30 s")
    assert stiffer["final_friction"] != base["final_friction"]


# ----------------------------------------------------------------------------- refusals
REFUSALS = [
    (["simulate", "--v0", "50 um/s", "--duration", "60 s", "--control", "velocity"], "--control velocity"),
    (["simulate", "--v0", "50 um/s", "--duration", "60 s", "--segment", "1 mm/s:1 s"], "one constant velocity"),
    (["simulate", "--protocol", str(data_path("slide-hold-slide.csv"))], "one constant velocity"),
    (["simulate", "--v0", "50 um/s"], "--v0 needs --duration"),
    (["simulate", "--duration", "50 s"], "--duration needs --v0"),
    (["simulate"], "give the protocol"),
    (["simulate", "--v0", "50 um/s", "--duration", "6 s", "--stiffness", "300"], "--stiffness 300"),
    (
        ["transient", "--control", "velocity", "--v0", "50 um/s", "--duration", "1 s", "--stiffness", "1 MPa/m"],
        "--stiffness",
    ),
    (["transient", "--protocol", str(data_path("slide-hold-slide.csv")), "--v0", "1 um/s"], "--protocol"),
    ([*RSF, "--v0", "1 um/s", "--duration", "10 s", "--control", "velocity"], "--control velocity"),
    ([*RSF, "--protocol", str(data_path("slide-hold-slide.csv")), "--segment", "1 um/s:1 s"], "--protocol"),
    ([*RSF], "give the protocol"),
]


@pytest.mark.parametrize(("argv", "named"), REFUSALS, ids=lambda x: " ".join(x) if isinstance(x, list) else x)
def test_what_a_model_cannot_run_is_refused_in_one_line(argv, named, capsys):
    code, out, err = run_main(capsys, *argv)
    assert code == 2 and out == ""
    assert err.startswith("stickslip: error:") and err.count("\n") == 1
    assert named in err
