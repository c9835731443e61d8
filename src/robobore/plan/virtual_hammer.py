"""Virtual (SYNTHETIC) hammer test of any robot, from its pose-dependent multibody model.

The structure is :class:`robobore.plan.model.PoseModel` at one posture: the robot's rigid
links (masses and inertia tensors of its TOML ``[[links]]``, plus an optional end effector)
on elastic joints with the given joint stiffness. Its modes ``K phi = w^2 M(q) phi``
(mass-normalised) give the tool-point modal vectors ``u_j = R_b^T J_v phi_j`` in the boring
frame, and a hammer test at the tool point in X, Y, Z with accelerometers at the tool point
(``tool_x/y/z``) and at the wrist centre (``wrist_x/y/z``, the point ``d6`` behind the flange
on its axis; boring-frame directions). The static compliance of these modes,
``sum_j u_j u_j^T / w_j^2``, equals ``R_b^T J_v K^-1 J_v^T R_b`` exactly, so the test's
driving-point static stiffness ``1 / H_dd(0)`` is the robot's directional stiffness at that
posture (:func:`robobore.robot.stiffness.directional_stiffness_xyz`).

Damping is ASSUMED: one modal damping ratio for every mode (default 3 %, the order of the
bundled example's 2-5 %), since joint dampers are not identified by a stiffness campaign.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robobore.errors import InputError
from robobore.modal.virtual import ModalTruth

DEFAULT_DAMPING_RATIO = 0.03
OUTPUT_NAMES = ("tool_x", "tool_y", "tool_z", "wrist_x", "wrist_y", "wrist_z")
INPUT_NAMES = ("hammer_x", "hammer_y", "hammer_z")


def robot_truth(robot: Any, joints_deg: Any, joint_stiffness_Nm_per_rad: Any, *,
                tcp_m: Any = (0.0, 0.0, 0.0), damping_ratio: float = DEFAULT_DAMPING_RATIO,
                tool: Any = None) -> tuple[ModalTruth, dict[str, Any]]:
    """The modal truth of ``robot`` (name, TOML path or Robot) at ``joints_deg`` with the joint
    stiffness (N m/rad) -> ``(ModalTruth, info)``; ``info`` holds the robot, the posture, the
    robot's directional stiffness (N/m) and the modes' frequencies."""
    from robobore.plan.inertia import ToolBody
    from robobore.plan.model import PoseModel
    from robobore.robot.description import get_robot
    from robobore.robot.kinematics import fk_jacobian

    rb = get_robot(robot)
    q = np.asarray(joints_deg, float).ravel()
    if q.size != rb.n_joints or not np.all(np.isfinite(q)):
        raise InputError("posture must give every joint", field="joints_deg",
                         value=q.tolist(), expected=f"{rb.n_joints} finite angles in deg")
    k = np.asarray(joint_stiffness_Nm_per_rad, float).ravel()
    if not (0 < damping_ratio < 0.5):
        raise InputError("damping ratio out of range", field="damping_ratio",
                         value=damping_ratio, expected="0 < zeta < 0.5 (e.g. 0.03)")
    model = PoseModel(rb, k, np.zeros(rb.n_joints), tool=tool or ToolBody(),
                      tcp_m=tuple(float(v) for v in tcp_m), robot_file=rb.file)
    qr = np.radians(q)
    pm = model.modes(qr)
    f = pm.frequency_Hz[0]
    u_tool = pm.u[0]  # (nm, 3) boring frame
    R = pm.R[0]
    # wrist centre: d6 behind the flange along its z axis (a spherical wrist's centre)
    d6 = float(rb.d_m[-1])
    _, Jw = fk_jacobian(rb, qr, (0.0, 0.0, -d6))
    Jw = np.asarray(Jw)[:3] if np.ndim(Jw) == 2 else np.asarray(Jw)[0, :3]
    u_wrist = (R.T @ Jw @ pm.phi[0]).T  # (nm, 3)
    phi_out = np.column_stack([u_tool, u_wrist]).T  # (6 outputs, nm)
    truth = ModalTruth(f, np.full(f.size, float(damping_ratio)), phi_out, u_tool.T.copy(),
                       OUTPUT_NAMES, INPUT_NAMES,
                       f"SYNTHETIC virtual hammer test of {rb.name} at "
                       f"{', '.join(f'{v:g}' for v in q)} deg (robobore.plan.virtual_hammer)")
    ks = pm.directional_stiffness[0]
    info = {"robot": rb.name, "robot_file": rb.file, "joints_deg": q.tolist(),
            "joint_stiffness_Nm_per_rad": k.tolist(), "tcp_m": list(map(float, tcp_m)),
            "damping_ratio": float(damping_ratio),
            "directional_stiffness_N_per_m": dict(zip("xyz", map(float, ks), strict=True)),
            "frequencies_Hz": f.tolist()}
    return truth, info


def static_stiffness(truth: ModalTruth) -> dict[str, float]:
    """Driving-point static stiffness ``1 / H_dd(0)`` per hammer direction (N/m) of a truth
    whose inputs are the tool point X, Y, Z."""
    w = 2 * np.pi * truth.frequencies_Hz
    c = np.sum(np.real(truth.phi_in) ** 2 / w[None, :] ** 2, axis=1)
    axes = [n[-1] if n[-1] in "xyz" else n for n in truth.input_names]
    return dict(zip(axes, map(float, 1.0 / c), strict=True))


def sample_rate_for(truth: ModalTruth) -> float:
    """A sample rate for a test of ``truth``: a power of two >= 5x its highest mode, >= 256."""
    return float(max(256.0, 2.0 ** np.ceil(np.log2(5.0 * truth.frequencies_Hz.max()))))


def header_text(info: dict[str, Any]) -> dict[str, str]:
    """UFF 151 header fields naming the robot and the posture (read back by
    :func:`parse_header`)."""
    return {"model_name": f"robot={info['robot']}"[:80],
            "description": ("joints_deg=" + ",".join(f"{v:.6g}" for v in info["joints_deg"]))[:80],
            "program": "robobore virtual hammer test (SYNTHETIC)"}


def parse_header(header: dict[str, str] | None) -> dict[str, Any]:
    """``{"robot", "joints_deg"}`` from a header written by :func:`header_text` (empty when the
    header does not name them)."""
    out: dict[str, Any] = {}
    if not header:
        return out
    name = str(header.get("model_name", "")).strip()
    if name.startswith("robot="):
        out["robot"] = name[len("robot="):].strip()
    desc = str(header.get("description", "")).strip()
    if desc.startswith("joints_deg="):
        try:
            out["joints_deg"] = [float(v) for v in desc[len("joints_deg="):].split(",")]
        except ValueError:
            pass
    return out


__all__ = ["robot_truth", "static_stiffness", "sample_rate_for", "header_text", "parse_header",
           "DEFAULT_DAMPING_RATIO", "OUTPUT_NAMES", "INPUT_NAMES"]
