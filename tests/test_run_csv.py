"""A Run's table and file: units in the header, to_csv/read round-trip, `stickslip analyze` reads it as a trace."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

import stickslip
from stickslip import protocols
from stickslip.errors import DataError
from stickslip.models import Run


@pytest.fixture(scope="module")
def quasi_static_run():
    return stickslip.run("quasi-static", None, protocols.constant(50e-6, 100.0))


def _same(a: float, b: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or a == b


def test_to_csv_and_read_round_trip_at_15_digits(quasi_static_run, tmp_path):
    run = quasi_static_run
    path = tmp_path / "run.csv"
    run.to_csv(path)
    header = path.read_text().splitlines()[1]
    assert header.startswith("time [s],stress [Pa],slider_velocity [m/s],slider_position [m],load_point_position [m]")
    back = Run.read(path)
    for name in ("time", "stress", "slider_velocity", "slider_position", "load_point_position"):
        # 15 significant digits (round 28): each value within 5e-15 of itself
        np.testing.assert_allclose(getattr(back, name), getattr(run, name), rtol=1e-14, atol=0, err_msg=name)
    np.testing.assert_allclose(back.states["chain_fraction"], run.states["chain_fraction"], rtol=1e-14, atol=0)
    assert list(back.states["phase"]) == list(run.states["phase"])
    for field in ("kind", "periods", "amplitude_ratio", "period", "peak", "trough", "evidence"):
        a, b = getattr(back.regime, field), getattr(run.regime, field)
        assert _same(a, b) if isinstance(a, float) else a == b, field
    assert back.mean == run.mean and back.model == "quasi-static"
    assert back.row(get_columns()) == run.row(get_columns())
    assert back.to_frame().attrs["units"] == run.to_frame().attrs["units"]


def get_columns():
    return stickslip.get_model("quasi-static").sweep_columns


def test_a_csv_without_the_mark_is_classified_anew_and_a_wrong_unit_is_refused(tmp_path):
    t = np.linspace(0.0, 40.0, 4001)
    stress = 50.0 + 10.0 * ((t / 4.0) % 1.0)
    lines = ["time [s],stress [Pa],slider_velocity [m/s],slider_position [m],load_point_position [m]"]
    lines += [f"{a!r},{b!r},0.0,0.0,0.0" for a, b in zip(t.tolist(), stress.tolist(), strict=True)]
    path = tmp_path / "plain.csv"
    path.write_text("\n".join(lines) + "\n")
    run = Run.read(path)
    assert run.regime.kind == "stick-slip" and run.period == pytest.approx(4.0, rel=1e-3)
    path.write_text("\n".join([lines[0].replace("stress [Pa]", "stress [kPa]"), *lines[1:]]) + "\n")
    with pytest.raises(DataError, match=r"column 'stress' in \[kPa\]"):
        Run.read(path)
    path.write_text("\n".join([*lines[:5], "1.0,abc,0,0,0", *lines[6:]]) + "\n")
    with pytest.raises(DataError, match="column 'stress': not a number"):
        Run.read(path)


def test_analyze_reads_a_run_csv_as_a_measured_trace(quasi_static_run, tmp_path):
    """The measured-trace analysis finds the model's own cycle: period and sigma_s agree with the Run's."""
    from stickslip.cli.main import cli

    path = tmp_path / "run.csv"
    quasi_static_run.to_csv(path)
    result = CliRunner().invoke(cli, ["analyze", str(path), "--v0", "50 um/s", "--json"], catch_exceptions=False)
    assert result.exit_code == 0, result.output
    text = result.output[result.output.index("{") :]
    found = json.loads(text)
    assert found["regime"] == "stick-slip"
    complete = [c for c in found["cycles"] if c["complete"]]
    assert complete
    assert complete[-1]["period"] == pytest.approx(quasi_static_run.period, rel=1e-3)
    assert complete[-1]["peak_stress"] == pytest.approx(quasi_static_run.peak, rel=1e-6)


def test_plot_returns_the_axes(quasi_static_run):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    assert quasi_static_run.plot(ax=ax) is ax
    assert "stick-slip" in ax.get_title()
    plt.close(fig)


def test_a_rate_and_state_run_without_normal_stress_round_trips_its_friction_and_state(tmp_path):
    rsf = stickslip.get_model("rsf")
    run = rsf.run(rsf.parameters(None, {"b": 0.015, "k": 400.0, "eta": 1e3}), protocols.constant(1e-6, 200.0),
                  start=1.1e-6)  # fmt: skip
    assert run.stress is None and run.signal is run.friction
    path = tmp_path / "rsf.csv"
    run.to_csv(path)
    assert path.read_text().splitlines()[1].startswith("time [s],friction [1],slider_velocity [m/s]")
    back = Run.read(path)
    assert back.stress is None
    np.testing.assert_allclose(back.friction, run.friction, rtol=1e-14, atol=0)  # 15 significant digits
    np.testing.assert_allclose(back.states["state"], run.states["state"], rtol=1e-14, atol=0)
    assert back.state_units["state"] == "s"
    a, b = back.row(rsf.sweep_columns), run.row(rsf.sweep_columns)
    assert a.keys() == b.keys() and all(_same(a[k], b[k]) if isinstance(a[k], float) else a[k] == b[k] for k in a)
