"""``stickslip run --model NAME``: any registered friction model through the one model interface.

The protocol and the rig in the words every run command shares (:mod:`.protocol_options`); the parameters
as ``--params`` and ``--set KEY=VALUE`` (the model's own keys, with units); the result is one
:class:`stickslip.models.Run`: ``-o`` writes its CSV (units in the header, the regime in a first comment
line; ``stickslip analyze`` reads it as a measured trace), ``--json`` its summary, ``--plot`` its figure.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from .. import regimes
from ..errors import ModelError, ParameterError, RunFailed, UnitError
from ..numerics.budget import BudgetExhausted
from ..progress import progress
from ..units import shorten
from .common import (
    FILE_PATH,
    emit_json,
    key_value,
    refuse_overwriting_inputs,
    require_unit,
    save_figure,
    set_values,
    stacked,
    write_failed,
)
from .protocol_options import build_protocol, build_rig, inertia_options, protocol_options, refuse_unsupported
from .run_report import model_record, record_text

#: Exit status of a run the model could not finish (status "failed"); 2 is bad input.
RUN_FAILED = 3


def model_spec_options(func: Any) -> Any:
    """``--model NAME`` (a registered name or ``module:attr``), ``--params``, repeatable ``--set`` and ``--start``."""
    options = [
        click.option("--model", "model_name", default="quasi-static", show_default=True, metavar="NAME",
                     help="A registered model (quasi-static, transient, rsf, or one of an installed package) or"
                     " an import path MODULE:ATTR."),
        click.option("--params", "params_name", default=None, metavar="NAME|FILE",
                     help="The model's parameters: a built-in set or a file [the model's defaults]."),
        click.option("--set", "overrides", multiple=True, metavar="KEY=VALUE",
                     help="Override one of the model's parameter keys, with its unit; repeatable."),
    ]  # fmt: skip
    return stacked(options, func)


def output_options(func: Any) -> Any:
    """``-o``, ``--plot`` and ``--json``: what ``run`` and each of its spellings writes, in the same words."""
    options = [
        click.option("-o", "--output", type=FILE_PATH,
                     help="Write the Run as CSV (units in the header; stickslip analyze reads it)."),
        click.option("--plot", "plot_path", type=FILE_PATH,
                     help="Save the run's figure."),
        click.option("--json", "as_json", is_flag=True, help="Print the summary as JSON (SI units)."),
    ]  # fmt: skip
    return stacked(options, func)


def load_model(model_name: str) -> Any:
    from ..models import get_model
    from ..models.base import checked_dimensions

    model = get_model(model_name)
    checked_dimensions(model)  # a plug-in's key of an unknown dimension: refused before anything is read
    return model


def model_overrides(model: Any, overrides: tuple[str, ...]) -> dict[str, str]:
    """``--set KEY=VALUE`` as {key: text}: a dimensional value needs its unit, as everywhere on the command line."""
    return set_values(overrides, model.dimensions().get)


def model_parameters(model: Any, params_name: str | None, overrides: dict[str, str]) -> Any:
    """The model's parameters from ``--params`` (a name or a file; a JSON/TOML mapping for models that take one);
    a plug-in's own exception is refused in one line naming the plug-in (:func:`plugin_refusal`)."""
    try:
        return _model_parameters(model, params_name, overrides)
    except Exception as exc:
        refusal = plugin_refusal(model, exc, "its parameters()")
        if refusal is exc:
            raise
        raise refusal from None


def plugin_refusal(model: Any, exc: Exception, doing: str, start: Any = None, start_option: str = "--start ") -> Any:
    """``exc`` as it is, unless it is a plug-in's own (not a stickslip error): then a ParameterError (exit 2) that
    names the model, the plug-in's class, the exception and, for a word ``--start``, that option (before: "internal
    error (ValueError): could not convert string to float: np.str_('steady')", exit 1, as if stickslip's bug)."""
    from ..errors import StickslipError
    from ..models.registry import is_plugin, plugin_error

    if isinstance(exc, (StickslipError, MemoryError)) or not is_plugin(model):
        return exc
    return ParameterError(plugin_error(model, exc, doing, start, start_option))


def _model_parameters(model: Any, params_name: str | None, overrides: dict[str, str]) -> Any:
    from ..fileio import protect_inputs

    if params_name is not None:
        protect_inputs([params_name])
    try:
        return model.parameters(params_name, overrides)
    except ParameterError:
        from ..models.bond import BondModel

        path = Path(params_name) if params_name is not None else None
        if path is None or path.suffix.lower() not in (".json", ".toml") or not path.is_file():
            raise
        if isinstance(model, BondModel):  # it read the file itself: its refusal names the file and the key
            raise
    from .params_files import load_params_mapping  # a file of the mapping the model reads (rate-and-state's)

    return model.parameters(load_params_mapping(path), overrides)


def start_value(text: str | None, model: Any = None) -> Any:
    """``--start``: a word ("empty", "steady") as it is, or a number with its unit, in SI.

    A number must be of the dimension the model starts from (``model.start_dimension``: the quasi-static model's
    is a stress, rate-and-state's a velocity; None: the model starts only from words), so ``--start '3 Pa'`` is
    never read as 3 m/s.  Without a model (a start routed to several), a stress or a velocity.
    """
    from ..units import quantity_noun, to_si

    if text is None:
        return None
    if text.strip().isalpha():
        words = getattr(model, "start_words", None)
        if words is not None and text.strip() not in words:
            dimension = getattr(model, "start_dimension", None)
            example = _START_EXAMPLES.get(dimension, "a value with its unit")
            if words:  # a plug-in's start_words=("steady",) with a velocity: name both ("not a word" was untrue)
                number = "" if dimension is None else f", or {quantity_noun(dimension)} with its unit ({example})"
                raise ParameterError(
                    f"--start {shorten(text)}: --model {model.name} starts from {_word_list(words)}{number};"
                    f" got the word {text.strip()!r}"
                )
            raise ParameterError(
                f"--start {shorten(text)}: --model {model.name} starts from {quantity_noun(dimension)}, not a word;"
                f" expected one with its unit, e.g. {example}"
            )
        return text.strip()
    if model is not None:
        dimension = getattr(model, "start_dimension", None)
        if dimension is None:
            words = getattr(model, "start_words", None)
            named = _word_list(words) if words else "a word (transient: empty or steady)"
            raise ParameterError(f"--start {shorten(text)}: --model {model.name} starts from {named}, not a number")
        require_unit(text, dimension, "--start ")
        try:
            value = to_si(text, dimension, "--start")
        except UnitError:
            raise ParameterError(
                f"--start {shorten(text)}: --model {model.name} starts from {quantity_noun(dimension)};"
                f" expected one with its unit, e.g. {_START_EXAMPLES.get(dimension, 'a value with its unit')}"
            ) from None
        return _finite_start(value, text)
    for dimension in ("stress", "velocity"):
        try:
            require_unit(text, dimension, "--start ")
            return _finite_start(to_si(text, dimension, "--start"), text)
        except UnitError:
            continue
    raise ParameterError(
        f"--start {shorten(text)}: expected a word (empty, steady) or a stress or velocity with its unit"
    )


#: How a start of each dimension is written, in refusals.
_START_EXAMPLES = {"stress": "--start '400 Pa'", "velocity": "--start '50 um/s'"}


def _word_list(words: tuple[str, ...]) -> str:
    """A model's start words in a refusal: "the word steady", "one of the words empty or steady"."""
    if len(words) == 1:
        return f"the word {words[0]}"
    return f"one of the words {', '.join(words[:-1])} or {words[-1]}"


def _finite_start(value: float, text: str) -> float:
    if not math.isfinite(value):
        raise ParameterError(f"--start {shorten(text)}: expected a finite value")
    return value


def in_run_words(message: str, start_option: str) -> str:
    """A model's refusal in this command's words: ``rsf simulate``'s --start-velocity is --start here."""
    return message.replace("give --start-velocity", f"give {start_option}'V um/s', the start's velocity")


def settings_of(texts: tuple[str, ...], every_text: str | None) -> dict[str, Any]:
    """``--setting KEY=VALUE`` (a word, true/false, a number, or a quantity with its unit, in SI) and ``--every``."""
    from .common import positive

    settings: dict[str, Any] = {}
    for item in texts:
        key, value = key_value(item, "--setting", example="--setting jump_curve=no-aging")
        if value.lower() in ("true", "false"):
            settings[key] = value.lower() == "true"
            continue
        try:
            settings[key] = int(value) if value.lstrip("+-").isdigit() else float(value)
            continue
        except ValueError:
            pass
        settings[key] = _setting_quantity(value, key)
    if every_text is not None:
        settings["every"] = positive(every_text, "time", "--every")
    return settings


#: the dimensions a setting's value with a unit may have (its unit says which): every="10 ms",
#: start_velocity="150 um/s" (a time alone was read: a velocity stayed a string the model refused)
SETTING_DIMENSIONS = ("time", "velocity", "stress", "length", "stress_per_length", "mass_per_area")


def _setting_quantity(value: str, key: str) -> Any:
    """A setting's value with its unit in SI, or the text as it is (a word such as ``no-aging``)."""
    from ..units import to_si

    for dimension in SETTING_DIMENSIONS:
        try:
            return to_si(value, dimension, f"--setting {key}")
        except (UnitError, ParameterError):
            continue
    return value


#: Why a model that takes no ``every`` setting has no --every (its trace is sampled its own way).
NO_EVERY = {"quasi-static": "its trace is its phases, thinned"}

#: Models that sample no further than the end of the run (rate-and-state reads an --every beyond it at the end).
EVERY_WITHIN_RUN = ("transient",)


def refuse_every(model: Any, protocol: Any, every_text: str | None) -> None:
    """Refuse, in one line naming --every as written, an --every the model cannot take: a model without the
    setting, or a step longer than the run for a model that samples within it."""
    from ..units import format_si
    from .common import positive

    if every_text is None:
        return
    if "every" not in model.capabilities.settings:
        why = NO_EVERY.get(model.name, "it samples its trace itself")
        raise ParameterError(
            f"--every {shorten(every_text)}: the {model.name} model takes no --every ({why}); leave it out"
        )
    every = positive(every_text, "time", "--every")
    if model.name in EVERY_WITHIN_RUN and every > protocol.duration:
        raise ParameterError(
            f"--every: got {every_text.strip()} ({format_si(every, 'time')}), longer than the run"
            f" ({format_si(protocol.duration, 'time')}); expected a step no longer than the run"
        )


#: the regimes whose peak and trough are those of an oscillation (the others: the run's highest and lowest)
OSCILLATING = regimes.OSCILLATING


def run_summary(run: Any, protocol: Any, rig: Any, spring: tuple[float, str, str] | None = None) -> dict[str, Any]:
    """What a run settled into, in SI: regime with its evidence, period, peak, trough, mean, the model's own numbers.

    ``mean_*`` is the model's mean of what the run settled into (the repeating cycle's, the steady value; a sweep
    row's ``mean_stress``), ``run_mean_*`` the mean of the solution over the run; ``run_peak_*`` and
    ``run_trough_*`` the run's highest and lowest where the model gives them from its solution (the peak and trough
    are the last segment's).  ``spring``: the stiffness the run used, its unit and where it came from
    (``model.spring``); without it the rig's as given.
    """
    signal = "stress" if run.stress is not None else "friction"
    r = run.regime
    extremes = {  # the model's own, from its solution (the transient model's: every state, whatever the rows kept)
        f"run_{word}_{signal}": _above_round_off(float(run.summary[f"run_{word}_{signal}"]))
        for word in ("peak", "trough")
        if run.summary.get(f"run_{word}_{signal}") is not None
    }
    return {
        "model": run.model,
        "status": run.status,
        "message": run.message,
        "protocol": [{"velocity": s.velocity, "duration": s.duration} for s in protocol.segments],
        "rig": rig_record(rig, spring),
        "regime": run.regime_name,
        "oscillates": r.kind in OSCILLATING or (r.kind == regimes.BLOW_UP and r.periods > 0),
        "evidence": r.evidence,
        "periods_seen": r.periods,
        "amplitude_ratio": r.amplitude_ratio,
        "period": run.period,
        f"peak_{signal}": _above_round_off(run.peak),
        f"trough_{signal}": _above_round_off(run.trough),
        f"mean_{signal}": _above_round_off(run.mean),
        f"run_mean_{signal}": _above_round_off(run_mean(run)),
        **extremes,
        f"final_{signal}": float(run.signal[-1]) if run.time.size else None,
        "end_time": float(run.time[-1]) if run.time.size else None,
        "summary": dict(run.summary),
    }


def run_mean(run: Any) -> float:
    """The mean of the stress (or friction) over the whole run: the model's own (from its solution) where it gives
    one in its summary, else the time average of the trace."""
    from ..models.run import time_mean

    own = run.summary.get(f"run_mean_{run.signal_name}")
    return float(own) if own is not None else time_mean(run.time, run.signal)


#: Units of the summary's keys that the registry holds under another unit or not at all.
SUMMARY_UNITS = {
    "run_mean_stress": "Pa",
    "run_mean_friction": "1",
    "run_peak_stress": "Pa",
    "run_trough_stress": "Pa",
    "stiffness_from": None,
    "mass": "kg/m^2",  # the rig's block (--mass, --damping)
    "damping": "Pa s/m",
}


def summary_units(summary: dict[str, Any], spring: tuple[float, str, str] | None) -> dict[str, str]:
    """The JSON's ``units`` map: the registry's, the spring's stiffness in the model's unit (rate-and-state: 1/m)."""
    from ..columns import json_units

    extra = dict(SUMMARY_UNITS)
    if spring is not None:
        extra["stiffness"] = spring[1]
    return json_units(summary, extra)


def rig_record(rig: Any, spring: tuple[float, str, str] | None = None) -> dict[str, Any]:
    """The summary's ``rig``, in one vocabulary for every model: ``control`` ("spring" or "velocity", the
    :class:`~stickslip.models.Rig`'s words), the stiffness of ``spring`` (``model.spring``; else the rig's as given)
    and, wherever there is a stiffness, ``stiffness_from``: "rig" (given: ``--stiffness``, in Pa/m or in the model's
    own unit, or ``Rig(stiffness=...)``) or "parameters" (the parameter set's: Eq 17's K, rate-and-state's k, a
    ``--set``); under velocity control no stiffness and no source.  The block's mass and damping where it has
    them."""
    record: dict[str, Any] = {"control": rig.control, "stiffness": rig.stiffness}
    if spring is not None:  # the stiffness used, and where it came from
        record["stiffness"] = spring[0]
        # --stiffness in the model's own unit (rate-and-state's "1e-3 1/um") set its k: given, not the set's
        record["stiffness_from"] = "rig" if spring[2] == "rig" or stiffness_option_given() else spring[2]
    elif rig.stiffness is not None:
        record["stiffness_from"] = "rig"
    if rig.mass is not None:  # the block's inertia (transient --mass/--damping)
        record.update(mass=rig.mass, damping=rig.damping)
    return record


def stiffness_option_given() -> bool:
    """Whether the command being run was given ``--stiffness`` (every spring of its run then has that stiffness:
    the rig's, or the model's k it set; :func:`~stickslip.cli.protocol_options.build_rig`)."""
    ctx = click.get_current_context(silent=True)
    source = ctx.get_parameter_source("stiffness_text") if ctx is not None else None
    return source is not None and source is not click.core.ParameterSource.DEFAULT


def record_in_rig_words(record: dict[str, Any], rig: dict[str, Any]) -> dict[str, Any]:
    """The model's own record with its ``control`` and ``stiffness`` (the transient solver's: "block", and the
    block's K even under velocity control) in the words and values of the summary's ``rig``, which they must not
    contradict: "spring" for "block", no stiffness without a spring."""
    return {**record, **{key: rig[key] for key in ("control", "stiffness") if key in record}}


#: a protocol of more segments is described in one line by its count, length and range of velocities
DESCRIBED_SEGMENTS = 6


def protocol_words(segments: list[dict[str, float]]) -> str:
    """The protocol in one line: each segment, or for many their count, length and range of velocities."""
    from ..display import velocity

    if len(segments) <= DESCRIBED_SEGMENTS:
        return ", then ".join(f"{velocity(s['velocity'], 4)} for {s['duration']:.6g} s" for s in segments)
    speeds = [s["velocity"] for s in segments]
    return (
        f"{len(segments)} segments, {sum(s['duration'] for s in segments):.6g} s in all, at"
        f" {velocity(min(speeds), 4)} to {velocity(max(speeds), 4)}"
    )


#: A stress (Pa) or friction coefficient smaller than this is the solver's round-off, not a value (a block at rest
#: reports a mean stress of -5.6e-17 Pa): it is shown as 0.
ROUND_OFF = 1e-12


def _above_round_off(value: float) -> float:
    return 0.0 if value is not None and math.isfinite(value) and abs(value) < ROUND_OFF else value


def _run_range(summary: dict[str, Any], signal: str, unit: str) -> list[str]:
    """The run's lowest and highest (``run_trough_*``, ``run_peak_*``) where they lie beyond the last segment's: a
    350 -> 1000 -> 350 µm/s step's overshoot to 713.6 Pa, before the last segment, was in no line."""
    low, high = summary.get(f"run_trough_{signal}"), summary.get(f"run_peak_{signal}")
    if low is None or high is None or not (math.isfinite(low) and math.isfinite(high)):
        return []
    window_low, window_high = summary.get(f"trough_{signal}"), summary.get(f"peak_{signal}")
    if low == window_low and high == window_high:
        return []
    return [f"  range over the whole run: {low:.6g} ... {high:.6g}{unit}"]


def _settled_here(summary: dict[str, Any], signal: str) -> bool:
    """Whether the summary's ``mean_*`` is a value the run settled at within itself: the classifier found its tail
    steady (its evidence "steady: ..."; the quasi-static model's steady σ(V0) may lie beyond a run that ends
    before it settles).  A steady plug-in run printed only its mean over the run, which depends on its length."""
    value = summary.get(f"mean_{signal}")
    settled = summary["status"] == "ok" and str(summary.get("evidence", "")).startswith(f"{regimes.STEADY}:")
    return settled and value is not None and math.isfinite(value)


#: how the summary's regime line marks a run that did not finish
_STATUS_WORDS = {"ok": "", "stopped": " (of the run up to its stop: it used up its budget)"}


def summary_text(summary: dict[str, Any], units: dict[str, str] | None = None) -> str:
    """The summary for people: µm/s, Pa (or μ), s; the model's message in full.  ``units``: the JSON's units map
    (the spring's unit: Pa/m, or rate-and-state's 1/m)."""
    protocol = protocol_words(summary["protocol"])
    rig = summary["rig"]
    spring = ""
    if rig["stiffness"] is not None:
        per_slip = (units or {}).get("stiffness") == "1/m"  # rate-and-state's k, friction per slip
        spring = f", k = {rig['stiffness']:.6g} 1/m" if per_slip else f", K = {rig['stiffness'] / 1e3:.6g} kPa/m"
        if rig.get("stiffness_from") is not None:  # (files before 'rig' was said for a stiffness as given: none)
            spring += f" from the {rig['stiffness_from']}"
    if rig.get("mass") is not None:
        spring += f", block mass {rig['mass']:g} kg/m², damping {rig.get('damping') or 0:g} Pa·s/m"
    signal, unit = ("stress", " Pa") if "peak_stress" in summary else ("friction", "")
    lines = [
        f"model {summary['model']}: {protocol} ({rig['control']} control{spring})",
        f"  regime: {summary['regime']}" + _STATUS_WORDS.get(summary["status"], " (the run FAILED)"),
        f"  {summary['message'] or summary['evidence']}",
    ]
    numbers = []
    # a cycle's peak, trough and mean once the run holds a whole one; else the run's range and its mean
    blow_up = summary["regime"] == regimes.BLOW_UP  # its extremes are the run's, not a cycle's
    cycle = summary.get("oscillates", True) and summary.get("periods_seen", 1) != 0 and not blow_up
    if blow_up and summary.get("periods_seen"):
        numbers.append(f"before it {summary['evidence'].removeprefix('blow-up after ')}")
    elif summary["period"] is not None and math.isfinite(summary["period"]):
        numbers.append(f"period {summary['period']:.6g} s" + ("" if cycle else " (no whole cycle within the run)"))
    words = ("peak", "trough", "mean") if cycle else ("trough", "peak", "run_mean")
    shown = {} if cycle else {"peak": "highest", "trough": "lowest", "run_mean": "mean"}
    segments = summary["protocol"]
    for word in words:
        value = summary.get(f"{word}_{signal}")
        if word == "run_mean" and _settled_here(summary, signal):  # the value it settled at, not only the run's mean
            numbers.append(f"settled at {summary[f'mean_{signal}']:.6g}{unit}")
        if value is not None and math.isfinite(value):
            numbers.append(f"{shown.get(word, word)} {value:.6g}{unit}")
            if not cycle and word == "peak" and len(segments) > 1:  # the regime's window: the last segment's
                last = sum(s["duration"] for s in segments[:-1])
                numbers[-1] += f" over the last segment (from t = {last:.6g} s)"
    if not cycle and numbers:
        # "no oscillation" only where none was seen: an undetermined run may hold periods not yet settled
        seen = summary["period"] is not None and math.isfinite(summary["period"])
        quiet = not summary.get("oscillates", True) and not seen and not summary.get("periods_seen")
        numbers[-1] += " over the run" + (" (no oscillation)" if quiet else "")
    if numbers:
        lines.append("  " + ", ".join(numbers))
    if not cycle and len(segments) > 1:  # the run's own range where the last segment's is not all of it
        lines.extend(_run_range(summary, signal, unit))
    return "\n".join(lines)


@click.command("run")
@model_spec_options
@protocol_options(
    stiffness_help='Spring stiffness K in Pa/m, e.g. "400 kPa/m" (rate-and-state also "1e-3 1/um") [the model\'s own].'
)
@click.option(
    "--start",
    "start_text",
    default=None,
    metavar="S",
    help="The model's start: a word (transient: empty, steady) or a stress or velocity with its unit.",
)
@click.option("--every", "every_text", default=None, metavar="DT", help="Sample the trace every DT (if the model can).")
@click.option(
    "--setting",
    "setting_texts",
    multiple=True,
    metavar="KEY=VALUE",
    help="A model setting, e.g. jump_curve=no-aging, stick_population=true, rtol=1e-3; repeatable.",
)
@output_options
@inertia_options
def run_command(**options: Any) -> None:
    """Run any friction model on a protocol, through one interface, into one Run.

    The model refuses, in one line, what it cannot run (the quasi-static model:
    one constant velocity through a spring).  The run's regime comes from the
    one classifier on the model's dense solution.  A run that failed exits
    with status 3.
    """
    o = options
    refuse_overwriting_inputs([o["protocol_file"], o["params_name"]], [("-o", o["output"]), ("--plot", o["plot_path"])])
    model = load_model(o["model_name"])
    earlier, earlier_start = _earlier_run(model, o["params_name"])
    protocol = build_protocol(o["v0_text"], o["duration_text"], o["segment_texts"], o["protocol_file"], earlier)
    mapping = model_overrides(model, o["overrides"])
    rig, own_spring = build_rig(o["control"], o["stiffness_text"], [model], o["mass_text"], o["damping_text"])
    if own_spring:  # a stiffness in the model's own unit sets its key k, as --set k=... would
        mapping["k"] = own_spring[model.name]
    params = model_parameters(model, o["params_name"], mapping)
    refuse_every(model, protocol, o["every_text"])
    settings = settings_of(o["setting_texts"], o["every_text"])
    model.check(protocol, rig, settings)  # what the model cannot do, before any work
    start = start_value(o["start_text"], model)
    if start is None and protocol is earlier:
        start = earlier_start
    execute(model, params, protocol, rig, start=start, settings=settings, output=o["output"],
            plot_path=o["plot_path"], as_json=o["as_json"])  # fmt: skip


def _earlier_run(model: Any, params_name: str | None) -> tuple[Any, float | None]:
    """The protocol and start velocity that a ``.params.json`` written by ``rsf fit`` or ``rsf simulate -o``
    carries, for a model that starts from a velocity (rate-and-state): ``run --model rsf --params F.params.json``
    reruns that history as ``rsf simulate --params`` does.  (None, None) for any other file or model."""
    path = Path(params_name) if params_name is not None else None
    if path is None or path.suffix.lower() != ".json" or not path.is_file():
        return None, None
    if getattr(model, "start_dimension", None) != "velocity":
        return None, None
    from .params_files import history_protocol

    protocol, start = history_protocol(path)
    return (protocol, start) if protocol is not None else (None, None)


def run_spelling(
    model_name: str,
    options: dict[str, Any],
    command: str,
    *,
    settings: Callable[[], dict[str, Any]],
    start: Callable[[], Any] = lambda: None,
    start_option: str = "--start ",
    **limits: Any,
) -> None:
    """The one body of ``simulate`` and ``transient``, spellings of ``run --model NAME`` for the bond models.

    Their parameters from ``--params``/``--set``, the protocol and rig in the shared words (what the model cannot
    run refused first, ``limits`` going to :func:`refuse_unsupported`), then :func:`execute`.  ``settings`` and
    ``start`` read their options where each spelling always read them: before the parameters, and after.
    """
    from ..models import get_model
    from .common import resolve_params

    o = options
    output, plot_path = o["output"], o["plot_path"]
    refuse_overwriting_inputs([o["protocol_file"]], [("-o", output), ("--plot", plot_path)], o["params_name"])
    protocol = build_protocol(o["v0_text"], o["duration_text"], o["segment_texts"], o["protocol_file"])
    refuse_unsupported(command, protocol, o["control"], **limits)
    rig, _ = build_rig(
        o["control"], o["stiffness_text"], mass_text=o.get("mass_text"), damping_text=o.get("damping_text")
    )
    refuse_every(get_model(model_name), protocol, o.get("every_text"))
    chosen = settings()
    params = resolve_params(o["params_name"], o["overrides"])
    execute(get_model(model_name), params, protocol, rig, start=start(), settings=chosen, output=output,
            plot_path=plot_path, as_json=o["as_json"], start_option=start_option)  # fmt: skip


def execute(
    model: Any,
    params: Any,
    protocol: Any,
    rig: Any,
    *,
    start: Any,
    settings: dict[str, Any],
    output: Path | None,
    plot_path: Path | None,
    as_json: bool,
    beside: Any = None,
    start_option: str = "--start ",
) -> Any:
    """Run one model and report it: the one path of ``run`` and of its spellings ``simulate``, ``transient`` and
    ``rsf simulate``.

    ``-o`` writes the Run's CSV (of the run up to its stop, if a budget stopped it), ``--plot`` the figure
    (``run.plot()``, whichever spelling ran it), then the summary: JSON, or the shared text with the model's own
    record below it.  ``beside(run)`` writes what a spelling keeps beside the trace (``rsf simulate``'s
    parameters).  A failed run, or one stopped by its budget, exits with status 3 after saying how far it got.
    """
    from ..fileio import claim_stdout
    from ..models import as_run
    from ..models.run import finished

    claim_stdout([output, plot_path])  # (rsf simulate's trace goes to standard output without -o)
    checked = model.check(protocol, rig, settings)
    stopped: BudgetExhausted | None = None
    with progress(model.name, total=protocol.duration, unit="s", enabled=False if as_json else None) as bar:
        if "progress" in model.capabilities.settings and "progress" not in settings:  # a bar on a terminal only
            settings["progress"] = lambda fraction: bar.update(fraction * protocol.duration)
        try:
            run = finished(model.run(params, protocol, rig, start=start, **settings), protocol)
        except BudgetExhausted as exc:  # it ran and stopped at its budget: what it did is kept (exit 3)
            if getattr(exc, "partial", None) is None:
                click.echo(f"stickslip: the run failed: {exc}", err=True)
                raise SystemExit(RUN_FAILED) from None
            stopped, run = exc, as_run(exc.partial, protocol)
        except RunFailed as exc:  # it ran and could not go on: a failed run (exit 3), not bad input
            if getattr(exc, "partial", None) is None:
                click.echo(f"stickslip: the run failed: {exc}", err=True)
                raise SystemExit(RUN_FAILED) from None
            run = as_run(exc.partial, protocol)  # what it computed, status "failed": written and summarised below
        except (ParameterError, ModelError) as exc:
            raise type(exc)(in_run_words(str(exc), start_option)) from None
        except Exception as exc:  # a plug-in's own (ValueError, ...): named as the plug-in's, not stickslip's bug
            refusal = plugin_refusal(model, exc, "its run", start, start_option)
            if refusal is exc:
                raise
            raise refusal from None
    spring = model.spring(params, checked)
    summary = run_summary(run, protocol, rig, spring)
    record = record_in_rig_words(model_record(run), summary["rig"])
    summary.update((key, value) for key, value in record.items() if key not in summary)
    units = summary_units(summary, spring)
    if stopped is not None:
        summary["status"] = "stopped"
        run = dataclasses.replace(run, status="stopped")  # the file written says so too, as the summary does
    if output is not None:
        _write_run(run, output)
        if beside is not None:
            beside(run)
    if plot_path is not None:
        save_figure(run.plot().figure, plot_path)
    if as_json:
        emit_json({**summary, "units": units})
    else:  # (beside a trace on standard output, claim_stdout above sends it to stderr)
        record = record_text(run, summary["rig"])
        click.echo(summary_text(summary, units) + ("\n" + record if record else ""))
    if stopped is not None:
        written = [str(path) for path in (output, plot_path) if path is not None]
        kept = f"; the run up to there is in {' and '.join(written)}" if written else ""
        click.echo(f"stickslip: error: {stopped}{kept}", err=True)
        raise SystemExit(RUN_FAILED)
    if run.status != "ok":
        click.echo(f"stickslip: the run failed: {run.message}", err=True)
        raise SystemExit(RUN_FAILED)
    return run


def _write_run(run: Any, output: Path) -> None:
    try:
        run.to_csv(output)
    except OSError as exc:
        raise write_failed(output, exc) from None


def register(cli: click.Group) -> None:
    cli.add_command(run_command)


__all__ = ["execute", "output_options", "run_command", "run_spelling", "run_summary", "summary_text"]
