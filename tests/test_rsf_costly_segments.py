"""A segment that needs many evaluations is run, or refused for its projected cost, never called "stalled".

A random draw over the physical box (round 35): slip law, a = 0.0255, b = 0.0591, Dc = 0.287 um, k = 1608 1/m,
eta = 0.0145 s/m, 100 s at 2.44 mm/s: fast stick-slip that needs 2.5 million evaluations, ~40,000 a cycle, and a
clock that never stops.  The unsampled run was refused at 1 million ("stalled at t = 90.09 s ... too stiff") while
the same run sampled with every=0.5 s was "ok, stick-slip".  Here the limits are scaled down 25 times (MAX_CALLS
40,000, MAX_PROJECTED_CALLS 400,000) so that the same story costs seconds; the reference is the sampled run
(odeint, no limit), whose regime is read off the same accepted steps.
"""

from __future__ import annotations

import pytest

from stickslip.errors import ModelError
from stickslip.protocols import Protocol, Segment
from stickslip.rsf import simulate
from stickslip.rsf import solver as rsf_solver
from stickslip.rsf.params import RSFParams, StateVariable

FAST = RSFParams(a=0.025510091761319062, states=(StateVariable(law="slip", b=0.05911154837064979,
                 dc=2.8670057348126295e-07),), mu0=0.5, v_ref=5.5626820835403567e-05, stiffness=1608.4701664722518,
                 eta=0.014528505581351155)  # fmt: skip
SLOW, QUICK = 0.00017182782442952545, 0.0024363252895783357  # m/s


@pytest.fixture
def scaled_limits(monkeypatch):
    monkeypatch.setattr(rsf_solver, "MAX_CALLS", 40_000)
    monkeypatch.setattr(rsf_solver, "MAX_PROJECTED_CALLS", 400_000)


def test_a_segment_past_max_calls_on_a_steady_pace_runs_to_its_end_as_the_sampled_run_does(scaled_limits):
    protocol = Protocol((Segment(SLOW, 5.0), Segment(QUICK, 10.0)))  # ~250,000 evaluations in the second
    unsampled = simulate(FAST, protocol)
    sampled = simulate(FAST, protocol, every=0.1)
    assert unsampled.status == sampled.status == "ok"
    assert unsampled.time[-1] == pytest.approx(15.0, rel=1e-12)
    assert unsampled.regime.kind == sampled.regime.kind == "stick-slip"
    assert unsampled.regime.periods == sampled.regime.periods > 50
    assert unsampled.regime.period == pytest.approx(sampled.regime.period, rel=1e-6)
    assert unsampled.regime.peak == pytest.approx(sampled.regime.peak, rel=1e-8)


@pytest.mark.parametrize("every", [None, 0.1], ids=["unsampled", "sampled"])
def test_a_segment_whose_pace_projects_past_the_limit_is_refused_for_its_cost_in_words(scaled_limits, every):
    protocol = Protocol((Segment(SLOW, 5.0), Segment(QUICK, 30.0)))  # ~750,000 in the second
    with pytest.raises(ModelError) as refused:
        simulate(FAST, protocol, every=every)
    text = str(refused.value)
    assert "the segment 5 ... 35 s took" in text and "on pace for about" in text and "more than 400,000" in text
    assert "stalled" not in text and "too stiff" not in text
