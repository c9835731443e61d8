"""Pose-dependent elastic multibody model of a serial robot (rigid links, elastic joints).

Model (joint-space, small vibrations about a posture ``q``; Spong 1987 flexible-joint model
without motor inertia, linearised)::

    M(q) dq'' + C dq' + K dq = J(q)^T F,        r = J_v(q) dq

* ``M(q) = sum_l m_l J_vl^T J_vl + J_wl^T R_l I_l R_l^T J_wl``: the joint-space mass matrix of
  the rigid links (mass ``m_l``, centre of mass and inertia tensor ``I_l`` in D-H frame l) and
  of the end effector (``tool``: rigidly attached to the flange), with ``J_vl`` the Jacobian of
  the link's centre of mass and ``J_wl`` its angular Jacobian (Spong, Hutchinson &
  Vidyasagar 2006, eq. 7.31);
* ``K = diag(k_i)`` the identified joint stiffnesses; ``C = diag(c_i)`` joint dampers;
* the gravity-load (geometric) stiffness ``-d(tau_g)/dq`` is left out: for the IRB 6600
  it is ``m g L`` ~ 2e4 N m/rad at most, under 1 % of the identified joint stiffnesses
  (2.6e5 to 4e6 N m/rad), and the robot's balancing cylinder cancels most of it on axis 2.

Modes: ``K phi = w^2 M phi`` (mass-normalised ``phi``), damping ratios by the modal
(classical-damping) approximation ``zeta_j = phi_j^T C phi_j / (2 w_j)``. Tool-point modal
vectors ``u_j = R_b^T J_v phi_j`` (boring frame ``R_b``: Z the tool axis, X horizontal, Y =
Z x X; :func:`robobore.robot.stiffness.process_frame`) give the tool-point FRF
``G(iw) = sum_j u_j u_j^T / (w_j^2 - w^2 + 2 i zeta_j w_j w)`` and the static compliance
``sum_j u_j u_j^T / w_j^2 = R_b^T J_v K^-1 J_v^T R_b`` (the stiffness model of
:mod:`robobore.robot.stiffness`, exactly). Mode j acts at the tool point along
``u_j / |u_j|`` with modal stiffness ``w_j^2 / |u_j|^2``: a
:class:`~robobore.dynamics.structure.ToolPointStructure` for the stability stage.

Calibration at the measured posture (:func:`calibrate`): one scale factor per link on its
mass and inertia (bounded to [0.25, 4]) fitted by least squares on the log-frequencies of the
identified modes (identified mode j <-> the j-th of a subset of the model's modes, order kept;
every subset is tried and the best fit kept, since the test may miss a mode), with a weak pull
towards 1 (weight 0.05 per factor) so that the problem stays well posed with fewer modes than
links; then the joint dampers ``c_i >= 0`` from ``2 zeta_j w_j = sum_i c_i phi_ij^2`` by
bounded least squares, pulled towards a common stiffness-proportional damping
(:func:`fit_joint_damping`) so that joints the measured modes do not move stay damped.
The fitted factors and the residuals are reported.

Optional link compliance (:class:`LinkBending`, virtual-joint method: Pashkevich, Klimchik &
Chablat, Mech. Mach. Theory 44(5), 2009): a long link as an Euler-Bernoulli beam whose tip
deflects and turns in two bending planes; two coordinates per plane move the links beyond
it, tip rotations on the next joint's axis are merged with that joint (springs in series,
:func:`redundancy`), and the modes, damping, compliance and FRFs are computed over the
independent coordinates (:meth:`PoseModel.reduced_matrices`). The tool compliance stays
linear in the joint and link compliances (:func:`compliance_basis`) for identification.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numba import njit, prange

from robobore.errors import ConfigError, InputError
from robobore.robot.kinematics import Robot, fk_jacobian
from robobore.robot.stiffness import process_frame


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


def _merge_tool(m: np.ndarray, c: np.ndarray, inertia: np.ndarray, tool: ToolBody,
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


@dataclass(frozen=True)
class LinkBending:
    """Bending compliance of one link (virtual-joint method, Euler-Bernoulli beam).

    ``link``: the link, 1-based (link i moves with joint i); the beam runs from the origin of
    D-H frame i-1 to the origin of frame i (length ``sqrt(a_i^2 + d_i^2)``, the lower arm
    ``a_2`` and the forearm ``d_4`` of the IRB 6600). ``compliance_per_Nm2`` = ``(1/EI_1,
    1/EI_2)`` for bending with the tip deflecting along the two normals ``t_1``, ``t_2`` of
    the beam (``t_1``: the joint axis ``z_{i-1}`` made normal to the beam, or the frame's x
    axis where ``z_{i-1}`` runs along the beam; ``t_2 = e x t_1`` with ``e`` the beam
    direction). A value 0 is a rigid plane. ``damping_s``: the beam's damper is
    ``damping_s`` times its stiffness block.
    """

    link: int
    compliance_per_Nm2: tuple[float, float]
    damping_s: float = 0.0


def link_frames(robot: Robot, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World rotations (n, nj + 1, 3, 3) and origins (n, nj + 1, 3) of the D-H frames
    (row 0 the base) for postures Q (n, nj)."""
    d, a, al, off = robot.dh_arrays
    n, nj = Q.shape
    R = np.empty((n, nj + 1, 3, 3))
    O = np.empty((n, nj + 1, 3))
    R[:, 0] = robot.base[:3, :3]
    O[:, 0] = robot.base[:3, 3]
    for i in range(nj):
        th = Q[:, i] + off[i]
        ct, st = np.cos(th), np.sin(th)
        ca, sa = math.cos(al[i]), math.sin(al[i])
        A = np.zeros((n, 3, 3))
        A[:, 0, 0], A[:, 0, 1], A[:, 0, 2] = ct, -st * ca, st * sa
        A[:, 1, 0], A[:, 1, 1], A[:, 1, 2] = st, ct * ca, -ct * sa
        A[:, 2, 1], A[:, 2, 2] = sa, ca
        p = np.stack([a[i] * ct, a[i] * st, np.full(n, d[i])], axis=-1)
        R[:, i + 1] = R[:, i] @ A
        O[:, i + 1] = O[:, i] + np.einsum("nij,nj->ni", R[:, i], p)
    return R, O


def beam_geometry(robot: Robot, lb: LinkBending) -> tuple[float, np.ndarray, np.ndarray]:
    """(length L, beam direction e, normals (t_1, t_2) as rows) in D-H frame ``lb.link``
    (constant: the frame turns with the beam)."""
    nj = robot.n_joints
    if not 1 <= lb.link <= nj:
        raise InputError("link bending: no such link", field="link_bending.link",
                         value=lb.link, expected=f"1..{nj}")
    d, a, al, _ = robot.dh_arrays
    i = lb.link - 1
    ca, sa = math.cos(al[i]), math.sin(al[i])
    rxm = np.array([[1.0, 0.0, 0.0], [0.0, ca, sa], [0.0, -sa, ca]])  # Rot_x(-alpha)
    v = rxm @ np.array([a[i], 0.0, d[i]])
    L = float(np.linalg.norm(v))
    if L < 1e-6:
        raise InputError("link bending on a link of zero length", field="link_bending.link",
                         value=lb.link, expected="a link with a_i or d_i > 0")
    e = v / L
    t1 = None
    for cand in (rxm @ np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]),
                 np.array([0.0, 1.0, 0.0])):
        w = cand - (cand @ e) * e
        if np.linalg.norm(w) > 0.5:
            t1 = w / np.linalg.norm(w)
            break
    assert t1 is not None
    return L, e, np.stack([t1, np.cross(e, t1)])


def _planes(bending: tuple[LinkBending, ...]) -> list[tuple[LinkBending, int]]:
    """The compliant bending planes (1/EI > 0): (link bending, plane 0 or 1)."""
    return [(lb, k) for lb in bending for k in range(2) if lb.compliance_per_Nm2[k] > 0]


def beam_block(L: float) -> np.ndarray:
    """Tip compliance of a cantilever per unit 1/EI in (deflection along t, rotation about
    e x t) under (force along t, moment about e x t): ``[[L^3/3, L^2/2], [L^2/2, L]]``."""
    return np.array([[L ** 3 / 3, L ** 2 / 2], [L ** 2 / 2, L]])


def elastic_screws(robot: Robot, Q: np.ndarray, bending: tuple[LinkBending, ...]
                   ) -> dict[str, Any]:
    """Screws of every elastic coordinate (joints, then per bending link and plane the tip
    deflection and the tip rotation): angular part ``w`` (n, ndof, 3), a point on the axis
    ``p`` (n, ndof, 3), translational part ``v0`` (n, ndof, 3) (the velocity of a point x is
    ``v0 + w x (x - p)``), ``first_body`` (ndof,) the first link (0-based) each moves, the
    frames, and per plane its beam length and its compliance 1/EI."""
    R, O = link_frames(robot, Q)
    n, nj = Q.shape
    planes = _planes(bending)
    ndof = nj + 2 * len(planes)
    w = np.zeros((n, ndof, 3))
    p = np.zeros((n, ndof, 3))
    v0 = np.zeros((n, ndof, 3))
    first = np.zeros(ndof, dtype=np.int64)
    w[:, :nj] = R[:, :nj, :, 2]
    p[:, :nj] = O[:, :nj]
    first[:nj] = np.arange(nj)
    lengths, comp = [], []
    for j, (lb, k) in enumerate(planes):
        L, e, T = beam_geometry(robot, lb)
        Rl = R[:, lb.link]
        t = Rl @ T[k]
        r = Rl @ np.cross(e, T[k])
        a_, b_ = nj + 2 * j, nj + 2 * j + 1
        v0[:, a_] = t
        w[:, b_] = r
        p[:, b_] = O[:, lb.link]
        first[a_] = first[b_] = lb.link  # 0-based index of the next link: distal bodies only
        lengths.append(L)
        comp.append(float(lb.compliance_per_Nm2[k]))
    return {"w": w, "p": p, "v0": v0, "first_body": first, "R": R, "O": O,
            "plane_length_m": np.array(lengths), "plane_compliance": np.array(comp),
            "planes": planes}


def _point_jacobian(sc: dict[str, Any], x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Translational (n, 3, ndof) and angular (n, 3, ndof) Jacobian of points x (n, 3)."""
    Jv = sc["v0"] + np.cross(sc["w"], x[:, None, :] - sc["p"])
    return np.swapaxes(Jv, 1, 2), np.swapaxes(sc["w"], 1, 2)


def redundancy(robot: Robot, bending: tuple[LinkBending, ...]
               ) -> tuple[np.ndarray, np.ndarray]:
    """Map ``P`` (n_red, ndof) from the elastic coordinates to independent motion
    coordinates, and the kept coordinates (n_red,). A bending plane whose tip rotation
    turns about the next joint's axis (the lower arm's in-plane bending and axis 3, the
    forearm's bending and axis 5) moves every body exactly as that joint does: the two
    springs act in series and only their sum ``theta + s beta`` is a coordinate (the tip
    rotation carries no mass of its own). Found on the screws at a generic posture (the
    coincidence is structural)."""
    nj = robot.n_joints
    qg = np.array([[0.31, -0.23, 0.41, 0.53, 0.67, 0.71, 0.2, 0.3][:nj]]) if nj <= 8 else \
        np.full((1, nj), 0.3)
    sc = elastic_screws(robot, qg, bending)
    w, p, v0 = sc["w"][0], sc["p"][0], sc["v0"][0]
    lin = v0 - np.cross(w, p)  # velocity of the point at the origin
    scr = np.concatenate([w, lin], axis=1)
    ndof = scr.shape[0]
    P = np.eye(ndof)
    drop = []
    for j in range(nj, ndof):
        for i in range(nj):
            for sgn in (1.0, -1.0):
                if np.allclose(scr[j], sgn * scr[i], atol=1e-9 * (1 + np.abs(scr[i]).max())):
                    P[i, j] = sgn
                    drop.append(j)
                    break
            if drop and drop[-1] == j:
                break
    keep = [k for k in range(ndof) if k not in drop]
    return P[keep], np.array(keep, dtype=np.int64)


def elastic_matrices(robot: Robot, bending: tuple[LinkBending, ...], k_joint: np.ndarray,
                     c_joint: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Stiffness and damping matrices (ndof, ndof) of joints + bending planes."""
    nj = robot.n_joints
    planes = _planes(bending)
    K = np.zeros((nj + 2 * len(planes), nj + 2 * len(planes)))
    C = np.zeros_like(K)
    K[:nj, :nj] = np.diag(k_joint)
    C[:nj, :nj] = np.diag(c_joint)
    for j, (lb, k) in enumerate(planes):
        L = beam_geometry(robot, lb)[0]
        s = slice(nj + 2 * j, nj + 2 * j + 2)
        Kb = np.linalg.inv(beam_block(L)) / float(lb.compliance_per_Nm2[k])
        K[s, s] = Kb
        C[s, s] = lb.damping_s * Kb
    return K, C


def compliance_basis(robot: Robot, Q: np.ndarray, tcp_m: Any,
                     bending_links: tuple[int, ...] = ()) -> np.ndarray:
    """6x6 tool-point compliance per unit parameter, (n, nj + 2 len(bending_links), 6, 6):
    ``C6 = sum_i (1/k_i) B_i + sum_planes (1/EI) B_plane`` (rows: translation, rotation;
    for identification: the compliance is linear in the joint and link compliances)."""
    Q = np.atleast_2d(np.asarray(Q, float))
    bend = tuple(LinkBending(int(li), (1.0, 1.0)) for li in bending_links)
    sc = elastic_screws(robot, Q, bend)
    T, _ = fk_jacobian(robot, Q, tcp_m)
    Jv, Jw = _point_jacobian(sc, T[:, :3, 3])
    J = np.concatenate([Jv, Jw], axis=1)  # (n, 6, ndof)
    nj = robot.n_joints
    out = [np.einsum("na,nb->nab", J[:, :, i], J[:, :, i]) for i in range(nj)]
    for j in range(len(sc["planes"])):
        G = J[:, :, nj + 2 * j: nj + 2 * j + 2]
        out.append(np.einsum("nai,ij,nbj->nab", G, beam_block(sc["plane_length_m"][j]), G))
    return np.stack(out, axis=1)


def boring_frames(T: np.ndarray) -> np.ndarray:
    """Boring frames (n, 3, 3) for tool transforms (n, 4, 4); see process_frame."""
    return np.stack([process_frame(t[:3, :3], "boring") for t in T])


@dataclass(frozen=True)
class PostureModes:
    """Modal results for n postures (SI). Shapes: ``frequency_Hz``, ``damping_ratio``
    (n, nm) ascending (nm: the joints, plus the independent bending coordinates of a model
    with link bending); ``u`` (n, nm, 3) tool-point modal translations of the mass-normalised
    modes in the process frame; ``phi`` (n, nm, nm) mass-normalised shapes in the model's
    coordinates (mode index second); ``compliance``
    (n, 3, 3) static tool-point compliance [m/N] in the process frame; ``R`` (n, 3, 3)
    process frames; ``T`` (n, 4, 4) tool transforms."""

    frequency_Hz: np.ndarray
    damping_ratio: np.ndarray
    u: np.ndarray
    phi: np.ndarray
    compliance: np.ndarray
    R: np.ndarray
    T: np.ndarray

    @property
    def directional_stiffness(self) -> np.ndarray:
        """Stiffness along process X, Y, Z, ``1 / C_aa`` [N/m], shape (n, 3)."""
        return 1.0 / np.einsum("nii->ni", self.compliance)

    def structure(self, i: int, min_share: float = 0.0):
        """Tool-point structure (modes with direction and modal stiffness) of posture i.

        Modes whose tool-point flexibility ``|u_j|^2 / w_j^2`` is below ``min_share`` of the
        largest are left out (they do not move the tool point)."""
        from robobore.dynamics.structure import ToolPointStructure

        w = 2 * np.pi * self.frequency_Hz[i]
        un = np.linalg.norm(self.u[i], axis=1)
        flex = un ** 2 / w ** 2
        keep = flex > min_share * flex.max()
        keep &= un > 0
        return ToolPointStructure(self.frequency_Hz[i][keep].copy(),
                                  self.damping_ratio[i][keep].copy(),
                                  (w[keep] ** 2 / un[keep] ** 2),
                                  self.u[i][keep] / un[keep, None])

    def frf(self, i: int, omega: np.ndarray) -> np.ndarray:
        """Tool-point receptance G(iw) [m/N], (3, 3, n_w), in the process frame."""
        w = 2 * np.pi * self.frequency_Hz[i]
        z = self.damping_ratio[i]
        om = np.asarray(omega, float)
        den = w[:, None] ** 2 - om[None, :] ** 2 + 2j * z[:, None] * w[:, None] * om[None, :]
        return np.einsum("ja,jb,jw->abw", self.u[i], self.u[i], 1.0 / den)

    def modes_list(self, i: int) -> list[dict[str, float]]:
        return [{"frequency_Hz": float(f), "damping_ratio": float(z)}
                for f, z in zip(self.frequency_Hz[i], self.damping_ratio[i], strict=True)]


@dataclass(frozen=True)
class PoseModel:
    """The pose-dependent model: robot, joint stiffness [N m/rad], joint dampers [N m s/rad],
    link mass/inertia scale factors, end effector and tool point."""

    robot: Robot
    k_Nm_per_rad: np.ndarray
    c_Nms_per_rad: np.ndarray
    tool: ToolBody = field(default_factory=ToolBody)
    tcp_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    link_scale: np.ndarray | None = None
    robot_file: str | None = None
    link_bending: tuple[LinkBending, ...] = ()

    @property
    def n_dof(self) -> int:
        """Elastic coordinates: the joints plus two per compliant bending plane."""
        if not _planes(self.link_bending):
            return self.robot.n_joints
        return int(redundancy(self.robot, self.link_bending)[1].size)

    def reduced_matrices(self) -> dict[str, np.ndarray]:
        """Stiffness and damping in the independent coordinates ``y = P x``: springs in
        series add compliances, ``K_y = (P K^-1 P^T)^-1``; dampers by the quasi-static force
        path, ``C_y = K_y P K^-1 C K^-1 P^T K_y``; ``X = K^-1 P^T K_y`` maps y-shapes to
        element deflections."""
        P, keep = redundancy(self.robot, self.link_bending)
        K, C = elastic_matrices(self.robot, self.link_bending, self.k_Nm_per_rad,
                                self.c_Nms_per_rad)
        Ki = np.linalg.inv(K)
        Ky = np.linalg.inv(P @ Ki @ P.T)
        Ky = 0.5 * (Ky + Ky.T)
        X = Ki @ P.T @ Ky
        Cy = X.T @ C @ X
        return {"P": P, "keep": keep, "K": K, "C": C, "Ky": Ky, "Cy": 0.5 * (Cy + Cy.T),
                "X": X, "Cyinv": P @ Ki @ P.T}

    def __post_init__(self) -> None:
        nj = self.robot.n_joints
        k = np.asarray(self.k_Nm_per_rad, float)
        if k.shape != (nj,) or not np.all(np.isfinite(k)) or np.any(k <= 0):
            raise InputError("joint stiffness must be one positive number per joint",
                             field="joint_stiffness_Nm_per_rad", value=k.tolist(),
                             expected=f"{nj} values > 0 in N m/rad")
        object.__setattr__(self, "k_Nm_per_rad", k)
        object.__setattr__(self, "c_Nms_per_rad",
                           np.broadcast_to(np.asarray(self.c_Nms_per_rad, float), (nj,)).copy())
        if self.link_scale is None:
            object.__setattr__(self, "link_scale", np.ones(nj))
        link_arrays(self.robot, file=self.robot_file)  # inertial data present?
        for lb in self.link_bending:
            c = np.asarray(lb.compliance_per_Nm2, float)
            if c.shape != (2,) or not np.all(np.isfinite(c)) or np.any(c < 0) \
                    or not np.isfinite(lb.damping_s) or lb.damping_s < 0:
                raise InputError("link bending compliance must be two values >= 0 and a "
                                 "damping >= 0", field=f"link_bending.link{lb.link}",
                                 value=c.tolist(), expected="1/EI in 1/(N m^2), >= 0; "
                                 "damping_s in s, >= 0")
            beam_geometry(self.robot, lb)

    def inertial_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        m, c, inertia = link_arrays(self.robot, file=self.robot_file)
        s = np.asarray(self.link_scale, float)
        m = m * s
        inertia = inertia * s[:, None, None]
        return _merge_tool(m, c, inertia, self.tool, np.zeros(3))

    def mass_matrix(self, Q_rad: Any) -> np.ndarray:
        m, c, inertia = self.inertial_arrays()
        return mass_matrix(self.robot, Q_rad, m, c, inertia)

    def modes(self, Q_rad: Any, frame: str | np.ndarray = "boring") -> PostureModes:
        """Modes, tool-point modal vectors and compliance at postures Q (n, nj) or (nj,)."""
        Q = np.atleast_2d(np.asarray(Q_rad, float))
        T, J = fk_jacobian(self.robot, Q, self.tcp_m)
        R = self._frames(T, Q, frame)
        if _planes(self.link_bending):
            return self._modes_elastic(Q, T, R)
        M = self.mass_matrix(Q)
        kis = 1.0 / np.sqrt(self.k_Nm_per_rad)
        A = M * kis[None, :, None] * kis[None, None, :]
        mu, V = np.linalg.eigh(A)  # mu = 1 / w^2, ascending -> w descending
        mu = mu[:, ::-1]
        V = V[:, :, ::-1]
        if np.any(mu <= 0):
            raise InputError("the mass matrix is not positive definite at a posture",
                             expected="positive link masses/inertias")
        w = 1.0 / np.sqrt(mu)
        phi = kis[None, :, None] * V * w[:, None, :]  # mass-normalised
        zeta = np.einsum("i,nij->nj", self.c_Nms_per_rad, phi ** 2) / (2 * w)
        Jv = J[:, :3, :]
        u = np.einsum("nab,nbi,nij->nja", np.swapaxes(R, 1, 2), Jv, phi)
        Cq = np.einsum("nai,i,nbi->nab", np.einsum("nba,nbi->nai", R, Jv),
                       1.0 / self.k_Nm_per_rad, np.einsum("nba,nbi->nai", R, Jv))
        return PostureModes(w / (2 * np.pi), zeta, u, phi, Cq, np.asarray(R), T)

    @staticmethod
    def _frames(T: np.ndarray, Q: np.ndarray, frame: str | np.ndarray) -> np.ndarray:
        if isinstance(frame, str) and frame == "boring":
            return boring_frames(T)
        if isinstance(frame, str):
            return np.stack([process_frame(t[:3, :3], frame) for t in T])
        return np.broadcast_to(np.asarray(frame, float), (Q.shape[0], 3, 3))

    def elastic_mass_matrix(self, Q: np.ndarray) -> np.ndarray:
        """Mass matrix (n, n_dof, n_dof) over the independent joint and bending coordinates
        (:meth:`reduced_matrices`): every link moves rigidly with the joints before it and
        with the bending of the links before it (a link's own mass stays on its proximal
        joint: lumped masses of the virtual-joint method)."""
        m, c, inertia = self.inertial_arrays()
        keep = redundancy(self.robot, self.link_bending)[1]
        sc = self._screws(Q, keep)
        R, O = sc["R"], sc["O"]
        n = Q.shape[0]
        M = np.zeros((n, keep.size, keep.size))
        for b in range(self.robot.n_joints):
            x = O[:, b + 1] + np.einsum("nij,j->ni", R[:, b + 1], c[b])
            Jv, Jw = _point_jacobian(sc, x)
            mask = (sc["first_body"] <= b).astype(float)
            Jv = Jv * mask
            Jw = Jw * mask
            Iw = R[:, b + 1] @ inertia[b] @ np.swapaxes(R[:, b + 1], 1, 2)
            M += m[b] * np.einsum("nai,naj->nij", Jv, Jv) + \
                np.einsum("nai,nab,nbj->nij", Jw, Iw, Jw)
        return M

    def _screws(self, Q: np.ndarray, keep: np.ndarray) -> dict[str, Any]:
        sc = elastic_screws(self.robot, Q, self.link_bending)
        for key in ("w", "p", "v0"):
            sc[key] = sc[key][:, keep]
        sc["first_body"] = sc["first_body"][keep]
        return sc

    def _modes_elastic(self, Q: np.ndarray, T: np.ndarray, R: np.ndarray) -> PostureModes:
        """Modes with link bending: ``K_y phi = w^2 M phi`` in the independent coordinates
        (Cholesky ``K_y = L L^T``; ``L^-1 M L^-T`` symmetric); ``phi`` (n, n_dof, n_dof)
        holds the shapes in those coordinates."""
        rm = self.reduced_matrices()
        M = self.elastic_mass_matrix(Q)
        Lc = np.linalg.cholesky(rm["Ky"])
        Li = np.linalg.inv(Lc)
        A = Li[None] @ M @ Li.T[None]
        mu, V = np.linalg.eigh(A)
        mu, V = mu[:, ::-1], V[:, :, ::-1]
        if np.any(mu <= 0):
            raise InputError("the mass matrix is not positive definite at a posture",
                             expected="positive link masses/inertias")
        w = 1.0 / np.sqrt(mu)
        phi = (Li.T[None] @ V) * w[:, None, :]
        zeta = np.einsum("nij,ik,nkj->nj", phi, rm["Cy"], phi) / (2 * w)
        sc = self._screws(Q, rm["keep"])
        Jv, _ = _point_jacobian(sc, T[:, :3, 3])
        Jp = np.einsum("nba,nbi->nai", R, Jv)  # process frame
        u = np.einsum("nai,nij->nja", Jp, phi)
        Cq = np.einsum("nai,ij,nbj->nab", Jp, rm["Cyinv"], Jp)
        return PostureModes(w / (2 * np.pi), zeta, u, phi, Cq, np.asarray(R), T)

    def equivalent(self, q_rad: Any):
        """The paper's equivalent model (per direction m, k, c) at posture q, boring frame.

        Directional stiffness from the compliance; each axis takes the lowest mode whose
        tool-point direction is largest on it (:meth:`EquivalentModel.from_stiffness_and_modes`).
        """
        from robobore.equivalent import EquivalentModel

        pm = self.modes(np.asarray(q_rad, float))
        ks = dict(zip("xyz", (float(v) for v in pm.directional_stiffness[0]), strict=True))
        modes = [{"frequency_Hz": float(f), "damping_ratio": float(z), "direction": list(u)}
                 for f, z, u in zip(pm.frequency_Hz[0], pm.damping_ratio[0], pm.u[0],
                                    strict=True)]
        return EquivalentModel.from_stiffness_and_modes(
            {"directional_stiffness_N_per_m": ks}, {"modes": modes})


@dataclass(frozen=True)
class Calibration:
    """Result of :func:`calibrate`: the calibrated model and how well it matches."""

    model: PoseModel
    matched: int
    identified_frequency_Hz: np.ndarray
    model_frequency_Hz: np.ndarray
    identified_damping_ratio: np.ndarray
    model_damping_ratio: np.ndarray
    uncalibrated_frequency_Hz: np.ndarray
    model_modes: tuple[int, ...] = ()

    @property
    def frequency_error_percent(self) -> np.ndarray:
        return 100 * (self.model_frequency_Hz / self.identified_frequency_Hz - 1)

    def to_dict(self) -> dict[str, Any]:
        return {
            "matched_modes": self.matched,
            "model_mode_of_identified": [int(i) + 1 for i in self.model_modes],
            "link_scale": [float(v) for v in self.model.link_scale],
            "joint_damping_Nms_per_rad": [float(v) for v in self.model.c_Nms_per_rad],
            "link_bending": [{"link": lb.link,
                              "EI_Nm2": [float(1 / c) if c > 0 else None
                                         for c in lb.compliance_per_Nm2],
                              "damping_s": lb.damping_s} for lb in self.model.link_bending],
            "identified_frequency_Hz": self.identified_frequency_Hz.tolist(),
            "model_frequency_Hz": self.model_frequency_Hz.tolist(),
            "uncalibrated_frequency_Hz": self.uncalibrated_frequency_Hz.tolist(),
            "frequency_residual_percent": self.frequency_error_percent.tolist(),
            "rms_frequency_residual_percent": float(np.sqrt(np.mean(
                self.frequency_error_percent ** 2))),
            "identified_damping_ratio": self.identified_damping_ratio.tolist(),
            "model_damping_ratio": self.model_damping_ratio.tolist(),
            "damping_residual_percent": (100 * (self.model_damping_ratio
                                                / self.identified_damping_ratio - 1)).tolist(),
        }


def fit_joint_damping(phi: np.ndarray, w: np.ndarray, zeta: np.ndarray, k: np.ndarray,
                      regularisation: float = 0.01) -> np.ndarray:
    """Joint dampers ``c_i >= 0`` [N m s/rad] from modal damping ratios (see module docstring).

    ``phi`` (nj, m) mass-normalised shapes of the matched modes, ``w`` (m,) rad/s, ``zeta``
    (m,). Written as ``c_i = r_i beta k_i`` with ``beta`` the common stiffness-proportional
    coefficient that fits the modes best in the least-squares sense; ``r_i >= 0`` solve the
    relative equations ``sum_i phi_ij^2 r_i beta k_i / (2 zeta_j w_j) = 1`` with a pull
    ``regularisation (r_i - 1) = 0``. A joint that no identified mode moves keeps the common
    coefficient (``r_i = 1``) instead of an arbitrary value, so that modes it dominates at
    other postures stay damped.
    """
    G = (phi ** 2).T * k[None, :]  # (m, nj): 2 zeta w = G beta_i
    return fit_proportional_damping(G, w, zeta, regularisation) * k


def fit_proportional_damping(G: np.ndarray, w: np.ndarray, zeta: np.ndarray,
                             regularisation: float = 0.01) -> np.ndarray:
    """Stiffness-proportional damping coefficients ``beta_i >= 0`` [s] of elastic elements
    (damper = ``beta_i`` times the element's stiffness) from ``2 zeta_j w_j = sum_i G_ji
    beta_i``, ``G_ji = phi_j^T K_i phi_j`` the modal strain energy of element i in mode j;
    ``beta_i = r_i beta`` with the common ``beta`` and a pull ``r_i -> 1`` (see
    :func:`fit_joint_damping`)."""
    from scipy.optimize import lsq_linear

    y = 2 * zeta * w
    ne = G.shape[1]
    if not np.any(y > 0):
        return np.zeros(ne)
    gs = G.sum(axis=1)
    beta = float(np.sum(gs * y) / np.sum(gs * gs))
    A = np.vstack([G * beta / y[:, None], regularisation * np.eye(ne)])
    b = np.concatenate([np.ones(y.size), regularisation * np.ones(ne)])
    r = lsq_linear(A, b, bounds=(0.0, np.inf)).x
    return r * beta


def calibrate(model: PoseModel, q_meas_rad: Any, frequency_Hz: Any, damping_ratio: Any, *,
              scale_bounds: tuple[float, float] = (0.25, 4.0),
              regularisation: float = 0.05,
              damping_regularisation: float = 0.01) -> Calibration:
    """Fit link scale factors and joint dampers so the modes at ``q_meas`` match (see module
    docstring). ``frequency_Hz``/``damping_ratio``: the identified modes (any order)."""
    from scipy.optimize import least_squares

    f_id = np.asarray(frequency_Hz, float)
    z_id = np.asarray(damping_ratio, float)
    order = np.argsort(f_id)
    f_id, z_id = f_id[order], z_id[order]
    nj = model.robot.n_joints
    nm = min(f_id.size, nj)
    if nm < 1:
        raise InputError("no identified modes to calibrate to", field="modes",
                         expected="at least one mode")
    f_id, z_id = f_id[:nm], z_id[:nm]
    q = np.asarray(q_meas_rad, float)
    f0_all = model.modes(q).frequency_Hz[0]

    import itertools

    lo, hi = np.log(scale_bounds[0]), np.log(scale_bounds[1])
    sol = None
    pick: tuple[int, ...] = tuple(range(nm))
    # identified mode j <-> model mode pick[j], order preserved; every choice of nm of the
    # model's modes is tried (the test may miss a mode the model has) and the best fit kept
    for sel in itertools.combinations(range(nj), nm):
        def resid(x: np.ndarray, sel: tuple[int, ...] = sel) -> np.ndarray:
            m = replace(model, link_scale=np.exp(x))
            f = m.modes(q).frequency_Hz[0, list(sel)]
            return np.concatenate([np.log(f / f_id), regularisation * x])

        s_ = least_squares(resid, np.zeros(nj), bounds=(np.full(nj, lo), np.full(nj, hi)),
                           x_scale=1.0, xtol=1e-10, ftol=1e-12)
        if sol is None or s_.cost < sol.cost - 1e-15:
            sol, pick = s_, sel
    m1 = replace(model, link_scale=np.exp(sol.x))
    pm = m1.modes(q)
    sel = list(pick)
    w = 2 * np.pi * pm.frequency_Hz[0, sel]
    if m1.n_dof == nj:
        c = fit_joint_damping(pm.phi[0][:, sel], w, z_id, model.k_Nm_per_rad,
                              damping_regularisation)
        m2 = replace(m1, c_Nms_per_rad=c)
    else:  # joints and bending links: stiffness-proportional dampers per element
        rm = m1.reduced_matrices()
        ph = rm["X"] @ pm.phi[0][:, sel]  # element deflections of the matched modes
        K = rm["K"]
        G = [ph[i] ** 2 * m1.k_Nm_per_rad[i] for i in range(nj)]
        j = nj
        for lb in m1.link_bending:
            s_ = slice(j, j + 2 * len(_planes((lb,))))
            G.append(np.einsum("ij,ik,kj->j", ph[s_], K[s_, s_], ph[s_]))
            j = s_.stop
        beta = fit_proportional_damping(np.array(G).T, w, z_id, damping_regularisation)
        lbs = tuple(replace(lb, damping_s=float(b)) for lb, b in
                    zip(m1.link_bending, beta[nj:], strict=True))
        m2 = replace(m1, c_Nms_per_rad=beta[:nj] * m1.k_Nm_per_rad, link_bending=lbs)
    pm2 = m2.modes(q)
    return Calibration(m2, nm, f_id, pm2.frequency_Hz[0, sel], z_id,
                       pm2.damping_ratio[0, sel], f0_all[sel], tuple(pick))


__all__ = ["ToolBody", "PoseModel", "PostureModes", "Calibration", "calibrate", "LinkBending",
           "compliance_basis", "elastic_screws", "elastic_matrices", "link_frames", "redundancy",
           "link_arrays", "mass_matrix", "boring_frames"]
