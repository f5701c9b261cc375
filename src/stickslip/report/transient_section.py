"""The report's section on the full time-dependent model (Eq 1), which the paper never solves.

Three runs of the ``transient`` model through the model interface, each beside what the paper's quasi-static
picture predicts: a step down from steady sliding through the Eq 17 block, velocity steps under velocity control,
and slide-hold-slide (docs/transient.md section 7).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from .computations import ModelRun
from .figures import ReportFigure

if TYPE_CHECKING:  # pragma: no cover
    from ..models import Run
    from ..parameters import Parameters
    from ..protocols import Protocol

UM = 1e6
#: local tolerance of the report's runs (the cycle agrees with rtol 1e-4 to 1e-5; docs/transient.md)
RTOL = 1e-3
STEP_DOWN = (350e-6, 100e-6, 20.0)  # from, to (m/s), duration (s)
VELOCITY_STEPS = ((100e-6, 0.005), (1000e-6, 0.01), (100e-6, 0.03))
HOLDS = (1e-3, 1e-2, 1e-1, 1.0, 10.0)


def transient_figure(run: ModelRun) -> ReportFigure:
    from ..plots.transient import figure_transient_runs
    from ..protocols import constant, segments

    params = run.params
    high, low, duration = STEP_DOWN
    down = constant(low, duration)
    full = _run("transient", params, down, start="steady", start_velocity=high, rtol=RTOL, stick_population=True)
    alone = _run("transient", params, down, start="steady", start_velocity=high, rtol=RTOL)
    quasi = _run("quasi-static", params, down)
    steps = _run("transient", params, segments(list(VELOCITY_STEPS)), "velocity", start="steady", rtol=1e-5)
    peaks = [_hold_peak(params, hold) for hold in HOLDS]

    fig = figure_transient_runs(
        alone.native,
        full.native,
        quasi.native,
        STEP_DOWN,
        steps.native,
        (VELOCITY_STEPS[0][1], _second_step()),
        "100 → 1000 → 100 µm/s (velocity control)",
        HOLDS,
        peaks,
    )
    caption = _caption(run, full, alone, quasi, steps, peaks)
    return ReportFigure("transient_eq1", "Eq 1", "The full time-dependent model (Eq 1), solved", caption, fig)


def _run(
    model: str, params: Parameters, protocol: Protocol, control: str = "spring", *, start: Any = None, **settings: Any
) -> Run:
    """One run of a registered model through the interface: the paper's block (the model's own spring) or a rigid
    rig (``control="velocity"``)."""
    from ..models import Rig, get_model

    return get_model(model).run(params, protocol, Rig(control=control), start=start, **settings)


def _second_step() -> float:
    return VELOCITY_STEPS[0][1] + VELOCITY_STEPS[1][1]


def _hold_peak(params: Parameters, hold: float) -> float:
    from ..protocols import segments

    protocol = segments([(100e-6, 0.002), (0.0, hold), (100e-6, 0.015)])
    result = _run("transient", params, protocol, "velocity", start="steady", rtol=RTOL)
    return float(result.stress[result.time > 0.002 + hold].max())


def _caption(run: ModelRun, full: Run, alone: Run, quasi: Run, steps: Run, peaks: list[float]) -> str:
    from ..quasistatic.steady import steady_state

    sigma_c = run.critical.stress if run.critical is not None else float("nan")
    stuck = np.flatnonzero(alone.slider_velocity < 0.01 * STEP_DOWN[1])
    stick_alone = (
        f"Eq 1 alone slides down the steady curve and sticks at σ = {alone.stress[stuck[0]]:.2f} Pa "
        f"(σc = {sigma_c:.2f} Pa) after {alone.time[stuck[0]]:.2f} s, then never lets go: at "
        f"{alone.time[-1]:.0f} s σ = {alone.stress[-1]:.1f} Pa and the slider creeps at "
        f"{alone.slider_velocity[-1] * 1e9:.1f} nm/s, because Eq 1's aging (τa = 0.9 ms) makes a resting bond "
        "unbreakable within milliseconds"
        if stuck.size
        else "Eq 1 alone does not stick in this run"
    )
    cycle_text = "the stick chains give no whole cycle in this run"
    if full.native.cycles and quasi.native.cycles:  # the per-cycle numbers are each solver's own
        c, q = full.native.cycles[0], quasi.native.cycles[0]
        slip = f"{c.slip_time:.3f} s" if c.slip_time is not None else "past the end of the run"
        q_slip = f"{q.slip_time:.3f} s" if q.slip_time is not None else "—"
        cycle_text = (
            f"with the paper's stick chains (Eqs 13-16) it cycles: stick {c.stick_time:.3f} s from σ = "
            f"{c.start_stress:.2f} Pa to σs = {c.peak_stress:.2f} Pa, jump to {c.jump_velocity * UM:.0f} µm/s, slip "
            f"{slip}, against the quasi-static cycle's {q.stick_time:.3f} s, {q.peak_stress:.2f} Pa, "
            f"{q.jump_velocity * UM:.0f} µm/s and {q_slip} (dashed, shifted to the same start)"
        )
    high = float(steady_state(run.params, VELOCITY_STEPS[1][0]).stress)
    low = float(steady_state(run.params, VELOCITY_STEPS[0][0]).stress)
    up = steps.time < _second_step()
    peak = float(steps.stress[up].max())
    ln10 = float(np.log(10.0))
    holds = ", ".join(f"{h:g} s: {p:.3g} Pa" for h, p in zip(HOLDS, peaks, strict=True))
    return (
        "The paper writes its model as a time-dependent population balance (Eq 1) and solves only quasi-static "
        f"reductions of it; stickslip.transient solves Eq 1 itself (docs/transient.md). Top: {stick_alone}; "
        f"{cycle_text}. The slip phase of the full model is quasi-static to about 2 %, and the jump is the "
        "paper's, imposed at the chains' collapse: stick-slip does not emerge from Eq 1 alone. Bottom left: a velocity "
        f"step up first lowers σ (aging is erased at once), then σ peaks at {peak:.1f} Pa and relaxes over a "
        f"fraction of a micrometre to σ(1000 µm/s) = {high:.2f} Pa; back down, σ dips and recovers to "
        f"{low:.2f} Pa; a − b = {(high - low) / ln10:.0f} Pa per e-fold (velocity strengthening above Vc; the fitted "
        "rate-and-state reading is the figure 'A rate-and-state reading of the bond model'). Bottom right: the peak "
        "on re-sliding after a "
        f"hold ({holds}) grows almost in proportion to the hold, to 10⁵ times the sliding stress: held bonds age "
        "past breaking, which gels do not show (their static threshold grows about logarithmically); a model "
        f"limitation, and the reason the paper needs a separate stick population. Local tolerance {RTOL:g}."
    )


TRANSIENT_FIGURES: list[tuple[str, Callable[[ModelRun], ReportFigure]]] = [
    ("The full time-dependent model (Eq 1)", transient_figure),
]
