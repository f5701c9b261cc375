"""The command line's files and labels say what they hold (a black-box tester's findings):

* ``sweep -o sw.csv`` made a folder ``sw.csv/`` of Parquet chunks, exit 0, no CSV and no word said;
* ``params export -o ex.json`` wrote TOML, and ``--params set.json`` holding JSON was "malformed TOML: Invalid
  statement", without saying only TOML was read;
* the run's JSON said ``stiffness_from: parameters`` for ``run --model rsf --stiffness "1 1/um"``, nothing for a
  stiffness given in Pa/m, and the transient record said ``control: block`` and a stiffness under velocity control;
* ``params export --set bonds.bond_time=0.3ms`` wrote ``name = "gelatin-glass"``, which ``critical`` then printed
  beside another critical velocity.
"""

from __future__ import annotations

import json
import re
import sys
from importlib import resources

import pytest
from tests.cli_helpers import run_main

from stickslip.parameters import load_parameters

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

SWEEP = ("sweep", "--vary", "pulling_velocity=30um/s,300um/s", "--duration", "20 s", "--workers", "0", "--quiet")


def _vc(text: str) -> float:
    """Vc in m/s from ``critical``'s text (µm/s there)."""
    match = re.search(r"Vc\s*=\s*([0-9.eE+-]+) µm/s", text)
    assert match, text
    return float(match.group(1)) * 1e-6


def _builtin_mapping() -> dict:
    """The built-in gelatin-glass set as its TOML file holds it (read here, independently of the package's
    reader)."""
    text = (resources.files("stickslip") / "parameter_sets" / "gelatin-glass.toml").read_text(encoding="utf-8")
    return tomllib.loads(text)


# ----------------------------------------------------------------------------- 1. sweep -o names a folder


@pytest.mark.parametrize("name", ["sw.csv", "sw.json", "sw.parquet", "SW.CSV"])
def test_a_new_sweep_named_as_a_file_is_refused_in_one_line_before_any_work(capsys, tmp_path, name):
    target = tmp_path / name
    status, _, err = run_main(capsys, *SWEEP, "-o", str(target))
    assert status == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert f"-o {target}" in err and "a sweep writes a folder" in err
    folder = str(target.with_suffix(""))
    # what to give, and how to get the file asked for, naming its units (round 29: pandas' to_csv named none)
    assert f"-o {folder}" in err and f"stickslip.sweeps as s; s.write_table('{folder}', '{target}')" in err
    assert not target.exists() and not list(tmp_path.iterdir())  # nothing written


def test_a_sweep_folder_named_with_a_suffix_earlier_is_still_resumed(capsys, tmp_path):
    from stickslip.sweeps import build_spec, run_sweep

    old = tmp_path / "old.csv"  # as the command made it before it refused such a name
    spec = build_spec(["pulling_velocity=30um/s,300um/s"], model="quasi-static", duration="20 s")
    run_sweep(spec, old, workers=0)
    before = sorted(p.name for p in old.iterdir())
    status, _, err = run_main(capsys, *SWEEP[:-1], "-o", str(old))
    assert status == 0, err
    assert "2 already done" in err and "nothing to run" in err
    assert sorted(p.name for p in old.iterdir()) == before


def test_a_sweep_labelled_before_its_set_was_named_for_its_changes_is_resumed(capsys, tmp_path):
    """A --set sweep's label names the change now; a folder whose manifest holds the bare name (as the package
    wrote it before) is the same sweep: resumed, not refused as another specification."""
    import dataclasses

    from stickslip.sweeps import build_spec, run_sweep

    folder = tmp_path / "sw"
    spec = build_spec(["pulling_velocity=30um/s,300um/s"], model="quasi-static", duration="20 s",
                      overrides={"bonds.bond_time": "0.3 ms"})  # fmt: skip
    assert spec.label == "gelatin-glass, modified: bonds.bond_time"
    run_sweep(dataclasses.replace(spec, label="gelatin-glass"), folder, workers=0)
    status, _, err = run_main(capsys, *SWEEP[:-1], "--set", "bonds.bond_time=0.3 ms", "-o", str(folder))
    assert status == 0 and "nothing to run" in err, err
    manifest = json.loads((folder / "_manifest.json").read_text(encoding="utf-8"))
    assert manifest["specification"]["label"] == "gelatin-glass"
    # another value of the same key is another sweep, as ever
    status, _, err = run_main(capsys, *SWEEP, "--set", "bonds.bond_time=0.4 ms", "-o", str(folder))
    assert status == 2 and "another specification" in err and "bonds.bond_time" in err


# ----------------------------------------------------------------------------- 2. JSON and TOML parameter files


def test_params_export_writes_json_for_a_json_name_and_it_reads_back_to_the_set(capsys, tmp_path):
    path = tmp_path / "ex.json"
    status, _, err = run_main(capsys, "params", "export", "gelatin-glass", "-o", str(path))
    assert status == 0, err
    document = json.loads(path.read_text(encoding="utf-8"))  # JSON, not TOML
    truth = _builtin_mapping()
    assert document["name"] == "gelatin-glass"
    assert set(document) == set(truth)  # the same sections and descriptive entries as the set's own TOML
    assert load_parameters(str(path)).as_dict() == load_parameters("gelatin-glass").as_dict()  # every bit
    toml = tmp_path / "ex.toml"
    assert run_main(capsys, "params", "export", "gelatin-glass", "-o", str(toml))[0] == 0
    assert tomllib.loads(toml.read_text(encoding="utf-8"))["bonds"]["bond_time"] == truth["bonds"]["bond_time"]


def test_every_params_reader_takes_a_hand_written_json_file(capsys, tmp_path):
    """JSON written here from the set's own TOML (bond_time 0.3 ms): ``critical --params set.json`` gives the Vc of
    ``critical --set bonds.bond_time=0.3ms`` (it was "malformed TOML: Invalid statement")."""
    mapping = _builtin_mapping()
    mapping["bonds"]["bond_time"] = "0.3 ms"
    path = tmp_path / "set.json"
    path.write_text(json.dumps(mapping), encoding="utf-8")
    status, by_file, err = run_main(capsys, "critical", "--params", str(path))
    assert status == 0, err
    status, by_set, err = run_main(capsys, "critical", "--set", "bonds.bond_time=0.3ms")
    assert status == 0, err
    assert _vc(by_file) == pytest.approx(_vc(by_set), rel=1e-9)
    assert _vc(by_file) > 1.2 * _vc(run_main(capsys, "critical")[1])  # the file's value counted: Vc moved
    status, out, err = run_main(capsys, "params", "show", str(path))
    assert status == 0 and "300 µs" in out, err


def test_a_json_name_holding_toml_is_read_as_toml(capsys, tmp_path):
    """What ``params export -o x.json`` wrote before (TOML) is still read."""
    path = tmp_path / "old.json"
    path.write_text(load_parameters("gelatin-glass").to_toml(), encoding="utf-8")
    assert load_parameters(str(path)).as_dict() == load_parameters("gelatin-glass").as_dict()


#: a malformed file of each kind, and what the refusal says of how it was read
MALFORMED = [
    ("set.json", '{"bonds": {"bond_time": "224 us",}', "malformed JSON (read as JSON: its name ends in .json)"),
    ("set.toml", "[bonds\nbond_time = ", "malformed TOML (read as TOML: its name ends in .toml)"),
    ("set.cfg", "{ nonsense", "malformed JSON (read as JSON: its name ends in neither .json nor .toml and its text"),
    ("set.cfg", "bonds = ", "malformed TOML (read as TOML: its name ends in neither .json nor .toml"),
]


@pytest.mark.parametrize(("name", "text", "said"), MALFORMED)
def test_a_malformed_parameter_file_says_how_it_was_read_and_why(capsys, tmp_path, name, text, said):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    commands = [("critical", "--params", str(path)), ("params", "show", str(path))]
    if not name.endswith(".cfg"):  # rate-and-state reads a .json or .toml file through the same reader
        commands.append(("run", "--model", "rsf", "--params", str(path), "--v0", "1 um/s", "--duration", "1 s"))
    for command in commands:
        status, _, err = run_main(capsys, *command)
        assert status == 2 and err.count("\n") == 1 and said in err and "Traceback" not in err, (command, err)


def test_a_rate_and_state_file_exports_to_json_and_toml_and_both_read_back(capsys, tmp_path):
    from stickslip.cli.params_files import load_params_mapping
    from stickslip.rsf import RSFParams

    truth = {"a": 0.011, "mu0": 0.61, "v_ref": 1e-6, "stiffness": 4000.0,
             "states": [{"law": "aging", "b": 0.015, "dc": 2e-5}]}  # fmt: skip
    source = tmp_path / "slider.params.json"
    source.write_text(json.dumps({"parameters": truth}), encoding="utf-8")
    expected = RSFParams.from_dict(truth)
    for name in ("out.json", "out.toml"):
        status, _, err = run_main(capsys, "params", "export", str(source), "-o", str(tmp_path / name))
        assert status == 0, err
        assert RSFParams.from_dict(load_params_mapping(tmp_path / name)) == expected, name
    json.loads((tmp_path / "out.json").read_text(encoding="utf-8"))  # JSON indeed


def test_params_export_refuses_a_suffix_of_another_format(capsys, tmp_path):
    path = tmp_path / "set.yaml"
    status, _, err = run_main(capsys, "params", "export", "-o", str(path))
    assert status == 2 and err.count("\n") == 1 and ".toml" in err and ".json" in err and "set.yaml" in err, err
    assert not path.exists()


# ----------------------------------------------------------------------------- 4. an overridden set is renamed


def test_an_exported_set_with_set_values_is_named_for_them_and_read_back_so(capsys, tmp_path):
    path = tmp_path / "my.toml"
    status, _, err = run_main(capsys, "params", "export", "--set", "bonds.bond_time=0.3ms", "-o", str(path))
    assert status == 0, err
    assert tomllib.loads(path.read_text(encoding="utf-8"))["name"] == "gelatin-glass, modified: bonds.bond_time"
    status, out, err = run_main(capsys, "critical", "--params", str(path))
    assert status == 0, err
    assert "parameter set gelatin-glass, modified: bonds.bond_time:" in out
    status, out, _ = run_main(capsys, "critical", "--set", "bonds.bond_time=0.3ms")
    assert "parameter set gelatin-glass, modified: bonds.bond_time:" in out
    status, out, _ = run_main(capsys, "critical")
    assert "parameter set gelatin-glass:" in out  # without --set the name is the set's own
    # a further --set on the file adds its key; JSON says the same
    again = tmp_path / "again.json"
    status, _, err = run_main(capsys, "params", "export", "--params", str(path), "--set", "block.height=5 mm", "-o",
                              str(again))  # fmt: skip
    assert status == 0, err
    name = json.loads(again.read_text(encoding="utf-8"))["name"]
    assert name == "gelatin-glass, modified: bonds.bond_time, block.height"
    assert load_parameters(str(again)).name == name


def test_a_set_value_equal_to_the_sets_own_leaves_its_name():
    from stickslip.parameters import modified_name

    own = load_parameters("gelatin-glass")
    assert load_parameters("gelatin-glass", {"bonds.bond_time": "224 us"}).name == "gelatin-glass"
    assert load_parameters(own, {"bonds.bond_time": own.bonds.bond_time * 2}).name == (
        "gelatin-glass, modified: bonds.bond_time"
    )
    assert modified_name("x, modified: a", ["b", "a"]) == "x, modified: a, b"
    assert modified_name("x", []) == "x"


# ----------------------------------------------------------------------------- 3. the rig in one vocabulary


def _json(capsys, *args: str) -> dict:
    status, out, err = run_main(capsys, *args, "--json")
    assert status == 0, err
    return json.loads(out)


def test_the_spring_given_by_stiffness_is_said_to_come_from_the_rig_in_every_model(capsys):
    rsf = _json(capsys, "run", "--model", "rsf", "--v0", "10 um/s", "--duration", "5 s", "--stiffness", "1 1/um")
    assert rsf["rig"] == {"control": "spring", "stiffness": pytest.approx(1e6, rel=1e-12), "stiffness_from": "rig"}
    assert rsf["units"]["stiffness"] == "1/m"
    own = _json(capsys, "run", "--model", "rsf", "--v0", "10 um/s", "--duration", "5 s")
    assert own["rig"]["stiffness_from"] == "parameters"
    qs = _json(capsys, "run", "--model", "quasi-static", "--v0", "50 um/s", "--duration", "2 s", "--stiffness",
               "400 kPa/m")  # fmt: skip
    assert qs["rig"] == {"control": "spring", "stiffness": 4e5, "stiffness_from": "rig"}


def test_the_transient_record_says_the_rigs_control_and_no_spring_under_velocity_control(capsys):
    words = ("run", "--model", "transient", "--v0", "50 um/s", "--duration", "5 ms")
    rigid = _json(capsys, *words, "--control", "velocity")
    assert rigid["rig"] == {"control": "velocity", "stiffness": None}
    assert rigid["control"] == "velocity" and rigid["stiffness"] is None  # it said the block's 306.5 kPa/m
    spring = _json(capsys, *words)
    k_block = load_parameters("gelatin-glass").block.effective_stiffness  # Eq 17's K
    assert spring["rig"] == {"control": "spring", "stiffness": pytest.approx(k_block, rel=1e-12),
                             "stiffness_from": "parameters"}  # fmt: skip
    assert spring["control"] == "spring"  # it said "block", the solver's word
    assert spring["stiffness"] == pytest.approx(k_block, rel=1e-12)
