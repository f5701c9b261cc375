"""The spring-slider's equations in log variables: right-hand side and analytic Jacobian.

The unknowns are ``x = ln(V/V0)`` and the state terms ``psi_i = ln(V0 theta_i/Dc_i)`` (plus ``s``, the spring's
pull in friction units, when the slider has mass); the equations, with A = dmu/dx, B_i = dmu/dpsi_i of each
friction form and the ``dmu/dt`` coupling of Nagata's law: docs/rsf.md, "Spring–slider".
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from .laws import EXP_CAP, CutoffForm, get_law
from .laws import cexp as _exp
from .params import RSFParams


class System:
    """Numbers of one :class:`RSFParams`, ready for fast scalar evaluation."""

    def __init__(self, params: RSFParams) -> None:
        self.params = params
        self.a = params.a
        self.mu0 = params.mu0
        self.v0 = params.v_ref
        self.k = params.stiffness
        self.eta = params.eta
        self.inertial = params.mass > 0
        self.inertia = params.mass / params.normal_stress if self.inertial and params.normal_stress else 0.0
        self.regularized = params.regularized
        self.laws = [get_law(s.law) for s in params.states]
        self.b = [s.b for s in params.states]
        self.dc = [s.dc for s in params.states]
        self.h = [law.coupling(s.b, s.c) for law, s in zip(self.laws, params.states, strict=True)]
        self.n = len(self.b)
        self.offset = 1 if self.inertial else 0  # index of x in y
        self.size = self.n + 1 + self.offset
        self.one_minus_h = 1.0 - sum(b * h for b, h in zip(self.b, self.h, strict=True))  # classical form
        self.has_jacobian = not self.regularized
        #: integrate by Radau, not LSODA (set by the solver once LSODA kept to explicit steps on a stiff problem)
        self.implicit = False
        self.cutoff = None if params.cutoff is None else CutoffForm(*params.cutoff, self.v0)
        self._terms = [(law.rate, b, dc) for law, b, dc in zip(self.laws, self.b, self.dc, strict=True)]
        self._coupled = any(h != 0.0 for h in self.h)
        #: the classical form without mass or dmu/dt coupling (the common case, without generality's cost)
        self.classical = self.cutoff is None and self.has_jacobian and not (self._coupled or self.inertial)
        self._choose_rhs()

    def _choose_rhs(self) -> None:
        if self.cutoff is not None:
            if not self.inertial:
                self.rhs = self._rhs_cutoff  # type: ignore[method-assign]
        elif self.classical:
            # its numbers bound in a closure (a fit's millions of evaluations: ~1/3 less per run, the same
            # arithmetic in the same order as _rhs_classical)
            self.rhs = _one_state_rhs(self) if self.n == 1 else _states_rhs(self)  # type: ignore[method-assign]
            # LSODA asks for it once per ~36 right-hand sides, at ~15x a right-hand side's cost in the general form
            self.jacobian = _classical_jacobian(self)  # type: ignore[method-assign]

    def __getstate__(self) -> dict[str, Any]:
        # a closure does not pickle: rebuilt
        return {k: v for k, v in self.__dict__.items() if k not in ("rhs", "jacobian")}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._choose_rhs()

    # ------------------------------------------------------------------ friction
    def friction(self, x: float, psi: list[float] | np.ndarray) -> float:
        if self.cutoff is not None:
            return self.cutoff.friction(self.mu0, self.a, self.b, x, [float(p) for p in psi])
        if not self.regularized:
            return self.mu0 + self.a * x + sum(b * p for b, p in zip(self.b, psi, strict=True))
        z = x + (self.mu0 + sum(b * p for b, p in zip(self.b, psi, strict=True))) / self.a
        return self.a * _asinh_half_exp(z)

    def friction_many(self, x: np.ndarray, psi: np.ndarray) -> np.ndarray:
        """Vectorised :meth:`friction`; ``psi`` has shape (n, len(x))."""
        if self.cutoff is not None:
            c = self.cutoff
            evolution = sum(b * np.logaddexp(0.0, row + c.l2) for b, row in zip(self.b, psi, strict=True))
            return self.mu0 - self.a * np.logaddexp(0.0, c.l1 - np.asarray(x, dtype=float)) + evolution
        bpsi = sum(b * row for b, row in zip(self.b, psi, strict=True))  # tensordot is slow for these shapes
        if not self.regularized:
            return self.mu0 + self.a * x + bpsi
        z = x + (self.mu0 + bpsi) / self.a
        return self.a * np.where(z > 0, z + np.log(0.5 + 0.5 * np.sqrt(1 + 4 * np.exp(-2 * np.abs(z)))),
                                 np.arcsinh(0.5 * np.exp(np.minimum(z, 0))))  # fmt: skip

    def _slopes(self, x: float, psi: list[float]) -> tuple[float, float]:
        """(A, factor) with A = dmu/dx and B_i = factor * b_i."""
        if not self.regularized:
            return self.a, 1.0
        z = x + (self.mu0 + sum(b * p for b, p in zip(self.b, psi, strict=True))) / self.a
        factor = 1.0 / math.sqrt(1.0 + 4.0 * _exp(-2.0 * z)) if z > 0 else _half_exp_ratio(z)
        return self.a * factor, factor

    # ------------------------------------------------------------------ equations
    def rhs(self, t: float, y: np.ndarray, vlp: float) -> list[float]:
        o = self.offset
        x = float(y[o])
        psi = [float(p) for p in y[o + 1 :]]
        v = self.v0 * _exp(x)
        g = [law.rate(x, p, self.v0, dc)[0] for law, p, dc in zip(self.laws, psi, self.dc, strict=True)]
        if self.cutoff is not None:  # H = 0 (no coupled law with this form)
            A = self.cutoff.direct(self.a, x)[0]
            G = sum(self.cutoff.evolution(b, p)[0] * gi for b, p, gi in zip(self.b, psi, g, strict=True))
            Q = 1.0
        else:
            A, factor = self._slopes(x, psi)
            G = factor * sum(b * gi for b, gi in zip(self.b, g, strict=True))
            Q = 1.0 - factor * sum(b * h for b, h in zip(self.b, self.h, strict=True))
        if self.inertial:
            s = float(y[0])
            xdot = (s - self.friction(x, psi) - self.eta * v) / (self.inertia * v)
            mudot = (A * xdot + G) / Q
            return [self.k * (vlp - v), xdot, *(gi + hi * mudot for gi, hi in zip(g, self.h, strict=True))]
        xdot = (Q * self.k * (vlp - v) - G) / (A + Q * self.eta * v)
        mudot = (A * xdot + G) / Q
        return [xdot, *(gi + hi * mudot for gi, hi in zip(g, self.h, strict=True))]

    def _rhs_classical(self, t: float, y: np.ndarray, vlp: float) -> list[float]:
        """:meth:`rhs` for the classical form without mass or dmu/dt coupling (same equations, fewer steps).

        No run calls it since every number of states has a bound closure (:func:`_one_state_rhs`,
        :func:`_states_rhs`); it stays as their plain reference, which tests/test_rsf_laws.py holds them to, bit for
        bit."""
        x, *psi = y.tolist()
        v0 = self.v0
        out = [0.0]
        G = 0.0
        for (rate, b, dc), p in zip(self._terms, psi):  # noqa: B905  (lengths match by construction)
            g = rate(x, p, v0, dc)[0]
            out.append(g)
            G += b * g
        v = v0 * _exp(x)
        out[0] = (self.k * (vlp - v) - G) / (self.a + self.eta * v)
        return out

    def _rhs_cutoff(self, t: float, y: np.ndarray, vlp: float) -> list[float]:
        """:meth:`rhs` for the cut-off velocity form without mass: dx/dt = (k (V_lp - V) - sum B_i g_i)/(A + eta V)."""
        x, *psi = y.tolist()
        v0, c = self.v0, self.cutoff
        assert c is not None
        out = [0.0]
        G = 0.0
        for (rate, b, dc), p in zip(self._terms, psi):  # noqa: B905  (lengths match by construction)
            g = rate(x, p, v0, dc)[0]
            out.append(g)
            G += c.evolution(b, p)[0] * g
        v = v0 * _exp(x)
        out[0] = (self.k * (vlp - v) - G) / (c.direct(self.a, x)[0] + self.eta * v)
        return out

    def jacobian(self, t: float, y: np.ndarray, vlp: float) -> np.ndarray:
        """Analytic Jacobian of :meth:`rhs` (classical and cut-off friction forms)."""
        if self.cutoff is not None:
            return self._jacobian_cutoff(y, vlp)
        if self.inertial:
            return self._jacobian_inertial(y, vlp)
        x = float(y[0])
        psi = [float(p) for p in y[1:]]
        n, a, k, eta, Q = self.n, self.a, self.k, self.eta, self.one_minus_h
        v = self.v0 * _exp(x)
        rates = [law.rate(x, p, self.v0, dc) for law, p, dc in zip(self.laws, psi, self.dc, strict=True)]
        G = sum(b * r[0] for b, r in zip(self.b, rates, strict=True))
        D = a + Q * eta * v
        xdot = (Q * k * (vlp - v) - G) / D
        jac = np.empty((n + 1, n + 1))
        dxx = (-Q * k * v - sum(b * r[1] for b, r in zip(self.b, rates, strict=True)) - xdot * Q * eta * v) / D
        jac[0, 0] = dxx
        dmu_dx = (a * dxx + sum(b * r[1] for b, r in zip(self.b, rates, strict=True))) / Q
        for j in range(n):
            jac[0, j + 1] = -self.b[j] * rates[j][2] / D
        for i in range(n):
            jac[i + 1, 0] = rates[i][1] + self.h[i] * dmu_dx
            for j in range(n):
                dmu_dpj = (a * jac[0, j + 1] + self.b[j] * rates[j][2]) / Q
                jac[i + 1, j + 1] = (rates[i][2] if i == j else 0.0) + self.h[i] * dmu_dpj
        return jac

    def _jacobian_inertial(self, y: np.ndarray, vlp: float) -> np.ndarray:
        """Jacobian of the inertial equations in (s, x, psi): xdot = (s - mu - eta V)/(m' V), m' = m/sigma."""
        s, x = float(y[0]), float(y[1])
        psi = [float(p) for p in y[2:]]
        n, a, Q = self.n, self.a, self.one_minus_h
        v = self.v0 * _exp(x)
        rates = [law.rate(x, p, self.v0, dc) for law, p, dc in zip(self.laws, psi, self.dc, strict=True)]
        force = s - self.friction(x, psi) - self.eta * v
        mv = self.inertia * v
        jac = np.zeros((n + 2, n + 2))
        jac[0, 1] = -self.k * v
        dx = np.empty(n + 2)  # d xdot / d (s, x, psi)
        dx[0] = 1.0 / mv
        dx[1] = (-a - self.eta * v - force) / mv
        dx[2:] = [-b / mv for b in self.b]
        jac[1] = dx
        # dmu/dt = (a xdot + sum b g) / Q
        dmu = a * dx / Q
        dmu[1] += sum(b * r[1] for b, r in zip(self.b, rates, strict=True)) / Q
        for j in range(n):
            dmu[2 + j] += self.b[j] * rates[j][2] / Q
        for i in range(n):
            jac[2 + i] = self.h[i] * dmu
            jac[2 + i, 1] += rates[i][1]
            jac[2 + i, 2 + i] += rates[i][2]
        return jac

    def _jacobian_cutoff(self, y: np.ndarray, vlp: float) -> np.ndarray:
        """Jacobian with A(x) = dmu/dx and B_i(psi_i) = dmu/dpsi_i varying (docs/rsf.md, Laws); H = 0."""
        c, o, n = self.cutoff, self.offset, self.n
        assert c is not None
        x = float(y[o])
        psi = [float(p) for p in y[o + 1 :]]
        v = self.v0 * _exp(x)
        rates = [law.rate(x, p, self.v0, dc) for law, p, dc in zip(self.laws, psi, self.dc, strict=True)]
        A, dA = c.direct(self.a, x)
        weights = [c.evolution(b, p) for b, p in zip(self.b, psi, strict=True)]
        jac = np.zeros((self.size, self.size))
        for i in range(n):
            jac[o + 1 + i, o] = rates[i][1]
            jac[o + 1 + i, o + 1 + i] = rates[i][2]
        if self.inertial:  # xdot = (s - mu - eta V)/(m' V)
            mv = self.inertia * v
            xdot = (float(y[0]) - self.friction(x, psi) - self.eta * v) / mv
            jac[0, 1] = -self.k * v
            jac[1, 0] = 1.0 / mv
            jac[1, 1] = (-A - self.eta * v) / mv - xdot
            for j in range(n):
                jac[1, 2 + j] = -weights[j][0] / mv
            return jac
        G = sum(w[0] * r[0] for w, r in zip(weights, rates, strict=True))
        D = A + self.eta * v
        xdot = (self.k * (vlp - v) - G) / D
        jac[0, 0] = (-self.k * v - sum(w[0] * r[1] for w, r in zip(weights, rates, strict=True))
                     - xdot * (dA + self.eta * v)) / D  # fmt: skip
        for j in range(n):
            jac[0, 1 + j] = -(weights[j][1] * rates[j][0] + weights[j][0] * rates[j][2]) / D
        return jac

    # ------------------------------------------------------------------ states
    def steady_y(self, velocity: float) -> np.ndarray:
        """The steady state at slider velocity ``velocity`` (> 0)."""
        x = math.log(velocity) - math.log(self.v0)  # the ratio itself can overflow (v0 = 5e-324 m/s)
        psi = [-x] * self.n
        head = [self.friction(x, psi) + self.eta * velocity] if self.inertial else []
        return np.array([*head, x, *psi])

    def theta(self, psi: np.ndarray) -> np.ndarray:
        """State variables theta_i (s) from the state terms psi_i; shape (n, ...)."""
        scale = np.array([law.theta_scale * dc / self.v0 for law, dc in zip(self.laws, self.dc, strict=True)])
        return scale.reshape((-1,) + (1,) * (np.ndim(psi) - 1)) * np.exp(np.minimum(psi, EXP_CAP))


def _asinh_half_exp(z: float) -> float:
    """asinh(e^z / 2) without overflow."""
    if z > 0:
        return z + math.log(0.5 + 0.5 * math.sqrt(1.0 + 4.0 * math.exp(-2.0 * z)))
    return math.asinh(0.5 * math.exp(z))


def _half_exp_ratio(z: float) -> float:
    """w / sqrt(1 + w^2) with w = e^z/2, for z <= 0."""
    w = 0.5 * math.exp(z)
    return w / math.sqrt(1.0 + w * w)


def _states_rhs(system: System) -> Callable[[float, np.ndarray, float], list[float]]:
    """:meth:`System._rhs_classical` for several state variables, each law's g alone (``state_rate``: no tuple of
    derivatives, no call per exponential), the numbers bound as locals and cexp written out (the same arithmetic
    in the same order: the same numbers); two states, the common case, without a loop."""
    v0, k, a, eta, exp, cap = system.v0, system.k, system.a, system.eta, math.exp, EXP_CAP
    terms = [(law.state_rate(v0, dc), b) for law, b, dc in zip(system.laws, system.b, system.dc, strict=True)]
    if len(terms) == 2:
        (rate1, b1), (rate2, b2) = terms

        def two(t: float, y: np.ndarray, vlp: float) -> list[float]:
            x, p1, p2 = y.tolist()
            g1 = rate1(x, p1)
            g2 = rate2(x, p2)
            v = v0 * exp(x if x < cap else cap)
            return [(k * (vlp - v) - (0.0 + b1 * g1 + b2 * g2)) / (a + eta * v), g1, g2]

        return two

    def rhs(t: float, y: np.ndarray, vlp: float) -> list[float]:
        x, *psi = y.tolist()
        out = [0.0]
        G = 0.0
        for (rate, b), p in zip(terms, psi):  # noqa: B905  (lengths match by construction)
            g = rate(x, p)
            out.append(g)
            G += b * g
        v = v0 * exp(x if x < cap else cap)
        out[0] = (k * (vlp - v) - G) / (a + eta * v)
        return out

    return rhs


def _one_state_rhs(system: System) -> Callable[[float, np.ndarray, float], list[float]]:
    """:meth:`System._rhs_classical` for one state variable, its numbers bound as locals and cexp written out."""
    ((_, b, dc),) = system._terms
    v0, k, a, eta, exp, cap = system.v0, system.k, system.a, system.eta, math.exp, EXP_CAP
    rate = system.laws[0].state_rate(v0, dc)  # g alone (the built-in laws: no tuple, no call per exponential)

    def rhs(t: float, y: np.ndarray, vlp: float) -> list[float]:
        x, p = y.tolist()
        g = rate(x, p)
        v = v0 * exp(x if x < cap else cap)
        return [(k * (vlp - v) - (0.0 + b * g)) / (a + eta * v), g]

    return rhs


def _classical_jacobian(system: System) -> Callable[[float, np.ndarray, float], np.ndarray]:
    """:meth:`System.jacobian` for the classical form without mass or dmu/dt coupling (``system.classical``), its
    numbers bound as locals: the same arithmetic in the same order (Q = 1 - sum b h and the h terms kept, so that a
    non-finite entry stays what the general form gives; tests/test_rsf_laws.py holds the two equal, bit for bit)."""
    v0, k, a, eta, Q, n = system.v0, system.k, system.a, system.eta, system.one_minus_h, system.n
    terms = [(law.rate, b, dc, h) for law, b, dc, h in zip(system.laws, system.b, system.dc, system.h, strict=True)]
    exp, cap = math.exp, EXP_CAP

    def jacobian(t: float, y: np.ndarray, vlp: float) -> np.ndarray:
        x, *psi = y.tolist()
        v = v0 * exp(x if x < cap else cap)
        rates = [rate(x, p, v0, dc) for (rate, _, dc, _), p in zip(terms, psi)]  # noqa: B905  (lengths match)
        G = 0
        S = 0
        for (_, b, _, _), r in zip(terms, rates):  # noqa: B905
            G += b * r[0]
            S += b * r[1]
        D = a + Q * eta * v
        xdot = (Q * k * (vlp - v) - G) / D
        dxx = (-Q * k * v - S - xdot * Q * eta * v) / D
        top = [dxx, *(-b * r[2] / D for (_, b, _, _), r in zip(terms, rates))]  # noqa: B905
        dmu_dx = (a * dxx + S) / Q
        dmu = [(a * top[j + 1] + terms[j][1] * rates[j][2]) / Q for j in range(n)]
        rows = [top]
        for i in range(n):
            h, r = terms[i][3], rates[i]
            rows.append([r[1] + h * dmu_dx, *((r[2] if i == j else 0.0) + h * dmu[j] for j in range(n))])
        return np.array(rows)

    return jacobian
