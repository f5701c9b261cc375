"""The bond model beside rate-and-state on the same experiments (``stickslip compare`` without ``--models``).

Three panels: a velocity step and a slide-hold-slide (the bond model's response and the RSF run of each) and
stick-slip (the bond model's jump cycle beside the RSF limit cycle).  Friction is stress over sigma_c on both sides.
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from .style import apply_style, new_axes

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

BOND_COLOR = "#1f4e9c"
RSF_COLOR = "#c0392b"


def figure_bond_and_rsf(panels: Mapping[str, Any], pair: Mapping[str, Any], rsf: Any, how: str) -> Figure:
    """The three panels of ``stickslip compare``, one row.

    ``panels``: name -> (bond response, RSF run or None, problem or None) of the velocity step and the
    slide-hold-slide (:func:`stickslip.studies.bond_rsf.bond_response`, :func:`stickslip.rsf.simulate`);
    ``pair``: :func:`stickslip.studies.bond_rsf.stick_slip_pair`; ``rsf``: the RSF standing for the bond model
    (:func:`stickslip.studies.bond_rsf.rsf_of_bond`); ``how``: how its a, b, Dc were found, in words.
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(12, 4.2), layout="constrained")
    axes = fig.subplots(1, 3)
    for ax, (name, (bond, run, problem)) in zip(axes[:2], panels.items(), strict=True):
        plot_panel(name, bond, run, problem, rsf.sigma_c, f"rate-and-state ({how})", ax=ax)
    plot_stick_slip_pair(pair, rsf.sigma_c, ax=axes[2])
    p = rsf.params
    fig.suptitle(f"One RSF set for all panels: a = {p.a:.3g}, b = {p.b:.3g}, Dc = {p.dc * 1e6:.3g} µm ({how})",
                 fontsize=9)  # fmt: skip
    return fig


def plot_panel(
    name: str, bond: Any, run: Any, problem: str | None, sigma_c: float, label: str, ax: Axes | None = None
) -> Axes:
    """One experiment: the bond model's stress and the RSF friction (``label``), both over sigma_c."""
    ax = new_axes(ax)
    ax.plot(bond.time, np.where(bond.stress > 0, bond.stress / sigma_c, np.nan), color=BOND_COLOR, lw=1.6,
            label=bond.source)  # fmt: skip
    if run is not None:
        shown = np.where(run.friction > 0, run.friction, np.nan)  # negative friction is not drawn
        ax.plot(run.time, shown, color=RSF_COLOR, lw=1.2, ls="--", label=label)
    if problem:
        say(ax, "RSF: " + problem)
    if name == "slide-hold-slide":
        # log: the re-sliding peak of the bond model can be 10^3 times its sliding stress; both must show
        ax.set_yscale("log")
    else:
        ax.set_ylim(bottom=0.0)  # friction is not negative: an RSF curve that reaches 0 is cut there
        ax.ticklabel_format(axis="y", useOffset=False)
    ax.set_title(name, fontsize=10)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("stress / σc")
    ax.legend(fontsize=7, frameon=False, loc="lower right")
    return apply_style(ax)


def plot_stick_slip_pair(pair: Mapping[str, Any], sigma_c: float, ax: Axes | None = None) -> Axes:
    """The bond model's jump cycle beside the RSF run at the same V0, stiffness and sigma_c."""
    ax = new_axes(ax)
    bond, run = pair["bond"], pair["rsf"]
    ax.plot(bond.time, bond.stress / sigma_c, color=BOND_COLOR, lw=1.4, label="bond model: jump cycle")
    if run is not None:
        shown = np.where(run.friction >= 0, run.friction, np.nan)
        regime = "failed" if pair["problem"] else run.regime.name
        ax.plot(run.time, shown, color=RSF_COLOR, lw=1.0, label=f"RSF: {regime}")
    if pair["problem"]:
        say(ax, "RSF: " + pair["problem"], top=False)  # the cycle fills the top; friction below sigma_c is empty
    ax.set_ylim(bottom=0.0)
    ax.set_title("stick-slip at the same V0, stiffness, σc", fontsize=10)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("stress / σc")
    ax.legend(fontsize=7, frameon=False, loc="lower right")
    return apply_style(ax)


def say(ax: Axes, text: str, top: bool = True) -> None:
    """A problem written in red in a corner of the panel (wrapped to fit)."""
    ax.text(0.02, 0.98 if top else 0.02, textwrap.fill(text, 60), transform=ax.transAxes, fontsize=6.5,
            color=RSF_COLOR, va="top" if top else "bottom")  # fmt: skip


__all__ = ["figure_bond_and_rsf", "plot_panel", "plot_stick_slip_pair", "say"]
