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
_KEYS = ("kind", "robot", "robot_hash", "robot_file", "joints_deg", "tcp_m", "frame",
         "synthetic", "source")


def make_identity(kind: str, *, robot: str | None = None, robot_hash: str | None = None,
                  robot_file: str | None = None, joints_deg: Any = None, tcp_m: Any = None,
                  frame: str | None = None, synthetic: bool | None = None,
                  source: str | None = None) -> dict[str, Any]:
    """The identity block of a result file (module docstring); ``None`` where unknown."""
    return {
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
    out = {k: blk.get(k) for k in _KEYS}
    out["joints_deg"] = _floats(blk.get("joints_deg"), file, "joints_deg", None, "deg")
    out["tcp_m"] = _floats(blk.get("tcp_m"), file, "tcp_m", 3, "m")
    return out


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


def unchecked_note(file: str) -> str:
    """The note for a file without an identity block."""
    return (f"{file} records no identity (robot, posture, frame): it could not be checked "
            "against the other inputs")


__all__ = ["IDENTITY_KEY", "POSTURE_TOL_DEG", "TCP_TOL_M", "make_identity", "read_identity",
           "same_robot", "check_robot", "posture_differs", "check_posture", "check_pair",
           "merged", "unchecked_note"]
