"""Command line: ``stickslip analyze`` (Table 1 rows from a measured record).

Records are written in the tests: a sawtooth with known corners (stick slope
K V0, K = G_d/h ln(B/l)/(B/l - 1) = 306.5 kPa/m) in mixed units, and a
record sampled from the simulator for ``--compare``.  Bad input goes through
``main()`` to check exit status 2 and a one-line message.
"""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip.cli.analyze_cmd import _comparison_text
from stickslip.tables import read_table

GD_H = 400e3
K = GD_H * math.log(5 / 3) / (2 / 3)
V0 = 50e-6
LOWS = (258.0, 256.0, 260.0, 257.0)
HIGHS = (552.0, 549.0, 556.0)
SLIP = 1.5  # s, a straight fall


def sawtooth(t: np.ndarray) -> tuple[np.ndarray, list[float], list[float]]:
    """Sticks at K V0 from LOWS[j] to HIGHS[j], straight falls of SLIP s; (stress, start times, peak times)."""
    slope = K * V0
    out = np.full(t.shape, np.nan)
    starts, peaks, start = [], [], 0.0
    for j, high in enumerate(HIGHS):
        peak = start + (high - LOWS[j]) / slope
        starts.append(start)
        peaks.append(peak)
        stick = (t >= start) & (t <= peak)
        out[stick] = LOWS[j] + slope * (t[stick] - start)
        fall = (t > peak) & (t < peak + SLIP)
        out[fall] = high + (LOWS[j + 1] - high) * (t[fall] - peak) / SLIP
        start = peak + SLIP
    starts.append(start)
    rest = t >= start
    out[rest] = LOWS[-1] + slope * (t[rest] - start)
    before = t < 0
    out[before] = LOWS[0] + slope * t[before]
    return out, starts, peaks


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    """A noisy sawtooth in ms and kPa, starting mid-stick, with a gap; and its truth."""
    rng = np.random.default_rng(7)
    t = np.arange(-6.0, 66.0, 0.02) + rng.uniform(-0.005, 0.005, 3600)
    stress, starts, peaks = sawtooth(t)
    stress = stress + 2.9 * rng.standard_normal(t.size)
    folder = tmp_path_factory.mktemp("analyze")
    path = folder / "trace.csv"
    lines = ["# a comment line", "time [ms],stress [kPa]"]
    for k, (a, b) in enumerate(zip(t, stress, strict=True)):
        lines.append(f"{a * 1e3:.4f}," + ("" if 900 <= k < 905 else f"{b * 1e-3:.7f}"))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    force = folder / "force.csv"  # the same record as a force on 20 cm^2, in mN
    force.write_text(
        "time [s],force [mN]\n" + "".join(f"{a:.17g},{b * 20e-4 * 1e3:.17g}\n" for a, b in zip(t, stress, strict=True)),
        encoding="utf-8",
    )
    return {"path": path, "force": force, "starts": starts, "peaks": peaks, "folder": folder}


def test_table_output(capsys, record):
    code, out, err = run_main(capsys, "analyze", str(record["path"]), "--v0", "50 um/s")
    assert code == 0, err
    assert "stick-slip: 4 cycle(s), 2 complete" in out
    for heading in ("σc [Pa]", "dσ/dt stick [Pa/s]", "Gd/h [kPa/m]", "σs [Pa]", "ts [s]", "Vs [µm/s]"):
        assert heading in out
    row = next(line for line in out.splitlines() if "Gd/h [kPa/m]" in line)
    values = [float(v) for v in row.replace("│", " ").split()[3:-3]]
    assert values == pytest.approx([GD_H / 1e3] * len(values), rel=0.01)


def test_json_output_in_si(capsys, record):
    code, out, _ = run_main(capsys, "analyze", str(record["path"]), "--v0", "5e-5 m/s", "--json")
    assert code == 0
    data = json.loads(out)
    assert data["regime"] == "stick-slip" and data["pulling_velocity"] == pytest.approx(V0)
    complete = [c for c in data["cycles"] if c["complete"]]
    assert [c["index"] for c in complete] == [2, 3]
    for cycle in complete:
        j = cycle["index"] - 1
        assert cycle["critical_stress"] == pytest.approx(LOWS[j], abs=2.9)
        assert cycle["peak_stress"] == pytest.approx(HIGHS[j], abs=2.9)
        assert cycle["stick_time"] == pytest.approx(record["peaks"][j] - record["starts"][j], rel=0.02)
        assert cycle["stiffness"] == pytest.approx(GD_H, rel=0.02)
        assert cycle["slip_time"] == pytest.approx(SLIP, abs=0.1)
        assert 5e-4 < cycle["jump_velocity"] < 8e-4  # m/s: SI
    assert data["cycles"][0]["critical_stress"] is None  # cut by the start of the record
    assert data["summary"]["stiffness"]["n"] == 4
    assert data["summary"]["stiffness"]["mean"] == pytest.approx(GD_H, rel=0.01)


def test_cycles_csv_reads_back_with_units(capsys, record, tmp_path):
    target = tmp_path / "cycles.csv"
    code, _, _ = run_main(capsys, "analyze", str(record["path"]), "--v0", "50 um/s", "-o", str(target))
    assert code == 0
    header = target.read_text(encoding="utf-8").splitlines()[0]
    assert "critical_stress [Pa]" in header and "stiffness [Pa/m]" in header and "model_jump_velocity [m/s]" in header
    assert "cycle [1]" in header and "complete [1]" in header  # pure numbers carry [1]
    dimensions = {"s": "time", "Pa": "stress", "Pa/s": "stress_rate", "Pa/m": "stress_per_length", "m/s": "velocity"}
    dimensions["1"] = "dimensionless"
    dimensions["Pa/s^2"] = "stress_acceleration"  # the sticks' curvature (round 30)
    columns = {}
    for cell in header.split(","):
        name, _, unit = cell.partition(" [")
        columns[name] = dimensions[unit.rstrip("]")] if unit else "dimensionless"
    names = list(columns)
    table = read_table(target, columns, required=names, allow_missing=names)  # units of the right dimension
    assert list(table["complete"]) == [0, 1, 1, 0]
    assert np.isnan(table["critical_stress"][0])
    assert table["peak_stress"][1] == pytest.approx(HIGHS[1], abs=2.9)


def test_model_derived_vs_is_marked_in_text_csv_and_json(capsys, record, tmp_path):
    """Vs comes from the model's steady curve: another bond time moves it while the measured columns stay put."""
    runs = {}
    for name, extra in (("default", ()), ("bond_time", ("--set", "bonds.bond_time=100 us"))):
        target = tmp_path / f"{name}.csv"
        code, out, err = run_main(capsys, "analyze", str(record["path"]), "--v0", "50 um/s", "--json", "-o",
                                  str(target), *extra)  # fmt: skip
        assert code == 0, err
        runs[name] = (json.loads(out), target.read_text(encoding="utf-8").splitlines()[0])
    (base, header), (other, _) = runs["default"], runs["bond_time"]
    first, moved = base["cycles"][1], other["cycles"][1]
    assert moved["peak_stress"] == first["peak_stress"] and moved["stick_time"] == first["stick_time"]
    assert moved["jump_velocity"] > 1.5 * first["jump_velocity"]  # the parameter set, not the record, sets Vs
    assert "jump_velocity" in base["model_derived"] and "model" in base["model_derived"]["jump_velocity"]
    assert "model_jump_velocity [m/s]" in header.split(",") and "jump_velocity [m/s]" not in header.split(",")
    code, out, err = run_main(capsys, "analyze", str(record["path"]), "--v0", "50 um/s")
    assert code == 0, err
    assert "Vs [µm/s] (model)" in out and "model-derived, not measured" in out


def test_force_with_contact_area_gives_the_same_stress(capsys, record):
    _, by_stress, _ = run_main(capsys, "analyze", str(record["path"]), "--v0", "50 um/s", "--json")
    code, by_force, err = run_main(
        capsys, "analyze", str(record["force"]), "--v0", "50 um/s", "--contact-area", "20 cm^2", "--json"
    )
    assert code == 0, err
    a, b = json.loads(by_stress), json.loads(by_force)
    for x, y in zip(a["cycles"], b["cycles"], strict=True):
        if x["peak_stress"] is not None:
            assert y["peak_stress"] == pytest.approx(x["peak_stress"], abs=0.05)


def test_plot_and_compare(capsys, tmp_path, record):
    from stickslip.parameters import load_parameters
    from stickslip.quasistatic.cycle import simulate

    sim = simulate(load_parameters("gelatin-glass"), V0, 90.0)
    rng = np.random.default_rng(8)
    t = np.arange(5.0, 85.0, 0.05)
    stress = np.interp(t, sim.time, sim.stress) + 3.0 * rng.standard_normal(t.size)
    path = tmp_path / "sim.csv"
    path.write_text("time,stress\n" + "".join(f"{a:.17g},{b:.17g}\n" for a, b in zip(t, stress, strict=True)))
    picture = tmp_path / "analysis.png"
    code, out, err = run_main(
        capsys, "analyze", str(path), "--v0", "50 um/s", "--compare", "--json", "--plot", str(picture)
    )
    assert code == 0, err
    comparison = json.loads(out)["comparison"]
    assert comparison["model_regime"] == "stick-slip"
    assert comparison["rms_misfit"] == pytest.approx(3.0, rel=0.15)
    assert comparison["cycles"][0]["difference"]["peak_stress"] == pytest.approx(0.0, abs=3.0)
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    code, out, _ = run_main(capsys, "analyze", str(path), "--v0", "50 um/s", "--compare")
    assert code == 0 and "RMS misfit" in out and "record cycle 2 - model cycle 1" in out


def test_steady_record(capsys, tmp_path):
    rng = np.random.default_rng(9)
    t = np.arange(0.0, 60.0, 0.05)
    path = tmp_path / "steady.csv"
    stress = 391.5 + 3.0 * rng.standard_normal(t.size)
    path.write_text("time,stress [Pa]\n" + "".join(f"{a:.17g},{b:.17g}\n" for a, b in zip(t, stress, strict=True)))
    code, out, _ = run_main(capsys, "analyze", str(path), "--v0", "350 um/s", "--json")
    assert code == 0
    data = json.loads(out)
    assert data["regime"] == "steady" and data["cycles"] == []
    assert data["summary"]["mean_stress"] == pytest.approx(391.5, abs=0.5)
    assert data["summary"]["stress_std"] == pytest.approx(3.0, rel=0.1)
    code, out, _ = run_main(capsys, "analyze", str(path), "--v0", "350 um/s")
    assert "steady sliding" in out and "mean stress" in out


@pytest.mark.parametrize(
    ("content", "args", "match"),
    [
        (None, [], "file not found"),
        ("time,stress\n" + "".join(f"{k},1\n" for k in (0, 2, 1, 3) * 8), [], "row 4: time 1 s goes back"),
        ("time,stress\n" + "".join(f"{k},1\n" for k in range(5)), [], "too short"),
        ("time,value\n1,2\n", [], "unknown column 'value'"),
        ("time\n" + "".join(f"{k}\n" for k in range(30)), [], "missing column 'stress'"),
        ("time,force\n" + "".join(f"{k},1\n" for k in range(30)), [], "contact area"),
        ("time,stress\n1,abc\n", [], "row 2, column 'stress': 'abc' is not a number"),
    ],
)
def test_bad_files_exit_2(capsys, tmp_path, content, args, match):
    path = tmp_path / "bad.csv"
    if content is not None:
        path.write_text(content, encoding="utf-8")
    code, out, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s", *args)
    assert code == 2 and out == ""
    assert err.startswith("stickslip: error: ") and match in err and err.count("\n") == 1


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["--v0", "50 Pa"], "--v0"),
        (["--v0", "-5 um/s"], "--v0"),
        (["--v0", "0"], "--v0"),
        ([], "--v0"),
        (["--v0", "50 um/s", "--contact-area", "3 s"], "--contact-area"),
        (["--v0", "50 um/s", "--set", "block.height=-1 mm"], "block.height"),
    ],
)
def test_bad_options_exit_2(capsys, record, args, match):
    code, _, err = run_main(capsys, "analyze", str(record["path"]), *args)
    assert code == 2
    assert err.startswith("stickslip: error: ") and match in err and err.count("\n") == 1


# --------------------------------------------------------------------------- what other commands write
def test_simulate_output_chains_into_analyze(capsys, tmp_path):
    trace = tmp_path / "trace.csv"
    code, out, err = run_main(capsys, "simulate", "--v0", "50 um/s", "--duration", "60 s", "-o", str(trace), "--json")
    assert code == 0, err
    model = json.loads(out)["cycles"][1]  # a whole cycle of the simulation: the truth here
    code, out, err = run_main(capsys, "analyze", str(trace), "--v0", "50 um/s", "--json")
    assert code == 0, err
    notes = err.splitlines()
    assert notes[0] == (
        "note: ignored column(s) slider_velocity, slider_position, load_point_position, block_shear, chain_fraction,"
        " phase: analyze reads time and stress only"
    )
    assert len(notes) == 2 and "repeat the time and stress of the row before" in notes[1]
    data = json.loads(out)  # the notes went to stderr: stdout is still one JSON document
    assert data["regime"] == "stick-slip"
    cycle = next(c for c in data["cycles"] if c["complete"])
    assert cycle["critical_stress"] == pytest.approx(model["start_stress"], rel=1e-4)
    assert cycle["peak_stress"] == pytest.approx(model["peak_stress"], rel=1e-4)
    assert cycle["stick_time"] == pytest.approx(model["stick_time"], rel=1e-3)
    assert cycle["slip_time"] == pytest.approx(model["slip_time"], rel=1e-2)
    assert cycle["jump_velocity"] == pytest.approx(model["jump_velocity"], rel=1e-3)
    assert cycle["stiffness"] == pytest.approx(GD_H, rel=1e-4)


def test_jumps_at_one_instant_are_kept(capsys, tmp_path):
    # the no-aging jump raises the stress at the instant of the slip: two rows at one time, both kept
    trace = tmp_path / "trace.csv"
    args = ("simulate", "--v0", "50 um/s", "--duration", "50 s", "--jump-curve", "no-aging", "-o", str(trace), "--json")
    code, out, err = run_main(capsys, *args)
    assert code == 0, err
    model = json.loads(out)["cycles"][1]
    code, out, err = run_main(capsys, "analyze", str(trace), "--v0", "50 um/s", "--json")
    assert code == 0, err
    cycle = next(c for c in json.loads(out)["cycles"] if c["complete"])
    assert cycle["critical_stress"] == pytest.approx(model["start_stress"], rel=1e-4)
    # the hinge assumes a continuous corner; an upward step at the slip moves it by < 0.5 % (docs/analysis.md)
    assert cycle["peak_stress"] == pytest.approx(model["peak_stress"], rel=5e-3)
    assert cycle["stick_time"] == pytest.approx(model["stick_time"], rel=5e-3)


def test_bond_model_transient_trace_is_read_as_is(capsys, tmp_path):
    t = np.arange(-5.0, 60.0, 0.01)
    stress, starts, peaks = sawtooth(t)
    columns = {
        "time": t,
        "stress": stress,
        "bonded_fraction": np.clip(stress / 600.0, 0, 1),
        "slider_velocity": np.zeros_like(t),
        "slider_position": np.zeros_like(t),
        "puller_position": V0 * t,
    }
    path = tmp_path / "transient.csv"
    rows = zip(*columns.values(), strict=True)
    path.write_text(",".join(columns) + "\n" + "".join(",".join(f"{v:.17g}" for v in row) + "\n" for row in rows))
    code, out, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s", "--json")
    assert code == 0, err
    assert err == (
        "note: ignored column(s) bonded_fraction, slider_velocity, slider_position, puller_position:"
        " analyze reads time and stress only\n"
    )
    cycles = json.loads(out)["cycles"]
    assert [c["complete"] for c in cycles] == [False, True, False]  # cut by the record's start and end
    assert [c["peak_stress"] for c in cycles] == [
        pytest.approx(HIGHS[0], abs=0.5),
        pytest.approx(HIGHS[1], abs=0.5),
        None,
    ]
    assert cycles[1]["stick_time"] == pytest.approx(peaks[1] - starts[1], rel=0.01)


def test_rate_and_state_trace_is_refused_with_a_hint(capsys, tmp_path):
    path = tmp_path / "rsf.csv"
    header = "time,friction,slider_velocity,state,load_point_displacement,slider_displacement\n"
    path.write_text(header + "".join(f"{k},0.6,1e-6,1,0,0\n" for k in range(30)))
    code, out, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s")
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "missing column 'stress'" in err and "friction coefficient" in err


def test_duplicated_rows_and_long_tables(capsys, tmp_path):
    path = tmp_path / "dup.csv"
    path.write_text("time,stress\n" + "".join(f"{k},{k % 7}\n" for k in range(40)) + "39,4\n")
    code, _, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s")
    assert code == 2 and "row 42: time 39 s repeats the previous time 39 s with the same stress" in err
    t = np.arange(0.0, 240.0, 0.05)  # ~ 11 cycles of a 21 s sawtooth: the table shows 8 and says so
    phase = np.mod(t, 21.0)
    stress = np.where(phase < 19.0, 257.0 + 15.3 * phase, 547.7 - 145.35 * (phase - 19.0))
    path.write_text("time,stress\n" + "".join(f"{a:.6f},{b:.6f}\n" for a, b in zip(t, stress, strict=True)))
    code, out, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s")
    assert code == 0, err
    assert "cycle 8" in out and "cycle 9" not in out
    assert "the table shows the first 8 of 12 cycles; -o cycles.csv or --json gives every one" in out
    difference = dict.fromkeys(("critical_stress", "peak_stress", "stick_time", "slip_time"), 0.0)
    rows = [{"record_cycle": k + 2, "model_cycle": k + 1, "difference": difference} for k in range(11)]
    comparison = SimpleNamespace(model_regime="stick-slip", message="", rms_misfit=None, cycles=rows)
    text = _comparison_text(comparison).splitlines()
    assert sum(line.startswith("record cycle ") for line in text) == 8
    assert text[-1] == "(first 8 of 11 compared cycles; --json gives every one)"


# ------------------------------------------------------------------ what `run -o` writes, `analyze` reads without --v0
def _numbers_close(a, b, path=""):
    """Equal structure and strings; numbers to 1e-9 relative or 1e-9 absolute (SI: Pa, s)."""
    if isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            _numbers_close(a[k], b[k], f"{path}/{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for i, (u, v) in enumerate(zip(a, b, strict=True)):
            _numbers_close(u, v, f"{path}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert abs(a - b) <= 1e-9 * max(abs(a), abs(b)) + 1e-9, (path, a, b)
    else:
        assert a == b, (path, a, b)


def test_a_run_trace_is_analysed_at_the_pulling_velocity_its_load_point_records(capsys, tmp_path):
    trace = tmp_path / "run.csv"
    code, _, err = run_main(capsys, "simulate", "--v0", "100 um/s", "--duration", "40 s", "-o", str(trace))
    assert code == 0, err
    code, inferred, err = run_main(capsys, "analyze", str(trace), "--json")
    assert code == 0, err
    assert "--v0 not given: the trace's load point moves at 100 µm/s throughout" in err, err
    code, stated, err = run_main(capsys, "analyze", str(trace), "--json", "--v0", "100 um/s")
    assert code == 0, err
    # "100 um/s" converts to 9.999999999999999e-05 m/s, the load point's slope to 1e-4: the same analysis to round-off
    _numbers_close(json.loads(inferred), json.loads(stated))
    assert json.loads(inferred)["pulling_velocity"] == pytest.approx(1e-4, rel=1e-12)


def test_without_v0_a_trace_with_no_one_pulling_velocity_is_refused_naming_v0(capsys, tmp_path):
    two = tmp_path / "two.csv"
    code, _, err = run_main(capsys, "run", "--model", "transient", "--v0", "350 um/s", "--duration", "0.05 s",
                            "--start", "steady", "--segment", "100 um/s:0.05 s", "-o", str(two))  # fmt: skip
    assert code == 0, err
    code, _, err = run_main(capsys, "analyze", str(two))
    assert code == 2 and "--v0: needed: its load point (load_point_position) does not move at one velocity" in err
    plain = tmp_path / "plain.csv"
    plain.write_text("time,stress\n" + "".join(f"{k},{1 + k % 2}\n" for k in range(30)))  # a trace, no load point
    code, _, err = run_main(capsys, "analyze", str(plain))
    assert code == 2 and "--v0: needed: the trace has no load-point column" in err, err
    assert len(err.strip().splitlines()) == 1
