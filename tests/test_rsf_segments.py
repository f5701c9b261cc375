"""Load-point histories found from displacement: up-and-back steps, staircases and holds, with noise."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip import protocols
from stickslip.errors import DataError
from stickslip.rsf.data import find_segments

UM = 1e-6
SEQUENCES = {
    "up and back": ([1, 10, 1], [100, 100, 100]),
    "up, back, third": ([1, 10, 1, 3], [50, 20, 200, 70]),
    "up, back, up": ([1, 10, 1, 10], [100, 100, 100, 100]),
    "staircase": ([0.3, 1, 3, 10, 30], [100, 60, 40, 30, 20]),
    "slide-hold-slide": ([1, 0, 1, 3], [50, 100, 50, 50]),
    "down staircase": ([30, 10, 3, 1], [20, 30, 60, 100]),
}


@pytest.mark.parametrize("name", sorted(SEQUENCES))
@pytest.mark.parametrize("noise", [0.0, 0.02 * UM])
def test_each_step_is_found_with_its_time_and_velocity(name, noise):
    velocities, durations = SEQUENCES[name]
    truth = protocols.velocity_steps([v * UM for v in velocities], durations)
    t = np.arange(0.0, truth.duration + 1e-9, 0.1)
    d = truth.displacement_at(t) + noise * np.random.default_rng(len(name)).standard_normal(t.size)
    found = find_segments(t, d)
    assert len(found.segments) == len(velocities), found.describe()
    # a slope over >= 20 s of 0.02 um scatter is known to ~1e-4 um/s; a change time to ~0.02 s
    assert found.velocities == pytest.approx(truth.velocities, abs=2e-3 * UM)
    assert found.boundaries == pytest.approx(truth.boundaries, abs=0.05)


def test_a_displacement_that_is_not_piecewise_linear_is_refused():
    t = np.linspace(0, 100, 2000)
    with pytest.raises(DataError, match="straight pieces"):
        find_segments(t, 1e-6 * t**2, max_segments=8)


def test_a_long_record_is_segmented_quickly_and_exactly():
    """50,000 rows: the search on block means, each break then placed on the full record."""
    import time

    truth = protocols.velocity_steps([v * UM for v in (1, 10, 1, 10, 1)], [1000.0] * 5)
    t = np.arange(0.0, truth.duration + 1e-9, 0.1)
    d = truth.displacement_at(t) + 0.05 * UM * np.random.default_rng(4).standard_normal(t.size)
    start = time.perf_counter()
    found = find_segments(t, d)
    assert time.perf_counter() - start < 3.0  # the full-resolution search took 13 s
    assert found.velocities == pytest.approx(truth.velocities, abs=1e-3 * UM)
    assert found.boundaries == pytest.approx(truth.boundaries, abs=0.05)


def test_a_record_with_the_load_point_velocity_instead_of_displacement(tmp_path):
    from stickslip.rsf.data import read_record

    truth = protocols.velocity_steps([v * UM for v in (1, 10, 1, 3)], [50, 20, 200, 70])
    t = np.arange(0.0, truth.duration + 1e-9, 0.1)
    path = tmp_path / "rig.txt"
    rows = zip(t, truth.velocity_at(t) / UM, 0.6 + 0 * t, strict=True)
    path.write_text("Time(s)\tVel(um/s)\tFriction\n" + "\n".join(f"{a:.2f}\t{v:g}\t{f}" for a, v, f in rows) + "\n")
    record = read_record(path, {"time": "Time(s)", "velocity": "Vel(um/s)", "friction": "Friction"})
    found = find_segments(record.time, record.displacement)
    assert found.velocities == pytest.approx(truth.velocities, rel=1e-6)
    # each step's first row carries the new velocity, and the step comes out at that row's time
    assert found.boundaries == pytest.approx(truth.boundaries, abs=1e-6)
    assert record.length_unit == "um"
