"""Stick-phase fit (Eq 15): recovery of known parameters, what Table 1 can and cannot determine, bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stickslip.errors import DataError, ParameterError
from stickslip.fitting import StickData, datasets
from stickslip.fitting.stick_fit import fit_stick
from stickslip.parameters import load_parameters
from stickslip.quasistatic.critical import critical_point
from stickslip.quasistatic.stick import stick_phase

TRUE = load_parameters("gelatin-glass")
SIGMA_C = critical_point(TRUE).stress
VELOCITIES = np.array([30e-6, 60e-6, 100e-6])


@pytest.fixture(scope="module")
def synthetic_table() -> StickData:
    phases = [stick_phase(TRUE, v, start_stress=SIGMA_C) for v in VELOCITIES]
    times = np.array([p.stick_time for p in phases])
    peaks = np.array([p.peak_stress for p in phases])
    return StickData.from_arrays(VELOCITIES, times, peaks, np.full(3, SIGMA_C))


def test_recovery_from_exact_stick_times_at_three_velocities(synthetic_table):
    """Three pulling velocities determine Nc0, uc/tau and tau_a; from a start off by factors 1.2-2 the fit
    returns the generating values (stick times from the model itself, so to the ODE tolerance)."""
    start = TRUE.with_overrides(
        {"stick.attached_chains": 2.07e12 * 1.2, "stick.break_rate": 2.8e-4, "stick.aging_time": 5.0}
    )
    fit = fit_stick(synthetic_table, params=start)
    assert fit.free_keys == ("stick.attached_chains", "stick.break_rate", "stick.aging_time")
    for key, value in (("stick.attached_chains", 2.07e12), ("stick.break_rate", 1.4e-4), ("stick.aging_time", 10.0)):
        assert fit.parameters.as_dict()[key] == pytest.approx(value, rel=1e-5)
    assert fit.fitted_peak_stress  # no measured loading rate: peak stresses are data too
    assert np.allclose(fit.model_stick_time, synthetic_table.stick_time, rtol=1e-6)


def test_table1_two_velocities_cannot_determine_three_parameters():
    """Table 1 has stick-slip cycles at only 50 and 100 um/s: one direction is undetermined, a parameter is
    fixed with a message, and the rest reproduce the measured stick times (the paper: 18.3 s, 9.3 s)."""
    fit = fit_stick(datasets.table1_path(), exclude_rows=[10, 11, 14])
    assert len(fit.free_keys) == 2
    assert any("is not determined by these stick times" in m for m in fit.messages)
    assert any("row 15 left out" in m for m in fit.messages)  # 350 um/s: above Vc
    assert any("measured stick_slope" in m for m in fit.messages)
    used = fit.used
    assert list(fit.data.rows[used]) == [8, 9, 12, 13]
    assert np.allclose(fit.model_stick_time[used], fit.data.stick_time[used], rtol=0.05)
    nc0 = fit.parameters.stick.attached_chains
    assert 1.5e12 < nc0 < 3e12  # the paper's Nc0 = 2.07e12 m^-2
    assert fit.noise_scale < 0.05  # ln-residuals of a few per cent
    assert fit.reduced_chi_square is None  # 1 by construction: the noise is estimated from the residuals
    assert "χ²ᵣ = 1 by construction" in fit.report()
    text = fit.report()
    assert "## Rows" in text and "left out" in text
    out = fit.as_dict()
    assert {r["row"] for r in out["rows"] if r["used"]} == {8, 9, 12, 13}


def test_outlier_row_is_flagged():
    fit = fit_stick(datasets.table1_path(), fix={"stick.aging_time": "10 s", "stick.break_rate": "1.4e-4 1/s"})
    assert any(m.startswith("row 11:") and "outlier" in m for m in fit.messages)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"fix": {"bonds.bond_time": 1e-4}}, ParameterError, "not a stick-phase fit parameter"),
        ({"free": ["stick.nonsense"]}, ParameterError, "unknown parameter key"),
        ({"exclude_rows": [99]}, DataError, "no such data row"),
        ({"exclude_rows": ["a"]}, ParameterError, "exclude_rows: expected file row numbers"),
        ({"exclude_rows": [8, 9, 10, 11, 12, 13]}, DataError, "1 usable row"),
        ({"level": 0.0}, ParameterError, "level"),
    ],
)
def test_bad_requests(kwargs, error, match):
    with pytest.raises(error, match=match):
        fit_stick(datasets.table1_path(), **kwargs)


def test_batched_stick_times_against_the_closed_form_and_the_single_solver():
    """t_s of many phases at once: constant load without aging has t_s = E1(s0)/r exactly; with loading and
    aging they agree with stick_phase (scipy, rtol 1e-11), stuck phases included (NaN there)."""
    from scipy.special import exp1

    from stickslip.fitting.stick_batch import stick_times

    s0 = np.array([0.01, 0.3, 1.0, 3.0, 10.0, 40.0])
    r = np.array([1e-4, 1.0, 1e3, 1.4e-4, 2.0, 1e-6])
    assert np.allclose(stick_times(r, s0, 0.0, 0.0, np.inf), exp1(s0) / r, rtol=1e-8, atol=0)
    rng = np.random.default_rng(3)
    b = TRUE.bonds.force_sensitivity
    cases = [(2.07e12 * f, 1.4e-4 * g, 10.0 * a, v) for f, g, a, v in zip(
        np.exp(rng.uniform(-0.7, 0.7, 8)), np.exp(rng.uniform(-2, 2, 8)), np.exp(rng.uniform(-2, 2, 8)),
        [10e-6, 20e-6, 30e-6, 50e-6, 100e-6, 50e-6, 30e-6, 10e-6], strict=True)]  # fmt: skip
    nc0, br, ta, v = (np.array(c) for c in zip(*cases, strict=True))
    k = b * TRUE.block.effective_stiffness * v / nc0
    batch = stick_times(br, b * SIGMA_C / nc0, k, 1.0 / ta, 1e6)
    for j, (n, g, a, vel) in enumerate(cases):
        p = TRUE.with_overrides({"stick.attached_chains": n, "stick.break_rate": g, "stick.aging_time": a})
        phase = stick_phase(p, vel, start_stress=SIGMA_C)
        if phase.stick_time is None:
            assert np.isnan(batch[j])
        else:
            assert batch[j] == pytest.approx(phase.stick_time, rel=1e-7)


def test_stick_plot_has_model_line_error_bars_and_linear_axes():
    fit = fit_stick(datasets.table1_path(), exclude_rows=[11])
    ax = fit.plot()
    assert ax.get_xscale() == "linear" and ax.get_yscale() == "linear"
    assert any(len(line.get_xdata()) > 50 for line in ax.get_lines())  # the fitted t_s(V0) curve
    assert any(c.has_yerr for c in ax.containers)
    assert ax.get_xlim()[0] == 0.0 and ax.get_ylim()[0] == 0.0


def _table(velocity, stick_time) -> StickData:
    velocity = np.asarray(velocity, dtype=float)
    return StickData.from_arrays(velocity, np.asarray(stick_time, dtype=float), None, np.full(velocity.size, SIGMA_C))


GARBAGE = {
    # issue 29: each exited 0 and wrote -o, with 341 % relative noise and every parameter "not determined"
    "random": ([20e-6, 30e-6, 50e-6, 70e-6, 100e-6, 150e-6], [14.1, 2.3, 27.0, 5.5, 21.9, 1.7]),
    "increasing": ([20e-6, 30e-6, 50e-6, 70e-6, 100e-6, 150e-6], [3.0, 8.4, 13.8, 19.2, 24.6, 30.0]),
    "same velocity": ([50e-6] * 5, [6.0, 22.0, 11.0, 29.0, 15.0]),
    "tiny velocities": ([2e-11, 3e-11, 5e-11, 7e-11, 1e-10, 1.5e-10], [30.0, 24.6, 19.2, 13.8, 8.4, 3.0]),
}


@pytest.mark.parametrize("name", list(GARBAGE))
def test_garbage_tables_fail(name):
    fit = fit_stick(_table(*GARBAGE[name]))
    assert fit.status == "failed" and not fit.success and fit.reason
    assert fit.as_dict()["status"] == "failed" and fit.as_dict()["reason"] == fit.reason
    assert all(e.interval is None for e in fit.estimates)
    assert fit.report().startswith("# Stick-phase fit") and "**Fit failed:**" in fit.report()


def test_good_tables_have_status_ok(synthetic_table):
    """The exact table and Table 1 (its outlier row 11 kept or left out) are fits, with status ok."""
    assert fit_stick(synthetic_table).status == "ok"
    for rows in ([], [11]):
        fit = fit_stick(datasets.table1_path(), exclude_rows=rows)
        assert fit.status == "ok" and fit.reason == "" and fit.as_dict()["status"] == "ok"


def test_a_misfit_larger_than_the_scatter_of_repeated_cycles_fails():
    """Repeated cycles measure the noise without the model (here 1 %): stick times that rise with velocity,
    which Eq 15 cannot follow, leave a misfit far above it."""
    velocity = np.repeat([30e-6, 60e-6, 100e-6], 3)
    times = np.repeat([6.0, 12.0, 24.0], 3) * (1 + 0.01 * np.tile([-1.0, 0.0, 1.0], 3))
    fit = fit_stick(_table(velocity, times))
    assert fit.status == "failed" and "model does not describe these stick times" in fit.reason


def test_cli_fit_stick_fails_with_exit_3_and_no_output(tmp_path, capsys):
    from cli_helpers import run_main

    velocity, times = GARBAGE["random"]
    path = tmp_path / "random.csv"
    path.write_text(
        "pulling_velocity,stick_time,start_stress [Pa]\n"
        + "\n".join(f"{v},{t},{SIGMA_C}" for v, t in zip(velocity, times, strict=True))
        + "\n"
    )
    toml = tmp_path / "out.toml"
    code, out, err = run_main(capsys, "fit", "stick", str(path), "--json", "-o", str(toml))
    assert code == 3 and not toml.exists()
    assert "stickslip: fit failed:" in err and "not written" in err
    assert json.loads(out)["status"] == "failed"


def test_stick_fit_frame_of_the_shipped_table_names_every_unit():
    """The shipped Table 1 carries extra columns (cycle, stick_slope, stiffness, jump_velocity): the fit's frame
    keeps them with their SI units (read in kPa/m and um/s, held in Pa/m and m/s), a cycle number with none."""
    frame = fit_stick(datasets.table1_path()).to_frame()
    units = frame.attrs["units"]
    assert units["stiffness"] == "Pa/m" and units["jump_velocity"] == "m/s" and units["stick_slope"] == "Pa/s"
    assert units["cycle"] is None and units["model_stick_time"] == "s"
    assert frame["stiffness"].iloc[0] == pytest.approx(431e3)  # 431 kPa/m in the file
