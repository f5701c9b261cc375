"""``stickslip sweep``: parameter sweeps on dask into a resumable Parquet folder, and their phase diagrams."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import click

from ..errors import DataError, ParameterError, StickslipError
from .common import FILE_PATH, check_output, echo_err, require_unit, set_values

MODEL_NAMES = ("quasi-static", "transient", "rsf")  # the built-ins; any registered model or module:attr is taken


@click.group(
    "sweep",
    invoke_without_command=True,
    subcommand_metavar="[plot OUT ...]",
    context_settings={"help_option_names": ["-h", "--help"]},
)
@click.option(
    "--vary",
    "vary",
    multiple=True,
    metavar="KEY=SPEC",
    help="A varied key: 'KEY=LO..HI:N[:log]' or 'KEY=V1,V2,...' (values with units); several make a grid."
    " Keys: the parameter keys (stickslip params show), pulling_velocity, block.stiffness, block.effective_stiffness"
    " (for --model rsf: a, b, dc, k, eta, ...).",
)
@click.option(
    "--samples", type=int, default=None, help="Latin-hypercube sample of N points over ranges 'KEY=LO..HI[:log]'."
)
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the Latin-hypercube sample.")
@click.option(
    "--model",
    default="quasi-static",
    show_default=True,
    metavar="NAME|MODULE:ATTR",
    help=f"A registered model ({', '.join(MODEL_NAMES)}, or one an installed package registers) or an import path.",
)
@click.option(
    "--v0", "v0_text", default=None, metavar="V", help="Pulling velocity when it is not varied, e.g. '50 um/s'."
)
@click.option(
    "--duration", "duration_text", default="100 s", show_default=True, metavar="T", help="Length of each run."
)
@click.option(
    "--jump-curve", type=click.Choice(["aging", "no-aging"]), default="aging", show_default=True, help="As in simulate."
)
@click.option(
    "--stick-population",
    is_flag=True,
    help="--model transient: add the paper's stick chains (Eqs 13-16); without them Eq 1 never lets a stuck block go.",
)
@click.option(
    "-o",
    "--output",
    default=None,
    metavar="OUT",
    help="Output folder OUT, named without a file suffix (-o sw.csv is refused: no CSV is written).",
)
@click.option(
    "--workers",
    type=int,
    default=None,
    help="Local worker processes [default: one per core, or none when the sweep would take under 5 s in this"
    " process]; 0: no dask.",
)
@click.option("--scheduler", default=None, metavar="ADDRESS", help="Use a running cluster, e.g. tcp://HOST:8786.")
@click.option("--batch-size", type=int, default=None, help="Points per task [default: up to 256, at least 64 tasks].")
@click.option("--quiet", is_flag=True, help="No progress and no summary.")
@click.option("--overwrite", is_flag=True, help="Replace a sweep of another specification in OUT.")
@click.option(
    "--set",
    "overrides",
    multiple=True,
    metavar="KEY=VALUE",
    help="Fix one of the model's keys, with its unit, e.g. bonds.bond_time='224 us'; repeatable.",
)
@click.option(
    "--params",
    "params_name",
    default=None,
    metavar="NAME|FILE",
    help="The model's parameter set [default: its own; gelatin-glass for the bond models].",
)
@click.pass_context
def sweep_command(ctx: click.Context, **options: Any) -> None:
    """Run the model over a grid or a Latin hypercube of parameters, on dask, into the Parquet folder OUT.

    Re-running the same command continues where it stopped (also after kill -9);
    a different specification into the same OUT is refused unless --overwrite.
    `pandas.read_parquet(OUT)` reads the rows: one per point, the varied keys and
    the results in SI units (its `.attrs["units"]` names each column's), status
    'ok', 'failed' (the model could not finish the run) or 'error'
    (no result) with the message.  Exit status 3 when no point is 'ok' and
    some 'failed'; 2 when every point is an 'error'.  Then draw
    the phase diagram with `stickslip sweep plot OUT --x KEY --y KEY --color regime`.
    """
    if ctx.invoked_subcommand is not None:
        return
    _run(**options)


def _run(
    vary: tuple[str, ...],
    samples: int | None,
    seed: int,
    model: str,
    v0_text: str | None,
    duration_text: str,
    jump_curve: str,
    stick_population: bool,
    output: str | None,
    workers: int | None,
    scheduler: str | None,
    batch_size: int | None,
    quiet: bool,
    overwrite: bool,
    params_name: str | None,
    overrides: tuple[str, ...],
) -> None:
    from ..sweeps import build_spec, damage_note, run_sweep
    from ..sweeps.progress import reporter

    if output is None:
        raise ParameterError("-o OUT: give the output folder of the sweep")
    if not output.strip() or output.strip() == "-":
        raise ParameterError(f"-o {output!r}: a sweep writes a folder; give its name, e.g. -o sweep-out")
    _refuse_file_name(output)
    if not vary:
        raise ParameterError(
            "--vary: give at least one varied key, e.g. --vary 'pulling_velocity=5 um/s..5 mm/s:20:log'"
        )
    if workers is not None and workers < 0:
        raise ParameterError(f"--workers: expected 0 (no dask) or more worker processes, got {workers}")
    if workers is not None and scheduler is not None:
        raise ParameterError("--workers and --scheduler: give one (a running cluster has its own workers)")
    if batch_size is not None and batch_size < 1:
        raise ParameterError(f"--batch-size: expected a positive number of points, got {batch_size}")
    require_unit(duration_text, "time", "--duration ")  # the API reads a bare number as seconds; a user types one
    spec = build_spec(
        list(vary),
        model=model,
        params=params_name,
        overrides=set_values(overrides),
        pulling_velocity=v0_text,
        duration=duration_text,
        samples=samples,
        seed=seed,
        jump_curve=jump_curve,
        stick_population=stick_population,
        unit_check=require_unit,
    )
    if not overwrite:
        spec = _as_labelled_before(spec, output)
    try:
        store = run_sweep(
            spec,
            output,
            workers=workers,
            scheduler=scheduler,
            overwrite=overwrite,
            progress=reporter(quiet),
            batch_size=batch_size,
        )
    except KeyboardInterrupt:  # Ctrl-C, or SIGTERM (cli.main.Terminated): what is kept, and how to go on
        note = interrupted_note(output)
        if note:
            echo_err(note)
        raise
    if store.damaged:  # said even with --quiet: the folder was not as the last run left it
        echo_err(damage_note(store))
    summary, no_run_finished = _summary(store.folder, spec.size)
    if store.report is not None:  # workers and parallel efficiency (issue 31), also in OUT/_run.json
        summary += f"; {store.report.words()}"
    if not quiet:
        echo_err(summary)
    if no_run_finished:  # no point ran to its end and some ran and failed: the sweep failed, as such a run does
        echo_err(f"stickslip: the sweep failed: {no_run_finished}")
        raise SystemExit(SWEEP_FAILED)


def interrupted_note(output: str) -> str:
    """The line an interrupted sweep adds to "stickslip: aborted" (or "terminated"): the points its folder keeps and
    that the same command resumes; "" where it keeps none (rerunning starts afresh) or holds no sweep."""
    from ..sweeps.store import saved_points

    found = saved_points(output)
    if found is None or found[0] == 0:
        return ""
    saved, total = found
    if saved == total:  # stopped after its last chunk: nothing is left to compute
        return f"sweep: stopped with all {total} points saved in {output}; run the same command again for its summary"
    return (
        f"sweep: stopped with {saved} of {total} points saved in {output}; run the same command again to resume"
        f" (the other {total - saved} points)"
    )


#: Suffixes of the files a sweep's -o may be taken for: a sweep writes a folder of Parquet chunks, never one file.
FILE_SUFFIXES = frozenset(
    ".csv .tsv .txt .dat .json .jsonl .parquet .pq .feather .arrow .xlsx .xls .h5 .hdf5 .nc .npz .npy .pkl"
    " .pickle .zip .gz .png .svg .pdf".split()
)


def _refuse_file_name(output: str) -> None:
    """Refuse, in one line, a new sweep folder named as a file (``-o sw.csv`` made a folder ``sw.csv/`` of Parquet
    chunks, no CSV, and no word said); a sweep folder of that name made earlier is resumed as ever."""
    from ..sweeps.store import MANIFEST

    path = Path(output)
    suffix = path.suffix.lower()
    if suffix not in FILE_SUFFIXES or (path / MANIFEST).is_file():
        return
    from ..sweeps.export import TABLE_SUFFIXES

    folder = str(path.with_suffix(""))
    if suffix in TABLE_SUFFIXES:  # the package's writer: 'name [unit]' headers, no index (pandas' to_csv: neither)
        kind = {".json": "JSON document with a units map", ".parquet": "Parquet file naming its units"}.get(
            suffix, f"{suffix[1:].upper()} file with 'name [unit]' headers"
        )
        then = (
            f"python -c \"import stickslip.sweeps as s; s.write_table('{folder}', '{output}')\" writes its rows as one"
            f" {kind}"
        )
    else:
        then = f"stickslip.sweeps.load_sweep('{folder}')[0] is its rows as a DataFrame, units in .attrs['units']"
    raise ParameterError(
        f"-o {output}: a sweep writes a folder of Parquet chunks (resumable), not a {suffix} file; name the folder"
        f" without a suffix, e.g. -o {folder}; then {then}"
    )


def _as_labelled_before(spec: Any, output: str) -> Any:
    """``spec`` under the label of the sweep in ``output`` where that sweep differs only in it, its label the bare
    name of the set whose --set values this label lists (a folder made before a set's name said what --set changed,
    "gelatin-glass" now "gelatin-glass, modified: bonds.bond_time"): the same sweep, resumed, not refused."""
    import dataclasses
    import json

    from ..parameters import MODIFIED
    from ..sweeps.store import MANIFEST

    try:
        earlier = json.loads((Path(output) / MANIFEST).read_text(encoding="utf-8"))["specification"]
    except (OSError, ValueError, KeyError, TypeError):  # no sweep there yet, or one the store judges itself
        return spec
    now = json.loads(spec.to_json())
    label = earlier.get("label") if isinstance(earlier, dict) else None
    renamed = label != now["label"] and label == now["label"].partition(MODIFIED)[0]
    if renamed and {**earlier, "label": now["label"]} == now:
        return dataclasses.replace(spec, label=label)
    return spec


#: Exit status of a sweep none of whose points ran to its end, some of them run and failed (that of a failed run)
SWEEP_FAILED = 3


def _summary(folder: Path, total: int) -> tuple[str, str]:
    """(the summary line, "" or why the sweep failed), counted chunk by chunk (never the whole table in memory).

    The regimes count every row that has one, a failed run's too (named: "undetermined 13 (12 failed)"),
    and the rows without a result ("error"), so the counts add up to the points.  A sweep whose every point is an
    error (nothing was computed: most likely the settings every point shares) is refused (exit 2); one with no
    point "ok" and some "failed" (the model ran and could not finish) failed, as such a run does (exit 3)."""
    from collections import Counter

    import pyarrow.dataset as ds

    regimes: Counter[str] = Counter()
    failed_in: Counter[str] = Counter()
    statuses: Counter[str] = Counter()
    first: dict[str, str] = {}
    for batch in ds.dataset(folder, format="parquet").to_batches(columns=["status", "regime", "message"]):
        frame = batch.to_pydict()
        for status, regime, message in zip(frame["status"], frame["regime"], frame["message"], strict=True):
            kind = status if status in ("ok", "error") else "failed"  # (a plug-in's "stopped" run did not finish)
            statuses[kind] += 1
            first.setdefault(kind, message or "")
            if kind != "error" and regime:
                regimes[regime] += 1
                failed_in[regime] += kind == "failed"
    rows = sum(statuses.values())
    if rows != total:  # never report success on a folder that does not hold exactly the sweep
        raise DataError(f"{folder}: holds {rows} rows for {total} points; run the same command again to repair it")
    failed, errors = statuses["failed"], statuses["error"]
    if total and errors == total:  # nothing was computed: the settings every point shares, most likely
        raise ParameterError(
            f"every point of the sweep failed ({total} of {total}; each an error, no result; {folder} holds each"
            f" reason), the first: {first['error']}"
        )
    shown = [
        f"{name} {count}" + (f" ({failed_in[name]} failed)" if failed_in[name] else "")
        for name, count in regimes.most_common()
    ]
    if errors:
        shown.append(f"none (error) {errors}")
    said = f"{failed} failed" + (f", {errors} error{'s' if errors != 1 else ''}" if errors else "")
    line = f"sweep: {total} points in {folder} ({said}){'; regimes: ' + ', '.join(shown) if shown else ''}"
    why = ""
    if total and not statuses["ok"]:
        kinds = f"{failed} failed" + (f" and {errors} error(s)" if errors else "")
        why = (
            f"no point of the {total} ran to its end ({kinds}; {folder} holds each row), the first failed:"
            f" {first['failed']}"
        )
    return line, why


@sweep_command.command("plot")
@click.argument("folder", type=click.Path(exists=True, file_okay=False, path_type=Path), metavar="OUT")
@click.option("--x", "x", default="pulling_velocity", show_default=True, help="Key on the horizontal axis.")
@click.option(
    "--y",
    "y",
    default=None,
    help="Key on the vertical axis; none for a sweep of one key: its results against --x "
    "(--color: the columns, comma-separated; regime: period, peak and mean).",
)
@click.option(
    "--color", "color", default="regime", show_default=True, help="Column shown in colour (regime: discrete)."
)
@click.option(
    "--at",
    "at",
    multiple=True,
    metavar="KEY=VALUE",
    help="Only the points at this value of a varied key (with a unit, or SI); repeatable. Without it, a sweep of"
    " more keys than --x and --y draws a panel per value of the others (up to 6).",
)
@click.option(
    "-o",
    "--output",
    type=FILE_PATH,
    default=None,
    help="Image [default: OUT-COLOR.png].",
)
def plot_command(folder: Path, x: str, y: str | None, color: str, at: tuple[str, ...], output: Path | None) -> None:
    """Draw the phase diagram of the sweep in OUT, with the model's analytic stability boundary."""
    from ..fileio import atomic_path
    from ..plots.export import file_tick_labels
    from ..plots.sweeps import keys_not_plotted, plot_phase_diagram, select_rows
    from ..sweeps import load_sweep

    picked: dict[str, str] = {}
    for item in at:
        key, sep, value = item.partition("=")
        if not sep or not key.strip() or not value.strip():
            raise ParameterError(f"--at {item}: expected KEY=VALUE, e.g. --at 'pulling_velocity=1 mm/s'")
        picked[key.strip()] = value.strip()

    target = output if output is not None else folder.parent / f"{folder.name}-{color}.png"
    _refuse_inside(folder, target)
    if str(target) != "-":
        check_output("-o", target, plot=True)  # before the work, in one line (it was an errno and a temporary name)
    frame, spec = load_sweep(folder)
    ax = plot_phase_diagram(frame, spec, x=x, y=y, color=color, at=picked)
    # the keys not on the axes, said here too: whoever reads only this line must know the panels' split
    note = keys_not_plotted(select_rows(frame, spec, picked), spec, x, y) if y is not None else ""
    try:
        with atomic_path(target) as temp, file_tick_labels(ax.figure):  # log labels that never crowd
            ax.figure.savefig(temp, format=target.suffix.lstrip(".") or "png", dpi=120, bbox_inches="tight")
    except StickslipError:
        raise
    except (OSError, ValueError) as exc:
        raise click.FileError(str(target), hint=str(exc)) from None
    if str(target) != "-":  # the image itself went to standard output
        click.echo(f"phase diagram: {target}{f' ({note})' if note else ''}")


def _refuse_inside(folder: Path, target: Path) -> None:
    """An image inside the sweep folder would be a foreign file there, and poison every later resume."""
    if str(target) == "-":
        return
    real_folder = Path(os.path.realpath(folder))
    real_target = Path(os.path.realpath(target))
    if real_folder == real_target or real_folder in real_target.parents:
        raise ParameterError(f"-o {target}: inside the sweep folder {folder}; write the image beside it instead")


def register(cli: click.Group) -> None:
    """Add ``stickslip sweep`` (and ``stickslip sweep plot``) to the group."""
    cli.add_command(sweep_command)
