"""The cohort kernel and run_transient split into named steps (issue 30 item 4) give the same numbers.

A regression test of a refactor: the reference arrays in ``tests/data/transient_split_reference.npz`` were written
by ``python tests/test_transient_split.py --write`` from the code *before* the split (commit 6299fba).  Every trace
array of each case must equal them within ``SAME`` (1e-6) of the array's largest value (nan where nan), the step
count within ``SAME_STEPS``, the regime and the message exactly.  The numbers themselves are validated
independently elsewhere (tests/test_transient*.py: closed forms, the steady solver, convergence orders); this file
pins that the kernel's and the solver's outcome does not move when their code is rearranged.

Until 2026-11-29 the comparison was bit for bit, which held on the machines that wrote the reference and failed on
a fresh one (AMD EPYC, AVX2 without AVX-512): numba compiles the kernel for the host's CPU, and the last bits of
the adaptive steps differ between CPUs.  Measured there against the stored arrays: the same step counts and verdicts,
every array within 4.0e-8 of its largest value (``from_rest_chains``: its slider position and running totals after
the jump; ``steady_reduced`` 8.8e-14; the other cases 1.3e-18 or equal).  ``SAME`` is 25 times that, and below the
smallest change of method this file was rewritten for that moved the stress or N (2.6e-6, the births' spacing).

Each case starts from cleared caches (the quasi-steady reduction's built manifolds, ``reduction._BUILT``, are
reused within a process, and one built at a tighter rtol serves a looser one: the answer would depend on the
order of the cases), so the cases are independent of the order they run in; the reference was written twice,
once per case in a fresh process and once all in one process, and the two agreed bit for bit.

The ``saturating`` case was rewritten when the method changed for saturating aging (issue 33 item 3: the births'
own error bound and converged sweeps, wider bins for light saturated cohorts; docs/transient.md section 8), after
the new trace was checked against the old one and against the plain cohorts at rtol 1e-5 (60 ms from rest at rtol
1e-3, interpolated at its rows past 2 ms): sigma within 2.1e-8 of the peak stress (old 2.1e-8), N within 1.7e-5 N0
(old 1.0e-5), 392 steps against 669; at 60 ms sigma equal to the old to 2.6e-9, N to 5.8e-6 N0.  Rewritten again
for the cheaper cohort step of saturating aging (its clock without expm1 past t_s ln 2, the cohorts' error by a
series; docs/transient.md section 8): every array within 1.1e-11 of its largest value of the previous one, the
same 392 steps and verdict.  The other six cases still equal the arrays of commit 6299fba.

Every case was rewritten for the cheaper step of issue 33 item 3's last round (docs/transient.md section 8: the
slider's Newton iteration from the last point it evaluated, stopped where its next correction is within its
tolerance; saturated cohorts merged every MERGE_EVERY steps; the saturating clock carried by one factor per step).
Against the arrays before, each case took the same steps to the same verdict: every array within 1.5e-10 of its
largest value (from_rest 2.2e-11, from_rest_chains 1.5e-10, steady_spring 1.6e-13, steady_reduced 1.1e-14;
velocity_step and mass, which the slider's root does not enter, bit for bit), and the saturating case's trace within
4.5e-7 (sigma), 2.1e-6 (N/N0); its bond energy, 7e-5 of the puller's work there, 1.0e-2 lower: against the plain
cohorts at rtol 1e-5 (9.766e-11 J/m^2 at 60 ms) the merged cohorts' is 5.0 % low before and 6.0 % after (at rtol
1e-4 3.1 % and 3.4 %), the energy of a merged cohort's mean extension.

The two cases through the quasi-steady reduction (``from_rest_chains``, ``steady_reduced``) were rewritten when the
reduced bonded count took its own first-order lag (N = N_ss(V) + C_N V', issue 31; docs/transient.md section 10):
only ``bonded_fraction`` and ``bookkeeping_broken`` (births less the change of N) changed, every other array bit
for bit.  Against the plain cohorts at rtol 1e-5, N/N0 of ``steady_reduced`` (on its 5 ms grid) is within 2.6e-9
instead of 6.2e-6, and of ``from_rest_chains`` (interpolated at its rows past 0.5 s) within 9.5e-7 instead of
1.1e-6.

``from_rest_chains`` was rewritten again when, with the stick chains under a moving puller, the births' spacing took
their own Gauss error and a stick was landed on the slider's crossing of the stick velocity (issue 31;
docs/transient.md section 11): the same 52 steps and verdict, the trace within 5.3e-8 (sigma), 2.6e-6 (N/N0, V) of
the largest values of the previous one; against the plain cohorts at rtol 1e-5 (rows past 0.5 s) sigma within
6.2e-8 (before 6.2e-8), N/N0 2.6e-6 (2.3e-6), V 2.4e-6 (2.1e-6) of their largest values.

``from_rest_chains`` was rewritten again when a step came to end short of a loaded cohort's arrival at the FENE wall
(kernel.WALL_LANDING, issue 31; docs/transient.md section 12): the same 52 steps and verdict, sigma within 4.9e-14,
N/N0 and V within 2.6e-6 and 2.3e-6 of the largest values of the previous trace; against the plain cohorts at rtol
1e-5 (rows past 0.5 s) unchanged: sigma 6.2e-8, N/N0 2.6e-6, V 2.4e-6.  The other six cases are unchanged.

The two cases through the reduction were rewritten again when its glide ODE took its first step on the velocity's
own scale and ran compiled (``transient/glide.py``, issue 31; docs/transient.md section 13): scipy's heuristic had
counted the quadratures' atol of 1e-30 and started at 10 ulp of t.  Fewer ODE steps (``from_rest_chains`` 38 against
52, ``steady_reduced`` 67 against 81), hence other rows inside the glides, and the same verdicts.  ``steady_reduced``:
every array within 3.1e-12 of its largest value at the same 5 ms rows (its ``lowest_stress``, the least stress of
the ODE's own steps since the last row, moves by up to 1.3e-3 where a row holds no step now).
``from_rest_chains``: the last row within 1.1e-9 (V) of the old one; against the plain cohorts at rtol 1e-5 (rows
past 0.5 s) sigma within 6.4e-8 (before 6.2e-8), N/N0 2.6e-6 and V 2.4e-6 (unchanged).  And once more in the
same round, for the coarser population rebuilt at a glide's end and at the paper's jump (``solver._rebuilt_cells``):
the same steps and verdicts, every array within 5.7e-9 (``from_rest_chains``, V) and 3.6e-12 (``steady_reduced``)
of its largest value; against the plain cohorts unchanged.
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import stickslip
from stickslip.protocols import Protocol, Segment, constant
from stickslip.transient import reduction, run_transient, solver
from stickslip.transient.result import TransientResult

REFERENCE = Path(__file__).parent / "data" / "transient_split_reference.npz"


def _gel() -> stickslip.Parameters:
    return stickslip.load_parameters("gelatin-glass")


def _from_rest() -> TransientResult:
    """The massless block from rest under Eq 1 alone (stuck, creeping; every cohort kept)."""
    return run_transient(_gel(), constant(100e-6, 0.02))


def _from_rest_chains() -> TransientResult:
    """The massless block from rest with the stick chains: stuck, the chains' collapse, the jump, the slip."""
    return run_transient(_gel(), constant(1e-3, 8.0), stick_population=True, rtol=1e-3)


def _steady_spring() -> TransientResult:
    """A steady start through the spring, a step of the puller down (the paper's cycle's start), the plain cohorts."""
    protocol = Protocol((Segment(350e-6, 0.02), Segment(100e-6, 0.02)))
    return run_transient(_gel(), protocol, start="steady", rtol=1e-3, reduction="off")


def _steady_reduced() -> TransientResult:
    """The same through the quasi-steady reduction, sampled every 5 ms."""
    protocol = Protocol((Segment(350e-6, 0.2), Segment(700e-6, 0.2)))
    return run_transient(_gel(), protocol, start="steady", every=5e-3)


def _velocity_step() -> TransientResult:
    """Velocity control from empty, a step of the slider's velocity."""
    protocol = Protocol((Segment(100e-6, 4e-3), Segment(300e-6, 4e-3)))
    return run_transient(_gel(), protocol, control="velocity", rtol=1e-4, reduction="off")


def _mass() -> TransientResult:
    """A block with mass (and damping) from a steady start, a kick of the puller."""
    protocol = Protocol((Segment(360e-6, 2e-3), Segment(350e-6, 2e-3)))
    return run_transient(_gel(), protocol, start="steady", start_velocity=350e-6, mass=1.0, damping=10.0, rtol=1e-3)


def _saturating() -> TransientResult:
    """Saturating aging from rest: the merging of saturated cohorts and their relative drop."""
    return run_transient(stickslip.load_parameters("gelatin-glass-saturating"), constant(50e-6, 0.06), rtol=1e-3)


CASES: dict[str, Callable[[], TransientResult]] = {
    "from_rest": _from_rest,
    "from_rest_chains": _from_rest_chains,
    "steady_spring": _steady_spring,
    "steady_reduced": _steady_reduced,
    "velocity_step": _velocity_step,
    "mass": _mass,
    "saturating": _saturating,
}


def _clear_caches() -> None:
    reduction._BUILT.clear()
    solver._STEADY_COHORTS.clear()


def _arrays(run: TransientResult) -> dict[str, np.ndarray]:
    """Every trace array of a run, its counts, its verdict and its last snapshot's sums (its cohorts, thousands from a
    steady population, would make the file large; the sums of the weights, and of the weights times ages and
    extensions, change with any of them)."""
    out = {
        name: np.asarray(getattr(run, name))
        for name in ("time", "stress", "bonded_fraction", "slider_velocity", "slider_position", "puller_position")
    }
    for name in ("chain_fraction", "lowest_stress"):
        if getattr(run, name) is not None:
            out[name] = np.asarray(getattr(run, name))
    for name in ("born", "broken", "work", "dissipation", "bond_energy", "block_energy", "stress_integral"):
        value = getattr(run.bookkeeping, name)
        if value is not None:
            out["bookkeeping_" + name] = np.asarray(value)
    out["counts"] = np.array([run.steps, run.rejected])
    out["verdict"] = np.array([run.regime, run.message])
    last = run.snapshots[-1]
    w = np.asarray(last.weight)
    out["snapshot"] = np.array([last.time, w.size, w.sum(), w @ np.asarray(last.age), w @ np.asarray(last.extension)])
    return out


def _case(name: str) -> dict[str, np.ndarray]:
    _clear_caches()
    return _arrays(CASES[name]())


@pytest.fixture(scope="module")
def reference() -> dict[str, np.ndarray]:
    with np.load(REFERENCE) as data:
        return {key: data[key] for key in data.files}


#: an array agrees when within this share of its largest value (the module docstring: 25x the spread between CPUs)
SAME = 1e-6
#: and a step count within this share (no case moved by a step between CPUs; an accepted step's error near 1 could)
SAME_STEPS = 0.02


def _same(got: np.ndarray, expected: np.ndarray) -> bool:
    """Equal where not floats (counts within SAME_STEPS, verdict strings exactly); floats of one shape within SAME of
    the largest expected value, nan where nan."""
    if expected.dtype.kind != "f":
        if expected.dtype.kind in "iu" and got.dtype.kind in "iu" and got.shape == expected.shape:
            return bool(np.all(np.abs(got - expected) <= SAME_STEPS * np.abs(expected) + 1))
        return bool(np.array_equal(got, expected))
    if got.shape != expected.shape or not np.array_equal(np.isnan(got), np.isnan(expected)):
        return False
    finite = np.isfinite(expected)
    if not np.array_equal(got[~finite], expected[~finite], equal_nan=True):
        return False
    scale = float(np.max(np.abs(expected[finite]), initial=0.0))
    return bool(np.all(np.abs(got[finite] - expected[finite]) <= SAME * scale))


@pytest.mark.parametrize("name", list(CASES))
def test_the_split_changes_no_number(name: str, reference: dict[str, np.ndarray]) -> None:
    got = _case(name)
    keys = sorted(key.split("/", 1)[1] for key in reference if key.startswith(name + "/"))
    assert keys == sorted(got), (keys, sorted(got))
    for key in keys:
        if (name, key) in SAMPLED_LOWEST:
            _check_sampled_lowest(got, reference[f"{name}/{key}"])
            continue
        expected = reference[f"{name}/{key}"]
        if key == "verdict":  # the words after "(docs/transient.md section 7); " are a hint, reworded in round 28
            got[key], expected = (np.array([str(v).split(HINT)[0] for v in pair]) for pair in (got[key], expected))
            # round 29: an undetermined run whose last event is a slip says how far it is from settling (words)
            got[key] = np.array([re.sub(NOT_SETTLED, "", str(v)) for v in got[key]])
        assert _same(got[key], expected), f"{name}: {key} differs"


#: where the stuck block's hint to add the stick chains begins (its wording is no number of the run)
HINT = "(docs/transient.md section 7); "
#: the clause round 29 added to a run whose stick chains' last event is a slip and that has not settled after it
#: (docs/transient.md section 20; its numbers are the steady curve's, checked in tests/test_transient_verdicts_r29.py)
NOT_SETTLED = r"; the slide since has not settled to steady sliding \(.*?lies within [^)]* of it\)"


#: the cases whose rows are sampled onto a grid after the integration (docs/transient.md section 19): a row's lowest
#: stress is now the least of every state the solver took since the row before, the glide's own rows included, where
#: it was the least of the states the grid-landing steps took (1.2e-3 of the largest value lower at one row)
SAMPLED_LOWEST = {("steady_reduced", "lowest_stress")}


def _check_sampled_lowest(got: dict[str, np.ndarray], old: np.ndarray) -> None:
    """The new lowest stress of each row sees at least the states the old one saw: at or below the old value (to
    SAME), and at or below the row's own stress."""
    new, stress = got["lowest_stress"], got["stress"]
    assert new.shape == old.shape
    scale = float(np.max(np.abs(old[np.isfinite(old)]), initial=0.0))
    finite = np.isfinite(old) & np.isfinite(new)
    assert np.all(new[finite] <= old[finite] + SAME * scale)
    assert np.all(new[finite] <= stress[finite] + SAME * scale)


def test_the_comparison_can_fail(reference: dict[str, np.ndarray]) -> None:
    """A change of 2 SAME of the largest value at one row is seen, as is one more nan, a row less, a step count 5 %
    off; one of SAME / 2 is not."""
    stress = reference["velocity_step/stress"]
    scale = float(np.max(np.abs(stress)))
    for moved, seen in ((2 * SAME, True), (0.5 * SAME, False)):
        changed = stress.copy()
        changed[len(changed) // 2] += moved * scale
        assert _same(changed, stress) is not seen
    holed = stress.copy()
    holed[-1] = np.nan
    assert not _same(holed, stress) and not _same(stress[:-1], stress)
    counts = reference["velocity_step/counts"]
    assert not _same(np.rint(counts * 1.05).astype(counts.dtype) + 1, counts) and _same(counts.copy(), counts)


def _write(names: list[str]) -> None:
    """Write the reference of the named cases (all when none), merged into the file."""
    stored: dict[str, np.ndarray] = {}
    if REFERENCE.exists():
        with np.load(REFERENCE) as data:
            stored = {key: data[key] for key in data.files}
    for name in names or list(CASES):
        stored = {key: value for key, value in stored.items() if not key.startswith(name + "/")}
        stored.update({f"{name}/{key}": value for key, value in _case(name).items()})
    REFERENCE.parent.mkdir(exist_ok=True)
    np.savez_compressed(REFERENCE, **stored)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--write"]:
        _write(sys.argv[2:])
