"""The end of a time step, one code for the 2D and 3D engines on the CPU and the GPU: the
checks that stop a run, the time-averaged histories and the history sampler.

The end of a step (``end_step``, made by :func:`make_end_step`) runs after a step's element
pass: it moves the clock and the step counter on, stops the run on an inverted element, an
empty mesh, non-finite contact forces or time step, a collapsed time step or the end time
(``ist[I_STATUS]``), stores the next stable step and adds the step's contribution to the
time-averaged channels; its ``sample_history`` writes one history row when a sample interval
is complete. Both are plain-Python scalar functions in the project's device-ready style,
written inside the factory :func:`make_end_step`, which receives one engine's layout and
functions and returns them compiled with ``numba.njit`` for the CPU loops
(:func:`robobore.cutting.fe.engine.chunk_loop.run_chunk_for`,
:func:`robobore.cutting.fe.engine.kernels3d.run_chunk3`) or ``numba.cuda.jit(device=True)``
for the GPU kernels (:mod:`robobore.cutting.fe.engine.gpu.kernels2d`,
:mod:`robobore.cutting.fe.engine.gpu.kernels3d`).

History row layout, the same in both engines (``hist[k]``, ``hacc`` indexed alike):

* column :data:`H_T` = 0: the time at the end of the sample interval [s];
* columns :data:`H_AVG` = 1 onwards, the time averages over the interval (``hacc / t_acc``):
  the ``NDIM`` components of the force on the tool (``tool[T_FORCE:]``), the ``NDIM``
  components of the tool support's displacement (``tool[T_DISP:]``), the number of contact
  nodes, then ``N_SPLIT`` components of the force by tool face (2D: rake, edge arc, flank,
  x and y each);
* ``N_TOOL_COLUMNS`` (1 or 2) instantaneous tool columns (the engine's ``tool_columns``);
* seven energies at the end of the interval, in the order of :data:`HIST_ENERGIES`
  (kinetic, internal, plastic, hourglass, contact, external, eroded), :data:`HE_KIN` ...
  relative to the first of them.

:func:`columns` gives the indices for an engine; the layouts
(:mod:`robobore.cutting.fe.engine.layout`, :mod:`robobore.cutting.fe.hex.scalar3d`) name them
``H_*``.

An engine is described to :func:`make_end_step` by the values of ``NDIM``, ``N_SPLIT``,
``N_TOOL_COLUMNS``, ``T_FORCE``, ``T_DISP`` (tool-state slots), ``P_CFL``, ``P_DTMIN``,
``P_SAMPLE_DT``, ``P_TEND`` (parameter slots), ``COUNT_STOPPED_STEP`` (1: a step stopped by
an inverted element or an empty mesh still moves the clock and the step counter on, the 3D
engine; 0: it does not, the 2D engine) (:data:`ENGINE_NAMES`), and by its functions
``tool_columns(tool)`` (the two instantaneous tool values, the second ignored with one
column) and ``energy_totals(es, en)`` (the totals of the energy accumulators,
:func:`make_energy_totals` of the engine's ``NDIM``; or a function that returns False where
the engine records no per-sample energies: then only the external work is written).
"""

from __future__ import annotations

import math

from robobore.cutting.fe.engine.layout import (
    E_ERODED,
    E_EROKE,
    E_EXT,
    E_FRIC,
    E_HG,
    E_INT,
    E_KIN,
    E_NODEWORK,
    E_PLAST,
    I_BADELEM,
    I_SAMPLE,
    I_STATUS,
    I_STEP,
    STATUS_DONE,
    STATUS_DT_COLLAPSE,
    STATUS_INVERTED,
    STATUS_NO_ELEMENTS,
    STATUS_NONFINITE,
)

__all__ = ["H_T", "H_AVG", "HE_KIN", "HE_INT", "HE_PL", "HE_HG", "HE_FRIC", "HE_EXT", "HE_ERO",
           "HIST_ENERGIES", "columns", "make_energy_totals", "make_end_step", "ENGINE_NAMES"]

#: history column of the time at the end of each sample interval [s]
H_T = 0
#: first time-averaged history column
H_AVG = 1
#: the energy columns relative to the first of them
HE_KIN, HE_INT, HE_PL, HE_HG, HE_FRIC, HE_EXT, HE_ERO = range(7)
#: the energy accumulators (``en`` indices) recorded in the energy columns, in column order
HIST_ENERGIES = (E_KIN, E_INT, E_PLAST, E_HG, E_FRIC, E_EXT, E_ERODED)
#: the names that describe an engine to :func:`make_end_step`
ENGINE_NAMES = ("NDIM", "N_SPLIT", "N_TOOL_COLUMNS", "T_FORCE", "T_DISP", "P_CFL", "P_DTMIN",
                "P_SAMPLE_DT", "P_TEND", "COUNT_STOPPED_STEP")


def columns(ndim: int, n_split: int, n_tool_columns: int) -> dict[str, int]:
    """History column indices of an engine: ``force`` (first force component), ``disp``
    (first displacement component), ``ncont``, ``split`` (first force-by-face component),
    ``n_avg`` (number of averaged columns), ``tool`` (first instantaneous tool column),
    ``energy`` (first energy column) and ``n_hist`` (row length)."""
    n_avg = 2 * ndim + 1 + n_split
    tool = H_AVG + n_avg
    energy = tool + n_tool_columns
    return {"force": H_AVG, "disp": H_AVG + ndim, "ncont": H_AVG + 2 * ndim,
            "split": H_AVG + 2 * ndim + 1, "n_avg": n_avg, "tool": tool, "energy": energy,
            "n_hist": energy + len(HIST_ENERGIES)}


def make_energy_totals(ndim: int, name: str):
    """The energy totals of an engine of ``ndim`` (2 or 3) dimensions as a plain-Python
    function ``energy_totals(es, en)`` named ``name`` (compile it with ``numba.njit`` or
    ``numba.cuda.jit(device=True)``): the totals of the energy accumulators into ``en``
    (serial, a fixed order; [J/m] in 2D, [J] in 3D); True. ``es`` = (mass, vx, vy, vz, ie,
    plast, hge, alive, fric, pen, ero_ke, nwork); ``vz`` is read only where ``ndim`` = 3."""
    if ndim not in (2, 3):
        raise ValueError(f"ndim {ndim!r}: expected 2 or 3")
    NDIM = ndim

    def energy_totals(es, en):
        mass, vx, vy, vz, ie, plast, hge, alive, fric, pen, ero_ke, nwork = es
        ke = 0.0
        sf = 0.0
        spn = 0.0
        sek = 0.0
        sw = 0.0
        for n in range(mass.shape[0]):
            v2 = vx[n] * vx[n] + vy[n] * vy[n]
            if NDIM == 3:
                v2 += vz[n] * vz[n]
            ke += 0.5 * mass[n] * v2
            sf += fric[n]
            spn += pen[n]
            sek += ero_ke[n]
            sw += nwork[n]
        si = 0.0
        sp = 0.0
        sh = 0.0
        se = 0.0
        for e in range(ie.shape[0]):
            si += ie[e]
            sp += plast[e]
            sh += hge[e]
            if alive[e] != 1:
                se += ie[e]
        en[E_KIN] = ke
        en[E_INT] = si
        en[E_PLAST] = sp
        en[E_HG] = sh
        en[E_FRIC] = sf + spn
        en[E_NODEWORK] = sw
        en[E_ERODED] = se + sek
        en[E_EROKE] = sek
        return True

    energy_totals.__name__ = energy_totals.__qualname__ = name
    return energy_totals


def make_end_step(dev, engine: dict, tool_columns, energy_totals):
    """The end of a step of one engine, ``end_step(dt, (dtmin, bad), (fx, fy, fz, ncont),
    split, ist, clock, prm, tool, en, hacc, hist, es)`` with its ``sample_history``, compiled with
    ``dev`` (``numba.njit``, ``njit(inline="always")`` or ``numba.cuda.jit(device=True)``).

    ``engine`` holds the values of :data:`ENGINE_NAMES` (the module docstring);
    ``tool_columns`` and ``energy_totals`` are the engine's functions, already compiled with
    ``dev``. The two functions below close over those values, which numba compiles as
    constants. ValueError for an engine description without every name of
    :data:`ENGINE_NAMES` or with another.
    """
    missing = set(ENGINE_NAMES) - set(engine)
    if missing or set(engine) - set(ENGINE_NAMES):
        raise ValueError(f"engine description {sorted(engine)}: expected the names "
                         f"{ENGINE_NAMES}")
    NDIM, N_SPLIT, N_TOOL_COLUMNS = engine["NDIM"], engine["N_SPLIT"], engine["N_TOOL_COLUMNS"]
    T_FORCE, T_DISP = engine["T_FORCE"], engine["T_DISP"]
    P_CFL, P_DTMIN, P_SAMPLE_DT, P_TEND = (engine["P_CFL"], engine["P_DTMIN"],
                                           engine["P_SAMPLE_DT"], engine["P_TEND"])
    COUNT_STOPPED_STEP = engine["COUNT_STOPPED_STEP"]

    def sample_history_py(k, t, ist, clock, tool, en, hacc, hist, es):
        """Write history row ``k`` at time ``t`` [s] and start the next sample interval.

        The energy totals first (``energy_totals``; a non-finite kinetic energy stops the run
        with STATUS_NONFINITE, nothing written, and returns False), then the time, the
        averages of the accumulated channels over the interval ``clock[2]`` [s], the
        instantaneous tool columns and the energies. Clears ``hacc`` and ``clock[2]`` and
        counts the sample. Returns True.
        """
        summed = energy_totals(es, en)
        if summed and not math.isfinite(en[E_KIN]):
            ist[I_STATUS] = STATUS_NONFINITE
            return False
        ta = clock[2]
        hist[k, 0] = t
        n_avg = 2 * NDIM + 1 + N_SPLIT
        for j in range(H_AVG, H_AVG + n_avg):
            hist[k, j] = hacc[j] / ta
        h = H_AVG + n_avg
        a, b = tool_columns(tool)
        hist[k, h] = a
        if N_TOOL_COLUMNS > 1:
            hist[k, h + 1] = b
        h += N_TOOL_COLUMNS
        if summed:
            hist[k, h + HE_KIN] = en[E_KIN]
            hist[k, h + HE_INT] = en[E_INT]
            hist[k, h + HE_PL] = en[E_PLAST]
            hist[k, h + HE_HG] = en[E_HG]
            hist[k, h + HE_FRIC] = en[E_FRIC]
            hist[k, h + HE_ERO] = en[E_ERODED]
        hist[k, h + HE_EXT] = en[E_EXT]
        for j in range(hacc.shape[0]):
            hacc[j] = 0.0
        clock[2] = 0.0
        ist[I_SAMPLE] = k + 1
        return True

    def end_step(dt, elements, contact, split, ist, clock, prm, tool, en, hacc, hist, es):
        """The end of a step of length ``dt`` [s] (``clock`` = [t, dt, t_acc]); True: go on.

        ``elements`` = ``(dtmin, bad)``, the element pass's result: the smallest stable step
        of the elements [s] (1e30: none left) and an inverted element (-1: none);
        ``contact`` = ``(fx, fy, fz, ncont)``, the node pass's: the contact-force total
        (``fz`` = 0 in 2D) and the number of contact nodes; ``split``: the force by tool face
        (``N_SPLIT`` values); ``es``: the state arrays of ``energy_totals``. Moves
        ``clock[0]`` and ``ist[I_STEP]`` on, then stops (False, with ``ist[I_STATUS]``) on an
        inverted element, no element, non-finite forces or step, a step below
        ``prm[P_DTMIN]`` or at ``prm[P_TEND]`` (after the energy totals); else stores the next
        step ``prm[P_CFL] * dtmin`` in ``clock[1]``, adds ``dt`` times each averaged channel
        to ``hacc`` and ``dt`` to ``clock[2]``, and writes a history row
        (``sample_history``) when the time passes the end of the current sample interval.
        """
        dtmin, bad = elements
        fx, fy, fz, ncont = contact
        t = clock[0] + dt
        if COUNT_STOPPED_STEP:
            clock[0] = t
            ist[I_STEP] += 1
        if bad >= 0:
            ist[I_BADELEM] = bad
            ist[I_STATUS] = STATUS_INVERTED
            return False
        if dtmin >= 1e30:
            ist[I_STATUS] = STATUS_NO_ELEMENTS
            return False
        if not COUNT_STOPPED_STEP:
            clock[0] = t
            ist[I_STEP] += 1
        new_dt = prm[P_CFL] * dtmin
        if not (math.isfinite(fx) and math.isfinite(fy) and math.isfinite(fz)
                and math.isfinite(new_dt)):
            ist[I_STATUS] = STATUS_NONFINITE
            return False
        clock[1] = new_dt
        if new_dt < prm[P_DTMIN]:
            ist[I_STATUS] = STATUS_DT_COLLAPSE
            return False
        h = H_AVG
        for j in range(NDIM):
            hacc[h + j] += dt * tool[T_FORCE + j]
        h += NDIM
        for j in range(NDIM):
            hacc[h + j] += dt * tool[T_DISP + j]
        h += NDIM
        hacc[h] += dt * ncont
        for j in range(N_SPLIT):
            hacc[h + 1 + j] += dt * split[j]
        clock[2] += dt
        k = ist[I_SAMPLE]
        if t >= (k + 1) * prm[P_SAMPLE_DT] and k < hist.shape[0]:
            if not sample_history(k, t, ist, clock, tool, en, hacc, hist, es):
                return False
        if t >= prm[P_TEND]:
            ist[I_STATUS] = STATUS_DONE
            energy_totals(es, en)
            return False
        return True

    # each engine's functions under its own names: numba names machine code by qualified
    # name, a per-process counter and argument types (the same in 2D and 3D), so functions
    # sharing a name, loaded from numba's cache into one process, could run one another's code
    sample_history_py.__name__ = sample_history_py.__qualname__ = f"sample_history{NDIM}d"
    sample_history = dev(sample_history_py)
    end_step.__name__ = end_step.__qualname__ = f"end_step{NDIM}d"
    return dev(end_step)
