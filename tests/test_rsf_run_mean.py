"""The rate-and-state run's mean friction comes from the solver (the integral of mu dt it carries), not from the
output rows: README, "A summary never depends on how the output is sampled".  Before, run_mean_friction was the
trapezoidal mean of the rows and moved by 4.6e-4 (relative 8e-4) between --every 0.1 s and the solver's own steps
on a velocity step."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip.models import get_model
from stickslip.models.run import time_mean
from stickslip.protocols import constant, segments
from stickslip.rsf import simulate

STEP = ["--v0", "50 um/s", "--duration", "1 s", "--segment", "500 um/s:2 s", "--set", "b=0.015", "--set", "dc=10 um"]


def _params():
    return get_model("rsf").parameters(None, {"b": "0.015", "dc": "10 um"})


def test_two_samplings_give_one_run_mean(capsys):
    means = []
    for every in ([], ["--every", "10 ms"], ["--every", "0.1 s"], ["--every", "0.7 s"]):
        code, out, err = run_main(capsys, "run", "--model", "rsf", *STEP, *every, "--json")
        assert code == 0, err
        means.append(json.loads(out)["run_mean_friction"])
    assert max(means) - min(means) <= 1e-9 * means[0]


def test_the_run_mean_is_that_of_a_much_finer_trace():
    """Reference: the trapezoidal means of traces sampled every 100 and 50 us, Richardson-extrapolated (their
    error falls as the step squared: the extrapolation leaves about 1e-13 here)."""
    protocol = segments([(50e-6, 1.0), (500e-6, 2.0)])
    coarse, fine = (simulate(_params(), protocol, every=h, detect=False) for h in (1e-4, 5e-5))
    reference = (4 * time_mean(fine.time, fine.friction) - time_mean(coarse.time, coarse.friction)) / 3
    own = simulate(_params(), protocol).run_mean_friction
    assert own == pytest.approx(reference, rel=1e-9)
    assert coarse.run_mean_friction == pytest.approx(own, rel=1e-12)  # (and the samplings agree with each other)


def test_steady_sliding_has_the_closed_form_mean():
    """Started steady at V and pulled at V: mu = mu0 + (a - b) ln(V / v_ref) throughout."""
    params = _params()
    run = simulate(params, constant(50e-6, 7.0), every=0.3)
    expected = params.mu0 + (params.a - params.states[0].b) * math.log(50e-6 / params.v_ref)
    assert run.run_mean_friction == pytest.approx(expected, rel=1e-12)


def test_a_fit_run_without_the_integral_has_the_same_trace_and_no_mean() -> None:
    """``mean=False`` (what a fit asks: it reads the trace only) leaves the integral of mu dt out and changes no
    number of the trace: q's tolerance is out of reach, so it never chose a step (a fit's search follows
    differences of 1e-12)."""
    protocol = segments([(1e-6, 20.0), (10e-6, 20.0), (3e-6, 20.0)])
    times = np.linspace(0.0, 60.0, 601)
    carried = simulate(_params(), protocol, times=times, detect=False)
    plain = simulate(_params(), protocol, times=times, detect=False, mean=False)
    assert np.array_equal(carried.friction, plain.friction)
    assert np.array_equal(carried.slider_velocity, plain.slider_velocity)
    assert math.isfinite(carried.run_mean_friction) and math.isnan(plain.run_mean_friction)


#: issue 17's damped aging-law slider (tests/test_regimes.py): a limit cycle of period 62.02 s over 500 s
CYCLE = dict(a=0.001, b=0.0015, dc=3e-5, mu0=0.6, v0=1e-6, k=10.0, eta=0.5, vlp=10e-6, duration=500.0)


def _cycle_reference() -> tuple[float, float]:
    """(period, settled mean) by an independent integration: DOP853 at rtol 1e-12 in (ln V, ln theta, q = integral of
    mu dt), the period between the last two up-crossings of V = V_lp, the window the last whole periods within the
    second half (regimes.settled_window_start), its mean from q on the dense output."""
    from scipy.integrate import solve_ivp

    from stickslip.regimes import settled_window_start

    c = CYCLE

    def rhs(t, y):
        v, theta = math.exp(y[0]), math.exp(y[1])
        dlog_theta = (1 - v * theta / c["dc"]) / theta
        mu = c["mu0"] + c["a"] * y[0] - c["a"] * math.log(c["v0"]) + c["b"] * (y[1] + math.log(c["v0"] / c["dc"]))
        return [(c["k"] * (c["vlp"] - v) - c["b"] * dlog_theta) / (c["a"] + c["eta"] * v), dlog_theta, mu]

    def crossing(t, y):
        return y[0] - math.log(c["vlp"])

    crossing.direction = 1
    y0 = [math.log(c["v0"]), math.log(c["dc"] / c["v0"]), 0.0]
    end = c["duration"]
    sol = solve_ivp(rhs, (0, end), y0, method="DOP853", rtol=1e-12, atol=1e-14, events=crossing, dense_output=True)
    period = float(np.diff(sol.t_events[0])[-1])
    start = settled_window_start(0.0, end, period)
    return period, float((sol.y[2, -1] - sol.sol(start)[2]) / (end - start))


def test_the_settled_mean_is_the_solutions_whatever_the_sampling():
    """The sweep's mean_friction (the last whole periods within the second half) from the solver's integral: four
    samplings and a run at six given times within 1e-10 of an independent DOP853 integration (measured: 1.2e-12).
    Before, it was the rows' trapezoid: 5.5e-4 off at every 25 s (the window starts between rows), 1.9e-5 at 1 s,
    3.9e-6 at 0.37 s, 2.1e-8 on the solver's own steps, 8.4e-4 at the six times (whose first row, not t = 0, set
    the window's half)."""
    from stickslip.models.rsf import rsf_run
    from stickslip.rsf.params import rsf_params

    c = CYCLE
    params = rsf_params(c["a"], c["b"], c["dc"], mu0=c["mu0"], v_ref=c["v0"], stiffness=c["k"], eta=c["eta"])
    period, expected = _cycle_reference()
    means = []
    for every in (None, 25.0, 1.0, 0.37):
        run = simulate(params, constant(c["vlp"], c["duration"]), start_velocity=c["v0"], every=every)
        assert run.regime.period == pytest.approx(period, rel=1e-7)
        means.append(rsf_run(run).mean)
        assert means[-1] == pytest.approx(expected, rel=1e-10), every
    times = np.linspace(0.0, c["duration"], 7)[1:]  # a run asked for at given times (the start row dropped)
    given = simulate(params, constant(c["vlp"], c["duration"]), start_velocity=c["v0"], times=times)
    assert rsf_run(given).mean == pytest.approx(expected, rel=1e-10)
