"""The report's model steps run once, as `build_report` runs them before its figures (shared by the report tests)."""

from __future__ import annotations

from stickslip.parameters import Parameters
from stickslip.report.computations import ModelRun, run_steps


def model_run(params: Parameters) -> ModelRun:
    """A ModelRun of ``params`` with every step of :func:`run_steps` done."""
    model = ModelRun(params)
    for _name, step in run_steps():
        step(model)
    return model
