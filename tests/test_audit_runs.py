"""Audit of runs and sweeps: what a user met calling the run results and the protocol files as documented."""

from __future__ import annotations

import numpy as np

import stickslip
from stickslip import protocols
from stickslip.transient import run_transient

P = stickslip.load_parameters("gelatin-glass")


def test_transient_result_prints_a_few_lines_not_its_arrays():
    result = run_transient(P, protocols.constant(350e-6, 0.02), control="velocity", start="steady")
    text = repr(result)
    assert text.startswith("TransientResult(") and len(text) < 1200, text
    assert f"<{result.time.size} values>" in text and "array(" not in text
    assert isinstance(result.time, np.ndarray) and result.time.size > 6
