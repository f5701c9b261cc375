"""Round 28: a Ctrl-C that lands in a gc callback still stops a sweep; a plug-in's own exception is named as the
plug-in's; the sweep's Parquet names its units to plain pandas; the compare figure's velocity axis; the lock file.

Every expected number is the truth the test builds in (the velocities it draws, the units the model declares).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

# ------------------------------------------------------------------------------ S1: a Ctrl-C lost in a gc callback
from cli_helpers import ctrl_c_as_at_a_terminal
from test_plugin_and_sweep_round27 import NAP_MODEL

# what distributed's GCDiagnosis._gc_callback does to a Ctrl-C, made certain: once two chunks are written, the first
# garbage collection in the main thread holds it 1.5 s inside a gc callback (after saying so in a marker file), so the
# test's Ctrl-C is handled there, where Python ignores the KeyboardInterrupt it raises
GC_TRAP = """
import gc, os, threading, time

_out, _marker, _sprung = os.environ["TRAP_FOLDER"], os.environ["TRAP_MARKER"], []


def _hold(phase, info):
    if _sprung or phase != "start" or threading.current_thread() is not threading.main_thread():
        return
    if not os.path.isdir(_out) or sum(n.startswith("part-") for n in os.listdir(_out)) < 2:
        return
    _sprung.append(True)
    open(_marker, "w").close()
    time.sleep(1.5)


gc.callbacks.append(_hold)
gc.set_threshold(50)  # collections often, so that one falls in the main thread soon
"""
POINTS = 100


def _chunks(folder: Path) -> list[Path]:
    return sorted(folder.glob("part-*.parquet")) if folder.is_dir() else []


def _rows(folder: Path) -> list[int]:
    import pyarrow.parquet as pq

    return [p for chunk in _chunks(folder) for p in pq.read_table(chunk, columns=["point"]).column(0).to_pylist()]


def test_a_ctrl_c_handled_inside_a_gc_callback_still_stops_the_sweep(tmp_path):
    """Before: "Exception ignored in: <function _hold ...> KeyboardInterrupt", the sweep ran to its end, exit 0."""
    (tmp_path / "napmodel.py").write_text(textwrap.dedent(NAP_MODEL))
    (tmp_path / "gctrap.py").write_text(textwrap.dedent(GC_TRAP))
    out, marker = tmp_path / "out", tmp_path / "in-gc-callback"
    command = [sys.executable, "-c", "import gctrap; from stickslip.cli.main import main; main()", "sweep",
               "--model", "napmodel:MODEL", "--vary", f"pulling_velocity=1 um/s..1 mm/s:{POINTS}:log",
               "--duration", "1 s", "-o", str(out), "--workers", "1", "--batch-size", "4"]  # fmt: skip
    env = {**os.environ, "TRAP_FOLDER": str(out), "TRAP_MARKER": str(marker),
           "PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}  # fmt: skip
    stopped = subprocess.Popen(command, cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               start_new_session=True, preexec_fn=ctrl_c_as_at_a_terminal)  # fmt: skip
    try:
        deadline = time.monotonic() + 60
        while not marker.exists() and stopped.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        assert marker.exists() and stopped.poll() is None, "the sweep ended before its main thread collected garbage"
        os.killpg(stopped.pid, signal.SIGINT)  # as a terminal's Ctrl-C: to every process of the group
        _, err = stopped.communicate(timeout=60)
    finally:
        if stopped.poll() is None:
            os.killpg(stopped.pid, signal.SIGKILL)
    err = err.decode()
    assert stopped.returncode == 130, err
    assert "Exception ignored" not in err and "Traceback" not in err and "KeyboardInterrupt" not in err, err
    kept = len(_rows(out))
    assert 0 < kept < POINTS, err
    assert f"sweep: stopped with {kept} of {POINTS} points saved in {out}" in err
    assert err.rstrip().endswith("stickslip: aborted")
    assert not (out / ".stickslip.lock").exists()  # S5: an interrupted run leaves no lock file either


# ------------------------------------------------------------------------------ S2: a plug-in's own exception
# a plug-in as tester L's (and docs/models.md's) example writes it: a start velocity read with float(), no start
# words declared, and a key whose zero the equations divide by without the model refusing it
WORD_TAKER = """
import numpy as np
from stickslip.models import Capabilities, FrictionModel, Run
from stickslip.units import to_si


class Lag(FrictionModel):
    name = "lag-plugin"
    capabilities = Capabilities(controls=("velocity", "spring"), protocols="any")
    start_dimension = "velocity"

    def dimensions(self):
        return {"c": "stress_per_velocity", "tau": "time"}

    def parameters(self, spec=None, overrides=None):
        given = {key: to_si(value, self.dimensions()[key], key) for key, value in (overrides or {}).items()}
        return {"c": 1e6, "tau": 0.01, **given}

    def run(self, params, protocol, rig=None, *, start=None, **settings):
        self.check(protocol, rig, settings)
        v0 = float(start) if start is not None else protocol.segments[0].velocity
        rate = 1.0 / float(params["tau"])  # ZeroDivisionError at tau = 0: the plug-in's own
        t = np.linspace(0.0, protocol.duration, 201)
        v = protocol.velocity_at(t) + (v0 - protocol.velocity_at(t)) * np.exp(-rate * t)
        return Run.from_trace(self.name, t, stress=params["c"] * v, slider_velocity=v, slider_position=v * t,
                              load_point_position=v * t, protocol=protocol)


MODEL = Lag()
"""


@pytest.fixture
def plugin(tmp_path, monkeypatch):
    (tmp_path / "lagplugin.py").write_text(textwrap.dedent(WORD_TAKER))
    monkeypatch.syspath_prepend(str(tmp_path))
    return "lagplugin:MODEL"


RUN = ("--v0", "100 um/s", "--duration", "0.1 s")


@pytest.mark.parametrize(
    ("command", "option"),
    [(("run", "--model", "{p}", *RUN, "--start", "steady"), "--start 'steady'"),
     (("compare", "--models", "{p},rsf", *RUN, "--start", "lag-plugin=steady"), "--start lag-plugin='steady'")],
)  # fmt: skip
def test_a_plugins_own_exception_on_a_start_word_names_the_option_and_the_plugin(plugin, capsys, command, option):
    """Before: "stickslip: error: internal error (ValueError): could not convert string to float: 'steady'", exit 1."""
    from cli_helpers import run_main

    status, _, err = run_main(capsys, *(word.format(p=plugin) for word in command))
    assert status == 2, err
    line = err.strip()
    assert "\n" not in line and "internal error" not in line and "Traceback" not in line
    assert line.startswith(
        f"stickslip: error: {option}: model lag-plugin (the plug-in lagplugin.Lag) raised ValueError"
    )
    assert "could not convert string to float" in line and "declares no start words" in line
    assert "starts from a velocity" in line


def test_a_plugins_own_exception_without_a_start_names_the_plugin(plugin, capsys):
    from cli_helpers import run_main

    status, _, err = run_main(capsys, "run", "--model", plugin, *RUN, "--set", "tau=0 s")
    assert status == 2, err
    assert err.strip().startswith(
        "stickslip: error: model lag-plugin (the plug-in lagplugin.Lag) raised ZeroDivisionError in its run:"
    )
    assert "internal error" not in err and "--start" not in err
    status, _, err = run_main(capsys, "run", "--model", plugin, *RUN, "--start", "150 um/s", "--json")
    assert status == 0, err  # the same plug-in, given what it takes, runs


# ------------------------------------------------------------------------------ S3: units that pandas reads back
def test_plain_pandas_read_parquet_holds_the_units_of_a_sweep(tmp_path):
    """Before: pandas.read_parquet(OUT).attrs was {}; the units only in the schema's stickslip:units."""
    import pandas as pd

    import stickslip

    (tmp_path / "napmodel2.py").write_text(textwrap.dedent(NAP_MODEL).replace("time.sleep(0.04)", "pass"))
    sys.path.insert(0, str(tmp_path))
    try:
        out = tmp_path / "out"
        stickslip.sweep({"c": "1 kPa*s/m,2 kPa*s/m,3 kPa*s/m"}, out, model="napmodel2:MODEL",
                        pulling_velocity="50 um/s", duration=1.0, workers=0)  # fmt: skip
    finally:
        sys.path.remove(str(tmp_path))
    # the truth: docs/models.md's table of dimensions (stress_per_velocity: Pa s/m) and the sweep's columns
    expected = {"point": None, "c": "Pa s/m", "pulling_velocity": "m/s", "period": "s", "stick_time": "s",
                "peak_stress": "Pa", "jump_velocity": "m/s", "mean_stress": "Pa", "wall_time": "s",
                "regime": None, "status": None, "message": None}  # fmt: skip
    for path in (out, next(out.glob("part-*.parquet"))):  # the folder, and one chunk alone
        frame = pd.read_parquet(path)
        units = frame.attrs["units"]
        assert set(units) == set(frame.columns)
        assert {k: units[k] for k in expected if k in units} == {k: v for k, v in expected.items() if k in units}
        assert units["c"] == "Pa s/m" and units["peak_stress"] == "Pa"
    assert sorted(pd.read_parquet(out)["c"]) == pytest.approx([1e3, 2e3, 3e3], rel=1e-12)


# ------------------------------------------------------------------------------ S4: the compare figure's velocity axis
def _runs(peak: float, steady: float) -> dict:
    from stickslip import protocols
    from stickslip.models import Run

    protocol = protocols.constant(steady, 4.0)
    t = np.linspace(0.0, 4.0, 4001)
    spike = np.where(np.abs(t - 2.0) < 0.02, peak, 0.0)  # one slip at `peak` m/s, stuck otherwise
    flat = np.full_like(t, steady)
    return {name: Run.from_trace(name, t, stress=400.0 + 0 * v, slider_velocity=v, slider_position=np.cumsum(v) * 1e-3,
                                 load_point_position=steady * t, protocol=protocol)
            for name, v in (("slipping", spike), ("steady", flat))}  # fmt: skip


@pytest.mark.parametrize(("peak", "unit", "top"), [(1.7, "m/s", 1.7), (0.3, "mm/s", 300.0), (4e-4, "µm/s", 400.0)])
def test_the_compare_figure_draws_velocities_in_a_unit_without_a_multiplier(peak, unit, top):
    """Before: a 1.7 m/s slip read 1.5 on a "µm/s" axis under a "1e6" multiplier; now 1.7 on an m/s axis."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from stickslip.plots.overlay import overlay_figure

    fig = overlay_figure(_runs(peak, 0.03 * peak))
    FigureCanvasAgg(fig).draw()
    bottom = fig.axes[1]
    assert bottom.get_ylabel() == f"slider velocity ({unit})"
    assert bottom.yaxis.get_offset_text().get_text() == ""  # no "1e6" over the axis
    high = bottom.get_ylim()[1]
    assert top <= high <= 1.25 * top  # the axis reaches the slip's peak in that unit, and little beyond
    drawn = max(float(np.nanmax(line.get_ydata())) for line in bottom.get_lines())
    assert drawn == pytest.approx(top, rel=1e-9)


# ------------------------------------------------------------------------------ S5: the lock file
def test_the_lock_file_goes_when_the_run_ends_and_a_second_writer_is_still_refused(tmp_path):
    from stickslip.errors import DataError
    from stickslip.sweeps import build_spec, run_sweep
    from stickslip.sweeps.store import LOCK, open_store

    spec = build_spec(["pulling_velocity=10 um/s,20 um/s"], duration=1.0)
    folder = tmp_path / "out"
    store = open_store(folder, spec, 1)
    assert (folder / LOCK).read_text().strip() == str(os.getpid())
    with pytest.raises(DataError, match=rf"another sweep is writing into this folder \(process {os.getpid()}\)"):
        open_store(folder, spec, 1)
    waiting = os.open(folder / LOCK, os.O_RDWR)  # a second writer that opened the file before the first ended
    store.close()
    assert not (folder / LOCK).exists()
    from stickslip.sweeps.store import _same_file

    assert not _same_file(waiting, folder / LOCK)  # ... locks what is there now instead of the removed file
    os.close(waiting)
    (folder / LOCK).write_text("999999\n")  # a killed run's lock file: its process is gone, its flock released
    run_sweep(spec, folder, workers=0)
    assert not (folder / LOCK).exists()
    assert sorted(p.name for p in folder.iterdir()) == ["_chunks.jsonl", "_manifest.json", "_run.json",
                                                        "part-000000.parquet", "part-000001.parquet"]  # fmt: skip
