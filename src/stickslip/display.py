"""How quantities are written for people: one spelling per quantity in every message, table and figure.

Machines get SI and ASCII (CSV headers, JSON keys, TOML files); people get the
paper's symbols (σs, τa, Δl_m) and µm/s.  What a user types stays ASCII
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


def velocity(value: float, digits: int = 6) -> str:
    """A velocity (SI) in µm/s, the unit of every velocity the package prints: ``velocity(7.02e-4) == "702 µm/s"``;
    a whole number of µm/s is written out up to 1 km/s (``velocity(0.1, 4) == "100000 µm/s"``, not "1e+05")."""
    shown = value * 1e6
    if math.isfinite(shown) and 10.0**digits <= abs(shown) < 1e15:
        digits = int(math.log10(abs(shown))) + 1
    return f"{shown:.{digits}g} µm/s"
