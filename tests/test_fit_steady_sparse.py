"""Steady fit of sparse curves (a tester's 4, 6 and 8 points, 2026-11-30).

``auto`` refused six valid points as bad input (exit 2) because the two-step method's step 1 had one point above
the split; ``--method joint`` called a curve falling by a factor 25 and rising by 3.4 (2 % noise) "no significant
velocity dependence" (the neighbours' scatter counts the bend as noise; the nested F test has one degree of freedom
for its noise), and with 2 % stated errors the same ("varies by 28.2 stated errors … p = 0.39").  The truth of
these synthetic curves is known: gelatin-glass, Vc = 124.097 µm/s.
"""

from __future__ import annotations

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip.errors import DataError
from stickslip.fitting import SteadyData, fit_steady
from stickslip.fitting.scatter import local_scatter, velocity_dependence
from stickslip.parameters import load_parameters
from stickslip.quasistatic.critical import critical_point
from stickslip.quasistatic.steady import steady_state

TRUE = load_parameters("gelatin-glass")
VC = critical_point(TRUE).velocity
#: the tester's six velocities (31 µm/s to 2.8 mm/s, one above the two-step's split of 800 µm/s)
SIX = np.array([30.8884, 82.8643, 145.635, 222.3, 686.649, 2811.77]) * 1e-6
#: eight, three above the split (step 1 has three parameters)
EIGHT = np.geomspace(13.26e-6, 5.69e-3, 8)


def _curve(velocity: np.ndarray, seed: int, noise: float = 0.02) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return steady_state(TRUE, velocity).stress * (1 + noise * rng.standard_normal(velocity.size))


def _covers(fit) -> bool:  # type: ignore[no-untyped-def]
    interval = fit.critical_velocity.interval
    return interval is not None and interval[0] <= VC <= interval[1]


@pytest.mark.parametrize("stated", [False, True])
def test_auto_answers_six_points_with_the_joint_fit(stated: bool) -> None:
    """Exit 2 before ("step 1 …: 1 data point(s) for 3 free parameter(s)"); the joint fit has the points."""
    stress = _curve(SIX, 7)
    fit = fit_steady(SteadyData.from_arrays(SIX, stress, 0.02 * stress if stated else None))
    assert fit.status == "ok", fit.reason
    assert fit.method == "joint"
    assert any("two-step method (the paper's) cannot fit these points" in m for m in fit.messages)
    assert _covers(fit), fit.critical_velocity


def test_eight_points_with_three_above_the_split_fit_and_cover_the_truth() -> None:
    fit = fit_steady(SteadyData.from_arrays(EIGHT, _curve(EIGHT, 3), None))
    assert fit.status == "ok", fit.reason
    assert fit.method == "joint" and _covers(fit), fit.critical_velocity


def test_a_linear_trend_against_correct_stated_errors_is_a_velocity_dependence() -> None:
    """Known truth: a straight line in ln V, 3 stated errors from end to middle, with noise of the stated size.
    The neighbours see no bend, so their scatter agrees with the errors and the χ² of a constant decides (the F
    test against the scatter, with ~3 degrees of freedom, said p = 0.01-0.1, and the larger p was taken)."""
    velocity = np.geomspace(30e-6, 3e-3, 8)
    x = np.log(velocity / velocity[0]) / np.log(100.0)  # 0 … 1
    error = np.full(8, 4.0)
    stress = 400.0 + 24.0 * (x - 0.5) + 4.0 * np.random.default_rng(2).standard_normal(8)
    dependence = velocity_dependence(stress, error, local_scatter(velocity, stress, error))
    assert dependence.significant, dependence.text
    assert "χ² test against the stated errors" in dependence.text


def test_the_constant_is_judged_by_the_noise_the_model_leaves() -> None:
    """The model's own curve stands for its fit (known truth): against its residuals' scatter (relative) and
    against the stated errors they bear out, six points varying by a factor 25 are no constant."""
    from stickslip.fitting.scatter import fitted_dependence

    stress = _curve(SIX, 7)
    model = steady_state(TRUE, SIX).stress
    p, noise = fitted_dependence(SIX, stress, None, model)
    assert p < 1e-3 and 0.002 < noise.scale < 0.06
    p, noise = fitted_dependence(SIX, stress, 0.02 * stress, model)
    assert p < 1e-30 and noise.scale < 3.0
    flat = np.full(6, 500.0) * (1 + 0.02 * np.random.default_rng(1).standard_normal(6))
    assert fitted_dependence(SIX, flat, None, np.full(6, 500.0))[0] > 1e-3  # noise about a flat curve


@pytest.mark.parametrize(
    ("velocity", "seed", "stated"),
    [(SIX, 0, None), (EIGHT, 1, None), (SIX, 2, 0.02), (EIGHT, 3, 0.002)],  # the last: errors stated 10× too small
)
def test_flat_noise_is_still_no_velocity_dependence(velocity: np.ndarray, seed: int, stated: float | None) -> None:
    stress = 500.0 * (1 + 0.02 * np.random.default_rng(seed).standard_normal(velocity.size))
    data = SteadyData.from_arrays(velocity, stress, None if stated is None else stated * stress)
    fit = fit_steady(data, method="joint")
    assert fit.status == "failed" and "no significant velocity dependence" in fit.reason


def test_four_points_are_too_few_for_any_method_and_the_advice_says_so(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """4 points, 5 joint parameters: exit 2, without advising the joint fit (which said "use --method joint")."""
    velocity = np.array([54.29, 145.6, 339.3, 1389.5]) * 1e-6
    data = SteadyData.from_arrays(velocity, _curve(velocity, 4), None)
    for method in ("auto", "joint"):
        with pytest.raises(DataError, match="4 data point") as error:
            fit_steady(data, method=method)
        assert "--method joint" not in str(error.value) and "--fix" in str(error.value)
    path = tmp_path / "s4.csv"
    path.write_text("velocity,stress\n" + "\n".join(f"{v},{s}" for v, s in zip(velocity, data.stress, strict=True)))
    code, _, err = run_main(capsys, "fit", "steady", str(path))
    assert code == 2 and "--method joint" not in err


def test_a_split_asked_for_is_kept_and_its_advice_names_the_joint_fit_where_it_can_fit() -> None:
    data = SteadyData.from_arrays(SIX, _curve(SIX, 7), None)
    with pytest.raises(DataError, match="step 1") as error:
        fit_steady(data, split="1 mm/s")
    assert "use --method joint" in str(error.value)
