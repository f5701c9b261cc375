"""A limit cycle with two maxima per period (a slip that rings) is stick-slip with the whole period, not an
'undetermined' oscillation at the ringing's spacing (found by notebook 05: rate-and-state with a mass)."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip.regimes import STICK_SLIP, classify

PERIOD = 2.0  # s: the signals' own period, the truth the classifier must find


def ringing_sawtooth(t: np.ndarray, decay: float = np.inf) -> np.ndarray:
    """A stick (linear rise over the period), a drop, and a ringing bump after it: two maxima per period."""
    phase = np.mod(t, PERIOD)
    ring = np.where(phase < 0.2, 0.4 * np.exp(-phase / 0.15) * np.sin(np.pi * phase / 0.2) ** 2, 0.0)
    return (phase / PERIOD + ring) * np.exp(-t / decay)


@pytest.mark.parametrize("step", [1e-3, 7e-4])
def test_two_maxima_per_period_is_a_limit_cycle_of_the_whole_period(step):
    t = np.arange(0.0, 12.5 * PERIOD, step)
    regime = classify(t, ringing_sawtooth(t), floor=1e-9)
    assert regime.kind == STICK_SLIP, regime.evidence
    assert regime.period == pytest.approx(PERIOD, rel=2e-3)
    assert "2 maxima per period" in regime.evidence
    assert regime.peak == pytest.approx(1.0, abs=2e-3) and regime.trough == pytest.approx(0.0, abs=2e-3)


def test_a_decaying_two_peak_oscillation_is_not_a_limit_cycle():
    t = np.arange(0.0, 12 * PERIOD, 1e-3)
    regime = classify(t, ringing_sawtooth(t, decay=10.0), floor=1e-9)
    assert regime.kind != STICK_SLIP, regime.evidence


def test_a_rate_and_state_slider_with_mass_that_rings_after_each_slip():
    """The notebook's case: its main peaks (scipy's find_peaks, an independent reading) repeat every ~0.321 s."""
    from scipy.signal import find_peaks

    import stickslip
    from stickslip import protocols
    from stickslip.models import Rig

    spec = {"mu0": 0.5, "v_ref": 1e-3, "a": 0.005, "b": 0.015, "dc": "100 um", "normal_stress": 1e3}
    params = stickslip.get_model("rsf").parameters(None, spec)
    run = stickslip.run("rsf", params, protocols.constant(0.03, 2.0), Rig(stiffness=1e4, damping=100.0, mass=1.0),
                        start=0.033)  # fmt: skip
    main, _ = find_peaks(run.stress, prominence=20.0)
    assert run.regime.kind == STICK_SLIP, run.regime.evidence
    assert run.regime.period == pytest.approx(float(np.diff(run.time[main])[-1]), rel=5e-3)
