"""Data shipped with the package (``src/stickslip/data/``, described in its README.md).

* :func:`table1`: the paper's Table 1 -- stick-slip cycles *measured* by
  Baumberger et al. (2002), as printed by Juvekar & Singh.
* :func:`synthetic_steady_path`: a *synthetic* steady friction curve made
  from the built-in ``gelatin-glass`` parameters with 2 % noise
  (``scripts/make_synthetic.py``), for examples and tests.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

from .data import read_stick_data

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd


def data_path(name: str) -> Path:
    """Path of a file in the package's data folder."""
    return Path(str(resources.files("stickslip") / "data" / name))


def table1_path() -> Path:
    """Path of ``table1.csv`` (units in the header, '#' comment lines)."""
    return data_path("table1.csv")


def table1() -> pd.DataFrame:
    """The paper's Table 1 as a DataFrame in SI units, one row per stick-slip cycle (NaN for '--')."""
    return read_stick_data(table1_path()).to_frame().drop(columns="row")


def synthetic_steady_path() -> Path:
    """Path of ``synthetic_steady.csv``: SYNTHETIC sigma(V) from gelatin-glass, 2 % noise, stated stress_err."""
    return data_path("synthetic_steady.csv")
