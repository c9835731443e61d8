"""Stable content hashes of nested inputs (conditions, model configs, FE inputs).

A hash must not depend on dict order, on ``1`` vs ``1.0``, on ``-0.0`` vs ``0.0``, on a
tuple vs a list or on numpy vs Python scalars, and must be the same on every machine and
Python run (no ``hash()``, which is salted). :func:`canonical_json` turns the input into
one canonical JSON text; :func:`stable_hash` is the SHA-256 of that text.

Non-finite floats are refused (a NaN in an input is almost always a bug, and NaN != NaN
would make two "equal" inputs hash the same while comparing unequal).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from pathlib import PurePath
from typing import Any

from robobore.errors import InputError


def _number(x: float, where: str) -> float | int:
    f = float(x)
    if not math.isfinite(f):
        raise InputError(
            "non-finite number cannot be hashed", field=where or None, value=x,
            expected="a finite number",
        )
    if f == 0.0:
        return 0  # -0.0 and 0.0 and 0 are one value
    if f.is_integer() and abs(f) < 2**53:
        return int(f)  # 1 and 1.0 are one value
    return f


def canonicalise(obj: Any, where: str = "") -> Any:
    """Plain JSON types with numbers normalised (see module doc); dict keys as strings."""
    import numpy as np

    if obj is None or isinstance(obj, str):
        return obj
    if isinstance(obj, bool | np.bool_):
        return bool(obj)
    if isinstance(obj, int | float | np.integer | np.floating):
        return _number(obj, where)
    if isinstance(obj, dict):
        return {
            str(k): canonicalise(v, f"{where}.{k}" if where else str(k)) for k, v in obj.items()
        }
    if isinstance(obj, list | tuple):
        return [canonicalise(v, f"{where}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, np.ndarray):
        return canonicalise(obj.tolist(), where)
    if isinstance(obj, PurePath):
        return str(obj)
    if hasattr(obj, "model_dump"):  # pydantic model
        return canonicalise(obj.model_dump(mode="python"), where)
    if hasattr(obj, "to_dict"):
        return canonicalise(obj.to_dict(), where)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return canonicalise(dataclasses.asdict(obj), where)
    raise InputError(
        f"cannot hash an object of type {type(obj).__name__}",
        field=where or None,
        expected="numbers, strings, booleans, lists, dicts, arrays or objects with to_dict()",
    )


def canonical_json(obj: Any) -> str:
    """One canonical JSON text for ``obj``: sorted keys, no spaces, normalised numbers."""
    return json.dumps(
        canonicalise(obj), sort_keys=True, separators=(",", ":"), ensure_ascii=True,
        allow_nan=False,
    )


def stable_hash(obj: Any, length: int = 64) -> str:
    """Hex SHA-256 of :func:`canonical_json` of ``obj``, cut to ``length`` characters."""
    if not 8 <= length <= 64:
        raise ValueError("length must be between 8 and 64 hex characters")
    return hashlib.sha256(canonical_json(obj).encode("ascii")).hexdigest()[:length]


__all__ = ["canonicalise", "canonical_json", "stable_hash"]
