"""Numba kernels of the 3D explicit engine (hexahedra, SI units, forces in N).

Reuses the 2D engine's scalar physics unchanged: the Johnson-Cook return mapping and damage
(:mod:`robobore.material.johnson_cook`), the 2D wedge signed distance
(:func:`robobore.cutting.fe.physics.tool_contact.tool_gap`, applied in the local normal section of
the insert edge) and the spring-damper step
(:func:`robobore.cutting.fe.physics.tool_contact.tool_support_step`). The 3D state layout and scalar
functions (``_py`` original + ``njit``, device-ready) are
:mod:`robobore.cutting.fe.hex.scalar3d`'s, which this module calls; it holds the parallel loops
(elements, nodes), the energy sums, the contact-force total, the conduction pass, the step
phases and the chunk loops :func:`run_chunk3` (the step loop of
:mod:`robobore.cutting.fe.engine.step_loop` with those phases; workpiece frame) and
:func:`run_chunk3_ale` (the same with the tool-frame ALE pass of
:mod:`robobore.cutting.fe.ale.rezone3d` as its remesh phase). The scalar functions:

* :func:`insert_gap3_py` -- signed distance of a point to a boring insert with nose radius,
  approach and end-edge angles, rake, clearance, edge radius and inclination;
* :func:`contact_force3_py` -- the 2D contact law (:func:`tool_contact.contact_force_py`: mass-
  proportional penalty, viscous normal damping, Coulomb friction, shear-stress cap) with a
  tangential *vector*;
* :func:`friction_at3_py` -- the 2D engine's friction table lookup
  (:func:`robobore.cutting.fe.quad.node_contact.friction_at_py`, the same code re-bound to the 3D
  parameter slots);
* :func:`hex_node_py` -- gather, contact and central-difference update of one node.

Energy indices, status codes and the energy-balance definition are the 2D engine's
(:mod:`robobore.cutting.fe.engine.layout`), so
:func:`robobore.cutting.fe.engine.chunk_driver.energy_error` applies to both.

Frames: the kernels work in the *local* frame of the insert at the start of the run
(x along the cutting velocity, y normal to the bore wall pointing out of the material,
towards the bore axis, z along the feed). The tool support integrates in the *boring*
frame (X horizontal, Y vertical, Z feed) and rotates with the bar angle
``theta(t) = theta0 + vc t / R``; see :mod:`robobore.cutting.fe.models.boring3d`.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit, prange

from robobore.cutting.fe.ale.groups3d import (
    Cells3,
    Contact3,
    ElementOut3,
    ElementState3,
    Nodes3,
    RemapWork3,
    ToolFrameAle3,
)
from robobore.cutting.fe.ale.rezone3d import rezone3d
from robobore.cutting.fe.engine.history import make_end_step, make_energy_totals
from robobore.cutting.fe.engine.step_loop import StepPhases, make_chunk_loop
from robobore.cutting.fe.hex.element import hex_element
from robobore.cutting.fe.hex.layout3d import (
    P_ALE_X0,
    P_ALE_Z0,
    P_CFL,
    P_COND_T,
    P_DTMIN,
    P_EROSION,
    P_FHEAT,
    P_HC,
    P_MS,
    P_MSF_DT,
    P_RZ_EVERY,
    P_RZ_MAXMOVE,
    P_RZ_VEL,
    P_SAMPLE_DT,
    P_TEND,
    P_TTOOL,
)
from robobore.cutting.fe.hex.scalar3d import (
    T_FX,
    T_GX,
    T_THETA,
    T_UX,
    hex_node,
    is_conduction_step,
    lane_sum3,
    tool_kinematics,
    tool_step,
)
from robobore.cutting.fe.physics.thermal3d import conduct3, tool_heat3
from robobore.cutting.fe.quad.node_contact import N_SUM_LANES
from robobore.material import johnson_cook as jc

__all__ = [
    "conduction_pass3", "element_update3", "node_update3", "run_chunk3", "sum_energies3",
    "contact_total3", "run_chunk3_ale", "run_chunk3_heat", "run_chunk3_ale_heat", "RUN_CHUNK3",
    "run_chunk3_for", "renew_inertia_factors_py", "renew_inertia_factors", "energy_arrays3",
    "ENERGY_FIELDS3",
]


@njit(parallel=True, cache=True)
def element_update3(nodes, cells, layer, elems, out, mat, prm, dt, erosion):
    """:func:`hex.element.hex_element_py` over all elements (parallel). The groups of
    :mod:`robobore.cutting.fe.ale.groups3d`: ``nodes`` (Nodes3), ``cells`` (Cells3: ``conn``,
    ``alive``), ``elems`` (ElementState3), ``out`` (ElementOut3); ``layer`` (e,) the
    separation-layer flags, ``mat`` the material vector, ``prm`` the parameter vector, ``dt``
    the step [s], ``erosion`` the erosion mode."""
    # the prange body reads flat locals, one bound per statement (ale.groups3d)
    x = nodes.x
    y = nodes.y
    z = nodes.z
    vx = nodes.vx
    vy = nodes.vy
    vz = nodes.vz
    conn = cells.conn
    alive = cells.alive
    sd = elems.sd
    pres = elems.pres
    eps_p = elems.eps_p
    temp = elems.temp
    dmg = elems.dmg
    qh = elems.qh
    vol0 = elems.vol0
    ie = out.ie
    hge = out.hge
    fe = out.fe
    dte = out.dte
    plast = out.plast
    rate = out.rate
    for e in prange(conn.shape[0]):
        hex_element(e, conn, x, y, z, vx, vy, vz, alive, layer, sd, pres, eps_p, temp, dmg, qh,
                    vol0, ie, hge, fe, dte, plast, rate, mat, prm, dt, erosion)


@njit(parallel=True, cache=True)
def node_update3(nodes, ncorner, cells, elems, out, contact, prm, kin, dt):
    """:func:`hex_node_py` over all nodes (parallel). The groups of
    :mod:`robobore.cutting.fe.ale.groups3d`: ``nodes`` (Nodes3), ``cells`` (Cells3:
    ``alive``), ``elems`` (ElementState3: ``vol0``), ``out`` (ElementOut3: ``fe``),
    ``contact`` (Contact3); ``ncorner`` the node's corner in each element of its CSR list,
    ``prm`` the parameter vector, ``kin`` = (edge centre x, y, z [m], tool velocity x, y, z
    [m/s]), ``dt`` the step [s]."""
    # the prange body reads flat locals, one bound per statement (ale.groups3d)
    x = nodes.x
    y = nodes.y
    z = nodes.z
    vx = nodes.vx
    vy = nodes.vy
    vz = nodes.vz
    mass = nodes.mass
    fixed = nodes.fixed
    ptr = nodes.ptr
    nel = nodes.nel
    alive = cells.alive
    vol0 = elems.vol0
    fe = out.fe
    cf = contact.cf
    fric = contact.fric
    pen = contact.pen
    ndead = contact.ndead
    ero_ke = contact.ero_ke
    nwork = contact.nwork
    pairs = contact.pairs
    cx, cy, cz, tvx, tvy, tvz = kin
    for n in prange(x.shape[0]):
        hex_node(np.int64(n), x, y, z, vx, vy, vz, mass, fixed, ptr, nel, ncorner, alive, vol0,
                 fe, cf, fric, pen, ndead, ero_ke, nwork, prm, cx, cy, cz, tvx, tvy, tvz, dt,
                 pairs)


@njit(inline="always")
def _groups3(s):
    # the groups of robobore.cutting.fe.ale.groups3d of the chunk loop's state ``s``
    nodes = Nodes3(x=s.x, y=s.y, z=s.z, vx=s.vx, vy=s.vy, vz=s.vz, mass=s.mass,
                   fixed=s.fixed, ptr=s.ptr, nel=s.nel)
    cells = Cells3(conn=s.conn, alive=s.alive, fnbr=s.enbr, bflag=s.bflag)
    elems = ElementState3(sd=s.sd, pres=s.pres, eps_p=s.eps_p, temp=s.temp, dmg=s.dmg,
                          qh=s.qh, vol0=s.vol0, msf=s.msf)
    out = ElementOut3(ie=s.ie, hge=s.hge, fe=s.fe, dte=s.dte, plast=s.plast, rate=s.rate)
    contact = Contact3(cf=s.cf, fric=s.fric, pen=s.pen, ndead=s.ndead, ero_ke=s.ero_ke,
                       nwork=s.nwork, pairs=s.pairs)
    return nodes, cells, elems, out, contact


#: the energy totals (:func:`robobore.cutting.fe.engine.history.make_energy_totals` in 3D) of
#: the state arrays ``es`` = (mass, vx, vy, vz, ie, plast, hge, alive, fric, pen, ero_ke, nwork)
#: into ``en`` (2D engine's indices) [J], under its own name (see history.make_end_step)
sum_energies3_py = make_energy_totals(3, "sum_energies3_py")
_energy_totals3 = njit(sum_energies3_py)


@njit(cache=True)
def sum_energies3(es, en):
    """:data:`sum_energies3_py` of the arrays ``es`` (:func:`energy_arrays3`) into ``en``."""
    _energy_totals3(es, en)


def energy_arrays3(st):
    """The arrays ``es`` of :data:`sum_energies3_py` of a 3D state ``st`` (any object with
    them as attributes: :class:`~robobore.cutting.fe.engine.state3d.FEState3`), by name."""
    return tuple(getattr(st, f) for f in ENERGY_FIELDS3)


#: the state's arrays ``es`` of :data:`sum_energies3_py`, in its order
ENERGY_FIELDS3 = ("mass", "vx", "vy", "vz", "ie", "plast", "hge", "alive", "fric", "pen",
                  "ero_ke", "nwork")


@njit(inline="always")
def _energy_arrays3(s):
    # the arrays ``es`` of sum_energies3_py in the chunk loop's state ``s`` (ENERGY_FIELDS3)
    return (s.mass, s.vx, s.vy, s.vz, s.ie, s.plast, s.hge, s.alive, s.fric, s.pen, s.ero_ke,
            s.nwork)


def tool_columns3_py(tool):
    """The 3D engine's instantaneous tool history columns: the guide's x [m] (local frame)
    and the bar angle [rad]."""
    return tool[T_GX], tool[T_THETA]


#: the 3D engine's history layout and parameter slots for :mod:`robobore.cutting.fe.engine.history`
#: (forces, local frame, and support displacements, boring frame, x, y, z; no force by tool
#: face; the guide's x and the bar angle; a step stopped by an inverted element or an empty
#: mesh still counted)
ENGINE3 = {"NDIM": 3, "N_SPLIT": 0, "N_TOOL_COLUMNS": 2, "T_FORCE": T_FX, "T_DISP": T_UX,
           "P_CFL": P_CFL, "P_DTMIN": P_DTMIN, "P_SAMPLE_DT": P_SAMPLE_DT, "P_TEND": P_TEND,
           "COUNT_STOPPED_STEP": 1}
#: the end of a step on the CPU (:func:`robobore.cutting.fe.engine.history.make_end_step`)
_end_step3 = make_end_step(njit, ENGINE3, njit(tool_columns3_py), _energy_totals3)


@njit(cache=True)
def contact_total3(cf):
    """Total contact force on the workpiece [N] and number of contact nodes, summed in the
    fixed lane order of :func:`robobore.cutting.fe.quad.node_contact.contact_total` (the GPU engine
    sums the same way, so a GPU run is reproducible bit for bit)."""
    fx = 0.0
    fy = 0.0
    fz = 0.0
    nc = 0
    for lane in range(N_SUM_LANES):
        a, b, c, k = lane_sum3(cf, lane, N_SUM_LANES)
        fx += a
        fy += b
        fz += c
        nc += k
    return fx, fy, fz, nc



@njit(cache=True)
def conduction_pass3(nodes, ncorner, cells, elems, contact, tbuf, theat, mat, prm, t_end_step):
    """Conduction and the thermal contact with the insert over the time since the last pass,
    ``t_end_step - prm[P_COND_T]`` [s], which then moves to ``t_end_step``; the groups and
    ``tbuf``, ``theat`` as in :func:`robobore.cutting.fe.physics.thermal3d.tool_heat3`."""
    dt_th = t_end_step - prm[P_COND_T]
    rcp = mat[jc.RHO] * mat[jc.CP]
    conduct3(nodes, cells, elems, contact, tbuf, mat[jc.KCOND], rcp, dt_th)
    if prm[P_HC] > 0.0 or prm[P_FHEAT] > 0.0:
        tool_heat3(nodes, ncorner, cells, elems, contact, theat, rcp, prm[P_HC], prm[P_FHEAT],
                   prm[P_TTOOL], dt_th)
    prm[P_COND_T] = t_end_step


#: the state arrays of the loop, in the order of ``FEState3.kernel_args()`` (its fields)
CHUNK_ARGS3 = ("x", "y", "z", "vx", "vy", "vz", "mass", "fixed", "ptr", "nel", "ncorner",
               "conn", "alive", "layer", "sd", "pres", "eps_p", "temp", "dmg", "qh", "vol0",
               "ie", "hge", "fe", "dte", "plast", "rate", "cf", "fric", "pen", "ndead",
               "ero_ke", "nwork", "mat", "prm", "tool", "en", "ist", "clock", "hacc", "hist",
               "pairs", "enbr", "tbuf", "theat", "x0", "y0", "z0", "acls", "aflt", "bflag",
               "xn", "yn", "zn", "buf", "vbuf", "scratch", "msf")
#: the state of the loop's phases (numba reads the fields by name)
ChunkState3 = namedtuple("ChunkState3", CHUNK_ARGS3)


@njit(inline="always")
def _nodes3(s, kin, dt, split):
    # node update and contact, then the contact-force total in the fixed lane order
    nodes, cells, elems, out, contact = _groups3(s)
    node_update3(nodes, s.ncorner, cells, elems, out, contact, s.prm, kin, dt)
    return contact_total3(s.cf)


@njit(inline="always")
def _tool_step3(s, fx, fy, fz, dt):
    return tool_step(s.tool, s.prm, fx, fy, fz, dt)


@njit(inline="always")
def _elements3(s, dt):
    # the element update, then its smallest stable step and an inverted element
    prm = s.prm
    conn, dte, alive = s.conn, s.dte, s.alive
    nodes, cells, elems, out, _contact = _groups3(s)
    element_update3(nodes, cells, s.layer, elems, out, s.mat, prm, dt, int(prm[P_EROSION]))
    dtmin = 1e30
    bad = -1
    for e in range(conn.shape[0]):
        if dte[e] < dtmin:
            dtmin = dte[e]
        if alive[e] == -2:
            bad = e
    return dtmin, bad


@njit(inline="always")
def _elements3_ale(s, dt):
    # the element update, then the smallest stable step with the elements' inertia factors
    # (tool frame: mass scaling attached to the mesh, FEState3.msf; empty: 1)
    dtmin, bad = _elements3(s, dt)
    msf, dte = s.msf, s.dte
    if msf.shape[0] > 0:
        dtmin = 1e30
        for e in range(dte.shape[0]):
            d = dte[e] * math.sqrt(msf[e])
            if d < dtmin:
                dtmin = d
    return dtmin, bad


@njit(inline="always")
def _heat3(s, step, t, dt):
    # every prm[P_COND_EVERY] (>= 1) steps: conduction and the thermal contact
    if is_conduction_step(step, s.prm):
        nodes, cells, elems, _out, contact = _groups3(s)
        conduction_pass3(nodes, s.ncorner, cells, elems, contact, s.tbuf, s.theat, s.mat,
                         s.prm, t + dt)


def renew_inertia_factors_py(msf, dte, alive, dt_target):
    """The tool frame's inertia factors renewed from the elements' material stable steps
    ``dte`` [s] of the last element pass: ``msf[e] = max(1, (dt_target / dte[e])^2)`` for
    every live element, so each element's stable step is at least ``dt_target`` (mass
    scaling attached to the place in the insert's frame, renewed as the mesh deforms: the
    squeezed chip elements of the thin end slices keep the nose-tip section's step; others
    fall back to 1). Dead elements and elements without a step keep theirs."""
    for e in range(msf.shape[0]):
        d = dte[e]
        if alive[e] == 1 and d > 0.0 and d < 1e30:
            r = dt_target / d
            msf[e] = r * r if r > 1.0 else 1.0


renew_inertia_factors = njit(cache=True, inline="always")(renew_inertia_factors_py)


@njit(inline="always")
def _remesh3(s, step):
    # the tool-frame ALE pass every prm[P_RZ_EVERY] steps: the inertia factors renewed (the
    # remap assembles the lumped masses with them), each node back to its place shifted by
    # the insert's travel since the mesh was built, then the remap
    prm, mat = s.prm, s.mat
    if step % int(prm[P_RZ_EVERY]) == 0:
        if prm[P_MSF_DT] > 0.0 and s.msf.shape[0] > 0:
            renew_inertia_factors(s.msf, s.dte, s.alive, prm[P_MSF_DT])
        cx, cy, cz, _vx, _vy, _vz = tool_kinematics(s.tool, prm)
        nodes, cells, elems, _out, _contact = _groups3(s)
        work = RemapWork3(xn=s.xn, yn=s.yn, zn=s.zn, buf=s.buf, vbuf=s.vbuf)
        ale = ToolFrameAle3(x0=s.x0, y0=s.y0, z0=s.z0, acls=s.acls, aflt=s.aflt,
                            scratch=s.scratch)
        rezone3d(nodes, cells, elems, work, ale, mat[jc.RHO] * prm[P_MS], mat[jc.TROOM],
                 int(prm[P_RZ_VEL]), prm,
                 (cx - prm[P_ALE_X0], cz - prm[P_ALE_Z0], prm[P_RZ_MAXMOVE]), (cx, cy, cz))


@njit(inline="always")
def _no_heat3(s, step, t, dt):
    # adiabatic: no heat pass
    return None


def _bind3(name, remesh, elements, heat):
    # the step loop of robobore.cutting.fe.engine.step_loop bound to the 3D phases
    return make_chunk_loop(name=name, state=ChunkState3, n_split=ENGINE3["N_SPLIT"],
                           energy_arrays=_energy_arrays3, energy_totals=_energy_totals3,
                           phases=StepPhases(kinematics=tool_kinematics, nodes=_nodes3,
                                             tool_step=_tool_step3, elements=elements,
                                             heat=heat, end_step=_end_step3, remesh=remesh),
                           totals_at_chunk_end=True)


# the step loop of robobore.cutting.fe.engine.step_loop bound to the 3D phases, one per
# choice under its own name: workpiece frame (no remesh phase) or tool frame (the ALE pass),
# adiabatic or with the heat pass
_loop3 = _bind3("loop3", None, _elements3, _no_heat3)
_loop3_heat = _bind3("loop3_heat", None, _elements3, _heat3)
_loop3_ale = _bind3("loop3_ale", _remesh3, _elements3_ale, _no_heat3)
_loop3_ale_heat = _bind3("loop3_ale_heat", _remesh3, _elements3_ale, _heat3)


@njit(cache=True)
def run_chunk3(n_steps, *arrays):
    """Advance up to ``n_steps`` central-difference steps (the whole loop in numba) of the
    state arrays ``FEState3.kernel_args()`` (:data:`CHUNK_ARGS3`): the step loop of
    :mod:`robobore.cutting.fe.engine.step_loop` with the 3D phases (the parallel node and
    element loops, the fixed-order contact-force total, the tool); workpiece frame,
    adiabatic.

    ``clock`` = [t, dt, t_acc] as in the 2D engine. Stops early with ``ist[I_STATUS]`` =
    STATUS_DONE at ``prm[P_TEND]``, or an instability status (each step ends with
    :func:`robobore.cutting.fe.engine.history.make_end_step`). Returns the steps taken; the
    energy totals are summed after a chunk that ran to its end.
    """
    return _loop3(n_steps, *arrays)


@njit(cache=True)
def run_chunk3_heat(n_steps, *arrays):
    """:func:`run_chunk3` with the heat pass: every ``prm[P_COND_EVERY]`` (>= 1) steps heat
    conduction and the thermal contact with the insert over the time since the last pass
    (:mod:`~robobore.cutting.fe.physics.thermal3d`, :func:`conduction_pass3`)."""
    return _loop3_heat(n_steps, *arrays)


@njit(cache=True)
def run_chunk3_ale(n_steps, *arrays):
    """:func:`run_chunk3` with the tool-frame ALE pass
    (:func:`robobore.cutting.fe.ale.rezone3d.rezone3d`) as the loop's ``remesh`` phase every
    ``prm[P_RZ_EVERY]`` steps (>= 1): the mesh of
    :mod:`robobore.cutting.fe.mesh.toolframe3d` put back to its place in the insert's frame
    (the places ``x0, y0, z0`` shifted by the insert tip's travel since ``prm[P_ALE_X0]``,
    ``prm[P_ALE_Z0]``) and the state remapped; the state's ALE arrays must be attached
    (:meth:`robobore.cutting.fe.engine.state3d.FEState3.attach_tool_frame`). Adiabatic."""
    return _loop3_ale(n_steps, *arrays)


@njit(cache=True)
def run_chunk3_ale_heat(n_steps, *arrays):
    """:func:`run_chunk3_ale` with the heat pass of :func:`run_chunk3_heat`."""
    return _loop3_ale_heat(n_steps, *arrays)


#: the compiled 3D chunk function of each choice (tool frame, conduction)
RUN_CHUNK3 = {
    (False, False): run_chunk3,
    (False, True): run_chunk3_heat,
    (True, False): run_chunk3_ale,
    (True, True): run_chunk3_ale_heat,
}


def run_chunk3_for(spec):
    """The compiled 3D chunk function of a
    :class:`~robobore.cutting.fe.config.spec.ModelSpec` with a 3D frame: the tool frame's
    ALE pass for a ``ToolFrame3D``, the heat pass for a ``Conduction`` thermal model
    (:data:`RUN_CHUNK3`)."""
    from robobore.cutting.fe.config.spec import Conduction

    return RUN_CHUNK3[(spec.frame.tool_frame, isinstance(spec.thermal, Conduction))]
