"""Issue 30 item 5: the old module names still import, with a DeprecationWarning naming the new home."""

from __future__ import annotations

import importlib
import sys

import pytest


@pytest.mark.parametrize(
    ("old", "new", "name"),
    [
        ("stickslip.plotting", "stickslip.plots.steady", "figure_steady_curve"),
        ("stickslip.cycle_plots", "stickslip.plots.cycles", "figure_cycles"),
        ("stickslip.rsf.compare", "stickslip.studies.bond_rsf", "rsf_of_bond"),
    ],
)
def test_an_old_name_warns_and_gives_the_same_function(old, new, name):
    sys.modules.pop(old, None)
    with pytest.warns(DeprecationWarning, match=new):
        module = importlib.import_module(old)
    assert getattr(module, name) is getattr(importlib.import_module(new), name)


def test_the_package_itself_imports_no_deprecated_name():
    import subprocess

    code = (
        "import sys, stickslip, stickslip.report.build, stickslip.report.figures, stickslip.cli.main; "
        "import stickslip.studies.bond_rsf, stickslip.studies.rsf_reading, stickslip.cli.compare_cmd; "
        "print(sorted(m for m in ('stickslip.plotting', 'stickslip.cycle_plots', 'stickslip.rsf.compare')"
        " if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stdout.strip() == "[]", done.stdout + done.stderr[-2000:]
