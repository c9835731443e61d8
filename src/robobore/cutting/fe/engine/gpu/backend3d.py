"""GPU backend of the 3D explicit engine (numba-cuda), built from the SAME scalar physics.

The per-element and per-node updates are the plain-Python scalar functions of the CPU engine
(:func:`hex.element.hex_element_py`, :func:`hex.scalar3d.hex_node_py`,
:func:`hex.scalar3d.tool_step_py`) and the shared material/contact/support functions
(:mod:`robobore.material.johnson_cook`, :mod:`robobore.cutting.fe.physics.tool_contact`), made
with device versions of their callees by their factories and compiled with
``numba.cuda.jit(device=True)``. One time step is five kernel launches: nodes, the contact-force
total (one block, in the CPU's fixed lane order, so a run is reproducible bit for bit), the tool
(one thread), elements (stable step by atomic min), and the step end (one thread: time, status,
time-averaged histories); every ``solver.conduction_interval`` steps the heat conduction of
:mod:`robobore.cutting.fe.physics.thermal3d` adds five more (centroids, new temperatures, their
copy, the insert's heat per node, then per element). The loop stays on the device; the host only
checks the status between chunks.

Optional: needs an NVIDIA GPU and numba's CUDA target (``pip install robobore[gpu]``, i.e.
``numba-cuda``). Importing this module never needs either; :func:`require_gpu` raises a
clear :class:`robobore.errors.ConfigError` when no GPU is usable. Correctness is tested on
the CPU with numba's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1``) against the CPU engine.

Layout: the CUDA plumbing shared with the 2D engine (availability, binding, the cooperative
launch) is :mod:`robobore.cutting.fe.engine.gpu.shared`; the kernels are built in
:mod:`robobore.cutting.fe.engine.gpu.kernels3d`; this module hands them, with the 3D state and
its launch-per-kernel step, to the host driver both engines share
(:func:`robobore.cutting.fe.engine.gpu.shared.drive_gpu`).

Limits: per-sample energy histories are not recorded on the GPU (the final energy totals
are computed on the host from the copied-back state). The 2D engine's GPU port, built the
same way from its scalar functions, is :mod:`robobore.cutting.fe.engine.gpu.backend2d`.
"""

from __future__ import annotations

from collections.abc import Callable

from robobore.cutting.fe.engine.gpu.kernels3d import N_RED, RUN_ARRAYS, RunState3, kernels3
from robobore.cutting.fe.engine.gpu.shared import (
    THREADS,
    GpuEngine,
    blocks,
    cooperative,
    drive_gpu,
    require_gpu,
)

__all__ = ["advance3_gpu"]

_THREADS = THREADS
#: the kernels (benchmarks/gpu_compile_check.py compiles the persistent one, the last)
_kernels = kernels3
#: the cooperative launch (tests/cutting/fe3d/test_fe3d_gpu.py checks its fallback)
_cooperative = cooperative

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
    """GPU counterpart of :func:`robobore.cutting.fe.engine.state3d.advance3` (same contract).

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
    from robobore.cutting.fe.engine.state3d import heat_pass
    from robobore.cutting.fe.hex import layout3d, scalar3d
    from robobore.cutting.fe.quad import node_contact

    require_gpu()
    # the kernels of the state's thermal model: the heat phase for a heat-pass interval
    conduction = heat_pass(st.prm)
    k_nodes, k_contact_sum, k_tool, k_elems, k_finish, k_thermal, k_run = _kernels(conduction)
    k_centroids, k_conduct, k_copy_temp, k_heat_nodes, k_heat_elems, k_cond_done = k_thermal
    gn, ge = blocks(st.x.shape[0]), blocks(st.conn.shape[0])
    erosion = int(st.prm[layout3d.P_EROSION])
    heat = st.prm[layout3d.P_HC] > 0.0 or st.prm[layout3d.P_FHEAT] > 0.0

    def launch_step(a, dred, step, tick):
        # one step as one launch per phase (the persistent kernel's phases) on the state
        # RunState3 a
        tick(None)
        k_nodes[gn, _THREADS](a, dred)
        tick("nodes")
        k_contact_sum[1, node_contact.N_SUM_LANES](a, dred)
        tick("contact_sum")
        k_tool[1, 1](a, dred)
        tick("tool")
        k_elems[ge, _THREADS](a, dred)
        tick("elements")
        if conduction and scalar3d.is_conduction_step_py(step, st.prm):
            k_centroids[ge, _THREADS](a)
            k_conduct[ge, _THREADS](a)
            k_copy_temp[ge, _THREADS](a)
            if heat:
                k_heat_nodes[gn, _THREADS](a)
                k_heat_elems[ge, _THREADS](a)
            k_cond_done[1, 1](a)
            tick("conduction")
        k_finish[1, 1](a, dred)
        tick("finish")

    engine = GpuEngine(names=_RUN_ARGS, p_tend=layout3d.P_TEND, n_red=N_RED, k_run=k_run,
                       run_state=RunState3, run_extra=[erosion], launch_step=launch_step,
                       copy_back=_copy_back, label="3D simulation (GPU)")
    return drive_gpu(st, t_end, engine, chunk_steps=chunk_steps, progress=progress,
                     check=check, profile=profile, persistent=persistent)


#: the state arrays on the device, in the persistent kernel's state RunState3 (then erosion)
_RUN_ARGS = RUN_ARRAYS



def _copy_back(st, g) -> None:
    from robobore.cutting.fe.engine import kernels3d as K3
    from robobore.cutting.fe.engine import layout

    for name in _MUTABLE:
        getattr(st, name)[...] = g[name].copy_to_host()
    ext = float(st.en[layout.E_EXT])
    K3.sum_energies3(K3.energy_arrays3(st), st.en)
    st.en[layout.E_EXT] = ext
