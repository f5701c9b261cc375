"""The interface response's compiled sum (``stability._response_sum``) against the same quadrature written plainly:
each cell's e^{-s d/2}, e^{-s d} and e^{-s a} taken directly with ``cmath.exp`` in Python (the compiled sum takes one
exp per cell and the rest as products, re-anchored every ``REANCHOR`` cells; docs/transient.md section 6)."""

from __future__ import annotations

import cmath

import numpy as np
import pytest

import stickslip
from stickslip.transient import stability


def _plain(s: complex, a, w, width, f, fp, r, gv, c_f: float, birth_tau: float) -> tuple[complex, complex]:  # type: ignore[no-untyped-def]
    def phi1(x: complex) -> complex:
        return 1.0 - x / 2.0 + x * x / 6.0 if abs(x) < 1e-4 else (1.0 - cmath.exp(-x)) / x

    e_acc = r_acc = s_wphi = s_wfe = s_we = s_wphif = s_inst = 0j
    for k in range(a.size):
        d = float(width[k])
        q1 = r[k] * (c_f * fp[k] + s * gv[k])
        q2 = r[k] * c_f * fp[k]
        e_mid = e_acc * cmath.exp(-s * 0.5 * d) + q1 * phi1(s * 0.5 * d) * 0.5 * d
        r_mid = r_acc + q2 * 0.5 * d
        e_acc = e_acc * cmath.exp(-s * d) + q1 * phi1(s * d) * d
        r_acc = r_acc + q2 * d
        ea = cmath.exp(-s * a[k])
        phi = e_mid - ea * r_mid
        s_wphi += w[k] * phi
        s_wfe += w[k] * f[k] * ea
        s_we += w[k] * ea
        s_wphif += w[k] * phi * f[k]
        s_inst += w[k] * fp[k] * (1.0 - ea)
    return s_wphi * s_wfe / (birth_tau + s_we) - s_wphif + s_inst, -s_wphi * birth_tau / (birth_tau + s_we)


@pytest.mark.parametrize("velocity", [1e-6, 120e-6])
def test_the_compiled_sum_is_the_plain_quadrature(velocity: float) -> None:
    params = stickslip.load_parameters("gelatin-glass")
    b = params.bonds
    cells = stability._cells(params, velocity, True)
    birth_tau = (b.site_density - cells[1].sum()) / b.bond_time * b.bond_time
    rates = np.array([1e-3 + 1j, 10 + 100j, 0.5 + 3000j, 1e-7j, 2e5 + 4e4j])
    got = stability._response_kernel()(rates, *cells, b.force_sensitivity, birth_tau)
    for j, s in enumerate(rates):
        z, n = _plain(complex(s), *cells, b.force_sensitivity, birth_tau)
        assert abs(got[0, j] - z) <= 1e-9 * abs(z), (s, got[0, j], z)
        assert abs(got[1, j] - n) <= 1e-9 * abs(n), (s, got[1, j], n)
