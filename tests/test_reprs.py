"""Issue 28 item 7: results print a short summary (scalars, arrays as counts), and CriticalPoint has to_frame."""

from __future__ import annotations

import numpy as np
import pytest

import stickslip
from stickslip.quasistatic.stick import stick_phase
from stickslip.reprs import short_value

P = stickslip.load_parameters("gelatin-glass")


def _results():
    sim = stickslip.simulate(P, pulling_velocity=50e-6, duration=30.0)
    return {
        "steady": stickslip.steady_state(P, np.geomspace(1e-5, 1e-2, 500)),
        "critical": stickslip.critical_point(P),
        "simulation": sim,
        "stick": stick_phase(P, 50e-6),
        "run": stickslip.run("quasi-static", P, stickslip.protocols.constant(50e-6, 30.0)),
    }


@pytest.mark.parametrize("name", ["steady", "critical", "simulation", "stick", "run"])
def test_a_result_prints_a_few_lines_whatever_its_size(name):
    result = _results()[name]
    text = repr(result)
    assert len(text) < 1200 and "..." not in text.replace("...'", ""), text
    assert type(result).__name__ in text
    arrays = [v for v in vars(result).values() if isinstance(v, np.ndarray) and v.size > 6]
    for array in arrays:  # no element of a long array is printed, only its count
        assert f"<{array.size} values>" in text


def test_short_values_say_what_is_not_a_number_in_words():
    assert short_value(float("nan")) == "not a number" and short_value(float("inf")) == "infinite"
    assert short_value(np.zeros((3, 4))) == "<array 3x4>" and short_value(0.1 + 0.2) == "0.3"


def test_critical_point_to_frame_is_its_dict_with_units():
    c = stickslip.critical_point(P)
    frame = c.to_frame()
    assert len(frame) == 1
    assert frame.loc[0, "critical_velocity"] == c.velocity and frame.loc[0, "critical_stress"] == c.stress
    assert frame.attrs["units"]["critical_velocity"] == "m/s" and frame.attrs["units"]["critical_stress"] == "Pa"


def test_critical_point_plots_its_extrema_alone_or_over_a_curve():
    """Every result has plot(ax=None) (the README says so; CriticalPoint had none): the minimum at (Vc, sigma_c)
    as Eq 9 gives them, the maximum open, over a steady curve's own Axes when given them."""
    import matplotlib

    matplotlib.use("Agg")
    point = stickslip.critical_point(P)
    ax = point.plot()
    (minimum,) = [line for line in ax.get_lines() if line.get_label() == "critical point (Eq 9)"]
    assert minimum.get_xdata()[0] == pytest.approx(point.velocity * 1e6, rel=1e-12)  # µm/s
    assert minimum.get_ydata()[0] == pytest.approx(point.stress, rel=1e-12)
    assert ax.get_xscale() == "log" and any(line.get_label().startswith("maximum at") for line in ax.get_lines())
    curve = stickslip.steady_state(P, np.geomspace(1e-5, 1e-2, 50)).plot()
    assert point.plot(ax=curve) is curve and len(curve.get_lines()) == 3
    flat = stickslip.critical_point(P.with_overrides({"bonds.bond_time": 1e-9}))  # no minimum: its message shown
    assert not flat.exists and flat.message in [text.get_text() for text in flat.plot().texts]
