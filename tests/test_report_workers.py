"""The report's figures drawn in forked processes are the figures drawn in this one, in the same order."""

from __future__ import annotations

import multiprocessing
import os
from pathlib import Path

import pytest

from stickslip.report import build as build_module
from stickslip.report.figures import ReportFigure


def _figure(run: dict, k: int) -> ReportFigure:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 2))
    ax = fig.add_subplot()
    ax.plot([0, 1, 2], [k, run["scale"] * k, float(os.getpid() > 0)], label=f"curve {k}")
    return ReportFigure(f"f{k}", f"Fig {k}", f"title {k}", f"caption {k}", fig)


@pytest.fixture
def cheap_builders(monkeypatch: pytest.MonkeyPatch) -> None:
    builders = [(f"figure {k}", lambda run, k=k: _figure(run, k)) for k in range(5)]
    monkeypatch.setattr(build_module, "FIGURE_BUILDERS", builders)


def _draw(folder: Path, workers: int) -> tuple[list, list[str]]:
    folder.mkdir()
    steps: list[str] = []
    out = list(build_module._rendered_figures({"scale": 3.0}, folder, steps.append, workers))
    return out, steps


@pytest.mark.skipif("fork" not in multiprocessing.get_all_start_methods(), reason="no fork on this platform")
def test_forked_figures_equal_the_serial_ones_file_for_file(tmp_path: Path, cheap_builders: None) -> None:
    serial, serial_steps = _draw(tmp_path / "one", 1)
    forked, forked_steps = _draw(tmp_path / "two", 2)
    assert serial_steps == forked_steps == [f"figure {k}" for k in range(5)]
    for (a, a_paths, a_csvs), (b, b_paths, b_csvs) in zip(serial, forked, strict=True):
        assert (a.figure.id, a.figure.number, a.figure.caption, a.png) == (
            b.figure.id,
            b.figure.number,
            b.figure.caption,
            b.png,
        )
        assert a.figure.figure is None and b.figure.figure is None  # drawn, written and let go
        assert [c.name for c in a.curves] == [c.name for c in b.curves]
        for pa, pb in zip([*a_paths, *a_csvs], [*b_paths, *b_csvs], strict=True):
            assert pa.name == pb.name and pa.parent.name == "one" and pb.parent.name == "two"
            if pa.suffix != ".svg":  # an SVG names its own random ids
                assert pa.read_bytes() == pb.read_bytes()


def test_a_failing_figure_in_a_worker_is_the_same_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from stickslip.errors import ModelError

    def broken(run: dict) -> ReportFigure:
        raise ModelError("figure 0: no answer here")

    monkeypatch.setattr(build_module, "FIGURE_BUILDERS", [("broken", broken)])
    with pytest.raises(ModelError, match="no answer here"):
        _draw(tmp_path / "w", 2)


def test_one_worker_on_one_core_or_without_fork() -> None:
    assert build_module._figure_workers(1) == 1
    assert 1 <= build_module._figure_workers(None) <= 2
