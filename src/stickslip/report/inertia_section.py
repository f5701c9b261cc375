"""The report's section on issue 22 Q4: the block's mass and radiation damping in the Hopf point of Eq 1.

At 120 µm/s (just below Vc) the linear analysis of :mod:`stickslip.transient.stability` with
m s^2 + eta s + K + Z(s) = 0 for the paper's massless block, the gel block's mass rho h and Rice's radiation
damping G/(2 c_s); the scan is limited to 10-3000 rad/s around the Hopf frequency so that the section costs
under a second (the full scan, the other velocities, the fastest modes and the convergence checks are in
docs/extensions.md section 4); and the nonlinear solver with the gel block's mass, from steady sliding on
the unstable branch at 50 µm/s (two runs of 1.5 ms, a few hundredths of a second).
"""

from __future__ import annotations

import math
from collections.abc import Callable

from .computations import ModelRun
from .figures import ReportFigure

VELOCITY = 120e-6
BAND = (10.0, 3000.0, 30)  # rad/s: low, high, points (the Hopf crossing is at 205 rad/s)
FACTOR = 0.7


def inertia_figure(run: ModelRun) -> ReportFigure:
    import numpy as np
    from matplotlib.figure import Figure

    from ..plots.style import apply_style
    from ..studies.inertia import gel_block_cases
    from ..transient.stability import critical_from_response, follow_root, interface_response

    params = run.params
    memo: dict[bytes, np.ndarray] = {}

    def response(s: np.ndarray) -> np.ndarray:
        key = np.asarray(s, dtype=complex).tobytes()
        if key not in memo:
            memo[key] = interface_response(params, VELOCITY, s).z
        return memo[key]

    cases = gel_block_cases(params)
    chosen = [cases[0], cases[1], cases[3], cases[4]]  # massless, rho h, 1000 rho h, G/(2 c_s)
    w = np.geomspace(*BAND)
    rows = []
    for block in chosen:
        kc = critical_from_response(response, w, block.mass, block.damping)
        rows.append((block, kc))
    gel, gel_kc = rows[1]
    heavy = rows[2][1].value / rows[0][1].value
    paper_kc = rows[0][1]
    massless = follow_root(response, 1j * paper_kc.rate, paper_kc.value, FACTOR * paper_kc.value, 0.0, 0.0, 2)
    root = follow_root(response, 1j * gel_kc.rate, gel_kc.value, FACTOR * gel_kc.value, gel.mass, gel.damping, 2)

    z = response(1j * w)
    fig = Figure(figsize=(6.8, 4.2))
    ax_im, ax_re = fig.subplots(2, 1, sharex=True)
    hz = w / (2 * math.pi)
    for ax in (ax_im, ax_re):  # scales first: which curves coincide is judged as the axes show them
        ax.set_xscale("log")
        ax.set_yscale("symlog", linthresh=1e6, linscale=0.4)
    # the stiffness a root at i w needs, K = m w^2 - i eta w - Z(i w): a Hopf point where it is real
    needs = [block.mass * w * w - 1j * block.damping * w - z for block, _ in rows]
    labels = [shown_label(block.label) for block, _ in rows]
    colors = ("k", "C0", "C3", "C1")
    for ax, part in ((ax_im, np.imag), (ax_re, np.real)):
        drawn = _draw_coinciding(ax, hz, [part(need) for need in needs], labels, colors)
    for (_, kc), label, color in zip(rows, labels, drawn, strict=True):
        # the Hopf points, on their line and in its colour, are named in the caption (dots); each keeps its name
        # for its CSV
        ax_re.plot([kc.rate / (2 * math.pi)], [kc.value], "o", color=color, ms=4, label="_hopf",
                   gid=f"Hopf point, {label}")  # fmt: skip
    ax_im.axhline(0.0, color="0.5", lw=0.6)
    for ax in (ax_im, ax_re):  # decades only: the linear band around 0 would crowd its labels
        ax.set_yticks([-1e9, -1e7, 0.0, 1e7, 1e9] + ([] if ax is ax_im else [1e11]))
    ax_im.set_ylabel("Im (Pa/m)")
    ax_re.set_ylabel("Re (Pa/m)")
    ax_re.set_xlabel("frequency ω/2π (Hz)")
    ax_im.set_title(f"K = m ω² − iηω − Z(iω) puts a root at iω ({VELOCITY * 1e6:.0f} µm/s)", fontsize=9)
    # where no curve goes: below zero at low frequency (Im), above the heavy block's rise (Re)
    ax_im.legend(fontsize="x-small", loc="lower left", frameon=False)
    ax_re.set_ylim(top=1e13)  # room for that legend above the heavy block's line
    ax_re.legend(fontsize="x-small", loc="upper left", frameon=False)
    for ax in (ax_im, ax_re):
        apply_style(ax)
    fig.set_layout_engine("tight")  # laid out when drawn, with the text sizes the drawing measures anyway
    return ReportFigure("inertia_hopf", "Extension", "Inertia and radiation damping at the Hopf point",
                        _caption(rows, root, massless, gel, heavy), fig)  # fmt: skip


#: The blocks' labels (stickslip.studies.inertia) as a reader writes them.
_SYMBOLS = (("rho h", "ρh"), (" x ", " × "), ("2 c_s", "2cₛ"))


def shown_label(label: str) -> str:
    """``"1000 x rho h"`` -> ``"1000 × ρh"``: the symbols, not their ASCII spelling."""
    for ascii_text, symbol in _SYMBOLS:
        label = label.replace(ascii_text, symbol)
    return label


def _draw_coinciding(ax, x, curves, labels, colors) -> list[str]:  # type: ignore[no-untyped-def]
    """One visible line, with one legend entry, per group of curves that lie on top of one another on ``ax``.

    Every curve is still drawn (its CSV holds it), in its group's colour; the legend names the group once.
    Returns the colour each curve was drawn in.
    """
    from ..plots.legends import coinciding_groups

    drawn = list(colors)
    for group in coinciding_groups(ax, curves):
        names = [labels[k] for k in group]
        shown = "\n= ".join(names)  # "a\n= b": a and b lie on one line
        for position, k in enumerate(group):
            drawn[k] = colors[group[0]]
            ax.plot(x, curves[k], color=drawn[k], lw=1.2, label=shown if position == 0 else "_same",
                    gid=labels[k])  # fmt: skip
    return drawn


def _caption(rows, root, massless, gel, heavy) -> str:  # type: ignore[no-untyped-def]
    base = rows[0][1]
    parts = [
        f"{shown_label(block.label)} (m = {block.mass:.3g} kg/m², η = {block.damping:.4g} Pa·s/m):"
        f" Kc = {kc.value:.5g} Pa/m"
        f" ({100 * (kc.value / base.value - 1):+.2f} %), {kc.rate / (2 * math.pi):.4g} Hz"
        for block, kc in rows
    ]
    return (
        "Linear stability of steady sliding in the full model (Eq 1) through a block with mass m per unit area and"
        " viscous damping η: eigenvalues solve m s² + η s + K + Z(s) = 0 (docs/extensions.md section 4). A root"
        " crosses the imaginary axis at iω for the stiffness K = m ω² − iηω − Z(iω) where that is real: each"
        " curve's imaginary part vanishes (top) at the Hopf frequency, where its real part is Kc (dots). Blocks whose"
        " curves coincide share one line and one legend entry (“=”)."
        f" At {VELOCITY * 1e6:.0f} µm/s: " + "; ".join(parts) + "."
        f" With the gel block, at K = {FACTOR:g} Kc the Hopf eigenvalue grows at {root.real:+.4g} 1/s and"
        f" oscillates at {root.imag / (2 * math.pi):.4g} Hz (massless: {massless.real:+.4g} 1/s at"
        f" {massless.imag / (2 * math.pi):.4g} Hz). A realistic gel"
        " block (ρ = 1050 kg/m³ × h = 10 mm) changes the Hopf prediction by a fraction of a percent: m ω² ="
        f" {gel.mass * rows[1][1].rate ** 2:.3g} Pa/m against Kc ≈ 1.3e8 Pa/m."
        f" A block 1000 × heavier would raise Kc {heavy:.2g}-fold. With any mass the fastest modes are"
        " bounded (√(−(K + Z(∞))/m) where the interface's instantaneous stiffness is negative, V0 < 69.6 µm/s);"
        " the massless model is ill posed only there."
    )


#: steady sliding on the unstable branch through the paper's block, where the massless model has no fastest time
DEPARTURE_VELOCITY = 50e-6
DEPARTURE_TIME = 1.5e-3  # s: the departure, the deceleration and the first ringing of the block
STOPPED = 10e-6  # m/s: "below 10 µm/s", the slider's deceleration done


def inertia_run_figure(run: ModelRun) -> ReportFigure:
    """The nonlinear solver from steady sliding at 50 µm/s: the massless block's instant jump, the gel block's
    resolved deceleration and ringing (docs/extensions.md section 4, "What the mass changes")."""
    import numpy as np
    from matplotlib.figure import Figure
    from scipy.signal import find_peaks

    from ..plots.style import apply_style
    from ..protocols import constant
    from ..studies.inertia import gel_block_cases
    from ..transient import run_transient

    params = run.params
    gel = next(b for b in gel_block_cases(params) if b.mass > 0 and b.damping > 0)  # rho h and G/(2 c_s)
    protocol = constant(DEPARTURE_VELOCITY, DEPARTURE_TIME)
    common = dict(start="steady", start_velocity=DEPARTURE_VELOCITY, rtol=1e-5)
    with_mass = run_transient(params, protocol, mass=gel.mass, damping=gel.damping, **common)
    runs = [
        ("massless block (the paper's)", run_transient(params, protocol, **common), "k"),
        (shown_label(gel.label), with_mass, "C0"),
    ]
    fig = Figure(figsize=(6.8, 3.4))
    ax = fig.subplots()
    for label, result, color in runs:
        ax.plot(result.time * 1e3, result.slider_velocity * 1e6, color=color, lw=1.2, label=label)
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("slider velocity V (µm/s)")
    ax.set_title(
        f"Steady sliding at {DEPARTURE_VELOCITY * 1e6:.0f} µm/s through the paper's block (unstable)", fontsize=9
    )
    ax.legend(fontsize="x-small")
    apply_style(ax)
    fig.set_layout_engine("tight")  # laid out when drawn, with the text sizes the drawing measures anyway
    massless, massive = runs[0][1], runs[1][1]
    stopped = float(massive.time[np.argmax(massive.slider_velocity < STOPPED)])
    peaks, _ = find_peaks(massive.slider_velocity)
    peaks = peaks[massive.time[peaks] > stopped]
    first, last = (massive.slider_velocity[peaks[k]] * 1e6 for k in (0, -1))
    caption = (
        f"The time-dependent model (Eq 1) from steady sliding at {DEPARTURE_VELOCITY * 1e6:.0f} µm/s, the unstable"
        f" branch, through the paper's block K = {massless.stiffness:.3g} Pa/m, without and with the block's mass"
        f" and damping ({shown_label(gel.label)}: m = {gel.mass:.3g} kg/m², η = {gel.damping:.4g} Pa·s/m)."
        " The massless slider"
        f" leaves the branch in its first step, its velocity jumping to {massless.slider_velocity[1] * 1e6:.4g} µm/s"
        " (no time scale: there the massless model is ill posed), and creeps towards rest. With the mass the slider"
        " slides on until the unstable root (3.9e4 1/s by the linear analysis) has grown from round-off, decelerates,"
        f" and is below {STOPPED * 1e6:.0f} µm/s at {stopped * 1e3:.3g} ms; the block then oscillates about the"
        f" massless slider's creep, damped: its velocity peaks fall from {first:.3g} to {last:.3g} µm/s by"
        f" {DEPARTURE_TIME * 1e3:g} ms ({massless.slider_velocity[-1] * 1e6:.3g} µm/s for the massless slider then)."
        " Both then come to rest, stuck (docs/extensions.md section 4): the mass resolves the jump and leaves the"
        " outcome unchanged."
    )
    return ReportFigure("inertia_departure", "Extension", "The block's mass in the nonlinear solver", caption, fig)


INERTIA_FIGURES: list[tuple[str, Callable[[ModelRun], ReportFigure]]] = [
    ("Inertia and radiation damping at the Hopf point (issue 22 Q4)", inertia_figure),
    ("The block's mass in the time-dependent solver (issue 22 Q4)", inertia_run_figure),
]
