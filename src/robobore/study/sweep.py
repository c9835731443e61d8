"""Run a runner over many conditions (Dask or a process pool), storing each result as it finishes.

A *runner* is a picklable, importable function ``runner(condition: dict, context: dict)
-> xarray.Dataset`` (condition: :class:`~robobore.study.conditions.Condition` as a dict;
context: ``model`` (the model config), ``runner_options``, ``postures``, ``posture``
(this condition's posture table or ``{}``), ``seed`` (this condition's seed), ``key``,
``sweep``, and ``config_file`` (the sweep's config file, when the plan was read from one,
for error messages; not part of the key)). It is named in the sweep config: a registered
name (:data:`RUNNERS`) or ``"package.module:function"``. Runners must be importable on the
Dask workers.

Execution (:func:`run_sweep`):

* conditions already in the store are skipped; missing and failed ones are (re)computed;
* a local Dask cluster (``workers`` processes, one thread each; or threads in this process
  with ``processes=False``) is started unless a scheduler address is given, and closed at
  the end; ``pool="processes"`` runs the conditions on ``workers`` processes forked from a
  forkserver that has imported the runner once instead (:func:`_run_pool`); ``workers=0``
  runs in this process without Dask (debugging, profiling);
* results are collected with ``as_completed`` and written by the client at once, one
  netCDF file per condition, atomically; a failing condition (runner exception, a result
  that breaks the summary contract, a lost worker) is recorded with its error and
  traceback and does not stop the others;
* ``index.json`` is rewritten every few seconds and at the end, ``summary.csv`` at the end.

Killing the process at any moment loses at most the conditions in flight; the next run
recomputes exactly those.
"""

from __future__ import annotations

import importlib
import logging
import os
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from robobore.errors import ConfigError, DataError, RoboboreError
from robobore.study.conditions import (
    Condition,
    SweepConfig,
    condition_key,
    condition_seed,
)
from robobore.study.store import ResultsStore, StoreWarning, worker_label

Runner = Callable[[dict[str, Any], dict[str, Any]], Any]

#: Registered runner names -> "module:function". The real boring runner is added here when
#: the process-dynamics stage provides it.
RUNNERS: dict[str, str] = {
    "demo": "robobore.study.demo:demo_runner",
    "boring": "robobore.study.runners:boring_runner",
}


def resolve_runner(spec: str, file: str | None = None) -> Runner:
    """The runner function for a registered name or a ``"module:function"`` path
    (``file``: the sweep config, named in the errors)."""
    target = RUNNERS.get(spec, spec)
    if ":" not in target:
        raise ConfigError("unknown runner", file=file, field="sweep.runner", value=spec,
                          expected=f"one of {sorted(RUNNERS)} or 'package.module:function'")
    mod_name, _, attr = target.partition(":")
    try:
        mod = importlib.import_module(mod_name)
        fn = getattr(mod, attr)
    except (ImportError, AttributeError) as exc:
        raise ConfigError(f"cannot import runner ({exc})", file=file, field="sweep.runner",
                          value=spec,
                          expected="an importable 'package.module:function'") from None
    if not callable(fn):
        raise ConfigError("runner is not callable", file=file, field="sweep.runner", value=spec,
                          expected="a function runner(condition, context) -> xarray.Dataset")
    return fn


@dataclass(frozen=True)
class SweepItem:
    """One condition of a sweep with its key and its own context."""

    key: str
    condition: dict[str, Any]
    context: dict[str, Any]


@dataclass(frozen=True)
class SweepPlan:
    """Everything needed to run a sweep: name, runner spec, items (in order)."""

    name: str
    runner: str
    items: tuple[SweepItem, ...]
    config: dict[str, Any]
    #: the config file the plan was read from (named in per-condition error messages)
    source: str | None = None

    @classmethod
    def from_config(cls, cfg: SweepConfig, conditions: list[Condition]) -> SweepPlan:
        items = []
        for c in conditions:
            posture = cfg.postures.get(c.posture, {})
            key = condition_key(c, cfg.sweep.runner, cfg.model, posture)
            ctx = {
                "model": cfg.model, "runner_options": cfg.runner_options,
                "postures": cfg.postures, "posture": posture,
                "seed": condition_seed(cfg.sweep.seed, key), "key": key,
                "sweep": cfg.sweep.name,
            }
            items.append(SweepItem(key=key, condition=c.to_dict(), context=ctx))
        keys = [i.key for i in items]
        if len(set(keys)) != len(keys):  # pragma: no cover - duplicates are caught earlier
            raise ConfigError("two conditions have the same key", expected="distinct conditions")
        return cls(
            name=cfg.sweep.name, runner=cfg.sweep.runner, items=tuple(items),
            config={"sweep": cfg.sweep.model_dump(), "model": cfg.model,
                    "postures": cfg.postures},
        )


@dataclass(frozen=True, slots=True)
class SweepOutcome:
    """What a sweep run did (``to_dict()``: the ``robobore sweep --json`` keys after ``name``
    and ``runner``; contract in tests/study/contract/sweep.json)."""

    #: the results store's folder
    store: Path
    #: conditions of the plan
    total: int
    #: already done before this run
    skipped: int
    #: finished in this run
    computed: int
    #: failed in this run
    failed: int
    #: still not done (failed or never run) after this run
    pending: int
    #: wall time of the run [s]
    wall_time_s: float
    #: how the conditions ran (serial, a Dask local cluster, a Dask scheduler)
    mode: str
    #: the failed conditions: key, condition, error
    failures: tuple[dict[str, Any], ...] = field(default_factory=tuple)
    #: store problems met and repaired (result files set aside and recomputed)
    warnings: tuple[str, ...] = field(default_factory=tuple)

    @property
    def conditions_per_s(self) -> float:
        n = self.computed + self.failed
        return n / self.wall_time_s if self.wall_time_s > 0 and n else 0.0

    def to_dict(self) -> dict[str, Any]:
        return {
            "store": str(self.store), "total": self.total, "skipped": self.skipped,
            "computed": self.computed, "failed": self.failed, "pending": self.pending,
            "wall_time_s": self.wall_time_s, "conditions_per_s": self.conditions_per_s,
            "mode": self.mode, "failures": list(self.failures),
            "warnings": list(self.warnings),
        }


def execute(runner: Runner, condition: dict[str, Any], context: dict[str, Any]) -> dict[str, Any]:
    """Run one condition (on a worker); never raises: returns ``ok`` and the dataset or the
    error text and traceback."""
    t0 = time.perf_counter()
    try:
        ds = runner(condition, context)
        import xarray as xr

        if not isinstance(ds, xr.Dataset):
            raise TypeError(f"runner returned {type(ds).__name__}, expected xarray.Dataset")
        return {"ok": True, "dataset": ds, "wall_time_s": time.perf_counter() - t0,
                "worker": worker_label()}
    except Exception as exc:  # recorded, the sweep goes on
        return {"ok": False, "error": f"{type(exc).__name__}: {exc}",
                "traceback": traceback.format_exc(), "wall_time_s": time.perf_counter() - t0,
                "worker": worker_label()}


def _default_workers() -> int:
    return max(1, os.cpu_count() or 1)


class _Recorder:
    """Writes results/failures to the store and keeps the counts (client side)."""

    def __init__(self, store: ResultsStore, plan: SweepPlan, advance: Callable[[int], None],
                 index_every_s: float) -> None:
        self.store, self.plan, self.advance = store, plan, advance
        self.computed = 0
        self.failures: list[dict[str, Any]] = []
        self.index_every_s = index_every_s
        self._last_index = time.monotonic()
        self._pairs = [(i.key, i.condition) for i in plan.items]
        #: the runners' coefficient warnings (dataset attribute ``coefficient_warnings``, "; "
        #: separated) -> number of conditions computed in this run that carry it
        self.coefficient_warnings: dict[str, int] = {}

    def record(self, item: SweepItem, res: dict[str, Any]) -> None:
        if res.get("ok"):
            try:
                self.store.write_result(
                    item.key, item.condition, res["dataset"], runner=self.plan.runner,
                    config={**self.plan.config, "runner_options":
                            item.context.get("runner_options", {})},
                    seed=item.context.get("seed"), wall_time_s=res.get("wall_time_s"),
                    worker=res.get("worker"),
                )
                self.computed += 1
                for w in str(res["dataset"].attrs.get("coefficient_warnings", "")).split("; "):
                    if w.strip():
                        self.coefficient_warnings[w] = self.coefficient_warnings.get(w, 0) + 1
            except (DataError, TypeError, ValueError) as exc:
                # the result breaks the summary contract or cannot be stored as netCDF
                # (e.g. a dict-valued attribute): a failure of this condition, not the sweep
                self._fail(item, f"{type(exc).__name__}: {exc}", traceback.format_exc(),
                           res.get("worker"))
        else:
            self._fail(item, res["error"], res.get("traceback", ""), res.get("worker"))
        self.advance(1)
        now = time.monotonic()
        if now - self._last_index >= self.index_every_s:
            self.write_index()
            self._last_index = now

    def _fail(self, item: SweepItem, error: str, tb: str, worker: str | None) -> None:
        self.store.write_failure(item.key, item.condition, error, tb, worker=worker)
        self.failures.append({"key": item.key, "condition": item.condition, "error": error})

    def write_index(self) -> dict[str, Any]:
        return self.store.write_index(self.plan.name, self.plan.runner, self._pairs)


def run_sweep(
    plan: SweepPlan,
    store: ResultsStore | str | Path,
    *,
    runner: Runner | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    processes: bool = True,
    progress: Callable[[str, int, int], None] | None = None,
    index_every_s: float = 2.0,
    connect_timeout_s: float = 15.0,
    pool: str = "dask",
    executor: Any = None,
) -> SweepOutcome:
    """Run the pending conditions of ``plan`` and store each result as it finishes.

    ``scheduler``: address of a running Dask scheduler (``tcp://host:port``); otherwise a
    local cluster with ``workers`` workers (default: CPU count), processes or threads
    (``processes``); ``workers=0`` (and no scheduler) runs serially in this process.
    ``pool="processes"`` (no scheduler, ``processes``): ``workers`` processes forked from a
    server that has imported the runner's module once (:func:`_run_pool`), instead of a
    Dask cluster whose workers each start an interpreter and import everything; same
    results, less start-up work. ``executor``: with ``pool="processes"``, an open
    ``concurrent.futures`` process pool to submit the conditions to instead of starting one
    (it is left open; a study that runs other work on the same workers passes it).
    ``runner`` overrides the plan's runner spec (a picklable function). The store is
    locked for the duration (:meth:`ResultsStore.lock`). ``progress(task, done, total)``, if
    given, is called with ``task = "sweep <name>"`` once before the first condition (done 0)
    and after each condition that finishes, ``total`` being the conditions to compute.
    """
    if not isinstance(store, ResultsStore):
        store = ResultsStore(store)
    fn = runner if runner is not None else resolve_runner(plan.runner,
                                                          getattr(plan, "source", None))
    if pool not in POOLS:
        raise ConfigError("unknown sweep pool", field="pool", value=pool,
                          expected=f"one of {POOLS}")
    with store.lock():
        return _run_locked(plan, store, fn, scheduler=scheduler, workers=workers,
                           processes=processes, progress=progress, index_every_s=index_every_s,
                           connect_timeout_s=connect_timeout_s, pool=pool,
                           executor=executor)


#: Local executors of :func:`run_sweep`: a Dask local cluster, or a forked process pool.
POOLS = ("dask", "processes")


def _run_locked(plan: SweepPlan, store: ResultsStore, fn: Runner, *, scheduler: str | None,
                workers: int | None, processes: bool,
                progress: Callable[[str, int, int], None] | None, index_every_s: float,
                connect_timeout_s: float, pool: str = "dask",
                executor: Any = None) -> SweepOutcome:
    import warnings

    store.cleanup_partial()  # safe: the lock says no other sweep is writing here
    bad = store.set_aside_invalid(i.key for i in plan.items)
    for w in bad:
        warnings.warn(w, StoreWarning, stacklevel=2)
    todo = [i for i in plan.items if not store.is_done(i.key)]
    if plan.source is not None:  # per-condition errors name the config file
        todo = [SweepItem(i.key, i.condition, {**i.context, "config_file": plan.source})
                for i in todo]
    skipped = len(plan.items) - len(todo)
    t0 = time.perf_counter()

    if scheduler is not None:
        mode = f"dask scheduler {scheduler}"
    elif workers == 0:
        mode = "serial (no Dask)"
    elif pool == "processes" and processes:
        mode = f"local process pool, {workers or _default_workers()} worker(s)"
    else:
        nw = workers or _default_workers()
        mode = f"dask local cluster, {nw} {'process' if processes else 'thread'} worker(s)"

    task, done = f"sweep {plan.name}", [0]

    def advance(n: int) -> None:
        done[0] += n
        if progress is not None:
            progress(task, done[0], len(todo))

    advance(0)
    rec = _Recorder(store, plan, advance, index_every_s)
    rec.write_index()
    if todo:
        if scheduler is None and workers == 0:
            for item in todo:
                rec.record(item, execute(fn, item.condition, item.context))
        elif scheduler is None and pool == "processes" and processes:
            _run_pool(fn, todo, rec, workers=workers or _default_workers(), executor=executor)
        else:
            _run_dask(fn, todo, rec, scheduler=scheduler,
                      workers=workers or _default_workers(), processes=processes,
                      connect_timeout_s=connect_timeout_s)
    index = rec.write_index()
    store.write_summary_csv([i.key for i in plan.items])
    return SweepOutcome(
        store=store.root, total=len(plan.items), skipped=skipped, computed=rec.computed,
        failed=len(rec.failures), pending=index["counts"]["failed"] + index["counts"]["pending"],
        wall_time_s=time.perf_counter() - t0, mode=mode, failures=tuple(rec.failures),
        warnings=tuple(bad) + coefficient_warning_lines(rec.coefficient_warnings,
                                                        len(plan.items)),
    )


#: At most this many distinct coefficient warnings are listed by a sweep (then a count).
MAX_COEFFICIENT_WARNINGS = 10


def coefficient_warning_lines(counts: dict[str, int], total: int) -> tuple[str, ...]:
    """One line per distinct coefficient warning of the computed conditions ("coefficients
    (n of N conditions): ..."), the most frequent first, at most
    :data:`MAX_COEFFICIENT_WARNINGS` and a line saying how many more."""
    items = sorted(counts.items(), key=lambda kv: (-kv[1], kv[0]))
    out = [f"coefficients ({n} of {total} conditions): {w}"
           for w, n in items[:MAX_COEFFICIENT_WARNINGS]]
    if len(items) > MAX_COEFFICIENT_WARNINGS:
        out.append(f"coefficients: {len(items) - MAX_COEFFICIENT_WARNINGS} more distinct "
                   "warnings (each condition's `coefficient_warnings` in its Dataset)")
    return tuple(out)


def _forget_failed_client(exc: BaseException) -> None:
    """Mark the half-built ``Client`` of a failed connection closed, so that its ``__del__``
    does not try (30 s) to close a connection that never opened and print a traceback."""
    from distributed import Client

    tb = exc.__traceback__
    while tb is not None:
        obj = tb.tb_frame.f_locals.get("self")
        if isinstance(obj, Client):
            obj.status = "closed"
        tb = tb.tb_next


def _client_within(client_cls: Any, scheduler: str, timeout_s: float) -> Any:
    """``Client(scheduler)`` or TimeoutError after ``timeout_s``: Dask's own connect
    timeout does not bound the handshake, so a server that accepts the connection and never
    answers would hang the sweep; the client is built in a daemon thread and abandoned when
    it does not finish in time."""
    import threading

    box: dict[str, Any] = {}

    def target() -> None:
        try:
            box["client"] = client_cls(scheduler, timeout=f"{timeout_s}s",
                                       set_as_default=False)
        except BaseException as exc:  # noqa: BLE001 - re-raised in the caller's thread
            box["error"] = exc

    t = threading.Thread(target=target, name="robobore-dask-connect", daemon=True)
    t.start()
    t.join(timeout_s + 1.0)
    if t.is_alive():
        raise TimeoutError(f"no Dask handshake within {timeout_s:g} s (the server accepts "
                           "connections but does not answer)")
    if "error" in box:
        raise box["error"]
    return box["client"]


def _run_dask(fn: Runner, todo: list[SweepItem], rec: _Recorder, *, scheduler: str | None,
              workers: int, processes: bool, connect_timeout_s: float) -> None:
    from distributed import Client, LocalCluster, as_completed

    cluster = None
    client = None
    try:
        if scheduler is not None:
            try:
                client = _client_within(Client, scheduler, connect_timeout_s)
            except (OSError, TimeoutError) as exc:
                _forget_failed_client(exc)
                raise RoboboreError(
                    f"cannot connect to the Dask scheduler at {scheduler!r} within "
                    f"{connect_timeout_s:g} s ({exc}); expected a running scheduler, e.g. "
                    "'dask scheduler' then 'dask worker ADDR'"
                ) from None
            except Exception as exc:  # something answers, but not as a Dask scheduler
                _forget_failed_client(exc)
                raise RoboboreError(
                    f"the server at {scheduler!r} does not answer as a Dask scheduler "
                    f"({type(exc).__name__}); expected the address of a running scheduler, "
                    "e.g. 'dask scheduler' then 'dask worker ADDR'"
                ) from None
        else:
            # processes: TCP on loopback only; threads: Dask's in-process transport
            extra = {"host": "127.0.0.1"} if processes else {}
            # the scheduler's HTTP server always starts; a random loopback port avoids
            # clashes with other clusters (the default 8787) and exposes nothing
            cluster = LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=processes,
                dashboard_address="127.0.0.1:0", silence_logs=logging.ERROR, **extra,
            )
            client = Client(cluster, set_as_default=False)
        by_future = {}
        for item in todo:
            fut = client.submit(execute, fn, item.condition, item.context, pure=False,
                                key=f"robobore-{item.key}-{os.urandom(4).hex()}")
            by_future[fut] = item
        for fut in as_completed(list(by_future), loop=client.loop):
            item = by_future.pop(fut)
            if fut.status == "finished":
                res = fut.result()
            else:  # lost worker (KilledWorker), cancelled, unpicklable result ...
                res = _dask_failure(fut)
            fut.release()
            rec.record(item, res)
    finally:
        if client is not None:
            client.close(timeout=10)
        if cluster is not None:
            cluster.close(timeout=10)


def pool_preload(fn: Runner) -> list[str]:
    """The modules the forkserver of a sweep's process pool imports before it forks the
    workers: this module, the runner's and those its ``preload_modules`` attribute names."""
    return [__name__, getattr(fn, "__module__", __name__), *getattr(fn, "preload_modules", ())]


def _run_pool(fn: Runner, todo: list[SweepItem], rec: _Recorder, *, workers: int,
              executor: Any = None) -> None:
    """The conditions on ``workers`` processes of a ``concurrent.futures`` pool whose
    processes are forked from a server that imported the runner's module and the modules it
    names in its ``preload_modules`` attribute (numpy, xarray, the numba kernels' modules)
    once; results are recorded as they finish. A
    worker that dies breaks the pool: the conditions not finished then are recorded as
    failures (run the sweep again to retry them). ``executor``: an open pool to use instead
    (left open)."""
    import contextlib
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor, as_completed
    from concurrent.futures.process import BrokenProcessPool

    if executor is None:
        ctx = mp.get_context("forkserver")
        ctx.set_forkserver_preload(pool_preload(fn))
        pool_cm: Any = ProcessPoolExecutor(max_workers=min(workers, len(todo)), mp_context=ctx)
    else:
        pool_cm = contextlib.nullcontext(executor)
    with pool_cm as ex:
        by_future = {}
        for i in todo:
            try:
                by_future[ex.submit(execute, fn, i.condition, i.context)] = i
            except BrokenProcessPool:  # a shared pool broken by other work
                rec.record(i, {"ok": False, "error": "the sweep's process pool is broken (a "
                               "worker died); run the sweep again to retry this condition",
                               "traceback": traceback.format_exc()})
        for fut in as_completed(by_future):
            item = by_future.pop(fut)
            try:
                res = fut.result()
            except BrokenProcessPool:
                res = {"ok": False, "error": "a worker process of the sweep pool died while "
                       "this condition was queued or running; run the sweep again to retry "
                       "it", "traceback": traceback.format_exc()}
            except Exception as exc:  # unpicklable result, ...
                res = {"ok": False, "error": f"{type(exc).__name__}: {exc}",
                       "traceback": traceback.format_exc()}
            rec.record(item, res)


def _dask_failure(fut: Any) -> dict[str, Any]:
    """Failure record of a Dask future that did not finish (never raises)."""
    exc, tb = None, ""
    try:
        if fut.status == "error":
            exc = fut.exception()
            t = fut.traceback()
            tb = "".join(traceback.format_tb(t)) if t is not None else ""
    except Exception as e:  # cancelled futures raise on inspection
        exc = e
    if exc is None:
        err = (f"Dask task ended as '{fut.status}' without a result (its worker was probably "
               "lost while it was queued there); run the sweep again to retry it")
    else:
        err = f"{type(exc).__name__}: {exc}"
    return {"ok": False, "error": err, "traceback": tb}


def plan_from_file(path: str | Path) -> SweepPlan:
    """Read a sweep config TOML into a :class:`SweepPlan` (validates the runner name too)."""
    from robobore.study.conditions import load_sweep_config

    cfg, conds = load_sweep_config(path)
    plan = replace(SweepPlan.from_config(cfg, conds), source=str(path))
    resolve_runner(plan.runner, str(path))
    return plan


__all__ = [
    "RUNNERS",
    "Runner",
    "SweepItem",
    "SweepPlan",
    "SweepOutcome",
    "resolve_runner",
    "execute",
    "run_sweep",
    "plan_from_file",
    "coefficient_warning_lines",
    "MAX_COEFFICIENT_WARNINGS",
    "POOLS",
]
