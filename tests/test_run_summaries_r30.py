"""Round 30 (tester U): a segment's peak and trough are its own at a boundary written twice; a plug-in's start words
named in a refusal; the quasi-static record's K says where it came from; a steady run's settled value in its text;
a sweep row's peak only for a run that oscillated; fast velocities in mm/s and m/s.

Every expected number is the truth built into the test's own model (closed form) or written by hand.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import stickslip
from stickslip import protocols
from stickslip.models import Capabilities, FrictionModel, Run
from stickslip.models.base import CYCLE_RESULTS
from stickslip.units import to_si

S0, ETA, BETA, T_RELAX = 1000.0, 1e6, 5e5, 0.2  # Pa, Pa s/m, Pa s/m, s


def psi_steady(v: float) -> float:
    return -BETA * v


class DirectEffect(FrictionModel):
    """sigma = s0 + eta V + psi, psi relaxing to -beta V over T: a direct effect (a jump at each velocity step under
    velocity control) and an exponential evolution, solved segment by segment as a plug-in would: each segment's
    rows from its start to its end, so every boundary is written twice (the old value, then the new one)."""

    name = "r30-direct"
    capabilities = Capabilities(controls=("velocity",), protocols="any")
    start_dimension = "velocity"
    start_words = ("steady",)

    def __init__(self, name: str = "r30-direct", give_protocol: bool = True) -> None:
        self.name = name
        self.give_protocol = give_protocol

    def dimensions(self):
        return {"s0": "stress"}

    def parameters(self, spec=None, overrides=None):
        values = {"s0": S0}
        for key, raw in (overrides or {}).items():
            values[key] = to_si(raw, "stress", key)
        return values

    def values(self, params):
        return dict(params)

    def run(self, params, protocol, rig=None, *, start=None, **settings):
        self.check(protocol, rig, settings)
        psi = psi_steady(protocol.segments[0].velocity if start in (None, "steady") else float(start))
        times, stresses, speeds = [], [], []
        for a, b, v in protocol.pieces():
            t = np.linspace(a, b, 201)
            p = psi_steady(v) + (psi - psi_steady(v)) * np.exp(-(t - a) / T_RELAX)
            times.append(t), stresses.append(params["s0"] + ETA * v + p), speeds.append(np.full_like(t, v))
            psi = float(p[-1])
        t, s, v = np.concatenate(times), np.concatenate(stresses), np.concatenate(speeds)
        x = protocol.displacement_at(t)
        extra = {"protocol": protocol} if self.give_protocol else {}
        return Run.from_trace(self.name, t, stress=s, slider_velocity=v, slider_position=x, load_point_position=x,
                              floor=1e-6 * S0, **extra)  # fmt: skip


def truth_last_segment(velocities, durations):
    """(the last segment's lowest, highest, the value it settles to) in closed form, on a fine grid of its own."""
    psi = psi_steady(velocities[0])
    for v, d in zip(velocities, durations, strict=True):
        t = np.linspace(0.0, d, 200001)
        s = S0 + ETA * v + psi_steady(v) + (psi - psi_steady(v)) * np.exp(-t / T_RELAX)
        psi = psi_steady(v) + (psi - psi_steady(v)) * math.exp(-d / T_RELAX)
    return float(s.min()), float(s.max()), S0 + ETA * velocities[-1] + psi_steady(velocities[-1])


SHS = ([1e-4, 0.0, 1e-4], [1.0, 2.0, 1.0])  # slide 100 µm/s 1 s, hold 2 s, re-slide 1 s


@pytest.fixture
def plugin():
    models = [DirectEffect(), DirectEffect("r30-direct-b")]
    for model in models:
        stickslip.register_model(model, replace=True)
    yield models[0]
    for model in models:
        stickslip.models.unregister_model(model.name)


@pytest.mark.parametrize("give_protocol", [True, False])
def test_a_re_slide_s_trough_is_its_own_not_the_hold_s_last_value(give_protocol):
    """Before: trough 999.998 Pa, the hold's last value written at t = 3 s, for a re-slide that never goes below
    1050.34 Pa; with the protocol (Run.from_trace) and without it (classified again by ``finished``)."""
    model = DirectEffect(give_protocol=give_protocol)
    protocol = protocols.segments(list(zip(*SHS, strict=True)))
    run = stickslip.run(model, None, protocol, stickslip.models.Rig(control="velocity"), start="steady")
    low, high, _ = truth_last_segment(*SHS)
    assert low > 1050.0 and high > 1099.9  # the truth itself: the re-slide jumps to 1100 Pa and decays to 1050 Pa
    assert run.trough == pytest.approx(low, abs=1e-6)
    assert run.peak == pytest.approx(high, abs=1e-6)


def test_a_velocity_step_s_window_takes_the_new_segment_s_value_at_the_step():
    """Tester U's trace: 1100 Pa, then a jump to 1200 Pa at t = 1 s decaying to 1150 Pa (trough read 1100 Pa)."""
    prot = protocols.velocity_steps([1e-4, 1e-3], 1.0)
    t1, t2 = np.linspace(0, 1, 101), np.linspace(1, 2, 101)
    t, s = np.r_[t1, t2], np.r_[np.full_like(t1, 1100.0), 1150 + 50 * np.exp(-(t2 - 1) / 0.05)]
    x = prot.displacement_at(t)
    run = Run.from_trace("toy", t, stress=s, slider_velocity=prot.velocity_at(t), slider_position=x,
                         load_point_position=x, protocol=prot, floor=1e-6)  # fmt: skip
    assert run.peak == pytest.approx(1200.0, abs=1e-9)
    assert run.trough == pytest.approx(1150 + 50 * math.exp(-20.0), abs=1e-9)


def test_the_segment_window_keeps_the_last_sample_at_its_start_and_a_lone_one():
    from stickslip.models.run import segment_window

    t = np.array([0.0, 0.5, 1.0, 1.0, 1.0, 1.5, 2.0])
    y = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0])
    tw, yw, start = segment_window(t, y, 1.0)
    assert start == 1.0 and list(yw[tw >= start]) == [5.0, 6.0, 7.0]
    # within 1 ns of the boundary (a plug-in's own sum of durations): the later sample is the segment's
    t2 = np.array([0.0, 1.0 - 1e-12, 1.0 + 1e-12, 2.0])
    tw, yw, start = segment_window(t2, np.array([0.0, 1.0, 9.0, 8.0]), 1.0)
    assert list(yw[tw >= start]) == [9.0, 8.0]
    # a single sample at the boundary is the signal's value there: kept
    t3 = np.array([0.0, 1.0, 2.0])
    tw, yw, start = segment_window(t3, np.array([0.0, 1.0, 2.0]), 1.0)
    assert list(yw[tw >= start]) == [1.0, 2.0]


def test_run_and_compare_report_the_re_slide_s_own_trough(plugin, tmp_path, capsys):
    from cli_helpers import run_main

    table = tmp_path / "shs.csv"
    table.write_text("velocity [um/s],duration [s]\n100,1\n0,2\n100,1\n")
    low, high, _ = truth_last_segment(*SHS)
    common = ("--control", "velocity", "--protocol", str(table))
    code, out, err = run_main(capsys, "run", "--model", plugin.name, *common, "--start", "steady", "--json")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["trough_stress"] == pytest.approx(low, abs=1e-6)
    assert summary["peak_stress"] == pytest.approx(high, abs=1e-6)
    code, out, err = run_main(capsys, "run", "--model", plugin.name, *common, "--start", "steady")
    assert code == 0, err
    line = next(x for x in out.splitlines() if "lowest" in x)
    assert float(line.split("lowest")[1].split()[0]) == pytest.approx(low, abs=1e-2)  # was 999.998
    code, out, err = run_main(capsys, "compare", "--models", f"{plugin.name},r30-direct-b", *common, "--json")
    assert code == 0, err
    for row in json.loads(out)["models"].values():
        assert row["trough_stress"] == pytest.approx(low, abs=1e-6)


def test_a_plug_in_s_start_words_are_named_when_another_word_is_given(plugin, capsys):
    """Before: "starts from a velocity, not a word", though --start steady runs."""
    from cli_helpers import run_main

    args = ("run", "--model", plugin.name, "--control", "velocity", "--v0", "100 um/s", "--duration", "1 s")
    code, _, err = run_main(capsys, *args, "--start", "empty")
    assert code == 2 and "Traceback" not in err
    assert "the word steady" in err and "velocity" in err and "not a word" not in err
    code, _, err = run_main(capsys, *args, "--start", "steady")
    assert code == 0, err


def test_a_steady_run_s_text_gives_the_value_it_settled_at(plugin, capsys):
    """100 µm/s for 1 s, then 200 µm/s for 3 s: it settles at s0 + (eta - beta) 200 µm/s = 1100 Pa, while its mean
    over the run is 1090 Pa (the first segment's 1050 Pa in it); the text gave only the run's mean."""
    from cli_helpers import run_main

    code, out, err = run_main(capsys, "run", "--model", plugin.name, "--control", "velocity", "--v0", "100 um/s",
                              "--duration", "1 s", "--segment", "200 um/s:3 s")  # fmt: skip
    assert code == 0, err
    line = next(x for x in out.splitlines() if "lowest" in x)
    settled = float(line.split("settled at")[1].split()[0])
    assert settled == pytest.approx(truth_last_segment([1e-4, 2e-4], [1.0, 3.0])[2], abs=1e-3)
    # the run's mean: 1050 Pa for 1 s, 1100 Pa for 3 s and the decay from 1150 Pa, 50 Pa x T, over 4 s
    run_mean = (1050.0 + 3 * 1100.0 + 50.0 * T_RELAX * (1 - math.exp(-3.0 / T_RELAX))) / 4.0
    assert float(line.split("mean")[1].split()[0]) == pytest.approx(run_mean, abs=1e-2)


def test_a_sweep_row_s_peak_is_a_cycle_s_not_a_steady_run_s_window():
    """docs/sweep.md: peak_stress "NaN if the block never slips"; a plug-in's steady row carried its steady stress."""
    t = np.linspace(0.0, 10.0, 4001)
    x = 1e-4 * t
    steady = Run.from_trace("toy", t, stress=np.full_like(t, 1230.0), slider_velocity=np.full_like(t, 1e-4),
                            slider_position=x, load_point_position=x)  # fmt: skip
    row = steady.row(CYCLE_RESULTS)
    assert steady.regime.kind == "steady" and math.isnan(row["peak_stress"]) and row["cycles"] == 0
    assert row["mean_stress"] == pytest.approx(1230.0, abs=1e-9)
    ring = 1000.0 + 30.0 * np.sin(2 * np.pi * t / 0.5)
    ringing = Run.from_trace("toy", t, stress=ring, slider_velocity=np.full_like(t, 1e-4), slider_position=x,
                             load_point_position=x)  # fmt: skip
    row = ringing.row(CYCLE_RESULTS)
    assert ringing.regime.kind == "stick-slip" and row["cycles"] > 0
    assert row["peak_stress"] == pytest.approx(1030.0, abs=0.1)  # the cycle's peak, as before


def test_the_quasi_static_record_says_where_its_stiffness_came_from(capsys):
    from cli_helpers import run_main

    args = ("simulate", "--v0", "50 um/s", "--duration", "1 s")
    code, out, _ = run_main(capsys, *args, "--stiffness", "1 GPa/m")  # fails after its stick (exit 3): K is the rig's
    line = next(x for x in out.splitlines() if "starting stuck at" in x)
    assert "K = 1e+06 kPa/m" in line and "Eq 17" not in line and "the rig's" in line
    code, out, err = run_main(capsys, *args)
    assert code == 0, err
    assert "K = 306.495 kPa/m (Eq 17)" in next(x for x in out.splitlines() if "starting stuck at" in x)


def test_fast_velocities_are_written_in_mm_s_and_m_s():
    from stickslip.display import velocity

    assert velocity(1.0) == "1 m/s" and velocity(0.1, 4) == "100 mm/s" and velocity(13.8e-3) == "13.8 mm/s"
    assert velocity(5.0385e-3) == "5038.5 µm/s" and velocity(7.02e-4) == "702 µm/s" and velocity(0.0) == "0 µm/s"
    assert velocity(9.99999e-3, 4) == "10 mm/s"  # the unit of the number as written, not "1e+04 µm/s"
    assert velocity(1e3) == "1000 m/s" and "e+" not in velocity(123456.0)
    assert protocols.constant(1.0, 1.0).describe().startswith("1 m/s for 1 s")
