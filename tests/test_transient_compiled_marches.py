"""A time-dependent run asks for its steady states on the compiled march (issue 31, the command's start).

numba is loaded by every run, so the quasi-static pieces a run asks for (its critical point, the quasi-static cycle
its cost estimate reads, the jump's branch) use the compiled march too, at every width
(``stickslip.quasistatic.steady.compiled_marches``).  References: the numpy march and search (the second
implementation, tests/test_critical_compiled.py checks the two against each other); a result must not depend on what
ran before it in the process.
"""

from __future__ import annotations

import math

import pytest

from stickslip import load_parameters
from stickslip.errors import ParameterError
from stickslip.protocols import Protocol, Segment
from stickslip.quasistatic import critical, jump, steady
from stickslip.quasistatic.critical import critical_point
from stickslip.transient.solver import run_transient

GEL = load_parameters("gelatin-glass")
#: issue 31's cycle: 350 -> 100 um/s through the block, the steady start, the stick chains
CYCLE = Protocol((Segment(350e-6, 5.0), Segment(100e-6, 20.0)))


def _forget() -> None:
    for cache in (
        critical.cached_critical_point,
        critical._cached_minimum,
        critical._grid_signs,
        critical._refine,
        jump.branch_interpolant,
    ):
        cache.cache_clear()


def test_every_steady_state_of_a_run_is_compiled_and_the_cycle_is_the_issue_s(monkeypatch):
    _forget()
    widths = []  # (lanes, the width from which that call runs compiled)
    real = steady._march

    def recording(s, q, keep_nodes=False, compiled_from=None):
        widths.append((s.log_t.size, steady.COMPILED_LANES if compiled_from is None else compiled_from, keep_nodes))
        return real(s, q, keep_nodes, compiled_from)

    monkeypatch.setattr(steady, "_march", recording)
    run = run_transient(GEL, CYCLE, start="steady", stick_population=True)
    assert widths, "the run asked for no steady state"
    on_numpy = [w for w in widths if w[2] or w[0] < w[1]]
    assert not on_numpy, on_numpy[:5]
    # the cycle the issue names (ts 9.7654 s, sigma_s 556.405 Pa to 1e-3), as before the marches were compiled
    cycle = run.cycles[0]
    assert cycle.stick_time == pytest.approx(9.7654, rel=1e-3)
    assert cycle.peak_stress == pytest.approx(556.405, rel=1e-3)
    assert not steady.marches_compiled()  # the setting ends with the run


def test_a_critical_point_after_a_run_is_the_numpy_search_s_bit_for_bit():
    """The run's compiled critical point is cached apart: ``critical_point`` afterwards is what a fresh process
    finds, and the two agree to the searches' own accuracy."""
    _forget()
    fresh = critical_point(GEL)
    _forget()
    run_transient(GEL, Protocol((Segment(350e-6, 0.05),)), start="steady", stick_population=True)
    after = critical_point(GEL)
    assert (after.velocity, after.stress, after.turnover_velocity) == (
        fresh.velocity,
        fresh.stress,
        fresh.turnover_velocity,
    )
    with steady.compiled_marches():
        compiled = critical_point(GEL)
    assert compiled is not after
    assert math.isclose(compiled.velocity, fresh.velocity, rel_tol=1e-10)
    assert math.isclose(compiled.stress, fresh.stress, rel_tol=1e-12)


def test_the_setting_is_undone_when_a_run_is_refused():
    with pytest.raises(ParameterError, match="would take about"):  # refused by its estimate, within the setting
        run_transient(GEL, CYCLE, start="steady", stick_population=True, max_steps=1)
    assert not steady.marches_compiled()
