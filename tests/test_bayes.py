"""The Bayesian steady fit's length and progress (issue 19): it converges on a hard 20-point record within a
bounded number of steps, says plainly when it stops unconverged, and shows progress only on a terminal."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip.fitting import SteadyData, fit_steady
from stickslip.fitting.bayes import CONVERGED_TIMES, MIN_STEPS, sample_posterior
from stickslip.fitting.datasets import synthetic_steady_path
from stickslip.parameters import load_parameters
from stickslip.progress import Silent, progress
from stickslip.quasistatic.steady import steady_state

pytest.importorskip("emcee")


#: _unbounded's notes by its inputs, for the tests of this file (see shared_unbounded)
_UNBOUNDED: dict[tuple, list[str]] = {}


@pytest.fixture(autouse=True)
def shared_unbounded(monkeypatch):
    """bayes._unbounded made once per log posterior and centre: the three tests on the hard fit (and the CLI's two
    runs on one record) ask it the same (1-2 s each: eight refits at the prior's edges).  It is a function of the
    data, the sampled keys, the box and the centre, all in the key, so each caller gets the notes it would
    compute; the first caller computes them."""
    from stickslip.fitting import bayes

    compute = bayes._unbounded

    def unbounded(log_post, centre):
        block = log_post.block
        data = block.residuals_of(np.zeros((1, block.eval_points.size)))  # the data over their errors
        key = (log_post.space.keys, log_post.space.vector().tobytes(), log_post.lower.tobytes(),
               log_post.upper.tobytes(), log_post.stated, centre.tobytes(), block.eval_points.tobytes(),
               np.asarray(data).tobytes(), bayes.UNBOUNDED_DROP)  # fmt: skip
        if key not in _UNBOUNDED:
            _UNBOUNDED[key] = compute(log_post, centre)
        return list(_UNBOUNDED[key])

    monkeypatch.setattr(bayes, "_unbounded", unbounded)


@pytest.fixture(scope="module")
def hard_fit():
    """benchmarks/bench_fit.py's "harder 20-point set": gelatin-glass, 140-2000 µm/s, 2 % noise, seed 2 -- a
    skewed, strongly correlated posterior on which the sampler used to run into its 10000-step cap."""
    velocity = np.geomspace(140e-6, 2000e-6, 20)
    true = steady_state(load_parameters("gelatin-glass"), velocity).stress
    noisy = true * (1 + 0.02 * np.random.default_rng(2).standard_normal(20))
    return fit_steady(SteadyData.from_arrays(velocity, noisy, 0.02 * true))


def test_the_default_length_converges_on_a_hard_record_in_a_few_thousand_steps(hard_fit):
    post = sample_posterior(hard_fit, seed=1, critical_draws=100)
    assert post.converged and [m.split(":")[0] for m in post.messages] == ["aging.aging_velocity"]  # see below
    assert post.steps <= 3000  # was 10000 (the cap) and unconverged, tau up to ~200 steps
    assert post.steps - post.burn >= CONVERGED_TIMES * np.max(post.autocorrelation)
    # the posterior of Vc overlaps the least-squares interval (the posterior is skewed: medians differ)
    lo, hi = post.critical_velocity.interval
    lsq_lo, lsq_hi = hard_fit.critical_velocity.interval
    assert lo < lsq_hi and lsq_lo < hi


def test_a_chain_stopped_short_says_it_did_not_converge(hard_fit):
    post = sample_posterior(hard_fit, seed=1, max_steps=MIN_STEPS, critical_draws=20)
    assert not post.converged and post.messages[0].startswith("NOT CONVERGED")
    assert f"limit of {MIN_STEPS} steps" in post.messages[0]
    assert "NOT CONVERGED" in post.report() and post.as_dict()["converged"] is False


def test_cli_warns_on_stderr_and_in_json_when_the_chain_did_not_converge(capsys, monkeypatch):
    from stickslip.fitting import bayes

    monkeypatch.setattr(bayes, "MAX_STEPS", MIN_STEPS)  # the automatic length stops at this cap, unconverged
    args = ["fit", "steady", str(synthetic_steady_path()), "--bayes", "--walkers", "10", "--seed", "3"]
    status, out, err = run_main(capsys, *args, "--json")
    assert status == 0 and json.loads(out)["posterior"]["converged"] is False
    assert err.startswith("stickslip: warning: Bayesian fit: NOT CONVERGED") and err.count("\n") == 1
    assert "\r" not in err and "━" not in err  # no progress bar with --json or off a terminal
    status, out, err = run_main(capsys, *args, "--steps", "20", "--json")  # a length the user fixed
    assert status == 0 and err == "" and json.loads(out)["posterior"]["converged"] is False


def test_progress_is_silent_off_a_terminal_and_a_bar_on_one(monkeypatch):
    stream = io.StringIO()
    monkeypatch.setattr("sys.stderr", stream)
    with progress("work", total=10, unit="steps") as bar:
        assert type(bar) is Silent
        bar.update(5, total=20, note="half")
    assert stream.getvalue() == ""

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    screen = Terminal()
    monkeypatch.setattr("sys.stderr", screen)
    with progress("work", total=10, unit="steps") as bar:
        bar.update(7, note="τ ≈ 3 steps")
    assert "work" in screen.getvalue()


def test_the_kernel_density_of_the_fitted_proposal_is_scipys():
    """The proposal's kernel estimate (samples whitened once) against scipy's gaussian_kde: density and draws."""
    from scipy.stats import gaussian_kde

    from stickslip.fitting.bayes import _Kernels

    rng = np.random.default_rng(0)
    mixing = np.array([[1, 0.9, 0, 0], [0, 0.3, 0, 0], [0, 0, 2, 0], [0.5, 0, 0, 0.1]])
    samples = rng.standard_normal((2400, 4)) @ mixing + 3
    ours, scipy = _Kernels(samples), gaussian_kde(samples.T)
    # and one point far out, where every kernel's term underflows alone (the sum is shifted by the nearest one)
    points = np.vstack([rng.standard_normal((16, 4)) * 2 + 3, [[60.0, -40.0, 30.0, 25.0]]])
    np.testing.assert_allclose(ours.log_density(points), scipy.logpdf(points.T), rtol=1e-12, atol=1e-8)
    drawn = ours.draw(200_000, np.random.RandomState(1))
    # a draw is a sample plus kernel noise: mean of the samples, covariance (1 + factor^2) x theirs
    factor2 = 2400 ** (-2 / 8)
    np.testing.assert_allclose(drawn.mean(axis=0), samples.mean(axis=0), atol=0.02)
    np.testing.assert_allclose(np.cov(drawn.T), (1 + factor2) * np.cov(samples.T), atol=0.03)


def test_a_key_the_data_do_not_bound_is_named_with_its_drop_at_the_prior_edge(hard_fit):
    """On the hard record Va is not bounded above: with Va at the prior's upper edge and the other keys refitted
    the log posterior is only ~3 below its peak.  Checked against an independent profile (Nelder-Mead on the
    log posterior itself, not the package's least squares); the shipped synthetic curve bounds every key."""
    import math

    from scipy.optimize import minimize

    from stickslip.fitting.bayes import _LogPosterior, _unbounded
    from stickslip.fitting.data import read_steady_data

    log_post = _LogPosterior(hard_fit, tuple(hard_fit.free_keys))
    centre, _ = log_post.mode()
    notes = _unbounded(log_post, centre)
    assert len(notes) == 1 and notes[0].startswith("aging.aging_velocity: the data do not bound it above")
    drop = float(notes[0].split("only ")[1].split(" below")[0])
    peak = log_post(centre[None, :])[0]
    edge = log_post.upper[3]
    profile = minimize(lambda x: -log_post(np.r_[x, edge][None, :])[0], centre[:3], method="Nelder-Mead",
                       options={"xatol": 1e-6, "fatol": 1e-6, "maxfev": 2000})  # fmt: skip
    assert drop == pytest.approx(peak + profile.fun, abs=0.05)
    assert 2.0 < drop < 4.0 and math.isfinite(drop)
    synthetic = fit_steady(read_steady_data(synthetic_steady_path()))
    log_post = _LogPosterior(synthetic, tuple(synthetic.free_keys))
    assert _unbounded(log_post, log_post.mode()[0]) == []


def test_compare_and_transient_show_progress_on_a_terminal_only(monkeypatch, capsys):
    """Issue 19: compare and long transient runs showed nothing while they ran; a bar on a terminal, never with
    --json (the bar's text is what rich draws on the terminal stand-in)."""

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    screen = Terminal()
    monkeypatch.setattr("sys.stderr", screen)
    from stickslip.cli.main import main

    for argv in (["compare", "--duration", "20 s"], ["transient", "--v0", "50 um/s", "--duration", "25 s"]):
        with pytest.raises(SystemExit) as done:
            main(argv)
        assert done.value.code == 0
    drawn = screen.getvalue()
    assert "compare" in drawn and "stages" in drawn and "transient" in drawn
    screen.truncate(0)
    screen.seek(0)
    with pytest.raises(SystemExit):
        main(["compare", "--duration", "20 s", "--json"])
    assert "stages" not in screen.getvalue()
    capsys.readouterr()
