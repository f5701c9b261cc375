"""Round 30 (tester W): a saturated friction sensor (a run of rows clipped at the record's maximum) is found and its
rows are left out of the fit as censored, so the intervals hold the truth (docs/rsf.md, "A saturated sensor")."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from stickslip.rsf.data import LabRecord
from stickslip.rsf.fit import fit_record
from stickslip.rsf.saturation import find_saturation

TRUTH = {"a": 0.008, "b": 0.012, "dc": 5e-6, "stiffness": 5000.0}
SEGMENTS = [(2e-6, 10.0), (20e-6, 8.0), (2e-6, 12.0)]


def _spring_slider(t: np.ndarray, mu0: float = 0.6) -> np.ndarray:
    """Aging-law spring-slider friction at ``t`` (scipy Radau, independent of stickslip's solver), steady at first."""
    a, b, dc, k = TRUTH["a"], TRUTH["b"], TRUTH["dc"], TRUTH["stiffness"]
    v0 = SEGMENTS[0][0]

    def rhs(_: float, y: np.ndarray, vlp: float) -> list[float]:
        v = v0 * np.exp((y[0] - mu0 - b * y[1]) / a)
        return [k * (vlp - v), (v0 * np.exp(-y[1]) - v) / dc]

    out, y, start = np.empty(t.size), [mu0, 0.0], 0.0
    for i, (vlp, duration) in enumerate(SEGMENTS):
        end = start + duration
        rows = (t >= start - 1e-12) & ((t < end - 1e-12) if i < len(SEGMENTS) - 1 else np.ones(t.size, bool))
        run = solve_ivp(rhs, (start, end), y, args=(vlp,), method="Radau", dense_output=True, rtol=1e-10, atol=1e-13)
        out[rows] = run.sol(np.clip(t[rows], start, end))[0]
        y, start = run.y[:, -1], end
    return out


def _clipped_record(seed: int, clip: float = 0.605) -> tuple[LabRecord, int]:
    """1 kHz, AR(1) noise (sd 2e-4, phi 0.9), a drift 1e-5 / s, friction written to 5 decimals and clipped at
    ``clip``: the record and its rows at the clip."""
    rng = np.random.default_rng(seed)
    t = np.arange(30001) / 1000.0
    noise = np.empty(t.size)
    noise[0] = rng.standard_normal() * 2e-4
    shocks = rng.standard_normal(t.size) * 2e-4 * np.sqrt(1 - 0.81)
    for i in range(1, t.size):
        noise[i] = 0.9 * noise[i - 1] + shocks[i]
    mu = np.minimum(np.round(_spring_slider(t) + noise + 1e-5 * t, 5), clip)
    edges = np.cumsum([0.0] + [d for _, d in SEGMENTS])
    x = sum(v * np.clip(t - edges[i], 0.0, d) for i, (v, d) in enumerate(SEGMENTS))
    x = np.round((x + 2e-8 * rng.standard_normal(t.size)) * 1e8) / 1e8
    return LabRecord.from_arrays(t, x, mu, source=f"clipped{seed}", length_unit="um"), int(np.sum(mu == clip))


@pytest.fixture(scope="module")
def clipped() -> tuple[LabRecord, int]:
    return _clipped_record(1)


def test_clipped_run_found_not_on_a_quantised_steady_record(clipped: tuple[LabRecord, int]) -> None:
    record, flat = clipped
    assert flat > 200  # (the clip cuts the peak after the step up)
    found = find_saturation(record.friction)
    assert found is not None and found.side == "maximum" and found.level == pytest.approx(0.605)
    assert int(found.at.sum()) == flat
    # a noise-free record written to 4 decimals: its steady stretches read one value each, the last (the record's
    # minimum, velocity weakening after a step up) 9 times longer than the first: no saturation
    t = np.arange(20001) / 1000.0
    steady = np.where(t < 2.0, 0.6, 0.6 - 0.004 * np.log(10) * (1 - np.exp(-(t - 2.0) / 0.3)))
    quantised = np.round(np.where(t < 2.0, 0.6, steady + 0.018 * np.exp(-(t - 2.0) / 0.05)), 4)
    assert np.sum(quantised == quantised.min()) > 10 * np.sum(t < 2.0) / 2
    assert find_saturation(quantised) is None
    # the same noisy record without its clip: none
    assert find_saturation(np.round(record.friction + 0.0, 5)[: int(np.argmax(record.friction >= 0.605)) - 50]) is None


def test_clipped_record_fit_leaves_the_run_out_and_holds_the_truth(clipped: tuple[LabRecord, int]) -> None:
    record, flat = clipped
    fit = fit_record(record, trend="time", alternatives=False, drift_check=False)
    said = [n for n in fit.notes if "saturated friction sensor" in n]
    assert said and "censored" in said[0] and "0.605" in said[0]
    assert len(fit.record) <= len(record) - flat  # the rows at the clip (and any the model puts near it) left out
    assert not np.any(fit.record.friction >= 0.605)
    assert fit.status == "ok" and fit.reduced_chi_square < 1.5
    for key, value in TRUTH.items():  # (the clipped rows fitted: a 0.00647 [0.00603, 0.00690], all four missed)
        lo, hi = fit.parameters[key].interval
        assert lo <= value <= hi, (key, value, lo, hi)
