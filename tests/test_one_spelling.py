"""One spelling per quantity (stickslip.display): the sweep figures' axis names and the protocol's description
write symbols and velocities as every other message does."""

from __future__ import annotations

from dataclasses import fields

from stickslip.display import symbol, velocity
from stickslip.parameters import SECTIONS
from stickslip.plots.sweeps import _parameter_name
from stickslip.protocols import segments


def test_a_sweep_axis_names_every_parameter_by_its_shown_symbol():
    """Before: the sweep figures had their own table and wrote the stick chains' break rate as uc/tau."""
    assert _parameter_name("stick.break_rate").endswith(" uc/τ")
    for section, kind in SECTIONS.items():
        for field in fields(kind):
            assert _parameter_name(f"{section}.{field.name}").endswith(" " + symbol(field.metadata["symbol"]))


def test_a_protocol_describes_its_velocities_as_display_writes_them():
    protocol = segments([(1e-4, 10.0), (7.02e-4, 20.0)])
    assert protocol.describe() == f"{velocity(1e-4)} for 10 s, then {velocity(7.02e-4)} for 20 s"
    assert protocol.describe() == "100 µm/s for 10 s, then 702 µm/s for 20 s"
