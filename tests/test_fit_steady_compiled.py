"""A steady fit runs every steady state on the compiled march, its Vc and sigma_c search too (round 35).

Reference: the numpy march and critical-point search, the second implementation (tests/test_critical_compiled.py
holds the two to each other); what a fit reports must not depend on which march found it beyond rounding, and
``critical_point`` after a fit is still the numpy search's, bit for bit.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from cli_helpers import run_main
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


def test_the_reported_vc_and_sigma_c_are_those_of_the_parameters_written_out(data, tmp_path, capsys):
    """The default (joint, profile) fit reported the Vc of its profile's own refit, 1.5e-6 to 3.5e-6 off the Vc of
    the parameters it wrote (sigma_c 3e-7 to 8e-7): `critical --params fitted.toml` read another critical point."""
    table = tmp_path / "steady.csv"
    rows = zip(data.velocity, data.stress, data.stress_err, strict=True)
    table.write_text(
        "velocity,stress,stress_err\n" + "".join(f"{float(v)!r},{float(s)!r},{float(e)!r}\n" for v, s, e in rows)
    )
    fitted = tmp_path / "fitted.toml"
    code, out, err = run_main(capsys, "fit", "steady", str(table), "--json", "-o", str(fitted))
    assert code == 0, err
    fit = json.loads(out)
    assert "profile likelihood" in fit["critical_velocity"]["note"]
    code, out, err = run_main(capsys, "critical", "--params", str(fitted), "--json")
    assert code == 0, err
    point = json.loads(out)
    assert fit["critical_velocity"]["value"] == pytest.approx(point["critical_velocity"], rel=1e-10)
    assert fit["critical_stress"]["value"] == pytest.approx(point["critical_stress"], rel=1e-12)
