"""stickslip.numerics.roots.brentq against scipy.optimize.brentq: the same iterates, so the same floats.

The model uses the plain-Python Brent to keep scipy.optimize (0.3 s to import)
off the start-up path of ``stickslip critical``; these tests hold it to
scipy's results bit for bit, and the critical point to the one found with
scipy's solver.
"""

from __future__ import annotations

import math

import pytest
from scipy.optimize import brentq as scipy_brentq

import stickslip.quasistatic.critical as critical_module
from stickslip.numerics.roots import MIN_RTOL, brentq

CASES = [
    ("cubic", lambda x: x**3 - 2 * x - 5, 2.0, 3.0),
    ("cos x = x", lambda x: math.cos(x) - x, 0.0, 1.0),
    ("steep exponential", lambda x: math.exp(x) - 1e5, 0.0, 20.0),
    ("flat ninth power", lambda x: x**9 - 1e-3, -1.0, 2.0),
    ("step-like tanh", lambda x: math.tanh(50 * (x - 0.123)), -1.0, 1.0),
    ("root at an end", lambda x: x - 1.0, 1.0, 3.0),
    ("log-velocity shape", lambda x: math.sinh(x + 9.0) * math.exp(-0.1 * x), -12.0, -3.0),
]
TOLERANCES = [(2e-12, MIN_RTOL), (1e-13, 1e-13), (1e-3, 1e-6)]


@pytest.mark.parametrize("name, f, a, b", CASES, ids=[c[0] for c in CASES])
@pytest.mark.parametrize("xtol, rtol", TOLERANCES)
def test_same_root_as_scipy_bit_for_bit(name, f, a, b, xtol, rtol):
    assert brentq(f, a, b, xtol=xtol, rtol=rtol) == scipy_brentq(f, a, b, xtol=xtol, rtol=rtol)
    assert brentq(f, b, a, xtol=xtol, rtol=rtol) == scipy_brentq(f, b, a, xtol=xtol, rtol=rtol)


def test_same_errors_as_scipy():
    with pytest.raises(ValueError, match="different signs"):
        brentq(lambda x: x * x + 1, -1.0, 1.0)
    with pytest.raises(ValueError, match="NaN"):
        brentq(lambda x: math.nan if x > 0.5 else x - 0.7, 0.0, 1.0)
    with pytest.raises(ValueError, match="rtol too small"):
        brentq(lambda x: x, -1.0, 1.0, rtol=1e-17)
    slow = (lambda x: math.atan(x - 0.3) ** 3, -5.0, 7.0)  # a triple root: scipy gives up too
    with pytest.raises(RuntimeError):
        scipy_brentq(*slow)
    with pytest.raises(RuntimeError):
        brentq(*slow)


def test_critical_point_is_the_same_with_scipys_solver(params, monkeypatch):
    ours = critical_module.critical_point(params)
    monkeypatch.setattr(critical_module, "brentq", scipy_brentq)
    critical_module.cached_critical_point.cache_clear()  # computed once per curve: solve it again
    theirs = critical_module.critical_point(params)
    assert ours.as_dict() == theirs.as_dict()  # exact: every float identical
    assert ours.velocity == pytest.approx(124.1e-6, rel=2e-3)  # the paper's Vc, as a sanity anchor
