"""Round-28 rate-and-state defects: the units of a fit's parameters file, the noise a ringing rig's fit is judged by,
and a posterior from a chain too short to have mixed.

The records are made by an independent spring-slider (scipy's LSODA on ln V and ln theta, aging law), not by the
package's solver, so the truths below are the simulation's own."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from cli_helpers import run_main
from stickslip import protocols
from stickslip.rsf.data import LabRecord
from stickslip.rsf.fit import fit_record

UM = 1e-6
A, B, DC, K, MU0, V0 = 0.008, 0.011, 5e-6, 2000.0, 0.6, 1e-6  # k = 3.3 k_c: an underdamped rig that rings


def spring_slider(history: list[tuple[float, float]], fs: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(time s, load point m, friction) of the aging-law spring-slider, steady at the first velocity at t = 0."""
    y = [math.log(history[0][0]), math.log(DC / history[0][0])]
    times, points, friction = [], [], []
    start = point = 0.0
    for velocity, duration in history:

        def rhs(t: float, y: list[float], v: float = velocity) -> list[float]:
            slip_rate, theta = math.exp(y[0]), math.exp(y[1])
            dlog_theta = (1.0 - slip_rate * theta / DC) / theta
            return [(K * (v - slip_rate) - B * dlog_theta) / A, dlog_theta]

        t = start + np.arange(round(duration * fs)) / fs
        sol = solve_ivp(rhs, (start, start + duration), y, method="LSODA", rtol=1e-10, atol=1e-12, dense_output=True)
        ys = sol.sol(t)
        times.append(t)
        points.append(point + velocity * (t - start))
        friction.append(MU0 + A * (ys[0] - math.log(V0)) + B * (math.log(V0 / DC) + ys[1]))
        y, start, point = sol.y[:, -1], start + duration, point + velocity * duration
    return np.concatenate(times), np.concatenate(points), np.concatenate(friction)


def ar1(size: int, sd: float, phi: float, seed: int) -> np.ndarray:
    """Stationary AR(1) noise of standard deviation ``sd`` and lag-one correlation ``phi``."""
    rng = np.random.default_rng(seed)
    kicks = rng.normal(0.0, sd * math.sqrt(1.0 - phi**2), size)
    out = np.empty(size)
    out[0] = rng.normal(0.0, sd)
    for i in range(1, size):
        out[i] = phi * out[i - 1] + kicks[i]
    return out


# --- D1: the parameters file's units -----------------------------------------------------------------------------

HISTORY_D1 = [(1 * UM, 10.0), (10 * UM, 10.0), (1 * UM, 10.0)]


@pytest.fixture(scope="module")
def d1_record(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, np.ndarray, np.ndarray]:
    """A 100 Hz record (time s, displacement um, friction with white noise 2e-4), and its noise-free truth."""
    t, x, f = spring_slider(HISTORY_D1, 100.0)
    noisy = f + 2e-4 * np.random.default_rng(5).standard_normal(t.size)
    path = tmp_path_factory.mktemp("d1") / "steps.txt"
    np.savetxt(path, np.c_[t, x / UM, noisy], fmt=["%.3f", "%.5f", "%.6f"], delimiter="\t",
               header="Time(s)\tDispl(microns)\tFriction", comments="")  # fmt: skip
    return path, t, f


def _same(unit: str) -> str:
    return {"1": "dimensionless"}.get(unit, unit)


def _friction(csv: Path) -> tuple[np.ndarray, np.ndarray]:
    """(time, friction) of a Run CSV (its first line a '#' comment, then a header naming each column's unit)."""
    lines = [line for line in csv.read_text(encoding="utf-8").splitlines() if not line.startswith("#")]
    names = lines[0].split(",")
    assert names[0] == "time [s]" and names[1] == "friction [1]", names
    data = np.array([[float(v) for v in line.split(",")[:2]] for line in lines[1:]])
    return data[:, 0], data[:, 1]


def test_the_fits_files_name_one_unit_for_each_value_and_rerun_the_record(d1_record, tmp_path, capsys):
    """The fit's NAME.params.json said "stiffness": "Pa/m" beside 2002.1 in its top-level units (the package's
    registry, the bond model's spring), while the value is friction per metre of slip: its own ``fit.units``, the
    TOML header and `rsf simulate -o` say 1/m.  Every unit the files name now agrees, and both files rerun the
    record's noise-free friction through `rsf simulate --params` and `run --model rsf --params`."""
    path, t, truth = d1_record
    toml, as_json = tmp_path / "fit.toml", tmp_path / "fit.json"
    for output in (toml, as_json):
        code, _, err = run_main(capsys, "rsf", "fit", str(path), "-o", str(output))
        assert code == 0, err
    side = tmp_path / "fit.params.json"
    documents = [json.loads(side.read_text(encoding="utf-8")), json.loads(as_json.read_text(encoding="utf-8"))]
    expected = {"stiffness": "1/m", "dc": "m", "v_ref": "m/s", "eta": "s/m", "mass": "kg/m^2", "a": "1", "b": "1",
                "mu0": "1", "c": "1", "start_velocity": "m/s", "velocity": "m/s", "duration": "s"}  # fmt: skip
    for doc in documents:
        units, report = doc["units"], doc["fit"]
        assert {k: units.get(k) for k in expected} == expected
        for key, unit in report["units"].items():  # the report's own block (its words: record_length_unit, note)
            if key in units:
                assert _same(units[key]) == _same(unit), key
        for key, entry in report["parameters"].items():
            if key in units:
                assert _same(units[key]) == _same(entry["unit"]), key
        # the value is friction per metre: 2000 1/m within its interval's reach, not a Pa/m (it would be x sigma)
        assert doc["parameters"]["stiffness"] == pytest.approx(K, rel=0.05)
    header = toml.read_text(encoding="utf-8")
    assert "stiffness in 1/m" in header and "eta in s/m" in header and "mass in kg/m^2" in header
    reruns = []
    for command in (("rsf", "simulate"), ("run", "--model", "rsf")):
        for source in (side, as_json):
            csv = tmp_path / f"{command[0]}-{source.stem}.csv"
            code, _, err = run_main(capsys, *command, "--params", str(source), "--every", "0.01 s", "-o", str(csv))
            assert code == 0, err
            time, friction = _friction(csv)
            reruns.append(np.interp(t, time, friction))
            if command[0] == "rsf":  # (`run` writes no parameters beside its trace)
                written = json.loads(csv.with_name(csv.stem + ".params.json").read_text(encoding="utf-8"))
                assert written["parameters"]["stiffness"] == pytest.approx(documents[0]["parameters"]["stiffness"])
                assert "stiffness 1/m" in written["units"]
    for rerun in reruns:  # the record's own friction without its noise: within a few noise levels everywhere
        assert np.max(np.abs(rerun - truth)) < 1.5e-3
        assert np.sqrt(np.mean((rerun - truth) ** 2)) < 2e-4
    # the TOML has no history: rerun with the record's own, it gives the same friction
    segments = [word for v, d in HISTORY_D1[1:] for word in ("--segment", f"{v / UM:g} um/s:{d:g} s")]
    csv = tmp_path / "toml.csv"
    code, _, err = run_main(capsys, "rsf", "simulate", "--params", str(toml), "--v0", "1 um/s", "--duration", "10 s",
                            *segments, "--every", "0.01 s", "-o", str(csv))  # fmt: skip
    assert code == 0, err
    time, friction = _friction(csv)
    assert np.max(np.abs(np.interp(t, time, friction) - reruns[0])) < 1e-5


# --- D2: the noise a ringing rig's fit is judged by -------------------------------------------------------------

HISTORY_D2 = [(1 * UM, 8.0), (10 * UM, 8.0)]


@pytest.mark.parametrize("seed", [1, 2])
def test_a_ringing_rigs_fit_is_judged_by_the_records_own_noise(seed):
    """k = 3.3 k_c: steady sliding after a step decays at V (k - k_c) / (2 a), one e-fold per 2.3 Dc / V, so 5 Dc / V
    after the step to 10 um/s it still rang at a tenth of its amplitude; at 100 Hz with correlated noise (lag-one
    correlation 0.9) the noise's second differences level off only at lags of 0.3-1.3 s, where that ringing counted
    as noise: 1.75x the true level (chi-square_r 0.31, so a model misfitting up to chi-square_r ~3 would pass).  The
    rows left out now follow the fitted rig's own decay time."""
    t, x, f = spring_slider(HISTORY_D2, 100.0)
    noise = ar1(t.size, 3e-4, 0.9, seed)
    rng = np.random.default_rng(seed + 10)
    record = LabRecord.from_arrays(t, x + 1e-9 * rng.standard_normal(t.size), f + noise, source="ringing",
                                   length_unit="um")  # fmt: skip
    history = protocols.velocity_steps([v for v, _ in HISTORY_D2], [d for _, d in HISTORY_D2])
    fit = fit_record(record, protocol=history, drift_check=False, alternatives=False)
    assert fit.status == "ok", fit.reason
    true_level = float(np.std(noise))
    assert fit.rms == pytest.approx(true_level, rel=0.1)  # the model follows the truth: its residuals are the noise
    assert 0.8 < fit.noise / true_level < 1.2, fit.noise_method
    assert 0.7 < fit.reduced_chi_square < 1.5


# --- D3: a posterior from a chain too short to have mixed --------------------------------------------------------

HISTORY_D3 = [(1 * UM, 10.0), (10 * UM, 10.0)]


@pytest.fixture(scope="module")
def d3_record() -> LabRecord:
    t, x, f = spring_slider(HISTORY_D3, 50.0)
    rng = np.random.default_rng(8)
    return LabRecord.from_arrays(t, x, f + 2e-4 * rng.standard_normal(t.size), source="d3", length_unit="um")


def _d3_fit(record: LabRecord, steps: int) -> object:
    history = protocols.velocity_steps([v for v, _ in HISTORY_D3], [d for _, d in HISTORY_D3])
    return fit_record(record, protocol=history, fixed={"stiffness": K}, mcmc_steps=steps, seed=1,
                      drift_check=False, alternatives=False)  # fmt: skip


def test_a_chain_too_short_to_mix_gives_no_interval_and_says_so(d3_record):
    """--mcmc 30 gave a's 95 % posterior 4x narrower than the least-squares interval and Dc's excluding the truth,
    under emcee's generic autocorrelation warning: the walkers started within 1e-4 of each value.  A chain short of
    50 autocorrelation times after its burn-in now gives no interval, says NOT CONVERGED and how many steps would do."""
    fit = _d3_fit(d3_record, 12)
    post = fit.posterior
    assert post["converged"] is False
    assert post["warning"].startswith("NOT CONVERGED")
    for key in ("mu0", "a", "b", "dc"):
        assert post[key]["interval"] is None
        assert fit.parameters[key].interval is not None  # the least-squares intervals stand
    # the walkers start as wide as the least-squares covariance: even so short a chain is about as wide
    lo, hi = post["a"]["unconverged_percentiles"]
    ls_lo, ls_hi = fit.parameters["a"].interval
    assert 0.4 < (hi - lo) / (ls_hi - ls_lo) < 2.0


def test_a_mixed_chains_intervals_agree_with_least_squares_and_hold_the_truth(d3_record):
    """Started from the least-squares covariance with independence and differential-evolution moves (as fit steady
    --bayes), a few hundred steps mix: converged, with intervals as wide as the least-squares ones (white noise, a
    near-Gaussian posterior) and holding the simulation's a, b and Dc."""
    fit = _d3_fit(d3_record, 240)
    post = fit.posterior
    assert post["converged"] is True, post.get("warning")
    for key, truth in (("a", A), ("b", B), ("dc", DC)):
        lo, hi = post[key]["interval"]
        ls_lo, ls_hi = fit.parameters[key].interval
        assert lo < truth < hi, key
        assert 0.6 < (hi - lo) / (ls_hi - ls_lo) < 1.6, key


def test_the_cli_says_an_unmixed_posterior_and_prints_no_interval_for_it(d1_record, capsys):
    """`rsf fit --mcmc N` short of mixing: the text gives medians only under NOT CONVERGED, stderr says it, and the
    JSON's intervals are null; the exit status is 0, as `fit steady --bayes --steps N` (the fit itself stands)."""
    path, _, _ = d1_record
    code, out, err = run_main(capsys, "rsf", "fit", str(path), "--fix", "stiffness=2e-3/um", "--mcmc", "10", "--seed",
                              "1")  # fmt: skip
    assert code == 0, err
    assert "NOT CONVERGED" in out and "NOT CONVERGED" in err
    block = out[out.index("posterior (") :].splitlines()
    assert not any("95 %" in line for line in block[1:5])
