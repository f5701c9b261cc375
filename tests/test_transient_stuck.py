"""A stuck block with saturating aging (issue 33 item 3): saturated cohorts merged, light ones dropped, same answer.

With ``aging.saturation_age`` the resting bonds die at a finite hazard, so the plain cohorts kept every cohort
until it weighed 1e-30 N0 (~1.7 s at the resting hazard, ~5e4 cohorts).  The kernel now merges cohorts past the
saturation age that lie in one bin of their log hazard (aging and force terms, width 0.1 sqrt(rtol)) and drops
those lighter than 1e-3 rtol of the bonds and of the stress, shared among the cohorts (docs/transient.md
section 2, *Housekeeping*).  The references: the plain cohorts (``plain_cohorts()``) at the same and at a ten
times tighter rtol, and the closed-form survival of a held steady population.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import expi

import stickslip
from stickslip.protocols import constant
from stickslip.transient import run_transient
from stickslip.transient.model import chain_force, plain_cohorts, steady_population

SAT = stickslip.load_parameters("gelatin-glass-saturating")
RTOL = 1e-4


def _stuck(duration: float, rtol: float, plain: bool = False):  # type: ignore[no-untyped-def]
    """50 um/s through the block from rest, cohorts throughout (the merging is what is compared)."""
    kw = {"rtol": rtol, "reduction": "off", "every": duration / 30, "snapshot_times": [duration]}
    if plain:
        with plain_cohorts():
            return run_transient(SAT, constant(50e-6, duration), **kw)
    return run_transient(SAT, constant(50e-6, duration), **kw)


@pytest.fixture(scope="module")
def stuck_runs():  # type: ignore[no-untyped-def]
    duration = 0.04  # 13 saturation ages: the bonds of the first 30 ms are merged
    return _stuck(duration, RTOL), _stuck(duration, RTOL, plain=True), _stuck(duration, 0.1 * RTOL, plain=True)


def test_the_merged_stuck_trace_is_the_plain_cohorts_trace(stuck_runs) -> None:  # type: ignore[no-untyped-def]
    """Same rtol: the merging and the births' own error bound (kernel._relaxed_births; the plain cohorts keep one
    lumped cohort's) change sigma by < 1e-3 rtol and N by < 0.1 rtol N0 (measured 1.7e-4 and 1.4e-2 rtol), with
    a third of the cohorts and fewer steps (566 against 1006)."""
    merged, plain, _tight = stuck_runs
    assert merged.steps < 0.7 * plain.steps
    assert np.array_equal(merged.time, plain.time)
    scale = np.max(np.abs(plain.stress))
    assert np.max(np.abs(merged.stress - plain.stress)) <= 1e-3 * RTOL * scale
    assert np.max(np.abs(merged.bonded_fraction - plain.bonded_fraction)) <= 0.1 * RTOL
    assert merged.snapshots[-1].weight.size < plain.snapshots[-1].weight.size / 3  # it did merge


def test_the_merged_stuck_trace_against_tighter_plain_cohorts(stuck_runs) -> None:  # type: ignore[no-untyped-def]
    """Against the plain cohorts at rtol/10: within 0.1 rtol of sigma and N0, as the plain cohorts at rtol."""
    merged, plain, tight = stuck_runs
    scale = np.max(np.abs(tight.stress))
    for run in (merged, plain):
        assert np.array_equal(run.time, tight.time)  # the every grid
        assert np.max(np.abs(run.stress - tight.stress)) <= 0.1 * RTOL * scale
        assert np.max(np.abs(run.bonded_fraction - tight.bonded_fraction)) <= 0.1 * RTOL


def test_dropped_and_merged_bonds_are_booked(stuck_runs) -> None:  # type: ignore[no-untyped-def]
    """N(0) + born - broken = N(t): dropped cohorts count as broken, merges keep the weight."""
    merged = stuck_runs[0]
    book = merged.bookkeeping
    n0 = SAT.bonds.site_density
    bonds = merged.bonded_fraction[0] * n0 + book.born - book.broken
    assert np.max(np.abs(bonds - merged.bonded_fraction * n0)) <= 1e-9 * n0


def _held_stress(population, t: float) -> float:  # type: ignore[no-untyped-def]
    """A population held still for t: each cohort keeps its force and ages on the saturating clock (closed form).

    At V = 0 a cohort of age a has the hazard (u0/tau) e^(c f) exp(-g (1 - e^(-a/t_s))), g = t_s/tau_a, so its
    cumulative hazard over [a0, a0 + t] is (u0/tau) e^(c f) t_s e^-g [Ei(g y0) - Ei(g y1)], y = e^(-a/t_s); bonds
    born during the hold sit at zero extension and carry nothing.
    """
    b, g = SAT.bonds, SAT.aging
    ts = g.saturation_age
    f = chain_force(population.extension, SAT)
    gam = ts / g.aging_time
    y0, y1 = np.exp(-population.age / ts), np.exp(-(population.age + t) / ts)
    big_h = b.breakage_weight / b.bond_time * np.exp(b.force_sensitivity * f) * ts * math.exp(-gam)
    big_h = big_h * (expi(gam * y0) - expi(gam * y1))
    return float(np.sum(population.weight * np.exp(-big_h) * f))


def test_a_held_creeping_population_follows_the_closed_form_survival() -> None:
    """The steady population of the creep branch (5 um/s: its bonds saturated) held still for 0.1 s.

    Its cohorts die at the resting hazard (~40/s, the stress falls 200-fold) and are merged and dropped: the
    stress follows the closed form to 0.1 rtol of its current value (measured: 3.5e-7 to 2.6e-6; the plain cohorts
    3e-10) with a quarter of the plain cohorts (1404 against 5991)."""
    velocity = 5e-6
    population = steady_population(SAT, velocity, True)
    kw = {"control": "velocity", "start": "steady", "start_velocity": velocity, "rtol": RTOL, "every": 0.025}
    times = [0.025, 0.05, 0.1]
    run = run_transient(SAT, constant(0.0, 0.1), snapshot_times=times, **kw)
    for t in times:
        row = int(np.argmin(np.abs(run.time - t)))
        assert run.time[row] == pytest.approx(t, rel=1e-12)
        assert run.stress[row] == pytest.approx(_held_stress(population, t), rel=0.1 * RTOL)
    with plain_cohorts():
        plain = run_transient(SAT, constant(0.0, 0.1), snapshot_times=times, **kw)
    assert run.snapshots[-1].weight.size < plain.snapshots[-1].weight.size / 3


def test_a_block_creeping_up_the_rising_branch_is_reduced() -> None:
    """Below Vc the saturating set's N-shaped curve has a rising creep branch: the quasi-steady reduction takes it.

    A steady start at 1 um/s on that branch, the puller at 50 um/s: 6513 steps reduced against 46 130 with the
    cohorts throughout (final sigma equal to 5e-9); before, a shortcut that took every velocity below Vc for the
    falling branch left the whole creep to the cohorts.  The slider ends on the steady curve to within the
    population's lag (~0.025 s x dsigma/dt, 0.2 %)."""
    from stickslip.quasistatic.steady import steady_state

    run = run_transient(SAT, constant(50e-6, 2.0), start="steady", start_velocity=1e-6, rtol=RTOL)
    assert run.steps < 10_000
    on_curve = float(steady_state(SAT, float(run.slider_velocity[-1])).stress)
    assert run.final_stress == pytest.approx(on_curve, rel=1e-2)
