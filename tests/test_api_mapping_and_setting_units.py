"""Two spellings a user reaches for (round-25 tester): ``stickslip.run`` with a mapping of the bond model's
parameters (its docstring promised one; it was read as a set's name), and ``--setting KEY=VALUE`` with a unit of
any dimension (``start_velocity="150 um/s"`` was refused while ``start_velocity=150e-6`` ran)."""

from __future__ import annotations

import json

import pytest
from tests.cli_helpers import run_main

import stickslip
from stickslip.errors import ParameterError
from stickslip.protocols import constant

SLOW = constant(100e-6, 30.0)


def _peak(spec):
    return stickslip.run("quasi-static", spec, SLOW).peak


def test_a_mapping_of_section_keys_nested_sections_or_a_whole_exported_set_is_read(capsys):
    by_set = _peak(stickslip.load_parameters("gelatin-glass", overrides={"bonds.bond_time": "200 us"}))
    assert _peak({"bonds.bond_time": "200 us"}) == by_set
    assert _peak({"bonds": {"bond_time": "200 us"}}) == by_set
    assert _peak({"bonds.bond_time": 2e-4}) == pytest.approx(by_set, rel=1e-12)
    assert by_set != _peak(None)  # the override changes the answer: the test can tell a mapping that is ignored
    import tomllib

    status, exported, _ = run_main(capsys, "params", "export", "gelatin-glass")
    assert status == 0
    assert _peak(tomllib.loads(exported)) == _peak(None)  # the whole set as a dict, its name and description too


def test_a_misspelt_key_in_a_mapping_is_named():
    with pytest.raises(ParameterError, match=r"bonds\.bond_tme"):
        _peak({"bonds": {"bond_tme": "200 us"}})


def test_a_setting_takes_a_velocity_with_its_unit(capsys):
    runs = []
    for value in ("150 um/s", "150e-6"):
        status, out, err = run_main(capsys, "run", "--model", "transient", "--v0", "100 um/s", "--duration", "0.05 s",
                                    "--start", "steady", "--setting", f"start_velocity={value}", "--json")  # fmt: skip
        assert status == 0, err
        runs.append(json.loads(out))
    assert runs[0]["final_stress"] == runs[1]["final_stress"] and runs[0]["end_time"] == 0.05
