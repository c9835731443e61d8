"""SYNTHETIC richer-truth robot for validating the pose-dependent model.

Ground truth (documented, generated here; nothing is measured):

* the IRB 6600-175/2.55 kinematics of the library;
* joint springs ``TRUTH_JOINT_K`` [N m/rad] and joint dampers ``TRUTH_JOINT_C`` [N m s/rad];
* link BENDING: the lower arm (link 2) and the forearm (link 4) each get two extra
  rotational degrees of freedom at mid-length, about the two axes normal to the link, with
  springs ``TRUTH_BEND_K`` and dampers ``TRUTH_BEND_C`` (a lumped model of a flexible beam:
  the outer half of the link and everything beyond it rotate about the mid-point);
* DISTRIBUTED masses: every link's mass (the library value times ``TRUTH_MASS_FACTOR``) is
  split into ``N_POINTS`` point masses along its length plus a rigid remainder carrying
  ``RIGID_SHARE`` of the mass with the library's centre of mass and inertia (scaled);
* the end effector of the plan example (60 kg, centre of mass 0.15 m along flange z).

So the truth has 10 degrees of freedom, posture-dependent link compliance that joint springs
cannot represent exactly, and a mass distribution different from the library's estimates.

What the planner's model sees (:func:`identify_from_truth`): joint stiffnesses (and, with
``link_bending=True``, the bending compliances of the lower arm and the forearm as
Euler-Bernoulli beams) fitted, like a stiffness campaign does, by non-negative least squares
of the 6x6 tool-point compliance over ``campaign`` postures; and the truth's
modes below 60 Hz at the measured posture, as a hammer test would give them. It then
calibrates the library-based model there (:func:`robobore.plan.model.calibrate`) and
predicts at held-out postures (:func:`validation_postures`).

Truth mechanics: body positions/orientations from a chain of 4x4 transforms; Jacobians by
central differences (step 1e-6 rad; error ~1e-10 relative); ``M = sum m J_v^T J_v +
J_w^T I J_w``, ``K = diag(k)``, modes by ``eigh``, modal damping as in the planner's model.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.plan.inertia import ToolBody
from robobore.plan.model import PoseModel
from robobore.robot.description import Robot, get_robot
from robobore.robot.kinematics import rotation_vector

TRUTH_JOINT_K = np.array([3.2e6, 4.2e6, 2.5e6, 4.8e5, 4.4e5, 2.6e5])
TRUTH_JOINT_C = np.array([3000.0, 3500.0, 900.0, 150.0, 80.0, 30.0])
#: lower-arm bending (two axes), forearm bending (two axes), N m/rad: a mid-length hinge
#: with ``k = 3 E I / (4 L)`` has the tip deflection ``F L^3 / (3 E I)`` of a cantilever.
#: Sections (ASSUMED, typical of this robot size): lower arm a box 0.35 x 0.30 m with 20 mm
#: walls, L = 1.075 m; forearm a tube of 0.25 m diameter with 20 mm wall, L = 1.142 m;
#: nodular cast iron E = 170 GPa.
E_LINK_PA = 170e9


def _box_I(b: float, h: float, t: float) -> float:
    return (b * h ** 3 - (b - 2 * t) * (h - 2 * t) ** 3) / 12


_I_TUBE = np.pi / 64 * (0.25 ** 4 - 0.21 ** 4)
TRUTH_BEND_K = np.array([3 * E_LINK_PA * _box_I(0.35, 0.30, 0.02) / (4 * 1.075),
                         3 * E_LINK_PA * _box_I(0.30, 0.35, 0.02) / (4 * 1.075),
                         3 * E_LINK_PA * _I_TUBE / (4 * 1.142),
                         3 * E_LINK_PA * _I_TUBE / (4 * 1.142)])
TRUTH_BEND_C = np.array([2000.0, 2000.0, 400.0, 400.0])
TRUTH_MASS_FACTOR = np.array([1.15, 0.85, 1.25, 0.8, 1.1, 1.0])
N_POINTS = 6
RIGID_SHARE = 0.4
TOOL = ToolBody(60.0, (0.0, 0.0, 0.15), (0.95, 0.95, 0.30, 0.0, 0.0, 0.0))
PAPER_Q_DEG = np.array([-48.38, 54.82, 6.86, -54.16, 107.43, -21.95])


def _rz(t: float) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    return T


def _rx(t: float) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    T = np.eye(4)
    T[1:3, 1:3] = [[c, -s], [s, c]]
    return T


def _ry(t: float) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    T = np.eye(4)
    T[0, 0], T[0, 2], T[2, 0], T[2, 2] = c, s, -s, c
    return T


def _tr(x: float, y: float, z: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


@dataclass(frozen=True)
class TruthRobot:
    """The SYNTHETIC 10-DOF truth (module docstring)."""

    robot: Robot
    tcp_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    bend_scale: float = 1.0

    @property
    def n_dof(self) -> int:
        return 10

    def stiffness(self) -> np.ndarray:
        return np.concatenate([TRUTH_JOINT_K, self.bend_scale * TRUTH_BEND_K])

    def damping(self) -> np.ndarray:
        return np.concatenate([TRUTH_JOINT_C, TRUTH_BEND_C])

    def bodies(self, x: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
        """World transforms of every body (list of 4x4) and the tool transform, at x (10,).

        Body list order matches :meth:`body_data`."""
        rb = self.robot
        d, a, al, off = rb.dh_arrays
        q, bend = x[:6], x[6:]
        n = N_POINTS
        out: list[np.ndarray] = []
        T = rb.base.copy()
        # link 1 (rigid remainder + points along its a1 offset)
        T1 = T @ _rz(q[0] + off[0]) @ _tr(0, 0, d[0]) @ _tr(a[0], 0, 0) @ _rx(al[0])
        out.append(T1)
        for s in (np.arange(n) + 0.5) / n:  # points from the axis-1 column to frame 1
            out.append(T @ _rz(q[0] + off[0]) @ _tr(a[0] * s, 0, d[0] * s))
        # link 2 with mid-length bending
        Tj = T1 @ _rz(q[1] + off[1])
        Tmid = Tj @ _tr(a[1] / 2, 0, 0)
        Tb = Tmid @ _ry(bend[0]) @ _rz(bend[1])
        T2 = Tb @ _tr(a[1] / 2, 0, 0) @ _rx(al[1])
        out.append(T2)
        for s in (np.arange(n) + 0.5) / n:
            if s < 0.5:
                out.append(Tj @ _tr(a[1] * s, 0, 0))
            else:
                out.append(Tb @ _tr(a[1] * (s - 0.5), 0, 0))
        # link 3 (housing at the elbow)
        T3 = T2 @ _rz(q[2] + off[2]) @ _tr(0, 0, d[2]) @ _tr(a[2], 0, 0) @ _rx(al[2])
        out.append(T3)
        for s in (np.arange(n) + 0.5) / n:
            out.append(T2 @ _rz(q[2] + off[2]) @ _tr(a[2] * s, 0, 0))
        # link 4 (forearm, along z3) with mid-length bending
        Tj = T3 @ _rz(q[3] + off[3])
        Tmid = Tj @ _tr(0, 0, d[3] / 2)
        Tb = Tmid @ _rx(bend[2]) @ _ry(bend[3])
        T4 = Tb @ _tr(0, 0, d[3] / 2) @ _tr(a[3], 0, 0) @ _rx(al[3])
        out.append(T4)
        for s in (np.arange(n) + 0.5) / n:
            if s < 0.5:
                out.append(Tj @ _tr(0, 0, d[3] * s))
            else:
                out.append(Tb @ _tr(0, 0, d[3] * (s - 0.5)))
        T5 = T4 @ _rz(q[4] + off[4]) @ _tr(0, 0, d[4]) @ _tr(a[4], 0, 0) @ _rx(al[4])
        out.append(T5)
        T6 = T5 @ _rz(q[5] + off[5]) @ _tr(0, 0, d[5]) @ _tr(a[5], 0, 0) @ _rx(al[5])
        out.append(T6)
        Tt = T6 @ _tr(*self.tcp_m)
        return out, Tt

    def body_data(self) -> list[tuple[float, np.ndarray, np.ndarray]]:
        """(mass, centre of mass in the body frame, inertia about it) per body."""
        rb = self.robot
        out = []
        for i, li in enumerate(rb.links):
            m = li.mass_kg * TRUTH_MASS_FACTOR[i]
            inertia = li.tensor() * TRUTH_MASS_FACTOR[i]
            if i in (0, 1, 2, 3):
                out.append((RIGID_SHARE * m, np.asarray(li.com_m), RIGID_SHARE * inertia))
                for _ in range(N_POINTS):
                    out.append(((1 - RIGID_SHARE) * m / N_POINTS, np.zeros(3), np.zeros((3, 3))))
            elif i == 4:
                out.append((m, np.asarray(li.com_m), inertia))
            else:  # flange + end effector
                mt = m + TOOL.mass_kg
                c1, c2 = np.asarray(li.com_m), np.asarray(TOOL.com_m)
                ct = (m * c1 + TOOL.mass_kg * c2) / mt

                def sh(mm: float, dd: np.ndarray) -> np.ndarray:
                    return mm * (float(dd @ dd) * np.eye(3) - np.outer(dd, dd))

                It = inertia + sh(m, c1 - ct) + TOOL.tensor() + sh(TOOL.mass_kg, c2 - ct)
                out.append((mt, ct, It))
        return out

    def _state(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        bodies, Tt = self.bodies(x)
        data = self.body_data()
        P = np.array([T[:3, :3] @ c + T[:3, 3] for T, (_, c, _) in zip(bodies, data,
                                                                         strict=True)])
        R = np.array([T[:3, :3] for T in bodies])
        return P, R, Tt

    def matrices(self, q_rad: np.ndarray, h: float = 1e-6) -> dict[str, np.ndarray]:
        """Mass matrix (10x10), tool Jacobian (6x10) and tool transform at the undeformed
        posture q (bending 0)."""
        x0 = np.concatenate([np.asarray(q_rad, float), np.zeros(4)])
        nd = x0.size
        data = self.body_data()
        nb = len(data)
        Jv = np.zeros((nb, 3, nd))
        Jw = np.zeros((nb, 3, nd))
        Jt = np.zeros((6, nd))
        _, R0, T0 = self._state(x0)
        for k in range(nd):
            e = np.zeros(nd)
            e[k] = h
            Pp, Rp, Tp = self._state(x0 + e)
            Pm, Rm, Tm = self._state(x0 - e)
            Jv[:, :, k] = (Pp - Pm) / (2 * h)
            Jw[:, :, k] = rotation_vector(Rp @ np.swapaxes(Rm, 1, 2)) / (2 * h)
            Jt[:3, k] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
            Jt[3:, k] = rotation_vector(Tp[:3, :3] @ Tm[:3, :3].T) / (2 * h)
        M = np.zeros((nd, nd))
        for b, (m, _, inertia) in enumerate(data):
            Iw = R0[b] @ inertia @ R0[b].T
            M += m * Jv[b].T @ Jv[b] + Jw[b].T @ Iw @ Jw[b]
        return {"M": M, "J": Jt, "T": T0}

    def evaluate(self, q_rad: np.ndarray, R_process: np.ndarray | None = None
                 ) -> dict[str, Any]:
        """Truth modes (ascending), damping ratios, tool compliance, directional stiffness
        (boring frame unless ``R_process`` is given)."""
        from robobore.robot.stiffness import process_frame

        mats = self.matrices(q_rad)
        K = self.stiffness()
        kis = 1 / np.sqrt(K)
        A = mats["M"] * kis[:, None] * kis[None, :]
        mu, V = np.linalg.eigh(A)
        mu, V = mu[::-1], V[:, ::-1]
        w = 1 / np.sqrt(mu)
        phi = kis[:, None] * V * w[None, :]
        zeta = (self.damping() @ phi ** 2) / (2 * w)
        R = process_frame(mats["T"][:3, :3], "boring") if R_process is None else R_process
        Jv = R.T @ mats["J"][:3]
        C = Jv @ np.diag(1 / K) @ Jv.T
        C6 = mats["J"] @ np.diag(1 / K) @ mats["J"].T
        return {"frequency_Hz": w / (2 * np.pi), "damping_ratio": zeta, "compliance": C,
                "compliance6": C6, "J": mats["J"],
                "directional_stiffness": 1 / np.diag(C)}

    def bending_share(self, q_rad: np.ndarray) -> float:
        """Share of the tool-point translational compliance (trace) due to link bending."""
        mats = self.matrices(q_rad)
        K = self.stiffness()
        Jv = mats["J"][:3]
        tot = np.trace(Jv @ np.diag(1 / K) @ Jv.T)
        bend = np.trace(Jv[:, 6:] @ np.diag(1 / K[6:]) @ Jv[:, 6:].T)
        return float(bend / tot)


def campaign_postures(n: int = 12, seed: int = 7) -> np.ndarray:
    """Stiffness-campaign postures (rad), spread like a measurement campaign."""
    rng = np.random.default_rng(seed)
    lo = np.radians([-90, -30, -90, -150, 30, -180])
    hi = np.radians([90, 60, 30, 150, 120, 180])
    return rng.uniform(lo, hi, (n, 6))


def validation_postures(n: int = 24, seed: int = 11, margin: float = 0.05) -> np.ndarray:
    """Held-out postures (rad) over the workspace: uniform in q1 [-120, 120], q2 [-40, 70],
    q3 [-120, 40], q4 [-170, 170], q5 [25, 120], q6 [-180, 180] deg, keeping those at least
    ``margin`` from a singularity (:func:`robobore.plan.candidates.singularity_measure`; near a
    singularity the stiffness along the stretched direction comes from what the joint springs
    leave out, link flexibility, and a joint-spring model cannot predict it)."""
    from robobore.plan.candidates import singularity_measure
    from robobore.robot.kinematics import jacobian

    robot = get_robot("irb6600-175-2.55")
    rng = np.random.default_rng(seed)
    lo = np.radians([-120, -40, -120, -170, 25, -180])
    hi = np.radians([120, 70, 40, 170, 120, 180])
    out: list[np.ndarray] = []
    while len(out) < n:
        Q = rng.uniform(lo, hi, (4 * n, 6))
        s = singularity_measure(robot, jacobian(robot, Q))
        out.extend(Q[s >= margin])
    return np.array(out[:n])


def identify_from_truth(truth: TruthRobot, campaign: np.ndarray,
                        bending_links: tuple[int, ...] = ()
                        ) -> tuple[np.ndarray, np.ndarray] | tuple[np.ndarray, np.ndarray,
                                                                   np.ndarray]:
    """Joint stiffnesses fitted to the truth's 6x6 tool compliance over the campaign (NNLS on
    the joint compliances 1/k; rotations scaled by 1 m). Returns (k, relative residual).

    With ``bending_links`` (1-based links, e.g. ``(2, 4)``) the fit also has the bending
    compliances 1/EI of those links as Euler-Bernoulli beams (virtual-joint method,
    :func:`robobore.plan.bending.compliance_basis`: the compliance stays linear in the
    unknowns); returns (k, relative residual, 1/EI per link and plane (n_links, 2))."""
    from scipy.optimize import nnls

    from robobore.plan.bending import compliance_basis

    nj = truth.robot.n_joints
    iu = np.triu_indices(6)
    B = compliance_basis(truth.robot, campaign, truth.tcp_m, tuple(bending_links))
    rows, rhs = [], []
    for i, q in enumerate(campaign):
        ev = truth.evaluate(q)
        rows.append(B[i][:, iu[0], iu[1]].T)
        rhs.append(ev["compliance6"][iu])
    Amat = np.vstack(rows)
    b = np.concatenate(rhs)
    scale = np.abs(Amat).max(axis=0)
    c, res = nnls(Amat / scale, b)
    c = c / scale
    rel = np.array([res / np.linalg.norm(b)])
    if not bending_links:
        return 1.0 / c, rel
    return 1.0 / c[:nj], rel, c[nj:].reshape(-1, 2)


def run_validation(n_heldout: int = 24, f_max_Hz: float = 60.0,
                   bend_scale: float = 1.0, link_bending: bool = False) -> dict[str, Any]:
    """Identify + calibrate at the paper's posture, predict at held-out postures; errors.

    ``bend_scale`` multiplies the truth's bending springs (0.5: links twice as flexible, a
    sensitivity case). ``link_bending``: the planner's model also has the lower arm and the
    forearm as Euler-Bernoulli beams (:class:`robobore.plan.bending.LinkBending`), their
    compliances identified with the joint compliances from the same campaign."""
    from robobore.plan.bending import LinkBending
    from robobore.plan.model import calibrate

    robot = get_robot("irb6600-175-2.55")
    truth = TruthRobot(robot, bend_scale=bend_scale)
    bend: tuple[LinkBending, ...] = ()
    if link_bending:
        k_id, res, cb = identify_from_truth(truth, campaign_postures(), (2, 4))
        bend = (LinkBending(2, (float(cb[0, 0]), float(cb[0, 1]))),
                LinkBending(4, (float(cb[1, 0]), float(cb[1, 1]))))
    else:
        k_id, res = identify_from_truth(truth, campaign_postures())
    q0 = np.radians(PAPER_Q_DEG)
    ev0 = truth.evaluate(q0)
    sel = ev0["frequency_Hz"] < f_max_Hz
    model = PoseModel(robot, k_id, np.zeros(6), tool=TOOL, link_bending=bend)
    cal = calibrate(model, q0, ev0["frequency_Hz"][sel], ev0["damping_ratio"][sel])
    Q = validation_postures(n_heldout)
    pm = cal.model.modes(Q)
    ferr, kerr, spread = [], [], []
    T0 = truth.evaluate(q0)
    for i, q in enumerate(Q):
        ev = truth.evaluate(q, R_process=pm.R[i])
        ferr.append(pm.frequency_Hz[i, :3] / ev["frequency_Hz"][:3] - 1)
        kerr.append(pm.directional_stiffness[i] / ev["directional_stiffness"] - 1)
        spread.append(ev["frequency_Hz"][:3] / T0["frequency_Hz"][:3])
    from robobore.robot.kinematics import fk

    p0 = fk(robot, q0)[:3, 3]
    dist = np.linalg.norm(fk(robot, Q)[:, :3, 3] - p0, axis=1)
    ferr, kerr, spread = np.array(ferr), np.array(kerr), np.array(spread)
    bshare = np.array([truth.bending_share(q) for q in Q])
    return {
        "synthetic": True,
        "bend_scale": bend_scale,
        "model_link_bending": link_bending,
        "identified_bending_EI_Nm2": {f"link{lb.link}": [float(1 / c) if c > 0 else None
                                                         for c in lb.compliance_per_Nm2]
                                      for lb in bend},
        "truth_bending_stiffness_Nm_per_rad": (bend_scale * TRUTH_BEND_K).tolist(),
        "bending_share_heldout_range": [float(bshare.min()), float(bshare.max())],
        "heldout_within_5_percent": {
            "frequencies": int(np.sum(np.abs(ferr).max(axis=1) <= 0.05)),
            "stiffness": int(np.sum(np.abs(kerr).max(axis=1) <= 0.05))},
        "identified_joint_stiffness_Nm_per_rad": k_id.tolist(),
        "truth_joint_stiffness_Nm_per_rad": TRUTH_JOINT_K.tolist(),
        "campaign_fit_relative_residual": float(res[0]),
        "bending_share_at_measured_posture": truth.bending_share(q0),
        "calibration": cal.to_dict(),
        "heldout_postures": int(Q.shape[0]),
        "heldout_distance_from_measured_m": [float(dist.min()), float(dist.max())],
        "truth_frequency_ratio_to_measured_range": [float(spread.min()), float(spread.max())],
        "frequency_error_percent": (100 * ferr).tolist(),
        "stiffness_error_percent": (100 * kerr).tolist(),
        "max_abs_frequency_error_percent": float(100 * np.abs(ferr).max()),
        "max_abs_stiffness_error_percent": float(100 * np.abs(kerr).max()),
        "rms_frequency_error_percent": float(100 * np.sqrt(np.mean(ferr ** 2))),
        "rms_stiffness_error_percent": float(100 * np.sqrt(np.mean(kerr ** 2))),
    }


__all__ = ["TruthRobot", "identify_from_truth", "run_validation", "campaign_postures",
           "validation_postures"]
