"""SIGTERM (a batch system's time limit, `kill`) unwinds a command: its temporaries are removed, one line, 143.

Before, the default action ended the process where it stood: a half-written ``.name.xxxx.tmp`` stayed beside the
output (the next writer into that folder cleaned it) and a report's forked figure workers were left to finish.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from stickslip.cli.main import Terminated, sigterm_unwinds
from stickslip.fileio import atomic_open

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")


def test_sigterm_inside_an_atomic_write_removes_the_temporary(tmp_path: Path) -> None:
    target = tmp_path / "out.csv"
    with pytest.raises(Terminated), sigterm_unwinds(), atomic_open(target) as handle:
        handle.write("time (s),stress (Pa)\n")
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)  # the signal arrives before this ends
    assert list(tmp_path.iterdir()) == []  # neither the target nor the temporary
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # the handler is the block's only


def test_a_handler_set_by_the_caller_is_kept(tmp_path: Path) -> None:
    seen: list[int] = []
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: seen.append(signum))
    try:
        with sigterm_unwinds():
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.05)
        assert seen == [signal.SIGTERM]
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_reproduce_terminated_ends_with_one_line_143_and_no_temporaries(tmp_path: Path) -> None:
    folder = tmp_path / "report"
    command = [sys.executable, "-m", "stickslip.cli.main", "reproduce", "--quiet", "-o", str(folder)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not any(folder.glob("*.png")) and time.monotonic() < deadline and process.poll() is None:
        time.sleep(0.05)  # the figures are being drawn: workers forked, files being written
    assert process.poll() is None, "the report ended before it could be terminated"
    process.send_signal(signal.SIGTERM)
    started = time.monotonic()
    _out, err = process.communicate(timeout=60)
    assert process.returncode == 128 + signal.SIGTERM
    assert time.monotonic() - started < 10  # the workers are stopped, not waited for
    assert "stickslip: terminated" in err and "Traceback" not in err
    assert not [p.name for p in folder.iterdir() if p.name.endswith(".tmp")]


def _write_slowly(target: Path) -> None:
    with atomic_open(target) as handle:
        handle.write("time (s),stress (Pa)\n")
        handle.flush()
        time.sleep(60)  # killed here, inside the write


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="forked figure workers")
def test_stopping_the_figure_workers_removes_the_temporary_a_killed_worker_was_writing(tmp_path: Path) -> None:
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from stickslip.report.build import _stop_workers

    pool = ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("fork"))
    pool.submit(_write_slowly, tmp_path / "figure.csv")
    deadline = time.monotonic() + 30
    while not list(tmp_path.glob(".figure.csv.*.tmp")) and time.monotonic() < deadline:
        time.sleep(0.02)
    assert list(tmp_path.glob(".figure.csv.*.tmp")), "the worker never started its write"
    _stop_workers(pool, tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_a_temporary_a_live_writer_holds_is_kept(tmp_path: Path) -> None:
    from stickslip.fileio import remove_orphaned_temporaries

    with atomic_open(tmp_path / "out.csv") as handle:
        handle.write("x\n")
        assert remove_orphaned_temporaries(tmp_path) == []
        assert len(list(tmp_path.glob(".out.csv.*.tmp"))) == 1
    assert [p.name for p in tmp_path.iterdir()] == ["out.csv"]
