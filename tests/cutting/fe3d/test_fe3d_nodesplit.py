"""3D node splitting: parting-surface mesh, tied pairs move as one node, release at the insert.

The rule is the 2D engine's (tests/cutting/fe/test_node_split.py): the nodes of a parting
surface are doubled; a tied pair gathers the forces and masses of both copies in a fixed
order, so a fully tied split mesh must move exactly as the unsplit mesh; a pair parts when
it touches the insert.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from robobore.cutting.fe.config.boring3d import parse_boring_config
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.state3d import advance3, box_mesh, default_prm3, make_state3
from robobore.cutting.fe.hex import layout3d, scalar3d
from robobore.cutting.fe.mesh.boring3d import build_boring_mesh, parting_surface
from robobore.cutting.fe.models.boring3d import setup_boring
from robobore.cutting.geometry import BoringInsert
from robobore.errors import ConfigError
from robobore.material import load_material

INS = BoringInsert(nose_radius_m=0.4e-3, edge_radius_m=20e-6)


def _section_s(ins, y, z):
    return scalar3d.edge_section(y, z, ins.nose_radius_m, math.radians(ins.approach_angle_deg),
                           math.radians(ins.end_edge_angle_deg), ins.edge_radius_m)[0]


def test_parting_surface_is_offset_along_the_profile_normal():
    """s(y_p(z), z) = re - height (bisection to 1e-12 m) and, on the nose arc, the closed form
    y = rn - sqrt((rn - height)^2 - z^2) (concentric circle)."""
    h = 5e-6
    zs = np.linspace(-30e-6, 150e-6, 13)  # on the nose arc (end-edge angle 5 deg: z > -34.9 um)
    yp = parting_surface(INS, zs, h, -100e-6)
    for y, z in zip(yp, zs, strict=True):
        assert _section_s(INS, y, z) == pytest.approx(INS.edge_radius_m - h, abs=1e-12)
    rn = INS.nose_radius_m
    np.testing.assert_allclose(yp, rn - np.sqrt((rn - h) ** 2 - zs**2), atol=1e-11)


def test_split_mesh_pairs_and_chip_rows():
    ap, f, le = 0.05e-3, 0.15e-3, 12.5e-6
    m = build_boring_mesh(INS, ap, f, le, 0.05e-3, split_height=5e-6)
    tw = m.twin
    assert tw is not None
    k = np.flatnonzero(tw >= 0)
    assert k.size > 0 and np.array_equal(tw[tw[k]], k)
    np.testing.assert_array_equal(m.nodes[k], m.nodes[tw[k]])
    assert np.all(m.fixed[k] == 0)
    # elements never share a node with its twin, and every pair is used on both sides
    used = np.zeros(len(m.nodes), bool)
    used[m.conn.ravel()] = True
    assert used[k].all()
    for row in m.conn[:200]:
        assert not np.intersect1d(row, tw[row][tw[row] >= 0]).size
    # the erosion layer only where the parting surface had to be lowered (thin chip ends)
    cen = m.nodes[m.conn].mean(axis=1)
    assert m.layer.sum() < 0.2 * m.chip.sum()
    assert np.all(cen[m.layer, 1] > INS.drop(cen[m.layer, 2]) - le)


def _block(split: bool):
    le = 10e-6
    nodes, conn, idx = box_mesh(3, 4, 3, 3 * le, 4 * le, 3 * le)
    fixed = np.zeros(len(nodes), np.int64)
    fixed[idx[:, 0, :].ravel()] = 7
    twin = None
    if split:
        line = idx[:, 2, :].ravel()
        new = len(nodes) + np.arange(line.size)
        nodes = np.vstack([nodes, nodes[line]])
        fixed = np.concatenate([fixed, fixed[line]])
        remap = np.arange(len(nodes))
        remap[line] = new
        erow = np.broadcast_to(np.arange(4)[None, :, None], (3, 4, 3)).ravel()
        conn = conn.copy()
        conn[erow >= 2] = remap[conn[erow >= 2]]
        twin = -np.ones(len(nodes), np.int64)
        twin[line] = new
        twin[new] = line
    p = default_prm3()
    p[layout3d.P_GATE] = 0.0
    st = make_state3(nodes, conn, fixed, load_material("TC4"), prm=p, twin=twin)
    # a shearing, stretching initial velocity: plastic flow through the parting surface
    st.vx[:] = 60.0 * st.y / (4 * le)
    st.vy[:] = 15.0 * st.y / (4 * le)
    st.vz[:] = 10.0 * st.x / (3 * le)
    st.vx[fixed == 7] = st.vy[fixed == 7] = st.vz[fixed == 7] = 0.0
    return st, len(idx.ravel())


@pytest.mark.parametrize("tie", [True, False])
def test_tied_split_mesh_moves_as_the_unsplit_mesh(tie):
    a, n = _block(False)
    b, _ = _block(True)
    if not tie:  # mutation check: untied copies must part
        b.tied[:] = 0
    t_end = 300 * float(a.clock[1])
    advance3(a, t_end)
    advance3(b, t_end)
    assert int(a.ist[layout.I_STEP]) == int(b.ist[layout.I_STEP])
    assert np.abs(a.eps_p).max() > 0.0
    # the pair's mass is summed in another order than the unsplit node's: rounding only
    close = np.allclose(b.x[:n], a.x, rtol=0, atol=1e-14) and np.allclose(
        b.y[:n], a.y, rtol=0, atol=1e-14)
    assert close is tie
    if tie:
        k = np.flatnonzero(b.twin >= 0)
        np.testing.assert_array_equal(b.x[k], b.x[b.twin[k]])


def test_pairs_part_where_the_insert_passed():
    # the parting rule on the adiabatic model (the rule is geometric; heat conduction moves
    # the flow of this 16.6 um mesh, and with it which of the swept pairs the edge reaches)
    d = {"cut": {"depth_of_cut_mm": 0.05, "feed_mm_per_rev": 0.15, "speed_rpm": 300.0,
                 "cut_length_mm": 0.04},
         "mesh": {"element_size_um": 16.6, "frame": "workpiece", "separation": "node_split",
                  "ahead_mm": 0.03},
         "solver": {"mass_scaling": 400.0, "n_samples": 20, "heat_conduction": False}}
    s = setup_boring(parse_boring_config(d))
    st = s.state
    advance3(st, s.t_end)
    k = np.flatnonzero(st.twin >= 0)
    x0, z0 = s.mesh.nodes[k, 0], s.mesh.nodes[k, 2]
    y0 = s.mesh.nodes[k, 1]
    tip = st.tool[scalar3d.T_GX]
    # pairs the edge swept (parting surface above the edge path) have parted; pairs ahead
    # of the insert, or below its path (the lowered thin chip ends), are still tied
    swept = (x0 < tip - 20e-6) & (y0 >= s.insert.drop(z0))
    assert swept.sum() > 10
    assert (st.tied[k][swept] == 0).mean() > 0.9
    assert np.all(st.tied[k][x0 > tip + 30e-6] == 1)
    assert np.all(st.tied[k][y0 < s.insert.drop(z0) - 1e-6] == 1)


def test_bad_split_settings():
    d = {"cut": {"depth_of_cut_mm": 0.05, "feed_mm_per_rev": 0.15, "speed_rpm": 300.0},
         "mesh": {"element_size_um": 12.5, "frame": "workpiece", "separation": "glue"}}
    with pytest.raises(ConfigError, match="separation"):
        parse_boring_config(d)
    d["mesh"]["separation"] = "node_split"
    d["contact"] = {"friction": -0.1}
    with pytest.raises(ConfigError, match="friction"):
        parse_boring_config(d)
