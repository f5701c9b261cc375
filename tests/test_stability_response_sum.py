"""The interface response's compiled sum (``stability._response_sum``) against the same quadrature written plainly:
each cell's e^{-s d/2}, e^{-s d} and e^{-s a} taken directly with ``cmath.exp`` in Python (the compiled sum takes one
exp per cell and the rest as products, re-anchored every ``REANCHOR`` cells; docs/transient.md section 6)."""

from __future__ import annotations

import cmath

import numpy as np
import pytest

import stickslip
from stickslip.transient import stability


def _plain(s: complex, a, w, width, f, fp, r, gv, c_f: float, birth_tau: float) -> tuple[complex, complex]:  # type: ignore[no-untyped-def]
    def phi1(x: complex) -> complex:
        return 1.0 - x / 2.0 + x * x / 6.0 if abs(x) < 1e-4 else (1.0 - cmath.exp(-x)) / x

    e_acc = r_acc = s_wphi = s_wfe = s_we = s_wphif = s_inst = 0j
    for k in range(a.size):
        d = float(width[k])
        q1 = r[k] * (c_f * fp[k] + s * gv[k])
        q2 = r[k] * c_f * fp[k]
        e_mid = e_acc * cmath.exp(-s * 0.5 * d) + q1 * phi1(s * 0.5 * d) * 0.5 * d
        r_mid = r_acc + q2 * 0.5 * d
        e_acc = e_acc * cmath.exp(-s * d) + q1 * phi1(s * d) * d
        r_acc = r_acc + q2 * d
        ea = cmath.exp(-s * a[k])
        phi = e_mid - ea * r_mid
        s_wphi += w[k] * phi
        s_wfe += w[k] * f[k] * ea
        s_we += w[k] * ea
        s_wphif += w[k] * phi * f[k]
        s_inst += w[k] * fp[k] * (1.0 - ea)
    return s_wphi * s_wfe / (birth_tau + s_we) - s_wphif + s_inst, -s_wphi * birth_tau / (birth_tau + s_we)


@pytest.mark.parametrize("velocity", [1e-6, 120e-6])
def test_the_compiled_sum_is_the_plain_quadrature(velocity: float) -> None:
    params = stickslip.load_parameters("gelatin-glass")
    b = params.bonds
    cells = stability._cells(params, velocity, True)
    birth_tau = (b.site_density - cells[1].sum()) / b.bond_time * b.bond_time
    rates = np.array([1e-3 + 1j, 10 + 100j, 0.5 + 3000j, 1e-7j, 2e5 + 4e4j])
    got = stability._response_kernel()(rates, *cells, b.force_sensitivity, birth_tau)
    for j, s in enumerate(rates):
        z, n = _plain(complex(s), *cells, b.force_sensitivity, birth_tau)
        assert abs(got[0, j] - z) <= 1e-9 * abs(z), (s, got[0, j], z)
        assert abs(got[1, j] - n) <= 1e-9 * abs(n), (s, got[1, j], n)


@pytest.mark.parametrize(("velocity", "aging"), [(1e-6, True), (120e-6, True), (120e-6, False), (3e-3, True)])
def test_the_compiled_cells_are_the_python_march(velocity: float, aging: bool) -> None:
    """The cells of the response (the reduction's compiled march) against model.steady_population's Python march:
    the same cells; ages, weights, forces, stiffnesses, rates and aging slopes to rounding (within 1e-11 of each
    array's largest value; measured 5e-13); the widths within 1e-9 (the Python layout rebuilds them from the
    midpoints one after another, which carries 9e-11 of rounding into the cells at the FENE wall; the compiled
    march takes them from its edges) and tiling the same ages."""
    params = stickslip.load_parameters("gelatin-glass")
    fast = stability._cells(params, velocity, aging)
    plain = stability._cells_plain(params, velocity, aging)
    names = ("age", "weight", "width", "force", "stiffness", "rate", "aging slope")
    for name, x, y in zip(names, fast, plain, strict=True):
        assert x.shape == y.shape, name
        bound = 1e-9 if name == "width" else 1e-11
        assert np.max(np.abs(x - y)) <= bound * np.max(np.abs(y)), name
    age, width = fast[0], fast[2]
    assert np.sum(width) == pytest.approx(age[-1] + 0.5 * width[-1], rel=1e-12)


def test_the_response_from_the_compiled_cells_is_the_python_marchs() -> None:
    """Z(s) on either march's cells, at rates about Kc's crossing at 120 µm/s (32.7 Hz) and far from it: within
    1e-10 (Kc itself moved by 3e-15 when the compiled cells replaced the Python march, 1.5e-13 at 1 µm/s)."""
    params = stickslip.load_parameters("gelatin-glass")
    b = params.bonds
    rates = np.array([1e-3 + 1j, 205.0 + 205.2j, 1e4j])
    responses = []
    for cells in (stability._cells(params, 120e-6, True), stability._cells_plain(params, 120e-6, True)):
        birth_tau = (b.site_density - cells[1].sum()) / b.bond_time * b.bond_time
        responses.append(stability._response_kernel()(rates, *cells, b.force_sensitivity, birth_tau)[0])
    assert np.all(np.abs(responses[0] - responses[1]) <= 1e-10 * np.abs(responses[1]))


def _counting(monkeypatch: pytest.MonkeyPatch) -> list[np.ndarray]:
    """Every array of rates ``interface_response`` is asked for, in order (the real function still answers)."""
    asked: list[np.ndarray] = []
    real = stability.interface_response

    def counted(params, velocity, s, aging=True, cell_hazard=stability.CELL_HAZARD):  # type: ignore[no-untyped-def]
        asked.append(np.atleast_1d(np.asarray(s, dtype=complex)).copy())
        return real(params, velocity, s, aging, cell_hazard)

    monkeypatch.setattr(stability, "interface_response", counted)
    return asked


def test_kc_from_the_memo_is_kc_from_fresh_responses_and_a_second_mass_pays_only_its_bisection(monkeypatch):
    """Kc's scan of Z is the same for any block mass: a process evaluates each rate once (stability._response).

    Against critical_from_response on a plain response (every rate computed afresh): the same Kc, mode and rate
    to the bit, massless and with a mass; the memo's values equal fresh ones to the bit; a second Kc at the same
    velocity asks only for its bisection's rates (30 per crossing), and the imaginary scan stops at the resolved
    frequency (a crossing above it is ignored, so Z there was never needed)."""
    params = stickslip.load_parameters("gelatin-glass").with_overrides({"bonds.bond_time": 0.3e-3})  # a fresh memo
    velocity = 120e-6
    stability._memo.cache_clear()
    asked = _counting(monkeypatch)
    first = stability.critical_stiffness_details(params, velocity, True, 0.0, 0.0)
    evaluated_first = sum(a.size for a in asked)
    top = stability.resolved_frequency(params, velocity, True)
    scan = stability.SCAN / params.bonds.bond_time
    assert first.mode == "oscillatory" and first.value > 0
    imaginary = np.concatenate([a for a in asked if np.all(a.real == 0.0)])
    assert np.max(imaginary.imag) <= max(top, first.rate * 1.0001) and imaginary.size < scan.size + 40
    asked.clear()
    # a mass alone leaves Im D(i w) and so the bisection's rates as they were; a damping moves them
    heavy = stability.critical_stiffness_details(params, velocity, True, 50.0, 1e4)
    assert 0 < sum(a.size for a in asked) <= 30 * 4, [a.size for a in asked]
    assert evaluated_first > 500

    def plain(s: np.ndarray) -> np.ndarray:
        return stability.interface_response(params, velocity, s, True).z

    for got, mass, damping in ((first, 0.0, 0.0), (heavy, 50.0, 1e4)):
        want = stability.critical_from_response(plain, scan, mass, damping, top)
        assert (got.value, got.mode, got.rate) == (want.value, want.mode, want.rate), (got, want)
    rates = np.concatenate([scan[::37], 1j * scan[::41], [3.0 + 4.0j]])
    assert np.array_equal(stability._response(params, velocity, True)(rates), plain(rates))
