"""Issue 32 item 1: the licence, the citation and the changelog ship; ``python -m stickslip`` and ``--version``."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import stickslip

ROOT = Path(__file__).resolve().parents[1]


def test_python_dash_m_is_the_command_line_and_reports_the_version():
    done = subprocess.run([sys.executable, "-m", "stickslip", "--version"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert stickslip.__version__ in done.stdout and "stickslip" in done.stdout


def test_licence_citation_and_changelog_agree_with_the_package():
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert project["license"] == "MIT" and (ROOT / "LICENSE").read_text(encoding="utf-8").startswith("MIT License")
    import yaml  # (dask's dependency): the citation must be valid YAML, as GitHub and Zenodo read it

    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert citation["version"] == project["version"] and citation["license"] == "MIT"
    assert citation["cff-version"] == "1.2.0" and citation["title"] and citation["authors"]
    paper = citation["references"][0]
    assert paper["title"] == "Analysis of Stick-Slip Motion as a Jump Phenomenon"
    assert [a["family-names"] for a in paper["authors"]] == ["Juvekar", "Singh"]
    assert f"## [{project['version']}]" in (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
