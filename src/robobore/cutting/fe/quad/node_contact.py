"""The node update of the plane-strain engine: central-difference integration, tool contact
(penalty, Coulomb friction constant or read from a friction-velocity table), node-splitting
separation; the fixed-order contact-force total and its split by tool face.

``quad_node_py`` is a plain-Python scalar function that allocates nothing;
:func:`node_update` calls its ``njit`` version over all nodes and
:mod:`robobore.cutting.fe.engine.gpu.backend2d` compiles the same source for an NVIDIA GPU.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from robobore.cutting.fe.engine.layout import (
    P_CDAMP,
    P_GATE,
    P_MU,
    P_MUTAB_MU,
    P_MUTAB_N,
    P_MUTAB_V,
    P_NFX,
    P_NFY,
    P_NRX,
    P_NRY,
    P_PEN,
    P_R,
    P_SLIP_TAU,
    P_TAU,
    P_TCX,
    P_TCY,
)
from robobore.cutting.fe.physics.tool_contact import (
    contact_force,
    tool_face,
    tool_gap,
)


def make_friction_at(p_mu: int, p_mutab_n: int, p_mutab_v: int, p_mutab_mu: int, name: str):
    """The friction lookup ``friction_at(prm, speed)`` of an engine whose parameter vector
    holds the constant coefficient at ``p_mu`` and the table's size, velocities and
    coefficients from ``p_mutab_n``, ``p_mutab_v``, ``p_mutab_mu`` (the 2D engine's slots
    here, the 3D engine's in :mod:`robobore.cutting.fe.hex.scalar3d`), as a plain-Python
    function named ``name``; the slots are closed over (numba compiles them as constants).
    """

    def friction_at(prm, speed):
        """Coulomb coefficient at the sliding speed ``speed`` [m/s] (>= 0).

        ``prm[P_MUTAB_N]`` = 0: the constant ``prm[P_MU]``; otherwise the table in
        ``prm[P_MUTAB_V:]`` / ``prm[P_MUTAB_MU:]``, linear between its points and constant
        beyond its ends (as Abaqus' slip-rate-dependent friction tables).
        """
        n = int(prm[p_mutab_n])
        if n == 0:
            return prm[p_mu]
        if speed <= prm[p_mutab_v]:
            return prm[p_mutab_mu]
        for i in range(1, n):
            v1 = prm[p_mutab_v + i]
            if speed <= v1:
                v0 = prm[p_mutab_v + i - 1]
                m0 = prm[p_mutab_mu + i - 1]
                return m0 + (prm[p_mutab_mu + i] - m0) * (speed - v0) / (v1 - v0)
        return prm[p_mutab_mu + n - 1]

    friction_at.__name__ = friction_at.__qualname__ = name
    return friction_at


#: Coulomb coefficient at a sliding speed [m/s] on the 2D engine's slots
#: (:func:`make_friction_at`): the constant ``prm[P_MU]`` when ``prm[P_MUTAB_N]`` = 0, else the
#: table, linear between its points, constant beyond its ends
friction_at_py = make_friction_at(P_MU, P_MUTAB_N, P_MUTAB_V, P_MUTAB_MU, "friction_at_py")
friction_at = njit(cache=True, inline="always")(friction_at_py)


def make_quad_node(tool_gap, contact_force, friction_at):
    """:func:`quad_node_py` with its callees ``tool_gap``, ``contact_force``,
    ``friction_at`` given (the CPU's compiled functions here, a GPU engine's device
    functions in its port)"""

    def quad_node_py(n, x, y, vx, vy, mass, fixed, ptr, nel, ncorner, alive, area0, fex, fey,
                     cfx, cfy, fric, pen, ndead, ero_ke, nwork, tool_cx, tool_cy, tool_vx,
                     tool_vy, prm, dt, twin, tied, vslip):
        """Gather element forces on node ``n``, add tool contact, advance its velocity and position.

        One node of :func:`node_update` (scalar code, allocates nothing: compiled for the CPU as
        :data:`quad_node` and for a GPU in :mod:`robobore.cutting.fe.engine.gpu.backend2d`). Returns
        ``(fx, fy, touched)``: this node's contact force on the workpiece [N/m] (``cfx[n]``,
        ``cfy[n]``) and whether it touched the tool. Contact uses positions at step n and
        velocities at n-1/2; ``cfx``/``cfy`` receive the contact force on the node [N/m]; ``fric``
        (cumulative) the frictional dissipation and the contact damping's, ``pen`` the current
        penalty energy, ``nwork``
        (cumulative) the contact work on the node [J/m]. A node left without a live element is
        retired (velocity zeroed, its kinetic energy booked in ``ero_ke``).

        Node splitting: a node with ``twin[n] >= 0`` and ``tied[n]`` moves with its twin as one
        node (forces and masses of both, summed in a fixed order so that both copies stay
        bitwise identical; the contact force is shared half and half). The pair is released
        (``tied`` = 0) when it comes within ``prm[P_GATE]`` of the tool surface: the material
        separates where it meets the cutting edge.

        Friction: the constant ``prm[P_MU]``, or with a table (``prm[P_MUTAB_N]`` > 0) the
        table at the node's sliding speed relative to the tool, low-pass filtered with the time
        constant ``prm[P_SLIP_TAU]`` and kept in ``vslip[n]`` [m/s] (:func:`friction_at_py`).
        """
        r = prm[P_R]
        nrx, nry, nfx, nfy = prm[P_NRX], prm[P_NRY], prm[P_NFX], prm[P_NFY]
        tau, pf = prm[P_TAU], prm[P_PEN]
        gate = prm[P_GATE]
        cfx[n] = 0.0
        cfy[n] = 0.0
        pen[n] = 0.0
        if ndead[n]:
            return 0.0, 0.0, False
        tw = twin[n]
        pair = tw >= 0 and tied[n] != 0
        # node ids as int64 (the prange index is unsigned: mixing would give floats); a
        # tied pair is gathered in a fixed order so that both copies compute the same sums
        na = np.int64(n)
        nb = np.int64(-1)
        share = 1.0
        if pair:
            nb = max(na, tw)
            na = min(na, tw)
            share = 0.5
        fx = 0.0
        fy = 0.0
        nlive = 0
        asum = 0.0
        m = 0.0
        for j in range(2):
            nk = na if j == 0 else nb
            if nk < 0:
                continue
            m += mass[nk]
            for k in range(ptr[nk], ptr[nk + 1]):
                e = nel[k]
                if alive[e] == 1:
                    c = ncorner[k]
                    fx -= fex[e, c]
                    fy -= fey[e, c]
                    nlive += 1
                    asum += area0[e]
        if nlive == 0:
            ndead[n] = 1
            ero_ke[n] = 0.5 * mass[n] * (vx[n] * vx[n] + vy[n] * vy[n])
            vx[n] = 0.0
            vy[n] = 0.0
            return 0.0, 0.0, False
        if fixed[n]:
            vx[n] = 0.0
            vy[n] = 0.0
            return 0.0, 0.0, False
        gap, gnx, gny = tool_gap(x[n], y[n], tool_cx, tool_cy, nrx, nry, nfx, nfy, r)
        if pair and gap <= gate:
            tied[n] = 0
        fcx = 0.0
        fcy = 0.0
        ft = 0.0
        fd = 0.0
        vt0 = 0.0
        vn0 = 0.0
        if gap < 0.0:
            vrx = vx[n] - tool_vx
            vry = vy[n] - tool_vy
            trib = math.sqrt(asum / nlive)
            vt0 = -vrx * gny + vry * gnx
            mu = prm[P_MU]
            if prm[P_MUTAB_N] > 0.0:
                # the sliding speed, filtered over the time constant prm[P_SLIP_TAU]: a contact
                # node's velocity chatters from step to step, its mean is the material's sliding
                tau_s = prm[P_SLIP_TAU]
                a = dt / tau_s if tau_s > dt else 1.0  # tau_s <= dt: no filter
                vs = vslip[n] + a * (abs(vt0) - vslip[n])
                vslip[n] = vs
                mu = friction_at(prm, vs)
            fcx, fcy, fn, ft, fd = contact_force(gap, (gnx, gny), (vrx, vry), (fx, fy), m, trib,
                                                 dt, (mu, tau, pf, prm[P_CDAMP]))
            vn0 = vrx * gnx + vry * gny
            pen[n] = share * 0.5 * (fn - fd) * (-gap)
        cfx[n] = share * fcx
        cfy[n] = share * fcy
        touched = fcx != 0.0 or fcy != 0.0
        ox = vx[n]
        oy = vy[n]
        nvx = ox + dt * (fx + fcx) / m
        nvy = oy + dt * (fy + fcy) / m
        vx[n] = nvx
        vy[n] = nvy
        x[n] += dt * nvx
        y[n] += dt * nvy
        if gap < 0.0:
            nwork[n] += share * dt * (fcx * 0.5 * (ox + nvx) + fcy * 0.5 * (oy + nvy))
            vt1 = -(nvx - tool_vx) * gny + (nvy - tool_vy) * gnx
            fric[n] -= share * dt * ft * 0.5 * (vt0 + vt1)
            if fd != 0.0:  # contact damping: booked with the frictional dissipation
                vn1 = (nvx - tool_vx) * gnx + (nvy - tool_vy) * gny
                fric[n] -= share * dt * fd * 0.5 * (vn0 + vn1)
        return share * fcx, share * fcy, touched

    return quad_node_py


# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
quad_node_py = make_quad_node(tool_gap, contact_force, friction_at)
quad_node = njit(cache=False, inline="always")(quad_node_py)


@njit(parallel=True, cache=True)
def node_update(nodes, quads, out, contact, kin, prm, dt):
    """:func:`quad_node_py` over all nodes (parallel).

    The groups of :mod:`robobore.cutting.fe.engine.groups2d`: ``nodes`` (Nodes2), ``quads``
    (Quads2: ``alive``, ``area0`` read), ``out`` (QuadOut2: the element forces ``fex``,
    ``fey``), ``contact`` (Contact2); ``kin`` = (edge centre x, y [m], tool velocity x, y
    [m/s]), ``prm`` the parameter vector, ``dt`` the step [s].
    Returns the number of nodes in contact; their contact forces are in ``cfx``/``cfy``
    (summed in a fixed order by :func:`contact_total`).
    """
    # the prange body reads flat locals, one bound per statement (engine.groups2d)
    x = nodes.x
    y = nodes.y
    vx = nodes.vx
    vy = nodes.vy
    mass = nodes.mass
    fixed = nodes.fixed
    ptr = nodes.ptr
    nel = nodes.nel
    ncorner = nodes.ncorner
    alive = quads.alive
    area0 = quads.area0
    fex = out.fex
    fey = out.fey
    cfx = contact.cfx
    cfy = contact.cfy
    fric = contact.fric
    pen = contact.pen
    ndead = contact.ndead
    ero_ke = contact.ero_ke
    nwork = contact.nwork
    twin = contact.twin
    tied = contact.tied
    vslip = contact.vslip
    tool_cx, tool_cy, tool_vx, tool_vy = kin
    ncont = 0
    for n in prange(x.shape[0]):
        _fcx, _fcy, touched = quad_node(n, x, y, vx, vy, mass, fixed, ptr, nel, ncorner, alive,
                                        area0, fex, fey, cfx, cfy, fric, pen, ndead, ero_ke,
                                        nwork, tool_cx, tool_cy, tool_vx, tool_vy, prm, dt,
                                        twin, tied, vslip)
        if touched:
            ncont += 1
    return ncont


#: lanes of the fixed-order contact-force total (one GPU block of this many threads)
N_SUM_LANES = 256


def lane_sum_py(a, lane, lanes):
    """Sum of ``a[lane], a[lane + lanes], ...`` in index order (one lane of
    :func:`contact_total_py`)."""
    s = 0.0
    for n in range(lane, a.shape[0], lanes):
        s += a[n]
    return s


lane_sum = njit(cache=True, inline="always")(lane_sum_py)


@njit(cache=True)
def contact_total(cfx, cfy):
    """Total contact force on the workpiece [N/m] from the per-node forces, summed in a fixed
    order: ``N_SUM_LANES`` strided lane sums, then the lanes in order. The GPU engine sums
    the same way (one thread per lane), so both devices get the same bits whatever the
    thread count."""
    fx = 0.0
    fy = 0.0
    for lane in range(N_SUM_LANES):
        fx += lane_sum(cfx, lane, N_SUM_LANES)
        fy += lane_sum(cfy, lane, N_SUM_LANES)
    return fx, fy


def make_contact_split_node(tool_face):
    """:func:`contact_split_node_py` with its callees ``tool_face`` given (the CPU's
    compiled functions here, a GPU engine's device functions in its port)."""

    def contact_split_node_py(i, cfx, cfy, x, y, faces, out, o):
        """Node ``i``'s contact force on the tool added to its face's pair in ``out[o:o + 6]``
        = [Fx, Fy] of the rake face, the edge arc and the flank [N/m]. A node belongs to the
        face that gives its gap (:func:`robobore.cutting.fe.physics.tool_contact.tool_face_py`);
        ``faces`` = (edge centre x, y [m], rake normal x, y, flank normal x, y). Called in
        increasing node order by one thread on both devices (:func:`contact_split`, the GPU's
        block 0), so the sums have the same bits."""
        fx = cfx[i]
        fy = cfy[i]
        if fx == 0.0 and fy == 0.0:
            return
        cx, cy, nrx, nry, nfx, nfy = faces
        k = tool_face(x[i] - cx, y[i] - cy, nrx, nry, nfx, nfy)
        out[o + 2 * k] -= fx
        out[o + 2 * k + 1] -= fy

    return contact_split_node_py


def tool_geometry_py(prm):
    """The tool's edge centre x, y, rake and flank normals and edge radius from ``prm``: the
    tool geometry tuple of the ALE passes (:mod:`robobore.cutting.fe.ale.rezone`)."""
    return (prm[P_TCX], prm[P_TCY], prm[P_NRX], prm[P_NRY], prm[P_NFX], prm[P_NFY],
            prm[P_R])


# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
contact_split_node_py = make_contact_split_node(tool_face)
contact_split_node = njit(cache=False, inline="always")(contact_split_node_py)
tool_geometry = njit(cache=True, inline="always")(tool_geometry_py)


@njit(cache=True)
def contact_split(cfx, cfy, x, y, faces, out):
    """Contact force on the tool by face into ``out`` = [Fx, Fy] of the rake face, the edge
    arc and the flank [N/m] (serial, fixed order: :func:`contact_split_node_py`; ``faces`` as
    there)."""
    for j in range(6):
        out[j] = 0.0
    for i in range(cfx.shape[0]):
        contact_split_node(i, cfx, cfy, x, y, faces, out, 0)
