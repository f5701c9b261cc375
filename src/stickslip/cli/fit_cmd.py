"""``stickslip fit steady`` and ``stickslip fit stick``: the model's parameters from measurements (Section 3).

Without ``--json`` the Markdown report is printed; ``-o`` writes the fitted
parameter set as TOML (usable by every other command with ``--params``).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import click

from ..errors import ParameterError
from ..parameters import Parameters, key_dimension
from ..units import shorten
from .common import (
    FILE_PATH,
    InputFile,
    emit_json,
    key_value,
    params_options,
    positive,
    refuse_overwriting_inputs,
    require_unit,
    resolve_params,
    save_figure,
    stacked,
    write_text,
)

SPLIT_DEFAULT = "800 um/s"


def _fix_values(items: tuple[str, ...]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for item in items:
        key, value = key_value(item, "--fix", example="--fix 'bonds.max_extension=1 um'")
        if not value:
            raise ParameterError(f"--fix {shorten(item)}: expected a value after '=', e.g. --fix '{key}=1 um'")
        require_unit(value, key_dimension(key), f"--fix {key}=")  # unknown keys: ParameterError
        if key in out:
            raise ParameterError(f"--fix {key}: given twice")
        out[key] = value
    return out


def _write_fitted(output: Path, params: Parameters, name: str, description: str, header: list[str]) -> None:
    """The fitted set as TOML, its header lines as comments, the start set named as its reference."""
    reference = f"start values: {params.reference}" if params.reference else ""
    fitted = dataclasses.replace(params, name=name, description=description, reference=reference)
    write_text(output, "\n".join(f"# {line}" for line in header) + "\n" + fitted.to_toml())


def _fit_outputs(plot_help: str) -> Any:
    """-o, --report, --plot and --json, as both fits take them."""
    options = [
        click.option("-o", "--output", type=FILE_PATH,
                     help="Write the fitted parameters (TOML)."),
        click.option("--report", "report_path", type=FILE_PATH,
                     help="Write the report (Markdown)."),
        click.option("--plot", "plot_path", type=FILE_PATH, help=plot_help),
        click.option("--json", "as_json", is_flag=True, help="Print the results as JSON (SI units)."),
    ]  # fmt: skip

    return lambda func: stacked(options, func)


def _figure_to(path: Path, make: Any) -> None:
    import matplotlib

    matplotlib.use("Agg")
    save_figure(make(), path)


@click.group("fit")
def fit_group() -> None:
    """Fit the model to measurements: steady friction curves and stick times."""


@fit_group.command("steady")
@click.argument("data", type=InputFile())
@click.option(
    "--method",
    type=click.Choice(["auto", "two-step", "joint"]),
    default="auto",
    show_default=True,
    help="two-step: the paper's (no aging above --split, then aging below it); joint: everything at once; auto:"
    " the joint fit started from the two-step result, with profile-likelihood intervals (the two-step where the"
    " joint fit fails, or with --intervals delta/bootstrap).",
)
@click.option(
    "--split", default=SPLIT_DEFAULT, show_default=True, metavar="V", help="Split velocity of the two-step fit."
)
@click.option(
    "--fix", "fix_items", multiple=True, metavar="KEY=VALUE", help="Hold a parameter at a value (repeatable)."
)
@click.option("--free", "free_keys", multiple=True, metavar="KEY", help="Also fit this parameter (repeatable).")
@click.option(
    "--exclude-row", "exclude_rows", multiple=True, type=int, metavar="N", help="Leave out file row N (repeatable)."
)
@click.option(
    "--intervals",
    type=click.Choice(["auto", "delta", "profile", "bootstrap"]),
    default="auto",
    show_default=True,
    help="Intervals of Vc and σc (profile: of the parameters too); auto: delta for two-step, profile likelihood"
    " for joint (docs/fitting.md).",
)
@click.option("--samples", type=click.IntRange(min=20), default=200, show_default=True, help="Bootstrap refits.")
@click.option("--level", type=click.FloatRange(0.5, 0.999), default=0.95, show_default=True, help="Confidence level.")
@click.option("--seed", type=int, default=None, help="Random seed (bootstrap, Bayesian sampler).")
@_fit_outputs("Save the fit and residuals (PNG).")
@click.option("--bayes", is_flag=True, help="Also sample the posterior with emcee (needs stickslip[bayes]).")
@click.option(
    "--walkers",
    type=click.IntRange(min=4),
    default=None,
    help="emcee walkers [default: max(16, 4 x the fitted parameters)].",
)
@click.option(
    "--steps",
    type=click.IntRange(min=10),
    default=None,
    help="emcee steps per walker [default: until the convergence check passes, at most 10000].",
)
@click.option(
    "--corner",
    "corner_path",
    type=FILE_PATH,
    help="Save a corner plot (with --bayes).",
)
@params_options
def steady_command(
    data: Path,
    method: str,
    split: str,
    fix_items: tuple[str, ...],
    free_keys: tuple[str, ...],
    exclude_rows: tuple[int, ...],
    intervals: str,
    samples: int,
    level: float,
    seed: int | None,
    output: Path | None,
    report_path: Path | None,
    plot_path: Path | None,
    as_json: bool,
    bayes: bool,
    walkers: int | None,
    steps: int | None,
    corner_path: Path | None,
    params_name: str,
    overrides: tuple[str, ...],
) -> None:
    """Fit the steady friction curve (Eqs 6-8) to DATA: a CSV of velocity, stress and optional stress_err.

    Units go in the header (velocity [um/s]); bare names are SI.  Start values and
    everything not fitted come from --params/--set (default gelatin-glass).
    """
    written = [("-o", output), ("--report", report_path), ("--plot", plot_path), ("--corner", corner_path)]
    refuse_overwriting_inputs([data], written, params_name)
    from ..fitting.steady_fit import fit_steady

    if corner_path is not None and not bayes:
        raise click.UsageError("--corner needs --bayes")
    posterior_module = _bayes_module() if bayes else None
    params = resolve_params(params_name, overrides)
    # the default split is not a request: auto may then answer a two-step fit short of points with the joint fit
    split_value = None if split == SPLIT_DEFAULT else positive(split, "velocity", "--split")
    fit = fit_steady(
        data,
        params=params,
        method=method,
        split=split_value,
        fix=_fix_values(fix_items),
        free=list(free_keys),
        intervals=None if intervals == "auto" else intervals,
        level=level,
        bootstrap_samples=samples,
        seed=seed,
        exclude_rows=list(exclude_rows),
    )
    posterior = None
    if posterior_module is not None and fit.success:  # a failed fit has no posterior worth sampling
        # a bar on a terminal only (never with --json); a chain that stopped at the cap unconverged is said on
        # stderr too (a length fixed by --steps is the user's choice: the report and the JSON say it)
        posterior = posterior_module.sample_posterior(
            fit,
            walkers=walkers,
            steps=steps,
            seed=seed,
            max_steps=posterior_module.MAX_STEPS,
            progress=False if as_json else None,
        )
        if steps is None and not posterior.converged:
            click.echo(f"stickslip: warning: Bayesian fit: {posterior.messages[0]}", err=True)
    if output is not None and fit.success:
        vc, sc = fit.critical_velocity, fit.critical_stress
        header = [f"Fitted by stickslip fit steady ({fit.method}) to {data}; fitted keys: {', '.join(fit.free_keys)}."]
        if vc.value is not None and sc.value is not None:
            from ..fitting.results import human  # not at module level: it imports lmfit (start-up time)

            header.append(f"Vc = {human(vc.value, 'velocity')}, σc = {human(sc.value, 'stress')} (Eq 9).")
        else:
            header.append(f"Vc, σc (Eq 9): {vc.note or 'not determined'}.")
        header.extend(_covariance_lines(fit))
        description = f"stickslip fit steady --method {fit.method} of {data}, start values from {params.name}"
        _write_fitted(output, fit.parameters, f"fit of {data.name}", description, header)
    report = fit.report() if posterior is None else fit.report() + "\n" + posterior.report()
    if report_path is not None:
        write_text(report_path, report)
    if plot_path is not None:
        from ..plots.fits import steady_fit_figure

        band = posterior.stress_band() if posterior is not None else None
        _figure_to(plot_path, lambda: steady_fit_figure(fit, band=band))
    if corner_path is not None and posterior is not None:
        from ..plots.fits import corner_figure

        _figure_to(corner_path, lambda: corner_figure(posterior))
    if as_json:
        result = fit.as_dict()
        if posterior is not None:
            result["posterior"] = posterior.as_dict()
        emit_json(result)
    else:
        click.echo(report)
    if fit.success and fit.critical_velocity.value is None:  # the curve fits; its minimum is not known (exit 0)
        click.echo(f"stickslip: warning: Vc and σc: {fit.critical_velocity.note}", err=True)
    _exit_if_failed(fit, output)


def _covariance_lines(fit: Any) -> list[str]:
    """The comment line of the fitted keys' ln-covariance that ``fit stick --params`` reads back (round 29:
    its intervals carry the bond parameters' uncertainty); none where the fit has no finite covariance."""
    import numpy as np

    from ..fitting.input_uncertainty import covariance_comment

    keys = list(fit.free_keys)
    covariance = np.asarray(fit.covariance, dtype=float)
    if not keys or covariance.shape != (len(keys), len(keys)) or not np.all(np.isfinite(covariance)):
        return []
    values = [fit.parameters.as_dict()[k] for k in keys]
    return [
        "The covariance of the fitted keys' ln-values (Wald): fit stick --params reads it into its intervals.",
        covariance_comment(keys, values, covariance),
    ]


def _bayes_module() -> Any:
    try:
        import corner  # noqa: F401
        import emcee  # noqa: F401
    except ImportError:
        raise click.ClickException("the Bayesian fit needs emcee and corner: pip install stickslip[bayes]") from None
    from ..fitting import bayes

    return bayes


@fit_group.command("stick")
@click.argument("table", type=InputFile())
@click.option("--fix", "fix_items", multiple=True, metavar="KEY=VALUE", help="Hold a stick parameter at a value.")
@click.option("--free", "free_keys", multiple=True, metavar="KEY", help="Prefer to fit this stick parameter.")
@click.option("--exclude-row", "exclude_rows", multiple=True, type=int, metavar="N", help="Leave out file row N.")
@click.option("--include-steady", is_flag=True, help="Keep rows whose pulling velocity is above Vc.")
@click.option("--level", type=click.FloatRange(0.5, 0.999), default=0.95, show_default=True, help="Confidence level.")
@click.option(
    "--start-stress",
    "start_stress",
    type=click.Choice(["measured", "model"]),
    default="measured",
    show_default=True,
    help="Where each stick starts: measured (the table's start_stress or critical_stress) or model (σc of the bond"
    " parameters in every row: for forces with a drift or an offset; docs/fitting.md).",
)
@_fit_outputs("Save stick times, data and fit (PNG).")
@params_options
def stick_command(
    table: Path,
    fix_items: tuple[str, ...],
    free_keys: tuple[str, ...],
    exclude_rows: tuple[int, ...],
    include_steady: bool,
    level: float,
    start_stress: str,
    output: Path | None,
    report_path: Path | None,
    plot_path: Path | None,
    as_json: bool,
    params_name: str,
    overrides: tuple[str, ...],
) -> None:
    """Fit Nc0, uc/τ and the stick aging time (Eq 15) to measured stick times in TABLE.

    Columns: pulling_velocity, stick_time, optional peak_stress, start_stress (and the
    other columns of the paper's Table 1); or the cycles of 'stickslip analyze -o'
    (of traces at two or more velocities, stacked).  Bond parameters, block and start values
    come from --params/--set: use the file written by 'stickslip fit steady -o', whose
    uncertainty the intervals then include (otherwise they are conditional on the bond parameters).
    """
    refuse_overwriting_inputs([table], [("-o", output), ("--report", report_path), ("--plot", plot_path)], params_name)
    from ..fitting.input_uncertainty import read_fit_covariance
    from ..fitting.stick_fit import fit_stick
    from ..parameters import available_parameter_sets

    params = resolve_params(params_name, overrides)
    written = None if params_name in available_parameter_sets() else read_fit_covariance(params_name)
    fit = fit_stick(
        table,
        params=params,
        fix=_fix_values(fix_items),
        free=list(free_keys),
        exclude_rows=list(exclude_rows),
        include_steady=include_steady,
        level=level,
        start_stress=start_stress,
        bond_covariance=written if written is not None else False,
    )
    if output is not None and fit.success:
        header = [f"Fitted by stickslip fit stick to {table}; fitted keys: {', '.join(fit.free_keys)}."]
        _write_fitted(output, fit.parameters, f"stick fit of {table.name}", f"stickslip fit stick of {table}, from "
                      f"{params.name}", header)  # fmt: skip
    report = fit.report()
    if report_path is not None:
        write_text(report_path, report)
    if plot_path is not None:
        from ..plots.fits import panels, plot_stick_fit

        def make() -> Any:
            fig, (ax,) = panels()
            plot_stick_fit(fit, ax)
            return fig

        _figure_to(plot_path, make)
    if as_json:
        from ..columns import json_units
        from ..fitting.stick_fit import JSON_UNITS

        result = fit.as_dict()
        result["units"] = json_units(result, JSON_UNITS)  # the drift's and the combination's keys too
        emit_json(result)
    else:
        click.echo(report)
    _exit_if_failed(fit, output)


def _exit_if_failed(fit: Any, output: Path | None) -> None:
    """A fit that ran but cannot be trusted: its reason on stderr, -o left unwritten, exit status 3."""
    if fit.success:
        return
    unwritten = f" ({output} not written)" if output is not None else ""
    click.echo(f"stickslip: fit failed: {fit.reason}{unwritten}", err=True)
    raise SystemExit(3)  # as `rsf fit`: 3 is a fit that ran but cannot be trusted (2 is bad input)


def register(cli: click.Group) -> None:
    """Add ``stickslip fit steady|stick`` to the group."""
    cli.add_command(fit_group)
