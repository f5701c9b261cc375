"""Rate-and-state friction on a spring-slider (:func:`stickslip.rsf.simulate`) behind the interface."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from .. import regimes
from ..errors import ParameterError
from ..protocols import Protocol
from ..units import shorten
from .base import Boundary, Capabilities, FrictionModel, Rig
from .run import Run, settled_mean

NAN = math.nan
#: Other spellings accepted for keys (the issue's symbols).
ALIASES = {"Dc": "dc", "η": "eta"}


class RSFModel(FrictionModel):
    """Rate-and-state friction (one state variable from keys, or any :class:`stickslip.rsf.RSFParams`).

    ``k`` is the spring stiffness in friction per slip (1/m) and ``eta`` the radiation damping in friction per
    velocity (s/m); a rig's K (Pa/m), damping (Pa s/m) and mass need ``normal_stress`` to be read in those
    terms.  ``start``: the slider's velocity (m/s) in the initial steady state (default: the first segment's).
    """

    name = "rsf"
    aliases = ("rate-and-state", "rate-state")
    start_dimension = "velocity"
    start_words = ()
    description = "rate-and-state friction on a spring-slider (Dieterich-Ruina laws)"
    capabilities = Capabilities(
        controls=("spring",), protocols="any", damping=True, mass=True, settings=("every", "times", "rtol", "atol")
    )
    sweep_columns: ClassVar[Mapping[str, str]] = {
        "regime": "str",
        "period": "float",
        "peak_friction": "float",
        "trough_friction": "float",
        "mean_friction": "float",
        "growth": "float",
        "critical_stiffness": "float",
    }
    #: key -> dimension (``law`` is taken too: a name, kept in a sweep's numbers as its index in LAW_NAMES)
    requires = ("stickslip.rsf",)
    KEYS: Mapping[str, str] = {
        "a": "dimensionless",
        "b": "dimensionless",
        "dc": "length",
        "k": "per_length",
        "eta": "slowness",
        "mu0": "dimensionless",
        "v_ref": "velocity",
        "normal_stress": "stress",
    }
    LAW_NAMES = ("aging", "slip", "prz")  # the laws with one state variable and no further constant
    #: a sweep point starts in steady sliding at this times the pulling velocity: from exactly the steady
    #: state an unstable slider would never leave it, so the step seeds the oscillation whose fate is reported
    START_STEP = 1.1

    @classmethod
    def sweep_start(cls, protocol: Protocol) -> float:
        velocity = protocol.segments[0].velocity
        if not velocity > 0:  # the start is steady sliding at a step above it
            raise ParameterError(f"pulling_velocity: expected a value > 0 m/s, got {velocity:g}")
        return cls.START_STEP * velocity

    def dimensions(self) -> dict[str, str]:
        return dict(self.KEYS)

    def describe_start(self, start: Any, protocol: Protocol, settings: Any = None) -> str:
        from ..display import velocity

        shown = velocity(protocol.segments[0].velocity if start is None else float(start), 4)
        return f"steady sliding at {shown}"

    def parameters(self, spec: Any = None, overrides: Mapping[str, Any] | None = None) -> Any:
        """:class:`stickslip.rsf.RSFParams` from ``spec`` (RSFParams, a mapping as in a TOML file, or None for
        the defaults) and ``overrides`` of :attr:`KEYS` and ``law`` (a name, or its index in :attr:`LAW_NAMES`)."""
        from ..rsf import RSFParams, rsf_params
        from ..units import override_to_si

        if overrides is not None and not isinstance(overrides, Mapping):
            raise ParameterError(f"overrides: expected a mapping {{key: value}}, got {type(overrides).__name__}")
        if spec is None:
            base = RSFParams()
        elif isinstance(spec, RSFParams):
            base = spec
        elif isinstance(spec, Mapping):
            base = RSFParams.from_dict(spec)
        else:
            raise ParameterError(f"rsf parameters: expected RSFParams or a mapping, got {type(spec).__name__}")
        if not overrides:
            return base
        values = self.values(base)
        for given, raw in overrides.items():
            key = ALIASES.get(given, given)  # --set Dc=..., η=... as --vary takes them
            if key == "law":
                values["law"] = float(self._law_code(raw))
            elif key in self.KEYS:
                values[key] = override_to_si(raw, self.KEYS[key], key, values.get(key))
            else:
                expected = ", ".join((*self.KEYS, "law"))
                raise ParameterError(f"unknown rate-and-state key {shorten(given)}; expected one of: {expected}")
        _refuse_unphysical(values, overrides)
        return rsf_params(
            values["a"],
            values["b"],
            values["dc"],
            law=self.LAW_NAMES[int(values.get("law", 0))],
            mu0=values["mu0"],
            v_ref=values["v_ref"],
            stiffness=values["k"],
            eta=values["eta"],
            normal_stress=values.get("normal_stress"),
            cutoff=base.cutoff,  # the friction form is not a key: an override keeps the one given
        )

    def _law_code(self, raw: Any) -> int:
        if isinstance(raw, (int, float)) and not isinstance(raw, bool) and float(raw) in range(len(self.LAW_NAMES)):
            return int(raw)
        name = str(raw).strip().lower()
        if name not in self.LAW_NAMES:
            from ..rsf.laws import LAWS

            others = sorted(set(LAWS) - set(self.LAW_NAMES))
            beyond = (
                f" ({', '.join(others)}: a further constant or state, through stickslip rsf simulate --law)"
                if others
                else ""
            )
            raise ParameterError(f"law: expected one of {', '.join(self.LAW_NAMES)}{beyond}, got {shorten(raw)}")
        return self.LAW_NAMES.index(name)

    def values(self, params: Any) -> dict[str, float]:
        """The keys' SI values (``law`` as its index in LAW_NAMES): one state variable of those laws only."""
        state = params.states[0]
        if len(params.states) != 1 or state.law not in self.LAW_NAMES:
            raise ParameterError(
                f"rsf parameters: keys hold one state variable of the {', '.join(self.LAW_NAMES)} law, got"
                f" {len(params.states)} of the {', '.join(s.law for s in params.states)} law"
            )
        law = self.LAW_NAMES.index(state.law)
        fixed = {"a": params.a, "b": state.b, "dc": state.dc, "k": params.stiffness, "eta": params.eta}
        fixed.update(mu0=params.mu0, v_ref=params.v_ref, law=float(law))
        if params.normal_stress is not None:
            fixed["normal_stress"] = params.normal_stress
        return fixed

    def label(self, params: Any) -> str:
        return f"rate-and-state, {params.states[0].law} law"

    def run(
        self, params: Any, protocol: Protocol, rig: Rig | None = None, *, start: Any = None, **settings: Any
    ) -> Run:
        from ..rsf import RSFParams, simulate

        rig = self.check(protocol, rig, settings)
        if not isinstance(params, RSFParams):
            raise ParameterError(f"params: expected RSFParams (model rsf), got {type(params).__name__}")
        params = _with_rig(params, rig)
        result = simulate(params, protocol, start_velocity=start, **settings)
        return rsf_run(result)

    def spring(self, params: Any, rig: Rig) -> tuple[float, str, str] | None:
        """The spring the run uses, in friction per slip (1/m): the rig's K over the normal stress, else ``k``."""
        if rig.control != "spring":
            return None
        return float(_with_rig(params, rig).stiffness), "1/m", "parameters" if rig.stiffness is None else "rig"

    def stability_boundary(self, fixed: Any, x: str, y: str | None, frame: Any = None) -> list[Boundary]:
        """k = kc from :func:`stickslip.rsf.critical_stiffness`, against the other axis when k is on one."""
        from ..rsf import critical_stiffness

        if frame is None or "k" not in (x, y):
            return []
        other = y if x == "k" else x
        if other == "pulling_velocity":  # kc(V) on a fine grid (it depends on V through eta V)
            params = self.parameters(None, {k: v for k, v in fixed.items() if k != "pulling_velocity"})
            lo, hi = float(frame[other].min()), float(frame[other].max())
            along = np.geomspace(lo, hi, 80) if lo > 0 and hi > lo else np.array([lo, hi])
            critical = np.array([critical_stiffness(params, v) for v in along], dtype=float)
        elif other in frame:
            kc = frame.groupby(other)["critical_stiffness"].median().dropna()
            along, critical = kc.index.to_numpy(dtype=float), kc.to_numpy(dtype=float)
        elif other is None and "critical_stiffness" in frame:  # k alone varied: one kc, a vertical line
            critical, along = np.full(2, float(frame["critical_stiffness"].median())), np.full(2, np.nan)
        else:
            return []
        keep = critical > 0  # kc = 0: steady sliding is stable at every stiffness there, no boundary
        curve = (critical[keep], along[keep]) if x == "k" else (along[keep], critical[keep])
        return [Boundary(curve[0], curve[1], "k = kc (rsf.critical_stiffness)")]


def _with_rig(params: Any, rig: Rig) -> Any:
    """The spring, damping and mass of the rig in rate-and-state's terms (per unit normal stress)."""
    given = {"stiffness": rig.stiffness, "eta": rig.damping, "mass": rig.mass}
    given = {k: v for k, v in given.items() if v is not None}
    if not given:
        return params
    sigma = params.normal_stress
    if sigma is None:
        raise ParameterError(
            f"rig {', '.join(given)}: rate-and-state reads a rig in friction units; set normal_stress, or give"
            " k (1/m) and eta (s/m) in the parameters instead"
        )
    changes = {k: (v if k == "mass" else v / sigma) for k, v in given.items()}
    return params.replace(**changes)


def rsf_run(result: Any) -> Run:
    """The :class:`Run` of a :class:`stickslip.rsf.RSFRun` (its regime is already the classifier's, from the
    solver's dense solution)."""
    from ..rsf import critical_stiffness

    r = result.regime
    params, protocol = result.params, result.protocol
    kind = r.kind  # rate-and-state's regime is the classifier's (stickslip.rsf.Regime), in friction units
    sigma = params.normal_stress
    scale = 1.0 if sigma is None else sigma
    regime = regimes.Regime(
        kind, r.periods, r.growth, r.period, r.peak_friction * scale, r.trough_friction * scale,
        r.evidence or result.summary()["message"],
    )  # fmt: skip
    # the solver's integral over the settled window where it was carried; the rows' otherwise (a fit's runs)
    settled = result.settled_mean_friction
    begin = float(protocol.boundaries[-2])  # the settled window lies in the last segment, as the solver's does
    mean = settled if math.isfinite(settled) else settled_mean(result.time, result.friction, r.period, begin)
    velocity = protocol.segments[-1].velocity  # the last segment's, whose regime is reported
    kc = critical_stiffness(params, velocity) if velocity > 0 else NAN
    summary = {
        "regime": r.name,
        "period": r.period,
        "peak_friction": r.peak_friction,
        "trough_friction": r.trough_friction,
        "mean_friction": mean,
        "growth": r.growth,
        "critical_stiffness": kc,
    }
    if math.isfinite(result.run_mean_friction):  # the solver's own mean over the run, not the samples' (run_mean)
        summary["run_mean_friction"] = result.run_mean_friction
        if sigma is not None:  # a run in stress: its mean over the run in Pa (run --json's run_mean_stress)
            summary["run_mean_stress"] = result.run_mean_friction * sigma
    states = {"state" if i == 0 else f"state{i + 1}": row for i, row in enumerate(result.state)}
    return Run(
        model=RSFModel.name,
        time=result.time,
        stress=None if sigma is None else result.friction * sigma,
        friction=result.friction,
        slider_velocity=result.slider_velocity,
        slider_position=result.slider_displacement,
        load_point_position=result.load_point_displacement,
        regime=regime,
        mean=mean * scale,
        states=states,
        state_units=dict.fromkeys(states, "s"),
        summary=summary,
        message=result.summary()["message"],
        status="ok" if result.status == "ok" else "failed",
        native=result,
    )


#: Largest a or |b| an override may give: the terms a ln(V/v_ref), b ln(...) are corrections to mu0 (of order 0.01);
#: one of order 1 already makes friction negative within a decade of velocity.
MAX_RATE_COEFFICIENT = 1.0


def _refuse_unphysical(values: Mapping[str, float], overrides: Mapping[str, Any]) -> None:
    """An override no friction can have: a negative mu0, a or |b| beyond :data:`MAX_RATE_COEFFICIENT`."""

    def shown(key: str) -> str:
        given = next((raw for name, raw in overrides.items() if ALIASES.get(name, name) == key), values[key])
        return f"--set {key}={given}"

    if values["mu0"] < 0:
        raise ParameterError(f"{shown('mu0')}: expected a friction coefficient >= 0")
    for key in ("a", "b"):
        if abs(values[key]) > MAX_RATE_COEFFICIENT:
            raise ParameterError(
                f"{shown(key)}: expected |{key}| <= {MAX_RATE_COEFFICIENT:g} (a rate-and-state coefficient is a small"
                " correction to mu0, typically 0.001 to 0.05)"
            )
