"""The report runs its models through the model interface (issue 20, item 4), with the same numbers bit for bit."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import stickslip.models
from stickslip.parameters import load_parameters

REPORT = Path(__file__).resolve().parents[1] / "src" / "stickslip" / "report"
SOLVER_ENTRIES = {"run_transient", "simulate"}


@pytest.mark.parametrize("module", ["transient_section.py", "sweep_section.py"])
def test_report_sections_call_no_solver_directly(module: str) -> None:
    tree = ast.parse((REPORT / module).read_text(encoding="utf-8"))
    imported = {alias.name for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) for alias in node.names}
    assert not imported & SOLVER_ENTRIES, sorted(imported & SOLVER_ENTRIES)


def test_hold_peak_runs_the_transient_model_and_matches_the_solver_bit_for_bit(monkeypatch) -> None:
    from stickslip.protocols import segments
    from stickslip.report import transient_section
    from stickslip.transient import run_transient

    asked = []
    real = stickslip.models.get_model

    def spy(name):
        asked.append(name)
        return real(name)

    monkeypatch.setattr(stickslip.models, "get_model", spy)
    params = load_parameters("gelatin-glass")
    hold = 1e-3
    peak = transient_section._hold_peak(params, hold)
    assert asked == ["transient"]
    protocol = segments([(100e-6, 0.002), (0.0, hold), (100e-6, 0.015)])
    direct = run_transient(params, protocol, control="velocity", start="steady", rtol=transient_section.RTOL)
    assert peak == float(direct.stress[direct.time > 0.002 + hold].max())  # the same number, not a close one
