"""The time-step loop of both CPU engines (numba): one loop for 2D and 3D.

:func:`make_chunk_loop` builds an engine's chunk loop ``loop(n_steps, *arrays)`` -- the state
arrays in the order of the state's ``kernel_args()`` -- from the engine's phases, numba
functions that take the state as a namedtuple ``s`` of those arrays (``s.x``, ``s.prm``, ...):
a factory that receives the phases as arguments and returns the compiled loop, a closure over
them, so that every callee of the loop is a name in its source. The loop advances up to
``n_steps`` central-difference steps and returns the number taken. One step (``clock`` =
[t, dt, t_acc]):

1. ``nodes(s, kinematics(s.tool, s.prm), dt, split)`` -> ``(fx, fy, fz, ncont)``: the node
   update with the tool contact, the contact-force total in the fixed lane order shared with
   the GPU (``fz`` = 0 in 2D) and the number of contact nodes; in 2D also the force by tool
   face into ``split``;
2. the external work ``en[E_EXT]`` += ``tool_step(s, fx, fy, fz, dt)`` (the tool support);
3. ``remesh(s, step)``: the 2D tool-frame ALE pass at the steps that have one (3D: none);
4. ``elements(s, dt)`` -> ``(dtmin, bad)``: the element update, the smallest stable step [s]
   and an inverted element (-1: none);
5. ``heat(s, step, t, dt)``: the conduction pass at the steps that have one;
6. the end of step of :mod:`robobore.cutting.fe.engine.history` (``end_step``, made for the
   engine by :func:`~robobore.cutting.fe.engine.history.make_end_step`): stop checks,
   histories, samples; a stop ends the chunk.

With ``totals_at_chunk_end`` the energy totals are summed after a chunk that ran to its end
(3D: the host's energy check reads them).

The phases are compiled with ``njit(inline="always")``: inlined into the loop, they read the
state's arrays in place. As separate functions each call would pass the whole state (about 64
arrays, with their reference counts) five times a step, about 1 % of a 2D step (the 2D
contract config on one thread, side by side with the loop of separate phases).

The engines wrap the loop in their own ``njit(cache=True)`` functions, one per model choice
(2D: ``run_chunk_*`` of :mod:`robobore.cutting.fe.engine.chunk_loop`; 3D: ``run_chunk3*`` of
:mod:`robobore.cutting.fe.engine.kernels3d`), so numba's cache of each sits beside the
engine's phases and is renewed when that module changes; like any callee in another module,
a change to this module needs the cache files cleared (``*.nbi``, ``*.nbc``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from robobore.cutting.fe.engine.layout import E_EXT, I_STEP

__all__ = ["StepPhases", "make_chunk_loop", "no_remesh_py"]


def no_remesh_py(s, step):
    """The ``remesh`` phase of an engine without mesh motion: nothing."""
    return None


_no_remesh = njit(inline="always")(no_remesh_py)


@dataclass(frozen=True)
class StepPhases:
    """The phases of one engine's step (the module docstring's steps 1-6), each compiled with
    ``njit(inline="always")``."""

    #: ``kinematics(tool, prm)``: the tool's motion for the node update
    kinematics: Any
    #: ``nodes(s, kin, dt, split) -> (fx, fy, fz, ncont)``: the node update with the contact
    nodes: Any
    #: ``tool_step(s, fx, fy, fz, dt)``: the tool support's step, returns the external work
    tool_step: Any
    #: ``elements(s, dt) -> (dtmin, bad)``: the element update
    elements: Any
    #: ``heat(s, step, t, dt)``: the conduction pass (a no-op when adiabatic)
    heat: Any
    #: the engine's end of step (:func:`robobore.cutting.fe.engine.history.make_end_step`)
    end_step: Any
    #: ``remesh(s, step)``: the ALE pass; None: none (:func:`no_remesh_py`)
    remesh: Any = None


def make_chunk_loop(*, name: str, state, n_split: int, energy_arrays, energy_totals,
                    phases: StepPhases, totals_at_chunk_end: bool = False):
    """The chunk loop of the module docstring for one engine, compiled with ``numba.njit``
    (not cached: the engines call it from their own cached functions).

    ``name``: the loop's own ``__qualname__``, distinct for each engine and choice: numba
    names a compiled function's machine code by its qualified name, a per-process counter and
    its argument types, so two loops of one name with the same argument types, each compiled
    in another process and both loaded from numba's cache into one, could resolve to one
    machine code; ``state``: the namedtuple class of the state arrays (the order of
    ``kernel_args()``); ``n_split``: the length of the force-by-face buffer (the engine's
    ``N_SPLIT``); ``energy_arrays(s)``: the arrays of ``energy_totals(es, en)``; ``phases``:
    the engine's :class:`StepPhases`; ``totals_at_chunk_end``: sum the energy totals after a
    chunk that ran to its end.
    """
    # the phases as plain names of the closure: the compiled loop calls them directly
    kinematics = phases.kinematics
    nodes = phases.nodes
    tool_step = phases.tool_step
    elements = phases.elements
    heat = phases.heat
    end_step = phases.end_step
    remesh = _no_remesh if phases.remesh is None else phases.remesh

    def chunk_loop(n_steps, *a):
        s = state(*a)
        ist, clock, tool, prm, en = s.ist, s.clock, s.tool, s.prm, s.en
        split = np.zeros(n_split)
        es = energy_arrays(s)
        taken = 0
        for _s in range(n_steps):
            step = ist[I_STEP]
            t = clock[0]
            dt = clock[1]
            contact = nodes(s, kinematics(tool, prm), dt, split)
            fx, fy, fz, _ncont = contact
            en[E_EXT] += tool_step(s, fx, fy, fz, dt)
            remesh(s, step)
            elems = elements(s, dt)
            heat(s, step, t, dt)
            taken += 1
            if not end_step(dt, elems, contact, split, ist, clock, prm, tool, en, s.hacc,
                            s.hist, es):
                return taken
        if totals_at_chunk_end:
            energy_totals(es, en)
        return taken

    chunk_loop.__name__ = chunk_loop.__qualname__ = name
    return njit(chunk_loop)
