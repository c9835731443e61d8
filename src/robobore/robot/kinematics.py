"""Serial-robot kinematics from standard Denavit-Hartenberg data.

Convention (standard / "distal" D-H, Spong-Hutchinson-Vidyasagar, *Robot Modeling and
Control*, 2006, sec. 3.2): the transform from frame i-1 to frame i is

    A_i = Rot_z(q_i + theta_offset_i) Trans_z(d_i) Trans_x(a_i) Rot_x(alpha_i)

and the flange frame is ``T = B A_1 ... A_n`` (``B`` = base transform, identity by default).
Joint i turns about the z-axis of frame i-1 through the origin of frame i-1.

Geometric Jacobian (Spong et al. eq. 4.52) at a tool point ``p`` (the TCP, given as an
offset in the flange frame): for a revolute joint i, column i is
``[z_{i-1} x (p - o_{i-1}); z_{i-1}]``, so that the twist ``[v_p; omega] = J dq`` (base frame).

The robot itself (D-H data, joint limits, link inertia, the robot library) is
:mod:`robobore.robot.description`; its public names are importable from here too.

Everything inside is SI (m, rad); degrees only at the edges (names ending in ``_deg``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit, prange

from robobore.errors import InputError
from robobore.robot.description import Robot

# --- kernels --------------------------------------------------------------------------------


@njit(cache=True, parallel=True)
def _fk_jac_kernel(q, d, a, alpha, off, base, tcp, T_out, J_out, Z, O):  # pragma: no cover
    """FK and geometric Jacobian for many postures (parallel over postures).

    q (n, nj); d, a, alpha, off (nj,); base (4, 4); tcp (3,) in the flange frame;
    outputs T_out (n, 4, 4) flange-with-TCP transforms, J_out (n, 6, nj);
    scratch Z, O (n, nj + 1, 3): joint axes and origins in the world frame.
    """
    n = q.shape[0]
    nj = q.shape[1]
    for k in prange(n):
        r00 = base[0, 0]
        r01 = base[0, 1]
        r02 = base[0, 2]
        r10 = base[1, 0]
        r11 = base[1, 1]
        r12 = base[1, 2]
        r20 = base[2, 0]
        r21 = base[2, 1]
        r22 = base[2, 2]
        px = base[0, 3]
        py = base[1, 3]
        pz = base[2, 3]
        Z[k, 0, 0] = r02
        Z[k, 0, 1] = r12
        Z[k, 0, 2] = r22
        O[k, 0, 0] = px
        O[k, 0, 1] = py
        O[k, 0, 2] = pz
        for i in range(nj):
            th = q[k, i] + off[i]
            ct = math.cos(th)
            st = math.sin(th)
            ca = math.cos(alpha[i])
            sa = math.sin(alpha[i])
            # A = [[ct, -st ca, st sa, a ct], [st, ct ca, -ct sa, a st], [0, sa, ca, d]]
            a00 = ct
            a01 = -st * ca
            a02 = st * sa
            a10 = st
            a11 = ct * ca
            a12 = -ct * sa
            a21 = sa
            a22 = ca
            ax = a[i] * ct
            ay = a[i] * st
            az = d[i]
            npx = r00 * ax + r01 * ay + r02 * az + px
            npy = r10 * ax + r11 * ay + r12 * az + py
            npz = r20 * ax + r21 * ay + r22 * az + pz
            n00 = r00 * a00 + r01 * a10
            n01 = r00 * a01 + r01 * a11 + r02 * a21
            n02 = r00 * a02 + r01 * a12 + r02 * a22
            n10 = r10 * a00 + r11 * a10
            n11 = r10 * a01 + r11 * a11 + r12 * a21
            n12 = r10 * a02 + r11 * a12 + r12 * a22
            n20 = r20 * a00 + r21 * a10
            n21 = r20 * a01 + r21 * a11 + r22 * a21
            n22 = r20 * a02 + r21 * a12 + r22 * a22
            r00, r01, r02 = n00, n01, n02
            r10, r11, r12 = n10, n11, n12
            r20, r21, r22 = n20, n21, n22
            px, py, pz = npx, npy, npz
            Z[k, i + 1, 0] = r02
            Z[k, i + 1, 1] = r12
            Z[k, i + 1, 2] = r22
            O[k, i + 1, 0] = px
            O[k, i + 1, 1] = py
            O[k, i + 1, 2] = pz
        # tool point
        tx = px + r00 * tcp[0] + r01 * tcp[1] + r02 * tcp[2]
        ty = py + r10 * tcp[0] + r11 * tcp[1] + r12 * tcp[2]
        tz = pz + r20 * tcp[0] + r21 * tcp[1] + r22 * tcp[2]
        T_out[k, 0, 0] = r00
        T_out[k, 0, 1] = r01
        T_out[k, 0, 2] = r02
        T_out[k, 1, 0] = r10
        T_out[k, 1, 1] = r11
        T_out[k, 1, 2] = r12
        T_out[k, 2, 0] = r20
        T_out[k, 2, 1] = r21
        T_out[k, 2, 2] = r22
        T_out[k, 0, 3] = tx
        T_out[k, 1, 3] = ty
        T_out[k, 2, 3] = tz
        T_out[k, 3, 0] = 0.0
        T_out[k, 3, 1] = 0.0
        T_out[k, 3, 2] = 0.0
        T_out[k, 3, 3] = 1.0
        for i in range(nj):
            zx = Z[k, i, 0]
            zy = Z[k, i, 1]
            zz = Z[k, i, 2]
            dx = tx - O[k, i, 0]
            dy = ty - O[k, i, 1]
            dz = tz - O[k, i, 2]
            J_out[k, 0, i] = zy * dz - zz * dy
            J_out[k, 1, i] = zz * dx - zx * dz
            J_out[k, 2, i] = zx * dy - zy * dx
            J_out[k, 3, i] = zx
            J_out[k, 4, i] = zy
            J_out[k, 5, i] = zz


#: Same kernel compiled without threads: for a few postures the parallel launch costs more
#: than the work (milliseconds on a loaded machine vs microseconds).
_fk_jac_kernel_serial = njit(cache=True)(_fk_jac_kernel.py_func)
PARALLEL_MIN_POSTURES = 256


def _kernel(n: int):
    return _fk_jac_kernel if n >= PARALLEL_MIN_POSTURES else _fk_jac_kernel_serial


def _prep(robot: Robot, q_rad: Any, tcp_m: Any) -> tuple[np.ndarray, bool, np.ndarray]:
    q = np.asarray(q_rad, dtype=np.float64)
    single = q.ndim == 1
    q2 = np.ascontiguousarray(np.atleast_2d(q))
    if q2.ndim != 2 or q2.shape[1] != robot.n_joints:
        raise InputError(
            f"joint array has shape {q.shape}",
            expected=f"(n_postures, {robot.n_joints}) or ({robot.n_joints},) angles in rad",
        )
    tcp = np.zeros(3) if tcp_m is None else np.asarray(tcp_m, dtype=np.float64).reshape(3)
    return q2, single, np.ascontiguousarray(tcp)


def fk_jacobian(
    robot: Robot, q_rad: Any, tcp_m: Any = None
) -> tuple[np.ndarray, np.ndarray]:
    """Tool transform and geometric Jacobian, vectorised over postures.

    Parameters
    ----------
    q_rad: (n_joints,) or (n, n_joints) joint angles, rad.
    tcp_m: (3,) tool point in the flange frame, m (default: flange origin).

    Returns
    -------
    T: (4, 4) or (n, 4, 4) world <- tool transform (rotation = flange orientation, position
       = tool point), m.
    J: (6, n_joints) or (n, 6, n_joints) geometric Jacobian at the tool point, rows
       (v_x, v_y, v_z [m/rad], omega_x, omega_y, omega_z [rad/rad]) in the world frame.
    """
    q, single, tcp = _prep(robot, q_rad, tcp_m)
    d, a, al, off = robot.dh_arrays
    n, nj = q.shape
    T = np.empty((n, 4, 4))
    J = np.empty((n, 6, nj))
    Z = np.empty((n, nj + 1, 3))
    O = np.empty((n, nj + 1, 3))
    _kernel(n)(q, d, a, al, off, np.ascontiguousarray(robot.base), tcp, T, J, Z, O)
    if single:
        return T[0], J[0]
    return T, J


def fk(robot: Robot, q_rad: Any, tcp_m: Any = None) -> np.ndarray:
    """World <- tool transform, (4, 4) or (n, 4, 4); see :func:`fk_jacobian`."""
    return fk_jacobian(robot, q_rad, tcp_m)[0]


def jacobian(robot: Robot, q_rad: Any, tcp_m: Any = None) -> np.ndarray:
    """Geometric Jacobian at the tool point, (6, nj) or (n, 6, nj); see :func:`fk_jacobian`."""
    return fk_jacobian(robot, q_rad, tcp_m)[1]


def joint_frames(robot: Robot, q_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Joint axes ``z_{i-1}`` and origins ``o_{i-1}`` (world frame) for one posture.

    Returns (Z, O), each (n_joints + 1, 3): row i is frame i (row 0 the base frame, row n the
    flange frame). Joint i+1 turns about Z[i] through O[i].
    """
    q, _, tcp = _prep(robot, q_rad, None)
    d, a, al, off = robot.dh_arrays
    nj = robot.n_joints
    T = np.empty((1, 4, 4))
    J = np.empty((1, 6, nj))
    Z = np.empty((1, nj + 1, 3))
    O = np.empty((1, nj + 1, 3))
    _fk_jac_kernel_serial(q[:1], d, a, al, off, np.ascontiguousarray(robot.base), tcp, T, J, Z, O)
    return Z[0], O[0]


def jacobian_derivative(robot: Robot, q_rad: Any, tcp_m: Any = None) -> np.ndarray:
    """Analytic derivatives of the geometric Jacobian, dJ/dq_i, for one posture.

    Returns ``dJ`` of shape (n_joints, 6, n_joints) with ``dJ[i] = dJ/dq_i`` (world frame,
    tool point ``tcp_m`` fixed in the flange frame). With ``z_j``, ``o_j`` the axis and origin
    of joint j+1 and ``p`` the tool point: joint i moves every frame distal to it, so for
    i < j: dz_j/dq_i = z_i x z_j, do_j/dq_i = z_i x (o_j - o_i); dp/dq_i = z_i x (p - o_i).
    Hence dJv_j/dq_i = (z_i x z_j) x (p - o_j) + z_j x (z_i x (p - o_j)) for i < j and
    z_j x (z_i x (p - o_i)) for i >= j; dJw_j/dq_i = z_i x z_j for i < j, 0 otherwise.
    Checked against finite differences in tests/robot/test_stiffness.py.
    """
    q = np.asarray(q_rad, float).reshape(robot.n_joints)
    Z, O = joint_frames(robot, q)
    T = fk(robot, q, tcp_m)
    p = T[:3, 3]
    nj = robot.n_joints
    zi = Z[:nj, None, :]  # joint i (axis of derivative), broadcast over j
    zj = Z[None, :nj, :]
    oi = O[:nj, None, :]
    oj = O[None, :nj, :]
    dzj = np.cross(zi, zj)  # (i, j, 3)
    lower = np.cross(dzj, p - oj) + np.cross(zj, np.cross(zi, p - oj))  # i < j
    upper = np.cross(zj, np.cross(zi, p - oi))  # i >= j
    before = (np.arange(nj)[:, None] < np.arange(nj)[None, :])[..., None]
    dJ = np.zeros((nj, 6, nj))
    dJ[:, :3, :] = np.swapaxes(np.where(before, lower, upper), 1, 2)
    dJ[:, 3:, :] = np.swapaxes(np.where(before, dzj, 0.0), 1, 2)
    return dJ


def rotation_vector(R: np.ndarray) -> np.ndarray:
    """Rotation vector (axis * angle, rad) of rotation matrices, (..., 3, 3) -> (..., 3).

    Uses the skew part for small angles and the axis-angle formula otherwise; valid for
    angles below pi (stiffness deflections are micro-radians).
    """
    R = np.asarray(R, float)
    w = 0.5 * np.stack(
        [R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]],
        axis=-1,
    )
    cos = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    s = np.linalg.norm(w, axis=-1)
    ang = np.arctan2(s, cos)
    factor = np.where(s > 1e-12, ang / np.where(s > 1e-12, s, 1.0), 1.0)
    return w * factor[..., None]


__all__ = [
    "fk",
    "jacobian",
    "fk_jacobian",
    "joint_frames",
    "jacobian_derivative",
    "rotation_vector",
    "inverse_kinematics",
]


def inverse_kinematics(
    robot: Robot,
    T_target: np.ndarray,
    q0_rad: Any,
    tcp_m: Any = None,
    *,
    tol: float = 1e-11,
    max_iter: int = 100,
    damping: float = 1e-6,
) -> np.ndarray:
    """Joint angles (rad) that put the tool frame at ``T_target`` (4x4), starting from ``q0``.

    Damped least squares Newton on the geometric Jacobian (Wampler 1986; Buss 2004): error
    ``e = [p_t - p; log(R_t R^T)]``, ``dq = J^T (J J^T + lambda^2 I)^-1 e``. Converges to the
    solution in the branch of ``q0`` (local method: use continuation for scans). Raises
    NumericalError when it does not converge (target out of reach or singular).
    """
    from robobore.errors import NumericalError

    q = np.asarray(q0_rad, float).reshape(robot.n_joints).copy()
    Tt = np.asarray(T_target, float)
    for _ in range(max_iter):
        T, J = fk_jacobian(robot, q, tcp_m)
        e = np.concatenate([Tt[:3, 3] - T[:3, 3], rotation_vector(Tt[:3, :3] @ T[:3, :3].T)])
        if np.max(np.abs(e)) < tol:
            return q
        JJt = J @ J.T + damping ** 2 * np.eye(6)
        q = q + J.T @ np.linalg.solve(JJt, e)
    raise NumericalError(
        f"inverse kinematics did not converge (residual {np.max(np.abs(e)):.3e}); the target "
        "may be out of reach or at a singularity"
    )
