"""stickslip.numerics.transforms against scipy: dct1 against scipy.fft.dct(type=1), exprel against
scipy.special.exprel, bit for bit (numpy 2's FFT is the pocketfft that scipy.fft runs; math.expm1 is the C
library's expm1 that scipy's exprel calls), so the jump's and the slip's Chebyshev series are scipy's numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.fft
import scipy.special

from stickslip.numerics.transforms import dct1, exprel

#: numpy 1's FFT is an older pocketfft (C): the same transform to rounding, not bit for bit
SAME_POCKETFFT = int(np.__version__.split(".")[0]) >= 2


@pytest.mark.parametrize("n", [1, 2, 3, 7, 12, 32, 64, 100, 256, 1024, 4096])
@pytest.mark.parametrize("rows", [1, 3])
def test_dct1_is_scipys(n, rows):
    rng = np.random.default_rng(n * 10 + rows)
    values = rng.standard_normal((rows, n + 1)) * 10.0 ** rng.uniform(-8, 8, (rows, 1))
    expected = scipy.fft.dct(values, type=1, axis=-1)
    if SAME_POCKETFFT:
        assert np.array_equal(dct1(values), expected)
        assert np.array_equal(dct1(values[0]), expected[0])  # one dimension too
    else:  # pragma: no cover - numpy 1
        np.testing.assert_allclose(dct1(values), expected, rtol=1e-13, atol=1e-13 * np.abs(expected).max())


def test_dct1_of_a_cosine_is_a_spike():
    # independent of scipy: the DCT-I of cos(pi k j/n) at the n+1 points is n at k (2n at k = 0 and n), else 0
    n, k = 16, 5
    j = np.arange(n + 1)
    out = dct1(np.cos(np.pi * k * j / n))
    expected = np.zeros(n + 1)
    expected[k] = n
    np.testing.assert_allclose(out, expected, atol=1e-12)


def test_exprel_is_scipys():
    rng = np.random.default_rng(7)
    x = np.concatenate([
        rng.uniform(-50, 50, 20000), rng.uniform(-1e-3, 1e-3, 10000), rng.uniform(-800, 800, 2000),
        [0.0, -0.0, 1e-20, -1e-20, 2e-16, 2.3e-16, -2.3e-16, 709.5, 709.9, 716.9, 717.0, 717.5, -745.0, -800.0],
        [math.inf, -math.inf, math.nan],
    ])  # fmt: skip
    ours, theirs = exprel(x), scipy.special.exprel(x)
    assert np.array_equal(ours, theirs, equal_nan=True)
    assert np.array_equal(exprel(x[:32].reshape(4, 8)), theirs[:32].reshape(4, 8))  # any shape


def test_exprel_is_its_definition():
    # independent of scipy: the series 1 + x/2 + x^2/6 near 0, (e^x - 1)/x away from it
    assert exprel(0.0) == 1.0
    assert exprel(1e-9) == pytest.approx(1 + 0.5e-9, rel=1e-15)
    assert exprel(1.0) == pytest.approx(math.e - 1, rel=1e-15)
    assert exprel(-30.0) == pytest.approx((math.exp(-30.0) - 1) / -30.0, rel=1e-15)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 17, 48, 65, 200])
def test_chebval_at_one_point_is_numpys(n):
    """numerics.chebyshev.chebval is numpy's chebval bit for bit: Clenshaw's recurrence on Python floats for one
    point (a float, a numpy float, a 0-d array), numpy's own for arrays; a numpy float either way, so that a
    division by zero downstream is inf with a warning as before."""
    from numpy.polynomial import chebyshev as cheb

    from stickslip.numerics.chebyshev import chebval

    rng = np.random.default_rng(n)
    for _ in range(300):
        c = rng.standard_normal(n) * 10.0 ** rng.uniform(-6, 6)
        x = float(rng.uniform(-1.2, 1.2))
        for point in (x, np.float64(x), np.asarray(x)):
            got, want = chebval(point, c), cheb.chebval(point, c)
            assert got == want and type(got) is type(want), (n, point)
        many = rng.uniform(-1.0, 1.0, 5)
        assert np.array_equal(chebval(many, c), cheb.chebval(many, c))
    with np.errstate(all="ignore"):
        for point in (math.inf, -math.inf, math.nan, 0.0, -0.0, 1e308):
            got, want = chebval(point, c), cheb.chebval(point, c)
            assert got == want or (math.isnan(got) and math.isnan(want)), (n, point, got, want)
    with pytest.warns(RuntimeWarning):
        assert chebval(0.5, np.array([1.0, 2.0, 3.0])) / np.float64(0.0) == math.inf
