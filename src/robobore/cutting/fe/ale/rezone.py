"""The tool-frame ALE pass of the plane-strain engine: node relocation + first-order donor-cell
remap (:func:`rezone`).

Every ``solver.ale_interval`` steps the mesh of the tool-frame model (``mesh.frame = "tool"``,
:mod:`robobore.cutting.fe.ale.toolframe`) is moved back to its place in the tool's frame
(:func:`toolframe_targets`): rigid nodes (inflow face, bottom) to their place, surface-chain
nodes sliding along their surface polyline towards it, chain ends along their outflow line,
outflow-face nodes between their ends, interior nodes to their place plus a mesh displacement
interpolated from the boundary's (Jacobi sweeps). Node moves are limited to ``max_move`` of
the local element size so the remap Courant number stays below 1.

The element state is then transported through the moving element edges by a conservative
first-order donor-cell (upwind) remap: for each edge the area swept by its motion carries the
state of the element it sweeps into (Benson 1992, "Computational methods in Lagrangian and
Eulerian hydrocodes", CMAME 99, sec. 4.2). Nodal velocities are remapped by a first-order
Taylor expansion with the mean velocity gradient of the adjacent elements.

Remapped element fields: deviatoric stress, pressure, plastic strain, temperature, damage,
stored hourglass force; element mass (held as the reference area ``area0`` = mass /
scaled density) is remapped conservatively and the lumped nodal masses recomputed. Edges
shared by two live elements carry a flux; outline edges carry one by their flux type
(``bflag``: virgin material flows in through the inflow face, material leaves through the
outflow faces); what any other outline edge sweeps as its nodes slide along a curved surface
is not mass that enters or leaves the model, and the intensive fields are divided by the area
their fluxes account for (a uniform field stays uniform).

The remap's scalar passes are in :mod:`robobore.cutting.fe.ale.remap`, the element neighbours
across each edge (:func:`edge_neighbours`) in :mod:`robobore.cutting.fe.ale.stencils`.
"""

from __future__ import annotations

import math

from numba import njit, prange

from robobore.cutting.fe.ale.remap import (
    rz_flux,
    rz_node_mass,
    rz_velocity,
    rz_write,
)
from robobore.cutting.fe.physics.tool_contact import tool_gap

#: tool-frame node classes (``acls[:, 0]``): interior, rigid (inflow face, bottom), on a
#: surface chain (free or against the tool), chain end on an outflow line, on an outflow face
TF_INTERIOR, TF_RIGID, TF_CHAIN, TF_LINE, TF_FACE = 0, 1, 2, 3, 4
#: Jacobi sweeps of the mesh-displacement interpolation per tool-frame pass
TF_SWEEPS = 4


def limit_py(px, py, tx, ty, lim):
    """``(tx, ty)`` moved back towards ``(px, py)`` so that the move is at most ``lim``."""
    dx = tx - px
    dy = ty - py
    d = math.sqrt(dx * dx + dy * dy)
    if d > lim:
        return px + dx * lim / d, py + dy * lim / d
    return tx, ty


def make_off_tool(tool_gap):
    """:func:`off_tool_py` with its callees ``tool_gap`` given (the CPU's compiled
    functions here, a GPU engine's device functions in its port)."""

    def off_tool_py(px, py, qx, qy, tg):
        """``(qx, qy)`` put back along the tool normal if it lies deeper in the tool than
        ``(px, py)`` did (or in it at all when ``(px, py)`` was outside): a surface node that
        slides along a chord wrapped round the edge adds no penalty energy."""
        g0, _a, _b = tool_gap(px, py, tg[0], tg[1], tg[2], tg[3], tg[4], tg[5], tg[6])
        g1, n1x, n1y = tool_gap(qx, qy, tg[0], tg[1], tg[2], tg[3], tg[4], tg[5], tg[6])
        gt = min(g0, 0.0)
        if g1 < gt:
            return qx + (gt - g1) * n1x, qy + (gt - g1) * n1y
        return qx, qy

    return off_tool_py


limit = njit(cache=True, inline="always")(limit_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
off_tool_py = make_off_tool(tool_gap)
off_tool = njit(cache=False, inline="always")(off_tool_py)


# -- the tool-frame and remap passes as scalar functions (one node or element each), called
# -- by the CPU's prange loops below and by the GPU kernels
# (robobore.cutting.fe.engine.gpu.backend2d)

def make_tf_place(limit, off_tool):
    """:func:`tf_place_py` with its callees ``limit``, ``off_tool`` given (the CPU's
    compiled functions here, a GPU engine's device functions in its port)."""

    def tf_place_py(n, x, y, xn, yn, x0, y0, acls, aflt, off, max_move, tg):
        """first pass, node ``n``: the new place of a rigid node, a surface-chain
        node or a chain end on an outflow line into ``xn[n]``, ``yn[n]`` (other classes: left
        as they are). Reads the old positions only."""
        c = acls[n, 0]
        px = x[n]
        py = y[n]
        qx = x0[n] + off
        qy = y0[n]
        if c == TF_RIGID:
            xn[n] = qx
            yn[n] = qy
        elif c == TF_CHAIN:
            a = acls[n, 1]
            b = acls[n, 2]
            tx = px
            ty = py
            best = (qx - px) ** 2 + (qy - py) ** 2
            la = math.sqrt((x[a] - px) ** 2 + (y[a] - py) ** 2)
            lb = math.sqrt((x[b] - px) ** 2 + (y[b] - py) ** 2)
            for k in range(2):
                m = a if k == 0 else b
                ex = x[m] - px
                ey = y[m] - py
                l2 = ex * ex + ey * ey
                if l2 <= 0.0:
                    continue
                t = ((qx - px) * ex + (qy - py) * ey) / l2
                if t <= 0.0:
                    continue
                t = min(t, 1.0)
                sx = px + t * ex
                sy = py + t * ey
                d = (qx - sx) ** 2 + (qy - sy) ** 2
                if d < best:
                    best = d
                    tx = sx
                    ty = sy
            tx, ty = limit(px, py, tx, ty, max_move * min(la, lb))
            tx, ty = off_tool(px, py, tx, ty, tg)
            xn[n] = tx
            yn[n] = ty
        elif c == TF_LINE:
            # where the surface (its last segment, extended) crosses the line through the
            # node's tool-frame place along aflt[n, 1:3], at most aflt[n, 0] from that place
            a = acls[n, 1]
            ex = px - x[a]
            ey = py - y[a]
            dx = aflt[n, 1]
            dy = aflt[n, 2]
            cr = ex * dy - ey * dx
            le = math.sqrt(ex * ex + ey * ey)
            if abs(cr) > 0.05 * le:
                t = ((qx - x[a]) * dy - (qy - y[a]) * dx) / cr
                tx = x[a] + t * ex
                ty = y[a] + t * ey
                s = (tx - qx) * dx + (ty - qy) * dy
            else:  # surface nearly along the line: project onto it
                s = (px - qx) * dx + (py - qy) * dy
            # at most aflt[n, 0] along the line from the node's place
            s = max(-aflt[n, 0], min(aflt[n, 0], s))
            tx = qx + s * dx
            ty = qy + s * dy
            tx, ty = limit(px, py, tx, ty, max_move * le)
            tx, ty = off_tool(px, py, tx, ty, tg)
            xn[n] = tx
            yn[n] = ty

    return tf_place_py


def tf_face_py(n, xn, yn, x0, y0, acls, aflt, off):
    """second pass, node ``n`` (after :func:`tf_place_py` of every node):
    an outflow-face node spread between its two (placed) ends; then, for every node but an
    interior one, its mesh displacement (the boundary values of the interpolation)."""
    c = acls[n, 0]
    if c == TF_FACE:
        a = acls[n, 1]
        b = acls[n, 2]
        f = aflt[n, 0]
        xn[n] = xn[a] + f * (xn[b] - xn[a])
        yn[n] = yn[a] + f * (yn[b] - yn[a])
    if c != TF_INTERIOR:
        aflt[n, 4] = xn[n] - x0[n] - off
        aflt[n, 5] = yn[n] - y0[n]


def tf_sweep_py(n, acls, aflt, scratch):
    """One Jacobi sweep of the mesh-displacement interpolation, interior node ``n``: the mean
    of its four edge neighbours into ``scratch[n]`` (all nodes, then :func:`tf_sweep_copy_py`)."""
    if acls[n, 0] != TF_INTERIOR:
        return
    sx = 0.0
    sy = 0.0
    for k in range(4):
        m = acls[n, 3 + k]
        sx += aflt[m, 4]
        sy += aflt[m, 5]
    scratch[n, 0] = 0.25 * sx
    scratch[n, 1] = 0.25 * sy


def tf_sweep_copy_py(n, acls, aflt, scratch):
    """Second half of a Jacobi sweep: interior node ``n`` takes its new displacement."""
    if acls[n, 0] == TF_INTERIOR:
        aflt[n, 4] = scratch[n, 0]
        aflt[n, 5] = scratch[n, 1]


def make_tf_interior(limit):
    """:func:`tf_interior_py` with its callees ``limit`` given (the CPU's compiled
    functions here, a GPU engine's device functions in its port)."""

    def tf_interior_py(n, x, y, xn, yn, x0, y0, acls, aflt, off, max_move):
        """last pass, interior node ``n``: its place in the tool frame plus the
        interpolated mesh displacement, the move limited to ``max_move`` of its local size."""
        if acls[n, 0] == TF_INTERIOR:
            tx, ty = limit(x[n], y[n], x0[n] + off + aflt[n, 4], y0[n] + aflt[n, 5],
                            max_move * aflt[n, 3])
            xn[n] = tx
            yn[n] = ty

    return tf_interior_py


# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
tf_place_py = make_tf_place(limit, off_tool)
tf_place = njit(cache=False, inline="always")(tf_place_py)
tf_face = njit(cache=True, inline="always")(tf_face_py)
tf_sweep = njit(cache=True, inline="always")(tf_sweep_py)
tf_sweep_copy = njit(cache=True, inline="always")(tf_sweep_copy_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
tf_interior_py = make_tf_interior(limit)
tf_interior = njit(cache=False, inline="always")(tf_interior_py)


@njit(parallel=True, cache=True)
def toolframe_targets(x, y, xn, yn, x0, y0, acls, aflt, off, max_move, tg, scratch):
    """New node positions ``xn``, ``yn`` (see
    :mod:`robobore.cutting.fe.ale.toolframe`). ``x0``, ``y0`` are the nodes' places in the tool
    frame at the start (the tool's edge centre then at x = its current x - ``off``);
    ``acls``/``aflt`` the classes, neighbours, face fractions, line directions, local sizes
    and the mesh displacement carried from pass to pass (``aflt[:, 4:6]``, updated);
    ``scratch`` (n, 2) work array. The passes (:func:`tf_place_py`, :func:`tf_face_py`,
    ``TF_SWEEPS`` x :func:`tf_sweep_py` + :func:`tf_sweep_copy_py`,
    :func:`tf_interior_py`) each read only what the previous ones wrote.
    """
    nn = x.shape[0]
    # 1. rigid nodes, surface chains and the chain ends on the outflow lines
    for n in prange(nn):
        tf_place(n, x, y, xn, yn, x0, y0, acls, aflt, off, max_move, tg)
    # 2. outflow faces between their (now placed) ends; the boundary values of the mesh
    # displacement
    for n in prange(nn):
        tf_face(n, xn, yn, x0, y0, acls, aflt, off)
    # 3. Jacobi sweeps of the interior
    for _sweep in range(TF_SWEEPS):
        for n in prange(nn):
            tf_sweep(n, acls, aflt, scratch)
        for n in prange(nn):
            tf_sweep_copy(n, acls, aflt, scratch)
    for n in prange(nn):
        tf_interior(n, x, y, xn, yn, x0, y0, acls, aflt, off, max_move)


@njit(parallel=True, cache=True)
def rezone(nodes, quads, qs, ale, rho_s, max_move, tg, t_room, off):
    """One tool-frame ALE pass: relocation + remap (see module docstring).

    The groups of :mod:`robobore.cutting.fe.engine.groups2d`: ``nodes`` (Nodes2), ``quads``
    (Quads2), ``qs`` the element state (N_QS, e), ``ale`` (Ale2); ``rho_s`` the mass-scaled
    density [kg/m^3], ``max_move`` the largest node move of a pass [m].
    ``ale.acls``, ``ale.aflt`` the node classes and data (:func:`toolframe_targets`),
    ``ale.x0``, ``ale.y0`` the nodes' places in the tool frame at the start, ``off`` the
    tool's x travel since the start [m], ``tg`` the tool geometry (tool edge centre x, y, rake
    and flank normals, edge radius); ``ale.snodes`` are the nodes whose velocity is remapped
    (all but the rigid ones). ``ale.bflag`` (n_elem, 4): flux type of each outline edge
    (BF_*): virgin material at ``t_room`` [K] flows in through BF_VIRGIN edges, material
    leaves through BF_VIRGIN and BF_OPEN edges (and comes back through BF_OPEN ones with the
    element's own state). ``ale.xn``, ``ale.yn`` (n_nodes,) and ``ale.buf`` (n_elem,
    N_RZ_FIELDS) are work arrays, ``ale.vbuf`` (n_nodes, 2) scratch for the velocity
    increments (all computed from the old velocities before any is applied). Returns the
    number of nodes moved.

    The passes are the scalar functions :func:`rz_flux_py`, :func:`rz_velocity_py`,
    :func:`rz_write_py` and :func:`rz_node_mass_py` (and the tool-frame ones), which the
    GPU engine runs in the same order (:mod:`robobore.cutting.fe.engine.gpu.backend2d`)."""
    # the prange bodies read flat locals, one bound per statement (engine.groups2d)
    x = nodes.x
    y = nodes.y
    vx = nodes.vx
    vy = nodes.vy
    mass = nodes.mass
    ptr = nodes.ptr
    nel = nodes.nel
    conn = quads.conn
    alive = quads.alive
    area0 = quads.area0
    enbr = ale.enbr
    bflag = ale.bflag
    snodes = ale.snodes
    x0 = ale.x0
    y0 = ale.y0
    acls = ale.acls
    aflt = ale.aflt
    xn = ale.xn
    yn = ale.yn
    buf = ale.buf
    vbuf = ale.vbuf
    nn = x.shape[0]
    ne = conn.shape[0]
    for n in prange(nn):
        xn[n] = x[n]
        yn[n] = y[n]
    # 1. new positions of movable nodes
    toolframe_targets(x, y, xn, yn, x0, y0, acls, aflt, off, max_move, tg, vbuf)
    # 2. element fluxes into buf (old geometry x, y -> new geometry xn, yn)
    old = (x, y)
    new = (xn, yn)
    fields = (qs, area0)
    for e in prange(ne):
        rz_flux(e, conn, alive, old, new, enbr, bflag, buf, fields, t_room)
    # 3. nodal velocity: first-order Taylor with the mean old gradient of adjacent elements
    moved = 0
    for k in prange(snodes.shape[0]):
        moved += rz_velocity(snodes[k], x, y, xn, yn, vx, vy, ptr, nel, conn, vbuf)
    for k in prange(snodes.shape[0]):
        n = snodes[k]
        vx[n] += vbuf[n, 0]
        vy[n] += vbuf[n, 1]
    # 4. write back element fields and positions, recompute nodal masses
    for e in prange(ne):
        rz_write(e, alive, buf, qs, area0)
    for n in prange(nn):
        x[n] = xn[n]
        y[n] = yn[n]
    for n in prange(nn):
        rz_node_mass(n, ptr, nel, area0, rho_s, mass)
    return moved


__all__ = [
    "TF_INTERIOR",
    "TF_RIGID",
    "TF_CHAIN",
    "TF_LINE",
    "TF_FACE",
    "TF_SWEEPS",
    "limit_py",
    "limit",
    "make_off_tool",
    "off_tool_py",
    "off_tool",
    "make_tf_place",
    "make_tf_interior",
    "tf_place_py",
    "tf_face_py",
    "tf_sweep_py",
    "tf_sweep_copy_py",
    "tf_interior_py",
    "tf_place",
    "tf_face",
    "tf_sweep",
    "tf_sweep_copy",
    "tf_interior",
    "toolframe_targets",
    "rezone",
]
