"""Round 29b, the quasi-static cycle (tester S): a cycle shorter than the sliding bonds' memory at Vc, Δl_m/Vc, is
outside the quasi-static model at every stiffness.  The stress rule of round 29 (σs within 1e-9 of σc) left
N0 = 1e15 m^-2 at 50 µm/s and G/h = 40 MPa/m, σs - σc = 4.9e-6 Pa = 2.3e-9 σc, a 5.3 ns "cycle" refused as
"60 s holds 1.13e+10 cycles" (exit 2), while at 4 kPa/m-10 MPa/m the same 3.17 ns stick was degenerate (exit 3)."""

from __future__ import annotations

import re

import pytest
from scipy.special import exp1

from cli_helpers import run_main
from stickslip import load_parameters, protocols
from stickslip import run as run_model
from stickslip.models import Rig
from stickslip.quasistatic.critical import cached_critical_point, steady_curve_key
from stickslip.quasistatic.cycle import simulate
from stickslip.sweeps.models import get_model, run_point

STIFFNESSES = (4e3, 400e3, 10e6, 40e6)  # block.stiffness (G/h), Pa/m: tester S's four
#: the words of the time rule (the stress rule's say "creep by infinitesimal slips, outside the model")
TOO_SHORT = "the sliding bonds take to renew at Vc"


def _params(density: float, stiffness: float):
    return load_parameters("gelatin-glass").with_overrides(
        {"bonds.site_density": density, "block.stiffness": stiffness}
    )


def _number_after(text: str, words: str) -> float:
    match = re.search(re.escape(words) + r"\s*([-+]?\d[\d.]*(?:e[-+]?\d+)?)", text)
    assert match, (words, text)
    return float(match.group(1))


def _memory(params) -> float:
    """Δl_m/Vc: the oldest age of the steady population at Vc (the upper limit of Eqs 7-8's integrals)."""
    vc = float(cached_critical_point(steady_curve_key(params)).velocity)
    return params.bonds.max_extension / vc


def _small_rise_cycle(params, v0: float) -> tuple[float, float]:
    """(stick, period) of a cycle whose σs hardly leaves σc, in closed form: the stick is the constant-load
    lifetime of fresh chains at σc, E1(s0)/r (dn/dt = -r n exp(s0/n), s0 = λσc/(kT Nc0)), and the slip from
    Vs to Vc lasts (σs - σc)/(K (Vc - V0)) = V0 ts/(Vc - V0) (σ - σc = σ''(V - Vc)²/2 near the minimum, Eq 10)."""
    cp = cached_critical_point(steady_curve_key(params))
    sigma_c, vc = float(cp.stress), float(cp.velocity)
    s0 = params.bonds.force_sensitivity * sigma_c / params.stick.attached_chains
    stick = float(exp1(s0)) / params.stick.break_rate
    return stick, stick * vc / (vc - v0)


@pytest.mark.parametrize("stiffness", STIFFNESSES)
def test_a_nanosecond_cycle_is_outside_the_model_at_every_stiffness(stiffness):
    # before: 4 kPa/m-10 MPa/m failed/degenerate (the stress rule), 40 MPa/m raised ParameterError "duration: 60 s
    # holds 1.13e+10 cycles of 5.31387e-09 s ... give a shorter duration"
    params = _params(1e15, stiffness)
    sim = simulate(params, 50e-6, 60.0)
    assert sim.regime == "undetermined" and sim.status == "failed", sim.message
    assert sim.message.startswith("degenerate cycle: the chains collapse after")
    assert TOO_SHORT in sim.message and "shorter duration" not in sim.message
    stick, period = _small_rise_cycle(params, 50e-6)
    assert 1e-9 < stick < 1e-8  # 3.17 ns
    assert _number_after(sim.message, "collapse after") == pytest.approx(stick, rel=1e-4)
    # the period it names is the stick and the slip back to Vc (0 s where σs is σc to the curve's resolution)
    named = _number_after(sim.message, "lasts")
    assert stick * (1 - 1e-3) <= named <= period * (1 + 1e-2)
    memory = _memory(params)
    assert 8e-3 < memory < 9e-3  # 1.074 µm / 124.1 µm/s
    assert _number_after(sim.message, "of the") == pytest.approx(memory, rel=1e-2)
    assert _number_after(sim.message, f"{named:.3g} s:") == pytest.approx(named / memory, rel=0.06)
    # the trace stops at the collapse, and no nanosecond cycle is counted
    assert sim.time[-1] == pytest.approx(stick, rel=1e-4) and sim.regime.periods == 0 and not sim.cycles


def test_the_sweep_rows_of_every_stiffness_read_alike():
    model = get_model("quasi-static")
    rows = [
        run_point(model, {"pulling_velocity": 50e-6, "bonds.site_density": 1e15, "block.stiffness": k},
                  {"duration": 60.0})
        for k in STIFFNESSES
    ]  # fmt: skip
    assert [r["status"] for r in rows] == ["failed"] * 4  # before: failed, failed, failed, error
    words = {re.sub(r"[-+]?\d[\d.]*(e[-+]?\d+)?", "#", r["message"]) for r in rows}
    assert len(words) == 1 and TOO_SHORT in words.pop()


def test_the_command_line_fails_the_run_with_exit_3(capsys):
    code, _, err = run_main(
        capsys, "simulate", "--v0", "50 um/s", "--duration", "60 s",
        "--set", "bonds.site_density=1e15 1/m^2", "--set", "block.stiffness=40 MPa/m",
    )  # fmt: skip
    assert code == 3, err  # before: 2, "duration: 60 s holds 1.13e+10 cycles of 5.31387e-09 s ..."
    assert TOO_SHORT in err and "shorter duration" not in err and "Traceback" not in err
    # a short run, which before printed "stick-slip with period 5.31387e-09 s ... 94093 whole cycle(s)", exit 0
    code, out, err = run_main(
        capsys, "simulate", "--v0", "50 um/s", "--duration", "0.0005 s",
        "--set", "bonds.site_density=1e15 1/m^2", "--set", "block.stiffness=40 MPa/m",
    )  # fmt: skip
    assert code == 3 and "stick-slip" not in out and TOO_SHORT in err


@pytest.mark.parametrize("stiffness", (4e3, 400e3, 40e6))
def test_a_millisecond_cycle_below_the_bonds_memory_is_outside_the_model(stiffness):
    # N0 = 5e14 m^-2 at 50 µm/s: a 1.8 ms stick and a 1.2 ms slip, a third of Δl_m/Vc = 8.65 ms, at every
    # stiffness; before: stick-slip (the stress rule catches none: σs - σc = 2.4e-8 to 2.4e-3 of σc)
    params = _params(5e14, stiffness)
    _, period = _small_rise_cycle(params, 50e-6)
    assert period < 0.5 * _memory(params)
    sim = simulate(params, 50e-6, 1.0)
    assert sim.regime == "undetermined" and sim.status == "failed", sim.message
    assert TOO_SHORT in sim.message
    assert _number_after(sim.message, "lasts") == pytest.approx(period, rel=0.05)  # 2% at 40 MPa/m (rise 2.4e-3)


def test_the_full_model_has_no_such_cycle():
    # the time-dependent model (Eq 1 with the stick chains, no quasi-static picture) at N0 = 5e14 m^-2, 400 kPa/m,
    # 50 µm/s: its slip ends below σc (the bonds lag the slip), where the chains collapse with no branch to jump
    # onto; no cycle of the quasi-static 3 ms
    params = {"bonds.site_density": 5e14, "block.stiffness": 400e3}
    run = run_model(
        "transient", params, protocols.segments([(130e-6, 0.01), (50e-6, 0.3)]), Rig(control="spring"),
        start="steady", stick_population=True,
    )  # fmt: skip
    _, period = _small_rise_cycle(_params(5e14, 400e3), 50e-6)
    assert run.regime.kind != "stick-slip" or not 0.3 < run.period / period < 3.0, run.regime


@pytest.mark.parametrize(
    ("density", "stiffness", "v0"),
    [(4.4e14, 40e6, 50e-6), (3e14, 40e6, 79.2e-6), (3e14, 4e3, 5e-6)],  # 1.6, 15 and 34 times Δl_m/Vc
)
def test_cycles_longer_than_the_bonds_memory_stay_stick_slip(density, stiffness, v0):
    params = _params(density, stiffness)
    sim = simulate(params, v0, 2.0)
    assert sim.regime == "stick-slip" and sim.status == "ok", sim.message
    assert sim.regime.period > _memory(params)


def test_a_long_stick_that_never_leaves_sigma_c_keeps_the_stress_words():
    # the puller stands still and the chains do not age: σs = σc after a long stick (85 s), so the jump lands at Vc;
    # the cycle is no shorter than the bonds' memory, and the words are the stress rule's
    params = load_parameters("gelatin-glass").with_overrides({"stick.aging_time": "1e6 s"})
    sim = simulate(params, 0.0, 300.0)
    assert sim.regime == "undetermined" and "creep by infinitesimal slips" in sim.message
    assert TOO_SHORT not in sim.message and sim.time[-1] > 1.0
