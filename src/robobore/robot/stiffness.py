"""Joint-space to Cartesian stiffness: compliance, stiffness, CCT, directional stiffness.

Model (lumped joint springs, rigid links; Salisbury 1980, Dumas et al. 2011): with the
geometric Jacobian ``J`` at the tool point (:mod:`robobore.robot.kinematics`) and the diagonal
joint stiffness ``Ktheta = diag(k_1..k_n)`` [N m/rad],

* compliance           ``C = J Ktheta^-1 J^T``       (6x6; [m/N, m/(N m); rad/N, rad/(N m)])
* Cartesian stiffness  ``K = J^-T Ktheta J^-1``      (6x6, needs a square, regular J)
* directional stiffness along a unit vector ``u`` (force along u, everything else free):
  ``k_u = 1 / (u^T C_tt u)`` with ``C_tt`` the translational 3x3 block of ``C`` [N/m].
  Note ``k_u`` is *not* ``u^T K_tt u``: the latter holds the other five coordinates fixed.
* principal stiffnesses: eigen-decomposition of ``C_tt``; ``k_i = 1/lambda_i`` along the
  eigenvectors (orthonormal in the world frame).

Complementary stiffness under load (conservative congruence transformation, Chen & Kao,
*Int. J. Robotics Research* 19(9), 2000, eq. 9-12). Sign convention used here: ``W`` is the
external wrench *acting on the robot* at the tool point (force on the tool, moment about the
tool point), in the world frame. Static equilibrium of the joint springs,
``Ktheta dtheta = J(q + dtheta)^T W``, differentiated, gives

    K_C = J^-T (Ktheta - K_G) J^-1,    K_G = [dJ^T/dq_1 W, ..., dJ^T/dq_n W]   (n x n)

so a load can soften or stiffen the tool point. ``K_G`` is verified in the tests against a
finite-difference tangent of the nonlinear equilibrium.

Frames for directional stiffness: ``"base"`` (world), ``"tool"`` (flange orientation: z =
spindle/feed axis for a spindle mounted along the flange z-axis), ``"boring"`` (the paper's
process frame: Z = tool z = feed, X horizontal, Y = Z x X, i.e. vertical up when the bore is
horizontal), or a user rotation matrix ``R_world_process`` whose columns are the process X,
Y, Z axes in the world frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.errors import ConfigError, IdentificationError, InputError, NumericalError
from robobore.robot.description import Robot, get_robot
from robobore.robot.kinematics import fk_jacobian, jacobian_derivative

FRAMES = ("tool", "base", "boring")
#: a feed axis within this angle of the vertical (deg) is a vertical bore: the boring
#: frame's X is then the base x axis projected onto the plane normal to the feed axis
VERTICAL_TOL_DEG = 1.0


def joint_stiffness_arg(k: Any, name: str = "joint_stiffness") -> Any:
    """The joint stiffnesses the stage accepts, as a :class:`JointStiffness` or an array.

    Accepts the identification stage's object (:class:`~robobore.robot.identify.
    StiffnessIdentification`: its ``joint``), a :class:`JointStiffness`, their dict form
    (the JSON of ``robobore identify stiffness`` or :meth:`JointStiffness.to_dict`) or
    numbers (n,) in N m/rad (returned unchanged). Anything else is an :class:`InputError`
    naming the argument ``name``.
    """
    if isinstance(k, JointStiffness):
        return k
    if isinstance(k, dict):
        return JointStiffness.from_dict(k)
    if isinstance(k, str | bytes) or k is None:
        raise InputError("not joint stiffnesses", field=name, value=k,
                         expected="a StiffnessIdentification, a JointStiffness, its dict "
                                  "form or n numbers in N m/rad")
    joint = getattr(k, "joint", None)  # a StiffnessIdentification (identify imports this module)
    if isinstance(joint, JointStiffness):
        return joint
    if isinstance(k, list | tuple | np.ndarray) or np.isscalar(k):
        return k
    raise InputError("not joint stiffnesses", field=name, value=type(k).__name__,
                     expected="a StiffnessIdentification, a JointStiffness, its dict form "
                              "or n numbers in N m/rad")


def _k_array(k: Any, n: int) -> np.ndarray:
    k = joint_stiffness_arg(k)
    if isinstance(k, JointStiffness):
        k = k.as_array()
    arr = np.asarray(k, float).reshape(-1)
    if arr.size != n:
        raise InputError(f"got {arr.size} joint stiffnesses", field="joint_stiffness",
                         expected=f"{n} values in N m/rad")
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise InputError("joint stiffnesses must be positive finite numbers",
                         field="joint_stiffness", value=arr.tolist(),
                         expected="positive values in N m/rad")
    return arr


def compliance_matrix(J: np.ndarray, k_Nm_per_rad: Any) -> np.ndarray:
    """``C = J diag(1/k) J^T``; J (..., 6, n), k (n,) -> C (..., 6, 6)."""
    J = np.asarray(J, float)
    k = _k_array(k_Nm_per_rad, J.shape[-1])
    return np.einsum("...in,n,...jn->...ij", J, 1.0 / k, J)


def cartesian_stiffness(J: np.ndarray, k_Nm_per_rad: Any, *, cond_max: float = 1e10) -> np.ndarray:
    """``K = J^-T diag(k) J^-1``; J (..., 6, 6) -> K (..., 6, 6).

    Raises NumericalError near a singular posture (cond(J) > ``cond_max``).
    """
    J = np.asarray(J, float)
    if J.shape[-1] != 6 or J.shape[-2] != 6:
        raise InputError("Cartesian stiffness needs a square 6x6 Jacobian (6-joint robot)",
                         value=J.shape[-2:], expected="(6, 6)")
    k = _k_array(k_Nm_per_rad, 6)
    c = np.linalg.cond(J)
    if np.any(~np.isfinite(c)) or np.any(c > cond_max):
        raise NumericalError(f"posture is (near) singular: cond(J) = {np.max(c):.3e}; "
                             "the Cartesian stiffness matrix is not defined there")
    Jinv = np.linalg.inv(J)
    return np.einsum("...ni,n,...nj->...ij", Jinv, k, Jinv)


def geometric_stiffness(robot: Robot, q_rad: Any, wrench: Any, tcp_m: Any = None) -> np.ndarray:
    """``K_G = [dJ^T/dq_1 W, ..., dJ^T/dq_n W]`` (n x n), N m/rad.

    ``wrench`` (6,): external force [N] and moment about the tool point [N m] acting on the
    robot, world frame (Chen & Kao 2000 convention; see module docstring).
    """
    W = np.asarray(wrench, float).reshape(6)
    dJ = jacobian_derivative(robot, q_rad, tcp_m)  # (i, 6, j)
    # column i of K_G: dJ^T/dq_i W  -> entry (j, i) = sum_r dJ[i, r, j] W[r]
    return np.einsum("irj,r->ji", dJ, W)


def complementary_stiffness(
    robot: Robot, q_rad: Any, k_Nm_per_rad: Any, wrench: Any, tcp_m: Any = None
) -> np.ndarray:
    """Cartesian stiffness under load ``K_C = J^-T (Ktheta - K_G) J^-1`` (6x6), CCT.

    ``wrench`` is the external wrench on the robot at the tool point (force N, moment N m),
    world frame. With ``wrench = 0`` this is :func:`cartesian_stiffness`.
    """
    _, J = fk_jacobian(robot, np.asarray(q_rad, float), tcp_m)
    k = _k_array(k_Nm_per_rad, robot.n_joints)
    KG = geometric_stiffness(robot, q_rad, wrench, tcp_m)
    Jinv = np.linalg.inv(J)
    return Jinv.T @ (np.diag(k) - KG) @ Jinv


def directional_stiffness(C: np.ndarray, u: Any) -> np.ndarray:
    """``k_u = 1/(u^T C_tt u)`` [N/m]; C (..., 6, 6) or (..., 3, 3), u (3,) or (m, 3)."""
    C = np.asarray(C, float)[..., :3, :3]
    u = np.asarray(u, float)
    u = u / np.linalg.norm(u, axis=-1, keepdims=True)
    if u.ndim == 1:
        return 1.0 / np.einsum("i,...ij,j->...", u, C, u)
    return 1.0 / np.einsum("mi,...ij,mj->...m", u, C, u)


def principal_stiffness(C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Principal translational stiffnesses and directions from a compliance matrix.

    Returns ``k`` (3,) [N/m], stiffest first, and ``V`` (3, 3) whose columns are the
    corresponding unit directions (world frame; right-handed).
    """
    Ctt = np.asarray(C, float)[:3, :3]
    Ctt = 0.5 * (Ctt + Ctt.T)
    lam, V = np.linalg.eigh(Ctt)  # ascending compliance = descending stiffness
    if np.linalg.det(V) < 0:
        V[:, 2] *= -1.0
    return 1.0 / lam, V


def x_hint_arg(x_hint: Any, field: str = "x_hint", file: str | None = None) -> np.ndarray | None:
    """``x_hint`` as a unit 3-vector (base frame), or None; a ConfigError naming ``field``."""
    if x_hint is None:
        return None
    try:
        h = np.asarray(x_hint, float).reshape(-1)
    except (TypeError, ValueError):
        h = np.zeros(0)
    if h.shape != (3,) or not np.all(np.isfinite(h)) or np.linalg.norm(h) == 0:
        raise ConfigError("not a direction", file=file, field=field, value=x_hint,
                          expected="[x, y, z]: 3 finite numbers, not all zero (robot base "
                                   "frame; the boring frame's X is their projection onto the "
                                   "plane normal to the bore axis)")
    return h / np.linalg.norm(h)


def process_frame(
    R_world_tool: np.ndarray, frame: str | np.ndarray = "boring", *, vertical: Any = (0, 0, 1),
    x_hint: Any = None,
) -> np.ndarray:
    """Rotation ``R_world_process`` (columns: process X, Y, Z in the world frame).

    ``frame``: "tool" (the flange/tool orientation), "base" (identity), "boring" (Z = tool z
    = feed, X = normalise(vertical x Z) horizontal, Y = Z x X), or a 3x3 rotation matrix.
    A feed axis within :data:`VERTICAL_TOL_DEG` of the vertical (a vertical bore, up or
    down) leaves "horizontal" undefined: X is then the robot base's x axis projected onto
    the plane normal to Z (Y = Z x X). ``x_hint`` (a direction in the base frame) sets the
    boring frame's X for any bore axis: its projection onto the plane normal to Z; a hint
    within :data:`VERTICAL_TOL_DEG` of the bore axis is refused.
    """
    if isinstance(frame, str):
        if frame == "base":
            return np.eye(3)
        if frame == "tool":
            return np.asarray(R_world_tool, float).copy()
        if frame == "boring" and x_hint is not None:
            z = np.asarray(R_world_tool, float)[:, 2]
            h = x_hint_arg(x_hint)
            x = h - (h @ z) * z
            nx = np.linalg.norm(x)
            if nx < math.sin(math.radians(VERTICAL_TOL_DEG)):
                raise ConfigError("x_hint lies along the bore axis: it sets no X",
                                  field="x_hint", value=np.round(h, 6).tolist(),
                                  expected=f"a direction more than {VERTICAL_TOL_DEG:g} deg "
                                           "from the bore axis (robot base frame)")
            x /= nx
            return np.column_stack([x, np.cross(z, x), z])
        if frame == "boring":
            z = np.asarray(R_world_tool, float)[:, 2]
            v = np.asarray(vertical, float)
            x = np.cross(v, z)
            nx = np.linalg.norm(x)
            if nx < math.sin(math.radians(VERTICAL_TOL_DEG)) * np.linalg.norm(v):
                ex = np.array([1.0, 0.0, 0.0])
                x = ex - (ex @ z) * z
                nx = np.linalg.norm(x)
            x /= nx
            return np.column_stack([x, np.cross(z, x), z])
        raise ConfigError("unknown frame", field="frame", value=frame,
                          expected=f"one of {FRAMES} or a 3x3 rotation matrix")
    R = np.asarray(frame, float)
    if R.shape != (3, 3) or not np.allclose(R.T @ R, np.eye(3), atol=1e-6) or \
            np.linalg.det(R) < 0:
        raise ConfigError("process frame is not a rotation matrix", field="frame",
                          value=np.round(R, 6).tolist(),
                          expected="an orthonormal, right-handed 3x3 matrix (columns = axes)")
    return R


def directional_stiffness_xyz(
    robot: Robot | str,
    q_rad: Any,
    joint_stiffness: Any,
    *,
    frame: str | np.ndarray = "boring",
    tcp_m: Any = None,
) -> dict[str, float]:
    """Directional stiffness ``{"x", "y", "z"}`` [N/m] along the process-frame axes.

    The public entry point for the equivalent-model stage. ``q_rad`` (n_joints,), joint
    stiffness (n,) in N m/rad, a :class:`JointStiffness`, the identification's
    ``StiffnessIdentification`` or their dict form (:func:`joint_stiffness_arg`), ``tcp_m``
    the tool point in the flange frame [m], ``frame`` see :func:`process_frame`.

    A :class:`JointStiffness` with unidentified joints (``None``) is accepted when those joints
    do not move the tool point along the requested axis (e.g. joint 6 for a tool point on the
    spindle axis); otherwise the entry is ``None``.
    """
    robot = get_robot(robot)
    T, J = fk_jacobian(robot, np.asarray(q_rad, float), tcp_m)
    R = process_frame(T[:3, :3], frame)
    joint_stiffness = joint_stiffness_arg(joint_stiffness)
    if isinstance(joint_stiffness, JointStiffness):
        ks = joint_stiffness.k_Nm_per_rad
    else:
        ks = tuple(float(x) for x in _k_array(joint_stiffness, robot.n_joints))
    if len(ks) != robot.n_joints:
        raise InputError(f"got {len(ks)} joint stiffnesses", field="joint_stiffness",
                         expected=f"{robot.n_joints} values in N m/rad")
    out: dict[str, float] = {}
    for name, u in zip("xyz", R.T, strict=True):
        g = (u @ J[:3]) ** 2  # (n,) m^2 per rad^2: sensitivity of u-deflection to each joint
        comp = 0.0
        ok = True
        for i, ki in enumerate(ks):
            if ki is None:
                if g[i] > 1e-12 * max(g.max(), 1e-300):
                    ok = False
                continue
            comp += g[i] / ki
        out[name] = float(1.0 / comp) if ok and comp > 0 else None
    return out


def directional_stiffness_map(
    robot: Robot | str,
    Q_rad: Any,
    k_Nm_per_rad: Any,
    *,
    frame: str = "tool",
    tcp_m: Any = None,
) -> np.ndarray:
    """Directional stiffness k_xx, k_yy, k_zz [N/m] for many postures at once, (n, 3).

    ``Q_rad`` (n, n_joints); ``frame`` "tool", "base" or "boring" (per posture). Vectorised
    (one numba FK/Jacobian call), for workspace maps and posture optimisation.
    """
    robot = get_robot(robot)
    k = _k_array(k_Nm_per_rad, robot.n_joints)
    T, J = fk_jacobian(robot, np.atleast_2d(np.asarray(Q_rad, float)), tcp_m)
    if frame == "base":
        R = np.broadcast_to(np.eye(3), T[:, :3, :3].shape)
    elif frame == "tool":
        R = T[:, :3, :3]
    elif frame == "boring":
        R = np.stack([process_frame(t[:3, :3], "boring") for t in T])
    else:
        raise ConfigError("unknown frame", field="frame", value=frame,
                          expected=f"one of {FRAMES}")
    G = np.einsum("nia,nij->naj", R, J[:, :3, :]) ** 2  # (n, 3 axes, joints)
    return 1.0 / np.einsum("naj,j->na", G, 1.0 / k)


@dataclass(frozen=True)
class StiffnessResult:
    """Stiffness of a robot at one posture (what ``robobore robot stiffness`` prints)."""

    position_m: tuple[float, float, float]
    rotation: tuple[tuple[float, ...], ...]
    frame: str
    R_world_process: tuple[tuple[float, ...], ...]
    directional_stiffness_N_per_m: dict[str, float]
    directional_stiffness_base_N_per_m: dict[str, float]
    cartesian_stiffness: tuple[tuple[float, ...], ...]
    compliance: tuple[tuple[float, ...], ...]
    principal_stiffness_N_per_m: tuple[float, float, float]
    principal_directions: tuple[tuple[float, ...], ...]
    jacobian_condition: float
    complementary_stiffness: tuple[tuple[float, ...], ...] | None = None

    def to_dict(self) -> dict[str, Any]:
        from dataclasses import asdict

        return asdict(self)


def stiffness_at(
    robot: Robot | str,
    q_rad: Any,
    k_Nm_per_rad: Any,
    *,
    frame: str | np.ndarray = "boring",
    tcp_m: Any = None,
    wrench: Any = None,
) -> StiffnessResult:
    """All stiffness quantities at one posture (see module docstring).

    ``k_Nm_per_rad``: any form :func:`joint_stiffness_arg` accepts, every joint identified."""
    robot = get_robot(robot)
    q = np.asarray(q_rad, float)
    k = _k_array(k_Nm_per_rad, robot.n_joints)
    T, J = fk_jacobian(robot, q, tcp_m)
    C = compliance_matrix(J, k)
    K = cartesian_stiffness(J, k)
    R = process_frame(T[:3, :3], frame)
    kd = directional_stiffness(C, R.T)
    kb = directional_stiffness(C, np.eye(3))
    kp, V = principal_stiffness(C)
    KC = None
    if wrench is not None:
        KC = complementary_stiffness(robot, q, k, wrench, tcp_m)
        KC = tuple(map(tuple, KC.tolist()))
    return StiffnessResult(
        position_m=tuple(T[:3, 3].tolist()),
        rotation=tuple(map(tuple, T[:3, :3].tolist())),
        frame=frame if isinstance(frame, str) else "user",
        R_world_process=tuple(map(tuple, R.tolist())),
        directional_stiffness_N_per_m=dict(zip("xyz", kd.tolist(), strict=True)),
        directional_stiffness_base_N_per_m=dict(zip("xyz", kb.tolist(), strict=True)),
        cartesian_stiffness=tuple(map(tuple, K.tolist())),
        compliance=tuple(map(tuple, C.tolist())),
        principal_stiffness_N_per_m=tuple(kp.tolist()),
        principal_directions=tuple(map(tuple, V.tolist())),
        jacobian_condition=float(np.linalg.cond(J)),
        complementary_stiffness=KC,
    )


@dataclass(frozen=True)
class JointStiffness:
    """Joint stiffnesses of a robot (identified or given), N m/rad.

    ``k_Nm_per_rad[i]`` is ``None`` where the campaign could not determine joint i
    (never a made-up number). ``std`` is the delta-method standard error; ``ci95_low/high``
    the 95 % interval obtained by inverting the interval of the compliance ``c = 1/k``
    (``high`` is ``None`` when that interval reaches ``c <= 0``, i.e. "stiffer than the data
    can tell").
    """

    robot: str
    k_Nm_per_rad: tuple[float | None, ...]
    std_Nm_per_rad: tuple[float | None, ...] | None = None
    ci95_low_Nm_per_rad: tuple[float | None, ...] | None = None
    ci95_high_Nm_per_rad: tuple[float | None, ...] | None = None
    status: tuple[str, ...] | None = None
    source: str = "given"
    synthetic: bool = False

    @property
    def identifiable(self) -> tuple[bool, ...]:
        return tuple(k is not None for k in self.k_Nm_per_rad)

    def as_array(self) -> np.ndarray:
        """All stiffnesses as an array (n,); IdentificationError if one is unidentified."""
        missing = [i + 1 for i, k in enumerate(self.k_Nm_per_rad) if k is None]
        if missing:
            raise IdentificationError(
                f"joint stiffness of joint(s) {missing} was not identified; give it explicitly "
                "(e.g. from another campaign) to build the full stiffness matrix"
            )
        return np.asarray(self.k_Nm_per_rad, float)

    def to_dict(self) -> dict[str, Any]:
        return {
            "robot": self.robot,
            "joint_stiffness_Nm_per_rad": list(self.k_Nm_per_rad),
            "joint_stiffness_std_Nm_per_rad": None if self.std_Nm_per_rad is None
            else list(self.std_Nm_per_rad),
            "joint_stiffness_ci95_low_Nm_per_rad": None if self.ci95_low_Nm_per_rad is None
            else list(self.ci95_low_Nm_per_rad),
            "joint_stiffness_ci95_high_Nm_per_rad": None if self.ci95_high_Nm_per_rad is None
            else list(self.ci95_high_Nm_per_rad),
            "joint_status": None if self.status is None else list(self.status),
            "source": self.source,
            "synthetic": self.synthetic,
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> JointStiffness:
        """Inverse of :meth:`to_dict`; also accepts the JSON of ``identify stiffness``."""
        if "joint_stiffness_Nm_per_rad" not in data:
            raise InputError("missing key", field="joint_stiffness_Nm_per_rad",
                             expected="a list of joint stiffnesses in N m/rad (null allowed)")

        def _vals(key: str) -> tuple[float | None, ...] | None:
            v = data.get(key)
            if v is None:
                return None
            out = []
            for i, x in enumerate(v):
                if x is None:
                    out.append(None)
                    continue
                try:
                    f = float(x)
                except (TypeError, ValueError):
                    raise InputError("not a number", field=f"{key}[{i}]", value=x,
                                     expected="a number in N m/rad or null") from None
                if not math.isfinite(f) or (key == "joint_stiffness_Nm_per_rad" and f <= 0):
                    raise InputError("not a positive finite number", field=f"{key}[{i}]",
                                     value=x, expected="a positive number in N m/rad or null")
                out.append(f)
            return tuple(out)

        st = data.get("joint_status")
        return cls(
            robot=str(data.get("robot", "")),
            k_Nm_per_rad=_vals("joint_stiffness_Nm_per_rad"),  # type: ignore[arg-type]
            std_Nm_per_rad=_vals("joint_stiffness_std_Nm_per_rad"),
            ci95_low_Nm_per_rad=_vals("joint_stiffness_ci95_low_Nm_per_rad"),
            ci95_high_Nm_per_rad=_vals("joint_stiffness_ci95_high_Nm_per_rad"),
            status=None if st is None else tuple(str(s) for s in st),
            source=str(data.get("source", "given")),
            synthetic=bool(data.get("synthetic", False)),
        )


__all__ = [
    "FRAMES",
    "compliance_matrix",
    "cartesian_stiffness",
    "geometric_stiffness",
    "complementary_stiffness",
    "directional_stiffness",
    "principal_stiffness",
    "process_frame",
    "x_hint_arg",
    "directional_stiffness_xyz",
    "directional_stiffness_map",
    "stiffness_at",
    "StiffnessResult",
    "JointStiffness",
    "joint_stiffness_arg",
]
