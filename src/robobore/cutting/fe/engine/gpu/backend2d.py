"""GPU backend of the 2D explicit engine (numba-cuda), built from the SAME scalar physics.

The per-element, per-node, tool and conduction updates are the plain-Python scalar functions
of the CPU engine (:func:`quad.element.quad_element_py`, :func:`quad.node_contact.quad_node_py`,
:func:`quad.tool_motion.tool_kinematics_py`, :func:`quad.tool_motion.tool_step_py`,
:func:`physics.thermal2d.quad_centroid_py`, :func:`physics.thermal2d.quad_conduct_py`,
:func:`engine.chunk_loop.sum_energies_py`) and the shared material/contact/support functions
(:mod:`robobore.material.johnson_cook`, :mod:`robobore.cutting.fe.physics.tool_contact`), made
with device versions of their callees by their factories
(:mod:`robobore.cutting.fe.engine.gpu.device2d`) and compiled with
``numba.cuda.jit(device=True)``; the CPU engine calls the ``njit`` versions of the same
functions from its ``prange`` loops.

One time step is five kernel launches: nodes (contact count by atomic add), the contact-
force total (one block, summed in the CPU engine's fixed lane order,
``quad.node_contact.contact_total``: the same bits on both devices), the tool (one thread: support
springs, external work), elements (stable step by atomic min, inverted element by atomic
max) and the step end (one thread: time, status, time-averaged histories and, at each
sample, the energy totals summed serially in the CPU engine's order). With
``solver.heat_conduction`` more launches run every ``solver.conduction_interval`` steps:
centroids, fluxes, copy, the tied parting-line edges (node splitting), the thermal
contact with the tool (nodes, then elements) and the reset of the accumulated time. The
loop stays on the device; the host copies the state back between chunks (for the progress
bar and the energy check).


Optional: needs an NVIDIA GPU and numba's CUDA target (``pip install robobore[gpu]``).
Importing this module needs neither; :func:`robobore.cutting.fe.engine.gpu.shared.require_gpu`
raises a clear :class:`robobore.errors.ConfigError` when no GPU is usable. Correctness is tested on
the CPU with numba's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1``) against the CPU engine. The
workpiece-frame model is timed on an H100 (docs/fe.md, "GPU path"); the tool-frame model is
checked in the simulator and compiled for sm_90, not timed on a GPU.

The tool-frame ALE model (``mesh.frame = "tool"``) runs here too: every
``solver.ale_interval`` steps, after the tool step, the persistent kernel runs the ALE pass of
:func:`robobore.cutting.fe.ale.rezone.rezone` from the same scalar functions
(``tf_place_py``, ``tf_face_py``, the Jacobi sweeps ``tf_sweep_py`` / ``tf_sweep_copy_py``,
``tf_interior_py``, the donor-cell remap ``rz_flux_py``, ``rz_velocity_py``, ``rz_write_py``,
``rz_node_mass_py``), a grid barrier wherever one pass reads what another wrote (14 per
pass); the launch-per-kernel path launches one kernel per pass. The contact force by tool
face (``quad.node_contact.contact_split``) is added by one thread in increasing node order over the
chunks holding a contact node: the CPU's serial order, the same bits.

Layout: the device functions are bound in :mod:`robobore.cutting.fe.engine.gpu.device2d`, the
kernels built in :mod:`robobore.cutting.fe.engine.gpu.kernels2d`, the CUDA plumbing shared with
the 3D engine is :mod:`robobore.cutting.fe.engine.gpu.shared`, whose
:func:`~robobore.cutting.fe.engine.gpu.shared.drive_gpu` is the host driver of both engines;
this module hands it the 2D state, the kernels and the launch-per-kernel step.

Kernel parameters: every kernel takes the whole state (the launch-per-kernel kernels also the
reductions), 3944 bytes of CUDA's classic 4096-byte limit (checked by a test with numba's data
model).

Not ported: the B-bar element is refused with a ConfigError.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from robobore.cutting.fe.ale import rezone as RZ
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.gpu.kernels2d import kernels2
from robobore.cutting.fe.engine.gpu.runstate2d import N_RED, RUN_ARRAYS, RunState
from robobore.cutting.fe.engine.gpu.shared import GpuEngine, blocks, drive_gpu, require_gpu
from robobore.cutting.fe.quad import node_contact
from robobore.errors import ConfigError

__all__ = ["advance_gpu", "check_gpu_supported"]

_THREADS = 128
#: the kernels (benchmarks/gpu_compile_check.py compiles them)
_kernels = kernels2

def check_gpu_supported(element: str, source: str | None = None) -> None:
    """Raise a ConfigError for a setting the GPU engine does not run (the B-bar element)."""
    if element != "q4r":
        raise ConfigError("the B-bar element is not ported to the GPU", file=source,
                          field="solver.element", value=element,
                          expected='"q4r" with --device gpu, or --device cpu')


#: FEState arrays used by the kernels (copied to the device; the persistent kernel's state
#: RunState holds them, then its scalar settings)
_ARRAYS = RUN_ARRAYS
#: the arrays the kernels change (copied back to the host)
_MUTABLE = ("x", "y", "vx", "vy", "mass", "alive", "qs", "area0", "ie", "hge", "fex", "fey",
            "dte", "plast", "rate", "cfx", "cfy", "fric", "pen", "ndead", "ero_ke", "nwork", "prm",
            "tool", "en", "ist", "clock", "hacc", "hist", "tied", "tbuf", "fheat", "tcq",
            "vslip", "xn", "yn", "buf", "vbuf", "aflt")


def advance_gpu(st: Any, t_end: float, *, chunk_steps: int = 2000,
                progress: Callable[[float], None] | None = None,
                check: Callable[[Any], None] | None = None,
                profile: dict[str, float] | None = None,
                persistent: bool | None = None) -> int:
    """GPU counterpart of :func:`robobore.cutting.fe.engine.chunk_driver.advance` (same contract).

    Copies the :class:`~robobore.cutting.fe.engine.state2d.FEState` to the device, runs chunks of
    ``chunk_steps`` steps there, copies the step counter and clock back after each chunk
    (the whole state when ``check`` is given, before calling it) and the whole state at the
    end. Returns the number of steps taken. Raises NumericalError on instability (same
    messages as the CPU engine) and ConfigError when no GPU is usable or the state asks for
    the B-bar element. ``profile`` and ``persistent``:
    as in :func:`robobore.cutting.fe.engine.gpu.backend3d.advance3_gpu` (per-kernel wall times for
    benchmarks; one cooperative launch per chunk, the default without ``profile``).
    """
    phases = st.phases
    check_gpu_supported("q4r" if phases.element == "q4r" else "q4_bbar")
    # the tool-frame ALE pass every rz_every steps (the tool frame only), conduction every
    # cond_every steps (conduction only): the kernels of the state's phases
    rz_every = int(st.prm[layout.P_RZ_EVERY]) if phases.tool_frame else 0
    cond_every = int(st.prm[layout.P_COND_EVERY]) if phases.conduction else 0
    require_gpu()
    (k_nodes, k_contact_sum, k_tool, k_elems, k_centroids, k_conduct, k_conduct_end,
     k_parting, k_theat_nodes, k_theat_elems, k_conduct_reset, k_finish, k_run,
     ale) = _kernels(phases)
    gn, ge = blocks(st.x.shape[0]), blocks(st.conn.shape[0])
    erosion = int(st.prm[layout.P_EROSION])
    npair = int(st.ppair.shape[0])
    gp, gs = blocks(npair), blocks(int(st.snodes.shape[0]))
    theat = st.prm[layout.P_HC] > 0.0 or st.prm[layout.P_FHEAT] > 0.0

    def launch_step(a, dred, step, tick):
        # one step as one launch per phase (the persistent kernel's phases) on the state
        # RunState a; conduction where ist[I_STEP] % cond_every == 0, as on the CPU
        tick(None)
        k_nodes[gn, _THREADS](a, dred)
        tick("nodes")
        k_contact_sum[1, node_contact.N_SUM_LANES](a, dred)
        tick("contact_sum")
        k_tool[1, 1](a, dred)
        tick("tool")
        if phases.tool_frame and step % rz_every == 0:
            _ale_launches(a, ale, gn, ge, gs)
            tick("ale")
        k_elems[ge, _THREADS](a, dred)
        tick("elements")
        if phases.conduction and step % cond_every == 0:
            k_centroids[ge, _THREADS](a)
            k_conduct[ge, _THREADS](a)
            k_conduct_end[ge, _THREADS](a)
            if npair > 0:
                k_parting[gp, _THREADS](a)
            if theat:
                k_theat_nodes[gn, _THREADS](a)
                k_theat_elems[ge, _THREADS](a)
            k_conduct_reset[1, 1](a)
            tick("conduction")
        k_finish[1, 1](a, dred)
        tick("finish")

    engine = GpuEngine(names=_ARRAYS, p_tend=layout.P_TEND, n_red=N_RED, k_run=k_run,
                       run_state=RunState, run_extra=[erosion, cond_every, int(theat), rz_every],
                       launch_step=launch_step, copy_back=_copy_back, label="simulation (GPU)")
    return drive_gpu(st, t_end, engine, chunk_steps=chunk_steps, progress=progress,
                     check=check, profile=profile, persistent=persistent)


def _ale_launches(a: Any, ale: tuple, gn: int, ge: int, gs: int) -> None:
    """One tool-frame ALE pass as one launch per phase (the persistent kernel's phases) on the
    state RunState ``a``."""
    (k_ale_place, k_ale_face, k_ale_sweep, k_ale_sweep_copy, k_ale_interior, k_ale_flux,
     k_ale_velocity, k_ale_apply, k_ale_write, k_ale_nodes, k_ale_mass) = ale
    T = _THREADS
    k_ale_place[gn, T](a)
    k_ale_face[gn, T](a)
    for _ in range(RZ.TF_SWEEPS):
        k_ale_sweep[gn, T](a)
        k_ale_sweep_copy[gn, T](a)
    k_ale_interior[gn, T](a)
    k_ale_flux[ge, T](a)
    k_ale_velocity[gs, T](a)
    k_ale_apply[gs, T](a)
    k_ale_write[ge, T](a)
    k_ale_nodes[gn, T](a)
    k_ale_mass[gn, T](a)


def _copy_back(st: Any, g: dict) -> None:
    for name in _MUTABLE:
        getattr(st, name)[...] = g[name].copy_to_host()
