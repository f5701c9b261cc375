"""The report's section on issue 22 Q2: which predictions rest on the loosely fitted tau_a and V_a.

The 95 % region of (tau_a, V_a) that the shipped steady curve allows (stored, :data:`REGION_95`; regenerated
and checked as docs/extensions.md section 2 says) and the quasi-static predictions over it (Eq 9, Eqs 11-17):
about 0.6 s of CPU.  The slow predictions (Kc of Eq 1, V*, slide-hold-slide peaks) are in the doc.
"""

from __future__ import annotations

from collections.abc import Callable

from .computations import ModelRun
from .figures import ReportFigure

UM = 1e6
#: prediction key -> (label, scale to the shown unit, unit)
SHOWN = {
    "critical_velocity": ("Vc", UM, "µm/s"),
    "critical_stress": ("σc", 1.0, "Pa"),
    "stick_time_from_sigma_c": ("stick from σc", 1.0, "s"),
    "peak_stress_from_sigma_c": ("σs from σc", 1.0, "Pa"),
    "stick_time_from_rest": ("stick from rest", 1.0, "s"),
    "peak_stress_from_rest": ("σs from rest", 1.0, "Pa"),
}


def sensitivity_figure(run: ModelRun) -> ReportFigure:
    import numpy as np
    from matplotlib.figure import Figure

    from ..plots.style import apply_style
    from ..studies.sensitivity import TOLERANCE, predictions, quasi_static_predictions, spreads, stored_region

    region = stored_region(run.params)
    rows = predictions(region, quasi_static_predictions)
    table = spreads(rows, TOLERANCE)

    fig = Figure(figsize=(6.8, 3.4))
    ax_region, ax_spread = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1, 1.5]})
    ring = region[1:] + region[1:2]
    ax_region.plot([p.aging_time * 1e3 for p in ring], [p.aging_velocity * UM for p in ring], "o-", color="C0", ms=3,
                   label="95 % boundary")  # fmt: skip
    ax_region.plot(region[0].aging_time * 1e3, region[0].aging_velocity * UM, "k*", ms=9, label="best fit")
    ax_region.set_xlabel("τa (ms)")
    ax_region.set_ylabel("Va (µm/s)")
    ax_region.set_yscale("log")
    ax_region.set_title("95 % region (Δχ² = 5.99)", fontsize=9)
    # below the panel: inside, the ring's empty middle is where the best-fit star sits
    ax_region.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.3), ncols=2, frameon=False)
    for k, (key, (label, _, _)) in enumerate(SHOWN.items()):
        values = np.array([r[key] for r in rows])
        change = 100 * (values[1:] / values[0] - 1)
        ax_spread.plot(np.full(values.size - 1, k), change, "o", color="C0", ms=3, label=label)
    ax_spread.axhspan(-100 * TOLERANCE / 2, 100 * TOLERANCE / 2, color="0.9", zorder=0)
    ax_spread.axhline(0.0, color="k", lw=0.8)
    ax_spread.set_xticks(range(len(SHOWN)), [v[0] for v in SHOWN.values()], rotation=30, ha="right", fontsize=8)
    ax_spread.set_ylabel("change from the best fit (%)")
    ax_spread.set_xlabel("quasi-static prediction")
    ax_spread.set_title("quasi-static predictions over the region", fontsize=9)
    for ax in (ax_region, ax_spread):
        apply_style(ax)
    fig.set_layout_engine("tight")  # laid out when drawn, with the text sizes the drawing measures anyway
    return ReportFigure(
        "sensitivity_aging", "Extension", "What the predictions rest on: τa and Va", _caption(region, table), fig
    )


def _caption(region, table) -> str:  # type: ignore[no-untyped-def]
    from ..studies.sensitivity import TOLERANCE

    ta = [p.aging_time * 1e3 for p in region]
    va = [p.aging_velocity * UM for p in region]
    parts = []
    for s in table:
        label, scale, unit = SHOWN[s.key]
        verdict = "robust" if s.robust else "not robust"
        parts.append(
            f"{label} {s.low * scale:.4g}–{s.high * scale:.4g} {unit} (best {s.best * scale:.4g}; spread"
            f" {100 * s.relative:.1f} %, {verdict})"
        )
    return (
        "The joint fit of Eqs 6-8 to the shipped steady curve (synthetic_steady.csv: the paper's parameters with 2 %"
        " noise, 140 µm/s to 2 mm/s) leaves τa and Va loosely determined. Left: the boundary of the region of"
        f" (τa, Va) it allows at 95 % (profile χ², N0 and τ refitted at each point; λ, Δl_{{m}}, M, T, u0 held as the"
        f" fit holds them): τa {min(ta):.3f}–{max(ta):.3f} ms, Va {min(va):.0f}–{max(va):.0f} µm/s. Right: each"
        " quasi-static prediction at the 8 boundary points against the best fit (grey band: a spread of"
        f" {100 * TOLERANCE:.0f} %, the line between robust and not). Over the region: " + "; ".join(parts) + "."
        " The stick from rest does not depend on Eq 1's parameters at all (Eq 15: the stick chains and the block);"
        " the stick from σc moves only through σc. Kc of the full model, V* and the slide-hold-slide peaks over"
        " the same region are in docs/extensions.md section 2 (minutes of CPU: scripts/sensitivity_table.py)."
    )


SENSITIVITY_FIGURES: list[tuple[str, Callable[[ModelRun], ReportFigure]]] = [
    ("What the predictions rest on: τa and Va (issue 22 Q2)", sensitivity_figure),
]
