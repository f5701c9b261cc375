"""Kc ignores the crossings of the age grid above its resolved frequency, with or without a mass.

A box draw of last session's audit (seed 2026, draw 10: a bond time of 64 ns at 0.99 m/s) took 18 s of CPU in
critical_stiffness_details: its scan of Z(i w) had 132 sign changes of Im Z, 123 of them above the resolved
frequency where the cohort sums alias, each bisected 30 times, and it returned the largest, Kc = 1.3e15 Pa/m at
6e11 Hz, which moved to 9e7 Hz on an age grid twice as fine: the grid's, not Z's.  The check here is against
that finer grid: near the returned frequency (within 2 %) it must cross at the same w and K.  (Z varies by 2 %
over 1e-7 of w there, a near-pole of its closure: the crossings are compared, not Z at one w.)
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from stickslip import load_parameters
from stickslip.transient.stability import (
    SCAN,
    critical_from_response,
    critical_stiffness_details,
    interface_response,
    resolved_frequency,
)

DRAW = {
    "bonds.site_density": 377564085949260.0,
    "bonds.bond_time": 6.379302701387996e-08,
    "bonds.breakage_weight": 1.1475117573245248,
    "bonds.chain_stiffness": 1.208640930314304e-06,
    "bonds.activation_length": 7.48766360444345e-08,
    "bonds.max_extension": 0.00021855819210607347,
    "aging.aging_time": 1.3190691388720062e-09,
    "aging.aging_velocity": 0.3667013278558313,
}
VELOCITY = 0.9909580600686254


def test_an_aliased_crossing_is_not_kc_and_costs_no_bisection():
    params = load_parameters("gelatin-glass").with_overrides(DRAW)
    critical_stiffness_details(load_parameters("gelatin-glass"), 1e-4)  # (the compiled kernel loaded)
    start = time.process_time()
    kc = critical_stiffness_details(params, VELOCITY)
    spent = time.process_time() - start
    assert kc.mode == "oscillatory"
    near = np.geomspace(kc.rate / 1.02, kc.rate * 1.02, 9)  # (the finer grid costs ~0.1 s a rate)
    fine = critical_from_response(lambda s: interface_response(params, VELOCITY, s, cell_hazard=0.001).z, near)
    assert fine.mode == "oscillatory" and fine.rate == pytest.approx(kc.rate, rel=1e-5)
    assert fine.value == pytest.approx(kc.value, rel=3e-3)  # (the two grids' Kc differ by 1.2e-3)
    assert kc.rate < resolved_frequency(params, VELOCITY)
    assert spent < 8.0  # was 18 s (2.8 s now, on the same loaded machine)


def test_the_paper_set_at_1_um_s_has_the_kc_of_a_finer_grid():
    """gelatin-glass at 1 um/s: the old scan's Kc, 1.52e13 Pa/m from an oscillation at 5.6e8 Hz, was 3.5e13 and
    1.3e13 on grids twice and four times as fine (the aliasing moves).  Kc is now the runaway (real) mode's,
    max over s > 0 of -Z(s), which the grid twice as fine gives to 3e-5 (real s: no aliasing there)."""
    params = load_parameters("gelatin-glass")
    kc = critical_stiffness_details(params, 1e-6)
    # the finer grid's -Z(s) over the scan within a factor 3 of the returned rate (here the scan's top end, where
    # -Z still climbs; the whole scan on the finer grid, 1 122 rates, gives the same maximum in 2-3 s more)
    scan = SCAN / params.bonds.bond_time
    near = scan[(scan > kc.rate / 3.0) & (scan < kc.rate * 3.0)]
    fine = interface_response(params, 1e-6, near, cell_hazard=0.001).z.real
    assert near.size >= 20
    assert kc.mode == "real" and kc.value == pytest.approx(-fine.min(), rel=1e-4)
