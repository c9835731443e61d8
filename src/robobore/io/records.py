"""The base of the typed results of the stages: frozen dataclasses with ``to_dict()``.

A result class derives from :class:`Record` and is declared
``@dataclass(frozen=True, slots=True)``; its fields are documented one by one (``#:`` above
the field, in the unit its name carries). ``to_dict()`` gives the JSON-ready dict of the
entry point that returns it: the fields in declaration order, tuples as lists, nested records
as dicts. A field named in ``_OMIT`` is left out while it is None (a key the entry point
adds only in some cases), a field in ``_SKIP`` always (an in-memory object). :func:`json_types`
gives a record's keys with the JSON types each may take (what the contract tests store);
:func:`json_mismatches` checks a JSON document against such a key map.
"""

from __future__ import annotations

import types
import typing
from dataclasses import fields, is_dataclass
from typing import Any

__all__ = ["Record", "plain", "json_types", "json_mismatches"]


def plain(v: Any) -> Any:
    """``v`` with records as dicts and tuples as lists (recursively); other values as they
    are (numpy arrays stay arrays, as the entry points return them)."""
    if is_dataclass(v) and not isinstance(v, type):
        return v.to_dict()  # type: ignore[attr-defined]
    if isinstance(v, tuple):
        return [plain(x) for x in v]
    if isinstance(v, list):
        return [plain(x) for x in v]
    if isinstance(v, dict):
        return {k: plain(x) for k, x in v.items()}
    return v


class Record:
    """``to_dict``: the fields in order, ``_OMIT`` fields left out while None, ``_SKIP``
    fields (in-memory objects of no JSON) left out always."""

    __slots__ = ()
    _OMIT: frozenset[str] = frozenset()
    _SKIP: frozenset[str] = frozenset()

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for f in fields(self):  # type: ignore[arg-type]
            if f.name in self._SKIP:
                continue
            v = getattr(self, f.name)
            if v is None and f.name in self._OMIT:
                continue
            out[f.name] = plain(v)
        return out


def _json_type(t: Any) -> list[Any]:
    if t is Any:
        return ["any"]
    origin = typing.get_origin(t)
    if origin in (typing.Union, types.UnionType):
        out: list[Any] = []
        for a in typing.get_args(t):
            out += [x for x in _json_type(a) if x not in out]
        return out
    if t is type(None):
        return ["null"]
    if t is bool:
        return ["boolean"]
    if t is int:
        return ["integer"]
    if t is float:
        return ["number"]
    if t is str:
        return ["string"]
    if isinstance(t, type) and issubclass(t, Record) and is_dataclass(t):
        return [json_types(t)]
    if origin in (tuple, list) or t in (tuple, list) or getattr(t, "__name__", "") == "ndarray":
        return ["array"]
    if origin is dict or t is dict:
        return ["object"]
    raise TypeError(f"no JSON type for {t!r}")


def json_types(cls: type) -> dict[str, list[Any]]:
    """The keys of ``cls``'s ``to_dict()`` in order, each with the JSON types its value may
    take ("null", "boolean", "integer", "number", "string", "array", "object", "any"; a
    nested record as its own key map), from the field annotations. A field of ``_OMIT`` is
    marked "absent" (left out while None)."""
    hints = typing.get_type_hints(cls)
    out: dict[str, list[Any]] = {}
    for f in fields(cls):
        if f.name in cls._SKIP:  # type: ignore[attr-defined]
            continue
        tt = _json_type(hints[f.name])
        if f.name in cls._OMIT:  # type: ignore[attr-defined]
            tt = ["absent"] + tt
        out[f.name] = tt
    return out


_CHECKS = {
    "null": lambda v: v is None,
    "boolean": lambda v: isinstance(v, bool),
    "integer": lambda v: isinstance(v, int) and not isinstance(v, bool),
    # a non-finite number is written as null (robobore.io.results.to_jsonable)
    "number": lambda v: v is None or (isinstance(v, int | float) and not isinstance(v, bool)),
    "string": lambda v: isinstance(v, str),
    "array": lambda v: isinstance(v, list),
    "object": lambda v: isinstance(v, dict),
    "any": lambda v: True,
}


def json_mismatches(doc: dict[str, Any], spec: dict[str, list[Any]],
                    where: str = "") -> list[str]:
    """Where the parsed JSON ``doc`` departs from the key map ``spec`` of :func:`json_types`:
    keys missing (unless "absent" is allowed), keys not in ``spec``, keys out of order, values
    of another JSON type; one line each (empty: ``doc`` conforms)."""
    bad = []
    extra = [k for k in doc if k not in spec]
    bad += [f"{where}{k}: not in the contract" for k in extra]
    order = [k for k in spec if k in doc]
    if [k for k in doc if k in spec] != order:
        bad.append(f"{where}keys out of order: {list(doc)} (contract {list(spec)})")
    for k, allowed in spec.items():
        if k not in doc:
            if "absent" not in allowed:
                bad.append(f"{where}{k}: missing")
            continue
        v = doc[k]
        subs = [a for a in allowed if isinstance(a, dict)]
        if any(isinstance(a, str) and a in _CHECKS and _CHECKS[a](v) for a in allowed):
            continue
        if isinstance(v, dict) and subs:
            bad += json_mismatches(v, subs[0], f"{where}{k}.")
            continue
        bad.append(f"{where}{k}: {type(v).__name__} {v!r:.40} is not one of {allowed}")
    return bad
