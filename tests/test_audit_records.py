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


def test_rsf_fit_mcmc_json_is_json_and_text_shows_the_posterior(step_record, capsys, monkeypatch):
    """--mcmc with a short chain: lmfit printed emcee's autocorrelation warning on stdout, before the JSON (which
    then did not parse), and the text report never showed the posterior it had computed.

    The fit (4 s, most of it the chain) runs once, in the --json run, where the stray print happened; the text run
    gets the same fit from fit_record and renders it (the same settings, so the same fit it would compute).  10
    steps, not 30: any chain this short draws emcee's warning (the print that broke the JSON), and the posterior
    lines are there or not whatever the length (both checked to fail: the print let through, the lines dropped)."""
    from stickslip.rsf import fit as rsf_fit

    fitted = []
    compute = rsf_fit.fit_record

    def fit_once(record, **settings):
        if not fitted:
            fitted.append((settings, compute(record, **settings)))
        assert settings == fitted[0][0]  # the text run asks for the very fit the --json run made
        return fitted[0][1]

    monkeypatch.setattr(rsf_fit, "fit_record", fit_once)
    args = ("rsf", "fit", str(step_record), "--stiffness", "1.6e-3 1/um", "--mcmc", "10", "--seed", "1")
    code, out, _ = run_main(capsys, *args, "--json")
    assert code == 0
    report = json.loads(out)
    post = report["posterior"]
    assert {"a", "b", "dc", "mu0"} <= set(post) and "autocorrelation" in post["warning"]
    code, out, _ = run_main(capsys, *args)
    assert code == 0
    assert "posterior (emcee, 10 steps" in out
    # (round 28: a chain this short has not mixed: its medians alone, no interval, and it says so)
    posterior = out[out.index("posterior (emcee, 10 steps") :]
    assert "NOT CONVERGED" in posterior
    line = next(x for x in posterior.splitlines() if x.strip().startswith("dc"))
    assert "µm" in line and "95 %" not in line  # in the record's unit, as the values above it
    assert "warning: posterior:" in out


@pytest.mark.parametrize(
    ("line", "column", "value", "said"),
    [(11, 0, "0.001", "row 11: time 0.001 s does not increase"), (21, 1, "inf", "row 21: friction is not a finite")],
)
def test_rsf_fit_names_the_file_row_of_a_bad_sample(tmp_path, capsys, line, column, value, said):
    """A bad row of a record was named by its index among the data rows (row 9 for line 11 of a Run CSV, whose
    metadata and header lines come first), not by its line, as the package's other readers (analyze, fit steady,
    protocols) name it.  (An infinite friction is still refused; an empty or NaN cell is a dropped sample, left
    out with a note: tests/test_rsf_fit_jitter_and_short_pieces.py.)"""
    params = rsf_params(0.005, 0.01, 20 * UM, v_ref=UM, stiffness=1600.0)
    run = simulate(params, protocols.velocity_steps([UM, 10 * UM], [5, 5]), every=0.05)
    path = tmp_path / "trace.csv"
    frame = run.to_frame()
    text = "# a comment line\n" + frame.to_csv(index=False, header=[f"{c} [{frame.attrs['units'][c]}]" for c in frame])
    lines = text.splitlines()
    cells = lines[line - 1].split(",")
    cells[column] = value
    lines[line - 1] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    code, _, err = run_main(capsys, "rsf", "fit", str(path))
    assert code == 2 and said in err, err


def test_analyze_json_names_the_units_of_its_own_keys(tmp_path, capsys):
    """The JSON of a steady record called the stress trend ``stress_slope`` "Pa s/m" (the registry's unit of the
    steady curve's dsigma/dV) though it is a trend in time, Pa/s; noise, the drop threshold, the steady window and
    the stress scatter had no unit at all."""
    t = np.arange(0.0, 60.0, 0.01)
    stress = 400.0 + 0.02 * t + np.random.default_rng(0).normal(0.0, 1.0, t.size)
    path = tmp_path / "steady.csv"
    pd.DataFrame({"time [s]": t, "stress [Pa]": stress}).to_csv(path, index=False)
    code, out, _ = run_main(capsys, "analyze", str(path), "--v0", "350 um/s", "--json")
    assert code == 0
    report = json.loads(out)
    assert report["summary"]["stress_slope"] == pytest.approx(0.02, abs=0.005)
    units = report["units"]
    assert units["stress_slope"] == "Pa/s"
    for key in ("noise", "drop_threshold", "stress_std", "stress_sem", "mean_stress"):
        assert units[key] == "Pa", key
    assert units["steady_from"] == units["steady_to"] == "s"


def test_fit_steady_on_a_flat_record_has_finite_residuals(tmp_path, capsys):
    """A steady curve whose stresses are all equal (a logger at its resolution): the failed fit's residuals were
    0/0 = NaN ("+nan" in the report's table, NaN in to_frame) because the noise scale from the scatter is 0."""
    from stickslip.fitting import fit_steady

    path = tmp_path / "flat.csv"
    pd.DataFrame({"velocity [m/s]": np.geomspace(1e-4, 1e-2, 10), "stress [Pa]": 300.0}).to_csv(path, index=False)
    fit = fit_steady(path)
    assert fit.status == "failed" and np.all(np.isfinite(fit.residuals))
    assert np.isfinite(fit.to_frame()["residual"]).all()
    code, out, _ = run_main(capsys, "fit", "steady", str(path))
    assert code == 3 and "nan" not in out.lower()


def test_rsf_stability_json_names_rate_and_state_spring_in_its_unit(capsys):
    """rsf stability --json said the spring was in Pa/m (the bond model's unit) while it holds friction per slip,
    k = K/sigma in 1/m (3e9 Pa/m at 30 MPa: 100 1/m), and gave k_c in Pa/m no unit."""
    code, out, _ = run_main(
        capsys, "rsf", "stability", "--velocity", "1 um/s", "--a", "0.01", "--b", "0.02", "--dc", "10 um",
        "--stiffness", "3e9 Pa/m", "--normal-stress", "30 MPa", "--json",
    )  # fmt: skip
    assert code == 0
    document = json.loads(out)
    assert document["stiffness"] == pytest.approx(100.0)
    assert document["units"]["stiffness"] == "1/m" and document["units"]["critical_stiffness"] == "1/m"
    assert document["units"]["critical_stiffness_pa"] == "Pa/m"
    # k_c = sigma (b - a) / Dc in Pa/m, the closed form of the aging law's spring-slider (docs/rsf.md)
    assert document["critical_stiffness_pa"] == pytest.approx(30e6 * 0.01 / 10e-6, rel=1e-9)


def test_headers_with_units_in_parentheses_are_read_and_converted(tmp_path, capsys):
    """``velocity (um/s),stress (Pa)`` (spreadsheets, lab software) was refused by fit steady and analyze ("cannot
    read header"), while rsf fit read it; the same curve with ``[um/s]`` was read.  Both now give the same fit, and the
    unit is converted (a curve in mm/s with the velocities a thousandth: the same fit)."""
    from stickslip.fitting import fit_steady

    shipped = pd.read_csv("src/stickslip/data/synthetic_steady.csv", comment="#")
    v, s = shipped["velocity [um/s]"].to_numpy(), shipped["stress [Pa]"].to_numpy()
    paths = {}
    for name, header, scale in (("brackets", "velocity [um/s]", 1.0), ("parens", "velocity (um/s)", 1.0),
                                ("mm", "velocity (mm/s)", 1e-3)):  # fmt: skip
        paths[name] = tmp_path / f"{name}.csv"
        pd.DataFrame({header: v * scale, "stress (Pa)": s}).to_csv(paths[name], index=False)
    fits = {name: fit_steady(path) for name, path in paths.items()}
    assert fits["brackets"].status == "ok"
    for name in ("parens", "mm"):
        assert fits[name].status == fits["brackets"].status
        assert fits[name].critical_velocity.value == pytest.approx(fits["brackets"].critical_velocity.value, rel=1e-9)
    trace = tmp_path / "trace.csv"
    t = np.arange(0.0, 30.0, 0.01)
    pd.DataFrame({"time (s)": t, "stress (kPa)": 0.4 + 1e-5 * t}).to_csv(trace, index=False)
    code, out, _ = run_main(capsys, "analyze", str(trace), "--v0", "350 um/s", "--json")
    assert code == 0
    assert json.loads(out)["summary"]["stick_slope"]["mean"] == pytest.approx(0.01, rel=1e-6)  # 1e-5 kPa/s in Pa/s
