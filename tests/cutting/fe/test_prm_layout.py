"""The engines' parameter vectors are laid out from one declaration each
(:data:`robobore.cutting.fe.engine.layout.PRM_FIELDS`,
:data:`robobore.cutting.fe.hex.layout3d.PRM_FIELDS`): every ``P_*`` constant a kernel reads
is the first slot of its declared field, the fields tile ``0 .. N_PRM - 1`` without gap or
overlap, modules that import the constants agree with the declaration, and the literal
block of constants in each layout module is the one its table renders (a table edited
without ``python -m robobore.cutting.fe.engine.prm_layout`` fails here).
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

from robobore.cutting.fe.engine import chunk_loop as CL
from robobore.cutting.fe.engine import kernels3d as K3
from robobore.cutting.fe.engine import layout as L
from robobore.cutting.fe.engine.prm_layout import (
    BEGIN,
    END,
    LAYOUT_MODULES,
    describe,
    generated_block,
    prm_slots,
    render,
)
from robobore.cutting.fe.hex import layout3d as L3
from robobore.cutting.fe.hex import scalar3d as S3


@pytest.mark.parametrize("layout, users", [(L, (CL,)), (L3, (K3, S3))])
def test_fields_tile_the_vector_and_bind_the_constants(layout, users):
    rows = describe(layout.PRM_FIELDS)
    nxt = 0
    for first, size, name, doc in rows:
        assert first == nxt and size >= 1 and doc
        assert getattr(layout, name) == first and isinstance(getattr(layout, name), int)
        nxt = first + size
    assert layout.N_PRM == nxt
    declared = {name for _f, _s, name, _d in rows}
    # no P_* constant outside the declaration
    assert {k for k in vars(layout) if k.startswith("P_")} == declared
    for mod in users:
        for name in declared & set(vars(mod)):
            assert getattr(mod, name) == getattr(layout, name), (mod.__name__, name)


def test_table_fields_take_their_size():
    assert L.P_MUTAB_MU - L.P_MUTAB_V == L.MU_TABLE_MAX
    assert L.P_SLIP_TAU - L.P_MUTAB_MU == L.MU_TABLE_MAX
    assert L3.P_MUTAB_MU - L3.P_MUTAB_V == L.MU_TABLE_MAX


@pytest.mark.parametrize("fields, word", [
    ((("P_A", 1, "a"), ("P_A", 1, "again")), "twice"),
    ((("P_A", 0, "empty"),), "size"),
    ((("X_A", 1, "not a P_ name"),), "P_"),
])
def test_bad_declarations_are_refused(fields, word):
    with pytest.raises(ValueError, match=word):
        prm_slots(fields)


@pytest.mark.parametrize("module", LAYOUT_MODULES)
def test_the_literal_block_is_the_one_its_table_renders(module):
    mod = importlib.import_module(module)
    text = Path(mod.__file__).read_text(encoding="utf-8")
    assert generated_block(text, module) == render(mod.PRM_FIELDS), (
        f"{module}: PRM_FIELDS and its block differ; run "
        "python -m robobore.cutting.fe.engine.prm_layout")
    # every constant of the block is a plain assignment in the source (grep finds it)
    for _first, _size, name, _doc in describe(mod.PRM_FIELDS):
        assert re.search(rf"^{name} = \d+$", text, re.MULTILINE), name


def test_a_table_edited_without_its_block_is_caught():
    """The check above fails on a field added to a table whose block was not rewritten, and
    on a block whose markers are gone."""
    text = Path(L.__file__).read_text(encoding="utf-8")
    edited = L.PRM_FIELDS[:3] + (("P_NEW", 1, "a new field"),) + L.PRM_FIELDS[3:]
    assert generated_block(text) != render(edited)
    assert "P_NEW = 3" in render(edited) and "P_HGS = 4" in render(edited)
    with pytest.raises(ValueError, match="one generated block"):
        generated_block(text.replace(END + "\n", ""), "layout.py")
    assert render(L.PRM_FIELDS).startswith(BEGIN + "\n")


def test_no_module_binds_names_at_run_time():
    """No ``globals().update`` / ``globals()[...] =`` in the FE engine: every name a kernel
    reads is written in the source."""
    src = Path(L.__file__).parents[2]  # robobore/cutting/fe ... up to robobore/cutting
    hits = [f"{p}:{i}" for p in sorted(src.rglob("*.py"))
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
            if re.search(r"globals\(\)\s*(\.update|\[)", line)]
    assert not hits, hits
