"""Index layout of the 2D engine's small state arrays (module constants).

``prm`` float64 parameters (``P_*``), ``tool`` float64 tool state (``T_*``), ``en`` float64
energy accumulators (``E_*``), ``ist`` int64 counters/status (``I_*``, ``STATUS_*``), ``hist``
(n_samples, N_HIST) histories (``H_*``, the column order of
:mod:`robobore.cutting.fe.engine.history`); element formulations (``ELEM_*``),
per-Gauss-point state of the B-bar element (``G_*``), damage erosion (``ERODE_*``).
"""

from __future__ import annotations

# --- prm indices (float parameters)
P_CFL, P_MS, P_HGV, P_HGS, P_BV1, P_BV2, P_DIST = 0, 1, 2, 3, 4, 5, 6
P_MU, P_TAU, P_PEN, P_R = 7, 8, 9, 10
P_NRX, P_NRY, P_NFX, P_NFY = 11, 12, 13, 14
P_VC, P_KX, P_KY, P_CX, P_CY, P_MX, P_MY, P_WIDTH = 15, 16, 17, 18, 19, 20, 21, 22
P_SAMPLE_DT, P_DTMIN, P_TEND, P_EROSION, P_SUPPORT = 23, 24, 25, 26, 27
#: tool-frame ALE: steps between ALE passes (0: none, the Lagrangian workpiece frame) and the
#: largest node move of a pass, as a fraction of the local element size
P_RZ_EVERY, P_RZ_MAXMOVE, P_DT_ERODE = 28, 29, 30
#: separation gate [m] (a layer element erodes only with a node within this distance of the
#: tool surface; < 0: no gate) and the current tool edge centre (set every step)
P_GATE, P_TCX, P_TCY = 31, 32, 33
#: heat conduction: steps between conduction updates (0: adiabatic), time accumulated since
#: the last one [s]
P_COND_EVERY, P_COND_ACC = 34, 35
#: element formulation: ELEM_Q4R (one-point quad + hourglass control) or ELEM_Q4BBAR (2x2
#: Gauss points with mean-dilatation B-bar, no hourglass modes)
P_ELEM = 36
#: thermal contact with the tool (heat conduction runs only): interface conductance
#: [W/(m^2 K)] to a tool held at ``P_TTOOL`` [K], and the fraction of the frictional
#: dissipation that heats the workpiece (the rest goes into the tool)
P_HC, P_FHEAT, P_TTOOL = 37, 38, 39
#: tool-frame ALE: the tool edge centre's x at the start [m] (the mesh travels with the tool)
P_ALE_X0 = 40
#: viscous contact damping, fraction of the contact spring's critical damping
P_CDAMP = 41
#: friction vs sliding velocity (``contact.friction_velocity = "sliding"``): number of table
#: points (0: the constant ``P_MU``), then MU_TABLE_MAX velocities [m/s] (increasing) and
#: MU_TABLE_MAX coefficients; each contact node uses the table at its own sliding speed
P_MUTAB_N = 42
MU_TABLE_MAX = 8
P_MUTAB_V = 43
P_MUTAB_MU = P_MUTAB_V + MU_TABLE_MAX
#: time constant [s] of the filter on the sliding speed the friction table is read at
P_SLIP_TAU = P_MUTAB_MU + MU_TABLE_MAX
N_PRM = P_SLIP_TAU + 1
ELEM_Q4R, ELEM_Q4BBAR = 0, 1
#: per-Gauss-point state of the B-bar element: deviatoric stress xx, yy, zz, xy, plastic strain
G_SX, G_SY, G_SZ, G_SXY, G_EPS = 0, 1, 2, 3, 4
N_GPS = 5
#: damage erosion: none, or the elements of the separation layer
ERODE_NONE, ERODE_LAYER = 0, 1
# --- tool state: guide x, y; displacement u, v; velocity of displacement; force
T_GX, T_GY, T_UX, T_UY, T_VUX, T_VUY, T_FX, T_FY = 0, 1, 2, 3, 4, 5, 6, 7
N_TOOL = 8
# --- energies
E_EXT, E_KIN, E_INT, E_PLAST, E_HG, E_FRIC, E_NODEWORK, E_ERODED, E_EROKE = range(9)
N_EN = 9
# --- int state
I_STEP, I_SAMPLE, I_STATUS, I_ERODED_DAMAGE, I_ERODED_DIST, I_BADELEM = 0, 1, 2, 3, 4, 5
N_IST = 6
STATUS_OK, STATUS_NONFINITE, STATUS_DT_COLLAPSE, STATUS_DONE, STATUS_INVERTED = 0, 1, 2, 3, 4
STATUS_NO_ELEMENTS = 5
# --- history columns, in the order of robobore.cutting.fe.engine.history: the time [s]; the time
# averages over each sample interval (force on the tool [N/m], tool support displacement [m],
# contact nodes, then the force on the tool by face -- rake, edge arc, flank, x and y [N/m]);
# the tool tip's x [m]; the energies at the interval's end [J/m]
H_T, H_FX, H_FY, H_UX, H_UY, H_NCONT = range(6)
H_FX_RAKE, H_FY_RAKE, H_FX_EDGE, H_FY_EDGE, H_FX_FLANK, H_FY_FLANK = range(6, 12)
H_TIP_X = 12
H_EKIN, H_EINT, H_EPL, H_EHG, H_EFRIC, H_EEXT, H_EERO = range(13, 20)
N_HIST = 20
#: names of the tool faces of that split, in column order (summary ``force_by_face_N_per_mm``)
FACES = ("rake", "edge", "flank")
