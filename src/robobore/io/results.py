"""Results files written atomically and durably.

Every writer goes through the same steps: write a temporary file in the destination's
folder, flush it and ``fsync`` it, ``os.replace`` it onto the destination, then ``fsync``
the folder so that the rename itself survives a power cut. An interrupted run never leaves a
half-written or zero-byte file: either the old file (or none) is there, or the complete new
one. :func:`atomic_path` gives writers that need a file name (netCDF, meshio, matplotlib)
the same guarantee; :func:`save_figure` does it for matplotlib figures.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _tmp_path(dest: Path) -> Path:
    """A temporary file beside ``dest`` with the permissions a plain ``open`` would give.

    ``mkstemp`` creates files with mode 0600; results are ordinary user files, so the mode is
    set from the umask (typically 0644) before the rename.
    """
    dest.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(prefix=f".{dest.name}.", suffix=".tmp", dir=dest.parent)
    os.close(fd)
    os.chmod(name, 0o666 & ~_umask())
    return Path(name)


def fsync_dir(folder: str | Path) -> None:
    """``fsync`` a folder so that a rename in it is on disk (no-op where unsupported)."""
    try:
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:  # pragma: no cover - platforms without directory handles
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover - file systems that refuse fsync on folders
        pass
    finally:
        os.close(fd)


def fsync_file(path: str | Path) -> None:
    """``fsync`` a closed file's contents to disk."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextmanager
def atomic_path(path: str | Path, suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` for a writer that needs a file name.

    When the block ends without error the temporary file is synced, renamed onto ``path``
    and the folder synced; on error it is removed and ``path`` is untouched. ``suffix``
    (e.g. ``".png"``) ends the temporary name, for writers that choose the format by the
    name's extension.
    """
    dest = Path(path)
    tmp = _tmp_path(dest)
    if suffix:
        named = tmp.with_name(tmp.name + suffix)
        os.replace(tmp, named)
        tmp = named
    try:
        yield tmp
        fsync_file(tmp)
        os.replace(tmp, dest)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    fsync_dir(dest.parent)


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically and durably; returns the path."""
    dest = Path(path)
    tmp = _tmp_path(dest)
    try:
        with tmp.open("wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, dest)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    fsync_dir(dest.parent)
    return dest


def save_figure(fig: Any, path: str | Path, **savefig_kw: Any) -> Path:
    """``fig.savefig`` to ``path`` atomically and durably (format from the extension)."""
    dest = Path(path)
    fmt = savefig_kw.pop("format", None) or (dest.suffix.lstrip(".") or "png")
    with atomic_path(dest) as tmp:
        fig.savefig(tmp, format=fmt, **savefig_kw)
    return dest


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def to_jsonable(obj: Any) -> Any:
    """Convert numpy scalars/arrays (and nested containers) to plain JSON types.

    Non-finite floats become ``None`` (JSON has no NaN); complex numbers become
    ``{"re": .., "im": ..}``.
    """
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.bool_ | bool):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, complex | np.complexfloating):
        return {"re": to_jsonable(float(obj.real)), "im": to_jsonable(float(obj.imag))}
    if isinstance(obj, float | np.floating):
        f = float(obj)
        return f if np.isfinite(f) else None
    if isinstance(obj, Path):
        return str(obj)
    if hasattr(obj, "to_dict"):
        return to_jsonable(obj.to_dict())
    return obj


def dumps_json(obj: Any) -> str:
    """JSON text of ``obj`` after :func:`to_jsonable`, indented."""
    return json.dumps(to_jsonable(obj), indent=2)


def write_json(path: str | Path, obj: Any) -> Path:
    """Write ``obj`` as JSON, atomically."""
    return atomic_write_text(path, dumps_json(obj) + "\n")


def write_netcdf(
    ds: Any,
    path: str | Path,
    *,
    config: dict[str, Any] | None = None,
    seed: int | None = None,
) -> Path:
    """Write an ``xarray.Dataset`` to netCDF atomically, with provenance in its attributes.

    The full input ``config`` (as JSON text), the package version and the ``seed`` are
    stored as global attributes ``robobore_config``, ``robobore_version`` and
    ``robobore_seed``.
    """
    from robobore import __version__

    ds = ds.copy()
    ds.attrs["robobore_version"] = __version__
    if config is not None:
        ds.attrs["robobore_config"] = dumps_json(config)
    if seed is not None:
        ds.attrs["robobore_seed"] = int(seed)
    dest = Path(path)
    with atomic_path(dest) as tmp:
        ds.to_netcdf(tmp)
    return dest
