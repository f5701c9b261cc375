"""The critical-point search on the compiled march (round 32): the saturating-aging extension in the compiled
steady kernel, and ``compiled=True`` for callers that search many curves (the saturating-aging fit, the
sensitivity study).

References: the numpy march (a second implementation of the same quadrature, itself checked against nested
``scipy.integrate.quad`` in tests/test_aging_saturation.py and tests/test_steady.py) and the numpy search.
"""

from __future__ import annotations

import numpy as np
import pytest

from stickslip import load_parameters
from stickslip.fitting.saturation_fit import curve_extrema
from stickslip.quasistatic import critical, steady
from stickslip.quasistatic.critical import ACCURATE_QUADRATURE, critical_minimum, critical_point, find_extrema

GEL = load_parameters("gelatin-glass")
SAT = load_parameters("gelatin-glass-saturating")
VELOCITIES = np.geomspace(1e-9, 100.0, 240)


@pytest.mark.parametrize("quadrature", [None, ACCURATE_QUADRATURE], ids=["default", "accurate"])
@pytest.mark.parametrize("params", [SAT, SAT.with_overrides({"aging.saturation_age": "0.05 s"})], ids=["ts", "short"])
def test_the_compiled_march_ages_with_saturation_as_numpy_does(params, quadrature):
    kw = {} if quadrature is None else {"quadrature": quadrature}
    plain = steady.steady_state(params, VELOCITIES, compiled_from=10**9, **kw)
    fast = steady.steady_state(params, VELOCITIES, compiled_from=1, **kw)
    np.testing.assert_allclose(fast.stress, plain.stress, rtol=1e-13)
    np.testing.assert_allclose(fast.bonded_fraction, plain.bonded_fraction, rtol=1e-13)
    # the slope crosses zero at the extrema: relative to the stress over a decade, not to itself
    np.testing.assert_allclose(fast.stress_slope * VELOCITIES, plain.stress_slope * VELOCITIES, rtol=0,
                               atol=1e-12 * np.max(plain.stress))  # fmt: skip


def test_a_saturating_set_runs_compiled_when_asked(monkeypatch):
    calls = []
    real = steady._march_compiled

    def counting(s, q):
        calls.append(s.log_t.size)
        return real(s, q)

    monkeypatch.setattr(steady, "_march_compiled", counting)
    steady.steady_state(SAT, np.array([1e-4]), compiled_from=1)
    assert calls == [1]  # before round 32 the extension always stayed on numpy


def _forget() -> None:
    for cache in (critical.cached_critical_point, critical._cached_minimum, critical._grid_signs, critical._refine):
        cache.cache_clear()


@pytest.mark.parametrize(
    "params", [GEL, SAT, GEL.with_overrides({"aging.aging_velocity": "300 um/s"})], ids=["paper", "saturating", "va"]
)
def test_compiled_search_finds_the_numpy_search_s_extrema(params):
    _forget()
    plain = find_extrema(params, aging=True)
    fast = find_extrema(params, aging=True, compiled=True)
    assert [e.kind for e in fast] == [e.kind for e in plain] and plain
    for a, b in zip(fast, plain, strict=True):
        assert a.velocity == pytest.approx(b.velocity, rel=1e-10)
        assert a.stress == pytest.approx(b.stress, rel=1e-12)


def test_the_caches_keep_the_two_searches_apart():
    """A compiled search first must not hand its bits to the plain one (critical_point stays numpy's own)."""
    _forget()
    fast = critical_minimum(GEL, compiled=True)
    plain = critical_minimum(GEL)
    _forget()
    alone = critical_minimum(GEL)
    assert (plain.velocity, plain.stress) == (alone.velocity, alone.stress)
    assert (critical_point(GEL).velocity, critical_point(GEL).stress) == (plain.velocity, plain.stress)
    assert fast.velocity == pytest.approx(plain.velocity, rel=1e-10)
    assert fast.stress == pytest.approx(plain.stress, rel=1e-12)


def test_the_saturation_fit_s_extrema_are_the_plain_search_s():
    _forget()
    peak, minimum = curve_extrema(SAT)
    plain = find_extrema(SAT, aging=True, search_range=(peak.velocity / 2, minimum.velocity * 2))
    kinds = {e.kind: e for e in plain}
    assert peak.stress == pytest.approx(kinds["maximum"].stress, rel=1e-12)
    assert minimum.stress == pytest.approx(kinds["minimum"].stress, rel=1e-12)
    assert minimum.velocity == pytest.approx(kinds["minimum"].velocity, rel=1e-10)


def test_the_two_marches_agree_on_saturating_sets_over_the_box(monkeypatch):
    """tests/test_steady_speed.py's box (half in the deep-dip/cliff corner), each set given a saturation age from
    10 us to 100 s: the compiled and the numpy march to 1e-10, as for the paper's linear aging."""
    from reference_steady import box_cases

    rng = np.random.default_rng(3201)
    cases = [
        (p.with_overrides({"aging.saturation_age": f"{10 ** rng.uniform(-5, 2)!r} s"}), v, aging)
        for p, v, aging in box_cases(seed=3201, count=120, base=GEL, corner_share=0.5)
    ]
    marches = []
    for lanes in (1, 10**12):
        monkeypatch.setattr(steady, "COMPILED_LANES", lanes)
        got = [steady.steady_state(p, v, aging=aging) for p, v, aging in cases]
        marches.append([np.array([float(getattr(g, name)) for g in got]) for name in ("stress", "bonded_fraction")])
    for fast, plain in zip(*marches, strict=True):
        assert float(np.max(np.abs(fast / plain - 1.0))) <= 1e-10
