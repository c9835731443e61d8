"""The persistent kernel of both GPU engines (numba-cuda): one step loop for 2D and 3D.

:func:`persistent_kernel` builds ``k_run(n_steps, a, red, cflag, clist)``, which runs
``n_steps`` whole time steps in one cooperative launch, from one dimension's device
functions (its phases). ``a`` is the engine's state, a namedtuple of the state arrays and
then its scalar settings (``RunState`` of :mod:`robobore.cutting.fe.engine.gpu.runstate2d`,
``RunState3`` of :mod:`robobore.cutting.fe.engine.gpu.kernels3d`; both name ``x``, ``conn``,
``ist``, ``clock``, ``tool`` and ``prm``), ``red`` the reduction slots
(:data:`R_DTMIN`, :data:`R_BAD`, then the contact-force sums from :data:`R_SUMS`), ``cflag``
and ``clist`` one flag and one slot per chunk of :data:`~robobore.cutting.fe.quad.node_contact.
N_SUM_LANES` nodes. One step:

1. the loop returns unless the status ``ist[I_STATUS]`` is OK; the step number
   ``ist[I_STEP]``, the step length ``clock[1]`` and the tool's kinematics
   ``kin = kinematics(tool, prm)``;
2. ``node(n, a, kin, dt, red)`` for every node (grid-stride), True where the node carries a
   contact force: its chunk is flagged; grid barrier;
3. block 0 lists the flagged chunks in increasing order
   (:func:`~robobore.cutting.fe.engine.gpu.shared.chunk_list_py`), ``lane_sums(a, clist, m,
   lane, p)`` writes each lane's partial sums over them into ``p[:, lane]``, then one thread
   adds the lanes in lane order into ``red[R_SUMS:]`` -- the CPU's fixed order
   (``contact_total``), the same bits on both devices -- and runs ``tool(a, clist, m, kin,
   dt, red)`` (the tool step; in 2D also the force by tool face);
4. a grid barrier where the dimension's later phases read the moved tool
   (``sync_after_tool``), then ``remesh(a, step, tid, nthr, grid)`` (the 2D tool-frame ALE
   pass; none in 3D);
5. ``elem(e, a, dt, red)`` for every element (stable step by atomic min, inverted element
   into ``red[R_BAD]``); grid barrier;
6. ``heat(a, step, dt, tid, nthr, grid)``: the conduction pass where the step has one;
7. ``finish(a, red)`` by thread 0 (the end of step of
   :mod:`robobore.cutting.fe.engine.history`), the step's minimum and inverted element
   reset; grid barrier.

Every phase takes the state and reads its arrays by name (``a.x``), so the loop above is
written once for both dimensions; the phases call the same scalar functions as the CPU engine
(whose one loop is :mod:`robobore.cutting.fe.engine.step_loop`).
"""

from __future__ import annotations

from robobore.cutting.fe.engine.gpu.shared import MAX_BLOCK, bind_cuda, chunk_list_py

__all__ = ["persistent_kernel", "R_DTMIN", "R_BAD", "R_SUMS"]

#: reduction slots shared by both engines: the smallest stable step [s] (drive_gpu starts it
#: at 1e30), the inverted element (-1: none), the first contact-force sum
R_DTMIN, R_BAD, R_SUMS = 0, 1, 2

#: the numba.cuda module, bound on first use (a module global, so that numba's simulator can
#: substitute its own inside the kernel)
cuda = None


def no_remesh_py(a, step, tid, nthr, grid):
    """The ``remesh`` phase of an engine without mesh motion: nothing."""
    return None


def persistent_kernel(*, n_sums: int, kinematics, node, lane_sums, tool, elem, heat, finish,
                      remesh=None, sync_after_tool: bool = False):
    """The persistent kernel ``k_run(n_steps, a, red, cflag, clist)`` of one engine, from its
    device functions (the phases of the module docstring); ``n_sums`` contact-force sums per
    lane."""
    global cuda
    cuda = bind_cuda()
    from numba import float64, int64

    from robobore.cutting.fe.engine.layout import I_STATUS, I_STEP, STATUS_OK
    from robobore.cutting.fe.quad.node_contact import N_SUM_LANES

    dev = cuda.jit(device=True)
    chunks = dev(chunk_list_py)
    if remesh is None:
        remesh = dev(no_remesh_py)
    LANES = N_SUM_LANES
    NCNT = MAX_BLOCK + 1
    NSUM = n_sums
    SYNC_AFTER_TOOL = sync_after_tool

    @cuda.jit(device=True)
    def lanes_total(p, red):
        # each sum's lanes added in lane order by one thread: the CPU's order
        for k in range(NSUM):
            s = 0.0
            for j in range(LANES):
                s += p[k, j]
            red[R_SUMS + k] = s

    @cuda.jit
    def k_run(n_steps, a, red, cflag, clist):
        grid = cuda.cg.this_grid()
        tid = cuda.grid(1)
        nthr = cuda.gridsize(1)
        t = cuda.threadIdx.x
        nb = cuda.blockDim.x
        nn = a.x.shape[0]
        ne = a.conn.shape[0]
        ist, clock, tool_state, prm = a.ist, a.clock, a.tool, a.prm
        p = cuda.shared.array((NSUM, LANES), float64)
        cnt = cuda.shared.array(NCNT, int64)
        for _ in range(n_steps):
            if ist[I_STATUS] != STATUS_OK:
                return
            # the step number is read before the step's first barrier (thread 0 moves it on
            # after the last): every thread takes the same branches below
            step = ist[I_STEP]
            dt = clock[1]
            kin = kinematics(tool_state, prm)
            for n in range(tid, nn, nthr):
                if node(n, a, kin, dt, red):
                    cflag[n // LANES] = 1  # the chunk of LANES nodes holding n has contact
            grid.sync()
            if cuda.blockIdx.x == 0:
                # block 0: the contact-force sums in the CPU's lane order over the chunks
                # holding a contact node (the others add nothing), then the tool
                m = chunks(cflag, clist, cnt, t, nb)
                for lane in range(t, LANES, nb):
                    lane_sums(a, clist, m, lane, p)
                cuda.syncthreads()
                if t == 0:
                    lanes_total(p, red)
                    tool(a, clist, m, kin, dt, red)
            if SYNC_AFTER_TOOL:
                grid.sync()
            remesh(a, step, tid, nthr, grid)
            for e in range(tid, ne, nthr):
                elem(e, a, dt, red)
            grid.sync()
            heat(a, step, dt, tid, nthr, grid)
            if tid == 0:
                finish(a, red)
                red[R_DTMIN] = 1e30
                red[R_BAD] = -1.0
            grid.sync()

    return k_run
