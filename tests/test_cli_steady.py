"""Command line: ``stickslip params``, ``curve`` and ``critical``.

Reference numbers are the issue's independent computation for gelatin-glass:
Vc = 124.1 um/s, sigma_c = 257.4 Pa, sigma(350 um/s) = 391.5 Pa (the paper
prints 125 um/s, 259 Pa and "0.4 kPa").  Bad input goes through ``main()``
(in-process, and twice in a real subprocess) to check exit status 2 and a
one-line message.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import tomllib

from cli_helpers import run, run_main
from stickslip.cli.main import cli
from stickslip.parameters import load_parameters
from stickslip.quasistatic.steady import steady_state
from stickslip.tables import read_table
from stickslip.units import DIMENSIONS

VC_ISSUE = 124.1e-6  # m/s
SIGMA_C_ISSUE = 257.4  # Pa
SIGMA_350_ISSUE = 391.5  # Pa


# --- critical ---------------------------------------------------------------------------------


def test_critical_human_output(runner):
    out = run(runner, "critical")
    vc = float(re.search(r"Vc\s*=\s*([0-9.]+) µm/s", out).group(1))
    sc = float(re.search(r"σc\s*=\s*([0-9.]+) Pa", out).group(1))
    assert vc == pytest.approx(VC_ISSUE * 1e6, rel=5e-3)
    assert sc == pytest.approx(SIGMA_C_ISSUE, rel=5e-3)
    assert "turnover" in out and "mm/s" in out


def test_critical_json_in_si(runner):
    data = json.loads(run(runner, "critical", "--json"))
    assert data["critical_velocity"] == pytest.approx(VC_ISSUE, rel=5e-3)
    assert data["critical_stress"] == pytest.approx(SIGMA_C_ISSUE, rel=5e-3)
    assert data["exists"] is True
    # the no-aging curve turns over at a few mm/s, well above Vc
    assert 1e-3 < data["turnover_velocity"] < 1e-2


def test_critical_stress_scales_with_site_density(runner):
    # sigma = M N0 dl_m j / (birth + i) and nothing else depends on N0 (Eq 7-8):
    # doubling N0 doubles sigma_c and leaves Vc where it was.
    base = json.loads(run(runner, "critical", "--json"))
    double = json.loads(run(runner, "critical", "--json", "--set", "bonds.site_density=2.44e14 1/m^2"))
    assert double["critical_velocity"] == pytest.approx(base["critical_velocity"], rel=1e-9)
    assert double["critical_stress"] == pytest.approx(2 * base["critical_stress"], rel=1e-9)


def test_critical_without_minimum_says_so_and_exits_zero(runner):
    # a very slow aging (tau_a = 1000 s) leaves the aging term negligible: no minimum
    data = json.loads(run(runner, "critical", "--json", "--set", "aging.aging_time=1000 s"))
    assert data["critical_velocity"] is None and data["critical_stress"] is None
    assert data["exists"] is False and "no minimum" in data["message"]
    out = run(runner, "critical", "--set", "aging.aging_time=1000 s")
    assert "no minimum" in out and "Vc  =" not in out


# --- curve ------------------------------------------------------------------------------------


def test_curve_json_default_range(runner):
    data = json.loads(run(runner, "curve", "--format", "json"))
    assert data.pop("units") == {"bonded_fraction": "1", "stress": "Pa", "stress_slope": "Pa s/m", "velocity": "m/s"}
    assert set(data) == {"velocity", "stress", "bonded_fraction", "stress_slope"}
    assert {len(v) for v in data.values()} == {50}
    np.testing.assert_allclose(data["velocity"], np.geomspace(10e-6, 10e-3, 50), rtol=1e-13)
    fraction = np.array(data["bonded_fraction"])
    assert np.all((fraction > 0) & (fraction < 1))


def test_curve_json_matches_the_python_api(runner):
    data = json.loads(
        run(runner, "curve", "--format", "json", "--vmin", "50 um/s", "--vmax", "5 mm/s", "--points", "7")
    )
    api = steady_state(load_parameters(), np.geomspace(50e-6, 5e-3, 7))
    for name in ("velocity", "stress", "bonded_fraction", "stress_slope"):
        np.testing.assert_allclose(data[name], getattr(api, name), rtol=1e-13)


def test_curve_slope_changes_sign_at_the_issue_vc(runner):
    data = json.loads(run(runner, "curve", "--format", "json", "--vmin", "110 um/s", "--vmax", "140 um/s"))
    v, slope = np.array(data["velocity"]), np.array(data["stress_slope"])
    assert np.all(slope[v < VC_ISSUE * 0.995] < 0)
    assert np.all(slope[v > VC_ISSUE * 1.005] > 0)


def test_curve_at_350_um_per_s(runner):
    data = json.loads(run(runner, "curve", "--velocity", "350 um/s", "--format", "json"))
    assert data["velocity"] == [pytest.approx(350e-6, rel=1e-15)]
    assert data["stress"][0] == pytest.approx(SIGMA_350_ISSUE, rel=1e-3)


def test_curve_velocity_in_si_units_and_repeatable(runner):
    data = json.loads(run(runner, "curve", "--velocity", "0.00035 m/s", "--velocity", "1 mm/s", "--format", "json"))
    assert data["velocity"] == pytest.approx([350e-6, 1e-3], rel=1e-15)
    assert data["stress"][0] == pytest.approx(SIGMA_350_ISSUE, rel=1e-3)


def test_curve_no_aging(runner):
    args = ("curve", "--velocity", "350 um/s", "--velocity", "10 mm/s", "--format", "json")
    aging = json.loads(run(runner, *args))
    plain = json.loads(run(runner, *args, "--no-aging"))
    # at 350 um/s ~ V_a aging strengthens the bonds; at 10 mm/s its weight exp(-V/V_a) = e^-27.8 ~ 1e-12
    assert plain["stress"][0] < aging["stress"][0] - 20
    assert plain["stress"][1] == pytest.approx(aging["stress"][1], rel=1e-9)


def test_curve_csv_header_and_round_trip(runner, tmp_path):
    out = run(runner, "curve", "--format", "csv", "--points", "6")
    lines = out.splitlines()
    assert lines[0] == "velocity [m/s],stress [Pa],bonded_fraction [1],stress_slope [Pa s/m]"
    assert len(lines) == 7
    values = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    np.testing.assert_allclose(values[:, 0], np.geomspace(10e-6, 10e-3, 6), rtol=1e-14)
    api = steady_state(load_parameters(), values[:, 0])
    for k, name in enumerate(("velocity", "stress", "bonded_fraction", "stress_slope")):
        # 15 significant digits (round 28): each value within 5e-15 of itself, and of the JSON's
        np.testing.assert_allclose(values[:, k], getattr(api, name), rtol=1e-14)


@pytest.mark.skipif(
    "stress_per_velocity" not in DIMENSIONS,
    reason="units.DIMENSIONS has no dimension for 'Pa s/m' (stress_per_velocity); requested from the lead",
)
def test_curve_csv_reads_back_with_read_table(runner, tmp_path):
    path = tmp_path / "curve.csv"
    run(runner, "curve", "--format", "csv", "--points", "6", "-o", str(path))
    table = read_table(
        path,
        {
            "velocity": "velocity",
            "stress": "stress",
            "bonded_fraction": "dimensionless",
            "stress_slope": "stress_per_velocity",
        },
        required=["velocity", "stress", "bonded_fraction", "stress_slope"],
    )
    api = steady_state(load_parameters(), table["velocity"])
    for name in ("stress", "bonded_fraction", "stress_slope"):
        np.testing.assert_allclose(table[name], getattr(api, name), rtol=1e-14)  # 15 digits: 5e-15 at most


def test_curve_csv_units_mean_si(tmp_path):
    # the header units, converted by pint, are exactly the SI base units the values are in
    from stickslip.units import registry

    ureg = registry()
    assert ureg.Quantity(1, "m/s").to_base_units().magnitude == 1
    assert ureg.Quantity(1, "Pa s/m").to("kg/m^2/s").magnitude == pytest.approx(1, rel=1e-15)


def test_curve_table_is_in_human_units(runner):
    out = run(runner, "curve", "--velocity", "350 um/s", "--velocity", "50 um/s")
    assert "µm/s" in out and "σ [Pa]" in out
    row = next(line for line in out.splitlines() if " 350 " in line)
    assert "391.5" in row and "strengthening" in row
    assert "weakening" in next(line for line in out.splitlines() if " 50 " in line)


def test_curve_output_file(runner, tmp_path):
    path = tmp_path / "out.json"
    result = runner.invoke(cli, ["curve", "--points", "3", "--format", "json", "-o", str(path)])
    assert result.exit_code == 0 and result.output == ""
    assert json.loads(path.read_text())["velocity"] == pytest.approx([1e-5, 3.1622776601683795e-4, 1e-2])


def test_curve_plot_writes_png(runner, tmp_path):
    path = tmp_path / "curve.png"
    run(runner, "curve", "--points", "4", "--format", "csv", "--plot", str(path))
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000


# --- params -----------------------------------------------------------------------------------


def test_params_show_lists_every_key_with_units(runner):
    out = run(runner, "params", "show")
    for key in load_parameters().as_dict():
        assert key in out
    for text in ("224 µs", "1.074 µm", "360 µm/s", "293.15 K", "1 Å", "4 kPa"):
        assert text in out, text
    # derived quantities: lambda/kT = 1e-10/(1.380649e-23 * 293.15), Gd/h = 4 kPa / 10 mm, ln(5/3)/(2/3)
    for text in ("2.47074e+10 1/N", "2.47074 1/µm", "400 kPa/m", "0.766238", "306.495 kPa/m"):
        assert text in out, text


def test_params_show_with_set(runner):
    out = run(runner, "params", "show", "--set", "bonds.bond_time=1 ms", "--set", "block.height=0.02 m")
    row = next(line for line in out.splitlines() if "bonds.bond_time (set)" in line)
    assert "1 ms" in row
    assert "bonds.site_density (set)" not in out
    assert "20 mm" in out and "200 kPa/m" in out


def test_params_list(runner):
    assert "gelatin-glass" in run(runner, "params", "list")


def test_params_export_round_trip_through_the_cli(runner, tmp_path):
    path = tmp_path / "mine.toml"
    run(runner, "params", "export", "gelatin-glass", "-o", str(path), "--set", "aging.aging_velocity=0.0004 m/s")
    loaded = load_parameters(str(path))
    assert loaded.aging.aging_velocity == 0.0004
    stdout_text = run(runner, "params", "export")
    assert load_parameters().as_dict() == load_parameters(_saved(tmp_path, stdout_text)).as_dict()
    assert tomllib.loads(stdout_text)["bonds"]["bond_time"] == "224 us"
    # the file works as --params, with the override still in it
    via_file = json.loads(run(runner, "curve", "--velocity", "350 um/s", "--format", "json", "--params", str(path)))
    via_set = json.loads(
        run(runner, "curve", "--velocity", "350 um/s", "--format", "json", "--set", "aging.aging_velocity=0.0004 m/s")
    )
    assert via_file == via_set
    assert via_file["stress"][0] != pytest.approx(SIGMA_350_ISSUE, rel=1e-3)
    assert run(runner, "params", "show", str(path)) == run(runner, "params", "show", "--params", str(path))


def _saved(tmp_path: Path, text: str) -> str:
    path = tmp_path / "stdout.toml"
    path.write_text(text, encoding="utf-8")
    return str(path)


# --- bad input: exit status 2, one line, no traceback -----------------------------------------


BAD_INPUT = [
    (["critical", "--set", "bonds.nope=1"], "bonds.nope"),
    (["critical", "--set", "bonds.bond_time=224 m"], "bonds.bond_time: '224 m' has dimension"),
    (["critical", "--set", "block.height=-1 mm"], "block.height: expected a positive value"),
    (["critical", "--set", "bonds.site_density=0"], "bonds.site_density: expected a positive value"),
    (["critical", "--set", "aging.aging_time=nan"], "aging.aging_time: expected a finite"),
    (["critical", "--set", "aging.aging_time=inf"], "aging.aging_time: expected a finite"),
    (["critical", "--set", "bonds.bond_time"], "expected SECTION.KEY=VALUE"),
    (["critical", "--params", "no-such-set"], "unknown parameter set 'no-such-set'"),
    (["curve", "--vmin", "1 mm/s", "--vmax", "1 mm/s"], "--vmin '1 mm/s' (0.001 m/s) must be below --vmax"),
    (["curve", "--vmin", "2 mm/s", "--vmax", "1 mm/s"], "must be below --vmax"),
    (["curve", "--velocity", "1 mm/s", "--vmin", "1 um/s"], "--velocity cannot be combined with --vmin"),
    (["curve", "--velocity", "1 mm/s", "--points", "3"], "--velocity cannot be combined with --points"),
    (["curve", "--velocity", "-1 mm/s"], "--velocity: expected a positive value"),
    (["curve", "--velocity", "0"], "--velocity: expected a positive value"),
    (["curve", "--velocity", "nan"], "--velocity: expected a finite"),
    (["curve", "--velocity", "3 s"], "--velocity: '3 s' has dimension"),
    (["curve", "--vmin", "-5 um/s"], "--vmin: expected a positive value"),
    (["curve", "--points", "1"], "--points"),
    (["curve", "--points", "many"], "--points"),
    (["curve", "--format", "xml"], "--format"),
    (["params", "show", "no-such-set"], "unknown parameter set"),
    (["params", "show", "gelatin-glass", "--params", "other"], "either NAME"),
]


@pytest.mark.parametrize(("args", "message"), BAD_INPUT, ids=[" ".join(a) for a, _ in BAD_INPUT])
def test_bad_input_is_one_line_and_exit_2(capsys, args, message):
    status, out, err = run_main(capsys, *args)
    assert status == 2
    assert out == ""
    assert err.count("\n") == 1 and err.startswith("stickslip: error: ")
    assert message in err
    assert "Traceback" not in err


def test_missing_and_malformed_parameter_files(capsys, tmp_path):
    status, _, err = run_main(capsys, "critical", "--params", str(tmp_path / "missing.toml"))
    assert status == 2 and "missing.toml" in err and "not found" in err and err.count("\n") == 1
    bad = tmp_path / "bad.toml"
    bad.write_text("[bonds\nsite_density = ", encoding="utf-8")
    status, _, err = run_main(capsys, "curve", "--params", str(bad))
    assert status == 2 and "bad.toml" in err and "malformed TOML" in err and err.count("\n") == 1


def test_unwritable_output_is_one_line(capsys, tmp_path):
    status, _, err = run_main(capsys, "curve", "--points", "2", "-o", str(tmp_path / "no" / "dir" / "x.txt"))
    assert status == 2 and err.count("\n") == 1 and "Traceback" not in err


def _subprocess(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "stickslip.cli.main", *args], capture_output=True, text=True, timeout=120, check=False
    )


def test_real_process_success():
    done = _subprocess("critical", "--json")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["critical_velocity"] == pytest.approx(VC_ISSUE, rel=5e-3)


def test_real_process_bad_input():
    done = _subprocess("curve", "--set", "bonds.bond_time=224 m")
    assert done.returncode == 2
    assert done.stdout == ""
    assert done.stderr.count("\n") == 1 and "bonds.bond_time" in done.stderr
    assert "Traceback" not in done.stderr


# --- plotting ---------------------------------------------------------------------------------


def test_steady_state_plot_returns_axes_in_um_per_s():
    from matplotlib._pylab_helpers import Gcf

    managers = Gcf.get_num_fig_managers()
    result = steady_state(load_parameters(), np.array([1e-3, 1e-4, 5e-4]), aging=False)
    ax = result.plot()
    assert ax.get_xscale() == "log"
    (line,) = ax.get_lines()
    np.testing.assert_allclose(line.get_xdata(), [100.0, 500.0, 1000.0])  # sorted, um/s
    np.testing.assert_allclose(line.get_ydata(), result.stress[[1, 2, 0]])
    assert line.get_label() == "without aging"
    assert Gcf.get_num_fig_managers() == managers  # no pyplot figure was opened
    single = steady_state(load_parameters(), 350e-6).plot(label="one")
    assert single.get_lines()[0].get_marker() == "o"


def test_figure_steady_curve_marks_vc_and_data():
    from stickslip.plots.steady import figure_steady_curve

    data = {"velocity": np.array([2e-4, 1e-3]), "stress": np.array([300.0, 650.0])}
    fig = figure_steady_curve(load_parameters(), vmin=20e-6, vmax=5e-3, data=data)
    ax = fig.axes[0]
    labels = [line.get_label() for line in ax.get_lines()]
    assert {"with aging", "without aging", "critical point"} <= set(labels)
    critical = ax.get_lines()[labels.index("critical point")]
    assert critical.get_xdata()[0] == pytest.approx(VC_ISSUE * 1e6, rel=5e-3)
    assert critical.get_ydata()[0] == pytest.approx(SIGMA_C_ISSUE, rel=5e-3)
    texts = " ".join(t.get_text() for t in ax.texts)
    assert "velocity weakening" in texts and "velocity strengthening" in texts
    (container,) = ax.containers  # errorbar
    assert container.get_label() == "data"
    points = container.lines[0]
    np.testing.assert_allclose(points.get_xdata(), [200.0, 1000.0])
    np.testing.assert_allclose(points.get_ydata(), [300.0, 650.0])
    with pytest.raises(ValueError, match="vmin < vmax"):
        figure_steady_curve(load_parameters(), vmin=1e-3, vmax=1e-4)
