"""Round 28b (tester M): an outlier that pulls the fit of exact data (D2), identical stick rows (D3)."""

from __future__ import annotations

import numpy as np

from stickslip.fitting.data import SteadyData, StickData, read_stick_data
from stickslip.fitting.steady_fit import fit_steady

# `stickslip curve --set "bonds.bond_time=300 us" --points 8 --format csv` (3 significant figures), row 3 halved
VELOCITY = np.array([10, 26.8, 72, 193, 518, 1390, 3730, 10000]) * 1e-6  # m/s
STRESS = np.array([21900, 12152, 2140, 411, 578, 837, 982, 840.0])  # Pa, the truth
HALVED = 1  # index of file row 3


def test_exact_curve_with_one_halved_point_names_it_and_is_no_constant():
    stress = STRESS.copy()
    stress[HALVED] /= 2
    fit = fit_steady(SteadyData.from_arrays(VELOCITY, stress, source="halved"), method="joint")
    text = "\n".join(fit.messages)
    assert "described by a constant" not in text
    # the halved point, and only it, is named; the fit of the other seven misses it by about -50 %
    assert any("misses row 2 (" in m for m in fit.messages), text
    warning = next(m for m in fit.messages if "misses row 2 (" in m)
    percent = float(warning.split("a residual of ")[1].split(" %")[0])
    assert -60 < percent < -40


def test_identical_stick_rows_are_warned_of(tmp_path):
    v = np.array([50, 50, 100, 100, 200, 200, 400, 400]) * 1e-6
    t = np.array([18.3, 17.8, 8.8, 8.6, 4.4, 4.3, 2.2, 2.1])
    clean = StickData.from_arrays(v, t)
    assert not any("identical rows" in n for n in clean.notes())
    pasted = StickData.from_arrays(np.r_[v, v], np.r_[t, t])
    note = next(n for n in pasted.notes() if "identical rows" in n)
    assert "1 and 9" in note and "2 and 10" in note
    # a table with its cycle numbers pasted twice: the same cycles, said so
    path = tmp_path / "k.csv"
    lines = ["pulling_velocity [um/s],cycle,stick_time [s]"]
    lines += [f"{1e6 * a:g},{i % 2 + 1},{b:g}" for i, (a, b) in enumerate(zip(v, t, strict=True))] * 2
    path.write_text("\n".join(lines) + "\n")
    note = next(n for n in read_stick_data(path).notes() if "identical rows" in n)
    assert "same cycle" in note
    # equal in every column but the cycle number: not identical
    lines2 = lines[:9] + [f"{1e6 * a:g},{i % 2 + 3},{b:g}" for i, (a, b) in enumerate(zip(v, t, strict=True))]
    path.write_text("\n".join(lines2) + "\n")
    assert not any("identical rows" in n for n in read_stick_data(path).notes())
