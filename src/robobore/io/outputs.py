"""Output destinations checked before any computation starts.

Every command that writes files calls :func:`check_output_dir` (a folder it will write into:
``--plot``, ``--vtk``, ``--out`` of ``paper``/``sweep``) or :func:`check_output_file` (a file
it will write: ``--out x.nc``, ``--report x.html``, a campaign CSV or UFF file) on each of
its output options first. The folder is created if needed and a probe file is written and
removed in it, so an existing file where a folder is expected, a folder that cannot be
created and a read-only folder are each one clear :class:`~robobore.errors.ConfigError`
(naming the option, the path and the cause) before the simulation runs, not a traceback
after it.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from robobore.errors import ConfigError


def _probe(folder: Path, option: str, what: str) -> None:
    try:
        fd, name = tempfile.mkstemp(prefix=".robobore-probe.", dir=folder)
        os.close(fd)
        os.unlink(name)
    except OSError as exc:
        raise ConfigError(f"cannot write into the folder ({exc.strerror or exc})",
                          file=str(folder), field=option,
                          expected=f"a writable folder for {what}") from None


def _make_dir(folder: Path, option: str, what: str) -> None:
    if folder.exists() and not folder.is_dir():
        raise ConfigError("is an existing file, not a folder", file=str(folder), field=option,
                          expected=f"a folder (or a new name) for {what}")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        # a component of the path is a file
        raise ConfigError("cannot create the folder: a part of the path is a file",
                          file=str(folder), field=option,
                          expected=f"a folder path for {what}") from None
    except OSError as exc:
        raise ConfigError(f"cannot create the folder ({exc.strerror or exc})",
                          file=str(folder), field=option,
                          expected=f"a creatable folder for {what}") from None


def check_output_dir(path: str | Path | None, option: str, what: str = "the output files"
                     ) -> Path | None:
    """Create the folder ``path`` (and its parents) and check that files can be written in
    it; ``None`` passes through. Raises :class:`ConfigError` naming ``option``."""
    if path is None:
        return None
    folder = Path(path)
    _make_dir(folder, option, what)
    _probe(folder, option, what)
    return folder


def check_output_file(path: str | Path | None, option: str, what: str = "the output file"
                      ) -> Path | None:
    """Check that the file ``path`` can be written (atomically, beside itself): its folder is
    created and writable, and ``path`` is not an existing folder. ``None`` passes through."""
    if path is None:
        return None
    p = Path(path)
    if p.is_dir():
        raise ConfigError("is an existing folder, not a file", file=str(p), field=option,
                          expected=f"a file name for {what}")
    if p.name in ("", ".", ".."):
        raise ConfigError("no file name", file=str(p), field=option,
                          expected=f"a file name for {what}")
    folder = p.parent
    try:
        _make_dir(folder, option, what)
        _probe(folder, option, what)
    except ConfigError as exc:  # name the file the user gave, and its folder
        raise ConfigError(f"its folder {folder}: {exc.message}", file=str(p), field=option,
                          expected=exc.expected) from None
    if p.exists() and not os.access(p, os.W_OK) and not os.access(folder, os.W_OK):
        raise ConfigError("the file exists and cannot be replaced", file=str(p), field=option,
                          expected=f"a writable destination for {what}")
    return p


__all__ = ["check_output_dir", "check_output_file"]
