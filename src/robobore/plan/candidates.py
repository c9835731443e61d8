"""Candidate postures for a bore: tool-axis rotation grid x closed-form IK branches, verified.

Each inverse-kinematics solution is checked by forward kinematics (tool point within
:data:`POSITION_TOL_M`, tool axis within :data:`AXIS_TOL_DEG` of the bore axis), the joint
limits and a singularity margin (:func:`singularity_measure`); see
:mod:`robobore.plan.posture`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.errors import ConfigError

POSITION_TOL_M = 1e-4
AXIS_TOL_DEG = 0.05


def boring_frame(axis: np.ndarray, x_hint: Any = None) -> np.ndarray:
    """Columns X (horizontal, vertical x Z), Y = Z x X, Z = the bore axis (a unit vector; a
    vertical one takes X from the base x axis, ``x_hint`` from the hint projected,
    :func:`robobore.robot.stiffness.process_frame`); the robot stage's ``"boring"`` frame of
    a tool whose z axis is the bore axis."""
    from robobore.robot.stiffness import process_frame

    z = np.asarray(axis, float) / np.linalg.norm(axis)
    R = np.zeros((3, 3))
    R[:, 2] = z
    return process_frame(R, "boring", x_hint=x_hint)


def rotation_of(Rb: np.ndarray, R_flange: np.ndarray) -> float:
    """Tool-axis rotation [deg] of a flange orientation: angle of flange x in the boring XY."""
    x = Rb.T @ R_flange[:, 0]
    return math.degrees(math.atan2(x[1], x[0]))


def reach_length(robot: Any) -> float:
    d, a, _, _ = robot.dh_arrays
    return float(np.sum(np.abs(a)) + np.sum(np.abs(d)))


def singularity_measure(robot: Any, J: np.ndarray) -> np.ndarray:
    """Smallest singular value of the Jacobian with translational rows / reach, (n,)."""
    Jn = J.copy()
    Jn[:, :3, :] /= reach_length(robot)
    return np.linalg.svd(Jn, compute_uv=False)[:, -1]


@dataclass
class Candidates:
    rotation_deg: np.ndarray  # (n,)
    branch: np.ndarray  # (n,) int
    q_rad: np.ndarray  # (n, nj)
    position_error_m: np.ndarray
    axis_error_deg: np.ndarray
    singularity: np.ndarray
    n_tried: int
    n_reached: int
    n_in_limits: int


def enumerate_candidates(robot: Any, point: np.ndarray, axis: np.ndarray, tcp: np.ndarray,
                         rotations_deg: np.ndarray, margin: float,
                         x_hint: Any = None) -> Candidates:
    """Every verified posture on the rotation grid x IK branches (see module docstring)."""
    from robobore.plan.ik import N_BRANCHES, ik_all, is_supported
    from robobore.robot.kinematics import fk_jacobian

    if not is_supported(robot):
        raise ConfigError(f"robot '{robot.name}' is not a 6R arm with a spherical wrist; the "
                          "posture planner's closed-form inverse kinematics needs one",
                          file=robot.file or None, field="robot",
                          expected="D-H data of the Pieper class (docs/plan.md)")
    Rb = boring_frame(axis, x_hint)
    psi = np.radians(rotations_deg)
    c, s = np.cos(psi), np.sin(psi)
    Rz = np.zeros((psi.size, 3, 3))
    Rz[:, 0, 0], Rz[:, 0, 1], Rz[:, 1, 0], Rz[:, 1, 1], Rz[:, 2, 2] = c, -s, s, c, 1.0
    Rf = np.einsum("ij,njk->nik", Rb, Rz)
    pf = point[None, :] - np.einsum("nij,j->ni", Rf, tcp)
    Q, ok = ik_all(robot, Rf, pf)
    reached = np.all(np.isfinite(Q), axis=2)
    rot = np.repeat(np.asarray(rotations_deg, float), N_BRANCHES)
    br = np.tile(np.arange(N_BRANCHES), psi.size)
    Qf = Q.reshape(-1, robot.n_joints)
    keep = ok.reshape(-1)
    n_reached = int(reached.sum())
    n_lim = int(keep.sum())
    Qk = Qf[keep]
    if Qk.shape[0] == 0:
        e = np.zeros(0)
        return Candidates(rot[keep], br[keep], Qk, e, e, e, Qf.shape[0], n_reached, n_lim)
    T, J = fk_jacobian(robot, Qk, tcp)
    pos_err = np.linalg.norm(T[:, :3, 3] - point[None, :], axis=1)
    cosang = np.clip(T[:, :3, 2] @ axis, -1, 1)
    ax_err = np.degrees(np.arccos(cosang))
    sing = singularity_measure(robot, J)
    good = (pos_err <= POSITION_TOL_M) & (ax_err <= AXIS_TOL_DEG) & (sing >= margin)
    return Candidates(rot[keep][good], br[keep][good], Qk[good], pos_err[good], ax_err[good],
                      sing[good], Qf.shape[0], n_reached, n_lim)


def rotation_grid(step_deg: float, anchor_deg: float = 0.0) -> np.ndarray:
    n = max(1, int(round(360.0 / step_deg)))
    g = anchor_deg + step_deg * np.arange(n)
    return (g + 180.0) % 360.0 - 180.0


__all__ = ["POSITION_TOL_M", "AXIS_TOL_DEG", "Candidates", "boring_frame", "rotation_of",
           "reach_length", "singularity_measure", "enumerate_candidates", "rotation_grid"]
