"""Link compliance of a serial robot by the virtual-joint method.

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
from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.errors import InputError
from robobore.robot.description import Robot
from robobore.robot.kinematics import fk_jacobian


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


def compliant_planes(bending: tuple[LinkBending, ...]) -> list[tuple[LinkBending, int]]:
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
    planes = compliant_planes(bending)
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


def point_jacobian(sc: dict[str, Any], x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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
    planes = compliant_planes(bending)
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
    Jv, Jw = point_jacobian(sc, T[:, :3, 3])
    J = np.concatenate([Jv, Jw], axis=1)  # (n, 6, ndof)
    nj = robot.n_joints
    out = [np.einsum("na,nb->nab", J[:, :, i], J[:, :, i]) for i in range(nj)]
    for j in range(len(sc["planes"])):
        G = J[:, :, nj + 2 * j: nj + 2 * j + 2]
        out.append(np.einsum("nai,ij,nbj->nab", G, beam_block(sc["plane_length_m"][j]), G))
    return np.stack(out, axis=1)


__all__ = ["LinkBending", "link_frames", "beam_geometry", "compliant_planes", "beam_block",
           "elastic_screws", "point_jacobian", "redundancy", "elastic_matrices",
           "compliance_basis"]
