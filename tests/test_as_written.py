"""Issue 28 item 8: a refused value is named as the user wrote it, not converted to SI."""

from __future__ import annotations

import pytest

from cli_helpers import run_main


@pytest.mark.parametrize(
    ("argv", "written"),
    [
        (["rsf", "simulate", "--segment", "-1 um/s:10 s"], "got '-1 um/s'"),
        (["params", "show", "--set", "block.height=-5 mm"], "got '-5 mm'"),
        (["run", "--model", "transient", "--segment", "100 um/s:1 s", "--segment=-5 um/s:1 s"], "got '-5 um/s'"),
        (["simulate", "--set", "bonds.bond_time=-3 us", "--v0", "50 um/s", "--duration", "1 s"], "got '-3 us'"),
    ],
)
def test_a_refused_value_is_echoed_as_written(capsys, argv, written):
    code, _, err = run_main(capsys, *argv)
    assert code == 2 and err.count("\n") == 1 and written in err, err
