"""GPU backend of the 3D explicit engine (numba-cuda), built from the SAME scalar physics.

The per-element and per-node updates are the plain-Python scalar functions of the CPU engine
(:func:`hex8.hex_element_py`, :func:`kernels3d.hex_node_py`, :func:`kernels3d.tool_step_py`)
and the shared material/contact/support functions (:mod:`robobore.material.johnson_cook`,
:mod:`robobore.cutting.fe.physics`), re-bound to device versions with
:func:`robobore.material.johnson_cook.rebind` and compiled with
``numba.cuda.jit(device=True)``. One time step is five kernel launches: nodes, the contact-
force total (one block, in the CPU's fixed lane order, so a run is reproducible bit for
bit), the tool (one thread), elements (stable step by atomic min), and the step end (one
thread: time, status, time-averaged histories); every ``solver.conduction_interval`` steps
the heat conduction of :mod:`robobore.cutting.fe.thermal3d` adds five more (centroids, new
temperatures, their copy, the insert's heat per node, then per element). The loop stays on
the device; the host only checks the status between chunks.

Optional: needs an NVIDIA GPU and numba's CUDA target (``pip install robobore[gpu]``, i.e.
``numba-cuda``). Importing this module never needs either; :func:`require_gpu` raises a
clear :class:`robobore.errors.ConfigError` when no GPU is usable. Correctness is tested on
the CPU with numba's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1``) against the CPU engine.

Limits: per-sample energy histories are not recorded on the GPU (the final energy totals
are computed on the host from the copied-back state). The 2D engine's GPU port, built the
same way from its scalar functions, is :mod:`robobore.cutting.fe.gpu2d`.
"""

from __future__ import annotations

import functools
import math  # noqa: F401  (math.isfinite inside the kernels)
import os
from collections.abc import Callable

import numpy as np

from robobore.errors import ConfigError

__all__ = ["cuda_available", "require_gpu", "advance3_gpu", "simulator_enabled",
           # shared with the 2D GPU engine (robobore.cutting.fe.gpu2d)
           "MAX_BLOCK", "bind_cuda", "chunk_list_py", "jc_device_functions", "persistent_run",
           "profile_ticker"]

_THREADS = 128
#: largest block size of the persistent kernels, 2D and 3D (their shared compaction counters)
MAX_BLOCK = 1024
# reduction slots on the device
R_DTMIN, R_BAD, R_FX, R_FY, R_FZ, R_NC = 0, 1, 2, 3, 4, 5
N_RED = 6


def simulator_enabled() -> bool:
    """True when numba's CUDA simulator is switched on (NUMBA_ENABLE_CUDASIM=1)."""
    return os.environ.get("NUMBA_ENABLE_CUDASIM", "0") == "1"


def cuda_available() -> bool:
    """True when a CUDA device (or the simulator) can run the kernels."""
    try:
        from numba import cuda
    except Exception:  # pragma: no cover - numba without a CUDA target
        return False
    try:
        return bool(cuda.is_available())
    except Exception:  # pragma: no cover
        return False


def require_gpu() -> None:
    """Raise a clear ConfigError unless a CUDA GPU (or the simulator) is usable."""
    if not cuda_available():
        raise ConfigError(
            "no usable NVIDIA GPU: numba could not find a CUDA device or driver",
            field="--device", value="gpu",
            expected="an NVIDIA GPU with its driver and numba-cuda installed "
                     "(pip install 'robobore[gpu]'), or --device cpu")


#: the numba.cuda module, bound on first use (a module global, so that numba's simulator can
#: substitute its own inside the kernels)
cuda = None


def jc_device_functions(dev):
    """Device versions ``(damage increment, return mapping)`` of the Johnson-Cook functions
    (shared by the 2D and 3D GPU engines); ``dev`` = ``numba.cuda.jit(device=True)``."""
    from robobore.material import johnson_cook as jc

    th = dev(jc.homologous_temperature_py)
    athermal = dev(jc.jc_athermal_py)
    fail = dev(jc.rebind(jc.jc_failure_strain_py, homologous_temperature=th))
    dmg = dev(jc.rebind(jc.jc_damage_increment_py, jc_failure_strain=fail))
    ret = dev(jc.rebind(jc.jc_return_py, jc_athermal=athermal, homologous_temperature=th))
    return dmg, ret


def bind_cuda():
    """Bind (once) and return the ``numba.cuda`` module as this module's global ``cuda``,
    which the kernels and :func:`chunk_list_py` name."""
    global cuda
    from numba import cuda as _cuda

    cuda = _cuda
    return _cuda


def chunk_list_py(cflag, clist, cnt, t, nb):
    """Block-level step of the persistent kernels (every thread ``t`` of a block of ``nb``
    calls it): list the chunks whose flag is set in ``cflag`` into ``clist`` in increasing
    index order, clear those flags, and return how many there are. ``cnt`` is a shared int
    array of ``nb + 1`` (a prefix sum of the per-thread counts over contiguous ranges)."""
    nchunk = cflag.shape[0]
    q = (nchunk + nb - 1) // nb
    c0 = min(t * q, nchunk)
    c1 = min(c0 + q, nchunk)
    k = 0
    for c in range(c0, c1):
        if cflag[c] != 0:
            k += 1
    cnt[t] = k
    cuda.syncthreads()
    if t == 0:
        acc = 0
        for j in range(nb):
            v = cnt[j]
            cnt[j] = acc
            acc += v
        cnt[nb] = acc
    cuda.syncthreads()
    k = cnt[t]
    for c in range(c0, c1):
        if cflag[c] != 0:
            clist[k] = c
            k += 1
            cflag[c] = 0
    cuda.syncthreads()
    return cnt[nb]


@functools.lru_cache(maxsize=1)
def _kernels():
    """Compile (lazily, once) the device functions and kernels."""
    bind_cuda()
    from numba import float64 as _float64
    from numba import int64 as _int64

    from robobore.cutting.fe import kernels3d as K3
    from robobore.cutting.fe import thermal3d as T3
    from robobore.cutting.fe.hex8 import hex_element_py
    from robobore.cutting.fe.physics import tool_face_py, tool_gap_py, tool_support_step_py
    from robobore.material import johnson_cook as jc

    dev = cuda.jit(device=True)
    dmg, ret = jc_device_functions(dev)
    elem = dev(jc.rebind(hex_element_py, jc_return=ret, jc_damage_increment=dmg))
    tg = dev(jc.rebind(tool_gap_py, tool_face=dev(tool_face_py)))
    sec = dev(K3.edge_section_py)
    gap3 = dev(jc.rebind(K3.insert_gap3_py, tool_gap=tg, edge_section=sec))
    cf3 = dev(K3.contact_force3_py)
    fat3 = dev(K3.friction_at3_py)
    node = dev(jc.rebind(K3.hex_node_py, insert_gap3=gap3, contact_force3=cf3,
                         friction_at3=fat3))
    sup = dev(tool_support_step_py)
    kin = dev(K3.tool_kinematics_py)
    tstep = dev(jc.rebind(K3.tool_step_py, tool_kinematics=kin, tool_support_step=sup))
    lsum3 = dev(K3.lane_sum3_py)
    th = {}
    for name, func, deps in T3.DEVICE_FUNCTIONS:
        th[name] = dev(jc.rebind(func, **{d: th[d] for d in deps}))
    centroid3, conduct3 = th["hex_centroid3"], th["hex_conduct3"]
    heat_node3, heat_elem3 = th["tool_heat_node3"], th["tool_heat_elem3"]
    is_cond = dev(K3.is_conduction_step_py)
    RHO, CP, KCOND = jc.RHO, jc.CP, jc.KCOND
    P_COND_T, P_HC, P_FHEAT, P_TTOOL = K3.P_COND_T, K3.P_HC, K3.P_FHEAT, K3.P_TTOOL
    chunks = dev(chunk_list_py)
    LANES = K3.N_SUM_LANES
    float64 = _float64
    int64 = _int64
    NCNT = MAX_BLOCK + 1

    I_STATUS, I_STEP, I_SAMPLE, I_BADELEM = K3.I_STATUS, K3.I_STEP, K3.I_SAMPLE, K3.I_BADELEM
    ST_OK, ST_DONE, ST_INV = K3.STATUS_OK, K3.STATUS_DONE, K3.STATUS_INVERTED
    ST_NOEL, ST_NONF, ST_DTC = K3.STATUS_NO_ELEMENTS, K3.STATUS_NONFINITE, K3.STATUS_DT_COLLAPSE
    P_CFL, P_DTMIN, P_TEND, P_SAMPLE_DT = K3.P_CFL, K3.P_DTMIN, K3.P_TEND, K3.P_SAMPLE_DT
    T_FX, T_FY, T_FZ, T_UX, T_UY, T_UZ = K3.T_FX, K3.T_FY, K3.T_FZ, K3.T_UX, K3.T_UY, K3.T_UZ
    T_GX, T_THETA, E_EXT = K3.T_GX, K3.T_THETA, K3.E_EXT
    H_T, H_FX, H_FY, H_FZ, H_UX, H_UY, H_UZ = (K3.H_T, K3.H_FX, K3.H_FY, K3.H_FZ, K3.H_UX,
                                               K3.H_UY, K3.H_UZ)
    H_NCONT, H_TIPX, H_THETA, H_EEXT = K3.H_NCONT, K3.H_TIPX, K3.H_THETA, K3.H_EEXT

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

    @cuda.jit
    def k_nodes(x, y, z, vx, vy, vz, mass, fixed, ptr, nel, ncorner, alive, vol0, fe, cf, fric,
                pen, ndead, ero_ke, nwork, prm, tool, clock, ist, red, pairs):
        n = cuda.grid(1)
        if n >= x.shape[0] or ist[I_STATUS] != ST_OK:
            return
        cx, cy, cz, tvx, tvy, tvz = kin(tool, prm)
        node(n, x, y, z, vx, vy, vz, mass, fixed, ptr, nel, ncorner, alive, vol0, fe, cf, fric,
             pen, ndead, ero_ke, nwork, prm, cx, cy, cz, tvx, tvy, tvz, clock[1], pairs)

    @cuda.jit
    def k_contact_sum(cf, red):
        # the CPU's fixed-order total (kernels3d.contact_total3): one thread per lane, then
        # the lanes in order by thread 0 -- reproducible bit for bit
        t = cuda.threadIdx.x
        px = cuda.shared.array(LANES, float64)
        py = cuda.shared.array(LANES, float64)
        pz = cuda.shared.array(LANES, float64)
        pn = cuda.shared.array(LANES, float64)
        a, b, c, k = lsum3(cf, t, LANES)
        px[t] = a
        py[t] = b
        pz[t] = c
        pn[t] = k
        cuda.syncthreads()
        if t == 0:
            lanes_total(px, py, pz, pn, red)

    @cuda.jit
    def k_tool(tool, prm, en, clock, ist, red):
        if cuda.grid(1) != 0 or ist[I_STATUS] != ST_OK:
            return
        en[E_EXT] += tstep(tool, prm, red[R_FX], red[R_FY], red[R_FZ], clock[1])
        red[R_DTMIN] = 1e30
        red[R_BAD] = -1.0

    @cuda.jit
    def k_elems(conn, x, y, z, vx, vy, vz, alive, layer, sd, pres, eps_p, temp, dm, qh, vol0,
                ie, hge, fe, dte, plast, rate, mat, prm, clock, erosion, ist, red):
        e = cuda.grid(1)
        if e >= conn.shape[0] or ist[I_STATUS] != ST_OK:
            return
        elem(e, conn, x, y, z, vx, vy, vz, alive, layer, sd, pres, eps_p, temp, dm, qh, vol0,
             ie, hge, fe, dte, plast, rate, mat, prm, clock[1], erosion)
        cuda.atomic.min(red, R_DTMIN, dte[e])
        if alive[e] == -2:
            red[R_BAD] = e

    @cuda.jit
    def k_centroids(conn, x, y, z, tbuf, ist):
        e = cuda.grid(1)
        if e >= conn.shape[0] or ist[I_STATUS] != ST_OK:
            return
        centroid3(e, conn, x, y, z, tbuf)

    @cuda.jit
    def k_conduct(conn, x, y, z, alive, enbr, pairs, vol0, temp, tbuf, mat, prm, clock, ist):
        e = cuda.grid(1)
        if e >= conn.shape[0] or ist[I_STATUS] != ST_OK:
            return
        dt_th = clock[0] + clock[1] - prm[P_COND_T]
        conduct3(e, conn, x, y, z, alive, enbr, pairs, vol0, temp, tbuf, mat[KCOND],
                 mat[RHO] * mat[CP], dt_th)

    @cuda.jit
    def k_copy_temp(temp, tbuf, ist):
        e = cuda.grid(1)
        if e >= temp.shape[0] or ist[I_STATUS] != ST_OK:
            return
        temp[e] = tbuf[e, 3]

    @cuda.jit
    def k_heat_nodes(conn, x, y, z, ptr, nel, ncorner, alive, enbr, pairs, vol0, cf, fric,
                     temp, theat, mat, prm, clock, ist):
        n = cuda.grid(1)
        if n >= x.shape[0] or ist[I_STATUS] != ST_OK:
            return
        dt_th = clock[0] + clock[1] - prm[P_COND_T]
        heat_node3(n, conn, x, y, z, ptr, nel, ncorner, alive, enbr, pairs, vol0, cf, fric,
                   temp, theat, mat[RHO] * mat[CP], prm[P_HC], prm[P_FHEAT], prm[P_TTOOL],
                   dt_th)

    @cuda.jit
    def k_heat_elems(conn, alive, temp, theat, mat, ist):
        e = cuda.grid(1)
        if e >= conn.shape[0] or ist[I_STATUS] != ST_OK:
            return
        heat_elem3(e, conn, alive, temp, theat, mat[RHO] * mat[CP])

    @cuda.jit
    def k_cond_done(prm, clock, ist):
        if cuda.grid(1) != 0 or ist[I_STATUS] != ST_OK:
            return
        prm[P_COND_T] = clock[0] + clock[1]

    @cuda.jit(device=True)
    def finish(tool, prm, clock, ist, hacc, hist, en, red):
        # the step end (one thread): time, stable step, status, time-averaged histories
        dt = clock[1]
        t = clock[0] + dt
        clock[0] = t
        ist[I_STEP] += 1
        fwx = red[R_FX]
        fwy = red[R_FY]
        fwz = red[R_FZ]
        nc = red[R_NC]
        if red[R_BAD] >= 0.0:
            ist[I_BADELEM] = int(red[R_BAD])
            ist[I_STATUS] = ST_INV
            return
        if red[R_DTMIN] >= 1e30:
            ist[I_STATUS] = ST_NOEL
            return
        new_dt = prm[P_CFL] * red[R_DTMIN]
        if not (math.isfinite(fwx) and math.isfinite(fwy) and math.isfinite(fwz)
                and math.isfinite(new_dt)):
            ist[I_STATUS] = ST_NONF
            return
        clock[1] = new_dt
        if new_dt < prm[P_DTMIN]:
            ist[I_STATUS] = ST_DTC
            return
        hacc[H_FX] += dt * tool[T_FX]
        hacc[H_FY] += dt * tool[T_FY]
        hacc[H_FZ] += dt * tool[T_FZ]
        hacc[H_UX] += dt * tool[T_UX]
        hacc[H_UY] += dt * tool[T_UY]
        hacc[H_UZ] += dt * tool[T_UZ]
        hacc[H_NCONT] += dt * nc
        clock[2] += dt
        k = ist[I_SAMPLE]
        if t >= (k + 1) * prm[P_SAMPLE_DT] and k < hist.shape[0]:
            ta = clock[2]
            hist[k, H_T] = t
            hist[k, H_FX] = hacc[H_FX] / ta
            hist[k, H_FY] = hacc[H_FY] / ta
            hist[k, H_FZ] = hacc[H_FZ] / ta
            hist[k, H_UX] = hacc[H_UX] / ta
            hist[k, H_UY] = hacc[H_UY] / ta
            hist[k, H_UZ] = hacc[H_UZ] / ta
            hist[k, H_NCONT] = hacc[H_NCONT] / ta
            hist[k, H_TIPX] = tool[T_GX]
            hist[k, H_THETA] = tool[T_THETA]
            hist[k, H_EEXT] = en[E_EXT]
            for j in range(hacc.shape[0]):
                hacc[j] = 0.0
            clock[2] = 0.0
            ist[I_SAMPLE] = k + 1
        if t >= prm[P_TEND]:
            ist[I_STATUS] = ST_DONE

    @cuda.jit
    def k_finish(tool, prm, clock, ist, hacc, hist, en, red):
        if cuda.grid(1) != 0 or ist[I_STATUS] != ST_OK:
            return
        finish(tool, prm, clock, ist, hacc, hist, en, red)

    @cuda.jit
    def k_run(n_steps, x, y, z, vx, vy, vz, mass, fixed, ptr, nel, ncorner, conn, alive, layer,
              sd, pres, eps_p, temp, dm, qh, vol0, ie, hge, fe, dte, plast, rate, cf, fric, pen,
              ndead, ero_ke, nwork, mat, prm, tool, en, ist, clock, hacc, hist, pairs, enbr,
              tbuf, theat, erosion, red, cflag, clist):
        # ``n_steps`` whole steps in one cooperative launch (a persistent kernel): the phases
        # of the five kernels above separated by grid-wide barriers, so the host launches
        # once per chunk instead of five times per step. Same functions, same order, same
        # bits as the five launches.
        grid = cuda.cg.this_grid()
        tid = cuda.grid(1)
        nthr = cuda.gridsize(1)
        t = cuda.threadIdx.x
        nb = cuda.blockDim.x
        nn = x.shape[0]
        ne = conn.shape[0]
        px = cuda.shared.array(LANES, float64)
        py = cuda.shared.array(LANES, float64)
        pz = cuda.shared.array(LANES, float64)
        pn = cuda.shared.array(LANES, float64)
        cnt = cuda.shared.array(NCNT, int64)
        for _ in range(n_steps):
            if ist[I_STATUS] != ST_OK:
                return
            dt = clock[1]
            # the step number, read before the step's first barrier (thread 0 moves it on
            # after its last): every thread takes the same conduction branch below
            step = ist[I_STEP]
            cx, cy, cz, tvx, tvy, tvz = kin(tool, prm)
            for n in range(tid, nn, nthr):
                node(n, x, y, z, vx, vy, vz, mass, fixed, ptr, nel, ncorner, alive, vol0, fe,
                     cf, fric, pen, ndead, ero_ke, nwork, prm, cx, cy, cz, tvx, tvy, tvz, dt,
                     pairs)
                if cf[n, 0] != 0.0 or cf[n, 1] != 0.0 or cf[n, 2] != 0.0:
                    cflag[n // LANES] = 1  # the chunk of LANES nodes holding n has contact
            grid.sync()
            if cuda.blockIdx.x == 0:
                # block 0: the contact-force total in the CPU's lane order, visiting only
                # the chunks that hold a contact node (the others add nothing), then the tool
                m = chunks(cflag, clist, cnt, t, nb)
                for lane in range(t, LANES, nb):
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
                    px[lane] = sx
                    py[lane] = sy
                    pz[lane] = sz
                    pn[lane] = sc
                cuda.syncthreads()
                if t == 0:
                    sx, sy, sz = lanes_total(px, py, pz, pn, red)
                    en[E_EXT] += tstep(tool, prm, sx, sy, sz, dt)
            # elements (they do not read the tool or the contact forces: no barrier needed
            # after block 0's work above)
            for e in range(tid, ne, nthr):
                elem(e, conn, x, y, z, vx, vy, vz, alive, layer, sd, pres, eps_p, temp, dm, qh,
                     vol0, ie, hge, fe, dte, plast, rate, mat, prm, dt, erosion)
                cuda.atomic.min(red, R_DTMIN, dte[e])
                if alive[e] == -2:
                    red[R_BAD] = e
            grid.sync()
            if is_cond(step, prm):
                # conduction (thermal3d, the CPU's conduction_pass3): the phases of the five
                # launches of the launch path, separated by barriers
                dt_th = clock[0] + dt - prm[P_COND_T]
                rcp = mat[RHO] * mat[CP]
                for e in range(tid, ne, nthr):
                    centroid3(e, conn, x, y, z, tbuf)
                grid.sync()
                for e in range(tid, ne, nthr):
                    conduct3(e, conn, x, y, z, alive, enbr, pairs, vol0, temp, tbuf,
                             mat[KCOND], rcp, dt_th)
                grid.sync()
                for e in range(tid, ne, nthr):
                    temp[e] = tbuf[e, 3]
                grid.sync()
                if prm[P_HC] > 0.0 or prm[P_FHEAT] > 0.0:
                    for n in range(tid, nn, nthr):
                        heat_node3(n, conn, x, y, z, ptr, nel, ncorner, alive, enbr, pairs,
                                   vol0, cf, fric, temp, theat, rcp, prm[P_HC], prm[P_FHEAT],
                                   prm[P_TTOOL], dt_th)
                    grid.sync()
                    for e in range(tid, ne, nthr):
                        heat_elem3(e, conn, alive, temp, theat, rcp)
                    grid.sync()
                if tid == 0:
                    prm[P_COND_T] = clock[0] + dt
            if tid == 0:
                finish(tool, prm, clock, ist, hacc, hist, en, red)
                red[R_DTMIN] = 1e30
                red[R_BAD] = -1.0
            grid.sync()

    # the persistent kernel last (benchmarks/gpu_compile_check.py compiles it)
    return (k_nodes, k_contact_sum, k_tool, k_elems, k_finish,
            (k_centroids, k_conduct, k_copy_temp, k_heat_nodes, k_heat_elems, k_cond_done), k_run)


#: arrays of FEState3 that the kernels change (copied back to the host)
_MUTABLE = ("x", "y", "z", "vx", "vy", "vz", "alive", "sd", "pres", "eps_p", "temp", "dmg",
            "qh", "ie", "hge", "fe", "dte", "plast", "rate", "cf", "fric", "pen", "ndead",
            "ero_ke", "nwork", "tool", "en", "ist", "clock", "hacc", "hist", "pairs", "prm",
            "tbuf", "theat")


def advance3_gpu(st, t_end: float, *, chunk_steps: int = 500,
                 progress: Callable[[float], None] | None = None,
                 check: Callable[[object], None] | None = None,
                 profile: dict[str, float] | None = None,
                 persistent: bool | None = None) -> int:
    """GPU counterpart of :func:`robobore.cutting.fe.solver3d.advance3` (same contract).

    Copies the state to the device, runs chunks of ``chunk_steps`` steps, copies the state
    back after each chunk (for ``check``/``progress``) and at the end, and computes the
    energy totals on the host. Raises NumericalError on instability, ConfigError when no
    GPU is usable. ``profile`` (a dict, for benchmarks): synchronize after every launch and
    add each kernel's wall time [s] under its name (slows the run down; five launches a
    step). ``persistent``: run each chunk as one cooperative launch of the persistent
    kernel (``None``, the default: when the device supports cooperative launches and no
    ``profile`` is asked for; the same bits as the five launches a step, without their
    host-side launch cost).
    """
    from robobore.cutting.fe import kernels3d as K3
    from robobore.cutting.fe.status import STATUS_TEXT, instability_error

    require_gpu()
    k_nodes, k_contact_sum, k_tool, k_elems, k_finish, k_thermal, k_run = _kernels()
    k_centroids, k_conduct, k_copy_temp, k_heat_nodes, k_heat_elems, k_cond_done = k_thermal
    st.prm[K3.P_TEND] = t_end
    st.ist[K3.I_STATUS] = K3.STATUS_OK
    g = {name: cuda.to_device(np.ascontiguousarray(getattr(st, name))) for name in _RUN_ARGS}
    red = np.zeros(N_RED)
    red[R_DTMIN] = 1e30
    red[R_BAD] = -1.0
    dred = cuda.to_device(red)
    nn = st.x.shape[0]
    ne = st.conn.shape[0]
    gn = (nn + _THREADS - 1) // _THREADS
    ge = (ne + _THREADS - 1) // _THREADS
    erosion = int(st.prm[K3.P_EROSION])
    t_start = st.time
    step0 = int(st.ist[K3.I_STEP])
    tick = profile_ticker(profile)
    run = persistent_run(k_run, [g[name] for name in _RUN_ARGS] + [erosion, dred], nn,
                         profile, persistent)
    heat = st.prm[K3.P_HC] > 0.0 or st.prm[K3.P_FHEAT] > 0.0
    while True:
        if run is not None:
            run(chunk_steps)
        step = int(st.ist[K3.I_STEP])  # the launch path: the host counts the steps
        for _ in range(0 if run is not None else chunk_steps):
            tick(None)
            k_nodes[gn, _THREADS](g["x"], g["y"], g["z"], g["vx"], g["vy"], g["vz"], g["mass"],
                                  g["fixed"], g["ptr"], g["nel"], g["ncorner"], g["alive"],
                                  g["vol0"], g["fe"], g["cf"], g["fric"], g["pen"], g["ndead"],
                                  g["ero_ke"], g["nwork"], g["prm"], g["tool"], g["clock"],
                                  g["ist"], dred, g["pairs"])
            tick("nodes")
            k_contact_sum[1, K3.N_SUM_LANES](g["cf"], dred)
            tick("contact_sum")
            k_tool[1, 1](g["tool"], g["prm"], g["en"], g["clock"], g["ist"], dred)
            tick("tool")
            k_elems[ge, _THREADS](g["conn"], g["x"], g["y"], g["z"], g["vx"], g["vy"], g["vz"],
                                  g["alive"], g["layer"], g["sd"], g["pres"], g["eps_p"],
                                  g["temp"], g["dmg"], g["qh"], g["vol0"], g["ie"], g["hge"],
                                  g["fe"], g["dte"], g["plast"], g["rate"], g["mat"], g["prm"],
                                  g["clock"], erosion, g["ist"], dred)
            tick("elements")
            if K3.is_conduction_step_py(step, st.prm):
                k_centroids[ge, _THREADS](g["conn"], g["x"], g["y"], g["z"], g["tbuf"], g["ist"])
                k_conduct[ge, _THREADS](g["conn"], g["x"], g["y"], g["z"], g["alive"], g["enbr"],
                                        g["pairs"], g["vol0"], g["temp"], g["tbuf"], g["mat"],
                                        g["prm"], g["clock"], g["ist"])
                k_copy_temp[ge, _THREADS](g["temp"], g["tbuf"], g["ist"])
                if heat:
                    k_heat_nodes[gn, _THREADS](g["conn"], g["x"], g["y"], g["z"], g["ptr"],
                                               g["nel"], g["ncorner"], g["alive"], g["enbr"],
                                               g["pairs"], g["vol0"], g["cf"], g["fric"],
                                               g["temp"], g["theat"], g["mat"], g["prm"],
                                               g["clock"], g["ist"])
                    k_heat_elems[ge, _THREADS](g["conn"], g["alive"], g["temp"], g["theat"],
                                               g["mat"], g["ist"])
                k_cond_done[1, 1](g["prm"], g["clock"], g["ist"])
                tick("conduction")
            step += 1
            k_finish[1, 1](g["tool"], g["prm"], g["clock"], g["ist"], g["hacc"], g["hist"],
                           g["en"], dred)
            tick("finish")
        for name in ("ist", "clock"):
            getattr(st, name)[...] = g[name].copy_to_host()
        status = int(st.ist[K3.I_STATUS])
        if status in STATUS_TEXT or status == K3.STATUS_DONE or check is not None:
            _copy_back(st, g)
        if status in STATUS_TEXT:
            raise instability_error(st, "3D simulation (GPU)", "a smaller solver.cfl, a larger "
                                    "mesh.element_size_um or less mass scaling")
        if progress is not None:
            progress(min(1.0, (st.time - t_start) / max(t_end - t_start, 1e-300)))
        if check is not None:
            check(st)
        if status == K3.STATUS_DONE or st.time >= t_end:
            _copy_back(st, g)
            return int(st.ist[K3.I_STEP]) - step0


#: the state arrays on the device, in the persistent kernel's argument order (then erosion,
#: red, the chunk flags and the chunk list)
_RUN_ARGS = ("x", "y", "z", "vx", "vy", "vz", "mass", "fixed", "ptr", "nel", "ncorner", "conn",
             "alive", "layer", "sd", "pres", "eps_p", "temp", "dmg", "qh", "vol0", "ie", "hge",
             "fe", "dte", "plast", "rate", "cf", "fric", "pen", "ndead", "ero_ke", "nwork",
             "mat", "prm", "tool", "en", "ist", "clock", "hacc", "hist", "pairs", "enbr", "tbuf",
             "theat")


def persistent_run(kernel, args: list, n_nodes: int, profile, persistent: bool | None):
    """``run(n_steps)`` of a persistent kernel (2D or 3D engine) whose arguments are
    ``n_steps``, ``args``, the chunk flags and the chunk list (allocated here for ``n_nodes``
    nodes); ``None`` where the caller launches one kernel per phase (``persistent`` False, or
    None with a ``profile``, or a cooperative launch that cannot be set up -- then with a
    warning)."""
    from robobore.cutting.fe.kernels import N_SUM_LANES

    auto = persistent is None
    if not (profile is None if auto else persistent):
        return None
    nchunk = (n_nodes + N_SUM_LANES - 1) // N_SUM_LANES
    args = list(args) + [cuda.to_device(np.zeros(nchunk, np.int32)),
                         cuda.to_device(np.zeros(nchunk, np.int64))]
    launch = _cooperative(kernel, [1] + args, _THREADS, fallback=auto)
    if launch is None:
        return None
    return lambda n_steps: launch(n_steps, *args)


def _cooperative(kernel, args: list, threads: int, fallback: bool = False):
    """``launch(*args)`` of a grid-synchronising kernel with as many blocks of ``threads``
    as the device keeps resident at once (a cooperative launch needs them all resident);
    one block in numba's simulator (the only cooperative grid it runs).

    When the kernel cannot be compiled or made resident: ``None`` with ``fallback`` (the
    caller then launches one kernel per phase, with a warning), else a ConfigError."""
    if simulator_enabled():
        return lambda *a: kernel[1, threads](*a)
    try:
        spec = kernel.specialize(*args)
        ov = next(iter(spec.overloads.values()))
        blocks = int(ov.max_cooperative_grid_blocks(threads))
        if blocks < 1:
            raise RuntimeError("not one block of the persistent kernel fits on a "
                               "multiprocessor")
    except Exception as e:
        if not fallback:
            raise ConfigError(f"the persistent GPU kernel is not usable here: {e}",
                              field="--device", value="gpu",
                              expected="a GPU and numba-cuda that run cooperative launches "
                                       "(persistent=False launches one kernel per phase)"
                              ) from e
        import warnings

        warnings.warn(f"persistent GPU kernel not usable ({type(e).__name__}: {e}); "
                      "launching one kernel per phase and step (slower on small meshes)",
                      RuntimeWarning, stacklevel=3)
        return None
    launcher = spec[blocks, threads]
    return lambda *a: launcher(*a)


def profile_ticker(profile: dict[str, float] | None) -> Callable[[str | None], None]:
    """``tick(name)`` for the launch-per-kernel loops of both GPU engines: with a ``profile``
    dict, wait for the device and add the wall time since the previous tick under ``name``
    (``None`` only restarts the clock); without one, a no-op (the launches stay
    asynchronous)."""
    if profile is None:
        return lambda name: None
    import time

    from numba import cuda as _cuda

    last = [time.perf_counter()]

    def tick(name: str | None) -> None:
        _cuda.synchronize()
        now = time.perf_counter()
        if name is not None:
            profile[name] = profile.get(name, 0.0) + now - last[0]
        last[0] = now

    return tick


def _copy_back(st, g) -> None:
    from robobore.cutting.fe import kernels3d as K3

    for name in _MUTABLE:
        getattr(st, name)[...] = g[name].copy_to_host()
    ext = float(st.en[K3.E_EXT])
    K3.sum_energies3(st.mass, st.vx, st.vy, st.vz, st.ie, st.plast, st.hge, st.alive, st.fric,
                     st.pen, st.ero_ke, st.nwork, st.en)
    st.en[K3.E_EXT] = ext
