#!/usr/bin/env bash
# The release as a user gets it: build the sdist and, from it, the wheel; install the wheel (not editable) in a
# fresh virtual environment; run it from a folder outside the checkout, so `src/` cannot be imported.
#
#   bash scripts/check-wheel.sh                 # STICKSLIP_DIST=DIR keeps the built sdist and wheel in DIR
#
# Checks: every file of src/stickslip that git tracks is in the wheel and in the sdist (the data files, the
# parameter sets and the report's templates included); `stickslip --version` is pyproject's version;
# `stickslip critical` gives the critical point; the shipped data load through the package; one example notebook
# runs on a fresh kernel of that environment (scripts/run-notebooks.py; STICKSLIP_WHEEL_NOTEBOOK=NAME picks it).
# Prints the time of each step.
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$(pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
dist="${STICKSLIP_DIST:-$work/dist}"
# default: the rate-and-state notebook (it reads the shipped sepiolite record through the package, and compiles no
# numba kernels, which a fresh environment would spend a minute on); else examples/' first notebook
first="$(find examples -maxdepth 1 -name '*.ipynb' | sort | head -1)"
[ -f examples/03-rate-and-state-record.ipynb ] && first=examples/03-rate-and-state-record.ipynb
notebook="${STICKSLIP_WHEEL_NOTEBOOK:-$(basename "${first:-none}" .ipynb)}"

step() {  # step NAME COMMAND...: run one step, print how long it took
  local name="$1" start
  shift
  start=$(date +%s)
  "$@"
  echo "check-wheel: $name: $(($(date +%s) - start)) s"
}

build() {
  python3 -m venv "$work/build-venv"
  "$work/build-venv/bin/python" -m pip install -q build
  rm -rf "$dist"
  # without --sdist/--wheel, build makes the sdist and then the wheel from the unpacked sdist: a file missing
  # from the sdist is missing from the wheel too, and the check below finds it
  "$work/build-venv/bin/python" -m build -q --outdir "$dist" . >"$work/build.log" 2>&1 || {
    cat "$work/build.log"
    return 1
  }
  ls "$dist"
}

contents() {
  git ls-files src/stickslip >"$work/tracked"
  python3 - "$dist" "$work/tracked" <<'EOF'
import sys, tarfile, zipfile
from pathlib import Path

dist, tracked = Path(sys.argv[1]), Path(sys.argv[2]).read_text().split()
(wheel,), (sdist,) = list(dist.glob("stickslip-*.whl")), list(dist.glob("stickslip-*.tar.gz"))
in_wheel = set(zipfile.ZipFile(wheel).namelist())
with tarfile.open(sdist) as tar:
    in_sdist = {name.split("/", 1)[1] for name in tar.getnames() if "/" in name}
missing = [f"wheel: {p}" for p in tracked if p.removeprefix("src/") not in in_wheel]
missing += [f"sdist: {p}" for p in tracked if p not in in_sdist]
missing += [f"sdist: {p}" for p in ("LICENSE", "README.md", "pyproject.toml") if p not in in_sdist]
if not any(p.endswith("/licenses/LICENSE") for p in in_wheel):
    missing.append("wheel: the LICENSE file (dist-info/licenses/LICENSE)")
data = [p for p in tracked if not p.endswith(".py")]
print(f"check-wheel: {len(tracked)} tracked files of src/stickslip in the wheel and the sdist ({len(data)} data files)")
for p in missing:
    print(f"check-wheel: MISSING from the {p}", file=sys.stderr)
sys.exit(1 if missing else 0)
EOF
}

install() {
  python3 -m venv "$work/venv"
  "$work/venv/bin/python" -m pip install -q --upgrade pip
  # the wheel itself (no checkout, not editable) and what running a notebook needs
  "$work/venv/bin/python" -m pip install -q "$dist"/stickslip-*.whl nbclient nbformat ipykernel
}

run_installed() {
  local bin="$work/venv/bin" version
  cd "$work"  # outside the checkout: only the installed package can be imported
  unset PYTHONPATH
  "$bin/python" -c "import stickslip, sys; f = stickslip.__file__; print(f); sys.exit('site-packages' not in f)"
  version="$(sed -n 's/^version = "\(.*\)"/\1/p' "$repo/pyproject.toml")"
  "$bin/stickslip" --version | tee "$work/version"
  grep -q "$version" "$work/version" || { echo "check-wheel: --version does not say $version" >&2; return 1; }
  "$bin/python" -m stickslip --version >/dev/null
  "$bin/stickslip" critical
  "$bin/stickslip" params list
  "$bin/python" - <<'EOF'
from importlib import resources

import stickslip
from stickslip.fitting import datasets

p = stickslip.load_parameters("gelatin-glass")
table = datasets.table1()
steady = stickslip.fitting.read_steady_data(datasets.synthetic_steady_path())
report = resources.files("stickslip") / "report"
templates = [(report / name).read_text(encoding="utf-8") for name in ("template.html", "style.css", "errata.md")]
sepiolite = sorted(p.name for p in (resources.files("stickslip") / "data" / "giacomel-sepiolite").iterdir())
print(f"check-wheel: data load: {len(table)} Table 1 cycles, {len(steady.velocity)} synthetic steady points, "
      f"{len(templates)} report templates, sepiolite files {sepiolite}")
EOF
  cd "$repo"
}

notebook() {
  cd "$work"
  unset PYTHONPATH
  "$work/venv/bin/python" "$repo/scripts/run-notebooks.py" --out "$work/notebooks" "$notebook"
  cd "$repo"
}

step "build sdist and wheel" build
step "contents" contents
step "install the wheel in a fresh venv" install
step "run the installed package" run_installed
step "notebook $notebook from the installed package" notebook
echo "check-wheel: ok"
