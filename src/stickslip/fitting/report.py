"""Markdown reports of the fits (also the plain-text output of ``stickslip fit``).

The fits' ``report()`` methods call down here; this module names none of their types (a ``SteadyFit``, a
``StickFit``: ``Any`` below), so the fits and their reports form no import loop (tests/test_import_graph.py).
The posterior's report is written in :mod:`stickslip.fitting.bayes` with the helpers of this module.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .results import Estimate, display_unit, human


def _table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return lines


def _g(x: float | None, digits: int = 4) -> str:
    if x is None or not np.isfinite(x):
        return "—"
    return f"{x:.{digits}g}"


def _interval(e: Estimate, size: float = 1.0) -> str:
    if e.interval is None:
        return "—"
    lo, hi = e.interval
    return f"[{'unbounded' if lo is None else _g(lo / size)}, {'unbounded' if hi is None else _g(hi / size)}]"


def _scaled(x: float | None, size: float, digits: int) -> str:
    return "—" if x is None else _g(x / size, digits)


def estimate_rows(estimates: Sequence[Estimate], with_key: bool = True) -> list[list[str]]:
    rows = []
    for e in estimates:
        unit, size = display_unit(e.value, e.dimension)
        status = "fixed: " + e.note if e.fixed else (e.note or e.status)
        first = [f"`{e.key}`", e.symbol] if with_key else [e.symbol]
        rows.append([*first, _scaled(e.value, size, 6), _scaled(e.stderr, size, 3), _interval(e, size), unit, status])
    return rows


def _messages(messages: Sequence[str]) -> list[str]:
    if not messages:
        return []
    return ["## Notes", "", *[f"- {m}" for m in messages], ""]


def _parameters(estimates: Sequence[Estimate], level: str) -> list[str]:
    header = ["key", "symbol", "value", "std. error", f"{level} interval", "unit", "status"]
    return ["## Parameters", "", *_table(header, estimate_rows(estimates)), ""]


def _correlation(keys: Sequence[str], matrix: np.ndarray) -> list[str]:
    if not keys:
        return []
    header = ["", *[f"`{k.split('.')[1]}`" for k in keys]]
    rows = [[f"`{k.split('.')[1]}`", *[_g(x, 3) for x in row]] for k, row in zip(keys, matrix, strict=True)]
    return ["## Correlation of the fitted ln-parameters", "", *_table(header, rows), ""]


def steady_report(fit: Any) -> str:
    """The Markdown report of a :class:`stickslip.fitting.SteadyFit`."""
    level = f"{100 * fit.level:g} %"
    data = fit.data
    lines = [
        "# Steady friction fit",
        "",
        *([f"**Fit failed:** {fit.reason}.", ""] if fit.status != "ok" else []),
        f"- data: `{data.source}`, {len(data)} points, {human(float(data.velocity.min()), 'velocity')} to"
        f" {human(float(data.velocity.max()), 'velocity')}",
        f"- method: {fit.method}" + (f" (split at {human(fit.split, 'velocity')})" if fit.split else ""),
        f"- noise: {fit.noise}",
        (
            "- no model fitted: the data were compared with a constant stress"
            if fit.flat_level is not None
            else goodness_line(fit.chi_square, fit.dof, fit.noise_estimated)
        ),
        f"- intervals: {level}; parameters {_parameter_interval_method(fit)}; Vc and σc by {fit.interval_method}",
        "",
        "## Critical point (Eq 9)",
        "",
        *_table(
            ["quantity", "value", "std. error", f"{level} interval", "unit", "method"],
            estimate_rows((fit.critical_velocity, fit.critical_stress), with_key=False),
        ),
        "",
        *_messages(fit.messages),
        *_parameters(fit.estimates, level),
        "## Identifiable combinations",
        "",
        "σ(V) depends on the parameters only through these (docs/fitting.md).",
        "",
        *_table(
            ["combination", "value", "std. error", f"{level} interval", "unit", "status"],
            estimate_rows(fit.combinations, with_key=False),
        ),
        "",
        *_correlation(fit.free_keys, fit.correlation),
        "## Fit steps",
        "",
        *_table(
            ["step", "fitted", "points", "χ²", "evaluations", "status"],
            [
                [
                    s.name,
                    ", ".join(f"`{k}`" for k in s.keys) or "—",
                    str(s.points),
                    _g(s.chi_square),
                    str(s.nfev),
                    s.message,
                ]
                for s in fit.stages
            ],
        ),
        "",
        *_residual_table(fit),
    ]
    return "\n".join(lines)


def _parameter_interval_method(fit: Any) -> str:
    if getattr(fit, "parameter_intervals", "wald") == "profile":
        return "by profile likelihood (combinations carried by one key likewise, the others symmetric in ln)"
    return "symmetric in ln (Wald)"


#: Longest residual table printed in full; longer records get a summary and their largest residuals.
RESIDUAL_ROWS = 60


def _residual_table(fit: Any) -> list[str]:
    data = fit.data
    picks = np.arange(len(data))
    lines = ["## Residuals", ""]
    if len(data) > RESIDUAL_ROWS:
        z = fit.residuals
        picks = np.sort(np.argsort(-np.abs(z), kind="stable")[:10])
        lines += [
            f"{len(data)} points: rms of (data − fit)/error {float(np.sqrt(np.mean(z * z))):.3g}, mean"
            f" {float(np.mean(z)):+.3g}; the 10 largest in absolute value (all of them: --json or the Python API):",
            "",
        ]
    rows = [
        [str(data.rows[k]), _g(data.velocity[k] * 1e6, 5), _g(data.stress[k], 5), _g(fit.model_stress[k], 5),
         f"{fit.residuals[k]:+.2f}"]
        for k in picks
    ]  # fmt: skip
    return [*lines, *_table(["row", "V (µm/s)", "σ (Pa)", "fit (Pa)", "(data − fit)/error"], rows), ""]


def goodness_line(chi_square: float, dof: int, noise_estimated: bool) -> str:
    """The χ² line of a report: with the noise estimated from the residuals χ²ᵣ is 1 by construction."""
    if noise_estimated:
        return (
            f"- χ²ᵣ = 1 by construction (the noise is estimated from the residuals, {dof} degrees of freedom),"
            " so it does not test the fit; judge it by the residuals below"
        )
    return f"- χ² = {_g(chi_square)}, degrees of freedom {dof}, reduced χ² = {_g(chi_square / dof if dof else None)}"


#: How the stick report names where the sticks start (``fit stick --start-stress``).
_START_MODES = {
    "measured": "measured (each row's start_stress; σc of the bond parameters where a cell is empty)",
    "model": "the bond parameters' σc in every row (--start-stress model)",
}


def _stick_combinations(combinations: Sequence[Estimate], level: str) -> list[str]:
    if not combinations:
        return []
    header = ["combination", "value", "std. error", f"{level} interval", "unit", "status"]
    return ["## Identifiable combination", "", *_table(header, estimate_rows(combinations, with_key=False)), ""]


def stick_report(fit: Any) -> str:
    """The Markdown report of a :class:`stickslip.fitting.StickFit`."""
    level = f"{100 * fit.level:g} %"
    data = fit.data
    rows = []
    for k in range(len(data)):
        used = bool(fit.used[k])
        rows.append(
            [
                str(data.rows[k]),
                _g(data.pulling_velocity[k] * 1e6, 4),
                _g(fit.start_stress[k], 4),
                _g(data.stick_time[k], 4),
                _g(fit.model_stick_time[k], 4) if used else "—",
                _g(data.peak_stress[k], 4) if data.peak_stress is not None else "—",
                _g(fit.model_peak_stress[k], 4) if used else "—",
                "fitted" if used else "left out: " + fit.excluded.get(int(data.rows[k]), ""),
            ]
        )
    lines = [
        "# Stick-phase fit (Eqs 13-16)",
        "",
        *([f"**Fit failed:** {fit.reason}.", ""] if fit.status != "ok" else []),
        f"- data: `{data.source}`, {fit.rows_line()}",
        f"- noise: {fit.noise}",
        goodness_line(fit.chi_square, fit.dof, True),
        f"- intervals: {level}, symmetric in ln (Wald)"
        + (f"; {fit.intervals_note}" if getattr(fit, "intervals_note", "") else ""),
        *([f"- start stresses: {_START_MODES[fit.start_stress_mode]}"] if hasattr(fit, "start_stress_mode") else []),
        "",
        *_messages(fit.messages),
        *_parameters(fit.estimates, level),
        *_stick_combinations(getattr(fit, "combinations", ()), level),
        *_correlation(fit.free_keys, fit.correlation),
        "## Rows",
        "",
        *_table(["row", "V0 (µm/s)", "start σ (Pa)", "ts (s)", "fit ts (s)", "σs (Pa)", "fit σs (Pa)", "use"], rows),
        "",
    ]
    return "\n".join(lines)
