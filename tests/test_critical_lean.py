"""The critical-point search without repeated work (issue 31): each point of a Brent refinement is solved once,
and Vc, sigma_c alone (critical_minimum) cost one grid and one refinement.

References: the full search (critical_point, which the rest of the suite checks against independent ODE
references and the paper), a brute-force dense scan of the curve, and the number of steady states solved.
"""

from __future__ import annotations

import numpy as np
import pytest

from stickslip import load_parameters, steady_state
from stickslip.quasistatic import critical
from stickslip.quasistatic.critical import critical_minimum, critical_point

GEL = load_parameters("gelatin-glass")
#: two other steady curves: a faster and a slower aging than the paper's
OTHERS = (
    GEL.with_overrides({"aging.aging_time": 0.0012, "bonds.bond_time": 0.00025}),
    GEL.with_overrides({"aging.aging_velocity": 0.0003}),
)


@pytest.mark.parametrize("params", [GEL, *OTHERS])
def test_critical_minimum_is_the_critical_point(params):
    full = critical_point(params)
    lean = critical_minimum(params)
    assert lean is not None and lean.kind == "minimum"
    assert (lean.velocity, lean.stress) == (full.velocity, full.stress)  # the same search, bit for bit


def test_critical_minimum_lies_at_the_bottom_of_a_dense_scan():
    lean = critical_minimum(OTHERS[1])
    assert lean is not None
    v = lean.velocity * np.geomspace(0.9, 1.1, 201)
    scan = steady_state(OTHERS[1], v).stress
    assert lean.stress <= scan.min() * (1 + 1e-9)
    assert v[np.argmin(scan)] == pytest.approx(lean.velocity, rel=2e-3)  # the scan's step is 1e-3


def test_critical_minimum_is_none_without_a_minimum():
    # V_a so small that the aging term vanishes from 1 nm/s on: no minimum (as test_steady says of critical_point)
    params = GEL.with_overrides({"aging.aging_velocity": "1e-12 m/s"})
    assert critical_minimum(params) is None
    assert critical_point(params).velocity is None


def test_a_refinement_solves_each_point_once(monkeypatch):
    seen: list[float] = []
    real = critical._curve

    def counting(params, velocity, aging, compiled=False):
        if np.ndim(velocity) == 0:
            seen.append(float(velocity))
        return real(params, velocity, aging, compiled)

    monkeypatch.setattr(critical, "_curve", counting)
    _forget()
    extrema = critical.find_extrema(OTHERS[0], aging=True)
    assert len(extrema) == 2  # the minimum at Vc and the maximum at a few mm/s
    assert len(seen) == len(set(seen))  # Brent's ends and its root are not solved again
    assert len(seen) <= 2 * 12  # two refinements from brackets 1/16 decade wide to 1e-12 in ln V


def _forget() -> None:
    """Clear every remembered part of the search (the points, the minima, the grids and the refinements)."""
    for cache in (critical.cached_critical_point, critical._cached_minimum, critical._grid_signs, critical._refine):
        cache.cache_clear()


def test_the_whole_point_after_vc_alone_solves_nothing_twice(monkeypatch):
    """A transient run asks for Vc alone (critical_minimum), a jump later for the whole point: together they
    solve the steady states of the whole point's search once, not the grid and the minimum's refinement twice."""
    calls: list[float] = []
    real = critical._curve

    def counting(params, velocity, aging, compiled=False):
        calls.append(np.size(velocity))
        return real(params, velocity, aging, compiled)

    monkeypatch.setattr(critical, "_curve", counting)
    params = OTHERS[1]
    _forget()
    alone = critical_point(params)
    whole = list(calls)
    _forget()
    calls.clear()
    lean = critical_minimum(params)
    first = list(calls)
    assert critical_point(params) == alone
    assert lean is not None and (lean.velocity, lean.stress) == (alone.velocity, alone.stress)
    assert sorted(calls) == sorted(whole)  # the same steady states, each once
    assert sum(n > 1 for n in first) == 1 and len(first) - 1 <= 12  # Vc alone: one grid, one refinement
    assert sum(n > 1 for n in whole) == 2  # the whole point: the no-aging curve's grid too
