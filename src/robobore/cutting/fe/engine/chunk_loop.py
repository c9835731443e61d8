"""The compiled time-step loop of the plane-strain engine (:func:`run_chunk`): element,
node and tool updates, heat passes and the ALE pass, a chunk of steps at a time; each step ends
with the engines' shared end of step (:mod:`robobore.cutting.fe.engine.history`: stop conditions,
time-averaged histories, history samples with the energy totals), bound here to the 2D
layout (:data:`ENGINE2`, :func:`tool_columns_py`, :data:`sum_energies_py`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from robobore.cutting.fe.ale.rezone import rezone
from robobore.cutting.fe.engine.history import bind_end_step, energy_totals_py
from robobore.cutting.fe.engine.layout import (
    E_EXT,
    ELEM_Q4BBAR,
    I_STEP,
    P_ALE_X0,
    P_CFL,
    P_COND_ACC,
    P_COND_EVERY,
    P_DTMIN,
    P_ELEM,
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

#: the energy totals (:func:`robobore.cutting.fe.engine.history.energy_totals_py` in 2D) of the
#: state arrays ``es`` = (mass, vx, vy, vx, ie, plast, hge, alive, fric, pen, ero_ke, nwork) into
#: ``en`` [J/m] (serial, a fixed order)
sum_energies_py = jc.rebind(energy_totals_py, NDIM=2)


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
#: the end of a step on the CPU (:func:`robobore.cutting.fe.engine.history.end_step_py`)
_end_step = bind_end_step(njit, ENGINE2, njit(tool_columns_py), njit(sum_energies_py))


@njit(cache=True)
def run_chunk(n_steps, x, y, vx, vy, mass, fixed, ptr, nel, ncorner, conn, layer, alive,
              sdx, sdy, sdz, sdxy, pres, eps_p, temp, dmg, qhx, qhy, area0, ie, hge, fex, fey,
              dte, plast, rate, cfx, cfy, fric, pen, ndead, ero_ke, nwork, mat, prm, tool,
              en, ist, clock, hacc, hist, enbr, snodes, xn, yn, buf, twin, tied, tbuf,
              gps, fheat, tcq, ppair, x0, y0, vbuf, acls, aflt, bflag, vslip):
    """Advance up to ``n_steps`` central-difference steps (the whole loop in numba).

    ``clock`` = [t, dt, t_acc] (time [s], current step [s], time accumulated in the current
    sample interval). Each step ends with :func:`robobore.cutting.fe.engine.history.end_step_py`
    (stop checks, time-averaged histories, samples): stops early with ``ist[I_STATUS]`` =
    STATUS_DONE at ``prm[P_TEND]`` or an instability status. Returns the number of steps
    taken.
    """
    erosion = int(prm[P_EROSION])
    bbar = int(prm[P_ELEM]) == ELEM_Q4BBAR
    rz_every = int(prm[P_RZ_EVERY])
    rho_s = mat[jc.RHO] * prm[P_MS]
    fsplit = np.zeros(6)
    es = (mass, vx, vy, vx, ie, plast, hge, alive, fric, pen, ero_ke, nwork)
    taken = 0
    for _s in range(n_steps):
        dt = clock[1]
        cx, cy, tvx, tvy = tool_kinematics(tool, prm)
        ncont = node_update(x, y, vx, vy, mass, fixed, ptr, nel, ncorner, alive, area0, fex,
                            fey, cfx, cfy, fric, pen, ndead, ero_ke, nwork, cx, cy, tvx, tvy,
                            prm, dt, twin, tied, vslip)
        fwx, fwy = contact_total(cfx, cfy)
        contact_split(cfx, cfy, x, y, cx, cy, prm[P_NRX], prm[P_NRY], prm[P_NFX], prm[P_NFY],
                      fsplit)
        en[E_EXT] += tool_step(tool, prm, fwx, fwy, dt)
        if rz_every > 0 and ist[I_STEP] % rz_every == 0 and snodes.shape[0] > 0:
            rezone(x, y, vx, vy, mass, conn, alive, ptr, nel, enbr, snodes, xn, yn, buf, sdx,
                   sdy, sdz, sdxy, pres, eps_p, temp, dmg, qhx, qhy, area0, rho_s,
                   prm[P_RZ_MAXMOVE], x0, y0, vbuf, tool_geometry(prm), acls, aflt, bflag,
                   mat[jc.TROOM], prm[P_TCX] - prm[P_ALE_X0])
        if bbar:
            dtmin, bad = element_update_bbar(conn, x, y, vx, vy, alive, layer, sdx, sdy, sdz,
                                             sdxy, pres, eps_p, temp, dmg, gps, area0, ie, fex,
                                             fey, dte, plast, rate, mat, prm, dt, erosion)
        else:
            dtmin, bad = element_update(conn, x, y, vx, vy, alive, layer, sdx, sdy, sdz, sdxy,
                                        pres, eps_p, temp, dmg, qhx, qhy, area0, ie, hge, fex,
                                        fey, dte, plast, rate, mat, prm, dt, erosion)
        cond_every = int(prm[P_COND_EVERY])
        if cond_every > 0:
            prm[P_COND_ACC] += dt
            if ist[I_STEP] % cond_every == 0:
                rcp = mat[jc.RHO] * mat[jc.CP]
                conduct(conn, x, y, alive, enbr, temp, tbuf, mat[jc.KCOND], rcp,
                        prm[P_COND_ACC])
                if ppair.shape[0] > 0:
                    parting_conduct(ppair, x, y, alive, tied, temp, tbuf, mat[jc.KCOND], rcp,
                                    prm[P_COND_ACC])
                if prm[P_HC] > 0.0 or prm[P_FHEAT] > 0.0:
                    tool_heat(conn, x, y, ptr, nel, ncorner, alive, enbr, cfx, cfy, fric,
                              fheat, temp, tbuf, tcq, rcp, prm[P_HC], prm[P_FHEAT],
                              prm[P_TTOOL], prm[P_COND_ACC])
                prm[P_COND_ACC] = 0.0
        taken += 1
        if not _end_step(dt, bad, dtmin, fwx, fwy, 0.0, ncont, fsplit, ist, clock, prm, tool,
                         en, hacc, hist, es):
            return taken
    return taken
