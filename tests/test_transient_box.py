"""The time-dependent model over the README's parameter box, against the steady solver (issue 17 section 4).

Velocity control: steady sliding is imposed, so after every bond of the start has been replaced the population
must sit on the steady solution of Eqs 6-8, which the steady solver computes by a different method (adaptive
panels in age, DOP853-checked over the box in tests/test_robust_box.py).  The error allowed is 10 x rtol.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from reference_steady import box_case
from stickslip import ModelError, load_parameters, steady_state
from stickslip.protocols import constant
from stickslip.transient import run_transient
from stickslip.transient.model import steady_population
from stickslip.transient.solver import estimate_cost

GEL = load_parameters("gelatin-glass")
RTOL = 1e-4
#: sets whose run would need more steps than this are redrawn (the box spans 1e-9..1 s bond times and ages up to
#: dl_m/V = 1e7 s; a CI test cannot afford every corner): the count of redrawn sets is asserted below
STEP_CAP = 30_000
SETS = 60

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


def _cases(seed: int, count: int):
    """``count`` runnable (params, V, aging, duration) from a fixed seed, and how many draws were redrawn."""
    rng = np.random.default_rng(seed)
    cases, redrawn = [], 0
    while len(cases) < count:
        params, velocity, aging = box_case(rng, GEL, corner=bool(rng.integers(2)))
        try:
            duration = 2.0 * _oldest(params, velocity, aging)
            cost = estimate_cost(params, constant(velocity, duration), control="velocity", rtol=RTOL, aging=aging)
        except ModelError:
            redrawn += 1
            continue
        if not math.isfinite(cost.steps) or cost.steps > STEP_CAP:
            redrawn += 1
            continue
        cases.append((params, velocity, aging, duration))
    return cases, redrawn


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
    """60 sets over the README box (half in issue 12's deep-dip/cliff corner), steady start, two lifetimes."""
    cases, redrawn = _cases(2017, SETS)
    assert redrawn < 3 * SETS  # most of the box is affordable; the rest is said above
    worst, start = 0.0, time.process_time()
    for params, velocity, aging, duration in cases:
        ref = steady_state(params, velocity, aging=aging)
        run = run_transient(
            params, constant(velocity, duration), control="velocity", start="steady", aging=aging, rtol=RTOL
        )
        for got, want in (
            (run.final_stress, float(ref.stress)),
            (run.final_bonded_fraction, float(ref.bonded_fraction)),
        ):
            error = abs(got / want - 1)
            worst = max(worst, error)
            assert error <= 10 * RTOL, (params, velocity, aging, got, want)
    assert time.process_time() - start < 30.0
    assert worst > 0.0  # the comparison compared something


@pytest.mark.parametrize("seed", [7])
def test_random_box_from_empty_relaxes_to_the_steady_curve(seed):
    """From an empty surface (the audit's start): after the oldest steady age twice over, on the steady curve."""
    cases, _ = _cases(seed, 12)
    for params, velocity, aging, duration in cases:
        ref = steady_state(params, velocity, aging=aging)
        run = run_transient(params, constant(velocity, 2.0 * duration), control="velocity", aging=aging, rtol=RTOL)
        assert abs(run.final_stress / float(ref.stress) - 1) <= 10 * RTOL, (params, velocity, aging)
