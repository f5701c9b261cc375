"""Log axes' tick labels in plain Unicode when a figure is written (issue 31: mathtext's parsing was ~0.6 s of the
report's CPU).  The labels must say what matplotlib's own say, and the figure must be left as it was."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.plots.export import plain_log_label, png_and_svg_bytes

pytest.importorskip("matplotlib")


@pytest.mark.parametrize(
    ("label", "plain"),
    [
        (r"$\mathdefault{10^{3}}$", "10³"),
        (r"$\mathdefault{10^{-12}}$", "10⁻¹²"),
        (r"$\mathdefault{10^{0}}$", "10⁰"),
        (r"$\mathdefault{3\times10^{2}}$", "3×10²"),
        (r"$\mathdefault{2.5\times10^{-4}}$", "2.5×10⁻⁴"),
        (r"$\mathdefault{-10^{9}}$", "\u221210⁹"),  # mathtext draws a hyphen as the minus sign
        (r"$\mathdefault{0}$", "0"),
        (r"$\mathdefault{-0.5}$", "\u22120.5"),
        (r"$\mathdefault{2^{5}}$", "2⁵"),
        ("", ""),
        (r"$V_c$ = 124.1 µm/s", r"$V_c$ = 124.1 µm/s"),  # not a log label: left to mathtext
        (r"$\mathdefault{10^{1.50}}$", r"$\mathdefault{10^{1.50}}$"),  # a fractional exponent: left as it is
        (r"$\mathdefault{1e+20}$", r"$\mathdefault{1e+20}$"),
    ],
)
def test_a_log_label_in_unicode(label: str, plain: str) -> None:
    assert plain_log_label(label) == plain


def _figure():  # type: ignore[no-untyped-def]
    from matplotlib.figure import Figure

    fig = Figure(figsize=(5.0, 2.6), layout="constrained")
    left, right = fig.subplots(1, 2)
    x = np.logspace(-3.0, 3.0, 50)
    left.loglog(x, x**1.5)
    left.set_xlabel(r"V (µm/s), $V_c$ marked")  # mathtext elsewhere stays mathtext
    right.plot(np.linspace(-1e9, 1e9, 50), np.linspace(-1.0, 1.0, 50))
    right.set_xscale("symlog", linthresh=1e6, linscale=0.4)
    return fig


def _tick_labels(fig) -> list[list[str]]:  # type: ignore[no-untyped-def]
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()
    return [
        [label.get_text() for label in getattr(ax, f"get_{which}ticklabels")(minor=minor)]
        for ax in fig.axes
        for which in ("x", "y")
        for minor in (False, True)
    ]


def test_the_written_figure_has_matplotlibs_labels_without_mathtext(monkeypatch: pytest.MonkeyPatch) -> None:
    import re

    from matplotlib import _mathtext

    expected = [plain_log_label(text) for axis in _tick_labels(_figure()) for text in axis if text]
    assert "10⁻³" in expected and "\u221210⁹" in expected  # matplotlib's own labels, converted
    parsed: list[str] = []
    parse = _mathtext.Parser.parse

    def recorded(self, s, *args, **kwargs):  # type: ignore[no-untyped-def]
        parsed.append(s)
        return parse(self, s, *args, **kwargs)

    monkeypatch.setattr(_mathtext.Parser, "parse", recorded)
    _, svg = png_and_svg_bytes(_figure())
    assert parsed and all("mathdefault" not in s for s in parsed)  # only the axis label's $V_c$ went to mathtext
    written = re.findall(r"<!-- (.*?) -->", svg.decode())  # the SVG names each text it draws
    assert "10⁻³" in written and "\u221210⁹" in written
    powers = {text for text in written if any(c in text for c in "⁰¹²³⁴⁵⁶⁷⁸⁹")}
    assert powers <= set(expected) and not any("mathdefault" in text for text in written)


def _formatters(fig) -> list[tuple[object, ...]]:  # type: ignore[no-untyped-def]
    return [
        (
            type(axis.get_major_formatter()),
            type(axis.get_minor_formatter()),
            axis.isDefault_majfmt,
            axis.isDefault_minfmt,
        )
        for ax in fig.axes
        for axis in (ax.xaxis, ax.yaxis)
    ]


def test_the_figure_keeps_its_formatters() -> None:
    from matplotlib.ticker import LogFormatterSciNotation

    fig = _figure()
    before = _formatters(fig)
    png_and_svg_bytes(fig)
    after = _formatters(fig)
    assert after == before and before[0][0] is LogFormatterSciNotation
    assert _tick_labels(fig)[0][0].startswith("$")  # matplotlib's own labels again when drawn afterwards


def test_the_same_size_as_matplotlibs_own_labels() -> None:
    import io

    from PIL import Image

    png, _ = png_and_svg_bytes(_figure())
    reference = io.BytesIO()
    _figure().savefig(reference, format="png", dpi=110, bbox_inches="tight")
    new, ref = Image.open(io.BytesIO(png)).size, Image.open(reference).size
    assert abs(new[0] - ref[0]) <= 2 and abs(new[1] - ref[1]) <= 2
