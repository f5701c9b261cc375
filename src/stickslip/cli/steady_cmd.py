"""``stickslip curve`` and ``stickslip critical``: the steady friction curve (Eqs 6-8) and its minimum (Eq 9).

Output in SI base units for machines (csv, json) and in um/s and Pa for
people (the rich table and the ``critical`` summary).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click
import numpy as np

from ..columns import CSV_DIGITS, header_cell, unit_of
from ..errors import ParameterError
from .common import (
    FILE_PATH,
    emit_json,
    params_options,
    positive,
    refuse_overwriting_inputs,
    resolve_params,
    save_figure,
    write_failed,
)
from .params_cmd import human, print_rich

DEFAULT_VMIN = "10 um/s"
DEFAULT_VMAX = "10 mm/s"
DEFAULT_POINTS = 50
#: Most velocities one ``curve`` run evaluates (csv streams them in chunks: about a minute and 1 GB of file).
MAX_POINTS = 10_000_000
#: Velocities evaluated and written at a time, so that memory does not grow with --points.
CHUNK = 8192
#: Most rows the table prints (a terminal shows no more); beyond, it shows this many, evenly spread.
TABLE_ROWS = 100
#: Most velocities in --format json (one document in memory); csv has no such limit.
JSON_POINTS = 100_000
#: Columns of csv/json output, with the SI unit written in the csv header (:mod:`stickslip.columns`).
COLUMNS = tuple((name, unit_of(name)) for name in ("velocity", "stress", "bonded_fraction", "stress_slope"))


def _velocity(text: str, name: str) -> float:
    """A positive, finite velocity from an option value with its unit (a bare number other than 0 is refused)."""
    value = positive(text, "velocity", name)
    if value > SPEED_OF_LIGHT:  # no sliding is faster; and far above it the curve's numbers leave the float range
        raise ParameterError(
            f"{name} {text!r}: expected a velocity below the speed of light (3e8 m/s), got {value:g} m/s"
        )
    return value


#: The speed of light (m/s): no velocity of a sliding block is above it.
SPEED_OF_LIGHT = 299_792_458.0


def _velocities(
    velocity: tuple[str, ...], vmin: str | None, vmax: str | None, points: int | None
) -> tuple[np.ndarray, float, float]:
    """The velocities to evaluate, and the range (m/s) to plot."""
    if velocity:
        used = [flag for flag, value in (("--vmin", vmin), ("--vmax", vmax), ("--points", points)) if value is not None]
        if used:
            raise click.UsageError(f"--velocity cannot be combined with {', '.join(used)}: give a list or a range")
        values = np.array([_velocity(text, "--velocity") for text in velocity])
        lo = min(_velocity(DEFAULT_VMIN, "--vmin"), float(values.min()) / 1.5)
        hi = max(_velocity(DEFAULT_VMAX, "--vmax"), float(values.max()) * 1.5)
        return values, lo, hi
    low_text = vmin if vmin is not None else DEFAULT_VMIN
    high_text = vmax if vmax is not None else DEFAULT_VMAX
    lo, hi = _velocity(low_text, "--vmin"), _velocity(high_text, "--vmax")
    if lo >= hi:
        raise ParameterError(f"--vmin {low_text!r} ({lo:g} m/s) must be below --vmax {high_text!r} ({hi:g} m/s)")
    count = DEFAULT_POINTS if points is None else points
    return np.geomspace(lo, hi, count), lo, hi


def _csv_header() -> bytes:
    return (",".join(header_cell(name, unit) for name, unit in COLUMNS) + "\n").encode()


def _csv_rows(columns: dict[str, np.ndarray]) -> bytes:
    """Rows at 15 significant digits (:data:`stickslip.columns.CSV_DIGITS`), the numbers of the JSON output: ``1e-05``
    for "10 um/s", not the ``0.000009999999999999999`` of its 9.999999999999999e-06 that every digit wrote.  One
    format per row (~2 s per million rows)."""
    row = ",".join([f"{{:.{CSV_DIGITS}g}}"] * len(COLUMNS)) + "\n"
    values = [np.asarray(columns[name], dtype=float).tolist() for name, _ in COLUMNS]
    return "".join(map(row.format, *values)).encode()


def _evaluate(params: Any, velocities: np.ndarray, aging: bool) -> dict[str, np.ndarray]:
    from ..quasistatic.steady import steady_state

    result = steady_state(params, velocities, aging=aging)
    columns = {name: np.ravel(getattr(result, name)) for name, _ in COLUMNS}
    for name, values in columns.items():  # never print inf or nan: say where the numbers ran out
        bad = ~np.isfinite(values)
        if bad.any():
            where = float(np.ravel(velocities)[np.argmax(bad)])
            raise ParameterError(
                f"the steady curve's {name} cannot be computed at V = {where:.4g} m/s with these parameters"
                " (a number leaves the floating-point range); give a narrower --vmin/--vmax or --velocity"
            )
    return columns


def _stream_csv(params: Any, velocities: np.ndarray, aging: bool, output: Path | None) -> None:
    """Evaluate and write CHUNK velocities at a time: memory stays flat whatever --points is."""

    # both ends first: a velocity outside what the model integrates fails there, before a header is written
    # to standard output with nothing after it
    _evaluate(params, velocities[[0, -1]], aging)

    def write_all(write: Any) -> None:
        write(_csv_header())
        for start in range(0, velocities.size, CHUNK):
            write(_csv_rows(_evaluate(params, velocities[start : start + CHUNK], aging)))

    if output is None:
        write_all(lambda chunk: click.echo(chunk.decode("utf-8"), nl=False))
        return
    from ..fileio import atomic_open

    try:
        with atomic_open(output, "wb") as handle:
            write_all(handle.write)
    except OSError as exc:
        raise write_failed(output, exc) from None


def _table_picks(count: int) -> np.ndarray:
    """Indices of the rows the table shows: all of them, or TABLE_ROWS evenly spread with both ends."""
    if count <= TABLE_ROWS:
        return np.arange(count)
    return np.unique(np.linspace(0, count - 1, TABLE_ROWS).round().astype(int))


def curve_table(columns: dict[str, np.ndarray], title: str) -> Any:
    """A rich table in um/s and Pa, with the branch (sign of dsigma/dV) of each row."""
    from rich.table import Table

    table = Table(title=title, title_justify="left")
    for heading in ("V [µm/s]", "σ [Pa]", "N/N0", "dσ/dV [Pa s/mm]", "branch"):
        table.add_column(heading, justify="right" if heading != "branch" else "left")
    for v, s, n, d in zip(*(columns[name] for name, _ in COLUMNS), strict=True):
        branch = "weakening" if d < 0 else "strengthening" if d > 0 else "extremum"
        table.add_row(f"{v * 1e6:.6g}", f"{s:.6g}", f"{n:.4g}", f"{d * 1e-3:.5g}", branch)
    return table


@click.command("curve")
@click.option("--vmin", default=None, metavar="V", help=f"Lowest velocity of the range [default: {DEFAULT_VMIN}].")
@click.option("--vmax", default=None, metavar="V", help=f"Highest velocity of the range [default: {DEFAULT_VMAX}].")
@click.option(
    "--points",
    type=click.IntRange(min=2, max=MAX_POINTS),
    default=None,
    help=f"Number of log-spaced velocities [default: {DEFAULT_POINTS}; at most {MAX_POINTS:,}].",
)
@click.option(
    "--velocity",
    multiple=True,
    metavar="V",
    help='A velocity to evaluate, e.g. "350 um/s" (repeatable; replaces the range).',
)
@click.option("--no-aging", is_flag=True, help="Drop the aging term of Eq 6 (the paper's no-aging curve).")
@click.option(
    "--format", "fmt", type=click.Choice(["table", "csv", "json"]), default="table", show_default=True, help="Output."
)
@click.option("-o", "--output", type=FILE_PATH, help="Write the output here.")
@click.option(
    "--plot",
    "plot_path",
    type=FILE_PATH,
    help="Also save the figure of Fig 1/Fig 4 (σ against log V, with and without aging).",
)
@params_options
def curve_command(
    vmin: str | None,
    vmax: str | None,
    points: int | None,
    velocity: tuple[str, ...],
    no_aging: bool,
    fmt: str,
    output: Path | None,
    plot_path: Path | None,
    params_name: str,
    overrides: tuple[str, ...],
) -> None:
    """The steady friction curve σ(V) of Eqs 6-8.

    Velocities carry their unit ("350 um/s", "1 mm/s"; a bare number is refused).
    csv and json are in SI base units; the table uses µm/s and Pa.  csv is
    computed and written in chunks (any --points); the table shows at most
    100 rows, evenly spread; json holds at most 100,000 velocities.
    """
    printed = f"--format {fmt} (no -o)" if output is None and fmt != "table" else None  # a table is for people
    refuse_overwriting_inputs([], [("-o", output), ("--plot", plot_path)], params_name, printed)
    values, lo, hi = _velocities(velocity, vmin, vmax, points)
    params = resolve_params(params_name, overrides)
    aging = not no_aging
    if fmt == "json":
        if values.size > JSON_POINTS:
            raise ParameterError(
                f"--format json holds at most {JSON_POINTS} velocities, got {values.size};"
                f" --format csv -o FILE streams up to {MAX_POINTS}"
            )
        emit_json(_evaluate(params, values, aging), output)
    elif fmt == "csv":
        _stream_csv(params, values, aging, output)
    else:
        picks = _table_picks(values.size)
        title = f"Steady friction curve, {params.name}, {'without' if no_aging else 'with'} aging"
        parts: list[Any] = [curve_table(_evaluate(params, values[picks], aging), title)]
        if picks.size < values.size:
            parts.append(
                f"{picks.size} of {values.size} velocities shown, evenly spread; --format csv -o FILE writes every one"
            )
        print_rich(*parts, output=output)
    if plot_path is not None:
        stress = _evaluate(params, values, aging)["stress"] if velocity else None  # marks only for --velocity
        from ..plots.steady import figure_steady_curve
        from ..plots.style import UM_PER_S

        fig = figure_steady_curve(params, vmin=lo, vmax=hi)
        if stress is not None:  # the requested velocities, on the curve they were computed with
            ax = fig.axes[0]
            label = "requested (without aging)" if no_aging else "requested (with aging)"
            ax.plot(values * UM_PER_S, stress, "s", markersize=6, color="#e67e22", label=label, zorder=8)
            ax.legend(loc="lower right", frameon=False)
        save_figure(fig, plot_path)


@click.command("critical")
@click.option("--json", "as_json", is_flag=True, help="Print JSON in SI units.")
@click.option(
    "--plot",
    "plot_path",
    type=FILE_PATH,
    help="Also save the steady curves around Vc (a decade either side) with the critical point marked.",
)
@params_options
def critical_command(as_json: bool, plot_path: Path | None, params_name: str, overrides: tuple[str, ...]) -> None:
    """Vc and σc (Eq 9): the minimum of the aging curve.

    Also prints the maximum (turnover) of the no-aging curve.  When the
    curve has no minimum the message says why, and the exit status is 0.
    """
    from ..quasistatic.critical import critical_point

    refuse_overwriting_inputs([], [("--plot", plot_path)], params_name)
    params = resolve_params(params_name, overrides)
    point = critical_point(params)
    if plot_path is not None:
        from ..plots.steady import figure_steady_curve

        centre = point.velocity if point.exists else 1e-4  # no minimum: the paper's range of velocities
        save_figure(figure_steady_curve(params, vmin=centre / 10, vmax=centre * 10), plot_path)
    if as_json:
        emit_json(point.as_dict())
        return
    lines = [f"Critical point (Eq 9), parameter set {params.name}:"]
    if point.exists:
        lines += [
            f"  Vc  = {point.velocity * 1e6:.6g} µm/s   (critical velocity: minimum of the aging curve)",
            f"  σc  = {point.stress:.6g} Pa   (critical stress)",
        ]
    else:
        lines.append(f"  none: {point.message}")
    lines.append("No-aging curve turnover (its maximum; jump velocities lie below it):")
    if point.turnover_velocity is not None:
        lines += [
            f"  V   = {human(point.turnover_velocity, 'velocity')}",
            f"  σ   = {point.turnover_stress:.6g} Pa",
        ]
    else:
        lines.append(f"  none: {point.turnover_message}")
    click.echo("\n".join(lines))


def register(cli: click.Group) -> None:
    """Add ``stickslip curve`` and ``stickslip critical`` to the group."""
    cli.add_command(curve_command)
    cli.add_command(critical_command)
