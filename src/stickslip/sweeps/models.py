"""The models a sweep can run, behind one small interface (the model registry).

Each adapter says which keys it accepts (with their dimensions), builds the
fixed values of a sweep, runs one point into a row of plain numbers, and
draws its analytic stability boundary.  The quasi-static cycle is the
package's :func:`stickslip.simulate`; the time-dependent bond model and
rate-and-state are imported lazily from ``stickslip.transient`` and
``stickslip.rsf`` so that a version without them still sweeps the rest, and
says so in one line when asked for them.  The names those modules are
called by are kept here, in one place.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from importlib import import_module
from typing import Any

import numpy as np

from ..errors import ParameterError, StickslipError
from ..parameters import Parameters, key_dimension, load_parameters, parameter_keys, parameters_from_mapping

#: Keys that set the block's stiffness directly (through its height): G_d/h, and K = (G_d/h) ln(B/l)/(B/l - 1).
STIFFNESS_KEYS = {"block.stiffness": "stress_per_length", "block.effective_stiffness": "stress_per_length"}
#: Columns every cycle model reports (SI), beside the inputs, status, message and wall time.
CYCLE_RESULTS = {
    "regime": "str",
    "period": "float",
    "stick_time": "float",
    "peak_stress": "float",
    "jump_velocity": "float",
    "mean_stress": "float",
    "cycles": "int",
}
NAN = float("nan")


@dataclass(frozen=True)
class Boundary:
    """An analytic stability boundary in the plane of two swept keys (SI), with its legend label."""

    x: np.ndarray
    y: np.ndarray
    label: str


def _require(module: str, model: str) -> Any:
    try:
        return import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name is not None and module.startswith(exc.name):
            raise ParameterError(
                f"--model {model}: this version of stickslip has no {module} module; use --model quasi-static"
            ) from None
        raise


# --------------------------------------------------------------------------- the bond model (both forms)
class BondModel:
    """Shared by the quasi-static and the time-dependent bond model: parameter keys, stiffness keys."""

    name = ""
    results: Mapping[str, str] = {**CYCLE_RESULTS, "critical_velocity": "float"}

    def dimensions(self) -> dict[str, str]:
        return {
            "pulling_velocity": "velocity",
            **{k: key_dimension(k) for k in parameter_keys()},
            **STIFFNESS_KEYS,
        }

    def fixed_values(self, params: str | Parameters, overrides: Mapping[str, Any]) -> tuple[dict[str, float], str]:
        """(SI values of every key not varied, the parameter set's name) from ``--params`` and ``--set``."""
        from ..units import to_si

        extra = {k: v for k, v in overrides.items() if k in ("pulling_velocity", *STIFFNESS_KEYS)}
        base = load_parameters(params, {k: v for k, v in overrides.items() if k not in extra})
        fixed = base.as_dict()
        for key, raw in extra.items():
            fixed[key] = to_si(raw, self.dimensions()[key], key)
        return fixed, base.name

    def parameters(self, values: Mapping[str, float]) -> tuple[Parameters, float]:
        """(the parameter set, the pulling velocity) of one point."""
        params = _parameter_set(tuple(values.get(k) for k in parameter_keys()))  # an extension's key may be absent
        block = params.block
        if "block.stiffness" in values:
            params = params.with_overrides({"block.height": block.shear_modulus / _positive(values, "block.stiffness")})
        if "block.effective_stiffness" in values:
            height = block.shear_modulus * block.geometric_factor / _positive(values, "block.effective_stiffness")
            params = params.with_overrides({"block.height": height})
        if "pulling_velocity" not in values:
            raise ParameterError("pulling_velocity: give --v0 V or --vary 'pulling_velocity=...'")
        velocity = values["pulling_velocity"]
        if not velocity >= 0:
            raise ParameterError(f"pulling_velocity: expected a value >= 0 m/s, got {velocity:g}")
        return params, velocity

    def check_keys(self, varied: tuple[str, ...], fixed: Mapping[str, float]) -> None:
        """Refuse two keys that set the same thing (the height and a stiffness)."""
        setting = [k for k in ("block.height", *STIFFNESS_KEYS) if k in varied or (k in STIFFNESS_KEYS and k in fixed)]
        if len(setting) > 1:
            raise ParameterError(f"{' and '.join(setting)} both set the block's height; vary or set only one of them")

    def stiffness_of(self, key: str, params: Parameters, k_effective: np.ndarray) -> np.ndarray:
        """The value of stiffness-like ``key`` at which the effective stiffness is ``k_effective``."""
        factor = params.block.geometric_factor
        if key == "block.effective_stiffness":
            return k_effective
        if key == "block.stiffness":
            return k_effective / factor
        return params.block.shear_modulus * factor / k_effective  # block.height


@lru_cache(maxsize=64)
def _parameter_set(values: tuple[float | None, ...]) -> Parameters:
    """Parameters from the SI values of :func:`parameter_keys`, in that order (validated)."""
    nested: dict[str, dict[str, float]] = {}
    for key, value in zip(parameter_keys(), values, strict=True):
        if value is None:  # an extension's optional key left out: the paper's model
            continue
        section, _, name = key.partition(".")
        nested.setdefault(section, {})[name] = value
    return parameters_from_mapping({"name": "sweep point", **nested}, "sweep point")


def _positive(values: Mapping[str, float], key: str) -> float:
    value = values[key]
    if not value > 0:
        raise ParameterError(f"{key}: expected a positive value, got {value:g}")
    return value


def _mean(time: np.ndarray, stress: np.ndarray) -> float:
    """Time average by the trapezoidal rule (NaN for a single instant)."""
    span = float(time[-1] - time[0]) if time.size else 0.0
    if span <= 0:
        return float(stress[-1]) if stress.size else NAN
    return float(np.sum(np.diff(time) * (stress[1:] + stress[:-1])) / (2.0 * span))


class QuasiStatic(BondModel):
    """The quasi-static stick -> jump -> slip cycle, :func:`stickslip.simulate`."""

    name = "quasi-static"

    def check_available(self) -> None:
        return None

    def run(self, values: Mapping[str, float], settings: Mapping[str, Any]) -> dict[str, Any]:
        from ..model.cycle import simulate

        params, velocity = self.parameters(values)
        sim = simulate(params, velocity, settings["duration"], jump_curve=settings.get("jump_curve", "aging"))
        row: dict[str, Any] = {
            "regime": sim.regime,
            "period": NAN,
            "stick_time": NAN,
            "peak_stress": NAN,
            "jump_velocity": NAN,
            "mean_stress": _mean(sim.time, sim.stress),
            "cycles": sum(c.period is not None for c in sim.cycles),
            "critical_velocity": sim.critical_velocity,
            "message": sim.message,
        }
        # the first stick starts at sigma_c, so the first phases are those of the repeating cycle
        if sim.slip_phases and sim.jumps and sim.jumps[0].velocity is not None:
            stick, slip = sim.stick_phases[0], sim.slip_phases[0]
            row.update(stick_time=stick.stick_time, peak_stress=stick.peak_stress, jump_velocity=sim.jumps[0].velocity)
            if sim.regime == "stick-slip":
                row["period"] = stick.stick_time + slip.duration
                row["mean_stress"] = _cycle_mean(stick, slip, sim.stiffness, velocity)
            elif sim.regime == "steady":
                row["mean_stress"] = slip.end_stress
        return row

    def boundaries(self, spec: Any, frame: Any, x: str, y: str) -> list[Boundary]:
        """V0 = Vc: the critical velocity against the other axis (from the rows' own Vc)."""
        if "pulling_velocity" not in (x, y) or "critical_velocity" not in frame:
            return []
        other = y if x == "pulling_velocity" else x
        if other in frame:
            vc = frame.groupby(other)["critical_velocity"].median().dropna()
            along, critical = vc.index.to_numpy(dtype=float), vc.to_numpy(dtype=float)
        else:
            critical = np.full(2, float(frame["critical_velocity"].median()))
            along = np.array([np.nan, np.nan])
        curve = (critical, along) if x == "pulling_velocity" else (along, critical)
        return [Boundary(curve[0], curve[1], "V0 = Vc (Eq 9)")]


def _cycle_mean(stick: Any, slip: Any, stiffness: float, velocity: float) -> float:
    """Mean stress over the repeating cycle: the stick's is linear in time (Eq 12), the slip's by trapezoids."""
    ts = stick.stick_time
    stick_integral = stick.start_stress * ts + 0.5 * stiffness * velocity * ts * ts
    t, s = slip.time, slip.stress
    slip_integral = float(np.sum(np.diff(t) * (s[1:] + s[:-1])) / 2.0) if t.size > 1 else 0.0
    return (stick_integral + slip_integral) / (ts + slip.duration)


class Transient(BondModel):
    """The time-dependent population balance (Eqs 1-5), ``stickslip.transient.run_transient``."""

    name = "transient"

    def check_available(self) -> None:
        _require("stickslip.transient", self.name)

    def run(self, values: Mapping[str, float], settings: Mapping[str, Any]) -> dict[str, Any]:
        transient = _require("stickslip.transient", self.name)
        from ..protocols import constant

        params, velocity = self.parameters(values)
        protocol = constant(velocity, settings["duration"])
        result = transient.run_transient(
            params,
            protocol,
            control="block",
            start=settings.get("start", "steady"),
            stick_population=bool(settings.get("stick_population", False)),
        )
        whole = [c for c in result.cycles if getattr(c, "period", None) is not None]
        time, stress = np.asarray(result.time, dtype=float), np.asarray(result.stress, dtype=float)
        row: dict[str, Any] = {
            "regime": result.regime,
            "period": NAN,
            "stick_time": NAN,
            "peak_stress": NAN,
            "jump_velocity": NAN,
            "mean_stress": _mean(time, stress),
            "cycles": len(whole),
            "critical_velocity": NAN,
            "message": result.message,
        }
        if whole:  # the last whole cycle: the run has settled onto its cycle by then, if ever
            last = whole[-1]
            row.update(
                period=last.period,
                stick_time=last.stick_time,
                peak_stress=last.peak_stress,
                jump_velocity=last.jump_velocity,
            )
            inside = (time >= whole[0].start_time) & (time <= last.start_time + last.period)
            if np.count_nonzero(inside) > 1:
                row["mean_stress"] = _mean(time[inside], stress[inside])
        return row

    def boundaries(self, spec: Any, frame: Any, x: str, y: str) -> list[Boundary]:
        """Kc(V0) of the linear stability of steady sliding, in the plane (V0, a stiffness key)."""
        stiffness_axes = ("block.height", *STIFFNESS_KEYS)
        if "pulling_velocity" not in (x, y) or not ({x, y} & set(stiffness_axes)):
            return []
        try:
            transient = _require("stickslip.transient", self.name)
        except ParameterError:
            return []
        other = y if x == "pulling_velocity" else x
        params, _ = self.parameters({**spec.fixed, "pulling_velocity": 0.0})
        lo, hi = float(frame["pulling_velocity"].min()), float(frame["pulling_velocity"].max())
        velocity = np.geomspace(max(lo, 1e-12), max(hi, 2e-12), 80)
        kc = np.array([transient.critical_stiffness(params, v) for v in velocity], dtype=float)
        good = np.isfinite(kc) & (kc > 0)
        along = self.stiffness_of(other, params, kc[good])
        curve = (velocity[good], along) if x == "pulling_velocity" else (along, velocity[good])
        return [Boundary(curve[0], curve[1], "K = Kc(V0), linear stability")]


# --------------------------------------------------------------------------- rate-and-state
class RateAndState:
    """Rate-and-state friction on a spring-slider, :func:`stickslip.rsf.simulate` (units as ``rsf simulate``).

    ``k`` is the spring stiffness in friction per slip (1/m) and ``eta`` the radiation damping in friction
    per velocity (s/m), as ``stickslip rsf simulate --stiffness/--eta`` take them without ``--normal-stress``;
    a machine stiffness K in Pa/m is k = K/σ.  ``law`` is a name, kept in the fixed values as its index in
    :attr:`LAW_NAMES` (the specification holds numbers only).  Each point starts in steady sliding at
    :attr:`START_STEP` times the pulling velocity: from exactly the steady state an unstable slider would
    never leave it, so the step seeds the oscillation whose fate the regime reports.
    """

    name = "rsf"
    results: Mapping[str, str] = {
        "regime": "str",
        "period": "float",
        "peak_friction": "float",
        "trough_friction": "float",
        "mean_friction": "float",
        "growth": "float",
        "critical_stiffness": "float",
    }
    #: key -> dimension; defaults are those of :class:`stickslip.rsf.RSFParams` (one source).
    KEYS: Mapping[str, str] = {
        "pulling_velocity": "velocity",
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
    START_STEP = 1.1

    def dimensions(self) -> dict[str, str]:
        return dict(self.KEYS)

    def check_available(self) -> None:
        _require("stickslip.rsf", self.name)

    def fixed_values(self, params: str | Parameters, overrides: Mapping[str, Any]) -> tuple[dict[str, float], str]:
        """rsf's defaults, then ``--set`` (``law=slip`` by name); ``normal_stress`` only when given."""
        from ..units import to_si

        rsf = _require("stickslip.rsf", self.name)
        base = rsf.RSFParams()
        fixed = {"a": base.a, "b": base.b, "dc": base.dc, "k": base.stiffness, "eta": base.eta, "mu0": base.mu0}
        fixed.update(v_ref=base.v_ref, law=0.0)
        for given, raw in overrides.items():
            key = ALIASES.get(given, given)  # --set Dc=..., η=... as --vary takes them
            if key == "law":
                fixed["law"] = float(self._law_code(raw))
            elif key in self.KEYS:
                fixed[key] = to_si(raw, self.KEYS[key], key)
            else:
                expected = ", ".join((*self.KEYS, "law"))
                raise ParameterError(f"--set {given}: unknown rate-and-state key; expected one of: {expected}")
        law = self.LAW_NAMES[int(fixed["law"])]
        return fixed, f"rate-and-state, {law} law"

    def _law_code(self, raw: Any) -> int:
        name = str(raw).strip().lower()
        if name not in self.LAW_NAMES:
            raise ParameterError(f"--set law={raw}: expected one of {', '.join(self.LAW_NAMES)}")
        return self.LAW_NAMES.index(name)

    def check_keys(self, varied: tuple[str, ...], fixed: Mapping[str, float]) -> None:
        return None

    def parameters(self, values: Mapping[str, float]) -> tuple[Any, float]:
        """(the :class:`stickslip.rsf.RSFParams`, the pulling velocity) of one point (validated by rsf)."""
        rsf = _require("stickslip.rsf", self.name)
        if "pulling_velocity" not in values:
            raise ParameterError("pulling_velocity: give --v0 V or --vary 'pulling_velocity=...'")
        velocity = values["pulling_velocity"]
        if not velocity > 0:
            raise ParameterError(f"pulling_velocity: expected a value > 0 m/s, got {velocity:g}")
        params = rsf.rsf_params(
            values["a"],
            values["b"],
            values["dc"],
            law=self.LAW_NAMES[int(values.get("law", 0))],
            mu0=values["mu0"],
            v_ref=values["v_ref"],
            stiffness=values["k"],
            eta=values["eta"],
            normal_stress=values.get("normal_stress"),
        )
        return params, velocity

    def run(self, values: Mapping[str, float], settings: Mapping[str, Any]) -> dict[str, Any]:
        rsf = _require("stickslip.rsf", self.name)
        from ..protocols import constant

        params, velocity = self.parameters(values)
        run = rsf.simulate(params, constant(velocity, settings["duration"]), start_velocity=self.START_STEP * velocity)
        regime = run.regime
        return {
            "regime": regime.name,
            "period": regime.period,
            "peak_friction": regime.peak_friction,
            "trough_friction": regime.trough_friction,
            "mean_friction": _settled_mean(run.time, run.friction, regime.period),
            "growth": regime.growth,
            "critical_stiffness": rsf.critical_stiffness(params, velocity),
            "message": run.summary()["message"],
        }

    def boundaries(self, spec: Any, frame: Any, x: str, y: str) -> list[Boundary]:
        """k = kc from :func:`stickslip.rsf.critical_stiffness`, against the other axis when k is on one."""
        if "k" not in (x, y):
            return []
        other = y if x == "k" else x
        if other == "pulling_velocity":  # kc(V) on a fine grid (it depends on V through eta V)
            rsf = _require("stickslip.rsf", self.name)
            params, _ = self.parameters({**spec.fixed, "pulling_velocity": 1.0})
            lo, hi = float(frame[other].min()), float(frame[other].max())
            along = np.geomspace(lo, hi, 80) if lo > 0 and hi > lo else np.array([lo, hi])
            critical = np.array([rsf.critical_stiffness(params, v) for v in along], dtype=float)
        elif other in frame:
            kc = frame.groupby(other)["critical_stiffness"].median().dropna()
            along, critical = kc.index.to_numpy(dtype=float), kc.to_numpy(dtype=float)
        else:
            return []
        keep = critical > 0  # kc = 0: steady sliding is stable at every stiffness there, no boundary
        curve = (critical[keep], along[keep]) if x == "k" else (along[keep], critical[keep])
        return [Boundary(curve[0], curve[1], "k = kc (rsf.critical_stiffness)")]


def _settled_mean(time: np.ndarray, friction: np.ndarray, period: float) -> float:
    """Mean friction over the last whole periods within the run's second half (over that half if none)."""
    end = float(time[-1])
    half = 0.5 * (end - float(time[0]))
    span = float(np.floor(half / period) * period) if np.isfinite(period) and period > 0 else 0.0
    inside = time >= end - (span if span > 0 else half)
    return _mean(time[inside], friction[inside])


MODELS: dict[str, Any] = {m.name: m for m in (QuasiStatic(), Transient(), RateAndState())}
#: Other spellings accepted for keys (the issue's symbols).
ALIASES = {"Dc": "dc", "η": "eta", "V0": "pulling_velocity"}


def get_model(name: str) -> Any:
    """The adapter of ``--model NAME``."""
    try:
        return MODELS[name]
    except KeyError:
        raise ParameterError(f"--model {name!r}: expected one of {', '.join(MODELS)}") from None


def result_columns(model: Any) -> dict[str, str]:
    """Columns after the inputs: the model's results, then status, message and wall time."""
    return {**model.results, "status": "str", "message": "str", "wall_time": "float"}


def run_point(model: Any, values: Mapping[str, float], settings: Mapping[str, Any]) -> dict[str, Any]:
    """One point as a row; a failure is a row with status "error" and the one-line reason, never an exception."""
    import time

    start = time.perf_counter()
    try:
        row = model.run(values, settings)
        row["status"] = "ok"
    except Exception as exc:  # any failure of one point is that point's result; the sweep goes on
        row = {name: (None if kind == "str" else 0 if kind == "int" else NAN) for name, kind in model.results.items()}
        kind = "" if isinstance(exc, StickslipError) else f"{type(exc).__name__}: "
        row.update(status="error", message=(kind + str(exc)).replace("\n", " "))
    row["wall_time"] = time.perf_counter() - start
    return row
