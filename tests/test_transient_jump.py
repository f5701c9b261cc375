"""The massless block's jump through a rupture cascade (issue 33 item 1; transient/jump.py, docs/transient.md
section 2b).

With ``bonds.activation_length = 2 Å``, a steady start at 4.2 mm/s and a ±1 % kick of the puller, the bonds give
way in a cascade: the slider passes 4e8 m/s within 3e-17 s and the time steps collapsed; the run failed, or,
before that was refused, ended as the sampling chose.  The jump takes the cascade in no time.  Checked against
what does not come from the jump: the outcome of every sampling, the convergence of the jump's instant with the
tolerance, the spring's relaxation seen in the stress the puller rebuilds afterwards, and closed forms of the
jump's balance."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import stickslip
from cli_helpers import run_main
from stickslip import protocols
from stickslip.transient import jump, run_transient
from stickslip.transient import kernel as K
from stickslip.transient.model import pack_parameters

PULL = 4.2e-3
PARAMS = stickslip.load_parameters("gelatin-glass").with_overrides({"bonds.activation_length": 2e-10})


def _kick(sign: int):  # type: ignore[no-untyped-def]
    return protocols.segments([(PULL * (1 + 0.01 * sign), 0.01), (PULL, 0.01)])


def _run(sign: int, every: float | None = None, rtol: float = 1e-4):  # type: ignore[no-untyped-def]
    return run_transient(PARAMS, _kick(sign), start="steady", start_velocity=PULL, every=every, rtol=rtol)


def _puller_travel(protocol, t0: float) -> float:  # type: ignore[no-untyped-def]
    """The puller's travel from t0 to the protocol's end (exact: piecewise constant velocities)."""
    travel = 0.0
    for a, b, v in protocol.pieces():
        travel += v * max(0.0, b - max(a, t0))
    return travel


@pytest.fixture(scope="module")
def unsampled() -> dict[int, object]:
    return {sign: _run(sign) for sign in (1, -1)}


@pytest.mark.parametrize("sign", [1, -1])
@pytest.mark.parametrize("every", [1e-3, 1e-4, 1e-5])
def test_every_sampling_ends_stuck_after_the_same_jump(unsampled, sign, every):
    """The runs without --every and sampled every 1, 0.1 and 0.01 ms all jump once and end stuck.  The instants
    agree to 6e-7 s (measured: +1 % 3.07260 / 3.07260 / 3.07251 / 3.07202 ms), well inside the jump instant's own
    error at the default rtol (6.9e-6 s against rtol 1e-6: next test); the final stresses differ by what the
    puller rebuilt in between."""
    reference = unsampled[sign]
    run = _run(sign, every)
    assert reference.regime == run.regime == "stuck", run.message
    assert len(run.jumps) == len(reference.jumps) == 1
    assert run.jumps[0].time == pytest.approx(reference.jumps[0].time, abs=2e-6)
    # the stress rebuilt since the jump moves with its instant, at the puller's K V: nothing else differs
    shift = run.stiffness * PULL * 1.01 * abs(run.jumps[0].time - reference.jumps[0].time)
    assert abs(run.final_stress - reference.final_stress) <= shift + 1e-5 * reference.final_stress
    assert "jumped at t = " in run.message and "every bond broke" in run.message
    # the trace knows the stress fell to zero, whichever rows it kept (the lowest stress between rows)
    assert np.min(run.lowest_stress) == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("sign", [1, -1])
def test_the_spring_relaxes_and_the_puller_rebuilds_the_stress(unsampled, sign):
    """Every bond breaks and the spring relaxes at the jump (sigma 520 Pa -> 0): what the slider carries at the
    end is the puller's travel since the jump times K, less the slider's creep (from 243 and 872 nm/s at the end:
    below 1e-3 of it).  The closed form needs only the protocol and the instant."""
    run = unsampled[sign]
    (found,) = run.jumps
    assert found.survivors == 0 and found.stress_after == 0.0 and found.stress_before > 500.0
    assert found.travel == pytest.approx(found.stress_before / run.stiffness, rel=1e-9)  # P - X at the jump
    rebuilt = run.stiffness * _puller_travel(_kick(sign), found.time)
    assert 0.999 < run.final_stress / rebuilt <= 1.0


def test_the_jump_instant_converges_with_the_tolerance(unsampled):
    """The instant of the cascade is what the tolerance moves (an instability amplifies the local error): against
    rtol 1e-5, rtol 1e-3 is off by 1.7e-4 s and the default 1e-4 by 6.6e-6 s (measured; rtol 1e-6: 3.06568 ms,
    1e-5: 3.06598 ms), a factor ~25 per decade."""
    tight = _run(1, rtol=1e-5).jumps[0].time
    loose = _run(1, rtol=1e-3).jumps[0].time
    default = unsampled[1].jumps[0].time
    assert abs(default - tight) < 1e-5
    assert abs(loose - tight) > 10 * abs(default - tight)


def _two_cohorts(stiffness: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float, float]:
    """Cohort A at 0.999 of the FENE limit (its hazard at the kernel's cap), B at 0.1 of it; the block in balance."""
    p = pack_parameters(PARAMS, False, stiffness)
    dlm, m = p[K.P_DLM], p[K.P_M]
    x = 0.0
    xb = np.array([x - 0.999 * dlm, x - 0.1 * dlm])
    weights = np.array([1e12, 1e13])
    force = m * (x - xb) / (1 - ((x - xb) / dlm) ** 2)
    puller = x + float(weights @ force) / stiffness
    return p, xb, np.zeros(2), np.log(weights), x, puller


def test_a_stiff_spring_arrests_the_cascade_where_the_survivor_balances_it():
    """K = 1e11 Pa/m against the survivor's 1e9: A breaks, B takes the spring's load at the root of the cubic
    (K/dlm^2) e^3 - (K D/dlm^2) e^2 - (K + w m) e + K D = 0 (w m e/(1 - e^2/dlm^2) = K (D - e), D = P - x_b), and
    the slider there is slow enough for the time steps again."""
    stiffness = 1e11
    p, xb, tb, lw, x, puller = _two_cohorts(stiffness)
    dlm, m = p[K.P_DLM], p[K.P_M]
    x1, v1, n, found, dissipated = jump.cascade(0.0, x, 1e3, puller, 1e-4, 1e-4, 2, xb, tb, lw, p, K.compiled())
    assert n == 1 and found.survivors == 1 and xb[0] == pytest.approx(-0.1 * dlm) and lw[0] == math.log(1e13)
    d = puller - xb[0]
    roots = np.roots([stiffness / dlm**2, -stiffness * d / dlm**2, -(stiffness + 1e13 * m), stiffness * d])
    e = [r.real for r in roots if abs(r.imag) < 1e-30 and 0 < r.real < dlm]
    assert len(e) == 1 and x1 - xb[0] == pytest.approx(e[0], rel=1e-10)
    assert found.stress_after == pytest.approx(stiffness * (puller - x1), rel=1e-9)
    assert found.broken_share == pytest.approx(1e12 / p[K.P_N0], rel=1e-12)
    assert 0 < v1 <= jump.EXIT * 1e-4 and dissipated > 0


def test_a_soft_spring_lets_every_bond_go():
    """K = 3e5 Pa/m: no survivor can hold the spring: both break, the slider lands on the puller (sigma = 0), and
    the energy dissipated is all the energy there was, the spring's sigma^2/2K and both chains' FENE energy."""
    stiffness = 3e5
    p, xb, tb, lw, x, puller = _two_cohorts(stiffness)
    dlm, m = p[K.P_DLM], p[K.P_M]
    x1, v1, n, found, dissipated = jump.cascade(0.0, x, 1e3, puller, 1e-4, 1e-4, 2, xb, tb, lw, p, K.compiled())
    assert n == 0 and x1 == puller and v1 == 1e-4 and found.stress_after == 0.0
    assert found.broken_share == pytest.approx(1.1e13 / p[K.P_N0], rel=1e-12)
    sigma = stiffness * (puller - x)
    y = (x - xb) / dlm
    chains = float(np.exp(lw) @ (-0.5 * m * dlm**2 * np.log1p(-(y**2))))
    assert dissipated == pytest.approx(sigma**2 / (2 * stiffness) + chains, rel=1e-9)


ISSUE_COMMAND = (
    "transient", "--set", "bonds.activation_length=2 Å", "--start", "steady", "--start-velocity", "4.2 mm/s",
    "--v0", "4.242 mm/s", "--duration", "10 ms", "--segment", "4.2 mm/s:10 ms", "--every", "1 ms",
)  # fmt: skip


def test_the_command_ends_stuck_and_names_the_jump(capsys):
    """The command of issue 33.1 (sampled every 1 ms) exits 0 with 'stuck' and the jump in words; before, it
    failed (exit 3) or, sampled otherwise, jumped without a word; its JSON lists the jump, each number's unit
    named."""
    code, out, err = run_main(capsys, *ISSUE_COMMAND)
    assert code == 0, err
    assert "stuck" in out and "jumped at t = 0.00307" in out and "every bond broke" in out, out
    code, out, err = run_main(capsys, *ISSUE_COMMAND, "--json")
    document = json.loads(out)
    (found,) = document["jumps"]
    assert found["stress_after"] == 0.0 and found["survivors"] == 0 and document["regime"] == "stuck"
    units = document["units"]
    assert (units["time"], units["stress_before"], units["travel"], units["broken_share"]) == ("s", "Pa", "m", "1")


def test_with_aging_a_slow_arrest_takes_the_kernels_root():
    """Below 50 V_a the aging term counts and the velocity at a balance is the kernel's stable root of g: for
    bonds born at this instant (age 0, so the aging term vanishes) it is the linear root of the case without
    aging, to round-off; the arrest and the balance are the same."""
    stiffness, pace = 1e11, 1e-5
    outcomes = []
    for aging in (False, True):
        p, xb, tb, lw, x, puller = _two_cohorts(stiffness)
        p = pack_parameters(PARAMS, aging, stiffness)
        outcomes.append(jump.cascade(0.0, x, 1e3, puller, pace, pace, 2, xb, tb, lw, p, K.compiled()))
    (x0, v0, n0, _, _), (x1, v1, n1, _, _) = outcomes
    assert n0 == n1 == 1 and x1 == x0
    assert v0 < jump.FAST * PARAMS.aging.aging_velocity and v1 == pytest.approx(v0, rel=1e-9)


def test_a_cycle_through_a_cascade_has_no_finite_jump_velocity(capsys):
    """At 1 m/s through the paper's massless block every bond breaks at once at each slip, the spring relaxing in
    no time: the cycle's jump velocity is not the runaway velocity that set the cascade off (it read 1.6e14 µm/s,
    the last step before the collapse), but none: inf in the API, null in JSON, "a jump in no time" in words."""
    code, out, err = run_main(capsys, "transient", "--v0", "1 m/s", "--duration", "5 ms", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert len(summary["jumps"]) == 1 and summary["jumps"][0]["stress_after"] == 0.0
    (cycle,) = summary["cycles"]
    assert cycle["jump_velocity"] is None
    assert cycle["start_time"] + cycle["stick_time"] == pytest.approx(summary["jumps"][0]["time"], rel=1e-4)
    code, out, err = run_main(capsys, "transient", "--v0", "1 m/s", "--duration", "5 ms")
    assert "cycle 1: stick 0.003648 s, σs = 1116.4 Pa, a jump in no time" in out
    assert "µm/s, slip" not in out.split("cycle 1:")[1]
