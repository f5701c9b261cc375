"""The look of the report's figures and of the phase diagrams (issue 19): legends name what is drawn, markers
belong visibly to their curve, axes name the quantity and its unit and follow the sweep's spacing."""

from __future__ import annotations

import re

import numpy as np
import pytest
from matplotlib.colors import to_rgba

from stickslip.parameters import load_parameters
from stickslip.plots.cycles import figure_cycles
from stickslip.plots.sweeps import plot_phase_diagram
from stickslip.quasistatic.cycle import simulate
from stickslip.report.computations import DURATIONS, ModelRun
from stickslip.report.report_figures import chain_fraction_figure
from stickslip.sweeps import build_spec, load_sweep, run_sweep

#: Fig 6 of the paper: simulated stick times (V0 in µm/s, ts in s).
PAPER_STICK_TIMES = ((50, 18.3), (100, 9.3))


@pytest.fixture(scope="module")
def params():
    return load_parameters("gelatin-glass")


@pytest.fixture(scope="module")
def simulations(params):
    return {v: simulate(params, v * 1e-6, DURATIONS[v], start_stress=0.0 if v == 350 else None) for v in (50, 100, 350)}


def test_fig5_each_panel_legend_names_what_that_panel_draws(simulations):
    """Fig 5c's steady part is green in panel (c) only: panel (c) names it, panel (a)'s legend does not (issue 32);
    every phase drawn anywhere is named by some legend, each once."""
    fig = figure_cycles([simulations[v] for v in (50, 100, 350)])
    named: list[str] = []
    for ax in fig.axes:
        drawn = {line.get_label() for line in ax.get_lines() if not line.get_label().startswith("_")}
        legend = ax.get_legend()
        shown = [t.get_text() for t in legend.get_texts()] if legend is not None else []
        assert set(shown) <= drawn, f"{ax.get_title()}: legend names {set(shown) - drawn}, not drawn there"
        assert drawn <= set(shown) | set(named)  # what an earlier legend did not name, this one does
        named += shown
    assert "steady" in named and "steady" not in [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert len(named) == len(set(named))


def test_fig3_6_paper_triangles_take_the_colour_of_their_curve(params, simulations):
    run = ModelRun(params=params, simulations=dict(simulations))
    ax = chain_fraction_figure(run).figure.axes[0]
    curves = {line.get_label(): line for line in ax.get_lines() if line.get_label().startswith("V0 = ")}
    triangles = [line for line in ax.get_lines() if line.get_marker() == "v"]
    assert len(triangles) == len(PAPER_STICK_TIMES) == len(curves) == 2
    for triangle, (velocity, stick_time) in zip(triangles, PAPER_STICK_TIMES, strict=True):
        curve = curves[f"V0 = {velocity} µm/s"]
        assert to_rgba(triangle.get_color()) == to_rgba(curve.get_color())
        assert triangle.get_xdata()[0] == stick_time and f"V0 = {velocity} µm/s" in triangle.get_label()
    assert to_rgba(triangles[0].get_color()) != to_rgba(triangles[1].get_color())


@pytest.fixture(scope="module")
def narrow_log_sweep(tmp_path_factory):
    """A log-spaced stiffness range of less than the 30x that would make a log axis on its own."""
    spec = build_spec(
        ["pulling_velocity=20 um/s..2 mm/s:3:log", "block.stiffness=200 kPa/m..1.6 MPa/m:3:log"], duration="20 s"
    )
    folder = tmp_path_factory.mktemp("look") / "sweep"
    run_sweep(spec, folder, workers=0)
    frame, spec = load_sweep(folder)
    return frame, spec


def test_phase_diagram_axes_name_the_quantity_and_follow_log_spacing(narrow_log_sweep):
    frame, spec = narrow_log_sweep
    ax = plot_phase_diagram(frame, spec, x="pulling_velocity", y="block.stiffness", color="regime")
    assert ax.get_xlabel() == "pulling velocity V0 (µm/s)"
    assert ax.get_ylabel() == "block stiffness Gd/h (Pa/m)"
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"  # the sweep spaced both geometrically
    ax.figure.canvas.draw()
    assert ax.yaxis.get_offset_text().get_text() == ""  # no "1e6" multiplier hiding the scale
    # the cells meet halfway between grid values on the log axis (geometric means)
    mesh = ax.collections[0]
    edges = np.unique(np.round(mesh.get_coordinates()[:, 0, 1], 6))
    grid = np.geomspace(200e3, 1.6e6, 3)
    assert edges[1] == pytest.approx(np.sqrt(grid[0] * grid[1]), rel=1e-8)


@pytest.mark.parametrize(
    ("key", "dimension", "label"),
    [
        ("bonds.bond_time", "time", "thermal make-break time constant τ (s)"),
        ("aging.aging_velocity", "velocity", "characteristic aging velocity Va (µm/s)"),
        ("block.height", "length", "height of the block h (m)"),
        ("bonds.breakage_weight", "dimensionless", "breakage weight exp(-W0/kT) of a new bond u0"),
    ],
)
def test_parameter_axes_use_the_parameters_own_names(key, dimension, label):
    from stickslip.plots.sweeps import _label

    assert _label(key, dimension) == label
    assert not re.search(r"\b[a-z]+_[a-z]+\b", label)  # no raw key left in a label
