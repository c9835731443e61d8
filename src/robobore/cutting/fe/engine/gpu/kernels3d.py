"""The 3D GPU engine's kernels (numba-cuda), built from the SAME scalar physics as the CPU
engine.

The per-element and per-node updates are the plain-Python scalar functions of the CPU engine
(:func:`hex.element.hex_element_py`, :func:`hex.scalar3d.hex_node_py`,
:func:`hex.scalar3d.tool_step_py`) and the shared material/contact/support functions
(:mod:`robobore.material.johnson_cook`, :mod:`robobore.cutting.fe.physics.tool_contact`), made
with device versions of their callees by their factories (``make_hex_element``,
``make_hex_node``, ...) and compiled with
``numba.cuda.jit(device=True)``. :func:`kernels3` returns the launch-per-kernel phases
(nodes, contact-force total, tool, elements, step end, the heat-conduction kernels) and the
persistent kernel ``k_run`` that runs a whole chunk of steps in one cooperative launch (the
step loop of :func:`robobore.cutting.fe.engine.gpu.persistent.persistent_kernel` with the 3D
phases, on the state :data:`RunState3`); the host driver is
:func:`robobore.cutting.fe.engine.gpu.backend3d.advance3_gpu`.
"""

from __future__ import annotations

import functools
from collections import namedtuple

from robobore.cutting.fe.engine.gpu.persistent import (
    R_BAD,
    R_DTMIN,
    persistent_kernel,
)
from robobore.cutting.fe.engine.gpu.shared import bind_cuda, jc_device_functions

__all__ = ["kernels3", "RUN_ARRAYS", "RunState3", "R_FX", "R_FY", "R_FZ", "R_NC", "N_RED"]

# reduction slots on the device (engine.gpu.persistent's R_DTMIN, R_BAD, then the four sums of
# its contact-force total: the force and the number of contact nodes)
R_FX, R_FY, R_FZ, R_NC = 2, 3, 4, 5
N_RED = 6

#: the state arrays on the device, in the order of the persistent kernel's state
RUN_ARRAYS = ("x", "y", "z", "vx", "vy", "vz", "mass", "fixed", "ptr", "nel", "ncorner", "conn",
              "alive", "layer", "sd", "pres", "eps_p", "temp", "dmg", "qh", "vol0", "ie", "hge",
              "fe", "dte", "plast", "rate", "cf", "fric", "pen", "ndead", "ero_ke", "nwork",
              "mat", "prm", "tool", "en", "ist", "clock", "hacc", "hist", "pairs", "enbr",
              "tbuf", "theat")
#: the persistent kernel's state: the arrays, then the erosion mode
RunState3 = namedtuple("RunState3", RUN_ARRAYS + ("erosion",))

#: the numba.cuda module, bound on first use (a module global, so that numba's simulator can
#: substitute its own inside the kernels)
cuda = None


def no_energy_totals_py(es, en):
    """The energy totals of the 3D GPU engine's history samples: none (False; the samples
    record the external work only, the host sums the totals from the copied-back state)."""
    return False


@functools.lru_cache(maxsize=2)
def kernels3(conduction: bool):
    """Compile (lazily, once per choice) the device functions and kernels: ``(k_nodes,
    k_contact_sum, k_tool, k_elems, k_finish, (k_centroids, k_conduct, k_copy_temp,
    k_heat_nodes, k_heat_elems, k_cond_done), k_run)``; ``k_run`` has the heat phase (every
    ``prm[P_COND_EVERY]`` >= 1 steps) with ``conduction``, none without (adiabatic), as the
    CPU's ``kernels3d.RUN_CHUNK3``."""
    global cuda
    cuda = bind_cuda()
    from numba import float64 as _float64

    from robobore.cutting.fe.engine import kernels3d as K3
    from robobore.cutting.fe.engine import layout
    from robobore.cutting.fe.hex import layout3d, scalar3d
    from robobore.cutting.fe.hex.element import make_hex_element
    from robobore.cutting.fe.physics import thermal3d as T3
    from robobore.cutting.fe.physics.tool_contact import (
        make_tool_gap,
        normal_force_py,
        tool_face_py,
        tool_support_step_py,
    )
    from robobore.cutting.fe.quad import node_contact
    from robobore.material import johnson_cook as jc

    dev = cuda.jit(device=True)
    dmg, ret = jc_device_functions(dev)
    elem = dev(make_hex_element(jc_return=ret, jc_damage_increment=dmg))
    tg = dev(make_tool_gap(tool_face=dev(tool_face_py)))
    sec = dev(scalar3d.edge_section_py)
    gap3 = dev(scalar3d.make_insert_gap3(tool_gap=tg, edge_section=sec))
    cf3 = dev(scalar3d.make_contact_force3(normal_force=dev(normal_force_py)))
    fat3 = dev(scalar3d.friction_at3_py)
    node = dev(scalar3d.make_hex_node(insert_gap3=gap3, contact_force3=cf3, friction_at3=fat3))
    sup = dev(tool_support_step_py)
    kin = dev(scalar3d.tool_kinematics_py)
    tstep = dev(scalar3d.make_tool_step(tool_kinematics=kin, tool_support_step=sup))
    lsum3 = dev(scalar3d.lane_sum3_py)
    th = {}
    for name, source, deps in T3.DEVICE_FUNCTIONS:
        th[name] = dev(source(**{d: th[d] for d in deps}) if deps else source)
    centroid3, conduct3 = th["hex_centroid3"], th["hex_conduct3"]
    heat_node3, heat_elem3 = th["tool_heat_node3"], th["tool_heat_elem3"]
    is_cond = dev(scalar3d.is_conduction_step_py)
    from robobore.cutting.fe.engine.history import make_end_step
    RHO, CP, KCOND = jc.RHO, jc.CP, jc.KCOND
    P_COND_T, P_HC = layout3d.P_COND_T, layout3d.P_HC
    P_FHEAT, P_TTOOL = layout3d.P_FHEAT, layout3d.P_TTOOL
    LANES = node_contact.N_SUM_LANES
    float64 = _float64

    I_STATUS, ST_OK, E_EXT = layout.I_STATUS, layout.STATUS_OK, layout.E_EXT
    # the end of a step (robobore.cutting.fe.engine.history) bound to the 3D engine, without the
    # per-sample energy totals
    end_step = make_end_step(dev, K3.ENGINE3, dev(K3.tool_columns3_py), dev(no_energy_totals_py))

    @cuda.jit(device=True)
    def lanes_total(px, py, pz, pn, red):
        # the lanes' partial sums added in lane order by one thread: the order of the CPU's
        # kernels3d.contact_total3, so the total has the same bits on both devices
        sx = 0.0
        sy = 0.0
        sz = 0.0
        sn = 0.0
        for j in range(LANES):
            sx += px[j]
            sy += py[j]
            sz += pz[j]
            sn += pn[j]
        red[R_FX] = sx
        red[R_FY] = sy
        red[R_FZ] = sz
        red[R_NC] = sn
        return sx, sy, sz

    @cuda.jit(device=True)
    def finish(tool, prm, clock, ist, hacc, hist, en, red):
        # the step end (one thread): history.make_end_step's end_step on the step's reductions (no
        # per-sample energy totals: the host sums them from the copied-back state)
        end_step(clock[1], (red[R_DTMIN], int(red[R_BAD])),
                 (red[R_FX], red[R_FY], red[R_FZ], red[R_NC]), red, ist, clock, prm, tool, en,
                 hacc, hist, ())

    # one item of a conduction pass on the state RunState3 ``a`` (``dt_th`` the time since the
    # last pass [s]): shared by the persistent kernel's heat phase and the launch-per-kernel
    # path

    @cuda.jit(device=True)
    def conduct_item(e, a, dt_th):
        mat = a.mat
        # the tuples of the CPU's conduct3 (physics.thermal3d.hex_conduct3_py)
        conduct3(e, (a.conn, a.x, a.y, a.z, a.alive, a.enbr, a.pairs, a.vol0), a.temp, a.tbuf,
                 (mat[KCOND], mat[RHO] * mat[CP], dt_th))

    @cuda.jit(device=True)
    def heat_node_item(n, a, dt_th):
        mat, prm = a.mat, a.prm
        # the tuples of the CPU's tool_heat3 (physics.thermal3d.tool_heat_node3_py)
        heat_node3(n, (a.conn, a.x, a.y, a.z, a.ptr, a.nel, a.ncorner, a.alive, a.enbr,
                       a.pairs, a.vol0), (a.cf, a.fric, a.temp), a.theat,
                   (mat[RHO] * mat[CP], prm[P_HC], prm[P_FHEAT], prm[P_TTOOL], dt_th))

    # the persistent kernel's phases (engine.gpu.persistent), on the state RunState3

    @cuda.jit(device=True)
    def node_phase(n, a, kv, dt, red):
        cx, cy, cz, tvx, tvy, tvz = kv
        cf = a.cf
        node(n, a.x, a.y, a.z, a.vx, a.vy, a.vz, a.mass, a.fixed,
             a.ptr, a.nel, a.ncorner, a.alive, a.vol0, a.fe, cf, a.fric,
             a.pen, a.ndead, a.ero_ke, a.nwork, a.prm, cx, cy, cz, tvx, tvy,
             tvz, dt, a.pairs)
        return cf[n, 0] != 0.0 or cf[n, 1] != 0.0 or cf[n, 2] != 0.0

    @cuda.jit(device=True)
    def lane_sums(a, clist, m, lane, p):
        # one lane's force and contact-node count over the listed chunks (kernels3d.lane_sum3)
        cf = a.cf
        nn = cf.shape[0]
        sx = 0.0
        sy = 0.0
        sz = 0.0
        sc = 0
        for i in range(m):
            n = clist[i] * LANES + lane
            if n < nn and (cf[n, 0] != 0.0 or cf[n, 1] != 0.0 or cf[n, 2] != 0.0):
                sx += cf[n, 0]
                sy += cf[n, 1]
                sz += cf[n, 2]
                sc += 1
        p[0, lane] = sx
        p[1, lane] = sy
        p[2, lane] = sz
        p[3, lane] = sc

    @cuda.jit(device=True)
    def tool_phase(a, clist, m, kv, dt, red):
        a.en[E_EXT] += tstep(a.tool, a.prm, red[R_FX], red[R_FY], red[R_FZ], dt)

    @cuda.jit(device=True)
    def elem_phase(e, a, dt, red):
        dte, alive = a.dte, a.alive
        elem(e, a.conn, a.x, a.y, a.z, a.vx, a.vy, a.vz, alive,
             a.layer, a.sd, a.pres, a.eps_p, a.temp, a.dmg, a.qh,
             a.vol0, a.ie, a.hge, a.fe, dte, a.plast, a.rate, a.mat,
             a.prm, dt, a.erosion)
        cuda.atomic.min(red, R_DTMIN, dte[e])
        if alive[e] == -2:
            red[R_BAD] = e

    CONDUCTION = bool(conduction)

    @cuda.jit(device=True)
    def heat_phase(a, step, dt, tid, nthr, grid):
        # conduction (thermal3d, the CPU's conduction_pass3): the phases of the launch path,
        # separated by barriers; none in the adiabatic kernel
        if not CONDUCTION:
            return
        prm, clock = a.prm, a.clock
        if not is_cond(step, prm):
            return
        conn, x, y, z, alive = a.conn, a.x, a.y, a.z, a.alive
        temp, tbuf, mat = a.temp, a.tbuf, a.mat
        ne = conn.shape[0]
        dt_th = clock[0] + dt - prm[P_COND_T]
        rcp = mat[RHO] * mat[CP]
        for e in range(tid, ne, nthr):
            centroid3(e, conn, x, y, z, tbuf)
        grid.sync()
        for e in range(tid, ne, nthr):
            conduct_item(e, a, dt_th)
        grid.sync()
        for e in range(tid, ne, nthr):
            temp[e] = tbuf[e, 3]
        grid.sync()
        if prm[P_HC] > 0.0 or prm[P_FHEAT] > 0.0:
            for n in range(tid, x.shape[0], nthr):
                heat_node_item(n, a, dt_th)
            grid.sync()
            for e in range(tid, ne, nthr):
                heat_elem3(e, conn, alive, temp, a.theat, rcp)
            grid.sync()
        if tid == 0:
            prm[P_COND_T] = clock[0] + dt

    @cuda.jit(device=True)
    def finish_phase(a, red):
        finish(a.tool, a.prm, a.clock, a.ist, a.hacc, a.hist, a.en, red)

    # the launch-per-kernel path (no cooperative launch, or a per-kernel profile): one kernel
    # per pass on the state RunState3 ``a`` (and the reductions ``red``), as the phases per item

    @cuda.jit
    def k_nodes(a, red):
        n = cuda.grid(1)
        if n >= a.x.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        node_phase(n, a, kin(a.tool, a.prm), a.clock[1], red)

    @cuda.jit
    def k_contact_sum(a, red):
        # the CPU's fixed-order total (kernels3d.contact_total3): one thread per lane, then
        # the lanes in order by thread 0 -- reproducible bit for bit
        t = cuda.threadIdx.x
        px = cuda.shared.array(LANES, float64)
        py = cuda.shared.array(LANES, float64)
        pz = cuda.shared.array(LANES, float64)
        pn = cuda.shared.array(LANES, float64)
        sa, sb, sc, sk = lsum3(a.cf, t, LANES)
        px[t] = sa
        py[t] = sb
        pz[t] = sc
        pn[t] = sk
        cuda.syncthreads()
        if t == 0:
            lanes_total(px, py, pz, pn, red)

    @cuda.jit
    def k_tool(a, red):
        if cuda.grid(1) != 0 or a.ist[I_STATUS] != ST_OK:
            return
        a.en[E_EXT] += tstep(a.tool, a.prm, red[R_FX], red[R_FY], red[R_FZ], a.clock[1])
        red[R_DTMIN] = 1e30
        red[R_BAD] = -1.0

    @cuda.jit
    def k_elems(a, red):
        e = cuda.grid(1)
        if e >= a.conn.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        elem_phase(e, a, a.clock[1], red)

    @cuda.jit
    def k_centroids(a):
        e = cuda.grid(1)
        if e >= a.conn.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        centroid3(e, a.conn, a.x, a.y, a.z, a.tbuf)

    @cuda.jit
    def k_conduct(a):
        e = cuda.grid(1)
        if e >= a.conn.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        clock = a.clock
        conduct_item(e, a, clock[0] + clock[1] - a.prm[P_COND_T])

    @cuda.jit
    def k_copy_temp(a):
        e = cuda.grid(1)
        if e >= a.temp.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        a.temp[e] = a.tbuf[e, 3]

    @cuda.jit
    def k_heat_nodes(a):
        n = cuda.grid(1)
        if n >= a.x.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        clock = a.clock
        heat_node_item(n, a, clock[0] + clock[1] - a.prm[P_COND_T])

    @cuda.jit
    def k_heat_elems(a):
        e = cuda.grid(1)
        if e >= a.conn.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        mat = a.mat
        heat_elem3(e, a.conn, a.alive, a.temp, a.theat, mat[RHO] * mat[CP])

    @cuda.jit
    def k_cond_done(a):
        if cuda.grid(1) != 0 or a.ist[I_STATUS] != ST_OK:
            return
        clock = a.clock
        a.prm[P_COND_T] = clock[0] + clock[1]

    @cuda.jit
    def k_finish(a, red):
        if cuda.grid(1) != 0 or a.ist[I_STATUS] != ST_OK:
            return
        finish_phase(a, red)

    # the elements do not read the tool or the contact forces: no barrier after the tool
    k_run = persistent_kernel(n_sums=4, kinematics=kin, node=node_phase,
                              lane_sums=lane_sums, tool=tool_phase, elem=elem_phase,
                              heat=heat_phase, finish=finish_phase)

    # the persistent kernel last (benchmarks/gpu_compile_check.py compiles it)
    return (k_nodes, k_contact_sum, k_tool, k_elems, k_finish,
            (k_centroids, k_conduct, k_copy_temp, k_heat_nodes, k_heat_elems, k_cond_done), k_run)
