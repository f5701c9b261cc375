"""``stickslip rsf fit`` on the command line (issue 27): --window, --fix/--free/--guess, --step-weight, --history,
mixed --law, the cost estimate and --max-time, SI JSON beside the record-unit text, exit statuses 2 and 3, and a
simulate -> fit -> simulate chain.  Records are simulated with known parameters (the truth the fits are judged by)."""

from __future__ import annotations

import json
import math
import re
import signal
import time

import numpy as np
import pandas as pd
import pytest

from cli_helpers import run_main
from stickslip import protocols
from stickslip.cli import rsf_cmd
from stickslip.errors import DataError, ModelError, UnitError
from stickslip.rsf import rsf_params, simulate
from stickslip.rsf.data import read_record
from stickslip.units import to_si

UM = 1e-6
#: the truth of every record here; the stiffness 1.6e-3/um = 1600 1/m
TRUE = {"a": 0.010, "b": 0.015, "dc": 10 * UM, "stiffness": 1600.0}
T0 = 1000.0  # the file's own clock starts here: --window is read on it
STEPS = [("1 um/s", "40 s"), ("10 um/s", "40 s"), ("1 um/s", "40 s")]


def _truth_run(every: float = 0.25):
    params = rsf_params(TRUE["a"], TRUE["b"], TRUE["dc"], v_ref=UM, stiffness=TRUE["stiffness"], mu0=0.6)
    history = protocols.velocity_steps([1 * UM, 10 * UM, 1 * UM], [40, 40, 40])
    t = np.arange(0.0, history.duration + 1e-9, every)
    return t, simulate(params, history, times=t)


@pytest.fixture(scope="module")
def record_path(tmp_path_factory):
    """1 -> 10 -> 1 um/s at 4 Hz (481 rows), friction noise 1e-4, displacement in um (its header says so)."""
    t, run = _truth_run()
    rng = np.random.default_rng(7)
    frame = pd.DataFrame({
        "time [s]": T0 + t,
        "load_point_displacement [um]": run.load_point_displacement / UM + 0.005 * rng.standard_normal(t.size),
        "friction": run.friction + 1e-4 * rng.standard_normal(t.size),
    })  # fmt: skip
    path = tmp_path_factory.mktemp("rsf-fit-cli") / "record.csv"
    frame.to_csv(path, index=False)
    return path


# --- units -----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("text", ["1.6e-3/um", "1.6e-3 /um", "1.6e-3 1/um", "1.6e-3 um^-1"])
def test_a_stiffness_per_micrometre_reads_as_an_inverse_length(text):
    assert to_si(text, "per_length", "k") == pytest.approx(1.6e-3 / UM, rel=1e-14)


def test_a_leading_slash_is_per_unit_only_after_a_number():
    assert to_si("2e-5/s", "rate", "r") == pytest.approx(2e-5, rel=1e-14)
    with pytest.raises(UnitError, match="has no number"):
        to_si("/um", "per_length", "k")
    with pytest.raises(UnitError, match="expected a length"):
        to_si("1.6e-3/um", "length", "dc")


# --- bad input: one line, exit 2, naming the option, before any fitting ----------------------------------------


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (["--window", "1000:1050"], '--window "1000 s"'),
        (["--window", "1050 s:1000 s"], "--window"),
        (["--window", "2000 s:3000 s"], "0 rows"),
        (["--window", "1000 s"], "START:END"),
        (["--fix", "dc=20"], '--fix dc="20 um"'),
        (["--fix", "bogus=1"], "unknown parameter 'bogus'"),
        (["--fix", "dc"], "KEY=VALUE"),
        (["--fix", "dc=20 um", "--fix", "dc=3 um"], "given twice"),
        (["--fix", "dc=-1 um"], "--fix dc"),
        (["--fix", "a=0.01", "--guess", "a=0.02"], "--fix a and --guess a"),
        (["--fix", "stiffness=1.6e-3/um", "--fit-stiffness"], "--fix stiffness and --fit-stiffness"),
        (["--fix", "stiffness=1.6e-3/um", "--stiffness", "1e-3 1/um"], "--stiffness and --fix stiffness"),
        (["--fix", "stiffness=30 MPa/mm"], "--normal-stress"),
        (["--fix", "b2=0.01"], "--states 2"),
        (["--fix", "trend=5/m", "--trend"], "--fix trend and --trend"),
        (["--free", "k"], "--free 'k'"),
        (["--law", "aging,slip", "--states", "1"], "--law 'aging,slip'"),
        (["--law", "aging,bogus"], "law 'bogus'"),
        (["--law", "aging,slip,prz"], "at most 2"),
        (["--step-weight", "-1"], "--step-weight"),
        (["--history", "measured", "--segment", "1 um/s:120 s"], "--history measured and --segment"),
        (["--max-time", "300"], '--max-time "300 s"'),
        (["--max-time", "1 ms"], '--max-time 0.001 s; allow it with --max-time "'),
    ],
)
def test_bad_input_is_one_line_naming_the_option_exit_2(record_path, capsys, args, named):
    code, out, err = run_main(capsys, "rsf", "fit", str(record_path), *args)
    assert code == 2, err
    assert err.startswith("stickslip: error:") and err.count("\n") == 1 and out == ""
    assert named in err, err


def test_an_implausible_load_point_speed_is_refused_at_once(record_path, tmp_path, capsys):
    """Issue 27 item 4: micrometres read as metres put the load point at 1-10 m/s and the fit ran ~17 minutes."""
    frame = pd.read_csv(record_path)
    frame.columns = ["time", "displacement", "friction"]  # the unit no longer in the header: read as metres
    path = tmp_path / "no-unit.csv"
    frame.to_csv(path, index=False)
    code, _, err = run_main(capsys, "rsf", "fit", str(path), "--max-time", "20 s")
    assert code == 2 and err.startswith("stickslip: error:") and err.count("\n") == 1, err
    assert "m/s" in err and "--displacement-unit" in err


# --- what the options hand to fit_record -----------------------------------------------------------------------


class _Stop(DataError):
    pass


@pytest.fixture
def captured(monkeypatch):
    """fit_record replaced by a stub that keeps its arguments and stops the command (exit 2, no fit)."""
    calls: list[dict] = []

    def stub(record, **kwargs):
        calls.append(kwargs)
        raise _Stop("stub: stopped before fitting")

    monkeypatch.setattr("stickslip.rsf.fit.fit_record", stub)
    return calls


def _settings(capsys, captured, path, *args):
    code, _, err = run_main(capsys, "rsf", "fit", str(path), *args)
    assert code == 2 and "stub: stopped" in err, err
    return captured[-1]


def test_fix_guess_window_weight_and_mixed_laws_reach_fit_record_in_si(record_path, capsys, captured):
    kwargs = _settings(capsys, captured, record_path, "--fix", "dc=20 um", "--fix", "mu0=0.6", "--fix",
                       "stiffness=1.6e-3/um", "--guess", "a=0.02", "--guess", "dc2=0.1 mm", "--window",
                       "1010 s:1100 s", "--step-weight", "5", "--law", "aging,slip")  # fmt: skip
    assert kwargs["fixed"] == pytest.approx({"dc": 20 * UM, "mu0": 0.6, "stiffness": 1600.0}, rel=1e-14)
    assert kwargs["guess"] == pytest.approx({"a": 0.02, "dc2": 1e-4}, rel=1e-14)
    assert kwargs["window"] == (1010.0, 1100.0)  # on the file's own clock
    assert kwargs["step_weight"] == 5.0
    assert kwargs["law"] == ("aging", "slip") and kwargs["states"] == 2
    assert "fit_stiffness" not in kwargs and kwargs["protocol"] is None and kwargs["trend"] is False


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--stiffness", "1.6e-3 1/um"], {"fixed": {"stiffness": 1600.0}}),
        (["--stiffness", "1.6e-3 1/um", "--fit-stiffness"], {"guess": {"stiffness": 1600.0}, "fit_stiffness": True}),
        (["--guess", "stiffness=1.6e-3/um"], {"guess": {"stiffness": 1600.0}, "fit_stiffness": True}),
        (["--stiffness", "48 MPa/m", "--normal-stress", "30 MPa"], {"fixed": {"stiffness": 1.6}}),
        (["--free", "trend", "--free", "time_trend"], {"trend": "both"}),
        (["--fix", "trend=5/m", "--trend", "time"], {"fixed": {"trend": 5.0}, "trend": "time"}),
        (["--window", "1060 s:"], {"window": (1060.0, T0 + 120.0)}),  # (open-ended; it holds the step at 1080 s)
    ],
)
def test_stiffness_and_drift_words(record_path, capsys, captured, args, expected):
    kwargs = _settings(capsys, captured, record_path, *args)
    for key, value in expected.items():
        assert kwargs[key] == (value if isinstance(value, str) else pytest.approx(value, rel=1e-12)), key


def test_history_measured_drives_the_fit_with_the_measured_displacement(record_path, capsys, captured):
    from stickslip.rsf.data import measured_history

    kwargs = _settings(capsys, captured, record_path, "--history", "measured")
    expected = measured_history(read_record(record_path))
    assert len(expected.segments) > 3  # many short pieces, not the three steps
    np.testing.assert_array_equal(kwargs["protocol"].velocities, expected.velocities)
    np.testing.assert_array_equal(kwargs["protocol"].boundaries, expected.boundaries)


def test_a_search_that_ends_where_the_model_cannot_run_is_a_failed_fit_exit_3(
    record_path, tmp_path, capsys, monkeypatch
):
    def blows_up(record, **kwargs):
        raise ModelError("rate-and-state fit: the best parameters found cannot be evaluated: blow-up")

    monkeypatch.setattr("stickslip.rsf.fit.fit_record", blows_up)
    code, out, err = run_main(capsys, "rsf", "fit", str(record_path), "-o", str(tmp_path / "never.toml"))
    assert code == 3 and out == ""
    assert (
        err.splitlines()[-1] == "stickslip: fit failed: rate-and-state fit: the best parameters found cannot be "
        "evaluated: blow-up"
    )


# --- the cost estimate ------------------------------------------------------------------------------------------


def test_the_estimated_runs_bracket_the_runs_a_fit_makes(record_path, monkeypatch):
    """Counted model runs of a real fit against the estimated count (runs, not seconds: a count does not depend on
    the machine's load)."""
    import stickslip.rsf.fit as fit_module

    record = read_record(record_path)
    settings = {"law": "aging", "states": 1, "trend": False, "protocol": None, "mcmc_steps": 0, "seed": None}
    cost = rsf_cmd.estimate_fit_cost(record, settings)
    assert cost.free == 5 and cost.run_seconds > 0
    runs = 0
    original = fit_module.simulate

    def counting(*args, **kwargs):
        nonlocal runs
        runs += 1
        return original(*args, **kwargs)

    monkeypatch.setattr(fit_module, "simulate", counting)
    fit = fit_module.fit_record(record, **settings)
    assert fit.status == "ok", fit.reason
    assert cost.runs / 2 <= runs <= 2 * cost.runs, (runs, cost.runs)  # a converged fit: no restarts


def test_a_fit_still_running_at_max_time_is_stopped_exit_3(record_path, tmp_path, capsys, monkeypatch):
    """The estimate can be wrong (the issue's fit ran 17 minutes): the real fit, estimated as instant, is stopped
    at --max-time inside the optimiser and the integrator, and nothing is written."""
    monkeypatch.setattr(rsf_cmd, "estimate_fit_cost", lambda record, settings: rsf_cmd.FitCost(1e-6, 90, 5))
    output = tmp_path / "fit.toml"
    began = time.perf_counter()
    # the whole fit takes 0.3 s warm on a quiet machine (1-4 s loaded): a limit well under it stops it wherever
    code, out, err = run_main(capsys, "rsf", "fit", str(record_path), "--max-time", "0.03 s", "-o", str(output))
    assert time.perf_counter() - began < 3.0
    assert code == 3 and out == "" and not output.exists()
    assert err.startswith("stickslip: fit failed: stopped at --max-time 0.03 s") and err.count("\n") == 1, err
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)  # the alarm is off again


# --- real fits: SI JSON, held and started stiffness, windows, exit 3 ------------------------------------------


def _text_value(text: str, name: str) -> tuple[float, str]:
    """The value and unit of one parameter line of the text report ("  dc   9.98 ± 0.01 µm   95 % [...]")."""
    line = next(line for line in text.splitlines() if line.strip().startswith(name + " "))
    match = re.match(rf"\s*{name}\s+(\S+)(?: ± \S+)? ?([^\s(]*)", line)
    return float(match.group(1)), match.group(2).replace("µ", "u")


def test_json_is_si_and_the_text_is_in_the_records_unit(record_path, tmp_path, capsys):
    """Issue 27 items 4 and 9: the unit named in a mapped header is used (it was read as metres), the text report
    gives Dc in it (um) and the JSON in SI (the -o sidecar and --json hold the same report)."""
    frame = pd.read_csv(record_path)
    frame.columns = ["Time (s)", "LP Displacement (um)", "Friction"]
    path = tmp_path / "lab.csv"
    frame.to_csv(path, index=False)
    output = tmp_path / "fit.toml"
    code, out, err = run_main(capsys, "rsf", "fit", str(path), "--columns",
                              'time="Time (s)",displacement="LP Displacement (um)",friction=Friction', "--fix",
                              "stiffness=1.6e-3/um", "-o", str(output))  # fmt: skip
    assert code == 0, err
    report = json.loads((tmp_path / "fit.params.json").read_text())["fit"]
    dc_text, unit = _text_value(out, "dc")
    assert unit == "um"
    assert report["parameters"]["dc"]["value"] == pytest.approx(to_si(f"{dc_text} {unit}", "length"), rel=1e-5)
    stiffness = report["parameters"]["stiffness"]
    assert stiffness["fixed"] and stiffness["value"] == pytest.approx(1600.0, rel=1e-14)  # 1/m, as typed in 1/um
    dc = report["parameters"]["dc"]
    assert dc["value"] == pytest.approx(TRUE["dc"], rel=0.01) and dc["interval"][0] < dc["value"] < dc["interval"][1]
    assert "time:" in out and "estimated" in out


def test_a_stiffness_given_with_fit_stiffness_is_a_start_not_a_constraint(record_path, capsys):
    code, out, err = run_main(capsys, "rsf", "fit", str(record_path), "--stiffness", "3e-3 1/um", "--fit-stiffness",
                              "--json")  # fmt: skip
    assert code == 0, err
    stiffness = json.loads(out)["parameters"]["stiffness"]
    assert not stiffness["fixed"]
    assert stiffness["value"] == pytest.approx(TRUE["stiffness"], rel=0.01)  # from 3000 1/m to the truth, 1600


def test_a_window_fits_only_its_rows(record_path, capsys):
    """The first step alone (t = 1000-1075 s on the file's clock): 301 rows, the truth inside the intervals."""
    code, out, err = run_main(capsys, "rsf", "fit", str(record_path), "--window", "1000 s:1075 s", "--json")
    assert code == 0, err
    report = json.loads(out)
    assert report["record"]["rows"] == 301
    for key in ("a", "b", "dc", "stiffness"):
        lo, hi = report["parameters"][key]["interval"]
        assert lo <= TRUE[key] <= hi, key


def test_a_fit_that_cannot_be_trusted_exits_3_in_one_line(record_path, tmp_path, capsys):
    frame = pd.read_csv(record_path)
    frame["friction"] = 0.6 + 1e-4 * np.random.default_rng(3).standard_normal(len(frame))  # no velocity dependence
    path = tmp_path / "flat.csv"
    frame.to_csv(path, index=False)
    output = tmp_path / "flat.toml"
    code, out, err = run_main(capsys, "rsf", "fit", str(path), "--fix", "stiffness=1.6e-3/um", "--json", "-o",
                              str(output))  # fmt: skip
    assert code == 3
    assert json.loads(out)["status"] == "failed" and not output.exists()
    last = err.splitlines()[-1]
    assert last.startswith("stickslip: fit failed:") and "no significant response" in last
    assert err.endswith(last + "\n")


# --- one command writes what the next reads ---------------------------------------------------------------------


@pytest.mark.parametrize("name", ["fit.toml", "fit.json"])
def test_simulate_fit_simulate_chain(tmp_path, capsys, name):
    """rsf simulate -o trace.csv; rsf fit trace.csv -o fit.toml; rsf simulate --params fit.toml: the rerun gives
    the first run's friction (the fit of a noise-free trace recovers the truth).  ``-o fit.json`` is JSON, as its
    name says (it held TOML, which ``--params fit.json`` refused as malformed JSON), with no sidecar."""
    segments = [arg for v, t in STEPS for arg in ("--segment", f"{v}:{t}")]
    trace = tmp_path / "trace.csv"
    model = ["--a", str(TRUE["a"]), "--b", str(TRUE["b"]), "--dc", "10 um", "--v-ref", "1 um/s", "--stiffness",
             "1.6e-3/um"]  # fmt: skip
    code, _, err = run_main(capsys, "rsf", "simulate", *model, *segments, "--every", "0.25 s", "-o", str(trace))
    assert code == 0, err
    fitted = tmp_path / name
    code, out, err = run_main(capsys, "rsf", "fit", str(trace), "-o", str(fitted), "--json")
    assert code == 0, err
    assert json.loads(out)["parameters"]["dc"]["value"] == pytest.approx(TRUE["dc"], rel=1e-3)
    if name.endswith(".json"):
        assert json.loads(fitted.read_text())["parameters"]["states"][0]["dc"] == pytest.approx(TRUE["dc"], rel=1e-3)
        assert not (tmp_path / "fit.params.json").exists()
    else:
        assert (tmp_path / "fit.params.json").exists()
    code, _, err = run_main(capsys, "rsf", "simulate", "--params", str(fitted), *segments, "--every", "0.25 s",
                            "-o", str(tmp_path / "again.csv"))  # fmt: skip
    assert code == 0, err
    first, again = (pd.read_csv(path, skiprows=1) for path in (trace, tmp_path / "again.csv"))  # Run CSVs
    assert len(first) == len(again) == 481
    assert np.max(np.abs(again["friction [1]"] - first["friction [1]"])) < 1e-5  # of a 0.012 step
    assert math.isclose(first["friction [1]"].iloc[0], 0.6, abs_tol=1e-12)


def test_a_fit_stopped_inside_the_optimiser_leaves_numpy_warnings_on(record_path, monkeypatch):
    """lmfit's leastsq sets numpy's errors to 'ignore' and restores them only when it returns: a stop inside it (the
    --max-time alarm, raised from the model run) left overflow warnings off for the rest of the process (found as a
    later test of the CLI's warning summary failing on the same worker)."""
    import numpy as np

    from stickslip.rsf import fit as fit_module
    from stickslip.rsf.data import read_record

    class Stop(BaseException):
        pass

    real, calls = fit_module.simulate, []

    def stopping(*args, **kwargs):
        calls.append(1)
        if len(calls) > 5:  # inside the optimiser's iterations
            raise Stop
        return real(*args, **kwargs)

    monkeypatch.setattr(fit_module, "simulate", stopping)
    before = np.geterr()
    with pytest.raises(Stop):
        fit_module.fit_record(read_record(record_path))
    assert np.geterr() == before
