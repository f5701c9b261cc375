"""The CLI draws nothing itself: its figures are built by stickslip.plots (issue 20, item 6)."""

from __future__ import annotations

import ast
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

CLI = Path(__file__).resolve().parents[1] / "src" / "stickslip" / "cli"


@pytest.mark.parametrize("module", ["analyze_cmd.py", "compare_cmd.py", "compare_models.py"])
def test_cli_module_builds_no_figure(module: str) -> None:
    """No matplotlib import and no Axes call in the command modules: they call stickslip.plots and save."""
    tree = ast.parse((CLI / module).read_text(encoding="utf-8"))
    imported = [node.module or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)] + [
        alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names
    ]
    assert not [name for name in imported if name.startswith("matplotlib")], imported
    drawing = {"plot", "set_xlabel", "set_ylabel", "set_title", "legend", "subplots", "add_subplot", "suptitle"}
    calls = {
        node.func.attr for node in ast.walk(tree) if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
    }
    assert not calls & drawing, sorted(calls & drawing)


def test_bond_and_rsf_figure_draws_both_models_over_sigma_c() -> None:
    from matplotlib.figure import Figure

    from stickslip.plots.compare import figure_bond_and_rsf

    t = np.linspace(0.0, 4.0, 9)
    sigma_c = 250.0
    bond = SimpleNamespace(time=t, stress=sigma_c * (1.0 + 0.1 * t), source="bond model")
    run = SimpleNamespace(time=t, friction=1.0 + 0.05 * t - 0.3 * (t > 3.5), regime=SimpleNamespace(name="stick-slip"))
    panels = {"velocity step": (bond, run, None), "slide-hold-slide": (bond, None, "negative friction in the hold")}
    pair = {"bond": bond, "rsf": run, "problem": None}
    rsf = SimpleNamespace(sigma_c=sigma_c, params=SimpleNamespace(a=0.01, b=0.015, dc=2e-5))
    fig = figure_bond_and_rsf(panels, pair, rsf, "fitted to the bond model's step")
    assert isinstance(fig, Figure)
    step, shs, pair_ax = fig.axes
    assert [ax.get_title() for ax in fig.axes] == [
        "velocity step",
        "slide-hold-slide",
        "stick-slip at the same V0, stiffness, σc",
    ]
    bond_line, rsf_line = step.get_lines()
    np.testing.assert_allclose(bond_line.get_ydata(), 1.0 + 0.1 * t)  # stress / sigma_c
    np.testing.assert_array_equal(rsf_line.get_ydata(), run.friction)
    assert rsf_line.get_label() == "rate-and-state (fitted to the bond model's step)"
    assert shs.get_yscale() == "log" and len(shs.get_lines()) == 1  # no RSF run: only the bond model
    assert any("negative friction in the hold" in text.get_text() for text in shs.texts)
    assert pair_ax.get_lines()[1].get_label() == "RSF: stick-slip"
    assert "a = 0.01, b = 0.015, Dc = 20 µm" in fig.get_suptitle()


def test_analysis_figure_is_the_analysis_plot(tmp_path: Path) -> None:
    from matplotlib.figure import Figure

    from stickslip.analysis import analyze_trace, read_trace
    from stickslip.plots.traces import figure_analysis

    time = np.linspace(0.0, 60.0, 1201)
    stress = 300.0 + 50.0 * ((time % 10.0) / 10.0)  # a sawtooth: a linear stick, then a drop, every 10 s
    path = tmp_path / "saw.csv"
    rows = zip(time.tolist(), stress.tolist(), strict=True)
    path.write_text("time [s],stress [Pa]\n" + "".join(f"{t!r},{s!r}\n" for t, s in rows))
    analysis = analyze_trace(read_trace(path), None, 50e-6)
    fig = figure_analysis(analysis)
    assert isinstance(fig, Figure) and len(fig.axes) == 1
    (ax,) = fig.axes
    record = ax.get_lines()[0]
    assert record.get_label() == "record"
    np.testing.assert_array_equal(record.get_ydata(), stress)
    assert ax.get_title().startswith(f"{analysis.source}: ")
