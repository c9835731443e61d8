"""Results files written atomically (temporary file in the same folder, then rename).

An interrupted run never leaves a half-written file: either the old file (or none) is
there, or the complete new one.
"""

from __future__ import annotations

import json
import os
import tempfile
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


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically; returns the path."""
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
    tmp = _tmp_path(dest)
    try:
        ds.to_netcdf(tmp)
        os.replace(tmp, dest)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return dest
