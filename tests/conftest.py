"""Fixtures shared by the whole suite."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from stickslip import critical_point, load_parameters


@pytest.fixture(scope="session")
def params():
    """The paper's parameter set (frozen, so sharing it is safe)."""
    return load_parameters("gelatin-glass")


@pytest.fixture(scope="session")
def critical(params):
    """Vc and sigma_c of gelatin-glass (Eq 9)."""
    return critical_point(params)


@pytest.fixture(scope="session")
def sigma_c(critical):
    return critical.stress


@pytest.fixture(scope="session")
def runner() -> CliRunner:
    return CliRunner()
