"""Parameter vectors of the FE engines laid out from named fields.

Each engine declares its ``prm`` vector once, as an ordered table of fields (name, number of
slots, meaning); :func:`prm_slots` turns it into the index of each field's first slot and
the vector's length ``N_PRM``. The engine's layout module binds those indices as module
constants (``P_CFL = 0``, ...), so the kernels read ``prm[P_X]`` with ``P_X`` a global
integer, which numba compiles as a constant on the CPU and in CUDA alike.
"""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["prm_slots", "describe"]


def prm_slots(fields: Sequence[tuple[str, int, str]]) -> dict[str, int]:
    """The first slot of each field of ``fields`` ((name, size, meaning), in slot order) and
    ``"N_PRM"``, the number of slots in all. Names are unique ``P_*`` identifiers, sizes >= 1.
    """
    out: dict[str, int] = {}
    i = 0
    for name, size, _doc in fields:
        if not name.startswith("P_") or not name.isidentifier():
            raise ValueError(f"prm field {name!r}: expected a P_* identifier")
        if name in out:
            raise ValueError(f"prm field {name!r} declared twice")
        if size < 1:
            raise ValueError(f"prm field {name!r}: size {size}, expected >= 1")
        out[name] = i
        i += size
    out["N_PRM"] = i
    return out


def describe(fields: Sequence[tuple[str, int, str]]) -> list[tuple[int, int, str, str]]:
    """The layout as rows (first slot, size, name, meaning), for documentation and checks."""
    slots = prm_slots(fields)
    return [(slots[name], size, name, doc) for name, size, doc in fields]
