"""A friction model written outside the package, for the CLI tests: stress = c V on a rigid rig.

``--model viscous_model:MODEL``; ``--set fail=1`` (or the setting ``fail=true``) makes its run report failure.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stickslip.models import Capabilities, FrictionModel, Run


class Viscous(FrictionModel):
    name = "test-viscous"
    description = "stress = c V (a test model)"
    capabilities = Capabilities(controls=("velocity",), settings=("fail",))

    def dimensions(self) -> dict[str, str]:
        return {"c": "stress_per_velocity", "fail": "dimensionless"}

    def parameters(self, spec: Any = None, overrides: Any = None) -> dict[str, float]:
        from stickslip.units import to_si

        given = dict(overrides or {})
        return {"c": to_si(given.get("c", 1e6), "stress_per_velocity", "c"), "fail": float(given.get("fail", 0))}

    def run(self, params: Any, protocol: Any, rig: Any = None, *, start: Any = None, **settings: Any) -> Run:
        self.check(protocol, rig, settings)
        t = np.linspace(0.0, protocol.duration, 201)
        v = protocol.velocity_at(t)
        x = np.concatenate([[0.0], np.cumsum(np.diff(t) * v[1:])])
        failed = bool(settings.get("fail")) or params["fail"] != 0
        return Run.from_trace(self.name, t, stress=params["c"] * v, slider_velocity=v, slider_position=x,
                              load_point_position=x, status="failed" if failed else "ok",
                              message="told to fail" if failed else "")  # fmt: skip


MODEL = Viscous()


def forget() -> None:
    """Take the model out of the registry again (``--model viscous_model:MODEL`` registers it for the process)."""
    from stickslip.models import registry

    if registry.available_models().get(MODEL.name) is MODEL:
        registry.unregister_model(MODEL.name)
