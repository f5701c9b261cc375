"""Summaries that must not depend on how the output is sampled (fixred)."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.models.run import settled_mean


def test_settled_mean_starts_its_window_at_the_cut_not_at_the_next_row():
    """A ramp s = t over [0, 10] s, no period: the mean over the second half [5, 10] s is 7.5 whatever the rows;
    the window began at the first row after the cut (here the last row: 10)."""
    for time in (np.array([0.0, 1.0, 2.0, 3.0, 10.0]), np.linspace(0.0, 10.0, 7), np.linspace(0.0, 10.0, 1001)):
        assert settled_mean(time, time.copy(), np.nan) == pytest.approx(7.5, rel=1e-14)


def test_settled_mean_over_whole_periods_of_a_sampled_oscillation():
    """s = 1 + sin(2 pi t / T) over 10.3 periods: the mean over the last whole periods of the second half is 1
    (exactly, for the trace's linear interpolant on rows that divide each period evenly from the cut)."""
    period = 0.7
    end = 10.3 * period
    for rows in (50, 233, 4001):
        time = np.linspace(0.0, end, rows)
        values = 1.0 + np.sin(2 * np.pi * time / period)
        fine = np.linspace(0.0, end, 200_001)
        want = settled_mean(fine, 1.0 + np.sin(2 * np.pi * fine / period), period)
        assert want == pytest.approx(1.0, abs=1e-9)
        step = end / (rows - 1)
        # the linear interpolant of a sine errs by ~(step/T)^2; the window's start no longer adds ~step/T
        assert settled_mean(time, values, period) == pytest.approx(1.0, abs=2.0 * (2 * np.pi * step / period) ** 2)
