"""Audit of records and fits as a user chains them: what broke on real-looking input, each with its fix."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from cli_helpers import run_main
from stickslip import protocols
from stickslip.rsf import rsf_params, simulate

UM = 1e-6


@pytest.fixture(scope="module")
def step_record(tmp_path_factory):
    """1 -> 10 um/s at 4 Hz (161 rows) with friction noise 1e-4, displacement in um."""
    params = rsf_params(0.010, 0.015, 10 * UM, v_ref=UM, stiffness=1600.0, mu0=0.6)
    t = np.arange(0.0, 40.0 + 1e-9, 0.25)
    run = simulate(params, protocols.velocity_steps([1 * UM, 10 * UM], [20, 20]), times=t)
    rng = np.random.default_rng(3)
    frame = pd.DataFrame({
        "time [s]": t,
        "load_point_displacement [um]": run.load_point_displacement / UM,
        "friction": run.friction + 1e-4 * rng.standard_normal(t.size),
    })  # fmt: skip
    path = tmp_path_factory.mktemp("audit-records") / "record.csv"
    frame.to_csv(path, index=False)
    return path


def test_rsf_fit_mcmc_json_is_json_and_text_shows_the_posterior(step_record, capsys):
    """--mcmc with a short chain: lmfit printed emcee's autocorrelation warning on stdout, before the JSON (which
    then did not parse), and the text report never showed the posterior it had computed."""
    args = ("rsf", "fit", str(step_record), "--stiffness", "1.6e-3 1/um", "--mcmc", "30", "--seed", "1")
    code, out, _ = run_main(capsys, *args, "--json")
    assert code == 0
    report = json.loads(out)
    post = report["posterior"]
    assert {"a", "b", "dc", "mu0"} <= set(post) and "autocorrelation" in post["warning"]
    code, out, _ = run_main(capsys, *args)
    assert code == 0
    assert "posterior (emcee, 30 steps" in out
    line = next(x for x in out.splitlines() if x.strip().startswith("dc") and "95 %" in x and "±" not in x)
    assert "µm" in line  # in the record's unit, as the values above it
    assert "warning: posterior:" in out
