"""The report's phase diagram: regimes of the paper's parameters over V0 and the block's stiffness.

A grid sweep (:mod:`stickslip.sweeps`, in this process: no cluster for ~140
points) of V0 = 5 µm/s … 5 mm/s by G/h × 0.1 … × 10 of the paper's block,
drawn with the quasi-static boundary V0 = Vc (Eq 9).  Each point is a run of
the ``quasi-static`` model through the model interface (the sweep's only way
to run a model: ``model.parameters`` + ``model.run`` -> Run -> one row).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from .computations import ModelRun
from .figures import ReportFigure

#: Grid of the report's phase diagram (velocities by stiffness factors); regimes do not depend on the run length.
VELOCITIES = "5 um/s..5 mm/s:15:log"
STIFFNESS_FACTORS = (0.1, 10.0, 9)
DURATION = "20 s"
#: the registered model the diagram sweeps (its regimes and its analytic boundary)
MODEL = "quasi-static"
#: the name of the dotted line at the paper's block (its CSV: phase_diagram_paper-s-block.csv)
BLOCK_LINE = "paper's block"


def phase_diagram_figure(run: ModelRun) -> ReportFigure:
    import tempfile

    from ..plots.sweeps import plot_phase_diagram
    from ..sweeps import build_spec, load_sweep, run_sweep

    params = run.params
    low, high, count = STIFFNESS_FACTORS
    stiffness = params.block.stiffness
    spec = build_spec(
        [f"pulling_velocity={VELOCITIES}", f"block.stiffness={low * stiffness!r}..{high * stiffness!r}:{count}:log"],
        model=MODEL,
        params=params,
        duration=DURATION,
    )
    with tempfile.TemporaryDirectory() as folder:
        # one chunk: the folder is thrown away, so resuming needs no finer chunks (45 chunks of 3 points cost
        # ~0.3 s CPU of writing and syncing Parquet files; the rows are the same)
        run_sweep(spec, f"{folder}/sweep", workers=0, batch_size=spec.size)
        frame, _ = load_sweep(f"{folder}/sweep")
    ax = plot_phase_diagram(frame, spec, x="pulling_velocity", y="block.stiffness", color="regime")
    # the paper's block across the plot, as a line in data coordinates (an axhline is a reference line, which the
    # curves' CSV export skips), named for its file; the axes' limits are already fixed
    ax.plot(ax.get_xlim(), [stiffness, stiffness], color="white", linewidth=1.0, linestyle=":", gid=BLOCK_LINE)
    ax.set_title("Regimes over pulling velocity and block stiffness (quasi-static model)", fontsize=11)
    counts = frame["regime"].value_counts()
    at_paper = frame[(frame["block.stiffness"] - stiffness).abs() <= 1e-9 * stiffness]
    vc = run.critical.velocity if run.critical is not None else None
    band = stick_slip_band(at_paper["pulling_velocity"], at_paper["regime"], run.jump_floor, vc, stiffness)
    caption = (
        f"Regime of {len(frame)} runs of the quasi-static cycle (a {VELOCITIES.split(':')[1]} × {count} grid, log"
        f" spaced: V0 = 5 µm/s to 5 mm/s, block stiffness G/h from {low:g} to {high:g} times the paper's, set through"
        f" the block height): {', '.join(f'{n} {c}' for n, c in counts.items())}. The dashed line is V0 = Vc"
        f" = {run.critical.velocity * 1e6 if run.critical and run.critical.velocity else float('nan'):.1f} µm/s"
        " (Eq 9): above it the slip settles onto the steady curve; below it a stick that ends is followed by"
        f" stick-slip, and at low V0 or a soft block the chains age faster than they are loaded and the block stays"
        f" stuck. {band} Made with `stickslip sweep` (docs/sweep.md)."
    )
    return ReportFigure("phase_diagram", "Phase diagram", "Stick-slip, steady sliding and sticking", caption, ax.figure)


def stick_slip_band(
    velocities: Iterable[float], regimes: Iterable[str], jump_floor: float | None, vc: float | None, stiffness: float
) -> str:
    """Where the grid finds stick-slip at the paper's block, beside where the theory puts it.

    The grid can only bracket a boundary between two of its points; the theory's boundaries are computed: Vc
    (Eq 9) above, and below the lowest V0 whose σs the steady curve still carries (Eqs 15, 8).
    """
    points = sorted(zip(velocities, regimes, strict=True))
    slipping = [k for k, (_, regime) in enumerate(points) if regime == "stick-slip"]
    where = f"At the paper's block (dotted line, G/h = {stiffness / 1e3:.0f} kPa/m)"
    if slipping:
        first, last = slipping[0], slipping[-1]
        below = f"{points[first - 1][0] * 1e6:.3g} µm/s: {points[first - 1][1]}" if first > 0 else None
        above = f"{points[last + 1][0] * 1e6:.3g} µm/s: {points[last + 1][1]}" if last + 1 < len(points) else None
        outside = "; ".join(x for x in (below, above) if x)
        grid = (
            f"{where} the grid's stick-slip points run from {points[first][0] * 1e6:.3g} to"
            f" {points[last][0] * 1e6:.3g} µm/s" + (f" (its next points: {outside})" if outside else "")
        )
    else:
        grid = f"{where} no grid point is in stick-slip"
    if jump_floor is None or vc is None:
        return grid + "; the theory's boundary could not be computed here."
    return (
        f"{grid}. The model's own boundary, which the grid only brackets: stick-slip from"
        f" {jump_floor * 1e6:.4g} µm/s (below it the stick's σs exceeds the steady curve's maximum: no jump, Eqs"
        f" 15, 8) to Vc = {vc * 1e6:.4g} µm/s (Eq 9)."
    )


SWEEP_FIGURES: list[tuple[str, Callable[[ModelRun], ReportFigure]]] = [
    ("Phase diagram: regimes over V0 and stiffness", phase_diagram_figure),
]
