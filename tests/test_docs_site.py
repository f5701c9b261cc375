"""The documentation site's configuration and build hook (fast checks; the whole build is scripts/build-docs.sh).

The site is built in CI (``.ci/run`` -> scripts/build-docs.sh -> ``mkdocs build --strict`` and a headless-Chromium
check).  Here: the navigation lists every page exactly once, and the hook's link rewriting and TeX-to-MathML
conversion do what the site relies on (those tests need the ``docs`` extra and are skipped without it).
"""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pytest

yaml = pytest.importorskip("yaml")

ROOT = Path(__file__).resolve().parents[1]
HOOKS = ROOT / "scripts" / "mkdocs_hooks.py"
#: pages the hook makes at build time (no file in docs/)
GENERATED_PAGES = {"index.md", "changelog.md", "paper-errata.md", "report-figures.md"}


def _nav_pages(entries: object) -> list[str]:
    if isinstance(entries, str):
        return [entries]
    if isinstance(entries, list):
        return [page for entry in entries for page in _nav_pages(entry)]
    if isinstance(entries, dict):
        return [page for value in entries.values() for page in _nav_pages(value)]
    raise AssertionError(f"unexpected nav entry {entries!r}")


def _config() -> dict:
    return yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))


def test_the_navigation_lists_every_docs_page_once_and_nothing_else():
    pages = _nav_pages(_config()["nav"])
    assert len(pages) == len(set(pages)), f"listed twice: {sorted(p for p in pages if pages.count(p) > 1)}"
    on_disk = {p.name for p in (ROOT / "docs").glob("*.md")}
    assert on_disk - set(pages) == set(), "docs pages missing from mkdocs.yml's nav"
    assert set(pages) - on_disk - GENERATED_PAGES == set(), "nav entries with no page"
    assert GENERATED_PAGES <= set(pages)


def test_the_build_fails_on_warnings_and_the_hook_is_the_checked_one():
    config = _config()
    assert config["strict"] is True
    assert config["docs_dir"] == "docs"
    assert config["hooks"] == ["scripts/mkdocs_hooks.py"]
    jupyter = next(p["mkdocs-jupyter"] for p in config["plugins"] if isinstance(p, dict) and "mkdocs-jupyter" in p)
    assert jupyter["execute"] is False, "notebooks run once, in scripts/run-notebooks.py, not again in the build"


@pytest.fixture(scope="module")
def hooks():
    pytest.importorskip("mkdocs")
    spec = importlib.util.spec_from_file_location("stickslip_mkdocs_hooks", HOOKS)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class _Files:
    def __init__(self, present: set[str]):
        self.present = present

    def get_file_from_path(self, path: str) -> object | None:
        return object() if path in self.present else None


@pytest.mark.parametrize(
    ("target", "source", "expected"),
    [
        ("docs/transient.md", "README.md", "transient.md"),  # the README's links to the docs pages
        ("docs/fitting.md#intervals", "README.md", "fitting.md#intervals"),
        ("CHANGELOG.md", "README.md", "changelog.md"),
        ("LICENSE", "README.md", "LICENSE.txt"),
        ("src/stickslip/report/errata.md", "README.md", "paper-errata.md"),
        ("../README.md", "docs/models.md", "index.md"),  # a page's link to the README
        ("../src/stickslip/report/errata.md#e3", "docs/errata.md", "paper-errata.md#e3"),
        ("report.md#errata", "docs/errata.md", "report.md#errata"),
        ("../examples/01-x.ipynb", "docs/models.md", "examples/01-x.ipynb"),
        ("examples/README.md", "README.md", "examples/index.md"),  # the notebooks' own README is a site page
        ("01-x.ipynb", "examples/README.md", "01-x.ipynb"),  # ... whose links lead to the notebooks beside it
        ("https://distributed.dask.org", "README.md", "https://distributed.dask.org"),  # left alone
        ("#section", "docs/rsf.md", "#section"),
        ("../tests/test_docs.py", "docs/rsf.md", "../tests/test_docs.py"),  # not in the site: mkdocs reports it
    ],
)
def test_links_written_for_github_lead_to_the_site_pages(hooks, target, source, expected):
    site_page = hooks.GENERATED.get(source) or source.removeprefix("docs/")
    assert hooks._site_link(target, source, site_page, _Files({"examples/01-x.ipynb"})) == expected


def test_tex_becomes_mathml_with_its_structure(hooks):
    pytest.importorskip("latex2mathml")
    html = (
        '<p>x <span class="arithmatex">\\(t_a\\)</span></p>'
        '<div class="arithmatex">\\[\\sigma_s = \\frac{G_d}{h}V_0 t_s + \\sigma_c \\qquad (16)\\]</div>'
    )
    out = hooks.on_page_content(html, None, None, None)
    assert "arithmatex" not in out and "\\frac" not in out and "\\(" not in out
    inline, block = re.findall(r"<math[^>]*>.*?</math>", out)
    assert 'display="inline"' in inline and "<msub><mi>t</mi><mi>a</mi></msub>" in inline
    # the fraction G_d / h as a MathML fraction: numerator G with subscript d, denominator h
    assert 'display="block"' in block
    assert re.search(r"<mfrac><mrow><msub><mi>G</mi><mi>d</mi></msub></mrow><mrow><mi>h</mi></mrow></mfrac>", block)


def test_sphinx_roles_in_docstrings_render_as_plain_code(hooks):
    out = hooks.on_page_content("returns its :class:<code>Run</code>.", None, None, None)
    assert out == "returns its <code>Run</code>."


def test_the_equations_page_numbers_eqs_1_to_17_once_each():
    # the equations page carries the paper's Eqs 1-17 (checked against the paper's TeX when written: see
    # docs/documentation.md); here only that none went missing or doubled in an edit
    text = (ROOT / "docs" / "equations.md").read_text(encoding="utf-8")
    numbers = [int(n) for n in re.findall(r"\\qquad \((\d+)\)\s*\$\$", text)]
    assert sorted(numbers) == list(range(1, 18))


def test_notebook_markdown_math_becomes_mathml_and_code_and_prices_stay(hooks):
    pytest.importorskip("latex2mathml")
    cell = (
        '<div class="jp-RenderedHTMLCommon jp-RenderedMarkdown jp-MarkdownOutput" data-mime-type="text/markdown">'
        "<p>At $V_c$ the slope is zero: $$\\frac{d\\sigma}{dV} = 0$$ "
        "(<code>echo $HOME $PATH</code>; it costs $5 and $6).</p></div>"
        '<div class="jp-OutputArea-output"><pre>$x$ printed by a cell</pre></div>'
    )
    out = hooks.on_page_content(cell, None, None, None)
    inline, block = re.findall(r"<math[^>]*>.*?</math>", out)
    assert "<msub><mi>V</mi><mi>c</mi></msub>" in inline and 'display="inline"' in inline
    assert "<mfrac>" in block and 'display="block"' in block
    assert "<code>echo $HOME $PATH</code>" in out and "costs $5 and $6" in out
    assert "<pre>$x$ printed by a cell</pre>" in out  # outputs are not Markdown


def test_the_pages_the_hook_makes_are_the_ones_the_navigation_expects(hooks):
    made = {page for page in hooks.GENERATED.values() if page.endswith(".md")} | {hooks.REPORT_PAGE}
    assert made == GENERATED_PAGES | {"examples/index.md"}  # the last listed by the hook, with the notebooks
    for source in hooks.GENERATED:
        assert (ROOT / source).is_file(), f"{source}: the hook makes a site page from it, but it is gone"
