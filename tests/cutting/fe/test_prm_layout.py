"""The engines' parameter vectors are laid out from one declaration each
(:data:`robobore.cutting.fe.engine.layout.PRM_FIELDS`,
:data:`robobore.cutting.fe.hex.layout3d.PRM_FIELDS`): every ``P_*`` constant a kernel reads
is the first slot of its declared field, the fields tile ``0 .. N_PRM - 1`` without gap or
overlap, and the modules that re-export the constants agree with the declaration.
"""

from __future__ import annotations

import pytest

from robobore.cutting.fe.engine import kernels as K
from robobore.cutting.fe.engine import kernels3d as K3
from robobore.cutting.fe.engine import layout as L
from robobore.cutting.fe.engine.prm_layout import describe, prm_slots
from robobore.cutting.fe.hex import layout3d as L3
from robobore.cutting.fe.hex import scalar3d as S3


@pytest.mark.parametrize("layout, users", [(L, (K,)), (L3, (K3, S3))])
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
    assert L3.P_MUTAB_MU - L3.P_MUTAB_V == L3.MU_TABLE_MAX


@pytest.mark.parametrize("fields, word", [
    ((("P_A", 1, "a"), ("P_A", 1, "again")), "twice"),
    ((("P_A", 0, "empty"),), "size"),
    ((("X_A", 1, "not a P_ name"),), "P_"),
])
def test_bad_declarations_are_refused(fields, word):
    with pytest.raises(ValueError, match=word):
        prm_slots(fields)
