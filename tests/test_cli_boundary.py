"""The command line's boundary: units on dimensional options, bounded input, no lost data, start-up.

Issue 9 section 5 and issue 12 sections 3-4: every bad command line ends
quickly in one line; no command writes over its input; outputs are atomic;
`stickslip` alone prints the help; the light commands import no heavy library.
Cases that would block or eat memory if the guard were missing run in a
subprocess with a timeout.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import warnings
from importlib import import_module
from pathlib import Path

import click
import pytest

import stickslip
from cli_helpers import run_main
from stickslip.cli import common
from stickslip.errors import DataError
from stickslip.report.build import MARKER, prepare_report_folder

#: the folder holding the package these tests import (installed, under scripts/run-tests.sh): the subprocesses run
#: the same code, and load the kernels from its numba cache.  The checkout's src/ had a cache of its own, so on a
#: fresh clone the two transient runs below compiled the kernels a second time (~45 s of CI's test time).
SRC = Path(stickslip.__file__).resolve().parents[1]


def _subprocess(*args: str, timeout: float = 60) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    command = [sys.executable, "-m", "stickslip.cli.main", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=env, check=False)


def _one_error_line(status: int, err: str) -> None:
    assert status == 2, err
    assert err.count("\n") == 1 and err.startswith("stickslip: error: "), err
    assert "Traceback" not in err and "internal error" not in err


# --- a dimensional value needs its unit --------------------------------------------------------


def test_bare_v0_is_refused_with_the_way_to_write_it(capsys):
    status, out, err = run_main(capsys, "simulate", "--v0", "50", "--duration", "10 s")
    _one_error_line(status, err)
    assert err.strip() == (
        'stickslip: error: --v0 50: a velocity needs a unit, e.g. --v0 "50 um/s" (or "50 m/s" if you mean SI)'
    )
    assert out == ""


@pytest.mark.parametrize(
    "args, expected",
    [
        (["curve", "--velocity", "350"], '--velocity 350: a velocity needs a unit, e.g. --velocity "350 um/s"'),
        (["curve", "--vmin", "1e-5"], "--vmin 1e-5: a velocity needs a unit"),
        (["simulate", "--v0", "5 um/s", "--duration", "30"], '--duration 30: a time needs a unit, e.g. --duration "30'),
        (["stick", "--v0", "5 um/s", "--start-stress", "300"], "--start-stress 300: a stress needs a unit, e.g. --sta"),
        (["critical", "--set", "bonds.bond_time=224"], 'a time needs a unit, e.g. --set bonds.bond_time="224 us"'),
        # issue 19: the unit suggested is the one the number was presumably meant in (nearest the typical size)
        (["curve", "--velocity", "350e-6"], 'a velocity needs a unit, e.g. --velocity "350e-6 m/s"\n'),
        (["critical", "--set", "block.height=5"], 'e.g. --set block.height="5 mm" (or "5 m" if you mean SI)'),
        (["compare", "--eta", "1"], 'a slowness needs a unit, e.g. --eta "1 s/m"\n'),
        (["analyze", "--v0", "5 um/s", "--contact-area", "15", "x.csv"], "an area needs a unit, e.g. --contac"),
        (["rsf", "stability", "--velocity", "1 um/s", "--stiffness", "1000"], '--stiffness "1000 1/m"'),
        (["critical", "--set", "bonds.max_extension=1e300"], "--set bonds.max_extension=1e300: a length needs a unit"),
        (["critical", "--set", "aging.aging_velocity=-3"], "--set aging.aging_velocity=-3: a velocity needs a unit"),
        (["fit", "steady", "x.csv", "--fix", "bonds.max_extension=1"], "--fix bonds.max_extension=1: a length needs"),
    ],
)
def test_bare_numbers_for_dimensional_values_are_refused(capsys, tmp_path, monkeypatch, args, expected):
    (tmp_path / "x.csv").write_text("velocity [um/s],stress [Pa]\n100,250\n200,260\n", encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    status, _, err = run_main(capsys, *args)
    _one_error_line(status, err)
    assert expected in err


def test_zero_and_dimensionless_values_need_no_unit(capsys):
    status, out, err = run_main(capsys, "params", "show", "--set", "bonds.breakage_weight=2")
    assert status == 0, err
    assert "bonds.breakage_weight (set)" in out
    status, out, err = run_main(capsys, "params", "show", "--set", "bonds.activation_length=0")
    assert status == 0, err


def test_values_with_units_in_si_still_work(capsys):
    status, out, err = run_main(capsys, "curve", "--velocity", "0.00035 m/s", "--format", "json")
    assert status == 0, err
    assert json.loads(out)["velocity"] == [0.00035]


# --- bounded parsing and echo ----------------------------------------------------------------


HOSTILE_VALUES = ["(10**10**10) s", "(10**400) s", "1" * 100_000 + " s", "(" * 5000 + "s" + ")" * 5000]


def test_hostile_values_end_at_once_in_one_short_line():
    """All in one subprocess with a timeout: a power tower that got through would never return."""
    code = (
        "import sys\n"
        "from stickslip.cli.main import main\n"
        "for value in sys.argv[1:]:\n"
        "    try:\n"
        "        main(['params', 'show', '--set', 'bonds.bond_time=' + value])\n"
        "    except SystemExit as exc:\n"
        "        print('STATUS', exc.code)\n"
    )
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    command = [sys.executable, "-c", code, *HOSTILE_VALUES]
    done = subprocess.run(command, capture_output=True, text=True, timeout=60, env=env, check=False)
    assert done.stdout.split() == ["STATUS", "2"] * len(HOSTILE_VALUES), done.stderr[-500:]
    lines = done.stderr.splitlines()
    assert len(lines) == len(HOSTILE_VALUES)
    assert all(line.startswith("stickslip: error: bonds.bond_time: ") and len(line) < 700 for line in lines)


def test_a_huge_key_is_echoed_short(capsys):
    status, _, err = run_main(capsys, "critical", "--set", "bonds." + "k" * 100_000 + "=1 s")
    _one_error_line(status, err)
    assert len(err) < 700


def test_fifo_and_device_inputs_are_refused_without_blocking(tmp_path):
    fifo = tmp_path / "record.csv"
    os.mkfifo(fifo)
    done = _subprocess("analyze", str(fifo), "--v0", "50 um/s", timeout=60)
    _one_error_line(done.returncode, done.stderr)
    assert "not a regular file" in done.stderr
    done = _subprocess("params", "show", "/dev/zero", timeout=60)
    _one_error_line(done.returncode, done.stderr)
    assert "'/dev/zero': not a regular file" in done.stderr


def test_input_files_must_exist_be_files_and_fit_the_limit(tmp_path):
    kind = common.InputFile(max_bytes=10)
    with pytest.raises(click.BadParameter, match="file not found"):
        kind.convert(str(tmp_path / "missing.csv"), None, None)
    with pytest.raises(click.BadParameter, match="is a folder"):
        kind.convert(str(tmp_path), None, None)
    big = tmp_path / "big.csv"
    big.write_text("time,stress\n0,1\n", encoding="utf-8")
    with pytest.raises(click.BadParameter, match="16 bytes; at most 10"):
        kind.convert(str(big), None, None)
    assert common.InputFile().convert(str(big), None, None) == big


def test_a_record_near_the_float_limit_ends_in_at_most_one_line(capsys, tmp_path):
    rows = [f"{k * 0.01!r},{1e300 * (1 + (k % 100) / 100)!r}" for k in range(2000)]
    path = tmp_path / "huge.csv"
    path.write_text("time,stress\n" + "\n".join(rows) + "\n", encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("default", RuntimeWarning)  # as a user runs it: main() must summarise them
        status, _, err = run_main(capsys, "analyze", str(path), "--v0", "50 um/s", "--json")
    assert status in (0, 2) and err.count("\n") <= 1, err
    assert "Traceback" not in err and "internal error" not in err


def test_numpy_warnings_reach_the_user_as_one_summary_line(capsys, monkeypatch):
    import numpy as np

    import stickslip.quasistatic.critical as critical_module

    real = critical_module.critical_point

    def noisy(params):
        np.exp(np.array([1000.0]))  # overflow encountered in exp
        np.log(np.array([0.0]))  # divide by zero encountered in log
        return real(params)

    monkeypatch.setattr(critical_module, "critical_point", noisy)
    with warnings.catch_warnings():
        warnings.simplefilter("default", RuntimeWarning)
        status, out, err = run_main(capsys, "critical")
    assert status == 0 and "Vc" in out
    assert err.count("\n") == 1
    assert err.startswith("stickslip: warning: the computation met floating-point trouble (overflow encountered in exp")
    assert "and 1 more" in err


def test_bare_stickslip_prints_the_help(capsys):
    status, out, err = run_main(capsys)
    assert status == 0 and err == ""
    assert out.startswith("Usage: stickslip") and "\nCommands:\n" in out and "critical" in out
    assert out.count("\n") > 10  # readable: one command per line
    status, out, _ = run_main(capsys, "fit")
    assert status == 0 and out.startswith("Usage: stickslip fit")


# --- no lost data ----------------------------------------------------------------------------


@pytest.fixture()
def steady_data(tmp_path: Path) -> Path:
    path = tmp_path / "mydata.csv"
    path.write_text("velocity [um/s],stress [Pa]\n100,250\n300,270\n", encoding="utf-8")
    return path


@pytest.mark.parametrize(
    "args",
    [
        ["fit", "steady", "{data}", "-o", "{data}"],
        ["fit", "steady", "{data}", "--report", "{data}"],
        ["fit", "steady", "{data}", "--plot", "{data}"],
        ["fit", "stick", "{data}", "-o", "{data}"],
        ["analyze", "{data}", "--v0", "50 um/s", "-o", "{data}"],
        ["analyze", "{data}", "--v0", "50 um/s", "--plot", "{data}"],
        ["curve", "--params", "{toml}", "-o", "{toml}"],
        ["simulate", "--v0", "50 um/s", "--duration", "1 s", "--params", "{toml}", "--plot", "{toml}"],
        ["params", "export", "{toml}", "-o", "{toml}"],
    ],
)
def test_no_command_overwrites_its_input(capsys, steady_data, args):
    toml = steady_data.with_name("mine.toml")
    status, _, _ = run_main(capsys, "params", "export", "-o", str(toml))
    assert status == 0
    before = {p: p.read_bytes() for p in (steady_data, toml)}
    argv = [a.format(data=steady_data, toml=toml) for a in args]
    status, _, err = run_main(capsys, *argv)
    _one_error_line(status, err)
    assert "that is the input file; refusing to overwrite it" in err
    assert {p: p.read_bytes() for p in before} == before
    assert sorted(p.name for p in steady_data.parent.iterdir()) == ["mine.toml", "mydata.csv"]


def test_a_failing_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path, monkeypatch):
    target = tmp_path / "out.csv"
    target.write_text("old\n", encoding="utf-8")

    def refuse(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr("stickslip.fileio.os.replace", refuse)
    with pytest.raises(click.ClickException, match="no space left on the device while writing it"):
        common.write_text(target, "new\n" * 1000)
    assert target.read_text(encoding="utf-8") == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["out.csv"]


def test_a_figure_failing_midway_keeps_the_old_file(tmp_path):
    target = tmp_path / "fig.png"
    target.write_bytes(b"old picture")

    class HalfFigure:
        def savefig(self, path, **kwargs):
            Path(path).write_bytes(b"\x89PNG half")
            raise ValueError("renderer failed")

    with pytest.raises(click.ClickException, match="cannot be written \\(renderer failed\\)"):
        common.save_figure(HalfFigure(), target)
    assert target.read_bytes() == b"old picture"
    assert [p.name for p in tmp_path.iterdir()] == ["fig.png"]


def test_a_figure_is_written_in_the_format_of_its_suffix(tmp_path):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 2))
    fig.add_subplot().plot([0, 1], [1, 0])
    common.save_figure(fig, tmp_path / "a.svg")
    common.save_figure(fig, tmp_path / "a.png")
    assert (tmp_path / "a.svg").read_text(encoding="utf-8").lstrip().startswith("<?xml")
    assert (tmp_path / "a.png").read_bytes()[:4] == b"\x89PNG"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "a.svg"]


def test_reproduce_refuses_an_empty_path_and_a_foreign_folder(capsys, tmp_path):
    status, _, err = run_main(capsys, "reproduce", "-o", "")
    _one_error_line(status, err)
    assert "empty path" in err
    foreign = tmp_path / "thesis"
    foreign.mkdir()
    (foreign / "report.html").write_text("my own report", encoding="utf-8")
    status, _, err = run_main(capsys, "reproduce", "-o", str(foreign))
    _one_error_line(status, err)
    assert "holds other files and no earlier stickslip report" in err
    assert (foreign / "report.html").read_text(encoding="utf-8") == "my own report"
    assert sorted(p.name for p in foreign.iterdir()) == ["report.html"]


def test_report_folder_may_be_new_empty_or_an_earlier_report(tmp_path):
    assert prepare_report_folder(tmp_path / "new" / "deep") == tmp_path / "new" / "deep"
    assert (tmp_path / "new" / "deep" / MARKER).is_file()
    (tmp_path / "new" / "deep" / "report.html").write_text("earlier run", encoding="utf-8")
    prepare_report_folder(tmp_path / "new" / "deep")  # ours: accepted again
    empty = tmp_path / "empty"
    empty.mkdir()
    prepare_report_folder(empty)
    older = tmp_path / "older"  # a report written before the marker existed
    older.mkdir()
    from stickslip.report.build import PAPER

    (older / "results.json").write_text(json.dumps({"paper": PAPER, "stickslip_version": "0.1.0"}), encoding="utf-8")
    prepare_report_folder(older)
    stranger = tmp_path / "stranger"
    stranger.mkdir()
    (stranger / "results.json").write_text('{"something": "else"}', encoding="utf-8")
    with pytest.raises(DataError, match="no earlier stickslip report"):
        prepare_report_folder(stranger)
    with pytest.raises(DataError, match="not a folder"):
        prepare_report_folder(older / "results.json")


# --- start-up --------------------------------------------------------------------------------

HEAVY = ("pint", "pandas", "matplotlib", "scipy.optimize", "scipy.integrate", "scipy.special", "lmfit")


def test_the_light_commands_import_no_heavy_library():
    code = (
        "import sys\n"
        "from stickslip.cli.main import cli\n"
        "cli.main(sys.argv[1:], standalone_mode=False)\n"
        f"print('HEAVY', [m for m in {HEAVY!r} if m in sys.modules])\n"
    )
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    for argv in (["--help"], ["critical", "--json"], ["curve", "--velocity", "50 um/s", "--velocity", "1 mm/s"]):
        done = subprocess.run(
            [sys.executable, "-c", code, *argv], capture_output=True, text=True, timeout=120, env=env, check=False
        )
        assert done.returncode == 0, done.stderr
        assert done.stdout.strip().splitlines()[-1] == "HEAVY []", (argv, done.stdout[-300:])


#: what a short transient run must not load (issue 31: scipy.fft and scipy.optimize came in at import through
#: stickslip.quasistatic.jump, scipy.linalg through numba's BLAS probe, stickslip.numerics.numba_start)
TRANSIENT_HEAVY = (*HEAVY, "scipy.fft", "scipy.linalg", "scipy.interpolate", "scipy.sparse")


@pytest.mark.parametrize(
    ("extra", "regime"),
    [
        (["--duration", "0.05 s"], "regime: steady"),
        # the cycle: glides (transient/glide.py, compiled), fresh stick chains (Eq 15), the jump
        (["--duration", "5 s", "--segment", "100 um/s:20 s"], "regime: stick-slip"),
    ],
    ids=["short", "one-cycle"],
)
def test_a_short_transient_run_imports_no_heavy_library(extra: list[str], regime: str) -> None:
    code = (
        "import sys\n"
        "from stickslip.cli.main import main\n"
        "try:\n"
        "    main(sys.argv[1:])\n"
        "except SystemExit as stop:\n"
        "    assert not stop.code, stop.code\n"
        f"print('HEAVY', [m for m in {TRANSIENT_HEAVY!r} if m in sys.modules])\n"
        "print('COMMANDS', sorted(m for m in sys.modules if m.startswith('stickslip.cli.') and m.endswith('_cmd')))\n"
    )
    argv = ["transient", "--start", "steady", "--stick-population", "--v0", "350 um/s", *extra]
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    done = subprocess.run(  # a first run in a fresh checkout compiles the kernels into numba's cache (~20 s)
        [sys.executable, "-c", code, *argv], capture_output=True, text=True, timeout=600, env=env, check=False
    )
    assert done.returncode == 0, done.stderr
    assert regime in done.stdout  # the run ran, not just its imports
    *_, heavy, commands = done.stdout.strip().splitlines()
    assert heavy == "HEAVY []", done.stdout[-300:]
    # the command's own module and those it builds on (run's options and output), not every other command's
    assert commands == "COMMANDS ['stickslip.cli.run_cmd', 'stickslip.cli.transient_cmd']", commands


def test_the_quasi_static_cycle_loads_no_scipy():
    """Stick (dop853's collapse), jump and slip find their roots with stickslip.numerics.roots.brentq, and their
    Chebyshev series with stickslip.numerics.transforms: scipy's numbers bit for bit (tests/test_roots.py,
    tests/test_transforms.py).  A transient run's cost estimate and its jumps solve them; scipy.optimize would
    bring scipy.linalg, sparse and spatial with it (~0.2 s), scipy.fft and scipy.special ~0.3 s."""
    code = (
        "import sys, stickslip\n"
        "params = stickslip.load_parameters()\n"
        "sim = stickslip.simulate(params, 50e-6, 60.0)\n"
        "stick = stickslip.stick_phase(params, 50e-6)\n"
        "print('RAN', sim.regime, len(sim.cycles), 0 < stick.chain_fraction_at(5.0) < 1)\n"
        "heavy = ('scipy.optimize', 'scipy.integrate', 'scipy.linalg', 'scipy.fft', 'scipy.special')\n"
        "print('LOADED', [m for m in heavy if m in sys.modules])\n"
    )
    ran, loaded = _last_two_lines(code)
    assert ran == "RAN stick-slip 2 True"  # stick, jump, slip and the chains' dense output were all solved
    assert loaded == "LOADED []"


def test_numba_without_its_blas_probe_still_compiles_linear_algebra():
    """The command skips numba's BLAS probe (stickslip.numerics.numba_start); np.dot and @ still compile (numba's
    linear algebra imports scipy.linalg itself; np.linalg's LAPACK bindings, 5 s more to compile, the same way)
    and agree with numpy's."""
    code = (
        "import sys\n"
        "from stickslip.numerics.numba_start import skip_blas_probe\n"
        "skip_blas_probe()\n"
        "import numba, numpy as np\n"
        "from numba.core.registry import cpu_target\n"
        "cpu_target.target_context.refresh()\n"
        "import numba.np.arraymath\n"
        "print('PROBE', numba.np.arraymath._HAVE_BLAS, 'scipy.linalg' in sys.modules)\n"
        "f = numba.njit(lambda a, b: (np.dot(a, b), a @ b))\n"
        "a, b = np.array([[2.0, 1.0], [1.0, 3.0]]), np.array([[1.0, -1.0], [0.5, 2.0]])\n"
        "dot, at = f(a, b)\n"
        "print('SAME', np.array_equal(dot, np.dot(a, b)), np.array_equal(at, a @ b))\n"
    )
    probe, same = _last_two_lines(code)
    assert probe == "PROBE False False"  # the probe was skipped, and scipy.linalg not loaded for it
    assert same == "SAME True True"


def test_every_command_is_registered_by_the_module_named_for_it():
    from stickslip.cli.main import COMMAND_MODULES

    modules = {path.stem for path in (SRC / "stickslip" / "cli").glob("*_cmd.py")}
    assert set(COMMAND_MODULES.values()) == modules  # a new command module must be named there to be found
    for module in modules:
        group = click.Group()
        import_module(f"stickslip.cli.{module}").register(group)
        assert sorted(group.commands) == sorted(name for name, m in COMMAND_MODULES.items() if m == module), module


def test_outputs_get_the_usual_file_mode_not_a_private_one(tmp_path):
    umask = os.umask(0o022)
    os.umask(umask)
    common.write_text(tmp_path / "new.csv", "a\n")
    assert (tmp_path / "new.csv").stat().st_mode & 0o777 == 0o666 & ~umask
    kept = tmp_path / "kept.csv"
    kept.write_text("old\n", encoding="utf-8")
    kept.chmod(0o640)
    common.write_text(kept, "new\n")
    assert kept.stat().st_mode & 0o777 == 0o640 and kept.read_text(encoding="utf-8") == "new\n"


def _last_two_lines(code: str) -> list[str]:
    """The last two lines a fresh interpreter prints running ``code`` (this checkout's package first)."""
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip().splitlines()[-2:]
