"""Each compiled kernel function is compiled once: no second specialisation for a literal argument.

numba compiles a jitted function once per distinct argument types, and a constant passed from a jitted caller
(``False``, ``1``, an omitted default, or a variable first assigned such a constant) is typed as a literal of its
own: ``_cohort_pass`` was compiled twice (``Literal[bool](False)`` and ``bool``), as were ``_balance_from``, the
glide's ``_select_initial_step`` and the steady march ``_march``.  Those duplicates cost ~10 s of the ~50 s a fresh
install's first stick-slip run spent compiling (docs/transient.md section 13).

A warm cache hides them (a caller loaded from the cache never asks for its callees' signatures), and a cold compile
costs ~40 s, so the check reads the source: no call between compiled functions that are not inlined passes a bool
or int constant, a variable first bound to one, or leaves a default out.
"""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import pytest

from stickslip.quasistatic import steady_kernel
from stickslip.transient import cells, glide, kernel, stability

MODULES = (kernel, glide, cells, stability, steady_kernel)
#: jitted by a name of their own (not from a tuple of strings)
NAMED = {"advance", "integrate", "march", "_phi1", "_response_sum"}
#: compiled on their own (inlined functions are typed in their caller, so a literal there costs nothing extra)
INLINED = set(kernel.INLINED) | {"_dense_at", "_stage", "_squares", "_scaled_norm"}


def _defs(module) -> dict[str, ast.FunctionDef]:  # type: ignore[no-untyped-def]
    tree = ast.parse(Path(inspect.getfile(module)).read_text(encoding="utf-8"))
    return {node.name: node for node in tree.body if isinstance(node, ast.FunctionDef)}


def _compiled_names() -> set[str]:
    """The functions the modules compile: the names their ``compiled()`` loops jit (strings in a tuple there)."""
    names: set[str] = set(NAMED)
    for module in MODULES:
        source = Path(inspect.getfile(module)).read_text(encoding="utf-8")
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value.startswith("_"):
                names.add(node.value)
    return names


def _literal(node: ast.expr) -> bool:
    return isinstance(node, ast.Constant) and isinstance(node.value, (bool, int))


def _first_bound_to_a_literal(function: ast.FunctionDef) -> set[str]:
    first: dict[str, bool] = {}
    for node in ast.walk(function):
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            first.setdefault(node.targets[0].id, _literal(node.value))
    return {name for name, literal in first.items() if literal}


def _rebound_just_before(function: ast.FunctionDef) -> dict[int, set[str]]:
    """id(call) -> names rebound to a non-constant earlier in the call's own statement list (the value that reaches
    the call is then that one alone, not a merge with the first constant)."""
    rebound: dict[int, set[str]] = {}
    for node in ast.walk(function):
        for field in ("body", "orelse"):
            statements = getattr(node, field, None)
            if not isinstance(statements, list):
                continue
            names: set[str] = set()
            for statement in statements:
                for call in ast.walk(statement):
                    if isinstance(call, ast.Call):
                        rebound.setdefault(id(call), set()).update(names)
                target = getattr(statement, "target", None) if isinstance(statement, ast.AugAssign) else None
                if isinstance(statement, ast.Assign) and len(statement.targets) == 1:
                    target = None if _literal(statement.value) else statement.targets[0]
                if isinstance(target, ast.Name):
                    names.add(target.id)
    return rebound


def problems(defs: dict[str, ast.FunctionDef], jitted: set[str]) -> list[str]:
    found = []
    for caller in defs.values():
        literal_names = _first_bound_to_a_literal(caller)
        rebound = _rebound_just_before(caller)
        for call in ast.walk(caller):
            if not (isinstance(call, ast.Call) and isinstance(call.func, ast.Name)):
                continue
            callee = call.func.id
            if callee not in defs or callee not in jitted or callee in INLINED:
                continue
            where = f"{caller.name} -> {callee} (line {call.lineno})"
            for k, arg in enumerate(call.args):
                if _literal(arg):
                    found.append(f"{where}: argument {k} is the constant {ast.unparse(arg)}")
                elif isinstance(arg, ast.Name) and arg.id in literal_names - rebound.get(id(call), set()):
                    found.append(f"{where}: argument {k} ({arg.id}) is first bound to a constant")
            if len(call.args) + len(call.keywords) < len(defs[callee].args.args):
                found.append(f"{where}: a default left out")
    return found


def test_no_compiled_call_passes_a_literal_or_leaves_a_default_out():
    jitted = _compiled_names()
    assert {"_cohort_pass", "_balance_from", "_select_initial_step", "_march", "_housekeeping", "_grown"} <= jitted
    found = []
    for module in MODULES:
        found += problems(_defs(module), jitted)
    assert not found, found


F = "def f(a, b=1.0):\n    return a\n"


@pytest.mark.parametrize(
    ("bad", "expected", "fine"),
    [
        ("return f(x, False)", "the constant False", "return f(x, x < 0)"),
        ("return f(x, 4)", "the constant 4", "return f(x, x)"),
        ("return f(x)", "a default left out", "return f(x, 1.0)"),
        # a loop merges the first constant with the later values (kernel.advance's ``cached``)
        (
            "c = False\n    for i in x:\n        f(i, c)\n        c = i > 0\n    return x",
            "first bound",
            "c = x < 0\n    for i in x:\n        f(i, c)\n        c = i > 0\n    return x",
        ),
        # rebound just before the call in its own block: only that value reaches it (glide.integrate's cap_steps)
        (
            "m = 4\n    if x:\n        m *= 2\n    return f(x, m)",
            "first bound",
            "m = 4\n    if x:\n        m *= 2\n        return f(x, m)\n    return x",
        ),
    ],
)
def test_the_check_finds_each_kind(bad: str, expected: str, fine: str) -> None:
    def found(body: str) -> list[str]:
        tree = ast.parse(F + f"def g(x):\n    {body}\n")
        return problems({n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}, {"f", "g"})

    assert len(found(bad)) == 1 and expected in found(bad)[0], found(bad)
    assert not found(fine), found(fine)
