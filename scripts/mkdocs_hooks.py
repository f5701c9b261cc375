"""MkDocs hooks of the documentation site (mkdocs.yml ``hooks:``; built by scripts/build-docs.sh).

Every page has one source in the repository; nothing here is committed twice.  At build time this hook

* makes the home page from README.md, the changelog page from CHANGELOG.md and the errata page from
  src/stickslip/report/errata.md, and ships LICENSE and CITATION.cff as plain files;
* adds the executed example notebooks (``STICKSLIP_DOCS_NOTEBOOKS``: the folder scripts/run-notebooks.py wrote;
  unset, the unexecuted ``examples/*.ipynb``) under ``examples/`` and to the navigation;
* adds the report's figures (``STICKSLIP_DOCS_REPORT``: a folder written by ``stickslip reproduce``) as the page
  ``report-figures.md``, and the self-contained report.html beside it;
* rewrites links written for GitHub (``docs/transient.md`` in the README, ``../README.md`` in a page) to the
  site's pages, so the same Markdown works in both places;
* turns TeX (``$...$``, ``$$...$$``, marked by pymdownx.arithmatex) into MathML at build time: the site needs
  no MathJax and no network, and browsers render MathML natively.
"""

from __future__ import annotations

import html
import os
import posixpath
import re
from pathlib import Path
from typing import Any

from mkdocs.plugins import event_priority
from mkdocs.structure.files import File, Files

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOKS_ENV = "STICKSLIP_DOCS_NOTEBOOKS"
REPORT_ENV = "STICKSLIP_DOCS_REPORT"

#: repository files outside docs/ that become site files: repository path -> site path
GENERATED = {
    "README.md": "index.md",
    "CHANGELOG.md": "changelog.md",
    "src/stickslip/report/errata.md": "paper-errata.md",
    "LICENSE": "LICENSE.txt",
    "CITATION.cff": "CITATION.cff",
    "examples/README.md": "examples/index.md",
}
REPORT_PAGE = "report-figures.md"
LINK = re.compile(r"(\]\()([^)\s]+)(\))")
ERRATUM_HEADING = re.compile(r"^(## (E\d+)\b.*)$", re.MULTILINE)
NOT_A_LINK = re.compile(r"\]\(([^)\n]*\s[^)\n]*)\)")
API_FUNCTION = re.compile(r"^<!-- api-function: (stickslip(?:\.\w+)+) -->$", re.MULTILINE)
ROLE = re.compile(r":(?:class|func|meth|mod|data|attr|exc|obj):(<code>)")
LOCAL_LINK = re.compile(r'\b(href|src)="(?![a-z]+:|#|/)')
NOTEBOOK_MARKDOWN = re.compile(r'(<div class="jp-RenderedHTMLCommon jp-RenderedMarkdown[^>]*>)(.*?)(</div>)', re.DOTALL)
CODE = re.compile(r"(<code\b.*?</code>|<pre\b.*?</pre>)", re.DOTALL)
DOLLARS = re.compile(r"\$\$(.+?)\$\$|(?<![\\$\w])\$(?=\S)([^$\n]+?)(?<=\S)\$(?![\w$])", re.DOTALL)
FIGURE = re.compile(r"<figure\b.*?</figure>", re.DOTALL)
MATH = re.compile(r'<(span|div) class="arithmatex">(.*?)</\1>', re.DOTALL)


def _notebook_folder() -> Path:
    given = os.environ.get(NOTEBOOKS_ENV)
    folder = Path(given).resolve() if given else ROOT / "examples"
    if folder.name != "examples":  # the site's URLs are examples/NAME/, served from the folder's parent
        raise ValueError(f"{NOTEBOOKS_ENV}={given}: expected a folder named 'examples'")
    return folder


def _notebooks() -> list[Path]:
    return sorted(_notebook_folder().glob("*.ipynb"))


def on_config(config: Any) -> Any:
    """Lists the notebooks under "Examples" in the navigation (their names are known only at build time)."""
    pages = [f"examples/{path.name}" for path in _notebooks()]
    if pages and config.get("nav") is not None:
        config["nav"].append({"Examples": ["examples/index.md", *pages]})  # the folder's README, then each
    return config


@event_priority(100)  # before mkdocs-jupyter's on_files, which must see the notebooks to render them
def on_files(files: Files, config: Any) -> Files:
    for source, target in GENERATED.items():
        content = (ROOT / source).read_text(encoding="utf-8")
        if source == "src/stickslip/report/errata.md":
            content = ERRATUM_HEADING.sub(lambda m: f"{m.group(1)} {{#{m.group(2).lower()}}}", content)
            # "[ln(B/l)/((B/l)−1)](V0 − V)" is a product in prose, not a link
            content = NOT_A_LINK.sub(lambda m: "]&#40;" + m.group(1) + ")", content)
        files.append(File.generated(config, target, content=content))
    for path in _notebooks():
        # a File backed by a real folder (mkdocs-jupyter's wrapper loses a generated file's source path)
        files.append(
            File(f"examples/{path.name}", str(path.parent.parent), config["site_dir"], config["use_directory_urls"])
        )
    files.append(File.generated(config, REPORT_PAGE, content=_report_page(files, config)))
    return files


def _report_page(files: Files, config: Any) -> str:
    """The report's figures with their captions, taken from the report.html that ``stickslip reproduce`` wrote."""
    folder = os.environ.get(REPORT_ENV)
    head = "# The report's figures\n\n"
    if not folder:
        return head + (
            "This page is filled by `scripts/build-docs.sh`, which runs `stickslip reproduce` and shows its "
            "figures here. See [report.md](report.md) for what the report holds.\n"
        )
    report = Path(folder) / "report.html"
    text = report.read_text(encoding="utf-8")
    figures = FIGURE.findall(text)
    if not figures:
        raise ValueError(f"{report}: no <figure> found; is this a report written by stickslip reproduce?")
    for path in sorted(Path(folder).iterdir()):  # the report and the figures' PNG, SVG and CSV it links
        if path.is_file() and path.suffix in (".html", ".png", ".svg", ".csv", ".json"):
            files.append(File.generated(config, f"report/{path.name}", abs_src_path=str(path)))
    intro = (
        "The figures of the offline report that `stickslip reproduce` writes, as built with this site "
        f"({len(figures)} figures). The whole report, with the table of every number the paper states beside "
        "the computed value, is one self-contained file: [report.html](report/report.html). "
        "What each part means: [report.md](report.md).\n\n"
    )
    figures = [LOCAL_LINK.sub(r'\1="../report/', f) for f in figures]  # the page is report-figures/index.html
    return head + intro + "\n\n".join(f'<div class="stickslip-figure" markdown="0">\n{f}\n</div>' for f in figures)


def on_page_markdown(markdown: str, page: Any, config: Any, files: Files) -> str:
    """Links written for a GitHub checkout, rewritten to the site's pages; the API page's hand-placed functions."""
    markdown = API_FUNCTION.sub(lambda m: _function_reference(m.group(1)), markdown)
    source = _repository_path(page.file)
    if source is None:
        return markdown
    return LINK.sub(lambda m: m.group(1) + _site_link(m.group(2), source, page.file.src_uri, files) + m.group(3),
                    markdown)  # fmt: skip


def _function_reference(dotted: str) -> str:
    """Signature and docstring of a function mkdocstrings cannot reach by name.

    ``stickslip.models.run`` is both a function and a submodule (models/run.py, shadowed by the function on
    import); griffe, reading the source, finds the submodule.  Imported, the name is the function.
    """
    import inspect
    from importlib import import_module

    module, _, name = dotted.rpartition(".")
    function = getattr(import_module(module), name)
    if not callable(function):
        raise TypeError(f"{dotted}: expected a function, found {type(function).__name__}")
    try:
        signature = f"{name}{inspect.signature(function, eval_str=True)}"
    except NameError:  # an annotation names a type imported only for type checkers
        signature = f"{name}{inspect.signature(function)}"
    return f"```python\n{signature}\n```\n\n{inspect.getdoc(function) or ''}\n"


def _repository_path(file: File) -> str | None:
    for source, target in GENERATED.items():
        if file.src_uri == target:
            return source
    if file.src_uri.endswith(".md") and not file.generated_by:
        return f"docs/{file.src_uri}"
    return None


def _site_link(target: str, source: str, page_uri: str, files: Files) -> str:
    if re.match(r"[a-z][a-z0-9+.-]*:|#|/", target):
        return target
    path, _, anchor = target.partition("#")
    if not path:
        return target
    in_repository = posixpath.normpath(posixpath.join(posixpath.dirname(source), path))
    site = GENERATED.get(in_repository)
    if site is None and in_repository.startswith("docs/"):
        site = in_repository[len("docs/") :]
    if site is None and in_repository.startswith("examples/") and files.get_file_from_path(in_repository):
        site = in_repository
    if site is None:
        return target  # left as written: mkdocs --strict reports it if it does not resolve
    relative = posixpath.relpath(site, posixpath.dirname(page_uri) or ".")
    return relative + (f"#{anchor}" if anchor else "")


def on_page_content(html_text: str, page: Any, config: Any, files: Files) -> str:
    """TeX as MathML: marked by pymdownx.arithmatex (generic mode) in the pages, between dollars in the notebooks'
    Markdown cells; and the docstrings' Sphinx roles as plain code."""
    html_text = ROLE.sub(r"\1", html_text)
    html_text = NOTEBOOK_MARKDOWN.sub(lambda m: m.group(1) + _notebook_math(m.group(2)) + m.group(3), html_text)
    return MATH.sub(_arithmatex, html_text)


def _mathml(tex: str, block: bool) -> str:
    from latex2mathml.converter import convert

    tag = "div" if block else "span"
    return f'<{tag} class="math">{convert(html.unescape(tex).strip(), display="block" if block else "inline")}</{tag}>'


def _arithmatex(match: re.Match[str]) -> str:
    tex = html.unescape(match.group(2)).strip()
    for opening, closing in ((r"\[", r"\]"), (r"\(", r"\)")):
        if tex.startswith(opening) and tex.endswith(closing):
            tex = tex[len(opening) : -len(closing)]
    return _mathml(tex, match.group(1) == "div")


def _notebook_math(cell: str) -> str:
    # nbconvert leaves a Markdown cell's $...$ and $$...$$ for MathJax, which the offline site does not load
    parts = CODE.split(cell)  # odd parts are <code>/<pre> elements: a dollar there is code, not TeX
    for i in range(0, len(parts), 2):
        parts[i] = DOLLARS.sub(lambda m: _mathml(m.group(1) or m.group(2), m.group(1) is not None), parts[i])
    return "".join(parts)
