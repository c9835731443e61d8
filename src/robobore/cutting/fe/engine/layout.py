"""Index layout of the 2D engine's small state arrays (module constants).

``prm`` float64 parameters (``P_*``: the first slot of each field of the one declaration
:data:`PRM_FIELDS`, written out below it as literal constants by
:mod:`robobore.cutting.fe.engine.prm_layout`), ``tool`` float64 tool state
(``T_*``), ``en`` float64 energy accumulators (``E_*``), ``ist`` int64 counters/status
(``I_*``, ``STATUS_*``), ``hist`` (n_samples, N_HIST) histories (``H_*``, the column order of
:mod:`robobore.cutting.fe.engine.history`); per-Gauss-point state of the B-bar element
(``G_*``), damage erosion (``ERODE_*``).
"""

from __future__ import annotations

#: most points of a friction table read at the sliding speed (its ``P_MUTAB_*`` slots)
MU_TABLE_MAX = 8

#: the parameter vector ``prm`` of the 2D engine: (name, slots, meaning) in slot order; the
#: module constant of each name is its first slot, ``N_PRM`` the length (the block just
#: below, written by :func:`robobore.cutting.fe.engine.prm_layout.render`)
PRM_FIELDS: tuple[tuple[str, int, str], ...] = (
    # time integration and element numerics
    ("P_CFL", 1, "fraction of the stable time step"),
    ("P_MS", 1, "mass scaling: density factor of the inertial mass"),
    ("P_HGV", 1, "Flanagan-Belytschko hourglass coefficient, viscous"),
    ("P_HGS", 1, "Flanagan-Belytschko hourglass coefficient, stiffness"),
    ("P_BV1", 1, "bulk viscosity, linear"),
    ("P_BV2", 1, "bulk viscosity, quadratic"),
    ("P_DIST", 1, "distortion erosion limit (area ratio, corner Jacobian); 0: off"),
    # contact and friction
    ("P_MU", 1, "Coulomb coefficient (constant, or the table at the cutting speed)"),
    ("P_TAU", 1, "cap on the contact shear stress [Pa]"),
    ("P_PEN", 1, "penalty factor: normal stiffness = factor * nodal mass / dt^2"),
    # tool geometry
    ("P_R", 1, "edge radius [m]"),
    ("P_NRX", 1, "rake face normal, x"),
    ("P_NRY", 1, "rake face normal, y"),
    ("P_NFX", 1, "flank face normal, x"),
    ("P_NFY", 1, "flank face normal, y"),
    # tool motion and support
    ("P_VC", 1, "cutting speed [m/s] (the guide point moves at -vc along x)"),
    ("P_KX", 1, "support stiffness x [N/m per m of width]"),
    ("P_KY", 1, "support stiffness y [N/m per m of width]"),
    ("P_CX", 1, "support damping x [N s/m per m of width]"),
    ("P_CY", 1, "support damping y [N s/m per m of width]"),
    ("P_MX", 1, "support mass x [kg per m of width]"),
    ("P_MY", 1, "support mass y [kg per m of width]"),
    ("P_WIDTH", 1, "width of cut [m]"),
    # run control
    ("P_SAMPLE_DT", 1, "history sample interval [s]"),
    ("P_DTMIN", 1, "smallest time step before the run stops [s]"),
    ("P_TEND", 1, "end time [s]"),
    ("P_EROSION", 1, "damage erosion: ERODE_NONE or ERODE_LAYER"),
    ("P_SUPPORT", 1, "tool on its support springs (1) or rigid (0)"),
    # tool-frame ALE
    ("P_RZ_EVERY", 1, "steps between tool-frame ALE passes (0: none, the workpiece frame)"),
    ("P_RZ_MAXMOVE", 1, "largest node move of an ALE pass, fraction of the local size"),
    ("P_DT_ERODE", 1, "time-step erosion: the smallest element step [s] (given as minus "
                      "the fraction of the initial one until the first step); 0: off"),
    ("P_GATE", 1, "separation gate [m]: a layer element erodes, a tied pair parts, only "
                  "within this distance of the tool surface; < 0: no gate"),
    ("P_TCX", 1, "tool edge centre x [m] (set every step)"),
    ("P_TCY", 1, "tool edge centre y [m] (set every step)"),
    # heat
    ("P_COND_EVERY", 1, "steps between heat-conduction passes (0: adiabatic)"),
    ("P_COND_ACC", 1, "time accumulated since the last conduction pass [s]"),
    ("P_HC", 1, "tool interface conductance [W/(m^2 K)] (conduction runs)"),
    ("P_FHEAT", 1, "fraction of the frictional dissipation that heats the workpiece"),
    ("P_TTOOL", 1, "tool heat-sink temperature [K]"),
    ("P_ALE_X0", 1, "tool-frame ALE: the tool edge centre's x at the start [m]"),
    ("P_CDAMP", 1, "viscous contact damping, fraction of the penalty spring's critical"),
    # friction read at each node's sliding speed
    ("P_MUTAB_N", 1, "friction table points (0: the constant P_MU)"),
    ("P_MUTAB_V", MU_TABLE_MAX, "friction table velocities [m/s], increasing"),
    ("P_MUTAB_MU", MU_TABLE_MAX, "friction table coefficients"),
    ("P_SLIP_TAU", 1, "time constant of the filter on the sliding speed [s]"),
)
# --- generated from PRM_FIELDS by robobore.cutting.fe.engine.prm_layout: do not edit ---
#: fraction of the stable time step
P_CFL = 0
#: mass scaling: density factor of the inertial mass
P_MS = 1
#: Flanagan-Belytschko hourglass coefficient, viscous
P_HGV = 2
#: Flanagan-Belytschko hourglass coefficient, stiffness
P_HGS = 3
#: bulk viscosity, linear
P_BV1 = 4
#: bulk viscosity, quadratic
P_BV2 = 5
#: distortion erosion limit (area ratio, corner Jacobian); 0: off
P_DIST = 6
#: Coulomb coefficient (constant, or the table at the cutting speed)
P_MU = 7
#: cap on the contact shear stress [Pa]
P_TAU = 8
#: penalty factor: normal stiffness = factor * nodal mass / dt^2
P_PEN = 9
#: edge radius [m]
P_R = 10
#: rake face normal, x
P_NRX = 11
#: rake face normal, y
P_NRY = 12
#: flank face normal, x
P_NFX = 13
#: flank face normal, y
P_NFY = 14
#: cutting speed [m/s] (the guide point moves at -vc along x)
P_VC = 15
#: support stiffness x [N/m per m of width]
P_KX = 16
#: support stiffness y [N/m per m of width]
P_KY = 17
#: support damping x [N s/m per m of width]
P_CX = 18
#: support damping y [N s/m per m of width]
P_CY = 19
#: support mass x [kg per m of width]
P_MX = 20
#: support mass y [kg per m of width]
P_MY = 21
#: width of cut [m]
P_WIDTH = 22
#: history sample interval [s]
P_SAMPLE_DT = 23
#: smallest time step before the run stops [s]
P_DTMIN = 24
#: end time [s]
P_TEND = 25
#: damage erosion: ERODE_NONE or ERODE_LAYER
P_EROSION = 26
#: tool on its support springs (1) or rigid (0)
P_SUPPORT = 27
#: steps between tool-frame ALE passes (0: none, the workpiece frame)
P_RZ_EVERY = 28
#: largest node move of an ALE pass, fraction of the local size
P_RZ_MAXMOVE = 29
#: time-step erosion: the smallest element step [s] (given as minus the fraction of the initial
#: one until the first step); 0: off
P_DT_ERODE = 30
#: separation gate [m]: a layer element erodes, a tied pair parts, only within this distance of
#: the tool surface; < 0: no gate
P_GATE = 31
#: tool edge centre x [m] (set every step)
P_TCX = 32
#: tool edge centre y [m] (set every step)
P_TCY = 33
#: steps between heat-conduction passes (0: adiabatic)
P_COND_EVERY = 34
#: time accumulated since the last conduction pass [s]
P_COND_ACC = 35
#: tool interface conductance [W/(m^2 K)] (conduction runs)
P_HC = 36
#: fraction of the frictional dissipation that heats the workpiece
P_FHEAT = 37
#: tool heat-sink temperature [K]
P_TTOOL = 38
#: tool-frame ALE: the tool edge centre's x at the start [m]
P_ALE_X0 = 39
#: viscous contact damping, fraction of the penalty spring's critical
P_CDAMP = 40
#: friction table points (0: the constant P_MU)
P_MUTAB_N = 41
#: friction table velocities [m/s], increasing (slots 42 .. 49)
P_MUTAB_V = 42
#: friction table coefficients (slots 50 .. 57)
P_MUTAB_MU = 50
#: time constant of the filter on the sliding speed [s]
P_SLIP_TAU = 58
#: the length of ``prm``
N_PRM = 59
# --- end of the generated block ---
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
