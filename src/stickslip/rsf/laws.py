"""State evolution laws of rate-and-state friction, all in one place.

Every law is written for the state term ``psi = ln(V0 theta / Dc)`` with ``x = ln(V/V0)`` and returns ``d psi/dt``
*without* the ``dmu/dt`` coupling, with its two partial derivatives (the solver's analytic Jacobian); a law linear
in ``dmu/dt`` (Nagata's) gives its coefficient by :meth:`StateLaw.coupling`.  :class:`CutoffForm` is the cut-off
velocity friction.  The laws' table, the cut-off form and adding a law (:func:`register_law`): docs/rsf.md, "Laws".
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import ClassVar

from ..errors import ParameterError

#: exp() arguments are capped here, so a run that blows up is caught by the solver, not an OverflowError.
EXP_CAP = 700.0


def cexp(z: float) -> float:
    """exp(z) with the argument capped at :data:`EXP_CAP` (for use inside laws)."""
    return math.exp(z if z < EXP_CAP else EXP_CAP)


__all__ = [
    "EXP_CAP",
    "LAWS",
    "Aging",
    "CutoffForm",
    "Nagata",
    "Prz",
    "Slip",
    "StateLaw",
    "cexp",
    "get_law",
    "register_law",
]


def softplus(z: float) -> float:
    """ln(1 + e^z) without overflow or loss of the small tail."""
    return (z if z > 0 else 0.0) + math.log1p(math.exp(-abs(z)))


def logistic(z: float) -> float:
    """1/(1 + e^-z), the slope of :func:`softplus`, without overflow."""
    if z >= 0:
        return 1.0 / (1.0 + math.exp(-z))
    e = math.exp(z)
    return e / (1.0 + e)


class CutoffForm:
    """The cut-off velocity friction in the solver's variables (see the module notes and docs/rsf.md, Laws).

    ``mu = mu0 - a sp(l1 - x) + sum_i b_i sp(psi_i + l2)``, so
    ``dmu/dx = a L(l1 - x) = a V1/(V1 + V)`` and
    ``dmu/dpsi_i = b_i L(psi_i + l2) = b_i V2 theta_i/(V2 theta_i + s Dc_i)``
    (L the logistic function); their own derivatives, ``-a L(1 - L)`` and ``b_i L(1 - L)``, enter the Jacobian.
    """

    def __init__(self, v1: float, v2: float, v0: float) -> None:
        self.l1 = math.log(v1) - math.log(v0)  # the ratios themselves may overflow
        self.l2 = math.log(v2) - math.log(v0)

    def friction(self, mu0: float, a: float, b: list[float], x: float, psi: list[float]) -> float:
        return mu0 - a * softplus(self.l1 - x) + sum(bi * softplus(p + self.l2) for bi, p in zip(b, psi, strict=True))

    def direct(self, a: float, x: float) -> tuple[float, float]:
        """(dmu/dx, d2mu/dx2)."""
        s = logistic(self.l1 - x)
        return a * s, -a * s * (1.0 - s)

    def evolution(self, b: float, psi: float) -> tuple[float, float]:
        """(dmu/dpsi, d2mu/dpsi2) of one state term."""
        s = logistic(psi + self.l2)
        return b * s, b * s * (1.0 - s)


class StateLaw:
    """Base class (and documentation) of a state evolution law.

    ``theta_scale``: theta = theta_scale (Dc/V0) e^psi.  ``rate`` returns
    ``(g, dg/dx, dg/dpsi)`` where ``g`` is d psi/dt without the dmu/dt term.
    ``coupling(b, c)`` is the coefficient h of ``d psi/dt = g + h dmu/dt``.  ``state_rate(v0, dc)`` is ``g`` alone
    as a function of ``(x, psi)``, for the solver's right-hand side (a law need not write it: the default takes
    ``rate``'s first value; the built-in laws write it out, the same arithmetic in the same order).
    """

    name: ClassVar[str] = "law"
    theta_scale: ClassVar[float] = 1.0
    description: ClassVar[str] = ""

    def rate(self, x: float, psi: float, v0: float, dc: float) -> tuple[float, float, float]:
        raise NotImplementedError

    def state_rate(self, v0: float, dc: float) -> Callable[[float, float], float]:
        rate = self.rate
        return lambda x, psi: rate(x, psi, v0, dc)[0]

    def coupling(self, b: float, c: float) -> float:
        return 0.0


class Aging(StateLaw):
    name = "aging"
    description = "Dieterich (1979) aging law: d theta/dt = 1 - V theta/Dc"

    def rate(self, x: float, psi: float, v0: float, dc: float) -> tuple[float, float, float]:
        r = v0 / dc
        ev, ep = cexp(x), cexp(-psi)
        return r * (ep - ev), -r * ev, -r * ep

    def state_rate(self, v0: float, dc: float) -> Callable[[float, float], float]:
        r, exp, cap = v0 / dc, math.exp, EXP_CAP

        def g(x: float, psi: float) -> float:
            z = -psi
            return r * (exp(z if z < cap else cap) - exp(x if x < cap else cap))

        return g


class Slip(StateLaw):
    name = "slip"
    description = "Ruina (1983) slip law: d theta/dt = -(V theta/Dc) ln(V theta/Dc)"

    def rate(self, x: float, psi: float, v0: float, dc: float) -> tuple[float, float, float]:
        w = v0 * cexp(x) / dc
        s = x + psi
        return -w * s, -w * (s + 1.0), -w

    def state_rate(self, v0: float, dc: float) -> Callable[[float, float], float]:
        exp, cap = math.exp, EXP_CAP

        def g(x: float, psi: float) -> float:
            return -(v0 * exp(x if x < cap else cap) / dc) * (x + psi)

        return g


class Prz(StateLaw):
    name = "prz"
    theta_scale = 2.0
    description = "Perrin, Rice & Zheng (1995): d theta/dt = 1 - (V theta/(2 Dc))^2"

    def rate(self, x: float, psi: float, v0: float, dc: float) -> tuple[float, float, float]:
        r = v0 / (2.0 * dc)
        ep, eq = cexp(-psi), cexp(2.0 * x + psi)
        return r * (ep - eq), -2.0 * r * eq, -r * (ep + eq)

    def state_rate(self, v0: float, dc: float) -> Callable[[float, float], float]:
        r, exp, cap = v0 / (2.0 * dc), math.exp, EXP_CAP

        def g(x: float, psi: float) -> float:
            z, u = -psi, 2.0 * x + psi
            return r * (exp(z if z < cap else cap) - exp(u if u < cap else cap))

        return g


class Nagata(Aging):
    name = "nagata"
    description = "Nagata et al. (2012): d theta/dt = 1 - V theta/Dc - (c/b) theta dmu/dt"

    def coupling(self, b: float, c: float) -> float:
        return -c / b


#: The registry: law name -> law object.
LAWS: dict[str, StateLaw] = {}


def register_law(law: StateLaw, name: str | None = None, *, replace: bool = False) -> StateLaw:
    """Make ``law`` available under ``name`` (default ``law.name``); returns it.

    A name already taken by another law (a built-in such as ``aging`` included) is refused unless
    ``replace=True``: silently swapping the aging law for the rest of the process would change every later run.
    """
    if name is not None and not isinstance(name, str):
        raise ParameterError(f"register_law: expected name as a text, got {type(name).__name__}")
    own = getattr(law, "name", None)
    key = (name if name is not None else own if isinstance(own, str) else "").strip().lower()
    if not key:
        raise ParameterError("register_law: expected a non-empty law name (name=... or the law's .name)")
    for attr in ("rate", "coupling", "theta_scale"):
        if not hasattr(law, attr):
            raise ParameterError(f"register_law {key!r}: the law has no {attr!r} (see stickslip.rsf.laws.StateLaw)")
    if not isinstance(replace, bool):
        raise ParameterError(f"register_law: expected replace=True or False, got {replace!r}")
    taken = LAWS.get(key)
    if taken is not None and taken is not law and not replace:
        raise ParameterError(
            f"register_law {key!r}: the name is taken by the {type(taken).__name__} law; give another name,"
            " or replace=True to replace it for the rest of this process"
        )
    LAWS[key] = law
    return law


def get_law(name: str | StateLaw) -> StateLaw:
    """The law registered under ``name`` (a law object passes through; anything else is a ParameterError)."""
    if not isinstance(name, str):
        if all(hasattr(name, attr) for attr in ("rate", "coupling", "theta_scale")):
            return name
        raise ParameterError(f"law: expected a law name, one of {', '.join(sorted(LAWS))}; got {name!r}"[:300])
    try:
        return LAWS[name.strip().lower()]
    except KeyError:
        raise ParameterError(f"law {name!r}: unknown; expected one of {', '.join(sorted(LAWS))}") from None


for _law in (Aging(), Slip(), Prz(), Nagata()):
    register_law(_law)
