"""Two velocities compared in words are written with the digits that tell them apart (tester R: "124.1 µm/s is
below Vc = 124.1 µm/s" for a start at 124.05 µm/s)."""

from __future__ import annotations

import re

from stickslip.display import velocities_apart
from stickslip.parameters import load_parameters
from stickslip.protocols import constant
from stickslip.quasistatic.critical import critical_minimum
from stickslip.transient import run_transient


def _number(text: str) -> float:
    return float(text.split()[0])


def test_close_velocities_read_in_their_true_order() -> None:
    for a, b in ((124.05e-6, 124.097e-6), (1.0e-4, 1.00001e-4), (0.5e-6, 0.49999999e-6)):
        first, second = velocities_apart(a, b)
        assert (_number(first) < _number(second)) == (a < b)
        assert first != second


def test_far_velocities_keep_four_digits() -> None:
    assert velocities_apart(100e-6, 124.097e-6) == ("100 µm/s", "124.1 µm/s")


def test_a_steady_start_just_below_vc_says_so_truthfully() -> None:
    params = load_parameters("gelatin-glass")
    vc = critical_minimum(params).velocity
    start = vc * (1 - 4e-4)  # 124.05 µm/s for Vc = 124.097 µm/s
    result = run_transient(params, constant(start, 0.01), start="steady", rtol=1e-3)
    said = re.search(r"steady start: ([0-9.]+) µm/s is below Vc = ([0-9.]+) µm/s", result.message)
    assert said is not None, result.message
    assert float(said.group(1)) < float(said.group(2))
