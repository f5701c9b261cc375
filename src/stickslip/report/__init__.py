"""The reproduction report: the paper's figures and every number it states, beside this package's.

``build_report(folder)`` writes ``report.html`` (one self-contained file),
``results.json`` (the comparison table in SI units), each figure as PNG and
SVG, and one CSV per plotted curve.  ``stickslip reproduce`` is its command.
"""

from .build import Report, build_report

__all__ = ["Report", "build_report"]
