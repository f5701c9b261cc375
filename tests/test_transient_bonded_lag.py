"""The bonded count's first-order lag on the quasi-steady manifold (reduction.effective_bonded, issue 31).

N = N_ss(V) + C_N V' with C_N = d/ds[Z_N(s)/s] at s = 0, Z_N the bonded count's linear response to the slider's
displacement (stability._response_sum, row 1). Checked against two independent things: its quasi-static limit
(Z_N(s)/s -> dN_ss/dV, a finite difference of the steady solver), and the plain cohorts at a tight rtol.
"""

from __future__ import annotations

import numpy as np
import pytest

import stickslip
from stickslip.protocols import Protocol, Segment
from stickslip.quasistatic.steady import steady_state
from stickslip.transient import cells, reduction, run_transient
from stickslip.transient.model import pack_parameters
from stickslip.transient.stability import _response_kernel

GEL = stickslip.load_parameters("gelatin-glass")


@pytest.mark.parametrize("velocity", [200e-6, 700e-6, 3e-3])
def test_the_bonded_response_has_the_steady_slope_as_its_quasi_static_limit(velocity):
    """Z_N(s)/s at s -> 0 is dN_ss/dV (central difference of the steady solver's N, h = 1e-4 V)."""
    b = GEL.bonds
    p = pack_parameters(GEL, True, 1.0)
    a, w, width, f, fp, r, gv, _energy = cells._steady_cells()(velocity, p, cells.CELL_HAZARD)
    eps = 1e-4 * velocity / b.max_extension
    s = np.array([eps, -eps], dtype=complex)
    z = _response_kernel()(s, a, w, width, f, fp, r, gv, b.force_sensitivity, b.site_density - w.sum()).real
    limit = float(np.mean(z[1] / s.real))
    h = 1e-4 * velocity
    up, down = (float(steady_state(GEL, v).bonded_fraction) * b.site_density for v in (velocity + h, velocity - h))
    assert limit == pytest.approx((up - down) / (2 * h), rel=2e-4)  # measured 4.6e-5, 1.0e-5, 6.5e-6


def test_the_reduced_bonded_fraction_follows_the_cohorts():
    """350 then 700 um/s through the block from steady sliding: on its 5 ms grid the reduced run's N/N0 is within
    2e-8 of the plain cohorts' at rtol 1e-5 (measured 2.6e-9; without the lag, the steady N(V): 6.2e-6)."""
    protocol = Protocol((Segment(350e-6, 0.2), Segment(700e-6, 0.2)))
    reduction._BUILT.clear()
    reduced = run_transient(GEL, protocol, start="steady", every=5e-3)
    plain = run_transient(GEL, protocol, start="steady", every=5e-3, reduction="off", rtol=1e-5)
    assert np.allclose(reduced.time, plain.time)
    assert reduced.steps * 20 < plain.steps
    assert np.max(np.abs(reduced.bonded_fraction - plain.bonded_fraction)) < 2e-8
