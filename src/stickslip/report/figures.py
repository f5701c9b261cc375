"""The report's figures: which of the paper's figures each one reproduces, and writing it (PNG, SVG).

Drawing, PNG/SVG bytes and the export of every plotted curve as CSV are :mod:`stickslip.plots.export`'s; the
names build.py and html.py use are imported here from there.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..fileio import atomic_write_bytes
from ..plots.export import PNG_DPI, Curve, data_uri, extract_curves, png_and_svg_bytes

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["PNG_DPI", "Curve", "ReportFigure", "data_uri", "extract_curves", "save_figure_files"]


@dataclass(frozen=True)
class ReportFigure:
    """A figure of the report: which of the paper's figures it reproduces, and what to look for."""

    id: str  # file stem, e.g. "fig1-4_steady_curve"
    number: str  # the paper's numbering, e.g. "Figs 1 and 4"
    title: str
    caption: str  # plain text
    figure: Figure | None  # None once drawn and written (what the HTML and results.json need stays)

    def curves(self) -> list[Curve]:
        return extract_curves(self.figure, self.id)


def save_figure_files(figure: ReportFigure, folder: Path) -> tuple[bytes, list[Path]]:
    """Write ``<id>.png`` and ``<id>.svg`` into ``folder``; returns the PNG bytes (for embedding) and the paths."""
    png, svg = png_and_svg_bytes(figure.figure)  # one layout for both: half the cost of two savefig calls
    png_path, svg_path = folder / f"{figure.id}.png", folder / f"{figure.id}.svg"
    atomic_write_bytes(png_path, png)
    atomic_write_bytes(svg_path, svg)
    return png, [png_path, svg_path]
