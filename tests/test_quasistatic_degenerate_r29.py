"""Round 29, the quasi-static cycle (tester R): (A) a stick whose σs is σc to the steady curve's resolution is a
degenerate cycle at every stiffness, whatever length the root finder gives its slip; (B) an undetermined run whose
collapse comes after its end says so, and stays ``ok``, while one that reaches its collapse within the run fails."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import exp1

from cli_helpers import run_main
from stickslip import load_parameters
from stickslip.quasistatic.critical import NOISE, cached_critical_point, steady_curve_key
from stickslip.quasistatic.cycle import simulate
from stickslip.sweeps.models import get_model, run_point

DENSE = 1e15  # bonds.site_density, m^-2: σc = 2109.5 Pa, which the paper's stick chains hold for 3.17 ns alone
BLOCK_STIFFNESSES = (40e3, 400e3, 4e6)  # block.stiffness (G_d/h), Pa/m: tester R's three
V0 = 50e-6


def _dense(stiffness: float):
    return load_parameters("gelatin-glass").with_overrides({"bonds.site_density": DENSE, "block.stiffness": stiffness})


def test_a_stick_that_never_leaves_sigma_c_is_degenerate_at_every_stiffness():
    # before: 40 kPa/m was failed/degenerate, 400 kPa/m and 4 MPa/m raised "100 s holds 1.88e+10 cycles ... give a
    # shorter duration" (their root finder put the jump 4e-6 and 1.2e-5 above Vc, a 2.1 ns slip)
    times = []
    for stiffness in BLOCK_STIFFNESSES:
        params = _dense(stiffness)
        sim = simulate(params, V0, 100.0)
        assert sim.regime == "undetermined" and sim.status == "failed", (stiffness, sim.message)
        assert sim.message.startswith("degenerate cycle: the chains collapse after")
        # round 29b: a cycle that short (3.17 ns, under the bonds' memory Δl_m/Vc = 8.65 ms) is outside the model,
        # which the message says in place of the stress rule's "creep by infinitesimal slips"
        assert "outside the model" in sim.message and "shorter duration" not in sim.message
        # the stick of Eq 15 under a load that hardly rises: its collapse is the constant-load lifetime of fresh
        # chains at σc, E1(s0)/r with s0 = (λ/kT) σc/Nc0 (dn/dt = -r n e^(s0/n): t = ∫ e^(-s0/n) dn/(r n))
        sigma_c = float(cached_critical_point(steady_curve_key(params)).stress)
        s0 = params.bonds.force_sensitivity * sigma_c / params.stick.attached_chains
        lifetime = float(exp1(s0)) / params.stick.break_rate
        assert 1e-9 < lifetime < 1e-8
        stick = sim.stick_phases[0]
        assert stick.stick_time == pytest.approx(lifetime, rel=1e-6)
        times.append(stick.stick_time)
        rise = stick.peak_stress - sigma_c  # K V0 ts: 2e-12 to 2e-10 of σc, under the model's resolution
        assert rise == pytest.approx(params.block.effective_stiffness * V0 * lifetime, rel=1e-3, abs=1e-12 * sigma_c)
        assert 0.0 < rise < NOISE * sigma_c
        # the trace stops at the collapse, the same at every stiffness: no nanosecond slip is traced as a cycle
        assert sim.time[-1] == pytest.approx(lifetime, rel=1e-6) and sim.regime.periods == 0
    assert max(times) == pytest.approx(min(times), rel=1e-6)


def test_the_sweep_rows_of_the_three_stiffnesses_read_alike():
    model = get_model("quasi-static")
    rows = [
        run_point(
            model, {"pulling_velocity": V0, "bonds.site_density": DENSE, "block.stiffness": k}, {"duration": 100.0}
        )
        for k in BLOCK_STIFFNESSES
    ]
    assert [r["status"] for r in rows] == ["failed"] * 3  # before: failed, error, error
    words = {re.sub(r"[-+]?\d[\d.]*(e[-+]?\d+)?", "#", r["message"]) for r in rows}
    assert len(words) == 1 and "degenerate cycle" in words.pop()


def test_the_command_line_fails_the_run_instead_of_refusing_the_duration(capsys):
    code, _, err = run_main(
        capsys, "simulate", "--v0", "50 um/s", "--stiffness", "4 MPa/m", "--duration", "100 s",
        "--set", "bonds.site_density=1e15 1/m^2",
    )  # fmt: skip
    assert code == 3, err  # before: 2, "duration: 100 s holds 1.88e+10 cycles of 5.31e-09 s ..."
    assert "degenerate cycle" in err and "give a shorter duration" not in err and "Traceback" not in err


@pytest.mark.parametrize(
    ("density", "v0", "stiffness"),
    [(3e14, 5e-6, 4e3), (3e14, 120e-6, 40e6)],  # σs - σc = 6.9e-3 Pa (1.1e-5 of σc) and 233 Pa
)
def test_small_but_resolved_cycles_stay_stick_slip(density, v0, stiffness):
    params = load_parameters("gelatin-glass").with_overrides(
        {"bonds.site_density": density, "block.stiffness": stiffness}
    )
    sim = simulate(params, v0, 30.0)
    sigma_c = sim.critical_stress
    assert sim.regime == "stick-slip" and sim.status == "ok"
    stick = sim.stick_phases[0]
    assert stick.peak_stress - sigma_c > 1e3 * NOISE * sigma_c
    assert stick.peak_stress - sigma_c == pytest.approx(sim.stiffness * v0 * stick.stick_time, rel=1e-9)


def test_a_degenerate_stick_above_vc_still_settles_at_v0():
    # above Vc the slip from Vc runs to V0: steady sliding, whatever σs (unchanged)
    sim = simulate(_dense(400e3), 200e-6, 1000.0)
    assert sim.regime == "steady" and sim.status == "ok"
    assert sim.final_velocity == pytest.approx(200e-6, rel=1e-6)


# ---------------------------------------------------------------- B: a collapse after the run's end
POINT_804 = {"pulling_velocity": 8.018593718756654e-06, "block.stiffness": 958010.6479949947}  # tester R's grid
POINT_843 = {"pulling_velocity": 7.125513351514995e-06, "block.stiffness": 1122894.6}  # its neighbour


def _collapse_time(params, v0: float, sigma0: float) -> float:
    """Eq 15 integrated on its own (scipy, in t): dn/dt = -r n exp((s0 + k t)/n - t/τa) from n(0) = 1 to n = 1/2,
    past which the explosive collapse takes under 1e-6 s here."""
    b, nc0 = params.bonds.force_sensitivity, params.stick.attached_chains
    r, tau_a = params.stick.break_rate, params.stick.aging_time
    s0, k = b * sigma0 / nc0, b * params.block.effective_stiffness * v0 / nc0

    def rate(t, y):
        n = max(y[0], 1e-3)  # only n >= 1/2 matters
        return [-r * n * math.exp((s0 + k * t) / n - t / tau_a)]

    def gone(_t, y):
        return y[0] - 0.5

    gone.terminal = True
    solution = solve_ivp(rate, (0.0, 1e4), [1.0], method="DOP853", events=gone, rtol=1e-10, atol=1e-14)
    return float(solution.t_events[0][0])


def _number_after(text: str, words: str) -> float:
    match = re.search(re.escape(words) + r"\s*([-+]?\d[\d.]*(?:e[-+]?\d+)?)", text)
    assert match, (words, text)
    return float(match.group(1))


def test_a_collapse_after_the_run_end_is_said_and_the_run_is_ok():
    params = load_parameters("gelatin-glass").with_overrides({"block.stiffness": POINT_804["block.stiffness"]})
    v0 = POINT_804["pulling_velocity"]
    sim = simulate(params, v0, 300.0)
    sigma_c = sim.critical_stress
    truth = _collapse_time(params, v0, sigma_c)
    assert 340.0 < truth < 370.0  # 353.1 s
    # before: "... no jump velocity" and nothing more, while the trace ended at 300 s with 2023.2 Pa
    assert sim.regime == "undetermined" and sim.status == "ok" and sim.time[-1] == 300.0
    assert "after the run's end at 300 s" in sim.message and "the run ends stuck" in sim.message
    assert _number_after(sim.message, "that collapse comes at t =") == pytest.approx(truth, rel=1e-4)
    final = sigma_c + sim.stiffness * v0 * 300.0  # Eq 12: the stress of a stick rises as K V0 t
    assert _number_after(sim.message, "at σ =") == pytest.approx(final, rel=1e-5)
    assert np.max(sim.stress) == pytest.approx(final, rel=1e-9)


def test_a_collapse_within_the_run_still_fails_it():
    params = load_parameters("gelatin-glass").with_overrides({"block.stiffness": POINT_843["block.stiffness"]})
    v0 = POINT_843["pulling_velocity"]
    sim = simulate(params, v0, 300.0)
    truth = _collapse_time(params, v0, sim.critical_stress)
    assert sim.regime == "undetermined" and sim.status == "failed"
    assert "after the run's end" not in sim.message
    assert _number_after(sim.message, "the model stops at t =") == pytest.approx(truth, rel=1e-4)
    assert sim.time[-1] == pytest.approx(truth, rel=1e-4)


def test_a_run_that_ends_before_the_stick_from_sigma_c_says_so():
    # from 900 Pa the first stick slips within 1 s; the stick from σc that follows would collapse above the branch
    params = load_parameters("gelatin-glass").with_overrides({"block.stiffness": POINT_804["block.stiffness"]})
    sim = simulate(params, POINT_804["pulling_velocity"], 1.0, start_stress=900.0)
    assert sim.regime == "undetermined" and sim.status == "ok"
    assert "begins after the run's end at 1 s" in sim.message and "the run ends slipping" in sim.message
