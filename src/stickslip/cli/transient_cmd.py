"""``stickslip transient``: the time-dependent population balance (Eqs 1-5) through any loading protocol."""

from __future__ import annotations

from typing import Any

import click

from .common import params_options, positive
from .protocol_options import inertia_options, protocol_options
from .run_cmd import output_options, run_spelling


class StepCount(click.ParamType):
    """A step budget: a positive whole number in any float spelling (3e6, 3000000, 3_000_000)."""

    name = "steps"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> int:
        from ..errors import ParameterError
        from ..numerics.budget import parse_step_count

        if isinstance(value, int) and not isinstance(value, bool):
            return value
        try:
            return parse_step_count(value, "--max-steps")
        except ParameterError as exc:
            self.fail(str(exc).split(": ", 1)[1], param, ctx)


@click.command("transient")
@protocol_options(stiffness_help='Spring stiffness K with --control spring, e.g. "400 kPa/m" [the block\'s, Eq 17].')
@inertia_options
@click.option("--start", type=click.Choice(["empty", "steady"]), default="empty", show_default=True)
@click.option("--start-velocity", "start_v_text", metavar="V", help="Steady start at this velocity [first segment's].")
@click.option("--no-aging", is_flag=True, help="Drop the aging term of Eq 1.")
@click.option("--stick-population", is_flag=True, help="Add the paper's attached chains (Eqs 13-15) at rest.")
@click.option(
    "--every",
    "every_text",
    metavar="DT",
    help="Sample the trace every DT (rows on the grid; jumps of the stick chains add their instant; a settled"
    " cycle is still repeated, docs/transient.md §10).",
)
@click.option("--rtol", default=1e-4, show_default=True, type=float, help="Local error tolerance (relative).")
@click.option(
    "--no-reduce",
    is_flag=True,
    help="Cohorts throughout: no quasi-steady reduction where the slider changes pace slowly (the reference).",
)
@click.option(
    "--max-steps",
    type=StepCount(),
    default=None,
    help="Step budget (3e6, 3000000 or 3_000_000): a run stops when it gets there, and a run estimated at more"
    " than 10x is refused [3e6].",
)
@click.option(
    "--max-time",
    "max_time_text",
    metavar="T",
    help='CPU time budget, e.g. "30 min": a run stops when it gets there, and a run estimated at more than 3x is'
    " refused [10 min].",
)
@output_options
@params_options
def transient_command(**options: Any) -> None:
    """Solve the full time-dependent population balance (Eq 1, history form of Eq 3) through a protocol.

    The spelling of `stickslip run --model transient` (its options are run's
    --start and --setting KEY=VALUE): the same Run CSV (-o), the same figure
    (--plot), the same summary and the slip events below it.

    With --control spring (or block) the protocol is the puller's velocity and
    the block (Eq 17, or --stiffness K) couples it to the slider, without
    inertia unless --mass (and --damping) give the block's; with
    --control velocity it is the slider's own velocity.  The protocol:
    --v0 V --duration T, then any --segment "V:T"; or --protocol FILE.  The regime is "steady", "stick-slip", "stuck" or
    "undetermined" (still changing at the end of the run).

    The work is estimated first; a run estimated at more than 10x its step
    budget (--max-steps, default 3e6) or 3x its CPU time budget (--max-time,
    default 10 min) is refused in one line.  Any other run starts (with a
    progress bar on a terminal when it is expected to take more than 2 s) and
    stops only when it uses up a budget: then it says how far it got, writes
    the trace up to there (-o, --plot) and exits with status 3.
    """
    o = options

    def settings() -> dict[str, Any]:
        start_velocity = (
            None if o["start_v_text"] is None else positive(o["start_v_text"], "velocity", "--start-velocity")
        )
        every = None if o["every_text"] is None else positive(o["every_text"], "time", "--every")
        max_time = None if o["max_time_text"] is None else positive(o["max_time_text"], "time", "--max-time")
        return dict(start_velocity=start_velocity, aging=not o["no_aging"], stick_population=o["stick_population"],
                    every=every, rtol=o["rtol"], max_steps=o["max_steps"], max_time=max_time,
                    reduction="off" if o["no_reduce"] else "auto")  # fmt: skip

    run_spelling("transient", options, "transient", settings=settings, start=lambda: o["start"])


def register(cli: click.Group) -> None:
    cli.add_command(transient_command)
