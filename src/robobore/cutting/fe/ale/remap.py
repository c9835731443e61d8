"""The donor-cell remap of the ALE pass (:func:`robobore.cutting.fe.ale.rezone.rezone`).

First-order conservative (upwind) transport of the element state through the moving element
edges: for each edge the area swept by its motion carries the state of the element it sweeps
into (Benson 1992, "Computational methods in Lagrangian and Eulerian hydrocodes", CMAME 99,
sec. 4.2); nodal velocities by a first-order Taylor expansion with the mean velocity gradient
of the adjacent elements; element mass (the reference area ``area0``) remapped conservatively
and the lumped nodal masses recomputed. Only edges shared by two live elements carry a flux,
except the outline edges flagged in ``bflag`` (``BF_*``: inflow of virgin material, open
outflow).

The passes are plain-Python scalar functions (``rz_flux_py``, ``rz_velocity_py``,
``rz_write_py``, ``rz_node_mass_py``) that the CPU pass calls as ``njit`` functions and
:mod:`robobore.cutting.fe.engine.gpu.backend2d` compiles for an NVIDIA GPU.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from robobore.cutting.fe.engine.groups2d import (
    QS_DMG,
    QS_EPS_P,
    QS_FIELDS,
    QS_PRES,
    QS_QHX,
    QS_QHY,
    QS_SDX,
    QS_SDXY,
    QS_SDY,
    QS_SDZ,
    QS_TEMP,
)

#: the element fields the remap transports, in the order of its work array's columns
#: (``buf[:, k]``): the rows of the element state (``engine.groups2d.QS_FIELDS``), then the
#: reference area
RZ_FIELDS = QS_FIELDS + ("area0",)
N_RZ_FIELDS = len(RZ_FIELDS)
#: flux through an element edge on the outline (``bflag``): none, virgin material flowing
#: in (inflow face), open (outflow; a backflow brings the element's own state)
BF_CLOSED, BF_VIRGIN, BF_OPEN = 0, 1, 2


def swept_py(ax0, ay0, bx0, by0, ax1, ay1, bx1, by1):
    """Area swept outward by edge a->b of a counter-clockwise element moving 0 -> 1."""
    s = (ax0 * by0 - bx0 * ay0) + (bx0 * by1 - bx1 * by0) + (bx1 * ay1 - ax1 * by1) \
        + (ax1 * ay0 - ax0 * ay1)
    return -0.5 * s


swept = njit(cache=True)(swept_py)


def make_rz_flux(swept):
    """:func:`rz_flux_py` with its callees ``swept`` given (the CPU's compiled functions
    here, a GPU engine's device functions in its port)."""

    def rz_flux_py(e, conn, alive, old, new, enbr, bflag, buf, fields, t_room):
        """Donor-cell remap of element ``e`` (old geometry ``old`` = ``(x, y)`` -> new
        ``new`` = ``(xn, yn)``): its new intensive fields and reference area into ``buf[e]``
        (see :func:`rezone`). ``fields`` = ``(qs, area0)`` the element state (N_QS, e) and
        the reference areas (:data:`RZ_FIELDS`, the order of ``buf``'s columns). Reads the
        old state only, so all elements can run at once; writes ``buf`` only (flat: a
        ``prange`` body's writes through a tuple are dropped,
        :mod:`robobore.cutting.fe.engine.groups2d`)."""
        x, y = old
        xn, yn = new
        qs, area0 = fields
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
        c0 = qs[QS_SDX, e] * a_old
        c1 = qs[QS_SDY, e] * a_old
        c2 = qs[QS_SDZ, e] * a_old
        c3 = qs[QS_SDXY, e] * a_old
        c4 = qs[QS_PRES, e] * a_old
        c5 = qs[QS_EPS_P, e] * a_old
        c6 = qs[QS_TEMP, e] * a_old
        c7 = qs[QS_DMG, e] * a_old
        c8 = qs[QS_QHX, e] * a_old
        c9 = qs[QS_QHY, e] * a_old
        c10 = area0[e]
        for kk in range(4):
            a = conn[e, kk]
            b = conn[e, (kk + 1) % 4]
            sw = swept(x[a], y[a], x[b], y[b], xn[a], yn[a], xn[b], yn[b])
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
            c0 += sw * qs[QS_SDX, u]
            c1 += sw * qs[QS_SDY, u]
            c2 += sw * qs[QS_SDZ, u]
            c3 += sw * qs[QS_SDXY, u]
            c4 += sw * qs[QS_PRES, u]
            c5 += sw * qs[QS_EPS_P, u]
            c6 += sw * qs[QS_TEMP, u]
            c7 += sw * qs[QS_DMG, u]
            c8 += sw * qs[QS_QHX, u]
            c9 += sw * qs[QS_QHY, u]
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

    return rz_flux_py


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


def rz_write_py(e, alive, buf, qs, area0):
    """Live element ``e`` takes its remapped fields from ``buf[e]``: the element state ``qs``
    (N_QS, e) and the reference area ``area0`` (e,) [m^2]."""
    if alive[e] != 1:
        return
    qs[QS_SDX, e] = buf[e, 0]
    qs[QS_SDY, e] = buf[e, 1]
    qs[QS_SDZ, e] = buf[e, 2]
    qs[QS_SDXY, e] = buf[e, 3]
    qs[QS_PRES, e] = buf[e, 4]
    qs[QS_EPS_P, e] = buf[e, 5]
    qs[QS_TEMP, e] = buf[e, 6]
    qs[QS_DMG, e] = buf[e, 7]
    qs[QS_QHX, e] = buf[e, 8]
    qs[QS_QHY, e] = buf[e, 9]
    area0[e] = buf[e, 10]


def rz_node_mass_py(n, ptr, nel, area0, rho_s, mass):
    """Lumped mass of node ``n`` from its elements' (remapped) reference areas."""
    m = 0.0
    for q in range(ptr[n], ptr[n + 1]):
        m += 0.25 * rho_s * area0[nel[q]]
    mass[n] = m


# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
rz_flux_py = make_rz_flux(swept)
rz_flux = njit(cache=False, inline="always")(rz_flux_py)
rz_velocity = njit(cache=True, inline="always")(rz_velocity_py)
rz_write = njit(cache=True, inline="always")(rz_write_py)
rz_node_mass = njit(cache=True, inline="always")(rz_node_mass_py)
