"""A slider with mass far below V0: LSODA kept to its explicit steps, each held to the inertial time
m V/(sigma a) = 1e-12 s (3e-10 s steps), and the run stalled after 1e6 evaluations (19.5 s of CPU, then an
error) on 100 s of a regularised law at 1.5e-11 m/s.  The solver now sees from LSODA's pace that the piece
would need more than 1e8 evaluations and takes implicit (Radau) steps from then on.

Checked against the massless slider (an independent system of equations: its inertia, 1e-12 s beside a run of
100 s, changes nothing that can be measured) and against scipy's BDF on the same equations."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from stickslip.models import get_model
from stickslip.protocols import constant
from stickslip.rsf import simulate
from stickslip.rsf.system import System

SLOW, START = 1.5e-11, 1e-10


def _params(mass: float, regularized: bool = True):
    base = get_model("rsf").parameters(None, {"normal_stress": "1 MPa"})
    return dataclasses.replace(base, mass=mass, regularized=regularized)


@pytest.mark.parametrize("every", [None, 10.0])
def test_a_slider_with_mass_far_below_v0_runs_in_seconds(every):
    protocol = constant(SLOW, 100.0)
    start = time.process_time()
    heavy = simulate(_params(100.0), protocol, start_velocity=START, every=every)
    spent = time.process_time() - start
    light = simulate(_params(0.0), protocol, start_velocity=START, times=heavy.time)  # at the same times
    assert heavy.status == "ok" and np.array_equal(heavy.time, light.time)
    assert heavy.friction == pytest.approx(light.friction, rel=1e-10, abs=0)
    assert heavy.slider_velocity == pytest.approx(light.slider_velocity, rel=1e-7, abs=0)
    assert heavy.run_mean_friction == pytest.approx(light.run_mean_friction, rel=1e-12)
    assert heavy.slider_velocity[-1] < 0.9995 * START  # (the slider did slow down: the run is not trivial)
    assert spent < 8.0  # was 19.5 s, then a "stalled" error; 1 s now


def test_the_implicit_steps_agree_with_scipy_bdf():
    params = _params(100.0, regularized=False)
    run = simulate(params, constant(SLOW, 100.0), start_velocity=START, every=25.0)
    system = System(params)
    bdf = solve_ivp(system.rhs, (0.0, 100.0), system.steady_y(START), method="BDF", t_eval=run.time, args=(SLOW,),
                    jac=system.jacobian, rtol=1e-11, atol=1e-13)  # fmt: skip
    assert bdf.status == 0
    assert run.friction == pytest.approx(system.friction_many(bdf.y[1], bdf.y[2:]), rel=1e-10, abs=0)


def test_the_implicit_path_reads_its_regime_off_the_same_steps_whatever_the_sampling():
    """Radau's error norm is a mean over all the unknowns: the run's steps carrying the integral of friction were not
    those of the equations alone, which a sampled run reads its regime off; the approach's 'still to come' (a
    ratio of two changes ~1e-5 of mu, near 1) then read 0.00996 unsampled and 0.0103 sampled."""
    params = _params(100.0)
    found = {
        every: simulate(params, constant(SLOW, 100.0), start_velocity=START, every=every).regime
        for every in (None, 10.0, 3.0)
    }
    assert found[None].kind == "undetermined" and "still to come" in found[None].evidence
    assert len({regime.evidence for regime in found.values()}) == 1, found
    assert len({(regime.peak, regime.trough) for regime in found.values()}) == 1, found
