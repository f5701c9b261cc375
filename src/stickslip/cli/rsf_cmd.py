"""``stickslip rsf simulate | fit | stability``: rate-and-state friction on the command line.

Values carry units (``--dc "10 um"``, ``--stiffness "1e-3 1/um"``, ``--v-ref "1 um/s"``);
a stiffness in Pa/m or a damping in Pa s/m needs ``--normal-stress``.  Every trace
and fit writes its parameters beside it (``NAME.params.json``) so it can be rerun
with ``--params``.
"""

from __future__ import annotations

import functools
import json
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from ..errors import DataError, ParameterError, StickslipError, UnitError
from ..fileio import atomic_path, atomic_write_text, protect_inputs, read_input_text, refuse_input_as_output
from ..units import quantity_noun, shorten
from .common import json_text, quantity
from .protocol_options import build_protocol as build_run_protocol
from .protocol_options import protocol_options, refuse_unsupported

LAW_NAMES = ("aging", "slip", "prz", "nagata")


#: Help of ``--stiffness`` on the rate-and-state commands.
STIFFNESS_HELP = 'Spring stiffness: friction per slip ("1e-3 1/um") or Pa/m with --normal-stress.'


def model_options(func: Callable[..., Any], stiffness: bool = True) -> Callable[..., Any]:
    """The friction law and spring-slider options shared by simulate and stability.

    ``stiffness=False`` leaves ``--stiffness`` to :func:`~stickslip.cli.protocol_options.protocol_options`.
    """
    options = [
        click.option("--params", "params_file", type=click.Path(dir_okay=False, path_type=Path), default=None,
                     help="Start from parameters written by an earlier run or fit (.params.json or .toml)."),
        click.option("--law", default=None, help="State evolution law: aging, slip, prz, nagata or a registered one."),
        click.option("--a", "a", default=None, help="Direct effect a."),
        click.option("--b", "b", default=None, help="State weight b (first state variable)."),
        click.option("--dc", default=None, help='Critical slip distance, e.g. "10 um".'),
        click.option("--b2", default=None, help="Weight of a second state variable."),
        click.option("--dc2", default=None, help="Critical slip distance of the second state variable."),
        click.option("--c", "nagata_c", default=None, help="Nagata's c (nagata law only)."),
        click.option("--mu0", default=None, help="Reference friction mu0 [0.6]."),
        click.option("--v-ref", default=None, help='Reference velocity V0, e.g. "1 um/s" [1 um/s].'),
        *([click.option("--stiffness", default=None, help=STIFFNESS_HELP)] if stiffness else []),
        click.option("--eta", default=None, help='Radiation damping: "s/m" (friction per velocity) or Pa s/m.'),
        click.option("--mass", default=None, help='Slider mass per area, e.g. "100 kg/m^2" (needs --normal-stress).'),
        click.option("--normal-stress", default=None, help='Normal stress, e.g. "30 MPa".'),
        click.option("--regularized", is_flag=True, default=None, help="Use the regularised (asinh) friction form."),
        click.option("--cutoff-v1", default=None,
                     help='Cut-off velocity form (QDYN): V1 of the direct effect, e.g. "1 mm/s"; needs --cutoff-v2.'),
        click.option("--cutoff-v2", default=None, help='Cut-off velocity V2 of the evolution effect, e.g. "1 um/s".'),
    ]  # fmt: skip
    for option in reversed(options):
        func = option(func)
    return func


def build_params(options: dict[str, Any]) -> Any:
    """RSFParams from the model options (on top of ``--params`` if given)."""
    from ..rsf import RSFParams

    base: dict[str, Any] = {}
    if options.get("params_file") is not None:
        base = load_params_mapping(options["params_file"])
    states = _base_states(base, options.get("params_file"))
    first = states[0]
    if options.get("law") is not None:  # --law "" is an error (unknown law), not the default
        for s in states:
            s["law"] = options["law"]
    if options.get("b") is not None:
        first["b"] = _number(options["b"], "--b")
    if options.get("dc") is not None:
        first["dc"] = _positive(options["dc"], "length", "--dc")
    if options.get("nagata_c") is not None:
        for s in states:
            s["c"] = _number(options["nagata_c"], "--c")
    if (options.get("b2") is None) != (options.get("dc2") is None):
        raise ParameterError("--b2/--dc2: a second state variable needs both --b2 and --dc2")
    if options.get("b2") is not None:
        second = {"law": first.get("law", "aging"), "b": _number(options["b2"], "--b2"),
                  "dc": _positive(options["dc2"], "length", "--dc2"), "c": first.get("c", 0.0)}  # fmt: skip
        states = [first, second]
    mapping: dict[str, Any] = {k: v for k, v in base.items() if k != "states"}
    mapping["states"] = states
    sigma = base.get("normal_stress")
    if options.get("normal_stress") is not None:
        sigma = mapping["normal_stress"] = _positive(options["normal_stress"], "stress", "--normal-stress")
    if options.get("a") is not None:
        mapping["a"] = _number(options["a"], "--a")
    if options.get("mu0") is not None:
        mapping["mu0"] = _number(options["mu0"], "--mu0")
    if options.get("v_ref") is not None:
        mapping["v_ref"] = _positive(options["v_ref"], "velocity", "--v-ref")
    if options.get("stiffness") is not None:
        mapping["stiffness"] = _per_sigma(options["stiffness"], "per_length", "stress_per_length", sigma, "--stiffness")
    if options.get("eta") is not None:
        mapping["eta"] = _per_sigma(options["eta"], "slowness", "stress_per_velocity", sigma, "--eta", allow_zero=True)
    if options.get("mass") is not None:
        mapping["mass"] = _positive(options["mass"], "mass_per_area", "--mass", allow_zero=True)
    if options.get("regularized"):
        mapping["regularized"] = True
    if (options.get("cutoff_v1") is None) != (options.get("cutoff_v2") is None):
        raise ParameterError("--cutoff-v1/--cutoff-v2: the cut-off velocity form needs both V1 and V2")
    if options.get("cutoff_v1") is not None:
        mapping["cutoff"] = (_positive(options["cutoff_v1"], "velocity", "--cutoff-v1"),
                             _positive(options["cutoff_v2"], "velocity", "--cutoff-v2"))  # fmt: skip
    source = "options" if options.get("params_file") is None else f"--params {options['params_file']} (or options)"
    return RSFParams.from_dict(mapping, source=source)


#: Largest --params file read (one written by a run or fit is a few kB).
MAX_PARAMS_BYTES = 1_000_000


def _base_states(base: dict[str, Any], path: Path | None) -> list[dict[str, Any]]:
    """The state variables of a --params file (one aging state without one), each a table."""
    if "states" not in base:
        return [{"law": "aging", "b": 0.01, "dc": 10e-6}]
    states = base["states"]
    if not isinstance(states, list) or not states or not all(isinstance(s, dict) for s in states):
        raise ParameterError(
            f"--params {path}: 'states' must be a non-empty list of tables with law, b, dc; got {shorten(states)}"
        )
    return [dict(s) for s in states]


def load_params_mapping(path: Path) -> dict[str, Any]:
    """The parameter mapping of a ``.params.json`` (trace or fit) or a ``.toml`` file."""
    data = load_params_file(path)
    mapping = data.get("parameters", data)
    if not isinstance(mapping, dict):
        raise DataError(f"--params {path}: 'parameters' must be a table of values, got {type(mapping).__name__}")
    return dict(mapping)


def load_params_file(path: Path) -> dict[str, Any]:
    """The whole top-level table of a ``--params`` file; every problem with the file is one DataError line."""
    path = Path(path)
    text = _params_text(path)
    protect_inputs([path])  # `rsf simulate --params run.params.json -o run.csv` must not rewrite it
    try:
        if path.suffix.lower() == ".toml":
            try:
                import tomllib
            except ModuleNotFoundError:  # pragma: no cover - Python 3.10
                import tomli as tomllib  # type: ignore[no-redef]
            data = tomllib.loads(text)
        else:
            data = json.loads(text)
    except ValueError as exc:  # JSONDecodeError and TOMLDecodeError are ValueErrors
        kind = "TOML" if path.suffix.lower() == ".toml" else "JSON"
        raise DataError(f"--params {path}: malformed {kind} ({(str(exc).splitlines() or [''])[0]})") from None
    except RecursionError:  # "[[[[..." a hundred thousand deep: the parsers recurse
        raise DataError(f"--params {path}: nested too deeply to be a parameter file") from None
    if not isinstance(data, dict):
        raise DataError(f"--params {path}: expected a table of parameters (a JSON object), got {type(data).__name__}")
    return data


def _params_text(path: Path) -> str:
    return read_input_text(path, f"--params {path}", MAX_PARAMS_BYTES)


def _run_meta(path: Path) -> tuple[list[dict[str, Any]] | None, float | None]:
    """The protocol and start velocity a ``.params.json`` of an earlier run carries (None where absent)."""
    data = load_params_file(path)
    protocol, start = data.get("protocol"), data.get("start_velocity")
    if protocol is not None:
        rows = protocol if isinstance(protocol, list) else None
        if rows is None or not all(isinstance(r, dict) and {"velocity", "duration"} <= set(r) for r in rows):
            raise DataError(
                f'--params {path}: \'protocol\' must be a list of {{"velocity": ..., "duration": ...}} segments'
                f" (SI), got {shorten(protocol)}"
            )
    if start is not None and (isinstance(start, bool) or not isinstance(start, (int, float))):
        raise DataError(f"--params {path}: 'start_velocity' must be a number in m/s, got {shorten(start)}")
    return protocol or None, start


def _number(text: str, name: str) -> float:
    return quantity(text, "dimensionless", name)


def _positive(text: str, dimension: str, name: str, allow_zero: bool = False) -> float:
    from .common import positive

    return positive(text, dimension, name, allow_zero=allow_zero)


def _per_sigma(
    text: str, dimension: str, stress_dimension: str, sigma: float | None, name: str, allow_zero: bool = False
) -> float:
    """A value in friction units, or in stress units divided by the normal stress."""
    from .common import require_unit

    require_unit(text, dimension, f"{name} ")  # a bare number: say it needs a unit, not that its unit is wrong
    try:
        return _positive(text, dimension, name, allow_zero)
    except UnitError:
        try:
            value = _positive(text, stress_dimension, name, allow_zero)
        except UnitError:
            raise UnitError(
                f"{name}: {text!r} has the wrong dimension; expected {quantity_noun(dimension)} "
                f"or {quantity_noun(stress_dimension)} with --normal-stress"
            ) from None
        if sigma is None:
            raise ParameterError(f"{name} {text!r} is in stress units: give --normal-stress to convert it") from None
        converted = value / sigma
        if value > 0 and not 0 < converted < math.inf:
            raise ParameterError(
                f"{name} {text!r} over --normal-stress {sigma:g} Pa is {converted:g}: outside the floating-point range"
            ) from None
        return converted


def _fallback_protocol(fallback: list[dict] | None) -> Any:
    """The protocol an earlier run's ``.params.json`` carries (None without one)."""
    from .. import protocols

    return protocols.segments([(s["velocity"], s["duration"]) for s in fallback]) if fallback else None


def trace_csv(frame: Any) -> str:
    """The trace as CSV, units in the header brackets (:mod:`stickslip.columns`)."""
    from ..columns import csv_text

    return csv_text(frame)


def sidecar(path: Path) -> Path:
    """Where the parameters of an output file go: ``NAME.params.json`` beside it."""
    return path.with_name(path.stem + ".params.json")


def save_figure(fig: Any, path: Path) -> None:
    try:
        with atomic_path(path) as temp:
            fig.savefig(temp, dpi=120, bbox_inches="tight", format=path.suffix.lstrip(".") or "png")
    except StickslipError:  # a refusal (an input named as output) is already one line
        raise
    except (OSError, ValueError) as exc:
        raise click.FileError(str(path), hint=str(exc)) from None


def write(path: Path, text: str) -> None:
    try:
        atomic_write_text(path, text)
    except OSError as exc:
        raise click.FileError(str(path), hint=str(exc.strerror or exc)) from None


@click.group("rsf")
def rsf_group() -> None:
    """Rate-and-state friction: spring-slider runs, fits to lab records, stability."""


@rsf_group.command("simulate")
@functools.partial(model_options, stiffness=False)
@protocol_options(stiffness_help=STIFFNESS_HELP)
@click.option("--start-velocity", default=None, help="Steady sliding at this velocity at t = 0 [first segment's].")
@click.option("--every", default=None, help='Sample the trace every DT (e.g. "0.1 s"); default: the solver\'s steps.')
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path), help="Write the trace CSV here.")
@click.option("--json", "as_json", is_flag=True, help="Print the summary as JSON.")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path), help="Save a figure.")
def simulate_command(**options: Any) -> None:
    """Run a loading protocol on the rate-and-state spring-slider.

    The protocol in the words of every run command: --v0 V --duration T, then
    any --segment "V:T" (or --segment alone, or --protocol FILE); the rig is a
    spring (--stiffness), so --control velocity is refused.
    The trace has columns time, friction, slider_velocity, state,
    load_point_displacement, slider_displacement (SI).  With -o the
    parameters go beside it in NAME.params.json.
    """
    from ..models import Rig, get_model

    fallback = None
    start = None
    if options["params_file"] is not None and options["params_file"].suffix.lower() == ".json":
        fallback, start = _run_meta(options["params_file"])
    options["stiffness"] = options.pop("stiffness_text")
    params = build_params(options)
    protocol = build_run_protocol(options["v0_text"], options["duration_text"], options["segment_texts"],
                                  options["protocol_file"], _fallback_protocol(fallback))  # fmt: skip
    refuse_unsupported("rsf simulate (the rate-and-state spring-slider)", protocol, options["control"],
                       controls=("spring",))  # fmt: skip
    if options["start_velocity"] is not None:
        start = _positive(options["start_velocity"], "velocity", "--start-velocity")
    every = None if options["every"] is None else _positive(options["every"], "time", "--every")
    output, plot_path = options["output"], options["plot_path"]
    side = sidecar(output) if output is not None and str(output) != "-" else None
    refuse_input_as_output(
        [options["protocol_file"], options["params_file"]],
        [("-o", output), ("-o (its NAME.params.json)", side), ("--plot", plot_path)],
    )
    run = get_model("rsf").run(params, protocol, Rig(), start=start, every=every).native  # the RSFRun
    if output is not None:
        write(output, trace_csv(run.to_frame()))
        if side is not None:
            write(side, run.metadata_json())
    summary = run.summary()
    if options["as_json"]:
        click.echo(json_text(summary))
    elif output is None:
        click.echo(trace_csv(run.to_frame()), nl=False)
    else:
        click.echo(_summary_text(summary), err=True)
    if plot_path is not None:
        from ..plots.rsf import run_figure

        save_figure(run_figure(run), plot_path)


def _summary_text(summary: dict[str, Any]) -> str:
    period = summary.get("period")
    lines = [f"regime: {summary['regime']}", f"final friction: {summary['final_friction']:.6g}"]
    if period is not None:
        lines.append(f"period: {period:.6g} s")
    lines.append(summary["message"])
    return "\n".join(lines)


@rsf_group.command("stability")
@model_options
@click.option("--velocity", "velocities", multiple=True, required=True, help='Sliding velocity, e.g. "1 um/s".')
@click.option("--json", "as_json", is_flag=True, help="Print JSON (SI units).")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Save the critical stiffness against velocity.")  # fmt: skip
def stability_command(**options: Any) -> None:
    """Critical stiffness k_c and neutral period of steady sliding (docs/rsf.md)."""
    from ..rsf import stability

    params = build_params(options)
    refuse_input_as_output([options.get("params_file")], [("--plot", options["plot_path"])])
    reports = [stability(params, _positive(v, "velocity", "--velocity")).as_dict() for v in options["velocities"]]
    if options["as_json"]:
        click.echo(json_text(reports if len(reports) > 1 else reports[0]))
    else:
        for r in reports:
            period = r["neutral_period"]
            click.echo(
                f"V = {r['velocity']:.6g} m/s: k_c = {r['critical_stiffness']:.6g} 1/m"
                + (f" ({r['critical_stiffness_pa']:.6g} Pa/m)" if r["critical_stiffness_pa"] is not None else "")
                + (f", neutral period {period:.6g} s" if not math.isnan(period) else "")
                + f"; {r['message']}"
            )
    if options["plot_path"] is not None:
        from ..plots.rsf import stability_figure

        speeds = [r["velocity"] for r in reports]
        low = max(min(speeds) / 100, sys.float_info.min)  # two decades either side, within the floats
        high = min(max(speeds) * 100, sys.float_info.max)
        save_figure(stability_figure(params, low, high), options["plot_path"])


@rsf_group.command("fit")
@click.argument("record_file", metavar="FILE", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "--columns",
    default=None,
    metavar="ROLE=HEADER,...",
    help='Map headers: time="Time(s)",displacement="Displ(microns)",friction=Friction.',
)
@click.option("--displacement-unit", default="m", show_default=True, help="Unit of the displacement column.")
@click.option("--time-unit", default="s", show_default=True, help="Unit of the time column.")
@click.option("--law", default="aging", show_default=True, help="State evolution law.")
@click.option("--states", type=click.IntRange(1, 2), default=1, show_default=True, help="State variables.")
@click.option("--stiffness", default=None, help='Fixed spring stiffness ("1e-3 1/um", or Pa/m with --normal-stress).')
@click.option("--normal-stress", default=None, help="Normal stress, to read a stiffness in Pa/m.")
@click.option("--fit-stiffness", is_flag=True, help="Fit the stiffness (the default when --stiffness is not given).")
@click.option(
    "--trend",
    type=click.Choice(["slip", "time", "both"]),
    is_flag=False,
    flag_value="slip",
    default=None,
    help="Fit a linear drift as well: in slip (--trend alone), in time, or both.",
)
@click.option(
    "--segment",
    multiple=True,
    metavar="V:T",
    help="Load-point history from the record's start (default: found from the displacement).",
)
@click.option(
    "--protocol",
    "protocol_file",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="Load-point history as a protocol CSV (time,velocity or velocity,duration; SI), as for simulate.",
)
@click.option("--mcmc", "mcmc_steps", type=click.IntRange(min=0), default=0, help="emcee steps for a posterior.")
@click.option("--seed", type=int, default=None, help="Seed of the emcee walkers.")
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON (SI units).")
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path), help="Write fitted parameters (TOML).")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path), help="Save data and fit.")
def fit_command(**options: Any) -> None:
    """Fit rate-and-state friction to a lab record (time, load-point displacement, friction).

    The load point's velocity history is found from the displacement (or
    given with --segment or --protocol); the slider starts in steady sliding.
    The report gives the history used, values in the record's units with
    standard errors and 95 % intervals, a - b with its own error, correlations,
    reduced chi-square against the record's own noise, and warnings.  A fit
    that cannot be trusted says why (status "failed", reason) and exits with
    status 3; its parameters are not written to -o.
    """
    from .. import protocols
    from ..rsf.data import parse_columns, read_record
    from ..rsf.fit import fit_record

    output, plot_path = options["output"], options["plot_path"]
    refuse_input_as_output([options["record_file"], options["protocol_file"]], [("-o", output), ("--plot", plot_path)])
    record = read_record(options["record_file"], parse_columns(options["columns"]), options["displacement_unit"],
                         options["time_unit"])  # fmt: skip
    sigma = None
    if options["normal_stress"] is not None:
        sigma = _positive(options["normal_stress"], "stress", "--normal-stress")
    stiffness = None
    if options["stiffness"] is not None:
        if options["fit_stiffness"]:
            raise click.UsageError("--stiffness and --fit-stiffness: give one of them")
        stiffness = _per_sigma(options["stiffness"], "per_length", "stress_per_length", sigma, "--stiffness")
    protocol = None
    if options["segment"] and options["protocol_file"] is not None:
        raise click.UsageError("--segment and --protocol: give one of them")
    if options["protocol_file"] is not None:
        protocol = protocols.read_protocol(options["protocol_file"])
    elif options["segment"]:
        protocol = protocols.Protocol(tuple(protocols.parse_segment(s) for s in options["segment"]))
    fit = fit_record(record, law=options["law"], states=options["states"], stiffness=stiffness,
                     fit_stiffness=True if options["fit_stiffness"] else None, trend=options["trend"] or False,
                     protocol=protocol, mcmc_steps=options["mcmc_steps"], seed=options["seed"])  # fmt: skip
    report = fit.summary()
    if output is not None and fit.status == "ok":
        write(output, fit.to_toml())
        write(sidecar(output), json_text({"parameters": fit.params.to_dict(), "fit": report}))
    if options["as_json"]:
        click.echo(json_text(report))
    else:
        click.echo(_fit_text(fit))
    if plot_path is not None:
        from ..plots.rsf import fit_figure

        save_figure(fit_figure(fit), plot_path)
    if fit.status != "ok":
        unwritten = f" ({output} not written)" if output is not None else ""
        click.echo(f"stickslip: fit failed: {fit.reason}{unwritten}", err=True)
        # SystemExit, not click's Exit: main() runs click with standalone_mode=False, which swallows Exit's code
        raise SystemExit(FIT_FAILED)


#: exit status of a fit that ran but cannot be trusted (2 is bad input, 1 an internal error)
FIT_FAILED = 3


def _fit_text(fit: Any) -> str:
    from ..display import unit as shown_unit

    unit = shown_unit(fit.record.length_unit)
    lines = [f"rate-and-state fit of {fit.record.source} ({len(fit.record)} rows): {fit.status}"
             + (f": {fit.reason}" if fit.reason else "")]  # fmt: skip
    lines.append(f"  load point ({fit.protocol_source}):")
    for row in fit.protocol_rows():
        lines.append(f"    from {row['start']:.6g} s: {row['velocity']:.6g} {unit}/s for {row['duration']:.6g} s")
    for name, p in {**fit.parameters, **fit.derived}.items():
        lines.append(f"  {name:10s} {p.text()}")
    lines.append(f"  reduced chi-square {fit.reduced_chi_square:.4g} (noise {fit.noise:.3g}), rms {fit.rms:.4g}")
    lines += [f"  warning: {w}" for w in fit.warnings]
    return "\n".join(lines)


def register(cli: click.Group) -> None:
    cli.add_command(rsf_group)
