"""Content-addressed cache of computed result files (used for FE virtual cutting tests).

An entry is a folder named by the SHA-256 of the canonical JSON
(:func:`robobore.io.hashing.canonical_json`) of ``{"namespace", "inputs", "version"}``:
the same inputs with the same package version give the same entry on every machine; any
change of input (or a new version of robobore) gives a new one. Layout::

    <root>/<namespace>/<key[:2]>/<key>/inputs.json     the inputs, for audit
                                      /meta.json       namespace, version, created time
                                      /<result files>  written by the compute function

An entry appears atomically: it is built in a temporary folder next to it and renamed into
place, so a reader sees a complete entry or none. Two processes computing the same entry
at once both compute; the first rename wins and the other copy is discarded.

The default root is ``$ROBOBORE_CACHE_DIR``, else ``$XDG_CACHE_HOME/robobore``, else
``~/.cache/robobore``.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from robobore.errors import InputError
from robobore.io.hashing import canonicalise, stable_hash
from robobore.io.results import fsync_dir


def default_cache_dir() -> Path:
    """``$ROBOBORE_CACHE_DIR`` or ``$XDG_CACHE_HOME/robobore`` or ``~/.cache/robobore``."""
    env = os.environ.get("ROBOBORE_CACHE_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "robobore"


def _check_name(name: str, what: str) -> None:
    if not name or "/" in name or "\\" in name or name.startswith(".") or name in {
        "inputs.json", "meta.json"}:
        raise InputError(f"invalid {what}", value=name,
                         expected="a plain file name, not starting with '.', not "
                         "inputs.json/meta.json")


class ResultCache:
    """Content-addressed cache (see module doc)."""

    def __init__(self, root: str | Path | None = None, version: str | None = None) -> None:
        from robobore import __version__

        self.root = Path(root) if root is not None else default_cache_dir()
        self.version = version if version is not None else __version__

    def key(self, namespace: str, inputs: Any) -> str:
        """The entry key (64 hex characters) of ``inputs`` in ``namespace``."""
        _check_name(namespace, "namespace")
        return stable_hash({"namespace": namespace, "inputs": inputs, "version": self.version})

    def path(self, namespace: str, key: str) -> Path:
        return self.root / namespace / key[:2] / key

    def get(self, namespace: str, inputs: Any) -> Path | None:
        """Folder of the entry for ``inputs``, or ``None`` when it is not cached."""
        p = self.path(namespace, self.key(namespace, inputs))
        return p if (p / "meta.json").is_file() else None

    def put(self, namespace: str, inputs: Any, files: dict[str, bytes | str | Path]) -> Path:
        """Store ``files`` (name -> bytes, text or a path to copy) as the entry of ``inputs``."""

        def write(tmp: Path) -> None:
            for name, data in files.items():
                _check_name(name, "file name")
                if isinstance(data, Path):
                    shutil.copyfile(data, tmp / name)
                elif isinstance(data, str):
                    (tmp / name).write_text(data, encoding="utf-8")
                else:
                    (tmp / name).write_bytes(data)

        return self._commit(namespace, inputs, write)

    def get_or_compute(self, namespace: str, inputs: Any,
                       compute: Callable[[Path], None]) -> tuple[Path, bool]:
        """The entry folder for ``inputs``, computing it when missing.

        ``compute(folder)`` writes the result files into ``folder`` (a temporary folder
        that becomes the entry when ``compute`` returns; if it raises, nothing is cached).
        Returns ``(folder, hit)`` with ``hit`` true when it came from the cache.
        """
        hit = self.get(namespace, inputs)
        if hit is not None:
            return hit, True
        return self._commit(namespace, inputs, compute), False

    def _commit(self, namespace: str, inputs: Any, write: Callable[[Path], None]) -> Path:
        key = self.key(namespace, inputs)
        dest = self.path(namespace, key)
        dest.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{key[:12]}.", suffix=".tmp", dir=dest.parent))
        try:
            write(tmp)
            (tmp / "inputs.json").write_text(
                json.dumps(canonicalise(inputs), indent=1, sort_keys=True), encoding="utf-8")
            # meta.json last: an entry is complete when meta.json exists
            (tmp / "meta.json").write_text(json.dumps({
                "namespace": namespace, "key": key, "version": self.version,
                "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
                "files": sorted(p.name for p in tmp.iterdir()),
            }, indent=1), encoding="utf-8")
            for f in tmp.iterdir():
                with f.open("rb") as fh:
                    os.fsync(fh.fileno())
            fsync_dir(tmp)
            try:
                os.rename(tmp, dest)
            except OSError:
                if (dest / "meta.json").is_file():  # somebody else committed it first
                    shutil.rmtree(tmp, ignore_errors=True)
                else:  # a broken leftover (should not happen): replace it
                    shutil.rmtree(dest, ignore_errors=True)
                    os.rename(tmp, dest)
        except BaseException:
            shutil.rmtree(tmp, ignore_errors=True)
            raise
        fsync_dir(dest.parent)  # the rename itself on disk
        return dest

    def entries(self, namespace: str | None = None) -> list[Path]:
        """Complete entries (of one namespace, or all)."""
        base = self.root / namespace if namespace else self.root
        if not base.is_dir():
            return []
        return sorted(p.parent for p in base.rglob("meta.json")
                      if not p.parent.name.startswith("."))

    def clean_partial(self) -> int:
        """Remove temporary folders of interrupted writes; returns how many."""
        n = 0
        if self.root.is_dir():
            for p in self.root.rglob(".*.tmp"):
                if p.is_dir():
                    shutil.rmtree(p, ignore_errors=True)
                    n += 1
        return n

    def size_bytes(self) -> int:
        return sum(f.stat().st_size for f in self.root.rglob("*") if f.is_file()) \
            if self.root.is_dir() else 0


__all__ = ["ResultCache", "default_cache_dir"]
