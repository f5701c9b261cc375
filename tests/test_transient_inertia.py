"""The time-dependent model through a block with mass and damping (issue 22 Q4; docs/extensions.md section 4).

Each number against something independent: a linear ODE solved by DOP853 at rtol 1e-13 (the Maxwell interface
that Eq 1 becomes for lambda = 0), the observed order of the trapezoid rule, the linear stability analysis of
transient/stability.py (its Hopf root with the block's mass).  The energy balance with a mass:
tests/test_transient.py::test_bookkeeping_bonds_and_energy.
"""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.integrate import solve_ivp
from scipy.signal import find_peaks

import stickslip
from cli_helpers import run_main
from stickslip.cli.main import cli
from stickslip.errors import ParameterError
from stickslip.models import Rig, get_model
from stickslip.protocols import constant, segments
from stickslip.transient import run_transient
from stickslip.transient.stability import critical_stiffness_details, hopf_root

GEL_MASS = 10.5  # kg/m^2: rho h of a 10 mm gelatin block (docs/extensions.md section 4)
RADIATION = 1025.0  # Pa s/m: G / (2 c_s)
SPRING = 3e8  # Pa/m: a stiff spring, so the block rings at ~4 kHz against the bonds


@pytest.fixture(scope="module")
def params():
    return stickslip.load_parameters("gelatin-glass")


@pytest.fixture(scope="module")
def maxwell(params):
    """lambda = 0, no aging, FENE out of reach: every bond a linear spring M e breaking at u0/tau.

    Then N(t) = N_inf (1 - e^{-ct}) from empty (c = (1 + u0)/tau), and the interface stress, the spring's stretch
    u = P - X and the velocity obey  s' = M N V - (u0/tau) s,  u' = Vp - V,  m V' = K u - eta V - s."""
    p = params.with_overrides({"bonds.activation_length": 0.0, "bonds.max_extension": 1.0})
    b = p.bonds
    rate, fill = b.breakage_weight / b.bond_time, (1 + b.breakage_weight) / b.bond_time
    n_inf = b.site_density / (1 + b.breakage_weight)
    pull, duration = 300e-6, 2e-3

    def reference(times):
        def rhs(t, y):
            s, u, v = y
            bonded = -n_inf * np.expm1(-fill * t)
            return [b.chain_stiffness * bonded * v - rate * s, pull - v, (SPRING * u - RADIATION * v - s) / GEL_MASS]

        # the block starts in balance: the spring carries the damping of the slider moving with the puller
        start = [0.0, RADIATION * pull / SPRING, pull]
        sol = solve_ivp(rhs, (0, duration), start, method="DOP853", rtol=1e-13, atol=1e-20, t_eval=times)
        return sol.y

    def run(**settings):
        return run_transient(p, constant(pull, duration), start="empty", aging=False, stiffness=SPRING,
                             mass=GEL_MASS, damping=RADIATION, every=duration / 50, **settings)  # fmt: skip

    def error(result):
        stress, stretch, velocity = reference(result.time)
        return max(
            np.max(np.abs(result.stress - stress)) / np.max(np.abs(stress)),
            np.max(np.abs(result.slider_velocity - velocity)) / pull,
            np.max(np.abs(result.puller_position - result.slider_position - stretch)) / np.max(stretch),
        )

    return run, error, duration


def test_block_with_mass_follows_the_maxwell_ode(maxwell):
    """The slider rings (V swings through zero) and the solution meets the ODE's; the error falls with rtol."""
    run, error, _ = maxwell
    coarse, fine = run(rtol=1e-5), run(rtol=1e-7)
    assert fine.slider_velocity.min() < 0 < fine.slider_velocity.max()  # the block's oscillation is resolved
    assert error(fine) < 1e-4
    assert error(fine) < 0.1 * error(coarse)


def test_fixed_steps_converge_at_second_order(maxwell):
    """The trapezoid rule for the block: the observed order is 2 (the population alone is fourth order)."""
    run, error, duration = maxwell
    errors = [error(run(rtol=0.1, max_step=duration / n)) for n in (1000, 2000, 4000)]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((orders > 1.9) & (orders < 2.1)), orders


def _growth(result, v0, after):
    """Growth rate (1/s) and frequency (Hz) of the slider's velocity peaks after time ``after``."""
    peaks, _ = find_peaks(result.slider_velocity - v0)
    late = peaks[result.time[peaks] > after]
    times, heights = result.time[late], result.slider_velocity[late] - v0
    return np.polyfit(times, np.log(heights), 1)[0], 1 / np.mean(np.diff(times)), heights


def test_heavy_block_grows_at_the_linear_hopf_rate(params):
    """1000 rho h at 120 um/s, K = 0.7 Kc(m): the nonlinear run grows at the linear Hopf root's rate (+2.81 1/s
    at 27.24 Hz, where the massless block at that K would decay, Kc = 1.31e8 Pa/m)."""
    v0, mass = 120e-6, 1000 * GEL_MASS
    kc = critical_stiffness_details(params, v0, True, mass, 0.0).value
    root = hopf_root(params, v0, 0.7, mass, 0.0, True)
    assert kc > 3 * critical_stiffness_details(params, v0, True, 0.0, 0.0).value  # the mass matters here
    kick = segments([(1.001 * v0, 2e-3), (v0, 0.25)])
    run = run_transient(params, kick, start="steady", start_velocity=v0, stiffness=0.7 * kc, mass=mass, rtol=1e-5)
    growth, frequency, _ = _growth(run, v0, 0.03)
    assert growth == pytest.approx(root.real, rel=0.01)
    assert frequency == pytest.approx(root.imag / (2 * np.pi), rel=1e-3)
    massless = run_transient(params, segments([(1.001 * v0, 2e-3), (v0, 0.1)]), start="steady",
                             start_velocity=v0, stiffness=0.7 * kc, rtol=1e-5)  # fmt: skip
    assert _growth(massless, v0, 0.01)[0] < 0  # stiffer than its own Kc: the oscillation dies


def test_massless_settings_are_the_paper_block(params):
    """mass = 0 (or None) is the massless block, bit for bit."""
    protocol = segments([(350e-6, 0.002), (200e-6, 0.003)])
    plain = run_transient(params, protocol, start="steady")
    zero = run_transient(params, protocol, start="steady", mass=0.0, damping=None)
    assert np.array_equal(plain.stress, zero.stress) and np.array_equal(plain.time, zero.time)
    assert zero.mass == 0.0


def test_model_interface_takes_the_rig_mass(params):
    protocol = segments([(350e-6, 0.002), (200e-6, 0.002)])
    rig = Rig(control="spring", mass=GEL_MASS, damping=RADIATION)
    run = get_model("transient").run(params, protocol, rig, start="steady")
    direct = run_transient(params, protocol, start="steady", mass=GEL_MASS, damping=RADIATION)
    assert run.native.mass == GEL_MASS and run.native.damping == RADIATION
    assert np.array_equal(run.native.stress, direct.stress)


@pytest.mark.parametrize(
    ("settings", "words"),
    [
        ({"damping": 100.0}, "damping only with a block mass"),
        ({"mass": -1.0}, "mass: expected a non-negative"),
        ({"mass": float("nan")}, "mass: expected a finite"),
        ({"mass": 1.0, "control": "velocity"}, "has no block"),
        ({"mass": 1.0, "stick_population": True}, "one or the other"),
    ],
)
def test_bad_block_settings_are_refused(params, settings, words):
    with pytest.raises(ParameterError, match=words):
        run_transient(params, constant(100e-6, 0.001), **settings)


def test_cli_block_mass_writes_a_trace_analyze_reads(tmp_path):
    out = tmp_path / "trace.csv"
    args = ["transient", "--v0", "350 um/s", "--duration", "3 ms", "--start", "steady", "--mass", "10.5 kg/m^2",
            "--damping", "1025 Pa s/m", "-o", str(out)]  # fmt: skip
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 0, result.output
    assert "block mass 10.5 kg/m², damping 1025 Pa·s/m" in result.output
    header = out.read_text().splitlines()[1]  # below the Run CSV's metadata line
    assert "slider_velocity" in header
    run = CliRunner().invoke(cli, ["run", "--model", "transient", "--v0", "350 um/s", "--duration", "3 ms",
                                   "--start", "steady", "--mass", "10.5 kg/m^2", "--json"])  # fmt: skip
    assert run.exit_code == 0, run.output


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--damping", "1025 Pa s/m"], "damping only with a block mass"),
        (["--mass", "10 kg"], "--mass"),
        (["--mass", "10.5 kg/m^2", "--control", "velocity"], "--mass: under --control velocity"),
    ],
)
def test_cli_bad_block_is_one_line_exit_2(capsys, args, words):
    code, out, err = run_main(capsys, "transient", "--v0", "100 um/s", "--duration", "1 ms", *args)
    assert code == 2 and out == ""
    assert words in err and "Traceback" not in err
    assert err.count("\n") == 1


def test_gel_block_departs_at_the_fastest_real_root(params):
    """50 um/s through the paper's block, where the massless Eq 1 has no fastest time scale (K + Z(inf) < 0):
    with the gel's mass a kicked steady state departs at the real root of m s^2 + K + Z(s) = 0 (3.89e4 1/s),
    measured between 6 and 9 e-folds (above the kick's start-up, below the nonlinearity)."""
    from stickslip.transient.stability import real_growth_rates

    v0, stiffness = 50e-6, params.block.effective_stiffness
    rate = real_growth_rates(params, v0, stiffness, mass=GEL_MASS).max()
    kick = segments([(v0 * (1 + 1e-6), 0.2 / rate), (v0, 9.5 / rate)])
    run = run_transient(params, kick, start="steady", start_velocity=v0, mass=GEL_MASS, rtol=1e-7)
    window = (run.time > 6 / rate) & (run.time < 9 / rate)
    growth = np.polyfit(run.time[window], np.log(np.abs(run.slider_velocity[window] - v0)), 1)[0]
    assert growth == pytest.approx(rate, rel=0.01)


def test_run_passes_the_rig_mass_to_every_model(capsys):
    """--mass is the one rig builder's: rate-and-state takes it (in its own units, through the normal stress)
    and says so in one line without one; the quasi-static model refuses it."""
    base = ["run", "--v0", "10 um/s", "--duration", "0.5 s", "--mass", "100 kg/m^2"]
    code, _, err = run_main(capsys, *base, "--model", "rsf")
    assert code == 2 and "rig mass" in err and "normal_stress" in err
    code, out, _ = run_main(capsys, *base, "--model", "rsf", "--set", "normal_stress=10 MPa", "--json")
    assert code == 0 and '"regime"' in out
    code, _, err = run_main(capsys, *base, "--model", "quasi-static")
    assert code == 2 and "mass (inertia) is not part of this model" in err


@pytest.mark.parametrize("mass", [GEL_MASS, 1.0])
def test_cost_estimate_counts_the_ringing_of_a_light_block(params, mass):
    """A block with mass rings at sqrt((K + N0 M)/m)/(2 pi) after every change of the protocol, lightly damped
    against resting bonds (a hold): the estimate counts it, within 0.5-10x of the steps taken, and grows as the
    block gets lighter (m^-1/2)."""
    from stickslip.transient.solver import estimate_cost

    protocol = segments([(200e-6, 0.01), (0.0, 0.05), (300e-6, 0.02)])
    run = run_transient(params, protocol, start="steady", mass=mass)
    estimate = estimate_cost(params, protocol, mass=mass, start="steady").steps
    assert 0.5 < estimate / run.steps < 10, (estimate, run.steps)
    lighter = estimate_cost(params, protocol, mass=mass / 100, start="steady").steps
    assert lighter > 5 * estimate


@pytest.mark.parametrize(
    ("ratio", "kind"), [(1.0, "stick-slip"), (1.05, "growing oscillation"), (0.95, "decaying oscillation")]
)
def test_an_oscillation_within_the_tolerance_is_not_judged(ratio, kind):
    """A block with mass rang against resting bonds at ~2 x the tolerance with ~4 steps a period and was read
    as growing, or as a limit cycle, while it decays: a swing below 10 x rtol x sigma is undetermined, in words;
    the same signal from a run 100 x tighter is judged."""
    from stickslip.transient.cycles import classify

    time = np.linspace(0.0, 0.02, 4001)
    swing = 0.5 * ratio ** (time / 1.6e-4 - 0.02 / 1.6e-4)  # Pa peak to trough at the end, 1.6e-4 s period
    stress = 2511.0 + 0.5 * swing * np.sin(2 * np.pi * time / 1.6e-4)
    velocity = np.full(time.size, 1e-7)
    protocol = constant(50e-6, 0.02)
    loose = classify(time, stress, velocity, protocol, (), [], "block", None, resolution=1e-4)
    assert loose[0] == "undetermined" and "within 10 × the solver's tolerance" in loose[1]
    tight = classify(time, stress, velocity, protocol, (), [], "block", None, resolution=1e-6)
    assert tight[0] == kind
