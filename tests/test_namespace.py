"""The package's namespace: what ``dir(stickslip)`` and ``__all__`` promise resolves (issue 19)."""

from __future__ import annotations

import subprocess
import sys

import stickslip


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
    code = "import stickslip; d = dir(stickslip); print('steady_state' in d, 'import_module' in d)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["True", "False"]


def test_star_import_gives_the_public_names():
    namespace: dict = {}
    exec("from stickslip import *", namespace)
    assert set(stickslip.__all__) <= set(namespace)
