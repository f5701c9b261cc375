"""The births' vacancy (kernel ``_vacancy``), which the births' sweeps now take with its exponentials computed once
a step (``_vacancy_kernel``, ``_vacancy_from``): against the integral of its ODE by adaptive quadrature.

Q(u) solves dQ/du = -Q/tau + L(u) with L the cubic Hermite of the breakage rate over a step of length h, so
Q(u) = q0 e^(-u/tau) + int_0^u L(s) e^(-(u-s)/tau) ds; the kernel takes a four-point Gauss-Legendre rule for
u < tau (exact for the cubic times a smooth exponential to ~1e-10 of it here) and the closed form by parts above.
"""

from __future__ import annotations

import math

import pytest
from scipy.integrate import quad

from stickslip.transient import kernel as K

TAU = 2.24e-4


def _hermite(s: float, h: float, l0: float, d0: float, l1: float, d1: float) -> float:
    """The cubic through (0, l0) and (h, l1) with slopes d0, d1, written out independently of the kernel's form."""
    a, b = l0, d0
    c = (3.0 * (l1 - l0) / h - 2.0 * d0 - d1) / h
    e = (2.0 * (l0 - l1) / h + d0 + d1) / (h * h)
    return a + s * (b + s * (c + s * e))


@pytest.mark.parametrize("h", [0.3 * TAU, 2.0 * TAU, 30.0 * TAU])
@pytest.mark.parametrize("share", [0.2113248654, 0.7886751346, 1.0])
def test_the_vacancy_is_the_integral_of_its_ode(h, share):
    K.compiled()
    u = share * h
    q0, l0, l1 = 3.1e13, 4.0e16, 2.5e16
    d0, d1 = -1.0e16 / h, 3.0e15 / h
    want = (
        q0 * math.exp(-u / TAU)
        + quad(lambda s: _hermite(s, h, l0, d0, l1, d1) * math.exp(-(u - s) / TAU), 0.0, u, epsabs=0.0, epsrel=1e-13)[0]
    )
    got = K._vacancy(u, q0, TAU, h, l0, d0, l1, d1)
    assert got == pytest.approx(want, rel=1e-9, abs=1e-9 * q0)
    # the sweeps' split: the same number, its exponentials taken apart
    dec, c0, c1, c2, c3 = K._vacancy_kernel(u, TAU)
    assert K._vacancy_from(u, q0, TAU, h, l0, d0, l1, d1, dec, c0, c1, c2, c3) == got


def test_no_time_no_relaxation():
    K.compiled()
    assert K._vacancy(0.0, 5.0e13, TAU, TAU, 1.0, 2.0, 3.0, 4.0) == 5.0e13
