"""Steady sliding: the bond population at constant velocity (Eqs 6-8).

In the dimensionless age x = t_a V / dl_m the log-hazard is L(x) = ln T + a x/(1-x^2) - alpha x, and N/N0 and
sigma are two integrals i, j of the survival (docs/steady-state.md).  L is convex, so the quadrature chooses its
panels from explicit bounds (:func:`_march`); dsigma/dV is differentiated under the integral on the same panels.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..columns import attribute_frame
from ..errors import ModelError, ParameterError
from ..numerics.quadrature import panel_rule
from ..parameters import BOLTZMANN, Parameters, require_flag
from ..reprs import compact_repr
from ..units import refused_as_written, shorten, si_argument

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd
    from matplotlib.axes import Axes


@dataclass(frozen=True)
class QuadratureSettings:
    """Panel rule of the steady-state quadrature (defaults give ~1e-9 relative error).

    order: Gauss-Legendre nodes per panel.  log_hazard_step / hazard_step: the
    largest change of the log-hazard L and of the cumulative hazard H allowed
    across one panel.  end_ratio: panels near x = 1 span at most this fraction
    of the remaining gap 1 - x.  Coarser settings exist for convergence studies.
    """

    order: int = 16
    log_hazard_step: float = 16.0
    hazard_step: float = 16.0
    end_ratio: float = 0.7
    widest_panel: float = 0.5
    #: the survival is cut where H exceeds this (exp(-36) ~ 2e-16) and what it can still add is below tail_tolerance
    hazard_cutoff: float = 36.0
    tail_tolerance: float = 1e-11
    #: a stretch whose hazard integral is below this is crossed in one panel
    negligible_hazard: float = 1e-13

    def refined(self, factor: float) -> QuadratureSettings:
        """Panels ``factor`` times narrower (same order): for convergence tests."""
        return dataclasses.replace(
            self,
            log_hazard_step=self.log_hazard_step / factor,
            hazard_step=self.hazard_step / factor,
            end_ratio=self.end_ratio / factor,
            widest_panel=self.widest_panel / factor,
        )


DEFAULT_QUADRATURE = QuadratureSettings()
#: ~1e-12 relative: for curves sampled once and then interpolated or root-found
#: (jump velocity, slip trajectory, critical point), where noise would limit convergence.
ACCURATE_QUADRATURE = QuadratureSettings(log_hazard_step=10.0, hazard_step=10.0)
#: With no FENE term (a = 0) the march stops this close to x = 1.
SMALLEST_GAP = 1e-30
MAX_PANELS = 20000
#: Panel widths are found to within this factor of the widest good width.
WIDTH_RATIO = 1.5
MAX_BISECTIONS = 40
#: A panel narrower than this many ulps of the position cannot be sampled (its nodes would round onto
#: each other, and L changes by O(1) per ulp): when not even that is good, the survival steps to 0 there.
#: 2^20 ulps (~1e-10 of the position) moves i and j by < 1e-10 relative; the step's ln V derivative is
#: added in _march (with alpha ~ 1e14 L changes by ~0.1 per ulp, so a cliff a few thousand ulps wide only
#: gives noise).
STEP_ULPS = float(2**20)
_LOG_WIDTH_RATIO = float(np.log(WIDTH_RATIO))
#: The width search starts this far (in ln w) below the left end's cap, where the widest good width usually lies,
#: and first moves by 2 FIRST_REACH (doubling on).
START_OFFSET = float(np.log(4.0))
FIRST_REACH = float(np.log(1.5))
_LOG_CAP = 700.0  # exp(700) ~ 1e304: keeps e^L finite where S is long zero
_TINY = 1e-300


@dataclass(frozen=True)
class SteadyState:
    """Steady friction curve sigma(V) (Eqs 6-8); arrays have the shape of ``velocity``."""

    __repr__ = compact_repr  # counts, not hundreds of array elements

    velocity: np.ndarray
    stress: np.ndarray
    bonded_fraction: np.ndarray
    stress_slope: np.ndarray
    aging: bool
    parameters: Parameters = field(repr=False)
    ages: tuple[np.ndarray, ...] | None = field(default=None, repr=False)
    densities: tuple[np.ndarray, ...] | None = field(default=None, repr=False)

    def age_distribution(self, index: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """(t_a in s, n(t_a) in 1/(m^2 s)) at velocity number ``index`` (needs ``distribution=True``)."""
        if self.ages is None or self.densities is None:
            raise ValueError("age distribution not computed: call steady_state(..., distribution=True)")
        return self.ages[index], self.densities[index]

    def to_frame(self) -> pd.DataFrame:
        """One row per velocity, SI units."""
        return attribute_frame(self, "velocity stress bonded_fraction stress_slope")

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        """sigma against log V; returns the Axes (never shows the figure)."""
        from ..plots.steady import plot_steady

        return plot_steady(self, ax=ax, **kwargs)


@dataclass(frozen=True)
class _Scales:
    """Dimensionless groups of Eq 6 at each velocity (see module docstring)."""

    log_t: np.ndarray  # ln T
    a: np.ndarray  # FENE strength lambda M dl_m/kT (per point: batches may mix parameter sets)
    alpha: np.ndarray
    beta: np.ndarray  # -d(alpha)/d(ln V) / ... : alpha (1 + V/V_a)
    birth: np.ndarray  # tau V / dl_m = u0/T
    # the saturating-aging extension (docs/extensions.md): 1/x_s = dl_m/(V t_s) (0 in a lane without it) and
    # V/V_a; the aging term -alpha x becomes -alpha (1 - e^(-x/x_s)) x_s.  None when no lane has it: the
    # paper's model then runs exactly the code it always did, at no extra cost
    sat: np.ndarray | None = None
    ratio: np.ndarray | None = None


def _scales(params: Parameters, velocity: np.ndarray, aging: bool) -> _Scales:
    b, g = params.bonds, params.aging
    log_age = math.log(b.max_extension) - np.log(velocity)  # ln(dl_m/V), in logs: dl_m/V may overflow
    log_t = math.log(b.breakage_weight) + log_age - math.log(b.bond_time)
    a = b.activation_length * b.chain_stiffness * b.max_extension / (BOLTZMANN * b.temperature)
    if aging:
        # capped at e^700 (~1e304) so that it stays finite: _check_scales refuses anything above LARGEST_RATE
        alpha = np.exp(np.minimum(log_age - math.log(g.aging_time) - velocity / g.aging_velocity, 700.0))
        beta = alpha * (1.0 + velocity / g.aging_velocity)
    else:
        alpha = np.zeros_like(velocity)
        beta = np.zeros_like(velocity)
    ts = g.saturation_age
    saturating = ts is not None and aging
    return _Scales(
        log_t=log_t,
        a=np.full_like(velocity, a),
        alpha=alpha,
        beta=beta,
        birth=b.bond_time * velocity / b.max_extension,
        sat=b.max_extension / (velocity * ts) if saturating else None,
        ratio=velocity / g.aging_velocity if saturating else None,
    )


def _aged(x: np.ndarray, sat: np.ndarray | None) -> np.ndarray:
    """The scaled age the aging term sees: x (the paper), or (1 - e^(-x sat))/sat with saturation."""
    if sat is None:
        return x
    safe = np.where(sat > 0.0, sat, 1.0)
    return np.where(sat > 0.0, -np.expm1(-x * safe) / safe, x)


def _aged_rate(x: np.ndarray, sat: np.ndarray | None) -> np.ndarray | float:
    """d(aged)/dx: 1, or e^(-x sat) with saturation."""
    if sat is None:
        return 1.0
    return np.exp(-x * sat)


def _ln_v_moment(x: np.ndarray, s: _Scales) -> np.ndarray:
    """m(x) with d(aging term)/d ln V = beta m(x): x for linear aging, else (ratio aged + x aged')/(1 + ratio).

    With saturation the aging term is -(t_s/tau_a) e^(-V/V_a) (1 - e^(-x/x_s)), x_s = t_s V/dl_m; at fixed x
    its ln V derivative is alpha (ratio (1 - e^(-u))/sat + x e^(-u)), u = x sat (docs/extensions.md).
    """
    if s.sat is None or s.ratio is None:
        return x
    return (s.ratio * _aged(x, s.sat) + x * _aged_rate(x, s.sat)) / (1.0 + s.ratio)


#: FENE strength and aging rate beyond which the log-hazard's terms could overflow (the box needs < 1e17).
LARGEST_RATE = 1e200


def check_steady_range(params: Parameters, velocity: Any, aging: bool = True) -> None:
    """The ModelError :func:`steady_state` raises where the dimensionless groups at ``velocity`` (m/s, > 0) leave
    floating point, without integrating anything (the time-dependent model checks its protocol's velocities with it
    before it starts: its steady start, its reduction and its cost estimate use the steady model)."""
    _check_scales(_scales(params, np.atleast_1d(np.asarray(velocity, dtype=float)), aging))


def _check_scales(s: _Scales) -> None:
    """A one-line ModelError where the dimensionless groups leave floating point (far outside any physical box)."""
    groups = (
        ("FENE strength a = λMΔl_m/kT", s.a, "bonds.activation_length, chain_stiffness, max_extension, temperature"),
        ("aging rate Δl_m/(V τa) e^(−V/Va)", s.alpha, "aging.aging_time, aging.aging_velocity, bonds.max_extension,"
         " the velocity"),
    )  # fmt: skip
    for name, values, keys in groups:
        bad = ~(np.abs(values) <= LARGEST_RATE)
        if np.any(bad):
            raise ModelError(
                f"the {name} is {float(values[bad][0]):.3g}, beyond {LARGEST_RATE:g}: these parameters are outside"
                f" what the steady model can integrate in floating point (set by {keys})"
            )
    bad = ~(np.isfinite(s.log_t) & np.isfinite(s.birth))
    if np.any(bad):
        raise ModelError("the breakage rate u0 Δl_m/(V τ) or τV/Δl_m is not finite for these parameters")


def _join(parts: Sequence[_Scales]) -> _Scales:
    """One _Scales of many lanes; the saturation fields are zeros (sat) in lanes without the extension."""
    columns = {}
    for f in dataclasses.fields(_Scales):
        pieces = [getattr(part, f.name) for part in parts]
        if all(piece is None for piece in pieces):
            columns[f.name] = None
            continue
        fill = 1.0 if f.name == "ratio" else 0.0
        pairs = zip(parts, pieces, strict=True)
        filled = [np.full(part.log_t.shape, fill) if piece is None else piece for part, piece in pairs]
        columns[f.name] = np.concatenate(filled)
    return _Scales(**columns)


def _log_hazard_and_slope(x: np.ndarray, y: np.ndarray, s: _Scales) -> tuple[np.ndarray, np.ndarray]:
    """L and |L'| at x (y = 1 - x), sharing the FENE denominator."""
    d = y * (1.0 + x)
    return s.log_t + s.a * x / d - s.alpha * _aged(x, s.sat), np.abs(
        s.a * (1.0 + x * x) / (d * d) - s.alpha * _aged_rate(x, s.sat)
    )


def _panel_width(x: np.ndarray, y: np.ndarray, s: _Scales, q: QuadratureSettings) -> tuple[np.ndarray, np.ndarray]:
    """(width of the next panel at left end x (y = 1 - x), lanes where the survival steps to 0 there).

    A panel is good when resolved (|L'| w <= q.log_hazard_step and e^L w <= q.hazard_step) or negligible
    (e^L w <= q.negligible_hazard); L is convex, so testing both ends decides, and the good widths form an interval
    (0, w*].  The width returned is good and within WIDTH_RATIO of w* (or the widest allowed panel), by a galloping
    search and bisection on ln w run until the bracket is that tight.  When not even STEP_ULPS ulps of the position
    are good the survival is a step there and the lane is flagged (docs/steady-state.md, section 2).
    Everything is done on logarithms: no exponential can overflow.
    """
    log_widest = np.log(np.minimum(q.widest_panel, q.end_ratio * y))
    l_left, slope_left = _log_hazard_and_slope(x, y, s)
    log_slope_left = np.log(np.maximum(slope_left, _TINY))
    log_step, log_resolved = np.log(q.log_hazard_step), np.log(q.hazard_step)
    # dH/d ln V = int (beta x - 1) e^L: a stretch is only negligible when (1 + beta) times its hazard is (with
    # beta ~ 1e14 a hazard of 1e-13 ahead of the FENE cliff moves the slope by O(1))
    log_negligible = np.log(q.negligible_hazard) - np.log1p(s.beta)
    # the left end's share of the tests: resolved needs ln w below cap_resolved, negligible below cap_negligible
    cap_resolved = np.minimum(log_resolved - l_left, log_step - log_slope_left)
    cap_negligible = log_negligible - l_left

    def good(log_w: np.ndarray, lanes: _Lanes) -> np.ndarray:
        w = np.exp(log_w)
        l_right, slope_right = _log_hazard_and_slope(lanes.x + w, lanes.y - w, lanes.s)
        log_integral = l_right + log_w
        resolved = (log_w <= lanes.cap_resolved) & (slope_right * w <= q.log_hazard_step)
        resolved &= log_integral <= log_resolved
        return resolved | ((log_w <= lanes.cap_negligible) & (log_integral <= lanes.log_negligible))

    log_w = log_widest.copy()
    step = np.zeros(x.size, dtype=bool)
    # the widest panel can only be good where the left end allows it: test just those lanes
    searching = (log_widest > cap_resolved) & (log_widest > cap_negligible)
    every = _Lanes(x, y, s, cap_resolved, cap_negligible, log_negligible)
    tried = np.nonzero(~searching)[0]
    if tried.size:
        searching[tried] = ~good(log_widest[tried], every.take(tried))
    open_ = np.nonzero(searching)[0]
    if open_.size == 0:
        return np.exp(log_w), step
    lanes = every.take(open_)
    # bracket [low, top]: top is not good; low is good once confirmed (before that it is the floor, STEP_ULPS
    # ulps of the position).  Gallop from the left end's cap (usually within a few times w*) with steps in ln w
    # that double, then bisect: a few tests per panel, and at most ~2 log2(745) however deep the dip.
    # The arrays below hold only the lanes still searching (k: their places among open_), so that each round
    # costs what those lanes cost; a lane's bracket is written to found/confirmed when it closes.
    top = log_widest[open_]
    low = np.log(STEP_ULPS * np.spacing(np.where(lanes.x < 0.5, lanes.x, lanes.y)))
    guess = np.clip(lanes.cap_resolved - START_OFFSET, low, top)
    found = low.copy()
    confirmed = np.zeros(open_.size, dtype=bool)
    sure = confirmed.copy()
    reach = np.full(open_.size, FIRST_REACH)
    k = np.arange(open_.size)
    active = lanes
    for _ in range(MAX_BISECTIONS):
        better = good(guess, active)
        low = np.where(better, guess, low)
        top = np.where(better, top, guess)
        sure |= better
        reach *= 2.0
        gap = top - low
        wide = gap > _LOG_WIDTH_RATIO
        if not wide.all():
            closed = k[~wide]
            found[closed] = low[~wide]
            confirmed[closed] = sure[~wide]
            k = k[wide]
            if k.size == 0:
                break
            low, top, sure, reach, gap = low[wide], top[wide], sure[wide], reach[wide], gap[wide]
            active = active.take(wide)
        move = np.minimum(reach, 0.5 * gap)
        guess = np.where(sure, low + move, top - move)
    else:  # pragma: no cover - MAX_BISECTIONS halvings close any bracket of ln w (at most ~745 wide)
        found[k], confirmed[k] = low, sure
    unconfirmed = np.nonzero(~confirmed)[0]
    if unconfirmed.size:  # the bracket closed on the floor: is even that good?
        step[open_[unconfirmed]] = ~good(found[unconfirmed], lanes.take(unconfirmed))
    log_w[open_] = found
    return np.exp(log_w), step


@dataclass(frozen=True)
class _Lanes:
    """The lanes whose panel width is being searched: left ends and the left end's caps on ln w."""

    x: np.ndarray
    y: np.ndarray
    s: _Scales
    cap_resolved: np.ndarray
    cap_negligible: np.ndarray
    log_negligible: np.ndarray

    def take(self, k: np.ndarray) -> _Lanes:
        return _Lanes(
            self.x[k], self.y[k], _take(self.s, k), self.cap_resolved[k], self.cap_negligible[k], self.log_negligible[k]
        )


def _take(s: _Scales, k: np.ndarray | slice) -> _Scales:
    """The lanes ``k`` of ``s``."""
    sat = None if s.sat is None else s.sat[k]
    ratio = None if s.ratio is None else s.ratio[k]
    return _Scales(s.log_t[k], s.a[k], s.alpha[k], s.beta[k], s.birth[k], sat, ratio)


@dataclass
class _Integrals:
    i: np.ndarray
    j: np.ndarray
    di: np.ndarray  # d i / d ln V
    dj: np.ndarray  # d j / d ln V
    nodes: list[list[np.ndarray]] | None  # per velocity: panels of (x, S)


def _march(s: _Scales, q: QuadratureSettings, keep_nodes: bool = False, compiled_from: int | None = None) -> _Integrals:
    """Integrate i, j and their ln V derivatives panel by panel from x = 0.

    All points advance together; each finishes when its cumulative hazard
    passes ``hazard_cutoff`` (the survival is then below 2e-16) or x reaches 1.
    The working arrays hold only the points still marching: finished ones are
    written out and dropped, so a step costs what the remaining points cost.
    """
    lanes = COMPILED_LANES if compiled_from is None else compiled_from
    if not keep_nodes and s.log_t.size >= lanes:
        return _march_compiled(s, q)
    rule = panel_rule(q.order)
    # Node arrays are (K, n): the long axis innermost, so that per-point factors broadcast along rows cheaply
    # (an (n, K) layout with K = 16 runs numpy's inner loops 16 elements at a time).
    t_half = 0.5 * (rule.nodes + 1.0)[:, None]  # node positions in [0, 1] of a panel
    integrate = rule.cumulative  # (K+1, K): integrals to each node and (last row) over the panel
    weights = rule.weights
    n = s.log_t.size
    out = _Integrals(np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), [[] for _ in range(n)] if keep_nodes else None)
    index = np.arange(n)  # original position of each marching point
    sub = s
    x_left, y_left = np.zeros(n), np.ones(n)
    hazard, moment = np.zeros(n), np.zeros(n)  # H and G = int x e^L
    sums = np.zeros((4, n))  # i, j, -di, -dj
    if n == 0:
        return out
    for _ in range(MAX_PANELS):
        w, step = _panel_width(x_left, y_left, sub, q)
        w[step] = 0.0  # the survival steps to 0 within a few ulps: nothing more to integrate
        if step.any():
            # ... but where that step lies moves with V: dx_s/d ln V = -(dL/d ln V)/L' = (1 - beta x)/L', and the
            # step carries i and j's boundary terms S_s dx_s/d ln V and S_s x/(1-x^2) dx_s/d ln V (this is what
            # an integral across the cliff gives, where L cannot be resolved in floating point)
            k = np.nonzero(step)[0]
            xs, ys, sk = x_left[k], y_left[k], _take(sub, k)
            d = ys * (1.0 + xs)
            rise = sk.a * (1.0 + xs * xs) / (d * d) - sk.alpha * _aged_rate(xs, sk.sat)
            shift = np.exp(-hazard[k]) * (sk.beta * _ln_v_moment(xs, sk) - 1.0) / rise  # -S_s dx_s/d ln V
            sums[2, k] += shift
            sums[3, k] += shift * (xs / d)
        offset = t_half * w
        x = offset + x_left
        y = np.subtract(y_left, offset, out=offset)
        stretch = 1.0 + x
        stretch *= y
        np.divide(x, stretch, out=stretch)  # x/(1-x^2), the FENE factor
        h = stretch * sub.a
        h -= _aged(x, sub.sat) * sub.alpha
        h += sub.log_t  # the log-hazard L
        np.minimum(h, _LOG_CAP, out=h)
        np.exp(h, out=h)
        half = 0.5 * w
        h *= half  # e^L times the panel's half-width: the integrals below need no further scaling
        # H and G = int x e^L at the nodes and (last row) over the whole panel
        cumulative_h = _one_thread_product(integrate, h)
        moment_weight = _ln_v_moment(x, sub)  # x, or its saturating-aging counterpart
        if moment_weight is x:
            x *= h
        else:
            x = moment_weight * h
        cumulative_g = _one_thread_product(integrate, x)
        big_h = cumulative_h[:-1]
        big_h += hazard
        d_hazard = cumulative_g[:-1]
        d_hazard += moment  # G at the nodes
        d_hazard *= sub.beta
        d_hazard -= big_h  # d H / d ln V = beta G - H
        survival = np.negative(big_h)
        np.exp(survival, out=survival)
        if out.nodes is not None:
            x_nodes = t_half * w + x_left  # x was overwritten by x e^L
            for row, k in enumerate(index):
                out.nodes[k].append(np.stack([x_nodes[:, row], survival[:, row]]))
        weighted = survival * stretch
        sums[0] += np.einsum("k,kn->n", weights, survival) * half  # einsum: numpy's own loop, never threaded BLAS
        sums[1] += np.einsum("k,kn->n", weights, weighted) * half
        survival *= d_hazard
        weighted *= d_hazard
        sums[2] += np.einsum("k,kn->n", weights, survival) * half
        sums[3] += np.einsum("k,kn->n", weights, weighted) * half
        hazard += cumulative_h[-1]
        moment += cumulative_g[-1]
        x_left += w
        y_left -= w
        # step: the survival falls to zero within a few ulps of x (see _panel_width), exact to that precision
        done = (y_left <= SMALLEST_GAP) | step
        past = np.nonzero(hazard >= q.hazard_cutoff)[0]
        if past.size:
            tail = _tail_negligible(hazard[past], y_left[past], sums[0, past], sums[1, past], _take(sub, past), q)
            done[past] |= tail
        if done.any():
            finished = index[done]
            out.i[finished], out.j[finished] = sums[0, done], sums[1, done]
            out.di[finished], out.dj[finished] = -sums[2, done], -sums[3, done]
            if done.all():
                return out
            keep = ~done
            index, x_left, y_left, hazard, moment = index[keep], x_left[keep], y_left[keep], hazard[keep], moment[keep]
            sums = sums[:, keep]
            sub = _take(sub, keep)
    raise ModelError(f"steady-state quadrature did not converge: more than {MAX_PANELS} panels needed")


#: From this many lanes (velocities x parameter sets) on, the march runs compiled (stickslip.quasistatic.steady_kernel),
#: and from BATCH_COMPILED_LANES in the batched call; why these: docs/steady-state.md, "Wide batches run compiled".
COMPILED_LANES = 1000
BATCH_COMPILED_LANES = 16


def _march_compiled(s: _Scales, q: QuadratureSettings) -> _Integrals:
    """:func:`_march` lane by lane in compiled loops: the same panels and nodes, equal to rounding."""
    from . import steady_kernel

    rule = panel_rule(q.order)
    settings = np.array(
        [
            q.log_hazard_step,
            q.hazard_step,
            q.end_ratio,
            q.widest_panel,
            q.negligible_hazard,
            q.hazard_cutoff,
            q.tail_tolerance,
            SMALLEST_GAP,
            _LOG_CAP,
            MAX_PANELS,
            np.log(q.log_hazard_step),
            np.log(q.hazard_step),
        ]
    )
    search = np.array(
        [STEP_ULPS, _LOG_WIDTH_RATIO, START_OFFSET, FIRST_REACH, _TINY, MAX_BISECTIONS, _CLIFF_LOG_HAZARD]
    )
    out = np.empty((4, s.log_t.size))
    sat = np.zeros_like(s.log_t) if s.sat is None else s.sat  # 0: the paper's linear aging
    ratio = np.ones_like(s.log_t) if s.ratio is None else s.ratio
    status = steady_kernel.compiled()(
        *(np.ascontiguousarray(v, dtype=float) for v in (s.log_t, s.a, s.alpha, s.beta, sat, ratio)),
        settings,
        search,
        0.5 * (rule.nodes + 1.0),
        rule.cumulative,
        rule.weights,
        out,
    )
    if status != steady_kernel.MARCHED:
        raise ModelError(f"steady-state quadrature did not converge: more than {MAX_PANELS} panels needed")
    return _Integrals(out[0], out[1], out[2], out[3], None)


#: OpenBLAS keeps a product of fewer multiply-adds than this on one thread (docs/steady-state.md, "One thread").
ONE_THREAD_PRODUCT = 2**18


def _one_thread_product(matrix: np.ndarray, samples: np.ndarray) -> np.ndarray:
    """``matrix @ samples`` for a small matrix and wide samples, in column blocks that BLAS keeps on one thread."""
    rows, inner = matrix.shape
    n = samples.shape[1]
    columns = max(1, (ONE_THREAD_PRODUCT - 1) // (rows * inner))  # 963 for order 16
    if n <= columns:
        return matrix @ samples
    out = np.empty((rows, n))
    for start in range(0, n, columns):
        block = slice(start, start + columns)
        np.matmul(matrix, samples[:, block], out=out[:, block])
    return out


#: Beyond 1 - y_c (see _tail_negligible) the log-hazard is at least this.
_CLIFF_LOG_HAZARD = 50.0


def _tail_negligible(
    hazard: np.ndarray, y: np.ndarray, i: np.ndarray, j: np.ndarray, s: _Scales, q: QuadratureSettings
) -> np.ndarray:
    """True where the survival S = e^-H left at x = 1 - y can add at most q.tail_tolerance to i and to j.

    The rest of i is at most S y and the rest of j at most S (ln(1/y_c)/2 + 1), y_c = a/(3(alpha + |ln T| + 50));
    why (a plateau of the survival with aging can carry much of j): docs/steady-state.md, "Where the march stops".
    """
    y_c = np.minimum(y, np.maximum(s.a, _TINY) / (3.0 * (s.alpha + np.abs(s.log_t) + _CLIFF_LOG_HAZARD)))
    room_i = np.log(np.maximum(q.tail_tolerance * i, _TINY)) - np.log(y)
    room_j = np.log(np.maximum(q.tail_tolerance * j, _TINY)) - np.log(0.5 * np.log(1.0 / y_c) + 1.0)
    return -hazard <= np.minimum(room_i, room_j)


def require_parameters(params: Any, name: str = "params") -> None:
    """ParameterError unless ``params`` is a :class:`Parameters` set (a str, None or dict is a one-line error)."""
    if not isinstance(params, Parameters):
        raise ParameterError(
            f"{name}: expected a stickslip Parameters set (load_parameters(...)), got {type(params).__name__}"
        )


def _check_velocity(velocity: Any) -> np.ndarray:
    if hasattr(velocity, "dimensionality") and hasattr(velocity, "magnitude"):  # np.asarray would drop the unit
        try:
            velocity = velocity.to("m/s").magnitude  # (in the quantity's own registry)
        except Exception:  # pint's DimensionalityError, or a registry without m/s
            raise ParameterError(f"velocity: expected a velocity, got {shorten(velocity)}") from None
    try:
        raw = np.asarray(velocity)
    except (TypeError, ValueError):  # ragged nested lists
        raise ParameterError(f"velocity: expected numbers in m/s, got {shorten(velocity)}") from None
    if raw.dtype.kind not in "iuf":  # True would be 1 m/s, 1+0j would lose its imaginary part, "1" is text
        raise ParameterError(f"velocity: expected real numbers in m/s, got {shorten(velocity)}")
    v = raw.astype(float)
    bad = ~np.isfinite(v) | (v <= 0)
    if np.any(bad):
        raise ParameterError(f"velocity: expected positive finite values in m/s, got {float(v[bad].ravel()[0])!r}")
    return v


def _velocity_argument(velocity: Any) -> np.ndarray:
    """``velocity`` of a public entry: numbers in m/s (scalar or array), one value with its unit (``"0.2 mm/s"``)
    or a pint quantity; checked by :func:`_check_velocity`; an array of texts is a ParameterError saying that arrays are
    numbers in SI.  An empty array gives an empty curve (tests/test_robust_box.py), as numpy's own functions do."""
    if isinstance(velocity, str):
        with refused_as_written(velocity):
            return _check_velocity(si_argument(velocity, "velocity", "velocity"))
    if isinstance(velocity, (list, tuple)) and any(isinstance(item, str) for item in velocity):
        raise ParameterError(
            f"velocity: an array of velocities holds numbers in m/s (SI); a unit is read from one velocity"
            f" alone ('0.2 mm/s'), got {shorten(velocity)}"
        )
    return _check_velocity(velocity)  # an empty array gives an empty curve, as a numpy function does


def _require_finite_stress(params: Parameters, which: str = "") -> None:
    if params.bonds.activation_length == 0.0:
        raise ModelError(
            f"{which}bonds.activation_length = 0: bonds survive to full extension, where the FENE force (Eq 3) is"
            " infinite, so the stress integral (Eq 8) diverges; use a positive activation length"
        )


def _stress_scale(params: Parameters) -> float:
    b = params.bonds
    return b.chain_stiffness * b.site_density * b.max_extension


#: Set for the length of a time-dependent run (:func:`compiled_marches`): numba is loaded there in any case, so every
#: steady state the run asks for, however narrow (its critical point, the quasi-static cycle its cost estimate reads,
#: the jump's branch), runs on the compiled march, the same numbers to ~1e-13.  A critical point found so is cached
#: apart from the numpy march's (critical.cached_critical_point's ``compiled``), so no result depends on what ran
#: before it in the process.
_COMPILED_MARCHES: ContextVar[bool] = ContextVar("stickslip_compiled_marches", default=False)


@contextmanager
def compiled_marches() -> Iterator[None]:
    """Within: every steady state runs on the compiled march (see :data:`_COMPILED_MARCHES`)."""
    token = _COMPILED_MARCHES.set(True)
    try:
        yield
    finally:
        _COMPILED_MARCHES.reset(token)


def marches_compiled() -> bool:
    """Whether this is within :func:`compiled_marches`."""
    return _COMPILED_MARCHES.get()


def _lanes(compiled_from: Any, default: int) -> int:
    """The width from which the march runs compiled: ``compiled_from`` (a positive integer) or ``default`` (1 within
    :func:`compiled_marches`)."""
    if compiled_from is None:
        return 1 if _COMPILED_MARCHES.get() else default
    if isinstance(compiled_from, bool) or not isinstance(compiled_from, int | np.integer) or compiled_from < 1:
        raise ParameterError(f"compiled_from: expected a positive whole number of lanes, got {compiled_from!r}")
    return int(compiled_from)


def steady_state(
    params: Parameters,
    velocity: Any,
    aging: bool = True,
    distribution: bool = False,
    quadrature: QuadratureSettings = DEFAULT_QUADRATURE,
    *,
    compiled_from: int | None = None,
) -> SteadyState:
    """The steady friction stress, bonded fraction and dsigma/dV at each sliding velocity (Eqs 6-8).

    ``velocity`` is in m/s (real numbers, scalar or array: True or a complex value is a
    ParameterError, not 1 m/s or its real part), or one velocity with its unit (``"0.2 mm/s"``, a pint
    quantity); an empty array gives an empty curve.  ``aging=False`` drops the aging
    term of Eq 6 (the paper's no-aging curve).  With ``distribution=True`` the
    age distribution n(t_a) of Eqs 6-7 is kept at the quadrature nodes.
    ``quadrature`` sets the panel rule (see :class:`QuadratureSettings`).  The march runs compiled from
    ``compiled_from`` velocities on (default COMPILED_LANES; a caller that repeats narrow calls, such as a fit,
    passes 1).

    Raises :class:`ModelError` when the stress is infinite: with a zero
    activation length bonds survive to full extension, where the FENE force
    of Eq 3 diverges, and the integral of Eq 8 diverges logarithmically.
    """
    require_parameters(params)
    aging, distribution = require_flag(aging, "aging"), require_flag(distribution, "distribution")
    if not isinstance(quadrature, QuadratureSettings):
        raise ParameterError(f"quadrature: expected QuadratureSettings, got {type(quadrature).__name__}")
    v = _velocity_argument(velocity)
    _require_finite_stress(params)
    flat = np.ravel(v)
    s = _scales(params, flat, aging)
    _check_scales(s)
    got = _march(s, quadrature, keep_nodes=distribution, compiled_from=_lanes(compiled_from, COMPILED_LANES))
    denom = s.birth + got.i
    scale = _stress_scale(params)
    stress = scale * got.j / denom
    fraction = got.i / denom
    # d(sigma)/d(ln V), with d(birth)/d(ln V) = birth
    dstress = scale * (got.dj - (got.j / denom) * (s.birth + got.di)) / denom  # no denom**2: it can underflow
    slope = dstress / flat
    ages = densities = None
    if got.nodes is not None:
        b = params.bonds
        max_age = b.max_extension / flat
        newborn = b.site_density / (max_age * denom)  # n(0) = N0/(tau + I), Eq 7
        ages = tuple(np.concatenate([p[0] for p in panels]) * max_age[k] for k, panels in enumerate(got.nodes))
        densities = tuple(np.concatenate([p[1] for p in panels]) * newborn[k] for k, panels in enumerate(got.nodes))
    shape = v.shape
    return SteadyState(
        velocity=v,
        stress=stress.reshape(shape),
        bonded_fraction=fraction.reshape(shape),
        stress_slope=slope.reshape(shape),
        aging=aging,
        parameters=params,
        ages=ages,
        densities=densities,
    )


def steady_stress_many(
    params_list: Sequence[Parameters],
    velocity: Any,
    aging: bool = True,
    quadrature: QuadratureSettings = DEFAULT_QUADRATURE,
    paired: bool = False,
    *,
    compiled_from: int | None = None,
) -> np.ndarray:
    """sigma(V) (Eqs 6-8) for many parameter sets at once: shape (len(params_list), len(velocity)).

    One quadrature march serves every (set, velocity) pair, so the per-call
    cost is paid once: this is what fitting Jacobians and MCMC walkers need.
    With ``paired=True`` set k is evaluated only at velocity[k] (shape
    (len(params_list),)).  Same accuracy as :func:`steady_state`.  The march runs compiled from
    ``compiled_from`` lanes (sets x velocities) on (default BATCH_COMPILED_LANES, at most COMPILED_LANES).
    """
    aging, paired = require_flag(aging, "aging"), require_flag(paired, "paired")
    v = np.ravel(_check_velocity(velocity))
    for k, p in enumerate(params_list):
        require_parameters(p, f"parameter set {k}")
        _require_finite_stress(p, f"parameter set {k}: ")
    if paired and v.size != len(params_list):
        raise ParameterError(
            f"velocity: paired=True needs one velocity per parameter set, got {v.size} for {len(params_list)} sets"
        )
    if len(params_list) == 0:
        return np.empty(0) if paired else np.empty((0, v.size))
    if paired:
        parts = [_scales(p, v[k : k + 1], aging) for k, p in enumerate(params_list)]
        scale = np.array([_stress_scale(p) for p in params_list])
    else:
        parts = [_scales(p, v, aging) for p in params_list]
        scale = np.repeat([_stress_scale(p) for p in params_list], v.size)
    joined = _join(parts)
    _check_scales(joined)
    got = _march(joined, quadrature, compiled_from=min(COMPILED_LANES, _lanes(compiled_from, BATCH_COMPILED_LANES)))
    stress = scale * got.j / (joined.birth + got.i)
    return stress if paired else stress.reshape(len(params_list), v.size)
