"""The curves' CSV files keep the package's header rule, ``name [unit]`` (``[1]`` for a pure number; a text column
bare): a panel whose x label sits under another panel, an axis of named categories and a dimensionless axis
included (the report's Fig 5a-c panels were headed ``x``, the sensitivity panel's categories written as 0.0 … 5.0,
N_c/N_c0 and σ/σc without ``[1]``)."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from stickslip.columns import split_header
from stickslip.plots.export import extract_curves

pytest.importorskip("matplotlib")


def _check_csv(text: str, where: str) -> pd.DataFrame:
    """Every header cell is ``name [unit]`` with a real name; a cell without a unit heads a column of text."""
    table = pd.read_csv(io.StringIO(text))
    for cell in table.columns:
        name, unit = split_header(cell)
        assert name and name.strip().lower() not in {"x", "y"}, f"{where}: header cell {cell!r} names no quantity"
        if unit is None:
            numeric = pd.api.types.is_numeric_dtype(table[cell])
            assert not numeric, f"{where}: numeric column {cell!r} without a [unit]"
            assert not any(_is_number(v) for v in table[cell]), f"{where}: {cell!r} holds numbers as text"
        else:
            assert unit, f"{where}: empty unit in {cell!r}"
            assert pd.api.types.is_numeric_dtype(table[cell]), f"{where}: text under the unit of {cell!r}"
    return table


def _is_number(value: object) -> bool:
    try:
        float(str(value))
    except ValueError:
        return False
    return True


def _headers(figure) -> list[str]:  # type: ignore[no-untyped-def]
    return [c.to_csv().splitlines()[0] for c in extract_curves(figure, "f")]


def test_a_stack_named_under_its_last_panel_names_every_panel_x() -> None:
    """Fig 5a-c: three panels, not sharing x, the x label on the bottom one only."""
    from matplotlib.figure import Figure

    fig = Figure()
    axes = fig.subplots(3, 1)
    for ax in axes:
        ax.plot([0.0, 75.0], [1.0, 2.0])
        ax.set_ylabel("friction stress σ (Pa)")
    axes[-1].set_xlabel("time t (s)")
    assert _headers(fig) == ["time t [s],friction stress σ [Pa]"] * 3
    for curve in extract_curves(fig, "f"):
        _check_csv(curve.to_csv(), curve.name)


def test_shared_x_and_the_figures_supxlabel_name_x() -> None:
    from matplotlib.figure import Figure

    shared = Figure()
    top, bottom = shared.subplots(2, 1, sharex=True)
    top.plot([1.0, 2.0], [3.0, 4.0])
    bottom.plot([1.0, 2.0], [5.0, 6.0])
    top.set_ylabel("σ (Pa)")
    bottom.set_ylabel("V (µm/s)")
    bottom.set_xlabel("slip (µm)")
    assert _headers(shared) == ["slip [µm],σ [Pa]", "slip [µm],V [µm/s]"]

    sup = Figure()
    left, right = sup.subplots(1, 2)
    for ax in (left, right):
        ax.plot([1.0, 2.0], [3.0, 4.0])
        ax.set_ylabel("σ (Pa)")
    sup.supxlabel("time (s)")
    assert _headers(sup) == ["time [s],σ [Pa]"] * 2


def test_named_categories_are_written_as_names() -> None:
    """The sensitivity panel: one point set per category at x = k, the ticks named."""
    from matplotlib.figure import Figure

    fig = Figure()
    ax = fig.add_subplot()
    names = ["Vc", "$\\sigma_c$", "stick from rest"]
    for k, name in enumerate(names):
        ax.plot(np.full(2, k), [1.0 + k, -1.0], "o", label=name)
    ax.set_xticks(range(len(names)), names, rotation=30)
    ax.set_xlabel("quasi-static prediction")
    ax.set_ylabel("change from the best fit (%)")
    curves = extract_curves(fig, "f")
    assert curves[1].to_csv() == "quasi-static prediction,change from the best fit [%]\nσ_c,2.0\nσ_c,-1.0\n"
    for curve in curves:
        table = _check_csv(curve.to_csv(), curve.name)
        assert list(table.iloc[:, 0]) == [curve.label] * 2


def test_numbered_ticks_stay_numbers_and_units_need_a_space() -> None:
    """Ticks set without names (or named with numbers) are an axis of numbers; "ln(V/V₀)" holds no unit."""
    from matplotlib.figure import Figure

    fig = Figure()
    left, right = fig.subplots(1, 2)
    left.plot([0.0, 1.0], [2.0, 3.0])
    left.set_xticks([0.0, 1.0], ["0", "1"])
    left.set_xlabel("ln(V/V₀)")
    left.set_ylabel("attached chains $N_c/N_{c0}$")
    right.plot([0.0, 1.0], [2.0, 3.0])
    right.set_xlabel("time [s]")
    right.set_ylabel("friction σ/σc")
    assert _headers(fig) == ["ln(V/V₀) [1],attached chains N_c/N_c0 [1]", "time [s],friction σ/σc [1]"]


def test_an_unlabelled_axis_is_no_bare_x() -> None:
    from matplotlib.figure import Figure

    fig = Figure()
    fig.add_subplot().plot([1.0, 2.0], [3.0, 4.0])
    header = _headers(fig)[0]
    assert [split_header(cell) for cell in header.split(",")] == [
        ("unlabelled x axis", "?"),
        ("unlabelled y axis", "?"),
    ]


def test_every_csv_of_the_report_keeps_the_header_rule(tmp_path_factory: pytest.TempPathFactory) -> None:
    """The report's own files (built once per session, shared with tests/test_report.py)."""
    from test_report import built_report

    report: Path = built_report(tmp_path_factory)
    files = sorted(report.glob("*.csv"))
    assert len(files) > 40
    for path in files:
        _check_csv(path.read_text(encoding="utf-8"), path.name)
    categories = _check_csv((report / "sensitivity_aging_b_vc.csv").read_text(encoding="utf-8"), "sensitivity")
    assert list(categories.columns) == ["quasi-static prediction", "change from the best fit [%]"]
    assert set(categories.iloc[:, 0]) == {"Vc"}
    cycles = pd.read_csv(report / "fig5a-c_cycles_a_stick.csv")
    assert cycles.columns[0] == "time t [s]"
