"""Issue 29: `kill -9` of `stickslip reproduce` or `stickslip sweep` must not leave their worker processes alive.

The report's parent here is a real process drawing slow figures in two forked workers (the report's own
``_rendered_figures``); it is killed with SIGKILL, which runs no cleanup at all, and every worker must be
gone within seconds.  Before the fix the workers sat blocked on their task pipe for as long as the machine ran.
The sweep is the real command on a two-worker dask cluster, killed the same way once its workers run.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

PARENT = textwrap.dedent(
    """
    import os, sys, time
    from pathlib import Path
    from stickslip.report import build

    marks = Path(sys.argv[1])

    def slow(run, k):
        (marks / f"worker-{os.getpid()}").write_text("")
        time.sleep(60)  # far longer than the test: only the parent's death can end it

    build.FIGURE_BUILDERS = [(f"figure {k}", lambda run, k=k: slow(run, k)) for k in range(4)]
    (marks / f"parent-{os.getpid()}").write_text("")
    list(build._rendered_figures({}, marks, lambda step: None, 2))
    """
)


def _alive(pid: int) -> bool:
    """Running (a zombie, dead but not yet reaped by a PID 1 that does not reap, counts as gone)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError, IndexError):
        return False
    return state not in ("Z", "X")


def _survivors_of_a_killed_parent(parent: subprocess.Popen, children: list[int], seconds: float) -> list[int]:
    """SIGKILL ``parent`` (no cleanup runs), then the ``children`` still alive after ``seconds``."""
    os.kill(parent.pid, signal.SIGKILL)
    parent.wait(timeout=10)
    deadline = time.monotonic() + seconds
    while any(_alive(pid) for pid in children) and time.monotonic() < deadline:
        time.sleep(0.05)
    return [pid for pid in children if _alive(pid)]


def _pids(folder: Path, prefix: str) -> list[int]:
    return [int(p.name.split("-", 1)[1]) for p in folder.glob(f"{prefix}-*")]


@pytest.mark.skipif(
    not sys.platform.startswith("linux") or "fork" not in multiprocessing.get_all_start_methods(),
    reason="forked figure workers exist only on Linux",
)
def test_forked_figure_workers_die_with_a_killed_parent(tmp_path: Path) -> None:
    parent = subprocess.Popen([sys.executable, "-c", PARENT, str(tmp_path)], stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while len(_pids(tmp_path, "worker")) < 2 and time.monotonic() < deadline:
            assert parent.poll() is None, "the parent ended before its workers started"
            time.sleep(0.05)
        workers = _pids(tmp_path, "worker")
        assert len(workers) == 2, f"expected two forked workers drawing, saw {workers}"
        assert all(_alive(pid) for pid in workers)
        survivors = _survivors_of_a_killed_parent(parent, workers, 10)
    finally:
        if parent.poll() is None:
            parent.kill()
    for pid in survivors:  # leave nothing behind even when the test fails
        os.kill(pid, signal.SIGKILL)
    assert not survivors, f"workers {survivors} outlived their killed parent"


def test_die_with_parent_ends_a_worker_whose_parent_is_already_gone() -> None:
    """The race the kernel signal cannot cover: the parent died before the worker asked for the signal."""
    from stickslip.report.build import die_with_parent

    child = os.fork()
    if child == 0:  # pragma: no cover - the child's path: it must exit inside die_with_parent
        try:
            die_with_parent(parent=-1)  # not our parent: as if it had died and we were reparented
        finally:
            os._exit(0)
    _, status = os.waitpid(child, 0)
    assert os.WEXITSTATUS(status) == 1


def _descendants(pid: int) -> list[int]:
    """Every living process below ``pid`` (children, their children, ...), from /proc."""
    parents: dict[int, int] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (FileNotFoundError, ProcessLookupError, IndexError):
            continue
        if fields[0] not in ("Z", "X"):
            parents[int(stat.parent.name)] = int(fields[1])
    found, frontier = [], [pid]
    while frontier:
        children = [child for child, parent in parents.items() if parent in frontier]
        found += children
        frontier = children
    return found


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the process tree from /proc")
def test_a_killed_sweep_leaves_no_dask_worker_behind(tmp_path: Path) -> None:
    """`kill -9` of `stickslip sweep --workers 2`: its resource tracker and both dask worker processes go too."""
    grid = ["--vary", "pulling_velocity=5 um/s..5 mm/s:40:log", "--vary", "block.stiffness=40 kPa/m..4 MPa/m:30:log"]
    command = [sys.executable, "-m", "stickslip", "sweep", *grid, "-o", str(tmp_path / "out"), "--workers", "2"]
    parent = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while len(_descendants(parent.pid)) < 3 and time.monotonic() < deadline:
            assert parent.poll() is None, "the sweep ended before its workers started"
            time.sleep(0.1)
        started = _descendants(parent.pid)
        assert len(started) >= 3, f"expected a resource tracker and two workers, saw {started}"
        survivors = _survivors_of_a_killed_parent(parent, started, 30)
    finally:
        if parent.poll() is None:
            parent.kill()
    for pid in survivors:  # leave nothing behind even when the test fails
        os.kill(pid, signal.SIGKILL)
    assert not survivors, f"processes {survivors} outlived their killed sweep"
