#!/usr/bin/env bash
# Build the documentation site (MkDocs, docs/documentation.md) and check it in a real browser.
#
#   bash scripts/build-docs.sh            # the site in ./site (open site/index.html through a web server)
#
# Makes (or reuses) a virtual environment with the `docs` extra (STICKSLIP_VENV, default .venv), executes the
# example notebooks once on fresh kernels (scripts/run-notebooks.py), writes the report (`stickslip reproduce`),
# builds the site with `mkdocs build --strict` (any warning fails the build) into STICKSLIP_SITE (default
# ./site), and checks it in headless Chromium (scripts/check-site.py).  Prints the time of each step.
# STICKSLIP_DOCS_NO_INSTALL=1 uses the environment as it is (to rebuild quickly after editing a page).
set -euo pipefail
cd "$(dirname "$0")/.."

venv="${STICKSLIP_VENV:-.venv}"
site="${STICKSLIP_SITE:-site}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

step() {  # step NAME COMMAND...: run one step, print how long it took
  local name="$1" start
  shift
  start=$(date +%s)
  "$@"
  echo "build-docs: $name: $(($(date +%s) - start)) s"
}

install() {
  python3 -m venv "$venv"
  "$venv/bin/python" -m pip install -q --upgrade pip
  # editable: the API pages are read from src/ anyway; scripts/check-wheel.sh checks the installed wheel
  "$venv/bin/python" -m pip install -q -e ".[docs]" "pytest>=7.4"
}

if [ "${STICKSLIP_DOCS_NO_INSTALL:-0}" = 1 ]; then
  echo "build-docs: install: skipped (STICKSLIP_DOCS_NO_INSTALL=1; using $venv as it is)"
else
  step "install" install
fi
# the tests the test command's environment skips without the docs extra (the hook's; the notebooks' schema): run here
step "hook and notebook tests" "$venv/bin/python" -m pytest -q -p no:cacheprovider tests/test_docs_site.py \
  tests/test_notebooks_static.py
step "notebooks" "$venv/bin/python" scripts/run-notebooks.py --out "$work/examples"
step "report" "$venv/bin/stickslip" reproduce -o "$work/report" --quiet
export NO_MKDOCS_2_WARNING=1 STICKSLIP_DOCS_NOTEBOOKS="$work/examples" STICKSLIP_DOCS_REPORT="$work/report"
step "mkdocs build --strict" "$venv/bin/mkdocs" build --strict --quiet -d "$(realpath -m "$site")"
step "browser check" "$venv/bin/python" scripts/check-site.py "$site"
echo "build-docs: the site is in $site/"
