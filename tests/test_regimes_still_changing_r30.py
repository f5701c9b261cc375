"""Round 30 (tester U, D4): a tail that is no exponential approach is said in words, never as "inf Pa".

The trace is built by hand: an exponential approach (1 - exp(-t / 0.2)) with a rise added over its last 0.1 s, so
that over the last 0.25 s (two halves of 0.125 s) it speeds up, while over longer spans it still slows down.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from stickslip import regimes


def _tail():
    t = np.linspace(0.0, 1.0, 2001)
    y = 100.0 * (1.0 - np.exp(-t / 0.2)) + 2.0 * np.clip((t - 0.9) / 0.1, 0.0, None) ** 2
    return t, y


def test_a_tail_that_speeds_up_over_a_short_span_is_said_so_not_inf():
    t, y = _tail()
    found = regimes.classify(t, y, floor=1e-9, unit="Pa")
    text = found.evidence
    assert found.kind == regimes.UNDETERMINED and "not as one exponential approach" in text and "not known" in text
    assert "inf" not in text and "nan" not in text
    assert "(not slowing down)" in text
    # the two changes of the shortest span are the trace's own (d1 < d2: it speeds up), with their unit
    tau = 0.125
    a, b, c = np.interp([1.0 - 2 * tau, 1.0 - tau, 1.0], t, y)
    assert 0 < b - a < c - b
    assert f"{b - a:+.3g} Pa then {c - b:+.3g} Pa (not slowing down)" in text
    # every pair's words say what its two changes show (the rule written out here: opposite signs turn back, a
    # second change as large as the first does not slow down, else, as one exponential, d2 q / (1 - q) more)
    pairs = re.findall(r"([+-][0-9.e+-]+) Pa then ([+-][0-9.e+-]+) Pa \(([^)]*)\)", text)
    assert len(pairs) == 3
    for first, second, words in pairs:
        d1, d2 = float(first), float(second)
        if d1 * d2 < 0:
            assert words == "turns back"
        elif abs(d2) >= abs(d1):
            assert words == "not slowing down"
        else:
            q = d2 / d1
            assert words.startswith("slows down: ") and words.endswith(" Pa more as one exponential")
            assert float(words.split()[2]) == pytest.approx(abs(d2) * q / (1 - q), rel=0.02)  # 3 digits shown
