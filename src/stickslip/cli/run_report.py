"""What a run prints below the shared summary: each model's own record (cycles, final state), text and JSON.

``stickslip run --model NAME`` and its spellings (``simulate``, ``transient``, ``rsf simulate``) print one
summary for every model (:func:`stickslip.cli.run_cmd.summary_text`); the model's own record follows it: the
quasi-static model's critical point and its table of cycles, the transient model's final state and its cycles,
rate-and-state's final friction.  In JSON the record's keys stand beside the summary's (the summary's win).
"""

from __future__ import annotations

from typing import Any

from ..display import velocity
from .common import plain_text

#: Width of the plain text a table is drawn in (as ``print_rich`` draws it to a pipe).
PLAIN_WIDTH = 120


def model_record(run: Any) -> dict[str, Any]:
    """The engine's own summary (SI): ``simulate --json``'s cycles and critical point, ``transient --json``'s
    final state and cycles, ``rsf simulate --json``'s friction numbers."""
    summary = getattr(run.native, "summary", None)
    record = dict(summary()) if callable(summary) else {}
    record.pop("units", None)  # the JSON's units map is drawn for the whole document
    return record


def record_text(run: Any, rig: dict[str, Any] | None = None) -> str:
    """The model's own record in words, below the shared summary ("" for a model without one).  ``rig``: the
    summary's (its ``stiffness_from`` says whether the quasi-static model's K is Eq 17's or the rig's)."""
    native = run.native
    kind = type(native).__name__
    if kind == "Simulation":
        return "\n".join(
            item if isinstance(item, str) else plain_text([item], PLAIN_WIDTH)
            for item in _simulation_record(native, (rig or {}).get("stiffness_from"))
        )
    if kind == "TransientResult":
        return "\n".join(_transient_record(native))
    if kind == "RSFRun":
        return f"  at t = {native.time[-1]:.6g} s: μ = {float(native.friction[-1]):.6g}"
    return ""


def _fmt(value: float | None, scale: float = 1.0, digits: int = 5) -> str:
    return "—" if value is None else f"{value * scale:.{digits}g}"


#: where the quasi-static run's K came from, as its record says it (the summary rig's ``stiffness_from``)
K_SOURCE = {"rig": "the rig's, as given", "parameters": "Eq 17"}


def _simulation_record(sim: Any, stiffness_from: str | None = None) -> list[Any]:
    """The quasi-static run: its parameter set, start and critical point, where it ended, and its cycles.
    ``stiffness_from``: "rig" where K was given (``--stiffness``: "(Eq 17)" was written beside it), else Eq 17's."""
    from rich.table import Table

    name = sim.parameters.name if sim.parameters is not None else "parameters"
    head = [
        f"  {name}: starting stuck at {sim.start_stress:.6g} Pa (jump onto the {sim.jump_curve} curve);"
        f" Vc = {velocity(sim.critical_velocity)}, σc = {sim.critical_stress:.6g} Pa,"
        f" K = {sim.stiffness / 1e3:.6g} kPa/m ({K_SOURCE.get(stiffness_from or 'parameters', 'Eq 17')})",
        f"  at t = {sim.time[-1]:.6g} s: σ = {sim.final_stress:.6g} Pa, V = {velocity(sim.final_velocity)}"
        + ("" if sim.time[-1] >= sim.duration else " (the model stops here)"),
    ]
    out: list[Any] = ["\n".join(head)]
    if not sim.cycles:
        out.append("  no stick phase ended in a slip within the run")
        return out
    table = Table(title="Cycles", title_justify="left")
    headings = ("#", "start (s)", "σ start (Pa)", "σs (Pa)", "ts (s)", "Vs (µm/s)", "slip (s)", "period (s)")
    for heading in headings:
        table.add_column(heading, justify="right")
    # a long run's tens of thousands of cycles (1e6 s at 50 µm/s: 43,316, 35 s and 550 MB to draw): the first few,
    # the count left out, the last ones, as the transient run's text (--json lists every cycle)
    for c in shown_cycles(sim.cycles):
        if c is None:
            table.add_row(*("…" for _ in headings))
            continue
        table.add_row(
            str(c.index + 1),
            _fmt(c.start_time, digits=6),
            _fmt(c.start_stress),
            _fmt(c.peak_stress),
            _fmt(c.stick_time),
            _fmt(c.jump_velocity, 1e6),
            _fmt(c.slip_time),
            _fmt(c.period),
        )
    out.append(table)
    if len(sim.cycles) > CYCLE_LINES:
        out.append(left_out(len(sim.cycles)))
    return out


def _transient_record(result: Any) -> list[str]:
    """The transient run: where it ended (stress, bonded fraction, velocity, steps) and each stick-slip event."""
    from ..transient.cycles import describe_jump

    lines = [
        f"  at t = {result.time[-1]:.6g} s: σ = {result.final_stress:.6g} Pa,"
        f" N/N0 = {result.final_bonded_fraction:.6g},"
        f" V = {result.slider_velocity[-1] * 1e6:.6g} µm/s ({result.steps} steps)"
    ]
    cycles = result.cycles
    # a long run's thousands of cycles: the first few, a count, and the last ones (the settled cycle; --json: all)
    for c in shown_cycles(cycles):
        if c is None:
            lines.append(left_out(len(cycles)))
            continue
        slip = "—" if c.slip_time is None else f"{c.slip_time:.4g} s"
        lines.append(
            f"  cycle {c.index + 1}: stick {c.stick_time:.4g} s, σs = {c.peak_stress:.5g} Pa,"
            f" {describe_jump(c.jump_velocity)}, slip {slip}"
        )
    return lines


#: a run's text lists its cycles (the transient run's one a line, the quasi-static run's table) up to this many;
#: beyond, the first CYCLE_HEAD and the last CYCLE_TAIL, with the count left out between
CYCLE_LINES = 12
CYCLE_HEAD = 5
CYCLE_TAIL = 3


def shown_cycles(cycles: Any) -> list[Any]:
    """The cycles a run's text lists: all of them up to CYCLE_LINES, else the first CYCLE_HEAD, None where the
    others are left out (:func:`left_out` says how many), and the last CYCLE_TAIL (the settled cycle)."""
    cycles = list(cycles)
    if len(cycles) <= CYCLE_LINES:
        return cycles
    return [*cycles[:CYCLE_HEAD], None, *cycles[-CYCLE_TAIL:]]


def left_out(count: int) -> str:
    """The line for the cycles :func:`shown_cycles` leaves out of ``count``, and where the full table is."""
    return (
        f"  … {count - CYCLE_HEAD - CYCLE_TAIL:,} cycles more (cycles {CYCLE_HEAD + 1} to {count - CYCLE_TAIL:,} of"
        f" {count:,} left out; --json lists every cycle) …"
    )


__all__ = ["model_record", "record_text"]
