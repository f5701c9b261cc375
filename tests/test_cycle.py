"""Whole cycles: the issue's acceptance numbers, bookkeeping, regimes, truncation, bad input, properties.

Independent references: the issue's item 6 and the paper's Table 1 / Fig 5 numbers (stated tolerances),
steady_state evaluated directly (sigma(350 um/s), the stress on the trace), and bookkeeping identities
checked against a plain trapezoid integral of the velocity on the trace.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from stickslip.errors import ParameterError
from stickslip.parameters import load_parameters
from stickslip.quasistatic.cycle import CYCLE_COLUMNS, simulate
from stickslip.quasistatic.slip import slip_phase
from stickslip.quasistatic.steady import steady_state
from stickslip.quasistatic.stick import stick_phase


@pytest.fixture(scope="module")
def sim50(params):
    return simulate(params, 50e-6, 120.0)


@pytest.fixture(scope="module")
def sim100(params):
    return simulate(params, 100e-6, 120.0)


@pytest.fixture(scope="module")
def sim350(params):
    return simulate(params, 350e-6, 120.0)


# --- the numbers (item 6, Done when) ------------------------------------------------------------


def test_fifty_microns_per_second(sim50, critical):
    assert sim50.regime == "stick-slip"
    assert len(sim50.cycles) == 5  # period ~23.1 s in 120 s
    for c in sim50.cycles:
        assert c.start_stress == critical.stress
        assert c.stick_time == pytest.approx(19.3, abs=0.05)
        assert c.peak_stress == pytest.approx(553.0, abs=1.0)
        assert c.jump_velocity == pytest.approx(702e-6, abs=1e-6)  # Table 1: 702 um/s
        assert 1.0 < c.slip_time < 10.0  # "slip durations of a few seconds"
        assert c.period == pytest.approx(c.stick_time + c.slip_time, rel=1e-15)
    slip = sim50.slip_phases[0]
    assert slip.ends == "stick" and slip.end_velocity == pytest.approx(124e-6, abs=0.5e-6)  # Fig 5d


def test_hundred_microns_per_second(sim100):
    assert sim100.regime == "stick-slip"
    c = sim100.cycles[0]
    assert c.stick_time == pytest.approx(9.75, abs=0.01)
    assert c.peak_stress == pytest.approx(556.0, abs=1.0)
    assert 1.0 < c.slip_time < 10.0
    assert sim100.slip_phases[0].end_velocity == pytest.approx(124e-6, abs=0.5e-6)


def test_350_microns_per_second_ends_in_steady_sliding(sim350, params):
    assert sim350.regime == "steady"
    assert sim350.final_stress == pytest.approx(float(steady_state(params, 350e-6).stress), rel=1e-8)
    assert sim350.final_stress == pytest.approx(391.5, abs=0.05)
    assert sim350.final_velocity == 350e-6
    assert sim350.slip_phases[0].end_velocity == pytest.approx(350e-6, rel=1e-8)  # Fig 5d
    assert sim350.phase[-1] == "steady"
    assert len(sim350.cycles) == 1 and sim350.cycles[0].slip_time is None and sim350.cycles[0].period is None


def test_ten_microns_per_second_stays_stuck(params):
    sim = simulate(params, 10e-6, 200.0)
    assert sim.regime == "stuck" and not sim.cycles
    assert "stays stuck" in sim.message
    assert set(sim.phase) == {"stick"} and sim.time[-1] == 200.0
    assert np.all(sim.velocity == 0.0)


def test_unreachable_jump_is_undetermined(params):
    # at 20 um/s the chains hold until sigma_s ~ 1112 Pa, above the steady curve's maximum (~982 Pa)
    sim = simulate(params, 20e-6, 300.0)
    assert sim.regime == "undetermined"
    assert "no jump velocity" in sim.message
    assert not sim.cycles


# --- the trace's bookkeeping -------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["sim50", "sim100", "sim350"])
def test_bookkeeping(name, request):
    sim = request.getfixturevalue(name)
    assert sim.time[0] == 0.0 and sim.time[-1] == pytest.approx(sim.duration, rel=1e-15)
    assert np.all(np.diff(sim.time) >= 0.0)
    # the stress is continuous: rows at the same instant (the jumps) carry the same stress
    same = np.diff(sim.time) == 0.0
    assert np.any(same)
    assert np.allclose(sim.stress[1:][same], sim.stress[:-1][same], rtol=0, atol=1e-9)
    # puller = slider + block shear; the slider from an independent integral of V over the trace
    assert np.max(np.abs(sim.puller_displacement - sim.slider_displacement - sim.block_shear)) < 1e-12
    trapezoid = np.concatenate([[0.0], np.cumsum(0.5 * (sim.velocity[1:] + sim.velocity[:-1]) * np.diff(sim.time))])
    assert np.max(np.abs(trapezoid - sim.slider_displacement)) < 1e-4 * sim.slider_displacement[-1]
    assert np.allclose(sim.puller_displacement - sim.puller_displacement[0], sim.pulling_velocity * sim.time)
    assert np.allclose(sim.block_shear, sim.stress / sim.stiffness, rtol=1e-15)
    # chain fraction: fresh chains at each stick, none during slip and steady sliding
    assert np.all((sim.chain_fraction >= 0) & (sim.chain_fraction <= 1))
    assert np.all(sim.chain_fraction[sim.phase != "stick"] == 0.0)
    for column in CYCLE_COLUMNS[:-1]:
        assert np.all(np.isfinite(getattr(sim, column)))


def test_stress_on_the_trace_is_on_the_steady_curve_during_slip(sim50, params):
    slip = sim50.phase == "slip"
    assert np.max(np.abs(sim50.stress[slip] - steady_state(params, sim50.velocity[slip]).stress)) < 1e-8
    stick = sim50.phase == "stick"
    assert np.all(sim50.velocity[stick] == 0.0)


def test_cycles_repeat_exactly(sim50):
    period = sim50.cycles[0].period
    starts = np.array([c.start_time for c in sim50.cycles])
    assert np.allclose(starts, period * np.arange(len(starts)), rtol=1e-14, atol=1e-12)
    # the trace is periodic too (inside each period: a boundary row's time is the sum of the phases' times, within
    # rounding of k x period, on either side of it)
    edge = 1e-9 * period
    one = (sim50.time > edge) & (sim50.time < period - edge)
    two = (sim50.time > period + edge) & (sim50.time < 2 * period - edge)
    assert np.allclose(sim50.time[two] - period, sim50.time[one], rtol=0, atol=1e-12)
    assert np.allclose(sim50.stress[one], sim50.stress[two], rtol=1e-14)


def test_no_aging_jump_lands_off_the_aging_curve(params):
    """Eq 8 without aging puts Vs at ~751 um/s, where the aging curve (which the slip follows) carries
    ~18 Pa more than sigma_s: the stress must jump up, and the slider back by that over K."""
    sim = simulate(params, 50e-6, 30.0, jump_curve="no-aging")
    c = sim.cycles[0]
    assert c.jump_velocity == pytest.approx(751e-6, abs=1e-6)  # the issue: ~751 um/s
    rise = float(steady_state(params, c.jump_velocity).stress) - c.peak_stress
    assert rise > 1.0  # the aging curve lies above the no-aging one
    at_jump = np.nonzero(sim.time == c.stick_time)[0]
    assert sim.stress[at_jump[-1]] - sim.stress[at_jump[0]] == pytest.approx(rise, rel=1e-9)
    lurch = sim.slider_displacement[at_jump[-1]] - sim.slider_displacement[at_jump[0]]
    assert lurch == pytest.approx(-rise / sim.stiffness, rel=1e-9)
    assert np.max(np.abs(sim.puller_displacement - sim.slider_displacement - sim.block_shear)) < 1e-12


# --- truncation and start stress ---------------------------------------------------------------------------------


def test_run_ending_in_a_stick(params, critical):
    sim = simulate(params, 50e-6, 10.0)
    stick = stick_phase(params, 50e-6)
    assert sim.regime == "stick-slip" and not sim.cycles  # heading for stick-slip, no slip yet
    assert sim.final_stress == pytest.approx(critical.stress + sim.stiffness * 50e-6 * 10.0, rel=1e-14)
    assert sim.chain_fraction[-1] == pytest.approx(stick.chain_fraction_at(10.0), abs=1e-12)


def test_run_ending_in_a_slip(params):
    sim = simulate(params, 50e-6, 21.0)
    c = sim.cycles[0]
    assert c.slip_time is None and c.period is None  # the next stick has not begun
    slip = slip_phase(params, 50e-6, c.jump_velocity)
    v, s, _ = slip.at(21.0 - c.stick_time)
    assert sim.final_velocity == pytest.approx(v, rel=1e-12)
    assert sim.final_stress == pytest.approx(s, rel=1e-12)


def test_start_stress(params, critical):
    sim = simulate(params, 50e-6, 60.0, start_stress=400.0)
    first, second = sim.cycles[0], sim.cycles[1]
    assert first.start_stress == 400.0 and second.start_stress == critical.stress
    assert first.stick_time < second.stick_time
    assert sim.stress[0] == 400.0


def test_frame_summary_and_plot(sim50):
    frame = sim50.to_frame()
    assert tuple(frame.columns) == CYCLE_COLUMNS
    summary = sim50.summary()
    assert summary["regime"] == "stick-slip"
    assert set(summary["cycles"][0]) == {
        "start_time", "start_stress", "peak_stress", "stick_time", "jump_velocity", "slip_time", "period",
    }  # fmt: skip
    assert sim50.plot().get_lines()


def test_figures(sim50, sim100, sim350, params):
    from matplotlib.figure import Figure

    from stickslip.plots.cycles import figure_chain_fraction, figure_cycle_path, figure_cycles, figure_slip_velocity

    sims = [sim50, sim100, sim350]
    data = [(sim50.time, sim50.stress + 1.0), None, None]
    for fig in (
        figure_cycles(sims, data=data),
        figure_slip_velocity(sims),
        figure_chain_fraction([*sims, stick_phase(params, 10e-6, horizon=40.0)]),
        figure_cycle_path(params, sim50),
    ):
        assert isinstance(fig, Figure) and fig.axes
    with pytest.raises(ValueError, match="data entries"):
        figure_cycles(sims, data=[None])


# --- bad input ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("args", "kwargs", "word"),
    [
        ((-50e-6, 10.0), {}, "pulling_velocity"),
        ((50e-6, 0.0), {}, "duration"),
        ((50e-6, -1.0), {}, "duration"),
        ((50e-6, float("inf")), {}, "duration"),
        ((50e-6, 10.0), {"start_stress": -1.0}, "start_stress"),
        ((50e-6, 10.0), {"jump_curve": "fast"}, "jump curve"),
    ],
)
def test_bad_input(params, args, kwargs, word):
    with pytest.raises(ParameterError, match=word):
        simulate(params, *args, **kwargs)


def test_zero_stiffness_is_refused():
    with pytest.raises(ParameterError, match=r"block\.shear_modulus"):
        load_parameters(overrides={"block.shear_modulus": 0.0})


# --- properties -------------------------------------------------------------------------------------------------------


@settings(max_examples=10, deadline=None)
@given(v0=st.floats(min_value=35e-6, max_value=1e-3), modulus=st.floats(min_value=3e3, max_value=12e3))
def test_properties_over_velocity_and_stiffness(v0, modulus):
    p = load_parameters(overrides={"block.shear_modulus": modulus})
    sim = simulate(p, v0, 80.0)
    assert sim.regime in ("stick-slip", "steady", "stuck", "undetermined")
    assert np.all(np.diff(sim.time) >= 0) and sim.time[-1] == pytest.approx(80.0, rel=1e-14)
    assert np.max(np.abs(sim.puller_displacement - sim.slider_displacement - sim.block_shear)) < 1e-12
    same = np.diff(sim.time) == 0.0
    assert np.allclose(sim.stress[1:][same], sim.stress[:-1][same], rtol=0, atol=1e-9)
    vc = sim.critical_velocity
    if sim.regime == "steady":
        assert v0 >= vc
    if sim.regime == "stick-slip":
        assert v0 < vc
        for c in sim.cycles:
            assert c.jump_velocity > vc and c.peak_stress > c.start_stress
    for c in sim.cycles:  # sigma_s (Eq 16) and the stress on the curve at Vs
        assert c.peak_stress == pytest.approx(c.start_stress + sim.stiffness * v0 * c.stick_time, rel=1e-12)


def test_degenerate_cycle_under_constant_load_is_undetermined(params):
    # without aging in Eq 15 the chains at sigma_c break under the held load; sigma_s = sigma_c, so the
    # jump lands at Vc and the slip has no length: the model cannot say more
    slow_aging = params.with_overrides({"stick.aging_time": "1e6 s"})
    sim = simulate(slow_aging, 0.0, 300.0)
    assert sim.regime == "undetermined" and "degenerate" in sim.message
    # the trace stops where the model does: at the collapse
    stick = stick_phase(slow_aging, 0.0)
    assert sim.time[-1] == pytest.approx(stick.stick_time, rel=1e-14) and np.all(np.isfinite(sim.stress))


def test_too_many_cycles_are_refused(params):
    with pytest.raises(ParameterError, match="cycles"):
        simulate(params, 50e-6, 1e8)
