"""What a robobore result file describes, recorded in it and checked where it is read.

Every JSON that travels between commands (joint stiffness, modes, equivalent model, plan)
carries an ``"identity"`` block::

    {"kind": "joint stiffness", "robot": "kr240-r2900", "robot_hash": "3f0c9a1b2d4e5f60",
     "joints_deg": [20.0, 20.0, 10.0, 0.0, -30.0, 0.0], "tcp_m": [0.0, 0.0, 0.35],
     "frame": "boring", "synthetic": true, "source": "kuka_campaign.csv"}

``robot_hash`` is :func:`robobore.io.hashing.stable_hash` of the robot's kinematic
description (D-H data, joint limits, base transform; not its name), so a renamed copy of a
robot file is the same robot and an edited one is not. ``joints_deg`` is the posture the
file describes (the campaign's first, boring posture; the hammer-test posture), ``tcp_m``
the tool point in the flange frame, ``frame`` the process frame of directional values and
``synthetic`` whether the data came from a virtual experiment (None: not known). A key that
does not apply is null.

Files about the cut rather than the robot (cutting coefficients, FE results) record the
``material`` (its name as the config gives it) and the ``insert`` geometry (the config's
insert or tool keys: ``rake_deg``, ``edge_radius_um``, ``inclination_deg``, ...)::

    {"kind": "cutting coefficients", "material": "TC4",
     "insert": {"rake_deg": 7.0, "edge_radius_um": 20.0, "inclination_deg": 0.0,
                "clearance_deg": 7.0},
     "source": "robobore calibrate forces (2D FE, ...)", "synthetic": null, ...}

:func:`check_material` and :func:`check_insert` refuse a coefficients file of another
material or insert edge (rake and inclination more than :data:`INSERT_ANGLE_TOL_DEG` apart,
edge radii more than :data:`EDGE_RADIUS_TOL_UM`) than the config that uses it.

The readers compare what they receive with the options, the config and each other:
:func:`check_robot`, :func:`check_posture` and :func:`check_pair` raise a
:class:`~robobore.errors.ConfigError` naming both files (or the file and the option) and
both values. A file without an identity block (written before robobore recorded one) is
accepted; :func:`unchecked_note` says that its identity could not be checked.
"""

from __future__ import annotations

import math
from typing import Any

from robobore.errors import ConfigError

IDENTITY_KEY = "identity"
#: two postures whose joint angles differ by more than this (deg) are different postures
POSTURE_TOL_DEG = 0.5
#: two tool points further apart than this (m) are different tool points
TCP_TOL_M = 1e-3
#: two insert angles (rake, inclination) further apart than this (deg) are different edges
INSERT_ANGLE_TOL_DEG = 0.5
#: two edge radii further apart than this (um) are different edges
EDGE_RADIUS_TOL_UM = 2.0
#: the insert keys an identity may record (the units are in the names)
INSERT_KEYS = ("nose_radius_mm", "approach_angle_deg", "end_edge_angle_deg", "rake_deg",
               "inclination_deg", "clearance_deg", "edge_radius_um")
#: the insert keys the orthogonal cutting coefficients depend on (checked on arrival)
COEFFICIENT_INSERT_KEYS = ("rake_deg", "edge_radius_um", "inclination_deg")
_KEYS = ("kind", "robot", "robot_hash", "robot_file", "joints_deg", "tcp_m", "frame",
         "synthetic", "source", "material", "insert")


def make_identity(kind: str, *, robot: str | None = None, robot_hash: str | None = None,
                  robot_file: str | None = None, joints_deg: Any = None, tcp_m: Any = None,
                  frame: str | None = None, synthetic: bool | None = None,
                  source: str | None = None, material: str | None = None,
                  insert: Any = None) -> dict[str, Any]:
    """The identity block of a result file (module docstring); ``None`` where unknown.
    ``material`` and ``insert`` (a dict or an object with the :data:`INSERT_KEYS`
    attributes) appear only when given."""
    out = {
        "kind": kind,
        "robot": robot,
        "robot_hash": robot_hash,
        "robot_file": None if not robot_file else str(robot_file),
        "joints_deg": None if joints_deg is None else [float(v) for v in joints_deg],
        "tcp_m": None if tcp_m is None else [float(v) for v in tcp_m],
        "frame": frame,
        "synthetic": None if synthetic is None else bool(synthetic),
        "source": None if source is None else str(source),
    }
    if material is not None:
        out["material"] = str(material)
    if insert is not None:
        out["insert"] = insert_of(insert)
    return out


def insert_of(obj: Any) -> dict[str, float]:
    """The :data:`INSERT_KEYS` values of a dict or an object (config section), as floats."""
    get = obj.get if isinstance(obj, dict) else (lambda k: getattr(obj, k, None))
    out = {}
    for k in INSERT_KEYS:
        v = get(k)
        if isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v):
            out[k] = float(v)
    return out


def _floats(v: Any, file: str, key: str, n: int | None, unit: str) -> list[float] | None:
    if v is None:
        return None
    bad = ConfigError("not a list of numbers", file=file, field=f"{IDENTITY_KEY}.{key}",
                      value=v, expected=f"{n or 'a list of'} numbers in {unit} or null")
    if not isinstance(v, list | tuple) or (n is not None and len(v) != n):
        raise bad
    out = []
    for x in v:
        if isinstance(x, bool) or not isinstance(x, int | float) or not math.isfinite(x):
            raise bad
        out.append(float(x))
    return out


def read_identity(data: Any, file: str) -> dict[str, Any] | None:
    """The validated identity block of a loaded JSON object (None: the file has none)."""
    if not isinstance(data, dict) or data.get(IDENTITY_KEY) is None:
        return None
    blk = data[IDENTITY_KEY]
    if not isinstance(blk, dict):
        raise ConfigError("must be an object", file=file, field=IDENTITY_KEY,
                          value=type(blk).__name__,
                          expected="the identity block robobore writes (robot, posture, ...)")
    unknown = sorted(set(blk) - set(_KEYS))
    if unknown:
        raise ConfigError("unknown key", file=file, field=f"{IDENTITY_KEY}.{unknown[0]}",
                          expected=f"only {list(_KEYS)}")
    for key in ("kind", "robot", "robot_hash", "robot_file", "frame", "source"):
        v = blk.get(key)
        if v is not None and not isinstance(v, str):
            raise ConfigError("not a string", file=file, field=f"{IDENTITY_KEY}.{key}",
                              value=v, expected="a string or null")
    syn = blk.get("synthetic")
    if syn is not None and not isinstance(syn, bool):
        raise ConfigError("not a boolean", file=file, field=f"{IDENTITY_KEY}.synthetic",
                          value=syn, expected="true, false or null")
    mat = blk.get("material")
    if mat is not None and not isinstance(mat, str):
        raise ConfigError("not a string", file=file, field=f"{IDENTITY_KEY}.material",
                          value=mat, expected="a material name or null")
    out = {k: blk.get(k) for k in _KEYS}
    out["joints_deg"] = _floats(blk.get("joints_deg"), file, "joints_deg", None, "deg")
    out["tcp_m"] = _floats(blk.get("tcp_m"), file, "tcp_m", 3, "m")
    out["insert"] = _insert_block(blk.get("insert"), file, f"{IDENTITY_KEY}.insert")
    return out


def _insert_block(v: Any, file: str, field: str) -> dict[str, float] | None:
    if v is None:
        return None
    if not isinstance(v, dict):
        raise ConfigError("must be an object", file=file, field=field, value=type(v).__name__,
                          expected=f"{{key: number}} with keys among {list(INSERT_KEYS)}")
    out = {}
    for k, x in v.items():
        if k not in INSERT_KEYS:
            continue  # other insert keys (n_inserts, ...) are not part of the identity
        if isinstance(x, bool) or not isinstance(x, int | float) or not math.isfinite(x):
            raise ConfigError("not a number", file=file, field=f"{field}.{k}", value=x,
                              expected="a finite number (unit in the key's name)")
        out[k] = float(x)
    return out


def cut_identity_of(data: Any, file: str) -> dict[str, Any] | None:
    """The identity of a coefficients (or FE results) file: its ``identity`` block, else
    (a file written before robobore recorded one) its top-level ``material`` and ``insert``
    keys; None when it says neither."""
    ident = read_identity(data, file)
    if ident is not None:
        return ident
    if not isinstance(data, dict):
        return None
    mat = data.get("material") if isinstance(data.get("material"), str) else None
    ins = data.get("insert")
    ins = _insert_block(ins, file, "insert") if isinstance(ins, dict) else None
    if mat is None and not ins:
        return None
    out = make_identity("cutting coefficients")
    out["material"], out["insert"] = mat, ins or None
    return out


def material_key(name: Any) -> str:
    """A material name compared case- and punctuation-blind (``Ti-6Al-4V`` = ``TI6AL4V`` =
    ``TC4``); a path compares by its file name without suffix."""
    s = str(name).strip()
    if s.lower().endswith(".toml"):
        s = s.replace("\\", "/").rsplit("/", 1)[-1][:-5]
    k = "".join(ch for ch in s.upper() if ch.isalnum())
    return {"TI6AL4V": "TC4"}.get(k, k)


def check_material(ident: dict[str, Any] | None, file: str, material: str | None,
                   given_by: str) -> None:
    """Refuse a file made for another material than ``material`` (None: nothing to check)."""
    if ident is None or material is None or not ident.get("material"):
        return
    if material_key(ident["material"]) != material_key(material):
        raise ConfigError(
            f"{file} was made for material {ident['material']}; {given_by} is {material}",
            file=file, field=f"{IDENTITY_KEY}.material", value=ident["material"],
            expected=f"a file for material {material}, or {given_by} naming the file's")


def check_insert(ident: dict[str, Any] | None, file: str, insert: Any, given_by: str,
                 keys: tuple[str, ...] = COEFFICIENT_INSERT_KEYS) -> None:
    """Refuse a file made for another insert edge than ``insert`` (a dict or config section):
    each of ``keys`` both give must agree (angles within :data:`INSERT_ANGLE_TOL_DEG`, the
    edge radius within :data:`EDGE_RADIUS_TOL_UM`)."""
    if ident is None or not ident.get("insert") or insert is None:
        return
    mine = insert_of(insert)
    for k in keys:
        a, b = ident["insert"].get(k), mine.get(k)
        if a is None or b is None:
            continue
        tol = EDGE_RADIUS_TOL_UM if k.endswith("_um") else INSERT_ANGLE_TOL_DEG
        if abs(a - b) > tol:
            unit = "um" if k.endswith("_um") else "deg"
            raise ConfigError(
                f"{file} was made for an insert with {k} = {a:g}; {given_by} has {k} = {b:g}",
                file=file, field=f"{IDENTITY_KEY}.insert.{k}", value=a,
                expected=f"{b:g} {unit} within {tol:g} {unit} (the insert that uses the "
                         "file), or coefficients made for this insert")



def _robot_text(name: Any, h: Any) -> str:
    return f"{name} (hash {h})" if h else str(name)


def same_robot(a: dict[str, Any], b: dict[str, Any]) -> bool | None:
    """Whether two identities describe one robot (None: one of them does not say)."""
    if a.get("robot_hash") and b.get("robot_hash"):
        return a["robot_hash"] == b["robot_hash"]
    if a.get("robot") and b.get("robot"):
        return a["robot"] == b["robot"]
    return None


def check_robot(ident: dict[str, Any] | None, file: str, robot: str, robot_hash: str,
                given_by: str, verb: str = "was identified for") -> None:
    """Refuse a file identified for another robot than the one ``given_by`` names."""
    if ident is None or not (ident.get("robot") or ident.get("robot_hash")):
        return
    if same_robot(ident, {"robot": robot, "robot_hash": robot_hash}) is False:
        raise ConfigError(
            f"{file} {verb} {_robot_text(ident.get('robot'), ident.get('robot_hash'))}"
            f"; {given_by} is {_robot_text(robot, robot_hash)}",
            file=file, field=f"{IDENTITY_KEY}.robot", value=ident.get("robot"),
            expected=f"a file of robot {robot}, or {given_by} naming the file's robot")


def posture_differs(a: Any, b: Any, tol_deg: float = POSTURE_TOL_DEG) -> bool:
    """True when two joint-angle lists (deg) are given and differ (length or > tol)."""
    if a is None or b is None:
        return False
    if len(a) != len(b):
        return True
    return any(abs(float(x) - float(y)) > tol_deg for x, y in zip(a, b, strict=True))


def _fmt_q(q: Any) -> str:
    return "(" + ", ".join(f"{float(v):g}" for v in q) + ") deg"


def check_posture(ident: dict[str, Any] | None, file: str, joints_deg: Any,
                  given_by: str) -> None:
    """Refuse a file that describes another posture than ``joints_deg`` (deg)."""
    if ident is None or not posture_differs(ident.get("joints_deg"), joints_deg):
        return
    raise ConfigError(
        f"{file} describes the posture {_fmt_q(ident['joints_deg'])}; {given_by} is "
        f"{_fmt_q(joints_deg)}", file=file, field=f"{IDENTITY_KEY}.joints_deg",
        expected=f"the same posture within {POSTURE_TOL_DEG:g} deg per joint")


def check_pair(a: dict[str, Any] | None, file_a: str, b: dict[str, Any] | None,
               file_b: str) -> None:
    """Refuse two files that describe different robots, postures, tool points or frames."""
    if a is None or b is None:
        return
    if same_robot(a, b) is False:
        raise ConfigError(
            f"{file_a} describes robot {_robot_text(a.get('robot'), a.get('robot_hash'))}; "
            f"{file_b} describes robot {_robot_text(b.get('robot'), b.get('robot_hash'))}",
            file=file_b, field=f"{IDENTITY_KEY}.robot", value=b.get("robot"),
            expected=f"files of one robot ({a.get('robot')})")
    if posture_differs(a.get("joints_deg"), b.get("joints_deg")):
        raise ConfigError(
            f"{file_a} describes the posture {_fmt_q(a['joints_deg'])}; {file_b} describes "
            f"{_fmt_q(b['joints_deg'])}", file=file_b, field=f"{IDENTITY_KEY}.joints_deg",
            expected=f"files of one posture (within {POSTURE_TOL_DEG:g} deg per joint)")
    ta, tb = a.get("tcp_m"), b.get("tcp_m")
    if ta is not None and tb is not None and math.dist(ta, tb) > TCP_TOL_M:
        raise ConfigError(f"{file_a} describes the tool point {ta} m; {file_b} describes {tb} m",
                          file=file_b, field=f"{IDENTITY_KEY}.tcp_m",
                          expected=f"files of one tool point (within {TCP_TOL_M * 1e3:g} mm)")
    fa, fb = a.get("frame"), b.get("frame")
    if fa and fb and fa != fb:
        raise ConfigError(f"{file_a} is in the {fa} frame; {file_b} is in the {fb} frame",
                          file=file_b, field=f"{IDENTITY_KEY}.frame", value=fb,
                          expected=f"files in one frame ({fa})")


def merged(*idents: dict[str, Any] | None, kind: str, source: str | None = None
           ) -> dict[str, Any]:
    """The identity of a result built from several checked inputs (first known value wins;
    synthetic when any input is)."""
    out = make_identity(kind, source=source)
    syn: list[bool] = []
    for idn in idents:
        if idn is None:
            continue
        for k in ("robot", "robot_hash", "robot_file", "joints_deg", "tcp_m", "frame"):
            if out[k] is None and idn.get(k) is not None:
                out[k] = idn[k]
        if idn.get("synthetic") is not None:
            syn.append(bool(idn["synthetic"]))
    out["synthetic"] = any(syn) if syn else None
    return out


def check_cut_file(path: Any, *, material: str | None, insert: Any, material_by: str,
                   insert_by: str) -> str | None:
    """Read a coefficients file (JSON or TOML) and refuse it when it was made for another
    material (``material`` None: not checked) or insert edge than ``insert``; the note for a
    file that records neither (None when checked)."""
    from pathlib import Path

    p = Path(path)
    if p.suffix.lower() == ".json":
        from robobore.io.readers import load_json

        data = load_json(p, "coefficient file", "a JSON object of cutting coefficients")
    else:
        from robobore.io.config import load_toml

        data = load_toml(p)
    ident = cut_identity_of(data, str(p))
    if ident is None:
        return f"{p} records no material or insert: not checked against the config"
    check_material(ident, str(p), material, material_by)
    check_insert(ident, str(p), insert, insert_by)
    return None


def fe_identity(kind: str, cfg: Any, source: str | None) -> dict[str, Any]:
    """The identity of an FE result (``fe orthogonal`` / ``fe boring`` / ``fe validate``):
    the config's material and insert (its ``[insert]``, else its ``[tool]``), the config
    file and the package version that produced it. An FE run is a simulation, not a
    virtual experiment with a ground truth: ``synthetic`` is null."""
    from robobore import __version__

    mat = getattr(getattr(cfg, "material", None), "name", None)
    ins = getattr(cfg, "insert", None)
    ins = ins if ins is not None and not isinstance(ins, str) else getattr(cfg, "tool", None)
    return make_identity(kind, material=None if mat is None else str(mat),
                         insert={} if ins is None else ins,
                         source=f"robobore {__version__} FE simulation of {source}")


def unchecked_note(file: str) -> str:
    """The note for a file without an identity block."""
    return (f"{file} records no identity (robot, posture, frame): it could not be checked "
            "against the other inputs")


__all__ = ["IDENTITY_KEY", "POSTURE_TOL_DEG", "TCP_TOL_M", "INSERT_ANGLE_TOL_DEG",
           "EDGE_RADIUS_TOL_UM", "INSERT_KEYS", "COEFFICIENT_INSERT_KEYS", "make_identity",
           "read_identity", "insert_of", "cut_identity_of", "material_key", "check_material",
           "check_insert", "same_robot", "check_robot", "posture_differs", "check_posture",
           "check_pair", "merged", "unchecked_note", "fe_identity", "check_cut_file"]
