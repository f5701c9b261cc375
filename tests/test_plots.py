"""stickslip.plots: one package for every figure, results drawing through it lazily, and the 1-D sweep plot."""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.axes import Axes
from matplotlib.colors import to_hex

import stickslip
import stickslip.plots
from cli_helpers import run_main
from stickslip.errors import ParameterError
from stickslip.plots.sweeps import REGIME_COLORS, figure_sweep_1d, plot_phase_diagram
from stickslip.sweeps import build_spec, load_sweep, run_sweep

SOURCE = Path(stickslip.__file__).resolve().parent
PLOT_MODULES = [f"stickslip.plots.{m.name}" for m in pkgutil.iter_modules(stickslip.plots.__path__)]

# rate-and-state over k alone, at one pulling velocity (the README's example, three points)
RSF_SET = ["--set", "a=0.005", "--set", "b=0.01", "--set", "dc=10 um", "--set", "eta=0.5 s/m"]
RSF_V0 = 3e-6


def rsf_kc(velocity: float) -> float:
    """The Hopf point of the aging law with radiation damping: kc = (b - a - eta V)/Dc (docs/rsf.md), 1/m."""
    return (0.01 - 0.005 - 0.5 * velocity) / 10e-6


# --------------------------------------------------------------------------- the package
def test_the_plots_package_imports_nothing_eagerly() -> None:
    tree = ast.parse((SOURCE / "plots" / "__init__.py").read_text(encoding="utf-8"))
    assert all(isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) for node in tree.body)


@pytest.mark.parametrize("module", PLOT_MODULES)
def test_plot_functions_take_ax_none_and_return_axes_figure_functions_a_figure(module: str) -> None:
    for name, function in inspect.getmembers(importlib.import_module(module), inspect.isfunction):
        if function.__module__ != module or name.startswith("_"):
            continue
        signature = inspect.signature(function)
        if name.startswith("plot_") or name.endswith("_plot"):
            assert "ax" in signature.parameters and signature.parameters["ax"].default is None, name
            assert signature.return_annotation == "Axes", name
        elif name.startswith("figure_") or name.endswith("_figure"):
            assert signature.return_annotation == "Figure", name


def _calls_show_or_uses_pyplot(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and "pyplot" in node.module:
            found.append(f"from {node.module} import")
        elif (
            isinstance(node, ast.ImportFrom)
            and node.module == "matplotlib"
            and any(a.name == "pyplot" for a in node.names)
        ):
            found.append("from matplotlib import pyplot")
        elif isinstance(node, ast.Import) and any("pyplot" in a.name for a in node.names):
            found.append("import matplotlib.pyplot")
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "show":
            found.append(f"{ast.unparse(node.func)}()")
    return found


def test_library_code_never_shows_a_window_nor_uses_pyplot() -> None:
    offenders = {
        str(path.relative_to(SOURCE)): found
        for path in sorted(SOURCE.rglob("*.py"))
        if (found := _calls_show_or_uses_pyplot(path))
    }
    assert not offenders


def test_results_load_neither_the_plots_nor_matplotlib_until_they_draw() -> None:
    code = (
        "import sys\n"
        "import stickslip.quasistatic.cycle, stickslip.quasistatic.steady\n"
        "import stickslip.quasistatic.stick, stickslip.quasistatic.slip\n"
        "import stickslip.transient.result, stickslip.rsf.results, stickslip.rsf.fit, stickslip.rsf.data\n"
        "import stickslip.analysis.cycles, stickslip.analysis.compare, stickslip.protocols, stickslip.sweeps\n"
        "import stickslip.fitting.steady_fit, stickslip.fitting.stick_fit, stickslip.fitting.bayes\n"
        "print(sorted(m for m in sys.modules if m.startswith(('stickslip.plots', 'matplotlib'))))\n"
    )
    env_path = str(SOURCE.parent)
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, env={"PYTHONPATH": env_path}
    )
    assert out.stdout.strip() == "[]", out.stdout


def test_a_result_draws_through_the_plots_on_a_given_axes() -> None:
    from matplotlib.figure import Figure

    ax = Figure().add_subplot()
    drawn = stickslip.steady_state(stickslip.load_parameters(), [1e-4, 1e-3]).plot(ax=ax)
    assert drawn is ax and ax.get_xscale() == "log" and ax.get_ylabel() == "friction stress σ (Pa)"
    np.testing.assert_allclose(ax.get_lines()[0].get_xdata(), [100.0, 1000.0])  # drawn in µm/s


# --------------------------------------------------------------------------- 1-D sweeps
def test_sweep_plot_of_one_key_draws_results_against_it_and_kc(capsys, tmp_path: Path) -> None:
    """Rate-and-state over k alone at V0 = 3 µm/s (the README's example, k/kc = 0.5, 1, 2)."""
    folder = tmp_path / "rsfsweep"
    args = ["sweep", "--model", "rsf", "--vary", "k=250 1/m,500 1/m,1000 1/m", "--v0", "3 um/s", *RSF_SET]
    status, _, err = run_main(capsys, *args, "--duration", "400 s", "--workers", "0", "-o", str(folder))
    assert status == 0, err
    image = tmp_path / "k.png"
    status, out, err = run_main(capsys, "sweep", "plot", str(folder), "--x", "k", "-o", str(image))
    assert status == 0, err
    assert image.read_bytes()[:4] == b"\x89PNG" and str(image) in out

    frame, spec = load_sweep(folder)
    fig = figure_sweep_1d(frame, spec, "k")
    axes = fig.axes
    assert [ax.get_ylabel() for ax in axes] == ["period (s)", "peak friction μ", "mean friction μ"]
    assert axes[-1].get_xlabel() == "spring stiffness k (1/m)" and axes[-1].get_xscale() == "linear"
    for ax in axes:  # kc of the closed form, on every panel
        lines = [line for line in ax.get_lines() if line.get_linestyle() == "--"]
        assert len(lines) == 1
        np.testing.assert_allclose(lines[0].get_xdata(), rsf_kc(RSF_V0), rtol=1e-9)
    assert "k = kc (rsf.critical_stiffness)" in [t.get_text() for t in axes[0].get_legend().get_texts()]


def _points_by_colour(ax: Axes) -> dict[str, np.ndarray]:
    """x values of the markers drawn, by their colour."""
    out: dict[str, np.ndarray] = {}
    for collection in ax.collections:
        offsets = np.asarray(collection.get_offsets())
        if offsets.size:
            out[to_hex(collection.get_facecolor()[0])] = offsets[:, 0]
    return out


def _frame(spec, rows: list[dict]) -> pd.DataFrame:  # type: ignore[no-untyped-def]
    base = {"status": "ok", "message": "", "wall_time": 0.1}
    return pd.DataFrame([{"point": k, **base, **row} for k, row in enumerate(rows)])


QS_ROWS = [  # V0 (m/s), regime, period (s), peak stress (Pa), mean stress (Pa)
    (20e-6, "stuck", np.nan, np.nan, 300.0),
    (50e-6, "stick-slip", 30.0, 700.0, 500.0),
    (100e-6, "stick-slip", 10.0, 650.0, 450.0),
    (1000e-6, "steady", np.nan, 600.0, 410.0),
]


@pytest.fixture(scope="module")
def qs_one_key():  # type: ignore[no-untyped-def]
    params = stickslip.load_parameters()
    spec = build_spec(["pulling_velocity=20 um/s,50 um/s,100 um/s,1 mm/s"], params=params, duration="20 s")
    vc = stickslip.critical_point(params).velocity
    rows = [
        {"pulling_velocity": v, "regime": r, "period": p, "peak_stress": s, "mean_stress": m, "critical_velocity": vc}
        for v, r, p, s, m in QS_ROWS
    ]
    return spec, _frame(spec, rows), vc


def test_one_key_plot_colours_each_point_by_regime_and_leaves_blanks_out(qs_one_key) -> None:
    spec, frame, vc = qs_one_key
    fig = figure_sweep_1d(frame, spec, "pulling_velocity")
    period, _, mean = fig.axes
    assert [ax.get_ylabel() for ax in fig.axes] == ["period (s)", "peak stress σs (Pa)", "mean stress (Pa)"]
    assert period.get_title() == "gelatin-glass: results against pulling velocity V0 (4 points)"
    assert mean.get_xlabel() == "pulling velocity V0 (µm/s)" and mean.get_xscale() == "log"  # 50x: decades
    red, blue, grey = (REGIME_COLORS[r] for r in ("stick-slip", "steady", "stuck"))
    assert {k: list(v) for k, v in _points_by_colour(period).items()} == {red: [50.0, 100.0]}
    assert {k: list(v) for k, v in _points_by_colour(mean).items()} == {red: [50.0, 100.0], blue: [1000.0],
                                                                        grey: [20.0]}  # fmt: skip
    boundary = [line for line in period.get_lines() if line.get_label() == "V0 = Vc (Eq 9)"]
    np.testing.assert_allclose(boundary[0].get_xdata(), vc * 1e6, rtol=1e-12)  # the model's own Vc, in µm/s


def test_one_key_plot_marks_failed_points_and_takes_chosen_columns(qs_one_key) -> None:
    spec, frame, _ = qs_one_key
    frame = frame.copy()
    frame.loc[0, ["status", "message"]] = ["error", "boom"]
    ax = plot_phase_diagram(frame, spec, "pulling_velocity", color="mean_stress,period")
    fig = ax.figure
    assert [a.get_ylabel() for a in fig.axes] == ["mean stress (Pa)", "period (s)"]
    crosses = [line for line in fig.axes[-1].get_lines() if line.get_label() == "failed (1)"]
    assert len(crosses) == 1 and list(crosses[0].get_xdata()) == [20.0]


def test_one_key_plot_refusals_are_one_line(qs_one_key) -> None:
    spec, frame, _ = qs_one_key
    with pytest.raises(ParameterError, match=r"--color stick_time: not a numeric result of this sweep"):
        figure_sweep_1d(frame, spec, "pulling_velocity", ["stick_time"])
    with pytest.raises(ParameterError, match=r"--x block.height: not the varied key of this sweep"):
        figure_sweep_1d(frame, spec, "block.height")
    two = build_spec(["pulling_velocity=20 um/s,50 um/s", "block.height=1 cm,2 cm"], duration="20 s")
    with pytest.raises(ParameterError, match=r"--y: this sweep varies pulling_velocity, block.height; give --y"):
        plot_phase_diagram(frame, two, "pulling_velocity")


def test_sweep_plot_without_y_on_a_two_key_sweep_says_give_y(tmp_path: Path, capsys) -> None:
    spec = build_spec(["pulling_velocity=1 mm/s,2 mm/s", "block.height=1 cm,2 cm"], duration="2 s")
    run_sweep(spec, tmp_path / "two", workers=0)
    status, _, err = run_main(capsys, "sweep", "plot", str(tmp_path / "two"), "-o", str(tmp_path / "x.png"))
    assert status == 2 and "give --y KEY" in err and err.count("\n") == 1


def test_one_key_plot_of_a_sweep_whose_every_point_failed_draws_the_crosses(qs_one_key) -> None:
    spec, frame, _ = qs_one_key
    failed = frame.assign(status="error", message="boom", period=np.nan, peak_stress=np.nan, mean_stress=np.nan)
    fig = figure_sweep_1d(failed, spec, "pulling_velocity")
    assert [line.get_label() for line in fig.axes[-1].get_lines()] == ["_trend", "failed (4)"]
    assert not any(ax.collections for ax in fig.axes)  # no point in any regime colour, and no boundary line
    assert not [line for ax in fig.axes for line in ax.get_lines() if line.get_linestyle() == "--"]
