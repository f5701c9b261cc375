"""Coverage of the steady fit's 95 % intervals of the parameters, Vc and σc over many synthetic data sets (round 27).

The study behind docs/fitting.md, "Uncertainty of the parameters".  Designs (``--design``):

* ``tester``: tester E's -- gelatin-glass with τ = 300 µs, Va = 250 µm/s, τa = 1.2 ms; 25 points geometric from
  80 µm/s to 3 mm/s; 2 % Gaussian noise; set ``seed`` drawn by ``default_rng(100 + seed)`` (their t11_steadyfit.py).
* ``paper``: the shipped curve's design -- gelatin-glass, 24 points from 140 µm/s to 2 mm/s, 2 % noise,
  ``default_rng(seed)`` (tests/test_fit_steady.py's ``noisy``).
* ``nomin9``: tester F's -- gelatin-glass, 9 points from 5 to 90 µm/s (no minimum in the data: Vc = 124.1 µm/s
  lies above them), 2 % relative noise, ``default_rng(seed)``.

``--noise stated`` gives the fit the errors (2 % of the true stress); ``estimated`` leaves them out (relative noise
estimated from the residuals).  ``--method`` and ``--intervals`` are passed to ``fit_steady`` (``auto``/``none``:
the defaults).  Prints one line per set and the counts of intervals holding the truth, with the binomial standard
deviation at 95 %.  About 0.5-0.8 s of CPU per set on one core.

Run: ``python benchmarks/bench_fit_parameter_coverage.py --design tester --seeds 200 [--method two-step]``
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from stickslip.fitting import SteadyData, fit_steady
from stickslip.parameters import load_parameters
from stickslip.quasistatic.critical import critical_point
from stickslip.quasistatic.steady import steady_state

KEYS = (
    "bonds.site_density",
    "bonds.bond_time",
    "bonds.activation_length",
    "aging.aging_time",
    "aging.aging_velocity",
)


def design(name: str) -> tuple[object, np.ndarray, int]:
    """(truth, velocities, seed offset) of a design."""
    if name == "tester":
        truth = load_parameters(
            "gelatin-glass",
            overrides={"bonds.bond_time": "300 us", "aging.aging_velocity": "250 um/s", "aging.aging_time": "1.2 ms"},
        )
        return truth, np.geomspace(80e-6, 3e-3, 25), 100
    if name == "paper":
        return load_parameters("gelatin-glass"), np.geomspace(140e-6, 2000e-6, 24), 0
    if name == "nomin9":
        return load_parameters("gelatin-glass"), np.geomspace(5e-6, 90e-6, 9), 0
    raise SystemExit(f"unknown design {name!r}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--design", default="tester", choices=["tester", "paper", "nomin9"])
    parser.add_argument("--seeds", type=int, default=200)
    parser.add_argument("--first", type=int, default=0)
    parser.add_argument("--method", default="auto", choices=["auto", "two-step", "joint"])
    parser.add_argument("--intervals", default="none", choices=["none", "delta", "profile", "bootstrap"])
    parser.add_argument("--noise", default="stated", choices=["stated", "estimated"])
    args = parser.parse_args()
    truth, velocity, offset = design(args.design)
    point = critical_point(truth)
    values = truth.as_dict()  # type: ignore[attr-defined]
    targets = {key: values[key] for key in KEYS} | {"Vc": point.velocity, "σc": point.stress}
    exact = steady_state(truth, velocity).stress
    hits: dict[str, list[int]] = {}
    methods: dict[str, int] = {}
    started, cpu = time.time(), time.process_time()
    for seed in range(args.first, args.first + args.seeds):
        rng = np.random.default_rng(offset + seed)
        error = 0.02 * exact
        stress = exact + error * rng.standard_normal(velocity.size)
        data = SteadyData.from_arrays(velocity, stress, error if args.noise == "stated" else None, source=f"set {seed}")
        fit = fit_steady(data, method=args.method, intervals=None if args.intervals == "none" else args.intervals)
        methods[fit.method] = methods.get(fit.method, 0) + 1
        line = [f"{seed} {fit.method} {fit.status}"]
        pairs = [(e.key, e) for e in fit.estimates] + [("Vc", fit.critical_velocity), ("σc", fit.critical_stress)]
        for key, estimate in pairs:
            if key not in targets or estimate.interval is None:
                continue
            lo, hi = estimate.interval
            inside = (lo is None or lo <= targets[key]) and (hi is None or targets[key] <= hi)
            count = hits.setdefault(key, [0, 0])
            count[0] += inside
            count[1] += 1
            line.append(f"{key.split('.')[-1]}={'in' if inside else 'OUT'}")
        print(" ".join(line), flush=True)
    print(f"design {args.design}, method {args.method}, intervals {args.intervals}, noise {args.noise}; {methods}")
    for key, (inside, total) in hits.items():
        sd = math.sqrt(0.95 * 0.05 / total)
        share = f"{inside:4d} / {total:4d} = {100 * inside / total:5.1f} %"
        print(f"  {key:24s} {share}  (binomial sd at 95 %: {100 * sd:.1f} %)")
    print(f"  {time.time() - started:.0f} s wall, {time.process_time() - cpu:.0f} s CPU")


if __name__ == "__main__":
    main()
