"""CUDA plumbing shared by the 2D and 3D GPU engines (numba-cuda): availability checks, the
binding of the ``numba.cuda`` module, the Johnson-Cook device functions, the block-level
chunk listing of the persistent kernels, the host side of a chunk (the cooperative launch
of a persistent kernel, or the per-launch profile clock of the launch-per-kernel loop) and the
host driver of both engines (:func:`drive_gpu`).

Importing this module needs neither a GPU nor numba's CUDA target; :func:`require_gpu` raises
a clear :class:`robobore.errors.ConfigError` when no GPU is usable. The engines themselves are
:mod:`robobore.cutting.fe.engine.gpu.backend3d` (3D) and
:mod:`robobore.cutting.fe.engine.gpu.backend2d` (2D).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.errors import ConfigError

__all__ = ["THREADS", "MAX_BLOCK", "simulator_enabled", "cuda_available", "require_gpu",
           "jc_device_functions", "bind_cuda", "chunk_list_py", "persistent_run", "cooperative",
           "profile_ticker", "blocks", "GpuEngine", "drive_gpu"]

#: threads per block of the GPU engines' launches
THREADS = 128
#: largest block size of the persistent kernels, 2D and 3D (their shared compaction counters)
MAX_BLOCK = 1024


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
    fail = dev(jc.make_jc_failure_strain(homologous_temperature=th))
    dmg = dev(jc.make_jc_damage_increment(jc_failure_strain=fail))
    ret = dev(jc.make_jc_return(jc_athermal=athermal, homologous_temperature=th))
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


def persistent_run(kernel, state: tuple, red, n_nodes: int, profile,
                   persistent: bool | None):
    """``run(n_steps)`` of a persistent kernel (2D or 3D engine, built by
    :func:`robobore.cutting.fe.engine.gpu.persistent.persistent_kernel`) whose arguments are
    ``n_steps``, the state ``state`` (a namedtuple), the reduction slots ``red``, the chunk
    flags and the chunk list (allocated here for ``n_nodes`` nodes); ``None`` where the caller
    launches one kernel per phase (``persistent`` False, or None with a ``profile``, or a
    cooperative launch that cannot be set up -- then with a warning)."""
    from robobore.cutting.fe.quad.node_contact import N_SUM_LANES

    auto = persistent is None
    if not (profile is None if auto else persistent):
        return None
    nchunk = (n_nodes + N_SUM_LANES - 1) // N_SUM_LANES
    args = [state, red, cuda.to_device(np.zeros(nchunk, np.int32)),
            cuda.to_device(np.zeros(nchunk, np.int64))]
    launch = cooperative(kernel, [1] + args, THREADS, fallback=auto)
    if launch is None:
        return None
    return lambda n_steps: launch(n_steps, *args)


def cooperative(kernel, args: list, threads: int, fallback: bool = False):
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


def blocks(n: int) -> int:
    """Blocks of :data:`THREADS` threads that cover ``n`` items (at least one)."""
    return max(1, (n + THREADS - 1) // THREADS)


@dataclass(frozen=True)
class GpuEngine:
    """What :func:`drive_gpu` runs: one GPU engine's state on the device and its kernels."""

    #: the state's arrays copied to the device, in the persistent kernel's order
    names: tuple[str, ...]
    #: the parameter slot of the end time
    p_tend: int
    #: the number of reduction slots of the kernels
    n_red: int
    #: the persistent kernel (:func:`robobore.cutting.fe.engine.gpu.persistent.persistent_kernel`)
    k_run: Any
    #: the namedtuple class of the persistent kernel's state: the arrays, then ``run_extra``
    run_state: Any
    #: the state's scalar settings after the arrays
    run_extra: list
    #: ``launch_step(state, dred, step, tick)``: one step as one launch per kernel on the state
    #: ``run_state(*arrays, *run_extra)`` (the persistent kernel's argument)
    launch_step: Callable
    #: ``copy_back(st, g)``: the device arrays back into the host state
    copy_back: Callable
    #: the run's name in an instability message
    label: str


def drive_gpu(st, t_end: float, engine: GpuEngine, *, chunk_steps: int,
              progress: Callable[[float], None] | None, check: Callable | None,
              profile: dict[str, float] | None, persistent: bool | None) -> int:
    """The host driver of both GPU engines
    (:func:`robobore.cutting.fe.engine.gpu.backend2d.advance_gpu`,
    :func:`robobore.cutting.fe.engine.gpu.backend3d.advance3_gpu`): the state's arrays
    ``engine.names`` to the device, then chunks of ``chunk_steps`` steps until ``t_end`` [s]
    or a stop status; returns the number of steps taken.

    A chunk is one cooperative launch of the persistent kernel ``engine.k_run`` (arguments:
    the state ``run_state(*arrays, *run_extra)``, a namedtuple, the ``n_red`` reduction slots
    of the kernels, the smallest stable step in slot 0 and the inverted element in slot 1;
    see :func:`persistent_run`), or ``launch_step(state, dred, step, tick)`` once per step
    (``state`` the same namedtuple of the device arrays, ``step`` the step's number, ``tick`` the
    :func:`profile_ticker`). After each chunk the step counter and clock come back (the whole
    state, by ``copy_back(st, g)``, when ``check`` is given, at the end and on a stop); an
    instability status raises :func:`robobore.cutting.fe.status.instability_error` labelled
    ``engine.label``.
    """
    names, launch_step, copy_back = engine.names, engine.launch_step, engine.copy_back
    from robobore.cutting.fe.engine import layout
    from robobore.cutting.fe.engine.status import STATUS_TEXT, instability_error

    require_gpu()
    _cuda = bind_cuda()
    st.prm[engine.p_tend] = t_end
    st.ist[layout.I_STATUS] = layout.STATUS_OK
    g = {name: _cuda.to_device(np.ascontiguousarray(getattr(st, name))) for name in names}
    red = np.zeros(engine.n_red)
    red[0] = 1e30  # no stable step yet (R_DTMIN)
    red[1] = -1.0  # no inverted element (R_BAD)
    dred = _cuda.to_device(red)
    t_start = st.time
    step0 = int(st.ist[layout.I_STEP])
    tick = profile_ticker(profile)
    state = engine.run_state(*[g[name] for name in names], *engine.run_extra)
    run = persistent_run(engine.k_run, state, dred, st.x.shape[0], profile, persistent)
    while True:
        if run is not None:
            run(chunk_steps)
        else:
            # while the status is OK every launch sequence is exactly one step, so the host
            # knows the step number; once the status changes the launches return at once
            step = int(st.ist[layout.I_STEP])
            for i in range(chunk_steps):
                launch_step(state, dred, step + i, tick)
        for name in ("ist", "clock"):
            getattr(st, name)[...] = g[name].copy_to_host()
        status = int(st.ist[layout.I_STATUS])
        if status in STATUS_TEXT or status == layout.STATUS_DONE or check is not None:
            copy_back(st, g)
        if status in STATUS_TEXT:
            raise instability_error(st, engine.label, "a smaller solver.cfl, a larger "
                                    "mesh.element_size_um or less mass scaling")
        if progress is not None:
            progress(min(1.0, (st.time - t_start) / max(t_end - t_start, 1e-300)))
        if check is not None:
            check(st)
        if status == layout.STATUS_DONE or st.time >= t_end:
            copy_back(st, g)
            return int(st.ist[layout.I_STEP]) - step0
