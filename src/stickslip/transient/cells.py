"""The steady population of Eqs 6-7 as cells, compiled: model.steady_population's march in numba.

Two layouts of the same march: the Gauss rule's two cohorts per cell (:func:`steady_cohorts`, the solver's steady
starts, their cells cut ahead of the FENE cliff by :func:`_refine`, and rebuilt populations) and one cohort per cell
at its middle with its force, stiffness, hazard and aging sensitivity (:func:`_steady_cells`: the quasi-steady
reduction's lag and the linear stability's response).  Apart from both so that neither imports the other for it.
"""

from __future__ import annotations

import math

import numpy as np

from ..parameters import Parameters
from . import kernel
from .kernel import P_AGING, P_DLM, P_FORCE_SENS, P_INV_TAU_A, P_LOG_U0_TAU, P_M, P_N0, P_TAU, P_VA
from .model import CELL_HAZARD, GAUSS, MAX_CELLS, REFINED_MOST, WALL_CELL

#: the compiled steady cells (model.steady_population's, with its CELL_HAZARD, GAUSS and MAX_CELLS)
_CELLS: list = []


def _steady_cells():  # type: ignore[no-untyped-def]
    """model.steady_population's midpoint cells with force, stiffness, hazard and aging sensitivity (numba)."""
    if not _CELLS:
        from numba import njit

        g = globals()
        kernel.compiled()  # the kernel's chain functions, compiled in place
        g["_force"], g["_stiffness"], g["_energy"] = kernel._chain_force, kernel._chain_stiffness, kernel._chain_energy
        g["_aging_clock"] = kernel._aging_clock
        for name in ("_log_rate", "_march", "_lumping", "_need", "_cut_cells", "_refine"):
            g[name] = njit(cache=True)(g[name])
        _CELLS.append(njit(cache=True)(_cells))
        _CELLS.append(njit(cache=True)(_gauss))
    return _CELLS[0]


def steady_cohorts(  # type: ignore[no-untyped-def]
    params: Parameters,
    velocity: float,
    aging: bool,
    cell_hazard: float = CELL_HAZARD,
    cells_least: float = 1000.0,
    reach: float = 0.0,
    ripple: float = 0.0,
):
    """model.steady_population(params, velocity, aging) (the Gauss rule), compiled: the same cohorts, faster.

    ``reach`` (s of age at ``velocity``: how far the run carries the cohorts) and ``ripple`` (relative): the cells
    whose cohorts reach the FENE cliff within ``reach`` are cut until the ripple their lumped deaths leave in the
    stress there is at most ``ripple`` (:func:`_refine`, docs/transient.md section 18); 0 (the default): the cells
    of model.steady_population, uncut."""
    from .model import Population, pack_parameters, steady_population

    if not (velocity > 0 and math.isfinite(velocity)):
        return steady_population(params, velocity, aging)  # its error, in words
    _steady_cells()
    p = pack_parameters(params, aging, 1.0)
    age, weight = _CELLS[1](float(velocity), p, cell_hazard, cells_least, float(reach), float(ripple))
    if age.size >= 2 * MAX_CELLS:
        return steady_population(params, velocity, aging)  # its error, in words
    return Population(extension=velocity * age, age=age, weight=weight)


# the chain's force, stiffness and energy are the kernel's (Eq 3), one definition
_force, _stiffness, _energy = kernel._chain_force, kernel._chain_stiffness, kernel._chain_energy
_aging_clock = kernel._aging_clock  # the age the aging term sees (the saturating-aging extension changes it)


def _log_rate(age, v, slope, p):  # type: ignore[no-untyped-def]
    """ln r of a steady bond of this age (capped at 700), kernel.P_* layout of p."""
    force = _force(v * age, p[P_M], p[P_DLM])
    return min(p[P_LOG_U0_TAU] + p[P_FORCE_SENS] * force - _aging_clock(age, p)[0] * slope, 700.0)


def _march(v, p, cell_hazard, cells_least=1000.0):  # type: ignore[no-untyped-def]
    """Cell edges in age and the cumulative hazard at them: model.steady_population's march, compiled."""
    slope = p[P_INV_TAU_A] * math.exp(-v / p[P_VA]) if p[P_AGING] > 0.0 else 0.0
    t_max = p[P_DLM] / v
    widest = t_max / cells_least
    edges = [0.0]
    cum = [0.0]
    a = 0.0
    big_h = 0.0
    while big_h < 45.0 and a < t_max and len(edges) <= MAX_CELLS:
        lr = _log_rate(a, v, slope, p)
        step = widest if lr < -700.0 else min(widest, cell_hazard / math.exp(lr))
        step = min(step, WALL_CELL * (t_max - a))
        if step <= 1e-15 * a:
            break
        while True:  # as model.steady_population: shrink a cell over which the hazard climbs
            r0 = math.exp(_log_rate(a, v, slope, p))
            r1 = math.exp(_log_rate(a + 0.5 * step, v, slope, p))
            r2 = math.exp(_log_rate(a + step, v, slope, p))
            increment = step * (r0 + 4.0 * r1 + r2) / 6.0
            if (increment <= 2.0 * cell_hazard and r2 <= 2.0 * r0 + 1e-300) or increment <= 0.1 * cell_hazard:
                break
            if step <= 1e-12 * max(a, t_max):
                break
            step *= 0.25
        big_h += increment
        a += step
        edges.append(a)
        cum.append(big_h)
    return np.array(edges), np.array(cum), slope


def _gauss(v, p, cell_hazard, cells_least, reach, ripple):  # type: ignore[no-untyped-def]
    """(age, weight) of model.steady_population(rule="gauss"): two cohorts per cell at its Gauss points (the cells
    cut by :func:`_refine` where ``reach`` and ``ripple`` ask for it)."""
    edges, cum, slope = _march(v, p, cell_hazard, cells_least)
    if reach > 0.0 and ripple > 0.0:
        edges, cum = _refine(edges, cum, v, p, slope, reach, ripple)
    n = edges.size - 1
    age = np.empty(2 * n)
    weight = np.empty(2 * n)
    total = 0.0
    for k in range(n):
        a0 = edges[k]
        width = edges[k + 1] - a0
        r0 = math.exp(_log_rate(a0, v, slope, p))
        for j in range(2):
            ag = a0 + (0.5 - GAUSS if j == 0 else 0.5 + GAUSS) * width
            r_mid = math.exp(_log_rate(0.5 * (a0 + ag), v, slope, p))
            r_end = math.exp(_log_rate(ag, v, slope, p))
            part = (ag - a0) * (r0 + 4.0 * r_mid + r_end) / 6.0
            age[2 * k + j] = ag
            weight[2 * k + j] = 0.5 * width * math.exp(-(cum[k] + part))
            total += weight[2 * k + j]
    birth = p[P_N0] / (p[P_TAU] + total)
    for k in range(2 * n):
        weight[k] *= birth
    return age, weight


def _lumping(x):  # type: ignore[no-untyped-def]
    """The lumping ripple of cells h = x/g wide, in units of (e/pi) D/g^2 (:func:`_refine`): the Gauss pairs'
    harmonics k = 1, 2, 3 at 2 pi k/h, each |cos(2 pi k GAUSS)|/k times |Gamma(1 - 2 pi i k/x)|."""
    out = 0.0
    for k in range(1, 4):
        arg = 2.0 * math.pi * math.pi * k / x  # pi y, y = 2 pi k/x
        if arg > 700.0:
            break
        gamma = 1.0 if arg < 1e-6 else math.sqrt(arg / math.sinh(arg))
        out += abs(math.cos(2.0 * math.pi * k * GAUSS)) / k * gamma
    return x * out


def _need(a, hazard, v, p, slope, scale, ripple):  # type: ignore[no-untyped-def]
    """1/h: the inverse of the widest cell whose cohorts, passing age ``a`` (cumulative hazard ``hazard`` there),
    leave a lumping ripple within ``ripple`` of the stress (``scale``: the integral of S f over the ages); 0 where the
    hazard does not rise with age (no cliff) or nothing dies there."""
    g = p[P_FORCE_SENS] * _stiffness(v * a, p[P_M], p[P_DLM]) * v - slope * _aging_clock(a, p)[1]
    if not g > 0.0:
        return 0.0
    force = _force(v * a, p[P_M], p[P_DLM])
    if not force > 0.0:
        return 0.0
    log_death = _log_rate(a, v, slope, p) - hazard + math.log(force / scale)
    if log_death < -700.0:
        return 0.0
    # the ripple (e/pi) (D/g^2) _lumping(h g) <= ripple, D = r S f/scale the stress dying per unit age
    log_quota = math.log(ripple * math.pi / math.e * g * g) - log_death
    if log_quota > 30.0:  # cells far wider than the cliff: _lumping(x) is x times its harmonics' sum, 0.905
        return 0.0
    quota = math.exp(log_quota)
    lo, hi = 0.05, 2.0 * quota + 10.0
    if _lumping(hi) <= quota:
        return g / hi
    for _ in range(60):
        mid = math.sqrt(lo * hi)
        if _lumping(mid) <= quota:
            lo = mid
        else:
            hi = mid
        if hi < 1.001 * lo:
            break
    return g / lo


def _cut_cells(edges, cum, v, p, slope, reach, ripple):  # type: ignore[no-untyped-def]
    """How many equal parts each cell takes: enough that its cohorts, swept over the ages [a_k, a_k+1 + reach] the
    run carries them through, stay within ``ripple`` wherever they die on a rising hazard (:func:`_need` at every
    edge of that window, and at its far end), and that up to where the most stress dies (the cliff) the cell keeps
    the march's resolution of the chain force, WALL_CELL of its distance from the FENE wall, where it arrives."""
    n = edges.size - 1
    t_max = p[P_DLM] / v
    scale = 0.0
    for k in range(n):
        f0 = _force(v * edges[k], p[P_M], p[P_DLM]) * math.exp(-cum[k])
        f1 = _force(v * edges[k + 1], p[P_M], p[P_DLM]) * math.exp(-cum[k + 1])
        scale += 0.5 * (f0 + f1) * (edges[k + 1] - edges[k])
    need = np.empty(n + 1)
    cliff, most_death = edges[n], -np.inf  # where r S f, the stress dying per unit age, peaks
    for j in range(n + 1):
        need[j] = _need(edges[j], cum[j], v, p, slope, scale, ripple)
        force = max(_force(v * edges[j], p[P_M], p[P_DLM]), 1e-300)
        death = _log_rate(edges[j], v, slope, p) - cum[j] + math.log(force)
        if death > most_death:
            cliff, most_death = edges[j], death
    parts = np.ones(n, dtype=np.int64)
    queue = np.empty(n + 1, dtype=np.int64)  # the window's edges, their need decreasing (a sliding maximum)
    head, tail, nxt = 0, 0, 0
    for k in range(n):
        far = edges[k + 1] + reach
        while nxt <= n and edges[nxt] <= far:
            while tail > head and need[queue[tail - 1]] <= need[nxt]:
                tail -= 1
            queue[tail] = nxt
            tail += 1
            nxt += 1
        while tail > head and queue[head] < k:
            head += 1
        most = need[queue[head]] if tail > head else 0.0
        if nxt <= n:  # the window ends inside cell nxt - 1: its far end, its hazard by Simpson from that cell's start
            a0 = edges[nxt - 1]
            r0 = math.exp(_log_rate(a0, v, slope, p))
            r1 = math.exp(_log_rate(0.5 * (a0 + far), v, slope, p))
            r2 = math.exp(_log_rate(far, v, slope, p))
            hazard = cum[nxt - 1] + (far - a0) * (r0 + 4.0 * r1 + r2) / 6.0
            most = max(most, _need(far, hazard, v, p, slope, scale, ripple))
        arrival = min(far, cliff)
        if arrival > edges[k + 1]:
            most = max(most, 1.0 / (WALL_CELL * (t_max - arrival)))
        cut = most * (edges[k + 1] - edges[k])
        if cut > 1.0:
            parts[k] = math.ceil(min(cut, 1e9))
    return parts


def _refine(edges, cum, v, p, slope, reach, ripple):  # type: ignore[no-untyped-def]
    """The march's cells cut into equal parts where :func:`_cut_cells` asks, each part's hazard by Simpson's rule;
    at most REFINED_MOST cells added, from the oldest cells down (those reach the cliff first)."""
    parts = _cut_cells(edges, cum, v, p, slope, reach, ripple)
    n = edges.size - 1
    added = 0
    for k in range(n - 1, -1, -1):
        if added + parts[k] - 1 > REFINED_MOST:
            for j in range(k + 1):
                parts[j] = 1
            break
        added += parts[k] - 1
    if added == 0:
        return edges, cum
    out_edges = np.empty(n + 1 + added)
    out_cum = np.empty(n + 1 + added)
    out_edges[0], out_cum[0] = edges[0], cum[0]
    i = 0
    for k in range(n):
        if parts[k] == 1:
            out_edges[i + 1] = edges[k + 1]
            out_cum[i + 1] = out_cum[i] + (cum[k + 1] - cum[k])
            i += 1
            continue
        h = (edges[k + 1] - edges[k]) / parts[k]
        for j in range(parts[k]):
            a0 = edges[k] + j * h
            a1 = edges[k + 1] if j == parts[k] - 1 else a0 + h
            r0 = math.exp(_log_rate(a0, v, slope, p))
            r1 = math.exp(_log_rate(0.5 * (a0 + a1), v, slope, p))
            r2 = math.exp(_log_rate(a1, v, slope, p))
            out_edges[i + 1] = a1
            out_cum[i + 1] = out_cum[i] + (a1 - a0) * (r0 + 4.0 * r1 + r2) / 6.0
            i += 1
    return out_edges, out_cum


def _cells(v, p, cell_hazard):  # type: ignore[no-untyped-def]
    dlm, m = p[P_DLM], p[P_M]
    edges, cum, slope = _march(v, p, cell_hazard, 1000.0)
    n = len(edges) - 1
    mid = np.empty(n)
    width = np.empty(n)
    w = np.empty(n)
    total = 0.0
    for k in range(n):
        mid[k] = 0.5 * (edges[k] + edges[k + 1])
        width[k] = edges[k + 1] - edges[k]
        dh = cum[k + 1] - cum[k]
        s0 = math.exp(-cum[k])
        w[k] = (s0 * -math.expm1(-dh) / dh if dh > 1e-12 else s0 * (1.0 - 0.5 * dh)) * width[k]
        total += w[k]
    birth = p[P_N0] / (p[P_TAU] + total)
    f = np.empty(n)
    fp = np.empty(n)
    r = np.empty(n)
    gv = np.empty(n)
    energy = 0.0
    for k in range(n):
        w[k] *= birth
        e = v * mid[k]
        f[k] = _force(e, m, dlm)
        fp[k] = _stiffness(e, m, dlm)
        r[k] = math.exp(_log_rate(mid[k], v, slope, p))
        gv[k] = _aging_clock(mid[k], p)[0] * slope / p[P_VA]
        energy += w[k] * _energy(e, m, dlm)
    return mid, w, width, f, fp, r, gv, energy
