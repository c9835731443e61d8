"""Donor-cell remap of hexahedral meshes (:mod:`robobore.cutting.fe.ale.remap3d`).

Checks: the swept volumes are the exact flux integral (the six faces of an element sum to
its volume change for any trilinear motion), a zero move is the identity, a uniform field
stays uniform, every field's volume integral and the total momentum are conserved through
closed boundaries, a step profile is carried exactly one element by a one-element move
(Courant number 1), and on an extruded mesh with in-plane motion the 3D remap is the
validated 2D remap (:mod:`robobore.cutting.fe.ale.remap`) times the extrusion thickness.
Tolerances are round-off bounds, stated per test.
"""

from __future__ import annotations

import numpy as np
import pytest

from robobore.cutting.fe.ale.groups3d import Cells3, ElementState3, Nodes3, RemapWork3
from robobore.cutting.fe.ale.hexvolume3d import (
    FACES_OUT,
    element_volumes3,
    hex_volume_py,
    swept_face_py,
)
from robobore.cutting.fe.ale.remap import BF_OPEN, BF_VIRGIN, rz_flux_py, rz_velocity_py
from robobore.cutting.fe.ale.remap3d import VEL_MOMENTUM, VEL_TAYLOR, remap3d_py
from robobore.cutting.fe.ale.stencils import edge_neighbours
from robobore.cutting.fe.engine.groups2d import QS_FIELDS
from robobore.cutting.fe.engine.state3d import box_mesh, hex_volumes
from robobore.cutting.fe.physics.thermal3d import HEX_FACES

H = 10e-6  # element size [m]
ORIGIN = (1.3e-3, -0.7e-3, 2.1e-3)  # away from the origin, as in a model frame
RHO_S = 4430.0 * 100.0


def _box(nx=5, ny=4, nz=3, jitter=0.15, seed=0):
    nodes, conn, idx = box_mesh(nx, ny, nz, nx * H, ny * H, nz * H, origin=ORIGIN)
    rng = np.random.default_rng(seed)
    inner = np.zeros(nodes.shape[0], bool)
    inner[idx[1:-1, 1:-1, 1:-1].ravel()] = True
    nodes = nodes.copy()
    nodes[inner] += rng.uniform(-jitter * H, jitter * H, (int(inner.sum()), 3))
    return nodes, conn, idx, inner


def _fields(ne, rng):
    return {"sd": rng.normal(size=(ne, 6)) * 1e8, "pres": rng.normal(size=ne) * 1e8,
            "eps_p": rng.uniform(0, 2, ne), "temp": 300 + 200 * rng.uniform(size=ne),
            "dmg": rng.uniform(0, 1, ne), "qh": rng.normal(size=(ne, 12)),
            }


def _interior_move(nodes, inner, amp, seed):
    rng = np.random.default_rng(seed)
    new = nodes.copy()
    new[inner] += rng.uniform(-amp * H, amp * H, (int(inner.sum()), 3))
    return new


def test_hex_volume_matches_the_engine():
    nodes, conn, _, _ = _box(jitter=0.3)
    v = element_volumes3(nodes, conn)
    ref = hex_volumes(nodes, conn)  # 2x2x2 Gauss, exact for the trilinear element
    assert np.all(v > 0)
    assert np.max(np.abs(v / ref - 1.0)) < 1e-12


def test_face_table_is_outward_and_matches_the_thermal_faces():
    for f in range(6):
        assert sorted(FACES_OUT[f]) == sorted(HEX_FACES[f])
    # unit cube (scaled), each face pushed out by d: the swept volume is +A d
    nodes, conn, _ = box_mesh(1, 1, 1, H, H, H, origin=ORIGIN)
    xyz = [nodes[:, k].copy() for k in range(3)]
    d = 0.1 * H
    axis = (0, 0, 1, 1, 2, 2)
    sign = (-1, 1, -1, 1, -1, 1)
    for f in range(6):
        new = nodes.copy()
        new[conn[0, FACES_OUT[f]], axis[f]] += sign[f] * d
        sw = swept_face_py(0, f, conn, *xyz, new[:, 0], new[:, 1], new[:, 2])
        assert sw == pytest.approx(H * H * d, rel=1e-12)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_swept_volumes_are_the_exact_volume_change(seed):
    # any trilinear motion of a distorted element: the six outward swept volumes sum to
    # V_new - V_old (Reynolds transport; exact for the trilinear swept hexahedra)
    rng = np.random.default_rng(seed)
    nodes, conn, _ = box_mesh(1, 1, 1, H, H, H, origin=ORIGIN)
    old = nodes + rng.uniform(-0.2 * H, 0.2 * H, nodes.shape)
    new = old + rng.uniform(-0.3 * H, 0.3 * H, nodes.shape)
    xo = [old[:, k].copy() for k in range(3)]
    xn = [new[:, k].copy() for k in range(3)]
    total = sum(swept_face_py(0, f, conn, *xo, *xn) for f in range(6))
    dv = element_volumes3(new, conn)[0] - element_volumes3(old, conn)[0]
    assert total == pytest.approx(dv, rel=1e-12, abs=1e-12 * H ** 3)


def test_hex_volume_is_translation_invariant_far_from_the_origin():
    rng = np.random.default_rng(5)
    p = rng.uniform(0, H, (8, 3)) + np.array([[0, 0, 0], [H, 0, 0], [H, H, 0], [0, H, 0],
                                              [0, 0, H], [H, 0, H], [H, H, H], [0, H, H]])
    v0 = hex_volume_py(tuple(p[:, 0]), tuple(p[:, 1]), tuple(p[:, 2]))
    q = p + np.array([5e-3, -3e-3, 7e-3])
    v1 = hex_volume_py(tuple(q[:, 0]), tuple(q[:, 1]), tuple(q[:, 2]))
    assert v1 == pytest.approx(v0, rel=1e-13)


@pytest.mark.parametrize("mode", [VEL_MOMENTUM, VEL_TAYLOR])
def test_zero_move_is_the_identity(mode):
    nodes, conn, _, _ = _box()
    rng = np.random.default_rng(3)
    ne = conn.shape[0]
    f = _fields(ne, rng)
    vel = rng.normal(size=(nodes.shape[0], 3))
    vol0 = element_volumes3(nodes, conn) * rng.uniform(0.9, 1.1, ne)
    r = remap3d_py(nodes, nodes, conn, {**f, "vol0": vol0}, vel=vel, rho_s=RHO_S,
                   vel_mode=mode)
    for k, a in f.items():
        assert np.allclose(r[k], a, rtol=1e-15, atol=0.0), k  # f V / V: a few ulp
    assert np.allclose(r["vol0"], vol0, rtol=0.0, atol=0.0)
    assert np.array_equal(r["vel"], vel)
    assert r["moved"] == 0


@pytest.mark.parametrize("mode", [VEL_MOMENTUM, VEL_TAYLOR])
def test_uniform_fields_stay_uniform(mode):
    nodes, conn, _, inner = _box()
    new = _interior_move(nodes, inner, 0.2, 7)
    ne = conn.shape[0]
    vals = {"sd": np.tile(np.arange(1.0, 7.0) * 1e8, (ne, 1)), "pres": np.full(ne, -3e8),
            "eps_p": np.full(ne, 0.7), "temp": np.full(ne, 512.0), "dmg": np.full(ne, 0.3),
            "qh": np.tile(np.linspace(-1, 1, 12), (ne, 1))}
    vel = np.tile([2.0, -0.5, 0.25], (nodes.shape[0], 1))
    r = remap3d_py(nodes, new, conn, vals, vel=vel, rho_s=RHO_S, vel_mode=mode)
    for k, a in vals.items():
        assert np.allclose(r[k], a, rtol=1e-13, atol=0.0), k
    # reference density 1 everywhere stays 1: vol0 = the new volume
    assert np.allclose(r["vol0"], element_volumes3(new, conn), rtol=1e-12)
    assert np.allclose(r["vel"], vel, rtol=1e-13, atol=0.0)


@pytest.mark.parametrize("seed", [11, 12])
def test_volume_integrals_and_momentum_are_conserved(seed):
    nodes, conn, _, inner = _box(nx=6, ny=5, nz=4, seed=seed)
    new = _interior_move(nodes, inner, 0.25, seed + 100)
    rng = np.random.default_rng(seed)
    ne, n = conn.shape[0], nodes.shape[0]
    f = _fields(ne, rng)
    v_old = element_volumes3(nodes, conn)
    v_new = element_volumes3(new, conn)
    vol0 = v_old * rng.uniform(0.95, 1.05, ne)  # a non-uniform density
    vel = rng.normal(size=(n, 3))
    r = remap3d_py(nodes, new, conn, {**f, "vol0": vol0}, vel=vel, rho_s=RHO_S)
    for k, a in f.items():
        a = np.asarray(a).reshape(ne, -1)
        before = (a * v_old[:, None]).sum(axis=0)
        after = (np.asarray(r[k]).reshape(ne, -1) * v_new[:, None]).sum(axis=0)
        scale = (np.abs(a) * v_old[:, None]).sum(axis=0)
        assert np.all(np.abs(after - before) <= 1e-12 * scale), k
    assert abs(r["vol0"].sum() - vol0.sum()) <= 1e-12 * vol0.sum()
    m_old = np.zeros(n)
    np.add.at(m_old, conn.ravel(), np.repeat(RHO_S * vol0 / 8.0, 8))
    assert abs(r["mass"].sum() - m_old.sum()) <= 1e-12 * m_old.sum()
    p_old = (m_old[:, None] * vel).sum(axis=0)
    p_new = (r["mass"][:, None] * r["vel"]).sum(axis=0)
    p_scale = (m_old[:, None] * np.abs(vel)).sum(axis=0)
    assert np.all(np.abs(p_new - p_old) <= 1e-12 * p_scale)
    # the moved elements do change (the test is not trivially passed)
    assert np.max(np.abs(r["pres"] - f["pres"])) > 1e-3 * np.max(np.abs(f["pres"]))


def test_fixed_components_keep_their_velocity():
    nodes, conn, _, inner = _box()
    new = _interior_move(nodes, inner, 0.2, 8)
    rng = np.random.default_rng(8)
    vel = rng.normal(size=(nodes.shape[0], 3))
    fixed = np.zeros(nodes.shape[0], np.int64)
    k = int(np.flatnonzero(inner)[0])
    fixed[k] = 1 | 4
    r = remap3d_py(nodes, new, conn, {}, vel=vel, fixed=fixed)
    assert r["vel"][k, 0] == vel[k, 0] and r["vel"][k, 2] == vel[k, 2]
    assert r["vel"][k, 1] != vel[k, 1]


def test_step_profile_moves_exactly_one_element():
    # a Lagrangian step of one element length in +x, then every node back by one element:
    # the material (and its step profile) ends one element further along x; virgin
    # material enters through the inflow face x = x_min, the last column leaves through
    # the open face x = x_max
    nx, ny, nz = 8, 3, 2
    nodes, conn, idx = box_mesh(nx, ny, nz, nx * H, ny * H, nz * H, origin=ORIGIN)
    ne = conn.shape[0]
    ix = np.arange(ne) // (ny * nz)  # hex_conn order: x slowest
    lag = nodes + np.array([H, 0.0, 0.0])
    temp = np.where(ix < 3, 900.0, 400.0)
    eps = np.where(ix < 3, 1.5, 0.2)
    vol0 = element_volumes3(nodes, conn) * np.where(ix < 3, 1.1, 1.0)
    bflag = np.zeros((ne, 6), np.int64)
    bflag[ix == 0, 0] = BF_VIRGIN
    bflag[ix == nx - 1, 1] = BF_OPEN
    r = remap3d_py(lag, nodes, conn, {"temp": temp, "eps_p": eps, "vol0": vol0}, bflag=bflag,
                   t_room=293.15)
    for i in range(nx):
        sel = ix == i
        want_t = 293.15 if i == 0 else (900.0 if i - 1 < 3 else 400.0)
        want_e = 0.0 if i == 0 else (1.5 if i - 1 < 3 else 0.2)
        assert np.allclose(r["temp"][sel], want_t, rtol=1e-13), i
        assert np.allclose(r["eps_p"][sel], want_e, rtol=1e-13, atol=1e-15), i
    v = element_volumes3(nodes, conn)
    dens = r["vol0"] / v
    assert np.allclose(dens[ix == 0], 1.0, rtol=1e-13)
    assert np.allclose(dens[(ix >= 1) & (ix <= 3)], 1.1, rtol=1e-13)
    assert np.allclose(dens[ix >= 4], 1.0, rtol=1e-13)


def _quad_mesh(nx, ny, seed):
    # at the origin: the 2D remap evaluates its areas in absolute coordinates (round-off
    # relative to the coordinates' size), the 3D one relative to a corner
    rng = np.random.default_rng(seed)
    xs = H * np.arange(nx + 1)
    ys = H * np.arange(ny + 1)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    nodes = np.stack([X.ravel(), Y.ravel()], axis=1)
    idx = np.arange(nodes.shape[0]).reshape(nx + 1, ny + 1)
    inner = np.zeros(nodes.shape[0], bool)
    inner[idx[1:-1, 1:-1].ravel()] = True
    nodes[inner] += rng.uniform(-0.2 * H, 0.2 * H, (int(inner.sum()), 2))
    conn = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]],
                    axis=-1).reshape(-1, 4)
    return nodes, conn, inner


def test_extruded_mesh_equals_the_2d_remap_times_the_thickness():
    n2_x, n2_y, lz = 5, 4, 0.7 * H
    nodes2, conn2, inner2 = _quad_mesh(n2_x, n2_y, 21)
    rng = np.random.default_rng(21)
    new2 = nodes2.copy()
    new2[inner2] += rng.uniform(-0.25 * H, 0.25 * H, (int(inner2.sum()), 2))
    n2, ne = nodes2.shape[0], conn2.shape[0]
    # two layers in z, in-plane motion only
    nl = 2
    zs = lz * np.arange(nl + 1)
    nodes3 = np.vstack([np.column_stack([nodes2, np.full(n2, zk)]) for zk in zs])
    new3 = np.vstack([np.column_stack([new2, np.full(n2, zk)]) for zk in zs])
    conn3 = np.vstack([np.hstack([conn2 + k * n2, conn2 + (k + 1) * n2]) for k in range(nl)])
    f2 = {k: rng.normal(size=ne) for k in ("sdx", "sdy", "sdz", "sdxy", "pres", "eps_p",
                                          "temp", "dmg", "qhx", "qhy")}
    a_old = 0.5 * ((nodes2[conn2[:, 2], 0] - nodes2[conn2[:, 0], 0])
                   * (nodes2[conn2[:, 3], 1] - nodes2[conn2[:, 1], 1])
                   + (nodes2[conn2[:, 1], 0] - nodes2[conn2[:, 3], 0])
                   * (nodes2[conn2[:, 2], 1] - nodes2[conn2[:, 0], 1]))
    area0 = a_old * rng.uniform(0.9, 1.1, ne)
    # 2D: the validated remap's element pass
    enbr = edge_neighbours(conn2)
    buf2 = np.zeros((ne, 11))
    x, y = nodes2[:, 0].copy(), nodes2[:, 1].copy()
    xn, yn = new2[:, 0].copy(), new2[:, 1].copy()
    alive = np.ones(ne, np.int64)
    for e in range(ne):
        rz_flux_py(e, conn2, alive, (x, y), (xn, yn), enbr, np.zeros((0, 4), np.int64), buf2,
                   (np.array([f2[k] for k in QS_FIELDS]), area0), 293.15)
    # 3D, the same fields in every layer
    sd = np.zeros((ne, 6))
    sd[:, 0], sd[:, 1], sd[:, 2], sd[:, 3] = f2["sdx"], f2["sdy"], f2["sdz"], f2["sdxy"]
    sd[:, 4], sd[:, 5] = rng.normal(size=ne), rng.normal(size=ne)
    qh = rng.normal(size=(ne, 12))
    qh[:, 0], qh[:, 1] = f2["qhx"], f2["qhy"]
    rep = np.tile
    f3 = {"sd": rep(sd, (nl, 1)), "pres": rep(f2["pres"], nl), "eps_p": rep(f2["eps_p"], nl),
          "temp": rep(f2["temp"], nl), "dmg": rep(f2["dmg"], nl), "qh": rep(qh, (nl, 1)),
          "vol0": rep(area0 * lz, nl)}
    vel2 = rng.normal(size=(n2, 2))
    vel3 = np.column_stack([rep(vel2[:, 0], nl + 1), rep(vel2[:, 1], nl + 1),
                            np.zeros(n2 * (nl + 1))])
    r = remap3d_py(nodes3, new3, conn3, f3, vel=vel3, vel_mode=VEL_TAYLOR)
    tol = dict(rtol=1e-12, atol=1e-13)
    for k in range(nl):
        s = slice(k * ne, (k + 1) * ne)
        for j, key in enumerate(("sdx", "sdy", "sdz", "sdxy")):
            assert np.allclose(r["sd"][s, j], buf2[:, j], **tol), key
        assert np.allclose(r["pres"][s], buf2[:, 4], **tol)
        assert np.allclose(r["eps_p"][s], buf2[:, 5], **tol)
        assert np.allclose(r["temp"][s], buf2[:, 6], **tol)
        assert np.allclose(r["dmg"][s], buf2[:, 7], **tol)
        assert np.allclose(r["qh"][s, 0], buf2[:, 8], **tol)
        assert np.allclose(r["qh"][s, 1], buf2[:, 9], **tol)
        assert np.allclose(r["vol0"][s], buf2[:, 10] * lz, rtol=1e-12, atol=0.0)
    # the moved elements changed: the comparison is not between unchanged fields
    assert np.max(np.abs(buf2[:, 4] - f2["pres"])) > 1e-3
    # nodal velocities, VEL_TAYLOR: the 2D Taylor step (in-plane gradient; a node of the
    # middle layer has the same element set as its 2D node, stacked twice)
    counts = np.bincount(conn2.ravel(), minlength=n2)
    ptr = np.zeros(n2 + 1, np.int64)
    ptr[1:] = np.cumsum(counts)
    nel = (np.argsort(conn2.ravel(), kind="stable") // 4).astype(np.int64)
    vbuf = np.zeros((n2, 2))
    mid = slice(n2, 2 * n2)
    for nd in range(n2):
        rz_velocity_py(nd, x, y, xn, yn, vel2[:, 0].copy(), vel2[:, 1].copy(), ptr, nel, conn2,
                       vbuf)
    assert np.allclose(r["vel"][mid, 0], vel2[:, 0] + vbuf[:, 0], rtol=1e-12, atol=1e-12)
    assert np.allclose(r["vel"][mid, 1], vel2[:, 1] + vbuf[:, 1], rtol=1e-12, atol=1e-12)
    assert np.allclose(r["vel"][:, 2], 0.0, atol=1e-12)


def test_runs_on_the_engine_state_and_keeps_its_lumped_masses():
    # the pass takes the arrays of FEState3 as they are (face neighbours: the state's
    # enbr); its lumped masses are the engine's (make_state3) for the remapped vol0
    from robobore.cutting.fe.ale.remap3d import N_RZ3, remap3d
    from robobore.cutting.fe.engine.state3d import make_state3
    from robobore.cutting.fe.hex import layout3d
    from robobore.material import load_material

    nodes, conn, _, inner = _box()
    mat = load_material("TC4")
    st = make_state3(nodes, conn, np.zeros(nodes.shape[0], np.int64), mat)
    rho_s = mat.rho * st.prm[layout3d.P_MS]
    rng = np.random.default_rng(4)
    st.vx[:] = rng.normal(size=st.vx.size)
    st.sd[:] = rng.normal(size=st.sd.shape) * 1e8
    mass0 = st.mass.copy()
    p0 = np.array([np.sum(st.mass * v) for v in (st.vx, st.vy, st.vz)])
    new = _interior_move(nodes, inner, 0.2, 4)
    buf = np.zeros((st.n_elements, N_RZ3))
    vbuf = np.zeros((nodes.shape[0], 3))
    remap3d(Nodes3(x=st.x, y=st.y, z=st.z, vx=st.vx, vy=st.vy, vz=st.vz, mass=st.mass,
                   fixed=st.fixed, ptr=st.ptr, nel=st.nel),
            Cells3(conn=st.conn, alive=st.alive, fnbr=st.enbr,
                   bflag=np.zeros((0, 6), np.int64)),
            ElementState3(sd=st.sd, pres=st.pres, eps_p=st.eps_p, temp=st.temp, dmg=st.dmg,
                          qh=st.qh, vol0=st.vol0, msf=np.zeros(0)),
            RemapWork3(xn=new[:, 0].copy(), yn=new[:, 1].copy(), zn=new[:, 2].copy(), buf=buf,
                       vbuf=vbuf),
            rho_s, mat.T_room, VEL_MOMENTUM)
    assert np.array_equal(st.nodes(), new)
    want = np.zeros(nodes.shape[0])
    np.add.at(want, conn.ravel(), np.repeat(st.vol0 * rho_s / 8.0, 8))
    assert np.allclose(st.mass, want, rtol=1e-14, atol=0.0)
    assert st.mass.sum() == pytest.approx(mass0.sum(), rel=1e-13)
    p1 = np.array([np.sum(st.mass * v) for v in (st.vx, st.vy, st.vz)])
    assert np.allclose(p1, p0, rtol=0.0, atol=1e-12 * np.sum(mass0 * np.abs(st.vx)))
