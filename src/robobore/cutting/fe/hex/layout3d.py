"""Index layout of the 3D engine's parameter vector ``prm`` (module constants ``P_*``, the first
slot of each field of the one declaration :data:`PRM_FIELDS`, written out below it as literal
constants by :mod:`robobore.cutting.fe.engine.prm_layout`; ``N_PRM`` its length) and the
damage-erosion codes ``ERODE_*``; read by the hexahedron
(:mod:`robobore.cutting.fe.hex.element`), the scalar node and tool functions
(:mod:`robobore.cutting.fe.hex.scalar3d`) and the 3D loops on both devices.
"""

from __future__ import annotations

from robobore.cutting.fe.engine.layout import MU_TABLE_MAX

#: the parameter vector ``prm`` of a 3D model: (name, slots, meaning) in slot order; the
#: module constant of each name is its first slot, ``N_PRM`` the length (the block just
#: below, written by :func:`robobore.cutting.fe.engine.prm_layout.render`)
PRM_FIELDS: tuple[tuple[str, int, str], ...] = (
    # time integration, element numerics, numerical erosion
    ("P_CFL", 1, "fraction of the stable time step"),
    ("P_MS", 1, "mass scaling: density factor of the inertial mass"),
    ("P_HGV", 1, "Flanagan-Belytschko hourglass coefficient, viscous"),
    ("P_HGS", 1, "Flanagan-Belytschko hourglass coefficient, stiffness"),
    ("P_BV1", 1, "bulk viscosity, linear"),
    ("P_BV2", 1, "bulk viscosity, quadratic"),
    ("P_DIST", 1, "distortion erosion limit (volume ratio, corner Jacobian); 0: off"),
    ("P_DT_ERODE", 1, "time-step erosion: the smallest element step [s] (given as minus "
                      "the fraction of the initial one until the first step); 0: off"),
    ("P_DTMIN", 1, "smallest time step before the run stops [s]"),
    # contact
    ("P_MU", 1, "Coulomb coefficient (constant, or the table at the cutting speed)"),
    ("P_TAU", 1, "cap on the contact shear stress [Pa]"),
    ("P_PEN", 1, "penalty factor: normal stiffness = factor * nodal mass / dt^2"),
    ("P_CDAMP", 1, "viscous normal contact damping, fraction of the penalty spring's critical "
                   "damping (0: none)"),
    # insert geometry
    ("P_RN", 1, "nose radius [m]"),
    ("P_KAPPA", 1, "approach angle [rad]"),
    ("P_KEND", 1, "end-edge angle [rad]"),
    ("P_RAKE", 1, "rake angle [rad]"),
    ("P_CLR", 1, "clearance angle [rad]"),
    ("P_RE", 1, "edge radius [m]"),
    ("P_TANI", 1, "tan(inclination)"),
    ("P_TOOL", 1, "insert present (1) or not (0)"),
    # tool kinematics and support
    ("P_VC", 1, "cutting speed [m/s]"),
    ("P_VF", 1, "feed speed [m/s]"),
    ("P_RADIUS", 1, "radius of the bore [m]"),
    ("P_SUPPORT", 1, "tool on its support springs (1) or rigid (0)"),
    ("P_KX", 1, "support stiffness x [N/m]"),
    ("P_KY", 1, "support stiffness y [N/m]"),
    ("P_KZ", 1, "support stiffness z [N/m]"),
    ("P_CX", 1, "support damping x [N s/m]"),
    ("P_CY", 1, "support damping y [N s/m]"),
    ("P_CZ", 1, "support damping z [N s/m]"),
    ("P_MX", 1, "support mass x [kg]"),
    ("P_MY", 1, "support mass y [kg]"),
    ("P_MZ", 1, "support mass z [kg]"),
    # run control
    ("P_THETA0", 1, "bar angle at the start [rad]"),
    ("P_SAMPLE_DT", 1, "history sample interval [s]"),
    ("P_TEND", 1, "end time [s]"),
    ("P_EROSION", 1, "damage erosion: ERODE_NONE or ERODE_LAYER"),
    ("P_GATE", 1, "node splitting: a tied pair parts within this distance of the insert [m]"),
    # friction vs sliding speed (the 2D engine's fields)
    ("P_MUTAB_N", 1, "friction table points (0: the constant P_MU)"),
    ("P_MUTAB_V", MU_TABLE_MAX, "friction table velocities [m/s], increasing"),
    ("P_MUTAB_MU", MU_TABLE_MAX, "friction table coefficients"),
    ("P_SLIP_TAU", 1, "time constant of the filter on the sliding speed [s]"),
    # heat conduction (the 2D engine's model)
    ("P_COND_EVERY", 1, "steps between heat-conduction passes (0: adiabatic)"),
    ("P_COND_T", 1, "time of the last conduction pass [s]"),
    ("P_HC", 1, "insert interface conductance [W/(m^2 K)]"),
    ("P_FHEAT", 1, "fraction of the frictional dissipation that heats the workpiece"),
    ("P_TTOOL", 1, "insert temperature [K]"),
    # tool-frame ALE (mesh.frame = "tool"; robobore.cutting.fe.ale.rezone3d)
    ("P_RZ_EVERY", 1, "steps between tool-frame ALE passes (0: workpiece frame, no pass)"),
    ("P_RZ_MAXMOVE", 1, "largest node move of an ALE pass, fraction of the local element "
                        "size"),
    ("P_RZ_VEL", 1, "nodal velocity remap of an ALE pass (remap3d.VEL_TAYLOR or "
                    "VEL_MOMENTUM)"),
    ("P_ALE_X0", 1, "insert tip's x when the mesh was built [m] (the mesh's travel is "
                    "measured from it)"),
    ("P_ALE_Z0", 1, "insert tip's z when the mesh was built [m]"),
    ("P_MSF_DT", 1, "the stable step [s] the inertia factors give every element, renewed at "
                    "each ALE pass (0: no factors)"),
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
#: distortion erosion limit (volume ratio, corner Jacobian); 0: off
P_DIST = 6
#: time-step erosion: the smallest element step [s] (given as minus the fraction of the initial
#: one until the first step); 0: off
P_DT_ERODE = 7
#: smallest time step before the run stops [s]
P_DTMIN = 8
#: Coulomb coefficient (constant, or the table at the cutting speed)
P_MU = 9
#: cap on the contact shear stress [Pa]
P_TAU = 10
#: penalty factor: normal stiffness = factor * nodal mass / dt^2
P_PEN = 11
#: viscous normal contact damping, fraction of the penalty spring's critical damping (0: none)
P_CDAMP = 12
#: nose radius [m]
P_RN = 13
#: approach angle [rad]
P_KAPPA = 14
#: end-edge angle [rad]
P_KEND = 15
#: rake angle [rad]
P_RAKE = 16
#: clearance angle [rad]
P_CLR = 17
#: edge radius [m]
P_RE = 18
#: tan(inclination)
P_TANI = 19
#: insert present (1) or not (0)
P_TOOL = 20
#: cutting speed [m/s]
P_VC = 21
#: feed speed [m/s]
P_VF = 22
#: radius of the bore [m]
P_RADIUS = 23
#: tool on its support springs (1) or rigid (0)
P_SUPPORT = 24
#: support stiffness x [N/m]
P_KX = 25
#: support stiffness y [N/m]
P_KY = 26
#: support stiffness z [N/m]
P_KZ = 27
#: support damping x [N s/m]
P_CX = 28
#: support damping y [N s/m]
P_CY = 29
#: support damping z [N s/m]
P_CZ = 30
#: support mass x [kg]
P_MX = 31
#: support mass y [kg]
P_MY = 32
#: support mass z [kg]
P_MZ = 33
#: bar angle at the start [rad]
P_THETA0 = 34
#: history sample interval [s]
P_SAMPLE_DT = 35
#: end time [s]
P_TEND = 36
#: damage erosion: ERODE_NONE or ERODE_LAYER
P_EROSION = 37
#: node splitting: a tied pair parts within this distance of the insert [m]
P_GATE = 38
#: friction table points (0: the constant P_MU)
P_MUTAB_N = 39
#: friction table velocities [m/s], increasing (slots 40 .. 47)
P_MUTAB_V = 40
#: friction table coefficients (slots 48 .. 55)
P_MUTAB_MU = 48
#: time constant of the filter on the sliding speed [s]
P_SLIP_TAU = 56
#: steps between heat-conduction passes (0: adiabatic)
P_COND_EVERY = 57
#: time of the last conduction pass [s]
P_COND_T = 58
#: insert interface conductance [W/(m^2 K)]
P_HC = 59
#: fraction of the frictional dissipation that heats the workpiece
P_FHEAT = 60
#: insert temperature [K]
P_TTOOL = 61
#: steps between tool-frame ALE passes (0: workpiece frame, no pass)
P_RZ_EVERY = 62
#: largest node move of an ALE pass, fraction of the local element size
P_RZ_MAXMOVE = 63
#: nodal velocity remap of an ALE pass (remap3d.VEL_TAYLOR or VEL_MOMENTUM)
P_RZ_VEL = 64
#: insert tip's x when the mesh was built [m] (the mesh's travel is measured from it)
P_ALE_X0 = 65
#: insert tip's z when the mesh was built [m]
P_ALE_Z0 = 66
#: the stable step [s] the inertia factors give every element, renewed at each ALE pass (0: no
#: factors)
P_MSF_DT = 67
#: the length of ``prm``
N_PRM = 68
# --- end of the generated block ---
#: damage erosion: none, or the elements of the separation layer
ERODE_NONE, ERODE_LAYER = 0, 1
