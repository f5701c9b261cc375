"""Benchmark: how long a ``stickslip`` command takes to start and finish, issue 9 section 5.

Each command runs as a fresh subprocess (as a user runs it), several times;
the script prints the best and the median wall time and the child's CPU time
(user + system), beside ``python -c pass`` (the interpreter alone) and
``python -c "import numpy"`` as the plain references.  The target is
<= 0.4 s for ``stickslip --help``, ``stickslip critical`` and ``stickslip curve``
with a few velocities, and <= 1 s for ``stickslip fit stick`` on Table 1 (issue 21).  Issue 31: <= 0.8 s CPU
for ``stickslip transient ... --stick-population`` with a short run, beside the libraries such a run needs:
``import numpy, numba``, and that with numba's CPU target built as the first kernel loaded from numba's cache
builds it (without numba's BLAS probe, as the command does: stickslip.numerics.numba_start), the floor of any command
that runs a kernel.  No scipy on that path (tests/test_cli_boundary.py).

    python benchmarks/bench_startup.py [--repeat N] [--compare OTHER_SRC] [--only TEXT]

The package is taken from this checkout's ``src/``, with its bytecode (``PYTHONDONTWRITEBYTECODE`` is dropped
from the children's environment, so the warm-up run writes it, as an installed package has it: without it every
run compiles the package's sources, ~0.1 s more).  ``--compare`` times a
second copy of the package (e.g. an older commit unpacked with
``git archive COMMIT src | tar -x -C /tmp/old``, then ``--compare /tmp/old/src``)
in the same run, run by run alternately, so that both see the same machine load.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
from pathlib import Path

from timing import child_run, package_environments

ROOT = Path(__file__).resolve().parent.parent
STICKSLIP = [sys.executable, "-m", "stickslip.cli.main"]
TABLE1 = ROOT / "src" / "stickslip" / "data" / "table1.csv"
TRANSIENT = [*STICKSLIP, "transient", "--start", "steady", "--stick-population"]
#: a run short enough that the command is its start-up: Python, numpy, click, the package, the critical point (the
#: steady start and the cost estimate ask for Vc), numba and the compiled kernels loaded from numba's cache
SHORT_RUN = ["--v0", "350 um/s", "--duration", "0.05 s"]
#: issue 31's cycle (README speed table): 350 -> 100 um/s through the block, one stick-slip cycle
ONE_CYCLE = ["--v0", "350 um/s", "--duration", "5 s", "--segment", "100 um/s:20 s"]
LIBRARIES_LABEL = 'python -c "import numpy, numba" (reference: a transient run\'s libraries)'
#: numba's CPU target as the first call of a cached kernel on an array builds it (its typing and target registries,
#: the array's type, which loads numpy.ma), without the BLAS probe
NUMBA_READY = (
    "from stickslip.numerics.numba_start import skip_blas_probe; skip_blas_probe(); import numpy, numba;"
    " from numba.core.registry import cpu_target; cpu_target.target_context.refresh();"
    " cpu_target.typing_context.refresh(); numba.typeof(numpy.zeros(1))"
)
NUMBA_LABEL = "numpy, numba and numba's CPU target (reference: the floor of a transient run)"
CASES = (
    ("python -c pass (reference)", [sys.executable, "-c", "pass"]),
    ('python -c "import numpy" (reference)', [sys.executable, "-c", "import numpy"]),
    ("stickslip --help", [*STICKSLIP, "--help"]),
    ("stickslip critical", [*STICKSLIP, "critical"]),
    ("stickslip critical --json", [*STICKSLIP, "critical", "--json"]),
    (
        "stickslip curve --velocity (3 velocities)",
        [*STICKSLIP, "curve", "--velocity", "50 um/s", "--velocity", "350 um/s", "--velocity", "1 mm/s"],
    ),
    ("stickslip params show", [*STICKSLIP, "params", "show"]),
    ("stickslip fit stick (Table 1; target <= 1 s)", [*STICKSLIP, "fit", "stick", str(TABLE1)]),
    # issue 31: the time-dependent model's command with the stick chains; its floor is the libraries it runs on
    (LIBRARIES_LABEL, [sys.executable, "-c", "import numpy, numba"]),
    (NUMBA_LABEL, [sys.executable, "-c", NUMBA_READY]),
    ("stickslip transient, 0.05 s, stick chains (target <= 0.8 s)", [*TRANSIENT, *SHORT_RUN]),
    ("stickslip transient, one cycle, stick chains", [*TRANSIENT, *ONE_CYCLE]),
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=9, help="runs per command")
    parser.add_argument("--compare", type=Path, default=None, help="another src/ folder to time beside this one")
    parser.add_argument("--only", default=None, help="time only the commands whose label contains TEXT")
    args = parser.parse_args()
    sources = {"": ROOT / "src"} if args.compare is None else {"this: ": ROOT / "src", "other: ": args.compare}
    envs = package_environments(sources)
    machine = f"Python {platform.python_version()} on {platform.machine()}, {os.cpu_count()} cores"
    print(f"{machine}; {args.repeat} runs each, wall time and the child's CPU time (user + system)")
    print(f"{'command':50s} {'best':>8s} {'median':>8s} {'cpu best':>9s} {'cpu med':>8s}")
    for label, command in CASES:
        if args.only is not None and args.only not in label:
            continue
        # the references do not depend on the package: timed with the first source only
        timed = dict(list(envs.items())[:1]) if "reference" in label else envs
        for env in timed.values():
            child_run(command, env)  # warm the file cache and the bytecode
        times: dict[str, list[tuple[float, float]]] = {source: [] for source in timed}
        for _ in range(args.repeat):  # alternating, run by run: a change of the machine's load hits both alike
            for source, env in timed.items():
                times[source].append(child_run(command, env))
        for source, runs in times.items():
            walls, cpus = zip(*runs, strict=True)
            print(
                f"{source + label:50s} {min(walls):7.3f}s {statistics.median(walls):7.3f}s"
                f" {min(cpus):8.3f}s {statistics.median(cpus):7.3f}s"
            )


if __name__ == "__main__":
    main()
