"""The notice before numba compiles a kernel family for this machine (numerics/first_compile.py): said where numba's
own cache holds nothing for the kernel, silent once it does, silent without a listener (the library never
prints), and given by the command only on a terminal."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

KERNEL = textwrap.dedent(
    """
    from numba import njit

    def twice(x):
        return 2.0 * x

    twice = njit(cache=True)(twice)
    """
)

PROBE = textwrap.dedent(
    """
    import sys
    sys.path.insert(0, sys.argv[1])
    from stickslip.numerics.first_compile import announce_if_uncached, on_first_compile
    import probe_kernel

    heard = []
    if sys.argv[2] == "listen":
        on_first_compile(heard.append)
    announce_if_uncached(probe_kernel.twice, "the probe's kernel")
    announce_if_uncached(probe_kernel.twice, "the probe's kernel")  # once per family and process
    assert probe_kernel.twice(3.0) == 6.0  # compiles (and caches) where nothing was cached
    print(len(heard))
    """
)


def _heard(tmp_path: Path, listen: bool) -> int:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    done = subprocess.run(
        [sys.executable, "-c", PROBE, str(tmp_path), "listen" if listen else "quiet"],
        capture_output=True, text=True, env=env, timeout=120, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return int(done.stdout.strip())


def test_the_notice_comes_where_numba_has_nothing_cached_and_only_then(tmp_path):
    """Against numba's own cache: a kernel never compiled is announced (once), the same kernel loaded from the
    cache the first run wrote is not."""
    (tmp_path / "probe_kernel.py").write_text(KERNEL)
    assert _heard(tmp_path, listen=True) == 1  # compiled here: said once
    assert _heard(tmp_path, listen=True) == 0  # loaded from the cache the run before wrote


class _Uncached:
    """A stand-in numba dispatcher whose cache index is empty (nothing compiled for this source)."""

    class _cache:  # numba's attribute names
        class _cache_file:
            @staticmethod
            def _load_index() -> dict:
                return {}


def test_the_command_says_it_on_a_terminal_only_and_the_library_never(monkeypatch, capsys):
    """A listener only where the command's standard error is a terminal (in a pipe or a capture it carries only
    what the command reports, as for progress bars); without a listener the library says nothing."""
    from stickslip.cli import main as cli_main
    from stickslip.numerics import first_compile

    for terminal, expected in ((False, ""), (True, "stickslip: compiling the probe's kernel for this machine")):
        monkeypatch.setattr(first_compile, "_LISTENERS", [])
        monkeypatch.setattr(first_compile, "_ANNOUNCED", set())
        monkeypatch.setattr("stickslip.progress.on_terminal", lambda terminal=terminal: terminal)
        cli_main._notice_first_compiles()
        first_compile.announce_if_uncached(_Uncached(), "the probe's kernel")
        first_compile.announce_if_uncached(_Uncached(), "the probe's kernel")
        err = capsys.readouterr().err
        assert err.count("compiling") == (1 if terminal else 0) and expected in err
