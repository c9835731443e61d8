"""Rigid-body inertia of a serial robot: end effector, link data, joint-space mass matrix.

``M(q) = sum_l m_l J_vl^T J_vl + J_wl^T R_l I_l R_l^T J_wl``: the joint-space mass matrix of
the rigid links (mass ``m_l``, centre of mass and inertia tensor ``I_l`` in D-H frame l) and of
the end effector (:class:`ToolBody`: rigidly attached to the flange, merged with the last link),
with ``J_vl`` the Jacobian of the link's centre of mass and ``J_wl`` its angular Jacobian
(Spong, Hutchinson & Vidyasagar 2006, eq. 7.31); numba, vectorised over postures. Used by the
pose-dependent model :mod:`robobore.plan.model`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit, prange

from robobore.errors import ConfigError, InputError
from robobore.robot.description import Robot


@dataclass(frozen=True)
class ToolBody:
    """End effector rigidly attached to the flange (spindle, holder, boring bar).

    ``mass_kg``; ``com_m`` centre of mass in the flange frame; ``inertia_kg_m2`` about the
    centre of mass in the flange frame (Ixx, Iyy, Izz, Ixy, Ixz, Iyz).
    """

    mass_kg: float = 0.0
    com_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    inertia_kg_m2: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

    def tensor(self) -> np.ndarray:
        xx, yy, zz, xy, xz, yz = self.inertia_kg_m2
        return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], float)


def link_arrays(robot: Robot, *, file: str | None = None) -> tuple[np.ndarray, np.ndarray,
                                                                      np.ndarray]:
    """(mass (n,), com (n, 3), inertia (n, 3, 3)) of the robot's links, SI.

    Raises ConfigError naming the robot file when the robot has no inertial data.
    """
    if not robot.links:
        raise ConfigError(
            f"robot '{robot.name}' has no inertial data (the pose-dependent dynamic model "
            "needs mass, centre of mass and inertia per link)",
            file=file or robot.file or None, field="links", value="none",
            expected=f"{robot.n_joints} [[links]] tables with mass_kg, com_m and inertia_kg_m2 "
                     "(see robot/library/irb6600-175-2.55.toml)")
    m = np.array([li.mass_kg for li in robot.links], float)
    c = np.array([li.com_m for li in robot.links], float)
    inertia = np.stack([li.tensor() for li in robot.links])
    return m, c, inertia


def merge_tool(m: np.ndarray, c: np.ndarray, inertia: np.ndarray, tool: ToolBody,
                flange_offset: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Add the tool body to the last link (parallel-axis theorem); ``flange_offset`` is the
    flange origin in the last link's frame (zero for standard D-H: frame n is the flange)."""
    if tool.mass_kg <= 0:
        return m, c, inertia
    m, c, inertia = m.copy(), c.copy(), inertia.copy()
    m1, c1, i1 = m[-1], c[-1], inertia[-1]
    m2, c2, i2 = tool.mass_kg, np.asarray(tool.com_m, float) + flange_offset, tool.tensor()
    mt = m1 + m2
    ct = (m1 * c1 + m2 * c2) / mt

    def shift(mm: float, d: np.ndarray) -> np.ndarray:
        return mm * (float(d @ d) * np.eye(3) - np.outer(d, d))

    inertia[-1] = i1 + shift(m1, c1 - ct) + i2 + shift(m2, c2 - ct)
    m[-1], c[-1] = mt, ct
    return m, c, inertia


@njit(cache=True, parallel=True)
def _mass_kernel(q, d, a, alpha, off, base, mass, com, inertia, M, Rw, Ow):  # pragma: no cover
    """Joint-space mass matrices for many postures (parallel over postures).

    q (n, nj); mass (nj,); com (nj, 3); inertia (nj, 3, 3) in the link frames;
    out M (n, nj, nj); scratch Rw (n, nj + 1, 3, 3), Ow (n, nj + 1, 3) frame rotations and
    origins (row 0: base).
    """
    n = q.shape[0]
    nj = q.shape[1]
    for k in prange(n):
        for r in range(3):
            for s in range(3):
                Rw[k, 0, r, s] = base[r, s]
            Ow[k, 0, r] = base[r, 3]
        for i in range(nj):
            th = q[k, i] + off[i]
            ct = math.cos(th)
            st = math.sin(th)
            ca = math.cos(alpha[i])
            sa = math.sin(alpha[i])
            # A = [[ct, -st ca, st sa, a ct], [st, ct ca, -ct sa, a st], [0, sa, ca, d]]
            for r in range(3):
                r0 = Rw[k, i, r, 0]
                r1 = Rw[k, i, r, 1]
                r2 = Rw[k, i, r, 2]
                Rw[k, i + 1, r, 0] = r0 * ct + r1 * st
                Rw[k, i + 1, r, 1] = -r0 * st * ca + r1 * ct * ca + r2 * sa
                Rw[k, i + 1, r, 2] = r0 * st * sa - r1 * ct * sa + r2 * ca
                Ow[k, i + 1, r] = Ow[k, i, r] + r0 * a[i] * ct + r1 * a[i] * st + r2 * d[i]
        for r in range(nj):
            for s in range(nj):
                M[k, r, s] = 0.0
        for link in range(nj):
            fr = link + 1
            # centre of mass in the world frame
            cx = Ow[k, fr, 0]
            cy = Ow[k, fr, 1]
            cz = Ow[k, fr, 2]
            for s in range(3):
                cx += Rw[k, fr, 0, s] * com[link, s]
                cy += Rw[k, fr, 1, s] * com[link, s]
                cz += Rw[k, fr, 2, s] * com[link, s]
            # world inertia Iw = R I R^T
            Iw00 = 0.0
            Iw01 = 0.0
            Iw02 = 0.0
            Iw11 = 0.0
            Iw12 = 0.0
            Iw22 = 0.0
            for s in range(3):
                for t in range(3):
                    v = inertia[link, s, t]
                    if v == 0.0:
                        continue
                    Iw00 += Rw[k, fr, 0, s] * v * Rw[k, fr, 0, t]
                    Iw01 += Rw[k, fr, 0, s] * v * Rw[k, fr, 1, t]
                    Iw02 += Rw[k, fr, 0, s] * v * Rw[k, fr, 2, t]
                    Iw11 += Rw[k, fr, 1, s] * v * Rw[k, fr, 1, t]
                    Iw12 += Rw[k, fr, 1, s] * v * Rw[k, fr, 2, t]
                    Iw22 += Rw[k, fr, 2, s] * v * Rw[k, fr, 2, t]
            m = mass[link]
            for j1 in range(link + 1):
                z1x = Rw[k, j1, 0, 2]
                z1y = Rw[k, j1, 1, 2]
                z1z = Rw[k, j1, 2, 2]
                d1x = cx - Ow[k, j1, 0]
                d1y = cy - Ow[k, j1, 1]
                d1z = cz - Ow[k, j1, 2]
                v1x = z1y * d1z - z1z * d1y
                v1y = z1z * d1x - z1x * d1z
                v1z = z1x * d1y - z1y * d1x
                w1x = Iw00 * z1x + Iw01 * z1y + Iw02 * z1z
                w1y = Iw01 * z1x + Iw11 * z1y + Iw12 * z1z
                w1z = Iw02 * z1x + Iw12 * z1y + Iw22 * z1z
                for j2 in range(j1, link + 1):
                    z2x = Rw[k, j2, 0, 2]
                    z2y = Rw[k, j2, 1, 2]
                    z2z = Rw[k, j2, 2, 2]
                    d2x = cx - Ow[k, j2, 0]
                    d2y = cy - Ow[k, j2, 1]
                    d2z = cz - Ow[k, j2, 2]
                    v2x = z2y * d2z - z2z * d2y
                    v2y = z2z * d2x - z2x * d2z
                    v2z = z2x * d2y - z2y * d2x
                    val = m * (v1x * v2x + v1y * v2y + v1z * v2z) + \
                        w1x * z2x + w1y * z2y + w1z * z2z
                    M[k, j1, j2] += val
                    if j2 != j1:
                        M[k, j2, j1] += val


_mass_kernel_serial = njit(cache=True)(_mass_kernel.py_func)


def mass_matrix(robot: Robot, Q_rad: Any, mass: np.ndarray, com: np.ndarray,
                inertia: np.ndarray) -> np.ndarray:
    """Joint-space mass matrices M(q), (n, nj, nj) for Q (n, nj) (or (nj, nj) for one)."""
    Q = np.asarray(Q_rad, float)
    single = Q.ndim == 1
    Q2 = np.ascontiguousarray(np.atleast_2d(Q))
    n, nj = Q2.shape
    if nj != robot.n_joints:
        raise InputError(f"got {nj} joint angles", expected=f"{robot.n_joints} per posture")
    d, a, al, off = robot.dh_arrays
    M = np.empty((n, nj, nj))
    Rw = np.empty((n, nj + 1, 3, 3))
    Ow = np.empty((n, nj + 1, 3))
    kern = _mass_kernel if n >= 64 else _mass_kernel_serial
    kern(Q2, d, a, al, off, np.ascontiguousarray(robot.base), np.ascontiguousarray(mass, float),
         np.ascontiguousarray(com, float), np.ascontiguousarray(inertia, float), M, Rw, Ow)
    return M[0] if single else M


__all__ = ["ToolBody", "link_arrays", "merge_tool", "mass_matrix"]
