"""Outputs never destroy what their name points at; killed writes leave nothing behind for long; inputs are safe.

Every special target here is a private copy in tmp_path (a device node made
with mknod, a FIFO, a link to /proc/self/fd/1): never the system's own
/dev/null or /dev/stdout, which a faulty writer would replace machine-wide.
"""

from __future__ import annotations

import os
import stat
import threading
import time
from pathlib import Path

import click
import pytest

from stickslip.errors import DataError
from stickslip.fileio import (
    atomic_path,
    atomic_write_bytes,
    atomic_write_text,
    output_kind,
    protect_inputs,
    refuse_input_as_output,
    remove_stale_temporaries,
)

PAYLOAD = b"time,stress\n0,1\n1,2\n"


def _char_device(folder: Path) -> Path:
    """A private null device (major 1, minor 3), made with mknod."""
    node = folder / "null"
    try:
        os.mknod(node, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    except PermissionError:
        pytest.fail("mknod needs root (the test machine runs as root)")
    return node


def _read_fifo(fifo: Path, into: list[bytes]) -> threading.Thread:
    def reader() -> None:
        with open(fifo, "rb") as handle:
            into.append(handle.read())

    thread = threading.Thread(target=reader, daemon=True)
    thread.start()
    return thread


def _only_names(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


# --------------------------------------------------------------------------- regular files and links
def test_a_new_path_and_a_regular_file_are_written_whole_with_their_mode_kept(tmp_path):
    target = tmp_path / "out.csv"
    atomic_write_bytes(target, b"old")
    os.chmod(target, 0o640)
    atomic_write_bytes(target, PAYLOAD)
    assert target.read_bytes() == PAYLOAD and stat.S_IMODE(target.stat().st_mode) == 0o640
    assert _only_names(tmp_path) == ["out.csv"]


def test_a_symlink_is_followed_its_target_replaced_and_the_link_kept(tmp_path):
    (tmp_path / "real").mkdir()
    real = tmp_path / "real" / "data.csv"
    real.write_bytes(b"old")
    link = tmp_path / "link.csv"
    link.symlink_to(real)
    atomic_write_text(link, PAYLOAD.decode())
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert real.read_bytes() == PAYLOAD
    assert _only_names(tmp_path) == ["link.csv", "real"] and _only_names(tmp_path / "real") == ["data.csv"]


def test_a_chain_of_links_and_a_dangling_link_write_the_final_target(tmp_path):
    real = tmp_path / "final.csv"
    (tmp_path / "middle.csv").symlink_to("final.csv")  # relative link
    (tmp_path / "first.csv").symlink_to(tmp_path / "middle.csv")
    atomic_write_bytes(tmp_path / "first.csv", PAYLOAD)  # dangling at first: final.csv does not exist
    assert real.read_bytes() == PAYLOAD
    assert (tmp_path / "first.csv").is_symlink() and (tmp_path / "middle.csv").is_symlink()


def test_a_figure_writer_through_a_symlink_replaces_the_target(tmp_path):
    real = tmp_path / "fig.png"
    real.write_bytes(b"old")
    link = tmp_path / "link.png"
    link.symlink_to(real)
    with atomic_path(link) as temp:
        temp.write_bytes(b"\x89PNG new")
    assert link.is_symlink() and real.read_bytes() == b"\x89PNG new"


# --------------------------------------------------------------------------- devices, FIFOs, standard output
def test_a_character_device_is_written_as_it_is_and_stays_a_device(tmp_path):
    node = _char_device(tmp_path)
    assert output_kind(node) == "stream"
    atomic_write_bytes(node, PAYLOAD)
    with atomic_path(node) as temp:  # the path-taking writers (savefig, parquet) too
        temp.write_bytes(PAYLOAD)
    assert stat.S_ISCHR(node.lstat().st_mode)
    assert _only_names(tmp_path) == ["null"]


def test_a_fifo_is_written_through_and_its_reader_gets_every_byte(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    received: list[bytes] = []
    thread = _read_fifo(fifo, received)
    atomic_write_bytes(fifo, PAYLOAD)
    thread.join(10)
    assert received == [PAYLOAD] and stat.S_ISFIFO(fifo.lstat().st_mode)
    received.clear()
    thread = _read_fifo(fifo, received)
    with atomic_path(fifo, suffix=".png") as temp:
        temp.write_bytes(b"\x89PNG")
    thread.join(10)
    assert received == [b"\x89PNG"] and stat.S_ISFIFO(fifo.lstat().st_mode)
    assert _only_names(tmp_path) == ["pipe"]


def test_a_link_to_the_process_stdout_is_written_through_and_kept(tmp_path, capfd):
    link = tmp_path / "stdout"
    link.symlink_to("/proc/self/fd/1")  # a private /dev/stdout
    assert output_kind(link) == "stream"
    atomic_write_bytes(link, PAYLOAD)
    with atomic_path(link) as temp:
        temp.write_bytes(b"second\n")
    assert capfd.readouterr().out == PAYLOAD.decode() + "second\n"
    assert link.is_symlink() and os.readlink(link) == "/proc/self/fd/1"
    assert _only_names(tmp_path) == ["stdout"]


def test_bytes_to_the_own_stdout_keep_their_place_among_the_process_output(tmp_path, capfd):
    link = tmp_path / "stdout"
    link.symlink_to("/proc/self/fd/1")  # fd 1 is a file here (pytest's capture), as after a shell's `>`
    os.write(1, b"before\n")
    atomic_write_bytes(link, PAYLOAD)
    os.write(1, b"after\n")
    assert capfd.readouterr().out == "before\n" + PAYLOAD.decode() + "after\n"


def test_dash_is_standard_output(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    atomic_write_text("-", PAYLOAD.decode())
    with atomic_path(Path("-"), suffix=".svg") as temp:
        temp.write_bytes(b"<svg/>")
    assert capsys.readouterr().out == PAYLOAD.decode() + "<svg/>"
    assert _only_names(tmp_path) == []


# --------------------------------------------------------------------------- temporaries of killed writes
def _old(path: Path, data: bytes = b"half") -> Path:
    path.write_bytes(data)
    past = time.time() - 3600
    os.utime(path, (past, past))
    return path


def test_stale_temporaries_of_the_target_are_removed_at_the_next_write(tmp_path):
    stale = [_old(tmp_path / ".out.csv.ab12cd_9.csv.tmp"), _old(tmp_path / ".out.csv.zz99yy00.tmp")]
    keep = [
        _old(tmp_path / ".out.csv.mine.tmp"),  # not our pattern: a user's file
        _old(tmp_path / ".other.csv.ab12cd_9.csv.tmp"),  # another target's
        _old(tmp_path / "out.csv.ab12cd_9.csv.tmp"),  # no leading dot
        tmp_path / ".out.csv.fresh000.csv.tmp",  # younger than this process: maybe a live writer's
    ]
    keep[-1].write_bytes(b"live")
    atomic_write_bytes(tmp_path / "out.csv", PAYLOAD)
    assert not any(p.exists() for p in stale)
    assert all(p.exists() for p in keep)


def test_a_temporary_locked_by_a_live_writer_is_kept(tmp_path):
    import fcntl

    busy = _old(tmp_path / ".out.csv.ab12cd34.csv.tmp")
    with open(busy, "rb") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        assert remove_stale_temporaries(tmp_path / "out.csv") == []
    assert busy.exists()
    assert remove_stale_temporaries(tmp_path / "out.csv") == [busy]


# --------------------------------------------------------------------------- inputs
def test_an_input_is_recognised_through_a_symlink_and_a_hard_link(tmp_path):
    data = tmp_path / "data.csv"
    data.write_bytes(PAYLOAD)
    soft, hard = tmp_path / "soft.csv", tmp_path / "hard.csv"
    soft.symlink_to(data)
    os.link(data, hard)
    for alias in (data, soft, hard):
        with pytest.raises(DataError, match="input file"):
            refuse_input_as_output([data], [("-o", alias)])
    refuse_input_as_output([data], [("-o", tmp_path / "new.csv"), ("-o", "-")])


def test_inside_a_command_no_later_write_replaces_a_protected_input(tmp_path):
    params = tmp_path / "run.params.json"
    params.write_text("{}", encoding="utf-8")
    hard = tmp_path / "hard.json"
    os.link(params, hard)

    @click.command()
    def command() -> None:
        protect_inputs([params, "gelatin-glass", None])
        atomic_write_text(tmp_path / "run.csv", "fine\n")
        for target in (params, hard):
            with pytest.raises(DataError, match="that is the input file"):
                atomic_write_text(target, "clobbered")

    command.main([], standalone_mode=False)
    assert params.read_text(encoding="utf-8") == "{}"
    atomic_write_text(params, "{}\n")  # outside the command: the API writes what it is told
