"""First-order conservative (donor-cell) remap of a hexahedral mesh: the 3D counterpart of
:mod:`robobore.cutting.fe.ale.remap`, for the 3D tool-frame ALE boring model
(:mod:`robobore.cutting.fe.mesh.toolframe3d` builds its mesh).

A remap pass takes the mesh from the positions the Lagrangian steps left (``x, y, z``) to
the relocated ones (``xn, yn, zn``) and transports the state through the moving element
faces (Benson 1992, "Computational methods in Lagrangian and Eulerian hydrocodes", CMAME
99, sec. 4.2):

* **Swept volume.** Each node moves on a straight line from its old to its new place, so a
  face (bilinear in its two parameters) sweeps the region of the map
  ``(s, t, tau) -> (1 - tau) X_old(s, t) + tau X_new(s, t)``, which is trilinear: the 8-node
  hexahedron with the old face as its bottom and the new face as its top. Its signed volume
  is computed with the Flanagan-Belytschko volume derivatives of :mod:`robobore.cutting.fe.hex.element`
  (``V = sum_I x_I dV/dx_I``; exact for a trilinear hexahedron), in coordinates relative to
  the face's first old corner (round-off of the order of the face, not of the distance to
  the origin). Being the exact flux integral ``int_0^1 int_face v . n dA dtau``, the six
  swept volumes of an element sum exactly to its volume change (Reynolds transport).
* **Donor cell.** For each face with outward swept volume ``dV``: ``dV > 0`` (the element
  grows into its neighbour) brings the neighbour's state, ``dV < 0`` gives away the
  element's own. Element-centred intensive fields are remapped as volume-weighted averages:
  deviatoric stress (6), pressure, plastic strain, temperature, damage and the 12 stored
  hourglass components (treated like the 2D remap treats its two); the element mass, held
  as the reference volume ``vol0`` (= mass / mass-scaled density), is transported with the
  donor's density ``vol0_u / V_u``. The cumulative energy accounts (``ie``, ``plast``,
  ``hge``) stay with their elements, as in 2D (their totals are what the energy balance
  uses). Only faces shared by two live elements carry a flux, plus the outline faces that
  ``bflag`` opens (:data:`BF_VIRGIN`: virgin material -- no stress, strain, damage, at the
  room temperature, with its reference density and at rest -- flows in, the element's own
  state flows out; :data:`BF_OPEN`: outflow, a backflow brings the element's own state).
  Intensive fields are divided by the volume the fluxes account for, so a uniform field
  stays uniform and the volume integral of every field is conserved to round-off.
* **Nodal velocities**, two ways (``vel_mode``):
  :data:`VEL_MOMENTUM` (conservative) -- each element's momentum (its mass times the mean
  of its eight nodal velocities; with lumped masses of 1/8 the element momenta sum to the
  nodal momentum) is transported with the mass fluxes like the other fields, and the change
  of each element's momentum goes back to its nodes in eighths, each node's velocity being
  its new momentum over its new lumped mass. Total momentum is conserved to round-off
  (through closed boundaries), a uniform velocity stays uniform, a zero move changes
  nothing. :data:`VEL_TAYLOR` -- the 2D engine's scheme
  (:func:`robobore.cutting.fe.ale.remap.rz_velocity_py`): a first-order Taylor step with the
  mean old velocity gradient of the node's elements (not conservative). Fixed velocity
  components (``fixed`` bits 1 x, 2 y, 4 z) keep their values in both.

The passes are scalar functions of one element or node (``*_py`` originals, ``njit``
versions without the suffix), read only what the previous pass wrote and allocate nothing,
so the CPU chunk loop calls them from ``prange`` loops (:func:`remap3d`) and a GPU kernel
can compile the same source; the arrays a pass only reads come in tuples built at the call
(``pos``, ``posn`` = old, new ``(x, y, z)`` [m]; ``vel`` [m/s]; ``csr`` = ``(ptr, nel)``;
``fields`` = ``(sd, pres, eps_p, temp, dmg, qh, vol0)``: :mod:`~robobore.cutting.fe.ale.groups3d`).
:func:`remap3d_py` is the allocating wrapper for tests and scripts. The volumes (hexahedra, swept faces, the face numbering) are in
:mod:`robobore.cutting.fe.ale.hexvolume3d`.
"""
# ruff: noqa: E501

from __future__ import annotations

import numpy as np
from numba import njit, prange

from robobore.cutting.fe.ale.groups3d import Cells3, ElementState3, Nodes3, RemapWork3
from robobore.cutting.fe.ale.hexvolume3d import (
    corner_gradient,
    elem_volume,
    element_volumes3,
    swept_face,
)
from robobore.cutting.fe.ale.remap import BF_CLOSED, BF_VIRGIN

__all__ = [
    "N_RZ3", "N_INTENSIVE3", "VEL_MOMENTUM", "VEL_TAYLOR", "rz3_flux_py", "rz3_flux",
    "rz3_momentum_py", "rz3_momentum", "rz3_taylor_py", "rz3_taylor", "rz3_write_py",
    "rz3_write", "rz3_node_mass_py", "rz3_node_mass", "remap3d", "remap3d_py",
    "remap3d_inputs", "remap3d_groups", "remap3d_outputs"]

#: remapped intensive element fields (volume-weighted averages): sd (6), pres, eps_p, temp,
#: dmg, qh (12); then in ``buf``: the new reference volume, the new momentum / rho_s (3),
#: the old momentum / rho_s (3)
N_INTENSIVE3 = 22
B_VOL0 = N_INTENSIVE3
B_PNEW = N_INTENSIVE3 + 1
B_POLD = N_INTENSIVE3 + 4
N_RZ3 = N_INTENSIVE3 + 7
#: nodal velocity remap: conservative element-centred momentum, or the 2D Taylor step
VEL_MOMENTUM, VEL_TAYLOR = 0, 1


def _gather_py(e, w, u, sd, pres, eps_p, temp, dmg, qh, buf):
    """``buf[e, :N_INTENSIVE3] += w * (fields of element u)``."""
    for k in range(6):
        buf[e, k] += w * sd[u, k]
    buf[e, 6] += w * pres[u]
    buf[e, 7] += w * eps_p[u]
    buf[e, 8] += w * temp[u]
    buf[e, 9] += w * dmg[u]
    for k in range(12):
        buf[e, 10 + k] += w * qh[u, k]


_gather = njit(cache=True, inline="always")(_gather_py)


def _mean_velocity_py(u, k, conn, vx, vy, vz):
    """Component ``k`` of the mean of element ``u``'s nodal velocities."""
    s = 0.0
    for c in range(8):
        n = conn[u, c]
        if k == 0:
            s += vx[n]
        elif k == 1:
            s += vy[n]
        else:
            s += vz[n]
    return 0.125 * s


_mean_velocity = njit(cache=True, inline="always")(_mean_velocity_py)


def rz3_flux_py(e, conn, pos, posn, vel, alive, fnbr, bflag, buf, fields, t_room):
    """Donor-cell remap of element ``e`` (old geometry ``pos`` -> new ``posn``): its new
    intensive fields, reference volume and momentum into ``buf[e]`` (layout: :data:`N_RZ3`).
    Reads the old state only, so all elements can run at once. ``fnbr`` (e, 6) the element
    across each face (< 0: none); ``bflag`` (e, 6) the flux type of each outline face
    (``BF_*``; empty: all closed); ``t_room`` the virgin material's temperature [K]."""
    x, y, z = pos
    xn, yn, zn = posn
    vx, vy, vz = vel
    sd, pres, eps_p, temp, dmg, qh, vol0 = fields
    for f in range(N_RZ3):
        buf[e, f] = 0.0
    if alive[e] != 1:
        return
    v_old = elem_volume(e, conn, x, y, z)
    v_new = v_old
    _gather(e, v_old, e, sd, pres, eps_p, temp, dmg, qh, buf)
    m_new = vol0[e]
    px = 0.0
    py = 0.0
    pz = 0.0
    for k in range(3):
        pk = vol0[e] * _mean_velocity(e, k, conn, vx, vy, vz)
        buf[e, B_POLD + k] = pk
        if k == 0:
            px = pk
        elif k == 1:
            py = pk
        else:
            pz = pk
    for f in range(6):
        sw = swept_face(e, f, conn, x, y, z, xn, yn, zn)
        if sw == 0.0:
            continue
        nb = np.int64(fnbr[e, f])
        u = nb
        if nb < 0:
            if bflag.shape[0] == 0 or bflag[e, f] == BF_CLOSED:
                continue
            v_new += sw
            if sw > 0.0 and bflag[e, f] == BF_VIRGIN:
                buf[e, 8] += sw * t_room  # virgin: no stress, strain, damage; at rest
                m_new += sw
                continue
            u = np.int64(e)
        elif alive[nb] != 1:
            continue
        else:
            v_new += sw
            if sw <= 0.0:
                u = np.int64(e)
        _gather(e, sw, u, sd, pres, eps_p, temp, dmg, qh, buf)
        dm = sw * vol0[u] / elem_volume(u, conn, x, y, z)
        m_new += dm
        px += dm * _mean_velocity(u, 0, conn, vx, vy, vz)
        py += dm * _mean_velocity(u, 1, conn, vx, vy, vz)
        pz += dm * _mean_velocity(u, 2, conn, vx, vy, vz)
    inv = 1.0 / v_new
    for f in range(N_INTENSIVE3):
        buf[e, f] *= inv
    buf[e, B_VOL0] = m_new
    buf[e, B_PNEW] = px
    buf[e, B_PNEW + 1] = py
    buf[e, B_PNEW + 2] = pz


rz3_flux = njit(cache=True, inline="always")(rz3_flux_py)


def factor_py(msf, e):
    """The inertia factor of element ``e``: ``msf[e]``, or 1 where ``msf`` is empty (no
    element-attached mass scaling)."""
    if msf.shape[0] == 0:
        return 1.0
    return msf[e]


_factor = njit(cache=True, inline="always")(factor_py)


def rz3_momentum_py(n, csr, conn, alive, vol0, msf, buf, vel, fixed, vbuf):
    """:data:`VEL_MOMENTUM`, node ``n``: its new velocity into ``vbuf[n]`` (after
    :func:`rz3_flux_py` of every element, before :func:`rz3_write_py`): old nodal momentum
    plus an eighth of each of its elements' momentum change, over the new lumped mass (all
    per unit mass-scaled density; each element's share times its inertia factor ``msf[e]``,
    which stays with the element as the material moves through it). Fixed components keep
    their values. Returns 1 when the velocity changes."""
    ptr, nel = csr
    vx, vy, vz = vel
    m_old = 0.0
    m_new = 0.0
    dpx = 0.0
    dpy = 0.0
    dpz = 0.0
    for q in range(ptr[n], ptr[n + 1]):
        e = nel[q]
        if alive[e] != 1:
            continue
        w = 0.125 * _factor(msf, e)
        m_old += w * vol0[e]
        m_new += w * buf[e, B_VOL0]
        dpx += w * (buf[e, B_PNEW] - buf[e, B_POLD])
        dpy += w * (buf[e, B_PNEW + 1] - buf[e, B_POLD + 1])
        dpz += w * (buf[e, B_PNEW + 2] - buf[e, B_POLD + 2])
    vbuf[n, 0] = vx[n]
    vbuf[n, 1] = vy[n]
    vbuf[n, 2] = vz[n]
    if m_new <= 0.0 or (dpx == 0.0 and dpy == 0.0 and dpz == 0.0 and m_new == m_old):
        return 0
    inv = 1.0 / m_new
    fx = fixed[n]
    if (fx & 1) == 0:
        vbuf[n, 0] = (m_old * vx[n] + dpx) * inv
    if (fx & 2) == 0:
        vbuf[n, 1] = (m_old * vy[n] + dpy) * inv
    if (fx & 4) == 0:
        vbuf[n, 2] = (m_old * vz[n] + dpz) * inv
    return 1


rz3_momentum = njit(cache=True, inline="always")(rz3_momentum_py)


def rz3_taylor_py(n, pos, posn, vel, csr, conn, alive, fixed, vbuf):
    """:data:`VEL_TAYLOR`, node ``n``: its new velocity into ``vbuf[n]``: the old one plus
    the mean old velocity gradient of its live elements (the mean gradient
    ``b_I = dV/dx_I / V`` of each) times the node's move, the 2D engine's
    :func:`robobore.cutting.fe.ale.remap.rz_velocity_py` in 3D. Returns 1 when the node
    moves."""
    x, y, z = pos
    xn, yn, zn = posn
    vx, vy, vz = vel
    ptr, nel = csr
    vbuf[n, 0] = vx[n]
    vbuf[n, 1] = vy[n]
    vbuf[n, 2] = vz[n]
    dx = xn[n] - x[n]
    dy = yn[n] - y[n]
    dz = zn[n] - z[n]
    if dx == 0.0 and dy == 0.0 and dz == 0.0:
        return 0
    gx0 = 0.0
    gx1 = 0.0
    gx2 = 0.0
    gy0 = 0.0
    gy1 = 0.0
    gy2 = 0.0
    gz0 = 0.0
    gz1 = 0.0
    gz2 = 0.0
    cnt = 0
    for q in range(ptr[n], ptr[n + 1]):
        e = nel[q]
        if alive[e] != 1:
            continue
        vol = elem_volume(e, conn, x, y, z)
        for c in range(8):
            m = conn[e, c]
            bx, by, bz = corner_gradient(e, c, conn, x, y, z)
            bx /= vol
            by /= vol
            bz /= vol
            gx0 += vx[m] * bx
            gx1 += vx[m] * by
            gx2 += vx[m] * bz
            gy0 += vy[m] * bx
            gy1 += vy[m] * by
            gy2 += vy[m] * bz
            gz0 += vz[m] * bx
            gz1 += vz[m] * by
            gz2 += vz[m] * bz
        cnt += 1
    if cnt == 0:
        return 0
    inv = 1.0 / cnt
    fx = fixed[n]
    if (fx & 1) == 0:
        vbuf[n, 0] = vx[n] + (gx0 * dx + gx1 * dy + gx2 * dz) * inv
    if (fx & 2) == 0:
        vbuf[n, 1] = vy[n] + (gy0 * dx + gy1 * dy + gy2 * dz) * inv
    if (fx & 4) == 0:
        vbuf[n, 2] = vz[n] + (gz0 * dx + gz1 * dy + gz2 * dz) * inv
    return 1


rz3_taylor = njit(cache=True, inline="always")(rz3_taylor_py)


def rz3_write_py(e, alive, buf, sd, pres, eps_p, temp, dmg, qh, vol0):
    """Live element ``e`` takes its remapped fields from ``buf[e]``."""
    if alive[e] != 1:
        return
    for k in range(6):
        sd[e, k] = buf[e, k]
    pres[e] = buf[e, 6]
    eps_p[e] = buf[e, 7]
    temp[e] = buf[e, 8]
    dmg[e] = buf[e, 9]
    for k in range(12):
        qh[e, k] = buf[e, 10 + k]
    vol0[e] = buf[e, B_VOL0]


rz3_write = njit(cache=True, inline="always")(rz3_write_py)


def rz3_node_mass_py(n, ptr, nel, alive, vol0, rho_s, msf, mass):
    """Lumped mass of node ``n`` from its live elements' (remapped) reference volumes, each
    times its element's inertia factor ``msf[e]`` (an empty ``msf``: 1)."""
    m = 0.0
    for q in range(ptr[n], ptr[n + 1]):
        e = nel[q]
        if alive[e] == 1:
            m += 0.125 * rho_s * vol0[e] * _factor(msf, e)
    mass[n] = m


rz3_node_mass = njit(cache=True, inline="always")(rz3_node_mass_py)


@njit(parallel=True, cache=True)
def remap3d(nodes, cells, elems, work, rho_s, t_room, vel_mode):
    """One remap pass from the nodes' ``x, y, z`` to the new positions ``work.xn, yn, zn``
    (then copied into ``x, y, z``): element state, reference volumes, nodal velocities and
    lumped masses. The arrays come grouped (:mod:`robobore.cutting.fe.ale.groups3d`):
    ``nodes`` a :class:`Nodes3`, ``cells`` a :class:`Cells3`, ``elems`` an
    :class:`ElementState3` (``msf`` the elements' inertia factors: the lumped masses are
    ``rho_s vol0 msf / 8`` a corner; empty: 1), ``work`` a :class:`RemapWork3` (``buf``
    (e, :data:`N_RZ3)`, ``vbuf`` (n, 3) work arrays); ``rho_s`` the mass-scaled density
    [kg/m^3], ``t_room`` the virgin material's temperature [K], ``vel_mode``
    :data:`VEL_MOMENTUM` or :data:`VEL_TAYLOR`. Returns the number of nodes whose velocity
    was remapped. Allocates nothing.

    The parallel loops read the groups' arrays as locals, each bound by its own statement
    before them (:mod:`robobore.cutting.fe.ale.groups3d`: a ``prange`` body's writes into an
    array reached through a tuple are dropped)."""
    x = nodes.x
    y = nodes.y
    z = nodes.z
    vx = nodes.vx
    vy = nodes.vy
    vz = nodes.vz
    mass = nodes.mass
    fixed = nodes.fixed
    ptr = nodes.ptr
    nel = nodes.nel
    conn = cells.conn
    alive = cells.alive
    fnbr = cells.fnbr
    bflag = cells.bflag
    sd = elems.sd
    pres = elems.pres
    eps_p = elems.eps_p
    temp = elems.temp
    dmg = elems.dmg
    qh = elems.qh
    vol0 = elems.vol0
    msf = elems.msf
    xn = work.xn
    yn = work.yn
    zn = work.zn
    buf = work.buf
    vbuf = work.vbuf
    nn = x.shape[0]
    ne = conn.shape[0]
    for e in prange(ne):
        rz3_flux(e, conn, (x, y, z), (xn, yn, zn), (vx, vy, vz), alive, fnbr, bflag, buf,
                 (sd, pres, eps_p, temp, dmg, qh, vol0), t_room)
    moved = 0
    if vel_mode == VEL_TAYLOR:
        for n in prange(nn):
            moved += rz3_taylor(n, (x, y, z), (xn, yn, zn), (vx, vy, vz), (ptr, nel), conn,
                                alive, fixed, vbuf)
    else:
        for n in prange(nn):
            moved += rz3_momentum(n, (ptr, nel), conn, alive, vol0, msf, buf, (vx, vy, vz),
                                  fixed, vbuf)
    for n in prange(nn):
        vx[n] = vbuf[n, 0]
        vy[n] = vbuf[n, 1]
        vz[n] = vbuf[n, 2]
    for e in prange(ne):
        rz3_write(e, alive, buf, sd, pres, eps_p, temp, dmg, qh, vol0)
    for n in prange(nn):
        x[n] = xn[n]
        y[n] = yn[n]
        z[n] = zn[n]
    for n in prange(nn):
        rz3_node_mass(n, ptr, nel, alive, vol0, rho_s, msf, mass)
    return moved


def remap3d_inputs(old: np.ndarray, conn: np.ndarray, fields: dict, *,
                   vel: np.ndarray | None = None, fixed: np.ndarray | None = None,
                   fnbr: np.ndarray | None = None, bflag: np.ndarray | None = None,
                   alive: np.ndarray | None = None, t_room: float = 293.15) -> dict:
    """The arrays :func:`remap3d` takes, built from the node positions ``old`` (n, 3), the
    hexahedra ``conn`` and the ``fields`` dict of :func:`remap3d_py` (same defaults): keys
    ``x, y, z, vx, vy, vz, mass, fixed, conn, alive, ptr, nel, fnbr, bflag, sd, pres, eps_p,
    temp, dmg, qh, vol0, msf, buf, vbuf`` (fresh copies; ``msf`` from ``fields``, else
    empty)."""
    from robobore.cutting.fe.physics.thermal3d import face_neighbours

    old = np.ascontiguousarray(old, np.float64)
    conn = np.ascontiguousarray(conn, np.int64)
    n, ne = old.shape[0], conn.shape[0]

    def get(key, shape, default):
        if key in fields:
            return np.array(fields[key], np.float64).reshape(shape).copy()
        return np.full(shape, default, np.float64)

    v = np.zeros((n, 3)) if vel is None else np.array(vel, np.float64)
    counts = np.bincount(conn.ravel(), minlength=n)
    ptr = np.zeros(n + 1, np.int64)
    ptr[1:] = np.cumsum(counts)
    return {
        "x": old[:, 0].copy(), "y": old[:, 1].copy(), "z": old[:, 2].copy(),
        "vx": v[:, 0].copy(), "vy": v[:, 1].copy(), "vz": v[:, 2].copy(),
        "mass": np.zeros(n),
        "fixed": np.zeros(n, np.int64) if fixed is None else np.array(fixed, np.int64),
        "conn": conn,
        "alive": np.ones(ne, np.int64) if alive is None else np.array(alive, np.int64),
        "ptr": ptr, "nel": (np.argsort(conn.ravel(), kind="stable") // 8).astype(np.int64),
        "fnbr": face_neighbours(conn) if fnbr is None else np.asarray(fnbr, np.int64),
        "bflag": np.zeros((0, 6), np.int64) if bflag is None else np.asarray(bflag, np.int64),
        "sd": get("sd", (ne, 6), 0.0), "pres": get("pres", (ne,), 0.0),
        "eps_p": get("eps_p", (ne,), 0.0), "temp": get("temp", (ne,), t_room),
        "dmg": get("dmg", (ne,), 0.0), "qh": get("qh", (ne, 12), 0.0),
        "vol0": (np.array(fields["vol0"], np.float64) if "vol0" in fields
                 else element_volumes3(old, conn)),
        "msf": (np.array(fields["msf"], np.float64) if "msf" in fields else np.zeros(0)),
        "buf": np.zeros((ne, N_RZ3)), "vbuf": np.zeros((n, 3)),
    }


def remap3d_groups(a: dict, new: np.ndarray | None = None
                   ) -> tuple[Nodes3, Cells3, ElementState3, RemapWork3]:
    """The groups :func:`remap3d` takes from the arrays of :func:`remap3d_inputs` (the same
    arrays, not copies); ``new`` (n, 3) the new positions (None: empty ``xn, yn, zn``, for
    a pass that places the nodes itself)."""
    n = a["x"].shape[0]
    new_xyz = ((np.empty(n), np.empty(n), np.empty(n)) if new is None else
               tuple(np.ascontiguousarray(new[:, k], np.float64).copy() for k in range(3)))
    nodes = Nodes3(x=a["x"], y=a["y"], z=a["z"], vx=a["vx"], vy=a["vy"], vz=a["vz"],
                   mass=a["mass"], fixed=a["fixed"], ptr=a["ptr"], nel=a["nel"])
    cells = Cells3(conn=a["conn"], alive=a["alive"], fnbr=a["fnbr"], bflag=a["bflag"])
    elems = ElementState3(sd=a["sd"], pres=a["pres"], eps_p=a["eps_p"], temp=a["temp"],
                          dmg=a["dmg"], qh=a["qh"], vol0=a["vol0"], msf=a["msf"])
    work = RemapWork3(xn=new_xyz[0], yn=new_xyz[1], zn=new_xyz[2], buf=a["buf"],
                      vbuf=a["vbuf"])
    return nodes, cells, elems, work


def remap3d_outputs(a: dict, moved: int) -> dict:
    """The result dict of :func:`remap3d_py` from the arrays of :func:`remap3d_inputs` after
    a pass."""
    return {"sd": a["sd"], "pres": a["pres"], "eps_p": a["eps_p"], "temp": a["temp"],
            "dmg": a["dmg"], "qh": a["qh"], "vol0": a["vol0"],
            "vel": np.stack([a["vx"], a["vy"], a["vz"]], axis=1), "mass": a["mass"],
            "moved": int(moved), "nodes": np.stack([a["x"], a["y"], a["z"]], axis=1)}


def remap3d_py(old: np.ndarray, new: np.ndarray, conn: np.ndarray, fields: dict,
               *, vel: np.ndarray | None = None, fixed: np.ndarray | None = None,
               fnbr: np.ndarray | None = None, bflag: np.ndarray | None = None,
               alive: np.ndarray | None = None, rho_s: float = 1.0, t_room: float = 293.15,
               vel_mode: int = VEL_MOMENTUM) -> dict:
    """Allocating wrapper of :func:`remap3d` for tests and scripts.

    ``old``, ``new`` (n, 3) node positions [m]; ``conn`` (e, 8) VTK order; ``fields``: any of
    ``sd`` (e, 6), ``pres``, ``eps_p``, ``temp``, ``dmg`` (e,), ``qh`` (e, 12), ``vol0``,
    ``msf`` (e,) (missing: zero, ``vol0`` the old volumes, ``temp`` ``t_room``, ``msf`` 1);
    ``vel`` (n, 3) (zero); ``fixed`` (n,) bit mask; ``fnbr`` (e, 6) face neighbours (default
    ``thermal3d.face_neighbours``); ``bflag`` (e, 6) outline flux types (default: closed).
    Returns the remapped copies: the same keys plus ``vel``, ``mass``, ``moved``, ``nodes``."""
    a = remap3d_inputs(old, conn, fields, vel=vel, fixed=fixed, fnbr=fnbr, bflag=bflag,
                       alive=alive, t_room=t_room)
    new = np.ascontiguousarray(new, np.float64)
    moved = remap3d(*remap3d_groups(a, new), float(rho_s), float(t_room), int(vel_mode))
    return remap3d_outputs(a, moved)
