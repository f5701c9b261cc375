"""The file chain `simulate -o` -> `analyze -o` -> `fit stick`: honest intervals, and analyze's messages.

A noise-free chain at 30, 50 and 90 um/s gave intervals 25-28 standard errors off the parameter set's own values:
analyze's start corner (the hinge's c1 s + c2 s^2 slip branch) lands ~0.5 ms after the true end of the slip in
every repeat of a cycle, a bias no scatter over cycles shows, and the fit's noise was the scatter of identical
cycles (~1e-6).  analyze now reports each cycle's systematic uncertainty (``*_uncertainty`` columns) and fit stick
floors the error of each velocity's mean with it (docs/analysis.md, docs/fitting.md).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from cli_helpers import run_main
from stickslip.analysis import analyze_trace, read_trace
from stickslip.cli.analyze_cmd import cycles_csv
from stickslip.fitting.stick_fit import fit_stick
from stickslip.parameters import load_parameters
from stickslip.quasistatic.critical import critical_point
from stickslip.quasistatic.stick import stick_phase

PARAMS = load_parameters("gelatin-glass")
#: the parameter set's own values: the truth of every simulated record here
TRUTH = {
    "stick.attached_chains": PARAMS.stick.attached_chains,
    "stick.break_rate": PARAMS.stick.break_rate,
    "stick.aging_time": PARAMS.stick.aging_time,
}
VELOCITIES = (30, 50, 90)  # um/s
UNCERTAINTY_COLUMNS = ("critical_stress_uncertainty [Pa]", "peak_stress_uncertainty [Pa]", "stick_time_uncertainty [s]")


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    """simulate -o and analyze -o at each velocity (as the command line runs them) and the stacked cycles."""
    folder = tmp_path_factory.mktemp("chain")
    capsys = _Capture()
    for v in VELOCITIES:
        for args in (
            ("simulate", "--v0", f"{v} um/s", "--duration", "150 s", "-o", str(folder / f"sim{v}.csv")),
            ("analyze", str(folder / f"sim{v}.csv"), "-o", str(folder / f"cycles{v}.csv")),
        ):
            code, _, err = capsys.main(*args)
            assert code == 0, err
    stacked = pd.concat([pd.read_csv(folder / f"cycles{v}.csv") for v in VELOCITIES])
    stacked.to_csv(folder / "cycles.csv", index=False)
    return folder


class _Capture:
    """run_main for a module fixture (pytest's capsys is function-scoped)."""

    def main(self, *args):
        import contextlib
        import io

        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), pytest.raises(SystemExit) as info:
            from stickslip.cli.main import main

            main(list(args))
        return int(info.value.code), out.getvalue(), err.getvalue()


def _intervals(document):
    return {key: document["parameters"][key]["interval"] for key in TRUTH}


def test_noise_free_chain_intervals_cover_the_parameter_sets_values(chain):
    """Before: Nc0 2.07045e12 +- 1.6e7, uc/tau 1.40196e-4 +- 7e-9, tau_a 9.99971 +- 1.2e-5 s: 25-28 standard
    errors off.  Now each 95 % interval holds the value the records were simulated with."""
    code, out, err = _Capture().main("fit", "stick", str(chain / "cycles.csv"), "--json")
    assert code == 0, err
    document = json.loads(out)
    assert document["status"] == "ok"
    for key, (low, high) in _intervals(document).items():
        assert low <= TRUTH[key] <= high, (key, low, high, TRUTH[key])
    # the floors are what widened them: the scatter of identical cycles stays ~1e-6
    assert document["relative_noise"] < 1e-5
    assert {round(f["pulling_velocity"] * 1e6) for f in document["error_floors"]} == set(VELOCITIES)
    # honest, not vacuous: still a few per cent at most
    for key, (low, high) in _intervals(document).items():
        assert high / low < 1.05, key


def test_uncertainty_columns_bound_each_cycles_corner_errors(chain):
    """Against simulate's own cycles (the truth): sigma_c, sigma_s and t_s of every complete cycle lie within
    analyze's stated uncertainty; the columns carry their units."""
    for v in VELOCITIES:
        header = (chain / f"cycles{v}.csv").read_text().splitlines()[0].split(",")
        assert all(name in header for name in UNCERTAINTY_COLUMNS)
        result = analyze_trace(read_trace(chain / f"sim{v}.csv"), None, v * 1e-6, PARAMS)
        sigma_c = critical_point(PARAMS).stress
        truth = stick_phase(PARAMS, v * 1e-6, start_stress=sigma_c)  # every simulated cycle starts at sigma_c
        complete = [c for c in result.cycles if c.complete]
        assert len(complete) >= 2
        for c in complete:
            assert abs(c.critical_stress - sigma_c) <= c.critical_stress_uncertainty, (v, c.index)
            assert abs(c.peak_stress - truth.peak_stress) <= c.peak_stress_uncertainty + 1e-9 * truth.peak_stress
            assert abs(c.stick_time - truth.stick_time) <= c.stick_time_uncertainty, (v, c.index)
            # and they are no blanket: well under a per mille of the values
            assert c.stick_time_uncertainty < 1e-3 * c.stick_time
            assert c.critical_stress_uncertainty < 1e-3 * c.critical_stress


def test_noisy_chain_intervals_widen_little(chain):
    """The same records sampled at 1 kHz under 1 Pa of white noise: the floors widen the intervals by less than
    1.6 times here (1.2; over 10 seeds 1.1-1.3 in the median, at most 2.1: docs/fitting.md), the estimates do not
    move, and the intervals hold the truth."""
    parts = []
    for v in VELOCITIES:
        trace = read_trace(chain / f"sim{v}.csv")
        t = np.arange(0.0, 150.0, 1e-3)
        x = np.interp(t, trace.time, trace.stress) + np.random.default_rng(v).normal(0.0, 1.0, t.size)
        text = cycles_csv(analyze_trace(t, x, v * 1e-6, PARAMS))
        parts.append(text if not parts else text.split("\n", 1)[1])
    with_floors = chain / "noisy.csv"
    with_floors.write_text("".join(parts))
    without = chain / "noisy_without.csv"
    pd.read_csv(with_floors).drop(columns=list(UNCERTAINTY_COLUMNS)).to_csv(without, index=False)
    after, before = fit_stick(with_floors, params=PARAMS), fit_stick(without, params=PARAMS)
    assert after.success and before.success
    for a, b in zip(after.estimates, before.estimates, strict=True):
        assert a.value == pytest.approx(b.value, rel=1e-12)  # the estimate is the same least-squares one
        assert 1.0 - 1e-9 <= a.stderr / b.stderr < 1.6, a.key
        low, high = a.interval
        assert low <= TRUTH[a.key] <= high, a.key


def test_stick_table_uncertainty_floors_repeated_identical_cycles(tmp_path):
    """A Table-1-like table: 4 identical cycles at each of 3 velocities, each velocity's stick time off by a
    systematic 0.05 % (+, -, + from the model's own), given as +-0.1 % in stick_time_uncertainty.  Without the
    column the fit believes the ~1e-8 scatter of the repeats (the truth is far outside its intervals); with it
    the intervals hold the truth."""
    velocities = np.repeat([30e-6, 50e-6, 90e-6], 4)
    sigma_c = critical_point(PARAMS).stress
    exact = {v: stick_phase(PARAMS, v, start_stress=sigma_c).stick_time for v in set(velocities)}
    bias = {30e-6: 5e-4, 50e-6: -5e-4, 90e-6: 5e-4}
    jitter = 1e-8 * np.tile([1.0, -1.0, 0.5, -0.5], 3)
    times = np.array([exact[v] * (1 + bias[v]) for v in velocities]) * (1 + jitter)
    frame = pd.DataFrame({"pulling_velocity [m/s]": velocities, "stick_time [s]": times, "start_stress [Pa]": sigma_c})
    frame.to_csv(tmp_path / "plain.csv", index=False)
    frame["stick_time_uncertainty [s]"] = 1e-3 * times
    frame.to_csv(tmp_path / "bounded.csv", index=False)
    plain, bounded = (
        fit_stick(tmp_path / "plain.csv", params=PARAMS),
        fit_stick(tmp_path / "bounded.csv", params=PARAMS),
    )
    missed = [e.key for e in plain.estimates if not e.interval[0] <= TRUTH[e.key] <= e.interval[1]]
    assert missed  # the failure the floors mend
    for e in bounded.estimates:
        assert e.interval[0] <= TRUTH[e.key] <= e.interval[1], e.key
    assert len(bounded.floors) == 3
    assert any("floored" in m for m in bounded.messages)
    # the uncertainty reaches the data unchanged, in SI
    assert np.allclose(bounded.data.extra["stick_time_uncertainty"], 1e-3 * times)


def test_negative_uncertainty_is_refused(tmp_path, capsys):
    path = tmp_path / "t.csv"
    path.write_text("pulling_velocity [um/s],stick_time [s],stick_time_uncertainty [s]\n50,18,0.01\n100,9,-0.01\n")
    code, _, err = run_main(capsys, "fit", "stick", str(path))
    assert code == 2 and err.count("\n") == 1
    assert "row 3, column 'stick_time_uncertainty'" in err and "-0.01" in err


# --------------------------------------------------------------------------- analyze's messages
def test_a_header_name_with_a_space_is_named_as_an_unknown_column(tmp_path, capsys):
    """'Shear stress (kPa)' is in the 'name (unit)' form; its name is the problem, not its form."""
    t = np.arange(0.0, 30.0, 0.01)
    stress = 250.0 + 15.0 * (t % 10.0)
    path = tmp_path / "saw.csv"
    path.write_text(
        "Time (ms),Shear stress (kPa)\n"
        + "".join(f"{a * 1e3:.3f},{b / 1e3:.6f}\n" for a, b in zip(t, stress, strict=True))
    )
    code, out, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s")
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "unknown column 'Shear stress'" in err and "expected time, stress, force" in err
    assert "cannot read header" not in err
    # a cell that is no header at all still says so
    path.write_text("time,[Pa]\n1,2\n")
    code, _, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s")
    assert code == 2 and "cannot read header '[Pa]'" in err


def _record(path, slips):
    """A sawtooth at 15 Pa/s from 250 Pa with a 1 s exponential slip at each time in ``slips``, to t = 20 s."""
    t = np.arange(0.0, 20.0, 0.01)
    x = 300.0 + 15.0 * t
    for start in slips:
        after = t >= start
        peak = np.interp(start, t, x)
        x[after] = np.maximum(
            250.0 + (peak - 250.0) * np.exp(-(t[after] - start) / 0.2), 250.0 + 15.0 * (t[after] - start - 2.0)
        )
    path.write_text("time [s],stress [Pa]\n" + "".join(f"{a},{b}\n" for a, b in zip(t, x, strict=True)))
    return path


def test_a_record_without_a_whole_stick_is_undetermined_not_stick_slip(tmp_path, capsys):
    """One slip between a stick cut by the start and one cut by the end: 'undetermined', in text and JSON."""
    path = _record(tmp_path / "short.csv", [12.0])
    code, out, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s")
    assert code == 0, err
    first = " ".join(out.split("V0 = ")[0].split())  # the head line, as rich wraps it
    assert "undetermined: 2 cycle(s), none complete" in first and "too short a record" in first
    assert "stick-slip:" not in first
    code, out, _ = run_main(capsys, "analyze", str(path), "--v0", "50 um/s", "--json")
    document = json.loads(out)
    assert document["regime"] == document["summary"]["regime"] == "undetermined"
    assert document["message"].startswith("undetermined:")
    # a whole stick phase between two slips is stick-slip
    code, out, _ = run_main(
        capsys, "analyze", str(_record(tmp_path / "two.csv", [6.0, 14.0])), "--v0", "50 um/s", "--json"
    )
    document = json.loads(out)
    assert document["regime"] == "stick-slip" and math.isfinite(document["cycles"][1]["stick_time"])
