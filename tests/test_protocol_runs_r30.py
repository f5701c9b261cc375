"""Round 30 (tester V): ``compare``'s NAME.params.json is a parameter file the ``--params`` readers take; an
undetermined time-dependent run's ``mean_stress`` is the run's; a rate-and-state limit cycle's period comes from its
settled swings (a start-up swing moved it, so it changed with the run's length)."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp
from tests.cli_helpers import run_main


def test_compare_params_json_reruns_as_the_rsf_set_it_reports(capsys, tmp_path):
    """`compare -o cmp.png` wrote cmp.params.json, the report alone: `run --model rsf --params cmp.params.json`
    exited 2 ("unknown key 'bond_model'") and `params show` refused it, though docs/models.md says every --params
    reads rate-and-state's NAME.params.json.  Now it holds the set and the step it was fitted to."""
    figure = tmp_path / "cmp.png"
    code, _, err = run_main(capsys, "compare", "--duration", "60 s", "-o", str(figure))
    assert code == 0, err
    side = tmp_path / "cmp.params.json"
    document = json.loads(side.read_text(encoding="utf-8"))
    reported = document["rsf_of_bond_model"]  # the report is still there
    assert document["status"] == "ok" and "panels" in document
    p = document["parameters"]
    assert (p["a"], p["states"][0]["b"], p["states"][0]["dc"]) == (reported["a"], reported["b"], reported["dc"])

    code, out, err = run_main(capsys, "run", "--model", "rsf", "--params", str(side), "--json")
    assert code == 0, err
    rerun = json.loads(out)
    v0, v1 = (segment["velocity"] for segment in document["protocol"])
    assert (v0, v1) == (200e-6, 2e-3)  # compare's default step, 200 um/s -> 2 mm/s
    # the step's end, steady at V1: mu0 + (a - b) ln(V1 / v_ref), v_ref = V0 (closed form)
    steady = p["mu0"] + (p["a"] - p["states"][0]["b"]) * math.log(v1 / p["v_ref"])
    assert abs(rerun["final_friction"] - steady) <= 1e-6 * abs(steady)

    code, out, err = run_main(capsys, "params", "show", str(side))
    assert code == 0, err
    assert "direct effect" in out

    # a protocol given on the command line still wins
    code, out, err = run_main(capsys, "run", "--model", "rsf", "--params", str(side), "--v0", "200 um/s",
                              "--duration", "0.01 s", "--json")  # fmt: skip
    assert code == 0, err
    assert abs(json.loads(out)["final_friction"] - p["mu0"]) <= 1e-9


SHS_SPRING = "velocity [um/s],duration [s]\n100,20\n0,1\n100,20\n0,10\n100,20\n0,100\n100,30\n"


def test_undetermined_transient_run_reports_the_run_mean(capsys, tmp_path):
    """A slide-hold-slide on the block's spring with the stick chains, stuck at its end (undetermined): mean_stress
    was cycle 4's, 364.267 Pa (a cycle that ended 133 s before the run), the run's being 422.449 Pa.  The truth:
    the trapezoid mean of the run's own trace."""
    protocol = tmp_path / "shs_spring.csv"
    protocol.write_text(SHS_SPRING, encoding="utf-8")
    trace = tmp_path / "shs.csv"
    words = ("run", "--model", "transient", "--start", "steady", "--setting", "stick_population=true")
    code, out, err = run_main(capsys, *words, "--protocol", str(protocol), "--json", "-o", str(trace))
    assert code == 0, err
    summary = json.loads(out)
    assert summary["regime"] == "undetermined"
    rows = pd.read_csv(trace, comment="#")
    t, s = rows["time [s]"].to_numpy(), rows["stress [Pa]"].to_numpy()
    truth = float(np.sum(0.5 * (s[1:] + s[:-1]) * np.diff(t)) / (t[-1] - t[0]))
    assert abs(summary["mean_stress"] - truth) <= 1e-3 * truth  # 422.45 Pa; the old 364.27 Pa is 14 % off
    assert summary["mean_stress"] == summary["run_mean_stress"]


# a = 0.01, b = 0.015, Dc = 10 um, k = 100 1/m, eta = 100 s/m at V0 = 3.162 um/s, from 1.1 V0 (tester V)
A, B, DC, K, ETA, MU0, VREF, V0, VSTART = 0.01, 0.015, 10e-6, 100.0, 100.0, 0.6, 1e-6, 3.16227766e-6, 3.4785e-6


def _independent_period() -> float:
    """The limit cycle's period by scipy's LSODA on (ln V/Vref, ln theta), no mass: the spacing of the last falls
    through one fixed level (the settled cycle's mid-level)."""

    def rhs(_t, y):
        v, theta = VREF * math.exp(y[0]), math.exp(y[1])
        dlntheta = (1.0 - v * theta / DC) / theta
        return [(K * (V0 - v) - B * dlntheta) / (A + ETA * v), dlntheta]

    solution = solve_ivp(rhs, (0.0, 1000.0), [math.log(VSTART / VREF), math.log(DC / VSTART)], method="LSODA",
                         rtol=1e-10, atol=1e-12, dense_output=True)  # fmt: skip
    t = np.linspace(600.0, 1000.0, 400_001)
    x, lntheta = solution.sol(t)
    mu = MU0 + A * x + B * (lntheta + math.log(VREF / DC))
    level = 0.5 * (mu.max() + mu.min())
    falls = np.flatnonzero((mu[:-1] >= level) & (mu[1:] < level))
    times = t[falls] + (mu[falls] - level) / (mu[falls] - mu[falls + 1]) * (t[1] - t[0])
    return float(np.diff(times)[-1])


def _period(capsys, duration: str) -> tuple[float, dict]:
    code, out, err = run_main(capsys, "run", "--model", "rsf", "--v0", f"{V0} m/s", "--duration", duration,
                              "--start", f"{VSTART} m/s", "--set", f"a={A}", "--set", f"b={B}", "--set", "dc=10 um",
                              "--set", "eta=100 s/m", "--set", "k=100 1/m", "--set", f"mu0={MU0}",
                              "--set", "v_ref=1 um/s", "--json")  # fmt: skip
    assert code == 0, err
    summary = json.loads(out)
    return summary["period"], summary


def test_rsf_limit_cycle_period_comes_from_the_settled_swings(capsys):
    """500 s and 600 s read 144.315 s, the mean of the start-up interval (143.76 s) and two of the cycle's
    (144.59 s); 700 s and 1000 s read 144.591 s.  Now every length gives the cycle's own period."""
    truth = _independent_period()  # 144.591 s
    for duration in ("500 s", "1000 s"):
        period, summary = _period(capsys, duration)
        assert summary["regime"] == "stick-slip", summary["message"]
        assert abs(period - truth) <= 1e-4 * truth, (duration, period, truth)  # the old 144.315 s is 1.9e-3 off
