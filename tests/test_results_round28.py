"""Round 28: results pickle and hold read-only columns, CSV numbers at 15 digits, messages that say what is so,
numbers beyond the float range refused by name, and the massless block with a dashpot in the stability analysis."""

from __future__ import annotations

import json
import math
import pickle
import re
from fractions import Fraction

import numpy as np
import pytest
from click.testing import CliRunner

import stickslip
from stickslip import protocols
from stickslip.cli.main import cli
from stickslip.errors import ParameterError
from stickslip.models import Run
from stickslip.numerics.roots import brentq
from stickslip.quasistatic.stick import stick_phase
from stickslip.transient.stability import critical_from_response, critical_stiffness_details, interface_response

#: tester J's own gel (/tmp/testerJ-work/mygel3.toml): not the paper's
MY_GEL = """
name = "pva3"
description = "my PVA-borax gel on glass, other units"

[bonds]
site_density = "300 1/um^2"
bond_time = "500000 ns"
breakage_weight = 0.8
chain_stiffness = "200 uN/m"
activation_length = "0.15 nm"
temperature = "24.85 degC"
max_extension = "0.8 um"

[aging]
aging_time = "2 ms"
aging_velocity = "0.5 mm/s"

[stick]
attached_chains = "9 1/um^2"
break_rate = "0.012 1/min"
aging_time = "8000 ms"

[block]
shear_modulus = "0.006 MPa"
height = "0.8 cm"
top_length = "40 mm"
base_length = "25 mm"
"""


@pytest.fixture(scope="module")
def paper():
    return stickslip.load_parameters("gelatin-glass")


@pytest.fixture(scope="module")
def qs_run():
    return stickslip.run("quasi-static", "gelatin-glass", protocols.constant(50e-6, 100.0))


# --- Q1: every quasi-static result pickles, and works after unpickling ------------------------------------------


def test_quasi_static_run_and_simulation_round_trip_through_pickle(qs_run, paper):
    back = pickle.loads(pickle.dumps(qs_run))
    for name in ("time", "stress", "slider_velocity", "slider_position", "load_point_position"):
        assert np.array_equal(getattr(back, name), getattr(qs_run, name)), name
    for name, values in qs_run.states.items():
        assert list(back.states[name]) == list(values), name
    assert back.regime == qs_run.regime and back.summary == qs_run.summary and back.mean == qs_run.mean
    sim = stickslip.simulate(paper, "50 um/s", "60 s")
    again = pickle.loads(pickle.dumps(sim))
    assert np.array_equal(again.time, sim.time) and np.array_equal(again.stress, sim.stress)
    assert again.regime == sim.regime and again.message == sim.message
    # the stick phases keep their dense solution: Nc/Nc0 between the samples is the same function after unpickling
    for stick, copy in zip(sim.stick_phases, again.stick_phases, strict=True):
        assert stick.stick_time == copy.stick_time
        for fraction in (0.1, 0.5, 0.93, 0.999):
            t = fraction * stick.end_time
            assert copy.chain_fraction_at(t) == stick.chain_fraction_at(t)
            assert 0.0 < copy.chain_fraction_at(t) < 1.0


def test_a_stick_phase_with_bounded_aging_pickles(paper):
    stick = stick_phase(paper, 10e-6, aging_cap=3.0)  # the bounded-aging extension: the other integrand
    copy = pickle.loads(pickle.dumps(stick))
    assert copy.status == stick.status == "slipped" and copy.stick_time == stick.stick_time
    t = 0.5 * stick.end_time
    assert copy.chain_fraction_at(t) == stick.chain_fraction_at(t)


# --- Q2: a Run's columns are read-only ---------------------------------------------------------------------------


def test_run_columns_are_read_only_and_the_callers_arrays_are_not(qs_run):
    for name in ("time", "stress", "slider_velocity", "slider_position", "load_point_position"):
        with pytest.raises(ValueError, match="read-only"):
            getattr(qs_run, name)[0] = 99.0
    with pytest.raises(ValueError, match="read-only"):
        qs_run.states["chain_fraction"][0] = 99.0
    copy = np.array(qs_run.time)  # a copy is the user's to change
    copy[0] = 99.0
    assert qs_run.time[0] == 0.0
    back = pickle.loads(pickle.dumps(qs_run))  # numpy's pickle gives writable arrays back: frozen again
    with pytest.raises(ValueError, match="read-only"):
        back.time[0] = 99.0
    with pytest.raises(ValueError, match="read-only"):
        back.states["chain_fraction"][0] = 99.0
    t = np.linspace(0.0, 10.0, 11)
    stress = 100.0 + t
    run = Run.from_trace("trace", t, stress=stress, slider_velocity=np.zeros(11), slider_position=np.zeros(11),
                         load_point_position=np.zeros(11))  # fmt: skip
    t[0] = -1.0  # the arrays given are still the caller's, writable
    stress[0] = 1.0
    with pytest.raises(ValueError, match="read-only"):
        run.stress[1] = 0.0


# --- Q3: CSV numbers at 15 significant digits --------------------------------------------------------------------


def _significant_digits(cell: str) -> int:
    mantissa = cell.lower().split("e")[0].lstrip("+-").replace(".", "").lstrip("0").rstrip("0")
    return max(len(mantissa), 1)


def test_curve_csv_writes_10_um_per_s_as_the_json_does(paper):
    runner = CliRunner()
    args = ["curve", "--velocity", "10 um/s", "--velocity", "350 um/s"]
    csv = runner.invoke(cli, [*args, "--format", "csv"])
    assert csv.exit_code == 0, csv.output
    rows = [line.split(",") for line in csv.output.splitlines()[1:]]
    assert rows[0][0] == "1e-05"  # not 0.000009999999999999999 (10 x 1e-6 is 1 ulp below 1e-5)
    document = json.loads(runner.invoke(cli, [*args, "--format", "json"]).output)
    api = stickslip.steady_state(paper, [1e-5, 350e-6])
    for k, name in enumerate(("velocity", "stress", "bonded_fraction", "stress_slope")):
        cells = [row[k] for row in rows]
        assert all(_significant_digits(c) <= 15 for c in cells), cells
        assert [float(c) for c in cells] == document[name]  # the same numbers as the JSON's
        np.testing.assert_allclose([float(c) for c in cells], getattr(api, name), rtol=1e-14)  # 15 digits: <= 5e-15


def test_run_csv_numbers_have_15_digits_and_read_back_within_5e_15(qs_run, tmp_path):
    path = tmp_path / "run.csv"
    qs_run.to_csv(path)
    lines = path.read_text().splitlines()[2:]
    cells = [c for line in lines for c in line.split(",") if re.fullmatch(r"[-+0-9.eE]+", c)]
    assert len(cells) > 1000
    assert max(_significant_digits(c) for c in cells) <= 15
    # each cell is the shortest text of its own float (as the JSON writes it; before: every digit, 16 or 17 of them)
    assert all(repr(float(c)) == c for c in cells)
    back = Run.read(path)
    for name in ("time", "stress", "slider_velocity", "slider_position", "load_point_position"):
        np.testing.assert_allclose(getattr(back, name), getattr(qs_run, name), rtol=1e-14, atol=0, err_msg=name)
    assert back.regime == qs_run.regime and back.period == qs_run.period


# --- Q4: the stuck hint of the time-dependent model is a suggestion ----------------------------------------------


def test_transient_stuck_message_suggests_the_stick_population(paper):
    from stickslip.transient.solver import run_transient

    result = run_transient(paper, protocols.constant(50e-6, 1.0))
    assert result.regime == "stuck"
    assert "run with --stick-population (with `run --model transient`: --setting stick_population=true;" in (
        result.message
    )
    assert "in Python: stick_population=True)" in result.message
    assert "stick_population=True (--stick-population) adds" not in result.message


# --- Q5: "the paper has no data" only for the paper's gel --------------------------------------------------------


def test_stuck_limitation_names_the_papers_data_only_for_the_papers_gel(paper, tmp_path):
    path = tmp_path / "mygel3.toml"
    path.write_text(MY_GEL)
    mine = stickslip.load_parameters(str(path))
    stuck = stick_phase(mine, "1 um/s", start_stress="100 Pa")
    assert stuck.status == "stuck"
    assert "limitation of Eq 15" in stuck.message and "the paper has no stick-slip data" not in stuck.message
    theirs = stick_phase(paper, "10 um/s")
    assert theirs.status == "stuck" and "the paper has no stick-slip data below 50 µm/s" in theirs.message


# --- Q6: a number beyond the float range is a ParameterError naming the argument ---------------------------------


@pytest.mark.parametrize("huge", [10**400, -(10**400), Fraction(10**400, 3)], ids=["1e400", "-1e400", "fraction"])
def test_numbers_beyond_the_float_range_are_refused_by_name(paper, huge):
    cases = {
        "pulling_velocity": lambda: stickslip.simulate(paper, huge, 10.0),
        "duration": lambda: stickslip.simulate(paper, 50e-6, huge),
        "start_stress": lambda: stickslip.simulate(paper, 50e-6, 10.0, start_stress=huge),
        "horizon": lambda: stick_phase(paper, 1e-4, horizon=huge),
        "aging_cap": lambda: stick_phase(paper, 1e-4, aging_cap=huge),
        "start_velocity": lambda: stickslip.slip_phase(paper, 1e-4, huge),
        "stress": lambda: stickslip.jump_velocity(paper, huge),
        "velocity": lambda: critical_stiffness_details(paper, huge),
        "damping": lambda: critical_stiffness_details(paper, 120e-6, damping=huge),
    }
    for name, call in cases.items():
        with pytest.raises(ParameterError, match=rf"^{name}: "):
            call()


# --- Q7: the massless block with a dashpot ------------------------------------------------------------------------

SIGMA, A, B, DC, V = 1e6, 0.01, 0.016, 10e-6, 20e-6


def test_massless_block_with_a_dashpot_matches_the_rsf_closed_form():
    """Z(s) = sigma s [a/V - b/(V + Dc s)] (one-state rate and state): eta s + K + Z(s) = 0 times (V + Dc s) is
    s^2 Dc (eta + sigma a/V) + s (eta V + K Dc - sigma (b - a)) + K V = 0: the Hopf point is
    Kc = (sigma (b - a) - eta V)/Dc, at w = (V/Dc) sqrt((b - a')/a'), a' = a + eta V/sigma."""
    rates = np.geomspace(1e-4, 1e6, 401)
    for eta in (0.0, 2e7, 1e8):  # Pa s/m: eta V/sigma = 0, 0.0004, 0.002 against b - a = 0.006
        found = critical_from_response(lambda s: SIGMA * s * (A / V - B / (V + DC * s)), rates, damping=eta)
        a_eff = A + eta * V / SIGMA
        assert found.mode == "oscillatory"
        assert found.value == pytest.approx((SIGMA * (B - A) - eta * V) / DC, rel=1e-7)
        assert found.rate == pytest.approx((V / DC) * math.sqrt((B - a_eff) / a_eff), rel=1e-6)


def test_bond_model_kc_with_a_dashpot_is_the_crossing_and_the_massless_limit(paper):
    """100 um/s, eta = 1e5 Pa s/m without a mass (tester K): Kc = -Re Z(iw) where eta w + Im Z(iw) = 0, found here
    by Brent on Z itself; and a mass of 1e-6 kg/m^2 adds m w^2 (~0.09 Pa/m) and nothing else."""
    v, eta = 100e-6, 1e5
    damped = critical_stiffness_details(paper, v, damping=eta)
    plain = critical_stiffness_details(paper, v)
    assert damped.mode == plain.mode == "oscillatory"

    def z(w: float) -> complex:
        return complex(interface_response(paper, v, np.array([1j * w])).z[0])

    w = brentq(lambda w: eta * w + z(w).imag, 0.8 * plain.rate, 1.1 * plain.rate, xtol=1e-10, rtol=1e-13)
    assert damped.rate == pytest.approx(w, rel=1e-7)
    assert damped.value == pytest.approx(-z(w).real, rel=1e-7)
    assert damped.value < plain.value * 0.995  # the dashpot lowers Kc (by 1.4 %) and the frequency
    light = critical_stiffness_details(paper, v, mass=1e-6, damping=eta)
    assert abs(light.value - damped.value) < 1e-8 * damped.value


def test_stability_says_a_damping_without_a_mass_is_a_massless_block_with_a_dashpot():
    result = CliRunner().invoke(cli, ["stability", "--v0", "100 um/s", "--damping", "100000 Pa s/m"])
    assert result.exit_code == 0, result.output
    assert "massless block with a dashpot" in result.output
    help_text = CliRunner().invoke(cli, ["stability", "--help"]).output
    assert "damping only with a mass" in help_text
