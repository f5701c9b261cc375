"""One regime type: rate-and-state's regime is the classifier's stickslip.regimes.Regime (issue 20, item 3)."""

from __future__ import annotations

import math

from stickslip import protocols, regimes
from stickslip.models import as_run
from stickslip.rsf import RSFParams, StateVariable, simulate


def _params(k: float) -> RSFParams:
    # aging law, a = 0.005, b = 0.01, Dc = 10 um, eta = 0.5 s/m: kc = (b - a - eta V) / Dc = 498.5 1/m at 3 um/s
    return RSFParams(a=0.005, states=(StateVariable("aging", 0.01, 10e-6),), stiffness=k, eta=0.5)


def test_rsf_regime_is_the_classifiers_regime() -> None:
    kind, name = regimes.STEADY, "steady sliding"  # k = 2000 1/m is well above kc = 498.5 1/m
    run = simulate(_params(2000.0), protocols.constant(3e-6, 100.0), start_velocity=3.3e-6)
    r = run.regime
    assert isinstance(r, regimes.Regime)
    assert r.kind == kind and r.kind in regimes.KINDS
    # rate-and-state's historical names, read-only aliases of the classifier's fields
    assert r.name == name
    assert (r.peak_friction, r.trough_friction) == (r.peak, r.trough)
    assert r.growth is r.amplitude_ratio or (math.isnan(r.growth) and math.isnan(r.amplitude_ratio))
    summary = run.summary()
    assert summary["regime"] == name  # the JSON key and value rsf prints are unchanged
    assert set(summary) == {
        "regime", "final_friction", "period", "peak_friction", "trough_friction", "growth", "periods", "status",
        "message",
    }  # fmt: skip
    assert as_run(run).regime.kind == kind


def test_rsf_blow_up_and_unanalysed_runs_carry_a_classifier_kind() -> None:
    # slip law, quasi-static (eta = 0) far below kc: the slip rate runs away (tests/test_rsf_laws.py's case)
    slip = RSFParams(a=0.01, states=(StateVariable("slip", 0.015, 10e-6),), v_ref=1e-6, stiffness=250.0)
    blown = simulate(slip, protocols.constant(1e-6, 300.0), start_velocity=1.1e-6)
    assert blown.status == "blow-up"
    assert isinstance(blown.regime, regimes.Regime) and blown.regime.kind == regimes.BLOW_UP
    # the extremes of the solution, placed between the solver's steps (round 27): at or beyond the rows' own
    assert max(blown.friction) <= blown.regime.peak <= max(blown.friction) + 1e-6
    assert min(blown.friction) - 1e-6 <= blown.regime.trough <= min(blown.friction)
    fit_like = simulate(_params(2000.0), protocols.constant(3e-6, 10.0), detect=False)
    assert fit_like.regime.kind == regimes.UNDETERMINED and fit_like.regime.evidence == "not analysed"
