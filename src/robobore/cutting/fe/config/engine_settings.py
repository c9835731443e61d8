"""The config's solver, thermal and friction settings written into an engine's parameter
vector (shared by the 2D and 3D engines: each passes its kernel module, whose ``P_*``
indices the settings go to).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robobore.material import Material


def apply_solver_settings(p: np.ndarray, s: Any, kernels: Any) -> np.ndarray:
    """Write the solver settings shared by the 2D and 3D configs into ``p`` (returned).

    ``s`` is a ``[solver]`` section (2D or 3D), ``kernels`` the engine's kernel module (its
    ``P_*`` indices and ``ERODE_*`` codes).
    """
    k = kernels
    p[k.P_CFL] = s.cfl
    p[k.P_MS] = s.mass_scaling
    p[k.P_HGV] = s.hourglass_viscous
    p[k.P_HGS] = s.hourglass_stiffness
    p[k.P_BV1] = s.bulk_viscosity_linear
    p[k.P_BV2] = s.bulk_viscosity_quadratic
    p[k.P_DIST] = s.distortion_limit
    p[k.P_DT_ERODE] = -s.erode_time_step_fraction
    p[k.P_EROSION] = {"none": k.ERODE_NONE, "layer": k.ERODE_LAYER}[s.erosion]
    if hasattr(k, "P_ELEM"):
        p[k.P_ELEM] = {"q4r": k.ELEM_Q4R, "q4_bbar": k.ELEM_Q4BBAR}[s.element]
    return p


def apply_thermal_settings(p: np.ndarray, solver: Any, contact: Any, material: Material,
                           kernels: Any) -> np.ndarray:
    """Write the heat conduction (``solver.heat_conduction``, ``conduction_interval``) and the
    thermal contact with the tool (``contact.thermal_conductance_W_per_m2K``,
    ``friction_heat_fraction``, ``tool_temperature_K``; None: the material's room
    temperature) into ``p`` (returned); shared by the 2D and 3D engines."""
    k = kernels
    p[k.P_COND_EVERY] = solver.conduction_interval if solver.heat_conduction else 0
    p[k.P_HC] = contact.thermal_conductance_W_per_m2K
    p[k.P_FHEAT] = contact.friction_heat_fraction
    p[k.P_TTOOL] = (material.T_room if contact.tool_temperature_K is None
                    else contact.tool_temperature_K)
    return p


def apply_friction_settings(p: np.ndarray, contact: Any, vc_m_per_min: float,
                            kernels: Any) -> np.ndarray:
    """Write the friction of a ``[contact]`` section into ``p`` (returned); shared by the 2D
    and 3D engines.

    ``contact`` is a :class:`robobore.cutting.fe.config.orthogonal.ContactSection` (or the 3D
    engine's, built on it), ``vc_m_per_min`` the cutting speed, ``kernels`` the engine's kernel
    module (its ``P_MU``, ``P_TAU``, ``P_MUTAB_*`` and ``P_SLIP_TAU`` slots). ``P_MU``: the
    constant, or the table at the cutting speed; with ``friction_velocity = "sliding"`` the table
    goes into the ``P_MUTAB_*`` slots (velocities in m/s) and every contact node reads it at its own
    sliding speed, filtered over the time the tool takes to travel ``sliding_filter_um``.
    """
    k = kernels
    p[k.P_MU] = contact.coefficient_at(vc_m_per_min)
    if contact.friction == "table" and contact.friction_velocity == "sliding":
        tv, tmu = contact.table()
        p[k.P_MUTAB_N] = tv.size
        p[k.P_MUTAB_V:k.P_MUTAB_V + tv.size] = tv / 60.0
        p[k.P_MUTAB_MU:k.P_MUTAB_MU + tv.size] = tmu
        p[k.P_SLIP_TAU] = contact.sliding_filter_um * 1e-6 / (vc_m_per_min / 60.0)
    p[k.P_TAU] = contact.shear_limit_MPa * 1e6
    return p
