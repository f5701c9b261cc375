"""``stickslip params``: list, show and export parameter sets.

``params show [NAME|FILE]`` prints every key with its symbol, value (in a
readable unit) and meaning, then the derived quantities the paper uses
(lambda/kT, lambda*M/kT, G_d/h, the Eq 17 geometric factor and K).
``params export [NAME|FILE] [-o FILE]`` writes an editable TOML file (JSON for
``-o FILE.json``) whose reload gives exactly the same set.  Both take ``--params``
and ``--set``.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import click

from ..display import symbol
from ..errors import ParameterError
from ..parameters import (
    BOLTZMANN,
    SECTIONS,
    STIFFNESS_KEYS,
    Parameters,
    available_parameter_sets,
    load_parameters,
)
from ..units import DIMENSIONS, shorten
from .common import (
    FILE_PATH,
    check_output,
    params_options,
    plain_text,
    refuse_overwriting_inputs,
    resolve_params,
    stdout_is_terminal,
    write_text,
)

#: Width of tables written to files or pipes (a terminal uses its own width).
PLAIN_WIDTH = 140

_PREFIXES = ((1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"), (1e-12, "p"))
#: Dimensions shown with an SI prefix on their leading unit, and that unit split as (leading, rest).
_PREFIXED = {
    "time": ("s", ""),
    "length": ("m", ""),
    "velocity": ("m", "/s"),
    "stress": ("Pa", ""),
    "stress_rate": ("Pa", "/s"),
    "stress_per_length": ("Pa", "/m"),
    "stiffness": ("N", "/m"),
    "force": ("N", ""),
}


def human(value: float, dimension: str, digits: int = 6) -> str:
    """``value`` (SI) in a readable unit: ``human(2.24e-4, "time") == "224 µs"``."""
    if not math.isfinite(value):
        return f"{value} {DIMENSIONS[dimension][1]}".strip()
    if dimension == "temperature":
        return f"{value:.{digits}g} K ({value - 273.15:.{digits}g} °C)"
    if dimension == "length" and 1e-11 <= abs(value) < 1e-9:  # molecular lengths read best in angstrom
        return f"{value * 1e10:.{digits}g} Å"
    if dimension in _PREFIXED and value != 0:
        lead, rest = _PREFIXED[dimension]
        factor, prefix = next(((f, p) for f, p in _PREFIXES if abs(value) >= f * (1 - 1e-12)), _PREFIXES[-1])
        return f"{value / factor:.{digits}g} {prefix}{lead}{rest}"
    unit = DIMENSIONS[dimension][1].replace("^2", "²")
    return f"{value:.{digits}g} {unit}".strip()


def _chosen_set(ctx: click.Context, name: str | None, params_name: str) -> str:
    """NAME argument or --params, not both."""
    if name is None:
        return params_name
    source = ctx.get_parameter_source("params_name")
    if source is not None and source.name == "COMMANDLINE" and params_name != name:
        raise click.UsageError(f"give the parameter set once: either NAME ({name!r}) or --params ({params_name!r})")
    return name


def _with_override_note(params: Parameters, overrides: Sequence[str]) -> Parameters:
    if not overrides:
        return params
    note = "with --set " + ", ".join(overrides)
    description = f"{params.description} ({note})" if params.description else note
    return dataclasses.replace(params, description=description)


def print_rich(*renderables: Any, output: Path | None = None) -> None:
    """Print rich renderables: in colour on a terminal, as plain text to a pipe or ``output`` file."""
    from rich.console import Console

    if output is None and stdout_is_terminal():
        console = Console(highlight=False)
        for item in renderables:
            console.print(item)
        return
    text = plain_text(renderables, PLAIN_WIDTH) + "\n"
    if output is None:
        click.echo(text, nl=False)
    else:
        write_text(output, text)


def parameter_table(params: Parameters, changed: Sequence[str] = ()) -> Any:
    """A rich table: key, symbol, value with unit, meaning (keys in ``changed`` are flagged)."""
    from rich.table import Table

    title = f"Parameter set {params.name}" + (f"\n{params.description}" if params.description else "")
    table = Table(title=title, title_justify="left")
    for column in ("key", "symbol", "value", "meaning"):
        table.add_column(column, overflow="fold")
    for s, cls in SECTIONS.items():
        for f in dataclasses.fields(cls):
            key = f"{s}.{f.name}"
            if getattr(getattr(params, s), f.name) is None:  # an extension's key left out: the paper's model
                continue
            value = human(getattr(getattr(params, s), f.name), f.metadata["dimension"])
            flag = " (set)" if key in changed else ""
            if key == "block.height":  # a stiffness key sets the height (stickslip.parameters.STIFFNESS_KEYS)
                flag = next((f" (set by {k})" for k in STIFFNESS_KEYS if k in changed), flag)
            table.add_row(key + flag, symbol(f.metadata["symbol"]), value, f.metadata["doc"])
    return table


def derived_rows(params: Parameters) -> list[tuple[str, str, str, str]]:
    """(quantity, symbol, value, meaning) of the derived quantities used by the model."""
    b, k = params.bonds, params.block
    kt = BOLTZMANN * b.temperature
    return [
        ("thermal energy", "kT", f"{kt:.6g} J", "Boltzmann constant times T"),
        ("force sensitivity", "λ/kT", f"{b.force_sensitivity:.6g} 1/N", "Eyring exponent per unit chain force (Eq 15)"),
        (
            "stretch sensitivity",
            "λM/kT",
            f"{b.stretch_sensitivity:.6g} 1/m = {b.stretch_sensitivity * 1e-6:.6g} 1/µm",
            "Eyring exponent per unit chain extension (Eq 6); the paper's '2.47e12 m^-2'",
        ),
        ("block stiffness", "Gd/h", human(k.stiffness, "stress_per_length"), "shear modulus over height (Eq 5)"),
        ("geometric factor", "ln(B/l)/(B/l-1)", f"{k.geometric_factor:.6g}", "trapezoid correction (Eq 17)"),
        (
            "effective stiffness",
            "K",
            human(k.effective_stiffness, "stress_per_length"),
            "Gd/h times the factor (Eq 17)",
        ),
    ]


def derived_table(params: Parameters) -> Any:
    from rich.table import Table

    table = Table(title="Derived quantities", title_justify="left")
    for column in ("quantity", "symbol", "value", "meaning"):
        table.add_column(column, overflow="fold")
    for row in derived_rows(params):
        table.add_row(*row)
    return table


#: (unit, meaning) of each rate-and-state key as :meth:`stickslip.rsf.RSFParams.to_dict` writes it (SI)
_RSF_KEYS = {
    "a": ("", "direct effect"),
    "mu0": ("", "steady friction at v_ref"),
    "v_ref": ("m/s", "reference velocity"),
    "stiffness": ("1/m", "spring stiffness over the normal stress"),
    "eta": ("s/m", "radiation damping over the normal stress"),
    "mass": ("kg/m^2", "slider mass per area"),
    "normal_stress": ("Pa", "normal stress"),
    "regularized": ("", "arcsinh form near V = 0"),
    "cutoff": ("m/s", "cut-off velocities V1, V2"),
}
_STATE_KEYS = {"law": ("", "evolution law"), "b": ("", "evolution effect"), "dc": ("m", "critical slip distance"),
               "c": ("", "Nagata's stress coupling")}  # fmt: skip


def rate_and_state_file(chosen: str, overrides: Sequence[str]) -> Any:
    """The :class:`stickslip.rsf.RSFParams` of ``chosen`` where it is a rate-and-state file (a ``.params.json``
    written by ``rsf fit`` or ``rsf simulate -o``, a JSON of its keys as ``params export -o F.json`` writes, or a
    TOML of them); None for a bond-model set or file (JSON or TOML, its sections ``bonds``, ``aging``, ...).
    ``params show`` and ``export`` read both kinds; ``--set`` names the bond model's keys, so it is refused here."""
    path = Path(chosen)
    if path.suffix.lower() not in (".json", ".toml") or not path.is_file():
        return None
    from ..rsf import RSFParams
    from .params_files import load_params_mapping

    mapping = load_params_mapping(path)  # the one reader of --params files, JSON or TOML
    if not ({"a", "states"} & set(mapping)) or set(mapping) & set(SECTIONS):
        return None  # a bond-model set: load_parameters reads it and names what is wrong
    if overrides:
        raise ParameterError(
            f"--set {shorten(overrides[0])}: {chosen} is a rate-and-state parameter file and --set names the bond"
            " model's keys; edit the file, or run it with `stickslip run --model rsf --params FILE --set KEY=VALUE`"
        )
    return RSFParams.from_dict(mapping, source=str(path))


def rate_and_state_table(chosen: str, params: Any) -> Any:
    """A rich table of a rate-and-state parameter set: key, value with its SI unit, meaning."""
    from rich.table import Table

    table = Table(title=f"Rate-and-state parameters {chosen} (SI)", title_justify="left")
    for column in ("key", "value", "unit", "meaning"):
        table.add_column(column, overflow="fold")
    values = params.to_dict()
    for key, (unit, meaning) in _RSF_KEYS.items():
        if key in values:
            value = values[key]
            shown = f"{value['v1']:.6g}, {value['v2']:.6g}" if key == "cutoff" else _plain(value)
            table.add_row(key, shown, unit, meaning)
    for number, state in enumerate(values["states"], 1):
        for key, (unit, meaning) in _STATE_KEYS.items():
            table.add_row(f"states[{number}].{key}", _plain(state[key]), unit, meaning)
    return table


def _plain(value: Any) -> str:
    return f"{value:.6g}" if isinstance(value, float) else str(value).lower() if isinstance(value, bool) else str(value)


def _changed_keys(overrides: Sequence[str]) -> list[str]:
    return [item.partition("=")[0].strip() for item in overrides]


@click.group("params")
def params_group() -> None:
    """List, show and export parameter sets (values carry units)."""


@params_group.command("list")
def list_command() -> None:
    """The built-in parameter sets."""
    from rich.table import Table

    table = Table(title="Built-in parameter sets", title_justify="left")
    table.add_column("name")
    table.add_column("description", overflow="fold")
    for name in available_parameter_sets():
        table.add_row(name, load_parameters(name).description)
    print_rich(table)


@params_group.command("show")
@click.argument("name", required=False, metavar="[NAME|FILE]")
@params_options
@click.pass_context
def show_command(ctx: click.Context, name: str | None, params_name: str, overrides: tuple[str, ...]) -> None:
    """Print a parameter set with units, and the derived quantities.

    NAME is a built-in set (see `stickslip params list`) or a TOML or JSON file;
    it defaults to --params.  A rate-and-state file (a NAME.params.json of
    `rsf fit` or `rsf simulate -o`, or a TOML of its keys) is shown in SI.
    """
    chosen = _chosen_set(ctx, name, params_name)
    rate_and_state = rate_and_state_file(chosen, overrides)
    if rate_and_state is not None:
        print_rich(rate_and_state_table(chosen, rate_and_state))
        return
    params = resolve_params(chosen, overrides)
    params = _with_override_note(params, overrides)
    print_rich(parameter_table(params, _changed_keys(overrides)), derived_table(params))


@params_group.command("export")
@click.argument("name", required=False, metavar="[NAME|FILE]")
@params_options
@click.option("-o", "--output", type=FILE_PATH, help="Write here instead of stdout.")
@click.pass_context
def export_command(
    ctx: click.Context, name: str | None, params_name: str, overrides: tuple[str, ...], output: Path | None
) -> None:
    """Write a parameter set as an editable file (values with units): TOML, or JSON for -o FILE.json.

    Loading the file back (`--params FILE`) gives exactly the same values.
    With --set the set is named for what it changed ("gelatin-glass, modified:
    bonds.bond_time").  A rate-and-state file (NAME.params.json) is written
    as its TOML (or JSON).
    """
    chosen = _chosen_set(ctx, name, params_name)
    refuse_overwriting_inputs([], [("-o", output)], chosen)
    check_output("-o", output)  # -o '' (click reads it as the folder '.'): one line naming -o
    kind = export_format(output)
    rate_and_state = rate_and_state_file(chosen, overrides)
    if rate_and_state is not None:
        text = rate_and_state.to_toml() if kind == "TOML" else json.dumps(rate_and_state.to_dict(), indent=2) + "\n"
    else:
        params = _with_override_note(resolve_params(chosen, overrides), overrides)
        text = params.to_toml() if kind == "TOML" else params.to_json()
    if output is None:
        click.echo(text, nl=False)
    else:
        write_text(output, text)


#: The file formats ``params export`` writes, by the suffix of -o (standard output and a name without one: TOML).
EXPORT_FORMATS = {".toml": "TOML", ".json": "JSON", "": "TOML"}


def export_format(output: Path | None) -> str:
    """ "TOML" or "JSON", as -o's suffix says; another suffix is refused in one line: the file would be read back
    by its content while its name promises a third format (``-o set.yaml`` held TOML)."""
    if output is None or str(output) == "-":
        return "TOML"
    suffix = output.suffix.lower()
    if suffix not in EXPORT_FORMATS:
        raise ParameterError(
            f"-o {shorten(str(output))}: params export writes TOML (.toml) or JSON (.json), not {suffix}; name the"
            f" file {output.stem}.toml or {output.stem}.json"
        )
    return EXPORT_FORMATS[suffix]


def register(cli: click.Group) -> None:
    """Add ``stickslip params ...`` to the group."""
    cli.add_command(params_group)
