"""The block's mass and damping are checked by one rule wherever they are given: the Rig of the model interface
and the linear stability analysis (stickslip.transient.stability) refuse the same values in the same words."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip.errors import ParameterError
from stickslip.models import Rig
from stickslip.parameters import load_parameters
from stickslip.transient.stability import critical_stiffness

#: text with a unit is read (round 27: "10 kg/m^2" is a mass to both); text of another dimension is refused by both
BAD = [True, -1.0, math.nan, math.inf, "10 m/s", "-10 kg/m^2", None]


@pytest.mark.parametrize("value", BAD, ids=repr)
@pytest.mark.parametrize("name", ["mass", "damping"])
def test_the_stability_analysis_refuses_what_the_rig_refuses(name, value):
    """Before: the analysis took mass=True as 1 kg/m^2, and its messages differed from the rig's."""
    params = load_parameters("gelatin-glass")
    with pytest.raises(ParameterError) as analysis:
        critical_stiffness(params, 120e-6, **{name: value})
    if value is None:  # the rig's None is "not given"; the analysis has no such value
        assert str(analysis.value).startswith(f"{name}: expected a number")
        return
    with pytest.raises(ParameterError) as rig:
        Rig(**{name: value})
    assert f"rig {analysis.value}" == str(rig.value)


def test_values_with_their_units_are_read_alike():
    params = load_parameters("gelatin-glass")
    rig = Rig(mass="10 kg/m^2", damping="2 kPa s/m")
    assert (rig.mass, rig.damping) == (10.0, 2000.0)
    with_units = critical_stiffness(params, 120e-6, mass="10 kg/m^2", damping="2 kPa s/m")
    assert with_units == critical_stiffness(params, 120e-6, mass=10.0, damping=2000.0)


def test_numpy_numbers_are_numbers_to_both():
    from stickslip.transient.stability import _block_terms  # the analysis' check, without an analysis

    assert Rig(mass=np.float32(2.0), damping=np.int64(3)).mass == 2.0
    assert _block_terms(np.float32(2.0), np.int64(3)) == (2.0, 3.0)
