"""A sweep's phase diagram shows every point on axes that fit them (a tester's findings, 2026-11-30): a Latin
hypercube over log ranges was drawn with its points outside frozen axes; a linear grid of a positive quantity
reached negative values; a sweep of several keys with all but x pinned by --at is a sweep of one key."""

from __future__ import annotations

import numpy as np
import pytest

from cli_helpers import run_main


def _sweep(tmp_path, capsys, *args: str):  # type: ignore[no-untyped-def]
    out = tmp_path / "sweep"
    code, _, err = run_main(capsys, "sweep", *args, "--duration", "20 s", "--workers", "0", "--quiet", "-o", str(out))
    assert code == 0, err
    from stickslip.sweeps import load_sweep

    return load_sweep(out)


def test_a_latin_hypercube_over_log_ranges_shows_its_points(tmp_path, capsys):
    import matplotlib

    matplotlib.use("Agg")
    from stickslip.plots.sweeps import plot_phase_diagram

    frame, spec = _sweep(tmp_path, capsys, "--vary", "pulling_velocity=20 um/s..500 um/s:log", "--vary",
                         "block.stiffness=40 kPa/m..4 MPa/m:log", "--samples", "12", "--seed", "3")  # fmt: skip
    for color in ("regime", "mean_stress"):
        ax = plot_phase_diagram(frame, spec, "pulling_velocity", "block.stiffness", color=color)
        assert ax.get_xscale() == ax.get_yscale() == "log"
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        xs, ys = frame["pulling_velocity"].to_numpy() * 1e6, frame["block.stiffness"].to_numpy()  # µm/s, Pa/m
        assert 0 < x0 < xs.min() and xs.max() < x1 < 2 * xs.max(), (x0, x1)  # the lower limit was negative
        assert 0 < y0 < ys.min() and ys.max() < y1 < 2 * ys.max(), (y0, y1)
        ax.figure.clf()


def test_a_positive_grid_on_a_linear_axis_stays_positive(tmp_path, capsys):
    import matplotlib

    matplotlib.use("Agg")
    from stickslip.plots.sweeps import plot_phase_diagram

    frame, spec = _sweep(tmp_path, capsys, "--vary", "pulling_velocity=50 um/s,100 um/s,200 um/s", "--vary",
                         "block.stiffness=400 kPa/m,4 MPa/m")  # fmt: skip
    ax = plot_phase_diagram(frame, spec, "pulling_velocity", "block.stiffness")
    assert ax.get_yscale() == "linear" and ax.get_ylim()[0] >= 0.0  # the first cell reached -1.4 MPa/m
    assert ax.get_xlim()[0] >= 0.0


def test_pinning_every_other_key_makes_a_one_key_plot(tmp_path, capsys):
    _sweep(tmp_path, capsys, "--vary", "pulling_velocity=50 um/s,100 um/s", "--vary", "block.height=5 mm,10 mm",
           "--vary", "bonds.bond_time=200 us,224 us")  # fmt: skip
    out, png = str(tmp_path / "sweep"), str(tmp_path / "p.png")
    code, _, err = run_main(capsys, "sweep", "plot", out, "--x", "pulling_velocity", "--at", "bonds.bond_time=224 us",
                            "--at", "block.height=1 cm", "-o", png)  # fmt: skip
    assert code == 0, err
    code, _, err = run_main(capsys, "sweep", "plot", out, "--x", "pulling_velocity", "--at", "block.height=1 cm",
                            "-o", png)  # fmt: skip
    assert code == 2 and "give --y KEY, or pin bonds.bond_time with --at KEY=VALUE" in err
    code, _, err = run_main(capsys, "sweep", "plot", out, "--x", "pulling_velocity", "--y", "block.height",
                            "--color", "status", "-o", png)  # fmt: skip
    assert code == 2 and "--color status: not a result column to colour by" in err


@pytest.mark.parametrize("log", [False, True])
def test_cell_edges_hold_the_grid_values_between_them(log):
    from stickslip.plots.sweeps import _edges

    values = np.array([4e5, 4e6]) if not log else np.array([20.0, 60.0, 500.0])
    edges = _edges(values, log)
    assert np.all(edges[:-1] < values) and np.all(values < edges[1:]) and edges[0] >= 0.0
