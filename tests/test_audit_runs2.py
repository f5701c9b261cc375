"""Audit of the runs' summaries and JSON: the spring the run used, the mean over the run, a run shorter than its
relaxation (``stickslip run`` and ``rsf simulate``, as a user reads them)."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from cli_helpers import run
from stickslip.parameters import load_parameters

QS = ["run", "--model", "quasi-static", "--duration", "2 s"]
RSF = ["--v0", "1 um/s", "--duration", "10 s", "--segment", "10 um/s:30 s"]


def as_json(*args: str) -> dict:
    return json.loads(run(CliRunner(), *args, "--json"))


def test_the_json_gives_the_spring_the_run_used_with_its_unit_and_source():
    k_block = load_parameters("gelatin-glass").block.effective_stiffness  # Eq 17's K, 306.5 kPa/m
    own = as_json(*QS, "--v0", "100 um/s")
    assert own["rig"] == {"control": "spring", "stiffness": pytest.approx(k_block, rel=1e-14),
                          "stiffness_from": "parameters"}  # fmt: skip
    assert own["units"]["stiffness"] == "Pa/m"
    assert "K = 306.495 kPa/m from the parameters" in run(CliRunner(), *QS, "--v0", "100 um/s")
    given = as_json(*QS, "--v0", "100 um/s", "--stiffness", "400 kPa/m")
    assert given["rig"] == {"control": "spring", "stiffness": 4e5, "stiffness_from": "rig"}  # as given: the rig
    # rate-and-state's spring is friction per slip: 1/m, from its k or from the rig's K over the normal stress
    out = as_json("run", "--model", "rsf", *RSF, "--set", "k=1000 1/m")
    assert out["rig"] == {"control": "spring", "stiffness": pytest.approx(1000.0), "stiffness_from": "parameters"}
    assert out["units"]["stiffness"] == "1/m"
    by_rig = as_json("run", "--model", "rsf", *RSF, "--set", "normal_stress=10 MPa", "--stiffness", "10 GPa/m")
    assert by_rig["rig"] == {"control": "spring", "stiffness": pytest.approx(1000.0), "stiffness_from": "rig"}
    assert by_rig["units"]["stiffness"] == "1/m"


def test_rsf_simulate_json_gives_its_spring_in_friction_per_slip(tmp_path):
    out = json.loads(run(CliRunner(), "rsf", "simulate", *RSF, "--stiffness", "2e-3 1/um", "-o",
                         str(tmp_path / "r.csv"), "--json"))  # fmt: skip
    # --stiffness set k: the stiffness came from the option, not the parameter set (one vocabulary with run)
    assert out["rig"] == {"control": "spring", "stiffness": pytest.approx(2000.0), "stiffness_from": "rig"}
    assert out["units"]["stiffness"] == "1/m"


def test_a_run_shorter_than_its_relaxation_says_so_and_means_over_itself():
    # 200 um/s > Vc: heading for steady sliding, but the 2 s run is all in the first stick (sigma linear in t)
    text = run(CliRunner(), *QS, "--v0", "200 um/s")
    out = as_json(*QS, "--v0", "200 um/s")
    low, high = out["trough_stress"], out["peak_stress"]
    assert out["regime"] == "steady" and high > low
    assert out["run_mean_stress"] == pytest.approx((low + high) / 2, rel=1e-9)  # the mean of the 2 s it covers
    assert out["units"]["run_mean_stress"] == "Pa"
    assert out["mean_stress"] == pytest.approx(299.706, abs=1e-3)  # sigma(V0): a sweep row's mean, as documented
    assert f"mean {out['run_mean_stress']:.6g} Pa over the run" in text
    assert f"mean {out['mean_stress']:.6g} Pa" not in text
    assert "the run ends at 2 s, still stuck, before it settles at t = 51.56" in out["message"]
    assert "the run ends at" in text
    longer = as_json(*QS[:-2], "--duration", "200 s", "--v0", "200 um/s")
    assert "the run ends" not in longer["message"]  # settled at 51.6 s, within the run


def test_a_cycle_not_yet_whole_is_not_summarised_by_the_cycles_mean():
    # 100 um/s < Vc: stick-slip of period 15.3 s; a 2 s run holds no whole cycle, its stress 257 -> 319 Pa
    text = run(CliRunner(), *QS, "--v0", "100 um/s")
    out = as_json(*QS, "--v0", "100 um/s")
    assert out["periods_seen"] == 0
    assert out["trough_stress"] < out["run_mean_stress"] < out["peak_stress"]
    assert "no whole cycle within the run" in text
    assert f"mean {out['run_mean_stress']:.6g} Pa over the run" in text
    assert f"mean {out['mean_stress']:.6g}" not in text  # the repeating cycle's 383.7 Pa, above the run's peak


def test_rsf_summary_mean_is_over_the_run():
    out = as_json("run", "--model", "rsf", *RSF)
    text = run(CliRunner(), "run", "--model", "rsf", *RSF)
    assert not out["oscillates"]
    assert f"mean {out['run_mean_friction']:.6g} over the run" in text
    assert out["units"]["run_mean_friction"] == "1"


def test_the_rigs_mass_and_damping_have_their_units_in_the_json():
    out = as_json("run", "--model", "rsf", *RSF, "--set", "normal_stress=10 MPa", "--mass", "1e8 kg/m^2",
                  "--damping", "1 MPa s/m")  # fmt: skip
    assert out["rig"]["mass"] == 1e8 and out["rig"]["damping"] == 1e6
    assert out["units"]["mass"] == "kg/m^2" and out["units"]["damping"] == "Pa s/m"
