"""``stickslip rsf simulate | fit | stability``: rate-and-state friction on the command line.

Values carry units (``--dc "10 um"``, ``--stiffness "1e-3 1/um"``, ``--v-ref "1 um/s"``);
a stiffness in Pa/m or a damping in Pa s/m needs ``--normal-stress``.  Every trace
and fit writes its parameters beside it (``NAME.params.json``) so it can be rerun
with ``--params``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import importlib.util
import math
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import click
import numpy as np

from ..errors import ModelError, ParameterError, StickslipError, UnitError
from ..numerics.budget import PROGRESS_AFTER_SECONDS
from ..units import bare_number, quantity_noun, shorten
from .common import (
    FILE_PATH,
    json_text,
    positive,
    quantity,
    refuse_overwriting_inputs,
    save_figure,
    stacked,
    write_text,
)
from .params_files import history_protocol, load_params_mapping
from .protocol_options import build_protocol as build_run_protocol
from .protocol_options import checked_segment_text, protocol_options, refuse_unsupported
from .run_cmd import execute, output_options

#: Help of ``--stiffness`` on the rate-and-state commands.
STIFFNESS_HELP = 'Spring stiffness: friction per slip ("1e-3 1/um") or Pa/m with --normal-stress.'


def model_options(func: Callable[..., Any], stiffness: bool = True) -> Callable[..., Any]:
    """The friction law and spring-slider options shared by simulate and stability.

    ``stiffness=False`` leaves ``--stiffness`` to :func:`~stickslip.cli.protocol_options.protocol_options`.
    """
    options = [
        click.option("--params", "params_file", type=FILE_PATH, default=None,
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
    return stacked(options, func)


def build_params(options: dict[str, Any]) -> Any:
    """RSFParams from the model options (on top of ``--params`` if given)."""
    from ..rsf import RSFParams

    base = {} if options.get("params_file") is None else load_params_mapping(options["params_file"])
    states = _base_states(base, options.get("params_file"))
    first = states[0]
    if options.get("law") is not None:  # --law "" is an error (unknown law), not the default
        for s in states:
            s["law"] = options["law"]
    if options.get("b") is not None:
        first["b"] = _number(options["b"], "--b")
    if options.get("dc") is not None:
        first["dc"] = positive(options["dc"], "length", "--dc")
    if options.get("nagata_c") is not None:
        for s in states:
            s["c"] = _number(options["nagata_c"], "--c")
    if (options.get("b2") is None) != (options.get("dc2") is None):
        raise ParameterError("--b2/--dc2: a second state variable needs both --b2 and --dc2")
    if options.get("b2") is not None:
        second = {"law": first.get("law", "aging"), "b": _number(options["b2"], "--b2"),
                  "dc": positive(options["dc2"], "length", "--dc2"), "c": first.get("c", 0.0)}  # fmt: skip
        states = [first, second]
    mapping: dict[str, Any] = {**{k: v for k, v in base.items() if k != "states"}, "states": states}
    sigma = base.get("normal_stress")
    if options.get("normal_stress") is not None:
        sigma = mapping["normal_stress"] = positive(options["normal_stress"], "stress", "--normal-stress")
    if options.get("a") is not None:
        mapping["a"] = _number(options["a"], "--a")
    if options.get("mu0") is not None:
        mapping["mu0"] = _number(options["mu0"], "--mu0")
    if options.get("v_ref") is not None:
        mapping["v_ref"] = positive(options["v_ref"], "velocity", "--v-ref")
    if options.get("stiffness") is not None:
        mapping["stiffness"] = _per_sigma(options["stiffness"], "per_length", "stress_per_length", sigma, "--stiffness")
    if options.get("eta") is not None:
        mapping["eta"] = _per_sigma(options["eta"], "slowness", "stress_per_velocity", sigma, "--eta", allow_zero=True)
    if options.get("mass") is not None:
        mapping["mass"] = positive(options["mass"], "mass_per_area", "--mass", allow_zero=True)
    if options.get("regularized"):
        mapping["regularized"] = True
    if (cutoff := _cutoff(options)) is not None:
        mapping["cutoff"] = cutoff
    source = "options" if options.get("params_file") is None else f"--params {options['params_file']} (or options)"
    try:
        return RSFParams.from_dict(mapping, source=source)
    except ParameterError as exc:  # name the option the user typed, where the value came from one
        key, sep, rest = str(exc).partition(": ")
        given = key in _OPTION_OF and options.get(key) is not None
        raise ParameterError(f"{_OPTION_OF[key]}: {rest}" if sep and given else str(exc)) from None


#: the option of each top-level parameter an option sets (for messages)
_OPTION_OF = {"a": "--a", "mu0": "--mu0", "v_ref": "--v-ref", "stiffness": "--stiffness", "eta": "--eta",
              "mass": "--mass", "normal_stress": "--normal-stress"}  # fmt: skip


def _cutoff(options: dict[str, Any]) -> tuple[float, float] | None:
    """``--cutoff-v1``/``--cutoff-v2`` in m/s (None without them; one alone is refused)."""
    if (options.get("cutoff_v1") is None) != (options.get("cutoff_v2") is None):
        raise ParameterError("--cutoff-v1/--cutoff-v2: the cut-off velocity form needs both V1 and V2")
    if options.get("cutoff_v1") is None:
        return None
    return (positive(options["cutoff_v1"], "velocity", "--cutoff-v1"),
            positive(options["cutoff_v2"], "velocity", "--cutoff-v2"))  # fmt: skip


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


def _number(text: str, name: str) -> float:
    return quantity(text, "dimensionless", name)


def _per_sigma(
    text: str, dimension: str, stress_dimension: str, sigma: float | None, name: str, allow_zero: bool = False
) -> float:
    """A value in friction units, or in stress units divided by the normal stress."""
    from .common import require_unit

    require_unit(text, dimension, f"{name} ")  # a bare number: say it needs a unit, not that its unit is wrong
    try:
        return positive(text, dimension, name, allow_zero)
    except UnitError:
        try:
            value = positive(text, stress_dimension, name, allow_zero)
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


def sidecar(path: Path | None) -> Path | None:
    """Where the parameters of an output file go: ``NAME.params.json`` beside it; none beside standard output or
    a special file (``-o /dev/null`` wrote ``/dev/null.params.json``)."""
    if path is None or str(path) == "-":
        return None
    if path.exists() and not path.resolve().is_file():  # a device, a FIFO, a link to one: written as it is, alone
        return None
    return path.with_name(path.stem + ".params.json")


@click.group("rsf")
def rsf_group() -> None:
    """Rate-and-state friction: spring-slider runs, fits to lab records, stability."""


@rsf_group.command("simulate")
@functools.partial(model_options, stiffness=False)
@protocol_options(stiffness_help=STIFFNESS_HELP)
@click.option("--start-velocity", default=None, help="Steady sliding at this velocity at t = 0 [first segment's].")
@click.option("--every", default=None, help='Sample the trace every DT (e.g. "0.1 s"); default: the solver\'s steps.')
@output_options
def simulate_command(**options: Any) -> None:
    """Run a loading protocol on the rate-and-state spring-slider.

    The protocol in the words of every run command: --v0 V --duration T, then
    any --segment "V:T" (or --segment alone, or --protocol FILE); the rig is a
    spring (--stiffness), so --control velocity is refused.
    The spelling of `stickslip run --model rsf` (the law options are its
    --set keys, --start-velocity its --start): the same Run CSV (time,
    friction, slider_velocity, slider_position, load_point_position, state;
    on standard output without -o, the summary then on stderr), the same
    figure (--plot) and the same summary.  With -o the parameters go beside it in NAME.params.json.
    """
    from ..models import Rig, get_model

    earlier, start = history_protocol(options["params_file"])  # the earlier run's own, where no protocol is given
    options["stiffness"] = options.pop("stiffness_text")
    params = build_params(options)
    protocol = build_run_protocol(options["v0_text"], options["duration_text"], options["segment_texts"],
                                  options["protocol_file"], earlier)  # fmt: skip
    refuse_unsupported("rsf simulate (the rate-and-state spring-slider)", protocol, options["control"],
                       controls=("spring",))  # fmt: skip
    if options["start_velocity"] is not None:
        start = positive(options["start_velocity"], "velocity", "--start-velocity")
    every = None if options["every"] is None else positive(options["every"], "time", "--every")
    output, plot_path = options["output"], options["plot_path"]
    side = sidecar(output)
    printed = "the trace (standard output without -o)" if output is None and not options["as_json"] else None
    refuse_overwriting_inputs(
        [options["protocol_file"], options["params_file"]],
        [("-o", output), ("-o (its NAME.params.json)", side), ("--plot", plot_path)],
        printed=printed,
    )
    beside = None if side is None else lambda run: write_text(side, run.native.metadata_json())
    execute(get_model("rsf"), params, protocol, Rig(), start=start, settings={} if every is None else {"every": every},
            output=Path("-") if output is None and not options["as_json"] else output, plot_path=plot_path,
            as_json=options["as_json"], beside=beside, start_option="--start-velocity ")  # fmt: skip


#: rate-and-state's spring is friction per slip (1/m), not the bond model's Pa/m; k_c in Pa/m with a normal stress
_STABILITY_UNITS = {"stiffness": "1/m", "critical_stiffness_pa": "Pa/m"}


@rsf_group.command("stability")
@model_options
@click.option("--velocity", "velocities", multiple=True, required=True, help='Sliding velocity, e.g. "1 um/s".')
@click.option("--json", "as_json", is_flag=True, help="Print JSON (SI units).")
@click.option("--plot", "plot_path", type=FILE_PATH,
              help="Save the critical stiffness against velocity.")  # fmt: skip
def stability_command(**options: Any) -> None:
    """Critical stiffness k_c and neutral period of steady sliding (docs/rsf.md)."""
    from ..rsf import stability

    params = build_params(options)
    refuse_overwriting_inputs([options.get("params_file")], [("--plot", options["plot_path"])])
    reports = [stability(params, positive(v, "velocity", "--velocity")).as_dict() for v in options["velocities"]]
    if options["as_json"]:
        from ..columns import json_safe, json_units

        single = {**reports[0], "units": json_units(json_safe(reports[0]), _STABILITY_UNITS)}
        click.echo(json_text(reports if len(reports) > 1 else single))
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


#: The keys of ``--fix`` and ``--guess`` and their dimensions (a stiffness may also be Pa/m with --normal-stress).
FIT_KEYS = {
    "mu0": "dimensionless",
    "a": "dimensionless",
    "b": "dimensionless",
    "dc": "length",
    "b2": "dimensionless",
    "dc2": "length",
    "stiffness": "per_length",
    "trend": "per_length",
    "time_trend": "rate",
}
_POSITIVE_KEYS = ("a", "dc", "dc2", "stiffness")
_SECOND_STATE_KEYS = ("b2", "dc2")
#: Fewest rows a --window may hold (a record has at least 10).
MIN_WINDOW_ROWS = 10
#: Default of ``rsf fit --max-time``.
MAX_TIME_DEFAULT = "5 min"
#: Jacobians (each n + 1 model runs, n the free parameters) of one least-squares search (docs/rsf.md, "Cost estimate").
JACOBIANS_PER_SEARCH = 10
#: Jacobians of each search a troubled fit adds (a restart from another Dc, another law tried): at most 37 counted
#: on the measured records of docs/rsf.md ("Cost estimate and --max-time"), 12-27 typically
RESTART_JACOBIANS = 30
#: A model run this long is timed once (the first run's set-up, about a second, is then a small part of it).
SLOW_RUN_SECONDS = 10.0
#: More rows than this in the text report's history are summarised (a measured history has hundreds).
SHOWN_SEGMENTS = 12


@dataclass(frozen=True)
class FitCost:
    """The up-front estimate of an ``rsf fit``: one model run (measured) times the runs a fit typically takes, and
    the runs it may take when its first search does not fit the record to its noise (``restart_runs``, from the
    searches it then adds: ``restarts`` says which)."""

    run_seconds: float
    runs: int
    free: int
    restart_runs: int = 0
    restarts: str = ""

    @property
    def seconds(self) -> float:
        return self.run_seconds * self.runs

    @property
    def restart_seconds(self) -> float:
        return self.run_seconds * max(self.restart_runs, self.runs)

    def text(self) -> str:
        typical = (f"about {_duration(self.seconds)} ({self.runs} model runs of {_duration(self.run_seconds)} each for"
                   f" {self.free} free parameters)")  # fmt: skip
        if self.restart_runs <= self.runs:
            return typical
        return (
            f"{typical}; a record its first search does not fit to the noise (reduced chi-square > 2, as measured "
            f"records usually are) adds {self.restarts}: up to {_duration(self.restart_seconds)} "
            f"({self.restart_runs} runs)"
        )


def _duration(seconds: float) -> str:
    """A length of time as people read it: "0.76 s", "45 s", "17 min", "3.5 h"."""
    if seconds < 1e-3:
        return "under 1 ms"
    for limit, scale, unit in ((120.0, 1.0, "s"), (7200.0, 60.0, "min"), (math.inf, 3600.0, "h")):
        if seconds < limit:
            value = seconds / scale
            return f"{value:.2g} {unit}" if value < 100 else f"{value:.0f} {unit}"
    return "an unbounded time"


@rsf_group.command("fit")
@click.argument("record_file", metavar="FILE", type=FILE_PATH)
@click.option(
    "--columns",
    default=None,
    metavar="ROLE=HEADER,...",
    help='Map headers: time="Time(s)",displacement="Displ(microns)",friction=Friction; a shear stress and the '
    'normal stress instead of friction: shear_stress="Tau (kPa)",normal_stress="Sn (MPa)" (or forces, "Fs (kN)"; '
    "a force beside a stress needs --contact-area).",
)
@click.option("--displacement-unit", default=None,
              help="Unit of the displacement column [the unit its header names, e.g. (um), else m].")  # fmt: skip
@click.option("--time-unit", default=None,
              help="Unit of the time column [the unit its header names, e.g. (s), else s].")  # fmt: skip
@click.option("--window", "window_text", default=None, metavar="T0:T1",
              help='Fit only the rows from T0 to T1 in the file\'s own clock, e.g. "20100 s:21000 s" (an end may be '
                   "left out).")  # fmt: skip
@click.option("--law", default="aging", show_default=True,
              help="State evolution law; one per state for mixed laws, e.g. aging,slip with --states 2.")  # fmt: skip
@click.option("--states", type=click.IntRange(1, 2), default=None, help="State variables [1, or one per --law].")
@click.option("--fix", "fix_items", multiple=True, metavar="KEY=VALUE",
              help=f'Hold a parameter at a value, with its unit (repeatable): --fix "dc=20 um", '
                   f'--fix "stiffness=1.6e-3/um", --fix mu0=0.6; keys {", ".join(FIT_KEYS)}.')  # fmt: skip
@click.option("--free", "free_keys", multiple=True, metavar="KEY",
              help="Also fit this parameter (repeatable): stiffness, trend (slip drift), time_trend.")  # fmt: skip
@click.option("--guess", "guess_items", multiple=True, metavar="KEY=VALUE",
              help='Start a fitted parameter here (repeatable), e.g. --guess "stiffness=2e-3/um".')  # fmt: skip
@click.option("--stiffness", default=None,
              help='Spring stiffness ("1e-3 1/um", or Pa/m with --normal-stress): held fixed, as --fix stiffness=K; '
                   "with --fit-stiffness the free stiffness starts there, as --guess stiffness=K.")  # fmt: skip
@click.option("--normal-stress", default=None,
              help='Normal stress ("10 MPa"): divides a shear-stress column into friction, and reads a stiffness in '
                   "Pa/m.")  # fmt: skip
@click.option("--contact-area", "area_text", default=None, metavar="A",
              help='Contact area with its unit, e.g. "100 cm^2": makes a shear- or normal-force column a stress '
                   "beside a stress column (a force over a force needs none).")  # fmt: skip
@click.option("--fit-stiffness", is_flag=True,
              help="Fit the stiffness (the default without --stiffness), as --free stiffness.")  # fmt: skip
@click.option(
    "--trend",
    type=click.Choice(["slip", "time", "both"]),
    is_flag=False,
    flag_value="slip",
    default=None,
    help="Fit a linear drift as well: in slip (--trend alone), in time, or both.",
)
@click.option("--step-weight", default=None, metavar="W",
              help="Weight of the rows just after each velocity step, relative to the rest (> 0).")  # fmt: skip
@click.option("--cutoff-v1", default=None, help='Fit the cut-off velocity form (QDYN) with V1 held, e.g. "1 mm/s".')
@click.option("--cutoff-v2", default=None, help='The cut-off form\'s V2 of the evolution effect, e.g. "1 um/s".')
@click.option("--history", type=click.Choice(["segments", "measured"]), default="segments", show_default=True,
              help="Load-point history: constant-velocity segments found in the displacement, or the measured "
                   "displacement itself (smoothed), as lab codes drive the model.")  # fmt: skip
@click.option(
    "--segment",
    multiple=True,
    metavar="V:T",
    help="Load-point history from the record's start (default: found from the displacement).",
)
@click.option(
    "--protocol",
    "protocol_file",
    type=FILE_PATH,
    default=None,
    help="Load-point history as a protocol CSV (time,velocity or velocity,duration; SI), as for simulate, from the "
    "record's first row (no negative times).",
)
@click.option(
    "--max-time",
    default=MAX_TIME_DEFAULT,
    show_default=True,
    help="Refuse a fit estimated to take longer (a model run is timed first); stop one that runs on.",
)
@click.option("--mcmc", "mcmc_steps", type=click.IntRange(min=0), default=0, help="emcee steps for a posterior.")
@click.option("--seed", type=int, default=None, help="Seed of the emcee walkers.")
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON (SI units: Dc in m, stiffness in 1/m).")
@click.option(
    "-o",
    "--output",
    type=FILE_PATH,
    help="Write fitted parameters: TOML (with NAME.params.json beside it), or JSON for a NAME.json.",
)
@click.option("--plot", "plot_path", type=FILE_PATH, help="Save data and fit.")
def fit_command(**options: Any) -> None:
    """Fit rate-and-state friction to a lab record (time, load-point displacement, friction).

    The load point's velocity history is found from the displacement (or
    given with --segment or --protocol, or the measured displacement itself
    with --history measured); the slider starts in steady sliding.  Free:
    mu0, a, b, Dc (b2, Dc2 with two states) and the stiffness unless held
    (--stiffness or --fix); --fix holds any of them, --guess starts one.
    The report gives the history used, values in the record's units with
    standard errors and 95 % intervals, a - b with its own error, correlations,
    reduced chi-square against the record's own noise, and warnings; --json
    gives it in SI units.  The cost is estimated before the fit (one model
    run timed): a fit estimated above --max-time is refused, and one still
    running at --max-time is stopped (a failed fit).  A fit that
    cannot be trusted says why (status "failed", reason) and exits with
    status 3; its parameters are not written to -o.  Bad input exits 2.
    """
    from ..rsf.data import parse_columns, read_record
    from ..rsf.fit import FitNotEvaluated, fit_record, response_check, restart_notice

    output, plot_path = options["output"], options["plot_path"]
    side = None if output is None or output.suffix.lower() == ".json" else sidecar(output)
    refuse_overwriting_inputs(
        [options["record_file"], options["protocol_file"]],
        [("-o", output), ("-o (its NAME.params.json)", side), ("--plot", plot_path)],
    )
    window = _window(options["window_text"])  # the options first: a typing error is said before the record is read
    max_time = positive(options["max_time"], "time", "--max-time")
    sigma = options["normal_stress"]  # divides a shear-stress column into friction
    sigma = None if sigma is None else positive(sigma, "stress", "--normal-stress")
    area = None if options["area_text"] is None else positive(options["area_text"], "area", "--contact-area")
    record = read_record(options["record_file"], parse_columns(options["columns"]), options["displacement_unit"],
                         options["time_unit"], normal_stress=sigma, contact_area=area)  # fmt: skip
    settings = _fit_settings(options, record, window)
    if settings["mcmc_steps"] and importlib.util.find_spec("emcee") is None:  # said before any work, as --bayes
        raise ParameterError("--mcmc: the posterior needs emcee: pip install stickslip[bayes]")
    started = time.perf_counter()
    # a record with no response to its velocity changes (or rows at one velocity) is said in seconds, before the
    # estimate of a search that cannot find one (tester W's 1e6 noise rows: "up to 8.7 min", then 47 s of CPU)
    fit = response_check(record, **settings)
    cost = estimate_fit_cost(record, settings) if fit is None else FitCost(0.0, 0, 0)
    if cost.seconds > max_time:
        raise ParameterError(
            f"rsf fit: estimated {cost.text()}, above --max-time {_duration(max_time)}; allow it with --max-time "
            f'"{_duration(2 * cost.seconds).replace("under ", "")}" or fit less: a --window, fixed parameters'
        )
    if cost.seconds > PROGRESS_AFTER_SECONDS:
        click.echo(f"stickslip: rsf fit: {cost.text()}", err=True)
    try:
        if fit is None:
            started = time.perf_counter()
            with _deadline(max_time), restart_notice(_restart_notice(cost)):
                fit = fit_record(record, **settings)
    except FitNotEvaluated as exc:  # a failed fit whose report (where the search ended) is printed below, exit 3
        fit = exc.fit
    except ModelError as exc:  # the search ran and ended where the model cannot be run: a failed fit, not bad input
        click.echo(_one_line(f"stickslip: fit failed: {exc}"), err=True)
        raise SystemExit(FIT_FAILED) from None
    except _OutOfTime:
        click.echo(f"stickslip: fit failed: stopped at --max-time {_duration(max_time)} (estimated "
                   f"{_duration(cost.seconds)}); nothing written; allow more with --max-time or fit less (a "
                   "--window, fixed parameters)", err=True)  # fmt: skip
        raise SystemExit(FIT_FAILED) from None
    elapsed = time.perf_counter() - started
    if options["history"] == "measured" and fit.protocol_source == "given":
        fit = dataclasses.replace(fit, protocol_source="measured load-point displacement (smoothed)")
    report = fit.summary()
    report["cost"] = {"seconds": elapsed, "estimated_seconds": cost.seconds, "model_run_seconds": cost.run_seconds,
                      "estimated_model_runs": cost.runs}  # fmt: skip
    if output is not None and fit.status == "ok":
        as_parameters = json_text(fit.parameters_document(report))  # what `rsf simulate --params` reads
        if output.suffix.lower() == ".json":  # what its name says: the JSON `--params` reads (no TOML inside)
            write_text(output, as_parameters)
        else:
            write_text(output, fit.to_toml())
            if side is not None:
                write_text(side, as_parameters)
    if options["as_json"]:
        click.echo(json_text(report))
    else:
        estimated = f"estimated {_duration(cost.seconds)}" if cost.runs else "no search: nothing to estimate"
        click.echo(_fit_text(fit) + f"\n  time: {_duration(elapsed)} ({estimated})")
    if plot_path is not None:
        from ..plots.rsf import fit_figure

        save_figure(fit_figure(fit), plot_path)
    if fit.posterior and not fit.posterior.get("converged", True):  # said, as fit steady --bayes says it; exit 0
        click.echo(_one_line(f"stickslip: warning: rsf fit --mcmc: {fit.posterior.get('warning', 'NOT CONVERGED')}"),
                   err=True)  # fmt: skip
    if fit.status != "ok":
        unwritten = f" ({output} not written)" if output is not None else ""
        click.echo(_one_line(f"stickslip: fit failed: {fit.reason}{unwritten}"), err=True)
        # SystemExit, not click's Exit: main() runs click with standalone_mode=False, which swallows Exit's code
        raise SystemExit(FIT_FAILED)


#: exit status of a fit that ran but cannot be trusted (2 is bad input, 1 an internal error)
FIT_FAILED = 3


def _one_line(text: str) -> str:
    return " ".join(text.split())


#: A --max-time beyond this (three years) sets no timer: the platform's timers overflow near 1e12 s.
LONGEST_TIMER_SECONDS = 1e8


class _OutOfTime(BaseException):
    """Raised by the --max-time alarm inside a running fit: a BaseException, so no ``except Exception`` on the
    way (the optimiser, the integrator's callbacks) can swallow it."""


@contextlib.contextmanager
def _deadline(seconds: float) -> Iterator[None]:
    """Stop the block with :class:`_OutOfTime` after ``seconds`` (an estimate can be wrong: the issue's fit ran
    17 minutes); a no-op off the main thread or without interval timers (Windows)."""
    if (
        threading.current_thread() is not threading.main_thread()
        or not hasattr(signal, "setitimer")
        or seconds > LONGEST_TIMER_SECONDS
    ):
        yield
        return

    def ring(signum: int, frame: Any) -> None:
        raise _OutOfTime

    previous = signal.signal(signal.SIGALRM, ring)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _window(text: str | None) -> tuple[float | None, float | None] | None:
    """``--window T0:T1`` as (T0, T1) in seconds (None for an end left out); units required, as everywhere."""
    if text is None:
        return None
    parts = text.split(":")
    if len(parts) != 2 or not "".join(parts).strip():
        raise ParameterError(
            f"--window {shorten(text)}: expected START:END with units, e.g. --window '20100 s:21000 s'"
            " (an end may be left out)"
        )
    ends = [None if not part.strip() else _window_end(part.strip()) for part in parts]
    if ends[0] is not None and ends[1] is not None and not ends[0] < ends[1]:
        raise ParameterError(f"--window {shorten(text)}: the start must come before the end")
    return ends[0], ends[1]


def _window_end(text: str) -> float:
    from .common import require_unit

    require_unit(text, "time", "--window ", typical=1e3)  # a bare 20100 is meant in seconds, not ms
    return quantity(text, "time", "--window")


def _within_record(window: tuple[float | None, float | None], text: str, record: Any) -> tuple[float, float]:
    """The window's ends on the record's own clock (its ends where left out); at least 10 rows inside."""
    first, last = record.t0, record.t0 + float(record.time[-1])
    lo = first if window[0] is None else window[0]
    hi = last if window[1] is None else window[1]
    clock = record.time + record.t0
    inside = int(np.count_nonzero((clock >= lo) & (clock <= hi)))
    if inside < MIN_WINDOW_ROWS:
        raise ParameterError(
            f"--window {shorten(text)}: {inside} rows of the record fall inside (it runs from {first:.6g} s to "
            f"{last:.6g} s on its own clock); expected at least {MIN_WINDOW_ROWS}"
        )
    return lo, hi


def _key_values(items: tuple[str, ...], flag: str, sigma: float | None) -> dict[str, float]:
    """Repeated ``FLAG KEY=VALUE`` (the house parser, :func:`stickslip.cli.common.key_value`) as SI values."""
    from .common import key_value

    out: dict[str, float] = {}
    for item in items:
        key, value = key_value(item, flag, example=f"{flag} 'dc=20 um'")
        key = key.lower()
        if key not in FIT_KEYS:
            raise ParameterError(f"{flag} {shorten(item)}: unknown parameter {key!r}; expected one of "
                                 f"{', '.join(FIT_KEYS)}")  # fmt: skip
        if not value:
            raise ParameterError(f"{flag} {key}=: expected a value after '=', e.g. {flag} '{key}=...'")
        if key in out:
            raise ParameterError(f"{flag} {key}: given twice")
        out[key] = _fit_value(key, value, flag, sigma)
    return out


def _fit_value(key: str, text: str, flag: str, sigma: float | None) -> float:
    from .common import require_unit

    dimension = FIT_KEYS[key]
    require_unit(text, dimension, f"{flag} {key}=")
    name = f"{flag} {key}"
    if key == "stiffness":
        return _per_sigma(text, "per_length", "stress_per_length", sigma, name)
    if key in _POSITIVE_KEYS:
        return positive(text, dimension, name)
    return quantity(text, dimension, name)


def _free_keys(items: tuple[str, ...]) -> set[str]:
    keys = {item.strip().lower() for item in items}
    unknown = sorted(keys - set(FIT_KEYS))
    if unknown:
        raise ParameterError(f"--free {shorten(unknown[0])}: unknown parameter; expected one of {', '.join(FIT_KEYS)}")
    return keys


def _laws(text: str, states: int | None) -> tuple[str | tuple[str, ...], int]:
    """``--law aging`` or ``--law aging,slip`` (one per state) and the number of states."""
    from ..rsf import get_law

    names = [name.strip().lower() for name in text.split(",")]
    if not all(names):
        raise ParameterError(f"--law {shorten(text)}: expected law names separated by commas, e.g. aging,slip")
    for name in names:
        try:
            get_law(name)
        except ParameterError as exc:
            raise ParameterError(f"--law {shorten(text)}: {exc}") from None
    if len(names) > 2:
        raise ParameterError(f"--law {shorten(text)}: {len(names)} laws, but a fit has at most 2 state variables")
    if states is None:
        states = len(names)
    if len(names) > 1 and len(names) != states:
        raise ParameterError(f"--law {shorten(text)} names {len(names)} laws for --states {states}: give one law "
                             "for every state, or one per state")  # fmt: skip
    return (names[0] if len(names) == 1 else tuple(names)), states


def _stiffness_roles(
    options: dict[str, Any], fixed: dict[str, float], guess: dict[str, float], free: set[str], sigma: float | None
) -> None:
    """Place --stiffness among the held (alone) or started (with --fit-stiffness) values."""
    if options["fit_stiffness"]:
        free.add("stiffness")
    if options["stiffness"] is None:
        return
    k = _per_sigma(options["stiffness"], "per_length", "stress_per_length", sigma, "--stiffness")
    for flag, given in (("--fix", fixed), ("--guess", guess)):
        if "stiffness" in given:
            raise ParameterError(f"--stiffness and {flag} stiffness=: give one of them")
    (guess if "stiffness" in free else fixed)["stiffness"] = k


def _trend_kinds(options: dict[str, Any], fixed: dict[str, float], guess: dict[str, float], free: set[str]) -> str:
    """The drifts to fit as fit_record's word: '' (none), slip, time or both."""
    kinds = {"slip": {"slip"}, "time": {"time"}, "both": {"slip", "time"}, None: set()}[options["trend"]]
    for key, kind in (("trend", "slip"), ("time_trend", "time")):
        if key in free or key in guess:
            kinds.add(kind)
        if key in fixed and kind in kinds:
            also = "--trend" if key not in free and key not in guess else ("--free" if key in free else "--guess")
            raise ParameterError(f"--fix {key} and {also}: the {kind} drift is either held or fitted")
    return "both" if len(kinds) == 2 else next(iter(kinds), "")


def _fit_settings(
    options: dict[str, Any], record: Any, window: tuple[float | None, float | None] | None
) -> dict[str, Any]:
    """The keyword arguments of :func:`stickslip.rsf.fit.fit_record` the options ask for (every value SI)."""
    sigma = None
    if options["normal_stress"] is not None:
        sigma = positive(options["normal_stress"], "stress", "--normal-stress")
    law, states = _laws(options["law"], options["states"])
    fixed = _key_values(options["fix_items"], "--fix", sigma)
    guess = _key_values(options["guess_items"], "--guess", sigma)
    free = _free_keys(options["free_keys"])
    _stiffness_roles(options, fixed, guess, free, sigma)
    for key in sorted(set(fixed) & (set(guess) | free)):
        named = key in _free_keys(options["free_keys"])  # (else the stiffness was freed by --fit-stiffness)
        other = f"--guess {key}" if key in guess else f"--free {key}" if named else "--fit-stiffness"
        raise ParameterError(f"--fix {key} and {other}: a parameter is either held or fitted")
    if states == 1:
        for flag, keys in (("--fix", fixed), ("--guess", guess), ("--free", free)):
            for key in _SECOND_STATE_KEYS:
                if key in keys:
                    raise ParameterError(f"{flag} {key}: a second state variable needs --states 2")
    settings: dict[str, Any] = {"law": law, "states": states, "trend": _trend_kinds(options, fixed, guess, free)
                                or False, "protocol": _history(options, record),
                                "mcmc_steps": options["mcmc_steps"], "seed": options["seed"]}  # fmt: skip
    if "stiffness" in free or "stiffness" in guess:
        settings["fit_stiffness"] = True
    # only what was asked for goes in: fit_record's other arguments keep their defaults
    if fixed:
        settings["fixed"] = fixed
    if guess:
        settings["guess"] = guess
    if window is not None:
        settings["window"] = _within_record(window, options["window_text"], record)
    if options["step_weight"] is not None:
        settings["step_weight"] = _step_weight(options["step_weight"])
    if (cutoff := _cutoff(options)) is not None:
        settings["cutoff"] = cutoff
    return settings


def _step_weight(text: str) -> float:
    weight = bare_number(text)
    if weight is None or not (math.isfinite(weight) and weight > 0):
        raise ParameterError(f"--step-weight {shorten(text)}: expected a positive number, e.g. --step-weight 5")
    return weight


def _history(options: dict[str, Any], record: Any) -> Any:
    """The load-point history the options give (None: fit_record finds it from the displacement)."""
    from .. import protocols

    given = [flag for flag, value in (("--segment", options["segment"]), ("--protocol", options["protocol_file"]))
             if value]  # fmt: skip
    if len(given) == 2:
        raise ParameterError("--segment and --protocol: give one of them")
    if options["history"] == "measured":
        if given:
            raise ParameterError(f"--history measured and {given[0]}: the measured history is the record's own "
                                 "displacement; give one of them")  # fmt: skip
        from ..rsf.data import measured_history

        return measured_history(record)
    if options["protocol_file"] is not None:  # (its time starts at the record's first row: none before it)
        return protocols.read_protocol(options["protocol_file"], negative_time=(
            "rsf fit's history starts at the record's first row (time 0), and the model cannot be started on a "
            "history from before the record; expected times from 0, or fit from where the friction has settled "
            '(--window "T0 s:")'))  # fmt: skip
    if options["segment"]:
        return protocols.Protocol(tuple(protocols.parse_segment(checked_segment_text(s)) for s in options["segment"]))
    return None


def estimate_fit_cost(record: Any, settings: dict[str, Any]) -> FitCost:
    """One model run of the record's history at the fit's tolerance, timed, times the runs a fit typically takes
    (docs/rsf.md, "Cost estimate and --max-time"; tests/test_rsf_fit_cli.py checks one)."""
    held = set(settings.get("fixed", {})) - {"trend", "time_trend"}  # a held drift is no fitted one either way
    free = 5 + (2 if settings["states"] == 2 else 0) - len(held)  # mu0, a, b, Dc, k (b2, Dc2)
    trend = settings["trend"] or ""
    free += {"both": 2, "slip": 1, "time": 1}.get(trend, 0)
    searches = 2 + 2 * (settings["states"] == 2)  # the two-state search follows a one-state one and runs longer
    runs = searches * (free + 1) * JACOBIANS_PER_SEARCH
    if settings["mcmc_steps"]:
        runs += max(4 * free, 16) * settings["mcmc_steps"]
    added, words = _restart_searches(settings)
    restart_runs = runs + added * (free + 1) * RESTART_JACOBIANS
    return FitCost(_timed_run(record, settings), runs, free, restart_runs, words)


def _restart_notice(cost: FitCost) -> Callable[[str, int], None]:
    """What ``rsf fit`` says on stderr when the first search restarts (fit_record's ``notify``): the searches it adds
    and their time at the estimate's pace, where that is above PROGRESS_AFTER_SECONDS (the tester's velstep1 fit,
    estimated at 2.3 s, ran 17 s without a word)."""

    def notice(text: str, searches: int) -> None:
        more = cost.run_seconds * searches * (cost.free + 1) * RESTART_JACOBIANS
        if more > PROGRESS_AFTER_SECONDS:
            click.echo(f"stickslip: rsf fit: {text} (up to {searches} more searches, up to {_duration(more)} more)",
                       err=True)  # fmt: skip

    return notice


def _restart_searches(settings: dict[str, Any]) -> tuple[int, str]:
    """The searches a fit adds when its first search ends troubled (reduced chi-square > 2: every measured record of
    docs/rsf.md), and their words: one per other start in Dc (each in as many stages as the first: a one-state
    search before a two-state one, one without the time drift first), and, for one state of a built-in law, one
    per other law tried (and with a held stiffness, the stiffness freed, alone and with the best other law)."""
    from ..rsf.fit import ALTERNATIVE_LAWS, RETRY_DC_FACTORS

    fixed, states = settings.get("fixed", {}), settings["states"]
    stages = 1 + (states == 2) + (settings["trend"] in ("time", "both"))
    retries = 0 if "dc" in fixed else len(RETRY_DC_FACTORS)
    law = settings["law"] if isinstance(settings["law"], str) else settings["law"][0]
    laws = len(ALTERNATIVE_LAWS) - 1 if states == 1 and law in ALTERNATIVE_LAWS else 0
    held = "stiffness" in fixed and not settings.get("fit_stiffness")
    # one state: a second state variable of the same law, where no one-state alternative describes the record (its
    # two stages from the fit's answer, 2.2 s of CPU on the tester's 105,001-row r_2state record: about one search)
    second = int(states == 1)
    others = laws + (1 + (laws > 0) if held else 0) + second
    words = [f"{retries} searches from other starts in Dc" if retries else "",
             f"{laws} other law{'s' if laws > 1 else ''}" if laws else "",
             "the stiffness freed" if held else ""]  # fmt: skip
    said = " and ".join(w for w in words if w)
    if second:
        said += f"{', and ' if said else ''}a second state variable where no one-state alternative describes it"
    return retries * stages + others, said


def _timed_run(record: Any, settings: dict[str, Any]) -> float:
    """Seconds of one model run over the fitted rows at start-like values (the mean of the second and third)."""
    from ..rsf import simulate
    from ..rsf.fit import FIT_RTOL, fitted_rows, refuse_one_velocity

    rows, history = fitted_rows(record, settings["protocol"], settings.get("window"))  # refused as the fit would be
    if history.initial_velocity > 0:  # rows at one velocity: refused before any estimate, as the fit refuses them
        refuse_one_velocity(rows, history)
    if float(np.max(history.velocities)) <= 0:
        return 0.0
    start = history.initial_velocity if history.initial_velocity > 0 else float(np.max(history.velocities))
    params = _start_params(rows, start, settings)
    times = np.clip(rows.time, 0.0, history.duration)
    took = []
    for _ in range(3):
        began = time.perf_counter()
        try:
            simulate(params, history, start_velocity=start, times=times, rtol=FIT_RTOL, atol=FIT_RTOL * 1e-2,
                     detect=False)  # fmt: skip
        except StickslipError:  # a start that blows up still took its time
            pass
        took.append(time.perf_counter() - began)
        if took[0] > SLOW_RUN_SECONDS:
            return took[0]
    # the first run in a process imports the integrators (about a second): the mean of the other two
    return (took[1] + took[2]) / 2


def _start_params(record: Any, v_ref: float, settings: dict[str, Any]) -> Any:
    """Values like the fit's starting ones (held and guessed values where given): the estimate's model."""
    from ..rsf import RSFParams, StateVariable

    given = {**settings.get("guess", {}), **settings.get("fixed", {})}
    slip = max(float(np.ptp(record.displacement)), 1e-9)
    dc = given.get("dc", min(max(slip / 100, 1e-7), 1e-3))
    stiffness = given.get("stiffness", 0.02 / dc)
    laws = settings["law"] if isinstance(settings["law"], tuple) else (settings["law"],) * settings["states"]
    states = [StateVariable(laws[0], given.get("b", 0.015), dc)]
    if settings["states"] == 2:
        states.append(StateVariable(laws[1], given.get("b2", 0.002), given.get("dc2", 10 * dc)))
    mu0 = given.get("mu0", float(np.median(record.friction[: max(5, len(record) // 50)])))
    return RSFParams(a=given.get("a", 0.01), states=tuple(states), mu0=mu0, v_ref=v_ref, stiffness=stiffness)


def _fit_text(fit: Any) -> str:
    from ..display import unit as shown_unit

    unit = shown_unit(fit.record.length_unit)
    lines = [f"rate-and-state fit of {fit.record.source} ({len(fit.record)} rows): {fit.status}"
             + (f": {fit.reason}" if fit.reason else "")]  # fmt: skip
    laws = [state.law for state in fit.params.states]
    if len(set(laws)) == 1:
        lines.append(f"  state evolution: {laws[0]} law" + (f" ({len(laws)} state variables)" if len(laws) > 1 else ""))
    else:
        lines.append(f"  state evolution: {laws[0]} law (first state), {laws[1]} law (second)")
    # every time in the text is on the record file's own clock, the clock --window and the title use
    lines.append(f"  load point ({fit.protocol_source}), times on the file's own clock:")
    rows = fit.protocol_rows()
    if len(rows) > SHOWN_SEGMENTS:  # a measured history: hundreds of short pieces
        speeds = [row["velocity"] for row in rows]
        lines.append(f"    {len(rows)} constant-velocity pieces from {_clock(rows[0]['file_time'], fit)} s over "
                     f"{sum(r['duration'] for r in rows):.6g} s, {min(speeds):.6g} to {max(speeds):.6g} "
                     f"{unit}/s")  # fmt: skip
    for row in rows if len(rows) <= SHOWN_SEGMENTS else []:
        lines.append(f"    from {_clock(row['file_time'], fit)} s: {row['velocity']:.6g} {unit}/s for "
                     f"{row['duration']:.6g} s")  # fmt: skip
    for name, p in {**fit.parameters, **fit.derived}.items():
        # mu0 is the friction at the fit's reference velocity (the first load-point velocity), not at any other
        lines.append(f"  {name:10s} {p.text()}" + (f", at {fit.reference_velocity_text()}" if name == "mu0" else ""))
    lines += [f"  {line}" for line in fit.change_lines()]  # (on the file's own clock too)
    lines.append(f"  reduced chi-square {fit.reduced_chi_square:.4g} (noise {fit.noise:.3g}), rms {fit.rms:.4g}")
    lines += _posterior_lines(fit)
    lines += [f"  note: {n}" for n in fit.notes]
    lines += [f"  warning: {w}" for w in fit.warnings]
    return "\n".join(lines)


def _clock(seconds: float, fit: Any) -> str:
    """A time on the file's own clock to six significant digits of the fitted span (a record at 20086 s shows
    centiseconds over a 2233 s span, as its start times relative to the first row did), trailing zeros cut."""
    span = float(fit.record.time[-1]) if len(fit.record) else 0.0
    decimals = min(max(5 - math.floor(math.log10(span)), 0), 9) if span > 0 else 6
    text = f"{seconds:.{decimals}f}"
    return text.rstrip("0").rstrip(".") if "." in text else text


def _posterior_lines(fit: Any) -> list[str]:
    """The --mcmc posterior (medians and 2.5/97.5 % percentiles) in the record's units, as the values above."""
    from ..display import unit as shown_unit

    post = fit.posterior
    if not post:
        return []
    size = f"emcee, {post['steps']} steps x {post['walkers']} walkers"
    mixed = post.get("converged", True)
    lines = [
        f"  posterior ({size}): median, 95 % [2.5 %, 97.5 %]"
        if mixed
        else f"  posterior ({size}) NOT CONVERGED: medians only, no interval (the least-squares ones above stand)"
    ]
    for name, entry in post.items():
        if not isinstance(entry, dict) or "median" not in entry:
            continue
        shown = fit.parameters.get(name)
        k = shown.scale if shown is not None else 1.0
        unit = f" {shown_unit(shown.unit)}" if shown is not None and shown.unit else ""
        if entry.get("interval") is None:  # an unmixed chain's percentiles are no interval (too narrow, off centre)
            lines.append(f"    {name:10s} {entry['median'] / k:.6g}{unit}")
            continue
        lo, hi = entry["interval"]
        lines.append(f"    {name:10s} {entry['median'] / k:.6g}{unit}   95 % [{lo / k:.6g}, {hi / k:.6g}]")
    if post.get("warning"):
        lines.append(f"  warning: posterior: {post['warning']}")
    return lines


def register(cli: click.Group) -> None:
    cli.add_command(rsf_group)
