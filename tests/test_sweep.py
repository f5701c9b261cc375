"""Sweeps without a cluster: --vary parsing, the designs, the output folder, resume, refusals, phase diagrams."""

from __future__ import annotations

import itertools
import json
import math
import sys

import numpy as np
import pandas as pd
import pytest

import stickslip
from cli_helpers import run_main
from stickslip.errors import DataError, ParameterError
from stickslip.plots.sweeps import plot_phase_diagram
from stickslip.sweeps import build_spec, load_sweep, run_sweep
from stickslip.sweeps.models import get_model
from stickslip.sweeps.sampling import latin_hypercube, permute
from stickslip.sweeps.spec import parse_vary
from stickslip.sweeps.store import MANIFEST

DIMENSIONS = get_model("quasi-static").dimensions()
VELOCITIES = "pulling_velocity=20 um/s..2 mm/s:4:log"


def results(frame: pd.DataFrame) -> pd.DataFrame:
    """Everything but the wall time, which differs from run to run."""
    return frame.drop(columns="wall_time")


# --------------------------------------------------------------------------- --vary
def test_log_range_with_units_is_geometric_and_keeps_its_ends_exactly():
    axis = parse_vary("bonds.bond_time=100 us..1 ms:20:log", DIMENSIONS)
    values = np.array(axis.values)
    assert values.size == 20 and values[0] == pytest.approx(1e-4, rel=1e-15) and values[-1] == pytest.approx(1e-3)
    np.testing.assert_allclose(values[1:] / values[:-1], 10 ** (1 / 19), rtol=1e-12)


def test_linear_range_and_explicit_list_convert_units_to_si():
    linear = parse_vary("block.height=1 cm..3 cm:3", DIMENSIONS)
    np.testing.assert_allclose(linear.values, [0.01, 0.02, 0.03], rtol=1e-15)
    listed = parse_vary("pulling_velocity=5 um/s, 0.05 mm/s,1 mm/s", DIMENSIONS)
    np.testing.assert_allclose(listed.values, [5e-6, 5e-5, 1e-3], rtol=1e-15)
    sampled = parse_vary("pulling_velocity=5 um/s..5 mm/s:log", DIMENSIONS)
    assert sampled.is_range and sampled.log and sampled.low == pytest.approx(5e-6) and sampled.high == 5e-3


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--vary", "nonsense.key=1 s..2 s:3"], "unknown key 'nonsense.key'"),
        (["--vary", "pulling_velocity"], "expected KEY=LO..HI:N[:log]"),
        (["--vary", "pulling_velocity=5 um/s..1 mm/s:many"], "whole number, got 'many'"),
        (["--vary", "pulling_velocity=5 um/s..1 mm/s:0"], "at least 1, got 0"),
        (["--vary", "pulling_velocity=5 s..1 mm/s:3"], "expected a velocity"),
        (["--vary", "pulling_velocity=0 um/s..1 mm/s:3:log"], "a log range needs positive ends"),
        (["--vary", "pulling_velocity=5 um/s..1 mm/s:3:cubic"], "unknown spacing 'cubic'"),
        (["--vary", "pulling_velocity=5 um/s..1 mm/s"], "needs --samples N"),
        (["--vary", "pulling_velocity=5 um/s,1 mm/s", "--samples", "10"], "must be a range"),
        (["--vary", "pulling_velocity=5 um/s", "--vary", "pulling_velocity=6 um/s"], "varied twice"),
        (["--vary", "block.height=-1 cm..1 cm:3", "--v0", "50 um/s"], "--vary block.height"),
        (["--vary", "block.height=1 cm..2 cm:3"], "give --v0 V"),
        (["--vary", "block.height=1 cm,2 cm", "--vary", "block.stiffness=1 kPa/m", "--v0", "1 mm/s"], "only one"),
        (["--vary", "pulling_velocity=5 um/s", "--duration", "-3 s"], "--duration"),
        (["--vary", "pulling_velocity=5 um/s", "--v0", "5 um/s"], "give the pulling velocity once"),
    ],
)
def test_bad_sweep_options_fail_in_one_line(capsys, tmp_path, args, expected):
    status, _, err = run_main(capsys, "sweep", *args, "-o", str(tmp_path / "out"), "--workers", "0", "--quiet")
    assert status == 2, err
    assert err.startswith("stickslip: error:") and err.count("\n") == 1 and expected in err, err
    assert not (tmp_path / "out").exists() or not list((tmp_path / "out").iterdir())


# --------------------------------------------------------------------------- designs
@pytest.mark.parametrize("size", [1, 2, 7, 1000, 4099])
def test_feistel_permutation_is_a_bijection(size):
    image = permute(np.arange(size), size, seed=11, dimension=2)
    assert sorted(image.tolist()) == list(range(size))


@pytest.mark.parametrize("log", [False, True])
def test_latin_hypercube_puts_exactly_one_point_in_each_stratum_of_each_key(log):
    n, low, high = 500, 2e-6, 3e-3
    for dimension in range(3):
        values = latin_hypercube(np.arange(n), n, 7, dimension, low, high, log)
        unit = (np.log(values / low) / np.log(high / low)) if log else (values - low) / (high - low)
        assert np.all((unit >= 0) & (unit < 1))
        assert sorted(np.floor(unit * n).astype(int).tolist()) == list(range(n))
    a = latin_hypercube(np.arange(n), n, 7, 0, low, high, log)
    b = latin_hypercube(np.arange(n), n, 7, 1, low, high, log)
    assert abs(np.corrcoef(a, b)[0, 1]) < 0.2  # the keys are permuted independently


def test_points_of_a_batch_are_the_same_whichever_way_the_sweep_is_cut():
    spec = build_spec(["bonds.bond_time=100 us..1 ms:log", VELOCITIES.split(":")[0]], samples=37, seed=5)
    whole = spec.points(0, 37)
    parts = [spec.points(i, i + 5) for i in range(0, 37, 5)]
    for key in spec.keys:
        np.testing.assert_array_equal(whole[key], np.concatenate([p[key] for p in parts]))
    other = build_spec(["bonds.bond_time=100 us..1 ms:log", VELOCITIES.split(":")[0]], samples=37, seed=6)
    assert not np.array_equal(whole["bonds.bond_time"], other.points(0, 37)["bonds.bond_time"])


def test_grid_covers_the_product_once_with_the_velocity_fastest():
    spec = build_spec(["pulling_velocity=1 um/s,2 um/s,3 um/s", "block.height=1 cm,2 cm", "bonds.bond_time=1 ms,2 ms"])
    points = spec.points(0, spec.size)
    triples = list(zip(*(points[k].tolist() for k in spec.keys), strict=True))
    assert sorted(triples) == sorted(itertools.product(*(a.values for a in spec.axes)))
    assert points["pulling_velocity"][:3].tolist() == [1e-6, 2e-6, 3e-6]


# --------------------------------------------------------------------------- output folder, resume, refusal
@pytest.fixture(scope="module")
def small_sweep(tmp_path_factory):
    """A 4 x 2 grid run in this process (workers=0), with its specification and folder."""
    folder = tmp_path_factory.mktemp("sweep") / "out"
    spec = build_spec([VELOCITIES, "block.height=1 cm,2 cm"], duration="60 s")
    run_sweep(spec, folder, workers=0, batch_size=3)
    return spec, folder


def test_folder_reads_whole_with_pandas_and_manifest_is_skipped(small_sweep):
    spec, folder = small_sweep
    frame = pd.read_parquet(folder)
    assert len(frame) == spec.size == 8 and sorted(frame["point"]) == list(range(8))
    assert list(frame.columns[:3]) == ["point", "pulling_velocity", "block.height"]
    manifest = json.loads((folder / MANIFEST).read_text())
    assert manifest["version"] == stickslip.__version__ and manifest["batch_size"] == 3
    assert manifest["specification"]["axes"][1] == {"key": "block.height", "values": [0.01, 0.02], "log": False}
    assert manifest["specification"]["fixed"]["bonds.bond_time"] == stickslip.load_parameters().bonds.bond_time


def test_resume_rewrites_only_missing_chunks_and_ignores_a_half_written_one(small_sweep, tmp_path):
    spec, folder = small_sweep
    before, _ = load_sweep(folder)
    copy = tmp_path / "copy"
    copy.mkdir()
    for path in folder.iterdir():
        (copy / path.name).write_bytes(path.read_bytes())
    (copy / "part-000001.parquet").unlink()
    half = copy / ".part-000001.parquet.x1y2z3.parquet.tmp"
    half.write_bytes(b"PAR1 half a chunk")
    untouched = (copy / "part-000000.parquet").stat().st_mtime_ns
    run_sweep(spec, copy, workers=0)
    after, _ = load_sweep(copy)
    pd.testing.assert_frame_equal(results(after), results(before))
    assert not half.exists() and (copy / "part-000000.parquet").stat().st_mtime_ns == untouched


def test_another_specification_is_refused_in_one_line_unless_overwrite(small_sweep, tmp_path, capsys):
    folder = small_sweep[1]
    args = ["sweep", "--vary", "pulling_velocity=20 um/s..2 mm/s:5:log", "--workers", "0", "--quiet"]
    status, _, err = run_main(capsys, *args, "-o", str(folder))
    assert status == 2 and err.count("\n") == 1 and "another specification" in err and "--overwrite" in err, err
    fresh = tmp_path / "again"
    assert run_main(capsys, *args, "-o", str(fresh))[0] == 0
    with pytest.raises(ParameterError, match=r"fixed value of bonds\.bond_time"):
        run_sweep(build_spec([VELOCITIES.replace(":4", ":5")], overrides={"bonds.bond_time": "1 ms"}), fresh, workers=0)
    run_sweep(build_spec(["pulling_velocity=1 mm/s"]), fresh, workers=0, overwrite=True)
    assert len(pd.read_parquet(fresh)) == 1


def test_a_folder_of_other_files_is_never_written_into(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(DataError, match=r"not a sweep's \(notes.txt\)"):
        run_sweep(build_spec(["pulling_velocity=1 mm/s"]), tmp_path, workers=0, overwrite=True)
    assert (tmp_path / "notes.txt").read_text() == "mine"


def test_a_failing_point_records_its_error_and_the_sweep_goes_on():
    frame = stickslip.sweep(["bonds.activation_length=0 m,1 angstrom"], pulling_velocity="50 um/s", workers=0)
    failed, fine = frame.iloc[0], frame.iloc[1]
    assert failed["status"] == "error" and "\n" not in failed["message"] and failed["message"]
    assert (math.isnan(failed["period"]) and failed["regime"] is None) or pd.isna(failed["regime"])
    assert fine["status"] == "ok" and fine["regime"] == "stick-slip"


def test_python_sweep_is_a_function_and_the_package_imports():
    import stickslip.sweeps

    assert callable(stickslip.sweep) and stickslip.sweep is stickslip.sweeps.sweep


# --------------------------------------------------------------------------- phase diagrams
def test_phase_diagram_has_log_axes_regime_colours_and_the_critical_velocity(small_sweep, params):
    frame, spec = load_sweep(small_sweep[1])
    ax = plot_phase_diagram(frame, spec, x="pulling_velocity", y="block.height", color="regime")
    assert ax.get_xscale() == "log" and ax.get_yscale() == "linear"
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "V0 = Vc (Eq 9)" in labels and set(frame["regime"]) <= set(labels)
    vc = stickslip.critical_point(params).velocity * 1e6  # the boundary, in um/s, from the model itself
    line = next(line for line in ax.get_lines() if line.get_label() == "V0 = Vc (Eq 9)")
    np.testing.assert_allclose(line.get_xdata(), vc, rtol=1e-9)


def test_sweep_plot_command_writes_an_image_and_refuses_unknown_keys(small_sweep, tmp_path, capsys):
    folder = small_sweep[1]
    image = tmp_path / "phase.png"
    args = ["sweep", "plot", str(folder), "--y", "block.height", "--color", "period", "-o", str(image)]
    status, out, _ = run_main(capsys, *args)
    assert status == 0 and image.read_bytes()[:4] == b"\x89PNG" and str(image) in out
    status, _, err = run_main(capsys, "sweep", "plot", str(folder), "--y", "bonds.bond_time")
    assert status == 2 and "not a varied key" in err and err.count("\n") == 1


def test_progress_is_plain_lines_when_not_a_terminal_and_nothing_when_quiet(tmp_path, capsys):
    args = ["sweep", "--vary", "pulling_velocity=1 mm/s,2 mm/s", "--workers", "0", "-o"]
    status, out, err = run_main(capsys, *args, str(tmp_path / "a"))
    assert status == 0 and out == ""
    assert err.splitlines()[0] == "sweep: 2 points" and "2/2 points (100%)" in err
    last = err.splitlines()[-1]
    assert last.startswith(f"sweep: 2 points in {tmp_path / 'a'} (0 failed); regimes: steady 2; in process (2 points")
    assert last.endswith("parallel efficiency not meaningful")  # issue 31: said in words, in this process
    status, out, err = run_main(capsys, *args, str(tmp_path / "a"))  # resumed: nothing left to do
    assert status == 0 and "2 already done" in err
    assert run_main(capsys, *args, str(tmp_path / "b"), "--quiet")[1:] == ("", "")


@pytest.mark.parametrize("model", ["transient", "rsf"])
def test_a_model_not_in_this_version_is_refused_in_one_line(model, tmp_path, capsys, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, f"stickslip.{model}", None)  # as an install without that module
    status, _, err = run_main(
        capsys, "sweep", "--model", model, "--vary", "pulling_velocity=1 mm/s", "-o", str(tmp_path)
    )
    assert status == 2 and f"no stickslip.{model} module" in err and err.count("\n") == 1, err


def test_a_sweep_of_another_stickslip_version_is_refused(tmp_path):
    spec = build_spec(["pulling_velocity=1 mm/s"])
    run_sweep(spec, tmp_path, workers=0)
    manifest = json.loads((tmp_path / MANIFEST).read_text())
    (tmp_path / MANIFEST).write_text(json.dumps({**manifest, "version": "0.0.1"}))
    with pytest.raises(ParameterError, match=r"same specification but stickslip 0\.0\.1"):
        run_sweep(spec, tmp_path, workers=0)


def test_the_steady_curve_is_solved_once_for_every_block_and_stick(params):
    from stickslip.quasistatic import jump

    stickslip.simulate(params, 50e-6, 30.0)
    before = jump.cached_critical_point.cache_info().misses, jump.branch_interpolant.cache_info().misses
    for height in (0.007, 0.013):
        other = params.with_overrides({"block.height": height, "stick.aging_time": "12 s"})
        assert stickslip.simulate(other, 50e-6, 30.0).critical_velocity == stickslip.critical_point(params).velocity
    after = jump.cached_critical_point.cache_info().misses, jump.branch_interpolant.cache_info().misses
    assert after == before


# --------------------------------------------------------------------------- the adapters of models still to land
def test_transient_adapter_follows_its_contract(monkeypatch, params):
    """A stand-in ``stickslip.transient`` (the quasi-static cycle behind the contract's names) runs the adapter."""
    import types

    calls = []

    def run_transient(p, protocol, control, start, stick_population=False):
        calls.append((control, start, protocol.initial_velocity, protocol.duration))
        return stickslip.simulate(p, protocol.initial_velocity, protocol.duration)

    fake = types.SimpleNamespace(run_transient=run_transient, critical_stiffness=lambda p, v: 2e5 * (v / 1e-4) ** 0.5)
    monkeypatch.setitem(sys.modules, "stickslip.transient", fake)
    vary = ["pulling_velocity=50 um/s,1 mm/s", "block.effective_stiffness=100 kPa/m,300 kPa/m"]
    transient = stickslip.sweep(vary, model="transient", duration="60 s", workers=0)
    quasi = stickslip.sweep(vary, duration="60 s", workers=0)
    assert calls[0][:2] == ("block", "steady") and calls[0][2:] == pytest.approx((50e-6, 60.0)) and len(calls) == 4
    pd.testing.assert_series_equal(transient["regime"], quasi["regime"])
    np.testing.assert_allclose(transient["period"], quasi["period"], rtol=1e-12)  # the last whole cycle = the first
    spec = build_spec(vary, model="transient", duration="60 s")
    ax = plot_phase_diagram(transient, spec, x="pulling_velocity", y="block.effective_stiffness")
    line = next(line for line in ax.get_lines() if line.get_label().startswith("K = Kc"))
    v = line.get_xdata() / 1e6  # drawn in um/s
    np.testing.assert_allclose(line.get_ydata(), 2e5 * (v / 1e-4) ** 0.5, rtol=1e-12)


# --------------------------------------------------------------------------- rate-and-state (stickslip.rsf)
RSF_FIXED = {"a": "0.005", "b": "0.01", "Dc": "10 um", "η": "0.5 s/m"}  # the aliases --vary takes
RSF_VARY = ["k=250 1/m,350 1/m,750 1/m,1000 1/m", "pulling_velocity=10 um/s,20 um/s"]


def rsf_kc(velocity):
    """The Hopf point of one aging-law state with damping: kc = (b - a - eta V)/Dc (docs/rsf.md), in 1/m."""
    return (0.01 - 0.005 - 0.5 * velocity) / 10e-6


@pytest.fixture(scope="module")
def rsf_sweep():
    spec = build_spec(RSF_VARY, model="rsf", overrides=RSF_FIXED, duration="200 s")
    return spec, stickslip.sweep(RSF_VARY, model="rsf", overrides=RSF_FIXED, duration="200 s", workers=0)


def test_rsf_sweep_regimes_follow_the_analytic_critical_stiffness(rsf_sweep):
    """k/kc = 0.5, 0.7 settle on a limit cycle; 1.5, 2 return to steady sliding (eta > 0: no blow-up)."""
    _, frame = rsf_sweep
    kc = rsf_kc(frame["pulling_velocity"])
    np.testing.assert_allclose(frame["critical_stiffness"], kc, rtol=1e-12)
    assert set(np.round(frame["k"] / kc, 1)) == {0.5, 0.7, 1.5, 2.0}
    assert (frame["status"] == "ok").all()
    below, above = frame[frame["k"] < kc], frame[frame["k"] > kc]
    assert (below["regime"] == "stick-slip").all(), below[["k", "pulling_velocity", "regime", "growth"]]
    assert above["regime"].isin(["decaying oscillation", "steady sliding"]).all(), above[["k", "regime"]]
    assert (below["peak_friction"] - below["trough_friction"] > 0.03).all()
    assert (
        (below["trough_friction"] < below["mean_friction"]) & (below["mean_friction"] < below["peak_friction"])
    ).all()
    steady = 0.6 + (0.005 - 0.01) * np.log(above["pulling_velocity"] / 1e-6)  # mu_ss(V0), rsf's mu0 and v_ref
    np.testing.assert_allclose(above["mean_friction"], steady, atol=1e-6)


def test_rsf_sweep_rows_are_those_of_one_by_one_simulations(rsf_sweep):
    from stickslip import protocols, rsf

    spec, frame = rsf_sweep
    fixed = spec.fixed  # the SI values the units gave ("10 um" need not be exactly 10e-6)
    for row in frame.iloc[[0, 3, 6]].itertuples():  # a limit cycle and a stable point at each velocity
        params = rsf.rsf_params(fixed["a"], fixed["b"], fixed["dc"], eta=fixed["eta"], stiffness=row.k)
        run = rsf.simulate(
            params, protocols.constant(row.pulling_velocity, 200.0), start_velocity=1.1 * row.pulling_velocity
        )
        assert row.regime == run.regime.name
        np.testing.assert_allclose(
            [row.period, row.peak_friction, row.trough_friction, row.growth],
            [run.regime.period, run.regime.peak_friction, run.regime.trough_friction, run.regime.growth],
            rtol=1e-9,
        )


def test_rsf_phase_diagram_draws_kc_of_rsf(rsf_sweep):
    spec, frame = rsf_sweep
    ax = plot_phase_diagram(frame, spec, x="k", y="pulling_velocity", color="regime")
    line = next(line for line in ax.get_lines() if line.get_label().startswith("k = kc"))
    v = line.get_ydata() / 1e6  # drawn in um/s
    assert v.min() == pytest.approx(10e-6) and v.max() == pytest.approx(20e-6)
    np.testing.assert_allclose(line.get_xdata(), rsf_kc(v), rtol=1e-12)


@pytest.mark.parametrize(
    ("option", "expected"),
    [
        ("law=nagata", "law: expected one of aging, slip, prz"),
        ("k=1 MPa/m", "expected an inverse length"),
        ("sigma=1 MPa", "unknown rate-and-state key 'sigma'"),
        ("dc=-1 um", "dc: expected a value > 0"),
    ],
)
def test_rsf_sweep_refuses_bad_values_in_one_line(option, expected, tmp_path, capsys):
    status, _, err = run_main(
        capsys, "sweep", "--model", "rsf", "--vary", "pulling_velocity=1 um/s", "--set", option, "-o", str(tmp_path)
    )
    assert status == 2 and expected in err and err.count("\n") == 1, err


def test_a_small_sweep_starts_no_cluster(tmp_path, monkeypatch):
    """Issue 28 item 8: a sweep whose work is projected under the cluster's start-up runs in this process (a
    60-point sweep took 11 s on a local cluster and 2.3 s without); a large one still gets its cluster."""
    import stickslip.sweeps as sweeps
    from stickslip.sweeps import engine

    def no_cluster(*args, **kwargs):
        raise AssertionError("a cluster was started for a small sweep")

    monkeypatch.setattr(sweeps, "dask_client", no_cluster)
    frame = sweeps.sweep(["pulling_velocity=10 um/s..1 mm/s:12:log"], output=tmp_path / "small", duration=10.0)
    assert len(frame) == 12 and (frame["status"] == "ok").all()
    # the same decision when every point looks expensive: the first batch runs here, the rest goes to a cluster
    monkeypatch.setattr(engine, "CLUSTER_START_SECONDS", 0.0)
    spec = sweeps.build_spec(["pulling_velocity=10 um/s..1 mm/s:12:log"], duration=10.0)
    with sweeps.open_store(tmp_path / "large", spec, 3) as store:
        assert engine.compute_while_cheap(store, lambda n: None) is False
        assert store.finished() == {0, 1}  # the first batch pays the one-off costs: the second is the measure
