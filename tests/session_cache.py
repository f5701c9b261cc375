"""Build an expensive test input once per pytest session, however many xdist workers ask for it.

The pattern pytest-xdist documents ("Making session-scoped fixtures execute only once"): the workers share the
session's base temporary folder (the parent of each worker's own), so the first worker to take a file lock there
builds, writes what it built and a small JSON record beside it, and every later caller, in any worker, reads the
record instead of building again.  A failed build is recorded too, so the other workers fail at once with the same
message instead of spending the same minute again.
"""

from __future__ import annotations

import fcntl
import json
import os
from collections.abc import Callable
from pathlib import Path

import pytest


def session_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The base temporary folder every process of this session shares (a worker's own is one level down)."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


def build_once(tmp_path_factory: pytest.TempPathFactory, name: str, build: Callable[[Path], dict]) -> tuple[Path, dict]:
    """``build(folder)`` writes into ``folder`` and returns a JSON-able record; run once per session under a lock.

    Returns the folder and the record (the builder's, or the one a previous caller wrote).
    """
    root = session_folder(tmp_path_factory)
    folder, record = root / f"shared-{name}", root / f"shared-{name}.json"
    with open(root / f"shared-{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes; the other workers wait here meanwhile
        if not record.exists():
            folder.mkdir(exist_ok=True)
            made = build(folder)
            partial = record.with_suffix(".partial")
            partial.write_text(json.dumps(made), encoding="utf-8")
            partial.replace(record)
    return folder, json.loads(record.read_text(encoding="utf-8"))
