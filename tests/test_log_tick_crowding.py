"""Log axes spanning about a decade: matplotlib labels the minor ticks at 2, 3, 4 and 6 times a power of ten, which
run together in a narrow panel ("2×10¹3×10¹4×10¹" over 20-500 µm/s).  Written through the package's save path
(:func:`stickslip.plots.export.png_and_svg_bytes`), no two tick labels touch, and the major labels stay."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.plots.export import file_tick_labels, png_and_svg_bytes
from stickslip.plots.style import apply_style

pytest.importorskip("matplotlib")

#: the least gap between two drawn tick labels, in units of their font size (the save path keeps 0.8)
GAP_EM = 0.5


def _drawn_labels(figure) -> list[list[tuple[str, object, float]]]:  # type: ignore[no-untyped-def]
    """(text, window extent, font size in pixels) of every drawn tick label, per axis, at each draw of the save
    path (the PNG's and the SVG's)."""
    seen: list[list[tuple[str, object, float]]] = []

    def measure(event) -> None:  # type: ignore[no-untyped-def]
        renderer = event.renderer
        for ax in figure.axes:
            for axis in (ax.xaxis, ax.yaxis):
                seen.append(_labels_of(axis, renderer))

    figure.canvas.mpl_connect("draw_event", measure)
    png, _ = png_and_svg_bytes(figure)
    assert png.startswith(b"\x89PNG")
    return seen


def _labels_of(axis, renderer) -> list[tuple[str, object, float]]:  # type: ignore[no-untyped-def]
    labels = []
    for tick in axis._update_ticks():  # the ticks this draw drew, labelled as it labelled them
        text = tick.label1
        if text.get_visible() and text.get_text():
            size = renderer.points_to_pixels(text.get_fontsize())
            labels.append((text.get_text(), text.get_window_extent(renderer), size))
    return labels


def _crowded(labels: list[tuple[str, object, float]]) -> list[tuple[str, str, float]]:
    """Pairs of labels closer than GAP_EM (negative: overlapping), as (left, right, gap in em)."""
    found = []
    for i, (a, box_a, size) in enumerate(labels):
        for b, box_b, _ in labels[i + 1 :]:
            gap_x = max(box_b.x0 - box_a.x1, box_a.x0 - box_b.x1)  # type: ignore[attr-defined]
            gap_y = max(box_b.y0 - box_a.y1, box_a.y0 - box_b.y1)  # type: ignore[attr-defined]
            gap = max(gap_x, gap_y) / size
            if gap < GAP_EM:
                found.append((a, b, round(gap, 2)))
    return found


@pytest.mark.parametrize("width", [3.0, 4.0])  # panels of the sweep's grid (4 inches wide)
def test_tick_labels_of_a_short_log_axis_do_not_touch(width: float) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, 3.0), layout="constrained")
    ax = apply_style(fig.add_subplot())
    velocity = np.geomspace(20.0, 500.0, 12)
    ax.plot(velocity, np.log(velocity), "o")
    ax.set_xscale("log")
    ax.set_xlim(20.0, 500.0)
    ax.set_xlabel("pulling velocity V0 (µm/s)")
    draws = _drawn_labels(fig)
    assert len(draws) == 4  # two draws (PNG, SVG) of two axes
    for labels in draws:
        assert not _crowded(labels), _crowded(labels)
    x_labels = [text for text, _, _ in draws[0]]
    assert "10²" in x_labels and "2×10¹" in x_labels  # the major label, and a minor one where there is room


def test_a_narrow_log_y_axis_keeps_its_labels_apart() -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(3.0, 1.2), layout="constrained")
    ax = fig.add_subplot()
    ax.plot([0.0, 1.0], [30.0, 200.0])
    ax.set_yscale("log")
    ax.set_ylim(30.0, 200.0)
    for labels in _drawn_labels(fig):
        assert not _crowded(labels), _crowded(labels)


def test_savefig_within_file_tick_labels_keeps_labels_apart() -> None:
    """The way for ``savefig`` (the command line's plots): the same labels, the figure's formatters back after."""
    import io

    from matplotlib.figure import Figure
    from matplotlib.ticker import LogFormatterSciNotation

    fig = Figure(figsize=(4.0, 3.0), layout="constrained")
    ax = fig.add_subplot()
    ax.plot([20.0, 500.0], [1.0, 2.0])
    ax.set_xscale("log")
    seen: list[list[tuple[str, object, float]]] = []
    fig.canvas.mpl_connect("draw_event", lambda event: seen.append(_labels_of(ax.xaxis, event.renderer)))
    with file_tick_labels(fig):
        fig.savefig(io.BytesIO(), format="png", dpi=120, bbox_inches="tight")
    assert seen and all(not _crowded(labels) for labels in seen)
    assert type(ax.xaxis.get_minor_formatter()) is LogFormatterSciNotation
