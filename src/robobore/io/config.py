"""Config files (TOML) and their validation into pydantic models.

Human units live in the key names (``feed_mm_per_rev``); conversion to SI happens once,
in the model that parses the file. Validation errors are turned into
:class:`robobore.errors.ConfigError` naming the file, the dotted key, the value and what
was expected.
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path
from types import UnionType
from typing import Any, Literal, TypeVar, Union, get_args, get_origin

from pydantic import BaseModel, ValidationError

from robobore.errors import ConfigError
from robobore.io import ranges

M = TypeVar("M", bound=BaseModel)


def load_toml(path: str | Path) -> dict[str, Any]:
    """Read a TOML file into a dict; a missing, unreadable or non-UTF-8 file or a syntax
    error is a ConfigError naming the file.

    While the range checks are off (``--no-range-check``) the dict carries
    ``range_check = {disabled = "--no-range-check"}``, so that the config recorded in the
    results says so (:mod:`robobore.io.ranges`).
    """
    p = Path(path)
    if p.is_dir():
        raise ConfigError("is a folder, not a file", file=str(p), expected="a TOML file")
    if not p.is_file():
        raise ConfigError("config file not found", file=str(p), expected="an existing TOML file")
    try:
        with p.open("rb") as fh:
            data = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"not valid TOML: {exc}", file=str(p),
                          expected="a TOML file (key = value lines, [section] headers)") from None
    except UnicodeDecodeError as exc:
        hint = (" (looks like UTF-16: save it as UTF-8)"
                if exc.object[:2] in (b"\xff\xfe", b"\xfe\xff") else "")
        raise ConfigError(f"not UTF-8 text at byte {exc.start}{hint}", file=str(p),
                          expected="a UTF-8 encoded TOML file") from None
    except OSError as exc:
        raise ConfigError(f"cannot read the file ({exc.strerror or exc})", file=str(p),
                          expected="a readable TOML file") from None
    off = ranges.provenance()
    if off is not None:
        rc = data.get(ranges.OVERRIDE_KEY)
        data[ranges.OVERRIDE_KEY] = {**(rc if isinstance(rc, dict) else {}), **off}
    return data


def _toml_key(k: Any) -> str:
    k = str(k)
    return k if k and all(c.isascii() and (c.isalnum() or c in "_-") for c in k) else json.dumps(k)


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        if v != v:
            return "nan"
        if v in (float("inf"), float("-inf")):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string is a TOML basic string
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(x)}"
                                for k, x in v.items()) + " }"
    raise TypeError(f"no TOML form for {type(v).__name__} {v!r}")


def dump_toml(data: dict[str, Any]) -> str:
    """The TOML text of a dict as :func:`load_toml` reads it back (tables, arrays of tables,
    scalars, arrays, nan/inf): for writing a modified config (tests, benchmarks, sweeps)."""
    out: list[str] = []

    def is_aot(v: Any) -> bool:
        return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)

    def table(t: dict[str, Any], name: str) -> None:
        for k, v in t.items():
            if not isinstance(v, dict) and not is_aot(v):
                out.append(f"{_toml_key(k)} = {_toml_value(v)}")
        for k, v in t.items():
            sub = f"{name}.{_toml_key(k)}" if name else _toml_key(k)
            if isinstance(v, dict):
                out.append(f"[{sub}]")
                table(v, sub)
            elif is_aot(v):
                for x in v:
                    out.append(f"[[{sub}]]")
                    table(x, sub)

    table(data, "")
    return "\n".join(out) + "\n"


def _allows_bool(ann: Any) -> bool:
    if ann is bool or ann is Any:
        return True
    if get_origin(ann) is Literal:
        return any(isinstance(a, bool) for a in get_args(ann))
    if get_origin(ann) in (Union, UnionType):
        return any(_allows_bool(a) for a in get_args(ann))
    return False


def _allows_number(ann: Any) -> bool:
    if ann in (int, float):
        return True
    if get_origin(ann) in (Union, UnionType):
        return any(_allows_number(a) for a in get_args(ann))
    return False


def _check_bools(ann: Any, v: Any, path: str, source: str) -> None:
    """Refuse a TOML/JSON boolean where the model expects a number (``depth_mm = true``
    would otherwise be read as 1)."""
    if isinstance(v, bool):
        if not _allows_bool(ann) and ann is not str:
            rng = ranges.quantity_of(path) if path else None
            unit = f" in {rng.unit}" if rng is not None and rng.unit != "-" else ""
            what = f"a number{unit}" if _allows_number(ann) else "not a boolean"
            raise ConfigError("a boolean where a number is expected" if _allows_number(ann)
                              else "a boolean is not accepted here", file=source,
                              field=path or None, value=v, expected=what)
        return
    options = list(get_args(ann)) if get_origin(ann) in (Union, UnionType) else [ann]
    for a in options:
        if isinstance(a, type) and issubclass(a, BaseModel) and isinstance(v, dict):
            for name, f in a.model_fields.items():
                key = f.alias or name
                if key in v:
                    _check_bools(f.annotation, v[key], f"{path}.{key}" if path else key,
                                 source)
            return
        origin, args = get_origin(a), get_args(a)
        if origin in (list, tuple) and isinstance(v, list) and args:
            for i, item in enumerate(v):
                _check_bools(args[0], item, f"{path}.{i}", source)
            return
        if origin is dict and isinstance(v, dict) and len(args) == 2:
            for k, item in v.items():
                _check_bools(args[1], item, f"{path}.{k}" if path else str(k), source)
            return


def _loc(err: dict[str, Any]) -> str:
    return ".".join(str(x) for x in err.get("loc", ()))


def validate_model(model: type[M], data: dict[str, Any], source: str | Path = "<config>") -> M:
    """Validate ``data`` into ``model``; errors name the file and the dotted key.

    Before the model sees the data, booleans where the model expects numbers are refused and
    every number is checked against the plausible range of its quantity
    (:mod:`robobore.io.ranges`; the top-level ``[range_check]`` table is read there and not
    passed to the model).

    All validation problems are listed in the message; the first one fills the
    structured ``field``/``value`` attributes of the raised :class:`ConfigError`.
    """
    src = str(source)
    file = None if src.startswith("<") else src
    if isinstance(data, dict):
        _check_bools(model, data, "", src)
        ranges.check_tree(data, file if file is not None else src)
        data = {k: v for k, v in data.items() if k != ranges.OVERRIDE_KEY}
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        errs = exc.errors()
        lines = []
        for e in errs:
            msg = e.get("msg", "invalid")
            inp = e.get("input")
            shown = "" if isinstance(inp, dict) else f" (got {inp!r})"
            note = ""
            if e.get("type") == "extra_forbidden":
                keys = _keys_at(model, e.get("loc", ())[:-1])
                msg = "unknown key (a typo?)"
                note = f" -- the keys here: {', '.join(keys)}" if keys else ""
            elif e.get("type") == "missing":
                msg, shown = "required key missing", ""
            lines.append(f"[{_loc(e) or 'top level'}] {msg}{shown}{note}")
        first = errs[0] if errs else {}
        first_in = first.get("input")
        kind = first.get("type")
        expected = {"extra_forbidden": "only the documented keys",
                    "missing": "every required key"}.get(str(kind))
        # every line already shows its value: the structured ``value`` is set afterwards so
        # that the message does not repeat the first one
        err = ConfigError("; ".join(lines), file=str(source), field=_loc(first) or None,
                          expected=expected)
        err.value = None if isinstance(first_in, dict) else first_in
        raise err from None


def _keys_at(model: Any, loc: tuple[Any, ...]) -> list[str]:
    """The keys of the (sub-)model at ``loc`` (for "unknown key" messages)."""
    cur = model
    for part in loc:
        if isinstance(part, int):
            continue
        if not (isinstance(cur, type) and issubclass(cur, BaseModel)) or \
                part not in cur.model_fields:
            return []
        ann = cur.model_fields[part].annotation
        options = list(get_args(ann)) if get_origin(ann) in (Union, UnionType, list) else [ann]
        cur = next((a for a in options if isinstance(a, type) and issubclass(a, BaseModel)),
                   None)
    if isinstance(cur, type) and issubclass(cur, BaseModel):
        return [f.alias or n for n, f in cur.model_fields.items()]
    return []


def load_config(model: type[M], path: str | Path) -> M:
    """Read and validate a TOML config file in one step."""
    return validate_model(model, load_toml(path), source=path)
