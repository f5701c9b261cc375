"""The steady stress for many parameter sets at once (finite-difference Jacobians, MCMC walkers).

:func:`stickslip.model.steady.steady_state` is vectorised over velocities but
takes one parameter set; its cost is mostly per call, so evaluating 16 sets
one by one costs about 8 times one call with 16 times the velocities.
:func:`stress_many` therefore uses, in order of preference:

1. ``stickslip.model.steady.steady_stress_batch`` if the model module provides it;
2. one quadrature march over all sets that share the FENE strength
   a = lambda M dl_m/kT (the only group of Eq 6 that ``steady_state``'s
   march holds common to all velocities), built from the model module's
   internal helpers; this path is checked against ``steady_state`` on first
   use and abandoned for good if the two disagree or the internals changed;
3. a plain loop over ``steady_state``.

Rows of sets for which the model has no finite answer are NaN.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import ModelError, ParameterError
from ..model import steady as steady_module
from ..model.steady import steady_state
from ..parameters import BOLTZMANN, Parameters

#: Largest relative difference from steady_state accepted when checking the grouped path.
CHECK_TOLERANCE = 1e-12
_grouped_path_ok: bool | None = None  # None: not checked yet


def _fene_strength(p: Parameters) -> float:
    b = p.bonds
    return b.activation_length * b.chain_stiffness * b.max_extension / (BOLTZMANN * b.temperature)


def _loop(params_list: Sequence[Parameters], velocity: np.ndarray, aging: bool) -> np.ndarray:
    out = np.full((len(params_list), velocity.size), np.nan)
    for k, p in enumerate(params_list):
        try:
            out[k] = steady_state(p, velocity, aging=aging).stress
        except (ModelError, ParameterError):
            pass
    return out


def _grouped(params_list: Sequence[Parameters], velocity: np.ndarray, aging: bool) -> np.ndarray:
    """One march for sets sharing ``a`` (raises AttributeError/TypeError if the internals changed)."""
    scales = [steady_module._scales(p, velocity, aging) for p in params_list]
    joined = steady_module._Scales(
        log_t=np.concatenate([s.log_t for s in scales]),
        a=scales[0].a,
        alpha=np.concatenate([s.alpha for s in scales]),
        beta=np.concatenate([s.beta for s in scales]),
        birth=np.concatenate([s.birth for s in scales]),
    )
    got = steady_module._march(joined, steady_module.DEFAULT_QUADRATURE)
    stress_scale = np.repeat(
        [p.bonds.chain_stiffness * p.bonds.site_density * p.bonds.max_extension for p in params_list], velocity.size
    )
    return (stress_scale * got.j / (joined.birth + got.i)).reshape(len(params_list), velocity.size)


def _check_grouped(params: Parameters, velocity: np.ndarray, aging: bool) -> bool:
    try:
        twin = _grouped([params, params], velocity, aging)
        reference = steady_state(params, velocity, aging=aging).stress
    except (AttributeError, TypeError, ValueError, ModelError, ParameterError):
        return False
    return bool(np.all(np.abs(twin / reference - 1.0) <= CHECK_TOLERANCE))


def stress_many(params_list: Sequence[Parameters], velocity: np.ndarray, aging: bool = True) -> np.ndarray:
    """sigma(V) of Eqs 6-8, shape (len(params_list), len(velocity)); NaN rows where the model fails."""
    global _grouped_path_ok
    velocity = np.asarray(velocity, dtype=float).ravel()
    public = getattr(steady_module, "steady_stress_batch", None)
    if public is not None:
        return np.asarray(public(list(params_list), velocity, aging=aging), dtype=float)
    if len(params_list) < 2 or any(p.bonds.activation_length == 0.0 for p in params_list):
        return _loop(params_list, velocity, aging)
    if _grouped_path_ok is None:
        _grouped_path_ok = _check_grouped(params_list[0], velocity, aging)
    if not _grouped_path_ok:
        return _loop(params_list, velocity, aging)
    out = np.full((len(params_list), velocity.size), np.nan)
    groups: dict[float, list[int]] = {}
    for k, p in enumerate(params_list):
        groups.setdefault(_fene_strength(p), []).append(k)
    for members in groups.values():
        subset = [params_list[k] for k in members]
        try:
            values = _grouped(subset, velocity, aging) if len(subset) > 1 else _loop(subset, velocity, aging)
        except (ModelError, ParameterError, FloatingPointError):
            values = _loop(subset, velocity, aging)  # isolate the set that fails
        bad = ~np.all(np.isfinite(values), axis=1)
        if np.any(bad) and len(subset) > 1:
            values[bad] = _loop([s for s, b in zip(subset, bad, strict=True) if b], velocity, aging)
        out[members] = values
    return out


def reset_check() -> None:
    """Forget the result of the grouped-path check (for tests)."""
    global _grouped_path_ok
    _grouped_path_ok = None
