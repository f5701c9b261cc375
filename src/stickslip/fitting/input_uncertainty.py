"""The uncertainty of a parameter set that a fit wrote: read by the next fit, which holds those parameters fixed.

``stickslip fit steady -o`` writes, below its header, one comment line holding the covariance of the ln-values of
the keys it fitted (the Wald covariance of the fit, at the values it wrote)::

    # stickslip covariance of ln(value) (fit steady): {"keys": [...], "values": [...], "covariance": [[...]]}

``fit stick --params`` that file reads it back (:func:`read_fit_covariance`) and carries it into its own
intervals (docs/fitting.md, "Stick phase": the bond parameters' uncertainty).  A comment is what a TOML reader
ignores, so the file stays an ordinary parameter set; a set whose values were edited after the fit no longer
matches the covariance, which is then not used (:func:`matching_covariance` says so).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..parameters import Parameters, key_dimension

#: The comment's lead (after "# "): the line is recognised by it.
COVARIANCE_TAG = "stickslip covariance of ln(value) (fit steady):"
#: Relative difference within which a set's value is the value the covariance was written for (the TOML
#: round trip of a value is exact to ~1e-15).
SAME_VALUE = 1e-9


@dataclass(frozen=True)
class FitCovariance:
    """The covariance of the ln-values of ``keys`` at ``values`` (SI), as a fit wrote it; ``source``: its file."""

    keys: tuple[str, ...]
    values: np.ndarray
    covariance: np.ndarray
    source: str = ""

    def stderr(self, key: str) -> float:
        """The standard error of ln(value) of ``key`` (its relative standard error)."""
        k = self.keys.index(key)
        return math.sqrt(max(float(self.covariance[k, k]), 0.0))


def covariance_comment(keys: Sequence[str], values: Sequence[float], covariance: np.ndarray) -> str:
    """The comment line (without its "# ") that :func:`read_fit_covariance` reads."""
    document = {
        "keys": list(keys),
        "values": [float(v) for v in values],
        "covariance": np.asarray(covariance, dtype=float).tolist(),
    }
    return f"{COVARIANCE_TAG} {json.dumps(document)}"


def read_fit_covariance(path: str | Path | Parameters | None) -> FitCovariance | None:
    """The covariance a fit wrote into the parameter file ``path`` (None: a built-in set, a set in memory, a file
    without the line, or a line that does not read as one: such a line is a comment, not an input)."""
    if path is None or isinstance(path, Parameters):
        return None
    file = Path(path)
    try:
        if not file.is_file():
            return None
        text = file.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError, ValueError):
        return None
    for line in text.splitlines():
        body = line.strip().lstrip("#").strip()
        if body.startswith(COVARIANCE_TAG):
            return _parsed(body[len(COVARIANCE_TAG) :], str(path))
    return None


def _parsed(text: str, source: str) -> FitCovariance | None:
    try:
        document = json.loads(text)
        keys = tuple(str(k) for k in document["keys"])
        values = np.asarray(document["values"], dtype=float)
        covariance = np.asarray(document["covariance"], dtype=float)
        for key in keys:
            key_dimension(key)
    except (ValueError, KeyError, TypeError, ParameterError):  # a damaged line is a comment, not an input
        return None
    n = len(keys)
    if values.shape != (n,) or covariance.shape != (n, n) or not n:
        return None
    if not (np.all(np.isfinite(values)) and np.all(np.isfinite(covariance))):
        return None
    covariance = 0.5 * (covariance + covariance.T)
    if np.min(np.linalg.eigvalsh(covariance)) < -1e-9 * max(float(np.max(np.diag(covariance))), 1e-300):
        return None
    return FitCovariance(keys, values, covariance, source)


def matching_covariance(covariance: FitCovariance | None, params: Parameters) -> tuple[FitCovariance | None, str]:
    """``covariance`` where ``params`` holds the values it was written for, else None and why (a note)."""
    if covariance is None:
        return None, ""
    held = params.as_dict()
    changed = [
        key
        for key, value in zip(covariance.keys, covariance.values, strict=True)
        if key not in held or not math.isclose(held[key], float(value), rel_tol=SAME_VALUE)
    ]
    if changed:
        return None, (
            f"the covariance that fit steady wrote into {covariance.source} is for other values of"
            f" {', '.join(changed)} than the set holds (edited, or changed by --set?): not used; the intervals are"
            " conditional on the bond parameters"
        )
    return covariance, ""
