"""The measured load point when the levels are not straight pieces: a servo whose speed drifts slowly within each
level (so ``find_segments`` refuses the record as not piecewise linear) must still keep each velocity step as a
kink, at one instant located from the displacement, and follow the slow acceleration between steps with the
smoothed pieces (docs/rsf.md, "The measured load point").  Before, such a record was smoothed whole and each
step ramped over ~0.4 s in four segments; a fit driven by it said "ok" with every interval missing the truth.

Records are made here from a known, analytic load point; the truth is never the code's own output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip.errors import DataError
from stickslip.protocols import Protocol, Segment
from stickslip.rsf.data import LabRecord, find_segments, measured_history

UM = 1e-6
ROW = 0.1  # s
NOISE = 0.01 * UM  # displacement noise (white), m


def accelerating_levels(levels: list[tuple[float, float, float]], pieces: int = 200) -> Protocol:
    """Levels (velocity in um/s, duration in s, relative change of speed across the level, e.g. +0.06 for
    -3 % -> +3 %) whose speed varies linearly within each level, as many tiny constant pieces (0.03 % apart for
    a 6 % drift over 200 pieces, far below what a record resolves); the steps between levels are instantaneous."""
    items = []
    for v, duration, drift in levels:
        for j in range(pieces):
            items.append(Segment(v * UM * (1.0 + drift * ((j + 0.5) / pieces - 0.5)), duration / pieces))
    return Protocol(tuple(items), name="truth")


def record_of(truth: Protocol, seed: int, friction: np.ndarray | None = None) -> tuple[np.ndarray, LabRecord]:
    t = np.arange(0.0, truth.duration + 1e-9, ROW)
    exact = truth.displacement_at(t)
    d = exact + NOISE * np.random.default_rng(seed).standard_normal(t.size)
    return exact, LabRecord.from_arrays(t, d, 0.6 + 0.0 * t if friction is None else friction)


def step_times(levels: list[tuple[float, float, float]]) -> np.ndarray:
    return np.cumsum([duration for _, duration, _ in levels])[:-1]


CASES = {
    "up and back, +-3 %": [(1.0, 60.0, 0.06), (10.0, 40.0, 0.06), (1.0, 60.0, 0.06)],
    "down and back, +-10 %": [(10.0, 40.0, 0.2), (1.0, 60.0, -0.2), (10.0, 40.0, 0.2)],
    "3 -> 1 -> 3, -+3 %": [(3.0, 50.0, -0.06), (1.0, 80.0, 0.06), (3.0, 50.0, -0.06)],
}


@pytest.mark.parametrize("seed", [1, 2])
@pytest.mark.parametrize("levels", list(CASES.values()), ids=list(CASES))
def test_a_step_between_accelerating_levels_stays_a_kink(levels, seed):
    """Each step is a change of velocity at one instant within a few sigma_t = sqrt(2) noise / |dv| of the truth
    (no ramp of intermediate pieces across it), the pieces either side at the truth's speeds there, and the whole
    history within a few noise of the TRUE load point (the smeared step missed it by ~50 noise)."""
    truth = accelerating_levels(levels)
    exact, record = record_of(truth, seed)
    with pytest.raises(DataError, match="straight pieces"):  # the case: not piecewise linear
        find_segments(record.time, record.displacement)
    history = measured_history(record)
    edges, speeds = history.boundaries, history.velocities
    for when in step_times(levels):
        before, after = truth.velocity_at(when - 1e-6), truth.velocity_at(when + 1e-6)
        sigma_t = math.sqrt(2.0) * NOISE / abs(after - before)
        j = int(np.argmin(np.abs(edges - when)))
        assert abs(edges[j] - when) < 5 * sigma_t, (when, edges[j - 2 : j + 3])
        # one instant: over 1.5 s either side of it the history moves at the two levels' speeds (a smeared step
        # ramped through speeds in between for ~0.4 s)
        for lo, hi in ((when - 1.5, when), (when, when + 1.5)):
            moved = np.diff(history.displacement_at(np.array([lo, hi])))[0]
            assert moved == pytest.approx(np.diff(truth.displacement_at(np.array([lo, hi])))[0], rel=0.05), (lo, hi)
    miss = history.displacement_at(record.time) - exact
    miss -= miss.mean()
    assert np.max(np.abs(miss)) < 4 * NOISE
    assert np.all(speeds >= 0) and history.duration == pytest.approx(record.time[-1], rel=1e-12)


def test_a_smooth_ramp_between_accelerating_levels_is_no_kink():
    """A servo's 3 s ramp from 1 to 10 um/s between drifting levels is no step: no kink is put into it (no two
    neighbouring pieces differ by half the ramp's change), and the history follows it within a few noise."""
    t = np.arange(0.0, 100.0, ROW)
    fine = np.linspace(0.0, 100.0, 200_001)
    v = np.interp(fine, [0, 40, 43, 100], [0.97, 1.03, 10.0 * 0.97, 10.0 * 1.03]) * UM
    x = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(fine))])
    exact = np.interp(t, fine, x)
    record = LabRecord.from_arrays(t, exact + NOISE * np.random.default_rng(5).standard_normal(t.size), 0.6 + 0 * t)
    history = measured_history(record)
    miss = history.displacement_at(t) - exact
    assert np.max(np.abs(miss - miss.mean())) < 5 * NOISE  # as the levels' smoothing alone follows it
    edges, speeds = history.boundaries, history.velocities
    inside = (edges[1:-1] > 39.0) & (edges[1:-1] < 44.0)
    jumps = np.abs(np.diff(speeds))[inside]
    assert np.all(jumps < 0.5 * 9.0 * UM)  # a kink would carry most of the 9 um/s at once


def test_a_fit_driven_by_the_measured_history_covers_the_truth():
    """RSF (a = 0.008, b = 0.012, Dc = 20 um, k = 3000 1/m) driven by levels 1 -> 10 -> 1 um/s drifting +-3 %:
    driven by the measured history, the intervals of a, b, Dc and k hold the truth (smeared, every one missed)."""
    from stickslip import rsf
    from stickslip.rsf.fit import fit_record

    levels = [(1.0, 40.0, 0.06), (10.0, 30.0, 0.06), (1.0, 40.0, 0.06)]
    truth = accelerating_levels(levels, pieces=40)
    params = rsf.rsf_params(0.008, 0.012, 20 * UM, law="aging", stiffness=3000.0, mu0=0.6, v_ref=1 * UM)
    t = np.arange(0.0, truth.duration + 1e-9, ROW)
    friction = np.asarray(rsf.simulate(params, truth, times=t).to_frame()["friction"])
    friction = friction + 2e-4 * np.random.default_rng(7).standard_normal(t.size)
    _, record = record_of(truth, 8, friction)
    fit = fit_record(record, protocol=measured_history(record), drift_check=False)
    assert fit.status == "ok"
    for key, value in (("a", 0.008), ("b", 0.012), ("dc", 20 * UM), ("stiffness", 3000.0)):
        lo, hi = fit.parameters[key].interval
        assert lo <= value <= hi, (key, fit.parameters[key])
