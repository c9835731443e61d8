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

Optional link compliance (:class:`~robobore.plan.bending.LinkBending`,
:mod:`robobore.plan.bending`): the modes, damping, compliance and FRFs are computed over the
independent joint and bending coordinates (:meth:`PoseModel.reduced_matrices`). The rigid-body
inertia (``M(q)``, the end effector :class:`~robobore.plan.inertia.ToolBody`) is
:mod:`robobore.plan.inertia`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from robobore.errors import InputError
from robobore.plan.bending import (
    LinkBending,
    beam_geometry,
    compliant_planes,
    elastic_matrices,
    elastic_screws,
    point_jacobian,
    redundancy,
)
from robobore.plan.inertia import ToolBody, link_arrays, mass_matrix, merge_tool
from robobore.robot.description import Robot
from robobore.robot.kinematics import fk_jacobian
from robobore.robot.stiffness import process_frame


def boring_frames(T: np.ndarray, x_hint: Any = None) -> np.ndarray:
    """Boring frames (n, 3, 3) for tool transforms (n, 4, 4); see process_frame."""
    return np.stack([process_frame(t[:3, :3], "boring", x_hint=x_hint) for t in T])


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
    #: the boring frame's X hint (base frame; robobore.robot.stiffness.process_frame)
    x_hint: tuple[float, float, float] | None = None

    @property
    def n_dof(self) -> int:
        """Elastic coordinates: the joints plus two per compliant bending plane."""
        if not compliant_planes(self.link_bending):
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
        return merge_tool(m, c, inertia, self.tool, np.zeros(3))

    def mass_matrix(self, Q_rad: Any) -> np.ndarray:
        m, c, inertia = self.inertial_arrays()
        return mass_matrix(self.robot, Q_rad, m, c, inertia)

    def modes(self, Q_rad: Any, frame: str | np.ndarray = "boring") -> PostureModes:
        """Modes, tool-point modal vectors and compliance at postures Q (n, nj) or (nj,)."""
        Q = np.atleast_2d(np.asarray(Q_rad, float))
        T, J = fk_jacobian(self.robot, Q, self.tcp_m)
        R = self._frames(T, Q, frame, self.x_hint)
        if compliant_planes(self.link_bending):
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
    def _frames(T: np.ndarray, Q: np.ndarray, frame: str | np.ndarray,
                x_hint: Any = None) -> np.ndarray:
        if isinstance(frame, str) and frame == "boring":
            return boring_frames(T, x_hint)
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
            Jv, Jw = point_jacobian(sc, x)
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
        Jv, _ = point_jacobian(sc, T[:, :3, 3])
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


#: Link inertia scale factors of :func:`calibrate` are bounded to this range.
SCALE_BOUNDS = (0.25, 4.0)
#: A calibration frequency residual above this [%] is a warning (:meth:`Calibration.warnings`).
CALIBRATION_RESIDUAL_WARN_PERCENT = 10.0


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

    def warnings(self, residual_limit_percent: float = CALIBRATION_RESIDUAL_WARN_PERCENT,
                 scale_bounds: tuple[float, float] = SCALE_BOUNDS) -> list[str]:
        """Plain-language warnings on the calibration: a frequency residual above
        ``residual_limit_percent`` (the model does not reproduce the identified modes) and link
        scale factors at their bounds (the fit wanted more than the model allows)."""
        out = []
        err = np.abs(self.frequency_error_percent)
        for j, e in enumerate(err):
            if e > residual_limit_percent:
                out.append(f"calibration: identified mode {j + 1} "
                           f"({self.identified_frequency_Hz[j]:.4g} Hz) is matched at "
                           f"{self.model_frequency_Hz[j]:.4g} Hz ({e:.3g} % off, above "
                           f"{residual_limit_percent:g} %): the pose-dependent model does not "
                           "reproduce it; its posture ratings are less certain")
        lo, hi = scale_bounds
        at = [i + 1 for i, v in enumerate(self.model.link_scale)
              if v <= lo * (1 + 1e-6) or v >= hi * (1 - 1e-6)]
        if at:
            out.append(f"calibration: link inertia scale factor(s) of link(s) {at} at the bounds "
                       f"{lo:g} / {hi:g}: the link data or the identified modes are unlikely "
                       "for this robot (check the robot file, the modes file and the posture)")
        return out

    def to_dict(self) -> dict[str, Any]:
        return {
            "warnings": self.warnings(),
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
              scale_bounds: tuple[float, float] = SCALE_BOUNDS,
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
            s_ = slice(j, j + 2 * len(compliant_planes((lb,))))
            G.append(np.einsum("ij,ik,kj->j", ph[s_], K[s_, s_], ph[s_]))
            j = s_.stop
        beta = fit_proportional_damping(np.array(G).T, w, z_id, damping_regularisation)
        lbs = tuple(replace(lb, damping_s=float(b)) for lb, b in
                    zip(m1.link_bending, beta[nj:], strict=True))
        m2 = replace(m1, c_Nms_per_rad=beta[:nj] * m1.k_Nm_per_rad, link_bending=lbs)
    pm2 = m2.modes(q)
    return Calibration(m2, nm, f_id, pm2.frequency_Hz[0, sel], z_id,
                       pm2.damping_ratio[0, sel], f0_all[sel], tuple(pick))


__all__ = ["PoseModel", "PostureModes", "Calibration", "calibrate", "boring_frames",
           "fit_joint_damping", "fit_proportional_damping"]
