"""A steady fit runs every steady state on the compiled march, its Vc and sigma_c search too (round 35).

Reference: the numpy march and critical-point search, the second implementation (tests/test_critical_compiled.py
holds the two to each other); what a fit reports must not depend on which march found it beyond rounding, and
``critical_point`` after a fit is still the numpy search's, bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest

from stickslip import load_parameters
from stickslip.fitting import SteadyData, fit_steady
from stickslip.quasistatic import critical, steady
from stickslip.quasistatic.critical import critical_point

GEL = load_parameters("gelatin-glass")
VELOCITY = np.geomspace(140e-6, 2000e-6, 24)


def _forget() -> None:
    for cache in (critical.cached_critical_point, critical._cached_minimum, critical._grid_signs, critical._refine):
        cache.cache_clear()


@pytest.fixture(scope="module")
def data() -> SteadyData:
    true = steady.steady_state(GEL, VELOCITY).stress
    stress = true * (1 + 0.02 * np.random.default_rng(5003).standard_normal(VELOCITY.size))
    return SteadyData.from_arrays(VELOCITY, stress, 0.02 * true)


def test_no_steady_state_of_a_fit_runs_on_numpy_and_its_critical_point_is_the_numpy_search_s(data, monkeypatch):
    _forget()
    on_numpy = []
    real = steady._march

    def recording(s, q, keep_nodes=False, compiled_from=None):
        lanes = steady.COMPILED_LANES if compiled_from is None else compiled_from
        if keep_nodes or s.log_t.size < lanes:
            on_numpy.append(s.log_t.size)
        return real(s, q, keep_nodes, compiled_from)

    monkeypatch.setattr(steady, "_march", recording)
    fit = fit_steady(data, method="two-step")  # (the joint fit's profile reports the Vc of its own refit)
    assert fit.status == "ok", fit.reason
    assert not on_numpy, on_numpy[:5]
    assert not steady.marches_compiled()  # the setting ends with the fit
    monkeypatch.undo()
    after = critical_point(fit.parameters)  # numpy's, whatever the fit cached
    _forget()
    fresh = critical_point(fit.parameters)
    assert (after.velocity, after.stress) == (fresh.velocity, fresh.stress)
    assert fit.critical_velocity.value == pytest.approx(fresh.velocity, rel=1e-10)
    assert fit.critical_stress.value == pytest.approx(fresh.stress, rel=1e-12)
