"""The few marks the report's captions and errata may use, rendered as HTML: never shown raw in the page.

Captions are written as plain text with three marks, so that they read well in the source and in results:

* ```stickslip sweep``` (backticks): code, ``<code>stickslip sweep</code>``;
* ``e^{−V/Va}``, ``(t − t0)^{1/2}``, ``e^(1.77×10⁶)``, ``e^-10``: a superscript, ``e<sup>−V/Va</sup>``;
* ``Δl_{m}``: a subscript, ``Δl<sub>m</sub>`` (a bare underscore, as in ``stuck_threshold``, stays as it is).

Everything else is escaped.
"""

from __future__ import annotations

import re
from html import escape

#: Braces holding at most one level of braces: ^{Δl_{m}/V0}.
_BRACED = r"[^{}]*(?:\{[^{}]*\}[^{}]*)*"
#: `code`, ^{...}, ^(...), ^-10 / ^2, _{...}
_MARKS = re.compile(
    r"`(?P<code>[^`\n]+)`"
    rf"|\^\{{(?P<sup>{_BRACED})\}}"
    r"|\^\((?P<paren>[^()]*)\)"
    r"|\^(?P<bare>[−-]?[0-9]+)"
    rf"|_\{{(?P<sub>{_BRACED})\}}"
)


def inline_html(text: str) -> str:
    """``text`` escaped, with its code, superscript and subscript marks as HTML elements."""
    out: list[str] = []
    position = 0
    for match in _MARKS.finditer(text):
        out.append(escape(text[position : match.start()]))
        out.append(_element(match))
        position = match.end()
    out.append(escape(text[position:]))
    return "".join(out)


def _element(match: re.Match[str]) -> str:
    if match.group("code") is not None:
        return f"<code>{escape(match.group('code'))}</code>"
    if match.group("sub") is not None:
        return f"<sub>{inline_html(match.group('sub'))}</sub>"
    raised = next(match.group(g) for g in ("sup", "paren", "bare") if match.group(g) is not None)
    return f"<sup>{inline_html(raised.replace('-', '−') if match.group('bare') else raised)}</sup>"


#: Raw markup a reader must never see in the page's text (outside code): TeX's ^{ _{ \\cmd and $, Markdown's
#: backticks and **bold**.
RAW_MARKUP = re.compile(r"\^\{|_\{|`|\$|\*\*|\\[a-zA-Z]+")
