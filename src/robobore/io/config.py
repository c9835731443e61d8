"""Config files (TOML) and their validation into pydantic models.

Human units live in the key names (``feed_mm_per_rev``); conversion to SI happens once,
in the model that parses the file. Validation errors are turned into
:class:`robobore.errors.ConfigError` naming the file, the dotted key, the value and what
was expected.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

from robobore.errors import ConfigError

M = TypeVar("M", bound=BaseModel)


def load_toml(path: str | Path) -> dict[str, Any]:
    """Read a TOML file into a dict; a missing file or a syntax error is a ConfigError."""
    p = Path(path)
    if p.is_dir():
        raise ConfigError("is a folder, not a file", file=str(p), expected="a TOML file")
    if not p.is_file():
        raise ConfigError("config file not found", file=str(p), expected="an existing TOML file")
    try:
        with p.open("rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"not valid TOML: {exc}", file=str(p)) from exc
    except UnicodeDecodeError as exc:
        hint = (" (looks like UTF-16: save it as UTF-8)"
                if exc.object[:2] in (b"\xff\xfe", b"\xfe\xff") else "")
        raise ConfigError(f"not UTF-8 text at byte {exc.start}{hint}", file=str(p),
                          expected="a UTF-8 encoded TOML file") from None
    except OSError as exc:
        raise ConfigError(f"cannot read the file ({exc.strerror or exc})", file=str(p),
                          expected="a readable TOML file") from None


def _loc(err: dict[str, Any]) -> str:
    return ".".join(str(x) for x in err.get("loc", ()))


def validate_model(model: type[M], data: dict[str, Any], source: str | Path = "<config>") -> M:
    """Validate ``data`` into ``model``; errors name the file and the dotted key.

    All validation problems are listed in the message; the first one fills the
    structured ``field``/``value`` attributes of the raised :class:`ConfigError`.
    """
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        errs = exc.errors()
        lines = []
        for e in errs:
            msg = e.get("msg", "invalid")
            inp = e.get("input")
            shown = "" if isinstance(inp, dict) else f" (got {inp!r})"
            lines.append(f"[{_loc(e)}] {msg}{shown}")
        first = errs[0] if errs else {}
        first_in = first.get("input")
        # every line already shows its value: the structured ``value`` is set afterwards so
        # that the message does not repeat the first one
        err = ConfigError("; ".join(lines), file=str(source), field=_loc(first) or None)
        err.value = None if isinstance(first_in, dict) else first_in
        raise err from None


def load_config(model: type[M], path: str | Path) -> M:
    """Read and validate a TOML config file in one step."""
    return validate_model(model, load_toml(path), source=path)
