"""Issue 22 Q4: does the block's inertia (or radiation damping) change the Hopf prediction of Eq 1?

The linear stability of steady sliding (:mod:`stickslip.transient.stability`) with a block of mass m per
unit area and a viscous damping eta: eigenvalues solve m s^2 + eta s + K + Z(s) = 0 (docs/extensions.md
section 4).  ``python -m stickslip.studies.inertia`` prints the tables of that section.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..parameters import Parameters
from ..transient.stability import (
    CELL_HAZARD,
    SCAN,
    critical_from_response,
    follow_root,
    interface_response,
    real_growth_rates,
    resolved_frequency,
)

#: gelatin gel density, kg/m^3 (5 wt% gel: water plus 5 % protein; 1000-1100 spans it)
GEL_DENSITY = 1050.0


@dataclass(frozen=True)
class Block:
    """A block case: label, mass per unit area m (kg/m^2), viscous damping eta (Pa s/m)."""

    label: str
    mass: float
    damping: float


def gel_block_cases(params: Parameters, density: float = GEL_DENSITY) -> list[Block]:
    """The massless block, the gel block (rho h), 10x and 1000x heavier, and radiation damping G/(2 c_s)."""
    block = params.block
    mass = density * block.height
    shear_speed = math.sqrt(block.shear_modulus / density)
    radiation = block.shear_modulus / (2.0 * shear_speed)
    return [
        Block("massless (the paper's)", 0.0, 0.0),
        Block("gel block rho h", mass, 0.0),
        Block("10 x rho h", 10.0 * mass, 0.0),
        Block("1000 x rho h", 1000.0 * mass, 0.0),
        Block("radiation damping G/(2 c_s)", 0.0, radiation),
        Block("rho h and G/(2 c_s)", mass, radiation),
    ]


@dataclass(frozen=True)
class HopfRow:
    """Kc (Pa/m), the Hopf frequency (Hz) and the eigenvalue at ``factor`` x Kc (1/s) for one block."""

    velocity: float
    block: Block
    critical_stiffness: float
    frequency: float
    growth: float
    growth_frequency: float
    mode: str


def hopf_row(
    params: Parameters, velocity: float, block: Block, factor: float = 0.7, cell_hazard: float = CELL_HAZARD
) -> HopfRow:
    """The Hopf point of steady sliding at ``velocity`` through ``block``, and its root at ``factor`` x Kc."""

    def response(s: np.ndarray) -> np.ndarray:
        return interface_response(params, velocity, s, True, cell_hazard).z

    top = resolved_frequency(params, velocity, True, cell_hazard)  # (with or without a mass: see its notes)
    kc = critical_from_response(response, SCAN / params.bonds.bond_time, block.mass, block.damping, top)
    if kc.mode != "oscillatory":
        return HopfRow(velocity, block, kc.value, math.nan, math.nan, math.nan, kc.mode)
    root = follow_root(response, 1j * kc.rate, kc.value, factor * kc.value, block.mass, block.damping)
    return HopfRow(velocity, block, kc.value, kc.rate / (2 * math.pi), root.real, root.imag / (2 * math.pi), kc.mode)


def fastest_runaway(params: Parameters, velocity: float, masses: tuple[float, ...]) -> list[tuple[float, float]]:
    """(m, fastest real growth rate 1/s) through the paper's block K: bounded for m > 0, ~ m^-1/2 if K + Z(inf) < 0."""
    stiffness = params.block.effective_stiffness
    rows = []
    for mass in masses:
        rates = real_growth_rates(params, velocity, stiffness, mass=mass)
        rows.append((mass, float(rates.max()) if rates.size else 0.0))
    return rows


def high_frequency_stiffness(params: Parameters, velocity: float) -> float:
    """Z(inf) (Pa/m): the interface's instantaneous stiffness; the massless block is ill-posed where K + Z(inf) < 0."""
    return float(interface_response(params, velocity, np.array([1e6 / params.bonds.bond_time])).z[0].real)


def main() -> None:  # pragma: no cover - prints the tables of docs/extensions.md section 4
    from ..parameters import load_parameters

    params = load_parameters("gelatin-glass")
    print("velocity µm/s | block | m kg/m^2 | eta Pa s/m | Kc Pa/m | f_Hopf Hz | growth at 0.7 Kc 1/s | f there Hz")
    for velocity in (100e-6, 120e-6, 124e-6):
        for block in gel_block_cases(params):
            r = hopf_row(params, velocity, block)
            print(
                f"{velocity * 1e6:g} | {block.label} | {block.mass:.4g} | {block.damping:.4g} | "
                f"{r.critical_stiffness:.5g} | {r.frequency:.4g} | {r.growth:+.4g} | {r.growth_frequency:.4g}"
            )
    print("convergence (gel block, 120 µm/s): cell_hazard | Kc | f | growth")
    gel = gel_block_cases(params)[1]
    for hazard in (0.004, 0.002, 0.001):
        r = hopf_row(params, 120e-6, gel, cell_hazard=hazard)
        print(f"{hazard} | {r.critical_stiffness:.7g} | {r.frequency:.6g} | {r.growth:+.6g}")
    for velocity in (50e-6, 120e-6):
        print(f"Z(inf) at {velocity * 1e6:g} µm/s = {high_frequency_stiffness(params, velocity):.4g} Pa/m")
        for mass, rate in fastest_runaway(params, velocity, (1e-6, 1e-3, 10.5, 105.0, 10500.0)):
            print(f"  m = {mass:g} kg/m^2: fastest real growth {rate:.4g} 1/s")


if __name__ == "__main__":  # pragma: no cover
    main()
