"""Issue 31 (round 30): the report draws its figures with the heap it inherits frozen, and leaves the collector as
it found it; ``stickslip reproduce`` freezes what is left at exit; the curve CSVs keep their text."""

from __future__ import annotations

import gc
import math
import multiprocessing
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from stickslip.report import build as build_module
from stickslip.report.comparisons import Computed
from stickslip.report.errata import render_errata
from stickslip.report.figures import Curve, ReportFigure
from stickslip.report.paper import PAPER_NUMBERS

#: far fewer objects than the imported modules alone hold (numpy, matplotlib, the package: ~10^5)
MANY = 20_000


def _figure_reporting_the_freeze(run: object) -> ReportFigure:
    """A tiny figure whose caption carries how many objects the collector leaves alone while it is drawn."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 2))
    fig.add_subplot().plot([1.0, 2.0], [3.0, 4.0], label="line")
    return ReportFigure("frozen", "Fig 0", "frozen", f"{gc.get_freeze_count()}", fig)


@pytest.fixture
def tiny_report(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(build_module, "run_steps", lambda: [("nothing", lambda run: None)])
    monkeypatch.setattr(build_module, "FIGURE_BUILDERS", [("frozen", _figure_reporting_the_freeze)])
    monkeypatch.setattr(build_module, "load_errata", lambda: render_errata("## E1 an erratum\n"))
    monkeypatch.setattr(build_module, "_load_before_fork", lambda run: None)
    monkeypatch.setattr(
        build_module, "computed_values", lambda run: {n.key: Computed(n.paper, "x") for n in PAPER_NUMBERS}
    )


def _frozen_while_drawn(folder: Path, workers: int) -> int:
    report = build_module.build_report(folder, workers=workers)
    (figure,) = [f for f in report.figures if f.suffix == ".png"]
    results = (folder / "results.json").read_text(encoding="utf-8")
    assert figure.name == "frozen.png" and '"frozen"' in results
    html = report.html.read_text(encoding="utf-8")
    counts = [int(word) for word in html.split("<figcaption>")[1].split("<")[0].split() if word.isdigit()]
    assert len(counts) == 1, html.split("<figcaption>")[1][:200]
    return counts[0]


@pytest.mark.parametrize("workers", [1, 2])
def test_figures_are_drawn_with_the_inherited_heap_frozen(tiny_report: None, tmp_path: Path, workers: int) -> None:
    if workers > 1 and "fork" not in multiprocessing.get_all_start_methods():
        pytest.skip("no fork on this platform")
    assert gc.isenabled() and gc.get_freeze_count() == 0
    # before the change the collector walked the whole inherited heap in each worker (0 frozen)
    assert _frozen_while_drawn(tmp_path / "r", workers) > MANY
    assert gc.get_freeze_count() == 0  # handed back to the collector


def test_a_collector_the_caller_froze_or_disabled_is_left_as_it_was(tiny_report: None, tmp_path: Path) -> None:
    keep = [[k] for k in range(100)]  # objects of the caller's, frozen by the caller
    gc.freeze()
    try:
        before = gc.get_freeze_count()
        # neither unfrozen nor frozen further (objects the build made would add thousands); a frozen object that
        # is freed leaves the count
        assert before - 1000 <= _frozen_while_drawn(tmp_path / "a", 1) <= before
        assert before - 1000 <= gc.get_freeze_count() <= before
    finally:
        gc.unfreeze()
    gc.disable()
    try:
        assert _frozen_while_drawn(tmp_path / "b", 1) == 0
        assert not gc.isenabled() and gc.get_freeze_count() == 0
    finally:
        gc.enable()
    assert len(keep) == 100


def test_reproduce_freezes_what_is_left_before_the_interpreter_exits(tmp_path: Path) -> None:
    """The command registers gc.freeze at exit: the interpreter's last collection then walks nothing it leaves."""
    script = textwrap.dedent(
        """
        import atexit, gc, sys
        from pathlib import Path

        import stickslip.report
        from stickslip.report.build import Report

        def stub(folder, progress=None):
            folder = Path(folder)
            return Report(folder, folder / "report.html", folder / "results.json", (), (), (), 0.1)

        stickslip.report.build_report = stub
        # registered first, so it runs last: after whatever the command registered
        atexit.register(lambda: print(f"frozen at exit: {gc.get_freeze_count()}", flush=True))
        from stickslip.cli.main import cli

        cli.main(["reproduce", "--quiet", "-o", sys.argv[1]], standalone_mode=False)
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script, str(tmp_path / "r")], capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr[-2000:]
    frozen = int(done.stdout.rsplit("frozen at exit:", 1)[1])
    assert frozen > MANY  # 0 before the change


def test_curve_csv_text_is_the_package_csv_number_of_each_value() -> None:
    """Each cell is the shortest text of the value at 15 significant digits, a non-finite one empty."""
    x = np.array([1e-5, 9.999999999999999e-06, 0.1 + 0.2, -0.0, 123456789012345678.0, math.pi, np.nan])
    y = np.array([np.inf, -np.inf, 2.5, 1 / 3, -7e-300, 1.0000000000000004, 5e-324])
    curve = Curve("c", "f", "", "c", "x [m]", "y [Pa]", x, y)
    rows = curve.to_csv().splitlines()
    assert rows[0] == "x [m],y [Pa]"
    expected_x = ["1e-05", "1e-05", "0.3", "-0.0", "1.23456789012346e+17", "3.14159265358979", ""]
    expected_y = ["", "", "2.5", "0.333333333333333", "-7e-300", "1.0", "5e-324"]
    assert rows[1:] == [f"{a},{b}" for a, b in zip(expected_x, expected_y, strict=True)]
    for cell, value in zip(expected_x[:-1], x[:-1], strict=True):  # each read back within half a 15th digit
        assert float(cell) == pytest.approx(value, rel=5e-15, abs=0.0)
