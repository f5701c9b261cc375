"""Round 31 (tester Y's box of transient runs through the block, set 18 and four others): the stick chains of a set
whose steady curve with aging has no minimum.

From rest the chains hold the block until Eq 15 lets them go; the paper's jump then lands on the steady curve beyond
its minimum, and here there is none (the curve falls monotonically: velocity-weakening throughout).  The run raised
the critical point's ModelError at the collapse, discarding the stick it had computed, and the cost estimate, which
met the same error, counted the cohorts at the puller's pace throughout: a 2 s run that takes no step (0.3 s of CPU)
was refused as "about 7.02 min of CPU ... more than 3 x the time budget of 30 s".  Now the estimate stops at the
collapse as for a landing beyond the curve's reach, and the run stops there with the words of the critical point.
"""

from __future__ import annotations

import re

import numpy as np

import stickslip
from stickslip.protocols import constant
from stickslip.quasistatic.steady import steady_state
from stickslip.transient import run_transient
from stickslip.transient.solver import estimate_cost

#: tester Y's box set 18 (seed 1, each key of the paper's set times 10^U(-1, 1)) and its puller velocity (m/s)
SET_18 = {
    "bonds.site_density": 22424228692776.08,
    "bonds.bond_time": 0.00013295637467364697,
    "bonds.chain_stiffness": 4.768587824342073e-05,
    "bonds.activation_length": 5.608960775066552e-10,
    "bonds.max_extension": 7.387718111634027e-07,
    "aging.aging_time": 0.00013117458647371466,
    "aging.aging_velocity": 0.002569880360771096,
    "stick.attached_chains": 3635775618061.1416,
    "stick.break_rate": 2.3963362044932087e-05,
    "stick.aging_time": 1.6840241686886535,
    "block.shear_modulus": 3419.215500682807,
    "block.height": 0.0015281920335426943,
    "bonds.temperature": 302.17958313453613,
    "bonds.breakage_weight": 0.4134126782127875,
}
PULLER = 1.2028275631947131e-05


def _params() -> stickslip.Parameters:
    return stickslip.load_parameters("gelatin-glass").with_overrides(SET_18)


def test_the_steady_curve_has_no_minimum() -> None:
    """Independently of the critical-point search: σ(V) of the steady solver falls at every point of a log grid."""
    stress = steady_state(_params(), np.geomspace(1e-8, 1.0, 400)).stress
    assert np.all(np.diff(stress) < 0)


def test_a_run_that_ends_before_the_collapse_is_not_refused_and_takes_no_step() -> None:
    protocol = constant(PULLER, 2.0)
    assert estimate_cost(_params(), protocol, stick_population=True).steps <= 100  # measured 10; was 3.1e5
    run = run_transient(_params(), protocol, stick_population=True, max_time=30.0)
    assert run.steps == 0 and run.regime == "undetermined"
    collapse = float(re.search(r"collapse at t = ([\d.]+) s", run.message).group(1))
    assert collapse > 2.0  # measured 33.4694 s


def test_the_run_stops_at_the_collapse_in_words() -> None:
    """40 s: the chains go at t_s, σs = K Vp t_s (the block held since σ = 0); the run stops there, failed, saying
    why there is no landing point."""
    params = _params()
    run = run_transient(params, constant(PULLER, 40.0), stick_population=True, max_time=30.0)
    assert run.status == "failed" and run.steps == 0
    assert "no landing point" in run.message and "has no minimum" in run.message, run.message
    sigma_s = float(re.search(r"σs = ([\d.]+) Pa", run.message).group(1))
    t_s = float(re.search(r"stops at t = ([\d.]+) s", run.message).group(1))
    assert abs(sigma_s / (params.block.effective_stiffness * PULLER * t_s) - 1) < 1e-5
    assert abs(float(run.time[-1]) - t_s) < 1e-5 * t_s
