"""docs/api.md's table of column names: one set for every model's Run, the native results' own names mapped."""

from __future__ import annotations

import re
from pathlib import Path

import stickslip
from stickslip import protocols

DOC = Path(__file__).resolve().parents[1] / "docs" / "api.md"


def _table() -> list[list[str]]:
    text = DOC.read_text(encoding="utf-8")
    start = text.index("| `Run.to_frame()` and trace files")
    rows = []
    for line in text[start:].splitlines()[2:]:
        if not line.startswith("|"):
            break
        rows.append(re.findall(r"`([a-z_]+)`", line))
    return rows


def test_the_documented_names_are_the_frames_columns() -> None:
    runs = {
        "quasi-static": stickslip.run("quasi-static", "gelatin-glass", protocols.constant("50 um/s", "5 s")),
        "transient": stickslip.run(
            "transient", "gelatin-glass", protocols.constant("350 um/s", "0.01 s"), start="steady"
        ),
        "rsf": stickslip.run("rsf", {"a": 0.01, "b": 0.015, "dc": "10 um"}, protocols.constant("1 um/s", "1 s")),
    }
    rows = _table()
    assert len(rows) == 3
    for common, quasi, transient, rsf in rows:
        for model, native in (("quasi-static", quasi), ("transient", transient), ("rsf", rsf)):
            assert common in runs[model].to_frame().columns
            assert native in runs[model].native.to_frame().columns
