#!/usr/bin/env bash
# The README's test command: from a fresh machine to a finished test run.
# Installs Debian's chromium + chromium-driver (the report is checked in a real
# browser), makes a fresh virtual environment, installs stickslip with its test
# extras from this checkout, lints, and runs pytest (arguments go to pytest).
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v chromium >/dev/null 2>&1 || ! command -v chromedriver >/dev/null 2>&1; then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  $sudo apt-get update -qq
  # without recommends: the browser, its driver and their libraries (26 new packages on a Debian 12 machine
  # that had Python and X libraries already; no perl or systemd upgrades)
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends chromium chromium-driver
fi

venv="${STICKSLIP_VENV:-.venv}"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
"$venv/bin/python" -m pip install -q ".[test]"

"$venv/bin/ruff" check src tests benchmarks scripts
"$venv/bin/ruff" format --check src tests benchmarks scripts

# run from the tests' view of an installed package (not the source tree); one worker process per core
# (pytest-xdist), each test file on one worker so its module fixtures are built once; the files in
# tests/conftest.py's order, heaviest first, not xdist's (most tests first), so that no long file starts last
# (docs/documentation.md, "The test command": the figures)
# the plugins named, not loaded from every installed package: pytest rewrites the asserts of each autoloaded
# plugin's whole distribution, all of hypothesis's modules in each worker (~1.8 s of CPU a worker, 2026-11-30)
PYTEST_DISABLE_PLUGIN_AUTOLOAD=1 "$venv/bin/python" -m pytest -p xdist.plugin -p _hypothesis_pytestplugin \
  -n "${STICKSLIP_TEST_WORKERS:-auto}" --dist loadfile --no-loadscope-reorder "$@"
