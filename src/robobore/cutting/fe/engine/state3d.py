"""3D explicit solver: state arrays of a hexahedral model and the chunked time loop.

:class:`FEState3` holds every array (structure of arrays, SI, forces in N);
:func:`make_state3` builds one from any hexahedral mesh (used by the boring model and the
element tests); :func:`advance3` runs :func:`kernels3d.run_chunk3` in chunks and turns an
instability into :class:`robobore.errors.NumericalError` with the 2D engine's messages.
The energy balance is :func:`robobore.cutting.fe.engine.chunk_driver.energy_error` (same
accumulators).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, fields

import numpy as np

from robobore.cutting.fe.ale.groups3d import groups3_of
from robobore.cutting.fe.ale.remap3d import N_RZ3
from robobore.cutting.fe.engine import kernels3d as K3
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.chunk_driver import drive_chunks
from robobore.cutting.fe.engine.threads import ThreadGovernor
from robobore.cutting.fe.hex import layout3d, scalar3d
from robobore.cutting.fe.physics.thermal3d import face_neighbours
from robobore.errors import ConfigError
from robobore.material.johnson_cook import RHO as MAT_RHO
from robobore.material.library import Material

__all__ = ["FEState3", "default_prm3", "make_state3", "init_forces3", "element_steps3", "advance3",
           "hex_volumes", "split_node_layer"]

#: node sign pattern of the reference hexahedron (VTK order), shape (8, 3)
HEX_SIGNS = np.array([(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
                      (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)], float)


@dataclass
class FEState3:
    """All arrays of a 3D explicit model. Shapes: nodes (n,), (n, 3); elements (e,), (e, k)."""

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    vz: np.ndarray
    mass: np.ndarray
    fixed: np.ndarray
    ptr: np.ndarray
    nel: np.ndarray
    ncorner: np.ndarray
    conn: np.ndarray
    alive: np.ndarray
    layer: np.ndarray
    sd: np.ndarray
    pres: np.ndarray
    eps_p: np.ndarray
    temp: np.ndarray
    dmg: np.ndarray
    qh: np.ndarray
    vol0: np.ndarray
    ie: np.ndarray
    hge: np.ndarray
    fe: np.ndarray
    dte: np.ndarray
    plast: np.ndarray
    rate: np.ndarray
    cf: np.ndarray  # (n, 4): contact force on the node [N], filtered sliding speed [m/s]
    fric: np.ndarray
    pen: np.ndarray
    ndead: np.ndarray
    ero_ke: np.ndarray
    nwork: np.ndarray
    mat: np.ndarray
    prm: np.ndarray
    tool: np.ndarray
    en: np.ndarray
    ist: np.ndarray
    clock: np.ndarray
    hacc: np.ndarray
    hist: np.ndarray
    #: node splitting, (n, 2) int64: partner node (-1: none) and whether the pair is still
    #: tied (one array: see :func:`hex.scalar3d.hex_node_py`)
    pairs: np.ndarray
    #: heat conduction (:mod:`robobore.cutting.fe.physics.thermal3d`): the element across each face
    #: (e, 6) int64 (-1 none, -(nb + 2) across a parting face); scratch (e, 4): centroid,
    #: new temperature; per node (n, 3): frictional dissipation already turned into heat
    #: [J], heat exchanged with the insert in the current pass [J], volume of the node's live
    #: elements [m^3]
    enbr: np.ndarray
    tbuf: np.ndarray
    theat: np.ndarray
    #: tool-frame ALE (``mesh.frame = "tool"``, :mod:`robobore.cutting.fe.ale.rezone3d`; zero
    #: rows in the workpiece frame, so the loop's arguments are one list): the nodes' places
    #: when the mesh was built (n,) [m] (each pass puts a node back to its place shifted by
    #: the insert's travel); ``acls`` (n, 7) int64 node class and in-slice neighbours,
    #: ``aflt`` (n, 6) the placement's geometric data, ``bflag`` (e, 6) int64 the remap's
    #: flux flag of each face (:mod:`robobore.cutting.fe.mesh.toolframe3d`); scratch: new
    #: node places ``xn, yn, zn`` (n,), remapped element fields ``buf`` (e, remap3d.N_RZ3),
    #: nodal velocities ``vbuf`` (n, 3) and the placement's work array ``scratch`` (n, 3)
    x0: np.ndarray = field(default_factory=lambda: np.zeros(0))
    y0: np.ndarray = field(default_factory=lambda: np.zeros(0))
    z0: np.ndarray = field(default_factory=lambda: np.zeros(0))
    acls: np.ndarray = field(default_factory=lambda: np.zeros((0, 7), np.int64))
    aflt: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))
    bflag: np.ndarray = field(default_factory=lambda: np.zeros((0, 6), np.int64))
    xn: np.ndarray = field(default_factory=lambda: np.zeros(0))
    yn: np.ndarray = field(default_factory=lambda: np.zeros(0))
    zn: np.ndarray = field(default_factory=lambda: np.zeros(0))
    buf: np.ndarray = field(default_factory=lambda: np.zeros((0, N_RZ3)))
    vbuf: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    scratch: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    #: element-attached inertia factors (e,) >= 1 of the tool-frame mesh (empty: none): each
    #: element's corners carry ``rho_s vol0 msf / 8`` of inertia and its stable step is
    #: ``sqrt(msf)`` times its material one (:meth:`set_inertia_factors`)
    msf: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def kernel_args(self) -> tuple:
        """Arrays in the order of :func:`kernels3d.run_chunk3` (after ``n_steps``)."""
        return tuple(getattr(self, f.name) for f in fields(self))

    @property
    def tool_frame(self) -> bool:
        """Whether the state carries the tool-frame ALE arrays (the loop with the ALE pass,
        :func:`kernels3d.run_chunk3_ale`, runs it)."""
        return self.x0.shape[0] > 0

    def attach_tool_frame(self, acls: np.ndarray, aflt: np.ndarray, bflag: np.ndarray) -> None:
        """Give the state the tool-frame ALE arrays: the current node positions as the
        nodes' places, the node classes ``acls`` (n, 7), the placement data ``aflt`` (n, 6),
        the faces' flux flags ``bflag`` (e, 6), and the scratch arrays."""
        n = self.x.shape[0]
        ne = self.conn.shape[0]
        acls = np.ascontiguousarray(acls, np.int64)
        aflt = np.ascontiguousarray(aflt, np.float64)
        bflag = np.ascontiguousarray(bflag, np.int64)
        if acls.shape != (n, 7) or aflt.shape != (n, 6) or bflag.shape != (ne, 6):
            raise ConfigError("tool-frame arrays do not match the mesh", field="acls, aflt, "
                              "bflag", value=f"{acls.shape}, {aflt.shape}, {bflag.shape}",
                              expected=f"({n}, 7), ({n}, 6), ({ne}, 6)")
        self.x0, self.y0, self.z0 = self.x.copy(), self.y.copy(), self.z.copy()
        self.acls, self.aflt, self.bflag = acls, aflt, bflag
        self.xn, self.yn, self.zn = np.zeros(n), np.zeros(n), np.zeros(n)
        self.buf = np.zeros((ne, N_RZ3))
        self.vbuf = np.zeros((n, 3))
        self.scratch = np.zeros((n, 3))

    def set_inertia_factors(self, msf: np.ndarray) -> None:
        """Give the tool-frame state the element inertia factors ``msf`` (e,) >= 1 (mass
        scaling attached to the mesh, not to the material that flows through it): the lumped
        masses become ``rho_s vol0 msf / 8`` a corner (the ALE pass keeps them so), the
        stable step of each element ``sqrt(msf)`` times its material one; the initial step
        is recomputed."""
        if not self.tool_frame:
            raise ConfigError("inertia factors need the tool-frame arrays",
                              field="msf", value="workpiece-frame state",
                              expected="a state with attach_tool_frame")
        msf = np.ascontiguousarray(msf, np.float64)
        if msf.shape != self.vol0.shape or not np.all(msf >= 1.0):
            raise ConfigError("inertia factors must be >= 1, one per element", field="msf",
                              value=f"shape {msf.shape}, min {float(np.min(msf, initial=1))}",
                              expected=f"({self.vol0.shape[0]},), >= 1")
        self.msf = msf
        rho_s = self.mat[MAT_RHO] * self.prm[layout3d.P_MS]
        mass = np.zeros_like(self.mass)
        np.add.at(mass, self.conn.ravel(),
                  np.repeat(self.vol0 * rho_s * msf / 8.0, 8))
        self.mass[:] = mass
        init_forces3(self)

    @property
    def twin(self) -> np.ndarray:
        """Partner of each node on a parting surface (-1: none), a view."""
        return self.pairs[:, 0]

    @property
    def tied(self) -> np.ndarray:
        """1 while a node's pair is tied, a view."""
        return self.pairs[:, 1]

    @property
    def n_elements(self) -> int:
        return int(self.conn.shape[0])

    @property
    def time(self) -> float:
        return float(self.clock[0])

    def nodes(self) -> np.ndarray:
        """Current nodal positions, shape (n, 3) [m]."""
        return np.stack([self.x, self.y, self.z], axis=1)


def default_prm3() -> np.ndarray:
    """Parameter vector with neutral values (no insert, no support, no erosion)."""
    p = np.zeros(layout3d.N_PRM)
    p[layout3d.P_CFL] = 0.8
    p[layout3d.P_MS] = 1.0
    p[layout3d.P_HGV] = 0.05
    p[layout3d.P_HGS] = 0.05
    p[layout3d.P_BV1] = 0.06
    p[layout3d.P_BV2] = 1.2
    p[layout3d.P_PEN] = 0.1
    p[layout3d.P_TAU] = 1e30
    p[layout3d.P_SAMPLE_DT] = 1e30
    p[layout3d.P_TEND] = 1e30
    p[layout3d.P_EROSION] = layout3d.ERODE_NONE
    p[layout3d.P_GATE] = -1.0
    p[layout3d.P_KAPPA] = np.pi / 2
    p[layout3d.P_KEND] = np.radians(5.0)
    p[layout3d.P_RN] = 1e-3
    p[layout3d.P_COND_EVERY] = 0  # adiabatic
    return p


def hex_volumes(nodes: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Exact volumes of trilinear hexahedra (2x2x2 Gauss), shape (e,) [m^3]."""
    xe = nodes[conn]  # (e, 8, 3)
    g = 1.0 / np.sqrt(3.0)
    vol = np.zeros(conn.shape[0])
    for a in (-g, g):
        for b in (-g, g):
            for c in (-g, g):
                xi = np.array([a, b, c])
                fac = [1.0 + HEX_SIGNS[:, k] * xi[k] for k in range(3)]
                dN = np.empty((8, 3))
                dN[:, 0] = HEX_SIGNS[:, 0] * fac[1] * fac[2] / 8
                dN[:, 1] = HEX_SIGNS[:, 1] * fac[0] * fac[2] / 8
                dN[:, 2] = HEX_SIGNS[:, 2] * fac[0] * fac[1] / 8
                J = np.einsum("eia,ib->eab", xe, dN)
                vol += np.linalg.det(J)
    return vol


def make_state3(nodes: np.ndarray, conn: np.ndarray, fixed: np.ndarray, material: Material,
                prm: np.ndarray | None = None, n_samples: int = 1,
                layer: np.ndarray | None = None,
                tool_tip: tuple[float, float, float] = (1e3, 1e3, 1e3),
                twin: np.ndarray | None = None) -> FEState3:
    """State for a hexahedral mesh ``nodes`` (n, 3) [m], ``conn`` (e, 8) in VTK order.

    ``fixed`` (n,) bit mask (1 x, 2 y, 4 z: velocity component held at its value, i.e.
    zero unless set). Lumped nodal masses from the (mass-scaled) density; stresses zero;
    temperature T_room. The insert's tip reference starts at ``tool_tip`` [m]. ``layer`` (e,)
    marks the elements that may erode by damage under ERODE_LAYER. ``twin`` (n,) pairs the
    doubled nodes of a parting surface (node splitting, -1 = none); the pairs start tied.
    """
    nodes = np.ascontiguousarray(nodes, dtype=np.float64)
    conn = np.ascontiguousarray(conn, dtype=np.int64)
    if nodes.ndim != 2 or nodes.shape[1] != 3 or conn.ndim != 2 or conn.shape[1] != 8:
        raise ConfigError("mesh must be nodes (n, 3) and conn (e, 8)", field="mesh",
                          value=f"{nodes.shape}, {conn.shape}", expected="(n, 3), (e, 8)")
    n = nodes.shape[0]
    ne = conn.shape[0]
    prm = default_prm3() if prm is None else np.asarray(prm, np.float64).copy()
    vol = hex_volumes(nodes, conn)
    if np.any(vol <= 0):
        bad = int(np.argmin(vol))
        raise ConfigError("mesh has a hexahedron with non-positive volume (node order must "
                          "be the VTK order)", field="conn", value=bad)
    mass = np.zeros(n)
    np.add.at(mass, conn.ravel(), np.repeat(vol * material.rho * prm[layout3d.P_MS] / 8.0, 8))
    counts = np.bincount(conn.ravel(), minlength=n)
    ptr = np.zeros(n + 1, dtype=np.int64)
    ptr[1:] = np.cumsum(counts)
    order = np.argsort(conn.ravel(), kind="stable")
    z = np.zeros
    tw = -np.ones(n, np.int64) if twin is None else np.asarray(twin, np.int64)
    if tw.shape != (n,) or np.any(tw >= n) or np.any(
            tw[tw[tw >= 0]] != np.flatnonzero(tw >= 0)):
        raise ConfigError("twin must pair nodes symmetrically", field="twin",
                          value=str(tw.shape), expected=f"(n,) = ({n},), twin[twin[i]] = i")
    try:
        enbr = face_neighbours(conn, tw)
    except ValueError as exc:
        raise ConfigError(f"mesh is not a valid hexahedral mesh: {exc}", field="conn",
                          value=f"{ne} elements", expected="each face shared by at most two "
                          "hexahedra") from None
    tool = z(scalar3d.N_TOOL)
    tool[scalar3d.T_GX], tool[scalar3d.T_GY], tool[scalar3d.T_GZ] = tool_tip
    tool[scalar3d.T_THETA] = prm[layout3d.P_THETA0]
    if prm[layout3d.P_TTOOL] <= 0.0:
        prm[layout3d.P_TTOOL] = material.T_room
    st = FEState3(
        x=nodes[:, 0].copy(), y=nodes[:, 1].copy(), z=nodes[:, 2].copy(), vx=z(n), vy=z(n),
        vz=z(n), mass=mass, fixed=np.asarray(fixed, dtype=np.int64).copy(), ptr=ptr,
        nel=(order // 8).astype(np.int64), ncorner=(order % 8).astype(np.int64), conn=conn,
        alive=np.ones(ne, np.int64),
        layer=np.zeros(ne, np.bool_) if layer is None else np.asarray(layer, np.bool_).copy(),
        sd=z((ne, 6)), pres=z(ne), eps_p=z(ne),
        temp=np.full(ne, material.T_room), dmg=z(ne), qh=z((ne, 12)), vol0=vol, ie=z(ne),
        hge=z(ne), fe=z((ne, 24)), dte=z(ne), plast=z(ne), rate=z(ne), cf=z((n, 4)),
        fric=z(n), pen=z(n), ndead=np.zeros(n, np.bool_), ero_ke=z(n), nwork=z(n),
        mat=material.to_array(), prm=prm, tool=tool, en=z(layout.N_EN),
        ist=np.zeros(layout.N_IST, np.int64), clock=z(3), hacc=z(scalar3d.N_HIST),
        hist=np.full((max(1, n_samples), scalar3d.N_HIST), np.nan),
        pairs=np.ascontiguousarray(np.stack([tw, (tw >= 0).astype(np.int64)], axis=1)),
        enbr=enbr, tbuf=z((ne, 4)),
        theat=z((n, 3)))
    init_forces3(st)
    return st


def element_steps3(st: FEState3) -> np.ndarray:
    """The material stable step (e,) [s] of each element in the current configuration, at
    rest (the element update's own estimate, without the inertia factors; the state is not
    changed)."""
    dte = np.zeros_like(st.dte)
    copies = {f: getattr(st, f).copy() for f in ("alive", "sd", "pres", "eps_p", "temp", "dmg",
                                                   "qh", "ie", "hge", "plast", "rate")}
    nodes, cells, elems, out, _ = groups3_of(st, vx=st.vx * 0.0, vy=st.vy * 0.0,
                                             vz=st.vz * 0.0, fe=np.zeros_like(st.fe), dte=dte,
                                             **copies)
    K3.element_update3(nodes, cells, st.layer, elems, out, st.mat, st.prm, 1e-30,
                       layout3d.ERODE_NONE)
    return dte


def init_forces3(st: FEState3) -> float:
    """Stable step of the current configuration (no stress update); sets ``clock[1]``."""
    dte = element_steps3(st)
    if st.msf.shape[0] > 0:
        dte = dte * np.sqrt(st.msf)
    dt = st.prm[layout3d.P_CFL] * float(np.min(dte))
    st.clock[1] = dt
    if st.prm[layout3d.P_DTMIN] <= 0:
        st.prm[layout3d.P_DTMIN] = 1e-3 * dt
    if st.prm[layout3d.P_DT_ERODE] < 0:  # given as a fraction of the initial step: make absolute
        st.prm[layout3d.P_DT_ERODE] = -st.prm[layout3d.P_DT_ERODE] * float(np.min(dte))
    return dt


def heat_pass(prm: np.ndarray) -> bool:
    """Whether a 3D state's parameter vector asks for the heat pass (``prm[P_COND_EVERY]``
    >= 1 steps) or none (0: adiabatic); ConfigError for an interval between."""
    every = float(prm[layout3d.P_COND_EVERY])
    if every != 0.0 and every < 1.0:
        raise ConfigError("the heat pass needs an interval of at least one step (0: adiabatic)",
                          field="prm[P_COND_EVERY]", value=every, expected="0 or >= 1")
    return every >= 1.0


#: what to try when a 3D run becomes unstable (the message of NumericalError)
_HINT = ("a smaller solver.cfl, a larger mesh.element_size_um, less mass scaling or a softer "
         "contact.penalty_factor")
_TOOL_FRAME_HINT = (_HINT + "; in the tool frame (the default) a larger mesh.t_min_um, or "
                    '[mesh] frame = "workpiece" (docs/fe3d.md, "Tool-frame 3D model": where '
                    "the tool frame is checked)")


def advance3(st: FEState3, t_end: float, *, chunk_steps: int = 500,
             progress: Callable[[float], None] | None = None,
             check: Callable[[FEState3], None] | None = None,
             adaptive_threads: bool = True, governor: ThreadGovernor | None = None,
             step: Callable[..., int] | None = None) -> int:
    """Run the compiled loop until time ``t_end`` [s]; returns the number of steps taken.
    ``step``: the compiled chunk function (:func:`kernels3d.run_chunk3_for` of the model
    spec); default the one of the state (:data:`kernels3d.RUN_CHUNK3`): with the tool-frame
    ALE pass every ``prm[P_RZ_EVERY]`` steps for a state with the tool-frame arrays
    (:meth:`FEState3.attach_tool_frame`), with the heat pass for a state whose
    ``prm[P_COND_EVERY]`` is at least one step. ConfigError when a given loop and the state
    disagree.

    ``progress(fraction_done)`` and ``check(state)`` (may raise) are called between chunks.
    Raises NumericalError (step, time, cause, what to change) on instability.
    ``adaptive_threads``, ``governor``: see
    :func:`~robobore.cutting.fe.engine.chunk_driver.drive_chunks`.
    """
    if st.tool_frame and st.prm[layout3d.P_RZ_EVERY] < 1:
        raise ConfigError("the tool-frame ALE pass needs an interval of at least one step",
                          field="prm[P_RZ_EVERY]", value=float(st.prm[layout3d.P_RZ_EVERY]),
                          expected=">= 1")
    choice = (bool(st.tool_frame), heat_pass(st.prm))
    run = K3.RUN_CHUNK3[choice] if step is None else step
    if run is not K3.RUN_CHUNK3[choice]:
        raise ConfigError("the 3D loop and the state's frame or thermal model disagree",
                          field="step", value=getattr(run, "__name__", str(run)),
                          expected=f"{K3.RUN_CHUNK3[choice].__name__} for a state "
                          f"{'with' if choice[0] else 'without'} the tool-frame arrays and "
                          f"{'with' if choice[1] else 'without'} a heat-pass interval")
    return drive_chunks(st, t_end, run, layout3d.P_TEND, chunk_steps=chunk_steps,
                        label="3D simulation",
                        hint=_TOOL_FRAME_HINT if st.tool_frame else _HINT,
                        progress=progress, check=check, adaptive_threads=adaptive_threads,
                        governor=governor)


def box_mesh(nx: int, ny: int, nz: int, lx: float, ly: float, lz: float,
             origin: tuple[float, float, float] = (0.0, 0.0, 0.0)):
    """Structured hexahedral box: nodes (n, 3) [m], conn (e, 8) (VTK order), node index grid.

    Node (i, j, k) is ``(i * (ny + 1) + j) * (nz + 1) + k`` along x, y, z.
    """
    xs = origin[0] + np.linspace(0.0, lx, nx + 1)
    ys = origin[1] + np.linspace(0.0, ly, ny + 1)
    zs = origin[2] + np.linspace(0.0, lz, nz + 1)
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    nodes = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)
    idx = np.arange(nodes.shape[0]).reshape(nx + 1, ny + 1, nz + 1)
    return nodes, hex_conn(idx), idx


def hex_conn(idx: np.ndarray) -> np.ndarray:
    """Connectivity (e, 8), VTK order, of a structured node-index grid idx (i, j, k)."""
    a = idx[:-1, :-1, :-1]
    b = idx[1:, :-1, :-1]
    c = idx[1:, 1:, :-1]
    d = idx[:-1, 1:, :-1]
    e = idx[:-1, :-1, 1:]
    f = idx[1:, :-1, 1:]
    g = idx[1:, 1:, 1:]
    h = idx[:-1, 1:, 1:]
    return np.stack([a, b, c, d, e, f, g, h], axis=-1).reshape(-1, 8).astype(np.int64)


def split_node_layer(nodes: np.ndarray, conn: np.ndarray, fixed: np.ndarray, idx: np.ndarray,
                     j: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Node splitting on node layer ``j`` of a structured mesh (``idx`` from :func:`box_mesh`
    or the like, elements in :func:`hex_conn` order): its nodes that are not fully fixed are
    doubled, the elements of rows ``>= j`` take the copies (which inherit the fixed bits).
    Returns ``(nodes, conn, fixed, twin)`` with ``twin`` pairing each copy with its original.
    """
    nx, ny, nz = (k - 1 for k in idx.shape)
    line = idx[:, j, :].ravel()
    line = line[fixed[line] != 7]
    new = nodes.shape[0] + np.arange(line.size)
    nodes = np.vstack([nodes, nodes[line]])
    fixed = np.concatenate([fixed, fixed[line]])
    remap = np.arange(nodes.shape[0])
    remap[line] = new
    above = np.broadcast_to(np.arange(ny)[None, :, None], (nx, ny, nz)).ravel() >= j
    conn = conn.copy()
    conn[above] = remap[conn[above]]
    twin = -np.ones(nodes.shape[0], np.int64)
    twin[line] = new
    twin[new] = line
    return nodes, conn, fixed, twin
