"""Regenerate the numbers of docs/extensions.md section 2 (issue 22 Q2): the 95 % region of (tau_a, V_a)
allowed by the steady curve, and every prediction over it.

    PYTHONPATH=src python scripts/sensitivity_table.py [--slow] [--holds]

Prints the region (as the REGION_95 table of stickslip.studies.sensitivity), the quasi-static predictions,
with --slow the linear stability of Eq 1 (Kc at 100 and 120 um/s, V*; ~1 min CPU per point) and with
--holds the slide-hold-slide peaks through the block with the stick chains (minutes per point).
"""

from __future__ import annotations

import sys
import time

from stickslip.studies.sensitivity import (
    hold_peaks,
    predictions,
    quasi_static_predictions,
    region_points,
    spreads,
    stability_predictions,
    steady_fit,
)


def main() -> None:
    start = time.process_time()
    fit = steady_fit()
    region = region_points(fit)
    print(f"# minimum chi^2 {region.minimum_chi_square:.6f}; open rays: {region.open_directions or 'none'}")
    print("REGION_95 = (  # label, tau_a (s), V_a (m/s), N0 (1/m^2), tau (s), Delta chi^2")
    for p in region.points:
        b = p.params.bonds
        print(
            f"    ({p.label!r}, {p.aging_time!r}, {p.aging_velocity!r}, {b.site_density!r}, {b.bond_time!r}, "
            f"{p.delta_chi_square:.4f}),"
        )
    print(")")
    compute = [quasi_static_predictions]
    if "--slow" in sys.argv:
        compute.append(stability_predictions)
    if "--holds" in sys.argv:
        compute.append(hold_peaks)
    rows = []
    for p in region.points:
        rows.append(predictions([p], *compute)[0])
        print(p.label, {k: f"{v:.6g}" for k, v in rows[-1].items()}, flush=True)
    print("prediction | best | min | max | (max-min)/best | robust (<= 10 %)")
    for s in spreads(rows):
        print(f"{s.key} | {s.best:.6g} | {s.low:.6g} | {s.high:.6g} | {s.relative:.3f} | {s.robust}")
    print(f"# CPU {time.process_time() - start:.1f} s")


if __name__ == "__main__":
    main()
