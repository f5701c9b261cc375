"""The one regime classifier (stickslip.regimes): synthetic signals of known kind, and runs of every model
on both sides of their analytic stability boundary, whatever the output sampling (issues 17, 18, 20)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import stickslip
from cli_helpers import run_main
from stickslip import protocols, regimes
from stickslip.regimes import classify
from stickslip.rsf import critical_stiffness, rsf_params, simulate


# --------------------------------------------------------------------------- synthetic signals of known kind
def _sawtooth(t: np.ndarray, period: float = 10.0) -> np.ndarray:
    """Stick (linear rise) and slip (fast drop) with a small ringing overshoot after each slip."""
    phase = t % period
    rise = np.where(phase < 0.9 * period, phase / (0.9 * period), 1 - (phase - 0.9 * period) / (0.1 * period))
    return rise + 0.01 * np.exp(-5 * phase) * np.sin(20 * phase)


@pytest.mark.parametrize(
    ("name", "t", "y", "kind"),
    [
        ("exponential approach over 40 relaxation times", np.linspace(0, 40, 2001), None, regimes.STEADY),
        ("decaying sine, 10 periods", np.linspace(0, 60, 3001), None, regimes.DECAYING),
        ("decaying sine until below the tolerance", np.linspace(0, 400, 40001), None, regimes.STEADY),
        ("growing sine", np.linspace(0, 60, 3001), None, regimes.GROWING),
        ("stick-slip sawtooth with overshoots", np.linspace(0, 100, 100001), None, regimes.STICK_SLIP),
        ("exponential approach over 2 relaxation times", np.linspace(0, 2, 201), None, regimes.UNDETERMINED),
        ("one and a half periods", np.linspace(0, 9, 901), None, regimes.UNDETERMINED),
        ("a ramp (a stuck block's stress)", np.linspace(0, 5, 501), None, regimes.UNDETERMINED),
    ],
)
def test_synthetic_signals_are_classified_as_what_they_are(name, t, y, kind):
    signals = {
        "exponential approach over 40 relaxation times": lambda t: 1 - np.exp(-t),
        "decaying sine, 10 periods": lambda t: 0.5 + np.exp(-0.1 * t) * np.sin(t),
        "decaying sine until below the tolerance": lambda t: 0.5 + np.exp(-0.1 * t) * np.sin(t),
        "growing sine": lambda t: 0.5 + np.exp(0.05 * t) * np.sin(t),
        "stick-slip sawtooth with overshoots": _sawtooth,
        "exponential approach over 2 relaxation times": lambda t: 1 - np.exp(-t),
        "one and a half periods": np.sin,
        "a ramp (a stuck block's stress)": lambda t: 3.0 * t,
    }
    found = classify(t, signals[name](t), floor=1e-10)
    assert found.kind == kind, found.evidence
    assert found.evidence.startswith(kind)


def test_the_evidence_gives_periods_and_the_amplitude_ratio():
    t = np.linspace(0, 60, 3001)
    found = classify(t, 0.5 + np.exp(-0.1 * t) * np.sin(t), floor=1e-10)
    assert found.periods == 9 and found.period == pytest.approx(2 * math.pi, rel=1e-6)
    assert found.amplitude_ratio == pytest.approx(math.exp(-0.1 * 2 * math.pi), rel=1e-3)
    assert "9 period(s)" in found.evidence and "amplitude ratio 0.5335" in found.evidence
    short = classify(t[:600], np.sin(t[:600]), floor=1e-10)  # 12 s: one period and a bit
    assert short.kind == regimes.UNDETERMINED and "1 period(s)" in short.evidence


def test_the_classification_does_not_depend_on_the_sampling():
    fine = np.linspace(0, 100, 100001)
    for count in (100001, 3333, 1001, 333):
        t = np.linspace(0, 100, count)
        found = classify(t, _sawtooth(t), floor=1e-10)
        assert found.kind == regimes.STICK_SLIP and found.periods == 9, (count, found.evidence)
        # the fall through mid-level is steep: its time, and so the period, is found between samples
        assert found.period == pytest.approx(10.0, rel=2e-3), count
    # with the interpolant, the extremes are those of the signal, not of the samples
    t = np.linspace(0, 60, 61)
    found = classify(t, np.sin(t), floor=1e-10, dense=np.sin)
    assert found.peak == pytest.approx(1.0, abs=1e-9) and found.trough == pytest.approx(-1.0, abs=1e-9)
    assert found.period == pytest.approx(2 * math.pi, rel=1e-9)
    assert classify(fine, np.sin(fine), floor=1e-10).kind == regimes.STICK_SLIP


def test_oscillations_decayed_to_rounding_are_steady_not_noise():
    """Once the amplitude is below the tolerance, rounding wiggles are no periods (issue 17: 'growing')."""
    t = np.linspace(0, 2000, 200001)
    y = 0.6 + 1e-3 * np.exp(-0.5 * t) * np.sin(t) + 1e-16 * np.sin(977 * t)
    found = classify(t, y, floor=6e-10)
    assert found.kind == regimes.STEADY, found.evidence


def test_what_is_still_to_come_of_an_exponential_approach():
    t = np.linspace(0, 14, 1401)
    y = 391.5 - 0.5 * np.exp(-t / 1.8)
    change, remaining = regimes.remaining_change(t, y, 1.8)
    assert change == pytest.approx(0.5 * (math.exp(-(14 - 1.8) / 1.8) - math.exp(-14 / 1.8)), rel=1e-6)
    assert remaining == pytest.approx(0.5 * math.exp(-14 / 1.8), rel=1e-6)  # 2.1e-4 Pa
    assert classify(t, y, floor=1e-4, unit="Pa").kind == regimes.UNDETERMINED
    assert classify(t, y, floor=1e-3, unit="Pa").kind == regimes.STEADY


# --------------------------------------------------------------------------- rate-and-state
#: issue 17: the damped aging-law case, a limit cycle
DAMPED = ["--law", "aging", "--a", "0.001", "--b", "0.0015", "--mu0", "0.6", "--v-ref", "1 um/s",
          "--start-velocity", "1 um/s", "--dc", "3e-5 m", "--stiffness", "10 1/m", "--eta", "0.5 s/m",
          "--segment", "10 um/s:500 s"]  # fmt: skip


def _damped_reference() -> tuple[float, float, float]:
    """(period, peak, trough) of the same slider by an independent integration: DOP853 (explicit Runge-Kutta of
    order 8, not the package's LSODA) at rtol 1e-12 in (ln V, ln theta), the period between up-crossings of
    V = V_lp (events), each extremum of the last period refined on the interpolant by a bounded minimisation.
    (Radau at rtol 1e-12 agrees to 1e-10 s in the period and 1e-15 in friction, 25x slower.)"""
    from scipy.integrate import solve_ivp
    from scipy.optimize import minimize_scalar

    a, b, dc, mu0, v0, k, eta, vlp = 0.001, 0.0015, 3e-5, 0.6, 1e-6, 10.0, 0.5, 10e-6

    def rhs(t, y):
        v, theta = math.exp(y[0]), math.exp(y[1])
        dlog_theta = (1 - v * theta / dc) / theta
        return [(k * (vlp - v) - b * dlog_theta) / (a + eta * v), dlog_theta]

    def crossing(t, y):
        return y[0] - math.log(vlp)

    crossing.direction = 1
    y0 = [math.log(v0), math.log(dc / v0)]
    sol = solve_ivp(rhs, (0, 500), y0, method="DOP853", rtol=1e-12, atol=1e-14, events=crossing, dense_output=True)
    period = float(np.diff(sol.t_events[0])[-1])

    def mu(t):
        lv, lth = sol.sol(t)
        return mu0 + a * (lv - math.log(v0)) + b * (lth + math.log(v0 / dc))

    t = np.arange(500.0 - period, 500.0, 0.01)
    values = mu(t)
    extremes = []
    for sign in (1.0, -1.0):
        i = int(np.argmax(sign * values))
        bounds = (t[max(i - 1, 0)], t[min(i + 1, t.size - 1)])
        best = minimize_scalar(lambda s, sign=sign: -sign * mu(s), bounds=bounds, method="bounded")
        extremes.append(float(mu(best.x)))
    return period, extremes[0], extremes[1]


@pytest.fixture(scope="module")
def damped_reference():
    return _damped_reference()


@pytest.mark.parametrize("every", [None, "25 s", "1 s", "0.37 s"])
def test_rsf_summary_comes_from_the_solution_not_the_sampling(capsys, tmp_path, every, damped_reference):
    """Issue 17: --every 25 s said 'growing oscillation', 66.67 s; --every 1 s a trough of 0.59592."""
    args = [*DAMPED, "--json", "-o", str(tmp_path / "run.csv")] + ([] if every is None else ["--every", every])
    code, out, err = run_main(capsys, "rsf", "simulate", *args)
    assert code == 0, err
    summary = json.loads(out)
    period, peak, trough = damped_reference
    assert summary["regime"] == "stick-slip", summary["message"]
    assert summary["period"] == pytest.approx(period, rel=1e-7)  # 62.02497 s
    assert summary["peak_friction"] == pytest.approx(peak, abs=1e-9)  # 0.6010998
    assert summary["trough_friction"] == pytest.approx(trough, abs=1e-9)  # 0.5957825
    assert "below kc" in summary["message"] and "limit cycle" in summary["message"]


RSF_A, RSF_B, RSF_DC, RSF_ETA, RSF_V = 0.005, 0.01, 10e-6, 0.5, 10e-6


def _rsf_run(k: float, duration: float):
    p = rsf_params(RSF_A, RSF_B, RSF_DC, eta=RSF_ETA, stiffness=k)
    return simulate(p, protocols.constant(RSF_V, duration), start_velocity=1.1 * RSF_V), p


@pytest.mark.parametrize("ratio", [0.5, 0.7, 1.5, 2.0])
def test_rsf_regime_agrees_with_kc_on_both_sides(ratio):
    """kc = (b - a - eta V)/Dc = 499.5 1/m: below it a limit cycle, above it the oscillation decays (issue 17:
    k = 758 and 1000 1/m were 'growing oscillation ... unstable: k below critical' beside kc = 500)."""
    kc = (RSF_B - RSF_A - RSF_ETA * RSF_V) / RSF_DC
    run, p = _rsf_run(ratio * kc, 100.0)
    assert critical_stiffness(p, RSF_V) == pytest.approx(kc, rel=1e-12)
    message = run.summary()["message"]
    if ratio < 1:
        assert run.regime.name == "stick-slip" and "below kc" in message, message
    else:
        assert run.regime.name in ("decaying oscillation", "steady sliding"), message
        assert "above kc" in message and "unstable" not in message, message


def test_rsf_too_short_a_run_is_undetermined_with_the_evidence():
    kc = (RSF_B - RSF_A - RSF_ETA * RSF_V) / RSF_DC
    run, _ = _rsf_run(0.7 * kc, 8.0)  # a period is ~3.5 s: two periods, not enough to tell growth from a cycle
    assert run.regime.name == "undetermined", run.regime
    assert "period(s)" in run.summary()["message"] or "still changing" in run.summary()["message"]


def test_rsf_decayed_run_says_steady_sliding_at_mu_ss():
    run, _ = _rsf_run(1000.0, 1000.0)
    assert run.regime.name == "steady sliding", run.regime.evidence
    assert run.final_friction == pytest.approx(0.6 + (RSF_A - RSF_B) * math.log(RSF_V / 1e-6), abs=1e-9)


# --------------------------------------------------------------------------- the time-dependent bond model
@pytest.mark.parametrize(
    "args",
    [
        ["--duration", "20 ms", "--segment", "1 mm/s:10 us"],  # sigma 425.97 Pa, sigma(1 mm/s) = 653.43 Pa
        ["--duration", "1e-9 s"],
    ],
)
def test_transient_unsettled_runs_are_not_steady(capsys, args):
    """Issue 18: each of these was 'regime: steady' from a single sample, without a velocity check."""
    code, out, err = run_main(capsys, "transient", "--control", "velocity", "--v0", "350 um/s", *args, "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["regime"] == "undetermined", summary["message"]
    assert "too short" in summary["message"] or "still changing" in summary["message"]


def test_transient_regime_agrees_with_kc_on_both_sides():
    """Through the Eq 17 block (K = 3.06e5 Pa/m) steady sliding is unstable at 100 um/s (Kc ~ 1e9 Pa/m) and
    stable at 200 um/s (Kc = 0): the first must not be called steady, the second is."""
    from stickslip.transient import critical_stiffness as kc_bond
    from stickslip.transient import run_transient

    params = stickslip.load_parameters("gelatin-glass")
    k = params.block.effective_stiffness
    slow = run_transient(params, protocols.constant(100e-6, 1.0), start="steady")
    assert kc_bond(params, 100e-6) > k and slow.regime not in ("steady", "decaying oscillation"), slow.message
    fast = run_transient(params, protocols.constant(200e-6, 0.5), start="steady")
    assert kc_bond(params, 200e-6) < k and fast.regime == "steady", fast.message


def test_rsf_sweep_rows_never_contradict_their_own_kc():
    """Each row's message places k against the row's critical_stiffness the right way round (issue 17)."""
    kc = (RSF_B - RSF_A - RSF_ETA * RSF_V) / RSF_DC
    vary = [f"k={0.6 * kc:.6g} 1/m,{1.52 * kc:.6g} 1/m,{2.0 * kc:.6g} 1/m", "pulling_velocity=10 um/s"]
    fixed = {"a": str(RSF_A), "b": str(RSF_B), "Dc": "10 um", "η": f"{RSF_ETA} s/m"}
    frame = stickslip.sweep(vary, model="rsf", overrides=fixed, duration="100 s", workers=0)
    for row in frame.itertuples():
        below = row.k < row.critical_stiffness
        assert ("below kc" in row.message) == below and ("above kc" in row.message) == (not below), row.message
        expected = ("stick-slip",) if below else ("decaying oscillation", "steady sliding")
        assert row.regime in expected, row.message


def test_transient_cycles_come_from_the_slips_not_the_samples():
    """With the stick chains every stick and slip is an event at its exact time: sampled every 5 s the cycle is
    still the quasi-static model's to 1 % (stick 19.29 s, period 23.09 s).  From rest the start-up cycle does not
    repeat; the next does (issue 28: with fresh chains at each stick a repeated cycle repeats for ever), and the
    verdict says that one period backs it (issue 17: a period was called stick-slip from the samples alone)."""
    from stickslip.transient import run_transient

    params = stickslip.load_parameters("gelatin-glass")
    quasi = stickslip.simulate(params, 50e-6, 100.0).cycles[1]
    run = run_transient(
        params, protocols.constant(50e-6, 100.0), start="empty", stick_population=True, rtol=1e-3, every=5.0
    )
    cycle = run.cycles[1]
    assert cycle.stick_time == pytest.approx(quasi.stick_time, rel=0.01)
    assert cycle.period == pytest.approx(quasi.period, rel=0.01)
    assert cycle.peak_stress == pytest.approx(quasi.peak_stress, rel=0.01)
    assert len(run.cycles) == 3 and run.cycles[0].start_stress == 0.0
    assert run.regime == "stick-slip" and "1 period(s)" in run.message, run.message
    assert run.evidence.period == pytest.approx(quasi.period, rel=0.01)


def test_a_stuck_slider_at_rest_is_not_said_to_creep():
    """Issue 19: 'creeps at 0 m/s' for a slider the stick chains hold at rest."""
    from stickslip.protocols import constant
    from stickslip.transient.cycles import classify

    t = np.linspace(0.0, 10.0, 101)
    stress = 100.0 + 15.0 * t  # loading at K V0 while stuck
    regime, message = classify(t, stress, np.zeros_like(t), constant(50e-6, 10.0), (), [], "block", None)
    assert regime == "stuck" and "at rest" in message and "creeps" not in message
    regime, message = classify(t, stress, np.full_like(t, 1.25e-9), constant(50e-6, 10.0), (), [], "block", None)
    assert regime == "stuck" and "creeps at 1.25 nm/s" in message


def test_rsf_extremes_fall_back_to_the_accepted_steps_when_the_restart_fails(monkeypatch, capsys, damped_reference):
    """The interpolant restarts odeint from an accepted step; where that restart fails (here forced), the summary
    is read off the accepted steps themselves, coarser but never made up: no NaN, the same regime and period."""
    import scipy.integrate

    real = scipy.integrate.odeint

    def failing(*args, **kwargs):  # every restart fails, as odeint reports it (NaN rows and its message)
        out = real(*args, **kwargs)
        if kwargs.get("full_output"):
            return np.full_like(out[0], np.nan), {**out[1], "message": "Excess work done on this call."}
        return np.full_like(out, np.nan)

    monkeypatch.setattr(scipy.integrate, "odeint", failing)
    code, out, err = run_main(capsys, "rsf", "simulate", *DAMPED, "--json")
    assert code == 0, err
    summary = json.loads(out)
    period, peak, trough = damped_reference
    assert summary["regime"] == "stick-slip", summary["message"]
    assert summary["period"] == pytest.approx(period, rel=1e-3)
    assert summary["peak_friction"] == pytest.approx(peak, abs=1e-4)
    assert summary["trough_friction"] == pytest.approx(trough, abs=1e-4)


def test_a_settling_oscillation_reports_its_latest_period_not_a_mean_with_the_start_up():
    """Period 60 s, then 95 s (phase continuous), decaying 20 % a period: the last three intervals are 60, 95, 95 s;
    their mean (83 s) is no period the signal has now, the latest interval is."""
    t = np.linspace(0.0, 700.0, 70001)
    switch = 480.0
    phase = np.where(t < switch, 2 * np.pi * t / 60.0, 2 * np.pi * (switch / 60.0 + (t - switch) / 95.0))
    period_now = np.where(t < switch, 60.0, 95.0)
    envelope = np.exp(np.cumsum(np.log(0.8) / period_now) * (t[1] - t[0]))
    regime = regimes.classify(t, envelope * np.sin(phase), floor=1e-9)
    assert regime.kind == regimes.DECAYING
    assert regime.period == pytest.approx(95.0, rel=0.02)
