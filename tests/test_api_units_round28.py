"""The phases and the time-dependent solver read values with their units, as the rest of the API does (round 28:
``stick_phase``, ``slip_phase``, ``jump_velocity`` and ``run_transient``'s start velocity, stiffness, mass, damping,
max_step and max_time took numbers only).  The truth: the same call with the SI numbers written by hand."""

from __future__ import annotations

import pytest

import stickslip
from stickslip import jump_velocity, slip_phase, stick_phase
from stickslip.protocols import constant
from stickslip.transient import run_transient

GEL = stickslip.load_parameters("gelatin-glass")


def test_stick_phase_reads_velocity_stress_and_horizon_with_units() -> None:
    written = stick_phase(GEL, "50 um/s", start_stress="0.3 kPa", horizon="1 min")
    by_hand = stick_phase(GEL, 50e-6, start_stress=300.0, horizon=60.0)
    assert written.stick_time == pytest.approx(by_hand.stick_time, rel=1e-12)
    assert written.peak_stress == pytest.approx(by_hand.peak_stress, rel=1e-12)


def test_slip_phase_and_jump_velocity_read_units() -> None:
    assert slip_phase(GEL, "50 um/s", "1 mm/s").duration == pytest.approx(slip_phase(GEL, 50e-6, 1e-3).duration)
    assert jump_velocity(GEL, "0.6 kPa").velocity == pytest.approx(jump_velocity(GEL, 600.0).velocity, rel=1e-12)


@pytest.mark.parametrize(
    ("call", "error", "words"),
    [
        (lambda: stick_phase(GEL, "-5 um/s"), stickslip.ParameterError, "got '-5 um/s'"),
        (lambda: stick_phase(GEL, "5 kg"), stickslip.UnitError, "pulling_velocity: '5 kg' has dimension [mass]"),
        (lambda: jump_velocity(GEL, "5 um/s"), stickslip.UnitError, "expected a stress"),
        (lambda: slip_phase(GEL, "50 um/s", "-1 mm/s"), stickslip.ParameterError, "start_velocity"),
        (
            lambda: run_transient(GEL, constant(350e-6, 0.1), stiffness="3 kPa"),
            stickslip.UnitError,
            "stiffness: '3 kPa' has dimension",
        ),
    ],
)
def test_a_wrong_unit_or_range_is_refused_naming_the_argument(call, error, words) -> None:
    with pytest.raises(error) as caught:
        call()
    assert words in str(caught.value)


def test_run_transient_reads_its_settings_with_units() -> None:
    protocol = constant(350e-6, 0.2)
    written = run_transient(
        GEL, protocol, start="steady", start_velocity="0.4 mm/s", stiffness="300 kPa/m", every="10 ms",
        max_step="50 ms", max_time="1 min",
    )  # fmt: skip
    by_hand = run_transient(
        GEL, protocol, start="steady", start_velocity=4e-4, stiffness=3e5, every=0.01, max_step=0.05, max_time=60.0
    )
    assert written.stress[-1] == pytest.approx(by_hand.stress[-1], rel=1e-9)
    assert written.time.size == by_hand.time.size
    heavy = run_transient(GEL, constant(350e-6, 0.05), mass="10 kg/m^2", damping="1 kPa*s/m")
    assert heavy.stress[-1] == pytest.approx(
        run_transient(GEL, constant(350e-6, 0.05), mass=10.0, damping=1e3).stress[-1], rel=1e-9
    )
