"""Robot kinematics, stiffness model and joint-stiffness identification.

Public API (what the equivalent-model stage consumes):

* :func:`get_robot` / :class:`Robot`: D-H robots from the TOML library (or a user file).
* :func:`fk`, :func:`jacobian`, :func:`fk_jacobian`: vectorised kinematics (SI units).
* :func:`directional_stiffness_xyz`: ``{"x", "y", "z"}`` stiffness in N/m at a posture, in
  the tool / base / boring / user frame.
* :class:`JointStiffness` (``to_dict``/``from_dict``): identified or given joint stiffnesses.
* :func:`identify_joint_stiffness`: campaign -> :class:`StiffnessIdentification`.
* :func:`read_campaign`, :func:`write_campaign`, :func:`simulate_campaign`: campaign CSV and
  the virtual (synthetic) campaign generator.

Submodules are imported lazily so that ``import robobore.robot`` stays cheap.
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "Robot": "description",
    "get_robot": "description",
    "available_robots": "description",
    "fk": "kinematics",
    "jacobian": "kinematics",
    "fk_jacobian": "kinematics",
    "check_joint_limits": "description",
    "JointStiffness": "stiffness",
    "directional_stiffness_xyz": "stiffness",
    "stiffness_at": "stiffness",
    "compliance_matrix": "stiffness",
    "cartesian_stiffness": "stiffness",
    "complementary_stiffness": "stiffness",
    "process_frame": "stiffness",
    "identify_joint_stiffness": "identify",
    "StiffnessIdentification": "identify",
    "read_campaign": "campaign_io",
    "write_campaign": "campaign_io",
    "simulate_campaign": "campaign",
    "CampaignSpec": "campaign",
    "Campaign": "campaign",
    "TrackerNoise": "campaign",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        mod = importlib.import_module(f"robobore.robot.{_EXPORTS[name]}")
        return getattr(mod, name)
    raise AttributeError(f"module 'robobore.robot' has no attribute {name!r}")
