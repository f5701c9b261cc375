"""The phase diagram of a transient sweep: its boundary Kc(V0) in seconds, agreeing with critical_stiffness, and
the axes kept to the rows' range (80 direct Kc took ~4 min, and a boundary up to 4e11 Pa/m stretched the stiffness
axis five decades above rows of at most 4 MPa/m)."""

from __future__ import annotations

import time

import numpy as np
import pytest

#: the rows' velocities (m/s) and block stiffnesses G/h (Pa/m): Vc of gelatin-glass (124 um/s) among them
VELOCITIES = "60um/s..250um/s:3:log"
STIFFNESSES = "100kPa/m..2MPa/m:4:log"


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    """A 3 x 4 transient sweep with the stick chains, 1 s per point (the boundary needs the rows' range only)."""
    from stickslip.cli.main import main as cli_main

    out = tmp_path_factory.mktemp("transient_sweep") / "sw"
    argv = ["sweep", "--model", "transient", "--stick-population", "--vary", f"pulling_velocity={VELOCITIES}",
            "--vary", f"block.stiffness={STIFFNESSES}", "--duration", "1s", "--workers", "0", "--quiet",
            "-o", str(out)]  # fmt: skip
    with pytest.raises(SystemExit) as done:
        cli_main(argv)
    assert done.value.code == 0
    return out


def test_the_plot_is_drawn_in_seconds_and_keeps_the_rows_range(sweep):
    import matplotlib

    matplotlib.use("Agg")
    from stickslip.plots.sweeps import plot_phase_diagram
    from stickslip.sweeps import load_sweep

    frame, spec = load_sweep(sweep)
    start = time.process_time()
    ax = plot_phase_diagram(frame, spec, "pulling_velocity", "block.stiffness", color="regime")
    spent = time.process_time() - start
    assert spent < 30.0, spent  # 80 direct Kc: ~160-240 s
    low, high = ax.get_ylim()
    rows = frame["block.stiffness"].to_numpy(dtype=float)  # drawn in Pa/m, cells half a step (x1.65) beyond
    assert rows.min() / 2 <= low <= rows.min() and rows.max() <= high <= 2 * rows.max(), (low, high)
    lines = [line for line in ax.get_lines() if line.get_label().startswith("K = Kc(V0)")]
    assert len(lines) == 1
    # drawn inside the rows' range (Kc falls to 0 at Vc, so the curve crosses every stiffness just below it)
    x, y = (np.asarray(a, dtype=float) for a in lines[0].get_data())
    inside = (y >= low) & (y <= high)
    assert inside.any() and "outside" not in lines[0].get_label()
    assert np.all(x[inside] > 100.0) and np.all(x[inside] < 124.2)  # um/s, just below Vc = 124.1 um/s
    ax.figure.clf()


def test_the_boundary_agrees_with_critical_stiffness():
    """The curve's computed points against a direct critical_stiffness (the full scan), and a point between two of
    them against the one there: the drawn curve is Kc(V0), to the interpolation's few per cent."""
    import pandas as pd

    import stickslip
    from stickslip.models.transient import BOUNDARY_FILL
    from stickslip.transient import critical_stiffness

    gel = stickslip.load_parameters("gelatin-glass")
    model = stickslip.get_model("transient")
    frame = pd.DataFrame({"pulling_velocity": [60e-6, 250e-6], "block.effective_stiffness": [1e5, 4e6]})
    (boundary,) = model.stability_boundary({}, "pulling_velocity", "block.effective_stiffness", frame)
    v, k = boundary.x, boundary.y
    vc = stickslip.critical_point(gel).velocity
    assert np.all(v < vc) and np.all(np.diff(k) < 0)  # Kc > 0 only below Vc, falling towards it
    for at in (v[0], v[-1]):  # computed points (ends of the curve)
        assert k[v == at][0] == pytest.approx(critical_stiffness(gel, float(at)), rel=1e-4)
    # midway between the two slowest computed points (the widest gap, 112-123 um/s), drawn, not computed
    mid = BOUNDARY_FILL // 2
    assert k[mid] == pytest.approx(critical_stiffness(gel, float(v[mid])), rel=0.1)
