"""``stickslip fit steady|stick`` end to end, in process (main() with argv)."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest
from scipy import stats

from stickslip.cli.main import main
from stickslip.fitting import datasets, read_steady_data
from stickslip.parameters import load_parameters

SYNTHETIC = str(datasets.synthetic_steady_path())


def run(capsys, *argv: str) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as info:
        main(list(argv))
    out, err = capsys.readouterr()
    return int(info.value.code), out, err


def test_fit_steady_json_and_files(tmp_path, capsys):
    toml, report, png = tmp_path / "fitted.toml", tmp_path / "fit.md", tmp_path / "fit.png"
    code, out, err = run(
        capsys, "fit", "steady", SYNTHETIC, "--json", "-o", str(toml), "--report", str(report), "--plot", str(png)
    )
    assert code == 0, err
    result = json.loads(out)
    for name in ("critical_velocity", "critical_stress"):
        assert set(result[name]) >= {"value", "stderr", "interval"}
    assert result["parameters"]["bonds.max_extension"]["fixed"] is True
    assert set(result["parameters"]["bonds.site_density"]) >= {"value", "stderr", "interval"}
    assert 0.5 < result["reduced_chi_square"] < 2.0
    assert "## Critical point" in report.read_text()
    assert png.read_bytes()[:4] == b"\x89PNG"
    # the fitted file works in another command and reproduces the data's curve
    code, out, err = run(capsys, "critical", "--params", str(toml))
    assert code == 0, err
    vc = result["critical_velocity"]["value"] * 1e6
    assert f"{vc:.6g}" in out
    data = read_steady_data(SYNTHETIC)
    argv = ["curve", "--params", str(toml), "--format", "json"]
    for v in data.velocity:
        argv += ["--velocity", f"{float(v)!r} m/s"]
    code, out, err = run(capsys, *argv)
    assert code == 0, err
    stress = np.array(json.loads(out)["stress"])
    z = (data.stress - stress) / data.stress_err
    assert stats.chi2.sf(float(z @ z), 20) > 0.01


def test_fit_steady_prints_the_report_with_units(capsys):
    code, out, err = run(
        capsys, "fit", "steady", SYNTHETIC, "--fix", "bonds.bond_time=224 us", "--free", "bonds.breakage_weight"
    )
    assert code == 0, err
    assert "# Steady friction fit" in out and "µm/s" in out
    assert "fixed by request" in out


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        ("velocity [um/s],stress [Pa]\n100,250\n200,300\n200,310\n400,400\n", "4 data rows at 3 distinct velocities"),
        ("velocity [um/s],stress [Pa]\n100,250\n200,-3\n300,310\n400,400\n", "row 3, column 'stress'"),
        ("velocity [um/s],friction [Pa]\n100,250\n", "unknown column 'friction'"),
        ("velocity [zorks],stress [Pa]\n100,250\n", "unknown unit"),
    ],
)
def test_bad_files_exit_2_with_one_line(tmp_path, capsys, content, expected):
    path = tmp_path / "bad.csv"
    path.write_text(content)
    code, out, err = run(capsys, "fit", "steady", str(path))
    assert code == 2 and out == ""
    assert err.startswith("stickslip: error: ") and err.count("\n") == 1
    assert expected in err and "Traceback" not in err


STICK_HEADER = "pulling_velocity [um/s],stick_time [s],peak_stress [Pa],stick_slope [Pa/s],stiffness [kPa/m]\n"


@pytest.mark.parametrize(
    ("row", "expected"),
    [
        # a fuzz of the command line (2026-11-29): 1e300 Pa/s held the stick fit's integration for minutes
        ("50,17.8,552,1e300,437", "row 3, column 'stick_slope': 1e+300 Pa/s is outside the range of a stick phase's"),
        ("50,1e20,552,16.3,437", "row 3, column 'stick_time': 1e+20 s is outside the range of a stick time"),
        ("50,17.8,1e15,16.3,437", "row 3, column 'peak_stress': 1e+15 Pa is outside the range of a friction stress"),
        ("50,17.8,552,16.3,1e300", "row 3, column 'stiffness': 1e+303 Pa/m is outside the range of a block's"),
        ("1e20,17.8,552,16.3,437", "row 3, column 'pulling_velocity': 1e+14 m/s is outside the range"),
    ],
)
def test_stick_values_outside_their_physical_range_are_refused_at_once(tmp_path, capsys, row, expected):
    path = tmp_path / "stick.csv"
    path.write_text(STICK_HEADER + "50,18.3,554,16.5,431\n" + row + "\n100,18.2,658,35.0,457\n")
    code, out, err = run(capsys, "fit", "stick", str(path))
    assert code == 2 and out == "" and err.count("\n") == 1, err
    assert expected in err and "check the units in the header" in err, err


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--fix", "bonds.bond_time"], "expected KEY=VALUE"),
        (["--fix", "bonds.colour=3"], "unknown parameter key"),
        (["--free", "block.height"], "does not depend on it"),
        (["--split", "800"], '--split 800: a velocity needs a unit, e.g. --split "800 um/s"'),
        (["--split", "800 m/s"], "no data point at or above the split"),
        (["--split", "800 Pa"], "--split"),
        (["--corner", "c.png"], "--corner needs --bayes"),
    ],
)
def test_bad_options_exit_2(capsys, argv, expected):
    code, _, err = run(capsys, "fit", "steady", SYNTHETIC, *argv)
    assert code == 2 and expected in err and err.count("\n") == 1


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (["--fix", "bonds.site_density=1e300 1/m^2"], "bonds.site_density = 1e+300 (SI) held fixed"),  # was exit 1
        (["--set", "bonds.site_density=1e300 1/m^2"], "squares overflow"),  # named bonds.site_density ... got 0
        (["--set", "bonds.site_density=1e-300 1/m^2"], "squares vanish"),  # ... got inf
        (["--fix", "bonds.bond_time=1e-300 s"], "bonds.bond_time = 1e-300 (SI) held fixed"),  # site_density, nan
    ],
)
def test_start_values_outside_the_box_are_refused_naming_what_was_given(capsys, argv, named):
    """A fuzz of the command line (2026-11-29): such values overflowed in the search (an internal error, exit 1)
    or rescaled N0 to 0, inf or nan and were reported against bonds.site_density, which the user had not given."""
    code, out, err = run(capsys, "fit", "steady", SYNTHETIC, *argv)
    assert code == 2 and out == "" and err.count("\n") == 1, err
    assert named in err and "the fit cannot start there" in err, err
    assert "nan" not in err and "inf" not in err.replace("1e+300", ""), err


def test_bayes_option(tmp_path, capsys):
    corner_png = tmp_path / "corner.png"
    code, out, err = run(
        capsys, "fit", "steady", SYNTHETIC, "--bayes", "--walkers", "10", "--steps", "20", "--seed", "3",
        "--corner", str(corner_png), "--json",
    )  # fmt: skip
    assert code == 0, err
    assert err == ""  # no stray root-logger output from corner (issue 9)
    posterior = json.loads(out)["posterior"]
    assert posterior["walkers"] == 10 and posterior["steps"] == 20
    assert any("uniform in ln" in p for p in posterior["priors"])
    assert posterior["critical_velocity"]["value"] > 0
    assert corner_png.read_bytes()[:4] == b"\x89PNG"


def test_bayes_without_emcee(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "emcee", None)
    code, _, err = run(capsys, "fit", "steady", SYNTHETIC, "--bayes")
    assert code == 2 and "pip install stickslip[bayes]" in err and err.count("\n") == 1


def test_fit_stick(tmp_path, capsys):
    table = tmp_path / "stick.csv"
    table.write_text(
        "pulling_velocity [um/s],stick_time [s],start_stress [Pa]\n"
        "50,18.3,255\n50,18.3,262\n100,8.82,261\n100,8.61,261\n"
    )
    toml = tmp_path / "stick.toml"
    code, out, err = run(
        capsys, "fit", "stick", str(table), "--json", "-o", str(toml), "--fix", "stick.break_rate=1.4e-4 1/s"
    )
    assert code == 0, err
    result = json.loads(out)
    assert result["parameters"]["stick.break_rate"]["fixed"] is True
    assert set(result["parameters"]["stick.attached_chains"]) >= {"value", "stderr", "interval"}
    fitted = load_parameters(str(toml))
    assert fitted.stick.attached_chains == pytest.approx(result["parameters"]["stick.attached_chains"]["value"])
    code, out, err = run(capsys, "fit", "stick", str(table), "--exclude-row", "7")
    assert code == 2 and "no such data row" in err


def test_curve_output_feeds_fit_steady(tmp_path, capsys):
    """What one command writes the next reads (issue 9): curve's extra columns are ignored with a note."""
    curve = tmp_path / "c.csv"
    code, _, err = run(capsys, "curve", "--format", "csv", "-o", str(curve), "--vmin", "140 um/s", "--points", "30")
    assert code == 0, err
    assert "bonded_fraction" in curve.read_text().splitlines()[0]
    code, out, err = run(capsys, "fit", "steady", str(curve), "--json")
    assert code == 0, err
    result = json.loads(out)
    notes = [m for m in result["messages"] if "ignored" in m]
    assert len(notes) == 1 and "bonded_fraction" in notes[0] and "stress_slope" in notes[0]
    assert result["reduced_chi_square"] is None  # noise estimated from the residuals
    # an unknown column still fails, naming it
    bad = tmp_path / "bad.csv"
    bad.write_text(curve.read_text().replace("bonded_fraction", "friction_colour", 1))
    code, out, err = run(capsys, "fit", "steady", str(bad))
    assert code == 2 and "unknown column 'friction_colour'" in err and err.count("\n") == 1


def test_absurd_stresses_are_refused_with_one_line_and_no_warnings(tmp_path, capsys):
    path = tmp_path / "big.csv"
    path.write_text("velocity,stress\n" + "".join(f"{v!r},{1e300 * (1 + k)!r}\n" for k, v in enumerate(
        [1e-5, 1e-4, 1e-3, 1e-2, 1e-1])))  # fmt: skip
    code, out, err = run(capsys, "fit", "steady", str(path))
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "row 2, column 'stress'" in err and "outside the range of a friction stress" in err


def test_fit_stick_report_and_plot(tmp_path, capsys):
    png = tmp_path / "stick.png"
    code, out, err = run(capsys, "fit", "stick", str(datasets.table1_path()), "--exclude-row", "11", "--plot", str(png))
    assert code == 0, err
    assert "χ²ᵣ = 1 by construction" in out and "reduced χ² =" not in out
    assert png.read_bytes()[:4] == b"\x89PNG"
