"""Figures as files: PNG bytes for embedding, and every plotted curve read back for CSV export.

The CSV files are read back from the matplotlib artists themselves, so they
hold exactly what is drawn: every line and every set of points drawn in data
coordinates (reference lines such as ``axvline`` and shaded spans are not
curves and are skipped).  Columns are named after the axis labels; files after
the ``gid`` a figure gave the curve, else after its legend label.
"""

from __future__ import annotations

import base64
import io
import re
from dataclasses import dataclass
from functools import cache
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Resolution of the PNG files and of the images embedded in report.html.
PNG_DPI = 110


def png_and_svg_bytes(figure: Figure, dpi: int = PNG_DPI) -> tuple[bytes, bytes]:
    """The figure as PNG and as SVG, both cropped to what is drawn, from one layout and one raster draw.

    ``savefig(bbox_inches="tight")`` lays the figure out and measures every text twice per file before it draws.
    Here the figure is laid out and drawn once at ``dpi``; the tight box is measured on that same renderer (its
    text sizes cached); the PNG is the raster cut to the box (the padding past the figure's edge in its face
    colour, as ``savefig`` fills it), and the SVG is drawn into the same box with that layout kept.  Where an
    artist reaches past the figure's edge the PNG is drawn again into the box, as ``savefig`` would.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    dpi_before, engine, canvas_before = figure.dpi, figure.get_layout_engine(), figure.canvas
    formatters = _plain_log_labels(figure)
    try:
        figure.set_dpi(dpi)
        canvas = FigureCanvasAgg(figure)
        canvas.draw()  # the layout engine runs here, once
        tight = figure.get_tightbbox(canvas.get_renderer())
        box = tight.padded(_pad_inches())
        figure.set_layout_engine(None)  # keep that layout for the SVG (savefig would lay it out again at 72 dpi)
        png = io.BytesIO()
        if _inside(tight, figure):
            _write_png(png, _cut(np.asarray(canvas.buffer_rgba()), box, dpi, figure.get_facecolor()), dpi)
        else:
            figure.savefig(png, format="png", dpi=dpi, bbox_inches=box)
        svg = io.BytesIO()
        figure.savefig(svg, format="svg", bbox_inches=box)
    finally:
        figure.set_layout_engine(engine)
        figure.set_dpi(dpi_before)
        figure.set_canvas(canvas_before)
        _restore_formatters(formatters)
    return png.getvalue(), svg.getvalue()


#: mathtext's superscript digits and minus sign as the Unicode characters a text font draws
_SUPERSCRIPTS = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")
#: the labels of matplotlib's log formatters: ``$\mathdefault{[-][c\times]b^{e}}$`` and ``$\mathdefault{[-]x}$``
_LOG_POWER = re.compile(r"\$\\mathdefault\{(-?)(?:([0-9.]+)\\times)?([0-9.]+)\^\{(-?[0-9]+)\}\}\$")
_LOG_NUMBER = re.compile(r"\$\\mathdefault\{(-?)([0-9.]+)\}\$")
#: the minus sign mathtext draws for a hyphen
MINUS = "\u2212"


def plain_log_label(label: str) -> str:
    """A log axis's tick label written with Unicode characters instead of mathtext, the same text:
    ``$\\mathdefault{10^{-3}}$`` -> ``10⁻³``, ``$\\mathdefault{3\\times10^{2}}$`` -> ``3×10²``,
    ``$\\mathdefault{-10^{9}}$`` -> ``−10⁹``.  Any other label is returned as it is.

    Parsing mathtext costs ~10 ms a label (pyparsing), once for the raster and once for the SVG: the report's
    ~60 log-axis labels were ~0.6 s of its CPU; the plain text is measured from the font's cached metrics.
    """
    power = _LOG_POWER.fullmatch(label)
    if power is not None:
        sign, coefficient, base, exponent = power.groups()
        mantissa = f"{coefficient}×" if coefficient else ""
        return f"{MINUS if sign else ''}{mantissa}{base}{exponent.translate(_SUPERSCRIPTS)}"
    number = _LOG_NUMBER.fullmatch(label)
    if number is not None:
        sign, value = number.groups()
        return f"{MINUS if sign else ''}{value}"
    return label


def _plain_log_labels(figure: Figure) -> list[tuple[Any, str, Any, bool]]:
    """Give every axis labelled by matplotlib's own log formatter (log and symlog scales) the same labels in
    plain Unicode (:func:`plain_log_label`); returns what to put back."""
    from matplotlib.ticker import LogFormatterMathtext, LogFormatterSciNotation

    replaced: list[tuple[Any, str, Any, bool]] = []
    for ax in figure.axes:
        for axis in (ax.xaxis, ax.yaxis):
            for level, flag in ((axis.major, "isDefault_majfmt"), (axis.minor, "isDefault_minfmt")):
                formatter = level.formatter
                if type(formatter) in (LogFormatterSciNotation, LogFormatterMathtext):
                    replaced.append((level, flag, formatter, getattr(axis, flag)))
                    level.formatter = _plain_labels_type()(formatter)
    return replaced


def _restore_formatters(replaced: list[tuple[Any, str, Any, bool]]) -> None:
    for level, flag, formatter, default in replaced:
        level.formatter = formatter
        setattr(formatter.axis, flag, default)


@cache
def _plain_labels_type() -> type:
    """The formatter class of :func:`_plain_log_labels` (a matplotlib ``Formatter``, which an axis requires; made
    on first use, so that importing this module does not import matplotlib)."""
    from matplotlib.ticker import Formatter

    class PlainLabels(Formatter):
        """``inner``'s labels through :func:`plain_log_label`; the rest is ``inner``'s (which ticks get labels,
        the offset, the coordinates shown)."""

        def __init__(self, inner: Any) -> None:
            self.inner = inner

        def __call__(self, x: float, pos: int | None = None) -> str:
            return plain_log_label(self.inner(x, pos))

        def format_ticks(self, values: Any) -> list[str]:
            return [plain_log_label(label) for label in self.inner.format_ticks(values)]

        def set_axis(self, axis: Any) -> None:
            self.inner.set_axis(axis)

        def set_locs(self, locs: Any) -> None:
            self.inner.set_locs(locs)

        def get_offset(self) -> str:
            return str(self.inner.get_offset())

        def format_data(self, value: float) -> str:
            return str(self.inner.format_data(value))

        def format_data_short(self, value: float) -> str:
            return str(self.inner.format_data_short(value))

    return PlainLabels


def _pad_inches() -> float:
    from matplotlib import rcParams

    pad = rcParams["savefig.pad_inches"]
    return float(pad) if isinstance(pad, int | float) else 0.1


def _inside(box: Any, figure: Figure) -> bool:
    """Whether ``box`` (inches) lies within the figure: then the raster of the figure holds all it shows."""
    width, height = figure.get_size_inches()
    return box.x0 >= 0.0 and box.y0 >= 0.0 and box.x1 <= width and box.y1 <= height


def _cut(rgba: np.ndarray, box: Any, dpi: float, face: tuple[float, ...]) -> np.ndarray:
    """The pixels of ``box`` (inches, origin bottom left) out of the raster of the whole figure; where the box
    reaches past the raster (its padding), the figure's face colour."""
    height, width = rgba.shape[:2]
    # the size savefig gives (the Agg canvas truncates the box's size in pixels), within half a pixel of its place
    left, top = round(box.x0 * dpi), height - round(box.y1 * dpi)
    right, bottom = left + int(box.width * dpi), top + int(box.height * dpi)
    out = np.empty((bottom - top, right - left, 4), dtype=np.uint8)
    out[:] = np.round(np.asarray(face, dtype=float) * 255.0).astype(np.uint8)
    rows, cols = slice(max(top, 0), min(bottom, height)), slice(max(left, 0), min(right, width))
    out[rows.start - top : rows.stop - top, cols.start - left : cols.stop - left] = rgba[rows, cols]
    return out


def _write_png(buffer: io.BytesIO, rgba: np.ndarray, dpi: float) -> None:
    """``rgba`` as PNG with the resolution and the Software entry that matplotlib's own PNG files carry."""
    import matplotlib
    from PIL import Image, PngImagePlugin

    info = PngImagePlugin.PngInfo()
    info.add_text("Software", f"Matplotlib version{matplotlib.__version__}, https://matplotlib.org/")
    image = Image.frombuffer("RGBA", (rgba.shape[1], rgba.shape[0]), np.ascontiguousarray(rgba), "raw", "RGBA", 0, 1)
    image.save(buffer, format="png", pnginfo=info, dpi=(dpi, dpi))


_TEX = {
    r"\sigma": "σ",
    r"\tau": "τ",
    r"\lambda": "λ",
    r"\Delta": "Δ",
    r"\mu": "µ",
    r"\alpha": "α",
    r"\,": " ",
    r"\ ": " ",
    r"\cdot": "·",
    r"\times": "×",
    r"\mathrm": "",
    r"\rm": "",
}


@dataclass(frozen=True)
class Curve:
    """One plotted curve: the x and y values as drawn, with the axis labels as column names."""

    name: str  # file stem, unique within the report
    figure_id: str
    panel: str
    label: str
    x_name: str
    y_name: str
    x: np.ndarray
    y: np.ndarray

    def to_csv(self) -> str:
        lines = [f"{_csv_field(self.x_name)},{_csv_field(self.y_name)}"]
        lines += [f"{_num(a)},{_num(b)}" for a, b in zip(self.x, self.y, strict=True)]
        return "\n".join(lines) + "\n"


def data_uri(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def plain_label(text: str) -> str:
    """Axis or legend text without mathtext markup: ``$\\sigma$ (Pa)`` -> ``σ (Pa)``."""
    for tex, plain in _TEX.items():
        text = text.replace(tex, plain)
    text = text.replace("$", "").replace("{", "").replace("}", "").replace("\\", "")
    return " ".join(text.split())


def _column(label: str, fallback: str) -> str:
    text = plain_label(label) or fallback
    # "sliding velocity V (µm/s)" -> "sliding velocity V [µm/s]", the units convention of the package's tables
    return re.sub(r"\s*\(([^()]*)\)\s*$", r" [\1]", text)


def _axis_label(ax: Axes, which: str) -> str:
    get = ax.get_xlabel if which == "x" else ax.get_ylabel
    if get():
        return get()
    shared = ax.get_shared_x_axes() if which == "x" else ax.get_shared_y_axes()
    for other in shared.get_siblings(ax):
        text = other.get_xlabel() if which == "x" else other.get_ylabel()
        if text:
            return text
    return ""


#: Longest curve name taken from a legend label, in characters.
SLUG_LENGTH = 40


#: Letters of the labels spelled in ASCII for file names ("ρh" -> "rhoh", "1000 × ρh" -> "1000-x-rhoh").
_ASCII = str.maketrans({"µ": "u", "σ": "sigma", "τ": "tau", "ρ": "rho", "η": "eta", "λ": "lambda", "Δ": "delta",
                        "χ": "chi", "×": "x", "ₛ": "s", "₀": "0"})  # fmt: skip


def _slug(text: str) -> str:
    text = plain_label(text).translate(_ASCII).lower()
    slug = re.sub(r"[^a-z0-9]+", "-", text).strip("-")
    if len(slug) > SLUG_LENGTH:
        slug = slug[: SLUG_LENGTH + 1].rsplit("-", 1)[0]
    return slug


def _errorbar_parts(ax: Axes) -> tuple[dict[int, str], set[int]]:
    """Error bars: their data line carries the label of its container; the caps are not curves."""
    from matplotlib.container import ErrorbarContainer

    labels: dict[int, str] = {}
    caps: set[int] = set()
    for container in ax.containers:
        if isinstance(container, ErrorbarContainer):
            data_line, caplines, _ = container.lines
            if data_line is not None:
                labels[id(data_line)] = str(container.get_label())
            caps |= {id(line) for line in caplines}
    return labels, caps


def extract_curves(figure: Figure, figure_id: str) -> list[Curve]:
    """Every line and point set of ``figure`` drawn in data coordinates, panel by panel."""
    curves: list[Curve] = []
    used: set[str] = set()
    panels = [ax for ax in figure.axes if ax.get_lines() or ax.collections]
    for index, ax in enumerate(panels):
        panel = chr(ord("a") + index) if len(panels) > 1 else ""
        x_name = _column(_axis_label(ax, "x"), "x")
        y_name = _column(_axis_label(ax, "y"), "y")
        found: list[tuple[str, str | None, np.ndarray, np.ndarray]] = []
        labels, caps = _errorbar_parts(ax)
        for line in ax.get_lines():
            if line.get_transform() != ax.transData or id(line) in caps:
                continue
            x = np.asarray(line.get_xdata(), dtype=float).ravel()
            y = np.asarray(line.get_ydata(), dtype=float).ravel()
            if x.size and x.size == y.size:
                found.append((labels.get(id(line), str(line.get_label())), line.get_gid(), x, y))
        for collection in ax.collections:
            offsets = np.asarray(collection.get_offsets(), dtype=float)
            if offsets.ndim != 2 or offsets.shape[0] == 0 or collection.get_offset_transform() != ax.transData:
                continue
            found.append((str(collection.get_label()), collection.get_gid(), offsets[:, 0], offsets[:, 1]))
        for k, (label, gid, x, y) in enumerate(found):
            shown = _shown_name(label, gid)
            unnamed = f"{'point' if x.size == 1 else 'curve'}-{k + 1}"
            stem = "_".join(s for s in (figure_id, panel, _slug(shown) or unnamed) if s)
            name, n = stem, 2
            while name in used:
                name, n = f"{stem}-{n}", n + 1
            used.add(name)
            curves.append(Curve(name, figure_id, panel, shown, x_name, y_name, x, y))
    return curves


def _shown_name(label: str, gid: str | None) -> str:
    """A curve's name: the one its figure gave it as ``gid`` (a marker the legend leaves out, one of several
    lines drawn as one with one legend entry), else its legend label; empty when it has neither."""
    if gid:
        return plain_label(gid)
    return "" if label.startswith("_") else plain_label(label)


def _num(value: float) -> str:
    return "" if not np.isfinite(value) else repr(float(value))


def _csv_field(text: str) -> str:
    if any(c in text for c in ',"\n'):
        return '"' + text.replace('"', '""') + '"'
    return text
