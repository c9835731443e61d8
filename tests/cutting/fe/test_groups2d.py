"""The plane-strain engine's array groups (robobore.cutting.fe.engine.groups2d): the compiled
loop's builders and the Python one give each field the state array of that name."""

from __future__ import annotations

import numpy as np
from numba import njit

from robobore.cutting.fe.engine import groups2d, layout
from robobore.cutting.fe.engine.chunk_loop import ChunkState
from robobore.cutting.fe.engine.state2d import make_state
from robobore.cutting.fe.quad.element import element_update, quad_element_py
from robobore.cutting.fe.quad.node_contact import node_update, quad_node_py
from robobore.material import load_material

_GROUPS = (groups2d.Nodes2, groups2d.Quads2, groups2d.QuadOut2, groups2d.Contact2,
           groups2d.Ale2)


@njit
def _all_groups(s):
    return (groups2d.nodes_of(s), groups2d.quads_of(s), groups2d.out_of(s),
            groups2d.contact_of(s), groups2d.ale_of(s))


def _state():
    nodes = np.array([[0.0, 0.0], [1e-4, 0.0], [2e-4, 0.0], [0.0, 1e-4], [1e-4, 1e-4],
                      [2e-4, 1e-4]])
    conn = np.array([[0, 1, 4, 3], [1, 2, 5, 4]])
    return make_state(nodes, conn, np.zeros(6, bool), load_material("TC4"))


def _data(a):
    return a.__array_interface__["data"][0], a.shape, a.dtype


def test_compiled_builders_take_each_field_by_name():
    st = _state()
    s = ChunkState(*st.kernel_args())
    got = _all_groups(s)
    assert len(got) == len(_GROUPS)
    for g, group in zip(got, _GROUPS, strict=True):
        assert len(g) == len(group._fields)
        for f, a in zip(group._fields, g, strict=True):
            # the same memory as the state's array of that name (not only an equal one)
            assert _data(a) == _data(getattr(st, f)), (group.__name__, f)


def test_fields_name_distinct_state_arrays():
    fields = [f for g in _GROUPS for f in g._fields]
    assert len(fields) == len(set(fields))
    assert set(fields) | {"qs"} <= set(ChunkState._fields)
    st = _state()
    ptrs = [_data(getattr(st, f))[0] for f in fields + ["qs"] if getattr(st, f).size]
    assert len(ptrs) == len(set(ptrs))  # each field a distinct array of the state
    assert not set(fields) & set(groups2d.QS_FIELDS)


def test_element_state_rows_follow_the_field_list():
    # each QS_* constant is the row of its field in QS_FIELDS, and the state's attribute of
    # that name is that row of ``qs`` (a view: writing it writes ``qs``)
    names = {getattr(groups2d, "QS_" + f.upper()): f for f in groups2d.QS_FIELDS}
    assert sorted(names) == list(range(groups2d.N_QS)) == list(range(len(groups2d.QS_FIELDS)))
    st = _state()
    assert st.qs.shape == (groups2d.N_QS, st.conn.shape[0]) and st.qs.flags.c_contiguous
    for k, f in names.items():
        row = getattr(st, f)
        assert row.base is st.qs and _data(row) == _data(st.qs[k]), f
        row[:] = k + 1.0
        assert np.all(st.qs[k] == k + 1.0), f


def test_groups_of_reads_by_name_and_replaces():
    st = _state()
    vx = np.ones_like(st.vx)
    nodes, quads, qs, out, contact, ale = groups2d.groups_of(st, vx=vx)
    assert nodes.vx is vx and nodes.x is st.x and quads.area0 is st.area0
    assert qs is st.qs and out.fex is st.fex and contact.vslip is st.vslip
    qs2 = st.qs.copy()
    assert groups2d.groups_of(st, qs=qs2)[2] is qs2
    assert ale.vbuf is st.vbuf


def _moving_state():
    # two quads stretched and sheared, the tool's edge pressed into the top right node
    st = _state()
    rng = np.random.default_rng(5)
    st.vx[:] = rng.uniform(-1.0, 1.0, st.vx.shape)
    st.vy[:] = rng.uniform(-1.0, 1.0, st.vy.shape)
    st.x += 1e-9 * st.vx
    st.y += 1e-9 * st.vy
    st.prm[layout.P_R] = 2e-5
    st.prm[layout.P_MU] = 0.3
    st.prm[layout.P_TCX] = st.x[5] + 1e-6
    st.prm[layout.P_TCY] = st.y[5] + 1e-6
    return st


def _arrays(st):
    fields = [f for g in _GROUPS for f in g._fields] + list(groups2d.QS_FIELDS)
    return {f: getattr(st, f).copy() for f in fields}


def test_parallel_passes_write_what_the_scalar_code_writes():
    # each array the element and node passes write, against the scalar functions called
    # element by element and node by node from Python: a write lost in the prange shows
    ref, par = _moving_state(), _moving_state()
    dt = 1e-9
    for e in range(ref.conn.shape[0]):
        quad_element_py(e, ref.conn, ref.layer, ref.area0, ref.x, ref.y, ref.vx, ref.vy,
                        ref.alive, ref.qs, ref.ie, ref.hge, ref.fex, ref.fey, ref.dte, ref.plast,
                        ref.rate, ref.mat, ref.prm, dt, layout.ERODE_NONE)
    element_update(*groups2d.groups_of(par)[:4], par.mat, par.prm, dt, layout.ERODE_NONE)
    kin = (par.prm[layout.P_TCX], par.prm[layout.P_TCY], 0.0, 0.0)
    for n in range(ref.x.shape[0]):
        quad_node_py(n, ref.x, ref.y, ref.vx, ref.vy, ref.mass, ref.fixed, ref.ptr, ref.nel,
                     ref.ncorner, ref.alive, ref.area0, ref.fex, ref.fey, ref.cfx, ref.cfy,
                     ref.fric, ref.pen, ref.ndead, ref.ero_ke, ref.nwork, *kin, ref.prm, dt,
                     ref.twin, ref.tied, ref.vslip)
    nodes, quads, _, out, contact, _ = groups2d.groups_of(par)
    ncont = node_update(nodes, quads, out, contact, kin, par.prm, dt)
    assert ncont >= 1
    a, b = _arrays(ref), _arrays(par)
    for f in ("sdx", "pres", "ie", "hge", "qhx", "fex", "fey", "dte", "cfx", "cfy", "pen", "x", "vx"):
        assert np.any(a[f] != _arrays(_moving_state())[f]), f  # the pass changed it
    bad = [f for f in a if not np.array_equal(a[f], b[f])]
    assert not bad, bad
