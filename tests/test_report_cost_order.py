"""The report's slow figures, started first in the figure workers, are figures of the report (issue 31)."""

from __future__ import annotations

from stickslip.report import build as build_module


def test_the_slow_figures_are_named_as_the_report_names_them_and_start_first() -> None:
    descriptions = [description for description, _ in build_module.FIGURE_BUILDERS]
    assert set(build_module.SLOW_FIGURES) <= set(descriptions)  # a renamed figure would silently lose its place
    order = build_module._slowest_first()
    assert sorted(order) == list(range(len(descriptions)))
    slow = len(build_module.SLOW_FIGURES)
    assert {descriptions[i] for i in order[:slow]} == set(build_module.SLOW_FIGURES)
    rest = order[slow:]
    assert rest == sorted(rest)  # the others keep the report's order
