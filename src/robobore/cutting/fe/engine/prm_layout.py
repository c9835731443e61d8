"""Parameter vectors of the FE engines laid out from named fields.

Each engine declares its ``prm`` vector once, as an ordered table of fields (name, number of
slots, meaning); :func:`prm_slots` turns it into the index of each field's first slot and
the vector's length ``N_PRM``. The engine's layout module holds those indices as literal,
documented module constants (``P_CFL = 0``, ...) in a block written by :func:`render` between
the markers :data:`BEGIN` and :data:`END`, so that the kernels read ``prm[P_X]`` with ``P_X``
a global integer that numba compiles as a constant on the CPU and in CUDA alike, and that
an editor, grep and a type checker find where it is defined.

After an edit of a field table, rewrite the blocks::

    python -m robobore.cutting.fe.engine.prm_layout

``tests/cutting/fe/test_prm_layout.py`` renders each block again from its table and fails
where the file differs (a table edited without the blocks rewritten).
"""

from __future__ import annotations

import importlib
import sys
import textwrap
from collections.abc import Sequence
from pathlib import Path

__all__ = ["prm_slots", "describe", "render", "BEGIN", "END", "LAYOUT_MODULES",
           "generated_block", "rewrite", "main"]

#: the first line of a generated block of ``P_*`` constants
BEGIN = "# --- generated from PRM_FIELDS by robobore.cutting.fe.engine.prm_layout: do not edit ---"
#: the last line of a generated block
END = "# --- end of the generated block ---"
#: the modules whose ``PRM_FIELDS`` table is followed by a generated block
LAYOUT_MODULES = ("robobore.cutting.fe.engine.layout", "robobore.cutting.fe.hex.layout3d")


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


def render(fields: Sequence[tuple[str, int, str]]) -> str:
    """The generated block of ``fields``: :data:`BEGIN`, one documented constant per field
    (its first slot; a field of several slots says which), ``N_PRM``, :data:`END`; lines end
    with a newline."""
    lines = [BEGIN]
    for first, size, name, doc in describe(fields):
        where = f" (slots {first} .. {first + size - 1})" if size > 1 else ""
        lines += textwrap.wrap(f"{doc}{where}", width=96, initial_indent="#: ",
                               subsequent_indent="#: ", break_on_hyphens=False)
        lines.append(f"{name} = {first}")
    lines.append("#: the length of ``prm``")
    lines.append(f"N_PRM = {prm_slots(fields)['N_PRM']}")
    lines.append(END)
    return "\n".join(lines) + "\n"


def generated_block(text: str, where: str = "") -> str:
    """The generated block of a module's source ``text`` (markers included). ValueError
    naming ``where`` when the markers are missing, repeated or out of order."""
    if text.count(BEGIN + "\n") != 1 or text.count(END + "\n") != 1:
        raise ValueError(f"{where}: expected one generated block between {BEGIN!r} and {END!r}")
    start = text.index(BEGIN + "\n")
    stop = text.index(END + "\n") + len(END) + 1
    if stop <= start:
        raise ValueError(f"{where}: the end marker comes before the start marker")
    return text[start:stop]


def rewrite(module: str) -> bool:
    """Render the block of ``module`` (a name of :data:`LAYOUT_MODULES`) from its
    ``PRM_FIELDS`` and write it into the module's file in place of the old one; True when
    the file changed."""
    mod = importlib.import_module(module)
    path = Path(mod.__file__)
    text = path.read_text(encoding="utf-8")
    new = text.replace(generated_block(text, str(path)), render(mod.PRM_FIELDS))
    if new == text:
        return False
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(new, encoding="utf-8")
    tmp.replace(path)
    return True


def main() -> int:
    """Rewrite the blocks of :data:`LAYOUT_MODULES`; print each module and whether it
    changed."""
    for module in LAYOUT_MODULES:
        print(f"{module}: {'rewritten' if rewrite(module) else 'up to date'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
