"""The config's solver, thermal and friction settings written into an engine's parameter
vector (shared by the 2D and 3D engines: each passes its kernel module, whose ``P_*``
indices the settings go to). The model-choice slots are written by the typed model specs
(:mod:`robobore.cutting.fe.config.spec`: ``ModelSpec.write_prm``, for the orthogonal model, the
boring model and the 3D slab cross-check);
:func:`apply_numerics` writes the numerics every model uses; :func:`apply_friction_settings`
and :func:`apply_thermal_settings` write one section's friction or heat through the spec's
``write_friction`` / ``write_thermal``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robobore.cutting.fe.config.spec import write_friction, write_thermal
from robobore.cutting.fe.config.spec_build import friction_spec, thermal_spec
from robobore.material.library import Material


def apply_numerics(p: np.ndarray, s: Any, layout: Any) -> np.ndarray:
    """Write the time integration and element numerics of a ``[solver]`` section (2D or 3D)
    that every model variant uses into ``p`` (returned): CFL fraction, mass scaling, bulk
    viscosity, distortion limit."""
    k = layout
    p[k.P_CFL] = s.cfl
    p[k.P_MS] = s.mass_scaling
    p[k.P_BV1] = s.bulk_viscosity_linear
    p[k.P_BV2] = s.bulk_viscosity_quadratic
    p[k.P_DIST] = s.distortion_limit
    return p


def apply_thermal_settings(p: np.ndarray, solver: Any, contact: Any, material: Material,
                           layout: Any) -> np.ndarray:
    """Write the heat conduction (``solver.heat_conduction``, ``conduction_interval``) and the
    thermal contact with the tool (``contact.thermal_conductance_W_per_m2K``,
    ``friction_heat_fraction``, ``tool_temperature_K``; None: the material's room
    temperature) into ``p`` (returned) through the spec's thermal model."""
    return write_thermal(p, thermal_spec(solver, contact, material), layout)


def apply_friction_settings(p: np.ndarray, contact: Any, vc_m_per_min: float,
                            layout: Any) -> np.ndarray:
    """Write the friction of a ``[contact]`` section at the cutting speed ``vc_m_per_min``
    into ``p`` (returned) through the spec's friction model: ``P_MU`` the constant or the
    table at the cutting speed; with ``friction_velocity = "sliding"`` the table in the
    ``P_MUTAB_*`` slots (velocities in m/s), read by every contact node at its own sliding
    speed filtered over the time the tool takes to travel ``sliding_filter_um``."""
    return write_friction(p, friction_spec(contact, vc_m_per_min), layout, vc_m_per_min)
