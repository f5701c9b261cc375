"""Bayesian steady fit: posterior samples with emcee (optional extra ``stickslip[bayes]``).

The ln-values of the keys the least-squares fit determined are sampled; the priors, the likelihood (with an
unknown relative noise integrated out when no ``stress_err`` is given), the burn-in rounds with fitted
independence proposals (:class:`_Fitted`), the convergence check and the posteriors of Vc and sigma_c:
docs/fitting.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..columns import with_units
from ..errors import ParameterError, StickslipError
from ..parameters import Parameters, key_dimension
from ..progress import Silent
from ..progress import progress as progress_bar
from ..quasistatic.steady import steady_state
from . import identify
from .batch import stress_many
from .critical_uncertainty import critical_many
from .problem import SEARCH_BOX, Space, jacobian, make_block, minimize
from .results import CRITICAL, Estimate, display_unit, undetermined_critical

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    from matplotlib.axes import Axes

    from .data import SteadyData
    from .steady_fit import SteadyFit

#: Posterior samples used for Vc, sigma_c and the credible band.
CRITICAL_DRAWS = 400
BAND_DRAWS = 200
#: Convergence check: the chain after burn-in is at least this many autocorrelation times long ...
CONVERGED_TIMES = 50
#: ... after a burn-in of this many autocorrelation times.
BURN_TIMES = 5
#: Steps run between convergence checks, the fewest steps, and the most the automatic length runs.
CHUNK_STEPS = 50
MIN_STEPS = 200
MAX_STEPS = 10000
#: The independence proposal: t with this many degrees of freedom, scale this factor times the standard errors.
PROPOSAL_DOF = 10.0
PROPOSAL_SCALE = 1.0
#: Share of the independence proposal in the mixture of moves (the rest: differential evolution).
INDEPENDENCE_WEIGHT = 0.5
#: A key whose log posterior, at the prior's edge with the others refitted, is less than this below the peak
#: is reported as not bounded by the data on that side.
UNBOUNDED_DROP = 10.0
#: Burn-in rounds (steps each): the first with the mixture of moves, then the proposal fitted to the last round.
PILOT_STEPS = (150, 150, 150)
#: The fitted proposal: a kernel density estimate of the pilot samples, with this share of a t (PROPOSAL_DOF,
#: the pilot's covariance times DEFENSIVE_SCALE**2) that keeps its tails heavier than the posterior's ...
DEFENSIVE_WEIGHT = 0.3
DEFENSIVE_SCALE = 3.0
#: ... mixed with differential-evolution moves in this share (they explore where the pilot has not been).
FITTED_WEIGHT = 0.5


class BayesUnavailable(StickslipError):
    """emcee (or corner) is not installed."""


def _emcee() -> Any:
    try:
        import emcee
    except ImportError:
        raise BayesUnavailable("the Bayesian fit needs emcee: pip install stickslip[bayes]") from None
    return emcee


@dataclass(frozen=True)
class SteadyPosterior:
    """Posterior samples of a steady fit (ln-values of ``keys``) and what follows from them."""

    fit: SteadyFit
    keys: tuple[str, ...]
    chain: np.ndarray  # (samples, keys), ln of SI values
    log_prob: np.ndarray
    walkers: int
    steps: int
    burn: int
    thin: int
    acceptance: float
    autocorrelation: np.ndarray
    priors: tuple[str, ...]
    noise: str
    estimates: tuple[Estimate, ...]
    critical_velocity: Estimate
    critical_stress: Estimate
    critical_samples: np.ndarray = field(repr=False)  # (draws, 2): Vc, sigma_c
    messages: tuple[str, ...] = ()
    #: whether the chain passed the convergence check (else the first message says how it fell short)
    converged: bool = True

    @property
    def data(self) -> SteadyData:
        return self.fit.data

    def parameters(self, index: int) -> Parameters:
        """The parameter set of posterior sample ``index``."""
        return Space(self.fit.parameters, self.keys).params(self.chain[index])

    def stress_band(
        self, velocity: np.ndarray | None = None, level: float = 0.95, draws: int = BAND_DRAWS, seed: int = 0
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(velocity, lower, upper): the central ``level`` credible band of sigma(V)."""
        if velocity is None:
            lo = float(self.data.velocity.min()) / 2.0
            if self.fit.critical_velocity.value is not None:
                lo = min(lo, self.fit.critical_velocity.value / 2.0)
            velocity = np.geomspace(lo, float(self.data.velocity.max()) * 1.3, 60)
        rng = np.random.default_rng(seed)
        picks = rng.choice(self.chain.shape[0], size=min(draws, self.chain.shape[0]), replace=False)
        curves = np.array([steady_state(self.parameters(int(k)), velocity).stress for k in picks])
        tail = (1.0 - level) / 2.0
        low, high = np.quantile(curves, [tail, 1.0 - tail], axis=0)
        return velocity, low, high

    def corner_samples(self) -> tuple[np.ndarray, list[str]]:
        """Samples for the corner plot in units people use (µs, µm/s, Pa...), with axis labels.

        The rows are those where Vc and sigma_c were computed; a quantity whose 95 % range spans more than
        a factor 30 is shown as log10 of its value in that unit.
        """
        rng = np.random.default_rng(1)
        n = self.critical_samples.shape[0]
        rows = rng.choice(self.chain.shape[0], size=n, replace=False) if n < self.chain.shape[0] else np.arange(n)
        columns = [
            (np.exp(self.chain[rows, i]), identify.SYMBOLS.get(k, k), key_dimension(k)) for i, k in enumerate(self.keys)
        ]
        columns += [(self.critical_samples[:, 0], "Vc", "velocity"), (self.critical_samples[:, 1], "σc", "stress")]
        out, labels = [], []
        for values, symbol, dimension in columns:
            unit, size = display_unit(float(np.median(values)), dimension)
            power = math.floor(math.log10(abs(float(np.median(values)) / size) or 1.0))
            if abs(power) >= 4:  # no unit for it (site densities): a power of ten in the label instead
                size *= 10.0**power
                unit = f"1e{power} {unit}".strip()
            scaled = values / size
            lo, hi = np.quantile(scaled, [0.025, 0.975])
            suffix = f" ({unit})" if unit else ""
            if lo > 0 and hi / lo > 30:
                out.append(np.log10(scaled))
                labels.append(f"log10 {symbol}{suffix}")
            else:
                out.append(scaled)
                labels.append(f"{symbol}{suffix}")
        return np.column_stack(out), labels

    def to_frame(self) -> pd.DataFrame:
        """The posterior samples as SI values, one column per key, and their log-probability."""
        import pandas as pd

        frame = pd.DataFrame(np.exp(self.chain), columns=list(self.keys))
        frame["log_prob"] = self.log_prob
        return with_units(frame)

    def as_dict(self) -> dict[str, Any]:
        return {
            "parameters": {e.key: e.as_dict() for e in self.estimates},
            "critical_velocity": self.critical_velocity.as_dict(),
            "critical_stress": self.critical_stress.as_dict(),
            "priors": list(self.priors),
            "noise": self.noise,
            "walkers": self.walkers,
            "steps": self.steps,
            "burn": self.burn,
            "thin": self.thin,
            "samples": int(self.chain.shape[0]),
            "acceptance_fraction": self.acceptance,
            "autocorrelation_time": self.autocorrelation.tolist(),
            "converged": self.converged,
            "messages": list(self.messages),
        }

    def report(self) -> str:
        """A Markdown report of the posterior (the fit's report helpers, :mod:`stickslip.fitting.report`)."""
        from .report import _g, _messages, _table, estimate_rows

        rows = estimate_rows((*self.estimates, self.critical_velocity, self.critical_stress), with_key=False)
        lines = [
            "# Bayesian steady fit (emcee)",
            "",
            f"- data: `{self.data.source}`, {len(self.data)} points; noise: {self.noise}",
            f"- sampler: {self.walkers} walkers × {self.steps} steps, first {self.burn} discarded, thinned by"
            f" {self.thin}; {self.chain.shape[0]} samples; mean acceptance {self.acceptance:.2f}",
            f"- autocorrelation time (steps): {', '.join(_g(t, 3) for t in self.autocorrelation)}",
            f"- convergence: {self._convergence()}",
            "",
            "## Priors",
            "",
            *[f"- {p}" for p in self.priors],
            "",
            *_messages(self.messages),
            "## Posterior (median and central 95 % credible interval)",
            "",
            *_table(["quantity", "median", "std. dev.", "95 % credible interval", "unit", "prior / note"], rows),
            "",
        ]
        return "\n".join(lines)

    def _convergence(self) -> str:
        tau = float(max(self.autocorrelation))
        times = f"{(self.steps - self.burn) / tau:.0f}" if 0 < tau < float("inf") else "no measurable number of"
        verdict = "passed" if self.converged else "NOT CONVERGED"
        return f"{verdict}: {times} autocorrelation times after burn-in (the check asks for {CONVERGED_TIMES})"

    def plot(self, ax: Axes | None = None) -> Axes:
        """The fit with the 95 % credible band of sigma(V)."""
        from ..plots.fits import plot_steady_fit

        return plot_steady_fit(self.fit, ax=ax, band=self.stress_band())


class _LogPosterior:
    """Vectorised over walkers: rows of ln-parameters -> log posterior (uniform prior in the box)."""

    def __init__(self, fit: SteadyFit, keys: tuple[str, ...]) -> None:
        self.space = Space(fit.parameters, keys)
        centre = Space(fit.start, keys).vector()
        self.lower, self.upper = centre - SEARCH_BOX, centre + SEARCH_BOX
        data = fit.data
        self.points = len(data)
        # stated errors found too small by the fit: their scale is unknown, integrated out as the relative noise's
        self.stated = data.stress_err is not None and not fit.stated_errors_scaled
        error = data.stress_err if data.stress_err is not None else data.stress
        # all points with aging; a long record compressed exactly (stickslip.fitting.problem.Block)
        self.block = make_block(data.velocity, data.stress, error, True, fit.parameters)

    def mode(self) -> tuple[np.ndarray, np.ndarray]:
        """The maximum of the likelihood over the sampled keys, from the fit, and its Gauss-Newton covariance
        (the centre and shape of the independence proposal; for two-step fits these differ from the fit's)."""
        best = minimize(self.space, self.space.vector(), self.block)
        jac = jacobian(Space(self.space.params(best.theta), self.space.keys), best.theta, self.block)
        scale = 1.0 if self.stated else best.chi_square / max(self.points - len(self.space.keys), 1)
        return best.theta, scale * np.linalg.pinv(jac.T @ jac)

    def __call__(self, thetas: np.ndarray) -> np.ndarray:
        out = np.full(thetas.shape[0], -np.inf)
        inside = np.all((thetas >= self.lower) & (thetas <= self.upper), axis=1)
        rows = np.nonzero(inside)[0]
        if rows.size == 0:
            return out
        sets = []
        for k in rows:
            try:
                sets.append(self.space.params(thetas[k]))
            except ParameterError:  # exp overflow cannot happen inside the box, but be safe
                sets.append(None)
        good = [k for k, p in zip(rows, sets, strict=True) if p is not None]
        stress = stress_many([p for p in sets if p is not None], self.block.eval_points, aging=True)
        r = self.block.residuals_of(stress)
        chi = np.sum(r * r, axis=1) + self.block.offset
        finite = np.isfinite(chi)
        good_rows = np.asarray(good)[finite]
        chi = chi[finite]
        out[good_rows] = -0.5 * chi if self.stated else -0.5 * self.points * np.log(chi)
        return out


def _unbounded(log_post: _LogPosterior, centre: np.ndarray) -> list[str]:
    """Keys the data do not bound on one side: with the key at the prior's edge and the others refitted, the log
    posterior is within UNBOUNDED_DROP of its peak (a plateau reaching the edge, which the chain may barely have
    entered and its convergence check cannot see)."""
    peak = float(log_post(centre[None, :])[0])
    keys = log_post.space.keys
    notes = []
    for i, key in enumerate(keys):
        others = tuple(k for k in keys if k != key)
        for edge, side in ((log_post.lower[i], "below"), (log_post.upper[i], "above")):
            theta = centre.copy()
            theta[i] = edge
            try:
                space = Space(log_post.space.params(theta), others)
                best = minimize(space, space.vector(), log_post.block)
            except StickslipError:
                continue
            at_edge = -0.5 * best.chi_square if log_post.stated else -0.5 * log_post.points * math.log(best.chi_square)
            if math.isfinite(at_edge) and peak - at_edge < UNBOUNDED_DROP:
                notes.append(
                    f"{key}: the data do not bound it {side}: at the prior's edge ({math.exp(edge):.3g} SI), with the"
                    f" other parameters refitted, the log posterior is only {peak - at_edge:.2g} below its peak;"
                    f" its posterior {side} the peak is set by the prior's box, not by the data"
                )
    return notes


class _Independence:
    """Independence proposal q(x): multivariate t around the least-squares estimate (see module docstring)."""

    def __init__(self, centre: np.ndarray, covariance: np.ndarray) -> None:
        self.centre = centre
        self.chol = np.linalg.cholesky(PROPOSAL_SCALE**2 * covariance)

    def log_q(self, x: np.ndarray) -> np.ndarray:
        z = np.linalg.solve(self.chol, (x - self.centre).T)
        return -0.5 * (PROPOSAL_DOF + self.centre.size) * np.log1p(np.sum(z * z, axis=0) / PROPOSAL_DOF)

    def __call__(self, x0: np.ndarray, random: np.random.RandomState) -> tuple[np.ndarray, np.ndarray]:
        count, dim = x0.shape
        z = random.standard_normal((count, dim))
        w = np.sqrt(PROPOSAL_DOF / random.chisquare(PROPOSAL_DOF, size=count))
        x = self.centre + (z @ self.chol.T) * w[:, None]
        return x, self.log_q(x0) - self.log_q(x)  # log q(x0)/q(x): the Hastings factor


class _Kernels:
    """Gaussian kernel density estimate with Scott's bandwidth, as scipy's gaussian_kde, but with the samples
    whitened once: gaussian_kde.logpdf re-whitens all of them at every call (most of the sampler's time)."""

    def __init__(self, samples: np.ndarray) -> None:
        count, dim = samples.shape
        factor = count ** (-1.0 / (dim + 4))  # Scott's rule
        self.chol = np.linalg.cholesky(factor**2 * np.cov(samples.T))
        self.white = np.linalg.solve(self.chol, samples.T).T  # (count, dim)
        self.samples = samples
        self.norm = -math.log(count) - 0.5 * dim * math.log(2 * math.pi) - float(np.sum(np.log(np.diag(self.chol))))

    def log_density(self, x: np.ndarray) -> np.ndarray:
        z = np.linalg.solve(self.chol, x.T).T  # (points, dim)
        squared = np.sum((z[:, None, :] - self.white[None, :, :]) ** 2, axis=2)
        # log-sum-exp of -squared/2 over the kernels, each row shifted by its nearest kernel (every term finite;
        # scipy's logsumexp, which also handles infinities and signs, took half the proposal's time)
        nearest = squared.min(axis=1)
        return -0.5 * nearest + np.log(np.sum(np.exp(-0.5 * (squared - nearest[:, None])), axis=1)) + self.norm

    def draw(self, count: int, random: np.random.RandomState) -> np.ndarray:
        centres = self.samples[random.randint(self.samples.shape[0], size=count)]
        return centres + random.standard_normal(centres.shape) @ self.chol.T


class _Fitted:
    """Independence proposal fitted to pilot samples: q = (1 - w) KDE(pilot) + w t(pilot mean, scaled covariance).

    The kernel density estimate follows the skewed, curved posteriors that a single Gaussian misses (the
    acceptance rises and the autocorrelation time falls several-fold on hard data); the defensive t keeps the
    proposal's tails heavier than the posterior's, so that the independence sampler stays uniformly ergodic.
    Fixed once built, so the main run is an exact Metropolis-Hastings chain (the pilots are burn-in).
    """

    def __init__(self, samples: np.ndarray) -> None:
        self.kde = _Kernels(samples)
        self.tail = _Independence(samples.mean(axis=0), DEFENSIVE_SCALE**2 * np.cov(samples.T))
        dim = samples.shape[1]
        # normalising constant of the t (log_q of _Independence leaves it out), to mix it with the KDE's density
        self.tail_norm = (
            math.lgamma((PROPOSAL_DOF + dim) / 2)
            - math.lgamma(PROPOSAL_DOF / 2)
            - 0.5 * dim * math.log(PROPOSAL_DOF * math.pi)
            - float(np.sum(np.log(np.diag(self.tail.chol))))
        )

    def log_q(self, x: np.ndarray) -> np.ndarray:
        kde = self.kde.log_density(x) + math.log1p(-DEFENSIVE_WEIGHT)
        tail = self.tail.log_q(x) + self.tail_norm + math.log(DEFENSIVE_WEIGHT)
        return np.logaddexp(kde, tail)

    def __call__(self, x0: np.ndarray, random: np.random.RandomState) -> tuple[np.ndarray, np.ndarray]:
        count, _ = x0.shape
        from_tail = random.uniform(size=count) < DEFENSIVE_WEIGHT
        x = self.kde.draw(count, random)
        if np.any(from_tail):
            x[from_tail] = self.tail(x0[from_tail], random)[0]
        return x, self.log_q(x0) - self.log_q(x)


def _fitted_moves(emcee: Any, samples: np.ndarray, fallback: Any) -> Any:
    """The main run's moves: the fitted proposal and differential evolution (``fallback`` if it cannot be built)."""
    try:
        proposal = _Fitted(samples)
    except (np.linalg.LinAlgError, ValueError):  # a degenerate pilot (walkers that never moved)
        return fallback
    return [(emcee.moves.MHMove(proposal), FITTED_WEIGHT), (emcee.moves.DEMove(), 1.0 - FITTED_WEIGHT)]


def _moves(emcee: Any, centre: np.ndarray, covariance: np.ndarray) -> Any:
    """Half independence proposals, half differential-evolution moves (see the module docstring)."""
    evolution = emcee.moves.DEMove()
    try:
        proposal = _Independence(centre, covariance) if np.all(np.isfinite(covariance)) else None
    except np.linalg.LinAlgError:
        proposal = None
    if proposal is None:
        return [(evolution, 0.8), (emcee.moves.DESnookerMove(), 0.2)]
    return [(emcee.moves.MHMove(proposal), INDEPENDENCE_WEIGHT), (evolution, 1.0 - INDEPENDENCE_WEIGHT)]


def _autocorrelation(sampler: Any, burn: int) -> np.ndarray:
    """Integrated autocorrelation time of each parameter (steps) after ``burn``; infinite for a parameter in
    which some walker has not moved at all since then (emcee would divide by its zero variance, and such a
    chain has not converged)."""
    from emcee.autocorr import integrated_time

    chain = sampler.get_chain(discard=burn)  # (steps, walkers, parameters)
    out = np.full(chain.shape[2], np.inf)
    for k in range(chain.shape[2]):
        values = chain[:, :, k]
        if np.all(np.ptp(values, axis=0) > 0):
            out[k] = float(integrated_time(values[:, :, None], tol=0)[0])
    return out


def _pilot(emcee: Any, make: Any, moves: Any, start: np.ndarray, bar: Silent) -> tuple[Any, np.ndarray, int]:
    """Burn-in in rounds: the mixture of moves first, then the fitted proposal, refitted after each round to the
    round's samples (each round reaches further into the posterior than the last, and the proposal follows).
    Returns (the last round's moves fitted to its samples, the walkers' positions, steps run)."""
    state, total = start, 0
    for k, steps in enumerate(PILOT_STEPS):
        sampler = make(moves)
        state = sampler.run_mcmc(state, steps)
        total += steps
        bar.update(total, note="burn-in: fitting the proposal")
        samples = sampler.get_chain(discard=steps // 2 if k == 0 else 0, flat=True)
        moves = _fitted_moves(emcee, samples, moves)
    return moves, state.coords, total


def _run(
    sampler: Any, start: np.ndarray, steps: int | None, burn: int | None, max_steps: int, offset: int, bar: Silent
) -> tuple[int, int]:
    """Run the chain: ``steps`` steps, or by default until the convergence check passes (at most
    ``max_steps`` in all, ``offset`` of them already run as pilots).  Returns (steps run here, burn-in here)."""
    if steps is not None:
        for done in range(0, steps, CHUNK_STEPS):
            start = sampler.run_mcmc(start, min(CHUNK_STEPS, steps - done))
            bar.update(min(done + CHUNK_STEPS, steps), total=steps)
        return steps, steps // 4 if burn is None else burn
    state, total = start, 0
    while True:
        state = sampler.run_mcmc(state, CHUNK_STEPS)
        total += CHUNK_STEPS
        tau = float(np.max(_autocorrelation(sampler, 0)))
        chosen = (math.ceil(BURN_TIMES * tau) if math.isfinite(tau) else total // 4) if burn is None else burn
        chosen = min(chosen, total // 2)
        tau = float(np.max(_autocorrelation(sampler, chosen)))
        needed = chosen + CONVERGED_TIMES * tau if math.isfinite(tau) else float(max_steps)
        bar.update(offset + total, total=min(offset + max(needed, total), max_steps), note=f"τ ≈ {tau:.3g} steps")
        done = math.isfinite(tau) and total - chosen >= CONVERGED_TIMES * tau
        if (done and offset + total >= MIN_STEPS) or offset + total >= max_steps:
            return total, chosen


def sample_posterior(
    fit: SteadyFit,
    walkers: int | None = None,
    steps: int | None = None,
    burn: int | None = None,
    thin: int | None = None,
    seed: int | None = None,
    critical_draws: int = CRITICAL_DRAWS,
    max_steps: int = MAX_STEPS,
    progress: bool | None = None,
) -> SteadyPosterior:
    """Sample the posterior of the fit's free parameters with emcee (module docstring for the priors).

    ``walkers=None`` is max(16, 4 x the sampled keys); ``steps=None`` runs until the convergence check
    passes (at most ``max_steps``, pilots included); ``burn=None`` is 5 autocorrelation times (a quarter of a
    fixed ``steps``).  ``progress``: a bar on standard error (None: only when it is a terminal).
    """
    emcee = _emcee()
    keys = tuple(fit.free_keys)
    if not keys:
        raise ParameterError("nothing to sample: the fit has no free parameters")
    walkers = max(16, 4 * len(keys)) if walkers is None else walkers
    if walkers < 2 * len(keys):
        raise ParameterError(f"walkers: need at least {2 * len(keys)} for {len(keys)} parameters, got {walkers}")
    if steps is not None and steps < 10:
        raise ParameterError(f"steps: expected at least 10, got {steps}")
    if max_steps < MIN_STEPS:
        raise ParameterError(f"max_steps: expected at least {MIN_STEPS}, got {max_steps}")
    if burn is not None and not 0 <= burn < (steps if steps is not None else max_steps):
        raise ParameterError(f"burn: expected 0 <= burn < steps, got {burn}")
    rng = np.random.default_rng(seed)
    log_post = _LogPosterior(fit, keys)
    centre, covariance = log_post.mode()
    sd = np.sqrt(np.clip(np.diag(covariance), 1e-8, 1.0))
    start = centre + 0.05 * sd * rng.standard_normal((walkers, len(keys)))
    moves = _moves(emcee, centre, covariance)
    sampler = emcee.EnsembleSampler(walkers, len(keys), log_post, vectorize=True, moves=moves)
    seeds = rng.integers(2**31, size=2)
    sampler.random_state = np.random.RandomState(int(seeds[0])).get_state()
    automatic = steps is None
    with progress_bar("posterior (emcee)", total=steps or max_steps, unit="steps", enabled=progress) as bar:
        pilot = 0
        if automatic and max_steps >= 4 * sum(PILOT_STEPS):  # (a short cap runs the mixture of moves alone)

            def make(chosen: Any) -> Any:
                made = emcee.EnsembleSampler(walkers, len(keys), log_post, vectorize=True, moves=chosen)
                made.random_state = np.random.RandomState(random.randint(2**31)).get_state()
                return made

            random = np.random.RandomState(int(seeds[1]))
            fitted, start, pilot = _pilot(emcee, make, moves, start, bar)
            sampler = make(fitted)
        steps, burn = _run(sampler, start, steps, burn, max_steps, pilot, bar)
    tau = _autocorrelation(sampler, burn)
    steps, burn = steps + pilot, burn + pilot  # the pilots are burn-in
    messages = []
    if not np.all(np.isfinite(tau)):
        messages.append(
            f"NOT CONVERGED: some walkers did not move in the {steps - burn} steps after burn-in; the posterior"
            " summaries are unreliable; run more --steps or check the fit"
        )
    elif np.any(steps - burn < CONVERGED_TIMES * tau):
        stopped = (
            f"stopped at the limit of {max_steps} steps" if automatic else f"the chain has the {steps} steps asked"
        )
        messages.append(
            f"NOT CONVERGED: {stopped}, shorter than {CONVERGED_TIMES} autocorrelation times (τ up to"
            f" {np.nanmax(tau):.3g} steps after {burn} burn-in steps): the posterior summaries are rough; run more"
            " --steps"
        )
    converged = not messages
    messages += _unbounded(log_post, centre)
    finite = tau[np.isfinite(tau)]
    thin = (max(1, int(finite.min() / 2)) if finite.size else 1) if thin is None else thin
    chain = sampler.get_chain(discard=burn - pilot, thin=thin, flat=True)
    log_prob = sampler.get_log_prob(discard=burn - pilot, thin=thin, flat=True)
    estimates = _parameter_summaries(fit, keys, chain)
    vc, sc, critical = _critical_summaries(fit, keys, chain, critical_draws, rng, messages)
    priors = tuple(
        f"{k}: uniform in ln on [{math.exp(lo):.4g}, {math.exp(hi):.4g}] (SI; a factor 1e4 either side of"
        " the start value)"
        for k, lo, hi in zip(keys, log_post.lower, log_post.upper, strict=True)
    )
    if fit.stated_errors_scaled:
        noise = "Gaussian, the stated stress_err (too small) times an unknown s (Jeffreys prior 1/s, integrated out)"
    elif fit.data.stress_err is not None:
        noise = "Gaussian with the stated stress_err"
    else:
        noise = "Gaussian, relative error s·σ with unknown s (Jeffreys prior 1/s, integrated out)"
    held = [e.key for e in fit.estimates if e.fixed]
    priors += (f"held fixed as in the least-squares fit: {', '.join(held)}",)
    return SteadyPosterior(
        fit=fit,
        keys=keys,
        chain=chain,
        log_prob=log_prob,
        walkers=walkers,
        steps=steps,
        burn=burn,
        thin=thin,
        acceptance=float(np.mean(sampler.acceptance_fraction)),
        autocorrelation=tau,
        priors=priors,
        noise=noise,
        estimates=estimates,
        critical_velocity=vc,
        critical_stress=sc,
        critical_samples=critical,
        messages=tuple(messages),
        converged=converged,
    )


def _summary(key: str, symbol: str, dimension: str, values: np.ndarray, note: str = "") -> Estimate:
    lo, median, hi = np.quantile(values, [0.025, 0.5, 0.975])
    return Estimate(
        key, symbol, dimension, float(median), float(np.std(values, ddof=1)), (float(lo), float(hi)), "posterior", note
    )


def _parameter_summaries(fit: SteadyFit, keys: tuple[str, ...], chain: np.ndarray) -> tuple[Estimate, ...]:
    return tuple(
        _summary(k, identify.SYMBOLS.get(k, k), key_dimension(k), np.exp(chain[:, i]), "log-uniform prior")
        for i, k in enumerate(keys)
    )


def _critical_summaries(
    fit: SteadyFit,
    keys: tuple[str, ...],
    chain: np.ndarray,
    draws: int,
    rng: np.random.Generator,
    messages: list[str],
) -> tuple[Estimate, Estimate, np.ndarray]:
    guess = fit.critical_velocity.value
    space = Space(fit.parameters, keys)
    found = np.zeros((0, 2))
    if guess is not None:
        picks = rng.choice(chain.shape[0], size=min(draws, chain.shape[0]), replace=False)
        located = critical_many([space.params(chain[k]) for k in picks], guess)
        found = located[np.all(np.isfinite(located), axis=1)]
    missing = min(draws, chain.shape[0]) - len(found)
    if guess is None or len(found) < 10:
        # the least-squares fit's own reason where it gave no Vc (no minimum, or one the data do not determine)
        note = (
            fit.critical_velocity.note
            if guess is None and fit.critical_velocity.note
            else ("too few posterior samples have a minimum of σ(V)")
        )
        messages.append(note)
        return (*undetermined_critical(note), np.zeros((0, 2)))
    note = f"posterior of {len(found)} random samples"
    if missing:
        note += f" ({missing} without a minimum left out)"
    return _summary(*CRITICAL[0], found[:, 0], note), _summary(*CRITICAL[1], found[:, 1], note), found
