"""``stickslip stability``: linear stability of steady sliding in the time-dependent model (Eq 1).

Kc(V0) of :mod:`stickslip.transient.stability`, with the block's mass and a viscous damping
(docs/extensions.md section 4).  Heavy imports happen inside the command.
"""

from __future__ import annotations

import math
from typing import Any

import click

from .common import emit_json, params_options, positive, resolve_params


@click.command("stability")
@click.option("--v0", "velocities", multiple=True, required=True, metavar="V", help='Sliding velocity, "120 um/s".')
@click.option("--mass", "mass_text", default=None, metavar="M", help='Block mass per area, e.g. "10.5 kg/m^2" [0].')
@click.option("--damping", "damping_text", default=None, metavar="ETA", help='Viscous damping, "1025 Pa s/m" [0].')
@click.option("--growth-at", type=float, default=None, metavar="F", help="Also the Hopf root at K = F x Kc.")
@click.option("--no-aging", is_flag=True, help="Drop the aging term of Eq 1.")
@click.option("--json", "as_json", is_flag=True, help="Print the results as JSON (SI units).")
@params_options
def stability_command(
    velocities: tuple[str, ...],
    mass_text: str | None,
    damping_text: str | None,
    growth_at: float | None,
    no_aging: bool,
    as_json: bool,
    params_name: str,
    overrides: tuple[str, ...],
) -> None:
    """Kc (Pa/m) of steady sliding at each --v0 through a block of mass --mass and damping --damping.

    Steady sliding is linearly stable for a block stiffer than Kc; the mode is "oscillatory" (a Hopf
    point, with its frequency) or "real" (a runaway).  --growth-at F follows the Hopf eigenvalue to
    K = F x Kc and prints its growth rate (1/s) and frequency (Hz).

    --damping without --mass is the massless block with a dashpot, D(s) = ETA s + K + Z(s): well posed,
    and the limit of a vanishing mass (unlike `transient`, whose solver takes a damping only with a mass).
    """
    from ..errors import ParameterError
    from ..transient.stability import critical_stiffness_details, hopf_root

    mass = 0.0 if mass_text is None else positive(mass_text, "mass_per_area", "--mass", allow_zero=True)
    damping = 0.0 if damping_text is None else positive(damping_text, "stress_per_velocity", "--damping", True)
    if growth_at is not None and not (math.isfinite(growth_at) and growth_at > 0):
        raise ParameterError(f"--growth-at: expected a positive factor of Kc, got {growth_at!r}")
    params = resolve_params(params_name, overrides)
    rows: list[dict[str, Any]] = []
    for text in velocities:
        v = positive(text, "velocity", "--v0")
        kc = critical_stiffness_details(params, v, not no_aging, mass, damping)
        _refuse_unbounded(kc, text, mass_text, damping_text, growth_at)
        row: dict[str, Any] = {
            "velocity": v,
            "mass": mass,
            "damping": damping,
            "critical_stiffness": kc.value,
            "mode": kc.mode,
            "frequency": kc.rate / (2 * math.pi) if kc.mode == "oscillatory" else None,
            "message": kc.message,
        }
        if growth_at is not None and kc.mode == "oscillatory":
            root = hopf_root(params, v, growth_at, mass, damping, not no_aging)
            row.update(factor=growth_at, growth_rate=root.real, growth_frequency=root.imag / (2 * math.pi))
        rows.append(row)
    if as_json:
        emit_json({"units": UNITS, "rows": rows})
        return
    massless = " (a massless block with a dashpot: D(s) = η s + K + Z(s))" if mass == 0 and damping > 0 else ""
    click.echo(f"block mass {mass:.6g} kg/m^2, damping {damping:.6g} Pa s/m{massless}")
    for row in rows:
        click.echo(f"V0 = {row['velocity'] * 1e6:.6g} µm/s: {row['message']}")
        if "growth_rate" in row:
            click.echo(
                f"  at K = {growth_at:g} x Kc: growth {row['growth_rate']:+.6g} 1/s,"
                f" oscillating at {row['growth_frequency']:.6g} Hz"
            )


def _refuse_unbounded(
    kc: Any, v0_text: str, mass_text: str | None, damping_text: str | None, factor: float | None
) -> None:
    """A Kc (or F x Kc) beyond the floating-point range is no answer: refuse it, naming the inputs, never print inf."""
    from ..errors import ParameterError

    value = kc.value
    if kc.mode != "oscillatory" or value is None:
        return
    given = ", ".join(f"{name} {text}" for name, text in (("--mass", mass_text), ("--damping", damping_text)) if text)
    if not math.isfinite(value) or not math.isfinite(kc.rate):
        raise ParameterError(
            f"--v0 {v0_text}{', ' + given if given else ''}: Kc leaves the floating-point range (above 1e308 Pa/m);"
            " expected a smaller block mass or damping"
        )
    if factor is not None and not math.isfinite(factor * value):
        raise ParameterError(f"--growth-at {factor:g}: F x Kc = {factor:g} x {value:.4g} Pa/m is beyond 1e308 Pa/m")


UNITS = {
    "velocity": "m/s",
    "mass": "kg/m^2",
    "damping": "Pa s/m",
    "critical_stiffness": "Pa/m",
    "frequency": "Hz",
    "growth_rate": "1/s",
    "growth_frequency": "Hz",
}


def register(cli: click.Group) -> None:
    cli.add_command(stability_command)
