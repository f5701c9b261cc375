"""The found history's change times as nuisance parameters of the rate-and-state fit (docs/rsf.md, "What the
history's own uncertainty does to a fit").

Records made from a known truth (tests/records/make_records.py: quantised displacement with AR(1) noise, RSF friction
plus white noise).  Driven by the levels found from the displacement with the change times held where the
displacement dates them (a history given to ``fit_record`` is held), the intervals miss the truth; with the change
times fitted they hold it, chi-square_r falls to about 1, and the fitted change times land within their own
uncertainty of the true ones.  Every expected value is the generating truth.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from stickslip.rsf import simulate
from stickslip.rsf.data import LabRecord, change_time_uncertainty, find_segments, read_record
from stickslip.rsf.fit import fit_record

RECORDS = Path(__file__).parent / "records"
sys.path.insert(0, str(RECORDS))
from make_records import TRUTH_4LEVEL, UM, four_level_record, load_point, rsf_truth, sample_times  # noqa: E402

P = TRUTH_4LEVEL["params"]
TRUTH = {"a": P["a"], "b": P["b"], "dc": P["dc"] * UM, "stiffness": P["stiffness"] / UM}


def _holds(fit, key: str) -> bool:
    lo, hi = fit.parameters[key].interval
    return lo <= TRUTH[key] <= hi


@pytest.fixture(scope="module")
def shipped():
    record = read_record(RECORDS / "biaxial_4level.txt", {"displacement": "LP Displacement (um)"})
    truth, *_ = four_level_record(1)  # the shipped record's own truth (make_records writes it from seed 1)
    fitted = fit_record(record, fit_stiffness=True)
    held = fit_record(record, fit_stiffness=True, protocol=find_segments(record.time, record.displacement))
    return truth, fitted, held


def test_held_change_times_miss_the_truth_on_the_shipped_record(shipped):
    """A history found from the displacement and held as given puts k outside its interval: the change at 38 s
    is found 0.22 ms early (1.5 ms late before the per-piece sums of 2026-11-30: 0.34 um of slip at 228.7 um/s,
    7 % of Dc), and chi-square_r (1.03 now, > 1.5 then) no longer shows it; the intervals must carry the change
    times (the next test)."""
    _, _, held = shipped
    assert held.change_times == ()  # a history given is held as given
    assert not _holds(held, "stiffness")


def test_fitted_change_times_give_honest_intervals_on_the_shipped_record(shipped):
    """Dc, k and a - b hold the truth, chi-square_r ~ 1.  (a and b themselves sit 1.6e-5 low, just outside their
    +-1.6e-5 (+-1.4e-5 before the levels' velocities' noise was carried): the first level's velocity is found
    0.4 % fast, 5 of its standard errors, by the record's slow sensor drift, which no uncertainty taken from the
    displacement covers (docs/rsf.md); driven by the true change times with the found velocities they miss alike.
    They are checked on drift-free records below.)"""
    truth, fit, _ = shipped
    assert fit.status == "ok"
    assert _holds(fit, "dc") and _holds(fit, "stiffness")
    lo, hi = fit.derived["a-b"].interval
    assert lo <= TRUTH["a"] - TRUTH["b"] <= hi
    assert fit.reduced_chi_square < 1.2
    # the two fast changes matter (shifting them by 3 of their uncertainties changes chi-square by far more than
    # 0.1), and each lands within 3 standard errors of the true time
    free = [p for p in fit.change_times if not p.fixed]
    assert len(free) >= 2
    for p in fit.change_times:
        true = float(truth.boundaries[int(p.name.split("_")[1])])
        if not p.fixed:
            assert abs(p.value - true) <= 3.0 * p.stderr
            assert p.interval[0] < p.value < p.interval[1]


def test_the_change_times_are_reported_with_units(shipped):
    _, fit, _ = shipped
    summary = json.loads(json.dumps(fit.summary()))
    rows = summary["change_times"]
    assert len(rows) == 3 and all(row["unit"] == "s" for row in rows)
    assert all(row["interval"] is not None for row in rows if not row["fixed"])
    assert summary["units"]["change_times"].startswith("s ")
    toml = fit.to_toml()
    assert all(f"# change_{i}" in toml for i in (1, 2, 3))
    assert " s   95 % [" in "\n".join(fit.change_lines())
    # the fitted history is the one reported: its boundaries are the fitted change times
    fitted = [p.value for p in fit.change_times]
    assert np.allclose(fit.protocol.boundaries[1:-1], fitted, rtol=0, atol=1e-12)


def test_change_time_uncertainty_scales_with_noise_over_the_jump():
    """A clean step dated by its displacement: sqrt(2) x (row scatter) / jump (the lines meet between rows)."""
    t = np.arange(0.0, 20.0, 0.001)
    v1, v2, sigma = 10 * UM, 110 * UM, 0.2 * UM
    exact = np.where(t < 10.0, v1 * t, v1 * 10.0 + v2 * (t - 10.0))
    d = exact + sigma * np.random.default_rng(3).standard_normal(t.size)
    history = find_segments(t, d)
    (found,) = change_time_uncertainty(t, d, history)
    expected = np.sqrt(2) * sigma / (v2 - v1)
    assert found == pytest.approx(expected, rel=0.25)  # 100 rows' scatter: ~10 % sampling error


def _short_record(seed: int) -> tuple[object, LabRecord]:
    """The shipped record's shape, shorter (10, 4, 2, 10 s) and without the slow drift (whose ~1 % errors of the
    levels' velocities are not fitted: docs/rsf.md)."""
    spec = {**TRUTH_4LEVEL, "durations": (10.0, 4.0, 2.0, 10.0)}
    t = sample_times(((0.0, 0.1), (9.0, 0.01), (13.5, 0.001), (16.5, 0.1)), sum(spec["durations"]))
    truth, d = load_point(spec["velocities"], spec["durations"], t, bit=spec["bit"], noise=spec["noise"],
                          correlation_time=spec["correlation_time"], drift=0.0, seed=seed)  # fmt: skip
    run = simulate(rsf_truth(P, spec["velocities"][0] * UM), truth, times=t)
    friction = run.friction + spec["friction_noise"] * np.random.default_rng(seed + 100).standard_normal(t.size)
    return truth, LabRecord.from_arrays(t, d * UM, friction)


def test_coverage_over_seeds_with_fitted_change_times():
    """Two records (seeds 3, 4; 8 intervals of a, b, Dc, k): at 95 % each, 7 or more hits has probability 0.94;
    held, seed 4's k is missed (chi-square_r 5.9).  chi-square_r within 0.9-1.2 and every fitted change time
    within 3 standard errors of the truth.  The levels' velocities are estimates too: without their noise in the
    intervals seed 4 missed b and k (6 hits; over seeds 1-16 a's error was 2.16 standard errors rms, 0.94 with
    it carried, 0.87 driven by the true history)."""
    hits = 0
    for seed in (3, 4):
        truth, record = _short_record(seed)
        fit = fit_record(record, fit_stiffness=True)
        assert fit.status == "ok"
        hits += sum(_holds(fit, key) for key in TRUTH)
        assert 0.9 < fit.reduced_chi_square < 1.2
        for p in fit.change_times:
            if not p.fixed:
                true = float(truth.boundaries[int(p.name.split("_")[1])])
                assert abs(p.value - true) <= 3.0 * p.stderr
    assert hits >= 7
