"""Parameter sweeps on dask.distributed: grids or Latin hypercubes, resumable Parquet output, phase diagrams.

``stickslip.sweep(...)`` (this package's :func:`sweep`) runs one and returns
a pandas DataFrame; ``stickslip sweep`` is the command line.  See docs/sweep.md.
"""

from __future__ import annotations

import numbers
import shutil
import sys
import tempfile
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from ..errors import DataError, ParameterError
from ..parameters import Parameters, require_flag
from ..units import to_si
from .engine import check_scheduler_address, compute, compute_while_cheap, dask_client, default_batch_size, read_results
from .export import write_table
from .interrupts import heard_at_safe_points, stop_if_asked
from .main_guard import unguarded_script_line
from .models import ALIASES, MODELS, get_model
from .progress import Silent, reporter
from .schedule import RunReport, check_schedule
from .spec import Axis, SweepSpec, check_design, parse_vary
from .store import SweepStore, checked_manifest, open_store, read_manifest

__all__ = [
    "MODELS",
    "Axis",
    "SweepSpec",
    "build_spec",
    "load_sweep",
    "parse_vary",
    "read_manifest",
    "run_sweep",
    "sweep",
    "write_table",
]

DEFAULT_DURATION = 100.0  # s: several cycles at the paper's stick-slip velocities


def build_spec(
    vary: Sequence[str] | Mapping[str, Any],
    *,
    model: str = "quasi-static",
    params: str | Parameters | None = None,
    overrides: Mapping[str, Any] | None = None,
    pulling_velocity: float | str | None = None,
    duration: float | str = DEFAULT_DURATION,
    samples: int | None = None,
    seed: int = 0,
    jump_curve: str = "aging",
    stick_population: bool = False,
    unit_check: Callable[[str, str, str], None] | None = None,
) -> SweepSpec:
    """The specification of a sweep, validated: every key known, every value of the right unit and in range.

    ``vary`` is a list of ``--vary`` texts (``"KEY=LO..HI:N[:log]"``, ``"KEY=V1,V2"``) or a mapping
    ``{key: "LO..HI:N" or [values]}``; ``samples`` makes it a Latin hypercube over ranges ``LO..HI[:log]``.
    Bare numbers are SI.  ``unit_check(text, dimension, prefix)``, given by the command line, refuses
    them in every value typed there (``--v0``, ``--set``, ``--vary``), as every other command does.
    """
    model = _model_name(model)
    adapter = get_model(model)
    adapter.check_available()
    adapter.key_units()  # a plug-in's key of an unknown dimension is refused here, before any value is read
    dimensions = adapter.dimensions()
    seed = _whole(seed, "seed", minimum=0)
    samples = None if samples is None else _whole(samples, "samples", minimum=1)
    axes = tuple(_axis(item, dimensions, unit_check) for item in _vary_texts(vary))
    design = check_design(axes, samples)
    if not isinstance(overrides, (Mapping, type(None))):
        raise ParameterError(f"overrides: expected a mapping {{'section.key': value}}, got {type(overrides).__name__}")
    given = dict(overrides or {})
    if unit_check is not None:
        _check_typed_units(given, pulling_velocity, dimensions, unit_check)
    if pulling_velocity is not None and "pulling_velocity" in {a.key for a in axes}:
        raise ParameterError("--v0 and --vary pulling_velocity: give the pulling velocity once")
    if pulling_velocity is not None:
        given["pulling_velocity"] = pulling_velocity
    fixed, label = adapter.fixed_values(params, given)
    adapter.check_keys(tuple(a.key for a in axes), fixed)
    stick_population = require_flag(stick_population, "stick_population")
    settings = _settings(adapter, _duration(duration), jump_curve=jump_curve, stick_population=stick_population)
    spec = SweepSpec(
        model=model,
        fixed=fixed,
        axes=axes,
        design=design,
        samples=samples or 0,
        seed=int(seed),
        settings=settings,
        label=label,
    )
    _check_corners(adapter, spec)
    return spec


def run_sweep(
    spec: SweepSpec,
    output: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    overwrite: bool = False,
    progress: Silent | None = None,
    batch_size: int | None = None,
    schedule: str = "cost",
) -> SweepStore:
    """Run (or resume) ``spec`` into the folder ``output``; ``workers=0`` runs in this process, without dask.

    One process writes a folder at a time (a second is refused with
    :class:`~stickslip.errors.DataError`).  Chunks found damaged on resume are
    recomputed and named in the returned store's ``damaged``.  ``schedule``: "cost" (the dearest points first,
    by the model's estimate, in shrinking tasks) or "given" (chunk by chunk in point order); the rows are the same.
    The returned store's ``report`` (also ``OUT/_run.json``) gives the workers, wall time and parallel efficiency.
    """
    if not isinstance(spec, SweepSpec):
        raise ParameterError(f"spec: expected a SweepSpec (see build_spec), got {type(spec).__name__}")
    if workers is not None:
        workers = _whole(workers, "workers", minimum=0)
    if batch_size is not None:
        batch_size = _whole(batch_size, "batch_size", minimum=1)
    if scheduler is not None and not isinstance(scheduler, str):
        raise ParameterError(f"scheduler: expected an address such as 'tcp://HOST:8786', got {scheduler!r}")
    if scheduler is not None:
        check_scheduler_address(scheduler)
    workers = _workers_for_the_caller(workers, scheduler)
    overwrite = require_flag(overwrite, "overwrite")
    schedule = check_schedule(schedule)
    store = open_store(output, spec, batch_size or default_batch_size(spec.size), overwrite=overwrite)
    shown = progress if progress is not None else Silent()
    report = RunReport(schedule)

    def advance(points: int) -> None:  # after each chunk written: where a Ctrl-C noted meanwhile stops the sweep
        shown.advance(points)
        stop_if_asked()

    try:
        finished = store.finished()
        shown.start(spec.size, store.rows_done(finished))
        try:
            with heard_at_safe_points():  # a Ctrl-C is never lost in a gc callback (interrupts.py)
                if len(finished) == store.batches:
                    pass  # all done already: no cluster to start
                elif workers == 0 and scheduler is None:
                    compute(store, None, advance)
                elif workers is None and scheduler is None and compute_while_cheap(store, advance):
                    pass  # a small sweep: done in this process before a cluster would have started
                else:
                    _on_cluster(store, workers, scheduler, shown, report, advance)
        finally:
            shown.close()
        report.in_process_points += store.points_written - report.points
        report.in_process_seconds += store.point_seconds - report.point_seconds
        store.write_report(report)
    finally:
        store.close()
    return store


def _on_cluster(
    store: SweepStore,
    workers: int | None,
    scheduler: str | None,
    shown: Silent,
    report: RunReport,
    advance: Callable[[int], None] | None = None,
) -> None:
    """Run the chunks still missing on a cluster, timing the cluster's part (for the parallel efficiency)."""
    import time

    asked = time.perf_counter()
    points, seconds = store.points_written, store.point_seconds
    with dask_client(workers, scheduler) as client:
        began = time.perf_counter()
        report.cluster_start = began - asked
        report.workers = sum(client.nthreads().values()) or 1
        compute(store, client, advance or shown.advance, schedule=report.schedule)
        report.wall = time.perf_counter() - began
    report.points = store.points_written - points
    report.point_seconds = store.point_seconds - seconds


def _workers_for_the_caller(workers: int | None, scheduler: str | None) -> int | None:
    """0 (this process) for a script that calls a sweep outside ``if __name__ == "__main__":`` (see main_guard)."""
    if scheduler is not None or workers == 0:
        return workers
    unguarded = unguarded_script_line()
    if unguarded is None:
        return workers
    script, line = unguarded
    why = f"{script} line {line} calls it outside `if __name__ == '__main__':`, and worker processes rerun the script"
    if workers is not None:
        raise ParameterError(f"workers={workers}: {why}; put the call under that guard, or use workers=0")
    print(f"stickslip: note: the sweep runs in this process: {why}; put the call under that guard to use them",
          file=sys.stderr)  # fmt: skip
    return 0


def sweep(
    vary: Sequence[str] | Mapping[str, Any],
    output: str | Path | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    overwrite: bool = False,
    quiet: bool = True,
    **specification: Any,
) -> Any:
    """Run a sweep and return its rows as a pandas DataFrame (sorted by point; inputs and results in SI).

    >>> frame = sweep(["pulling_velocity=10 um/s..1 mm/s:5:log"], workers=0)  # doctest: +SKIP
    >>> frame = sweep({"block.height": "5 mm..2 cm:4"}, pulling_velocity="50 um/s", samples=None)  # doctest: +SKIP

    ``specification`` are the keywords of :func:`build_spec` (``model``: a registered name or ``module:attr``;
    ``params``: the model's parameter set, default its own; ``overrides``,
    ``pulling_velocity``, ``duration``, ``samples``, ``seed``, ``jump_curve``, ``stick_population``);
    ``workers``, ``scheduler`` and ``overwrite`` those of :func:`run_sweep`; ``quiet=False`` shows progress on
    standard error.

    With ``output`` the rows are also kept there as Parquet chunks, and a
    second call with the same arguments resumes (or just reads) them.  The
    returned frame holds every row in memory: for sweeps too large for that,
    give ``output`` and read the folder with pyarrow datasets instead.
    """
    if output is not None and not str(output).strip():  # Path("") would be the current folder
        raise ParameterError("output: the folder name is empty; give a folder, or None for no folder")
    quiet = require_flag(quiet, "quiet")
    spec = build_spec(vary, **specification)
    folder = Path(output) if output is not None else Path(tempfile.mkdtemp(prefix="stickslip-sweep-"))
    try:
        store = run_sweep(
            spec, folder, workers=workers, scheduler=scheduler, overwrite=overwrite, progress=reporter(quiet)
        )
        if store.damaged:
            warnings.warn(damage_note(store), UserWarning, stacklevel=2)
        return read_results(folder)
    finally:
        if output is None:
            shutil.rmtree(folder, ignore_errors=True)


def load_sweep(folder: str | Path) -> tuple[Any, SweepSpec]:
    """(the rows written so far as a DataFrame, the specification) of a sweep output folder."""
    folder = Path(folder)
    if not folder.is_dir():
        raise DataError(f"{folder}: not a sweep output folder (not a folder)")
    manifest = checked_manifest(folder)
    return read_results(folder), SweepSpec.from_dict(manifest["specification"])


def damage_note(store: SweepStore) -> str:
    """One line naming the chunks found damaged on resume (removed and recomputed)."""
    shown = ", ".join(store.damaged[:3]) + (f" and {len(store.damaged) - 3} more" if len(store.damaged) > 3 else "")
    return f"sweep: {len(store.damaged)} damaged chunk(s) in {store.folder} recomputed: {shown}"


def _model_name(model: Any) -> str:
    """A model's name: given as is, or a model object (registered under its name, so workers find it by it)."""
    from ..models import get_model as find_model
    from ..models import register_model

    if isinstance(model, str):
        return model
    if not all(hasattr(model, attr) for attr in ("name", "dimensions", "parameters", "run")):
        raise ParameterError(f"model: expected a name, one of {', '.join(MODELS)}; got {model!r}")
    try:
        known = find_model(model.name)
    except ParameterError:
        known = None
    if known is not model:
        register_model(model)
    return model.name


def _whole(value: Any, name: str, minimum: int) -> int:
    """A whole number >= minimum (an integral float such as 3.0 too); anything else is one ParameterError."""
    whole = isinstance(value, numbers.Integral) or (isinstance(value, numbers.Real) and float(value).is_integer())
    if isinstance(value, bool) or not whole:
        raise ParameterError(f"{name}: expected a whole number, got {value!r}")
    number = int(value)
    if number < minimum:
        raise ParameterError(f"{name}: expected a whole number >= {minimum}, got {number}")
    return number


def _vary_texts(vary: Sequence[str] | Mapping[str, Any]) -> list[str]:
    if isinstance(vary, str):
        return [vary]
    if isinstance(vary, Mapping):
        return [_vary_text(key, body) for key, body in vary.items()]
    if not isinstance(vary, Sequence) or not all(isinstance(v, str) for v in vary):
        raise ParameterError(
            "vary: expected 'KEY=LO..HI:N' texts or a mapping {key: 'LO..HI:N' or [values]},"
            f" got {type(vary).__name__}"
        )
    return list(vary)


def _vary_text(key: Any, body: Any) -> str:
    if isinstance(body, str):
        return f"{key}={body}"
    if isinstance(body, (Sequence, tuple)) and body and all(isinstance(v, (str, numbers.Real)) for v in body):
        return f"{key}=" + ",".join(v if isinstance(v, str) else repr(float(v)) for v in body)
    raise ParameterError(
        f"vary[{key!r}]: expected a range text 'LO..HI:N[:log]' or a non-empty list of values, got {body!r}"
        + (f" (one value: [{body!r}])" if isinstance(body, numbers.Real) else "")
    )


def _axis(text: str, dimensions: Mapping[str, str], unit_check: Callable[[str, str, str], None] | None) -> Axis:
    key, sep, body = text.partition("=")
    if sep and key.strip() in ALIASES:
        text = f"{ALIASES[key.strip()]}={body}"
    return parse_vary(text, dimensions, unit_check=unit_check)


def _check_typed_units(
    given: Mapping[str, Any],
    pulling_velocity: Any,
    dimensions: Mapping[str, str],
    unit_check: Callable[[str, str, str], None],
) -> None:
    """Values typed on the command line carry their units (``--v0 50`` is refused, as in every command)."""
    if isinstance(pulling_velocity, str):
        unit_check(pulling_velocity, "velocity", "--v0 ")
    for key, value in given.items():
        dimension = dimensions.get(ALIASES.get(key, key))
        if isinstance(value, str) and dimension is not None:
            unit_check(value, dimension, f"--set {key}=")


def _duration(value: float | str) -> float:
    seconds = to_si(value, "time", "--duration")
    if not seconds > 0 or seconds == float("inf"):
        raise ParameterError(f"--duration: expected a positive finite time, got {value!r}")
    return seconds


#: Run settings a sweep passes on to the models that take them, with the value that means "not asked for".
OPTIONAL_SETTINGS = {"jump_curve": "aging", "stick_population": False}


def _settings(adapter: Any, duration: float, **asked: Any) -> dict[str, Any]:
    """The duration and each optional setting the model takes; one asked of a model that does not is refused."""
    settings: dict[str, Any] = {"duration": duration}
    for name, value in asked.items():
        if adapter.takes(name):
            settings[name] = bool(value) if isinstance(OPTIONAL_SETTINGS[name], bool) else value
        elif value != OPTIONAL_SETTINGS[name]:
            takers = [f"--model {n}" for n, m in MODELS.items() if m.takes(name)]
            option = "--" + name.replace("_", "-")
            who = " or ".join(takers) or "no model"
            raise ParameterError(f"{option}: only {who} takes it, not --model {adapter.name}")
    return settings


def _check_corners(adapter: Any, spec: SweepSpec) -> None:
    """Build the model's inputs at each axis's ends, so a value out of range is refused before any work."""
    if not hasattr(adapter, "parameters"):
        return
    ends = {a.key: (min(a.values), max(a.values)) if a.values else (a.low, a.high) for a in spec.axes}
    first = {**spec.fixed, **{key: pair[0] for key, pair in ends.items()}}
    if "pulling_velocity" not in first:
        raise ParameterError("pulling_velocity: give --v0 V, or vary it with --vary 'pulling_velocity=LO..HI:N'")
    for key, pair in ends.items():
        for end in pair:
            try:
                adapter.parameters({**first, key: end})
            except ParameterError as exc:
                raise ParameterError(f"--vary {key}: the value {_shown(end, key, adapter)} is refused: {exc}") from None


def _shown(value: float, key: str, adapter: Any) -> str:
    """An SI value with its SI unit (from the model's dimensions), as refusals name it."""
    from ..units import DIMENSIONS

    dimension = adapter.dimensions().get(key, "") if hasattr(adapter, "dimensions") else ""
    unit = DIMENSIONS.get(dimension, ("", ""))[1]
    return f"{value:g} {unit}".strip()
