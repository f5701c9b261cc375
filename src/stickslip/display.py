"""How quantities are written for people: one spelling per quantity in every message, table and figure.

Machines get SI and ASCII (CSV headers, JSON keys, TOML files); people get the
paper's symbols (σs, τa, Δl_m) and µm/s (mm/s, m/s for fast velocities).  What a user types stays ASCII
(``--v0 "350 um/s"``): :func:`unit` turns such a unit into the one shown.
"""

from __future__ import annotations

import math

#: ASCII symbols of the parameter tables (``stickslip.parameters``) as the paper writes them.
SYMBOLS = {
    "tau": "τ",
    "tau_a": "τa",
    "lambda": "λ",
    "dl_m": "Δl_m",
    "V_a": "Va",
    "G_d": "Gd",
    "uc/tau": "uc/τ",
    "sigma_s": "σs",
    "sigma_c": "σc",
}

#: Units as typed (ASCII) and as shown.
UNITS = {"um": "µm", "um/s": "µm/s", "us": "µs", "1/um": "1/µm", "uN": "µN"}


def symbol(name: str) -> str:
    """The paper's spelling of an ASCII symbol: ``symbol("tau_a") == "τa"``; other names unchanged."""
    return SYMBOLS.get(name, name)


def unit(name: str) -> str:
    """A unit as shown to people: ``unit("um") == "µm"``; other units unchanged."""
    return UNITS.get(name, name)


def velocities_apart(a: float, b: float, digits: int = 4) -> tuple[str, str]:
    """Two different velocities (SI) as :func:`velocity` writes them, with at least ``digits`` significant digits and
    as many more as they need to read different: "124.05 µm/s is below Vc = 124.097 µm/s", not "124.1 µm/s is
    below Vc = 124.1 µm/s"."""
    for shown in range(digits, 16):
        first, second = velocity(a, shown), velocity(b, shown)
        if first != second or a == b:
            return first, second
    return velocity(a, 17), velocity(b, 17)


#: the units a velocity is written in, from the slowest: (the smallest |V| in m/s written in it, its factor, unit);
#: the paper's µm/s up to 10 mm/s (5038.5 µm/s, the aging curve's maximum, as every message writes it), then mm/s
#: and m/s ("1000000 µm/s" for 1 m/s was a count of digits, not a velocity to read)
VELOCITY_UNITS = ((1.0, 1.0, "m/s"), (1e-2, 1e3, "mm/s"), (0.0, 1e6, "µm/s"))


def velocity(value: float, digits: int = 6) -> str:
    """A velocity (SI) for people: in µm/s below 10 mm/s, in mm/s up to 1 m/s, in m/s from there
    (:data:`VELOCITY_UNITS`): ``velocity(7.02e-4) == "702 µm/s"``, ``velocity(0.1, 4) == "100 mm/s"``,
    ``velocity(1.0) == "1 m/s"``; a whole number in that unit is written out, not in exponent form, up to 1e15."""
    # the unit of the value as written (9.99999 mm/s to 4 digits is "10 mm/s", not "1e+04 µm/s")
    size = float(f"{abs(value):.{max(digits, 1)}g}") if math.isfinite(value) else 0.0
    factor, name = next((f, n) for smallest, f, n in VELOCITY_UNITS if size >= smallest)
    shown = value * factor
    rounded = abs(float(f"{shown:.{digits}g}")) if math.isfinite(shown) else 0.0
    if 10.0**digits <= rounded < 1e15:
        digits = int(math.log10(rounded)) + 1
    return f"{shown:.{digits}g} {name}"
