"""``stickslip simulate`` and ``stickslip stick``: stick-slip cycles (Eqs 10-17) and the stick phase (Eq 15).

Machines get SI base units (``--json``, the ``-o`` CSV with units in its
header); people get um/s, Pa and s.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click
import numpy as np

from .common import (
    FILE_PATH,
    emit_json,
    params_options,
    positive,
    refuse_overwriting_inputs,
    resolve_params,
    save_figure,
    write_text,
)
from .params_cmd import print_rich
from .protocol_options import protocol_options
from .run_cmd import output_options, run_spelling

#: Rows of the Nc/Nc0 table printed by ``stick`` (the whole curve is in --json and -o).
STICK_TABLE_ROWS = 11


def _velocity(text: str) -> float:
    return positive(text, "velocity", "--v0", allow_zero=True)


def _stress(text: str | None) -> float | None:
    if text is None:
        return None
    return positive(text, "stress", "--start-stress", allow_zero=True)


# --------------------------------------------------------------------------- simulate
@click.command("simulate")
@protocol_options(
    stiffness_help='Effective stiffness K of the block (Eq 17), e.g. "400 kPa/m" [from the block: Gd/h and B/l].'
)
@click.option(
    "--start-stress",
    "start_text",
    default=None,
    metavar="S",
    help="Stress at which the block starts stuck [default: σc].",
)
@click.option(
    "--jump-curve",
    type=click.Choice(["aging", "no-aging"]),
    default="aging",
    show_default=True,
    help="Steady curve the stick-to-slip jump lands on (aging keeps the stress continuous; see docs/errata.md).",
)
@output_options
@params_options
def simulate_command(**options: Any) -> None:
    """Simulate stick-slip: stick -> jump -> slip -> jump -> ... for a pulling velocity and duration.

    The spelling of `stickslip run --model quasi-static` (--start-stress is
    its --start, --jump-curve its --setting jump_curve=...): the same Run CSV
    (-o), the same figure (--plot), the same summary and the cycles below it.

    The quasi-static model is a spring (the block, or --stiffness K) pulled at
    one constant velocity: --v0 V --duration T (or one --segment "V:T", or a
    one-segment --protocol file); other protocols and --control velocity are
    refused (stickslip transient runs them).
    The block starts stuck at σc (or --start-stress) with fresh chains.  The
    regime is "stick-slip", "steady" (V0 >= Vc: the slip settles at V0),
    "stuck" (a stick never ends) or "undetermined" (the model has no answer).
    """
    run_spelling(
        "quasi-static",
        options,
        "simulate (the quasi-static model)",
        controls=("spring",),
        one_segment=True,
        instead="stickslip transient runs any protocol and rig",
        settings=lambda: {"jump_curve": options["jump_curve"]},
        start=lambda: _stress(options["start_text"]),
        start_option="--start-stress ",
    )


# --------------------------------------------------------------------------- stick
@click.command("stick")
@click.option(
    "--v0", "v0_text", required=True, metavar="V", help='Pulling velocity, e.g. "50 um/s"; 0 holds a constant load.'
)
@click.option(
    "--start-stress", "start_text", default=None, metavar="S", help="Stress at the instant of sticking [default: σc]."
)
@click.option("--no-aging", is_flag=True, help="Drop the aging term of Eq 15 (τa → ∞).")
@click.option(
    "--until",
    "until_text",
    default=None,
    metavar="T",
    help="When the block stays stuck, follow Nc/Nc0 up to this time [default: 10 aging times of Eq 15].",
)
@click.option("--json", "as_json", is_flag=True, help="Print the result and the Nc/Nc0 curve as JSON (SI units).")
@click.option("-o", "--output", type=FILE_PATH, help="Write the Nc/Nc0 curve as CSV.")
@click.option("--plot", "plot_path", type=FILE_PATH, help="Save Nc/Nc0(t) (Fig 6) here.")
@params_options
def stick_command(
    v0_text: str,
    start_text: str | None,
    no_aging: bool,
    until_text: str | None,
    as_json: bool,
    output: Path | None,
    plot_path: Path | None,
    params_name: str,
    overrides: tuple[str, ...],
) -> None:
    """The stick phase (Eqs 11-16): stick time ts, peak stress σs, and Nc/Nc0 against time.

    Says so when the block stays stuck for ever (aging wins over loading)
    instead of inventing a stick time.
    """
    from ..quasistatic.stick import stick_phase

    refuse_overwriting_inputs([], [("-o", output), ("--plot", plot_path)], params_name)
    v0 = _velocity(v0_text)
    start = _stress(start_text)
    params = resolve_params(params_name, overrides)
    if until_text is None:
        until = 10.0 * params.stick.aging_time
    else:
        until = positive(until_text, "time", "--until")
    stick = stick_phase(params, v0, start_stress=start, aging=not no_aging, horizon=until)
    jump = _jump_after(params, stick)
    if output is not None:
        from ..columns import csv_text

        write_text(output, csv_text(stick.to_frame()))
    if plot_path is not None:
        from ..plots.cycles import plot_stick

        ax = plot_stick(stick)
        ax.legend(loc="lower left", frameon=False, fontsize=8)
        ax.set_title(f"Attached chains, {params.name}: {stick.status}", fontsize=11)
        save_figure(ax.figure, plot_path)
    if as_json:
        extra = {"jump_velocity": jump.velocity, "jump_message": jump.message} if jump is not None else {}
        curve = {"time": stick.time, "stress": stick.stress, "chain_fraction": stick.chain_fraction}
        emit_json({**stick.as_dict(), **extra, "curve": curve})
        return
    print_rich(*_stick_report(stick, params.name, jump))


def _jump_after(params: Any, stick: Any) -> Any:
    """The jump that would follow the collapse (Eq 8), as ``simulate`` takes it; None when the block did not slip."""
    from ..errors import ModelError
    from ..quasistatic.jump import jump_velocity

    if stick.status != "slipped":
        return None
    try:
        return jump_velocity(params, stick.peak_stress)
    except ModelError:  # no critical point: the stick alone still has its answer
        return None


def _stick_report(stick: Any, name: str, jump: Any = None) -> list[Any]:
    from rich.table import Table

    detail = stick.message
    if stick.status == "slipped" and jump is not None and not jump.reachable:
        # the same verdict as simulate's "undetermined": no velocity on the steady curve carries sigma_s
        verdict = (
            f"  UNDETERMINED after the stick: the chains collapse at ts = {stick.stick_time:.6g} s, σs ="
            f" {stick.peak_stress:.6g} Pa, but no jump velocity exists ({jump.message})"
        )
        detail = "the model has no answer past this stick (simulate: regime undetermined)"
    elif stick.status == "slipped":
        verdict = f"  the block slips after ts = {stick.stick_time:.6g} s at σs = {stick.peak_stress:.6g} Pa"
    elif stick.stuck:
        verdict = "  THE BLOCK STAYS STUCK: it never slips (no stick time)"
    else:
        verdict = "  UNDETERMINED: no slip found, and no proof that the block stays stuck"
    head = [
        f"Stick phase (Eq 15), {name}: V0 = {stick.pulling_velocity * 1e6:.6g} µm/s, from {stick.start_stress:.6g} Pa,"
        f" {'with' if stick.aging else 'without'} aging",
        verdict,
        f"  {detail}",
    ]
    table = Table(title="Nc/Nc0 against time", title_justify="left")
    for heading in ("t (s)", "σ (Pa)", "Nc/Nc0"):
        table.add_column(heading, justify="right")
    picks = np.unique(np.linspace(0, stick.time.size - 1, STICK_TABLE_ROWS).round().astype(int))
    for k in picks:
        table.add_row(f"{stick.time[k]:.5g}", f"{stick.stress[k]:.5g}", f"{stick.chain_fraction[k]:.5f}")
    return ["\n".join(head), table]


def register(cli: click.Group) -> None:
    """Add ``stickslip simulate`` and ``stickslip stick`` to the group."""
    cli.add_command(simulate_command)
    cli.add_command(stick_command)
