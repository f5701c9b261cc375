"""The sweep folder: one writer at a time, chunks checked on resume, refusals in one line, memory flat in batches."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
import tracemalloc
from types import SimpleNamespace

import pandas as pd
import pytest

from cli_helpers import run_main
from stickslip.errors import DataError, ParameterError
from stickslip.sweeps import build_spec, run_sweep, sweep
from stickslip.sweeps.engine import compute, run_batch
from stickslip.sweeps.store import LEDGER, LOCK, MANIFEST, open_store

VELOCITIES = "pulling_velocity=20 um/s..2 mm/s:4:log"
SWEEP = ["sweep", "--vary", VELOCITIES, "--vary", "block.height=1 cm,2 cm", "--duration", "60 s", "--workers", "0"]


def _one_error_line(status: int, err: str) -> str:
    assert status == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stickslip: error: "), err
    return lines[0]


def _rows(folder) -> pd.DataFrame:
    frame = pd.read_parquet(folder).sort_values("point").reset_index(drop=True)
    return frame.drop(columns="wall_time")


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """An 8-point sweep in batches of 3, written by the command line, and its rows."""
    folder = tmp_path_factory.mktemp("reference") / "out"
    status = subprocess.run(
        [sys.executable, "-m", "stickslip.cli.main", *SWEEP, "--batch-size", "3", "--quiet", "-o", str(folder)],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)},
    )
    assert status.returncode == 0, status.stderr
    return folder, _rows(folder)


def _copy(folder, target):
    target.mkdir()
    for path in folder.iterdir():
        (target / path.name).write_bytes(path.read_bytes())
    return target


# --------------------------------------------------------------------------- refusals in one line
REFUSED = [
    (["--vary", "pulling_velocity=1 um/s..1 mm/s:99999999999999999999", "-o", "{d}/out"], "at most 1000000"),
    (["--vary", VELOCITIES, "-o", "/proc/stickslip-out"], "cannot create or write the folder"),
    (["--vary", VELOCITIES, "--scheduler", "garbage", "-o", "{d}/out"], "not a scheduler address"),
    (["--vary", VELOCITIES, "-o", ""], "give its name"),
    (["--vary", VELOCITIES, "-o", "-"], "give its name"),
    (["--vary", "block.height=1 cm,2 cm", "--v0", "50", "-o", "{d}/out"], "--v0 50: a velocity needs a unit"),
    (["--vary", VELOCITIES, "--set", "bonds.bond_time=224", "-o", "{d}/out"], "bond_time=224: a time needs a unit"),
    (["--model", "rsf", "--vary", VELOCITIES, "--set", "dc=10", "-o", "{d}/out"], "dc=10: a length needs a unit"),
    (["--vary", "pulling_velocity=50", "-o", "{d}/out"], "pulling_velocity=50: a velocity needs a unit"),
    (["--vary", "pulling_velocity=1..2 mm/s:3", "-o", "{d}/out"], "pulling_velocity=1: a velocity needs a unit"),
    (["--vary", "pulling_velocity=1 um/s..1 mm/s:log", "--samples", "100000000000", "-o", "{d}/out"], "free"),
]


@pytest.mark.parametrize(("args", "expected"), REFUSED, ids=[f"#{i}" for i in range(len(REFUSED))])
def test_bad_sweeps_fail_in_one_line_and_leave_no_folder(tmp_path, capsys, monkeypatch, args, expected):
    free = SimpleNamespace(total=10**11, used=2 * 10**10, free=8 * 10**10)  # whatever this machine's disk holds
    monkeypatch.setattr("stickslip.sweeps.store.shutil.disk_usage", lambda path: free)
    began = time.perf_counter()
    status, _, err = run_main(capsys, "sweep", *[a.format(d=tmp_path) for a in args])
    assert expected in _one_error_line(status, err)
    assert time.perf_counter() - began < 5
    assert list(tmp_path.iterdir()) == []


def test_a_sweep_whose_every_point_failed_exits_2_with_the_first_reason(tmp_path, capsys):
    """A fuzz of the command line (2026-11-29): a duration no point can trace (1e300 s) left every row an error and
    the command said "sweep: 3 points (3 failed)" with exit 0; one point failing among others is still a row."""
    out = tmp_path / "out"
    argv = ["--workers", "0", "--quiet", "--vary", "bonds.bond_time=100 us..500 us:3", "--v0", "50 um/s", "-o"]
    status, _, err = run_main(capsys, "sweep", *argv, str(out), "--duration", "1e300 s")
    line = _one_error_line(status, err)
    assert "every point of the sweep failed (3 of 3;" in line and "give a shorter duration" in line
    assert (pd.read_parquet(out)["status"] == "error").all()  # each reason kept in its row
    status, _, err = run_main(capsys, "sweep", *argv, str(tmp_path / "fine"), "--duration", "30 s")
    assert status == 0 and err == "", err


def test_a_sweep_too_large_for_the_disk_is_refused_before_any_work(tmp_path, monkeypatch):
    usage = SimpleNamespace(total=10**12, used=10**12 - 10**9, free=10**9)
    monkeypatch.setattr("stickslip.sweeps.store.shutil.disk_usage", lambda path: usage)
    spec = build_spec(["pulling_velocity=1 um/s..1 mm/s:log"], samples=10**9)
    with pytest.raises(ParameterError, match=r"1e\+09 points need at least .* GB of Parquet and the disk has 1 GB"):
        run_sweep(spec, tmp_path / "out", workers=0)
    assert not (tmp_path / "out").exists()


def test_a_folder_with_a_manifest_and_no_chunk_cannot_be_plotted(reference, tmp_path, capsys):
    folder = _copy(reference[0], tmp_path / "out")
    for chunk in folder.glob("part-*.parquet"):
        chunk.unlink()
    status, _, err = run_main(capsys, "sweep", "plot", str(folder), "--y", "block.height")
    assert "no finished batch yet" in _one_error_line(status, err)


def test_plot_into_the_sweep_folder_is_refused_and_the_folder_untouched(reference, tmp_path, capsys):
    folder = _copy(reference[0], tmp_path / "out")
    before = sorted(p.name for p in folder.iterdir())
    status, _, err = run_main(capsys, "sweep", "plot", str(folder), "--y", "block.height", "-o", f"{folder}/x.png")
    assert "inside the sweep folder" in _one_error_line(status, err)
    assert sorted(p.name for p in folder.iterdir()) == before


def test_plot_into_a_missing_folder_or_an_unknown_format_is_refused_before_drawing(reference, tmp_path, capsys):
    """A fuzz of the command line (2026-11-29): the missing folder came back as an errno with the temporary name."""
    plot = ["sweep", "plot", str(reference[0]), "--y", "block.height", "-o"]
    status, _, err = run_main(capsys, *plot, str(tmp_path / "typo" / "x.png"))
    line = _one_error_line(status, err)
    assert "does not exist" in line and ".tmp" not in line and "Errno" not in line
    status, _, err = run_main(capsys, *plot, str(tmp_path / "x.xyz"))
    assert "unknown figure format .xyz" in _one_error_line(status, err)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (lambda m: m.pop("specification"), "the specification is missing or damaged"),
        (lambda m: m.update(batch_size=0), "batch_size is 0"),
        (lambda m: m.update(batch_size="3"), "batch_size is '3'"),
        (lambda m: m["specification"].pop("axes"), "the specification is missing or damaged"),
    ],
)
def test_a_damaged_manifest_is_one_line_on_resume_and_on_plot(reference, tmp_path, capsys, edit, expected):
    folder = _copy(reference[0], tmp_path / "out")
    manifest = json.loads((folder / MANIFEST).read_text())
    edit(manifest)
    (folder / MANIFEST).write_text(json.dumps(manifest))
    status, _, err = run_main(capsys, *SWEEP, "--quiet", "-o", str(folder))
    assert expected in _one_error_line(status, err)
    status, _, err = run_main(capsys, "sweep", "plot", str(folder), "--y", "block.height")
    assert status == 2 and len(err.strip().splitlines()) == 1


# --------------------------------------------------------------------------- chunks checked on resume
def _random_bytes(folder):
    (folder / "part-000001.parquet").write_bytes(os.urandom(2000))
    return ["part-000001.parquet"]


def _truncated(folder):
    chunk = folder / "part-000002.parquet"
    chunk.write_bytes(chunk.read_bytes()[:-100])
    return ["part-000002.parquet"]


def _another_chunk(folder):
    (folder / "part-000000.parquet").write_bytes((folder / "part-000001.parquet").read_bytes())
    return ["part-000000.parquet"]


def _stray_chunk(folder):
    (folder / "part-000007.parquet").write_bytes((folder / "part-000001.parquet").read_bytes())
    return ["part-000007.parquet"]


def _edited_batch_size(folder):
    manifest = json.loads((folder / MANIFEST).read_text())
    manifest["batch_size"] = 2  # 4 batches of 2, where 3 chunks of 3 rows are
    (folder / MANIFEST).write_text(json.dumps(manifest))
    return ["part-000000.parquet", "part-000001.parquet", "part-000002.parquet"]


def _unrecorded_but_whole(folder):
    (folder / LEDGER).unlink()  # a folder from before the ledger: its chunks are read, and kept
    return []


@pytest.mark.parametrize(
    "damage", [_random_bytes, _truncated, _another_chunk, _stray_chunk, _edited_batch_size, _unrecorded_but_whole]
)
def test_resume_finds_damaged_chunks_recomputes_them_and_says_so(reference, tmp_path, capsys, damage):
    folder, expected = reference
    copy = _copy(folder, tmp_path / "out")
    named = damage(copy)
    status, _, err = run_main(capsys, *SWEEP, "--quiet", "-o", str(copy))
    assert status == 0, err
    if named:
        assert len(err.strip().splitlines()) == 1 and "damaged chunk" in err
        assert all(name in err for name in named)
    else:
        assert err == ""
    pd.testing.assert_frame_equal(_rows(copy), expected)
    status, _, err = run_main(capsys, *SWEEP, "--quiet", "-o", str(copy))  # and now it is whole
    assert status == 0 and err == ""


# --------------------------------------------------------------------------- one writer at a time
def test_a_second_writer_is_refused_in_one_line(reference, tmp_path, capsys):
    folder = tmp_path / "out"
    spec = build_spec([VELOCITIES, "block.height=1 cm,2 cm"], duration="60 s")
    with open_store(folder, spec, 3):
        status, _, err = run_main(capsys, *SWEEP, "-o", str(folder))
        assert f"(process {os.getpid()})" in _one_error_line(status, err)
        status, _, err = run_main(
            capsys, *SWEEP, "--overwrite", "--vary", "bonds.bond_time=1 ms,2 ms", "-o", str(folder)
        )
        assert "another sweep is writing into this folder" in _one_error_line(status, err)
    status, _, err = run_main(capsys, *SWEEP, "--batch-size", "3", "--quiet", "-o", str(folder))
    assert status == 0, err
    pd.testing.assert_frame_equal(_rows(folder), reference[1])


def test_the_lock_of_a_live_process_refuses_and_dies_with_it(tmp_path, capsys):
    folder = tmp_path / "out"
    folder.mkdir()
    holder = subprocess.Popen(
        [sys.executable, "-c", f"import fcntl,os,sys,time; f=os.open({str(folder / LOCK)!r}, os.O_RDWR|os.O_CREAT);"
         "fcntl.flock(f, fcntl.LOCK_EX); print('locked', flush=True); time.sleep(60)"],
        stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert holder.stdout.readline().strip() == "locked"
        status, _, err = run_main(capsys, *SWEEP, "-o", str(folder))
        assert "another sweep is writing into this folder" in _one_error_line(status, err)
    finally:
        holder.kill()
        holder.wait()
    status, _, err = run_main(capsys, *SWEEP, "--quiet", "-o", str(folder))
    assert status == 0, err


# --------------------------------------------------------------------------- the Python API
@pytest.mark.parametrize(
    ("call", "expected"),
    [
        (lambda: sweep({"pulling_velocity": 5e-5}, workers=0), r"one value: \[5e-05\]"),
        (lambda: sweep(5, workers=0), "vary: expected"),
        (lambda: sweep([VELOCITIES], seed=1.5, workers=0), "seed: expected a whole number, got 1.5"),
        (lambda: sweep([VELOCITIES], seed=True, workers=0), "seed: expected a whole number"),
        (lambda: sweep(["pulling_velocity=1 um/s..1 mm/s"], samples=2.5, workers=0), "samples: expected a whole"),
        (lambda: sweep([VELOCITIES], workers=-1), "workers: expected a whole number >= 0"),
        (lambda: sweep([VELOCITIES], model=3), "model: expected a name"),
        (lambda: sweep([VELOCITIES], "", workers=0), "output: the folder name is empty"),
        (lambda: sweep([VELOCITIES], overrides=["bonds.bond_time=1 ms"], workers=0), "overrides: expected a mapping"),
    ],
)
def test_the_python_api_raises_typed_errors(call, expected):
    with pytest.raises(ParameterError, match=expected):
        call()


def test_run_sweep_refuses_a_batch_size_of_zero_and_a_foreign_spec(tmp_path):
    spec = build_spec([VELOCITIES])
    with pytest.raises(ParameterError, match="batch_size: expected a whole number >= 1, got 0"):
        run_sweep(spec, tmp_path / "out", workers=0, batch_size=0)
    with pytest.raises(ParameterError, match="spec: expected a SweepSpec"):
        run_sweep({"model": "rsf"}, tmp_path / "out", workers=0)
    with pytest.raises(DataError, match="is a file"):
        (tmp_path / "file").write_text("x")
        run_sweep(spec, tmp_path / "file", workers=0)


def test_bare_numbers_stay_si_in_the_python_api():
    spec = build_spec(["pulling_velocity=5e-5,1e-4"], overrides={"bonds.bond_time": 224e-6})
    assert spec.axes[0].values == (5e-5, 1e-4) and spec.fixed["bonds.bond_time"] == 224e-6


# --------------------------------------------------------------------------- memory flat in the number of batches
def test_memory_does_not_grow_with_the_number_of_batches(tmp_path):
    spec = build_spec(["pulling_velocity=1 um/s..1 mm/s:log"], samples=2_000_000)

    class Enough(Exception):
        pass

    def stop_after_three(points, seen=[]):  # noqa: B006 - a counter local to this test
        seen.append(points)
        if len(seen) == 3:
            raise Enough

    store = open_store(tmp_path / "out", spec, batch_size=1)  # 2e6 batches
    import pyarrow.parquet  # noqa: F401 - imports and per-process caches first: they are no growth

    run_batch(spec.to_json(), 0, 1)
    tracemalloc.start()
    try:
        with pytest.raises(Enough):
            compute(store, None, stop_after_three)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
        store.close()
    assert peak < 10_000_000, f"{peak / 1e6:.0f} MB for 3 batches out of 2e6"  # the old code took 198 MB


def test_the_python_api_warns_of_damaged_chunks_it_recomputed(reference, tmp_path):
    folder, expected = reference
    copy = _copy(folder, tmp_path / "out")
    _truncated(copy)
    with pytest.warns(UserWarning, match=r"1 damaged chunk\(s\) .* recomputed: part-000002.parquet \(its bytes differ"):
        frame = sweep([VELOCITIES, "block.height=1 cm,2 cm"], copy, duration="60 s", workers=0)
    pd.testing.assert_frame_equal(frame.drop(columns="wall_time"), expected)
