"""The stored FE validation record: the ``--json`` output of ``robobore fe validate``
(:mod:`robobore.cutting.fe.models.validate`) read back as a :class:`ValidationRecord`
(:func:`load_validation_record`), and the record of the default model bundled with the package
(:func:`bundled_validation_path`, robobore/data/fe_validation/README.md)."""

from __future__ import annotations

import copy
from dataclasses import dataclass, fields, is_dataclass
from pathlib import Path
from types import UnionType
from typing import Any, Union, get_args, get_origin, get_type_hints

from robobore.cutting.fe.models.results import (
    MeasuredValues,
    PerQuantity,
    ValidationPoint,
    ValidationResult,
    ValidationSummary,
)
from robobore.errors import DataError
from robobore.io.readers import load_json

#: the bundled validation record of the default model: the ``--json`` output of
#: ``robobore fe validate examples/fe_orthogonal.toml --measured
#: ../shared/data/ti64_orthogonal_cutting_forces.json`` (robobore/data/fe_validation/README.md)
BUNDLED_RECORD = "tc4_default_model.json"


def bundled_validation_path() -> Path:
    """Path of the bundled validation record of the default FE model (TC4)."""
    from importlib import resources

    return Path(str(resources.files("robobore") / "data" / "fe_validation" / BUNDLED_RECORD))


@dataclass(frozen=True)
class ValidationRecord(ValidationResult):
    """A stored FE validation: the ``--json`` output of ``robobore fe validate`` read back by
    :func:`load_validation_record`. The validation's fields (``points``, ``summary``,
    ``config``, ``device``, ``out_dir``) and what the command adds to them; ``to_dict()`` gives
    back the JSON the record was read from, key for key and in its order."""

    _OMIT = frozenset({"measured_file", "identity", "files"})

    #: the measured-forces file the points were compared with (None: not in the record)
    measured_file: str | None = None
    #: the command's identity block (:func:`robobore.io.identity.fe_identity`; None: not in
    #: the record)
    identity: dict[str, Any] | None = None
    #: the files the command wrote, name -> path (``--plot``: ``png_validation``; None: none)
    files: dict[str, str] | None = None

    def to_dict(self) -> dict[str, Any]:
        return copy.deepcopy(super().to_dict())


def _kind(tp: Any) -> str | type:
    """The kind a field of type ``tp`` holds in the record: its table's type (a result
    dataclass), or "num" (float, int), "bool", "str", with "?" where it may be null."""
    if is_dataclass(tp):
        return tp
    args = set(get_args(tp)) if get_origin(tp) in (Union, UnionType) else {tp}
    base = args - {type(None)}
    kind = ("num" if base <= {float, int} and base else "bool" if base == {bool}
            else "str" if base == {str} else None)
    if kind is None:
        raise TypeError(f"no record kind for the field type {tp!r}")
    return kind + ("?" if type(None) in args else "")


#: the value each key of a record's tables holds, from the result types' fields (in their
#: order): a kind ("num", "bool", "str"; "?": may be null) or the table's type
_KINDS: dict[type, dict[str, Any]] = {
    cls: {f.name: _kind(get_type_hints(cls)[f.name]) for f in fields(cls)}
    for cls in (PerQuantity, MeasuredValues, ValidationPoint, ValidationSummary)}
_EXPECT = {"num": "a number", "bool": "true or false", "str": "a string"}


def _checked(kind: str, v: Any, f: str, field: str, row: int | None) -> Any:
    k = kind.rstrip("?")
    ok = ((v is None and kind.endswith("?")) or (k == "bool" and isinstance(v, bool))
          or (k == "str" and isinstance(v, str))
          or (k == "num" and isinstance(v, int | float) and not isinstance(v, bool)))
    if not ok:
        raise DataError("validation record value of the wrong type", file=f, row=row,
                        field=field, value=v,
                        expected=_EXPECT[k] + (" or null" if kind.endswith("?") else ""))
    return v


def _table(cls: type, v: Any, f: str, field: str, row: int | None) -> Any:
    """``v`` (a table of the record) as ``cls``: exactly ``_KINDS[cls]``'s keys, each of its
    kind."""
    kinds = _KINDS[cls]
    if not isinstance(v, dict):
        raise DataError("validation record entry is not a table", file=f, row=row, field=field,
                        value=v, expected=f"a JSON object with the keys {list(kinds)}")
    miss = [k for k in kinds if k not in v]
    if miss:
        raise DataError("validation record lacks a key", file=f, row=row,
                        field=f"{field}.{miss[0]}", expected=f"the keys {list(kinds)}")
    extra = [k for k in v if k not in kinds]
    if extra:
        raise DataError("unknown key in the validation record", file=f, row=row,
                        field=f"{field}.{extra[0]}", expected=f"only the keys {list(kinds)}")
    return cls(**{k: (_table(kind, v[k], f, f"{field}.{k}", row) if isinstance(kind, type)
                      else _checked(kind, v[k], f, f"{field}.{k}", row))
                  for k, kind in kinds.items()})


def load_validation_record(path: str | Path) -> ValidationRecord:
    """A validation record (the ``--json`` output of ``robobore fe validate``), checked:
    ``points`` (a non-empty list, each point with exactly the keys of the ``--json`` contract),
    ``summary``, ``config``, ``device`` and ``out_dir``, and the ``measured_file``,
    ``identity`` and ``files`` the command adds (each optional); a missing, malformed or
    unknown key is a :class:`DataError` naming the file and key."""
    f = str(path)
    data = load_json(Path(path), "FE validation record", "the --json output of robobore fe "
                     "validate", kind=dict, error=DataError)
    pts = data.get("points")
    if not isinstance(pts, list) or not pts:
        raise DataError("no validation points", file=f, field="points", value=pts,
                        expected="a non-empty list of points (robobore fe validate --json)")
    points = tuple(_table(ValidationPoint, pt, f, f"points[{i}]", i) for i, pt in enumerate(pts))
    if not isinstance(data.get("summary"), dict):
        raise DataError("no summary", file=f, field="summary", value=data.get("summary"),
                        expected="{max_abs_error, mean_abs_error, n_measured} per quantity")
    summary = _table(ValidationSummary, data["summary"], f, "summary", None)
    top = {"config": "str", "device": "str", "out_dir": "str?"}
    for k, kind in top.items():
        if k not in data:
            raise DataError("validation record lacks a key", file=f, field=k,
                            expected=f"the keys points, summary, {', '.join(top)}")
        _checked(kind, data[k], f, k, None)
    extra = {"measured_file": str, "identity": dict, "files": dict}
    for k, typ in extra.items():
        if k in data and not isinstance(data[k], typ):
            raise DataError("validation record value of the wrong type", file=f, field=k,
                            value=data[k], expected="a string" if typ is str else "a table")
    for k, v in (data.get("files") or {}).items():
        _checked("str", v, f, f"files.{k}", None)
    unknown = [k for k in data if k not in ("points", "summary", *top, *extra)]
    if unknown:
        raise DataError("unknown key in the validation record", file=f, field=unknown[0],
                        expected=f"only the keys points, summary, {', '.join([*top, *extra])}")
    return ValidationRecord(points=points, summary=summary,
                            **{k: data[k] for k in top}, **{k: data.get(k) for k in extra})


__all__ = ["BUNDLED_RECORD", "bundled_validation_path", "ValidationRecord",
           "load_validation_record"]
