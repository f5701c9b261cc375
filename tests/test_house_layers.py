"""Issue 30 items 1 and 6: an engine's result becomes a Run through the interface (``stickslip.models.as_run``),
and docs/architecture.md's diagram names the real rooms in the layers of tests/test_import_graph.py.

The layer and loop rules themselves are tested on the package and on synthetic trees in test_import_graph.py.
"""

from __future__ import annotations

import itertools
import re
import sys
from pathlib import Path

import numpy as np
import pytest

import stickslip
from stickslip import protocols
from stickslip.errors import ParameterError
from stickslip.models import Rig, Run, as_run, get_model

sys.path.insert(0, str(Path(__file__).resolve().parent))
import test_import_graph as graph

ARCHITECTURE = Path(__file__).resolve().parents[1] / "docs" / "architecture.md"


# --------------------------------------------------------------------------- as_run
def test_an_engine_result_is_not_a_run_and_knows_no_interface() -> None:
    for result_type in (stickslip.Simulation, stickslip.transient.TransientResult, stickslip.rsf.RSFRun):
        assert not hasattr(result_type, "to_run")  # the adapter converts; the engine does not know Run


def test_as_run_of_a_transient_result_is_the_models_run_and_on_the_steady_curve() -> None:
    p = stickslip.load_parameters()
    v0 = 300e-6
    protocol = protocols.constant(v0, 0.3)
    result = stickslip.transient.run_transient(p, protocol, control="velocity", start="steady")
    run = as_run(result, protocol)
    direct = stickslip.run("transient", p, protocol, Rig("velocity"), start="steady")
    columns = get_model("transient").sweep_columns
    assert run.row(columns) == direct.row(columns)
    # independent of both: Eqs 6-8's steady stress at V0 (above Vc, steady sliding under velocity control)
    assert run.regime.kind == "steady"
    assert run.stress[-1] == pytest.approx(stickslip.steady_state(p, v0).stress, rel=1e-4)


def test_as_run_passes_a_run_and_refuses_what_no_engine_returns() -> None:
    result = stickslip.rsf.simulate(stickslip.rsf.rsf_params(0.005, 0.01, 10e-6), protocols.constant(1e-6, 5.0))
    run = as_run(result)
    assert isinstance(run, Run) and as_run(run) is run
    assert run.regime_name == result.regime.name and np.array_equal(run.time, result.time)
    with pytest.raises(ParameterError, match=r"result: expected a Simulation, TransientResult or RSFRun.*dict"):
        as_run({"time": [0.0]})


# --------------------------------------------------------------------------- the diagram
def mermaid(text: str) -> str:
    found = re.findall(r"```mermaid\n(.*?)```", text, flags=re.S)
    assert len(found) == 1, "docs/architecture.md holds one mermaid diagram"
    return found[0]


def diagram_layers(block: str) -> dict[str, list[str]]:
    """Layer name -> the rooms the diagram draws in it (``subgraph NAME`` ... ``end``, a room per ``id[...]``,
    several to a line when ``;`` separates them)."""
    layers: dict[str, list[str]] = {}
    current = None
    for line in block.splitlines():
        line = line.strip()
        if match := re.match(r"subgraph (\w+)", line):
            current = layers.setdefault(match.group(1), [])
        elif line == "end":
            current = None
        elif current is not None:
            current.extend(re.findall(r"(\w+)\[", line))
    return layers


def diagram_arrows(block: str) -> list[tuple[str, str]]:
    """The solid arrows (``a --> b --> c`` is two); a dotted ``-.->`` arrow is the designed lazy draw."""
    arrows = []
    for line in block.splitlines():
        if "-->" in line:
            names = [name.strip() for name in line.split("-->")]
            assert all(re.fullmatch(r"\w+", name) for name in names), f"not an arrow between names: {line!r}"
            arrows += list(itertools.pairwise(names))
    return arrows


def test_diagram_parser_reads_layers_rooms_and_arrows() -> None:
    block = (
        'flowchart TB\n  subgraph top["faces"]\n    cli["cli/"]; report["r"]\n  end\n  subgraph low\n    errors["x"]\n'
    )
    block += '  end\n  top --> low\n  cli --> errors\n  errors -. "lazy" .-> cli\n'
    assert diagram_layers(block) == {"top": ["cli", "report"], "low": ["errors"]}
    assert diagram_arrows(block) == [("top", "low"), ("cli", "errors")]
    assert diagram_arrows("a --> b --> c") == [("a", "b"), ("b", "c")]


def test_the_diagram_draws_every_room_in_its_layer_and_no_arrow_up() -> None:
    block = mermaid(ARCHITECTURE.read_text(encoding="utf-8"))
    drawn = diagram_layers(block)
    assert drawn == {name: list(rooms) for name, rooms in graph.LAYERS}, "the diagram's layers are not LAYERS"
    for rooms in drawn.values():
        for name in rooms:
            assert (graph.SOURCE / name).is_dir() or (graph.SOURCE / f"{name}.py").is_file(), f"no room {name}"
    level = {name: number for number, (name, _) in enumerate(graph.LAYERS)} | graph.layer_of()
    real = {(graph.room(s), graph.room(t)) for s, t, _ in graph.import_edges()}
    arrows = diagram_arrows(block)
    assert arrows, "the diagram draws no arrow"
    for source, target in arrows:
        assert level[source] >= level[target], f"{source} --> {target} runs up the layers"
        if source in graph.layer_of() and target in graph.layer_of():
            assert (source, target) in real, f"{source} --> {target}: no such import in the package"
