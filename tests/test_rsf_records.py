"""Lab records as rigs write them: velocity levels found in quantised, correlated, unevenly sampled displacement
(against the known truth the records were made from), units read from headers, a velocity column's steps at their
own rows, and the measured load point as the model's history.  The records are made by tests/records/make_records.py.
"""

from __future__ import annotations

import math
import re
import time
from pathlib import Path

import numpy as np
import pytest

from records.make_records import (
    TRUTH_4LEVEL,
    TRUTH_VELOCITY,
    UM,
    load_point,
    sample_times,
)
from stickslip import protocols
from stickslip.errors import DataError, ParameterError
from stickslip.rsf import data as rsf_data
from stickslip.rsf.data import LabRecord, find_segments, measured_history, read_record

RECORDS = Path(__file__).parent / "records"
SHARED = Path(__file__).resolve().parents[2] / "shared/data/giacomel-steadystate"
SHIPPED = Path(rsf_data.__file__).parents[1] / "data/giacomel-sepiolite/velstep3_TR2_exp013_sepiolite.txt"
GIACOMEL = {"time": "Time(s)", "displacement": "Displ(microns)", "friction": "Friction"}


#: rows at half the rate: under the 2000 rows the search takes as they come, so equal time bins are made anyway
HALF_RATE = ((0.0, 0.2), (29.0, 0.02), (38.0, 0.004), (40.5, 0.2))


def four_level(seed: int, sampling: tuple | None = None) -> tuple[protocols.Protocol, np.ndarray, np.ndarray]:
    spec = TRUTH_4LEVEL
    t = sample_times(sampling or spec["sampling"], sum(spec["durations"]))
    truth, d = load_point(spec["velocities"], spec["durations"], t, drift=spec["drift"], seed=seed)
    return truth, t, d * UM


def change_tolerance(truth: protocols.Protocol, t: np.ndarray, noise: float) -> np.ndarray:
    """Where two lines through noise ``noise`` meet is known to ~noise / |dv|: allow 4 of those and two rows."""
    b = truth.boundaries[1:-1]
    dv = np.abs(np.diff(truth.velocities))
    rows = np.array([np.diff(t)[min(np.searchsorted(t, x), t.size - 2)] for x in b])
    return 4.0 * noise / dv + 2.0 * rows


@pytest.mark.parametrize("sampling", [None, HALF_RATE], ids=["3986 rows", "1369 rows"])
@pytest.mark.parametrize("seed", range(3))
def test_levels_of_a_quantised_correlated_record_with_changing_sampling_are_the_truth(seed, sampling):
    """2.29 -> 22.85 -> 228.7 -> 2.287 um/s in 0.1 um bits with AR(1) noise, a drift, rows every 0.1 s, 10 ms,
    1 ms then 0.1 s (the real record was refused with 101 pieces): four levels, each within 1.5 %, each change
    where the truth has it (the drift's speed is below 0.6 % of the slowest level)."""
    truth, t, d = four_level(seed, sampling)
    found = find_segments(t, d)
    assert len(found.segments) == 4, found.describe()
    assert found.velocities == pytest.approx(truth.velocities, rel=0.015)
    tolerance = change_tolerance(truth, t, TRUTH_4LEVEL["noise"] * UM)
    assert np.all(np.abs(found.boundaries[1:-1] - truth.boundaries[1:-1]) <= tolerance)


@pytest.mark.parametrize("window", [(25.0, 35.0), (35.0, 39.0), (38.5, 45.0), (39.5, 70.0)])
def test_a_one_step_window_is_one_step(window):
    """Windows holding one change (up 10x, up 10x at 1 kHz, down 100x from 1 kHz rows into 0.1 s rows): two
    levels, never the invented 0 or 400 um/s pieces."""
    for seed in range(3):
        truth, t, d = four_level(seed)
        keep = (t >= window[0]) & (t <= window[1])
        found = find_segments(t[keep] - t[keep][0], d[keep])
        expected = truth.velocity_at(np.array([window[0] + 0.2, window[1] - 0.2]))
        assert len(found.segments) == 2, (seed, found.describe())
        assert found.velocities == pytest.approx(expected, rel=0.05)


def test_correlated_quantised_noise_alone_is_one_level():
    """No change, 1 kHz rows, 0.1 um bits, noise correlated over 50 ms and a slow drift: one level."""
    t = np.arange(0.0, 30.0, 1e-3)
    for seed in range(3):
        _, d = load_point((5.0,), (30.0,), t, noise=0.3, correlation_time=0.05, drift=0.5, seed=seed)
        found = find_segments(t, d * UM)
        assert len(found.segments) == 1
        assert found.velocities[0] == pytest.approx(5.0 * UM, rel=0.02)


def test_the_noise_model_measures_white_noise_at_two_sampling_rates():
    """White noise sigma on rows every 0.1 s then every 10 ms: each bin mean's variance is sigma^2 / rows
    (the truth for white noise), within 25 %, and no inflation beyond chance."""
    sigma = 0.2 * UM
    t = np.concatenate([np.arange(0.0, 200.0, 0.1), np.arange(200.0, 240.0, 0.01)])
    d = 3 * UM * t + sigma * np.random.default_rng(5).standard_normal(t.size)
    bins = rsf_data._bins(t, d)
    scale = float(np.max(np.abs(d - np.polyval(np.polyfit(t, d, 1), t))))
    expected = (sigma / scale) ** 2 / bins.count
    ratio = bins.var / expected
    dense = bins.count > 5
    assert np.median(ratio[dense]) == pytest.approx(1.0, rel=0.25)
    assert np.median(ratio[~dense]) == pytest.approx(1.0, rel=0.25)
    assert bins.inflation[1][0] < 1.6


def test_a_long_1khz_record_is_fast():
    """100,000 rows at 1 kHz, four levels (10, 1, 100, 3 um/s), 0.3 um noise correlated over 50 ms: < 1.5 s."""
    t = np.arange(0.0, 100.0, 1e-3)
    truth, d = load_point((10, 1, 100, 3), (25, 25, 25, 25), t, noise=0.3, correlation_time=0.05, drift=1, seed=3)
    start = time.perf_counter()
    found = find_segments(t, d * UM)
    assert time.perf_counter() - start < 1.5  # 0.45 s on the development machine
    assert found.velocities == pytest.approx(truth.velocities, rel=0.02)
    assert np.all(np.abs(found.boundaries[1:-1] - truth.boundaries[1:-1]) <= change_tolerance(truth, t, 0.3 * UM))


def real_records() -> list[tuple[str, Path, tuple[float, float]]]:
    cases = [("velstep3 (shipped)", SHIPPED, (0.2, 2.0)), ("velstep1 slice", RECORDS / "sepiolite_velstep1_slice.txt",
                                                             (0.2, 2.0))]  # fmt: skip
    for name, speeds in (("velstep1", (0.2, 2.0)), ("velstep2", (2.0, 0.2))):
        path = SHARED / f"{name}_TR2_exp013_sepiolite.txt"
        cases.append((name, path, speeds))
    return cases


@pytest.mark.parametrize(("name", "path", "speeds"), real_records(), ids=[c[0] for c in real_records()])
def test_real_sepiolite_steps_up_and_down_are_two_levels(name, path, speeds):
    """Giacomel's sepiolite steps (0.2 -> 2 um/s up, 2 -> 0.2 um/s down), servo ramps and wander as recorded:
    two levels at the rig's nominal speeds (the old finder gave 3 and 5 pieces)."""
    if not path.is_file():
        pytest.skip(f"{path} not present")
    record = read_record(path, GIACOMEL)  # the header says microns: no unit option
    assert record.length_unit == "um"
    found = find_segments(record.time, record.displacement)
    assert len(found.segments) == 2, found.describe()
    assert found.velocities == pytest.approx(np.array(speeds) * UM, rel=0.01)


# --- units from headers ---------------------------------------------------------------------------------------


def write(path: Path, header: str, t: np.ndarray, d: np.ndarray) -> Path:
    rows = "".join(f"{a:.6g}\t{b:.9g}\t0.6\n" for a, b in zip(t, d, strict=True))
    path.write_text(f"{header}\tFriction\n" + rows)
    return path


@pytest.mark.parametrize(
    ("time_header", "time_factor", "disp_header", "disp_factor"),
    [
        ("Time(s)", 1.0, "Displ(microns)", 1e-6),
        ("Time (s)", 1.0, "LP Displacement (um)", 1e-6),
        ("time [ms]", 1e-3, "disp [µm]", 1e-6),
        ("Time(s)", 1.0, "Displ (mm)", 1e-3),
        ("t_ms", 1e-3, "Displ (nm)", 1e-9),
        ("Time(s)", 1.0, "disp_nm", 1e-9),
        ("Time(s)", 1.0, "LVDT displacement microns", 1e-6),
    ],
)
def test_units_are_read_from_the_header(tmp_path, time_header, time_factor, disp_header, disp_factor):
    """The record's own numbers times the unit its header names: 2 units of displacement per unit of time."""
    t = np.arange(0.0, 50.0)
    path = write(tmp_path / "rig.txt", f"{time_header}\t{disp_header}", t, 2.0 * t)
    record = read_record(path, {"time": time_header, "displacement": disp_header, "friction": "Friction"})
    np.testing.assert_allclose(record.time, t * time_factor)
    np.testing.assert_allclose(record.displacement, 2.0 * t * disp_factor)


def test_a_header_and_an_option_that_disagree_are_refused_in_one_line(tmp_path):
    t = np.arange(0.0, 50.0)
    path = write(tmp_path / "rig.txt", "Time(s)\tLP Displacement (um)", t, 2.0 * t)
    cols = {"time": "Time(s)", "displacement": "LP Displacement (um)", "friction": "Friction"}
    assert read_record(path, cols, displacement_unit="micron").displacement[-1] == pytest.approx(98e-6)
    with pytest.raises(DataError, match=r"is in um but --displacement-unit says mm") as caught:
        read_record(path, cols, displacement_unit="mm")
    assert "\n" not in str(caught.value)
    with pytest.raises(DataError, match="--time-unit says ms"):
        read_record(path, cols, time_unit="ms")


def test_a_forgotten_unit_is_refused_at_once_with_the_likely_one(tmp_path):
    """um read as metres: the load point at 2 m/s is no friction rig's; the message names um; given, it reads."""
    t = np.arange(0.0, 50.0, 0.1)
    path = write(tmp_path / "rig.txt", "Time\tLP Displacement", t, 2.0 * t)
    cols = {"time": "Time", "displacement": "LP Displacement", "friction": "Friction"}
    with pytest.raises(DataError, match=r"2 m/s .* if it is in um give --displacement-unit um") as caught:
        read_record(path, cols)
    assert "\n" not in str(caught.value)
    assert read_record(path, cols, displacement_unit="um").displacement[-1] == pytest.approx(2 * 49.9e-6)


def test_a_bracketed_unit_of_another_kind_is_refused(tmp_path):
    t = np.arange(0.0, 50.0)
    path = write(tmp_path / "rig.txt", "Time(s)\tDispl (mm/s)", t, t)
    with pytest.raises(DataError, match="is in mm/s, a velocity; expected a length"):
        read_record(path, {"time": "Time(s)", "displacement": "Displ (mm/s)", "friction": "Friction"})


@pytest.mark.parametrize(
    ("time_header", "friction_header", "refused"),
    [
        # a fuzz of the command line (2026-11-29): each was read as seconds or as mu, the fit said "ok"
        ("time [kg]", "Friction", "column 'time [kg]' is in kg, not a time"),
        ("time [xyz]", "Friction", "column 'time [xyz]': unknown unit 'xyz'; expected a time"),
        ("time [V]", "Friction", "column 'time [V]' is in V, not a time"),
        ("Time(s)", "friction [Pa]", "column 'friction [Pa]' is in Pa, a stress; expected the friction coefficient"),
    ],
)
def test_a_header_unit_that_is_not_the_columns_kind_is_refused(tmp_path, time_header, friction_header, refused):
    t = np.arange(0.0, 50.0)
    rows = "".join(f"{a:.6g}\t{2e-6 * a:.9g}\t0.6\n" for a in t)
    path = tmp_path / "rig.txt"
    path.write_text(f"{time_header}\tDispl(m)\t{friction_header}\n" + rows)
    with pytest.raises(DataError, match=re.escape(refused)) as caught:
        read_record(path, {"time": time_header, "displacement": "Displ(m)", "friction": friction_header})
    assert "\n" not in str(caught.value)


def test_labels_in_round_brackets_and_pure_numbers_are_no_units(tmp_path):
    """What a header may carry that names no unit: a label in round brackets (even one that pint reads as a unit of
    no kind a record has: A, mu), [1] or [-] on the friction."""
    t = np.arange(0.0, 50.0)
    for displ, friction in (
        ("Displ (LVDT 2)", "friction [1]"),
        ("Displ (A)", "friction [-]"),
        ("Displ", "Friction (mu)"),
    ):
        rows = "".join(f"{a:.6g}\t{2e-6 * a:.9g}\t0.6\n" for a in t)
        path = tmp_path / "rig.txt"
        path.write_text(f"Time(s)\t{displ}\t{friction}\n" + rows)
        record = read_record(path, {"time": "Time(s)", "displacement": displ, "friction": friction})
        assert record.displacement[-1] == pytest.approx(98e-6) and record.friction[0] == 0.6


def test_a_blank_separated_record_keeps_bracketed_units_with_their_names(tmp_path):
    """Columns separated by blanks: "time [s]" and "disp (um)" are one column each (a fuzz of the command line,
    2026-11-29, read a lone "time [s]" as two columns named "time" and "[s]"), after a comment line; a header whose
    names do not match the rows' width is refused in one line."""
    t = np.arange(0.0, 50.0)
    rows = "".join(f"{a:.6g}  {2.0 * a:.9g}   0.6\n" for a in t)
    path = tmp_path / "rig.txt"
    path.write_text("# rig 3\n  time [s]   disp (um)  mu\n" + rows)
    record = read_record(path, {"time": "time [s]", "displacement": "disp (um)", "friction": "mu"})
    assert record.displacement[-1] == pytest.approx(98e-6) and record.time[-1] == 49.0
    assert rsf_data.whitespace_headers("t [ms] Displ(microns) LP disp [um] mu") == [
        "t [ms]", "Displ(microns)", "LP", "disp [um]", "mu",
    ]  # fmt: skip
    lone = tmp_path / "lone.txt"
    lone.write_text("time [s]\n0\n1\n")
    with pytest.raises(DataError, match=r"no displacement column; found time \[s\] \(map") as caught:
        read_record(lone)
    assert "\n" not in str(caught.value)
    (tmp_path / "wide.txt").write_text("time disp\n0 1 0.6\n1 2 0.6\n")
    with pytest.raises(DataError, match=r"header names 2 column\(s\) \(time, disp\) but the rows have 3"):
        read_record(tmp_path / "wide.txt")


# --- a velocity column ------------------------------------------------------------------------------------------


def test_a_velocity_column_steps_at_the_row_that_carries_the_new_velocity():
    """Steps whose first rows are at t = 50.0 and 80.0 s come out at 50.0 and 80.0 s (trapezoids put them at
    49.95 and 79.95 s), and the displacement is the exact integral of the commanded history."""
    record = read_record(RECORDS / "velocity_column.txt")
    truth = protocols.velocity_steps([v * UM for v in TRUTH_VELOCITY["velocities"]], TRUTH_VELOCITY["durations"])
    np.testing.assert_allclose(record.displacement, truth.displacement_at(record.time), rtol=1e-9, atol=1e-15)
    found = find_segments(record.time, record.displacement)
    assert found.boundaries == pytest.approx(truth.boundaries, abs=1e-6)
    assert record.length_unit == "um"
    assert record.displacement_from == "velocity"
    assert read_record(RECORDS / "biaxial_4level.txt").displacement_from == "displacement"


def test_a_fit_of_a_velocity_column_record_covers_dc_and_k():
    """RSF with known a, b, Dc, k driven by the velocity column: the fit's intervals hold the truth (with the
    half-row shift Dc came out 1.0107e-5 in [1.0028, 1.0186]e-5 and k 8801 in [8623, 8983], truth 1e-5 and 1e4)."""
    from stickslip.rsf.fit import fit_record

    fit = fit_record(read_record(RECORDS / "velocity_column.txt"))
    assert fit.status == "ok"
    assert fit.protocol_source == "found from the load-point velocity"  # it read "... displacement"
    truth = TRUTH_VELOCITY["params"]
    for key, value in (("a", truth["a"]), ("b", truth["b"]), ("dc", truth["dc"] * UM),
                       ("stiffness", truth["stiffness"] / UM)):  # fmt: skip
        lo, hi = fit.parameters[key].interval
        assert lo <= value <= hi, (key, fit.parameters[key])


# --- the measured load point ---------------------------------------------------------------------------------------


def test_the_measured_history_follows_the_true_load_point():
    """From the quantised 4-level record: few segments (steady stretches cost one), velocities >= 0, the whole
    record covered, and the history's displacement within the noise of the TRUE load point (closer than the
    record itself, which carries 0.15 um of noise)."""
    record = read_record(RECORDS / "biaxial_4level.txt", {"displacement": "LP Displacement (um)"})
    truth, _, _ = four_level(1)
    history = measured_history(record)
    assert 4 <= len(history.segments) <= 50
    assert np.all(history.velocities >= 0)
    assert history.duration == pytest.approx(record.time[-1], rel=1e-12)
    miss = history.displacement_at(record.time) - truth.displacement_at(record.time)
    miss -= miss.mean()  # the history starts at 0, the record at its first (noisy) reading
    noise = TRUTH_4LEVEL["noise"] * UM
    assert math.sqrt(np.mean(miss**2)) < 0.8 * noise
    assert np.max(np.abs(miss)) < 4 * noise


def test_the_measured_history_follows_a_ramp_the_levels_cannot():
    """A servo's 5 s ramp from 1 to 10 um/s (smooth, no step): the measured history follows it to within the
    noise; two levels miss it by far more."""
    t = np.arange(0.0, 100.0, 0.05)
    v = np.interp(t, [0, 40, 45, 100], [1, 1, 10, 10]) * UM
    exact = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
    noise = 0.05 * UM
    d = exact + noise * np.random.default_rng(2).standard_normal(t.size)
    record = LabRecord.from_arrays(t, d, 0.6 + 0 * t)
    misses = []
    for history in (measured_history(record), find_segments(t, d)):
        miss = history.displacement_at(t) - exact
        misses.append(np.max(np.abs(miss - miss.mean())))
    assert misses[0] < 4 * noise < misses[1]


def test_the_measured_history_refuses_a_bad_window():
    record = LabRecord.from_arrays(np.arange(50.0), 1e-6 * np.arange(50.0), 0.6 + np.zeros(50))
    for bad in (0.0, -1.0, math.nan, "1 s"):
        with pytest.raises(ParameterError, match="smoothing"):
            measured_history(record, smoothing=bad)
    assert measured_history(record, smoothing=5.0).velocities == pytest.approx(1e-6, rel=1e-9)


@pytest.mark.parametrize(
    ("velocities", "durations", "sampling", "noise"),
    [
        ((10, 0, 10, 3), (20, 10, 30, 40), ((0, 0.01), (40, 0.1)), 0.2),  # slide-hold-slide, 100 Hz then 10 Hz
        ((1, 1.3, 1), (100, 100, 100), ((0, 0.01),), 0.2),  # a 30 % step, 30,000 rows
        ((1, 10, 1), (10, 10, 10), ((0, 0.1), (9, 0.001), (21, 0.1)), 1e-6),  # clean, 1 kHz around both steps
    ],
    ids=["slide-hold-slide", "30 % up and back", "clean at two rates"],
)
def test_other_shapes_with_bits_and_correlated_noise(velocities, durations, sampling, noise):
    """A hold (velocity 0), a small step, and a noise-free record at two rates (where PELT's three-bin slivers
    at a kink must not survive as levels): the truth's levels and change times."""
    t = sample_times(sampling, float(sum(durations)))
    bit = 0.1 if noise > 1e-3 else 1e-9
    truth, d = load_point(velocities, durations, t, bit=bit, noise=noise, correlation_time=0.05, seed=1)
    found = find_segments(t, d * UM)
    assert len(found.segments) == len(velocities), found.describe()
    assert found.velocities == pytest.approx(truth.velocities, rel=0.02, abs=0.02 * UM)
    assert np.all(np.abs(found.boundaries[1:-1] - truth.boundaries[1:-1]) <= change_tolerance(truth, t, noise * UM))


def test_the_measured_history_follows_a_smoothly_accelerating_load_point():
    """A load point accelerating steadily (no levels: find_segments refuses it) is still followed, to within the
    noise of the exact displacement."""
    t = np.linspace(0.0, 100.0, 4000)
    exact = 1e-8 * t**2
    noise = 0.02 * UM
    record = LabRecord.from_arrays(t, exact + noise * np.random.default_rng(3).standard_normal(t.size), 0.6 + 0 * t)
    with pytest.raises(DataError, match="straight pieces"):
        find_segments(record.time, record.displacement)
    history = measured_history(record)
    miss = history.displacement_at(t) - exact
    assert np.max(np.abs(miss - miss.mean())) < 3 * noise
    assert len(history.segments) < 100


def test_the_shipped_biaxial_record_is_read_as_it_comes():
    """Only the displacement column named (``Time (s)`` and ``mu`` are found): micrometres from its header, four
    levels at the truth it was made from."""
    record = read_record(RECORDS / "biaxial_4level.txt", {"displacement": "LP Displacement (um)"})
    assert record.length_unit == "um" and len(record) == 3986
    truth, t, _ = four_level(1)
    np.testing.assert_allclose(record.time, t, atol=5e-4)  # written to the millisecond
    found = find_segments(record.time, record.displacement)
    assert found.velocities == pytest.approx(truth.velocities, rel=0.015)
    assert np.all(np.abs(found.boundaries[1:-1] - truth.boundaries[1:-1]) <= change_tolerance(truth, t, 0.15 * UM))
