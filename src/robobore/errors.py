"""One error hierarchy for the whole package.

Every error a user can cause with bad input is a :class:`RoboboreError`. Errors about input
name where the problem is (file, row, field/column), the offending value and what was
expected (with its unit), so the CLI can print one clear line instead of a traceback.
"""

from __future__ import annotations

from typing import Any


class RoboboreError(Exception):
    """Base class of every error robobore raises on purpose."""


def _fmt_location(file: str | None, row: int | None, field: str | None) -> str:
    parts = []
    if file is not None:
        parts.append(str(file))
    if row is not None:
        parts.append(f"row {row}")
    if field is not None:
        parts.append(f"field '{field}'")
    return ", ".join(parts)


class InputError(RoboboreError, ValueError):
    """Bad user input: a file, a row, a field, a value and what was expected.

    Parameters
    ----------
    message:
        What is wrong, in words.
    file, row, field:
        Where. ``row`` is 1-based as a user counts data rows in a CSV (header excluded) or
        the line number in a text file; ``field`` is a CSV column or a dotted config key.
    value:
        The offending value, if there is one.
    expected:
        What was expected, including the unit (e.g. ``"a number in N"``).
    """

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        row: int | None = None,
        field: str | None = None,
        value: Any = None,
        expected: str | None = None,
    ) -> None:
        self.file = None if file is None else str(file)
        self.row = row
        self.field = field
        self.value = value
        self.expected = expected
        self.message = message
        text = message
        loc = _fmt_location(self.file, row, field)
        if loc:
            text = f"{loc}: {text}"
        if value is not None:
            text += f" (got {value!r})"
        if expected:
            text += f"; expected {expected}"
        super().__init__(text)


class ConfigError(InputError):
    """Bad configuration file or option (TOML key, CLI option)."""


class DataError(InputError):
    """Bad data file (CSV, UFF, NPZ): missing column, non-numeric value, wrong shape."""


class IdentificationError(RoboboreError):
    """An identification problem that the data cannot solve (too few equations, ...)."""


class NumericalError(RoboboreError):
    """A simulation became numerically unstable or produced non-finite values."""


__all__ = [
    "RoboboreError",
    "InputError",
    "ConfigError",
    "DataError",
    "IdentificationError",
    "NumericalError",
]
