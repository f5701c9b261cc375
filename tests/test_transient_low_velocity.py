"""Old bonds reaching a hazard cliff in lumps under velocity control (docs/transient.md section 21, round 29).

A tester's gel (8 wt%, their rig's guesses) driven 10 um/s then 1 um/s: the bonds born at 10 um/s, lumped two per
kernel step, reach the FENE cliff at 1 um/s ten times further apart in time than the cliff is wide, each as one lump,
and the stress over the 1 um/s segment was a sawtooth (0.6 % of sigma, 53 % of its row-to-row changes flipping sign
at the default rtol 1e-4; the final stress 1.7e-3 off a run at rtol 1e-6).  The kernel now cuts such cohorts into
pieces over the birth positions they stand for before they reach the cliff (kernel._split).

The truths used here are the model's own: its exact solution at a constant velocity is smooth (a polynomial fit
leaves only the tolerance), its bookkeeping conserves bonds exactly, and its error falls with rtol towards a run at a
tighter rtol; the reference kernel (``kernel.cohorts_unsplit``) shows each check can fail.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.special

import stickslip
from stickslip.protocols import segments
from stickslip.transient import kernel, run_transient
from tester_sets import TESTER_GEL

#: the tester's parameter file (mygel.toml), as they wrote it
MYGEL = TESTER_GEL

#: 10 um/s from an empty surface past the bonds' memory (1 um of travel: 0.1 s), then 1 um/s, where the bonds born
#: at 10 um/s reach the FENE cliff one after another
PROTOCOL = segments([(10e-6, 0.12), (1e-6, 0.05)])
#: the window read: the 1 um/s segment after its first 5 ms
WINDOW = 0.125


@pytest.fixture(scope="module")
def gel(tmp_path_factory: pytest.TempPathFactory) -> stickslip.Parameters:
    path = tmp_path_factory.mktemp("gel") / "mygel.toml"
    path.write_text(MYGEL, encoding="utf-8")
    return stickslip.load_parameters(str(path))


def _run(gel: stickslip.Parameters, rtol: float, unsplit: bool = False):  # type: ignore[no-untyped-def]
    if unsplit:
        with kernel.cohorts_unsplit():
            return run_transient(gel, PROTOCOL, control="velocity", rtol=rtol)
    return run_transient(gel, PROTOCOL, control="velocity", rtol=rtol)


@pytest.fixture(scope="module")
def runs(gel: stickslip.Parameters) -> dict[tuple[float, bool], object]:
    cases = [(1e-3, False), (1e-4, False), (1e-5, False), (1e-4, True)]
    return {case: _run(gel, *case) for case in cases}


def _sawtooth(run) -> tuple[float, float]:  # type: ignore[no-untyped-def]
    """(the largest distance of the rows from a smooth fit over the window, relative to sigma; the share of
    row-to-row changes that flip sign)."""
    keep = run.time >= WINDOW
    t, s = run.time[keep], run.stress[keep]
    u = 2.0 * (t - t[0]) / (t[-1] - t[0]) - 1.0
    fit = np.polynomial.chebyshev.Chebyshev.fit(u, s, 8)
    change = np.diff(s)
    return float(np.max(np.abs(s - fit(u))) / np.mean(s)), float(np.mean(change[1:] * change[:-1] < 0))


def test_the_stress_is_smooth_where_old_bonds_reach_their_cliff(runs) -> None:  # type: ignore[no-untyped-def]
    """Measured: 4.8e-7 of sigma off the fit and no flip at rtol 1e-4 (9.1e-6 at 1e-3); the kernel before: 7.1e-4,
    24 % of the changes flipping (3.8e-3, 51 % at 1e-3)."""
    for rtol in (1e-3, 1e-4):
        off, flips = _sawtooth(runs[(rtol, False)])
        assert off < 0.3 * rtol and flips < 0.01, (rtol, off, flips)
    off, flips = _sawtooth(runs[(1e-4, True)])
    assert off > 3e-4 and flips > 0.1  # the sawtooth the cut removes is there without it


def test_the_error_falls_with_rtol(runs) -> None:  # type: ignore[no-untyped-def]
    """The final stress against the rtol 1e-5 run: measured 8.1e-6 and 1.2e-6 of sigma at rtol 1e-3 and 1e-4 (against
    runs at rtol 1e-6 with and without the cut, 3.8e-7 apart: 7.6-8.0e-6, 1.4-1.7e-6, 1.1-5.0e-7 at 1e-3, 1e-4,
    1e-5); the kernel before: 7.1e-4 and 4.8e-4 off its own rtol 1e-5 run."""
    reference = runs[(1e-5, False)].stress[-1]
    errors = [abs(runs[(rtol, False)].stress[-1] / reference - 1) for rtol in (1e-3, 1e-4)]
    assert errors[0] < 0.1 * 1e-3 and errors[1] < 0.1 * 1e-4, errors
    assert errors[1] < errors[0]
    assert abs(runs[(1e-4, True)].stress[-1] / reference - 1) > 1e-4


def test_the_cut_keeps_every_bond(runs, gel) -> None:  # type: ignore[no-untyped-def]
    """N = born - broken from an empty start, to rounding, with cohorts cut (measured 2e-13 of N0)."""
    n0 = gel.bonds.site_density
    for rtol in (1e-3, 1e-4):
        run = runs[(rtol, False)]
        book = run.bookkeeping
        assert np.max(np.abs(run.bonded_fraction * n0 - (book.born - book.broken))) < 1e-9 * n0


def test_runs_without_lumps_at_a_cliff_are_unchanged() -> None:
    """The paper's gel at 350 um/s stepped to 1 mm/s under velocity control, and through its block: no cohort meets a
    cliff in lumps, and every number is that of the kernel without the cut (the block never cuts)."""
    p = stickslip.load_parameters("gelatin-glass")
    step = segments([(350e-6, 0.004), (1e-3, 0.004)])
    for control in ("velocity", "block"):
        runs = []
        for unsplit in (False, True):
            if unsplit:
                with kernel.cohorts_unsplit():
                    runs.append(run_transient(p, step, control=control, start="steady", reduction="off"))
            else:
                runs.append(run_transient(p, step, control=control, start="steady", reduction="off"))
        assert np.array_equal(runs[0].time, runs[1].time) and np.array_equal(runs[0].stress, runs[1].stress)


def test_the_ripple_is_the_gumbel_train_s_first_harmonic() -> None:
    """kernel._ripple against the closed form (2/pi) s |Gamma(1 - 2 pi i/c)|, Gamma from scipy."""
    kernel.compiled()
    for crossing in (0.5, 1.0, 2.0, 18.0, 300.0):
        exact = 2.0 / math.pi * abs(scipy.special.gamma(1.0 - 2j * math.pi / crossing))
        assert kernel._ripple(1.0, 1.0, crossing) == pytest.approx(exact, rel=1e-9, abs=1e-300)
    assert kernel._ripple(6.0, 3.0, 18.0) == pytest.approx(2.0 * kernel._ripple(1.0, 1.0, 18.0), rel=1e-12)


def test_a_cut_tiles_the_cells_between_gauss_pairs() -> None:
    """Cohorts born as Gauss pairs of steps h: two neighbours cut at once into pieces tile the births halfway to their
    own neighbours (half a step each), keep their weights, and the next cohort's cell starts where their pieces end;
    one cut alone waits for its younger neighbour."""
    kernel.compiled()
    h, v = 4.5e-5, 1e-5
    times = np.array([(k + 0.5 + s * kernel.GAUSS) * h for k in range(6) for s in (-1.0, 1.0)])
    n = times.size
    size = 64

    def arrays():  # type: ignore[no-untyped-def]
        xb, tb, lw = np.zeros(size), np.zeros(size), np.zeros(size)
        xb[:n], tb[:n], lw[:n] = v * times, times, np.log(np.arange(1.0, n + 1.0))
        return xb, tb, lw, np.zeros(size), np.zeros((4, size)), np.zeros((2, size))

    def cut(xb, tb, lw, rate0, known, clock, at):  # type: ignore[no-untyped-def]
        slots = np.zeros(64, np.int64)
        slots[: len(at)] = at
        pieces = np.zeros(64, np.int64)
        pieces[: len(at)] = 8
        return kernel._split(n, len(at), slots, pieces, np.empty((4, 64)), xb, tb, lw, rate0, known, clock)

    xb, tb, lw, rate0, known, clock = arrays()
    assert cut(xb, tb, lw, rate0, known, clock, [5]) == (n, False)  # alone: waits for cohort 6
    assert np.array_equal(xb[:n], v * times)
    # the second of the third step's pair and the first of the fourth's: cells [2.5 h, 3 h] and [3 h, 3.5 h]
    weights = np.exp(lw[5:7])
    n_new, full = cut(xb, tb, lw, rate0, known, clock, [5, 6])
    assert not full and n_new == n + 14
    got = xb[5:21]
    assert got == pytest.approx(v * h * (2.5 + (np.arange(16) + 0.5) / 16), rel=1e-12)
    assert tb[5:21] == pytest.approx(got / v, rel=1e-12)
    assert np.exp(lw[5:13]).sum() == pytest.approx(weights[0], rel=1e-12)
    assert np.exp(lw[13:21]).sum() == pytest.approx(weights[1], rel=1e-12)
    assert xb[21] == pytest.approx(v * times[7], rel=1e-15)  # the rest moved up, unchanged
    lo, _hi, _tl, _th = kernel._cell(21, n_new, xb, tb)
    assert lo == pytest.approx(3.5 * v * h, rel=1e-12)
