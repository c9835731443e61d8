"""Heat passes of the plane-strain engine: conduction between elements (:func:`conduct`),
across the parting line of a node-splitting mesh (:func:`parting_conduct`) and thermal
contact with the tool (:func:`tool_heat`: frictional heat and interface conductance).

The per-element, per-edge and per-node updates are plain-Python scalar functions
(``quad_centroid_py``, ``quad_conduct_py``, ``parting_edge_py``, ``tool_heat_node_py``,
``tool_heat_elem_py``) that the CPU loops call as ``njit`` functions and
:mod:`robobore.cutting.fe.engine.gpu.backend2d` compiles for an NVIDIA GPU.
"""

from __future__ import annotations

import math

from numba import njit, prange

from robobore.cutting.fe.engine.groups2d import QS_TEMP


def quad_centroid_py(e, conn, x, y, tbuf):
    """Centroid x, y and area of quad ``e`` into ``tbuf[e, 0:3]`` (first pass of conduction)."""
    i1, i2, i3, i4 = conn[e, 0], conn[e, 1], conn[e, 2], conn[e, 3]
    tbuf[e, 0] = 0.25 * (x[i1] + x[i2] + x[i3] + x[i4])
    tbuf[e, 1] = 0.25 * (y[i1] + y[i2] + y[i3] + y[i4])
    tbuf[e, 2] = 0.5 * ((x[i3] - x[i1]) * (y[i4] - y[i2]) + (x[i2] - x[i4]) * (y[i3] - y[i1]))


def quad_conduct_py(e, conn, x, y, alive, enbr, temp, tbuf, kcond, rcp, dt_th):
    """New temperature of quad ``e`` into ``tbuf[e, 3]`` (second pass of conduction).

    Needs ``tbuf[:, 0:3]`` of every element (:func:`quad_centroid_py`); reads ``temp`` only,
    so all elements can run at once. See :func:`conduct`.
    """
    tbuf[e, 3] = temp[e]
    ae = tbuf[e, 2]
    if alive[e] != 1 or ae <= 0.0:
        return
    dq = 0.0
    for k in range(4):
        nb = enbr[e, k]
        if nb < 0 or alive[nb] != 1:
            continue
        an = tbuf[nb, 2]
        na = conn[e, k]
        nb2 = conn[e, (k + 1) % 4]
        ledge = math.sqrt((x[nb2] - x[na]) ** 2 + (y[nb2] - y[na]) ** 2)
        d = math.sqrt((tbuf[nb, 0] - tbuf[e, 0]) ** 2 + (tbuf[nb, 1] - tbuf[e, 1]) ** 2)
        if d <= 0.0 or an <= 0.0:
            continue
        g = kcond * ledge / d * dt_th
        gmax = 0.25 * rcp * min(ae, an)
        if g > gmax:
            g = gmax
        dq += g * (temp[nb] - temp[e])
    tbuf[e, 3] = temp[e] + dq / (rcp * ae)


quad_centroid = njit(cache=True, inline="always")(quad_centroid_py)
quad_conduct = njit(cache=True, inline="always")(quad_conduct_py)


@njit(parallel=True, cache=True)
def conduct(conn, x, y, alive, enbr, temp, tbuf, kcond, rcp, dt_th):
    """Explicit heat conduction between live elements over ``dt_th`` [s] (finite volumes).

    Element temperatures are cell values on the current (deformed) mesh; across each edge
    shared by two live elements flows ``G (T_nb - T_e)`` with the two-point conductance
    ``G = k L_edge / d_centroids * dt_th`` [J/K per m of width]. ``G`` is capped at a quarter
    of the smaller of the two heat capacities ``rho cp A`` (stability of the explicit update
    for any element shape; symmetric, so heat is conserved exactly). Eroded elements and
    free surfaces are adiabatic (so is the tool). ``tbuf`` (n_elem, 4) is scratch: centroid
    x, y and area of every element, then its new temperature.
    """
    ne = conn.shape[0]
    for e in prange(ne):
        quad_centroid(e, conn, x, y, tbuf)
    for e in prange(ne):
        quad_conduct(e, conn, x, y, alive, enbr, temp, tbuf, kcond, rcp, dt_th)
    for e in prange(ne):
        temp[e] = tbuf[e, 3]


def parting_edge_py(i, ppair, x, y, alive, tied, temp, tbuf, kcond, rcp, dt_th):
    """Conduction across parting-line edge ``i`` while both its node pairs are still tied.

    ``ppair`` (m, 4): an element, the element across the parting line, and the first one's
    two nodes on the edge (:func:`robobore.cutting.fe.engine.state2d.parting_edges`). The two
    elements share no nodes (the line's nodes are doubled), so :func:`conduct` sees the
    line as a free surface; while the pairs are tied the material is continuous there and
    heat flows across with the two-point conductance (and cap) of :func:`quad_conduct_py`.
    Needs the centroids and areas in ``tbuf[:, 0:3]``. An element lies on at most one edge
    of ``ppair``, so all edges can run at once; heat is conserved exactly.
    """
    ea, eb, na, nb = ppair[i, 0], ppair[i, 1], ppair[i, 2], ppair[i, 3]
    if alive[ea] != 1 or alive[eb] != 1 or tied[na] == 0 or tied[nb] == 0:
        return
    aa = tbuf[ea, 2]
    ab = tbuf[eb, 2]
    d = math.sqrt((tbuf[eb, 0] - tbuf[ea, 0]) ** 2 + (tbuf[eb, 1] - tbuf[ea, 1]) ** 2)
    if d <= 0.0 or aa <= 0.0 or ab <= 0.0:
        return
    ledge = math.sqrt((x[nb] - x[na]) ** 2 + (y[nb] - y[na]) ** 2)
    g = kcond * ledge / d * dt_th
    gmax = 0.25 * rcp * min(aa, ab)
    if g > gmax:
        g = gmax
    q = g * (temp[eb] - temp[ea])
    temp[ea] += q / (rcp * aa)
    temp[eb] -= q / (rcp * ab)


def tool_heat_node_py(n, mesh, fields, fheat, tcq, heat):
    """Heat [J/m] node ``n`` exchanges with the tool since the last call, into ``tcq[n]``.

    Reads ``mesh`` = (``conn`` (e, 4) corners, ``x``, ``y`` (n,) positions [m], the CSR
    node-to-element lists ``ptr`` (n + 1,), ``nel``, ``ncorner``, ``alive`` (e,), ``enbr``
    (e, 4) the edge neighbours) and ``fields`` = (``cfx``, ``cfy`` (n,) the contact forces
    [N/m], ``fric`` (n,) the cumulative frictional work [J/m], ``temp`` (e,) [K], ``tbuf`` the
    centroids and areas of :func:`conduct`); writes ``fheat`` (n,) (the frictional work
    already turned into heat [J/m]) and ``tcq`` (n, 2) only: a parallel pass's writes go to
    arrays it holds directly (:mod:`robobore.cutting.fe.engine.groups2d`).
    ``heat`` = (rho c_p ``rcp`` [J/(m^3 K)], conductance ``hc`` [W/(m^2 K)], heat fraction
    ``eta``, tool temperature ``t_tool`` [K], time ``dt_th`` [s]).

    The node takes ``eta`` of the frictional dissipation booked on it since the last call
    (``fric - fheat``; the rest heats the tool). A node in contact (non-zero contact force)
    exchanges ``hc L_n (t_tool - T_n) dt_th`` with the tool, a heat sink at ``t_tool``:
    ``T_n`` is the area-weighted mean temperature of the node's live elements, ``L_n`` half
    the length of each free-surface edge joining it to another node in contact. The
    conductance is capped at a quarter of the heat capacity of the node's elements
    (stability, as in :func:`quad_conduct_py`). ``tcq[n]`` = (heat, area of the node's live
    elements). Needs the areas in ``tbuf[:, 2]``.
    """
    conn, x, y, ptr, nel, ncorner, alive, enbr = mesh
    cfx, cfy, fric, temp, tbuf = fields
    rcp, hc, eta, t_tool, dt_th = heat
    q = eta * (fric[n] - fheat[n])
    fheat[n] = fric[n]
    touching = hc > 0.0 and (cfx[n] != 0.0 or cfy[n] != 0.0)
    if q == 0.0 and not touching:
        tcq[n, 0] = 0.0  # nothing to hand on: the element pass skips this node
        return
    asum = 0.0
    tsum = 0.0
    for k in range(ptr[n], ptr[n + 1]):
        e = nel[k]
        if alive[e] == 1:
            a = tbuf[e, 2]
            asum += a
            tsum += a * temp[e]
    tcq[n, 1] = asum
    if asum <= 0.0:
        tcq[n, 0] = 0.0
        return
    if touching:
        ln = 0.0
        for k in range(ptr[n], ptr[n + 1]):
            e = nel[k]
            if alive[e] != 1:
                continue
            c = ncorner[k]
            for j in range(2):
                # edge c (n -> next corner), then edge c - 1 (previous corner -> n)
                kk = c if j == 0 else (c + 3) % 4
                o = conn[e, (c + 1) % 4] if j == 0 else conn[e, (c + 3) % 4]
                nb = enbr[e, kk]
                if nb >= 0 and alive[nb] == 1:
                    continue
                if cfx[o] == 0.0 and cfy[o] == 0.0:
                    continue
                ln += 0.5 * math.sqrt((x[o] - x[n]) ** 2 + (y[o] - y[n]) ** 2)
        g = hc * ln * dt_th
        gmax = 0.25 * rcp * asum
        if g > gmax:
            g = gmax
        q += g * (t_tool - tsum / asum)
    tcq[n, 0] = q


def tool_heat_elem_py(e, conn, alive, temp, tcq, rcp):
    """Element ``e`` takes, from each corner node, heat / (rho cp area of that node's live
    elements): a node's heat goes to its elements in proportion to their areas."""
    if alive[e] != 1:
        return
    dT = 0.0
    for c in range(4):
        n = conn[e, c]
        if tcq[n, 0] != 0.0 and tcq[n, 1] > 0.0:
            dT += tcq[n, 0] / (rcp * tcq[n, 1])
    temp[e] += dT


parting_edge = njit(cache=True, inline="always")(parting_edge_py)
tool_heat_node = njit(cache=True, inline="always")(tool_heat_node_py)
tool_heat_elem = njit(cache=True, inline="always")(tool_heat_elem_py)


@njit(parallel=True, cache=True)
def parting_conduct(ppair, x, y, alive, tied, temp, tbuf, kcond, rcp, dt_th):
    """:func:`parting_edge_py` over all parting-line edges (after :func:`conduct`)."""
    for i in prange(ppair.shape[0]):
        parting_edge(i, ppair, x, y, alive, tied, temp, tbuf, kcond, rcp, dt_th)


@njit(parallel=True, cache=True)
def tool_heat(nodes, quads, qs, contact, enbr, fheat, tbuf, tcq, rcp, interface):
    """Thermal contact with the tool (after :func:`conduct`): frictional heat and the interface
    conductance, node by node (:func:`tool_heat_node_py`), then into the elements
    (:func:`tool_heat_elem_py`). Heat is conserved between nodes and elements.

    The groups of :mod:`robobore.cutting.fe.engine.groups2d`: ``nodes`` (Nodes2: ``x``, ``y``,
    the CSR ``ptr``, ``nel``, ``ncorner``), ``quads`` (Quads2: ``conn``, ``alive``), ``qs``
    (the element state: its row ``temp``), ``contact`` (Contact2: ``cfx``, ``cfy``,
    ``fric``); ``enbr`` (e, 4) the edge neighbours, ``fheat`` (n,) the frictional work
    already turned into heat [J/m], ``tbuf`` the centroids and areas of :func:`conduct`,
    ``tcq`` (n, 2) work, ``rcp`` rho c_p [J/(m^3 K)]; ``interface`` = (conductance hc
    [W/(m^2 K)], heat fraction eta, tool temperature [K], time ``dt_th`` [s]).
    """
    # the prange bodies read flat locals, one bound per statement (engine.groups2d)
    x = nodes.x
    y = nodes.y
    ptr = nodes.ptr
    nel = nodes.nel
    ncorner = nodes.ncorner
    conn = quads.conn
    alive = quads.alive
    temp = qs[QS_TEMP]
    cfx = contact.cfx
    cfy = contact.cfy
    fric = contact.fric
    hc = interface[0]
    eta = interface[1]
    t_tool = interface[2]
    dt_th = interface[3]
    for n in prange(x.shape[0]):
        # the read-only arrays and the scalars in tuples built here, in the body
        tool_heat_node(n, (conn, x, y, ptr, nel, ncorner, alive, enbr),
                       (cfx, cfy, fric, temp, tbuf), fheat, tcq, (rcp, hc, eta, t_tool, dt_th))
    for e in prange(conn.shape[0]):
        tool_heat_elem(e, conn, alive, temp, tcq, rcp)
