"""The noise of a steady curve estimated without the model: the scatter between neighbouring points.

The pseudo-residuals of Gasser, Sroka and Jennen-Steinmetz (each interior point against the straight line
through its two neighbours in ln V), with Satterthwaite degrees of freedom, so the steady fit's tests do not
take the noise from a fit that may have ended far from the data (docs/fitting.md).
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
    effective degrees of freedom, from neighbouring points; ``relative`` says which."""

    variance: float
    dof: float
    relative: bool
    points: int

    @property
    def scale(self) -> float:
        return math.sqrt(self.variance)

    def describe(self) -> str:
        size = f"{100 * self.scale:.3g} % of the stress" if self.relative else f"{self.scale:.3g} stated errors"
        return (
            f"{size} (scatter of each point about the line through its neighbours, ≈{self.dof:.3g} degrees of freedom)"
        )


def local_scatter(velocity: np.ndarray, stress: np.ndarray, stress_err: np.ndarray | None) -> Scatter:
    """The scatter of the data about the line through each point's neighbours (module docstring)."""
    order = np.argsort(velocity)
    x = np.log(velocity[order])
    relative = stress_err is None
    y = np.log(stress[order]) if relative else stress[order] / 1.0
    e = np.ones_like(y) if relative else stress_err[order]  # type: ignore[index]
    n = x.size
    if n < 3:
        return Scatter(math.inf, 0.0, relative, n)
    h_left, h_right = x[1:-1] - x[:-2], x[2:] - x[1:-1]
    w_left, w_right = h_right / (h_left + h_right), h_left / (h_left + h_right)
    sd = np.sqrt(e[1:-1] ** 2 + (w_left * e[:-2]) ** 2 + (w_right * e[2:]) ** 2)
    pseudo = (y[1:-1] - w_left * y[:-2] - w_right * y[2:]) / sd
    variance = float(pseudo @ pseudo) / (n - 2)
    # Satterthwaite: pseudo = B z with z = y/e standard noise and B banded (row i: columns i, i+1, i+2);
    # s^2 = z^T B^T B z/(n - 2), tr(B^T B) = n - 2 (unit rows), tr((B^T B)^2) = |B B^T|_F^2 from its 3 diagonals
    c0, c1, c2 = -w_left * e[:-2] / sd, e[1:-1] / sd, -w_right * e[2:] / sd
    off1 = c1[:-1] * c0[1:] + c2[:-1] * c1[1:]
    off2 = c2[:-2] * c0[2:]
    square_trace = float(np.sum((c0**2 + c1**2 + c2**2) ** 2) + 2 * off1 @ off1 + 2 * off2 @ off2)
    dof = (n - 2) ** 2 / square_trace
    floor = SCATTER_FLOOR**2 if relative else (SCATTER_FLOOR * float(np.median(stress / e))) ** 2
    return Scatter(max(variance, floor), dof, relative, n)


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


def velocity_dependence(stress: np.ndarray, stress_err: np.ndarray | None, scatter: Scatter) -> Dependence:
    """Does the stress vary by more than its noise?  F test of the spread about a constant against the
    scatter between neighbours; with stated errors also the chi-square of a constant, and the larger p of
    the two (a dependence is claimed only when both noise estimates say so)."""
    n = stress.size
    if stress_err is None:
        y = np.log(stress)
        spread2 = float(np.var(y, ddof=1))
    else:
        w = 1.0 / stress_err**2
        level = float(np.sum(w * stress) / np.sum(w))
        spread2 = float(np.sum(w * (stress - level) ** 2)) / (n - 1)
    if spread2 <= scatter.variance * 1e-12 or spread2 == 0.0:
        p = 1.0
    elif scatter.dof <= 0:
        p = 1.0
    else:
        p = float(stats.f.sf(spread2 / scatter.variance, n - 1, scatter.dof))
        if stress_err is not None:
            p = max(p, float(stats.chi2.sf(spread2 * (n - 1), n - 1)))
    spread = math.sqrt(spread2)
    if stress_err is None:
        size = f"{100 * (math.exp(spread) - 1):.3g} % (rms of ln σ about its mean)"
        noise = f"{100 * scatter.scale:.3g} %"
    else:
        size = f"{spread:.3g} stated errors (rms about a constant)"
        noise = f"{scatter.scale:.3g} stated errors"
    text = (
        f"the stress varies by {size}, against a scatter of {noise} between neighbouring points (F test: p = {p:.2g})"
    )
    return Dependence(p, spread, p <= SIGNIFICANCE, text)


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
    if not (math.isfinite(fitted) and flat > 0.0) or fitted >= flat:
        return 1.0
    fitted = max(fitted, flat * 1e-28)  # the values' rounding: an exact curve's residuals are never below it
    return float(stats.f.sf(((flat - fitted) / (free - 1)) / (fitted / dof), free - 1, dof))


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


def misfit(
    velocity: np.ndarray,
    stress: np.ndarray,
    stress_err: np.ndarray | None,
    model: np.ndarray,
    free: int,
    scatter: Scatter,
) -> Misfit:
    """Is the fit's misfit larger than the noise?  F test of its residual variance against the scatter
    between neighbours; with stated errors also the chi-square test, and the larger p of the two (a misfit is
    claimed only when both say so: errors stated too small are not the model's fault)."""
    n = stress.size
    dof = max(n - free, 1)
    error = stress if stress_err is None else stress_err
    z = (stress - model) / error
    chi = float(z @ z)
    ratio = chi / dof / scatter.variance
    p = float(stats.f.sf(ratio, dof, scatter.dof)) if scatter.dof > 0 else 1.0
    if stress_err is not None:
        p = max(p, float(stats.chi2.sf(chi, dof)))
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
    )
