"""The compiled time-step loops of the plane-strain engine, a chunk of steps at a time: the
step loop of both CPU engines (:mod:`robobore.cutting.fe.engine.step_loop`) with the 2D phases
-- node update and contact with the force by tool face, tool, the tool-frame ALE pass, the
one-point or B-bar elements, heat passes -- on the state :data:`ChunkState`; each step ends
with the engines' shared end of step (:mod:`robobore.cutting.fe.engine.history`: stop
conditions, time-averaged histories, history samples with the energy totals), bound here to
the 2D layout (:data:`ENGINE2`, :func:`tool_columns_py`, :data:`sum_energies_py`).

The model choices are compiled in, not branched on: :class:`Phases` (element, tool frame,
conduction) names one specialised loop, :func:`phases_of` reads it from a
:class:`~robobore.cutting.fe.config.spec.ModelSpec`, and :func:`step_for` /
:func:`run_chunk_for` return its compiled chunk function. Each of the six buildable choices
is its own module-level ``njit(cache=True)`` function (:data:`RUN_CHUNK`), compiled on first
use and then loaded from numba's cache:

=========================  ==========  ==========  ===========================
function                   element     frame       thermal
=========================  ==========  ==========  ===========================
``run_chunk_q4r``          one-point   workpiece   adiabatic
``run_chunk_q4r_heat``     one-point   workpiece   conduction
``run_chunk_bbar``         B-bar       workpiece   adiabatic
``run_chunk_bbar_heat``    B-bar       workpiece   conduction
``run_chunk_ale``          one-point   tool        adiabatic
``run_chunk_ale_heat``     one-point   tool        conduction
=========================  ==========  ==========  ===========================
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass
from functools import partial
from typing import Any, Literal

from numba import njit

from robobore.cutting.fe.ale.rezone import rezone
from robobore.cutting.fe.engine.groups2d import (
    QS_TEMP,
    ale_of,
    contact_of,
    nodes_of,
    out_of,
    quads_of,
)
from robobore.cutting.fe.engine.history import make_end_step, make_energy_totals
from robobore.cutting.fe.engine.layout import (
    P_ALE_X0,
    P_CFL,
    P_COND_ACC,
    P_COND_EVERY,
    P_DTMIN,
    P_EROSION,
    P_FHEAT,
    P_HC,
    P_MS,
    P_NFX,
    P_NFY,
    P_NRX,
    P_NRY,
    P_RZ_EVERY,
    P_RZ_MAXMOVE,
    P_SAMPLE_DT,
    P_TCX,
    P_TEND,
    P_TTOOL,
    T_FX,
    T_GX,
    T_UX,
)
from robobore.cutting.fe.engine.step_loop import StepPhases, make_chunk_loop, no_remesh_py
from robobore.cutting.fe.physics.thermal2d import (
    conduct,
    parting_conduct,
    tool_heat,
)
from robobore.cutting.fe.quad.bbar import (
    element_update_bbar,
)
from robobore.cutting.fe.quad.element import (
    element_update,
)
from robobore.cutting.fe.quad.node_contact import (
    contact_split,
    contact_total,
    node_update,
    tool_geometry,
)
from robobore.cutting.fe.quad.tool_motion import (
    tool_kinematics,
    tool_step,
)
from robobore.material import johnson_cook as jc

#: the energy totals (:func:`robobore.cutting.fe.engine.history.make_energy_totals` in 2D) of
#: the state arrays ``es`` = (mass, vx, vy, vx, ie, plast, hge, alive, fric, pen, ero_ke, nwork)
#: into ``en`` [J/m] (serial, a fixed order), under its own name (see history.make_end_step)
sum_energies_py = make_energy_totals(2, "sum_energies_py")


def tool_columns_py(tool):
    """The 2D engine's instantaneous tool history column: the tool tip's x [m] (guide plus
    support displacement; the second value unused)."""
    return tool[T_GX] + tool[T_UX], 0.0


#: the 2D engine's history layout and parameter slots for
#: :mod:`robobore.cutting.fe.engine.history` (forces and displacements x, y; the force by
#: tool face, six columns; the tip's x)
ENGINE2 = {"NDIM": 2, "N_SPLIT": 6, "N_TOOL_COLUMNS": 1, "T_FORCE": T_FX, "T_DISP": T_UX,
           "P_CFL": P_CFL, "P_DTMIN": P_DTMIN, "P_SAMPLE_DT": P_SAMPLE_DT, "P_TEND": P_TEND,
           "COUNT_STOPPED_STEP": 0}
_energy_totals = njit(sum_energies_py)
_njit_inline = partial(njit, inline="always")
#: the end of a step on the CPU (:func:`robobore.cutting.fe.engine.history.make_end_step`),
#: inlined into the loop: as a call it costs about 0.5 % of a step of the 2D contract config
#: (one thread, paired with the same loop inlined; ``benchmarks/bench_fe_before_after.py``)
_end_step = make_end_step(_njit_inline, ENGINE2, njit(tool_columns_py), _energy_totals)


@njit(inline="always")
def _energy_arrays(s):
    # the arrays ``es`` of sum_energies_py in the loop's state ``s`` (vz: unread in 2D)
    return (s.mass, s.vx, s.vy, s.vx, s.ie, s.plast, s.hge, s.alive, s.fric, s.pen, s.ero_ke,
            s.nwork)


#: the state arrays of the loop, in the order of ``FEState.kernel_args()``
CHUNK_ARGS = ("x", "y", "vx", "vy", "mass", "fixed", "ptr", "nel", "ncorner", "conn", "layer",
              "alive", "qs", "area0", "ie", "hge", "fex", "fey", "dte", "plast", "rate", "cfx",
              "cfy", "fric", "pen", "ndead", "ero_ke", "nwork", "mat", "prm", "tool", "en", "ist",
              "clock", "hacc", "hist", "enbr", "snodes", "xn", "yn", "buf", "twin",
              "tied", "tbuf", "gps", "fheat", "tcq", "ppair", "x0", "y0", "vbuf", "acls",
              "aflt", "bflag", "vslip")
#: the state of the loop's phases (numba reads the fields by name)
ChunkState = namedtuple("ChunkState", CHUNK_ARGS)


@njit(inline="always")
def _nodes(s, kin, dt, split):
    # node update and contact, the contact-force total in the fixed lane order, the force by
    # tool face
    cx, cy, tvx, tvy = kin
    x, y, cfx, cfy, prm = s.x, s.y, s.cfx, s.cfy, s.prm
    ncont = node_update(nodes_of(s), quads_of(s), out_of(s), contact_of(s), kin, prm, dt)
    fwx, fwy = contact_total(cfx, cfy)
    contact_split(cfx, cfy, x, y, (cx, cy, prm[P_NRX], prm[P_NRY], prm[P_NFX], prm[P_NFY]),
                  split)
    return fwx, fwy, 0.0, ncont


@njit(inline="always")
def _tool_step(s, fx, fy, fz, dt):
    return tool_step(s.tool, s.prm, fx, fy, dt)


@njit(inline="always")
def _remesh(s, step):
    # the tool-frame ALE pass every prm[P_RZ_EVERY] steps
    mat, prm = s.mat, s.prm
    rho_s = mat[jc.RHO] * prm[P_MS]
    if step % int(prm[P_RZ_EVERY]) == 0 and s.snodes.shape[0] > 0:
        rezone(nodes_of(s), quads_of(s), s.qs, ale_of(s), rho_s, prm[P_RZ_MAXMOVE],
               tool_geometry(prm), mat[jc.TROOM], prm[P_TCX] - prm[P_ALE_X0])


@njit(inline="always")
def _elements_q4r(s, dt):
    # the one-point quad with hourglass control
    return element_update(nodes_of(s), quads_of(s), s.qs, out_of(s), s.mat, s.prm, dt,
                          int(s.prm[P_EROSION]))


@njit(inline="always")
def _elements_bbar(s, dt):
    # the B-bar quad
    return element_update_bbar(nodes_of(s), quads_of(s), s.qs, out_of(s), s.gps, s.mat,
                               s.prm, dt, int(s.prm[P_EROSION]))


@njit(inline="always")
def _heat(s, step, t, dt):
    # conduction every prm[P_COND_EVERY] steps over the time accumulated since the last pass
    prm, mat = s.prm, s.mat
    prm[P_COND_ACC] += dt
    if step % int(prm[P_COND_EVERY]) == 0:
        conn, x, y, alive, enbr, tbuf = s.conn, s.x, s.y, s.alive, s.enbr, s.tbuf
        temp = s.qs[QS_TEMP]
        rcp = mat[jc.RHO] * mat[jc.CP]
        conduct(conn, x, y, alive, enbr, temp, tbuf, mat[jc.KCOND], rcp, prm[P_COND_ACC])
        if s.ppair.shape[0] > 0:
            parting_conduct(s.ppair, x, y, alive, s.tied, temp, tbuf, mat[jc.KCOND], rcp,
                            prm[P_COND_ACC])
        if prm[P_HC] > 0.0 or prm[P_FHEAT] > 0.0:
            tool_heat(nodes_of(s), quads_of(s), s.qs, contact_of(s), enbr, s.fheat, tbuf,
                      s.tcq, rcp, (prm[P_HC], prm[P_FHEAT], prm[P_TTOOL], prm[P_COND_ACC]))
        prm[P_COND_ACC] = 0.0


@njit(inline="always")
def _no_heat(s, step, t, dt):
    # adiabatic: no heat pass
    return None


_no_remesh = njit(inline="always")(no_remesh_py)


def _bind(name, elements, remesh, heat):
    # the step loop of robobore.cutting.fe.engine.step_loop bound to the 2D phases
    return make_chunk_loop(name=name, state=ChunkState, n_split=ENGINE2["N_SPLIT"],
                           energy_arrays=_energy_arrays, energy_totals=_energy_totals,
                           phases=StepPhases(kinematics=tool_kinematics, nodes=_nodes,
                                             tool_step=_tool_step, elements=elements,
                                             heat=heat, end_step=_end_step, remesh=remesh))


@dataclass(frozen=True)
class Phases:
    """The model choices one compiled 2D loop is specialised for: ``element`` "q4r" (one-point
    quad) or "bbar" (B-bar quad); ``tool_frame``: the tool-frame ALE pass every
    ``prm[P_RZ_EVERY]`` steps (one-point quad only); ``conduction``: the heat pass every
    ``prm[P_COND_EVERY]`` steps (>= 1), else adiabatic."""

    element: Literal["q4r", "bbar"] = "q4r"
    tool_frame: bool = False
    conduction: bool = False


def phases_of(spec: Any) -> Phases:
    """The :class:`Phases` of a :class:`~robobore.cutting.fe.config.spec.ModelSpec`: the
    element from ``spec.frame.element``'s type, the ALE pass for a ``ToolFrame``, the heat
    pass for ``Conduction``."""
    from robobore.cutting.fe.config.spec import BBarQuad, Conduction, ToolFrame

    return Phases(element="bbar" if isinstance(spec.frame.element, BBarQuad) else "q4r",
                  tool_frame=isinstance(spec.frame, ToolFrame),
                  conduction=isinstance(spec.thermal, Conduction))


# one loop per choice, each under its own name (step_loop.make_chunk_loop)
_loop_q4r = _bind("loop2_q4r", _elements_q4r, _no_remesh, _no_heat)
_loop_q4r_heat = _bind("loop2_q4r_heat", _elements_q4r, _no_remesh, _heat)
_loop_bbar = _bind("loop2_bbar", _elements_bbar, _no_remesh, _no_heat)
_loop_bbar_heat = _bind("loop2_bbar_heat", _elements_bbar, _no_remesh, _heat)
_loop_ale = _bind("loop2_ale", _elements_q4r, _remesh, _no_heat)
_loop_ale_heat = _bind("loop2_ale_heat", _elements_q4r, _remesh, _heat)


@njit(cache=True)
def run_chunk_q4r(n_steps, *arrays):
    """:func:`run_chunk_for` ``Phases("q4r")``: workpiece frame, one-point quad, adiabatic."""
    return _loop_q4r(n_steps, *arrays)


@njit(cache=True)
def run_chunk_q4r_heat(n_steps, *arrays):
    """Workpiece frame, one-point quad, conduction."""
    return _loop_q4r_heat(n_steps, *arrays)


@njit(cache=True)
def run_chunk_bbar(n_steps, *arrays):
    """Workpiece frame, B-bar quad, adiabatic."""
    return _loop_bbar(n_steps, *arrays)


@njit(cache=True)
def run_chunk_bbar_heat(n_steps, *arrays):
    """Workpiece frame, B-bar quad, conduction."""
    return _loop_bbar_heat(n_steps, *arrays)


@njit(cache=True)
def run_chunk_ale(n_steps, *arrays):
    """Tool frame (the ALE pass), one-point quad, adiabatic."""
    return _loop_ale(n_steps, *arrays)


@njit(cache=True)
def run_chunk_ale_heat(n_steps, *arrays):
    """Tool frame (the ALE pass), one-point quad, conduction."""
    return _loop_ale_heat(n_steps, *arrays)


#: the compiled chunk function of each buildable :class:`Phases`
RUN_CHUNK = {
    Phases("q4r", False, False): run_chunk_q4r,
    Phases("q4r", False, True): run_chunk_q4r_heat,
    Phases("bbar", False, False): run_chunk_bbar,
    Phases("bbar", False, True): run_chunk_bbar_heat,
    Phases("q4r", True, False): run_chunk_ale,
    Phases("q4r", True, True): run_chunk_ale_heat,
}


def run_chunk_for(phases: Phases):
    """The compiled chunk function ``run_chunk(n_steps, *arrays)`` of ``phases``: advances up
    to ``n_steps`` central-difference steps (the whole loop in numba) of the state arrays
    ``FEState.kernel_args()`` (:data:`CHUNK_ARGS`) -- node update and contact, tool, the
    tool-frame ALE pass (tool frame only), the chosen element, conduction with the
    parting-line edges and the thermal contact (conduction only) -- each step ending with
    the end of step of :mod:`robobore.cutting.fe.engine.history` (stop checks, time-averaged
    histories, samples): stops early with ``ist[I_STATUS]`` = STATUS_DONE at ``prm[P_TEND]``
    or an instability status. Returns the number of steps taken. ValueError for a choice
    with no loop (the tool frame with the B-bar element)."""
    try:
        return RUN_CHUNK[phases]
    except KeyError:
        raise ValueError(f"no compiled 2D loop for {phases} (the tool frame has the "
                         "one-point quad only)") from None


def step_for(spec: Any):
    """The compiled chunk function of a :class:`~robobore.cutting.fe.config.spec.ModelSpec`
    (:func:`run_chunk_for` of :func:`phases_of`)."""
    return run_chunk_for(phases_of(spec))
