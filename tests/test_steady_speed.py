"""Issue 21: the compiled steady-state march (stickslip.quasistatic.steady_kernel) over the parameter box.

Wide batches (steady.COMPILED_LANES velocities or more) are marched lane by lane in numba-compiled loops
instead of numpy arrays.  Here the compiled march is forced on every call and checked against the
independent references of tests/reference_steady.py and tests/reference_slope.py (no code shared with
the panels) over random sets of the box, half in the deep-dip/cliff corner, and against the numpy march:
the same panels, so the two agree to the quadrature's own error (a width test that ties to an ulp can
pick another acceptable panel, which moves sigma by ~1e-12).
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from reference_slope import reference_slope_many, slope_error
from reference_steady import box_cases, reference_many
from stickslip import ModelError, ParameterError, load_parameters, steady_state
from stickslip.quasistatic import steady

GEL = load_parameters("gelatin-glass")
#: the issue's accuracy over the box (relative); reference_many itself is good to ~1e-9
ACCURACY = 1e-8


@pytest.fixture
def compiled(monkeypatch):
    monkeypatch.setattr(steady, "COMPILED_LANES", 1)


@pytest.fixture
def plain(monkeypatch):
    monkeypatch.setattr(steady, "COMPILED_LANES", 10**12)


def _outputs(cases):
    got = [steady_state(p, v, aging=aging) for p, v, aging in cases]
    return tuple(np.array([float(getattr(g, name)) for g in got]) for name in ("stress", "bonded_fraction"))


def _rel(got, ref):
    return np.abs(np.asarray(got) / ref - 1.0)


def test_compiled_march_over_the_box_against_the_reference(compiled):
    cases = box_cases(seed=2101, count=400, base=GEL, corner_share=0.5)
    ref_stress, ref_fraction = reference_many(cases)
    stress, fraction = _outputs(cases)
    assert float(np.max(_rel(stress, ref_stress))) <= ACCURACY, int(np.argmax(_rel(stress, ref_stress)))
    assert float(np.max(_rel(fraction, ref_fraction))) <= ACCURACY


def test_compiled_and_numpy_marches_agree_over_the_box(monkeypatch):
    cases = box_cases(seed=2102, count=200, base=GEL, corner_share=0.5)
    monkeypatch.setattr(steady, "COMPILED_LANES", 1)
    fast = [steady_state(p, v, aging=aging) for p, v, aging in cases]
    monkeypatch.setattr(steady, "COMPILED_LANES", 10**12)
    plain = [steady_state(p, v, aging=aging) for p, v, aging in cases]
    for name, tolerance in (("stress", 1e-10), ("bonded_fraction", 1e-10)):
        a = np.array([float(getattr(g, name)) for g in fast])
        b = np.array([float(getattr(g, name)) for g in plain])
        assert float(np.max(_rel(a, b))) <= tolerance, name


def test_compiled_slope_in_the_hard_corner_against_the_derivative_reference(compiled):
    cases = box_cases(seed=2103, count=60, base=GEL, corner_share=1.0)
    stress, ref = reference_slope_many(cases)
    velocity = np.array([c[1] for c in cases])
    slopes = np.array([float(steady_state(p, v, aging=aging).stress_slope) for p, v, aging in cases])
    err = slope_error(slopes, ref, stress, velocity)
    assert err.max() <= 1e-6, (float(err.max()), int(err.argmax()))


def test_compiled_slope_where_the_cliff_is_a_step(monkeypatch):
    """The sets whose FENE cliff is a step of the survival: the step's boundary terms (without them the slope
    was off by up to 100 %).  The numpy march is checked on them against a finite difference of the reference
    in tests/test_steady_slope.py; the compiled one must give the same slope."""
    from test_steady_slope import STEEP_CLIFF_CASES

    cases = box_cases(seed=12, count=9000, base=GEL, corner_share=0.5, only=STEEP_CLIFF_CASES)

    def slopes(lanes):
        monkeypatch.setattr(steady, "COMPILED_LANES", lanes)
        return np.array([float(steady_state(p, v, aging=aging).stress_slope) for p, v, aging in cases])

    fast, plain = slopes(1), slopes(10**12)
    assert np.all(np.abs(fast - plain) <= 1e-9 * np.abs(plain)), np.abs(fast / plain - 1).max()


def test_a_wide_curve_runs_compiled_and_matches_the_numpy_march(monkeypatch):
    velocity = np.geomspace(1e-6, 1e-1, steady.COMPILED_LANES)
    calls = []
    original = steady._march_compiled
    monkeypatch.setattr(steady, "_march_compiled", lambda *a: calls.append(1) or original(*a))
    wide = steady_state(GEL, velocity)
    assert calls
    monkeypatch.setattr(steady, "COMPILED_LANES", 10**12)
    narrow = steady_state(GEL, velocity)
    assert float(np.max(_rel(wide.stress, narrow.stress))) <= 1e-10
    assert float(np.max(_rel(wide.bonded_fraction, narrow.bonded_fraction))) <= 1e-10
    assert np.max(np.abs(wide.stress_slope - narrow.stress_slope) / np.abs(narrow.stress).max() * velocity) <= 1e-8


def test_compiled_march_that_needs_too_many_panels_is_a_model_error(compiled, monkeypatch):
    monkeypatch.setattr(steady, "MAX_PANELS", 2)
    with pytest.raises(ModelError, match="did not converge: more than 2 panels"):
        steady_state(GEL, [50e-6, 350e-6])


def test_compiled_march_is_faster_than_the_numpy_one(monkeypatch):
    """The benchmark's curve (1000 velocities, benchmarks/bench_steady.py) in the same process: process time."""
    velocity = np.geomspace(10e-6, 10e-3, 1000)

    def cost(lanes):
        monkeypatch.setattr(steady, "COMPILED_LANES", lanes)
        steady_state(GEL, velocity)  # warm (compiled code loaded)
        start = time.process_time()
        for _ in range(5):
            steady_state(GEL, velocity)
        return time.process_time() - start

    plain, fast = min(cost(10**12) for _ in range(2)), min(cost(1) for _ in range(2))
    assert fast < plain / 1.5, (plain, fast)  # measured ~3x


def test_compiled_exponential_is_within_an_ulp_of_numpy():
    """The march's vectorisable exp (Taylor on |r| <= ln2/2 times 2^n) against numpy's, over its whole range;
    below e^-708 (subnormal) it gives 0."""
    from stickslip.quasistatic import steady_kernel

    steady_kernel.compiled()
    rng = np.random.default_rng(2104)
    x = np.concatenate([rng.uniform(-750.0, 709.0, 100_000), rng.uniform(-1.0, 1.0, 10_000), [0.0, -708.0, 700.0]])
    out, bits = np.empty_like(x), np.empty(x.size, dtype=np.int64)
    steady_kernel._exp_into(x, out, bits)
    ref = np.exp(x)
    normal = x >= -708.0
    assert np.max(np.abs(out[normal] - ref[normal]) / np.spacing(ref[normal])) <= 2.0
    assert np.all(out[~normal] == 0.0)


def test_compiled_march_over_the_corners_of_the_box_is_finite_and_agrees(monkeypatch):
    """tests/test_steady.py's grid of extremes (chain length, bond time, u0, activation length, aging): the
    compiled march gives finite, physical values, equal to the numpy march's."""
    velocities = np.geomspace(5e-6, 1.0, 25)
    worst = {"stress": 0.0, "bonded_fraction": 0.0, "slope": 0.0}
    for dl in ("10 nm", "1 um", "1 m"):
        for tau in ("1 ns", "1 s"):
            for u0 in (0.01, 100.0):
                for lam in ("1e-16 m", "1 angstrom", "1e-7 m"):
                    keys = (
                        "bonds.max_extension",
                        "bonds.bond_time",
                        "bonds.breakage_weight",
                        "bonds.activation_length",
                    )
                    p = GEL.with_overrides(dict(zip(keys, (dl, tau, u0, lam), strict=True)))
                    for aging in (True, False):
                        monkeypatch.setattr(steady, "COMPILED_LANES", 1)
                        fast = steady_state(p, velocities, aging=aging)
                        monkeypatch.setattr(steady, "COMPILED_LANES", 10**12)
                        plain = steady_state(p, velocities, aging=aging)
                        for array in (fast.stress, fast.bonded_fraction, fast.stress_slope):
                            assert np.all(np.isfinite(array))
                        assert np.all(fast.stress > 0)
                        assert np.all((fast.bonded_fraction > 0) & (fast.bonded_fraction < 1))
                        for name in ("stress", "bonded_fraction"):
                            worst[name] = max(
                                worst[name], float(np.max(_rel(getattr(fast, name), getattr(plain, name))))
                            )
                        floor = np.maximum(np.abs(plain.stress_slope), 1e-3 * plain.stress / velocities)
                        worst["slope"] = max(
                            worst["slope"], float(np.max(np.abs(fast.stress_slope - plain.stress_slope) / floor))
                        )
    assert worst["stress"] <= 1e-10 and worst["bonded_fraction"] <= 1e-10 and worst["slope"] <= 1e-7, worst


def test_critical_point_is_computed_once_per_steady_curve(monkeypatch):
    """The report, the fits and the plots ask for the same critical point several times (~30 ms each): it is
    solved once per steady curve (bond and aging parameters), whatever the block, stick or name."""
    from stickslip import critical_point
    from stickslip.quasistatic import critical

    critical.cached_critical_point.cache_clear()
    solved = []
    real = critical.find_extrema
    monkeypatch.setattr(critical, "find_extrema", lambda *a, **k: solved.append(1) or real(*a, **k))
    first = critical_point(GEL)
    again = critical_point(GEL.with_overrides({"block.shear_modulus": 1234.0, "stick.aging_time": 3.0}))
    assert again is first and len(solved) == 2  # the aging and the no-aging curve, once
    other = critical_point(GEL.with_overrides({"aging.aging_time": 20.0}))
    assert len(solved) == 4 and other.velocity != first.velocity


def test_a_fits_small_batch_runs_compiled_and_agrees_with_the_numpy_march(monkeypatch):
    """A fit's Jacobian or a sampler's walkers: 16 sets x 4 velocities through steady_stress_many (64 lanes, far
    below COMPILED_LANES) take the compiled march, and give what the numpy march gives to its panel tolerance."""
    from stickslip.quasistatic.steady import steady_stress_many

    sets = [p for p, _, aging in box_cases(seed=2104, count=40, base=GEL, corner_share=0.0) if aging][:16]
    velocity = np.array([20e-6, 124e-6, 350e-6, 2e-3])
    calls = []
    original = steady._march_compiled
    monkeypatch.setattr(steady, "_march_compiled", lambda *a: calls.append(1) or original(*a))
    fast = steady_stress_many(sets, velocity)
    assert calls, "a batch of 64 lanes ran on numpy"
    monkeypatch.setattr(steady, "BATCH_COMPILED_LANES", 10**12)
    calls.clear()
    plain = steady_stress_many(sets, velocity)
    assert not calls
    assert float(np.max(_rel(fast, plain))) <= 1e-10


def test_a_fits_narrow_calls_run_compiled_and_agree_with_steady_state(monkeypatch):
    """A fit's residuals (model_stress at its data's few velocities) and its critical point's searches repeat
    narrow calls: they take the compiled march at any width, and give steady_state's numpy march to rounding."""
    from stickslip.fitting.batch import model_stress
    from stickslip.fitting.critical_uncertainty import local_critical

    velocity = np.array([20e-6, 124e-6, 350e-6])
    plain = steady_state(GEL, velocity)
    calls = []
    original = steady._march_compiled
    monkeypatch.setattr(steady, "_march_compiled", lambda *a: calls.append(1) or original(*a))
    fast = model_stress(GEL, velocity)
    assert calls, "a fit's narrow call ran on numpy"
    assert float(np.max(_rel(fast, plain.stress))) <= 1e-10
    calls.clear()
    vc, sc = local_critical(GEL, 124e-6)
    assert calls
    monkeypatch.setattr(steady, "_march_compiled", original)
    slope = steady_state(GEL, [vc * 0.999, vc * 1.001]).stress_slope
    assert slope[0] < 0.0 < slope[1]  # a minimum of the numpy march's curve lies between
    assert sc == pytest.approx(float(steady_state(GEL, vc).stress), rel=1e-10)


@pytest.mark.parametrize("bad", [0, -3, 2.5, True, "16"])
def test_compiled_from_must_be_a_positive_whole_number(bad):
    with pytest.raises(ParameterError, match="compiled_from"):
        steady_state(GEL, 1e-4, compiled_from=bad)
