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


def test_the_plot_is_drawn_in_seconds_on_the_rows_range_and_its_curve_is_kc(sweep):
    """One plot: its CPU, its axes, and its curve against a direct critical_stiffness (the full scan) at a computed
    point and midway between the two computed points furthest apart (the interpolation's few per cent)."""
    import matplotlib

    matplotlib.use("Agg")
    import stickslip
    from stickslip.models.transient import BOUNDARY_FILL
    from stickslip.plots.sweeps import plot_phase_diagram
    from stickslip.sweeps import load_sweep
    from stickslip.transient import critical_stiffness

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
    gel = stickslip.load_parameters("gelatin-glass")
    model = stickslip.get_model("transient")
    vc = stickslip.critical_point(gel).velocity * 1e6
    assert np.all(x < vc) and np.all(np.diff(y) < 0)  # Kc > 0 only below Vc, falling towards it

    def kc_on_axis(v_um: float) -> float:  # the effective Kc as the axis shows it (block.stiffness)
        return float(model.stiffness_of("block.stiffness", gel, np.array([critical_stiffness(gel, v_um * 1e-6)]))[0])

    computed = x[::BOUNDARY_FILL]  # every BOUNDARY_FILL-th point drawn is a computed one
    assert y[-1] == pytest.approx(kc_on_axis(computed[-1]), rel=1e-4)
    widest = int(np.argmax(np.diff(computed)))
    mid = widest * BOUNDARY_FILL + BOUNDARY_FILL // 2
    assert y[mid] == pytest.approx(kc_on_axis(x[mid]), rel=0.1)
