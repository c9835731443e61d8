"""Serial-robot kinematics from standard Denavit-Hartenberg data.

Convention (standard / "distal" D-H, Spong-Hutchinson-Vidyasagar, *Robot Modeling and
Control*, 2006, sec. 3.2): the transform from frame i-1 to frame i is

    A_i = Rot_z(q_i + theta_offset_i) Trans_z(d_i) Trans_x(a_i) Rot_x(alpha_i)

and the flange frame is ``T = B A_1 ... A_n`` (``B`` = base transform, identity by default).
Joint i turns about the z-axis of frame i-1 through the origin of frame i-1.

Geometric Jacobian (Spong et al. eq. 4.52) at a tool point ``p`` (the TCP, given as an
offset in the flange frame): for a revolute joint i, column i is
``[z_{i-1} x (p - o_{i-1}); z_{i-1}]``, so that the twist ``[v_p; omega] = J dq`` (base frame).

Robots are data: TOML files in ``robobore/robot/library``; users add their own by passing a
file path (``--robot-file``) or by putting TOML files in a folder listed in the environment
variable ``ROBOBORE_ROBOT_PATH`` (``os.pathsep``-separated). See ``docs/robot.md``.

Everything inside is SI (m, rad); degrees only at the edges (names ending in ``_deg``).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit, prange
from pydantic import BaseModel, ConfigDict, Field, field_validator

from robobore.errors import ConfigError, InputError

LIBRARY_ENV = "ROBOBORE_ROBOT_PATH"


@dataclass(frozen=True)
class LinkInertia:
    """Rigid-body data of one link, in its D-H frame i (the frame that moves with joint i).

    ``mass_kg``; ``com_m`` (3,) centre of mass in frame i, m; ``inertia_kg_m2`` (6,) the
    inertia tensor about the centre of mass in frame i as (Ixx, Iyy, Izz, Ixy, Ixz, Iyz),
    kg m^2. Used by the pose-dependent dynamic model (:mod:`robobore.plan.model`).
    """

    mass_kg: float
    com_m: tuple[float, float, float]
    inertia_kg_m2: tuple[float, float, float, float, float, float]

    def tensor(self) -> np.ndarray:
        """The 3x3 inertia tensor about the centre of mass (frame i), kg m^2."""
        xx, yy, zz, xy, xz, yz = self.inertia_kg_m2
        return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], float)


@dataclass(frozen=True)
class Robot:
    """A serial robot with revolute joints, as standard D-H data.

    Attributes (tuples of length ``n_joints``; SI units)
    ----------
    d_m, a_m: link offsets and lengths, m.
    alpha_rad: link twists, rad.
    theta_offset_rad: joint-angle offsets (D-H theta = q + offset), rad.
    lower_limit_rad, upper_limit_rad: joint limits on q, rad.
    base_transform: 4x4 homogeneous transform world <- D-H frame 0, row-major (16 floats).
    """

    name: str
    d_m: tuple[float, ...]
    a_m: tuple[float, ...]
    alpha_rad: tuple[float, ...]
    theta_offset_rad: tuple[float, ...]
    lower_limit_rad: tuple[float, ...]
    upper_limit_rad: tuple[float, ...]
    description: str = ""
    source: str = ""
    base_transform: tuple[float, ...] = field(
        default=(1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0)
    )
    #: inertial data per link (empty: the robot file has none); see :class:`LinkInertia`
    links: tuple[LinkInertia, ...] = ()
    inertia_source: str = ""
    #: the file the robot was read from ("" when built in code)
    file: str = ""

    def __post_init__(self) -> None:
        n = len(self.d_m)
        for nm in ("a_m", "alpha_rad", "theta_offset_rad", "lower_limit_rad", "upper_limit_rad"):
            if len(getattr(self, nm)) != n:
                raise ConfigError(
                    f"robot '{self.name}': {nm} has {len(getattr(self, nm))} values, d has {n}",
                    field=nm,
                    expected=f"{n} values (one per joint)",
                )
        if n < 1:
            raise ConfigError(f"robot '{self.name}' has no joints", field="d_m")
        for i in range(n):
            if not self.lower_limit_rad[i] < self.upper_limit_rad[i]:
                raise ConfigError(
                    f"robot '{self.name}': joint {i + 1} lower limit is not below upper limit",
                    field="lower_limit_deg",
                    value=(math.degrees(self.lower_limit_rad[i]),
                           math.degrees(self.upper_limit_rad[i])),
                    expected="lower < upper, deg",
                )
        if len(self.base_transform) != 16:
            raise ConfigError("base_transform must have 16 values (4x4 row-major)",
                              field="base_transform")
        if self.links and len(self.links) != n:
            raise ConfigError(f"robot '{self.name}' has {len(self.links)} [[links]] entries",
                              field="links", value=len(self.links),
                              expected=f"{n} entries (one per joint) or none")

    @property
    def n_joints(self) -> int:
        return len(self.d_m)

    @property
    def dh_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(d, a, alpha, theta_offset) as float arrays, shape (n_joints,)."""
        return (
            np.asarray(self.d_m, float),
            np.asarray(self.a_m, float),
            np.asarray(self.alpha_rad, float),
            np.asarray(self.theta_offset_rad, float),
        )

    @property
    def base(self) -> np.ndarray:
        return np.asarray(self.base_transform, float).reshape(4, 4)

    def to_dict(self) -> dict[str, Any]:
        """Human-unit dict, the same layout as the library TOML files."""
        return {
            "name": self.name,
            "description": self.description,
            "source": self.source,
            "d_m": list(self.d_m),
            "a_m": list(self.a_m),
            "alpha_deg": [math.degrees(x) for x in self.alpha_rad],
            "theta_offset_deg": [math.degrees(x) for x in self.theta_offset_rad],
            "lower_limit_deg": [math.degrees(x) for x in self.lower_limit_rad],
            "upper_limit_deg": [math.degrees(x) for x in self.upper_limit_rad],
            "base_transform": list(self.base_transform),
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any], source: str = "<robot>") -> Robot:
        """Build from the TOML layout (lengths in m, angles in deg); validates every key."""
        from robobore.io.config import validate_model

        m = validate_model(_RobotFile, data, source=source)
        try:
            return cls._from_model(m)
        except ConfigError as exc:
            raise ConfigError(exc.message, file=source, field=exc.field, value=exc.value,
                              expected=exc.expected) from None

    @classmethod
    def _from_model(cls, m: _RobotFile) -> Robot:
        return cls(
            name=m.name,
            d_m=tuple(m.d_m),
            a_m=tuple(m.a_m),
            alpha_rad=tuple(math.radians(x) for x in m.alpha_deg),
            theta_offset_rad=tuple(math.radians(x) for x in m.theta_offset_deg),
            lower_limit_rad=tuple(math.radians(x) for x in m.lower_limit_deg),
            upper_limit_rad=tuple(math.radians(x) for x in m.upper_limit_deg),
            description=m.description,
            source=m.source,
            base_transform=tuple(m.base_transform),
            links=tuple(LinkInertia(li.mass_kg, tuple(li.com_m), tuple(li.inertia_kg_m2))
                        for li in m.links),
            inertia_source=m.inertia_source,
        )


# --- robot files ----------------------------------------------------------------------------

class _LinkFile(BaseModel):
    model_config = ConfigDict(extra="forbid")
    mass_kg: float = Field(gt=0, le=1e5)
    com_m: list[float] = Field(min_length=3, max_length=3)
    inertia_kg_m2: list[float] = Field(min_length=6, max_length=6)

    @field_validator("com_m", "inertia_kg_m2")
    @classmethod
    def _finite(cls, v: list[float]) -> list[float]:
        if not all(math.isfinite(x) for x in v):
            raise ValueError("all values must be finite numbers")
        return v

    @field_validator("inertia_kg_m2")
    @classmethod
    def _psd(cls, v: list[float]) -> list[float]:
        xx, yy, zz, xy, xz, yz = v
        ev = np.linalg.eigvalsh(np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]))
        if ev.min() < -1e-9 * max(ev.max(), 1e-30):
            raise ValueError("inertia tensor (Ixx, Iyy, Izz, Ixy, Ixz, Iyz) in kg m^2 must be "
                             "positive semi-definite")
        return v


class _RobotFile(BaseModel):
    model_config = ConfigDict(extra="forbid")
    name: str = Field(min_length=1)
    description: str = ""
    source: str = ""
    d_m: list[float] = Field(min_length=1)
    a_m: list[float]
    alpha_deg: list[float]
    theta_offset_deg: list[float]
    lower_limit_deg: list[float]
    upper_limit_deg: list[float]
    base_transform: list[float] = Field(
        default_factory=lambda: [1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0],
        min_length=16,
        max_length=16,
    )
    inertia_source: str = ""
    links: list[_LinkFile] = Field(default_factory=list)

    @field_validator("d_m", "a_m", "alpha_deg", "theta_offset_deg", "lower_limit_deg",
                     "upper_limit_deg", "base_transform")
    @classmethod
    def _finite(cls, v: list[float]) -> list[float]:
        if not all(math.isfinite(x) for x in v):
            raise ValueError("all values must be finite numbers")
        return v


def _library_dirs() -> list[Path]:
    dirs = [Path(p) for p in os.environ.get(LIBRARY_ENV, "").split(os.pathsep) if p.strip()]
    dirs.append(Path(str(resources.files("robobore.robot") / "library")))
    return dirs


def available_robots() -> dict[str, Path]:
    """Robot name -> TOML file, user folders (``ROBOBORE_ROBOT_PATH``) first."""
    out: dict[str, Path] = {}
    for d in _library_dirs():
        if d.is_dir():
            for f in sorted(d.glob("*.toml")):
                out.setdefault(f.stem, f)
    return out


def load_robot_file(path: str | Path) -> Robot:
    """Read a robot TOML file (see ``library/irb6600-175-2.55.toml`` for the layout)."""
    import dataclasses

    from robobore.io.config import load_toml

    r = Robot.from_dict(load_toml(path), source=str(path))
    return dataclasses.replace(r, file=str(path))


def get_robot(name: str | Path | Robot) -> Robot:
    """A robot by library name, or by the path of a TOML file; unknown names raise ConfigError."""
    if isinstance(name, Robot):
        return name
    p = Path(str(name))
    if p.suffix == ".toml" and p.is_file():
        return load_robot_file(p)
    lib = available_robots()
    if str(name) not in lib:
        raise ConfigError(
            "unknown robot",
            field="robot",
            value=str(name),
            expected=f"one of {sorted(lib)} or the path of a robot TOML file",
        )
    return load_robot_file(lib[str(name)])


# --- joint limits ---------------------------------------------------------------------------


def check_joint_limits(
    robot: Robot,
    q_rad: np.ndarray,
    *,
    file: str | None = None,
    rows: list[int] | None = None,
    tol_rad: float = 1e-9,
) -> None:
    """Raise InputError if any joint angle is outside the robot's limits.

    ``q_rad`` is (n_joints,) or (n_postures, n_joints). ``rows`` (optional, one per posture)
    are the data rows to name in the message (CSV input).
    """
    q = np.atleast_2d(np.asarray(q_rad, float))
    if q.shape[-1] != robot.n_joints:
        raise InputError(
            f"got {q.shape[-1]} joint angles for robot '{robot.name}'",
            file=file,
            expected=f"{robot.n_joints} joint angles",
        )
    lo = np.asarray(robot.lower_limit_rad)
    hi = np.asarray(robot.upper_limit_rad)
    if not np.all(np.isfinite(q)):
        k = int(np.argwhere(~np.isfinite(q))[0][0])
        raise InputError("joint angle is not a finite number", file=file,
                         row=None if rows is None else rows[k], expected="a number in deg")
    bad = (q < lo - tol_rad) | (q > hi + tol_rad)
    if bad.any():
        k, j = (int(x) for x in np.argwhere(bad)[0])
        raise InputError(
            f"joint {j + 1} of robot '{robot.name}' is outside its limits",
            file=file,
            row=None if rows is None else rows[k],
            field=f"q{j + 1}_deg",
            value=round(math.degrees(q[k, j]), 6),
            expected=f"a value in [{math.degrees(lo[j]):g}, {math.degrees(hi[j]):g}] deg",
        )


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
    "Robot",
    "LinkInertia",
    "available_robots",
    "get_robot",
    "load_robot_file",
    "check_joint_limits",
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
