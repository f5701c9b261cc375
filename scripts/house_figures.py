"""The house's figures (docs/architecture.md, issue 30): rooms, floors, arrows, loops, lines, longest functions.

    .venv/bin/python scripts/house_figures.py [SRC_PACKAGE_DIR]

Drawn from the source with the import-graph checker of ``tests/test_import_graph.py`` (``ast``, nothing is
imported).  Definitions:

* a **module** is a ``.py`` file; a **room** is a top-level unit of the package (``stickslip.rsf``,
  ``stickslip.units``, ...);
* an **arrow** is an import of one module (or room) by another, of any kind (runtime, lazy, typing);
* a **loop** is a strongly connected component of the module graph with every kind of import; the designed
  one is a result's ``plot()`` importing its drawing from ``stickslip.plots`` lazily;
* **floors**: the rooms' graph with every import but the designed lazy draws, the imports of the root package
  (every module loads it first anyway: they are ``__version__``), each loop of rooms squeezed to one room; the
  number of rooms on its longest chain.  **Arrows in room loops** are the rooms' arrows inside such a loop (in
  any order of the rooms at least one per loop runs up);
* **arrows up the layers**: module imports of any kind, less the lazy draws, from a room to one of a higher
  layer of ``LAYERS`` (tests/test_import_graph.py); counted with no exemption.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import test_import_graph as graph


def room(module: str) -> str:
    return ".".join(module.split(".")[:2])


def rooms_graph(modules: dict[str, set[str]]) -> dict[str, set[str]]:
    rooms: dict[str, set[str]] = {}
    for source, targets in modules.items():
        rooms.setdefault(room(source), set()).update(room(t) for t in targets if room(t) != room(source))
    return rooms


def components(edges: dict[str, set[str]]) -> dict[str, int]:
    """Node -> the number of its strongly connected component (Kosaraju; singletons included)."""
    nodes = sorted(set(edges) | {t for targets in edges.values() for t in targets})
    order: list[str] = []
    seen: set[str] = set()
    for start in nodes:
        if start in seen:
            continue
        seen.add(start)
        stack = [(start, iter(sorted(edges.get(start, ()))))]
        while stack:
            node, following = stack[-1]
            target = next((t for t in following if t not in seen), None)
            if target is None:
                order.append(node)
                stack.pop()
            else:
                seen.add(target)
                stack.append((target, iter(sorted(edges.get(target, ())))))
    reverse: dict[str, set[str]] = {node: set() for node in nodes}
    for source, targets in edges.items():
        for target in targets:
            reverse[target].add(source)
    member: dict[str, int] = {}
    for start in reversed(order):
        if start in member:
            continue
        member[start] = number = len(set(member.values()))
        pending = [start]
        while pending:
            for source in reverse[pending.pop()]:
                if source not in member:
                    member[source] = number
                    pending.append(source)
    return member


def floors(edges: dict[str, set[str]]) -> tuple[int, int]:
    """(rooms on the longest chain with each loop squeezed to one, arrows inside loops)."""
    member = components(edges)
    squeezed: dict[int, set[int]] = {}
    for source, targets in edges.items():
        squeezed.setdefault(member[source], set()).update(member[t] for t in targets if member[t] != member[source])
    depth: dict[int, int] = {}

    def height(node: int) -> int:
        if node not in depth:
            depth[node] = 1 + max((height(t) for t in squeezed.get(node, ())), default=0)
        return depth[node]

    back = sum(1 for source, targets in edges.items() for t in targets if member[t] == member[source])
    return max(height(node) for node in squeezed), back


def longest_functions(root: Path, most: int = 10) -> list[tuple[int, str]]:
    found = []
    for path in sorted(root.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                where = f"{path.relative_to(root.parent)}:{node.name}"
                found.append((node.end_lineno - node.lineno + 1, where))
    return sorted(found, reverse=True)[:most]


def figures(root: Path = graph.SOURCE) -> dict[str, object]:
    every = graph.import_graph(root, graph.EVERY_KIND)
    undesigned = graph.import_graph(root, graph.EVERY_KIND, keep_lazy_draws=False)
    loops = graph.cycles(every)
    designed = [c for c in loops if c not in graph.cycles(undesigned)]
    kept = {source: {t for t in targets if graph.room(t)} for source, targets in undesigned.items()}
    chain, back = floors(rooms_graph(kept))
    lines = sum(len(p.read_text(encoding="utf-8").splitlines()) for p in root.rglob("*.py"))
    return {
        "modules": len(every),
        "rooms": len(rooms_graph(every)),
        "floors": chain,
        "module arrows": sum(len(t) for t in every.values()),
        "room arrows": sum(len(t) for t in rooms_graph(every).values()),
        "room arrows in room loops": back,
        "arrows up the layers": len(graph.upward_arrows(root)),
        "arrows up the layers, engines": len(graph.engine_breaches(root)),
        "loops": len(loops),
        "designed plot loops": len(designed),
        "other loops": [" -> ".join(c) for c in loops if c not in designed],
        "lines": lines,
        "functions over 100 lines": sum(1 for n, _ in longest_functions(root, 10_000) if n > 100),
        "longest functions": [f"{n} {where}" for n, where in longest_functions(root)],
    }


def main() -> None:
    root = Path(sys.argv[1]).resolve() if len(sys.argv) > 1 else graph.SOURCE
    for key, value in figures(root).items():
        if isinstance(value, list):
            print(f"{key}:")
            for item in value:
                print(f"  {item}")
        else:
            print(f"{key}: {value}")


if __name__ == "__main__":
    main()
