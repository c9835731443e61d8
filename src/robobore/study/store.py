"""Results store of a sweep: one netCDF file per condition, written atomically.

Layout of a store folder::

    store.json              format marker (store format version, created by which version)
    results/<key>.nc        one finished condition (an xarray Dataset + provenance attributes)
    failed/<key>.json       one failed condition: error, traceback, attempts
    index.json              done / failed / pending per condition of the last sweep
    summary.csv             one row per finished condition: condition + summary quantities

The files under ``results/`` are the truth: a condition is done when its netCDF file exists
and is not empty. Files are written to a temporary name, synced and renamed
(``robobore.io.results``), so a killed sweep leaves either the complete file or none, never
a half file; stale temporary files of a killed run are removed by
:meth:`ResultsStore.cleanup_partial` when the store is opened for a new run. A result file
that is empty or cannot be read as netCDF (a disk that lost it, a file copied by hand) is
set aside as ``results/<key>.nc.invalid`` by :meth:`ResultsStore.set_aside_invalid` before
a sweep runs, with a warning, and its condition is computed again. ``index.json`` and
``summary.csv`` are derived and rewritten from the files.

The key of a condition (:func:`robobore.study.conditions.condition_key`) hashes the
condition, the runner name and the model config, so several sweeps (even with different
model configs) can share one store without mixing their results.
"""

from __future__ import annotations

import csv
import io
import json
import os
import socket
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from robobore.errors import DataError, RoboboreError
from robobore.io.results import atomic_write_text, write_json, write_netcdf
from robobore.study.conditions import CONDITION_FIELDS
from robobore.study.summary import SUMMARY_QUANTITIES, summarise, summary_attrs

STORE_FORMAT = 1


class StoreWarning(UserWarning):
    """A store problem that was repaired (an unusable result set aside and recomputed)."""


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")


@dataclass(frozen=True)
class StoredResult:
    """What the store knows about one finished condition (read from its netCDF attributes)."""

    key: str
    condition: dict[str, Any]
    summary: dict[str, Any]
    path: Path
    attempt: int
    wall_time_s: float | None
    runner: str | None
    #: the runner's coefficient warnings (attribute ``coefficient_warnings``, "; " separated)
    coefficient_warnings: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {
            "key": self.key, "condition": self.condition, "summary": self.summary,
            "path": str(self.path), "attempt": self.attempt, "wall_time_s": self.wall_time_s,
            "runner": self.runner,
        }


class ResultsStore:
    """A folder of per-condition results (see module doc). Creating it creates the folder."""

    def __init__(self, root: str | Path) -> None:
        self.root = Path(root)
        self.results_dir = self.root / "results"
        self.failed_dir = self.root / "failed"
        meta = self.root / "store.json"
        if meta.exists():
            try:
                info = json.loads(meta.read_text())
                fmt = int(info["store_format"])
            except (ValueError, KeyError, TypeError) as exc:
                raise DataError(f"not a robobore results store ({exc})", file=str(meta),
                                expected=f"store_format {STORE_FORMAT}") from None
            if fmt != STORE_FORMAT:
                raise DataError("unsupported results store format", file=str(meta),
                                field="store_format", value=fmt,
                                expected=f"store_format {STORE_FORMAT}")
        elif self.root.exists() and any(self.root.iterdir()) and not self.results_dir.exists():
            raise DataError("folder exists, is not empty and is not a results store",
                            file=str(self.root), expected="an empty folder or a results store")
        else:
            from robobore import __version__

            self.results_dir.mkdir(parents=True, exist_ok=True)
            write_json(meta, {"store_format": STORE_FORMAT, "created_utc": _now(),
                              "created_by": f"robobore {__version__}"})
        self.results_dir.mkdir(parents=True, exist_ok=True)
        self.failed_dir.mkdir(parents=True, exist_ok=True)

    @classmethod
    def open_existing(cls, root: str | Path) -> ResultsStore:
        """Open a store that must already exist (for reading: ``robobore compare``)."""
        p = Path(root)
        if not (p / "store.json").is_file():
            raise DataError("not a robobore results store (no store.json)", file=str(p),
                            expected="a folder written by 'robobore sweep'")
        return cls(p)

    # --- exclusive use ----------------------------------------------------------------
    @contextmanager
    def lock(self) -> Iterator[None]:
        """Hold the store for one sweep: a second sweep on the same store (from any
        process on this machine) gets a clear error instead of racing on the files. The
        lock is an ``flock`` on ``.lock``, released by the OS when the process dies, so a
        killed sweep never leaves the store locked. (No-op where ``fcntl`` is missing.)"""
        try:
            import fcntl
        except ImportError:  # pragma: no cover - Windows
            yield
            return
        fh = (self.root / ".lock").open("a+")
        try:
            try:
                fcntl.flock(fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                fh.seek(0)
                who = fh.read().strip() or "another process"
                raise RoboboreError(
                    f"results store {self.root} is in use by another sweep ({who}); wait for "
                    "it to finish or use another --out folder"
                ) from None
            fh.seek(0)
            fh.truncate()
            fh.write(f"pid {os.getpid()} on {socket.gethostname()} since {_now()}\n")
            fh.flush()
            yield
        finally:
            fh.close()  # releases the lock

    # --- paths and status -------------------------------------------------------------
    def result_path(self, key: str) -> Path:
        return self.results_dir / f"{key}.nc"

    def failure_path(self, key: str) -> Path:
        return self.failed_dir / f"{key}.json"

    def is_done(self, key: str) -> bool:
        p = self.result_path(key)
        try:
            return p.is_file() and p.stat().st_size > 0
        except OSError:
            return False

    def result_problem(self, key: str) -> str | None:
        """Why the stored result of ``key`` is not usable (empty, unreadable), or None."""
        import netCDF4

        p = self.result_path(key)
        try:
            if p.stat().st_size == 0:
                return "zero-byte file"
            with netCDF4.Dataset(p) as nc:
                if "robobore_condition" not in nc.ncattrs():
                    return "no robobore_condition attribute"
        except FileNotFoundError:
            return None
        except OSError as exc:
            return f"unreadable ({exc.strerror or exc})"
        return None

    def set_aside_invalid(self, keys: Iterable[str]) -> list[str]:
        """Rename the result files of ``keys`` that are empty or unreadable to
        ``<key>.nc.invalid`` so that their conditions count as missing; returns one warning
        line per file set aside."""
        out = []
        for k in keys:
            p = self.result_path(k)
            if not p.exists():
                continue
            why = self.result_problem(k)
            if why is None:
                continue
            bad = p.with_name(p.name + ".invalid")
            os.replace(p, bad)
            out.append(f"result {p} is not usable ({why}): set aside as {bad.name}; the "
                       "condition is computed again")
        return out

    def status(self, key: str) -> str:
        """``"done"``, ``"failed"`` or ``"pending"``."""
        if self.is_done(key):
            return "done"
        if self.failure_path(key).is_file():
            return "failed"
        return "pending"

    def done_keys(self) -> set[str]:
        return {p.stem for p in self.results_dir.glob("*.nc") if self.is_done(p.stem)}

    def cleanup_partial(self) -> list[Path]:
        """Remove temporary files left by a killed run (never a finished result)."""
        removed = []
        for d in (self.results_dir, self.failed_dir, self.root):
            for p in d.glob(".*.tmp"):
                p.unlink(missing_ok=True)
                removed.append(p)
        return removed

    # --- writing ----------------------------------------------------------------------
    def write_result(
        self,
        key: str,
        condition: dict[str, Any],
        ds: Any,
        *,
        runner: str,
        config: dict[str, Any] | None = None,
        seed: int | None = None,
        wall_time_s: float | None = None,
        worker: str | None = None,
    ) -> Path:
        """Write one finished condition atomically; clears an earlier failure record.

        The summary (:func:`robobore.study.summary.summarise`) is validated first: a result
        that breaks the summary contract raises :class:`DataError` and is not stored.
        """
        summary = summarise(ds, source=f"result of {key}")
        prev = self._failure_record(key)
        attempt = (prev.get("attempts", 0) if prev else 0) + 1
        ds = ds.copy()
        ds.attrs.update({
            "robobore_key": key,
            "robobore_condition": json.dumps(condition, sort_keys=True),
            "robobore_runner": runner,
            "robobore_attempt": int(attempt),
            "robobore_wall_time_s": float(wall_time_s) if wall_time_s is not None else -1.0,
            "robobore_worker": worker or "",
            "robobore_finished_utc": _now(),
        })
        # the validated summary (data variables win over attributes) as attributes, so the
        # index can be rebuilt from attributes alone without reading the arrays
        ds.attrs.update(summary_attrs(summary))
        path = write_netcdf(ds, self.result_path(key),
                            config={"condition": condition, **(config or {})}, seed=seed)
        self.failure_path(key).unlink(missing_ok=True)
        return path

    def _failure_record(self, key: str) -> dict[str, Any] | None:
        p = self.failure_path(key)
        if not p.is_file():
            return None
        try:
            return json.loads(p.read_text())
        except ValueError:
            return None

    def write_failure(
        self, key: str, condition: dict[str, Any], error: str, tb: str = "",
        *, worker: str | None = None,
    ) -> Path:
        """Record a failed condition (error text and traceback); counts the attempts."""
        prev = self._failure_record(key)
        rec = {
            "key": key, "condition": condition, "error": error, "traceback": tb,
            "attempts": (prev.get("attempts", 0) if prev else 0) + 1,
            "worker": worker or "", "host": socket.gethostname(), "failed_utc": _now(),
        }
        return write_json(self.failure_path(key), rec)

    # --- reading ----------------------------------------------------------------------
    def failure(self, key: str) -> dict[str, Any] | None:
        return self._failure_record(key)

    def load(self, key: str) -> Any:
        """The stored Dataset of a finished condition, loaded into memory (file closed)."""
        import xarray as xr

        p = self.result_path(key)
        if not p.is_file():
            raise DataError("no result for this condition", file=str(p),
                            expected="a finished condition")
        with xr.open_dataset(p) as ds:
            return ds.load()

    def read_record(self, key: str) -> StoredResult:
        """Key, condition, summary and provenance of a finished condition (attributes only)."""
        import netCDF4

        p = self.result_path(key)
        try:
            with netCDF4.Dataset(p) as nc:
                attrs = {k: nc.getncattr(k) for k in nc.ncattrs()}
        except OSError as exc:
            raise DataError(f"cannot read result file ({exc})", file=str(p)) from None
        try:
            cond = json.loads(attrs["robobore_condition"])
        except (KeyError, ValueError):
            raise DataError("result file has no condition attribute", file=str(p),
                            field="robobore_condition", expected="a file written by the store"
                            ) from None

        class _A:  # minimal Dataset-like view for summarise()
            data_vars: dict[str, Any] = {}

        view = _A()
        view.attrs = attrs  # type: ignore[attr-defined]
        summary = summarise(view, source=str(p))
        wt = float(attrs.get("robobore_wall_time_s", -1.0))
        return StoredResult(
            key=key, condition=cond, summary=summary, path=p,
            attempt=int(attrs.get("robobore_attempt", 1)),
            wall_time_s=None if wt < 0 else wt, runner=attrs.get("robobore_runner"),
            coefficient_warnings=tuple(w for w in str(attrs.get("coefficient_warnings", ""))
                                       .split("; ") if w.strip()),
        )

    def records(self, keys: Iterable[str] | None = None) -> Iterator[StoredResult]:
        """Records of finished conditions (all of them, or the given keys that are done)."""
        ks = sorted(self.done_keys()) if keys is None else [k for k in keys if self.is_done(k)]
        for k in ks:
            yield self.read_record(k)

    # --- derived files ----------------------------------------------------------------
    def write_index(self, name: str, runner: str, items: list[tuple[str, dict[str, Any]]]
                    ) -> dict[str, Any]:
        """Write ``index.json`` (status of each condition of a sweep) and return it."""
        entries = []
        counts = {"done": 0, "failed": 0, "pending": 0}
        for key, cond in items:
            st = self.status(key)
            counts[st] += 1
            e: dict[str, Any] = {"key": key, "status": st, "condition": cond}
            if st == "failed":
                rec = self._failure_record(key) or {}
                e["error"] = rec.get("error", "")
                e["attempts"] = rec.get("attempts", 0)
            entries.append(e)
        index = {"sweep": name, "runner": runner, "updated_utc": _now(),
                 "total": len(items), "counts": counts, "conditions": entries}
        write_json(self.root / "index.json", index)
        return index

    def write_summary_csv(self, keys: Iterable[str] | None = None) -> Path:
        """Write ``summary.csv``: condition and summary of every finished condition
        (of ``keys`` if given), one row each; absent quantities are empty cells."""
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["key", *CONDITION_FIELDS, "posture", *SUMMARY_QUANTITIES])
        for r in self.records(keys):
            row = [r.key, *(r.condition.get(f) for f in CONDITION_FIELDS),
                   r.condition.get("posture", "")]
            for q in SUMMARY_QUANTITIES:
                v = r.summary.get(q)
                row.append("" if v is None else (str(v).lower() if q == "stable" else repr(v)))
            w.writerow(row)
        return atomic_write_text(self.root / "summary.csv", buf.getvalue())


def worker_label() -> str:
    """``host:pid`` of the calling process (recorded with each result)."""
    return f"{socket.gethostname()}:{os.getpid()}"


__all__ = ["ResultsStore", "StoredResult", "StoreWarning", "STORE_FORMAT", "worker_label"]
