"""The noise of a steady curve estimated without the model: the scatter between neighbouring points.

The pseudo-residuals of Gasser, Sroka and Jennen-Steinmetz (each interior point against the straight line
through its two neighbours in ln V), with Satterthwaite degrees of freedom, so the steady fit's tests do not
take the noise from a fit that may have ended far from the data (docs/fitting.md).  Repeated velocities add their
contrasts against each other (pure noise).  Whether the stress depends on velocity at all is asked of the data
alone too: a polynomial trend in ln V (:func:`trend_dependence`) and, with repeats, the analysis of variance
(:func:`replicate_dependence`), neither of which depends on where a model fit landed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

#: Smallest relative scatter taken as real: the model itself is accurate to ~1e-9, and an exact power law has
#: zero pseudo-residuals; below this the noise is "not measurable" and the floor is used.
SCATTER_FLOOR = 1e-6
#: p below this: a difference the noise does not explain (misfit, or a velocity dependence).
SIGNIFICANCE = 1e-3


@dataclass(frozen=True)
class Scatter:
    """Noise variance (``variance``, in units of the stated errors, or relative when none are stated) and its
    effective degrees of freedom, from neighbouring points; ``relative`` says which, ``of_residuals`` whether it
    was measured on the data or on a fit's residuals (:func:`residual_scatter`).  ``replicates``: how many of the
    contrasts are between points at one velocity (repeated measurements: pure noise, no bend of the curve)."""

    variance: float
    dof: float
    relative: bool
    points: int
    of_residuals: bool = False
    replicates: int = 0

    @property
    def scale(self) -> float:
        return math.sqrt(self.variance)

    def describe(self) -> str:
        size = f"{100 * self.scale:.3g} % of the stress" if self.relative else f"{self.scale:.3g} stated errors"
        what = (
            "each residual about the line through its neighbours' residuals"
            if self.of_residuals
            else "each point about the line through its neighbours"
        )
        if self.replicates:
            what = f"{self.replicates} repeated measurement(s) against the others at their velocity, and {what}"
        return f"{size} (scatter of {what}, ≈{self.dof:.3g} degrees of freedom)"


def local_scatter(velocity: np.ndarray, stress: np.ndarray, stress_err: np.ndarray | None) -> Scatter:
    """The scatter of the data about the line through each point's neighbours (module docstring)."""
    relative = stress_err is None
    values = np.log(stress) if relative else stress / 1.0
    return _neighbour_scatter(velocity, values, stress, stress_err, of_residuals=False)


def residual_scatter(
    velocity: np.ndarray, stress: np.ndarray, stress_err: np.ndarray | None, model: np.ndarray
) -> Scatter:
    """The scatter of a fit's residuals about the line through each point's neighbours' residuals.

    The data's own pseudo-residuals (:func:`local_scatter`) count the curve's bend between neighbours as noise:
    on 20 exact points of the gelatin-glass curve from 20 µm/s to 3 mm/s, 5.8 times a 2 % error, so a model that
    misses the data by 27 times their stated errors passed the F test against it.  A fit's residuals have the
    model's bend taken out; what a second difference of them still finds is the noise, and the part of a misfit
    that changes within three neighbouring points (the smooth rest of a misfit cancels).  Relative residuals
    (data − fit)/data when no errors are stated (≈ the difference of the logarithms the data's scatter uses)."""
    relative = stress_err is None
    values = (stress - model) / stress if relative else stress - model
    return _neighbour_scatter(velocity, values, stress, stress_err, of_residuals=True)


def _neighbour_scatter(
    velocity: np.ndarray,
    values: np.ndarray,
    stress: np.ndarray,
    stress_err: np.ndarray | None,
    of_residuals: bool,
) -> Scatter:
    """Gasser-Sroka-Jennen-Steinmetz pseudo-residuals of ``values`` in ln V, in units of the errors (1 when none
    are stated: ``values`` are then relative), with Satterthwaite degrees of freedom.  Points at one velocity
    (replicates) add their contrasts against each other and enter the neighbours' lines by their mean
    (:func:`_contrasts`)."""
    order = np.argsort(velocity, kind="stable")
    x = np.log(velocity[order])
    relative = stress_err is None
    y = values[order]
    e = np.ones_like(y) if relative else stress_err[order]  # type: ignore[index]
    n = x.size
    starts = _velocity_groups(x)
    rows = n - 2 if starts.size >= 3 else n - starts.size
    if rows < 1:
        return Scatter(math.inf, 0.0, relative, n, of_residuals)
    pseudo = _contrasts(x, y, e, starts)
    variance = float(pseudo @ pseudo) / rows
    # Satterthwaite: s^2 = z^T B^T B z/rows, tr(B^T B) = rows, tr((B^T B)^2) = |B B^T|_F^2: the replicates' contrasts
    # are orthonormal and orthogonal to the means (an identity block), the neighbours' rows have 3 diagonals
    square_trace = float(n - starts.size)
    if starts.size >= 3:
        c0, c1, c2 = _pseudo_rows(*_group_means(x, e, starts)[::2])
        off1 = c1[:-1] * c0[1:] + c2[:-1] * c1[1:]
        off2 = c2[:-2] * c0[2:]
        square_trace += float(np.sum((c0**2 + c1**2 + c2**2) ** 2) + 2 * off1 @ off1 + 2 * off2 @ off2)
    dof = rows**2 / square_trace
    floor = SCATTER_FLOOR**2 if relative else (SCATTER_FLOOR * float(np.median(stress / stress_err))) ** 2
    return Scatter(max(variance, floor), dof, relative, n, of_residuals, n - starts.size)


#: ln V closer than this are one velocity: their points are replicates (as the reader's duplicate tolerance).
SAME_VELOCITY = 1e-9


def _velocity_groups(x: np.ndarray) -> np.ndarray:
    """The first index of each run of one velocity in sorted ``x`` (ln V)."""
    return np.flatnonzero(np.r_[True, np.diff(x) > SAME_VELOCITY])


def _group_means(
    x: np.ndarray, e: np.ndarray, starts: np.ndarray, y: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray | None, np.ndarray]:
    """(ln V, weighted mean of ``y`` (None without ``y``), its error) of each velocity's points."""
    w = 1.0 / e**2
    total = np.add.reduceat(w, starts)
    mean = None
    if y is not None:
        tail = (1,) * (y.ndim - 1)
        mean = np.add.reduceat(w.reshape((-1, *tail)) * y, starts, axis=0) / total.reshape((-1, *tail))
    return x[starts], mean, 1.0 / np.sqrt(total)


def _contrasts(x: np.ndarray, y: np.ndarray, e: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """The unit-variance contrasts of ``y`` (sorted by ``x`` = ln V, errors ``e``; a trailing axis of draws
    allowed): each repeated point against the weighted mean of those before it at its velocity (Helmert: pure
    noise, independent of each other and of the means), then each velocity's mean against the straight line through
    its neighbours' (:func:`_pseudo_rows`).  Without repeated velocities, exactly the neighbours' pseudo-residuals."""
    n = x.size
    shape = y.shape[1:]

    def col(a: np.ndarray) -> np.ndarray:  # a per-point factor, broadcast over the draws
        return a.reshape((-1, *(1,) * len(shape)))

    parts = []
    if starts.size < n:
        w = 1.0 / e**2
        first = starts[np.cumsum(np.isin(np.arange(n), starts)) - 1]  # the first point at each point's velocity
        later = np.flatnonzero(np.arange(n) != first)  # every point but the first at its velocity
        cum_w = np.r_[0.0, np.cumsum(w)]
        cum_wy = np.concatenate((np.zeros((1, *shape)), np.cumsum(col(w) * y, axis=0)), axis=0)
        prev_w = cum_w[later] - cum_w[first[later]]  # the points before it at its velocity
        prev_mean = (cum_wy[later] - cum_wy[first[later]]) / col(prev_w)
        parts.append((y[later] - prev_mean) / col(np.sqrt(e[later] ** 2 + 1.0 / prev_w)))
    if starts.size >= 3:
        xg, mean, eg = _group_means(x, e, starts, y)
        c0, c1, c2 = (col(c / g) for c, g in zip(_pseudo_rows(xg, eg), (eg[:-2], eg[1:-1], eg[2:]), strict=True))
        parts.append(c0 * mean[:-2] + c1 * mean[1:-1] + c2 * mean[2:])
    return np.concatenate(parts, axis=0) if parts else np.zeros((0, *shape))


def _pseudo_rows(x: np.ndarray, e: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The three diagonals of B: row i takes point i+1 less the straight line through points i and i+2 (in
    ``x`` = ln V), in units of standard noise (``e``: the errors), scaled to unit variance."""
    h_left, h_right = x[1:-1] - x[:-2], x[2:] - x[1:-1]
    w_left, w_right = h_right / (h_left + h_right), h_left / (h_left + h_right)
    sd = np.sqrt(e[1:-1] ** 2 + (w_left * e[:-2]) ** 2 + (w_right * e[2:]) ** 2)
    return -w_left * e[:-2] / sd, e[1:-1] / sd, -w_right * e[2:] / sd


def replicate_scatter(velocity: np.ndarray, stress: np.ndarray, stress_err: np.ndarray | None) -> Scatter | None:
    """The scatter of repeated measurements at one velocity alone (pure error: no model, no bend), relative (of
    ln σ) or in units of the stated errors; None without repeated velocities."""
    order = np.argsort(velocity, kind="stable")
    x = np.log(velocity[order])
    starts = _velocity_groups(x)
    n = x.size
    if starts.size == n:
        return None
    relative = stress_err is None
    y = np.log(stress[order]) if relative else stress[order]
    e = np.ones(n) if relative else stress_err[order]  # type: ignore[index]
    pseudo = _contrasts(x, y, e, starts)[: n - starts.size]
    variance = float(pseudo @ pseudo) / (n - starts.size)
    return Scatter(variance, float(n - starts.size), relative, n, False, n - starts.size)


#: Draws of the misfit ratio under pure noise (:func:`misfit_p_value`); p below 1/DRAWS reads as 1/DRAWS.
DRAWS = 10_000
#: Above this many points the ratio's null distribution is taken as normal (its moments below) instead of drawn.
DRAWN_POINTS = 400


def misfit_p_value(velocity: np.ndarray, stress_err: np.ndarray | None, ratio: float, scatter: Scatter) -> float:
    """p of a fit's misfit ratio (residual variance over the scatter of the same residuals between neighbours,
    :func:`residual_scatter`) under pure noise.

    Both variances come from the same residuals, so they rise and fall together: the ratio spreads far less than
    an F ratio of independent estimates (variance ≈ 2/ν − 2/n against 2/ν + 2/n, ν the scatter's Satterthwaite
    degrees of freedom), and an F test with those degrees of freedom is blind to a misfit of several times the
    noise on twenty points (p = 0.002 for a curve 5.8 times its 1 % errors away from the model, in a wave the
    neighbours half see).  The distribution is drawn (a fixed seed: the same data give the same p) with the
    residuals taken as the noise itself, the fit's few parameters neglected; its normal limit above
    ``DRAWN_POINTS`` points."""
    n = velocity.size
    if n < 4 or not math.isfinite(ratio) or scatter.variance <= 0.0:
        return 1.0
    order = np.argsort(velocity, kind="stable")
    e = np.ones(n) if stress_err is None else stress_err[order]
    if n > DRAWN_POINTS:
        sd = math.sqrt(max(2.0 / scatter.dof - 2.0 / n, 2.0 / n**2)) if scatter.dof > 0 else math.inf
        return float(stats.norm.sf((ratio - 1.0) / sd))
    null = _null_ratios(np.log(velocity[order]), e)
    above = DRAWS - int(np.searchsorted(null, ratio, side="left"))
    return float((1 + above) / (1 + DRAWS))


_NULLS: dict[bytes, np.ndarray] = {}


def _null_ratios(x: np.ndarray, e: np.ndarray) -> np.ndarray:
    """The misfit ratio's draws under pure noise for these velocities (``x`` = ln V, sorted) and errors, sorted
    (one fit asks several times for the same points: remembered for the last few sets)."""
    key = np.concatenate((x, e)).tobytes()
    if key not in _NULLS:
        n = x.size
        starts = _velocity_groups(x)
        rows = n - 2 if starts.size >= 3 else n - starts.size
        z = np.random.default_rng(20261130).standard_normal((DRAWS, n))
        pseudo = _contrasts(x, (z * e).T, e, starts)
        null = (np.einsum("ij,ij->i", z, z) / n) / (np.einsum("ij,ij->j", pseudo, pseudo) / max(rows, 1))
        if len(_NULLS) >= 8:
            _NULLS.pop(next(iter(_NULLS)))
        _NULLS[key] = np.sort(null)
    return _NULLS[key]


#: Robust standard deviations (1.4826 x the median absolute deviation) beyond which a point is named as a
#: possible outlier: the stick fit's rows (few, each a whole cycle) and the steady fit's points.
STICK_OUTLIER_SPREADS = 4.0
STEADY_OUTLIER_SPREADS = 5.0


def outlying(
    residuals: np.ndarray, spreads: float, floor: float | np.ndarray = 0.0, confirm: bool = False
) -> tuple[np.ndarray, float, float]:
    """Indices of the residuals further than ``spreads`` robust standard deviations from their median (and
    further than ``floor``, in the residuals' units, scalar or per point), that robust standard deviation and the
    median.

    The spread is 1.4826 times the median absolute deviation, which the outliers themselves barely move (the
    rms, or a chi-square, grows with them and hides them); ``floor`` keeps a curve fitted to rounding error
    from calling its largest 1e-9 an outlier.  With ``confirm`` a point so found must also be ``spreads`` times the
    rms of the points not found from the median: on 24 points of Gaussian noise the median absolute deviation
    alone is small enough, in 1 % of the sets, to name a 3.7 sigma point (the noise's own).  Fewer than 4 finite
    residuals: none."""
    r = np.asarray(residuals, dtype=float)
    if r.size < 4 or not np.all(np.isfinite(r)):
        return np.zeros(0, dtype=int), math.nan, math.nan
    centre = float(np.median(r))
    spread = 1.4826 * float(np.median(np.abs(r - centre)))
    far = np.abs(r - centre) > np.maximum(spreads * spread, floor)
    if confirm and far.any() and (~far).sum() >= 2:
        rms = float(np.sqrt(np.mean((r[~far] - centre) ** 2)))
        far &= np.abs(r - centre) > spreads * rms
    return np.flatnonzero(far), spread, centre


@dataclass(frozen=True)
class Dependence:
    """Whether the stress varies with velocity by more than its noise."""

    p_value: float
    spread: float  # rms of ln(stress) about its mean (relative) or of (stress - mean)/error
    significant: bool
    text: str
    #: p of the test against the scatter between neighbours alone, and the polynomial trend test (None: not made)
    neighbours_p: float = math.nan
    trend: Trend | None = None
    #: the tests of the data alone besides the neighbours' (the trend, the repeated measurements), in words
    others: str = ""


#: Highest degree of the polynomials in ln V of :func:`trend_dependence`.
TREND_DEGREE = 3


@dataclass(frozen=True)
class Trend:
    """A polynomial in ln V against a constant (:func:`trend_dependence`)."""

    p_value: float  # Bonferroni-corrected over the degrees tried
    degree: int  # the degree with the smallest p (0: no test was possible)
    degrees: int  # how many degrees were tried
    smallest: float = math.nan  # the smallest p of the degrees tried, before the correction

    def describe(self) -> str:
        """In words, with the threshold and the correction that decide ("p = 0.035 against 0.05/3" left the reader
        to guess both: the threshold is ``SIGNIFICANCE``, and the correction multiplies the smallest p)."""
        if not self.degrees:
            return "too few velocities for a polynomial in ln V"
        verdict = "significant" if self.p_value <= SIGNIFICANCE else "not significant"
        if self.degrees == 1:
            return (
                f"a polynomial in ln V of degree 1 (a straight line) against a constant (F test against its own"
                f" residuals): p = {self.p_value:.2g},"
                f" {verdict} at the threshold p ≤ {SIGNIFICANCE:g}"
            )
        raw = "" if not math.isfinite(self.smallest) else f": {self.degrees} × {self.smallest:.2g}"
        if self.degrees * self.smallest > 1.0:
            raw += ", capped at 1"
        return (
            f"a polynomial in ln V (degrees 1 to {self.degrees} tried) against a constant (nested F tests against its"
            f" own residuals; smallest p at degree {self.degree}): p = {self.p_value:.2g} after the Bonferroni"
            f" correction for the {self.degrees} degrees tried (the smallest p times {self.degrees}{raw}), {verdict}"
            f" at the threshold p ≤ {SIGNIFICANCE:g}"
        )


def trend_dependence(velocity: np.ndarray, stress: np.ndarray, stress_err: np.ndarray | None) -> Trend:
    """p of "the stress is constant" against a polynomial trend of ln σ in ln V, from the data alone.

    For each degree d = 1 … ``TREND_DEGREE`` (fewer where the points leave the noise under 2 degrees of freedom, or
    the velocities are fewer than d + 1) the nested F test of the constant within the least-squares polynomial,
    F(d, n − d − 1), its noise the polynomial's own residuals (weighted by (σ/stress_err)² with stated errors,
    whose scale does not enter); the smallest p times the number of degrees tried (Bonferroni).  Exact for Gaussian
    noise in ln σ whatever the start values of any model fit: a curve rising by a factor 3.6 over six points is
    no constant (p = 2.4e-4), while the scatter between neighbours, which counts its bend as noise, said p = 0.004.
    The model's fit is not needed to see a trend, only to see a curve a cubic cannot follow."""
    n = stress.size
    x = np.log(velocity)
    distinct = int(np.unique(np.round(x / SAME_VELOCITY)).size) if n else 0
    degrees = max(min(TREND_DEGREE, n - 3, distinct - 1), 0)
    if degrees < 1:
        return Trend(1.0, 0, 0)
    x = (x - float(np.mean(x))) / (float(np.std(x)) or 1.0)
    y = np.log(stress)
    root_w = np.ones(n) if stress_err is None else stress / stress_err
    level = float(np.sum(root_w**2 * y) / np.sum(root_w**2))
    flat = float(np.sum((root_w * (y - level)) ** 2))
    if not flat > 0.0:
        return Trend(1.0, 0, degrees)
    best, best_degree = 1.0, 1
    for d in range(1, degrees + 1):
        design = np.vander(x, d + 1) * root_w[:, None]
        coef = np.linalg.lstsq(design, root_w * y, rcond=None)[0]
        p = nested_constant_p(flat, float(np.sum((root_w * y - design @ coef) ** 2)), d, n - d - 1)
        if p < best:
            best, best_degree = p, d
    return Trend(min(1.0, degrees * best), best_degree, degrees, best)


def velocity_dependence(
    stress: np.ndarray, stress_err: np.ndarray | None, scatter: Scatter, velocity: np.ndarray | None = None
) -> Dependence:
    """Does the stress vary by more than its noise?  F test of the spread about a constant against the
    scatter between neighbours; with stated errors also the chi-square of a constant, and the larger p of
    the two (a dependence is claimed only when both noise estimates say so).  With ``velocity`` also the trend test
    (:func:`trend_dependence`): a dependence is claimed when either test finds one (each at ``SIGNIFICANCE``), so
    a curve whose bend the neighbours count as noise is not called flat.  Both use the data alone."""
    n = stress.size
    if stress_err is None:
        y = np.log(stress)
        spread2 = float(np.var(y, ddof=1))
    else:
        w = 1.0 / stress_err**2
        level = float(np.sum(w * stress) / np.sum(w))
        spread2 = float(np.sum(w * (stress - level) ** 2)) / (n - 1)
    trusted = stress_err is not None and agrees_with_stated_errors(scatter)
    p_f = p_chi = 1.0
    if spread2 > scatter.variance * 1e-12 and spread2 > 0.0 and scatter.dof > 0:
        p_f = float(stats.f.sf(spread2 / scatter.variance, n - 1, scatter.dof))
        if stress_err is not None:
            p_chi = float(stats.chi2.sf(spread2 * (n - 1), n - 1))
    # the stated errors, where the scatter between neighbours agrees with them, are the noise: the chi-square of a
    # constant against them (the F test against a scatter inflated by the curve's bend said p = 0.39 for a curve
    # varying by 28 stated errors); where it does not (errors stated too small, or the bend), both must agree
    p = p_chi if trusted else (p_f if stress_err is None else max(p_f, p_chi))
    spread = math.sqrt(spread2)
    if stress_err is None:
        size = f"{100 * (math.exp(spread) - 1):.3g} % (rms of ln σ about its mean)"
        noise = f"{100 * scatter.scale:.3g} %"
    else:
        size = f"{spread:.3g} stated errors (rms about a constant)"
        noise = f"{scatter.scale:.3g} stated errors"
    if trusted:
        test = f"χ² test against the stated errors: p = {p:.2g}"
    elif stress_err is None:
        test = f"F test: p = {p:.2g}"
    else:
        test = f"F test: p = {p_f:.2g}; χ² test against the stated errors: p = {p_chi:.2g}"
    text = f"the stress varies by {size}, against a scatter of {noise} between neighbouring points ({test})"
    trend = None
    combined = p
    others = []
    if velocity is not None and spread2 > 0.0:
        trend = trend_dependence(velocity, stress, stress_err)
        combined = min(p, trend.p_value)
        others.append(trend.describe())
        between = replicate_dependence(velocity, stress, stress_err)
        if between is not None:
            combined = min(combined, between)
            others.append(
                "the velocities' means against the scatter of the repeated measurements (one-way analysis of"
                f" variance, F test): p = {between:.2g}"
            )
    text += "".join(f"; {other}" for other in others)
    return Dependence(combined, spread, combined <= SIGNIFICANCE, text, p, trend, "; ".join(others))


def replicate_dependence(velocity: np.ndarray, stress: np.ndarray, stress_err: np.ndarray | None) -> float | None:
    """p of "the stress is constant" from repeated measurements: the one-way analysis of variance of ln σ (weights
    (σ/stress_err)² with stated errors, whose scale does not enter), the spread of the velocities' means against the
    scatter within them, F(G − 1, n − G) for n points at G velocities; exact for Gaussian noise, and blind to
    nothing a curve does between the velocities.  None without repeated velocities (or without scatter in them)."""
    order = np.argsort(velocity, kind="stable")
    x = np.log(velocity[order])
    starts = _velocity_groups(x)
    n, groups = x.size, starts.size
    if groups == n or groups < 2:
        return None
    y = np.log(stress[order])
    e = np.ones(n) if stress_err is None else (stress_err / stress)[order]
    w = 1.0 / e**2
    _, mean, _ = _group_means(x, e, starts, y)
    assert mean is not None
    sizes = np.diff(np.r_[starts, n])
    within = float(np.sum(w * (y - np.repeat(mean, sizes)) ** 2))
    level = float(np.sum(w * y) / np.sum(w))
    between = float(np.sum(np.add.reduceat(w, starts) * (mean - level) ** 2))
    if not within > 0.0:
        return None
    return float(stats.f.sf((between / (groups - 1)) / (within / (n - groups)), groups - 1, n - groups))


def agrees_with_stated_errors(scatter: Scatter) -> bool:
    """Whether a scatter in units of the stated errors is consistent with them: not significantly above 1
    (chi-square test of ν s² with its ν Satterthwaite degrees of freedom)."""
    if scatter.relative or scatter.dof <= 0:
        return False
    return float(stats.chi2.sf(scatter.dof * scatter.variance, scatter.dof)) > SIGNIFICANCE


def fitted_dependence(
    velocity: np.ndarray, stress: np.ndarray, stress_err: np.ndarray | None, model: np.ndarray
) -> tuple[float, Scatter]:
    """p of "the stress is constant" against the noise a fitted curve of the model leaves, and that noise.

    The noise is the scatter of the fit's residuals between neighbours (:func:`residual_scatter`, as in the misfit
    test): the model's bend taken out, what remains is the noise, with ν ≈ (n − 2)/1.9 degrees of freedom whatever
    the number of fitted parameters.  With stated errors that scatter agrees with (:func:`agrees_with_stated_errors`),
    the chi-square of a constant against the stated errors; otherwise the F test of the constant's spread
    (F(n − 1, ν)) against that scatter, so errors stated too small do not make noise a velocity dependence.

    The F test of the nested constant (:func:`model_dependence`) has n − k degrees of freedom for its noise: one
    for six points and the joint fit's five parameters, where a curve falling by a factor 25 and rising by 3.4 with
    2 % noise gets p = 0.014 ("no velocity dependence")."""
    n = stress.size
    scatter = residual_scatter(velocity, stress, stress_err, model)
    error = stress if stress_err is None else stress_err
    weight = 1.0 / error**2
    level = float(np.sum(weight * stress) / np.sum(weight))
    flat = float(np.sum(weight * (stress - level) ** 2))
    fitted = float(np.sum(weight * (stress - model) ** 2))
    if n < 4 or not (math.isfinite(fitted) and flat > 0.0) or fitted >= flat or scatter.dof <= 0:
        return 1.0, scatter
    if stress_err is not None and agrees_with_stated_errors(scatter):
        return float(stats.chi2.sf(flat, n - 1)), scatter
    return float(stats.f.sf(flat / (n - 1) / scatter.variance, n - 1, scatter.dof)), scatter


def model_dependence(stress: np.ndarray, stress_err: np.ndarray | None, model: np.ndarray, free: int) -> float:
    """p of "the stress is constant" against a fitted curve of the model with ``free`` parameters (a level among
    them: the site density scales the stress): the F test of a constant within it, ``free - 1`` and
    ``n - free`` degrees of freedom, its noise the fit's own residuals (relative, or in units of the stated
    errors, whose scale does not enter); 1 where no degree of freedom is left to measure the noise.

    The scatter between neighbours (:func:`velocity_dependence`) counts a curve's own bend between widely spaced
    points as noise: ten exact points of the model from 60 µm/s to 3 mm/s have a "scatter" of 18.7 %, and the
    curve with its minimum was called flat (p = 0.02).  Where that test finds no dependence, the model's own fit
    is the alternative that the bend does not fool."""
    n = stress.size
    dof = n - free
    if free < 2 or dof < 1:
        return 1.0
    weight = 1.0 / (stress if stress_err is None else stress_err) ** 2
    level = float(np.sum(weight * stress) / np.sum(weight))
    flat = float(np.sum(weight * (stress - level) ** 2))
    fitted = float(np.sum(weight * (stress - model) ** 2))
    if not (math.isfinite(fitted) and flat > 0.0):
        return 1.0
    return nested_constant_p(flat, fitted, free - 1, dof)


def nested_constant_p(flat: float, left: float, extra: int, dof: int) -> float:
    """p of the F test of a constant (residual sum ``flat``) within a fit with ``extra`` more parameters (residual
    sum ``left``, ``dof`` degrees of freedom left): F(extra, dof); 1 where the fit does no better."""
    if not left < flat:
        return 1.0
    left = max(left, flat * 1e-28)  # the values' rounding: an exact curve's residuals are never below it
    return float(stats.f.sf(((flat - left) / extra) / (left / dof), extra, dof))


@dataclass(frozen=True)
class Misfit:
    """How far a fitted curve is from the data, against the model-independent noise."""

    p_value: float
    rms_relative: float  # rms of (data - model)/data
    rms_pa: float
    worst_pa: float  # data - model at the worst point
    worst_velocity: float
    worst_stress: float
    significant: bool
    ratio: float  # fit's residual variance / scatter variance
    chi_square: float  # with the errors of the fit (stated, or the stress itself: relative)
    scatter: Scatter  # the noise it is judged against: its residuals' scatter between neighbours
    #: the lack-of-fit test against the repeated measurements alone (:func:`lack_of_fit`; None without repeats)
    lack_of_fit: LackOfFit | None = None
    #: p of the tests against the scatter between neighbours (and the stated errors) alone, without the repeats'
    neighbours_p: float = math.nan
    #: the data's own scatter between neighbours (no model: it also counts the curve's bend, so it errs large) and
    #: p of the F test of the fit's residual variance against it (with stated errors, the larger p of that and the
    #: chi-square against them: both must reject); nan where it could not be made
    data_scatter: Scatter | None = None
    data_p: float = math.nan

    @property
    def data_ratio(self) -> float:
        """The fit's residual variance over the data's own scatter between neighbours (nan without it)."""
        if self.data_scatter is None or not self.data_scatter.variance > 0.0:
            return math.nan
        return self.ratio * self.scatter.variance / self.data_scatter.variance


def misfit(
    velocity: np.ndarray,
    stress: np.ndarray,
    stress_err: np.ndarray | None,
    model: np.ndarray,
    free: int,
) -> Misfit:
    """Is the fit's misfit larger than the noise?  Its residual variance against the scatter of its residuals
    between neighbours (:func:`residual_scatter`, p from :func:`misfit_p_value`); with stated errors also the
    chi-square test, and the larger p of the two (a misfit is claimed only when both say so: errors stated too
    small are not the model's fault)."""
    n = stress.size
    dof = max(n - free, 1)
    error = stress if stress_err is None else stress_err
    z = (stress - model) / error
    chi = float(z @ z)
    scatter = residual_scatter(velocity, stress, stress_err, model)
    ratio = chi / dof / scatter.variance
    p = misfit_p_value(velocity, stress_err, ratio, scatter)
    p_chi = float(stats.chi2.sf(chi, dof)) if stress_err is not None else 0.0
    if stress_err is not None:
        p = max(p, p_chi)
    # the same residuals against the data's own scatter between neighbours, measured without the model: a fit far
    # from the data cannot inflate it.  That of the residuals can: a wiggly fit 68 % off 8 smooth points, whose
    # own neighbours scatter 1.15 %, left residuals scattering 14.7 % between neighbours, and with ≈3.4 degrees of
    # freedom their ratio's p was 0.0031: "ok" (round 30).  The data's scatter counts the curve's bend as noise,
    # so it errs large and the test errs toward "describes"; with stated errors the chi-square must reject too
    # (errors the data's scatter finds too small are no misfit of the model)
    data_scatter = local_scatter(velocity, stress, stress_err)
    p_data = math.nan
    if data_scatter.dof > 0 and math.isfinite(data_scatter.variance) and data_scatter.variance > 0 and n > free:
        p_data = float(stats.f.sf(chi / dof / data_scatter.variance, dof, data_scatter.dof))
        p_data = max(p_data, p_chi)
        p = min(p, p_data)
    neighbours_p = p
    pure = lack_of_fit(velocity, stress, stress_err, model, free)
    if pure is not None:  # the repeats' scatter has no bend in it: a misfit the neighbours see as noise, it does not
        p = min(p, pure.p_value)
    diff = stress - model
    k = int(np.argmax(np.abs(diff)))
    return Misfit(
        p_value=p,
        rms_relative=float(np.sqrt(np.mean((diff / stress) ** 2))),
        rms_pa=float(np.sqrt(np.mean(diff**2))),
        worst_pa=float(diff[k]),
        worst_velocity=float(velocity[k]),
        worst_stress=float(stress[k]),
        significant=p <= SIGNIFICANCE,
        ratio=ratio,
        chi_square=chi,
        scatter=scatter,
        lack_of_fit=pure,
        neighbours_p=neighbours_p,
        data_scatter=data_scatter,
        data_p=p_data,
    )


@dataclass(frozen=True)
class LackOfFit:
    """The classical lack-of-fit F test: the misfit of the velocities' means against the scatter of the repeated
    measurements about them (pure error)."""

    p_value: float
    ratio: float  # F: lack-of-fit mean square over the pure-error mean square
    dof: tuple[int, int]  # (velocities - free parameters, points - velocities)
    pure_scale: float  # rms of the repeats about their velocity's mean, relative or in units of the stated errors
    relative: bool

    def describe(self) -> str:
        size = f"{self.pure_scale:.3g} stated errors"
        if self.relative:
            size = f"{100 * self.pure_scale:.3g} % of the stress"
        return (
            f"against the scatter of the repeated measurements alone ({size}, {self.dof[1]} degrees of freedom;"
            f" lack-of-fit F test, F({self.dof[0]}, {self.dof[1]}) = {self.ratio:.3g}): p = {self.p_value:.2g}"
        )


def lack_of_fit(
    velocity: np.ndarray, stress: np.ndarray, stress_err: np.ndarray | None, model: np.ndarray, free: int
) -> LackOfFit | None:
    """The lack-of-fit F test of a fit with ``free`` parameters against the repeated measurements (weights
    1/``stress_err``², or 1/stress² for relative noise; their scale does not enter): the residual sum splits into
    the repeats' scatter about their velocity's weighted mean (pure error, n − G degrees of freedom, no model and no
    bend in it) and the weighted squares of those means' residuals (G − k): F(G − k, n − G), exact for a model
    linear in its parameters and Gaussian noise.  The scatter between neighbours (:func:`residual_scatter`) counts
    a misfit that jumps from point to point as noise: a fit 90 % off most of ten points, whose two repeats agree
    within 1 %, passed it (p = 0.004) and was "ok" (round 28); here p = 9e-5.  None without repeated velocities,
    without a degree of freedom for the misfit, or without scatter among the repeats."""
    order = np.argsort(velocity, kind="stable")
    starts = _velocity_groups(np.log(velocity[order]))
    n, groups = velocity.size, starts.size
    if groups == n or groups <= free:
        return None
    error = stress if stress_err is None else stress_err
    w = 1.0 / error[order] ** 2
    r = (stress - model)[order]
    total = np.add.reduceat(w, starts)
    mean = np.add.reduceat(w * r, starts) / total
    pure = float(np.sum(w * (r - np.repeat(mean, np.diff(np.r_[starts, n]))) ** 2))
    between = float(np.sum(total * mean**2))
    if not (pure > 0.0 and math.isfinite(between)):
        return None
    f = (between / (groups - free)) / (pure / (n - groups))
    return LackOfFit(
        float(stats.f.sf(f, groups - free, n - groups)),
        f,
        (groups - free, n - groups),
        math.sqrt(pure / (n - groups)),
        stress_err is None,
    )
