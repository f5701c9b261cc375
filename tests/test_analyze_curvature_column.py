"""Round 30: `analyze -o` writes each stick's bend, and `fit stick` names the rows analyze found curved.

Round 29 measured the curvature of sticks (a parabola through each stick, flagged beyond 5 standard errors and a
noise level of bend) and warned of it on the screen, but the cycles table `fit stick` reads had no column for it:
the fit of a curved record said nothing.  The records are the quasi-static model's 50 um/s cycles with each stick
bent by a known amount (tests/test_analyze_r29.py's construction); the truth of the curvature is that bend.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from tests.cli_helpers import run_main
from tests.test_analyze_r29 import BEND, bent_record

from stickslip import load_parameters


@pytest.fixture(scope="module")
def gelatin():
    return load_parameters("gelatin-glass")


def _cycles_table(tmp_path, capsys, gelatin, bend: float, name: str):
    t, x, sim = bent_record(gelatin, bend, seed=5)
    trace = tmp_path / f"{name}.csv"
    pd.DataFrame({"time [s]": t, "stress [Pa]": x}).to_csv(trace, index=False)
    cycles = tmp_path / f"{name}-cycles.csv"
    code, _, err = run_main(capsys, "analyze", str(trace), "--v0", "50 um/s", "-o", str(cycles))
    assert code == 0, err
    return cycles, sim


def test_the_cycles_table_carries_each_stick_s_bend(tmp_path, capsys, gelatin):
    cycles, sim = _cycles_table(tmp_path, capsys, gelatin, BEND, "bent")
    table = pd.read_csv(cycles)
    assert {"stick_curvature [Pa/s^2]", "stick_curvature_stderr [Pa/s^2]", "stick_curved [1]"} <= set(table)
    assert set(table["stick_curved [1]"]) <= {0, 1} and table["stick_curved [1]"].dtype.kind == "i"
    whole = table[table["complete [1]"] == 1]
    assert len(whole) >= 3 and (whole["stick_curved [1]"] == 1).all()
    # sigma = sigma_c + drop (u + bend (u^2 - u)), u = (t - start)/t_s: d2sigma/dt2 = 2 bend drop / t_s^2
    c = next(c for c in sim.cycles if c.stick_time is not None)
    truth = 2 * BEND * (c.peak_stress - c.start_stress) / c.stick_time**2
    assert np.allclose(whole["stick_curvature [Pa/s^2]"], truth, rtol=0.1)


def test_fit_stick_names_the_curved_rows_and_not_straight_ones(tmp_path, capsys, gelatin):
    bent, _ = _cycles_table(tmp_path, capsys, gelatin, BEND, "bent")
    straight, _ = _cycles_table(tmp_path, capsys, gelatin, 0.0, "straight")
    table = pd.read_csv(bent)
    flagged = [str(k + 2) for k in np.flatnonzero((table["stick_curved [1]"] == 1) & table["stick_time [s]"].notna())]
    assert flagged
    code, out, err = run_main(capsys, "fit", "stick", str(bent))
    assert code == 3 and "one pulling velocity" in out, err  # read, then (one velocity) failed as such
    said = [line for line in (out + err).replace("\n", " ").split("  ") if "curved beyond its noise" in line]
    assert said and all(row in " ".join(said) for row in flagged[:1])
    code, out, err = run_main(capsys, "fit", "stick", str(straight))
    assert code == 3 and "one pulling velocity" in out, err
    assert "curved beyond its noise" not in out + err
