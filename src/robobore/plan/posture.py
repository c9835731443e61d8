"""Posture planning for a bore: candidates, their stiffness, modes and chatter limit, best one.

A six-axis robot holding a boring spindle keeps three freedoms once the bore is fixed: the
rotation of the flange about the tool axis (the spindle turns anyway), the inverse-kinematics
branch, and where the part sits. :func:`plan_posture` enumerates the first two (and, with a
``[workspace]`` section, a grid of part placements) and rates every candidate with the
calibrated pose-dependent model (:mod:`robobore.plan.model`):

1. tool-axis rotation ``psi`` on a grid of ``[plan] rotation_step_deg`` (angle of the flange x
   axis about the bore axis from the boring-frame X; the grid is anchored at the measured
   posture's angle so that the measured posture is a candidate when it reaches the bore);
2. every closed-form IK branch (:mod:`robobore.plan.ik`); each solution is verified by forward
   kinematics (tool point within 0.1 mm, tool axis within 0.05 deg of the bore axis) and kept
   when inside the joint limits and at least ``singularity_margin`` from a singularity
   (smallest singular value of the Jacobian with its translational rows divided by the
   robot's reach ``L = sum |a_i| + |d_i|``: dimensionless, 0 at a singularity);
3. per candidate: directional stiffness in the boring frame, modes, the lowest critical depth
   over ``[lobes]`` speed range (:mod:`robobore.plan.chatter`), and the feed-direction
   amplitude of the steady forced response at ``[cutting]`` (half peak-to-peak of Z, the
   quantity the time-domain simulation reports as ``feed_amplitude``; linear, valid when the
   cut is stable);
4. recommendation: the candidate with the largest value of the criterion
   (``critical_depth`` by default, or ``stiffness_x``/``stiffness_y``/``stiffness_z``/
   ``stiffness_min``).

Config: see ``examples/plan_paper_bore.toml`` and docs/plan.md.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from robobore.dynamics.config import CoefficientsCfg, InsertCfg
from robobore.errors import ConfigError, DataError, InputError
from robobore.io.readers import load_json

POSITION_TOL_M = 1e-4
AXIS_TOL_DEG = 0.05
CRITERIA = ("critical_depth", "stiffness_x", "stiffness_y", "stiffness_z", "stiffness_min")


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class RobotCfg(_Strict):
    name: str = "irb6600-175-2.55"


class LinkBendingCfg(_Strict):
    link: int
    EI_Nm2: list[float]


class IdentificationCfg(_Strict):
    joint_stiffness: str
    modes: str
    posture_deg: list[float] | None = None
    link_bending: list[LinkBendingCfg] = Field(default_factory=list)


class ToolCfg(_Strict):
    tcp_m: list[float]
    mass_kg: float = Field(0.0, ge=0, le=2000)
    com_m: list[float] = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    inertia_kg_m2: list[float] = Field(default_factory=lambda: [0.0] * 6)


class BoreCfg(_Strict):
    point_m: list[float]
    axis: list[float]
    diameter_mm: float = Field(gt=1, le=2000)


class PartCfg(_Strict):
    origin_m: list[float] = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    yaw_deg: float = 0.0


class CuttingCfg(_Strict):
    speed_rpm: float = Field(gt=0, le=100000)
    feed_mm_per_rev: float = Field(gt=0, le=5)
    depth_mm: float = Field(gt=0, le=50)


class LobesCfg(_Strict):
    speed_min_rpm: float = Field(gt=0, le=100000)
    speed_max_rpm: float = Field(gt=0, le=100000)


class PlanCfg(_Strict):
    rotation_step_deg: float = Field(1.0, gt=0, le=180)
    criterion: Literal["critical_depth", "stiffness_x", "stiffness_y", "stiffness_z",
                       "stiffness_min"] = "critical_depth"
    singularity_margin: float = Field(0.02, ge=0, le=1)


class WorkspaceCfg(_Strict):
    dx_m: list[float] = Field(min_length=1)
    dy_m: list[float] = Field(min_length=1)
    rotation_step_deg: float = Field(10.0, gt=0, le=180)


class PlanConfig(_Strict):
    robot: RobotCfg = RobotCfg()
    identification: IdentificationCfg
    tool: ToolCfg
    bore: BoreCfg
    part: PartCfg | None = None
    insert: InsertCfg = InsertCfg()
    cutting: CuttingCfg
    coefficients: CoefficientsCfg | None = None
    lobes: LobesCfg
    plan: PlanCfg = PlanCfg()
    workspace: WorkspaceCfg | None = None


# ----------------------------------------------------------------------------- inputs
def _vec3(v: Any, file: str, key: str, unit: str) -> np.ndarray:
    a = np.asarray(v, float)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ConfigError("needs 3 finite numbers", file=file, field=key, value=v,
                          expected=f"[x, y, z] in {unit}")
    return a


def _read_json(path: Path, cfg_file: str, key: str) -> dict[str, Any]:
    if not path.is_file():
        raise ConfigError("file not found", file=cfg_file, field=key, value=str(path),
                          expected="a JSON file written by 'robobore identify ... --json' "
                                   "(paths relative to the config file's folder)")
    return load_json(path, "identification file", "a JSON object written by 'robobore "
                     "identify ... --json'", error=DataError)


@dataclass
class PlanInputs:
    """Everything :func:`plan_posture` needs, validated (SI)."""

    cfg: PlanConfig
    raw: dict[str, Any]
    path: Path
    robot: Any
    k_Nm_per_rad: np.ndarray
    modes_f_Hz: np.ndarray
    modes_zeta: np.ndarray
    q_meas_rad: np.ndarray
    tcp_m: np.ndarray
    bore_point_m: np.ndarray
    bore_axis: np.ndarray
    stiffness_file: Path | None
    modes_file: Path | None
    synthetic: bool = False
    link_bending: tuple[Any, ...] = ()


def _resolve(base: Path, name: str) -> Path:
    p = Path(name)
    return p if p.is_absolute() else base.parent / p


def load_plan_config(path: str | Path) -> PlanInputs:
    """Read, validate and resolve a plan config (errors name the file, key, value, unit)."""
    from robobore.dynamics.structure import check_unit_vector
    from robobore.io.config import load_toml, validate_model
    from robobore.robot.kinematics import get_robot
    from robobore.robot.stiffness import JointStiffness

    p = Path(path)
    raw = load_toml(p)
    cfg = validate_model(PlanConfig, raw, source=p)
    f = str(p)
    rname = cfg.robot.name
    rpath = _resolve(p, rname) if rname.endswith(".toml") else None
    robot = get_robot(str(rpath) if rpath is not None else rname)
    if not robot.links:
        raise ConfigError(
            f"robot '{robot.name}' has no inertial data (mass, centre of mass and inertia per "
            "link), which the pose-dependent dynamic model needs",
            file=robot.file or f, field="links" if robot.file else "robot.name", value=rname,
            expected=f"{robot.n_joints} [[links]] tables with mass_kg, com_m and inertia_kg_m2 "
                     "(see robot/library/irb6600-175-2.55.toml)")
    # tool point: metres, flange frame
    tcp = _vec3(cfg.tool.tcp_m, f, "tool.tcp_m", "m")
    if np.linalg.norm(tcp) > 2.0:
        raise ConfigError(f"tool point {np.linalg.norm(tcp):.4g} m from the flange: looks like "
                          "millimetres", file=f, field="tool.tcp_m", value=cfg.tool.tcp_m,
                          expected="[x, y, z] in m in the flange frame (|tcp| <= 2 m)")
    com = _vec3(cfg.tool.com_m, f, "tool.com_m", "m")
    if np.linalg.norm(com) > 2.0:
        raise ConfigError("tool centre of mass more than 2 m from the flange: looks like "
                          "millimetres", file=f, field="tool.com_m", value=cfg.tool.com_m,
                          expected="[x, y, z] in m in the flange frame")
    if len(cfg.tool.inertia_kg_m2) != 6:
        raise ConfigError("needs 6 values", file=f, field="tool.inertia_kg_m2",
                          value=cfg.tool.inertia_kg_m2,
                          expected="[Ixx, Iyy, Izz, Ixy, Ixz, Iyz] in kg m^2 about the centre "
                                   "of mass, flange frame")
    point = _vec3(cfg.bore.point_m, f, "bore.point_m", "m")
    axis = check_unit_vector(cfg.bore.axis, "bore.axis", file=f)
    if abs(axis[2]) > 1 - 1e-9:
        raise ConfigError("a vertical bore axis leaves the boring frame's X undefined", file=f,
                          field="bore.axis", value=cfg.bore.axis,
                          expected="a non-vertical unit vector (base frame)")
    if cfg.part is not None:
        o = _vec3(cfg.part.origin_m, f, "part.origin_m", "m")
        y = math.radians(cfg.part.yaw_deg)
        Rz = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0],
                       [0, 0, 1.0]])
        point = o + Rz @ point
        axis = Rz @ axis
    if cfg.lobes.speed_max_rpm <= cfg.lobes.speed_min_rpm:
        raise ConfigError("empty speed range", file=f, field="lobes.speed_max_rpm",
                          value=cfg.lobes.speed_max_rpm,
                          expected=f"> lobes.speed_min_rpm = {cfg.lobes.speed_min_rpm} r/min")
    # identification results
    sfile = _resolve(p, cfg.identification.joint_stiffness)
    sdata = _read_json(sfile, f, "identification.joint_stiffness")
    try:
        js = JointStiffness.from_dict(sdata)
    except InputError as exc:
        raise InputError(exc.message, file=str(sfile), field=exc.field, value=exc.value,
                         expected=exc.expected) from None
    if len(js.k_Nm_per_rad) != robot.n_joints:
        raise DataError(f"{len(js.k_Nm_per_rad)} joint stiffnesses for a "
                        f"{robot.n_joints}-joint robot", file=str(sfile),
                        field="joint_stiffness_Nm_per_rad",
                        expected=f"{robot.n_joints} values in N m/rad")
    missing = [i + 1 for i, k in enumerate(js.k_Nm_per_rad) if k is None]
    if missing:
        raise DataError(f"joint stiffness of joint(s) {missing} not identified; the dynamic "
                        "model needs every joint", file=str(sfile),
                        field="joint_stiffness_Nm_per_rad", value=list(js.k_Nm_per_rad),
                        expected="a positive value in N m/rad for every joint")
    mfile = _resolve(p, cfg.identification.modes)
    mdata = _read_json(mfile, f, "identification.modes")
    ml = mdata.get("modes")
    if not isinstance(ml, list) or not ml:
        raise DataError("no modes", file=str(mfile), field="modes",
                        expected="a list of {frequency_Hz, damping_ratio} (robobore identify "
                                 "modes --json)")
    try:
        fz = np.array([[float(m["frequency_Hz"]), float(m.get("damping_ratio", 0.0))]
                       for m in ml])
    except (KeyError, TypeError, ValueError):
        raise DataError("a mode lacks a numeric frequency_Hz / damping_ratio", file=str(mfile),
                        field="modes", expected="frequency_Hz in Hz > 0, damping_ratio >= 0"
                        ) from None
    if not np.all(np.isfinite(fz)) or np.any(fz[:, 0] <= 0) or np.any(fz[:, 1] < 0):
        raise DataError("mode frequencies must be > 0 Hz and damping ratios >= 0",
                        file=str(mfile), field="modes", value=fz.tolist(),
                        expected="frequency_Hz > 0, damping_ratio >= 0")
    # the posture at which the modes were measured
    file_posture = mdata.get("posture_deg")
    cfg_posture = cfg.identification.posture_deg
    if cfg_posture is None and file_posture is None:
        raise ConfigError(
            "the posture at which the modes were measured is not given (the modes file does "
            "not record one)", file=f, field="identification.posture_deg", value=None,
            expected=f"{robot.n_joints} joint angles in deg: the robot's posture during the "
                     f"hammer test of {mfile.name}")
    if cfg_posture is not None and file_posture is not None and (
            len(file_posture) != len(cfg_posture)
            or np.max(np.abs(np.subtract(file_posture, cfg_posture, dtype=float))) > 0.01):
        raise ConfigError(
            f"the modes file {mfile.name} was measured at posture {list(file_posture)} deg, "
            "not at the configured one", file=f, field="identification.posture_deg",
            value=cfg_posture, expected=f"the posture of the modes file, {list(file_posture)} deg")
    qm = np.asarray(cfg_posture if cfg_posture is not None else file_posture, float)
    if qm.shape != (robot.n_joints,) or not np.all(np.isfinite(qm)):
        raise ConfigError("wrong number of joint angles", file=f,
                          field="identification.posture_deg", value=list(qm),
                          expected=f"{robot.n_joints} angles in deg")
    from robobore.robot.kinematics import check_joint_limits

    check_joint_limits(robot, np.radians(qm), file=f)
    synthetic = bool(sdata.get("synthetic", False)) or bool(mdata.get("synthetic", False))
    return PlanInputs(cfg, raw, p, robot, np.asarray(js.k_Nm_per_rad, float), fz[:, 0],
                      fz[:, 1], np.radians(qm), tcp, point, axis, sfile, mfile, synthetic,
                      _link_bending(cfg, robot, f))


def _link_bending(cfg: PlanConfig, robot: Any, f: str) -> tuple[Any, ...]:
    """``[[identification.link_bending]]``: optional beam compliance of long links."""
    from robobore.plan.bending import LinkBending, beam_geometry

    out, seen = [], set()
    for i, lb in enumerate(cfg.identification.link_bending):
        key = f"identification.link_bending[{i}]"
        if not 1 <= lb.link <= robot.n_joints or lb.link in seen:
            raise InputError("link bending: no such link, or given twice", file=f,
                             field=f"{key}.link", value=lb.link,
                             expected=f"a link number 1..{robot.n_joints}, once")
        ei = np.asarray(lb.EI_Nm2, float)
        if ei.shape != (2,) or not np.all(np.isfinite(ei)) or np.any(ei <= 0):
            raise InputError("link bending stiffness must be two positive values", file=f,
                             field=f"{key}.EI_Nm2", value=lb.EI_Nm2,
                             expected="[EI_1, EI_2] in N m^2 (> 0; e.g. 1e6..1e9 for an "
                                      "industrial robot's arm)")
        item = LinkBending(int(lb.link), (float(1 / ei[0]), float(1 / ei[1])))
        try:
            beam_geometry(robot, item)
        except InputError:
            raise InputError("link bending on a link of zero length", file=f,
                             field=f"{key}.link", value=lb.link,
                             expected="a link with a_i or d_i > 0 (a beam)") from None
        seen.add(lb.link)
        out.append(item)
    return tuple(out)


# ----------------------------------------------------------------------------- candidates
def boring_frame(axis: np.ndarray) -> np.ndarray:
    """Columns X (horizontal, vertical x Z), Y = Z x X, Z = the bore axis (a non-vertical unit
    vector); the robot stage's ``"boring"`` frame of a tool whose z axis is the bore axis."""
    from robobore.robot.stiffness import process_frame

    z = np.asarray(axis, float) / np.linalg.norm(axis)
    R = np.zeros((3, 3))
    R[:, 2] = z
    return process_frame(R, "boring")


def rotation_of(Rb: np.ndarray, R_flange: np.ndarray) -> float:
    """Tool-axis rotation [deg] of a flange orientation: angle of flange x in the boring XY."""
    x = Rb.T @ R_flange[:, 0]
    return math.degrees(math.atan2(x[1], x[0]))


def reach_length(robot: Any) -> float:
    d, a, _, _ = robot.dh_arrays
    return float(np.sum(np.abs(a)) + np.sum(np.abs(d)))


def singularity_measure(robot: Any, J: np.ndarray) -> np.ndarray:
    """Smallest singular value of the Jacobian with translational rows / reach, (n,)."""
    Jn = J.copy()
    Jn[:, :3, :] /= reach_length(robot)
    return np.linalg.svd(Jn, compute_uv=False)[:, -1]


@dataclass
class Candidates:
    rotation_deg: np.ndarray  # (n,)
    branch: np.ndarray  # (n,) int
    q_rad: np.ndarray  # (n, nj)
    position_error_m: np.ndarray
    axis_error_deg: np.ndarray
    singularity: np.ndarray
    n_tried: int
    n_reached: int
    n_in_limits: int


def enumerate_candidates(robot: Any, point: np.ndarray, axis: np.ndarray, tcp: np.ndarray,
                         rotations_deg: np.ndarray, margin: float) -> Candidates:
    """Every verified posture on the rotation grid x IK branches (see module docstring)."""
    from robobore.plan.ik import N_BRANCHES, ik_all, is_supported
    from robobore.robot.kinematics import fk_jacobian

    if not is_supported(robot):
        raise ConfigError(f"robot '{robot.name}' is not a 6R arm with a spherical wrist; the "
                          "posture planner's closed-form inverse kinematics needs one",
                          file=robot.file or None, field="robot",
                          expected="D-H data of the Pieper class (docs/plan.md)")
    Rb = boring_frame(axis)
    psi = np.radians(rotations_deg)
    c, s = np.cos(psi), np.sin(psi)
    Rz = np.zeros((psi.size, 3, 3))
    Rz[:, 0, 0], Rz[:, 0, 1], Rz[:, 1, 0], Rz[:, 1, 1], Rz[:, 2, 2] = c, -s, s, c, 1.0
    Rf = np.einsum("ij,njk->nik", Rb, Rz)
    pf = point[None, :] - np.einsum("nij,j->ni", Rf, tcp)
    Q, ok = ik_all(robot, Rf, pf)
    reached = np.all(np.isfinite(Q), axis=2)
    rot = np.repeat(np.asarray(rotations_deg, float), N_BRANCHES)
    br = np.tile(np.arange(N_BRANCHES), psi.size)
    Qf = Q.reshape(-1, robot.n_joints)
    keep = ok.reshape(-1)
    n_reached = int(reached.sum())
    n_lim = int(keep.sum())
    Qk = Qf[keep]
    if Qk.shape[0] == 0:
        e = np.zeros(0)
        return Candidates(rot[keep], br[keep], Qk, e, e, e, Qf.shape[0], n_reached, n_lim)
    T, J = fk_jacobian(robot, Qk, tcp)
    pos_err = np.linalg.norm(T[:, :3, 3] - point[None, :], axis=1)
    cosang = np.clip(T[:, :3, 2] @ axis, -1, 1)
    ax_err = np.degrees(np.arccos(cosang))
    sing = singularity_measure(robot, J)
    good = (pos_err <= POSITION_TOL_M) & (ax_err <= AXIS_TOL_DEG) & (sing >= margin)
    return Candidates(rot[keep][good], br[keep][good], Qk[good], pos_err[good], ax_err[good],
                      sing[good], Qf.shape[0], n_reached, n_lim)


def rotation_grid(step_deg: float, anchor_deg: float = 0.0) -> np.ndarray:
    n = max(1, int(round(360.0 / step_deg)))
    g = anchor_deg + step_deg * np.arange(n)
    return (g + 180.0) % 360.0 - 180.0


# ----------------------------------------------------------------------------- evaluation
def feed_amplitude(frequency_Hz: np.ndarray, damping_ratio: np.ndarray, u: np.ndarray,
                   force_basis_N: np.ndarray, speed_rpm: float, n_inserts: int) -> np.ndarray:
    """Half peak-to-peak feed-direction (Z) tool displacement of the steady forced response
    [m], (n,), for a rotating bar whose per-insert force is ``(f_t, f_r, f_z)`` in the insert
    basis. Only the first spindle harmonic reaches X/Y (the bar force is a rotating vector),
    and only through the cross receptances ``G_zx``, ``G_zy``; ``n_inserts`` equally spaced
    inserts cancel it (factor ``|sum_p exp(2 pi i p / N)|``)."""
    ft, fr, _ = force_basis_N
    W = 2 * np.pi * speed_rpm / 60.0
    w = 2 * np.pi * frequency_Hz
    h = 1.0 / (w ** 2 - W ** 2 + 2j * damping_ratio * w * W)  # (n, m)
    Gzx = np.einsum("nm,nm,nm->n", h, u[:, :, 2], u[:, :, 0])
    Gzy = np.einsum("nm,nm,nm->n", h, u[:, :, 2], u[:, :, 1])
    S = abs(np.sum(np.exp(2j * np.pi * np.arange(n_inserts) / n_inserts)))
    return np.abs(Gzx * (fr + 1j * ft) + Gzy * (ft - 1j * fr)) * S


def nominal_force_basis(process: Any, depth_m: float) -> np.ndarray:
    """Per-insert nominal force (t, r, z) [N] of a boring process at depth ``depth_m``."""
    return (np.einsum("e,e,ei->i", process.width_per_depth * depth_m, process.h0, process.shear)
            + np.einsum("e,ei->i", process.edge_per_depth * depth_m + process.edge_fixed_m,
                        process.edge))


def build_process(inp: PlanInputs) -> Any:
    """The boring-bar process at ``[cutting]`` from ``[insert]`` and ``[coefficients]``."""
    from robobore.dynamics.config import DynamicsConfig
    from robobore.dynamics.config import build_process as _bp

    c = inp.cfg
    dc = DynamicsConfig.model_validate({
        "structure": {"modes": [{"frequency_Hz": 10.0, "damping_ratio": 0.05,
                                 "stiffness_N_per_m": 1e6, "direction": [1, 0, 0]}]},
        "insert": c.insert.model_dump(), "bore": {"diameter_mm": c.bore.diameter_mm},
        "cutting": {"speed_rpm": c.cutting.speed_rpm,
                    "feed_mm_per_rev": c.cutting.feed_mm_per_rev,
                    "depth_mm": c.cutting.depth_mm},
        **({"coefficients": c.coefficients.model_dump(exclude_none=True)}
           if c.coefficients is not None else {})})
    return _bp(dc, source=str(inp.path))


def criterion_values(name: str, stiffness: np.ndarray, critical_depth_m: np.ndarray
                     ) -> np.ndarray:
    if name == "critical_depth":
        return critical_depth_m * 1e3
    if name == "stiffness_min":
        return stiffness.min(axis=1)
    return stiffness[:, "xyz".index(name[-1])]


CRITERION_UNITS = {"critical_depth": "mm", "stiffness_x": "N/m", "stiffness_y": "N/m",
                   "stiffness_z": "N/m", "stiffness_min": "N/m"}


def evaluate(model: Any, robot: Any, cand: Candidates, process: Any, A0: np.ndarray,
             cfg: PlanConfig, progress: Any = None) -> dict[str, np.ndarray]:
    """Stiffness, modes, critical depth and feed amplitude per candidate (chunks of 512)."""
    from robobore.plan.chatter import critical_depth_range

    n = cand.q_rad.shape[0]
    nj = model.n_dof
    out = {"frequency_Hz": np.empty((n, nj)), "damping_ratio": np.empty((n, nj)),
           "stiffness_N_per_m": np.empty((n, 3)), "critical_depth_m": np.empty(n),
           "chatter_frequency_Hz": np.empty(n), "critical_speed_rpm": np.empty(n),
           "feed_amplitude_m": np.empty(n)}
    fb = nominal_force_basis(process, cfg.cutting.depth_mm * 1e-3)
    for s in range(0, n, 512):
        e = min(n, s + 512)
        pm = model.modes(cand.q_rad[s:e])
        out["frequency_Hz"][s:e] = pm.frequency_Hz
        out["damping_ratio"][s:e] = pm.damping_ratio
        out["stiffness_N_per_m"][s:e] = pm.directional_stiffness
        b, fch, nch = critical_depth_range(pm.frequency_Hz, pm.damping_ratio, pm.u, A0,
                                           cfg.lobes.speed_min_rpm, cfg.lobes.speed_max_rpm,
                                           process.n_inserts)
        out["critical_depth_m"][s:e] = b
        out["chatter_frequency_Hz"][s:e] = fch
        out["critical_speed_rpm"][s:e] = nch
        out["feed_amplitude_m"][s:e] = feed_amplitude(pm.frequency_Hz, pm.damping_ratio, pm.u,
                                                      fb, cfg.cutting.speed_rpm,
                                                      process.n_inserts)
        if progress is not None:
            progress(e - s)
    return out


def recommend(crit: np.ndarray, Q: np.ndarray, q_ref: np.ndarray, rel_tol: float = 1e-6
              ) -> int:
    """Index of the best candidate: the largest criterion (an infinite critical depth counts
    as the largest); among candidates within ``rel_tol`` of the best (for a tool point on
    the flange axis, the tool-axis rotation only turns axis 6 and leaves stiffness and modes
    unchanged), the one nearest the measured posture (smallest largest joint move)."""
    c = np.where(np.isnan(crit), -np.inf, crit)
    top = np.max(c)
    if np.isinf(top) and top > 0:
        near = np.flatnonzero(np.isinf(c) & (c > 0))
    else:
        near = np.flatnonzero(c >= top - rel_tol * abs(top))
    move = np.max(np.abs(np.angle(np.exp(1j * (Q[near] - q_ref[None, :])))), axis=1)
    return int(near[int(np.argmin(move))])


def _same_posture(q1: np.ndarray, q2: np.ndarray, tol: float = 1e-6) -> bool:
    d = np.angle(np.exp(1j * (np.asarray(q1) - np.asarray(q2))))
    return bool(np.max(np.abs(d)) < tol)


def plan_posture(config: str | Path, *, progress_factory: Any = None) -> dict[str, Any]:
    """Run the posture plan of a config file; returns the result (JSON contract + arrays).

    ``progress_factory(description, total)`` -> context manager yielding ``advance(n)``
    (optional; :func:`robobore.clitools.progress_bar`).
    """
    t0 = time.perf_counter()
    return run_plan(load_plan_config(config), progress_factory=progress_factory, t0=t0)


def run_plan(inp: PlanInputs, *, progress_factory: Any = None,
             t0: float | None = None) -> dict[str, Any]:
    """The posture plan for validated inputs (see :func:`plan_posture`)."""
    from contextlib import nullcontext

    from robobore.dynamics.stability import lobes_frequency_domain
    from robobore.plan.model import PoseModel, ToolBody, calibrate
    from robobore.robot.kinematics import fk

    t0 = time.perf_counter() if t0 is None else t0
    cfg, robot, f = inp.cfg, inp.robot, str(inp.path)
    tool = ToolBody(cfg.tool.mass_kg, tuple(cfg.tool.com_m), tuple(cfg.tool.inertia_kg_m2))
    model0 = PoseModel(robot, inp.k_Nm_per_rad, np.zeros(robot.n_joints), tool=tool,
                       link_bending=inp.link_bending,
                       tcp_m=tuple(inp.tcp_m), robot_file=robot.file or None)
    cal = calibrate(model0, inp.q_meas_rad, inp.modes_f_Hz, inp.modes_zeta)
    model = cal.model
    process = build_process(inp)
    A0 = process.mean_directional_matrix()
    Rb = boring_frame(inp.bore_axis)
    # measured posture: does it hold this bore? anchor the rotation grid at its angle
    Tm = fk(robot, inp.q_meas_rad, inp.tcp_m)
    meas_pos_err = float(np.linalg.norm(Tm[:3, 3] - inp.bore_point_m))
    meas_ax_err = float(np.degrees(np.arccos(np.clip(Tm[:3, 2] @ inp.bore_axis, -1, 1))))
    meas_reaches = meas_pos_err <= POSITION_TOL_M and meas_ax_err <= AXIS_TOL_DEG
    anchor = rotation_of(Rb, Tm[:3, :3]) if meas_reaches else 0.0
    rot = rotation_grid(cfg.plan.rotation_step_deg, anchor)
    cand = enumerate_candidates(robot, inp.bore_point_m, inp.bore_axis, inp.tcp_m, rot,
                                cfg.plan.singularity_margin)
    if cand.n_reached == 0:
        raise InputError(
            "the bore is out of the robot's reach at every tool-axis rotation and IK branch",
            file=f, field="bore.point_m", value=[round(float(v), 6) for v in inp.bore_point_m],
            expected=f"a point the tool (tcp {inp.tcp_m.tolist()} m) can reach with its axis "
                     f"along bore.axis; robot '{robot.name}' reach about "
                     f"{reach_length(robot):.2f} m (base frame, m)")
    if cand.q_rad.shape[0] == 0:
        raise InputError(
            f"no posture reaches the bore inside the joint limits with singularity margin "
            f"{cfg.plan.singularity_margin} ({cand.n_reached} IK solutions reach it, "
            f"{cand.n_in_limits} inside the limits)", file=f, field="bore.point_m",
            value=[round(float(v), 6) for v in inp.bore_point_m],
            expected="a bore position/axis the robot reaches inside its limits, or a smaller "
                     "plan.singularity_margin")
    pf = progress_factory or (lambda d, t: nullcontext(lambda n=1: None))
    with pf("posture candidates", cand.q_rad.shape[0]) as adv:
        ev = evaluate(model, robot, cand, process, A0, cfg, adv)
    crit = criterion_values(cfg.plan.criterion, ev["stiffness_N_per_m"], ev["critical_depth_m"])
    best = recommend(crit, cand.q_rad, inp.q_meas_rad)
    meas_idx = None
    for i in np.flatnonzero(np.abs(((cand.rotation_deg - anchor) + 180) % 360 - 180) < 1e-9):
        if _same_posture(cand.q_rad[i], inp.q_meas_rad):
            meas_idx = int(i)
    entries = [_entry(i, cand, ev) for i in range(cand.q_rad.shape[0])]
    # lobes (frequency domain, stability module) at the recommended and measured postures
    lobes = {}
    speeds = np.linspace(cfg.lobes.speed_min_rpm, cfg.lobes.speed_max_rpm, 300)
    for name, idx in (("recommended", best), ("measured", meas_idx)):
        if idx is None:
            continue
        st = model.modes(cand.q_rad[idx]).structure(0)
        L = lobes_frequency_domain(st, process, speeds)
        lobes[name] = {"speed_rpm": speeds.tolist(),
                       "critical_depth_mm": (L.critical_depth_m * 1e3).tolist(),
                       "critical_depth_at_speed_mm": float(np.interp(
                           cfg.cutting.speed_rpm, speeds, L.critical_depth_m * 1e3))}
    equivalent = {}
    for name, idx in (("recommended", best), ("measured", meas_idx)):
        if idx is not None:
            equivalent[name] = model.equivalent(cand.q_rad[idx]).table()
    wall = time.perf_counter() - t0
    result = {
        "config": f,
        "robot": robot.name,
        "criterion": cfg.plan.criterion,
        "criterion_unit": CRITERION_UNITS[cfg.plan.criterion],
        "recommended": entries[best] | {"criterion_value": float(crit[best])},
        "measured": None if meas_idx is None else entries[meas_idx] | {
            "criterion_value": float(crit[meas_idx])},
        "measured_posture_deg": np.degrees(inp.q_meas_rad).tolist(),
        "measured_posture_reaches_bore": meas_reaches,
        "measured_posture_error": {"position_mm": meas_pos_err * 1e3,
                                   "axis_deg": meas_ax_err},
        "calibration": cal.to_dict(),
        "bore": {"point_m": inp.bore_point_m.tolist(), "axis": inp.bore_axis.tolist(),
                 "boring_frame_columns": Rb.T.tolist()},
        "tcp_m": inp.tcp_m.tolist(),
        "counts": {"rotations": int(rot.size), "ik_solutions_tried": cand.n_tried,
                   "reaching": cand.n_reached, "inside_limits": cand.n_in_limits,
                   "candidates": int(cand.q_rad.shape[0])},
        "max_position_error_mm": float(cand.position_error_m.max() * 1e3),
        "max_axis_error_deg": float(cand.axis_error_deg.max()),
        "speed_range_rpm": [cfg.lobes.speed_min_rpm, cfg.lobes.speed_max_rpm],
        "cutting": cfg.cutting.model_dump(),
        "candidates": entries,
        "lobes": lobes,
        "equivalent_model": equivalent,
        "synthetic_inputs": bool(inp.synthetic),
        "wall_time_s": wall,
    }
    result["_arrays"] = {"cand": cand, "ev": ev, "criterion": crit, "best": best,
                         "measured": meas_idx, "rotations": rot, "model": model,
                         "inputs": inp, "process": process}
    return result


def _entry(i: int, cand: Candidates, ev: dict[str, np.ndarray]) -> dict[str, Any]:
    from robobore.plan.ik import branch_label

    k = ev["stiffness_N_per_m"][i]
    b = ev["critical_depth_m"][i]
    return {
        "joints_deg": np.degrees(cand.q_rad[i]).tolist(),
        "tool_axis_rotation_deg": float(cand.rotation_deg[i]),
        "branch": int(cand.branch[i]),
        "branch_label": branch_label(int(cand.branch[i])),
        "directional_stiffness_N_per_m": {"x": float(k[0]), "y": float(k[1]), "z": float(k[2])},
        "modes": [{"frequency_Hz": float(fr), "damping_ratio": float(z)}
                  for fr, z in zip(ev["frequency_Hz"][i], ev["damping_ratio"][i], strict=True)],
        "critical_depth_mm": None if not math.isfinite(b) else float(b * 1e3),
        "chatter_frequency_Hz": float(ev["chatter_frequency_Hz"][i]),
        "feed_amplitude_um": float(ev["feed_amplitude_m"][i] * 1e6),
        "singularity_measure": float(cand.singularity[i]),
        "position_error_mm": float(cand.position_error_m[i] * 1e3),
        "axis_error_deg": float(cand.axis_error_deg[i]),
    }


def results_dataset(result: dict[str, Any]) -> Any:
    """The candidates as an xarray Dataset (dims candidate, joint, mode, axis)."""
    import xarray as xr

    A = result["_arrays"]
    cand, ev = A["cand"], A["ev"]
    n, nj = cand.q_rad.shape
    nm = ev["frequency_Hz"].shape[1]
    ds = xr.Dataset(
        {
            "joints": (("candidate", "joint"), np.degrees(cand.q_rad), {"units": "deg"}),
            "tool_axis_rotation": (("candidate",), cand.rotation_deg, {"units": "deg"}),
            "branch": (("candidate",), cand.branch.astype(np.int16)),
            "directional_stiffness": (("candidate", "axis"), ev["stiffness_N_per_m"],
                                      {"units": "N/m", "frame": "boring (Z bore axis)"}),
            "frequency": (("candidate", "mode"), ev["frequency_Hz"], {"units": "Hz"}),
            "damping_ratio": (("candidate", "mode"), ev["damping_ratio"]),
            "critical_depth": (("candidate",), ev["critical_depth_m"] * 1e3,
                               {"units": "mm", "long_name": "lowest critical depth over the "
                                "speed range"}),
            "chatter_frequency": (("candidate",), ev["chatter_frequency_Hz"], {"units": "Hz"}),
            "feed_amplitude": (("candidate",), ev["feed_amplitude_m"] * 1e6, {"units": "um"}),
            "singularity_measure": (("candidate",), cand.singularity),
            "criterion": (("candidate",), A["criterion"],
                          {"name": result["criterion"], "units": result["criterion_unit"]}),
        },
        coords={"candidate": np.arange(n), "joint": np.arange(1, nj + 1),
                "mode": np.arange(1, nm + 1), "axis": ["x", "y", "z"]},
        attrs={"recommended_candidate": A["best"],
               "measured_candidate": -1 if A["measured"] is None else A["measured"],
               "criterion": result["criterion"], "robot": result["robot"],
               "synthetic_inputs": int(result["synthetic_inputs"])},
    )
    return ds


def public(result: dict[str, Any]) -> dict[str, Any]:
    """The result without the in-memory arrays (the JSON contract)."""
    return {k: v for k, v in result.items() if not k.startswith("_")}


def workspace_map(result: dict[str, Any], progress: Any = None) -> dict[str, Any] | None:
    """Best criterion value over rotations x branches at each part placement of
    ``[workspace]`` (the bore point shifted by (dx, dy) in the base frame)."""
    inp: PlanInputs = result["_arrays"]["inputs"]
    ws = inp.cfg.workspace
    if ws is None:
        return None
    model = result["_arrays"]["model"]
    process = result["_arrays"]["process"]
    A0 = process.mean_directional_matrix()
    rot = rotation_grid(ws.rotation_step_deg)
    best = np.full((len(ws.dy_m), len(ws.dx_m)), np.nan)
    for iy, dy in enumerate(ws.dy_m):
        for ix, dx in enumerate(ws.dx_m):
            pt = inp.bore_point_m + np.array([dx, dy, 0.0])
            cand = enumerate_candidates(inp.robot, pt, inp.bore_axis, inp.tcp_m, rot,
                                        inp.cfg.plan.singularity_margin)
            if cand.q_rad.shape[0]:
                ev = evaluate(model, inp.robot, cand, process, A0, inp.cfg)
                c = criterion_values(inp.cfg.plan.criterion, ev["stiffness_N_per_m"],
                                     ev["critical_depth_m"])
                best[iy, ix] = float(np.max(c))
            if progress is not None:
                progress(1)
    return {"dx_m": list(ws.dx_m), "dy_m": list(ws.dy_m),
            "best_criterion": [[None if not np.isfinite(v) else float(v) for v in row]
                               for row in best],
            "criterion": inp.cfg.plan.criterion, "rotation_step_deg": ws.rotation_step_deg}


__all__ = ["PlanConfig", "PlanInputs", "load_plan_config", "plan_posture", "run_plan",
           "enumerate_candidates",
           "rotation_grid", "boring_frame", "results_dataset", "public", "workspace_map",
           "feed_amplitude", "nominal_force_basis", "recommend", "CRITERIA"]
