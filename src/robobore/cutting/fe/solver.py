"""Explicit solver: state arrays, the chunked central-difference loop, instability checks.

:class:`FEState` holds every array of a model (structure of arrays); :func:`make_state`
builds one from any quad mesh (used by the cutting model and by the element/bar tests);
:func:`advance` runs the compiled loop in chunks (progress between chunks) and turns a
non-finite state or a collapsing time step into :class:`robobore.errors.NumericalError`.
:func:`simulate_orthogonal` sets up and runs the orthogonal-cutting model from a config.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numba
import numpy as np

from robobore.cutting.fe import kernels as K
from robobore.cutting.fe.config import FEConfig
from robobore.cutting.fe.mesh import CuttingMesh, build_edge_refined_mesh, build_mesh
from robobore.cutting.fe.rezone import (
    MODE_ROWS,
    MODE_TOOLFRAME,
    N_RZ_FIELDS,
    TF_RIGID,
    edge_neighbours,
    row_stencil,
    smoothing_stencil,
)
from robobore.cutting.fe.status import STATUS_TEXT, instability_error
from robobore.cutting.fe.threads import ThreadGovernor
from robobore.errors import ConfigError, NumericalError
from robobore.material import Material, load_material


@dataclass
class FEState:
    """All arrays of an explicit model (SI, per unit width). Shapes: nodes (n,), elements (e,)."""

    x: np.ndarray
    y: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    mass: np.ndarray
    fixed: np.ndarray
    ptr: np.ndarray
    nel: np.ndarray
    ncorner: np.ndarray
    conn: np.ndarray
    layer: np.ndarray
    alive: np.ndarray
    sdx: np.ndarray
    sdy: np.ndarray
    sdz: np.ndarray
    sdxy: np.ndarray
    pres: np.ndarray
    eps_p: np.ndarray
    temp: np.ndarray
    dmg: np.ndarray
    qhx: np.ndarray
    qhy: np.ndarray
    area0: np.ndarray
    ie: np.ndarray
    hge: np.ndarray
    fex: np.ndarray
    fey: np.ndarray
    dte: np.ndarray
    plast: np.ndarray
    rate: np.ndarray
    cfx: np.ndarray
    cfy: np.ndarray
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
    enbr: np.ndarray = field(default=None)  # type: ignore[assignment]
    snodes: np.ndarray = field(default=None)  # type: ignore[assignment]
    snbr: np.ndarray = field(default=None)  # type: ignore[assignment]
    xn: np.ndarray = field(default=None)  # type: ignore[assignment]
    yn: np.ndarray = field(default=None)  # type: ignore[assignment]
    buf: np.ndarray = field(default=None)  # type: ignore[assignment]
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
    #: rezoning: velocity increments of the moved nodes (n_nodes, 2), scratch
    vbuf: np.ndarray = field(default=None)  # type: ignore[assignment]
    #: tool-frame ALE (``mesh.frame = "tool"``, robobore.cutting.fe.toolframe): node classes
    #: and neighbours (n, 7), node data (n, 6), flux type of each element edge (e, 4); empty
    #: for the Lagrangian models
    acls: np.ndarray = field(default=None)  # type: ignore[assignment]
    aflt: np.ndarray = field(default=None)  # type: ignore[assignment]
    bflag: np.ndarray = field(default=None)  # type: ignore[assignment]
    #: friction by sliding speed: each node's filtered sliding speed [m/s] (n_nodes,)
    vslip: np.ndarray = field(default=None)  # type: ignore[assignment]

    def kernel_args(self) -> tuple:
        return (self.x, self.y, self.vx, self.vy, self.mass, self.fixed, self.ptr, self.nel,
                self.ncorner, self.conn, self.layer, self.alive, self.sdx, self.sdy, self.sdz,
                self.sdxy, self.pres, self.eps_p, self.temp, self.dmg, self.qhx, self.qhy,
                self.area0, self.ie, self.hge, self.fex, self.fey, self.dte, self.plast,
                self.rate, self.cfx, self.cfy, self.fric, self.pen, self.ndead, self.ero_ke,
                self.nwork, self.mat, self.prm, self.tool, self.en, self.ist, self.clock,
                self.hacc, self.hist, self.enbr, self.snodes, self.snbr, self.xn, self.yn,
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
    p = np.zeros(K.N_PRM)
    p[K.P_CFL] = 0.8
    p[K.P_MS] = 1.0
    p[K.P_HGV] = 0.05
    p[K.P_HGS] = 0.05
    p[K.P_BV1] = 0.06
    p[K.P_BV2] = 1.2
    p[K.P_DIST] = 0.0
    p[K.P_PEN] = 0.1
    p[K.P_TAU] = 1e30
    p[K.P_R] = 0.0
    # tool far away: rake normal (-1, 0), flank normal (0, -1)
    p[K.P_NRX], p[K.P_NRY], p[K.P_NFX], p[K.P_NFY] = -1.0, 0.0, 0.0, -1.0
    p[K.P_WIDTH] = 1.0
    p[K.P_SAMPLE_DT] = 1e30
    p[K.P_TEND] = 1e30
    p[K.P_EROSION] = K.ERODE_NONE
    p[K.P_GATE] = -1.0
    return p


def make_state(nodes: np.ndarray, conn: np.ndarray, fixed: np.ndarray, material: Material,
               prm: np.ndarray | None = None, layer: np.ndarray | None = None,
               n_samples: int = 1, tool_center: tuple[float, float] = (1e3, 1e3),
               twin: np.ndarray | None = None) -> FEState:
    """State for a quad mesh ``nodes`` (n, 2) [m], ``conn`` (e, 4) counter-clockwise.

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
    np.add.at(mass, conn.ravel(), np.repeat(area * material.rho * prm[K.P_MS] / 4.0, 4))
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
    tool = np.zeros(K.N_TOOL)
    tool[K.T_GX], tool[K.T_GY] = tool_center
    z = np.zeros
    st = FEState(
        x=xs, y=ys, vx=z(n), vy=z(n), mass=mass, fixed=np.asarray(fixed, dtype=np.bool_),
        ptr=ptr, nel=nel, ncorner=nco, conn=conn,
        layer=np.zeros(ne, np.bool_) if layer is None else np.asarray(layer, np.bool_),
        alive=np.ones(ne, np.int64), sdx=z(ne), sdy=z(ne), sdz=z(ne), sdxy=z(ne), pres=z(ne),
        eps_p=z(ne), temp=np.full(ne, material.T_room), dmg=z(ne), qhx=z(ne), qhy=z(ne),
        area0=area.copy(), ie=z(ne), hge=z(ne), fex=z((ne, 4)), fey=z((ne, 4)),
        dte=z(ne), plast=z(ne), rate=z(ne), cfx=z(n), cfy=z(n), fric=z(n), pen=z(n),
        ndead=np.zeros(n, np.bool_), ero_ke=z(n), nwork=z(n), mat=mat, prm=prm, tool=tool,
        en=z(K.N_EN), ist=np.zeros(K.N_IST, np.int64), clock=z(3), hacc=z(K.N_HIST),
        hist=np.full((max(1, n_samples), K.N_HIST), np.nan), x0=xs.copy(), y0=ys.copy(),
        enbr=edge_neighbours(conn), snodes=np.zeros(0, np.int64),
        snbr=np.zeros((0, 6), np.int64), xn=z(n), yn=z(n), buf=z((ne, N_RZ_FIELDS)),
        twin=(-np.ones(n, np.int64) if twin is None else np.asarray(twin, np.int64)),
        tied=(np.zeros(n, np.int64) if twin is None
              else (np.asarray(twin) >= 0).astype(np.int64)),
        tbuf=z((ne, 4)),
        gps=z((ne if int(prm[K.P_ELEM]) == K.ELEM_Q4BBAR else 0, 4, K.N_GPS)),
        fheat=z(n), tcq=z((n, 2)), ppair=parting_edges(conn, twin), vbuf=z((n, 2)),
        acls=np.zeros((0, 7), np.int64), aflt=z((0, 6)), bflag=np.zeros((0, 4), np.int64),
        vslip=z(n))
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
    K.element_update(st.conn, st.x, st.y, st.vx * 0.0, st.vy * 0.0, st.alive, st.layer,
                     st.sdx.copy(), st.sdy.copy(), st.sdz.copy(), st.sdxy.copy(),
                     st.pres.copy(), st.eps_p.copy(), st.temp.copy(), st.dmg.copy(),
                     st.qhx.copy(), st.qhy.copy(), st.area0, st.ie.copy(), st.hge.copy(),
                     st.fex, st.fey, st.dte, st.plast.copy(), st.rate.copy(), st.mat, st.prm,
                     1e-30, K.ERODE_NONE)
    dt = st.prm[K.P_CFL] * float(np.min(st.dte))
    st.clock[1] = dt
    if st.prm[K.P_DTMIN] <= 0:
        st.prm[K.P_DTMIN] = 1e-3 * dt
    if st.prm[K.P_DT_ERODE] < 0:  # given as a fraction of the initial step: make absolute
        st.prm[K.P_DT_ERODE] = -st.prm[K.P_DT_ERODE] * float(np.min(st.dte))
    return dt


def drive_chunks(st: Any, t_end: float, run_chunk: Callable[..., int], p_tend: int, *,
                 chunk_steps: int, label: str, hint: str,
                 progress: Callable[[float], None] | None = None,
                 check: Callable[[Any], None] | None = None,
                 adaptive_threads: bool = True,
                 governor: ThreadGovernor | None = None) -> int:
    """Run a compiled chunk loop (2D ``run_chunk`` or 3D ``run_chunk3``) until ``t_end`` [s].

    Shared by :func:`advance` and :func:`~robobore.cutting.fe.solver3d.advance3`: ``st`` has
    ``prm``, ``ist``, ``time`` and ``kernel_args()``; ``p_tend`` is the index of the end time in
    that engine's ``prm``. ``progress(fraction_done)`` and ``check(state)`` (may raise) are
    called between chunks. Raises NumericalError (``label``, step, time, cause, ``hint``) on
    instability; returns the number of steps taken.

    ``adaptive_threads`` (default): each chunk runs on the thread count a
    :class:`~robobore.cutting.fe.threads.ThreadGovernor` (``governor``, or a fresh one) finds
    faster, all of numba's threads or one, so that a run sharing the cores with other work
    keeps its share; the results do not depend on it. False: numba's thread count throughout.
    numba's thread count is restored on return.
    """
    st.prm[p_tend] = t_end
    st.ist[K.I_STATUS] = K.STATUS_OK
    total = 0
    t_start = st.time
    gov = ThreadGovernor() if governor is None else governor
    threads_before = numba.get_num_threads()
    try:
        while True:
            threads, steps = gov.next_chunk(chunk_steps) if adaptive_threads \
                else (threads_before, chunk_steps)
            numba.set_num_threads(threads)
            t0 = time.perf_counter()
            taken = run_chunk(steps, *st.kernel_args())
            if adaptive_threads:
                gov.record(threads, int(taken), time.perf_counter() - t0)
            total += int(taken)
            status = int(st.ist[K.I_STATUS])
            if status in STATUS_TEXT:
                raise instability_error(st, label, hint)
            if progress is not None:
                progress(min(1.0, (st.time - t_start) / max(t_end - t_start, 1e-300)))
            if check is not None:
                check(st)
            if status == K.STATUS_DONE or st.time >= t_end:
                return total
    finally:
        numba.set_num_threads(threads_before)


def advance(st: FEState, t_end: float, *, chunk_steps: int = 2000,
            progress: Callable[[float], None] | None = None,
            check: Callable[[FEState], None] | None = None,
            adaptive_threads: bool = True, governor: ThreadGovernor | None = None) -> int:
    """Run the compiled loop until time ``t_end`` [s]; returns the number of steps taken.

    ``progress(fraction_done)`` is called between chunks; ``check(state)`` too (it may raise).
    Raises NumericalError (with step, time and cause) on instability. ``adaptive_threads``,
    ``governor``: see :func:`drive_chunks`.
    """
    return drive_chunks(st, t_end, K.run_chunk, K.P_TEND, chunk_steps=chunk_steps,
                        label="simulation",
                        hint="a smaller solver.cfl, a larger mesh.element_size_um or less "
                        "mass scaling", progress=progress, check=check,
                        adaptive_threads=adaptive_threads, governor=governor)


# ----------------------------------------------------------------- orthogonal cutting model


@dataclass
class CuttingSetup:
    """Everything derived from a config before the run."""

    cfg: FEConfig
    material: Material
    mesh: CuttingMesh
    state: FEState
    h: float
    vc: float
    rake: float
    t_end: float
    t_contact: float
    mu: float
    #: tool edge centre x [m] at which the cut length is 0 (the cut position of a sample is
    #: this minus the edge centre's x)
    x_cut_start: float = math.nan


def apply_solver_settings(p: np.ndarray, s: Any, kernels: Any) -> np.ndarray:
    """Write the solver settings shared by the 2D and 3D configs into ``p`` (returned).

    ``s`` is a ``[solver]`` section (2D or 3D), ``kernels`` the engine's kernel module (its
    ``P_*`` indices and ``ERODE_*`` codes).
    """
    k = kernels
    p[k.P_CFL] = s.cfl
    p[k.P_MS] = s.mass_scaling
    p[k.P_HGV] = s.hourglass_viscous
    p[k.P_HGS] = s.hourglass_stiffness
    p[k.P_BV1] = s.bulk_viscosity_linear
    p[k.P_BV2] = s.bulk_viscosity_quadratic
    p[k.P_DIST] = s.distortion_limit
    p[k.P_DT_ERODE] = -s.erode_time_step_fraction
    p[k.P_EROSION] = {"none": k.ERODE_NONE, "layer": k.ERODE_LAYER,
                      "everywhere": k.ERODE_ALL}[s.erosion]
    if hasattr(k, "P_ELEM"):
        p[k.P_ELEM] = {"q4r": k.ELEM_Q4R, "q4_bbar": k.ELEM_Q4BBAR}[s.element]
    return p


def apply_thermal_settings(p: np.ndarray, solver: Any, contact: Any, material: Material,
                           kernels: Any) -> np.ndarray:
    """Write the heat conduction (``solver.heat_conduction``, ``conduction_interval``) and the
    thermal contact with the tool (``contact.thermal_conductance_W_per_m2K``,
    ``friction_heat_fraction``, ``tool_temperature_K``; None: the material's room
    temperature) into ``p`` (returned); shared by the 2D and 3D engines."""
    k = kernels
    p[k.P_COND_EVERY] = solver.conduction_interval if solver.heat_conduction else 0
    p[k.P_HC] = contact.thermal_conductance_W_per_m2K
    p[k.P_FHEAT] = contact.friction_heat_fraction
    p[k.P_TTOOL] = (material.T_room if contact.tool_temperature_K is None
                    else contact.tool_temperature_K)
    return p


def apply_friction_settings(p: np.ndarray, contact: Any, vc_m_per_min: float,
                            kernels: Any) -> np.ndarray:
    """Write the friction of a ``[contact]`` section into ``p`` (returned); shared by the 2D
    and 3D engines.

    ``contact`` is a :class:`robobore.cutting.fe.config.ContactSection` (or the 3D engine's,
    built on it), ``vc_m_per_min`` the cutting speed, ``kernels`` the engine's kernel module (its
    ``P_MU``, ``P_TAU``, ``P_MUTAB_*`` and ``P_SLIP_TAU`` slots). ``P_MU``: the constant, or
    the table at the cutting speed; with ``friction_velocity = "sliding"`` the table goes into
    the ``P_MUTAB_*`` slots (velocities in m/s) and every contact node reads it at its own
    sliding speed, filtered over the time the tool takes to travel ``sliding_filter_um``.
    """
    k = kernels
    p[k.P_MU] = contact.coefficient_at(vc_m_per_min)
    if contact.friction == "table" and contact.friction_velocity == "sliding":
        tv, tmu = contact.table()
        p[k.P_MUTAB_N] = tv.size
        p[k.P_MUTAB_V:k.P_MUTAB_V + tv.size] = tv / 60.0
        p[k.P_MUTAB_MU:k.P_MUTAB_MU + tv.size] = tmu
        p[k.P_SLIP_TAU] = contact.sliding_filter_um * 1e-6 / (vc_m_per_min / 60.0)
    p[k.P_TAU] = contact.shear_limit_MPa * 1e6
    return p


def _layer_offset(cfg: FEConfig, le: float) -> float:
    """Top of the separation layer above the cut line, in element sizes (see build_mesh)."""
    if cfg.mesh.separation_height_um is not None:
        return 1.0 + cfg.mesh.separation_height_um * 1e-6 / le
    return {"above_cut_line": 1.0, "centred": 0.5, "below_cut_line": 0.0}[
        cfg.mesh.separation_layer]


def _split_height(cfg: FEConfig) -> float | None:
    """Parting-line height above the cut line [m] for node splitting, else None."""
    if cfg.mesh.separation != "node_split":
        return None
    sh = cfg.mesh.separation_height_um
    return (0.0 if sh is None else sh) * 1e-6


def _m_or_none(um: float | None) -> float | None:
    """An optional length in um as metres (None stays None: the mesh builder's default)."""
    return None if um is None else um * 1e-6


def setup_orthogonal(cfg: FEConfig, source: str | None = None) -> CuttingSetup:
    """Build mesh, tool and state for the orthogonal-cutting model of ``cfg``."""
    mat = load_material(cfg.material.name, source=source,
                        hardening_strain_limit=cfg.material.strain_limit())
    h = cfg.cut.uncut_chip_thickness_um * 1e-6
    le = cfg.mesh.element_size_um * 1e-6
    L = cfg.cut.length_mm * 1e-3
    vc = cfg.cut.cutting_speed_m_per_min / 60.0
    r = cfg.tool.edge_radius_um * 1e-6
    rake = math.radians(cfg.tool.rake_deg)
    clr = math.radians(cfg.tool.clearance_deg)
    cm = cfg.mesh
    tool_frame = cm.frame == "tool"
    if tool_frame:
        from robobore.cutting.fe.toolframe import build_toolframe_mesh

        ee = (cm.element_size_um / 4.0 if cm.edge_element_um is None else cm.edge_element_um)
        try:
            mesh = build_toolframe_mesh(
                h, r, rake, clr, element_size=le, edge_size=ee * 1e-6,
                chip_ratio=cm.initial_chip_ratio,
                join_height=_m_or_none(cm.join_height_um),
                chip_length=_m_or_none(cm.chip_length_um), depth=_m_or_none(cm.depth_um),
                ahead=_m_or_none(cm.inflow_length_um), behind=_m_or_none(cm.back_length_um))
        except ValueError as exc:
            raise ConfigError(str(exc), file=source, field="mesh.initial_chip_ratio",
                              value=cm.initial_chip_ratio,
                              expected="a larger initial chip ratio (the chip's root must "
                              "lie ahead of the edge)") from exc
    elif cm.edge_element_um is not None:
        try:
            mesh = build_edge_refined_mesh(
                h, le, L, split_height=_split_height(cfg) or 0.0,
                levels=int(round(math.log2(cm.element_size_um / cm.edge_element_um))),
                band_above=cm.edge_band_um[0] * 1e-6, band_below=cm.edge_band_um[1] * 1e-6,
                ahead=cm.ahead_mm * 1e-3, fine_depth_factor=cm.fine_depth_factor,
                height_factor=cm.height_factor, grading=cm.grading)
        except ValueError as exc:
            raise ConfigError(str(exc), file=source, field="mesh.edge_element_um",
                              value=cm.edge_element_um,
                              expected="fewer refinement levels, smaller elements or a "
                              "lower mesh.separation_height_um") from exc
    else:
        mesh = build_mesh(h, le, L, ahead=cm.ahead_mm * 1e-3,
                          fine_depth_factor=cm.fine_depth_factor,
                          height_factor=cm.height_factor, grading=cm.grading,
                          layer_offset=_layer_offset(cfg, le),
                          split_height=_split_height(cfg))
    s = cfg.solver
    p = apply_solver_settings(default_prm(), s, K)
    apply_friction_settings(p, cfg.contact, cfg.cut.cutting_speed_m_per_min, K)
    p[K.P_PEN] = cfg.contact.penalty_factor
    nd = cfg.contact.normal_damping
    p[K.P_CDAMP] = (1.0 if cm.frame == "tool" else 0.0) if nd is None else nd
    p[K.P_R] = r
    p[K.P_NRX], p[K.P_NRY] = -math.cos(rake), math.sin(rake)
    p[K.P_NFX], p[K.P_NFY] = math.sin(clr), -math.cos(clr)
    p[K.P_VC] = vc
    p[K.P_WIDTH] = cfg.cut.width_mm * 1e-3
    if tool_frame:
        cx0, cy0 = mesh.tool_center  # the mesh starts round the tool
        t_contact = 0.0
        t_end = L / vc
        x_cut_start = cx0
    else:
        gap0 = 0.5 * le
        cx0 = mesh.length + r + gap0
        cy0 = -h + r
        t_contact = gap0 / vc
        t_end = (L + r + gap0) / vc
        x_cut_start = mesh.length + r
    p[K.P_SAMPLE_DT] = t_end / s.n_samples
    ts = cfg.tool_support
    if ts is not None:
        p[K.P_SUPPORT] = 1.0
        p[K.P_KX], p[K.P_KY] = ts.stiffness_N_per_m  # type: ignore[misc]
        p[K.P_CX], p[K.P_CY] = ts.damping_N_s_per_m  # type: ignore[misc]
        p[K.P_MX], p[K.P_MY] = ts.mass_kg  # type: ignore[misc]
    p[K.P_RZ_EVERY] = s.rezone_interval
    p[K.P_RZ_OMEGA] = s.rezone_relaxation
    p[K.P_RZ_MAXMOVE] = 0.2
    if s.edge_ale_interval > 0:
        p[K.P_RZ_EVERY] = s.edge_ale_interval
        p[K.P_RZ_MODE] = MODE_ROWS
    apply_thermal_settings(p, s, cfg.contact, mat, K)
    if s.separation_gate_um is not None:
        p[K.P_GATE] = s.separation_gate_um * 1e-6
    elif cfg.mesh.separation == "node_split":
        p[K.P_GATE] = 0.0  # pairs part when they touch the tool
    if tool_frame:
        # no separation, no erosion (the mesh does not move with the material, and a hole
        # would have no flux rule); the ALE pass every solver.ale_interval steps
        p[K.P_EROSION] = K.ERODE_NONE
        p[K.P_DT_ERODE] = 0.0
        p[K.P_GATE] = -1.0
        p[K.P_RZ_EVERY] = s.ale_interval
        p[K.P_RZ_MODE] = MODE_TOOLFRAME
        p[K.P_ALE_X0], p[K.P_TCX], p[K.P_TCY] = cx0, cx0, cy0
    st = make_state(mesh.nodes, mesh.conn, mesh.fixed, mat, prm=p,
                    layer=getattr(mesh, "layer", None), n_samples=s.n_samples,
                    tool_center=(cx0, cy0), twin=getattr(mesh, "twin", None))
    if tool_frame:
        st.acls, st.aflt, st.bflag = mesh.acls.copy(), mesh.aflt.copy(), mesh.bflag.copy()
        st.snodes = np.where(mesh.acls[:, 0] != TF_RIGID)[0].astype(np.int64)
        st.snbr = np.zeros((st.snodes.size, 6), np.int64)
    if s.rezone_interval > 0:
        st.snodes, st.snbr = smoothing_stencil(mesh)
    if s.edge_ale_interval > 0:
        st.snodes, st.snbr = row_stencil(mesh, s.edge_ale_depth_um * 1e-6)
    if ts is not None:
        dt = st.clock[1]
        for i, (k, m) in enumerate(zip(ts.stiffness_N_per_m, ts.mass_kg, strict=True)):  # type: ignore[arg-type]
            if dt * math.sqrt(k / m) > 0.5:
                raise ConfigError("tool support too stiff for the explicit time step",
                                  file=source, field=f"tool_support.stiffness_N_per_m[{i}]",
                                  value=k, expected=f"k < {0.25 * m / dt**2:.3g} N/m for "
                                  f"mass {m} kg and time step {dt:.3g} s")
    return CuttingSetup(cfg=cfg, material=mat, mesh=mesh, state=st, h=h, vc=vc, rake=rake,
                        t_end=t_end, t_contact=t_contact, mu=float(p[K.P_MU]),
                        x_cut_start=x_cut_start)


def energy_error(en: np.ndarray) -> float:
    """|E_ext - (kinetic + internal + hourglass + contact + eroded kinetic)| / scale.

    Internal includes elastic, plastic and bulk-viscous work (and the internal energy of
    eroded elements); contact is frictional dissipation plus the current penalty energy.
    """
    parts = en[K.E_KIN] + en[K.E_INT] + en[K.E_HG] + en[K.E_FRIC] + en[K.E_EROKE]
    scale = max(abs(en[K.E_EXT]), abs(parts), 1e-300)
    return float(abs(en[K.E_EXT] - parts) / scale)


def check_device(device: str, cfg: FEConfig, source: str | None = None) -> None:
    """ConfigError unless ``device`` is "cpu" or a usable "gpu" that runs every option."""
    if device not in ("cpu", "gpu"):
        raise ConfigError("unknown device", field="--device", value=device,
                          expected="cpu or gpu")
    if device == "gpu":
        from robobore.cutting.fe.gpu import require_gpu
        from robobore.cutting.fe.gpu2d import check_gpu_supported

        check_gpu_supported(cfg.solver.rezone_interval, source, cfg.solver.element,
                            cfg.solver.edge_ale_interval)
        require_gpu()


def run_orthogonal(setup: CuttingSetup, progress: Callable[[float], None] | None = None,
                   device: str = "cpu"):
    """Run the cutting model to the end; returns (wall time [s], steps taken).

    ``device``: "cpu" (numba, parallel; the default) or "gpu" (numba-cuda,
    :func:`robobore.cutting.fe.gpu2d.advance_gpu`).
    """
    check_device(device, setup.cfg)
    st = setup.state
    limit = setup.cfg.solver.energy_error_limit

    def check(s: FEState) -> None:
        if s.time > setup.t_contact + 0.1 * (setup.t_end - setup.t_contact):
            err = energy_error(s.en)
            if err > limit:
                raise NumericalError(
                    f"energy balance lost at step {int(s.ist[K.I_STEP])}, time {s.time:.6g} s:"
                    f" error {err:.3g} > solver.energy_error_limit {limit}")

    t0 = time.perf_counter()
    if device == "gpu":
        from robobore.cutting.fe.gpu2d import advance_gpu

        steps = advance_gpu(st, setup.t_end, chunk_steps=setup.cfg.solver.chunk_steps,
                            progress=progress, check=check)
    else:
        steps = advance(st, setup.t_end, chunk_steps=setup.cfg.solver.chunk_steps,
                        progress=progress, check=check)
    return time.perf_counter() - t0, steps


def _final_fields(setup: CuttingSetup) -> dict[str, np.ndarray]:
    from robobore.cutting.fe.output import tool_outline

    st = setup.state
    cfg = setup.cfg
    cx = st.tool[K.T_GX] + st.tool[K.T_UX]
    cy = st.tool[K.T_GY] + st.tool[K.T_UY]
    sxx, syy, szz, sxy = st.sdx, st.sdy, st.sdz, st.sdxy
    vm = np.sqrt(1.5 * (sxx**2 + syy**2 + szz**2 + 2 * sxy**2))
    ox, oy = tool_outline(cx, cy, cfg.tool.edge_radius_um * 1e-6, setup.rake,
                          math.radians(cfg.tool.clearance_deg), 4 * setup.h)
    return {"x": st.x.copy(), "y": st.y.copy(), "x0": st.x0.copy(), "y0": st.y0.copy(),
            "conn": st.conn.copy(), "alive": st.alive.copy(), "eps_p": st.eps_p.copy(),
            "temperature_K": st.temp.copy(), "damage": st.dmg.copy(), "von_mises_Pa": vm,
            "pressure_Pa": st.pres.copy(), "tool_outline": np.array([ox, oy]),
            "tool_center": np.array([cx, cy]), "vx": st.vx.copy(), "vy": st.vy.copy(),
            "tool_velocity": np.array([-setup.vc + st.tool[K.T_VUX], st.tool[K.T_VUY]]),
            "deviatoric_stress_Pa": np.array([sxx, syy, szz, sxy]),
            "contact_force_N_per_m": np.array([st.cfx, st.cfy]),
            "sliding_speed_m_per_s": st.vslip.copy()}


def simulate_orthogonal(cfg: FEConfig, *, source: str | None = None,
                        progress: Callable[[float], None] | None = None,
                        device: str = "cpu"):
    """Set up and run the orthogonal-cutting model; returns an :class:`FEResult`.

    ``device``: "cpu" (default) or "gpu" (see :func:`run_orthogonal`); checked before the
    mesh is built.
    """
    from robobore.cutting.fe.output import (
        FEResult,
        chip_ratio_from_velocity,
        measure_chip,
        steady_window,
    )

    check_device(device, cfg, source)
    setup = setup_orthogonal(cfg, source)
    st = setup.state
    dt0 = float(st.clock[1])
    wall, steps = run_orthogonal(setup, progress, device)
    hist = st.hist
    ok = np.isfinite(hist[:, K.H_T])
    hh = hist[ok]
    t = hh[:, K.H_T]
    L = cfg.cut.length_mm * 1e-3
    frac = cfg.solver.steady_window_fraction
    t0w = setup.t_end - frac * L / setup.vc
    win = steady_window(t, t0w, setup.t_end + 1e-12)
    fc = hh[:, K.H_FX] * 1e-3
    ff = hh[:, K.H_FY] * 1e-3
    cut_pos_mm = (setup.x_cut_start - hh[:, K.H_TIP_X]) * 1e3
    if cfg.mesh.frame == "tool":
        from robobore.cutting.fe.toolframe import measure_chip_toolframe

        chip, r_vel, n_vel = measure_chip_toolframe(st, setup.mesh, setup.h, setup.rake,
                                                    setup.vc)
    else:
        chip = measure_chip(st, setup.mesh, setup.h, setup.rake, setup.vc)
        r_vel, n_vel = chip_ratio_from_velocity(st, setup.mesh, setup.h, setup.rake,
                                                setup.vc)
    en = st.en
    n_el = st.n_elements
    summary: dict[str, Any] = {
        "cutting_force_N_per_mm": float(np.mean(fc[win])),
        "feed_force_N_per_mm": float(np.mean(ff[win])),
        "cutting_force_std_N_per_mm": float(np.std(fc[win])),
        "feed_force_std_N_per_mm": float(np.std(ff[win])),
        "averaging_window_mm": [float(cut_pos_mm[win][0]) if win.any() else math.nan,
                                float(cut_pos_mm[win][-1]) if win.any() else math.nan],
        "chip_ratio": chip.ratio,
        "chip_ratio_points": chip.n_points,
        "chip_ratio_velocity": r_vel,
        "chip_ratio_velocity_points": n_vel,
        "chip_thickness_um": chip.thickness * 1e6,
        "shear_angle_deg": chip.shear_angle_deg,
        "peak_temperature_K": float(np.max(st.temp[st.alive == 1])),
        "energy_error": energy_error(en),
        "wall_time_s": wall,
        "element_updates_per_s": n_el * steps / max(wall, 1e-12),
        "steps": int(steps),
        "device": device,
        "time_step_s": dt0,
        "n_elements": n_el,
        "n_nodes": int(st.x.shape[0]),
        "friction_coefficient": setup.mu,
        "friction_law": cfg.friction_law(),
        "uncut_chip_thickness_um": cfg.cut.uncut_chip_thickness_um,
        "cutting_speed_m_per_min": cfg.cut.cutting_speed_m_per_min,
        "eroded_damage": int(np.sum(st.alive == 0)),
        "eroded_distortion": int(np.sum(st.alive == -1)),
        "eroded_chip_mass_fraction": float(
            np.sum(st.area0[(st.alive != 1) & setup.mesh.chip])
            / max(np.sum(st.area0[setup.mesh.chip]), 1e-300)),
        "energy_external_J_per_m": float(en[K.E_EXT]),
        "energy_plastic_J_per_m": float(en[K.E_PLAST]),
        "energy_hourglass_J_per_m": float(en[K.E_HG]),
        "energy_contact_J_per_m": float(en[K.E_FRIC]),
        "energy_kinetic_J_per_m": float(en[K.E_KIN]),
        "energy_internal_J_per_m": float(en[K.E_INT]),
        "hourglass_fraction": float(en[K.E_HG] / max(en[K.E_INT], 1e-300)),
    }
    faces = hh[:, K.H_FX_RAKE:K.H_FX_RAKE + 6] * 1e-3
    has_faces = bool(win.any() and np.all(np.isfinite(faces[win])))
    if has_faces:  # recorded by both devices
        fm = faces[win].mean(axis=0)
        summary["force_by_face_N_per_mm"] = {
            face: {"cutting": float(fm[2 * j]), "feed": float(fm[2 * j + 1])}
            for j, face in enumerate(K.FACES)}
    if cfg.tool_support is not None:
        kx, ky = cfg.tool_support.stiffness_N_per_m  # type: ignore[misc]
        w = cfg.cut.width_mm
        dx = hh[:, K.H_UX] * 1e6
        dy = hh[:, K.H_UY] * 1e6
        summary.update({
            "tool_dx_mean_um": float(np.mean(dx[win])),
            "tool_dy_mean_um": float(np.mean(dy[win])),
            "tool_dx_std_um": float(np.std(dx[win])),
            "tool_dy_std_um": float(np.std(dy[win])),
            "tool_dx_static_um": summary["cutting_force_N_per_mm"] * w / kx * 1e6,
            "tool_dy_static_um": summary["feed_force_N_per_mm"] * w / ky * 1e6,
        })
    history = {
        "time_s": t,
        "cut_length_mm": cut_pos_mm,
        "cutting_force_N_per_mm": fc,
        "feed_force_N_per_mm": ff,
        "tool_dx_um": hh[:, K.H_UX] * 1e6,
        "tool_dy_um": hh[:, K.H_UY] * 1e6,
        "tool_tip_x_mm": hh[:, K.H_TIP_X] * 1e3,
        "contact_nodes": hh[:, K.H_NCONT],
        "energy_external_J_per_m": hh[:, K.H_EEXT],
        "energy_kinetic_J_per_m": hh[:, K.H_EKIN],
        "energy_internal_J_per_m": hh[:, K.H_EINT],
        "energy_plastic_J_per_m": hh[:, K.H_EPL],
        "energy_hourglass_J_per_m": hh[:, K.H_EHG],
        "energy_contact_J_per_m": hh[:, K.H_EFRIC],
        "energy_eroded_J_per_m": hh[:, K.H_EERO],
    }
    if has_faces:
        for j, face in enumerate(K.FACES):
            history[f"{face}_cutting_force_N_per_mm"] = faces[:, 2 * j]
            history[f"{face}_feed_force_N_per_mm"] = faces[:, 2 * j + 1]
    return FEResult(summary=summary, history=history, config=cfg.model_dump(),
                    final=_final_fields(setup))
