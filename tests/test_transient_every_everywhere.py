"""``every`` never changes the integration, whatever the control (docs/transient.md section 19).

Until 2026-12 only a run with the stick chains through the massless block was integrated as without ``every`` and
sampled afterwards; every other run (velocity control, a block with mass, Eq 1 through the block) took a step at
each sampling instant, so ``every`` moved its steps and its summary (a slide-hold-slide under velocity control:
peak 3.55981e6 / 3.55959e6 Pa, trough 6.12102 / 6.12381 Pa, mean 500.205 / 500.356 Pa without / with every 1 ms;
3339 against 4185 steps).  Now every run is integrated as without it and its rows are sampled onto the grid
(transient/sampling.py): the steps and the regime are the unsampled run's to the bit, the extremes, means and cycles
to rounding (ROUNDING below), and the sampled rows agree with a run that lands a step on each grid instant
(``solver.SAMPLED_AFTER = False``) at a tenth of the tolerance to within a few times the tolerance (mostly a tenth of
it).  The interpolants are checked against rows of closed-form solutions.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import stickslip.transient.solver as solver
from stickslip.models.transient import transient_run
from stickslip.parameters import load_parameters
from stickslip.protocols import Protocol, Segment
from stickslip.transient import run_transient
from stickslip.transient.sampling import Sampler
from stickslip.transient.solver import _balanced_integral, estimate_cost

GEL = load_parameters()

#: (protocol, settings, every): a slide-hold-slide and a velocity step under velocity control (the step's boundary
#: between grid points: the last segment's window starts between two of them), a block with mass kicked, and a
#: steady start through the massless block stepped down (Eq 1 alone, the cohorts throughout)
CASES = {
    "slide-hold-slide": (
        Protocol((Segment(100e-6, 2e-3), Segment(0.0, 0.1), Segment(100e-6, 5e-3))),
        dict(control="velocity", start="steady", rtol=1e-3),
        1e-3,
    ),
    "velocity step": (
        Protocol((Segment(350e-6, 0.02), Segment(1e-3, 0.02))),
        dict(control="velocity", start="steady"),
        3e-3,
    ),
    "mass": (
        Protocol((Segment(360e-6, 2e-3), Segment(350e-6, 2e-3))),
        dict(start="steady", start_velocity=350e-6, mass=1.0, damping=10.0, rtol=1e-3),
        1e-4,
    ),
    "spring": (
        Protocol((Segment(350e-6, 0.02), Segment(100e-6, 0.02))),
        dict(start="steady", rtol=1e-3, reduction="off"),
        1e-3,
    ),
}


def _summary(result, protocol):  # type: ignore[no-untyped-def]
    """What a summary reports: the steps, the regime and its evidence's numbers, the means and extremes, the cycles
    and the end state (the verdict's words aside: they quote spans of the rows)."""
    run = transient_run(result, protocol)
    regime = run.regime
    numbers = {key: value for key, value in run.summary.items() if isinstance(value, (int, float))}
    return {
        "steps": (result.steps, result.rejected),
        "regime": (str(result.regime), regime.kind, regime.periods),
        "evidence": (regime.peak, regime.trough),
        "summary": numbers,
        "mean": run.mean,
        "cycles": [dataclasses.asdict(c) for c in result.cycles],
        "end": [float(getattr(result, name)[-1]) for name in ("time", "stress", "slider_position", "slider_velocity")],
        "extremes": (float(np.max(result.highest_stress)), float(np.min(result.lowest_stress))),
    }


#: how far a summary's float may be from the unsampled run's: rounding.  A window's mean reads the solver's integral
#: at the window's start between rows, and the rows differ (the grid's against the steps'), so the two trapezoids
#: agree to rounding, not to the bit: 653.4311608094694 against 653.4311608094696 Pa (1 ulp) on an AMD EPYC host with
#: AVX2 on 2026-12-02, where another host gave the same bits.  The defect was 3e-4 apart (the module's docstring).
ROUNDING = 1e-13


def _same(a, b) -> bool:  # type: ignore[no-untyped-def]
    """Equal to rounding (nan where nan; integers and strings exactly)."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and math.isnan(a):
        return isinstance(b, float) and math.isnan(b)
    if isinstance(a, float) and isinstance(b, float):
        return math.isclose(a, b, rel_tol=ROUNDING, abs_tol=0.0)
    return a == b


@pytest.fixture(scope="module")
def runs():  # type: ignore[no-untyped-def]
    """Each case unsampled, sampled, and landing a step on each grid instant at a tenth of the tolerance."""
    out = {}
    for name, (protocol, settings, every) in CASES.items():
        plain = run_transient(GEL, protocol, **settings)
        sampled = run_transient(GEL, protocol, every=every, **settings)
        solver.SAMPLED_AFTER = False
        try:
            tighter = dict(settings, rtol=settings.get("rtol", solver.RTOL) / 10)
            landed = run_transient(GEL, protocol, every=every, **tighter)
        finally:
            solver.SAMPLED_AFTER = True
        out[name] = plain, sampled, landed
    return out


@pytest.mark.parametrize("name", list(CASES))
def test_every_changes_neither_the_steps_nor_the_summary(runs, name):
    plain, sampled, _ = runs[name]
    protocol, _, every = CASES[name]
    assert plain.status == sampled.status == "ok"
    mine, theirs = _summary(sampled, protocol), _summary(plain, protocol)
    for key in mine:
        assert _same(mine[key], theirs[key]), (key, mine[key], theirs[key])
    # an oscillation's period and amplitude ratio, which the classifier reads off the rows (regimes.classify places
    # each turn by the rows around it): the block with mass rings at 3.7 kHz, 2.66704e-4 s sampled every 0.1 ms
    # against 2.66501e-4 s read at every step; every other case the same to the bit
    reading = [(run.evidence.period, run.evidence.amplitude_ratio) for run in (sampled, plain)]
    if name == "mass":
        assert reading[0] == pytest.approx(reading[1], rel=1e-3)
    else:
        assert _same(reading[0], reading[1])
    # the rows: the grid, and the protocol's boundaries (a window starts at one)
    grid = every * np.arange(math.floor(protocol.duration / every + 1e-9) + 1)
    expected = np.union1d(grid, protocol.boundaries)
    expected = expected[np.r_[True, np.diff(expected) > 1e-9 * every]]
    assert sampled.time.size == expected.size and np.max(np.abs(sampled.time - expected)) < 1e-9 * every


#: the sampled rows against the landed run (a tenth of the tolerance), of the largest value (N/N0: absolute), in
#: units of the sampled run's tolerance.  Measured: stress 1e-4 (spring) to 0.095 (slide-hold-slide), position
#: below 1e-10 under velocity control, 0.009 and 0.03 through the spring and with a mass, velocity 0, 0.013 and 2.4
#: (the block rings at 3.7 kHz; the landing run at the sampled run's own tolerance is 20 off), N/N0 1.6e-4 to 0.054
BOUNDS = {"stress": 0.5, "slider_position": 0.5, "slider_velocity": 5.0, "bonded_fraction": 0.5}


@pytest.mark.parametrize("name", list(CASES))
def test_sampled_rows_agree_with_steps_landed_on_the_grid(runs, name):
    _, sampled, landed = runs[name]
    rtol = CASES[name][1].get("rtol", solver.RTOL)
    assert landed.steps > sampled.steps  # (the landed run: a tighter tolerance and a step at each grid instant)
    common, mine, theirs = np.intersect1d(sampled.time, landed.time, return_indices=True)
    assert common.size >= 0.9 * sampled.time.size
    for column, bound in BOUNDS.items():
        a, b = getattr(sampled, column)[mine], getattr(landed, column)[theirs]
        scale = 1.0 if column == "bonded_fraction" else float(np.max(np.abs(b)))
        assert np.max(np.abs(a - b)) <= bound * rtol * scale, column


def test_a_sampled_stress_between_rows_whose_rate_no_row_carries():
    """Velocity control: the rows of sigma = 500 + 100 sin(w t) Pa (w = 2 pi/s), 0.04 and 0.06 s apart in turn, with
    the integral of sigma dt.  Away from a turn the sampled stress is within the remainder bound of the cubic
    through four rows (A w^4 max|prod(t - t_j)|/4!, 0.029 Pa; a line between rows errs by up to 1.76 Pa); at a
    turn it stays within its two rows, so by at most their own distance from the turn, A (1 - cos(w h/2))."""
    amplitude, w, vp = 100.0, 2 * math.pi, 1e-4
    times = np.r_[0.0, np.cumsum(np.tile([0.04, 0.06], 20))]
    rows = _rows(times, 500.0 + amplitude * np.sin(w * times), vp)
    rows[:, 13] = 500.0 * times - amplitude / w * (np.cos(w * times) - 1.0)
    grid = np.linspace(0.0, times[-1], 401)
    sampler = Sampler(grid, 3e5, control="velocity", breaks=())
    for chunk in np.array_split(rows, 5):  # (fed in blocks, as the solver's calls give them)
        sampler.feed(chunk)
    sampler.flush()
    got = np.vstack(sampler.rows())
    assert np.array_equal(got[:, 0], grid)
    error = np.abs(got[:, 1] - (500.0 + amplitude * np.sin(w * grid)))
    right = np.clip(np.searchsorted(times, grid, side="left"), 1, times.size - 1)
    turn = np.zeros(grid.size, dtype=bool)
    for when in (0.25, 0.75, 1.25, 1.75):
        turn |= (times[right - 1] < when) & (when < times[right])
    inner = (grid > times[2]) & (grid < times[-3])  # (next to the ends, a parabola through three rows)
    assert np.max(error[inner & ~turn]) <= amplitude * w**4 / 24 * _widest([0.0, 0.04, 0.1, 0.14])
    assert np.max(error[turn]) <= amplitude * (1.0 - math.cos(w * 0.06 / 2))
    low = np.minimum(rows[right - 1, 1], rows[right, 1])
    high = np.maximum(rows[right - 1, 1], rows[right, 1])
    assert np.all(got[:, 1] >= low) and np.all(got[:, 1] <= high)
    assert np.allclose(got[:, 4], vp * grid, rtol=1e-13, atol=0.0)  # the slider moves with the protocol
    assert np.all(got[:, 3] == vp) and np.all(got[:, 11] == 0.0)  # its velocity; no block


def test_a_relaxing_stress_between_rows_and_its_integral():
    """A hold under velocity control: sigma = 800 exp(-t/0.3) Pa relaxing, rows 0.02, 0.05 and 0.03 s apart in
    turn, with its integral.  The sampled stress within the remainder bound of the cubic through four rows
    (relative: max|prod(t - t_j)|/(4! tau^4)); the integral of sigma dt, whose rate (sigma) each row carries, within
    the cubic Hermite bound h^4 max|d4/dt4|/384."""
    tau = 0.3
    times = np.r_[0.0, np.cumsum(np.tile([0.02, 0.05, 0.03], 10))]
    rows = _rows(times, 800.0 * np.exp(-times / tau), 0.0)
    rows[:, 13] = 800.0 * tau * (1.0 - np.exp(-times / tau))
    grid = np.linspace(0.0, times[-1], 101)
    sampler = Sampler(grid, 3e5, control="velocity", breaks=())
    sampler.feed(rows)
    sampler.flush()
    got = np.vstack(sampler.rows())
    inner = (grid > times[2]) & (grid < times[-3])
    widest = max(_widest(s) for s in ([0.0, 0.02, 0.07, 0.1], [0.0, 0.05, 0.08, 0.1], [0.0, 0.03, 0.05, 0.1]))
    truth = 800.0 * np.exp(-grid / tau)
    assert np.max(np.abs(got[inner, 1] / truth[inner] - 1.0)) <= widest / (24 * tau**4)
    integral = 800.0 * tau * (1.0 - np.exp(-grid / tau))
    assert np.max(np.abs(got[:, 13] - integral)) <= 0.05**4 / 384 * 800.0 / tau**3


def test_a_ringing_block_with_mass_is_sampled_by_its_own_rates():
    """A block with mass m on a spring K, the interface's stress constant (sigma_c): X = Vp t - sigma_c/K +
    A sin(w t), w^2 = K/m, the puller at Vp t; rows 8 a period.  The slider's position and velocity, interpolated
    with their rates (V, and (K (P - X) - sigma)/m, from the row's own columns), within the cubic Hermite bound
    h^4 max|d4/dt4|/384: A w^4 h^4/384 and A w^5 h^4/384."""
    k, mass, vp, sigma_c, amplitude = 3e5, 1.0, 350e-6, 390.0, 2e-7
    w = math.sqrt(k / mass)
    times = np.linspace(0.0, 6 * 2 * math.pi / w, 49)
    h = times[1] - times[0]
    rows = _rows(times, np.full(times.size, sigma_c), vp)
    rows[:, 4] = vp * times - sigma_c / k + amplitude * np.sin(w * times)
    rows[:, 3] = vp + amplitude * w * np.cos(w * times)
    rows[:, 11] = 0.5 * k * (rows[:, 5] - rows[:, 4]) ** 2 + 0.5 * mass * rows[:, 3] ** 2
    rows[:, 13] = sigma_c * times
    grid = np.linspace(0.0, times[-1], 301)
    sampler = Sampler(grid, k, mass=mass, breaks=())
    sampler.feed(rows)
    sampler.flush()
    got = np.vstack(sampler.rows())
    x = vp * grid - sigma_c / k + amplitude * np.sin(w * grid)
    v = vp + amplitude * w * np.cos(w * grid)
    assert np.max(np.abs(got[:, 4] - x)) <= amplitude * (w * h) ** 4 / 384
    assert np.max(np.abs(got[:, 3] - v)) <= amplitude * w * (w * h) ** 4 / 384
    assert np.allclose(got[:, 1], sigma_c, rtol=1e-12, atol=0.0)
    energy = 0.5 * k * (vp * grid - got[:, 4]) ** 2 + 0.5 * mass * got[:, 3] ** 2  # the spring's and the block's
    assert np.allclose(got[:, 11], energy, rtol=1e-9, atol=0.0)


def _widest(stencil) -> float:  # type: ignore[no-untyped-def]
    """max |prod(t - t_j)| between the stencil's middle two points (the cubic's remainder without f''''/4!)."""
    nodes = np.asarray(stencil, dtype=float)
    between = np.linspace(nodes[1], nodes[2], 601)
    return float(np.max(np.abs(np.prod(between[:, None] - nodes[None, :], axis=1))))


def test_the_energy_balance_in_blocks_is_the_whole_traces():
    """Velocity control: the integral of sigma dt from the energy balance (solver._balanced_integral), applied to the
    rows a block at a time as they are sampled, equals it applied to the whole trace at once, to the bit."""
    protocol = Protocol((Segment(100e-6, 1.0), Segment(0.0, 0.5), Segment(300e-6, 1.0)))
    rng = np.random.default_rng(11)
    times = np.unique(np.r_[protocol.boundaries, rng.uniform(0.0, 2.5, 300)])
    table = np.full((times.size, 19), np.nan)
    table[:, 0] = times
    table[:, 10] = np.cumsum(rng.uniform(0.0, 1e-3, times.size))  # the bonds' energy, rising
    table[:, 9] = np.cumsum(rng.uniform(0.0, 1e-9, times.size))  # hardly any lost
    table[:, 13] = np.cumsum(rng.uniform(0.0, 1.0, times.size))  # the solver's integral
    table[:, 8] = np.cumsum(rng.uniform(0.0, 1e-4, times.size))
    whole = table.copy()
    _balanced_integral(whole, protocol)
    assert not np.array_equal(whole[:, 13], table[:, 13])
    blocks, carried, last = [], (0.0, 0.0), None
    for part in np.array_split(table, 7):
        block = part.copy() if last is None else np.vstack([last, part])
        carried = _balanced_integral(block, protocol, carried)
        blocks.append(block if last is None else block[1:])
        last = part[-1:].copy()
    assert np.array_equal(np.vstack(blocks)[:, [8, 13]], whole[:, [8, 13]])


def test_a_sampling_instant_costs_no_step_in_the_estimate():
    """A hold under velocity control sampled every 0.1 ms: each instant was a step that worked through the cohorts
    the hold keeps (10 s held every 0.1 ms estimated at 27 min); now the rows are sampled after the steps."""
    hold = Protocol((Segment(100e-6, 2e-3), Segment(0.0, 10.0), Segment(100e-6, 15e-3)))
    plain = estimate_cost(GEL, hold, control="velocity", start="steady")
    sampled = estimate_cost(GEL, hold, control="velocity", start="steady", every=1e-4)
    assert sampled.steps == plain.steps
    rows = hold.duration / 1e-4
    assert sampled.seconds - plain.seconds == pytest.approx(rows * solver.SAMPLE_SECONDS, rel=1e-9)


def _rows(times: np.ndarray, sigma: np.ndarray, vp: float) -> np.ndarray:
    """Trace rows (solver._row's columns) of a slider moved at vp with the given stress, each its own extremes."""
    rows = np.full((times.size, 19), np.nan)
    rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3] = times, sigma, 1.0, vp
    rows[:, 4] = rows[:, 5] = vp * times
    rows[:, 6:11] = 0.0
    rows[:, 11] = 0.0
    rows[:, 13] = 0.0
    rows[:, 14], rows[:, 15], rows[:, 16], rows[:, 17], rows[:, 18] = sigma, sigma, times, times, vp
    return rows
