"""The cost of a sampled transient run (``every``): a row is not a step (2026-11-30, a tester's report).

100 um/s for 60 s with the stick chains sampled every 20 us (3e6 rows) was refused under a 1 min budget as "about
5.01 min of CPU" (each row counted a step's CPU) and took 38.8 s (2.7 GB); every 10 us with a larger step budget
passed the estimate and then held more than 4.5 GB.  Measured on the 2-core machine with `-o`: 2.33, 2.39, 5.61
and 38.8 s of process time unsampled and every 2 ms, 200 us and 20 us.
"""

from __future__ import annotations

import pytest

from stickslip.errors import ParameterError
from stickslip.parameters import load_parameters
from stickslip.protocols import constant
from stickslip.transient import run_transient
from stickslip.transient.solver import estimate_cost

GEL = load_parameters("gelatin-glass")
RUN = constant(100e-6, 60.0)


def test_a_finely_sampled_run_is_estimated_near_what_it_took() -> None:
    estimate = estimate_cost(GEL, RUN, stick_population=True, every=20e-6)
    assert 0.5 < 38.8 / estimate.seconds < 2.0  # was 5.01 min: 0.13
    plain = estimate_cost(GEL, RUN, stick_population=True)
    # the rows' own cost: 3.3 s measured for 3e5 rows (5.61 - 2.33 s)
    extra = estimate_cost(GEL, RUN, stick_population=True, every=200e-6).seconds - plain.seconds
    assert 0.5 < 3.3 / extra < 2.0


def test_more_rows_than_memory_holds_are_refused_in_one_line() -> None:
    with pytest.raises(ParameterError, match=r"every: 1e-05 s gives 6e\+06 rows over 60 s; expected at most 5e\+06"):
        run_transient(GEL, RUN, stick_population=True, every=10e-6)
