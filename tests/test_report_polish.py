"""The report's polish as a reader sees it (issue 32 item 4): no raw markup, legends that name what is visible and
cover nothing, Greek symbols, one heading per section, tables inside the text column, curves named for what
they hold, the paper cited for what it is, and what agrees before what does not.

The figures are built directly with the report's figure functions; the page itself is the report that
tests/test_report.py builds once per session (:func:`test_report.built_report`).
"""

from __future__ import annotations

import re
import shutil
from html import unescape
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from stickslip.parameters import load_parameters
from stickslip.plots.export import extract_curves
from stickslip.report.computations import ModelRun
from stickslip.report.errata import load_errata, render_errata
from stickslip.report.html import parameter_table
from stickslip.report.markup import RAW_MARKUP, inline_html
from test_report import built_report

#: A curve named by its position only: what a reader cannot tell apart.
GENERIC = re.compile(r"_(curve|point)-\d+$")


@pytest.fixture(scope="module")
def params():
    return load_parameters("gelatin-glass")


@pytest.fixture(scope="module")
def run(params):
    return ModelRun(params)


@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> str:
    return (built_report(tmp_path_factory) / "report.html").read_text(encoding="utf-8")


def _reader_text(html: str) -> str:
    """What a reader reads as prose: no style, no code, no tags, entities decoded, white space as one space."""
    html = re.sub(r"<style>.*?</style>", "", html, flags=re.S)
    html = re.sub(r"<(pre|code)\b.*?</\1>", "", html, flags=re.S)
    return " ".join(unescape(re.sub(r"<[^>]+>", " ", html)).split())


# ---------------------------------------------------------------- markup


@pytest.mark.parametrize(
    ("text", "html"),
    [
        ("Made with `stickslip sweep` (docs/sweep.md).", "Made with <code>stickslip sweep</code> (docs/sweep.md)."),
        ("−(t_{a}/τa) e^{−V/Va}", "−(t<sub>a</sub>/τa) e<sup>−V/Va</sup>"),
        ("σ = ∫₀^{Δl_{m}/V0} n dt", "σ = ∫₀<sup>Δl<sub>m</sub>/V0</sup> n dt"),
        ("e^(1.77×10⁶), e^-10, (t − t0)^{1/2}", "e<sup>1.77×10⁶</sup>, e<sup>−10</sup>, (t − t0)<sup>1/2</sup>"),
        ("stuck_threshold & a<b", "stuck_threshold &amp; a&lt;b"),  # a bare underscore is a name, not a mark
    ],
)
def test_caption_marks_render_as_html(text: str, html: str) -> None:
    assert inline_html(text) == html
    assert not RAW_MARKUP.search(_reader_text(inline_html(text)))


def test_the_page_shows_no_raw_markdown_or_tex(page: str) -> None:
    prose = _reader_text(page)
    found = [prose[max(0, m.start() - 30) : m.end() + 30] for m in RAW_MARKUP.finditer(prose)]
    assert not found, f"raw markup in the page: {found[:5]}"
    # the marks the captions and errata use did become elements
    assert "<code>stickslip sweep</code>" in page and "e<sup>−V/Va</sup>" in page and "∫₀<sup>" in page


def test_errata_heading_appears_once(page: str) -> None:
    headings = [unescape(re.sub(r"<[^>]+>", "", h)) for h in re.findall(r"<h[1-6][^>]*>(.*?)</h[1-6]>", page)]
    assert [h for h in headings if h.startswith("Errata")] == ["Errata"]
    # the errata's own title is dropped (the report's section has its heading); a heading further down is kept
    errata = render_errata("# Errata of X\n\nIntro.\n\n## E1 First\n\nText.\n\n# Later\n")
    assert "Errata of X" not in errata.html and "<h2>Later</h2>" in errata.html and "Intro." in errata.html
    assert "Errata of" not in load_errata().html


# ---------------------------------------------------------------- parameters


def test_parameter_table_uses_the_papers_symbols_and_tells_the_two_aging_times_apart(params) -> None:
    table = parameter_table(params)
    symbols = [unescape(re.sub(r"<[^>]+>", "", cell)) for cell in re.findall(r"</code></td><td>(.*?)</td>", table)]
    assert len(symbols) == table.count("<tr>") - 1  # one per parameter row
    assert len(set(symbols)) == len(symbols), f"two rows share a symbol: {symbols}"
    ascii_names = re.compile(r"\b(tau|lambda|dl|eta|rho|sigma)\b|_")
    assert not [s for s in symbols if ascii_names.search(s)], symbols
    assert "τ" in symbols and "λ" in symbols and "Δlm" in symbols  # Δl<sub>m</sub> read as text
    aging = [s for s in symbols if s.startswith("τa")]
    assert len(aging) == 2 and any("bonds" in s for s in aging) and any("stick" in s for s in aging)


# ---------------------------------------------------------------- wide tables


def _css() -> str:
    return (resources.files("stickslip") / "report" / "style.css").read_text(encoding="utf-8")


def _rule(css: str, selector: str) -> str:
    match = re.search(rf"(?m)^{re.escape(selector)}\s*\{{(.*?)\}}", css, flags=re.S)
    assert match, f"no CSS rule for {selector}"
    return match.group(1)


def test_wide_tables_scroll_inside_the_text_column() -> None:
    wide = _rule(_css(), ".wide")
    assert re.search(r"overflow-x:\s*auto", wide) and re.search(r"max-width:\s*100%", wide)
    assert not re.search(r"transform|vw|left:", wide)  # nothing moves the box past the column's edges
    assert re.search(r"overflow-x:\s*auto", _rule(_css(), "#errata table"))


def test_wide_tables_stay_inside_the_column_in_a_browser(tmp_path: Path) -> None:
    """A table wider than the column, in the report's own CSS, rendered by headless Chromium."""
    chromium, driver_path = shutil.which("chromium") or "/usr/bin/chromium", shutil.which("chromedriver")
    if not Path(chromium).exists() or driver_path is None:
        pytest.skip("headless Chromium not installed (tests/test_report_browser.py insists on it)")
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    cells = "".join(f"<td>column_{k}_with_a_long_unbreakable_value</td>" for k in range(30))
    html = (
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><style>{_css()}</style></head><body><main>"
        f"<p>Text column.</p><div class='wide'><table class='comparisons'><tr>{cells}</tr></table></div>"
        "</main></body></html>"
    )
    (tmp_path / "wide.html").write_text(html, encoding="utf-8")
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for flag in ("--headless", "--no-sandbox", "--disable-gpu", "--window-size=1280,900"):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service(driver_path), options=options)
    try:
        driver.get((tmp_path / "wide.html").as_uri())
        main, box, table, scrolls = driver.execute_script(
            "const m = document.querySelector('main').getBoundingClientRect();"
            "const w = document.querySelector('.wide'); const b = w.getBoundingClientRect();"
            "const t = w.querySelector('table').getBoundingClientRect();"
            "return [[m.left, m.right], [b.left, b.right], [t.left, t.right], w.scrollWidth > w.clientWidth];"
        )
    finally:
        driver.quit()
    assert table[1] - table[0] > main[1] - main[0]  # the table really is wider than the column
    assert main[0] - 0.5 <= box[0] and box[1] <= main[1] + 0.5  # its box is not
    assert scrolls


# ---------------------------------------------------------------- figures


def _legend_covers(ax, legend) -> list[str]:  # type: ignore[no-untyped-def]
    """Labels of the lines of ``ax`` with a data point inside ``legend``'s box (both in display units)."""
    ax.figure.canvas.draw()
    box = legend.get_window_extent()
    covered = []
    for line in ax.get_lines():
        xy = np.column_stack([line.get_xdata(), line.get_ydata()]).astype(float)
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        points = ax.transData.transform(xy)
        inside = (box.x0 < points[:, 0]) & (points[:, 0] < box.x1) & (box.y0 < points[:, 1]) & (points[:, 1] < box.y1)
        if inside.any():
            covered.append(line.get_label())
    return covered


def test_sensitivity_legend_leaves_the_best_fit_star_visible_and_axes_name_their_quantity(run) -> None:
    from stickslip.report.sensitivity_section import sensitivity_figure

    figure = sensitivity_figure(run)
    region, spread = figure.figure.axes
    legend = region.get_legend()
    assert [t.get_text() for t in legend.get_texts()] == ["95 % boundary", "best fit"]
    assert _legend_covers(region, legend) == []  # neither the star nor the boundary
    labels = [ax.get_xlabel() for ax in (region, spread)] + [ax.get_ylabel() for ax in (region, spread)]
    assert not [label for label in labels if "#" in label], labels
    assert spread.get_xlabel() == "quasi-static prediction"


def _symlog(y: np.ndarray, linthresh: float = 1e6, linscale: float = 0.4) -> np.ndarray:
    """matplotlib's symlog, written out (base 10): linear inside ±linthresh, logarithmic outside."""
    y = np.asarray(y, dtype=float)
    scale = linscale / (1 - 1 / 10)
    inner = y * scale / linthresh
    outer = np.sign(y) * (scale + np.log10(np.maximum(np.abs(y), linthresh) / linthresh))
    return np.where(np.abs(y) <= linthresh, inner, outer)


def test_hopf_legends_name_each_visible_line_once(run) -> None:
    """Lines that coincide (closer than 1 % of the axis' height everywhere, measured here with symlog written out)
    get one legend entry; each legend entry is one visible line; every curve is still in the CSVs."""
    from stickslip.report.inertia_section import inertia_figure

    figure = inertia_figure(run)
    for ax in figure.figure.axes:
        curves = [line for line in ax.get_lines() if np.size(line.get_xdata()) > 1 and line.get_gid()]
        assert len(curves) == 4  # the four blocks, each drawn
        shown = [_symlog(line.get_ydata()) for line in curves]
        span = np.ptp(np.concatenate(shown))
        groups: list[list[int]] = []
        for k, y in enumerate(shown):
            home = next((g for g in groups if np.max(np.abs(shown[g[0]] - y)) < 0.01 * span), None)
            groups.append([k]) if home is None else home.append(k)
        entries = [t.get_text() for t in ax.get_legend().get_texts()]
        assert len(entries) == len(groups), (entries, groups)
        for group in groups:  # one entry per group, naming every block in it
            entry = next(e for e in entries if curves[group[0]].get_gid() in e)
            assert all(curves[k].get_gid() in entry for k in group)
        assert _legend_covers(ax, ax.get_legend()) == []
    top_entries = [t.get_text() for t in figure.figure.axes[0].get_legend().get_texts()]
    assert len(top_entries) == 1  # Im K: the four blocks lie on one line (the screenshot that filed issue 32)
    names = [c.name for c in extract_curves(figure.figure, figure.id)]
    assert len(names) == 12 and not [n for n in names if GENERIC.search(n) or "rho-h" in n]
    assert "G/(2cₛ)" in figure.caption and "rho h" not in figure.caption and "c_s" not in figure.caption


# ---------------------------------------------------------------- the page's order and citation


def test_the_paper_is_cited_as_the_preprint_it_is(page: str) -> None:
    header = _reader_text(page.split("</header>", 1)[0])
    assert "preprint" in header and "no journal, volume or year" in header
    assert "Phys. Rev. Lett. 88, 075509 (2002)" in header  # the data's paper, fully cited
    footer = _reader_text(page.split("<footer>", 1)[1])
    assert "preprint" in footer


def test_agreement_leads_and_limitations_follow_the_figures(page: str) -> None:
    lead = _reader_text(page.split('<p class="lead">', 1)[1].split("</p>", 1)[0])
    assert re.match(r"Of the \d+ distinct numbers the paper states, \d+ agree", lead)  # repeats counted once
    assert lead.index("agree") < lead.index("errors in the paper") < lead.index("inputs handed back")
    header = page.split("</header>", 1)[0]
    assert 'class="limitation"' not in header  # the first thing a reader sees is not a limitation
    first_figure = page.index('<section id="fig1-4_steady_curve"')
    limitations = page.index('<section id="limitations">')
    assert first_figure < limitations < page.index('<section id="comparisons">')
    assert page.index('class="limitation"') > limitations
    assert '<a href="#limitations">' in page.split("<main>", 1)[0]  # still reachable from the top


def test_curve_files_are_named_for_what_they_hold(page: str) -> None:
    csvs = re.findall(r'href="([^"]+)\.csv"', page)
    assert csvs and not [c for c in csvs if GENERIC.search(c)], [c for c in csvs if GENERIC.search(c)]
