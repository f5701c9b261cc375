"""Benchmark: records at real scale (issue 12 section 5), beside plain references in the same run.

Targets: ``analyze`` of 10^7 samples <= 30 s and <= 2 GB; ``curve`` at 10^6 velocities <= 5 s and <= 500 MB.

* records: a sawtooth sampled at 1 kHz (sticks at 15.3 Pa/s from 257.4 to 552.9 Pa, exponential falls of
  3.8 s, white noise 0.5 Pa: the 50 um/s cycle of gelatin-glass), written as ``time [s],stress [Pa]``.
* package: the command line in a fresh interpreter per run (start-up included), OPENBLAS_NUM_THREADS=1;
  each child reports its wall time, CPU time (user + system) and peak resident memory (VmHWM).
* references, same run: the former hinge fit (the sample-by-sample profile, O(candidates x window), still in
  ``stickslip.analysis.fits._sse_profile``) on the 10^5 record; the row-by-row CSV reader and a plain
  ``pandas.read_csv(engine="pyarrow")``; for ``curve``, one ``steady_state`` call on every velocity written
  row by row with ``repr`` (the former command) at 10^5.

Run: ``PYTHONPATH=src python benchmarks/bench_scale.py [--big]`` (``--big`` adds ``curve --points 10^7``).
Timings are wall and CPU; on a shared machine the wall time can be several times the CPU time.
"""

from __future__ import annotations

import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SRC = HERE.parent / "src"
SLOPE, LOW, HIGH, SLIP, NOISE, RATE = 15.3, 257.4, 552.9, 3.8, 0.5, 1000.0


def sawtooth_csv(path: Path, samples: int) -> Path:
    import pyarrow as pa
    import pyarrow.csv as pacsv

    t = np.arange(samples) / RATE
    stick = (HIGH - LOW) / SLOPE
    phase = np.mod(t + 5.0, stick + SLIP)
    fall = (np.exp(-3.0 * (phase - stick) / SLIP) - np.exp(-3.0)) / (1.0 - np.exp(-3.0))
    x = np.where(phase < stick, LOW + SLOPE * phase, LOW + (HIGH - LOW) * fall)
    x += np.random.default_rng(0).normal(0.0, NOISE, samples)
    with path.open("wb") as handle:
        handle.write(b"time [s],stress [Pa]\n")
        pacsv.write_csv(pa.table({"t": t, "x": x}), handle, pacsv.WriteOptions(include_header=False))
    return path


# --------------------------------------------------------------------------- children
def child(task: str, *args: str) -> None:
    """Run one task in this fresh interpreter and print its costs as JSON on the last line."""
    import contextlib
    import io

    start_wall, start_cpu = time.perf_counter(), time.process_time()
    with contextlib.redirect_stdout(io.StringIO()) as captured:
        if task == "cli":
            from stickslip.cli.main import main

            with contextlib.suppress(SystemExit):
                main(list(args))
        elif task in ("old-hinge", "new-hinge"):
            if task == "old-hinge":
                _use_sample_by_sample_hinge()
            from stickslip.analysis import analyze_trace, read_trace

            summary = analyze_trace(read_trace(args[0]), None, 50e-6).summary
            names = ("critical_stress", "peak_stress", "stick_time", "slip_time", "period")
            print(json.dumps({k: summary[k]["mean"] for k in names}))
        elif task == "make-record":
            sawtooth_csv(Path(args[0]), int(args[1]))
        elif task == "row-reader":
            from stickslip.tables import _read_header, _read_rows

            path = Path(args[0])
            header = _read_header(path, str(path), {"time": "time", "stress": "stress"}, ["time"], ())
            _read_rows(path, str(path), header, ["stress"])
        elif task == "columnar-reader":
            from stickslip.analysis import read_trace

            read_trace(args[0])
        elif task == "pandas-pyarrow":
            import pandas as pd

            pd.read_csv(args[0], engine="pyarrow")
        elif task == "old-curve":
            from stickslip.cli.steady_cmd import COLUMNS
            from stickslip.parameters import load_parameters
            from stickslip.quasistatic.steady import steady_state

            velocities = np.geomspace(10e-6, 10e-3, int(args[0]))
            result = steady_state(load_parameters(), velocities)
            columns = [np.ravel(getattr(result, name)) for name, _ in COLUMNS]
            text = "".join(",".join(repr(float(v)) for v in row) + "\n" for row in zip(*columns, strict=True))
            Path(args[1]).write_text(text)
    usage = resource.getrusage(resource.RUSAGE_SELF)
    report = {
        "wall": time.perf_counter() - start_wall,
        "cpu": usage.ru_utime + usage.ru_stime,
        "process_time": time.process_time() - start_cpu,
        "peak_mb": _peak_mb(usage),
        "out": captured.getvalue()[-600:],
    }
    sys.stdout.write(json.dumps(report) + "\n")


def _peak_mb(usage: resource.struct_rusage) -> float:
    """Peak resident memory of this process.  VmHWM where Linux has it: getrusage's ru_maxrss carries the
    parent's resident size across fork and exec, which would credit the records the parent made to the child."""
    try:
        for text in Path("/proc/self/status").read_text().splitlines():
            if text.startswith("VmHWM:"):
                return int(text.split()[1]) / 1024
    except OSError:
        pass
    return usage.ru_maxrss / 1024


def _use_sample_by_sample_hinge() -> None:
    """Swap the running-sum hinge profile for the former one, which sums every candidate over the window."""
    from stickslip.analysis import fits

    class SampleBySample:
        def __init__(self, t, on_line, slope, sign, search, powers, scale):  # same signature as _HingeProfile
            self.args = (t, on_line + slope * t, on_line, fits.Line(0.0, 0.0, slope, 0.0, 0.0, 3, 0.0, 0.0))
            self.sign, self.powers, self.scale = sign, powers, scale

        def __call__(self, tcs):
            t, x, on_line, line = self.args
            return fits._sse_profile(t, x, on_line, line, np.atleast_1d(tcs), self.sign, self.powers, self.scale)

    fits._HingeProfile = SampleBySample


def measure(task: str, *args: str, repeat: int = 1) -> dict:
    """Run the task ``repeat`` times, each in a fresh interpreter: best and median wall, CPU and peak memory."""
    env = dict(os.environ, PYTHONPATH=f"{SRC}{os.pathsep}{os.environ.get('PYTHONPATH', '')}", OPENBLAS_NUM_THREADS="1")
    runs = []
    for _ in range(repeat):
        start = time.perf_counter()
        done = subprocess.run(
            [sys.executable, __file__, "--child", task, *args], env=env, capture_output=True, text=True, check=True
        )
        run = json.loads(done.stdout.strip().splitlines()[-1])
        run["outer_wall"] = time.perf_counter() - start
        runs.append(run)
    walls = [r["outer_wall"] for r in runs]
    return {
        "best": min(walls),
        "median": statistics.median(walls),
        "cpu": min(r["cpu"] for r in runs),
        "peak_mb": max(r["peak_mb"] for r in runs),
        "out": runs[-1]["out"],
    }


def line(label: str, m: dict) -> None:
    print(
        f"  {label:<52} wall best {m['best']:7.2f} s (median {m['median']:7.2f} s)"
        f"   CPU {m['cpu']:7.2f} s   peak {m['peak_mb']:7.0f} MB"
    )


def main(big: bool) -> None:
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        print("analyze (sawtooth at 1 kHz, 50 um/s; CLI in a fresh interpreter, start-up included):")
        records = {n: work / f"r{n}.csv" for n in (10**5, 10**6, 10**7)}
        for n, path in records.items():  # in a child, so that this process stays small
            measure("make-record", str(path), str(n))
        for n, path in records.items():
            m = measure("cli", "analyze", str(path), "--v0", "50 um/s", "--json", repeat=3 if n < 10**7 else 1)
            line(f"stickslip analyze, {n:.0e} samples", m)
        old = measure("old-hinge", str(records[10**5]))
        line("reference: former hinge fit, 1e+05 samples", old)
        new = measure("new-hinge", str(records[10**5]))
        line("running-sum hinge fit (in-process analysis), 1e+05", new)
        a, b = json.loads(old["out"]), json.loads(new["out"])
        worst = max(abs(a[k] - b[k]) / abs(a[k]) for k in a)
        print(f"  per-cycle means, running-sum vs former hinge: largest relative difference {worst:.1e} ({b})")
        print("reading the 10^6-sample CSV:")
        line("stickslip read_trace (pyarrow columns)", measure("columnar-reader", str(records[10**6]), repeat=3))
        line("reference: row-by-row reader", measure("row-reader", str(records[10**6])))
        line("reference: pandas.read_csv(engine='pyarrow')", measure("pandas-pyarrow", str(records[10**6]), repeat=3))
        print("curve (gelatin-glass, 10 um/s - 10 mm/s):")
        for n in (10**5, 10**6) + ((10**7,) if big else ()):
            out = work / "curve.csv"
            m = measure(
                "cli", "curve", "--points", str(n), "--format", "csv", "-o", str(out), repeat=1 if n > 10**6 else 2
            )
            line(f"stickslip curve --format csv -o, {n:.0e} velocities ({out.stat().st_size / 1e6:.0f} MB)", m)
        line("stickslip curve (table), 1e+06 velocities", measure("cli", "curve", "--points", str(10**6), repeat=2))
        line(
            "reference: one steady_state call + repr rows, 1e+05", measure("old-curve", str(10**5), str(work / "o.csv"))
        )


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        child(sys.argv[2], *sys.argv[3:])
    else:
        main("--big" in sys.argv)
