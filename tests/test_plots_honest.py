"""Issue 28 item 6: figures that do not mislead (each check reads the drawn figure, not the code's numbers)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np

import stickslip
from stickslip.plots.overlay import overlay_figure
from stickslip.plots.steady import figure_steady_curve
from stickslip.plots.transient import _linear_threshold

P = stickslip.load_parameters("gelatin-glass")


def test_a_constant_friction_is_not_autoscaled_into_a_spike():
    """A steady rate-and-state run's mu is constant to round-off (2e-13); its axis spans at least 1e-6 of mu."""
    rsf = stickslip.run("rsf", None, stickslip.protocols.constant(50e-6, 60.0))
    qs = stickslip.run("quasi-static", P, stickslip.protocols.constant(50e-6, 60.0))
    fig = overlay_figure({"quasi-static": qs, "rsf": rsf})
    right = next(ax for ax in fig.axes if ax.get_ylabel().startswith("friction coefficient"))
    lo, hi = right.get_ylim()
    mu = float(np.median(rsf.friction))
    assert hi - lo >= 1e-6 * mu and lo <= mu <= hi
    assert right.yaxis.get_major_formatter().get_useOffset() is False


def test_the_steady_curve_names_both_weakening_branches_and_keeps_the_minimum_in_view():
    fig = figure_steady_curve(P)
    texts = " ".join(t.get_text() for t in fig.axes[0].texts)
    assert "velocity strengthening" in texts and "weakening again" in texts  # the maximum at 5.04 mm/s
    ax = stickslip.steady_state(P, np.geomspace(1e-5, 1e-2, 200)).plot()
    top = ax.get_ylim()[1]
    c = stickslip.critical_point(P)
    assert top < 5 * c.turnover_stress and top > c.turnover_stress  # not 19 kPa: the minimum is not squashed


def test_the_simulation_legend_names_sigma_c():
    from stickslip.plots.cycles import plot_simulation

    ax = plot_simulation(stickslip.simulate(P, pulling_velocity=50e-6, duration=30.0))
    labels = ax.get_legend_handles_labels()[1]
    assert any(label.startswith("σc = 257.4") for label in labels), labels


def test_a_run_figure_names_the_pulling_velocity():
    run = stickslip.run("quasi-static", P, stickslip.protocols.constant(50e-6, 30.0))
    assert "V0 = 50 µm/s" in run.plot().get_title()


def test_the_velocity_axis_leaves_a_decade_between_zero_and_the_first_tick():
    v = np.array([0.0, 0.0, 7.9, 300.0, 928.0])
    assert _linear_threshold(v) == 1.0  # 10^floor(log10 7.9): 0, 10^0, 10^1 a decade apart


def test_critical_has_a_plot(tmp_path, capsys):
    from cli_helpers import run_main

    png = tmp_path / "critical.png"
    code, out, err = run_main(capsys, "critical", "--plot", str(png))
    assert code == 0 and png.stat().st_size > 10_000 and "Vc" in out, err
    code, _, err = run_main(capsys, "critical", "--plot", str(tmp_path / "nowhere" / "c.png"))
    assert code == 2 and err.count("\n") == 1, err
