"""GPU backend of the 2D explicit engine (numba-cuda), built from the SAME scalar physics.

The per-element, per-node, tool and conduction updates are the plain-Python scalar functions
of the CPU engine (:func:`kernels.quad_element_py`, :func:`kernels.quad_node_py`,
:func:`kernels.tool_kinematics_py`, :func:`kernels.tool_step_py`,
:func:`kernels.quad_centroid_py`, :func:`kernels.quad_conduct_py`,
:func:`kernels.sum_energies_py`) and the shared material/contact/support functions
(:mod:`robobore.material.johnson_cook`, :mod:`robobore.cutting.fe.physics`), re-bound to
device versions with :func:`robobore.material.johnson_cook.rebind` and compiled with
``numba.cuda.jit(device=True)``; the CPU engine calls the ``njit`` versions of the same
functions from its ``prange`` loops.

One time step is five kernel launches: nodes (contact count by atomic add), the contact-
force total (one block, summed in the CPU engine's fixed lane order,
``kernels.contact_total``: the same bits on both devices), the tool (one thread: support
springs, external work), elements (stable step by atomic min, inverted element by atomic
max) and the step end (one thread: time, status, time-averaged histories and, at each
sample, the energy totals summed serially in the CPU engine's order). With
``solver.heat_conduction`` more launches run every ``solver.conduction_interval`` steps:
centroids, fluxes, copy, the tied parting-line edges (node splitting), the thermal
contact with the tool (nodes, then elements) and the reset of the accumulated time. The
loop stays on the device; the host copies the state back between chunks (for the progress
bar and the energy check).


Optional: needs an NVIDIA GPU and numba's CUDA target (``pip install robobore[gpu]``).
Importing this module needs neither; :func:`robobore.cutting.fe.gpu.require_gpu` raises a
clear :class:`robobore.errors.ConfigError` when no GPU is usable. Correctness is tested on
the CPU with numba's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1``) against the CPU engine. The
workpiece-frame model is timed on an H100 (docs/fe.md, "GPU path"); the tool-frame model is
checked in the simulator and compiled for sm_90, not timed on a GPU.

The tool-frame ALE model (``mesh.frame = "tool"``) runs here too: every
``solver.ale_interval`` steps, after the tool step, the persistent kernel runs the ALE pass of
:func:`robobore.cutting.fe.rezone.rezone` (``MODE_TOOLFRAME``) from the same scalar functions
(``tf_place_py``, ``tf_face_py``, the Jacobi sweeps ``tf_sweep_py`` / ``tf_sweep_copy_py``,
``tf_interior_py``, the donor-cell remap ``rz_flux_py``, ``rz_velocity_py``, ``rz_write_py``,
``rz_node_mass_py``), a grid barrier wherever one pass reads what another wrote (14 per
pass); the launch-per-kernel path launches one kernel per pass. The contact force by tool
face (``kernels.contact_split``) is added by one thread in increasing node order over the
chunks holding a contact node: the CPU's serial order, the same bits.

Kernel parameters: the persistent kernel takes the whole state, 3944 bytes of CUDA's classic
4096-byte limit (checked by a test with numba's data model).

Not ported: Laplacian rezoning (``solver.rezone_interval`` > 0), the ploughed-layer ALE and
the B-bar element are refused with a ConfigError.
"""

from __future__ import annotations

import functools
import math  # noqa: F401  (math.isfinite inside the kernels)
from collections.abc import Callable
from typing import Any

import numpy as np

from robobore.cutting.fe import kernels as K
from robobore.cutting.fe import rezone as RZ
from robobore.cutting.fe.gpu import (
    MAX_BLOCK,
    bind_cuda,
    chunk_list_py,
    jc_device_functions,
    persistent_run,
    profile_ticker,
    require_gpu,
)
from robobore.cutting.fe.rezone import MODE_LAPLACE, MODE_ROWS, MODE_TOOLFRAME
from robobore.cutting.fe.status import STATUS_TEXT, instability_error
from robobore.errors import ConfigError

__all__ = ["advance_gpu", "check_gpu_supported"]

_THREADS = 128
# reduction slots on the device
R_DTMIN, R_BAD, R_FX, R_FY, R_NC = 0, 1, 2, 3, 4
#: the contact force by tool face (kernels.contact_split): rake x, y, edge arc x, y, flank x, y
R_SPLIT = 5
N_RED = 11

#: the numba.cuda module, bound on first use (a module global, so that numba's simulator can
#: substitute its own inside the kernels)
cuda = None


def check_gpu_supported(rezone_interval: int, source: str | None = None,
                        element: str = "q4r", edge_ale_interval: int = 0) -> None:
    """Raise a ConfigError for a setting the GPU engine does not run (rezoning, the
    ploughed-layer ALE, B-bar)."""
    if element != "q4r":
        raise ConfigError("the B-bar element is not ported to the GPU", file=source,
                          field="solver.element", value=element,
                          expected='"q4r" with --device gpu, or --device cpu')
    if rezone_interval > 0:
        raise ConfigError("rezoning is not available on the GPU", file=source,
                          field="solver.rezone_interval", value=rezone_interval,
                          expected="0 (off, the default) with --device gpu, or --device cpu")
    if edge_ale_interval > 0:
        raise ConfigError("the ploughed-layer ALE is not available on the GPU", file=source,
                          field="solver.edge_ale_interval", value=edge_ale_interval,
                          expected="0 (off, the default) with --device gpu, or --device cpu")


@functools.lru_cache(maxsize=1)
def _kernels():
    """Compile (lazily, once) the device functions and kernels."""
    global cuda
    cuda = bind_cuda()  # also the gpu module's, for chunk_list_py
    from numba import float64 as _float64
    from numba import int64 as _int64

    from robobore.cutting.fe.physics import (
        contact_force_py,
        tool_face_py,
        tool_gap_py,
        tool_support_step_py,
    )
    from robobore.material import johnson_cook as jc

    dev = cuda.jit(device=True)
    dmg, ret = jc_device_functions(dev)
    rret = dev(jc.rebind(jc.radial_return_py, jc_return=ret))
    tface = dev(tool_face_py)
    tg = dev(jc.rebind(tool_gap_py, tool_face=tface))
    csplit = dev(jc.rebind(K.contact_split_node_py, tool_face=tface))
    tool_geometry = dev(K.tool_geometry_py)
    # the tool-frame ALE pass (rezone.py's scalar functions)
    lim = dev(RZ.limit_py)
    tplace = dev(jc.rebind(RZ.tf_place_py, _limit=lim,
                           _off_tool=dev(jc.rebind(RZ.off_tool_py, tool_gap=tg))))
    tfacep = dev(RZ.tf_face_py)
    tsweep = dev(RZ.tf_sweep_py)
    tscopy = dev(RZ.tf_sweep_copy_py)
    tinter = dev(jc.rebind(RZ.tf_interior_py, _limit=lim))
    rflux = dev(jc.rebind(RZ.rz_flux_py, _swept=dev(RZ.swept_py)))
    rvel = dev(RZ.rz_velocity_py)
    rwrite = dev(RZ.rz_write_py)
    rmass = dev(RZ.rz_node_mass_py)
    SWEEPS = RZ.TF_SWEEPS
    cf = dev(contact_force_py)
    sup = dev(tool_support_step_py)
    retire = dev(K.quad_retire_py)
    elem = dev(jc.rebind(
        K.quad_element_py, radial_return=rret, jc_damage_increment=dmg, quad_retire=retire,
        quad_area_corners=dev(K.quad_area_corners_py),
        quad_distorted=dev(jc.rebind(K.quad_distorted_py, quad_retire=retire)),
        quad_bvectors=dev(K.quad_bvectors_py), quad_step=dev(K.quad_step_py),
        damage_erosion=dev(jc.rebind(K.damage_erosion_py, tool_gap=tg))))
    node = dev(jc.rebind(K.quad_node_py, tool_gap=tg, contact_force=cf,
                         friction_at=dev(K.friction_at_py)))
    kin = dev(K.tool_kinematics_py)
    tstep = dev(jc.rebind(K.tool_step_py, tool_support_step=sup))
    cent = dev(K.quad_centroid_py)
    cond = dev(K.quad_conduct_py)
    pedge = dev(K.parting_edge_py)
    thnode = dev(K.tool_heat_node_py)
    thelem = dev(K.tool_heat_elem_py)
    sumen = dev(K.sum_energies_py)
    lsum = dev(K.lane_sum_py)
    chunks = dev(chunk_list_py)
    LANES = K.N_SUM_LANES
    float64 = _float64
    int64 = _int64
    NCNT = MAX_BLOCK + 1

    I_STATUS, I_STEP, I_SAMPLE, I_BADELEM = K.I_STATUS, K.I_STEP, K.I_SAMPLE, K.I_BADELEM
    ST_OK, ST_DONE, ST_INV = K.STATUS_OK, K.STATUS_DONE, K.STATUS_INVERTED
    ST_NOEL, ST_NONF, ST_DTC = K.STATUS_NO_ELEMENTS, K.STATUS_NONFINITE, K.STATUS_DT_COLLAPSE
    P_CFL, P_DTMIN, P_TEND, P_SAMPLE_DT = K.P_CFL, K.P_DTMIN, K.P_TEND, K.P_SAMPLE_DT
    P_COND_EVERY, P_COND_ACC = K.P_COND_EVERY, K.P_COND_ACC
    P_HC, P_FHEAT, P_TTOOL = K.P_HC, K.P_FHEAT, K.P_TTOOL
    P_TCX, P_NRX, P_NRY, P_NFX, P_NFY = K.P_TCX, K.P_NRX, K.P_NRY, K.P_NFX, K.P_NFY
    P_ALE_X0, P_RZ_MAXMOVE, P_MS = K.P_ALE_X0, K.P_RZ_MAXMOVE, K.P_MS
    H_FX_RAKE = K.H_FX_RAKE
    T_FX, T_FY, T_UX, T_UY, T_GX = K.T_FX, K.T_FY, K.T_UX, K.T_UY, K.T_GX
    E_EXT, E_KIN, E_INT, E_PLAST, E_HG, E_FRIC, E_ERODED = (K.E_EXT, K.E_KIN, K.E_INT,
                                                            K.E_PLAST, K.E_HG, K.E_FRIC,
                                                            K.E_ERODED)
    H_T, H_FX, H_FY, H_UX, H_UY, H_TIP_X, H_NCONT = (K.H_T, K.H_FX, K.H_FY, K.H_UX, K.H_UY,
                                                     K.H_TIP_X, K.H_NCONT)
    H_EKIN, H_EINT, H_EPL, H_EHG, H_EFRIC, H_EEXT, H_EERO = (K.H_EKIN, K.H_EINT, K.H_EPL,
                                                             K.H_EHG, K.H_EFRIC, K.H_EEXT,
                                                             K.H_EERO)
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
        rflux(e, conn, x, y, xn, yn, alive, enbr, bflag, buf, sdx, sdy, sdz, sdxy, pres,
              eps_p, temp, dm, qhx, qhy, area0, mat[TROOM])

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
        if prm[P_COND_EVERY] > 0.0:
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
    def finish(tool, prm, clock, ist, hacc, hist, en, red, mass, vx, vy, ie, plast, hge, alive,
               fric, pen, ero_ke, nwork):
        # the step end (one thread): time, stable step, status, histories
        dt = clock[1]
        fwx = red[R_FX]
        fwy = red[R_FY]
        nc = red[R_NC]
        red[R_NC] = 0.0  # the force total is rewritten by k_contact_sum every step
        if red[R_BAD] >= 0.0:
            ist[I_BADELEM] = int(red[R_BAD])
            ist[I_STATUS] = ST_INV
            return
        dtmin = red[R_DTMIN]
        if dtmin >= 1e30:
            ist[I_STATUS] = ST_NOEL
            return
        new_dt = prm[P_CFL] * dtmin
        t = clock[0] + dt
        clock[0] = t
        ist[I_STEP] += 1
        if not (math.isfinite(fwx) and math.isfinite(fwy) and math.isfinite(new_dt)):
            ist[I_STATUS] = ST_NONF
            return
        clock[1] = new_dt
        if new_dt < prm[P_DTMIN]:
            ist[I_STATUS] = ST_DTC
            return
        hacc[H_FX] += dt * tool[T_FX]
        hacc[H_FY] += dt * tool[T_FY]
        hacc[H_UX] += dt * tool[T_UX]
        hacc[H_UY] += dt * tool[T_UY]
        hacc[H_NCONT] += dt * nc
        for j in range(6):
            hacc[H_FX_RAKE + j] += dt * red[R_SPLIT + j]
        clock[2] += dt
        k = ist[I_SAMPLE]
        if t >= (k + 1) * prm[P_SAMPLE_DT] and k < hist.shape[0]:
            ta = clock[2]
            sumen(mass, vx, vy, ie, plast, hge, alive, fric, pen, ero_ke, nwork, en)
            if not math.isfinite(en[E_KIN]):
                ist[I_STATUS] = ST_NONF
                return
            hist[k, H_T] = t
            hist[k, H_FX] = hacc[H_FX] / ta
            hist[k, H_FY] = hacc[H_FY] / ta
            hist[k, H_UX] = hacc[H_UX] / ta
            hist[k, H_UY] = hacc[H_UY] / ta
            hist[k, H_NCONT] = hacc[H_NCONT] / ta
            for j in range(6):
                hist[k, H_FX_RAKE + j] = hacc[H_FX_RAKE + j] / ta
            hist[k, H_TIP_X] = tool[T_GX] + tool[T_UX]
            hist[k, H_EKIN] = en[E_KIN]
            hist[k, H_EINT] = en[E_INT]
            hist[k, H_EPL] = en[E_PLAST]
            hist[k, H_EHG] = en[E_HG]
            hist[k, H_EFRIC] = en[E_FRIC]
            hist[k, H_EEXT] = en[E_EXT]
            hist[k, H_EERO] = en[E_ERODED]
            for j in range(hacc.shape[0]):
                hacc[j] = 0.0
            clock[2] = 0.0
            ist[I_SAMPLE] = k + 1
        if t >= prm[P_TEND]:
            ist[I_STATUS] = ST_DONE
            sumen(mass, vx, vy, ie, plast, hge, alive, fric, pen, ero_ke, nwork, en)

    @cuda.jit
    def k_finish(tool, prm, clock, ist, hacc, hist, en, red, mass, vx, vy, ie, plast, hge,
                 alive, fric, pen, ero_ke, nwork):
        if cuda.grid(1) != 0 or ist[I_STATUS] != ST_OK:
            return
        finish(tool, prm, clock, ist, hacc, hist, en, red, mass, vx, vy, ie, plast, hge, alive,
               fric, pen, ero_ke, nwork)

    @cuda.jit
    def k_run(n_steps, x, y, vx, vy, mass, fixed, ptr, nel, ncorner, conn, layer, alive, sdx,
              sdy, sdz, sdxy, pres, eps_p, temp, dm, qhx, qhy, area0, ie, hge, fex, fey, dte,
              plast, rate, cfx, cfy, fric, pen, ndead, ero_ke, nwork, mat, prm, tool, en, ist,
              clock, hacc, hist, enbr, twin, tied, tbuf, fheat, tcq, ppair, vslip, snodes, x0,
              y0, xn, yn, buf, vbuf, acls, aflt, bflag, erosion, cond_every, theat, rz_every,
              red, cflag, clist):
        # ``n_steps`` whole steps in one cooperative launch (a persistent kernel): the phases
        # of the kernels above separated by grid-wide barriers (one launch per chunk instead
        # of five to twelve per step); same functions, same order, same bits
        grid = cuda.cg.this_grid()
        tid = cuda.grid(1)
        nthr = cuda.gridsize(1)
        t = cuda.threadIdx.x
        nb = cuda.blockDim.x
        nn = x.shape[0]
        ne = conn.shape[0]
        npair = ppair.shape[0]
        nsn = snodes.shape[0]
        rho_s = mat[RHO] * prm[P_MS]
        px = cuda.shared.array(LANES, float64)
        py = cuda.shared.array(LANES, float64)
        cnt = cuda.shared.array(NCNT, int64)
        for _ in range(n_steps):
            if ist[I_STATUS] != ST_OK:
                return
            step = ist[I_STEP]
            dt = clock[1]
            cx, cy, tvx, tvy = kin(tool, prm)
            for n in range(tid, nn, nthr):
                fcx, fcy, touched = node(n, x, y, vx, vy, mass, fixed, ptr, nel, ncorner, alive,
                                         area0, fex, fey, cfx, cfy, fric, pen, ndead, ero_ke,
                                         nwork, cx, cy, tvx, tvy, prm, dt, twin, tied,
                                         vslip)
                if touched:
                    cuda.atomic.add(red, R_NC, 1.0)
                if cfx[n] != 0.0 or cfy[n] != 0.0:
                    cflag[n // LANES] = 1  # the chunk of LANES nodes holding n has contact
            grid.sync()
            if cuda.blockIdx.x == 0:
                # block 0: the contact-force total in the CPU's lane order over the chunks
                # holding a contact node (the others hold zeros), then the tool
                m = chunks(cflag, clist, cnt, t, nb)
                for lane in range(t, LANES, nb):
                    sx = 0.0
                    sy = 0.0
                    for i in range(m):
                        n = clist[i] * LANES + lane
                        if n < nn:
                            sx += cfx[n]
                            sy += cfy[n]
                    px[lane] = sx
                    py[lane] = sy
                cuda.syncthreads()
                if t == 0:
                    sx, sy = lanes_total(px, py, red)
                    # the split by tool face, in increasing node order over the listed
                    # chunks (the CPU's serial order; the other nodes carry no force)
                    split_reset(red)
                    for i in range(m):
                        for lane in range(LANES):
                            n = clist[i] * LANES + lane
                            if n < nn:
                                split_add(n, x, y, cfx, cfy, cx, cy, prm, red)
                    en[E_EXT] += tstep(tool, prm, sx, sy, dt)
                    if prm[P_COND_EVERY] > 0.0:
                        prm[P_COND_ACC] += dt
            # the tool step writes the new edge centre into prm[P_TCX], prm[P_TCY], which the
            # elements' gated erosion and the ALE pass read (as after k_tool): a barrier
            grid.sync()
            if rz_every > 0 and step % rz_every == 0:
                # the tool-frame ALE pass (rezone.rezone, MODE_TOOLFRAME): the same passes in
                # the same order, a barrier wherever one reads what another wrote
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
                    rflux(e, conn, x, y, xn, yn, alive, enbr, bflag, buf, sdx, sdy, sdz,
                          sdxy, pres, eps_p, temp, dm, qhx, qhy, area0, mat[TROOM])
                for k in range(tid, nsn, nthr):
                    rvel(snodes[k], x, y, xn, yn, vx, vy, ptr, nel, conn, vbuf)
                grid.sync()
                for k in range(tid, nsn, nthr):
                    n = snodes[k]
                    vx[n] += vbuf[n, 0]
                    vy[n] += vbuf[n, 1]
                for e in range(tid, ne, nthr):
                    rwrite(e, alive, buf, sdx, sdy, sdz, sdxy, pres, eps_p, temp, dm, qhx,
                           qhy, area0)
                for n in range(tid, nn, nthr):
                    x[n] = xn[n]
                    y[n] = yn[n]
                grid.sync()
                for n in range(tid, nn, nthr):
                    rmass(n, ptr, nel, area0, rho_s, mass)
                grid.sync()
            for e in range(tid, ne, nthr):
                d, inv = elem(e, conn, x, y, vx, vy, alive, layer, sdx, sdy, sdz, sdxy, pres,
                              eps_p, temp, dm, qhx, qhy, area0, ie, hge, fex, fey, dte, plast,
                              rate, mat, prm, dt, erosion)
                cuda.atomic.min(red, R_DTMIN, d)
                if inv:
                    cuda.atomic.max(red, R_BAD, float(e))
            grid.sync()
            if cond_every > 0 and step % cond_every == 0:
                for e in range(tid, ne, nthr):
                    cent(e, conn, x, y, tbuf)
                grid.sync()
                for e in range(tid, ne, nthr):
                    cond(e, conn, x, y, alive, enbr, temp, tbuf, mat[KCOND],
                         mat[RHO] * mat[CP], prm[P_COND_ACC])
                grid.sync()
                for e in range(tid, ne, nthr):
                    temp[e] = tbuf[e, 3]
                grid.sync()
                if npair > 0:
                    for i in range(tid, npair, nthr):
                        pedge(i, ppair, x, y, alive, tied, temp, tbuf, mat[KCOND],
                              mat[RHO] * mat[CP], prm[P_COND_ACC])
                    grid.sync()
                if theat != 0:
                    for n in range(tid, nn, nthr):
                        thnode(n, conn, x, y, ptr, nel, ncorner, alive, enbr, cfx, cfy, fric,
                               fheat, temp, tbuf, tcq, mat[RHO] * mat[CP], prm[P_HC],
                               prm[P_FHEAT], prm[P_TTOOL], prm[P_COND_ACC])
                    grid.sync()
                    for e in range(tid, ne, nthr):
                        thelem(e, conn, alive, temp, tcq, mat[RHO] * mat[CP])
                    grid.sync()
                if tid == 0:
                    prm[P_COND_ACC] = 0.0
            if tid == 0:
                finish(tool, prm, clock, ist, hacc, hist, en, red, mass, vx, vy, ie, plast, hge,
                       alive, fric, pen, ero_ke, nwork)
                red[R_DTMIN] = 1e30
                red[R_BAD] = -1.0
            grid.sync()

    ale = (k_ale_place, k_ale_face, k_ale_sweep, k_ale_sweep_copy, k_ale_interior, k_ale_flux,
           k_ale_velocity, k_ale_apply, k_ale_write, k_ale_nodes, k_ale_mass)
    return (k_nodes, k_contact_sum, k_tool, k_elems, k_centroids, k_conduct, k_conduct_end,
            k_parting, k_theat_nodes, k_theat_elems, k_conduct_reset, k_finish, k_run, ale)


#: FEState arrays used by the kernels (copied to the device)
_ARRAYS = ("x", "y", "vx", "vy", "mass", "fixed", "ptr", "nel", "ncorner", "conn", "layer",
           "alive", "sdx", "sdy", "sdz", "sdxy", "pres", "eps_p", "temp", "dmg", "qhx", "qhy",
           "area0", "ie", "hge", "fex", "fey", "dte", "plast", "rate", "cfx", "cfy", "fric",
           "pen", "ndead", "ero_ke", "nwork", "mat", "prm", "tool", "en", "ist", "clock",
           "hacc", "hist", "enbr", "twin", "tied", "tbuf", "fheat", "tcq", "ppair", "vslip",
           "snodes", "x0", "y0", "xn", "yn", "buf", "vbuf", "acls", "aflt", "bflag")
#: the arrays the kernels change (copied back to the host)
_MUTABLE = ("x", "y", "vx", "vy", "mass", "alive", "sdx", "sdy", "sdz", "sdxy", "pres",
            "eps_p", "temp", "dmg", "qhx", "qhy", "area0", "ie", "hge", "fex", "fey", "dte",
            "plast", "rate", "cfx", "cfy", "fric", "pen", "ndead", "ero_ke", "nwork", "prm",
            "tool", "en", "ist", "clock", "hacc", "hist", "tied", "tbuf", "fheat", "tcq",
            "vslip", "xn", "yn", "buf", "vbuf", "aflt")


def advance_gpu(st: Any, t_end: float, *, chunk_steps: int = 2000,
                progress: Callable[[float], None] | None = None,
                check: Callable[[Any], None] | None = None,
                profile: dict[str, float] | None = None,
                persistent: bool | None = None) -> int:
    """GPU counterpart of :func:`robobore.cutting.fe.solver.advance` (same contract).

    Copies the :class:`~robobore.cutting.fe.solver.FEState` to the device, runs chunks of
    ``chunk_steps`` steps there, copies the step counter and clock back after each chunk
    (the whole state when ``check`` is given, before calling it) and the whole state at the
    end. Returns the number of steps taken. Raises NumericalError on instability (same
    messages as the CPU engine) and ConfigError when no GPU is usable or the state asks for
    rezoning, the ploughed-layer ALE or the B-bar element. ``profile`` and ``persistent``:
    as in :func:`robobore.cutting.fe.gpu.advance3_gpu` (per-kernel wall times for
    benchmarks; one cooperative launch per chunk, the default without ``profile``).
    """
    every = int(st.prm[K.P_RZ_EVERY]) if st.snodes is not None and st.snodes.shape[0] else 0
    mode = int(st.prm[K.P_RZ_MODE])
    # the tool-frame ALE runs here; Laplacian rezoning and the ploughed-layer ALE do not
    check_gpu_supported(every if mode == MODE_LAPLACE else 0, None,
                        "q4r" if int(st.prm[K.P_ELEM]) == K.ELEM_Q4R else "q4_bbar",
                        every if mode == MODE_ROWS else 0)
    rz_every = every if mode == MODE_TOOLFRAME else 0
    require_gpu()
    (k_nodes, k_contact_sum, k_tool, k_elems, k_centroids, k_conduct, k_conduct_end,
     k_parting, k_theat_nodes, k_theat_elems, k_conduct_reset, k_finish, k_run,
     ale) = _kernels()
    (k_ale_place, k_ale_face, k_ale_sweep, k_ale_sweep_copy, k_ale_interior, k_ale_flux,
     k_ale_velocity, k_ale_apply, k_ale_write, k_ale_nodes, k_ale_mass) = ale
    st.prm[K.P_TEND] = t_end
    st.ist[K.I_STATUS] = K.STATUS_OK
    g = {name: cuda.to_device(np.ascontiguousarray(getattr(st, name))) for name in _ARRAYS}
    red = np.zeros(N_RED)
    red[R_DTMIN] = 1e30
    red[R_BAD] = -1.0
    dred = cuda.to_device(red)
    nn = st.x.shape[0]
    ne = st.conn.shape[0]
    gn = (nn + _THREADS - 1) // _THREADS
    ge = (ne + _THREADS - 1) // _THREADS
    erosion = int(st.prm[K.P_EROSION])
    cond_every = int(st.prm[K.P_COND_EVERY])
    npair = int(st.ppair.shape[0])
    gp = max(1, (npair + _THREADS - 1) // _THREADS)
    nsn = int(st.snodes.shape[0])
    gs = max(1, (nsn + _THREADS - 1) // _THREADS)
    theat = st.prm[K.P_HC] > 0.0 or st.prm[K.P_FHEAT] > 0.0
    t_start = st.time
    step0 = int(st.ist[K.I_STEP])
    tick = profile_ticker(profile)
    run = persistent_run(k_run, [g[name] for name in _ARRAYS]
                         + [erosion, cond_every, int(theat), rz_every, dred], nn, profile,
                         persistent)
    while True:
        if run is not None:
            run(chunk_steps)
        # while the status is OK every launch sequence is exactly one step, so the host
        # knows the step index (conduction runs where ist[I_STEP] % cond_every == 0, as on
        # the CPU); once the status changes the remaining launches return at once
        step = int(st.ist[K.I_STEP])
        for i in range(0 if run is not None else chunk_steps):
            tick(None)
            k_nodes[gn, _THREADS](g["x"], g["y"], g["vx"], g["vy"], g["mass"], g["fixed"],
                                  g["ptr"], g["nel"], g["ncorner"], g["alive"], g["area0"],
                                  g["fex"], g["fey"], g["cfx"], g["cfy"], g["fric"], g["pen"],
                                  g["ndead"], g["ero_ke"], g["nwork"], g["prm"], g["tool"],
                                  g["clock"], g["ist"], g["twin"], g["tied"], g["vslip"],
                                  dred)
            tick("nodes")
            k_contact_sum[1, K.N_SUM_LANES](g["cfx"], g["cfy"], g["x"], g["y"], g["tool"],
                                            g["prm"], dred)
            tick("contact_sum")
            k_tool[1, 1](g["tool"], g["prm"], g["en"], g["clock"], g["ist"], dred)
            tick("tool")
            if rz_every > 0 and (step + i) % rz_every == 0:
                _ale_launches(g, ale, gn, ge, gs)
                tick("ale")
            k_elems[ge, _THREADS](g["conn"], g["x"], g["y"], g["vx"], g["vy"], g["alive"],
                                  g["layer"], g["sdx"], g["sdy"], g["sdz"], g["sdxy"],
                                  g["pres"], g["eps_p"], g["temp"], g["dmg"], g["qhx"],
                                  g["qhy"], g["area0"], g["ie"], g["hge"], g["fex"], g["fey"],
                                  g["dte"], g["plast"], g["rate"], g["mat"], g["prm"],
                                  g["clock"], erosion, g["ist"], dred)
            tick("elements")
            if cond_every > 0 and (step + i) % cond_every == 0:
                k_centroids[ge, _THREADS](g["conn"], g["x"], g["y"], g["tbuf"], g["ist"])
                k_conduct[ge, _THREADS](g["conn"], g["x"], g["y"], g["alive"], g["enbr"],
                                        g["temp"], g["tbuf"], g["mat"], g["prm"], g["ist"])
                k_conduct_end[ge, _THREADS](g["temp"], g["tbuf"], g["prm"], g["ist"])
                if npair > 0:
                    k_parting[gp, _THREADS](g["ppair"], g["x"], g["y"], g["alive"], g["tied"],
                                            g["temp"], g["tbuf"], g["mat"], g["prm"],
                                            g["ist"])
                if theat:
                    k_theat_nodes[gn, _THREADS](g["conn"], g["x"], g["y"], g["ptr"],
                                                g["nel"], g["ncorner"], g["alive"], g["enbr"],
                                                g["cfx"], g["cfy"], g["fric"], g["fheat"],
                                                g["temp"], g["tbuf"], g["tcq"], g["mat"],
                                                g["prm"], g["ist"])
                    k_theat_elems[ge, _THREADS](g["conn"], g["alive"], g["temp"], g["tcq"],
                                                g["mat"], g["ist"])
                k_conduct_reset[1, 1](g["prm"], g["ist"])
                tick("conduction")
            k_finish[1, 1](g["tool"], g["prm"], g["clock"], g["ist"], g["hacc"], g["hist"],
                           g["en"], dred, g["mass"], g["vx"], g["vy"], g["ie"], g["plast"],
                           g["hge"], g["alive"], g["fric"], g["pen"], g["ero_ke"],
                           g["nwork"])
            tick("finish")
        for name in ("ist", "clock"):
            getattr(st, name)[...] = g[name].copy_to_host()
        status = int(st.ist[K.I_STATUS])
        if status in STATUS_TEXT or status == K.STATUS_DONE or check is not None:
            _copy_back(st, g)
        if status in STATUS_TEXT:
            raise instability_error(st, "simulation (GPU)", "a smaller solver.cfl, a larger "
                                    "mesh.element_size_um or less mass scaling")
        if progress is not None:
            progress(min(1.0, (st.time - t_start) / max(t_end - t_start, 1e-300)))
        if check is not None:
            check(st)
        if status == K.STATUS_DONE or st.time >= t_end:
            _copy_back(st, g)
            return int(st.ist[K.I_STEP]) - step0


def _ale_launches(g: dict, ale: tuple, gn: int, ge: int, gs: int) -> None:
    """One tool-frame ALE pass as one launch per phase (the persistent kernel's phases)."""
    (k_ale_place, k_ale_face, k_ale_sweep, k_ale_sweep_copy, k_ale_interior, k_ale_flux,
     k_ale_velocity, k_ale_apply, k_ale_write, k_ale_nodes, k_ale_mass) = ale
    T = _THREADS
    k_ale_place[gn, T](g["x"], g["y"], g["xn"], g["yn"], g["x0"], g["y0"], g["acls"],
                       g["aflt"], g["prm"], g["ist"])
    k_ale_face[gn, T](g["xn"], g["yn"], g["x0"], g["y0"], g["acls"], g["aflt"], g["prm"],
                      g["ist"])
    for _ in range(RZ.TF_SWEEPS):
        k_ale_sweep[gn, T](g["acls"], g["aflt"], g["vbuf"], g["ist"])
        k_ale_sweep_copy[gn, T](g["acls"], g["aflt"], g["vbuf"], g["ist"])
    k_ale_interior[gn, T](g["x"], g["y"], g["xn"], g["yn"], g["x0"], g["y0"], g["acls"],
                          g["aflt"], g["prm"], g["ist"])
    k_ale_flux[ge, T](g["conn"], g["x"], g["y"], g["xn"], g["yn"], g["alive"], g["enbr"],
                      g["bflag"], g["buf"], g["sdx"], g["sdy"], g["sdz"], g["sdxy"], g["pres"],
                      g["eps_p"], g["temp"], g["dmg"], g["qhx"], g["qhy"], g["area0"],
                      g["mat"], g["ist"])
    k_ale_velocity[gs, T](g["snodes"], g["x"], g["y"], g["xn"], g["yn"], g["vx"], g["vy"],
                          g["ptr"], g["nel"], g["conn"], g["vbuf"], g["ist"])
    k_ale_apply[gs, T](g["snodes"], g["vx"], g["vy"], g["vbuf"], g["ist"])
    k_ale_write[ge, T](g["alive"], g["buf"], g["sdx"], g["sdy"], g["sdz"], g["sdxy"],
                       g["pres"], g["eps_p"], g["temp"], g["dmg"], g["qhx"], g["qhy"],
                       g["area0"], g["ist"])
    k_ale_nodes[gn, T](g["x"], g["y"], g["xn"], g["yn"], g["ist"])
    k_ale_mass[gn, T](g["ptr"], g["nel"], g["area0"], g["mass"], g["mat"], g["prm"],
                      g["ist"])


def _copy_back(st: Any, g: dict) -> None:
    for name in _MUTABLE:
        getattr(st, name)[...] = g[name].copy_to_host()
