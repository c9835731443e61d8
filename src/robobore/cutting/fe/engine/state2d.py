"""The state of the plane-strain engine: :class:`FEState` holds every array of a model
(structure of arrays); :func:`make_state` builds one from any quad mesh (used by the cutting
model and by the element/bar tests), :func:`default_prm` the neutral parameter vector
(:mod:`robobore.cutting.fe.engine.layout`), :func:`parting_edges` the parting-line edges of a
node-splitting mesh, :func:`init_forces` the forces and stable step of the first
configuration.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from robobore.cutting.fe.ale.remap import N_RZ_FIELDS
from robobore.cutting.fe.ale.stencils import edge_neighbours
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.chunk_loop import Phases
from robobore.cutting.fe.engine.groups2d import (
    N_QS,
    QS_DMG,
    QS_EPS_P,
    QS_PRES,
    QS_QHX,
    QS_QHY,
    QS_SDX,
    QS_SDXY,
    QS_SDY,
    QS_SDZ,
    QS_TEMP,
    groups_of,
)
from robobore.cutting.fe.quad import element as q_element
from robobore.errors import ConfigError
from robobore.material.library import Material


def _qs_row(k: int, doc: str) -> property:
    """A read-only attribute: row ``k`` of the element state ``qs`` (a view)."""
    return property(lambda st: st.qs[k], doc=doc)


@dataclass
class FEState:
    """All arrays of an explicit model (SI, per unit width). Shapes: nodes (n,), elements (e,).

    Grouped as declared: mesh, element state, element energies and outputs, contact and node
    energies, parameters / tool / counters / histories, then the arrays of the ALE pass, node
    splitting, conduction, the B-bar element and the friction table (empty where the model
    does not use them). :meth:`kernel_args` lists them in the order of the compiled loop's
    arguments.
    """

    # --- mesh: nodes (n,) and elements (e,)
    #: node positions [m]
    x: np.ndarray
    y: np.ndarray
    #: node velocities [m/s]
    vx: np.ndarray
    vy: np.ndarray
    #: lumped nodal mass [kg/m] (mass-scaled density)
    mass: np.ndarray
    #: node held in x and y (bool)
    fixed: np.ndarray
    #: node-to-element lists (CSR): the elements of node n are nel[ptr[n]:ptr[n + 1]], the
    #: node being their corner ncorner[...]
    ptr: np.ndarray
    nel: np.ndarray
    ncorner: np.ndarray
    #: element corners (e, 4), counter-clockwise
    conn: np.ndarray
    #: element of the separation (erosion) layer (bool)
    layer: np.ndarray
    #: element state: 1 alive, 0 eroded by damage, -1 by distortion or time step, -2 inverted
    alive: np.ndarray
    # --- element state
    #: the element state (N_QS, e), a row per field of engine.groups2d.QS_FIELDS: deviatoric
    #: stress xx, yy, zz, xy [Pa], pressure [Pa] (stress = deviatoric stress - pressure),
    #: equivalent plastic strain, temperature [K], Johnson-Cook damage (erodes at 1 where
    #: allowed), stored (co-rotated) hourglass stiffness force x and y [N/m]; read (and
    #: written in place) by row as ``sdx`` ... ``qhy``
    qs: np.ndarray
    #: reference area [m^2] = element mass / (scaled density)
    area0: np.ndarray
    # --- element energies and outputs (e,)
    #: internal (stress) work [J/m]
    ie: np.ndarray
    #: hourglass work [J/m]
    hge: np.ndarray
    #: internal force on each corner, x and y (e, 4) [N/m]
    fex: np.ndarray
    fey: np.ndarray
    #: stable time step of the element [s]
    dte: np.ndarray
    #: plastic work [J/m]
    plast: np.ndarray
    #: equivalent plastic strain rate of the last step [1/s]
    rate: np.ndarray
    # --- contact and node energies (n,)
    #: contact force on the node (from the tool), x and y [N/m]
    cfx: np.ndarray
    cfy: np.ndarray
    #: frictional dissipation [J/m] (with the contact damping's)
    fric: np.ndarray
    #: penalty energy stored in the contact spring [J/m]
    pen: np.ndarray
    #: node without a live element (its kinetic energy then booked in ero_ke)
    ndead: np.ndarray
    #: kinetic energy of the node when its last element eroded [J/m]
    ero_ke: np.ndarray
    #: work of the contact force on the node [J/m]
    nwork: np.ndarray
    # --- parameters, tool, counters and histories (engine.layout)
    #: material vector (robobore.material.Material.to_array)
    mat: np.ndarray
    #: parameter vector (engine.layout.PRM_FIELDS; model slots from config.spec)
    prm: np.ndarray
    #: tool state (T_*)
    tool: np.ndarray
    #: energy accumulators (E_*) [J/m]
    en: np.ndarray
    #: counters and status (I_*)
    ist: np.ndarray
    #: time [s], current step [s], time accumulated in the current sample interval [s]
    clock: np.ndarray
    #: time-integrated history columns of the current sample interval (N_HIST,)
    hacc: np.ndarray
    #: history rows (n_samples, N_HIST), engine.history's layout
    hist: np.ndarray
    # --- ALE, separation, conduction and B-bar arrays
    #: element across each edge (e, 4), -1 on the outline
    enbr: np.ndarray = field(default=None)  # type: ignore[assignment]
    #: tool-frame ALE: the nodes whose velocity a pass remaps (all but the rigid ones; empty
    #: for the Lagrangian models)
    snodes: np.ndarray = field(default=None)  # type: ignore[assignment]
    #: ALE pass scratch: new node positions (n,), remapped element fields (e, N_RZ_FIELDS)
    xn: np.ndarray = field(default=None)  # type: ignore[assignment]
    yn: np.ndarray = field(default=None)  # type: ignore[assignment]
    buf: np.ndarray = field(default=None)  # type: ignore[assignment]
    #: initial node positions [m] (the tool-frame places of the ALE, outputs)
    x0: np.ndarray = field(default=None)  # type: ignore[assignment]
    y0: np.ndarray = field(default=None)  # type: ignore[assignment]
    #: node splitting: partner node (-1: none) and whether the pair is still tied
    twin: np.ndarray = field(default=None)  # type: ignore[assignment]
    tied: np.ndarray = field(default=None)  # type: ignore[assignment]
    #: scratch for the heat-conduction update (n_elem, 4)
    tbuf: np.ndarray = field(default=None)  # type: ignore[assignment]
    #: Gauss-point state of the B-bar element (n_elem, 4, N_GPS); (0, 4, N_GPS) for Q4R
    gps: np.ndarray = field(default=None)  # type: ignore[assignment]
    #: thermal contact: frictional dissipation already turned into heat (n_nodes,), scratch
    #: (n_nodes, 2), and the parting-line edges (m, 4) = an element, the element across the
    #: line, and the first one's two nodes on the edge (conduction across tied pairs)
    fheat: np.ndarray = field(default=None)  # type: ignore[assignment]
    tcq: np.ndarray = field(default=None)  # type: ignore[assignment]
    ppair: np.ndarray = field(default=None)  # type: ignore[assignment]
    #: tool-frame ALE: velocity increments of the moved nodes (n_nodes, 2), scratch
    vbuf: np.ndarray = field(default=None)  # type: ignore[assignment]
    #: tool-frame ALE (``mesh.frame = "tool"``, robobore.cutting.fe.ale.toolframe): node classes
    #: and neighbours (n, 7), node data (n, 6), flux type of each element edge (e, 4); empty
    #: for the Lagrangian models
    acls: np.ndarray = field(default=None)  # type: ignore[assignment]
    aflt: np.ndarray = field(default=None)  # type: ignore[assignment]
    bflag: np.ndarray = field(default=None)  # type: ignore[assignment]
    #: friction by sliding speed: each node's filtered sliding speed [m/s] (n_nodes,)
    vslip: np.ndarray = field(default=None)  # type: ignore[assignment]
    # --- the model choices the compiled loop is specialised for (not a kernel argument)
    #: element, tool frame, conduction (engine.chunk_loop.Phases; advance runs its loop)
    phases: Phases = field(default_factory=Phases)

    # the rows of ``qs`` by name: views, written in place (``st.temp[:] = ...``)
    sdx = _qs_row(QS_SDX, "deviatoric stress xx (e,) [Pa]")
    sdy = _qs_row(QS_SDY, "deviatoric stress yy (e,) [Pa]")
    sdz = _qs_row(QS_SDZ, "deviatoric stress zz (e,) [Pa]")
    sdxy = _qs_row(QS_SDXY, "deviatoric stress xy (e,) [Pa]")
    pres = _qs_row(QS_PRES, "pressure (e,) [Pa]")
    eps_p = _qs_row(QS_EPS_P, "equivalent plastic strain (e,)")
    temp = _qs_row(QS_TEMP, "temperature (e,) [K]")
    dmg = _qs_row(QS_DMG, "Johnson-Cook damage (e,)")
    qhx = _qs_row(QS_QHX, "stored hourglass force x (e,) [N/m]")
    qhy = _qs_row(QS_QHY, "stored hourglass force y (e,) [N/m]")

    def kernel_args(self) -> tuple:
        return (self.x, self.y, self.vx, self.vy, self.mass, self.fixed, self.ptr, self.nel,
                self.ncorner, self.conn, self.layer, self.alive, self.qs, self.area0, self.ie,
                self.hge, self.fex, self.fey, self.dte, self.plast, self.rate, self.cfx, self.cfy, self.fric, self.pen, self.ndead, self.ero_ke,
                self.nwork, self.mat, self.prm, self.tool, self.en, self.ist, self.clock,
                self.hacc, self.hist, self.enbr, self.snodes, self.xn, self.yn,
                self.buf, self.twin, self.tied, self.tbuf, self.gps, self.fheat, self.tcq,
                self.ppair, self.x0, self.y0, self.vbuf, self.acls, self.aflt, self.bflag,
                self.vslip)

    @property
    def n_elements(self) -> int:
        return int(self.conn.shape[0])

    @property
    def time(self) -> float:
        return float(self.clock[0])


def default_prm() -> np.ndarray:
    """Parameter vector with neutral values (no tool contact, no support, no erosion)."""
    p = np.zeros(layout.N_PRM)
    p[layout.P_CFL] = 0.8
    p[layout.P_MS] = 1.0
    p[layout.P_HGV] = 0.05
    p[layout.P_HGS] = 0.05
    p[layout.P_BV1] = 0.06
    p[layout.P_BV2] = 1.2
    p[layout.P_DIST] = 0.0
    p[layout.P_PEN] = 0.1
    p[layout.P_TAU] = 1e30
    p[layout.P_R] = 0.0
    # tool far away: rake normal (-1, 0), flank normal (0, -1)
    p[layout.P_NRX], p[layout.P_NRY], p[layout.P_NFX], p[layout.P_NFY] = -1.0, 0.0, 0.0, -1.0
    p[layout.P_WIDTH] = 1.0
    p[layout.P_SAMPLE_DT] = 1e30
    p[layout.P_TEND] = 1e30
    p[layout.P_EROSION] = layout.ERODE_NONE
    p[layout.P_GATE] = -1.0
    return p


def make_state(nodes: np.ndarray, conn: np.ndarray, fixed: np.ndarray, material: Material,
               prm: np.ndarray | None = None, layer: np.ndarray | None = None,
               n_samples: int = 1, tool_center: tuple[float, float] = (1e3, 1e3),
               twin: np.ndarray | None = None, phases: Phases | None = None) -> FEState:
    """State for a quad mesh ``nodes`` (n, 2) [m], ``conn`` (e, 4) counter-clockwise.

    ``phases``: the model choices of the compiled loop (default: one-point quad, workpiece
    frame, adiabatic); the B-bar element gets its Gauss-point state.

    Lumped nodal masses from the (mass-scaled) density; stresses zero; temperature at
    T_room. The tool starts with its edge centre at ``tool_center`` [m].
    """
    nodes = np.ascontiguousarray(nodes, dtype=np.float64)
    conn = np.ascontiguousarray(conn, dtype=np.int64)
    n = nodes.shape[0]
    ne = conn.shape[0]
    prm = default_prm() if prm is None else prm.astype(np.float64)
    mat = material.to_array()
    xs = nodes[:, 0].copy()
    ys = nodes[:, 1].copy()
    xe = xs[conn]
    ye = ys[conn]
    area = 0.5 * ((xe[:, 2] - xe[:, 0]) * (ye[:, 3] - ye[:, 1])
                  + (xe[:, 1] - xe[:, 3]) * (ye[:, 2] - ye[:, 0]))
    if np.any(area <= 0):
        bad = int(np.argmin(area))
        raise ConfigError("mesh has an element with non-positive area (nodes must be "
                          "counter-clockwise)", field="conn", value=bad)
    mass = np.zeros(n)
    np.add.at(mass, conn.ravel(), np.repeat(area * material.rho * prm[layout.P_MS] / 4.0, 4))
    counts = np.bincount(conn.ravel(), minlength=n)
    ptr = np.zeros(n + 1, dtype=np.int64)
    ptr[1:] = np.cumsum(counts)
    nel = np.empty(ptr[-1], dtype=np.int64)
    nco = np.empty(ptr[-1], dtype=np.int64)
    fill = ptr[:-1].copy()
    flat = conn.ravel()
    order = np.argsort(flat, kind="stable")
    nel[:] = order // 4
    nco[:] = order % 4
    del fill
    tool = np.zeros(layout.N_TOOL)
    tool[layout.T_GX], tool[layout.T_GY] = tool_center
    z = np.zeros
    phases = Phases() if phases is None else phases
    qs = z((N_QS, ne))
    qs[QS_TEMP] = material.T_room
    st = FEState(
        x=xs, y=ys, vx=z(n), vy=z(n), mass=mass, fixed=np.asarray(fixed, dtype=np.bool_),
        ptr=ptr, nel=nel, ncorner=nco, conn=conn,
        layer=np.zeros(ne, np.bool_) if layer is None else np.asarray(layer, np.bool_),
        alive=np.ones(ne, np.int64), qs=qs, area0=area.copy(), ie=z(ne), hge=z(ne),
        fex=z((ne, 4)), fey=z((ne, 4)), dte=z(ne), plast=z(ne), rate=z(ne), cfx=z(n), cfy=z(n), fric=z(n), pen=z(n),
        ndead=np.zeros(n, np.bool_), ero_ke=z(n), nwork=z(n), mat=mat, prm=prm, tool=tool,
        en=z(layout.N_EN), ist=np.zeros(layout.N_IST, np.int64), clock=z(3), hacc=z(layout.N_HIST),
        hist=np.full((max(1, n_samples), layout.N_HIST), np.nan), x0=xs.copy(), y0=ys.copy(),
        enbr=edge_neighbours(conn), snodes=np.zeros(0, np.int64), xn=z(n), yn=z(n),
        buf=z((ne, N_RZ_FIELDS)),
        twin=(-np.ones(n, np.int64) if twin is None else np.asarray(twin, np.int64)),
        tied=(np.zeros(n, np.int64) if twin is None
              else (np.asarray(twin) >= 0).astype(np.int64)),
        tbuf=z((ne, 4)),
        gps=z((ne if phases.element == "bbar" else 0, 4, layout.N_GPS)),
        fheat=z(n), tcq=z((n, 2)), ppair=parting_edges(conn, twin), vbuf=z((n, 2)),
        acls=np.zeros((0, 7), np.int64), aflt=z((0, 6)), bflag=np.zeros((0, 4), np.int64),
        vslip=z(n), phases=phases)
    init_forces(st)
    return st


def parting_edges(conn: np.ndarray, twin: np.ndarray | None) -> np.ndarray:
    """(m, 4) int64: the edges of a node-splitting parting line, as element, element across,
    and the element's two nodes on the edge (the twins of the element across's nodes)."""
    if twin is None:
        return np.zeros((0, 4), np.int64)
    tw = np.asarray(twin, np.int64)
    owner: dict[tuple[int, int], tuple[int, int, int]] = {}
    rows: list[tuple[int, int, int, int]] = []
    for e in range(conn.shape[0]):
        for k in range(4):
            a, b = int(conn[e, k]), int(conn[e, (k + 1) % 4])
            if tw[a] < 0 or tw[b] < 0:
                continue
            other = (min(int(tw[a]), int(tw[b])), max(int(tw[a]), int(tw[b])))
            if other in owner:
                e2, _, _ = owner.pop(other)
                rows.append((e2, e, int(tw[a]), int(tw[b])))
            else:
                owner[(min(a, b), max(a, b))] = (e, a, b)
    out = np.array(rows, dtype=np.int64).reshape(-1, 4)
    # each element on one edge at most: the edges can then be updated in parallel
    if np.unique(out[:, :2]).size != 2 * out.shape[0]:
        raise ValueError("an element has two edges on the parting line")
    return out


def init_forces(st: FEState) -> float:
    """Element forces and stable step of the current configuration (no stress update)."""
    copies = {f: getattr(st, f).copy() for f in ("qs", "ie", "hge", "plast", "rate")}
    nodes, quads, qs, out, _, _ = groups_of(st, vx=st.vx * 0.0, vy=st.vy * 0.0, **copies)
    q_element.element_update(nodes, quads, qs, out, st.mat, st.prm, 1e-30, layout.ERODE_NONE)
    dt = st.prm[layout.P_CFL] * float(np.min(st.dte))
    st.clock[1] = dt
    if st.prm[layout.P_DTMIN] <= 0:
        st.prm[layout.P_DTMIN] = 1e-3 * dt
    if st.prm[layout.P_DT_ERODE] < 0:  # given as a fraction of the initial step: make absolute
        st.prm[layout.P_DT_ERODE] = -st.prm[layout.P_DT_ERODE] * float(np.min(st.dte))
    return dt
