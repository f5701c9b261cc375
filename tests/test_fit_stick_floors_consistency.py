"""fit stick's consistency check counts the table's own uncertainties (its ``*_uncertainty`` columns).

A stick time's systematic uncertainty (where analyze places a cycle's corners) is the same in every repeat of the
cycle: the scatter between repeats does not show it, yet the model may miss each velocity's mean by that much.  The
F test of the model's misfit compared it with the repeats' scatter alone, so a table whose stick times were off by
0.4 % per velocity, within bounds of ±2 %, failed ("rms misfit 0.33 % against a scatter of 0.00059 %", p = 1.6e-38)
although its intervals, floored by the same uncertainties, held the truth.  Now the misfit is judged against the
scatter plus the floors' mean square; floors far below the misfit still fail it.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from stickslip.fitting.stick_fit import fit_stick
from stickslip.parameters import load_parameters
from stickslip.quasistatic.critical import critical_point
from stickslip.quasistatic.stick import stick_phase

PARAMS = load_parameters("gelatin-glass")
#: a systematic offset of each velocity's stick times (relative), alternating so no parameter absorbs it
BIAS = {20: 0.004, 30: -0.004, 50: 0.004, 70: -0.004, 90: 0.003}
REPEATS = 4


def _table(path, bound: float) -> None:
    """Stick times of the parameter set's own model from sigma_c, each velocity off by BIAS, repeats scattered by
    1e-5, with the uncertainty column +-bound (relative) of each stick time."""
    sigma_c = critical_point(PARAMS).stress
    rng = np.random.default_rng(1)
    rows = []
    for v, bias in BIAS.items():
        exact = stick_phase(PARAMS, v * 1e-6, sigma_c).stick_time
        for _ in range(REPEATS):
            rows.append((v, sigma_c, exact * (1 + bias + 1e-5 * rng.normal()), bound * exact))
    columns = ["pulling_velocity [um/s]", "start_stress [Pa]", "stick_time [s]", "stick_time_uncertainty [s]"]
    pd.DataFrame(rows, columns=columns).to_csv(path, index=False)


def test_a_misfit_within_the_tables_own_uncertainties_is_no_failure(tmp_path):
    _table(tmp_path / "cycles.csv", bound=0.02)
    fit = fit_stick(tmp_path / "cycles.csv", PARAMS)
    assert fit.status == "ok", fit.reason
    truth = {"stick.attached_chains": 2.07e12, "stick.break_rate": 1.4e-4, "stick.aging_time": 10.0}
    for estimate in fit.estimates:  # and the floored intervals hold the set's values
        low, high = estimate.interval
        assert low <= truth[estimate.key] <= high, estimate


def test_a_misfit_far_beyond_them_still_fails(tmp_path):
    _table(tmp_path / "cycles.csv", bound=1e-4)
    fit = fit_stick(tmp_path / "cycles.csv", PARAMS)
    assert fit.status == "failed"
    assert "does not describe these stick times" in fit.reason
    assert "the table's own uncertainties of" in fit.reason


@pytest.mark.parametrize("bound", [0.02])
def test_without_the_column_the_repeats_scatter_alone_judges_it(tmp_path, bound):
    _table(tmp_path / "cycles.csv", bound=bound)
    frame = pd.read_csv(tmp_path / "cycles.csv").drop(columns=["stick_time_uncertainty [s]"])
    frame.to_csv(tmp_path / "bare.csv", index=False)
    fit = fit_stick(tmp_path / "bare.csv", PARAMS)
    assert fit.status == "failed" and "the table's own uncertainties" not in fit.reason
