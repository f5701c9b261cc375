"""Round 28, tester K's smaller API findings: each refused or read as the rest of the API does.

``fit_record`` takes the path of a record (``fit_steady`` and ``fit_stick`` take paths; a path was a raw
AttributeError), ``rsf_params`` reads values with their units (``dc="10 um"`` was "expected a number"), a protocol
segment beyond the float range is a ParameterError (was a raw OverflowError), and ``fit_steady`` given a DataFrame
says so in one line (its repr ran over many lines)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import stickslip
from stickslip import protocols
from stickslip.rsf import rsf_params, simulate
from stickslip.rsf.data import read_record
from stickslip.rsf.fit import fit_record

UM = 1e-6


def test_fit_record_reads_a_path_as_read_record_does(tmp_path) -> None:
    truth = rsf_params(0.010, 0.015, 10 * UM, v_ref=UM, stiffness=1600.0, mu0=0.6)
    t = np.arange(0.0, 40.0 + 1e-9, 0.25)
    run = simulate(truth, protocols.velocity_steps([1 * UM, 10 * UM], [20, 20]), times=t)
    noise = 1e-4 * np.random.default_rng(3).standard_normal(t.size)
    frame = pd.DataFrame(
        {
            "time [s]": t,
            "load_point_displacement [um]": run.load_point_displacement / UM,
            "friction": run.friction + noise,
        }
    )
    path = tmp_path / "record.csv"
    frame.to_csv(path, index=False)
    by_path = fit_record(path, fixed={"stiffness": 1600.0})
    by_record = fit_record(read_record(path), fixed={"stiffness": 1600.0})
    assert by_path.params.a == pytest.approx(by_record.params.a, rel=1e-12)
    assert by_path.params.a == pytest.approx(0.010, abs=5 * by_path.parameters["a"].stderr)  # the truth, within 5 se
    with pytest.raises(stickslip.ParameterError, match="record: expected a LabRecord or the path"):
        fit_record(None)


def test_rsf_params_reads_units() -> None:
    written = rsf_params(0.005, 0.01, "10 um", v_ref="1 um/s", stiffness="1e-3 1/um", eta="10 s/m")
    by_hand = rsf_params(0.005, 0.01, 10e-6, v_ref=1e-6, stiffness=1e3, eta=10.0)
    assert written.states[0].dc == pytest.approx(by_hand.states[0].dc, rel=1e-12)
    assert (written.v_ref, written.stiffness, written.eta) == pytest.approx((1e-6, 1e3, 10.0), rel=1e-12)
    with pytest.raises(stickslip.UnitError, match="dc: '10 um/s' has dimension"):
        rsf_params(0.005, 0.01, "10 um/s")


def test_a_segment_beyond_the_float_range_is_a_parameter_error() -> None:
    with pytest.raises(stickslip.ParameterError, match=r"segment velocity: .* beyond the range of a float"):
        protocols.constant(10**400, 1.0)


def test_fit_steady_given_a_frame_says_so_in_one_line() -> None:
    with pytest.raises(stickslip.DataError) as caught:
        stickslip.fit_steady(pd.DataFrame({"v": [1.0, 2.0], "s": [3.0, 4.0]}))
    assert "\n" not in str(caught.value) and "got a DataFrame" in str(caught.value)


@pytest.mark.parametrize(
    ("call", "words"),
    [
        (
            lambda p: stickslip.stick_phase(p, "50"),
            'pulling_velocity=50: a velocity needs a unit, e.g. pulling_velocity="50 um/s"',
        ),
        (lambda p: rsf_params(0.005, 0.01, "10"), 'dc=10: a length needs a unit, e.g. dc="10 um"'),
        (lambda p: stickslip.simulate(p, "50 um/s", "60"), "duration=60: a time needs a unit"),
    ],
)
def test_a_number_written_as_text_without_a_unit_is_refused_as_in_files(call, words) -> None:
    """Tester N: ``stick_phase(p, "50")`` ran at 50 m/s and ``rsf_params(..., "10")`` made Dc 10 m, without a word,
    while a quoted number without a unit in a parameter file, and a bare number on the command line, are refused."""
    with pytest.raises(stickslip.UnitError) as caught:
        call(stickslip.load_parameters("gelatin-glass"))
    assert words in str(caught.value)
    assert stickslip.stick_phase(stickslip.load_parameters("gelatin-glass"), "0").stuck  # zero needs no unit


def test_out_of_range_values_are_quoted_as_written() -> None:
    """Tester N: ``every="-10 ms"`` was refused as "got -0.01", ``dc="-10 um"`` as "got -1e-05"."""
    from stickslip.transient import run_transient

    gel = stickslip.load_parameters("gelatin-glass")
    with pytest.raises(stickslip.ParameterError, match="got '-10 ms'"):
        run_transient(gel, protocols.constant(1e-4, 1.0), every="-10 ms")
    with pytest.raises(stickslip.ParameterError, match="got '-3 kPa/m'"):
        run_transient(gel, protocols.constant(1e-4, 1.0), stiffness="-3 kPa/m")
    with pytest.raises(stickslip.ParameterError, match="got '-10 um'"):
        rsf_params(0.005, 0.01, "-10 um")


@pytest.mark.parametrize(
    ("text", "dimension", "literal"),
    [("10 um", "length", 10e-6), ("50 um/s", "velocity", 50e-6), ("1.6e-3 1/um", "per_length", 1.6e3),
     ("0.2 mm/s", "velocity", 0.2e-3), ("224 us", "time", 224e-6), ("300 1/um^2", "per_area", 300e12)],
)  # fmt: skip
def test_a_decimal_prefix_gives_the_literal_s_float(text, dimension, literal) -> None:
    """Tester N: "10 um" was 10 * 1e-6 = 9.999999999999999e-06, one float step from the literal 10e-6, so a call
    with units and its SI twin differed in the 15th digit; the prefix now shifts the written number's exponent."""
    from stickslip.units import to_si

    assert to_si(text, dimension) == literal
