"""The host driver of the compiled loops: :func:`drive_chunks` runs a chunk loop (2D or 3D)
to an end time with progress and checks between chunks and turns a non-finite state or a
collapsing time step into :class:`robobore.errors.NumericalError`; :func:`advance` drives
the 2D loop of the state's model choices
(:func:`robobore.cutting.fe.engine.chunk_loop.run_chunk_for`); :func:`energy_error` is
the energy-balance error checked during a run.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numba
import numpy as np

from robobore.cutting.fe.engine import chunk_loop, layout
from robobore.cutting.fe.engine.state2d import (
    FEState,
)
from robobore.cutting.fe.engine.status import STATUS_TEXT, instability_error
from robobore.cutting.fe.engine.threads import ThreadGovernor
from robobore.errors import ConfigError, NumericalError


def drive_chunks(st: Any, t_end: float, run_chunk: Callable[..., int], p_tend: int, *,
                 chunk_steps: int, label: str, hint: str,
                 progress: Callable[[float], None] | None = None,
                 check: Callable[[Any], None] | None = None,
                 adaptive_threads: bool = True,
                 governor: ThreadGovernor | None = None) -> int:
    """Run a compiled chunk loop (2D ``run_chunk_*`` or 3D ``run_chunk3``) until ``t_end`` [s].

    Shared by :func:`advance` and :func:`~robobore.cutting.fe.engine.state3d.advance3`: ``st`` has
    ``prm``, ``ist``, ``time`` and ``kernel_args()``; ``p_tend`` is the index of the end time in
    that engine's ``prm``. ``progress(fraction_done)`` and ``check(state)`` (may raise) are
    called between chunks. Raises NumericalError (``label``, step, time, cause, ``hint``) on
    instability; returns the number of steps taken.

    ``adaptive_threads`` (default): each chunk runs on the thread count a
    :class:`~robobore.cutting.fe.engine.threads.ThreadGovernor` (``governor``, or a fresh one) finds
    faster, all of numba's threads or one, so that a run sharing the cores with other work
    keeps its share; the results do not depend on it. False: numba's thread count throughout.
    numba's thread count is restored on return.
    """
    st.prm[p_tend] = t_end
    st.ist[layout.I_STATUS] = layout.STATUS_OK
    total = 0
    t_start = st.time
    gov = (governor or ThreadGovernor()) if adaptive_threads else None
    threads_before = numba.get_num_threads()
    try:
        while True:
            if gov is None:
                taken = run_chunk(chunk_steps, *st.kernel_args())
            else:
                threads, steps = gov.next_chunk(chunk_steps)
                numba.set_num_threads(threads)
                t0 = time.perf_counter()
                taken = run_chunk(steps, *st.kernel_args())
                gov.record(threads, int(taken), time.perf_counter() - t0)
            total += int(taken)
            status = int(st.ist[layout.I_STATUS])
            if status in STATUS_TEXT:
                raise instability_error(st, label, hint)
            if progress is not None:
                progress(min(1.0, (st.time - t_start) / max(t_end - t_start, 1e-300)))
            if check is not None:
                check(st)
            if status == layout.STATUS_DONE or st.time >= t_end:
                return total
    finally:
        numba.set_num_threads(threads_before)


def advance(st: FEState, t_end: float, *, chunk_steps: int = 2000,
            progress: Callable[[float], None] | None = None,
            check: Callable[[FEState], None] | None = None,
            adaptive_threads: bool = True, governor: ThreadGovernor | None = None,
            step: Callable[..., int] | None = None) -> int:
    """Run the compiled loop until time ``t_end`` [s]; returns the number of steps taken.

    ``step``: the compiled chunk function (:func:`~robobore.cutting.fe.engine.chunk_loop.step_for`
    of the model spec); default the one of ``st.phases``. ConfigError when ``st.phases`` has
    the ALE or heat pass and its interval (``prm[P_RZ_EVERY]``, ``prm[P_COND_EVERY]``) is
    below one step.

    ``progress(fraction_done)`` is called between chunks; ``check(state)`` too (it may raise).
    Raises NumericalError (with step, time and cause) on instability. ``adaptive_threads``,
    ``governor``: see :func:`drive_chunks`.
    """
    # the intervals the compiled ALE and heat phases divide the step number by
    for on, slot, name in ((st.phases.tool_frame, layout.P_RZ_EVERY, "P_RZ_EVERY"),
                           (st.phases.conduction, layout.P_COND_EVERY, "P_COND_EVERY")):
        if on and st.prm[slot] < 1:
            raise ConfigError(f"{st.phases} needs an interval of at least one step",
                              field=f"prm[{name}]", value=float(st.prm[slot]),
                              expected=">= 1")
    run = chunk_loop.run_chunk_for(st.phases) if step is None else step
    return drive_chunks(st, t_end, run, layout.P_TEND, chunk_steps=chunk_steps,
                        label="simulation",
                        hint="a smaller solver.cfl, a larger mesh.element_size_um or less "
                        "mass scaling", progress=progress, check=check,
                        adaptive_threads=adaptive_threads, governor=governor)


def energy_error(en: np.ndarray) -> float:
    """|E_ext - (kinetic + internal + hourglass + contact + eroded kinetic)| / scale.

    Internal includes elastic, plastic and bulk-viscous work (and the internal energy of
    eroded elements); contact is frictional dissipation plus the current penalty energy.
    """
    parts = (en[layout.E_KIN] + en[layout.E_INT] + en[layout.E_HG] + en[layout.E_FRIC]
             + en[layout.E_EROKE])
    scale = max(abs(en[layout.E_EXT]), abs(parts), 1e-300)
    return float(abs(en[layout.E_EXT] - parts) / scale)


def energy_check(t_contact: float, t_end: float, limit: float) -> Callable[[Any], None]:
    """The ``check(state)`` both engines run between chunks: once a tenth of the cut after
    first contact is done, a state whose :func:`energy_error` exceeds ``limit``
    (``solver.energy_error_limit``) stops the run with a NumericalError naming the step,
    the time and the limit."""
    t_on = t_contact + 0.1 * (t_end - t_contact)

    def check(s: Any) -> None:
        if s.time > t_on:
            err = energy_error(s.en)
            if err > limit:
                raise NumericalError(
                    f"energy balance lost at step {int(s.ist[layout.I_STEP])}, time {s.time:.6g} s:"
                    f" error {err:.3g} > solver.energy_error_limit {limit}")

    return check
