"""Round 29 (tester R): a sweep's exit status, summary counts, CSV units, transient rows' cycle numbers and Vc, and
the start a compared transient run really made."""

from __future__ import annotations

import csv
import json
import math
import re

import pandas as pd
import pytest
from scipy.optimize import minimize_scalar

from cli_helpers import run_main
from stickslip import load_parameters
from stickslip.quasistatic.steady import steady_state


def _vc_by_minimisation() -> float:
    """Vc of gelatin-glass found here, independently of the package's critical-point search: the minimum of the
    aging steady curve σ(V) (Eqs 6-8), bracketed between 50 and 300 µm/s, located in log V."""
    params = load_parameters("gelatin-glass")
    found = minimize_scalar(
        lambda u: float(steady_state(params, math.exp(u), aging=True).stress),
        bounds=(math.log(50e-6), math.log(300e-6)),
        method="bounded",
        options={"xatol": 1e-7},
    )
    return math.exp(found.x)


@pytest.fixture(scope="module")
def vc() -> float:
    return _vc_by_minimisation()


# ----------------------------------------------------------------------------- 1. exit status of failed sweeps


def test_a_sweep_whose_points_all_failed_exits_3_as_the_failed_run_does(tmp_path, capsys):
    """Tester R: every point 'failed' (the model ran and could not finish) exited 0; `simulate` of the point exits 3."""
    point = ["--v0", "1 m/s", "--duration", "60 s"]
    status, _, _ = run_main(capsys, "simulate", *point)
    assert status == 3  # the single run: a failed run
    out = tmp_path / "failed"
    status, _, err = run_main(
        capsys, "sweep", *point, "--vary", "bonds.bond_time=224 us", "--workers", "0", "-o", str(out)
    )
    assert status == 3, err
    assert "stickslip: the sweep failed: no point of the 1 ran to its end" in err and "Traceback" not in err
    assert (pd.read_parquet(out)["status"] == "failed").all()  # the rows are written all the same


def test_a_sweep_of_failed_and_error_points_and_none_ok_exits_3(tmp_path, capsys):
    """Tester R's d6: one point failed, the others errors, none ok: exited 0.  At 1 m/s the gel's point fails (no jump
    velocity); at 50 um/s 1e8 s holds over 100 000 cycles of 23 s: an error (no result).  (The error was a bond time
    of 1 ms, whose steady curve has no Vc; since round 30 that run returns a failed result, as the others do.)"""
    out = tmp_path / "mixed"
    argv = ["sweep", "--vary", "pulling_velocity=1 m/s,50 um/s", "--duration", "1e8 s", "--workers", "0"]
    status, _, err = run_main(capsys, *argv, "-o", str(out))
    frame = pd.read_parquet(out)
    assert sorted(frame["status"]) == ["error", "failed"]
    assert status == 3, err
    assert "(1 failed, 1 error)" in err and "no point of the 2 ran to its end (1 failed and 1 error(s)" in err


def test_a_sweep_with_one_point_ok_still_exits_0(tmp_path, capsys):
    out = tmp_path / "some-ok"
    argv = ["sweep", "--vary", "pulling_velocity=50 um/s,1 m/s", "--duration", "60 s", "--workers", "0", "-o"]
    status, _, err = run_main(capsys, *argv, str(out))
    assert status == 0, err


# ----------------------------------------------------------------------------- 8. summary counts add up to the rows


def test_the_summary_regime_counts_add_up_to_the_rows_naming_the_failed(tmp_path, capsys):
    """Tester R: "undetermined 1" + "(12 failed)" beside 13 undetermined rows: failed rows were left out."""
    out = tmp_path / "counts"
    argv = ["sweep", "--v0", "1 m/s", "--vary", "bonds.bond_time=224 us,300 us,1 ms", "--duration", "60 s"]
    _, _, err = run_main(capsys, *argv, "--workers", "0", "-o", str(out))
    line = next(x for x in err.splitlines() if x.startswith("sweep: 3 points in"))
    frame = pd.read_parquet(out)
    shown = line.split("; regimes: ")[1].split("; ")[0]
    counted = {}
    for part in shown.split(", "):
        match = re.fullmatch(r"(.+) (\d+)(?: \((\d+) failed\))?", part)
        assert match, part
        counted[match.group(1)] = (int(match.group(2)), int(match.group(3) or 0))
    assert sum(n for n, _ in counted.values()) == len(frame) == 3
    for regime, rows in frame[frame["status"] != "error"].groupby("regime"):
        assert counted[regime] == (len(rows), int((rows["status"] == "failed").sum()))
    assert counted.get("none (error)", (0, 0))[0] == int((frame["status"] == "error").sum())


# ----------------------------------------------------------------------------- 4. --workers -1


def test_negative_workers_are_refused_in_one_line(tmp_path, capsys):
    out = tmp_path / "neg"
    status, _, err = run_main(capsys, "sweep", "--v0", "50 um/s", "--vary", "bonds.bond_time=100 us,1 ms", "--workers",
                              "-1", "-o", str(out))  # fmt: skip
    assert status == 2 and err.count("\n") == 1 and "--workers" in err and "-1" in err, err
    assert not out.exists()


# ----------------------------------------------------------------------------- 5. a file that names its units


def test_the_rows_as_csv_name_their_units_and_have_no_index(tmp_path, capsys):
    from stickslip.sweeps import write_table

    out = tmp_path / "sw"
    argv = ["sweep", "--vary", "pulling_velocity=50 um/s,1 m/s", "--duration", "60 s", "--workers", "0", "-o"]
    run_main(capsys, *argv, str(out))
    frame = pd.read_parquet(out).sort_values("point").reset_index(drop=True)
    target = write_table(out, tmp_path / "sw.csv")
    with open(target, newline="", encoding="utf-8") as handle:
        rows = list(csv.reader(handle))
    truth = {"point": None, "pulling_velocity": "m/s", "period": "s", "peak_stress": "Pa", "mean_stress": "Pa",
             "critical_velocity": "m/s", "regime": None, "message": None, "wall_time": "s"}  # fmt: skip
    header = rows[0]
    assert len(header) == len(frame.columns)  # no index column
    for name, unit in truth.items():
        assert (name if unit is None else f"{name} [{unit}]") in header
    assert len(rows) == 1 + len(frame)
    velocity = header.index("pulling_velocity [m/s]")
    assert [float(r[velocity]) for r in rows[1:]] == pytest.approx(list(frame["pulling_velocity"]), rel=1e-14)
    message = header.index("message")
    assert [r[message] for r in rows[1:]] == list(frame["message"])  # its commas quoted, not new columns
    back = pd.read_json(write_table(out, tmp_path / "sw.json"), typ="series")
    assert back["units"]["peak_stress"] == "Pa" and len(back["rows"]) == len(frame)
    # the refusal of -o sw.csv names that route
    status, _, err = run_main(capsys, *argv, str(tmp_path / "other.csv"))
    assert status == 2 and f"write_table('{tmp_path / 'other'}', '{tmp_path / 'other.csv'}')" in err, err


def test_the_manifest_names_the_unit_of_every_value_it_holds(tmp_path, capsys):
    out = tmp_path / "m"
    argv = ["sweep", "--v0", "50 um/s", "--vary", "block.stiffness=100 kPa/m,200 kPa/m", "--duration", "5 s"]
    run_main(capsys, *argv, "--set", "bonds.bond_time=300 us", "--workers", "0", "-o", str(out))
    manifest = json.loads((out / "_manifest.json").read_text(encoding="utf-8"))
    units = manifest["units"]
    known = {
        "pulling_velocity": "m/s",
        "block.stiffness": "Pa/m",
        "bonds.bond_time": "s",
        "duration": "s",
        "block.shear_modulus": "Pa",
        "block.height": "m",
        "aging.aging_velocity": "m/s",
        "peak_stress": "Pa",
    }
    for key, unit in known.items():
        assert units[key] == unit, key
    fixed = manifest["specification"]["fixed"]
    assert set(fixed) <= set(units)  # every fixed value has its unit


# ----------------------------------------------------------------------------- 3 and 9. transient rows


@pytest.fixture(scope="module")
def transient_rows(tmp_path_factory):
    from stickslip.sweeps import sweep

    vary = ["pulling_velocity=100 um/s,200 um/s", "block.effective_stiffness=300 kPa/m"]
    return sweep(vary, model="transient", stick_population=True, duration="20 s", workers=0)


def test_a_transient_row_after_one_slip_gives_that_slips_stick_and_jump(transient_rows):
    """Tester R: one slip in 20 s (a start-up cycle, undetermined) left stick_time, peak_stress and jump_velocity NaN
    while the message quoted them.  Now the last slip's: the held block's stress rises as K V0 t (σs - σ0 = K V0
    ts) and the jump lands on the aging curve's right branch at σs (the quasi-static jump, computed apart)."""
    import stickslip
    from stickslip import protocols
    from stickslip.quasistatic.jump import jump_velocity

    row = transient_rows[transient_rows["pulling_velocity"] == 100e-6].iloc[0]
    assert row["regime"] != "stick-slip" and math.isnan(row["period"])  # nothing repeats: no period
    for name in ("stick_time", "peak_stress", "jump_velocity"):
        assert math.isfinite(row[name]), name
    run = stickslip.run("transient", {"block.effective_stiffness": 300e3}, protocols.constant(100e-6, 20.0),
                        start="steady", stick_population=True)  # fmt: skip
    first = run.native.cycles[-1]
    assert len(run.native.cycles) == 1
    k_v0 = 300e3 * 100e-6
    assert row["stick_time"] == pytest.approx((row["peak_stress"] - first.start_stress) / k_v0, rel=1e-3)
    landing = jump_velocity(load_parameters("gelatin-glass"), row["peak_stress"], "aging").velocity
    assert row["jump_velocity"] == pytest.approx(landing, rel=1e-4)


def test_transient_rows_carry_the_critical_velocity(transient_rows, vc):
    """Tester R: critical_velocity was NaN in every transient row while their messages quoted Vc = 124.1 µm/s."""
    assert list(transient_rows["critical_velocity"]) == pytest.approx([vc, vc], rel=1e-4)


# ----------------------------------------------------------------------------- 2. compare: the start really made


def test_compare_says_a_steady_start_below_vc_starts_just_above_vc(capsys, vc):
    argv = ["compare", "--models", "quasi-static,transient", "--v0", "100 um/s", "--duration", "2 s", "--start",
            "transient=steady", "--setting", "stick_population=true", "--json"]  # fmt: skip
    status, out, err = run_main(capsys, *argv)
    assert status == 0, err
    said = json.loads(out)["models"]["transient"]["start"]
    match = re.match(r"steady population at ([0-9.]+) µm/s", said)
    assert match, said
    began = float(match.group(1)) * 1e-6
    assert began == pytest.approx(vc, rel=2e-3) and began > vc  # the stable side of the critical point, not 100
    assert "100 µm/s is below Vc" in said
    argv[argv.index("100 um/s")] = "200 um/s"  # above Vc: the steady start is at V0 itself
    status, out, err = run_main(capsys, *argv)
    assert json.loads(out)["models"]["transient"]["start"] == "steady population at 200 µm/s"


def test_a_table_is_not_written_into_the_sweeps_own_folder(tmp_path, capsys):
    """Tester S: write_table(folder, folder/'all.parquet') made every point read twice, and folder/_manifest.json
    replaced the sweep's manifest; both are refused and the sweep reads as before."""
    from stickslip.errors import DataError
    from stickslip.sweeps import load_sweep, write_table

    out = tmp_path / "sw"
    run_main(capsys, "sweep", "--vary", "pulling_velocity=50 um/s,1 m/s", "--duration", "60 s", "--workers", "0",
             "-o", str(out))  # fmt: skip
    before = sorted(p.name for p in out.iterdir())
    for name in ("all.parquet", "_manifest.json", "rows.csv"):
        with pytest.raises(DataError, match="inside the sweep's folder"):
            write_table(out, out / name)
    assert sorted(p.name for p in out.iterdir()) == before
    frame, _ = load_sweep(out)
    assert len(frame) == 2
