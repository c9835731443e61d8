"""The robot as data: standard Denavit-Hartenberg parameters, joint limits, link inertia.

:class:`Robot` holds the D-H data in SI (m, rad) and, optionally, the inertial data of its
links (:class:`LinkInertia`); :mod:`robobore.robot.kinematics` computes with it. Robots are
data: TOML files in ``robobore/robot/library``; users add their own by passing a file path
(``--robot-file``) or by putting TOML files in a folder listed in the environment variable
``ROBOBORE_ROBOT_PATH`` (``os.pathsep``-separated). See ``docs/robot.md``.

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

    def description_hash(self) -> str:
        """16-hex-digit hash of the kinematic description (D-H data, joint limits, base
        transform; not the name): the ``robot_hash`` of result files
        (:mod:`robobore.io.identity`)."""
        from robobore.io.hashing import stable_hash

        return stable_hash({"d_m": self.d_m, "a_m": self.a_m, "alpha_rad": self.alpha_rad,
                            "theta_offset_rad": self.theta_offset_rad,
                            "lower_limit_rad": self.lower_limit_rad,
                            "upper_limit_rad": self.upper_limit_rad,
                            "base_transform": self.base_transform}, length=16)

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


def get_robot(name: str | Path | Robot, *, file: str | None = None,
              field: str = "robot") -> Robot:
    """A robot by library name, or by the path of a TOML file; unknown names raise ConfigError
    naming ``file`` (the config that named the robot) and ``field`` (its key or option)."""
    if isinstance(name, Robot):
        return name
    if not isinstance(name, str | Path):
        raise ConfigError("not a robot", file=file, field=field, value=type(name).__name__,
                          expected="a robot library name, a robot TOML path or a Robot")
    p = Path(str(name))
    if p.suffix == ".toml" and p.is_file():
        return load_robot_file(p)
    if p.suffix == ".toml":
        raise ConfigError("robot file not found", file=file, field=field, value=str(name),
                          expected="an existing robot TOML file")
    lib = available_robots()
    if str(name) not in lib:
        close = [n for n in lib if n.startswith(str(name)) or str(name) in n]
        raise ConfigError(
            "unknown robot" + (f" (did you mean {close[0]!r}?)" if close else ""),
            file=file,
            field=field,
            value=str(name),
            expected=f"one of {sorted(lib)} or the path of a robot TOML file",
        )
    return load_robot_file(lib[str(name)])


def robot_of_identity(ident: dict[str, Any], file: str) -> Robot:
    """The robot a file's identity names (its robot file if that still holds the same
    robot, else the library robot of that name), checked against the recorded hash."""
    from robobore.io.identity import IDENTITY_KEY, check_robot

    rf = ident.get("robot_file")
    if rf and Path(rf).is_file():
        rb = get_robot(Path(rf))
    elif ident.get("robot") in available_robots():
        rb = get_robot(ident["robot"])
    else:
        raise ConfigError(f"{file} was identified for robot {ident.get('robot')}, which is not "
                          "in the robot library", file=file, field=f"{IDENTITY_KEY}.robot",
                          value=ident.get("robot"),
                          expected="--robot NAME or --robot-file PATH of that robot")
    check_robot(ident, file, rb.name, rb.description_hash(),
                f"the robot found for it ({rb.file or rb.name})")
    return rb


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


__all__ = [
    "LIBRARY_ENV",
    "Robot",
    "LinkInertia",
    "available_robots",
    "get_robot",
    "load_robot_file",
    "robot_of_identity",
    "check_joint_limits",
]
