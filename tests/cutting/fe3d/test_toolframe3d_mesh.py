"""z-sliced tool-frame mesh of the 3D boring model (:mod:`robobore.cutting.fe.mesh.toolframe3d`)
at the paper's condition (ap 0.05 mm, f 0.15 mm/rev, the insert of
``examples/fe_boring_paper.toml``): valid hexahedra, the nose-tip slice is the 2D tool-frame
mesh, the chip block follows the uncut thickness, the chip area, the insert surface, the
boundary faces. Tolerances are stated per test.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from robobore.cutting.fe.ale.hexvolume3d import FACES_OUT
from robobore.cutting.fe.ale.remap import BF_CLOSED, BF_OPEN, BF_VIRGIN
from robobore.cutting.fe.ale.toolframe import ToolFrameExtent, build_toolframe_mesh
from robobore.cutting.fe.engine.state3d import HEX_SIGNS
from robobore.cutting.fe.hex.scalar3d import insert_gap3_py
from robobore.cutting.fe.mesh.toolframe3d import (
    FK_BOTTOM,
    FK_CHIP_SIDE,
    FK_FREE,
    FK_INFLOW,
    FK_INTERIOR,
    FK_OUTFLOW,
    FK_SIDE,
    FK_TOOL,
    build_toolframe3d_mesh,
)
from robobore.cutting.fe.mesh.toolframe3d_layout import ToolFrame3DSizes
from robobore.cutting.fe.mesh.toolframe3d_section import (
    clamp_area,
    s_of_y,
    section_coords,
    section_nodes,
    uncut_thickness,
)
from robobore.cutting.fe.physics.thermal3d import face_neighbours
from robobore.cutting.geometry import BoringInsert, chip_area

AP, F = 0.05e-3, 0.15e-3
INSERT = BoringInsert(nose_radius_m=0.4e-3, approach_angle_deg=90.0, end_edge_angle_deg=5.0,
                      rake_deg=7.0, clearance_deg=7.0, edge_radius_m=20e-6, inclination_deg=0.0)
LE = 12.5e-6
EXAMPLES = Path(__file__).parents[3] / "examples"


@pytest.fixture(scope="module")
def mesh():
    return build_toolframe3d_mesh(INSERT, AP, F, ToolFrame3DSizes(LE))


def _jacobian_dets(nodes, conn, points):
    """det J of every hexahedron at the reference points (m, 3)."""
    xe = nodes[conn]  # (e, 8, 3)
    out = []
    for xi in points:
        fac = [1.0 + HEX_SIGNS[:, k] * xi[k] for k in range(3)]
        dN = np.empty((8, 3))
        dN[:, 0] = HEX_SIGNS[:, 0] * fac[1] * fac[2] / 8
        dN[:, 1] = HEX_SIGNS[:, 1] * fac[0] * fac[2] / 8
        dN[:, 2] = HEX_SIGNS[:, 2] * fac[0] * fac[1] / 8
        out.append(np.linalg.det(np.einsum("eia,ib->eab", xe, dN)))
    return np.array(out)


def test_every_hexahedron_is_valid(mesh):
    g = 1.0 / math.sqrt(3.0)
    gauss = np.array([(a, b, c) for a in (-g, g) for b in (-g, g) for c in (-g, g)])
    corners = HEX_SIGNS
    assert np.all(_jacobian_dets(mesh.nodes, mesh.conn, gauss) > 0.0)
    assert np.all(_jacobian_dets(mesh.nodes, mesh.conn, corners) > 0.0)
    # every node is used, no two nodes coincide
    assert np.array_equal(np.unique(mesh.conn), np.arange(mesh.n_nodes))
    key = np.round(mesh.nodes / 1e-12).astype(np.int64)
    assert np.unique(key, axis=0).shape[0] == mesh.n_nodes


def test_the_nose_tip_slice_is_the_2d_mesh(mesh):
    # the 2D builder at h = t(0) with the slice's extents: inflow face at the plan's x_in
    # (the builder places it `ahead` before the chip root, found from a first call), back
    # face, bottom and chip top face as the plan's
    k0 = int(np.flatnonzero(mesh.z_slices == 0.0)[0])
    h0 = float(uncut_thickness(INSERT, AP, F, np.array([0.0]))[0])
    p = mesh.plan
    ext = dict(behind=p.x_out, depth=-mesh.y_bottom, chip_length=p.chip_length)
    kw = dict(element_size=LE, edge_size=LE / 4, chip_ratio=1.6)
    r, rake, clr = 20e-6, math.radians(7.0), math.radians(7.0)
    probe = build_toolframe_mesh(h0, r, rake, clr, extent=ToolFrameExtent(ahead=60e-6, **ext),
                                 **kw)
    root = probe.nodes[:, 0].min() + 60e-6
    m2 = build_toolframe_mesh(h0, r, rake, clr,
                              extent=ToolFrameExtent(ahead=root - p.x_in, **ext), **kw)
    sel = mesh.node_slice == k0
    local = mesh.node_local[sel]
    p3 = mesh.nodes[sel]
    assert local.size == m2.nodes.shape[0]
    # at z = 0 the map is x = -x2 (the insert moves along +x), y = y2 + h
    assert np.allclose(p3[:, 0], -m2.nodes[local, 0], rtol=0.0, atol=1e-12)
    assert np.allclose(p3[:, 1], m2.nodes[local, 1] + h0, rtol=0.0, atol=1e-12)
    assert np.all(p3[:, 2] == 0.0)
    assert np.array_equal(mesh.node_class[sel], m2.acls[local, 0])
    # the hexahedra on this slice are the 2D quads (reversed: mirrored in x)
    off = int(np.flatnonzero(sel)[0])
    el = mesh.elem_slice == k0
    assert np.array_equal(mesh.conn[el][:, :4] - off, m2.conn[:, [0, 3, 2, 1]])
    assert np.array_equal(mesh.chip[el], m2.chip)


def test_chip_block_follows_the_uncut_thickness(mesh):
    top_local = int(mesh.reference.chip_top_nodes[0])  # inflow face, chip's free surface
    t_min = mesh.sizes.t_min
    for k in np.flatnonzero(mesh.engaged):
        z = mesh.z_slices[k]
        n = np.flatnonzero((mesh.node_slice == k) & (mesh.node_local == top_local))[0]
        want = max(float(uncut_thickness(INSERT, AP, F, np.array([z]))[0]), t_min)
        got = mesh.nodes[n, 1] - float(INSERT.drop(np.array([z]))[0])
        assert got == pytest.approx(want, abs=1e-12), k
        assert mesh.t_mesh[k] == pytest.approx(want, abs=1e-12)
    # the clamp acts at the two ends only, and true thicknesses are in the mesh elsewhere
    clamped = mesh.engaged & (mesh.t < t_min)
    assert clamped.sum() >= 2
    assert np.allclose(mesh.t_mesh[mesh.engaged & ~clamped], mesh.t[mesh.engaged & ~clamped],
                       atol=1e-12)
    # margins: the surface lies below the edge (the insert clears it)
    m = ~mesh.engaged
    assert np.all(mesh.t[m] < 0.0)


def test_tool_faces_lie_on_the_insert_and_no_node_inside_it(mesh):
    rn, kap = 0.4e-3, math.radians(90.0)
    args = (rn, kap, math.radians(5.0), math.radians(7.0), math.radians(7.0), 20e-6, 0.0)
    gaps = np.array([insert_gap3_py(*p, *args)[0] for p in mesh.nodes])
    e, f = np.nonzero(mesh.fkind == FK_TOOL)
    on_tool = np.unique(mesh.conn[e[:, None], FACES_OUT[f]])
    assert on_tool.size > 0
    assert np.max(np.abs(gaps[on_tool])) < 1e-9  # 1 nm
    assert gaps.min() > -1e-9


def test_chip_area_of_the_mesh(mesh):
    # material above the edge profile in the mesh minus the clamp's fictitious part equals
    # the mechanistic chip area ap f - scallop within the mesh resolution: the chord error
    # of the top surface between slices (width dz^2 max|y_top''| / 8, y_top'' <= 1 /
    # (rn cos^3 psi)) plus the wedges between the end slices (chip block t_min thick, join
    # line t_min / 2 above the edge) and the margins (<= t_min dz / 4 each)
    a = mesh.areas
    chip = chip_area(INSERT, AP, F)
    assert a["chip"] == chip
    assert a["clamp"] == pytest.approx(clamp_area(INSERT, AP, F, mesh.sizes.t_min))
    dz = float(np.max(np.diff(mesh.z_slices)))
    z_e = mesh.z_slices[mesh.engaged]
    width = z_e[-1] - z_e[0]
    psi = math.asin(z_e[-1] / 0.4e-3)
    tol = width * dz ** 2 / (8 * 0.4e-3 * math.cos(psi) ** 3) + 0.5 * mesh.sizes.t_min * dz
    assert abs(a["mesh_above_edge"] - a["clamp"] - chip) < tol
    assert tol < 0.01 * chip  # the bound itself is a fine one
    assert 0.005 < a["clamp"] / chip < 0.015  # t_min = 5 um: about 1 %


def test_boundary_faces_are_flagged_once(mesh):
    fn = face_neighbours(mesh.conn)
    boundary = fn < 0
    kinds = mesh.fkind
    assert np.all(kinds[~boundary] == FK_INTERIOR)
    assert np.all(kinds[boundary] != FK_INTERIOR)
    assert set(np.unique(kinds[boundary]).tolist()) == {FK_INFLOW, FK_OUTFLOW, FK_TOOL,
                                                       FK_FREE, FK_BOTTOM, FK_SIDE,
                                                       FK_CHIP_SIDE}
    assert np.array_equal(mesh.bflag == BF_VIRGIN, kinds == FK_INFLOW)
    outflow = (kinds == FK_OUTFLOW) | (kinds == FK_CHIP_SIDE)
    assert np.array_equal(mesh.bflag == BF_OPEN, outflow)
    assert np.all(mesh.bflag[(kinds != FK_INFLOW) & ~outflow] == BF_CLOSED)
    # the chip's sides: z-faces of chip elements at the first and last engaged slices
    e, f = np.nonzero(kinds == FK_CHIP_SIDE)
    assert np.all(mesh.chip[e]) and np.all((f == 4) | (f == 5))
    k = mesh.elem_slice[e] + (f == 5)
    first, last = np.flatnonzero(mesh.engaged)[[0, -1]]
    assert set(np.unique(k).tolist()) == {first, last}
    # the boundary is closed: its outward vector area sums to zero
    P = mesh.nodes
    e, f = np.nonzero(boundary)
    q = mesh.conn[e[:, None], FACES_OUT[f]]
    vec = 0.5 * np.cross(P[q[:, 2]] - P[q[:, 0]], P[q[:, 3]] - P[q[:, 1]])
    assert np.all(np.abs(vec.sum(axis=0)) < 1e-12 * np.abs(vec).sum(axis=0))
    # where the kinds lie: inflow faces on the plane ahead, bottom on y = y_bottom, side
    # faces on the first and last slice planes
    def face_nodes(kind):
        ee, ff = np.nonzero(kinds == kind)
        return np.unique(mesh.conn[ee[:, None], FACES_OUT[ff]])
    assert np.allclose(P[face_nodes(FK_INFLOW), 0], -mesh.plan.x_in, atol=1e-15)
    assert np.allclose(P[face_nodes(FK_BOTTOM), 1], mesh.y_bottom, atol=1e-15)
    zs = P[face_nodes(FK_SIDE), 2]
    assert np.all(np.isin(zs, mesh.z_slices[[0, -1]]))
    # the rigid nodes are those of the inflow face and the bottom
    rigid = np.zeros(mesh.n_nodes, bool)
    rigid[face_nodes(FK_INFLOW)] = True
    rigid[face_nodes(FK_BOTTOM)] = True
    assert np.array_equal(rigid, mesh.rigid)
    # outflow faces: the back face behind the edge and the chip's top face
    out_n = face_nodes(FK_OUTFLOW)
    back = np.isclose(P[out_n, 0], -mesh.plan.x_out, atol=1e-15)
    assert back.any() and (~back).any()


def test_node_neighbours_stay_in_their_slice(mesh):
    a = mesh.acls
    for c in range(1, 7):
        has = a[:, c] >= 0
        assert np.all(mesh.node_slice[a[has, c]] == mesh.node_slice[has])


def test_bad_clamp_is_rejected():
    with pytest.raises(ValueError, match="t_min"):
        build_toolframe3d_mesh(INSERT, AP, F, ToolFrame3DSizes(LE, t_min=0.0))


def test_every_slice_is_its_normal_section_mapped_exactly(mesh):
    # back into each engaged slice's normal-section frame, the nodes are the 2D
    # construction at the slice's thickness (the bottom at the flat plane y_bottom)
    r = 20e-6
    for k in np.flatnonzero(mesh.engaged):
        z = mesh.z_slices[k]
        sel = mesh.node_slice == k
        back = section_coords(INSERT, mesh.nodes[sel], mesh.h2[k])
        s_bot = float(s_of_y(INSERT, np.array([mesh.y_bottom]), np.array([z]))[0])
        want, _ = section_nodes(mesh.plan, float(mesh.h2[k]), s_bot - r)
        assert np.allclose(back, want, rtol=0.0, atol=1e-12), k


def test_counts_without_building_the_mesh(mesh):
    """toolframe3d_counts (the memory check's estimate) gives the built mesh's node and
    hexahedron counts, here and with other slice spacing, margins and edge size."""
    from robobore.cutting.fe.mesh.toolframe3d_layout import toolframe3d_counts

    assert toolframe3d_counts(INSERT, AP, F, ToolFrame3DSizes(LE)) == (mesh.n_nodes,
                                                                       mesh.n_elements)
    other = ToolFrame3DSizes(16.6e-6, slice_spacing=10e-6, margin_slices=1, edge_size=5e-6)
    m2 = build_toolframe3d_mesh(INSERT, AP, F, other)
    assert toolframe3d_counts(INSERT, AP, F, other) == (m2.n_nodes, m2.n_elements)


def test_memory_estimate_of_a_tool_frame_config(monkeypatch):
    """cutting.fe.mesh.memory.fe3d_elements of a tool-frame boring config is its mesh's
    hexahedron count; a size whose lower bound alone does not fit is refused without building
    a section."""
    import robobore.cutting.fe.mesh.memory as memory
    import robobore.cutting.fe.mesh.toolframe3d_layout as layout
    from robobore.cutting.fe.config.boring3d import parse_boring_config
    from robobore.errors import ConfigError
    from robobore.io.config import load_toml

    d = load_toml(EXAMPLES / "fe_boring_paper.toml")
    d["mesh"].update(frame="tool", element_size_um=16.6)
    cfg = parse_boring_config(d)
    ins = cfg.insert.to_insert()
    built = build_toolframe3d_mesh(ins, cfg.cut.depth_of_cut_mm * 1e-3,
                                   cfg.cut.feed_mm_per_rev * 1e-3, ToolFrame3DSizes(16.6e-6))
    assert memory.fe3d_elements(cfg) == built.n_elements > 10_000

    def never(*a, **k):
        raise AssertionError("a section was built")

    monkeypatch.setattr(layout, "slice_layout", never)
    d["mesh"]["element_size_um"] = 0.01
    with pytest.raises(ConfigError, match="mesh.element_size_um"):
        parse_boring_config(d, "fine.toml")
