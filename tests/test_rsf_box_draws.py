"""Draws over the physical box that escaped as an internal exception (round 35's survey of 600 random sliders).

Aging law, a = 0.0101, b = -0.0115 (strongly rate-strengthening), Dc = 0.618 um, k = 95,578 1/m, eta = 0.0189 s/m,
a mass of 8.2e-5 kg/m^2 at 1 MPa (inertial time 3e-16 s), stepped 0.512 -> 0.0382 -> 0.512 um/s: the run reached
its end and then raised ``AttributeError: 'list' object has no attribute 'T'`` from the settled mean's short
integration, whose Radau solve reached none of its two times (scipy then leaves ``y`` a list).  The reference is
the closed form of steady sliding, mu_ss = mu0 + (a - b) ln(V / V0), which a stable slider reaches.
"""

from __future__ import annotations

import math

import pytest

from stickslip.errors import ModelError
from stickslip.models.rsf import rsf_run
from stickslip.protocols import Protocol, Segment
from stickslip.rsf import simulate
from stickslip.rsf.params import RSFParams, StateVariable

A, B, V0 = 0.010134025461975366, -0.011511930775113078, 5.864006576060988e-07
HEAVY = RSFParams(a=A, states=(StateVariable(law="aging", b=B, dc=6.176334011235949e-07),), mu0=0.5, v_ref=V0,
                  stiffness=95578.50291832177, eta=0.01885834054320317, mass=8.153509137167719e-05,
                  normal_stress=1e6)  # fmt: skip
FAST, SLOW = 5.122053367862449e-07, 3.819172545354822e-08
STEPS = Protocol((Segment(FAST, 50.0), Segment(SLOW, 100.0), Segment(FAST, 100.0)))


def test_a_run_whose_settled_mean_cannot_be_integrated_ends_steady_with_the_rows_mean():
    run = simulate(HEAVY, STEPS)
    assert run.status == "ok" and run.regime.kind == "steady"
    steady = 0.5 + (A - B) * math.log(FAST / V0)
    assert run.friction[-1] == pytest.approx(steady, abs=1e-7)
    assert math.isnan(run.settled_mean_friction)  # the solver's integral could not be had: said, not invented
    model_run = rsf_run(run)  # what `run --model rsf` and the sweeps read
    assert model_run.summary["mean_friction"] == pytest.approx(steady, abs=1e-6)  # the rows' over the settled window
    assert model_run.mean == pytest.approx(steady * 1e6, abs=1.0)  # in Pa at 1 MPa


def test_the_same_run_sampled_is_refused_for_its_negligible_inertia_not_said_to_have_stopped():
    """Sampled, a Radau trial step underflowed V (ZeroDivisionError in m dV/dt): it read "the slider stopped", a
    physical claim the unsampled run above contradicts.  An inertial time of 3e-16 s beside a 100 s segment cannot
    stop a slider; the refusal now says what is true and what to do (the words a tiny inertia gets elsewhere)."""
    with pytest.raises(ModelError) as refused:
        simulate(HEAVY, STEPS, every=0.5)
    text = str(refused.value)
    assert "the slider stopped" not in text
    assert "mV/(σa) = 3.07e-16 s" in text and "too short beside the run (100 s)" in text and "drop the mass" in text
