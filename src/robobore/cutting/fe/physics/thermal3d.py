"""Heat conduction of the 3D engine: the 2D engine's thermal model on hexahedra.

The same model as the 2D engine (:func:`robobore.cutting.fe.physics.thermal2d.conduct`,
:func:`~robobore.cutting.fe.physics.thermal2d.tool_heat`), written for hexahedra in the same
device-ready style (``_py`` scalar functions, bound to ``njit`` here and to
``numba.cuda.jit(device=True)`` in :mod:`robobore.cutting.fe.engine.gpu.backend3d`):

* **Conduction between elements** (finite volumes, explicit): element temperatures are cell
  values; across each face shared by two live elements flows ``G (T_nb - T_e)`` with the
  two-point conductance ``G = k A_face / d_centroids * dt_th`` [J/K], ``A_face`` and the
  centroids on the current (deformed) mesh. ``G`` is capped at a sixth of the smaller of the
  two heat capacities ``rho cp V0`` (six faces: the new temperature is a convex combination of
  the old ones for any element shape and any ``dt_th``). The cap and the face area are
  symmetric, so heat is conserved exactly. Free surfaces, eroded elements and the insert are
  adiabatic here; the insert exchanges heat through the next item.
* **Thermal contact with the insert**: a node takes ``eta`` of the frictional dissipation
  booked on it since the last pass (the rest heats the insert), and a node in contact
  exchanges ``h A_n (T_tool - T_n) dt_th`` with the insert, a heat sink at ``T_tool``:
  ``T_n`` is the volume-weighted mean temperature of the node's live elements, ``A_n`` its
  share of the free faces round it that touch the insert (a face with k of its four nodes in
  contact touches over (k - 2) / 2 of its area -- none along an edge, half as a triangle, all
  of it with four -- shared by those k nodes). Capped at a quarter of the heat
  capacity of the node's elements (as in 2D). The node's heat goes into its elements in
  proportion to their volumes.
* **Node splitting**: a face on the parting surface joins two elements that share no nodes
  (its nodes are doubled); heat crosses it while all four of its nodes are still tied, as in
  2D (:func:`robobore.cutting.fe.physics.thermal2d.parting_edge_py`).

Heat capacities use the initial volume ``V0`` and the material's true density (mass scaling
scales the inertia, not the heat capacity); plastic flow is isochoric, so ``V`` stays within
the elastic strain of ``V0``.

Neighbour table ``enbr`` (e, 6) int64, face ``f`` of :data:`HEX_FACES`: the element across
the face, ``-1`` none (free surface), ``-(nb + 2)`` element ``nb`` across a parting face of
node splitting (:func:`face_neighbours`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

__all__ = ["HEX_FACES", "face_neighbours", "hex_face_corner_py", "conduct3", "tool_heat3"]

#: the corners of each face of a hexahedron in VTK order, in cyclic order round the face:
#: xi = -1, xi = +1, eta = -1, eta = +1, zeta = -1, zeta = +1
HEX_FACES = np.array([(0, 3, 7, 4), (1, 2, 6, 5), (0, 1, 5, 4), (3, 2, 6, 7), (0, 1, 2, 3),
                      (4, 5, 6, 7)], np.int64)
#: :data:`HEX_FACES` packed in base 8 (corner j of face f = digit 3 - j), for device code
_FACE_CODE = tuple(int(sum(int(c) << (3 * (3 - j)) for j, c in enumerate(f))) for f in HEX_FACES)
_F0, _F1, _F2, _F3, _F4, _F5 = _FACE_CODE


def hex_face_corner_py(f, j):
    """Corner (0-7) number ``j`` (0-3) of face ``f`` (0-5) of :data:`HEX_FACES`."""
    if f == 0:
        code = _F0
    elif f == 1:
        code = _F1
    elif f == 2:
        code = _F2
    elif f == 3:
        code = _F3
    elif f == 4:
        code = _F4
    else:
        code = _F5
    return (code >> (3 * (3 - j))) & 7


def make_face_area3(hex_face_corner):
    """:func:`face_area3_py` with its callees ``hex_face_corner`` given (the CPU's compiled
    functions here, a GPU engine's device functions in its port)."""

    def face_area3_py(e, f, conn, x, y, z):
        """Area of face ``f`` of hexahedron ``e`` [m^2]: half the norm of the cross product of its
        diagonals (exact for a plane quadrilateral; the same bits from either side of the face)."""
        a = conn[e, hex_face_corner(f, 0)]
        b = conn[e, hex_face_corner(f, 1)]
        c = conn[e, hex_face_corner(f, 2)]
        d = conn[e, hex_face_corner(f, 3)]
        p1 = x[c] - x[a]
        p2 = y[c] - y[a]
        p3 = z[c] - z[a]
        q1 = x[d] - x[b]
        q2 = y[d] - y[b]
        q3 = z[d] - z[b]
        r1 = p2 * q3 - p3 * q2
        r2 = p3 * q1 - p1 * q3
        r3 = p1 * q2 - p2 * q1
        return 0.5 * math.sqrt(r1 * r1 + r2 * r2 + r3 * r3)

    return face_area3_py


def make_face_tied3(hex_face_corner):
    """:func:`face_tied3_py` with its callees ``hex_face_corner`` given (the CPU's compiled
    functions here, a GPU engine's device functions in its port)."""

    def face_tied3_py(e, f, conn, pairs):
        """True while every node of face ``f`` of element ``e`` is shared or still tied to its
        partner (node splitting: a parting face conducts until its nodes part)."""
        for j in range(4):
            n = conn[e, hex_face_corner(f, j)]
            if pairs[n, 0] >= 0 and pairs[n, 1] == 0:
                return False
        return True

    return face_tied3_py


def hex_centroid3_py(e, conn, x, y, z, tbuf):
    """Centroid of hexahedron ``e`` into ``tbuf[e, 0:3]`` (first pass of conduction)."""
    sx = 0.0
    sy = 0.0
    sz = 0.0
    for c in range(8):
        n = conn[e, c]
        sx += x[n]
        sy += y[n]
        sz += z[n]
    tbuf[e, 0] = 0.125 * sx
    tbuf[e, 1] = 0.125 * sy
    tbuf[e, 2] = 0.125 * sz


def make_hex_conduct3(face_tied3, face_area3):
    """:func:`hex_conduct3_py` with its callees ``face_tied3``, ``face_area3`` given (the
    CPU's compiled functions here, a GPU engine's device functions in its port)."""

    def hex_conduct3_py(e, mesh, temp, tbuf, conduction):
        """New temperature of hexahedron ``e`` into ``tbuf[e, 3]`` (second pass of conduction).

        Reads ``mesh`` = (``conn`` (e, 8) corners, ``x``, ``y``, ``z`` (n,) positions [m],
        ``alive`` (e,), ``enbr`` (e, 6) the face neighbours, ``pairs`` (n, 2) the node pairs
        of node splitting, ``vol0`` (e,) initial volumes [m^3]) and ``temp`` (e,) [K]; writes
        ``tbuf`` (e, 4) only. ``conduction`` = (conductivity ``kcond`` [W/(m K)], volumetric
        heat capacity ``rcp`` [J/(m^3 K)], time ``dt_th`` [s]).

        Needs the centroids ``tbuf[:, 0:3]`` of every element; reads ``temp`` only, so all
        elements can run at once. See the module docstring.
        """
        conn, x, y, z, alive, enbr, pairs, vol0 = mesh
        kcond, rcp, dt_th = conduction
        tbuf[e, 3] = temp[e]
        ve = vol0[e]
        if alive[e] != 1 or ve <= 0.0:
            return
        dq = 0.0
        for f in range(6):
            nb = enbr[e, f]
            if nb == -1:
                continue
            if nb <= -2:
                nb = -nb - 2
                if not face_tied3(e, f, conn, pairs):
                    continue
            if alive[nb] != 1:
                continue
            vn = vol0[nb]
            d = math.sqrt((tbuf[nb, 0] - tbuf[e, 0]) ** 2 + (tbuf[nb, 1] - tbuf[e, 1]) ** 2
                          + (tbuf[nb, 2] - tbuf[e, 2]) ** 2)
            if d <= 0.0 or vn <= 0.0:
                continue
            g = kcond * face_area3(e, f, conn, x, y, z) / d * dt_th
            gmax = rcp * min(ve, vn) / 6.0
            if g > gmax:
                g = gmax
            dq += g * (temp[nb] - temp[e])
        tbuf[e, 3] = temp[e] + dq / (rcp * ve)

    return hex_conduct3_py


def make_face_free3(face_tied3):
    """:func:`face_free3_py` with its callees ``face_tied3`` given (the CPU's compiled
    functions here, a GPU engine's device functions in its port)."""

    def face_free3_py(e, f, conn, alive, enbr, pairs):
        """True where face ``f`` of live element ``e`` is a free surface (no live neighbour
        across it, or a parting face whose nodes have parted)."""
        nb = enbr[e, f]
        if nb == -1:
            return True
        if nb <= -2:
            return alive[-nb - 2] != 1 or not face_tied3(e, f, conn, pairs)
        return alive[nb] != 1

    return face_free3_py


def make_tool_heat_node3(hex_face_corner, face_free3, face_area3):
    """:func:`tool_heat_node3_py` with its callees ``hex_face_corner``, ``face_free3``,
    ``face_area3`` given (the CPU's compiled functions here, a GPU engine's device
    functions in its port)"""

    def tool_heat_node3_py(n, mesh, fields, theat, heat):
        """Heat [J] node ``n`` exchanges with the insert since the last pass, into
        ``theat[n, 1]``, and the volume of its live elements into ``theat[n, 2]``; ``theat[n, 0]``
        holds the frictional dissipation already turned into heat. See the module docstring.

        Reads ``mesh`` = (``conn`` (e, 8) corners, ``x``, ``y``, ``z`` (n,) positions [m], the
        CSR node-to-element lists ``ptr`` (n + 1,), ``nel``, ``ncorner``, ``alive`` (e,),
        ``enbr`` (e, 6) the face neighbours, ``pairs`` (n, 2) the node pairs of node
        splitting, ``vol0`` (e,) initial volumes [m^3]) and ``fields`` = (``cf`` (n, 4) the
        contact forces [N] in ``cf[:, 0:3]``, ``fric`` (n,) the cumulative frictional work [J],
        ``temp`` (e,) [K]); writes ``theat`` (n, 3) only. ``heat`` = (volumetric heat capacity
        ``rcp`` [J/(m^3 K)], contact conductance ``hc`` [W/(m^2 K)], share ``eta`` of the
        frictional heat into the workpiece, insert temperature ``t_tool`` [K], time ``dt_th``
        [s]).
        """
        conn, x, y, z, ptr, nel, ncorner, alive, enbr, pairs, vol0 = mesh
        cf, fric, temp = fields
        rcp, hc, eta, t_tool, dt_th = heat
        q = eta * (fric[n] - theat[n, 0])
        theat[n, 0] = fric[n]
        touching = hc > 0.0 and (cf[n, 0] != 0.0 or cf[n, 1] != 0.0 or cf[n, 2] != 0.0)
        if q == 0.0 and not touching:
            theat[n, 1] = 0.0  # nothing to hand on: the element pass skips this node
            return
        vsum = 0.0
        tsum = 0.0
        for k in range(ptr[n], ptr[n + 1]):
            e = nel[k]
            if alive[e] == 1:
                v = vol0[e]
                vsum += v
                tsum += v * temp[e]
        theat[n, 2] = vsum
        if vsum <= 0.0:
            theat[n, 1] = 0.0
            return
        if touching:
            an = 0.0
            for k in range(ptr[n], ptr[n + 1]):
                e = nel[k]
                if alive[e] != 1:
                    continue
                c = ncorner[k]
                for f in range(6):
                    on = False
                    for j in range(4):
                        if hex_face_corner(f, j) == c:
                            on = True
                    if not on or not face_free3(e, f, conn, alive, enbr, pairs):
                        continue
                    touch = 0  # nodes of the face in contact (n among them)
                    for j in range(4):
                        o = conn[e, hex_face_corner(f, j)]
                        if cf[o, 0] != 0.0 or cf[o, 1] != 0.0 or cf[o, 2] != 0.0:
                            touch += 1
                    if touch > 2:
                        # the face touches the insert over (touch - 2) / 2 of its area (a
                        # triangle of three nodes, the whole face with four; an edge is a line),
                        # shared by its nodes in contact
                        an += face_area3(e, f, conn, x, y, z) * (touch - 2) / (2.0 * touch)
            g = hc * an * dt_th
            gmax = 0.25 * rcp * vsum
            if g > gmax:
                g = gmax
            q += g * (t_tool - tsum / vsum)
        theat[n, 1] = q

    return tool_heat_node3_py


def tool_heat_elem3_py(e, conn, alive, temp, theat, rcp):
    """Element ``e`` takes, from each corner node, its heat / (rho cp volume of that node's
    live elements): a node's heat goes to its elements in proportion to their volumes."""
    if alive[e] != 1:
        return
    dT = 0.0
    for c in range(8):
        n = conn[e, c]
        if theat[n, 1] != 0.0 and theat[n, 2] > 0.0:
            dT += theat[n, 1] / (rcp * theat[n, 2])
    temp[e] += dT


hex_face_corner = njit(cache=True, inline="always")(hex_face_corner_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
face_area3_py = make_face_area3(hex_face_corner)
face_area3 = njit(cache=False, inline="always")(face_area3_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
face_tied3_py = make_face_tied3(hex_face_corner)
face_tied3 = njit(cache=False, inline="always")(face_tied3_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
face_free3_py = make_face_free3(face_tied3)
face_free3 = njit(cache=False, inline="always")(face_free3_py)
hex_centroid3 = njit(cache=True, inline="always")(hex_centroid3_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
hex_conduct3_py = make_hex_conduct3(face_tied3, face_area3)
hex_conduct3 = njit(cache=False, inline="always")(hex_conduct3_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
tool_heat_node3_py = make_tool_heat_node3(hex_face_corner, face_free3, face_area3)
tool_heat_node3 = njit(cache=False, inline="always")(tool_heat_node3_py)
tool_heat_elem3 = njit(cache=True, inline="always")(tool_heat_elem3_py)

#: the device functions of this module in dependency order, each as (name, source, callees):
#: a function without callees is its plain-Python source, one with callees its factory, which
#: the GPU engine calls with the device versions of the callees named (keyword arguments)
DEVICE_FUNCTIONS = (
    ("hex_face_corner", hex_face_corner_py, ()),
    ("face_area3", make_face_area3, ("hex_face_corner",)),
    ("face_tied3", make_face_tied3, ("hex_face_corner",)),
    ("face_free3", make_face_free3, ("face_tied3",)),
    ("hex_centroid3", hex_centroid3_py, ()),
    ("hex_conduct3", make_hex_conduct3, ("face_tied3", "face_area3")),
    ("tool_heat_node3", make_tool_heat_node3, ("hex_face_corner", "face_free3", "face_area3")),
    ("tool_heat_elem3", tool_heat_elem3_py, ()),
)


@njit(parallel=True, cache=True)
def conduct3(nodes, cells, elems, contact, tbuf, kcond, rcp, dt_th):
    """Conduction between live elements over ``dt_th`` [s] (three passes over the elements:
    centroids, new temperatures into ``tbuf[:, 3]``, copy). The groups of
    :mod:`robobore.cutting.fe.ale.groups3d`: ``nodes`` (Nodes3: ``x, y, z``), ``cells``
    (Cells3: ``conn``, ``alive``, ``fnbr`` the face neighbours ``enbr`` of this module),
    ``elems`` (ElementState3: ``vol0``, ``temp``), ``contact`` (Contact3: ``pairs``);
    ``tbuf`` (e, 4) scratch, ``kcond`` the conductivity [W/(m K)], ``rcp`` the volumetric
    heat capacity [J/(m^3 K)]."""
    # the prange bodies read flat locals, one bound per statement (ale.groups3d)
    x = nodes.x
    y = nodes.y
    z = nodes.z
    conn = cells.conn
    alive = cells.alive
    enbr = cells.fnbr
    vol0 = elems.vol0
    temp = elems.temp
    pairs = contact.pairs
    ne = conn.shape[0]
    for e in prange(ne):
        hex_centroid3(e, conn, x, y, z, tbuf)
    for e in prange(ne):
        # the read-only arrays and the scalars in tuples built here, in the body
        hex_conduct3(e, (conn, x, y, z, alive, enbr, pairs, vol0), temp, tbuf,
                     (kcond, rcp, dt_th))
    for e in prange(ne):
        temp[e] = tbuf[e, 3]


@njit(parallel=True, cache=True)
def tool_heat3(nodes, ncorner, cells, elems, contact, theat, rcp, hc, eta, t_tool, dt_th):
    """Thermal contact with the insert over ``dt_th`` [s] (after :func:`conduct3`): node by
    node, then into the elements. Heat is conserved between nodes and elements. The groups as
    in :func:`conduct3` (``nodes.ptr``, ``nodes.nel`` and ``ncorner`` the node-to-element
    lists; ``contact.cf``, ``contact.fric`` the contact forces and frictional work), ``theat``
    (n, 3) the nodes' heat data, ``rcp`` [J/(m^3 K)], ``hc`` the contact conductance
    [W/(m^2 K)], ``eta`` the share of the frictional heat into the workpiece, ``t_tool`` the
    insert's temperature [K]."""
    # the prange bodies read flat locals, one bound per statement (ale.groups3d)
    x = nodes.x
    y = nodes.y
    z = nodes.z
    ptr = nodes.ptr
    nel = nodes.nel
    conn = cells.conn
    alive = cells.alive
    enbr = cells.fnbr
    vol0 = elems.vol0
    temp = elems.temp
    cf = contact.cf
    fric = contact.fric
    pairs = contact.pairs
    for n in prange(x.shape[0]):
        # the read-only arrays and the scalars in tuples built here, in the body
        tool_heat_node3(n, (conn, x, y, z, ptr, nel, ncorner, alive, enbr, pairs, vol0),
                        (cf, fric, temp), theat, (rcp, hc, eta, t_tool, dt_th))
    for e in prange(conn.shape[0]):
        tool_heat_elem3(e, conn, alive, temp, theat, rcp)


def face_neighbours(conn: np.ndarray, twin: np.ndarray | None = None) -> np.ndarray:
    """Neighbour table ``enbr`` (e, 6) of a hexahedral mesh (see the module docstring).

    Two faces match when they have the same four nodes; with node splitting (``twin`` (n,),
    the partner of each doubled node, -1 none) a face of copies that matches a face of
    originals only through ``twin`` is a parting face, stored as ``-(nb + 2)``. A face shared
    by more than two elements is a mesh error (ValueError).
    """
    conn = np.asarray(conn, np.int64)
    ne = conn.shape[0]
    faces = conn[:, HEX_FACES]  # (e, 6, 4)
    canon = faces.copy()
    if twin is not None:
        tw = np.asarray(twin, np.int64)
        has = tw >= 0
        base = np.arange(tw.size)
        base[has] = np.minimum(base[has], tw[has])
        canon = base[faces]
    key = np.sort(canon.reshape(-1, 4), axis=1)
    exact = np.sort(faces.reshape(-1, 4), axis=1)
    order = np.lexsort(key.T[::-1])
    ks = key[order]
    same = np.all(ks[1:] == ks[:-1], axis=1)
    if np.any(same[1:] & same[:-1]):
        raise ValueError("a face is shared by more than two hexahedra")
    enbr = -np.ones(ne * 6, np.int64)
    i = np.flatnonzero(same)
    a = order[i]
    b = order[i + 1]
    parting = np.any(exact[a] != exact[b], axis=1)
    ea = a // 6
    eb = b // 6
    enbr[a] = np.where(parting, -(eb + 2), eb)
    enbr[b] = np.where(parting, -(ea + 2), ea)
    return enbr.reshape(ne, 6)
