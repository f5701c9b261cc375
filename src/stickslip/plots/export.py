"""Figures as files: PNG bytes for embedding, and every plotted curve read back for CSV export.

The CSV files are read back from the matplotlib artists themselves, so they
hold exactly what is drawn: every line and every set of points drawn in data
coordinates (reference lines such as ``axvline`` and shaded spans are not
curves and are skipped), and the cells of a colour mesh whose colours the legend
names (a phase diagram's regimes, :func:`mesh_cells`): one file per legend entry,
the centre of each cell drawn in its colour.  Columns are named after the axis labels, ``name [unit]``
as every CSV of the package (:mod:`stickslip.columns`): a unit in parentheses
becomes one in brackets, a label without a unit is a pure number (``[1]``), a
panel without a label of its own takes the one of the axis it shares, of its
column (row) of panels, or the figure's ``supxlabel`` (``supylabel``); an axis
whose ticks are named categories writes the names, under its label alone (a
text column).  Files are named after the ``gid`` a figure gave the curve, else
after its legend label.
"""

from __future__ import annotations

import base64
import io
import math
import re
from collections.abc import Iterator
from contextlib import contextmanager
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


@contextmanager
def file_tick_labels(figure: Figure) -> Iterator[Figure]:
    """Within the block, ``figure``'s log axes are labelled as in the package's files (plain Unicode labels,
    :func:`plain_log_label`; minor labels that would touch others left off, :func:`uncrowded_minor_labels`);
    its own formatters are back afterwards.  :func:`png_and_svg_bytes` draws so; for ``savefig`` elsewhere::

        with file_tick_labels(fig):
            fig.savefig(path, dpi=120, bbox_inches="tight")
    """
    replaced = _plain_log_labels(figure)
    try:
        yield figure
    finally:
        _restore_formatters(replaced)


def _plain_log_labels(figure: Figure) -> list[tuple[Any, str, Any, bool]]:
    """Give every axis labelled by matplotlib's own log formatter (log and symlog scales) the same labels in
    plain Unicode (:func:`plain_log_label`); returns what to put back."""
    from matplotlib.ticker import LogFormatterMathtext, LogFormatterSciNotation

    replaced: list[tuple[Any, str, Any, bool]] = []
    for ax in getattr(figure, "axes", ()):  # (a stand-in with only savefig, as a caller may pass, has none)
        for axis in (ax.xaxis, ax.yaxis):
            for level, flag in ((axis.major, "isDefault_majfmt"), (axis.minor, "isDefault_minfmt")):
                formatter = level.formatter
                if type(formatter) in (LogFormatterSciNotation, LogFormatterMathtext):
                    replaced.append((level, flag, formatter, getattr(axis, flag)))
                    level.formatter = _plain_labels_type()(formatter, minor=level is axis.minor)
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
        the offset, the coordinates shown).  As the ``minor`` formatter, the labels that would touch a major
        label or each other are left off (:func:`uncrowded_minor_labels`)."""

        def __init__(self, inner: Any, minor: bool = False) -> None:
            self.inner = inner
            self.minor = minor

        def __call__(self, x: float, pos: int | None = None) -> str:
            return plain_log_label(self.inner(x, pos))

        def format_ticks(self, values: Any) -> list[str]:
            labels = [plain_log_label(label) for label in self.inner.format_ticks(values)]
            if self.minor and any(labels):
                labels = uncrowded_minor_labels(self.inner.axis, values, labels)
            return labels

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


#: The least space between two tick labels, in units of the labels' font size (an em).
LABEL_GAP_EM = 0.8
#: Which minor labels of a log axis stay first where not all fit: those at 2 and 5 times a power of ten.
_MINOR_ORDER = (2, 5, 3, 4, 6, 7, 8, 9)


def uncrowded_minor_labels(axis: Any, values: Any, labels: list[str]) -> list[str]:
    """``labels`` of a log axis's minor ticks at ``values``, less those that would overlap a major label or each
    other, or come within :data:`LABEL_GAP_EM` of one.

    matplotlib labels minor ticks where a log axis crosses at most one power of ten (at 2, 3, 4 and 6 times it
    where it spans more than 0.4 of a decade, at all of them below): 20-500 µm/s in a panel 4 inches wide runs
    "2×10¹3×10¹4×10¹".  Major labels are kept as they are; minor ones are kept while there is room, those at 2
    and then 5 times a power first, then 3, 4, 6, ... .  Each label's extent along the axis is measured from the
    font (the same metrics the renderers use, in points, so the choice is the same at any resolution).
    """
    from matplotlib.textpath import text_to_path

    ax = axis.axes
    horizontal = axis.axis_name == "x"
    length = ax.bbox.width if horizontal else ax.bbox.height
    scale = axis.get_transform()
    low, high = scale.transform(np.asarray(axis.get_view_interval(), dtype=float))
    if not (np.isfinite(low) and np.isfinite(high)) or high == low or length <= 0:
        return labels
    points_to_pixels = axis.figure.dpi / 72.0

    def extents(locs: Any, texts: list[str], tick: Any) -> list[tuple[float, float]]:
        where = (scale.transform(np.asarray(locs, dtype=float)) - low) / (high - low) * length
        text = tick.label1
        prop, angle = text.get_fontproperties(), np.deg2rad(text.get_rotation())
        pad = 0.5 * LABEL_GAP_EM * prop.get_size_in_points() * points_to_pixels
        spans = []
        for centre, label in zip(where, texts, strict=True):
            width, height, _ = text_to_path.get_text_width_height_descent(label, prop, ismath=False)
            along = abs(width * np.cos(angle)) + abs(height * np.sin(angle)) if horizontal else (
                abs(width * np.sin(angle)) + abs(height * np.cos(angle)))  # fmt: skip
            half = 0.5 * along * points_to_pixels + pad
            spans.append((centre - half, centre + half))
        return spans

    def shown(locs: Any) -> np.ndarray:
        where = (scale.transform(np.asarray(locs, dtype=float)) - low) / (high - low)
        return (where >= -1e-9) & (where <= 1 + 1e-9)

    major_locs = np.asarray(axis.get_majorticklocs(), dtype=float)
    major_locs = major_locs[shown(major_locs)] if major_locs.size else major_locs
    major_labels = [plain_log_label(t) for t in axis.major.formatter.format_ticks(major_locs)]
    taken = [
        span
        for span, text in zip(extents(major_locs, major_labels, axis.get_major_ticks(1)[0]), major_labels, strict=True)
        if text
    ]
    values = np.asarray(values, dtype=float)
    spans = extents(values, labels, axis.get_minor_ticks(1)[0])
    candidates = [k for k, text in enumerate(labels) if text and shown(values[k : k + 1])[0]]
    candidates.sort(key=lambda k: (_minor_rank(values[k]), k))
    kept = [""] * len(labels)
    for k in candidates:
        lo, hi = spans[k]
        if all(hi <= a or lo >= b for a, b in taken):
            taken.append((lo, hi))
            kept[k] = labels[k]
    return kept


def _minor_rank(value: float) -> int:
    """Where a minor tick at ``value`` stands in :data:`_MINOR_ORDER` (its leading digit; others last)."""
    size = abs(value)
    if not np.isfinite(size) or size == 0:
        return len(_MINOR_ORDER)
    digit = round(size / 10.0 ** np.floor(np.log10(size) + 1e-9))
    return _MINOR_ORDER.index(digit) if digit in _MINOR_ORDER else len(_MINOR_ORDER)


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
    """One plotted curve: the x and y values as drawn, with the axis labels as column names.  On an axis of named
    categories (tick labels set in place of numbers) ``x_text`` (``y_text``) holds each point's category, written
    in place of the position ``x`` (``y``)."""

    name: str  # file stem, unique within the report
    figure_id: str
    panel: str
    label: str
    x_name: str
    y_name: str
    x: np.ndarray
    y: np.ndarray
    x_text: tuple[str, ...] | None = None
    y_text: tuple[str, ...] | None = None

    def to_csv(self) -> str:
        xs = [_csv_field(t) for t in self.x_text] if self.x_text is not None else _numbers(self.x)
        ys = [_csv_field(t) for t in self.y_text] if self.y_text is not None else _numbers(self.y)
        lines = [f"{_csv_field(self.x_name)},{_csv_field(self.y_name)}"]
        lines += [f"{a},{b}" for a, b in zip(xs, ys, strict=True)]
        return "\n".join(lines) + "\n"


def data_uri(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def plain_label(text: str) -> str:
    """Axis or legend text without mathtext markup: ``$\\sigma$ (Pa)`` -> ``σ (Pa)``."""
    for tex, plain in _TEX.items():
        text = text.replace(tex, plain)
    text = text.replace("$", "").replace("{", "").replace("}", "").replace("\\", "")
    return " ".join(text.split())


#: A unit at the end of an axis label, after a space: ``(µm/s)`` or ``[µm/s]`` (not ``ln(V/V₀)``).
_LABEL_UNIT = re.compile(r"\s+(?:\(([^()]*)\)|\[([^\[\]]*)\])$")


def _column(label: str, which: str) -> str:
    """The CSV header cell of an axis labelled ``label``: ``name [unit]`` (:func:`stickslip.columns.header_cell`).

    "sliding velocity V (µm/s)" -> "sliding velocity V [µm/s]"; a label without a unit names a pure number,
    "friction σ/σc" -> "friction σ/σc [1]"; an axis without a label is "unlabelled x axis [?]" (neither a
    bare "x" nor a unit it may not have)."""
    from ..columns import DIMENSIONLESS, header_cell

    text = plain_label(label)
    if not text:
        return f"unlabelled {which} axis [?]"
    found = _LABEL_UNIT.search(text)
    if found is None:
        return header_cell(text, DIMENSIONLESS)
    name, unit = text[: found.start()].strip(), (found.group(1) if found.group(1) is not None else found.group(2))
    return header_cell(name, unit.strip() or DIMENSIONLESS) if name else header_cell(text, DIMENSIONLESS)


def _axis_label(ax: Axes, which: str) -> str:
    """``ax``'s own x (y) label; else the one of an axis it shares x (y) with, the one label of the other panels
    of its column (row) of a grid of subplots (a stack of panels that names x under the last one), or the
    figure's ``supxlabel`` (``supylabel``); "" when there is none."""
    own = _label_of(ax, which)
    if own:
        return own
    shared = ax.get_shared_x_axes() if which == "x" else ax.get_shared_y_axes()
    for other in shared.get_siblings(ax):
        if _label_of(other, which):
            return _label_of(other, which)
    in_line = {_label_of(other, which) for other in _same_column(ax, which)} - {""}
    if len(in_line) == 1:
        return in_line.pop()
    figure = ax.figure
    while figure is not None:
        sup = getattr(figure, "_supxlabel" if which == "x" else "_supylabel", None)
        if sup is not None and sup.get_visible() and sup.get_text():
            return str(sup.get_text())
        parent = getattr(figure, "_parent", None)
        figure = parent if parent is not figure else None
    return ""


def _label_of(ax: Axes, which: str) -> str:
    return str(ax.get_xlabel() if which == "x" else ax.get_ylabel())


def _same_column(ax: Axes, which: str) -> list[Axes]:
    """The other subplots of ``ax``'s grid in the same column (``which`` "x") or row ("y") as ``ax``."""
    spec = ax.get_subplotspec()
    if spec is None:
        return []
    lines = spec.colspan if which == "x" else spec.rowspan
    found = []
    for other in ax.figure.axes:
        other_spec = other.get_subplotspec() if other is not ax else None
        if other_spec is None or other_spec.get_gridspec() is not spec.get_gridspec():
            continue
        if (other_spec.colspan if which == "x" else other_spec.rowspan) == lines:
            found.append(other)
    return found


def _categories(axis: Any) -> dict[float, str] | None:
    """The category of each tick of an axis whose ticks are named (``set_xticks(positions, names)``): position ->
    name; None for an axis of numbers (its tick labels numbers, or made by a formatter)."""
    from matplotlib.ticker import FixedFormatter, FixedLocator, FuncFormatter

    locator, formatter = axis.get_major_locator(), axis.get_major_formatter()
    # set_ticks(positions, names) gives a FixedLocator and the names as a FuncFormatter (matplotlib >= 3.8) or a
    # FixedFormatter
    if not isinstance(locator, FixedLocator) or not isinstance(formatter, FixedFormatter | FuncFormatter):
        return None
    locs = np.asarray(locator.locs, dtype=float)
    names = [plain_label(str(t)) for t in formatter.format_ticks(locs)]
    if not any(names) or all(_is_number(n) for n in names if n):
        return None
    return dict(zip(locs.tolist(), names, strict=True))


def _is_number(text: str) -> bool:
    try:
        float(text.replace(MINUS, "-"))
    except ValueError:
        return False
    return True


def _category_text(values: np.ndarray, categories: dict[float, str] | None) -> tuple[str, ...] | None:
    """Each value's category name, where every value sits on a named tick; else None (the numbers are written)."""
    if categories is None or values.size == 0:
        return None
    locs = np.array(list(categories))
    names = list(categories.values())
    nearest = np.abs(values[:, None] - locs[None, :]).argmin(axis=1)
    if not np.allclose(values, locs[nearest], rtol=0.0, atol=1e-9 * max(1.0, float(np.abs(locs).max()))):
        return None
    texts = tuple(names[k] for k in nearest)
    return texts if all(texts) else None


def _category_column(label: str) -> str:
    """A text column's header: the axis label, bare (a text column has no unit), without a unit it may carry."""
    text = plain_label(label)
    found = _LABEL_UNIT.search(text)
    return (text[: found.start()].strip() if found else text) or "category"


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
        x_label, y_label = _axis_label(ax, "x"), _axis_label(ax, "y")
        x_categories, y_categories = _categories(ax.xaxis), _categories(ax.yaxis)
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
        found += [(label, None, x, y) for label, x, y in mesh_cells(ax)]
        for k, (label, gid, x, y) in enumerate(found):
            shown = _shown_name(label, gid)
            unnamed = f"{'point' if x.size == 1 else 'curve'}-{k + 1}"
            stem = "_".join(s for s in (figure_id, panel, _slug(shown) or unnamed) if s)
            name, n = stem, 2
            while name in used:
                name, n = f"{stem}-{n}", n + 1
            used.add(name)
            x_text, y_text = _category_text(x, x_categories), _category_text(y, y_categories)
            x_name = _category_column(x_label) if x_text is not None else _column(x_label, "x")
            y_name = _category_column(y_label) if y_text is not None else _column(y_label, "y")
            curves.append(Curve(name, figure_id, panel, shown, x_name, y_name, x, y, x_text, y_text))
    return curves


def mesh_cells(ax: Axes) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """The cells of each colour mesh of ``ax`` (``pcolormesh``) whose every colour is named by one legend entry
    of ``ax`` (a handle of one face colour: the squares a phase diagram's legend shows for its regimes): for each
    such entry, its label and the x and y of the centres of the cells drawn in its colour, sorted by x, then y.

    A cell's centre is the middle of its edges in the axis's scale (geometric on a log axis): for a sweep's cells,
    whose edges lie halfway between its grid points in that scale, the grid point itself (to :data:`CELL_DIGITS`
    digits) where the grid is evenly spaced in it (``a..b:n`` and ``a..b:n:log``, as the report's phase diagram),
    else the middle of the drawn cell.
    Masked cells (no value) are not written; a mesh on a colour scale, whose colours no legend entry names, is
    not a set of named cells and is skipped (it is not a curve)."""
    from matplotlib.collections import QuadMesh
    from matplotlib.colors import to_rgba_array

    named: list[tuple[str, np.ndarray]] = []
    for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
        faces = to_rgba_array(handle.get_facecolor()) if hasattr(handle, "get_facecolor") else np.empty((0, 4))
        if faces.shape[0] == 1:
            named.append((str(label), faces[0, :3]))
    found: list[tuple[str, np.ndarray, np.ndarray]] = []
    for mesh in ax.collections:
        if not isinstance(mesh, QuadMesh) or mesh.get_transform() != ax.transData or mesh.get_array() is None:
            continue
        corners = np.asarray(mesh.get_coordinates(), dtype=float)  # (rows + 1, columns + 1, 2)
        shape = (corners.shape[0] - 1, corners.shape[1] - 1)
        values = np.ma.masked_invalid(np.ma.asarray(mesh.get_array(), dtype=float).reshape(shape))
        drawn = ~np.ma.getmaskarray(values)
        if not drawn.any():
            continue
        colors = np.asarray(mesh.to_rgba(values.filled(0.0)), dtype=float)[..., :3][drawn]
        matches = np.array([np.all(np.abs(colors - rgb) <= 1e-6, axis=1) for _, rgb in named]).reshape(-1, len(colors))
        if not named or np.any(matches.sum(axis=0) != 1):  # a colour no entry (or more than one) names
            continue
        x, y = (_cell_centres(corners[..., k], axis)[drawn] for k, axis in ((0, ax.xaxis), (1, ax.yaxis)))
        for (label, _), mine in zip(named, matches, strict=True):
            if mine.any():
                order = np.lexsort((y[mine], x[mine]))
                found.append((label, x[mine][order], y[mine][order]))
    return found


#: Significant digits of a cell's centre: the edges are the grid's values taken into the axis's scale and back,
#: which leaves round-off in the 15th digit (4000000.00000001 for a grid point of 4e6 on a log axis).
CELL_DIGITS = 12


def _cell_centres(corners: np.ndarray, axis: Any) -> np.ndarray:
    """The centre of each cell of a mesh's corner coordinates on one axis, taken in that axis's scale, to
    :data:`CELL_DIGITS` significant digits."""
    scale = axis.get_transform()
    shown = scale.transform(corners.reshape(-1, 1)).reshape(corners.shape)
    middle = 0.25 * (shown[:-1, :-1] + shown[1:, :-1] + shown[:-1, 1:] + shown[1:, 1:])
    centres = np.asarray(scale.inverted().transform(middle.reshape(-1, 1)), dtype=float).reshape(middle.shape)
    return np.vectorize(lambda v: float(f"{v:.{CELL_DIGITS}g}"), otypes=[float])(centres)


def _shown_name(label: str, gid: str | None) -> str:
    """A curve's name: the one its figure gave it as ``gid`` (a marker the legend leaves out, one of several
    lines drawn as one with one legend entry), else its legend label; empty when it has neither."""
    if gid:
        return plain_label(gid)
    return "" if label.startswith("_") else plain_label(label)


def _numbers(values: np.ndarray) -> list[str]:
    """Each value as a CSV cell, in the package's CSV digits as every CSV it writes (``csv_number``), a non-finite
    one empty.  Taken as Python floats: the report's ~68 000 plotted numbers cost 0.17 s of CPU one numpy scalar at
    a time (its ``isfinite`` and an import each), 0.06 s so (issue 31)."""
    from ..columns import csv_number

    return [csv_number(v) if math.isfinite(v) else "" for v in np.asarray(values, dtype=float).ravel().tolist()]


def _csv_field(text: str) -> str:
    if any(c in text for c in ',"\n'):
        return '"' + text.replace('"', '""') + '"'
    return text
