"""The errata (``stickslip/report/errata.md``), rendered into the report so that its links work offline.

Entries are level-2 headings ``## E<n> title`` (errata of the paper) or
``## M<n> title`` (properties and limitations of the model, listed after the
errata under their own heading: not errors of the paper); each becomes an
element with ``id="e<n>"`` (``id="m<n>"``) so that the report can link
``#e<n>``.  The text is
package data, the one source of the errata (docs/errata.md only points to
it), so that an installed wheel renders it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from html import escape
from importlib import resources

from ..errors import DataError
from .markup import inline_html

_ENTRY = re.compile(r"^([EM]\d+)\b[\s.:—–-]*(.*)$")
#: The one piece of raw HTML the errata may use: an empty anchor, ``<a id="e1"></a>``.
_ANCHOR = re.compile(r'^\s*<a\s+(?:id|name)="([A-Za-z][\w.-]*)"\s*>\s*</a>\s*$')


@dataclass(frozen=True)
class ErrataEntry:
    id: str  # "E3" (an erratum of the paper) or "M1" (a property of the model)
    title: str

    @property
    def erratum(self) -> bool:
        """True for an error of the paper (E<n>), False for a property of the model (M<n>)."""
        return self.id.startswith("E")

    @property
    def anchor(self) -> str:
        return self.id.lower()


@dataclass(frozen=True)
class Errata:
    source: str
    entries: tuple[ErrataEntry, ...]
    html: str

    def get(self, entry_id: str) -> ErrataEntry | None:
        return next((e for e in self.entries if e.id == entry_id), None)


def errata_text() -> tuple[str, str]:
    """(markdown text, where it came from).  Raises DataError when the package data is missing."""
    packaged = resources.files("stickslip") / "report" / "errata.md"
    if not packaged.is_file():
        raise DataError("errata not found: expected package data stickslip/report/errata.md (reinstall stickslip)")
    return packaged.read_text(encoding="utf-8"), "stickslip/report/errata.md"


def render_errata(text: str, source: str = "errata.md") -> Errata:
    """Markdown to HTML with entry anchors, made safe for an offline page.

    markdown-it renders the Markdown; images are dropped (they would be
    fetched), raw HTML is shown as text, except empty anchors
    ``<a id="..."></a>``, which are kept unless the heading that follows
    already carries that id.
    """
    from markdown_it import MarkdownIt

    md = MarkdownIt("commonmark", {"html": True}).enable("table").disable("image")
    tokens = _without_title(md.parse(text))
    entries: list[ErrataEntry] = []
    for k, token in enumerate(tokens):
        if token.type != "heading_open" or token.tag != "h2":
            continue
        inline = tokens[k + 1]
        match = _ENTRY.match(inline.content.strip())
        if match:
            entry = ErrataEntry(match.group(1), match.group(2).strip())
            if any(e.id == entry.id for e in entries):
                raise DataError(f"{source}: errata entry {entry.id} appears twice")
            entries.append(entry)
            token.attrSet("id", entry.anchor)
    heading_ids = {e.anchor for e in entries}
    for token in tokens:
        # headings move one level down: the errata sit inside a section of the report
        if token.type in ("heading_open", "heading_close"):
            token.tag = f"h{min(int(token.tag[1]) + 1, 6)}"
        elif token.type == "html_block":
            _neutralise(token, heading_ids)
        elif token.type == "inline" and token.children:
            _neutralise_inline(token.children, heading_ids)
            _raise_superscripts(token.children)
    html = md.renderer.render(tokens, md.options, {}).replace("<p></p>\n", "")
    return Errata(source, tuple(entries), html)


def _without_title(tokens: list) -> list:
    """The tokens without the document's level-1 title: the report's section carries its own "Errata" heading,
    and the title, moved one level down, would be a second one."""
    if len(tokens) >= 3 and tokens[0].type == "heading_open" and tokens[0].tag == "h1":
        return tokens[3:]
    return tokens


def _neutralise(token: object, heading_ids: set[str]) -> None:
    """Raw HTML in the errata: keep an empty anchor (unless a heading has its id), show anything else as text."""
    content = token.content  # type: ignore[attr-defined]
    anchor = _ANCHOR.match(content)
    if anchor:
        name = anchor.group(1)
        token.content = "" if name in heading_ids else f'<a id="{name}"></a>\n'  # type: ignore[attr-defined]
    else:
        token.content = escape(content)  # type: ignore[attr-defined]


def _raise_superscripts(children: list) -> None:
    """``e^{−V/Va}`` in the errata's text (never in its code) as a superscript, not as raw TeX."""
    for child in children:
        if child.type == "text" and ("^" in child.content or "_{" in child.content):
            child.type = "html_inline"
            child.content = inline_html(child.content)


def _neutralise_inline(children: list, heading_ids: set[str]) -> None:
    """Inline raw HTML: an anchor arrives as two tokens, ``<a id="x">`` and ``</a>``."""
    k = 0
    while k < len(children):
        child = children[k]
        if child.type == "html_inline":
            after = children[k + 1] if k + 1 < len(children) else None
            if after is not None and after.type == "html_inline" and after.content.strip() == "</a>":
                child.content += after.content
                after.content = ""
                after.type = "text"
            _neutralise(child, heading_ids)
            child.content = child.content.rstrip("\n")
        k += 1


def load_errata() -> Errata:
    text, source = errata_text()
    return render_errata(text, source)
