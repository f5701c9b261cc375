"""``stickslip reproduce``: compute everything once, draw the figures, write the report.

The run is a list of named steps so that a caller can show progress
(:data:`ProgressCallback`); nothing here prints.
"""

from __future__ import annotations

import contextlib
import gc
import json
import multiprocessing
import os
import stat
import sys
import time
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from ..errors import DataError
from ..fileio import atomic_write_text, remove_orphaned_temporaries
from ..parameters import Parameters, load_parameters
from ..units import shorten
from .aging_section import AGING_FIGURES
from .comparisons import TOLERANCE, Comparison, compare, summary_counts
from .computations import ModelRun, computed_values, run_steps
from .errata import Errata, load_errata
from .figures import Curve, save_figure_files
from .html import RenderedFigure, render_report
from .inertia_section import INERTIA_FIGURES
from .paper import resolve_errata
from .report_figures import FIGURE_BUILDERS as PAPER_FIGURES
from .rsf_reading_section import RSF_READING_FIGURES
from .sensitivity_section import SENSITIVITY_FIGURES
from .sweep_section import SWEEP_FIGURES
from .transient_section import TRANSIENT_FIGURES

FIGURE_BUILDERS = [*PAPER_FIGURES, *SWEEP_FIGURES, *TRANSIENT_FIGURES]
FIGURE_BUILDERS += [*AGING_FIGURES, *SENSITIVITY_FIGURES, *RSF_READING_FIGURES, *INERTIA_FIGURES]

#: Called before each step with (description, steps done, total steps), and once more at the end.
ProgressCallback = Callable[[str, int, int], None]

PAPER = "V. A. Juvekar and A. K. Singh, Analysis of Stick-Slip Motion as a Jump Phenomenon"


@dataclass(frozen=True)
class Report:
    """What :func:`build_report` wrote."""

    folder: Path
    html: Path
    results: Path
    figures: tuple[Path, ...]
    curves: tuple[Path, ...]
    comparisons: tuple[Comparison, ...]
    elapsed: float

    @property
    def files(self) -> tuple[Path, ...]:
        return (self.html, self.results, *self.figures, *self.curves)


#: Written first into every report folder, so that a later run recognises the folder as its own.
MARKER = ".stickslip-report"


def prepare_report_folder(where: str | Path) -> Path:
    """The output folder: new, empty, or holding an earlier stickslip report; anything else is refused."""
    if not str(where).strip():
        raise DataError("output folder: empty path; name a folder, e.g. stickslip-report")
    if str(where).strip() == "-":  # elsewhere `-o -` is standard output; a report is a folder of files
        raise DataError(
            "output folder '-': a report is a folder of files, not standard output;"
            " name a folder, e.g. stickslip-report"
        )
    folder = Path(where)
    shown = shorten(str(folder), 240)
    if folder.exists() and not folder.is_dir():
        raise DataError(f"output folder {shown} exists and is not a folder")
    try:
        if folder.is_dir() and any(folder.iterdir()) and not _holds_report(folder):
            raise DataError(
                f"output folder {shown} holds other files and no earlier stickslip report;"
                " refusing to write into it (choose a new or empty folder)"
            )
        folder.mkdir(parents=True, exist_ok=True)
        atomic_write_text(folder / MARKER, "This folder holds a report written by stickslip reproduce.\n")
    except OSError as exc:
        raise DataError(f"output folder {shown} cannot be written: {exc.strerror or exc}") from None
    return folder


def _holds_report(folder: Path) -> bool:
    """Whether ``folder`` holds a report of ours: the marker, or (older reports) our results.json."""
    if (folder / MARKER).is_file():
        return True
    results = folder / "results.json"
    try:
        info = results.stat()
        if not stat.S_ISREG(info.st_mode) or info.st_size > 50_000_000:  # never block on a FIFO
            return False
        data = json.loads(results.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and "stickslip_version" in data and data.get("paper") == PAPER


def build_report(
    folder: str | Path = "stickslip-report",
    progress: ProgressCallback | None = None,
    params: Parameters | None = None,
    workers: int | None = None,
) -> Report:
    """Reproduce the paper's figures and numbers into ``folder``; returns what was written.

    ``folder`` gets ``report.html`` (self-contained), ``results.json``, one
    PNG and one SVG per figure and one CSV per plotted curve.  ``params``
    defaults to the built-in ``gelatin-glass`` set, the paper's.  ``folder``
    must be new, empty or hold an earlier report (a DataError otherwise), and
    every file is written atomically.  ``workers``: processes drawing the
    figures (default: one per available core, at most two; 1 draws them in
    this process); the report is the same whatever the number.
    """
    started = time.perf_counter()
    folder = prepare_report_folder(folder)
    with _frozen_heap() as freeze:
        return _build(folder, started, progress, params, workers, freeze)


def _build(
    folder: Path,
    started: float,
    progress: ProgressCallback | None,
    params: Parameters | None,
    workers: int | None,
    freeze: Callable[[], None],
) -> Report:
    """:func:`build_report` into the prepared ``folder``; ``freeze`` (:func:`_frozen_heap`) before the figures."""
    params = params if params is not None else load_parameters("gelatin-glass")
    notify = progress or (lambda description, done, total: None)

    model_steps = run_steps()
    total = len(model_steps) + len(FIGURE_BUILDERS) + 2
    done = 0

    def step(description: str) -> None:
        nonlocal done
        notify(description, done, total)
        done += 1

    errata = load_errata()
    run = ModelRun(params)
    for description, action in model_steps:
        step(description)
        action(run)

    if _figure_workers(workers) > 1:
        _load_before_fork(run)
    freeze()  # what the model steps and the loads made stays alive to the end: the collector leaves it alone too
    rendered: list[RenderedFigure] = []
    figure_paths: list[Path] = []
    curve_paths: list[Path] = []
    for item, paths, csvs in _rendered_figures(run, folder, step, workers):
        rendered.append(item)
        figure_paths += paths
        curve_paths += csvs

    step("Comparing every number the paper states")
    links = resolve_errata({e.id: e.title for e in errata.entries})
    comparisons = compare(computed_values(run), links)

    step("Writing report.html and results.json")
    names = [p.name for p in (*figure_paths, *curve_paths)]
    built = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    results_path = folder / "results.json"
    html_path = folder / "report.html"
    elapsed = time.perf_counter() - started
    results = _results(run, comparisons, rendered, errata, built, elapsed)
    _write_text(results_path, json.dumps(results, indent=2, ensure_ascii=False) + "\n")
    html = render_report(
        version=_version(),
        params=params,
        built=built,
        elapsed=elapsed,
        figures=rendered,
        comparisons=comparisons,
        errata=errata,
        files=["results.json", *names],
        analyses=run.trace_analyses,
        thresholds=run.thresholds,
        jump_floor=run.jump_floor,
        curve_maximum=run.critical.turnover_stress if run.critical is not None else None,
    )
    _write_text(html_path, html)
    notify("Done", total, total)
    return Report(
        folder=folder,
        html=html_path,
        results=results_path,
        figures=tuple(figure_paths),
        curves=tuple(curve_paths),
        comparisons=tuple(comparisons),
        elapsed=time.perf_counter() - started,
    )


def _results(
    run: ModelRun,
    comparisons: list[Comparison],
    figures: list[RenderedFigure],
    errata: Errata,
    built: str,
    elapsed: float,
) -> dict[str, Any]:
    from ..columns import json_safe

    return json_safe(
        {
            "paper": PAPER,
            "stickslip_version": _version(),
            "built": built,
            "elapsed_seconds": elapsed,
            "parameter_set": run.params.name,
            "parameters": run.params.as_dict(),
            "tolerance": TOLERANCE,
            "summary": summary_counts(comparisons),  # distinct statements of the paper; repeats counted once
            "comparisons": [c.as_dict() for c in comparisons],
            "model": run.summary(),
            "errata": [{"id": e.id, "title": e.title} for e in errata.entries],
            "figures": [
                {
                    "id": f.figure.id,
                    "number": f.figure.number,
                    "title": f.figure.title,
                    "png": f"{f.figure.id}.png",
                    "svg": f"{f.figure.id}.svg",
                    "curves": [_curve_entry(c) for c in f.curves],
                }
                for f in figures
            ],
        }
    )


def _curve_entry(curve: Curve) -> dict[str, Any]:
    return {
        "csv": f"{curve.name}.csv",
        "panel": curve.panel,
        "label": curve.label,
        "x": curve.x_name,
        "y": curve.y_name,
        "points": int(curve.x.size),
    }


def _version() -> str:
    from .. import __version__

    return __version__


def _render(run: ModelRun, index: int, folder: Path) -> tuple[RenderedFigure, list[Path], list[Path]]:
    """Build figure ``index`` of FIGURE_BUILDERS, write its PNG, SVG and curve CSVs; what the HTML needs of it."""
    figure = FIGURE_BUILDERS[index][1](run)
    png, paths = _write(lambda: save_figure_files(figure, folder))
    curves = tuple(figure.curves())
    csvs = [_write_text(folder / f"{curve.name}.csv", curve.to_csv()) for curve in curves]
    # the Figure is dropped here (nothing else holds it) and the collector frees it: clearing it first, artist by
    # artist, cost ~10 ms a figure
    return RenderedFigure(replace(figure, figure=None), png, curves), paths, csvs


#: The model run the forked figure workers read (set only while they run; a fork shares it without pickling).
_SHARED_RUN: ModelRun | None = None


def _render_in_worker(index: int, folder: Path) -> tuple[RenderedFigure, list[Path], list[Path]]:
    assert _SHARED_RUN is not None
    return _render(_SHARED_RUN, index, folder)


#: prctl(2) option: the signal a process gets when its parent dies (linux/prctl.h).
PR_SET_PDEATHSIG = 1


def die_with_parent(parent: int) -> None:
    """Worker initializer: end this process when ``parent`` dies, even by ``kill -9`` (no cleanup runs there).

    A forked worker blocked on its task pipe would otherwise outlive a killed ``stickslip reproduce`` for as long
    as the machine runs.  On Linux the kernel sends SIGKILL at the parent's death (PR_SET_PDEATHSIG); the parent
    may already be gone before the call, so that is checked after it.  Elsewhere (no fork there) nothing is done.
    """
    if not sys.platform.startswith("linux"):
        return
    import ctypes
    import signal

    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
    except (OSError, AttributeError):  # no prctl: the worker still ends when its task pipe closes normally
        return
    if os.getppid() != parent:  # the parent died between the fork and the prctl call
        os._exit(1)


def _figure_workers(workers: int | None) -> int:
    """Processes to draw the figures in: forked ones only where fork exists (they share the model run)."""
    if workers is not None:
        return max(1, int(workers))
    if sys.platform != "linux" or "fork" not in multiprocessing.get_all_start_methods():
        return 1
    return min(2, len(os.sched_getaffinity(0)))


def _rendered_figures(
    run: ModelRun, folder: Path, step: Callable[[str], None], workers: int | None
) -> Iterator[tuple[RenderedFigure, list[Path], list[Path]]]:
    """Every figure of FIGURE_BUILDERS in order; drawn in forked processes when there is more than one core.

    The figures are independent of one another once the model steps ran, and drawing them is most of the
    report's time: two processes halve it on two cores.
    """
    count = _figure_workers(workers)
    if count == 1:
        for index, (description, _) in enumerate(FIGURE_BUILDERS):
            step(description)
            yield _render(run, index, folder)
        return
    yield from _forked_figures(run, folder, step, count)


@contextlib.contextmanager
def _frozen_heap() -> Iterator[Callable[[], None]]:
    """Within the block the collector leaves alone every object alive at its start (``gc.freeze``), and those alive
    when the function it yields is called; all are handed back to it at the end (``gc.unfreeze``).

    What is alive before the figures are drawn (the imported modules, numba's, pandas' and matplotlib's tables, the
    model run: ~240 000 objects) stays alive to the end, yet each full collection walked all of it again: ~0.12 s
    a walk, a few times in the parent and once in each forked worker, where the walk also writes to every
    object's header and so copies each page of the parent's heap the worker had shared (issue 31).  The figures'
    own cycles, made after the freeze, are collected as before.  Where the collector is off, or the caller froze
    objects itself, nothing is frozen or unfrozen here.
    """
    if not gc.isenabled() or gc.get_freeze_count() > 0:
        yield lambda: None
        return
    gc.freeze()
    try:
        yield gc.freeze
    finally:
        gc.unfreeze()


def _forked_figures(
    run: ModelRun, folder: Path, step: Callable[[str], None], count: int
) -> Iterator[tuple[RenderedFigure, list[Path], list[Path]]]:
    """The figures of :func:`_rendered_figures` drawn by ``count`` forked processes, in order."""
    global _SHARED_RUN
    _SHARED_RUN = run
    try:
        context = multiprocessing.get_context("fork")
        with ProcessPoolExecutor(
            max_workers=count, mp_context=context, initializer=die_with_parent, initargs=(os.getpid(),)
        ) as pool:
            futures: list[Any] = [None] * len(FIGURE_BUILDERS)
            for i in _slowest_first():  # a slow figure started last would leave the other worker idle at the end
                futures[i] = pool.submit(_render_in_worker, i, folder)
            try:
                for (description, _), future in zip(FIGURE_BUILDERS, futures, strict=True):
                    step(description)
                    yield future.result()
            except BaseException:  # interrupted or terminated: leaving the pool would first draw every figure
                _stop_workers(pool, folder)
                raise
    finally:
        _SHARED_RUN = None


def _stop_workers(pool: ProcessPoolExecutor, folder: Path) -> None:
    """Cancel what the workers have not started, end them now and remove the temporaries they were writing.

    A worker killed inside an atomic write leaves its ``.name.xxxxxxxx.csv.tmp``; once it is gone (reaped, its
    file lock released) the temporary is removed here rather than by the next report written into the folder.
    """
    import signal

    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        with contextlib.suppress(OSError, ValueError, AttributeError):
            os.kill(process.pid, signal.SIGKILL)
    for process in processes:
        with contextlib.suppress(OSError, ValueError, AttributeError, AssertionError):
            process.join(timeout=5)
    remove_orphaned_temporaries(folder)


#: The figures that take longest to draw (2-6 s each; the others 0.3-1.5 s), started first in the workers.
SLOW_FIGURES = (
    "The full time-dependent model (Eq 1)",
    "One population that lets go (saturating aging)",
    "Phase diagram: regimes over V0 and stiffness",
)


def _slowest_first() -> list[int]:
    """Indices into FIGURE_BUILDERS: the slow figures first, then the others in their order."""
    order = range(len(FIGURE_BUILDERS))
    return sorted(order, key=lambda i: FIGURE_BUILDERS[i][0] not in SLOW_FIGURES)


def _load_before_fork(run: ModelRun) -> None:
    """Import, and load from numba's cache, what figures in both workers need, once here before the fork.

    The forked workers share this process's memory, so what is loaded here is loaded for both; loaded in the
    workers instead, it cost each of them the same CPU again: matplotlib (every figure, ~0.4 s), pandas (the phase
    diagram's sweep and the rate-and-state fits, ~0.35 s), numba with the transient kernels (the time-dependent,
    rate-and-state and inertia figures: ~0.6 s, most of it the compiled kernels read from the cache at the first
    run).  The run below is a millisecond of sliding through the solver; its result is discarded.
    """
    import matplotlib.figure  # noqa: F401
    import pandas  # noqa: F401

    from ..protocols import constant
    from ..transient import run_transient

    velocity = 100e-6
    run_transient(run.params, constant(velocity, 1e-3), control="velocity", start="steady", rtol=1e-3)


def _write(action: Callable[[], Any]) -> Any:
    try:
        return action()
    except OSError as exc:
        raise DataError(f"cannot write the report: {exc.strerror or exc} ({getattr(exc, 'filename', '')})") from None


def _write_text(path: Path, text: str) -> Path:
    _write(lambda: atomic_write_text(path, text))
    return path
