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

from robobore.cutting.fe.engine import layout
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
        csplit(n, cfx, cfy, x, y, cx, cy, prm[P_NRX], prm[P_NRY], prm[P_NFX], prm[P_NFY],
               red, R_SPLIT)

    @cuda.jit(device=True)
    def split_reset(red):
        for j in range(6):
            red[R_SPLIT + j] = 0.0

    @cuda.jit
    def k_nodes(x, y, vx, vy, mass, fixed, ptr, nel, ncorner, alive, area0, fex, fey, cfx, cfy,
                fric, pen, ndead, ero_ke, nwork, prm, tool, clock, ist, twin, tied, vslip, red):
        n = cuda.grid(1)
        if n >= x.shape[0] or ist[I_STATUS] != ST_OK:
            return
        cx, cy, tvx, tvy = kin(tool, prm)
        fcx, fcy, touched = node(n, x, y, vx, vy, mass, fixed, ptr, nel, ncorner, alive, area0,
                                 fex, fey, cfx, cfy, fric, pen, ndead, ero_ke, nwork, cx, cy,
                                 tvx, tvy, prm, clock[1], twin, tied, vslip)
        if touched:
            cuda.atomic.add(red, R_NC, 1.0)  # a count: exact in any order

    @cuda.jit
    def k_contact_sum(cfx, cfy, x, y, tool, prm, red):
        # the CPU's fixed-order total (kernels.contact_total): one thread per lane, then
        # the lanes in order by thread 0 -- the same bits on both devices; then the split by
        # tool face over every node in order (the persistent kernel visits only the chunks
        # holding a contact node)
        t = cuda.threadIdx.x
        px = cuda.shared.array(LANES, float64)
        py = cuda.shared.array(LANES, float64)
        px[t] = lsum(cfx, t, LANES)
        py[t] = lsum(cfy, t, LANES)
        cuda.syncthreads()
        if t == 0:
            lanes_total(px, py, red)
            cx, cy, tvx, tvy = kin(tool, prm)
            split_reset(red)
            for n in range(x.shape[0]):
                split_add(n, x, y, cfx, cfy, cx, cy, prm, red)

    @cuda.jit
    def k_ale_place(x, y, xn, yn, x0, y0, acls, aflt, prm, ist):
        n = cuda.grid(1)
        if n >= x.shape[0] or ist[I_STATUS] != ST_OK:
            return
        xn[n] = x[n]
        yn[n] = y[n]
        tplace(n, x, y, xn, yn, x0, y0, acls, aflt, prm[P_TCX] - prm[P_ALE_X0],
               prm[P_RZ_MAXMOVE], tool_geometry(prm))

    @cuda.jit
    def k_ale_face(xn, yn, x0, y0, acls, aflt, prm, ist):
        n = cuda.grid(1)
        if n >= xn.shape[0] or ist[I_STATUS] != ST_OK:
            return
        tfacep(n, xn, yn, x0, y0, acls, aflt, prm[P_TCX] - prm[P_ALE_X0])

    @cuda.jit
    def k_ale_sweep(acls, aflt, vbuf, ist):
        n = cuda.grid(1)
        if n >= acls.shape[0] or ist[I_STATUS] != ST_OK:
            return
        tsweep(n, acls, aflt, vbuf)

    @cuda.jit
    def k_ale_sweep_copy(acls, aflt, vbuf, ist):
        n = cuda.grid(1)
        if n >= acls.shape[0] or ist[I_STATUS] != ST_OK:
            return
        tscopy(n, acls, aflt, vbuf)

    @cuda.jit
    def k_ale_interior(x, y, xn, yn, x0, y0, acls, aflt, prm, ist):
        n = cuda.grid(1)
        if n >= x.shape[0] or ist[I_STATUS] != ST_OK:
            return
        tinter(n, x, y, xn, yn, x0, y0, acls, aflt, prm[P_TCX] - prm[P_ALE_X0],
               prm[P_RZ_MAXMOVE])

    @cuda.jit
    def k_ale_flux(conn, x, y, xn, yn, alive, enbr, bflag, buf, sdx, sdy, sdz, sdxy, pres,
                   eps_p, temp, dm, qhx, qhy, area0, mat, ist):
        e = cuda.grid(1)
        if e >= conn.shape[0] or ist[I_STATUS] != ST_OK:
            return
        rflux(e, conn, alive, (x, y), (xn, yn), enbr, bflag, buf,
              (sdx, sdy, sdz, sdxy, pres, eps_p, temp, dm, qhx, qhy, area0), mat[TROOM])

    @cuda.jit
    def k_ale_velocity(snodes, x, y, xn, yn, vx, vy, ptr, nel, conn, vbuf, ist):
        k = cuda.grid(1)
        if k >= snodes.shape[0] or ist[I_STATUS] != ST_OK:
            return
        rvel(snodes[k], x, y, xn, yn, vx, vy, ptr, nel, conn, vbuf)

    @cuda.jit
    def k_ale_apply(snodes, vx, vy, vbuf, ist):
        k = cuda.grid(1)
        if k >= snodes.shape[0] or ist[I_STATUS] != ST_OK:
            return
        n = snodes[k]
        vx[n] += vbuf[n, 0]
        vy[n] += vbuf[n, 1]

    @cuda.jit
    def k_ale_write(alive, buf, sdx, sdy, sdz, sdxy, pres, eps_p, temp, dm, qhx, qhy, area0,
                    ist):
        e = cuda.grid(1)
        if e >= alive.shape[0] or ist[I_STATUS] != ST_OK:
            return
        rwrite(e, alive, buf, sdx, sdy, sdz, sdxy, pres, eps_p, temp, dm, qhx, qhy, area0)

    @cuda.jit
    def k_ale_nodes(x, y, xn, yn, ist):
        n = cuda.grid(1)
        if n >= x.shape[0] or ist[I_STATUS] != ST_OK:
            return
        x[n] = xn[n]
        y[n] = yn[n]

    @cuda.jit
    def k_ale_mass(ptr, nel, area0, mass, mat, prm, ist):
        n = cuda.grid(1)
        if n >= mass.shape[0] or ist[I_STATUS] != ST_OK:
            return
        rmass(n, ptr, nel, area0, mat[RHO] * prm[P_MS], mass)

    @cuda.jit
    def k_tool(tool, prm, en, clock, ist, red):
        if cuda.grid(1) != 0 or ist[I_STATUS] != ST_OK:
            return
        dt = clock[1]
        en[E_EXT] += tstep(tool, prm, red[R_FX], red[R_FY], dt)
        if CONDUCTION:
            prm[P_COND_ACC] += dt
        red[R_DTMIN] = 1e30
        red[R_BAD] = -1.0

    @cuda.jit
    def k_elems(conn, x, y, vx, vy, alive, layer, sdx, sdy, sdz, sdxy, pres, eps_p, temp, dm,
                qhx, qhy, area0, ie, hge, fex, fey, dte, plast, rate, mat, prm, clock, erosion,
                ist, red):
        e = cuda.grid(1)
        if e >= conn.shape[0] or ist[I_STATUS] != ST_OK:
            return
        d, inv = elem(e, conn, x, y, vx, vy, alive, layer, sdx, sdy, sdz, sdxy, pres, eps_p,
                      temp, dm, qhx, qhy, area0, ie, hge, fex, fey, dte, plast, rate, mat, prm,
                      clock[1], erosion)
        cuda.atomic.min(red, R_DTMIN, d)
        if inv:
            cuda.atomic.max(red, R_BAD, float(e))

    @cuda.jit
    def k_centroids(conn, x, y, tbuf, ist):
        e = cuda.grid(1)
        if e >= conn.shape[0] or ist[I_STATUS] != ST_OK:
            return
        cent(e, conn, x, y, tbuf)

    @cuda.jit
    def k_conduct(conn, x, y, alive, enbr, temp, tbuf, mat, prm, ist):
        e = cuda.grid(1)
        if e >= conn.shape[0] or ist[I_STATUS] != ST_OK:
            return
        cond(e, conn, x, y, alive, enbr, temp, tbuf, mat[KCOND], mat[RHO] * mat[CP],
             prm[P_COND_ACC])

    @cuda.jit
    def k_conduct_end(temp, tbuf, prm, ist):
        e = cuda.grid(1)
        if e >= temp.shape[0] or ist[I_STATUS] != ST_OK:
            return
        temp[e] = tbuf[e, 3]

    @cuda.jit
    def k_parting(ppair, x, y, alive, tied, temp, tbuf, mat, prm, ist):
        i = cuda.grid(1)
        if i >= ppair.shape[0] or ist[I_STATUS] != ST_OK:
            return
        pedge(i, ppair, x, y, alive, tied, temp, tbuf, mat[KCOND], mat[RHO] * mat[CP],
              prm[P_COND_ACC])

    @cuda.jit
    def k_theat_nodes(conn, x, y, ptr, nel, ncorner, alive, enbr, cfx, cfy, fric, fheat, temp,
                      tbuf, tcq, mat, prm, ist):
        n = cuda.grid(1)
        if n >= x.shape[0] or ist[I_STATUS] != ST_OK:
            return
        thnode(n, conn, x, y, ptr, nel, ncorner, alive, enbr, cfx, cfy, fric, fheat, temp,
               tbuf, tcq, mat[RHO] * mat[CP], prm[P_HC], prm[P_FHEAT], prm[P_TTOOL],
               prm[P_COND_ACC])

    @cuda.jit
    def k_theat_elems(conn, alive, temp, tcq, mat, ist):
        e = cuda.grid(1)
        if e >= conn.shape[0] or ist[I_STATUS] != ST_OK:
            return
        thelem(e, conn, alive, temp, tcq, mat[RHO] * mat[CP])

    @cuda.jit
    def k_conduct_reset(prm, ist):
        if cuda.grid(1) != 0 or ist[I_STATUS] != ST_OK:
            return
        prm[P_COND_ACC] = 0.0

    @cuda.jit(device=True)
    def finish(tool, prm, clock, ist, hacc, hist, en, red, es):
        # the step end (one thread): history.make_end_step's end_step on the step's reductions
        nc = red[R_NC]
        red[R_NC] = 0.0  # the force total is rewritten by k_contact_sum every step
        end_step(clock[1], (red[R_DTMIN], int(red[R_BAD])), (red[R_FX], red[R_FY], 0.0, nc),
                 red[R_SPLIT:], ist, clock, prm, tool, en, hacc, hist, es)

    @cuda.jit
    def k_finish(tool, prm, clock, ist, hacc, hist, en, red, mass, vx, vy, ie, plast, hge,
                 alive, fric, pen, ero_ke, nwork):
        if cuda.grid(1) != 0 or ist[I_STATUS] != ST_OK:
            return
        finish(tool, prm, clock, ist, hacc, hist, en, red,
               (mass, vx, vy, vx, ie, plast, hge, alive, fric, pen, ero_ke, nwork))

    # the persistent kernel's phases (engine.gpu.persistent), on the state RunState

    @cuda.jit(device=True)
    def node_phase(n, a, kv, dt, red):
        cx, cy, tvx, tvy = kv
        cfx, cfy = a.cfx, a.cfy
        fcx, fcy, touched = node(n, a.x, a.y, a.vx, a.vy, a.mass, a.fixed,
                                 a.ptr, a.nel, a.ncorner, a.alive, a.area0,
                                 a.fex, a.fey, cfx, cfy, a.fric, a.pen,
                                 a.ndead, a.ero_ke, a.nwork, cx, cy, tvx, tvy,
                                 a.prm, dt, a.twin, a.tied, a.vslip)
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
        conn, alive, ptr, nel, area0 = a.conn, a.alive, a.ptr, a.nel, a.area0
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
            rflux(e, conn, alive, (x, y), (xn, yn), a.enbr, a.bflag, a.buf,
                  (a.sdx, a.sdy, a.sdz, a.sdxy, a.pres, a.eps_p, a.temp, a.dmg,
                   a.qhx, a.qhy, area0), mat[TROOM])
        for k in range(tid, nsn, nthr):
            rvel(snodes[k], x, y, xn, yn, vx, vy, ptr, nel, conn, vbuf)
        grid.sync()
        for k in range(tid, nsn, nthr):
            n = snodes[k]
            vx[n] += vbuf[n, 0]
            vy[n] += vbuf[n, 1]
        for e in range(tid, ne, nthr):
            rwrite(e, alive, a.buf, a.sdx, a.sdy, a.sdz, a.sdxy, a.pres,
                   a.eps_p, a.temp, a.dmg, a.qhx, a.qhy, area0)
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
        d, inv = elem(e, a.conn, a.x, a.y, a.vx, a.vy, a.alive, a.layer,
                      a.sdx, a.sdy, a.sdz, a.sdxy, a.pres, a.eps_p,
                      a.temp, a.dmg, a.qhx, a.qhy, a.area0, a.ie, a.hge,
                      a.fex, a.fey, a.dte, a.plast, a.rate, a.mat, a.prm,
                      dt, a.erosion)
        cuda.atomic.min(red, R_DTMIN, d)
        if inv:
            cuda.atomic.max(red, R_BAD, float(e))

    @cuda.jit(device=True)
    def heat_phase(a, step, dt, tid, nthr, grid):
        # conduction every cond_every steps (the CPU's conduction pass), the phases of the
        # launch path separated by barriers
        if step % a.cond_every != 0:
            return
        conn, x, y, alive, enbr = a.conn, a.x, a.y, a.alive, a.enbr
        temp, tbuf, mat, prm = a.temp, a.tbuf, a.mat, a.prm
        ppair = a.ppair
        ne = conn.shape[0]
        npair = ppair.shape[0]
        for e in range(tid, ne, nthr):
            cent(e, conn, x, y, tbuf)
        grid.sync()
        for e in range(tid, ne, nthr):
            cond(e, conn, x, y, alive, enbr, temp, tbuf, mat[KCOND], mat[RHO] * mat[CP],
                 prm[P_COND_ACC])
        grid.sync()
        for e in range(tid, ne, nthr):
            temp[e] = tbuf[e, 3]
        grid.sync()
        if npair > 0:
            for i in range(tid, npair, nthr):
                pedge(i, ppair, x, y, alive, a.tied, temp, tbuf, mat[KCOND],
                      mat[RHO] * mat[CP], prm[P_COND_ACC])
            grid.sync()
        if a.theat != 0:
            tcq = a.tcq
            for n in range(tid, x.shape[0], nthr):
                thnode(n, conn, x, y, a.ptr, a.nel, a.ncorner, alive, enbr, a.cfx,
                       a.cfy, a.fric, a.fheat, temp, tbuf, tcq, mat[RHO] * mat[CP],
                       prm[P_HC], prm[P_FHEAT], prm[P_TTOOL], prm[P_COND_ACC])
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
