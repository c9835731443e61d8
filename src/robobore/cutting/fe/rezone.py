"""ALE-type rezoning of the chip: Laplacian node smoothing + first-order donor-cell remap.

A Lagrangian chip mesh shears without limit in the primary and secondary shear zones
(elements 10-20 times thinner than wide, stable step collapsing). Every ``interval`` steps
the interior nodes of the chip layer (not on the free surface, not on the chip underside
that slides on the rake, not next to an eroded element) are moved a fraction ``omega``
towards the average of their four structured-grid neighbours (Laplacian smoothing in index
space, Winslow-like). The element state is then transported through the moving element
edges by a conservative first-order donor-cell (upwind) remap: for each edge the area swept
by its motion carries the state of the element it sweeps into (Benson 1992, "Computational
methods in Lagrangian and Eulerian hydrocodes", CMAME 99, sec. 4.2). Nodal velocities are
remapped by a first-order Taylor expansion with the mean velocity gradient of the adjacent
elements. Node moves are limited to ``max_move`` of the local element size so the remap
Courant number stays below 1.

Remapped element fields: deviatoric stress, pressure, plastic strain, temperature, damage,
stored hourglass force; element mass (held as the reference area ``area0`` = mass /
scaled density) is remapped conservatively and the lumped nodal masses recomputed. Only
edges shared by two live elements carry a flux: what an edge on the outline (or next to an
eroded element) sweeps as its nodes slide along a curved surface is not mass that enters
or leaves the model, so mass is conserved exactly and the intensive fields are divided by
the area their fluxes account for (a uniform field stays uniform).

Two ways of choosing the new node positions share the remap:

* ``MODE_LAPLACE`` (``solver.rezone_interval``, structured uniform mesh): the chip interior
  is smoothed as above (:func:`smoothing_stencil`).
* ``MODE_ROWS`` (``solver.edge_ale_interval``, node splitting): the **ploughed layer** --
  the node rows within ``depth`` under the parting line, which pass under the cutting edge
  and which a Lagrangian mesh shears until the distortion erosion deletes them -- is made
  Eulerian in the cutting direction and Lagrangian in depth. Once a column's parting-line
  pair has been released (the material there has met the edge), its surface node slides
  along the surface (the polyline through it and its row neighbours) back towards its
  initial x, by at most ``max_move`` of the shorter row segment
  per pass; the machined surface (the top row) keeps its shape, the rows under it are
  spread evenly in depth between it and the layer's bottom row (which stays Lagrangian),
  and the material flows through the elements (:func:`row_stencil`, :func:`_row_move`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from robobore.cutting.fe.physics import tool_gap

N_RZ_FIELDS = 11
#: node relocation of a rezoning pass: Laplacian smoothing, sliding along node rows, or the
#: tool-frame ALE (every node back to its place in the tool's frame, see
#: :mod:`robobore.cutting.fe.toolframe`)
MODE_LAPLACE, MODE_ROWS, MODE_TOOLFRAME = 0, 1, 2
#: tool-frame node classes (``acls[:, 0]``): interior, rigid (inflow face, bottom), on a
#: surface chain (free or against the tool), chain end on an outflow line, on an outflow face
TF_INTERIOR, TF_RIGID, TF_CHAIN, TF_LINE, TF_FACE = 0, 1, 2, 3, 4
#: flux through an element edge on the outline (``bflag``): none, virgin material flowing
#: in (inflow face), open (outflow; a backflow brings the element's own state)
BF_CLOSED, BF_VIRGIN, BF_OPEN = 0, 1, 2
#: Jacobi sweeps of the mesh-displacement interpolation per tool-frame pass
TF_SWEEPS = 4


def smoothing_stencil(mesh) -> tuple[np.ndarray, np.ndarray]:
    """Interior chip-layer nodes of a structured cutting mesh and their 4 neighbours.

    Returns ``nodes`` (k,) and ``nbr`` (k, 6) node indices (the 4 neighbours, then -1, -1:
    the layout of :func:`row_stencil`).
    """
    conn = mesh.conn
    # structured grid sizes from the node coordinates of row 0
    xs0 = mesh.nodes[:, 0]
    ys0 = mesh.nodes[:, 1]
    ny_nodes = len(np.unique(ys0))
    nx_nodes = mesh.n_nodes // ny_nodes
    assert nx_nodes * ny_nodes == mesh.n_nodes
    del conn, xs0
    yrows = ys0.reshape(ny_nodes, nx_nodes)[:, 0]
    # chip underside row: top of the separation layer; surface row: top
    under = int(np.argmin(np.abs(yrows - mesh.layer_top)))
    top = ny_nodes - 1
    nodes = []
    nbr = []
    for j in range(under + 1, top):
        for i in range(1, nx_nodes - 1):
            n = j * nx_nodes + i
            nodes.append(n)
            nbr.append((n - 1, n + 1, n - nx_nodes, n + nx_nodes, -1, -1))
    return np.array(nodes, dtype=np.int64), np.array(nbr, dtype=np.int64).reshape(-1, 6)


def row_stencil(mesh, depth: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes of the ploughed layer of a node-splitting mesh for ``MODE_ROWS``.

    The node rows (equal initial y) from the parting line (its workpiece-side copies) down
    to, but not including, ``depth`` [m] below it; in each row, the nodes whose left and
    right neighbours (by initial x) are joined to them by element edges. Fixed nodes are
    left out. Returns ``nodes`` (k,) and ``nbr`` (k, 6) = (left, right, parting-line node
    of the same column, node of the same column at ``depth`` (-1: none, or the node is on
    the parting line), node above, node below in the column (-1: none)); a node moves only
    once its parting-line node is released.
    """
    if mesh.twin is None:
        raise ValueError("row_stencil needs a node-splitting mesh (twin)")
    xy = mesh.nodes
    y_p = mesh.layer_top
    tol = 1e-6 * mesh.element_size
    idx = np.arange(mesh.n_nodes)
    upper = (mesh.twin >= 0) & (mesh.twin < idx)
    below = (xy[:, 1] <= y_p + tol) & (xy[:, 1] > y_p - depth - tol)
    cand = np.where(~upper & below)[0]
    edges: set[tuple[int, int]] = set()
    for el in mesh.conn:
        for k in range(4):
            a, b = int(el[k]), int(el[(k + 1) % 4])
            edges.add((a, b) if a < b else (b, a))

    def joined(a: int, b: int) -> bool:
        return (min(a, b), max(a, b)) in edges

    rkey = np.round((y_p - xy[cand, 1]) / tol).astype(np.int64)
    xkey = np.round(xy[cand, 0] / tol).astype(np.int64)
    at = {(int(r), int(c)): int(n) for r, c, n in zip(rkey, xkey, cand, strict=True)}
    rows = np.unique(rkey)
    bottom_key = int(np.round(depth / tol))
    nodes: list[int] = []
    nbr: list[tuple[int, int, int, int, int, int]] = []
    for j, key in enumerate(rows):
        if key >= bottom_key:
            break
        row = cand[rkey == key]
        row = row[np.argsort(xy[row, 0])]
        for i in range(1, row.size - 1):
            n, lft, rgt = int(row[i]), int(row[i - 1]), int(row[i + 1])
            if mesh.fixed[n] or not (joined(lft, n) and joined(n, rgt)):
                continue
            c = int(np.round(xy[n, 0] / tol))
            pc = at.get((int(rows[0]), c), -1)
            if pc < 0:
                continue
            up = at.get((int(rows[j - 1]), c), -1) if j > 0 else -1
            dn = at.get((int(rows[j + 1]), c), -1) if j + 1 < rows.size else -1
            bt = at.get((bottom_key, c), -1) if j > 0 else -1
            if up >= 0 and not joined(up, n):
                up = -1
            if dn >= 0 and not joined(n, dn):
                dn = -1
            if bt >= 0 and (up < 0 or dn < 0):
                bt = -1
            nodes.append(n)
            nbr.append((lft, rgt, pc, bt, up, dn))
    return np.array(nodes, dtype=np.int64), np.array(nbr, dtype=np.int64).reshape(-1, 6)


def edge_neighbours(conn: np.ndarray) -> np.ndarray:
    """(n_elem, 4): element across edge k (nodes k -> k+1), -1 on the boundary."""
    ne = conn.shape[0]
    out = -np.ones((ne, 4), dtype=np.int64)
    seen: dict[tuple[int, int], tuple[int, int]] = {}
    for e in range(ne):
        for k in range(4):
            a, b = int(conn[e, k]), int(conn[e, (k + 1) % 4])
            key = (a, b) if a < b else (b, a)
            if key in seen:
                e2, k2 = seen.pop(key)
                out[e, k] = e2
                out[e2, k2] = e
            else:
                seen[key] = (e, k)
    return out


def swept_py(ax0, ay0, bx0, by0, ax1, ay1, bx1, by1):
    """Area swept outward by edge a->b of a counter-clockwise element moving 0 -> 1."""
    s = (ax0 * by0 - bx0 * ay0) + (bx0 * by1 - bx1 * by0) + (bx1 * ay1 - ax1 * by1) \
        + (ax1 * ay0 - ax0 * ay1)
    return -0.5 * s


def limit_py(px, py, tx, ty, lim):
    """``(tx, ty)`` moved back towards ``(px, py)`` so that the move is at most ``lim``."""
    dx = tx - px
    dy = ty - py
    d = math.sqrt(dx * dx + dy * dy)
    if d > lim:
        return px + dx * lim / d, py + dy * lim / d
    return tx, ty


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


_swept = njit(cache=True)(swept_py)
_limit = njit(cache=True, inline="always")(limit_py)
_off_tool = njit(cache=True, inline="always")(off_tool_py)


@njit(cache=True, inline="always")
def _row_move(k, n, x, y, xn, yn, snbr, tied, x0, y0, max_move, tg):
    """MODE_ROWS: move node ``n`` of the ploughed layer back towards its column.

    A node of the machined surface (the parting-line row) slides along the surface (its row
    line) towards its initial x. A node under it that has a column node at the layer's
    depth moves towards its initial x and towards its initial share of the column between
    the surface node and that bottom node (the layer's compression under the edge is spread
    over all its rows instead of crushing the top one); without one it slides along its
    row. Each move is at most ``max_move`` of the shortest distance to the node's row and
    column neighbours.

    A surface node that the slide would put into the tool, or deeper into it than it was --
    the chord between two surface nodes wrapped round the edge lies inside the tool -- is
    put back along the tool normal to the tool surface (or to its old penetration), so the
    pass adds no penalty energy. ``tg`` = tool edge centre x, y, rake and flank normals,
    edge radius.
    """
    lft, rgt, pc, bt = snbr[k, 0], snbr[k, 1], snbr[k, 2], snbr[k, 3]
    if tied[pc] != 0:
        return
    hl = np.sqrt((x[lft] - x[n]) ** 2 + (y[lft] - y[n]) ** 2)
    hr = np.sqrt((x[rgt] - x[n]) ** 2 + (y[rgt] - y[n]) ** 2)
    if bt >= 0:
        up, dn = snbr[k, 4], snbr[k, 5]
        hv = min(abs(y[up] - y[n]), abs(y[dn] - y[n]))
        f = (y0[pc] - y0[n]) / (y0[pc] - y0[bt])
        xn[n], yn[n] = _limit(x[n], y[n], x0[n], y[pc] + f * (y[bt] - y[pc]),
                              max_move * min(min(hl, hr), hv))
        return
    lim = max_move * min(hl, hr)
    dx = x0[n] - x[n]
    if dx > lim:
        dx = lim
    elif dx < -lim:
        dx = -lim
    if dx > 0.0:
        run = x[rgt] - x[n]
        if run <= 0.1 * hr:  # row folded back or too steep: leave the node
            return
        dy = dx * (y[rgt] - y[n]) / run
    elif dx < 0.0:
        run = x[lft] - x[n]
        if run >= -0.1 * hl:
            return
        dy = dx * (y[lft] - y[n]) / run
    else:
        return
    px = x[n] + dx
    py = y[n] + dy
    if pc == n:
        px, py = _off_tool(x[n], y[n], px, py, tg)
    xn[n] = px
    yn[n] = py


@njit(parallel=True, cache=True)
def _relocate(x, y, xn, yn, alive, ptr, nel, snodes, snbr, omega, max_move, mode, tied, x0,
              y0, tg):
    """MODE_LAPLACE / MODE_ROWS: new positions of the nodes ``snodes`` whose elements are all
    alive (Laplacian smoothing with relaxation ``omega``, or :func:`_row_move`)."""
    for k in prange(snodes.shape[0]):
        n = snodes[k]
        ok = True
        for q in range(ptr[n], ptr[n + 1]):
            if alive[nel[q]] != 1:
                ok = False
        if not ok:
            continue
        if mode == MODE_ROWS:
            _row_move(k, n, x, y, xn, yn, snbr, tied, x0, y0, max_move, tg)
            continue
        ax = 0.25 * (x[snbr[k, 0]] + x[snbr[k, 1]] + x[snbr[k, 2]] + x[snbr[k, 3]])
        ay = 0.25 * (y[snbr[k, 0]] + y[snbr[k, 1]] + y[snbr[k, 2]] + y[snbr[k, 3]])
        # limit by the local size (mean distance to the neighbours)
        h = 0.0
        for j in range(4):
            h += np.sqrt((x[snbr[k, j]] - x[n]) ** 2 + (y[snbr[k, j]] - y[n]) ** 2)
        xn[n], yn[n] = _limit(x[n], y[n], x[n] + omega * (ax - x[n]),
                              y[n] + omega * (ay - y[n]), max_move * 0.25 * h)


# -- the tool-frame and remap passes as scalar functions (one node or element each), called
# -- by the CPU's prange loops below and by the GPU kernels (robobore.cutting.fe.gpu2d)

def tf_place_py(n, x, y, xn, yn, x0, y0, acls, aflt, off, max_move, tg):
    """MODE_TOOLFRAME, first pass, node ``n``: the new place of a rigid node, a surface-chain
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
        tx, ty = _limit(px, py, tx, ty, max_move * min(la, lb))
        tx, ty = _off_tool(px, py, tx, ty, tg)
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
        tx, ty = _limit(px, py, tx, ty, max_move * le)
        tx, ty = _off_tool(px, py, tx, ty, tg)
        xn[n] = tx
        yn[n] = ty


def tf_face_py(n, xn, yn, x0, y0, acls, aflt, off):
    """MODE_TOOLFRAME, second pass, node ``n`` (after :func:`tf_place_py` of every node):
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


def tf_interior_py(n, x, y, xn, yn, x0, y0, acls, aflt, off, max_move):
    """MODE_TOOLFRAME, last pass, interior node ``n``: its place in the tool frame plus the
    interpolated mesh displacement, the move limited to ``max_move`` of its local size."""
    if acls[n, 0] == TF_INTERIOR:
        tx, ty = _limit(x[n], y[n], x0[n] + off + aflt[n, 4], y0[n] + aflt[n, 5],
                        max_move * aflt[n, 3])
        xn[n] = tx
        yn[n] = ty


def rz_flux_py(e, conn, x, y, xn, yn, alive, enbr, bflag, buf, sdx, sdy, sdz, sdxy, pres,
               eps_p, temp, dmg, qhx, qhy, area0, t_room):
    """Donor-cell remap of element ``e`` (old geometry ``x``, ``y`` -> new ``xn``, ``yn``):
    its new intensive fields and reference area into ``buf[e]`` (see :func:`rezone`).
    Reads the old state only, so all elements can run at once."""
    for f in range(N_RZ_FIELDS):
        buf[e, f] = 0.0
    if alive[e] != 1:
        return
    i1, i2, i3, i4 = conn[e, 0], conn[e, 1], conn[e, 2], conn[e, 3]
    a_old = 0.5 * ((x[i3] - x[i1]) * (y[i4] - y[i2]) + (x[i2] - x[i4]) * (y[i3] - y[i1]))
    # the area after the pass that the fluxes account for: the old area plus the areas
    # swept by the edges shared with live elements (an edge on the outline or next to
    # an eroded element carries no flux, so a boundary node that slides along a
    # curved surface neither creates nor destroys mass)
    a_new = a_old
    c0 = sdx[e] * a_old
    c1 = sdy[e] * a_old
    c2 = sdz[e] * a_old
    c3 = sdxy[e] * a_old
    c4 = pres[e] * a_old
    c5 = eps_p[e] * a_old
    c6 = temp[e] * a_old
    c7 = dmg[e] * a_old
    c8 = qhx[e] * a_old
    c9 = qhy[e] * a_old
    c10 = area0[e]
    for kk in range(4):
        a = conn[e, kk]
        b = conn[e, (kk + 1) % 4]
        sw = _swept(x[a], y[a], x[b], y[b], xn[a], yn[a], xn[b], yn[b])
        if sw == 0.0:
            continue
        nb = np.int64(enbr[e, kk])
        u = nb
        if nb < 0:
            # an outline edge carries a flux only where bflag opens it
            if bflag.shape[0] == 0 or bflag[e, kk] == BF_CLOSED:
                continue
            a_new += sw
            if sw > 0.0 and bflag[e, kk] == BF_VIRGIN:
                c6 += sw * t_room  # virgin: no stress, strain, damage; A0 = A
                c10 += sw
                continue
            u = np.int64(e)  # outflow (or backflow through an open face): own state
        elif alive[nb] != 1:
            continue
        else:
            a_new += sw
            if sw <= 0.0:
                u = np.int64(e)
        iu1, iu2, iu3, iu4 = conn[u, 0], conn[u, 1], conn[u, 2], conn[u, 3]
        au = 0.5 * ((x[iu3] - x[iu1]) * (y[iu4] - y[iu2])
                    + (x[iu2] - x[iu4]) * (y[iu3] - y[iu1]))
        c0 += sw * sdx[u]
        c1 += sw * sdy[u]
        c2 += sw * sdz[u]
        c3 += sw * sdxy[u]
        c4 += sw * pres[u]
        c5 += sw * eps_p[u]
        c6 += sw * temp[u]
        c7 += sw * dmg[u]
        c8 += sw * qhx[u]
        c9 += sw * qhy[u]
        c10 += sw * area0[u] / au
    inv = 1.0 / a_new
    buf[e, 0] = c0 * inv
    buf[e, 1] = c1 * inv
    buf[e, 2] = c2 * inv
    buf[e, 3] = c3 * inv
    buf[e, 4] = c4 * inv
    buf[e, 5] = c5 * inv
    buf[e, 6] = c6 * inv
    buf[e, 7] = c7 * inv
    buf[e, 8] = c8 * inv
    buf[e, 9] = c9 * inv
    buf[e, 10] = c10


def rz_velocity_py(n, x, y, xn, yn, vx, vy, ptr, nel, conn, vbuf):
    """Velocity increment of moved node ``n`` into ``vbuf[n]``: first-order Taylor with the
    mean old velocity gradient of its elements (read from the old state only). Returns 1
    when the node moves, else 0."""
    vbuf[n, 0] = 0.0
    vbuf[n, 1] = 0.0
    dx = xn[n] - x[n]
    dy = yn[n] - y[n]
    if dx == 0.0 and dy == 0.0:
        return 0
    gxx = 0.0
    gxy = 0.0
    gyx = 0.0
    gyy = 0.0
    cnt = 0
    for q in range(ptr[n], ptr[n + 1]):
        e = nel[q]
        i1, i2, i3, i4 = conn[e, 0], conn[e, 1], conn[e, 2], conn[e, 3]
        A = 0.5 * ((x[i3] - x[i1]) * (y[i4] - y[i2]) + (x[i2] - x[i4]) * (y[i3] - y[i1]))
        inv2a = 0.5 / A
        bx1 = (y[i2] - y[i4]) * inv2a
        bx2 = (y[i3] - y[i1]) * inv2a
        bx3 = (y[i4] - y[i2]) * inv2a
        bx4 = (y[i1] - y[i3]) * inv2a
        by1 = (x[i4] - x[i2]) * inv2a
        by2 = (x[i1] - x[i3]) * inv2a
        by3 = (x[i2] - x[i4]) * inv2a
        by4 = (x[i3] - x[i1]) * inv2a
        gxx += vx[i1] * bx1 + vx[i2] * bx2 + vx[i3] * bx3 + vx[i4] * bx4
        gxy += vx[i1] * by1 + vx[i2] * by2 + vx[i3] * by3 + vx[i4] * by4
        gyx += vy[i1] * bx1 + vy[i2] * bx2 + vy[i3] * bx3 + vy[i4] * bx4
        gyy += vy[i1] * by1 + vy[i2] * by2 + vy[i3] * by3 + vy[i4] * by4
        cnt += 1
    if cnt > 0:
        vbuf[n, 0] = (gxx * dx + gxy * dy) / cnt
        vbuf[n, 1] = (gyx * dx + gyy * dy) / cnt
    return 1


def rz_write_py(e, alive, buf, sdx, sdy, sdz, sdxy, pres, eps_p, temp, dmg, qhx, qhy, area0):
    """Live element ``e`` takes its remapped fields from ``buf[e]``."""
    if alive[e] != 1:
        return
    sdx[e] = buf[e, 0]
    sdy[e] = buf[e, 1]
    sdz[e] = buf[e, 2]
    sdxy[e] = buf[e, 3]
    pres[e] = buf[e, 4]
    eps_p[e] = buf[e, 5]
    temp[e] = buf[e, 6]
    dmg[e] = buf[e, 7]
    qhx[e] = buf[e, 8]
    qhy[e] = buf[e, 9]
    area0[e] = buf[e, 10]


def rz_node_mass_py(n, ptr, nel, area0, rho_s, mass):
    """Lumped mass of node ``n`` from its elements' (remapped) reference areas."""
    m = 0.0
    for q in range(ptr[n], ptr[n + 1]):
        m += 0.25 * rho_s * area0[nel[q]]
    mass[n] = m


tf_place = njit(cache=True, inline="always")(tf_place_py)
tf_face = njit(cache=True, inline="always")(tf_face_py)
tf_sweep = njit(cache=True, inline="always")(tf_sweep_py)
tf_sweep_copy = njit(cache=True, inline="always")(tf_sweep_copy_py)
tf_interior = njit(cache=True, inline="always")(tf_interior_py)
rz_flux = njit(cache=True, inline="always")(rz_flux_py)
rz_velocity = njit(cache=True, inline="always")(rz_velocity_py)
rz_write = njit(cache=True, inline="always")(rz_write_py)
rz_node_mass = njit(cache=True, inline="always")(rz_node_mass_py)


@njit(parallel=True, cache=True)
def toolframe_targets(x, y, xn, yn, x0, y0, acls, aflt, off, max_move, tg, scratch):
    """MODE_TOOLFRAME: new node positions ``xn``, ``yn`` (see
    :mod:`robobore.cutting.fe.toolframe`). ``x0``, ``y0`` are the nodes' places in the tool
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
def rezone(x, y, vx, vy, mass, conn, alive, ptr, nel, enbr, snodes, snbr, xn, yn, buf,
           sdx, sdy, sdz, sdxy, pres, eps_p, temp, dmg, qhx, qhy, area0, rho_s, omega,
           max_move, mode, tied, x0, y0, vbuf, tg, acls, aflt, bflag, t_room, off):
    """One relocation + remap pass (see module docstring). ``mode``: MODE_LAPLACE (``omega``
    the relaxation) or MODE_ROWS (``tied``, ``x0``, ``y0``: pair state and initial
    positions of the nodes).
    ``xn``, ``yn`` (n_nodes,) and ``buf`` (n_elem, N_RZ_FIELDS) are work arrays. Returns
    the number of nodes moved. ``vbuf`` (n_nodes, 2) is scratch for the velocity
    increments (all computed from the old velocities before any is applied); ``tg`` the
    tool geometry for MODE_ROWS and MODE_TOOLFRAME (see :func:`_row_move`).

    MODE_TOOLFRAME (:func:`toolframe_targets`): ``acls``, ``aflt`` the node classes and data,
    ``off`` the tool's x travel since the start [m]; ``snodes`` are the nodes whose velocity
    is remapped (all but the rigid ones). ``bflag`` (n_elem, 4), any mode with
    ``bflag.shape[0] > 0``: flux type of each outline edge (BF_*): virgin material at
    ``t_room`` [K] flows in through BF_VIRGIN edges, material leaves through BF_VIRGIN and
    BF_OPEN edges (and comes back through BF_OPEN ones with the element's own state).

    The passes are the scalar functions :func:`rz_flux_py`, :func:`rz_velocity_py`,
    :func:`rz_write_py` and :func:`rz_node_mass_py` (and the tool-frame ones), which the
    GPU engine runs in the same order (:mod:`robobore.cutting.fe.gpu2d`)."""
    nn = x.shape[0]
    ne = conn.shape[0]
    for n in prange(nn):
        xn[n] = x[n]
        yn[n] = y[n]
    # 1. new positions of movable nodes
    if mode == MODE_TOOLFRAME:
        toolframe_targets(x, y, xn, yn, x0, y0, acls, aflt, off, max_move, tg, vbuf)
    else:
        _relocate(x, y, xn, yn, alive, ptr, nel, snodes, snbr, omega, max_move, mode, tied,
                  x0, y0, tg)
    # 2. element fluxes into buf (old geometry x, y -> new geometry xn, yn)
    for e in prange(ne):
        rz_flux(e, conn, x, y, xn, yn, alive, enbr, bflag, buf, sdx, sdy, sdz, sdxy, pres,
                eps_p, temp, dmg, qhx, qhy, area0, t_room)
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
        rz_write(e, alive, buf, sdx, sdy, sdz, sdxy, pres, eps_p, temp, dmg, qhx, qhy, area0)
    for n in prange(nn):
        x[n] = xn[n]
        y[n] = yn[n]
    for n in prange(nn):
        rz_node_mass(n, ptr, nel, area0, rho_s, mass)
    return moved
