"""Is ``stickslip.sweep`` being called from a script's top level without the ``__main__`` guard?

dask starts its local worker processes with multiprocessing's "spawn" method, which imports the calling script
again in every worker (as ``__mp_main__``).  A script that calls ``stickslip.sweep(...)`` at its top level, as
the README's one-liners do, would then start a sweep in every worker while it is still starting up: each
worker dies with a traceback and the sweep fails.  Found before any worker starts, the sweep runs in the
calling process instead and says so in one line.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path
from types import FrameType

__all__ = ["unguarded_script_line"]

#: multiprocessing start methods that import the main script again in each new process
REIMPORTING_METHODS = frozenset({"spawn", "forkserver"})


def unguarded_script_line(start_method: str | None = None) -> tuple[str, int] | None:
    """(script, line) of the top-level statement of ``__main__`` now running, if a new worker would rerun it.

    None when the workers would not: no script file (interactive, ``python -c``, a notebook), a start method
    that forks, or a call under ``if __name__ == "__main__":``.
    """
    method = start_method if start_method is not None else _dask_start_method()
    main = sys.modules.get("__main__")
    script = getattr(main, "__file__", None)
    if method not in REIMPORTING_METHODS or main is None or not script:
        return None
    frame = _top_level_frame(main.__dict__)
    if frame is None:
        return None
    line = frame.f_lineno
    try:
        tree = ast.parse(Path(script).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, SyntaxError, ValueError):
        return None
    if any(_is_main_guard(node) and node.lineno <= line <= (node.end_lineno or line) for node in ast.walk(tree)):
        return None
    return str(script), line


def _dask_start_method() -> str:
    try:
        import dask

        return str(dask.config.get("distributed.worker.multiprocessing-method", "spawn"))
    except ImportError:  # pragma: no cover - dask is a dependency
        return "spawn"


def _top_level_frame(main_globals: dict) -> FrameType | None:
    frame: FrameType | None = sys._getframe(1)
    while frame is not None:
        if frame.f_globals is main_globals and frame.f_code.co_name == "<module>":
            return frame
        frame = frame.f_back
    return None


def _is_main_guard(node: ast.AST) -> bool:
    if not isinstance(node, ast.If) or not isinstance(node.test, ast.Compare) or len(node.test.comparators) != 1:
        return False
    if not isinstance(node.test.ops[0], ast.Eq):
        return False
    sides = (node.test.left, node.test.comparators[0])
    names = {side.id for side in sides if isinstance(side, ast.Name)}
    texts = {side.value for side in sides if isinstance(side, ast.Constant)}
    return names == {"__name__"} and texts == {"__main__"}
