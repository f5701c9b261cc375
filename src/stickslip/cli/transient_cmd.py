"""``stickslip transient``: the time-dependent population balance (Eqs 1-5) through any loading protocol."""

from __future__ import annotations

import stat
import tempfile
from pathlib import Path
from typing import Any

import click

from ..errors import ParameterError
from ..units import shorten
from .common import (
    emit_json,
    params_options,
    positive,
    refuse_overwriting_inputs,
    resolve_params,
    save_figure,
    write_text,
)


def _check_output(option: str, path: Path | None, plot: bool = False) -> None:
    """Refuse, before computing, an output that cannot be written: no name, no such folder, an unknown format."""
    if path is None:
        return
    text = str(path)
    if not text.strip() or text == ".":
        raise ParameterError(f"{option}: expected a file name, got an empty one")
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise ParameterError(f"{option} {shorten(text)}: the folder {shorten(str(folder))} does not exist")
    try:
        info = path.stat()
    except OSError:
        info = None
    if info is not None and stat.S_ISDIR(info.st_mode):
        raise ParameterError(f"{option} {shorten(text)}: that is a folder, not a file")
    if info is None or stat.S_ISREG(info.st_mode):  # written beside, then renamed: the folder must take a file
        try:
            with tempfile.TemporaryFile(dir=folder):
                pass
        except OSError as exc:
            reason = exc.strerror or str(exc)
            raise ParameterError(
                f"{option} {shorten(text)}: cannot write in {shorten(str(folder))} ({reason})"
            ) from None
    if plot:
        from matplotlib.figure import Figure

        formats = Figure().canvas.get_supported_filetypes()
        suffix = path.suffix[1:].lower() or "png"
        if suffix not in formats:
            raise ParameterError(
                f"{option} {shorten(text)}: unknown figure format .{suffix};"
                f" expected one of {', '.join(sorted(formats))}"
            )


def _protocol(v0_text: str | None, duration_text: str | None, segment_texts: tuple[str, ...], protocol_file: Any):
    from ..protocols import Protocol, Segment, parse_segment, read_protocol

    if protocol_file is not None:
        if segment_texts or v0_text is not None:
            raise ParameterError("--protocol: give either a protocol file or --v0/--duration/--segment, not both")
        return read_protocol(protocol_file)
    if v0_text is None or duration_text is None:
        raise ParameterError("--v0 and --duration: both are needed (or --protocol FILE)")
    first = Segment(
        positive(v0_text, "velocity", "--v0", allow_zero=True), positive(duration_text, "time", "--duration")
    )
    return Protocol((first, *(parse_segment(text) for text in segment_texts)))


def _trace_csv(result: Any) -> str:
    from ..columns import csv_text

    return csv_text(result.to_frame())


@click.command("transient")
@click.option("--v0", "v0_text", metavar="V", help='Velocity of the first segment, e.g. "50 um/s".')
@click.option("--duration", "duration_text", metavar="T", help='Length of the first segment, e.g. "25 s".')
@click.option(
    "--control",
    type=click.Choice(["block", "velocity"]),
    default="block",
    show_default=True,
    help="block: the protocol moves the puller; velocity: it moves the slider (rigid rig).",
)
@click.option("--start", type=click.Choice(["empty", "steady"]), default="empty", show_default=True)
@click.option("--start-velocity", "start_v_text", metavar="V", help="Steady start at this velocity [first segment's].")
@click.option("--segment", "segment_texts", multiple=True, metavar='"V:T"', help='Further segments, e.g. "1 mm/s:2 s".')
@click.option("--protocol", "protocol_file", type=click.Path(dir_okay=False, path_type=Path), help="Protocol CSV.")
@click.option("--no-aging", is_flag=True, help="Drop the aging term of Eq 1.")
@click.option("--stick-population", is_flag=True, help="Add the paper's attached chains (Eqs 13-15) at rest.")
@click.option(
    "--every",
    "every_text",
    metavar="DT",
    help="Sample the trace every DT (the solver lands on the grid; jumps of the stick chains add their instant).",
)
@click.option("--rtol", default=1e-4, show_default=True, type=float, help="Local error tolerance (relative).")
@click.option(
    "--no-reduce",
    is_flag=True,
    help="Cohorts throughout: no quasi-steady reduction where the slider changes pace slowly (the reference).",
)
@click.option(
    "--max-steps",
    type=click.IntRange(min=1),
    default=None,
    help="Step budget: runs estimated to need more are refused, runs that get there stop [3e6].",
)
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path), help="Write the trace (CSV, SI).")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path), help="Save σ(t) and V(t) here.")
@click.option("--json", "as_json", is_flag=True, help="Print the summary as JSON (SI units).")
@params_options
def transient_command(
    v0_text: str | None,
    duration_text: str | None,
    control: str,
    start: str,
    start_v_text: str | None,
    segment_texts: tuple[str, ...],
    protocol_file: Path | None,
    no_aging: bool,
    stick_population: bool,
    every_text: str | None,
    rtol: float,
    no_reduce: bool,
    max_steps: int | None,
    output: Path | None,
    plot_path: Path | None,
    as_json: bool,
    params_name: str,
    overrides: tuple[str, ...],
) -> None:
    """Solve the full time-dependent population balance (Eq 1, history form of Eq 3) through a protocol.

    With --control block the protocol is the puller's velocity and the block
    (Eq 17) couples it to the slider; with --control velocity it is the
    slider's own velocity.  The regime is "steady", "stick-slip", "stuck" or
    "undetermined" (still changing at the end of the run).

    The work is estimated before the run starts; a run estimated to need more
    than the step budget (--max-steps, default 3e6) is refused in one line.
    """
    from ..numerics.budget import PROGRESS_AFTER_SECONDS
    from ..progress import progress
    from ..transient import run_transient
    from ..transient.solver import estimate_cost

    _check_output("-o", output)
    _check_output("--plot", plot_path, plot=True)
    protocol = _protocol(v0_text, duration_text, segment_texts, protocol_file)
    refuse_overwriting_inputs([protocol_file], [("-o", output), ("--plot", plot_path)], params_name)
    start_velocity = None if start_v_text is None else positive(start_v_text, "velocity", "--start-velocity")
    every = None if every_text is None else positive(every_text, "time", "--every")
    params = resolve_params(params_name, overrides)
    kwargs = dict(control=control, start=start, start_velocity=start_velocity, aging=not no_aging,
                  stick_population=stick_population, every=every, rtol=rtol, max_steps=max_steps,
                  reduction="off" if no_reduce else "auto")  # fmt: skip
    cost = estimate_cost(params, protocol, control=control, start_velocity=start_velocity, rtol=rtol, every=every,
                         aging=not no_aging)  # fmt: skip
    shown = None if cost.seconds > PROGRESS_AFTER_SECONDS and not as_json else False  # None: on a terminal
    with progress("transient", total=protocol.duration, unit="s", enabled=shown) as bar:
        result = run_transient(params, protocol, progress=lambda f: bar.update(f * protocol.duration), **kwargs)
    if output is not None:
        write_text(output, _trace_csv(result))
    if plot_path is not None:
        ax = result.plot()
        ax.set_title(f"{protocol.describe()}: {result.regime}", fontsize=9)
        save_figure(ax.figure, plot_path)
    if as_json:
        emit_json(result.summary())
        return
    click.echo(f"{protocol.describe()} ({control} control, {start} start)")
    click.echo(f"  regime: {result.regime}")
    click.echo(f"  {result.message}")
    click.echo(
        f"  at t = {result.time[-1]:.6g} s: σ = {result.final_stress:.6g} Pa,"
        f" N/N0 = {result.final_bonded_fraction:.6g},"
        f" V = {result.slider_velocity[-1] * 1e6:.6g} µm/s ({result.steps} steps)"
    )
    for c in result.cycles:
        slip = "—" if c.slip_time is None else f"{c.slip_time:.4g} s"
        click.echo(
            f"  cycle {c.index + 1}: stick {c.stick_time:.4g} s, σs = {c.peak_stress:.5g} Pa,"
            f" jump to {c.jump_velocity * 1e6:.4g} µm/s, slip {slip}"
        )


def register(cli: click.Group) -> None:
    cli.add_command(transient_command)
