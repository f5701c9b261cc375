"""The time-dependent model over the README's parameter box, against the steady solver (issue 17 section 4).

Velocity control: steady sliding is imposed, so after every bond of the start has been replaced the population
must sit on the steady solution of Eqs 6-8, which the steady solver computes by a different method (adaptive
panels in age, DOP853-checked over the box in tests/test_robust_box.py).  The error allowed is 10 x rtol.
"""

from __future__ import annotations

import time

import numpy as np

from reference_steady import box_case
from stickslip import load_parameters, steady_state
from stickslip.errors import ParameterError
from stickslip.protocols import constant
from stickslip.transient import run_transient
from stickslip.transient.model import steady_population

GEL = load_parameters("gelatin-glass")
RTOL = 1e-4
#: each set runs under this step budget (the solver's own cost bound): a set whose run would need more is
#: refused up front or stopped in one line, which is the behaviour under test for it; the box spans bond times
#: of 1e-9..1 s and ages up to dl_m/V = 1e7 s, and a CI test cannot afford every corner.  The sets checked take
#: 65-1103 steps; the seven stopped at the budget took 17 of the test's 24 s at 3000 steps (their cohorts
#: outnumber the others'), 5 s at 2000.  At 2000 one checked set (the 43rd draw, 193 steps, estimated 20947: the
#: estimate's caution under velocity control with a steady start) is refused up front and the 67th is checked
#: instead
BUDGET = 2000
SETS = 50
#: the steady start's quadrature in age (two Gauss cohorts per cell) over the box
START_TOLERANCE = 1e-2
MOST_DRAWS = 90

#: issue 17's audit set: bonds live ~40 us and die within ~3 us, while the steps were ~10 us
AUDIT = {
    "bonds.site_density": 1.12e14,
    "bonds.bond_time": 0.358,
    "bonds.breakage_weight": 0.0377,
    "bonds.chain_stiffness": 0.0554,
    "bonds.activation_length": 3.62e-11,
    "bonds.max_extension": 24.4e-6,
    "aging.aging_time": 8.56,
    "aging.aging_velocity": 73.2e-6,
}


def _oldest(params, velocity, aging):
    return float(np.max(steady_population(params, velocity, aging).age))


def test_audit_set_from_empty_stays_on_the_steady_curve():
    """Issue 17: sigma ended 4.6e-3 below the steady curve at rtol 1e-4 with nothing in the error estimate."""
    params = GEL.with_overrides(AUDIT)
    velocity = 703e-6
    ref = float(steady_state(params, velocity).stress)
    run = run_transient(params, constant(velocity, 0.008), control="velocity", rtol=RTOL)
    for t in (1e-3, 4e-3, 8e-3):
        k = int(np.searchsorted(run.time, t))
        assert abs(run.stress[k] / ref - 1) <= 10 * RTOL, (t, run.stress[k] / ref - 1)


def test_random_box_steady_sliding_matches_the_steady_solver():
    """>= 50 sets over the README box (half in issue 12's deep-dip/cliff corner): steady start, then the oldest
    steady age four times over (every initial bond replaced, and the renewal echo of the start faded), final
    sigma and N/N0 against the steady solver."""
    rng = np.random.default_rng(2017)
    checked, refused, worst = 0, 0, 0.0
    start = time.process_time()
    for _ in range(MOST_DRAWS):
        params, velocity, aging = box_case(rng, GEL, corner=bool(rng.integers(2)))
        ref = steady_state(params, velocity, aging=aging)
        duration = 4.0 * _oldest(params, velocity, aging)
        try:
            run = run_transient(params, constant(velocity, duration), control="velocity", start="steady",
                                aging=aging, rtol=RTOL, max_steps=BUDGET)  # fmt: skip
        except ParameterError as exc:
            assert "budget" in str(exc)
            refused += 1
            continue
        # the steady start itself (Eqs 6-8 as cohorts): sized from each cell's start alone, a cell swallowed the
        # whole population in 1 draw in 10 (sigma 100 % off); now the worst of 200 draws is 6.6e-3
        assert abs(run.stress[0] / float(ref.stress) - 1) <= START_TOLERANCE, (params, velocity, aging)
        for got, want in ((run.final_stress, ref.stress), (run.final_bonded_fraction, ref.bonded_fraction)):
            error = abs(got / float(want) - 1)
            worst = max(worst, error)
            assert error <= 10 * RTOL, (params, velocity, aging, got, float(want))
        checked += 1
        if checked == SETS:
            break
    assert checked == SETS, (checked, refused)
    assert 0.0 < worst
    assert time.process_time() - start < 60.0  # measured ~11 s on the project's 2-core machine
