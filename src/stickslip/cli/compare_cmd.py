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
from collections.abc import Iterator
from typing import Any

import click
import numpy as np

from ..columns import json_units
from ..errors import ModelError, ParameterError
from ..fileio import refuse_input_as_output
from ..progress import progress
from .common import (
    FILE_PATH,
    json_safe,
    json_text,
    params_options,
    positive,
    quantity,
    resolve_params,
    save_figure,
    write_text,
)
from .protocol_options import protocol_options
from .rsf_cmd import sidecar

#: The protocol sets of ``compare --models A,B --protocol-set NAME``: each runs its own protocols (options
#: --v0/--v1/--step-time/--hold/--pull/--duration) on its models; bond-vs-rsf takes a bond model and rsf.
PROTOCOL_SETS = {"bond-vs-rsf": ("quasi-static", "transient")}

#: The classic compare's --v0 and --duration when not given (with --models they are the protocol's first segment).
CLASSIC_V0, CLASSIC_DURATION = "200 um/s", "120 s"


#: Units of the protocol set's JSON keys that the package's registry does not know or names otherwise.
_SET_UNITS = {
    "stiffness": "1/m",
    "sigma_c": "Pa",
    "rsf_a_minus_b": "1",
    "bond_steady_slope": "1",
    "bond_max": "1",
    "bond_final": "1",
    "rsf_max": "1",
    "rsf_min": "1",
}


@click.command("compare")
@params_options
@click.option(
    "--models",
    "models",
    default=None,
    metavar="A,B[,...]",
    help="Run these models (registered names or module:attr) on one protocol and rig, side by side: a table of"
    " regime, period, peak, trough and mean, and an overlay figure (-o).",
)
@protocol_options(
    stiffness_help="--models: the rig's spring K for every model, in Pa/m, e.g. \"400 kPa/m\" [each model's own]."
)
@click.option(
    "--start",
    "start_texts",
    multiple=True,
    metavar="[MODEL=]S",
    help="--models: a model's start, as run --start takes it (transient: empty, steady; rsf: a velocity;"
    " quasi-static: a stress); MODEL=S for one model, S for every model; repeatable.",
)
@click.option(
    "--setting",
    "setting_texts",
    multiple=True,
    metavar="KEY=VALUE",
    help="--models: a run setting (e.g. stick_population=true) for each model that takes it; repeatable.",
)
@click.option("--every", "every_text", default=None, metavar="DT", help="--models: sample each trace every DT.")
@click.option(
    "--protocol-set",
    "protocol_set",
    type=click.Choice(sorted(PROTOCOL_SETS)),
    default=None,
    help="Run --models (a bond model and rsf) on a set of protocols instead of one: bond-vs-rsf is the velocity"
    " step, slide-hold-slide and stick-slip, rate-and-state fitted to the bond model's step (plain"
    " `stickslip compare` runs it with --models quasi-static,rsf).",
)
@click.option("--v1", default="2 mm/s", show_default=True, help="Velocity after the step.")
@click.option("--step-time", default="2 s", show_default=True, help="Duration of each velocity of the step.")
@click.option("--hold", default="1 s", show_default=True, help="Hold time of the slide-hold-slide.")
@click.option("--pull", default="50 um/s", show_default=True, help="Pulling velocity of the stick-slip pair.")
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
@click.option("-o", "--output", type=FILE_PATH, help="Save the figure here.")
def compare_command(**options: Any) -> None:
    """Models side by side on one protocol (--models A,B), or on a protocol set (--protocol-set).

    --models quasi-static,rsf --protocol-set bond-vs-rsf (plain `stickslip compare`, its older spelling, the
    same run): the bond model beside rate-and-state fitted to it, on a velocity step, a slide-hold-slide and
    stick-slip (--v0 is the velocity before the step [200 um/s], --duration that of the stick-slip pair
    [120 s]; --models transient,rsf or --bond-model transient for the time-dependent bond model).

    With --models A,B alone: every model runs the protocol of --v0/--duration/
    --segment/--protocol through the rig of --control/--stiffness; --set KEY=VALUE goes to each model that has
    the key (stickslip.models).  A run that failed makes the exit status 3.
    """
    if options["models"] is not None and options["protocol_set"] is None:
        from .compare_models import compare_models

        compare_models(options)
        return
    options["bond_model"] = _bond_model_of(options)
    _refuse_model_options(options)
    options["v0"] = options["v0_text"] or CLASSIC_V0
    options["duration"] = options["duration_text"] or CLASSIC_DURATION
    from .. import protocols
    from ..studies.bond_rsf import bond_response, rsf_of_bond, stick_slip_pair

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
    # four stages (the fit, two panels, the stick-slip pair): a bar on a terminal, nothing in a pipe or with --json
    with progress("compare", total=4, unit="stages", enabled=False if options["as_json"] else None) as bar:
        with _naming(steps):
            rsf = _override(rsf_of_bond(params, v0, v1, step_time, model=options["bond_model"]), options)
            bar.advance(note="RSF fitted to the step")
            step = protocols.velocity_steps([v0, v1], [step_time, step_time])
            shs = protocols.slide_hold_slide(v0, step_time, hold)
            panels = {}
            for name, protocol in (("velocity step", step), ("slide-hold-slide", shs)):
                bond = bond_response(params, protocol, "velocity", model=options["bond_model"])
                panels[name] = (bond, *_rsf_panel(rsf, protocol, bond.time))
                bar.advance(note=name)
        with _naming(f"the stick-slip pair (--pull {options['pull']})"):
            pair = stick_slip_pair(params, pull, duration, rsf, eta)
            bar.advance(note="stick-slip")
    failures = [] if rsf.usable else [rsf.note]
    summary = {
        "status": "failed" if failures else "ok",
        "failures": failures,
        "rsf_cannot_describe": _limitations(panels, pair) if rsf.usable else [],
        "rsf_of_bond_model": rsf.as_dict(),
        "bond_model": panels["velocity step"][0].note,
        "panels": {
            name: _panel_summary(bond, run, problem, rsf.sigma_c) for name, (bond, run, problem) in panels.items()
        },
        "stick_slip": {
            "pulling_velocity": pull,
            "stiffness": pair["stiffness"],
            "eta": pair["eta"],
            "bond": {"regime": pair["bond"].regime_name, "message": pair["bond"].message},
            "rsf": None if pair["rsf"] is None else pair["rsf"].summary(),
            "problem": pair["problem"],
        },
    }
    # the units map: friction is stress over sigma_c; the stick-slip pair's spring is rate-and-state's k (1/m)
    summary["units"] = json_units(json_safe(summary), _SET_UNITS)
    if options["as_json"]:
        click.echo(json_text(summary))
    else:
        click.echo(_text(summary))
    if options["output"] is not None:
        from ..plots.compare import figure_bond_and_rsf

        save_figure(figure_bond_and_rsf(panels, pair, rsf, _how(rsf.status)), options["output"])
        side = sidecar(options["output"])
        if side is not None:
            write_text(side, json_text(_parameters_document(rsf, step, summary)) + "\n")
    if failures:
        click.echo("stickslip: the rate-and-state side failed: " + failures[0], err=True)
        raise SystemExit(FAILED)


def _parameters_document(rsf: Any, step: Any, summary: dict[str, Any]) -> dict[str, Any]:
    """What ``-o NAME.png`` writes beside the figure, NAME.params.json: a parameter file every ``--params`` reads
    (``run --model rsf``, ``rsf simulate``, ``params show``), as ``rsf simulate -o`` and ``rsf fit -o`` write it:
    the RSF set standing for the bond model (``parameters``: a, b, Dc, mu0 at v_ref = --v0, the fitted rig
    stiffness), the velocity step it was fitted to (``protocol``, ``start_velocity``: a rerun without a protocol
    runs that step), then the comparison's report as before (status, failures, panels, ...).  Before, the file was
    the report alone and ``run --model rsf --params`` refused it ("unknown key 'bond_model'")."""
    from ..rsf.fit import PARAMETER_FILE_UNITS

    report = {key: value for key, value in summary.items() if key != "units"}
    document = {
        "model": "rate-and-state spring-slider",
        "parameters": rsf.params.to_dict(),
        "start_velocity": step.initial_velocity,
        "protocol": [{"velocity": s.velocity, "duration": s.duration} for s in step.segments],
        **report,
    }
    return {**document, "units": json_units(json_safe(document), {**PARAMETER_FILE_UNITS, **_SET_UNITS})}


def _bond_model_of(options: dict[str, Any]) -> str:
    """The bond model of the bond-vs-rsf set: from --models (a bond model and rsf), else --bond-model.

    Plain ``compare`` is ``compare --models quasi-static,rsf --protocol-set bond-vs-rsf`` (``--bond-model
    transient``: ``--models transient,rsf``); the two spellings run the same code on the same options.
    """
    ctx = click.get_current_context()
    if options["models"] is None:
        return str(options["bond_model"])
    names = [name.strip() for name in options["models"].split(",") if name.strip()]
    bond = [name for name in names if name in PROTOCOL_SETS["bond-vs-rsf"]]
    if len(names) != 2 or "rsf" not in names or len(bond) != 1:
        raise ParameterError(
            f"--models {options['models']}: --protocol-set bond-vs-rsf runs a bond model beside rate-and-state;"
            " expected quasi-static,rsf or transient,rsf"
        )
    given = ctx.get_parameter_source("bond_model") not in (None, click.core.ParameterSource.DEFAULT)
    if given and options["bond_model"] != bond[0]:
        raise ParameterError(
            f"--bond-model {options['bond_model']}: --models {options['models']} names the bond model already"
        )
    return bond[0]


def _refuse_model_options(options: dict[str, Any]) -> None:
    """The protocol and rig words belong to --models; the classic comparison runs its own three experiments."""
    ctx = click.get_current_context()
    words = (("segment_texts", "--segment"), ("protocol_file", "--protocol"), ("stiffness_text", "--stiffness"),
             ("start_texts", "--start"), ("setting_texts", "--setting"), ("every_text", "--every"))  # fmt: skip
    given = [name for key, name in words if options[key]]
    if ctx.get_parameter_source("control") not in (None, click.core.ParameterSource.DEFAULT):
        given.append("--control")
    if given:
        raise ParameterError(
            f"{given[0]}: only with --models A,B and no --protocol-set; the bond-vs-rsf set (plain compare) runs its"
            " own velocity step, slide-hold-slide and stick-slip"
        )


#: Exit status when the RSF side could not be fitted (or a given set is unphysical); 2 is bad input.
#: A panel the fitted RSF cannot describe (negative friction in a hold, say) is a finding of the comparison,
#: reported under ``rsf_cannot_describe``, not a failure of the command.
FAILED = 3


def _rsf_panel(rsf: Any, protocol: Any, times: Any) -> tuple[Any, str | None]:
    """The RSF run of one panel and what is wrong with it (None when fine); not run when the fit failed."""
    from ..rsf import simulate
    from ..studies.bond_rsf import check_friction

    if not rsf.usable:
        return None, "not run: the RSF fit failed"
    # on the bond model's own instants (dense where it changes fast) and a regular grid: no peak falls between
    grid = np.linspace(0.0, protocol.duration, 801)
    inside = np.asarray(times, float)
    inside = inside[np.isfinite(inside) & (inside >= 0.0) & (inside <= protocol.duration)]
    run = simulate(rsf.params, protocol, times=np.unique(np.concatenate([grid, inside])))
    if run.status != "ok":
        return run, f"the RSF run failed: {run.message}"
    return run, check_friction(run.time, run.friction)


def _panel_summary(bond: Any, run: Any, problem: str | None, sigma_c: float) -> dict[str, Any]:
    """What one panel shows: the extremes of both sides (friction = stress / sigma_c) and what went wrong."""
    mu = np.asarray(bond.stress, float) / sigma_c
    known = mu[np.isfinite(mu)]
    return {
        "bond_max": float(known.max()) if known.size else None,
        "bond_final": float(known[-1]) if known.size else None,
        "rsf_max": None if run is None else float(np.max(run.friction)),
        "rsf_min": None if run is None else float(np.min(run.friction)),
        "rsf": None if run is None else run.summary(),
        "problem": problem,
    }


def _limitations(panels: dict[str, Any], pair: dict[str, Any]) -> list[str]:
    """The panels where the fitted RSF says something unphysical (a limitation of the one-state law there)."""
    found = [f"{name}: {problem}" for name, (_, _, problem) in panels.items() if problem]
    if pair["problem"]:
        found.append(f"stick-slip: {pair['problem']}")
    return found


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
    from ..studies.bond_rsf import physical_problem

    shown = ", ".join(f"{k[4:]} = {v}" for k, v in given.items())
    params = p.replace(a=a, states=(StateVariable(s.law, b, dc, s.c),))
    kept = "" if len(given) == 3 else f"; the rest from the bond model ({rsf.status}: {rsf.note})"
    problem = physical_problem(params)
    if problem is not None:
        return dataclasses.replace(rsf, params=params, status="failed", note=f"given on the command line ({shown}) "
                                   f"but cannot stand for the bond model: {problem}")  # fmt: skip
    return dataclasses.replace(rsf, params=params, status="given", note=f"given on the command line: {shown}{kept}")


def _text(summary: dict[str, Any]) -> str:
    from ..display import velocity

    r = summary["rsf_of_bond_model"]
    s = summary["stick_slip"]
    lines = [
        f"one RSF parameter set for every panel (friction = stress / σc, σc = {r['sigma_c']:.4g} Pa): "
        f"a = {r['a']:.4g}, b = {r['b']:.4g}, Dc = {r['dc'] * 1e6:.4g} µm ({_how(r['status'])})",
        f"  {r['note']}",
        f"  the bond model's steady slope (1/σc) dσ/dlnV at {velocity(r['velocity'], 4)}: "
        f"{r['bond_steady_slope']:.4g} (RSF a − b = {r['rsf_a_minus_b']:.4g})",
        f"bond model: {summary['bond_model']}",
    ]
    for name, panel in summary["panels"].items():
        lines.append(f"{name}: RSF " + (f"cannot describe it: {panel['problem']}" if panel["problem"] else "ok"))
    lines += [
        f"stick-slip at {velocity(s['pulling_velocity'], 4)}, k = {s['stiffness']:.4g} 1/m, η = {s['eta']:.4g} s/m:",
        f"  bond model: {s['bond']['message']}",
        "  RSF: "
        + (f"cannot describe it: {s['problem']}" if s["problem"] else f"{s['rsf']['regime']}; {s['rsf']['message']}"),
        f"status: {summary['status']}",
    ]
    return "\n".join(lines)


def _how(status: str) -> str:
    return {"fitted": "fitted to the bond model's step", "given": "given on the command line"}.get(status, "FIT FAILED")


def register(cli: click.Group) -> None:
    cli.add_command(compare_command)


__all__ = ["compare_command"]
