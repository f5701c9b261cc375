"""Small lab-like records made from known truth, for the record-reading and velocity-level tests.

A rig writes the load point's displacement as its sensor reads it: in whole bits (quantised), with correlated
noise (the servo and the electronics), a slow drift, and at a sampling rate the operator changes mid-record.
:func:`load_point` makes such a displacement from a known piecewise-constant velocity history;
:func:`write_records` writes the shipped files beside this script (run it to regenerate them):

- ``biaxial_4level.txt``: 2.29 -> 22.85 -> 228.7 -> 2.287 um/s sampled at 0.1 s, 0.01 s, 1 ms and 0.1 s (the
  shape of the real 1 kHz section that was over-split), displacement in 0.1 um bits with AR(1) noise, friction
  from :func:`stickslip.rsf.simulate` with known a, b, Dc, k plus noise.  Its truth is in ``TRUTH_4LEVEL``.
- ``sepiolite_velstep1_slice.txt``: 500 s of a real record around its 0.2 -> 2 um/s step (Giacomel's sepiolite
  velstep1, MIT, ``LICENSE-sepiolite`` beside it), cut from ``../shared/data/giacomel-steadystate`` when present.
- ``velocity_column.txt``: a rig that writes the commanded velocity instead of the displacement (steps at whole
  row times), friction from RSF with known parameters (``TRUTH_VELOCITY``).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from stickslip import protocols
from stickslip.rsf import RSFParams, simulate
from stickslip.rsf.params import StateVariable

UM = 1e-6
HERE = Path(__file__).parent

#: velocities (um/s), durations (s) and the sampling intervals (s) from each time on, for biaxial_4level.txt
TRUTH_4LEVEL = {
    "velocities": (2.29, 22.85, 228.7, 2.287),
    "durations": (30.0, 8.0, 2.0, 30.0),
    "sampling": ((0.0, 0.1), (29.0, 0.01), (38.0, 0.001), (40.5, 0.1)),
    "bit": 0.1,  # um
    "noise": 0.15,  # um, AR(1) standard deviation
    "correlation_time": 0.02,  # s
    "drift": 0.3,  # um, amplitude of a slow sine over the record
    "params": {"a": 0.011, "b": 0.014, "dc": 5.0, "mu0": 0.62, "stiffness": 0.02},  # Dc in um, k in 1/um
    "friction_noise": 2e-4,
}
#: a velocity column stepping 1 -> 10 -> 1 um/s at the rows of t = 50.0 and 80.0 s (rows every 0.1 s)
TRUTH_VELOCITY = {
    "velocities": (1.0, 10.0, 1.0),
    "durations": (50.0, 30.0, 70.0),
    "interval": 0.1,
    "params": {"a": 0.010, "b": 0.014, "dc": 10.0, "mu0": 0.6, "stiffness": 0.01},
    "friction_noise": 1e-4,
}


def sample_times(sampling: tuple[tuple[float, float], ...], end: float) -> np.ndarray:
    """Row times from 0 to ``end``: interval ``dt`` from each ``(start, dt)`` on (the rate changes mid-record)."""
    pieces = []
    for (start, dt), nxt in zip(sampling, [*[s for s, _ in sampling[1:]], end], strict=True):
        pieces.append(start + dt * np.arange(math.ceil((nxt - start) / dt - 1e-9)))
    return np.unique(np.round(np.concatenate([*pieces, [end]]), 9))


def ar1(t: np.ndarray, sigma: float, tau: float, rng: np.random.Generator) -> np.ndarray:
    """Stationary Ornstein-Uhlenbeck noise sampled at (uneven) times ``t``: correlation exp(-|dt| / tau)."""
    out = np.empty(t.size)
    out[0] = sigma * rng.standard_normal()
    keep = np.exp(-np.diff(t) / tau)
    kicks = sigma * np.sqrt(1.0 - keep**2) * rng.standard_normal(t.size - 1)
    for i in range(1, t.size):
        out[i] = keep[i - 1] * out[i - 1] + kicks[i - 1]
    return out


def load_point(
    velocities: tuple[float, ...],
    durations: tuple[float, ...],
    t: np.ndarray,
    *,
    bit: float = 0.1,
    noise: float = 0.15,
    correlation_time: float = 0.02,
    drift: float = 0.0,
    seed: int = 0,
) -> tuple[protocols.Protocol, np.ndarray]:
    """The true history (SI) and the displacement a rig would write at ``t`` (um): the exact displacement plus
    AR(1) noise and a slow sine drift of amplitude ``drift`` over the record, rounded to whole ``bit`` s."""
    truth = protocols.velocity_steps([v * UM for v in velocities], list(durations))
    rng = np.random.default_rng(seed)
    exact = truth.displacement_at(t) / UM
    wander = ar1(t, noise, correlation_time, rng) + drift * np.sin(math.pi * t / t[-1])
    return truth, np.round((exact + wander) / bit) * bit


def rsf_truth(params: dict[str, float], v_ref: float) -> RSFParams:
    return RSFParams(
        a=params["a"],
        states=(StateVariable("aging", params["b"], params["dc"] * UM),),
        mu0=params["mu0"],
        v_ref=v_ref,
        stiffness=params["stiffness"] / UM,
    )


def four_level_record(seed: int = 1) -> tuple[protocols.Protocol, np.ndarray, np.ndarray, np.ndarray]:
    """The biaxial_4level record: truth, time (s), displacement (um), friction."""
    spec = TRUTH_4LEVEL
    t = sample_times(spec["sampling"], sum(spec["durations"]))
    truth, d = load_point(
        spec["velocities"],
        spec["durations"],
        t,
        bit=spec["bit"],
        noise=spec["noise"],
        correlation_time=spec["correlation_time"],
        drift=spec["drift"],
        seed=seed,
    )
    run = simulate(rsf_truth(spec["params"], spec["velocities"][0] * UM), truth, times=t)
    friction = run.friction + spec["friction_noise"] * np.random.default_rng(seed + 100).standard_normal(t.size)
    return truth, t, d, friction


def velocity_column_record(seed: int = 2) -> tuple[protocols.Protocol, np.ndarray, np.ndarray, np.ndarray]:
    """The velocity_column record: truth, time (s), commanded velocity (um/s), friction."""
    spec = TRUTH_VELOCITY
    truth = protocols.velocity_steps([v * UM for v in spec["velocities"]], list(spec["durations"]))
    t = np.round(np.arange(0.0, truth.duration + 1e-9, spec["interval"]), 9)
    velocity = truth.velocity_at(t) / UM  # a step's first row carries the new velocity
    run = simulate(rsf_truth(spec["params"], spec["velocities"][0] * UM), truth, times=t)
    friction = run.friction + spec["friction_noise"] * np.random.default_rng(seed).standard_normal(t.size)
    return truth, t, velocity, friction


def write_records(folder: Path = HERE) -> None:
    _, t, d, f = four_level_record()
    rows = "".join(f"{a:.3f}\t{b:.1f}\t{c:.5f}\n" for a, b, c in zip(t, d, f, strict=True))
    (folder / "biaxial_4level.txt").write_text("Time (s)\tLP Displacement (um)\tmu\n" + rows)
    _, t, v, f = velocity_column_record()
    rows = "".join(f"{a:.1f}\t{b:g}\t{c:.5f}\n" for a, b, c in zip(t, v, f, strict=True))
    (folder / "velocity_column.txt").write_text("Time(s)\tVel(um/s)\tFriction\n" + rows)


REAL = Path(__file__).resolve().parents[3] / "shared/data/giacomel-steadystate/velstep1_TR2_exp013_sepiolite.txt"


def write_real_slice(folder: Path = HERE, source: Path = REAL, step: float = 10334.9, half: float = 250.0) -> None:
    """Rows of the real velstep1 record within ``half`` seconds of its step (absolute time ``step``), as written."""
    lines = source.read_text().splitlines()
    kept = [row for row in lines[1:] if abs(float(row.split("\t")[0]) - step) <= half]
    (folder / "sepiolite_velstep1_slice.txt").write_text("\n".join([lines[0], *kept]) + "\n")
    (folder / "LICENSE-sepiolite").write_text((source.parent / "LICENSE").read_text())


if __name__ == "__main__":
    if REAL.is_file():
        write_real_slice()
    write_records()
