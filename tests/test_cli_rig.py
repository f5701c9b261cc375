"""One rig builder behind every run command: ``run``, ``compare --models``, ``simulate`` and ``transient`` read
``--stiffness`` and ``--control`` alike: the same K from the same spellings, the same one-line refusals.

The models' ``run`` is replaced by one that records the rig it is given and stops, so nothing is solved.
"""

from __future__ import annotations

import pytest

from cli_helpers import run_main
from stickslip.errors import ModelError
from stickslip.models.quasi_static import QuasiStatic
from stickslip.models.rsf import RSFModel
from stickslip.models.transient import Transient

PROTOCOL = ["--v0", "50 um/s", "--duration", "6 s"]
SPRING_COMMANDS = {
    "run": ["run", "--model", "quasi-static", *PROTOCOL],
    "compare --models": ["compare", "--models", "quasi-static,transient", *PROTOCOL],
    "simulate": ["simulate", *PROTOCOL],
    "transient": ["transient", *PROTOCOL],
}
#: 600 kPa/m, written as a user might
SPELLINGS = ["600 kPa/m", "6e5 Pa/m", "0.6 Pa/um", "600e3 N/m^3", "600 kPa m^-1", "0.6 MPa/m"]


@pytest.fixture
def rigs(monkeypatch):
    seen = []

    def record(self, params, protocol, rig=None, **settings):
        seen.append(rig)
        raise ModelError("stopped by the test")

    for model in (QuasiStatic, Transient, RSFModel):
        monkeypatch.setattr(model, "run", record)
    return seen


@pytest.mark.parametrize("spelling", SPELLINGS)
def test_every_run_command_reads_the_same_stiffness_from_the_same_spelling(spelling, rigs, capsys):
    for command, argv in SPRING_COMMANDS.items():
        rigs.clear()
        code, _, err = run_main(capsys, *argv, "--stiffness", spelling)
        assert code != 0 and "stopped by the test" in err, (command, err)
        assert rigs and all(r.control == "spring" for r in rigs), command
        assert [r.stiffness for r in rigs] == pytest.approx([600e3] * len(rigs), rel=1e-12), command


@pytest.mark.parametrize(
    ("stiffness", "expected"),
    [("600000", "--stiffness 600000: "), ("1e-3 1/um", "--stiffness"), ("-5 kPa/m", "expected a positive value")],
)
def test_every_run_command_refuses_a_stiffness_in_the_same_words(stiffness, expected, rigs, capsys):
    errors = {}
    for command, argv in SPRING_COMMANDS.items():
        code, _, errors[command] = run_main(capsys, *argv, "--stiffness", stiffness)
        assert code == 2 and errors[command].count("\n") == 1 and expected in errors[command], (command, errors)
    assert len(set(errors.values())) == 1, errors
    assert not rigs


VELOCITY_COMMANDS = {
    "run": ["run", "--model", "transient", "--control", "velocity", *PROTOCOL, "--stiffness", "1 MPa/m"],
    "run rsf": ["run", "--model", "rsf", "--control", "velocity", *PROTOCOL, "--stiffness", "1e-3 1/um"],
    "compare --models": [
        "compare", "--models", "transient,rsf", "--control", "velocity", *PROTOCOL, "--stiffness", "1 MPa/m",
    ],
    "transient": ["transient", "--control", "velocity", *PROTOCOL, "--stiffness", "1 MPa/m"],
}  # fmt: skip


def test_a_stiffness_under_velocity_control_is_refused_alike_in_any_unit(rigs, capsys):
    """Before: ``run --model rsf`` took a stiffness in friction per slip under velocity control and dropped it."""
    errors = {}
    for command, argv in VELOCITY_COMMANDS.items():
        code, _, errors[command] = run_main(capsys, *argv)
        assert code == 2 and "under --control velocity the rig is rigid" in errors[command], (command, errors)
    assert len(set(errors.values())) == 1, errors
    assert not rigs
