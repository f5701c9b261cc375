"""The package's namespace (what ``dir(stickslip)`` and ``__all__`` promise resolves) and its use from scripts."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import stickslip

SRC = Path(stickslip.__file__).resolve().parents[1]


def test_every_name_in_all_resolves():
    assert len(stickslip.__all__) == len(set(stickslip.__all__)), "a name listed twice in __all__"
    assert set(stickslip._LAZY) <= set(stickslip.__all__), "a lazy name missing from __all__"
    for name in stickslip.__all__:
        assert getattr(stickslip, name) is not None, name


def test_dir_lists_the_public_names_and_not_the_import_helpers():
    names = dir(stickslip)
    assert set(stickslip.__all__) <= set(names)
    assert {"steady_state", "simulate", "sweep", "__version__"} <= set(names)
    assert not {"Any", "TYPE_CHECKING", "import_module", "annotations"} & set(names)
    assert names == sorted(names)


def test_dir_in_a_fresh_interpreter_lists_lazy_names_before_use():
    # In this process other tests may have loaded the lazy names already; a fresh one has not.
    code = "import stickslip; d = dir(stickslip); print('steady_state' in d, 'import_module' in d, 'rsf' in d)"
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env).stdout
    assert out.split() == ["True", "False", "True"]


def test_subpackages_are_reachable_after_a_plain_import():
    # README: `stickslip.transient.run_transient(...)`, `stickslip.rsf`, `stickslip.protocols` after `import stickslip`
    code = "import stickslip; print(stickslip.rsf.simulate.__name__, stickslip.protocols.read_protocol.__name__)"
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env).stdout
    assert out.split() == ["simulate", "read_protocol"]
    assert stickslip.transient.run_transient is not None


def test_star_import_gives_the_public_names():
    namespace: dict = {}
    exec("from stickslip import *", namespace)
    assert set(stickslip.__all__) <= set(namespace)


SCRIPT = """
import stickslip
frame = stickslip.sweep(["pulling_velocity=50 um/s,100 um/s"], duration="20 s"{extra})
print(list(frame["regime"]))
"""


def _run_script(tmp_path, text):
    script = tmp_path / "plain_script.py"
    script.write_text(text)
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    return subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env, timeout=120)


def test_sweep_in_a_plain_script_runs_and_says_why_in_one_line(tmp_path):
    """README: `stickslip.sweep([...])` in a script without the __main__ guard (was: 258 lines, 7 tracebacks)."""
    done = _run_script(tmp_path, SCRIPT.format(extra=""))
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "['stick-slip', 'stick-slip']"
    assert "Traceback" not in done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("stickslip: note: the sweep runs in this process") and "line 3" in line


def test_sweep_in_a_plain_script_with_workers_asked_for_is_one_clear_error(tmp_path):
    done = _run_script(tmp_path, "from stickslip.errors import ParameterError\ntry:\n" + "\n".join(
        "    " + row for row in SCRIPT.format(extra=", workers=2").strip().splitlines()
    ) + "\nexcept ParameterError as exc:\n    print(exc)\n")  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("workers=2: ") and "`if __name__ == '__main__':`" in done.stdout


def test_the_main_guard_is_recognised(tmp_path):
    probe = "from stickslip.sweeps.main_guard import unguarded_script_line\nprint(unguarded_script_line('spawn'))\n"
    guarded = "if __name__ == '__main__':\n    " + probe.replace("\n", "\n    ").rstrip() + "\n"
    assert _run_script(tmp_path, probe).stdout.strip().endswith(", 2)")
    assert _run_script(tmp_path, guarded).stdout.strip() == "None"
    fork = probe.replace("'spawn'", "'fork'")
    assert _run_script(tmp_path, fork).stdout.strip() == "None"
