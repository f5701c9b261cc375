"""``stickslip compare --models A,B``: several models, one protocol, one rig, through the model interface.

Each model (a registered name or ``module:attr``) runs the same protocol (``--v0 --duration --segment
--protocol``) through the same rig (``--control``, ``--stiffness`` in Pa/m); ``--set KEY=VALUE`` goes to every
model that has the key, and a key no model has is refused.  The table gives each run's regime, period, peak,
trough and mean (stress in Pa, or the friction coefficient for a model without a normal stress), from the one
classifier; ``-o`` draws them over each other.
"""

from __future__ import annotations

import math
from typing import Any

import click

from ..columns import json_units
from ..errors import ModelError, ParameterError
from ..progress import progress
from ..units import shorten
from .common import check_output, check_unit, emit_json, key_value, refuse_overwriting_inputs, save_figure
from .protocol_options import build_protocol, build_rig
from .run_cmd import (
    in_run_words,
    model_parameters,
    plugin_refusal,
    rig_record,
    run_summary,
    settings_of,
    start_value,
    summary_units,
)

#: Exit status when a model's run failed (status "failed"); 2 is bad input.
FAILED = 3


def model_list(text: str) -> list[Any]:
    """The models of ``--models A,B``: at least two, each named once."""
    from ..models import get_model
    from ..models.base import checked_dimensions

    names = [n.strip() for n in text.split(",") if n.strip()]
    if len(names) < 2:
        raise ParameterError(f"--models {shorten(text)}: expected two or more models, e.g. --models quasi-static,rsf")
    models = [get_model(n) for n in names]
    for model in models:  # a plug-in's key of an unknown dimension: refused before anything is read
        checked_dimensions(model)
    seen: dict[str, str] = {}
    for given, model in zip(names, models, strict=True):
        if model.name in seen:
            raise ParameterError(f"--models: {seen[model.name]} and {given} are the same model ({model.name})")
        seen[model.name] = given
    return models


def merged_units(top: dict[str, str], each: list[dict[str, str]]) -> dict[str, str]:
    """The top-level ``units`` map: the top-level numbers' units, then every key of the models' own maps
    (:func:`~stickslip.cli.run_cmd.summary_units`, the one table) on which they agree.  A key of another unit in
    another model (a spring: Pa/m in one, 1/m in rate-and-state) is left to each model's own map."""
    units = dict(top)
    seen: dict[str, set[str]] = {}
    for own in each:
        for key, unit in own.items():
            seen.setdefault(key, set()).add(unit)
    for key, found in seen.items():
        if key not in units and len(found) == 1:
            units[key] = next(iter(found))
    return dict(sorted(units.items()))


def routed_overrides(models: list[Any], overrides: tuple[str, ...]) -> dict[str, dict[str, str]]:
    """``--set KEY=VALUE`` for each model that has KEY (with its unit, as everywhere on the command line)."""
    routed: dict[str, dict[str, str]] = {m.name: {} for m in models}
    for item in overrides:
        key, value = key_value(item)
        owners = [m for m in models if key in m.dimensions() or (key == "law" and "law" in _extra_keys(m))]
        if not owners:
            names = ", ".join(m.name for m in models)
            raise ParameterError(f"--set {key}: none of the models {names} has this key")
        for model in owners:
            check_unit(key, value, model.dimensions().get(key))
            routed[model.name][key] = value
    return routed


def routed_settings(models: list[Any], texts: tuple[str, ...], every_text: str | None) -> dict[str, dict[str, Any]]:
    """``--setting KEY=VALUE`` (and ``--every``) for each model that takes the setting; one no model takes is
    refused."""
    settings = settings_of(texts, every_text)
    routed: dict[str, dict[str, Any]] = {m.name: {} for m in models}
    for key, value in settings.items():
        owners = [m for m in models if key in m.capabilities.settings]
        if not owners:
            names = ", ".join(m.name for m in models)
            flag = "--every" if key == "every" else f"--setting {key}"
            raise ParameterError(f"{flag}: none of the models {names} takes this setting")
        for model in owners:
            routed[model.name][key] = value
    return routed


def routed_starts(models: list[Any], texts: tuple[str, ...]) -> dict[str, Any]:
    """``--start [MODEL=]S``: a start for one model, or (without MODEL=) for every model."""
    from ..models import get_model

    starts: dict[str, Any] = {}
    for text in texts:
        name, sep, value = text.partition("=")  # a start itself never holds "="
        if sep:
            model = get_model(name.strip())
            if model.name not in {m.name for m in models}:
                listed = ", ".join(m.name for m in models)
                raise ParameterError(f"--start {shorten(text)}: {name.strip()} is not one of the models {listed}")
            starts[model.name] = start_value(value, model)
        else:
            starts.update({m.name: start_value(text, m) for m in models})  # each model reads it in its dimension
    return starts


def _extra_keys(model: Any) -> tuple[str, ...]:
    """Keys a model takes besides its dimensional ones (rate-and-state's ``law``)."""
    return ("law",) if hasattr(model, "LAW_NAMES") else ()


def compare_models(options: dict[str, Any]) -> None:
    """Run every model of ``--models`` and report them side by side (see the module notes)."""
    from ..models.run import finished

    output = options["output"]
    ctx = click.get_current_context()
    params_given = ctx.get_parameter_source("params_name") not in (None, click.core.ParameterSource.DEFAULT)
    params_name = options["params_name"] if params_given else None
    refuse_overwriting_inputs([options["protocol_file"], params_name], [("-o", output)])
    check_output("-o", output, plot=True)
    _refuse_classic_options(ctx)
    models = model_list(options["models"])
    protocol = build_protocol(options["v0_text"], options["duration_text"], options["segment_texts"],
                              options["protocol_file"])  # fmt: skip
    rig, own_spring = build_rig(options["control"], options["stiffness_text"], models)
    settings = routed_settings(models, options.get("setting_texts", ()), options.get("every_text"))
    starts = routed_starts(models, options.get("start_texts", ()))
    # what a model cannot run is refused before any model runs; the checked rig is the one each spring is read from
    checked = {model.name: model.check(protocol, rig, settings[model.name]) for model in models}
    routed = routed_overrides(models, options["overrides"])
    for name, text in own_spring.items():
        routed[name]["k"] = text
    runs, springs = {}, {}
    # one stage per model: a bar on a terminal, nothing in a pipe or with --json
    with progress("compare", total=len(models), unit="models", enabled=False if options["as_json"] else None) as bar:
        for model in models:
            try:
                params = model_parameters(model, params_name, routed[model.name])
                runs[model.name] = finished(model.run(params, protocol, rig, start=starts.get(model.name),
                                                      **settings[model.name]), protocol)  # fmt: skip
                springs[model.name] = model.spring(params, checked[model.name])
            except (ParameterError, ModelError) as exc:
                said = in_run_words(str(exc), f"--start {model.name}=")
                raise type(exc)(f"model {model.name}: {said}") from None
            except Exception as exc:  # a plug-in's own (ValueError, ...): named as the plug-in's, not stickslip's bug
                refusal = plugin_refusal(model, exc, "its run", starts.get(model.name), f"--start {model.name}=")
                if refusal is exc:
                    raise
                raise refusal from None
            bar.advance(note=model.name)
    summaries = {name: run_summary(run, protocol, rig, springs[name]) for name, run in runs.items()}
    for model in models:  # models that start differently do not settle alike: each row says where it began
        summaries[model.name]["start"] = start_words(
            model, starts.get(model.name), protocol, settings[model.name], runs[model.name]
        )
        summaries[model.name]["settings"] = settings[model.name]
        # each model's own units map, as its `run --json` has: a spring is Pa/m in one model, 1/m in another
        summaries[model.name]["units"] = summary_units(summaries[model.name], springs[model.name])
    document = {
        "protocol": [{"velocity": s.velocity, "duration": s.duration} for s in protocol.segments],
        "rig": shared_rig(rig, list(springs.values())),
        "models": summaries,
        "status": "ok" if all(r.status == "ok" for r in runs.values()) else "failed",
    }
    document["units"] = merged_units(
        json_units({k: v for k, v in document.items() if k != "models"}), [s["units"] for s in summaries.values()]
    )
    if options["as_json"]:
        emit_json(document)
    else:
        from .params_cmd import print_rich

        print_rich(protocol.describe() + f" ({rig.control} control)", comparison_table(summaries))
    if output is not None:
        from ..plots.overlay import overlay_figure

        save_figure(overlay_figure(runs, title=protocol.describe()), output)
    failed = [name for name, run in runs.items() if run.status != "ok"]
    if failed:
        click.echo(f"stickslip: the run of {failed[0]} failed: {runs[failed[0]].message}", err=True)
        raise SystemExit(FAILED)


def start_words(model: Any, start: Any, protocol: Any, settings: Any, run: Any) -> str:
    """The start the run really made, in words: a model whose ``describe_start`` takes the ``run`` reads it there
    (the transient model's steady start below Vc begins just above Vc under σc, not at V0: it was said to begin
    "at 100 µm/s"); any other model says what it was asked to start from."""
    import inspect

    try:
        takes_run = "run" in inspect.signature(model.describe_start).parameters
    except (TypeError, ValueError):  # a plug-in's callable without a signature
        takes_run = False
    if takes_run:
        return str(model.describe_start(start, protocol, settings, run=run))
    return str(model.describe_start(start, protocol, settings))


def shared_rig(rig: Any, springs: list[tuple[float, str, str] | None]) -> dict[str, Any]:
    """The top-level rig: the spring every model pulls through where they share one (value and unit), else the
    rig as given; its stiffness null with ``stiffness_from`` "each model" where the models pull through springs
    of their own (each in its ``rig``, in its unit)."""
    if springs and all(s is not None and s[:2] == springs[0][:2] for s in springs):
        return rig_record(rig, springs[0])
    record = rig_record(rig)
    if record["stiffness"] is None and any(s is not None for s in springs):
        record["stiffness_from"] = "each model"
    return record


def _refuse_classic_options(ctx: click.Context) -> None:
    """The classic comparison's own options mean nothing beside --models: say so rather than ignore them."""
    classic = ("v1", "step_time", "hold", "pull", "bond_model", "eta", "rsf_a", "rsf_b", "rsf_dc")
    for name in classic:
        if ctx.get_parameter_source(name) not in (None, click.core.ParameterSource.DEFAULT):
            flag = next(p.opts[0] for p in ctx.command.params if p.name == name)
            raise ParameterError(f"{flag}: not with --models (give model keys with --set KEY=VALUE)")


def comparison_table(summaries: dict[str, dict[str, Any]]) -> Any:
    """A rich table: one row per model, regime and the settled numbers in the run's own unit."""
    from rich.table import Table

    table = Table(title="Same protocol and rig, each model", title_justify="left")
    for heading in ("model", "start", "regime", "period (s)", "peak", "trough", "mean", "unit"):
        table.add_column(heading, justify="left" if heading in ("model", "start", "regime") else "right")
    for name, s in summaries.items():
        signal, unit = ("stress", "Pa") if "peak_stress" in s else ("friction", "μ")
        table.add_row(name, s.get("start", ""), s["regime"] + ("" if s["status"] == "ok" else " (FAILED)"),
                      _number(s["period"]), *(_number(s[f"{w}_{signal}"]) for w in ("peak", "trough", "mean")),
                      unit)  # fmt: skip
    return table


def _number(value: float | None) -> str:
    return "—" if value is None or not math.isfinite(value) else f"{value:.6g}"


__all__ = ["compare_models", "comparison_table", "model_list", "routed_overrides"]
