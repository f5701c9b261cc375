"""The steady population of Eqs 6-7 as cells, compiled: model.steady_population's march in numba.

Two layouts of the same march: the Gauss rule's two cohorts per cell (:func:`steady_cohorts`, the solver's steady
starts and rebuilt populations) and one cohort per cell at its middle with its force, stiffness, hazard and aging
sensitivity (:func:`_steady_cells`: the quasi-steady reduction's lag and the linear stability's response).  Apart
from both so that neither imports the other for it.
"""

from __future__ import annotations

import math

import numpy as np

from ..parameters import Parameters
from . import kernel
from .kernel import P_AGING, P_DLM, P_FORCE_SENS, P_INV_TAU_A, P_LOG_U0_TAU, P_M, P_N0, P_TAU, P_VA
from .model import CELL_HAZARD, GAUSS, MAX_CELLS

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
        for name in ("_log_rate", "_march"):
            g[name] = njit(cache=True)(g[name])
        _CELLS.append(njit(cache=True)(_cells))
        _CELLS.append(njit(cache=True)(_gauss))
    return _CELLS[0]


def steady_cohorts(  # type: ignore[no-untyped-def]
    params: Parameters, velocity: float, aging: bool, cell_hazard: float = CELL_HAZARD, cells_least: float = 1000.0
):
    """model.steady_population(params, velocity, aging) (the Gauss rule), compiled: the same cohorts, faster."""
    from .model import Population, pack_parameters, steady_population

    if not (velocity > 0 and math.isfinite(velocity)):
        return steady_population(params, velocity, aging)  # its error, in words
    _steady_cells()
    age, weight = _CELLS[1](float(velocity), pack_parameters(params, aging, 1.0), cell_hazard, cells_least)
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
        step = min(step, 0.05 * (t_max - a))
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


def _gauss(v, p, cell_hazard, cells_least):  # type: ignore[no-untyped-def]
    """(age, weight) of model.steady_population(rule="gauss"): two cohorts per cell at its Gauss points."""
    edges, cum, slope = _march(v, p, cell_hazard, cells_least)
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
