"""Every number Juvekar & Singh state, as printed, with where they state it.

Values are SI floats converted from the printed value *as printed*: where the
paper's unit is wrong (lambda M/kT in m^-2, G_d/h in Pa/m) the printed unit is
kept in ``paper_unit`` and the row links the erratum that explains it.
Nothing here is computed; :mod:`stickslip.report.comparisons` puts the
model's value beside each of these.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

#: Sliding velocities of the stick-slip experiments (Figs 5a-c), m/s.
PULLING_VELOCITIES = (50e-6, 100e-6, 350e-6)

#: The range of the steady-sliding data of Baumberger et al. (Fig 4), m/s.
DATA_RANGE = (140e-6, 2000e-6)


#: How a difference beyond tolerance and scatter is explained (see PaperNumber.explanation).
EXPLANATIONS = ("erratum", "unstated", "open", "limitation")


@dataclass(frozen=True)
class PaperNumber:
    """One number the paper states.

    ``kind`` is "model" for a number the paper computes from its model (the
    model here should reproduce it), "parameter" for a fitted or chosen
    parameter, "input" for a measured property of the experiment the model
    takes as given, and "measured" for an experimental value the model is
    compared with (Table 1).
    """

    key: str
    quantity: str
    group: str
    kind: str
    paper: float
    unit: str  # SI unit of the model value
    display: str  # unit the report shows (see stickslip.report.formatting.DISPLAY_UNITS)
    printed: str  # as printed in the paper
    source: str
    paper_unit: str | None = None  # SI unit of the paper value, set only where the printed unit is wrong
    note: str = ""  # context a reader needs beside the number
    scatter: tuple[float, float] | None = None  # SI band the paper states (or shows) for this measurement
    # the class of a difference beyond tolerance and scatter: "erratum" where the paper contradicts itself (with
    # ``contradiction``), "unstated" where the paper's stated inputs do not give its number and an input it does not
    # state would (with ``unstated``), "open" where the model and the paper differ and nothing in the paper settles
    # why (with ``open_reason``: the model's difference, never the paper's error), "limitation" where the model
    # cannot give the number with any input
    explanation: str = "limitation"
    contradiction: str = ""  # how the paper contradicts itself (required for explanation="erratum")
    unstated: str = ""  # which stated input fails and what would give the number (required for "unstated")
    # the row states again what the rows ``repeat_of`` state (the same number for the same quantity, said twice):
    # it is shown, marked, and counted once, there
    repeat_of: tuple[str, ...] = ()
    repeat_note: str = ""  # in words: where the paper says it again
    open_reason: str = ""  # how far apart the model and the paper are and why it is not settled (for "open")
    scatter_source: str = ""  # what the band ``scatter`` is, in words (the paper's stated band, or measured range)

    def __post_init__(self) -> None:
        if self.explanation not in EXPLANATIONS:
            expected = ", ".join(EXPLANATIONS)
            raise ValueError(f"{self.key}: explanation must be one of {expected}, not {self.explanation!r}")
        if self.explanation == "erratum" and not self.contradiction:
            raise ValueError(f"{self.key}: a paper error must say how the paper contradicts itself")
        if self.explanation == "unstated" and not self.unstated:
            raise ValueError(f"{self.key}: a number the stated inputs do not give must say which input would")
        if self.explanation == "open" and not self.open_reason:
            raise ValueError(f"{self.key}: an open difference must say how far apart and why it is not settled")
        if self.scatter is not None and not self.scatter_source:
            raise ValueError(f"{self.key}: a scatter band must say what it is (stated by the paper, or measured)")
        if self.repeat_of and not self.repeat_note:
            raise ValueError(f"{self.key}: a repeated statement must say where the paper states it first")

    @property
    def units_differ(self) -> bool:
        """The paper prints this number with a wrong unit (an erratum): no relative difference is meaningful."""
        return self.paper_unit is not None


def _n(
    key,
    quantity,
    group,
    kind,
    paper,
    unit,
    display,
    printed,
    source,
    paper_unit=None,
    note="",
    scatter=None,
    scatter_source="",
) -> PaperNumber:
    return PaperNumber(key, quantity, group, kind, paper, unit, display, printed, source, paper_unit, note, scatter,
                       scatter_source=scatter_source)  # fmt: skip


#: "259 ± 5 Pa": the band the paper states for sigma_c over all cycles (Section 3, Table 1).
CRITICAL_STRESS_BAND = (254.0, 264.0)
CRITICAL_STRESS_SOURCE = "the band the paper states for σc (259 ± 5 Pa)"
#: "0.4 kPa" read off the 350 um/s trace: one significant figure.
STEADY_350_BAND = (350.0, 450.0)
STEADY_350_SOURCE = "the precision the paper prints (“0.4 kPa”: one significant figure)"
#: The band of a measurement that Table 1 holds several cycles of: their range as printed, not widened.
MEASURED_RANGE_SOURCE = "the range of Table 1's cycles at this V0 that the paper calls the same, as printed"


STEADY = "Steady sliding (Figs 1 and 4, Eq 9)"
FIT = "Fitted slip-phase parameters (Section 3, Fig 4)"
BLOCK = "Block stiffness and geometry (Eqs 5, 17)"
STICK = "Stick phase (Eqs 15-16, Fig 6)"
SLIP = "Jump and slip phase (Eqs 8, 10, Fig 5d)"
#: The slip stresses the text quotes (V0 in µm/s, σs in Pa, where), and the jump velocity it reads off for each.
SLIP_STRESSES = ((50, 554.0, "Table 1, cycle 1"), (100, 549.0, "Table 1, cycles 2 and 4"))

TEXT_NUMBERS: tuple[PaperNumber, ...] = (
    _n("critical_velocity", "Critical velocity Vc", STEADY, "model", 125e-6, "m/s", "um/s", "125 µm.s⁻¹", "Section 3"),
    _n("critical_stress", "Critical stress σc", STEADY, "model", 259.0, "Pa", "Pa", "259 Pa", "Section 3"),
    _n(
        "critical_stress_cycles",
        "σc where sticking begins, all cycles (259 ± 5 Pa)",
        STEADY,
        "measured",
        259.0,
        "Pa",
        "Pa",
        "259 ± 5 Pa",
        "Section 3, from Table 1",
        scatter=CRITICAL_STRESS_BAND,
        scatter_source=CRITICAL_STRESS_SOURCE,
    ),
    _n(
        "steady_stress_350",
        "Steady stress at V0 = 350 µm/s",
        STEADY,
        "measured",
        400.0,
        "Pa",
        "Pa",
        "0.4 kPa",
        "Section 3 (Fig 5c)",
        scatter=STEADY_350_BAND,
        scatter_source=STEADY_350_SOURCE,
    ),
    _n("site_density", "Site density N0", FIT, "parameter", 1.22e14, "1/m^2", "1/m^2", "1.22 × 10¹⁴ m⁻²", "Section 3"),
    _n("bond_time", "Make-break time τ", FIT, "parameter", 224e-6, "s", "us", "224 µs", "Section 3"),
    _n(
        "stretch_sensitivity",
        "λM/kT",
        FIT,
        "parameter",
        2.47e12,
        "1/m",
        "1/m",
        "2.47 × 10¹² m⁻²",
        "Section 3",
        paper_unit="1/m^2",
    ),
    _n("max_extension", "Maximum chain extension Δlm", FIT, "parameter", 1.074e-6, "m", "um", "1.074 µm", "Section 3"),
    _n("breakage_weight", "Breakage weight u0 (fixed)", FIT, "parameter", 1.0, "", "", "unity", "Section 3"),
    _n("aging_time", "Aging time τa", FIT, "parameter", 899e-6, "s", "us", "899 µs", "Section 3"),
    _n("aging_velocity", "Aging velocity Va", FIT, "parameter", 360e-6, "m/s", "um/s", "360 µm.s⁻¹", "Section 3"),
    _n("shear_modulus", "Shear modulus Gd", BLOCK, "input", 4e3, "Pa", "kPa", "4 kPa", "Section 3"),
    _n("height", "Block height h", BLOCK, "input", 10e-3, "m", "mm", "10 mm", "Section 3"),
    _n(
        "stiffness_printed",
        "Stiffness Gd/h, as printed in Section 3",
        BLOCK,
        "model",
        400.0,
        "Pa/m",
        "kPa/m",
        "400 Pa.m⁻¹",
        "Section 3",
        paper_unit="Pa/m",  # printed Pa/m where 4 kPa / 10 mm is 400 kPa/m (E2)
    ),
    _n(
        "stiffness",
        "Stiffness Gd/h, as printed in the Table 1 discussion",
        BLOCK,
        "model",
        400e3,
        "Pa/m",
        "kPa/m",
        "400 kPa.m⁻¹",
        "Section 3, after Table 1",
    ),
    _n(
        "stiffness_against_table1",
        "Gd/h = 400 kPa/m, “compares well” with Table 1's Gd/h (their mean)",
        BLOCK,
        "input",
        400e3,
        "Pa/m",
        "kPa/m",
        "400 kPa.m⁻¹",
        "Section 3, after Table 1",
        note="the one place where the nominal stiffness is compared with the measured slopes (E14)",
    ),
    _n("top_length", "Trapezoid length on the puller side B", BLOCK, "input", 50e-3, "m", "mm", "50 mm", "Eq 17"),
    _n("base_length", "Trapezoid length on the glass l", BLOCK, "input", 30e-3, "m", "mm", "30 mm", "Eq 17"),
    _n("geometric_factor", "Geometric factor ln(B/l)/(B/l − 1)", BLOCK, "model", 0.766, "", "", "0.766", "Eq 17"),
    _n(
        "attached_chains",
        "Attached chains Nc0",
        STICK,
        "parameter",
        2.07e12,
        "1/m^2",
        "1/m^2",
        "2.07 × 10¹²",
        "Section 3",
    ),
    _n(
        "break_rate",
        "Chain breakage rate uc/τ",
        STICK,
        "parameter",
        1.4e-4,
        "1/s",
        "1/s",
        "1.4 × 10⁻⁴ s⁻¹",
        "Section 3",
    ),
    _n("stick_aging_time", "Stick aging time τa (Eq 15)", STICK, "parameter", 10.0, "s", "s", "10 s", "Section 3"),
    *(
        _n(
            f"stick_time_{v0}",
            f"Stick time ts, V0 = {v0} µm/s (paper's simulation)",
            STICK,
            "model",
            ts,
            "s",
            "s",
            printed,
            "Section 3, Fig 6",
        )
        for v0, ts, printed in ((50, 18.3, "18.3 s"), (100, 9.3, "9.3 s (printed “for V0 = 50 µm.s⁻¹”)"))
    ),
    *(
        _n(
            f"stick_time_{kind}_{v0}",
            f"Stick time ts, V0 = {v0} µm/s (measured, {where} discussion)",
            STICK,
            "measured",
            ts,
            "s",
            "s",
            f"{ts:g} s",
            source,
        )
        for kind, where, source, times in (
            ("measured", "Fig 6", "Section 3, Fig 6", (18.1, 8.8)),
            ("table", "Table 1", "Section 3, after Table 1", (18.9, 8.6)),
        )
        for v0, ts in zip((50, 100), times, strict=True)
    ),
    *(
        _n(
            f"slip_stress_{v0}",
            f"Slip stress σs, V0 = {v0} µm/s (Eq 16)",
            STICK,
            "measured",
            stress,
            "Pa",
            "Pa",
            f"{stress:g} Pa",
            source,
        )
        for v0, stress, source in SLIP_STRESSES
    ),
    *(
        _n(
            f"jump_velocity_{v0}",
            f"Jump velocity Vs for σs = {stress:g} Pa, V0 = {v0} µm/s (Eq 8)",
            SLIP,
            "model",
            702e-6,
            "m/s",
            "um/s",
            "702 µm.s⁻¹",
            source,
        )
        for v0, stress, source in SLIP_STRESSES
    ),
    *(
        _n(
            f"slip_asymptote_{v0}",
            f"Slip-phase asymptote, V0 = {v0} µm/s",
            SLIP,
            "model",
            v,
            "m/s",
            "um/s",
            printed,
            "Section 3, Fig 5d",
        )
        for v0, v, printed in ((50, 125e-6, "125 µm.s⁻¹"), (100, 125e-6, "125 µm.s⁻¹"), (350, 350e-6, "350 µm.s⁻¹"))
    ),
)


TABLE1 = "Table 1: stick-slip cycles of Baumberger et al. (measured)"

#: Table 1 columns: (pulling velocity in m/s, cycle number).
TABLE1_COLUMNS: tuple[tuple[float, int], ...] = (
    (50e-6, 1),
    (50e-6, 2),
    (50e-6, 3),
    (100e-6, 1),
    (100e-6, 2),
    (100e-6, 3),
    (100e-6, 4),
    (350e-6, 1),
)

#: Columns whose stick started from rest (the start-up stick of a run): 100 um/s cycle 1 (sigma_s - slope t_s =
#: 658 - 35 x 18.2 = 21 Pa) and the one 350 um/s cycle (above Vc, Table 1 gives no sigma_c).  The model starts
#: these sticks at zero stress; every other stick starts at the model's sigma_c.
TABLE1_FROM_REST = frozenset({(100e-6, 1), (350e-6, 1)})
#: The column the paper sets apart (extra aging before shearing began); it is left out of the scatter bands.
TABLE1_SET_APART = frozenset({(100e-6, 1)})

#: Context for Table 1 columns that the model is not meant to reproduce cycle by cycle.
TABLE1_NOTES = {
    (100e-6, 1): "first cycle, a stick from rest (σs − slope·ts = 21 Pa); the paper puts its higher σs down to"
    " extra aging before shearing began, by an amount it does not state",
    (350e-6, 1): "above Vc: one start-up stick from rest, then steady sliding; the column contradicts itself (E13)",
}

#: Table 1 rows: key, label, SI unit, display unit, values as printed (None for "--"), SI value of one printed unit.
TABLE1_ROWS: tuple[tuple[str, str, str, str, tuple[str | None, ...], float], ...] = (
    ("critical_stress", "σc", "Pa", "Pa", ("255", "262", "264", "261", "261", "261", "254", None), 1.0),
    (
        "stick_slope",
        "dσ/dt in the stick phase",
        "Pa/s",
        "Pa/s",
        ("16.5", "16.3", "16.8", "35.0", "33.5", "34.0", "34.0", "116"),
        1.0,
    ),
    (
        "stiffness",
        "Gd/h from the stick slope",
        "Pa/m",
        "kPa/m",
        ("431", "424", "437", "457", "437", "444", "444", "457"),
        1e3,
    ),
    ("slip_stress", "σs", "Pa", "Pa", ("554", "556", "552", "658", "549", "542", "549", "800"), 1.0),
    ("stick_time", "ts", "s", "s", ("18.3", "18.3", "17.8", "18.2", "8.82", "8.61", "8.83", "7.51"), 1.0),
    ("jump_velocity", "Vs", "m/s", "um/s", ("702", "702", "720", "1026", "702", "702", "702", "760"), 1e-6),
)

#: What each Table 1 row is: measured on the stress records, or computed by the paper (Gd/h from the slope by
#: Eq 17, Vs read off its steady curve by Eq 8).
TABLE1_KINDS = {
    "critical_stress": "measured",
    "stick_slope": "measured",
    "stiffness": "model",
    "slip_stress": "measured",
    "stick_time": "measured",
    "jump_velocity": "model",
}

#: Relative difference up to which a computed value agrees with the paper's (the scatter bands are not widened by it).
TOLERANCE = 0.02

#: Rows where a difference beyond tolerance and scatter is an error in the paper: there the paper contradicts itself
#: (its own numbers, not the model, show it), and the text says how.  A difference between the model and a
#: measurement is never the paper's error by its size alone, and one contradiction is one error: where several cells
#: take part and which is wrong cannot be told, it is counted once, in the cell the paper computed from the others
#: (the others are compared with the model like any number).  Wrong printed units and echoes that do not match are
#: errors by rule (comparisons.classify).  Table 1's Vs cells are added below, by JUMP_VELOCITY_RULE.
PAPER_CONTRADICTIONS = {
    "stick_time_table_50": "the text's 18.9 s contradicts Table 1's own 18.3, 18.3 and 17.8 s at 50 µm/s (E9)",
    "table1_stiffness_350_1": "457 kPa/m is not the column's own slope 116 Pa/s over 0.766 V0 (432.7 kPa/m), the"
    " rule every other column follows; it is the 100 µm/s cycle 1 value (E14)",
}

#: Rows where the model and the paper differ beyond tolerance and scatter and nothing in the paper settles why: not
#: the paper's error (its own numbers do not show it), not an input it leaves unstated that the row could name; the
#: model's open difference, with the numbers that bound it.
PAPER_OPEN = {
    "table1_slip_stress_350_1": "whichever entry of the 350 µm/s column is wrong (E13: slope × ts = 871 Pa is more"
    " than σs = 800 Pa), the model's start-up stick from rest stays about 20 % low: 635.0 Pa at the column's"
    " 116 Pa/s (631.9 Pa at the nominal stiffness) against the printed 800 Pa (−20.6 %) or against the 871 Pa of"
    " slope × ts if σs is the wrong entry (−27.1 %); with the 106.5 Pa/s that σs/ts give if the slope is wrong,"
    " 631.6 Pa (−21 %). The paper sets apart only the first cycle at 100 µm/s for aging before shearing (E22), not"
    " this one: the model's difference, not the paper's error",
    "table1_stick_time_350_1": "whichever entry of the 350 µm/s column is wrong (E13: slope × ts = 871 Pa is more"
    " than σs = 800 Pa), the model's start-up stick from rest stays about 20 % short: 5.475 s at the column's"
    " 116 Pa/s (5.890 s at the nominal stiffness) against the printed 7.51 s (−27.1 %) or against the 6.90 s of"
    " σs/slope if ts is the wrong entry (−20.6 %); with the 106.5 Pa/s that σs/ts give if the slope is wrong,"
    " 5.929 s (−21 %). The model's difference, not the paper's error",
}

#: The one rule for every Table 1 Vs cell, stated once (the report shows it above Table 1; docs/report.md, errata
#: E15).  Vs is the paper's own computation from its column (Eq 8), so a cell is read against its column before a
#: difference is called the model's: by branch (i) it agrees, by (ii) the column disagrees with itself (a paper
#: error), by (iii) a paper error where the column's measured cells contradict each other, else the model's open
#: difference.  The size of a difference decides nothing beyond branch (i).
JUMP_VELOCITY_RULE = (
    "Table 1's Vs is the paper's own computation from its column (Eq 8: where its steady curve carries σs), so every"
    " Vs cell is judged by one rule: (i) the model's Vs at the printed σs is within 2 % of the printed Vs: it agrees;"
    " (ii) it is not, but the model's Vs at the σs the column's other cells give (σc + slope × ts; slope × ts from"
    " rest for a start-up stick) is: the column disagrees with itself under the paper's own curve, a paper error,"
    " not the model's difference, counted once per column, in its Vs (the cell the paper computed from the others;"
    " its σs and ts are compared with the model as measurements); (iii) neither: a paper error where the column's"
    " measured cells contradict each other (a stick whose slope × ts exceeds its σs even from rest), otherwise an"
    " open difference, the model's"
)

#: Branch of JUMP_VELOCITY_RULE -> (its label in the rule, the class it gives).
JUMP_VELOCITY_BRANCHES = {
    "agrees": ("i", "agrees"),
    "column": ("ii", "erratum"),
    "contradiction": ("iii", "erratum"),
    "model": ("iii", "open"),
}

#: The Vs cells that branch (i) does not settle: (V0 in µm/s, cycle) -> (branch of JUMP_VELOCITY_RULE, what the
#: column says, with the numbers).  Every other Vs cell agrees at its printed σs (branch i);
#: tests/test_report_classes_r29b.py applies the rule to every cell with independent solves.
JUMP_VELOCITY_CELLS: dict[tuple[int, int], tuple[str, str]] = {
    (50, 3): (
        "column",
        "the printed σs = 552 Pa disagrees with the column's σc, slope and ts, which give σc + slope × ts = 264 Pa +"
        " 16.8 Pa/s × 17.8 s = 563.0 Pa ((σs − σc)/slope = 17.14 s against the printed ts = 17.8 s, −3.7 %, E9), and"
        " with its Vs = 720 µm/s: the paper's curve with aging, which Table 1 follows (E15), gives 699.5 µm/s at"
        " 552 Pa (−2.8 %; without aging, as the text prescribes, 748.5 µm/s, +4.0 %) but 728.6 µm/s at 563.0 Pa"
        " (+1.2 %). Read at 552 Pa, 720 µm/s is also above the 702 µm/s printed for the larger σs = 554 and 556 Pa,"
        " where the curve rises by 2.4–2.6 µm/s per Pa; read at 563.0 Pa it is not",
    ),
    (100, 3): (
        "column",
        "the printed σs = 542 Pa disagrees with the column's σc, slope and ts, which give σc + slope × ts = 261 Pa +"
        " 34.0 Pa/s × 8.61 s = 553.7 Pa ((σs − σc)/slope = 8.26 s against the printed ts = 8.61 s, −4.0 %, E9), and"
        " with its Vs = 702 µm/s: the paper's curve with aging, which Table 1 follows (E15), gives 673.8 µm/s at"
        " 542 Pa (−4.0 %; without aging, as the text prescribes, 725.0 µm/s, +3.3 %) but 704.1 µm/s at 553.7 Pa"
        " (+0.3 %). Read at 542 Pa, the 702 µm/s it shares with σs = 549, 554 and 556 Pa breaks the curve's rise of"
        " 2.4–2.6 µm/s per Pa; read at 553.7 Pa it does not",
    ),
    (350, 1): (
        "contradiction",
        "whichever entry is wrong: its Vs = 760 µm/s is where the paper's curve carries 575 Pa, not any σs the"
        " column allows on either curve (800 Pa as printed needs 1643 µm/s; the 871 Pa of its slope × ts,"
        " 116 Pa/s × 7.51 s from rest, needs 2152 µm/s), and it is below the 1026 µm/s the paper prints for the lower"
        " σs = 658 Pa, where its curve rises with σs; its slope × ts = 871 Pa is more than its σs = 800 Pa even from"
        " rest (E13, E9)",
    ),
}

#: What the reason of a Vs cell says after the column's numbers, by branch.
_JUMP_VELOCITY_ENDINGS = {
    "column": ". Which is wrong, σs or the cells that agree with Vs, cannot be told from the paper: one error of"
    " the column, counted once, here, in the cell the paper computed from the others; its σs and ts are compared"
    " with the model as measurements. At the σs the column's other cells give, the model gives the printed Vs: the"
    " difference is inside the paper's column, not the model's",
    "contradiction": ". One error of the column, counted once, here, in the cell the paper computed from the"
    " others; its σs and ts are compared with the model as measurements",
    "model": ". The column agrees with itself and no σs it allows gives its Vs: the model's difference, not the"
    " paper's error",
}


def jump_velocity_branch(key: str) -> str | None:
    """The branch of JUMP_VELOCITY_RULE a Table 1 Vs row falls in when branch (i) does not settle it ("column",
    "contradiction" or "model"); None for a Vs cell that agrees at its printed σs, and for any other row."""
    if not key.startswith("table1_jump_velocity_"):
        return None
    v_um, cycle = key[len("table1_jump_velocity_") :].split("_")
    declared = JUMP_VELOCITY_CELLS.get((int(v_um), int(cycle)))
    return declared[0] if declared else None


def _jump_velocity_reasons() -> None:
    """Each Vs cell that branch (i) does not settle, into PAPER_CONTRADICTIONS or PAPER_OPEN by its branch, its
    reason naming the column, the branch and what the column says."""
    for (v_um, cycle), (branch, says) in JUMP_VELOCITY_CELLS.items():
        label, cls = JUMP_VELOCITY_BRANCHES[branch]
        column = f"{v_um} µm/s" + (f" cycle {cycle}" if v_um != 350 else "")
        text = f"in its {column} column of Table 1 (Vs rule ({label})), {says}{_JUMP_VELOCITY_ENDINGS[branch]}"
        key = f"table1_jump_velocity_{v_um}_{cycle}"
        (PAPER_CONTRADICTIONS if cls == "erratum" else PAPER_OPEN)[key] = text


_jump_velocity_reasons()

#: Rows where the paper's own stated inputs do not give its number, while an input it does not state would (or two
#: of its stated inputs disagree): a gap in the paper, not a limitation of the model, which can give the number.
#: Each row names the input; where it is computed, ``Computed.reproduced_by`` gives it with its value.
_SIMULATED_STICK = (
    "the paper's stated inputs (Nc0, uc/τ, τa = 10 s, λM/kT, K = 0.766 × 400 kPa/m, from σc), with the package's"
    " λ/kT = (λM/kT)/M at M = 100 µN/m (the paper states neither M nor λ/kT, E1, E17), do not give its simulated"
    " stick time; the paper does not state the stiffness, the σc or the λ/kT its simulation used, and each of them"
    " could give it (E18)"
)
PAPER_UNSTATED = {
    "stick_time_50": _SIMULATED_STICK,
    "stick_time_100": _SIMULATED_STICK,
    "stiffness_against_table1": "two of the paper's stated inputs disagree: the nominal Gd/h = 4 kPa / 10 mm ="
    " 400 kPa/m and the Gd/h its own Table 1 slopes give (424–457 kPa/m), which it says “compares well”; the model"
    " takes each Table 1 column's stiffness from its slope and the nominal one elsewhere (E14)",
    "table1_slip_stress_100_1": "the paper sets this cycle apart: the contact aged before shearing began, by an"
    " amount the paper does not state; the stated uc/τ (fresh chains at every stick) gives the model's value (E22)",
    "table1_stick_time_100_1": "the paper sets this cycle apart: the contact aged before shearing began, by an"
    " amount the paper does not state; the stated uc/τ (fresh chains at every stick) gives the model's value (E22)",
}

#: Rows that state again what other rows state: the same number for the same quantity, printed in two places (or a
#: Table 1 cell that a text row repeats).  Shown and marked, counted once (in the first row named).
REPEATS: dict[str, tuple[tuple[str, ...], str]] = {
    "critical_stress_cycles": (
        ("critical_stress",),
        "259 Pa is the paper's σc of Section 3 said again, as the centre of Table 1's σc row (254–264 Pa), whose"
        " cells are rows of their own",
    ),
    "slip_stress_50": (
        ("table1_slip_stress_50_1",),
        "Table 1's 554 Pa (50 µm/s, cycle 1); the text does not print it again; here at the mean stiffness of the"
        " 50 µm/s cycles",
    ),
    "slip_stress_100": (
        ("table1_slip_stress_100_2", "table1_slip_stress_100_4"),
        "Table 1's 549 Pa (100 µm/s, cycles 2 and 4); the text does not print it again; here at the mean stiffness"
        " of cycles 2–4",
    ),
    "jump_velocity_50": (
        ("table1_jump_velocity_50_1",),
        "Table 1's 702 µm/s for σs = 554 Pa (50 µm/s, cycle 1), the same computation",
    ),
    "jump_velocity_100": (
        ("table1_jump_velocity_100_2", "table1_jump_velocity_100_4"),
        "Table 1's 702 µm/s for σs = 549 Pa (100 µm/s, cycles 2 and 4), the same computation",
    ),
    "slip_asymptote_50": (
        ("critical_velocity",),
        "the slip below Vc ends at Vc (Eq 10, where dσ/dV = 0): the paper's 125 µm/s is its Vc said again, and the"
        " model's end velocity is its Vc",
    ),
    "slip_asymptote_100": (
        ("critical_velocity",),
        "the slip below Vc ends at Vc (Eq 10, where dσ/dV = 0): the paper's 125 µm/s is its Vc said again, and the"
        " model's end velocity is its Vc",
    ),
}


def table1_value(key: str, velocity: float, cycle: int) -> float | None:
    """A Table 1 entry in SI units, as printed (None for "--")."""
    _key, _label, _unit, _display, values, scale = next(r for r in TABLE1_ROWS if r[0] == key)
    value = values[TABLE1_COLUMNS.index((velocity, cycle))]
    return None if value is None else float(value) * scale


def scatter_band(key: str, velocity: float) -> tuple[float, float] | None:
    """The measurements of ``key`` at ``velocity`` that the paper calls the same, from lowest to highest as printed
    (not widened: a value outside the measured range is not within the scatter the paper shows; the printed digits'
    half unit is below 0.1 % here and is not added).  sigma_c has the paper's own 259 ± 5 Pa.  None when fewer than
    two cycles are alike."""
    if key == "critical_stress":
        return CRITICAL_STRESS_BAND
    values = [
        v
        for column in TABLE1_COLUMNS
        if column[0] == velocity and column not in TABLE1_SET_APART and (v := table1_value(key, *column)) is not None
    ]
    if len(values) < 2:
        return None
    return min(values), max(values)


def _explanation(key: str) -> dict:
    """How row ``key`` explains a difference beyond tolerance and scatter (PAPER_CONTRADICTIONS, PAPER_UNSTATED),
    and whether it repeats another row (REPEATS)."""
    out: dict = {"explanation": "limitation", "contradiction": "", "unstated": "", "open_reason": ""}
    if key in PAPER_CONTRADICTIONS:
        out.update(explanation="erratum", contradiction=PAPER_CONTRADICTIONS[key])
    elif key in PAPER_UNSTATED:
        out.update(explanation="unstated", unstated=PAPER_UNSTATED[key])
    elif key in PAPER_OPEN:
        out.update(explanation="open", open_reason=PAPER_OPEN[key])
    if key in REPEATS:
        out.update(repeat_of=REPEATS[key][0], repeat_note=REPEATS[key][1])
    return out


def _table1_numbers() -> tuple[PaperNumber, ...]:
    out = []
    for key, label, unit, display, values, scale in TABLE1_ROWS:
        for (velocity, cycle), value in zip(TABLE1_COLUMNS, values, strict=True):
            if value is None:
                continue
            v_um = round(velocity * 1e6)
            kind = TABLE1_KINDS[key]
            scatter = None
            if kind == "measured" and (velocity, cycle) not in TABLE1_SET_APART:
                scatter = scatter_band(key, velocity)
            source = ""
            if scatter is not None:
                source = CRITICAL_STRESS_SOURCE if key == "critical_stress" else MEASURED_RANGE_SOURCE
            out.append(
                PaperNumber(
                    key=f"table1_{key}_{v_um}_{cycle}",
                    quantity=f"{label}, V0 = {v_um} µm/s, cycle {cycle}",
                    group=TABLE1,
                    kind=kind,
                    paper=float(value) * scale,
                    unit=unit,
                    display=display,
                    printed=value,
                    source="Table 1",
                    note=TABLE1_NOTES.get((velocity, cycle), ""),
                    scatter=scatter,
                    scatter_source=source,
                    **_explanation(f"table1_{key}_{v_um}_{cycle}"),
                )
            )
    return tuple(out)


TABLE1_NUMBERS = _table1_numbers()

#: Measurements quoted in the text -> the Table 1 cycles they summarise (18.9 s is left out: a misprint, E9).
TEXT_SCATTER = {
    "stick_time_measured_50": ("stick_time", 50e-6),
    "stick_time_measured_100": ("stick_time", 100e-6),
    "stick_time_table_100": ("stick_time", 100e-6),
    "slip_stress_50": ("slip_stress", 50e-6),
    "slip_stress_100": ("slip_stress", 100e-6),
}

#: Every number the paper states, in report order.
PAPER_NUMBERS: tuple[PaperNumber, ...] = (
    tuple(
        replace(
            n, scatter=scatter_band(*TEXT_SCATTER[n.key]), scatter_source=MEASURED_RANGE_SOURCE, **_explanation(n.key)
        )
        if n.key in TEXT_SCATTER
        else replace(n, **_explanation(n.key))
        for n in TEXT_NUMBERS
    )
    + TABLE1_NUMBERS
)


def _check_references() -> None:
    """Every row the tables above name exists, and a repeat names rows that are counted themselves."""
    keys = {n.key for n in PAPER_NUMBERS}
    named = set(PAPER_CONTRADICTIONS) | set(PAPER_UNSTATED) | set(PAPER_OPEN) | set(REPEATS)
    named |= {k for originals, _ in REPEATS.values() for k in originals}
    if named - keys:
        raise KeyError(f"no paper number for: {', '.join(sorted(named - keys))}")
    chained = {k for originals, _ in REPEATS.values() for k in originals} & set(REPEATS)
    if chained:
        raise ValueError(f"a repeat must name a counted row, not another repeat: {', '.join(sorted(chained))}")


_check_references()


def _topics_for(number: PaperNumber) -> tuple[str, ...]:
    key = number.key
    if key in TEXT_ERRATA:
        return TEXT_ERRATA[key]
    if not key.startswith("table1_"):
        return ()
    row, v_um, cycle = key[len("table1_") :].rsplit("_", 2)
    column = (int(v_um), int(cycle))
    return TABLE1_ERRATA.get((row, column), TABLE1_ERRATA.get((row, None), ()))


# Errata are named by what their titles say, not by number, so that renumbering docs/errata.md (merging in
# new entries) keeps every link right.  Each pattern is a regular expression searched in the entry titles
# ("## E<n> title"); the first pattern that matches an entry gives the link.  tests/test_report.py checks
# that every pattern used matches exactly one entry.
CRITICAL = r"^Vc = 125 µm/s and σc = 259"
STICK_TIMES = (r"simulated stick times 18\.3 s and 9\.3 s", r"t_s = 9\.3 s for V0 = 50")
TABLE1_STICK_TIMES = (r"^Table 1 stick times",)
JUMP = (r"curve gives the jump velocity",)
COLUMN_350 = (r"^Table 1, 350 µm/s column",)

TEXT_ERRATA: dict[str, tuple[str, ...]] = {
    "critical_velocity": (CRITICAL,),
    "critical_stress": (CRITICAL,),
    "critical_stress_cycles": (CRITICAL,),
    "steady_stress_350": (r"350 µm/s, not 150 µm/s",),
    "stretch_sensitivity": (r"^λM/kT = 2\.47.*wrong dimension",),
    "aging_time": (r"^Notation: τ_A, V_A",),
    "aging_velocity": (r"V_a ≪ 800 µm/s",),
    "stiffness_printed": (r"400 Pa\.m⁻¹",),
    "stiffness": (r"400 Pa\.m⁻¹",),
    "stiffness_against_table1": (r"^Table 1's G_d/h row",),
    "geometric_factor": (r"Substitution of these lengths",),
    "stick_aging_time": (r"^Notation: τ_A, V_A",),
    "stick_time_50": STICK_TIMES,
    "stick_time_100": STICK_TIMES,
    "stick_time_measured_50": STICK_TIMES,
    "stick_time_measured_100": STICK_TIMES,
    "stick_time_table_50": TABLE1_STICK_TIMES,
    "stick_time_table_100": TABLE1_STICK_TIMES,
    "jump_velocity_50": JUMP,
    "jump_velocity_100": JUMP,
    "slip_asymptote_50": (r"asymptotic value 125", CRITICAL),
    "slip_asymptote_100": (r"asymptotic value 125", CRITICAL),
    "slip_asymptote_350": (r"asymptotic value 125",),
}

#: (Table 1 row, (V0 in um/s, cycle) or None for the whole row) -> topics, as in TEXT_ERRATA.
TABLE1_ERRATA: dict[tuple[str, tuple[int, int] | None], tuple[str, ...]] = {
    ("critical_stress", None): (CRITICAL,),
    ("stick_slope", None): (r"^Table 1's G_d/h row",),
    ("stiffness", None): (r"^Table 1's G_d/h row",),
    ("slip_stress", (100, 1)): (r"^Table 1 σs",),
    ("slip_stress", (100, 3)): (r"^Table 1 σs",),
    ("slip_stress", (350, 1)): COLUMN_350,
    ("stick_time", None): STICK_TIMES,
    ("stick_time", (100, 1)): (r"^Table 1 σs", *TABLE1_STICK_TIMES),
    ("stick_time", (350, 1)): (*COLUMN_350, *TABLE1_STICK_TIMES),
    ("jump_velocity", None): JUMP,
    ("jump_velocity", (350, 1)): COLUMN_350,
}

#: Paper key -> the topics of the errata that bear on it, best first.
ERRATA_TOPICS: dict[str, tuple[str, ...]] = {n.key: t for n in PAPER_NUMBERS if (t := _topics_for(n))}


def resolve_errata(titles: dict[str, str]) -> dict[str, str]:
    """Paper key -> erratum id, given the errata's ``{id: title}``; keys whose topics match no entry are left out."""
    found: dict[str, str] = {}
    for key, topics in ERRATA_TOPICS.items():
        for topic in topics:
            match = next((entry for entry, title in titles.items() if re.search(topic, title)), None)
            if match is not None:
                found[key] = match
                break
    return found
