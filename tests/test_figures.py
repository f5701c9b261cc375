"""Figures hold the data they claim to show (checked on the Axes' lines, not on pixels)."""

from __future__ import annotations

import numpy as np

from stickslip.plots.transient import plot_transient
from stickslip.transient.result import TransientResult


def _stick_slip_trace() -> TransientResult:
    """A synthetic block-control trace: slip at 700 um/s, a stick from 9.2 to 19 s (V = 0), slip again."""
    time = np.linspace(0.0, 25.0, 251)
    stuck = (time >= 9.2) & (time <= 19.0)
    velocity = np.where(stuck, 0.0, 700e-6 * np.exp(-((time - 20.0) ** 2)) + 3e-6)
    stress = 250.0 + 10.0 * time
    zeros = np.zeros_like(time)
    return TransientResult(time=time, stress=stress, bonded_fraction=zeros + 0.5, slider_velocity=velocity,
                           slider_position=np.cumsum(velocity), puller_position=50e-6 * time, regime="stick-slip",
                           cycles=(), message="synthetic", control="block", stiffness=1e8)  # fmt: skip


def test_transient_plot_draws_the_slider_at_rest_during_a_stick():
    result = _stick_slip_trace()
    ax = plot_transient(result)
    twin = next(other for other in ax.figure.axes if other is not ax)
    (line,) = twin.get_lines()
    t, v = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
    assert t.size == result.time.size  # no sample dropped
    stuck = (t >= 9.2) & (t <= 19.0)
    assert np.all(v[stuck] == 0.0)
    assert twin.get_ylim()[0] <= 0.0  # zero is on the axis, not below its bottom
    assert twin.get_yscale() == "symlog"
