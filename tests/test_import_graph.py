"""The package's import graph: no cycles, and the core never imports a face (matplotlib) at import time.

The graph is built from the source with :mod:`ast`, not by importing.  Each import is one of three kinds:
``runtime`` (it runs when the module is imported: module level, class bodies, ``if``/``try``/``with`` blocks),
``lazy`` (inside a function: it runs when the function is called) and ``typing`` (under ``if TYPE_CHECKING:``:
it never runs).  ``from P import name`` is an edge to the module ``P.name`` when that is a module of the
package, else to ``P``.

Two rules: the graph of runtime imports has no cycle (a cycle there is an ImportError waiting for the wrong
import order); and with every import counted, every loop through drawing code is the designed one, a result's
``plot()`` importing its drawing lazily from :mod:`stickslip.plots`, which may name the result back.  The second
rule is the one the six cycles of issue 20 broke (results and their plot modules, spread over nine places,
importing each other lazily and for typing); with runtime imports only, that code had no cycle either.

The house's rules (issue 30 item 1, docs/architecture.md): the package's rooms (its top-level modules and
subpackages) stand in :data:`LAYERS`, lowest first; no import of any kind runs up the layers but the designed
lazy draws and the :data:`UPWARD` arrows named with their reason; the engines import nothing above them, with
no exception at all; and with every import counted, the only loops are the designed lazy plot ones.
"""

from __future__ import annotations

import ast
import functools
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

import pytest

PACKAGE = "stickslip"
SOURCE = Path(__file__).resolve().parents[1] / "src" / PACKAGE
#: Packages that draw (faces): only they may import matplotlib at module level.
FACES = ("stickslip.plots", "stickslip.report", "stickslip.cli")


def module_name(path: Path, root: Path = SOURCE) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def package_modules(root: Path = SOURCE) -> dict[str, Path]:
    return {module_name(path, root): path for path in sorted(root.rglob("*.py"))}


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


RUNTIME, LAZY, TYPING = "runtime", "lazy", "typing"
EVERY_KIND = frozenset({RUNTIME, LAZY, TYPING})
#: The package every result draws through (lazily): the one allowed way back from the core to a face.
PLOTS = "stickslip.plots"
#: Names the plot modules had before stickslip.plots (plotting.py, cycle_plots.py, analysis/plots.py, ...).
DRAWING_NAMES = frozenset({"plots", "plotting", "cycle_plots"})


def import_statements(body: list[ast.stmt], kind: str = RUNTIME) -> Iterator[tuple[ast.Import | ast.ImportFrom, str]]:
    """Every import statement of ``body`` with its kind (``runtime``, ``lazy`` or ``typing``)."""
    for node in body:
        if isinstance(node, ast.Import | ast.ImportFrom):
            yield node, kind
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            yield from import_statements(node.body, TYPING if kind == TYPING else LAZY)
        elif isinstance(node, ast.If):
            yield from import_statements(node.body, TYPING if _is_type_checking(node.test) else kind)
            yield from import_statements(node.orelse, kind)
        elif isinstance(node, ast.Try | ast.TryStar):
            for block in (node.body, node.orelse, node.finalbody, *(h.body for h in node.handlers)):
                yield from import_statements(block, kind)
        elif isinstance(node, ast.With | ast.AsyncWith | ast.For | ast.AsyncFor | ast.While | ast.ClassDef):
            yield from import_statements(node.body, kind)
            yield from import_statements(getattr(node, "orelse", []), kind)


def _absolute(node: ast.ImportFrom, module: str, is_package: bool) -> str:
    if node.level == 0:
        return node.module or ""
    base = module.split(".") if is_package else module.split(".")[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join([*base, node.module] if node.module else base)


@functools.lru_cache(maxsize=4096)
def _statements(path: Path, mtime_ns: int) -> tuple[tuple[ast.Import | ast.ImportFrom, str], ...]:
    """The import statements of a file, parsed once per version of it (the tests walk the package many times)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    return tuple(import_statements(tree.body))


def imported_modules(
    module: str, path: Path, known: set[str], kinds: Iterable[str] = (RUNTIME,)
) -> Iterator[tuple[str, str]]:
    """(imported module, kind) for every import of ``module`` of one of ``kinds``, of any package."""
    wanted = set(kinds)
    for node, kind in _statements(path, path.stat().st_mtime_ns):
        if kind not in wanted:
            continue
        if isinstance(node, ast.Import):
            yield from ((alias.name, kind) for alias in node.names)
            continue
        target = _absolute(node, module, path.name == "__init__.py")
        for alias in node.names:
            submodule = f"{target}.{alias.name}"
            yield (submodule if submodule in known else target), kind


def _in(module: str, package: str) -> bool:
    return module == package or module.startswith(package + ".")


def is_drawing(module: str) -> bool:
    """Drawing code: stickslip.plots, or a module named as the package's plot modules were before it."""
    return _in(module, PLOTS) or module.rsplit(".", 1)[-1] in DRAWING_NAMES


def is_lazy_draw(source: str, target: str, kind: str) -> bool:
    """A result (or any module outside the plots) importing its drawing from stickslip.plots inside a function."""
    return kind == LAZY and _in(target, PLOTS) and not _in(source, PLOTS)


def import_graph(
    root: Path = SOURCE, kinds: Iterable[str] = (RUNTIME,), keep_lazy_draws: bool = True
) -> dict[str, set[str]]:
    """Module -> the package's modules it imports by one of ``kinds`` (without the lazy draws, if so asked)."""
    modules = package_modules(root)
    known = set(modules)
    kinds = tuple(kinds)
    return {
        name: {
            target
            for target, kind in imported_modules(name, path, known, kinds)
            if target in known and target != name and (keep_lazy_draws or not is_lazy_draw(name, target, kind))
        }
        for name, path in modules.items()
    }


def cycles(graph: dict[str, set[str]], involving: Callable[[str], bool] | None = None) -> list[list[str]]:
    """One cycle through every strongly connected component of more than one module (Tarjan); with
    ``involving``, only through the components with a module for which it is true."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for target in sorted(graph.get(node, ())):
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in on_stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                components.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    if involving is not None:
        components = [c for c in components if any(involving(member) for member in c)]
    return [_cycle_within(graph, set(component)) for component in components]


def _cycle_within(graph: dict[str, set[str]], component: set[str]) -> list[str]:
    """A shortest path from the component's first module back to itself, staying inside the component."""
    start = min(component)
    paths = {start: [start]}
    frontier = [start]
    while frontier:
        following = []
        for node in frontier:
            for target in sorted(graph[node] & component):
                if target == start:
                    return [*paths[node], start]
                if target not in paths:
                    paths[target] = [*paths[node], target]
                    following.append(target)
        frontier = following
    raise AssertionError(f"not a cycle: {sorted(component)}")


def matplotlib_importers(root: Path = SOURCE) -> list[str]:
    """Modules outside the faces that import matplotlib at import time."""
    modules = package_modules(root)
    known = set(modules)
    return sorted(
        name
        for name, path in modules.items()
        if not any(_in(name, face) for face in FACES)
        and any(target.split(".")[0] == "matplotlib" for target, _ in imported_modules(name, path, known))
    )


#: The package's rooms, lowest layer first; a module may import its own layer and those below it.  The root
#: (``stickslip/__init__.py``, the front door that re-exports) is in no layer: importing any module of the
#: package runs it first, so an import of it (``__version__``) adds no dependency.
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("plumbing", ("errors", "units", "fileio", "tables", "numerics", "reprs", "display", "progress",
                  "trace_columns", "regimes")),
    ("definitions", ("parameters", "columns", "protocols")),
    ("engines", ("quasistatic", "transient", "rsf")),
    ("interface", ("models",)),
    ("uses", ("analysis", "fitting", "studies", "sweeps")),
    ("faces", ("plots", "report", "cli", "__main__")),
)  # fmt: skip
ENGINES = "engines"
#: Arrows that run up the layers, each with its reason (source module, target module): none today.
UPWARD: dict[tuple[str, str], str] = {}


def room(module: str) -> str:
    """The top-level unit of the package a module belongs to (``stickslip.rsf.fit`` -> ``rsf``; the root: "")."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def layer_of(layers: tuple[tuple[str, tuple[str, ...]], ...] = LAYERS) -> dict[str, int]:
    return {name: number for number, (_, rooms) in enumerate(layers) for name in rooms}


def import_edges(root: Path = SOURCE) -> set[tuple[str, str, str]]:
    """(source, target, kind) for every import of one package module by another, of every kind."""
    modules = package_modules(root)
    known = set(modules)
    return {
        (name, target, kind)
        for name, path in modules.items()
        for target, kind in imported_modules(name, path, known, EVERY_KIND)
        if target in known and target != name
    }


def upward_arrows(
    root: Path = SOURCE,
    layers: tuple[tuple[str, tuple[str, ...]], ...] = LAYERS,
    allowed: Iterable[tuple[str, str]] = (),
    aliases: Iterable[str] = (),
) -> list[tuple[str, str, str]]:
    """Imports (of any kind) from a module to one of a higher layer, less the lazy draws, the ``allowed`` pairs
    and imports by the ``aliases``; imports of or by the root are no arrows (see :data:`LAYERS`)."""
    level, allowed, aliases = layer_of(layers), set(allowed), set(aliases)
    return sorted(
        (source, target, kind)
        for source, target, kind in import_edges(root)
        if room(source) and room(target) and level[room(target)] > level[room(source)]
        and not is_lazy_draw(source, target, kind) and (source, target) not in allowed and source not in aliases
    )  # fmt: skip


def engine_breaches(
    root: Path = SOURCE,
    layers: tuple[tuple[str, tuple[str, ...]], ...] = LAYERS,
    aliases: Iterable[str] = (),
) -> list[tuple[str, str, str]]:
    """Imports (runtime, lazy or typing) by an engine's module of a module above the engines, less the lazy draws."""
    level = layer_of(layers)
    engines = next(number for number, (name, _) in enumerate(layers) if name == ENGINES)
    return [arrow for arrow in upward_arrows(root, layers, aliases=aliases) if level[room(arrow[0])] == engines]


def unplaced_rooms(root: Path = SOURCE, layers: tuple[tuple[str, tuple[str, ...]], ...] = LAYERS) -> list[str]:
    """Rooms of the package in no layer (a new room must be given one)."""
    return sorted({room(name) for name in package_modules(root)} - set(layer_of(layers)) - {""})


def unreached_modules(root: Path = SOURCE, entries: Iterable[str] = ()) -> list[str]:
    """Modules no import of any kind reaches from ``entries`` (a module reached loads its parent packages too)."""
    graph = import_graph(root, EVERY_KIND)
    seen: set[str] = set()
    pending = list(entries)
    while pending:
        module = pending.pop()
        if module in seen or module not in graph:
            continue
        seen.add(module)
        parent = module.rsplit(".", 1)[0]
        pending.extend([*graph[module], *([parent] if parent != module else [])])
    return sorted(set(graph) - seen)


# --------------------------------------------------------------------------- the checker itself
def _tree(tmp_path: Path, files: dict[str, str]) -> Path:
    root = tmp_path / PACKAGE
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return root


def test_checker_finds_a_result_plot_cycle_and_ignores_lazy_and_type_checking_imports(tmp_path: Path) -> None:
    root = _tree(
        tmp_path,
        {
            "__init__.py": "",
            "sub/__init__.py": "",
            "sub/result.py": "from .plots import draw\nclass R:\n    def plot(self):\n        from . import other\n",
            "sub/plots.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .other import X\n"
            "from stickslip.sub import result\n",
            "sub/other.py": "import matplotlib.pyplot\ntry:\n    from .plots import draw\nexcept ImportError:\n"
            "    pass\n",
        },
    )
    graph = import_graph(root)
    assert graph["stickslip.sub.result"] == {"stickslip.sub.plots"}  # the lazy import inside plot() is no edge
    assert graph["stickslip.sub.plots"] == {"stickslip.sub.result"}  # TYPE_CHECKING is no edge; from P import mod
    assert graph["stickslip.sub.other"] == {"stickslip.sub.plots"}  # an import inside try counts
    assert cycles(graph) == [["stickslip.sub.plots", "stickslip.sub.result", "stickslip.sub.plots"]]
    assert matplotlib_importers(root) == ["stickslip.sub.other"]


def test_checker_resolves_relative_imports_of_packages_and_parents(tmp_path: Path) -> None:
    root = _tree(
        tmp_path,
        {
            "__init__.py": "from .a import b\n",
            "a/__init__.py": "from ..c import thing\nfrom . import b\n",
            "a/b.py": "from .. import c\n",
            "c.py": "x = 1\n",
        },
    )
    assert import_graph(root) == {
        "stickslip": {"stickslip.a.b"},
        "stickslip.a": {"stickslip.c", "stickslip.a.b"},
        "stickslip.a.b": {"stickslip.c"},  # `from .. import c`: c is a module of the package
        "stickslip.c": set(),
    }


def test_checker_separates_runtime_lazy_and_typing_imports(tmp_path: Path) -> None:
    root = _tree(
        tmp_path,
        {
            "__init__.py": "",
            "plots/__init__.py": "",
            "plots/things.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from ..result import R\n"
            "def draw():\n    from ..other import helper\n",
            "result.py": "class R:\n    def plot(self):\n        from .plots.things import draw\n",
            "other.py": "def helper():\n    from .result import R\n",
        },
    )
    assert cycles(import_graph(root)) == []
    everything = import_graph(root, EVERY_KIND)
    assert everything["stickslip.result"] == {"stickslip.plots.things"}
    assert len(cycles(everything)) == 1
    assert cycles(everything, involving=is_drawing) == cycles(everything)
    assert cycles(everything, involving=lambda module: module.endswith("nothing")) == []
    # without the result's lazy draw the loop is broken; the plots' lazy import of other.py is no draw
    assert cycles(import_graph(root, EVERY_KIND, keep_lazy_draws=False)) == []
    assert import_graph(root, EVERY_KIND, keep_lazy_draws=False)["stickslip.plots.things"] == {
        "stickslip.result",
        "stickslip.other",
    }


_HOUSE = (
    ("plumbing", ("errors",)),
    ("engines", ("engine",)),
    ("interface", ("models",)),
    ("faces", ("plots", "cli")),
)


def test_checker_finds_every_kind_of_arrow_up_from_an_engine_but_not_its_lazy_draw(tmp_path: Path) -> None:
    root = _tree(
        tmp_path,
        {
            "__init__.py": "from .models import run\n__version__ = '1'\n",
            "errors.py": "def refuse():\n    from .engine import result\n",  # plumbing lazily up to an engine
            "models.py": "from .engine.result import R\ndef run():\n    return R()\n",
            "engine/__init__.py": "from .result import R\n",
            "engine/result.py": "from typing import TYPE_CHECKING\nfrom .. import __version__\n"
            "if TYPE_CHECKING:\n    from ..models import run\nclass R:\n    def to_run(self):\n"
            "        from ..models import run\n    def plot(self):\n        from ..plots.draw import draw\n",
            "engine/old.py": "from ..cli import main\n",
            "plots/__init__.py": "",
            "plots/draw.py": "from ..engine.result import R\ndef draw(r: R):\n    pass\n",
            "cli.py": "from .models import run\ndef main():\n    pass\n",
        },
    )
    breaches = engine_breaches(root, _HOUSE)
    assert breaches == [
        ("stickslip.engine.old", "stickslip.cli", RUNTIME),
        ("stickslip.engine.result", "stickslip.models", LAZY),
        ("stickslip.engine.result", "stickslip.models", TYPING),
    ]  # the lazy draw into plots and the root's __version__ are no breach
    assert engine_breaches(root, _HOUSE, aliases={"stickslip.engine.old"}) == breaches[1:]
    up = upward_arrows(root, _HOUSE)
    assert ("stickslip.errors", "stickslip.engine.result", LAZY) in up and len(up) == 4
    assert upward_arrows(root, _HOUSE, allowed={("stickslip.errors", "stickslip.engine.result")}) == breaches
    assert unplaced_rooms(root, _HOUSE) == []
    assert unplaced_rooms(root, _HOUSE[1:]) == ["errors"]


def test_checker_finds_loops_of_lazy_and_typing_imports_but_lets_the_designed_draw_be(tmp_path: Path) -> None:
    root = _tree(
        tmp_path,
        {
            "__init__.py": "",
            "fit.py": "class Fit:\n    def report(self):\n        from .text import report\n"
            "    def plot(self):\n        from .plots.fits import draw\n",
            "text.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .fit import Fit\n",
            "plots/__init__.py": "",
            "plots/fits.py": "from ..fit import Fit\n",
        },
    )
    assert cycles(import_graph(root)) == []  # no loop at import time
    loops = cycles(import_graph(root, EVERY_KIND, keep_lazy_draws=False))
    assert loops == [["stickslip.fit", "stickslip.text", "stickslip.fit"]]  # the report's loop, not the draw's
    assert len(cycles(import_graph(root, EVERY_KIND))) == 1  # with the draw: one component of three modules


def test_checker_finds_a_module_no_entry_reaches(tmp_path: Path) -> None:
    root = _tree(
        tmp_path,
        {
            "__init__.py": "",
            "cli/__init__.py": "",
            "cli/main.py": "def main():\n    from ..sub.used import f\n",
            "sub/__init__.py": "",
            "sub/used.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .typed import T\n",
            "sub/typed.py": "T = int\n",
            "sub/dead.py": "from .used import f\n",
        },
    )
    assert unreached_modules(root, ["stickslip.cli.main"]) == ["stickslip.sub.dead"]


# --------------------------------------------------------------------------- the package
def _shown(found: list[list[str]]) -> str:
    return "\n".join(" -> ".join(cycle) for cycle in found)


def test_the_package_has_no_import_cycles_at_import_time() -> None:
    found = cycles(import_graph())
    assert not found, "import cycles (module-level imports):\n" + _shown(found)


def test_every_loop_through_drawing_code_is_a_result_drawing_lazily_through_stickslip_plots() -> None:
    found = cycles(import_graph(kinds=EVERY_KIND, keep_lazy_draws=False), involving=is_drawing)
    assert not found, (
        "import cycles through drawing code (every import counted, less lazy imports into stickslip.plots from"
        " outside it):\n" + _shown(found)
    )


def test_the_core_never_imports_matplotlib_at_import_time() -> None:
    found = matplotlib_importers()
    assert not found, f"modules outside {', '.join(FACES)} import matplotlib at module level: {', '.join(found)}"


@pytest.mark.parametrize("name", ["stickslip.plots.steady", "stickslip.sweeps.store"])
def test_the_checker_sees_the_real_package(name: str) -> None:
    assert name in import_graph()


def test_every_room_of_the_package_stands_in_a_layer() -> None:
    assert not unplaced_rooms(), f"rooms in no layer of LAYERS: {unplaced_rooms()}"


def test_no_engine_imports_anything_above_the_engines_by_any_kind_of_import() -> None:
    found = engine_breaches()
    assert not found, "engine modules importing the interface or above:\n" + "\n".join(map(str, found))


def test_no_import_runs_up_the_layers_but_the_named_ones() -> None:
    found = upward_arrows(allowed=UPWARD)
    assert not found, "imports running up the layers:\n" + "\n".join(map(str, found))
    every = {(source, target) for source, target, _ in import_edges()}
    assert set(UPWARD) <= every, f"named arrows that no longer exist: {sorted(set(UPWARD) - every)}"


def test_the_only_loops_of_any_kind_of_import_are_the_designed_lazy_draws() -> None:
    found = cycles(import_graph(kinds=EVERY_KIND, keep_lazy_draws=False))
    assert not found, "import loops (every import counted, less the lazy draws into stickslip.plots):\n" + _shown(found)


def test_every_module_is_reached_from_the_command_line_or_the_public_api() -> None:
    """A module no user path reaches (the ``stickslip`` command, ``python -m stickslip``, ``import stickslip``) is
    dead or misplaced."""
    found = unreached_modules(entries=["stickslip.cli.main", "stickslip.__main__", PACKAGE])
    assert not found, f"modules no user path reaches: {sorted(found)}"
