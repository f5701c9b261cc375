"""The comparison table: each number the paper states beside the value computed here.

relative_difference = (computed - paper) / |paper|.  Where it exceeds
:data:`TOLERANCE` the row names the erratum (docs/errata.md) that explains
the difference.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .paper import PAPER_NUMBERS, PaperNumber

#: Relative difference above which a row must be explained by an erratum.
TOLERANCE = 0.02


@dataclass(frozen=True)
class Computed:
    """The model's counterpart of one paper number, and how it was obtained."""

    value: float | None
    how: str


@dataclass(frozen=True)
class Comparison:
    number: PaperNumber
    computed: float | None
    how: str
    errata: str | None

    @property
    def relative_difference(self) -> float | None:
        if self.computed is None:
            return None
        return (self.computed - self.number.paper) / abs(self.number.paper)

    @property
    def flagged(self) -> bool:
        """True when the computed value differs from the paper's by more than the tolerance."""
        rd = self.relative_difference
        return rd is None or abs(rd) > TOLERANCE

    def as_dict(self) -> dict[str, Any]:
        n = self.number
        out: dict[str, Any] = {
            "key": n.key,
            "quantity": n.quantity,
            "group": n.group,
            "kind": n.kind,
            "paper": n.paper,
            "paper_unit": n.paper_unit if n.paper_unit is not None else n.unit,
            "printed": n.printed,
            "source": n.source,
            "computed": self.computed,
            "unit": n.unit,
            "relative_difference": self.relative_difference,
            "how": self.how,
        }
        if n.note:
            out["note"] = n.note
        if self.errata is not None:
            out["errata"] = self.errata
        return out


def compare(computed: dict[str, Computed], errata: dict[str, str]) -> list[Comparison]:
    """One row per paper number, in the paper's order; every number must have a computed counterpart."""
    missing = [n.key for n in PAPER_NUMBERS if n.key not in computed]
    if missing:
        raise KeyError(f"no computed value for: {', '.join(missing)}")
    rows = []
    for n in PAPER_NUMBERS:
        c = computed[n.key]
        value = c.value if c.value is None or math.isfinite(c.value) else None
        rows.append(Comparison(n, value, c.how, errata.get(n.key)))
    return rows
