"""report.html: one self-contained file (inline CSS, figures as data URIs, no scripts, no fonts)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from html import escape
from importlib import resources
from string import Template

from ..analysis import TraceAnalysis
from ..parameters import Parameters
from .comparisons import TOLERANCE, Comparison
from .errata import Errata
from .figures import Curve, ReportFigure, data_uri
from .formatting import format_percent, format_quantity
from .paper import TABLE1_COLUMNS, TABLE1_ROWS

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
        f"<figcaption>{escape(f.caption)}"
        f'<span class="files">Files: <a href="{escape(f.id)}.png">{escape(f.id)}.png</a>, '
        f'<a href="{escape(f.id)}.svg">{escape(f.id)}.svg</a>; curves: {csv_links}</span>'
        f"</figcaption>\n</figure>\n</section>"
    )


def comparison_table(rows: Sequence[Comparison], errata: Errata) -> str:
    head = (
        '<table class="comparisons">\n<thead><tr><th>Quantity</th><th>Kind</th><th>Paper</th><th>Source</th>'
        "<th>Computed</th><th>Difference</th><th>Erratum</th><th>Computed from</th></tr></thead>\n<tbody>"
    )
    out = [head]
    group = None
    for row in rows:
        n = row.number
        if n.group != group:
            group = n.group
            out.append(f'<tr class="group"><th colspan="8">{escape(group)}</th></tr>')
        css = "flagged" if row.flagged else "agrees"
        link = ""
        if row.errata is not None:
            entry = errata.get(row.errata)
            title = f' title="{escape(entry.title)}"' if entry is not None else ""
            anchor = entry.anchor if entry is not None else row.errata.lower()
            link = f'<a href="#{escape(anchor)}"{title}>{escape(row.errata)}</a>'
        out.append(
            f'<tr id="cmp-{escape(n.key)}" class="{css}" data-key="{escape(n.key)}">'
            f"<td>{escape(n.quantity)}{_note(n.note)}</td>"
            f'<td><span class="badge">{escape(KIND_LABELS[n.kind])}</span></td>'
            f'<td class="printed">{escape(n.printed)}</td>'
            f"<td>{escape(n.source)}</td>"
            f'<td class="num">{escape(format_quantity(row.computed, n.display))}</td>'
            f'<td class="num diff">{escape(format_percent(row.relative_difference))}</td>'
            f"<td>{link}</td>"
            f'<td class="how">{escape(row.how)}</td></tr>'
        )
    out.append("</tbody>\n</table>")
    return "\n".join(out)


def table1_matrix(rows: Sequence[Comparison]) -> str:
    """Table 1 laid out as in the paper, each cell the paper's value over the model's, with the difference."""
    by_key = {r.number.key: r for r in rows}
    head = "".join(f"<th>{round(v * 1e6)} µm/s<br>cycle {c}</th>" for v, c in TABLE1_COLUMNS)
    out = [f'<table class="table1">\n<thead><tr><th></th>{head}</tr></thead>\n<tbody>']
    for key, label, _unit, display, _values, _scale in TABLE1_ROWS:
        cells = []
        for velocity, cycle in TABLE1_COLUMNS:
            row = by_key.get(f"table1_{key}_{round(velocity * 1e6)}_{cycle}")
            if row is None:
                cells.append('<td class="num">--</td>')
                continue
            css = "flagged" if row.flagged else "agrees"
            cells.append(
                f'<td class="num {css}"><a href="#cmp-{escape(row.number.key)}">{escape(row.number.printed)}</a><br>'
                f"{escape(format_quantity(row.computed, display, digits=3))}<br>"
                f'<span class="diff">{escape(format_percent(row.relative_difference))}</span></td>'
            )
        out.append(f"<tr><th>{escape(label)}</th>{''.join(cells)}</tr>")
    out.append("</tbody>\n</table>")
    return "\n".join(out)


#: Table 1 row -> the trace analysis' name for it (stickslip.analysis.CYCLE_QUANTITIES).
_ANALYSIS_NAMES = {"slip_stress": "peak_stress"}


def trace_table(analyses: Mapping[int, TraceAnalysis]) -> str:
    """Table 1's quantities measured on the model's own σ(t) by the trace analysis, beside the paper's means.

    At 100 µm/s the paper's mean leaves out cycle 1, which the paper sets apart (extra aging).
    """
    head = "".join(f"<th>{escape(label)}</th>" for _key, label, *_ in TABLE1_ROWS)
    out = [f'<table class="traces">\n<thead><tr><th>V0</th><th></th>{head}<th>cycles</th></tr></thead>\n<tbody>']
    for velocity_um, analysis in analyses.items():
        velocity = velocity_um * 1e-6
        columns = [
            k for k, (v, c) in enumerate(TABLE1_COLUMNS) if round(v * 1e6) == velocity_um and (v, c) != (100e-6, 1)
        ]
        paper_cells, model_cells = [], []
        for key, _label, _unit, display, values, scale in TABLE1_ROWS:
            measured = [float(v) * scale for k in columns if (v := values[k]) is not None]
            paper_cells.append(format_quantity(sum(measured) / len(measured), display, 3) if measured else "--")
            stats = analysis.summary.get(_ANALYSIS_NAMES.get(key, key), {})
            model_cells.append(
                format_quantity(stats.get("mean"), display, 4) if stats.get("mean") is not None else "--"
            )
        used = "cycles 2-4" if velocity == 100e-6 else f"{len(columns)} cycle(s)"
        complete = analysis.summary.get("n_complete", 0)
        rows = (
            ("paper, Table 1 mean", paper_cells, used),
            (f"model trace ({analysis.regime})", model_cells, f"{complete} complete"),
        )
        for k, (what, cells, count) in enumerate(rows):
            first = f'<th rowspan="2">{velocity_um} µm/s</th>' if k == 0 else ""
            tds = "".join(f'<td class="num">{escape(c)}</td>' for c in cells)
            out.append(f"<tr>{first}<td>{escape(what)}</td>{tds}<td>{escape(count)}</td></tr>")
    out.append("</tbody>\n</table>")
    return "\n".join(out)


def _note(text: str) -> str:
    return f'<br><span class="note">{escape(text)}</span>' if text else ""


def parameter_table(params: Parameters) -> str:
    out = ["<table>\n<thead><tr><th>Key</th><th>Symbol</th><th>Value</th><th>Meaning</th></tr></thead>\n<tbody>"]
    for key, symbol, value, meaning in params.rows():
        out.append(
            f"<tr><td><code>{escape(key)}</code></td><td>{escape(symbol)}</td>"
            f'<td class="num">{escape(value)}</td><td>{escape(meaning)}</td></tr>'
        )
    out.append("</tbody>\n</table>")
    return "\n".join(out)


def file_list(names: Sequence[str]) -> str:
    items = "\n".join(f'<li><a href="{escape(n)}">{escape(n)}</a></li>' for n in names)
    return f"<ul>\n{items}\n</ul>"


def summary_sentence(rows: Sequence[Comparison]) -> str:
    total = len(rows)
    within = sum(not r.flagged for r in rows)
    flagged = [r for r in rows if r.flagged]
    explained = sum(r.errata is not None for r in flagged)
    text = (
        f"{total} numbers stated in the paper are compared with this package's computation: "
        f"{within} agree within {100 * TOLERANCE:g} %"
    )
    if flagged:
        text += f"; {len(flagged)} differ by more, {explained} of them explained by an erratum."
    else:
        text += "."
    return escape(text)


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
) -> str:
    contents = [
        f'<li><a href="#{escape(f.figure.id)}">{escape(f.figure.number)}: {escape(f.figure.title)}</a></li>'
        for f in figures
    ]
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
