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
import re
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


#: a cell holding a number with a decimal comma (``0,15``, ``-1,5e-3``)
_DECIMAL_COMMA = re.compile(r"^\s*[-+]?\d+,\d*([eE][-+]?\d+)?\s*$")


def comma_separated(text: str, columns: Any) -> str:
    """CSV text with ``,`` separators from a file separated by ``;``, a tab or ``|``.

    The separator is taken from the first line that is neither blank nor a ``#`` comment
    (the header): when it holds no comma but splits on one of those separators into at
    least one of ``columns``, the file is re-written with commas; in a ``;`` or tab
    separated file a decimal comma (``0,15``) is read as a decimal point. Any other text is
    returned unchanged (the column check then names what is missing)."""
    import csv
    import io

    header = next((ln for ln in text.lstrip("\ufeff").splitlines()
                   if ln.strip() and not ln.lstrip().startswith("#")), "")
    if "," in header:
        return text
    cols = set(columns)
    for sep in (";", "\t", "|"):
        if sep in header and cols & {c.strip() for c in header.split(sep)}:
            rows = list(csv.reader(io.StringIO(text), delimiter=sep))
            if sep != "|":
                rows = [[c.replace(",", ".") if _DECIMAL_COMMA.match(c) else c for c in r]
                        for r in rows]
            buf = io.StringIO()
            csv.writer(buf, lineterminator="\n").writerows(rows)
            return buf.getvalue()
    return text


__all__ = ["read_text", "load_json", "comma_separated"]
