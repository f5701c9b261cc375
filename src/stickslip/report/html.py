"""report.html: one self-contained file (inline CSS, figures as data URIs, no scripts, no fonts)."""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from html import escape
from importlib import resources
from string import Template

from ..analysis import TraceAnalysis
from ..parameters import Parameters
from ..quasistatic.stick import StuckThreshold
from .comparisons import CLASSES, MODEL_DIFFERENCES, TOLERANCE, Comparison, outside_by, summary_counts
from .errata import Errata
from .figures import Curve, ReportFigure, data_uri
from .formatting import DISPLAY_UNITS, format_parameter, format_percent, format_quantity
from .markup import inline_html
from .paper import (
    JUMP_VELOCITY_BRANCHES,
    JUMP_VELOCITY_RULE,
    TABLE1_COLUMNS,
    TABLE1_ROWS,
    PaperNumber,
    jump_velocity_branch,
)

#: Opening of a wide table's box: it scrolls sideways when the window is too narrow, and then says so
#: (style.css shows the line only while the box can scroll).
WIDE = (
    '<div class="wide"><p class="scroll-hint">Wider than the window: scroll sideways in this table to see every'
    " column →</p>"
)

KIND_LABELS = {
    "model": "model result",
    "parameter": "parameter",
    "input": "experiment",
    "measured": "measurement",
}


@dataclass(frozen=True)
class RenderedFigure:
    figure: ReportFigure
    png: bytes
    curves: tuple[Curve, ...]


def _resource(name: str) -> str:
    return (resources.files("stickslip") / "report" / name).read_text(encoding="utf-8")


def figure_section(item: RenderedFigure) -> str:
    f = item.figure
    csv_links = ", ".join(f'<a href="{escape(c.name)}.csv">{escape(c.name)}.csv</a>' for c in item.curves)
    return (
        f'<section id="{escape(f.id)}" class="figure">\n'
        f"<h2>{escape(f.number)}: {escape(f.title)}</h2>\n"
        f"<figure>\n"
        f'<img src="{data_uri(item.png)}" alt="{escape(f.number)}: {escape(f.title)}">\n'
        f"<figcaption>{inline_html(f.caption)}"
        f'<span class="files">Files: <a href="{escape(f.id)}.png">{escape(f.id)}.png</a>, '
        f'<a href="{escape(f.id)}.svg">{escape(f.id)}.svg</a>; curves: {csv_links}</span>'
        f"</figcaption>\n</figure>\n</section>"
    )


def paper_text(n: PaperNumber) -> str:
    """The paper's number as printed, with its unit (Table 1 prints the unit in the row heading only)."""
    if n.source != "Table 1":
        return n.printed
    unit = DISPLAY_UNITS[n.display][1]
    return f"{n.printed} {unit}" if unit else n.printed


def difference_text(row: Comparison) -> str:
    return "units differ" if row.number.units_differ else format_percent(row.relative_difference)


def class_badge(row: Comparison) -> str:
    c = row.classification
    return f'<span class="class class-{c}" title="{escape(row.reason)}">{escape(CLASSES[c])}</span>'


def _errata_link(row: Comparison, errata: Errata) -> str:
    if row.errata is None:
        return ""
    entry = errata.get(row.errata)
    title = f' title="{escape(entry.title)}"' if entry is not None else ""
    anchor = entry.anchor if entry is not None else row.errata.lower()
    return f'<a href="#{escape(anchor)}"{title}>{escape(row.errata)}</a>'


def _alternative(row: Comparison, display: str, digits: int = 4, label: str | None = None) -> str:
    """The second value shown beside the computed one (``label`` instead of the row's own name for it)."""
    if row.alternative is None:
        return ""
    value = format_quantity(row.alternative, display, digits)
    return (
        f'<br><span class="alt">{escape(label or row.alternative_label)}: {escape(value)}'
        f" ({escape(format_percent(row.alternative_difference))})</span>"
    )


def comparison_table(rows: Sequence[Comparison], errata: Errata) -> str:
    head = (
        f'{WIDE}<table class="comparisons">\n<thead><tr><th>Quantity</th><th>Kind</th><th>Paper</th>'
        "<th>Source</th>"
        "<th>Computed</th><th>Difference</th><th>Class</th><th>Erratum</th><th>Computed from</th></tr></thead>\n"
        "<tbody>"
    )
    out = [head]
    group = None
    quantities = {r.number.key: r.number.quantity for r in rows}
    for row in rows:
        n = row.number
        if n.group != group:
            group = n.group
            out.append(f'<tr class="group"><th colspan="9">{escape(group)}</th></tr>')
        css = "flagged" if row.flagged else "agrees"
        if not row.counted:
            css += " repeat"
        out.append(
            f'<tr id="cmp-{escape(n.key)}" class="{css}" data-key="{escape(n.key)}"'
            f' data-class="{escape(row.classification)}" data-counted="{str(row.counted).lower()}">'
            f"<td>{escape(n.quantity)}{_note(n.note)}{_repeat_note(n, quantities)}</td>"
            f'<td><span class="badge">{escape(KIND_LABELS[n.kind])}</span></td>'
            f'<td class="printed">{escape(paper_text(n))}</td>'
            f"<td>{escape(n.source)}</td>"
            f'<td class="num">{escape(format_quantity(row.computed, n.display))}{_alternative(row, n.display)}</td>'
            f'<td class="num diff">{escape(difference_text(row))}</td>'
            f"<td>{class_badge(row)}</td>"
            f"<td>{_errata_link(row, errata)}</td>"
            f'<td class="how">{escape(row.how)}{_reproduced(row)}</td></tr>'
        )
    out.append("</tbody>\n</table></div>")
    return "\n".join(out)


def table1_matrix(rows: Sequence[Comparison]) -> str:
    """Table 1 laid out as in the paper: each cell the paper's value, the model's (at the column's measured
    stiffness) with the difference and its class, and the model at the nominal stiffness."""
    by_key = {r.number.key: r for r in rows}
    head = "".join(f"<th>{round(v * 1e6)} µm/s<br>cycle {c}</th>" for v, c in TABLE1_COLUMNS)
    out = [f'{WIDE}<table class="table1">\n<thead><tr><th></th>{head}</tr></thead>\n<tbody>']
    for key, label, _unit, display, _values, _scale in TABLE1_ROWS:
        cells = []
        for velocity, cycle in TABLE1_COLUMNS:
            row = by_key.get(f"table1_{key}_{round(velocity * 1e6)}_{cycle}")
            if row is None:
                cells.append('<td class="num">--</td>')
                continue
            css = "flagged" if row.flagged else "agrees"
            nominal = _alternative(row, display, 3, "nominal")
            cells.append(
                f'<td class="num {css}"><a href="#cmp-{escape(row.number.key)}">{escape(paper_text(row.number))}</a>'
                f"<br>{escape(format_quantity(row.computed, display, digits=3))}<br>"
                f'<span class="diff">{escape(difference_text(row))}</span><br>{class_badge(row)}{nominal}</td>'
            )
        out.append(f"<tr><th>{escape(label)}</th>{''.join(cells)}</tr>")
    out.append("</tbody>\n</table></div>")
    return "\n".join(out)


#: Table 1 row -> the trace analysis' name for it (stickslip.analysis.CYCLE_QUANTITIES).
_ANALYSIS_NAMES = {"slip_stress": "peak_stress"}
#: The Table 1 rows a start-up stick from rest shows (it has no sigma_c: it began at zero stress).
_START_UP_ROWS = ("slip_stress", "stick_time", "jump_velocity")


def start_up_stick(analysis: TraceAnalysis) -> dict[str, float] | None:
    """sigma_s, t_s and V_s of a record's start-up stick, where the record starts from rest (zero stress) and the
    analysis holds no complete cycle: the stick from the record's start to its first peak (left out of the cycle
    averages, which are over repeats of a cycle)."""
    if analysis.summary.get("n_complete", 0) or not analysis.cycles or len(analysis.stress) == 0:
        return None
    first = analysis.cycles[0]
    if first.peak_stress is None or first.peak_time is None or analysis.stress[0] != 0.0:
        return None
    values = {"slip_stress": first.peak_stress, "stick_time": first.peak_time - float(analysis.time[0])}
    if first.jump_velocity is not None:
        values["jump_velocity"] = first.jump_velocity
    return values


def trace_table(analyses: Mapping[int, TraceAnalysis]) -> str:
    """Table 1's quantities measured on the model's own σ(t) by the trace analysis, beside the paper's means.

    At 100 µm/s the paper's mean leaves out cycle 1, which the paper sets apart (extra aging).
    """
    head = "".join(f"<th>{escape(label)}</th>" for _key, label, *_ in TABLE1_ROWS)
    out = [f'{WIDE}<table class="traces">\n<thead><tr><th>V0</th><th></th>{head}<th>cycles</th></tr></thead>\n<tbody>']
    for velocity_um, analysis in analyses.items():
        velocity = velocity_um * 1e-6
        columns = [
            k for k, (v, c) in enumerate(TABLE1_COLUMNS) if round(v * 1e6) == velocity_um and (v, c) != (100e-6, 1)
        ]
        paper_cells, model_cells = [], []
        start_up = start_up_stick(analysis)
        for key, _label, _unit, display, values, scale in TABLE1_ROWS:
            measured = [float(v) * scale for k in columns if (v := values[k]) is not None]
            paper_cells.append(format_quantity(sum(measured) / len(measured), display, 3) if measured else "--")
            stats = analysis.summary.get(_ANALYSIS_NAMES.get(key, key), {})
            if stats.get("mean") is not None:
                model_cells.append(format_quantity(stats.get("mean"), display, 4))
            elif start_up is not None and key in start_up:
                model_cells.append(f"{format_quantity(start_up[key], display, 4)} (start-up stick)")
            else:
                model_cells.append("--")
        used = "cycles 2-4" if velocity == 100e-6 else f"{len(columns)} cycle(s)"
        complete = analysis.summary.get("n_complete", 0)
        count = f"{complete} complete"
        regime = analysis.regime
        if start_up is not None:
            regime += " after a start-up stick from rest"
            count += (
                "; σs, ts and Vs are its start-up stick, from rest at the record's start to the first peak (not a"
                " repeated cycle: no σc)"
            )
        rows = (
            ("paper, Table 1 mean", paper_cells, used),
            (f"model trace ({regime})", model_cells, count),
        )
        for k, (what, cells, count) in enumerate(rows):
            first = f'<th rowspan="2">{velocity_um} µm/s</th>' if k == 0 else ""
            tds = "".join(f'<td class="num">{escape(c)}</td>' for c in cells)
            out.append(f"<tr>{first}<td>{escape(what)}</td>{tds}<td>{escape(count)}</td></tr>")
    out.append("</tbody>\n</table></div>")
    return "\n".join(out)


def _note(text: str) -> str:
    return f'<br><span class="note">{escape(text)}</span>' if text else ""


def _reproduced(row: Comparison) -> str:
    """For a number the paper's stated inputs do not give: the unstated input that does, in the row itself."""
    if row.classification != "unstated" or not row.reproduced_by:
        return ""
    return f'<br><span class="note">Not stated in the paper: {escape(row.reproduced_by)}.</span>'


def _repeat_note(n: PaperNumber, quantities: Mapping[str, str]) -> str:
    """For a row that states again what other rows state: which, linked, and that it is counted there."""
    if not n.repeat_of:
        return ""
    links = " and ".join(f'<a href="#cmp-{escape(k)}">{escape(quantities.get(k, k))}</a>' for k in n.repeat_of)
    return (
        f'<br><span class="note repeat">Same statement as row {links}: counted once, there, not in this row'
        f" ({escape(n.repeat_note)}).</span>"
    )


#: The paper's symbols where a parameter's own (ASCII, to be typed on a command line) differs; the two aging times
#: the paper calls τa both get a label saying which one they are.
PAPER_SYMBOLS = {
    "bonds.site_density": "N_{0}",
    "bonds.bond_time": "τ",
    "bonds.breakage_weight": "u_{0}",
    "bonds.activation_length": "λ",
    "bonds.max_extension": "Δl_{m}",
    "aging.aging_time": "τ_{a} of the bonds (Eqs 1, 6)",
    "aging.aging_velocity": "V_{a}",
    "aging.saturation_age": "t_{s}",
    "stick.attached_chains": "N_{c0}",
    "stick.break_rate": "u_{c}/τ",
    "stick.aging_time": "τ_{a} of the stick chains (Eq 15)",
    "block.shear_modulus": "G_{d}",
}
_GREEK = {"tau": "τ", "lambda": "λ", "eta": "η", "rho": "ρ", "sigma": "σ", "mu": "µ", "theta": "θ", "dl": "Δl"}
_ASCII_GREEK = re.compile(r"\b(" + "|".join(_GREEK) + r")(?=\b|_)")


def parameter_symbol(key: str, symbol: str) -> str:
    """The symbol a reader of the paper knows (with subscript marks for :func:`inline_html`): the paper's where
    known, else the parameter's own with its Greek letters and subscripts written out."""
    if key in PAPER_SYMBOLS:
        return PAPER_SYMBOLS[key]
    written = _ASCII_GREEK.sub(lambda m: _GREEK[m.group(1)], symbol)
    return re.sub(r"_([A-Za-z0-9]+)", r"_{\1}", written)


#: Parameters of the set that the paper does not give: the package's reading (key -> what the paper gives instead).
PACKAGE_READINGS = {
    "bonds.chain_stiffness": "the package's reading, not the paper's: the paper gives only λM/kT, with a wrong"
    " dimension; M sets the scale of every steady stress (Eq 8), so every stress agreement rests on it",
    "bonds.activation_length": "the package's reading, not the paper's: λ = (λM/kT) kT / M with the M above;"
    " Eq 15 uses λ/kT",
    "bonds.temperature": "the experiments' 20 °C (Section 3)",
}


def parameter_table(params: Parameters) -> str:
    out = ["<table>\n<thead><tr><th>Key</th><th>Symbol</th><th>Value</th><th>Meaning</th></tr></thead>\n<tbody>"]
    for key, symbol, value, dimension, meaning in parameter_rows(params):
        reading = PACKAGE_READINGS.get(key)
        note = f'<br><span class="note reading">{escape(reading)}</span>' if reading else ""
        link = ' (<a href="#e1">E1</a>)' if key in ("bonds.chain_stiffness", "bonds.activation_length") else ""
        out.append(
            f"<tr><td><code>{escape(key)}</code></td>"
            f"<td>{inline_html(parameter_symbol(key, symbol))}</td>"
            f'<td class="num">{escape(format_parameter(value, dimension))}</td>'
            f"<td>{escape(meaning)}{note}{link}</td></tr>"
        )
    out.append("</tbody>\n</table>")
    return "\n".join(out)


def parameter_rows(params: Parameters) -> list[tuple[str, str, float, str, str]]:
    """(key, symbol, SI value, dimension, meaning) of every parameter."""
    from dataclasses import fields

    from ..parameters import SECTIONS

    return [
        (f"{s}.{f.name}", f.metadata["symbol"], getattr(getattr(params, s), f.name), f.metadata["dimension"],
         f.metadata["doc"])
        for s, cls in SECTIONS.items()
        for f in fields(cls)
        if getattr(getattr(params, s), f.name) is not None  # an extension's key left out
    ]  # fmt: skip


def file_list(names: Sequence[str]) -> str:
    items = "\n".join(f'<li><a href="{escape(n)}">{escape(n)}</a></li>' for n in names)
    return f"<ul>\n{items}\n</ul>"


def summary_sentence(rows: Sequence[Comparison]) -> str:
    """The headline: how many distinct statements of the paper fall in each class (a row that repeats another is
    counted once), and what the stress agreements rest on."""
    s = summary_counts(list(rows))
    counts = s["by_class"]
    differences = sum(counts[c] for c in MODEL_DIFFERENCES)
    text = (
        f"Of the {s['compared']} distinct numbers the paper states, {counts['agrees']} agree with this package's "
        f"computation within {100 * TOLERANCE:g} % and {counts['scatter']} lie within the scatter the paper states "
        "or shows (its σc band 259 ± 5 Pa, the one significant figure of “0.4 kPa”, or the range of the cycles it "
        f"measured at one V0, as printed, not widened). {counts['outside']} lie outside that measured range"
        f"{_outside_span(rows)} and {counts['open']} are open differences{_open_span(rows)}, where nothing in the "
        f"paper settles why: these {differences} are the model's differences, not the paper's errors. "
        f"{counts['erratum']} are errors in the paper (it contradicts itself or prints a wrong unit; each "
        "links its erratum; a contradiction among several of its numbers is one error, counted once), "
        f"{counts['unstated']} are numbers of the paper that its own stated inputs do not give "
        f"(each row names the input, not stated in the paper, that gives it) and {counts['limitation']} are "
        "limitations of the model (numbers it cannot give with any input). The other "
        f"{counts['input']} are the paper's own inputs handed back (parameters and arithmetic on them), not counted "
        f"as agreement. The table has {s['rows']} rows: {s['repeats']} state again a number that another row "
        "states (the paper printing it twice) and are marked and counted once. A difference between the model and a "
        "measurement is never counted as the paper's error by its size alone. "
    )
    basis = (
        "Every stress agreement rests on the package's reading of the paper's λM/kT, which has a wrong dimension: "
        "M = 100 µN/m and λ = 0.1 nm, values the paper does not give (Parameters used; erratum "
    )
    return f'{escape(text)}{escape(basis)}<a href="#e1">E1</a>{escape(RESTS_ON)}'


def _outside_span(rows: Sequence[Comparison]) -> str:
    """How far beyond the measured range the rows outside it lie, e.g. " (by 0.62 to 1.97 % of its edge)"."""
    beyond = [100 * abs(b) for r in rows if r.counted and r.classification == "outside" and
              (b := outside_by(r.number, r.computed)) is not None]  # fmt: skip
    if not beyond:
        return ""
    if len(beyond) == 1:
        return f" (by {beyond[0]:.2f} % of its edge)"
    return f" (by {min(beyond):.2f} to {max(beyond):.2f} % of its edge)"


def _open_span(rows: Sequence[Comparison]) -> str:
    """How far the open differences are from the paper's numbers, e.g. " (2.8 to 27 % from the paper's number)"."""
    sizes = [100 * abs(d) for r in rows if r.counted and r.classification == "open" and
             (d := r.relative_difference) is not None]  # fmt: skip
    if not sizes:
        return ""
    low, high = min(sizes), max(sizes)
    return f" ({low:.2g} to {high:.2g} % from the paper's number)" if len(sizes) > 1 else f" ({low:.2g} %)"


#: What the M of E1 decides, after the link to E1 in the headline.
RESTS_ON = (
    "): at a fixed λM/kT every steady stress of Eq 8 is proportional to M, and Eq 15 uses λ/kT = (λM/kT)/M. Vc "
    "does not depend on it."
)


def stiffness_paragraph(rows: Sequence[Comparison]) -> str:
    """How the report keeps the one stiffness fact from being counted in every slope, Gd/h and stick time."""
    below = [-100 * d for r in rows if r.number.key.startswith("table1_stick_slope_") and
             (d := r.alternative_difference) is not None]  # fmt: skip
    span = f"{min(below):.0f}–{max(below):.0f} %" if below else "about 10 %"
    fact = next((r for r in rows if r.number.key == "stiffness_against_table1"), None)
    gap = "" if fact is None or fact.relative_difference is None else f", {format_percent(fact.relative_difference)}"
    return (
        "<p><strong>Stiffness.</strong> The nominal stiffness 0.766 × 400 kPa/m gives stick slopes "
        f"{span} below Table 1's: one fact, counted once, as a disagreement between two of the paper's own inputs "
        f"(the row “Gd/h = 400 kPa/m compares well”{gap}, class “{escape(CLASSES['unstated'])}”: the nominal "
        "4 kPa / 10 mm against the stiffness its measured slopes give; not a limitation of the model, which takes "
        "either). So that it "
        "is not counted again in every slope, Gd/h and stick time, Table 1's σs and ts are computed with the "
        "stiffness each column's own slope implies (K = slope / V0), and the model with the nominal stiffness is "
        "shown beside (“nominal”). The start-up sticks (100 µm/s cycle 1, where σs − slope × ts = 21 Pa, and the "
        "350 µm/s column, above Vc) start from rest, as the experiment did; every other stick starts at the "
        "model's σc.</p>"
    )


#: What each branch of the Vs rule (paper.JUMP_VELOCITY_RULE) says of its cells, for one cell and for several.
_BRANCH_WORDS = {
    "agrees": ("agrees at its printed σs", "agree at their printed σs"),
    "column": ("is in a column that disagrees with itself, a paper error",
               "are in columns that disagree with themselves, paper errors"),
    "contradiction": ("is in a column whose measured cells contradict each other, a paper error",
                      "are in columns whose measured cells contradict each other, paper errors"),
    "model": ("is an open difference of the model", "are open differences of the model"),
}  # fmt: skip


def jump_velocity_paragraph(rows: Sequence[Comparison]) -> str:
    """The one rule for Table 1's Vs cells (paper.JUMP_VELOCITY_RULE) and which cells each of its branches holds."""
    branches: dict[str, list[str]] = {b: [] for b in JUMP_VELOCITY_BRANCHES}
    for row in rows:
        key = row.number.key
        if not key.startswith("table1_jump_velocity_"):
            continue
        branch = jump_velocity_branch(key) or ("agrees" if row.classification == "agrees" else None)
        if branch is None:  # a cell the rule does not settle is a "model limitation" row, shown as such
            continue
        v_um, cycle = key[len("table1_jump_velocity_") :].split("_")
        branches[branch].append(f"{v_um} µm/s" + ("" if v_um == "350" else f" cycle {cycle}"))
    counted = sum(len(cells) for cells in branches.values())
    if not counted:
        return ""
    parts = []
    for branch, cells in branches.items():
        label = JUMP_VELOCITY_BRANCHES[branch][0]
        where = f": {', '.join(cells)}" if cells and branch != "agrees" else ""
        parts.append(f"{len(cells)} {_BRANCH_WORDS[branch][len(cells) != 1]} ({label}{where})")
    text = f"{JUMP_VELOCITY_RULE}. Of Table 1's {counted} Vs cells, {'; '.join(parts)}."
    return f"<p><strong>Jump velocity Vs, one rule.</strong> {escape(text)}</p>"


def threshold_paragraph(
    thresholds: Mapping[str, StuckThreshold], jump_floor: float | None = None, curve_maximum: float | None = None
) -> str:
    """The stuck-for-ever threshold of Eq 15, stated as the model limitation it is."""
    rest, sigma_c = thresholds.get("from rest"), thresholds.get("from sigma_c")
    if sigma_c is None or sigma_c.velocity is None:
        return ""
    v_star = sigma_c.velocity * 1e6
    extra = f" ({rest.velocity * 1e6:.1f} µm/s for a stick from rest)" if rest and rest.velocity else ""
    gap = ""
    narrowed = f" to {jump_floor * 1e6:.1f} µm/s–Vc" if jump_floor is not None else ""
    if jump_floor is not None and curve_maximum is not None:
        gap = (
            f" Between {v_star:.1f} and {jump_floor * 1e6:.1f} µm/s the chains collapse at a σs above the steady "
            f"curve's maximum ({curve_maximum:.0f} Pa): no jump velocity exists and the model has no answer."
        )
    return (
        f'<p class="limitation"><strong>Model limitation: stuck for ever below {v_star:.2f} µm/s.</strong> With '
        "τa = 10 s the aging term −t/τa of Eq 15 grows without bound, so below this pulling velocity the breakage "
        f"rate of the attached chains decays faster than the load raises it and the block never slips{escape(extra)};"
        f" no block stays stuck above Nc0 kT/(λ K τa) = {sigma_c.ceiling * 1e6:.2f} µm/s.{escape(gap)} "
        "It is a limitation because the aging term is unbounded (the aging of a real contact saturates), not "
        "because of a measurement: the paper's stick–slip data are at 50, 100 and 350 µm/s only, and its general "
        f"statement that stick–slip occurs below Vc is narrowed by its own Eq 15{escape(narrowed)}. Whether the gel "
        'stick-slips at lower pulling velocities is not in the paper and not checked here (<a href="#m1">M1</a>; '
        "<code>stickslip.quasistatic.stick.stuck_threshold</code>).</p>"
    )


def limitations_section(paragraphs: str) -> str:
    """The model's limitations, after the figures: a reader meets what agrees first."""
    if not paragraphs:
        return ""
    return (
        '<section id="limitations">\n<h2>Limitations of the model</h2>\n'
        "<p>What the model, as the paper writes it, cannot do whatever its inputs. A number the paper states that"
        " the model cannot give with any input would be in the table below, class “model limitation”; where the"
        " model gives the paper's number with an input the paper does not state, the row is the paper's (class"
        f" “{escape(CLASSES['unstated'])}”), not the model's. Where the model and the paper differ and nothing in"
        f" the paper settles why, the row is the model's: class “{escape(CLASSES['open'])}” (the 350 µm/s"
        " start-up stick among them) or, beyond the range of the cycles the paper measured,"
        f" “{escape(CLASSES['outside'])}”.</p>\n"
        f"{paragraphs}\n</section>"
    )


def render_report(
    *,
    version: str,
    params: Parameters,
    built: str,
    elapsed: float,
    figures: Sequence[RenderedFigure],
    comparisons: Sequence[Comparison],
    errata: Errata,
    files: Sequence[str],
    analyses: Mapping[int, TraceAnalysis],
    thresholds: Mapping[str, StuckThreshold] | None = None,
    jump_floor: float | None = None,
    curve_maximum: float | None = None,
) -> str:
    contents = [
        f'<li><a href="#{escape(f.figure.id)}">{escape(f.figure.number)}: {escape(f.figure.title)}</a></li>'
        for f in figures
    ]
    limitation = threshold_paragraph(thresholds or {}, jump_floor, curve_maximum)
    if limitation:
        contents.append('<li><a href="#limitations">Limitations of the model</a></li>')
    contents += [
        '<li><a href="#comparisons">Every number the paper states</a></li>',
        '<li><a href="#parameters">Parameters used</a></li>',
        '<li><a href="#errata">Errata</a></li>',
        '<li><a href="#files">Files</a></li>',
    ]
    template = Template(_resource("template.html"))
    return template.substitute(
        style=_resource("style.css"),
        version=escape(version),
        params_name=escape(params.name),
        params_description=escape(params.description or "(no description)"),
        built=escape(built),
        elapsed=f"{elapsed:.1f}",
        summary=summary_sentence(comparisons),
        limitations=limitations_section(limitation),
        stiffness=f"{stiffness_paragraph(comparisons)}\n{jump_velocity_paragraph(comparisons)}",
        contents="\n".join(contents),
        figures="\n".join(figure_section(f) for f in figures),
        tolerance=f"{100 * TOLERANCE:g} %",
        comparisons=comparison_table(comparisons, errata),
        table1=table1_matrix(comparisons),
        traces=trace_table(analyses),
        parameters=parameter_table(params),
        errata_source=escape(errata.source),
        errata=errata.html,
        files=file_list(files),
    )
