"""A creeping steady start that went non-finite (fixred, issue of round 2): the kernel accepted a step whose slider
velocity came out ~1e178 m/s (a cohort left just short of the FENE wall by the predicted slider path sat on its
hazard cliff at the balanced one); the reduction's look-ups only changed where the kernel's calls began."""

from __future__ import annotations

import pytest

import stickslip
from stickslip.protocols import constant

GEL = stickslip.load_parameters("gelatin-glass")


def test_creeping_steady_start_below_vc_finishes_and_agrees_with_the_cohorts():
    """100 um/s for 40 s from the steady start (below Vc: the run starts at Vc's stable side and sticks): raised
    ModelError at t = 38.5 s with reduction="auto"; now the same verdict, stress and stick as reduction="off"."""
    model = stickslip.get_model("transient")
    protocol = constant(100e-6, 40.0)
    auto = model.run(GEL, protocol, start="steady")
    off = model.run(GEL, protocol, start="steady", reduction="off")
    rtol = 1e-4  # the solver's default local tolerance
    assert auto.regime.kind == off.regime.kind == "stuck"
    assert auto.native.time[-1] == pytest.approx(40.0, rel=1e-12)
    assert auto.native.final_stress == pytest.approx(off.native.final_stress, rel=rtol)
    # the stick's numbers: the stress it starts from and the one it has reached, the mean over the run
    assert auto.regime.trough == pytest.approx(off.regime.trough, rel=rtol)
    assert auto.regime.peak == pytest.approx(off.regime.peak, rel=rtol)
    assert auto.summary["mean_stress"] == pytest.approx(off.summary["mean_stress"], rel=rtol)
    # independent of both: stuck, the block is loaded at K Vp less the slider's creep (below 1e-5 m here)
    k_block = GEL.block.effective_stiffness
    loaded = auto.regime.trough + k_block * 100e-6 * 40.0
    assert loaded - k_block * 1e-5 <= auto.native.final_stress <= loaded
