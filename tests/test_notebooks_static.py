"""The example notebooks, checked without running them (CI runs them: scripts/run-notebooks.py).

Each must be a valid nbformat-4 notebook for the ``python3`` kernel, stored without outputs, open with a markdown
cell that states its measured run time, and hold only code cells that compile (IPython magics and shell lines,
``%``/``!``, left out).
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
NOTEBOOKS = sorted(EXAMPLES.glob("*.ipynb"))
#: "Run time: 15 s", "run time: about 1 min", "Run time: 14–49 s" -- numbers with a unit of time, not a placeholder
RUN_TIME = re.compile(r"run time:?\**\s*(about\s+)?\d+(\.\d+)?(\s*[–-]\s*\d+(\.\d+)?)?\s*(s|min)\b", re.IGNORECASE)


def test_there_are_notebooks() -> None:
    assert len(NOTEBOOKS) >= 4, f"expected at least four example notebooks in {EXAMPLES}"


@pytest.fixture(params=NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def notebook(request: pytest.FixtureRequest) -> tuple[Path, Any]:
    # plain JSON, so that these checks run where nbformat (the docs extra) is not installed
    return request.param, json.loads(request.param.read_text(encoding="utf-8"), object_hook=_Cell)


class _Cell(dict):
    """A JSON object whose keys read as attributes too (cell.source), as nbformat's nodes do."""

    def __getattr__(self, key: str) -> Any:
        try:
            value = self[key]
        except KeyError as error:
            raise AttributeError(key) from error
        return "".join(value) if key == "source" and isinstance(value, list) else value


def test_valid_nbformat_4_for_python3(notebook: tuple[Path, Any]) -> None:
    path, nb = notebook
    assert nb.nbformat == 4, path.name
    assert nb.metadata["kernelspec"]["name"] == "python3", path.name
    assert all(cell.cell_type in ("markdown", "code", "raw") for cell in nb.cells), path.name
    nbformat = pytest.importorskip("nbformat")  # the schema itself, where the docs extra is installed
    nbformat.validate(nbformat.read(path, as_version=nbformat.NO_CONVERT))


def test_no_outputs_stored(notebook: tuple[Path, Any]) -> None:
    path, nb = notebook
    for i, cell in enumerate(nb.cells):
        if cell.cell_type == "code":
            assert cell.outputs == [], f"{path.name} cell {i}: outputs stored"
            assert cell.execution_count is None, f"{path.name} cell {i}: execution count stored"


def test_first_cell_states_the_run_time(notebook: tuple[Path, Any]) -> None:
    path, nb = notebook
    first = nb.cells[0]
    assert first.cell_type == "markdown", f"{path.name}: the first cell is not markdown"
    assert RUN_TIME.search(first.source), f"{path.name}: the first cell states no measured run time"


def test_ends_with_what_it_shows(notebook: tuple[Path, Any]) -> None:
    path, nb = notebook
    last = nb.cells[-1]
    assert last.cell_type == "markdown" and "what this shows" in last.source.lower(), path.name


def test_code_cells_compile(notebook: tuple[Path, Any]) -> None:
    path, nb = notebook
    for i, cell in enumerate(nb.cells):
        if cell.cell_type != "code":
            continue
        source = "\n".join(line for line in cell.source.splitlines() if not line.lstrip().startswith(("%", "!")))
        compile(source, f"{path.name}[cell {i}]", "exec")


def test_no_repository_paths(notebook: tuple[Path, Any]) -> None:
    # shipped data come through the package, so the notebooks run the same from an installed wheel
    path, nb = notebook
    for i, cell in enumerate(nb.cells):
        if cell.cell_type == "code":
            assert "src/stickslip" not in cell.source, f"{path.name} cell {i}: reads a path inside the checkout"
