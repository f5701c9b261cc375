"""``stickslip analyze``: per-cycle characteristics of a measured stick-slip record (Table 1).

Output in SI base units for machines (``--json``, ``-o cycles.csv`` with the
units in the header brackets) and in Table 1's units for people (the table).
"""

from __future__ import annotations

import io
import math
from pathlib import Path
from typing import Any

import click

from ..columns import json_units
from ..errors import ParameterError
from .common import (
    FILE_PATH,
    InputFile,
    echo_err,
    emit_json,
    params_options,
    positive,
    refuse_overwriting_inputs,
    resolve_params,
    save_figure,
    write_text,
)
from .params_cmd import print_rich

#: Columns of ``-o cycles.csv``: (field, SI unit).  A model-derived field's column is named ``model_<field>``.
CSV_COLUMNS = (
    ("pulling_velocity", "m/s"),  # the trace's V0: cycles tables of several traces stack into one for `fit stick`
    ("cycle", "1"),  # pure numbers carry [1], as every CSV of the package writes them
    ("complete", "1"),
    ("start_time", "s"),
    ("peak_time", "s"),
    ("end_time", "s"),
    ("critical_stress", "Pa"),
    ("stick_slope", "Pa/s"),
    ("stick_slope_stderr", "Pa/s"),
    ("stiffness", "Pa/m"),
    ("stiffness_stderr", "Pa/m"),
    ("peak_stress", "Pa"),
    ("stick_time", "s"),
    ("jump_velocity", "m/s"),
    ("slip_time", "s"),
    ("period", "s"),
    ("stress_drop", "Pa"),
    # how well the corners are located, apart from the noise's scatter (systematic: the same in every repeat of a
    # cycle); fit stick floors the error of each velocity's mean stick time with them
    ("critical_stress_uncertainty", "Pa"),
    ("peak_stress_uncertainty", "Pa"),
    ("stick_time_uncertainty", "s"),
    # the stick's bend (d2sigma/dt2 of a parabola through it) and whether it is beyond its noise: fit stick's model
    # sticks are straight, so it names the curved rows it reads (docs/analysis.md, "Curved sticks")
    ("stick_curvature", "Pa/s^2"),
    ("stick_curvature_stderr", "Pa/s^2"),
    ("stick_curved", "1"),
)

#: Units of the keys of ``--json`` that are particular to analyze (they win over the package's registry, where
#: ``stress_slope`` is the steady curve's dsigma/dV: here it is the steady stretch's trend in time).
JSON_UNITS = {
    "noise": "Pa",
    "drop_threshold": "Pa",
    "stress_slope": "Pa/s",
    "stress_std": "Pa",
    "stress_sem": "Pa",
    "steady_from": "s",
    "steady_to": "s",
    "shift": "s",
    "rms_misfit": "Pa",
    "peak_to_trough": "Pa",  # the swings of summary.oscillation and summary.unresolved_swings
    "spread": "Pa",
    "samples_per_swing": "1",
    "slip_time_bound": "s",  # a slip between samples lasts less than this (cycles, and summary.unresolved_slips)
    "stick_curvature": "Pa/s^2",  # a curved stick's d2sigma/dt2 (cycles; docs/analysis.md, "Curved sticks")
    "stick_curvature_stderr": "Pa/s^2",
    "stick_sagitta": "Pa",
    "stick_curved": None,  # a flag
    "stress_correlation_time": "s",  # the steady stretch's integrated autocorrelation time (its SEM's n_eff)
    "steady_effective_samples": "1",
    "model": None,  # the comparison's per-cycle table of the model's values, not a number
}

#: The printed table shows at most this many cycles (and the mean of all); -o and --json hold every one.
TABLE_CYCLES = 8

#: Rows of the printed table: (field, heading, factor from SI, digits).
TABLE_ROWS = (
    ("critical_stress", "σc [Pa]", 1.0, 4),
    ("stick_slope", "dσ/dt stick [Pa/s]", 1.0, 4),
    ("stiffness", "Gd/h [kPa/m]", 1e-3, 4),
    ("peak_stress", "σs [Pa]", 1.0, 4),
    ("stick_time", "ts [s]", 1.0, 4),
    ("jump_velocity", "Vs [µm/s] (model)", 1e6, 4),
    ("slip_time", "slip time [s]", 1.0, 4),
    ("period", "period [s]", 1.0, 4),
)


@click.command("analyze")
@click.argument("traces", metavar="TRACE...", nargs=-1, required=True, type=InputFile())
@click.option(
    "--v0",
    "v0_texts",
    multiple=True,
    metavar="V",
    help='Pulling velocity with its unit, e.g. "50 um/s"; without it, the one a stickslip trace records in its load'
    " point (a run at one velocity).  With several traces: none, or one --v0 per trace, in their order.",
)
@click.option(
    "--contact-area",
    "area_text",
    default=None,
    metavar="A",
    help='Contact area with its unit, e.g. "15 cm^2", to turn a force column into stress (every trace).',
)
@params_options
@click.option("--json", "as_json", is_flag=True, help="Print the analysis as JSON (SI units; one trace).")
@click.option(
    "-o",
    "--output",
    type=FILE_PATH,
    help="Write the per-cycle table as CSV (SI units in the header brackets; several traces: their rows stacked).",
)
@click.option(
    "--steady-table",
    "steady_path",
    type=FILE_PATH,
    help="Write the steady curve of steady-sliding traces as CSV, one row per trace (velocity, stress, stress_err:"
    " the mean and its standard error), as `fit steady` reads it.",
)
@click.option(
    "--plot",
    "plot_path",
    type=FILE_PATH,
    help="Save a figure of the record with the detected phases (and the model with --compare; one trace).",
)
@click.option(
    "--compare",
    is_flag=True,
    help="Simulate the model at V0, align it at the first whole cycle, report the misfit (one trace).",
)
def analyze_command(
    traces: tuple[Path, ...],
    v0_texts: tuple[str, ...],
    area_text: str | None,
    params_name: str,
    overrides: tuple[str, ...],
    as_json: bool,
    output: Path | None,
    steady_path: Path | None,
    plot_path: Path | None,
    compare: bool,
) -> None:
    """Analyse a measured stress record: regime, and per cycle σc, slope, Gd/h, σs, ts, Vs.

    TRACE is a CSV file with columns ``time`` and ``stress`` (or ``force``
    with --contact-area), units in header brackets (``time [s],stress [kPa]``;
    bare names are SI).  Empty stress cells are gaps.  Several traces (records
    at several velocities) are analysed one after the other; --steady-table
    writes the steady curve of those that slide steadily, for `fit steady`.
    """
    refuse_overwriting_inputs(
        list(traces), [("-o", output), ("--steady-table", steady_path), ("--plot", plot_path)], params_name
    )
    several = len(traces) > 1
    if several:
        for option, given in (("--json", as_json), ("--plot", plot_path is not None), ("--compare", compare)):
            if given:
                raise ParameterError(f"{option}: one trace at a time ({len(traces)} given)")
    if v0_texts and len(v0_texts) != len(traces):
        raise ParameterError(
            f"--v0: given {len(v0_texts)} time(s) for {len(traces)} trace(s); expected one per trace, in their order,"
            " or none (each trace's own load point)"
        )
    from ..analysis import compare_with_model

    area = None if area_text is None else positive(area_text, "area", "--contact-area")
    velocities = [None if not v0_texts else v0_texts[k] for k in range(len(traces))]
    for text in velocities:  # a value given: checked at once, before any trace is read
        if text is not None:
            positive(text, "velocity", "--v0")
    params = resolve_params(params_name, overrides)
    parameter_set, default_set = _parameter_set(params, params_name)
    analyses = [_analyze(trace, text, area, params, several) for trace, text in zip(traces, velocities, strict=True)]
    steady_rows = _steady_rows(traces, analyses) if steady_path is not None else None
    comparison = compare_with_model(analyses[0], params) if compare else None
    if output is not None:
        tables = [cycles_csv(a) for a in analyses]
        write_text(output, tables[0] + "".join(t.split("\n", 1)[1] for t in tables[1:]))
    if steady_rows is not None and steady_path is not None:
        write_text(steady_path, steady_rows)
    if as_json:
        data = analyses[0].as_dict()
        data["parameter_set_default"] = default_set
        if comparison is not None:
            data["comparison"] = comparison.as_dict()
        data["units"] = json_units(data, JSON_UNITS)
        emit_json(data)
    else:
        for analysis in analyses:
            print_rich(*_report(analysis, comparison, parameter_set))
    if plot_path is not None:
        from ..plots.traces import figure_analysis

        save_figure(figure_analysis(analyses[0], comparison), plot_path)


def _analyze(trace: Path, v0_text: str | None, area: float | None, params: Any, several: bool) -> Any:
    """One trace read, its pulling velocity found (--v0, or its load point) and checked, and analysed; the notes and
    warnings on stderr."""
    from ..analysis import analyze_trace, read_trace
    from ..analysis.traces import parameter_mismatch
    from ..models.run import recorded_status

    record = read_trace(trace, contact_area=area)  # before --v0 is asked for: a file that is no trace says so
    steps: list[tuple[float, float, float]] = []  # the load point's stretches at one velocity, when it steps
    if v0_text is None:
        v0_text = _recorded_v0(trace, several)
        v0 = positive(v0_text, "velocity", "--v0")
    else:
        v0 = positive(v0_text, "velocity", "--v0")
        steps = _check_recorded_v0(trace, v0, v0_text)
    for note in record.notes:
        echo_err(f"note: {note}")
    mismatch = parameter_mismatch(trace, params)
    if mismatch:
        echo_err(f"warning: {trace}: {mismatch}")
    status, why = recorded_status(trace)
    if status != "ok":  # a run cut short is still a record, but not of the run asked for
        echo_err(f"note: {trace} is a run that {'stopped' if status == 'stopped' else 'failed'} before its end: {why}")
    analysis = analyze_trace(record, None, v0, params)
    _refuse_unbounded(analysis, v0_text)
    for warning in analysis.warnings:
        echo_err(f"warning: {trace}: {warning}")
    for start, _, _ in steps[1:]:
        spanning = [c.index for c in analysis.cycles if c.stick_from < start < c.stick_to]
        if spanning:
            echo_err(
                f"warning: {trace}: the stick of cycle {spanning[0]} spans the velocity step at t = {start:.6g} s:"
                " it is no one line, and its σc, ts and Gd/h are not those of either velocity"
            )
    return analysis


#: A steady stretch whose mean's standard error is below this fraction of the mean is noise-free (a model's run).
NOISE_FREE = 1e-9
#: Columns of ``--steady-table``: what `fit steady` reads (docs/fitting.md, "Data files"), SI units.
STEADY_TABLE_COLUMNS = (("velocity", "m/s"), ("stress", "Pa"), ("stress_err", "Pa"))


def _steady_rows(traces: tuple[Path, ...], analyses: list[Any]) -> str:
    """The steady curve of the traces as `fit steady` reads it: per trace its pulling velocity (the sliding velocity
    of steady sliding), the mean stress over its steady window and that mean's standard error (under correlated
    noise: docs/analysis.md, section 6).  A trace that does not end in steady sliding has no point on the curve:
    refused, naming it.  Noise-free records (every error 0, as the model's own runs) get no stress_err column."""
    from ..display import velocity as show_velocity

    rows = []
    for trace, analysis in zip(traces, analyses, strict=True):
        summary = analysis.summary
        mean, error = summary.get("mean_stress"), summary.get("stress_sem")
        if analysis.regime != "steady" or mean is None:
            raise ParameterError(
                f"--steady-table: {trace} is {analysis.regime} at {show_velocity(analysis.pulling_velocity, 4)}, not"
                " steady sliding: it has no point on the steady curve; leave it out (analyze it alone for its cycles)"
            )
        if error is None:
            raise ParameterError(
                f"--steady-table: {trace}: its steady stretch has {summary.get('steady_samples')} sample(s), too"
                " few for a standard error of its mean"
            )
        # a noise-free record (a model's run) has an error of rounding alone: none
        rows.append((analysis.pulling_velocity, float(mean), float(error) if error > NOISE_FREE * abs(mean) else 0.0))
    columns = STEADY_TABLE_COLUMNS if any(row[2] > 0 for row in rows) else STEADY_TABLE_COLUMNS[:2]
    if len(columns) < len(STEADY_TABLE_COLUMNS):
        echo_err(
            "note: --steady-table: every steady stretch is noise-free (a standard error of 0 Pa): no stress_err"
            " column, and fit steady weighs every point alike"
        )
    elif any(not row[2] > 0 for row in rows):
        raise ParameterError(
            "--steady-table: "
            + ", ".join(str(t) for t, row in zip(traces, rows, strict=True) if not row[2] > 0)
            + " have a noise-free steady stretch (standard error 0 Pa) beside noisy ones: fit steady needs a"
            " positive stress_err in every row; analyze them apart"
        )
    out = io.StringIO()
    out.write(",".join(f"{name} [{unit}]" for name, unit in columns) + "\n")
    for row in rows:
        out.write(",".join(_cell(value) for value in row[: len(columns)]) + "\n")
    return out.getvalue()


def _recorded_v0(trace: Path, several: bool = False) -> str:
    """--v0 from the trace's own load point (what `run -o` and its spellings write), said on stderr."""
    from ..analysis.traces import recorded_pulling_velocity
    from ..display import velocity as show_velocity

    v0, why = recorded_pulling_velocity(trace)
    name = f"{trace}: " if several else ""
    if v0 is None:
        raise ParameterError(
            f"--v0: needed: {name}{why}; give the pulling velocity with its unit, e.g. --v0 '50 um/s'"
            + (" (one --v0 per trace, in their order)" if several else "")
        )
    whose = f"{trace}: its" if several else "the trace's"
    echo_err(f"note: --v0 not given: {whose} load point moves at {show_velocity(v0, 6)} throughout")
    return f"{v0:.12g} m/s"  # the load point is written to 17 digits; its slope is known to ~1e-12


#: --v0 and the velocity of the record's own load point agree when they differ by at most this fraction (the
#: load point's slope is known to ~1e-12; three significant digits typed, "33.3 um/s", stay within it).
V0_AGREEMENT = 5e-3


def _check_recorded_v0(trace: Path, v0: float, v0_text: str) -> list[tuple[float, float, float]]:
    """A --v0 that contradicts the load point the record carries is refused: the record's load point is a
    measurement of the very velocity --v0 states, and Gd/h (the stick slope over V0) would silently be wrong by
    their ratio; leaving --v0 out uses the record's own.  A load point that changes velocity (a velocity step)
    is warned of, with the times: Gd/h per cycle then assumes --v0 for every cycle."""
    from ..analysis.traces import LOAD_POINT_COLUMNS, load_point_velocities
    from ..display import velocity as show_velocity
    from ..tables import header_names

    if not {n.lower() for n in header_names(trace)} & set(LOAD_POINT_COLUMNS):
        return []  # no load point recorded (a measured record): nothing to check against, and no second read
    name, segments = load_point_velocities(trace)
    if name is None:
        return []
    if not segments:
        echo_err(
            f"warning: {trace}: its load point ({name}) does not move at one velocity throughout; Gd/h per cycle"
            f" is the stick slope over one V0 (--v0 {show_velocity(v0, 6)} for every cycle)"
        )
        return []
    if len(segments) == 1:
        recorded = segments[0][2]
        if abs(v0 - recorded) > V0_AGREEMENT * recorded:
            raise ParameterError(
                f"--v0 {v0_text}: {trace}'s own load point ({name}) moves at {show_velocity(recorded, 6)}, not"
                f" {show_velocity(v0, 6)}; leave --v0 out to use the record's, or give the velocity it records"
            )
        return []
    steps = ", ".join(f"{show_velocity(v, 4)} from t = {a:.6g} s" for a, _, v in segments[:6]) + (
        f" and {len(segments) - 6} more" if len(segments) > 6 else ""
    )
    echo_err(
        f"warning: {trace}: its load point ({name}) changes velocity within the record ({steps}); Gd/h per cycle"
        f" is the stick slope over one V0 (--v0 {show_velocity(v0, 6)} for every cycle)"
    )
    return segments


def _parameter_set(params: Any, params_name: str) -> tuple[str, bool]:
    """(how the report names the parameter set its model comparisons use, whether it is the default one)."""
    from click.core import ParameterSource

    context = click.get_current_context(silent=True)
    source = None if context is None else context.get_parameter_source("params_name")
    if source in (None, ParameterSource.DEFAULT, ParameterSource.DEFAULT_MAP):
        return f"{params.name} (the default: give --params NAME|FILE with the set the record belongs to)", True
    return (params.name if params_name == params.name else f"{params.name} (--params {params_name})"), False


def _refuse_unbounded(analysis: Any, v0_text: str) -> None:
    """A per-cycle statistic beyond the floating-point range (the stiffness slope/V0 at --v0 '1e-300 um/s') is no
    answer: refuse, naming --v0, rather than print inf."""
    for name, stats in analysis.summary.items():
        numbers = [v for v in (stats.get("mean"), stats.get("std")) if isinstance(v, float)] if isinstance(
            stats, dict) else []  # fmt: skip
        if any(not math.isfinite(v) for v in numbers):
            raise ParameterError(
                f"--v0 {v0_text}: the cycles' {name} leaves the floating-point range at this pulling velocity;"
                " expected the velocity the record was measured at"
            )


def cycles_csv(analysis: Any) -> str:
    """The cycles as CSV, SI units in the header brackets; empty cells where a value is not in the record."""
    out = io.StringIO()
    out.write(",".join(_csv_heading(name, unit) for name, unit in CSV_COLUMNS) + "\n")
    for cycle in analysis.cycles:
        data = cycle.as_dict()
        data["cycle"] = cycle.index
        data["pulling_velocity"] = analysis.pulling_velocity
        data["complete"] = int(cycle.complete)
        data["stick_curved"] = int(cycle.stick_curved)  # a flag, written as the 0/1 the other flags are
        out.write(",".join(_cell(data[name]) for name, _ in CSV_COLUMNS) + "\n")
    return out.getvalue()


def _csv_heading(name: str, unit: str) -> str:
    """``name [unit]``; a model-derived quantity is named ``model_<name>`` so that no reader takes it as measured."""
    from ..analysis.cycles import MODEL_DERIVED

    label = f"model_{name}" if name in MODEL_DERIVED else name
    return f"{label} [{unit}]" if unit else label


def _cell(value: Any) -> str:
    from ..columns import csv_number

    if value is None:
        return ""
    if isinstance(value, float):  # at the package's CSV digits, as every CSV it writes (columns.csv_number)
        return csv_number(value) if math.isfinite(value) else ""
    return str(value)


def _report(analysis: Any, comparison: Any, parameter_set: str | None = None) -> list[Any]:
    from rich.markup import escape
    from rich.table import Table

    from ..analysis.cycles import summary_note

    v0 = analysis.pulling_velocity
    head = (
        f"{analysis.source}: {analysis.message}\n"
        f"V0 = {v0 * 1e6:.6g} µm/s, noise {analysis.noise:.3g} Pa,"
        f" drops above {analysis.threshold:.3g} Pa count as slips"
    )
    if parameter_set is not None:
        head += f"\nmodel comparisons (Vs, Gd/h's block geometry, --compare) with {parameter_set}"
    parts: list[Any] = [escape(head)]
    if analysis.cycles:
        shown = analysis.cycles[:TABLE_CYCLES]
        table = Table(title="Per cycle (Table 1 rows)", title_justify="left")
        table.add_column("")
        for cycle in shown:
            table.add_column(f"cycle {cycle.index}" + ("" if cycle.complete else "*"), justify="right")
        complete = len(analysis.summary.get("averaged_cycles", ()))
        table.add_column(  # over the complete cycles (dσ/dt, Gd/h: every stick line); the note below says which
            f"mean ± sd ({complete} complete)" if complete < len(analysis.cycles) else "mean ± sd", justify="right"
        )
        between = [c for c in analysis.cycles if c.slip_time_bound is not None]
        after = {c.index + 1 for c in between}  # the cycles whose stick began after a slip between samples
        for name, heading, factor, digits in TABLE_ROWS:
            cells = [_table_cell(c, name, factor, digits, c.index in after) for c in shown]
            stats = analysis.summary[name]
            spread = "" if stats["std"] is None else f" ± {stats['std'] * factor:.2g}"
            mean = "" if stats["mean"] is None else f"{stats['mean'] * factor:.{digits}g}{spread}"
            if name == "slip_time" and between:  # the mean is over the timed slips (summary): the others bounded
                bound = f"< {max(c.slip_time_bound for c in between):.3g}"
                mean = f"{mean} ({len(between)}: {bound})" if mean else bound
            table.add_row(escape(heading), *cells, mean)
        parts.append(table)
        parts.append(escape(_model_note(analysis.parameters.name)))
        if between:
            parts.append(escape(_between_samples_note(between, analysis.cycles)))
        if len(shown) < len(analysis.cycles):
            parts.append(
                f"the table shows the first {len(shown)} of {len(analysis.cycles)} cycles;"
                " -o cycles.csv or --json gives every one"
            )
        if any(not c.complete for c in analysis.cycles):
            notes = [f"cycle {c.index}: {c.message}" for c in analysis.cycles if c.message]
            parts.append(escape("* cut by the record's ends or by a gap in it.  " + "; ".join(notes)))
            parts.append(escape(summary_note(analysis.summary)))  # the mean leaves them out: which, and why
    if "mean_stress" in analysis.summary:
        s = analysis.summary
        spread = "" if s["stress_std"] is None else f" ± {s['stress_std']:.3g} Pa (sd of {s['steady_samples']} samples)"
        if s.get("stress_sem") is not None and s.get("steady_effective_samples") is not None:
            spread += (
                f"; standard error of the mean {s['stress_sem']:.2g} Pa ({s['steady_effective_samples']:.4g} effective"
                f" samples: correlation time {s['stress_correlation_time']:.3g} s)"
            )
        parts.append(
            escape(f"steady sliding from t = {s['steady_from']:.6g} s: mean stress {s['mean_stress']:.6g} Pa{spread}")
        )
    if comparison is not None:
        parts.append(escape(_comparison_text(comparison)))
    return parts


def _model_note(parameter_set: str | None = None) -> str:
    from ..analysis.cycles import MODEL_DERIVED

    headings = {name: heading for name, heading, _, _ in TABLE_ROWS}
    note = "(model) " + "; ".join(f"{headings[name].split(' [')[0]}: {how}" for name, how in MODEL_DERIVED.items())
    return note if parameter_set is None else f"{note} (here {parameter_set})"


def _comparison_text(comparison: Any) -> str:
    lines = [f"model ({comparison.model_regime}): {comparison.message}"]
    if comparison.rms_misfit is not None:
        lines.append(f"RMS misfit {comparison.rms_misfit:.4g} Pa over {comparison.points} samples")
    for row in comparison.cycles[:TABLE_CYCLES]:
        diff = row["difference"]
        shown = [
            f"{label} {diff[name] * factor:+.4g}{unit}"
            for name, label, factor, unit in (
                ("critical_stress", "Δσc", 1.0, " Pa"),
                ("peak_stress", "Δσs", 1.0, " Pa"),
                ("stick_time", "Δts", 1.0, " s"),
                ("slip_time", "Δslip", 1.0, " s"),
            )
            if diff[name] is not None
        ]
        lines.append(f"record cycle {row['record_cycle']} - model cycle {row['model_cycle']}: " + ", ".join(shown))
    if len(comparison.cycles) > TABLE_CYCLES:
        lines.append(f"(first {TABLE_CYCLES} of {len(comparison.cycles)} compared cycles; --json gives every one)")
    return "\n".join(lines)


def _table_cell(cycle: Any, name: str, factor: float, digits: int, began_between: bool) -> str:
    """A cycle's value in the table; a slip between samples as its bound ("< 0.1"), and σs before it and σc after
    it with their resolution (± the stick slope times half the sampling interval)."""
    value = getattr(cycle, name)
    if name == "slip_time" and cycle.slip_time_bound is not None:
        return f"< {cycle.slip_time_bound:.3g}"
    text = _number(value, factor, digits)
    resolution = None
    if name == "peak_stress" and cycle.slip_time_bound is not None:
        resolution = cycle.peak_stress_uncertainty
    elif name == "critical_stress" and began_between:
        resolution = cycle.critical_stress_uncertainty
    return text if value is None or resolution is None else f"{text} ± {resolution * factor:.2g}"


def _between_samples_note(between: list[Any], cycles: Any) -> str:
    """What the table's bounds and ± mean where slips fall between samples."""
    names = ", ".join(str(c.index) for c in between[:8]) + (f" and {len(between) - 8} more" if len(between) > 8 else "")
    return (
        f"the drop of cycle(s) {names} falls between two samples, each on its stick line: the slip lasts less than"
        " that sampling interval (< shown), and σs before it and σc after it are read at the interval's middle,"
        " ± the stick slope times half the interval (their resolution, not noise); ts and the period run between"
        " those middles"
    )


def _number(value: float | None, factor: float, digits: int) -> str:
    return "--" if value is None else f"{value * factor:.{digits}g}"


def register(cli: click.Group) -> None:
    """Add ``stickslip analyze`` to the group."""
    cli.add_command(analyze_command)
