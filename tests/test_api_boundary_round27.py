"""The Python API's boundary (round-27 testers E and F): values with units, empty input, the stiffness keys, a
mapping given to ``run``, a set read from a file, and the critical point's plot.

* docs/api.md said "strings with units are read at the boundary", but only overrides read them:
  ``steady_state(p, "0.2 mm/s")``, ``simulate(p, "50 um/s", "2 min")``, ``protocols.constant("0.2 mm/s", "3 s")``,
  ``Rig(stiffness="300 kPa/m")`` were refused, and ``every="100 ms"`` was "expected a positive time ..., got '100 ms'";
* ``run("rsf", {"a": .., "b": .., "dc": ..})`` was "unknown key 'b'" (the keys of a rate-and-state file);
* ``block.effective_stiffness`` / ``block.stiffness``, documented keys, were unknown to ``load_parameters`` and
  ``params show --set``;
* an exported gelatin-glass whose bond_time was edited was still printed as ``parameter set gelatin-glass``;
* ``critical_point(p).plot(ax=ax)`` left both axis labels empty.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from tests.cli_helpers import run_main

import stickslip
from stickslip import Rig, protocols
from stickslip.errors import ParameterError, UnitError
from stickslip.parameters import load_parameters

# ----------------------------------------------------------------------------- 1. values with units


def test_steady_state_reads_one_velocity_with_its_unit(params):
    si = stickslip.steady_state(params, 2e-4).stress
    assert stickslip.steady_state(params, "0.2 mm/s").stress == pytest.approx(si, rel=1e-12)
    assert stickslip.steady_state(params, "200 um/s").stress == pytest.approx(si, rel=1e-12)
    with pytest.raises(UnitError, match=r"velocity: '0\.2 mm' has dimension \[length\], expected a velocity"):
        stickslip.steady_state(params, "0.2 mm")
    with pytest.raises(ParameterError, match=r"got '-0\.2 mm/s'"):  # refused as the user wrote it
        stickslip.steady_state(params, "-0.2 mm/s")
    with pytest.raises(ParameterError, match=r"an array of velocities holds numbers in m/s"):
        stickslip.steady_state(params, ["0.2 mm/s", "1 mm/s"])


def test_simulate_reads_its_velocity_duration_and_start_stress_with_units(params):
    by_si = stickslip.simulate(params, 50e-6, 120.0, start_stress=300.0)
    by_text = stickslip.simulate(params, "50 um/s", "2 min", start_stress="0.3 kPa")
    assert by_text.regime.kind == by_si.regime.kind == "stick-slip"  # "50 um/s" is 50e-6 m/s to a bit or so
    assert by_text.regime.period == pytest.approx(by_si.regime.period, rel=1e-9)
    assert by_text.time[-1] == pytest.approx(120.0, rel=1e-12) and by_text.start_stress == 300.0
    assert np.allclose(by_text.stress, by_si.stress, rtol=1e-9, atol=0)
    with pytest.raises(UnitError, match=r"pulling_velocity: '50 um' has dimension \[length\], expected a velocity"):
        stickslip.simulate(params, "50 um", 10.0)
    with pytest.raises(UnitError, match=r"duration: '10 m' has dimension \[length\], expected a time"):
        stickslip.simulate(params, 50e-6, "10 m")
    with pytest.raises(ParameterError, match=r"duration: expected a positive time in s, got '-1 s'"):
        stickslip.simulate(params, 50e-6, "-1 s")


def test_every_protocol_builder_reads_units():
    assert protocols.constant("0.2 mm/s", "3 s").segments == (protocols.Segment(2e-4, 3.0),)
    steps = protocols.velocity_steps(["1 um/s", "10 um/s"], "20 s")
    assert [(s.velocity, s.duration) for s in steps.segments] == [(1e-6, 20.0), (pytest.approx(1e-5, rel=1e-15), 20.0)]
    shs = protocols.slide_hold_slide("10 um/s", "20 s", "2 min")
    assert np.allclose(shs.velocities, [1e-5, 0.0, 1e-5], rtol=1e-15, atol=0)
    assert list(shs.boundaries) == [0.0, 20.0, 140.0, 160.0]
    assert protocols.segments([("1 mm/s", "500 ms")]).segments == (protocols.Segment(1e-3, 0.5),)
    quantity = stickslip.units.registry().Quantity
    assert protocols.constant(quantity(0.2, "mm/s"), quantity(3, "s")).segments[0].velocity == pytest.approx(2e-4)
    with pytest.raises(UnitError, match=r"segment duration: '3 m' has dimension \[length\], expected a time"):
        protocols.constant(1e-4, "3 m")
    with pytest.raises(ParameterError, match=r"segment velocity: expected a value >= 0 m/s, got '-0\.1 mm/s'"):
        protocols.constant("-0.1 mm/s", 1.0)


def test_the_rig_reads_units_and_names_a_wrong_dimension():
    rig = Rig(stiffness="300 kPa/m", damping="2 kPa s/mm", mass="10 kg/m^2")
    assert rig.stiffness == pytest.approx(3e5, rel=1e-15)
    assert rig.damping == pytest.approx(2e6, rel=1e-12)
    assert rig.mass == pytest.approx(10.0, rel=1e-15)
    with pytest.raises(UnitError, match=r"rig stiffness: '1 1/um' has dimension .*expected a stress per length"):
        Rig(stiffness="1 1/um")
    with pytest.raises(ParameterError, match=r"rig stiffness: expected a finite value > 0 Pa/m, got '-3 kPa/m'"):
        Rig(stiffness="-3 kPa/m")


def test_run_reads_every_and_start_with_units(params):
    one_second = protocols.constant(1e-4, 1.0)
    velocity = Rig(control="velocity")
    by_text = stickslip.run("transient", params, one_second, velocity, every="100 ms")
    by_si = stickslip.run("transient", params, one_second, velocity, every=0.1)
    assert np.array_equal(by_text.time, by_si.time)
    assert np.allclose(by_text.time[:11], np.arange(11) * 0.1, rtol=0, atol=1e-12)  # the grid of 100 ms
    slow = protocols.constant(50e-6, 30.0)
    assert stickslip.run("quasi-static", params, slow, start="0.3 kPa").peak == pytest.approx(
        stickslip.run("quasi-static", params, slow, start=300.0).peak, rel=1e-12
    )
    with pytest.raises(UnitError, match=r"start: '300 m/s' has dimension .*expected a stress"):
        stickslip.run("quasi-static", params, slow, start="300 m/s")


# ----------------------------------------------------------------------------- 3. run() with a mapping


def test_run_reads_a_mapping_with_the_models_own_keys():
    protocol = protocols.constant(1e-4, 1.0)
    keys = {"a": 0.01, "b": 0.015, "dc": "10 um"}
    model = stickslip.get_model("rsf")
    by_mapping = stickslip.run("rsf", keys, protocol)
    by_reader = stickslip.run("rsf", model.parameters(None, keys), protocol)
    assert np.array_equal(by_mapping.stress if by_mapping.stress is not None else by_mapping.friction,
                          by_reader.stress if by_reader.stress is not None else by_reader.friction)  # fmt: skip
    state = model.parameters(None, keys).states[0]
    assert (state.b, state.dc) == (0.015, pytest.approx(1e-5, rel=1e-12))
    with pytest.raises(ParameterError, match=r"bb.*expected one of: a, b, dc, k"):  # the model's own keys
        stickslip.run("rsf", {"a": 0.01, "bb": 0.015}, protocol)
    # a whole rate-and-state set as its file holds it (the states as a list) is still read as the file
    whole = model.parameters(None, keys).to_dict()
    assert np.array_equal(stickslip.run("rsf", whole, protocol).time, by_reader.time)


# ----------------------------------------------------------------------------- 4. the block's stiffness keys


def _trapezoid(params) -> float:
    """ln(B/l)/(B/l - 1) of Eq 17, written out."""
    ratio = params.block.top_length / params.block.base_length
    return math.log(ratio) / (ratio - 1.0)


def test_the_stiffness_keys_set_the_height_and_name_the_set(params):
    p = load_parameters("gelatin-glass", {"block.effective_stiffness": "0.3 kPa/mm"})
    assert p.block.shear_modulus == params.block.shear_modulus  # the gel's modulus kept
    assert p.block.height == pytest.approx(params.block.shear_modulus * _trapezoid(params) / 3e5, rel=1e-12)
    assert p.block.effective_stiffness == pytest.approx(3e5, rel=1e-12)
    assert p.name == "gelatin-glass, modified: block.effective_stiffness"
    q = load_parameters("gelatin-glass", {"block.stiffness": "400 kPa/m", "block.shear_modulus": "8 kPa"})
    assert (q.block.shear_modulus, q.block.height) == (8000.0, pytest.approx(0.02, rel=1e-12))
    assert q.block.stiffness == pytest.approx(4e5, rel=1e-12)
    with pytest.raises(ParameterError, match=r"block\.height and block\.stiffness both set the block's height"):
        load_parameters("gelatin-glass", {"block.height": "5 mm", "block.stiffness": "400 kPa/m"})
    with pytest.raises(ParameterError, match=r"block\.stiffness: expected a positive .*got '-4 kPa/m'"):
        load_parameters("gelatin-glass", {"block.stiffness": "-4 kPa/m"})
    with pytest.raises(ParameterError, match=r"expected one of: .*block\.stiffness, block\.effective_stiffness"):
        load_parameters("gelatin-glass", {"block.stifness": "4 kPa/m"})


def test_set_takes_the_stiffness_keys_and_an_export_reads_back_as_itself(capsys, tmp_path):
    status, out, err = run_main(capsys, "params", "show", "--set", "block.stiffness=200 kPa/m")
    assert status == 0, err
    assert "Parameter set gelatin-glass, modified: block.stiffness" in out
    assert "block.height (set by block.stiffness)" in out and "20 mm" in out  # 4 kPa / (200 kPa/m)
    path = tmp_path / "k.toml"
    status, _, err = run_main(capsys, "params", "export", "--set", "block.effective_stiffness=0.3 kPa/mm", "-o",
                              str(path))  # fmt: skip
    assert status == 0, err
    again = load_parameters(str(path))
    assert again.name == "gelatin-glass, modified: block.effective_stiffness"
    assert again.block.effective_stiffness == pytest.approx(3e5, rel=1e-12)


# ----------------------------------------------------------------------------- 5. a set read from a file


def test_a_file_carrying_a_built_in_name_with_other_values_is_named_so(params, capsys, tmp_path):
    exported = params.to_toml()
    assert 'bond_time = "224 us"' in exported
    unedited = tmp_path / "same.toml"
    unedited.write_text(exported, encoding="utf-8")
    assert load_parameters(str(unedited)).name == "gelatin-glass"  # what its name says: kept
    edited = tmp_path / "my.toml"
    edited.write_text(exported.replace('bond_time = "224 us"', 'bond_time = "250 us"'), encoding="utf-8")
    assert load_parameters(str(edited)).name == "gelatin-glass from my.toml, modified: bonds.bond_time"
    status, out, err = run_main(capsys, "critical", "--params", str(edited))
    assert status == 0, err
    assert "parameter set gelatin-glass from my.toml, modified: bonds.bond_time:" in out
    nameless = tmp_path / "noname.toml"
    nameless.write_text("\n".join(line for line in exported.splitlines() if not line.startswith("name")), "utf-8")
    assert load_parameters(str(nameless)).name == "noname.toml"


# ----------------------------------------------------------------------------- 6. the critical point's plot


def test_the_critical_points_plot_labels_both_axes_with_units(params):
    from matplotlib.figure import Figure

    point = stickslip.critical_point(params)
    ax = Figure().add_subplot()
    assert point.plot(ax=ax) is ax
    assert "(µm/s)" in ax.get_xlabel() and "(Pa)" in ax.get_ylabel()
    assert ax.get_xscale() == "log"
    # over a drawing of the user's, its scale and labels stay
    own = Figure().add_subplot()
    own.plot([1.0, 1e3], [200.0, 400.0])
    own.set_xlabel("V [um/s]")
    point.plot(ax=own)
    assert own.get_xlabel() == "V [um/s]" and own.get_xscale() == "linear" and "(Pa)" in own.get_ylabel()


def test_a_models_own_reader_names_a_set_changed_by_a_stiffness_key():
    """`run --model quasi-static --set block.stiffness=...` kept the name gelatin-glass (the model's reader set the
    height itself); it now reads the key as load_parameters does, and the height gives G/h = the stiffness."""
    model = stickslip.get_model("quasi-static")
    params = model.parameters(None, {"block.stiffness": "300 kPa/m"})
    assert params.name == "gelatin-glass, modified: block.stiffness"
    assert params.block.shear_modulus / params.block.height == pytest.approx(3e5, rel=1e-12)
    full = {**load_parameters("gelatin-glass").as_dict(), "block.effective_stiffness": 2e5}
    full.pop("block.height")
    assert model.parameters(None, full).block.effective_stiffness == pytest.approx(2e5, rel=1e-12)
