"""``stickslip compare``: the bond model and rate-and-state friction on the same experiments, in one figure.

Three panels: a velocity step, a slide-hold-slide (both under velocity control
of the slider for the bond model; RSF on its spring-slider) and stick-slip (the
bond model's jump cycle beside the RSF limit cycle with radiation damping, at
the same pulling velocity, stiffness and sigma_c).  Friction is stress over
sigma_c on both sides.  The output states the RSF a, b, Dc standing for the bond
model and, in words, which bond model ran (time-dependent or quasi-static).
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import click

from ..errors import ModelError, ParameterError
from ..fileio import refuse_input_as_output
from .common import json_safe, params_options, positive, quantity, resolve_params
from .rsf_cmd import save_figure, sidecar, write


@click.command("compare")
@params_options
@click.option("--v0", default="200 um/s", show_default=True, help="Velocity before the step (and of the slides).")
@click.option("--v1", default="2 mm/s", show_default=True, help="Velocity after the step.")
@click.option("--step-time", default="2 s", show_default=True, help="Duration of each velocity of the step.")
@click.option("--hold", default="1 s", show_default=True, help="Hold time of the slide-hold-slide.")
@click.option("--pull", default="50 um/s", show_default=True, help="Pulling velocity of the stick-slip pair.")
@click.option("--duration", default="120 s", show_default=True, help="Duration of the stick-slip pair.")
@click.option(
    "--bond-model",
    type=click.Choice(["quasi-static", "transient"]),
    default="quasi-static",
    show_default=True,
    help="Bond model of the step and slide-hold-slide panels; transient (Eqs 1-5): seconds of CPU per second.",
)
@click.option("--eta", default=None, help="RSF radiation damping (s/m) [a/(100 V0)].")
@click.option("--a", "rsf_a", default=None, help="Override the RSF a standing for the bond model.")
@click.option("--b", "rsf_b", default=None, help="Override the RSF b.")
@click.option("--dc", "rsf_dc", default=None, help='Override the RSF Dc, e.g. "50 um".')
@click.option("--json", "as_json", is_flag=True, help="Print the summary as JSON (SI units).")
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path), help="Save the figure here.")
def compare_command(**options: Any) -> None:
    """The bond model beside rate-and-state friction fitted to it: velocity step, slide-hold-slide, stick-slip."""
    from .. import protocols
    from ..rsf import simulate
    from ..rsf.compare import bond_response, rsf_of_bond, stick_slip_pair

    params = resolve_params(options["params_name"], options["overrides"])
    v0 = positive(options["v0"], "velocity", "--v0")
    v1 = positive(options["v1"], "velocity", "--v1")
    step_time = positive(options["step_time"], "time", "--step-time")
    hold = positive(options["hold"], "time", "--hold")
    pull = positive(options["pull"], "velocity", "--pull")
    duration = positive(options["duration"], "time", "--duration")
    eta = None if options["eta"] is None else positive(options["eta"], "slowness", "--eta", allow_zero=True)
    if options["rsf_a"] is not None:  # checked here, so the error names --a rather than a panel of the run
        positive(options["rsf_a"], "dimensionless", "--a")
    if options["rsf_b"] is not None:
        quantity(options["rsf_b"], "dimensionless", "--b")
    if options["rsf_dc"] is not None:
        positive(options["rsf_dc"], "length", "--dc")
    refuse_input_as_output([options["params_name"]], [("-o", options["output"])])

    steps = f"the velocity step and slide-hold-slide (--v0 {options['v0']}, --v1 {options['v1']})"
    with _naming(steps):
        rsf = _override(rsf_of_bond(params, v0, v1, step_time, model=options["bond_model"]), options)
        step = protocols.velocity_steps([v0, v1], [step_time, step_time])
        shs = protocols.slide_hold_slide(v0, step_time, hold)
        panels = {}
        for name, protocol in (("velocity step", step), ("slide-hold-slide", shs)):
            bond = bond_response(params, protocol, "velocity", model=options["bond_model"])
            run = simulate(rsf.params, protocol, every=protocol.duration / 800)
            panels[name] = (bond, run)
    with _naming(f"the stick-slip pair (--pull {options['pull']})"):
        local = _override(rsf_of_bond(params, pull / 1.05, pull * 1.05), options)
        pair = stick_slip_pair(params, pull, duration, local, eta)
    summary = {
        "rsf_of_bond_model": rsf.as_dict(),
        "bond_model": panels["velocity step"][0].note,
        "stick_slip": {
            "pulling_velocity": pull,
            "stiffness": pair["stiffness"],
            "eta": pair["eta"],
            "rsf_parameters": local.as_dict(),
            "bond": {"regime": pair["bond"].regime, "message": pair["bond"].message},
            "rsf": pair["rsf"].summary(),
        },
    }
    if options["as_json"]:
        click.echo(json.dumps(json_safe(summary), indent=2))
    else:
        click.echo(_text(summary))
    if options["output"] is not None:
        save_figure(_figure(panels, pair, rsf, local), options["output"])
        write(sidecar(options["output"]), json.dumps(json_safe(summary), indent=2) + "\n")


@contextlib.contextmanager
def _naming(stage: str) -> Iterator[None]:
    """Say which panel (and so which options) an error of the model came from: compare runs several."""
    try:
        yield
    except (ParameterError, ModelError) as exc:
        raise type(exc)(f"{stage}: {exc}") from None


def _override(rsf: Any, options: dict[str, Any]) -> Any:
    """The RSF of the bond model with a, b, Dc replaced where the user gave them (said in its note)."""
    import dataclasses

    from ..rsf import StateVariable

    given = {k: options[k] for k in ("rsf_a", "rsf_b", "rsf_dc") if options.get(k) is not None}
    if not given:
        return rsf
    p = rsf.params
    s = p.states[0]
    a = quantity(given["rsf_a"], "dimensionless", "--a") if "rsf_a" in given else p.a
    b = quantity(given["rsf_b"], "dimensionless", "--b") if "rsf_b" in given else s.b
    dc = positive(given["rsf_dc"], "length", "--dc") if "rsf_dc" in given else s.dc
    note = rsf.note + "; overridden on the command line: " + ", ".join(f"{k[4:]} = {v}" for k, v in given.items())
    params = p.replace(a=a, states=(StateVariable(s.law, b, dc, s.c),))
    return dataclasses.replace(rsf, params=params, a_minus_b=a - b, note=note)


def _text(summary: dict[str, Any]) -> str:
    r = summary["rsf_of_bond_model"]
    s = summary["stick_slip"]
    return "\n".join([
        f"RSF standing for the bond model near {r['velocity'] * 1e6:.4g} um/s (friction = stress / sigma_c, "
        f"sigma_c = {r['sigma_c']:.4g} Pa): a = {r['a']:.4g}, b = {r['b']:.4g}, Dc = {r['dc'] * 1e6:.4g} um",
        f"  {r['note']}",
        f"bond model: {summary['bond_model']}",
        f"stick-slip at {s['pulling_velocity'] * 1e6:.4g} um/s, k = {s['stiffness']:.4g} 1/m, "
        f"eta = {s['eta']:.4g} s/m:",
        f"  bond model: {s['bond']['message']}",
        f"  RSF (a = {s['rsf_parameters']['a']:.4g}, b = {s['rsf_parameters']['b']:.4g}): {s['rsf']['regime']}; "
        f"{s['rsf']['message']}",
    ])  # fmt: skip


def _figure(panels: dict[str, Any], pair: dict[str, Any], rsf: Any, local: Any) -> Any:
    from matplotlib.figure import Figure

    from ..plotting import apply_style

    fig = Figure(figsize=(12, 4.2), layout="constrained")
    axes = fig.subplots(1, 3)
    sc = rsf.sigma_c
    for ax, (name, (bond, run)) in zip(axes[:2], panels.items(), strict=True):
        ax.plot(bond.time, bond.stress / sc, color="#1f4e9c", lw=1.6, label=bond.source)
        ax.plot(run.time, run.friction, color="#c0392b", lw=1.2, ls="--", label="rate-and-state")
        ax.set_title(name, fontsize=10)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("stress / σc")
        ax.legend(fontsize=7, frameon=False)
        apply_style(ax)
    ax = axes[2]
    bond, run = pair["bond"], pair["rsf"]
    ax.plot(bond.time, bond.stress / local.sigma_c, color="#1f4e9c", lw=1.4, label="bond model: jump cycle")
    ax.plot(run.time, run.friction, color="#c0392b", lw=1.0, label=f"RSF: {run.regime.name}")
    ax.set_title("stick-slip at the same V0, stiffness, σc", fontsize=10)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("stress / σc")
    ax.legend(fontsize=7, frameon=False)
    apply_style(ax)
    p = rsf.params
    how = "fitted" if rsf.determined else "a, Dc assumed: quasi-static bond model"
    if "overridden" in rsf.note:
        how = "given on the command line"
    fig.suptitle(f"RSF of the bond model: a = {p.a:.3g}, b = {p.b:.3g}, Dc = {p.dc * 1e6:.3g} µm ({how})", fontsize=9)
    return fig


def register(cli: click.Group) -> None:
    cli.add_command(compare_command)


__all__ = ["compare_command"]
