"""The 2D GPU engine's kernels (numba-cuda), built from the SAME scalar physics as the CPU
engine (their device versions: :func:`robobore.cutting.fe.engine.gpu.device2d.device_functions2`).

:func:`kernels2` returns the launch-per-kernel phases (nodes, contact-force total, tool,
elements, the heat-conduction kernels, step end, the tool-frame ALE passes) and the
persistent kernel ``k_run`` that runs a whole chunk of steps in one cooperative launch (the
step loop of :func:`robobore.cutting.fe.engine.gpu.persistent.persistent_kernel` with the 2D
phases, on the state
:data:`robobore.cutting.fe.engine.gpu.runstate2d.RunState`), for one
:class:`~robobore.cutting.fe.engine.chunk_loop.Phases` -- the CPU loop's model choice: the
ALE phase only in the tool frame, the heat phase only with conduction, compiled in; the host
driver is :func:`robobore.cutting.fe.engine.gpu.backend2d.advance_gpu`, whose docstring
describes the step's phases.
"""

from __future__ import annotations

import functools

from robobore.cutting.fe.engine import groups2d, layout
from robobore.cutting.fe.engine.chunk_loop import Phases
from robobore.cutting.fe.engine.gpu.device2d import device_functions2
from robobore.cutting.fe.engine.gpu.persistent import (
    R_BAD,
    R_DTMIN,
    persistent_kernel,
)
from robobore.cutting.fe.engine.gpu.runstate2d import R_FX, R_FY, R_NC, R_SPLIT
from robobore.cutting.fe.engine.gpu.shared import bind_cuda
from robobore.cutting.fe.quad import node_contact

__all__ = ["kernels2"]


#: the numba.cuda module, bound on first use (a module global, so that numba's simulator can
#: substitute its own inside the kernels)
cuda = None


@functools.cache
def kernels2(phases: Phases):
    """Compile (lazily, once per ``phases``) the device functions and kernels: ``(k_nodes,
    k_contact_sum, k_tool, k_elems, k_centroids, k_conduct, k_conduct_end, k_parting,
    k_theat_nodes, k_theat_elems, k_conduct_reset, k_finish, k_run, ale)`` with ``ale`` the
    tool-frame ALE pass's kernels (the launch-per-kernel path). ``phases.element`` must be
    "q4r" (the GPU engine's element); ``k_run`` has the ALE phase with ``phases.tool_frame``
    and the heat phase with ``phases.conduction``."""
    if phases.element != "q4r":
        raise ValueError(f"no GPU kernels for {phases} (the GPU engine has the one-point quad)")
    global cuda
    cuda = bind_cuda()
    from numba import float64 as _float64

    from robobore.material import johnson_cook as jc

    f = device_functions2(cuda.jit(device=True))
    (csplit, tool_geometry, tplace, tfacep, tsweep, tscopy, tinter, rflux, rvel, rwrite, rmass,
     SWEEPS, elem, node, kin, tstep, cent, cond, pedge, thnode, thelem, end_step, lsum) = (
        f.csplit, f.tool_geometry, f.tplace, f.tfacep, f.tsweep, f.tscopy, f.tinter, f.rflux,
        f.rvel, f.rwrite, f.rmass, f.SWEEPS, f.elem, f.node, f.kin, f.tstep, f.cent, f.cond,
        f.pedge, f.thnode, f.thelem, f.end_step, f.lsum)
    LANES = node_contact.N_SUM_LANES
    float64 = _float64
    CONDUCTION = phases.conduction

    I_STATUS, ST_OK = layout.I_STATUS, layout.STATUS_OK
    P_COND_ACC = layout.P_COND_ACC
    P_HC, P_FHEAT, P_TTOOL = layout.P_HC, layout.P_FHEAT, layout.P_TTOOL
    P_TCX, P_NRX, P_NRY = layout.P_TCX, layout.P_NRX, layout.P_NRY
    P_NFX, P_NFY = layout.P_NFX, layout.P_NFY
    P_ALE_X0, P_RZ_MAXMOVE, P_MS = layout.P_ALE_X0, layout.P_RZ_MAXMOVE, layout.P_MS
    E_EXT = layout.E_EXT
    KCOND, RHO, CP, TROOM = jc.KCOND, jc.RHO, jc.CP, jc.TROOM
    QS_TEMP = groups2d.QS_TEMP

    @cuda.jit(device=True)
    def lanes_total(px, py, red):
        # the lanes' partial sums added in lane order by one thread: the order of the CPU's
        # kernels.contact_total, so the total has the same bits on both devices
        sx = 0.0
        sy = 0.0
        for j in range(LANES):
            sx += px[j]
            sy += py[j]
        red[R_FX] = sx
        red[R_FY] = sy
        return sx, sy

    @cuda.jit(device=True)
    def split_add(n, x, y, cfx, cfy, cx, cy, prm, red):
        # node n's share of the contact force by tool face into red[R_SPLIT:], called in
        # increasing node order by one thread: the CPU's serial order (kernels.contact_split)
        csplit(n, cfx, cfy, x, y, (cx, cy, prm[P_NRX], prm[P_NRY], prm[P_NFX], prm[P_NFY]),
               red, R_SPLIT)

    @cuda.jit(device=True)
    def split_reset(red):
        for j in range(6):
            red[R_SPLIT + j] = 0.0

    @cuda.jit(device=True)
    def finish(tool, prm, clock, ist, hacc, hist, en, red, es):
        # the step end (one thread): history.make_end_step's end_step on the step's reductions
        nc = red[R_NC]
        red[R_NC] = 0.0  # the force total is rewritten by k_contact_sum every step
        end_step(clock[1], (red[R_DTMIN], int(red[R_BAD])), (red[R_FX], red[R_FY], 0.0, nc),
                 red[R_SPLIT:], ist, clock, prm, tool, en, hacc, hist, es)

    # one item of a pass on the state RunState ``a``, for the persistent and launch paths

    @cuda.jit(device=True)
    def flux_item(e, a):
        rflux(e, a.conn, a.alive, (a.x, a.y), (a.xn, a.yn), a.enbr, a.bflag, a.buf,
              (a.qs, a.area0), a.mat[TROOM])

    @cuda.jit(device=True)
    def write_item(e, a):
        rwrite(e, a.alive, a.buf, a.qs, a.area0)

    @cuda.jit(device=True)
    def conduct_item(e, a):
        mat = a.mat
        cond(e, a.conn, a.x, a.y, a.alive, a.enbr, a.qs[QS_TEMP], a.tbuf, mat[KCOND],
             mat[RHO] * mat[CP], a.prm[P_COND_ACC])

    @cuda.jit(device=True)
    def parting_item(i, a):
        mat = a.mat
        pedge(i, a.ppair, a.x, a.y, a.alive, a.tied, a.qs[QS_TEMP], a.tbuf, mat[KCOND],
              mat[RHO] * mat[CP], a.prm[P_COND_ACC])

    @cuda.jit(device=True)
    def theat_item(n, a):
        mat, prm = a.mat, a.prm
        # the tuples of the CPU's tool_heat (physics.thermal2d.tool_heat_node_py)
        thnode(n, (a.conn, a.x, a.y, a.ptr, a.nel, a.ncorner, a.alive, a.enbr),
               (a.cfx, a.cfy, a.fric, a.qs[QS_TEMP], a.tbuf), a.fheat, a.tcq,
               (mat[RHO] * mat[CP], prm[P_HC], prm[P_FHEAT], prm[P_TTOOL], prm[P_COND_ACC]))

    # the persistent kernel's phases (engine.gpu.persistent), on the state RunState

    @cuda.jit(device=True)
    def node_phase(n, a, kv, dt, red):
        tool_cx, tool_cy, tool_vx, tool_vy = kv
        cfx, cfy = a.cfx, a.cfy
        fcx, fcy, touched = node(n, a.x, a.y, a.vx, a.vy, a.mass, a.fixed,
                                 a.ptr, a.nel, a.ncorner, a.alive, a.area0,
                                 a.fex, a.fey, cfx, cfy, a.fric, a.pen,
                                 a.ndead, a.ero_ke, a.nwork, tool_cx, tool_cy, tool_vx,
                                 tool_vy, a.prm, dt, a.twin, a.tied, a.vslip)
        if touched:
            cuda.atomic.add(red, R_NC, 1.0)  # a count: exact in any order
        return cfx[n] != 0.0 or cfy[n] != 0.0

    @cuda.jit(device=True)
    def lane_sums(a, clist, m, lane, p):
        # one lane's contact force over the listed chunks (kernels.lane_sum)
        cfx, cfy = a.cfx, a.cfy
        nn = cfx.shape[0]
        sx = 0.0
        sy = 0.0
        for i in range(m):
            n = clist[i] * LANES + lane
            if n < nn:
                sx += cfx[n]
                sy += cfy[n]
        p[0, lane] = sx
        p[1, lane] = sy

    @cuda.jit(device=True)
    def tool_phase(a, clist, m, kv, dt, red):
        # the split by tool face, in increasing node order over the listed chunks (the CPU's
        # serial order; the other nodes carry no force), then the tool step
        cx, cy, tvx, tvy = kv
        x, y, cfx, cfy, prm = a.x, a.y, a.cfx, a.cfy, a.prm
        nn = x.shape[0]
        split_reset(red)
        for i in range(m):
            for lane in range(LANES):
                n = clist[i] * LANES + lane
                if n < nn:
                    split_add(n, x, y, cfx, cfy, cx, cy, prm, red)
        a.en[E_EXT] += tstep(a.tool, prm, red[R_FX], red[R_FY], dt)
        if CONDUCTION:
            prm[P_COND_ACC] += dt

    @cuda.jit(device=True)
    def ale_phase(a, step, tid, nthr, grid):
        # the tool-frame ALE pass (rezone.rezone) every rz_every steps: the same passes in the
        # same order, a barrier wherever one reads what another wrote
        if step % a.rz_every != 0:
            return
        x, y, xn, yn, x0, y0 = a.x, a.y, a.xn, a.yn, a.x0, a.y0
        vx, vy, acls, aflt, vbuf = a.vx, a.vy, a.acls, a.aflt, a.vbuf
        conn, ptr, nel, area0 = a.conn, a.ptr, a.nel, a.area0
        snodes, prm, mat = a.snodes, a.prm, a.mat
        nn = x.shape[0]
        ne = conn.shape[0]
        nsn = snodes.shape[0]
        off = prm[P_TCX] - prm[P_ALE_X0]
        mm = prm[P_RZ_MAXMOVE]
        tgeo = tool_geometry(prm)
        for n in range(tid, nn, nthr):
            xn[n] = x[n]
            yn[n] = y[n]
            tplace(n, x, y, xn, yn, x0, y0, acls, aflt, off, mm, tgeo)
        grid.sync()
        for n in range(tid, nn, nthr):
            tfacep(n, xn, yn, x0, y0, acls, aflt, off)
        grid.sync()
        for _sw in range(SWEEPS):
            for n in range(tid, nn, nthr):
                tsweep(n, acls, aflt, vbuf)
            grid.sync()
            for n in range(tid, nn, nthr):
                tscopy(n, acls, aflt, vbuf)
            grid.sync()
        for n in range(tid, nn, nthr):
            tinter(n, x, y, xn, yn, x0, y0, acls, aflt, off, mm)
        grid.sync()
        for e in range(tid, ne, nthr):
            flux_item(e, a)
        for k in range(tid, nsn, nthr):
            rvel(snodes[k], x, y, xn, yn, vx, vy, ptr, nel, conn, vbuf)
        grid.sync()
        for k in range(tid, nsn, nthr):
            n = snodes[k]
            vx[n] += vbuf[n, 0]
            vy[n] += vbuf[n, 1]
        for e in range(tid, ne, nthr):
            write_item(e, a)
        for n in range(tid, nn, nthr):
            x[n] = xn[n]
            y[n] = yn[n]
        grid.sync()
        rho_s = mat[RHO] * prm[P_MS]
        for n in range(tid, nn, nthr):
            rmass(n, ptr, nel, area0, rho_s, a.mass)
        grid.sync()

    @cuda.jit(device=True)
    def elem_phase(e, a, dt, red):
        d, inv = elem(e, a.conn, a.layer, a.area0, a.x, a.y, a.vx, a.vy, a.alive, a.qs, a.ie,
                      a.hge, a.fex, a.fey, a.dte, a.plast, a.rate, a.mat, a.prm, dt, a.erosion)
        cuda.atomic.min(red, R_DTMIN, d)
        if inv:
            cuda.atomic.max(red, R_BAD, float(e))

    @cuda.jit(device=True)
    def heat_phase(a, step, dt, tid, nthr, grid):
        # conduction every cond_every steps (the CPU's conduction pass), the phases of the
        # launch path separated by barriers
        if step % a.cond_every != 0:
            return
        conn, x, y, alive = a.conn, a.x, a.y, a.alive
        temp, tbuf, mat, prm = a.qs[QS_TEMP], a.tbuf, a.mat, a.prm
        ppair = a.ppair
        ne = conn.shape[0]
        npair = ppair.shape[0]
        for e in range(tid, ne, nthr):
            cent(e, conn, x, y, tbuf)
        grid.sync()
        for e in range(tid, ne, nthr):
            conduct_item(e, a)
        grid.sync()
        for e in range(tid, ne, nthr):
            temp[e] = tbuf[e, 3]
        grid.sync()
        if npair > 0:
            for i in range(tid, npair, nthr):
                parting_item(i, a)
            grid.sync()
        if a.theat != 0:
            tcq = a.tcq
            for n in range(tid, x.shape[0], nthr):
                theat_item(n, a)
            grid.sync()
            for e in range(tid, ne, nthr):
                thelem(e, conn, alive, temp, tcq, mat[RHO] * mat[CP])
            grid.sync()
        if tid == 0:
            prm[P_COND_ACC] = 0.0

    @cuda.jit(device=True)
    def no_heat(a, step, dt, tid, nthr, grid):
        # adiabatic: no heat phase
        return None

    @cuda.jit(device=True)
    def finish_phase(a, red):
        finish(a.tool, a.prm, a.clock, a.ist, a.hacc, a.hist, a.en, red,
               (a.mass, a.vx, a.vy, a.vx, a.ie, a.plast, a.hge,
                a.alive, a.fric, a.pen, a.ero_ke, a.nwork))

    # the launch-per-kernel path (no cooperative launch, or a per-kernel profile): one kernel
    # per pass on the state RunState ``a`` (and the reductions ``red``), as the phases per item

    @cuda.jit
    def k_nodes(a, red):
        n = cuda.grid(1)
        if n >= a.x.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        node_phase(n, a, kin(a.tool, a.prm), a.clock[1], red)

    @cuda.jit
    def k_contact_sum(a, red):
        # the CPU's fixed-order total (kernels.contact_total): one thread per lane, then
        # the lanes in order by thread 0 -- the same bits on both devices; then the split by
        # tool face over every node in order (the persistent kernel visits only the chunks
        # holding a contact node)
        x, y, cfx, cfy, prm = a.x, a.y, a.cfx, a.cfy, a.prm
        t = cuda.threadIdx.x
        px = cuda.shared.array(LANES, float64)
        py = cuda.shared.array(LANES, float64)
        px[t] = lsum(cfx, t, LANES)
        py[t] = lsum(cfy, t, LANES)
        cuda.syncthreads()
        if t == 0:
            lanes_total(px, py, red)
            cx, cy, tvx, tvy = kin(a.tool, prm)
            split_reset(red)
            for n in range(x.shape[0]):
                split_add(n, x, y, cfx, cfy, cx, cy, prm, red)

    @cuda.jit
    def k_ale_place(a):
        n = cuda.grid(1)
        if n >= a.x.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        x, y, xn, yn, prm = a.x, a.y, a.xn, a.yn, a.prm
        xn[n] = x[n]
        yn[n] = y[n]
        tplace(n, x, y, xn, yn, a.x0, a.y0, a.acls, a.aflt, prm[P_TCX] - prm[P_ALE_X0],
               prm[P_RZ_MAXMOVE], tool_geometry(prm))

    @cuda.jit
    def k_ale_face(a):
        n = cuda.grid(1)
        if n >= a.xn.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        prm = a.prm
        tfacep(n, a.xn, a.yn, a.x0, a.y0, a.acls, a.aflt, prm[P_TCX] - prm[P_ALE_X0])

    @cuda.jit
    def k_ale_sweep(a):
        n = cuda.grid(1)
        if n >= a.acls.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        tsweep(n, a.acls, a.aflt, a.vbuf)

    @cuda.jit
    def k_ale_sweep_copy(a):
        n = cuda.grid(1)
        if n >= a.acls.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        tscopy(n, a.acls, a.aflt, a.vbuf)

    @cuda.jit
    def k_ale_interior(a):
        n = cuda.grid(1)
        if n >= a.x.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        prm = a.prm
        tinter(n, a.x, a.y, a.xn, a.yn, a.x0, a.y0, a.acls, a.aflt,
               prm[P_TCX] - prm[P_ALE_X0], prm[P_RZ_MAXMOVE])

    @cuda.jit
    def k_ale_flux(a):
        e = cuda.grid(1)
        if e >= a.conn.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        flux_item(e, a)

    @cuda.jit
    def k_ale_velocity(a):
        k = cuda.grid(1)
        if k >= a.snodes.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        rvel(a.snodes[k], a.x, a.y, a.xn, a.yn, a.vx, a.vy, a.ptr, a.nel, a.conn, a.vbuf)

    @cuda.jit
    def k_ale_apply(a):
        k = cuda.grid(1)
        if k >= a.snodes.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        n = a.snodes[k]
        a.vx[n] += a.vbuf[n, 0]
        a.vy[n] += a.vbuf[n, 1]

    @cuda.jit
    def k_ale_write(a):
        e = cuda.grid(1)
        if e >= a.alive.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        write_item(e, a)

    @cuda.jit
    def k_ale_nodes(a):
        n = cuda.grid(1)
        if n >= a.x.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        a.x[n] = a.xn[n]
        a.y[n] = a.yn[n]

    @cuda.jit
    def k_ale_mass(a):
        n = cuda.grid(1)
        if n >= a.mass.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        rmass(n, a.ptr, a.nel, a.area0, a.mat[RHO] * a.prm[P_MS], a.mass)

    @cuda.jit
    def k_tool(a, red):
        if cuda.grid(1) != 0 or a.ist[I_STATUS] != ST_OK:
            return
        prm = a.prm
        dt = a.clock[1]
        a.en[E_EXT] += tstep(a.tool, prm, red[R_FX], red[R_FY], dt)
        if CONDUCTION:
            prm[P_COND_ACC] += dt
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
        cent(e, a.conn, a.x, a.y, a.tbuf)

    @cuda.jit
    def k_conduct(a):
        e = cuda.grid(1)
        if e >= a.conn.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        conduct_item(e, a)

    @cuda.jit
    def k_conduct_end(a):
        e = cuda.grid(1)
        if e >= a.qs.shape[1] or a.ist[I_STATUS] != ST_OK:
            return
        a.qs[QS_TEMP, e] = a.tbuf[e, 3]

    @cuda.jit
    def k_parting(a):
        i = cuda.grid(1)
        if i >= a.ppair.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        parting_item(i, a)

    @cuda.jit
    def k_theat_nodes(a):
        n = cuda.grid(1)
        if n >= a.x.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        theat_item(n, a)

    @cuda.jit
    def k_theat_elems(a):
        e = cuda.grid(1)
        if e >= a.conn.shape[0] or a.ist[I_STATUS] != ST_OK:
            return
        mat = a.mat
        thelem(e, a.conn, a.alive, a.qs[QS_TEMP], a.tcq, mat[RHO] * mat[CP])

    @cuda.jit
    def k_conduct_reset(a):
        if cuda.grid(1) == 0 and a.ist[I_STATUS] == ST_OK:
            a.prm[P_COND_ACC] = 0.0

    @cuda.jit
    def k_finish(a, red):
        if cuda.grid(1) == 0 and a.ist[I_STATUS] == ST_OK:
            finish_phase(a, red)

    # the tool step writes the new edge centre into prm[P_TCX], prm[P_TCY], which the
    # elements' gated erosion and the ALE pass read: a barrier after the tool
    k_run = persistent_kernel(n_sums=2, kinematics=kin, node=node_phase,
                              lane_sums=lane_sums, tool=tool_phase, elem=elem_phase,
                              heat=heat_phase if phases.conduction else no_heat,
                              finish=finish_phase,
                              remesh=ale_phase if phases.tool_frame else None,
                              sync_after_tool=True)

    ale = (k_ale_place, k_ale_face, k_ale_sweep, k_ale_sweep_copy, k_ale_interior, k_ale_flux,
           k_ale_velocity, k_ale_apply, k_ale_write, k_ale_nodes, k_ale_mass)
    return (k_nodes, k_contact_sum, k_tool, k_elems, k_centroids, k_conduct, k_conduct_end,
            k_parting, k_theat_nodes, k_theat_elems, k_conduct_reset, k_finish, k_run, ale)
