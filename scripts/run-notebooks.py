#!/usr/bin/env python3
"""Execute the example notebooks top to bottom, each on a fresh kernel, and write the executed copies.

    python scripts/run-notebooks.py --out DIR [NAME ...]

NAME is a notebook of ``examples/`` (``01-paper-in-20-minutes``, with or without ``.ipynb``, or a path); without
names every ``examples/*.ipynb`` runs, in name order.  Each runs in a new empty temporary folder (its working
directory), so a notebook that writes files leaves nothing behind in the checkout, and none can read a file by a
path relative to the repository: shipped data come through the package (``stickslip.fitting.datasets``), which
works the same from a source checkout and from an installed wheel.  Prints ``name: N s`` per notebook; exits 1
when any cell raised (the error and the cell are printed, and the partly executed copy is still written), 2 on a
bad argument.
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
import time
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
#: Seconds one cell may run before the notebook counts as failed (the slowest cell takes well under a minute).
CELL_TIMEOUT = 300
KERNEL = "python3"
#: the terminal colours of IPython's tracebacks, which a CI log shows as raw escapes
ANSI = re.compile(r"\x1b\[[0-9;]*m")


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        notebooks = _notebooks(args.names)
    except FileNotFoundError as error:
        print(f"run-notebooks: error: {error}", file=sys.stderr)
        return 2
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    failed = []
    for path in notebooks:
        seconds, error = _execute(path, out / path.name, args.timeout)
        print(f"{path.stem}: {seconds:.1f} s" + ("" if error is None else " FAILED"), flush=True)
        if error is not None:
            failed.append(path.stem)
            print(error, file=sys.stderr, flush=True)
    if failed:
        print(f"run-notebooks: {len(failed)} of {len(notebooks)} failed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", required=True, help="folder for the executed copies (created if missing)")
    parser.add_argument("--timeout", type=int, default=CELL_TIMEOUT, help="seconds per cell (default %(default)s)")
    parser.add_argument("names", nargs="*", help="notebooks to run (default: every examples/*.ipynb)")
    return parser


def _notebooks(names: list[str]) -> list[Path]:
    if not names:
        found = sorted(EXAMPLES.glob("*.ipynb"))
        if not found:
            raise FileNotFoundError(f"no notebooks in {EXAMPLES}")
        return found
    paths = []
    for name in names:
        candidates = [Path(name), EXAMPLES / name, EXAMPLES / f"{name}.ipynb"]
        path = next((p for p in candidates if p.is_file() and p.suffix == ".ipynb"), None)
        if path is None:
            raise FileNotFoundError(f"{name}: no such notebook (looked in {EXAMPLES})")
        paths.append(path.resolve())
    return paths


def _execute(source: Path, target: Path, timeout: int) -> tuple[float, str | None]:
    """Run ``source`` on a fresh kernel in an empty temporary folder; write the executed copy to ``target``."""
    import nbformat
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError, CellTimeoutError, DeadKernelError

    nb = nbformat.read(source, as_version=4)
    error = None
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix=f"nb-{source.stem}-") as workdir:
        client = NotebookClient(
            nb, timeout=timeout, kernel_name=KERNEL, resources={"metadata": {"path": workdir}}, allow_errors=False
        )
        try:
            client.execute()
        except (CellExecutionError, CellTimeoutError, DeadKernelError) as exc:
            error = f"{source.name}: {type(exc).__name__}:\n{ANSI.sub('', str(exc))}"
    seconds = time.perf_counter() - start
    _write(nb, target)
    return seconds, error


def _write(nb: object, target: Path) -> None:
    # a half-written notebook must never be taken for a finished one: write beside it, then rename
    import nbformat

    partial = target.with_name(f".{target.name}.tmp")
    nbformat.write(nb, partial)
    partial.replace(target)


if __name__ == "__main__":
    sys.exit(main())
