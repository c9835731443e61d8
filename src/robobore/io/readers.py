"""Reading JSON files given by the user, with one clear error for every way it can fail.

:func:`load_json` reports a missing file, a folder, a permission or other OS error, text
that is not UTF-8 (UTF-16 from a Windows editor, a binary file), invalid JSON and a top
level that is not the expected kind (a list where an object is expected) as one
:class:`~robobore.errors.ConfigError` (or the ``error`` class a caller names, e.g.
:class:`~robobore.errors.DataError` for measurement files) naming the file, what was expected
and the cause.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from robobore.errors import ConfigError, InputError


def read_text(path: str | Path, what: str = "text file", expected: str = "a UTF-8 text file",
              error: type[InputError] = ConfigError) -> str:
    """The UTF-8 text of ``path`` (a BOM is accepted); every failure is an ``error``."""
    p = Path(path)
    if not p.is_file():
        why = "is a folder, not a file" if p.is_dir() else f"{what} not found"
        raise error(why, file=str(p), expected=expected)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise error(f"cannot read the {what} ({exc.strerror or exc})", file=str(p),
                          expected=expected) from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        hint = (" (looks like UTF-16: save it as UTF-8)"
                if data[:2] in (b"\xff\xfe", b"\xfe\xff") else "")
        raise error(f"not UTF-8 text at byte {exc.start}{hint}", file=str(p),
                    expected=expected) from None


def load_json(path: str | Path, what: str = "JSON file", expected: str = "a JSON object",
              kind: type | None = dict, error: type[InputError] = ConfigError) -> Any:
    """Parse the JSON file ``path``; its top level must be a ``kind`` (dict by default, None:
    any); every failure is an ``error``."""
    p = Path(path)
    text = read_text(p, what, f"a UTF-8 JSON file: {expected}", error)
    try:
        data = json.loads(text)
    except ValueError as exc:
        raise error(f"not valid JSON ({exc})", file=str(p), expected=expected) from None
    if kind is not None and not isinstance(data, kind):
        got = {dict: "an object (table)", list: "a list"}.get(type(data), type(data).__name__)
        raise error(f"the file holds {got} at the top level", file=str(p),
                    expected=expected)
    return data


__all__ = ["read_text", "load_json"]
