"""Round 30, tester Y's D2: a plain velocity step under velocity control (docs/transient.md section 24).

At a velocity step V -> 3 V, Eq 1 as printed erases the aging term at the velocity's pace: the oldest bonds of the
steady population at V, whose aging held them against the FENE force, get ln r up to ~139 at once and die within
far less than the clock resolves.  The kernel's step collapsed to its floor there (a step may lose at most a fifth of
sigma) and the run failed, in words about a hold the protocol did not have.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip import load_parameters, protocols, steady_state
from stickslip.transient import run_transient
from stickslip.transient import solver as S

#: tester Y's box set 31 (0.1x-10x of the paper's set), at V = 49.3 um/s
SET_31 = {
    "bonds.site_density": 199409040665040.4,
    "bonds.bond_time": 5.4128552150749284e-05,
    "bonds.chain_stiffness": 1.719028791135115e-05,
    "bonds.activation_length": 1.027886750754599e-10,
    "bonds.max_extension": 4.592245472767904e-06,
    "aging.aging_time": 0.0002442834550602882,
    "aging.aging_velocity": 5.088243547249774e-05,
    "stick.attached_chains": 2618546780734.955,
    "stick.break_rate": 3.386587740956377e-05,
    "stick.aging_time": 1.364103869801157,
    "block.shear_modulus": 14079.563388442988,
    "block.height": 0.043898856954105184,
    "bonds.temperature": 286.36731900536626,
    "bonds.breakage_weight": 0.19682323252789943,
}
V_31 = 4.929492652112578e-05


def _after_step(params, v, v2, delta, ages=20000, substeps=200) -> float:  # type: ignore[no-untyped-def]
    """Independent of the cohort code: sigma at delta after a step v -> v2 under velocity control from steady
    sliding at v, the steady age density built from Eq 1 directly (B S(a), B = N0/(tau + int S)) and each age
    class carried through delta at v2 by the trapezoid rule in time; the bonds born within delta (extension below
    v2 delta, ~1e-10 m) are left out (their stress is below 1e-5 of sigma at delta = 1 us here)."""
    b, g = params.bonds, params.aging
    lam, m, dl = b.force_sensitivity, b.chain_stiffness, b.max_extension

    def log_rate(e, age, vel):  # type: ignore[no-untyped-def]
        y = e / dl
        aging = age / g.aging_time * math.exp(-vel / g.aging_velocity)
        return math.log(b.breakage_weight / b.bond_time) + lam * m * e / (1 - y * y) - aging

    z = np.linspace(0.0, 1.0, ages + 1)[:-1]
    a = dl / v * (1.0 - (1.0 - z) ** 3)  # ages clustered at the FENE wall
    r = np.exp(np.minimum(log_rate(v * a, a, v), 700.0))
    survival = np.exp(-np.concatenate([[0.0], np.cumsum(0.5 * (r[1:] + r[:-1]) * np.diff(a))]))
    births = b.site_density / (b.bond_time + np.sum(0.5 * (survival[1:] + survival[:-1]) * np.diff(a)))
    density = births * survival
    live = v * a + v2 * delta < dl * (1.0 - 1e-12)
    a, density = a[live], density[live]
    s = np.linspace(0.0, delta, substeps + 1)
    rates = np.exp(np.minimum(np.array([log_rate(v * a + v2 * sk, a + sk, v2) for sk in s]), 700.0))
    lost = np.sum(0.5 * (rates[1:] + rates[:-1]) * np.diff(s)[:, None], axis=0)
    e = v * a + v2 * delta
    y = e / dl
    stress = density * np.exp(-lost) * m * e / (1.0 - y * y)
    return float(np.sum(0.5 * (stress[1:] + stress[:-1]) * np.diff(a)))


def test_a_velocity_step_that_erases_the_aging_of_old_bonds_runs_and_settles():
    """Tester Y's set 31: V -> 3 V after 20 ms failed at t = 0.02 s ("the step down to 1.73e-17 s ... aged at rest
    (a hold)").  Now the bonds that die within the clock's resolution are broken at once: sigma 1 us after the step
    is that of an independent integration of Eq 1 (measured 3.9e-7 off), and the run settles on the steady curve
    at 3 V (the steady solver: 129.6 Pa, from 32 565 Pa at V)."""
    params = load_parameters("gelatin-glass").with_overrides(SET_31)
    v, v2 = V_31, 3.0 * V_31
    run = run_transient(
        params, protocols.velocity_steps([v, v2, v2], [0.02, 1e-6, 0.06]), control="velocity", start="steady"
    )
    assert run.status == "ok" and run.regime == "steady", run.message
    assert "died at once" in run.message and "hold" not in run.message
    t, sigma = np.asarray(run.time), np.asarray(run.stress)
    at = np.flatnonzero(np.isclose(t, 0.02 + 1e-6, rtol=0.0, atol=1e-12))
    assert at.size, "the protocol's boundary is a row"
    reference = _after_step(params, v, v2, 1e-6)
    assert sigma[at[-1]] == pytest.approx(reference, rel=1e-4)  # measured 3.9e-7; sigma(V) is 1.7x higher
    assert sigma[0] == pytest.approx(_after_step(params, v, v, 0.0), rel=1e-4)  # the start, the same way
    settled = float(steady_state(params, v2).stress)
    assert sigma[-1] == pytest.approx(settled, rel=1e-4)
    assert sigma.min() >= settled * (1 - 1e-4)  # no undershoot below the new steady stress


def test_a_collapse_under_velocity_control_says_a_hold_only_where_there_was_one():
    """The words of a collapsed step under velocity control named "aged at rest (a hold)" and "a shorter hold stays
    within it" whatever the protocol; now the cohort's time at rest is read from the protocol."""
    params = load_parameters("gelatin-glass")
    dl = params.bonds.max_extension
    t, v = 300.004, 100e-6
    state = S._State(
        t=t, x=1.0, v=v, h=1e-13, puller=1.0, n=1, xb=np.array([1.0 - 0.99999 * dl]), tb=np.array([0.5]),
        lw=np.array([math.log(1e12)]),
    )  # fmt: skip
    held = protocols.velocity_steps([v, 0.0, v], [2e-3, 300.0, 15e-3])
    words = S._rigid_collapse(state, params, True, held)
    assert "aged at rest (a hold: 300 s of it)" in words and "a shorter hold" in words
    sliding = protocols.velocity_steps([v / 3, v], [300.0, 15e-3])
    words = S._rigid_collapse(state, params, True, sliding)
    assert "aged while sliding (no hold)" in words
    assert "at rest" not in words and "a shorter hold" not in words


#: tester Y's box set 49, at V = 44.2 um/s
SET_49 = {
    "bonds.site_density": 84260878465492.25,
    "bonds.bond_time": 0.0021163610381933983,
    "bonds.chain_stiffness": 6.774498743915186e-05,
    "bonds.activation_length": 2.3191951961864026e-11,
    "bonds.max_extension": 3.937008951501478e-06,
    "aging.aging_time": 0.00031419386193021204,
    "aging.aging_velocity": 0.0004873174493704911,
    "stick.attached_chains": 4055090071998.94,
    "stick.break_rate": 3.5114181692045736e-05,
    "stick.aging_time": 1.1716930971649964,
    "block.shear_modulus": 37681.36949529819,
    "block.height": 0.0431300822301476,
    "bonds.temperature": 268.8192864765886,
    "bonds.breakage_weight": 0.7046434675490687,
}
V_49 = 4.419015291372315e-05


def test_the_integral_of_sigma_and_the_work_stay_finite_sized_across_a_velocity_step():
    """Set 49: the first step after V -> 3 V (0.46 us) booked -2.7e12 Pa s of the integral of sigma and -3.6e8 J/m^2
    of the puller's work: the step's end correction h/12 (dsigma/dt1 - dsigma/dt0), with dsigma/dt ~ -1e19 Pa/s at
    its start where old bonds' aging was erased.  Both against the trapezoid rule over the trace's own rows
    (measured 4e-7 and 2e-5 apart)."""
    params = load_parameters("gelatin-glass").with_overrides(SET_49)
    v = V_49
    run = run_transient(params, protocols.velocity_steps([v, 3 * v], [0.02, 1e-4]), control="velocity", start="steady")
    t, sigma = np.asarray(run.time), np.asarray(run.stress)
    books = run.bookkeeping
    assert np.all(np.diff(books.stress_integral) >= 0)  # sigma > 0 throughout
    assert books.stress_integral[-1] == pytest.approx(np.trapezoid(sigma, t), rel=1e-4)
    pace = np.where(t <= 0.02, v, 3 * v)
    assert books.work[-1] == pytest.approx(np.trapezoid(sigma * pace, t), rel=1e-3)
