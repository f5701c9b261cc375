"""Round 29 (tester P): the report's extension figures say what their data are and in which units, and the phase
diagram exports what it draws.

* The saturating-aging figure is fitted to the shipped *synthetic* steady curve (the model plus 2 % noise): its
  caption, its legend and so its CSV say so; the paper's Vc is 125 µm/s (Section 3), beside the 124.1 µm/s its
  parameters give by Eq 9 (the caption said "paper: 124 µm/s").
* The rate-and-state reading prints a and b in units of σc (the fitted friction is σ/σc), and in pascals.
* The phase diagram's regime cells and its dotted line at the paper's block are exported as CSV, as every drawn
  curve is (only the Vc line was).

The section functions are called directly (no report is built): about 4 s of CPU.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd
import pytest

from stickslip.quasistatic.critical import critical_point
from stickslip.report.computations import ModelRun

#: The paper's Section 3: "The critical velocity is V_c = 125 µm.s^-1 and the corresponding critical stress 259 Pa".
PAPER_VC_UM_S = 125


@pytest.fixture(scope="module")
def run(params) -> ModelRun:
    return ModelRun(params, critical=critical_point(params))


def test_saturating_figure_calls_its_data_synthetic_and_quotes_the_papers_vc(run: ModelRun, params) -> None:
    from stickslip.fitting.datasets import synthetic_steady_path
    from stickslip.report.aging_section import saturating_figure

    figure = saturating_figure(run)
    caption = figure.caption
    fitted_to = caption.split("Fitted to", 1)[1].split("(95 % intervals)", 1)[0]
    assert "synthetic" in fitted_to and "not a measurement" in fitted_to, fitted_to
    # the points with error bars are the shipped synthetic file, read here independently: their curve says so
    data = pd.read_csv(synthetic_steady_path(), comment="#")
    velocity_um_s, stress = data.iloc[:, 0].to_numpy(float), data.iloc[:, 1].to_numpy(float)
    points = [
        c
        for c in figure.curves()
        if c.x.size == velocity_um_s.size and np.allclose(c.x, velocity_um_s, rtol=1e-9) and np.allclose(c.y, stress)
    ]
    assert len(points) == 1
    assert "synthetic" in points[0].label and "synthetic" in points[0].name, (points[0].label, points[0].name)
    assert points[0].x_name.endswith("[µm/s]") and points[0].y_name.endswith("[Pa]")
    # Vc: the paper's stated value, and the one its parameters give (Eq 9, computed here)
    vc = critical_point(params).velocity * 1e6
    assert f"paper: {PAPER_VC_UM_S} µm/s" in caption and f"give {vc:.1f} µm/s" in caption, caption
    assert "paper: 124" not in caption
    assert "702–720 µm/s" in caption  # Table 1's range with its unit


def test_rsf_reading_caption_gives_a_and_b_their_unit(run: ModelRun, params) -> None:
    from stickslip.quasistatic.steady import steady_state
    from stickslip.report.rsf_reading_section import rsf_reading_figure

    caption = rsf_reading_figure(run).caption
    values = list(re.finditer(r"\b([ab]) = ([0-9.]+)(?: \[[0-9.]+, [0-9.]+\])?", caption))
    assert len(values) >= 8  # a and b of each step, in σc and in pascals
    for found in values:
        after = caption[found.end() : found.end() + 4]
        assert after.startswith((" σc", " Pa")), (found.group(0), after)
    assert "0.54 σc" in caption and "2.49 σc" in caption  # the other steps' a, quoted from docs/extensions.md
    # the unit is right: a - b in pascals is the steady curve's rise per e-fold of V between the two velocities
    # (docs/extensions.md section 3: to 1.5 % on every single step), from the steady solver, not from the fit
    rise = float(steady_state(params, 1000e-6).stress - steady_state(params, 100e-6).stress) / math.log(10.0)
    in_pascals = [float(x) for x in re.findall(r"a − b = ([0-9.]+) Pa", caption)]
    assert len(in_pascals) == 2
    for value in in_pascals:
        assert value == pytest.approx(rise, rel=0.02)


def test_phase_diagram_exports_every_cell_and_the_paper_block_line(run: ModelRun, params) -> None:
    from stickslip.quasistatic.stick import stick_phase, stuck_threshold
    from stickslip.report.sweep_section import phase_diagram_figure

    figure = phase_diagram_figure(run)
    curves = {c.name: c for c in figure.curves()}
    stiffness = params.block.shear_modulus / params.block.height  # G/h of the paper's block, 400 kPa/m
    # the grid the caption describes: V0 5 µm/s ... 5 mm/s (15, log) by G/h x 0.1 ... x 10 (9, log)
    grid = {(v, k) for v in np.geomspace(5.0, 5000.0, 15) for k in np.geomspace(0.1, 10.0, 9) * stiffness}
    regimes = ("stick-slip", "steady", "stuck", "undetermined")
    cells: dict[tuple[float, float], str] = {}
    for regime in regimes:
        curve = curves.get(f"phase_diagram_{regime}")
        if curve is None:
            continue
        assert curve.x_name == "pulling velocity V0 [µm/s]" and curve.y_name == "block stiffness Gd/h [Pa/m]"
        assert curve.to_csv().splitlines()[0] == "pulling velocity V0 [µm/s],block stiffness Gd/h [Pa/m]"
        for x, y in zip(curve.x, curve.y, strict=True):
            point = min(grid, key=lambda g: abs(math.log(g[0] / x)) + abs(math.log(g[1] / y)))
            assert x == pytest.approx(point[0], rel=1e-9) and y == pytest.approx(point[1], rel=1e-9)
            assert point not in cells, point
            cells[point] = regime
    assert set(cells) == grid  # every one of the 135 cells, once
    # at the paper's block each cell's regime is the theory's (independent of the sweep's runs): stuck below V*
    # (Eq 15 from σc), steady above Vc (Eq 9), stick-slip between where the stick's σs is below the curve's top
    critical = critical_point(params)
    floor = stuck_threshold(params).velocity * 1e6
    row = sorted((v, r) for (v, k), r in cells.items() if k == pytest.approx(stiffness, rel=1e-9))
    assert len(row) == 15
    for v, regime in row:
        if v < floor:
            assert regime == "stuck", (v, regime)
        elif v > critical.velocity * 1e6:
            assert regime == "steady", (v, regime)
        elif stick_phase(params, v * 1e-6).peak_stress < critical.turnover_stress:
            assert regime == "stick-slip", (v, regime)
    assert [r for _, r in row].count("stick-slip") >= 4
    # the dotted line at the paper's block, across the whole plot
    line = next(c for n, c in curves.items() if "block" in n)
    assert np.allclose(line.y, stiffness, rtol=1e-12)
    assert line.x.min() < 5.0 and line.x.max() > 5000.0
    assert line.y_name == "block stiffness Gd/h [Pa/m]" and line.x_name == "pulling velocity V0 [µm/s]"


def test_a_mesh_of_named_colours_is_read_back_cell_by_cell() -> None:
    """export.mesh_cells: each cell's centre in the axis's scale, named by the legend entry of its colour; a
    masked cell is left out, and a mesh on a colour scale (no legend names its colours) is not a curve."""
    from matplotlib.colors import ListedColormap
    from matplotlib.figure import Figure

    from stickslip.plots.export import extract_curves

    fig = Figure()
    ax = fig.subplots()
    xs = np.array([1.0, 10.0, 100.0])  # log axis: edges at geometric midpoints
    ys = np.array([0.0, 2.0])  # linear axis
    x_edges = np.array([10**-0.5, 10**0.5, 10**1.5, 10**2.5])
    y_edges = np.array([-1.0, 1.0, 3.0])
    codes = np.ma.masked_invalid(np.array([[0.0, 1.0, 0.0], [1.0, np.nan, 0.0]]))
    ax.pcolormesh(x_edges, y_edges, codes, cmap=ListedColormap(["#c0392b", "#1f4e9c"]), vmin=-0.5, vmax=1.5)
    ax.scatter([], [], marker="s", color="#c0392b", label="red cells")
    ax.scatter([], [], marker="s", color="#1f4e9c", label="blue cells")
    ax.set_xscale("log")
    ax.set_xlabel("velocity (µm/s)")
    ax.set_ylabel("height (mm)")
    other = fig.add_axes((0.7, 0.7, 0.2, 0.2))
    other.pcolormesh(x_edges, y_edges, codes, cmap="viridis")  # a colour scale: not named cells
    curves = {c.name: c for c in extract_curves(fig, "f")}
    red, blue = curves["f_a_red-cells"], curves["f_a_blue-cells"]
    # codes by row (y = 0, then y = 2): red blue red / blue (masked) red; written sorted by x, then y
    assert np.allclose(red.x, [1.0, 100.0, 100.0], rtol=1e-12) and np.allclose(red.y, [0.0, 0.0, 2.0])
    assert np.allclose(blue.x, [1.0, 10.0], rtol=1e-12) and np.allclose(blue.y, [2.0, 0.0])
    assert red.to_csv().splitlines()[0] == "velocity [µm/s],height [mm]"
    assert set(curves) == {"f_a_red-cells", "f_a_blue-cells"}
    assert xs.size * ys.size == red.x.size + blue.x.size + 1  # the masked cell is the one not written
