"""The 3D tool-frame ALE pass (:mod:`robobore.cutting.fe.ale.rezone3d`) and the extruded
tool-frame mesh (:func:`robobore.cutting.fe.mesh.toolframe3d.extrude_toolframe_mesh`).

Checks: on an extruded mesh every slice is placed exactly as the 2D placement
(:func:`robobore.cutting.fe.ale.rezone.toolframe_targets`) places the 2D mesh with the same
(mirrored) node displacement, with and without the insert's "off tool" push; nodes stay in
their planes; surface-chain nodes stay on their (curved) surface polyline; a zero motion
moves nothing and the pass then changes no field; the remap conserves mass, volume and
the fields' volume integrals through closed faces, and through the open faces the mass
changes by what they sweep; ``toolframe3d_ale_data`` of an extruded mesh is the 2D ``aflt``
slice by slice; on the paper condition's sliced mesh a pass after a random Lagrangian
perturbation leaves every hexahedron with a positive volume. Tolerances
are round-off bounds, stated per test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from robobore.cutting.fe.ale.hexvolume3d import FACES_OUT, element_volumes3, swept_face_py
from robobore.cutting.fe.ale.remap import BF_CLOSED, BF_VIRGIN
from robobore.cutting.fe.ale.rezone import (
    TF_CHAIN,
    TF_FACE,
    TF_INTERIOR,
    TF_LINE,
    TF_RIGID,
    toolframe_targets,
)
from robobore.cutting.fe.ale.rezone3d import (
    off_insert_py,
    rezone3d_py,
    toolframe3d_ale_data,
    toolframe3d_targets_py,
)
from robobore.cutting.fe.ale.toolframe import build_toolframe_mesh
from robobore.cutting.fe.hex.layout3d import (
    N_PRM,
    P_CLR,
    P_KAPPA,
    P_KEND,
    P_RAKE,
    P_RE,
    P_RN,
    P_TANI,
    P_TOOL,
)
from robobore.cutting.fe.hex.scalar3d import insert_gap3_py
from robobore.cutting.fe.mesh.toolframe3d import (
    FK_SIDE,
    build_toolframe3d_mesh,
    extrude_toolframe_mesh,
    reference_blocks,
)
from robobore.cutting.fe.mesh.toolframe3d_layout import ToolFrame3DSizes
from robobore.cutting.fe.mesh.toolframe3d_section import slice_map
from robobore.cutting.fe.physics.thermal3d import face_neighbours
from robobore.cutting.geometry import BoringInsert

AP, F = 0.05e-3, 0.15e-3
INSERT = BoringInsert(nose_radius_m=0.4e-3, approach_angle_deg=90.0, end_edge_angle_deg=5.0,
                      rake_deg=7.0, clearance_deg=7.0, edge_radius_m=20e-6, inclination_deg=0.0)
LE = 12.5e-6
H2 = 30e-6  # uncut thickness of the extruded 2D mesh [m]
RAKE, CLR, RE = math.radians(7.0), math.radians(7.0), 20e-6
Z_EXT = np.linspace(-20e-6, 20e-6, 5)
RHO_S = 4430.0 * 100.0
MAX_MOVE = 0.25


def _prm(insert: BoringInsert, tool: bool = True) -> np.ndarray:
    p = np.zeros(N_PRM)
    p[P_RN] = insert.nose_radius_m
    p[P_KAPPA] = math.radians(insert.approach_angle_deg)
    p[P_KEND] = math.radians(insert.end_edge_angle_deg)
    p[P_RAKE] = math.radians(insert.rake_deg)
    p[P_CLR] = math.radians(insert.clearance_deg)
    p[P_RE] = insert.edge_radius_m
    p[P_TANI] = math.tan(math.radians(insert.inclination_deg))
    p[P_TOOL] = 1.0 if tool else 0.0
    return p


def _tg(cx: float, cy: float) -> np.ndarray:
    """The 2D tool geometry tuple of the ALE passes: edge centre, rake and flank normals (as
    the 3D insert's normal section: :func:`insert_gap3_py`), edge radius."""
    return np.array([cx, cy, -math.cos(RAKE), math.sin(RAKE), math.sin(CLR), -math.cos(CLR),
                     RE])


@pytest.fixture(scope="module")
def ref():
    return build_toolframe_mesh(H2, RE, RAKE, CLR, element_size=LE, edge_size=LE / 4)


@pytest.fixture(scope="module")
def ext(ref):
    return extrude_toolframe_mesh(ref, Z_EXT)


@pytest.fixture(scope="module")
def paper():
    return build_toolframe3d_mesh(INSERT, AP, F, ToolFrame3DSizes(LE))


def _targets_2d(nodes2, ref, aflt2, off2, tg):
    n = nodes2.shape[0]
    xn, yn = nodes2[:, 0].copy(), nodes2[:, 1].copy()
    toolframe_targets(nodes2[:, 0].copy(), nodes2[:, 1].copy(), xn, yn, ref.nodes[:, 0].copy(),
                      ref.nodes[:, 1].copy(), ref.acls, aflt2, float(off2), MAX_MOVE, tg,
                      np.zeros((n, 2)))
    return np.stack([xn, yn], axis=1)


def _mirror(xy2, h):
    return np.column_stack([-xy2[:, 0], xy2[:, 1] + h])


# ---------------------------------------------------------------- the extruded mesh


def test_extruded_mesh_is_the_2d_mesh_in_every_slice(ref, ext):
    """Every slice is the 2D mesh mirrored in x and shifted by h in y (the nose-tip map of
    :func:`slice_map`, to its bisection's round-off, 1e-15 m), the hexahedra are valid, the
    side planes' faces are FK_SIDE and the block sizes are those the sliced mesh's builder
    reports."""
    n2 = ref.nodes.shape[0]
    assert ext.n_nodes == n2 * Z_EXT.size
    assert ext.n_elements == ref.conn.shape[0] * (Z_EXT.size - 1)
    for k, zk in enumerate(Z_EXT):
        sl = ext.nodes[ext.node_slice == k]
        assert np.array_equal(sl[:, :2], _mirror(ref.nodes, H2))
        assert np.all(sl[:, 2] == zk)
    tip = slice_map(INSERT, 0.0, ref.nodes, H2)
    assert np.max(np.abs(tip[:, :2] - _mirror(ref.nodes, H2))) < 1e-15
    assert np.all(element_volumes3(ext.nodes, ext.conn) > 0.0)
    assert np.all(ext.engaged) and ext.chip.sum() == ref.chip.sum() * (Z_EXT.size - 1)
    first = ext.elem_slice == 0
    last = ext.elem_slice == Z_EXT.size - 2
    assert np.all(ext.fkind[first, 4] == FK_SIDE) and np.all(ext.fkind[last, 5] == FK_SIDE)
    assert np.array_equal(ext.acls[ext.node_slice == 2, 0], ref.acls[:, 0])


def test_reference_blocks_match_the_sliced_mesh(paper):
    assert reference_blocks(paper.reference) == paper.blocks


def test_ale_data_of_the_extruded_mesh_is_the_2d_data(ref, ext):
    """``toolframe3d_ale_data`` slice by slice equals the 2D ``aflt`` with the line
    directions mirrored in x (face fractions and directions 1e-12, sizes 1e-12 relative;
    the faces' offsets off their chords, zero in 2D, 1e-12)."""
    acls, aflt = toolframe3d_ale_data(ext)
    assert np.array_equal(acls, ext.acls)
    want = ref.aflt * np.array([1.0, -1.0, 1.0, 1.0, 1.0, 1.0])
    n2 = ref.nodes.shape[0]
    for k in range(Z_EXT.size):
        a = aflt[k * n2:(k + 1) * n2]
        assert np.allclose(a[:, :3], want[:, :3], rtol=0.0, atol=1e-12)
        assert np.allclose(a[:, 3], want[:, 3], rtol=1e-12, atol=0.0)
        assert np.all(a[:, 4:] == 0.0)
    # the data are not trivially zero: fractions, directions, slides
    assert np.count_nonzero(ref.aflt[:, 1:3]) >= 3 and np.all(ref.aflt[:, 3] > 0.0)


def test_ale_data_of_the_paper_mesh_tip_slice_is_the_reference(paper):
    """The nose-tip slice of the sliced mesh is the 2D reference mesh mapped by
    :func:`slice_map`: its ``aflt`` is the reference's, mirrored (1e-9 of the values: the
    map's bisection)."""
    acls, aflt = toolframe3d_ale_data(paper)
    k0 = int(np.flatnonzero(paper.z_slices == 0.0)[0])
    sel = paper.node_slice == k0
    want = paper.reference.aflt * np.array([1.0, -1.0, 1.0, 1.0, 1.0, 1.0])
    a = aflt[sel][paper.node_local[sel]]
    assert np.allclose(a[:, :3], want[:, :3], rtol=0.0, atol=1e-9)
    assert np.allclose(a[:, 3], want[:, 3], rtol=1e-9, atol=0.0)
    # every chain end has a line and a slide, every node a size
    line = acls[:, 0] == TF_LINE
    assert np.all(aflt[line, 0] > 0.0)
    assert np.allclose(np.hypot(aflt[line, 1], aflt[line, 2]), 1.0, rtol=1e-12)
    assert np.all(aflt[:, 3] > 0.0)


# ---------------------------------------------------------------- placement vs the 2D one


@pytest.mark.parametrize("motion", ["rigid", "random"])
def test_extruded_slices_are_placed_as_the_2d_placement(ref, ext, motion):
    """A rigid translation by (dx, 0, dz) (beyond the move limit near the edge), or a random
    in-plane displacement (the same in every slice) with a random drift in z, and an insert
    travel ``off_x``, ``off_z``: every slice is placed where the 2D placement places the 2D
    mesh with the mirrored displacement and travel (no insert: 1e-12 of the edge element,
    the round-off of the y shift), the mesh displacement carried in ``aflt`` too, and every
    node in its plane ``z0 + off_z`` exactly."""
    rng = np.random.default_rng(5)
    n2 = ref.nodes.shape[0]
    if motion == "rigid":
        d2 = np.tile([-2.0e-6, 0.0], (n2, 1))
        dz = np.full(ext.n_nodes, 1.5e-6)
    else:
        d2 = rng.uniform(-0.2, 0.2, (n2, 2)) * ref.aflt[:, 3:4]
        dz = rng.uniform(-0.2, 0.2, ext.n_nodes) * LE
    off_x, off_z = 0.8e-6, -0.3e-6
    acls, aflt = toolframe3d_ale_data(ext)
    cur = ext.nodes.copy()
    cur[:, :2] = np.tile(_mirror(ref.nodes + d2, H2), (Z_EXT.size, 1))
    cur[:, 2] += dz
    new = toolframe3d_targets_py(cur, ext.nodes, acls, aflt, off_x=off_x, off_z=off_z,
                                 max_move=MAX_MOVE, prm=_prm(INSERT, tool=False),
                                 tip=(off_x, 0.0, off_z))
    aflt2 = ref.aflt.copy()
    new2 = _targets_2d(ref.nodes + d2, ref, aflt2, -off_x, _tg(1.0, 1.0))  # tool far away
    want = _mirror(new2, H2)
    tol = 1e-12 * ref.edge_size
    for k in range(Z_EXT.size):
        sl = slice(k * n2, (k + 1) * n2)
        assert np.max(np.abs(new[sl, :2] - want)) <= tol
        assert np.max(np.abs(aflt[sl, 4] + aflt2[:, 4])) <= tol
        assert np.max(np.abs(aflt[sl, 5] - aflt2[:, 5])) <= tol
    assert np.array_equal(new[:, 2], ext.nodes[:, 2] + off_z)
    # the placement did move the nodes (and the move limit bit near the edge)
    moved = np.hypot(*(new2 - (ref.nodes + d2)).T)
    assert moved.max() > 0.5e-6
    if motion == "rigid":
        back = np.hypot(*(new2 - ref.nodes + np.array([off_x, 0.0])).T)
        assert np.any(back > 1e-3 * ref.edge_size)  # limited: not all back at the place


def test_off_insert_matches_the_2d_off_tool_in_the_tip_plane(ref):
    """With the insert: the slice z = 0 of an extruded mesh pushed into the insert is placed
    as the 2D placement with its 2D tool at the same place (1e-12 of the edge element: the
    3D insert's normal section there is the 2D tool), and the push acted on some nodes."""
    ext = extrude_toolframe_mesh(ref, np.array([-LE, 0.0, LE]))
    n2 = ref.nodes.shape[0]
    d2 = np.tile([1.5e-6, -0.4e-6], (n2, 1))  # the mesh into the tool's rake face and edge
    off_x = 0.5e-6
    acls, aflt = toolframe3d_ale_data(ext)
    cur = ext.nodes.copy()
    cur[:, :2] = np.tile(_mirror(ref.nodes + d2, H2), (3, 1))
    kw = {"off_x": off_x, "max_move": MAX_MOVE, "tip": (off_x, 0.0, 0.0)}
    new = toolframe3d_targets_py(cur, ext.nodes, acls, aflt.copy(), prm=_prm(INSERT), **kw)
    free = toolframe3d_targets_py(cur, ext.nodes, acls, aflt.copy(),
                                  prm=_prm(INSERT, tool=False), **kw)
    cx2, cy2 = ref.tool_center
    new2 = _targets_2d(ref.nodes + d2, ref, ref.aflt.copy(), -off_x, _tg(cx2 - off_x, cy2))
    sl = slice(n2, 2 * n2)
    assert np.max(np.abs(new[sl, :2] - _mirror(new2, H2))) <= 1e-12 * ref.edge_size
    pushed = np.hypot(*(new[sl, :2] - free[sl, :2]).T)
    assert np.count_nonzero(pushed > 1e-3 * ref.edge_size) >= 3


def test_off_insert_restores_the_gap_to_first_order():
    """A point placed deeper in the insert than its old point (under the edge in a plane off
    the nose tip, where the insert's normal leaves the plane by a quarter) comes back to the
    old gap, or to the surface when the old point was outside: the push is first order, the
    remaining deficit below 1e-2 of the push; a point placed outside, or shallower, is left
    as it is."""
    prm = _prm(INSERT)
    args = (prm[P_RN], prm[P_KAPPA], prm[P_KEND], prm[P_RAKE], prm[P_CLR], prm[P_RE],
            prm[P_TANI])
    z = 100e-6
    y_edge = INSERT.drop(np.array([z]))[0]
    lo, hi = y_edge - 5e-6, y_edge + 5e-6  # the edge's lowest point in that plane, at x = 0
    assert insert_gap3_py(0.0, lo, z, *args)[0] > 0.0 > insert_gap3_py(0.0, hi, z, *args)[0]
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if insert_gap3_py(0.0, mid, z, *args)[0] > 0.0:
            lo = mid
        else:
            hi = mid
    ys = 0.5 * (lo + hi)
    assert abs(ys - y_edge) < 1e-3 * RE
    assert abs(insert_gap3_py(0.0, ys, z, *args)[3]) > 0.2  # the normal leaves the plane
    qx, qy = 0.3e-6, ys + 0.4e-6
    g1 = insert_gap3_py(qx, qy, z, *args)[0]
    for y_old in (ys - 1e-6, ys + 0.1e-6):  # outside, inside
        g_want = min(insert_gap3_py(0.0, y_old, z, *args)[0], 0.0)
        assert g1 < g_want - 0.2e-6
        tx, ty = off_insert_py(0.0, y_old, z, qx, qy, z, prm, 0.0, 0.0, 0.0)
        g = insert_gap3_py(tx, ty, z, *args)[0]
        assert abs(g - g_want) <= 1e-2 * (g_want - g1)
    # an old point deeper than the new one: no push
    assert off_insert_py(0.0, ys + 1e-6, z, qx, qy, z, prm, 0.0, 0.0, 0.0) == (qx, qy)
    # outside: no push
    assert off_insert_py(0.0, ys, z, 0.0, ys - 1e-6, z, prm, 0.0, 0.0, 0.0) == (0.0, ys - 1e-6)


# ---------------------------------------------------------------- the paper mesh


def _outline_nodes(mesh) -> np.ndarray:
    """Nodes on an outline face of the hexahedra (no neighbour across it)."""
    fn = face_neighbours(mesh.conn)
    on = np.zeros(mesh.n_nodes, bool)
    for f in range(6):
        free = fn[:, f] < 0
        on[mesh.conn[free][:, FACES_OUT[f]].ravel()] = True
    return on


def _perturbed(mesh, acls, aflt, amp, seed, classes, in_plane=True, inner_only=False):
    rng = np.random.default_rng(seed)
    cur = mesh.nodes.copy()
    sel = np.isin(acls[:, 0], classes)
    if inner_only:
        sel &= ~_outline_nodes(mesh)
    k = 2 if in_plane else 3
    cur[sel, :k] += rng.uniform(-amp, amp, (int(sel.sum()), k)) * aflt[sel, 3:4]
    return cur


def test_nodes_stay_in_their_planes_and_chains_on_their_polylines(paper):
    """After a random 3D perturbation of every node but the rigid ones, the placement puts
    every node in its plane ``z0 + off_z`` exactly and every surface-chain node on the
    in-plane polyline through its old neighbours (1e-12 of its local size; without the
    insert's push, which by design may leave the polyline): the edge arc is curved, so a
    chord-free slide is what is checked."""
    acls, aflt = toolframe3d_ale_data(paper)
    cur = _perturbed(paper, acls, aflt, 0.15, 21, [TF_CHAIN, TF_LINE, TF_FACE, TF_INTERIOR],
                     in_plane=False)
    off_x, off_z = 0.6e-6, 0.2e-6
    new = toolframe3d_targets_py(cur, paper.nodes, acls, aflt, off_x=off_x, off_z=off_z,
                                 prm=_prm(INSERT, tool=False), tip=(off_x, 0.0, off_z))
    assert np.array_equal(new[:, 2], paper.nodes[:, 2] + off_z)
    chain = np.flatnonzero(acls[:, 0] == TF_CHAIN)
    p = cur[:, :2]
    q = new[:, :2]
    dist = np.full(chain.size, np.inf)
    for side in (1, 2):
        m = acls[chain, side]
        e = p[m] - p[chain]
        t = np.clip(np.einsum("ij,ij->i", q[chain] - p[chain], e) / np.einsum("ij,ij->i", e, e),
                    0.0, 1.0)
        d = np.hypot(*(p[chain] + t[:, None] * e - q[chain]).T)
        dist = np.minimum(dist, d)
    assert np.all(dist <= 1e-12 * aflt[chain, 3])
    slid = np.hypot(*(q[chain] - p[chain]).T)
    assert np.count_nonzero(slid > 0.01 * aflt[chain, 3]) > chain.size // 2


def test_zero_motion_changes_nothing(paper):
    """Nodes at their places, no travel, the insert at its place: the placement moves no node
    by more than round-off (1e-12 of the local size: the faces' chord coordinates) and the
    pass keeps every field (1e-13 of its largest value: the fluxes of those round-off moves),
    the reference volumes (1e-13 relative) and the velocities."""
    acls, aflt = toolframe3d_ale_data(paper)
    prm = _prm(INSERT)
    new = toolframe3d_targets_py(paper.nodes, paper.nodes, acls, aflt.copy(), prm=prm)
    assert np.all(np.abs(new - paper.nodes).max(axis=1) <= 1e-12 * aflt[:, 3])
    rng = np.random.default_rng(4)
    ne, n = paper.n_elements, paper.n_nodes
    f = {"sd": rng.normal(size=(ne, 6)) * 1e8, "pres": rng.normal(size=ne) * 1e8,
         "eps_p": rng.uniform(0, 2, ne), "temp": 300 + 200 * rng.uniform(size=ne),
         "dmg": rng.uniform(0, 1, ne), "qh": rng.normal(size=(ne, 12))}
    vol0 = element_volumes3(paper.nodes, paper.conn) * rng.uniform(0.9, 1.1, ne)
    vel = rng.normal(size=(n, 3))
    r = rezone3d_py(paper.nodes, paper.nodes, paper.conn, acls, aflt, {**f, "vol0": vol0},
                    vel=vel, bflag=paper.bflag, rho_s=RHO_S, prm=prm)
    for k, a in f.items():
        assert np.max(np.abs(r[k] - a)) <= 1e-13 * np.max(np.abs(a)), k
    assert np.allclose(r["vol0"], vol0, rtol=1e-13, atol=0.0)
    assert np.allclose(r["vel"], vel, rtol=1e-13, atol=1e-13 * np.abs(vel).max())
    assert np.all(np.abs(r["nodes"] - paper.nodes).max(axis=1) <= 1e-12 * aflt[:, 3])


@pytest.mark.parametrize("mesh_name", ["ext", "paper"])
def test_closed_faces_conserve_mass_volume_and_fields(mesh_name, request):
    """A random small in-plane perturbation of the nodes inside the hexahedra's outline
    (0.03 of the local size; the outline at its places: the in-plane interior nodes on the
    margins' top faces are on the 3D outline), all outline faces closed: the pass puts the
    interior back, and the total volume, the reference volumes, the mass, every field's
    volume integral and the momentum are conserved (1e-12 relative), while the perturbed
    elements' fields do change."""
    mesh = request.getfixturevalue(mesh_name)
    acls, aflt = toolframe3d_ale_data(mesh)
    cur = _perturbed(mesh, acls, aflt, 0.03, 33, [TF_INTERIOR], inner_only=True)
    rng = np.random.default_rng(8)
    ne, n = mesh.n_elements, mesh.n_nodes
    f = {"sd": rng.normal(size=(ne, 6)) * 1e8, "pres": rng.normal(size=ne) * 1e8,
         "eps_p": rng.uniform(0, 2, ne), "temp": 300 + 200 * rng.uniform(size=ne),
         "dmg": rng.uniform(0, 1, ne), "qh": rng.normal(size=(ne, 12))}
    v_old = element_volumes3(cur, mesh.conn)
    assert np.all(v_old > 0.0)
    vol0 = v_old * rng.uniform(0.95, 1.05, ne)
    vel = rng.normal(size=(n, 3))
    r = rezone3d_py(cur, mesh.nodes, mesh.conn, acls, aflt, {**f, "vol0": vol0}, vel=vel,
                    rho_s=RHO_S, prm=_prm(INSERT))
    inner = acls[:, 0] == TF_INTERIOR
    assert np.all(np.abs(r["nodes"] - mesh.nodes)[inner].max(axis=1) <= 1e-12 * aflt[inner, 3])
    v_new = element_volumes3(r["nodes"], mesh.conn)
    assert abs(v_new.sum() - v_old.sum()) <= 1e-12 * v_old.sum()
    assert abs(r["vol0"].sum() - vol0.sum()) <= 1e-12 * vol0.sum()
    for k, a in f.items():
        a = np.asarray(a).reshape(ne, -1)
        before = (a * v_old[:, None]).sum(axis=0)
        after = (np.asarray(r[k]).reshape(ne, -1) * v_new[:, None]).sum(axis=0)
        scale = (np.abs(a) * v_old[:, None]).sum(axis=0)
        assert np.all(np.abs(after - before) <= 1e-12 * scale), k
    m_old = np.zeros(n)
    np.add.at(m_old, mesh.conn.ravel(), np.repeat(RHO_S * vol0 / 8.0, 8))
    assert abs(r["mass"].sum() - m_old.sum()) <= 1e-12 * m_old.sum()
    p_old = (m_old[:, None] * vel).sum(axis=0)
    p_new = (r["mass"][:, None] * r["vel"]).sum(axis=0)
    p_scale = (m_old[:, None] * np.abs(vel)).sum(axis=0)
    assert np.all(np.abs(p_new - p_old) <= 1e-12 * p_scale)
    assert np.max(np.abs(r["pres"] - f["pres"])) > 1e-3 * np.max(np.abs(f["pres"]))


@pytest.mark.parametrize("closed", [True, False])
def test_paper_mesh_pass_keeps_hexahedra_valid(paper, closed):
    """The paper condition's sliced mesh (12.5 um elements), a random Lagrangian perturbation
    of every node but the rigid ones (3D, 0.03 of the local size: the chip's rows in the thin
end slices are a tenth of the shortest edge apart) and an insert travel of
    0.5 um: after the pass every hexahedron has a positive volume, every node is in its
    plane, and through closed faces the reference volume is conserved (1e-12 relative); with
    the model's open inflow and outflow faces it changes by less than what a 0.5 um travel
    can sweep through them."""
    acls, aflt = toolframe3d_ale_data(paper)
    cur = _perturbed(paper, acls, aflt, 0.03, 41, [TF_CHAIN, TF_LINE, TF_FACE, TF_INTERIOR],
                     in_plane=False)
    v_old = element_volumes3(cur, paper.conn)
    assert np.all(v_old > 0.0)
    off_x = 0.5e-6
    r = rezone3d_py(cur, paper.nodes, paper.conn, acls, aflt, {"vol0": v_old},
                    bflag=None if closed else paper.bflag, rho_s=RHO_S,
                    travel=(off_x, 0.0, 0.25), prm=_prm(INSERT), tip=(off_x, 0.0, 0.0))
    v_new = element_volumes3(r["nodes"], paper.conn)
    assert np.all(v_new > 0.0)
    assert np.array_equal(r["nodes"][:, 2], paper.nodes[:, 2])
    rigid = acls[:, 0] == TF_RIGID
    assert np.all(r["nodes"][rigid, 0] == paper.nodes[rigid, 0] + off_x)
    if closed:
        assert abs(r["vol0"].sum() - v_old.sum()) <= 1e-12 * v_old.sum()
    else:
        width = paper.z_slices[-1] - paper.z_slices[0]
        height = paper.nodes[:, 1].max() - paper.y_bottom
        assert abs(r["vol0"].sum() - v_old.sum()) <= 2.0 * off_x * width * height


def test_insert_travel_through_material_at_rest_balances_mass(paper):
    """The insert travels 0.3 um through material at rest (the nodes where the last pass left
    them): the inflow face sweeps exactly its area times the travel, and the reference
    volume changes by exactly what the flux-carrying outline faces sweep (virgin material in,
    the outflow faces' material out; 1e-12 relative), the density being uniform."""
    acls, aflt = toolframe3d_ale_data(paper)
    off_x = 0.3e-6
    prm = _prm(INSERT)
    tip = (off_x, 0.0, 0.0)
    new = toolframe3d_targets_py(paper.nodes, paper.nodes, acls, aflt.copy(), off_x=off_x,
                                 prm=prm, tip=tip)
    conn = paper.conn
    old = paper.nodes
    args = (conn, old[:, 0].copy(), old[:, 1].copy(), old[:, 2].copy(), new[:, 0].copy(),
            new[:, 1].copy(), new[:, 2].copy())
    flux_in = flux_out = 0.0
    area_in = 0.0
    for e, f in zip(*np.nonzero(paper.bflag != BF_CLOSED), strict=True):
        dv = swept_face_py(int(e), int(f), *args)
        if paper.bflag[e, f] == BF_VIRGIN:
            flux_in += dv
            q = old[conn[e, FACES_OUT[f]]][:, 1:]  # the face in the y-z plane
            area_in += 0.5 * abs(np.sum(q[:, 0] * np.roll(q[:, 1], -1)
                                        - np.roll(q[:, 0], -1) * q[:, 1]))
        else:
            flux_out += dv
    assert flux_in == pytest.approx(area_in * off_x, rel=1e-12)
    assert flux_out < 0.0  # the outflow faces follow the insert: material leaves
    v_old = element_volumes3(old, conn)
    r = rezone3d_py(old, old, conn, acls, aflt, {"vol0": v_old}, bflag=paper.bflag,
                    rho_s=RHO_S, travel=(off_x, 0.0, 0.25), prm=prm, tip=tip)
    assert np.array_equal(r["nodes"], new)
    assert abs(r["vol0"].sum() - (v_old.sum() + flux_in + flux_out)) <= 1e-12 * v_old.sum()
    assert np.all(r["vol0"] > 0.0)


def test_rezone3d_py_names_a_wrong_option(paper):
    # an option rezone3d_py neither takes nor passes on to remap3d_py is named in the error
    acls, aflt = toolframe3d_ale_data(paper)
    with pytest.raises(TypeError, match="off_x"):
        rezone3d_py(paper.nodes, paper.nodes, paper.conn, acls, aflt, {}, off_x=1e-6)
    with pytest.raises(ValueError, match="travel"):
        rezone3d_py(paper.nodes, paper.nodes, paper.conn, acls, aflt, {}, travel=(0.0, 0.0))
