"""Issue 21: the stick fit after its speed-up (fitting/stick_batch.py) still lands on the least-squares optimum.

The fit's stick times come from the batched Dormand-Prince march; here the optimum is checked with the
independent single-phase solver (:func:`stickslip.quasistatic.stick.stick_phase`, scipy at rtol 1e-11): one
Gauss-Newton step from the fitted values, with residuals and a central-difference Jacobian from
stick_phase, must move the free ln-parameters by less than the fit's tolerance.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip.fitting import datasets
from stickslip.fitting.stick_fit import _params_for_rate, fit_stick
from stickslip.quasistatic.stick import stick_phase

STEP = 1e-3  # in ln-parameter


def _residuals(fit, params):
    data, used = fit.data, fit.used
    out = []
    for k in np.nonzero(used)[0]:
        v, rate, s0 = float(data.pulling_velocity[k]), float(fit.loading_rate[k]), float(fit.start_stress[k])
        phase = stick_phase(_params_for_rate(params, v, rate), v, start_stress=s0)
        assert phase.stick_time is not None
        out.append(math.log(phase.stick_time / float(data.stick_time[k])))
    return np.array(out)


@pytest.mark.parametrize("exclude", [[], [11]])
def test_stick_fit_is_at_the_optimum_of_the_independent_solver(exclude):
    fit = fit_stick(datasets.table1_path(), exclude_rows=exclude)
    assert fit.free_keys and not fit.fitted_peak_stress
    values = fit.parameters.as_dict()
    r = _residuals(fit, fit.parameters)
    columns = []
    for key in fit.free_keys:
        shifted = [
            _residuals(fit, fit.parameters.with_overrides({key: values[key] * math.exp(sign * STEP)}))
            for sign in (1.0, -1.0)
        ]
        columns.append((shifted[0] - shifted[1]) / (2 * STEP))
    jac = np.column_stack(columns)
    step = np.linalg.lstsq(jac, -r, rcond=None)[0]
    # the optimiser stops at xtol = ftol = 1e-6; the batched march is good to ~1e-8 in t_s
    assert np.max(np.abs(step)) <= 1e-5, dict(zip(fit.free_keys, step, strict=True))
