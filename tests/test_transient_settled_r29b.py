"""Round 29, tester S: the words of a slide after the stick chains' last slip that is not (yet) steady.

D1: rows sampled by ``every`` can keep the verdict back by a row interval; the words now say so, and from when the
run reads steady with these rows and unsampled (the function on sampled rows; since round 31 a run with ``every``
is judged on the solver's own rows from its last slip on, and reads as the unsampled run).  D2: docs/regimes.md
says so.
D3: the words give the largest departure over the stretch judged and since when the run is within the band, with
digits that differ where the stresses do.  D4: below Vc, where steady sliding is unstable for the block, the words
do not offer settling onto it but the stick that comes next."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import stickslip
from stickslip import protocols, regimes
from stickslip.quasistatic.steady import steady_state
from stickslip.transient import run_transient
from stickslip.transient.cycles import SETTLED_RELAXATIONS, Between, SteadyReference, judge, steady_instability
from stickslip.transient.stability import critical_stiffness

ROOT = Path(__file__).resolve().parents[1]

# --------------------------------------------------------------------------- a slide whose approach is known
#: a stick from 0 Pa to σs at T_SLIP, then σ = LEVEL + (START - LEVEL) exp(-(t - T_SLIP)/TAU) towards the steady
#: state, the slider at V_PULL + 250 µm/s x the same exponential
V_PULL, LEVEL, START, TAU, T_SLIP, SIGMA_S, STIFFNESS = 300e-6, 587.45, 560.0, 1.0, 3.0, 775.0, 7.8e5
RTOL = 1e-4
BAND = RTOL * LEVEL  # the band the run must stay within: 0.0587 Pa
SPAN = SETTLED_RELAXATIONS * TAU  # the stretch: 10 s
#: the closed form's entry into the band: |START - LEVEL| exp(-(t - T_SLIP)/TAU) = BAND
T_IN = T_SLIP + TAU * math.log(abs(START - LEVEL) / BAND)  # 9.147 s
FINE = 0.01  # the solver's states, 10 ms apart


def _sigma(t: np.ndarray) -> np.ndarray:
    after = t > T_SLIP
    return np.where(after, LEVEL + (START - LEVEL) * np.exp(-(t - T_SLIP) / TAU), SIGMA_S * t / T_SLIP)


def _velocity(t: np.ndarray) -> np.ndarray:
    return np.where(t > T_SLIP, V_PULL + 250e-6 * np.exp(-(t - T_SLIP) / TAU), 0.0)


def _judge(end: float, every: float | None):
    """The verdict on the states every FINE s up to ``end`` (the slip's instant a state too), kept as they are
    (``every`` None) or as rows every ``every`` s that carry the extremes of the states since the row before."""
    states = np.unique(np.r_[np.arange(0.0, end, FINE), T_SLIP, end])
    values = _sigma(states)
    if every is None:
        rows, between = states, None
    else:
        rows = np.unique(np.r_[np.arange(0.0, end, every), T_SLIP, end])
        n = rows.size
        low, high = np.full(n, np.inf), np.full(n, -np.inf)
        t_low, t_high, fast = np.full(n, np.nan), np.full(n, np.nan), np.full(n, -np.inf)
        for k in range(1, n):
            inside = (states > rows[k - 1]) & (states <= rows[k])
            t, y = states[inside], values[inside]
            low[k], high[k] = y.min(), y.max()
            t_low[k], t_high[k] = t[np.argmin(y)], t[np.argmax(y)]
            fast[k] = _velocity(t).max()
        between = Between(low, high, t_low, t_high, fast)
    events = [("stick", 0.0, 0.0, 0.0), ("slip", T_SLIP, SIGMA_S, 5.5e-4)]
    reference = SteadyReference(V_PULL, LEVEL, TAU * STIFFNESS, STIFFNESS, 1e-6 / V_PULL, every)
    return judge(
        rows, _sigma(rows), _velocity(rows), protocols.constant(V_PULL, end), (), events, "block", None,
        resolution=RTOL, between=between, steady=reference,
    )  # fmt: skip


def _number(pattern: str, text: str) -> float:
    found = re.search(pattern, text)
    assert found, f"{pattern!r} not in {text[:2000]}"
    return float(found.group(1))


def test_unsampled_the_slide_reads_steady_a_stretch_after_it_enters_the_band():
    """Every state a row: steady from T_IN + 10 s (19.147 s, the closed form) on, to a state's spacing."""
    assert _judge(T_IN + SPAN + 2 * FINE, None)[0] == regimes.STEADY
    kind, message, _ = _judge(T_IN + SPAN - 2 * FINE, None)
    assert kind == regimes.UNDETERMINED, message


@pytest.mark.parametrize("every", [7.0, 3.0])
def test_rows_that_keep_the_verdict_back_say_so_and_from_when_it_reads_steady(every):
    """Rows every 7 (3) s: the last state off the band (9.14 s) lies between the rows at 7 and 14 s (9 and 12 s),
    known only by an extreme of the row after it, so the run reads steady once the stretch starts at that row, at
    24 s (22 s); at 0.5 s short of it, with the stretch past the closed form's entry, it is undetermined, and the
    words name the rows, the end from which they read steady and the earliest from which rows finer could."""
    row = every * math.ceil(T_IN / every)  # the first row after the last state off the band
    assert _judge(row + SPAN + 2 * FINE, every)[0] == regimes.STEADY
    end = row + SPAN - 0.5
    assert end - SPAN > T_IN  # the premise: unsampled, this end reads steady
    assert _judge(end, None)[0] == regimes.STEADY
    kind, message, _ = _judge(end, every)
    assert kind == regimes.UNDETERMINED, message
    assert f"rows every {every:g} s" in message and "these rows that keep it undetermined" in message, message
    assert _number(r"reads steady from about t = ([\d.]+) s on with rows", message) == pytest.approx(
        row + SPAN, abs=0.01
    )
    # the row after the entry carries its lowest state: the first after the row before it, the earliest bound
    earliest = every * math.floor(T_IN / every) + FINE + SPAN
    assert _number(r"from as early as about t = ([\d.]+) s", message) == pytest.approx(earliest, abs=0.01)


def test_the_words_give_the_departures_and_since_when_the_run_is_within_the_band():
    """At 15 s the stretch (5 to 15 s) starts 2 τ after the slip: its largest departure is the closed form's at
    its first row, -27.45 e^-2 = -3.715 Pa; the run is within the band after 9.14 s, the last state off it, and
    reads steady from about 19.14 s; at the end it is -27.45 e^-12 = -1.68e-4 Pa from the steady state, printed
    so, and the two stresses printed differ."""
    end = 15.0
    kind, message, _ = _judge(end, None)
    assert kind == regimes.UNDETERMINED, message
    judged = _number(r"judged, from the row at t = ([\d.]+) s", message)
    assert judged == pytest.approx(end - SPAN, abs=FINE)  # the last row at or before the stretch's start
    departure = (START - LEVEL) * math.exp(-(judged - T_SLIP) / TAU)
    assert _number(r"s\), is ([-+][\d.e+-]+) Pa at t = ", message) == pytest.approx(departure, rel=2e-3)
    last_off = FINE * math.floor(T_IN / FINE)  # the last state off the band, on the 10 ms grid
    assert _number(r"after t = ([\d.]+) s, the last state off it", message) == pytest.approx(last_off, abs=1e-6)
    assert _number(r"reads steady from about t = ([\d.]+) s", message) == pytest.approx(last_off + SPAN, abs=0.01)
    at_end = (START - LEVEL) * math.exp(-(end - T_SLIP) / TAU)
    assert _number(r"at the end, ([-+][\d.e+-]+) Pa and", message) == pytest.approx(at_end, rel=1e-2)
    printed = re.search(r"σ = ([\d.]+) Pa and V = .*? = ([\d.]+) Pa at V0", message)
    assert printed and printed.group(1) != printed.group(2), message


def test_a_slide_never_back_in_the_band_says_so_with_the_slip_as_its_largest_departure():
    kind, message, _ = _judge(8.0, None)
    assert kind == regimes.UNDETERMINED, message
    assert "reach back before the slip at t = 3 s" in message, message
    assert _number(r"since the slip is ([-+][\d.e+-]+) Pa at t = 3 s", message) == pytest.approx(
        SIGMA_S - LEVEL, rel=1e-3
    )
    assert "not within 0.0587 Pa of it at any row since the slip" in message, message


# --------------------------------------------------------------------------- the model: the tester's runs
@pytest.fixture(scope="module")
def paper() -> stickslip.Parameters:
    return stickslip.load_parameters("gelatin-glass")


def test_rows_every_10_s_at_350_um_s_read_as_the_unsampled_run_as_the_docs_say(paper):
    """The paper's set at 350 µm/s leaves the band B = 1e-4 σ(350 µm/s) last near t = 21 s (between 20.2 and
    21.2 s, with the glide's steps).  Round 29: with rows every 10 s the row at 30 s carried that, and the run read
    steady only from 30 s + 10 |dσ/dV|/K on, undetermined at 45 s where the unsampled run is steady.  Since round 31
    the sampler keeps the solver's rows from the last slip on and the verdict is judged on them: at 45 s (the tester's
    run), 30 s (not yet settled) and 39.3 s (just settled) the regime and every word are the unsampled run's, with rows
    every 10 s and 3 s; docs/regimes.md says so."""
    steady = steady_state(paper, 350e-6)
    for end, kind in ((45.0, regimes.STEADY), (30.0, regimes.UNDETERMINED), (39.3, regimes.STEADY)):
        unsampled = run_transient(paper, protocols.constant(350e-6, end), stick_population=True)
        assert unsampled.regime == kind, (end, unsampled.message)
        for every in (10.0, 3.0):
            sampled = run_transient(paper, protocols.constant(350e-6, end), stick_population=True, every=every)
            assert (sampled.regime, sampled.message) == (unsampled.regime, unsampled.message), (end, every)
    span = SETTLED_RELAXATIONS * abs(float(steady.stress_slope)) / unsampled.stiffness
    assert span == pytest.approx(18.07, abs=0.01)  # the stretch the docs quote
    docs = (ROOT / "docs" / "regimes.md").read_text(encoding="utf-8")
    assert "whatever `every`" in " ".join(docs.split())


def test_below_vc_the_words_await_the_next_stick_not_steady_sliding(paper):
    """100 µm/s for 25 s, ending in the slide after the start-up slip: steady sliding at 100 µm/s is unstable for
    the paper's block (K = 306 kPa/m against Kc(100 µm/s) = 1.26e9 Pa/m, transient.stability), so the words say so
    and await a stick; the lower bound they quote does not exceed Kc."""
    run = run_transient(paper, protocols.constant(100e-6, 25.0), stick_population=True)
    message = run.message
    assert run.regime == regimes.UNDETERMINED, message
    kc = critical_stiffness(paper, 100e-6)
    assert run.stiffness < kc and 100e-6 < run.critical_velocity  # the premise, independently
    assert "has not settled to steady sliding" not in message and "σ(100 µm/s)" not in message, message
    assert "steady sliding at 100 µm/s is unstable for this block" in message, message
    assert "what comes next is a stick" in message, message
    assert _number(r"at least ([\d.e+]+) Pa/m", message) <= kc * (1 + 1e-9)


def test_a_block_stiffer_than_kc_is_not_called_unstable(paper):
    """Above Kc steady sliding at 100 µm/s is stable: no instability words (the full Kc decides there)."""
    kc = critical_stiffness(paper, 100e-6)
    assert steady_instability(paper, 100e-6, 2.0 * kc) is None
    assert "below Kc(100 µm/s)" in (steady_instability(paper, 100e-6, 0.5 * kc) or "")
