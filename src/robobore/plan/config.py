"""The posture plan's config (``robobore plan posture CONFIG``): schema, loading, validation.

:func:`load_plan_config` reads the TOML, checks every key (errors name the file, key, value
and unit), reads the identification files it names and returns :class:`PlanInputs` (SI). The
layout is ``examples/plan_paper_bore.toml`` and docs/plan.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import Field

from robobore.dynamics.config import CoefficientsCfg, InsertCfg
from robobore.errors import ConfigError, DataError, InputError
from robobore.io.readers import load_json
from robobore.io.sections import StrictModel


class RobotCfg(StrictModel):
    name: str = "irb6600-175-2.55"


class LinkBendingCfg(StrictModel):
    link: int
    EI_Nm2: list[float]


class IdentificationCfg(StrictModel):
    joint_stiffness: str
    modes: str
    posture_deg: list[float] | None = None
    link_bending: list[LinkBendingCfg] = Field(default_factory=list)


class ToolCfg(StrictModel):
    tcp_m: list[float]
    mass_kg: float = Field(0.0, ge=0, le=2000)
    com_m: list[float] = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    inertia_kg_m2: list[float] = Field(default_factory=lambda: [0.0] * 6)


class BoreCfg(StrictModel):
    point_m: list[float]
    axis: list[float]
    diameter_mm: float = Field(gt=1, le=2000)
    x_hint: list[float] | None = None


class PartCfg(StrictModel):
    origin_m: list[float] = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    yaw_deg: float = 0.0


class CuttingCfg(StrictModel):
    # upper bounds: the one range of each quantity, robobore.io.ranges (check_tree)
    speed_rpm: float = Field(gt=0)
    feed_mm_per_rev: float = Field(gt=0)
    depth_mm: float = Field(gt=0)


class LobesCfg(StrictModel):
    speed_min_rpm: float = Field(gt=0, le=100000)
    speed_max_rpm: float = Field(gt=0, le=100000)


class PlanCfg(StrictModel):
    rotation_step_deg: float = Field(1.0, ge=0.01, le=180)  # 36,000 rotations at most
    criterion: Literal["critical_depth", "stiffness_x", "stiffness_y", "stiffness_z",
                       "stiffness_min"] = "critical_depth"
    singularity_margin: float = Field(0.02, ge=0, le=1)


class WorkspaceCfg(StrictModel):
    dx_m: list[float] = Field(min_length=1)
    dy_m: list[float] = Field(min_length=1)
    rotation_step_deg: float = Field(10.0, ge=0.01, le=180)


class PlanConfig(StrictModel):
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
    notes: tuple[str, ...] = ()
    x_hint: np.ndarray | None = None


def _resolve(base: Path, name: str) -> Path:
    p = Path(name)
    return p if p.is_absolute() else base.parent / p


def load_plan_config(path: str | Path, x_hint: Any = None) -> PlanInputs:
    """Read, validate and resolve a plan config (errors name the file, key, value, unit).

    ``x_hint`` (3 numbers, the frame of ``bore.axis``) overrides ``bore.x_hint``: the
    boring frame's X is its projection onto the plane normal to the bore axis."""
    from robobore.dynamics.structure import check_unit_vector
    from robobore.io.config import load_toml, validate_model
    from robobore.robot.stiffness import JointStiffness

    p = Path(path)
    raw = load_toml(p)
    cfg = validate_model(PlanConfig, raw, source=p)
    f = str(p)
    robot, robot_notes = _plan_robot(cfg, raw, p)
    if not robot.links:
        raise ConfigError(
            f"robot '{robot.name}' has no inertial data (mass, centre of mass and inertia per "
            "link), which the pose-dependent dynamic model needs",
            file=robot.file or f, field="links" if robot.file else "robot.name",
            value=robot.file or robot.name,
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
    from robobore.robot.stiffness import process_frame, x_hint_arg

    hint = x_hint_arg(x_hint if x_hint is not None else cfg.bore.x_hint,
                      "--x-hint" if x_hint is not None else "bore.x_hint",
                      None if x_hint is not None else f)
    if hint is not None:
        try:
            process_frame(np.column_stack([np.zeros(3), np.zeros(3), axis]), "boring",
                          x_hint=hint)
        except ConfigError as exc:
            raise ConfigError(exc.message, file=None if x_hint is not None else f,
                              field="--x-hint" if x_hint is not None else "bore.x_hint",
                              value=list(hint), expected=exc.expected) from None
    if cfg.part is not None:
        o = _vec3(cfg.part.origin_m, f, "part.origin_m", "m")
        y = math.radians(cfg.part.yaw_deg)
        Rz = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0],
                       [0, 0, 1.0]])
        point = o + Rz @ point
        axis = Rz @ axis
        hint = None if hint is None else Rz @ hint
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
    _check_mode_count(fz, mdata, mfile, sfile, robot, _link_bending(cfg, robot, f))
    # what the files describe (robobore.io.identity): one robot, the config's
    from robobore.io.identity import check_pair, check_robot, read_identity

    id_s = read_identity(sdata, str(sfile))
    id_m = read_identity(mdata, str(mfile))
    named = _names_robot(raw)
    for ident, fl in ((id_s, sfile), (id_m, mfile)):
        check_robot(ident, str(fl), robot.name, robot.description_hash(),
                    f"robot.name in {f}" if named else f"the robot of {f}",
                    verb="was identified for" if fl == sfile else "is a hammer test of")
    if id_s is not None and id_m is not None:
        check_pair({"robot": id_s.get("robot"), "robot_hash": id_s.get("robot_hash")},
                   str(sfile), {"robot": id_m.get("robot"), "robot_hash": id_m.get("robot_hash")},
                   str(mfile))
    # the posture at which the modes were measured
    file_posture = mdata.get("posture_deg")
    if file_posture is None and id_m is not None:
        file_posture = id_m.get("joints_deg")
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
    from robobore.robot.description import check_joint_limits

    check_joint_limits(robot, np.radians(qm), file=f)
    synthetic = bool(sdata.get("synthetic", False)) or bool(mdata.get("synthetic", False))
    return PlanInputs(cfg, raw, p, robot, np.asarray(js.k_Nm_per_rad, float), fz[:, 0],
                      fz[:, 1], np.radians(qm), tcp, point, axis, sfile, mfile, synthetic,
                      _link_bending(cfg, robot, f), tuple(robot_notes), hint)


def _check_mode_count(fz: np.ndarray, mdata: dict[str, Any], mfile: Path, sfile: Path,
                      robot: Any, link_bending: tuple[Any, ...]) -> None:
    """The modes fit the model the stiffness file sets up: inside the band they were
    identified in, at least one per direction of the tool point, at most one per elastic
    coordinate of the model (the joints of the stiffness file, plus the bending coordinates
    of ``link_bending``)."""
    from robobore.equivalent import check_modes_in_band
    from robobore.plan.bending import compliant_planes, redundancy

    check_modes_in_band([{"frequency_Hz": float(v)} for v in fz[:, 0]], mdata.get("band_Hz"),
                        str(mfile))
    n_dof = robot.n_joints if not compliant_planes(link_bending) else int(
        redundancy(robot, link_bending)[1].size)
    n = fz.shape[0]
    if n < 3:
        raise DataError(
            f"{mfile} has {n} mode(s): too few to calibrate the {robot.n_joints}-joint model of "
            f"{sfile} at the measured posture", file=str(mfile), field="modes", value=n,
            expected="at least 3 modes (one per direction of the tool point)")
    if n > n_dof:
        raise DataError(
            f"{mfile} has {n} modes; the model of {sfile} ({robot.name}, {robot.n_joints} "
            f"joint stiffnesses{', with link bending' if n_dof > robot.n_joints else ''}) has "
            f"{n_dof}", file=str(mfile), field="modes", value=n,
            expected=f"at most {n_dof} modes (the lowest modes of the arm; modes of the tool, "
                     "the part or the floor left out, or [[identification.link_bending]])")


def _names_robot(raw: dict[str, Any]) -> bool:
    return isinstance(raw.get("robot"), dict) and "name" in raw["robot"]


def _plan_robot(cfg: PlanConfig, raw: dict[str, Any], p: Path) -> tuple[Any, list[str]]:
    """The plan's robot: ``robot.name``, or (the config names none) the robot the joint
    stiffness file (else the modes file) was identified for, said in a note; the default
    robot when neither the config nor the files name one."""
    from robobore.io.identity import read_identity
    from robobore.robot.description import get_robot, robot_of_identity

    f = str(p)
    if not _names_robot(raw):
        for key in ("joint_stiffness", "modes"):
            fl = _resolve(p, getattr(cfg.identification, key))
            if not fl.is_file():
                continue
            data = _read_json(fl, f, f"identification.{key}")
            ident = read_identity(data, str(fl))
            if ident is None and isinstance(data.get("robot"), str) and data["robot"]:
                ident = {"robot": data["robot"]}
            if ident is not None and ident.get("robot"):
                rb = robot_of_identity(ident, str(fl))
                return rb, [f"robot {rb.name} taken from {fl} ({f} names no robot.name)"]
    rname = cfg.robot.name
    rpath = _resolve(p, rname) if rname.endswith(".toml") else None
    return get_robot(str(rpath) if rpath is not None else rname, file=f,
                     field="robot.name"), []


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


__all__ = ["PlanConfig", "PlanInputs", "load_plan_config"]
