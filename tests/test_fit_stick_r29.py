"""fit stick, round 29 (tester T): start stresses moved by a sensor's drift or offset, a cycles table without its
critical_stress columns, and the bond parameters' uncertainty in the intervals (docs/fitting.md, "Stick phase").

The stick tables are built here from the independent solver (`stick_phase`) at a known parameter set, each stick
starting at the set's own σc; the sensor's drift or offset is added to the start stresses only (the stick times are
differences of times, which neither moves).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from scipy.constants import Boltzmann

from stickslip.cli.main import cli
from stickslip.errors import ParameterError
from stickslip.fitting.data import read_stick_data
from stickslip.fitting.stick_fit import fit_stick
from stickslip.parameters import load_parameters
from stickslip.quasistatic.critical import critical_point
from stickslip.quasistatic.stick import stick_phase

#: The tester's gel (its truth.toml): the stick parameters a fit must recover.
TRUTH_TOML = """
name = "hydrogel-T"
[bonds]
site_density = "1.4e14 1/m^2"
bond_time = "250 us"
breakage_weight = 1.0
chain_stiffness = "1e-4 N/m"
activation_length = "1 angstrom"
temperature = "293.15 K"
max_extension = "1.074 um"
[aging]
aging_time = "1.0 ms"
aging_velocity = "300 um/s"
[stick]
attached_chains = "2.4e12 1/m^2"
break_rate = "1.8e-4 1/s"
aging_time = "7 s"
[block]
shear_modulus = "6 kPa"
height = "8 mm"
top_length = "40 mm"
base_length = "25 mm"
"""
TRUTH = {"stick.attached_chains": 2.4e12, "stick.break_rate": 1.8e-4, "stick.aging_time": 7.0}
#: Start values of the steady fit and its data: the tester's mygel-start and its drift-free steady curve of the
#: gel above (analyze's mean stress of each record, 150 µm/s to 2 mm/s).
START_TOML = TRUTH_TOML.replace('"1.4e14', '"1.22e14').replace('"250 us', '"224 us').replace(
    'aging_time = "1.0 ms"', 'aging_time = "899 us"').replace('"300 um/s"', '"360 um/s"')  # fmt: skip
STEADY_CSV = """velocity [um/s],stress [Pa],stress_err [Pa]
150,313.7856,0.0144
200,356.5216,0.0142
300,434.7122,0.0140
500,562.8005,0.0137
800,709.5231,0.0133
1200,848.9305,0.0132
2000,1009.6773,0.0131
"""
VELOCITIES = (20e-6, 35e-6, 50e-6, 70e-6, 90e-6)


@pytest.fixture(scope="module")
def truth_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("r29") / "truth.toml"
    path.write_text(TRUTH_TOML)
    return path


@pytest.fixture(scope="module")
def exact_times(truth_file):
    """sigma_c of the set, and each velocity's stick time from sigma_c at K V0 (the independent solver)."""
    params = load_parameters(truth_file)
    sigma_c = critical_point(params).stress
    return sigma_c, {v: stick_phase(params, v, start_stress=sigma_c).stick_time for v in VELOCITIES}


def cycles_frame(exact_times, drift=0.0, offset=0.0, cycles=5, seed=1, time_noise=3e-4, start_noise=0.03):
    """A stacked cycles table as analyze -o writes it (its columns; no stick_slope: the sticks load at K V0), the
    records' forces off by ``offset`` Pa plus ``drift`` Pa/s from each record's start."""
    sigma_c, times = exact_times
    rng = np.random.default_rng(seed)
    rows = []
    for v, ts in times.items():
        for k in range(cycles):
            start = 30.0 + k * (ts + 3.0)
            measured = ts * math.exp(rng.normal(0, time_noise))
            rows.append({
                "pulling_velocity [m/s]": v, "cycle [1]": k + 1, "complete [1]": 1, "start_time [s]": start,
                "peak_time [s]": start + measured, "end_time [s]": start + measured + 3.0,
                "critical_stress [Pa]": sigma_c + offset + drift * start + rng.normal(0, start_noise),
                "stick_time [s]": measured, "period [s]": ts + 3.0,
            })  # fmt: skip
    return pd.DataFrame(rows)


def z_scores(fit):
    """(ln estimate − ln truth) / its standard error in ln, per stick key."""
    return {e.key: math.log(e.value / TRUTH[e.key]) / (e.stderr / e.value) for e in fit.estimates}


def test_a_cycles_table_without_critical_stress_is_still_a_cycles_table(exact_times, truth_file, tmp_path):
    """The tester deleted the critical_stress columns to fit without the drifting start stresses: "unknown column
    'complete'" (exit 2).  Now read as analyze's table, every stick from σc of the bond parameters."""
    frame = cycles_frame(exact_times, drift=0.02).drop(columns=["critical_stress [Pa]"])
    path = tmp_path / "cycles.csv"
    frame.to_csv(path, index=False)
    data = read_stick_data(path)
    assert data.start_stress is None and len(data) == len(frame)
    assert any("without its critical_stress column" in n for n in data.notes())
    result = CliRunner().invoke(cli, ["fit", "stick", str(path), "--params", str(truth_file), "--json"])
    assert result.exit_code == 0, result.output
    fitted = json.loads(result.stdout)
    assert fitted["status"] == "ok"
    for key, truth in TRUTH.items():
        low, high = fitted["parameters"][key]["interval"]
        assert low < truth < high, (key, low, high)


def test_drifting_start_stresses_are_named_in_the_reason_and_start_stress_model_fits(exact_times, truth_file, tmp_path):
    """0.02 Pa/s of drift (the tester's 10 µN/s over 5 cm²): the fit with the measured start stresses fails, and its
    reason now names the drift and the way out; --start-stress model recovers the set."""
    data = as_table(cycles_frame(exact_times, drift=0.02), tmp_path)
    measured = fit_stick(data, params=truth_file)
    assert measured.status == "failed"
    assert "drift" in measured.reason and "--start-stress model" in measured.reason
    worst = measured.start_drifts[0]
    assert worst.pulling_velocity == pytest.approx(20e-6)
    span = worst.rows[-1] - worst.rows[0]
    sigma_c, times = exact_times
    assert worst.drift == pytest.approx(0.02 * span * (times[20e-6] + 3.0), rel=0.1)  # Pa over the rows
    assert worst.rate == pytest.approx(0.02, rel=0.1)
    model = fit_stick(data, params=truth_file, start_stress="model")
    assert model.success, model.reason
    assert np.allclose(model.start_stress, sigma_c)
    assert all(abs(z) < 4 for z in z_scores(model).values()), z_scores(model)


def test_no_drift_no_drift_message(exact_times, truth_file, tmp_path):
    data = as_table(cycles_frame(exact_times), tmp_path)
    measured = fit_stick(data, params=truth_file)
    assert measured.success and not measured.start_drifts
    assert not any("drift along" in m or "the critical stress σc" in m for m in measured.messages)
    assert all(abs(z) < 4 for z in z_scores(measured).values()), z_scores(measured)


def test_a_constant_offset_is_said_and_start_stress_model_removes_it(exact_times, truth_file, tmp_path):
    """+10 Pa on every start stress (a sensor not zeroed): the fit took it silently (the tester's uc/τ 1.55e-4
    [1.49, 1.61] against 1.8e-4); now a note names the offset from σc, and --start-stress model recovers the set."""
    data = as_table(cycles_frame(exact_times, offset=10.0), tmp_path)
    measured = fit_stick(data, params=truth_file)
    note = [m for m in measured.messages if "above the critical stress σc" in m]
    assert note and "lie 10 Pa above" in note[0] and "offset" in note[0]
    model = fit_stick(data, params=truth_file, start_stress="model")
    assert model.success
    assert all(abs(z) < 4 for z in z_scores(model).values()), z_scores(model)


def test_start_stress_is_checked(exact_times, truth_file, tmp_path):
    data = as_table(cycles_frame(exact_times, cycles=2), tmp_path)
    with pytest.raises(ParameterError, match="start_stress: expected one of measured, model"):
        fit_stick(data, params=truth_file, start_stress="table")
    path = tmp_path / "c.csv"
    cycles_frame(exact_times, cycles=2).to_csv(path, index=False)
    result = CliRunner().invoke(cli, ["fit", "stick", str(path), "--start-stress", "table"])
    assert result.exit_code == 2 and "--start-stress" in result.output


def test_intervals_without_the_bond_parameters_uncertainty_say_so(exact_times, truth_file, tmp_path):
    """The stick times determine Nc0 only as Nc0·kT/λ (Eq 15 holds Nc0 only through (λ/kT)/Nc0): the result says
    that its intervals are conditional on the bond parameters and gives that combination, which holds the truth."""
    fit = fit_stick(as_table(cycles_frame(exact_times), tmp_path), params=truth_file)
    out = fit.as_dict()
    assert out["intervals"]["conditional_on_bond_parameters"] is True
    assert "conditional on the bond parameters" in out["intervals"]["note"] and "Nc0·kT/λ" in out["intervals"]["note"]
    (scale,) = fit.combinations
    params = fit.parameters
    kt_over_lambda = Boltzmann * params.bonds.temperature / params.bonds.activation_length
    assert scale.value == pytest.approx(params.stick.attached_chains * kt_over_lambda, rel=1e-9)
    truth = TRUTH["stick.attached_chains"] * Boltzmann * 293.15 / 1e-10  # 97.1 Pa
    assert scale.interval[0] < truth < scale.interval[1]
    assert "conditional on the bond parameters" in fit.report()


def test_the_steady_fit_s_uncertainty_of_lambda_widens_nc0_only(exact_times, tmp_path):
    """fit steady -o writes its covariance; fit stick --params that file carries it: Nc0 scales with λ/kT exactly
    (Eq 15), so its variance in ln grows by λ's, and uc/τ and τa(stick), with measured start stresses, do not move.
    Before, the intervals left λ out without a word (Nc0 missed the truth in 5 of the tester's 6 chains)."""
    (tmp_path / "start.toml").write_text(START_TOML)
    (tmp_path / "steady.csv").write_text(STEADY_CSV)
    runner = CliRunner()
    command = ["fit", "steady", str(tmp_path / "steady.csv"), "--params", str(tmp_path / "start.toml")]
    steady = runner.invoke(cli, [*command, "-o", str(tmp_path / "fitted.toml"), "--json"])
    assert steady.exit_code == 0, steady.output
    lam = json.loads(steady.stdout)["parameters"]["bonds.activation_length"]
    # the Wald covariance the file carries (read here from the comment line as written), λ's close to the steady fit's
    # own standard error (its profile-likelihood one: within a few per cent)
    (line,) = [x for x in (tmp_path / "fitted.toml").read_text().splitlines() if '"covariance"' in x]
    written = json.loads(line[line.index("{") :])
    k = written["keys"].index("bonds.activation_length")
    var_lambda = written["covariance"][k][k]
    assert var_lambda == pytest.approx((lam["stderr"] / lam["value"]) ** 2, rel=0.1)
    table = tmp_path / "cycles.csv"
    cycles_frame(exact_times).to_csv(table, index=False)

    def run(*extra):
        result = runner.invoke(cli, ["fit", "stick", str(table), "--json", *extra])
        assert result.exit_code == 0, result.output
        return json.loads(result.stdout)

    carried = run("--params", str(tmp_path / "fitted.toml"))
    held = fit_stick(table, params=tmp_path / "fitted.toml", bond_covariance=False).as_dict()  # λ held exact
    assert carried["intervals"]["conditional_on_bond_parameters"] is False
    assert "bonds.activation_length" in carried["intervals"]["bond_parameter_uncertainty_of"]
    assert held["intervals"]["conditional_on_bond_parameters"] is True
    edited = run("--params", str(tmp_path / "fitted.toml"), "--set", f"bonds.activation_length={1.02 * lam['value']} m")
    assert edited["intervals"]["conditional_on_bond_parameters"] is True  # another λ than the covariance's
    assert any("not used" in m for m in edited["messages"])

    def rel(out, key):
        q = out["parameters"][key]
        return q["stderr"] / q["value"]

    nc0 = "stick.attached_chains"
    assert rel(carried, nc0) ** 2 == pytest.approx(rel(held, nc0) ** 2 + var_lambda, rel=1e-3)
    assert rel(carried, nc0) > 2 * rel(held, nc0)
    for key in ("stick.break_rate", "stick.aging_time"):
        assert rel(carried, key) == pytest.approx(rel(held, key), rel=1e-6)
    scale = carried["combinations"]["stick_stress_scale"]
    assert scale["stderr"] / scale["value"] == pytest.approx(rel(held, nc0), rel=1e-3)  # Nc0·kT/λ: λ drops out


def as_table(frame, folder, name="cycles.csv"):
    """The frame through the file reader (a cycles table, as fit stick reads it)."""
    frame.to_csv(folder / name, index=False)
    return read_stick_data(folder / name)
