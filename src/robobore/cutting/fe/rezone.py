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
scaled density) is remapped conservatively and the lumped nodal masses recomputed.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

N_RZ_FIELDS = 11


def smoothing_stencil(mesh) -> tuple[np.ndarray, np.ndarray]:
    """Interior chip-layer nodes of a structured cutting mesh and their 4 neighbours.

    Returns ``nodes`` (k,) and ``nbr`` (k, 4) node indices.
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
            nbr.append((n - 1, n + 1, n - nx_nodes, n + nx_nodes))
    return np.array(nodes, dtype=np.int64), np.array(nbr, dtype=np.int64).reshape(-1, 4)


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


@njit(cache=True)
def _swept(ax0, ay0, bx0, by0, ax1, ay1, bx1, by1):
    """Area swept outward by edge a->b of a counter-clockwise element moving 0 -> 1."""
    s = (ax0 * by0 - bx0 * ay0) + (bx0 * by1 - bx1 * by0) + (bx1 * ay1 - ax1 * by1) \
        + (ax1 * ay0 - ax0 * ay1)
    return -0.5 * s


@njit(parallel=True, cache=True)
def rezone(x, y, vx, vy, mass, conn, alive, ptr, nel, enbr, snodes, snbr, xn, yn, buf,
           sdx, sdy, sdz, sdxy, pres, eps_p, temp, dmg, qhx, qhy, area0, rho_s, omega,
           max_move):
    """One smoothing + remap pass (see module docstring). ``xn``, ``yn`` (n_nodes,) and
    ``buf`` (n_elem, N_RZ_FIELDS) are work arrays. Returns the number of nodes moved."""
    nn = x.shape[0]
    ne = conn.shape[0]
    for n in prange(nn):
        xn[n] = x[n]
        yn[n] = y[n]
    # 1. new positions of movable nodes
    for k in prange(snodes.shape[0]):
        n = snodes[k]
        ok = True
        for q in range(ptr[n], ptr[n + 1]):
            if alive[nel[q]] != 1:
                ok = False
        if not ok:
            continue
        ax = 0.25 * (x[snbr[k, 0]] + x[snbr[k, 1]] + x[snbr[k, 2]] + x[snbr[k, 3]])
        ay = 0.25 * (y[snbr[k, 0]] + y[snbr[k, 1]] + y[snbr[k, 2]] + y[snbr[k, 3]])
        dx = omega * (ax - x[n])
        dy = omega * (ay - y[n])
        # limit by the local size (mean distance to the neighbours)
        h = 0.0
        for j in range(4):
            h += np.sqrt((x[snbr[k, j]] - x[n]) ** 2 + (y[snbr[k, j]] - y[n]) ** 2)
        h *= 0.25
        d = np.sqrt(dx * dx + dy * dy)
        if d > max_move * h:
            dx *= max_move * h / d
            dy *= max_move * h / d
        xn[n] = x[n] + dx
        yn[n] = y[n] + dy
    # 2. element fluxes into buf (old geometry x, y -> new geometry xn, yn)
    for e in prange(ne):
        for f in range(N_RZ_FIELDS):
            buf[e, f] = 0.0
        if alive[e] != 1:
            continue
        i1, i2, i3, i4 = conn[e, 0], conn[e, 1], conn[e, 2], conn[e, 3]
        a_old = 0.5 * ((x[i3] - x[i1]) * (y[i4] - y[i2]) + (x[i2] - x[i4]) * (y[i3] - y[i1]))
        a_new = 0.5 * ((xn[i3] - xn[i1]) * (yn[i4] - yn[i2])
                       + (xn[i2] - xn[i4]) * (yn[i3] - yn[i1]))
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
            u = np.int64(e)
            if sw > 0.0:
                nb = np.int64(enbr[e, kk])
                if nb >= 0 and alive[nb] == 1:
                    u = nb
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
    # 3. nodal velocity: first-order Taylor with the mean old gradient of adjacent elements
    moved = 0
    for k in range(snodes.shape[0]):
        n = snodes[k]
        dx = xn[n] - x[n]
        dy = yn[n] - y[n]
        if dx == 0.0 and dy == 0.0:
            continue
        moved += 1
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
            vx[n] += (gxx * dx + gxy * dy) / cnt
            vy[n] += (gyx * dx + gyy * dy) / cnt
    # 4. write back element fields and positions, recompute nodal masses
    for e in prange(ne):
        if alive[e] != 1:
            continue
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
    for n in prange(nn):
        x[n] = xn[n]
        y[n] = yn[n]
    for n in prange(nn):
        m = 0.0
        for q in range(ptr[n], ptr[n + 1]):
            m += 0.25 * rho_s * area0[nel[q]]
        mass[n] = m
    return moved
