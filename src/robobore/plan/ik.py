"""Every inverse-kinematics branch of a 6R robot with a spherical wrist, in closed form.

Applies to the usual industrial layout (ABB IRB 6600, KUKA, Fanuc; Pieper 1968): standard
D-H with ``alpha_1 = +-90 deg``, ``alpha_2 = 0``, ``d_2 = d_3 = 0``, ``alpha_3 = +-90 deg``
and a spherical wrist (``a_4 = a_5 = a_6 = 0``, ``d_5 = 0``, ``alpha_4 = -alpha_5 = +-90
deg``, ``alpha_6 = 0``); :func:`is_supported` checks it.

With the D-H angles ``t_i = q_i + offset_i``, for a flange pose (R, p) (base transform
removed) and the wrist centre ``w = p - d_6 z``:

* shoulder: ``t_1 = atan2(w_y, w_x)`` or that + pi (the wrist centre must lie in the plane of
  the arm, which contains the z0 axis since d_2 = d_3 = 0);
* elbow: in frame 1 the wrist centre is ``R_z(t_2) ((a_2, 0) + w_2(t_3))`` with
  ``w_2 = (a_3 c_3 + d_4 s_alpha3 s_3, a_3 s_3 - d_4 s_alpha3 c_3)``, so
  ``a_3 c_3 + d_4 s_alpha3 s_3 = (|w_1|^2 - a_2^2 - a_3^2 - d_4^2) / (2 a_2)``: two roots
  ``t_3 = phi +- acos(.)``, ``phi = atan2(d_4 s_alpha3, a_3)``; then ``t_2`` from the angle of
  ``w_1``;
* wrist: ``R_36 = R_03^T R`` = ``R_z(t_4) R_x(alpha_4) R_z(t_5) R_x(alpha_5) R_z(t_6)``,
  solved as ZYZ-type Euler angles, two roots (``t_5`` and ``-t_5``).

That is up to 8 branches, numbered ``4 s + 2 e + w`` (s: shoulder back, e: second elbow
root, w: wrist flipped). Joints whose range exceeds 360 deg (axes 4 and 6 of the IRB 6600)
take the representative nearest to zero that is inside the limits. Every solution is checked
by forward kinematics by the caller.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from robobore.robot.description import Robot

N_BRANCHES = 8


def is_supported(robot: Robot) -> bool:
    """True when the closed form applies (see the module docstring)."""
    if robot.n_joints != 6:
        return False
    d, a, al, _ = robot.dh_arrays
    s = np.sin(al)
    c = np.cos(al)
    tol = 1e-9
    return bool(abs(abs(s[0]) - 1) < tol and abs(s[1]) < tol and c[1] > 0
                and abs(d[1]) < tol and abs(d[2]) < tol and abs(abs(s[2]) - 1) < tol
                and abs(a[3]) < tol and abs(a[4]) < tol and abs(a[5]) < tol and abs(d[4]) < tol
                and abs(abs(s[3]) - 1) < tol and abs(s[3] + s[4]) < tol
                and abs(s[5]) < tol and c[5] > 0 and abs(a[1]) > tol)


@njit(cache=True)
def _wrap(x):  # pragma: no cover - numba
    return math.atan2(math.sin(x), math.cos(x))


@njit(cache=True, parallel=True)
def _ik_kernel(Rt, pt, d, a, al, off, lo, hi, Q, ok, S):  # pragma: no cover - numba
    """Rt (n, 3, 3), pt (n, 3): flange poses in the D-H base frame; out Q (n, 8, 6), ok (n, 8);
    scratch S (n, 4, 3, 3)."""
    n = Rt.shape[0]
    sa1 = math.sin(al[0])
    sa3 = math.sin(al[2])
    sa4 = math.sin(al[3])
    L = math.sqrt(a[2] * a[2] + d[3] * d[3])
    phi = math.atan2(d[3] * sa3, a[2])
    for k in prange(n):
        wx = pt[k, 0] - d[5] * Rt[k, 0, 2]
        wy = pt[k, 1] - d[5] * Rt[k, 1, 2]
        wz = pt[k, 2] - d[5] * Rt[k, 2, 2]
        for b in range(8):
            ok[k, b] = False
            for j in range(6):
                Q[k, b, j] = np.nan
        if wx * wx + wy * wy < 1e-18:
            continue  # shoulder singularity: wrist centre on axis 1
        for sh in range(2):
            t1 = math.atan2(wy, wx) + sh * math.pi
            c1 = math.cos(t1)
            s1 = math.sin(t1)
            # wrist centre in frame 1: A1^-1 (w); A1 = Rz(t1) Tz(d1) Tx(a1) Rx(al1)
            rx = c1 * wx + s1 * wy - a[0]
            ry = -s1 * wx + c1 * wy
            rz = wz - d[0]
            # rotate by Rx(al1)^T: (x, y cos + z sin, -y sin + z cos)
            ca1 = math.cos(al[0])
            x1 = rx
            y1 = ry * ca1 + rz * sa1
            # z1 = -ry * sa1 + rz * ca1 must be ~0 (planarity), true by construction of t1
            r2 = x1 * x1 + y1 * y1
            K = (r2 - a[1] * a[1] - a[2] * a[2] - d[3] * d[3]) / (2 * a[1])
            if abs(K) > L:
                continue
            acs = math.acos(min(1.0, max(-1.0, K / L)))
            for el in range(2):
                t3 = phi + (acs if el == 0 else -acs)
                c3 = math.cos(t3)
                s3 = math.sin(t3)
                w2x = a[2] * c3 + d[3] * sa3 * s3
                w2y = a[2] * s3 - d[3] * sa3 * c3
                t2 = math.atan2(y1, x1) - math.atan2(w2y, a[1] + w2x)
                # R03 = Rz(t1) Rx(al1) Rz(t2 + t3) Rx(al3)   (alpha2 = 0)
                t23 = t2 + t3
                c23 = math.cos(t23)
                s23 = math.sin(t23)
                ca3 = math.cos(al[2])
                # R01 = Rz(t1) Rx(al1)
                R01 = S[k, 0]
                R01[0, 0] = c1
                R01[0, 1] = -s1 * ca1
                R01[0, 2] = s1 * sa1
                R01[1, 0] = s1
                R01[1, 1] = c1 * ca1
                R01[1, 2] = -c1 * sa1
                R01[2, 0] = 0.0
                R01[2, 1] = sa1
                R01[2, 2] = ca1
                R13 = S[k, 1]
                R13[0, 0] = c23
                R13[0, 1] = -s23 * ca3
                R13[0, 2] = s23 * sa3
                R13[1, 0] = s23
                R13[1, 1] = c23 * ca3
                R13[1, 2] = -c23 * sa3
                R13[2, 0] = 0.0
                R13[2, 1] = sa3
                R13[2, 2] = ca3
                R03 = S[k, 2]
                R36 = S[k, 3]
                for r in range(3):
                    for c in range(3):
                        R03[r, c] = (R01[r, 0] * R13[0, c] + R01[r, 1] * R13[1, c]
                                     + R01[r, 2] * R13[2, c])
                for r in range(3):
                    for c in range(3):
                        R36[r, c] = (R03[0, r] * Rt[k, 0, c] + R03[1, r] * Rt[k, 1, c]
                                     + R03[2, r] * Rt[k, 2, c])
                # R36 = Rz(t4) Rx(a4) Rz(t5) Rx(-a4) Rz(t6), a4 = +-90:
                # col 2 = (-s4 s5 g... ) derived for sa4 = +1: (-c4 s5, -s4 s5, c5) -> general
                # sa4: (-sa4 c4 s5, -sa4 s4 s5, c5); row 2 = (sa4 s5 c6, -sa4 s5 s6, c5)
                c5 = min(1.0, max(-1.0, R36[2, 2]))
                for wr in range(2):
                    s5abs = math.sqrt(max(0.0, 1.0 - c5 * c5))
                    s5 = s5abs if wr == 0 else -s5abs
                    t5 = math.atan2(s5, c5)
                    if s5abs < 1e-12:
                        t4 = 0.0
                        # R36 = Rz(t4 + t6) when c5 = 1
                        t6 = math.atan2(R36[1, 0], R36[0, 0])
                    else:
                        t4 = math.atan2(-sa4 * R36[1, 2] / s5, -sa4 * R36[0, 2] / s5)
                        t6 = math.atan2(-sa4 * R36[2, 1] / s5, sa4 * R36[2, 0] / s5)
                    th0 = t1
                    th1 = t2
                    th2 = t3
                    th3 = t4
                    th4 = t5
                    th5 = t6
                    b = 4 * sh + 2 * el + wr
                    good = True
                    for j in range(6):
                        if j == 0:
                            tj = th0
                        elif j == 1:
                            tj = th1
                        elif j == 2:
                            tj = th2
                        elif j == 3:
                            tj = th3
                        elif j == 4:
                            tj = th4
                        else:
                            tj = th5
                        qj = _wrap(tj - off[j])
                        # representative nearest zero inside the limits
                        best = np.nan
                        for m in range(-2, 3):
                            cand = qj + 2 * math.pi * m
                            if lo[j] - 1e-9 <= cand <= hi[j] + 1e-9:
                                if not (abs(cand) >= abs(best)):
                                    best = cand
                        if math.isnan(best):
                            good = False
                            best = qj
                        Q[k, b, j] = best
                    ok[k, b] = good


def ik_all(robot: Robot, R_flange: np.ndarray, p_flange: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray]:
    """All closed-form branches for flange poses (world frame).

    ``R_flange`` (n, 3, 3), ``p_flange`` (n, 3). Returns ``Q`` (n, 8, 6) rad (NaN where the
    branch does not reach) and ``within_limits`` (n, 8) bool (False also where it does not
    reach). Branch numbering: module docstring.
    """
    B = robot.base
    Rb = B[:3, :3].T
    R = np.einsum("ij,njk->nik", Rb, np.asarray(R_flange, float))
    p = np.einsum("ij,nj->ni", Rb, np.asarray(p_flange, float) - B[:3, 3])
    d, a, al, off = robot.dh_arrays
    n = R.shape[0]
    Q = np.empty((n, N_BRANCHES, 6))
    ok = np.empty((n, N_BRANCHES), dtype=np.bool_)
    S = np.empty((n, 4, 3, 3))
    _ik_kernel(np.ascontiguousarray(R), np.ascontiguousarray(p), d, a, al, off,
               np.asarray(robot.lower_limit_rad), np.asarray(robot.upper_limit_rad), Q, ok, S)
    reached = np.all(np.isfinite(Q), axis=2)
    return Q, ok & reached


def branch_label(b: int) -> str:
    """Readable name of branch ``b``: shoulder front/back, elbow 1/2, wrist +/-."""
    sh, el, wr = (b >> 2) & 1, (b >> 1) & 1, b & 1
    return (f"{'back' if sh else 'front'}/{'elbow-2' if el else 'elbow-1'}/"
            f"{'flip' if wr else 'noflip'}")


__all__ = ["ik_all", "is_supported", "branch_label", "N_BRANCHES"]
