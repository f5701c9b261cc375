"""Short printed forms of results: the scalars in full, every array and sequence as a count (like scipy's
``OptimizeResult``), so ``print(result)`` in a notebook is a few lines, never hundreds of array elements."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

#: a text field longer than this is cut (with "...") in a repr
TEXT_WIDTH = 70


def short_value(value: Any) -> str:
    """One field's value as a repr shows it."""
    if value is None or isinstance(value, (bool, np.bool_)):
        return repr(bool(value) if isinstance(value, np.bool_) else value)
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        number = float(value)
        return f"{number:.6g}" if math.isfinite(number) else ("not a number" if math.isnan(number) else "infinite")
    if isinstance(value, str):
        text = value if len(value) <= TEXT_WIDTH else value[: TEXT_WIDTH - 3] + "..."
        return repr(text)
    if isinstance(value, np.ndarray):
        return f"<{value.size} values>" if value.ndim <= 1 else f"<array {'x'.join(map(str, value.shape))}>"
    if isinstance(value, (list, tuple)):
        return f"<{len(value)} {'item' if len(value) == 1 else 'items'}>"
    if isinstance(value, dict):
        return f"<{len(value)} {'entry' if len(value) == 1 else 'entries'}>"
    return f"<{type(value).__name__}>"


def compact_repr(obj: Any) -> str:
    """``Name(field=value, ...)``: the public fields a dataclass shows, arrays and sequences as counts."""
    parts = []
    for item in dataclasses.fields(obj):
        if item.name.startswith("_") or not item.repr:
            continue
        parts.append(f"{item.name}={short_value(getattr(obj, item.name))}")
    return f"{type(obj).__name__}({', '.join(parts)})"


def field_values(obj: Any, names: str) -> dict[str, Any]:
    """``{name: obj.name}`` for each of the space-separated ``names``, in order (a result's ``as_dict``)."""
    return {name: getattr(obj, name) for name in names.split()}
