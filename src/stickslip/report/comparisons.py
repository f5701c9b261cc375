"""The comparison table: each number the paper states beside the value computed here, and what the difference is.

relative_difference = (computed - paper) / |paper| (None where the units differ).  Every row is put in one class
of :data:`CLASSES` (input, agrees within :data:`TOLERANCE`, within the scatter the paper states or shows, then paper
error or the paper's unstated or inconsistent inputs, outside the measured range, an open difference, or model
limitation, decided in that order: docs/report.md, "Classes, and the headline") and carries its reason in words
(:func:`class_reason`).  Table 1's Vs cells, the paper's own computation from their column, are classed by one
rule, :data:`stickslip.report.paper.JUMP_VELOCITY_RULE`: a cell the model gives only at the σs its column's other
cells give is the column disagreeing with itself (a paper error), never the model's difference.  A row that states
again what another row states (the paper printing one number in two places) is shown and marked, and counted once:
:func:`count_classes` counts distinct statements only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .paper import PAPER_NUMBERS, TOLERANCE, PaperNumber

__all__ = [
    "CLASSES",
    "MODEL_DIFFERENCES",
    "TOLERANCE",
    "Comparison",
    "Computed",
    "class_reason",
    "classify",
    "compare",
    "count_classes",
    "outside_by",
    "summary_counts",
]

#: Class -> how the report names it, in the order the headline counts them.
CLASSES = {
    "input": "input (echo)",
    "agrees": f"agrees (≤ {100 * TOLERANCE:g} %)",
    "scatter": "within the paper's scatter",
    "outside": "outside the measured range",
    "erratum": "paper error (erratum)",
    "unstated": "paper: stated inputs do not give it",
    "open": "open difference",
    "limitation": "model limitation",
}
#: The classes that are the model's differences from the paper, never the paper's error (the headline counts them
#: apart): a measurement outside the range of the cycles the paper measured, and an open difference.
MODEL_DIFFERENCES = ("outside", "open")


@dataclass(frozen=True)
class Computed:
    """The model's counterpart of one paper number, and how it was obtained.

    ``echo`` marks a value that is the paper's own input handed back (not a
    prediction).  ``alternative`` is a second value shown beside it, e.g. the
    model with the nominal stiffness where ``value`` uses the stiffness
    measured in that Table 1 column; it is shown, not classified.
    ``reproduced_by`` names, with its value, an input the paper does not
    state that gives the paper's number (rows whose stated inputs do not).
    """

    value: float | None
    how: str
    echo: bool = False
    alternative: float | None = None
    alternative_label: str = ""
    reproduced_by: str = ""


def classify(number: PaperNumber, computed: float | None, echo: bool) -> str:
    """The class of one row (see the module docstring)."""
    difference = relative_difference(number, computed)
    close = difference is not None and abs(difference) <= TOLERANCE
    if echo:
        return "input" if close else "erratum"
    if number.units_differ:
        return "erratum"
    if close:
        return "agrees"
    if computed is not None and number.scatter is not None:
        low, high = number.scatter
        if low <= computed <= high:
            return "scatter"
        if number.explanation not in ("erratum", "unstated"):
            return "outside"
    return number.explanation


def class_reason(number: PaperNumber, computed: float | None, echo: bool) -> str:
    """Why the row is in its class, in words."""
    cls = classify(number, computed, echo)
    if cls == "input":
        return "the paper's own input (or arithmetic on its numbers) handed back: not a prediction"
    if cls == "agrees":
        return f"within {100 * TOLERANCE:g} %"
    if cls in ("scatter", "outside"):
        low, high = number.scatter or (math.nan, math.nan)
        band = f"{number.scatter_source} ({low:.4g} to {high:.4g} {number.unit})"
        if cls == "scatter":
            return f"inside {band}"
        beyond = outside_by(number, computed) or 0.0
        side = f"{100 * abs(beyond):.2f} % {'above its highest' if beyond > 0 else 'below its lowest'} value"
        return (
            f"outside {band}: {side}; the model's difference from the measurements, not the paper's error and not"
            " within the scatter the paper shows"
        )
    if number.units_differ:
        return "the paper prints the number with a wrong unit"
    if number.contradiction:
        return "the paper contradicts itself: " + number.contradiction
    if echo:
        return "the paper's arithmetic on its own numbers does not give its printed value"
    if cls == "unstated":
        return number.unstated
    if cls == "open":
        return number.open_reason
    return "the model cannot give this number with any input; the linked entry says why"


def outside_by(number: PaperNumber, computed: float | None) -> float | None:
    """How far ``computed`` lies outside the row's scatter band, relative to the edge it passes: positive above the
    highest value, negative below the lowest; 0 inside; None without a band or a value."""
    if computed is None or number.scatter is None:
        return None
    low, high = number.scatter
    if computed > high:
        return (computed - high) / abs(high)
    if computed < low:
        return (computed - low) / abs(low)
    return 0.0


def relative_difference(number: PaperNumber, computed: float | None) -> float | None:
    if computed is None or number.units_differ:
        return None
    return (computed - number.paper) / abs(number.paper)


@dataclass(frozen=True)
class Comparison:
    number: PaperNumber
    computed: float | None
    how: str
    errata: str | None
    echo: bool = False
    alternative: float | None = None
    alternative_label: str = ""
    reproduced_by: str = ""

    @property
    def relative_difference(self) -> float | None:
        return relative_difference(self.number, self.computed)

    @property
    def alternative_difference(self) -> float | None:
        return relative_difference(self.number, self.alternative)

    @property
    def classification(self) -> str:
        return classify(self.number, self.computed, self.echo)

    @property
    def reason(self) -> str:
        reason = class_reason(self.number, self.computed, self.echo)
        if self.classification == "unstated" and self.reproduced_by:
            reason += f"; {self.reproduced_by}"
        return reason

    @property
    def counted(self) -> bool:
        """False for a row that states again what another row states (counted there)."""
        return not self.number.repeat_of

    @property
    def flagged(self) -> bool:
        """True when the row is neither an echoed input nor an agreement within the tolerance."""
        return self.classification not in ("input", "agrees")

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
            "class": self.classification,
            "class_reason": self.reason,
            "how": self.how,
            "counted": self.counted,
        }
        if n.repeat_of:
            out["repeat_of"] = list(n.repeat_of)
            out["repeat_note"] = n.repeat_note
        if self.reproduced_by:
            out["reproduced_by"] = self.reproduced_by
        if n.units_differ:
            out["difference"] = "units differ"
        if n.scatter is not None:
            out["scatter"] = list(n.scatter)
        if self.alternative is not None:
            out["alternative"] = {
                "value": self.alternative,
                "label": self.alternative_label,
                "relative_difference": self.alternative_difference,
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
        value = _finite(c.value)
        rows.append(
            Comparison(
                n, value, c.how, errata.get(n.key), c.echo, _finite(c.alternative), c.alternative_label,
                c.reproduced_by,
            )
        )  # fmt: skip
    return rows


def count_classes(rows: list[Comparison] | tuple[Comparison, ...]) -> dict[str, int]:
    """Distinct statements of the paper per class, every class present (0 when none): a row that repeats another
    (``Comparison.counted`` False) is counted once, in the row it repeats."""
    counts = dict.fromkeys(CLASSES, 0)
    for row in rows:
        if row.counted:
            counts[row.classification] += 1
    return counts


def summary_counts(rows: list[Comparison] | tuple[Comparison, ...]) -> dict[str, Any]:
    """The headline's numbers: distinct statements (by class), rows shown and repeats among them."""
    counted = [r for r in rows if r.counted]
    flagged = [r for r in counted if r.flagged]
    return {
        "compared": len(counted),
        "rows": len(rows),
        "repeats": len(rows) - len(counted),
        "by_class": count_classes(rows),
        "flagged": len(flagged),
        "flagged_with_errata": sum(r.errata is not None for r in flagged),
    }


def _finite(value: float | None) -> float | None:
    return value if value is None or math.isfinite(value) else None
